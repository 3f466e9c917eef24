"""Error against cost: the declared parameter sweeps of the catalogue (issue 6, item 1).

A case declares its sweeps in case.txt, one [sweep NAME] section per swept parameter (keys in
sweep_spec.py).

The default point of a curve (factor 1) is the variant's own run of the default tier
(reports/runs/<case>/<variant>), unless the sweep has `set =` overrides: then factor 1 is a
point of its own, run with the overrides (reports/sweeps/<case>/<sweep>_x1), and the curve
is labelled by the sweep's name (e.g. one curve per integrator).  The swept runs go to
reports/sweeps/<case>/<sweep>_x<factor>.

A point whose run failed (status unstable: the overlap budget or energy runaway guard stopped
it, or no run.json) has no error; its row says so (status, note = the run's message) and the
report draws it as "unstable" at the top of the diagram, at the cost it spent before stopping.

The error of a run (one number, documented in docs/error-against-cost.md) is the largest of its error terms:

  * a check of the case (reference/*.ref) of kind analytic, exact or paper with a point
    reference (tolerance abs, rel or ratio): |q - ref| / |ref|, where q is the check's
    quantity (for ratio: quantity / other); |q - ref| when ref = 0.  It is evaluated with the
    check machinery of compare.py, the swept run standing in for the variant.  Eligible are
    the checks that read the variant and, besides it, only reference solutions (command =
    exact, which no sweep changes).  A check that reads another DEM variant (a ratio or trend
    between runs, or series()/contact_error() of a DEM sibling) relates two runs and is left
    out: found before any run for ratio/trend, and at evaluation for siblings read inside an
    expression (the term is then dropped from the whole curve and a note says so).
    Interval and trend checks have no point reference and never count; nor do regressions.
  * each `error =` expression: |value|.
  * each `converge =` expression q (a scalar of the run): |q - q_f| / |q_f| (|q - q_f| when
    q_f = 0), where q_f is the same quantity of the FINEST point of the same sweep
    (error_cost.finest_index, as `harness study --set` picks its reference point: status ok,
    every converge quantity measured, the most particle-steps, the last on a tie).  This is
    self-convergence: an error against the finest swept run, not against a reference; it is
    meaningful only for sweeps whose most expensive run is the most accurate (dt, stop
    tolerances).  The finest point itself has no such term (its note says so).

Cost is particle-steps = steps x n_discs from run.json (wall-clock seconds are recorded too).

This module is the catalogue's layer: which points a [sweep] declares, its error terms from the
references, cost.tsv and the cheapest setting per tolerance.  The points' jobs, their launch
(`run_declared` is given points.launch), their cost (points.run_cost), the relative deviation
and the finest point (error_cost.py) are the machinery `harness study` and `harness sweep CASE`
run through as well; the report (harness/report/cost_plot.py) draws cost.tsv.
"""
import json
from pathlib import Path

from . import core_info, files
from .compare import RunStore, quantity_in
from .error_cost import deviation, finest_index
from .errors import EvalError, IniError, RunProblem
from .points import FORCE, jobs as point_jobs, run_cost
from .sweep_spec import number
from .tables import load_run, read_run_json

POINT_TOLERANCES = ("abs", "rel", "ratio")
ERROR_KINDS = ("analytic", "exact", "paper")
TOLERANCES = (1e-2, 1e-3, 1e-4)
COST_COLUMNS = ("sweep", "factor", "sets", "status", "steps", "n_discs", "particle_steps", "wall_seconds",
                "error", "worst", "note")


def validate(cases, checks):
    """Every sweep names a run variant of its case and has something to measure its error by."""
    for case in cases:
        names = [s.name for s in case.sweeps]
        for sweep in case.sweeps:
            where = lambda msg: IniError(sweep.path, sweep.line, f"sweep '{sweep.name}' of case '{case.name}': {msg}")
            if names.count(sweep.name) > 1:
                raise where("defined twice")
            variant = case.variant(sweep.variant)
            if variant is None:
                raise where(f"no variant '{sweep.variant}' (has: {', '.join(case.variant_names())})")
            if variant.command != "run":
                raise where(f"variant '{sweep.variant}' has command = {variant.command}: only DEM runs are swept")
            mine = {c.name: c for c in checks if c.case == case.name}
            for name in sweep.checks:
                if name not in mine:
                    raise where(f"no check '{name}' in the references of the case")
                why = ineligible(mine[name], sweep.variant, case)
                if why:
                    raise where(f"check '{name}' cannot measure the error: {why}")
            if not terms_of(sweep, case, checks)[0] and not sweep.errors and not sweep.converge:
                raise where(f"nothing measures the error: no eligible check of variant '{sweep.variant}' "
                            "(kind analytic/exact/paper, tolerance abs/rel/ratio), no 'error =' "
                            "and no 'converge ='")


