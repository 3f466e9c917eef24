"""The report's figures, drawn by gnuplot: one script maker per figure kind of case.txt
(SCRIPTS; kinds as in catalogue.py), and the running of gnuplot, which the error-against-cost
diagram (cost_plot.py) shares.

Figure kinds: series (columns of series.tsv against x, and any reference lines
y = slope x + intercept, dashed grey); network (force network, see
network.py); profile (pile_S(component, row) against pile_X(row), lines with points, one
curve per variant and component, from families/piles.py); principal (MLH Fig. 3(d): the discs of
the final state and, centred on every free disc, a line along the most compressive
principal axis of length proportional to S_max and one across it proportional to S_min,
compression positive, tensile values in red, the largest |S| drawn PRINCIPAL_SHARE of the
largest diameter; `set arrow ... nohead` per line, square aspect); points (one point per
variant at (x, y) = two quantity expressions, joined in the order listed and labelled
with the variant name, optional log axes); curves (per variant, one line per y of array
expressions against the array expression x, JYH Fig. 11); errorbars (per variant a point of
quantity expressions; the variants sharing an x drawn as one point at the mean of their y with
a bar from the least to the largest, joined per series, and the paper's published points beside,
JYH Fig. 13); fit (per group of variants and per (x, y) pair, the points and their least-squares
line drawn from x = 0 or the least x, whichever is smaller, to the largest x, its slope and
intercept in the legend, JYH Fig. 12); snapshots and movie (the variants' snapshots drawn to
scale by harness/pictures.py: a PNG grid of frames, an animated GIF).  Whatever a figure cannot
show -- a variant without data, an expression that fails, a non-positive value on a log axis,
non-finite values -- is listed in its notes, never silently dropped.

gnuplot draws in a scratch folder; each figure reaches reports/figures through files.py
(a temporary file, then rename), so a killed report leaves it old or new, never cut.
"""
import shutil
import subprocess
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import files, pictures
from ..children import options as child_options
from ..compare import evaluate, evaluate_array
from ..errors import EvalError, RunProblem
from ..expressions import Siblings
from ..families import piles
from ..final_state import state
from . import network

STYLE = Path(__file__).resolve().parent.parent / "gnuplot" / "style.gp"
SIZE = "960,540"


@dataclass
class FigureOut:
    name: str
    title: str
    paper: str = ""
    svg: Path = None
    png: Path = None         # the raster image: a PNG, or a GIF for a movie (RASTER)
    notes: list = field(default_factory=list)


# ---------------------------------------------------------------- figures

def gp_string(text):
    """A gnuplot single-quoted string."""
    return "'" + str(text).replace("'", "''") + "'"


def curve_title(variant, column, figure):
    """A curve's legend: the variant's `label` (its name when it has none), and the column when
    the figure draws several."""
    if len(figure.variants) == 1:
        return column
    name = figure.names.get(variant, variant)
    return name if len(figure.y) == 1 else f"{name}: {column}"


def figure_data(case, figure, store, workdir):
    """Write one data file per variant (x then the y columns it has); the plot clauses and notes."""
    clauses, notes = [], []
    for variant in figure.variants:
        try:
            columns = store.get(case.name, variant).columns
        except RunProblem as problem:
            notes.append(f"{variant}: no data ({problem})")
            continue
        present = [y for y in figure.y if y in columns]
        missing = [c for c in [figure.x] + figure.y if c not in columns]
        if missing:
            notes.append(f"{variant}: column(s) missing from series.tsv: {', '.join(missing)}")
        if figure.x not in columns or not present:
            continue
        path = Path(workdir) / f"{variant}.dat"
        _write_columns(path, [columns[figure.x]] + [columns[y] for y in present])
        clauses += [f"{gp_string(path)} using 1:{i + 2} with lines title {gp_string(curve_title(variant, y, figure))}"
                    for i, y in enumerate(present)]
    return clauses, notes


def _write_columns(path, arrays):
    files.write_text(path, "".join("\t".join(repr(float(x)) for x in row) + "\n" for row in zip(*arrays)))


def gnuplot_script(figure, clauses, png, svg, settings=()):
    """The script rendering one figure to png then svg (settings: extra lines before plot)."""
    return "\n".join([
        f"set terminal pngcairo size {SIZE} noenhanced font 'sans,10'",
        f"set output {gp_string(png)}",
        f"load {gp_string(STYLE)}",
        f"set title {gp_string(figure.title)}",
        f"set xlabel {gp_string(figure.xlabel)}",
        f"set ylabel {gp_string(figure.ylabel)}",
        f"set xrange [{figure.xrange or '*:*'}]",
        f"set yrange [{figure.yrange or '*:*'}]",
        *settings,
        "plot " + ", \\\n     ".join(clauses),
        f"set terminal svg size {SIZE} noenhanced font 'sans,10' background '#ffffff'",
        f"set output {gp_string(svg)}",
        "replot",
        "unset output",
        ""])


