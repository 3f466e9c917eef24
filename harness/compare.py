"""Checks against run outputs: expression evaluation, tolerance kinds, verdicts.

A quantity is a Python expression evaluated without builtins in a namespace holding every
series.tsv column (numpy array) and the functions that harness/expressions.py gives for the
run: the expression language's own (at, first, last, after, upto, between, mean, max, min,
std, abs, sqrt, amp, run, energy) and those every case family registered there (the
modules of harness/families: signals, variants, piles, networks, collisions, biaxial).  This
module knows no family: it asks the registry.  evaluate_check() turns one Check into a Verdict;
anything that goes wrong (missing output, failed run, missing column, an expression that
raises, a NaN/inf value) is a FAIL whose message says which, never a pass and never a skip.
The one SKIP: a run that could not be made and says why (RunSkipped: a cross-check against
LAMMPS where LAMMPS is absent and cannot be installed).  A check that reads a run another
engine could not express (RunNotExpressible, harness/engines) is NOT EXPRESSIBLE, with why.
evaluate_array() gives a figure (report/plots.py) an expression's whole row of numbers.
"""
import ast
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import EvalError, RunNotExpressible, RunProblem, RunSkipped
from .expressions import Siblings, functions
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
    skipped: bool = False  # SKIP: its run could not be made (passed is False, message says why)
    known: str = ""        # KNOWN: outside its tolerance, as reference/ says it is (the reason)
    unexpressible: str = ""  # a run it reads is one another engine could not express (why)

    @property
    def result(self):
        """PASS, FAIL, SKIP or KNOWN (a documented discrepancy with a paper: neither passes nor
        fails the gate, and is shown with its reason); NOT EXPRESSIBLE for a run of another
        engine that could not express the scene (harness/engines)."""
        if self.unexpressible:
            return "NOT EXPRESSIBLE"
        return "SKIP" if self.skipped else "KNOWN" if self.known else "PASS" if self.passed else "FAIL"

    def as_dict(self):
        """The summary.json record (keys as in the spec; non-finite numbers as null); a
        skipped check also has "skip": true."""
        out = {"case": self.case, "variant": self.variant, "check": self.check,
               "quantity": self.quantity, "value": _json_number(self.value),
               "reference": _json_number(self.reference), "tolerance": self.tolerance,
               "kind": self.kind, "provenance": self.provenance, "pass": self.passed,
               "message": self.message}
        if self.skipped:
            out["skip"] = True
        if self.known:
            out["known"] = self.known
        if self.unexpressible:
            out["not_expressible"] = self.unexpressible
        return out

    @classmethod
    def from_dict(cls, d):
        return cls(d["case"], d["variant"], d["check"], d["quantity"], d["value"], d["reference"],
                   d["tolerance"], d["kind"], d["provenance"], d["pass"], d["message"],
                   bool(d.get("skip", False)), d.get("known", ""), d.get("not_expressible", ""))


def _json_number(x):
    if isinstance(x, list):
        return [_json_number(v) for v in x]
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


# ---------------------------------------------------------------- run outputs

