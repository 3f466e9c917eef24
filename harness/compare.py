"""Checks against run outputs: expression evaluation, tolerance kinds, verdicts.

A quantity is a Python expression evaluated without builtins in a namespace holding
every series.tsv column (numpy array) and the functions of the spec (at, first, last,
after, upto, between, mean, max, min, std, abs, sqrt, amp, run), plus series(variant,
column) for a column of another variant of the same case, period(arr) for the mean
number of rows between upward crossings of the mean, and settle(col, target, tol) for
the cycle from which a column stays within tol of target; and the pile functions of
piles.py (pile_X, pile_S, middle, horizontal_contacts, contact_error, contact_mismatch,
weight), which read the run's final state (discs.tsv, contacts.tsv, stress.tsv) when
called; and the collision and order functions of the block at the end (contact_start,
contact_end, contact_duration, restitution, sine_period, sine_amplitude, of, order).  evaluate_check() turns one Check into a Verdict; anything that goes wrong
(missing output, failed run, missing column, an expression that raises, a NaN/inf
value) is a FAIL whose message says which, never a pass and never a skip.
"""
import ast
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import EvalError, RunProblem
from .tables import load_run

@dataclass
class Verdict:
    case: str
    variant: str
    check: str
    quantity: str
    value: object        # float, list of floats (trend), or None when it could not be computed
    reference: object    # float, [lo, hi] (interval), or None (trend)
    tolerance: str
    kind: str
    provenance: str
    passed: bool
    message: str

    def as_dict(self):
        """The summary.json record (keys as in the spec; non-finite numbers as null)."""
        return {"case": self.case, "variant": self.variant, "check": self.check,
                "quantity": self.quantity, "value": _json_number(self.value),
                "reference": _json_number(self.reference), "tolerance": self.tolerance,
                "kind": self.kind, "provenance": self.provenance, "pass": self.passed,
                "message": self.message}

    @classmethod
    def from_dict(cls, d):
        return cls(d["case"], d["variant"], d["check"], d["quantity"], d["value"], d["reference"],
                   d["tolerance"], d["kind"], d["provenance"], d["pass"], d["message"])


def _json_number(x):
    if isinstance(x, list):
        return [_json_number(v) for v in x]
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


# ---------------------------------------------------------------- run outputs

class RunStore:
    """Loads each run folder once; locate(case, variant) gives the folder."""

    def __init__(self, locate):
        self.locate = locate
        self._cache = {}

    def get(self, case, variant):
        """The Run of case/variant, or raise its RunProblem."""
        key = (case, variant)
        if key not in self._cache:
            try:
                self._cache[key] = load_run(self.locate(case, variant))
            except RunProblem as problem:
                self._cache[key] = problem
        found = self._cache[key]
        if isinstance(found, RunProblem):
            raise found
        return found


def folder_locator(runs_root):
    """locate() for the usual layout runs_root/<case>/<variant>."""
    return lambda case, variant: Path(runs_root) / case / variant


# ---------------------------------------------------------------- expressions

def namespace(run, sibling=None):
    """Columns by header name, then the expression functions (functions win a clash,
    except where the expression uses the name as a value: see _compile).

    sibling(variant) gives the Run of another variant of the same case, for series(),
    contact_error() and contact_mismatch().
    """
    names = dict(run.columns)
    names.update(REDUCERS)
    names.update(_selectors(run.columns["cycle"]))
    names.update(_signal_functions(run.columns["cycle"]))
    names["run"] = _run_field(run.info)
    names["energy"] = _energy_term(run.info)
    names["series"] = _series_of(sibling)
    from . import piles   # here, not at the top: piles imports EvalError from this module
    names.update(piles.functions(run, sibling))
    names.update(_collision_functions(run, sibling))
    return names


def _series_of(sibling):
    """series(variant, column): a whole column of another variant of the same case."""
    def series(variant, column):
        if sibling is None:
            raise EvalError("series(): no other variants are available here")
        try:
            other = sibling(variant)
        except RunProblem as problem:
            raise EvalError(f"series(): variant '{variant}': {problem}") from None
        if column not in other.columns:
            raise EvalError(f"series(): variant '{variant}' has no column '{column}'")
        return other.columns[column]
    return series


