"""harness/peer/common.py -- what the cross-checks and the race against LAMMPS share.

The two programs (Codes: the ballast executable and LAMMPS's `lmp`, passed to every
function that runs one), the material both codes get, the inputs written for each (a
ballast scene listing every disc, a LAMMPS data file, a filled-in LAMMPS input), the
outputs read back (ballast's discs.tsv, walls.tsv and contacts.tsv through
harness/final_state.py's Table; LAMMPS's log and dumps), the comparison of one ballast
run with one LAMMPS run (compare(), check_verdict()), the cross-check's initial state
(check_state()), installing or refusing LAMMPS, and a cross-check's run outputs
(series.tsv and run.json, written whole by harness/files.py).

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
alone when nothing touches at t = 0 (the cross-check and the race's
`settling`).  For the race's `dense` (overlapping at t = 0, starting at rest)
both start with v = 0; the difference, dt^2 a_0 / 2 in the first move, does
not matter to a timing.

Only numpy, the standard library and the harness; LAMMPS (Debian package
`lammps`) is installed with apt-get when `lmp` is missing.
"""
import json
import math
import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from .. import REPO_ROOT
from .. import files
from ..final_state import Table
from ..tables import read_run_json

HERE = Path(__file__).resolve().parent
BALLAST = REPO_ROOT / "bin" / "ballast"
DENSE_SCENE = REPO_ROOT / "cases" / "bench" / "dense.scene"
TEMPLATE = HERE / "in.peer"
LMP = "lmp"
# apt-get's command line for LAMMPS (a test gives another to see the skip path).
INSTALL = ("apt-get", "install", "-y", "-qq", "--no-install-recommends", "lammps")

# The material of cases/bench/dense.scene, for discs and box walls alike.
KN = 1e5
KT = 1e5
MU = 0.5
DENSITY = 1.0
G = 9.81

# The cross-check's discs (harness/peer/check.py; rolling.py's packing takes them too):
# CHECK_N discs of dense.scene's fill in CHECK_COLUMNS columns, on its lattice.
CHECK_N = 300
CHECK_COLUMNS = 24
FIGURES = ("max_dx", "max_dv", "max_dF", "max_dT", "max_dfn", "max_dfs")
# max_dx: |x_ballast - x_lammps| / mean diameter; max_dv: |dv| / largest speed;
# max_dF: per-disc force (contacts + walls + gravity) / largest contact f_n;
# max_dT: per-disc torque / (largest contact f_n x mean radius);
# max_dfn, max_dfs: per disc-disc contact f_n, f_s / largest contact f_n.

DISC_COLUMNS = ("x", "y", "r", "vx", "vy", "omega", "m", "fixed")
WALL_COLUMNS = ("name", "ax", "ay", "bx", "by")
CONTACT_COLUMNS = ("a", "b", "kind", "nx", "ny", "fn", "fs", "dn", "ds")


@dataclass(frozen=True)
class Codes:
    """The two programs, handed to every function that runs one: ballast, the executable
    every ballast run uses; lmp, LAMMPS's executable (a name on PATH or a path); install,
    apt-get's command line for LAMMPS when lmp is missing."""
    ballast: Path
    lmp: str = LMP
    install: tuple = INSTALL

    def pinned(self, folder):
        """These codes with ballast copied to folder/ballast and run from there: every run
        of a script uses one binary, even if bin/ballast is rebuilt meanwhile."""
        copy = Path(folder) / "ballast"
        shutil.copy2(self.ballast, copy)
        return replace(self, ballast=copy)


def code_arguments(parser):
    """--ballast and --lmp, the options of every script of harness/peer."""
    parser.add_argument("--ballast", type=Path, default=BALLAST,
                        help="the ballast executable (default: the repository's bin/ballast)")
    parser.add_argument("--lmp", default=LMP, help="LAMMPS's executable (default: lmp on PATH)")


def codes_of(args):
    """The Codes of code_arguments()' options; ends the script when ballast is not built."""
    if not args.ballast.exists():
        sys.exit(f"peer: no {args.ballast}: build the core first (make bin/ballast)")
    return Codes(args.ballast, args.lmp)


# --------------------------------------------------------------------------
# Files: ballast's TSV outputs, LAMMPS logs and dumps
# --------------------------------------------------------------------------

def disc_state(path):
    """ballast's discs.tsv -> the state written to both codes (float arrays by name).

    Velocities are taken as given (for a run of 0 cycles they are the scene's
    v_{1/2}; after a run they are the centred ones, and the race zeroes them)."""
    table = Table(path, DISC_COLUMNS)
    if table.numbers("fixed").any():
        raise ValueError("held discs are not part of the race")
    return {k: table.numbers(k) for k in ("x", "y", "r", "vx", "vy", "omega", "m")}


