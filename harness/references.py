"""The references: reference/<family>.ref read into Check objects.

Each [check NAME] section names a case, the variant(s) to evaluate in, a quantity
expression and a tolerance.  Tolerance lines:

    abs X | rel X                     with value
    interval                          with lo and/or hi (no value)
    trend <direction>                 with variants = v1 v2 ... (no value)
    ratio X                           with value and other (optional other_variant)

load() validates the syntax of every check (errors name file:line); validate() checks
the case and variant names against the catalogue.
"""
from dataclasses import dataclass, field, replace
from pathlib import Path

from . import reference_root
from .errors import IniError, shown
from .ini import parse_file

KINDS = ("analytic", "exact", "paper", "regression")
TRENDS = ("increasing", "decreasing", "nondecreasing", "nonincreasing")
KEYS = {"case", "variant", "quantity", "value", "tolerance", "kind", "provenance",
        "lo", "hi", "variants", "other", "other_variant", "known"}


@dataclass
class Check:
    name: str
    case: str
    quantity: str
    tolerance: str           # abs | rel | interval | trend | ratio
    tolerance_text: str      # the tolerance line as written (blanks normalised)
    kind: str
    provenance: str
    variant: str = ""
    value: float = None
    width: float = None      # X of abs / rel / ratio
    lo: float = None
    hi: float = None
    direction: str = ""      # trend
    variants: list = field(default_factory=list)
    other: str = ""
    other_variant: str = ""
    path: str = ""
    line: int = 0
    value_line: int = 0      # line of 'value = ...' (0 when absent); rebaseline rewrites it
    known: str = ""          # a KNOWN DISCREPANCY with a paper: why ballast differs (kind paper only)

    @property
    def run_variants(self):
        """Every variant whose outputs the check reads, in order."""
        if self.tolerance == "trend":
            return list(self.variants)
        names = [self.variant]
        if self.tolerance == "ratio" and self.other_variant not in ("", self.variant):
            names.append(self.other_variant)
        return names

    @property
    def variant_label(self):
        return " ".join(self.variants) if self.tolerance == "trend" else self.variant


def load(root=None):
    """Every check of reference/*.ref (files sorted by name, checks in file order)."""
    root = Path(root or reference_root())
    checks, seen = [], {}
    for path in sorted(root.glob("*.ref")):
        for check in load_file(path):
            key = (check.case, check.name)
            if key in seen:
                raise IniError(check.path, check.line,
                               f"check '{check.name}' of case '{check.case}' already defined at {seen[key]}")
            seen[key] = f"{shown(check.path)}:{check.line}"
            checks.append(check)
    return checks


def load_file(path):
    """The checks of one .ref file."""
    checks = []
    for section in parse_file(path):
        if section.kind != "check":
            raise section.error(f"unknown section kind '{section.kind}' (a .ref file holds [check NAME])")
        checks.append(_check(section))
    return checks


def _check(section):
    section.check_keys(KEYS)
    kind = section.require("kind")
    if kind not in KINDS:
        raise section.error(f"kind must be one of {', '.join(KINDS)}, not '{kind}'", section.entry("kind").line)
    value = section.entry("value")
    check = Check(name=section.name, case=section.require("case"), quantity=section.require("quantity"),
                  tolerance="", tolerance_text="", kind=kind, provenance=_provenance(section),
                  variant=section.get("variant", ""), value=section.number("value"),
                  path=section.path, line=section.line, value_line=value.line if value else 0)
    _tolerance(check, section)
    known = section.entry("known")
    if known is not None:
        if kind != "paper":
            raise section.error("'known = REASON' (a known discrepancy) is for kind = paper only: ballast's "
                                "own solutions and baselines must agree", known.line)
        if not known.value.strip():
            raise section.error("'known' needs the reason ballast differs, or where it is discussed", known.line)
        check.known = known.value.strip()
    return check


def _provenance(section):
    lines = [e.value for e in section.all("provenance")]
    if not any(lines):
        raise section.error("every check needs a non-empty 'provenance = ...' (where the reference comes from)")
    return " ".join(v for v in lines if v)


def _tolerance(check, section):
    """Fill the tolerance fields of check and enforce the keys each kind needs."""
    entry = section.entry("tolerance")
    if entry is None or not entry.value:
        raise section.error("every check needs 'tolerance = ...'")
    words = entry.value.split()
    check.tolerance, check.tolerance_text = words[0], " ".join(words)
    parsers = {"abs": _width, "rel": _width, "ratio": _ratio, "interval": _interval, "trend": _trend}
    if check.tolerance not in parsers:
        raise section.error(f"unknown tolerance '{words[0]}' (known: {', '.join(parsers)})", entry.line)
    parsers[check.tolerance](check, section, words[1:], entry.line)
    _only_with(section, check.tolerance)


