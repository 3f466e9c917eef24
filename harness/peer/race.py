"""harness/peer/race.py -- ballast against LAMMPS on the same physics (`make bench-peer`).

    /usr/bin/python3 -m harness.peer.race [--quick] [--ballast BIN] [--lmp LMP]

1. Cross-check (harness/peer/check.py): both codes on the same 300 discs,
   three runs; stops with exit status 1 on a FAIL: a race between different
   physics would mean nothing.

2. Race, per scene (`dense`: N = 20000 discs settled frictionless, raced
   with friction from rest -- see settle_dense();
   `settling`: the same discs released from the lattice of dense.scene with
   its random velocities):
   - LAMMPS's neighbour settings are swept, one run of the race's steps
     each (skin, then bin size, then sort frequency, each keeping the best
     so far; delay 0, every 1, check yes throughout), and the fastest is
     kept; ballast is not swept: it runs with skin_rule = motion, which
     chooses its skin from the measured motion at every rebuild;
   - then ballast and LAMMPS run alternately, REPEATS times each, the same
     steps from the same files, and the stepping alone is timed: ballast's
     run.json wall_seconds, LAMMPS's "Loop time" (both exclude set-up and
     output).  Prints

       peer dense N=20000 steps=S ballast=MEDIAN [min..max] lammps=MEDIAN [min..max] ratio=R lammps_best=skin=..,binsize=..,sort=..

   with rates in particle-steps per second and R = ballast / LAMMPS (medians).

Results are appended to reports/bench/<host>/peer.csv and
reports/bench/<host>/peer_sweep.csv; the scenes, data files, inputs and logs
of the last run stay in reports/bench/<host>/peer/.  The physics of both
sides and the integrator convention: harness/peer/common.py.
core/bench/cost.py counts and times the same two scenes (settle_dense(),
initial_lattice(), race_scene()).
"""
import argparse
import math
import socket
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from .. import REPO_ROOT
from .. import files
from . import check
from .common import (DENSE_SCENE, ballast_scene, box_of_walls, code_arguments, codes_of, disc_state,
                     lammps_problem, parse_lammps_log, run_ballast, run_lammps)

REPEATS = 5
# Steps of every timed run, sweep and race alike (the sweep times what the
# race runs): about 2 s of ballast and 5-7 s of LAMMPS at N = 20000 on the
# 2-core VM of docs/benchmarks.md.
RACE_STEPS = 3000
RACE_N = 20000
# ballast's skin in the race: chosen from the measured motion at each rebuild
# (settings.skin_rule = motion), its own setting for any scene, not tuned to
# this one; LAMMPS gets the fastest of its swept neighbour settings.
RACE_SKIN_RULE = "motion"


# --------------------------------------------------------------------------
# Timing figures
# --------------------------------------------------------------------------

def spread(rates):
    """(median, min, max) of a list of rates."""
    return statistics.median(rates), min(rates), max(rates)


def race_line(scene, n, steps, b_rates, l_rates, best):
    bm, bl, bh = spread(b_rates)
    lm, ll, lh = spread(l_rates)
    return (f"peer {scene} N={n} steps={steps} ballast={bm:.4g} [{bl:.4g}..{bh:.4g}] "
            f"lammps={lm:.4g} [{ll:.4g}..{lh:.4g}] ratio={bm / lm:.3g} "
            f"lammps_best={settings_label(best)}")


def settings_label(s):
    return (f"skin={s['skin']:.4g},binsize={'default' if s['binsize'] == 0 else format(s['binsize'], '.4g')},"
            f"sort={s['sort_every']}")


def append_csv(path, header, row):
    """Append a row (a list) to a CSV, writing the header into a new file.

    A file whose header is not `header` (written by an older race) is
    moved aside to NAME.csv.old first, so that a file's rows match its header."""
    files.make_dirs(path.parent)
    if path.exists():
        with open(path) as f:
            first = f.readline().rstrip("\n")
        if first != ",".join(header):
            path.replace(path.with_name(path.name + ".old"))
    fresh = not path.exists()
    with open(path, "a") as f:
        if fresh:
            f.write(",".join(header) + "\n")
        f.write(",".join(str(v) for v in row) + "\n")


