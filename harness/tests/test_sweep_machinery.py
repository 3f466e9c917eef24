"""One machinery for sweeping, convergence and cost (issue 31, item 2): `harness study SCENE`,
`harness sweep CASE --set` and the declared [sweep] sections of `harness cost` run their points,
cost them and measure their errors through the same code (harness/points.py,
harness/error_cost.py).

On a two-disc collision outside the repository, held by a private catalogue (BALLAST_CASES,
BALLAST_REFERENCE in a temporary folder) whose one check is the contact duration against the
linear closed form pi sqrt(m12/k) (MLH Sec. 2.1, computed here):

  * the same grid through `study --set` on the bare scene and through `harness sweep CASE --set
    --quantity` gives the same rows: the same status, steps, particle-steps, values, reference
    points and errors;
  * a declared sweep's row equals the study's row of the same point: the same particle-steps
    and the same self-convergence error, also when the points tie in cost (before, the declared
    sweep took the first of a tie as its finest point and the study the last);
  * `harness sweep CASE` draws its checks' errors against particle-steps (before, no figure);
  * a refinement the core refuses writes nothing (before, it made the study's folder first).
"""
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from harness import error_cost, sweep
from harness.tests.test_study import GAP, M12, write_scene
from harness.tests.test_study_sweep import rows

REPO = Path(__file__).resolve().parents[2]
BIN = REPO / "bin" / "ballast"
pytestmark = pytest.mark.skipif(not BIN.exists(), reason="bin/ballast not built")
KN = 7000
DT = 2 ** -12
FACTORS = (2, 4)            # declared around KN; every point has the same step: equal particle-steps
DTS = ("0.00048828125", "0.000244140625")

CASE = """[case pair]
tier = quick
title = two discs head-on, a private catalogue
checks = the contact duration against the linear closed form
runtime = 1

[variant v]
scene = {scene}

[sweep kn]
variant = v
keys = material.disc.kn={kn}
factors = {factors}
checks = none
converge = {gap}
"""

REF = """[check tc]
case = pair
variant = v
quantity = {gap}
value = {tc!r}
tolerance = rel 1e-2
kind = analytic
provenance = MLH Sec. 2.1: t_c = pi sqrt(m12/k), undamped, computed by the test.
"""


def harness(args, tmp_path):
    env = {**os.environ, "PYTHONPATH": str(REPO), "BALLAST_REPORTS": str(tmp_path / "reports"),
           "BALLAST_CASES": str(tmp_path / "cases"), "BALLAST_REFERENCE": str(tmp_path / "reference")}
    env.pop("BALLAST_BIN", None)
    return subprocess.run([sys.executable, "-m", "harness"] + args, cwd=REPO, env=env, capture_output=True,
                          text=True, timeout=300)


@pytest.fixture
def catalogue(tmp_path):
    """The scene in tmp_path/scene, the case and its reference in a private catalogue."""
    (tmp_path / "scene").mkdir()
    scene = write_scene(tmp_path / "scene", 1, KN, 0, DT)
    (tmp_path / "cases" / "pair").mkdir(parents=True)
    (tmp_path / "reference").mkdir()
    (tmp_path / "cases" / "pair" / "case.txt").write_text(
        CASE.format(scene=scene, kn=KN, factors=" ".join(map(str, FACTORS)), gap=GAP))
    (tmp_path / "reference" / "pair.ref").write_text(REF.format(gap=GAP, tc=math.pi * math.sqrt(M12 / KN)))
    return scene


def without_seconds(table):
    return [{k: v for k, v in r.items() if k != "wall_seconds"} for r in table]


def test_study_and_harness_sweep_give_the_same_rows_for_the_same_grid(catalogue, tmp_path):
    grid = ["--set", f"material.disc.kn={KN},{2 * KN}", "--set", f"settings.dt={','.join(DTS)}"]
    studied = harness(["study", str(catalogue), "--out", str(tmp_path / "study"), "-j", "2", "--quantity", GAP]
                      + grid, tmp_path)
    assert studied.returncode == 0, studied.stdout + studied.stderr
    swept = harness(["sweep", "pair", "-j", "2", "--quantity", GAP] + grid, tmp_path)
    assert swept.returncode == 0, swept.stdout + swept.stderr
    study_rows = rows(tmp_path / "study" / "sweep.tsv")
    sweep_rows = rows(tmp_path / "reports" / "sweeps" / "pair" / "quantities_v.tsv")
    assert len(study_rows) == 4 and all(r["status"] == "ok" for r in study_rows)
    assert without_seconds(sweep_rows) == without_seconds(study_rows)
    assert [r["reference_point"] for r in sweep_rows] == ["P2", "P2", "P4", "P4"]
    assert float(sweep_rows[0]["error"]) > 0
    # the case's check is tabulated beside the quantities: the same runs
    assert "tc " in swept.stdout and "(particle-steps)" in swept.stdout


