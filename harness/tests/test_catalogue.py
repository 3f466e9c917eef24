"""The catalogue: reading cases/*/case.txt, validation with file:line, selection by name and tier."""
import pytest

from harness import catalogue, stability
from harness.errors import CatalogueError, IniError


def test_loads_cases_variants_and_figures(project):
    cases = catalogue.load()          # root from BALLAST_CASES
    assert [c.name for c in cases] == ["slow", "spring"]     # families sorted by folder name
    spring = cases[1]
    assert (spring.tier, spring.runtime, spring.family) == ("quick", 3.0, "springs")
    assert spring.variant_names() == ["soft", "stiff", "stiffer"]
    assert spring.variant("stiff").sets == ["k=2"]
    assert spring.variant("soft").scene == project / "cases" / "springs" / "spring.scene"
    figure = spring.figures[0]
    assert (figure.name, figure.x, figure.y, figure.variants) == ("force", "cycle", ["F"], ["soft", "stiff"])
    assert cases[0].figures == []


def test_figure_variants_default_to_all(tmp_path):
    write(tmp_path, "fam", CASE + "[figure f]\nx = cycle\ny = A B\n")
    case = catalogue.load(tmp_path)[0]
    assert case.figures[0].variants == ["v1", "v2"]
    assert case.figures[0].xlabel == "cycle"


@pytest.mark.parametrize("given, kept", [("0:12", "0:12"), (" -1.5e3 : ", "-1.5e3:"), (":7", ":7")])
def test_figure_ranges(tmp_path, given, kept):
    write(tmp_path, "fam", CASE + f"[figure f]\nx = cycle\ny = A\nxrange = {given}\n")
    assert catalogue.load(tmp_path)[0].figures[0].xrange == kept


def test_bad_figure_range_is_an_error(tmp_path):
    write(tmp_path, "fam", CASE + "[figure f]\nx = cycle\ny = A\nyrange = 0 to 12\n")
    with pytest.raises(IniError, match=r"case\.txt:16: 'yrange' must be 'lo:hi'"):
        catalogue.load(tmp_path)


def test_select_by_tier_and_name(project):
    cases = catalogue.load()
    assert [c.name for c in catalogue.select(cases, tier="quick")] == ["spring"]
    assert [c.name for c in catalogue.select(cases, tier="standard")] == ["spring"]
    assert [c.name for c in catalogue.select(cases, tier="full")] == ["slow", "spring"]
    assert [c.name for c in catalogue.select(cases, ["slow"], tier="quick")] == ["slow"]
    with pytest.raises(CatalogueError, match="unknown case"):
        catalogue.select(cases, ["nope"])


CASE = """\
[case c1]
tier = quick
title = t
checks = c
runtime = 1

[variant v1]
scene = s.scene

[variant v2]
scene = s.scene
set = a.b=2
"""


def write(root, family, text):
    folder = root / family
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "case.txt").write_text(text)
    return folder / "case.txt"


@pytest.mark.parametrize("text, line, words", [
    (CASE.replace("tier = quick", "tier = slowish"), 2, "tier must be one of"),
    (CASE.replace("runtime = 1", "runtime = soon"), 5, "must be a number"),
    (CASE.replace("runtime = 1\n", ""), 1, "needs 'runtime"),
    (CASE.replace("title = t\n", ""), 1, "needs 'title"),
    (CASE.replace("set = a.b=2", "set = nokeyvalue"), 12, "needs KEY=VALUE"),
    (CASE + "[variant v1]\nscene = s\n", 13, "defined twice"),
    (CASE + "[figure f]\nx = cycle\ny = A\nvariants = v1 v9\n", 13, "unknown variant 'v9'"),
    (CASE + "[plot p]\nx = 1\n", 13, "unknown section kind"),
    (CASE + "[figure f]\nx = cycle\nyy = A\n", 15, "unknown key 'yy'"),
    ("[variant v]\nscene = s\n", 1, "before any [case]"),
    (CASE.split("[variant")[0], 1, "has no [variant]"),
], ids=["tier", "runtime", "no-runtime", "no-title", "set", "variant-twice", "figure-variant",
        "section-kind", "figure-key", "orphan-variant", "no-variant"])
def test_errors_name_file_and_line(tmp_path, text, line, words):
    write(tmp_path, "fam", text)
    with pytest.raises(IniError) as err:
        catalogue.load(tmp_path)
    assert f"case.txt:{line}:" in str(err.value)
    assert words in str(err.value)


def test_case_names_are_unique_across_the_catalogue(tmp_path):
    write(tmp_path, "a", CASE)
    write(tmp_path, "b", "# other family\n" + CASE)
    with pytest.raises(IniError) as err:
        catalogue.load(tmp_path)
    assert "b/case.txt:2:" in str(err.value) and "already defined" in str(err.value)


def test_several_cases_in_one_file(tmp_path):
    write(tmp_path, "fam", CASE + CASE.replace("[case c1]", "[case c2]").replace("quick", "full"))
    cases = catalogue.load(tmp_path)
    assert [(c.name, c.tier, len(c.variants)) for c in cases] == [("c1", "quick", 2), ("c2", "full", 2)]


def test_stability_no_keeps_a_case_from_the_finder(tmp_path):
    """`stability = no` (a case whose motion is prescribed) has no targets for the finder."""
    from_case = CASE.replace("runtime = 1\n", "runtime = 1\nstability = no\n")
    write(tmp_path, "fam", from_case)
    case = catalogue.load(tmp_path)[0]
    assert case.stability is False
    assert stability.targets_for([case]) == []
    write(tmp_path, "fam", CASE)
    assert len(stability.targets_for(catalogue.load(tmp_path))) == 2


def test_stability_value_is_checked(tmp_path):
    write(tmp_path, "fam", CASE.replace("runtime = 1\n", "runtime = 1\nstability = maybe\n"))
    with pytest.raises(IniError, match="stability must be yes or no, not 'maybe'"):
        catalogue.load(tmp_path)


def test_every_axis_of_the_catalogue_says_its_unit():
    """Issue 23: each axis label of every figure ends with its unit in parentheses: '(kPa)', '(s)',
    '(m g / l)', '(-)' for a pure number or a count, '(BALL units of force)' where the paper has
    none (C&S: 'No attempts have been made to relate the units used in BALL to physical units')."""
    import re
    from pathlib import Path
    unit = re.compile(r"\([^()]+\)\s*$")
    missing = [f"{c.name}/{f.name}: {axis} '{label}'"
               for c in catalogue.load(Path(__file__).resolve().parents[2] / "cases") for f in c.figures
               if f.kind not in ("network", "principal", "snapshots", "movie")     # pictures without axes
               for axis, label in (("xlabel", f.xlabel), ("ylabel", f.ylabel)) if not unit.search(label or "")]
    assert not missing, "axis labels without a unit: " + "; ".join(missing)
