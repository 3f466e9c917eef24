"""Interruption and resume (issue 7, item 4).

With the fake core: a run that leaves a file missing or a NAME.tmp behind is a failure, for
the runner and for every reader (load_run); --resume keeps exactly the runs whose folder
holds a complete successful run of the same identity and redoes the rest.

With the real bin/ballast (skipped when it is not built; `make test` builds it): a sweep is
interrupted -- SIGINT to its process group (Ctrl-C) or SIGTERM to the harness alone -- after
two runs finished and while the third runs; no process is left, nothing unfinished reads as
a result; `--resume` redoes only the unfinished runs, and its outputs equal those of an
uninterrupted sweep byte for byte (wall-clock fields aside).  A wrapper around bin/ballast
makes the third run long while BALLAST_TEST_HOLD names it, so the test waits on files
appearing, not on sleeps.
"""
import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from harness.__main__ import main
from harness.errors import RunProblem
from harness.runner import Job, binary_identity, identity, run_all, stale
from harness.tables import load_run
from harness.tests.fakes import default_sigint, tree_snapshot, write_fake_bin
from harness.tests.test_runner import add_sets

REPO = Path(__file__).resolve().parents[2]
BALLAST = REPO / "bin" / "ballast"


def harness_record(folder):
    return json.loads((Path(folder) / "harness.json").read_text())


# ---------------------------------------------------------------- unfinished outputs (fake core)

def test_missing_output_file_is_a_failed_run(project, runs, capsys):
    add_sets(project, "soft", "drop=discs.tsv")
    assert main(["run", "spring", "-j", "1"]) == 1
    out = capsys.readouterr().out
    assert "FAILED spring/soft: exit code 0 but unfinished outputs: discs.tsv missing" in out
    assert not harness_record(runs / "spring" / "soft")["ok"]
    with pytest.raises(RunProblem, match="failed"):
        load_run(runs / "spring" / "soft")
    assert main(["check", "spring"]) == 1


def test_tmp_left_behind_is_a_failed_run(project, runs, capsys):
    add_sets(project, "stiff", "tmp=series.tsv")
    assert main(["run", "spring", "-j", "1"]) == 1
    assert "FAILED spring/stiff: exit code 0 but unfinished outputs: series.tsv.tmp left behind" in \
        capsys.readouterr().out


def test_readers_refuse_unfinished_folders(project, runs, capsys):
    """Even when harness.json says ok (say the folder was touched afterwards), load_run looks."""
    assert main(["run", "spring"]) == 0
    soft, stiff, stiffer = (runs / "spring" / v for v in ("soft", "stiff", "stiffer"))
    (soft / "contacts.tsv.tmp").write_text("half")              # a writer stopped before its rename
    (stiff / "stress.tsv").unlink()                             # a file every run writes, gone
    with pytest.raises(RunProblem, match=r"contacts\.tsv\.tmp left behind"):
        load_run(soft)
    with pytest.raises(RunProblem, match=r"stress\.tsv missing"):
        load_run(stiff)
    load_run(stiffer)
    (stiffer / "harness.json").unlink()                         # no record: the core's files decide
    (stiffer / "run.json.tmp").write_text("{")
    with pytest.raises(RunProblem, match=r"run\.json\.tmp left behind"):
        load_run(stiffer)


def test_interrupted_status_is_never_a_result(project, runs, capsys):
    add_sets(project, "soft", "status=interrupted")
    assert main(["run", "spring"]) == 1
    with pytest.raises(RunProblem, match="status 'interrupted'"):
        load_run(runs / "spring" / "soft")


def test_a_core_that_was_interrupted_stops_the_batch(project, runs, capsys):
    """Ctrl-C reaches the cores too: one ending with 130 means no further run should start,
    even before the harness itself has seen the signal."""
    add_sets(project, "soft", "fail=130")
    assert main(["run", "spring", "-j", "1"]) == 1
    out = capsys.readouterr().out
    assert "FAILED spring/soft: interrupted: exit code 130" in out
    assert out.count("interrupted before it started") == 2
    assert not (runs / "spring" / "stiff").exists() and not (runs / "spring" / "stiffer").exists()


