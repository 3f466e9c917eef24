"""The report: gnuplot figures, reports/summary.md and a self-contained reports/index.html.

Per case: title, what it checks, its figures (from its [figure] sections; one script
maker per figure kind in SCRIPTS, kinds as in catalogue.py), the checks
table (measured beside reference, tolerance, kind, provenance, PASS/FAIL) and each run's
wall time and status; the page header has the git revision and the date.  Verdicts come
from reports/summary.json when it is newer than the runs and the references of a case,
otherwise they are evaluated here.  Figures are inlined into the HTML (SVG as a base64
data URI, PNG as fallback), so index.html opens without a server or any other file.

Figure kinds: series (columns of series.tsv against x); network (force network, see
network.py); profile (pile_S(component, row) against pile_X(row), lines with points, one
curve per variant and component, from families/piles.py); principal (MLH Fig. 3(d): the discs of
the final state and, centred on every free disc, a line along the most compressive
principal axis of length proportional to S_max and one across it proportional to S_min,
compression positive, tensile values in red, the largest |S| drawn PRINCIPAL_SHARE of the
largest diameter; `set arrow ... nohead` per line, square aspect); points (one point per
variant at (x, y) = two quantity expressions, joined in the order listed and labelled
with the variant name, optional log axes).  Whatever a figure cannot show -- a variant
without data, an expression that fails, a non-positive value on a log axis, non-finite
values -- is listed in its notes, never silently dropped.

gnuplot draws in a scratch folder; the figures, summary.md and index.html reach reports/
through files.py (a temporary file, then rename), so a killed report leaves each of them
old or new, never empty or cut.
"""
import base64
import html
import shutil
import subprocess
import tempfile
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from . import REPO_ROOT
from . import files, network
from .children import options as child_options
from .compare import evaluate, evaluate_all
from .errors import EvalError, RunProblem
from .families import piles
from .final_state import state
from .gate import fmt_number, fmt_reference, read_summary, tally
from .tables import read_harness_record, read_run_json

STYLE = Path(__file__).resolve().parent / "gnuplot" / "style.gp"
SIZE = "960,540"


@dataclass
class FigureOut:
    name: str
    title: str
    paper: str = ""
    svg: Path = None
    png: Path = None
    notes: list = field(default_factory=list)


@dataclass
class CaseReport:
    case: object
    runs: list
    figures: list
    verdicts: list
    verdict_source: str
    cost: object = None          # CostOut: the error-against-cost section (see the end of this module)


# ---------------------------------------------------------------- header facts

def git_revision(root=REPO_ROOT):
    """`git rev-parse --short HEAD`, or 'unknown'."""
    try:
        done = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=root,
                              capture_output=True, text=True, timeout=10, **child_options(keep_lock=False))
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return done.stdout.strip() if done.returncode == 0 and done.stdout.strip() else "unknown"


def now_text():
    return datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")


# ---------------------------------------------------------------- runs

def run_status(folder):
    """One run's row: variant folder -> {status, wall, steps, dt, n_discs, message}."""
    folder = Path(folder)
    record = read_harness_record(folder) or {}
    try:
        info = read_run_json(folder)
    except RunProblem:
        info = None
    if info is None:
        status = "failed" if record else ("no run.json" if folder.is_dir() else "not run")
        return {"status": status, "wall": record.get("wall_seconds"), "steps": None, "dt": None,
                "n_discs": None, "message": record.get("cause", "")}
    status = info.get("status", "?")
    if record.get("returncode") not in (None, 0):
        status = f"{status}, exit {record['returncode']}"
    return {"status": status, "wall": info.get("wall_seconds", record.get("wall_seconds")),
            "steps": info.get("steps"), "dt": info.get("dt"), "n_discs": info.get("n_discs"),
            "message": info.get("message", "") or record.get("cause", ""),
            "energy": info.get("energy") if isinstance(info.get("energy"), dict) else None}


def run_rows(case, runs_root):
    return [dict(variant=v.name, **run_status(Path(runs_root) / case.name / v.name)) for v in case.variants]


# ---------------------------------------------------------------- figures

def gp_string(text):
    """A gnuplot single-quoted string."""
    return "'" + str(text).replace("'", "''") + "'"


