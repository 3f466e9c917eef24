"""The realisations of an [ensemble] of the same case, inside an expression: statistics over
many runs that differ only in their seed (harness/ensembles.py declares them).

    members(name)         the variant names of ensemble name's realisations, in seed order
                          (NAME_s<seed>), for use in a comprehension:
                          [of(v, 'last(Ek)') for v in members('poly')]
    seeds(name)           their seeds, as an array in the same order
    realisations(name)    how many there are
    over(name, expr)      expr evaluated in every realisation: an array in seed order, for
                          mean, std, min, max ...:  mean(over('poly', "max(pile_S('zz'))"))

A check over an ensemble is an ordinary check of one of its realisations (or of any variant
of the case): `variant = poly_s1`, `quantity = std(over('poly', ...)) / sqrt(realisations('poly'))`.
A realisation whose run is missing or failed, or where expr fails, makes the whole value fail,
with that realisation's name: a statistic never silently drops a run.
"""
import numpy as np

from ..compare import evaluate
from ..errors import EvalError
from ..expressions import ensemble_members, register, sibling_run

NAMES = ("members", "seeds", "realisations", "over")


def seed_of(ensemble, variant):
    """The seed of a realisation NAME_s<seed>."""
    return int(variant[len(ensemble) + 2:])


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

    return {"members": members, "seeds": seeds, "realisations": realisations, "over": over}


register("ensembles", NAMES, bind)
