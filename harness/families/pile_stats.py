"""Statistics of polydisperse piles over an [ensemble] (Matuttis, Luding & Herrmann 2000,
Sec. 4.4, Figs 8-9): the averaged S_zz(1) profile with its standard errors, its dip depth with
a standard error, the coordination number, and the distribution of contact forces.

The expression functions of the family (NAME an [ensemble] of the case, as in ensembles.py):

    ens_X(name, row=1)              X of the discs of pile row `row`, averaged over the
                                    realisations (disc k of the row = the k-th from the left)
    ens_S(name, component='zz', row=1)
                                    the averaged profile: mean over the realisations of
                                    pile_S(component, row), disc by disc
    ens_S_se(name, component='zz', row=1)
                                    its standard error, disc by disc (std / sqrt(n), ddof = 1)
    dip(name, component='zz', row=1, flank=0.1)
                                    the dip depth D of the averaged profile (dip_depth below)
    dip_se(name, component='zz', row=1, flank=0.1)
                                    its standard error over the realisations (jackknife)
    profile_dip(profile, X, flank=0.1)
                                    D of one profile (e.g. pile_S('zz') of one run)
    coordination(row_min=1)         contacts per disc of rows >= row_min of this run (contacts
                                    with a held disc of row 0 counted; held discs never counted
                                    as discs)
    ens_forces(name)                every disc-disc contact force of every realisation, each
                                    over the mean force of its own run (f = F / <F>), pooled
    tail_rate(f, f0=1)              the maximum-likelihood decay rate beta of an exponential
                                    tail P(f) ~ exp(-beta f) fitted to the f > f0
    ens_fluct(name, mono)           per realisation, the largest |S_zz(1) - averaged S_zz(1)|
                                    over X, divided by the largest S_zz(1) of the variant mono
                                    (MLH: "fluctuations much larger than the total stress for
                                    the monodisperse pile"); an array in seed order
    ens_rho(name)                   rho = r_d k_n / (sigma d) of the ensemble's first
                                    realisation: r_d and d from run.json's pile, sigma = W / l
                                    (the weight of its free discs over the base width), k_n
                                    from its run.json `sets` (material.grain.kn=..., required)
    log10(x)                        the base-10 logarithm, element by element (a figure's axis)

The ensemble's size (issue 33: how many realisations the dip needs), each over a list `sizes`
of numbers of realisations n (whole, 2 to the ensemble's size):

    dip_first(name, sizes)          D of the first n realisations (seed order), for each n: the
                                    dip the ensemble would have shown with n runs
    dip_se_first(name, sizes)       its jackknife standard error, for each n
    dip_se_blocks(name, sizes)      for each n, the mean of the jackknife standard error over the
                                    ensemble's disjoint blocks of n consecutive realisations (the
                                    last, partial block left out): SE against n from one ensemble
    dip_sd_blocks(name, sizes)      for each n, the standard deviation (n - 1) of D over those
                                    blocks (at least two): the spread the SE should predict
    dip_mean_blocks(name, sizes)    for each n, the mean of D over those blocks: what an ensemble
                                    of n shows on average (D of an averaged profile is biased
                                    at small n: R is a largest window mean, lifted by the noise)
    se_exponent(name, sizes)        the least-squares slope of log dip_se_blocks on log n:
                                    -1/2 for the sqrt(N) law
    n_for_z(name, z, sizes)         the number of realisations at which |D| / SE = z, with D the
                                    whole ensemble's and SE(n) = a n^b the least-squares power
                                    law of dip_se_blocks over sizes
    tail_ks(f, f0=1)                the Kolmogorov-Smirnov distance between the f > f0 and that
                                    exponential, times sqrt(count) (below 1.63: not rejected
                                    at the 1 % level; rate estimated, so conservative)

Definitions (fixed once, from the paper's wording, and not adjusted to the outcome of the gates;
cases/piles_poly/README.md):

  * C, the centre: the mean of the three central discs of the profile (an odd row has one
    middle disc and its two neighbours; an even one the two middle ones and, of their two
    neighbours, the mean).  MLH average "over 100 runs and three particles" (Fig. 8).
  * R, the flanks: the largest mean of three neighbouring discs among the windows whose three
    discs all lie at |X - 1/2| >= flank (0.1: ten disc diameters at L1 = 97, three at L1 = 31).
  * D = (R - C) / R.  D > 0: the centre is lower than the flanks (a dip, MLH Fig. 8(b));
    D < 0: the centre stands above them (a hump, Fig. 8(a)).
  * The standard error of D is the jackknife's over the realisations (D of the averaged
    profile is not linear in the runs): n - 1 over n times the sum of squares of the
    leave-one-out D about their mean, square-rooted.  For a statistic linear in the runs it is
    exactly std / sqrt(n) (harness/tests/test_pile_stats.py).

A realisation whose run is missing or failed makes the value fail, naming it (as over()).
"""
import math

