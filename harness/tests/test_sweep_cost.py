"""Error against cost (harness/sweep.py): [sweep] declarations, the error of a run, the
cheapest-setting table, `harness cost` and the report section, on the fake project."""
import re
import os
import shutil
from pathlib import Path

import pytest

from harness import catalogue, references, sweep, sweep_spec
from harness.__main__ import main
from harness.errors import IniError
from harness.ini import parse
from harness.report import cost_plot
from harness.tests.fakes import spring_columns, write_run, write_spring_runs

needs_gnuplot = pytest.mark.skipif(not shutil.which("gnuplot"), reason="gnuplot not installed")

SWEEPS = """
[sweep stiffness]
variant = soft
keys = settings.k=1
factors = 2 0.5
scale = stage.n=10
checks = abs_at2

[sweep length]
variant = stiff
keys = stage.n=10
factors = 2
error = abs(at(F, 1) - 1)
"""


def section(body, name="dt"):
    return parse(f"[sweep {name}]\n{body}", "cases/x/case.txt")[0]


def add_sweeps(project, text=SWEEPS):
    path = project / "cases" / "springs" / "case.txt"
    path.write_text(path.read_text() + text)
    return path


# ---------------------------------------------------------------- declarations

def test_parse_a_full_declaration():
    s = sweep_spec.parse(section("variant = v\nkeys = settings.dt=0.01 stage.a.b=2\nfactors = 0.5 2 4\n"
                            "scale = stage.load.cycles=40\nchecks = c1 c2\nerror = e(1)\nerror = e(2)\n"))
    assert (s.name, s.variant, s.factors) == ("dt", "v", [0.5, 2.0, 4.0])
    assert s.keys == [("settings.dt", 0.01), ("stage.a.b", 2.0)] and s.scale == [("stage.load.cycles", 40.0)]
    assert s.checks == ["c1", "c2"] and s.errors == ["e(1)", "e(2)"]
    assert s.sets(2) == ["settings.dt=0.02", "stage.a.b=4", "stage.load.cycles=20"]
    assert s.sets(0.5) == ["settings.dt=0.005", "stage.a.b=1", "stage.load.cycles=80"]
    assert s.label(0.5) == "dt_x0.5"


@pytest.mark.parametrize("body, message, line", [
    ("variant = v\nfactors = 2\n", "needs 'keys = KEY=DEFAULT", 1),
    ("variant = v\nkeys = settings.dt=0.01\n", "needs 'factors = F1 F2", 1),
    ("variant = v\nkeys = settings.dt=0.01\nfactors = 2 1\n", "factor 1 is the default run", 4),
    ("variant = v\nkeys = settings.dt=0.01\nfactors = 2 x\n", "factor 'x' is not a number", 4),
    ("variant = v\nkeys = settings.dt=0.01\nfactors = 2 -1\n", "must be a positive number", 4),
    ("variant = v\nkeys = settings.dt=0.01\nfactors = 2 2\n", "given twice", 4),
    ("variant = v\nkeys = settings.dt\nfactors = 2\n", "KEY=DEFAULT words", 3),
    ("variant = v\nkeys = settings.dt=abc\nfactors = 2\n", "KEY=DEFAULT words", 3),
    ("variant = v\nkeys = a=1 a=2\nfactors = 2\n", "a given twice", 3),
    ("variant = v\nkeys = a=1\nfactors = 3\nscale = stage.load.cycles=40\n", "is not a whole number", 5),
    ("variant = v\nkeys = a=1\nfactors = 2\nvalues = 1 2\n", "unknown key 'values'", 5),
    ("keys = a=1\nfactors = 2\n", "needs 'variant = ...'", 1),
])
def test_parse_errors_name_file_and_line(body, message, line):
    with pytest.raises(IniError) as err:
        sweep_spec.parse(section(body))
    assert message in str(err.value) and f"case.txt:{line}:" in str(err.value)


def test_catalogue_attaches_sweeps_to_their_case(project):
    add_sweeps(project)
    case = catalogue.select(catalogue.load(), ["spring"])[0]
    assert [s.name for s in case.sweeps] == ["stiffness", "length"]


