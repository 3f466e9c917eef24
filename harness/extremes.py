"""The extreme probe scenes of cases/extremes/extremes.txt (issue 6, item 3): each probe a scene
pushed to a limit of the physics, and what is acceptable of it -- a run that goes through
within its criteria (energy out over energy in, overlap, bounds on columns), or a stop with
exit 1 and a message, or a largest stable step within a stated range of the estimate.  One
row per probe in reports/extremes.tsv.

A probe is one run of the runner (harness/runner.py), into <work>/extremes/<probe>, read
with stability.py's criteria (Trial, run): so it too gets resume and interrupt handling.
A limit probe (expect = limit) is instead the stability finder's bisection of the probe's
scene (stability.measure: its baseline is the scene at its own dt, its trials f x the
estimate), into the same folder; it is as expected when the largest stable f lies within
`limit = LO HI`.  So a scene that is not a catalogue case (the extreme sizes, rolling
resistance) gets a measured limit and an expectation on it.
"""
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path

from .ini import parse_file
from .runner import run_tasks
from .stability import Target, measure, run

EXTREME_KEYS = {"scene", "set", "group", "what", "expect", "energy_ratio", "e_in", "overlap_max", "bound",
                "limit"}
EXPECTS = ("stable", "stop", "limit")


@dataclass
class Probe:
    name: str
    group: str               # which physics the row probes (rows of later physics add groups)
    what: str
    scene: Path
    sets: list
    expect: str              # stable: runs through and passes its criteria;
                             # stop: ballast ends it with exit 1 and says why;
                             # limit: its largest stable dt / estimate within limit
    energy_ratio: float      # stable: E_out/E_in (last over first row of E_k + E_el) at most this
                             # (nan: not a criterion, e.g. under gravity)
    overlap_max: float       # stable: largest final overlap / smaller radius at most this
    bounds: list = field(default_factory=list)   # [(column, lo, hi)]: every row within
    line: int = 0
    e_in: float = float("nan")   # the energy put in, when the first row cannot give it (nan: first row)
    limit: tuple = ()            # expect = limit: (LO, HI), the accepted range of limit / estimate


def load_probes(path):
    """The probes of cases/extremes/extremes.txt ([probe NAME] sections)."""
    probes = []
    for sec in parse_file(path):
        if sec.kind != "probe":
            raise sec.error(f"unknown section kind '{sec.kind}' (known: probe)")
        sec.check_keys(EXTREME_KEYS)
        expect = sec.get("expect", "stable")
        if expect not in EXPECTS:
            raise sec.error(f"expect must be one of {', '.join(EXPECTS)}, not '{expect}'")
        limit = ()
        if sec.entry("limit") is not None or expect == "limit":
            if expect != "limit":
                raise sec.error("'limit = LO HI' goes with 'expect = limit'", sec.entry("limit").line)
            text = sec.require("limit")
            try:
                lo, hi = (float(x) for x in text.split())
            except ValueError:
                raise sec.error(f"limit needs 'LO HI', got '{text}'", sec.entry("limit").line) from None
            if not 0 < lo <= hi:
                raise sec.error(f"limit needs 0 < LO <= HI, got '{text}'", sec.entry("limit").line)
            limit = (lo, hi)
        bounds = []
        for e in sec.all("bound"):
            parts = e.value.split()
            try:
                bounds.append((parts[0], float(parts[1]), float(parts[2])))
            except (IndexError, ValueError):
                raise sec.error(f"bound needs 'COLUMN LO HI', got '{e.value}'", e.line) from None
        probes.append(Probe(sec.name, sec.require("group"), sec.require("what"),
                            Path(path).parent / sec.require("scene"), [e.value for e in sec.all("set")],
                            expect, sec.number("energy_ratio", float("nan")), sec.number("overlap_max", 0.1),
                            bounds, sec.line, sec.number("e_in", float("nan")), limit))
    return probes


def energy_in_out(path):
    """(E at the first row, E at the last row) of E_k + E_el in a series."""
    nan = float("nan")
    try:
        lines = Path(path).read_text().splitlines()
    except OSError:
        return nan, nan
    if len(lines) < 2:
        return nan, nan
    head = lines[0].split("\t")
    cols = [head.index(c) for c in ("Ek", "Ee") if c in head]
    if not cols:
        return nan, nan

    def energy(line):
        row = line.split("\t")
        try:
            return sum(float(row[c]) for c in cols)
        except (ValueError, IndexError):
            return nan
    return energy(lines[1]), energy(lines[-1])


