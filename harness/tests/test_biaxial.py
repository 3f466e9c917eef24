"""The biaxial family (harness/families/biaxial.py) on synthetic runs with known answers
(biaxial_fakes.py): stresses, strains against hand values, the start of the shearing, the
mobilised, peak and residual friction angles, the envelope's slope and intercept, and the
clear EvalErrors of what cannot be evaluated.

Kept whole (about 660 lines): the tests of one family module, all on the same fixtures (the
synthetic store of runs and its expected values); split, those fixtures would move to a
conftest.py that only these tests read."""
import json
import math
import shutil
from dataclasses import replace

import numpy as np
import pytest

from harness import catalogue, references, report
from harness.compare import RunStore, evaluate, evaluate_all, evaluate_array, folder_locator
from harness.errors import EvalError, IniError
from harness.families import biaxial
from harness.report import plots
from harness.tests import biaxial_fakes as fake

CASE = "biax"


@pytest.fixture
def store(tmp_path):
    """Variants of case biax: three confining stresses of a material on the line t = 0.5 s + 10 kPa
    at the peak and t = 0.35 s at the residual; and a cohesionless one (m0)."""
    root = tmp_path / "runs" / CASE
    for kpa in (100, 200, 400):
        sh = kpa * 1e3
        fake.write_biaxial_run(root / f"m1_d0.4_s{kpa}", sh, fake.on_line(sh, 0.5, 10e3), fake.on_line(sh, 0.35, 0))
        fake.write_biaxial_run(root / f"m0_s{kpa}", sh, fake.on_line(sh, 0.4, 0), fake.on_line(sh, 0.3, 0))
    return RunStore(folder_locator(tmp_path / "runs"))


def value(store, expr, variant="m1_d0.4_s200"):
    return evaluate(expr, store.get(CASE, variant), lambda other: store.get(CASE, other))


def array(store, expr, variant="m1_d0.4_s200"):
    run = store.get(CASE, variant)
    names = dict(run.columns)
    names.update(biaxial.bind(run, lambda other: store.get(CASE, other)))
    return np.asarray(eval(expr, {"__builtins__": {}}, names))   # noqa: S307 -- the test's own text


def eps_rows():
    """The natural axial strain of the shearing rows: 0, 0.001, ..., 0.2."""
    return np.arange(0, fake.SHEAR + 1, fake.EVERY) * fake.RATE


# ---------------------------------------------------------------- stresses and strains

def test_stresses_against_the_construction(store):
    sh = 200e3
    t = fake.deviator(eps_rows(), fake.on_line(sh, 0.5, 10e3), fake.on_line(sh, 0.35, 0))
    assert array(store, "sigma_h()") == pytest.approx(np.full(t.size, sh), rel=1e-12)
    assert array(store, "sigma_v()") == pytest.approx(sh + 2 * t, rel=1e-12)
    assert array(store, "deviator()") == pytest.approx(t, rel=1e-12, abs=1e-6)
    assert array(store, "mean_stress()") == pytest.approx(sh + t, rel=1e-12)


def test_stresses_by_hand():
    """sigma_v = (|fy_top| + |fy_bottom|)/2 / width, sigma_h = (|fx_left| + |fx_right|)/2 / height."""
    cols = {"cycle": np.array([1.0]), "fy_top": np.array([30.0]), "fy_bottom": np.array([-10.0]),
            "fx_left": np.array([-6.0]), "fx_right": np.array([2.0]), "y_top": np.array([5.0]),
            "y_bottom": np.array([1.0]), "x_left": np.array([-1.0]), "x_right": np.array([1.0])}
    sv, sh = biaxial.stresses(cols)
    assert (sv[0], sh[0]) == (10.0, 1.0)                                     # 20 / 2, 4 / 4
    assert biaxial.mobilised(sv, sh, cols["cycle"])[0] == pytest.approx(math.degrees(math.asin(9 / 11)))


def test_strains_by_hand():
    """H 1 -> 0.9, W 1 -> 1.05: natural ln(1/0.9), ln(1/1.05); engineering 0.1, -0.05."""
    height, width = np.array([1.0, 0.95, 0.9]), np.array([1.0, 1.02, 1.05])
    assert biaxial.strain(height)[-1] == pytest.approx(0.105360515657826)
    assert biaxial.strain(width)[-1] == pytest.approx(-0.048790164169432)
    assert biaxial.strain(height, "engineering")[-1] == pytest.approx(0.1)
    assert biaxial.strain(width, "engineering")[-1] == pytest.approx(-0.05)
    assert biaxial.strain(height)[0] == 0.0
    with pytest.raises(EvalError, match="measure must be one of natural, engineering"):
        biaxial.strain(height, "true")


def test_strains_against_the_construction(store):
    eps = eps_rows()
    assert array(store, "axial_strain()") == pytest.approx(eps, abs=1e-14)
    assert array(store, "axial_strain('engineering')") == pytest.approx(1 - np.exp(-eps), abs=1e-14)
    assert array(store, "volumetric_strain()") == pytest.approx(fake.volumetric(eps), abs=1e-14)
    assert array(store, "lateral_strain()") == pytest.approx(fake.volumetric(eps) - eps, abs=1e-14)
    engineering = (1 - np.exp(-eps)) + (1 - np.exp(-(fake.volumetric(eps) - eps)))
    assert array(store, "volumetric_strain('engineering')") == pytest.approx(engineering, abs=1e-14)
    # compresses to 0.003 at eps_a = 0.01, then dilates at slope 0.5 to 0.003 - 0.095 at 0.2
    assert value(store, "max(volumetric_strain())") == pytest.approx(0.003)
    assert value(store, "dilation()") == pytest.approx(0.095)
    assert value(store, "last(volumetric_strain())") < 0


