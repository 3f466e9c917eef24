"""harness/engines/matrix.py -- the agreement matrix: the catalogue's cases through ballast and
another engine, gated by the same references, side by side (`make validate-peers`).

    /usr/bin/python3 -m harness.engines.matrix [CASE ...] [--tier standard] [--engine lammps]
        [-j N] [--resume] [--realisations N]

1. ballast's runs of the selected cases, into reports/runs as `harness run` makes them (kept
   when they are already there with the same identity: --resume's rule, always);
2. the engine's runs of every variant, command ENGINE:COMMAND (harness/engines/run.py),
   into reports/peers/runs/ENGINE/<case>/<variant>, through the same runner (--resume keeps
   the finished ones, as for any batch);
3. every check of those cases (reference/*.ref) evaluated on each engine's runs
   (compare.evaluate_check): PASS, FAIL, KNOWN, SKIP, or for the engine NOT EXPRESSIBLE;
4. the questions of reference/questions.txt (harness/engines/questions.py): tables of named
   quantities, each row a test evaluated in both engines beside the paper's value; their runs
   are made in both engines when the cases above do not hold them (a table is answered whole);
5. reports/peers/index.md, index.html and matrix.json: the questions' tables, per case its cost
   in each engine (particle-steps, seconds), then check by check both verdicts and values.
   Given case names, only their part of an existing matrix is replaced, and only the questions
   with a row in one of them are answered again.

Ensembles: --realisations N runs the first N seeds of every [ensemble] in both engines and
evaluates the ensemble checks over those N in both (stated in the report); 0 runs them all.
The exit status is 0 when the matrix was written (a disagreement is a finding, not an error of
the command), 2 for bad arguments, 3 when it could not write, 75 when busy, 130 interrupted.
"""
import argparse
import html
import json
import math
import os
import sys
from dataclasses import replace
from pathlib import Path

from .. import TIERS, bin_path, cases_root, reports_root, runs_root
from .. import catalogue, files, references
from .. import families  # noqa: F401 -- registers every case family's expression functions
from ..compare import RunStore, evaluate_check, folder_locator
from ..errors import Busy, CatalogueError, IniError
from ..lock import reports_lock
from ..runner import jobs_for, run_all, sigterm_as_interrupt
from ..tables import read_run_json
from . import questions
from .driver import engines

DEFAULT_REALISATIONS = 10     # per ensemble in the matrix (docs/engines.md: the full ones in the full tier)


def peers_root(reports=None):
    return Path(reports or reports_root()) / "peers"


def engine_jobs(engine, cases, root):
    """One Job per variant in the engine: command ENGINE:COMMAND, into root/<case>/<variant>."""
    return [replace(j, command=f"{engine}:{j.command}") for j in jobs_for(cases, root)]


def cost_of(folder):
    """(particle-steps, seconds) of one run folder: run.json's n_discs x steps and, for ballast,
    its wall_seconds; for an engine run the engine's own loop time (engine_seconds); None for a
    run that could not be read or was not made."""
    try:
        info = read_run_json(folder)
    except Exception:
        return None
    if info.get("status") != "ok":
        return None
    steps, n = info.get("steps") or 0, info.get("n_discs") or 0
    seconds = info.get("engine_seconds", info.get("wall_seconds"))
    return float(n) * float(steps), float(seconds or 0.0)


def case_cost(case, root):
    ps = sec = 0.0
    made = 0
    for v in case.variants:
        c = cost_of(Path(root) / case.name / v.name)
        if c:
            ps, sec, made = ps + c[0], sec + c[1], made + 1
    return {"particle_steps": ps, "seconds": sec, "runs": made, "variants": len(case.variants)}


def stores(cases, runs, engine_runs):
    """(ballast's RunStore, the engine's) over the cases' runs, their ensembles as run."""
    ens = catalogue.ensembles_of(cases)
    return RunStore(folder_locator(runs), ens), RunStore(folder_locator(engine_runs), ens)


def evaluate(checks, cases, runs, engine_runs):
    """[(check, ballast verdict, engine verdict)] for every check of the cases."""
    ballast, other = stores(cases, runs, engine_runs)
    return [(c, evaluate_check(c, ballast), evaluate_check(c, other, known_is_ours=False))
            for c in checks]


def tally(verdicts):
    out = {}
    for v in verdicts:
        out[v.result] = out.get(v.result, 0) + 1
    return out


def number(x):
    if x is None:
        return "-"
    if isinstance(x, list):
        return ", ".join(number(v) for v in x)
    if isinstance(x, float) and not math.isfinite(x):
        return str(x)
    return f"{x:.6g}" if isinstance(x, (int, float)) else str(x)


