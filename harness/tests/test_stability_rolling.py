"""Stability with rolling resistance (issue 20, item 5): the limit probes of extremes.py
(expect = limit), and the critical-step estimate of the delta = 1.6 slope scenes of
cases/extremes against the exact limit of their linearised start network.

The exact check is the sharp one.  The stability finder's limit is where a mode past its
limit becomes visible, and on these scenes Coulomb sliding and the rolling cap (Model 1)
or break (Model 2) hold such a mode finite for a while: an estimate that left K_m out
(about 3 % above the exact limit at 1:100) would still pass the finder.  The exact
lambda_max(M^-1 K) of the network ballast sees at the start, with the rolling springs,
does not let it pass."""
import math
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

from harness import extremes
from harness import stability as st
from harness.runner import Batch

ROOT = Path(__file__).resolve().parents[2]
BIN = ROOT / "bin" / "ballast"
EXTREMES = ROOT / "cases" / "extremes"
needs_bin = pytest.mark.skipif(not BIN.exists(), reason="bin/ballast not built")

MARGIN = 0.95      # BAL_DT_MARGIN of core/timestep.c
GAP = 0.01         # BAL_DT_GAP: a start contact's largest gap over the smaller radius


# ---------------------------------------------------------------- limit probes (extremes.py)

LIMIT_PROBES = """[probe lim]
group = g
what = bisected
scene = s.scene
set = settings.rolling_model=model2
expect = limit
limit = 1 1.5
"""


def test_limit_probe_loads(tmp_path):
    (tmp_path / "extremes.txt").write_text(LIMIT_PROBES)
    (p,) = extremes.load_probes(tmp_path / "extremes.txt")
    assert (p.expect, p.limit, p.sets) == ("limit", (1.0, 1.5), ["settings.rolling_model=model2"])


@pytest.mark.parametrize("text, message", [
    ("expect = limit\n", "needs 'limit = ...'"),
    ("expect = limit\nlimit = 1\n", "limit needs 'LO HI'"),
    ("expect = limit\nlimit = 1 x\n", "limit needs 'LO HI'"),
    ("expect = limit\nlimit = 1.5 1\n", "0 < LO <= HI"),
    ("expect = stable\nlimit = 1 1.5\n", "goes with 'expect = limit'"),
])
def test_limit_probe_rejects_bad_declarations(tmp_path, text, message):
    (tmp_path / "extremes.txt").write_text("[probe a]\ngroup = g\nwhat = w\nscene = s\n" + text)
    with pytest.raises(Exception, match=message):
        extremes.load_probes(tmp_path / "extremes.txt")


def _limit(f, unstable=float("nan"), cause="", note=""):
    return st.Limit("extremes", "lim", estimate=2e-5, single=1e-4, dt_case=1.8e-5, limit=f,
                    unstable=unstable, cause=cause, note=note, trials=8)


def test_judge_limit():
    tmp = extremes.Probe("lim", "g", "w", Path("s"), [], "limit", math.nan, 0.1, limit=(1.0, 1.5))
    outcome, ok = extremes.judge_limit(tmp, _limit(1.285, 1.294, "probe Dfric range [0, 4e-06]"))
    assert ok and outcome.startswith("limit 1.285 x estimate (8 trials; unstable at 1.294: probe Dfric")
    assert outcome.endswith("within [1, 1.5]")
    outcome, ok = extremes.judge_limit(tmp, _limit(0.97, 0.98, "exit 1: energy runaway"))
    assert not ok and "NOT SAFE" in outcome
    outcome, ok = extremes.judge_limit(tmp, _limit(1.9, 1.91, "exit 1"))
    assert not ok and outcome.endswith("above 1.5")
    outcome, ok = extremes.judge_limit(tmp, _limit(math.nan, note="baseline (its own dt) fails: exit 1"))
    assert not ok and outcome == "no limit found: baseline (its own dt) fails: exit 1"
    outcome, ok = extremes.judge_limit(tmp, _limit(1.2, note="no unstable step up to f = 64"))
    assert ok and "no unstable step up to f = 64" in outcome


def test_limit_probe_row_is_the_bisection(monkeypatch, tmp_path):
    seen = []

    def measure(batch, target, folder):
        seen.append((target.scene.name, target.sets, Path(folder)))
        return _limit(1.19, 1.199, "probe Dfric range")
    monkeypatch.setattr(extremes, "measure", measure)
    (tmp_path / "extremes.txt").write_text(LIMIT_PROBES)
    (p,) = extremes.load_probes(tmp_path / "extremes.txt")
    row = extremes.run_probe(None, p, tmp_path / "lim")
    assert seen == [("s.scene", ["settings.rolling_model=model2"], tmp_path / "lim")]
    assert set(row) == set(extremes.EXTREME_COLUMNS)
    assert (row["as_expected"], row["limit_fraction"], row["unstable_fraction"], row["estimate"]) == \
        ("yes", "1.19", "1.199", "2e-05")


