"""The command line: python3 -m harness {list,run,check,report,validate,rebaseline,sweep,cost,
stability,study,export,job,gather,plot,movie}.

Each command is a small function that loads the catalogue and references, picks the
cases, and hands over to runner, gate, report or rebaseline.  Exit statuses besides 0 and
1 (a check or run failed):

  2    errors in case.txt or .ref files (named file:line), unknown case names, bad options;
  3    the harness could not write under reports/ (or a reference file): disk full,
       read-only, a path through a regular file -- one line names the path and the OS's
       reason, and no temporary file is left (files.py);
  75   another harness is using the same reports folder (lock.py; 75 is sysexits'
       EX_TEMPFAIL: try again later);
  130  interrupted (Ctrl-C, SIGTERM).

Every command but `list` holds the reports folder's lock while it works.
"""
import argparse
import functools
import os
import shutil
import sys
import time
from contextlib import nullcontext
from pathlib import Path

from . import TIERS, bin_path, cases_root, reference_root, reports_root, runs_root
from . import catalogue, compact, export, extremes, files, known, pictures, points, references, stability
from . import study as studies
from . import families  # noqa: F401 -- registers every case family's expression functions
from . import sweep as sweeps
from . import sweep_grid
from .compare import RunStore, folder_locator
from .console import Transient
from .errors import Busy, CatalogueError, IniError, PictureError
from .gate import counts_text, gate
from .lock import reports_lock
from .rebaseline import rebaseline
from .report import budget, write_report
from .runner import STOPPED, jobs_for, run_all, sigterm_as_interrupt, unrecorded

USAGE_ERROR = 2
IO_ERROR = 3         # as the core's exit code for an I/O error
BUSY = 75            # sysexits.h EX_TEMPFAIL: another harness holds the reports folder


# ---------------------------------------------------------------- loading

def load_cases():
    return catalogue.load(cases_root())


def load_checks(cases):
    """Every reference check, validated against the catalogue."""
    checks = references.expand(references.load(reference_root()), cases)
    references.validate(checks, cases)
    sweeps.validate(cases, checks)
    return checks


def selected(args, cases):
    return catalogue.select(cases, getattr(args, "cases", []) or [], args.tier)


def default_store(cases=()):
    """The runs under reports/runs, with the ensembles of the cases (for over(), members())."""
    return RunStore(folder_locator(runs_root()), catalogue.ensembles_of(cases))


# ---------------------------------------------------------------- commands

def cmd_list(args):
    cases = selected(args, load_cases())
    rows = [("CASE", "TIER", "VARIANTS", "RUNTIME", "CHECKS")]
    rows += [(c.name, c.tier, c.variant_summary(), f"{c.runtime:g} s", c.checks) for c in cases]
    widths = [max(len(r[i]) for r in rows) for i in range(4)]
    for r in rows:
        print("  ".join(x.ljust(w) for x, w in zip(r, widths)) + "  " + r[4])
    print(f"{len(cases)} case(s), about {sum(c.runtime for c in cases):g} s of runs on the reference machine")
    return 0


def cmd_run(args):
    cases = selected(args, load_cases())
    if not cases:
        print("no cases selected", file=sys.stderr)
        return 1
    outcomes = run_all(jobs_for(cases, runs_root()), args.bin, args.jobs, sys.stdout, resume=args.resume)
    return runs_status(outcomes)


def runs_status(outcomes):
    """0 if every run is ok; IO_ERROR (said on stderr) if the harness could not prepare or
    record some run folder; else 1."""
    if unrecorded(outcomes):
        print(f"ballast-harness: {unrecorded(outcomes)}", file=sys.stderr)
        return IO_ERROR
    return 0 if all(o.ok for o in outcomes) else 1


def subset(args):
    """True when the command was given case names: it updates their part of the report only."""
    return bool(getattr(args, "cases", None))


def cmd_check(args, verdicts=None):
    """The gate; verdicts (a list), when given, gets the verdicts evaluated (validate's last line)."""
    all_cases = load_cases()
    checks = load_checks(all_cases)
    cases = selected(args, all_cases)
    refresh = None
    if args.tier == "full" or subset(args):
        refresh = functools.partial(refresh_known, checks, {c.name: c.tier for c in all_cases})

    def evaluated(found):
        if verdicts is not None:
            verdicts.extend(found)
        if refresh:
            refresh(found)
    return gate(references.for_cases(checks, cases), default_store(all_cases), reports_root(), sys.stdout,
                keep_others=subset(args), verbose=getattr(args, "verbose", False), on_verdicts=evaluated)


