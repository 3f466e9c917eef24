"""The `ballast` command under careless or hostile use (issue 18), on the real bin/ballast
(skipped when it is not built; `make test` builds it).

- `--out` naming a file is refused as such (exit 2), not with internal temporary paths;
- a scene saved with a UTF-8 byte-order mark runs like the same scene without it;
- `ballast keys` lists every probe quantity (and so does docs/scene-format.md, test_readme.py);
- a rerun into a folder that held a finished run removes the old run.json before anything
  else, so a kill at any moment never leaves it saying ok beside missing outputs;
- on a full disk `run` and `exact` end with exit 3 and leave no temporary file (a small
  tmpfs, mounted for the test: skipped where mounting is not permitted).
"""
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
BALLAST = REPO / "bin" / "ballast"
MINIMAL = REPO / "core" / "tests" / "scenes" / "minimal.scene"
PILE = REPO / "cases" / "piles" / "pile30_smooth.scene"

needs_ballast = pytest.mark.skipif(not BALLAST.exists(), reason="bin/ballast not built")
OUTPUTS = ("run.json", "series.tsv", "discs.tsv", "contacts.tsv", "walls.tsv", "stress.tsv")


def ballast(*args, timeout=120):
    return subprocess.run([str(BALLAST), *map(str, args)], capture_output=True, text=True,
                          timeout=timeout)


@needs_ballast
@pytest.mark.parametrize("command", ["run", "exact"])
def test_out_naming_a_file_is_refused_as_such(tmp_path, command):
    target = tmp_path / "afile"
    target.write_text("keep me\n")
    done = ballast(command, PILE if command == "exact" else MINIMAL, "--out", target)
    assert done.returncode == 2
    assert done.stderr.strip() == f"ballast {command}: --out {target} is not a directory"
    assert target.read_text() == "keep me\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile"]


@needs_ballast
def test_byte_order_mark_is_accepted(tmp_path):
    plain, marked = tmp_path / "plain.scene", tmp_path / "marked.scene"
    shutil.copy(MINIMAL, plain)
    marked.write_bytes(b"\xef\xbb\xbf" + MINIMAL.read_bytes())
    assert ballast("run", plain, "--out", tmp_path / "a").returncode == 0
    done = ballast("run", marked, "--out", tmp_path / "b")
    assert done.returncode == 0, done.stderr
    for name in ("series.tsv", "discs.tsv", "contacts.tsv"):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()


@needs_ballast
def test_byte_order_mark_only_at_the_start(tmp_path):
    text = MINIMAL.read_text().replace("[disc a]", "\ufeff[disc a]")
    scene = tmp_path / "inner.scene"
    scene.write_text(text, encoding="utf-8")
    done = ballast("run", scene, "--out", tmp_path / "o")
    assert done.returncode == 2 and "expected" in done.stderr
    assert not (tmp_path / "o").exists()


QUANTITIES = ("contact_fn contact_fs contact_sliding wall_f1 wall_f2 wall_moment wall_ecc disc_x "
              "disc_y disc_vx disc_vy disc_theta disc_omega energy_kinetic energy_elastic "
              "work_walls work_gravity dissipated_dashpot dissipated_friction dissipated_global "
              "energy_imbalance unbalanced n_contacts n_sliding held_fx held_fy weight_x "
              "weight_y contact_mr contact_theta_r contact_rolling dissipated_rolling wall_px "
              "wall_py wall_gap wall_stress").split()


@needs_ballast
def test_keys_list_every_probe_quantity():
    keys = ballast("keys").stdout
    row = next(line for line in keys.splitlines() if line.startswith("| `quantity` |"))
    listed = row.split("|")[4].split()
    assert listed == QUANTITIES


