"""The INI-like parser: sections, repeated keys, comments, and file:line on malformed input."""
import pytest

from harness.errors import IniError
from harness.ini import parse, parse_file

GOOD = """\
# leading comment
[case two]          # trailing comment
tier = quick
set = a.b=1
set = c=2   # the value keeps its own '='
empty =

[variant v1]
scene = x.scene
"""


def test_sections_entries_and_lines():
    sections = parse(GOOD, "good.txt")
    assert [(s.kind, s.name, s.line) for s in sections] == [("case", "two", 2), ("variant", "v1", 8)]
    case = sections[0]
    assert case.get("tier") == "quick"
    assert [e.value for e in case.all("set")] == ["a.b=1", "c=2"]
    assert [e.line for e in case.all("set")] == [4, 5]
    assert case.get("empty") == ""
    assert case.get("missing", "dflt") == "dflt"


@pytest.mark.parametrize("text, line, words", [
    ("[case a]\nno equals sign here\n", 2, "expected 'key = value'"),
    ("tier = quick\n[case a]\n", 1, "before any [section]"),
    ("[case a]\n[broken\n", 2, "malformed section header"),
    ("[case]\n", 1, "malformed section header"),
    ("[case a b c]\n", 1, "malformed section header"),
    ("[case a/b]\n", 1, "malformed section header"),
    ("[case a]\n\n\n = value\n", 4, "malformed key"),
    ("[case a]\nbad key = 1\n", 2, "malformed key"),
])
def test_malformed_input_names_file_and_line(text, line, words):
    with pytest.raises(IniError) as err:
        parse(text, "cases/x/case.txt")
    assert str(err.value).startswith(f"cases/x/case.txt:{line}: ")
    assert words in str(err.value)
    assert err.value.line == line


def test_repeated_single_key_is_an_error_at_the_second_line():
    section = parse("[case a]\ntier = quick\ntier = full\n", "f.txt")[0]
    with pytest.raises(IniError, match=r"f\.txt:3: 'tier' given twice"):
        section.get("tier")


def test_require_and_number_report_lines():
    section = parse("[check c]\nvalue = abc\nkind =\n", "r.ref")[0]
    with pytest.raises(IniError, match=r"r\.ref:2: 'value' must be a number"):
        section.number("value")
    with pytest.raises(IniError, match=r"r\.ref:3: 'kind' is empty"):
        section.require("kind")
    with pytest.raises(IniError, match=r"r\.ref:1: .*needs 'case = \.\.\.'"):
        section.require("case")


def test_unknown_key_is_reported():
    section = parse("[case a]\ntier = quick\ntitel = typo\n", "f.txt")[0]
    with pytest.raises(IniError, match=r"f\.txt:3: unknown key 'titel'"):
        section.check_keys({"tier", "title"})


def test_parse_file_names_the_file(tmp_path):
    path = tmp_path / "bad.ref"
    path.write_text("[check a]\ncase = x\noops\n")
    with pytest.raises(IniError) as err:
        parse_file(path)
    assert "bad.ref:3:" in str(err.value)


def test_unreadable_file_is_an_ini_error(tmp_path):
    with pytest.raises(IniError, match="cannot read"):
        parse_file(tmp_path / "absent.txt")
