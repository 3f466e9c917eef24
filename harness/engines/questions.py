"""harness/engines/questions.py -- the questions the agreement matrix answers with two engines
(issue 34, item 4): tables of named quantities, each row a case's test (or an ensemble's
statistic) evaluated in ballast and in the other engine, beside the paper's value.

The tables are data, reference/questions.txt:

    [table biaxial_phi]
    title = ...                       # the table's heading
    question = ...                    # what it asks
    columns = peak residual           # the quantities of every row, in order
    format = .2f                      # how a value is printed (Python format spec; default .4g)
    notes = ...                       # optional: what to read it with (repeatable)

    [row e020_m0]
    table = biaxial_phi
    label = e = 0.20, no rolling resistance, 200 kPa
    case = biaxial                    # any case of the catalogue, of any tier
    variant = m0_s200_e020            # the run the quantities are evaluated in
    ensembles = hump dip              # optional: ensembles its quantities read (their runs are made)
    reads = m0_s100 m0_s400           # optional: other variants its quantities read (phi_envelope)
    quantity.peak = phi_peak(rows=5)  # one expression per column (as a check's quantity)
    paper.peak = 24.4                 # optional, per column: the paper's value (a number or words)
    provenance = JYH Sec. 5.2 ...     # where the paper's values come from (required with paper.*)

A row's case need not be among the matrix's cases: its runs (the variant, and the first
--realisations of each named ensemble) are made in both engines all the same, so a table is
always answered whole (extra_cases).  Each cell is a number, or why there is none: NOT
EXPRESSIBLE in the engine, the run not made, the quantity's error.  Each column gets the other
engine's difference from ballast, and each engine's from the paper where the paper gives a number.
"""
import html
import math
from dataclasses import dataclass, field, replace
from pathlib import Path

from .. import catalogue, reference_root
from ..compare import quantity_in
from ..errors import CatalogueError, EvalError, IniError, RunNotExpressible, RunProblem, RunSkipped
from ..ini import parse_file

FILE = "questions.txt"
TABLE_KEYS = {"title", "question", "columns", "format", "notes"}
ROW_KEYS = {"table", "label", "case", "variant", "ensembles", "reads", "provenance"}
DEFAULT_FORMAT = ".4g"


@dataclass
class Row:
    name: str
    table: str
    label: str
    case: str
    variant: str
    quantities: dict                  # column -> expression
    paper: dict                       # column -> the paper's value as written ('' : none)
    provenance: str = ""
    ensembles: tuple = ()
    reads: tuple = ()                 # other variants of the case the quantities read
    path: str = ""
    line: int = 0

    def error(self, message):
        return IniError(self.path, self.line, message)


@dataclass
class Table:
    name: str
    title: str
    question: str
    columns: list
    format: str = DEFAULT_FORMAT
    notes: list = field(default_factory=list)
    rows: list = field(default_factory=list)
    path: str = ""
    line: int = 0


