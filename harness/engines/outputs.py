"""harness/engines/outputs.py -- an engine's Trajectory written as ballast's output files.

series.tsv (the scene's probes at every row), discs.tsv, contacts.tsv, walls.tsv and
stress.tsv of the last state, and run.json, in the formats core/output.c writes (numbers as
%.17g), with each quantity defined as core/probes.c and core/measure.c define it:

- velocities and the kinetic energy at t_N; held discs at rest;
- the elastic energy of the contact springs: F_n^2/(2 k_n) for the incremental law,
  k_n delta0^2 (delta/delta0)^(nu+1)/(nu+1) for the power law, F_s^2/(2 k_s), M^2/(2 K_m);
- a wall's resultant, moment about P and the eccentricity of its normal force (C&S Table 1);
- the unbalanced-force ratio (C&S dF/F), held forces, the free discs' weight;
- per-disc stress (MLH eq. 8): sum of f (x) l over the disc's contacts, l from the centre to the
  middle of the overlap (for a wall halfway between the disc's surface and the wall), over
  V = 2 sqrt(3) r^2 -- bal_measure_moments.

So the checks read another engine's run through the same files and the same definitions; only
the numbers in them are the engine's.  Probes the engine cannot give (the energy ledger: work
of the walls and gravity, dissipation; a disc's angle) are left out of series.tsv and listed
in run.json's `unexpressible`, so a check that reads one is "not expressible" (compare.py).
"""
import json
import math

import numpy as np

from .. import files
from . import scene as scenes

# Probes whose values need the energy ledger ballast keeps cycle by cycle (core/energy.c), or a
# disc's angle; an engine's trajectory of output rows cannot give them.
LEDGER = ("work_walls", "work_gravity", "dissipated_dashpot", "dissipated_friction",
          "dissipated_global", "dissipated_rolling", "energy_imbalance")
LEDGER_WHY = ("the energy ledger (work of walls and gravity, dissipation; core/energy.c) is "
              "ballast's own, accumulated every cycle: the engine reports no such terms")
THETA_WHY = "the engine keeps no angle for a disc (a sphere's orientation is not integrated)"
SERVO_WHY = ("the adapter does not report the stress a servo measured (its wall's force over its span "
             "is there: wall_f1, wall_f2 and the walls' positions)")


def unexpressible_probes(scene):
    """{probe name: why} for the scene's probes an engine trajectory cannot give, and the
    run.json energy audit that expressions.energy() reads."""
    out = {}
    for p in scene.probes:
        if p.quantity in LEDGER:
            out[p.name] = LEDGER_WHY
        elif p.quantity == "disc_theta":
            out[p.name] = THETA_WHY
        elif p.quantity == "wall_stress":
            out[p.name] = SERVO_WHY
    out["energy"] = LEDGER_WHY
    return out


def g(v):
    return "nan" if not math.isfinite(v) else "%.17g" % v


class Laws:
    """The pair laws of the scene's materials (core/build.c): k = 2 k_a k_b/(k_a + k_b), the
    smaller friction and rolling parameter; and the normal law's energy."""

    def __init__(self, scene):
        self.scene = scene
        self.power = scene.setting("normal_law") == "power"
        self.nu, self.delta0 = scene.number("nu"), scene.number("delta0")
        names = list(scene.materials)
        laws = [[self.pair(p, q) for q in names] for p in names]
        # kn, ks, friction, rolling as tables over material indices; each disc's and wall's index
        self.table = [np.array([[law[f] for law in row] for row in laws]) for f in range(4)]
        self.disc_mat = (np.array([names.index(m) for m in scene.disc_material], dtype=int)
                         if scene.disc_material is not None else None)
        self.wall_mat = np.array([names.index(w.material) for w in scene.walls], dtype=int)

    def of(self, contacts):
        """(kn, ks, friction, rolling) arrays of every contact."""
        a = self.disc_mat[contacts["a"]]
        wall = contacts["wall"].astype(bool)
        b = np.where(wall, self.wall_mat[np.where(wall, contacts["b"], 0)] if len(self.wall_mat) else 0,
                     self.disc_mat[np.where(wall, 0, contacts["b"])])
        return [t[a, b] for t in self.table]

    def normal_energies(self, kn, fn, delta):
        if not self.power:
            return fn * fn / (2 * kn)
        d0 = self.delta0
        return np.where(delta > 0, kn * d0 * d0 * (np.maximum(delta, 0) / d0) ** (self.nu + 1) / (self.nu + 1), 0.0)

    def pair(self, ma, mb):
        A, B = self.scene.materials[ma], self.scene.materials[mb]
        kn = 2 * A.kn * B.kn / (A.kn + B.kn)
        ks = 2 * A.ks * B.ks / (A.ks + B.ks)
        return kn, ks, min(A.friction, B.friction), min(A.rolling, B.rolling)

    def normal_energy(self, kn, fn, delta):
        if not self.power:
            return fn * fn / (2 * kn)
        d0 = self.delta0
        return kn * d0 * d0 * (delta / d0) ** (self.nu + 1) / (self.nu + 1) if delta > 0 else 0.0