def _signal_functions(cycle):
    """period and settle: properties of a signal over the rows of a run."""
    def period(arr):
        """Mean number of cycles between upward crossings of the signal's mean."""
        arr = _nonempty(arr, "period")
        x = arr - arr.mean()
        up = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
        if up.size < 2:
            raise EvalError("period(): fewer than two upward crossings of the mean")
        return float(np.mean(np.diff(up)))

    def settle(col, target, tol):
        """First cycle from which |col - target| <= tol |target| holds to the end."""
        col = np.asarray(col, dtype=float)
        if col.shape != cycle.shape:
            raise EvalError("settle(): first argument must be a whole series column")
        outside = np.flatnonzero(np.abs(col - target) > tol * abs(target))
        if outside.size == 0:
            return float(cycle[0])
        if outside[-1] == col.size - 1:
            raise EvalError(f"settle(): still outside {tol:g} of {target:g} at the last row")
        return float(cycle[outside[-1] + 1])

    return {"period": period, "settle": settle}


def _nonempty(arr, fname):
    arr = np.atleast_1d(np.asarray(arr, dtype=float))
    if arr.size == 0:
        raise EvalError(f"{fname}(): no rows selected")
    return arr


def _reducer(fn, fname):
    """fn over one array (or over several numbers, as in max(a, b)); empty is an error."""
    def reduce(*args):
        arr = args[0] if len(args) == 1 else np.array(args, dtype=float)
        return float(fn(_nonempty(arr, fname)))
    return reduce


REDUCERS = {
    "first": _reducer(lambda a: a[0], "first"), "last": _reducer(lambda a: a[-1], "last"),
    "mean": _reducer(np.mean, "mean"), "max": _reducer(np.max, "max"),
    "min": _reducer(np.min, "min"), "std": _reducer(np.std, "std"),
    "amp": _reducer(lambda a: (a.max() - a.min()) / 2, "amp"),
    "abs": np.abs, "sqrt": np.sqrt,
}


def _selectors(cycle):
    """at, after, upto, between: rows of a whole column chosen by the cycle column."""
    def whole(col, fname):
        col = np.asarray(col, dtype=float)
        if col.shape != cycle.shape:
            raise EvalError(f"{fname}(): first argument must be a whole series column")
        return col

    def at(col, c):
        rows = np.flatnonzero(cycle == c)
        if rows.size == 0:
            raise EvalError(f"at(): no row with cycle == {c:g}")
        return float(whole(col, "at")[rows[0]])

    return {
        "at": at,
        "after": lambda col, c: whole(col, "after")[cycle > c],
        "upto": lambda col, c: whole(col, "upto")[cycle <= c],
        "between": lambda col, a, b: whole(col, "between")[(cycle >= a) & (cycle <= b)],
    }


def _run_field(info):
    def run(key):
        if key not in info:
            raise EvalError(f"run(): run.json has no field '{key}'")
        return info[key]
    return run


def _energy_term(info):
    """energy(term): a term of the run's energy audit (run.json "energy", core/energy.c)."""
    def energy(term):
        audit = info.get("energy")
        if not isinstance(audit, dict):
            raise EvalError("energy(): run.json has no energy audit")
        if term not in audit:
            raise EvalError(f"energy(): the audit has no term '{term}' (has: {', '.join(audit)})")
        if audit[term] is None:
            raise EvalError(f"energy(): the audit's '{term}' is not finite")
        return audit[term]
    return energy


SHADOWED = "column_shadowed_by_function_"


def _compile(expr, names, columns=None):
    """Compile expr; refuse private attributes and names the namespace lacks.

    A name that is both a series column and a function (a probe called 'weight' beside
    weight()) is the function where it is called and the column where it is used as a
    value: those uses are renamed SHADOWED + name, and names gets that entry.
    """
    try:
        tree = ast.parse(expr, mode="eval")
    except SyntaxError as exc:
        raise EvalError(f"syntax error in '{expr}': {exc.msg}") from None
    nodes = list(ast.walk(tree))
    called = {id(n.func) for n in nodes if isinstance(n, ast.Call)}
    bound = {n.id for n in nodes if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)}
    for node in nodes:
        if (isinstance(node, ast.Name) and id(node) not in called and node.id not in bound
                and columns and node.id in columns and callable(names.get(node.id))):
            names[SHADOWED + node.id] = columns[node.id]
            node.id = SHADOWED + node.id
    for node in nodes:
        if isinstance(node, ast.Attribute) and node.attr.startswith("_"):
            raise EvalError(f"'{node.attr}' is not allowed in an expression")
        if isinstance(node, ast.Name) and node.id not in names and node.id not in bound:
            raise EvalError(_unknown_name(node.id, id(node) in called, names))
    return compile(tree, "<quantity>", "eval")