def test_a_declared_sweep_row_equals_the_study_row_of_the_same_point(catalogue, tmp_path):
    """kn x1 (the variant's own run), x2, x4 at one step: three points of equal cost.  The
    declared self-convergence error and the study's error against its reference point are one
    computation, so they agree -- with a tie, both take the last point as the finest."""
    assert harness(["run", "pair"], tmp_path).returncode in (0, 1)
    cost = harness(["cost", "pair", "-j", "2"], tmp_path)
    assert cost.returncode == 0, cost.stdout + cost.stderr
    declared = sweep.read_tsv(tmp_path / "reports" / "sweeps" / "pair" / "cost.tsv")
    assert [r["factor"] for r in declared] == [1.0, 2.0, 4.0]
    studied = harness(["study", str(catalogue), "--out", str(tmp_path / "study"), "-j", "2", "--quantity", GAP,
                       "--set", "material.disc.kn=" + ",".join(str(KN * f) for f in (1,) + FACTORS)], tmp_path)
    assert studied.returncode == 0, studied.stdout + studied.stderr
    study_rows = rows(tmp_path / "study" / "sweep.tsv")
    assert len({r["particle_steps"] for r in study_rows}) == 1                      # a tie in cost
    assert [r["reference_point"] for r in study_rows] == ["P3"] * 3
    for d, s in zip(declared, study_rows):
        assert d["particle_steps"] == int(s["particle_steps"]) and d["steps"] == int(s["steps"])
        if s["reference_point"] == s["point"]:
            assert d["error"] is None and "the finest run" in d["note"], d
        else:
            assert d["error"] == pytest.approx(float(s["error"]), rel=1e-5), (d, s)
            assert d["worst"] == f"vs finest: {GAP}"


def test_the_finest_of_a_tie_is_the_last_point():
    costs = [{"status": "ok", "particle_steps": 64}, {"status": "ok", "particle_steps": 64},
             {"status": "unstable", "particle_steps": 900}]
    assert sweep.finest_index(costs) == 1
    assert error_cost.reference_points([["a"], ["b"], ["c"]], costs) == [1, 1, 1]


@pytest.mark.skipif(not shutil.which("gnuplot"), reason="gnuplot not installed")
def test_harness_sweep_draws_its_checks_error_against_cost(catalogue, tmp_path):
    done = harness(["sweep", "pair", "-j", "2", "--set", f"settings.dt={','.join(DTS)}"], tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    folder = tmp_path / "reports" / "sweeps" / "pair"
    assert (folder / "sweep_v.svg").is_file() and f"wrote {folder / 'sweep_v.svg'}" in done.stdout
    data = (folder / "sweep_v.dat").read_text().split("\n\n\n")[0].splitlines()
    assert data[0] == "# tc"
    table = rows(folder / "sweep_v.tsv")
    # each point: its particle-steps and the check's error against the closed form, as in the table
    drawn = [tuple(map(float, line.split())) for line in data[1:]]
    tabulated = sorted((float(r["particle_steps"]), float(r["error"])) for r in table)
    assert len(drawn) == len(tabulated) == 2
    for (c, e), (tc, te) in zip(drawn, tabulated):
        assert c == tc and e == pytest.approx(te, rel=1e-5)              # the TSV has 6 digits


def test_a_refused_refinement_writes_nothing(catalogue, tmp_path):
    out = tmp_path / "study"
    done = harness(["study", str(catalogue), "--out", str(out), "--refine", "material.disc.knn", "--base", "1"],
                   tmp_path)
    assert done.returncode == 2 and "unknown key" in done.stderr, done.stdout + done.stderr
    assert not out.exists()
