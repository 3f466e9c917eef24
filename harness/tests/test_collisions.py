"""The collision and order functions of compare.py (contact_start, contact_end,
contact_duration, restitution, sine_period, sine_amplitude, of, order), and the
derivations behind reference/collisions.ref and reference/two_discs_order.ref."""
import importlib.util
import math
import pathlib
import re

import numpy as np
import pytest

from harness.compare import RunStore, evaluate, folder_locator
from harness.errors import EvalError
from harness.tables import load_run
from harness.tests.fakes import write_run

ROOT = pathlib.Path(__file__).resolve().parents[2]
DT = 0.125


def collision_columns(v_in=2.0, v_out=0.75, t_on=0.4375, t_off=1.3, n=16):
    """A gap that closes at v_in (free flight), reaches zero at t_on, stays negative, and
    opens at v_out from t_off: the rows outside contact lie on the two free-flight lines,
    and so do the first and last rows in contact, as in the time-centred scheme."""
    cycles = np.arange(1, n + 1)
    t = cycles * DT
    gap = np.where(t <= t_on + DT, -v_in * (t - t_on), -0.01)
    last_in = np.flatnonzero(t < t_off)[-1]
    gap[last_in:] = v_out * (t[last_in:] - t_off)
    return {"cycle": list(cycles), "time": list(t), "g": list(gap)}


def run_of(tmp_path, columns, name="v", **info):
    return load_run(write_run(tmp_path / "runs" / "c" / name, columns, **info))


def test_contact_times_and_restitution_are_exact_on_free_flight_lines(tmp_path):
    run = run_of(tmp_path, collision_columns())
    assert evaluate("contact_start(g)", run) == pytest.approx(0.4375, abs=1e-15)
    assert evaluate("contact_end(g)", run) == pytest.approx(1.3, abs=1e-14)
    assert evaluate("contact_duration(g)", run) == pytest.approx(1.3 - 0.4375, abs=1e-14)
    assert evaluate("restitution(g)", run) == pytest.approx(0.375, rel=1e-13)


def test_a_row_exactly_touching_is_not_in_contact(tmp_path):
    """C&S eq. 8 is strict: gap == 0 on a row is the onset, and the contact starts there."""
    run = run_of(tmp_path, collision_columns(t_on=4 * DT))
    assert evaluate("contact_start(g)", run) == 4 * DT


@pytest.mark.parametrize("change, message", [
    (lambda c: c.update(g=[1.0] * len(c["g"])), "never becomes negative"),
    (lambda c: c.update(g=[x if i < 10 else -0.01 for i, x in enumerate(c["g"])]),
     "start and end inside"),
    (lambda c: c.update(g=[-0.01] + c["g"][1:]), "start and end inside"),
    (lambda c: c.update(cycle=[x + (x > 3) for x in c["cycle"]]), "not consecutive"),
])
def test_collision_problems_are_errors(tmp_path, change, message):
    columns = collision_columns()
    change(columns)
    run = run_of(tmp_path, columns)
    with pytest.raises(EvalError, match=message):
        evaluate("restitution(g)", run)


def test_collision_functions_want_a_whole_column(tmp_path):
    run = run_of(tmp_path, collision_columns())
    with pytest.raises(EvalError, match="whole series column"):
        evaluate("contact_duration(g[2:])", run)


@pytest.mark.parametrize("phase", [0.0, 0.3, 2.1])
def test_sine_fit_is_exact_for_a_sampled_sinusoid(tmp_path, phase):
    n = np.arange(1, 200)
    theta = 2 * math.pi / 17.3
    col = 5.0 + 2.385 * np.sin(n * theta + phase)
    run = run_of(tmp_path, {"cycle": list(n), "time": list(n * DT), "F": list(col)})
    assert evaluate("sine_period(F, 5.0)", run) == pytest.approx(17.3, rel=1e-12)
    assert evaluate("sine_amplitude(after(F, 20), 5.0)", run) == pytest.approx(2.385, rel=1e-12)


def test_sine_fit_refuses_what_is_not_a_sinusoid(tmp_path):
    n = np.arange(1, 20)
    run = run_of(tmp_path, {"cycle": list(n), "time": list(n * DT), "F": [3.0] * 19,
                            "G": list(np.exp(n / 3.0))})
    with pytest.raises(EvalError, match="equals the level"):
        evaluate("sine_period(F, 3.0)", run)
    with pytest.raises(EvalError, match="not a sampled sinusoid"):
        evaluate("sine_amplitude(G, 0)", run)
    with pytest.raises(EvalError, match="at least three"):
        evaluate("sine_period(upto(F, 2), 0)", run)


@pytest.fixture
def orders(tmp_path):
    """Variants whose 'last(Q)' is 1 + 3 dt^2 (order 2), dt = 0.1, 0.05, and one with the
    same dt as another; and the store over them."""
    root = tmp_path / "runs"
    for name, dt in (("coarse", 0.1), ("fine", 0.05), ("same", 0.05), ("finer", 0.025)):
        write_run(root / "c" / name, {"cycle": [1, 2], "time": [dt, 2 * dt],
                                      "Q": [0.0, 1 + 3 * dt * dt]}, dt=dt)
    write_run(root / "c" / "nodt", {"cycle": [1], "time": [1], "Q": [1.0]}, dt=None)
    return RunStore(folder_locator(root))


def order_value(store, expr):
    return evaluate(expr, store.get("c", "fine"), lambda v: store.get("c", v))


