"""The report: figures rendered by gnuplot, summary.md, and a self-contained index.html that
shows per case the title, what it checks, figures, checks with provenance, runs and the header."""
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


@needs_gnuplot
def test_report_is_self_contained_and_complete(project, runs, capsys):
    write_spring_runs(runs)
    main(["check"])
    make_report(capsys)
    reports = project / "reports"
    index = reports / "index.html"
    page = parse(index)
    for tag, attr, value in page.links:
        assert value.startswith("data:image/") or value.startswith("#"), (tag, attr, value[:40])
    images = [v for t, a, v in page.links if t == "img"]
    assert len(images) == 1 and images[0].startswith("data:image/svg+xml;base64,")
    text = " ".join(page.text)
    for words in ("A linear spring", "F = k x at every cycle; trend in k", "Spring force",
                  "git revision", "F = k x with k = 1, x = 2", "a plausible range (second line)",
                  "regress_mean", "6 passed, 0 failed", "wall s", "ok"):
        assert words in text, words
    assert (reports / "figures" / "spring_force.png").stat().st_size > 1000
    assert (reports / "figures" / "spring_force.svg").read_text().lstrip().startswith("<?xml")
    md = (reports / "summary.md").read_text()
    assert "## spring: A linear spring" in md and "figures/spring_force.png" in md
    assert "| rel_last | stiff | 20 | 20 | rel 1e-9 | exact | PASS |" in md


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
    assert "verdicts: reports/summary.json" in (project / "reports" / "index.html").read_text()
    time.sleep(0.01)
    write_spring_runs(runs, (("soft", 1), ("stiff", 5), ("stiffer", 6)))       # newer than summary.json
    make_report(capsys, "spring")
    html = (project / "reports" / "index.html").read_text()
    assert "evaluated by `report`" in html and "4 passed, 2 failed" in html


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
    assert "&lt;b&gt;k&lt;/b&gt; &amp; co" in (project / "reports" / "index.html").read_text()
