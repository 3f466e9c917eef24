#!/usr/bin/python3
"""core/bench/cost.py -- the cost model of issue 24 (`make bench-cost`).

    /usr/bin/python3 core/bench/cost.py [--repeats R] [--cpu C] [--reuse]

For the two scenes of `make bench-peer` (harness/peer/race.py: `dense`, 20 000
discs settled frictionless then raced from rest with friction; `settling`, the
same discs released from dense.scene's lattice; 3000 steps each, power law
nu = 1, friction 0.5, no damping), per particle-step and per phase:

1. counts that the machine's load does not change (callgrind, build/bench
   --cost: the scene stepped as bal_sim_run steps it, on one thread; the last
   WINDOW of every PERIOD cycles collected, so the 3000 cycles are sampled
   evenly): instructions (Ir), data reads and writes (Dr, Dw), simulated
   misses of the L1d (D1mr + D1mw: lines brought in from L2 or beyond) and
   of the last level (DLmr + DLmw: lines from memory), for two simulated last
   levels: this VM's 32 MB L3 and its 1 MB L2 (so that the second run's LL
   misses are the lines that come from beyond the L2);
2. time (bin/ballast run of the same scene, what bench-peer times, pinned to
   one core with taskset, R alternating repeats): run.json's per-phase
   timers, and wall_seconds minus their sum for the rest (energy audit,
   checks, the series row); cycles = seconds x the measured clock;
3. the machine (build/cost_machine, pinned): clock, peak flops (AVX2 FMA
   and the scalar code the build compiles to), sqrt and division
   throughput, triad bandwidth from L1, L2, L3 and memory.

Phases (callgrind's inclusive cost of the functions cycle() calls, sim.c):
  positions:  bal_integrate_positions, bal_walls_move, bal_grid_due
  neighbours: bal_grid_rebuild, bal_grid_reorder, bal_integrate_reordered
  contacts:   the pair loop (loop_pow_s for these scenes, any loop_* found)
  walls:      bal_wall_loop_run, bal_energy_walls, bal_walls_control
  velocities: bal_integrate_velocities
  outputs:    the rest of the collected cycles (the energy audit of every
              cycle, bal_energy_guard every 256 cycles, the phase timers)

Prints the table (markdown) and writes it with every raw figure to
build/cost/cost.md and build/cost/cost.json.
"""
import argparse
import json
import math
import os
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))    # the repository root, whose harness package this script uses
from harness.peer import race  # noqa: E402  (the scenes of bench-peer, written the same way)
from harness.peer.common import Codes  # noqa: E402

OUT = ROOT / "build" / "cost"
BENCH = ROOT / "build" / "bench"
MACHINE = ROOT / "build" / "cost_machine"
BALLAST = ROOT / "bin" / "ballast"
STEPS = race.RACE_STEPS
N = race.RACE_N
PERIOD, WINDOW = 300, 15          # 10 windows of 15 collected cycles in 3000
CACHES = ["--I1=32768,8,64", "--D1=32768,8,64"]   # lscpu: 32 KB L1d/L1i per core
LLS = {"L3": "--LL=33554432,16,64", "L2": "--LL=1048576,8,64"}
EVENTS = ["Ir", "Dr", "Dw", "D1mr", "D1mw", "DLmr", "DLmw"]
PHASES = {
    "positions": ["bal_integrate_positions", "bal_walls_move", "bal_grid_due"],
    "neighbours": ["bal_grid_rebuild", "bal_grid_reorder", "bal_integrate_reordered"],
    "contacts": [],   # loop_* (the pair loop variant), found by name
    "walls": ["bal_wall_loop_run", "bal_energy_walls", "bal_walls_control"],
    "velocities": ["bal_integrate_velocities"],
}
TIMERS = ["positions", "neighbours", "contacts", "walls", "velocities"]
LINE = 64


