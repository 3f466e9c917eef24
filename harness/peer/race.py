#!/usr/bin/python3
"""harness/peer/race.py -- ballast against LAMMPS on the same physics (`make bench-peer`).

    /usr/bin/python3 harness/peer/race.py [--quick]

1. Cross-check.  A small fill of cases/bench/dense.scene (300 discs on the
   lattice, with the scene's random velocities, nothing touching) is written
   out disc by disc as a ballast scene and as a LAMMPS data file.  Both codes
   run the same 400 steps with gravity, three times: frictionless, with
   friction 0.5, and with friction and half the time step.  The final
   positions, velocities, per-disc forces and torques, and every disc-disc
   contact's f_n and f_s are compared (the limits and why: TOL_* below).
   Prints a line per run

       peer check friction=0.5 N=300 steps=400 max_dx=... max_dF=... ... PASS|FAIL

   and stops with exit status 1 on a FAIL: a race between different physics
   would mean nothing.

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
of the last run stay in reports/bench/<host>/peer/.

`--check-only --out DIR` runs the cross-check alone and writes it as a run
(the catalogue's case peer_check); where LAMMPS is absent and cannot be
installed it writes a skipped run instead (lammps_problem, skip_outputs).
The writers, readers and comparisons here also serve harness/peer/rolling.py
(JYH's rolling resistance against LAMMPS's pair granular).

The physics of both sides (the same in both by construction; see
harness/peer/in.peer for LAMMPS):
  discs of unit thickness, m = density pi r^2, I = m r^2 / 2;
  F_n = k_n * overlap (ballast: normal_law = power, nu = 1, delta0 = 1;
  LAMMPS: gran/hooke/history); incremental shear spring k_t with the Coulomb
  cap mu F_n, moments at the full radius; no dashpots and no global damping
  in either code (LAMMPS's dashpots scale with each contact's effective mass,
  ballast's do not, so the only damping both can share is none);
  the four box walls of the fill (ballast segments, LAMMPS wall/gran planes);
  gravity 9.81 downwards; ballast's time step.

Time integration: ballast's cycle N moves x_N = x_{N-1} + dt v_{N-1/2},
computes forces at x_N with v_{N-1/2}, then v_{N+1/2} = v_{N-1/2} + dt a_N.
LAMMPS's velocity Verlet gives the same sequence, its v_{n+1/2} after the
first half kick.  A scene's velocities are ballast's v_{1/2}; LAMMPS's
initial velocities are therefore v_{1/2} - dt a_0 / 2, where a_0 is gravity
alone when nothing touches at t = 0 (the cross-check and `settling`).  For
`dense` (overlapping at t = 0, starting at rest) both start with v = 0; the
difference, dt^2 a_0 / 2 in the first move, does not matter to a timing.

Only numpy and the standard library; LAMMPS (Debian package `lammps`) is
installed with apt-get when `lmp` is missing.
"""
import argparse
import json
import math
import os
import re
import shutil
import socket
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
BALLAST = ROOT / "bin" / "ballast"
BALLAST_RUN = BALLAST   # main() copies bin/ballast into the work folder and runs the copy
DENSE_SCENE = ROOT / "cases" / "bench" / "dense.scene"
TEMPLATE = HERE / "in.peer"
LMP = "lmp"

# The material of cases/bench/dense.scene, for discs and box walls alike.
KN = 1e5
KT = 1e5
MU = 0.5
DENSITY = 1.0
G = 9.81

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

# The cross-check (see docs/benchmarks.md, bench-peer, for the measured
# values).  Three runs of the same 300 discs for CHECK_STEPS steps:
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
CHECK_N = 300
CHECK_COLUMNS = 24
CHECK_STEPS = 400
FIGURES = ("max_dx", "max_dv", "max_dF", "max_dT", "max_dfn", "max_dfs")
# max_dx: |x_ballast - x_lammps| / mean diameter; max_dv: |dv| / largest speed;
# max_dF: per-disc force (contacts + walls + gravity) / largest contact f_n;
# max_dT: per-disc torque / (largest contact f_n x mean radius);
# max_dfn, max_dfs: per disc-disc contact f_n, f_s / largest contact f_n.
TOL_EXACT = dict.fromkeys(FIGURES, 1e-10)
TOL_FRICTION = dict(max_dx=1e-6, max_dv=2e-5, max_dF=1e-5, max_dT=1e-5, max_dfn=1e-5,
                    max_dfs=1e-5)
TOL_RATIO = 0.7


# --------------------------------------------------------------------------
# Files: ballast's TSV outputs, LAMMPS logs and dumps
# --------------------------------------------------------------------------

def read_tsv(text):
    """A TSV with a header line -> {column: list of strings}."""
    lines = [l for l in text.splitlines() if l.strip()]
    head = lines[0].split("\t")
    cols = {h: [] for h in head}
    for line in lines[1:]:
        cells = line.split("\t")
        if len(cells) != len(head):
            raise ValueError(f"TSV row has {len(cells)} cells, header {len(head)}: {line!r}")
        for h, c in zip(head, cells):
            cols[h].append(c)
    return cols


def numeric(cols, *names):
    """The named columns of read_tsv() as float arrays."""
    return [np.array([float(v) for v in cols[n]], dtype=float) for n in names]