def curve_title(variant, column, figure):
    if len(figure.variants) == 1:
        return column
    return variant if len(figure.y) == 1 else f"{variant}: {column}"


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
    return gnuplot_script(figure, clauses, png, svg), notes


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
    sibling = lambda other: store.get(case.name, other)
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
           "principal": _principal_script, "points": _points_script}


def render_figure(case, figure, store, figures_dir):
    """Render one [figure] into figures_dir/<case>_<figure>.png/.svg; a FigureOut with notes."""
    out = FigureOut(figure.name, figure.title, figure.paper)
    png, svg = (Path(figures_dir) / f"{case.name}_{figure.name}.{ext}" for ext in ("png", "svg"))
    for old in (png, svg):
        files.remove(old)
    if not shutil.which("gnuplot"):
        out.notes.append("gnuplot not found: figure not rendered")
        return out
    with tempfile.TemporaryDirectory(prefix="ballast-fig-") as workdir:
        drawn = _drawn(workdir)
        text, out.notes = SCRIPTS[figure.kind](case, figure, store, workdir, *drawn)
        if text is None:
            return out
        error = _run_gnuplot(text, workdir)
        out.png, out.svg = _publish(drawn, (png, svg))
    if error:
        out.notes.append(f"gnuplot failed: {error}")
    return out


def _drawn(workdir):
    """Where gnuplot draws a figure: the scratch folder (its data files end in .dat)."""
    return Path(workdir) / "figure.png", Path(workdir) / "figure.svg"


def _publish(drawn, final):
    """Copy each non-empty drawing to its place in reports/figures (whole, by files.copy);
    the places filled, None for a drawing gnuplot did not make."""
    out = []
    for source, path in zip(drawn, final):
        made = source.is_file() and source.stat().st_size > 0
        if made:
            files.copy(source, path)
        out.append(path if made else None)
    return out


def _run_gnuplot(script, workdir):
    """Run gnuplot on script; '' on success, else its complaint."""
    path = Path(workdir) / "figure.gp"
    files.write_text(path, script)
    try:
        done = subprocess.run(["gnuplot", str(path)], capture_output=True, text=True, timeout=120,
                              **child_options(keep_lock=False))
    except (OSError, subprocess.SubprocessError) as exc:
        return str(exc)
    return "" if done.returncode == 0 else (done.stderr.strip().splitlines() or ["exit %d" % done.returncode])[-1]


# ---------------------------------------------------------------- verdicts

def _newest(paths):
    return max((p.stat().st_mtime for p in paths if p.is_file()), default=0.0)


def verdicts_for(case, checks, summary, saved, runs_root, store):
    """(verdicts, where they came from): summary.json if fresh for this case, else evaluated now."""
    mine = [c for c in checks if c.case == case.name]
    old = [v for v in saved if v.case == case.name]
    inputs = [Path(runs_root) / case.name / v.name / f for v in case.variants for f in ("run.json", "harness.json")]
    inputs += [Path(c.path) for c in mine]
    fresh = summary.is_file() and summary.stat().st_mtime >= _newest(inputs)
    if fresh and [v.check for v in old] == [c.name for c in mine]:
        return old, "reports/summary.json"
    return evaluate_all(mine, store), "evaluated by `report` (summary.json absent or older than the runs)"


def _saved(summary):
    try:
        return read_summary(summary) if summary.is_file() else []
    except (ValueError, KeyError, TypeError):
        return []


def gather(cases, checks, store, runs_root, reports_dir):
    """A CaseReport per case: runs, rendered figures, verdicts."""
    summary = Path(reports_dir) / "summary.json"
    saved, figures_dir = _saved(summary), files.make_dirs(Path(reports_dir) / "figures")
    reports = []
    for case in cases:
        verdicts, source = verdicts_for(case, checks, summary, saved, runs_root, store)
        figures = [render_figure(case, f, store, figures_dir) for f in case.figures]
        reports.append(CaseReport(case, run_rows(case, runs_root), figures, verdicts, source,
                                  cost_section(case, reports_dir, figures_dir)))
    return reports


# ---------------------------------------------------------------- summary.md

def markdown(reports, revision, date):
    verdicts = [v for r in reports for v in r.verdicts]
    passed, failed = tally(verdicts)
    lines = ["# ballast validation report", "", f"Revision `{revision}`, {date}. **{passed} passed, {failed} failed.**", ""]
    for r in reports:
        lines += _markdown_case(r)
    return "\n".join(lines) + "\n"