class RunStore:
    """Loads each run folder once; locate(case, variant) gives the folder.  ensembles:
    {case: {ensemble: its realisations' variant names}} (catalogue.ensembles_of), for the
    expression functions over an ensemble; empty when not given."""

    def __init__(self, locate, ensembles=None):
        self.locate = locate
        self.ensembles = dict(ensembles or {})
        self._cache = {}

    def siblings(self, case):
        """The other variants of case, for an expression evaluated in one of them."""
        return Siblings(lambda other: self.get(case, other), self.ensembles.get(case))

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

    sibling(variant) gives the Run of another variant of the same case, for the functions
    that read one (series(), of(), contact_error(), ...).
    """
    names = dict(run.columns)
    names.update(functions(run, sibling))
    return names


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


def _refuse_unexpressible(expr, run):
    """A run of another engine lists in run.json `unexpressible` the columns and functions it
    cannot give ({name: why}, harness/engines/outputs.py): an expression using one is not
    expressible in that engine (RunNotExpressible), not a missing column."""
    refused = run.info.get("unexpressible") if isinstance(run.info, dict) else None
    if not refused:
        return
    try:
        used = {n.id for n in ast.walk(ast.parse(expr, mode="eval")) if isinstance(n, ast.Name)}
    except SyntaxError:
        return
    hit = sorted(used & set(refused))
    if hit:
        raise RunNotExpressible(f"{hit[0]}: {refused[hit[0]]}")


def _value(expr, run, sibling=None):
    """The expression's value in run's outputs, whatever it is."""
    _refuse_unexpressible(expr, run)
    names = namespace(run, sibling)
    code = _compile(expr, names, run.columns)
    try:
        with np.errstate(all="ignore"):
            return eval(code, {**names, "__builtins__": {}})  # noqa: S307 -- no builtins, vetted names
    except (EvalError, RunNotExpressible):
        raise
    except Exception as exc:  # any failure of the expression is a FAIL with its reason
        raise EvalError(f"'{expr}' raised {type(exc).__name__}: {exc}") from None


def evaluate(expr, run, sibling=None):
    """The expression's value in run's outputs, as one finite float."""
    return _finite_scalar(_value(expr, run, sibling), expr)


def evaluate_array(expr, run, sibling=None):
    """The expression's value in run's outputs as a 1-d float array (a figure's curve, e.g.
    100 * axial_strain()); a number is an array of one.  Non-finite elements are kept: the
    caller says what it does with them."""
    result = _value(expr, run, sibling)
    try:
        arr = np.atleast_1d(np.asarray(result, dtype=float))
    except (TypeError, ValueError):
        raise EvalError(f"'{expr}' is not a number or an array of numbers: {result!r}") from None
    if arr.ndim != 1 or arr.size == 0:
        raise EvalError(f"'{expr}' gives {'no values' if arr.size == 0 else f'an array of shape {arr.shape}'}, "
                        "not a row of numbers")
    return arr


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
        return evaluate(expr, run, store.siblings(case))
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


def evaluate_check(check, store, known_is_ours=True):
    """The Verdict of one check; any problem is a FAIL with its reason, but a run that could
    not be made (RunSkipped) makes it a SKIP with that run's reason.  A check listed as a known
    discrepancy is KNOWN while it misses and FAIL once within its tolerance (the entry is stale).
    known_is_ours=False is another engine's column (harness/engines/matrix.py): the entry is
    ballast's, so there a value within the tolerance is simply a PASS, said so."""
    skipped, unexpressible = False, ""
    try:
        value, passed, message = JUDGES[check.tolerance](check, store)
    except RunNotExpressible as exc:
        value, passed, message, unexpressible = None, False, str(exc), str(exc)
    except RunSkipped as exc:
        value, passed, message, skipped = None, False, str(exc), True
    except (RunProblem, EvalError) as exc:
        value, passed, message = None, False, str(exc)
    known = ""
    if check.known and value is not None and not skipped:
        if passed and not known_is_ours:
            message = f"within its tolerance here; ballast lists a known discrepancy ({check.known}): {message}"
        elif passed:    # strict: a discrepancy that went away must leave reference/ and the docs
            passed, message = False, (f"listed as a known discrepancy ({check.known}) but within its tolerance "
                                      "now: remove 'known' from the check and update the docs")
        else:
            known = check.known
            message = f"known discrepancy: {check.known}" + (f" ({message})" if message else "")
    return Verdict(case=check.case, variant=check.variant_label, check=check.name,
                   quantity=quantity_text(check), value=value, reference=reference_of(check),
                   tolerance=check.tolerance_text, kind=check.kind, provenance=check.provenance,
                   passed=bool(passed), message=message, skipped=skipped, known=known,
                   unexpressible=unexpressible)


def evaluate_all(checks, store):
    """Verdicts of the checks, in the order given."""
    return [evaluate_check(c, store) for c in checks]