# ---- one script maker per figure kind: (gnuplot script or None, notes)


def _series_script(case, figure, store, workdir, png, svg):
    clauses, notes = figure_data(case, figure, store, workdir)
    if not clauses:
        return None, notes + ["nothing to plot"]
    return gnuplot_script(figure, clauses + line_clauses(figure.lines), png, svg), notes


def line_clauses(lines):
    """A series figure's reference lines y = slope x + intercept, grey and dashed.  Each titled
    line has a dash pattern of its own; a line without a title is drawn like the one before
    it and kept out of the key (the lower of a pair +-M)."""
    clauses, dash = [], 1
    for k, (slope, intercept, title) in enumerate(lines):
        dash += 1 if title or k == 0 else 0
        clauses.append(f"{slope!r} * x + {intercept!r} with lines dt {dash} lw 1.2 lc rgb '#555555' "
                       + (f"title {gp_string(title)}" if title else "notitle"))
    return clauses


def _network_script(case, figure, store, workdir, png, svg):
    try:
        return network.script(store.locate(case.name, figure.variants[0]), figure.title, png, svg), []
    except (OSError, ValueError, KeyError) as exc:
        return None, [f"{figure.variants[0]}: no final state to draw ({exc})"]


def _profile_script(case, figure, store, workdir, png, svg):
    """pile_S(component, row) against pile_X(row): one curve per (variant, component)."""
    clauses, notes = [], []
    for variant in figure.variants:
        try:
            final = state(store.get(case.name, variant))
            columns = [piles.pile_X(final, figure.row)]
        except (RunProblem, EvalError) as problem:
            notes.append(f"{variant}: no data ({problem})")
            continue
        present = []
        for component in figure.y:
            try:
                values = piles.pile_S(final, component, figure.row)
            except EvalError as problem:
                notes.append(f"{variant}: {component}: {problem}")
                continue
            bad = int(np.sum(~np.isfinite(values)))
            if bad:
                notes.append(f"{variant}: {component}: {bad} non-finite value(s) not drawn")
            columns.append(values)
            present.append(component)
        if not present:
            continue
        path = Path(workdir) / f"{variant}.dat"
        _write_columns(path, columns)
        clauses += [f"{gp_string(path)} using 1:{i + 2} with linespoints pt 7 ps 0.6 "
                    f"title {gp_string(curve_title(variant, c, figure))}" for i, c in enumerate(present)]
    if not clauses:
        return None, notes + ["nothing to plot"]
    return gnuplot_script(figure, clauses, png, svg), notes


def _points_script(case, figure, store, workdir, png, svg):
    """One point (x, y) per variant, joined in the order listed, labelled with its name."""
    rows, notes = [], []
    sibling = Siblings(lambda other: store.get(case.name, other), case.ensemble_members())
    for variant in figure.variants:
        try:
            run = store.get(case.name, variant)
            point = [evaluate(expr, run, sibling) for expr in (figure.x, figure.y[0])]
        except (RunProblem, EvalError) as problem:
            notes.append(f"{variant}: not drawn: {problem}")
            continue
        off_axis = [f"{axis} = {value:.6g}" for axis, value in zip("xy", point)
                    if axis in figure.logscale and value <= 0]
        if off_axis:
            notes.append(f"{variant}: not drawn: {', '.join(off_axis)} is not positive (log scale)")
            continue
        rows.append((*point, variant))
    if not rows:
        return None, notes + ["nothing to plot"]
    path = Path(workdir) / "points.dat"
    files.write_text(path, "".join(f"{x!r}\t{y!r}\t{name}\n" for x, y, name in rows))
    settings = [f"set logscale {figure.logscale}"] if figure.logscale else []
    clauses = [f"{gp_string(path)} using 1:2 with linespoints pt 7 ps 1 notitle",
               f"{gp_string(path)} using 1:2:3 with labels left offset char 0.8,0.6 notitle"]
    return gnuplot_script(figure, clauses, png, svg, settings), notes


def _sibling_of(store, case):
    """The case's other variants, and its ensembles' realisations (for over(), ens_S(), ...)."""
    return Siblings(lambda other: store.get(case.name, other), case.ensemble_members())