def sweep_plan(mean_d, r_max, quick=False):
    """The three stages of the neighbour sweep: skins (as fractions of the
    mean diameter), then bin sizes, then sort frequencies, each stage keeping
    the best of the one before.  Bin size 0 = LAMMPS's default (half the
    neighbour cutoff 2 r_max + skin); sort 1000 is LAMMPS's default."""
    fractions = (0.1, 0.3) if quick else (0.05, 0.1, 0.2, 0.4)
    skins = [f * mean_d for f in fractions]
    binsizes = lambda skin: [0, 2 * r_max + skin]
    sorts = [0, 1000] if quick else [0, 100, 1000]
    return skins, binsizes, sorts


def extend_skin(skins, rates, lo, hi):
    """When the fastest skin so far is the largest tried, the next to try is
    1.5 x larger; when it is the smallest, half as large; None when the best
    lies inside the range (or the next would leave [lo, hi])."""
    best = skins[max(range(len(rates)), key=lambda k: rates[k])]
    if best == max(skins) and 1.5 * best <= hi:
        return 1.5 * best
    if best == min(skins) and 0.5 * best >= lo:
        return 0.5 * best
    return None


# --------------------------------------------------------------------------
# The race's scenes and runs
# --------------------------------------------------------------------------

def race_scene(name, state, box, dt, steps):
    """The ballast scene of the race's scene `name`: ballast's own choice of skin
    (skin_rule = motion, docs/physics.md) against the best of LAMMPS's swept settings."""
    return ballast_scene(state, box, dt, steps, f"peer race '{name}', {len(state['x'])} discs",
                         skin_rule=RACE_SKIN_RULE)


class Race:
    """One scene of the race: its files and the runs of both codes."""

    def __init__(self, name, work, state, box, dt, steps, codes):
        self.name, self.work, self.state, self.box = name, Path(work), state, box
        self.dt, self.steps, self.codes = dt, steps, codes
        self.n = len(state["x"])
        files.make_dirs(self.work)
        self.scenes = {}

    def scene(self, steps):
        if steps not in self.scenes:
            path = self.work / f"{self.name}_{steps}.scene"
            files.write_text(path, race_scene(self.name, self.state, self.box, self.dt, steps))
            self.scenes[steps] = path
        return self.scenes[steps]

    def ballast(self, steps):
        run = run_ballast(self.codes, ["run", self.scene(steps)], self.work / "ballast_out")
        return self.n * run["steps"] / run["wall_seconds"], run

    def lammps(self, steps, s):
        """LAMMPS on the same scene through the harness's translation (engines/lammps.py) with
        the neighbour settings s; the rate of its last loop (the race's steps: the runs that
        solve for v_0 before it are runs of 0 steps, LAMMPS's set-up)."""
        log = run_lammps(self.codes, self.work / "lammps", self.scene(steps), skin=s["skin"],
                         binsize=s["binsize"], sort_every=s["sort_every"])
        if log["procs"] != 1 or log["atoms"] != self.n or log["steps"] != steps:
            sys.exit(f"peer: LAMMPS ran {log['steps']} steps of {log['atoms']} atoms on "
                     f"{log['procs']} procs")
        return self.n * steps / log["loop_seconds"], log