def disc_state(discs_tsv):
    """ballast's discs.tsv (text) -> the state race.py writes to both codes.

    Velocities are taken as given (for a run of 0 cycles they are the scene's
    v_{1/2}; after a run they are the centred ones, and race.py zeroes them)."""
    cols = read_tsv(discs_tsv)
    x, y, r, vx, vy, w, m = numeric(cols, "x", "y", "r", "vx", "vy", "omega", "m")
    fixed = np.array([int(v) for v in cols["fixed"]])
    if fixed.any():
        raise ValueError("held discs are not part of the race")
    return {"x": x, "y": y, "r": r, "vx": vx, "vy": vy, "omega": w, "m": m}


def box_of_walls(walls_tsv, rel=1e-12):
    """ballast's walls.tsv (text) -> (xlo, xhi, ylo, yhi) of an axis-aligned box.

    The fill's box has two horizontal and two vertical walls; anything else
    cannot be LAMMPS's xplane/yplane walls and is refused."""
    cols = read_tsv(walls_tsv)
    ax, ay, bx, by = numeric(cols, "ax", "ay", "bx", "by")
    horizontal, vertical = [], []
    for k in range(len(ax)):
        length = math.hypot(bx[k] - ax[k], by[k] - ay[k])
        if abs(by[k] - ay[k]) <= rel * length:
            horizontal.append((ay[k], min(ax[k], bx[k]), max(ax[k], bx[k])))
        elif abs(bx[k] - ax[k]) <= rel * length:
            vertical.append((ax[k], min(ay[k], by[k]), max(ay[k], by[k])))
        else:
            raise ValueError(f"wall {cols['name'][k]} is neither horizontal nor vertical")
    if len(horizontal) != 2 or len(vertical) != 2:
        raise ValueError(f"expected a box of 4 walls, got {len(horizontal)} horizontal "
                         f"and {len(vertical)} vertical")
    ylo, yhi = sorted(h[0] for h in horizontal)
    xlo, xhi = sorted(v[0] for v in vertical)
    # The walls must close the box (ballast's walls are segments, LAMMPS's
    # planes are infinite: the same only if the segments span the box).
    for y0, x0, x1 in horizontal:
        if x0 > xlo + rel * (xhi - xlo) or x1 < xhi - rel * (xhi - xlo):
            raise ValueError("a horizontal wall does not span the box")
    for x0, y0, y1 in vertical:
        if y0 > ylo + rel * (yhi - ylo) or y1 < yhi - rel * (yhi - ylo):
            raise ValueError("a vertical wall does not span the box")
    # walls.tsv prints cos(90 deg) * h, about 1e-15, for a vertical wall's x.
    snap = lambda v: 0.0 if abs(v) < 1e-12 * (xhi - xlo + yhi - ylo) else v
    return tuple(snap(v) for v in (xlo, xhi, ylo, yhi))


def min_gaps(state, box):
    """(smallest disc-disc gap, smallest disc-wall gap); negative = overlap."""
    x, y, r = state["x"], state["y"], state["r"]
    n = len(x)
    gap = math.inf
    block = 512
    for i0 in range(0, n, block):
        i1 = min(n, i0 + block)
        dx = x[i0:i1, None] - x[None, :]
        dy = y[i0:i1, None] - y[None, :]
        g = np.sqrt(dx * dx + dy * dy) - (r[i0:i1, None] + r[None, :])
        for k in range(i0, i1):
            g[k - i0, k] = np.inf
        gap = min(gap, float(g.min()))
    xlo, xhi, ylo, yhi = box
    wall = float(min((x - r - xlo).min(), (xhi - x - r).min(),
                     (y - r - ylo).min(), (yhi - y - r).min()))
    return gap, wall


def parse_lammps_log(text):
    """The figures of a LAMMPS log that race.py uses.

    loop_seconds, procs, steps, atoms from "Loop time of X on P procs for S
    steps with N atoms" (the last one); version from the banner; builds and
    dangerous from the neighbour statistics."""
    out = {}
    m = re.search(r"^LAMMPS \((.*)\)\s*$", text, re.M)
    out["version"] = m.group(1) if m else ""
    loops = re.findall(r"^Loop time of ([-+0-9.eE]+) on (\d+) procs for (\d+) steps "
                       r"with (\d+) atoms", text, re.M)
    if not loops:
        raise ValueError("no 'Loop time' line in the LAMMPS log")
    sec, procs, steps, atoms = loops[-1]
    out.update(loop_seconds=float(sec), procs=int(procs), steps=int(steps), atoms=int(atoms))
    m = re.findall(r"^Neighbor list builds = (\d+)", text, re.M)
    out["builds"] = int(m[-1]) if m else -1
    m = re.findall(r"^Dangerous builds = (\d+)", text, re.M)
    out["dangerous"] = int(m[-1]) if m else -1
    return out


