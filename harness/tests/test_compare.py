"""Checks against fake outputs: every tolerance kind passes and fails where it should, every
kind of broken output is a FAIL with a message saying why, and the expression language works."""
import math

import numpy as np
import pytest

from harness.compare import RunStore, evaluate, evaluate_check, folder_locator
from harness.errors import EvalError
from harness.references import load_file
from harness.tables import Run, load_run
from harness.tests.fakes import spring_columns, write_run, write_series


def make_check(tmp_path, body, name="c"):
    """One Check of case 'spring' from the lines of its body."""
    path = tmp_path / f"{name}.ref"
    path.write_text(f"[check {name}]\ncase = spring\nkind = analytic\nprovenance = test\n" + body)
    return load_file(path)[0]


@pytest.fixture
def store(tmp_path):
    """Correct spring outputs for soft (k=1), stiff (k=2), stiffer (k=3); 'flat' has k=2 like stiff."""
    root = tmp_path / "runs"
    for variant, k in (("soft", 1), ("stiff", 2), ("stiffer", 3), ("flat", 2)):
        write_run(root / "spring" / variant, spring_columns(k), wall_seconds=1.5)
    return RunStore(folder_locator(root))


def verdict(tmp_path, store, body):
    return evaluate_check(make_check(tmp_path, body), store)


# ---------------------------------------------------------------- tolerance kinds

@pytest.mark.parametrize("body, passed", [
    ("variant = soft\nquantity = at(F, 3)\nvalue = 3\ntolerance = abs 0\n", True),
    ("variant = soft\nquantity = at(F, 3)\nvalue = 3.05\ntolerance = abs 0.1\n", True),
    ("variant = soft\nquantity = at(F, 3)\nvalue = 3.5\ntolerance = abs 0.1\n", False),
    ("variant = soft\nquantity = at(F, 3)\nvalue = 2.95\ntolerance = abs 0.1\n", True),
    ("variant = soft\nquantity = at(F, 3)\nvalue = 2.8\ntolerance = abs 0.1\n", False),
    ("variant = stiff\nquantity = last(F)\nvalue = 20.0000001\ntolerance = rel 1e-6\n", True),
    ("variant = stiff\nquantity = last(F)\nvalue = 20.001\ntolerance = rel 1e-6\n", False),
    ("variant = stiff\nquantity = last(F)\nvalue = -20\ntolerance = rel 0.5\n", False),
    ("variant = soft\nquantity = first(F) - 1\nvalue = 0\ntolerance = rel 1\n", True),
    ("variant = soft\nquantity = first(F)\nvalue = 0\ntolerance = rel 1\n", False),
    ("variant = soft\nquantity = max(Ek)\ntolerance = interval\nlo = 49\nhi = 51\n", True),
    ("variant = soft\nquantity = max(Ek)\ntolerance = interval\nlo = 50\nhi = 50\n", True),
    ("variant = soft\nquantity = max(Ek)\ntolerance = interval\nlo = 51\n", False),
    ("variant = soft\nquantity = max(Ek)\ntolerance = interval\nhi = 49\n", False),
    ("variant = soft\nquantity = max(Ek)\ntolerance = interval\nlo = 0\n", True),
    ("variant = soft\nquantity = max(Ek)\ntolerance = interval\n", True),
    ("quantity = last(F)\ntolerance = trend increasing\nvariants = soft stiff stiffer\n", True),
    ("quantity = last(F)\ntolerance = trend increasing\nvariants = stiffer stiff soft\n", False),
    ("quantity = last(F)\ntolerance = trend decreasing\nvariants = stiffer stiff soft\n", True),
    ("quantity = last(F)\ntolerance = trend increasing\nvariants = soft stiff flat\n", False),
    ("quantity = last(F)\ntolerance = trend nondecreasing\nvariants = soft stiff flat\n", True),
    ("quantity = last(F)\ntolerance = trend nonincreasing\nvariants = stiffer stiff flat\n", True),
    ("quantity = last(F)\ntolerance = trend nonincreasing\nvariants = soft stiff\n", False),
    ("quantity = last(F)\ntolerance = trend decreasing\nvariants = stiff flat\n", False),
    ("variant = stiff\nquantity = last(F)\nother = last(F)\nother_variant = soft\nvalue = 2\ntolerance = ratio 1e-12\n", True),
    ("variant = stiff\nquantity = last(F)\nother = last(F)\nother_variant = soft\nvalue = 2.1\ntolerance = ratio 0.01\n", False),
    ("variant = stiff\nquantity = last(F)\nother = last(F)\nother_variant = soft\nvalue = 2.1\ntolerance = ratio 0.05\n", True),
    ("variant = soft\nquantity = last(Ek)\nother = last(F)\nvalue = 5\ntolerance = ratio 1e-12\n", True),
    ("variant = soft\nquantity = last(Ek)\nother = last(F)\nvalue = 6\ntolerance = ratio 1e-3\n", False),
])
def test_tolerance_kinds(tmp_path, store, body, passed):
    v = verdict(tmp_path, store, body)
    assert v.passed is passed, v.message
    assert v.message