def load(path=None):
    """The tables of reference/questions.txt (or path), each with its rows, in file order;
    an IniError names file:line and the key of anything malformed."""
    path = Path(path) if path else Path(reference_root()) / FILE
    tables, rows = {}, []
    for s in parse_file(path):
        if s.kind == "table":
            if s.name in tables:
                raise s.error(f"[table {s.name}] given twice (first on line {tables[s.name].line})")
            s.check_keys(TABLE_KEYS)
            columns = s.require("columns").split()
            if len(set(columns)) != len(columns):
                raise s.error("'columns' names a column twice", s.entry("columns").line)
            fmt = s.get("format", DEFAULT_FORMAT)
            try:
                format(1.5, fmt)
            except ValueError:
                raise s.error(f"'format' is not a number format: '{fmt}'", s.entry("format").line) from None
            tables[s.name] = Table(s.name, s.require("title"), s.require("question"), columns, fmt,
                                   [e.value for e in s.all("notes")], path=str(path), line=s.line)
        elif s.kind == "row":
            quantities, paper = {}, {}
            for e in s.entries:
                head, _, column = e.key.partition(".")
                if head in ("quantity", "paper") and column:
                    (quantities if head == "quantity" else paper)[column] = e.value
                elif e.key not in ROW_KEYS:
                    known = ", ".join(sorted(ROW_KEYS | {"quantity.COLUMN", "paper.COLUMN"}))
                    raise s.error(f"unknown key '{e.key}' in [row] (known: {known})", e.line)
            for key in ROW_KEYS:
                s.entry(key)                                   # a repeated key is an error
            row = Row(s.name, s.require("table"), s.require("label"), s.require("case"), s.require("variant"),
                      quantities, paper, s.get("provenance", ""), tuple(s.get("ensembles", "").split()),
                      tuple(s.get("reads", "").split()), str(path), s.line)
            if paper and not row.provenance:
                raise s.error("a row with paper values needs 'provenance = ...' (where they come from)")
            rows.append((row, s))
        else:
            raise s.error(f"unknown section [{s.kind}] (known: [table], [row])")
    for row, s in rows:
        table = tables.get(row.table)
        if table is None:
            raise s.error(f"'table = {row.table}' names no [table] of {path.name} "
                          f"(known: {', '.join(tables) or 'none'})", s.entry("table").line)
        for key, book in (("quantity", row.quantities), ("paper", row.paper)):
            for column in book:
                if column not in table.columns:
                    line = next(e.line for e in s.entries if e.key == f"{key}.{column}")
                    raise s.error(f"'{key}.{column}': [table {table.name}] has no column '{column}' "
                                  f"(its columns: {' '.join(table.columns)})", line)
        missing = [c for c in table.columns if c not in row.quantities]
        if missing:
            raise s.error(f"[row {row.name}] needs 'quantity.{missing[0]} = ...' (a column of [table {table.name}])")
        if any(r.name == row.name for r in table.rows):
            raise s.error(f"[row {row.name}] given twice in [table {table.name}]")
        table.rows.append(row)
    return list(tables.values())


def validate(tables, cases):
    """Every row's case, variant and ensembles exist in the catalogue (an IniError at the row)."""
    by_name = {c.name: c for c in cases}
    for t in tables:
        for r in t.rows:
            case = by_name.get(r.case)
            if case is None:
                raise r.error(f"[row {r.name}]: 'case = {r.case}' is no case of the catalogue")
            for v in (r.variant,) + r.reads:
                if case.variant(v) is None:
                    raise r.error(f"[row {r.name}]: case {r.case} has no variant '{v}'")
            for e in r.ensembles:
                if case.ensemble(e) is None:
                    raise r.error(f"[row {r.name}]: case {r.case} has no [ensemble {e}]")


def chosen(tables, names=()):
    """The tables a matrix answers: all of them for a whole tier, and for named cases the tables
    with a row in one of them."""
    if not names:
        return list(tables)
    return [t for t in tables if any(r.case in names for r in t.rows)]


def extra_cases(tables, all_cases, selected, realisations=0):
    """The runs the tables read that the matrix's cases do not hold, as cases cut to those
    variants (the rows' variant and reads; each named ensemble to its first `realisations`
    seeds, 0: all)."""
    have = {c.name for c in selected}
    need = {}
    for t in tables:
        for r in t.rows:
            if r.case not in have:
                variants, ens = need.setdefault(r.case, (set(), set()))
                variants.update((r.variant,) + r.reads)
                ens.update(r.ensembles)
    out = []
    for case in all_cases:
        if case.name not in need:
            continue
        variants, ens = need[case.name]
        kept = [e for e in case.ensembles if e.name in ens]
        members = {m for e in kept for m in e.members}
        out.append(replace(case, variants=[v for v in case.variants if v.name in variants or v.name in members],
                           ensembles=kept))
    return catalogue.first_realisations(out, realisations)


# ---------------------------------------------------------------- the answers

