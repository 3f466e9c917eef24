"""harness/engines/lammps_output.py -- a LAMMPS run read back in ballast's conventions: its log and
dumps (parse_log, parse_frames), each series row's state as a trajectory Frame (Reader: the
elastic forces from the overlap by the law, the dashpots from the half-step velocities LAMMPS's
forces saw), the walls where the stages moved them, the stop rules' checks called from inside
LAMMPS (stop_check), and the whole run as a Trajectory (trajectory_of).
"""
import json
import math
import os
import pickle
import re
import subprocess
from pathlib import Path

import numpy as np

from .. import files
from . import scene as scenes
from .lammps_input import (_stop_rule, controlled_walls, midpoint, pair_law, pivot, wall_fixes,
                           wall_motion)
from .outputs import Bodies, Laws, Measure, wall_gap
from .trajectory import Frame, Trajectory, concatenate, contacts_of, empty_contacts

# A contact at the Coulomb (or rolling) cap: |F_s| >= mu |F_n| to this relative round-off.
CAP_ROUNDOFF = 1e-9
# The wall's plane is infinite, ballast's wall a segment: a contact point this far (relative
# to the wall's length) beyond an end is a contact ballast would not have made.
WALL_END_ROUNDOFF = 1e-9


def parse_log(text):
    """The figures of a LAMMPS log that the harness uses: loop_seconds, procs, steps, atoms of
    the last "Loop time of X on P procs for S steps with N atoms", the sum of every loop's
    seconds and steps (total_seconds, total_steps), version from the banner, builds and
    dangerous from the last neighbour statistics."""
    out = {}
    m = re.search(r"^LAMMPS \((.*)\)\s*$", text, re.M)
    out["version"] = m.group(1) if m else ""
    loops = re.findall(r"^Loop time of ([-+0-9.eE]+) on (\d+) procs for (\d+) steps "
                       r"with (\d+) atoms", text, re.M)
    if not loops:
        raise ValueError("no 'Loop time' line in the LAMMPS log")
    sec, procs, steps, atoms = loops[-1]
    out.update(loop_seconds=float(sec), procs=int(procs), steps=int(steps), atoms=int(atoms),
               total_seconds=sum(float(x[0]) for x in loops), total_steps=sum(int(x[2]) for x in loops))
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
        data = np.array(" ".join(body).split(), dtype=float).reshape(count, len(names))
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


def last_frame(path):
    """The last frame of a dump file, read from its end (a run's dump grows with its rows)."""
    with open(path, "rb") as f:
        f.seek(0, os.SEEK_END)
        size = f.tell()
        chunk = 1 << 16
        while True:
            start = max(0, size - chunk)
            f.seek(start)
            text = f.read(size - start).decode()
            at = text.rfind("ITEM: TIMESTEP")
            if at >= 0 or start == 0:
                return parse_dump(text[max(at, 0):])
            chunk *= 4


def run_lmp(lmp, work, input_text, name="in.lmp"):
    """Run LAMMPS serially in work on an input; its log's figures (parse_log).  RuntimeError
    with the log's tail when it fails."""
    work = files.make_dirs(work)
    files.write_text(work / name, input_text)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    res = subprocess.run([lmp, "-in", name, "-log", "log.lammps", "-screen", "none", "-nocite"],
                         cwd=work, capture_output=True, text=True, env=env)
    log = (work / "log.lammps").read_text() if (work / "log.lammps").exists() else ""
    if res.returncode != 0:
        tail = "\n".join((log or res.stdout + res.stderr).splitlines()[-6:])
        raise RuntimeError(f"LAMMPS failed ({res.returncode}) in {work}:\n{tail}")
    return parse_log(log)


