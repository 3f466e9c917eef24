"""reports/index.html and the case pages reports/cases/<case>.html, from what contents.py gathered.

index.html stays light whatever the catalogue's size (issue 32, item 4; it was 9.8 MB with its
figures inlined and every table in it): the verdict, the failures, the skipped checks, the
KNOWN list, the table of the cases, then per case what it checks, its counts, the rows that did
not pass, its figures and its error against cost; the stability digest.  The figures are linked
from reports/figures/ (the report is index.html with its folder), an SVG above SVG_LINK_MAX
shown by its PNG with a link to the vector file (gzipped: contents.pack_vector); each case's
full tables (runs, energy audit,
every check, every swept point) are on its page, cases/<case>.html, and the stability tables
on stability.html.
"""
import html

from .. import sweep
from ..gate import counts_text, fmt_number, fmt_reference, tally
from .contents import (ENERGY_COLUMNS, SVG_LINK_MAX, case_counts, energy_cells, skip_groups, stability_digest,
                       stability_tables)
from .markdown import CASES_DIR, STABILITY_PAGE

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


def image_html(figure, prefix=""):
    """The figure, linked from the figures folder (prefix: the way there from the page, '../' from
    a case page): its SVG, or its PNG when there is no SVG or the SVG is above SVG_LINK_MAX bytes
    (kept gzipped then: contents.pack_vector; linked below the PNG), else only its notes."""
    link = ""
    if figure.svg and figure.svg.suffix == ".svg" and (figure.svg.stat().st_size <= SVG_LINK_MAX or not figure.png):
        src = f"{prefix}figures/{figure.svg.name}"
    elif figure.png:
        src = f"{prefix}figures/{figure.png.name}"
        if figure.svg:
            kind = "gzipped SVG, " if figure.svg.suffix == ".gz" else ""
            link = (f" (<a href=\"{esc(prefix)}figures/{esc(figure.svg.name)}\">vector version</a>, "
                    f"{kind}{figure.svg.stat().st_size / 1e6:.1f} MB)")
    else:
        src = ""
    img = f"<img alt=\"{esc(figure.title)}\" src=\"{esc(src)}\">" if src else "<p class=\"bad\">(no figure)</p>"
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


def _checks_html(verdicts):
    rows = [[cell(v.check), cell(v.variant), cell(v.quantity), cell(fmt_number(v.value), "num"),
             cell(fmt_reference(v), "num"), cell(v.tolerance), cell(v.kind), cell(v.provenance),
             cell(v.result, v.result), cell(v.message)]
            for v in verdicts]
    if not rows:
        return "<p>(no checks for this case)</p>"
    return table_html(["check", "variant", "quantity", "value", "reference", "tolerance", "kind",
                       "provenance", "result", "message"], rows)


def case_page_name(case):
    return f"{CASES_DIR}/{case.name}.html"


def _state(verdicts):
    passed, failed = tally(verdicts)
    return "FAIL" if failed or not verdicts else "PASS" if passed else "SKIP"


def _case_html(r):
    """A case in index.html: what it checks, its counts, the rows that did not pass, its figures and
    its error against cost; its full tables are on its page."""
    c = r.case
    n = case_counts(r)
    page = case_page_name(c)
    not_passed = [v for v in r.verdicts if v.result != "PASS"]
    return "\n".join([
        f"<section id=\"case-{esc(c.name)}\"><h2>{esc(c.name)}: {esc(c.title)}</h2>",
        f"<p><b>Checks:</b> {esc(c.checks)}</p>",
        f"<p class=\"meta\">tier {esc(c.tier)} &middot; runs ok {n['runs_ok']}/{n['runs']} &middot; "
        f"<span class=\"{_state(r.verdicts)}\">{counts_text(r.verdicts)}</span> &middot; defined at "
        f"<code>{esc(c.source)}</code> &middot; <a href=\"{esc(page)}\">runs, energy audit and every check</a></p>",
        _unfinished_html(r),
        (f"<h3>Checks that did not pass</h3>{_checks_html(not_passed)}" if not_passed else ""),
        "<h3>Figures</h3>" if r.figures else "", *[image_html(f) for f in r.figures],
        _cost_html(r.cost, every=False, page=page), "</section>"])