# ---------------------------------------------------------------- the start of the shearing

def test_the_shearing_starts_at_the_stage_named_shear(store):
    assert value(store, "shear_start()") == fake.CONSOLIDATE
    assert array(store, "sigma_v()").size == fake.SHEAR // fake.EVERY + 1
    assert value(store, "shear_start(start='consolidate')") == fake.EVERY    # the first row
    assert value(store, "shear_start(start=300)") == 300
    assert value(store, "shear_start(start=295)") == 300                     # first row at or after
    assert value(store, "first(axial_strain(start=300))") == 0.0
    assert value(store, "last(axial_strain(start=300))") == pytest.approx(0.2 - 0.02)


def test_a_stage_stopped_between_rows_starts_at_the_next_row(tmp_path):
    """A consolidation stopped by its rule at cycle 95: the reference row is the one at 100."""
    fake.write_biaxial_run(tmp_path / CASE / "v", info={"stages": fake.stages(consolidate=95, shear=2005)})
    assert evaluate("shear_start()", RunStore(folder_locator(tmp_path)).get(CASE, "v")) == 100


def test_the_start_of_the_shearing_from_run_json():
    assert biaxial.stage_start({"stages": fake.stages(120, 50)}, "shear") == 120.0
    assert biaxial.stage_start({"stages": fake.stages(120, 50)}, "consolidate") == 0.0
    stages = fake.stages(120, 50) + [{"name": "unload", "cycles": 30}]
    assert biaxial.stage_start({"stages": stages}, "unload") == 170.0


@pytest.mark.parametrize("info, start, words", [
    ({}, None, "run.json has no stages"),
    ({"stages": fake.stages(name="load")}, None,
     "run.json has no stage 'shear' (stages: consolidate, load): name the shearing stage [stage shear], "
     "or give start='STAGE' or start=CYCLE"),
    ({"stages": fake.stages()}, "nope", "run.json has no stage 'nope'"),
    ({"stages": fake.stages(shear=0)}, None, "stage 'shear' ran no cycles"),
    ({"stages": [{"name": "shear"}]}, None, "do not all give their cycles run"),
    ({"stages": fake.stages()}, 2100, "fewer than 2 rows at or after cycle 2100, the start of the shearing "
                                      "(last row: cycle 2100)"),
    ({"stages": fake.stages()}, 5000, "fewer than 2 rows at or after cycle 5000"),
    ({"stages": fake.stages()}, [1], "start must be a stage name or a cycle, not [1]"),
])
def test_a_bad_start_says_why(info, start, words):
    cycle = np.arange(10.0, 2101.0, 10.0)
    with pytest.raises(EvalError) as caught:
        biaxial.start_row(cycle, info, start)
    assert words in str(caught.value)


# ---------------------------------------------------------------- friction angles

def sin_phi(t, sh):
    return t / (sh + t)


def test_the_mobilised_angle_is_jyh_s(store):
    sh = 200e3
    t = fake.deviator(eps_rows(), fake.on_line(sh, 0.5, 10e3), fake.on_line(sh, 0.35, 0))
    assert array(store, "phi()") == pytest.approx(np.degrees(np.arcsin(sin_phi(t, sh))), abs=1e-12)
    assert array(store, "phi()")[0] == pytest.approx(0.0, abs=1e-12)           # isotropic at the start


def test_peak_and_residual(store):
    sh = 200e3
    t_peak, t_res = fake.on_line(sh, 0.5, 10e3), fake.on_line(sh, 0.35, 0)
    peak, res = (math.degrees(math.asin(sin_phi(t, sh))) for t in (t_peak, t_res))
    assert value(store, "phi_peak()") == pytest.approx(peak, abs=1e-12)
    assert value(store, "peak_cycle()") == fake.CONSOLIDATE + fake.EPS_PEAK / fake.RATE
    assert value(store, "at_peak(axial_strain())") == pytest.approx(fake.EPS_PEAK)
    assert value(store, "at_peak(mean_stress())") == pytest.approx(sh + t_peak)
    assert value(store, "at_peak(deviator())") == pytest.approx(t_peak)
    assert value(store, "phi_residual(0.1, 0.19)") == pytest.approx(res, abs=1e-12)
    assert value(store, "window_mean(deviator(), 0.1, 0.19)") == pytest.approx(t_res)
    assert value(store, "residual_drift(0.1, 0.19)") == pytest.approx(0.0, abs=1e-12)
    assert value(store, "phi_peak() - phi_residual(0.1, 0.19)") > 5          # it softens


def test_a_peak_over_several_rows_is_their_mean(store):
    """rows = 3: t rises to the peak at 7.3 MPa per unit strain and falls after it at 2.2, so the
    three consecutive rows of the largest mean are the peak and the two after it (eps 0.030,
    0.031, 0.032), not the rows either side of it; peak_cycle is the middle one's."""
    sh = 200e3
    t_peak, t_res = fake.on_line(sh, 0.5, 10e3), fake.on_line(sh, 0.35, 0)
    slopes = t_peak / fake.EPS_PEAK, (t_peak - t_res) / (fake.EPS_RES - fake.EPS_PEAK)
    assert slopes == pytest.approx((7.33e6, 2.25e6), rel=1e-2)
    t = fake.deviator(np.array([0.030, 0.031, 0.032]), t_peak, t_res)
    angles = np.degrees(np.arcsin(sin_phi(t, sh)))
    assert value(store, "phi_peak(rows=3)") == pytest.approx(angles.mean(), abs=1e-12)
    assert value(store, "peak_cycle(rows=3)") == fake.CONSOLIDATE + 310
    assert value(store, "at_peak(deviator(), rows=3)") == pytest.approx(t.mean())