def seconds_text(s):
    return f"{s:.3g} s" if s else "-"


def rows_of(cases, triples, runs, engine_runs, engine):
    """The matrix's records: per case its costs and its checks' two verdicts."""
    out = []
    by_case = {}
    for c, b, e in triples:
        by_case.setdefault(c.case, []).append((c, b, e))
    for case in cases:
        items = by_case.get(case.name, [])
        refused = {}
        for v in case.variants:
            try:
                info = read_run_json(Path(engine_runs) / case.name / v.name)
            except Exception:
                continue
            if info.get("status") == "not_expressible":
                refused[v.name] = info.get("message", "")
        out.append({
            "case": case.name, "title": case.title, "tier": case.tier,
            "ballast": case_cost(case, runs), "engine": case_cost(case, engine_runs),
            "not_expressible": refused,
            "checks": [{"check": c.name, "variant": b.variant, "quantity": b.quantity,
                        "reference": b.reference, "tolerance": b.tolerance, "kind": b.kind,
                        "ballast": {"result": b.result, "value": b.value, "message": b.message},
                        "engine": {"result": e.result, "value": e.value, "message": e.message}}
                       for c, b, e in items]})
    return out


def markdown(rows, engine, title, realisations, totals, answers=()):
    t = title
    lines = [f"# ballast and {t}: the agreement matrix", "",
             f"Every check of the catalogue's cases (reference/*.ref) evaluated on ballast's runs and on "
             f"{t}'s runs of the same scenes (harness/engines, docs/engines.md). "
             f"NOT EXPRESSIBLE: the scene uses something {t} cannot express (the reason is given); "
             f"KNOWN: a documented discrepancy with a paper; a check where the two engines differ is "
             f"explained in its case's notes (cases/<case>/README.md).", ""]
    if realisations:
        lines += [f"Ensembles: the first {realisations} realisations of each [ensemble], in both engines, "
                  "and their checks over those (the full ensembles: --realisations 0).", ""]
    lines += ["| | " + " | ".join(sorted(set(totals["ballast"]) | set(totals["engine"]))) + " |"]
    keys = sorted(set(totals["ballast"]) | set(totals["engine"]))
    lines += ["|---|" + "---|" * len(keys)]
    lines += ["| ballast | " + " | ".join(str(totals["ballast"].get(k, 0)) for k in keys) + " |",
              f"| {t} | " + " | ".join(str(totals["engine"].get(k, 0)) for k in keys) + " |", ""]
    lines += questions.markdown(answers, t)
    lines += ["", "## The cases", "",
              "| case | checks | ballast | " + t + " | cost ballast (particle-steps, s) | cost " + t + " |",
              "|---|---|---|---|---|---|"]
    for r in rows:
        bt = tally_text([c["ballast"]["result"] for c in r["checks"]])
        et = tally_text([c["engine"]["result"] for c in r["checks"]])
        lines.append(f"| [{r['case']}](#{r['case']}) | {len(r['checks'])} | {bt} | {et} | "
                     f"{r['ballast']['particle_steps']:.3g}, {seconds_text(r['ballast']['seconds'])} | "
                     f"{r['engine']['particle_steps']:.3g}, {seconds_text(r['engine']['seconds'])} |")
    for r in rows:
        lines += ["", f"## {r['case']}", "", r["title"], ""]
        if r["not_expressible"]:
            reasons = sorted(set(r["not_expressible"].values()))
            lines += [f"Not expressible in {t} ({len(r['not_expressible'])} of {r['engine']['variants']} "
                      "variants): " + " / ".join(reasons), ""]
        lines += ["| check | variant | reference | ballast | value | " + t + " | value |",
                  "|---|---|---|---|---|---|---|"]
        for c in r["checks"]:
            lines.append(f"| {c['check']} | {c['variant']} | {number(c['reference'])} ({c['tolerance']}) | "
                         f"{c['ballast']['result']} | {number(c['ballast']['value'])} | "
                         f"{c['engine']['result']} | {number(c['engine']['value'])} |")
    return "\n".join(lines) + "\n"


def tally_text(results):
    counts = {}
    for r in results:
        counts[r] = counts.get(r, 0) + 1
    return ", ".join(f"{n} {k}" for k, n in sorted(counts.items())) or "-"


CLASS = {"PASS": "pass", "FAIL": "fail", "KNOWN": "known", "SKIP": "skip", "NOT EXPRESSIBLE": "nx"}


