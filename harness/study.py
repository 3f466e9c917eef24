"""`harness study SCENE`: self-convergence of a user's own scene, with accuracy advice.

Any scene file, anywhere: no case, reference or catalogue entry.  The study runs the scene at
h, h*f, h*f^2, ... (h the value of the refined key, --refine, default settings.dt; f = --factor,
default 1/2; --levels of them, default 4), evaluates each --quantity (the harness's expression
language over the run's outputs, compare.py; default: the final energies of run.json and the
last value of every series.tsv column) in every run, and for each quantity reports:

  * d_k = q_{k+1} - q_k, the differences between successive levels;
  * the pairwise observed orders p_k = log(|d_k| / |d_{k+1}|) / log(r), r = 1/f, and the
    least-squares order (slope of log|d_k| against log h_k);
  * a verdict (thresholds below; differences that change sign are never extrapolated:
    a convergent power law's differences keep one sign) and, when it converges, the Richardson limit
    q* = q_finest + d_last / (r^p - 1) with p the finest pairwise order, and each level's
    error |q_k - q*| / |q*|.

--target REL (repeatable) then gives, per converging quantity, the largest h predicted to meet
|q_h - q*| / |q*| <= REL by the error model e(h) = e_finest (h / h_finest)^p, with a margin
(ADVICE_MARGIN), its predicted cost (particle-steps and seconds, by a power-law fit of the
levels' costs against h), and RUNS that h once: the achieved error against q* is reported
beside the prediction.

Refining the step keeps each stage's simulated time (as `harness sweep` does): `ballast info`
gives each stage's cycles and dt at the scene's own settings, and every run sets
stage.NAME.time = cycles x dt for the stages given in cycles, and settings.force_dt = 1 (a
step past the estimate is a point to measure; the run-time guards say if it went unstable).
Other keys are refined as given: the base value comes from --base (the harness does not read
the scene's text; `ballast info` reports only the step).

Outputs go to reports/studies/<scene-stem>-<n>/ (n the next free number) or --out DIR, never
over an earlier study: runs/<label>/ (one run folder each), study.tsv, study.md and, when
gnuplot works, error.svg (error against h, log-log; error.gp beside it).  --stability adds
the largest stable step of the scene at its own settings (stability.py's bisection, its
trials under stability/), printed beside the estimate and the advised steps.

--set KEY=V1,V2,... (repeatable: a grid; KEY1,KEY2=V1,... couples keys on one axis; sweep_grid.py
parses and checks it, every point read by `ballast info` before any run) runs the grid of points
instead of the refinement: each point's quantities, cost, and error against its reference point
(the costliest point with the same values on every axis but the last), in sweep.tsv, study.md,
a short-column table and error_cost.svg (sweep_study below).  --resume continues
an interrupted study in its folder (the newest <scene-stem>-<n>, or --out DIR), keeping every
complete run of the same identity (runner.py).

The points, their runs and their cost are points.py's; the analysis, the errors against a
reference point, the tables' columns and the figures are error_cost.py's; the grid of --set is
sweep_grid.py's -- the same code `harness sweep CASE` and the declared sweeps run through.
"""
import math
import sys
from pathlib import Path

from . import core_info, envelope, files, points, stability, sweep_grid
from .error_cost import (ADVICE_MARGIN, MIN_LEVELS, ORDER_AGREE, P_MIN, advise, aligned, analyse, cost_model,
                         deviation, num, plot)
from .errors import CatalogueError, RunProblem
from .points import DT_KEYS
from .tables import load_run

STUDIES = "studies"
TSV_COLUMNS = ("quantity", "level", "h", "value", "difference", "pairwise_order", "error_est",
               "particle_steps", "wall_seconds", "status")
ADVICE_COLUMNS = ("quantity", "target", "h_advised", "predicted_error", "predicted_particle_steps",
                  "predicted_seconds", "achieved_value", "achieved_error", "met")
