"""One run's final state: discs.tsv, contacts.tsv, stress.tsv and run.json, each read when first
needed and once per run.

The expression functions of the families that look at the final state (harness/families:
piles, networks) and the report's pile figures read it through state(run), which makes one
FinalState per Run.  What a family derives from it (a pile's scaled stress, the contact
forces by pair) it keeps with once(), so that too is computed once per run.

Contacts.  The force of a contact is fn + dn (elastic plus dashpot), 0 when the contact is
marked open (open = 1, the exact solver's opened contacts).  Contacts are keyed by the
unordered pair of body names.

Anything missing or malformed (a file, a column, a number, zero weight) raises EvalError,
so a check built on it FAILs with the reason (a table validate removed after its report says
so: tables.removed_tables).  A table is read plain or gzipped (tables.read_text).
"""
import math
from pathlib import Path

import numpy as np

from .errors import EvalError
from .tables import read_harness_record, read_text, removed_tables

DISC_COLUMNS = ("id", "name", "x", "y", "r", "m", "fixed", "row")
CONTACT_COLUMNS = ("a", "b", "kind", "x", "y", "nx", "ny", "fn", "dn")


class Table:
    """A tab-separated file with a header line: text and float columns by name."""

    def __init__(self, path, needed):
        self.path = Path(path)
        try:
            lines = read_text(self.path).splitlines()
        except OSError as exc:
            removed = removed_tables(self.path.parent, read_harness_record(self.path.parent), self.path.name)
            raise EvalError(removed or f"{self.path.name} missing or unreadable: {self.path} ({exc.strerror})") from None
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


def finite_number(value, what):
    """A finite number of run.json as a float; EvalError naming what it is otherwise."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise EvalError(f"run.json: {what} is not a finite number: {value!r}")
    return float(value)


class FinalState:
    """The final state of one run folder, each file read when first needed."""

    def __init__(self, folder, info):
        self.folder = Path(folder)
        self.info = info
        self._tables = {}
        self._derived = {}

    def table(self, name, needed):
        """The Table of the file name (a failure to read it is kept and raised again)."""
        if name not in self._tables:
            try:
                self._tables[name] = Table(self.folder / name, needed)
            except EvalError as exc:
                self._tables[name] = exc
        found = self._tables[name]
        if isinstance(found, EvalError):
            raise found
        return found

    def once(self, key, make):
        """make(), computed the first time key is asked for and kept."""
        if key not in self._derived:
            self._derived[key] = make()
        return self._derived[key]

    def gravity(self):
        """|g| from run.json "gravity" [gx, gy], 1 when absent."""
        g = self.info.get("gravity")
        if g is None:
            return 1.0
        if not isinstance(g, list) or len(g) != 2:
            raise EvalError(f"run.json: gravity must be [gx, gy], not {g!r}")
        return math.hypot(finite_number(g[0], "gravity[0]"), finite_number(g[1], "gravity[1]"))

    def discs(self):
        """discs.tsv as a dict of arrays (id and name as text), and free = not held."""
        def make():
            t = self.table("discs.tsv", DISC_COLUMNS)
            d = {n: t.numbers(n) for n in ("x", "y", "r", "m", "fixed", "row")}
            d["id"], d["name"] = t.text("id"), t.text("name")
            d["free"] = d["fixed"] == 0
            return d
        return self.once("discs", make)

    def body(self):
        """Body name -> (row, held) for every disc."""
        def make():
            d = self.discs()
            return {name: (int(row), not free) for name, row, free in zip(d["name"], d["row"], d["free"])}
        return self.once("body", make)

    def weight(self):
        """W = |g| * (sum of m over the free discs)."""
        def make():
            d = self.discs()
            w = self.gravity() * float(np.sum(d["m"][d["free"]]))
            if not (math.isfinite(w) and w > 0):
                raise EvalError(f"the weight of the free discs is {w:g}, not positive ({self.folder / 'discs.tsv'})")
            return w
        return self.once("weight", make)

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
        return self.once("contacts", make)


def state(run):
    """The FinalState of a Run (made once per Run object)."""
    found = getattr(run, "final_state", None)
    if found is None:
        found = FinalState(run.folder, run.info)
        run.final_state = found
    return found
