"""The budget of a validate (issue 33, item 4): what each case of the report cost to run.

One row per case: how many runs it has, counted by kind -- its own [variant]s, the realisations
of its [ensemble]s, the points of its declared [sweep]s, and the trial runs of its stability
bisection (validate bisects the first DEM variant of each case) -- and, summed over them, the
particle-steps (steps x n_discs of each run.json) and the run seconds (each run.json's
wall_seconds: the core's time stepping; the runs overlap at -j N, so their sum is CPU time,
not the time waited).  The extreme probes belong to no case: a row of their own.  A run without
run.json (it failed before writing one, was never run, or was stopped) is counted in "no
run.json" and adds nothing: the sums are then lower bounds.  When the validate is known (its
start, -j, tier: `validate` passes them; `report` alone reuses those of the last validate's
budget.json), each case's span is the wall-clock time from the start of its first run to the
end of its last, over the runs this validate made -- a run ended when the runner wrote its
harness.json (its last write; compact.py keeps its time) and started the runner's wall_seconds
before -- and the total row has the validate's wall time to the writing of its report.

A run kept by --resume is counted with the seconds it took when it was made, not in the span.
The stability trials are deleted once measured (__main__.cmd_stability): validate tallies them
just before (stability_costs), and budget.json keeps the tally for a later `report`.

Written to reports/budget.json (machine-readable; summary.json stays the list of one record per
check that gate.read_summary and its readers expect), and as one table in summary.md and
index.html.
"""
import json
from pathlib import Path

from .. import files, sweep
from ..errors import RunProblem
from ..tables import read_harness_record, read_run_json
from .html_page import cell, esc, table_html

BUDGET_FILE = "budget.json"
EXTREMES_ROW = "(extreme probes)"       # the row of the runs that belong to no case
KINDS = ("variants", "realisations", "sweep_points", "stability_trials")
CAPTION = ("Runs by kind: the case's variants, ensemble realisations, declared sweep points and "
           "stability-bisection trials (the extreme probes: a row of their own). Particle-steps = steps x discs "
           "and run s = the core's wall_seconds (time spent stepping), each summed over the runs' run.json; "
           "at -j N the runs overlap, so run s is CPU time, not time waited. Span s: the wall clock from the "
           "start of the case's first run in this validate to the end of its last, across its phases (the "
           "other cases' runs in between included). A run with no run.json (failed, stopped, never run) is "
           "counted, its cost unknown: the sums are then marked >=. A run kept by --resume counts the seconds "
           "it took when it was made, and is not in the span.")


def empty():
    return {**{k: 0 for k in KINDS}, "runs": 0, "unknown": 0, "particle_steps": 0, "run_seconds": 0.0,
            "started": None, "ended": None}


def run_cost(folder):
    """(particle-steps, seconds, started, ended) of a run folder; particle-steps and seconds None
    when it has no readable run.json (or it lacks them), started/ended (epoch seconds) None when
    it has no harness.json with a wall_seconds."""
    folder = Path(folder)
    try:
        info = read_run_json(folder) if folder.is_dir() else None
    except RunProblem:
        info = None
    info = info if isinstance(info, dict) else None
    record = read_harness_record(folder) if folder.is_dir() else None
    record = record if isinstance(record, dict) else {}
    steps, n, seconds = ((info or {}).get(k) for k in ("steps", "n_discs", "wall_seconds"))
    ps = steps * n if isinstance(steps, int) and isinstance(n, int) else None
    seconds = float(seconds) if isinstance(seconds, (int, float)) and not isinstance(seconds, bool) else None
    # harness.json is the runner's last write (runner._record; compact.py keeps its time): its
    # modification time is when the run ended, less the runner's wall_seconds when it started
    wall = record.get("wall_seconds")
    if not isinstance(wall, (int, float)) or isinstance(wall, bool):
        return ps, seconds, None, None
    try:
        ended = (folder / "harness.json").stat().st_mtime
    except OSError:
        return ps, seconds, None, None
    return ps, seconds, ended - wall, ended


def add(row, kind, cost, since=None):
    """Count one run of kind into row; its times into the span when it started at or after since."""
    ps, seconds, started, ended = cost
    row[kind] += 1
    row["runs"] += 1
    if ps is None or seconds is None:
        row["unknown"] += 1
    else:
        row["particle_steps"] += ps
        row["run_seconds"] += seconds
    if since is not None and started is not None and started >= since:
        row["started"] = started if row["started"] is None else min(row["started"], started)
        row["ended"] = ended if row["ended"] is None else max(row["ended"], ended)


def run_folders(work):
    """Every run folder under work (one holding run.json or harness.json), sorted."""
    work = Path(work)
    if not work.is_dir():
        return []
    found = {p.parent for name in ("run.json", "harness.json") for p in work.rglob(name)}
    return sorted(found)


def stability_costs(work):
    """The tally of the stability runs under work (stability.py: limits/<case>/<variant>/trialNN;
    extremes.py: extremes/<probe>), to be taken before the folder is removed:
    {case or EXTREMES_ROW: {runs, unknown, particle_steps, run_seconds, started, ended}}."""
    work = Path(work)
    out = {}
    for folder in run_folders(work / "limits"):
        case = folder.relative_to(work / "limits").parts[0]
        add(out.setdefault(case, empty()), "stability_trials", run_cost(folder), since=0.0)
    for folder in run_folders(work / "extremes"):
        add(out.setdefault(EXTREMES_ROW, empty()), "stability_trials", run_cost(folder), since=0.0)
    return out