class Bodies:
    """Disc and wall names of a resolved scene: a probe's a and b to indices."""

    def __init__(self, scene):
        self.disc = {n: k for k, n in enumerate(scene.discs["name"])}
        self.wall = {w.name: k for k, w in enumerate(scene.walls)}

    def find(self, name):
        if name in self.disc:
            return False, self.disc[name]
        if name in self.wall:
            return True, self.wall[name]
        raise scenes.SceneError(f"probe body '{name}' is neither a disc nor a wall of the scene")


def wall_point(scene, k):
    """The point P of wall k (its [wall] section's p; a generated wall's end A)."""
    w = scene.walls[k]
    keys = scene.wall_sections.get(w.name)
    if keys and "p" in keys:
        px, py = (float(v) for v in keys["p"].split())
        return px, py
    return w.ax, w.ay


class Measure:
    """The quantities of one Frame, as core/measure.c and core/probes.c define them."""

    def __init__(self, scene, frame, laws, bodies):
        self.s, self.f, self.laws, self.bodies = scene, frame, laws, bodies
        d = scene.discs
        self.m, self.r = d["m"], d["r"]
        self.inertia = 0.5 * self.m * self.r ** 2
        self.held = scenes.held(scene)
        self.c = frame.contacts
        n = len(self.m)
        fx, fy, tq = np.zeros(n), np.zeros(n), np.zeros(n)
        c = self.c
        ftn, fts = c["fn"] + c["dn"], c["fs"] + c["ds"]
        cx = ftn * c["nx"] + fts * c["ny"]
        cy = ftn * c["ny"] - fts * c["nx"]
        couple = c["mr"] + c["md"]
        a, b, wall = c["a"], c["b"], c["wall"].astype(bool)
        np.add.at(fx, a, -cx)
        np.add.at(fy, a, -cy)
        arm_a = self.r[a]
        np.add.at(tq, a, fts * arm_a - couple)
        disc = ~wall
        np.add.at(fx, b[disc], cx[disc])
        np.add.at(fy, b[disc], cy[disc])
        np.add.at(tq, b[disc], fts[disc] * self.r[b[disc]] + couple[disc])
        self.fx, self.fy, self.tq = fx, fy, tq
        self.cx, self.cy = cx, cy

    def contact(self, a, b):
        """The row of the contact of bodies a and b (names), its flip (1 when the row's a is
        the probe's b), or (None, 0) when they do not touch."""
        wa, ia = self.bodies.find(a)
        wb, ib = self.bodies.find(b)
        c = self.c
        if wa and wb:
            return None, 0
        if wa or wb:
            disc, wall = (ib, ia) if wa else (ia, ib)
            rows = np.flatnonzero((c["wall"] == 1) & (c["a"] == disc) & (c["b"] == wall))
            return (int(rows[0]) if rows.size else None), int(wa)
        rows = np.flatnonzero((c["wall"] == 0) & (((c["a"] == ia) & (c["b"] == ib))
                                                   | ((c["a"] == ib) & (c["b"] == ia))))
        if not rows.size:
            return None, 0
        row = int(rows[0])
        return row, int(c["a"][row] != ia)

    def kinetic(self):
        f = self.f
        return float(np.sum(0.5 * self.m * (f.vx ** 2 + f.vy ** 2) + 0.5 * self.inertia * f.omega ** 2))

    def elastic(self):
        """The springs' energy (measure.c): normal, F_s^2/(2 k_s), M^2/(2 K_m), K_m = k_n B^2/12
        with B = delta r, r the common radius (2 r1 r2/(r1 + r2); 2 r against a wall)."""
        c = self.c
        if not len(c["a"]):
            return 0.0
        kn, ks, _, droll = self.laws.of(c)
        e = self.laws.normal_energies(kn, c["fn"], c["delta"])
        e = e + np.where(ks > 0, c["fs"] ** 2 / (2 * np.where(ks > 0, ks, 1.0)), 0.0)
        if np.any(droll > 0):
            ra = self.r[c["a"]]
            wall = c["wall"].astype(bool)
            rb = np.where(wall, 1.0, self.r[np.where(wall, 0, c["b"])])
            common = np.where(wall, 2 * ra, 2 * ra * rb / (ra + rb))
            km = kn * (droll * common) ** 2 / 12
            e = e + np.where(droll > 0, c["mr"] ** 2 / (2 * np.where(km > 0, km, 1.0)), 0.0)
        return float(np.sum(e))

    def unbalanced(self):
        c = self.c
        if not len(c["a"]):
            return 0.0
        big = float(np.max(np.hypot(c["fn"] + c["dn"], c["fs"] + c["ds"])))
        if big == 0:
            return 0.0
        gx, gy = self.s.gravity()
        sx = self.fx + self.m * gx * self.f.gfac
        sy = self.fy + self.m * gy * self.f.gfac
        worst = 0.0
        for i, hold in enumerate(self.held):
            if {"x", "y", "rotation"} <= hold:
                continue
            hx = 0.0 if "x" in hold else sx[i]
            hy = 0.0 if "y" in hold else sy[i]
            worst = max(worst, math.hypot(hx, hy))
        return worst / big

    def wall(self, k):
        """(f1, f2, moment about P, eccentricity) of wall k: the force the discs exert on it."""
        c = self.c
        rows = np.flatnonzero((c["wall"] == 1) & (c["b"] == k))
        px, py = wall_point(self.s, k)
        ax, ay, bx, by = self.f.walls[k]
        length = math.hypot(bx - ax, by - ay)
        ex, ey = (bx - ax) / length, (by - ay) / length
        f1 = f2 = mom = fn_sum = fn_s = 0.0
        # P moves with the wall: its offset from A along the wall is fixed
        w0 = self.s.walls[k]
        h1 = (w0.ax - px) * ex + (w0.ay - py) * ey if (w0.ax, w0.ay) != (px, py) else 0.0
        h1 = ((w0.ax - px) * (w0.bx - w0.ax) + (w0.ay - py) * (w0.by - w0.ay)) / math.hypot(
            w0.bx - w0.ax, w0.by - w0.ay)
        pnx, pny = ax - h1 * ex, ay - h1 * ey
        for row in rows:
            i = c["a"][row]
            nx, ny = c["nx"][row], c["ny"][row]
            dist = self.r[i] - c["delta"][row]
            wx, wy = self.f.x[i] + dist * nx, self.f.y[i] + dist * ny    # the wall's point
            fcx, fcy = self.cx[row], self.cy[row]
            f1 += fcx
            f2 += fcy
            mom += (wx - pnx) * fcy - (wy - pny) * fcx + c["mr"][row] + c["md"][row]
            ftn = c["fn"][row] + c["dn"][row]
            fn_sum += ftn
            fn_s += ftn * ((wx - pnx) * ex + (wy - pny) * ey)
        h2 = h1 + length
        mid, half = 0.5 * (h1 + h2), 0.5 * (h2 - h1)
        ecc = (fn_s / fn_sum - mid) / half if fn_sum != 0 else 0.0
        return f1, f2, mom, ecc, (pnx, pny)

    def probe(self, p):
        q = p.quantity
        if q.startswith("contact_"):
            row, flip = self.contact(p.a, p.b)
            if row is None:
                return 0.0
            c = self.c
            if q == "contact_fn":
                return float(c["fn"][row])
            if q == "contact_fs":
                return float(-c["fs"][row] if flip else c["fs"][row])
            if q == "contact_sliding":
                return float(c["sliding"][row])
            if q == "contact_mr":
                return float(-c["mr"][row] if flip else c["mr"][row])
            if q == "contact_theta_r":
                return float(-c["theta_r"][row] if flip else c["theta_r"][row])
            if q == "contact_rolling":
                return float(c["rolling"][row])
        if q.startswith("disc_"):
            _, i = self.bodies.find(p.a)
            f = self.f
            return float({"disc_x": f.x, "disc_y": f.y, "disc_vx": f.vx, "disc_vy": f.vy,
                          "disc_omega": f.omega}[q][i])
        if q.startswith("wall_"):
            _, k = self.bodies.find(p.a)
            if q == "wall_gap":
                _, kb = self.bodies.find(p.b)
                return wall_gap(self.f.walls[k], self.f.walls[kb])
            f1, f2, mom, ecc, (px, py) = self.wall(k)
            return float({"wall_f1": f1, "wall_f2": f2, "wall_moment": mom, "wall_ecc": ecc,
                          "wall_px": px, "wall_py": py}[q])
        if q == "energy_kinetic":
            return self.kinetic()
        if q == "energy_elastic":
            return self.elastic()
        if q == "unbalanced":
            return self.unbalanced()
        if q == "n_contacts":
            return float(len(self.c["a"]))
        if q == "n_sliding":
            return float(np.sum(self.c["sliding"]))
        if q in ("held_fx", "held_fy"):
            axis = "x" if q == "held_fx" else "y"
            f = self.fx if axis == "x" else self.fy
            return float(sum(f[i] for i, h in enumerate(self.held) if axis in h))
        if q in ("weight_x", "weight_y"):
            axis = "x" if q == "weight_x" else "y"
            gx, gy = self.s.gravity()
            mass = sum(self.m[i] for i, h in enumerate(self.held) if axis not in h)
            return float(mass * (gx if axis == "x" else gy) * self.f.gfac)
        raise scenes.SceneError(f"probe {p.name}: quantity '{q}' has no engine counterpart here")

    def moments(self):
        """Per disc the moment sum f (x) l of its contacts (bal_measure_moments), (n, 4)."""
        n = len(self.m)
        out = np.zeros((n, 4))
        c = self.c
        for row in range(len(c["a"])):
            i = c["a"][row]
            nx, ny = c["nx"][row], c["ny"][row]
            fx, fy = self.cx[row], self.cy[row]        # force on b (the wall, or disc b)
            if c["wall"][row]:
                dist = self.r[i] - c["delta"][row]
                arm = 0.5 * (self.r[i] + dist)
                _add(out, i, -fx, -fy, arm * nx, arm * ny)
                continue
            j = c["b"][row]
            li, lj = self.r[i] - c["delta"][row] / 2, self.r[j] - c["delta"][row] / 2
            _add(out, i, -fx, -fy, li * nx, li * ny)
            _add(out, j, fx, fy, -lj * nx, -lj * ny)
        return out