def test_the_drift_shows_a_residual_not_yet_reached(store):
    """Over [0.0305, 0.0905] (mid 0.0605; edges between rows) phi still falls until 0.08: the
    upper half's mean is below the lower's."""
    sh = 200e3
    t_peak, t_res = fake.on_line(sh, 0.5, 10e3), fake.on_line(sh, 0.35, 0)
    lower, upper = np.arange(31, 61) * 1e-3, np.arange(61, 91) * 1e-3        # the rows of each half
    mean_phi = lambda eps: np.degrees(np.arcsin(sin_phi(fake.deviator(eps, t_peak, t_res), sh))).mean()
    assert value(store, "residual_drift(0.0305, 0.0905)") == pytest.approx(mean_phi(upper) - mean_phi(lower), abs=1e-9)
    assert value(store, "residual_drift(0.0305, 0.0905)") < -3


def test_the_drift_needs_two_rows_in_each_half():
    """Rows at 0, 0.1, 0.2, 0.3 and 1: window [0, 1] holds five, its lower half [0, 0.5) four and
    its upper half one."""
    eps = np.array([0.0, 0.1, 0.2, 0.3, 1.0])
    assert biaxial.drift(np.array([1.0, 1.0, 2.0, 2.0, 2.0]), eps, 0.0, 0.35) == 1.0
    with pytest.raises(EvalError, match=r"residual_drift\(\): each half of window \[0, 1\] needs two rows \(has 4 and 1\)"):
        biaxial.drift(np.ones(5), eps, 0.0, 1.0)


@pytest.mark.parametrize("expr, words", [
    ("phi_residual(0.1, 0.3)", "phi_residual(): window [0.1, 0.3] of axial strain outside the data "
                               "(the shearing spans 0 to 0.2)"),
    ("phi_residual(-0.01, 0.1)", "outside the data"),
    ("phi_residual(0.1, 0.1)", "phi_residual(): the window needs lo < hi, not [0.1, 0.1]"),
    ("phi_residual(0.1, 0.1015)", "phi_residual(): 2 row(s) in window [0.1, 0.1015], fewer than 4"),
    ("window_mean(deviator(), 0.1, 0.2, start='consolidate')",
     "window_mean(): the first argument must be a per-row array of the shearing (210 rows"),
    ("window_mean(deviator(start='consolidate'), 0.1, 0.2, start='consolidate')", None),
    ("window_mean(fy_top, 0.1, 0.19)", "window_mean(): the first argument must be a per-row array of the "
                                      "shearing (201 rows, e.g. mean_stress()), not of shape (210,)"),
    ("at_peak(3)", "at_peak(): the first argument must be a per-row array"),
    ("phi_peak(rows=0)", "phi_peak(): rows must be 1 to 201 (the shearing's rows), not 0"),
    ("phi_peak(rows=2.5)", "phi_peak(): rows must be a whole number, not 2.5"),
])
def test_windows_and_arrays_that_cannot_be_used(store, expr, words):
    if words is None:      # a start that moves the shearing moves the window's strains with it
        assert value(store, expr) > 0
        return
    with pytest.raises(EvalError) as caught:
        value(store, expr)
    assert words in str(caught.value)


def test_missing_columns_and_unusable_rows(tmp_path):
    cols = fake.columns(200e3, 1e5, 6e4)
    store = RunStore(folder_locator(tmp_path))
    fake.write_biaxial_run(tmp_path / CASE / "short", cols={k: v for k, v in cols.items() if k != "x_left"})
    with pytest.raises(EvalError, match=r"column\(s\) missing from series.tsv: x_left \(a biaxial run writes"):
        evaluate("phi_peak()", store.get(CASE, "short"))
    flat = dict(cols, fy_top=0 * cols["fy_top"], fy_bottom=0 * cols["fy_top"], fx_left=0 * cols["fx_left"],
                fx_right=0 * cols["fx_left"])
    fake.write_biaxial_run(tmp_path / CASE / "flat", cols=flat)
    with pytest.raises(EvalError, match="sigma_v \\+ sigma_h is 0, not positive, at cycle 100: no stress"):
        evaluate("phi_peak()", store.get(CASE, "flat"))
    crossed = dict(cols, x_right=cols["x_left"] - 1)
    fake.write_biaxial_run(tmp_path / CASE / "crossed", cols=crossed)
    with pytest.raises(EvalError, match="x_right - x_left is -1, not positive, at cycle 100"):
        evaluate("sigma_v()", store.get(CASE, "crossed"))


# ---------------------------------------------------------------- the strength envelope

def test_the_peak_envelope_has_the_known_slope_and_intercept(store):
    """Peaks on t = 0.5 s + 10 kPa: sin phi = 0.5 (30 degrees), c cos phi = 10 kPa."""
    names = "'m1_d0.4_s100', 'm1_d0.4_s200', 'm1_d0.4_s400'"
    assert value(store, f"phi_envelope('peak', {names})") == pytest.approx(30.0, abs=1e-9)
    assert value(store, f"cohesion_envelope('peak', {names})") == pytest.approx(10e3 / math.cos(math.pi / 6))
    assert value(store, "phi_envelope('peak', 'm0_s100', 'm0_s400')") == pytest.approx(
        math.degrees(math.asin(0.4)), abs=1e-9)
    assert value(store, "cohesion_envelope('peak', 'm0_s100', 'm0_s200', 'm0_s400')") == pytest.approx(0, abs=1e-6)