def settle_dense(codes, work, n, columns):
    """Run dense.scene to rest (E_k <= 1e-3 E_el) with the race's normal law
    and without friction; the settled state (velocities zeroed: the race
    starts at rest), its box, its dt and the settling stage of run.json.

    Without friction, because neither code can hand its contacts' shear
    history to the other: both start the race with none.  A packing settled
    with friction and then stripped of its shear forces slips and rings
    (without damping, ballast rebuilt its lists 23 times in 3000 steps, and
    LAMMPS more); one settled frictionless is in equilibrium with normal
    forces alone and stays at rest when the race turns friction on."""
    out = Path(work) / "settled"
    run = run_ballast(codes, ["run", DENSE_SCENE, "--set", f"fill.pack.n={n}",
                              "--set", f"fill.pack.columns={columns}",
                              "--set", "material.grain.friction=0", "--set", "material.box.friction=0",
                              "--set", "settings.normal_law=power", "--set", "settings.output_every=1000",
                              "--set", "stage.settle.cycles=40000", "--set", "stage.settle.stop_ke=1e-3",
                              "--set", "stage.settle.check_every=1000",
                              "--set", "stage.measure.cycles=0"], out)
    state = disc_state(out / "discs.tsv")
    for k in ("vx", "vy", "omega"):
        state[k] = np.zeros_like(state[k])
    stage = run["stages"][0]
    return state, box_of_walls(out / "walls.tsv"), run["dt"], stage


def initial_lattice(codes, work, n, columns):
    """dense.scene's n discs on its lattice with its random velocities: (state, box, dt)."""
    out = Path(work) / "lattice"
    run = run_ballast(codes, ["run", DENSE_SCENE, "--set", f"fill.pack.n={n}",
                              "--set", f"fill.pack.columns={columns}",
                              "--set", "stage.settle.cycles=0", "--set", "stage.measure.cycles=0"], out)
    state = disc_state(out / "discs.tsv")
    return state, box_of_walls(out / "walls.tsv"), run["dt"]


def sweep(race, steps, quick, host_dir, stamp):
    """Greedy sweep of LAMMPS's neighbour settings on `steps` steps: the
    skins of sweep_plan() (extended past an end of the range while the end is
    the fastest), then the bin sizes, then the sort frequencies, each stage
    starting from the best so far.  Returns (best settings, every try)."""
    mean_d = 2 * float(np.mean(race.state["r"]))
    r_max = float(np.max(race.state["r"]))
    skins, binsizes, sorts = sweep_plan(mean_d, r_max, quick)
    tried = []

    def one(s):
        rate, log = race.lammps(steps, s)
        if log["dangerous"] != 0:
            rate = 0.0                     # missed contacts: not a valid setting
        tried.append((dict(s), rate, log))
        print(f"peer sweep {race.name} {settings_label(s)} steps={steps} lammps={rate:.4g} "
              f"builds={log['builds']} dangerous={log['dangerous']}", flush=True)
        append_csv(host_dir / "peer_sweep.csv",
                   ["unix_time", "scene", "n", "steps", "skin", "binsize", "sort_every",
                    "particle_steps_per_s", "builds", "dangerous"],
                   [stamp, race.name, race.n, steps, f"{s['skin']:.6g}", f"{s['binsize']:.6g}",
                    s["sort_every"], f"{rate:.6g}", log["builds"], log["dangerous"]])
        return rate

    best = None
    skin_rates = []
    while True:
        skin = skins[len(skin_rates)] if len(skin_rates) < len(skins) else \
            extend_skin(skins, skin_rates, 0.01 * mean_d, 1.2 * mean_d)
        if skin is None:
            break
        if len(skin_rates) >= len(skins):
            skins = skins + [skin]
        s = {"skin": skin, "binsize": 0, "sort_every": 1000}
        rate = one(s)
        skin_rates.append(rate)
        if best is None or rate > best[1]:
            best = (s, rate)
    base = best[0]
    for b in binsizes(base["skin"])[1:]:
        s = dict(base, binsize=b)
        rate = one(s)
        if rate > best[1]:
            best = (s, rate)
    base = best[0]
    for so in sorts:
        if so == base["sort_every"]:
            continue
        s = dict(base, sort_every=so)
        rate = one(s)
        if rate > best[1]:
            best = (s, rate)
    return best[0], tried


