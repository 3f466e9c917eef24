"""The statistics of polydisperse piles over an ensemble (families/pile_stats.py) on synthetic
data with known answers: the dip depth of hand-made profiles, the jackknife's standard error
against the exact one and against the spread of many synthetic ensembles, the exponential
tail's rate and its Kolmogorov-Smirnov distance, the coordination number and the force list
of the hand-made pile of pile_fakes.py, and the functions through the expression language
over a fake ensemble."""
import json
import math

import numpy as np
import pytest

from harness.compare import RunStore, folder_locator, quantity_in
from harness.errors import EvalError
from harness.families import pile_stats as ps
from harness.final_state import FinalState
from harness.tests.pile_fakes import write_pile_run


def test_centre_flank_and_dip_of_hand_made_profiles():
    X = np.linspace(0.05, 0.95, 19)              # spacing 0.05; flank 0.12: from the 3rd disc off centre
    hump = 1.0 - np.abs(X - 0.5)                 # a tent: centre 1, windows symmetric
    assert ps.centre_value(hump) == pytest.approx((0.95 + 1.0 + 0.95) / 3)
    # the windows wholly at |X - 1/2| >= 0.12: the best is X = .25 .3 .35 (or its mirror)
    assert ps.flank_value(hump, X, 0.12) == pytest.approx((0.75 + 0.8 + 0.85) / 3)
    assert ps.dip_depth(hump, X, 0.12) == pytest.approx(1 - (2.9 / 3) / 0.8)
    assert ps.dip_depth(hump, X, 0.12) < 0
    dip = hump.copy()
    dip[8:11] = [0.4, 0.4, 0.4]                   # the centre three pulled down to 0.4
    assert ps.dip_depth(dip, X, 0.12) == pytest.approx((0.8 - 0.4) / 0.8)
    flat = np.full(19, 2.0)
    assert ps.dip_depth(flat, X) == 0.0
    # even length: middle pair and half of each neighbour
    assert ps.centre_value([0, 1, 2, 3, 4, 5]) == pytest.approx((2 + 3 + 0.5 * (1 + 4)) / 3)
    assert ps.centre_value([1.0] * 4) == pytest.approx(1.0)


def test_dip_refuses_what_it_cannot_measure():
    with pytest.raises(EvalError, match="no three central"):
        ps.centre_value([1, 2])
    with pytest.raises(EvalError, match="no three neighbouring discs"):
        ps.flank_value([1, 2, 3, 4, 5], [0.45, 0.48, 0.5, 0.52, 0.55])
    with pytest.raises(EvalError, match="5 profile values against 4 X"):
        ps.flank_value([1, 2, 3, 4, 5], [0, 0.1, 0.2, 0.3])
    with pytest.raises(EvalError, match="at least two realisations"):
        ps.mean_profile([[1.0, 2.0, 3.0]])


def test_jackknife_of_a_linear_statistic_is_the_standard_error_of_the_mean():
    rng = np.random.default_rng(7)
    S = rng.normal(size=(37, 5))
    exact = S[:, 2].std(ddof=1) / math.sqrt(37)
    assert ps.jackknife_se(S, lambda m: m[2]) == pytest.approx(exact, rel=1e-12)
    assert ps.jackknife_se(S, lambda m: 3 * m[1] - m[4]) == pytest.approx(
        (3 * S[:, 1] - S[:, 4]).std(ddof=1) / math.sqrt(37), rel=1e-12)
    assert ps.mean_profile(S)[1][2] == pytest.approx(exact, rel=1e-12)


def synthetic_ensemble(rng, n, depth, noise, points=31):
    """n noisy profiles of a tent with its centre three lowered: D = depth exactly when noiseless."""
    X = (np.arange(points) + 0.5) / points
    base = 2.0 - np.abs(X - 0.5)
    c = points // 2
    clean = base.copy()
    R = ps.flank_value(base, X)
    clean[c - 1:c + 2] = R * (1 - depth)          # the centre three at (1 - depth) of the flanks
    return X, clean, clean + rng.normal(scale=noise, size=(n, points))


@pytest.mark.parametrize("depth", [0.2, -0.05])
def test_dip_and_its_standard_error_on_synthetic_ensembles(depth):
    rng = np.random.default_rng(11)
    X, clean, _ = synthetic_ensemble(rng, 2, depth, 0.0)
    assert ps.dip_depth(clean, X) == pytest.approx(depth, abs=1e-12)
    # 400 ensembles of 60 noisy runs: D scatters about the true depth as the jackknife says
    estimates, errors = [], []
    for _ in range(400):
        X, _, P = synthetic_ensemble(rng, 60, depth, 0.3)
        d, se = ps.dip_with_se(P, X)
        estimates.append(d)
        errors.append(se)
    estimates = np.array(estimates)
    spread = estimates.std(ddof=1)
    assert abs(estimates.mean() - depth) < 4 * spread / math.sqrt(400) + 0.01   # the max biases R up a little
    assert np.median(errors) == pytest.approx(spread, rel=0.15)
    z = (estimates - depth) / np.array(errors)
    assert np.mean(np.abs(z) < 3) > 0.97