def box_of_walls(path, rel=1e-12):
    """ballast's walls.tsv -> (xlo, xhi, ylo, yhi) of an axis-aligned box.

    The fill's box has two horizontal and two vertical walls; anything else
    cannot be LAMMPS's xplane/yplane walls and is refused."""
    table = Table(path, WALL_COLUMNS)
    ax, ay, bx, by = (table.numbers(k) for k in ("ax", "ay", "bx", "by"))
    horizontal, vertical = [], []
    for k in range(len(ax)):
        length = math.hypot(bx[k] - ax[k], by[k] - ay[k])
        if abs(by[k] - ay[k]) <= rel * length:
            horizontal.append((ay[k], min(ax[k], bx[k]), max(ax[k], bx[k])))
        elif abs(bx[k] - ax[k]) <= rel * length:
            vertical.append((ax[k], min(ay[k], by[k]), max(ay[k], by[k])))
        else:
            raise ValueError(f"wall {table.text('name')[k]} is neither horizontal nor vertical")
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
    """The figures of a LAMMPS log that the scripts use.

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
    out = [f"# {title}", "# written by harness/peer/common.py: one [disc] per disc, the fill's box",
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
    out = ["LAMMPS data file written by harness/peer/common.py", "", f"{n} atoms", "1 atom types", "",
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
    return re.sub(r"@(\w+)@", sub, template)


# --------------------------------------------------------------------------
# Comparing a ballast run with a LAMMPS run
# --------------------------------------------------------------------------

def ballast_forces(state, contacts, g=G, arm="radius"):
    """Per-disc force (contacts + gravity) and torque at the final step of a
    ballast run, from its contacts.tsv (a path), and the disc-disc contacts
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
    table = Table(contacts, CONTACT_COLUMNS)
    nx, ny, fn, fs, dn, ds = (table.numbers(k) for k in ("nx", "ny", "fn", "fs", "dn", "ds"))
    couple = (table.numbers("mr") + table.numbers("md")) if table.has("mr") else np.zeros(len(fn))
    idx = lambda name: int(name[1:])
    x, y, r = state["x"], state["y"], state["r"]
    a_, b_, kind = table.text("a"), table.text("b"), table.text("kind")
    for k in range(len(fn)):
        a = idx(a_[k])
        ftn, fts = fn[k] + dn[k], fs[k] + ds[k]
        cx = ftn * nx[k] + fts * ny[k]
        cy = ftn * ny[k] - fts * nx[k]
        fx[a] -= cx
        fy[a] -= cy
        if kind[k] != "disc":
            tq[a] += fts * r[a] - couple[k]
            continue
        b = idx(b_[k])
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


def compare(state, run, atoms, local, dt, g=G, arm="radius"):
    """The cross-check figures: a ballast run's final state (its folder `run`: discs.tsv,
    contacts.tsv) against LAMMPS's dumps (atoms: the custom dump, local: pair/local).

    `state` is the initial state (velocities v_{1/2}); `touched` counts the
    discs whose final velocity is not that of free flight in ballast's run
    (those that met another disc or a wall on the way); arm: ballast_forces()."""
    run = Path(run)
    b = disc_state(run / "discs.tsv")
    order = np.argsort(atoms["id"])
    L = {k: v[order] for k, v in atoms.items() if k != "_step"}
    if len(L["id"]) != len(b["x"]) or not np.array_equal(L["id"], np.arange(1, len(b["x"]) + 1)):
        raise ValueError("LAMMPS lost or renumbered atoms")
    mean_d = 2 * float(np.mean(state["r"]))
    mean_r = 0.5 * mean_d
    fx, fy, tq, bp = ballast_forces(b, run / "contacts.tsv", g, arm)
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
    contacts = Table(run / "contacts.tsv", CONTACT_COLUMNS)
    sliding = sum(int(s) for s in contacts.text("sliding")) if contacts.has("sliding") else 0
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


# --------------------------------------------------------------------------
# Running the codes
# --------------------------------------------------------------------------