def test_the_residual_envelope(store):
    names = "'m1_d0.4_s100', 'm1_d0.4_s200', 'm1_d0.4_s400'"
    assert value(store, f"phi_envelope('residual', {names}, lo=0.1, hi=0.19)") == pytest.approx(
        math.degrees(math.asin(0.35)), abs=1e-9)
    assert value(store, f"cohesion_envelope('residual', {names}, lo=0.1, hi=0.19)") == pytest.approx(0, abs=1e-6)


def test_the_envelope_of_this_variants_material(store):
    """'_s100' etc. name this variant's material at another confining stress, so one quantity
    serves every material of a trend check (evaluated in m0_s200 and in m1_d0.4_s100)."""
    q = "phi_envelope('peak', '_s100', '_s200', '_s400')"
    assert value(store, q, "m0_s200") == pytest.approx(math.degrees(math.asin(0.4)), abs=1e-9)
    assert value(store, q, "m1_d0.4_s100") == pytest.approx(30.0, abs=1e-9)
    assert biaxial.resolve("_s400", "m1_d0.4_s100_r2") == "m1_d0.4_s400_r2"
    assert biaxial.resolve("m0_s100", "m1_d0.4_s100") == "m0_s100"
    assert biaxial.resolve("_soft", "m1_s100") == "_soft"


def test_the_spread_of_a_quantity_over_variants(store):
    """Peak less residual envelope angle: m1 asin 0.5 - asin 0.35, m0 asin 0.4 - asin 0.3."""
    soft = "phi_envelope('peak', '_s100', '_s200', '_s400') - phi_envelope('residual', '_s100', '_s200', '_s400', lo=0.1, hi=0.19)"
    m1, m0 = (math.degrees(math.asin(a) - math.asin(b)) for a, b in ((0.5, 0.35), (0.4, 0.3)))
    assert value(store, f'spread("{soft}", "m1_d0.4_s100", "m0_s400")', "m0_s100") == pytest.approx(abs(m1 - m0), abs=1e-9)
    assert value(store, 'spread("phi_peak()", "m0_s100", "m0_s200", "m0_s400")') == pytest.approx(0, abs=1e-9)
    # with cohesion, the angle of each test falls with the confining stress: 100 kPa above 400
    angle = [math.degrees(math.asin(sin_phi(fake.on_line(sh, 0.5, 10e3), sh))) for sh in (100e3, 400e3)]
    assert value(store, 'spread("phi_peak()", "m1_d0.4_s100", "m1_d0.4_s200", "m1_d0.4_s400")') == pytest.approx(
        angle[0] - angle[1], abs=1e-9)
    with pytest.raises(EvalError, match="spread\\(\\): needs at least two variants"):
        value(store, 'spread("phi_peak()", "m0_s100")')
    with pytest.raises(EvalError, match="of\\(\\): variant 'nope'"):
        value(store, 'spread("phi_peak()", "m0_s100", "nope")')


def test_the_envelope_fit_by_hand():
    """Three points off a line: the least-squares slope and intercept of numpy's own normal equations."""
    points = [(100.0, 52.0), (200.0, 98.0), (400.0, 201.0)]
    s, t = np.array(points).T
    a = ((s - s.mean()) * (t - t.mean())).sum() / ((s - s.mean()) ** 2).sum()
    b = t.mean() - a * s.mean()
    phi, c = biaxial.envelope(points)
    assert math.sin(math.radians(phi)) == pytest.approx(a) and c * math.cos(math.radians(phi)) == pytest.approx(b)


@pytest.mark.parametrize("expr, words", [
    ("phi_envelope('peak', 'm0_s100')", "phi_envelope(): needs two or more variants, has 1"),
    ("phi_envelope('peak', 'm0_s100', 'm0_s100', 'm0_s200')", "phi_envelope(): variant(s) m0_s100 named twice"),
    ("phi_envelope('peak', '_s100', 'm0_s100')", "variant(s) m0_s100 named twice"),
    ("phi_envelope('crest', 'm0_s100', 'm0_s200')", "phi_envelope(): kind must be one of peak, residual, not 'crest'"),
    ("phi_envelope('residual', 'm0_s100', 'm0_s200')", "a residual envelope needs its window: lo=..., hi=..."),
    ("phi_envelope('peak', 'm0_s100', 'm0_s200', lo=0.1, hi=0.19)", "a peak envelope takes no window"),
    ("cohesion_envelope('residual', 'm0_s100', 'm0_s200', lo=0.1, hi=0.4)",
     "cohesion_envelope(): variant 'm0_s100': cohesion_envelope(): window [0.1, 0.4] of axial strain outside"),
    ("phi_envelope('peak', 'm0_s100', 'nope_s100')", "phi_envelope(): variant 'nope_s100': run output missing"),
    ("phi_envelope('peak', 'm0_s100', 'm0_s200', rows=0)", "phi_envelope(): variant 'm0_s100': phi_envelope(): rows must"),
    ("phi_envelope('peak', 'm0_s100', 3)", "a variant must be a name in quotes, not 3"),
])
def test_envelopes_that_cannot_be_made(store, expr, words):
    with pytest.raises(EvalError) as caught:
        value(store, expr, "m0_s200")
    assert words in str(caught.value), str(caught.value)


def test_an_envelope_needs_different_mean_stresses_and_a_sine():
    with pytest.raises(EvalError, match="needs two or more different mean stresses, has 300000, 300000"):
        biaxial.envelope([(300e3, 1e5), (300e3, 1.2e5)])
    with pytest.raises(EvalError, match="the envelope's slope 2 is no sine of an angle"):
        biaxial.envelope([(1.0, 1.0), (2.0, 3.0)])


