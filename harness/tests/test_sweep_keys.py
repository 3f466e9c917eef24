"""`harness sweep` and the declared sweeps against careless grids (issue 29, item 14), on the
real bin/ballast and the real two_discs case (its scene gives dt = 0.01).

Every point is read by the core (`ballast info` with all its overrides) before any runs: a
key the core does not know, or a value out of its range, is refused with exit 2 and the
core's message, and nothing is run or written -- before, `--set settings.dtt=1,2` ran both
points, each failing at once, and left their folders.  So is a grid that sweeps a key another
key makes unused (settings.dt > 0 makes settings.dt_fraction unused; the core's table says
which, test_unused_keys.py tries each of its rules): its points would be the same run under
different labels, a curve of a parameter that does nothing.
"""
import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
BIN = REPO / "bin" / "ballast"
pytestmark = pytest.mark.skipif(not BIN.exists(), reason="bin/ballast not built")


def harness(reports, *args, cases=None, reference=None):
    env = {**os.environ, "BALLAST_REPORTS": str(reports), "PYTHONPATH": str(REPO)}
    for var in ("BALLAST_CASES", "BALLAST_REFERENCE", "BALLAST_BIN"):
        env.pop(var, None)
    if cases:
        env.update(BALLAST_CASES=str(cases), BALLAST_REFERENCE=str(reference))
    return subprocess.run([sys.executable, "-m", "harness", *args], cwd=REPO, env=env, capture_output=True,
                          text=True, timeout=300)


def sweep(reports, *sets):
    return harness(reports, "sweep", "two_discs", "--variant", "undamped", *[a for s in sets for a in ("--set", s)])


@pytest.mark.parametrize("sets, words", [
    (["settings.dtt=1,2"], ["sweep point settings.dtt=1:", "--set dtt: unknown key in [settings]"]),
    (["settings.alpha=0,-1"], ["sweep point settings.alpha=-1:", "--set alpha: -1 is out of range"]),
    (["settings.dt_fraction=0.05,0.1"],
     ["sweep point settings.dt_fraction=0.05: settings.dt_fraction is unused there (settings.dt > 0 sets the step)"]),
    (["settings.dt=0,0.005", "settings.dt_fraction=0.05,0.1"],
     ["sweep point settings.dt=0.005,settings.dt_fraction=0.05: settings.dt_fraction is unused there"]),
])
def test_a_bad_grid_is_refused_before_any_run(tmp_path, sets, words):
    done = sweep(tmp_path, *sets)
    assert done.returncode == 2, done.stdout + done.stderr
    for w in words:
        assert w in done.stderr
    assert not (tmp_path / "sweeps").exists() and not (tmp_path / "runs").exists()   # nothing ran


def test_a_grid_where_the_key_is_used_runs(tmp_path):
    """settings.dt = 0: dt_fraction sets the step, and its two points are two runs."""
    done = sweep(tmp_path, "settings.dt=0", "settings.dt_fraction=0.05,0.1")
    assert done.returncode == 0, done.stdout + done.stderr
    for label in ("settings.dt=0,settings.dt_fraction=0.05", "settings.dt=0,settings.dt_fraction=0.1"):
        assert (tmp_path / "sweeps" / "two_discs" / label / "run.json").is_file()


CASE = """[case t]
tier = quick
title = two discs with a declared sweep
checks = none
runtime = 1

[variant v]
scene = {scene}

[sweep s]
variant = v
keys = {key}
factors = 2
error = last(Ek)
"""


@pytest.mark.parametrize("key, words", [
    ("settings.dt_fraction=0.1", "sweep point t/s_x2: settings.dt_fraction is unused there"),
    ("settings.dtt=0.1", "sweep point t/s_x2: ballast refuses its overrides (exit 2)"),
])
def test_a_declared_sweep_is_read_by_the_core_before_it_runs(tmp_path, key, words):
    cases, reference = tmp_path / "cases", tmp_path / "reference"
    (cases / "t").mkdir(parents=True)
    reference.mkdir()
    (cases / "t" / "case.txt").write_text(CASE.format(scene=REPO / "cases" / "two_discs" / "two_discs.scene",
                                                      key=key))
    done = harness(tmp_path / "reports", "cost", "t", cases=cases, reference=reference)
    assert done.returncode == 2, done.stdout + done.stderr
    assert words in done.stderr
    assert not (tmp_path / "reports" / "sweeps").exists()
