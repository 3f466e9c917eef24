"""The report: figures rendered by gnuplot, a short summary.md and index.html that link the figures
and each case's page (cases/<case>.md and .html: runs, checks with provenance), and the header."""
import re
import shutil
import subprocess
import time
from html.parser import HTMLParser

import pytest

from harness import report
from harness.__main__ import main
from harness.tests.fakes import spring_columns, tree_snapshot, write_run, write_spring_runs

needs_gnuplot = pytest.mark.skipif(not shutil.which("gnuplot"), reason="gnuplot not installed")


class Links(HTMLParser):
    """Every src and href of a page, and its text."""

    def __init__(self):
        super().__init__()
        self.links, self.text = [], []

    def handle_starttag(self, tag, attrs):
        self.links += [(tag, k, v) for k, v in attrs if k in ("src", "href")]

    def handle_data(self, data):
        self.text.append(data)


def parse(path):
    page = Links()
    page.feed(path.read_text())
    return page


def make_report(capsys, *args):
    assert main(["report", *args]) == 0
    capsys.readouterr()


def assert_links_resolve(page_path):
    """Every src and href of a page is an anchor of it or a file of the report folder that exists."""
    page = parse(page_path)
    for tag, attr, value in page.links:
        if value.startswith("#"):
            continue
        assert "://" not in value and not value.startswith("data:"), (page_path.name, tag, attr, value[:40])
        assert (page_path.parent / value.split("#")[0]).is_file(), (page_path.name, tag, attr, value)
    return page


@needs_gnuplot
def test_report_links_its_figures_and_case_pages(project, runs, capsys):
    """Issue 32, item 4: index.html links its figures (it was one page with every figure inlined,
    9.8 MB for the catalogue) and the case's page holds the full tables."""
    write_spring_runs(runs)
    main(["check"])
    make_report(capsys)
    reports = project / "reports"
    page = assert_links_resolve(reports / "index.html")
    images = [v for t, a, v in page.links if t == "img"]
    assert images == ["figures/spring_force.svg"]
    assert ("a", "href", "cases/spring.html") in page.links
    text = " ".join(page.text)
    for words in ("A linear spring", "F = k x at every cycle; trend in k", "Spring force",
                  "git revision", "6 passed, 0 failed", "runs ok"):
        assert words in text, words
    assert "regress_mean" not in text          # the passing rows are on the case page, not here
    case = assert_links_resolve(reports / "cases" / "spring.html")
    assert [v for t, a, v in case.links if t == "img"] == ["../figures/spring_force.svg"]
    text = " ".join(case.text)
    for words in ("F = k x with k = 1, x = 2", "a plausible range (second line)", "regress_mean",
                  "6 passed, 0 failed", "wall s", "ok"):
        assert words in text, words
    assert (reports / "figures" / "spring_force.png").stat().st_size > 1000
    assert (reports / "figures" / "spring_force.svg").read_text().lstrip().startswith("<?xml")
    md = (reports / "summary.md").read_text()
    assert "| spring | A linear spring | quick | 3/3 | 6 | 0 | 0 | 0 | [cases/spring.md](cases/spring.md) |" in md
    page_md = (reports / "cases" / "spring.md").read_text()
    assert "# spring: A linear spring" in page_md and "](../figures/spring_force.png)" in page_md
    assert "| rel_last | stiff | 20 | 20 | rel 1e-9 | exact | PASS |" in page_md


@needs_gnuplot
def test_report_shows_missing_and_failed_runs_as_failures(project, runs, capsys):
    write_run(runs / "spring" / "soft", spring_columns(1), status="unstable")
    write_run(runs / "spring" / "stiff", spring_columns(2))
    make_report(capsys)
    text = " ".join(parse(project / "reports" / "index.html").text)
    assert "unstable" in text and "not run" in text
    assert "1 passed, 5 failed" in text             # only rel_last reads stiff alone
    assert "soft: no data" in text                  # the figure says why a curve is missing
    assert (project / "reports" / "figures" / "spring_force.png").exists()   # stiff still plotted


def test_report_without_any_data_draws_no_figure(project, capsys):
    make_report(capsys)
    text = " ".join(parse(project / "reports" / "index.html").text)
    assert "nothing to plot" in text and "(no figure)" in text
    assert not (project / "reports" / "figures" / "spring_force.png").exists()


def test_report_without_gnuplot_still_writes_the_page(project, runs, capsys, monkeypatch):
    write_spring_runs(runs)
    monkeypatch.setattr(shutil, "which", lambda name: None)
    make_report(capsys)
    assert "gnuplot not found" in (project / "reports" / "index.html").read_text()


def test_report_uses_fresh_summary_and_reevaluates_stale_one(project, runs, capsys):
    write_spring_runs(runs)
    main(["check"])
    make_report(capsys, "spring")
    assert "verdicts: reports/summary.json" in (project / "reports" / "cases" / "spring.html").read_text()
    time.sleep(0.01)
    write_spring_runs(runs, (("soft", 1), ("stiff", 5), ("stiffer", 6)))       # newer than summary.json
    make_report(capsys, "spring")
    html = (project / "reports" / "cases" / "spring.html").read_text()
    assert "evaluated by `report`" in html and "4 passed, 2 failed" in html
    assert "4 passed, 2 failed" in (project / "reports" / "index.html").read_text()