def refresh_known(checks, tiers, verdicts):
    """reference/known.tsv, the committed record of the KNOWN discrepancies: its rows of the KNOWN
    checks just evaluated get their value, date, commit and tier (harness/known.py).  Only a
    `check`/`validate --tier full` or one given case names calls this: a default-tier validate
    leaves the committed file alone."""
    path = known.record_path(reference_root())
    done = known.refresh(path, checks, verdicts, tiers)
    if done:
        print(f"{path}: refreshed {len(done)} KNOWN row(s) ({', '.join(c for _, c in done)}); commit it")


def cmd_report(args):
    """The report of the tier; given case names, their figures are drawn anew and the other cases
    that have runs keep what an earlier report drew, so the report stays whole.  A validate
    calling sets args.budget_validate and args.budget_stability: its account for the budget
    (report/budget.py)."""
    all_cases = load_cases()
    checks = load_checks(all_cases)
    cases, render = selected(args, all_cases), None
    if subset(args):
        render = {c.name for c in cases}
        tier = catalogue.select(all_cases, [], args.tier)
        tier_names = {c.name for c in tier}
        cases = [c for c in all_cases
                 if c.name in render or (c.name in tier_names and (runs_root() / c.name).is_dir())]
    write_report(cases, references.for_cases(checks, cases), default_store(all_cases), runs_root(), reports_root(),
                 sys.stdout, render, getattr(args, "budget_validate", None),
                 getattr(args, "budget_stability", None))
    return 0


def cmd_validate(args):
    """Run, check, cost, stability, report, then compact what the report no longer needs
    (compact.py; not with --keep-outputs).  Without -v the terminal gets a line or two per phase
    and every failure, KNOWN row and finding; the detail of the sweeps, the bisections and the
    probes goes to a Transient status line (console.py) and is in the report (issue 32, item 4)."""
    load_checks(load_cases())          # a broken reference file stops us before any run
    # the budget (report/budget.py): the validate's start, -j and tier; the stability runs' tally
    args.budget_validate = {"started": round(time.time(), 3), "jobs": args.jobs, "tier": args.tier}
    args.budget_stability = None
    run_status = cmd_run(args)
    verdicts = []
    check_status = cmd_check(args, verdicts)
    if not args.no_sweeps:
        cost_phase(args)
    if not args.no_stability:
        # the first DEM variant of each case and the extreme probes (all variants:
        # `harness stability`); a measurement shown in the report, not a gate
        stab = argparse.Namespace(**vars(args))
        # the extreme probes belong to no case: a validate of some cases runs them only when asked
        stab.one_per_case, stab.extremes_only = True, False
        stab.no_extremes = subset(args) and not args.extremes
        stab.cap, stab.tolerance = 20000, 0.01
        stab.quiet = not args.verbose
        stab.budget = args.budget_stability = {}
        try:
            cmd_stability(stab)
        except (RuntimeError, OSError, ValueError, CatalogueError) as exc:
            # a measurement for the report: its failure is said, not fatal to the gate
            print(f"stability: not measured: {exc}")
    cmd_report(args)
    if not args.keep_outputs:
        # the report is written: what no check, figure, report or resume reads again goes (compact.py)
        tally = compact.compact(selected(args, load_cases()), runs_root(),
                                None if args.no_sweeps else reports_root() / "sweeps")
        print(f"kept {compact.disk(reports_root()) / 1e6:.0f} MB under {reports_root()}: {tally.text()} "
              "(--keep-outputs keeps every file)")
    print(f"validate: {counts_text(verdicts)}; the report: {reports_root() / 'summary.md'}, "
          f"{reports_root() / 'index.html'}")
    return run_status or check_status


