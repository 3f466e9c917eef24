"""[ensemble NAME] sections of case.txt: many realisations of one scene, one per seed.

An ensemble is a compact way to write many variants that differ only in a seed:

    [ensemble poly]
    scene = pile_poly.scene          # may contain {seed}
    set = pile.p.L=100               # repeatable, as in [variant]; may contain {seed}
    set = pile.p.seed={seed}
    seeds = 1-100                    # N, A-B, or several of them: 1-10 20 30-32 (commas allowed)
    command = run                    # optional: run (default) or exact

stands for the variants poly_s1, poly_s2, ..., poly_s100 (NAME_s<seed>, the seed in
decimal without leading zeros), in the order of `seeds`, each an ordinary variant:
{seed} replaced by the seed in its scene and set lines.  They are run, resumed, checked
and reported as any variant is (reports/runs/<case>/poly_s17/).

Rules (each broken one is an IniError naming file:line):
  * seeds are whole numbers >= 0, no seed twice, at most MAX_REALISATIONS;
  * {seed} appears in the scene or in some set line (else every realisation would be the
    same run), and no other {...} placeholder does;
  * the names NAME_s<digits> belong to the ensemble: no [variant] of the case may be called
    so, and NAME itself names no [variant] (a figure's `variants = NAME` means the ensemble's
    realisations);
  * command is run or exact (the cross-checks against LAMMPS have no seed).

The ensemble's realisations, by name, are what the expression functions of
harness/families/ensembles.py read (members, seeds, over): a case's statistics over its
realisations are ordinary checks.

This module imports nothing of the harness but errors: the catalogue parses with it, and the
runner and the expression families know ensembles only through the variants it makes.
"""
import re
from dataclasses import dataclass, field

ENSEMBLE_KEYS = {"scene", "set", "seeds", "command"}
COMMANDS = ("run", "exact")
PLACEHOLDER = "{seed}"
MAX_REALISATIONS = 100000
_BRACES = re.compile(r"\{[^{}]*\}|[{}]")
_ITEM = re.compile(r"^(\d+)(?:-(\d+))?$")


@dataclass
class Ensemble:
    name: str
    scene: str                   # the scene as written (relative to the case folder), maybe with {seed}
    sets: list                   # KEY=VALUE templates, maybe with {seed}
    seeds: list                  # ints, in declared order
    command: str = "run"
    path: str = ""
    line: int = 0
    members: list = field(default_factory=list)   # variant names, in seed order

    def realisation(self, seed):
        """(variant name, scene, sets) of the realisation with this seed."""
        text = str(seed)
        return (realisation_name(self.name, seed), self.scene.replace(PLACEHOLDER, text),
                [s.replace(PLACEHOLDER, text) for s in self.sets])


def realisation_name(ensemble, seed):
    """The variant name of an ensemble's realisation: NAME_s<seed>."""
    return f"{ensemble}_s{int(seed)}"


def claims(ensemble, variant):
    """True when variant is a name of the form ENSEMBLE_s<digits> (reserved for the ensemble)."""
    prefix = f"{ensemble}_s"
    return variant.startswith(prefix) and variant[len(prefix):].isdigit()


def parse_seeds(text):
    """'1-100', '1 2 5', '1-10, 20 30-32' -> [ints] in order; ValueError saying what is wrong."""
    items = [w for w in re.split(r"[\s,]+", text.strip()) if w]
    if not items:
        raise ValueError("no seeds: give N, A-B or a list of them (e.g. 'seeds = 1-100')")
    seeds, seen = [], set()
    for item in items:
        match = _ITEM.match(item)
        if not match:
            raise ValueError(f"'{item}' is not a seed (N) or a range of seeds (A-B): whole numbers >= 0")
        lo = int(match.group(1))
        hi = int(match.group(2)) if match.group(2) is not None else lo
        if hi < lo:
            raise ValueError(f"range '{item}' runs backwards")
        if len(seeds) + hi - lo + 1 > MAX_REALISATIONS:
            raise ValueError(f"more than {MAX_REALISATIONS} realisations")
        for seed in range(lo, hi + 1):
            if seed in seen:
                raise ValueError(f"seed {seed} is given twice")
            seen.add(seed)
            seeds.append(seed)
    return seeds


def seeds_text(seeds):
    """The seeds written compactly, consecutive runs as ranges: [1, 2, 3, 7] -> '1-3 7'."""
    parts, i = [], 0
    while i < len(seeds):
        j = i
        while j + 1 < len(seeds) and seeds[j + 1] == seeds[j] + 1:
            j += 1
        parts.append(str(seeds[i]) if i == j else f"{seeds[i]}-{seeds[j]}")
        i = j + 1
    return " ".join(parts)


def _template(section, text, line, what):
    """A scene or set template: {seed} is its only placeholder."""
    for found in _BRACES.findall(text):
        if found != PLACEHOLDER:
            raise section.error(f"{what} '{text}': '{found}' is not a placeholder (the only one is {PLACEHOLDER})",
                                line)
    return text


def parse(section):
    """One [ensemble NAME] section -> Ensemble (members filled); IniError naming file:line."""
    section.check_keys(ENSEMBLE_KEYS)
    scene_entry = section.entry("scene")
    scene = _template(section, section.require("scene"), scene_entry.line, "scene")
    sets = []
    for entry in section.all("set"):
        if "=" not in entry.value:
            raise section.error(f"'set' needs KEY=VALUE, got '{entry.value}'", entry.line)
        sets.append(_template(section, entry.value, entry.line, "set"))
    if PLACEHOLDER not in scene and not any(PLACEHOLDER in s for s in sets):
        raise section.error(f"[ensemble {section.name}] uses {PLACEHOLDER} nowhere: every realisation would be "
                            f"the same run (put it in a set line, e.g. 'set = fill.pack.seed={PLACEHOLDER}')")
    seeds_entry = section.entry("seeds")
    if seeds_entry is None:
        raise section.error(f"[ensemble {section.name}] needs 'seeds = ...' (e.g. 'seeds = 1-100')")
    try:
        seeds = parse_seeds(seeds_entry.value)
    except ValueError as exc:
        raise section.error(f"seeds: {exc}", seeds_entry.line) from None
    command = section.get("command", "run")
    if command not in COMMANDS:
        raise section.error(f"an ensemble's command must be one of {', '.join(COMMANDS)}, not '{command}'",
                            section.entry("command").line)
    ensemble = Ensemble(section.name, scene, sets, seeds, command, section.path, section.line)
    ensemble.members = [realisation_name(section.name, s) for s in seeds]
    return ensemble
