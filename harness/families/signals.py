"""One series column as a signal: its period, when it settles, and the period and amplitude of a
sampled sinusoid (cases/nine_discs, reference/two_discs_order.ref).

    period(arr)              the mean number of rows between upward crossings of arr's mean
    settle(col, target, tol) the cycle from which col stays within tol |target| of target
    sine_period(arr, level), sine_amplitude(arr, level)
                             the period (in rows) and amplitude of a sampled sinusoid about level

sine_period and sine_amplitude resolve below one step: with y_N = arr_N - level =
A sin(N theta + phi), y_{N+1} + y_{N-1} = 2 cos(theta) y_N gives cos(theta) (least squares
over all rows), and y_N^2 - y_{N-1} y_{N+1} = A^2 sin^2(theta) gives A (mean over all rows).
Both are exact for a pure sampled sinusoid, whatever the phase of the samples.
"""
import math

import numpy as np

from ..errors import EvalError
from ..expressions import nonempty, register

NAMES = ("period", "settle", "sine_period", "sine_amplitude")


def period(arr):
    """Mean number of cycles between upward crossings of the signal's mean."""
    arr = nonempty(arr, "period")
    x = arr - arr.mean()
    up = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
    if up.size < 2:
        raise EvalError("period(): fewer than two upward crossings of the mean")
    return float(np.mean(np.diff(up)))


def _sine_theta(arr, level, fname):
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
    _, theta = _sine_theta(arr, level, "sine_period")
    return 2 * math.pi / theta


def sine_amplitude(arr, level):
    y, theta = _sine_theta(arr, level, "sine_amplitude")
    a2 = np.mean(y[1:-1] ** 2 - y[:-2] * y[2:])
    return math.sqrt(max(a2, 0.0)) / math.sin(theta)


def bind(run, sibling=None):
    """The family's functions; settle reads run's cycle column."""
    cycle = run.columns["cycle"]

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

    return {"period": period, "settle": settle, "sine_period": sine_period, "sine_amplitude": sine_amplitude}


register("signals", NAMES, bind)
