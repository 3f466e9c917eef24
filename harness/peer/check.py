"""harness/peer/check.py -- ballast and LAMMPS on the same physics: the cross-check.

    /usr/bin/python3 -m harness.peer.check --out DIR [--ballast BIN] [--lmp LMP]

A small fill of cases/bench/dense.scene (300 discs on the lattice, with the
scene's random velocities, nothing touching) is written out disc by disc as a
ballast scene (harness/peer/common.py), which ballast runs and the harness's
translation (harness/engines/lammps.py) turns into LAMMPS's data file and input.  Both codes
run the same 400 steps with gravity, three times: frictionless, with friction
0.5, and with friction and half the time step.  The final positions,
velocities, per-disc forces and torques, and every disc-disc contact's f_n and
f_s are compared (the limits and why: TOL_* below).  Prints a line per run

    peer check friction=0.5 N=300 steps=400 max_dx=... max_dF=... ... PASS|FAIL

The catalogue's full-tier case `peer_check` runs this module: it writes the
figures into DIR as a run (series.tsv, run.json), or, where LAMMPS is absent
and cannot be installed, a skipped run (common.skip_outputs).  The race
(harness/peer/race.py, `make bench-peer`) runs cross_check() first and races
only when it passes: a race between different physics would mean nothing.
"""
import argparse
import sys
from pathlib import Path

from .. import files
from .common import (FIGURES, MU, ballast_scene, check_state, check_verdict, code_arguments,
                     codes_of, compare, lammps_problem, parse_dump, run_ballast, run_lammps,
                     skip_outputs, write_outputs)

# Three runs of the same 300 discs for CHECK_STEPS steps (see docs/benchmarks.md,
# bench-peer, for the measured values):
#
# - frictionless: both codes do the same arithmetic in a different order, so
#   they differ by round-off only, amplified by the collisions over the run
#   (about e-fold per 50 steps here: ~1e-13 after 400 steps, ~1e-7 after
#   1000, O(1) after 2000 -- hence a few hundred steps).  Limits TOL_EXACT.
# - with friction: one term differs.  LAMMPS's gran/hooke/history keeps the
#   shear displacement as a 3-vector and each step projects it onto the new
#   tangent plane, which shortens it by cos(d_theta) when the line of centres
#   turns by d_theta; ballast carries the shear force as a scalar along the
#   turning tangent (C&S), which keeps it.  The difference is
#   F_s (1 - cos d_theta) ~ F_s d_theta^2 / 2 per step, d_theta ~ |v_t| dt / D
#   ~ 1e-3 here, so O(dt^2) per step and O(dt) over a collision.  (Wall
#   contacts do not turn: no difference there.)  Limits TOL_FRICTION, about
#   10 x the measured values.
# - with friction and dt / 2 (twice the steps, the same time): the
#   difference must fall as dt, as that term does (round-off or a wrong law
#   would not): ratio to the run above <= TOL_RATIO.
CHECK_STEPS = 400
TOL_EXACT = dict.fromkeys(FIGURES, 1e-10)
TOL_FRICTION = dict(max_dx=1e-6, max_dv=2e-5, max_dF=1e-5, max_dT=1e-5, max_dfn=1e-5,
                    max_dfs=1e-5)
TOL_RATIO = 0.7

# LAMMPS's neighbour settings of the cross-check (any would do: the physics does not depend
# on them): skin 0.25, atoms sorted every 1000 steps.
CHECK_NEIGHBOURS = dict(skin=0.25, sort_every=1000)
CHECK_OUTPUT = """compute         pairs all pair/local dist force p1 p2 p4
compute         ids all property/local patom1 patom2
dump            atoms all custom @steps@ atoms.dump id radius mass x y vx vy omegaz fx fy tqz
dump_modify     atoms sort id format float %.17g
dump            pairs all local @steps@ pairs.dump c_ids[1] c_ids[2] c_pairs[1] c_pairs[2] c_pairs[3] c_pairs[4] c_pairs[5]
dump_modify     pairs format float %.17g"""


def convergence(full, half):
    """Ratios of the dt/2 run's position and force differences to the full-dt run's."""
    return (half["max_dx"] / max(full["max_dx"], 1e-300),
            half["max_dF"] / max(full["max_dF"], 1e-300))


def check_line(c, verdict, label, extra=""):
    figures = " ".join(f"{k}={c[k]:.3g}" for k in FIGURES)
    return (f"peer check {label} N={c['n']} steps={c['step']} {figures} "
            f"contacts={c['contacts_ballast']}/{c['contacts_lammps']} sliding={c['sliding']} "
            f"touched={c['touched']}{extra} {'PASS' if verdict else 'FAIL'}")