class Reader:
    """Frames of a LAMMPS run in ballast's conventions (trajectory.Frame)."""

    def __init__(self, scene, opts):
        self.scene, self.opts = scene, opts
        d = scene.discs
        self.n = len(d["x"])
        self.r = d["r"]
        self.mat = scene.disc_material
        self.held = scenes.held(scene)
        self.fixed = np.array([h == {"x", "y", "rotation"} for h in self.held])
        self.fixes = wall_fixes(scene, opts)
        self.beta, self.gamma_n = scene.number("beta"), scene.number("gamma_n")
        self.power = scene.setting("normal_law") == "power"
        self.nu, self.delta0 = scene.number("nu"), scene.number("delta0")
        self.dt = scene.dt
        # the pair laws as tables over material indices (pair_law: 2 k_a k_b/(k_a + k_b), ...)
        names = list(scene.materials)
        self.mat_index = np.array([names.index(m) for m in self.mat], dtype=int)
        laws = [[pair_law(scene, p, q) for q in names] for p in names]
        self.law_table = [np.array([[law[f] for law in row] for row in laws]) for f in range(4)]
        self.beyond = 0            # wall contacts found beyond a wall's end (beyond_end)
        self.unsplit = 0           # discs touching two walls with rolling at once (wall_rolling)
        # theta_r of each touching pair, summed from the half-step spins of every step (only when
        # the frames are every step: track_theta())
        self.theta, self.theta_step = None, None

    def track_theta(self):
        self.theta, self.theta_step = {}, 0

    def accumulate_theta(self, rows, hw, step):
        """theta_r = sum of (omega_a - omega_b)_{N-1/2} dt since the contact formed (JYH eqs
        12-13, as the core keeps it); a wall does not turn here (plan() refuses rolling
        against a turning wall).  Frames must come every step, in order."""
        if step != self.theta_step + 1:
            raise RuntimeError(f"theta_r needs every step: frame {step} after {self.theta_step}")
        now = {}
        c = rows
        for k in range(len(c["a"])):
            key = (int(c["a"][k]), int(c["b"][k]), int(c["wall"][k]))
            spin = hw[key[0]] - (0.0 if key[2] else hw[key[1]])
            now[key] = self.theta.get(key, 0.0) + spin * self.dt
            c["theta_r"][k] = now[key]
        self.theta, self.theta_step = now, step

    def law(self, ma, mb):
        return pair_law(self.scene, ma, mb)

    def elastic_normal(self, kn, delta):
        if self.power and self.nu != 1.0:
            return kn * self.delta0 * (delta / self.delta0) ** self.nu
        return kn * delta

    def mat_of_wall(self, wk):
        return list(self.scene.materials).index(self.scene.walls[wk].material)

    def frame(self, atoms, pairs, walls, gfac):
        """A Frame from one atoms frame and one pairs frame (dicts of columns), the walls'
        segments at that step (carried walls: where their carriers are, carriers()) and the
        ramp factor."""
        order = np.argsort(atoms["id"])
        A = {k: v[order][:self.n] for k, v in atoms.items() if k != "_step"}
        self.walls_now = walls
        self.carried_v = {k: (vx, vy) for k, (_, _, vx, vy) in carriers(self.scene, atoms).items()}
        if not np.array_equal(A["id"], np.arange(1, self.n + 1)):
            raise RuntimeError("LAMMPS lost or renumbered atoms")
        step = int(atoms["_step"])
        x, y, vx, vy, w = A["x"], A["y"], A["vx"], A["vy"], A["c_pa[1]"]
        mass, fx, fy, tq = A["mass"], A["fx"], A["fy"], A["c_pa[2]"]
        inertia = 0.5 * mass * self.r ** 2
        # the velocities the step's forces saw: v_{N-1/2} = v_N - dt/2 f_N / m (LAMMPS's masses)
        hx = np.where(self.fixed, 0.0, vx - 0.5 * self.dt * fx / mass)
        hy = np.where(self.fixed, 0.0, vy - 0.5 * self.dt * fy / mass)
        hw = np.where(self.fixed, 0.0, w - 0.5 * self.dt * tq / inertia)
        frame = getattr(self.opts, "frame", None)
        if frame is not None:
            # in the wall's frame (lammps_input.frame_wall(): every disc held): the wall-frame
            # contacts, then positions, points and forces rotated back into the lab; theta_r
            # sums the discs' spin in that frame, omega - omega_wall, which fix move held
            # constant through the step (no integration acts on them)
            to_lab = WallFrame(self.scene, self.stage_cycles, step, frame)
            rows = self.frame_contacts(A, x, y, tq, to_lab)
            x, y = to_lab.point(x, y)
            zero = np.zeros(self.n)
            contacts = contacts_of(rows)
            if self.theta is not None:
                self.accumulate_theta(contacts, w, step)
            return Frame(step, step * self.dt, x, y, zero, zero, zero.copy(), contacts, walls, gfac)
        for k, h in enumerate(self.held):
            if "x" in h:
                hx[k] = 0.0
            if "y" in h:
                hy[k] = 0.0
        vx, vy, w = (np.where(self.fixed, 0.0, v) for v in (vx, vy, w))
        discs = self.disc_contacts(pairs, x, y, (hx, hy, hw), (vx, vy, w))
        wall_rows = self.wall_contacts(A, x, y, hx, hy, hw, walls, step)
        self.wall_rolling(wall_rows, discs, tq, hw)
        contacts = concatenate(discs, contacts_of(wall_rows))
        if self.theta is not None:
            self.accumulate_theta(contacts, hw, step)
        return Frame(step, step * self.dt, x, y, vx, vy, w, contacts, walls, gfac)

    def dashpots(self, kn, ks, mu, ndot, sdot):
        eta = self.gamma_n + self.beta * kn
        return eta * ndot, (self.beta * ks * sdot if mu > 0 else 0.0)

    def disc_contacts(self, pairs, x, y, half, whole):
        """The disc-disc contacts of a pair/local frame, as contact columns (trajectory.py).
        LAMMPS applied its dashpots at the half-step velocities (half); compute pair/local's
        single() recomputes the forces with the dump's whole-step ones (whole), so the springs
        are its forces less the whole-step dashpots, and the dashpots reported are the
        half-step ones, as applied."""
        hx, hy, hw = half
        vx, vy, w = whole
        if not pairs or "c_pid[1]" not in pairs or not len(pairs["c_pid[1]"]):
            return empty_contacts()
        ii, jj = pairs["c_pid[1]"].astype(int) - 1, pairs["c_pid[2]"].astype(int) - 1
        a, b = np.minimum(ii, jj), np.maximum(ii, jj)
        r = self.r
        dx, dy = x[b] - x[a], y[b] - y[a]
        dist = np.hypot(dx, dy)
        delta = r[a] + r[b] - dist
        touch = delta > 0
        if not np.any(touch):
            return empty_contacts()
        sel = lambda v: v[touch]
        ii, jj, a, b, dx, dy, dist, delta = map(sel, (ii, jj, a, b, dx, dy, dist, delta))
        col = {k: sel(v) for k, v in pairs.items() if k != "_step"}
        ex, ey = dx / dist, dy / dist
        tx, ty = ey, -ex
        kn, ks, mu, droll = (t[self.mat_index[a], self.mat_index[b]] for t in self.law_table)
        fn = self.elastic_normal(kn, delta)
        flip = np.where(ii == a, 1.0, -1.0)            # p1, p2 are the tangential force on atom i
        ft_on_a = flip * (col["c_pl[3]"] * tx + col["c_pl[4]"] * ty)    # on a: -(fs + ds) along t
        rvx, rvy = hx[a] - hx[b], hy[a] - hy[b]
        ndot = rvx * ex + rvy * ey
        sdot = rvx * tx + rvy * ty - (hw[a] * r[a] + hw[b] * r[b])
        eta = self.gamma_n + self.beta * kn
        shear = mu > 0
        dn = eta * ndot
        ds = np.where(shear, self.beta * ks * sdot, 0.0)
        wvx, wvy = vx[a] - vx[b], vy[a] - vy[b]
        ds_whole = np.where(shear, self.beta * ks * (wvx * tx + wvy * ty - (w[a] * r[a] + w[b] * r[b])), 0.0)
        fn_total = np.abs(col["c_pl[2]"])
        sliding = shear & (np.abs(ft_on_a) >= mu * fn_total * (1 - CAP_ROUNDOFF)) & (np.abs(ft_on_a) > 0)
        ds = np.where(sliding, 0.0, ds)
        ds_whole = np.where(sliding, 0.0, ds_whole)
        arm = r[a] - delta / 2
        n = len(a)
        out = {"a": a, "b": b, "wall": np.zeros(n, dtype=int), "nx": ex, "ny": ey, "delta": delta,
               "px": x[a] + arm * ex, "py": y[a] + arm * ey, "fn": fn, "dn": dn,
               "fs": -ft_on_a - ds_whole, "ds": ds, "sliding": sliding.astype(int),
               "mr": np.zeros(n), "md": np.zeros(n), "theta_r": np.zeros(n), "rolling": np.zeros(n, dtype=int)}
        if np.any(droll > 0) and "c_pl[8]" in col:
            # the rolling pseudo-force on atom i (p5, p6); the couple on i is R_eff (n_i x F_roll),
            # n_i = (x_i - x_j)/|.| = -flip e, and a gets flip times i's: R_eff (-e x F_roll)
            r_eff = r[a] * r[b] / (r[a] + r[b])
            frx, fry = col["c_pl[7]"], col["c_pl[8]"]
            couple_a = r_eff * (-ex * fry + ey * frx)
            mu_m = eta * droll ** 2 / 3 * r_eff ** 2
            md, md_whole = mu_m * (hw[a] - hw[b]), mu_m * (w[a] - w[b])
            m0 = droll / 3 * r_eff * fn_total
            at_cap = (m0 > 0) & (np.abs(couple_a) >= m0 * (1 - CAP_ROUNDOFF))
            roll = droll > 0
            out["mr"] = np.where(roll, -couple_a - np.where(at_cap, 0.0, md_whole), 0.0)
            out["md"] = np.where(roll & ~at_cap, md, 0.0)
            out["rolling"] = (roll & at_cap).astype(int)
        return out

    def wall_touch(self, A, fid, i, x, y):
        """Disc i's contact with the wall of fix fid, from its columns: the contact point (cx, cy),
        the force on the disc (fx, fy), the centre-to-point vector (dx, dy), its length, the unit
        normal (ex, ey) towards the wall and the overlap r - dist."""
        cx, cy = A[f"f_{fid}[5]"][i], A[f"f_{fid}[6]"][i]
        fx, fy = A[f"f_{fid}[2]"][i], A[f"f_{fid}[3]"][i]      # the force on the disc
        dx, dy = cx - x[i], cy - y[i]
        dist = math.hypot(dx, dy)
        return cx, cy, fx, fy, dx, dy, dist, dx / dist, dy / dist, self.r[i] - dist

    def wall_contacts(self, A, x, y, hx, hy, hw, walls, step):
        rows = []
        for wk, fid in self.fixes:
            flag = A[f"f_{fid}[1]"]
            for i in np.flatnonzero(flag > 0):
                cx, cy, fx, fy, dx, dy, dist, ex, ey, delta = self.wall_touch(A, fid, i, x, y)
                wall = self.scene.walls[wk]
                kn, ks, mu, droll = self.law(self.mat[i], wall.material)
                fn = self.elastic_normal(kn, delta)
                tx, ty = ey, -ex
                fn_total = -(fx * ex + fy * ey)
                ft_total = -(fx * tx + fy * ty)
                wvx, wvy = self.wall_velocity(wk, cx, cy, step)
                rvx, rvy = hx[i] - wvx, hy[i] - wvy
                dn, ds = self.dashpots(kn, ks, mu, rvx * ex + rvy * ey, rvx * tx + rvy * ty - hw[i] * self.r[i])
                sliding = int(mu > 0 and abs(ft_total) >= mu * abs(fn_total) * (1 - CAP_ROUNDOFF)
                              and abs(ft_total) > 0)
                if sliding:
                    ds = 0.0
                at = 0.5 * (self.r[i] + dist)
                rows.append(dict(a=i, b=wk, wall=1, nx=ex, ny=ey, delta=delta, px=x[i] + at * ex,
                                 py=y[i] + at * ey, fn=fn, dn=fn_total - fn, fs=ft_total - ds, ds=ds,
                                 sliding=sliding, droll=droll, kn=kn, fn_total=fn_total,
                                 couple=self.r[i] * (ex * fy - ey * fx)))   # the wall fixes' lever: r
                self.beyond += self.beyond_end(walls[wk], cx, cy)
        return rows

    def arm(self, r, delta):
        """The lever of a disc-disc contact's tangential force about the disc's centre: r - delta/2
        in pair granular, r in gran/hooke/history (docs/engines.md, Dashpots).  A wall fix's lever
        is r in both (measured: harness/tests/data/rolling_floor.scene with friction)."""
        return r - 0.5 * delta if self.opts.granular else r

    def wall_rolling(self, rows, discs, tq, hw):
        """The rolling moments of the wall contacts with rolling resistance (in the lab; walls that
        do not turn: plan()).  The wall fix reports no torque, so a disc's rolling couple from its
        wall is its torque less the couples of its other contacts: each disc-disc contact's
        tangential force about the centre and its rolling couple (applied: with the half-step
        dashpots, -(mr + md) on a and +(mr + md) on b, as disc_contacts() reads them), and every
        wall contact's tangential force.  Then as disc_contacts(): mr the spring, md the dashpot
        mu_m omega below the cap, the cap when |M| reaches M_0 = (delta/3) R |F_n| (R_eff = r).
        A disc touching two walls with rolling at once cannot be split: counted in self.unsplit
        (the run fails with that message) and left at 0."""
        rolling = [row for row in rows if row["droll"] > 0]
        if not rolling:
            return
        other = np.zeros(self.n)
        if len(discs["a"]):
            a, b, delta = discs["a"], discs["b"], discs["delta"]
            ft_a = -(discs["fs"] + discs["ds"])
            couple = discs["mr"] + discs["md"]
            np.add.at(other, a, -self.arm(self.r[a], delta) * ft_a - couple)
            np.add.at(other, b, -self.arm(self.r[b], delta) * ft_a + couple)
        for row in rows:
            other[row["a"]] += row["couple"]
        count = {}
        for row in rolling:
            count[row["a"]] = count.get(row["a"], 0) + 1
        for row in rolling:
            i = row["a"]
            if count[i] > 1:
                self.unsplit += 1
                continue
            moment = tq[i] - other[i]                      # the wall's rolling couple on the disc
            droll, r = row["droll"], self.r[i]
            m0 = droll / 3 * r * abs(row["fn_total"])
            mu_m = (self.gamma_n + self.beta * row["kn"]) * droll ** 2 / 3 * r ** 2
            at_cap = bool(m0 > 0 and abs(moment) >= m0 * (1 - CAP_ROUNDOFF))
            md = 0.0 if at_cap else mu_m * hw[i]
            row.update(mr=-moment - md, md=md, rolling=int(at_cap))

    def frame_contacts(self, A, x, y, tq, to_lab):
        """The wall contacts of a run in the wall's frame (frictionless and undamped: plan()),
        rows in the lab.  Each held disc touches that wall only (held pairs are excluded), so its
        torque less the couple of the contact's force about its centre is the rolling couple
        (LAMMPS's rolling resistance adds a torque, no force): the disc gets -M, M = mr.  At the
        cap |M| = mu_roll R |F_n| (LAMMPS's Frcrit times R_eff = R against a plane)."""
        rows = []
        for wk, fid in self.fixes:
            flag = A[f"f_{fid}[1]"]
            for i in np.flatnonzero(flag > 0):
                cx, cy, fx, fy, dx, dy, dist, ex, ey, delta = self.wall_touch(A, fid, i, x, y)
                wall = self.scene.walls[wk]
                kn, _, _, droll = self.law(self.mat[i], wall.material)
                fn = self.elastic_normal(kn, delta)
                fn_total = -(fx * ex + fy * ey)
                ft_total = -(fx * ey - fy * ex)
                mr = -(tq[i] - (dx * fy - dy * fx))
                m0 = droll / 3 * self.r[i] * abs(fn_total)
                at_cap = int(droll > 0 and m0 > 0 and abs(mr) >= m0 * (1 - CAP_ROUNDOFF))
                at = 0.5 * (self.r[i] + dist)
                nx, ny = to_lab.vector(ex, ey)
                px, py = to_lab.point(x[i] + at * ex, y[i] + at * ey)
                rows.append(dict(a=i, b=wk, wall=1, nx=nx, ny=ny, delta=delta, px=px, py=py, fn=fn,
                                 dn=fn_total - fn, fs=ft_total, ds=0.0, sliding=0, mr=mr, md=0.0,
                                 rolling=at_cap))
                self.beyond += self.beyond_end(self.walls_now[wk], *to_lab.point(cx, cy))
        return rows

    def wall_velocity(self, wk, cx, cy, step):
        """The velocity of wall wk's point (cx, cy) in the stage that holds step: V + omega x (c - P)
        (a carried wall: its carrier's velocity, the one it moved with into this step)."""
        if wk in getattr(self, "carried_v", {}):
            return self.carried_v[wk]
        name = self.scene.walls[wk].name
        n0 = 0
        for stage in self.stage_cycles:
            n_end = n0 + stage[1]
            if n0 < step <= n_end:
                for c in stage[0].controls:
                    if c.kind == "move" and c.wall == name:
                        v1, v2, om = c.numbers(3)
                        px, py = self.pivots[wk]
                        return v1 - om * (cy - py), v2 + om * (cx - px)
                return 0.0, 0.0
            n0 = n_end
        return 0.0, 0.0

    @staticmethod
    def beyond_end(seg, cx, cy):
        ax, ay, bx, by = seg
        length = math.hypot(bx - ax, by - ay)
        s = ((cx - ax) * (bx - ax) + (cy - ay) * (by - ay)) / length
        tol = WALL_END_ROUNDOFF * length
        return int(s < -tol or s > length + tol)


