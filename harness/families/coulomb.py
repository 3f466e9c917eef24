"""Coulomb sliding at the contacts of a run's final state (cases/coulomb, reference/coulomb.ref):
the cap of C&S eq. (19), |F_s| <= F_n tan(phi_mu) + c, which a sliding contact meets exactly.

    coulomb_error(tan_phi, cohesion=0, kind='disc')
                        the largest | |F_s| - F_max | / F_max, F_max = F_n tan_phi + cohesion,
                        over the contacts of that kind that contacts.tsv marks sliding
    sliding_contacts(kind='disc')
                        the number of contacts of that kind that contacts.tsv marks sliding

kind is disc (disc-disc contacts), wall (disc-wall) or all.  F_n is the elastic normal force
(contacts.tsv's fn: the cap takes no dashpot force).  tan_phi and cohesion are the scene's
numbers, written into the check (the smaller of the two bodies' where they differ).
coulomb_error has nothing to measure without a sliding contact: that is an error, never 0,
so a check on it cannot pass on a run where nothing slid.  A contact with F_max <= 0 is an
error too (it cannot slide: the core gives such a pair no shear force).
"""
import numpy as np

from ..errors import EvalError
from ..expressions import register
from ..final_state import state

NAMES = ("coulomb_error", "sliding_contacts")
KINDS = ("disc", "wall", "all")
COLUMNS = ("a", "b", "kind", "fn", "fs", "sliding")


def sliding(final, kind, fname):
    """(F_n, F_s, line) arrays of the contacts of kind marked sliding in the final state."""
    if kind not in KINDS:
        raise EvalError(f"{fname}(): kind must be one of {', '.join(KINDS)}, not {kind!r}")
    t = final.table("contacts.tsv", COLUMNS)
    kinds = t.text("kind")
    marked = t.numbers("sliding")
    fn, fs = t.numbers("fn"), t.numbers("fs")
    keep = np.array([(kind == "all" or k == kind) and m == 1 for k, m in zip(kinds, marked)], dtype=bool)
    return fn[keep], fs[keep], np.asarray(t.lines, dtype=int)[keep]


def coulomb_error(final, tan_phi, cohesion=0.0, kind="disc"):
    """max | |F_s| - F_max | / F_max over the sliding contacts of kind."""
    fn, fs, lines = sliding(final, kind, "coulomb_error")
    if fn.size == 0:
        raise EvalError(f"coulomb_error(): no {'' if kind == 'all' else kind + ' '}contact slides in "
                        f"{final.folder / 'contacts.tsv'}: nothing to check")
    fmax = fn * float(tan_phi) + float(cohesion)
    bad = np.flatnonzero(~(fmax > 0))
    if bad.size:
        raise EvalError(f"{final.folder / 'contacts.tsv'}:{lines[bad[0]]}: a sliding contact with "
                        f"F_max = F_n tan_phi + c = {fmax[bad[0]]:g}, not positive")
    return float(np.max(np.abs(np.abs(fs) - fmax) / fmax))


def sliding_contacts(final, kind="disc"):
    """The number of contacts of kind marked sliding."""
    return int(sliding(final, kind, "sliding_contacts")[0].size)


def bind(run, sibling=None):
    """The family's functions, bound to run's final state."""
    return {"coulomb_error": lambda tan_phi, cohesion=0.0, kind="disc":
            coulomb_error(state(run), tan_phi, cohesion, kind),
            "sliding_contacts": lambda kind="disc": sliding_contacts(state(run), kind)}


register("coulomb", NAMES, bind)
