"""harness/engines/lammps_input.py -- a resolved ballast scene as LAMMPS's data file and input:
the harness's one translation (docs/engines.md derives each line; lammps.py decides, per
scene, what is expressible and with which options).

data_text() writes every disc (type, diameter, density, position, the scene's v_1/2); translate()
the input: atom style and types, pair style and coefficients (pair_law: ballast's
2 k_a k_b/(k_a + k_b)), the integrator, gravity with its ramp, C&S's global damping, the walls
as moving region planes, the holds, the start from v_1/2 (start_lines), and the stages' runs
with the dumps the reader takes back (stage_lines) and a stop rule's checks.

Kept whole (780 lines): it is one translation, written in the order of the input file it emits,
and its parts share the scene's resolved walls, types and frames (the carriers of controlled
walls, the wall's frame of a turning floor); split, each part would need the others' naming of
atoms, groups and variables, which is the translation itself.
"""
import math

import numpy as np

from .. import REPO_ROOT
from . import scene as scenes

# LAMMPS's fix langevin takes a rotational drag of SINERTIA m r^2 / damp (a sphere's 0.4); a
# disc's I is m r^2 / 2, so the drag -alpha I omega needs 1/damp = (0.5/0.4) alpha / s.
LANGEVIN_SINERTIA = 0.4
# Passes of start_lines()'s fixed-point iteration for v_0: each divides the error by at least
# 1/(dt/2 |da/dv|) >= 2 at a stable step (dt/2 eta/m <= zeta dt omega/2 < 1/2 for the catalogue's
# damping ratios zeta <= 0.5), so 60 passes leave 2^-60 of the first correction, below round-off.
START_PASSES = 60
SEED = 1                   # fix langevin's seed: at T = 0 its random force is 0 x random


def fmt(v):
    """A float written so that strtod reads back the same double."""
    return repr(float(v))


def wall_side(scene, wall):
    """+1 or -1: the side of the wall's line (left of A->B is +1) where the discs lie; 0 when
    discs lie on both sides within reach of the segment."""
    ex, ey = wall.bx - wall.ax, wall.by - wall.ay
    length = math.hypot(ex, ey)
    ex, ey = ex / length, ey / length
    d = scene.discs
    signed = (d["x"] - wall.ax) * (-ey) + (d["y"] - wall.ay) * ex
    along = (d["x"] - wall.ax) * ex + (d["y"] - wall.ay) * ey
    near = (along > -d["r"]) & (along < length + d["r"])
    pos, neg = np.any(near & (signed > 0)), np.any(near & (signed < 0))
    if pos and neg:
        return 0
    return 1 if pos or not neg else -1


def pair_law(scene, ma, mb):
    A, B = scene.materials[ma], scene.materials[mb]
    return (2 * A.kn * B.kn / (A.kn + B.kn), 2 * A.ks * B.ks / (A.ks + B.ks),
            min(A.friction, B.friction), min(A.rolling, B.rolling))


def granular_coeff(scene, kn, ks, mu, delta, r_eff=None):
    """A pair granular coefficient string (pair_coeff or fix wall/gran granular) of one pair
    law: hooke or hertz (r_eff given), damping velocity, linear_history, rolling sds."""
    beta, gamma_n = scene.number("beta"), scene.number("gamma_n")
    eta_n = gamma_n + beta * kn
    xgamma = beta * ks / eta_n if eta_n > 0 else 0.0
    if r_eff is None:
        normal = f"hooke {fmt(kn)} {fmt(eta_n)}"
    else:
        normal = f"hertz {fmt(kn / math.sqrt(scene.number('delta0') * r_eff))} {fmt(eta_n)}"
    out = f"{normal} tangential linear_history {fmt(ks)} {fmt(xgamma)} {fmt(mu)}"
    if delta > 0:
        roll = rolling_sds(delta, kn, eta_n)
        out += f" rolling sds {fmt(roll['k_roll'])} {fmt(roll['gamma_roll'])} {fmt(roll['mu_roll'])}"
    return out + " damping velocity"


def rolling_sds(delta, kn, mu_n=0.0):
    """LAMMPS's `rolling sds k_roll gamma_roll mu_roll` of JYH's Model 1 with shape parameter
    delta, normal stiffness kn and normal dashpot mu_n (docs/engines.md): JYH's common radius is
    2 R_eff at every contact, B = 2 delta R_eff, so K_m = k_n B^2/12 = (k_n delta^2/3) R_eff^2,
    M_0 = F_n B/6 = (delta/3) R_eff F_n and mu_m = mu_n B^2/12 = (mu_n delta^2/3) R_eff^2: the
    same three numbers for every pair of radii and for flat walls."""
    d2 = delta * delta
    return {"k_roll": kn * d2 / 3, "gamma_roll": mu_n * d2 / 3, "mu_roll": delta / 3}


