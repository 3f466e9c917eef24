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
"""
import math
import subprocess
import sys
from pathlib import Path

import numpy as np

from . import core_info, files, stability, sweep_grid
from .compare import evaluate
from .errors import CatalogueError, EvalError, RunProblem
from .runner import Job, run_all
from .sweep import run_cost
from .tables import load_run

DT_KEYS = ("settings.dt", "settings.dt_fraction")
FORCE = "settings.force_dt=1"
MIN_LEVELS = 3          # two differences give one pairwise order; three levels are the least
# A pairwise order below P_MIN means a refinement by r cut the difference by less than r^P_MIN
# (1.41 for r = 2): the differences are not shrinking the way a convergent sequence's do, as in
# a chaotic scene whose particle-level quantities differ by O(1) at every step size.
P_MIN = 0.5
# Pairwise orders that differ by more than ORDER_AGREE are not yet asymptotic.  With p off by
# 0.25 the Richardson error estimate d/(r^p - 1) is off by at most ~40 % for p >= 1, r = 2,
# which ADVICE_MARGIN covers; a larger spread would make the extrapolation a guess.
ORDER_AGREE = 0.25
# Differences below ROUNDOFF x |q| are floating-point noise: the quantity does not depend on h.
ROUNDOFF = 1e-12
# The advice aims at REL / ADVICE_MARGIN: the error model's constant and q* are estimates from
# the levels (their own error is of the order of the pairwise orders' spread, see ORDER_AGREE).
ADVICE_MARGIN = 2.0
STUDIES = "studies"
TSV_COLUMNS = ("quantity", "level", "h", "value", "difference", "pairwise_order", "error_est",
               "particle_steps", "wall_seconds", "status")
ADVICE_COLUMNS = ("quantity", "target", "h_advised", "predicted_error", "predicted_particle_steps",
                  "predicted_seconds", "achieved_value", "achieved_error", "met")
GNUPLOT_TIMEOUT = 60    # seconds
# The refinement's options (None on the command line = not given: --set refuses them when given).
REFINE_DEFAULTS = {"refine": "settings.dt", "factor": 0.5, "levels": 4}
SWEEP_TSV_COLUMNS = ("point", "sets", "status", "steps", "particle_steps", "wall_seconds", "quantity", "value",
                     "reference_point", "error")
# A quantity's column in the printed sweep table is headed by its expression up to this length,
# else by q1, q2, ... with the expressions listed below the table.
SHORT_HEADER = 20


# ---------------------------------------------------------------- the analysis (pure)

def analyse(hs, qs, factor):
    """The convergence of one quantity over levels hs (coarsest first) with values qs.

    {verdict, text, order, orders, order_lsq, limit, errors, diffs}: verdict is 'converging',
    'asymptotic?' (not yet in the asymptotic range), 'not converging', 'independent' (the
    differences are round-off) or 'failed' (a value is missing); order is the p used (the
    finest pairwise order), limit the Richardson q* (None unless converging or independent),
    errors each level's |q - q*| / |q*| (None where there is no q*)."""
    r = 1.0 / factor
    out = {"verdict": "failed", "text": "", "order": None, "orders": [], "order_lsq": None,
           "limit": None, "errors": [None] * len(qs), "diffs": []}
    if any(q is None or not math.isfinite(q) for q in qs):
        out["text"] = "no value at some level (see the table)"
        return out
    d = [b - a for a, b in zip(qs, qs[1:])]
    out["diffs"] = d
    scale = max(abs(q) for q in qs)
    if max(abs(x) for x in d) <= ROUNDOFF * max(scale, np.finfo(float).tiny):
        out.update(verdict="independent", limit=qs[-1], errors=[0.0] * len(qs),
                   text=f"independent of h: every difference is at round-off (<= {ROUNDOFF:g} |q|)")
        return out
    if any(x == 0 for x in d):
        out.update(verdict="not converging", text="some differences are exactly zero and others not: "
                                                  "not a smooth sequence in h")
        return out
    orders = [math.log(abs(a) / abs(b)) / math.log(r) for a, b in zip(d, d[1:])]
    out["orders"] = orders
    out["order_lsq"] = float(np.polyfit(np.log(hs[:-1]), np.log(np.abs(d)), 1)[0])
    listed = ", ".join(f"{p:.3g}" for p in orders)
    if min(orders) <= P_MIN:
        out.update(verdict="not converging",
                   text=f"not converging: pairwise orders {listed}; a refinement by {r:g} must cut the "
                        f"difference by at least {r:g}^{P_MIN:g} (order > {P_MIN:g}): noise or chaos, "
                        f"no extrapolation; the levels spread over {spread(qs)}")
        return out
    if any((a > 0) != (b > 0) for a, b in zip(d, d[1:])):
        out.update(verdict="asymptotic?",
                   text=f"not yet in the asymptotic range: the differences change sign (pairwise orders "
                        f"{listed}): the error is not a smooth power of h here (a phase effect within "
                        "the step, or noise); no extrapolation")
        return out
    if max(orders) - min(orders) > ORDER_AGREE:
        out.update(verdict="asymptotic?",
                   text=f"not yet in the asymptotic range: pairwise orders {listed} differ by more than "
                        f"{ORDER_AGREE:g}; refine further (--levels, or a smaller base)")
        return out
    p = orders[-1]
    limit = qs[-1] + d[-1] / (r ** p - 1)
    errors = [abs(q - limit) / abs(limit) if limit != 0 else abs(q - limit) for q in qs]
    out.update(verdict="converging", order=p, limit=limit, errors=errors,
               text=f"converging at order {p:.3g} (pairwise {listed}; least squares {out['order_lsq']:.3g})")
    return out


