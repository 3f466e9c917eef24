#!/usr/bin/python3
"""harness/peer/rolling.py -- JYH rolling resistance (Model 1) against LAMMPS's pair granular.

    /usr/bin/python3 -m harness.peer.rolling --out DIR [--ballast BIN] [--lmp LMP]

ballast's Model 1 (Jiang, Yu & Harris 2005, core/laws.h) against LAMMPS's pair
granular `rolling sds k_roll gamma_roll mu_roll` (Debian's lammps, 29 Sep 2021
update 2), both written from the same discs by harness/peer/common.py.  The
catalogue's full-tier case `peer_rolling` (cases/peer/case.txt) runs this and
holds its figures to reference/peer_rolling.ref; docs/benchmarks.md has the
mapping table, its sources and the figures measured.

The mapping (lammps_rolling()).  JYH's common radius r is 2 r1 r2 / (r1 + r2)
for two discs (eq. 9b) and 2 r1 against a wall (eq. 11b); LAMMPS's R_eff is
r1 r2 / (r1 + r2), and r1 against a flat wall.  So r = 2 R_eff at every contact,
B = delta r = 2 delta R_eff, and

    K_m  = k_n B^2 / 12  = (k_n delta^2 / 3) R_eff^2    ->  k_roll     = k_n delta^2 / 3
    M_0  = F_n B / 6     = (delta / 3) R_eff F_n        ->  mu_roll    = delta / 3
    mu_m = mu_n B^2 / 12 = (mu_n delta^2 / 3) R_eff^2   ->  gamma_roll = mu_n delta^2 / 3

LAMMPS's couple on i is R_eff n x F_roll, F_roll = -k_roll xi - gamma_roll v_roll,
v_roll = R_eff (omega_i - omega_j) x n and xi its integral, kept in the tangent
plane at its length: in 2D -(k_roll R_eff^2 theta_r + gamma_roll R_eff^2
theta_r'), ballast's -(M + M_d) with theta_r = int (omega_i - omega_j) dt.  The
three numbers do not depend on the radii: one atom type serves a polydisperse
packing, and the walls take the same three.  The dashpot matches only below the
cap: LAMMPS caps spring and dashpot together at mu_roll R_eff |F_n + D_n|, ballast
the spring alone at the elastic F_n's M_0, adding M_d on top.

Tests (each prints a line; --out DIR also writes them as a run, series.tsv and
run.json, one column per figure):

1. two_discs: two discs (r 0.5 and 0.75), frictionless, pressed between two
   walls without gravity (the forces balance, nothing translates).  Disc 0
   spins at TWO_OMEGA0, disc 1 is at rest: the rolling spring loads
   elastically, reaches M_0, rolls plastically until the relative spin stops,
   then unloads and oscillates elastically.  M and both spins at every step.
   damped: the same with contact damping beta = DAMPED_BETA and a spin small
   enough that the moment stays below the cap, where the dashpots match.
2. packing: PACK_N discs of cases/bench/dense.scene's fill, released from its
   lattice with its random velocities and random spins (frictionless, rolling
   would otherwise have nothing to resist), fall and collide in the box for
   PACK_STEPS steps with rolling at every contact, walls included.  Positions,
   velocities, spins, forces, torques and every contact's f_n and rolling
   couple at the end, as common.compare() compares them.
3. collision: friction 0.5 as well.  LAMMPS's pair granular applies the
   tangential force at the middle of the overlap (r - overlap/2), ballast (C&S)
   at r: the codes differ by F_s overlap / 2 per contact.  Two discs collide
   obliquely, disc 0 spinning, at k_n, 4 k_n and 16 k_n (the step and the
   steps scaled so that each resolves the collision alike): the difference
   falls as the overlap, halving each time.
   friction_packing: the packing of 2 with friction 0.5 and without the
   spins, for the record only: that term, amplified by the collisions, is
   1e-3 of the positions after 400 steps (docs/benchmarks.md).

LAMMPS's neighbour lists are all-pairs without sorting (engines/lammps.py: in
this LAMMPS a pair that changes sides at a rebuild has its rolling history
negated).  Where LAMMPS is absent and cannot be installed, --out writes a
skipped run (common.skip_outputs) and the case's checks are SKIP.

Model 2 (elasto-brittle, JYH eq. 36) has no counterpart in LAMMPS.
"""
import argparse
import math
import sys
from pathlib import Path