def cell(store, row, column):
    """{value} or {why}: the row's quantity in one engine's runs."""
    try:
        return {"value": quantity_in(store, row.case, row.variant, row.quantities[column])}
    except RunNotExpressible as exc:
        return {"why": "NOT EXPRESSIBLE", "message": str(exc)}
    except RunSkipped as exc:
        return {"why": "SKIP", "message": str(exc)}
    except RunProblem as exc:
        return {"why": "not run", "message": str(exc)}
    except EvalError as exc:
        return {"why": "error", "message": str(exc)}


def paper_number(text):
    try:
        x = float(text)
    except (TypeError, ValueError):
        return None
    return x if math.isfinite(x) else None


def answer(tables, ballast, engine):
    """The tables' records, each row's cells in both engines (RunStores) and the differences."""
    out = []
    for t in tables:
        rows, spread = [], {c: {"engine_ballast": None, "ballast_paper": None, "engine_paper": None}
                            for c in t.columns}
        for r in t.rows:
            cells = {}
            for c in t.columns:
                b, e = cell(ballast, r, c), cell(engine, r, c)
                p = paper_number(r.paper.get(c))
                diff = {"engine_ballast": _minus(e, b.get("value")),
                        "ballast_paper": _minus(b, p), "engine_paper": _minus(e, p)}
                for k, d in diff.items():
                    if d is not None and (spread[c][k] is None or abs(d) > abs(spread[c][k])):
                        spread[c][k] = d
                cells[c] = {"paper": r.paper.get(c, ""), "ballast": b, "engine": e, **diff}
            rows.append({"row": r.name, "label": r.label, "case": r.case, "variant": r.variant,
                         "provenance": r.provenance, "cells": cells})
        out.append({"table": t.name, "title": t.title, "question": t.question, "columns": t.columns,
                    "format": t.format, "notes": t.notes, "rows": rows, "largest": spread})
    return out


def _minus(c, x):
    v = c.get("value")
    return None if v is None or x is None else v - x


def text(c, fmt):
    """A cell as printed: its value, or why it has none."""
    if "value" in c:
        return format(c["value"], fmt)
    return c["why"]


def signed(d, fmt):
    return "" if d is None else format(d, "+" + fmt.lstrip("+"))


def merged(new, old, order=()):
    """new answers with the other tables of old (an earlier matrix) kept, in the order of the
    table names `order` (reference/questions.txt's), the others after."""
    mine = {a["table"]: a for a in new}
    both = [a for a in old or [] if a.get("table") not in mine] + list(new)
    rank = {name: k for k, name in enumerate(order)}
    return sorted(both, key=lambda a: rank.get(a.get("table"), len(rank)))


# ---------------------------------------------------------------- pages

def markdown(answers, title):
    lines = []
    for a in answers:
        fmt = a["format"]
        lines += ["", f"## Question: {a['title']}", "", a["question"], ""]
        for note in a["notes"]:
            lines += [note, ""]
        papers = with_paper(a)
        head = ["row"]
        for c in a["columns"]:
            head += ([f"{c}: paper"] if c in papers else []) + [f"{c}: ballast", f"{c}: {title}",
                                                                 f"{c}: {title} − ballast"]
        lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        for r in a["rows"]:
            cells = [r["label"]]
            for c in a["columns"]:
                x = r["cells"][c]
                cells += ([x["paper"] or "-"] if c in papers else []) + [
                    text(x["ballast"], fmt), text(x["engine"], fmt), signed(x["engine_ballast"], fmt) or "-"]
            lines.append("| " + " | ".join(cells) + " |")
        lines += [""] + largest_lines(a, title) + [""]
        lines += ["Rows: " + "; ".join(f"{r['label']}: {r['case']}/{r['variant']}" for r in a["rows"]) + ".", ""]
        lines += why_lines(a, title)
        provenance = sorted({r["provenance"] for r in a["rows"] if r["provenance"]})
        if provenance:
            lines += ["Paper values: " + " / ".join(provenance), ""]
    return lines


