"""`harness study SCENE --set ...` (issue 31, item 1, Sweeps) and the coupled form
`--set K1,K2=V1,V2` of sweep_grid.parse_sets, shared with `harness sweep CASE`.

On a two-disc collision outside the repository whose discs have two materials: a coupled axis
sets both materials' kn at each point (run.json echoes the overrides, and the contact duration
follows the linear closed form pi sqrt(m12/k) of the coupled stiffness, computed here), a grid
of two axes runs every point, a bad grid is refused with exit 2 before any run, and the study
writes only its own folder."""
import json
import re
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

from harness import sweep_grid
from harness.errors import CatalogueError
from harness.tests.test_study import COLLISION, GAP, M12, page_block

REPO = Path(__file__).resolve().parents[2]
BIN = REPO / "bin" / "ballast"
pytestmark = pytest.mark.skipif(not BIN.exists(), reason="bin/ballast not built")
KN = (5000, 7000, 9000)
# Disc b of its own material: a pair of two materials combines their kn, so moving one of them
# alone would give another stiffness than the value swept.
TWO_MATERIALS = COLLISION.format(dt=2 ** -12, nu=1, kn=7000, gamma=0, time=0.125).replace(
    "material = disc\nv = -0.75 0", "material = other\nv = -0.75 0").replace(
    "[disc a]", "[material other]\nkn = 7000\ndensity = 1\n\n[disc a]")


def harness(args, reports):
    env = {**os.environ, "BALLAST_REPORTS": str(reports), "PYTHONPATH": str(REPO)}
    for var in ("BALLAST_CASES", "BALLAST_REFERENCE", "BALLAST_BIN"):
        env.pop(var, None)
    return subprocess.run([sys.executable, "-m", "harness"] + args, cwd=REPO, env=env, capture_output=True,
                          text=True, timeout=300)


def rows(path):
    lines = Path(path).read_text().splitlines()
    return [dict(zip(lines[0].split("\t"), line.split("\t"))) for line in lines[1:]]


@pytest.fixture
def scene(tmp_path):
    path = tmp_path / "pair.scene"
    path.write_text(TWO_MATERIALS)
    return path


def test_a_coupled_axis_sets_both_keys_at_each_point(scene, tmp_path):
    out = tmp_path / "study"
    axis = "material.disc.kn,material.other.kn=" + ",".join(map(str, KN))
    done = harness(["study", str(scene), "--out", str(out), "-j", "2", "--quantity", GAP, "--set", axis],
                   tmp_path / "reports")
    assert done.returncode == 0, done.stdout + done.stderr
    table = rows(out / "sweep.tsv")
    assert [r["point"] for r in table] == ["P1", "P2", "P3"]
    for i, kn in enumerate(KN):
        sets = json.loads((out / "points" / f"P{i + 1}" / "run.json").read_text())["sets"]
        assert f"material.disc.kn={kn}" in sets and f"material.other.kn={kn}" in sets
        # both materials at kn: the linear contact lasts pi sqrt(m12/kn) (MLH Sec. 2.1, undamped)
        exact = math.pi * math.sqrt(M12 / kn)
        assert abs(float(table[i]["value"]) - exact) / exact < 1e-2, (kn, table[i]["value"], exact)
    assert table[2]["reference_point"] == "P3" and table[2]["error"] == "0"      # equal cost: the last
    # the printed table: short column names (the axis' key tail), the point's values
    head = done.stdout.splitlines()[[i for i, l in enumerate(done.stdout.splitlines())
                                     if l.startswith("point ")][0]]
    assert head.split() == ["point", "kn", "q1", "status", "particle-steps", "wall", "s", "ref"]
    assert f"q1 = {GAP}" in done.stdout
    assert "kn = material.disc.kn,material.other.kn" in done.stdout
    assert "## Sweep" in (out / "study.md").read_text()


def test_a_grid_of_two_axes_runs_every_point(scene, tmp_path):
    out = tmp_path / "study"
    done = harness(["study", str(scene), "--out", str(out), "-j", "2", "--quantity", GAP,
                    "--set", "material.disc.kn,material.other.kn=5000,9000", "--set", "settings.dt=0.001,0.0005"],
                   tmp_path / "reports")
    assert done.returncode == 0, done.stdout + done.stderr
    expected = [(kn, dt) for kn in (5000, 9000) for dt in ("0.001", "0.0005")]      # first axis slowest
    table = rows(out / "sweep.tsv")
    assert len(table) == 4
    for i, (kn, dt) in enumerate(expected):
        run = json.loads((out / "points" / f"P{i + 1}" / "run.json").read_text())
        assert run["status"] == "ok"
        assert {f"material.disc.kn={kn}", f"material.other.kn={kn}", f"settings.dt={dt}"} <= set(run["sets"])
    # the cost: half the step, twice the steps (the stage keeps its simulated time)
    steps = [int(r["steps"]) for r in table]
    assert steps[1] == pytest.approx(2 * steps[0], abs=2) and steps[3] == pytest.approx(2 * steps[2], abs=2)
    # each point's error is against the costliest point with its values on the other axes
    assert [r["reference_point"] for r in table] == ["P2", "P2", "P4", "P4"]
    assert float(table[0]["error"]) == pytest.approx(abs(float(table[0]["value"]) / float(table[1]["value"]) - 1), rel=1e-5)