import numpy as np

from .. import files
from ..final_state import Table
from ..tables import read_series
from . import common
from ..engines.lammps import rolling_sds
from .common import DENSITY, FIGURES, KN, MU

DELTA = 0.8            # JYH's shape parameter of every test
# Where the physics is the same in both codes (tests 1 and 2): round-off, as check.py's
# frictionless check (collisions amplify it about e-fold per 50 steps; measured 1e-11 at
# most after the 500 steps of the packing, 2e-14 over the two discs' 1200).
TOL_EXACT = 1e-10

# ---- test 1: two discs --------------------------------------------------------------------
TWO_R = (0.5, 0.75)    # unequal: R_eff = 0.3, JYH's r = 0.6, B = 0.48
TWO_OVERLAP = 0.01     # at every contact, so that the normal forces balance
TWO_OMEGA0 = 20.0      # 3 x the 6.4 rad/time the elastic spring alone could stop
TWO_DT = 1e-4          # 410 steps per period of the rolling oscillation
TWO_STEPS = 1200
DAMPED_BETA = 1e-3     # damping ratio of the rolling oscillation beta Omega / 2 = 0.08
DAMPED_OMEGA0 = 3.0    # peak |M + M_d| about 0.55 M_0: below the cap
TWO_PROBES = (("m", "contact_mr", "d0", "d1"), ("capped", "contact_rolling", "d0", "d1"),
              ("w0", "disc_omega", "d0", None), ("w1", "disc_omega", "d1", None))
TWO_OUTPUT = """dump            spins all custom 1 spins.dump id omegaz tqz
dump_modify     spins sort id format float %.17g"""

# ---- test 2: a packing ----------------------------------------------------------------------
PACK_STEPS = 500       # 17 disc-disc contacts at the end, 3 of them at the cap
SPIN = 4.0             # initial spins uniform in [-SPIN, SPIN], rad/time
SPIN_SEED = 20
FRICTION_STEPS = 400
PACK_OUTPUT = """compute         pairs all pair/local dist force p1 p2 p4 p5 p6
compute         ids all property/local patom1 patom2
dump            atoms all custom @steps@ atoms.dump id radius mass x y vx vy omegaz fx fy tqz
dump_modify     atoms sort id format float %.17g
dump            pairs all local @steps@ pairs.dump c_ids[1] c_ids[2] c_pairs[1] c_pairs[2] c_pairs[3] c_pairs[4] c_pairs[5] c_pairs[6] c_pairs[7]
dump_modify     pairs format float %.17g"""
PACK_FIGURES = FIGURES + ("max_dM",)

# ---- test 3: a collision with friction ------------------------------------------------------
COLL_STIFFNESS = (1, 4, 16)   # k_n / KN; dt and the steps scale with sqrt of it
COLL_DT = 1e-4
COLL_STEPS = 150              # the collision takes about 70 steps at k_n = KN
COLL_OMEGA0 = 8.0
# First order in the overlap, which scales as k_n^(-1/2): each ratio 0.5 (measured 0.49,
# 0.50); the limits keep out an O(dt) or O(1) difference (ratio 1) and round-off.
COLL_RATIO = (0.4, 0.6)


# ---------------------------------------------------------------------------------------------
# The mapping
# ---------------------------------------------------------------------------------------------

def lammps_rolling(delta, kn, mu_n=0.0):
    """LAMMPS's pair granular `rolling sds k_roll gamma_roll mu_roll` of JYH's Model 1 with
    shape parameter delta, normal stiffness kn and normal dashpot mu_n (the module docstring):
    the same for every pair of radii and for flat walls.  The translation's own
    (engines/lammps.py, rolling_sds), which every LAMMPS input of the harness takes."""
    return rolling_sds(delta, kn, mu_n)