def data_text(scene, opts):
    """The LAMMPS data file (atom_style sphere): every disc with its type, diameter, density
    (the material's, times s when global damping acts: data_text's masses are LAMMPS's) and
    position, and the scene's velocities (ballast's v_1/2; translate() takes them to v_0).
    The box holds the discs and walls with a margin; its boundaries shrink-wrap (m m p)."""
    d = scene.discs
    x, y, r = d["x"], d["y"], d["r"]
    xs = list(x - r) + list(x + r) + [c for w in scene.walls for c in (w.ax, w.bx)]
    ys = list(y - r) + list(y + r) + [c for w in scene.walls for c in (w.ay, w.by)]
    margin = float(r.max())
    n = len(x)
    carriers = controlled_walls(scene)
    out = [f"LAMMPS data file written by harness/engines/lammps.py from {scene.path}", "",
           f"{n + len(carriers)} atoms", f"{len(opts.types) + (1 if carriers else 0)} atom types", "",
           f"{fmt(min(xs) - margin)} {fmt(max(xs) + margin)} xlo xhi",
           f"{fmt(min(ys) - margin)} {fmt(max(ys) + margin)} ylo yhi", "-0.5 0.5 zlo zhi", "",
           "Atoms # sphere", ""]
    for k in range(n):
        rho = scene.materials[scene.disc_material[k]].density * opts.scale
        out.append(f"{k + 1} {opts.type_of[k]} {fmt(2 * r[k])} {fmt(rho)} {fmt(x[k])} {fmt(y[k])} 0")
    # a carrier atom per controlled wall, at the wall's midpoint (carrier_lines())
    rho = scene.materials[opts.types[0][0]].density
    for j, k in enumerate(carriers):
        mx, my = midpoint(scene.walls[k])
        out.append(f"{n + j + 1} {len(opts.types) + 1} {fmt(2 * float(r.min()))} {fmt(rho)} {fmt(mx)} {fmt(my)} 0")
    out += ["", "Velocities", ""]
    out += [f"{k + 1} {fmt(d['vx'][k])} {fmt(d['vy'][k])} 0 0 0 {fmt(d['omega'][k])}" for k in range(n)]
    out += [f"{n + j + 1} 0.0 0.0 0 0 0 0.0" for j in range(len(carriers))]
    return "\n".join(out) + "\n"


def _ids(indices):
    return " ".join(str(i + 1) for i in indices)


def translate(scene, opts, work=None, extra=()):
    """The LAMMPS input of a resolved scene (its data file: data_text()): the one translation.
    With opts.dumps, the run's dumps (atoms.dump, pairs.dump) at ballast's series rows, and a
    stop rule's checks through harness/engines (work: where the context pickle is); extra:
    lines of the caller's own (computes, dumps: harness/peer) before the stages' runs."""
    d = scene.discs
    n = len(d["x"])
    held = scenes.held(scene)
    fixed = [k for k in range(n) if held[k] == {"x", "y", "rotation"}]
    dt = scene.dt
    L = [f"# written by harness/engines/lammps.py from {scene.path}",
         f"# --set {' '.join(scene.sets)}" if scene.sets else "# (no --set lines)",
         "units           lj", "dimension       2", "atom_style      sphere",
         f"atom_modify     map array sort {opts.sort_every} {fmt(opts.sort_binsize)}",
         "boundary        m m p", "comm_modify     vel yes", "read_data       data.lmp"]
    for t, (mat, _) in enumerate(opts.types):
        L.append(f"set             type {t + 1} density/disc "
                 f"{fmt(scene.materials[mat].density * opts.scale)}")
    carriers = controlled_walls(scene)
    L.append("group           held id " + _ids(fixed) if fixed else "group           held empty")
    if carriers:
        L.append(f"group           carriers type {len(opts.types) + 1}")
        L.append("group           free subtract all held carriers")
    else:
        L.append("group           free subtract all held")
    for t, (mat, _) in enumerate(opts.types):
        L.append(f"group           t{t + 1} type {t + 1}")
    style = "nsq" if opts.nsq else "bin"
    L.append(f"neighbor        {fmt(opts.skin)} {style}")
    L.append("neigh_modify    delay 0 every 1 check yes"
             + (f" binsize {fmt(opts.binsize)}" if opts.binsize and not opts.nsq else "")
             + (" exclude group held held" if fixed else "")
             + (" exclude group carriers all" if carriers else ""))
    L += pair_lines(scene, opts)
    L.append(f"timestep        {fmt(dt)}")
    # the carriers move first in a step, from the state of the step before (carrier_lines())
    L += carrier_fix(scene)
    L.append("fix             integrate free nve/sphere disc")
    L += gravity_lines(scene, opts)
    if opts.alpha > 0:
        damp = opts.scale / (opts.alpha * 0.5 / LANGEVIN_SINERTIA)
        excess = opts.alpha * (0.5 / LANGEVIN_SINERTIA - 1)          # langevin's -1.25 alpha m v, less alpha
        L += [f"fix             drag free langevin 0.0 0.0 {fmt(damp)} {SEED} omega yes",
              f"variable        trimx atom {fmt(excess)}*mass/{fmt(opts.scale)}*vx",
              f"variable        trimy atom {fmt(excess)}*mass/{fmt(opts.scale)}*vy",
              "fix             trim free addforce v_trimx v_trimy 0.0"]
    L += wall_lines(scene, opts)
    L += carrier_lines(scene, opts)
    L += frame_lines(scene, opts)
    for axis in ("x", "y"):
        part = [k for k in range(n) if axis in held[k] and held[k] != {"x", "y", "rotation"}]
        if part:
            L += [f"group           hold{axis} id {_ids(part)}",
                  f"fix             hold{axis} hold{axis} setforce "
                  + ("0.0 NULL NULL" if axis == "x" else "NULL 0.0 NULL")]
    L.append("fix             plane all enforce2d")
    L += start_lines(scene, opts)
    L += list(extra)
    L += stage_lines(scene, opts, work)
    return "\n".join(L) + "\n"