def spread(qs):
    """max - min of the levels' values, and relative to the largest |q|: what a user can count on
    when the quantity does not converge."""
    width, top = max(qs) - min(qs), max(abs(q) for q in qs)
    return f"{width:.3g}" + (f" ({width / top:.2g} of |q|)" if top > 0 else "")


def advise(hs, analysis, target):
    """(h, predicted relative error at h) for a converging quantity: the largest h with
    e(h) = e_finest (h / h_finest)^p <= target / ADVICE_MARGIN; None when there is no advice
    (not converging, q* = 0).  An independent quantity meets any target at the coarsest h."""
    if analysis["verdict"] == "independent":
        return hs[0], 0.0
    if analysis["verdict"] != "converging" or analysis["limit"] == 0:
        return None
    p, e_f = analysis["order"], analysis["errors"][-1]
    if e_f == 0:
        return hs[0], 0.0
    h = hs[-1] * (target / ADVICE_MARGIN / e_f) ** (1.0 / p)
    return h, e_f * (h / hs[-1]) ** p


def cost_model(hs, costs):
    """cost(h) by a least-squares power law over the levels with a cost (None when < 2)."""
    pts = [(h, c) for h, c in zip(hs, costs) if isinstance(c, (int, float)) and c > 0]
    if len(pts) < 2:
        return None
    slope, icpt = np.polyfit(np.log([h for h, _ in pts]), np.log([c for _, c in pts]), 1)
    return lambda h: float(math.exp(icpt + slope * math.log(h)))


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


def time_keeping(binary, scene, key):
    """The overrides that keep each stage's simulated time while the step is refined."""
    if key not in DT_KEYS:
        return []
    info = core_info.query(binary, scene, [])
    return [f"stage.{name}.time={fmt_h(cycles * info['dt'])}" for name, cycles, _, given in info["stages"]
            if given == "cycles" and cycles > 0] + [FORCE]


def job(scene, folder, label, key, h, extra):
    return Job("study", label, scene, list(extra) + [f"{key}={fmt_h(h)}"], folder / "runs" / label,
               probe=bool(extra))


def default_quantities(folder):
    """The final energies of run.json and the last value of each series.tsv column."""
    try:
        run = load_run(folder)
    except RunProblem as problem:
        raise CatalogueError(f"no default quantities: the coarsest run failed ({problem})") from None
    out = [f"run('{k}')" for k in ("energy_kinetic", "energy_elastic") if k in run.info]
    return out + [f"last({c})" for c in run.columns if c not in ("cycle", "time")]


