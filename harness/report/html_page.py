"""reports/index.html: the report as one self-contained page, from what contents.py gathered.

Figures are inlined (SVG as a base64 data URI, PNG as fallback), so index.html opens without
a server or any other file; an SVG above SVG_INLINE_MAX is linked instead (its PNG inlined).
"""
import base64
import html

from .. import sweep
from ..gate import counts_text, fmt_number, fmt_reference, tally
from .contents import ENERGY_COLUMNS, energy_cells, stability_tables

CSS = """
body{font-family:system-ui,sans-serif;margin:0 auto;max-width:1200px;padding:1em 2em;color:#222}
h1{margin-bottom:.2em} h2{border-bottom:2px solid #ccc;padding-bottom:.2em;margin-top:2em}
table{border-collapse:collapse;margin:.5em 0 1em;font-size:.9em}
th,td{border:1px solid #ccc;padding:.25em .5em;text-align:left;vertical-align:top}
th{background:#f2f2f2} td.num{text-align:right;font-family:monospace;white-space:nowrap}
.PASS{background:#d9f2d9;font-weight:bold} .FAIL{background:#f8d0d0;font-weight:bold} .SKIP{background:#eeeeee;font-weight:bold} .KNOWN{background:#fde9c8;font-weight:bold}
.bad{color:#a00} figure{margin:1em 0} figure img{max-width:100%;border:1px solid #ddd}
figcaption{font-size:.9em;color:#444} blockquote{margin:.4em 0 0 1em;padding-left:.8em;border-left:3px solid #bbb;font-style:italic} code{background:#f4f4f4;padding:0 .2em} .meta{color:#555}
"""

# The class of a run's status cell: a run that could not be made (skipped) is neither.
RUN_CLASS = {"ok": "PASS", "skipped": "SKIP"}


def esc(text):
    return html.escape("" if text is None else str(text))


def cell(text, cls=""):
    return f"<td class=\"{cls}\">{esc(text)}</td>" if cls else f"<td>{esc(text)}</td>"


def table_html(headers, rows):
    head = "".join(f"<th>{esc(h)}</th>" for h in headers)
    return f"<table><tr>{head}</tr>\n" + "\n".join(f"<tr>{''.join(r)}</tr>" for r in rows) + "</table>"


SVG_INLINE_MAX = 512 * 1024   # a larger SVG (a force network of thousands of lines) is linked, its PNG inlined


def image_html(figure):
    """The figure inlined: SVG as a data URI, else PNG, else only its notes.  An SVG above
    SVG_INLINE_MAX bytes is not inlined: its PNG is, with a link to the SVG file (in figures/,
    beside index.html), so the page stays small enough to open at once."""
    link = ""
    if figure.svg and (figure.svg.stat().st_size <= SVG_INLINE_MAX or not figure.png):
        src = "data:image/svg+xml;base64," + base64.b64encode(figure.svg.read_bytes()).decode()
    elif figure.png:
        src = (f"data:image/{figure.png.suffix.lstrip('.')};base64,"      # png, or gif: a movie
               + base64.b64encode(figure.png.read_bytes()).decode())
        if figure.svg:
            link = (f" (<a href=\"figures/{esc(figure.svg.name)}\">vector version</a>, "
                    f"{figure.svg.stat().st_size / 1e6:.1f} MB)")
    else:
        src = ""
    img = f"<img alt=\"{esc(figure.title)}\" src=\"{src}\">" if src else "<p class=\"bad\">(no figure)</p>"
    notes = link + "".join(f"<br><span class=\"bad\">{esc(n)}</span>" for n in figure.notes)
    paper = f"<blockquote>{esc(figure.paper)}</blockquote>" if figure.paper else ""
    return f"<figure>{img}<figcaption><b>{esc(figure.title)}</b>{notes}{paper}</figcaption></figure>"