def parse_frames(text):
    """Every frame of a LAMMPS text dump (custom or local), in order: a list of
    {column: float array, "_step": step}."""
    lines = text.splitlines()
    starts = [k for k, l in enumerate(lines) if l.startswith("ITEM: TIMESTEP")]
    frames = []
    for k in starts:
        step = int(lines[k + 1])
        count = int(lines[k + 3])
        head = next(j for j in range(k, len(lines)) if lines[j].startswith("ITEM: ATOMS")
                    or lines[j].startswith("ITEM: ENTRIES"))
        names = lines[head].split()[2:]
        body = lines[head + 1:head + 1 + count]
        if len(body) != count or any(l.startswith("ITEM:") for l in body):
            raise ValueError(f"dump frame of step {step} is cut short: announced {count} rows")
        data = np.array([l.split() for l in body], dtype=float).reshape(count, len(names))
        out = {n: data[:, j] for j, n in enumerate(names)}
        out["_step"] = step
        frames.append(out)
    return frames


def parse_dump(text):
    """The last frame of a LAMMPS text dump (custom or local) -> {column: float array}."""
    frames = parse_frames(text)
    if not frames:
        raise ValueError("no frame in the dump")
    return frames[-1]


# --------------------------------------------------------------------------
# Writing the two codes' inputs
# --------------------------------------------------------------------------

def fmt(v):
    """A float written so that strtod reads back the same double."""
    return repr(float(v))


def ballast_scene(state, box, dt, steps, title, kn=KN, kt=KT, mu=MU, g=G, density=DENSITY,
                  rolling=0.0, wall_rolling=None, rolling_model="model1", output_every=None,
                  probes=(), wall_mu=None, beta=0.0, skin_rule=None):
    """A ballast scene listing every disc, the box walls and one stage.

    wall_mu: the walls' friction when not mu; beta: contact damping (C&S eq. 28,
    c_n = beta k_n, c_s = beta k_s), none by default.  rolling > 0 gives the discs (and, unless
    wall_rolling says otherwise, the walls) JYH's shape parameter delta with
    rolling_model (harness/peer/rolling.py); output_every
    (default: one row at the end) and probes, (name, quantity, a, b) with b None for a
    disc's, add series.tsv rows and columns; skin_rule: ballast's settings.skin_rule
    (default: not written, so the core's default, fixed)."""
    xlo, xhi, ylo, yhi = box
    wall_rolling = rolling if wall_rolling is None else wall_rolling
    wall_mu = mu if wall_mu is None else wall_mu
    every = max(1, int(steps)) if output_every is None else int(output_every)
    out = [f"# {title}", "# written by harness/peer/race.py: one [disc] per disc, the fill's box",
           "# walls, F_n = k_n overlap, no damping (the physics of harness/peer/in.peer)",
           "", "[settings]", f"dt = {fmt(dt)}", f"gravity = 0 {fmt(-g)}",
           "normal_law = power", "nu = 1", "delta0 = 1", f"beta = {fmt(beta) if beta else 0}", "alpha = 0",
           "gamma_n = 0", f"output_every = {every}",
           "# the step and the state are LAMMPS's: a settled packing (discs in contact) and",
           "# the peer's dt, which ballast's contact-network bound may call too large",
           "allow_overlap = 1", "force_dt = 1"]
    if skin_rule:
        out.append(f"skin_rule = {skin_rule}")
    if rolling > 0 or wall_rolling > 0:
        out.append(f"rolling_model = {rolling_model}")
    out += ["", "[material grain]", f"kn = {fmt(kn)}", f"ks = {fmt(kt)}", f"friction = {fmt(mu)}",
            f"density = {fmt(density)}"]
    out += [f"rolling = {fmt(rolling)}"] if rolling > 0 else []
    out += ["", "[material box]", f"kn = {fmt(kn)}", f"ks = {fmt(kt)}", f"friction = {fmt(wall_mu)}"]
    out += [f"rolling = {fmt(wall_rolling)}"] if wall_rolling > 0 else []
    out.append("")
    walls = (("bottom", xlo, ylo, 0, xhi - xlo), ("right", xhi, ylo, 90, yhi - ylo),
             ("top", xlo, yhi, 0, xhi - xlo), ("left", xlo, ylo, 90, yhi - ylo))
    for name, px, py, angle, length in walls:
        out += [f"[wall {name}]", f"p = {fmt(px)} {fmt(py)}", f"angle = {angle}", "h1 = 0",
                f"h2 = {fmt(length)}", "material = box", ""]
    x, y, r = state["x"], state["y"], state["r"]
    vx, vy, w = state["vx"], state["vy"], state["omega"]
    for k in range(len(x)):
        out += [f"[disc d{k}]", f"x = {fmt(x[k])} {fmt(y[k])}", f"r = {fmt(r[k])}",
                f"v = {fmt(vx[k])} {fmt(vy[k])}", f"omega = {fmt(w[k])}", "material = grain", ""]
    out += ["[stage race]", f"cycles = {int(steps)}", ""]
    for name, quantity, a, b in probes:
        out += [f"[probe {name}]", f"quantity = {quantity}", f"a = {a}"] + \
            ([f"b = {b}"] if b is not None else []) + [""]
    return "\n".join(out)


