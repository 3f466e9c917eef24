"""Stability limits (issue 6, item 3): the largest stable time step of every catalogue
variant, found by bisection, against ballast's critical-step estimate.

Limit of one variant.  Every trial runs the variant's scene with its `set =` overrides,
`settings.dt = f x estimate` (the estimate that `bin/ballast info` prints for that
variant; an explicit dt of the case is replaced the same way) and every stage's cycles
scaled by dt_case / dt_trial, so that each trial covers the same physical time as the
case, with at most CYCLE_CAP cycles per stage (the bounded run).  A stage's cycles at
dt_case are those `ballast info` prints (core_info.py), whether the stage is given in
cycles or in time (`time = T`), in the scene or by an override; a trial gives each stage
in cycles (`stage.NAME.cycles`, which replaces a `time`), and writes its series rows at
the case's simulated times (output_every scaled the same way).  A trial is unstable when
any of these holds:

  - ballast exits non-zero (1 = unstable: today a non-finite state; later also the
    overlap and runaway-energy guards of core/sim.c);
  - a series value is not finite;
  - the largest E_k + E_el of the series falls below the baseline's over ENERGY_LOSS
    (spurious sliding has dissipated what the case stores: a stable step resolves the
    same loading), or it, or the largest E_k alone, exceeds ENERGY_GROWTH times that of
    the baseline (the variant at its own dt, with the same
    cycle cap).  E_k alone catches an oscillation that Coulomb sliding keeps bounded
    (a shear-rotation mode past its limit in a frictional quasi-static test, where E_k
    is a small part of the energy); or
  - the range (min, max over the run) of some probe of the series moves by more than
    DEVIATION of the baseline's largest magnitude of that probe: a stable run covers
    the same physical time with O((omega dt)^2) errors in its slow motions, while an
    instability that sliding or a stop rule keeps finite still shows in the forces or
    in the number of sliding contacts (phases are not compared: the leapfrog's
    frequency error shifts them legitimately); or
  - the largest overlap / smaller radius of the final contacts exceeds
    max(OVERLAP_GROWTH x baseline, baseline + OVERLAP_SLACK).

An unstable leapfrog grows geometrically (by 1.3 per step at 1 % past the limit), so
these bounds are not fine-tuned: the energy of a stable run near the limit differs from
the baseline's by O((omega dt)^2) < 4x only through the staggered velocities.

The bisection brackets [stable, unstable] starting at f = 1, moving by STEP, then
halves the bracket until hi/lo <= 1 + TOLERANCE.  The limit reported is the largest
stable f: the measured limit over the estimate.  A safe and tight estimate has it in
[1, 1.25].

Every trial is a run of the runner (harness/runner.py): a variant's bisection is one task
of run_tasks, which launches its trials one after another into
<work>/limits/<case>/<variant>/ (base, trial01, trial02, ...).  So they get the runner's run folders and records, its interrupt
handling (Ctrl-C stops the trials running and starts no other) and --resume (a trial
whose folder holds a complete run of the same identity is not run again); -j sets how
many variants are bisected side by side, which changes no result.

The extreme probes (extremes.py) use the same runs and criteria; write_tsv, merge_tsv
and read_tsv below keep both tables (stability.tsv, extremes.tsv).
"""
import json
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path

from . import core_info, files
from .errors import CatalogueError
from .runner import Job, run_tasks

ENERGY_GROWTH = 4.0
ENERGY_LOSS = 1.5
STEP = 1.25              # the bracket search moves by this factor (not 2: an unstable band
                         # that friction or a stop rule ends can lie between stable steps)
DEVIATION = 1.0
OVERLAP_GROWTH = 2.0
OVERLAP_SLACK = 0.05
TOLERANCE = 0.01
CYCLE_CAP = 20000
F_MIN, F_MAX = 1 / 64, 64


# ---------------------------------------------------------------- targets

@dataclass
class Target:
    """One scene with its overrides: a catalogue variant or an extreme probe."""
    case: str
    variant: str
    scene: Path
    sets: list