def test_order_of_a_second_order_error(orders):
    assert order_value(orders, "order('last(Q)', 1, 'coarse', 'fine')") == pytest.approx(2, abs=1e-9)
    assert order_value(orders, "of('coarse', 'last(Q)')") == pytest.approx(1.03)
    three = "order('last(Q)', 1, 'coarse', 'fine', 'finer')"
    assert order_value(orders, three) == pytest.approx(2, abs=1e-9)
    assert order_value(orders, "order('last(Q)', 1 - 1e-3, 'coarse', 'fine', 'finer')") < 2


@pytest.mark.parametrize("expr, message", [
    ("order('last(Q)', 1, 'fine', 'same')", "same dt"),
    ("order('last(Q)', 1, 'fine')", "at least two"),
    ("order('last(Q)', 1.03, 'coarse', 'fine')", "an error is zero"),
    ("order('last(Q)', 1, 'coarse', 'nodt')", "no positive dt"),
    ("order('last(Q)', 1, 'coarse', 'missing')", "variant 'missing'"),
    ("of('coarse', 'last(R)')", "variant 'coarse'"),
])
def test_order_problems_are_errors(orders, expr, message):
    with pytest.raises(EvalError, match=message):
        order_value(orders, expr)


def test_of_needs_sibling_variants(tmp_path):
    run = run_of(tmp_path, collision_columns())
    with pytest.raises(EvalError, match="no other variants"):
        evaluate("of('x', 'last(g)')", run)


# ---------------------------------------------------------------- the derivations

def load_derive(name):
    spec = importlib.util.spec_from_file_location(name, ROOT / "reference" / "derive" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_hertz_constants_from_the_beta_function():
    """2 I = 2.9433 (t_c V/d_max) and 3.2181 (t_c (K/m12)^(2/5) V^(1/5)), with the
    integral I = int_0^1 (1 - x^(5/2))^(-1/2) dx checked by quadrature (x = 1 - s^2
    removes the endpoint singularity)."""
    col = load_derive("collisions")
    s = np.linspace(0, 1, 200001)
    x = 1 - s * s
    f = 2 * s / np.sqrt(np.maximum(1 - x ** 2.5, 1e-300))
    f[0] = 2 / math.sqrt(2.5)                       # limit s -> 0: 1 - x^2.5 ~ 2.5 s^2
    quad = float(np.sum((f[1:] + f[:-1]) / 2 * np.diff(s)))
    assert col.HERTZ_I == pytest.approx(quad, rel=1e-8)
    assert 2 * col.HERTZ_I == pytest.approx(2.9433, abs=1e-4)
    assert col.hertz_constant() == pytest.approx(3.2181, abs=1e-4)


def test_linear_closed_form_of_the_scheme_matches_its_iteration():
    col = load_derive("collisions")
    for gamma_n in (0.0, 40.0):
        p = dict(kn=7000.0, nu=1.0, delta0=1.0, gamma_n=gamma_n, psi=0.0, dt=2.0 ** -10)
        closed = col.measure(col.discrete_linear(p, 1.13, 2.0)[0], p["dt"])
        iterated = col.measure(col.discrete_iterate(p, 1.13, 2.0), p["dt"])
        assert closed == pytest.approx(iterated, rel=1e-11)


def test_undamped_linear_error_has_the_leading_term():
    """t_c error -(omega0 dt)^2/24 t_c to leading order (2 sin(theta/2) = omega0 dt)."""
    col = load_derive("collisions")
    p = dict(kn=7000.0, nu=1.0, delta0=1.0, gamma_n=0.0, psi=0.0, dt=2.0 ** -14)
    tc, _, omega = col.closed_form(p, 1.13, 2.0)
    tcd, _ = col.discrete(p, 1.13, 2.0)
    assert (tcd - tc) / tc == pytest.approx(-(omega * p["dt"]) ** 2 / 24, rel=1e-3)


def test_figure_constants_are_the_derived_closed_forms():
    """The y expressions of cases/collisions figures subtract closed forms by value."""
    col = load_derive("collisions")
    common, variants = col.read_inputs()
    derived = {f"{fam}": col.closed_form(variants[f"{fam}_9"], common["m12"], common["V"])
               for fam in col.FAMILIES}
    text = (ROOT / "cases" / "collisions" / "case.txt").read_text()
    for fig, fam, idx in (("tc_linear", "linear", 0), ("tc_damped", "damped", 0),
                          ("r_damped", "damped", 1), ("tc_hertz", "hertz", 0)):
        block = text.split(f"[figure {fig}]", 1)[1].split("\n[", 1)[0]
        y = re.search(r"^y = .* - ([0-9.e+-]+)\)$", block, re.M).group(1)
        assert float(y) == derived[fam][idx], fig


def test_two_discs_figure_constant_is_the_derived_amplitude():
    order = load_derive("two_discs_order")
    p = order.read_scene(order.SCENE)
    m = p["rho"] * math.pi * p["r"] ** 2
    omega, T = math.sqrt(3 * p["k"] / m), p["load"] * p["dt"]
    amp = 4 * p["k"] * p["v"] / (3 * omega) * abs(math.sin(omega * T / 2))
    text = (ROOT / "cases" / "two_discs" / "case.txt").read_text()
    block = text.split("[figure order_amplitude]", 1)[1]
    y = re.search(r"^y = .* - ([0-9.e+-]+)\)$", block, re.M).group(1)
    assert float(y) == amp
