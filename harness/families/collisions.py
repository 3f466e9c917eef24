"""A binary collision, measured from the surface gap of two discs (cases/collisions,
reference/collisions.ref): when it starts and ends, how long it lasts, and the restitution.

    contact_start(gap), contact_end(gap), contact_duration(gap)
    restitution(gap)         -(free-flight velocity after) / (free-flight velocity before)

gap is a whole series column expression, e.g. x_b - x_a - 1.75; negative while the discs
overlap.  The first contact is the first run of rows with gap < 0 (C&S eq. 8 is strict).
Its start and end are the zero crossings of the gap, interpolated linearly between the rows
that straddle them: the row outside contact lies on the free-flight line, and so does the
row inside (the scheme moves the discs with v_{N-1/2}, C&S eq. 23, before the force acts),
so the interpolation is exact on the free-flight side.  restitution is -(chord after) /
(chord before): the chords across the crossings are the free-flight velocities v_{N+1/2}
(C&S eq. 22), which the scheme holds exactly in flight; the centred velocities of eq. 31
would mix a half step in contact.  The straddling rows must be consecutive cycles
(output_every = 1 there).
"""
import numpy as np

from ..errors import EvalError
from ..expressions import register

NAMES = ("contact_start", "contact_end", "contact_duration", "restitution")


def bind(run, sibling=None):
    """The family's functions, bound to run's cycle and time columns."""
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

    return {"contact_start": contact_start, "contact_end": contact_end,
            "contact_duration": contact_duration, "restitution": restitution}


register("collisions", NAMES, bind)