def lammps_data(state, box, dt, g=G, margin=2.0, half_kick=True, density=DENSITY):
    """A LAMMPS data file (atom_style sphere) of the same discs.

    The state's velocities are ballast's v_{1/2}.  With half_kick, LAMMPS gets
    v_y + dt g / 2 (g the magnitude of gravity, pointing down), which its
    first half kick takes back to v_{1/2} when nothing touches at t = 0 (see
    the module docstring).  The simulation box is the wall box plus `margin`
    on every side (LAMMPS's box is not a wall: boundary f f p)."""
    xlo, xhi, ylo, yhi = box
    x, y, r = state["x"], state["y"], state["r"]
    vx, vy, w = state["vx"], state["vy"], state["omega"]
    shift = 0.5 * dt * g if half_kick else 0.0
    n = len(x)
    out = ["LAMMPS data file written by harness/peer/race.py", "", f"{n} atoms", "1 atom types", "",
           f"{fmt(xlo - margin)} {fmt(xhi + margin)} xlo xhi",
           f"{fmt(ylo - margin)} {fmt(yhi + margin)} ylo yhi", "-0.5 0.5 zlo zhi", "",
           "Atoms # sphere", ""]
    out += [f"{k + 1} 1 {fmt(2 * r[k])} {fmt(density)} {fmt(x[k])} {fmt(y[k])} 0"
            for k in range(n)]
    out += ["", "Velocities", ""]
    out += [f"{k + 1} {fmt(vx[k])} {fmt(vy[k] + shift)} 0 0 0 {fmt(w[k])}" for k in range(n)]
    return "\n".join(out) + "\n"


def lammps_input(template, **values):
    """Fill in every @name@ of the template; a name left unfilled is an error."""
    def sub(m):
        key = m.group(1)
        if key not in values:
            raise KeyError(f"no value for @{key}@")
        v = values[key]
        return fmt(v) if isinstance(v, float) else str(v)
    text = re.sub(r"@(\w+)@", sub, template)
    return text


CHECK_OUTPUT = """compute         pairs all pair/local dist force p1 p2 p4
compute         ids all property/local patom1 patom2
dump            atoms all custom @steps@ atoms.dump id radius mass x y vx vy omegaz fx fy tqz
dump_modify     atoms sort id format float %.17g
dump            pairs all local @steps@ pairs.dump c_ids[1] c_ids[2] c_pairs[1] c_pairs[2] c_pairs[3] c_pairs[4] c_pairs[5]
dump_modify     pairs format float %.17g"""


# --------------------------------------------------------------------------
# Comparing the cross-check runs
# --------------------------------------------------------------------------

def ballast_forces(state, contacts_tsv, g=G, arm="radius"):
    """Per-disc force (contacts + gravity) and torque at the final step of a
    ballast run, from contacts.tsv, and the disc-disc contacts
    {(lower id, higher id): (f_n, f_t)} where f_t is the tangential force on
    the lower id along t = (e_y, -e_x), e from the lower id to the higher.

    contacts.tsv: for disc a and body b, e = (nx, ny) from a to b; the force
    on a is -(fn + dn) e - (fs + ds) t_ab, t_ab = (ny, -nx); on b the
    opposite; the moment on both discs is (fs + ds) r.  With rolling
    resistance (columns mr, md), a also gets the couple -(mr + md) and a disc b
    +(mr + md).

    arm: where the tangential force of a disc-disc contact acts -- "radius"
    (ballast, C&S, and LAMMPS's gran/hooke/history: at r from each centre) or
    "contact" (LAMMPS's pair granular: at the middle of the overlap, r - overlap/2;
    wall contacts at r in both).  "contact" gives the torques LAMMPS's
    pair granular would compute from ballast's forces."""
    n = len(state["x"])
    fx = np.zeros(n)
    fy = -state["m"] * g
    tq = np.zeros(n)
    pairs = {}
    cols = read_tsv(contacts_tsv) if contacts_tsv.strip() else None
    if cols is None or not cols.get("a"):
        return fx, fy, tq, pairs
    nx, ny, fn, fs, dn, ds = numeric(cols, "nx", "ny", "fn", "fs", "dn", "ds")
    couple = (numeric(cols, "mr")[0] + numeric(cols, "md")[0]) if "mr" in cols else np.zeros(len(fn))
    idx = lambda name: int(name[1:])
    x, y, r = state["x"], state["y"], state["r"]
    for k in range(len(fn)):
        a = idx(cols["a"][k])
        ftn, fts = fn[k] + dn[k], fs[k] + ds[k]
        cx = ftn * nx[k] + fts * ny[k]
        cy = ftn * ny[k] - fts * nx[k]
        fx[a] -= cx
        fy[a] -= cy
        if cols["kind"][k] != "disc":
            tq[a] += fts * r[a] - couple[k]
            continue
        b = idx(cols["b"][k])
        half = 0.0
        if arm == "contact":
            half = 0.5 * (r[a] + r[b] - math.hypot(x[b] - x[a], y[b] - y[a]))
        tq[a] += fts * (r[a] - half) - couple[k]
        fx[b] += cx
        fy[b] += cy
        tq[b] += fts * (r[b] - half) + couple[k]
        pairs[(min(a, b), max(a, b))] = (fn[k], -fs[k])
    return fx, fy, tq, pairs


