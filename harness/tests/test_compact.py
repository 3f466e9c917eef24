"""What a validate keeps under reports/ (harness/compact.py, issue 32, item 4): a case's own runs
whole with a large series.tsv gzipped, of an ensemble's realisations and the sweep points only
what says what ran, a failed run whole; every reader goes on from what is kept, --resume too.

A default validate left 335 MB under reports/ (136 MB the realisations' tables, 92 MB the sweep
points', 40 MB the series.tsv of the cases' own runs)."""
import gzip
import json
import os

import pytest

from harness import compact
from harness.__main__ import main
from harness.report.contents import SVG_LINK_MAX, pack_vector
from harness.report.plots import FigureOut
from harness.tests.test_sweep_cost import SWEEPS

ROWS = 3000          # the fake core's series.tsv of `long`: some 100 KiB, above GZIP_MIN
ENSEMBLE = "\n[ensemble k]\nscene = spring.scene\nset = k={seed}\nseeds = 1-4\n"
LONG = "\n[variant long]\nscene = spring.scene\nset = k=1\nset = n=%d\n" % ROWS
FAILS = "\n[variant broken]\nscene = spring.scene\nset = fail=4\n"
# checks that read a realisation's series.tsv alone, and its removed discs.tsv (as the pile
# statistics read theirs): the first still evaluates after validate, the second says why not (the
# fake core's discs.tsv has no columns: the check fails before too, having read the file)
REFS = """
[check k_last]
case = spring
variant = k_s3
quantity = last(F)
value = 30
tolerance = rel 1e-12
kind = exact
provenance = F = k x with k = 3, x = 10

[check k_discs]
case = spring
variant = k_s3
quantity = weight()
value = 0
tolerance = abs 1
kind = regression
provenance = a check that reads discs.tsv
"""


def project_with_everything(project, broken=False):
    case = project / "cases" / "springs" / "case.txt"
    case.write_text(case.read_text() + LONG + (FAILS if broken else "") + ENSEMBLE + SWEEPS)
    (project / "reference" / "more.ref").write_text(REFS)
    return project / "reports"


def files_in(folder):
    return sorted(p.name for p in folder.iterdir())


def summary(reports):
    return {(d["case"], d["check"], d["variant"]): d for d in json.loads((reports / "summary.json").read_text())}


@pytest.fixture
def validated(project, monkeypatch):
    """A validate of the fake project with a long run, an ensemble and the sweeps (no stability)."""
    reports = project_with_everything(project)
    assert main(["validate", "--no-stability"]) in (0, 1)
    return reports


def test_validate_gzips_large_series_and_drops_what_nothing_reads(validated):
    runs = validated / "runs" / "spring"
    assert files_in(runs / "long") == ["ballast.stderr", "ballast.stdout", "contacts.tsv", "discs.tsv",
                                       "harness.json", "run.json", "series.tsv.gz", "stress.tsv", "walls.tsv"]
    text = gzip.decompress((runs / "long" / "series.tsv.gz").read_bytes()).decode()
    assert len(text.splitlines()) == ROWS + 1
    record = json.loads((runs / "long" / "harness.json").read_text())
    assert record["outputs"]["series.tsv"] == compact.sha256_bytes(text.encode())     # the run's own bytes
    assert "series.tsv" in files_in(runs / "soft")            # below GZIP_MIN: plain
    for seed in range(1, 5):                                  # a realisation: what ran, and its series
        assert files_in(runs / f"k_s{seed}") == ["ballast.stderr", "harness.json", "run.json", "series.tsv"]
    points = sorted((validated / "sweeps" / "spring").iterdir())
    assert points and all(files_in(p) == ["ballast.stderr", "harness.json", "run.json"] for p in points if p.is_dir())
    assert (validated / "sweeps" / "spring" / "cost.tsv").is_file()


def test_every_check_but_those_on_removed_tables_evaluates_the_same_after_validate(validated, capsys):
    before = summary(validated)
    assert "column(s) missing from discs.tsv" in before[("spring", "k_discs", "k_s3")]["message"]
    main(["check"])
    capsys.readouterr()
    after = summary(validated)
    assert after.keys() == before.keys()
    changed = [k for k in before if before[k] != after[k]]
    assert changed == [("spring", "k_discs", "k_s3")]
    message = after[("spring", "k_discs", "k_s3")]["message"]
    assert "discs.tsv of " in message and "was removed after the report of the validate" in message
    assert "`harness run spring` makes it again" in message