def test_catalogue_error_from_a_sweep_section_names_its_line(project):
    path = add_sweeps(project, "\n[sweep bad]\nvariant = soft\nkeys = settings.k=1\nfactors = 1\n")
    with pytest.raises(IniError) as err:
        catalogue.load()
    assert f"case.txt:{len(path.read_text().splitlines())}:" in str(err.value)


@pytest.mark.parametrize("text, message", [
    ("\n[sweep s]\nvariant = nope\nkeys = k=1\nfactors = 2\n", "no variant 'nope'"),
    ("\n[sweep s]\nvariant = soft\nkeys = k=1\nfactors = 2\nchecks = nope\n", "no check 'nope'"),
    ("\n[sweep s]\nvariant = soft\nkeys = k=1\nfactors = 2\nchecks = interval_ek\n", "has no point reference"),
    ("\n[sweep s]\nvariant = soft\nkeys = k=1\nfactors = 2\nchecks = regress_mean\n", "kind regression"),
    ("\n[sweep s]\nvariant = soft\nkeys = k=1\nfactors = 2\nchecks = rel_last\n", "evaluated in stiff, not soft"),
    ("\n[sweep s]\nvariant = stiff\nkeys = k=1\nfactors = 2\nchecks = ratio_k\n", "reads the DEM variant(s) soft"),
    ("\n[sweep s]\nvariant = stiffer\nkeys = k=1\nfactors = 2\n", "nothing measures the error"),
    ("\n[sweep s]\nvariant = soft\nkeys = k=1\nfactors = 2\n[sweep s]\nvariant = soft\nkeys = k=1\nfactors = 3\n",
     "defined twice"),
])
def test_validate_against_the_references(project, capsys, text, message):
    add_sweeps(project, text)
    assert main(["list"]) == 0        # list loads the catalogue only
    assert main(["check"]) == 2       # commands that load the references validate the sweeps
    assert message in capsys.readouterr().err


def test_only_run_variants_are_swept(project, capsys):
    path = project / "cases" / "springs" / "case.txt"
    path.write_text(path.read_text() + "\n[variant solved]\nscene = spring.scene\ncommand = exact\n"
                    "\n[sweep s]\nvariant = solved\nkeys = k=1\nfactors = 2\nerror = 1\n")
    assert main(["check"]) == 2
    assert "only DEM runs are swept" in capsys.readouterr().err


def test_eligible_terms_by_default_and_by_name(project):
    add_sweeps(project)
    cases = catalogue.load()
    checks = references.load()
    case = catalogue.select(cases, ["spring"])[0]
    named, left = sweep.terms_of(case.sweeps[0], case, checks)
    assert [c.name for c in named] == ["abs_at2"] and left == []
    every, _ = sweep.terms_of(case.sweeps[1], case, checks)
    # stiff: rel_last counts; ratio_k reads soft (a DEM run) and the trend has no point reference
    assert [c.name for c in every] == ["rel_last"]


# ---------------------------------------------------------------- the error of a run

def test_deviation_is_relative_and_absolute_at_zero():
    assert sweep.deviation(2.2, 2.0) == pytest.approx(0.1)
    assert sweep.deviation(-1.8, -2.0) == pytest.approx(0.1)
    assert sweep.deviation(1e-3, 0.0) == 1e-3


def test_run_error_is_the_largest_term_and_any_failure_is_no_error():
    assert sweep.run_error({"a": 1e-3, "b": 2e-2}) == (2e-2, "b", "")
    assert sweep.run_error({"a": 1e-3, "b": 2e-2}, dropped=["b"]) == (1e-3, "a", "")
    error, worst, note = sweep.run_error({"a": 1e-3, "b": "column 'X' missing"})
    assert error is None and worst == "b" and "column 'X' missing" in note
    assert sweep.run_error({})[0] is None


def _case_and_checks(project):
    add_sweeps(project)
    cases, checks = catalogue.load(), references.load()
    return catalogue.select(cases, ["spring"])[0], checks