def value_of(expr, folder):
    """(value, '') or (None, why)."""
    try:
        return evaluate(expr, load_run(folder)), ""
    except (RunProblem, EvalError) as exc:
        return None, str(exc)


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
    extra = time_keeping(args.bin, scene, key)
    folder = study_folder(reports_root, scene, args.out, args.resume)
    files.make_dirs(folder)
    hs = [base * args.factor ** k for k in range(args.levels)]
    jobs = [job(scene, folder, f"L{k}", key, h, extra) for k, h in enumerate(hs)]
    core_info.refuse_bad_points(args.bin, [(j.variant, j.scene, j.sets, [key]) for j in jobs])
    print(f"study of {scene}: {key} = {', '.join(f'{h:.6g}' for h in hs)} -> {folder}", file=out)
    if extra:
        print(f"refining the step: every run keeps the stages' simulated time ({' '.join(extra)})", file=out)
    outcomes = run_all(jobs, args.bin, args.jobs, out, resume=args.resume)
    if any(o.io_error for o in outcomes):
        raise OSError(f"cannot record the runs: {next(o.io_error for o in outcomes if o.io_error)}")
    quantities = list(args.quantity or []) or default_quantities(jobs[0].out)
    costs = [run_cost(j.out) for j in jobs]
    values, analyses, notes = {}, {}, {}
    for expr in quantities:
        got = [value_of(expr, j.out) for j in jobs]
        values[expr] = [v for v, _ in got]
        notes[expr] = next((why for v, why in got if v is None), "")
        analyses[expr] = analyse(hs, values[expr], args.factor)
        if notes[expr]:
            analyses[expr]["text"] += f": {notes[expr]}"
    advice = advice_rows(args, scene, folder, key, extra, hs, quantities, analyses, costs, out)
    limit = stability_limit(args, scene, folder, out) if getattr(args, "stability", False) else None
    write_outputs(folder, scene, key, hs, quantities, values, analyses, costs, advice, args, out, limit)
    return 0


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
            got = advise(hs, analyses[expr], target)
            rows.append({"quantity": expr, "target": target, "h": None if got is None else got[0],
                         "predicted": None if got is None else got[1],
                         "steps": steps(got[0]) if got and steps else None,
                         "seconds": seconds(got[0]) if got and seconds else None,
                         "why": "" if got else f"no advice: {analyses[expr]['verdict']}"})
    wanted = sorted({fmt_h(r["h"]) for r in rows if r["h"] is not None}, key=float, reverse=True)
    checks = {h: job(scene, folder, f"check_{i}", key, float(h), extra) for i, h in enumerate(wanted)}
    if checks:
        print(f"checking the advice: {len(checks)} run(s) at the advised {key}", file=out)
        run_all(list(checks.values()), args.bin, args.jobs, out, resume=args.resume)
    for r in rows:
        r["achieved_value"] = r["achieved"] = r["met"] = None
        if r["h"] is None:
            continue
        value, why = value_of(r["quantity"], checks[fmt_h(r["h"])].out)
        limit = analyses[r["quantity"]]["limit"]
        if value is None:
            r["why"] = f"the check run gave no value: {why}"
            continue
        r["achieved_value"] = value
        r["achieved"] = abs(value - limit) / abs(limit) if limit != 0 else abs(value - limit)
        r["met"] = r["achieved"] <= r["target"]
    return rows


# ---------------------------------------------------------------- outputs