def test_verdict_fields(tmp_path, store):
    v = verdict(tmp_path, store, "variant = soft\nquantity = at(F, 3)\nvalue = 3.5\ntolerance = abs 0.1\n")
    assert (v.case, v.variant, v.check, v.value, v.reference, v.tolerance, v.kind, v.provenance) == \
        ("spring", "soft", "c", 3.0, 3.5, "abs 0.1", "analytic", "test")
    assert "0.5 > 0.1" in v.message
    trend = verdict(tmp_path, store, "quantity = last(F)\ntolerance = trend increasing\nvariants = soft stiff\n")
    assert (trend.variant, trend.value, trend.reference) == ("soft stiff", [10.0, 20.0], None)
    interval = verdict(tmp_path, store, "variant = soft\nquantity = max(Ek)\ntolerance = interval\nhi = 60\n")
    assert interval.reference == [None, 60.0]


# ---------------------------------------------------------------- honest failures

GOOD = "variant = soft\nquantity = last(F)\nvalue = 10\ntolerance = rel 1e-9\n"


def test_right_output_passes_wrong_output_fails(tmp_path, store):
    assert verdict(tmp_path, store, GOOD).passed
    write_run(tmp_path / "runs" / "spring" / "soft", spring_columns(1.01))
    wrong = evaluate_check(make_check(tmp_path, GOOD), RunStore(folder_locator(tmp_path / "runs")))
    assert not wrong.passed and wrong.value == pytest.approx(10.1)


def fails_with(tmp_path, store, words, body=GOOD):
    v = verdict(tmp_path, store, body)
    assert v.passed is False
    assert words in v.message, v.message
    return v


def test_missing_run_folder_fails(tmp_path, store):
    fails_with(tmp_path, store, "run output missing", GOOD.replace("soft", "absent"))


def test_missing_run_json_fails(tmp_path, store):
    (tmp_path / "runs" / "spring" / "soft" / "run.json").unlink()
    fails_with(tmp_path, store, "run.json missing")


def test_malformed_run_json_fails(tmp_path, store):
    (tmp_path / "runs" / "spring" / "soft" / "run.json").write_text("{not json")
    fails_with(tmp_path, store, "run.json unreadable")


def test_failed_run_status_fails_even_with_good_series(tmp_path, store):
    write_run(tmp_path / "runs" / "spring" / "soft", spring_columns(1), status="unstable")
    fails_with(tmp_path, store, "run failed: status 'unstable'")


def test_nonzero_exit_recorded_by_runner_fails(tmp_path, store):
    (tmp_path / "runs" / "spring" / "soft" / "harness.json").write_text('{"returncode": 3}')
    fails_with(tmp_path, store, "exited with code 3")


