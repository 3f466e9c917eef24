"""What the report shows, gathered once for both of its pages (markdown.py, html_page.py):
per case its runs (status, wall time, energy audit), its rendered figures (plots.py), its
verdicts and its error-against-cost section (cost_plot.py); and the stability tables.

Verdicts come from reports/summary.json when it is newer than the runs and the references of
a case, otherwise they are evaluated here.
"""
import gzip
from dataclasses import dataclass, field, replace
from pathlib import Path

from .. import files, sweep
from ..compare import evaluate_all
from ..errors import RunProblem
from ..gate import known, read_summary, skipped, tally
from ..references import reference_lines
from ..stability import read_tsv
from ..tables import read_harness_record, read_run_json
from .cost_plot import render_cost
from .plots import RASTER, FigureOut, render_figure


@dataclass
class CaseReport:
    case: object
    runs: list
    figures: list
    verdicts: list
    verdict_source: str
    cost: object = None          # CostOut: the error-against-cost section (below)


def case_counts(r):
    """A case's counts for the table of cases: runs, runs ok, passed, failed, KNOWN, skipped."""
    passed, failed = tally(r.verdicts)
    return {"runs": len(r.runs), "runs_ok": sum(x["status"] == "ok" for x in r.runs), "passed": passed,
            "failed": failed, "known": known(r.verdicts), "skipped": skipped(r.verdicts)}


def skip_groups(verdicts):
    """{(case, message): [check names]} of the skipped checks, as the gate table groups them."""
    groups = {}
    for v in verdicts:
        if v.skipped:
            groups.setdefault((v.case, v.message), []).append(v.check)
    return groups


# ---------------------------------------------------------------- runs

def run_status(folder):
    """One run's row: variant folder -> {status, wall, steps, dt, n_discs, message}."""
    folder = Path(folder)
    record = read_harness_record(folder) or {}
    try:
        info = read_run_json(folder)
    except RunProblem:
        info = None
    if info is None:
        status = "failed" if record else ("no run.json" if folder.is_dir() else "not run")
        return {"status": status, "wall": record.get("wall_seconds"), "steps": None, "dt": None,
                "n_discs": None, "message": record.get("cause", "")}
    status = info.get("status", "?")
    if record.get("returncode") not in (None, 0):
        status = f"{status}, exit {record['returncode']}"
    return {"status": status, "wall": info.get("wall_seconds", record.get("wall_seconds")),
            "steps": info.get("steps"), "dt": info.get("dt"), "n_discs": info.get("n_discs"),
            "message": info.get("message", "") or record.get("cause", ""),
            "energy": info.get("energy") if isinstance(info.get("energy"), dict) else None}


def run_rows(case, runs_root):
    return [dict(variant=v.name, **run_status(Path(runs_root) / case.name / v.name)) for v in case.variants]


# ---------------------------------------------------------------- verdicts

def _newest(paths):
    return max((p.stat().st_mtime for p in paths if p.is_file()), default=0.0)


def verdicts_for(case, checks, summary, saved, runs_root, store):
    """(verdicts, where they came from): summary.json if fresh for this case, else evaluated now."""
    mine = [c for c in checks if c.case == case.name]
    old = [v for v in saved if v.case == case.name]
    inputs = [Path(runs_root) / case.name / v.name / f for v in case.variants for f in ("run.json", "harness.json")]
    inputs += [Path(c.path) for c in mine]
    fresh = summary.is_file() and summary.stat().st_mtime >= _newest(inputs)
    if fresh and [v.check for v in old] == [c.name for c in mine]:
        return old, "reports/summary.json"
    return evaluate_all(mine, store), "evaluated by `report` (summary.json absent or older than the runs)"


def with_references(figure, checks):
    """The figure with its `reference` checks' values among its lines (a copy; the case's figure
    is left as it is)."""
    if not figure.references:
        return figure
    return replace(figure, lines=list(figure.lines) + reference_lines(figure, checks))


# An SVG above this is not shown on the page (a force network of thousands of lines, up to 8 MB):
# its PNG is, with a link to the SVG, which is kept gzipped (NAME.svg.gz, a tenth of the size;
# a browser does not open a gzipped SVG from a folder, a reader gunzips it to zoom in).
SVG_LINK_MAX = 512 * 1024
GZIP_LEVEL = 6


