"""An ensemble's realisations run by the harness (issue 22, item 4), with the real bin/ballast.

The test ensemble is harness/tests/ensemble (a tiny seeded packing, eight seeds), copied into
a catalogue of its own:

- whatever -j and whatever order, every realisation's outputs are the same bytes (wall-clock
  fields of run.json and of the core's summary line aside), and realisations of different seeds differ in every file the
  core writes; each realisation's outputs carry its seed (run.json's --set lines,
  harness.json's ensemble and seed);
- the harness killed outright (SIGKILL) in the middle of the ensemble, then `run --resume`:
  every realisation whose harness.json said ok at the kill is kept untouched, the others are
  run again, and the result equals the uninterrupted run's bytes.
"""
import io
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from harness import catalogue
from harness.runner import jobs_for, run_all
from harness.tests.fakes import tree_snapshot
from harness.tests.test_interrupt import comparable, without_summary_clock, without_wall_clock

REPO = Path(__file__).resolve().parents[2]
BALLAST = REPO / "bin" / "ballast"
ENSEMBLE = Path(__file__).resolve().parent / "ensemble"
SEEDS = range(1, 9)
NAMES = [f"pack_s{s}" for s in SEEDS]
CORE_FILES = {"series.tsv", "discs.tsv", "contacts.tsv", "walls.tsv", "stress.tsv", "run.json"}
needs_ballast = pytest.mark.skipif(not BALLAST.exists(), reason="bin/ballast not built")


def catalogue_with_ensemble(root, settle=None):
    """A catalogue of the test ensemble under root/cases (settle: cycles of the settle stage);
    the environment that points the harness at it (reports under root/reports)."""
    folder = root / "cases" / "packing"
    shutil.copytree(ENSEMBLE, folder)
    text = (folder / "case.txt").read_text()
    if settle:
        text += f"set = stage.settle.cycles={settle}\n"
    (folder / "case.txt").write_text(text)
    (root / "reference").mkdir(exist_ok=True)
    return {"BALLAST_CASES": str(root / "cases"), "BALLAST_REFERENCE": str(root / "reference"),
            "BALLAST_BIN": str(BALLAST), "BALLAST_REPORTS": str(root / "reports")}


def harness(env, *argv, **options):
    """`python3 -m harness ARGV` in a session of its own, pointed at env's catalogue."""
    return subprocess.Popen([sys.executable, "-m", "harness", *argv], cwd=REPO,
                            env={**os.environ, **env, "PYTHONPATH": str(REPO)}, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True, **options)


def finish(proc, timeout=300):
    out, _ = proc.communicate(timeout=timeout)
    return proc.returncode, out


def outputs(folder):
    """{file: bytes} of a run folder but harness.json, the wall clocks of run.json and of the
    core's summary line (ballast.stdout) masked."""
    mask = {"run.json": without_wall_clock, "ballast.stdout": without_summary_clock}
    return {p.name: mask.get(p.name, bytes)(p.read_bytes())
            for p in sorted(Path(folder).iterdir()) if p.name != "harness.json"}


@needs_ballast
def test_realisations_are_the_same_bytes_whatever_jobs_and_order_and_carry_their_seed(tmp_path):
    """-j 1 in seed order and -j 2 shuffled, both at once (their runs share the machine)."""
    catalogue_with_ensemble(tmp_path)
    cases = catalogue.load(tmp_path / "cases")
    in_order, shuffled = jobs_for(cases, tmp_path / "one"), jobs_for(cases, tmp_path / "two")
    random.Random(22).shuffle(shuffled)
    assert [j.variant for j in in_order] == NAMES != [j.variant for j in shuffled]
    result = {}
    first = threading.Thread(target=lambda: result.update(one=run_all(in_order, BALLAST, 1, io.StringIO())))
    first.start()
    result["two"] = run_all(shuffled, BALLAST, 2, io.StringIO())
    first.join()
    assert all(o.ok for o in result["one"] + result["two"])
    runs_one, runs_two = tmp_path / "one" / "packing", tmp_path / "two" / "packing"
    for seed, name in zip(SEEDS, NAMES):
        left, right = outputs(runs_one / name), outputs(runs_two / name)
        assert CORE_FILES <= set(left) and left == right, name
        info = json.loads((runs_one / name / "run.json").read_text())
        record = json.loads((runs_one / name / "harness.json").read_text())
        assert info["sets"] == [f"fill.pack.seed={seed}"] and info["status"] == "ok"
        assert (record["ensemble"], record["seed"], record["variant"]) == ("pack", seed, name)
    # the seed matters: no file of the core's final state is the same in two realisations
    for a, b in [(NAMES[0], NAMES[1]), (NAMES[2], NAMES[7])]:
        same = [f for f in CORE_FILES if outputs(runs_one / a)[f] == outputs(runs_one / b)[f]]
        assert not same, f"{a} and {b} share {same}"


HOLD_WRAPPER = """#!/bin/sh
# bin/ballast; while $BALLAST_TEST_HOLD is set, the run whose --out ends in it goes on for
# 4e8 cycles (minutes) without series rows: a realisation still running when the harness dies.
if [ -n "$BALLAST_TEST_HOLD" ]; then
  case "$4" in *"$BALLAST_TEST_HOLD")
    exec "{bin}" "$@" --set settings.output_every=1000000000 --set stage.settle.cycles=400000000;;
  esac
fi
exec "{bin}" "$@"
"""
HELD = "pack_s2"      # -j 2 in seed order: the other thread finishes s1, s3, s4, ... meanwhile