def test_missing_series_fails(tmp_path, store):
    (tmp_path / "runs" / "spring" / "soft" / "series.tsv").unlink()
    fails_with(tmp_path, store, "series.tsv missing")


def test_missing_column_fails(tmp_path, store):
    v = fails_with(tmp_path, store, "column 'Fn_Z' missing", GOOD.replace("last(F)", "last(Fn_Z)"))
    assert "cycle, time, F, Ek" in v.message


def test_nan_value_fails(tmp_path, store):
    cols = spring_columns(1)
    cols["F"][-1] = math.nan
    write_series(tmp_path / "runs" / "spring" / "soft", cols)
    v = fails_with(tmp_path, store, "not finite")
    assert v.value is None


def test_inf_value_fails(tmp_path, store):
    fails_with(tmp_path, store, "not finite", GOOD.replace("last(F)", "last(F / 0)"))


def test_nan_fails_even_for_an_unbounded_interval(tmp_path, store):
    fails_with(tmp_path, store, "not finite",
               "variant = soft\nquantity = sqrt(-last(F))\ntolerance = interval\n")


def test_expression_that_raises_fails(tmp_path, store):
    fails_with(tmp_path, store, "no row with cycle == 99", GOOD.replace("last(F)", "at(F, 99)"))
    fails_with(tmp_path, store, "ZeroDivisionError", GOOD.replace("last(F)", "1 / 0"))
    fails_with(tmp_path, store, "syntax error", GOOD.replace("last(F)", "last(F"))
    fails_with(tmp_path, store, "no rows selected", GOOD.replace("last(F)", "mean(after(F, 1000))"))
    fails_with(tmp_path, store, "gives 10 values", GOOD.replace("last(F)", "F"))
    fails_with(tmp_path, store, "not a number", GOOD.replace("last(F)", "run('version')"))
    fails_with(tmp_path, store, "has no field 'nope'", GOOD.replace("last(F)", "run('nope')"))


def test_no_builtins_in_expressions(tmp_path, store):
    fails_with(tmp_path, store, "unknown function 'len'", GOOD.replace("last(F)", "len(open('/etc/passwd').read())"))
    fails_with(tmp_path, store, "unknown function 'open'", GOOD.replace("last(F)", "open('/etc/passwd')"))
    fails_with(tmp_path, store, "unknown function '__import__'", GOOD.replace("last(F)", "__import__('os').getpid()"))
    fails_with(tmp_path, store, "not allowed", GOOD.replace("last(F)", "F.__class__"))


def test_failure_in_one_trend_variant_fails_the_trend(tmp_path, store):
    write_run(tmp_path / "runs" / "spring" / "stiff", spring_columns(2), status="error")
    fails_with(tmp_path, store, "stiff", "quantity = last(F)\ntolerance = trend increasing\nvariants = soft stiff stiffer\n")


def test_ratio_with_zero_other_fails(tmp_path, store):
    fails_with(tmp_path, store, "is zero",
               "variant = soft\nquantity = last(F)\nother = last(F) * 0\nvalue = 1\ntolerance = ratio 1\n")


def test_ratio_with_missing_other_variant_fails(tmp_path, store):
    fails_with(tmp_path, store, "run output missing",
               "variant = soft\nquantity = last(F)\nother = last(F)\nother_variant = gone\nvalue = 1\ntolerance = ratio 1\n")


# ---------------------------------------------------------------- expression language

@pytest.fixture
def run(tmp_path):
    cols = {"cycle": [1, 2, 3, 4, 5], "time": [0.1, 0.2, 0.3, 0.4, 0.5], "x": [4.0, -2.0, 6.0, 0.0, 1.0]}
    write_run(tmp_path / "r", cols, dt=0.25, steps=5)
    return load_run(tmp_path / "r")