def test_a_relative_name_needs_one_confining_stress_part(store, tmp_path):
    store2 = RunStore(folder_locator(tmp_path / "runs"))
    fake.write_biaxial_run(tmp_path / "runs" / CASE / "plain")
    with pytest.raises(EvalError, match="'_s200' replaces the confining-stress part '_s<digits>' of this "
                                        "variant's name, but 'plain' has 0 such parts"):
        evaluate("phi_envelope('peak', 'plain', '_s200')", store2.get(CASE, "plain"), lambda v: store2.get(CASE, v))


def test_setting_reads_the_runs_overrides(tmp_path):
    info = {"sets": ["material.grain.delta=0.4", "stage.shear.cycles=2000", "material.grain.delta=0.8", "x=y"]}
    fake.write_biaxial_run(tmp_path / CASE / "v", info=info)
    run = RunStore(folder_locator(tmp_path)).get(CASE, "v")
    assert evaluate("setting('material.grain.delta')", run) == 0.8           # the last one given
    with pytest.raises(EvalError, match="the run has no --set material.wall.delta=... \\(its sets: "):
        evaluate("setting('material.wall.delta')", run)
    with pytest.raises(EvalError, match="--set x=y is not a number"):
        evaluate("setting('x')", run)
    assert json.loads((tmp_path / CASE / "v" / "run.json").read_text())["sets"][0] == "material.grain.delta=0.4"


def test_the_strain_rate_of_a_run_and_the_fastest_rate_within_a_tolerance():
    info = {"sets": ["stage.shear.strain_rate=spec_top 0.5 spec_bottom", "stage.shear.strain_rate=spec_top 0.125 b",
                     "stage.load.strain_rate=w", "stage.other.strain_rate=w x y"]}
    assert biaxial.rate_of(info) == 0.125                                     # the last one given
    with pytest.raises(EvalError, match="gives no rate"):
        biaxial.rate_of(info, "load")
    with pytest.raises(EvalError, match="gives no rate"):
        biaxial.rate_of(info, "other")
    with pytest.raises(EvalError, match="no --set stage.consolidate.strain_rate"):
        biaxial.rate_of(info, "consolidate")
    # rates 0.125 (the reference) ... 4, in any order; 2 /s is within 0.6 but 1 /s is not
    rates, errors = [4, 0.125, 0.25, 0.5, 1, 2], [3.0, 0.0, 0.2, -0.4, 0.7, 0.1]
    assert biaxial.fastest_within_of(rates, errors, 0.5) == 0.5
    assert biaxial.fastest_within_of(rates, errors, 0.7) == 2
    assert biaxial.fastest_within_of(rates, errors, 3.0) == 4
    assert biaxial.fastest_within_of(rates, errors, 0.1) == 0.125
    assert biaxial.fastest_within_of([0.25, 0.5], [0.2, 0.0], 0.1) is None
    assert biaxial.fastest_within_of(rates, [float("nan")] + errors[1:], 10) == 2   # NaN is never within


# ---------------------------------------------------------------- figures: JYH Figs 11-13

needs_gnuplot = pytest.mark.skipif(not shutil.which("gnuplot"), reason="gnuplot not installed")

DELTAS, SEEDS, KPA = (0.0, 0.4, 1.6), (1, 2), (100, 200, 400)


def peak_sine(delta, seed):
    """The synthetic material's sin phi at the peak: 0.4 + 0.1 delta, seed 1 0.005 below, seed 2 above."""
    return 0.4 + 0.1 * delta + (0.005 if seed == 2 else -0.005)


def residual_sine(delta, seed):
    return 0.3 + 0.1 * delta + (0.005 if seed == 2 else -0.005)


def name(delta, kpa, seed):
    return f"m1_d{delta}_s{kpa}_r{seed}"


NAMES = [name(d, k, r) for d in DELTAS for r in SEEDS for k in KPA]
FIGURE_CASE = "[case biax]\ntier = full\ntitle = t\nchecks = c\nruntime = 1\n" + "".join(
    f"\n[variant {v}]\nscene = biaxial.scene\n" for v in NAMES + ["unrun_s100"])

FIG11 = """
[figure fig11a]
kind = curves
variants = m1_d0.0_s200_r1 m1_d1.6_s200_r1
x = 100 * axial_strain()
y = (sigma_v() - sigma_h()) / 2 / 1000
xlabel = axial strain (%)
ylabel = (sigma_v - sigma_h)/2 (kPa)
paper = "deviatoric stress (sigma_v - sigma_h)/2 against axial strain" (JYH 2005, Fig. 11(a))
"""

FIG12 = """
[figure fig12]
kind = fit
group = no rolling; m1_d0.0_s100_r1 m1_d0.0_s200_r1 m1_d0.0_s400_r1
group = Model 1, delta 1.6; m1_d1.6_s100_r1 m1_d1.6_s200_r1 m1_d1.6_s400_r1
x = peak; at_peak(mean_stress()) / 1000
y = peak; at_peak(deviator()) / 1000
x = residual; window_mean(mean_stress(), 0.1, 0.19) / 1000
y = residual; window_mean(deviator(), 0.1, 0.19) / 1000
slope = asin
xlabel = (sigma_v + sigma_h)/2 (kPa)
ylabel = (sigma_v - sigma_h)/2 (kPa)
"""

FIG13 = """
[figure fig13]
kind = errorbars
variants = """ + " ".join(name(d, 100, r) for d in DELTAS for r in SEEDS) + """
x = setting('material.grain.delta')
y = ballast peak; phi_envelope('peak', '_s100', '_s200', '_s400')
y = ballast residual; phi_envelope('residual', '_s100', '_s200', '_s400', lo=0.1, hi=0.19)
paper_point = 0 24.4 JYH 2005
paper_point = 0 19.3 JYH 2005
paper_point = 1.6 42.3 JYH 2005
paper_point = 1.6 35.8 JYH 2005
paper_point = 0.4 26.5 JYH 2005, Model 2
xlabel = delta
ylabel = phi (degrees)
"""