def _unfinished_html(r):
    """The runs of a case that are not ok, named with their status (none: nothing)."""
    bad = [x for x in r.runs if x["status"] != "ok"]
    if not bad:
        return ""
    return ("<p class=\"bad\">Runs not ok: " + ", ".join(f"{esc(x['variant'])} ({esc(x['status'])})" for x in bad[:20])
            + (f" and {len(bad) - 20} more" if len(bad) > 20 else "") + "</p>")


def case_page(r, revision, date):
    """cases/<case>.html: every table of one case, its figures linked from ../figures."""
    c = r.case
    return "\n".join([
        "<!DOCTYPE html>", "<html lang=\"en\"><head><meta charset=\"utf-8\">",
        f"<title>ballast: {esc(c.name)}</title>", f"<style>{CSS}</style></head><body>",
        f"<header><h1>{esc(c.name)}: {esc(c.title)}</h1>",
        f"<p class=\"meta\">git revision <code>{esc(revision)}</code> &middot; {esc(date)} &middot; "
        f"<span class=\"{_state(r.verdicts)}\">{counts_text(r.verdicts)}</span> &middot; "
        f"<a href=\"../index.html#case-{esc(c.name)}\">back to the report</a></p></header>",
        f"<p><b>Checks:</b> {esc(c.checks)}</p>",
        f"<p class=\"meta\">tier {esc(c.tier)} &middot; defined at <code>{esc(c.source)}</code></p>",
        "<h3>Runs</h3>", _runs_html(r), _energy_html(r),
        "<h3>Figures</h3>" if r.figures else "", *[image_html(f, "../") for f in r.figures],
        f"<h3>Checks</h3><p class=\"meta\">verdicts: {esc(r.verdict_source)}</p>", _checks_html(r.verdicts),
        _cost_html(r.cost, every=True, prefix="../"), "</body></html>", ""])


def _index_html(reports):
    rows = []
    for r in reports:
        n = case_counts(r)
        rows.append([f"<td><a href=\"#case-{esc(r.case.name)}\">{esc(r.case.name)}</a></td>", cell(r.case.title),
                     cell(r.case.tier), cell(f"{n['runs_ok']}/{n['runs']}", "num"),
                     cell(counts_text(r.verdicts), _state(r.verdicts)),
                     f"<td><a href=\"{esc(case_page_name(r.case))}\">tables</a></td>"])
    return table_html(["case", "title", "tier", "runs ok", "checks", "page"], rows)


def _failures_html(verdicts):
    """The failures and the skipped checks, named at the top of the page (none: nothing)."""
    parts = []
    failures = [v for v in verdicts if v.result == "FAIL"]
    if failures:
        items = "".join(f"<li><span class=\"FAIL\">FAIL</span> <a href=\"#case-{esc(v.case)}\">{esc(v.case)}</a>/"
                        f"{esc(v.check)} ({esc(v.variant)}): {esc(v.message)}</li>" for v in failures)
        parts.append(f"<section id=\"failures\"><h2>Failures ({len(failures)})</h2><ul>{items}</ul></section>")
    skips = skip_groups(verdicts)
    if skips:
        items = "".join(f"<li><span class=\"SKIP\">SKIP</span> {esc(case)} ({len(names)} check"
                        f"{'s' if len(names) > 1 else ''}): {esc(message)}</li>" for (case, message), names in skips.items())
        parts.append(f"<section id=\"skipped\"><h2>Skipped ({sum(len(n) for n in skips.values())})</h2>"
                     f"<ul>{items}</ul></section>")
    return "\n".join(parts)