def test_swept_run_stands_in_for_its_variant(project, runs, tmp_path):
    case, checks = _case_and_checks(project)
    write_spring_runs(runs)
    swept = write_run(tmp_path / "point", spring_columns(1.1))       # at(F, 2) = 2.2 against 2
    terms, _ = sweep.terms_of(case.sweeps[0], case, checks)
    by_term, read = sweep.term_errors(case, "soft", swept, runs, terms, ["at(F, 2) / 2 - 1"])
    assert by_term["abs_at2"] == pytest.approx(0.1)
    assert by_term["at(F, 2) / 2 - 1"] == pytest.approx(0.1)
    assert read == {"abs_at2": [], "at(F, 2) / 2 - 1": []}


def test_ratio_check_against_the_same_variant_and_zero_reference(project, runs, tmp_path):
    ref = project / "reference" / "springs.ref"
    ref.write_text(ref.read_text() + "\n[check self_ratio]\ncase = spring\nvariant = soft\nquantity = at(F, 4)\n"
                   "other = at(F, 2)\nvalue = 2\ntolerance = ratio 1e-9\nkind = exact\nprovenance = linear\n"
                   "\n[check zero]\ncase = spring\nvariant = soft\nquantity = at(F, 2) - 2 * at(F, 1)\n"
                   "value = 0\ntolerance = abs 1e-9\nkind = analytic\nprovenance = linear\n")
    case, checks = _case_and_checks(project)
    mine = {c.name: c for c in checks}
    point = write_run(tmp_path / "p", {"cycle": [1, 2, 3, 4], "time": [0.1, 0.2, 0.3, 0.4], "F": [1, 2.5, 3, 4.5],
                                       "Ek": [0, 0, 0, 0]})
    by_term, _ = sweep.term_errors(case, "soft", point, runs, [mine["self_ratio"], mine["zero"]], [])
    assert by_term["self_ratio"] == pytest.approx(abs(4.5 / 2.5 - 2) / 2)
    assert by_term["zero"] == pytest.approx(0.5)           # |q - 0|: absolute when the reference is 0


def test_terms_reading_a_dem_sibling_are_dropped_from_the_whole_curve(project, runs):
    case, checks = _case_and_checks(project)
    write_spring_runs(runs)
    case.sweeps[0].errors = ["abs(last(F) / last(series('stiff', 'F')) - 0.5)"]
    sweeps_root = project / "reports" / "sweeps"
    for f in case.sweeps[0].factors:
        write_run(sweeps_root / "spring" / case.sweeps[0].label(f), spring_columns(f), steps=int(10 / f))
    rows = [r for r in sweep.points(case, checks, runs, sweeps_root) if r["sweep"] == "stiffness"]
    assert [r["factor"] for r in rows] == [1.0, 2.0, 0.5]
    assert all("left out (reads a DEM sibling)" in r["note"] and r["worst"] == "abs_at2" for r in rows)
    assert [r["error"] for r in rows] == [0.0, pytest.approx(1.0), pytest.approx(0.5)]
    assert [r["particle_steps"] for r in rows] == [20, 10, 40]


def test_missing_run_gives_no_error_and_says_why(project, runs):
    case, checks = _case_and_checks(project)
    write_spring_runs(runs)
    rows = sweep.points(case, checks, runs, project / "reports" / "sweeps")
    missing = [r for r in rows if r["factor"] != 1.0]
    assert all(r["error"] is None and r["status"].startswith("no run.json") for r in missing)
    assert all(r["note"] for r in missing)


def test_unsettled_stop_rule_is_noted(tmp_path):
    folder = write_run(tmp_path / "r", stages=[{"name": "relax", "stop_rule": True, "stopped": False},
                                               {"name": "load", "stop_rule": False, "stopped": False}])
    assert sweep.run_cost(folder)["unsettled"] == ["relax"]


# ---------------------------------------------------------------- the cheapest-setting table

def row(sweep_name, factor, error, ps, status="ok", wall=1.0):
    return {"sweep": sweep_name, "factor": factor, "sets": "(default)" if factor == 1.0 else f"k={factor}",
            "status": status, "steps": ps,
            "n_discs": 1, "particle_steps": ps, "wall_seconds": wall, "error": error, "worst": "t", "note": ""}