def contact_constants(delta, kn, r1, r2=None, mu_n=0.0):
    """One contact's rolling constants in both codes' terms: JYH's common radius r, B, K_m,
    M_0 / F_n and mu_m (core/laws.h), and LAMMPS's R_eff with k_roll R_eff^2,
    mu_roll R_eff and gamma_roll R_eff^2 (r2 None: a flat wall).  They agree for every
    radius."""
    r = 2 * r1 if r2 is None else 2 * r1 * r2 / (r1 + r2)
    r_eff = r1 if r2 is None else r1 * r2 / (r1 + r2)
    b = delta * r
    lmp = lammps_rolling(delta, kn, mu_n)
    return {"r": r, "B": b, "K_m": kn * b * b / 12, "M0_per_Fn": b / 6,
            "mu_m": mu_n * b * b / 12, "R_eff": r_eff,
            "k_roll_R2": lmp["k_roll"] * r_eff * r_eff, "mu_roll_R": lmp["mu_roll"] * r_eff,
            "gamma_roll_R2": lmp["gamma_roll"] * r_eff * r_eff}


def state_of(x, y, r, vx, vy, omega):
    """A state of common.disc_state()'s form (m = density pi r^2) from lists."""
    out = {k: np.array(v, dtype=float) for k, v in
           (("x", x), ("y", y), ("r", r), ("vx", vx), ("vy", vy), ("omega", omega))}
    out["m"] = DENSITY * math.pi * out["r"] ** 2
    return out


def run_both(codes, work, label, state, box, dt, steps, output, mu, g=common.G, kn=KN,
             delta=DELTA, wall_rolling=True, beta=0.0, probes=(), output_every=None):
    """Write one test as a ballast scene and run it in both codes under work/label_ballast and
    work/label_lammps (LAMMPS through the harness's translation, engines/lammps.py, which maps
    Model 1 to `rolling sds` with lammps_rolling()'s numbers and keeps every pair on one side:
    all-pairs lists, no sorting)."""
    work = files.make_dirs(work)
    scene = work / f"{label}.scene"
    files.write_text(scene, common.ballast_scene(state, box, dt, steps, f"peer rolling {label}",
                                                 kn=kn, kt=kn, mu=mu, g=g, rolling=delta,
                                                 wall_rolling=delta if wall_rolling else 0.0,
                                                 output_every=output_every, probes=probes, beta=beta))
    common.run_ballast(codes, ["run", scene], work / f"{label}_ballast")
    lw = files.make_dirs(work / f"{label}_lammps")
    common.run_lammps(codes, lw, scene, output.replace("@steps@", str(steps)), skin=0.25)
    return work / f"{label}_ballast", lw


# ---------------------------------------------------------------------------------------------
# Test 1: two discs
# ---------------------------------------------------------------------------------------------

def two_disc_state(omega0):
    """Disc 0 spinning at omega0 and disc 1 at rest side by side between two walls, every
    overlap TWO_OVERLAP: the normal forces balance and nothing translates."""
    ra, rb = TWO_R
    ov = TWO_OVERLAP
    xa = ra - ov
    xb = xa + ra + rb - ov
    box = (0.0, xb + rb - ov, 0.0, 4 * rb)
    return state_of([xa, xb], [2 * rb, 2 * rb], [ra, rb], [0, 0], [0, 0], [omega0, 0]), box


