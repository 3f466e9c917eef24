"""A sweep over a grid of --set points: `harness study SCENE --set ...` (study.py) on a bare
scene, and `harness sweep CASE --set ...` on one variant of a catalogue case, which adds the
case's checks.  Both run the grid through the same code (points.py: the jobs, the time keeping,
the launcher, the cost; error_cost.py: the errors, the table, the figure).

Several --set options combine as a GRID (every value of the first key with every value of the
second, ...; the first key varies slowest).  One option may COUPLE keys, --set K1,K2=V1,V2: one
axis on which both keys take each value together (a pair of materials uses the smaller δ of the
two, so a grain's and a wall's δ must move together); its point label is 'K1=V1,K2=V1'.  A key
given twice is refused, as are a value with '/' and a key with '/' or '..' (they name the
point's folder).  A point's label is 'KEY=V' for one key and 'KEY=V,KEY2=W' for several; a
case's point runs in reports/sweeps/<case>/<label>, a study's in <study>/points/P<n>.

Before any run, `ballast info` reads every point with all its overrides: a key the core does
not know or a value out of its range is refused (exit 2) with the core's message, and so is a
grid that sweeps a key which another key's value makes unused at some point (settings.dt > 0
makes settings.dt_fraction unused; `ballast info` lists such keys, from the core's table in
core/scene_keys.c): its values would all give the same run.  A grid over the time step keeps
each stage's simulated time and sets settings.force_dt = 1 (points.time_keeping).

The quantities of a grid (a study's --quantity, or `harness sweep CASE --quantity`): each
point's value and its error |q - q_ref| / |q_ref| against its reference point, the finest
point with the same values on every axis but the last (error_cost.reference_points); a table
of one row per point (points_table), a TSV of one row per point and quantity (write_points_tsv)
and a figure of each quantity's error against particle-steps (draw).

The checks of `harness sweep CASE` (those that read the variant alone): one row per check, one
column per point -- the value, its verdict and its error against the reference (|q - ref|/|ref|,
|q - ref| when ref = 0; '-' for an interval, a trend or a value that could not be computed) --
and below them each point's cost: its status, steps, particle-steps and wall-clock seconds
(run.json).  The same numbers go to reports/sweeps/<case>/sweep_<variant>.tsv, one row per
point and check, and the checks' errors against particle-steps to sweep_<variant>.svg.
"""
import itertools
from dataclasses import dataclass

from . import files, points
from .compare import RunStore, evaluate_all
from .error_cost import aligned, cost_curves, deviation, num, plot, reference_points
from .errors import CatalogueError
from .gate import fmt_number, fmt_reference

TSV_COLUMNS = ("point", "sets", "status", "steps", "particle_steps", "wall_seconds", "check", "value",
               "reference", "error", "result")
POINTS_TSV_COLUMNS = ("point", "sets", "status", "steps", "particle_steps", "wall_seconds", "quantity", "value",
                      "reference_point", "error")
# A quantity's column in the printed table is headed by its expression up to this length, else
# by q1, q2, ... with the expressions listed below the table.
SHORT_HEADER = 20
COST_AXIS = "particle-steps"


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
    out = []
    for combo in itertools.product(*axes):
        sets = [s for part in combo for s in part]
        out.append((",".join(sets), sets))
    return out


def axis_value(axis, sets):
    """The value of an axis at a point (the coupled keys share it)."""
    key = axis_keys(axis)[0]
    return next(s.split("=", 1)[1] for s in sets if s.split("=", 1)[0] == key)


def short_axis(axis, axes):
    """An axis's column header: each key's last part ('settings.dt' -> 'dt'; coupled keys with
    one last part share it), the whole axis when two axes would get the same header."""
    def short(a):
        tails = list(dict.fromkeys(k.rsplit(".", 1)[-1] for k in axis_keys(a)))
        return ",".join(tails)
    return short(axis) if [short(a) for a in axes].count(short(axis)) == 1 else axis


# ---------------------------------------------------------------- the grid's points, run

def plan(binary, scene, base, keyed, folder_of, **job):
    """(jobs, extra): one runner Job per grid point, run with base (a variant's overrides), the
    time keeping of a grid over the step (extra) and the point's sets, in folder_of(i, label);
    job: the Job's owner, expected seconds and command (points.jobs).  Every point is read by
    the core before any runs (points.refuse)."""
    swept = swept_keys(keyed)
    extra = points.time_keeping(binary, scene, base, swept)
    jobs = points.jobs([(label, sets, folder_of(i, label)) for i, (label, sets) in enumerate(grid(keyed))],
                       scene, base, extra, **job)
    points.refuse(binary, jobs, swept)
    return jobs, extra


@dataclass
class Measured:
    """A grid's points after their runs: per point (in grid order) its own sets, cost, values
    on the axes and reference point; per quantity its values and errors."""
    keyed: list
    sets: list          # [[KEY=V, ...]] of each point (without the base and time-keeping overrides)
    quantities: list
    costs: list
    values: dict        # {expr: [value or None]}
    point_values: list  # [[the value of each axis]]
    refs: list          # [index of the reference point, or None]
    errors: dict        # {expr: [|q - q_ref| / |q_ref| or None]}


