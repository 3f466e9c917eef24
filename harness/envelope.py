"""The error envelope of a quantity that converges in h but not smoothly (issue 31).

Richardson extrapolation (study.analyse) assumes q(h) = q* + C h^p + o(h^p) with ONE constant
C.  An event that falls inside a step while a force jumps breaks it: a spring-dashpot collision
starts and ends between two steps, and its damping force jumps by gamma v_n at both ends, so the
impulse of the step that straddles the end depends on where in the step the end falls.  The
error is then

    e(h) = q(h) - q* = c(h) h^p,   c(h) bounded but erratic:

c depends on the phase of the event within its step, and that phase jumps from one h to the
next (halving h maps a phase phi to 2 phi mod 1).  Measured on the spring-dashpot restitution
of harness/tests/test_study.py (k = 7000, gamma = 40, e = 0.4845): over 240 steps from 2e-6 to
2e-3, (e(h)/e*)/h ranged from -38 to +25 with no trend, i.e. order 1 with an erratic coefficient.
Four levels of such a sequence can keep one sign and agree on an order by chance, and then the
Richardson limit is off by the erratic term itself (1.2e-3 of e* from 2^-11 .. 2^-14).

So a study also runs the geometric midpoints h_k f^(1/2) between successive levels.  A smooth
quantity's midpoint lies on the power law through the levels; where one departs from it by more
than SMOOTH_TOLERANCE of the difference between its two neighbours the quantity is 'not smooth in
h', and so is a quantity whose differences change sign.  For those, this module bounds instead
of extrapolating:

  * the envelope order p: the least-squares slope of log|q_{i+1} - q_i| against log h over all
    points sorted by h (levels, midpoints and the extra samples below);
  * the limit q* and the mean coefficient c: weighted least squares of q_i = q* + c h_i^p with
    weights h_i^-p (the erratic term is proportional to h^p, so each point counts by its own
    noise);
  * the envelope K = max_i |q_i - q*| / h_i^p over all points, and the limit's uncertainty
    U = ENVELOPE_MARGIN K h_min^p: the finest point lies within K h_min^p of the limit, and the
    margin covers a K that understates the erratic coefficient's range (below) and an order p
    off by its scatter, which bias the fitted q*;
  * advice: the largest h with K h^p <= target |q*| / ENVELOPE_MARGIN, given only when U is
    below target |q*| / RESOLVE (otherwise the check run could not tell a hit from a miss: refine
    further).

K is the largest of a sample of an erratic coefficient, so more samples give a truer K:
samples() adds ENVELOPE_SAMPLES cheap runs spread over the two coarsest intervals (a sample
there costs 1/2^(levels-2) of the finest level or less), used only for quantities found not
smooth.
"""
import math

import numpy as np

# A smooth quantity's midpoint departs from the power law through its neighbours by the
# o(h^p) terms only: measured 1-5 % of the neighbours' difference for the contact durations of
# test_study.py (linear and Hertz), against ~100 % for the spring-dashpot's restitution.  A
# quarter separates the two by a factor 5 either way (and matches study.ORDER_AGREE's spirit).
SMOOTH_TOLERANCE = 0.25
# Fewest points (levels + midpoints + samples) for an envelope: the envelope order scatters
# with the erratic term; from 4 levels and 3 midpoints of the restitution it came out 1.46 and
# 1.62 (true 1), and the advice from it missed; from 6 levels and more, 1.02-1.37, and it met.
MIN_POINTS = 11
# And they must span at least a factor 2^5 in h (6 levels at f = 1/2), for the same reason.
MIN_SPAN = 32.0
# An envelope order at or below this is no convergence (as study.P_MIN).
P_MIN = 0.5
# Advice aims at K h^p = target / ENVELOPE_MARGIN.  K is a sample maximum of an erratic
# coefficient and p a fit to scattered differences.  Measured on the restitution (nine studies:
# bases 2^-9, 2^-10, 2^-11 x 6, 8, 10 levels, with midpoints and samples; 19 advised steps for
# targets 1e-2 .. 1e-4): with a margin of 1, 3 of 19 missed the closed form (worst 1.24 x the
# target); with 2, none did (worst 0.79 x), and every advised step lay within 0.5-1.5 x the
# largest step below which every step meets (from the 240-step scan).
ENVELOPE_MARGIN = 2.0
# The limit must be known to target / RESOLVE for a check run to tell a hit from a miss.
RESOLVE = 2.0
# Extra samples for the envelope of a not-smooth quantity (see the module's docstring).
ENVELOPE_SAMPLES = 12
GOLDEN = (math.sqrt(5) - 1) / 2


def midpoints(hs, factor):
    """The geometric midpoints between successive levels hs (coarsest first)."""
    return [h * factor ** 0.5 for h in hs[:-1]]