def install_lammps(install):
    """Run the command line install (apt-get install lammps), after an apt-get update if the
    first try fails (a machine that never ran one has no package lists); '' when it worked,
    else why not."""
    print("peer: installing LAMMPS (apt-get install lammps)", flush=True)
    sudo = [] if os.geteuid() == 0 else ["sudo"]
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    command = sudo + list(install)
    try:
        if subprocess.run(command, env=env).returncode == 0:
            return ""
        subprocess.run(sudo + [install[0], "update", "-qq"], env=env, check=True)
        subprocess.run(command, env=env, check=True)
    except (OSError, subprocess.CalledProcessError) as exc:
        return f"`{' '.join(command)}` failed ({exc})"
    return ""


def lammps_problem(codes, styles=("gran/hooke/history",)):
    """Why LAMMPS cannot run a cross-check ('' when it can), installing it first when
    codes.lmp is missing: not installed and the install failed, or no `lmp -h` listing
    these styles of the GRANULAR package (pair or fix styles)."""
    lmp = codes.lmp
    if shutil.which(lmp) is None:
        failed = install_lammps(codes.install)
        if failed or shutil.which(lmp) is None:
            return (f"LAMMPS is not installed (no `{lmp}` on PATH) and "
                    f"{failed or 'the install left no ' + lmp + ' on PATH'}")
    try:
        help_text = subprocess.run([lmp, "-h"], capture_output=True, text=True).stdout
    except OSError as exc:
        return f"`{lmp} -h` cannot run ({exc})"
    missing = [s for s in styles if not re.search(rf"(?<![\w/]){re.escape(s)}(?![\w/])", help_text)]
    if "GRANULAR" not in help_text or missing:
        return (f"this LAMMPS ({shutil.which(lmp)}) lacks the GRANULAR package's "
                f"{', '.join(missing or styles)}")
    return ""


def skip_outputs(reason):
    """A cross-check that could not run, as a run's outputs (series.tsv, run.json): no
    rows, and status 'skipped' with the reason, which the harness reports as SKIP for
    every check of the case (harness/tables.py)."""
    return "cycle\ttime\n", {"status": "skipped", "message": reason, "steps": 0, "n_discs": 0}


def write_outputs(out, series, info):
    """series.tsv and run.json into out, each written whole (harness/files.py)."""
    files.write_text(Path(out) / "series.tsv", series)
    files.write_text(Path(out) / "run.json", json.dumps(info, indent=1) + "\n")


def run_ballast(codes, args, out):
    """Run codes.ballast with arguments, its outputs into out; return its run.json."""
    env = dict(os.environ, OMP_NUM_THREADS="1")
    res = subprocess.run([str(codes.ballast)] + [str(a) for a in args] + ["--out", str(out)],
                         capture_output=True, text=True, cwd=REPO_ROOT, env=env)
    if res.returncode != 0:
        sys.exit(f"peer: ballast failed ({res.returncode}): {res.stderr.strip()}")
    run = read_run_json(out)
    if run.get("status") != "ok":
        sys.exit(f"peer: ballast run failed: {run.get('message')}")
    return run


def run_lammps(codes, work, input_text):
    """Run LAMMPS serially in `work` on an input; return parse_lammps_log()."""
    work = files.make_dirs(work)
    files.write_text(work / "in.lmp", input_text)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    res = subprocess.run([codes.lmp, "-in", "in.lmp", "-log", "log.lammps", "-screen", "none",
                          "-nocite"], cwd=work, capture_output=True, text=True, env=env)
    log = (work / "log.lammps").read_text() if (work / "log.lammps").exists() else ""
    if res.returncode != 0:
        tail = "\n".join((log or res.stdout + res.stderr).splitlines()[-5:])
        sys.exit(f"peer: LAMMPS failed ({res.returncode}) in {work}:\n{tail}")
    return parse_lammps_log(log)


def check_state(codes, work):
    """The cross-check's initial state: CHECK_N discs of dense.scene's fill on
    its lattice, with its random velocities (ballast's v_{1/2}); refused if
    anything touches (both codes must start without contact forces).
    (state, box, dt)."""
    init = Path(work) / "init"
    run = run_ballast(codes, ["run", DENSE_SCENE, "--set", f"fill.pack.n={CHECK_N}",
                              "--set", f"fill.pack.columns={CHECK_COLUMNS}",
                              "--set", "stage.settle.cycles=0", "--set", "stage.measure.cycles=0"],
                      init)
    state = disc_state(init / "discs.tsv")
    box = box_of_walls(init / "walls.tsv")
    gap, wall_gap = min_gaps(state, box)
    if gap <= 0 or wall_gap <= 0:
        sys.exit(f"peer: the cross-check state overlaps (gap {gap:.3g}, wall gap {wall_gap:.3g}); "
                 "both codes must start without contact forces")
    return state, box, run["dt"]