def lammps_pairs(local, atoms):
    """LAMMPS's touching pairs from the pair/local dump ->
    {(lower id, higher id): (f_n, f_t)} in the convention of ballast_forces
    (0-based ids).  `atoms` is the custom dump (for the positions)."""
    if not local or "c_ids[1]" not in local:
        return {}
    pos = {int(i): (x, y) for i, x, y in zip(atoms["id"], atoms["x"], atoms["y"])}
    out = {}
    i_, j_ = local["c_ids[1]"], local["c_ids[2]"]
    force, p1, p2 = local["c_pairs[2]"], local["c_pairs[3]"], local["c_pairs[4]"]
    for k in range(len(i_)):
        i, j = int(i_[k]), int(j_[k])
        if force[k] <= 0:
            continue                       # a neighbour, not touching (f_n = k_n overlap > 0)
        lo, hi = min(i, j), max(i, j)
        ex, ey = pos[hi][0] - pos[lo][0], pos[hi][1] - pos[lo][1]
        d = math.hypot(ex, ey)
        ex, ey = ex / d, ey / d
        ft = p1[k] * ey - p2[k] * ex       # tangential force on i along t
        if i != lo:
            ft = -ft
        out[(lo - 1, hi - 1)] = (force[k], ft)
    return out


def compare(state, contacts_tsv, discs_tsv, atoms, local, dt, g=G, arm="radius"):
    """The cross-check figures: ballast's final state against LAMMPS's dump.

    `state` is the initial state (velocities v_{1/2}); `touched` counts the
    discs whose final velocity is not that of free flight in ballast's run
    (those that met another disc or a wall on the way); arm: ballast_forces()."""
    b = disc_state(discs_tsv)
    order = np.argsort(atoms["id"])
    L = {k: v[order] for k, v in atoms.items() if k != "_step"}
    if len(L["id"]) != len(b["x"]) or not np.array_equal(L["id"], np.arange(1, len(b["x"]) + 1)):
        raise ValueError("LAMMPS lost or renumbered atoms")
    mean_d = 2 * float(np.mean(state["r"]))
    mean_r = 0.5 * mean_d
    fx, fy, tq, bp = ballast_forces(b, contacts_tsv, g, arm)
    lp = lammps_pairs(local, atoms)
    fscale = max([v[0] for v in bp.values()] + [1e-300])
    speed = float(np.max(np.hypot(b["vx"], b["vy"])))
    dx = np.hypot(b["x"] - L["x"], b["y"] - L["y"])
    dv = np.hypot(b["vx"] - L["vx"], b["vy"] - L["vy"])
    dF = np.hypot(fx - L["fx"], fy - L["fy"])
    dT = np.abs(tq - L["tqz"])
    common = set(bp) & set(lp)
    only = len(set(bp) ^ set(lp))
    dfn = max([abs(bp[k][0] - lp[k][0]) for k in common] + [0.0])
    dfs = max([abs(bp[k][1] - lp[k][1]) for k in common] + [0.0])
    steps = int(atoms["_step"])
    vy_free = state["vy"] - g * dt * (steps - 0.5)
    free_dv = np.hypot(b["vx"] - state["vx"], b["vy"] - vy_free)
    touched = int(np.count_nonzero((free_dv > 1e-9 * (1 + np.abs(vy_free))) | (b["omega"] != 0)))
    sliding = 0
    if contacts_tsv.strip():
        cols = read_tsv(contacts_tsv)
        sliding = sum(int(s) for s in cols.get("sliding", []))
    return {
        "n": len(b["x"]), "step": int(atoms["_step"]),
        "max_dx": float(dx.max()) / mean_d,
        "max_dv": float(dv.max()) / max(speed, 1e-300),
        "max_dF": float(dF.max()) / fscale,
        "max_dT": float(dT.max()) / (fscale * mean_r),
        "max_dfn": dfn / fscale, "max_dfs": dfs / fscale,
        "contacts_ballast": len(bp), "contacts_lammps": len(lp), "contacts_only_one": only,
        "sliding": sliding, "fscale": fscale,
        "touched": touched,
        "mass_rel": float(np.max(np.abs(b["m"] - L["mass"]) / b["m"])),
    }


def check_verdict(c, tol):
    """PASS when every figure is finite and within its limit, both codes see
    the same disc-disc contacts, there are contacts to compare, and the masses
    agree."""
    values = [c[k] for k in FIGURES]
    return (all(math.isfinite(v) for v in values)
            and all(c[k] <= tol[k] for k in FIGURES)
            and c["contacts_only_one"] == 0 and c["contacts_ballast"] > 0
            and c["mass_rel"] <= 1e-14)


def convergence(full, half):
    """Ratios of the dt/2 run's position and force differences to the full-dt run's."""
    return (half["max_dx"] / max(full["max_dx"], 1e-300),
            half["max_dF"] / max(full["max_dF"], 1e-300))


def check_line(c, verdict, label, extra=""):
    figures = " ".join(f"{k}={c[k]:.3g}" for k in FIGURES)
    return (f"peer check {label} N={c['n']} steps={c['step']} {figures} "
            f"contacts={c['contacts_ballast']}/{c['contacts_lammps']} sliding={c['sliding']} "
            f"touched={c['touched']}{extra} {'PASS' if verdict else 'FAIL'}")


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

    A file whose header is not `header` (written by an older race.py) is
    moved aside to NAME.csv.old first, so that a file's rows match its header."""
    path.parent.mkdir(parents=True, exist_ok=True)
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
# Running the codes
# --------------------------------------------------------------------------