def _runs_html(r):
    rows = [[cell(x["variant"]), cell(x["status"], RUN_CLASS.get(x["status"], "FAIL")),
             cell(fmt_number(x["wall"]), "num"), cell(fmt_number(x["steps"]), "num"), cell(fmt_number(x["dt"]), "num"),
             cell(fmt_number(x["n_discs"]), "num"), cell(x["message"])] for x in r.runs]
    return table_html(["variant", "status", "wall s", "steps", "dt", "discs", "message"], rows)


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
             cell(v.result, v.result), cell(v.message)]
            for v in r.verdicts]
    if not rows:
        return "<p>(no checks for this case)</p>"
    return table_html(["check", "variant", "quantity", "value", "reference", "tolerance", "kind",
                       "provenance", "result", "message"], rows)


def _case_html(r):
    c = r.case
    return "\n".join([
        f"<section id=\"case-{esc(c.name)}\"><h2>{esc(c.name)}: {esc(c.title)}</h2>",
        f"<p><b>Checks:</b> {esc(c.checks)}</p>",
        f"<p class=\"meta\">tier {esc(c.tier)} &middot; {counts_text(r.verdicts)} &middot; "
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
        state = "FAIL" if failed or not r.verdicts else "PASS" if passed else "SKIP"
        rows.append([f"<td><a href=\"#case-{esc(r.case.name)}\">{esc(r.case.name)}</a></td>", cell(r.case.title),
                     cell(r.case.tier), cell(f"{runs_ok}/{len(r.runs)}", "num"),
                     cell(counts_text(r.verdicts), state)])
    return table_html(["case", "title", "tier", "runs ok", "checks"], rows)


def page(reports, revision, date, known_html=""):
    verdicts = [v for r in reports for v in r.verdicts]
    passed, failed = tally(verdicts)
    return "\n".join([
        "<!DOCTYPE html>", "<html lang=\"en\"><head><meta charset=\"utf-8\">",
        "<title>ballast validation report</title>", f"<style>{CSS}</style></head><body>",
        "<header><h1>ballast validation report</h1>",
        f"<p class=\"meta\">git revision <code>{esc(revision)}</code> &middot; {esc(date)} &middot; "
        f"<span class=\"{'FAIL' if failed or not verdicts else 'PASS' if passed else 'SKIP'}\">"
        f"{counts_text(verdicts)}</span></p>",
        "</header>", known_html, _index_html(reports), *[_case_html(r) for r in reports], "</body></html>", ""])


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


def _cost_html(cost):
    if cost is None:
        return ""
    parts = ["<h3>Error against cost</h3>", f"<p class=\"meta\">{esc(COST_TEXT)}</p>"]
    parts += [f"<p><b>{esc(m)}</b></p>" for m in cost.meta]
    parts += [f"<p class=\"bad\">{esc(n)}</p>" for n in cost.notes]
    if cost.figure:
        parts.append(image_html(cost.figure))
    if cost.rows:
        rows = [[cell(f"{tol:g}"), cell(sweep.setting(r) if r else "none of the swept settings"),
                 cell(fmt_number(r["error"]) if r else "-", "num"),
                 cell(fmt_number(r["particle_steps"]) if r else "-", "num"),
                 cell(fmt_number(r["steps"]) if r else "-", "num"),
                 cell(fmt_number(r["wall_seconds"]) if r else "-", "num")] for tol, r in cost.cheapest.items()]
        parts.append("<p>Cheapest setting meeting each tolerance (least particle-steps with error &le; tolerance):</p>")
        parts.append(table_html(["tolerance", "cheapest setting", "error", "particle-steps", "steps", "wall s"], rows))
        every = [[cell(r["sweep"]), cell(f"{r['factor']:g}", "num"), cell(r["sets"]), cell(r["status"]),
                  cell(r["status"], "bad") if sweep.failed(r) else cell(fmt_number(r["error"]), "num"), cell(r["worst"]), cell(fmt_number(r["particle_steps"]), "num"),
                  cell(fmt_number(r["steps"]), "num"), cell(fmt_number(r["wall_seconds"]), "num"), cell(r["note"])]
                 for r in cost.rows]
        parts.append("<details><summary>every point</summary>" +
                     table_html(["sweep", "factor", "settings", "status", "error", "largest term", "particle-steps",
                                 "steps", "wall s", "note"], every) + "</details>")
    return "\n".join(parts)


def stability_html(reports_dir):
    parts = []
    for title, note, headers, rows in stability_tables(reports_dir):
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