def pair_lines(scene, opts):
    if not opts.granular:
        # one law for every pair: gran/hooke/history's coefficients are global
        laws = {pair_law(scene, a, b) for a, _ in opts.types for b, _ in opts.types}
        if len(laws) == 1:
            kn, ks, mu, _ = laws.pop()
            return [f"pair_style      gran/hooke/history {fmt(kn)} {fmt(ks)} 0.0 0.0 {fmt(mu)} 0",
                    "pair_coeff      * *"]
    out = ["pair_style      granular"]
    for i, (ma, ra) in enumerate(opts.types):
        for j, (mb, rb) in enumerate(opts.types):
            if j < i:
                continue
            kn, ks, mu, delta = pair_law(scene, ma, mb)
            r_eff = ra * rb / (ra + rb) if opts.hertz else None
            out.append(f"pair_coeff      {i + 1} {j + 1} {granular_coeff(scene, kn, ks, mu, delta, r_eff)}")
    if controlled_walls(scene):
        # the carriers' pairs are excluded from the neighbour lists; pair granular still wants a
        # coefficient set for their type
        kn, ks, mu, delta = pair_law(scene, opts.types[0][0], opts.types[0][0])
        law = granular_coeff(scene, kn, ks, mu, delta, None)
        carrier = len(opts.types) + 1
        out += [f"pair_coeff      {t} {carrier} {law}" for t in range(1, carrier + 1)]
    return out


def gfac_expr(scene, starts):
    """gfac(step) as an equal-style formula: (step - N0)/C in each ramp stage, 1 elsewhere."""
    terms, covered = [], []
    for stage, n0 in zip(scene.stages, starts):
        if stage.number("ramp") and stage.cycles > 0:
            c = stage.cycles
            inside = f"(step>{n0})*(step<={n0 + c})"
            terms.append(f"{inside}*(step-{n0})/{c}")
            covered.append(inside)
    if not terms:
        return "1"
    return "+".join(terms) + "+(1-(" + "+".join(covered) + "))"


def stage_starts(scene):
    out, n = [], 0
    for s in scene.stages:
        out.append(n)
        n += s.cycles
    return out


def gravity_lines(scene, opts):
    gx, gy = scene.gravity()
    size = math.hypot(gx, gy)
    if size == 0:
        return []
    ramps = any(s.number("ramp") for s in scene.stages)
    has_stop = any(_stop_rule(s) for s in scene.stages)
    if ramps and has_stop:
        # a ramp after a stop rule would start at a step known only at run time
        first_stop = next(k for k, s in enumerate(scene.stages) if _stop_rule(s))
        if any(s.number("ramp") for s in scene.stages[first_stop + 1:]):
            raise scenes.SceneError("a gravity ramp after a stage with a stop rule")
    g = fmt(size / opts.scale)
    return [f"variable        gfac equal \"{gfac_expr(scene, stage_starts(scene))}\"",
            f"variable        gmag equal \"{g}*v_gfac\"",
            f"fix             gravity free gravity v_gmag vector {fmt(gx / size)} {fmt(gy / size)} 0.0"]


def wall_lines(scene, opts):
    """A region plane and fix wall/gran/region per wall and disc material; moving walls get
    displacement and angle variables Wk_dx, Wk_dy, Wk_th that stage_lines() redefines per stage."""
    out = []
    mats = []
    for mat, _ in opts.types:
        if mat not in mats:
            mats.append(mat)
    moves = moving_walls(scene, opts)
    carriers = controlled_walls(scene)
    for k, w in enumerate(scene.walls):
        side = wall_side(scene, w)
        (qx, qy), (ex, ey) = wall_line(scene, w)
        nx, ny = -ey * side, ex * side
        motion = ""
        if k in carriers:
            # where its carrier atom has gone since the start (carrier_lines())
            j = carriers.index(k)
            mx, my = midpoint(w)
            out += [f"variable        W{k}_dx equal x[{len(scene.discs['x']) + j + 1}]-{fmt(mx)}",
                    f"variable        W{k}_dy equal y[{len(scene.discs['x']) + j + 1}]-{fmt(my)}"]
            motion = f" move v_W{k}_dx v_W{k}_dy NULL"
        elif w.name in moves:
            out += [f"variable        W{k}_dx equal 0.0", f"variable        W{k}_dy equal 0.0",
                    f"variable        W{k}_th equal 0.0"]
            px, py = pivot(scene, w)
            motion = f" move v_W{k}_dx v_W{k}_dy NULL"
            if w.name in turning_walls(scene):
                motion += f" rotate v_W{k}_th {fmt(px)} {fmt(py)} 0.0 0.0 0.0 1.0"
        out.append(f"region          W{k} plane {fmt(qx)} {fmt(qy)} 0.0 {fmt(nx)} {fmt(ny)} 0.0 "
                   f"side in units box{motion}")
        for m, mat in enumerate(mats):
            kn, ks, mu, delta = pair_law(scene, mat, w.material)
            types = [t + 1 for t, (tm, _) in enumerate(opts.types) if tm == mat]
            group = f"m{m}"
            if k == 0:
                out.append(f"group           {group} type {' '.join(map(str, types))}")
            if opts.granular:
                law = "granular " + granular_coeff(scene, kn, ks, mu, delta)
            else:
                law = f"hooke/history {fmt(kn)} {fmt(ks)} 0.0 0.0 {fmt(mu)} 0"
            out.append(f"fix             W{k}m{m} {group} wall/gran/region {law} region W{k} contacts")
    return out