def test_cheapest_setting_per_tolerance():
    rows = [row("dt", 1.0, 5e-4, 100), row("dt", 2.0, 5e-3, 50), row("dt", 4.0, 0.5, 25),
            row("k", 10.0, 5e-5, 400), row("k", 0.1, 1e-6, 20, status="unstable"),
            row("k", 0.5, None, 10), row("tol", 10.0, 5e-4, 100, wall=0.5)]
    table = sweep.cheapest(rows, (1e-2, 1e-3, 1e-4, 1e-7))
    assert table[1e-2]["factor"] == 2.0
    assert table[1e-3]["sweep"] == "tol"                   # same particle-steps as the default: less wall time
    assert table[1e-4]["sweep"] == "k" and table[1e-4]["factor"] == 10.0
    assert table[1e-7] is None                             # the unstable run does not count
    assert sweep.setting(rows[0]) == "default" and sweep.setting(rows[1]) == "dt x2 (k=2.0)"


def test_cost_tsv_round_trip(tmp_path):
    rows = [row("dt", 1.0, 5e-4, 100), row("dt", 2.0, None, None, status="no run.json")]
    rows[1]["note"] = "tab\there"
    path = tmp_path / "s" / "cost.tsv"
    sweep.write_tsv(rows, path)
    back = sweep.read_tsv(path)
    assert back[0] == rows[0]
    assert back[1]["error"] is None and back[1]["particle_steps"] is None and back[1]["note"] == "tab here"
    path.write_text("nope\n")
    with pytest.raises(ValueError):
        sweep.read_tsv(path)


# ---------------------------------------------------------------- the command and the report

def test_cost_command_runs_every_declared_point(project, capsys):
    add_sweeps(project)
    assert main(["run", "spring"]) == 0
    assert main(["cost", "spring", "-j", "2"]) == 0
    out = capsys.readouterr().out
    assert "3 runs: 3 ok" in out and "spring: default error" in out and "error <= 0.01:" in out
    rows = sweep.read_tsv(project / "reports" / "sweeps" / "spring" / "cost.tsv")
    assert [(r["sweep"], r["factor"]) for r in rows] == [("stiffness", 1.0), ("stiffness", 2.0), ("stiffness", 0.5),
                                                         ("length", 1.0), ("length", 2.0)]
    by = {(r["sweep"], r["factor"]): r for r in rows}
    assert by[("stiffness", 2.0)]["sets"] == "settings.k=2 stage.n=5"
    assert by[("stiffness", 2.0)]["error"] == pytest.approx(1.0) and by[("stiffness", 2.0)]["steps"] == 5
    assert by[("length", 2.0)]["error"] == pytest.approx(1.0)     # last(F) = 40 against 20
    assert by[("stiffness", 1.0)]["error"] == 0.0


def test_cost_command_reports_cases_without_sweeps(project, capsys):
    assert main(["cost", "spring"]) == 0
    assert "spring: no [sweep] declared" in capsys.readouterr().out
    assert not (project / "reports" / "sweeps").exists()


def test_validate_runs_the_sweeps_unless_told_not_to(project, capsys):
    add_sweeps(project)
    main(["validate", "spring", "--no-sweeps"])
    assert not (project / "reports" / "sweeps" / "spring" / "cost.tsv").exists()
    main(["validate", "spring"])
    assert (project / "reports" / "sweeps" / "spring" / "cost.tsv").exists()
    capsys.readouterr()


def test_cost_points_mark_the_default_and_note_what_is_not_drawn():
    rows = [row("dt", 1.0, 5e-4, 100), row("dt", 2.0, 5e-3, 50), row("dt", 0.5, 0.0, 200),
            row("k", 1.0, 5e-4, 100), row("k", 3.0, None, 80, status="unstable")]
    curves, defaults, notes, bad = cost_plot.cost_points(rows)
    assert defaults == [(100, 5e-4)]
    assert curves["dt"] == [(100, 5e-4, ""), (50, 5e-3, "x2")] and curves["k"] == [(100, 5e-4, "")]
    assert any("dt x0.5: not drawn: error 0 is not positive" in n for n in notes)
    assert bad == {"k": [(80, "x3 unstable")]}          # drawn at the top, labelled
    assert any("k x3: unstable (drawn at the top" in n for n in notes)