# ---------------------------------------------------------------- resume (fake core)

def test_resume_keeps_complete_runs_untouched(project, runs, capsys):
    assert main(["run", "spring"]) == 0
    before = tree_snapshot(runs)
    capsys.readouterr()
    assert main(["run", "spring", "--resume"]) == 0
    out = capsys.readouterr().out
    assert out.count("done before, kept (--resume)") == 3 and "3 runs: 3 ok (3 kept from before), 0 failed" in out
    assert tree_snapshot(runs) == before                        # not a byte, not an mtime changed
    assert main(["check", "spring"]) == 0


def _redone(project, runs, capsys, change):
    """Run, apply change(), run --resume: the variants run again."""
    assert main(["run", "spring"]) == 0
    change()
    capsys.readouterr()
    main(["run", "spring", "--resume"])
    out = capsys.readouterr().out
    return sorted(v for v in ("soft", "stiff", "stiffer") if f"spring/{v}  done before" not in out)


def test_resume_redoes_a_variant_whose_sets_changed(project, runs, capsys):
    assert _redone(project, runs, capsys, lambda: add_sets(project, "stiff", "n=12")) == ["stiff"]
    assert "12" in (runs / "spring" / "stiff" / "run.json").read_text()


def test_resume_redoes_everything_when_the_scene_text_changes(project, runs, capsys):
    scene = project / "cases" / "springs" / "spring.scene"
    assert _redone(project, runs, capsys, lambda: scene.write_text(scene.read_text() + "# edited\n")) == \
        ["soft", "stiff", "stiffer"]


def test_resume_redoes_everything_when_the_executable_changes(project, runs, capsys):
    fake = project / "bin" / "ballast"
    rebuilt = lambda: fake.write_text(fake.read_text() + "# rebuilt\n")
    assert _redone(project, runs, capsys, rebuilt) == ["soft", "stiff", "stiffer"]


def test_resume_ignores_a_touch_of_the_executable(project, runs, capsys):
    fake = project / "bin" / "ballast"
    assert _redone(project, runs, capsys, lambda: os.utime(fake, (1, 1))) == []


def test_resume_redoes_failed_unrecorded_and_tampered_runs(project, runs, capsys):
    def damage():
        (runs / "spring" / "soft" / "harness.json").unlink()            # stopped before the record
        with open(runs / "spring" / "stiff" / "series.tsv", "a") as f:  # changed after the run
            f.write("11\t1.1\t11\t60.5\n")
        (runs / "spring" / "stiffer" / "discs.tsv.tmp").write_text("x")  # an extra, unfinished file
    assert _redone(project, runs, capsys, damage) == ["soft", "stiff", "stiffer"]
    case_txt = project / "cases" / "springs" / "case.txt"
    original = case_txt.read_text()
    add_sets(project, "soft", "fail=1")
    main(["run", "spring"])
    case_txt.write_text(original)                # the same command line as the failed attempt
    capsys.readouterr()
    assert main(["run", "spring", "--resume"]) == 0
    out = capsys.readouterr().out
    assert "spring/soft  done before" not in out and "spring/stiff  done before" in out


def test_stale_says_why(project, runs, tmp_path):
    scene = project / "cases" / "springs" / "spring.scene"
    binary = project / "bin" / "ballast"
    job = Job("spring", "soft", scene, ["k=1"], tmp_path / "out")
    ident = identity(job, binary, binary_identity(binary))
    assert "no harness.json" in stale(job, ident)
    assert run_all([job], binary, 1, open(os.devnull, "w"))[0].ok
    assert stale(job, ident) == ""
    other = Job("spring", "soft", scene, ["k=2"], tmp_path / "out")
    assert "another command line" in stale(other, identity(other, binary, binary_identity(binary)))