def cost_phase(args):
    """validate's sweeps: `cost`; without -v, each case's cheapest settings shown in passing (they
    are in the report and in cost.tsv) and a sweep point past its stability limit only counted."""
    if args.verbose:
        cmd_cost(args)
        return
    detail = Transient(sys.stdout)      # each case's cost summary (sweep.summary_text)
    runs = functools.partial(points.launch, resume=args.resume, limits=False)
    try:
        done = run_declared(args, detail, lambda jobs, binary, workers, _out: runs(jobs, binary, workers, sys.stdout))
    finally:
        detail.close()
    n_points = sum(len(rows) for _, rows in done)
    print(f"sweeps: {n_points} point(s) of {len(done)} case(s); each case's error against cost and cheapest settings "
          f"are in the report ({reports_root() / 'sweeps'}/<case>/cost.tsv)")


def cmd_rebaseline(args):
    cases = load_cases()
    case = catalogue.select(cases, [args.case])[0]
    return rebaseline(case, load_checks(cases), default_store(cases), sys.stdout)


def cmd_sweep(args):
    """One variant at every point of a --set grid (sweep_grid.py, the machinery `study --set` runs
    through): the table of its checks (sweep_<variant>.tsv, sweep_<variant>.svg) and, with
    --quantity, each quantity's value and error against the point's reference point
    (quantities_<variant>.tsv), under reports/sweeps/<case>/."""
    cases = load_cases()
    case = catalogue.select(cases, [args.case])[0]
    variant = sweep_variant(case, args.variant)
    keyed = sweep_grid.parse_sets(args.set)
    folder = reports_root() / "sweeps" / case.name
    jobs, extra = sweep_grid.plan(args.bin, variant.scene, variant.sets, keyed, lambda _, label: folder / label,
                                  owner=case.name, expected=case.runtime / max(len(case.variants), 1),
                                  command=variant.command)
    if extra:
        print(f"sweep over the time step: every point keeps the stages' simulated time ({' '.join(extra)})")
    outcomes = points.launch(jobs, args.bin, args.jobs, sys.stdout, args.resume)
    checks = [c for c in load_checks(cases) if c.case == case.name and c.run_variants == [variant.name]]
    measured = sweep_grid.measure(keyed, jobs, args.quantity or [])
    curves = []
    if checks:
        labels = [j.variant for j in jobs]
        results = sweep_grid.evaluate(checks, jobs, measured.costs)
        print(sweep_grid.checks_table(labels, checks, results))
        path = folder / f"sweep_{variant.name}.tsv"
        sweep_grid.write_checks_tsv(path, jobs, checks, results)
        print(f"wrote {path}")
        curves = sweep_grid.check_curves(labels, checks, results, measured.costs)
    else:
        print(f"no checks of {case.name} use only variant '{variant.name}'")
    if measured.quantities:
        print(sweep_grid.points_table(measured))
        path = folder / f"quantities_{variant.name}.tsv"
        sweep_grid.write_points_tsv(path, measured)
        print(f"wrote {path}")
        curves += sweep_grid.point_curves(measured, " (vs ref point)")
    figure = sweep_grid.draw(folder, f"sweep_{variant.name}", curves, "|q - ref| / |ref|")
    if figure:
        print(f"wrote {folder / figure}")
    return runs_status(outcomes)


def cmd_cost(args):
    """Every declared [sweep] of the selected cases: run, write reports/sweeps/<case>/cost.tsv."""
    run_declared(args, sys.stdout, functools.partial(points.launch, resume=args.resume))
    return 0


def run_declared(args, out, runs):
    """sweep.run_declared on the selected cases, its lines to out, its runs through runs (run_all's
    signature); the list of (case, rows)."""
    all_cases = load_cases()
    checks = load_checks(all_cases)
    return sweeps.run_declared(selected(args, all_cases), checks, args.bin, args.jobs, runs_root(),
                               reports_root() / "sweeps", out, runs)


def cmd_study(args):
    """Self-convergence of any scene file, with accuracy advice (study.py); writes under
    reports/studies/<scene-stem>-<n>/ or --out DIR."""
    return studies.study(args, reports_root(), sys.stdout)


def cmd_export(args):
    """The selected cases' runs as a GNU parallel job list and a Slurm array (export.py)."""
    cases = selected(args, load_cases())
    if not cases:
        raise CatalogueError("no cases selected")
    export.export(cases, args.bin, args.to, sys.stdout, args.engine)
    return 0


def cmd_job(args):
    """One run of an export folder, where parallel or Slurm started it."""
    return runs_status([export.run_job(args.dir, args.index, sys.stdout)])