@needs_gnuplot
def test_report_section_draws_the_diagram_and_the_table(project, capsys):
    add_sweeps(project)
    assert main(["run", "spring"]) == 0
    assert main(["cost", "spring"]) == 0
    assert main(["report", "spring"]) == 0
    capsys.readouterr()
    page = (project / "reports" / "index.html").read_text()
    assert "Error against cost" in page and "Cheapest setting meeting each tolerance" in page
    assert (project / "reports" / "figures" / "spring_error_cost_sweep.svg").is_file()
    assert "default tier setting" in (project / "reports" / "figures" / "spring_error_cost_sweep.svg").read_text()
    for tol in ("0.01", "0.001", "0.0001"):
        assert f"<td>{tol}</td>" in page
    assert "<td>default</td>" in page           # the default (error 0) is the cheapest meeting every tolerance
    summary = (project / "reports" / "cases" / "spring.md").read_text()      # the case's page
    assert "**Error against cost**" in summary and "| 0.01 | default |" in summary


def test_report_without_results_says_how_to_get_them(project, capsys):
    add_sweeps(project)
    write_spring_runs(project / "reports" / "runs")
    assert main(["report", "spring"]) == 0
    capsys.readouterr()
    assert "python3 -m harness cost spring" in (project / "reports" / "index.html").read_text()


def test_report_notes_a_cost_table_older_than_the_declarations(project, capsys):
    path = add_sweeps(project)
    assert main(["run", "spring"]) == 0
    assert main(["cost", "spring"]) == 0
    later = (project / "reports" / "sweeps" / "spring" / "cost.tsv").stat().st_mtime + 10
    os.utime(path, (later, later))
    assert main(["report", "spring"]) == 0
    capsys.readouterr()
    assert "cost.tsv is older than case.txt" in (project / "reports" / "index.html").read_text()


# ---------------------------------------------------------------- fixed overrides, failed points, self-convergence

def test_parse_fixed_overrides_make_factor_one_a_point_of_its_own():
    s = sweep_spec.parse(section("variant = v\nset = settings.integrator=gear5\nset = settings.psi=0\n"
                            "keys = settings.dt=0.01\nfactors = 0.5\nchecks = none\nerror = e(1)\n"))
    assert s.fixed == ["settings.integrator=gear5", "settings.psi=0"] and s.no_checks and s.checks == []
    assert s.run_factors() == [1.0, 0.5]
    assert s.sets(1) == ["settings.integrator=gear5", "settings.psi=0", "settings.dt=0.01"]
    assert s.label(1) == "dt_x1"
    plain = sweep_spec.parse(section("variant = v\nkeys = settings.dt=0.01\nfactors = 0.5\n"))
    assert plain.run_factors() == [0.5] and plain.fixed == [] and not plain.no_checks


@pytest.mark.parametrize("body, message, line", [
    ("variant = v\nkeys = a=1\nfactors = 2\nset = settings.integrator\n", "'set' needs KEY=VALUE", 5),
    ("variant = v\nkeys = a=1\nfactors = 2\nset = a=3\n", "a is swept", 5),
    ("variant = v\nkeys = a=1\nfactors = 2\nscale = b=4\nset = b=3\n", "b is swept", 6),
    ("variant = v\nkeys = a=1\nfactors = 2\nset = b=1\nset = b=2\n", "b given twice", 6),
    ("variant = v\nkeys = a=1\nfactors = 2\nchecks = none c1\n", "'checks = none' takes no other name", 5),
])
def test_parse_errors_of_the_new_keys(body, message, line):
    with pytest.raises(IniError) as err:
        sweep_spec.parse(section(body))
    assert message in str(err.value) and f"case.txt:{line}:" in str(err.value)