@pytest.mark.parametrize("expr, expected", [
    ("at(x, 3)", 6.0), ("first(x)", 4.0), ("last(x)", 1.0),
    ("mean(after(x, 2))", 7 / 3), ("mean(upto(x, 2))", 1.0), ("max(between(x, 2, 4))", 6.0),
    ("min(x)", -2.0), ("std(x)", float(np.std([4, -2, 6, 0, 1]))), ("amp(x)", 4.0),
    ("abs(at(x, 2))", 2.0), ("sqrt(at(x, 1))", 2.0), ("run('dt') * 4", 1.0), ("run('steps')", 5.0),
    ("last(time) / last(cycle)", 0.1), ("max(at(x, 1), at(x, 3))", 6.0), ("first(after(x, 3))", 0.0),
    ("mean(x[cycle > 2])", 7 / 3), ("3 if at(x, 1) > 0 else 4", 3.0), ("max([at(x, c) for c in [1, 2]])", 4.0),
])
def test_expression_functions(run, expr, expected):
    assert evaluate(expr, run) == pytest.approx(expected)


@pytest.mark.parametrize("expr, words", [
    ("at(after(x, 1), 2)", "whole series column"),
    ("first(after(x, 9))", "no rows selected"),
    ("max(upto(x, 0))", "no rows selected"),
    ("undefined_thing", "missing from series.tsv"),
])
def test_expression_errors(run, expr, words):
    with pytest.raises(EvalError, match=words):
        evaluate(expr, run)


def test_store_loads_each_run_once(tmp_path, store):
    first = store.get("spring", "soft")
    (tmp_path / "runs" / "spring" / "soft" / "series.tsv").unlink()
    assert store.get("spring", "soft") is first


# ---------------------------------------------------------------- series, period, settle

def _fake_run(columns, info=None):
    cols = {k: np.asarray(v, dtype=float) for k, v in columns.items()}
    return Run(folder=None, columns=cols, info=info or {"status": "ok"})


def test_period_of_a_sampled_sine():
    cycle = np.arange(1, 401)
    run = _fake_run({"cycle": cycle, "time": cycle, "F": np.sin(2 * np.pi * cycle / 23.5)})
    assert abs(evaluate("period(F)", run) - 23.5) < 0.2


def test_period_needs_two_crossings():
    cycle = np.arange(1, 11)
    run = _fake_run({"cycle": cycle, "time": cycle, "F": cycle * 1.0})
    with pytest.raises(EvalError, match="crossings"):
        evaluate("period(F)", run)


def test_settle_finds_the_last_excursion():
    cycle = np.arange(1, 11)
    f = np.array([0, 5, 12, 9, 10.5, 9.95, 10.02, 10.0, 9.99, 10.0])
    run = _fake_run({"cycle": cycle, "time": cycle, "F": f})
    assert evaluate("settle(F, 10, 0.01)", run) == 6.0
    assert evaluate("settle(F, 10, 0.1)", run) == 4.0


def test_settle_that_never_happens_is_an_error():
    cycle = np.arange(1, 6)
    run = _fake_run({"cycle": cycle, "time": cycle, "F": [1, 2, 3, 4, 5.0]})
    with pytest.raises(EvalError, match="still outside"):
        evaluate("settle(F, 10, 0.01)", run)


def test_series_reads_another_variant():
    cycle = np.arange(1, 4)
    a = _fake_run({"cycle": cycle, "time": cycle, "F": [1, 2, 3.0]})
    b = _fake_run({"cycle": cycle, "time": cycle, "F": [1, 2, 4.0]})
    sibling = {"b": b}.__getitem__
    assert evaluate("max(abs(F - series('b', 'F')))", a, sibling) == 1.0
    with pytest.raises(EvalError, match="no column"):
        evaluate("max(series('b', 'G'))", a, sibling)
    with pytest.raises(EvalError, match="no other variants"):
        evaluate("max(series('b', 'F'))", a)