def html_page(rows, engine, title, realisations, totals, answers=()):
    t = html.escape(title)
    esc = lambda s: html.escape(str(s))
    out = ["<!doctype html><html><head><meta charset=\"utf-8\"><title>ballast and " + t + "</title>",
           "<style>body{font-family:sans-serif;max-width:80em;margin:auto}table{border-collapse:collapse}"
           "td,th{border:1px solid #ccc;padding:2px 6px;font-size:90%}.pass{background:#dfd}"
           ".fail{background:#fdd}.known{background:#ffd}.nx{background:#eee;color:#555}"
           ".skip{background:#eef}</style></head><body>",
           f"<h1>ballast and {t}: the agreement matrix</h1>",
           f"<p>Every check of the catalogue's cases evaluated on ballast's runs and on {t}'s runs of the "
           "same scenes (harness/engines, docs/engines.md). NOT EXPRESSIBLE: the scene uses something "
           f"{t} cannot express. A check where the engines differ is explained in its case's notes.</p>"]
    if realisations:
        out.append(f"<p>Ensembles: the first {realisations} realisations of each ensemble, in both engines.</p>")
    keys = sorted(set(totals["ballast"]) | set(totals["engine"]))
    out.append("<table><tr><th></th>" + "".join(f"<th>{esc(k)}</th>" for k in keys) + "</tr>")
    for who, label in (("ballast", "ballast"), ("engine", t)):
        out.append(f"<tr><td>{label}</td>" + "".join(f"<td>{totals[who].get(k, 0)}</td>" for k in keys) + "</tr>")
    out.append("</table>")
    out += questions.html_part(answers, title)
    out.append("<h2>Cases</h2><table><tr><th>case</th><th>checks</th><th>ballast</th>"
               f"<th>{t}</th><th>ballast particle-steps</th><th>ballast s</th><th>{t} particle-steps</th>"
               f"<th>{t} s</th></tr>")
    for r in rows:
        out.append(f"<tr><td><a href=\"#{esc(r['case'])}\">{esc(r['case'])}</a></td><td>{len(r['checks'])}</td>"
                   f"<td>{esc(tally_text([c['ballast']['result'] for c in r['checks']]))}</td>"
                   f"<td>{esc(tally_text([c['engine']['result'] for c in r['checks']]))}</td>"
                   f"<td>{r['ballast']['particle_steps']:.3g}</td><td>{r['ballast']['seconds']:.3g}</td>"
                   f"<td>{r['engine']['particle_steps']:.3g}</td><td>{r['engine']['seconds']:.3g}</td></tr>")
    out.append("</table>")
    for r in rows:
        out.append(f"<h2 id=\"{esc(r['case'])}\">{esc(r['case'])}</h2><p>{esc(r['title'])}</p>")
        if r["not_expressible"]:
            out.append(f"<p>Not expressible in {t} ({len(r['not_expressible'])} of {r['engine']['variants']} "
                       "variants): " + esc(" / ".join(sorted(set(r["not_expressible"].values())))) + "</p>")
        out.append("<table><tr><th>check</th><th>variant</th><th>reference</th><th>ballast</th><th>value</th>"
                   f"<th>{t}</th><th>value</th><th>{t}: why</th></tr>")
        for c in r["checks"]:
            b, e = c["ballast"], c["engine"]
            why = e["message"] if e["result"] != "PASS" else ""
            out.append(f"<tr><td>{esc(c['check'])}</td><td>{esc(c['variant'])}</td>"
                       f"<td>{esc(number(c['reference']))} ({esc(c['tolerance'])})</td>"
                       f"<td class=\"{CLASS.get(b['result'], '')}\">{esc(b['result'])}</td><td>{esc(number(b['value']))}</td>"
                       f"<td class=\"{CLASS.get(e['result'], '')}\">{esc(e['result'])}</td><td>{esc(number(e['value']))}</td>"
                       f"<td>{esc(why[:300])}</td></tr>")
        out.append("</table>")
    out.append("</body></html>")
    return "\n".join(out) + "\n"


def json_safe(x):
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, dict):
        return {k: json_safe(v) for k, v in x.items()}
    if isinstance(x, list):
        return [json_safe(v) for v in x]
    return x


def previous(engine, out_dir):
    """The matrix already in out_dir when it is of the same engine, else {}."""
    try:
        old = json.loads((Path(out_dir) / "matrix.json").read_text())
    except (OSError, ValueError):
        return {}
    return old if isinstance(old, dict) and old.get("engine") == engine else {}


def merged(rows, engine, out_dir):
    """rows with the other cases of the matrix already in out_dir (of the same engine) kept, in
    the catalogue's order: a run of some cases updates their part of the matrix only."""
    old = previous(engine, out_dir)
    if not old:
        return rows
    order = [c.name for c in catalogue.load(cases_root())]
    mine = {r["case"]: r for r in rows}
    kept = {r["case"]: r for r in old.get("cases", []) if r.get("case") not in mine}
    both = {**kept, **mine}
    return sorted(both.values(), key=lambda r: order.index(r["case"]) if r["case"] in order else len(order))