def cmd_gather(args):
    """The finished runs of an export folder into reports/runs; 1 if some are not there."""
    gathered, kept, refused = export.gather(args.dir, load_cases(), args.bin, runs_root(), sys.stdout,
                                            reports_root())
    return 1 if refused else 0


def cmd_plot(args):
    """One state of any run folder drawn to scale with its force chains (pictures.py)."""
    return _picture(pictures.plot, args.run, at=args.at, out=args.out, colour=args.colour, since=args.since,
                    script=args.script)


def cmd_movie(args):
    """An animation of a run folder's snapshots (pictures.py)."""
    return _picture(pictures.movie, args.run, out=args.out, every=args.every, colour=args.colour,
                    since=args.since, script=args.script)


def _picture(fn, run, **options):
    try:
        said = fn(run, **options)
    except RuntimeError as exc:        # gnuplot missing or failing: not the input's fault
        print(f"ballast-harness: {exc}", file=sys.stderr)
        return 1
    for line in said:
        print(line)
    return 0


STABILITY_RUNS = "stability-runs"     # the trial runs of `stability`, under the reports root


def cmd_stability(args):
    """Stability limits per variant and the extreme probes (stability.py, extremes.py).  Their
    runs go to reports/stability-runs/, which is emptied first (kept with --resume) and removed
    when the command ends, except when it is interrupted: then --resume keeps what it holds."""
    for old in reports_root().glob(STABILITY_RUNS + ".*"):  # scratch folders of an older harness
        shutil.rmtree(old, ignore_errors=True)
    work = reports_root() / STABILITY_RUNS
    if not args.resume:
        files.remove_tree(work)
    files.make_dirs(work)
    interrupted = False
    try:
        return _stability(args, work)
    except KeyboardInterrupt:
        interrupted = True
        raise
    finally:
        if not interrupted:
            if getattr(args, "budget", None) is not None:    # validate's budget: the runs about to go
                args.budget.update(budget.stability_costs(work))
            shutil.rmtree(work, ignore_errors=True)


def _stability(args, work):
    """cmd_stability's work, its trial runs in the scratch folder work.  args.quiet (validate's
    default view): each bisection's limit and each probe's outcome shown in passing (Transient),
    then one line per part; a limit outside its target and a finding are printed in full."""
    status = 0
    quiet = getattr(args, "quiet", False)
    # shown in passing: the bisections' lines; kept: the batch's account of an interrupt (runner._stop)
    detail = Transient(sys.stdout, keep=lambda line: line.startswith(STOPPED)) if quiet else sys.stdout
    try:
        if not args.extremes_only:
            cases = selected(args, load_cases())
            targets = stability.targets_for(cases, getattr(args, "one_per_case", False))
            print(f"stability: bisecting {len(targets)} variant(s)", file=detail)
            limits = stability.measure_all(args.bin, targets, work, args.jobs, args.cap, args.tolerance, detail,
                                           args.resume)
            rows = stability.limit_rows(limits)
            stability.merge_tsv(rows, stability.LIMIT_COLUMNS, reports_root() / "stability.tsv", ("case", "variant"))
            status = 0 if all(r["in_target"] == "yes" for r in rows) else 1
            if quiet:
                _close(detail)
                outside = [f"{r['case']}/{r['variant']} ({r['limit_fraction']} x estimate)"
                           for r in rows if r["in_target"] != "yes"]
                print(f"stability: {len(rows)} limit(s) bisected, {len(rows) - len(outside)} in [1, 1.25] of the "
                      f"estimate" + (f"; outside: {', '.join(outside)}" if outside else "")
                      + f"; wrote {reports_root() / 'stability.tsv'}")
            else:
                print(f"wrote {reports_root() / 'stability.tsv'}")
        if not args.no_extremes:
            probes = extremes.load_probes(cases_root() / "extremes" / "extremes.txt")
            print(f"stability: {len(probes)} extreme probe(s)", file=detail)
            rows = extremes.run_probes(args.bin, probes, work, args.jobs, sys.stdout, args.resume)
            stability.merge_tsv(rows, extremes.EXTREME_COLUMNS, reports_root() / "extremes.tsv", ("probe",))
            findings = 0
            for r in rows:
                print(f"  {r['group']}/{r['probe']}: {r['outcome']}", file=detail)
                if r["as_expected"] != "yes":
                    findings += 1
                    if quiet:
                        _close(detail)
                        print(f"  finding {r['group']}/{r['probe']}: declared '{r['expect']}': {r['outcome']}")
                    else:
                        print(f"      finding: declared '{r['expect']}', behaved otherwise (above); a measurement "
                              "for docs/stability.md, not a gate")
            _close(detail)
            print(f"extreme probes: {len(rows) - findings} as declared, {findings} finding(s); the probes "
                  f"measure limits and never change the exit status; wrote {reports_root() / 'extremes.tsv'}")
    finally:
        _close(detail)
    return status