def _unknown_name(name, is_call, names):
    if is_call:
        functions = ", ".join(n for n in names if callable(names[n]))
        return f"unknown function '{name}' (functions: {functions})"
    columns = ", ".join(n for n in names if not callable(names[n]))
    return f"column '{name}' missing from series.tsv (columns: {columns})"


def evaluate(expr, run, sibling=None):
    """The expression's value in run's outputs, as one finite float."""
    names = namespace(run, sibling)
    code = _compile(expr, names, run.columns)
    try:
        with np.errstate(all="ignore"):
            result = eval(code, {**names, "__builtins__": {}})  # noqa: S307 -- no builtins, vetted names
    except EvalError:
        raise
    except Exception as exc:  # any failure of the expression is a FAIL with its reason
        raise EvalError(f"'{expr}' raised {type(exc).__name__}: {exc}") from None
    return _finite_scalar(result, expr)


def _finite_scalar(result, expr):
    try:
        arr = np.asarray(result, dtype=float)
    except (TypeError, ValueError):
        raise EvalError(f"'{expr}' is not a number: {result!r}") from None
    if arr.size != 1:
        raise EvalError(f"'{expr}' gives {arr.size} values, not one")
    value = float(arr.reshape(-1)[0])
    if not math.isfinite(value):
        raise EvalError(f"'{expr}' is {value} (not finite)")
    return value


def quantity_in(store, case, variant, expr):
    """Evaluate expr in the outputs of case/variant; errors say which variant."""
    run = store.get(case, variant)
    try:
        return evaluate(expr, run, lambda other: store.get(case, other))
    except EvalError as exc:
        raise EvalError(f"{variant}: {exc}") from None


# ---------------------------------------------------------------- tolerance kinds

def _judge_abs(check, store):
    q = quantity_in(store, check.case, check.variant, check.quantity)
    err = abs(q - check.value)
    ok = err <= check.width
    return q, ok, f"|q - ref| = {err:.3g} {'<=' if ok else '>'} {check.width:g}"


def _judge_rel(check, store):
    q = quantity_in(store, check.case, check.variant, check.quantity)
    return q, *_relative(q, check.value, check.width, "q")


def _relative(q, ref, width, label):
    err, bound = abs(q - ref), width * abs(ref)
    ok = err <= bound
    return ok, f"|{label} - ref| = {err:.3g} {'<=' if ok else '>'} {width:g}*|ref| = {bound:.3g}"


def _judge_interval(check, store):
    q = quantity_in(store, check.case, check.variant, check.quantity)
    ok = (check.lo is None or check.lo <= q) and (check.hi is None or q <= check.hi)
    lo = "-inf" if check.lo is None else f"{check.lo:.6g}"
    hi = "+inf" if check.hi is None else f"{check.hi:.6g}"
    return q, ok, f"{lo} <= {q:.6g} <= {hi}" if ok else f"{q:.6g} outside [{lo}, {hi}]"


def _judge_ratio(check, store):
    q = quantity_in(store, check.case, check.variant, check.quantity)
    other = quantity_in(store, check.case, check.other_variant, check.other)
    if other == 0:
        raise EvalError(f"{check.other_variant}: other quantity '{check.other}' is zero")
    ratio = q / other
    ok, message = _relative(ratio, check.value, check.width, "q/other")
    return ratio, ok, f"q = {q:.6g}, other = {other:.6g}; {message}"


MONOTONE = {
    "increasing": lambda a, b: b > a, "decreasing": lambda a, b: b < a,
    "nondecreasing": lambda a, b: b >= a, "nonincreasing": lambda a, b: b <= a,
}