def carriers(scene, atoms):
    """{wall index: (dx, dy, vx, vy)} of the carried walls (lammps_input.controlled_walls()) in
    one atoms frame: the carrier's displacement from the wall's midpoint and its velocity."""
    carried = controlled_walls(scene)
    if not carried:
        return {}
    n = len(scene.discs["x"])
    ids = atoms["id"].astype(int)
    out = {}
    for j, k in enumerate(carried):
        row = np.flatnonzero(ids == n + j + 1)
        if not len(row):
            raise RuntimeError(f"LAMMPS lost the carrier atom of wall {scene.walls[k].name}")
        r = row[0]
        mx, my = midpoint(scene.walls[k])
        out[k] = (atoms["x"][r] - mx, atoms["y"][r] - my, atoms["vx"][r], atoms["vy"][r])
    return out


def walls_at(scene, schedule, step, atoms=None):
    """Every wall's segment (ax, ay, bx, by) after `step` cycles: moved by each stage's velocity
    for its cycles and turned about its (moving) pivot (ballast's `move`); a carried wall
    translated by its carrier's displacement in the atoms frame of that step. schedule: (stage,
    its actual cycles) in order."""
    out = []
    carried = carriers(scene, atoms) if atoms is not None else {}
    for k, w in enumerate(scene.walls):
        if k in carried:
            dx, dy = carried[k][:2]
            out.append((w.ax + dx, w.ay + dy, w.bx + dx, w.by + dy))
            continue
        px, py = pivot(scene, w)
        dx, dy, th = wall_motion(scene, schedule, step, w)
        cs, sn = math.cos(th), math.sin(th)

        def move(qx, qy):
            rx, ry = qx - px, qy - py
            return px + dx + cs * rx - sn * ry, py + dy + sn * rx + cs * ry
        out.append(move(w.ax, w.ay) + move(w.bx, w.by))
    return out