def with_paper(a):
    """The columns for which some row gives the paper's value (the others get no paper column)."""
    return {c for c in a["columns"] if any(r["cells"][c]["paper"] for r in a["rows"])}


def largest_lines(a, title):
    """One line per column: the largest difference between the engines, and from the paper."""
    fmt = a["format"]
    out = []
    for c in a["columns"]:
        g = a["largest"][c]
        parts = [f"{title} − ballast {signed(g['engine_ballast'], fmt) or 'n/a'}"]
        if g["ballast_paper"] is not None or g["engine_paper"] is not None:
            parts += [f"ballast − paper {signed(g['ballast_paper'], fmt) or 'n/a'}",
                      f"{title} − paper {signed(g['engine_paper'], fmt) or 'n/a'}"]
        out.append(f"- {c}, the largest differences over the rows: " + ", ".join(parts))
    return out


def why_lines(a, title):
    """Why a cell has no number, once per distinct reason."""
    seen, out = set(), []
    for r in a["rows"]:
        for c in a["columns"]:
            for who, name in (("ballast", "ballast"), ("engine", title)):
                x = r["cells"][c][who]
                if "value" not in x and (name, x["message"]) not in seen:
                    seen.add((name, x["message"]))
                    out.append(f"- {r['label']} in {name}: {x['why']}: {x['message'][:300]}")
    return out + ([""] if out else [])


def html_part(answers, title):
    esc = lambda s: html.escape(str(s))
    out = []
    for a in answers:
        fmt = a["format"]
        out.append(f"<h2 id=\"question-{esc(a['table'])}\">Question: {esc(a['title'])}</h2><p>{esc(a['question'])}</p>")
        out += [f"<p>{esc(n)}</p>" for n in a["notes"]]
        papers = with_paper(a)
        out.append("<table><tr><th rowspan=\"2\">row</th>" +
                   "".join(f"<th colspan=\"{4 if c in papers else 3}\">{esc(c)}</th>" for c in a["columns"]) +
                   "</tr><tr>" + "".join(("<th>paper</th>" if c in papers else "") + f"<th>ballast</th><th>{esc(title)}"
                                         f"</th><th>{esc(title)} − ballast</th>" for c in a["columns"]) + "</tr>")
        for r in a["rows"]:
            tds = [f"<td title=\"{esc(r['case'] + '/' + r['variant'])}\">{esc(r['label'])}</td>"]
            for c in a["columns"]:
                x = r["cells"][c]
                tds += [f"<td>{esc(x['paper'] or '-')}</td>"] if c in papers else []
                for who in ("ballast", "engine"):
                    y = x[who]
                    cls = "" if "value" in y else " class=\"nx\""
                    tds.append(f"<td{cls} title=\"{esc(y.get('message', ''))}\">{esc(text(y, fmt))}</td>")
                tds.append(f"<td>{esc(signed(x['engine_ballast'], fmt) or '-')}</td>")
            out.append("<tr>" + "".join(tds) + "</tr>")
        out.append("</table><ul>" + "".join(f"<li>{esc(s[2:])}</li>" for s in largest_lines(a, title)) + "</ul>")
        why = why_lines(a, title)
        if why:
            out.append("<ul>" + "".join(f"<li>{esc(s[2:])}</li>" for s in why if s) + "</ul>")
        provenance = sorted({r["provenance"] for r in a["rows"] if r["provenance"]})
        if provenance:
            out.append("<p>Paper values: " + esc(" / ".join(provenance)) + "</p>")
    return out


def check_loaded(cases):
    """load() and validate() as the matrix calls them: CatalogueError for a missing file."""
    path = Path(reference_root()) / FILE
    if not path.exists():
        raise CatalogueError(f"{path}: missing (the agreement matrix's questions)")
    tables = load(path)
    validate(tables, cases)
    return tables
