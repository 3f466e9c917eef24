"""The command line as a whole: list, sweep, validate, the wrapper script, and malformed series."""
import json
import os
import subprocess
from pathlib import Path

import pytest

from harness.__main__ import main
from harness.compare import RunStore, evaluate_check, folder_locator
from harness.errors import RunProblem
from harness.references import load
from harness.tables import read_series
from harness.tests.fakes import env_for, write_run

WRAPPER = Path(__file__).resolve().parents[1] / "ballast-harness"


def test_list(project, capsys):
    assert main(["list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split() == ["CASE", "TIER", "VARIANTS", "RUNTIME", "CHECKS"]
    assert lines[2].split()[:6] == ["spring", "quick", "soft", "stiff", "stiffer", "3"]
    assert lines[2].endswith("F = k x at every cycle; trend in k")
    assert lines[0].index("TIER") == lines[1].index("full") == lines[2].index("quick")   # aligned
    assert main(["list", "--tier", "quick"]) == 0
    assert "slow" not in capsys.readouterr().out


def test_wrapper_script_runs_the_harness(project):
    assert os.access(WRAPPER, os.X_OK)
    done = subprocess.run([str(WRAPPER), "list"], capture_output=True, text=True,
                          env={**os.environ, **env_for(project)}, timeout=60)
    assert done.returncode == 0, done.stderr
    assert "spring" in done.stdout and "slow" in done.stdout


def test_wrapper_script_takes_paths_relative_to_where_it_is_called(tmp_path):
    """A user's scene and --out given relative to the user's folder (the wrapper used to cd to
    the repository first, so `ballast-harness study my.scene` said "no such scene file")."""
    (tmp_path / "two.scene").write_text("[settings]\ndt = 1e-3\n\n[material m]\nkn = 1000\ndensity = 1\n\n"
                                        "[disc a]\nx = 0 0\nr = 1\nmaterial = m\nv = 1 0\n\n"
                                        "[disc b]\nx = 2.1 0\nr = 1\nmaterial = m\n\n[stage s]\ncycles = 400\n")
    done = subprocess.run([str(WRAPPER), "study", "two.scene", "--out", "here", "--levels", "3",
                           "--quantity", "final(disc_x(b))"], cwd=tmp_path, capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    rows = (tmp_path / "here" / "study.tsv").read_text().splitlines()
    status = rows[0].split("\t").index("status")
    assert [r.split("\t")[status] for r in rows[1:]] == ["ok"] * 3, rows


def test_validate_runs_checks_and_reports(project, capsys):
    assert main(["validate", "-j", "3"]) == 0
    out = capsys.readouterr().out
    assert "3 runs: 3 ok" in out and "6 passed, 0 failed" in out
    assert (project / "reports" / "index.html").exists() and (project / "reports" / "junit.xml").exists()


def test_validate_with_failed_runs_still_checks_and_reports(project, capsys):
    case = project / "cases" / "springs" / "case.txt"
    case.write_text(case.read_text().replace("set = k=3", "set = k=3\nset = fail=4"))
    assert main(["validate"]) == 1
    out = capsys.readouterr().out
    assert "FAILED spring/stiffer: exit code 4" in out and "5 passed, 1 failed" in out
    assert (project / "reports" / "index.html").exists()


def test_sweep(project, capsys):
    assert main(["sweep", "spring", "--set", "k=1,2", "--variant", "soft"]) == 0
    out = capsys.readouterr().out
    sweeps = project / "reports" / "sweeps" / "spring"
    assert (sweeps / "k=1" / "series.tsv").exists() and (sweeps / "k=2" / "series.tsv").exists()
    table = out[out.index("check"):out.index("wrote")].splitlines()
    assert table[0].split() == ["check", "reference", "tolerance", "k=1", "k=2"]
    rows = {line.split()[0]: line for line in table[1:]}
    assert set(rows) == {"abs_at2", "interval_ek", "regress_mean",       # checks of soft alone
                         "(status)", "(steps)", "(particle-steps)", "(wall"}   # ... and each point's cost
    # value, verdict and error against the reference 2 (abs tolerance): 0 at k=1, |4 - 2|/2 at k=2
    assert rows["abs_at2"].split()[-8:] == ["2", "PASS", "err", "0.00e+00", "4", "FAIL", "err", "1.00e+00"]
    assert rows["(status)"].split()[-2:] == ["ok", "ok"]
    tsv = (sweeps / "sweep_soft.tsv").read_text().splitlines()
    assert tsv[0].split("\t")[:3] == ["point", "sets", "status"] and len(tsv) == 1 + 2 * 3


def test_sweep_with_several_keys_runs_their_grid(project, capsys):
    """Issue 23: several --set options combine as a grid (the first key slowest); a key twice is
    refused rather than one of them dropped in silence."""
    assert main(["sweep", "spring", "--set", "k=1,2", "--set", "x=5,6,7", "--variant", "soft"]) == 0
    out = capsys.readouterr().out
    labels = out[out.index("check"):].splitlines()[0].split()[3:]
    assert labels == ["k=1,x=5", "k=1,x=6", "k=1,x=7", "k=2,x=5", "k=2,x=6", "k=2,x=7"]
    run = project / "reports" / "sweeps" / "spring" / "k=2,x=6"
    assert json.loads((run / "run.json").read_text())["sets"][-2:] == ["k=2", "x=6"]
    assert main(["sweep", "spring", "--set", "k=1,2", "--set", "k=3", "--variant", "soft"]) == 2
    assert "--set k given twice" in capsys.readouterr().err


def test_sweep_needs_a_variant_when_several(project, capsys):
    assert main(["sweep", "spring", "--set", "k=1,2"]) == 2
    assert "pick one with --variant" in capsys.readouterr().err
    assert main(["sweep", "spring", "--set", "k", "--variant", "soft"]) == 2


def test_unknown_case_is_a_usage_error(project, capsys):
    assert main(["run", "nope"]) == 2
    assert "unknown case(s): nope" in capsys.readouterr().err


@pytest.mark.parametrize("text, words", [
    ("", "series.tsv is empty"),
    ("time\tcycle\tF\n1\t2\t3\n", ":1: header must start with 'cycle<TAB>time'"),
    ("cycle\ttime\tF\n1\t0.1\t3\n2\t0.2\n", ":3: 2 fields, header has 3"),
    ("cycle\ttime\tF\n1\t0.1\tabc\n", ":2: not a number"),
    ("cycle\ttime\tF\tF\n", "repeated column name"),
])
def test_malformed_series_is_a_run_problem(tmp_path, text, words):
    (tmp_path / "series.tsv").write_text(text)
    with pytest.raises(RunProblem, match=words):
        read_series(tmp_path / "series.tsv")


def test_malformed_series_fails_the_check(project, runs):
    write_run(runs / "spring" / "soft")
    (runs / "spring" / "soft" / "series.tsv").write_text("cycle\ttime\tF\n1\t0.1\n")
    check = next(c for c in load() if c.name == "abs_at2")
    verdict = evaluate_check(check, RunStore(folder_locator(runs)))
    assert not verdict.passed and "series.tsv:2: 2 fields" in verdict.message


def test_series_with_header_only_has_empty_columns(tmp_path):
    (tmp_path / "series.tsv").write_text("cycle\ttime\tEk\n")
    columns = read_series(tmp_path / "series.tsv")
    assert list(columns) == ["cycle", "time", "Ek"] and columns["Ek"].size == 0


def test_validate_of_one_case_updates_its_part_and_keeps_the_rest(project, capsys):
    """Issue 23: `validate CASE` checks and draws that case and leaves the other cases' verdicts
    and figures in summary.json, junit.xml and index.html as an earlier validate wrote them."""
    (project / "reference" / "slow.ref").write_text(
        "[check slow_last]\ncase = slow\nvariant = only\nquantity = last(F)\nvalue = 10\n"
        "tolerance = rel 1e-9\nkind = exact\nprovenance = F = k x with k = 1, x = 10\n")
    assert main(["validate", "--tier", "full", "--no-stability"]) == 0
    reports = project / "reports"
    before = json.loads((reports / "summary.json").read_text())
    spring = [v for v in before if v["case"] == "spring"]
    assert spring and (reports / "figures" / "spring_force.png").exists()
    figure = (reports / "figures" / "spring_force.png").stat().st_mtime_ns
    capsys.readouterr()
    assert main(["validate", "slow", "--tier", "full", "--no-stability"]) == 0
    out = capsys.readouterr().out
    assert "spring/" not in out                                   # spring was not run again
    after = json.loads((reports / "summary.json").read_text())
    assert [v for v in after if v["case"] == "spring"] == spring   # ... and its verdicts kept
    assert 'classname="spring.' in (reports / "junit.xml").read_text()
    page = (reports / "index.html").read_text()
    assert "A linear spring" in page and "A slow case" in page
    assert (reports / "figures" / "spring_force.png").stat().st_mtime_ns == figure   # not redrawn


def test_validate_of_some_cases_runs_the_extreme_probes_only_when_asked(project, monkeypatch):
    """Issue 23: the extreme probes belong to no case: a validate of all cases runs them, a
    validate of named cases only with --extremes."""
    import harness.__main__ as cli
    seen = []
    monkeypatch.setattr(cli, "cmd_stability", lambda a: seen.append(a.no_extremes) or 0)
    for argv, skipped in ((["validate"], False), (["validate", "spring"], True),
                          (["validate", "spring", "--extremes"], False)):
        main(argv)
        assert seen.pop() is skipped, argv
