"""Snapshots of a run on the real bin/ballast (issue 32, item 1; docs/paraview.md), skipped when
it is not built (`make test` builds it):

- a pile's frames: index.tsv lists frame 0 at cycle 0, every N cycles, then the final state;
  the last frame's contacts and walls are the final contacts.tsv and walls.tsv byte for byte
  and its discs the final discs' columns; no .tmp left;
- a run that fails leaves no snapshots/ (as it leaves no discs.tsv), a full disk too (exit 3);
- an interrupted run keeps the frames written so far, as it keeps series.tsv, each listed frame
  with all its files;
- a new run into the folder removes an earlier run's snapshots.
The schedule, the keys and the rows are tested in core/tests/check_snapshots.c.
"""
import csv
import signal
import subprocess
import time
from pathlib import Path

import pytest

from harness.tests.test_core_cli import full_disk  # noqa: F401 -- the fixture: a nearly full tmpfs

REPO = Path(__file__).resolve().parents[2]
BALLAST = REPO / "bin" / "ballast"
PILE = REPO / "cases" / "piles" / "pile30_smooth.scene"
SHORT = ["--set", "stage.ramp.cycles=300", "--set", "stage.relax.cycles=450"]

needs_ballast = pytest.mark.skipif(not BALLAST.exists(), reason="bin/ballast not built")
DISC_COLUMNS = ["id", "name", "x", "y", "r", "theta", "vx", "vy", "omega", "m", "fixed"]

# A disc between two held discs, spinning on a huge cohesion with a step 28 times its
# critical one: its spin overflows within ~90 cycles (check_sim.c, unstable_scene).
UNSTABLE = """[settings]
dt = 0.5
force_dt = 1
allow_overlap = 1
energy_guard = 0
snapshot_every = 10
[material m]
kn = 1e4
ks = 1e4
friction = 0
cohesion = 1.7e308
density = 1
[disc left]
x = -1.9 0
r = 1
fixed = 1
material = m
[disc free]
x = 0 0
r = 1
omega = 1
material = m
[disc right]
x = 1.9 0
r = 1
fixed = 1
material = m
[stage s]
cycles = 1000
"""


def ballast(*args, timeout=120):
    return subprocess.run([str(BALLAST), *map(str, args)], capture_output=True, text=True,
                          timeout=timeout)


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f, delimiter="\t"))


def listed_frames_complete(snap):
    """The frames index.tsv lists, each checked to have its three files."""
    frames = rows(snap / "index.tsv")
    for row in frames:
        k = int(row["frame"])
        for part in ("discs", "contacts", "walls"):
            assert (snap / f"{part}.{k:06d}.tsv").is_file(), (k, part)
    return frames


@needs_ballast
def test_a_pile_from_cycle_0_to_the_final_state(tmp_path):
    out = tmp_path / "o"
    done = ballast("run", PILE, "--out", out, *SHORT, "--set", "settings.snapshot_every=200")
    assert done.returncode == 0, done.stderr
    snap = out / "snapshots"
    frames = listed_frames_complete(snap)
    # 750 cycles: frame 0, 200, 400 and 600, then the final state at 750
    assert [(r["frame"], r["cycle"], r["stage"]) for r in frames] == [
        ("0", "0", "ramp"), ("1", "200", "ramp"), ("2", "400", "relax"), ("3", "600", "relax"),
        ("4", "750", "relax")]
    assert float(frames[0]["time"]) == 0
    series = rows(out / "series.tsv")
    assert frames[-1]["time"] == series[-1]["time"]  # the same %.17g of the same double
    assert sorted(p.name for p in snap.iterdir() if p.name.endswith(".tmp")) == []
    assert len(list(snap.iterdir())) == 1 + 3 * 5
    for part in ("contacts", "walls"):
        assert (snap / f"{part}.000004.tsv").read_bytes() == (out / f"{part}.tsv").read_bytes()
    final, last = rows(out / "discs.tsv"), rows(snap / "discs.000004.tsv")
    assert len(final) == len(last) == 51
    assert [[r[c] for c in DISC_COLUMNS] for r in last] == [[r[c] for c in DISC_COLUMNS]
                                                             for r in final]
    assert {(r["generator"], r["index"]) for r in last} == {("p", str(k)) for k in range(51)}
    assert len(rows(snap / "contacts.000004.tsv")) > 51  # a pile under gravity touches


@needs_ballast
def test_a_failed_run_leaves_no_snapshots(tmp_path):
    scene = tmp_path / "unstable.scene"
    scene.write_text(UNSTABLE)
    out = tmp_path / "o"
    done = ballast("run", scene, "--out", out)
    assert done.returncode == 1, done.stderr
    assert "not finite" in done.stderr
    assert sorted(p.name for p in out.iterdir()) == ["run.json"]


@needs_ballast
def test_a_full_disk_leaves_no_snapshot_and_no_temporary_file(full_disk):
    out = full_disk / "o"
    done = ballast("run", PILE, "--out", out, *SHORT, "--set", "settings.snapshot_every=1")
    assert done.returncode == 3, done.stderr
    assert "No space left on device" in done.stderr or "write failed" in done.stderr
    assert sorted(p.name for p in out.iterdir()) in (["run.json"], [])


@needs_ballast
def test_an_interrupted_run_keeps_the_frames_so_far(tmp_path):
    out = tmp_path / "o"
    proc = subprocess.Popen([str(BALLAST), "run", str(PILE), "--out", str(out),
                             "--set", "stage.relax.cycles=100000000", "--set", "stage.relax.stop_ke=0",
                             "--set", "settings.snapshot_every=500"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    index = out / "snapshots" / "index.tsv"
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            if index.is_file() and len(index.read_text().splitlines()) >= 4:
                break
            time.sleep(0.05)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err
    frames = listed_frames_complete(out / "snapshots")
    assert len(frames) >= 3
    assert [int(r["cycle"]) for r in frames] == [500 * k for k in range(len(frames))]
    assert sorted(p.name for p in (out / "snapshots").iterdir() if p.name.endswith(".tmp")) == []
    assert (out / "series.tsv").is_file() and not (out / "discs.tsv").exists()


@needs_ballast
def test_a_new_run_removes_the_earlier_snapshots(tmp_path):
    out = tmp_path / "o"
    assert ballast("run", PILE, "--out", out, *SHORT, "--set",
                   "settings.snapshot_every=300").returncode == 0
    assert (out / "snapshots" / "discs.000003.tsv").is_file()
    assert ballast("run", PILE, "--out", out, *SHORT).returncode == 0
    assert not (out / "snapshots").exists()
