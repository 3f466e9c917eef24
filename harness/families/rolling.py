"""The rolling-resistance law tester (cases/rolling, reference/rolling.ref): a straight line
fitted to a branch of a curve.

    fit_slope(x, y)     the least-squares slope of y against x (arrays of the same length,
                        e.g. between(mr, a, b) against between(theta_r, a, b)): the elastic
                        rolling stiffness K_m of a branch of M against theta_r (JYH eq. 28)

The fit is on the deviations from the means, sum((x - mean x)(y - mean y)) /
sum((x - mean x)^2), so a branch that does not pass through the origin (unloading from the
cap) has the same slope as one that does.  Fewer than two points, arrays of different
lengths and an x that does not vary are errors, never a number.
"""
import numpy as np

from ..errors import EvalError
from ..expressions import register

NAMES = ("fit_slope",)


def fit_slope(x, y):
    """Least-squares slope of y on x."""
    x = np.atleast_1d(np.asarray(x, dtype=float))
    y = np.atleast_1d(np.asarray(y, dtype=float))
    if x.shape != y.shape or x.ndim != 1:
        raise EvalError(f"fit_slope(): x and y must be rows of the same length ({x.size} and {y.size})")
    if x.size < 2:
        raise EvalError(f"fit_slope(): needs at least two points, got {x.size}")
    dx, dy = x - x.mean(), y - y.mean()
    sxx = float(np.dot(dx, dx))
    if not sxx > 0:
        raise EvalError("fit_slope(): x does not vary")
    return float(np.dot(dx, dy)) / sxx


def bind(run, sibling=None):
    """The family's functions (they need nothing of the run)."""
    return {"fit_slope": fit_slope}


register("rolling", NAMES, bind)