def _close(stream):
    """Erase a Transient's status line (sys.stdout has none)."""
    if isinstance(stream, Transient):
        stream.close()


def sweep_variant(case, name):
    if name:
        if not case.variant(name):
            raise CatalogueError(f"case '{case.name}' has no variant '{name}' "
                                           f"(has: {', '.join(case.variant_names())})")
        return case.variant(name)
    if len(case.variants) > 1:
        raise CatalogueError(f"case '{case.name}' has several variants: pick one with --variant "
                                       f"({', '.join(case.variant_names())})")
    return case.variants[0]


# ---------------------------------------------------------------- arguments

def parser():
    p = argparse.ArgumentParser(prog="ballast-harness",
                                description="ballast validation harness: run the cases, check them, report.",
                                epilog=f"exit status: 0 ok; 1 a check or a run failed; {USAGE_ERROR} bad input; "
                                       f"{IO_ERROR} the harness could not write under the reports folder; "
                                       f"{BUSY} another harness is using the reports folder; 130 interrupted")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    _selection(_command(sub, "list", cmd_list, "table of the cases: tier, variants, expected run time, what each checks",
                        writes=False), default_tier="full", names=False)
    _runs(_selection(_command(sub, "run", cmd_run, "run every variant of the selected cases")))
    check = _selection(_command(sub, "check", cmd_check,
                                "evaluate the checks, print the gate table, write summary.json and junit.xml"))
    check.add_argument("-v", "--verbose", action="store_true",
                       help="list every check's row (default: the failures, KNOWN and SKIP rows and the counts)")
    _selection(_command(sub, "report", cmd_report, "render figures, write reports/summary.md and reports/index.html"))
    validate = _runs(_selection(_command(sub, "validate", cmd_validate, "run + check + cost + report")))
    validate.add_argument("--no-sweeps", action="store_true", help="skip the declared sweeps (cost)")
    validate.add_argument("-v", "--verbose", action="store_true",
                          help="list every check's row and each sweep's, limit's and probe's line (default: the "
                               "failures, KNOWN and SKIP rows, the counts and a line or two per phase)")
    validate.add_argument("--extremes", action="store_true",
                          help="run the extreme probes even when cases are named (a validate of all cases runs them)")
    validate.add_argument("--no-stability", action="store_true",
                          help="skip the stability limits (first variant of each case) and extreme probes")
    validate.add_argument("--keep-outputs", action="store_true",
                          help="keep every file the runs wrote (default: once the report is written, a series.tsv "
                               "of 64 KiB or more is gzipped and the tables of ensemble realisations and sweep "
                               "points are removed: harness/compact.py)")
    rebase = _command(sub, "rebaseline", cmd_rebaseline, "rewrite the regression values of CASE from its current outputs")
    rebase.add_argument("case", metavar="CASE")
    sweep = _command(sub, "sweep", cmd_sweep, "run one variant at every point of a grid of --set values and "
                                              "tabulate its checks, their error and each point's cost")
    sweep.add_argument("case", metavar="CASE")
    sweep.add_argument("--set", required=True, action="append", metavar="KEY=V1,V2,...",
                       help="repeatable: several keys combine as a grid (KEY1,KEY2=V1,V2,... moves two keys "
                            "together); a dt sweep keeps the simulated time")
    sweep.add_argument("--variant", metavar="NAME", help="the variant to sweep (needed when the case has several)")
    sweep.add_argument("--quantity", action="append", metavar="EXPR",
                       help="repeatable: also each point's value of EXPR and its error against the point's "
                            "reference point, as `study --set` gives them (quantities_<variant>.tsv)")
    _runs(sweep)
    _runs(_selection(_command(sub, "cost", cmd_cost,
                              "run every declared [sweep] of the selected cases (error against cost); "
                              "needs their default runs; writes reports/sweeps/<case>/cost.tsv")))
    stab = _command(sub, "stability", cmd_stability,
                    "bisect the largest stable dt fraction of every DEM variant; run the extreme probes "
                    "(writes reports/stability.tsv and reports/extremes.tsv)")
    _runs(_selection(stab))
    stab.add_argument("--cap", type=int, default=20000, help="most cycles per stage of a trial (default 20000)")
    stab.add_argument("--tolerance", type=float, default=0.01, help="bisect until hi/lo <= 1 + this (default 0.01)")
    stab.add_argument("--extremes-only", action="store_true", help="only the probes of cases/extremes")
    stab.add_argument("--no-extremes", action="store_true", help="only the catalogue's limits")
    stab.add_argument("--one-per-case", action="store_true", help="only the first DEM variant of each case")
    stu = _command(sub, "study", cmd_study,
                   "run any scene file at a refined key (the step by default), give each quantity's observed "
                   "order, Richardson limit and error, and advise the step for a target accuracy "
                   "(docs/your-scene.md)")
    stu.add_argument("scene", metavar="SCENE", help="a scene file, anywhere (no case needed)")
    stu.add_argument("--quantity", action="append", metavar="EXPR",
                     help="repeatable: an expression over the run's outputs (default: the final energies "
                          "and each series column's last value)")
    stu.add_argument("--refine", default=None, metavar="KEY", help="the key refined (default settings.dt)")
    stu.add_argument("--base", type=float, default=None, metavar="V",
                     help="the coarsest value of the refined key (default: the scene's step, from ballast info; "
                          "needed for any other key)")
    stu.add_argument("--factor", type=float, default=None, help="each level's h over the last's (default 0.5)")
    stu.add_argument("--levels", type=int, default=None, help="number of levels (default 4, at least 3)")
    stu.add_argument("--no-midpoints", action="store_true",
                     help="skip the runs at the geometric midpoints between levels (they tell a smooth "
                          "quantity from one whose error jumps with h: envelope.py)")
    stu.add_argument("--target", type=float, action="append", metavar="REL",
                     help="repeatable: advise the largest h for |q - q*|/|q*| <= REL, and check it by a run")
    stu.add_argument("--stability", action="store_true",
                     help="also bisect the largest stable step (stability.py), printed beside the advice")
    stu.add_argument("--set", action="append", metavar="KEY=V1,V2,...",
                     help="repeatable: run the grid of these points instead of the refinement (KEY1,KEY2=V1,V2,... "
                          "moves two keys together); each point's quantities, cost and error against the "
                          "costliest point (sweep.tsv, error_cost.svg)")
    stu.add_argument("--out", type=Path, default=None, metavar="DIR",
                     help="the study's folder (default reports/studies/<scene-stem>-<n>, n the next free)")
    _runs(stu)
    exp = _command(sub, "export", cmd_export,
                   "write the selected cases' runs as a GNU parallel job list and a Slurm job-array "
                   "script into DIR (docs/ensembles.md)", writes=False)
    _selection(exp)
    exp.add_argument("--to", required=True, type=Path, metavar="DIR",
                     help="the export folder, seen at the same path by every machine that runs jobs")
    exp.add_argument("--bin", type=Path, default=None, help="the core executable (default $BALLAST_BIN or bin/ballast)")
    exp.add_argument("--engine", default="", metavar="ENGINE",
                     help="export another engine's runs of the cases (docs/engines.md: lammps), as `make "
                          "validate-peers` makes them; gather puts them in reports/peers/runs/ENGINE")
    job = _command(sub, "job", cmd_job, "run job INDEX of an export folder (what jobs.txt and slurm.sh call)",
                   writes=False)
    job.add_argument("dir", type=Path, metavar="DIR")
    job.add_argument("index", type=int, metavar="INDEX")
    gat = _command(sub, "gather", cmd_gather,
                   "copy the finished runs of an export folder into reports/runs, as `run` writes them")
    gat.add_argument("dir", type=Path, metavar="DIR")
    gat.add_argument("--bin", type=Path, default=None,
                     help="the core executable the runs must have been made by (default $BALLAST_BIN or bin/ballast)")
    _pictures(sub)
    return p