def test_resume_keeps_the_gzipped_runs_and_reruns_the_compacted_ones(validated, capsys):
    capsys.readouterr()
    assert main(["run", "spring", "--resume"]) == 0
    out = capsys.readouterr().out
    assert "spring/long  done before, kept (--resume)" in out and "spring/soft  done before, kept" in out
    assert "k_s1  done before" not in out                     # its tables were removed: run again
    assert "contacts.tsv" in files_in(validated / "runs" / "spring" / "k_s1")


def test_a_later_report_keeps_the_figures_of_a_case_whose_tables_were_removed(validated, capsys):
    figure = validated / "figures" / "spring_force.png"
    drawn = figure.stat().st_mtime_ns
    assert main(["report"]) == 0
    assert figure.stat().st_mtime_ns == drawn
    assert "have their tables removed since" in (validated / "index.html").read_text()
    # harness.json keeps its time: summary.json is still fresh, its verdicts are the report's
    assert "verdicts: reports/summary.json" in (validated / "cases" / "spring.html").read_text()


def test_keep_outputs_keeps_every_file(project):
    reports = project_with_everything(project)
    main(["validate", "--no-stability", "--keep-outputs"])
    assert "series.tsv" in files_in(reports / "runs" / "spring" / "long")
    assert "contacts.tsv" in files_in(reports / "runs" / "spring" / "k_s1")
    assert "harness.json" in files_in(reports / "sweeps" / "spring" / "stiffness_x2")
    assert "series.tsv" in files_in(reports / "sweeps" / "spring" / "stiffness_x2")


def test_a_failed_run_and_an_interrupted_validate_keep_every_file(project, monkeypatch):
    reports = project_with_everything(project, broken=True)
    assert main(["validate", "--no-stability"]) == 1
    assert "ballast.stderr" in files_in(reports / "runs" / "spring" / "broken")
    assert "contacts.tsv" not in files_in(reports / "runs" / "spring" / "k_s1")
    import harness.__main__ as cli

    def interrupted(args):
        raise KeyboardInterrupt
    monkeypatch.setattr(cli, "cmd_report", interrupted)
    assert main(["validate", "--no-stability"]) == 130                # stopped before the report
    assert "series.tsv" in files_in(reports / "runs" / "spring" / "long")
    assert "contacts.tsv" in files_in(reports / "runs" / "spring" / "k_s1")


def test_validate_says_what_it_kept(project, capsys):
    project_with_everything(project)
    main(["validate", "--no-stability"])
    out = capsys.readouterr().out
    line = next(ln for ln in out.splitlines() if ln.startswith("kept "))
    assert "1 series.tsv gzipped" in line and "the tables of 4 ensemble realisation(s) and 3 sweep point(s) removed" in line
    assert "--keep-outputs keeps every file" in line


def test_a_large_vector_figure_is_kept_gzipped_and_linked(tmp_path):
    svg, png = tmp_path / "c_big.svg", tmp_path / "c_big.png"
    svg.write_text("<svg>" + "<line/>" * (SVG_LINK_MAX // 6) + "</svg>")
    png.write_bytes(b"png")
    out = pack_vector(FigureOut("big", "big", svg=svg, png=png), svg)
    assert out.svg == tmp_path / "c_big.svg.gz" and not svg.exists()
    assert gzip.decompress(out.svg.read_bytes()).startswith(b"<svg>")
    small = pack_vector(FigureOut("big", "big", svg=None, png=png), svg)       # drawn again, no SVG now
    assert small.svg is None and not (tmp_path / "c_big.svg.gz").exists()      # the old one goes
    svg.write_text("<svg/>")
    kept = pack_vector(FigureOut("big", "big", svg=svg, png=png), svg)
    assert kept.svg == svg and svg.exists()


def test_disk_counts_every_file_once(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "x").write_bytes(b"12345")
    (tmp_path / "y").write_bytes(b"123")
    os.symlink(tmp_path / "y", tmp_path / "link")
    assert compact.disk(tmp_path) == 8


def test_a_validate_without_sweeps_leaves_the_points_an_earlier_cost_wrote(project):
    reports = project_with_everything(project)
    assert main(["run", "spring"]) == 0 and main(["cost", "spring"]) == 0
    assert main(["validate", "--no-stability", "--no-sweeps"]) == 1      # k_discs fails (see REFS)
    assert "series.tsv" in files_in(reports / "sweeps" / "spring" / "stiffness_x2")
    assert "contacts.tsv" not in files_in(reports / "runs" / "spring" / "k_s1")