import numpy as np

from ..errors import EvalError
from ..expressions import ensemble_members, register, sibling_run
from ..final_state import state
from . import piles

FLANK = 0.1


# ---------------------------------------------------------------- pure functions (tested)

def centre_value(profile):
    """C: the mean of the three central values (even length: the two middle ones and the mean of
    their two neighbours, weighted so that the window stays symmetric)."""
    p = np.asarray(profile, dtype=float).reshape(-1)
    n = p.size
    if n < 3:
        raise EvalError(f"dip: a profile of {n} value(s) has no three central discs")
    if n % 2:
        c = n // 2
        return float(np.mean(p[c - 1:c + 2]))
    c = n // 2
    return float((p[c - 1] + p[c] + 0.5 * (p[c - 2] + p[c + 1])) / 3.0)


def flank_value(profile, X, flank=FLANK):
    """R: the largest mean of three neighbours whose X all lie at |X - 1/2| >= flank."""
    p = np.asarray(profile, dtype=float).reshape(-1)
    x = np.asarray(X, dtype=float).reshape(-1)
    if p.size != x.size:
        raise EvalError(f"dip: {p.size} profile values against {x.size} X")
    outside = np.abs(x - 0.5) >= flank
    best = -math.inf
    for k in range(p.size - 2):
        if outside[k] and outside[k + 1] and outside[k + 2]:
            best = max(best, float(np.mean(p[k:k + 3])))
    if best == -math.inf:
        raise EvalError(f"dip: no three neighbouring discs at |X - 1/2| >= {flank:g}")
    return best


def dip_depth(profile, X, flank=FLANK):
    """D = (R - C) / R of one profile (module docstring)."""
    r = flank_value(profile, X, flank)
    if not r > 0:
        raise EvalError(f"dip: the flank value is {r:g}, not positive")
    return (r - centre_value(profile)) / r


def mean_profile(profiles):
    """(mean, standard error) disc by disc of an (n_runs, n_discs) array; n_runs >= 2."""
    P = np.asarray(profiles, dtype=float)
    if P.ndim != 2 or P.shape[0] < 2:
        raise EvalError("an averaged profile needs at least two realisations")
    return P.mean(axis=0), P.std(axis=0, ddof=1) / math.sqrt(P.shape[0])


def jackknife_se(samples, statistic):
    """The jackknife standard error of statistic(mean of samples) over the rows of samples."""
    S = np.asarray(samples, dtype=float)
    n = S.shape[0]
    if n < 2:
        raise EvalError("a standard error needs at least two realisations")
    total = S.sum(axis=0)
    loo = np.array([statistic((total - S[i]) / (n - 1)) for i in range(n)])
    return float(math.sqrt((n - 1) / n * np.sum((loo - loo.mean()) ** 2)))


def dip_with_se(profiles, X, flank=FLANK):
    """(D of the averaged profile, its jackknife standard error)."""
    P = np.asarray(profiles, dtype=float)
    mean, _ = mean_profile(P)
    return dip_depth(mean, X, flank), jackknife_se(P, lambda m: dip_depth(m, X, flank))


def first_dips(profiles, X, sizes, flank=FLANK):
    """[(D, SE)] of the first n rows of profiles, for each n of sizes."""
    return [dip_with_se(profiles[:n], X, flank) for n in sizes]


def block_stats(profiles, X, n, flank=FLANK):
    """(D, SE) of each disjoint block of n consecutive rows of profiles (a partial last block is
    left out)."""
    blocks = profiles.shape[0] // n
    return [dip_with_se(profiles[k * n:(k + 1) * n], X, flank) for k in range(blocks)]


def power_law(sizes, se):
    """(a, b) of the least-squares line log se = log a + b log n."""
    b, log_a = np.polyfit(np.log(np.asarray(sizes, dtype=float)), np.log(np.asarray(se, dtype=float)), 1)
    return float(math.exp(log_a)), float(b)


def n_for(z, depth, a, b):
    """The n at which |depth| / (a n^b) = z (b < 0)."""
    if not b < 0:
        raise EvalError(f"n_for_z(): the standard error does not fall with n (exponent {b:.3g})")
    if depth == 0:
        raise EvalError("n_for_z(): D is 0: no number of realisations makes it stand out")
    return float((z * a / abs(depth)) ** (1.0 / -b))


def tail(f, f0):
    f = np.asarray(f, dtype=float).reshape(-1)
    t = f[f > f0] - f0
    if t.size < 10:
        raise EvalError(f"tail: {t.size} forces above f0 = {f0:g}, fewer than 10")
    return t