def wall_line(scene, wall):
    """A point of the wall's line and its unit direction e, as the core builds them (build.c):
    a [wall] section's P and (cos alpha, sin alpha), alpha = angle pi/180; a generated wall's
    end A and (B - A)/|B - A|."""
    keys = scene.wall_sections.get(wall.name, {})
    if "p" in keys and "angle" in keys:
        px, py = (float(v) for v in keys["p"].split())
        alpha = float(keys["angle"]) * (math.pi / 180)
        return (px, py), (math.cos(alpha), math.sin(alpha))
    ex, ey = wall.bx - wall.ax, wall.by - wall.ay
    length = math.hypot(ex, ey)
    return (wall.ax, wall.ay), (ex / length, ey / length)


def pivot(scene, wall):
    keys = scene.wall_sections.get(wall.name, {})
    if "p" in keys:
        px, py = (float(v) for v in keys["p"].split())
        return px, py
    return wall.ax, wall.ay


def turning_walls(scene):
    """The walls some stage turns (a `move` with omega != 0): only they get a region rotation
    (an unturned one would add its transform's round-off)."""
    return {c.wall for s in scene.stages for c in s.controls if c.kind == "move" and c.numbers(3)[2] != 0}


def moving_walls(scene, opts=None):
    """The walls a `move` moves (and no carrier carries: controlled_walls(); nor the wall whose
    frame the run is made in, opts.frame: that one stands still, frame_lines())."""
    carried = {scene.walls[k].name for k in controlled_walls(scene)}
    frame = getattr(opts, "frame", None)
    if frame is not None:
        carried.add(scene.walls[frame].name)
    return {c.wall for s in scene.stages for c in s.controls if c.kind == "move"
            and any(v != 0 for v in c.numbers(3)) and c.wall not in carried}


# ---------------------------------------------------------------------------------- the wall's frame
#
# Rolling against a turning wall (docs/engines.md, "Rolling against a turning wall"): fix
# wall/gran's rolling displacement takes the particle's spin only, not the wall's.  Where one
# wall moves and every disc is held, the run is made in that wall's own frame (moving and turning
# with it): there the wall stands still and each held disc moves rigidly,
#     X'(t) = P0 + R(-theta(t)) (X - P0 - d(t)),   spin omega' = omega - omega_wall = -omega_wall,
# X the disc's (fixed) place in the lab, P0 the wall's pivot at the start, d(t) and theta(t) the
# wall's displacement and angle (the same step formulas as a moving region's).  The contact's
# relative kinematics are those of the lab (a rotation of them), so its forces, its moment and
# theta_r = int (omega - omega_wall) dt are ballast's; lammps_output.Reader takes the state back.


def frame_wall(scene):
    """The index of the wall the run can be made in the frame of, or None: rolling resistance,
    exactly one wall, a [wall] section (its pivot P), turned by some stage and driven by `move`
    only, every disc held (fixed = 1), no stop rule.  lammps.plan() decides whether it is taken."""
    if len(scene.walls) != 1 or not any(m.rolling > 0 for m in scene.materials.values()):
        return None
    w = scene.walls[0]
    if w.name not in turning_walls(scene) or "p" not in scene.wall_sections.get(w.name, {}):
        return None
    if controlled_walls(scene) or any(c.kind != "move" for s in scene.stages for c in s.controls):
        return None
    if not all(h == {"x", "y", "rotation"} for h in scenes.held(scene)):
        return None
    if any(_stop_rule(s) for s in scene.stages):
        return None            # frame_stage_lines() takes each stage's start from the schedule
    return 0


def frame_lines(scene, opts):
    """The held discs' rigid motion in the frame of wall opts.frame (frame_wall()): their lab
    places X stored at the start (fix store/state; the frame is the lab's at t = 0) and fix move
    variable, whose atom-style formulas frame_stage_lines() writes per stage (here: at rest)."""
    if getattr(opts, "frame", None) is None:
        return []
    return ["fix             lab held store/state 0 x y",
            "variable        F_x atom 0.0", "variable        F_y atom 0.0",
            "variable        F_vx atom 0.0", "variable        F_vy atom 0.0",
            "fix             frame held move variable v_F_x v_F_y NULL v_F_vx v_F_vy NULL"]