def pack_vector(out, svg):
    """The FigureOut of a figure just drawn to svg (its path whether drawn or not), its SVG gzipped
    as svg.gz when above SVG_LINK_MAX and a PNG shows it; an older svg.gz of it removed otherwise."""
    svg = Path(svg)
    packed = svg.with_name(svg.name + ".gz")
    if out.svg and out.png and out.svg.suffix == ".svg" and out.svg.stat().st_size > SVG_LINK_MAX:
        files.write_bytes(packed, gzip.compress(out.svg.read_bytes(), compresslevel=GZIP_LEVEL, mtime=0))
        files.remove(out.svg)
        out.svg = packed
    elif out.svg != packed:
        files.remove(packed)
    return out


def drawn_before(case, figure, figures_dir):
    """The FigureOut of a figure an earlier report drew (its files, where they exist)."""
    out = FigureOut(figure.name, figure.title, figure.paper)
    png, svg = (Path(figures_dir) / f"{case.name}_{figure.name}.{ext}"
                for ext in (RASTER.get(figure.kind, "png"), "svg"))
    packed = svg.with_name(svg.name + ".gz")
    out.png, out.svg = (png if png.is_file() else None), (svg if svg.is_file() else packed if packed.is_file() else None)
    if out.png is None and out.svg is None:
        out.notes.append("not drawn yet: run `harness report` (or validate) with this case")
    return out


def tables_removed(case, runs_root):
    """How many runs of case have had their tables removed by a validate after its report
    (compact.py: the realisations of its ensembles); 0 when none has."""
    removed = 0
    for v in case.variants:
        record = read_harness_record(Path(runs_root) / case.name / v.name) if v.ensemble else None
        removed += bool(record and (record.get("compacted") or {}).get("removed"))
    return removed


def _saved(summary):
    try:
        return read_summary(summary) if summary.is_file() else []
    except (ValueError, KeyError, TypeError):
        return []


def gather(cases, checks, store, runs_root, reports_dir, render=None):
    """A CaseReport per case: runs, rendered figures, verdicts.  render (a set of case names, or
    None for all): the cases whose figures are drawn anew; the others keep the figure files an
    earlier report drew (a report of one case leaves the rest of the report as it was)."""
    summary = Path(reports_dir) / "summary.json"
    saved, figures_dir = _saved(summary), files.make_dirs(Path(reports_dir) / "figures")
    reports = []
    for case in cases:
        verdicts, source = verdicts_for(case, checks, summary, saved, runs_root, store)
        removed = tables_removed(case, runs_root)
        if (render is None or case.name in render) and not removed:
            mine = [c for c in checks if c.case == case.name]
            figures = [pack_vector(render_figure(case, with_references(f, mine), store, figures_dir),
                                   Path(figures_dir) / f"{case.name}_{f.name}.svg") for f in case.figures]
        else:
            figures = [drawn_before(case, f, figures_dir) for f in case.figures]
            if removed:
                for f in figures:
                    f.notes.append(f"drawn by the report of the validate that made the runs; {removed} of them "
                                   f"have their tables removed since (harness/compact.py): `harness run {case.name}` "
                                   "makes them again")
        reports.append(CaseReport(case, run_rows(case, runs_root), figures, verdicts, source,
                                  cost_section(case, reports_dir, figures_dir)))
    return reports

# The energy audit of core/energy.c: work in = change of stored energy + each loss + imbalance.
ENERGY_COLUMNS = (("W walls", lambda e: e["work_walls"]), ("W gravity", lambda e: e["work_gravity"]),
                  ("dE kinetic", lambda e: e["kinetic"] - e["kinetic0"]),
                  ("dE elastic", lambda e: e["elastic"] - e["elastic0"]),
                  ("D dashpot", lambda e: e["dissipated_dashpot"]),
                  ("D friction", lambda e: e["dissipated_friction"]),
                  ("D global", lambda e: e["dissipated_global"]),
                  ("imbalance", lambda e: e["imbalance"]), ("relative", lambda e: e["relative_imbalance"]))


def energy_cells(audit):
    """The audit's terms in ENERGY_COLUMNS order (None where a term is missing or not finite)."""
    out = []
    for _, term in ENERGY_COLUMNS:
        try:
            out.append(term(audit))
        except (KeyError, TypeError):
            out.append(None)
    return out


@dataclass
class CostOut:
    figure: FigureOut = None
    rows: list = field(default_factory=list)
    cheapest: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)
    meta: list = field(default_factory=list)     # what the error means, when not the usual definition