def _merge_stability(row, tally, since):
    for key in ("stability_trials", "runs", "unknown", "particle_steps", "run_seconds"):
        row[key] += tally.get(key) or 0
    for key, pick in (("started", min), ("ended", max)):
        t = tally.get(key)
        if since is not None and isinstance(t, (int, float)) and t >= since:
            row[key] = t if row[key] is None else pick(row[key], t)


def _finish(row):
    row["span_seconds"] = (round(row["ended"] - row["started"], 3)
                           if row["started"] is not None and row["ended"] is not None else None)
    row["run_seconds"] = round(row["run_seconds"], 6)
    return row


def budget(cases, runs_root, sweeps_root, validate=None, stability=None):
    """{"rows": one per case (and the extreme probes'), "total", "validate"}: see the module.
    validate: {started (epoch s), jobs, tier, wall_seconds} or None; stability: stability_costs()."""
    validate = dict(validate or {})
    since = validate.get("started")
    stability = stability or {}
    rows = []
    for case in cases:
        row = {"case": case.name, "tier": case.tier, **empty()}
        for v in case.variants:
            kind = "realisations" if v.ensemble else "variants"
            add(row, kind, run_cost(Path(runs_root) / case.name / v.name), since)
        if case.sweeps and sweeps_root is not None:
            for job in sweep.jobs(case, sweeps_root):
                add(row, "sweep_points", run_cost(job.out), since)
        _merge_stability(row, stability.get(case.name, {}), since)
        rows.append(_finish(row))
    if EXTREMES_ROW in stability:
        row = {"case": EXTREMES_ROW, "tier": "-", **empty()}
        _merge_stability(row, stability[EXTREMES_ROW], since)
        rows.append(_finish(row))
    total = {"case": "total", "tier": "", **empty()}
    for r in rows:
        for key in KINDS + ("runs", "unknown", "particle_steps", "run_seconds"):
            total[key] += r[key]
    _finish(total)
    total["span_seconds"] = validate.get("wall_seconds")
    for r in rows + [total]:
        del r["started"], r["ended"]
    return {"rows": rows, "total": total, "validate": validate or None,
            "stability": stability or None, "caption": CAPTION}


def saved(reports_dir):
    """budget.json of an earlier report, or {} when there is none or it cannot be read."""
    try:
        data = json.loads((Path(reports_dir) / BUDGET_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


def write(reports_dir, data):
    files.write_text(Path(reports_dir) / BUDGET_FILE, json.dumps(data, indent=1, allow_nan=False) + "\n")


# ---------------------------------------------------------------- rendering

HEADERS = ("case", "tier", "variants", "realisations", "sweep points", "stability trials", "no run.json",
           "particle-steps", "run s", "span s")


def cells(r):
    def num(x, fmt):
        return "-" if x is None else format(x, fmt)
    unknown = r["unknown"]
    lower = ">= " if unknown else ""
    return [r["case"], r["tier"], str(r["variants"]), str(r["realisations"]), str(r["sweep_points"]),
            str(r["stability_trials"]), str(unknown),
            lower + num(r["particle_steps"], ".4g"), lower + num(r["run_seconds"], ".4g"),
            num(r["span_seconds"], ".4g")]


def validate_text(data):
    v = data.get("validate") or {}
    if not v:
        return ("Not from a validate: no validate's start, -j or wall time is known (`harness validate` "
                "writes them), so no span.")
    wall = v.get("wall_seconds")
    return (f"The validate (tier {v.get('tier') or '-'}, -j {v.get('jobs')}) took "
            f"{'-' if wall is None else format(wall, '.4g')} s of wall-clock time to the writing of this report "
            f"(the total's span); its run s summed to {format(data['total']['run_seconds'], '.4g')} s."
            + (" Re-rendered by `harness report`: the validate's figures and stability tally are the last "
               "validate's (budget.json)." if v.get("rerendered") else ""))


def markdown_lines(data):
    lines = [f"## Budget ({BUDGET_FILE})", "", CAPTION, "", validate_text(data), "",
             "| " + " | ".join(HEADERS) + " |", "|" + "---|" * len(HEADERS)]
    for r in data["rows"] + [data["total"]]:
        c = cells(r)
        if r is data["total"]:
            c = [f"**{x}**" if x else x for x in c]
        lines.append("| " + " | ".join(str(x).replace("|", "\\|") for x in c) + " |")
    return lines + [""]


def html_section(data):
    """The budget's section of index.html."""
    rows = []
    for r in data["rows"] + [data["total"]]:
        c = cells(r)
        rows.append([cell(c[0]), cell(c[1])] + [cell(x, "num") for x in c[2:]])
    return (f"<section id=\"budget\"><h2>Budget</h2><p class=\"meta\">{esc(CAPTION)}</p>"
            f"<p>{esc(validate_text(data))} Machine-readable: <a href=\"{BUDGET_FILE}\">{BUDGET_FILE}</a>.</p>"
            + table_html(list(HEADERS), rows) + "</section>")