def two_discs(codes, work, damped=False):
    """Test 1 in both codes (undamped through the cap, or damped below it); its figures:
    max_dM (the couple on disc 0 at every step, relative to M_0), max_dw (both spins, to
    the initial spin), peak (largest |M| / M_0 in ballast: 1 at the cap), capped (steps
    at the cap) and plastic_end (the last step of the first stretch at the cap)."""
    omega0, beta = (DAMPED_OMEGA0, DAMPED_BETA) if damped else (TWO_OMEGA0, 0.0)
    label = "two_damped" if damped else "two"
    state, box = two_disc_state(omega0)
    const = contact_constants(DELTA, KN, *TWO_R, mu_n=beta * KN)
    bw, lw = run_both(codes, work, label, state, box, TWO_DT, TWO_STEPS, TWO_OUTPUT,
                      mu=0.0, g=0.0, wall_rolling=False, beta=beta, probes=TWO_PROBES, output_every=1)
    series = read_series(bw / "series.tsv")
    cycle, m, capped, w0, w1 = (series[k] for k in ("cycle", "m", "capped", "w0", "w1"))
    frames = {f["_step"]: f for f in common.parse_frames((lw / "spins.dump").read_text())}
    inertia = 0.5 * state["m"] * state["r"] ** 2
    return two_disc_figures(cycle, m, capped, w0, w1, frames, KN * TWO_OVERLAP * const["M0_per_Fn"],
                            omega0, const["mu_m"], inertia, TWO_DT)


def two_disc_figures(cycle, m, capped, w0, w1, frames, m0, omega0, mu_m=0.0, inertia=None,
                     dt=TWO_DT):
    """The figures of two_discs() from ballast's series and LAMMPS's frames {step: frame}.

    The couple on disc 0 is -(M + M_d); ballast's probe gives M, and M_d = mu_m times the
    relative spin of the step, (omega_0 - omega_1) at t - dt/2, which the centred spins
    of the series give back with the couple itself (inertia: the discs' I)."""
    dm, dw, n = 0.0, 0.0, 0
    for k, step in enumerate(cycle.astype(int)):
        if step == 0 or step not in frames:
            continue
        f = frames[step]
        order = np.argsort(f["id"])
        wz, tq = f["omegaz"][order], f["tqz"][order]
        couple = m[k]
        if mu_m:
            # omega(t - dt/2) = omega(t) - dt/2 T/I with T = -(M + M_d) on 0, + on 1
            rel = (w0[k] - w1[k]) + 0.5 * dt * m[k] * (1 / inertia[0] + 1 / inertia[1])
            rel /= 1 - 0.5 * dt * mu_m * (1 / inertia[0] + 1 / inertia[1])
            couple = m[k] + mu_m * rel
        dm = max(dm, abs(couple + tq[0]))
        dw = max(dw, abs(w0[k] - wz[0]), abs(w1[k] - wz[1]))
        n += 1
    at_cap = np.flatnonzero(capped == 1)
    end = -1
    if at_cap.size:
        breaks = np.flatnonzero(np.diff(at_cap) > 1)
        end = int(cycle[at_cap[breaks[0]] if breaks.size else at_cap[-1]])
    return {"steps": int(cycle[-1]), "compared": n, "max_dM": dm / m0, "max_dw": dw / omega0,
            "peak": float(np.max(np.abs(m))) / m0, "capped": int(at_cap.size),
            "plastic_end": end}


def two_disc_verdict(c, damped=False):
    """Round-off agreement at every step; undamped, a stretch at the cap (peak 1) ending
    well before the run does; damped, never at the cap."""
    ok = (c["compared"] == c["steps"] and c["max_dM"] <= TOL_EXACT and c["max_dw"] <= TOL_EXACT)
    if damped:
        return ok and c["capped"] == 0 and c["peak"] < 0.9
    return (ok and abs(c["peak"] - 1) <= TOL_EXACT and c["capped"] >= 10
            and 0 < c["plastic_end"] < c["steps"] / 2)


def two_disc_line(c, ok, label):
    return (f"peer rolling {label} steps={c['steps']} compared={c['compared']} "
            f"max_dM={c['max_dM']:.3g} max_dw={c['max_dw']:.3g} peak={c['peak']:.6g} "
            f"capped={c['capped']} plastic_end={c['plastic_end']} {'PASS' if ok else 'FAIL'}")


# ---------------------------------------------------------------------------------------------
# Test 2: a packing
# ---------------------------------------------------------------------------------------------

