"""`harness sweep CASE --set KEY=V1,V2 [--set KEY2=W1,W2 ...]`: one variant run at every point
of a grid of overrides, and a table of its checks with their error and the cost of each point.
`harness study SCENE --set ...` runs the same grid on a bare scene (study.py).

Several --set options combine as a GRID (every value of the first key with every value of the
second, ...; the first key varies slowest).  One option may COUPLE keys, --set K1,K2=V1,V2: one
axis on which both keys take each value together (a pair of materials uses the smaller δ of the
two, so a grain's and a wall's δ must move together); its point label is 'K1=V1,K2=V1'.  A key given twice is refused, as are a value with
'/' and a key with '/' or '..' (they name the point's folder).  A point's label is 'KEY=V' for
one key and 'KEY=V,KEY2=W' for several; its outputs go to reports/sweeps/<case>/<label>.

Before any run, `ballast info` reads every point with all its overrides: a key the core does
not know or a value out of its range is refused (exit 2) with the core's message, and so is a
grid that sweeps a key which another key's value makes unused at some point (settings.dt > 0
makes settings.dt_fraction unused; `ballast info` lists such keys, from the core's table in
core/scene_keys.c): its values would all give the same run.

A sweep over the time step (settings.dt or settings.dt_fraction) keeps the SIMULATED time of
every stage fixed: `ballast info` of the unswept variant gives each stage's cycles and dt, and
every point runs each stage given in cycles as `stage.NAME.time = cycles x dt` (a stage given
in time already keeps it).  Without this a smaller step would cover a fraction of the time and
nearly every check would fail for that reason alone.  Such a sweep also sets
settings.force_dt = 1, as the declared error-against-cost sweeps do: a step past the stability
estimate is a point to measure, and the run-time guards say whether it went unstable.

The table has one row per check that reads the variant alone, one column per point: the value,
its verdict and its error against the reference (|q - ref|/|ref|, |q - ref| when ref = 0; '-'
for an interval, a trend or a value that could not be computed), and below them each point's
cost: its status, steps, particle-steps and wall-clock seconds (run.json).  The same numbers go
to reports/sweeps/<case>/sweep_<variant>.tsv, one row per point and check.
"""
import itertools

from . import core_info, files
from .compare import RunStore, evaluate_all
from .errors import CatalogueError
from .gate import fmt_number, fmt_reference
from .runner import Job
from .sweep import deviation, run_cost

DT_KEYS = ("settings.dt", "settings.dt_fraction")
FORCE = "settings.force_dt=1"
TSV_COLUMNS = ("point", "sets", "status", "steps", "particle_steps", "wall_seconds", "check", "value",
               "reference", "error", "result")


def parse_sets(texts):
    """['KEY=V1,V2', 'K1,K2=W1,W2', ...] -> [(AXIS, [V1, V2]), ...], AXIS the key, or the coupled
    keys 'K1,K2' (axis_keys splits them: every key of the axis takes each value together).
    Refuses a malformed option, a key with '/' or '..' and a key given twice (in any axis)."""
    out, seen = [], []
    for text in texts:
        axis, sep, values = text.partition("=")
        keys = [k.strip() for k in axis.split(",")]
        values = [v.strip() for v in values.split(",") if v.strip()]
        if not sep or not all(keys) or not values or any("/" in v for v in values):
            raise CatalogueError(f"--set needs KEY=V1,V2,... or KEY1,KEY2=V1,V2,... (no '/' in values), "
                                 f"got '{text}'")
        for key in keys:
            if "/" in key or ".." in key:
                # the key starts each point's folder name (reports/sweeps/<case>/KEY=V): a path in it
                # would put the folder elsewhere, and no scene key holds '/' or '..'
                raise CatalogueError(f"--set {key}: a key holds no '/' or '..' (it names the point's folder "
                                     f"under reports/sweeps), got '{text}'")
            if key in seen:
                raise CatalogueError(f"--set {key} given twice: give its values once, KEY=V1,V2,... "
                                     "(several --set keys combine as a grid; KEY1,KEY2=V1,V2,... moves "
                                     "two keys together)")
            seen.append(key)
        out.append((",".join(keys), values))
    return out


def axis_keys(axis):
    """The keys of one axis of parse_sets: 'K' -> ['K'], 'K1,K2' -> ['K1', 'K2']."""
    return axis.split(",")