def cross_run(codes, work, state, box, dt, steps, friction, label):
    """Both codes on the same discs for `steps` steps; compare()'s figures."""
    scene = work / f"{label}.scene"
    files.write_text(scene, ballast_scene(state, box, dt, steps,
                                          f"peer cross-check {label}, {len(state['x'])} discs", mu=friction))
    run_ballast(codes, ["run", scene], work / f"{label}_ballast")
    lw = files.make_dirs(work / f"{label}_lammps")
    run_lammps(codes, lw, scene, CHECK_OUTPUT.replace("@steps@", str(steps)), **CHECK_NEIGHBOURS)
    atoms = parse_dump((lw / "atoms.dump").read_text())
    if atoms["_step"] != steps:
        sys.exit(f"peer: the LAMMPS dump is of step {atoms['_step']}, not {steps}")
    local = parse_dump((lw / "pairs.dump").read_text())
    return compare(state, work / f"{label}_ballast", atoms, local, dt)


def cross_check(codes, work, steps=CHECK_STEPS):
    """The three runs of the cross-check; prints a line each.  Returns (all passed,
    {"friction0", "friction", "half_dt": each run's figures, "ratio_dx", "ratio_dF"})."""
    work = files.make_dirs(work)
    state, box, dt = check_state(codes, work)
    exact = cross_run(codes, work, state, box, dt, steps, 0.0, "frictionless")
    ok0 = check_verdict(exact, TOL_EXACT)
    print(check_line(exact, ok0, "friction=0"), flush=True)
    full = cross_run(codes, work, state, box, dt, steps, MU, "friction")
    ok1 = check_verdict(full, TOL_FRICTION)
    print(check_line(full, ok1, f"friction={MU:g}"), flush=True)
    half = cross_run(codes, work, state, box, 0.5 * dt, 2 * steps, MU, "friction_half_dt")
    rx, rf = convergence(full, half)
    ok2 = check_verdict(half, TOL_FRICTION) and rx <= TOL_RATIO and rf <= TOL_RATIO
    print(check_line(half, ok2, f"friction={MU:g},dt/2",
                     f" ratio_dx={rx:.3g} ratio_dF={rf:.3g}"), flush=True)
    if not (ok0 and ok1 and ok2):
        print(f"peer: FAIL: limits: friction=0 {TOL_EXACT['max_dx']:g} for every figure; "
              f"friction: {', '.join(f'{k} {v:g}' for k, v in TOL_FRICTION.items())}; "
              f"dt/2 ratios <= {TOL_RATIO}; the same contacts in both codes", file=sys.stderr)
    results = {"friction0": exact, "friction": full, "half_dt": half, "ratio_dx": rx, "ratio_dF": rf}
    return ok0 and ok1 and ok2, results


def check_outputs(results, ok):
    """The cross-check as a run's outputs (series.tsv, run.json), for the
    catalogue's full-tier case `peer_check`: one row, one column per figure of
    each of the three runs, and the two convergence ratios."""
    names, values = ["cycle", "time"], [0.0, 0.0]
    for run in ("friction0", "friction", "half_dt"):
        for k in FIGURES:
            names.append(f"{run}_{k}")
            values.append(float(results[run][k]))
    names += ["ratio_dx", "ratio_dF"]
    values += [float(results["ratio_dx"]), float(results["ratio_dF"])]
    series = "\t".join(names) + "\n" + "\t".join(repr(v) for v in values) + "\n"
    info = {"status": "ok" if ok else "failed", "message": "" if ok else "cross-check failed",
            "steps": int(results["friction"]["step"]), "n_discs": int(results["friction"]["n"])}
    return series, info


def run(out, codes):
    """The cross-check written like a run into out (exit status 0 when it passed); a
    skipped run when LAMMPS cannot run it (common.lammps_problem())."""
    out = files.make_dirs(out)
    problem = lammps_problem(codes)
    if problem:
        print(f"peer: skipped: {problem}", flush=True)
        write_outputs(out, *skip_outputs(problem))
        return 0
    ok, results = cross_check(codes.pinned(out), out / "work")
    write_outputs(out, *check_outputs(results, ok))
    return 0 if ok else 1


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True, type=Path,
                    help="folder for the run's outputs (series.tsv, run.json, work/)")
    code_arguments(ap)
    a = ap.parse_args(argv)
    return run(a.out, codes_of(a))


if __name__ == "__main__":
    sys.exit(main())
