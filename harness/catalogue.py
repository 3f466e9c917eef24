"""The case catalogue: cases/<family>/case.txt read into Case, Variant and Figure objects.

A case.txt holds one or more [case NAME] sections; the [variant] and [figure] sections
after a [case] belong to it.  load() reads every family folder (sorted by name, cases in
file order) and validates names, tiers and references between sections; select() picks
cases by name or by tier.
"""
import re
from dataclasses import dataclass, field
from pathlib import Path

from . import TIERS, cases_root
from .ini import IniError, parse_file, shown

CASE_KEYS = {"tier", "title", "checks", "runtime"}
VARIANT_KEYS = {"scene", "set"}
FIGURE_KEYS = {"kind", "title", "variants", "x", "y", "xlabel", "ylabel", "xrange", "yrange", "paper"}
FIGURE_KINDS = ("series", "network")
NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
RANGE = re.compile(rf"^\s*({NUMBER})?\s*:\s*({NUMBER})?\s*$")


class CatalogueError(ValueError):
    """A catalogue problem that is not tied to one line (e.g. an unknown case name)."""


@dataclass
class Variant:
    name: str
    scene: Path
    sets: list


@dataclass
class Figure:
    name: str
    title: str
    variants: list
    x: str
    y: list
    xlabel: str
    ylabel: str
    xrange: str = ""         # gnuplot range 'lo:hi' (either side may be empty); '' = automatic
    yrange: str = ""
    line: int = 0
    kind: str = "series"     # series: columns against x; network: force network of a final state
    paper: str = ""          # the paper's words the figure reproduces, shown beside it


@dataclass
class Case:
    name: str
    family: str
    folder: Path
    tier: str
    title: str
    checks: str
    runtime: float
    path: str = ""
    line: int = 0
    variants: list = field(default_factory=list)
    figures: list = field(default_factory=list)

    @property
    def source(self):
        """'file:line' of the [case] header."""
        return f"{shown(self.path)}:{self.line}"

    def variant(self, name):
        """The variant called name, or None."""
        return next((v for v in self.variants if v.name == name), None)

    def variant_names(self):
        return [v.name for v in self.variants]


def tier_rank(tier):
    """quick < standard < full."""
    return TIERS.index(tier)


def load(root=None):
    """Every case of the catalogue, in order (families sorted, cases in file order)."""
    root = Path(root or cases_root())
    cases, seen = [], {}
    for path in sorted(root.glob("*/case.txt")):
        for case in load_file(path):
            if case.name in seen:
                raise IniError(case.path, case.line, f"case '{case.name}' already defined at {seen[case.name]}")
            seen[case.name] = case.source
            cases.append(case)
    return cases


def load_file(path):
    """The cases of one case.txt."""
    cases = []
    for section in parse_file(path):
        if section.kind == "case":
            cases.append(_case(section, Path(path)))
        elif not cases:
            raise section.error(f"[{section.kind} {section.name}] comes before any [case]")
        elif section.kind == "variant":
            _add_variant(cases[-1], section)
        elif section.kind == "figure":
            _add_figure(cases[-1], section)
        else:
            raise section.error(f"unknown section kind '{section.kind}' (known: case, variant, figure)")
    for case in cases:
        _finish(case)
    return cases


def _case(section, path):
    section.check_keys(CASE_KEYS)
    tier = section.require("tier")
    if tier not in TIERS:
        raise section.error(f"tier must be one of {', '.join(TIERS)}, not '{tier}'", section.entry("tier").line)
    runtime = section.number("runtime")
    if runtime is None:
        raise section.error("[case] needs 'runtime = <expected seconds>'")
    return Case(name=section.name, family=path.parent.name, folder=path.parent, tier=tier,
                title=section.require("title"), checks=section.require("checks"),
                runtime=runtime, path=section.path, line=section.line)


def _add_variant(case, section):
    section.check_keys(VARIANT_KEYS)
    if case.variant(section.name):
        raise section.error(f"variant '{section.name}' defined twice in case '{case.name}'")
    for entry in section.all("set"):
        if "=" not in entry.value:
            raise section.error(f"'set' needs KEY=VALUE, got '{entry.value}'", entry.line)
    sets = [e.value for e in section.all("set")]
    case.variants.append(Variant(section.name, case.folder / section.require("scene"), sets))


def _add_figure(case, section):
    section.check_keys(FIGURE_KEYS)
    if any(f.name == section.name for f in case.figures):
        raise section.error(f"figure '{section.name}' defined twice in case '{case.name}'")
    kind = section.get("kind", "series")
    if kind not in FIGURE_KINDS:
        raise section.error(f"figure kind must be one of {', '.join(FIGURE_KINDS)}, not '{kind}'")
    paper = " ".join(e.value for e in section.all("paper"))
    if kind == "network":
        variants = section.require("variants").split()
        if len(variants) != 1:
            raise section.error("a network figure shows exactly one variant")
        case.figures.append(Figure(
            name=section.name, title=section.get("title", section.name), variants=variants,
            x="", y=[], xlabel="", ylabel="", line=section.line, kind=kind, paper=paper))
        return
    case.figures.append(Figure(
        name=section.name, title=section.get("title", section.name),
        variants=section.get("variants", "").split(), x=section.require("x"),
        y=section.require("y").split(), xlabel=section.get("xlabel", section.require("x")),
        ylabel=section.get("ylabel", ""), xrange=_range(section, "xrange"),
        yrange=_range(section, "yrange"), line=section.line, kind=kind, paper=paper))


def _range(section, key):
    """An optional axis range 'lo:hi' (numbers; either may be omitted), normalised."""
    entry = section.entry(key)
    if entry is None:
        return ""
    match = RANGE.match(entry.value)
    if not match:
        raise section.error(f"'{key}' must be 'lo:hi' (numbers, either may be empty), not '{entry.value}'", entry.line)
    return f"{match.group(1) or ''}:{match.group(2) or ''}"


def _finish(case):
    """Whole-case checks: at least one variant; figures name existing variants."""
    if not case.variants:
        raise IniError(case.path, case.line, f"case '{case.name}' has no [variant]")
    for figure in case.figures:
        for name in figure.variants:
            if not case.variant(name):
                raise IniError(case.path, figure.line,
                               f"figure '{figure.name}' names unknown variant '{name}'")
        figure.variants = figure.variants or case.variant_names()


def select(cases, names=(), tier="standard"):
    """The named cases (any tier), or, with no names, every case of tier <= tier."""
    by_name = {c.name: c for c in cases}
    unknown = [n for n in names if n not in by_name]
    if unknown:
        raise CatalogueError(f"unknown case(s): {', '.join(unknown)} (known: {', '.join(by_name)})")
    if names:
        return [by_name[n] for n in dict.fromkeys(names)]
    return [c for c in cases if tier_rank(c.tier) <= tier_rank(tier)]