def test_checks_none_leaves_out_every_check(project, capsys):
    add_sweeps(project, "\n[sweep s]\nvariant = stiff\nkeys = k=1\nfactors = 2\nchecks = none\nerror = 0.5\n")
    cases, checks = catalogue.load(), references.load()
    case = catalogue.select(cases, ["spring"])[0]
    terms, left = sweep.terms_of(case.sweeps[0], case, checks)
    assert terms == [] and left == ["rel_last"]
    add_sweeps(project, "\n[sweep t]\nvariant = stiff\nkeys = k=1\nfactors = 2\nchecks = none\n")
    assert main(["check"]) == 2
    assert "nothing measures the error" in capsys.readouterr().err


FIXED = """
[sweep k_fixed]
variant = soft
set = settings.n=20
keys = settings.k=1
factors = 2
checks = none
error = abs(last(F) / 20 - 1)
"""


def test_a_fixed_sweep_runs_factor_one_and_is_not_the_default(project, capsys):
    add_sweeps(project, FIXED)
    assert main(["run", "spring"]) == 0
    assert main(["cost", "spring"]) == 0
    out = capsys.readouterr().out
    assert "2 runs: 2 ok" in out                      # factor 1 and factor 2, both run by the sweep
    rows = sweep.read_tsv(project / "reports" / "sweeps" / "spring" / "cost.tsv")
    assert [(r["factor"], r["sets"]) for r in rows] == [(1.0, "settings.n=20 settings.k=1"),
                                                        (2.0, "settings.n=20 settings.k=2")]
    assert (project / "reports" / "sweeps" / "spring" / "k_fixed_x1" / "run.json").is_file()
    assert rows[0]["steps"] == 20 and rows[0]["error"] == 0.0 and rows[1]["error"] == pytest.approx(1.0)
    assert not sweep.is_default(rows[0])
    assert sweep.setting(rows[0]) == "k_fixed x1 (settings.n=20 settings.k=1)"
    curves, defaults, _, _ = cost_plot.cost_points(rows)
    assert defaults == [] and curves["k_fixed"] == [(40, pytest.approx(1.0), "x2")]   # error 0 is off the log scale


UNSTABLE = """
[sweep blows_up]
variant = soft
set = settings.status=unstable
keys = settings.k=1
factors = 2
error = abs(last(F) - 10)

[sweep no_output]
variant = soft
set = settings.fail=1
keys = settings.k=1
factors = 2
error = abs(last(F) - 10)
"""


def test_failed_points_have_no_error_and_say_why(project, capsys):
    add_sweeps(project, UNSTABLE)
    assert main(["run", "spring"]) == 0
    assert main(["cost", "spring"]) == 0
    out = capsys.readouterr().out
    # Issue 23: a point past its limit is a measurement, said as one; a run without output fails
    assert "LIMIT spring/blows_up_x2: past its stability limit" in out and "FAILED spring/blows_up" not in out
    assert "FAILED spring/no_output_x2" in out
    assert re.search(r"\d+ runs: \d+ ok, 2 past their stability limit \(measured, not failures\), 2 failed", out), out
    assert "beyond the stability limit (the run-time guards stopped them; a measured limit of the trade, " \
           "not a gate): blows_up x1, blows_up x2" in out
    assert "no result (no usable run.json; not a gate): no_output x1, no_output x2" in out
    rows = sweep.read_tsv(project / "reports" / "sweeps" / "spring" / "cost.tsv")
    by = {(r["sweep"], r["factor"]): r for r in rows}
    blown = by[("blows_up", 2.0)]
    assert blown["status"] == "unstable" and blown["error"] is None and blown["particle_steps"] == 20
    assert blown["note"].startswith("unstable: ") and "stage(s)" not in blown["note"]
    gone = by[("no_output", 1.0)]
    assert gone["status"].startswith("no run.json") and gone["error"] is None
    assert "fail: asked to fail" in gone["note"]          # the runner's cause (harness.json)
    assert all(sweep.failed(r) for r in rows)
    assert all(r is None for r in sweep.cheapest(rows).values())
    _, _, notes, bad = cost_plot.cost_points(rows)
    assert bad == {"blows_up": [(20, "x1 unstable"), (20, "x2 unstable")]}
    assert any(n.startswith("no_output x1: no run.json") and "not drawn" in n for n in notes)