# --------------------------------------------------------------------------
# The whole of `make bench-peer`
# --------------------------------------------------------------------------

def race_all(codes, quick=False):
    """The cross-check, then the race of both scenes; the exit status."""
    problem = lammps_problem(codes)
    if problem:
        sys.exit(f"peer: {problem}")
    host = socket.gethostname() or "unknown"
    host_dir = REPO_ROOT / "reports" / "bench" / host
    work = host_dir / "peer"
    files.remove_tree(work)
    files.make_dirs(work)
    stamp = int(time.time())
    codes = codes.pinned(work)

    # 1. Cross-check: refuse to race different physics.
    ok, results = check.cross_check(codes, work / "check")
    if not ok:
        return 1
    c = results["friction"]

    # 2. The race.
    n = 2000 if quick else RACE_N
    columns = int(round(math.sqrt(2 * n)))
    repeats = 2 if quick else REPEATS
    steps = {"dense": 200 if quick else RACE_STEPS, "settling": 200 if quick else RACE_STEPS}

    state, box, dt, stage = settle_dense(codes, work, n, columns)
    print(f"# dense: N={n} settled frictionless for {stage['cycles']} cycles with "
          f"normal_law = power: "
          f"E_k/E_el = {stage['ke_over_ee']:.2g}; dt = {dt:.6g}", flush=True)
    lattice, lbox, ldt = initial_lattice(codes, work, n, columns)
    races = [Race("dense", work / "dense", state, box, dt, steps["dense"], codes),
             Race("settling", work / "settling", lattice, lbox, ldt, steps["settling"], codes)]
    version = parse_lammps_log((work / "check" / "friction_lammps" / "log.lammps").read_text())["version"]
    for race in races:
        best, _ = sweep(race, race.steps, quick, host_dir, stamp)
        b_rates, l_rates = [], []
        for k in range(repeats):
            rb, run = race.ballast(race.steps)
            rl, log = race.lammps(race.steps, best)
            b_rates.append(rb)
            l_rates.append(rl)
            if log["dangerous"] != 0:
                sys.exit(f"peer: LAMMPS had {log['dangerous']} dangerous neighbour builds")
            print(f"#   {race.name} repeat {k + 1}: ballast {rb:.4g} ({run['wall_seconds']:.2f} s, "
                  f"{run['rebuilds']} rebuilds)  lammps {rl:.4g} ({log['loop_seconds']:.2f} s, "
                  f"{log['builds']} builds, {log['dangerous']} dangerous)", flush=True)
        print(race_line(race.name, race.n, race.steps, b_rates, l_rates, best), flush=True)
        bm, bl, bh = spread(b_rates)
        lm, ll, lh = spread(l_rates)
        append_csv(host_dir / "peer.csv",
                   ["unix_time", "scene", "n", "steps", "repeats", "ballast_median", "ballast_min",
                    "ballast_max", "lammps_median", "lammps_min", "lammps_max", "ratio",
                    "lammps_skin", "lammps_binsize", "lammps_sort_every", "lammps_version",
                    "check_max_dx", "check_max_dF", "ballast_rebuilds", "lammps_builds", "quick"],
                   [stamp, race.name, race.n, race.steps, repeats, f"{bm:.6g}", f"{bl:.6g}",
                    f"{bh:.6g}", f"{lm:.6g}", f"{ll:.6g}", f"{lh:.6g}", f"{bm / lm:.4g}",
                    f"{best['skin']:.6g}", f"{best['binsize']:.6g}", best["sort_every"],
                    '"' + version + '"', f"{c['max_dx']:.3g}", f"{c['max_dF']:.3g}", run["rebuilds"], log["builds"],
                    int(quick)])
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true",
                    help="small N, 2 repeats of short runs: a test of the machinery, not a benchmark")
    code_arguments(ap)
    a = ap.parse_args(argv)
    return race_all(codes_of(a), a.quick)


if __name__ == "__main__":
    sys.exit(main())
