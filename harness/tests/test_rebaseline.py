"""rebaseline: rewrites only regression values, in place, keeping every other character;
refuses (and writes nothing) when an output is missing or a run failed."""
import pytest

from harness.__main__ import main
from harness.rebaseline import replace_value
from harness.tests.fakes import REF_TXT, spring_columns, tree_snapshot, write_run, write_spring_runs

REGRESSION_RATIO = """
[check regress_ratio]   # a ratio kept as a regression
case = spring
variant = stiffer
quantity = last(F)
other = last(F)
other_variant = soft
value = 3
tolerance = ratio 1e-12
kind = regression
provenance = recorded

[check regress_interval]
case = spring
variant = soft
quantity = max(F)
tolerance = interval
lo = 0
kind = regression
provenance = recorded
"""


def ref_path(project):
    return project / "reference" / "springs.ref"


def rebaseline(capsys, case="spring"):
    status = main(["rebaseline", case])
    return status, capsys.readouterr().out


def test_rewrites_only_the_regression_value(project, runs, capsys):
    # soft with k = 2: mean(F) becomes 11, and the analytic checks on soft become wrong:
    # rebaseline must still touch only the regression value.
    write_spring_runs(runs, (("soft", 2), ("stiff", 2), ("stiffer", 3)))
    status, out = rebaseline(capsys)
    assert status == 0
    assert "regress_mean: 5.5 -> 11.0" in out
    old, new = REF_TXT.splitlines(keepends=True), ref_path(project).read_text().splitlines(keepends=True)
    changed = [(a, b) for a, b in zip(old, new) if a != b]
    assert len(old) == len(new)
    assert changed == [("value = 5.5   # regression value, keep this comment\n",
                        "value = 11.0   # regression value, keep this comment\n")]


def test_after_rebaseline_the_regression_check_passes(project, runs, capsys):
    write_spring_runs(runs, (("soft", 1.5), ("stiff", 2), ("stiffer", 3)))
    main(["check", "spring"])
    assert "FAIL spring/regress_mean" in capsys.readouterr().out
    rebaseline(capsys)
    main(["check", "spring"])
    assert "FAIL spring/regress_mean" not in capsys.readouterr().out


def test_ratio_regression_and_interval_regression(project, runs, capsys):
    ref_path(project).write_text(REF_TXT + REGRESSION_RATIO)
    write_spring_runs(runs, (("soft", 1), ("stiff", 2), ("stiffer", 4)))
    status, out = rebaseline(capsys)
    assert status == 0
    assert "regress_ratio: 3.0 -> 4.0" in out
    assert "regress_interval: interval check has no value to rebaseline" in out
    assert "1 value(s) changed, 1 unchanged" in out
    assert REGRESSION_RATIO.replace("value = 3\n", "value = 4.0\n") in ref_path(project).read_text()


def test_unchanged_values_are_left_alone(project, runs, capsys):
    write_spring_runs(runs)
    before = tree_snapshot(project / "reference")
    status, out = rebaseline(capsys)
    assert status == 0 and "->" not in out and "0 value(s) changed, 1 unchanged" in out
    assert tree_snapshot(project / "reference") == before


@pytest.mark.parametrize("breakage, words", [
    ("missing", "run output missing"),
    ("failed", "status 'unstable'"),
    ("nan", "not finite"),
    ("no_series", "series.tsv missing"),
])
def test_refuses_and_writes_nothing(project, runs, capsys, breakage, words):
    write_spring_runs(runs, (("soft", 3), ("stiff", 2), ("stiffer", 3)))
    soft = runs / "spring" / "soft"
    if breakage == "missing":
        for p in (runs / "spring" / "stiffer").iterdir():
            p.unlink()
        (runs / "spring" / "stiffer").rmdir()
    elif breakage == "failed":
        write_run(soft, spring_columns(3), status="unstable")
    elif breakage == "nan":
        cols = spring_columns(3)
        cols["F"][4] = float("nan")
        write_run(soft, cols)
    else:
        (soft / "series.tsv").unlink()
    before = tree_snapshot(project / "reference")
    status, out = rebaseline(capsys)
    assert status != 0
    assert "refused, nothing written" in out and words in out
    assert tree_snapshot(project / "reference") == before


def test_unknown_case_is_refused(project, capsys):
    assert main(["rebaseline", "nope"]) == 2


def test_case_without_regression_checks(project, runs, capsys):
    status, out = rebaseline(capsys, "slow")
    assert status == 0 and "no regression checks" in out


@pytest.mark.parametrize("line, new", [
    ("value = 1\n", "value = 2.5\n"),
    ("  value   =   1e6   # note # more\n", "  value   =   2.5   # note # more\n"),
    ("value = 1\r\n", "value = 2.5\r\n"),
    ("value=1", "value=2.5"),
])
def test_replace_value_keeps_layout(line, new):
    assert replace_value(line, "2.5") == new


def test_crlf_file_keeps_its_line_endings(project, runs, capsys):
    ref_path(project).write_bytes(REF_TXT.replace("\n", "\r\n").encode())
    write_spring_runs(runs, (("soft", 2), ("stiff", 2), ("stiffer", 3)))
    assert rebaseline(capsys)[0] == 0
    data = ref_path(project).read_bytes()
    assert data == REF_TXT.replace("value = 5.5 ", "value = 11.0 ").replace("\n", "\r\n").encode()
