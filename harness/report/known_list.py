"""The KNOWN discrepancies of the whole catalogue in the report, from reference/known.tsv.

Every KNOWN check is listed, those of cases this tier did not run too (all of them are in
full-tier cases today), with the paper's value, ballast's last measured value, when (date,
tier, commit) it was measured, the reason and a link to the case notes (harness/known.py)."""
import html
import os

from .. import cases_root, reference_root
from .. import known

HEADERS = ("case", "check", "paper", "ballast", "last measured", "tier", "commit", "reason", "notes")
INTRO = ("Known discrepancies with the papers: every `known =` check of reference/, whether or not "
         "this report ran its case; the values are those last measured, from reference/known.tsv "
         "(refreshed by `check`/`validate --tier full`).")


def rows(root=None):
    return known.load(known.record_path(root or reference_root()))


def _href(notes, reports_dir):
    """The case notes relative to the report's folder (the repository holds both)."""
    return os.path.relpath(cases_root().parent / notes, reports_dir)


def _cells(r):
    return (r["case"], r["check"], r["paper"], r["value"], r["date"], r["tier"], r["commit"][:12], r["reason"])


def markdown_lines(record, reports_dir):
    if not record:
        return []
    md = [f"## Known discrepancies ({len(record)})", "", INTRO, "",
          "| " + " | ".join(HEADERS) + " |", "|" + "---|" * len(HEADERS)]
    md += ["| " + " | ".join(str(c).replace("|", "\\|") for c in _cells(r))
           + f" | [{r['notes']}]({_href(r['notes'], reports_dir)}) |" for r in record]
    return md + [""]


def html_section(record, reports_dir):
    if not record:
        return ""
    esc = html.escape
    head = "".join(f"<th>{esc(h)}</th>" for h in HEADERS)
    body = "\n".join("<tr>" + "".join(f"<td>{esc(str(c))}</td>" for c in _cells(r))
                     + f"<td><a href=\"{esc(_href(r['notes'], reports_dir))}\">{esc(r['notes'])}</a></td></tr>"
                     for r in record)
    return (f"<section id=\"known\"><h2>Known discrepancies ({len(record)})</h2>"
            f"<p class=\"meta\">{esc(INTRO)}</p><table><tr>{head}</tr>\n{body}</table></section>")