def num(x, fmt=".6g"):
    return "-" if x is None else format(x, fmt)


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
          f"asymptotic; advice aims at the target / {ADVICE_MARGIN:g} (harness/study.py).", "", "```", text, "```", ""]
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
    widths = [max(len(r[j]) for r in rows) for j in range(len(rows[0]))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
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
    curves = [(e, analyses[e]) for e in quantities if analyses[e]["verdict"] == "converging"]
    curves = [(e, a) for e, a in curves if all(x and x > 0 for x in a["errors"])]
    if not curves:
        return None
    data = []
    for i, (expr, a) in enumerate(curves):
        data.append(f"# {expr}")
        data += [f"{h!r} {err!r}" for h, err in zip(hs, a["errors"])]
        data += ["", ""]
    files.write_text(folder / "error.dat", "\n".join(data) + "\n")
    style = Path(__file__).resolve().parent / "gnuplot" / "style.gp"
    esc = lambda s: s.replace("\\", "\\\\").replace('"', '\\"')
    plots = ", ".join(f'"error.dat" index {i} using 1:2 with linespoints title "{esc(e)}"'
                      for i, (e, _) in enumerate(curves))
    gp = [f'load "{esc(str(style))}"', "set terminal svg size 800,500", 'set output "error.svg"',
          "set logscale xy", f'set xlabel "{esc(key)}"', 'set ylabel "|q - q*| / |q*|"',
          "set key inside left top", f"plot {plots}"]
    files.write_text(folder / "error.gp", "\n".join(gp) + "\n")
    try:
        done = subprocess.run(["gnuplot", "error.gp"], cwd=folder, capture_output=True, timeout=GNUPLOT_TIMEOUT,
                              stdin=subprocess.DEVNULL)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return "error.svg" if done.returncode == 0 and (folder / "error.svg").is_file() else None


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
    swept = sweep_grid.swept_keys(keyed)
    extra = time_keeping(args.bin, scene, DT_KEYS[0]) if any(k in DT_KEYS for k in swept) else []
    folder = study_folder(reports_root, scene, args.out, args.resume)
    points = sweep_grid.grid(keyed)
    jobs = [Job("study", label, scene, list(extra) + sets, folder / "points" / f"P{i + 1}", probe=bool(extra))
            for i, (label, sets) in enumerate(points)]
    core_info.refuse_bad_points(args.bin, [(j.variant, j.scene, j.sets, swept) for j in jobs])   # before any run
    files.make_dirs(folder)
    print(f"study of {scene}: {len(jobs)} point(s) of {' x '.join(a for a, _ in keyed)} -> {folder}", file=out)
    if extra:
        print(f"sweeping the step: every run keeps the stages' simulated time ({' '.join(extra)})", file=out)
    outcomes = run_all(jobs, args.bin, args.jobs, out, resume=args.resume)
    if any(o.io_error for o in outcomes):
        raise OSError(f"cannot record the runs: {next(o.io_error for o in outcomes if o.io_error)}")
    quantities = list(args.quantity or []) or default_quantities(jobs[0].out)
    costs = [run_cost(j.out) for j in jobs]
    values = {expr: [value_of(expr, j.out)[0] for j in jobs] for expr in quantities}
    point_values = [[values_of_axis(axis, sets) for axis, _ in keyed] for _, sets in points]
    refs = reference_points(point_values, costs, values, quantities)
    errors = {expr: [None if refs[i] is None or v is None else relative(v, values[expr][refs[i]])
                     for i, v in enumerate(values[expr])] for expr in quantities}
    text = sweep_table(keyed, point_values, quantities, values, errors, costs, refs)
    limit = stability_limit(args, scene, folder, out) if getattr(args, "stability", False) else None
    if limit:
        text += "\n" + limit
    print(text, file=out)
    lines = ["\t".join(SWEEP_TSV_COLUMNS)]
    for i, job_ in enumerate(jobs):
        for expr in quantities:
            c = costs[i]
            lines.append("\t".join([f"P{i + 1}", " ".join(points[i][1]), str(c.get("status")),
                                    num(c.get("steps"), "g"), num(c.get("particle_steps"), "g"),
                                    num(c.get("wall_seconds"), ".4g"), expr, num(values[expr][i], ".17g"),
                                    "-" if refs[i] is None else f"P{refs[i] + 1}", num(errors[expr][i], ".6g")]))
    files.write_text(folder / "sweep.tsv", "\n".join(lines) + "\n")
    figure = draw_cost(folder, quantities, errors, costs, refs)
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


def values_of_axis(axis, sets):
    """The value of an axis at a point (the coupled keys share it)."""
    key = sweep_grid.axis_keys(axis)[0]
    return next(s.split("=", 1)[1] for s in sets if s.split("=", 1)[0] == key)


def relative(v, ref):
    return abs(v - ref) / abs(ref) if ref != 0 else abs(v - ref)


def reference_points(point_values, costs, values, quantities):
    """Each point's reference: among the points with its values on every axis but the last (the
    whole sweep for one axis), the one of highest particle-steps with every quantity measured
    (the last such point on a tie); None where there is none.  The last axis is the one whose
    values a point's error is measured along: put the resolution key (the step, 1/kn) last."""
    ok = [i for i, c in enumerate(costs) if isinstance(c.get("particle_steps"), int)
          and all(values[e][i] is not None for e in quantities)]
    refs = []
    for pv in point_values:
        group = [i for i in ok if point_values[i][:-1] == pv[:-1]]
        refs.append(max(group, key=lambda i: (costs[i]["particle_steps"], i)) if group else None)
    return refs


def short_axis(axis, axes):
    """An axis's column header: each key's last part ('settings.dt' -> 'dt'; coupled keys with
    one last part share it), the whole axis when two axes would get the same header."""
    def short(a):
        tails = list(dict.fromkeys(k.rsplit(".", 1)[-1] for k in sweep_grid.axis_keys(a)))
        return ",".join(tails)
    return short(axis) if [short(a) for a in axes].count(short(axis)) == 1 else axis


def sweep_table(keyed, point_values, quantities, values, errors, costs, refs):
    """One row per point: its values on each axis, each quantity's value (its error against its
    reference point in brackets) and the point's cost; the axes and quantities named below."""
    axes = [a for a, _ in keyed]
    names = [e if len(e) <= SHORT_HEADER else f"q{i + 1}" for i, e in enumerate(quantities)]
    rows = [["point"] + [short_axis(a, axes) for a in axes] + names + ["status", "particle-steps", "wall s", "ref"]]
    for i, pv in enumerate(point_values):
        cells = [f"{num(values[e][i], '.8g')} ({num(errors[e][i], '.1e')})" if refs[i] != i
                 else f"{num(values[e][i], '.8g')} (ref)" for e in quantities]
        ref = "-" if refs[i] is None else f"P{refs[i] + 1}"
        rows.append([f"P{i + 1}"] + pv + cells + [str(costs[i].get("status")), num(costs[i].get("particle_steps"), "g"),
                                                  num(costs[i].get("wall_seconds"), ".3g"), ref])
    widths = [max(len(r[j]) for r in rows) for j in range(len(rows[0]))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
    lines.append("")
    lines += [f"{short_axis(a, axes)} = {a}" for a in axes if short_axis(a, axes) != a]
    lines += [f"{n} = {e}" for n, e in zip(names, quantities) if n != e]
    lines.append("(error) = |q - q_ref| / |q_ref|, q_ref at the point's ref: the point of highest cost "
                 "(particle-steps) with the same values on every axis but the last")
    return "\n".join(lines)


def draw_cost(folder, quantities, errors, costs, refs):
    """error_cost.svg: each quantity's error against the reference point by particle-steps,
    log-log (points with a zero or missing error left out); None if gnuplot fails."""
    curves = []
    for expr in quantities:
        pts = [(costs[i]["particle_steps"], e) for i, e in enumerate(errors[expr])
               if refs[i] != i and e and e > 0 and isinstance(costs[i].get("particle_steps"), int)]
        if pts:
            curves.append((expr, sorted(pts)))
    if not curves:
        return None
    data = []
    for expr, pts in curves:
        data += [f"# {expr}"] + [f"{c!r} {e!r}" for c, e in pts] + ["", ""]
    files.write_text(folder / "error_cost.dat", "\n".join(data) + "\n")
    style = Path(__file__).resolve().parent / "gnuplot" / "style.gp"
    esc = lambda s: s.replace("\\", "\\\\").replace('"', '\\"')
    plots = ", ".join(f'"error_cost.dat" index {i} using 1:2 with linespoints title "{esc(e)}"'
                      for i, (e, _) in enumerate(curves))
    gp = [f'load "{esc(str(style))}"', "set terminal svg size 800,500", 'set output "error_cost.svg"',
          "set logscale xy", 'set xlabel "particle-steps"', 'set ylabel "|q - q_ref| / |q_ref|"',
          "set key inside right top", f"plot {plots}"]
    files.write_text(folder / "error_cost.gp", "\n".join(gp) + "\n")
    try:
        done = subprocess.run(["gnuplot", "error_cost.gp"], cwd=folder, capture_output=True,
                              timeout=GNUPLOT_TIMEOUT, stdin=subprocess.DEVNULL)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return "error_cost.svg" if done.returncode == 0 and (folder / "error_cost.svg").is_file() else None
