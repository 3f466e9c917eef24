"""Error against cost: the errors of a sweep's points, the Richardson analysis of a refinement,
and the table and figure they are shown in -- one implementation for `harness study`
(study.py), `harness sweep CASE --set` (sweep_grid.py) and the declared [sweep] sections
(sweep.py), which add the catalogue's own error terms (reference checks) on top.

  * deviation(q, ref) = |q - ref| / |ref| (|q - ref| when ref = 0): every error of every sweep.
  * finest_index(): the reference point of self-convergence, the FINEST point: status ok, a
    particle-step count, every quantity measured; the most particle-steps, the last on a tie.
    reference_points() picks it per group of a grid (the points with the same values on every
    axis but the last); a declared sweep is one group.
  * analyse() / advise() / cost_model(): the Richardson analysis of levels h, h f, h f^2 ...
    (observed orders, a verdict, the limit q* and each level's error against it; the largest h
    predicted to meet a target, and its cost) -- thresholds below, with their reasons.
  * aligned(): a terminal table's columns; plot(): a log-log gnuplot figure (NAME.dat, NAME.gp,
    NAME.svg; None when gnuplot fails); cost_curves(): each quantity's error by particle-steps.
"""
import math
import subprocess
from pathlib import Path

import numpy as np

from . import files

MIN_LEVELS = 3          # two differences give one pairwise order; three levels are the least
# A pairwise order below P_MIN means a refinement by r cut the difference by less than r^P_MIN
# (1.41 for r = 2): the differences are not shrinking the way a convergent sequence's do, as in
# a chaotic scene whose particle-level quantities differ by O(1) at every step size.
P_MIN = 0.5
# Pairwise orders that differ by more than ORDER_AGREE are not yet asymptotic.  With p off by
# 0.25 the Richardson error estimate d/(r^p - 1) is off by at most ~40 % for p >= 1, r = 2,
# which ADVICE_MARGIN covers; a larger spread would make the extrapolation a guess.
ORDER_AGREE = 0.25
# Differences below ROUNDOFF x |q| are floating-point noise: the quantity does not depend on h.
ROUNDOFF = 1e-12
# The advice aims at REL / ADVICE_MARGIN: the error model's constant and q* are estimates from
# the levels (their own error is of the order of the pairwise orders' spread, see ORDER_AGREE).
ADVICE_MARGIN = 2.0
GNUPLOT_TIMEOUT = 60    # seconds
STYLE = Path(__file__).resolve().parent / "gnuplot" / "style.gp"


# ---------------------------------------------------------------- errors against a point

def deviation(q, ref):
    """|q - ref| / |ref|, or |q - ref| when ref = 0."""
    return abs(q - ref) / abs(ref) if ref != 0 else abs(q - ref)


def finest_index(costs, among=None, usable=None):
    """The index of the finest point among the indices `among` (default: every point): status
    ok, a particle-step count and usable(i) (default: any); the most particle-steps, the last
    on a tie (equal cost: none is finer, and the last is the one a sweep lists as its end).
    None if no point qualifies."""
    among = range(len(costs)) if among is None else among
    ok = [i for i in among if costs[i]["status"] == "ok" and costs[i]["particle_steps"] is not None
          and (usable is None or usable(i))]
    return max(ok, key=lambda i: (costs[i]["particle_steps"], i)) if ok else None


def reference_points(point_values, costs, usable=None):
    """Each point's reference: the finest point (finest_index) among those with its values on
    every axis but the last (the whole sweep for one axis); None where there is none.  The last
    axis is the one a point's error is measured along: put the resolution key (the step, 1/kn)
    last."""
    return [finest_index(costs, [j for j, other in enumerate(point_values) if other[:-1] == pv[:-1]], usable)
            for pv in point_values]


# ---------------------------------------------------------------- the Richardson analysis (pure)

def analyse(hs, qs, factor):
    """The convergence of one quantity over levels hs (coarsest first) with values qs.

    {verdict, text, order, orders, order_lsq, limit, errors, diffs}: verdict is 'converging',
    'asymptotic?' (not yet in the asymptotic range), 'not converging', 'independent' (the
    differences are round-off) or 'failed' (a value is missing); order is the p used (the
    finest pairwise order), limit the Richardson q* (None unless converging or independent),
    errors each level's |q - q*| / |q*| (None where there is no q*)."""
    r = 1.0 / factor
    out = {"verdict": "failed", "text": "", "order": None, "orders": [], "order_lsq": None,
           "limit": None, "errors": [None] * len(qs), "diffs": []}
    if any(q is None or not math.isfinite(q) for q in qs):
        out["text"] = "no value at some level (see the table)"
        return out
    d = [b - a for a, b in zip(qs, qs[1:])]
    out["diffs"] = d
    scale = max(abs(q) for q in qs)
    if max(abs(x) for x in d) <= ROUNDOFF * max(scale, np.finfo(float).tiny):
        out.update(verdict="independent", limit=qs[-1], errors=[0.0] * len(qs),
                   text=f"independent of h: every difference is at round-off (<= {ROUNDOFF:g} |q|)")
        return out
    if any(x == 0 for x in d):
        out.update(verdict="not converging", text="some differences are exactly zero and others not: "
                                                  "not a smooth sequence in h")
        return out
    orders = [math.log(abs(a) / abs(b)) / math.log(r) for a, b in zip(d, d[1:])]
    out["orders"] = orders
    out["order_lsq"] = float(np.polyfit(np.log(hs[:-1]), np.log(np.abs(d)), 1)[0])
    listed = ", ".join(f"{p:.3g}" for p in orders)
    if min(orders) <= P_MIN:
        out.update(verdict="not converging",
                   text=f"not converging: pairwise orders {listed}; a refinement by {r:g} must cut the "
                        f"difference by at least {r:g}^{P_MIN:g} (order > {P_MIN:g}): noise or chaos, "
                        f"no extrapolation; the levels spread over {spread(qs)}")
        return out
    if any((a > 0) != (b > 0) for a, b in zip(d, d[1:])):
        out.update(verdict="asymptotic?",
                   text=f"not yet in the asymptotic range: the differences change sign (pairwise orders "
                        f"{listed}): the error is not a smooth power of h here (a phase effect within "
                        "the step, or noise); no extrapolation")
        return out
    if max(orders) - min(orders) > ORDER_AGREE:
        out.update(verdict="asymptotic?",
                   text=f"not yet in the asymptotic range: pairwise orders {listed} differ by more than "
                        f"{ORDER_AGREE:g}; refine further (--levels, or a smaller base)")
        return out
    p = orders[-1]
    limit = qs[-1] + d[-1] / (r ** p - 1)
    errors = [deviation(q, limit) for q in qs]
    out.update(verdict="converging", order=p, limit=limit, errors=errors,
               text=f"converging at order {p:.3g} (pairwise {listed}; least squares {out['order_lsq']:.3g})")
    return out