def _judge_trend(check, store):
    values = [quantity_in(store, check.case, v, check.quantity) for v in check.variants]
    step_ok = MONOTONE[check.direction]
    for (va, a), (vb, b) in zip(zip(check.variants, values), zip(check.variants[1:], values[1:])):
        if not step_ok(a, b):
            return values, False, f"not {check.direction}: {va} = {a:.6g} then {vb} = {b:.6g}"
    return values, True, f"{check.direction} over {', '.join(check.variants)}"


JUDGES = {"abs": _judge_abs, "rel": _judge_rel, "interval": _judge_interval,
          "ratio": _judge_ratio, "trend": _judge_trend}


# ---------------------------------------------------------------- verdicts

def reference_of(check):
    """What the verdict shows as the reference value."""
    if check.tolerance == "interval":
        return [check.lo, check.hi]
    if check.tolerance == "trend":
        return None
    return check.value


def quantity_text(check):
    if check.tolerance != "ratio":
        return check.quantity
    where = "" if check.other_variant == check.variant else f" [in {check.other_variant}]"
    return f"({check.quantity}) / ({check.other}){where}"


def evaluate_check(check, store):
    """The Verdict of one check; any problem is a FAIL with its reason."""
    try:
        value, passed, message = JUDGES[check.tolerance](check, store)
    except (RunProblem, EvalError) as exc:
        value, passed, message = None, False, str(exc)
    return Verdict(case=check.case, variant=check.variant_label, check=check.name,
                   quantity=quantity_text(check), value=value, reference=reference_of(check),
                   tolerance=check.tolerance_text, kind=check.kind, provenance=check.provenance,
                   passed=bool(passed), message=message)


def evaluate_all(checks, store):
    """Verdicts of the checks, in the order given."""
    return [evaluate_check(c, store) for c in checks]


# ---------------------------------------------------------------- collisions and orders
# (cases/collisions, reference/collisions.ref, reference/two_discs_order.ref)
#
# contact_start(gap), contact_end(gap), contact_duration(gap), restitution(gap): a binary
# collision measured from the surface gap of two discs (a whole series column expression,
# e.g. x_b - x_a - 1.75; negative while they overlap).  The first contact is the first run
# of rows with gap < 0 (C&S eq. 8 is strict).  Its start and end are the zero crossings of
# the gap, interpolated linearly between the rows that straddle them: the row outside
# contact lies on the free-flight line, and so does the row inside (the scheme moves the
# discs with v_{N-1/2}, C&S eq. 23, before the force acts), so the interpolation is exact
# on the free-flight side.  restitution is -(chord after)/(chord before): the chords across
# the crossings are the free-flight velocities v_{N+1/2} (C&S eq. 22), which the scheme
# holds exactly in flight; the centred velocities of eq. 31 would mix a half step in
# contact.  The straddling rows must be consecutive cycles (output_every = 1 there).
#
# sine_period(arr, level), sine_amplitude(arr, level): the period (in rows) and amplitude of
# a sampled sinusoid about level, y_N = arr_N - level = A sin(N theta + phi), with sub-step
# resolution: y_{N+1} + y_{N-1} = 2 cos(theta) y_N gives cos(theta) (least squares over all
# rows), and y_N^2 - y_{N-1} y_{N+1} = A^2 sin^2(theta) gives A (mean over all rows).  Both
# are exact for a pure sampled sinusoid, whatever the phase of the samples.
# of(variant, expr): the value of expr in another variant of the same case.
# order(expr, exact, v1, v2, ...): the observed order of accuracy; for two variants
# p = log(|q_1 - exact| / |q_2 - exact|) / log(dt_1 / dt_2), q = expr in each variant, dt
# from each run.json; for more, the least-squares slope of log|q - exact| on log dt.

