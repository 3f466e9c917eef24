"""The points of a sweep or a refinement, their runs, their cost and their quantities: the one
implementation that `harness study` (study.py), `harness sweep CASE --set` (sweep_grid.py) and
the declared [sweep] sections of `harness cost` / `make validate` (sweep.py) share.

A point is (label, sets, folder): the overrides that make it, given after the scene's base
overrides (a catalogue variant's own; none for a bare scene), and the folder its run goes to.
Which points a sweep has is its caller's: the levels h, h f, h f^2 ... of a study, the grid of
--set options (sweep_grid.grid), the factors of a declared sweep (sweep_spec.Sweep.sets).

  * time_keeping(): points that change the step (settings.dt or settings.dt_fraction) keep
    each stage's SIMULATED time: `ballast info` of the scene with its base overrides gives each
    stage's cycles and dt, and every point runs each stage given in cycles as
    `stage.NAME.time = cycles x dt` (a stage given in time keeps it already); they also set
    settings.force_dt = 1: a step past the stability estimate is a point to measure, and the
    run-time guards say if it went unstable.  Without this a smaller step would cover a
    fraction of the time.  (A declared sweep states its cycles itself, `scale =`, and always
    forces the step: sweep_spec.py.)
  * jobs(): one runner Job per point; refuse(): every point read by `ballast info` before any
    runs (core_info.refuse_bad_points); launch(): runner.run_all (parallel, progress,
    --resume keeps every complete run of the same identity), and OSError (exit 3) when a run
    folder could not be prepared or recorded.
  * run_cost(): a run's cost from run.json; measure(): each point's cost and each quantity's
    value (compare.evaluate over the run's outputs).
"""
from pathlib import Path

from . import core_info
from .compare import evaluate
from .errors import EvalError, RunProblem
from .runner import Job, run_all, unrecorded
from .tables import load_run, read_run_json

DT_KEYS = ("settings.dt", "settings.dt_fraction")
FORCE = "settings.force_dt=1"


def time_keeping(binary, scene, base, swept):
    """The overrides that keep each stage's simulated time when a swept key sets the step; []
    when none does."""
    if not any(k in DT_KEYS for k in swept):
        return []
    info = core_info.query(binary, scene, list(base))
    return [f"stage.{name}.time={cycles * info['dt']!r}" for name, cycles, _, given in info["stages"]
            if given == "cycles" and cycles > 0] + [FORCE]


def jobs(points, scene, base=(), extra=(), owner="study", expected=0.0, command="run", probe=None):
    """One runner Job per point (label, sets, folder), run with base (a variant's overrides),
    then extra (the time keeping), then the point's sets.  probe: a point past a stability limit
    is a measured limit, not a failure (runner.py); by default when extra keeps the time."""
    return [Job(owner, label, scene, list(base) + list(extra) + list(sets), Path(folder), expected, command,
                probe=bool(extra) if probe is None else probe)
            for label, sets, folder in points]


def refuse(binary, jobs_, swept):
    """Before any run: every point as the core reads it, with all its overrides; exit 2 for an
    unknown key, a value out of range or a swept key that another key makes unused there."""
    core_info.refuse_bad_points(binary, [(job.variant, job.scene, job.sets, swept) for job in jobs_])


def launch(jobs_, binary, workers, out, resume=False, **options):
    """Run the points (runner.run_all, with its other options); their Outcomes.  An OSError naming the first run folder
    the harness could not prepare or record (the command exits 3 with that line), and how many
    more: no table is made of runs that were not recorded."""
    outcomes = run_all(jobs_, binary, workers, out, resume=resume, **options)
    if unrecorded(outcomes):
        raise OSError(unrecorded(outcomes))
    return outcomes


def run_cost(folder):
    """{status, steps, n_discs, particle_steps, wall_seconds} from run.json (None where absent),
    and 'unsettled': the stages that have a stop rule but ran to their cycle limit."""
    try:
        info = read_run_json(folder)
    except RunProblem as problem:
        return {"status": f"no run.json ({problem})", "steps": None, "n_discs": None,
                "particle_steps": None, "wall_seconds": None, "unsettled": []}
    steps, n = info.get("steps"), info.get("n_discs")
    unsettled = [st.get("name", "?") for st in info.get("stages", []) or []
                 if isinstance(st, dict) and st.get("stop_rule") and not st.get("stopped")]
    return {"status": info.get("status", "?"), "steps": steps, "n_discs": n,
            "particle_steps": steps * n if isinstance(steps, int) and isinstance(n, int) else None,
            "wall_seconds": info.get("wall_seconds"), "unsettled": unsettled}


def value_of(expr, folder):
    """(value, '') of a quantity in the run at folder, or (None, why)."""
    try:
        return evaluate(expr, load_run(folder)), ""
    except (RunProblem, EvalError) as exc:
        return None, str(exc)


def measure(jobs_, quantities):
    """(costs, values, why): each point's run_cost, {expr: [its value at each point, None where
    there is none]} and {expr: why the first missing value is missing, '' when none is}."""
    costs = [run_cost(job.out) for job in jobs_]
    values, why = {}, {}
    for expr in quantities:
        got = [value_of(expr, job.out) for job in jobs_]
        values[expr] = [v for v, _ in got]
        why[expr] = next((w for v, w in got if v is None), "")
    return costs, values, why