# apt-get's command line for LAMMPS (a test replaces it to see the skip path).
INSTALL = ("apt-get", "install", "-y", "-qq", "--no-install-recommends", "lammps")


def install_lammps():
    """apt-get install lammps (after an apt-get update if the first try fails: a machine
    that never ran one has no package lists); '' when it worked, else why not."""
    print("peer: installing LAMMPS (apt-get install lammps)", flush=True)
    sudo = [] if os.geteuid() == 0 else ["sudo"]
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    install = sudo + list(INSTALL)
    try:
        if subprocess.run(install, env=env).returncode == 0:
            return ""
        subprocess.run(sudo + [INSTALL[0], "update", "-qq"], env=env, check=True)
        subprocess.run(install, env=env, check=True)
    except (OSError, subprocess.CalledProcessError) as exc:
        return f"`{' '.join(install)}` failed ({exc})"
    return ""


def lammps_problem(styles=("gran/hooke/history",)):
    """Why LAMMPS cannot run a cross-check ('' when it can), installing it first when `lmp`
    is missing: not installed and the install failed, or no `lmp -h` listing these
    styles of the GRANULAR package (pair or fix styles)."""
    if shutil.which(LMP) is None:
        failed = install_lammps()
        if failed or shutil.which(LMP) is None:
            return (f"LAMMPS is not installed (no `{LMP}` on PATH) and "
                    f"{failed or 'the install left no ' + LMP + ' on PATH'}")
    try:
        help_text = subprocess.run([LMP, "-h"], capture_output=True, text=True).stdout
    except OSError as exc:
        return f"`{LMP} -h` cannot run ({exc})"
    missing = [s for s in styles if not re.search(rf"(?<![\w/]){re.escape(s)}(?![\w/])", help_text)]
    if "GRANULAR" not in help_text or missing:
        return (f"this LAMMPS ({shutil.which(LMP)}) lacks the GRANULAR package's "
                f"{', '.join(missing or styles)}")
    return ""


def ensure_lammps():
    """The race's lammps_problem(): a problem ends the script (exit status 1)."""
    problem = lammps_problem()
    if problem:
        sys.exit(f"peer: {problem}")


def skip_outputs(reason):
    """A cross-check that could not run, as a run's outputs (series.tsv, run.json): no
    rows, and status 'skipped' with the reason, which the harness reports as SKIP for
    every check of the case (harness/tables.py)."""
    return "cycle\ttime\n", {"status": "skipped", "message": reason, "steps": 0, "n_discs": 0}


def write_outputs(out, series, info):
    """series.tsv and run.json into out, each written whole (a .tmp, then a rename)."""
    out = Path(out)
    for name, text in (("series.tsv", series), ("run.json", json.dumps(info, indent=1) + "\n")):
        tmp = out / (name + ".tmp")
        tmp.write_text(text)
        tmp.rename(out / name)


def run_ballast(args, out):
    """Run ballast (the copy main() made of bin/ballast) with arguments; return run.json."""
    env = dict(os.environ, OMP_NUM_THREADS="1")
    res = subprocess.run([str(BALLAST_RUN)] + [str(a) for a in args] + ["--out", str(out)],
                         capture_output=True, text=True, cwd=ROOT, env=env)
    if res.returncode != 0:
        sys.exit(f"peer: ballast failed ({res.returncode}): {res.stderr.strip()}")
    run = json.loads((Path(out) / "run.json").read_text())
    if run.get("status") != "ok":
        sys.exit(f"peer: ballast run failed: {run.get('message')}")
    return run


def run_lammps(work, input_text):
    """Run LAMMPS serially in `work` on an input; return parse_lammps_log()."""
    work = Path(work)
    work.mkdir(parents=True, exist_ok=True)
    (work / "in.lmp").write_text(input_text)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    res = subprocess.run([LMP, "-in", "in.lmp", "-log", "log.lammps", "-screen", "none",
                          "-nocite"], cwd=work, capture_output=True, text=True, env=env)
    log = (work / "log.lammps").read_text() if (work / "log.lammps").exists() else ""
    if res.returncode != 0:
        tail = "\n".join((log or res.stdout + res.stderr).splitlines()[-5:])
        sys.exit(f"peer: LAMMPS failed ({res.returncode}) in {work}:\n{tail}")
    return parse_lammps_log(log)