def write(rows, engine, title, realisations, out_dir, answers=()):
    totals = {"ballast": {}, "engine": {}}
    for r in rows:
        for c in r["checks"]:
            for who in ("ballast", "engine"):
                k = c[who]["result"]
                totals[who][k] = totals[who].get(k, 0) + 1
    out_dir = files.make_dirs(out_dir)
    files.write_text(out_dir / "index.md", markdown(rows, engine, title, realisations, totals, answers))
    files.write_text(out_dir / "index.html", html_page(rows, engine, title, realisations, totals, answers))
    files.write_text(out_dir / "matrix.json", json.dumps(json_safe(
        {"engine": engine, "title": title, "realisations": realisations, "totals": totals,
         "questions": list(answers), "cases": rows}), indent=1) + "\n")
    return totals


def main(argv=None):
    ap = argparse.ArgumentParser(prog="harness.engines.matrix", description=__doc__.split("\n\n")[0])
    ap.add_argument("cases", nargs="*", metavar="CASE")
    ap.add_argument("--tier", choices=TIERS, default="standard")
    ap.add_argument("--engine", default="lammps", choices=sorted(engines()))
    ap.add_argument("-j", "--jobs", type=int, default=os.cpu_count())
    ap.add_argument("--resume", action="store_true", help="keep the engine's finished runs of the same identity")
    ap.add_argument("--realisations", type=int, default=DEFAULT_REALISATIONS,
                    help=f"realisations per ensemble (default {DEFAULT_REALISATIONS}; 0: all)")
    ap.add_argument("--bin", type=Path, default=None)
    a = ap.parse_args(argv)
    binary = (a.bin or bin_path()).absolute()
    try:
        with sigterm_as_interrupt(), reports_lock(reports_root(), "validate-peers"):
            all_cases = catalogue.load(cases_root())
            checks = references.expand(references.load(), all_cases)
            references.validate(checks, all_cases)
            cases = catalogue.first_realisations(catalogue.select(all_cases, a.cases, a.tier), a.realisations)
            every_table = questions.check_loaded(all_cases)
            tables = questions.chosen(every_table, a.cases)
            extra = questions.extra_cases(tables, all_cases, cases, a.realisations)
            engine = engines()[a.engine]()
            problem = engine.problem()
            if problem:
                print(f"validate-peers: {engine.title} cannot run: {problem}", file=sys.stderr)
            runs = runs_root()
            print(f"validate-peers: ballast's runs of {len(cases)} case(s)"
                  + (f" and the questions' {sum(len(c.variants) for c in extra)} other run(s)" if extra else "")
                  + " (kept when already made)")
            run_all(jobs_for(cases + extra, runs), binary, a.jobs, sys.stdout, resume=True)
            engine_runs = peers_root() / "runs" / a.engine
            print(f"validate-peers: {engine.title}'s runs")
            run_all(engine_jobs(a.engine, cases + extra, engine_runs), binary, a.jobs, sys.stdout, resume=a.resume)
            mine = references.for_cases(checks, cases)
            members = {c.name: {v.name for v in c.variants} for c in cases}
            mine = [c for c in mine if all(v in members[c.case] for v in c.run_variants)]
            triples = evaluate(mine, cases, runs, engine_runs)
            rows = rows_of(cases, triples, runs, engine_runs, a.engine)
            answers = questions.answer(tables, *stores(cases + extra, runs, engine_runs))
            if a.cases:
                rows = merged(rows, a.engine, peers_root())
                answers = questions.merged(answers, previous(a.engine, peers_root()).get("questions"),
                                           [t.name for t in every_table])
            totals = write(rows, a.engine, engine.title, a.realisations, peers_root(), answers)
            print(f"validate-peers: ballast {tally_text_dict(totals['ballast'])}; "
                  f"{engine.title} {tally_text_dict(totals['engine'])}")
            print(f"wrote {peers_root() / 'index.md'} and index.html")
            return 0
    except (IniError, CatalogueError) as exc:
        print(f"validate-peers: {exc}", file=sys.stderr)
        return 2
    except Busy as exc:
        print(f"validate-peers: {exc}", file=sys.stderr)
        return 75
    except KeyboardInterrupt:
        print("\nvalidate-peers: interrupted", file=sys.stderr)
        return 130
    except OSError as exc:
        print(f"validate-peers: {files.describe(exc)}", file=sys.stderr)
        return 3


def tally_text_dict(d):
    return ", ".join(f"{n} {k}" for k, n in sorted(d.items())) or "no checks"


if __name__ == "__main__":
    sys.exit(main())
