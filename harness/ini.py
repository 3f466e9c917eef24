"""The INI-like format shared by cases/*/case.txt and reference/*.ref.

    # a comment (a '#' anywhere starts one; it runs to the end of the line)
    [kind name]          a section: its kind and its name
    key = value          an entry of the section above; keys may repeat

parse() turns text into a list of Section objects that remember the line of every
entry; every error raised here or by Section accessors is an IniError (errors.py) naming
file:line.
"""
import re
from dataclasses import dataclass, field

from .errors import IniError

# A section's name.  Case, variant, ensemble and probe names are folder names too
# (reports/runs/<case>/<variant>), so a name holds no '/' and cannot start with '.': never
# '..' or a path (export.py holds a manifest's names to the same rule).
NAME = r"[A-Za-z0-9_][A-Za-z0-9_.\-]*"
HEADER = re.compile(rf"^\[\s*([A-Za-z_]\w*)\s+({NAME})\s*\]$")
KEY = re.compile(r"^[A-Za-z_][A-Za-z0-9_.]*$")


@dataclass
class Entry:
    key: str
    value: str
    line: int


@dataclass
class Section:
    kind: str
    name: str
    path: str
    line: int
    entries: list = field(default_factory=list)

    def error(self, message, line=None):
        """An IniError located at this section (or at the given line)."""
        return IniError(self.path, line or self.line, message)

    def all(self, key):
        """Every entry with this key, in file order."""
        return [e for e in self.entries if e.key == key]

    def entry(self, key):
        """The single entry with this key, or None; a repeated key is an error."""
        found = self.all(key)
        if len(found) > 1:
            raise self.error(f"'{key}' given twice (first on line {found[0].line})", found[1].line)
        return found[0] if found else None

    def get(self, key, default=None):
        """The value of a single key, or default."""
        found = self.entry(key)
        return found.value if found else default

    def require(self, key):
        """The non-empty value of a single key; missing or empty is an error."""
        found = self.entry(key)
        if found is None:
            raise self.error(f"[{self.kind} {self.name}] needs '{key} = ...'")
        if not found.value:
            raise self.error(f"'{key}' is empty", found.line)
        return found.value

    def number(self, key, default=None):
        """The value of a single key as a float (default when absent)."""
        found = self.entry(key)
        if found is None:
            return default
        try:
            return float(found.value)
        except ValueError:
            raise self.error(f"'{key}' must be a number, not '{found.value}'", found.line) from None

    def check_keys(self, allowed):
        """Reject keys this kind of section does not know (catches typos)."""
        for e in self.entries:
            if e.key not in allowed:
                known = ", ".join(sorted(allowed))
                raise self.error(f"unknown key '{e.key}' in [{self.kind}] (known: {known})", e.line)


def strip_comment(line):
    """The line without its comment and surrounding blanks."""
    return line.split("#", 1)[0].strip()


def parse(text, path="<string>"):
    """Parse text into Sections; raise IniError naming path:line on malformed input."""
    sections = []
    for number, raw in enumerate(text.splitlines(), start=1):
        line = strip_comment(raw)
        if not line:
            continue
        if line.startswith("["):
            sections.append(_header(line, path, number))
        else:
            entry = _entry(line, path, number)
            if not sections:
                raise IniError(path, number, f"'{entry.key}' comes before any [section]")
            sections[-1].entries.append(entry)
    return sections


def parse_file(path):
    """Parse a file; a file that cannot be read is an IniError at line 0."""
    try:
        text = open(path, encoding="utf-8").read()
    except (OSError, UnicodeDecodeError) as exc:
        raise IniError(path, 0, f"cannot read: {exc}") from None
    return parse(text, str(path))


def _header(line, path, number):
    match = HEADER.match(line)
    if not match:
        raise IniError(path, number, f"malformed section header '{line}': expected '[kind name]'")
    return Section(match.group(1), match.group(2), str(path), number)


def _entry(line, path, number):
    key, sep, value = line.partition("=")
    key = key.strip()
    if not sep:
        raise IniError(path, number, f"expected 'key = value' or '[kind name]', got '{line}'")
    if not KEY.match(key):
        raise IniError(path, number, f"malformed key '{key}'")
    return Entry(key, value.strip(), number)
