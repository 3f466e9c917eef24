"""The figure kinds profile, principal and points: parsed by the catalogue (bad keys, kinds and
values refused with file:line), rendered by the report from fake pile outputs, and whatever
cannot be drawn listed in the figure's notes."""
import math
import shutil

import pytest

from harness import catalogue, report
from harness.compare import RunStore, folder_locator
from harness.errors import IniError
from harness.report import plots
from harness.tests.pile_fakes import write_pile_run

needs_gnuplot = pytest.mark.skipif(not shutil.which("gnuplot"), reason="gnuplot not installed")

CASE = """\
[case pile]
tier = quick
title = a fake pile
checks = pile figures
runtime = 1

[variant dem]
scene = s.scene

[variant dem2]
scene = s.scene

[variant exact]
scene = s.scene
command = exact
"""


def load(tmp_path, figure):
    folder = tmp_path / "cases" / "piles"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "case.txt").write_text(CASE + "\n" + figure)
    return catalogue.load(tmp_path / "cases")[0]


# ---------------------------------------------------------------- catalogue

def test_profile_figure(tmp_path):
    case = load(tmp_path, "[figure s]\nkind = profile\nvariants = dem dem2\ny = zz xx\npaper = \"dip\" (MLH)\n")
    f = case.figures[0]
    assert (f.kind, f.variants, f.y, f.row, f.paper) == ("profile", ["dem", "dem2"], ["zz", "xx"], 1, "\"dip\" (MLH)")
    assert f.xlabel == catalogue.PROFILE_XLABEL and f.ylabel == catalogue.PROFILE_YLABEL
    case = load(tmp_path, "[figure s]\nkind = profile\ny = ratio phi max min xz\nrow = 2\n"
                          "xlabel = X\nylabel = S\nxrange = 0:1\n")
    f = case.figures[0]
    assert (f.variants, f.row, f.xlabel, f.ylabel, f.xrange) == (["dem", "dem2", "exact"], 2, "X", "S", "0:1")


def test_principal_figure(tmp_path):
    f = load(tmp_path, "[figure p]\nkind = principal\nvariants = dem\ntitle = axes\n").figures[0]
    assert (f.kind, f.variants, f.title) == ("principal", ["dem"], "axes")


def test_points_figure(tmp_path):
    f = load(tmp_path, "[figure e]\nkind = points\nvariants = dem2 dem\nx = run('steps')\n"
                       "y = contact_error('exact', kind = 'wall')\nlogscale = yx\n").figures[0]
    assert (f.kind, f.variants, f.x, f.y, f.logscale) == (
        "points", ["dem2", "dem"], "run('steps')", ["contact_error('exact', kind = 'wall')"], "xy")
    assert (f.xlabel, f.ylabel) == ("run('steps')", "contact_error('exact', kind = 'wall')")
    f = load(tmp_path, "[figure e]\nkind = points\nx = weight()\ny = weight()\nlogscale =\n").figures[0]
    assert f.logscale == "" and f.variants == ["dem", "dem2", "exact"]


@pytest.mark.parametrize("figure, line, words", [
    ("[figure f]\nkind = pie\n", 17, "figure kind must be one of series, network, profile, principal, points"),
    ("[figure f]\nkind = profile\ny = zz yy\n", 19, "profile component must be one of"),
    ("[figure f]\nkind = profile\nrow = 1.5\ny = zz\n", 19, "'row' must be a pile row number"),
    ("[figure f]\nkind = profile\nrow = -1\ny = zz\n", 19, "'row' must be a pile row number"),
    ("[figure f]\nkind = profile\nrow = one\ny = zz\n", 19, "'row' must be a number"),
    ("[figure f]\nkind = profile\n", 17, "needs 'y = ...'"),
    ("[figure f]\nkind = profile\ny = zz\nlogscale = x\n", 20, "'logscale' does not apply to a profile figure"),
    ("[figure f]\nkind = profile\ny = zz\nx = cycle\n", 20, "'x' does not apply to a profile figure"),
    ("[figure f]\nx = cycle\ny = F\nrow = 1\n", 20, "'row' does not apply to a series figure"),
    ("[figure f]\nkind = principal\nvariants = dem dem2\n", 17, "a principal figure shows exactly one variant"),
    ("[figure f]\nkind = principal\n", 17, "needs 'variants = ...'"),
    ("[figure f]\nkind = principal\nvariants = dem\ny = zz\n", 20, "'y' does not apply to a principal figure"),
    ("[figure f]\nkind = network\nvariants = dem\nx = cycle\n", 20, "'x' does not apply to a network figure"),
    ("[figure f]\nkind = points\nx = weight()\ny = contact_error('exact'\n", 20, "'y' is not an expression"),
    ("[figure f]\nkind = points\nx = weight()\n", 17, "needs 'y = ...'"),
    ("[figure f]\nkind = points\nx = 1\ny = 2\nlogscale = z\n", 21, "'logscale' must be xy, x, y or empty"),
    ("[figure f]\nkind = points\nx = 1\ny = 2\nrow = 1\n", 21, "'row' does not apply to a points figure"),
    ("[figure f]\nkind = points\nx = 1\ny = 2\nvariants = dem nope\n", 17, "unknown variant 'nope'"),
    ("[figure f]\nkind = points\nx = 1\ny = 2\nlogscal = x\n", 21, "unknown key 'logscal'"),
])
def test_bad_figures_are_refused(tmp_path, figure, line, words):
    with pytest.raises(IniError) as err:
        load(tmp_path, figure)
    assert f"case.txt:{line}:" in str(err.value) and words in str(err.value), str(err.value)