@pytest.fixture
def figure_store(tmp_path):
    """Model 1 materials delta = 0, 0.4, 1.6 with seeds 1 and 2 at 100, 200 and 400 kPa: peaks on
    t = peak_sine s, residuals on t = residual_sine s (no cohesion); setting() gives delta."""
    for delta in DELTAS:
        for seed in SEEDS:
            for kpa in KPA:
                sh = kpa * 1e3
                fake.write_biaxial_run(tmp_path / "runs" / "biax" / name(delta, kpa, seed), sh,
                                       fake.on_line(sh, peak_sine(delta, seed), 0),
                                       fake.on_line(sh, residual_sine(delta, seed), 0),
                                       info={"sets": [f"material.grain.delta={delta}"]})
    return RunStore(folder_locator(tmp_path / "runs"))


def load_case(tmp_path, figures):
    folder = tmp_path / "cases" / "biaxial"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "case.txt").write_text(FIGURE_CASE + figures)
    return catalogue.load(tmp_path / "cases")[0]


def script_data(tmp_path, store, figures, kind_script):
    """Run a figure's script maker in a scratch folder: (script, notes, {data file: rows})."""
    case = load_case(tmp_path, figures)
    work = tmp_path / "work"
    work.mkdir(exist_ok=True)
    text, notes = kind_script(case, case.figures[0], store, work, work / "f.png", work / "f.svg")
    data = {p.name: np.loadtxt(p, ndmin=2) for p in sorted(work.glob("*.dat"))}
    return text, notes, data


def test_a_curve_is_an_array_expression(store):
    run = store.get(CASE, "m0_s100")
    assert evaluate_array("100 * axial_strain()", run).shape == (201,)
    assert evaluate_array("phi_peak()", run).shape == (1,)
    with pytest.raises(EvalError, match="'sigma_v\\(\\)\\[:0\\]' gives no values, not a row of numbers"):
        evaluate_array("sigma_v()[:0]", run)
    with pytest.raises(EvalError, match="gives an array of shape \\(2, 201\\), not a row of numbers"):
        evaluate_array("[phi(), phi()]", run)
    with pytest.raises(EvalError, match="is not a number or an array of numbers: 'x'"):
        evaluate_array("'x'", run)


def test_the_new_figure_kinds_are_read(tmp_path):
    case = load_case(tmp_path, FIG11 + FIG12 + FIG13)
    curves, fit, bars = case.figures
    assert (curves.kind, curves.x, curves.y, curves.labels) == (
        "curves", "100 * axial_strain()", ["(sigma_v() - sigma_h()) / 2 / 1000"], ["(sigma_v() - sigma_h()) / 2 / 1000"])
    assert (curves.xlabel, curves.ylabel) == ("axial strain (%)", "(sigma_v - sigma_h)/2 (kPa)")
    assert fit.groups[1] == ("Model 1, delta 1.6", ["m1_d1.6_s100_r1", "m1_d1.6_s200_r1", "m1_d1.6_s400_r1"])
    assert fit.labels == ["peak", "residual"] and fit.xs[1] == "window_mean(mean_stress(), 0.1, 0.19) / 1000"
    assert fit.slope == "asin" and fit.variants == [name(d, k, 1) for d in (0.0, 1.6) for k in KPA]
    assert bars.labels == ["ballast peak", "ballast residual"] and len(bars.variants) == 6
    assert bars.paper_points[-1] == (0.4, 26.5, "JYH 2005, Model 2")


@pytest.mark.parametrize("figure, words", [
    ("[figure f]\nkind = fit\nvariants = m1_d0.0_s100_r1\ngroup = a; m1_d0.0_s100_r1 m1_d0.0_s200_r1\nx = 1\ny = 2\n",
     "'variants' does not apply to a fit figure"),
    ("[figure f]\nkind = fit\ngroup = a; m1_d0.0_s100_r1\nx = 1\ny = 2\n",
     "'group' must be 'LABEL; VARIANT VARIANT ...' (two or more variants)"),
    ("[figure f]\nkind = fit\ngroup = m1_d0.0_s100_r1 m1_d0.0_s200_r1\nx = 1\ny = 2\n", "'group' must be 'LABEL;"),
    ("[figure f]\nkind = fit\nx = 1\ny = 2\n", "needs 'group = LABEL; VARIANT VARIANT ...'"),
    ("[figure f]\nkind = fit\ngroup = a; m1_d0.0_s100_r1 nope\nx = 1\ny = 2\n", "names unknown variant 'nope'"),
    ("[figure f]\nkind = fit\ngroup = a; m1_d0.0_s100_r1 m1_d0.0_s200_r1\nx = 1\ny = 2\ny = 3\n",
     "a fit figure pairs each 'x' with a 'y': it has 1 x and 2 y"),
    ("[figure f]\nkind = fit\ngroup = a; m1_d0.0_s100_r1 m1_d0.0_s200_r1\nx = 1\ny = 2\nslope = atan\n",
     "'slope' must be one of number, asin, not 'atan'"),
    ("[figure f]\nkind = curves\nx = axial_strain()\n", "needs 'y = [LABEL;] EXPR'"),
    ("[figure f]\nkind = curves\nx = axial_strain()\ny = a; phi(\n", "'y' is not an expression"),
    ("[figure f]\nkind = curves\nx = axial_strain()\ny = a;\n", "'y' is empty"),
    ("[figure f]\nkind = curves\nx = axial_strain()\ny = phi()\nslope = asin\n", "'slope' does not apply to a curves"),
    ("[figure f]\nkind = errorbars\nx = 1\ny = 2\npaper_point = 0 24.4\n", "'paper_point' must be 'X Y LABEL'"),
    ("[figure f]\nkind = errorbars\nx = 1\ny = 2\npaper_point = zero 24.4 JYH\n", "'paper_point' must be 'X Y LABEL'"),
    ("[figure f]\nkind = errorbars\ny = 2\n", "needs 'x = ...'"),
])
def test_bad_new_figures_are_refused(tmp_path, figure, words):
    with pytest.raises(IniError) as caught:
        load_case(tmp_path, "\n" + figure)
    assert "case.txt:" in str(caught.value) and words in str(caught.value), str(caught.value)