def targets_for(cases, one_per_case=False):
    """Every DEM variant (command = run) of the cases; or only the first of each case.  A case
    that says `stability = no` has none (its motion is prescribed: no limit to find).  Of an
    [ensemble] only the first realisation: the others differ from it by a seed alone."""
    out = []
    for c in cases:
        if not c.stability:
            continue
        firsts = {e.name: e.members[0] for e in c.ensembles}
        runs = [Target(c.name, v.name, v.scene, list(v.sets)) for v in c.variants
                if v.command == "run" and (not v.ensemble or firsts[v.ensemble] == v.name)]
        out += runs[:1] if one_per_case else runs
    return out


# ---------------------------------------------------------------- ballast

def info(batch, scene, sets):
    """`ballast info` of a scene (asked through the runner's batch): estimate (the bound),
    single (C&S 2 sqrt(m/k)), dt, output_every and stages [(name, cycles)] (core_info.py)."""
    cmd = core_info.command(batch.binary, scene, sets)
    returncode, stdout, stderr = batch.ask(cmd)
    if returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {returncode}: {stderr.strip()}")
    return parse_info(stdout)


def parse_info(text):
    """The numbers of `ballast info` the bisection needs, and each stage's cycles at the
    scene's own dt as the core resolves them: a stage given in cycles or in time (`time =
    T`), in the file or by an override, alike.  Never read from the scene text, which
    knows neither the dt a stage in time is divided by nor what an override replaced."""
    try:
        got = core_info.parse(text)
    except CatalogueError as exc:
        raise RuntimeError(str(exc)) from None
    if math.isnan(got["estimate"]) or got["output_every"] is None:
        raise RuntimeError(f"cannot read the estimate and the output interval from ballast info:\n{text}")
    return {"estimate": got["estimate"], "single": got["single"], "dt": got["dt"],
            "output_every": got["output_every"],
            "stages": [(name, cycles) for name, cycles, _, _ in got["stages"]]}


def scaled_cycles(stages, dt_case, dt_trial, cap=CYCLE_CAP):
    """Overrides giving each stage the same physical time at dt_trial (at least one cycle
    for a stage that had any; at most cap); stages: [(name, cycles at dt_case)] from info()."""
    out = []
    for name, cycles in stages:
        n = 0 if cycles == 0 else max(1, min(cap, int(round(cycles * dt_case / dt_trial))))
        out.append(f"stage.{name}.cycles={n}")
    return out


def scaled_output(output_every, dt_case, dt_trial):
    """The override giving a trial's series rows the simulated times of the case's (every
    output_every cycles at dt_case; at least every cycle).  The energy and envelope criteria
    read the rows: a trial at 10 x the case's dt with the case's output_every = 500 would
    write a row every 0.5 s where the case wrote one every 0.05 s, miss an impact's peak
    between two rows, and be called unstable for energy lost that it never lost."""
    return f"settings.output_every={max(1, int(round(output_every * dt_case / dt_trial)))}"


@dataclass
class Trial:
    exit: int
    message: str = ""
    steps: int = 0
    energy_max: float = float("nan")   # largest E_k + E_el of the series
    kinetic_max: float = float("nan")  # largest E_k of the series
    overlap_max: float = float("nan")   # largest overlap / smaller radius, final contacts
    nonfinite: str = ""                 # first non-finite series value: 'cycle C column K'
    envelope: dict = field(default_factory=dict)   # column -> (min, max) over the series


def run(batch, target, sets, folder):
    """Run the target's scene once with sets, through the runner's batch, into folder; read
    what the criteria need.  A folder the harness cannot write is its WriteError (exit 3)."""
    folder = Path(folder)
    outcome = batch.launch(Job(target.case, target.variant, target.scene, list(sets), folder))
    if outcome.io_error:
        raise outcome.io_error
    t = Trial(outcome.returncode, _stderr(folder))
    try:
        meta = json.loads((folder / "run.json").read_text())
        t.steps = int(meta.get("steps", 0))
        t.message = meta.get("message", "") or t.message
    except (OSError, ValueError):
        pass
    t.energy_max, t.kinetic_max, t.nonfinite = series_energy(folder / "series.tsv")
    t.envelope = series_envelope(folder / "series.tsv")
    t.overlap_max = largest_overlap(folder / "discs.tsv", folder / "contacts.tsv")
    return t


