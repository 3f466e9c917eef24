"""harness/peer/common.py -- what the cross-checks and the race against LAMMPS share.

The two programs (Codes: the ballast executable and LAMMPS's `lmp`, passed to every
function that runs one), the material both codes get, the input written for both (a
ballast scene listing every disc: ballast runs it, and harness/engines/lammps.py, the
harness's one translation of a scene into LAMMPS, writes LAMMPS's data file and input from
it: run_lammps()), the outputs read back (ballast's discs.tsv, walls.tsv and contacts.tsv
through harness/final_state.py's Table; LAMMPS's log and dumps), the comparison of one
ballast run with one LAMMPS run (compare(), check_verdict()), the cross-check's initial
state (check_state()), installing or refusing LAMMPS (engines/lammps.py), and a
cross-check's run outputs (series.tsv and run.json, written whole by harness/files.py).

The physics of both sides (the same in both by construction; docs/engines.md derives the
translation):
  discs of unit thickness, m = density pi r^2, I = m r^2 / 2;
  F_n = k_n * overlap (ballast: normal_law = power, nu = 1, delta0 = 1;
  LAMMPS: gran/hooke/history); incremental shear spring k_t with the Coulomb
  cap mu F_n, moments at the full radius; no dashpots and no global damping
  (gran/hooke's dashpots scale with each contact's effective mass, ballast's do
  not: a damped scene goes to pair granular's `damping velocity`, whose arm for
  F_s is r - delta/2, so the undamped cross-check keeps gran/hooke/history);
  the four box walls of the fill (ballast segments, LAMMPS region planes);
  gravity 9.81 downwards; ballast's time step.

Time integration: ballast's cycle N moves x_N = x_{N-1} + dt v_{N-1/2},
computes forces at x_N with v_{N-1/2}, then v_{N+1/2} = v_{N-1/2} + dt a_N.
LAMMPS's velocity Verlet gives the same sequence, its v_{n+1/2} after the
first half kick.  A scene's velocities are ballast's v_{1/2}; LAMMPS's
initial velocities are therefore v_0 with v_0 + dt a_0(v_0) / 2 = v_{1/2}, a_0
LAMMPS's own forces at t = 0 (the translation solves it: engines/lammps.py,
start_lines), for the race's settled `dense` (overlapping at t = 0) as for the
cross-check's free discs.

Only numpy, the standard library and the harness; LAMMPS (Debian package
`lammps`) is installed with apt-get when `lmp` is missing (engines/lammps.py).
"""
import json
import math
import os
import shutil
import subprocess
import sys
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from .. import REPO_ROOT
from .. import files
from ..engines import lammps as translation
from ..engines.lammps import INSTALL, LMP, install_lammps, parse_dump, parse_frames  # noqa: F401
from ..engines.lammps import parse_log as parse_lammps_log  # noqa: F401
from ..final_state import Table
from ..tables import read_run_json

HERE = Path(__file__).resolve().parent
BALLAST = REPO_ROOT / "bin" / "ballast"
DENSE_SCENE = REPO_ROOT / "cases" / "bench" / "dense.scene"

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

def lammps_problem(codes, styles=("gran/hooke/history",)):
    """Why LAMMPS cannot run a cross-check ('' when it can), installing it first when
    codes.lmp is missing (engines/lammps.py, lammps_problem)."""
    return translation.lammps_problem(codes.lmp, codes.install, styles)


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


def run_lammps(codes, work, scene, extra="", **options):
    """Run a ballast scene file in LAMMPS serially in `work` through the harness's one
    translation (engines/lammps.py, run_scene), with extra, the caller's own LAMMPS lines
    (computes, dumps) before the runs, and options for its neighbour settings (skin, binsize,
    sort_every); return its log's figures (parse_lammps_log)."""
    work = files.make_dirs(work)
    try:
        return translation.run_scene(codes.lmp, codes.ballast, scene, work, extra.splitlines(), **options)
    except RuntimeError as exc:
        sys.exit(f"peer: {exc}")


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