def make_scenes(reuse):
    """The two race scenes of bench-peer, in build/cost (settling the dense one
    takes bin/ballast about 15 s)."""
    OUT.mkdir(parents=True, exist_ok=True)
    scenes = {"dense": OUT / f"dense_{STEPS}.scene", "settling": OUT / f"settling_{STEPS}.scene"}
    if reuse and all(p.exists() for p in scenes.values()):
        return scenes
    codes = Codes(BALLAST)
    n, columns = N, int(round(math.sqrt(2 * N)))
    state, box, dt, stage = race.settle_dense(codes, OUT, n, columns)
    print(f"# dense: N={n} settled frictionless for {stage['cycles']} cycles: "
          f"E_k/E_el = {stage['ke_over_ee']:.2g}", flush=True)
    scenes["dense"].write_text(race.race_scene("dense", state, box, dt, STEPS))
    lattice, lbox, ldt = race.initial_lattice(codes, OUT, n, columns)
    scenes["settling"].write_text(race.race_scene("settling", lattice, lbox, ldt, STEPS))
    return scenes


def callgrind(scene, name, ll):
    """Start one counted run; returns (Popen, out file, count file)."""
    cg = OUT / f"{name}-{ll}.callgrind"
    count = OUT / f"{name}-{ll}.count"
    cmd = ["valgrind", "--tool=callgrind", "--instr-atstart=no", "--collect-atstart=no",
           "--cache-sim=yes"] + CACHES + [LLS[ll], f"--callgrind-out-file={cg}",
                                         str(BENCH), "--cost", str(scene), str(PERIOD), str(WINDOW)]
    proc = subprocess.Popen(cmd, stdout=open(count, "w"), stderr=open(f"{count}.log", "w"))
    return proc, cg, count


def parse_count(path):
    line = [l for l in Path(path).read_text().splitlines() if l.startswith("bench cost ")]
    if not line:
        sys.exit(f"cost: no 'bench cost' line in {path} (see {path}.log)")
    return {k: float(v) for k, v in re.findall(r"(\w+)=([-+0-9.eE]+)", line[0])}


def inclusive(cg):
    """{function: [events]} inclusive, and the totals, from callgrind_annotate.

    callgrind_annotate lists a function once per source file its code comes
    from (laws.h inlined into loop_pow_s is a line `core/laws.h:loop_pow_s`)
    and once summed over them; the sum is the largest, and is kept."""
    res = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100",
                          "--show=" + ",".join(EVENTS), str(cg)],
                         capture_output=True, text=True, check=True)
    funcs, total = {}, None
    for line in res.stdout.splitlines():
        head = line.split(" [")[0]
        nums = re.findall(r"(?:^|\s)([0-9][0-9,]*|\.)(?=\s)", head + " ")
        if "PROGRAM TOTALS" in line:
            total = [float(x.replace(",", "")) if x != "." else 0.0 for x in nums[:len(EVENTS)]]
            continue
        m = re.search(r"\S+:([A-Za-z_][\w.']*)\s*$", head)
        if m and len(nums) >= len(EVENTS):
            name = m.group(1)
            vals = [float(x.replace(",", "")) if x != "." else 0.0 for x in nums[:len(EVENTS)]]
            if name not in funcs or vals[0] > funcs[name][0]:
                funcs[name] = vals
    return funcs, total


def phase_counts(cg):
    """Per phase, the events summed over its functions; `outputs` is the rest of
    the collected total."""
    funcs, total = inclusive(cg)
    out = {}
    loops = [f for f in funcs if re.fullmatch(r"loop_(inc|pow)\w*", f) and not f.endswith("_threads")]
    for phase, names in PHASES.items():
        names = loops if phase == "contacts" else names
        out[phase] = [sum(funcs.get(f, [0] * len(EVENTS))[e] for f in names)
                      for e in range(len(EVENTS))]
    out["outputs"] = [total[e] - sum(out[p][e] for p in PHASES) for e in range(len(EVENTS))]
    out["total"] = total
    return out, loops


def machine(cpu, repeats):
    res = subprocess.run(["taskset", "-c", str(cpu), str(MACHINE), str(repeats)],
                         capture_output=True, text=True, check=True)
    m = {}
    for line in res.stdout.splitlines():
        kv = dict(re.findall(r"(\w+)=(\S+)", line))
        words = line.split()
        key = words[1] if "=" not in words[1] else "clock"
        if key in ("triad", "triad256"):
            key = key + "_" + kv.pop("level")
        m[key] = {k: float(v) for k, v in kv.items()}
    m["raw"] = res.stdout
    return m