# The refinement's options (None on the command line = not given: --set refuses them when given).
REFINE_DEFAULTS = {"refine": "settings.dt", "factor": 0.5, "levels": 4}
# The advice's check run is made only when it costs at most this many times the finest level:
# a study's levels and midpoints cost ~3.5 x its finest level (1 + 1/2 + 1/4 ... and the
# midpoints' 1.41 + 0.71 + ...), so a check of up to 16 x stays within ~5 x the whole study; an
# advised step beyond it is far outside the range the levels measured (an extrapolation by a
# factor of 16 in cost) and is reported, not run.
CHECK_COST_CEILING = 16.0


# ---------------------------------------------------------------- folders and runs

def study_folder(root, scene, out, resume):
    """The study's folder: out, or root/studies/<stem>-<n> (n the next free number; with resume,
    the newest).  Refuses to write over an earlier study."""
    if out is not None:
        out = Path(out)
        if out.exists() and any(out.iterdir()) and not resume:
            raise CatalogueError(f"--out {out}: the folder exists and is not empty; a study never writes "
                                 "over another (give a new folder, or --resume to continue that study)")
        return out
    base, stem = Path(root) / STUDIES, Path(scene).stem
    taken = sorted(int(p.name[len(stem) + 1:]) for p in base.glob(f"{stem}-*")
                   if p.name[len(stem) + 1:].isdigit()) if base.is_dir() else []
    if resume:
        if not taken:
            raise CatalogueError(f"--resume: no earlier study of {stem} under {base}")
        return base / f"{stem}-{taken[-1]}"
    return base / f"{stem}-{(taken[-1] + 1) if taken else 1}"


def fmt_h(h):
    return repr(float(h))


def base_value(binary, scene, key, base):
    """The refined key's value at the scene's own settings: --base, or `ballast info` for the step."""
    if base is not None:
        return base
    if key not in DT_KEYS:
        raise CatalogueError(f"--refine {key}: give its value in the scene with --base (the harness reads "
                             "the step from `ballast info`, no other key)")
    info = core_info.query(binary, scene, [])
    value = info["dt"] if key == "settings.dt" else info.get("fraction", float("nan"))
    if not math.isfinite(value) or value <= 0:
        raise CatalogueError(f"cannot read the value of {key} from `ballast info {scene}`")
    return value


def level_jobs(scene, folder, levels, key, extra):
    """One runner Job per level (label, h): the scene with key = h (after the time keeping extra),
    in folder/runs/<label>."""
    return points.jobs([(label, [f"{key}={fmt_h(h)}"], folder / "runs" / label) for label, h in levels],
                       scene, extra=extra)


def default_quantities(folder):
    """The final energies of run.json and the last value of each series.tsv column."""
    try:
        run = load_run(folder)
    except RunProblem as problem:
        raise CatalogueError(f"no default quantities: the coarsest run failed ({problem})") from None
    out = [f"run('{k}')" for k in ("energy_kinetic", "energy_elastic") if k in run.info]
    return out + [f"last({c})" for c in run.columns if c not in ("cycle", "time")]


def run_points(args, scene, folder, jobs, extra, what, verb, out):
    """Make the study's folder, say what runs (what: the points; verb: what the points do to the
    step, when extra keeps the stages' time), run the points (parallel, resumable);
    (outcomes, the quantities: --quantity, or the defaults of the first point's run)."""
    files.make_dirs(folder)
    print(f"study of {scene}: {what} -> {folder}", file=out)
    if extra:
        print(f"{verb} the step: every run keeps the stages' simulated time ({' '.join(extra)})", file=out)
    outcomes = points.launch(jobs, args.bin, args.jobs, out, args.resume)
    return outcomes, list(args.quantity or []) or default_quantities(jobs[0].out)


# ---------------------------------------------------------------- the command

