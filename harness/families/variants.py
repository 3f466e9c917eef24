"""Another variant of the same case, inside an expression: its column, a quantity of it, and the
order of accuracy observed over several (reference/nine_discs.ref, two_discs_order.ref,
collisions.ref).

    series(variant, column)  a whole column of another variant, for comparing curves
    of(variant, expr)        the value of expr in another variant
    order(expr, exact, v1, v2, ...)
                             the observed order of accuracy: for two variants
                             p = log(|q_1 - exact| / |q_2 - exact|) / log(dt_1 / dt_2), q = expr
                             in each variant, dt from each run.json; for more, the least-squares
                             slope of log|q - exact| on log dt
    spread(expr, v1, v2, ...)
                             the largest less the least value of expr over the variants: how
                             far a quantity that should not change between them does (JYH's
                             peak less residual angle over delta, the seeds of one material)
"""
import numpy as np

from ..compare import evaluate
from ..errors import EvalError
from ..expressions import register, sibling_run

NAMES = ("series", "of", "order", "spread")


def bind(run, sibling=None):
    """The family's functions; sibling(variant) gives the other variants' runs."""
    def series(variant, column):
        other = sibling_run(sibling, variant, "series")
        if column not in other.columns:
            raise EvalError(f"series(): variant '{variant}' has no column '{column}'")
        return other.columns[column]

    def of(variant, expr):
        try:
            return evaluate(expr, sibling_run(sibling, variant, "of"), sibling)
        except EvalError as exc:
            raise EvalError(f"of(): variant '{variant}': {exc}") from None

    def order(expr, exact, *variants):
        if len(variants) < 2:
            raise EvalError("order(): needs at least two variants")
        errors, steps = [], []
        for variant in variants:
            errors.append(abs(of(variant, expr) - exact))
            dt = sibling_run(sibling, variant, "order").info.get("dt")
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

    def spread(expr, *variants):
        if len(variants) < 2:
            raise EvalError("spread(): needs at least two variants")
        values = [of(variant, expr) for variant in variants]
        return float(max(values) - min(values))

    return {"series": series, "of": of, "order": order, "spread": spread}


register("variants", NAMES, bind)