def _stderr(folder):
    """What ballast said on stderr (the runner keeps it as ballast.stderr), stripped."""
    try:
        return (Path(folder) / "ballast.stderr").read_text(encoding="utf-8", errors="replace").strip()
    except OSError:
        return ""


def series_energy(path):
    """(largest E_k + E_el, largest E_k, first non-finite value) of a series.tsv."""
    nan = float("nan")
    try:
        lines = Path(path).read_text().splitlines()
    except OSError:
        return nan, nan, ""
    if not lines:
        return nan, nan, ""
    head = lines[0].split("\t")
    cols = [head.index(c) for c in ("Ek", "Ee") if c in head]
    ek = head.index("Ek") if "Ek" in head else None
    best, kin, bad = nan, nan, ""
    for line in lines[1:]:
        row = line.split("\t")
        try:
            vals = [float(x) for x in row]
        except ValueError:
            vals = [nan] * len(row)
        if not bad:
            for k, v in enumerate(vals):
                if not math.isfinite(v):
                    bad = f"cycle {row[0]} column {head[k] if k < len(head) else k}"
                    break
        if cols:
            e = sum(vals[c] for c in cols)
            if math.isfinite(e):
                best = e if math.isnan(best) else max(best, e)
        if ek is not None and math.isfinite(vals[ek]):
            kin = vals[ek] if math.isnan(kin) else max(kin, vals[ek])
    return best, kin, bad


def series_envelope(path):
    """{column: (min, max)} over the finite values of every probe column of a series.tsv."""
    try:
        lines = Path(path).read_text().splitlines()
    except OSError:
        return {}
    if not lines:
        return {}
    head = lines[0].split("\t")
    env = {}
    for line in lines[1:]:
        for name, x in zip(head[2:], line.split("\t")[2:]):
            try:
                v = float(x)
            except ValueError:
                continue
            if math.isfinite(v):
                lo, hi = env.get(name, (v, v))
                env[name] = (min(lo, v), max(hi, v))
    return env


def envelope_deviation(trial, base):
    """(column, deviation) of the probe whose range moved most: max(|min_t - min_b|,
    |max_t - max_b|) / its scale, the scale being max(|min_b|, |max_b|) but at least
    1e-9 of the largest scale of the series (so a column that is zero to round-off in
    the baseline does not divide by nothing)."""
    scales = {c: max(abs(lo), abs(hi)) for c, (lo, hi) in base.items()}
    floor = 1e-9 * max(scales.values(), default=0)
    worst = ("", 0.0)
    for c, (lo, hi) in base.items():
        if c not in trial:
            continue
        tlo, thi = trial[c]
        scale = max(scales[c], floor)
        if scale <= 0:
            continue
        dev = max(abs(tlo - lo), abs(thi - hi)) / scale
        if dev > worst[1]:
            worst = (c, dev)
    return worst


def largest_overlap(discs, contacts):
    """Largest overlap / smaller radius over the final contacts.  The contact point of
    contacts.tsv lies R_a - delta/2 from the centre of a (C&S; halfway between the
    surfaces), so delta = 2 (R_a - |p - x_a|)."""
    try:
        dl = Path(discs).read_text().splitlines()
        cl = Path(contacts).read_text().splitlines()
    except OSError:
        return float("nan")
    if not dl or not cl:
        return float("nan")
    dh = dl[0].split("\t")
    ix, iy, ir, iname = dh.index("x"), dh.index("y"), dh.index("r"), dh.index("name")
    disc = {}
    for line in dl[1:]:
        f = line.split("\t")
        disc[f[iname]] = (float(f[ix]), float(f[iy]), float(f[ir]))
    ch = cl[0].split("\t")
    ca, cb, cx, cy = ch.index("a"), ch.index("b"), ch.index("x"), ch.index("y")
    best = 0.0
    for line in cl[1:]:
        f = line.split("\t")
        if f[ca] not in disc:
            continue
        xa, ya, ra = disc[f[ca]]
        delta = 2 * (ra - math.hypot(float(f[cx]) - xa, float(f[cy]) - ya))
        r = min(ra, disc[f[cb]][2]) if f[cb] in disc else ra
        if math.isfinite(delta):
            best = max(best, delta / r)
        else:
            return float("inf")
    return best