def _md(text):
    return str(text).replace("|", "\\|").replace("\n", " ")


def _markdown_case(r):
    c = r.case
    lines = [f"## {c.name}: {c.title}", "", f"*Checks:* {c.checks}  ", f"*Tier:* {c.tier}; *source:* `{c.source}`", "",
             "| variant | status | wall s | steps | message |", "|---|---|---|---|---|"]
    lines += [f"| {x['variant']} | {_md(x['status'])} | {fmt_number(x['wall'])} | {fmt_number(x['steps'])} | {_md(x['message'])} |"
              for x in r.runs]
    lines.append("")
    audited = [x for x in r.runs if x.get("energy")]
    if audited:
        lines += ["Energy audit (core/energy.c):", "", "| variant | " + " | ".join(c for c, _ in ENERGY_COLUMNS) + " |",
                  "|---|" + "---|" * len(ENERGY_COLUMNS)]
        lines += [f"| {x['variant']} | " + " | ".join(fmt_number(v) for v in energy_cells(x["energy"])) + " |"
                  for x in audited]
        lines.append("")
    for f in r.figures:
        image = f"![{_md(f.title)}](figures/{f.png.name})" if f.png else "*(no figure)*"
        lines += [f"**{_md(f.title)}**", "", image] + [f"- {_md(n)}" for n in f.notes] + [""]
        if f.paper:
            lines += [f"> {_md(f.paper)}", ""]
    lines += [f"Checks ({r.verdict_source}):", "",
              "| check | variant | value | reference | tolerance | kind | result | provenance | message |",
              "|---|---|---|---|---|---|---|---|---|"]
    lines += [f"| {v.check} | {v.variant} | {fmt_number(v.value)} | {fmt_reference(v)} | {v.tolerance} | {v.kind} | "
              f"{'PASS' if v.passed else '**FAIL**'} | {_md(v.provenance)} | {_md(v.message)} |" for v in r.verdicts]
    if not r.verdicts:
        lines.append("| *(no checks for this case)* | | | | | | | | |")
    return lines + [""] + _cost_markdown(r.cost)


# ---------------------------------------------------------------- index.html

CSS = """
body{font-family:system-ui,sans-serif;margin:0 auto;max-width:1200px;padding:1em 2em;color:#222}
h1{margin-bottom:.2em} h2{border-bottom:2px solid #ccc;padding-bottom:.2em;margin-top:2em}
table{border-collapse:collapse;margin:.5em 0 1em;font-size:.9em}
th,td{border:1px solid #ccc;padding:.25em .5em;text-align:left;vertical-align:top}
th{background:#f2f2f2} td.num{text-align:right;font-family:monospace;white-space:nowrap}
.PASS{background:#d9f2d9;font-weight:bold} .FAIL{background:#f8d0d0;font-weight:bold}
.bad{color:#a00} figure{margin:1em 0} figure img{max-width:100%;border:1px solid #ddd}
figcaption{font-size:.9em;color:#444} blockquote{margin:.4em 0 0 1em;padding-left:.8em;border-left:3px solid #bbb;font-style:italic} code{background:#f4f4f4;padding:0 .2em} .meta{color:#555}
"""


def esc(text):
    return html.escape("" if text is None else str(text))


def cell(text, cls=""):
    return f"<td class=\"{cls}\">{esc(text)}</td>" if cls else f"<td>{esc(text)}</td>"


def table_html(headers, rows):
    head = "".join(f"<th>{esc(h)}</th>" for h in headers)
    return f"<table><tr>{head}</tr>\n" + "\n".join(f"<tr>{''.join(r)}</tr>" for r in rows) + "</table>"


def image_html(figure):
    """The figure inlined: SVG as a data URI, else PNG, else only its notes."""
    if figure.svg:
        src = "data:image/svg+xml;base64," + base64.b64encode(figure.svg.read_bytes()).decode()
    elif figure.png:
        src = "data:image/png;base64," + base64.b64encode(figure.png.read_bytes()).decode()
    else:
        src = ""
    img = f"<img alt=\"{esc(figure.title)}\" src=\"{src}\">" if src else "<p class=\"bad\">(no figure)</p>"
    notes = "".join(f"<br><span class=\"bad\">{esc(n)}</span>" for n in figure.notes)
    paper = f"<blockquote>{esc(figure.paper)}</blockquote>" if figure.paper else ""
    return f"<figure>{img}<figcaption><b>{esc(figure.title)}</b>{notes}{paper}</figcaption></figure>"


