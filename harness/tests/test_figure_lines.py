"""Reference lines of series figures (line = SLOPE INTERCEPT [TITLE]): parsed by the catalogue
(bad ones refused with file:line), drawn by the report beside the data, never without it."""
import shutil

import numpy as np
import pytest

from harness import catalogue
from harness.compare import RunStore, folder_locator
from harness.errors import IniError
from harness.report import plots
from harness.tests.fakes import write_run

needs_gnuplot = pytest.mark.skipif(not shutil.which("gnuplot"), reason="gnuplot not installed")

CASE = """\
[case law]
tier = quick
title = a fake law tester
checks = lines
runtime = 1

[variant a]
scene = s.scene

[variant b]
scene = s.scene
"""


def load(tmp_path, figure):
    folder = tmp_path / "cases" / "laws"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "case.txt").write_text(CASE + "\n" + figure)
    return catalogue.load(tmp_path / "cases")[0]


def test_lines_are_read_in_order_with_their_titles(tmp_path):
    f = load(tmp_path, "[figure m]\nx = theta_r\ny = mr\nline = 196608 0 K_m theta_r (eq. 29)\n"
                       "line = 0 40 +-M_0\nline = 0 -40\nline = -1.5e3 2.5e-1\n").figures[0]
    assert f.lines == [(196608.0, 0.0, "K_m theta_r (eq. 29)"), (0.0, 40.0, "+-M_0"), (0.0, -40.0, ""),
                       (-1500.0, 0.25, "")]
    assert load(tmp_path, "[figure m]\nx = cycle\ny = mr\n").figures[0].lines == []


@pytest.mark.parametrize("figure, line, words", [
    ("[figure f]\nx = cycle\ny = F\nline = 1\n", 16, "'line' must be 'SLOPE INTERCEPT [title]'"),
    ("[figure f]\nx = cycle\ny = F\nline = one 2 three\n", 16, "not 'one 2 three'"),
    ("[figure f]\nx = cycle\ny = F\nline = 1 inf\n", 16, "two finite numbers first"),
    ("[figure f]\nx = cycle\ny = F\nline = 1 nan\n", 16, "two finite numbers first"),
    ("[figure f]\nx = cycle\ny = F\nline = 1 2\nline = 1 2 x\nline = 3\n", 18, "not '3'"),
    ("[figure f]\nkind = points\nx = 1\ny = 2\nline = 1 2\n", 17, "'line' does not apply to a points figure"),
    ("[figure f]\nkind = network\nvariants = a\nline = 1 2\n", 16, "'line' does not apply to a network figure"),
])
def test_bad_lines_are_refused(tmp_path, figure, line, words):
    with pytest.raises(IniError) as err:
        load(tmp_path, figure)
    assert f"case.txt:{line}:" in str(err.value) and words in str(err.value), str(err.value)


def test_a_line_without_a_title_is_drawn_like_the_one_before():
    clauses = plots.line_clauses([(2.5, 0.0, "K"), (0.0, 4.0, "M's level"), (0.0, -4.0, ""), (0.0, 8.0, "2M")])
    assert clauses == [
        "2.5 * x + 0.0 with lines dt 2 lw 1.2 lc rgb '#555555' title 'K'",
        "0.0 * x + 4.0 with lines dt 3 lw 1.2 lc rgb '#555555' title 'M''s level'",
        "0.0 * x + -4.0 with lines dt 3 lw 1.2 lc rgb '#555555' notitle",
        "0.0 * x + 8.0 with lines dt 4 lw 1.2 lc rgb '#555555' title '2M'"]
    assert plots.line_clauses([(1.0, 0.0, "")]) == ["1.0 * x + 0.0 with lines dt 2 lw 1.2 lc rgb '#555555' notitle"]