def ineligible(check, variant, case):
    """Why check cannot be an error term of a run of variant ('' when it can)."""
    if check.kind not in ERROR_KINDS:
        return f"kind {check.kind} (only {', '.join(ERROR_KINDS)} references count)"
    if check.tolerance not in POINT_TOLERANCES:
        return f"tolerance {check.tolerance} has no point reference"
    if variant not in check.run_variants:
        return f"it is evaluated in {check.variant_label}, not {variant}"
    others = [v for v in check.run_variants if v != variant and case.variant(v).command != "exact"]
    if others:
        return f"it also reads the DEM variant(s) {', '.join(others)}"
    return ""


def terms_of(sweep, case, checks):
    """(the checks that make up the error, the names of eligible checks left out by `checks =`)."""
    mine = [c for c in checks if c.case == case.name and not ineligible(c, sweep.variant, case)]
    if sweep.no_checks:
        return [], [c.name for c in mine]
    if sweep.checks:
        return [c for c in mine if c.name in sweep.checks], [c.name for c in mine if c.name not in sweep.checks]
    return mine, []


# ---------------------------------------------------------------- the error of one run

class _Recording(RunStore):
    """A RunStore for one point: the variant from its own folder, every other from the default runs;
    remembers which other variants an evaluation read.  `loaded` (folder -> Run or RunProblem) is
    shared between the stores of a case, so a reference solution is read once."""

    def __init__(self, variant, folder, runs_root, loaded):
        self.read, self._loaded = set(), loaded

        def locate(c, v):
            if v == variant:
                return Path(folder)
            self.read.add(v)
            return Path(runs_root) / c / v
        super().__init__(locate)

    def get(self, case, variant):
        folder = self.locate(case, variant)
        if folder not in self._loaded:
            try:
                self._loaded[folder] = load_run(folder)
            except RunProblem as problem:
                self._loaded[folder] = problem
        found = self._loaded[folder]
        if isinstance(found, RunProblem):
            raise found
        return found


def term_errors(case, variant, folder, runs_root, terms, errors, loaded=None):
    """{term name: error or an EvalError/RunProblem message (str)}, and {term: DEM siblings it read}."""
    out, siblings, loaded = {}, {}, {} if loaded is None else loaded
    for check in terms:
        store = _Recording(variant, folder, runs_root, loaded)
        try:
            q = quantity_in(store, case.name, variant, check.quantity)
            if check.tolerance == "ratio":
                other = quantity_in(store, case.name, check.other_variant, check.other)
                if other == 0:
                    raise EvalError(f"other quantity '{check.other}' is zero")
                q = q / other
            out[check.name] = deviation(q, check.value)
        except (RunProblem, EvalError) as exc:
            out[check.name] = str(exc)
        siblings[check.name] = _dem(case, store.read)
    for expr in errors:
        store = _Recording(variant, folder, runs_root, loaded)
        try:
            out[expr] = abs(quantity_in(store, case.name, variant, expr))
        except (RunProblem, EvalError) as exc:
            out[expr] = str(exc)
        siblings[expr] = _dem(case, store.read)
    return out, siblings


CONVERGE = "vs finest: "      # the name of a self-convergence term: CONVERGE + expression


def converge_values(case, variant, folder, runs_root, exprs, loaded=None):
    """{expression: its value in the run at folder, or a message (str)} for `converge =`."""
    out, loaded = {}, {} if loaded is None else loaded
    for expr in exprs:
        store = _Recording(variant, folder, runs_root, loaded)
        try:
            out[expr] = quantity_in(store, case.name, variant, expr)
        except (RunProblem, EvalError) as exc:
            out[expr] = str(exc)
    return out


def converge_terms(values, finest):
    """{CONVERGE + expr: |q - q_f| / |q_f| or a message}: a point's values against the finest's."""
    out = {}
    for expr, q in values.items():
        ref = finest.get(expr, "the finest point has no value")
        if isinstance(q, str):
            out[CONVERGE + expr] = q
        elif isinstance(ref, str):
            out[CONVERGE + expr] = f"finest point: {ref}"
        else:
            out[CONVERGE + expr] = deviation(q, ref)
    return out


def _dem(case, variants):
    return sorted(v for v in variants if case.variant(v) is None or case.variant(v).command != "exact")