def alive_in_group(pgid):
    """pids of the live processes (zombies aside: no subreaper may reap them here) of the
    process group pgid."""
    alive = []
    for entry in Path("/proc").iterdir():
        try:
            if entry.name.isdigit():
                fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
                if int(fields[2]) == pgid and fields[0] not in "ZX":
                    alive.append(int(entry.name))
        except (OSError, IndexError, ValueError):
            pass
    return alive


def wait_for(condition, what, proc=None, limit=300):
    """Poll condition() until it holds: an event, not a time, ends the wait; limit only
    bounds a test that would otherwise hang, and proc (the harness) must not end first."""
    deadline = time.monotonic() + limit
    while not condition():
        assert proc is None or proc.poll() is None, proc.communicate()[0]
        assert time.monotonic() < deadline, f"{what}: not after {limit} s"
        time.sleep(0.01)


@needs_ballast
def test_an_ensemble_killed_outright_resumes_without_redoing_finished_realisations(tmp_path):
    """The harness gets SIGKILL once 3 of the 8 realisations (about half a second each) are
    recorded while a fourth, held by a wrapper of the core, is in its time-step loop; its runs
    die with it.  What read as finished then is kept by --resume, byte for byte and mtime for
    mtime; the rest is run again; the end equals an uninterrupted run.  Every wait is on an
    event (issue 29, item 16: the kill used to come at a time, then a 0.3 s sleep stood for
    the runs' death; under load 7-9 the test once failed)."""
    env = catalogue_with_ensemble(tmp_path, settle=100000)
    wrapper = tmp_path / "bin" / "ballast"
    wrapper.parent.mkdir()
    wrapper.write_text(HOLD_WRAPPER.replace("{bin}", str(BALLAST)))
    wrapper.chmod(0o755)
    env["BALLAST_BIN"] = str(wrapper)
    expected = tmp_path / "expected"
    status, out = finish(harness({**env, "BALLAST_REPORTS": str(expected)}, "run", "-j", "2"))
    assert status == 0, out

    reports = tmp_path / "reports"
    runs = reports / "runs" / "packing"
    proc = harness({**env, "BALLAST_TEST_HOLD": HELD}, "run", "-j", "2")
    try:
        wait_for(lambda: sum((runs / n / "harness.json").exists() for n in NAMES) >= 3 and
                 (runs / HELD / "series.tsv.tmp").exists(), "3 realisations recorded, the held one running", proc)
        assert alive_in_group(proc.pid)                  # the harness and its runs are alive
        proc.send_signal(signal.SIGKILL)
        proc.communicate()
        wait_for(lambda: not alive_in_group(proc.pid), "its runs die with it (PDEATHSIG)")
    finally:
        if alive_in_group(proc.pid):
            os.killpg(proc.pid, signal.SIGKILL)
    finished = [n for n in NAMES if (runs / n / "harness.json").exists()
                and json.loads((runs / n / "harness.json").read_text())["ok"]]
    unfinished = [n for n in NAMES if n not in finished]
    assert 3 <= len(finished) < len(NAMES) and HELD in unfinished, finished
    assert (runs / HELD).exists() and not (runs / HELD / "run.json").exists()   # killed in its loop
    before = {n: tree_snapshot(runs / n) for n in finished}

    status, out = finish(harness(env, "run", "-j", "2", "--resume"))
    assert status == 0, out
    assert f"8 runs: 8 ok ({len(finished)} kept from before), 0 failed" in out
    assert sorted(l.split()[1] for l in out.splitlines() if "done before, kept" in l) == \
        sorted(f"packing/{n}" for n in finished)
    for n in finished:
        assert tree_snapshot(runs / n) == before[n], n
    for n in NAMES:
        assert comparable(runs / n, reports) == comparable(expected / "runs" / "packing" / n, expected), n
    assert not list(reports.rglob("*.tmp"))


def test_a_long_ensemble_shows_rate_and_time_left(tmp_path, monkeypatch, capsys):
    """80 realisations (more than LONG_BATCH) through the command line: status lines with the
    rate and time left, not 80 lines (the fake core)."""
    from harness.__main__ import main
    from harness.tests.fakes import env_for, make_project
    root = make_project(tmp_path / "project")
    for key, value in env_for(root).items():
        monkeypatch.setenv(key, value)
    path = root / "cases" / "springs" / "case.txt"
    path.write_text(path.read_text() + "\n[ensemble k]\nscene = spring.scene\nset = k={seed}\nseeds = 1-80\n")
    assert main(["run", "spring", "-j", "2"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("[1/83] 1 %  ") and " left" in lines[0] and "runs/" in lines[0]
    assert lines[-2].startswith("[83/83] 100 %  ") and " 0 s left" in lines[-2]
    assert lines[-1].startswith("83 runs: 83 ok, 0 failed (") and "runs/min)" in lines[-1]
    assert len(lines) < 10