def swept_keys(keyed):
    """Every key of every axis."""
    return [k for axis, _ in keyed for k in axis_keys(axis)]


def grid(keyed):
    """[(label, [KEY=V, ...])] of every combination, the first axis varying slowest; a coupled
    axis sets each of its keys to the same value ('K1=V,K2=V' in the label)."""
    axes = [[[f"{k}={v}" for k in axis_keys(axis)] for v in values] for axis, values in keyed]
    points = []
    for combo in itertools.product(*axes):
        sets = [s for part in combo for s in part]
        points.append((",".join(sets), sets))
    return points


def stages_of(binary, scene, sets):
    """(dt, [(stage, cycles, seconds, given_in)]) from `ballast info` of the scene (core_info.py)."""
    got = core_info.query(binary, scene, sets)
    return got["dt"], got["stages"]


def time_keeping(binary, variant):
    """The overrides that keep each stage's simulated time while dt is swept."""
    dt, stages = stages_of(binary, variant.scene, variant.sets)
    return [f"stage.{name}.time={repr(cycles * dt)}" for name, cycles, _, given in stages
            if given == "cycles" and cycles > 0] + [FORCE]


def jobs(case, variant, keyed, sweeps_root, binary):
    """One runner Job per grid point (with the time-keeping overrides of a dt sweep)."""
    extra = time_keeping(binary, variant) if any(k in DT_KEYS for k in swept_keys(keyed)) else []
    return [Job(case.name, label, variant.scene, list(variant.sets) + extra + sets,
                sweeps_root / case.name / label, case.runtime / max(len(case.variants), 1), variant.command,
                probe=bool(extra))
            for label, sets in grid(keyed)], extra


def refuse_bad_points(jobs_, keyed, binary):
    """Before any run: every point as the core reads it, with all its overrides (the variant's,
    the time-keeping ones, the point's); exit 2 for an unknown key, a value out of range or a
    swept key that another key makes unused at some point (core_info.refuse_bad_points)."""
    swept = swept_keys(keyed)
    core_info.refuse_bad_points(binary, [(job.variant, job.scene, job.sets, swept) for job in jobs_])


def error_of(v):
    """|q - ref| / |ref| of a verdict with a number for value and reference, else None."""
    numeric = lambda x: isinstance(x, (int, float)) and not isinstance(x, bool)
    if numeric(v.value) and numeric(v.reference):
        return deviation(float(v.value), float(v.reference))
    return None


def evaluate(checks, jobs_):
    """{label: (verdicts, cost)} of every point."""
    out = {}
    for job in jobs_:
        store = RunStore(lambda c, v, folder=job.out: folder)
        out[job.variant] = (evaluate_all(checks, store), run_cost(job.out))
    return out


def table(labels, checks, results):
    """The printed table: checks by points ('value VERDICT err E'), then the cost rows."""
    header = ["check", "reference", "tolerance"] + list(labels)
    rows = []
    for i, check in enumerate(checks):
        first = results[labels[0]][0][i]
        cells = []
        for label in labels:
            v = results[label][0][i]
            err = error_of(v)
            cells.append(f"{fmt_number(v.value)} {v.result}" + ("" if err is None else f" err {err:.2e}"))
        rows.append([check.name, fmt_reference(first), first.tolerance] + cells)
    for name, field in (("status", "status"), ("steps", "steps"), ("particle-steps", "particle_steps"),
                        ("wall s", "wall_seconds")):
        rows.append([f"({name})", "", ""] + [fmt_number(results[label][1].get(field)) for label in labels])
    widths = [max(len(r[j]) for r in [header] + rows) for j in range(len(header))]
    return "\n".join("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in [header] + rows)


def write_tsv(path, jobs_, checks, results):
    lines = ["\t".join(TSV_COLUMNS)]
    for job in jobs_:
        verdicts, cost = results[job.variant]
        for check, v in zip(checks, verdicts):
            err = error_of(v)
            cells = [job.variant, " ".join(job.sets), str(cost.get("status")), fmt_number(cost.get("steps")),
                     fmt_number(cost.get("particle_steps")), fmt_number(cost.get("wall_seconds")), check.name,
                     fmt_number(v.value), fmt_reference(v), "-" if err is None else f"{err:.6g}", v.result]
            lines.append("\t".join(c.replace("\t", " ") for c in cells))
    files.make_dirs(path.parent)
    files.write_text(path, "\n".join(lines) + "\n")