class Race:
    """One scene of the race: its files and the runs of both codes."""

    def __init__(self, name, work, state, box, dt, steps, template):
        self.name, self.work, self.state, self.box = name, Path(work), state, box
        self.dt, self.steps, self.template = dt, steps, template
        self.n = len(state["x"])
        self.work.mkdir(parents=True, exist_ok=True)
        self.data = self.work / "data.lmp"
        self.data.write_text(lammps_data(state, box, dt, half_kick=name != "dense"))
        self.scenes = {}

    def scene(self, steps):
        if steps not in self.scenes:
            path = self.work / f"{self.name}_{steps}.scene"
            # ballast's own choice of skin (skin_rule = motion, docs/physics.md) against
            # the best of LAMMPS's swept settings
            path.write_text(ballast_scene(self.state, self.box, self.dt, steps,
                                          f"peer race '{self.name}', {self.n} discs",
                                          skin_rule=RACE_SKIN_RULE))
            self.scenes[steps] = path
        return self.scenes[steps]

    def ballast(self, steps):
        run = run_ballast(["run", self.scene(steps)], self.work / "ballast_out")
        return self.n * run["steps"] / run["wall_seconds"], run

    def lammps(self, steps, s):
        text = lammps_input(self.template, data=str(self.data), density=DENSITY, kn=KN, kt=KT,
                            mu=MU, g=G, dt=self.dt, steps=steps, output="", skin=s["skin"],
                            binsize=s["binsize"], sort_every=s["sort_every"], sort_binsize=0,
                            xlo=self.box[0], xhi=self.box[1], ylo=self.box[2], yhi=self.box[3])
        log = run_lammps(self.work / "lammps", text)
        if log["procs"] != 1 or log["atoms"] != self.n or log["steps"] != steps:
            sys.exit(f"peer: LAMMPS ran {log['steps']} steps of {log['atoms']} atoms on "
                     f"{log['procs']} procs")
        return self.n * steps / log["loop_seconds"], log


# --------------------------------------------------------------------------
# The three parts
# --------------------------------------------------------------------------

def check_state(work):
    """The cross-check's initial state: CHECK_N discs of dense.scene's fill on
    its lattice, with its random velocities (ballast's v_{1/2}); refused if
    anything touches (both codes must start without contact forces)."""
    init = run_ballast(["run", DENSE_SCENE, "--set", f"fill.pack.n={CHECK_N}",
                        "--set", f"fill.pack.columns={CHECK_COLUMNS}",
                        "--set", "stage.settle.cycles=0", "--set", "stage.measure.cycles=0"],
                       work / "init")
    state = disc_state((work / "init" / "discs.tsv").read_text())
    box = box_of_walls((work / "init" / "walls.tsv").read_text())
    gap, wall_gap = min_gaps(state, box)
    if gap <= 0 or wall_gap <= 0:
        sys.exit(f"peer: the cross-check state overlaps (gap {gap:.3g}, wall gap {wall_gap:.3g}); "
                 "both codes must start without contact forces")
    return state, box, init["dt"]


def cross_run(work, template, state, box, dt, steps, friction, label):
    """Both codes on the same discs for `steps` steps; compare()'s figures."""
    scene = work / f"{label}.scene"
    scene.write_text(ballast_scene(state, box, dt, steps,
                                   f"peer cross-check {label}, {len(state['x'])} discs", mu=friction))
    run_ballast(["run", scene], work / f"{label}_ballast")
    lw = work / f"{label}_lammps"
    lw.mkdir(parents=True, exist_ok=True)
    (lw / "data.lmp").write_text(lammps_data(state, box, dt))
    text = lammps_input(template, data="data.lmp", density=DENSITY, kn=KN, kt=KT, mu=friction, g=G,
                        dt=dt, steps=steps, output=CHECK_OUTPUT.replace("@steps@", str(steps)),
                        skin=0.25, binsize=0, sort_every=1000, sort_binsize=0,
                        xlo=box[0], xhi=box[1], ylo=box[2], yhi=box[3])
    run_lammps(lw, text)
    atoms = parse_dump((lw / "atoms.dump").read_text())
    if atoms["_step"] != steps:
        sys.exit(f"peer: the LAMMPS dump is of step {atoms['_step']}, not {steps}")
    local = parse_dump((lw / "pairs.dump").read_text())
    return compare(state, (work / f"{label}_ballast" / "contacts.tsv").read_text(),
                   (work / f"{label}_ballast" / "discs.tsv").read_text(), atoms, local, dt)


def cross_check(work, template, steps=CHECK_STEPS):
    """The three runs of the cross-check; prints a line each.  Returns
    (all passed, the friction run's figures)."""
    work = Path(work)
    work.mkdir(parents=True, exist_ok=True)
    state, box, dt = check_state(work)
    exact = cross_run(work, template, state, box, dt, steps, 0.0, "frictionless")
    ok0 = check_verdict(exact, TOL_EXACT)
    print(check_line(exact, ok0, "friction=0"), flush=True)
    full = cross_run(work, template, state, box, dt, steps, MU, "friction")
    ok1 = check_verdict(full, TOL_FRICTION)
    print(check_line(full, ok1, f"friction={MU:g}"), flush=True)
    half = cross_run(work, template, state, box, 0.5 * dt, 2 * steps, MU, "friction_half_dt")
    rx, rf = convergence(full, half)
    ok2 = check_verdict(half, TOL_FRICTION) and rx <= TOL_RATIO and rf <= TOL_RATIO
    print(check_line(half, ok2, f"friction={MU:g},dt/2",
                     f" ratio_dx={rx:.3g} ratio_dF={rf:.3g}"), flush=True)
    cross_check.results = {"friction0": exact, "friction": full, "half_dt": half,
                           "ratio_dx": rx, "ratio_dF": rf}
    if not (ok0 and ok1 and ok2):
        print(f"peer: FAIL: limits: friction=0 {TOL_EXACT['max_dx']:g} for every figure; "
              f"friction: {', '.join(f'{k} {v:g}' for k, v in TOL_FRICTION.items())}; "
              f"dt/2 ratios <= {TOL_RATIO}; the same contacts in both codes", file=sys.stderr)
    return ok0 and ok1 and ok2, full


