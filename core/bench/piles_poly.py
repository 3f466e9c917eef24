"""Realisations per hour per core of the polydisperse pile (make bench-piles-poly; issue 22).

    python3 core/bench/piles_poly.py BIN SCENE [N] [--every-cycle K]

runs N (default 20) realisations of SCENE (cases/piles_poly/pile_poly.scene: L0 = 100,
r_d = 1/30, k_n = 1e4 m g/d0), seeds 1 ... N, one after the other on one core, each to rest
under the scene's stop rule, and prints per realisation the CPU seconds (user + system of the
child, getrusage), the cycles of each stage, and the cycle at which E_k / E_el first fell
below the stop rule's 1e-10 (from series.tsv).  The figure is 3600 / (mean CPU seconds): CPU,
not wall-clock, because this VM's two cores are shared.  With --every-cycle K it then runs the
first K seeds again with a series row every cycle (output_every = 1, the setting of the
monodisperse pile scenes) to show what that costs.  Nothing here is a test: no speed is
asserted.
"""
import json
import resource
import subprocess
import sys
import tempfile
from pathlib import Path


def child_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def first_below(series, ratio=1e-10, after=0):
    lines = Path(series).read_text().splitlines()
    head = lines[0].split("\t")
    c, k, e = head.index("cycle"), head.index("Ek"), head.index("Ee")
    for line in lines[1:]:
        cells = line.split("\t")
        cycle, ek, ee = int(cells[c]), float(cells[k]), float(cells[e])
        if cycle > after and ee > 0 and ek < ratio * ee:
            return cycle
    return None


def one(binary, scene, seed, extra, work):
    out = Path(work) / f"s{seed}"
    before = child_cpu()
    subprocess.run([binary, "run", scene, "--out", str(out), "--set", f"pile.p.seed={seed}", *extra],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    cpu = child_cpu() - before
    info = json.loads((out / "run.json").read_text())
    stages = info["stages"]
    return {"seed": seed, "cpu": cpu, "steps": info["steps"], "discs": info["n_discs"],
            "stages": [(s["name"], s["cycles"], s["stopped"]) for s in stages],
            "ke_below": first_below(out / "series.tsv", after=stages[0]["cycles"])}


def main(argv):
    args = [a for a in argv if not a.startswith("--")]
    every = 0
    if "--every-cycle" in argv:
        every = int(argv[argv.index("--every-cycle") + 1])
        args.remove(str(every))
    binary, scene = args[0], args[1]
    n = int(args[2]) if len(args) > 2 else 20
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for seed in range(1, n + 1):
            r = one(binary, scene, seed, [], work)
            rows.append(r)
            stages = " ".join(f"{name} {cycles}{'' if stopped or name == 'ramp' else ' (NOT at rest)'}"
                              for name, cycles, stopped in r["stages"])
            print(f"seed {seed:3d}  {r['discs']} discs  {r['cpu']:6.2f} s CPU  {r['steps']:6d} cycles "
                  f"({stages}; E_k < 1e-10 E_el first at cycle {r['ke_below']})", flush=True)
        cpu = sorted(r["cpu"] for r in rows)
        mean = sum(cpu) / n
        cycles = sum(r["steps"] for r in rows) / n
        discs = rows[0]["discs"]
        print(f"\n{n} realisations: CPU per realisation mean {mean:.3f} s, median {cpu[n // 2]:.3f} s, "
              f"min {cpu[0]:.3f} s, max {cpu[-1]:.3f} s; mean cycles to rest {cycles:.0f}; "
              f"{discs * cycles / mean:.3g} particle-steps/s")
        print(f"realisations per hour per core: {3600 / mean:.0f} (from the mean CPU time)")
        if every:
            slow = [one(binary, scene, seed, ["--set", "settings.output_every=1"], work)["cpu"]
                    for seed in range(1, every + 1)]
            fast = [r["cpu"] for r in rows[:every]]
            print(f"with a series row every cycle (output_every = 1), seeds 1-{every}: "
                  f"{sum(slow) / every:.3f} s CPU each against {sum(fast) / every:.3f} s "
                  f"(x{sum(slow) / sum(fast):.1f})")


if __name__ == "__main__":
    main(sys.argv[1:])