def test_cost_passes_resume_to_the_runner(project, monkeypatch, capsys):
    seen = {}
    monkeypatch.setattr("harness.sweep.run_declared", lambda *a: seen.update(resume=a[-1].keywords["resume"]))
    main(["cost", "spring", "--resume"])
    assert seen == {"resume": True}


# ---------------------------------------------------------------- interrupting the real core

HELD = "settings.dt=0.0025"
VALUES = "settings.dt=0.01,0.005,0.0025,0.002"
LABELS = [f"settings.dt={v}" for v in ("0.01", "0.005", "0.0025", "0.002")]
WRAPPER = """#!/bin/sh
# bin/ballast; while $BALLAST_TEST_HOLD is set, the run whose --out ends in it goes on for
# 4e8 cycles (minutes) without series rows: the run an interrupt catches.
if [ -n "$BALLAST_TEST_HOLD" ]; then
  case "$4" in *"$BALLAST_TEST_HOLD")
    exec "{bin}" "$@" --set settings.output_every=1000000000 --set stage.hold.cycles=400000000;;
  esac
fi
exec "{bin}" "$@"
"""
# run.json fields that hold wall-clock time (everything else must match to the byte)
WALL_CLOCK = [(re.compile(r'"wall_seconds": [^,\n]*'), '"wall_seconds": -'),
              (re.compile(r'"particle_steps_per_s": [^,\n]*'), '"particle_steps_per_s": -'),
              (re.compile(r'"timers": \{[^}]*\}'), '"timers": -')]

needs_ballast = pytest.mark.skipif(not BALLAST.exists(), reason="bin/ballast not built")


def without_wall_clock(run_json):
    text = run_json.decode()
    for pattern, replacement in WALL_CLOCK:
        text, n = pattern.subn(replacement, text)
        assert n == 1, pattern.pattern
    return text


SUMMARY_WALL = re.compile(rb"(ballast run: .*), wall [^ ]+ s,")


def without_summary_clock(stdout):
    """ballast.stdout with the wall-clock time of the core's summary line masked."""
    text, n = SUMMARY_WALL.subn(rb"\1, wall - s,", stdout)
    assert n == (1 if stdout.startswith(b"ballast run: ") else 0), stdout   # `exact` prints none
    return text


def comparable(folder, root):
    """{file: content} of a run folder, wall-clock fields masked, the root replaced by '<root>'."""
    out = {}
    for path in sorted(Path(folder).iterdir()):
        data = path.read_bytes()
        if path.name == "run.json":
            data = without_wall_clock(data)
        elif path.name == "ballast.stdout":
            data = without_summary_clock(data)
        elif path.name == "harness.json":
            record = json.loads(data)
            record.pop("wall_seconds")
            record["outputs"].pop("run.json")           # its digest covers wall_seconds
            record["outputs"].pop("ballast.stdout", None)   # ... and this the summary's wall time
            data = json.dumps(record, sort_keys=True).replace(str(root), "<root>")
        out[path.name] = data
    return out


@pytest.fixture(scope="module")
def wrapper(tmp_path_factory):
    path = tmp_path_factory.mktemp("bin") / "ballast"
    path.write_text(WRAPPER.replace("{bin}", str(BALLAST)))
    path.chmod(0o755)
    return path


def sweep(reports, wrapper, *extra, hold=None):
    env = dict(os.environ, BALLAST_REPORTS=str(reports), PYTHONPATH=str(REPO))
    for var in ("BALLAST_CASES", "BALLAST_REFERENCE", "BALLAST_BIN", "BALLAST_TEST_HOLD"):
        env.pop(var, None)
    if hold:
        env["BALLAST_TEST_HOLD"] = hold
    argv = [sys.executable, "-m", "harness", "sweep", "two_discs", "--variant", "undamped",
            "--set", VALUES, "-j", "1", "--bin", str(wrapper), *extra]
    # SIGINT at its default in the harness (preexec_fn): a shell's background job (`make test &` in
    # a script, nohup) inherits SIGINT ignored, and Python then never raises KeyboardInterrupt.
    return subprocess.Popen(argv, env=env, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, start_new_session=True, preexec_fn=default_sigint)


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory, wrapper):
    reports = tmp_path_factory.mktemp("uninterrupted")
    proc = sweep(reports, wrapper)
    out, _ = proc.communicate(timeout=120)
    assert proc.returncode == 0, out
    return reports