def settle_dense(work, n, columns):
    """Run dense.scene to rest (E_k <= 1e-3 E_el) with the race's normal law
    and without friction; the settled state (velocities zeroed: the race
    starts at rest), its box and its dt.

    Without friction, because neither code can hand its contacts' shear
    history to the other: both start the race with none.  A packing settled
    with friction and then stripped of its shear forces slips and rings
    (without damping, ballast rebuilt its lists 23 times in 3000 steps, and
    LAMMPS more); one settled frictionless is in equilibrium with normal
    forces alone and stays at rest when the race turns friction on."""
    out = work / "settled"
    run = run_ballast(["run", DENSE_SCENE, "--set", f"fill.pack.n={n}",
                       "--set", f"fill.pack.columns={columns}",
                       "--set", "material.grain.friction=0", "--set", "material.box.friction=0",
                       "--set", "settings.normal_law=power", "--set", "settings.output_every=1000",
                       "--set", "stage.settle.cycles=40000", "--set", "stage.settle.stop_ke=1e-3",
                       "--set", "stage.settle.check_every=1000",
                       "--set", "stage.measure.cycles=0"], out)
    state = disc_state((out / "discs.tsv").read_text())
    for k in ("vx", "vy", "omega"):
        state[k] = np.zeros_like(state[k])
    stage = run["stages"][0]
    return state, box_of_walls((out / "walls.tsv").read_text()), run["dt"], stage


def initial_lattice(work, n, columns):
    out = work / "lattice"
    run = run_ballast(["run", DENSE_SCENE, "--set", f"fill.pack.n={n}",
                       "--set", f"fill.pack.columns={columns}",
                       "--set", "stage.settle.cycles=0", "--set", "stage.measure.cycles=0"], out)
    state = disc_state((out / "discs.tsv").read_text())
    return state, box_of_walls((out / "walls.tsv").read_text()), run["dt"]


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


def check_only(out, template):
    """`--check-only --out DIR`: the cross-check alone, written like a run; a skipped
    run when LAMMPS cannot run it (lammps_problem())."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    problem = lammps_problem()
    if problem:
        print(f"peer: skipped: {problem}", flush=True)
        write_outputs(out, *skip_outputs(problem))
        return 0
    global BALLAST_RUN
    BALLAST_RUN = out / "ballast"
    shutil.copy2(BALLAST, BALLAST_RUN)
    ok, _ = cross_check(out / "work", template)
    write_outputs(out, *check_outputs(cross_check.results, ok))
    return 0 if ok else 1


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true",
                    help="small N, 2 repeats of short runs: a test of the machinery, not a benchmark")
    ap.add_argument("--check-only", action="store_true",
                    help="only the cross-check, written as a run into --out (the peer_check case)")
    ap.add_argument("--out", help="folder for --check-only")
    a = ap.parse_args(argv)
    if a.check_only:
        if not a.out:
            sys.exit("peer: --check-only needs --out DIR")
        if not BALLAST.exists():
            sys.exit("peer: build the core first (make bin/ballast)")
        return check_only(a.out, TEMPLATE.read_text())
    if not BALLAST.exists():
        sys.exit("peer: build the core first (make bin/ballast)")
    ensure_lammps()
    template = TEMPLATE.read_text()
    host = socket.gethostname() or "unknown"
    host_dir = ROOT / "reports" / "bench" / host
    work = host_dir / "peer"
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    stamp = int(time.time())
    # Every run uses one binary, even if bin/ballast is rebuilt meanwhile.
    global BALLAST_RUN
    BALLAST_RUN = work / "ballast"
    shutil.copy2(BALLAST, BALLAST_RUN)

    # 1. Cross-check: refuse to race different physics.
    ok, c = cross_check(work / "check", template)
    if not ok:
        return 1

    # 2. The race.
    n = 2000 if a.quick else RACE_N
    columns = int(round(math.sqrt(2 * n)))
    repeats = 2 if a.quick else REPEATS
    steps = {"dense": 200 if a.quick else RACE_STEPS, "settling": 200 if a.quick else RACE_STEPS}

    state, box, dt, stage = settle_dense(work, n, columns)
    print(f"# dense: N={n} settled frictionless for {stage['cycles']} cycles with "
          f"normal_law = power: "
          f"E_k/E_el = {stage['ke_over_ee']:.2g}; dt = {dt:.6g}", flush=True)
    lattice, lbox, ldt = initial_lattice(work, n, columns)
    races = [Race("dense", work / "dense", state, box, dt, steps["dense"], template),
             Race("settling", work / "settling", lattice, lbox, ldt, steps["settling"], template)]
    version = parse_lammps_log((work / "check" / "friction_lammps" / "log.lammps").read_text())["version"]
    for race in races:
        best, _ = sweep(race, race.steps, a.quick, host_dir, stamp)
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
                    int(a.quick)])
    return 0


if __name__ == "__main__":
    sys.exit(main())