def test_the_standard_error_against_the_number_of_realisations():
    """One synthetic ensemble of 400 runs: the first-n D and SE are those of the first n rows; the
    blocks are disjoint; the jackknife SE of the blocks falls as n^(-1/2) (i.i.d. runs: the
    exponent's own scatter here is about 0.02); the n for a z follows from the power law exactly."""
    rng = np.random.default_rng(5)
    X, _, P = synthetic_ensemble(rng, 400, 0.2, 0.3)
    (d10, se10), (d400, se400) = ps.first_dips(P, X, [10, 400])
    assert (d10, se10) == ps.dip_with_se(P[:10], X) and (d400, se400) == ps.dip_with_se(P, X)
    blocks = ps.block_stats(P, X, 30)                 # 13 blocks of 30, the last 10 runs left out
    assert len(blocks) == 13 and blocks[12] == ps.dip_with_se(P[360:390], X)
    sizes = [10, 20, 25, 40, 50, 80, 100, 200]
    se = [np.mean([s for _, s in ps.block_stats(P, X, n)]) for n in sizes]
    a, b = ps.power_law(sizes, se)
    assert b == pytest.approx(-0.5, abs=0.08)
    assert ps.power_law([1, 4, 16], [2.0, 1.0, 0.5]) == pytest.approx((2.0, -0.5))
    assert ps.n_for(5, 0.5, 1.0, -0.5) == pytest.approx(100.0)     # 0.5 / (1 / sqrt(100)) = 5
    assert ps.n_for(5, -0.5, 1.0, -0.5) == pytest.approx(100.0)    # a hump: |D|
    with pytest.raises(EvalError, match="does not fall with n"):
        ps.n_for(5, 0.5, 1.0, 0.1)
    with pytest.raises(EvalError, match="D is 0"):
        ps.n_for(5, 0.0, 1.0, -0.5)


def test_exponential_tail_rate_and_its_distance():
    rng = np.random.default_rng(3)
    beta = 1.7
    f = 1.0 + rng.exponential(1 / beta, size=20000)
    f = np.concatenate([f, rng.uniform(0, 1, size=5000)])     # below f0: ignored
    m = 20000
    assert ps.tail_rate(f) == pytest.approx(beta, abs=4 * beta / math.sqrt(m))
    assert ps.tail_ks(f) < 1.63
    uniform = 1 + rng.uniform(0, 2, size=m)                   # not exponential: far above 1.63
    assert ps.tail_ks(uniform) > 10
    gauss = 1 + np.abs(rng.normal(size=m))                    # a half-Gaussian tail: rejected too
    assert ps.tail_ks(gauss) > 5
    with pytest.raises(EvalError, match="fewer than 10"):
        ps.tail_rate([2.0, 3.0])


def test_fluctuations_and_rho():
    P = np.array([[1.0, 2.0, 3.0], [3.0, 2.0, 1.0]])       # mean 2 2 2
    assert list(ps.fluctuations(P, [0.5, 1.0, 0.5])) == [1.0, 1.0]
    with pytest.raises(EvalError, match="largest value"):
        ps.fluctuations(P, [0.0, 0.0])


def fake_final(folder, piles=None, sets=None):
    write_pile_run(folder)
    info = json.loads((folder / "run.json").read_text())
    if piles is not None:
        info["piles"] = piles
    return FinalState(folder, info)


def test_coordination_and_forces_of_the_hand_made_pile(tmp_path):
    final = fake_final(tmp_path / "dem")
    # free discs of rows >= 1: p.4 .5 .6 .7 .8; touching disc contacts: p.5-p.6, p.6-p.4,
    # p.5-p.7, p.6-p.7, p.7-p.8 (both ends inside: 10) and p.0-p.5 (one end: 1); p.1-p.2 held
    assert ps.coordination_number(final, 1) == pytest.approx(11 / 5)
    assert ps.coordination_number(final, 2) == pytest.approx(4 / 2)      # p.7 p.8: 1 + 1 + 2
    with pytest.raises(EvalError, match="no free disc"):
        ps.coordination_number(final, 5)
    f = ps.normalised_forces(final)        # 10.5 4 2 1 3 6 100: disc-disc, force fn + dn
    forces = np.array([10.5, 4, 2, 1, 3, 6, 100])
    assert sorted(f) == pytest.approx(sorted(forces / forces.mean()))