def spun(state, spin=SPIN, seed=SPIN_SEED):
    """The state with spins uniform in [-spin, spin] (a fixed seed)."""
    out = dict(state)
    out["omega"] = np.random.default_rng(seed).uniform(-spin, spin, len(state["x"]))
    return out


def ballast_couples(contacts):
    """The rolling couple of every disc-disc contact on its lower id, from contacts.tsv (a
    path): {(lower id, higher id): couple}; body a of a row gets -(mr + md)."""
    table = Table(contacts, common.CONTACT_COLUMNS)
    out = {}
    if not table.has("mr"):
        return out
    mr, md = table.numbers("mr"), table.numbers("md")
    a_, b_ = table.text("a"), table.text("b")
    for k, kind in enumerate(table.text("kind")):
        if kind != "disc":
            continue
        a, b = int(a_[k][1:]), int(b_[k][1:])
        couple = -(mr[k] + md[k])
        out[(min(a, b), max(a, b))] = couple if a < b else -couple
    return out


def lammps_couples(local, atoms):
    """The rolling couple of every touching pair on its lower id, from the pair/local dump
    of PACK_OUTPUT and the atoms dump: {(lower id, higher id): couple} (0-based ids).

    In this LAMMPS compute pair/local's p5, p6 of pair granular are the rolling
    pseudo-force F_roll (x, y), not a torque: the couple on i is R_eff (n x F_roll)_z,
    n = (x_i - x_j) / |x_i - x_j|."""
    out = {}
    if not local or "c_ids[1]" not in local:
        return out
    pos = {int(i): (x, y, r) for i, x, y, r in zip(atoms["id"], atoms["x"], atoms["y"],
                                                 atoms["radius"])}
    for i, j, fn, frx, fry in zip(local["c_ids[1]"], local["c_ids[2]"], local["c_pairs[2]"],
                                  local["c_pairs[6]"], local["c_pairs[7]"]):
        if fn <= 0:
            continue
        (xi, yi, ri), (xj, yj, rj) = pos[int(i)], pos[int(j)]
        d = math.hypot(xi - xj, yi - yj)
        nx, ny = (xi - xj) / d, (yi - yj) / d
        tz = ri * rj / (ri + rj) * (nx * fry - ny * frx)
        i, j = int(i) - 1, int(j) - 1
        out[(min(i, j), max(i, j))] = tz if i < j else -tz
    return out


def packing(codes, work, state, box, dt, steps, friction, label):
    """Test 2 on `state` in both codes: common.compare()'s figures, the tangential force
    taken at LAMMPS's arm (common.ballast_forces), and max_dM: every disc-disc contact's
    rolling couple, relative to the largest contact f_n times the mean radius; with
    rolling_contacts (those with a couple) and at_cap (those at the cap) in ballast."""
    bw, lw = run_both(codes, work, label, state, box, dt, steps, PACK_OUTPUT,
                      mu=friction)
    atoms = common.parse_dump((lw / "atoms.dump").read_text())
    if atoms["_step"] != steps:
        raise ValueError(f"the LAMMPS dump is of step {atoms['_step']}, not {steps}")
    local = common.parse_dump((lw / "pairs.dump").read_text())
    c = common.compare(state, bw, atoms, local, dt, arm="contact")
    bm, lm = ballast_couples(bw / "contacts.tsv"), lammps_couples(local, atoms)
    both = set(bm) & set(lm)
    c["max_dM"] = max([abs(bm[k] - lm[k]) for k in both] + [0.0]) / (
        c["fscale"] * float(np.mean(state["r"])))
    c["rolling_contacts"] = sum(1 for v in bm.values() if v != 0)
    contacts = Table(bw / "contacts.tsv", common.CONTACT_COLUMNS)
    c["at_cap"] = sum(int(v == "1") for v in contacts.text("rolling")) if contacts.has("rolling") else 0
    return c


def packing_verdict(c):
    """common.check_verdict() at TOL_EXACT for every figure, with couples to compare, some
    of them at the cap."""
    return (common.check_verdict(c, dict.fromkeys(FIGURES, TOL_EXACT))
            and c["max_dM"] <= TOL_EXACT and c["rolling_contacts"] > 0 and c["at_cap"] > 0)


