"""`ballast run --threads N` (issue 5, OpenMP) on the real bin/ballast (skipped when it is
not built; `make test` builds it).

The outputs of a run on 2 threads equal those on 1 byte for byte, wall-clock fields aside
(check_threads.c compares the state arrays; this compares what a user gets).  A bad count
is bad input: exit 2, a message naming --threads, and no output folder.
"""
import json
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
BALLAST = REPO / "bin" / "ballast"
DENSE = REPO / "cases" / "bench" / "dense.scene"

needs_ballast = pytest.mark.skipif(not BALLAST.exists(), reason="bin/ballast not built")

# 20 000 discs: about 40 000 candidates from the first cycle on, well above the two ranges
# of 16 chunks of 256 that 2 threads need (check_threads.c asserts the cut itself).
SETS = ["fill.pack.n=20000", "fill.pack.columns=200", "stage.settle.cycles=300",
        "stage.measure.cycles=100"]


def run(out, *extra):
    args = [str(BALLAST), "run", str(DENSE), "--out", str(out)]
    for s in SETS:
        args += ["--set", s]
    return subprocess.run(args + list(extra), capture_output=True, text=True, timeout=300)


def without_clock(run_json, threads):
    data = json.loads(run_json.read_text())
    assert data.pop("threads") == threads
    for key in ("wall_seconds", "particle_steps_per_s", "timers"):
        data.pop(key)
    return data


@needs_ballast
def test_two_threads_write_what_one_writes(tmp_path):
    one, two = tmp_path / "one", tmp_path / "two"
    assert run(one).returncode == 0
    done = run(two, "--threads", "2")
    assert done.returncode == 0, done.stderr
    names = sorted(p.name for p in one.iterdir())
    assert names == sorted(p.name for p in two.iterdir())
    assert "contacts.tsv" in names and "discs.tsv" in names
    assert json.loads((two / "run.json").read_text())["candidates"] > 2 * 16 * 256
    for name in names:
        if name == "run.json":
            assert without_clock(one / name, 1) == without_clock(two / name, 2)
        else:
            assert (one / name).read_bytes() == (two / name).read_bytes(), name


@needs_ballast
@pytest.mark.parametrize("count", ["0", "17", "two", "2x", ""])
def test_bad_thread_count_is_bad_input(tmp_path, count):
    out = tmp_path / "out"
    done = run(out, "--threads", count)
    assert done.returncode == 2
    assert "--threads" in done.stderr
    assert not out.exists()


@needs_ballast
def test_every_command_checks_the_thread_count():
    done = subprocess.run([str(BALLAST), "info", str(DENSE), "--threads", "99"],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    assert "--threads 99" in done.stderr