def _runs_html(r):
    rows = [[cell(x["variant"]), cell(x["status"], "PASS" if x["status"] == "ok" else "FAIL"),
             cell(fmt_number(x["wall"]), "num"), cell(fmt_number(x["steps"]), "num"), cell(fmt_number(x["dt"]), "num"),
             cell(fmt_number(x["n_discs"]), "num"), cell(x["message"])] for x in r.runs]
    return table_html(["variant", "status", "wall s", "steps", "dt", "discs", "message"], rows)


# The energy audit of core/energy.c: work in = change of stored energy + each loss + imbalance.
ENERGY_COLUMNS = (("W walls", lambda e: e["work_walls"]), ("W gravity", lambda e: e["work_gravity"]),
                  ("dE kinetic", lambda e: e["kinetic"] - e["kinetic0"]),
                  ("dE elastic", lambda e: e["elastic"] - e["elastic0"]),
                  ("D dashpot", lambda e: e["dissipated_dashpot"]),
                  ("D friction", lambda e: e["dissipated_friction"]),
                  ("D global", lambda e: e["dissipated_global"]),
                  ("imbalance", lambda e: e["imbalance"]), ("relative", lambda e: e["relative_imbalance"]))


def energy_cells(audit):
    """The audit's terms in ENERGY_COLUMNS order (None where a term is missing or not finite)."""
    out = []
    for _, term in ENERGY_COLUMNS:
        try:
            out.append(term(audit))
        except (KeyError, TypeError):
            out.append(None)
    return out


def _energy_html(r):
    rows = [[cell(x["variant"])] + [cell(fmt_number(v), "num") for v in energy_cells(x["energy"])]
            for x in r.runs if x.get("energy")]
    if not rows:
        return ""
    return ("<h3>Energy audit</h3><p class=\"meta\">from the first cycle to the end of the run: "
            "W walls + W gravity = dE kinetic + dE elastic + D dashpot + D friction + D global + imbalance "
            "(core/energy.c); relative = |imbalance| / (energy at the start + |W walls| + |W gravity|)</p>"
            + table_html(["variant"] + [c for c, _ in ENERGY_COLUMNS], rows))


def _checks_html(r):
    rows = [[cell(v.check), cell(v.variant), cell(v.quantity), cell(fmt_number(v.value), "num"),
             cell(fmt_reference(v), "num"), cell(v.tolerance), cell(v.kind), cell(v.provenance),
             cell("PASS" if v.passed else "FAIL", "PASS" if v.passed else "FAIL"), cell(v.message)]
            for v in r.verdicts]
    if not rows:
        return "<p>(no checks for this case)</p>"
    return table_html(["check", "variant", "quantity", "value", "reference", "tolerance", "kind",
                       "provenance", "result", "message"], rows)


def _case_html(r):
    c = r.case
    passed, failed = tally(r.verdicts)
    return "\n".join([
        f"<section id=\"case-{esc(c.name)}\"><h2>{esc(c.name)}: {esc(c.title)}</h2>",
        f"<p><b>Checks:</b> {esc(c.checks)}</p>",
        f"<p class=\"meta\">tier {esc(c.tier)} &middot; {passed} passed, {failed} failed &middot; "
        f"defined at <code>{esc(c.source)}</code></p>",
        "<h3>Runs</h3>", _runs_html(r), _energy_html(r),
        "<h3>Figures</h3>" if r.figures else "", *[image_html(f) for f in r.figures],
        f"<h3>Checks</h3><p class=\"meta\">verdicts: {esc(r.verdict_source)}</p>", _checks_html(r),
        _cost_html(r.cost), "</section>"])


def _index_html(reports):
    rows = []
    for r in reports:
        passed, failed = tally(r.verdicts)
        runs_ok = sum(x["status"] == "ok" for x in r.runs)
        state = "PASS" if r.verdicts and not failed else "FAIL"
        rows.append([f"<td><a href=\"#case-{esc(r.case.name)}\">{esc(r.case.name)}</a></td>", cell(r.case.title),
                     cell(r.case.tier), cell(f"{runs_ok}/{len(r.runs)}", "num"),
                     cell(f"{passed} passed, {failed} failed", state)])
    return table_html(["case", "title", "tier", "runs ok", "checks"], rows)