def test_the_rolling_rows_are_declared():
    probes = {p.name: p for p in extremes.load_probes(EXTREMES / "extremes.txt")}
    for ratio in ("1to10", "1to100"):
        for n in ("1", "2"):
            assert probes[f"roll_{ratio}_m{n}"].expect == "stable"
            lim = probes[f"roll_{ratio}_m{n}_limit"]
            assert lim.expect == "limit" and lim.limit[0] == 1.0      # the estimate is safe
            assert f"settings.rolling_model=model{n}" in lim.sets
    assert probes["roll_1to100_m1_over"].expect == probes["roll_1to100_m2_over"].expect == "stop"


# ---------------------------------------------------------------- the exact linear limit

def read_scene(scene, sets=()):
    """([(kind, name)], {(kind, name, key): value}) of a scene file (a section without a
    name, [settings], has name ''), with `material.NAME.KEY=VALUE` overrides."""
    sections, values, current = [], {}, None
    for raw in Path(scene).read_text(encoding="utf-8").splitlines():
        line = raw.split("#", 1)[0].strip()
        m = re.match(r"^\[\s*(\w+)\s*([^\]]*?)\s*\]$", line)
        if m:
            current = (m.group(1), m.group(2))
            sections.append(current)
        elif current and "=" in line:
            key, value = (x.strip() for x in line.split("=", 1))
            values[current + (key,)] = value
    for s in sets:
        key, value = s.split("=", 1)
        values[tuple(key.split("."))] = value
    return sections, values


def start_network(scene, sets=()):
    """(A, n): A = M^(-1/2) K M^(-1/2) of the contacts at the start of a one-material scene of
    free discs and walls (the slope scenes), with the energy of core/timestep.c per contact,
    (1/2) k_n g_n^2 + (1/2) k_s g_s^2 + (1/2) K_m g_r^2: g_n = (u_b - u_a).n, g_s = (u_b -
    u_a).t - R_a th_a - R_b th_b, g_r = th_a - th_b (a wall: u_b = th_b = 0, common radius
    2 R_a), K_m = k_n (delta r)^2 / 12."""
    sections, values = read_scene(scene, sets)
    (mat,) = [name for kind, name in sections if kind == "material"]
    kn = float(values[("material", mat, "kn")])
    ks = float(values.get(("material", mat, "ks"), kn))
    delta = float(values.get(("material", mat, "rolling"), 0))
    rho = float(values[("material", mat, "density")])
    discs = [name for kind, name in sections if kind == "disc"]
    x = np.array([[float(v) for v in values[("disc", d, "x")].split()] for d in discs])
    r = np.array([float(values[("disc", d, "r")]) for d in discs])
    n = len(discs)
    m = rho * math.pi * r ** 2
    inertia = m * r ** 2 / 2
    K = np.zeros((3 * n, 3 * n))

    def add(a, b, nrm, rc):
        t = np.array([-nrm[1], nrm[0]])
        idx, gn, gs, gr = [], [], [], []
        for body, sign in ((a, -1), (b, 1)):
            if body is None:
                continue
            idx += [3 * body, 3 * body + 1, 3 * body + 2]
            gn += [sign * nrm[0], sign * nrm[1], 0]
            gs += [sign * t[0], sign * t[1], -r[body]]
            gr += [0, 0, -sign]
        gn, gs, gr = np.array(gn), np.array(gs), np.array(gr)
        km = kn * (delta * rc) ** 2 / 12
        K[np.ix_(idx, idx)] += kn * np.outer(gn, gn) + ks * np.outer(gs, gs) + km * np.outer(gr, gr)

    d = x[None, :, :] - x[:, None, :]
    dist = np.hypot(d[..., 0], d[..., 1])
    gap = dist - r[:, None] - r[None, :]
    for i, j in zip(*np.nonzero(np.triu(gap <= GAP * np.minimum(r[:, None], r[None, :]), 1))):
        add(i, j, d[i, j] / dist[i, j], 2 * r[i] * r[j] / (r[i] + r[j]))
    for w in (name for kind, name in sections if kind == "wall"):
        p = np.array([float(v) for v in values[("wall", w, "p")].split()])
        alpha = math.radians(float(values[("wall", w, "angle")]))
        e = np.array([math.cos(alpha), math.sin(alpha)])
        h1, h2 = float(values[("wall", w, "h1")]), float(values[("wall", w, "h2")])
        for i in range(n):
            q = p + np.clip((x[i] - p) @ e, h1, h2) * e - x[i]
            if np.hypot(*q) - r[i] <= GAP * r[i]:
                add(i, None, q / np.hypot(*q), 2 * r[i])
    s = 1 / np.sqrt(np.stack([m, m, inertia], axis=1).ravel())
    return s[:, None] * K * s[None, :], n


