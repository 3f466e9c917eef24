"""The rolling-resistance law tester (cases/rolling, reference/rolling.ref): the family's
fit_slope, the derivation's hand calculation against the paper's closed forms, and the
figures' reference lines against the derivation."""
import importlib.util
import pathlib
import re
from fractions import Fraction

import numpy as np
import pytest

from harness import catalogue
from harness.compare import evaluate
from harness.errors import EvalError
from harness.families.rolling import fit_slope
from harness.tables import Run

ROOT = pathlib.Path(__file__).resolve().parents[2]
DERIVE = ROOT / "reference" / "derive" / "rolling.py"


def derivation():
    spec = importlib.util.spec_from_file_location("derive_rolling", DERIVE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _run(**columns):
    n = len(next(iter(columns.values())))
    cycle = np.arange(1.0, n + 1)
    cols = {"cycle": cycle, "time": cycle / 4, **{k: np.asarray(v, dtype=float) for k, v in columns.items()}}
    return Run(folder=None, info={"status": "ok", "dt": 0.25}, columns=cols)


# ---------------------------------------------------------------- fit_slope

def test_fit_slope_is_the_slope_of_a_line_with_any_offset():
    x = np.array([-3.0e-4, -1.0e-4, 2.5e-4, 7.0e-4, 7.5e-4])
    assert fit_slope(x, 196608.0 * x) == pytest.approx(196608.0, rel=1e-15)
    assert fit_slope(x, 2.385 - 12288.0 * x) == pytest.approx(-12288.0, rel=1e-14)


def test_fit_slope_is_least_squares():
    rng = np.random.default_rng(7)
    x = np.linspace(0, 1, 40)
    y = 3.1 * x + rng.normal(0, 0.1, x.size)
    assert fit_slope(x, y) == pytest.approx(np.polyfit(x, y, 1)[0], rel=1e-12)


def test_fit_slope_over_a_window_of_a_run():
    """Two branches of different slope: the window picks one."""
    theta = np.concatenate([np.arange(6.0), 5 - np.arange(1.0, 5)])     # up 0..5, back 4..1
    m = np.concatenate([2.5 * np.arange(6.0), 12.5 - 4.0 * np.arange(1.0, 5)])
    run = _run(theta_r=theta, mr=m)
    assert evaluate("fit_slope(between(theta_r, 1, 6), between(mr, 1, 6))", run) == pytest.approx(2.5)
    assert evaluate("fit_slope(between(theta_r, 6, 10), between(mr, 6, 10))", run) == pytest.approx(4.0)


@pytest.mark.parametrize("x, y, words", [
    ([1.0, 2.0, 3.0], [1.0, 2.0], "rows of the same length (3 and 2)"),
    ([1.0], [1.0], "at least two points, got 1"),
    ([], [], "at least two points, got 0"),
    ([2.0, 2.0, 2.0], [1.0, 2.0, 3.0], "x does not vary"),
])
def test_fit_slope_refuses_what_has_no_slope(x, y, words):
    with pytest.raises(EvalError, match=re.escape(words)):
        fit_slope(x, y)


def test_fit_slope_on_an_empty_window_fails_the_check():
    run = _run(theta_r=[0.0, 1.0, 2.0], mr=[0.0, 1.0, 2.0])
    with pytest.raises(EvalError, match="at least two points, got 0"):
        evaluate("fit_slope(between(theta_r, 10, 20), between(mr, 10, 20))", run)


# ---------------------------------------------------------------- the derivation

@pytest.fixture(scope="module")
def derive():
    return derivation()


@pytest.fixture(scope="module")
def variants(derive):
    return derive.read_inputs()


def test_every_variant_is_derived(variants):
    case = next(c for c in catalogue.load(ROOT / "cases") if c.name == "rolling_tester")
    assert sorted(variants) == sorted(case.variant_names())
    models = ("model1", "model2")
    assert sorted((p["kind"], p["model"], p["delta"]) for p in variants.values()) == sorted(
        [("wall", m, Fraction(d)) for m in models for d in ("1.6", "0.4")] + [("pair", m, Fraction("1.6")) for m in models])
    pair = variants["pair_model1"]
    assert pair["r"] == Fraction(3, 5) and pair["d"] == Fraction(1, 4096)     # 2 r1 r2/(r1 + r2), eq. 9b


def test_a_flywheel_too_light_to_turn_steadily_is_refused(derive, tmp_path):
    scene = (ROOT / "cases" / "rolling" / "rolling_pair.scene").read_text()
    light = tmp_path / "light.scene"
    light.write_text(scene.replace("density = 1e20", "density = 1e9"))
    with pytest.raises(AssertionError, match="the flywheel's spin would change"):
        derive.read_variant(light, [], "light")
    derive.read_variant(ROOT / "cases" / "rolling" / "rolling_pair.scene", [], "heavy")


def test_the_hand_calculation_meets_the_closed_forms(derive, variants):
    """The cycle-by-cycle law of the derivation against JYH's closed forms, within what the
    wall's turn (F_n rises by (R - p)(1 - cos a)) and one step's resolution allow."""
    for name, p in variants.items():
        rows = derive.hand(p)
        b, km = derive.constants(p)
        kn = p["kn"]
        assert km == kn * b * b / 12                                   # eq. 29
        for r in rows:
            assert r["m0"] == r["fn"] * b / 6                           # eq. 33a
            assert r["e_el"] == kn * r["d"] ** 2 / 2 + r["m"] ** 2 / (2 * km)
            if r["state"] == 1:
                assert abs(r["m"]) == r["m0"]                           # eq. 35b
            if r["state"] == 2:
                assert r["m"] == 0                                      # eq. 36b
        step = max(abs(rows[k]["theta"] - rows[k - 1]["theta"]) for k in range(1, len(rows)))
        first = next(r for r in rows if r["state"] != 0)
        theta0 = 2 * first["fn"] / (kn * b)                             # eq. 33b
        assert theta0 < first["theta"] <= theta0 + step
        if p["model"] == "model2":
            lost = rows[-1]["lost"]
            continuum = first["m0"] ** 2 / (2 * km)                     # F_n^2/(6 k_n)
            assert continuum == pytest.approx(first["fn"] ** 2 / (6 * kn), rel=1e-15)
            assert continuum < lost <= (first["m0"] + km * step) ** 2 / (2 * km)
        else:
            end = rows[derive.stage_ends(p)["twist"][1] - 1]
            nominal = derive.nominal(p)[1][0]
            plastic = end["theta"] - nominal / km
            # M_0 follows F_n, raised by the turn by at most (end d / d1 - 1)
            rise = float(end["fn"] / (nominal * 6 / b) - 1)
            assert float(end["lost"] / (nominal * plastic)) == pytest.approx(1, abs=2 * rise + 1e-12)


def test_the_figures_draw_the_derivations_nominal_lines(derive, variants):
    case = next(c for c in catalogue.load(ROOT / "cases") if c.name == "rolling_tester")
    moments = [f for f in case.figures if f.x == "theta_r" and f.y == ["mr"]]
    assert len(moments) == 3
    for figure in moments:
        for variant in figure.variants:
            km, levels = derive.nominal(variants[variant])
            drawn = [(slope, intercept) for slope, intercept, _ in figure.lines]
            assert drawn[0] == (float(km), 0.0) and all(slope == 0 for slope, _ in drawn[1:]), figure.name
            assert [i for _, i in drawn[1:]] in ([float(m) for m in levels],                   # +M_0
                                                 [float(s * m) for m in levels for s in (1, -1)]), figure.name


def test_an_ambiguous_cap_is_refused(derive, variants, monkeypatch):
    """A cap decision within AMBIGUOUS of a step's increment would make the onset cycle a matter
    of rounding: the derivation refuses it rather than print a cycle number.  (The case's caps
    are at least a tenth of a step clear; a guard of a whole step catches them.)"""
    derive.hand(variants["model1_d16"])
    monkeypatch.setattr(derive, "AMBIGUOUS", Fraction(1))
    with pytest.raises(AssertionError, match="within a millionth of a step"):
        derive.hand(variants["model1_d16"])