def study(args, reports_root, out=sys.stdout):
    scene = Path(args.scene).resolve()
    if not scene.is_file():
        raise CatalogueError(f"{args.scene}: no such scene file")
    if getattr(args, "set", None):
        return sweep_study(args, scene, reports_root, out)
    for name, default in REFINE_DEFAULTS.items():
        if getattr(args, name, None) is None:
            setattr(args, name, default)
    if args.levels < MIN_LEVELS:
        raise CatalogueError(f"--levels {args.levels}: at least {MIN_LEVELS} (two differences give one order)")
    if not 0 < args.factor < 1:
        raise CatalogueError(f"--factor {args.factor:g}: must lie between 0 and 1 (each level refines h)")
    if any(not t > 0 for t in args.target or []):
        raise CatalogueError("--target: a relative error above 0")
    key = args.refine
    base = base_value(args.bin, scene, key, args.base)
    extra = points.time_keeping(args.bin, scene, [], [key])
    folder = study_folder(reports_root, scene, args.out, args.resume)
    hs = [base * args.factor ** k for k in range(args.levels)]
    mids = [] if getattr(args, "no_midpoints", False) else envelope.midpoints(hs, args.factor)
    jobs = level_jobs(scene, folder, [(f"L{k}", h) for k, h in enumerate(hs)], key, extra)
    mid_jobs = level_jobs(scene, folder, [(f"M{k}", h) for k, h in enumerate(mids)], key, extra)
    points.refuse(args.bin, jobs + mid_jobs, [key])                        # before any run
    what = f"{key} = {', '.join(f'{h:.6g}' for h in hs)}" + (" and the midpoints between them" if mids else "")
    _, quantities = run_points(args, scene, folder, jobs + mid_jobs, extra, what, "refining", out)
    costs, values, why = points.measure(jobs, quantities)
    extra_points = {"M": (mids, points.measure(mid_jobs, quantities))}
    analyses = {}
    for expr in quantities:
        analyses[expr] = analyse(hs, values[expr], args.factor)
        if why[expr]:
            analyses[expr]["text"] += f": {why[expr]}"
        if mids:
            smoothness(analyses[expr], hs, values[expr], mids, extra_points["M"][1][1][expr])
    rough = [e for e in quantities if analyses[e].get("rough")]
    if rough:
        extra_points["S"] = envelope_samples(args, scene, folder, key, extra, hs, rough, out)
        for expr in rough:
            bounded(analyses[expr], hs, values[expr], extra_points, expr)
    advice = advice_rows(args, scene, folder, key, extra, hs, quantities, analyses, costs, out)
    limit = stability_limit(args, scene, folder, out) if getattr(args, "stability", False) else None
    write_outputs(folder, scene, key, hs, quantities, values, analyses, costs, advice, args, out, limit)
    write_extra_points(folder, quantities, extra_points)
    return 0


# ---------------------------------------------------------------- not smooth in h (envelope.py)

def smoothness(a, hs, qs, mids, qmids):
    """Marks the analysis a 'rough' (a candidate for envelope.bound) when its quantity is not a
    smooth power of h: a converging verdict whose midpoints depart from the power law by more
    than envelope.SMOOTH_TOLERANCE, or differences that change sign (analyse says so)."""
    if a["verdict"] == "converging":
        deps = envelope.departures(hs, qs, a, mids, qmids)
        a["departures"] = deps
        if not envelope.smooth(deps):
            a["rough"] = ("its midpoints depart from the power law through the levels by "
                          + ", ".join("-" if d is None else f"{d:.2g}" for d in deps)
                          + f" of the difference between their neighbours (smooth: <= {envelope.SMOOTH_TOLERANCE:g})")
    elif a["verdict"] == "asymptotic?" and "change sign" in a["text"]:
        a["rough"] = "its differences change sign"


def envelope_samples(args, scene, folder, key, extra, hs, rough, out):
    """The extra samples of envelope.samples, run once for every rough quantity; (hs, measured)."""
    hs_s = envelope.samples(hs) if len(hs) >= 3 else []
    jobs = level_jobs(scene, folder, [(f"S{k}", h) for k, h in enumerate(hs_s)], key, extra)
    if jobs:
        print(f"not smooth in h ({len(rough)} quantit{'y' if len(rough) == 1 else 'ies'}): "
              f"{len(jobs)} more runs to sample the error's envelope", file=out)
        points.launch(jobs, args.bin, args.jobs, out, args.resume)
    return hs_s, points.measure(jobs, rough)


