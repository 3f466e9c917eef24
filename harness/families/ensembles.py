"""The realisations of an [ensemble] of the same case, inside an expression: statistics over
many runs that differ only in their seed (harness/ensembles.py declares them).

    members(name)         the variant names of ensemble name's realisations, in seed order
                          (NAME_s<seed>), for use in a comprehension:
                          [of(v, 'last(Ek)') for v in members('poly')]
    seeds(name)           their seeds, as an array in the same order
    realisations(name)    how many there are
    over(name, expr)      expr evaluated in every realisation: an array in seed order, for
                          mean, std, min, max ...:  mean(over('poly', "max(pile_S('zz'))"))
    sd(values)            the sample standard deviation (n - 1 in the denominator; the language's
                          std divides by n): the spread of a few specimens
    this_ensemble()       the name of the ensemble this run is a realisation of
    same_seed(name, expr) expr in the realisation of ensemble name with this run's seed (a
                          realisation's own counterpart in another ensemble: the same specimen
                          at another rate)
    paired(name, reference, expr)
                          per seed, expr in NAME_s<seed> less expr in REFERENCE_s<seed>: an
                          array in seed order (the two ensembles must have the same seeds)
    means(names, expr)    for a list of ensembles, the mean of expr over each one's realisations
    paired_means(names, reference, expr)
                          for a list of ensembles, mean(paired(name, reference, expr)) of each

A check over an ensemble is an ordinary check of one of its realisations (or of any variant
of the case): `variant = poly_s1`, `quantity = std(over('poly', ...)) / sqrt(realisations('poly'))`.
A realisation whose run is missing or failed, or where expr fails, makes the whole value fail,
with that realisation's name: a statistic never silently drops a run.
"""
import numpy as np

from ..compare import evaluate
from ..errors import EvalError
from ..expressions import ensemble_members, register, sibling_run

NAMES = ("members", "seeds", "realisations", "over", "sd", "this_ensemble", "same_seed", "paired", "means",
         "paired_means")


def seed_of(ensemble, variant):
    """The seed of a realisation NAME_s<seed>."""
    return int(variant[len(ensemble) + 2:])


def sample_sd(values):
    """The standard deviation with n - 1 in the denominator; at least two values."""
    arr = np.atleast_1d(np.asarray(values, dtype=float)).reshape(-1)
    if arr.size < 2:
        raise EvalError(f"sd(): needs at least two values, has {arr.size}")
    return float(np.std(arr, ddof=1))


def ensemble_names(names, fname):
    """A list (or tuple) of ensemble names, not empty."""
    if isinstance(names, str) or not isinstance(names, (list, tuple)) or not names:
        raise EvalError(f"{fname}(): the first argument must be a list of ensemble names, e.g. ['a', 'b']")
    return list(names)


def bind(run, sibling=None):
    """The family's functions; sibling.ensembles lists the case's ensembles."""
    def members(name):
        return ensemble_members(sibling, name, "members")

    def seeds(name):
        return np.array([seed_of(name, v) for v in ensemble_members(sibling, name, "seeds")], dtype=float)

    def realisations(name):
        return float(len(ensemble_members(sibling, name, "realisations")))

    def over(name, expr):
        values = []
        for variant in ensemble_members(sibling, name, "over"):
            run_of = sibling_run(sibling, variant, "over")
            try:
                values.append(evaluate(expr, run_of, sibling))
            except EvalError as exc:
                raise EvalError(f"over(): realisation '{variant}': {exc}") from None
        return np.array(values, dtype=float)

    def own():
        """(ensemble, seed) of this run; EvalError when it is no realisation."""
        known = getattr(sibling, "ensembles", None) or {}
        name = run.folder.name if run.folder is not None else None
        for ensemble, variants in known.items():
            if name in variants:
                return ensemble, seed_of(ensemble, name)
        raise EvalError(f"this run ({name}) is no realisation of an ensemble of the case"
                        + ("" if known else " (no ensembles are known here)"))

    def realisation(name, seed, fname):
        for variant in ensemble_members(sibling, name, fname):
            if seed_of(name, variant) == seed:
                return variant
        raise EvalError(f"{fname}(): ensemble '{name}' has no realisation of seed {seed}")

    def value(variant, expr, fname):
        try:
            return float(evaluate(expr, sibling_run(sibling, variant, fname), sibling))
        except EvalError as exc:
            raise EvalError(f"{fname}(): realisation '{variant}': {exc}") from None

    def this_ensemble():
        return own()[0]

    def same_seed(name, expr):
        return value(realisation(name, own()[1], "same_seed"), expr, "same_seed")

    def paired(name, reference, expr):
        ours, theirs = (ensemble_members(sibling, n, "paired") for n in (name, reference))
        a = [seed_of(name, v) for v in ours]
        b = [seed_of(reference, v) for v in theirs]
        if sorted(a) != sorted(b):
            raise EvalError(f"paired(): ensembles '{name}' and '{reference}' have different seeds")
        return np.array([value(v, expr, "paired") - value(realisation(reference, k, "paired"), expr, "paired")
                         for v, k in zip(ours, a)], dtype=float)

    def means(names, expr):
        return np.array([float(np.mean(over(n, expr))) for n in ensemble_names(names, "means")], dtype=float)

    def paired_means(names, reference, expr):
        return np.array([float(np.mean(paired(n, reference, expr))) for n in ensemble_names(names, "paired_means")],
                        dtype=float)

    return {"members": members, "seeds": seeds, "realisations": realisations, "over": over, "sd": sample_sd,
            "this_ensemble": this_ensemble, "same_seed": same_seed, "paired": paired, "means": means,
            "paired_means": paired_means}


register("ensembles", NAMES, bind)
