"""The report: reports/summary.md and reports/index.html, each case's page under reports/cases/,
the stability page, and the gnuplot figures under reports/figures/.

summary.md and index.html lead with the verdict, the failures, the skipped checks and the KNOWN
list, then one row per case with its counts, and end with the budget (budget.py: each case's
runs, particle-steps and seconds, also in budget.json); they stay small whatever the catalogue's
size (issue 32, item 4).  index.html shows, per case, what it checks, the rows that did not pass, its
figures (linked from figures/) and its error against cost.  Each case's page (cases/<case>.md
and .html) holds its full tables: the runs (status, wall time, steps), the energy audit, every
check (measured beside reference, tolerance, kind, provenance, result) and every swept point;
stability.md and .html hold the stability limits and the extreme probes.  Every page has the
git revision and the date.  One module per output:

    contents.py   what the report shows, gathered once (runs, verdicts, figures, costs)
    plots.py      the figures of case.txt, drawn by gnuplot (network.py: the force network)
    cost_plot.py  the error-against-cost diagram
    markdown.py   summary.md and the case pages in markdown
    known_list.py every KNOWN discrepancy of the catalogue, from reference/known.tsv
    budget.py     what each case's runs cost (runs, particle-steps, seconds): budget.json and a table
    html_page.py  index.html and the case pages in HTML

write_report() below calls them in that order.  Every page reaches reports/ through files.py (a
temporary file, then rename), so a killed report leaves each of them old or new, never empty or
cut; a case page that no case of this report has any more is removed.
"""
import subprocess
import time
from datetime import datetime, timezone
from pathlib import Path

from .. import REPO_ROOT, files
from ..children import options as child_options
from . import budget as budgets
from .contents import gather
from .html_page import case_page as case_html, page, stability_page as stability_html_page
from .known_list import html_section as known_html, markdown_lines as known_markdown, rows as known_rows
from .markdown import CASES_DIR, STABILITY_PAGE, case_markdown, markdown, stability_page as stability_md_page


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


def budget_of(cases, runs_root, reports_dir, validate=None, stability=None):
    """The budget of the report's cases (budget.py).  validate ({started, jobs, tier}) and
    stability (budget.stability_costs) come from a validate; without them (`harness report`) those
    of the last validate's budget.json are reused, marked as re-rendered."""
    if validate is None:
        old = budgets.saved(reports_dir)
        validate = dict(old.get("validate") or {})
        if validate:
            validate["rerendered"] = True
        stability = old.get("stability") if stability is None else stability
    else:
        validate = dict(validate)
        if validate.get("started") is not None and validate.get("wall_seconds") is None:
            validate["wall_seconds"] = round(time.time() - validate["started"], 3)
    return budgets.budget(cases, runs_root, Path(reports_dir) / "sweeps", validate or None, stability)


def write_report(cases, checks, store, runs_root, reports_dir, out=None, render=None, validate=None,
                 stability=None):
    """Render figures, write summary.md, index.html, the case pages, the stability page and
    budget.json; return the index path.  render: the case names whose figures are drawn anew
    (None: all; gather); validate, stability: budget_of."""
    reports_dir = Path(reports_dir)
    reports = gather(cases, checks, store, runs_root, reports_dir, render)
    cost = budget_of(cases, runs_root, reports_dir, validate, stability)
    revision, date = git_revision(), now_text()
    record = known_rows()        # every KNOWN discrepancy, its case run or not (reference/known.tsv)
    pages = files.make_dirs(reports_dir / CASES_DIR)
    written = set()
    for r in reports:
        for name, text in ((f"{r.case.name}.md", case_markdown(r, revision, date)),
                           (f"{r.case.name}.html", case_html(r, revision, date))):
            files.write_text(pages / name, text)
            written.add(name)
    for old in pages.iterdir():        # the page of a case this report no longer has
        if old.is_file() and old.suffix in (".md", ".html") and old.name not in written:
            files.remove(old)
    for name, text in ((f"{STABILITY_PAGE}.md", stability_md_page(reports_dir, revision, date)),
                       (f"{STABILITY_PAGE}.html", stability_html_page(reports_dir, revision, date))):
        if text is None:
            files.remove(reports_dir / name)
        else:
            files.write_text(reports_dir / name, text)
    files.write_text(reports_dir / "summary.md",
                     markdown(reports, revision, date, known_markdown(record, reports_dir), reports_dir)
                     + "\n".join(budgets.markdown_lines(cost)) + peers_link(reports_dir, "md"))
    index = reports_dir / "index.html"
    files.write_text(index, page(reports, revision, date, known_html(record, reports_dir), reports_dir)
                     .replace("</body></html>", budgets.html_section(cost) + peers_link(reports_dir, "html")
                              + "</body></html>"))
    budgets.write(reports_dir, cost)
    if out:
        print(f"wrote {reports_dir / 'summary.md'} and {index}", file=out)
    return index
