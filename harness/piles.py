"""Pile quantities (Matuttis, Luding & Herrmann 2000): stress profiles of a pile row, contact
counts, and contact forces of one run against another variant of the same case.

These functions join the quantity expressions (compare.namespace); each reads the final
state of the run -- discs.tsv, contacts.tsv, stress.tsv, run.json -- only when called, and
once per run:

    pile_X(row=1)            X = (x - x0) / l of the discs of pile row `row`, sorted by x
    pile_S(component, row=1) the scaled stress of those discs, aligned with pile_X(row);
                             component: xx zz xz max min phi ratio
    middle(arr)              the middle element (mean of the two middle ones for even length)
    horizontal_contacts(xlo=0, xhi=1, row_min=1)
                             touching disc-disc contacts between free discs of rows >= row_min
                             whose normal is within 10 degrees of horizontal, X of the contact
                             point in [xlo, xhi] (a diamond network has none, a triangular one has)
    contact_error(variant, kind='all')
                             max |F - F_variant| / max F_variant over the contacts of both runs;
                             kind: all | wall | disc
    contact_mismatch(variant)
                             the number of contacts closed (F > 0) in exactly one of the two runs
    weight()                 W = |g| * (sum of m over the free discs)

The stress scale is that of MLH Sec. 3: S = sigma l / (m g), with l the base width of the
first pile of run.json (piles[0].width) and m g = W, the weight of the free discs (|g| from
run.json "gravity", 1 when absent).  S is COMPRESSION POSITIVE (stress.tsv is tension
positive): S_xx = -sxx l/W, S_zz = -szz l/W, S_xz = -sxz l/W, S_max = -smin l/W (the most
compressive principal value), S_min = -smax l/W, phi = the angle of the most compressive
principal axis (stress.tsv's phi + 90, in [0, 180) degrees), ratio = S_min / S_max.  The
pile row of a disc is the `row` column of discs.tsv (row 0 is the bottom row); x0 is the
left end of the base (piles[0].x0), so X runs from 0 to 1 across the base.

Contacts.  The force of a contact is fn + dn (elastic plus dashpot), 0 when the contact is
absent from contacts.tsv or marked open (open = 1, the exact solver's opened contacts).
Contacts are keyed by the unordered pair of body names.  Pairs of two held bodies (held
discs or walls) are left out of contact_error and contact_mismatch: the exact solver leaves
them out (their force is not determined by the free discs), so a DEM run's forces between
held discs would otherwise count as errors.  Open contacts are not touching, so
horizontal_contacts does not count them.

Anything missing or malformed (a file, a column, a number, no pile in run.json, a row with
no discs, zero weight) raises EvalError (errors.py), so a check built on it FAILs with the reason.
"""
import math
from pathlib import Path

import numpy as np

from .errors import EvalError, RunProblem

COMPONENTS = ("xx", "zz", "xz", "max", "min", "phi", "ratio")
CONTACT_KINDS = ("all", "wall", "disc")
HORIZONTAL_DEGREES = 10.0       # a contact normal within this of horizontal is "horizontal"

DISC_COLUMNS = ("id", "name", "x", "y", "r", "m", "fixed", "row")
CONTACT_COLUMNS = ("a", "b", "kind", "x", "y", "nx", "ny", "fn", "dn")
STRESS_COLUMNS = ("id", "sxx", "sxz", "szz", "smax", "smin", "phi")


# ---------------------------------------------------------------- tables

class Table:
    """A tab-separated file with a header line: text and float columns by name."""

    def __init__(self, path, needed):
        self.path = Path(path)
        try:
            lines = self.path.read_text(encoding="utf-8").splitlines()
        except OSError as exc:
            raise EvalError(f"{self.path.name} missing or unreadable: {self.path} ({exc.strerror})") from None
        if not lines:
            raise EvalError(f"{self.path}:1: {self.path.name} is empty (no header)")
        self.names = [n.strip() for n in lines[0].split("\t")]
        missing = [n for n in needed if n not in self.names]
        if missing:
            raise EvalError(f"{self.path}:1: column(s) missing from {self.path.name}: {', '.join(missing)}")
        self.rows, self.lines = [], []
        for number, line in enumerate(lines[1:], start=2):
            if not line.strip():
                continue
            fields = line.split("\t")
            if len(fields) != len(self.names):
                raise EvalError(f"{self.path}:{number}: {len(fields)} fields, header has {len(self.names)}")
            self.rows.append(fields)
            self.lines.append(number)

    def __len__(self):
        return len(self.rows)

    def has(self, name):
        return name in self.names

    def text(self, name):
        k = self.names.index(name)
        return [row[k].strip() for row in self.rows]

    def numbers(self, name):
        """A column as a float array; a field that is not a number names its line."""
        k = self.names.index(name)
        values = np.empty(len(self.rows))
        for i, row in enumerate(self.rows):
            try:
                values[i] = float(row[k])
            except ValueError:
                raise EvalError(f"{self.path}:{self.lines[i]}: {name} is not a number: '{row[k]}'") from None
        return values


