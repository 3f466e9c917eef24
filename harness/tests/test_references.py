"""Reference files: every tolerance kind parses; malformed checks are errors naming file:line."""
import pytest

from harness import catalogue, references
from harness.errors import IniError

BASE = """\
[check c]
case = spring
variant = soft
quantity = last(F)
value = 10
tolerance = rel 1e-9
kind = analytic
provenance = somewhere
"""


def load_text(tmp_path, text):
    path = tmp_path / "x.ref"
    path.write_text(text)
    return references.load_file(path)


def test_fake_project_references_parse(project):
    checks = references.load()
    assert [c.name for c in checks] == ["abs_at2", "rel_last", "interval_ek", "trend_k", "ratio_k", "regress_mean"]
    by = {c.name: c for c in checks}
    assert (by["abs_at2"].tolerance, by["abs_at2"].width, by["abs_at2"].value) == ("abs", 1e-12, 2.0)
    assert (by["interval_ek"].lo, by["interval_ek"].hi, by["interval_ek"].value) == (0.0, 100.0, None)
    assert by["interval_ek"].provenance == "a plausible range (second line)"
    assert by["trend_k"].variants == ["soft", "stiff", "stiffer"] and by["trend_k"].direction == "increasing"
    assert by["trend_k"].run_variants == ["soft", "stiff", "stiffer"]
    assert (by["ratio_k"].other, by["ratio_k"].other_variant) == ("last(F)", "soft")
    assert by["ratio_k"].run_variants == ["stiff", "soft"]
    assert by["regress_mean"].value_line == 54 and by["regress_mean"].kind == "regression"
    references.validate(checks, catalogue.load())


def test_interval_bounds_are_optional(tmp_path):
    text = BASE.replace("value = 10\n", "").replace("rel 1e-9", "interval") + "hi = 3\n"
    check = load_text(tmp_path, text)[0]
    assert (check.lo, check.hi) == (None, 3.0)


@pytest.mark.parametrize("old, new, line, words", [
    ("provenance = somewhere", "provenance =", 1, "non-empty 'provenance"),
    ("provenance = somewhere\n", "", 1, "non-empty 'provenance"),
    ("kind = analytic", "kind = guess", 7, "kind must be one of"),
    ("rel 1e-9", "relative 1e-9", 6, "unknown tolerance"),
    ("rel 1e-9", "rel", 6, "takes one number"),
    ("rel 1e-9", "rel tiny", 6, "must be a number"),
    ("rel 1e-9", "abs -1", 6, "must be >= 0"),
    ("value = 10\n", "", 1, "needs 'value"),
    ("value = 10", "value = ten", 5, "must be a number"),
    ("rel 1e-9", "interval", 5, "has no 'value'"),
    ("rel 1e-9", "trend upwards", 6, "'trend' takes one of"),
    ("rel 1e-9", "ratio 0.1", 1, "needs 'other"),
    ("kind = analytic", "kind = analytic\nlo = 1", 8, "'lo' only goes with 'tolerance = interval'"),
    ("kind = analytic", "kind = analytic\nvariants = a b", 8, "'variants' only goes with"),
    ("case = spring\n", "", 1, "needs 'case"),
    ("quantity = last(F)\n", "", 1, "needs 'quantity"),
    ("variant = soft\n", "", 1, "needs 'variant"),
    ("[check c]", "[case c]", 1, "unknown section kind"),
    ("kind = analytic", "kind = analytic\ncolour = red", 8, "unknown key 'colour'"),
], ids=lambda x: x if isinstance(x, str) and len(x) < 25 else None)
def test_malformed_checks_name_file_and_line(tmp_path, old, new, line, words):
    assert old in BASE
    with pytest.raises(IniError) as err:
        load_text(tmp_path, BASE.replace(old, new))
    assert f"x.ref:{line}:" in str(err.value)
    assert words in str(err.value)


def test_trend_needs_two_variants_and_no_single_variant(tmp_path):
    trend = BASE.replace("value = 10\n", "").replace("rel 1e-9", "trend increasing")
    with pytest.raises(IniError, match="not 'variant'"):
        load_text(tmp_path, trend + "variants = a b\n")
    with pytest.raises(IniError, match="at least two variants"):
        load_text(tmp_path, trend.replace("variant = soft\n", "") + "variants = a\n")


def test_check_names_are_unique_within_a_case(tmp_path):
    (tmp_path / "a.ref").write_text(BASE)
    (tmp_path / "b.ref").write_text("\n" + BASE)
    with pytest.raises(IniError) as err:
        references.load(tmp_path)
    assert "b.ref:2:" in str(err.value) and "already defined" in str(err.value)


def test_same_check_name_in_two_cases_is_fine(tmp_path):
    (tmp_path / "a.ref").write_text(BASE + "\n" + BASE.replace("case = spring", "case = other"))
    assert len(references.load(tmp_path)) == 2


def test_validate_against_catalogue(project, tmp_path):
    cases = catalogue.load()
    with pytest.raises(IniError, match="unknown case 'nope'"):
        references.validate(load_text(tmp_path, BASE.replace("case = spring", "case = nope")), cases)
    with pytest.raises(IniError, match="has no variant 'hard'"):
        references.validate(load_text(tmp_path, BASE.replace("variant = soft", "variant = hard")), cases)
    ratio = BASE.replace("rel 1e-9", "ratio 0.1") + "other = last(F)\nother_variant = hard\n"
    with pytest.raises(IniError, match="has no variant 'hard'"):
        references.validate(load_text(tmp_path, ratio), cases)