@needs_gnuplot
def test_report_draws_and_tabulates_failed_points_as_unstable(project, capsys):
    add_sweeps(project, SWEEPS + UNSTABLE)
    assert main(["run", "spring"]) == 0
    assert main(["cost", "spring"]) == 0
    assert main(["report", "spring"]) == 0
    capsys.readouterr()
    svg = (project / "reports" / "figures" / "spring_error_cost_sweep.svg").read_text()
    assert "blows_up: unstable" in svg and "x2 unstable" in svg
    page = (project / "reports" / "cases" / "spring.html").read_text()      # every point: on the case's page
    assert '<td class="bad">unstable</td>' in page
    summary = (project / "reports" / "cases" / "spring.md").read_text()
    assert "- unstable (run failed, no error): blows_up x1, blows_up x2, no_output x1, no_output x2" in summary


def test_converge_terms_and_the_finest_point():
    costs = [{"status": "ok", "particle_steps": 100}, {"status": "unstable", "particle_steps": 900},
             {"status": "ok", "particle_steps": 400}, {"status": "ok", "particle_steps": None}]
    assert sweep.finest_index(costs) == 2                  # the most particle-steps among the ok points
    assert sweep.finest_index([costs[1]]) is None
    terms = sweep.converge_terms({"a": 1.1, "b": 0.5, "c": "no column"}, {"a": 1.0, "b": 0.0, "c": 3.0})
    assert terms["vs finest: a"] == pytest.approx(0.1) and terms["vs finest: b"] == 0.5
    assert terms["vs finest: c"] == "no column"
    assert sweep.converge_terms({"a": 1.0}, {"a": "bad"}) == {"vs finest: a": "finest point: bad"}


CONVERGE = """
[sweep n]
variant = soft
keys = stage.n=10
factors = 2 0.5
checks = none
converge = last(F)
converge = mean(F)
"""


def test_self_convergence_is_against_the_finest_swept_run(project, capsys):
    add_sweeps(project, CONVERGE)
    assert main(["run", "spring"]) == 0
    assert main(["cost", "spring"]) == 0
    rows = sweep.read_tsv(project / "reports" / "sweeps" / "spring" / "cost.tsv")
    by = {r["factor"]: r for r in rows}
    # soft: F = cycle, n cycles: last(F) = n, mean(F) = (n + 1) / 2; the finest is n = 20 (factor 2)
    assert by[2.0]["error"] is None and "the finest run: the reference" in by[2.0]["note"]
    assert by[1.0]["error"] == pytest.approx(0.5) and by[1.0]["worst"] == "vs finest: last(F)"
    assert by[0.5]["error"] == pytest.approx(0.75)
    assert main(["report", "spring"]) == 0
    capsys.readouterr()
    page = (project / "reports" / "index.html").read_text()
    assert "Self-convergence (n)" in page and "not against a reference" in page


def test_validate_accepts_a_sweep_measured_by_converge_alone(project):
    add_sweeps(project, "\n[sweep s]\nvariant = stiffer\nkeys = k=1\nfactors = 2\nconverge = last(F)\n")
    assert main(["check"]) in (0, 1)                      # no declaration error (exit 2)


def test_labels_of_coinciding_points_are_merged():
    """Issue 23: points of one curve at (nearly) the same cost and error get one label, not three
    printed over each other; points apart keep their own."""
    from harness.report.cost_plot import merged_labels
    points = [(1000.0, 1e-5, "x0.5"), (1000.0, 1.01e-5, ""), (1010.0, 1.02e-5, "x2"), (1005.0, 0.99e-5, "x4"),
              (4000.0, 1e-5, "x0.25")]
    assert merged_labels(points) == [(1000.0, 1e-5, "x0.5, x2, x4"), (1000.0, 1.01e-5, ""), (1010.0, 1.02e-5, ""),
                                     (1005.0, 0.99e-5, ""), (4000.0, 1e-5, "x0.25")]