def native(scenes, cpu, repeats):
    """R alternating pinned runs of bin/ballast per scene: run.json figures."""
    runs = {name: [] for name in scenes}
    for k in range(repeats):
        for name, scene in scenes.items():
            out = OUT / f"run-{name}"
            env = dict(os.environ, OMP_NUM_THREADS="1")
            subprocess.run(["taskset", "-c", str(cpu), str(BALLAST), "run", str(scene), "--out",
                            str(out)], check=True, capture_output=True, env=env)
            run = json.loads((out / "run.json").read_text())
            t = run["timers"]
            runs[name].append({"wall": run["wall_seconds"], "steps": run["steps"],
                               "rebuilds": run["rebuilds"], **{p: t[p] for p in TIMERS},
                               "outputs": run["wall_seconds"] - sum(t[p] for p in TIMERS)})
            print(f"#   {name} repeat {k + 1}: {run['wall_seconds']:.3f} s, "
                  f"{run['rebuilds']} rebuilds", flush=True)
    return runs


def fmt(x, digits=3):
    if x == 0:
        return "0"
    if abs(x) >= 100:
        return f"{x:.0f}"
    return f"{x:.{digits}g}"


# Floating-point operations of the pair loop of these scenes (loop_pow_s, pair_loop.c and
# laws.h, counted from the C source; -ffp-contract=off and no -ffast-math keep every one):
#   every candidate pair: dx, dy, r_i + r_j, dx^2 + dy^2, (r_i + r_j)^2        7
#   every contact: sqrt 1, e = d/D 2 div, v_i - v_j 2, delta 1, F_n = k_n delta 1,
#     s-dot 7, F_s += k_s s-dot dt 3, F_n tan(phi) + c 2, moments 2, force
#     components 6, the four force and two moment sums 6                    33
#   a sliding contact, more: the friction loss f_max (|F_s| - f_max) / k_s   4 (1 div)
# (n-dot is not computed: with the power law and no dashpot nothing reads it.)
FLOPS_PAIR, FLOPS_CONTACT, FLOPS_SLIDE = 7, 33, 4
# the position and velocity passes (centred, undamped): 3 mul + 3 add and the
# displacement since the last rebuild (2 sub, 2 mul, 1 add); 3 x (f m^-1 dt + g dt) + v
FLOPS_POSITIONS, FLOPS_VELOCITIES = 11, 11