def _pictures(sub):
    """plot and movie: they read one run folder and write one file (no reports lock)."""
    plot = _command(sub, "plot", cmd_plot, "draw a run's discs to scale and its force chains (bar width "
                    "proportional to F_n) with gnuplot: the final state, or the snapshot nearest --at TIME "
                    "(docs/pictures.md)", writes=False)
    plot.add_argument("run", type=Path, metavar="RUN", help="a run folder (what bin/ballast run --out wrote)")
    plot.add_argument("--at", type=float, metavar="TIME",
                      help="draw the snapshot nearest this simulated time (snapshots/index.tsv)")
    plot.add_argument("--out", type=Path, metavar="FILE",
                      help="the picture, .svg or .png (default RUN/plot.svg, with --at RUN/plot.FFFFFF.svg)")
    movie = _command(sub, "movie", cmd_movie, "animate a run's snapshots: an animated GIF, or PNG frames in "
                     "a self-contained HTML player (docs/pictures.md)", writes=False)
    movie.add_argument("run", type=Path, metavar="RUN", help="a run folder with snapshots/")
    movie.add_argument("--out", type=Path, metavar="FILE", help="the movie, .gif or .html (default RUN/movie.gif)")
    movie.add_argument("--every", type=int, default=1, metavar="K",
                       help="every K-th snapshot from the first, and the last always (default 1)")
    for p in (plot, movie):
        p.add_argument("--colour", choices=pictures.COLOURS, default="rotation",
                       help="fill the discs by their rotation (default), speed, or grey")
        p.add_argument("--since", metavar="STAGE",
                       help="rotation since the start of this stage (the last snapshot at or before its first "
                            "cycle; default: since the first snapshot)")
        p.add_argument("--script", type=Path, metavar="FILE",
                       help="also write the gnuplot script, its data inline, to FILE")