def bounded(a, hs, qs, extra_points, expr):
    """Replaces a rough quantity's verdict by its envelope (envelope.bound over the levels, the
    midpoints and the samples): 'bounded' with q*, the order and each level's error against q*,
    or 'not smooth' with the reason there is no bound."""
    all_h, all_q = list(hs), list(qs)
    for hs_x, (_, values, _) in extra_points.values():
        if expr in values:
            all_h += list(hs_x)
            all_q += values[expr]
    env = envelope.bound(all_h, all_q)
    a["envelope"] = env
    head = f"not smooth in h: {a['rough']}"
    if env["ok"]:
        a.update(verdict="bounded", order=env["order"], limit=env["limit"],
                 errors=[deviation(q, env["limit"]) for q in qs], text=f"{head}; {env['text']}")
    else:
        a.update(verdict="not smooth", limit=None, errors=[None] * len(qs),
                 text=f"{head}; no Richardson limit, and no envelope: {env['text']}")


def write_extra_points(folder, quantities, extra_points):
    """points.tsv: the midpoints (M) and envelope samples (S) beside the levels of study.tsv."""
    lines = ["quantity	point	h	value	particle_steps	wall_seconds	status"]
    for tag, (hs_x, (costs, values, _)) in extra_points.items():
        for expr in quantities:
            if expr not in values:
                continue
            for k, h in enumerate(hs_x):
                lines.append("\t".join([expr, f"{tag}{k}", repr(h), num(values[expr][k], ".17g"),
                                        num(costs[k].get("particle_steps"), "g"),
                                        num(costs[k].get("wall_seconds"), ".4g"), str(costs[k].get("status"))]))
    if len(lines) > 1:
        files.write_text(folder / "points.tsv", "\n".join(lines) + "\n")


def stability_limit(args, scene, folder, out):
    """The largest stable step of the scene at its own settings, by stability.py's bisection
    (stages given in cycles or in time keep their simulated time), its trials under
    folder/stability.  A line of text: the limit beside the estimate."""
    print("stability: bisecting the largest stable step", file=out)
    lim = stability.measure_all(args.bin, [stability.Target("study", scene.stem, scene, [])], folder / "stability",
                                1, out=out, resume=args.resume)[0]
    if not math.isfinite(lim.limit):
        return f"stability: not measured ({lim.note or 'no stable step found'})"
    return (f"stability: largest stable dt {lim.limit * lim.estimate:.6g} = {lim.limit:.4g} x the estimate "
            f"{lim.estimate:.6g} (first unstable {lim.unstable * lim.estimate:.6g}: {lim.cause or '-'}); "
            f"the scene's own dt {lim.dt_case:.6g}")


def advice_rows(args, scene, folder, key, extra, hs, quantities, analyses, costs, out):
    """One row per quantity and target: the advised h, its predicted error and cost, and the
    achieved error of a run at that h (one run per distinct h)."""
    rows = []
    steps = cost_model(hs, [c.get("particle_steps") for c in costs])
    seconds = cost_model(hs, [c.get("wall_seconds") for c in costs])
    for expr in quantities:
        for target in args.target or []:
            a, why = analyses[expr], ""
            if a["verdict"] == "bounded":
                h, predicted = envelope.advise(a["envelope"], target)
                got, why = ((h, predicted), "") if h is not None else (None, predicted)
            else:
                got = advise(hs, a, target)
                if got is None and a["verdict"] == "converging":
                    why = (f"its limit {a['limit']:.3g} is no larger than the last difference "
                           f"{a['diffs'][-1]:.3g}: it converges to 0, where a relative target means nothing")
            rows.append({"quantity": expr, "target": target, "h": None if got is None else got[0],
                         "predicted": None if got is None else got[1],
                         "steps": steps(got[0]) if got and steps else None,
                         "seconds": seconds(got[0]) if got and seconds else None,
                         "why": "" if got else f"no advice: {why or a['verdict']}"})
    if steps:
        ceiling = CHECK_COST_CEILING * steps(hs[-1])
        for r in rows:
            if r["h"] is not None and r["steps"] > ceiling:
                r["why"] = (f"not run: the advised step would cost {r['steps']:.3g} particle-steps, over "
                            f"{CHECK_COST_CEILING:g} x the finest level's (run it yourself with --set, or add levels)")
                r["unchecked"] = True
    wanted = sorted({fmt_h(r["h"]) for r in rows if r["h"] is not None and not r.get("unchecked")},
                    key=float, reverse=True)
    checks = dict(zip(wanted, level_jobs(scene, folder, [(f"check_{i}", float(h)) for i, h in enumerate(wanted)],
                                         key, extra)))
    if checks:
        print(f"checking the advice: {len(checks)} run(s) at the advised {key}", file=out)
        points.launch(list(checks.values()), args.bin, args.jobs, out, args.resume)
    for r in rows:
        r["achieved_value"] = r["achieved"] = r["met"] = None
        if r["h"] is None or r.get("unchecked"):
            continue
        value, why = points.value_of(r["quantity"], checks[fmt_h(r["h"])].out)
        if value is None:
            r["why"] = f"the check run gave no value: {why}"
            continue
        r["achieved_value"] = value
        r["achieved"] = deviation(value, analyses[r["quantity"]]["limit"])
        r["met"] = r["achieved"] <= r["target"]
    return rows