def page(reports, revision, date):
    passed, failed = tally([v for r in reports for v in r.verdicts])
    return "\n".join([
        "<!DOCTYPE html>", "<html lang=\"en\"><head><meta charset=\"utf-8\">",
        "<title>ballast validation report</title>", f"<style>{CSS}</style></head><body>",
        "<header><h1>ballast validation report</h1>",
        f"<p class=\"meta\">git revision <code>{esc(revision)}</code> &middot; {esc(date)} &middot; "
        f"<span class=\"{'PASS' if passed and not failed else 'FAIL'}\">{passed} passed, {failed} failed</span></p>",
        "</header>", _index_html(reports), *[_case_html(r) for r in reports], "</body></html>", ""])


def write_report(cases, checks, store, runs_root, reports_dir, out=None):
    """Render figures, write summary.md and index.html; return the index path."""
    reports_dir = Path(reports_dir)
    reports = gather(cases, checks, store, runs_root, reports_dir)
    revision, date = git_revision(), now_text()
    files.write_text(reports_dir / "summary.md", markdown(reports, revision, date) + stability_markdown(reports_dir))
    index = reports_dir / "index.html"
    files.write_text(index, page(reports, revision, date).replace("</body></html>",
                                                                  stability_html(reports_dir) + "</body></html>"))
    if out:
        print(f"wrote {reports_dir / 'summary.md'} and {index}", file=out)
    return index


# ---------------------------------------------------------------- error against cost

COST_TEXT = ("Error against cost: every declared [sweep] of the case (harness/sweep.py). "
             "Error = the largest |q - ref| / |ref| over the checks of the swept variant that have a "
             "point reference of kind analytic, exact or paper, and of the sweep's `error =` quantities "
             "(relative deviations from a reference solution). Cost = particle-steps = steps x discs. "
             "Each curve is one swept parameter (points labelled by the factor applied to its default); "
             "a sweep with fixed `set =` overrides (e.g. the integrator) is a curve of its own, its factor 1 "
             "run with the overrides. The black star is the default tier's setting. A run that failed "
             "(unstable: the overlap-budget or energy-runaway guard stopped it) has no error: it is a cross "
             "labelled 'unstable' on the dotted line at the top, at the cost it spent before stopping. "
             "A sweep with `converge =` quantities measures self-convergence: the error is against the "
             "finest (most expensive) run of the same sweep, not against a reference.")


@dataclass
class CostOut:
    figure: FigureOut = None
    rows: list = field(default_factory=list)
    cheapest: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)
    meta: list = field(default_factory=list)     # what the error means, when not the usual definition


def cost_section(case, reports_dir, figures_dir):
    """The error-against-cost section of a case from reports/sweeps/<case>/cost.tsv; None when the
    case declares no sweep."""
    from . import sweep
    if not case.sweeps:
        return None
    out = CostOut()
    selfconv = [s.name for s in case.sweeps if s.converge]
    if selfconv:
        out.meta.append(f"Self-convergence ({', '.join(selfconv)}): the error of these sweeps is the largest "
                        "|q - q_finest| / |q_finest| over their `converge =` quantities, against the finest "
                        "(most particle-steps) run of the same sweep — an error against the finest swept run, "
                        "not against a reference. The finest run itself has no error.")
    path = sweep.cost_path(Path(reports_dir) / "sweeps", case.name)
    try:
        out.rows = sweep.read_tsv(path)
    except (OSError, ValueError, IndexError) as exc:
        out.notes.append(f"no sweep results ({exc}); run `python3 -m harness cost {case.name}`")
        return out
    if case.path and Path(case.path).is_file() and path.stat().st_mtime < Path(case.path).stat().st_mtime:
        out.notes.append(f"{path.name} is older than {Path(case.path).name}: the sweeps may have changed "
                         f"since (run `python3 -m harness cost {case.name}`)")
    out.cheapest = sweep.cheapest(out.rows)
    out.figure = render_cost(case, out.rows, figures_dir)
    return out