def omega_max(scene, sets=()):
    A, _ = start_network(scene, sets)
    return math.sqrt(np.linalg.eigvalsh(A)[-1])


def damped_limit(omega, beta):
    """The leapfrog limit of a mode with its dashpot on v_(N-1/2), zeta = beta omega / 2."""
    z = beta * omega / 2
    return 2 / omega * (math.sqrt(1 + z * z) - z)


@needs_bin
@pytest.mark.parametrize("ratio", ["1to10", "1to100"])
def test_the_estimate_covers_the_rolling_springs(ratio):
    scene = EXTREMES / f"slope_{ratio}_rolling.scene"
    exact = 2 / omega_max(scene)                  # the linear limit with K_m on every contact
    estimate = st.info(Batch(BIN), scene, [])["estimate"]
    # safe: at most the margin times the exact limit (the bound is an upper bound on omega) ...
    assert estimate <= MARGIN * exact * (1 + 1e-9)
    # ... and tight: the spectral bound is within 3 % of the exact omega here (measured 1.5 %)
    assert estimate >= 0.97 * MARGIN * exact
    # the rolling springs matter: the highest mode is stiffer by more than the margin, so an
    # estimate without K_m (delta = 0 in the same scene) would be above the exact limit
    without = st.info(Batch(BIN), scene, ["material.grain.rolling=0"])["estimate"]
    assert without > exact
    assert omega_max(scene) / omega_max(scene, ["material.grain.rolling=0"]) > 1.1


@needs_bin
def test_the_estimate_covers_the_rolling_dashpot():
    # beta gives c_n = beta k_n, c_s = beta k_s and the rolling dashpot mu_m = c_n B^2/12 =
    # beta K_m, so the damping is beta K: every mode has zeta = beta omega / 2 and the highest
    # binds
    scene, beta = EXTREMES / "slope_1to100_rolling.scene", 2.6e-5
    w = omega_max(scene)
    estimate = st.info(Batch(BIN), scene, [f"settings.beta={beta}"])["estimate"]
    assert 0.97 * MARGIN * damped_limit(w, beta) <= estimate <= MARGIN * damped_limit(w, beta)


# ---------------------------------------------------------------- runs at and past the limit

def ballast_run(tmp_path, name, *sets):
    scene = EXTREMES / "slope_1to100_rolling.scene"
    argv = [str(BIN), "run", str(scene), "--out", str(tmp_path / name)]
    for s in sets:
        argv += ["--set", s]
    return subprocess.run(argv, capture_output=True, text=True, timeout=300)


@needs_bin
@pytest.mark.parametrize("model", ["model1", "model2"])
def test_delta_16_at_1to100_is_stable_at_0p9_and_stops_at_1p5_times_the_limit(tmp_path, model):
    estimate = st.info(Batch(BIN), EXTREMES / "slope_1to100_rolling.scene", [])["estimate"]
    # at 0.9 of the estimate (the scene's dt_fraction): runs through, no energy created,
    # the large disc stays on the row, overlaps near the 1 % k_n was chosen for
    done = ballast_run(tmp_path, "stable", f"settings.rolling_model={model}")
    assert done.returncode == 0, done.stderr
    energy, _, bad = st.series_energy(tmp_path / "stable" / "series.tsv")
    assert not bad and energy < 0.01
    lo, hi = st.series_envelope(tmp_path / "stable" / "series.tsv")["big_y"]
    assert 1.68 < lo <= hi <= 1.7
    assert st.largest_overlap(tmp_path / "stable" / "discs.tsv", tmp_path / "stable" / "contacts.tsv") < 0.03
    # at 1.5 x the limit the stability finder measured (1.285 and 1.378 x the estimate, the
    # rows roll_1to100_m*_limit of cases/extremes/extremes.txt): the energy guard stops it
    limit = {"model1": 1.285, "model2": 1.378}[model]
    done = ballast_run(tmp_path, "over", f"settings.rolling_model={model}",
                       f"settings.dt={1.5 * limit * estimate!r}", "settings.force_dt=1")
    assert done.returncode == 1 and "energy runaway at step" in done.stderr, done.stderr