# ---------------------------------------------------------------- outputs

def write_outputs(folder, scene, key, hs, quantities, values, analyses, costs, advice, args, out, limit=None):
    lines = ["\t".join(TSV_COLUMNS)]
    for expr in quantities:
        a, qs = analyses[expr], values[expr]
        for k, h in enumerate(hs):
            d = a["diffs"][k - 1] if 0 < k <= len(a["diffs"]) else None
            p = a["orders"][k - 2] if 1 < k <= len(a["orders"]) + 1 else None
            lines.append("\t".join([expr, str(k), repr(h), num(qs[k], ".17g"), num(d, ".6g"), num(p, ".4g"),
                                    num(a["errors"][k], ".4g"), num(costs[k].get("particle_steps"), "g"),
                                    num(costs[k].get("wall_seconds"), ".4g"), str(costs[k].get("status"))]))
    files.write_text(folder / "study.tsv", "\n".join(lines) + "\n")
    alines = ["\t".join(ADVICE_COLUMNS)]
    for r in advice:
        alines.append("\t".join([r["quantity"], f"{r['target']:g}", num(r["h"], ".17g"), num(r["predicted"], ".4g"),
                                 num(r["steps"], ".4g"), num(r["seconds"], ".4g"), num(r["achieved_value"], ".17g"),
                                 num(r["achieved"], ".4g"),
                                 "-" if r["met"] is None else ("yes" if r["met"] else "no")]))
    if advice:
        files.write_text(folder / "advice.tsv", "\n".join(alines) + "\n")
    text = terminal_table(key, hs, quantities, values, analyses, costs, advice)
    if limit:
        text += "\n" + limit
    print(text, file=out)
    figure = draw(folder, key, hs, quantities, analyses)
    md = [f"# Study of {scene.name}", "", f"Scene: `{scene}`. Refined: `{key}` = "
          + ", ".join(f"{h:.6g}" for h in hs) + f" (factor {args.factor:g}).", "",
          "Verdict thresholds: a pairwise order <= "
          f"{P_MIN:g} is not converging; pairwise orders spread by more than {ORDER_AGREE:g} are not yet "
          f"asymptotic; advice aims at the target / {ADVICE_MARGIN:g} (harness/error_cost.py).", "", "```", text, "```", ""]
    if figure:
        md += [f"![error against {key}]({figure})", ""]
    md += ["Files: study.tsv (every level), " + ("advice.tsv (the advice and its check), " if advice else "")
           + "runs/ (the run folders)."]
    files.write_text(folder / "study.md", "\n".join(md) + "\n")
    print(f"wrote {folder / 'study.tsv'}, {folder / 'study.md'}" + (f", {folder / figure}" if figure else ""),
          file=out)


