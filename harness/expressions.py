"""The functions a quantity expression may call: the language's own, and a registry that the
case families fill.

A quantity (reference/*.ref, a `points` figure, a sweep's `error =`) is evaluated by
compare.py in a namespace of the run's series.tsv columns and the functions that
functions(run, sibling) returns, bound to that run:

  * the language's own, which any run has: first, last, mean, max, min, std, amp, abs,
    sqrt (reducers), at, after, upto, between (rows chosen by the cycle column), run(key)
    (a field of run.json) and energy(term) (a term of its energy audit);
  * every registered family's, in the order the families registered.

A case family -- the collisions, the piles, ... -- registers its functions from its own
module, at import:

    register("collisions", ("contact_start", ...), bind)

bind(run, sibling) returns {name: function} for exactly those names, bound to one run;
sibling(variant) gives the Run of another variant of the same case (None where there is
none).  Where the catalogue is known, sibling is a Siblings, whose `ensembles` lists the
realisations of each [ensemble] of the case (ensemble_members() reads it).  The harness/families package holds the families, and importing it registers them
all (the command line does, first thing).  So compare.py knows no family: the registry
sits below both, and a family is one module that nothing else has to name.

A name may belong to one family only, and never be one of the language's own: register
refuses a clash at once, not at the first evaluation.
"""
import numpy as np

from .errors import EvalError, RunNotExpressible, RunProblem

# ---------------------------------------------------------------- the language's own


def nonempty(arr, fname):
    """arr as a 1-d float array with at least one element; EvalError naming fname if empty."""
    arr = np.atleast_1d(np.asarray(arr, dtype=float))
    if arr.size == 0:
        raise EvalError(f"{fname}(): no rows selected")
    return arr


def _reducer(fn, fname):
    """fn over one array (or over several numbers, as in max(a, b)); empty is an error."""
    def reduce(*args):
        arr = args[0] if len(args) == 1 else np.array(args, dtype=float)
        return float(fn(nonempty(arr, fname)))
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


def _own(run):
    """The language's own functions, bound to run."""
    names = dict(REDUCERS)
    names.update(_selectors(run.columns["cycle"]))
    names["run"] = _run_field(run.info)
    names["energy"] = _energy_term(run.info)
    return names


OWN = tuple(REDUCERS) + ("at", "after", "upto", "between", "run", "energy")


# ---------------------------------------------------------------- the registry

_families = {}      # family name -> (its function names, bind), in registration order


def register(family, names, bind):
    """Add a family's functions: names, and bind(run, sibling) -> {name: function} for them.
    A family registered again (its module imported anew) replaces its old entry."""
    names = tuple(names)
    taken = {n: f for f, (ns, _) in _families.items() if f != family for n in ns}
    for name in names:
        if name in OWN:
            raise ValueError(f"family '{family}': '{name}' is a function of the expression language itself")
        if name in taken:
            raise ValueError(f"family '{family}': '{name}' is already a function of family '{taken[name]}'")
    _families[family] = (names, bind)


def registered():
    """{family: its function names}, in registration order."""
    return {family: names for family, (names, _) in _families.items()}


def functions(run, sibling=None):
    """Every function an expression over run may call, bound to it: the language's own, then
    each family's.  sibling(variant) gives another variant's Run (None: there is none)."""
    names = _own(run)
    for family, (declared, bind) in _families.items():
        made = bind(run, sibling)
        if set(made) != set(declared):
            raise ValueError(f"family '{family}' made {', '.join(made)}, not its registered {', '.join(declared)}")
        names.update(made)
    return names


class Siblings:
    """The other variants of a run's case, as the families' functions see them: calling it with
    a variant's name gives that variant's Run (or raises its RunProblem); `ensembles` maps each
    [ensemble] of the case to its realisations' variant names, in seed order."""

    def __init__(self, get, ensembles=None):
        self._get = get
        self.ensembles = dict(ensembles or {})

    def __call__(self, variant):
        return self._get(variant)


def ensemble_members(sibling, name, fname):
    """The variant names of the realisations of ensemble name, for a family's function fname;
    EvalError when the case has no such ensemble or its ensembles are not known here."""
    known = getattr(sibling, "ensembles", None)
    if not known:
        raise EvalError(f"{fname}(): no ensembles are known here (the case declares none, "
                        "or this evaluation has no catalogue)")
    if name not in known:
        raise EvalError(f"{fname}(): the case has no ensemble '{name}' (has: {', '.join(known)})")
    return list(known[name])


def sibling_run(sibling, variant, fname):
    """The Run of another variant, for a family's function fname; EvalError when there are no
    siblings here or that variant's run cannot be used (RunNotExpressible goes on as it is: a
    run another engine could not express makes the check reading it not expressible)."""
    if sibling is None:
        raise EvalError(f"{fname}(): no other variants are available here")
    try:
        return sibling(variant)
    except RunNotExpressible:
        raise
    except RunProblem as problem:
        raise EvalError(f"{fname}(): variant '{variant}': {problem}") from None
