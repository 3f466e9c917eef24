"""Pile quantities (Matuttis, Luding & Herrmann 2000): the stress profile of a pile row and the
contacts of the pile's network, from one run's final state (harness/final_state.py).

The expression functions of the family:

    pile_X(row=1, variant=None)
                             X = (x - x0) / l of the discs of pile row `row`, sorted by x
    pile_S(component, row=1, variant=None)
                             the scaled stress of those discs, aligned with pile_X(row);
                             component: xx zz xz max min phi ratio
    middle(arr)              the middle element (mean of the two middle ones for even length)
    horizontal_contacts(xlo=0, xhi=1, row_min=1, row_max=None)
                             touching disc-disc contacts between free discs of rows row_min to
                             row_max whose normal is within 10 degrees of horizontal, X of the
                             contact point in [xlo, xhi] (a diamond network has none, a
                             triangular one has)
    weight()                 W = |g| * (sum of m over the free discs)

(variant: the same quantity in another variant of the case.)

The stress scale is that of MLH Sec. 3: S = sigma l / (m g), with l the base width of the
first pile of run.json (piles[0].width) and m g = W, the weight of the free discs (|g| from
run.json "gravity", 1 when absent).  S is COMPRESSION POSITIVE (stress.tsv is tension
positive): S_xx = -sxx l/W, S_zz = -szz l/W, S_xz = -sxz l/W, S_max = -smin l/W (the most
compressive principal value), S_min = -smax l/W, phi = the angle of the most compressive
principal axis (stress.tsv's phi + 90, in [0, 180) degrees), ratio = S_min / S_max.  The
pile row of a disc is the `row` column of discs.tsv (row 0 is the bottom row); x0 is the
left end of the base (piles[0].x0), so X runs from 0 to 1 across the base.  Open contacts
are not touching, so horizontal_contacts does not count them.

The report's profile and principal-axis figures (harness/report/plots.py) draw pile_X,
pile_S and principal_axes.  Anything missing or malformed (no pile in run.json, a row with
no discs, a disc missing from stress.tsv) raises EvalError, so a check built on it FAILs
with the reason.
"""
import math

import numpy as np

from ..errors import EvalError
from ..expressions import register, sibling_run
from ..final_state import finite_number, state

COMPONENTS = ("xx", "zz", "xz", "max", "min", "phi", "ratio")
HORIZONTAL_DEGREES = 10.0       # a contact normal within this of horizontal is "horizontal"
STRESS_COLUMNS = ("id", "sxx", "sxz", "szz", "smax", "smin", "phi")