def _evaluated(case, figure, store, evaluate_with, notes):
    """Per variant and per y of the figure, (variant, k, label, x, y): the figure's x and its
    k-th y expression evaluated in the variant (evaluate_with: one number or an array); what
    cannot be evaluated goes to notes and is left out."""
    siblings = _sibling_of(store, case)
    for variant in figure.variants:
        try:
            run = store.get(case.name, variant)
            x = evaluate_with(figure.x, run, siblings)
        except (RunProblem, EvalError) as problem:
            notes.append(f"{variant}: not drawn: {problem}")
            continue
        for k, (label, expr) in enumerate(zip(figure.labels, figure.y)):
            try:
                y = evaluate_with(expr, run, siblings)
            except EvalError as problem:
                notes.append(f"{variant}: {label}: not drawn: {problem}")
                continue
            yield variant, k, label, x, y


def _curves_script(case, figure, store, workdir, png, svg):
    """Per variant, each y array expression against the x array expression: one line each."""
    clauses, notes = [], []
    for variant, k, label, x, y in _evaluated(case, figure, store, evaluate_array, notes):
        if y.shape != x.shape:
            notes.append(f"{variant}: {label}: not drawn: {y.size} values against {x.size} of x")
            continue
        kept = np.isfinite(x) & np.isfinite(y)
        if not kept.all():
            notes.append(f"{variant}: {label}: {int((~kept).sum())} non-finite point(s) not drawn")
        path = Path(workdir) / f"{variant}_{k}.dat"
        _write_columns(path, [x[kept], y[kept]])
        clauses.append(f"{gp_string(path)} using 1:2 with lines title "
                       f"{gp_string(curve_title(variant, label, figure))}")
    if not clauses:
        return None, notes + ["nothing to plot"]
    return gnuplot_script(figure, clauses, png, svg), notes


def number_key(x):
    """x rounded to 12 significant digits: the variants whose x agree to that share a point."""
    return float(f"{x:.12g}")


def spread_points(samples):
    """{x: [y, ...]} -> rows (x, mean, least, largest, count), sorted by x."""
    return [(x, float(np.mean(ys)), float(np.min(ys)), float(np.max(ys)), len(ys))
            for x, ys in sorted(samples.items())]


PAPER_POINT_TYPES = (6, 4, 8, 12, 10)    # open circle, square, triangle, diamond, pentagon


def _errorbars_script(case, figure, store, workdir, png, svg):
    """A point per distinct x and series: the mean of the variants' y, a bar from least to largest."""
    samples, notes = [{} for _ in figure.y], []
    for _, k, _, x, y in _evaluated(case, figure, store, evaluate, notes):
        samples[k].setdefault(number_key(x), []).append(y)
    clauses = []
    for k, label in enumerate(figure.labels):
        if not samples[k]:
            continue
        path = Path(workdir) / f"series_{k}.dat"
        _write_columns(path, list(zip(*spread_points(samples[k]))))
        clauses.append(f"{gp_string(path)} using 1:2:3:4 with yerrorlines lt {k + 1} pt 7 ps 0.8 "
                       f"title {gp_string(label)}")
    if not clauses:
        return None, notes + ["nothing to plot"]
    published = list(dict.fromkeys(label for _, _, label in figure.paper_points))
    for j, label in enumerate(published):
        path = Path(workdir) / f"paper_{j}.dat"
        _write_columns(path, list(zip(*[(x, y) for x, y, name in figure.paper_points if name == label])))
        clauses.append(f"{gp_string(path)} using 1:2 with points pt {PAPER_POINT_TYPES[j % len(PAPER_POINT_TYPES)]} "
                       f"ps 1.6 lw 2 lc rgb '#000000' title {gp_string(label)}")
    return gnuplot_script(figure, clauses, png, svg, ERRORBAR_SETTINGS), notes


ERRORBAR_SETTINGS = ("set offsets graph 0.04, graph 0.04, graph 0.05, graph 0.05",)   # bars clear of the frame