def verdict(trial, base):
    """'' if the trial is stable against the baseline, else why not."""
    if trial.exit != 0:
        return f"exit {trial.exit}: {trial.message}"[:200]
    if trial.nonfinite:
        return f"non-finite series value at {trial.nonfinite}"
    if math.isfinite(base.energy_max) and base.energy_max > 0:
        if not math.isfinite(trial.energy_max) or trial.energy_max > ENERGY_GROWTH * base.energy_max:
            return f"energy {trial.energy_max:.4g} > {ENERGY_GROWTH:g} x baseline {base.energy_max:.4g}"
        if trial.energy_max < base.energy_max / ENERGY_LOSS:
            return f"energy {trial.energy_max:.4g} < baseline {base.energy_max:.4g} / {ENERGY_LOSS:g}"
    if math.isfinite(base.kinetic_max) and base.kinetic_max > 0:
        if not math.isfinite(trial.kinetic_max) or trial.kinetic_max > ENERGY_GROWTH * base.kinetic_max:
            return f"E_k {trial.kinetic_max:.4g} > {ENERGY_GROWTH:g} x baseline {base.kinetic_max:.4g}"
    col, dev = envelope_deviation(trial.envelope, base.envelope)
    if dev > DEVIATION:
        lo, hi = trial.envelope[col]
        blo, bhi = base.envelope[col]
        return f"probe {col} range [{lo:.4g}, {hi:.4g}], baseline [{blo:.4g}, {bhi:.4g}]"
    if math.isfinite(base.overlap_max):
        bound = max(OVERLAP_GROWTH * base.overlap_max, base.overlap_max + OVERLAP_SLACK)
        if not trial.overlap_max <= bound:
            return f"overlap/r {trial.overlap_max:.4g} > {bound:.4g}"
    return ""


# ---------------------------------------------------------------- bisection

@dataclass
class Limit:
    case: str
    variant: str
    estimate: float          # the bound ballast uses
    single: float            # C&S 2 sqrt(m/k)
    dt_case: float
    limit: float = float("nan")      # largest stable f (x estimate)
    unstable: float = float("nan")   # smallest unstable f seen
    cause: str = ""          # why the first unstable trial above the limit failed
    trials: int = 0
    note: str = ""
    log: list = field(default_factory=list)

    @property
    def case_fraction(self):
        return self.dt_case / self.estimate

    @property
    def single_ratio(self):
        """measured limit over the single-spring estimate."""
        return self.limit * self.estimate / self.single


def measure(batch, target, folder, cap=CYCLE_CAP, tolerance=TOLERANCE):
    """The largest stable dt fraction of one target; its runs go to folder (base, trial01, ...:
    the same names in the same order at every attempt, which is what lets --resume keep them)."""
    est = info(batch, target.scene, target.sets)
    lim = Limit(target.case, target.variant, est["estimate"], est["single"], est["dt"])
    stages = est["stages"]
    folder = Path(folder)
    base_sets = target.sets + scaled_cycles(stages, 1, 1, cap)
    base = run(batch, target, base_sets, folder / "base")
    if base.exit != 0:
        lim.note = f"baseline (its own dt) fails: exit {base.exit}: {base.message}"
        return lim

    def stable(f):
        dt = f * lim.estimate
        # force_dt: a trial above the estimate is the point of the bisection (ballast refuses
        # such a step otherwise)
        sets = target.sets + [f"settings.dt={dt!r}", "settings.force_dt=1",
                              scaled_output(est["output_every"], lim.dt_case, dt)] + \
            scaled_cycles(stages, lim.dt_case, dt, cap)
        t = run(batch, target, sets, folder / f"trial{lim.trials + 1:02d}")
        why = verdict(t, base)
        lim.trials += 1
        lim.log.append((f, why or "stable"))
        return why

    f = 1.0
    why = stable(f)
    if not why:
        lo, hi, cause = f, None, ""
        while f < F_MAX:
            f *= STEP
            why = stable(f)
            if why:
                hi, cause = f, why
                break
            lo = f
    else:
        hi, lo, cause = f, None, why
        while f > F_MIN:
            f /= STEP
            why = stable(f)
            if not why:
                lo = f
                break
            hi, cause = f, why
    if lo is None or hi is None:
        lim.limit = lo if lo is not None else float("nan")
        lim.note = "no unstable step up to f = %g" % F_MAX if hi is None else "unstable down to f = %g" % F_MIN
        return lim
    while hi / lo > 1 + tolerance:
        mid = math.sqrt(lo * hi)
        why = stable(mid)
        if why:
            hi, cause = mid, why
        else:
            lo = mid
    lim.limit, lim.unstable, lim.cause = lo, hi, cause
    return lim