class WallFrame:
    """The map from the frame of wall k (lammps_input.frame_wall()) back to the lab at one step:
    a point q' goes to P0 + d + R(theta)(q' - P0), a vector f' to R(theta) f'."""

    def __init__(self, scene, schedule, step, k):
        self.px, self.py = pivot(scene, scene.walls[k])
        self.dx, self.dy, th = wall_motion(scene, schedule, step, scene.walls[k])
        self.c, self.s = math.cos(th), math.sin(th)

    def vector(self, fx, fy):
        return self.c * fx - self.s * fy, self.s * fx + self.c * fy

    def point(self, qx, qy):
        rx, ry = self.vector(qx - self.px, qy - self.py)
        return self.px + self.dx + rx, self.py + self.dy + ry


def gfac_at(scene, schedule, step):
    n0 = 0
    for stage, cycles in schedule:
        if n0 < step <= n0 + cycles and stage.number("ramp"):
            return (step - n0) / stage.cycles
        n0 += cycles
    return 1.0


def row_steps(scene, schedule, every):
    """The cycles of ballast's series rows (sim.c): every `every`-th (output_every, or the
    plan's thinned spacing), each stage's last (or the one its stop rule ended it at) when it
    has output_at_end or is the last stage."""
    total = sum(c for _, c in schedule)
    rows = set(range(every, total + 1, every))
    n0 = 0
    for g, (stage, cycles) in enumerate(schedule):
        n0 += cycles
        if cycles > 0 and (g == len(schedule) - 1 or float(stage.keys["output_at_end"])):
            rows.add(n0)
    if total:
        rows.add(total)
    return sorted(rows)