def frame_stage_lines(scene, opts, g):
    """Stage g's motion of the held discs in the wall's frame: x = X'(t) and v = dX'/dt =
    -omega_w J (X' - P0) - R(-theta) V, with X' - P0 = R(-theta)(X - P0 - d), d and theta the
    wall's displacement and angle at the step, d0 + V dt (step - N0) and theta0 + omega_w dt
    (step - N0) from where the stage starts (wall_motion(): the stages run their whole cycles,
    frame_wall() has no stop rules); and the discs' spin -omega_w.  Every number is a literal of
    the formula: LAMMPS hands an equal-style variable to another formula as a 15-digit string
    (Variable::retrieve), which would round the angle's cosine by up to 5e-16."""
    if getattr(opts, "frame", None) is None:
        return []
    w = scene.walls[opts.frame]
    stage = scene.stages[g]
    v1 = v2 = om = 0.0
    for c in stage.controls:
        if c.kind == "move" and c.wall == w.name:
            v1, v2, om = c.numbers(3)
    n0 = stage_starts(scene)[g]
    schedule = [(s, s.cycles) for s in scene.stages]
    dx0, dy0, th0 = wall_motion(scene, schedule, n0, w)
    dt = scene.dt
    px, py = pivot(scene, w)
    since = f"(step-{n0})"
    th = f"({fmt(th0)}+({fmt(om * dt)})*{since})"
    dx = f"({fmt(dx0)}+({fmt(v1 * dt)})*{since})"
    dy = f"({fmt(dy0)}+({fmt(v2 * dt)})*{since})"
    c, s = f"cos({th})", f"sin({th})"
    ox, oy = f"(f_lab[1]-({fmt(px)})-{dx})", f"(f_lab[2]-({fmt(py)})-{dy})"      # X - P0 - d
    rx, ry = f"({c}*{ox}+{s}*{oy})", f"(-{s}*{ox}+{c}*{oy})"                  # X' - P0
    return [f"variable        F_x atom \"{fmt(px)}+{rx}-f_lab[1]\"",              # X' - X (fix move adds X)
            f"variable        F_y atom \"{fmt(py)}+{ry}-f_lab[2]\"",
            f"variable        F_vx atom \"({fmt(om)})*{ry}-({c}*({fmt(v1)})+{s}*({fmt(v2)}))\"",
            f"variable        F_vy atom \"-({fmt(om)})*{rx}-(-{s}*({fmt(v1)})+{c}*({fmt(v2)}))\"",
            f"set             group held omega 0.0 0.0 {fmt(-om)}"]


def wall_motion(scene, schedule, step, w):
    """(dx, dy, theta): wall w's displacement and angle after `step` cycles, each stage's velocity
    and spin times its cycles (ballast's `move`; dyadic sums in the catalogue, so exact).
    schedule: (stage, its actual cycles) in order."""
    dt = scene.dt
    dx = dy = th = 0.0
    n0 = 0
    for stage, cycles in schedule:
        steps = max(0, min(step - n0, cycles))
        for c in stage.controls:
            if c.kind == "move" and c.wall == w.name:
                v1, v2, om = c.numbers(3)
                dx += v1 * dt * steps
                dy += v2 * dt * steps
                th += om * dt * steps
        n0 += cycles
    return dx, dy, th


# ---------------------------------------------------------------------------------- controlled walls
#
# A servo or strain-rate wall moves in cycle N + 1 with a velocity its controller computed from
# the state of cycle N (core/walls.c): state that LAMMPS's equal-style variables of the step do
# not keep.  Each such wall is carried by an atom of its own (a "carrier": no pair, no force,
# excluded from the neighbour lists) that `fix move variable NULL NULL NULL v_vx v_vy NULL` moves
# by x += dt v, v the controller's velocity evaluated first thing in the step (the fix is defined
# before the discs' integrator), i.e. from the discs, walls and wall contacts of the step before;
# the wall's region moves with its carrier (W<k>_dx = x[carrier] - x0).  docs/engines.md derives
# the laws.

CONTROLLERS = ("servo", "strain_rate")
# The speed at which a servo with vmax = 0 moves: this share of the smallest radius per step
# (core/walls.c, BAL_SERVO_CAP_SHARE).
SERVO_CAP_SHARE = 1e-3


def control_walls(control):
    """The other walls a controller line names: a servo's span walls, a strain rate's target."""
    if control.kind == "servo":
        return control.words[3:5]
    if control.kind == "strain_rate":
        return control.words[1:2]
    return []


def controlled_walls(scene):
    """Indices (wall order) of the walls a carrier atom carries: every wall a servo or strain
    rate drives in some stage, and every wall such a controller measures (a span, a target) that
    some stage moves."""
    driven, measured, moved = set(), set(), set()
    for st in scene.stages:
        for c in st.controls:
            moved.add(c.wall)
            if c.kind in CONTROLLERS:
                driven.add(c.wall)
                measured.update(control_walls(c))
    names = driven | (measured & moved)
    return [k for k, w in enumerate(scene.walls) if w.name in names]


def midpoint(wall):
    return 0.5 * (wall.ax + wall.bx), 0.5 * (wall.ay + wall.by)


def wall_normal(wall):
    """The core's normal (-e2, e1) of a wall, e = (B - A)/|B - A|."""
    ex, ey = wall.bx - wall.ax, wall.by - wall.ay
    length = math.hypot(ex, ey)
    return -ey / length, ex / length


def toward_discs(scene, wall):
    """A servo wall's direction of motion: its normal on the side of the discs' centroid (the
    core's servo_start; taken from the discs as the run starts)."""
    nx, ny = wall_normal(wall)
    cx, cy = float(np.mean(scene.discs["x"])), float(np.mean(scene.discs["y"]))
    side = (cx - wall.ax) * nx + (cy - wall.ay) * ny
    return (-nx, -ny) if side < 0 else (nx, ny)