def fitted_line(x, y):
    """(slope, intercept) of the least-squares line through the points; None for fewer than two
    different x."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if x.size < 2 or not np.ptp(x) > 0:
        return None
    slope, intercept = np.polyfit(x, y, 1)
    return float(slope), float(intercept)


def fit_legend(group, label, line, slope_as, scale=0.0):
    """The legend of one fitted line: its slope (or, slope_as 'asin', the angle whose sine it is)
    and its intercept (0 when below 1e-9 of scale, the largest |y|: round-off of a line through
    the origin)."""
    slope, intercept = line
    if slope_as == "asin" and -1 < slope < 1:
        shown = f"asin(slope) {np.degrees(np.arcsin(slope)):.1f} deg"
    else:
        shown = f"slope {slope:.4g}"
    intercept = 0.0 if abs(intercept) < 1e-9 * scale else intercept
    return f"{group}, {label}: {shown}, intercept {intercept:.4g}"


FIT_POINT_TYPES = (7, 5, 9, 11, 13)     # filled circle, square, triangle, diamond, pentagon


def _fit_script(case, figure, store, workdir, png, svg):
    """Per group and (x, y) pair: the variants' points and their least-squares line."""
    clauses, notes = [], []
    for g, (group, variants) in enumerate(figure.groups):
        for k, (xexpr, yexpr, label) in enumerate(zip(figure.xs, figure.y, figure.labels)):
            points = []
            for variant in variants:
                try:
                    run = store.get(case.name, variant)
                    points.append([evaluate(e, run, _sibling_of(store, case)) for e in (xexpr, yexpr)])
                except (RunProblem, EvalError) as problem:
                    notes.append(f"{group}, {label}: {variant}: not drawn: {problem}")
            if not points:
                continue
            x, y = np.array(points).T
            path = Path(workdir) / f"fit_{g}_{k}.dat"
            _write_columns(path, [x, y])
            style = f"lt {g + 1} pt {FIT_POINT_TYPES[k % len(FIT_POINT_TYPES)]} ps 1.2"
            line = fitted_line(x, y)
            if line is None:
                notes.append(f"{group}, {label}: fewer than two different x: no line")
                clauses.append(f"{gp_string(path)} using 1:2 with points {style} "
                               f"title {gp_string(f'{group}, {label}')}")
                continue
            if figure.slope == "asin" and not -1 < line[0] < 1:
                notes.append(f"{group}, {label}: the slope {line[0]:.4g} is no sine of an angle")
            ends = np.array([min(0.0, x.min()), x.max()])
            line_path = Path(workdir) / f"line_{g}_{k}.dat"
            _write_columns(line_path, [ends, line[0] * ends + line[1]])
            clauses += [f"{gp_string(path)} using 1:2 with points {style} notitle",
                        f"{gp_string(line_path)} using 1:2 with lines lt {g + 1} dt {k + 1} "
                        f"title {gp_string(fit_legend(group, label, line, figure.slope, np.abs(y).max()))}"]
    if not clauses:
        return None, notes + ["nothing to plot"]
    return gnuplot_script(figure, clauses, png, svg, FIT_SETTINGS), notes


FIT_SETTINGS = ("set key below left vertical maxrows 4",)   # the legends are long: under the plot


PRINCIPAL_SHARE = 0.9         # the largest principal value is drawn this share of the largest diameter
PRINCIPAL_COLOURS = {"compressive": "#1f3a93", "tensile": "#d62728"}


def principal_lines(axes):
    """The crosses of MLH Fig. 3(d): per free disc a line along phi (length ~ S_max) and one
    across it (length ~ S_min), the largest |S| drawn PRINCIPAL_SHARE of the largest diameter.

    axes: (x, y, r, S_max, S_min, phi) per free disc, compression positive.  Returns the
    segments (x0, y0, x1, y1, tensile) and the largest S_max.
    """
    largest = max((max(abs(a[3]), abs(a[4])) for a in axes), default=0.0)
    if not largest > 0 or not np.isfinite(largest):
        return [], largest
    unit = PRINCIPAL_SHARE * 2 * max(a[2] for a in axes) / largest
    segments = []
    for x, y, _, s_max, s_min, phi in axes:
        for value, angle in ((s_max, phi), (s_min, phi + 90.0)):
            half = 0.5 * unit * abs(value)
            if not half > 0:
                continue
            dx, dy = half * np.cos(np.radians(angle)), half * np.sin(np.radians(angle))
            segments.append((x - dx, y - dy, x + dx, y + dy, value < 0))
    return segments, max(a[3] for a in axes)


