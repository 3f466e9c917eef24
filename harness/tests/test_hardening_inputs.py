"""Hardening, round three (issue 29, items 1-3): what the harness takes from an export, a
sweep's command line and the Makefile, and what a run's identity covers.

1. Every path the harness takes from an export folder's manifest (a job's case and variant,
   which name its folder DIR/runs/<case>/<variant>; its scene) or from `sweep --set KEY=...`
   (KEY names the point's folder) stays where it belongs: a manifest that names anything
   else is refused whole, exit 2, nothing run, written or gathered.
2. A run's identity covers every file the run reads: `bin/ballast inputs` lists them (the
   scene and the files its [import] sections name, as the core resolves them) and the
   harness hashes them; `--resume` reruns a run whose imported file changed, and `job` and
   `gather` refuse a job whose inputs differ from what the export recorded.
3. `make validate RESUME=...` resumes for 1 or yes only, runs everything for 0, no or
   nothing, and refuses anything else.

Each test says what an attacker or a careless edit did before it.  Item 1 and the harness
side of item 2 use the fake core of fakes.py (fast); the core's `inputs` and the runs of
an imported scene use the real bin/ballast.
"""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from harness import runner
from harness.__main__ import main
from harness.errors import IniError
from harness.ini import parse
from harness.tests.fakes import tree_snapshot

REPO = Path(__file__).resolve().parents[2]
BALLAST = REPO / "bin" / "ballast"
needs_ballast = pytest.mark.skipif(not BALLAST.exists(), reason="bin/ballast not built")


def snapshot(*roots):
    """tree_snapshot of each root that exists (None for one that does not)."""
    return [tree_snapshot(r) if r.exists() else None for r in roots]


# ---------------------------------------------------------------- 1. paths from an export

@pytest.fixture
def exported(project, tmp_path):
    """The fake project's case 'spring' exported to tmp_path/shared/export, job 0 (soft) run:
    (the export folder, a victim folder beside it holding a file)."""
    folder = tmp_path / "shared" / "export"
    assert main(["export", "spring", "--to", str(folder)]) == 0
    assert main(["job", str(folder), "0"]) == 0
    assert (folder / "runs" / "spring" / "soft" / "harness.json").is_file()
    victim = tmp_path / "shared" / "victim"
    victim.mkdir()
    (victim / "precious.txt").write_text("not the harness's\n")
    return folder, victim


def edit_manifest(folder, index, **fields):
    path = folder / "manifest.json"
    manifest = json.loads(path.read_text())
    manifest["jobs"][index].update(fields)
    path.write_text(json.dumps(manifest))


@pytest.mark.parametrize("field, value", [
    # Before: the job's folder was DIR/runs/<case>/<variant> as written, emptied first, then run in.
    ("case", "../../victim"),      # emptied tmp/shared/victim (outside DIR) and ran there
    ("variant", ".."),             # DIR/runs/spring/..: wiped DIR/runs, every finished run with it
    ("variant", "."),              # DIR/runs/spring: wiped every run of the case
    ("case", ""),                  # likewise
    ("case", "spring/soft"),       # wrote into the folder of another job's finished run
    ("variant", "VICTIM"),         # an absolute path: Path / '/abs' is '/abs', so it ran in the victim folder
    ("variant", 7),                # not a name at all: a TypeError, not a refusal
    ("variant", "soft"),           # two jobs, one folder: job 1 replaced job 0's finished run
    ("command", "sh"),             # a command no case.txt can give: the folder was emptied, then the run failed
    ("ensemble", "../e"),          # not a name a case.txt can give, so not an export's
])
def test_job_and_gather_refuse_a_manifest_whose_names_leave_the_job_folder(exported, capsys, field, value):
    folder, victim = exported
    value = str(victim) if value == "VICTIM" else value
    edit_manifest(folder, 1, **{field: value})
    reports = Path(os.environ["BALLAST_REPORTS"]) / "runs"       # (gather takes the folder's lock file)
    before = snapshot(folder, victim, reports)
    capsys.readouterr()
    assert main(["job", str(folder), "1"]) == 2
    err = capsys.readouterr().err
    assert "manifest.json: job 1: " in err and "refused, nothing run or written" in err, err
    assert main(["job", str(folder), "0"]) == 2          # a tampered manifest runs no job at all
    assert main(["gather", str(folder)]) == 2            # nor gives any run to gather
    assert snapshot(folder, victim, reports) == before