def measure_all(binary, targets, workdir, jobs=None, cap=CYCLE_CAP, tolerance=TOLERANCE, out=None, resume=False):
    """The Limit of every target, one bisection task each (runner.run_tasks, jobs side by side),
    their runs under workdir/limits/<case>/<variant>; out gets one line per target as it ends."""
    def task(target):
        folder = Path(workdir) / "limits" / target.case / target.variant
        return lambda batch: measure(batch, target, folder, cap, tolerance)

    def done(i, lim):
        if out:
            print(f"  {lim.case}/{lim.variant}: limit {lim.limit:.4g} x estimate "
                  f"({lim.trials} trials){' ' + lim.note if lim.note else ''}", file=out, flush=True)

    return run_tasks([task(t) for t in targets], binary, jobs, out or sys.stdout, resume, done)


LIMIT_COLUMNS = ("case", "variant", "dt_case", "estimate", "single_spring", "single_over_estimate",
                 "case_fraction", "limit_fraction", "limit_over_single", "unstable_fraction",
                 "in_target", "trials", "cause", "note")


def in_target(f):
    """The estimate is safe (f >= 1) and tight (f <= 1.25)."""
    return math.isfinite(f) and 1.0 <= f <= 1.25


def limit_rows(limits):
    rows = []
    for L in limits:
        rows.append({
            "case": L.case, "variant": L.variant, "dt_case": f"{L.dt_case:.6g}",
            "estimate": f"{L.estimate:.6g}", "single_spring": f"{L.single:.6g}",
            "single_over_estimate": f"{L.single / L.estimate:.4g}",
            "case_fraction": f"{L.case_fraction:.4g}", "limit_fraction": f"{L.limit:.4g}",
            "limit_over_single": f"{L.single_ratio:.4g}", "unstable_fraction": f"{L.unstable:.4g}",
            "in_target": "yes" if in_target(L.limit) else "no", "trials": str(L.trials),
            "cause": L.cause.replace("\t", " ").replace("\n", " "),
            "note": L.note.replace("\t", " ").replace("\n", " ")})
    return rows


def write_tsv(rows, columns, path):
    """The table, written whole (files.write_text)."""
    path = Path(path)
    files.make_dirs(path.parent)
    files.write_text(path, "\t".join(columns) + "\n" +
                     "".join("\t".join(str(r.get(c, "")) for c in columns) + "\n" for r in rows))


def merge_tsv(rows, columns, path, key):
    """Write rows into the table at path: a row replaces the one with the same key
    columns, in place; new keys are appended.  So `stability CASE` updates one case."""
    path = Path(path)
    old = read_tsv(path) if path.exists() else []
    new = {tuple(r[k] for k in key): r for r in rows}
    merged = [new.pop(tuple(r.get(k) for k in key), r) for r in old]
    merged += [r for r in rows if tuple(r[k] for k in key) in new]
    write_tsv(merged, columns, path)


def read_tsv(path):
    lines = Path(path).read_text(encoding="utf-8").splitlines()
    if not lines:
        return []
    head = lines[0].split("\t")
    return [dict(zip(head, line.split("\t"))) for line in lines[1:]]