def packing_line(c, ok, label):
    figures = " ".join(f"{k}={c[k]:.3g}" for k in PACK_FIGURES)
    return (f"peer rolling {label} N={c['n']} steps={c['step']} {figures} "
            f"contacts={c['contacts_ballast']}/{c['contacts_lammps']} "
            f"rolling={c['rolling_contacts']} at_cap={c['at_cap']} sliding={c['sliding']}"
            + ("" if ok is None else f" {'PASS' if ok else 'FAIL'}"))


# ---------------------------------------------------------------------------------------------
# Test 3: a collision with friction
# ---------------------------------------------------------------------------------------------

def collision_state():
    """Disc 0 (r 0.5, spinning) about to hit disc 1 (r 0.75, at rest) obliquely."""
    ra, rb = TWO_R
    return (state_of([5.0 + ra + rb + 1e-4, 5.0], [5.0, 5.0], [ra, rb], [-2.0, 0.0], [1.0, 0.0],
                     [COLL_OMEGA0, 0.0]),
            (0.0, 12.0, 0.0, 10.0))


def collision(codes, work, stiffness):
    """Test 3 at k_n = stiffness KN: the largest relative difference of the final spins and
    velocities (to the largest of each), with overlap (the largest f_n / k_n over the
    run), capped and sliding (steps at the rolling cap and sliding) in ballast."""
    scale = int(round(math.sqrt(stiffness)))
    dt, steps = COLL_DT / scale, COLL_STEPS * scale
    state, box = collision_state()
    probes = (("fn", "contact_fn", "d0", "d1"), ("capped", "contact_rolling", "d0", "d1"),
              ("sliding", "contact_sliding", "d0", "d1"))
    out = ("dump            end all custom @steps@ end.dump id vx vy omegaz\n"
           "dump_modify     end sort id format float %.17g")
    bw, lw = run_both(codes, work, f"collision_k{stiffness}", state, box, dt, steps,
                      out, mu=MU, g=0.0, kn=stiffness * KN, wall_rolling=False, probes=probes,
                      output_every=1)
    b = common.disc_state(bw / "discs.tsv")
    lmp = common.parse_dump((lw / "end.dump").read_text())
    series = read_series(bw / "series.tsv")
    fn, capped, sliding = series["fn"], series["capped"], series["sliding"]
    dw = np.max(np.abs(b["omega"] - lmp["omegaz"])) / np.max(np.abs(b["omega"]))
    dv = (np.max(np.hypot(b["vx"] - lmp["vx"], b["vy"] - lmp["vy"]))
          / np.max(np.hypot(b["vx"], b["vy"])))
    return {"diff": float(max(dw, dv)), "overlap": float(fn.max()) / (stiffness * KN),
            "capped": int(capped.sum()), "sliding": int(sliding.sum())}


def collision_figures(runs):
    """{stiffness: collision()} -> the figures of test 3: the differences, the ratios of
    successive ones, and bound = the largest overlap / (2 r_min) at k_n = KN: the largest
    relative change of a torque by LAMMPS's arm."""
    out = {f"diff_k{s}": runs[s]["diff"] for s in COLL_STIFFNESS}
    for lo, hi in zip(COLL_STIFFNESS, COLL_STIFFNESS[1:]):
        out[f"ratio_k{hi}"] = runs[hi]["diff"] / max(runs[lo]["diff"], 1e-300)
    first = runs[COLL_STIFFNESS[0]]
    out.update(bound=first["overlap"] / (2 * min(TWO_R)), capped=first["capped"],
               sliding=first["sliding"])
    return out


def collision_verdict(c):
    ratios = [c[f"ratio_k{s}"] for s in COLL_STIFFNESS[1:]]
    return (all(COLL_RATIO[0] <= r <= COLL_RATIO[1] for r in ratios)
            and 0 < c[f"diff_k{COLL_STIFFNESS[0]}"] <= c["bound"]
            and c["capped"] > 0 and c["sliding"] > 0)