def _shift(scene, k, axis):
    """Wall k's displacement since the start along axis ('x' or 'y') as a formula: its carrier's,
    or 0 for a wall no stage moves (controlled_walls() carries every moving wall a controller
    reads)."""
    return f"v_W{k}_d{axis}" if k in controlled_walls(scene) else "0.0"


def gap_formula(scene, a, b):
    """gap(A, B) = (M_B - P_A) . n_A (signed; core/walls.c bal_walls_gap) at the current step,
    P_A a point of A's line, M_B the midpoint of B, both moved by their displacements."""
    wa, wb = scene.walls[a], scene.walls[b]
    nx, ny = wall_normal(wa)
    mx, my = midpoint(wb)
    c0 = (mx - wa.ax) * nx + (my - wa.ay) * ny
    return (f"({fmt(c0)}+({_shift(scene, b, 'x')}-{_shift(scene, a, 'x')})*{fmt(nx)}"
            f"+({_shift(scene, b, 'y')}-{_shift(scene, a, 'y')})*{fmt(ny)})")


def wall_index(scene, name):
    return next(k for k, w in enumerate(scene.walls) if w.name == name)


def carrier_lines(scene, opts):
    """What moves the carriers: per controlled wall k, the sums its servo reads from the wall's
    contacts of the step before (compute W<k>s: the springs' normal force sum k_n delta, the
    contacts per disc material, and where needed the whole force along the normal), its
    stiffness K and its velocity W<k>_vx, W<k>_vy (stage_lines() defines them per stage); the
    fix is carrier_fix()'s."""
    carriers = controlled_walls(scene)
    if not carriers:
        return []
    n = len(scene.discs["x"])
    mats = []
    for mat, _ in opts.types:
        if mat not in mats:
            mats.append(mat)
    out = []
    whole = whole_force_walls(scene)
    for k in carriers:
        w = scene.walls[k]
        side = wall_side(scene, w)
        (qx, qy), (ex, ey) = wall_line(scene, w)
        nx, ny = -ey * side, ex * side                 # the region's normal, towards the discs
        # k_n delta of each disc touching the wall: column 1 of the wall fix's contacts is 1 for a
        # contact, column 8 the disc's radius; delta = r - the centre's distance to the plane
        spring = "+".join(f"f_W{k}m{m}[1]*{fmt(pair_law(scene, mat, w.material)[0])}*(f_W{k}m{m}[8]"
                          f"-((x-v_W{k}_qx)*{fmt(nx)}+(y-v_W{k}_qy)*{fmt(ny)}))"
                          for m, mat in enumerate(mats))
        counts = " ".join(f"f_W{k}m{m}[1]" for m in range(len(mats)))
        out += [f"variable        W{k}_qx equal {fmt(qx)}+v_W{k}_dx",
                f"variable        W{k}_qy equal {fmt(qy)}+v_W{k}_dy",
                f"variable        W{k}_kd atom {spring}"]
        sums = f"v_W{k}_kd {counts}"
        if k in whole:
            along = "+".join(f"f_W{k}m{m}[2]*{fmt(nx)}+f_W{k}m{m}[3]*{fmt(ny)}" for m in range(len(mats)))
            out.append(f"variable        W{k}_ft atom {along}")
            sums += f" v_W{k}_ft"
        # [1] the springs' normal force, [2 ...] the contacts with each disc material, [then] the
        # whole force along the normal (only for a wall whose servo may need it: whole_force_walls())
        stiff = "+".join(f"c_W{k}s[{m + 2}]*{fmt(pair_law(scene, mat, w.material)[0])}"
                         for m, mat in enumerate(mats))
        out += [f"compute         W{k}s all reduce sum {sums}",
                f"variable        W{k}_K equal \"{stiff}\"",
                f"variable        W{k}_vx equal 0.0", f"variable        W{k}_vy equal 0.0"]
    return out


def carrier_fix(scene):
    """The fix that moves every carrier (defined before the discs' integrator, so that it moves
    first in a step; its variables are carrier_lines()', defined after the wall fixes they read)."""
    carriers = controlled_walls(scene)
    if not carriers:
        return []
    n = len(scene.discs["x"])
    vx = "+".join(f"(id=={n + j + 1})*v_W{k}_vx" for j, k in enumerate(carriers))
    vy = "+".join(f"(id=={n + j + 1})*v_W{k}_vy" for j, k in enumerate(carriers))
    return [f"variable        carry_vx atom {vx}", f"variable        carry_vy atom {vy}",
            "fix             carry carriers move variable NULL NULL NULL v_carry_vx v_carry_vy NULL"]


def whole_force_walls(scene):
    """The carried walls whose servo starts a stage after a stage with no controller: the core
    then reads the whole force of its contacts at that first step (control_lines())."""
    out = set()
    for g, stage in enumerate(scene.stages):
        before = [s for s in scene.stages[:g] if s.cycles > 0]
        if before and not stage_tracks(before[-1]):
            out |= {wall_index(scene, c.wall) for c in stage.controls if c.kind == "servo"}
    return out


def stage_tracks(stage):
    """Does a stage drive a wall by a controller that acts every cycle (the core's
    walls_controlled: then its wall loop keeps the dashpots' share apart)?"""
    return any(c.kind in CONTROLLERS for c in stage.controls)