@pytest.mark.parametrize("sets, words", [
    (["material.disc.knn,material.other.kn=1,2"], ["sweep point material.disc.knn=1,", "unknown key"]),
    (["material.disc.kn,material.other.kn=7000,-1"], ["sweep point material.disc.kn=-1,", "out of range"]),
    (["settings.dt_fraction=0.05,0.1"], ["settings.dt_fraction is unused there"]),
    (["material.disc.kn,material.disc.kn=1,2"], ["--set material.disc.kn given twice"]),
    (["material.disc.kn=1,2", "settings.dt,material.disc.kn=1"], ["--set material.disc.kn given twice"]),
    (["material/x.kn=1,2"], ["a key holds no '/' or '..'"]),
    (["material.disc.kn=1", "--target", "1e-2"], ["--target: options of the refinement"]),
])
def test_a_bad_grid_is_refused_before_any_run(scene, tmp_path, sets, words):
    out = tmp_path / "study"
    args = ["study", str(scene), "--out", str(out), "--quantity", GAP]
    it = iter(sets)
    for s in it:
        args += [s, next(it)] if s.startswith("--") else ["--set", s]
    done = harness(args, tmp_path / "reports")
    assert done.returncode == 2, done.stdout + done.stderr
    for w in words:
        assert w in done.stderr
    assert not out.exists()                                                   # nothing ran, nothing written
    assert {p.name for p in (tmp_path / "reports").glob("*")} <= {".harness.lock"}


def test_a_sweep_study_writes_only_its_own_folder(scene, tmp_path):
    """The default folder under BALLAST_REPORTS/studies; the repository's reports/ untouched."""
    reports = tmp_path / "reports"
    repo_reports = REPO / "reports"
    before = sorted(str(p) for p in repo_reports.rglob("*")) if repo_reports.is_dir() else []
    done = harness(["study", str(scene), "-j", "2", "--quantity", GAP, "--set", "material.disc.kn=5000,7000"],
                   reports)
    assert done.returncode == 0, done.stdout + done.stderr
    assert (reports / "studies" / "pair-1" / "sweep.tsv").is_file()
    assert {p.name for p in reports.iterdir()} <= {"studies", ".harness.lock"}
    assert (sorted(str(p) for p in repo_reports.rglob("*")) if repo_reports.is_dir() else []) == before


def test_parse_sets_keeps_one_key_and_couples_keys():
    assert sweep_grid.parse_sets(["k=1,2"]) == [("k", ["1", "2"])]
    keyed = sweep_grid.parse_sets(["a, b=1,2", "c=3"])
    assert keyed == [("a,b", ["1", "2"]), ("c", ["3"])]
    assert sweep_grid.swept_keys(keyed) == ["a", "b", "c"]
    assert sweep_grid.grid(keyed) == [("a=1,b=1,c=3", ["a=1", "b=1", "c=3"]),
                                      ("a=2,b=2,c=3", ["a=2", "b=2", "c=3"])]
    for bad in ("a,=1", "=1", "a,b", "a,b=1/2"):
        with pytest.raises(CatalogueError, match="--set needs KEY=V1,V2"):
            sweep_grid.parse_sets([bad])


def test_harness_sweep_takes_a_coupled_axis(tmp_path):
    """`harness sweep` on the catalogue's two_discs: both materials' kn at each point."""
    env = {**os.environ, "BALLAST_REPORTS": str(tmp_path), "PYTHONPATH": str(REPO)}
    for var in ("BALLAST_CASES", "BALLAST_REFERENCE", "BALLAST_BIN"):
        env.pop(var, None)
    done = subprocess.run([sys.executable, "-m", "harness", "sweep", "two_discs", "--variant", "undamped",
                           "--set", "material.disc.kn,material.wall.kn=1e9,2e9"], cwd=REPO, env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode in (0, 1), done.stdout + done.stderr
    for kn in ("1e9", "2e9"):
        label = f"material.disc.kn={kn},material.wall.kn={kn}"
        sets = json.loads((tmp_path / "sweeps" / "two_discs" / label / "run.json").read_text())["sets"]
        assert sets[-2:] == [f"material.disc.kn={kn}", f"material.wall.kn={kn}"]


def test_the_worked_sweep_runs_as_the_page_says(tmp_path):
    """docs/your-scene.md's sweep of the rolling disc, run as written (HOME a temporary folder):
    the table it quotes, the wall-clock seconds masked."""
    text = (REPO / "docs" / "your-scene.md").read_text()
    (tmp_path / "roll").mkdir()
    (tmp_path / "roll" / "roll.scene").write_text(page_block(text, "your-scene"))
    command = page_block(text, "your-scene-sweep-command").strip()
    done = subprocess.run(["sh", "-c", command], cwd=REPO, capture_output=True, text=True, timeout=300,
                          env={**os.environ, "HOME": str(tmp_path), "BALLAST_REPORTS": str(tmp_path / "reports")})
    assert done.returncode == 0, done.stderr

    def masked(lines):      # the wall seconds: the last column but one
        return [line.split()[:-2] + line.split()[-1:] for line in lines if re.match(r"^(point|P\d+) ", line)]
    quoted = page_block(text, "your-scene-sweep-output").splitlines()
    assert len(masked(quoted)) == 7
    assert masked(done.stdout.splitlines()) == masked(quoted), \
        "docs/your-scene.md quotes another sweep table than the study prints: rerun its command, update the page"
    assert (tmp_path / "roll" / "sweep" / "sweep.tsv").is_file()