def cost_section(case, reports_dir, figures_dir):
    """The error-against-cost section of a case from reports/sweeps/<case>/cost.tsv; None when the
    case declares no sweep."""
    if not case.sweeps:
        return None
    out = CostOut()
    selfconv = [s.name for s in case.sweeps if s.converge]
    if selfconv:
        out.meta.append(f"Self-convergence ({', '.join(selfconv)}): the error of these sweeps is the largest "
                        "|q - q_finest| / |q_finest| over their `converge =` quantities, against the finest "
                        "(most particle-steps) run of the same sweep — an error against the finest swept run, "
                        "not against a reference. The finest run itself has no error.")
    path = sweep.cost_path(Path(reports_dir) / "sweeps", case.name)
    try:
        out.rows = sweep.read_tsv(path)
    except (OSError, ValueError, IndexError) as exc:
        out.notes.append(f"no sweep results ({exc}); run `python3 -m harness cost {case.name}`")
        return out
    if case.path and Path(case.path).is_file() and path.stat().st_mtime < Path(case.path).stat().st_mtime:
        out.notes.append(f"{path.name} is older than {Path(case.path).name}: the sweeps may have changed "
                         f"since (run `python3 -m harness cost {case.name}`)")
    out.cheapest = sweep.cheapest(out.rows)
    out.figure = render_cost(case, out.rows, figures_dir)
    drawn = out.figure.svg or out.figure.png
    if drawn:
        pack_vector(out.figure, Path(drawn).with_suffix(".svg"))
    return out


# ---------------------------------------------------------------- stability (harness/stability.py)

STABILITY_LIMIT_HEADERS = [("case", "case"), ("variant", "variant"), ("estimate", "bound (dt)"),
                           ("single_spring", "2 sqrt(m/k)"), ("single_over_estimate", "old / bound"),
                           ("case_fraction", "case dt / bound"), ("limit_fraction", "limit / bound"),
                           ("limit_over_single", "limit / old"), ("in_target", "in [1, 1.25]"), ("cause", "first unstable trial")]
STABILITY_EXTREME_HEADERS = [("group", "group"), ("probe", "probe"), ("what", "what"), ("expect", "expect"),
                             ("exit", "exit"), ("steps", "steps"), ("e_out_over_in", "E_out/E_in"),
                             ("overlap_max", "overlap/r"), ("outcome", "outcome"), ("as_expected", "as expected")]
STABILITY_NOTE = ("Written by `harness stability` (every DEM variant, about 10 runs each) and by validate (the "
                  "first DEM variant of each case). *limit / bound* is the largest stable dt over ballast's estimate (the "
                  "contact-network bound of core/timestep.c); a safe and tight estimate has it in [1, 1.25]. "
                  "*old* is C&S's single-spring 2 sqrt(m/k). The criteria are in harness/stability.py.")
EXTREMES_NOTE = ("Extreme probes (cases/extremes/extremes.txt): each row a scene pushed to a limit of the physics; "
                 "*expect* says what is acceptable: a stable run within the stated criteria, or a stop with exit 1 "
                 "and a message.  A later model adds rows under its own group.")


def stability_tables(reports_dir):
    """[(title, note, headers, rows)] of the stability files that exist."""
    out = []
    for name, title, note, headers in (("stability.tsv", "Stability limits", STABILITY_NOTE, STABILITY_LIMIT_HEADERS),
                                       ("extremes.tsv", "Extreme probes", EXTREMES_NOTE, STABILITY_EXTREME_HEADERS)):
        path = Path(reports_dir) / name
        if path.exists():
            out.append((title, note, headers, read_tsv(path)))
    return out


def stability_digest(reports_dir):
    """A few sentences on reports/stability.tsv and extremes.tsv for the top of the report: how many
    limits were measured and how many lie in their target, how many probes behaved as declared,
    and which did not (none when neither file exists; the tables are on the stability page)."""
    out = []
    for title, _, _, rows in stability_tables(reports_dir):
        if title == "Stability limits":
            inside = [r for r in rows if r.get("in_target") == "yes"]
            fractions = sorted(float(r["limit_fraction"]) for r in rows if _number(r.get("limit_fraction")))
            spread = f", limit / bound from {fractions[0]:g} to {fractions[-1]:g}" if fractions else ""
            outside = [f"{r.get('case', '')}/{r.get('variant', '')}" for r in rows if r not in inside]
            out.append(f"Stability limits: {len(rows)} variant(s) bisected{spread}; {len(inside)} in [1, 1.25]"
                       + (f"; outside: {', '.join(outside)}" if outside else "") + ".")
        else:
            odd = [f"{r.get('group', '')}/{r.get('probe', '')}" for r in rows if r.get("as_expected") != "yes"]
            out.append(f"Extreme probes: {len(rows)}, {len(rows) - len(odd)} as declared, {len(odd)} finding(s)"
                       + (f": {', '.join(odd)}" if odd else "") + " (measurements, not a gate).")
    return out


def _number(text):
    try:
        return float(text) == float(text)
    except (TypeError, ValueError):
        return False