def control_lines(scene, g, first_step):
    """Each carried wall's velocity in stage g (the core's controllers, core/walls.c):
    servo        v = clip(alpha (sigma_t - S/L) L / (K dt), vcap) towards the discs, S the springs'
                 normal force sum (c_W<k>s[1]), K their stiffness (c_W<k>s[2]), L the span gap;
                 vcap when K = 0 (no contact; and at the first step of a run, before any wall
                 loop); at a stage's first step after a stage with no controller the whole force
                 (c_W<k>s[3]: the core kept no dashpot share then)
    strain_rate  v = rate gap(W, TO) along W's normal towards TO: rate (M_TO - P_W).n_W n_W
    move         (v1, v2) (a carried wall does not turn: plan())
    none         at rest.
    first_step: the formula that is 1 at the stage's first step."""
    out = []
    carriers = controlled_walls(scene)
    stage = scene.stages[g]
    before = [s for s in scene.stages[:g] if s.cycles > 0]
    r_min = float(np.min(scene.discs["r"]))
    for k in carriers:
        w = scene.walls[k]
        line = next((c for c in stage.controls if c.wall == w.name), None)
        if line is None:
            vx = vy = "0.0"
        elif line.kind == "move":
            v1, v2, _ = line.numbers(3)
            vx, vy = fmt(v1), fmt(v2)
        elif line.kind == "strain_rate":
            rate = line.numbers(1)[0]
            target = wall_index(scene, line.words[1])
            nx, ny = wall_normal(w)
            d = gap_formula(scene, k, target)
            vx, vy = f"{fmt(rate)}*{d}*{fmt(nx)}", f"{fmt(rate)}*{d}*{fmt(ny)}"
        else:
            sigma, gain, vmax = line.numbers(3)
            span = f"abs({gap_formula(scene, wall_index(scene, line.words[3]), wall_index(scene, line.words[4]))})"
            vcap = vmax if vmax > 0 else SERVO_CAP_SHARE * r_min / scene.dt
            stiff = f"v_W{k}_K"
            if not before:
                force = f"c_W{k}s[1]"
            elif not stage_tracks(before[-1]):
                whole = len(mats_of(scene)) + 2
                force = f"({first_step}*c_W{k}s[{whole}]+(1-{first_step})*c_W{k}s[1])"
            else:
                force = f"c_W{k}s[1]"
            # the uncapped speed (the denominator 1 instead of 0 where K = 0, which is then unused)
            out.append(f'variable        W{k}_raw equal "{fmt(gain)}*({fmt(sigma)}-{force}/{span})*{span}'
                       f'/(({stiff}+({stiff}<=0))*{fmt(scene.dt)})"')
            # clipped to [-vcap, vcap] by 0/1 factors (exact: no min/max of two numbers in LAMMPS)
            raw, cap = f"v_W{k}_raw", fmt(vcap)
            speed = (f"({stiff}>0)*(({raw}>{cap})*{cap}-({raw}<-{cap})*{cap}+({raw}>=-{cap})*({raw}<={cap})*{raw})"
                     f"+({stiff}<=0)*{cap}")
            if not before:
                speed = f"{first_step}*{fmt(vcap)}+(1-{first_step})*({speed})"
            tx, ty = toward_discs(scene, w)
            out.append(f'variable        W{k}_sp equal "{speed}"')
            # a component along which the wall does not move is 0 (not 0 times the speed: the
            # same, and LAMMPS evaluates the speed once less)
            vx, vy = (f"v_W{k}_sp*{fmt(t)}" if t != 0 else "0.0" for t in (tx, ty))
        out += [f'variable        W{k}_vx equal "{vx}"', f'variable        W{k}_vy equal "{vy}"']
    return out


def mats_of(scene):
    """The disc materials in the order of the wall fixes (one fix per wall and disc material)."""
    mats = []
    for mat in scene.disc_material:
        if mat not in mats:
            mats.append(mat)
    return mats


def wall_fixes(scene, opts):
    """The names of the wall fixes, (wall index, fix id), in wall_lines()'s order."""
    mats = []
    for mat, _ in opts.types:
        if mat not in mats:
            mats.append(mat)
    return [(k, f"W{k}m{m}") for k in range(len(scene.walls)) for m in range(len(mats))]


def atom_columns(scene, opts):
    cols = ["id", "x", "y", "vx", "vy", "c_pa[1]", "fx", "fy", "c_pa[2]", "mass"]
    for _, fid in wall_fixes(scene, opts):
        cols += [f"f_{fid}[{j}]" for j in (1, 2, 3, 5, 6)]
    return cols


def pair_columns(opts):
    extra = 8 if opts.granular else 4
    return ["c_pid[1]", "c_pid[2]"] + [f"c_pl[{j}]" for j in range(1, extra + 3)]


