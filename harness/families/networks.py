"""Contact networks: the contact forces of one run against those of another variant of the same
case (a DEM run against the exact static solution, `command = exact`), from the final states
(harness/final_state.py).

    contact_error(variant, kind='all')
                             max |F - F_variant| / max F_variant over the contacts of both runs;
                             kind: all | wall | disc
    contact_mismatch(variant)
                             the number of contacts closed (F > 0) in exactly one of the two runs

A contact absent from contacts.tsv, or marked open, has force 0.  Pairs of two held bodies
(held discs or walls) are left out: the exact solver leaves them out (their force is not
determined by the free discs), so a DEM run's forces between held discs would otherwise
count as errors.
"""
from ..errors import EvalError
from ..expressions import register, sibling_run
from ..final_state import state

CONTACT_KINDS = ("all", "wall", "disc")


def held(final, name, kind_of_b, is_b):
    """True for a held disc or a wall."""
    if is_b and kind_of_b == "wall":
        return True
    found = final.body().get(name)
    if found is None:
        raise EvalError(f"contacts.tsv names disc '{name}', which discs.tsv does not have ({final.folder})")
    return found[1]


def forces(final, kind="all"):
    """Contact key -> (force, kind), pairs of two held bodies left out."""
    def make():
        out = {}
        for c in final.contacts():
            if held(final, c["a"], c["kind"], False) and held(final, c["b"], c["kind"], True):
                continue
            if c["key"] in out:
                raise EvalError(f"{final.folder / 'contacts.tsv'}:{c['line']}: contact "
                                f"{c['key'][0]}-{c['key'][1]} listed twice")
            out[c["key"]] = (c["force"], c["kind"])
        return out
    everything = final.once("forces", make)
    if kind == "all":
        return everything
    return {k: v for k, v in everything.items() if v[1] == kind}


def _check_kind(kind, fname):
    if kind not in CONTACT_KINDS:
        raise EvalError(f"{fname}(): kind must be one of {', '.join(CONTACT_KINDS)}, not {kind!r}")


def contact_error(this, other, kind="all"):
    """max over both runs' contacts of |F_this - F_other| / max F_other."""
    _check_kind(kind, "contact_error")
    mine, theirs = forces(this, kind), forces(other, kind)
    keys = set(mine) | set(theirs)
    if not keys:
        raise EvalError(f"contact_error(): no {'' if kind == 'all' else kind + ' '}contacts in either run")
    largest = max((f for f, _ in theirs.values()), default=0.0)
    if not largest > 0:
        raise EvalError(f"contact_error(): the largest {'' if kind == 'all' else kind + ' '}"
                        f"contact force of the other run is {largest:g}, not positive")
    worst = max(abs(mine.get(k, (0.0,))[0] - theirs.get(k, (0.0,))[0]) for k in keys)
    return worst / largest


def contact_mismatch(this, other):
    """The number of contacts closed (F > 0) in exactly one of the two runs."""
    mine, theirs = forces(this), forces(other)
    closed = lambda table, k: table.get(k, (0.0,))[0] > 0
    return sum(closed(mine, k) != closed(theirs, k) for k in set(mine) | set(theirs))


# ---------------------------------------------------------------- the expression functions

NAMES = ("contact_error", "contact_mismatch")


def bind(run, sibling=None):
    """The family's functions, bound to run and its siblings.  This run's contacts are read
    first, then the other's; an error in the other's names the variant."""
    def both(variant, fname):
        other = state(sibling_run(sibling, variant, fname))
        this = state(run)
        forces(this)
        try:
            forces(other)
        except EvalError as exc:
            raise EvalError(f"{fname}('{variant}'): {exc}") from None
        return this, other

    def contact_error_(variant, kind="all"):
        return contact_error(*both(variant, "contact_error"), kind)

    def contact_mismatch_(variant):
        return contact_mismatch(*both(variant, "contact_mismatch"))

    return {"contact_error": contact_error_, "contact_mismatch": contact_mismatch_}


register("networks", NAMES, bind)