def test_report_never_writes_reference(project, runs, capsys):
    write_spring_runs(runs)
    before = tree_snapshot(project / "reference")
    make_report(capsys, "--tier", "full")
    assert tree_snapshot(project / "reference") == before


def test_git_revision(tmp_path):
    assert report.git_revision(tmp_path) == "unknown"
    git = ["git", "-c", "user.name=t", "-c", "user.email=t@t", "-c", "init.defaultBranch=main"]
    subprocess.run(git + ["init", "-q", str(tmp_path)], check=True)
    (tmp_path / "f").write_text("x")
    subprocess.run(git + ["-C", str(tmp_path), "add", "f"], check=True)
    subprocess.run(git + ["-C", str(tmp_path), "commit", "-q", "-m", "m"], check=True)
    revision = report.git_revision(tmp_path)
    assert revision != "unknown" and len(revision) >= 7


def test_html_escapes_text(project, runs, capsys):
    ref = project / "reference" / "springs.ref"
    ref.write_text(ref.read_text().replace("provenance = F grows with k", "provenance = <b>k</b> & co"))
    write_spring_runs(runs)
    make_report(capsys)
    assert "&lt;b&gt;k&lt;/b&gt; &amp; co" in (project / "reports" / "cases" / "spring.html").read_text()


def many_checks(project, n):
    """n more passing checks of case spring (the catalogue's piles_poly has 1014 of them)."""
    text = "".join(f"\n[check many_{i}]\ncase = spring\nvariant = soft\nquantity = at(F, 2)\nvalue = 2\n"
                   f"tolerance = abs 1e-12\nkind = analytic\nprovenance = one of many\n" for i in range(n))
    (project / "reference" / "many.ref").write_text(text)


def test_summary_and_index_do_not_grow_with_the_checks(project, runs, capsys):
    """Issue 32, item 4: summary.md and index.html list the failures, the KNOWN list and the counts
    per case; every check's row is on the case's page (summary.md was 1.1 MB for 1 326 checks)."""
    write_spring_runs(runs)
    main(["check"])
    make_report(capsys)
    reports = project / "reports"
    size = lambda page: (reports / page).stat().st_size if (reports / page).is_file() else 0
    pages = ("summary.md", "index.html", "cases/spring.md", "cases/spring.html")
    before = {p: size(p) for p in pages}
    many_checks(project, 1000)
    assert main(["check"]) == 0
    make_report(capsys)
    grown = {p: size(p) - before[p] for p in pages}
    assert grown["summary.md"] < 50 and grown["index.html"] < 50, grown      # "1006 passed" for "6 passed"
    assert grown["cases/spring.md"] > 1000 * 50 and grown["cases/spring.html"] > 1000 * 100, grown
    assert "many_999" in (reports / "cases" / "spring.md").read_text()
    assert "many_999" not in (reports / "summary.md").read_text()


def md_links(path):
    """The targets of the markdown links [text](target) of a file."""
    return re.findall(r"\]\(([^)\s]+)\)", path.read_text())


def test_summary_leads_with_the_verdict_and_the_failures_and_its_links_resolve(project, runs, capsys):
    write_spring_runs(runs, ks=(("soft", 1), ("stiff", 3), ("stiffer", 3)))   # rel_last, ratio_k, trend_k fail
    assert main(["report"]) == 0
    capsys.readouterr()
    reports = project / "reports"
    md = (reports / "summary.md").read_text()
    lines = md.splitlines()
    assert lines[0] == "# ballast validation report" and "**3 passed, 3 failed.**" in lines[2]
    assert md.index("## Failures (3)") < md.index("## Cases (1)")
    assert "- **FAIL** spring/rel_last (stiff):" in md and "| rel_last |" not in md
    assert "| spring | A linear spring | quick | 3/3 | 3 | **3** | 0 | 0 | [cases/spring.md](cases/spring.md) |" in md
    for page in (reports / "summary.md", reports / "cases" / "spring.md"):
        targets = md_links(page)
        assert targets, page
        for target in targets:
            assert (page.parent / target).is_file(), (page.name, target)
    html = (reports / "index.html").read_text()
    assert html.index("Failures (3)") < html.index("case-spring")
    assert_links_resolve(reports / "cases" / "spring.html")


def test_report_removes_the_page_of_a_case_it_no_longer_has(project, runs, capsys):
    write_spring_runs(runs)
    (project / "reports" / "cases").mkdir()
    for name in ("gone.md", "gone.html"):
        (project / "reports" / "cases" / name).write_text("an old page")
    make_report(capsys)
    assert sorted(p.name for p in (project / "reports" / "cases").iterdir()) == ["spring.html", "spring.md"]