def cost_points(rows):
    """({sweep: [(cost, error, label)]} sorted by factor, the default points (one per swept variant), notes,
    {sweep: [(cost, label)]} of the failed points (unstable: drawn at the top of the diagram))."""
    from .sweep import failed, is_default
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
        figure.ylabel = "error: max |q - q_finest| / |q_finest| (against the finest swept run)"
    errors = [y for pts in curves.values() for _, y, _ in pts]
    top = max(errors) * 10 if errors else 1.0
    names = list(dict.fromkeys(list(curves) + list(bad)))
    with tempfile.TemporaryDirectory(prefix="ballast-cost-") as workdir:
        clauses = []
        for i, name in enumerate(names):
            if name in curves:
                path = Path(workdir) / f"curve{i}.dat"
                files.write_text(path, "".join(f"{x!r}\t{y!r}\t{label}\n" for x, y, label in curves[name]))
                # point types cycle filled/open, so curves that coincide (verlet on centred) stay visible
                clauses += [f"{gp_string(path)} using 1:2 with linespoints pt {POINT_TYPES[i % len(POINT_TYPES)]} "
                            f"ps {1.0 if i % 2 == 0 else 1.6} lc {i + 1} title {gp_string(name)}",
                            f"{gp_string(path)} using 1:2:3 with labels left offset char 0.6,0.5 tc lt {i + 1} notitle"]
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
        drawn = _drawn(workdir)
        error = _run_gnuplot(gnuplot_script(figure, clauses, *drawn, extra), workdir)
        out.png, out.svg = _publish(drawn, (png, svg))
    if error:
        out.notes.append(f"gnuplot failed: {error}")
    return out


@dataclass
class _CostAxes:
    """What gnuplot_script needs of a figure, for the cost diagram."""
    title: str
    xlabel: str = "cost: particle-steps (steps x discs)"
    ylabel: str = "error: max |q - ref| / |ref| over the error terms"
    xrange: str = ""
    yrange: str = ""


def _setting(r):
    from .sweep import setting
    return setting(r)


def _cost_html(cost):
    if cost is None:
        return ""
    parts = ["<h3>Error against cost</h3>", f"<p class=\"meta\">{esc(COST_TEXT)}</p>"]
    parts += [f"<p><b>{esc(m)}</b></p>" for m in cost.meta]
    parts += [f"<p class=\"bad\">{esc(n)}</p>" for n in cost.notes]
    if cost.figure:
        parts.append(image_html(cost.figure))
    if cost.rows:
        rows = [[cell(f"{tol:g}"), cell(_setting(r) if r else "none of the swept settings"),
                 cell(fmt_number(r["error"]) if r else "-", "num"),
                 cell(fmt_number(r["particle_steps"]) if r else "-", "num"),
                 cell(fmt_number(r["steps"]) if r else "-", "num"),
                 cell(fmt_number(r["wall_seconds"]) if r else "-", "num")] for tol, r in cost.cheapest.items()]
        parts.append("<p>Cheapest setting meeting each tolerance (least particle-steps with error &le; tolerance):</p>")
        parts.append(table_html(["tolerance", "cheapest setting", "error", "particle-steps", "steps", "wall s"], rows))
        every = [[cell(r["sweep"]), cell(f"{r['factor']:g}", "num"), cell(r["sets"]), cell(r["status"]),
                  cell(r["status"], "bad") if _failed(r) else cell(fmt_number(r["error"]), "num"), cell(r["worst"]), cell(fmt_number(r["particle_steps"]), "num"),
                  cell(fmt_number(r["steps"]), "num"), cell(fmt_number(r["wall_seconds"]), "num"), cell(r["note"])]
                 for r in cost.rows]
        parts.append("<details><summary>every point</summary>" +
                     table_html(["sweep", "factor", "settings", "status", "error", "largest term", "particle-steps",
                                 "steps", "wall s", "note"], every) + "</details>")
    return "\n".join(parts)


def _failed(r):
    from .sweep import failed
    return failed(r)