def spread(qs):
    """max - min of the levels' values, and relative to the largest |q|: what a user can count on
    when the quantity does not converge."""
    width, top = max(qs) - min(qs), max(abs(q) for q in qs)
    return f"{width:.3g}" + (f" ({width / top:.2g} of |q|)" if top > 0 else "")


def advise(hs, analysis, target):
    """(h, predicted relative error at h) for a converging quantity: the largest h with
    e(h) = e_finest (h / h_finest)^p <= target / ADVICE_MARGIN; None when there is no advice
    (not converging, or a limit no larger than the last difference: a quantity converging to 0,
    such as an energy error, whose relative error only grows as it converges).  An independent
    quantity meets any target at the coarsest h."""
    if analysis["verdict"] == "independent":
        return hs[0], 0.0
    if analysis["verdict"] != "converging" or abs(analysis["limit"]) <= abs(analysis["diffs"][-1]):
        return None
    p, e_f = analysis["order"], analysis["errors"][-1]
    if e_f == 0:
        return hs[0], 0.0
    h = hs[-1] * (target / ADVICE_MARGIN / e_f) ** (1.0 / p)
    return h, e_f * (h / hs[-1]) ** p


def cost_model(hs, costs):
    """cost(h) by a least-squares power law over the levels with a cost (None when < 2)."""
    pts = [(h, c) for h, c in zip(hs, costs) if isinstance(c, (int, float)) and c > 0]
    if len(pts) < 2:
        return None
    slope, icpt = np.polyfit(np.log([h for h, _ in pts]), np.log([c for _, c in pts]), 1)
    return lambda h: float(math.exp(icpt + slope * math.log(h)))


# ---------------------------------------------------------------- the table and the figure

def num(x, fmt=".6g"):
    """A number for a table: '-' for none."""
    return "-" if x is None else format(x, fmt)


def aligned(rows):
    """Rows of cells as lines of left-aligned columns two blanks apart (trailing blanks cut)."""
    widths = [max(len(r[j]) for r in rows) for j in range(len(rows[0]))]
    return ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]


def cost_curves(names, errors, costs, skip=None):
    """[(name, [(particle-steps, error)])]: each quantity's points with a cost and an error > 0
    (a zero error has no place on a log axis), by cost; skip(i): a point left out (its own
    reference)."""
    curves = []
    for name in names:
        pts = [(costs[i]["particle_steps"], e) for i, e in enumerate(errors[name])
               if not (skip and skip(i)) and e and e > 0 and isinstance(costs[i].get("particle_steps"), int)]
        if pts:
            curves.append((name, sorted(pts)))
    return curves


def plot(folder, name, curves, xlabel, ylabel, key):
    """NAME.svg in folder: each curve (title, [(x, y)]) as lines and points on log-log axes,
    from NAME.dat and NAME.gp (kept beside it); the file's name, or None when there is no
    curve or gnuplot fails (missing, an error, or over GNUPLOT_TIMEOUT)."""
    if not curves:
        return None
    data = []
    for title, pts in curves:
        data += [f"# {title}"] + [f"{x!r} {y!r}" for x, y in pts] + ["", ""]
    files.write_text(Path(folder) / f"{name}.dat", "\n".join(data) + "\n")
    esc = lambda s: s.replace("\\", "\\\\").replace('"', '\\"')
    plots = ", ".join(f'"{name}.dat" index {i} using 1:2 with linespoints title "{esc(t)}"'
                      for i, (t, _) in enumerate(curves))
    gp = [f'load "{esc(str(STYLE))}"', "set terminal svg size 800,500", f'set output "{name}.svg"',
          "set logscale xy", f'set xlabel "{esc(xlabel)}"', f'set ylabel "{esc(ylabel)}"',
          f"set key inside {key}", f"plot {plots}"]
    files.write_text(Path(folder) / f"{name}.gp", "\n".join(gp) + "\n")
    try:
        done = subprocess.run(["gnuplot", f"{name}.gp"], cwd=folder, capture_output=True, timeout=GNUPLOT_TIMEOUT,
                              stdin=subprocess.DEVNULL)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return f"{name}.svg" if done.returncode == 0 and (Path(folder) / f"{name}.svg").is_file() else None