def _width(check, section, args, line):
    if len(args) != 1:
        raise section.error(f"'{check.tolerance}' takes one number, e.g. '{check.tolerance} 1e-9'", line)
    try:
        check.width = float(args[0])
    except ValueError:
        raise section.error(f"tolerance width must be a number, not '{args[0]}'", line) from None
    if not check.width >= 0:
        raise section.error("tolerance width must be >= 0", line)
    if check.value is None:
        raise section.error(f"tolerance '{check.tolerance}' needs 'value = ...'")
    if not check.variant:
        raise section.error("this check needs 'variant = ...'")


def _ratio(check, section, args, line):
    _width(check, section, args, line)
    check.other = section.require("other")
    check.other_variant = section.get("other_variant", "") or check.variant


def _interval(check, section, args, line):
    if args:
        raise section.error("'interval' takes no argument: give 'lo = ...' and/or 'hi = ...'", line)
    if check.value is not None:
        raise section.error("an interval check has no 'value'; give 'lo' and/or 'hi'", check.value_line)
    if not check.variant:
        raise section.error("this check needs 'variant = ...'")
    check.lo, check.hi = section.number("lo"), section.number("hi")
    if check.lo is not None and check.hi is not None and check.lo > check.hi:
        raise section.error(f"interval lo = {check.lo:g} is above hi = {check.hi:g}")


def _trend(check, section, args, line):
    if len(args) != 1 or args[0] not in TRENDS:
        raise section.error(f"'trend' takes one of {', '.join(TRENDS)}", line)
    if check.value is not None:
        raise section.error("a trend check has no 'value'", check.value_line)
    if check.variant:
        raise section.error("a trend check takes 'variants = v1 v2 ...', not 'variant'", section.entry("variant").line)
    check.direction = args[0]
    check.variants = section.require("variants").split()
    if len(check.variants) < 2:
        raise section.error("a trend needs at least two variants", section.entry("variants").line)


def _only_with(section, tolerance):
    """Keys that belong to one tolerance kind must not appear with another."""
    owners = {"lo": "interval", "hi": "interval", "variants": "trend", "other": "ratio", "other_variant": "ratio"}
    for key, owner in owners.items():
        entry = section.entry(key)
        if entry and owner != tolerance:
            raise section.error(f"'{key}' only goes with 'tolerance = {owner}'", entry.line)


EVERY = "*"


def expand(checks, cases):
    """A check with case = * and variant = * stands for one check per DEM variant
    (command = run) of every case: the gates every run must pass (the energy audit).
    Its copies are named NAME[variant]."""
    out = []
    for check in checks:
        if check.case != EVERY:
            out.append(check)
            continue
        if check.variant != EVERY or check.tolerance in ("trend", "ratio"):
            raise IniError(check.path, check.line,
                           f"check '{check.name}': case = * needs variant = * and an abs, rel or interval tolerance")
        for case in cases:
            for variant in case.variants:
                if variant.command == "run":
                    out.append(replace(check, name=f"{check.name}[{variant.name}]", case=case.name,
                                       variant=variant.name))
    return out


def validate(checks, cases):
    """Every check names a known case and variants of it (errors name file:line)."""
    by_name = {c.name: c for c in cases}
    for check in checks:
        case = by_name.get(check.case)
        if case is None:
            raise IniError(check.path, check.line, f"check '{check.name}' names unknown case '{check.case}'")
        for variant in check.run_variants:
            if not case.variant(variant):
                raise IniError(check.path, check.line,
                               f"check '{check.name}': case '{check.case}' has no variant '{variant}' "
                               f"(has: {', '.join(case.variant_names())})")
    names = {(c.case, c.name) for c in checks}
    for case in cases:
        for figure in case.figures:
            for name in figure.references:
                if (case.name, name) not in names:
                    raise IniError(case.path, figure.line, f"figure '{figure.name}': reference '{name}' is no "
                                   f"check of case '{case.name}'")


def reference_lines(figure, checks):
    """The reference lines (slope 0, level, title) a figure draws for its `reference` checks: a
    point reference's value, an interval's bounds."""
    lines = []
    for name in figure.references:
        check = next((c for c in checks if c.name == name), None)
        if check is None:
            continue
        if check.value is not None and check.tolerance in ("abs", "rel"):
            lines.append((0.0, float(check.value), f"reference {name} ({check.kind}): {check.value:.6g}"))
        else:
            bounds = [b for b in (check.lo, check.hi) if b is not None]
            lines += [(0.0, float(b), f"reference {name} ({check.kind}) bound {b:.6g}") for b in bounds]
    return lines


def for_cases(checks, cases):
    """The checks that belong to the given cases, in catalogue order, then reference order."""
    order = {c.name: i for i, c in enumerate(cases)}
    chosen = [c for c in checks if c.case in order]
    return sorted(chosen, key=lambda c: order[c.case])