def _collision_functions(run, sibling):
    cycle, time = run.columns["cycle"], run.columns["time"]

    def crossings(gap, fname):
        gap = np.asarray(gap, dtype=float)
        if gap.shape != cycle.shape:
            raise EvalError(f"{fname}(): argument must be a whole series column expression")
        inside = np.flatnonzero(gap < 0)
        if inside.size == 0:
            raise EvalError(f"{fname}(): the gap never becomes negative (no contact)")
        s = inside[0]
        after = np.flatnonzero(gap[s:] >= 0)
        if s == 0 or after.size == 0:
            raise EvalError(f"{fname}(): the contact must start and end inside the series")
        e = s + after[0] - 1               # last row of the first contact
        for a in (s - 1, e):
            if cycle[a + 1] - cycle[a] != 1:
                raise EvalError(f"{fname}(): rows {cycle[a]:g} and {cycle[a + 1]:g} are not "
                                "consecutive cycles (set output_every = 1)")
        return gap, s, e

    def cross_time(gap, a):
        """Time where the line through rows a and a + 1 crosses gap = 0."""
        return float(time[a] + (time[a + 1] - time[a]) * gap[a] / (gap[a] - gap[a + 1]))

    def chord(gap, a):
        return float((gap[a + 1] - gap[a]) / (time[a + 1] - time[a]))

    def contact_start(gap):
        gap, s, _ = crossings(gap, "contact_start")
        return cross_time(gap, s - 1)

    def contact_end(gap):
        gap, _, e = crossings(gap, "contact_end")
        return cross_time(gap, e)

    def contact_duration(gap):
        gap, s, e = crossings(gap, "contact_duration")
        return cross_time(gap, e) - cross_time(gap, s - 1)

    def restitution(gap):
        gap, s, e = crossings(gap, "restitution")
        return -chord(gap, e) / chord(gap, s - 1)

    def other(variant, fname):
        if sibling is None:
            raise EvalError(f"{fname}(): no other variants are available here")
        try:
            return sibling(variant)
        except RunProblem as problem:
            raise EvalError(f"{fname}(): variant '{variant}': {problem}") from None

    def of(variant, expr):
        try:
            return evaluate(expr, other(variant, "of"), sibling)
        except EvalError as exc:
            raise EvalError(f"of(): variant '{variant}': {exc}") from None

    def order(expr, exact, *variants):
        if len(variants) < 2:
            raise EvalError("order(): needs at least two variants")
        errors, steps = [], []
        for variant in variants:
            errors.append(abs(of(variant, expr) - exact))
            dt = other(variant, "order").info.get("dt")
            if not isinstance(dt, (int, float)) or not dt > 0:
                raise EvalError(f"order(): variant '{variant}': run.json has no positive dt")
            steps.append(float(dt))
        if len(set(steps)) < len(steps):
            raise EvalError(f"order(): two of {', '.join(variants)} have the same dt")
        if not all(e > 0 for e in errors):
            raise EvalError(f"order(): an error is zero ({', '.join(f'{e:g}' for e in errors)}): "
                            "no order can be observed")
        # Two variants: the pairwise order; more: the least-squares slope of log e on log dt.
        return float(np.polyfit(np.log(steps), np.log(errors), 1)[0])

    def sine_theta(arr, level, fname):
        y = np.atleast_1d(np.asarray(arr, dtype=float)) - level
        if y.size < 3:
            raise EvalError(f"{fname}(): needs at least three rows")
        mid = y[1:-1]
        denom = 2 * np.dot(mid, mid)
        if not denom > 0:
            raise EvalError(f"{fname}(): the signal equals the level")
        cos_theta = np.dot(mid, y[2:] + y[:-2]) / denom
        if not -1 < cos_theta < 1:
            raise EvalError(f"{fname}(): not a sampled sinusoid (cos theta = {cos_theta:g})")
        return y, math.acos(cos_theta)

    def sine_period(arr, level):
        _, theta = sine_theta(arr, level, "sine_period")
        return 2 * math.pi / theta

    def sine_amplitude(arr, level):
        y, theta = sine_theta(arr, level, "sine_amplitude")
        a2 = np.mean(y[1:-1] ** 2 - y[:-2] * y[2:])
        return math.sqrt(max(a2, 0.0)) / math.sin(theta)

    return {"contact_start": contact_start, "contact_end": contact_end,
            "sine_period": sine_period, "sine_amplitude": sine_amplitude,
            "contact_duration": contact_duration, "restitution": restitution,
            "of": of, "order": order}