def test_job_and_gather_refuse_a_symbolic_link_under_the_runs_folder(exported, capsys):
    # Before: DIR/runs/spring -> VICTIM made `job` empty VICTIM/stiff and run there, and made
    # `gather` copy whatever the link led to into reports/runs.
    folder, victim = exported
    shutil.rmtree(folder / "runs" / "spring")
    (folder / "runs" / "spring").symlink_to(victim)
    reports = Path(os.environ["BALLAST_REPORTS"]) / "runs"
    before = snapshot(victim, reports)
    capsys.readouterr()
    assert main(["job", str(folder), "1"]) == 2
    assert "is a symbolic link, or lies under one" in capsys.readouterr().err
    assert main(["gather", str(folder)]) == 2
    assert snapshot(victim, reports) == before


def test_gather_refuses_a_run_folder_holding_a_symbolic_link(exported, tmp_path, capsys):
    # Before: a run folder's discs.tsv -> a private file was read and copied into reports/runs.
    folder, victim = exported
    soft = folder / "runs" / "spring" / "soft"
    (soft / "discs.tsv").unlink()
    (soft / "discs.tsv").symlink_to(victim / "precious.txt")
    record = json.loads((soft / "harness.json").read_text())       # the digests made to agree
    record["outputs"] = runner.output_digests(soft)
    (soft / "harness.json").write_text(json.dumps(record))
    capsys.readouterr()
    assert main(["gather", str(folder)]) == 1
    assert "NOT GATHERED spring/soft: its folder holds a symbolic link" in capsys.readouterr().out
    assert not (Path(os.environ["BALLAST_REPORTS"]) / "runs" / "spring" / "soft").exists()