def start_lines(scene, opts):
    """The setup run, then the scene's v_1/2 taken to v_0 = v_1/2 - dt/2 a_0 (a_0 from LAMMPS's
    forces at t = 0, with LAMMPS's masses), for the free discs (centred scheme only)."""
    out = ["compute         pa all property/atom omegaz tqz radius"]
    if opts.granular:
        out.append("compute         pl all pair/local dist force p1 p2 p3 p4 p5 p6 p7 p8")
    else:
        out.append("compute         pl all pair/local dist force p1 p2 p3 p4")
    out.append("compute         pid all property/local patom1 patom2")
    if scene.setting("integrator") == "centred":
        # v_0 solves v_0 + dt/2 a_0(v_0) = v_1/2, a_0 LAMMPS's forces at t = 0 with the velocities
        # v_0 (dashpots of contacts that touch at the start, global damping's drag): a fixed-point
        # iteration from v_0 = v_1/2, each a `run 0`; it contracts by dt/2 |da/dv| per pass.
        out += ["fix             half free store/state 0 vx vy omegaz",
                f"variable        it loop {START_PASSES}", "label           startpass",
                "dump            start all custom 1 start.dump id c_pa[1] c_pa[2] c_pa[3]",
                "run             0", "undump          start",
                "variable        v0x atom f_half[1]-0.5*dt*fx/mass",
                "variable        v0y atom f_half[2]-0.5*dt*fy/mass",
                "variable        w0 atom f_half[3]-0.5*dt*c_pa[2]/(0.5*mass*c_pa[3]^2)",
                "velocity        free set v_v0x v_v0y NULL",
                "set             group free omega 0.0 0.0 v_w0",
                "next            it", "jump            SELF startpass", "unfix           half"]
    return out


def _stop_rule(stage):
    return (stage.number("stop_ke") > 0 or stage.number("stop_stress") > 0 or stage.number("stop_unbalanced") > 0
            or stage.number("stop_servo") > 0)


def stage_lines(scene, opts, work):
    """One run per stage (a stage with a stop rule: runs of check_every steps, the rule checked
    after each), the walls' motion redefined at each stage's start, and the dumps at ballast's
    series rows: every output_every steps and at each run's end."""
    every = opts.every
    out = []
    if opts.dumps:
        out += ["variable        chunkend equal 0",
                f"variable        nm equal \"(floor(step/{every})+1)*{every}\"",
                "variable        dumpnext equal \"(step<v_chunkend)*((v_nm<v_chunkend)*v_nm+"
                "(v_nm>=v_chunkend)*v_chunkend)+(step>=v_chunkend)*v_nm\"",
                "dump            atoms all custom 1 atoms.dump " + " ".join(atom_columns(scene, opts)),
                "dump_modify     atoms sort id format float %.17g every v_dumpnext",
                "dump            pairs all local 1 pairs.dump " + " ".join(pair_columns(opts)),
                "dump_modify     pairs format float %.17g every v_dumpnext"]
    if any(_stop_rule(s) for s in scene.stages):
        code = ("import sys\n    sys.path.insert(0, %r)\n    from harness.engines import lammps_output\n"
                "    return lammps_output.stop_check(%r, stage)" % (str(REPO_ROOT), str(work)))
        out += ["variable        stage equal 0",
                f"python          stoprule input 1 v_stage return v_met format ii here \"\"\"\n"
                f"def stoprule(stage):\n    {code}\n\"\"\"",
                "variable        met python stoprule"]
    moves = moving_walls(scene, opts)
    first = [True]

    def run(steps):
        pre = "" if first[0] else " pre no post no"
        first[0] = False
        return ["variable        chunkend equal $(step+%d)" % steps, f"run             {steps}{pre}"]

    carried = bool(controlled_walls(scene))
    for g, stage in enumerate(scene.stages):
        out.append(f"# stage {stage.name}: {stage.cycles} cycles")
        out += motion_lines(scene, stage, moves)
        out += frame_stage_lines(scene, opts, g)
        if carried and stage.cycles > 0:
            out.append("variable        gstart equal $(step)")
            out += control_lines(scene, g, "(step==v_gstart+1)")
        if stage.cycles <= 0:
            continue
        if not _stop_rule(stage):
            out += run(stage.cycles)
            continue
        k = int(float(stage.keys["check_every"]))
        checks, rest = divmod(stage.cycles, k)
        out.append(f"variable        stage equal {g}")
        if checks:
            out += [f"variable        n{g} loop {checks}", f"label           loop{g}"]
            out += run(k)
            out += [f"if              \"${{met}} > 0\" then \"jump SELF stopped{g}\"",
                    f"next            n{g}", f"jump            SELF loop{g}"]
        if rest:
            out += run(rest)
        out += [f"label           stopped{g}"]
    return out


def motion_lines(scene, stage, moves):
    """At a stage's start: each moving wall's displacement and angle from where it is, at its
    velocity and spin in this stage (0 for a wall this stage does not name)."""
    out, held = [], []
    dt = scene.dt
    for k, w in enumerate(scene.walls):
        if w.name not in moves:
            continue
        v1 = v2 = om = 0.0
        for c in stage.controls:
            if c.kind == "move" and c.wall == w.name:
                v1, v2, om = c.numbers(3)
        for var, rate in (("dx", v1), ("dy", v2), ("th", om)):
            # where the wall is (read before start moves on), then this stage's motion from there
            held += [f"variable        W{k}_{var}0 equal $(v_W{k}_{var}:%.17g)"]
            out += [f"variable        W{k}_{var} equal \"v_W{k}_{var}0+{fmt(rate * dt)}*(step-v_start)\""]
    if not out:
        return []
    return held + ["variable        start equal $(step)"] + out