def whole(value, fname, arg):
    """An integer argument (1 or 1.0, not 1.5)."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise EvalError(f"{fname}(): {arg} must be a whole number, not {value!r}") from None
    if not number.is_integer():
        raise EvalError(f"{fname}(): {arg} must be a whole number, not {value!r}")
    return int(number)


def pile(final):
    """(x0, width) of the first pile of run.json."""
    piles = final.info.get("piles")
    if not isinstance(piles, list) or not piles or not isinstance(piles[0], dict):
        raise EvalError("run.json has no piles (not a pile case?)")
    p = piles[0]
    for key in ("x0", "width"):
        if key not in p:
            raise EvalError(f"run.json: piles[0] has no '{key}'")
    x0, width = finite_number(p["x0"], "piles[0].x0"), finite_number(p["width"], "piles[0].width")
    if width <= 0:
        raise EvalError(f"run.json: piles[0].width is {width:g}, not positive")
    return x0, width


def scale(final):
    """l / W: sigma times this is S (MLH Sec. 3), up to the sign."""
    return pile(final)[1] / final.weight()


def X(final, x):
    """X = (x - x0) / l."""
    x0, width = pile(final)
    return (np.asarray(x, dtype=float) - x0) / width


def row_order(final, row, fname="pile_X"):
    """Indices (into discs.tsv) of the discs of pile row `row`, sorted by x."""
    row = whole(row, fname, "row")
    d = final.discs()
    chosen = np.flatnonzero(d["row"] == row)
    if chosen.size == 0:
        raise EvalError(f"no disc in pile row {row} ({final.folder / 'discs.tsv'})")
    return chosen[np.argsort(d["x"][chosen], kind="stable")]


def pile_X(final, row=1):
    return X(final, final.discs()["x"][row_order(final, row)])


def stress(final):
    """Disc id -> (S_xx, S_zz, S_xz, S_max, S_min, phi), compression positive, scaled."""
    def make():
        t = final.table("stress.tsv", STRESS_COLUMNS)
        s = -scale(final)
        cols = {n: t.numbers(n) for n in STRESS_COLUMNS[1:]}
        phi_c = np.mod(cols["phi"] + 90.0, 180.0)
        table = np.column_stack([s * cols["sxx"], s * cols["szz"], s * cols["sxz"],
                                 s * cols["smin"], s * cols["smax"], phi_c])
        return dict(zip(t.text("id"), table))
    return final.once("stress", make)


def pile_S(final, component, row=1):
    if component not in COMPONENTS:
        raise EvalError(f"pile_S(): component must be one of {', '.join(COMPONENTS)}, not {component!r}")
    order = row_order(final, row, "pile_S")
    by_id, ids = stress(final), final.discs()["id"]
    missing = [ids[i] for i in order if ids[i] not in by_id]
    if missing:
        raise EvalError(f"pile_S(): disc id(s) {', '.join(missing[:5])} missing from stress.tsv")
    rows = np.array([by_id[ids[i]] for i in order])
    if component == "ratio":
        with np.errstate(all="ignore"):
            return rows[:, 4] / rows[:, 3]
    return rows[:, ("xx", "zz", "xz", "max", "min", "phi").index(component)].copy()


def principal_axes(final):
    """Per free disc: x, y, r, S_max, S_min, phi (most compressive axis, degrees).

    S in MLH units (l / W) when run.json has a pile, else -sigma (unscaled); the second
    value says which (True when scaled).
    """
    d = final.discs()
    t = final.table("stress.tsv", STRESS_COLUMNS)
    try:
        s, scaled = -scale(final), True
    except EvalError:
        s, scaled = -1.0, False
    by_id = dict(zip(t.text("id"), zip(t.numbers("smin"), t.numbers("smax"), t.numbers("phi"))))
    axes = []
    for k in np.flatnonzero(d["free"]):
        if d["id"][k] not in by_id:
            raise EvalError(f"disc id {d['id'][k]} missing from stress.tsv")
        smin, smax, phi = by_id[d["id"][k]]
        axes.append((d["x"][k], d["y"][k], d["r"][k], s * smin, s * smax, (phi + 90.0) % 180.0))
    return axes, scaled


def horizontal_contacts(final, xlo=0.0, xhi=1.0, row_min=1, row_max=None):
    row_min = whole(row_min, "horizontal_contacts", "row_min")
    row_max = math.inf if row_max is None else whole(row_max, "horizontal_contacts", "row_max")
    limit = math.sin(math.radians(HORIZONTAL_DEGREES))
    body = final.body()
    count = 0
    for c in final.contacts():
        if c["kind"] != "disc" or c["open"]:
            continue
        ends = []
        for name in (c["a"], c["b"]):
            if name not in body:
                raise EvalError(f"contacts.tsv names disc '{name}', which discs.tsv does not have ({final.folder})")
            ends.append(body[name])
        if any(held or row < row_min or row > row_max for row, held in ends):
            continue
        if abs(c["ny"]) < limit and xlo <= float(X(final, c["x"])) <= xhi:
            count += 1
    return count


def middle(arr):
    """The middle element of an array; the mean of the two middle ones for even length."""
    arr = np.atleast_1d(np.asarray(arr, dtype=float)).reshape(-1)
    n = arr.size
    if n == 0:
        raise EvalError("middle(): empty array")
    return float(arr[n // 2]) if n % 2 else float(0.5 * (arr[n // 2 - 1] + arr[n // 2]))


# ---------------------------------------------------------------- the expression functions

NAMES = ("pile_X", "pile_S", "middle", "horizontal_contacts", "weight")


def bind(run, sibling=None):
    """The family's functions, bound to run (and its siblings)."""
    def which(variant, fname):
        """This run's final state, or (variant given) another variant's."""
        return state(run) if variant is None else state(sibling_run(sibling, variant, fname))

    def pile_X_(row=1, variant=None):
        return pile_X(which(variant, "pile_X"), row)

    def pile_S_(component, row=1, variant=None):
        return pile_S(which(variant, "pile_S"), component, row)

    def horizontal_contacts_(xlo=0, xhi=1, row_min=1, row_max=None):
        return horizontal_contacts(state(run), xlo, xhi, row_min, row_max)

    def weight():
        return state(run).weight()

    return {"pile_X": pile_X_, "pile_S": pile_S_, "middle": middle,
            "horizontal_contacts": horizontal_contacts_, "weight": weight}


register("piles", NAMES, bind)