def _add(m, i, fx, fy, lx, ly):
    m[i, 0] += fx * lx
    m[i, 1] += fx * ly
    m[i, 2] += fy * lx
    m[i, 3] += fy * ly


def wall_gap(wa, wb):
    """The distance from wall a's line to the midpoint of wall b along a's normal (walls.c)."""
    ax, ay, bx, by = wa
    length = math.hypot(bx - ax, by - ay)
    nx, ny = -(by - ay) / length, (bx - ax) / length
    mx, my = 0.5 * (wb[0] + wb[2]), 0.5 * (wb[1] + wb[3])
    return abs((mx - ax) * nx + (my - ay) * ny)


def principal(xx, xz, zx, zz):
    plus, minus, star = 0.5 * (xx + zz), 0.5 * (xx - zz), 0.5 * (xz + zx)
    rad = math.hypot(minus, star)
    a = 0.5 * math.atan2(2 * star, xx - zz) * (180 / math.pi)
    return plus + rad, plus - rad, a + 180 if a < 0 else a


# ---------------------------------------------------------------------------------- the files

def series_text(scene, trajectory, laws, bodies, skip):
    names = [p.name for p in scene.probes if p.name not in skip]
    lines = ["\t".join(["cycle", "time"] + names)]
    for frame in trajectory.frames:
        m = Measure(scene, frame, laws, bodies)
        values = [m.probe(p) for p in scene.probes if p.name not in skip]
        lines.append("\t".join([str(frame.step), g(frame.time)] + [g(v) for v in values]))
    return "\n".join(lines) + "\n"