def collision_line(c, ok):
    figures = " ".join(f"{k}={v:.3g}" for k, v in c.items() if k not in ("capped", "sliding"))
    return (f"peer rolling collision {figures} capped={c['capped']} sliding={c['sliding']} "
            f"{'PASS' if ok else 'FAIL'}")


# ---------------------------------------------------------------------------------------------
# All of it, and the run's outputs
# ---------------------------------------------------------------------------------------------

def cross_check(codes, work):
    """Every test, a line each; (all passed, {test: figures})."""
    work = Path(work)
    results, verdicts = {}, []
    for damped in (False, True):
        label = "two_damped" if damped else "two_discs"
        c = two_discs(codes, work, damped)
        ok = two_disc_verdict(c, damped)
        print(two_disc_line(c, ok, label), flush=True)
        results[label], verdicts = c, verdicts + [ok]
    state, box, dt = common.check_state(codes, work / "fill")
    c = packing(codes, work, spun(state), box, dt, PACK_STEPS, 0.0, "packing")
    ok = packing_verdict(c)
    print(packing_line(c, ok, "packing"), flush=True)
    results["packing"], verdicts = c, verdicts + [ok]
    c = collision_figures({s: collision(codes, work, s) for s in COLL_STIFFNESS})
    ok = collision_verdict(c)
    print(collision_line(c, ok), flush=True)
    results["collision"], verdicts = c, verdicts + [ok]
    c = packing(codes, work, state, box, dt, FRICTION_STEPS, MU, "friction_packing")
    print(packing_line(c, None, "friction_packing") + " (for the record)", flush=True)
    results["friction_packing"] = c
    return all(verdicts), results


# The columns of series.tsv: (test, figure) in order.
COLUMNS = ([("two_discs", k) for k in ("max_dM", "max_dw", "peak", "capped", "plastic_end")]
           + [("two_damped", k) for k in ("max_dM", "max_dw", "peak", "capped")]
           + [("packing", k) for k in PACK_FIGURES + ("contacts_ballast", "contacts_only_one",
                                                      "rolling_contacts", "at_cap")]
           + [("collision", k) for k in [f"diff_k{s}" for s in COLL_STIFFNESS]
              + [f"ratio_k{s}" for s in COLL_STIFFNESS[1:]] + ["bound", "capped", "sliding"]]
           + [("friction_packing", k) for k in PACK_FIGURES])


def check_outputs(results, ok):
    """The cross-check as a run's outputs (series.tsv, run.json): one row, a column
    TEST_FIGURE per entry of COLUMNS."""
    names = ["cycle", "time"] + [f"{t}_{k}" for t, k in COLUMNS]
    values = [0.0, 0.0] + [float(results[t][k]) for t, k in COLUMNS]
    series = "\t".join(names) + "\n" + "\t".join(repr(v) for v in values) + "\n"
    info = {"status": "ok" if ok else "failed", "message": "" if ok else "cross-check failed",
            "steps": PACK_STEPS, "n_discs": int(results["packing"]["n"])}
    return series, info


def run(out, codes):
    """Every test written like a run into out (exit status 0 when all passed); a skipped
    run when LAMMPS cannot run them (common.lammps_problem())."""
    out = files.make_dirs(out)
    problem = common.lammps_problem(codes, ("granular", "wall/gran"))
    if problem:
        print(f"peer rolling: skipped: {problem}", flush=True)
        common.write_outputs(out, *common.skip_outputs(problem))
        return 0
    ok, results = cross_check(codes.pinned(out), out / "work")
    common.write_outputs(out, *check_outputs(results, ok))
    return 0 if ok else 1


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True, type=Path,
                    help="folder for the run's outputs (series.tsv, run.json, work/)")
    common.code_arguments(ap)
    a = ap.parse_args(argv)
    return run(a.out, common.codes_of(a))


if __name__ == "__main__":
    sys.exit(main())