@needs_ballast
@pytest.mark.skipif(shutil.which("strace") is None, reason="strace is not installed")
def test_rerun_removes_the_old_run_json_first(tmp_path):
    out = tmp_path / "o"
    assert ballast("run", MINIMAL, "--out", out).returncode == 0
    trace = tmp_path / "trace"
    done = subprocess.run(["strace", "-f", "-e", "trace=unlink,unlinkat", "-o", str(trace),
                           str(BALLAST), "run", str(MINIMAL), "--out", str(out)],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    removed = [line for line in trace.read_text().splitlines()
               if "unlink" in line and "= 0" in line]
    names = [Path(line.split('"')[1]).name for line in removed]
    assert names[:2] == ["run.json", "series.tsv"], names


def _mount_tmpfs(path, size):
    try:
        done = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(path)],
                              capture_output=True, text=True, timeout=30)
    except OSError as exc:
        return str(exc)
    return "" if done.returncode == 0 else done.stderr.strip() or "mount failed"


@pytest.fixture
def full_disk():
    """A 200 KiB tmpfs, nearly filled; unmounted afterwards."""
    root = Path(tempfile.mkdtemp(prefix="ballast-full-"))
    why = _mount_tmpfs(root, "200k")
    if why:
        root.rmdir()
        pytest.skip(f"cannot mount a tmpfs here: {why}")
    try:
        (root / "filler").write_bytes(b"\0" * (190 * 1024))
        yield root
    finally:
        subprocess.run(["umount", str(root)], capture_output=True, timeout=30)
        root.rmdir()


@needs_ballast
@pytest.mark.parametrize("command", ["run", "exact"])
def test_full_disk_is_an_io_error_and_leaves_no_temporary_file(full_disk, command):
    out = full_disk / "o"
    done = ballast(command, PILE, "--out", out, "--set", "stage.ramp.cycles=50",
                   "--set", "stage.relax.cycles=50")
    assert done.returncode == 3, done.stderr
    assert "No space left on device" in done.stderr or "write failed" in done.stderr
    left = sorted(p.name for p in out.iterdir()) if out.exists() else []
    assert not [n for n in left if n.endswith(".tmp")], left
    # What is left says why: at most a run.json, and no result file.
    assert set(left) <= {"run.json"}, left


@needs_ballast
def test_run_ends_with_a_summary_of_what_it_simulated(tmp_path):
    """Issue 23: a run says on exit how it ended, its cycles, the simulated time (the dt it used)
    and the energy imbalance, so a stage count that covers a fraction of the time meant shows;
    the same stage given in time covers the same time whatever dt is."""
    import json
    import re
    line = re.compile(r"ballast run: ok, (\d+) cycles, (\S+) s simulated \(dt (\S+)\), wall \S+ s, "
                      r"energy imbalance \S+ of the energy through the run\n")
    scene = tmp_path / "drop.scene"
    scene.write_text("[settings]\ndt = 1e-3\ngravity = 0 -9.81\n[material m]\nkn = 1e3\ndensity = 1\n"
                     "[disc d]\nx = 0 1\nr = 0.1\nmaterial = m\n[stage fall]\ntime = 0.25\n")
    seen = []
    for dt in ("1e-3", "2.5e-4"):
        done = ballast("run", scene, "--out", tmp_path / dt, "--set", f"settings.dt={dt}")
        assert done.returncode == 0, done.stderr
        m = line.fullmatch(done.stdout)
        assert m, done.stdout
        seen.append((int(m.group(1)), float(m.group(2))))
        stage = json.loads((tmp_path / dt / "run.json").read_text())["stages"][0]
        assert stage["stage_time"] == 0.25 and stage["max_cycles"] == stage["cycles"] == seen[-1][0]
    assert seen[0][0] == 250 and seen[1][0] == 1000
    assert seen[0][1] == pytest.approx(0.25, rel=1e-12) and seen[1][1] == pytest.approx(0.25, rel=1e-12)