def run_error(by_term, dropped=()):
    """(error, the term giving it, note): the largest term; None when a term could not be evaluated."""
    kept = {k: v for k, v in by_term.items() if k not in dropped}
    bad = {k: v for k, v in kept.items() if isinstance(v, str)}
    if bad:
        name = next(iter(bad))
        return None, name, f"{name}: {bad[name]}"
    if not kept:
        return None, "", "no error term"
    worst = max(kept, key=lambda k: kept[k])
    return kept[worst], worst, ""


# ---------------------------------------------------------------- running and tabulating

def jobs(case, sweeps_root):
    """One runner Job per declared point of the case (points.jobs), after the variant's overrides.
    force_dt: a point past the stability estimate is part of the trade to measure (ballast refuses
    such a step otherwise); it runs, and the guards say if it is unstable (probe)."""
    out = []
    for sweep in case.sweeps:
        variant = case.variant(sweep.variant)
        out += point_jobs([(sweep.label(f), sweep.sets(f) + [FORCE], Path(sweeps_root) / case.name / sweep.label(f))
                            for f in sweep.run_factors()], variant.scene, variant.sets, owner=case.name,
                           expected=case.runtime / max(len(case.variants), 1), command=variant.command, probe=True)
    return out


def core_points(case, sweeps_root):
    """(label, scene, sets, swept keys) of every declared point, for core_info.refuse_bad_points:
    a key the core does not know, a value out of range, or a swept key that another key makes
    unused is refused before any point runs."""
    swept = {s.name: [k for k, _ in s.keys + s.scale] for s in case.sweeps}
    labels = {s.label(f): s.name for s in case.sweeps for f in s.run_factors()}
    return [(f"{case.name}/{j.variant}", j.scene, j.sets, swept[labels[j.variant]]) for j in jobs(case, sweeps_root)]


def points(case, checks, runs_root, sweeps_root):
    """Rows of cost.tsv: per sweep the default run (factor 1; with `set =`, its own run) and every
    swept point."""
    rows, loaded = [], {}
    for sweep in case.sweeps:
        terms, _ = terms_of(sweep, case, checks)
        pts = [] if sweep.fixed else [(1.0, Path(runs_root) / case.name / sweep.variant, [])]
        pts += [(f, Path(sweeps_root) / case.name / sweep.label(f), sweep.sets(f)) for f in sweep.run_factors()]
        costs = [run_cost(folder) for _, folder, _ in pts]
        evaluated = [(f, folder, sets, *term_errors(case, sweep.variant, folder, runs_root, terms, sweep.errors,
                                                     loaded))
                     for f, folder, sets in pts]
        dropped = sorted({t for *_, sib in evaluated for t, read in sib.items() if read})
        finest, values = None, []
        if sweep.converge:
            values = [converge_values(case, sweep.variant, folder, runs_root, sweep.converge, loaded)
                      for _, folder, _ in pts]
            finest = finest_index(costs, usable=lambda i: not any(isinstance(v, str) for v in values[i].values()))
        for i, ((f, folder, sets, by_term, _), cost) in enumerate(zip(evaluated, costs)):
            unsettled = cost.pop("unsettled")
            notes = []
            if sweep.converge:
                if i == finest:
                    notes.append("the finest run: the reference of the self-convergence error")
                elif finest is None:
                    by_term = {**by_term, CONVERGE + "*": "no ok point with every quantity measured to converge to"}
                else:
                    by_term = {**by_term, **converge_terms(values[i], values[finest])}
            if cost["status"] != "ok":
                error, worst = None, ""
                notes.append(f"{cost['status']}: {_message(folder)}")
            else:
                error, worst, note = run_error(by_term, dropped)
                if not (i == finest and note == "no error term"):
                    notes.append(note)
                if unsettled:
                    notes.append("stage(s) " + ", ".join(unsettled) +
                                 " ran to their cycle limit without meeting the stop rule")
            if dropped:
                notes.append(f"left out (reads a DEM sibling): {', '.join(dropped)}")
            rows.append({"sweep": sweep.name, "factor": f, "sets": " ".join(sets) or "(default)",
                         **cost, "error": error, "worst": worst, "note": "; ".join(filter(None, notes))})
    return rows


def _message(folder):
    """The run's own account of its failure: run.json message, else harness.json cause."""
    try:
        info = read_run_json(folder)
        if info.get("message"):
            return str(info["message"])
    except RunProblem:
        pass
    try:
        return str(json.loads((Path(folder) / "harness.json").read_text(encoding="utf-8")).get("cause") or "no message")
    except (OSError, ValueError):
        return "no run.json and no harness.json"


def is_default(row):
    """Whether a row is the variant's own default-tier run (not a point run by the sweep)."""
    return row["factor"] == 1.0 and row["sets"] == "(default)"