def _principal_script(case, figure, store, workdir, png, svg):
    """Discs of the final state and the principal-axis cross of every free disc."""
    variant = figure.variants[0]
    try:
        final = state(store.get(case.name, variant))
        axes, scaled = piles.principal_axes(final)
        discs = final.discs()
    except (RunProblem, EvalError) as problem:
        return None, [f"{variant}: no final state to draw ({problem})"]
    if not axes:
        return None, [f"{variant}: no free disc to draw"]
    segments, top = principal_lines(axes)
    unit = "m g / l" if scaled else "(stress, unscaled: run.json has no pile)"
    lines = ["set terminal pngcairo size 800,800 noenhanced font 'sans,10'", f"set output {gp_string(png)}",
             "set size ratio -1", "unset key",
             f"set title {gp_string(f'{figure.title} (largest S_max {top:.4g} {unit}; red: tensile)')}"]
    x, y, r = discs["x"], discs["y"], discs["r"]
    rmax = float(np.max(r))
    lines += [f"set xrange [{float(np.min(x)) - 2 * rmax!r}:{float(np.max(x)) + 2 * rmax!r}]",
              f"set yrange [{float(np.min(y)) - 2 * rmax!r}:{float(np.max(y)) + 2 * rmax!r}]"]
    k = 0
    for w in _walls(final.folder):
        k += 1
        lines.append(f"set arrow {k} from {w[0]!r},{w[1]!r} to {w[2]!r},{w[3]!r} nohead lw 3 lc rgb '#444444'")
    for x0, y0, x1, y1, tensile in segments:
        k += 1
        colour = PRINCIPAL_COLOURS["tensile" if tensile else "compressive"]
        lines.append(f"set arrow {k} from {x0!r},{y0!r} to {x1!r},{y1!r} nohead lw 1.5 lc rgb '{colour}' front")
    free = discs["free"]
    for name, chosen in (("free", free), ("held", ~free)):
        data = "\n".join(f"{a!r} {b!r} {c!r}" for a, b, c in zip(x[chosen], y[chosen], r[chosen]))
        lines += [f"${name} << EOD", data or "NaN NaN NaN", "EOD"]
    lines += ["plot $free using 1:2:3 with circles lc rgb '#7f8c8d' lw 1, "
              "$held using 1:2:3 with circles fill solid 0.3 lc rgb '#7f8c8d'",
              "set terminal svg size 800,800 noenhanced font 'sans,10' background '#ffffff'",
              f"set output {gp_string(svg)}", "replot", "unset output", ""]
    return "\n".join(lines), []


def _walls(folder):
    """(ax, ay, bx, by) of every wall in walls.tsv; none when the file is absent or unreadable."""
    try:
        return [(float(w["ax"]), float(w["ay"]), float(w["bx"]), float(w["by"]))
                for w in network.read_table(Path(folder) / "walls.tsv")]
    except (OSError, ValueError, KeyError):
        return []


SCRIPTS = {"series": _series_script, "network": _network_script, "profile": _profile_script,
           "principal": _principal_script, "points": _points_script, "curves": _curves_script,
           "errorbars": _errorbars_script, "fit": _fit_script,
           "snapshots": pictures.snapshots_script, "movie": pictures.movie_script}
RASTER = {"movie": "gif"}   # a kind drawn as another raster image than PNG: the movie, an animated GIF


def render_figure(case, figure, store, figures_dir):
    """Render one [figure] into figures_dir/<case>_<figure>.png/.svg; a FigureOut with notes."""
    out = FigureOut(figure.name, figure.title, figure.paper)
    raster = RASTER.get(figure.kind, "png")
    png, svg = (Path(figures_dir) / f"{case.name}_{figure.name}.{ext}" for ext in (raster, "svg"))
    for old in (png, svg):
        files.remove(old)
    if not shutil.which("gnuplot"):
        out.notes.append("gnuplot not found: figure not rendered")
        return out
    with tempfile.TemporaryDirectory(prefix="ballast-fig-") as workdir:
        drawn = drawings(workdir, raster)
        text, out.notes = SCRIPTS[figure.kind](case, figure, store, workdir, *drawn)
        if text is None:
            return out
        error = run_gnuplot(text, workdir)
        out.png, out.svg = publish(drawn, (png, svg))
    if error:
        out.notes.append(f"gnuplot failed: {error}")
    return out


def drawings(workdir, raster="png"):
    """Where gnuplot draws a figure: the scratch folder (its data files end in .dat)."""
    return Path(workdir) / f"figure.{raster}", Path(workdir) / "figure.svg"


def publish(drawn, final):
    """Copy each non-empty drawing to its place in reports/figures (whole, by files.copy);
    the places filled, None for a drawing gnuplot did not make."""
    out = []
    for source, path in zip(drawn, final):
        made = source.is_file() and source.stat().st_size > 0
        if made:
            files.copy(source, path)
        out.append(path if made else None)
    return out


def run_gnuplot(script, workdir):
    """Run gnuplot on script; '' on success, else its complaint."""
    path = Path(workdir) / "figure.gp"
    files.write_text(path, script)
    try:
        done = subprocess.run(["gnuplot", str(path)], capture_output=True, text=True, timeout=120,
                              **child_options(keep_lock=False))
    except (OSError, subprocess.SubprocessError) as exc:
        return str(exc)
    return "" if done.returncode == 0 else (done.stderr.strip().splitlines() or ["exit %d" % done.returncode])[-1]