def stops_path(work):
    return Path(work) / "stops.json"


def read_stops(work):
    p = stops_path(work)
    return json.loads(p.read_text()) if p.exists() else {}


def checks_path(work):
    return Path(work) / "checks.json"


def read_checks(work):
    """{stage: the values its rule's last check measured} (stop_check())."""
    p = checks_path(work)
    return json.loads(p.read_text()) if p.exists() else {}


def finite_or_none(x):
    """A check's value for JSON: the core writes a non-finite one as null (output.c json_number)."""
    return float(x) if math.isfinite(x) else None


def stage_log(stage, record):
    """A stage's record in run.json as the core writes it (core/output.c): the values its rule's
    last check measured, -1 where it never checked, null where a value was not finite; the
    servo and unbalanced rules' entries only where the stage has them."""
    out = {"ke_over_ee": record.get("ke_over_ee", -1), "stress_change": record.get("stress_change", -1)}
    if stage.number("stop_servo") > 0:
        out.update(stop_servo=stage.number("stop_servo"), servo_error=record.get("servo_error", -1))
    if stage.number("stop_unbalanced") > 0:
        out.update(stop_unbalanced=stage.number("stop_unbalanced"), unbalanced=record.get("unbalanced", -1))
    return out


_STOP_STATE = {}


