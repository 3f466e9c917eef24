"""The [sweep NAME] sections of case.txt: what a case declares to sweep for error against cost.

A case declares its sweeps in case.txt, one [sweep NAME] section per swept parameter
(after the [case], like [variant] and [figure]):

    [sweep dt]
    variant = damped                         # the variant whose run each point replaces
    keys = settings.dt=0.01                  # KEY=DEFAULT ...: every key is set to DEFAULT x factor
    factors = 0.5 2 4                        # a few factors around the default (1, the default, is implicit)
    scale = stage.load.cycles=40             # optional KEY=DEFAULT ...: set to DEFAULT / factor, a
                                             #   whole number (same simulated time, or same closure)
    checks = damped_eq_A damped_eq_B         # optional: the error terms (default: every eligible check;
                                             #   `checks = none`: no check, only error/converge terms)
    error = contact_error('exact')           # optional, repeatable: a quantity that is itself a
                                             #   relative deviation from a reference solution
    set = settings.integrator=gear5          # optional, repeatable: a fixed override of every point
    converge = max(Fn_C)                     # optional, repeatable: self-convergence (sweep.py)

parse() reads one section into a Sweep (catalogue.py calls it for every [sweep]); what a
sweep's points are run with and how their error is measured is sweep.py (on points.py and
error_cost.py, the machinery `harness study` and `harness sweep CASE` share).
"""
import math
from dataclasses import dataclass, field

SWEEP_KEYS = {"variant", "keys", "factors", "scale", "checks", "error", "set", "converge"}


@dataclass
class Sweep:
    name: str
    variant: str
    keys: list                   # [(key, default)]
    factors: list                # floats, never 1
    scale: list = field(default_factory=list)    # [(key, default)] set to default / factor
    checks: list = field(default_factory=list)   # names; [] = every eligible check
    errors: list = field(default_factory=list)   # expressions
    path: str = ""
    line: int = 0
    fixed: list = field(default_factory=list)    # `set =` overrides of every point: "KEY=VALUE"
    converge: list = field(default_factory=list)  # self-convergence expressions
    no_checks: bool = False                      # `checks = none`

    def run_factors(self):
        """The factors that are run by the sweep: with fixed overrides, 1 as well."""
        return ([1.0] if self.fixed else []) + list(self.factors)

    def sets(self, factor):
        """The --set overrides of the point at factor."""
        out = list(self.fixed)
        out += [f"{k}={number(d * factor)}" for k, d in self.keys]
        out += [f"{k}={round(d / factor)}" for k, d in self.scale]
        return out

    def label(self, factor):
        return f"{self.name}_x{number(factor)}"


def number(x):
    """A value as the core reads it back exactly enough: 12 significant digits."""
    return f"{x:.12g}"


def parse(section):
    """A [sweep NAME] section -> Sweep; errors name file:line."""
    section.check_keys(SWEEP_KEYS)
    keys = _pairs(section, "keys", required=True)
    scale = _pairs(section, "scale", required=False)
    entry = section.entry("factors")
    if entry is None or not entry.value:
        raise section.error(f"[sweep {section.name}] needs 'factors = F1 F2 ...' (factors of the default)")
    factors = []
    for word in entry.value.split():
        try:
            f = float(word)
        except ValueError:
            raise section.error(f"factor '{word}' is not a number", entry.line) from None
        if not (math.isfinite(f) and f > 0):
            raise section.error(f"factor '{word}' must be a positive number", entry.line)
        if f == 1:
            raise section.error("factor 1 is the default run itself (drawn on every curve): leave it out",
                                entry.line)
        if f in factors:
            raise section.error(f"factor '{word}' given twice", entry.line)
        factors.append(f)
    for key, default in scale:
        for f in factors:
            scaled = default / f
            if abs(scaled - round(scaled)) > 1e-9 * max(1.0, abs(scaled)) or round(scaled) < 1:
                raise section.error(f"scale: {key} = {number(default)} / factor {number(f)} = {scaled:g} "
                                    "is not a whole number >= 1", section.entry("scale").line)
    fixed = []
    for entry in section.all("set"):
        name, sep, value = entry.value.partition("=")
        if not sep or not name.strip() or not value.strip() or " " in entry.value.strip():
            raise section.error(f"'set' needs KEY=VALUE (no blanks), got '{entry.value}'", entry.line)
        if name in [k for k, _ in keys + scale]:
            raise section.error(f"'set': {name} is swept (keys/scale) and cannot be fixed", entry.line)
        if name in [f.partition("=")[0] for f in fixed]:
            raise section.error(f"'set': {name} given twice", entry.line)
        fixed.append(entry.value.strip())
    checks = section.get("checks", "").split()
    no_checks = checks == ["none"]
    if "none" in checks and not no_checks:
        raise section.error("'checks = none' takes no other name", section.entry("checks").line)
    return Sweep(name=section.name, variant=section.require("variant"), keys=keys, factors=factors,
                 scale=scale, checks=[] if no_checks else checks,
                 errors=[e.value for e in section.all("error")], path=section.path, line=section.line,
                 fixed=fixed, converge=[e.value for e in section.all("converge")], no_checks=no_checks)


def _pairs(section, key, required):
    entry = section.entry(key)
    if entry is None or not entry.value:
        if required:
            raise section.error(f"[sweep {section.name}] needs '{key} = KEY=DEFAULT ...'")
        return []
    pairs = []
    for word in entry.value.split():
        name, sep, value = word.partition("=")
        try:
            default = float(value)
        except ValueError:
            default = None
        if not sep or not name or default is None or not math.isfinite(default):
            raise section.error(f"'{key}' takes KEY=DEFAULT words (a number, no blanks), got '{word}'", entry.line)
        if any(name == n for n, _ in pairs):
            raise section.error(f"'{key}': {name} given twice", entry.line)
        pairs.append((name, default))
    return pairs