def test_fig11_curves_draw_the_deviator_against_the_axial_strain_in_kpa_and_percent(tmp_path, figure_store):
    text, notes, data = script_data(tmp_path, figure_store, FIG11, plots._curves_script)
    assert notes == [] and sorted(data) == ["m1_d0.0_s200_r1_0.dat", "m1_d1.6_s200_r1_0.dat"]
    rows = data["m1_d1.6_s200_r1_0.dat"]
    t_peak = fake.on_line(200e3, peak_sine(1.6, 1), 0)
    assert rows[0] == pytest.approx([0, 0], abs=1e-9) and rows[-1, 0] == pytest.approx(20.0)
    assert rows[:, 1].max() == pytest.approx(t_peak / 1000) and rows[30] == pytest.approx([3.0, t_peak / 1000])
    assert "title 'm1_d1.6_s200_r1'" in text and "set xlabel 'axial strain (%)'" in text


def test_fig11_curves_note_what_they_cannot_draw(tmp_path, figure_store):
    figure = FIG11.replace("variants = m1_d0.0_s200_r1", "variants = unrun_s100 m1_d0.0_s200_r1").replace(
        "y = (sigma_v()", "y = eps; 100 * volumetric_strain()\ny = bad; phi()[:3]\ny = (sigma_v()")
    text, notes, data = script_data(tmp_path, figure_store, figure, plots._curves_script)
    assert notes[0].startswith("unrun_s100: not drawn: run output missing")
    assert notes[1:] == [f"{v}: bad: not drawn: 3 values against 201 of x" for v in ("m1_d0.0_s200_r1", "m1_d1.6_s200_r1")]
    assert len(data) == 4 and text.count("with lines title") == 4


def test_fig12_fit_draws_points_and_envelopes_with_their_angle(tmp_path, figure_store):
    text, notes, data = script_data(tmp_path, figure_store, FIG12, plots._fit_script)
    assert notes == []
    points, line = data["fit_1_0.dat"], data["line_1_0.dat"]                 # Model 1, delta 1.6, peak
    sine = peak_sine(1.6, 1)
    s = [kpa + fake.on_line(kpa * 1e3, sine, 0) / 1e3 for kpa in KPA]
    assert points[:, 0] == pytest.approx(s) and points[:, 1] == pytest.approx(sine * np.array(s))
    assert line == pytest.approx(np.array([[0, 0], [s[-1], sine * s[-1]]]), abs=1e-9)
    angle = math.degrees(math.asin(residual_sine(0.0, 1)))
    assert f"title 'no rolling, residual: asin(slope) {angle:.1f} deg, intercept 0'" in text
    assert "lt 2 dt 2" in text                                               # group 2's colour, pair 2's dashes


def test_a_fit_line_and_its_legend():
    assert plots.fitted_line([1, 2, 4], [2.5, 3, 4]) == pytest.approx((0.5, 2.0))
    assert plots.fitted_line([1, 1], [2, 3]) is None and plots.fitted_line([1], [2]) is None
    assert plots.fit_legend("g", "peak", (0.5, 2.0), "asin") == "g, peak: asin(slope) 30.0 deg, intercept 2"
    assert plots.fit_legend("g", "peak", (1.5, 2.0), "asin") == "g, peak: slope 1.5, intercept 2"
    assert plots.fit_legend("g", "peak", (0.5, 2.0), "number") == "g, peak: slope 0.5, intercept 2"
    assert plots.fit_legend("g", "peak", (0.5, -4e-14), "number", 500.0) == "g, peak: slope 0.5, intercept 0"
    assert plots.fit_legend("g", "peak", (0.5, -4e-6), "number", 500.0) == "g, peak: slope 0.5, intercept -4e-06"


def test_fig12_fit_notes_a_missing_variant_and_a_degenerate_group(tmp_path, figure_store):
    figure = FIG12.replace("group = no rolling; m1_d0.0_s100_r1 m1_d0.0_s200_r1 m1_d0.0_s400_r1",
                           "group = lone; m1_d0.0_s100_r1 unrun_s100")
    text, notes, data = script_data(tmp_path, figure_store, figure, plots._fit_script)
    assert notes[0].startswith("lone, peak: unrun_s100: not drawn: run output missing")
    assert "lone, peak: fewer than two different x: no line" in notes
    assert "title 'lone, peak'" in text and "line_0_0.dat" not in data and "line_1_0.dat" in data


def test_fig13_errorbars_give_the_mean_and_the_spread_between_seeds(tmp_path, figure_store):
    text, notes, data = script_data(tmp_path, figure_store, FIG13, plots._errorbars_script)
    assert notes == []
    peak = data["series_0.dat"]
    for row, delta in zip(peak, DELTAS):
        angles = [math.degrees(math.asin(peak_sine(delta, seed))) for seed in SEEDS]
        assert row == pytest.approx([delta, np.mean(angles), min(angles), max(angles), 2])
    assert data["series_1.dat"][2, 1] == pytest.approx(np.mean(
        [math.degrees(math.asin(residual_sine(1.6, seed))) for seed in SEEDS]))
    assert data["paper_0.dat"].tolist() == [[0, 24.4], [0, 19.3], [1.6, 42.3], [1.6, 35.8]]
    assert data["paper_1.dat"].tolist() == [[0.4, 26.5]]
    assert "with yerrorlines lt 1" in text and "title 'JYH 2005'" in text and "title 'JYH 2005, Model 2'" in text