def discs_text(scene, frame):
    d = scene.discs
    out = ["id\tname\tx\ty\tr\ttheta\tvx\tvy\tomega\tm\tfixed\trow"]
    for k, name in enumerate(d["name"]):
        out.append("\t".join([str(k), name, g(frame.x[k]), g(frame.y[k]), g(d["r"][k]), "nan",
                              g(frame.vx[k]), g(frame.vy[k]), g(frame.omega[k]), g(d["m"][k]),
                              str(int(d["fixed"][k])), str(int(d["row"][k]))]))
    return "\n".join(out) + "\n"


def contacts_text(scene, frame, rolling):
    c, names = frame.contacts, scene.discs["name"]
    head = "a\tb\tkind\tx\ty\tnx\tny\tfn\tfs\tdn\tds\tsliding" + ("\tmr\tmd\ttheta_r\trolling" if rolling else "")
    out = [head]
    order = sorted(range(len(c["a"])), key=lambda k: (int(c["wall"][k]), int(c["a"][k]), int(c["b"][k])))
    for k in order:
        b = scene.walls[c["b"][k]].name if c["wall"][k] else names[c["b"][k]]
        row = [names[c["a"][k]], b, "wall" if c["wall"][k] else "disc", g(c["px"][k]), g(c["py"][k]),
               g(c["nx"][k]), g(c["ny"][k]), g(c["fn"][k]), g(c["fs"][k]), g(c["dn"][k]), g(c["ds"][k]),
               str(int(c["sliding"][k]))]
        if rolling:
            row += [g(c["mr"][k]), g(c["md"][k]), g(c["theta_r"][k]), str(int(c["rolling"][k]))]
        out.append("\t".join(row))
    return "\n".join(out) + "\n"


