"""The report: reports/summary.md and a self-contained reports/index.html, with gnuplot figures.

Per case: title, what it checks, its figures (from its [figure] sections), the checks table
(measured beside reference, tolerance, kind, provenance, PASS/FAIL), each run's wall time,
status and energy audit, and its error against cost; then the stability tables.  The page
header has the git revision and the date.  One module per output:

    contents.py   what the report shows, gathered once (runs, verdicts, figures, costs)
    plots.py      the figures of case.txt, drawn by gnuplot (network.py: the force network)
    cost_plot.py  the error-against-cost diagram
    markdown.py   summary.md (the verdict, the failures, the KNOWN list, then each case)
    known_list.py every KNOWN discrepancy of the catalogue, from reference/known.tsv
    html_page.py  index.html

write_report() below calls them in that order.  summary.md and index.html reach reports/
through files.py (a temporary file, then rename), so a killed report leaves each of them old
or new, never empty or cut.
"""
import subprocess
from datetime import datetime, timezone
from pathlib import Path

from .. import REPO_ROOT, files
from ..children import options as child_options
from .contents import gather
from .html_page import page, stability_html
from .known_list import html_section as known_html, markdown_lines as known_markdown, rows as known_rows
from .markdown import markdown, stability_markdown


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


def peers_link(reports_dir, kind):
    """A link to the agreement matrix with another engine (`make validate-peers`,
    harness/engines/matrix.py) when one has been written; '' otherwise."""
    if not (Path(reports_dir) / "peers" / "index.md").exists():
        return ""
    if kind == "md":
        return ("\n## Other engines\n\nThe catalogue's checks on LAMMPS's runs beside ballast's: "
                "[peers/index.md](peers/index.md).\n")
    return ("<h2>Other engines</h2><p>The catalogue's checks on LAMMPS's runs beside ballast's: "
            "<a href=\"peers/index.html\">peers/index.html</a>.</p>")


def write_report(cases, checks, store, runs_root, reports_dir, out=None, render=None):
    """Render figures, write summary.md and index.html; return the index path.  render: the
    case names whose figures are drawn anew (None: all; gather)."""
    reports_dir = Path(reports_dir)
    reports = gather(cases, checks, store, runs_root, reports_dir, render)
    revision, date = git_revision(), now_text()
    record = known_rows()        # every KNOWN discrepancy, its case run or not (reference/known.tsv)
    files.write_text(reports_dir / "summary.md", markdown(reports, revision, date, known_markdown(record, reports_dir))
                     + stability_markdown(reports_dir) + peers_link(reports_dir, "md"))
    index = reports_dir / "index.html"
    files.write_text(index, page(reports, revision, date, known_html(record, reports_dir)).replace("</body></html>",
                     stability_html(reports_dir) + peers_link(reports_dir, "html") + "</body></html>"))
    if out:
        print(f"wrote {reports_dir / 'summary.md'} and {index}", file=out)
    return index
