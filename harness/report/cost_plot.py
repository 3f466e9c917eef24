"""The error-against-cost diagram of a swept case (reports/sweeps/<case>/cost.tsv, sweep.py):
error against particle-steps on log-log axes, one curve per sweep, the default tier's setting
marked, failed (unstable) points as crosses on a line at the top.  Drawn by gnuplot through
plots.py.
"""
import math
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path

from .. import files
from ..sweep import failed, is_default
from .plots import FigureOut, drawings, gnuplot_script, gp_string, publish, run_gnuplot


def cost_points(rows):
    """({sweep: [(cost, error, label)]} sorted by factor, the default points (one per swept variant), notes,
    {sweep: [(cost, label)]} of the failed points (unstable: drawn at the top of the diagram))."""
    curves, defaults, notes, bad = {}, [], [], {}
    for r in rows:
        x, y = r["particle_steps"], r["error"]
        what = "default" if is_default(r) else f"{r['sweep']} x{r['factor']:g}"
        if failed(r):
            if x is not None and x > 0:
                bad.setdefault(r["sweep"], []).append((r["factor"], x))
                notes.append(f"{what}: {r['status']} (drawn at the top, at the cost it spent before stopping)")
            else:
                notes.append(f"{what}: {r['status']}, not drawn ({r['note'] or 'no cost'})")
            continue
        if x is None or y is None:
            if not is_default(r) or not defaults:
                notes.append(f"{what}: not drawn (no error: {r['note'] or 'no error term'})")
            continue
        if not (x > 0 and y > 0):
            notes.append(f"{what}: not drawn: error {y:.3g} is not positive (log scale)")
            continue
        if is_default(r) and (x, y) not in defaults:
            defaults.append((x, y))
        curves.setdefault(r["sweep"], []).append((r["factor"], x, y, is_default(r)))
    return ({k: [(x, y, "" if d else f"x{f:g}") for f, x, y, d in sorted(v)] for k, v in curves.items()}, defaults,
            list(dict.fromkeys(notes)),
            {k: [(x, f"x{f:g} {UNSTABLE}") for f, x in sorted(v)] for k, v in bad.items()})


UNSTABLE = "unstable"
POINT_TYPES = (7, 6, 5, 4, 9, 8, 11, 10, 13, 12)
# Where each curve's labels sit against their points (characters): curves take turns, so the
# labels of curves through one point do not print over each other.
LABEL_OFFSETS = ("left offset char 0.6,0.6", "left offset char 0.6,-0.9", "right offset char -0.6,-0.9",
                 "right offset char -0.6,0.6")
NEAR = (0.06, 0.12)     # decades in cost and error within which two points of a curve share a label


def merged_labels(points, near=NEAR):
    """The (x, y, label) of one curve with the labels of points that lie within `near` (decades,
    log-log) of an earlier labelled point joined onto that one ('x0.5, x2, x4') and their own
    blanked, so points that coincide are labelled once, legibly."""
    out, placed = [list(p) for p in points], []
    for p in out:
        if not p[2]:
            continue
        for q in placed:
            if abs(math.log10(p[0] / q[0])) < near[0] and abs(math.log10(p[1] / q[1])) < near[1]:
                q[2] += ", " + p[2]
                p[2] = ""
                break
        else:
            placed.append(p)
    return [tuple(p) for p in out]


def render_cost(case, rows, figures_dir):
    """The log-log diagram: error (y) against particle-steps (x), one curve per sweep, default marked;
    failed (unstable) points as crosses on a line at the top, labelled "unstable"."""
    out = FigureOut("error_cost_sweep", f"{case.name}: error against cost (declared sweeps)")
    png, svg = (Path(figures_dir) / f"{case.name}_error_cost_sweep.{ext}" for ext in ("png", "svg"))
    for old in (png, svg):
        files.remove(old)
    curves, defaults, out.notes, bad = cost_points(rows)
    if not curves and not bad:
        out.notes.append("nothing to plot")
        return out
    if not shutil.which("gnuplot"):
        out.notes.append("gnuplot not found: figure not rendered")
        return out
    figure = _CostAxes(out.title)
    if any(str(r["worst"]).startswith("vs finest: ") for r in rows):
        figure.ylabel = "error against the finest swept run: max |q - q_finest| / |q_finest| (-)"
    errors = [y for pts in curves.values() for _, y, _ in pts]
    top = max(errors) * 10 if errors else 1.0
    names = list(dict.fromkeys(list(curves) + list(bad)))
    with tempfile.TemporaryDirectory(prefix="ballast-cost-") as workdir:
        clauses = []
        for i, name in enumerate(names):
            if name in curves:
                path = Path(workdir) / f"curve{i}.dat"
                files.write_text(path, "".join(f"{x!r}\t{y!r}\t\"{label}\"\n"
                                               for x, y, label in merged_labels(curves[name])))
                # point types cycle filled/open, so curves that coincide (verlet on centred) stay visible
                clauses += [f"{gp_string(path)} using 1:2 with linespoints pt {POINT_TYPES[i % len(POINT_TYPES)]} "
                            f"ps {1.0 if i % 2 == 0 else 1.6} lc {i + 1} title {gp_string(name)}",
                            f"{gp_string(path)} using 1:2:3 with labels {LABEL_OFFSETS[i % len(LABEL_OFFSETS)]} "
                            f"tc lt {i + 1} notitle"]
            if name in bad:
                path = Path(workdir) / f"failed{i}.dat"
                files.write_text(path, "".join(f"{x!r}\t{top!r}\t\"{label}\"\n" for x, label in bad[name]))
                clauses += [f"{gp_string(path)} using 1:2 with points pt 2 ps 2 lw 2 lc {i + 1} "
                            f"title {gp_string(name + ': ' + UNSTABLE)}",
                            f"{gp_string(path)} using 1:2:3 with labels rotate by 90 left offset char 0,1 "
                            f"tc lt {i + 1} notitle"]
        if defaults:
            path = Path(workdir) / "default.dat"
            files.write_text(path, "".join(f"{x!r}\t{y!r}\n" for x, y in defaults))
            clauses.append(f"{gp_string(path)} using 1:2 with points pt 3 ps 3 lw 2 lc rgb 'black' "
                           "title 'default tier setting'")
        extra = ["set logscale xy", "set key outside"]
        if bad:
            extra.append(f"set arrow from graph 0, first {top!r} to graph 1, first {top!r} nohead dt 3 lc rgb 'gray'")
            extra.append(f"set label {gp_string('failed runs (' + UNSTABLE + '): no error')} at graph 0.01, "
                         f"first {top!r} offset 0,-0.8 tc rgb 'gray'")
            if errors:
                extra.append(f"set yrange [{min(errors) / 3!r}:{top * 30!r}]")
        drawn = drawings(workdir)
        error = run_gnuplot(gnuplot_script(figure, clauses, *drawn, extra), workdir)
        out.png, out.svg = publish(drawn, (png, svg))
    if error:
        out.notes.append(f"gnuplot failed: {error}")
    return out


@dataclass
class _CostAxes:
    """What gnuplot_script needs of a figure, for the cost diagram."""
    title: str
    xlabel: str = "cost: particle-steps (steps x discs)"
    ylabel: str = "error: max |q - ref| / |ref| over the error terms (-)"
    xrange: str = ""
    yrange: str = ""