def test_job_refuses_a_scene_that_is_not_a_regular_file_at_once(exported, tmp_path):
    # Before: a FIFO as the job's scene blocked `job` forever (hashing it, then the core reading it).
    folder, _ = exported
    fifo = tmp_path / "scene.fifo"
    os.mkfifo(fifo)
    manifest = json.loads((folder / "manifest.json").read_text())
    recorded = {"inputs": {str(fifo): "0" * 64}} if "inputs" in manifest["jobs"][1] else {}
    edit_manifest(folder, 1, scene=str(fifo), **recorded)
    done = subprocess.run([sys.executable, "-m", "harness", "job", str(folder), "1"], cwd=REPO,
                          env={**os.environ, "PYTHONPATH": str(REPO)}, capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 2, done.stderr
    assert f"its scene {fifo} is not a regular file" in done.stderr
    assert not (folder / "runs" / "spring" / "stiff").exists()


def test_job_refuses_a_scene_edited_since_the_export(exported, project, capsys):
    # Before: `job` ran whatever the scene held now; gather refused it only later.
    folder, _ = exported
    scene = project / "cases" / "springs" / "spring.scene"
    scene.write_text(scene.read_text() + "n = 12\n")
    capsys.readouterr()
    assert main(["job", str(folder), "1"]) == 2
    assert f"an input changed since: {scene}, against what the export recorded" in capsys.readouterr().err
    assert not (folder / "runs" / "spring" / "stiff").exists()


@pytest.mark.parametrize("option", ["x/../../escaped=1", "settings..dt=1,2", "../x=1"])
def test_sweep_refuses_a_key_that_names_another_folder(project, capsys, option):
    # Before: `sweep --set 'x/../../escaped=1'` put its point's run in reports/sweeps/escaped=1.
    assert main(["sweep", "spring", "--variant", "soft", "--set", option]) == 2
    assert "a key holds no '/' or '..'" in capsys.readouterr().err
    assert not list(project.rglob("*escaped*")) and not (project / "reports" / "sweeps").exists()


@pytest.mark.parametrize("header", ["[case ../x]", "[variant ..]", "[ensemble .e]", "[case a/b]", "[variant -x]"])
def test_catalogue_names_are_never_paths(header):
    # A guard, not a fix (this already held): case, variant, ensemble and probe names become
    # folders under reports/, and export.py holds a manifest's names to this same rule
    # (ini.NAME); were it loosened, `[variant ..]` would wipe reports/runs/<case>.
    with pytest.raises(IniError, match="malformed section header"):
        parse(header + "\n", "case.txt")


# ---------------------------------------------------------------- 2. what a run reads

SCENE = """# two imported discs over an imported floor
[settings]
gravity = 0 -9.81

[material grain]
kn = 1e6
ks = 1e6
density = 1000

[import pair]
discs = data/discs.tsv
walls = data/walls.tsv
material = grain
wall_material = grain

[stage fall]
cycles = 200
"""
DISCS = "x\ty\tr\ttheta\n0\t1\t1\t0\n3\t1.5\t1\t0\n"
MOVED = "x\ty\tr\ttheta\n0\t1\t1\t0\n3\t2.5\t1\t0\n"     # the second disc higher
WALLS = "name\tax\tay\tbx\tby\nfloor\t-10\t0\t10\t0\n"
CASE = """[case dropping]
tier = quick
title = imported discs
checks = none
runtime = 1

[variant pair]
scene = drop.scene
"""


def write_scene(folder):
    """drop.scene and its data files in folder; the path of its discs file."""
    (folder / "data").mkdir(parents=True)
    (folder / "drop.scene").write_text(SCENE)
    (folder / "data" / "discs.tsv").write_text(DISCS)
    (folder / "data" / "walls.tsv").write_text(WALLS)
    return folder / "data" / "discs.tsv"


@pytest.fixture
def imported(tmp_path, monkeypatch):
    """A catalogue of one case whose scene imports data/discs.tsv and data/walls.tsv, the
    harness pointed at it with the real core: the discs file's path."""
    discs = write_scene(tmp_path / "cases" / "dropping")
    (tmp_path / "cases" / "dropping" / "case.txt").write_text(CASE)
    (tmp_path / "reference").mkdir()
    for key, value in {"BALLAST_CASES": tmp_path / "cases", "BALLAST_REFERENCE": tmp_path / "reference",
                       "BALLAST_BIN": BALLAST, "BALLAST_REPORTS": tmp_path / "reports"}.items():
        monkeypatch.setenv(key, str(value))
    return discs


def core(*args, cwd):
    return subprocess.run([str(BALLAST), *map(str, args)], cwd=cwd, capture_output=True, text=True, timeout=60)


@needs_ballast
def test_inputs_lists_every_file_a_run_opens_as_the_run_opens_it(tmp_path):
    # Before: no such command; the harness hashed the scene's text only, blind to its imports.
    write_scene(tmp_path / "s")
    other = tmp_path / "other.tsv"
    other.write_text(DISCS)
    cases = [  # (cwd, arguments, the paths expected)
        (tmp_path / "s", ["drop.scene"], ["drop.scene", "data/discs.tsv", "data/walls.tsv"]),
        (tmp_path, ["s/drop.scene"], ["s/drop.scene", "s/data/discs.tsv", "s/data/walls.tsv"]),
        (REPO, [tmp_path / "s" / "drop.scene", "--set", f"import.pair.discs={other}"],
         [str(tmp_path / "s" / "drop.scene"), str(other), str(tmp_path / "s" / "data" / "walls.tsv")]),
        (tmp_path, ["s/drop.scene", "--set", "import.pair.discs=../other.tsv"],
         ["s/drop.scene", "s/../other.tsv", "s/data/walls.tsv"]),
    ]
    for cwd, args, expected in cases:
        done = core("inputs", *args, cwd=cwd)
        assert (done.returncode, done.stdout.splitlines(), done.stderr) == (0, expected, ""), args
        for path in expected[1:]:     # the path printed is the one the core opens: its error names it
            file = Path(cwd) / path
            good = file.read_text()
            file.write_text("no columns\n1\n")
            try:
                info = core("info", *args, cwd=cwd)
                assert info.returncode == 2 and f": {path}:1: " in info.stderr, (args, path, info.stderr)
            finally:
                file.write_text(good)
    missing = core("inputs", "drop.scene", "--set", "import.pair.discs=nothing.tsv", cwd=tmp_path / "s")
    info = core("info", "drop.scene", "--set", "import.pair.discs=nothing.tsv", cwd=tmp_path / "s")
    assert missing.returncode == info.returncode == 2 and missing.stdout == ""
    assert missing.stderr == info.stderr and "nothing.tsv" in missing.stderr
    assert core("inputs", "drop.scene", "--set", "settings.nokey=1", cwd=tmp_path / "s").returncode == 2
    (tmp_path / "s" / "two\nlines.tsv").write_text(DISCS)          # a path one line cannot hold
    split = core("inputs", "drop.scene", "--set", "import.pair.discs=two\nlines.tsv", cwd=tmp_path / "s")
    assert (split.returncode, split.stdout) == (2, "") and "a path with a line break" in split.stderr


@needs_ballast
def test_resume_reruns_a_run_whose_imported_file_changed(imported, capsys):
    # Before: after an edit of the discs.tsv an [import] names, `run --resume` (and `validate
    # --resume`, RESUME=1, which run the same code) kept the stale run as "done before".
    runs = Path(os.environ["BALLAST_REPORTS"]) / "runs" / "dropping" / "pair"
    assert main(["run", "dropping"]) == 0
    first = (runs / "discs.tsv").read_text()
    assert main(["run", "dropping", "--resume"]) == 0
    assert "done before, kept" in capsys.readouterr().out            # unchanged: kept
    imported.write_text(MOVED)
    assert main(["run", "dropping", "--resume"]) == 0
    out = capsys.readouterr().out
    assert "kept" not in out and "1 runs: 1 ok, 0 failed" in out
    assert (runs / "discs.tsv").read_text() != first                 # made from the new file
    scene = imported.parent.parent / "drop.scene"
    record = json.loads((runs / "harness.json").read_text())
    assert set(record["identity"]["inputs"]) == {str(scene), str(imported), str(imported.parent / "walls.tsv")}
    job = runner.Job("dropping", "pair", scene, [], runs)
    imported.write_text(DISCS)                                       # and --resume says which file changed
    assert runner.stale(job, runner.identity(job, BALLAST, runner.binary_identity(BALLAST))) == \
        f"an input changed since: {imported}"


@needs_ballast
def test_job_and_gather_refuse_a_job_whose_inputs_changed_since_the_export(imported, tmp_path, capsys):
    # Before: `job` ran on the edited file, and `gather` took jobs made from the old one (their
    # scene text was unchanged), so reports/runs held runs of a file that is no longer there.
    folder = tmp_path / "shared"
    reports = Path(os.environ["BALLAST_REPORTS"])
    assert main(["export", "dropping", "--to", str(folder)]) == 0
    imported.write_text(MOVED)
    capsys.readouterr()
    assert main(["job", str(folder), "0"]) == 2
    assert f"an input changed since: {imported}, against what the export recorded" in capsys.readouterr().err
    assert not (folder / "runs" / "dropping").exists()
    imported.write_text(DISCS)
    assert main(["job", str(folder), "0"]) == 0
    imported.write_text(MOVED)
    capsys.readouterr()
    assert main(["gather", str(folder)]) == 1
    assert (f"NOT GATHERED dropping/pair: an input changed since: {imported}, against what the export "
            "recorded (export again)") in capsys.readouterr().out
    assert not (reports / "runs").exists()
    imported.write_text(DISCS)                                       # as exported: taken
    assert main(["gather", str(folder)]) == 0
    assert (reports / "runs" / "dropping" / "pair" / "harness.json").is_file()
    manifest = json.loads((folder / "manifest.json").read_text())
    assert set(manifest["jobs"][0]["inputs"]) == {str(imported.parent.parent / "drop.scene"), str(imported),
                                                  str(imported.parent / "walls.tsv")}


COUNTING_CORE = """#!/bin/sh
# `inputs SCENE ...`: logs its call, prints the scene and the file shared.txt beside it
echo "$*" >> "{log}"
echo "$2"
echo "$(dirname "$2")/shared.txt"
"""


def test_a_batch_lists_each_command_line_once_and_hashes_each_file_once(tmp_path, monkeypatch):
    # What keeps the identity cheap for an ensemble of 1000 realisations: one `ballast inputs`
    # per distinct (scene, --set lines), one read of each file however many runs share it.
    log = tmp_path / "calls.log"
    binary = tmp_path / "ballast"
    binary.write_text(COUNTING_CORE.replace("{log}", str(log)))
    binary.chmod(0o755)
    (tmp_path / "a.scene").write_text("a")
    (tmp_path / "shared.txt").write_text("shared")
    hashed = []
    real = runner.sha256_of
    monkeypatch.setattr(runner, "sha256_of", lambda p: hashed.append(str(p)) or real(p))
    inputs = runner.Inputs()
    sets = [["k=1"], ["k=2"], ["k=1"], ["k=2"], ["k=3"]]
    found = [inputs.digests(binary, tmp_path / "a.scene", s) for s in sets]
    assert len(log.read_text().splitlines()) == 3                    # k=1, k=2, k=3
    assert hashed.count(str(tmp_path / "shared.txt")) == 1
    assert found[0] == {str(tmp_path / "a.scene"): real(tmp_path / "a.scene"),
                        str(tmp_path / "shared.txt"): real(tmp_path / "shared.txt")}
    (tmp_path / "shared.txt").write_text("edited")                  # a new version is hashed anew
    os.utime(tmp_path / "shared.txt", ns=(1, 1))
    assert inputs.digests(binary, tmp_path / "a.scene", ["k=1"])[str(tmp_path / "shared.txt")] == \
        real(tmp_path / "shared.txt")


# ---------------------------------------------------------------- 3. RESUME=

@pytest.mark.parametrize("value, resumes", [("", False), ("0", False), ("no", False), ("1", True), ("yes", True),
                                            ("maybe", None), ("true", None), ("0 1", None)])
def test_make_validate_resumes_for_1_or_yes_only(value, resumes):
    # Before: `make validate RESUME=0` resumed ($(if $(RESUME),...) is true for any text), so
    # a user who asked for a fresh validate got the stale runs of the last one.
    env = {k: v for k, v in os.environ.items() if k not in ("RESUME", "MAKEFLAGS", "MAKELEVEL")}
    done = subprocess.run(["make", "-n", "-C", str(REPO), "validate", f"RESUME={value}"], env=env,
                          capture_output=True, text=True, timeout=120)
    if resumes is None:
        assert done.returncode == 2 and f"RESUME={value}: give RESUME=1 or yes to resume" in done.stderr
        assert "harness validate" not in done.stdout
        return
    assert done.returncode == 0, done.stderr
    command = [line for line in done.stdout.splitlines() if "-m harness validate" in line]
    assert len(command) == 1 and ("--resume" in command[0].split()) == resumes, command