def wait_for(paths, proc, timeout=120.0):
    deadline = time.monotonic() + timeout
    while not all(p.exists() for p in paths):
        assert proc.poll() is None, f"the sweep ended early: {proc.communicate()[0]}"
        assert time.monotonic() < deadline, f"waited {timeout} s for {[str(p) for p in paths]}"
        time.sleep(0.01)


def gone(pgid):
    try:
        os.killpg(pgid, 0)
    except ProcessLookupError:
        return True
    return False


@needs_ballast
@pytest.mark.parametrize("how", ["SIGINT to the process group", "SIGTERM to the harness"])
def test_interrupted_sweep_resumes_to_the_uninterrupted_outputs(how, tmp_path, wrapper, uninterrupted):
    reports = tmp_path / "reports"
    folder = {label: reports / "sweeps" / "two_discs" / label for label in LABELS}
    proc = sweep(reports, wrapper, hold=HELD)
    try:
        # two runs recorded, the third inside its time-step loop (the core has opened series.tsv.tmp)
        wait_for([folder[LABELS[0]] / "harness.json", folder[LABELS[1]] / "harness.json",
                  folder[HELD] / "series.tsv.tmp"], proc)
        if how.startswith("SIGINT"):
            os.killpg(proc.pid, signal.SIGINT)
        else:
            os.kill(proc.pid, signal.SIGTERM)
        out, _ = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert proc.returncode == 130, out
    assert "interrupted: 1 run(s) stopped, 1 not started" in out
    deadline = time.monotonic() + 10                      # the harness waited for its runs: none left
    while not gone(proc.pid):
        assert time.monotonic() < deadline, "a process of the sweep outlived it"
        time.sleep(0.05)

    # Nothing unfinished reads as a result: the held run is recorded as interrupted, the core
    # said so in run.json ("complete": false) and kept only the series.tsv written so far (issue
    # 23: an interrupted run keeps it); the run never started has no folder.
    record = harness_record(folder[HELD])
    assert not record["ok"] and record["cause"].startswith("interrupted: exit code 130")
    held = json.loads((folder[HELD] / "run.json").read_text())
    assert held["status"] == "interrupted" and held["complete"] is False
    assert [p.name for p in folder[HELD].glob("*.tsv*")] == ["series.tsv"]
    rows = (folder[HELD] / "series.tsv").read_text().splitlines()
    assert rows[0].startswith("cycle\t") and all(r.count("\t") == rows[0].count("\t") for r in rows)
    with pytest.raises(RunProblem):
        load_run(folder[HELD])
    assert not folder[LABELS[3]].exists()
    for label in LABELS[:2]:
        load_run(folder[label])
    done_before = {label: tree_snapshot(folder[label]) for label in LABELS[:2]}

    resumed = sweep(reports, wrapper, "--resume")
    out, _ = resumed.communicate(timeout=120)
    assert resumed.returncode == 0, out
    assert "4 runs: 4 ok (2 kept from before), 0 failed" in out
    assert [line.split()[1] for line in out.splitlines() if "done before, kept" in line] == \
        [f"two_discs/{label}" for label in LABELS[:2]]
    for label in LABELS[:2]:
        assert tree_snapshot(folder[label]) == done_before[label]       # kept: not rewritten
    for label in LABELS:
        expected = comparable(uninterrupted / "sweeps" / "two_discs" / label, uninterrupted)
        assert comparable(folder[label], reports) == expected, label
        assert {"series.tsv", "discs.tsv", "contacts.tsv", "walls.tsv", "stress.tsv"} <= set(expected)