def judge(probe, trial, e_in, e_out):
    """(outcome, ok): what happened, and whether it is what the probe accepts."""
    if trial.exit != 0:
        msg = trial.message or "(no message)"
        return f"stopped, exit {trial.exit}: {msg}", probe.expect == "stop" and trial.exit == 1 and bool(trial.message)
    if trial.nonfinite:
        return f"NON-FINITE output with exit 0 at {trial.nonfinite}", False
    problems = []
    ratio = e_out / e_in if e_in > 0 else float("nan")
    if not math.isnan(probe.energy_ratio) and not ratio <= probe.energy_ratio:
        problems.append(f"E_out/E_in {ratio:.4g} > {probe.energy_ratio:g}")
    if not trial.overlap_max <= probe.overlap_max and not math.isnan(trial.overlap_max):
        problems.append(f"overlap/r {trial.overlap_max:.3g} > {probe.overlap_max:g}")
    for col, lo, hi in probe.bounds:
        if col not in trial.envelope:
            problems.append(f"no column {col}")
            continue
        tlo, thi = trial.envelope[col]
        if tlo < lo or thi > hi:
            problems.append(f"{col} in [{tlo:.4g}, {thi:.4g}], outside [{lo:g}, {hi:g}]")
    if problems:
        return "ran through: " + "; ".join(problems), False
    return "ran through, within its criteria", probe.expect == "stable"


def judge_limit(probe, lim):
    """(outcome, ok) of a limit probe from its bisection (a stability.Limit)."""
    lo, hi = probe.limit
    if not math.isfinite(lim.limit):
        return f"no limit found: {lim.note or lim.cause}", False
    found = (f"limit {lim.limit:.4g} x estimate ({lim.trials} trials; unstable at {lim.unstable:.4g}: {lim.cause})"
             if math.isfinite(lim.unstable) else f"limit {lim.limit:.4g} x estimate ({lim.note})")
    if lim.limit < lo:
        return f"{found}; below {lo:g}: the estimate is NOT SAFE here", False
    if lim.limit > hi:
        return f"{found}; above {hi:g}", False
    return f"{found}; within [{lo:g}, {hi:g}]", True


EXTREME_COLUMNS = ("group", "probe", "what", "expect", "exit", "steps", "e_in", "e_out", "e_out_over_in",
                   "overlap_max", "outcome", "as_expected", "estimate", "limit_fraction", "unstable_fraction")


def run_limit_probe(batch, probe, folder):
    """The extremes.tsv row of a limit probe: the bisection of its scene into folder."""
    lim = measure(batch, Target("extremes", probe.name, probe.scene, probe.sets), folder)
    outcome, ok = judge_limit(probe, lim)
    return {"group": probe.group, "probe": probe.name, "what": probe.what, "expect": probe.expect,
            "exit": "", "steps": "", "e_in": "", "e_out": "", "e_out_over_in": "", "overlap_max": "",
            "outcome": outcome.replace("\t", " ").replace("\n", " "), "as_expected": "yes" if ok else "no",
            "estimate": f"{lim.estimate:.6g}", "limit_fraction": f"{lim.limit:.4g}",
            "unstable_fraction": f"{lim.unstable:.4g}"}


def run_probe(batch, probe, folder):
    """The extremes.tsv row of one probe, run into folder."""
    if probe.expect == "limit":
        return run_limit_probe(batch, probe, folder)
    t = run(batch, Target("extremes", probe.name, probe.scene, probe.sets), probe.sets, folder)
    e_in, e_out = energy_in_out(Path(folder) / "series.tsv")
    if not math.isnan(probe.e_in):
        e_in = probe.e_in
    outcome, ok = judge(probe, t, e_in, e_out)
    ratio = e_out / e_in if e_in and e_in > 0 else float("nan")
    return {"group": probe.group, "probe": probe.name, "what": probe.what, "expect": probe.expect,
            "exit": str(t.exit), "steps": str(t.steps), "e_in": f"{e_in:.6g}", "e_out": f"{e_out:.6g}",
            "e_out_over_in": f"{ratio:.6g}", "overlap_max": f"{t.overlap_max:.4g}",
            "outcome": outcome.replace("\t", " ").replace("\n", " "), "as_expected": "yes" if ok else "no",
            "estimate": "", "limit_fraction": "", "unstable_fraction": ""}


def run_probes(binary, probes, workdir, jobs=None, out=None, resume=False):
    """The extremes.tsv rows of the probes, in order: one runner task each, their runs in
    workdir/extremes/<probe>."""
    def task(probe):
        return lambda batch: run_probe(batch, probe, Path(workdir) / "extremes" / probe.name)
    return run_tasks([task(p) for p in probes], binary, jobs, out or sys.stdout, resume)