def _cost_markdown(cost):
    if cost is None:
        return []
    lines = ["**Error against cost** (declared sweeps; cost = particle-steps)", ""]
    lines += [f"- {_md(m)}" for m in cost.meta]
    lines += [f"- {_md(n)}" for n in cost.notes]
    if cost.figure and cost.figure.png:
        lines += [f"![error against cost](figures/{cost.figure.png.name})", ""]
    lines += [f"- {_md(n)}" for n in (cost.figure.notes if cost.figure else [])]
    if cost.rows:
        lines += ["", "| tolerance | cheapest setting | error | particle-steps |", "|---|---|---|---|"]
        lines += [f"| {tol:g} | {_md(_setting(r)) if r else 'none of the swept settings'} | "
                  f"{fmt_number(r['error']) if r else '-'} | {fmt_number(r['particle_steps']) if r else '-'} |"
                  for tol, r in cost.cheapest.items()]
        bad = [f"{r['sweep']} x{r['factor']:g}" for r in cost.rows if _failed(r)]
        if bad:
            lines += ["", f"- {UNSTABLE} (run failed, no error): {_md(', '.join(bad))}"]
    return lines + [""]
# ---------------------------------------------------------------- stability (harness/stability.py)

STABILITY_LIMIT_HEADERS = [("case", "case"), ("variant", "variant"), ("estimate", "bound (dt)"),
                           ("single_spring", "2 sqrt(m/k)"), ("single_over_estimate", "old / bound"),
                           ("case_fraction", "case dt / bound"), ("limit_fraction", "limit / bound"),
                           ("limit_over_single", "limit / old"), ("in_target", "in [1, 1.25]"), ("cause", "first unstable trial")]
STABILITY_EXTREME_HEADERS = [("group", "group"), ("probe", "probe"), ("what", "what"), ("expect", "expect"),
                             ("exit", "exit"), ("steps", "steps"), ("e_out_over_in", "E_out/E_in"),
                             ("overlap_max", "overlap/r"), ("outcome", "outcome"), ("as_expected", "as expected")]
STABILITY_NOTE = ("Written by `python3 -m harness stability` (not by validate: it bisects every DEM variant, "
                  "about 10 runs each). *limit / bound* is the largest stable dt over ballast's estimate (the "
                  "contact-network bound of core/timestep.c); a safe and tight estimate has it in [1, 1.25]. "
                  "*old* is C&S's single-spring 2 sqrt(m/k). The criteria are in harness/stability.py.")
EXTREMES_NOTE = ("Extreme probes (cases/extremes/extremes.txt): each row a scene pushed to a limit of the physics; "
                 "*expect* says what is acceptable: a stable run within the stated criteria, or a stop with exit 1 "
                 "and a message.  A later model adds rows under its own group.")


def _stability_tables(reports_dir):
    """[(title, note, headers, rows)] of the stability files that exist."""
    from .stability import read_tsv
    out = []
    for name, title, note, headers in (("stability.tsv", "Stability limits", STABILITY_NOTE, STABILITY_LIMIT_HEADERS),
                                       ("extremes.tsv", "Extreme probes", EXTREMES_NOTE, STABILITY_EXTREME_HEADERS)):
        path = Path(reports_dir) / name
        if path.exists():
            out.append((title, note, headers, read_tsv(path)))
    return out


def stability_markdown(reports_dir):
    lines = []
    for title, note, headers, rows in _stability_tables(reports_dir):
        lines += [f"## {title}", "", note, "", "| " + " | ".join(h for _, h in headers) + " |",
                  "|" + "---|" * len(headers)]
        lines += ["| " + " | ".join(_md(r.get(k, "")) for k, _ in headers) + " |" for r in rows]
        lines.append("")
    return "\n".join(lines) + ("\n" if lines else "")


def stability_html(reports_dir):
    parts = []
    for title, note, headers, rows in _stability_tables(reports_dir):
        body = []
        for r in rows:
            cells = []
            for k, _ in headers:
                v = r.get(k, "")
                cls = ""
                if k in ("in_target", "as_expected"):
                    cls = "PASS" if v == "yes" else "FAIL"
                elif k not in ("case", "variant", "group", "probe", "what", "expect", "cause", "outcome"):
                    cls = "num"
                cells.append(cell(v, cls))
            body.append(cells)
        parts.append(f"<section id=\"{esc(title.lower().replace(' ', '-'))}\"><h2>{esc(title)}</h2>"
                     f"<p>{esc(note)}</p>" + table_html([h for _, h in headers], body) + "</section>")
    return "\n".join(parts)