def tail_rate(f, f0=1.0):
    """Maximum-likelihood beta of P(f) ~ exp(-beta f) for f > f0: 1 / mean(f - f0)."""
    return float(1.0 / np.mean(tail(f, f0)))


def tail_ks(f, f0=1.0):
    """sqrt(m) times the Kolmogorov-Smirnov distance of the m forces above f0 from the fitted
    exponential (Lilliefors: with the rate fitted the 1 % point is lower than 1.63)."""
    t = np.sort(tail(f, f0))
    m = t.size
    cdf = 1.0 - np.exp(-t / np.mean(t))
    upper = np.arange(1, m + 1) / m - cdf
    lower = cdf - np.arange(0, m) / m
    return float(math.sqrt(m) * max(upper.max(), lower.max()))


def coordination_number(final, row_min=1):
    """Touching contacts (force > 0) per free disc of rows >= row_min: each contact between two
    such discs counts twice, one with any other disc (held, or of a lower row) once."""
    body = final.body()
    discs = [name for name, (row, held) in body.items() if not held and row >= row_min]
    if not discs:
        raise EvalError(f"coordination(): no free disc in rows >= {row_min}")
    inside = set(discs)
    ends = 0
    for c in final.contacts():
        if c["kind"] != "disc" or c["open"] or not c["force"] > 0:
            continue
        ends += (c["a"] in inside) + (c["b"] in inside)
    return ends / len(discs)


def normalised_forces(final):
    """The disc-disc contact forces (> 0) of one run over their mean."""
    f = np.array([c["force"] for c in final.contacts()
                  if c["kind"] == "disc" and not c["open"] and c["force"] > 0], dtype=float)
    if f.size == 0:
        raise EvalError("no disc-disc contact carries a force")
    return f / f.mean()


# ---------------------------------------------------------------- the expression functions

NAMES = ("ens_X", "ens_S", "ens_S_se", "dip", "dip_se", "profile_dip", "coordination",
         "ens_forces", "tail_rate", "tail_ks", "ens_fluct", "ens_rho", "log10", "dip_first",
         "dip_se_first", "dip_se_blocks", "dip_sd_blocks", "dip_mean_blocks", "se_exponent", "n_for_z")
KN_KEY = "material.grain.kn="


def fluctuations(profiles, mono):
    """Per row of profiles: max |row - mean of the rows| / max(mono)."""
    P = np.asarray(profiles, dtype=float)
    top = float(np.max(np.asarray(mono, dtype=float)))
    if not top > 0:
        raise EvalError(f"ens_fluct(): the monodisperse profile's largest value is {top:g}")
    mean, _ = mean_profile(P)
    return np.max(np.abs(P - mean), axis=1) / top


def rho(final, sets):
    """rho = r_d k_n / (sigma d), sigma = W / l, of one pile run; k_n from its --set list."""
    pile = (final.info.get("piles") or [{}])[0]
    r_d, d = pile.get("size_spread", 0.0), pile.get("d")
    kn = [s[len(KN_KEY):] for s in sets or [] if isinstance(s, str) and s.startswith(KN_KEY)]
    if not kn:
        raise EvalError(f"ens_rho(): run.json's sets give no {KN_KEY}... (the case must set k_n)")
    if d is None:
        raise EvalError("ens_rho(): run.json's pile has no d")
    l = piles.pile(final)[1]
    return float(r_d) * float(kn[-1]) * l / (final.weight() * float(d))