def floors(result, mach, clock):
    """The floor per phase and particle-step, in cycles, from the counts and the
    machine: compute (AVX2 code at the measured peak rates; and today's scalar
    code) and data movement (the bytes from beyond each cache level at the
    measured vector-triad bandwidth of the level below)."""
    ghz = clock / 1e9
    bpc = {lvl: mach[f"triad256_{lvl}"]["gbs"] / ghz for lvl in ("L2", "L3", "memory")}
    sq, dv = mach["sqrt"]["ns"] * ghz, mach["div"]["ns"] * ghz
    sq4, dv4 = mach["sqrt256"]["ns"] * ghz, mach["div256"]["ns"] * ghz
    out = [f"Floor (cycles per particle-step at {ghz:.3f} GHz; bandwidths of the AVX2 triad: "
           f"L2 {bpc['L2']:.1f}, L3 {bpc['L3']:.1f}, memory {bpc['memory']:.1f} bytes/cycle; "
           f"sqrt {sq:.1f} and division {dv:.1f} cycles scalar, {sq4:.2f} and {dv4:.2f} per "
           f"element with AVX2; peak {mach['fma256']['flops_per_cycle']:.1f} flops/cycle "
           f"AVX2 FMA, {mach['scalar']['flops_per_cycle']:.1f} scalar):", "",
           "| scene | phase | flops | compute floor, AVX2 [scalar] | data floor | floor "
           "| measured | measured / floor |", "|---|---|---|---|---|---|---|---|"]
    for name, sc in result["scenes"].items():
        c = sc["count"]
        P, C, S = c["pairs_per_disc"], c["contacts_per_disc"], c["sliding_per_disc"]
        tot_floor = 0
        for phase, ph in sc["phases"].items():
            if phase == "total":
                continue
            data = max(ph["D1_bytes"] / bpc["L2"], ph["L2_bytes"] / bpc["L3"]) + \
                ph["L3_bytes"] / bpc["memory"]
            flops, comp, comp_s = 0, 0, 0
            if phase == "contacts":
                flops = FLOPS_PAIR * P + FLOPS_CONTACT * C + FLOPS_SLIDE * S
                other = flops - C - (2 * C + S)
                comp = max(other / 16, C * sq4 + (2 * C + S) * dv4)
                comp_s = max(other / 4, C * sq + (2 * C + S) * dv)
            elif phase in ("positions", "velocities"):
                flops = FLOPS_POSITIONS if phase == "positions" else FLOPS_VELOCITIES
                comp, comp_s = flops / 16, flops / 4
            floor = max(comp, data)
            tot_floor += floor
            ph["floor"] = {"flops": flops, "compute_avx2": comp, "compute_scalar": comp_s,
                           "data": data, "floor": floor}
            out.append(f"| {name} | {phase} | {fmt(flops)} | {fmt(comp)} [{fmt(comp_s)}] | "
                       f"{fmt(data)} | {fmt(floor)} | {fmt(ph['cycles_median'])} | "
                       f"{ph['cycles_median'] / floor:.1f} |" if floor > 0 else
                       f"| {name} | {phase} | - | - | - | - | {fmt(ph['cycles_median'])} | - |")
        m = sc["phases"]["total"]["cycles_median"]
        sc["floor_total"] = tot_floor
        out.append(f"| {name} | total | | | | {fmt(tot_floor)} | {fmt(m)} | {m / tot_floor:.1f} |")
    return "\n".join(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=5, help="timed runs of each scene")
    ap.add_argument("--cpu", type=int, default=1, help="core to pin the timed runs to")
    ap.add_argument("--reuse", action="store_true",
                    help="reuse build/cost's scenes and callgrind outputs when present")
    a = ap.parse_args(argv)
    stamp = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    scenes = make_scenes(a.reuse)

    # 1. counts (all four callgrind runs at once: they are counts, not times)
    procs = {}
    for name, scene in scenes.items():
        for ll in LLS:
            cg, count = OUT / f"{name}-{ll}.callgrind", OUT / f"{name}-{ll}.count"
            if a.reuse and cg.exists() and count.exists() and "bench cost" in count.read_text():
                procs[(name, ll)] = (None, cg, count)
            else:
                procs[(name, ll)] = callgrind(scene, name, ll)
    for key, (p, cg, count) in procs.items():
        if p is not None and p.wait() != 0:
            sys.exit(f"cost: callgrind failed for {key}: see {count}.log")
    # 2., 3. then the times, pinned (the other users of the machine stay: hence the
    # medians and ranges); the machine before and after the timed runs
    load0 = open("/proc/loadavg").read().split()[:3]
    mach = machine(a.cpu, 15)
    print(mach["raw"], end="", flush=True)
    runs = native(scenes, a.cpu, a.repeats)
    mach2 = machine(a.cpu, 15)
    print(mach2["raw"], end="", flush=True)
    load1 = open("/proc/loadavg").read().split()[:3]

    clock = max(mach["clock"]["clock_ghz"], mach2["clock"]["clock_ghz"]) * 1e9
    result = {"date": stamp, "load_before": load0, "load_after": load1, "clock_hz": clock,
              "machine": {k: v for k, v in mach.items() if k != "raw"},
              "machine_after": {k: v for k, v in mach2.items() if k != "raw"},
              "period": PERIOD, "window": WINDOW, "scenes": {}}
    rows = []
    for name in scenes:
        counts, loops = {}, None
        for ll in LLS:
            counts[ll], loops = phase_counts(procs[(name, ll)][1])
        info = parse_count(procs[(name, "L3")][2])
        ps = info["particle_steps"]
        r = runs[name]
        n_disc = info["N"]
        scene_res = {"count": info, "loops": loops, "runs": r, "phases": {}}
        # The windows hold a sample of the rebuilds: the neighbour phase is
        # scaled to the run's own rate (its cost per rebuild x rebuilds per cycle
        # of the whole run), and the total is the sum of the phases.
        scale = 1.0
        if info["counted_rebuilds"] > 0:
            scale = (info["rebuilds"] / info["steps"]) / (info["counted_rebuilds"] / info["counted_steps"])
        for ll in LLS:
            counts[ll]["neighbours"] = [v * scale for v in counts[ll]["neighbours"]]
            counts[ll]["total"] = [sum(counts[ll][p][e] for p in list(PHASES) + ["outputs"])
                                   for e in range(len(EVENTS))]
        scene_res["neighbour_scale"] = scale
        for phase in list(PHASES) + ["outputs", "total"]:
            c3, c2 = counts["L3"][phase], counts["L2"][phase]
            ev = dict(zip(EVENTS, c3))
            per = {
                "Ir": ev["Ir"] / ps,
                "Dr": ev["Dr"] / ps, "Dw": ev["Dw"] / ps,
                "D1_bytes": (ev["D1mr"] + ev["D1mw"]) * LINE / ps,
                "L2_bytes": (c2[EVENTS.index("DLmr")] + c2[EVENTS.index("DLmw")]) * LINE / ps,
                "L3_bytes": (ev["DLmr"] + ev["DLmw"]) * LINE / ps,
            }
            key = "wall" if phase == "total" else phase
            cyc = sorted(x[key] * clock / (n_disc * x["steps"]) for x in r)
            per["cycles_median"] = statistics.median(cyc)
            per["cycles_min"], per["cycles_max"] = cyc[0], cyc[-1]
            scene_res["phases"][phase] = per
            rows.append((name, phase, per))
        rates = sorted(n_disc * x["steps"] / x["wall"] for x in r)
        scene_res["rate_median"] = statistics.median(rates)
        scene_res["rate_min"], scene_res["rate_max"] = rates[0], rates[-1]
        result["scenes"][name] = scene_res

    lines = [f"Measured {stamp} on this machine (load average {' '.join(load0)} before, "
             f"{' '.join(load1)} after); clock {clock / 1e9:.3f} GHz (measured, best of 15); "
             f"callgrind on {STEPS // PERIOD} windows of {WINDOW} cycles "
             f"(every {PERIOD}) of the {STEPS}, the neighbour phase scaled to the run's rebuild rate; "
             f"times: {a.repeats} pinned repeats of bin/ballast.",
             "",
             "| scene | phase | instructions | data reads | data writes | L1d-miss bytes "
             "| L2-miss bytes | L3-miss bytes | cycles, median [range] |",
             "|---|---|---|---|---|---|---|---|---|"]
    for name, phase, p in rows:
        lines.append(f"| {name} | {phase} | {fmt(p['Ir'])} | {fmt(p['Dr'])} | {fmt(p['Dw'])} | "
                     f"{fmt(p['D1_bytes'])} | {fmt(p['L2_bytes'])} | {fmt(p['L3_bytes'])} | "
                     f"{fmt(p['cycles_median'])} [{fmt(p['cycles_min'])}–{fmt(p['cycles_max'])}] |")
    lines.append("")
    for name, s in result["scenes"].items():
        c = s["count"]
        lines.append(f"- {name}: {int(c['N'])} discs; sampled cycles: {c['pairs_per_disc']:.3f} "
                     f"candidate pairs, {c['contacts_per_disc']:.3f} disc-disc contacts, "
                     f"{c['wall_contacts_per_disc']:.4f} wall contacts, "
                     f"{c['sliding_per_disc']:.4f} sliding contacts per disc; "
                     f"{int(c['counted_rebuilds'])} rebuilds in {int(c['counted_steps'])} counted "
                     f"cycles ({int(c['rebuilds'])} in all {int(c['steps'])}); timed: "
                     f"{s['rate_median']:.4g} particle-steps/s [{s['rate_min']:.4g}–"
                     f"{s['rate_max']:.4g}], neighbour scale {s['neighbour_scale']:.3f}, rebuilds per run "
                     f"{sorted(set(x['rebuilds'] for x in s['runs']))}; pair loop {s['loops']}")
    lines += ["", floors(result, mach, clock)]
    text = "\n".join(lines) + "\n"
    print(text)
    (OUT / "cost.md").write_text(text + "\n```\n" + mach["raw"] + mach2["raw"] + "```\n")
    (OUT / "cost.json").write_text(json.dumps(result, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