def stability_digest_html(reports_dir):
    digest = stability_digest(reports_dir) if reports_dir is not None else []
    if not digest:
        return ""
    items = "".join(f"<li>{esc(d)}</li>" for d in digest)
    return (f"<section id=\"stability\"><h2>Stability limits and extreme probes</h2><ul>{items}</ul>"
            f"<p><a href=\"{STABILITY_PAGE}.html\">their tables</a></p></section>")


def page(reports, revision, date, known_html="", reports_dir=None):
    verdicts = [v for r in reports for v in r.verdicts]
    return "\n".join([
        "<!DOCTYPE html>", "<html lang=\"en\"><head><meta charset=\"utf-8\">",
        "<title>ballast validation report</title>", f"<style>{CSS}</style></head><body>",
        "<header><h1>ballast validation report</h1>",
        f"<p class=\"meta\">git revision <code>{esc(revision)}</code> &middot; {esc(date)} &middot; "
        f"<span class=\"{_state(verdicts)}\">{counts_text(verdicts)}</span></p>",
        "</header>", _failures_html(verdicts), known_html, _index_html(reports), *[_case_html(r) for r in reports],
        stability_digest_html(reports_dir), "</body></html>", ""])


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


def _cost_html(cost, every=True, prefix="", page=None):
    """The error-against-cost section: the figure and the cheapest setting per tolerance; every
    swept point too when every (a case page), else a link to page."""
    if cost is None:
        return ""
    parts = ["<h3>Error against cost</h3>", f"<p class=\"meta\">{esc(COST_TEXT)}</p>"]
    parts += [f"<p><b>{esc(m)}</b></p>" for m in cost.meta]
    parts += [f"<p class=\"bad\">{esc(n)}</p>" for n in cost.notes]
    if cost.figure:
        parts.append(image_html(cost.figure, prefix))
    if cost.rows:
        rows = [[cell(f"{tol:g}"), cell(sweep.setting(r) if r else "none of the swept settings"),
                 cell(fmt_number(r["error"]) if r else "-", "num"),
                 cell(fmt_number(r["particle_steps"]) if r else "-", "num"),
                 cell(fmt_number(r["steps"]) if r else "-", "num"),
                 cell(fmt_number(r["wall_seconds"]) if r else "-", "num")] for tol, r in cost.cheapest.items()]
        parts.append("<p>Cheapest setting meeting each tolerance (least particle-steps with error &le; tolerance):</p>")
        parts.append(table_html(["tolerance", "cheapest setting", "error", "particle-steps", "steps", "wall s"], rows))
        if not every:
            parts.append(f"<p><a href=\"{esc(page)}#every-point\">every swept point</a> "
                         f"({len(cost.rows)})</p>")
            return "\n".join(parts)
        every_row = [[cell(r["sweep"]), cell(f"{r['factor']:g}", "num"), cell(r["sets"]), cell(r["status"]),
                      cell(r["status"], "bad") if sweep.failed(r) else cell(fmt_number(r["error"]), "num"), cell(r["worst"]), cell(fmt_number(r["particle_steps"]), "num"),
                      cell(fmt_number(r["steps"]), "num"), cell(fmt_number(r["wall_seconds"]), "num"), cell(r["note"])]
                     for r in cost.rows]
        parts.append("<h4 id=\"every-point\">Every swept point</h4>" +
                     table_html(["sweep", "factor", "settings", "status", "error", "largest term", "particle-steps",
                                 "steps", "wall s", "note"], every_row))
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


def stability_page(reports_dir, revision, date):
    """stability.html: the limits and extreme probes in full, or None when there are none."""
    body = stability_html(reports_dir)
    if not body:
        return None
    return "\n".join([
        "<!DOCTYPE html>", "<html lang=\"en\"><head><meta charset=\"utf-8\">",
        "<title>ballast: stability limits and extreme probes</title>", f"<style>{CSS}</style></head><body>",
        "<header><h1>Stability limits and extreme probes</h1>",
        f"<p class=\"meta\">git revision <code>{esc(revision)}</code> &middot; {esc(date)} &middot; "
        "<a href=\"index.html#stability\">back to the report</a></p></header>", body, "</body></html>", ""])