def _number(value, what):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise EvalError(f"run.json: {what} is not a finite number: {value!r}")
    return float(value)


def _whole(value, fname, arg):
    """An integer argument (1 or 1.0, not 1.5)."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise EvalError(f"{fname}(): {arg} must be a whole number, not {value!r}") from None
    if not number.is_integer():
        raise EvalError(f"{fname}(): {arg} must be a whole number, not {value!r}")
    return int(number)


# ---------------------------------------------------------------- one run's final state

class FinalState:
    """The final state of one run folder, each file read when first needed."""

    def __init__(self, folder, info):
        self.folder = Path(folder)
        self.info = info
        self._tables = {}
        self._derived = {}

    def table(self, name, needed):
        if name not in self._tables:
            try:
                self._tables[name] = Table(self.folder / name, needed)
            except EvalError as exc:
                self._tables[name] = exc
        found = self._tables[name]
        if isinstance(found, EvalError):
            raise found
        return found

    def _once(self, key, make):
        if key not in self._derived:
            self._derived[key] = make()
        return self._derived[key]

    # -- run.json

    def pile(self):
        """(x0, width) of the first pile of run.json."""
        piles = self.info.get("piles")
        if not isinstance(piles, list) or not piles or not isinstance(piles[0], dict):
            raise EvalError("run.json has no piles (not a pile case?)")
        p = piles[0]
        for key in ("x0", "width"):
            if key not in p:
                raise EvalError(f"run.json: piles[0] has no '{key}'")
        x0, width = _number(p["x0"], "piles[0].x0"), _number(p["width"], "piles[0].width")
        if width <= 0:
            raise EvalError(f"run.json: piles[0].width is {width:g}, not positive")
        return x0, width

    def gravity(self):
        """|g| from run.json "gravity" [gx, gy], 1 when absent."""
        g = self.info.get("gravity")
        if g is None:
            return 1.0
        if not isinstance(g, list) or len(g) != 2:
            raise EvalError(f"run.json: gravity must be [gx, gy], not {g!r}")
        return math.hypot(_number(g[0], "gravity[0]"), _number(g[1], "gravity[1]"))

    # -- discs

    def discs(self):
        """discs.tsv as a dict of arrays (id and name as text)."""
        def make():
            t = self.table("discs.tsv", DISC_COLUMNS)
            d = {n: t.numbers(n) for n in ("x", "y", "r", "m", "fixed", "row")}
            d["id"], d["name"] = t.text("id"), t.text("name")
            d["free"] = d["fixed"] == 0
            return d
        return self._once("discs", make)

    def body(self):
        """Body name -> (row, held) for every disc."""
        def make():
            d = self.discs()
            return {name: (int(row), not free) for name, row, free in zip(d["name"], d["row"], d["free"])}
        return self._once("body", make)

    def weight(self):
        """W = |g| * (sum of m over the free discs)."""
        def make():
            d = self.discs()
            w = self.gravity() * float(np.sum(d["m"][d["free"]]))
            if not (math.isfinite(w) and w > 0):
                raise EvalError(f"the weight of the free discs is {w:g}, not positive ({self.folder / 'discs.tsv'})")
            return w
        return self._once("weight", make)

    def scale(self):
        """l / W: sigma times this is S (MLH Sec. 3), up to the sign."""
        return self.pile()[1] / self.weight()

    def X(self, x):
        x0, width = self.pile()
        return (np.asarray(x, dtype=float) - x0) / width

    def row_order(self, row, fname="pile_X"):
        """Indices (into discs.tsv) of the discs of pile row `row`, sorted by x."""
        row = _whole(row, fname, "row")
        d = self.discs()
        chosen = np.flatnonzero(d["row"] == row)
        if chosen.size == 0:
            raise EvalError(f"no disc in pile row {row} ({self.folder / 'discs.tsv'})")
        return chosen[np.argsort(d["x"][chosen], kind="stable")]

    def pile_X(self, row=1):
        return self.X(self.discs()["x"][self.row_order(row)])

    # -- stress

    def stress(self):
        """Disc id -> (S_xx, S_zz, S_xz, S_max, S_min, phi), compression positive, scaled."""
        def make():
            t = self.table("stress.tsv", STRESS_COLUMNS)
            s = -self.scale()
            cols = {n: t.numbers(n) for n in STRESS_COLUMNS[1:]}
            phi_c = np.mod(cols["phi"] + 90.0, 180.0)
            table = np.column_stack([s * cols["sxx"], s * cols["szz"], s * cols["sxz"],
                                     s * cols["smin"], s * cols["smax"], phi_c])
            return dict(zip(t.text("id"), table))
        return self._once("stress", make)

    def pile_S(self, component, row=1):
        if component not in COMPONENTS:
            raise EvalError(f"pile_S(): component must be one of {', '.join(COMPONENTS)}, not {component!r}")
        order = self.row_order(row, "pile_S")
        stress, ids = self.stress(), self.discs()["id"]
        missing = [ids[i] for i in order if ids[i] not in stress]
        if missing:
            raise EvalError(f"pile_S(): disc id(s) {', '.join(missing[:5])} missing from stress.tsv")
        rows = np.array([stress[ids[i]] for i in order])
        if component == "ratio":
            with np.errstate(all="ignore"):
                return rows[:, 4] / rows[:, 3]
        return rows[:, ("xx", "zz", "xz", "max", "min", "phi").index(component)].copy()

    def principal_axes(self):
        """Per free disc: x, y, r, S_max, S_min, phi (most compressive axis, degrees).

        S in MLH units (l / W) when run.json has a pile, else -sigma (unscaled); the second
        value says which (True when scaled).
        """
        d = self.discs()
        t = self.table("stress.tsv", STRESS_COLUMNS)
        try:
            s, scaled = -self.scale(), True
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

    # -- contacts

    def contacts(self):
        """contacts.tsv as a list of dicts: key (sorted pair), kind, x, y, nx, ny, force, open."""
        def make():
            t = self.table("contacts.tsv", CONTACT_COLUMNS)
            nums = {n: t.numbers(n) for n in ("x", "y", "nx", "ny", "fn", "dn")}
            opened = t.numbers("open") if t.has("open") else np.zeros(len(t))
            out = []
            for i, (a, b, kind) in enumerate(zip(t.text("a"), t.text("b"), t.text("kind"))):
                if kind not in ("disc", "wall"):
                    raise EvalError(f"{t.path}:{t.lines[i]}: contact kind must be disc or wall, not '{kind}'")
                is_open = opened[i] == 1
                out.append({"a": a, "b": b, "key": tuple(sorted((a, b))), "kind": kind,
                            "x": nums["x"][i], "y": nums["y"][i], "nx": nums["nx"][i], "ny": nums["ny"][i],
                            "open": is_open, "force": 0.0 if is_open else nums["fn"][i] + nums["dn"][i],
                            "line": t.lines[i]})
            return out
        return self._once("contacts", make)

    def _held(self, name, kind_of_b, is_b):
        """True for a held disc or a wall."""
        if is_b and kind_of_b == "wall":
            return True
        found = self.body().get(name)
        if found is None:
            raise EvalError(f"contacts.tsv names disc '{name}', which discs.tsv does not have ({self.folder})")
        return found[1]

    def forces(self, kind="all"):
        """Contact key -> (force, kind), pairs of two held bodies left out."""
        def make():
            out = {}
            for c in self.contacts():
                if self._held(c["a"], c["kind"], False) and self._held(c["b"], c["kind"], True):
                    continue
                if c["key"] in out:
                    raise EvalError(f"{self.folder / 'contacts.tsv'}:{c['line']}: contact "
                                    f"{c['key'][0]}-{c['key'][1]} listed twice")
                out[c["key"]] = (c["force"], c["kind"])
            return out
        everything = self._once("forces", make)
        if kind == "all":
            return everything
        return {k: v for k, v in everything.items() if v[1] == kind}

    def horizontal_contacts(self, xlo=0.0, xhi=1.0, row_min=1, row_max=None):
        row_min = _whole(row_min, "horizontal_contacts", "row_min")
        row_max = math.inf if row_max is None else _whole(row_max, "horizontal_contacts", "row_max")
        limit = math.sin(math.radians(HORIZONTAL_DEGREES))
        body = self.body()
        count = 0
        for c in self.contacts():
            if c["kind"] != "disc" or c["open"]:
                continue
            ends = []
            for name in (c["a"], c["b"]):
                if name not in body:
                    raise EvalError(f"contacts.tsv names disc '{name}', which discs.tsv does not have ({self.folder})")
                ends.append(body[name])
            if any(held or row < row_min or row > row_max for row, held in ends):
                continue
            if abs(c["ny"]) < limit and xlo <= float(self.X(c["x"])) <= xhi:
                count += 1
        return count


def state(run):
    """The FinalState of a Run (made once per Run object)."""
    found = getattr(run, "pile_state", None)
    if found is None:
        found = FinalState(run.folder, run.info)
        run.pile_state = found
    return found


# ---------------------------------------------------------------- two runs

def _check_kind(kind, fname):
    if kind not in CONTACT_KINDS:
        raise EvalError(f"{fname}(): kind must be one of {', '.join(CONTACT_KINDS)}, not {kind!r}")


def contact_error(this, other, kind="all"):
    """max over both runs' contacts of |F_this - F_other| / max F_other."""
    _check_kind(kind, "contact_error")
    mine, theirs = this.forces(kind), other.forces(kind)
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
    mine, theirs = this.forces(), other.forces()
    closed = lambda table, k: table.get(k, (0.0,))[0] > 0
    return sum(closed(mine, k) != closed(theirs, k) for k in set(mine) | set(theirs))