def stop_check(work, stage):
    """A stop rule's check on the run's last dumped state (called by LAMMPS through its PYTHON
    package, stage_lines()): 1 when the stage's rule is met (recorded in stops.json), else 0.
    The rule is the core's (sim.c, stop_rule_met): E_k <= stop_ke E_el, the disc stresses'
    largest change since the last check <= stop_stress of the largest (never at the first
    check), the unbalanced-force ratio <= stop_unbalanced."""
    work = Path(work)
    state = _STOP_STATE.get(str(work))
    if state is None:
        with open(work / "context.pickle", "rb") as f:
            ctx = pickle.load(f)
        state = _STOP_STATE[str(work)] = {"ctx": ctx, "prev": {}}
    scene, opts = state["ctx"]["scene"], state["ctx"]["options"]
    atoms = last_frame(work / "atoms.dump")
    pairs = last_frame(work / "pairs.dump")
    stage = int(stage)
    stops = read_stops(work)
    schedule = schedule_of(scene, stops)
    reader = Reader(scene, opts)
    reader.stage_cycles = schedule
    reader.pivots = [pivot(scene, w) for w in scene.walls]
    step = int(atoms["_step"])
    frame = reader.frame(atoms, pairs, walls_at(scene, schedule, step, atoms), gfac_at(scene, schedule, step))
    m = Measure(scene, frame, Laws(scene), Bodies(scene))
    st = scene.stages[stage]
    ee = m.elastic()
    ratio = m.kinetic() / ee if ee > 0 else math.inf
    met = st.number("stop_ke") <= 0 or ratio <= st.number("stop_ke")
    record = {"ke_over_ee": finite_or_none(ratio)}
    if st.number("stop_stress") > 0:
        mom = m.moments()
        prev = state["prev"].get(stage)
        state["prev"][stage] = mom
        if prev is None:
            met = False
            record["stress_change"] = None                 # the core's INFINITY at the first check
        else:
            size = float(np.max(np.abs(mom)))
            change = float(np.max(np.abs(mom - prev))) / size if size > 0 else math.inf
            met = met and change <= st.number("stop_stress")
            record["stress_change"] = finite_or_none(change)
    if st.number("stop_servo") > 0:
        errors = [abs(sigma - target) / target if sigma != 0 else math.inf
                  for sigma, target in servo_stresses(scene, frame, st)]
        met = met and max(errors, default=0.0) <= st.number("stop_servo")
        record["servo_error"] = finite_or_none(max(errors, default=0.0))
    if st.number("stop_unbalanced") > 0:
        unbalanced = m.unbalanced()
        met = met and unbalanced <= st.number("stop_unbalanced")
        record["unbalanced"] = finite_or_none(unbalanced)
    checks = read_checks(work)
    checks[str(stage)] = record
    files.write_text(checks_path(work), json.dumps(checks))
    if met:
        stops[str(stage)] = step
        files.write_text(stops_path(work), json.dumps(stops))
    return 1 if met else 0