# ---------------------------------------------------------------- report

@pytest.fixture
def store(tmp_path):
    root = tmp_path / "runs"
    write_pile_run(root / "pile" / "dem")
    write_pile_run(root / "pile" / "dem2", gravity=(0.0, -4.0))
    write_pile_run(root / "pile" / "exact", exact=True)
    return RunStore(folder_locator(root))


def render(tmp_path, store, figure):
    case = load(tmp_path, figure)
    out = plots.render_figure(case, case.figures[0], store, tmp_path)
    return out


def rendered(out):
    return out.png is not None and out.png.stat().st_size > 1000 and out.svg is not None


@needs_gnuplot
def test_profile_renders(tmp_path, store):
    out = render(tmp_path, store, "[figure s]\nkind = profile\nvariants = dem dem2\ny = zz xx\n")
    assert out.notes == [] and rendered(out)
    assert out.png.name == "pile_s.png"


@needs_gnuplot
def test_profile_notes_what_it_cannot_draw(tmp_path, store):
    out = render(tmp_path, store, "[figure s]\nkind = profile\nvariants = dem exact\ny = zz\n")
    assert rendered(out)                                   # dem is drawn
    assert len(out.notes) == 1 and out.notes[0].startswith("exact: zz:") and "stress.tsv missing" in out.notes[0]
    out = render(tmp_path, store, "[figure s]\nkind = profile\nvariants = exact\ny = zz\n")
    assert out.png is None and out.notes[-1] == "nothing to plot"


@needs_gnuplot
def test_principal_renders(tmp_path, store):
    out = render(tmp_path, store, "[figure p]\nkind = principal\nvariants = dem\n")
    assert out.notes == [] and rendered(out)


def test_principal_crosses():
    """Lengths proportional to S (largest |S| 0.9 of the largest diameter), along phi and across."""
    axes = [(0.0, 0.0, 0.5, 2.0, 1.0, 90.0), (3.0, 0.0, 0.5, 1.0, -0.5, 0.0)]
    segments, top = plots.principal_lines(axes)
    assert top == 2.0 and len(segments) == 4
    (ax0, ay0, ax1, ay1, t0), (bx0, by0, bx1, by1, t1) = segments[:2]
    assert (ax0, ax1) == pytest.approx((0.0, 0.0)) and (ay0, ay1) == pytest.approx((-0.45, 0.45))   # vertical, 0.9 d
    assert (bx0, bx1) == pytest.approx((0.225, -0.225)) and by1 == pytest.approx(0.0)  # across, half as long
    assert not t0 and not t1
    c, d = segments[2:]
    assert math.hypot(c[2] - c[0], c[3] - c[1]) == pytest.approx(0.45) and not c[4]
    assert math.hypot(d[2] - d[0], d[3] - d[1]) == pytest.approx(0.225) and d[4]     # tensile
    assert plots.principal_lines([(0, 0, 0.5, 0.0, 0.0, 0.0)]) == ([], 0.0)


@needs_gnuplot
def test_principal_without_stress_is_noted(tmp_path, store):
    out = render(tmp_path, store, "[figure p]\nkind = principal\nvariants = exact\n")
    assert out.png is None and len(out.notes) == 1 and "stress.tsv missing" in out.notes[0]


@needs_gnuplot
def test_points_render(tmp_path, store):
    out = render(tmp_path, store, "[figure e]\nkind = points\nvariants = dem dem2\nx = weight()\n"
                                  "y = contact_error('exact')\nlogscale = xy\n")
    assert out.notes == [] and rendered(out)


@needs_gnuplot
def test_points_list_the_variants_they_cannot_draw(tmp_path, store):
    out = render(tmp_path, store, "[figure e]\nkind = points\nvariants = dem exact dem2\n"
                                  "x = weight()\ny = middle(pile_S('zz'))\n")
    assert rendered(out)
    assert len(out.notes) == 1 and out.notes[0].startswith("exact: not drawn:") and "stress.tsv" in out.notes[0]
    out = render(tmp_path, store, "[figure e]\nkind = points\nvariants = dem dem2\n"
                                  "x = weight() - 20\ny = contact_error('exact')\nlogscale = x\n")
    assert rendered(out)                                   # dem2: x = 12
    assert out.notes == ["dem: not drawn: x = -4 is not positive (log scale)"]
    out = render(tmp_path, store, "[figure e]\nkind = points\nvariants = exact\nx = 1\ny = nope()\n")
    assert out.png is None and "unknown function 'nope'" in out.notes[0] and out.notes[-1] == "nothing to plot"


@needs_gnuplot
def test_new_figures_appear_in_the_report(tmp_path, store):
    case = load(tmp_path, "[figure s]\nkind = profile\ny = zz\nvariants = dem\npaper = \"a dip\" (MLH)\n\n"
                          "[figure p]\nkind = principal\nvariants = dem\npaper = \"arching\"\n\n"
                          "[figure e]\nkind = points\nvariants = dem dem2\nx = weight()\ny = 1\n")
    reports = tmp_path / "reports"
    index = report.write_report([case], [], store, tmp_path / "runs", reports)
    html, md = index.read_text(), (reports / "cases" / "pile.md").read_text()
    for name in ("pile_s", "pile_p", "pile_e"):
        assert (reports / "figures" / f"{name}.png").stat().st_size > 1000
        assert f"../figures/{name}.png" in md
    assert html.count('src="figures/') == 3 and html.count(".svg\"") == 3
    assert "&quot;a dip&quot; (MLH)" in html and "> \"arching\"" in md
