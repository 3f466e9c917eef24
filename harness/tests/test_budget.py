"""The budget of a validate (issue 33, item 4; harness/report/budget.py): per case its runs by
kind, particle-steps and run seconds summed over their run.json, its span; a total row; in
budget.json, summary.md and index.html.  A run without run.json is counted, its cost unknown."""
import json
import os

from harness import catalogue
from harness.__main__ import main
from harness.report import budget
from harness.tests.fakes import write_run
from harness.tests.test_compact import project_with_everything


def spring_case(project):
    return [c for c in catalogue.load(project / "cases") if c.name == "spring"]


def harness_json(folder, started, ended, **more):
    """The runner's record of a run that started and ended at these epoch seconds: its
    wall_seconds, and the file's modification time the end (runner._record writes it last)."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "harness.json").write_text(json.dumps({"ok": True, "wall_seconds": ended - started, **more}))
    os.utime(folder / "harness.json", (ended, ended))


def test_totals_are_the_hand_sums_of_the_run_json(project, runs, tmp_path):
    write_run(runs / "spring" / "soft", steps=100, n_discs=3, wall_seconds=1.5)      # 300 particle-steps
    write_run(runs / "spring" / "stiff", steps=40, n_discs=25, wall_seconds=2.25)    # 1000
    write_run(runs / "spring" / "stiffer", steps=7, n_discs=2, wall_seconds=0.125)   # 14
    harness_json(runs / "spring" / "soft", 1000.0, 1001.5)
    harness_json(runs / "spring" / "stiff", 1002.0, 1004.25)
    harness_json(runs / "spring" / "stiffer", 900.0, 900.125)      # before the validate: kept by --resume
    work = tmp_path / "stability-runs"
    write_run(work / "limits" / "spring" / "soft" / "base", steps=10, n_discs=3, wall_seconds=0.5)    # 30
    write_run(work / "limits" / "spring" / "soft" / "trial01", steps=20, n_discs=3, wall_seconds=1.0)  # 60
    write_run(work / "extremes" / "overlap", steps=5, n_discs=4, wall_seconds=0.25)                    # 20
    (work / "extremes" / "refused").mkdir(parents=True)          # no run.json: refused by the core
    harness_json(work / "extremes" / "refused", 1003.0, 1003.0, ok=False)
    tally = budget.stability_costs(work)
    data = budget.budget(spring_case(project), runs, project / "reports" / "sweeps",
                         {"started": 1000.0, "jobs": 2, "tier": "quick", "wall_seconds": 9.0}, tally)
    spring, probes = data["rows"]
    assert (spring["case"], spring["variants"], spring["stability_trials"], spring["runs"]) == ("spring", 3, 2, 5)
    assert spring["particle_steps"] == 300 + 1000 + 14 + 30 + 60
    assert spring["run_seconds"] == 1.5 + 2.25 + 0.125 + 0.5 + 1.0
    assert spring["unknown"] == 0
    # the span: from the first run this validate started (1000.0, soft) to the last end of its runs;
    # stiffer (900) was made before it, and the stability trials have no harness.json here
    assert spring["span_seconds"] == 4.25
    assert probes["case"] == budget.EXTREMES_ROW
    assert (probes["runs"], probes["unknown"], probes["particle_steps"]) == (2, 1, 20)
    total = data["total"]
    assert (total["runs"], total["unknown"], total["particle_steps"]) == (7, 1, 1404 + 20)
    assert total["run_seconds"] == 5.375 + 0.25
    assert total["span_seconds"] == 9.0 and data["validate"]["jobs"] == 2


def test_a_run_without_run_json_is_counted_with_its_cost_unknown(project, runs):
    write_run(runs / "spring" / "soft", steps=100, n_discs=3, wall_seconds=1.5)
    harness_json(runs / "spring" / "stiff", 1.0, 2.0, ok=False, cause="exit code 2")   # failed: no run.json
    (runs / "spring" / "stiffer").mkdir(parents=True)
    (runs / "spring" / "stiffer" / "run.json").write_text("{cut")                       # unreadable
    data = budget.budget(spring_case(project), runs, None)
    row = data["rows"][0]
    assert (row["runs"], row["unknown"], row["particle_steps"], row["run_seconds"]) == (3, 2, 300, 1.5)
    assert row["span_seconds"] is None and data["validate"] is None
    text = "\n".join(budget.markdown_lines(data))
    assert "| spring | quick | 3 | 0 | 0 | 0 | 2 | >= 300 | >= 1.5 | - |" in text
    assert "Not from a validate" in text


def run_json_sums(folders):
    """(runs, particle-steps, seconds) summed over the run.json of folders, by hand."""
    infos = [json.loads((f / "run.json").read_text()) for f in folders]
    return len(infos), sum(i["steps"] * i["n_discs"] for i in infos), sum(i["wall_seconds"] for i in infos)


def test_validate_writes_the_budget_to_budget_json_summary_md_and_index_html(project):
    reports = project_with_everything(project)
    assert main(["validate", "--no-stability", "-j", "2"]) in (0, 1)
    data = json.loads((reports / "budget.json").read_text())
    [row] = data["rows"]
    own = sorted(p for p in (reports / "runs" / "spring").iterdir() if not p.name.startswith("k_s"))
    realisations = sorted((reports / "runs" / "spring").glob("k_s*"))
    points = sorted(p for p in (reports / "sweeps" / "spring").iterdir() if p.is_dir())
    assert (row["variants"], row["realisations"], row["sweep_points"]) == (len(own), 4, len(points)) == (4, 4, 3)
    n, ps, seconds = run_json_sums(own + realisations + points)
    assert (row["runs"], row["particle_steps"]) == (n, ps) and abs(row["run_seconds"] - seconds) < 1e-9
    assert data["total"]["particle_steps"] == ps and data["validate"]["jobs"] == 2
    assert data["validate"]["tier"] == "standard" and data["total"]["span_seconds"] > 0
    assert 0 < row["span_seconds"] <= data["total"]["span_seconds"]
    md = (reports / "summary.md").read_text()
    assert "## Budget (budget.json)" in md
    assert f"| spring | quick | 4 | 4 | {len(points)} | 0 | 0 | {ps:.4g} |" in md
    assert "| **total** |" in md and "-j 2" in md
    assert "<section id=\"budget\">" in (reports / "index.html").read_text()
    # summary.json stays the list of one record per check
    assert isinstance(json.loads((reports / "summary.json").read_text()), list)
    # `report` alone re-renders it from the stored runs, with the last validate's -j and wall time
    assert main(["report"]) == 0
    again = json.loads((reports / "budget.json").read_text())
    assert again["rows"][0]["particle_steps"] == ps and again["validate"]["rerendered"]
    assert again["validate"]["wall_seconds"] == data["validate"]["wall_seconds"]
    assert "Re-rendered by `harness report`" in (reports / "summary.md").read_text()