def test_rho_of_a_run(tmp_path):
    pile = {"name": "p", "L": 4, "rows": 3, "discs": 9, "d": 1.0, "x0": 0.0, "width": 4.0,
            "size_spread": 0.05, "seed": 3}
    final = fake_final(tmp_path / "dem", piles=[pile])
    # W = |g| * 8 = 16, l = 4: sigma = 4; rho = 0.05 * 200 / (4 * 1)
    assert ps.rho(final, ["pile.p.L=4", "material.grain.kn=200"]) == pytest.approx(2.5)
    with pytest.raises(EvalError, match="no material.grain.kn"):
        ps.rho(final, ["pile.p.L=4"])


# ---------------------------------------------------------------- through the expression language

def perturbed_run(folder, seed, shift):
    """The fake pile with row 1's stresses scaled by (1 + shift) at its middle disc."""
    write_pile_run(folder)
    text = (folder / "stress.tsv").read_text().splitlines()
    head = text[0].split("\t")
    out = [text[0]]
    for line in text[1:]:
        cells = line.split("\t")
        if cells[1] == "p.6":                  # the middle disc of row 1 (X = 1/2)
            k = head.index("szz")
            cells[k] = repr(float(cells[k]) * (1 + shift))
        out.append("\t".join(cells))
    (folder / "stress.tsv").write_text("\n".join(out) + "\n")
    info = json.loads((folder / "run.json").read_text())
    info["sets"] = [f"pile.p.seed={seed}", "material.grain.kn=200"]
    info["piles"][0]["size_spread"] = 0.05
    (folder / "run.json").write_text(json.dumps(info))


def test_the_functions_over_a_fake_ensemble(tmp_path):
    runs = tmp_path / "runs"
    shifts = {1: 0.0, 2: 0.5, 3: -0.5, 4: 1.0}
    for seed, shift in shifts.items():
        perturbed_run(runs / "pile" / f"e_s{seed}", seed, shift)
    write_pile_run(runs / "pile" / "mono")
    store = RunStore(folder_locator(runs), {"pile": {"e": [f"e_s{s}" for s in shifts]}})
    q = lambda expr: quantity_in(store, "pile", "mono", expr)
    # row 1 by x: p.5 (S_zz 2), p.6 (1.5 (1 + shift)), p.4 (1); the mean shift is 0.25
    assert q("ens_S('e')[1]") == pytest.approx(1.5 * 1.25)
    middle = 1.5 * (1 + np.array(list(shifts.values())))
    assert q("ens_S_se('e')[1]") == pytest.approx(middle.std(ddof=1) / 2)
    assert q("ens_S_se('e')[0]") == 0
    assert q("ens_X('e')[2]") == pytest.approx(0.75)
    assert q("ens_rho('e')") == pytest.approx(2.5)
    # fluctuation: |1.5 (1 + s) - 1.875| over max mono S_zz (2)
    assert q("max(ens_fluct('e', 'mono'))") == pytest.approx(abs(1.5 * 2 - 1.875) / 2)
    assert q("log10(100)") == pytest.approx(2)
    with pytest.raises(EvalError, match="no three neighbouring discs"):
        q("dip('e')")          # a three-disc row has no flanks to compare with
    with pytest.raises(EvalError, match="no ensemble 'q'"):
        q("ens_S('q')")
    with pytest.raises(EvalError, match="sizes must be whole numbers from 2 to 4"):
        q("dip_first('e', [1, 2])")
    with pytest.raises(EvalError, match="from 2 to 2 .*at least 2 blocks"):
        q("dip_sd_blocks('e', [3])")
    with pytest.raises(EvalError, match="sizes must be whole numbers from 2 to 4"):
        q("dip_mean_blocks('e', [2.5])")
    with pytest.raises(EvalError, match="sizes must be a list"):
        q("dip_se_blocks('e', 3)")
    with pytest.raises(EvalError, match="two or more different sizes"):
        q("se_exponent('e', [2, 2])")
    with pytest.raises(EvalError, match="no three neighbouring discs"):
        q("dip_first('e', [2, 4])")
    (runs / "pile" / "e_s3" / "stress.tsv").unlink()
    fresh = RunStore(folder_locator(runs), {"pile": {"e": [f"e_s{s}" for s in shifts]}})
    with pytest.raises(EvalError, match="realisation 'e_s3'"):
        quantity_in(fresh, "pile", "mono", "ens_S('e')")