@needs_ballast
def test_a_sweep_over_the_time_step_keeps_the_simulated_time(tmp_path):
    """Issue 23: `harness sweep --set settings.dt=...` runs each stage given in cycles over the
    same simulated time (stage.NAME.time overrides from `ballast info`), so halving dt doubles
    the steps, and the table has each point's error and cost."""
    import json
    import sys
    env = {**os.environ, "BALLAST_REPORTS": str(tmp_path), "PYTHONPATH": str(REPO)}
    for var in ("BALLAST_CASES", "BALLAST_REFERENCE", "BALLAST_BIN"):
        env.pop(var, None)
    done = subprocess.run([sys.executable, "-m", "harness", "sweep", "two_discs", "--variant", "undamped",
                           "--set", "settings.dt=0.01,0.005", "-j", "2"], cwd=REPO, env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "keeps the stages' simulated time" in done.stdout and "(wall s)" in done.stdout
    runs = [json.loads((tmp_path / "sweeps" / "two_discs" / f"settings.dt={dt}" / "run.json").read_text())
            for dt in ("0.01", "0.005")]
    assert runs[1]["steps"] == 2 * runs[0]["steps"]
    assert runs[1]["time"] == pytest.approx(runs[0]["time"], rel=1e-12)
    for run in runs:
        assert [st["cycles"] * run["dt"] for st in run["stages"]] == pytest.approx([0.4, 6.0], rel=1e-12)


# ---- issue 29: inputs refused badly, slowly or not at all (items 9-13, 15) ----------------

# A refusal that takes longer than this was not "at once": each of these took from minutes to
# forever before (a FIFO blocked in fopen; 1e8 grains took 56 s and 1.9 GB before the refusal).
AT_ONCE_S = 10
IMPORT_HEAD = "[material m]\nkn = 1e5\ndensity = 2\n[import p]\n"


@needs_ballast
@pytest.mark.parametrize("where", ["scene", "discs", "walls"])
def test_a_fifo_is_refused_at_once(tmp_path, where):
    """Item 9: a FIFO as the scene, or as an [import]'s data file, is not a regular file:
    exit 2 at once, nothing written (it blocked forever in fopen, waiting for a writer)."""
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    if where == "scene":
        scene, line = fifo, ""
    else:
        (tmp_path / "d.tsv").write_text("x\ty\tr\ttheta\n0\t0\t0.5\t0\n")
        scene = tmp_path / "imp.scene"
        files = "discs = pipe\n" if where == "discs" else "discs = d.tsv\nwalls = pipe\n"
        scene.write_text(IMPORT_HEAD + files + "material = m\nwall_material = m\n"
                         "[stage s]\ncycles = 1\n")
        line = ":5: discs: " if where == "discs" else ":6: walls: "
    done = ballast("run", scene, "--out", tmp_path / "o", timeout=AT_ONCE_S)
    assert done.returncode == 2, done.stderr
    head = f"{fifo}" if where == "scene" else f"{scene}{line}{fifo}"
    assert done.stderr.startswith(f"{head}: not a regular file: a FIFO (named pipe)")
    assert not (tmp_path / "o").exists()


@needs_ballast
def test_an_import_file_with_a_byte_order_mark_runs(tmp_path):
    """Item 10: a discs.tsv saved with a UTF-8 byte-order mark before the header x ... runs
    like the same file without it (it was "no column 'x' in the header")."""
    rows = "x\ty\tr\ttheta\n0\t0\t0.5\t0\n2\t0\t0.5\t0\n"
    (tmp_path / "plain.tsv").write_text(rows)
    (tmp_path / "marked.tsv").write_bytes(b"\xef\xbb\xbf" + rows.encode())
    out = {}
    for name in ("plain", "marked"):
        scene = tmp_path / f"{name}.scene"
        scene.write_text(IMPORT_HEAD + f"discs = {name}.tsv\nmaterial = m\n[stage s]\ncycles = 5\n")
        done = ballast("run", scene, "--out", tmp_path / name)
        assert done.returncode == 0, done.stderr
        out[name] = (tmp_path / name / "discs.tsv").read_bytes()
    assert out["plain"] == out["marked"]


@needs_ballast
def test_discs_piled_at_one_point_are_bad_input(tmp_path):
    """Item 11: 600 imported discs at one point were "more than 512 neighbours within reach at
    step 0", exit 1, no line; the start overlap is bad input: exit 2, FILE:LINE: discs:, no
    output folder."""
    (tmp_path / "pile.tsv").write_text("x\ty\tr\ttheta\n" + "1\t1\t0.5\t0\n" * 600)
    scene = tmp_path / "pile.scene"
    scene.write_text(IMPORT_HEAD + "discs = pile.tsv\nmaterial = m\n[stage s]\ncycles = 1\n")
    done = ballast("run", scene, "--out", tmp_path / "o", timeout=AT_ONCE_S)
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith(f"{scene}:5: discs: disc p.0 of [import p] (line 2 of pile.tsv): "
                                  "overlaps disc p.1 by 1 (2 of the smaller radius) at the start")
    assert not (tmp_path / "o").exists()


GRAINS = ("[material m]\nkn = 1e5\ndensity = 2\n[grains g]\nsize = 20 20\nn = {n}\nmaterial = m\n"
          "dmin = 1\nd10 = 1.2\nd50 = 1.5\nd60 = 1.6\ndmax = 2\n{more}[stage s]\ncycles = 1\n")


@needs_ballast
def test_grains_that_cannot_fit_are_refused_at_once(tmp_path):
    """Item 12: 1e8 grains of diameter >= 1 in a 20 x 20 region were refused after 56 s and
    1.9 GB; the densest packing bounds them at 2 x 20 x 20 / sqrt(3) = 461, refused at once."""
    scene = tmp_path / "g.scene"
    scene.write_text(GRAINS.format(n=100000000, more=""))
    done = ballast("run", scene, "--out", tmp_path / "o", timeout=AT_ONCE_S)
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith(f"{scene}:6: n: [grains g]: 100000000 discs of diameter >= dmin = 1 "
                                  "cannot lie apart in the region 20 x 20: at most 461 can")


@needs_ballast
def test_a_grains_origin_beyond_precision_is_named(tmp_path):
    """Item 12: origin = 1e300 1e300 was blamed on n ("fewer discs"); it is the origin, where
    the doubles are 1.5e284 apart."""
    scene = tmp_path / "g.scene"
    scene.write_text(GRAINS.format(n=40, more="origin = 1e300 1e300\n"))
    done = ballast("run", scene, "--out", tmp_path / "o", timeout=AT_ONCE_S)
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith(f"{scene}:13: origin: [grains g]: the region reaches x = 1e+300, "
                                  "where doubles are 1.487016908477783e+284 apart")


@needs_ballast
def test_a_generated_disc_is_probed_by_its_name(tmp_path):
    """Item 13: `[probe] quantity = disc_y, a = g.0` was refused although every message names
    the disc g.0; its column is the y that discs.tsv gives the disc named g.0."""
    scene = tmp_path / "g.scene"
    scene.write_text(GRAINS.format(n=40, more="").replace(
        "[stage s]\ncycles = 1\n", "[stage s]\ncycles = 1\n[probe y]\nquantity = disc_y\na = g.0\n"))
    done = ballast("run", scene, "--out", tmp_path / "o")
    assert done.returncode == 0, done.stderr
    series = (tmp_path / "o" / "series.tsv").read_text().splitlines()
    assert series[0].split("\t")[-1] == "y"
    discs = [line.split("\t") for line in (tmp_path / "o" / "discs.tsv").read_text().splitlines()]
    col = {name: k for k, name in enumerate(discs[0])}
    row = next(r for r in discs[1:] if r[col["name"]] == "g.0")
    assert series[-1].split("\t")[-1] == row[col["y"]]


@needs_ballast
def test_a_value_just_out_of_range_prints_why(tmp_path):
    """Item 15: `rolling = 2.0000001` was "2 is out of range: expected 0 <= value <= 2"."""
    scene = tmp_path / "r.scene"
    scene.write_text("[material m]\nkn = 1e5\nrolling = 2.0000001\n")
    done = ballast("run", scene, "--out", tmp_path / "o")
    assert done.returncode == 2
    assert done.stderr.strip() == (f"{scene}:3: rolling: 2.0000001 is out of range: "
                                   "expected 0 <= value <= 2")