def servo_stresses(scene, frame, stage):
    """(sigma, sigma_t) of each servo wall of a stage in a frame, as the core's servo measures it
    (core/walls.c): the springs' normal forces of the wall's contacts over its span gap(A, B)."""
    out = []
    names = {w.name: k for k, w in enumerate(scene.walls)}
    c = frame.contacts
    for line in stage.controls:
        if line.kind != "servo":
            continue
        k = names[line.wall]
        rows = (c["wall"] == 1) & (c["b"] == k)
        force = float(np.sum(c["fn"][rows]))
        span = wall_gap(frame.walls[names[line.words[3]]], frame.walls[names[line.words[4]]])
        out.append((force / span if span > 0 else 0.0, line.numbers(1)[0]))
    return out


def schedule_of(scene, stops):
    """(stage, cycles it ran) in order: a stage a stop rule ended ran up to its stop step."""
    out, n0 = [], 0
    for g, stage in enumerate(scene.stages):
        cycles = stage.cycles
        if str(g) in stops:
            cycles = int(stops[str(g)]) - n0
        out.append((stage, cycles))
        n0 += cycles
    return out


def trajectory_of(scene, opts, work, log):
    """The run's Trajectory from its dumps (frames at ballast's row cycles) and stops.json."""
    work = Path(work)
    stops = read_stops(work)
    schedule = schedule_of(scene, stops)
    reader = Reader(scene, opts)
    reader.stage_cycles = schedule
    reader.pivots = [pivot(scene, w) for w in scene.walls]
    if any(m.rolling > 0 for m in scene.materials.values()) and opts.every == 1:
        reader.track_theta()
    atoms = {f["_step"]: f for f in parse_frames((work / "atoms.dump").read_text())}
    pairs = {f["_step"]: f for f in parse_frames((work / "pairs.dump").read_text())}
    total = sum(c for _, c in schedule)
    frames = []
    wanted = row_steps(scene, schedule, opts.every)
    missing = [s for s in wanted if s not in atoms]
    if missing:
        raise RuntimeError(f"LAMMPS wrote no state at cycle(s) {missing[:5]} of the series rows")
    for step in wanted:
        f = reader.frame(atoms[step], pairs.get(step, {}), walls_at(scene, schedule, step, atoms[step]),
                         gfac_at(scene, schedule, step))
        frames.append(f)
    final = frames[-1] if frames and frames[-1].step == total else reader.frame(
        atoms[max(atoms)], pairs.get(max(atoms), {}), walls_at(scene, schedule, max(atoms), atoms[max(atoms)]), 1.0)
    beyond = reader.beyond
    checks = read_checks(work)
    stages = [{"name": s.name, "cycles": c, "max_cycles": s.cycles, "stop_rule": _stop_rule(s),
               "stopped": str(g) in stops, **stage_log(s, checks.get(str(g), {}))}
              for g, (s, c) in enumerate(schedule)]
    notes = {"lammps_log": {k: log[k] for k in ("version", "builds", "dangerous")},
             "pair_style": "granular" if opts.granular else "gran/hooke/history",
             "atom_types": len(opts.types)}
    if beyond:
        notes["failure"] = (f"{beyond} wall contact(s) beyond a wall's end: LAMMPS's plane is infinite, "
                            "ballast's wall a segment")
    if reader.unsplit:
        notes["failure"] = (f"{reader.unsplit} wall contact(s) with rolling resistance of a disc touching two such "
                            "walls at once: LAMMPS's wall fixes report no torque, and the disc's torque cannot "
                            "be split between them")
    if log["dangerous"] > 0:
        notes["failure"] = f"{log['dangerous']} dangerous neighbour-list builds in LAMMPS"
    return Trajectory(frames, final, stages, total, log["total_seconds"], notes)