def middle(arr):
    """The middle element of an array; the mean of the two middle ones for even length."""
    arr = np.atleast_1d(np.asarray(arr, dtype=float)).reshape(-1)
    n = arr.size
    if n == 0:
        raise EvalError("middle(): empty array")
    return float(arr[n // 2]) if n % 2 else float(0.5 * (arr[n // 2 - 1] + arr[n // 2]))


# ---------------------------------------------------------------- the expression functions

def functions(run, sibling=None):
    """The pile functions of the quantity expressions, bound to run (and its siblings)."""
    def other_state(variant, fname):
        if sibling is None:
            raise EvalError(f"{fname}(): no other variants are available here")
        try:
            return state(sibling(variant))
        except RunProblem as problem:
            raise EvalError(f"{fname}(): variant '{variant}': {problem}") from None

    def in_other(fname, variant, fn):
        try:
            return fn()
        except EvalError as exc:
            raise EvalError(f"{fname}('{variant}'): {exc}") from None

    def which(variant, fname):
        """This run's state, or (variant given) another variant's."""
        return state(run) if variant is None else other_state(variant, fname)

    def pile_X(row=1, variant=None):
        return which(variant, "pile_X").pile_X(row)

    def pile_S(component, row=1, variant=None):
        return which(variant, "pile_S").pile_S(component, row)

    def horizontal_contacts(xlo=0, xhi=1, row_min=1, row_max=None):
        return state(run).horizontal_contacts(xlo, xhi, row_min, row_max)

    def contact_error_(variant, kind="all"):
        other = other_state(variant, "contact_error")
        this = state(run)
        this.forces()
        in_other("contact_error", variant, other.forces)
        return contact_error(this, other, kind)

    def contact_mismatch_(variant):
        other = other_state(variant, "contact_mismatch")
        this = state(run)
        this.forces()
        in_other("contact_mismatch", variant, other.forces)
        return contact_mismatch(this, other)

    def weight():
        return state(run).weight()

    return {"pile_X": pile_X, "pile_S": pile_S, "middle": middle,
            "horizontal_contacts": horizontal_contacts, "contact_error": contact_error_,
            "contact_mismatch": contact_mismatch_, "weight": weight}