def bind(run, sibling=None):
    def finals(name, fname):
        out = []
        for variant in ensemble_members(sibling, name, fname):
            out.append((variant, state(sibling_run(sibling, variant, fname))))
        return out

    def stack(name, fname, get):
        rows, width = [], None
        for variant, final in finals(name, fname):
            try:
                values = np.asarray(get(final), dtype=float)
            except EvalError as exc:
                raise EvalError(f"{fname}(): realisation '{variant}': {exc}") from None
            if width is not None and values.size != width:
                raise EvalError(f"{fname}(): realisation '{variant}' has {values.size} discs in the "
                                f"row, the others {width}")
            width = values.size
            rows.append(values)
        return np.array(rows)

    def profiles(name, component, row, fname):
        return stack(name, fname, lambda f: piles.pile_S(f, component, row))

    def ens_X(name, row=1):
        return stack(name, "ens_X", lambda f: piles.pile_X(f, row)).mean(axis=0)

    def ens_S(name, component="zz", row=1):
        return mean_profile(profiles(name, component, row, "ens_S"))[0]

    def ens_S_se(name, component="zz", row=1):
        return mean_profile(profiles(name, component, row, "ens_S_se"))[1]

    def dip(name, component="zz", row=1, flank=FLANK):
        return dip_with_se(profiles(name, component, row, "dip"), ens_X(name, row), flank)[0]

    def dip_se(name, component="zz", row=1, flank=FLANK):
        return dip_with_se(profiles(name, component, row, "dip_se"), ens_X(name, row), flank)[1]

    def profile_dip(profile, X, flank=FLANK):
        return dip_depth(profile, X, flank)

    def coordination(row_min=1):
        return coordination_number(state(run), piles.whole(row_min, "coordination", "row_min"))

    def ens_forces(name):
        parts = []
        for variant, final in finals(name, "ens_forces"):
            try:
                parts.append(normalised_forces(final))
            except EvalError as exc:
                raise EvalError(f"ens_forces(): realisation '{variant}': {exc}") from None
        return np.concatenate(parts)

    def ens_fluct(name, mono):
        mono_profile = piles.pile_S(state(sibling_run(sibling, mono, "ens_fluct")), "zz", 1)
        return fluctuations(profiles(name, "zz", 1, "ens_fluct"), mono_profile)

    def ens_rho(name):
        variant = ensemble_members(sibling, name, "ens_rho")[0]
        first = sibling_run(sibling, variant, "ens_rho")
        return rho(state(first), first.info.get("sets"))

    def sized(name, sizes, fname, blocks=1):
        """(profiles, X, [n, ...]) of ensemble name, each n whole, >= 2 and with `blocks` blocks."""
        P = profiles(name, "zz", 1, fname)
        if isinstance(sizes, str) or np.ndim(sizes) != 1 or len(sizes) == 0:
            raise EvalError(f"{fname}(): sizes must be a list of numbers of realisations, e.g. [10, 20, 50]")
        out = []
        for n in sizes:
            if isinstance(n, bool) or not float(n).is_integer() or not 2 <= n <= P.shape[0] // blocks:
                raise EvalError(f"{fname}(): {n!r} realisations: sizes must be whole numbers from 2 to "
                                f"{P.shape[0] // blocks} ({P.shape[0]} realisations"
                                + (f", at least {blocks} blocks)" if blocks > 1 else ")"))
            out.append(int(n))
        return P, ens_X(name), out

    def dip_first(name, sizes):
        P, X, ns = sized(name, sizes, "dip_first")
        return np.array([d for d, _ in first_dips(P, X, ns)])

    def dip_se_first(name, sizes):
        P, X, ns = sized(name, sizes, "dip_se_first")
        return np.array([se for _, se in first_dips(P, X, ns)])

    def se_blocks(name, sizes, fname="dip_se_blocks"):
        P, X, ns = sized(name, sizes, fname)
        return ns, np.array([np.mean([se for _, se in block_stats(P, X, n)]) for n in ns])

    def dip_se_blocks(name, sizes):
        return se_blocks(name, sizes)[1]

    def dip_sd_blocks(name, sizes):
        P, X, ns = sized(name, sizes, "dip_sd_blocks", blocks=2)
        return np.array([np.std([d for d, _ in block_stats(P, X, n)], ddof=1) for n in ns])

    def dip_mean_blocks(name, sizes):
        P, X, ns = sized(name, sizes, "dip_mean_blocks")
        return np.array([np.mean([d for d, _ in block_stats(P, X, n)]) for n in ns])

    def law(name, sizes, fname):
        if np.ndim(sizes) == 1 and len(set(np.asarray(sizes, dtype=float).tolist())) < 2:
            raise EvalError(f"{fname}(): needs two or more different sizes")
        return power_law(*se_blocks(name, sizes, fname))

    def se_exponent(name, sizes):
        return law(name, sizes, "se_exponent")[1]

    def n_for_z(name, z, sizes):
        return n_for(z, dip(name), *law(name, sizes, "n_for_z"))

    def log10(x):
        x = np.asarray(x, dtype=float)
        if np.any(~(x > 0)):
            raise EvalError("log10(): a value is not positive")
        return np.log10(x)

    return {"ens_fluct": ens_fluct, "ens_rho": ens_rho, "log10": log10, "ens_X": ens_X, "ens_S": ens_S, "ens_S_se": ens_S_se, "dip": dip, "dip_se": dip_se,
            "profile_dip": profile_dip, "coordination": coordination, "ens_forces": ens_forces,
            "tail_rate": tail_rate, "tail_ks": tail_ks, "dip_first": dip_first, "dip_se_first": dip_se_first,
            "dip_se_blocks": dip_se_blocks, "dip_sd_blocks": dip_sd_blocks, "dip_mean_blocks": dip_mean_blocks,
            "se_exponent": se_exponent,
            "n_for_z": n_for_z}


register("pile_stats", NAMES, bind)