def test_spread_points():
    assert plots.spread_points({0.4: [1.0, 3.0, 2.0], 0.0: [5.0]}) == [(0.0, 5.0, 5.0, 5.0, 1), (0.4, 2.0, 1.0, 3.0, 3)]
    assert plots.number_key(0.1 + 0.2) == plots.number_key(0.3)


def test_fig13_errorbars_note_the_variants_they_cannot_draw(tmp_path, figure_store):
    figure = FIG13.replace("variants = ", "variants = unrun_s100 ").replace(
        "x = setting('material.grain.delta')", "x = setting('material.grain.delta') + 0 * phi_peak(rows=300)")
    _, notes, data = script_data(tmp_path, figure_store, figure, plots._errorbars_script)
    assert notes[0].startswith("unrun_s100: not drawn: run output missing") and notes[-1] == "nothing to plot"
    assert len(notes) == 8 and all("phi_peak(): rows must be 1 to 201" in n for n in notes[1:-1])
    assert data == {}
    figure = FIG13.replace("y = ballast peak;", "y = ballast peak; 1 / 0 + ")
    _, notes, data = script_data(tmp_path, figure_store, figure, plots._errorbars_script)
    assert len(notes) == 6 and all(": ballast peak: not drawn: " in n and "ZeroDivisionError" in n for n in notes)
    assert sorted(data) == ["paper_0.dat", "paper_1.dat", "series_1.dat"]


@needs_gnuplot
def test_the_biaxial_figures_render_into_the_report(tmp_path, figure_store):
    """Figs 11(a), 12 and 13 drawn by gnuplot into the report, with the figure's paper quote."""
    case = load_case(tmp_path, FIG11 + FIG12 + FIG13)
    index = report.write_report([case], [], figure_store, tmp_path / "runs", tmp_path / "reports")
    html = index.read_text()
    for figure in ("fig11a", "fig12", "fig13"):
        assert (tmp_path / "reports" / "figures" / f"biax_{figure}.png").stat().st_size > 1000
    assert html.count('src="figures/') == 3 and html.count(".svg\"") == 3
    assert "(JYH 2005, Fig. 11(a))" in html


# ---------------------------------------------------------------- JYH's laws as checks

LAWS = """
[check phi_rises_with_delta]
case = biax
quantity = phi_envelope('peak', '_s100', '_s200', '_s400')
tolerance = trend increasing
variants = m1_d0.0_s100_r1 m1_d0.4_s100_r1 m1_d1.6_s100_r1
kind = paper
provenance = JYH 2005 Sec. 5.3: "the peak (residual) phi increases evidently with the increasing of delta"

[check residual_below_peak]
case = biax
variant = m1_d0.4_s100_r1
quantity = phi_envelope('peak', '_s100', '_s200', '_s400') - phi_envelope('residual', '_s100', '_s200', '_s400', lo=0.1, hi=0.19)
tolerance = interval
lo = 2
kind = paper
provenance = JYH 2005 Fig. 12

[check softening_constant]
case = biax
variant = m1_d0.0_s100_r1
quantity = spread("phi_envelope('peak', '_s100', '_s200', '_s400') - phi_envelope('residual', '_s100', '_s200', '_s400', lo=0.1, hi=0.19)", 'm1_d0.0_s100_r1', 'm1_d0.4_s100_r1', 'm1_d1.6_s100_r1')
tolerance = interval
hi = 1.5
kind = paper
provenance = JYH 2005 Sec. 5.3: "the difference between peak and residual strength is almost constant with delta"

[check dilates]
case = biax
variant = m1_d1.6_s200_r2
quantity = dilation()
tolerance = interval
lo = 0.01
kind = paper
provenance = JYH 2005 Fig. 11(b): "shear-dilant behaviour"

[check no_cohesion]
case = biax
variant = m1_d0.0_s100_r1
quantity = cohesion_envelope('peak', '_s100', '_s200', '_s400') / 1000
tolerance = abs 1
value = 0
kind = paper
provenance = JYH 2005 Sec. 5.2: "all strength envelopes of no rolling resistance materials nearly pass through the origin"
"""


def test_jyhs_laws_hold_as_checks_of_a_ref_file(tmp_path, figure_store):
    """The laws written as the case will write them: a trend over materials through the relative
    '_s100' names, intervals on the softening and on its spread over delta, the dilation, the
    cohesionless envelope -- all pass on the synthetic materials, and fail when the data break them."""
    ref = tmp_path / "biaxial.ref"
    ref.write_text(LAWS)
    checks = references.load_file(ref)
    verdicts = evaluate_all(checks, figure_store)
    assert [(v.check, v.passed) for v in verdicts] == [(c.name, True) for c in checks], [v.message for v in verdicts]
    assert verdicts[0].value == pytest.approx([math.degrees(math.asin(peak_sine(d, 1))) for d in DELTAS])
    # the same trend over the materials in the wrong order fails, naming the step
    backwards = replace(checks[0], variants=checks[0].variants[::-1])
    verdict = evaluate_all([backwards], figure_store)[0]
    assert not verdict.passed and verdict.message.startswith("not increasing: m1_d1.6_s100_r1 = 33.71")