def _command(sub, name, fn, text, writes=True):
    """A subcommand; writes: it writes under reports/, so it holds the reports lock."""
    p = sub.add_parser(name, help=text, description=text)
    p.set_defaults(fn=fn, writes=writes)
    return p


def _selection(p, default_tier="standard", names=True):
    if names:
        p.add_argument("cases", nargs="*", metavar="CASE", help="case names (default: all cases of tier <= --tier)")
    p.add_argument("--tier", choices=TIERS, default=default_tier, help=f"highest tier (default {default_tier})")
    return p


def _runs(p):
    p.add_argument("-j", "--jobs", type=int, default=os.cpu_count(), help="parallel runs (default: CPU count)")
    p.add_argument("--bin", type=Path, default=None, help="the core executable (default $BALLAST_BIN or bin/ballast)")
    p.add_argument("--resume", action="store_true",
                   help="keep every run whose folder holds a complete successful run of the same command line, "
                        "scene text, executable and files read (the scene's imports); run the rest (after an "
                        "interrupt)")
    return p


def main(argv=None):
    args = parser().parse_args(argv)
    if hasattr(args, "bin") and args.bin is None:
        args.bin = bin_path()
    # Every path given is taken from the caller's folder, once, here: the core runs in other
    # folders (runner.py), where a relative --out or --bin would name something else.
    for name, value in vars(args).items():
        if isinstance(value, Path):
            setattr(args, name, value.absolute())
    try:
        with sigterm_as_interrupt():          # SIGTERM stops the runs like Ctrl-C: exit 130
            with reports_lock(reports_root(), args.command) if args.writes else nullcontext():
                return args.fn(args)
    except (IniError, CatalogueError, PictureError) as exc:
        print(f"ballast-harness: {exc}", file=sys.stderr)
        return USAGE_ERROR
    except KeyboardInterrupt:
        print("\nballast-harness: interrupted", file=sys.stderr)
        return 130
    except Busy as exc:
        print(f"ballast-harness: {exc}", file=sys.stderr)
        return BUSY
    except OSError as exc:
        print(f"ballast-harness: {files.describe(exc)}", file=sys.stderr)
        return IO_ERROR


if __name__ == "__main__":
    sys.exit(main())