def walls_text(scene, frame, measure):
    out = ["name\tax\tay\tbx\tby\tf1\tf2\tmoment\tecc"]
    for k, w in enumerate(scene.walls):
        f1, f2, mom, ecc, _ = measure.wall(k)
        ax, ay, bx, by = frame.walls[k]
        out.append("\t".join([w.name] + [g(v) for v in (ax, ay, bx, by, f1, f2, mom, ecc)]))
    return "\n".join(out) + "\n"


def stress_text(scene, frame, measure):
    d = scene.discs
    m = measure.moments()
    out = ["id\tname\tx\ty\trow\tfixed\tV\tsxx\tsxz\tszx\tszz\tsmax\tsmin\tphi"]
    for k, name in enumerate(d["name"]):
        v = 2 * math.sqrt(3.0) * d["r"][k] ** 2
        xx, xz, zx, zz = (m[k, j] / v for j in range(4))
        smax, smin, phi = principal(xx, xz, zx, zz)
        out.append("\t".join([str(k), name, g(frame.x[k]), g(frame.y[k]), str(int(d["row"][k])),
                              str(int(d["fixed"][k])), g(v), g(xx), g(xz), g(zx), g(zz), g(smax),
                              g(smin), g(phi)]))
    return "\n".join(out) + "\n"


def write(scene, plan, trajectory, out, base, wall_seconds):
    """Every output file of the run into out, run.json last."""
    out = files.make_dirs(out)
    laws, bodies = Laws(scene), Bodies(scene)
    skip = unexpressible_probes(scene)
    skip.update(plan.unexpressible)
    final = Measure(scene, trajectory.final, laws, bodies)
    rolling = any(m.rolling > 0 for m in scene.materials.values())
    files.write_text(out / "series.tsv", series_text(scene, trajectory, laws, bodies, skip))
    files.write_text(out / "discs.tsv", discs_text(scene, trajectory.final))
    files.write_text(out / "contacts.tsv", contacts_text(scene, trajectory.final, rolling))
    files.write_text(out / "walls.tsv", walls_text(scene, trajectory.final, final))
    files.write_text(out / "stress.tsv", stress_text(scene, trajectory.final, final))
    n = len(scene.discs["x"])
    info = dict(base)
    init = scene.init_info or {}
    gx, gy = scene.gravity()
    status_ok = not trajectory.notes.get("failure")
    info.update(status="ok" if status_ok else "failed",
                message="" if status_ok else trajectory.notes["failure"],
                complete=status_ok, steps=trajectory.steps, time=trajectory.steps * scene.dt,
                dt=scene.dt, dt_estimate=init.get("dt_estimate"), wall_seconds=wall_seconds,
                engine_seconds=trajectory.engine_seconds, n_discs=n, n_walls=len(scene.walls),
                particle_steps=n * trajectory.steps,
                particle_steps_per_s=(n * trajectory.steps / trajectory.engine_seconds
                                      if trajectory.engine_seconds > 0 else None),
                gravity=[gx, gy], energy_kinetic=final.kinetic(), energy_elastic=final.elastic(),
                unbalanced=final.unbalanced(), stages=trajectory.stages, piles=init.get("piles", []),
                unexpressible=skip, notes=trajectory.notes)
    files.write_text(out / "run.json", json.dumps(info, indent=1) + "\n")