@pytest.fixture
def store(tmp_path):
    theta = np.concatenate([np.linspace(0, 2, 9), np.linspace(2, -2, 17)])
    m = np.clip(2.5 * theta, -2.5, 2.5)
    cycle = np.arange(1, theta.size + 1)
    write_run(tmp_path / "runs" / "law" / "a", {"cycle": list(cycle), "time": list(cycle * 0.5),
                                                 "theta_r": list(theta), "mr": list(m)})
    return RunStore(folder_locator(tmp_path / "runs"))


@needs_gnuplot
def test_lines_are_drawn_beside_the_data(tmp_path, store, monkeypatch):
    case = load(tmp_path, "[figure m]\nvariants = a\nx = theta_r\ny = mr\nline = 2.5 0 K_m\n"
                          "line = 0 2.5 +-M_0\nline = 0 -2.5\n")
    scripts = []
    run_gnuplot = plots.run_gnuplot
    monkeypatch.setattr(plots, "run_gnuplot", lambda text, workdir: scripts.append(text) or run_gnuplot(text, workdir))
    out = plots.render_figure(case, case.figures[0], store, tmp_path)
    assert out.notes == [] and out.png.stat().st_size > 1000 and out.svg is not None
    plot = scripts[0][scripts[0].index("plot "):]
    assert "a.dat' using 1:2 with lines title 'mr'" in plot     # one variant: titled by its column
    assert "2.5 * x + 0.0 with lines dt 2" in plot and "0.0 * x + -2.5 with lines dt 3" in plot


@needs_gnuplot
def test_lines_alone_are_not_a_figure(tmp_path, store):
    case = load(tmp_path, "[figure m]\nvariants = b\nx = theta_r\ny = mr\nline = 2.5 0 K_m\n")
    out = plots.render_figure(case, case.figures[0], store, tmp_path)
    assert out.png is None and out.notes[-1] == "nothing to plot"


def test_a_variant_label_names_its_curve_in_the_legend(tmp_path):
    """Issue 23: legends say what a curve is (`label` of the variant), not the variant's name."""
    folder = tmp_path / "cases" / "laws"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "case.txt").write_text(CASE.replace("[variant a]\n", "[variant a]\nlabel = Model 1, delta = 1.6\n")
                                     + "\n[figure m]\nx = cycle\ny = mr\n")
    figure = catalogue.load(tmp_path / "cases")[0].figures[0]
    assert plots.curve_title("a", "mr", figure) == "Model 1, delta = 1.6"
    assert plots.curve_title("b", "mr", figure) == "b"               # no label: its name


def test_a_figure_draws_the_reference_of_the_check_it_names(tmp_path):
    """Issue 23: `reference = CHECK` draws that check's reference (a value: its level; an interval:
    its bounds) on the figure, from reference/*.ref, so the line cannot drift from the gate."""
    from harness import references
    folder = tmp_path / "cases" / "laws"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "case.txt").write_text(CASE + "\n[figure m]\nx = cycle\ny = mr\nreference = eq band\n")
    (tmp_path / "ref").mkdir()
    (tmp_path / "ref" / "laws.ref").write_text(
        "[check eq]\ncase = law\nvariant = a\nquantity = last(mr)\nvalue = 2.5\ntolerance = rel 1e-3\n"
        "kind = exact\nprovenance = p\n\n[check band]\ncase = law\nvariant = a\nquantity = max(mr)\n"
        "lo = 1\nhi = 4\ntolerance = interval\nkind = paper\nprovenance = p\n")
    cases = catalogue.load(tmp_path / "cases")
    checks = references.expand(references.load(tmp_path / "ref"), cases)
    references.validate(checks, cases)
    lines = references.reference_lines(cases[0].figures[0], checks)
    assert [(slope, level) for slope, level, _ in lines] == [(0.0, 2.5), (0.0, 1.0), (0.0, 4.0)]
    assert lines[0][2] == "reference eq (exact): 2.5"
    (folder / "case.txt").write_text(CASE + "\n[figure m]\nx = cycle\ny = mr\nreference = nope\n")
    with pytest.raises(IniError, match="reference 'nope' is no check of case 'law'"):
        references.validate(checks, catalogue.load(tmp_path / "cases"))