def failed(row):
    """Whether a row's run failed (unstable, or no usable run.json)."""
    return row["status"] != "ok"


def cheapest(rows, tolerances=TOLERANCES):
    """Per tolerance: the row of least particle-steps (then wall seconds) with error <= tolerance, or None."""
    ok = [r for r in rows if r["status"] == "ok" and r["error"] is not None and r["particle_steps"] is not None]
    out = {}
    for tol in tolerances:
        meeting = [r for r in ok if r["error"] <= tol]
        out[tol] = min(meeting, key=lambda r: (r["particle_steps"], r["wall_seconds"] or 0.0)) if meeting else None
    return out


def _cell(x):
    if x is None:
        return "-"
    if isinstance(x, float):
        return f"{x:.6g}"
    return str(x).replace("\t", " ").replace("\n", " ")


def write_tsv(rows, path):
    """cost.tsv: one row per point, COST_COLUMNS; '-' for nothing (tmp file + rename)."""
    path = Path(path)
    files.make_dirs(path.parent)
    text = "\t".join(COST_COLUMNS) + "\n" + "".join(
        "\t".join(_cell(r[c]) for c in COST_COLUMNS) + "\n" for r in rows)
    files.write_text(path, text)


def read_tsv(path):
    """The rows of a cost.tsv (numbers back as numbers, '-' as None)."""
    lines = Path(path).read_text(encoding="utf-8").splitlines()
    header = lines[0].split("\t")
    if tuple(header) != COST_COLUMNS:
        raise ValueError(f"{path}: header is not {' '.join(COST_COLUMNS)}")
    rows = []
    for line in lines[1:]:
        cells = line.split("\t")
        if len(cells) != len(header):
            raise ValueError(f"{path}: row with {len(cells)} cells, not {len(header)}")
        row = dict(zip(header, cells))
        for key in ("factor", "error", "wall_seconds"):
            row[key] = None if row[key] == "-" else float(row[key])
        for key in ("steps", "n_discs", "particle_steps"):
            row[key] = None if row[key] == "-" else int(float(row[key]))
        rows.append(row)
    return rows


def cost_path(sweeps_root, case_name):
    return Path(sweeps_root) / case_name / "cost.tsv"


def run_declared(cases, checks, binary, workers, runs_root, sweeps_root, out, run_all):
    """Run every declared point of the cases (one parallel batch, by run_all: points.launch with
    the command's --resume), write each case's cost.tsv; print the cheapest setting per
    tolerance.  The list of (case, rows)."""
    swept = [c for c in cases if c.sweeps]
    for case in cases:
        if not case.sweeps:
            print(f"{case.name}: no [sweep] declared", file=out)
    all_jobs = [j for c in swept for j in jobs(c, sweeps_root)]
    core_info.refuse_bad_points(binary, [p for c in swept for p in core_points(c, sweeps_root)])
    if all_jobs:
        run_all(all_jobs, binary, workers, out)
    done = []
    for case in swept:
        rows = points(case, checks, runs_root, sweeps_root)
        write_tsv(rows, cost_path(sweeps_root, case.name))
        done.append((case, rows))
        print(summary_text(case.name, rows), file=out)
    return done


def setting(row):
    """'default' or 'dt x2 (settings.dt=0.02 ...)'."""
    if is_default(row):
        return "default"
    return f"{row['sweep']} x{number(row['factor'])} ({row['sets']})"


def summary_text(name, rows):
    """A few lines: the default's error and the cheapest setting per tolerance."""
    default = next((r for r in rows if is_default(r)), None)
    lines = [f"{name}: default error {_cell(default['error']) if default else '-'}, "
             f"{_cell(default['particle_steps']) if default else '-'} particle-steps"]
    for tol, r in cheapest(rows).items():
        lines.append(f"  error <= {tol:g}: " + (f"{setting(r)}, error {_cell(r['error'])}, "
                                                 f"{r['particle_steps']} particle-steps"
                                                 if r else "no swept setting"))
    unstable = [f"{r['sweep']} x{number(r['factor'])}" for r in rows if r["status"] == "unstable"]
    other = [f"{r['sweep']} x{number(r['factor'])}" for r in rows if failed(r) and r["status"] != "unstable"]
    if unstable:
        lines.append(f"  beyond the stability limit (the run-time guards stopped them; a measured limit of "
                     f"the trade, not a gate): {', '.join(unstable)}")
    if other:
        lines.append(f"  no result (no usable run.json; not a gate): {', '.join(other)}")
    return "\n".join(lines)