def measure(keyed, jobs, quantities):
    """Each point's cost and quantities, its reference point and each quantity's error."""
    costs, values, _ = points.measure(jobs, quantities)
    sets = [s for _, s in grid(keyed)]
    point_values = [[axis_value(axis, s) for axis, _ in keyed] for s in sets]
    refs = reference_points(point_values, costs, lambda i: all(values[e][i] is not None for e in quantities))
    errors = {e: [None if refs[i] is None or v is None else deviation(v, values[e][refs[i]])
                  for i, v in enumerate(values[e])] for e in quantities}
    return Measured(keyed, sets, quantities, costs, values, point_values, refs, errors)


def points_table(m):
    """One row per point: its values on each axis, each quantity's value (its error against its
    reference point in brackets) and the point's cost; the axes and quantities named below."""
    axes = [a for a, _ in m.keyed]
    names = [e if len(e) <= SHORT_HEADER else f"q{i + 1}" for i, e in enumerate(m.quantities)]
    rows = [["point"] + [short_axis(a, axes) for a in axes] + names + ["status", "particle-steps", "wall s", "ref"]]
    for i, pv in enumerate(m.point_values):
        cells = [f"{num(m.values[e][i], '.8g')} ({num(m.errors[e][i], '.1e')})" if m.refs[i] != i
                 else f"{num(m.values[e][i], '.8g')} (ref)" for e in m.quantities]
        ref = "-" if m.refs[i] is None else f"P{m.refs[i] + 1}"
        cost = m.costs[i]
        rows.append([f"P{i + 1}"] + pv + cells + [str(cost.get("status")), num(cost.get("particle_steps"), "g"),
                                                  num(cost.get("wall_seconds"), ".3g"), ref])
    lines = aligned(rows)
    lines.append("")
    lines += [f"{short_axis(a, axes)} = {a}" for a in axes if short_axis(a, axes) != a]
    lines += [f"{n} = {e}" for n, e in zip(names, m.quantities) if n != e]
    lines.append("(error) = |q - q_ref| / |q_ref|, q_ref at the point's ref: the point of highest cost "
                 "(particle-steps) with the same values on every axis but the last")
    return "\n".join(lines)


def write_points_tsv(path, m):
    """One row per point and quantity (POINTS_TSV_COLUMNS)."""
    lines = ["\t".join(POINTS_TSV_COLUMNS)]
    for i, cost in enumerate(m.costs):
        for expr in m.quantities:
            lines.append("\t".join([f"P{i + 1}", " ".join(m.sets[i]), str(cost.get("status")),
                                    num(cost.get("steps"), "g"), num(cost.get("particle_steps"), "g"),
                                    num(cost.get("wall_seconds"), ".4g"), expr, num(m.values[expr][i], ".17g"),
                                    "-" if m.refs[i] is None else f"P{m.refs[i] + 1}",
                                    num(m.errors[expr][i], ".6g")]))
    files.make_dirs(path.parent)
    files.write_text(path, "\n".join(lines) + "\n")


def point_curves(m, suffix=""):
    """Each quantity's error against its reference point by particle-steps (the references left
    out), titled by the expression and suffix."""
    curves = cost_curves(m.quantities, m.errors, m.costs, skip=lambda i: m.refs[i] == i)
    return [(name + suffix, pts) for name, pts in curves]


def draw(folder, name, curves, ylabel):
    """NAME.svg in folder: error against particle-steps, log-log (error_cost.plot)."""
    return plot(folder, name, curves, COST_AXIS, ylabel, "right top")


# ---------------------------------------------------------------- the checks of a case's sweep

def error_of(v):
    """|q - ref| / |ref| of a verdict with a number for value and reference, else None."""
    numeric = lambda x: isinstance(x, (int, float)) and not isinstance(x, bool)
    if numeric(v.value) and numeric(v.reference):
        return deviation(float(v.value), float(v.reference))
    return None


def evaluate(checks, jobs, costs):
    """{label: (verdicts, cost)} of every point, each run standing in for the variant."""
    out = {}
    for job, cost in zip(jobs, costs):
        store = RunStore(lambda c, v, folder=job.out: folder)
        out[job.variant] = (evaluate_all(checks, store), cost)
    return out


def checks_table(labels, checks, results):
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
    return "\n".join(aligned([header] + rows))


def check_curves(labels, checks, results, costs):
    """Each check's error against its reference by particle-steps (checks with no point error
    left out)."""
    errors = {c.name: [error_of(results[label][0][i]) for label in labels] for i, c in enumerate(checks)}
    return cost_curves([c.name for c in checks], errors, costs)


def write_checks_tsv(path, jobs, checks, results):
    lines = ["\t".join(TSV_COLUMNS)]
    for job in jobs:
        verdicts, cost = results[job.variant]
        for check, v in zip(checks, verdicts):
            err = error_of(v)
            cells = [job.variant, " ".join(job.sets), str(cost.get("status")), fmt_number(cost.get("steps")),
                     fmt_number(cost.get("particle_steps")), fmt_number(cost.get("wall_seconds")), check.name,
                     fmt_number(v.value), fmt_reference(v), "-" if err is None else f"{err:.6g}", v.result]
            lines.append("\t".join(c.replace("\t", " ") for c in cells))
    files.make_dirs(path.parent)
    files.write_text(path, "\n".join(lines) + "\n")