def samples(hs):
    """ENVELOPE_SAMPLES steps log-spaced inside (hs[2], hs[0]), the two coarsest intervals, each
    offset within its slot by the golden ratio's fraction so that none falls on a level or a
    midpoint (those sit at 0, 1/4, 1/2, 3/4 and 1 of the span in log h)."""
    lo, hi = math.log(hs[2]), math.log(hs[0])
    return [math.exp(lo + (hi - lo) * (k + GOLDEN) / ENVELOPE_SAMPLES) for k in range(ENVELOPE_SAMPLES)]


def departures(hs, qs, analysis, mids, qmids):
    """For a quantity analysed as converging (study.analyse): each midpoint's departure from the
    power law q* + (q_k - q*) (h / h_k)^p through its coarser neighbour, as a fraction of the
    difference between its two neighbours.  None where a value is missing."""
    p, limit = analysis["order"], analysis["limit"]
    out = []
    for k, (h, q) in enumerate(zip(mids, qmids)):
        if q is None or not math.isfinite(q) or qs[k + 1] == qs[k]:
            out.append(None)
            continue
        predicted = limit + (qs[k] - limit) * (h / hs[k]) ** p
        out.append(abs(q - predicted) / abs(qs[k + 1] - qs[k]))
    return out


def smooth(deps):
    """True when every measured midpoint lies on the power law within SMOOTH_TOLERANCE.  A
    midpoint without a value (its run failed, e.g. a guard stopped it) is no evidence either way
    and is left out; with none measured the levels' verdict stands."""
    return all(d <= SMOOTH_TOLERANCE for d in deps if d is not None)


def bound(hs, qs):
    """The envelope of a not-smooth quantity from all its points (any order).

    {ok, text, order, limit, mean, K, uncertainty, points}: ok False (with text saying why)
    when the points are too few or too close, or the envelope does not shrink (order <= P_MIN);
    K and uncertainty are absolute (divide by |limit| for relative)."""
    pts = sorted((h, q) for h, q in zip(hs, qs) if q is not None and math.isfinite(q))
    out = {"ok": False, "text": "", "order": None, "limit": None, "mean": None, "K": None,
           "uncertainty": None, "points": len(pts)}
    if len(pts) < MIN_POINTS or pts[-1][0] / pts[0][0] < MIN_SPAN * (1 - 1e-9):
        out["text"] = (f"{len(pts)} points over a factor {pts[-1][0] / pts[0][0]:.3g} in h" if pts else "no points")
        out["text"] += (f"; an envelope needs >= {MIN_POINTS} points over a factor >= {MIN_SPAN:g} "
                        "(--levels 6 or more, with the midpoints)")
        return out
    h = np.array([a for a, _ in pts])
    q = np.array([b for _, b in pts])
    d = np.abs(np.diff(q))
    hm = np.sqrt(h[1:] * h[:-1])
    keep = d > 0
    if keep.sum() < 2:
        out["text"] = "the values do not change with h"
        return out
    p = float(np.polyfit(np.log(hm[keep]), np.log(d[keep]), 1)[0])
    out["order"] = p
    if p <= P_MIN:
        out["text"] = (f"its envelope does not shrink: order {p:.3g} <= {P_MIN:g} over {len(pts)} points "
                       "(noise or chaos)")
        return out
    w = h ** -p
    # q_i h_i^-p = c + q* h_i^-p: ordinary least squares in these variables weighs each point by
    # h_i^-p, i.e. by its own erratic term's size.
    limit, mean = np.linalg.lstsq(np.vstack([w, np.ones_like(w)]).T, q * w, rcond=None)[0]
    K = float(np.max(np.abs(q - limit) * w))
    out.update(ok=True, order=p, limit=float(limit), mean=float(mean), K=K, uncertainty=ENVELOPE_MARGIN * K * h[0] ** p)
    rel = f" ({out['uncertainty'] / abs(limit):.2g} of it)" if limit != 0 else ""
    out["text"] = (f"bounded: |q - q*| <= K h^p with envelope order {p:.3g}, "
                   f"K = {K:.4g}, over {len(pts)} points; q* = {limit:.8g} +- {out['uncertainty']:.2g}{rel}")
    return out


def advise(env, target):
    """(h, predicted bound on the relative error at h) or (None, why) for an envelope env."""
    if not env["ok"]:
        return None, "no envelope: " + env["text"]
    limit = abs(env["limit"])
    if limit == 0:
        return None, "the limit is 0: a relative target has no meaning"
    if env["uncertainty"] > target * limit / RESOLVE:
        return None, (f"the limit is known to {env['uncertainty'] / limit:.2g} of it, above target/{RESOLVE:g}: "
                      "add levels (--levels) so the check can resolve the target")
    if env["K"] == 0:
        return None, "no scatter to bound"
    h = (target * limit / ENVELOPE_MARGIN / env["K"]) ** (1.0 / env["order"])
    return h, env["K"] * h ** env["order"] / limit