def terminal_table(key, hs, quantities, values, analyses, costs, advice):
    rows = [["quantity", "verdict"] + [f"{key}={h:.4g}" for h in hs] + ["limit q*"]]
    for expr in quantities:
        a = analyses[expr]
        rows.append([expr, a["verdict"]] + [num(q, ".10g") for q in values[expr]] + [num(a["limit"], ".10g")])
        rows.append(["", "  error vs q*"] + [num(e, ".2e") for e in a["errors"]] + [""])
    rows.append(["(particle-steps)", ""] + [num(c.get("particle_steps"), "g") for c in costs] + [""])
    rows.append(["(wall s)", ""] + [num(c.get("wall_seconds"), ".3g") for c in costs] + [""])
    lines = aligned(rows)
    lines.append("")
    for expr in quantities:
        lines.append(f"{expr}: {analyses[expr]['text']}")
    if advice:
        lines.append("")
        lines.append("advice (largest h predicted to meet |q_h - q*|/|q*| <= target, then run once):")
        for r in advice:
            if r["h"] is None:
                lines.append(f"  {r['quantity']} target {r['target']:g}: {r['why']}")
                continue
            checked = (f"achieved {num(r['achieved'], '.3g')} ({'met' if r['met'] else 'MISSED'})"
                       if r["achieved"] is not None else r["why"])
            lines.append(f"  {r['quantity']} target {r['target']:g}: {key} = {r['h']:.6g} (predicted error "
                         f"{r['predicted']:.3g}, {num(r['steps'], '.3g')} particle-steps, "
                         f"{num(r['seconds'], '.3g')} s); {checked}")
    return "\n".join(lines)


def draw(folder, key, hs, quantities, analyses):
    """error.svg: each converging quantity's error against q*, log-log; None if gnuplot fails."""
    curves = [(e, analyses[e]) for e in quantities if analyses[e]["verdict"] in ("converging", "bounded")]
    curves = [(e, list(zip(hs, a["errors"]))) for e, a in curves if all(x and x > 0 for x in a["errors"])]
    return plot(folder, "error", curves, key, "|q - q*| / |q*|", "left top")


# ---------------------------------------------------------------- sweeps (--set)

def sweep_study(args, scene, reports_root, out):
    """--set KEY=V1,V2 (a grid when repeated; KEY1,KEY2=V1,... couples keys on one axis, sweep_grid.py):
    every point of the grid run once, each quantity's value and each point's cost, and each
    value's deviation from the point of highest cost (the best-resolved point when the grid
    refines the step or the stiffness; for other keys simply the reference the deviations are
    measured from).  Writes sweep.tsv, study.md and, when gnuplot works, error_cost.svg."""
    given = [f"--{n}" for n in ("refine", "factor", "levels", "base", "target")
             if getattr(args, n, None) is not None]
    if given:
        raise CatalogueError(f"{', '.join(given)}: options of the refinement; --set runs the grid of its points "
                             "instead (run the refinement as a separate study)")
    keyed = sweep_grid.parse_sets(args.set)
    folder = study_folder(reports_root, scene, args.out, args.resume)
    jobs, extra = sweep_grid.plan(args.bin, scene, [], keyed, lambda i, _: folder / "points" / f"P{i + 1}")
    outcomes, quantities = run_points(args, scene, folder, jobs, extra,
                                      f"{len(jobs)} point(s) of {' x '.join(a for a, _ in keyed)}", "sweeping", out)
    measured = sweep_grid.measure(keyed, jobs, quantities)
    text = sweep_grid.points_table(measured)
    limit = stability_limit(args, scene, folder, out) if getattr(args, "stability", False) else None
    if limit:
        text += "\n" + limit
    print(text, file=out)
    sweep_grid.write_points_tsv(folder / "sweep.tsv", measured)
    figure = sweep_grid.draw(folder, "error_cost", sweep_grid.point_curves(measured), "|q - q_ref| / |q_ref|")
    md = [f"# Study of {scene.name}", "", f"Scene: `{scene}`.", "", "## Sweep", "",
          "Points: " + " x ".join(f"`{a}` = {', '.join(v)}" for a, v in keyed) + " (a coupled axis `K1,K2` sets "
          "both keys to each value). Error: |q - q_ref| / |q_ref| against the reference point: the point "
          "of highest cost (particle-steps) among those with the same values on every axis but the last.", "", "```", text, "```", ""]
    if figure:
        md += [f"![error against cost]({figure})", ""]
    md += ["Files: sweep.tsv (every point and quantity), points/P<n>/ (the run folders)."]
    files.write_text(folder / "study.md", "\n".join(md) + "\n")
    print(f"wrote {folder / 'sweep.tsv'}, {folder / 'study.md'}" + (f", {folder / figure}" if figure else ""),
          file=out)
    return 0 if all(o.ok for o in outcomes) else 1
