"""harness/engines/lammps.py -- the LAMMPS adapter: ballast's scenes as LAMMPS inputs, LAMMPS's
runs as ballast's outputs.  The one translation of a ballast scene into LAMMPS in the harness:
the cross-checks of harness/peer (check.py, rolling.py, race.py) write their scenes and run
them through translate() too.

Debian's `lammps` (29 Sep 2021, update 2; installed with apt-get when `lmp` is missing,
install_lammps()), run serially as `lmp -in in.lmp`.  docs/engines.md derives every mapping;
in short (plan() says per scene which apply, and refuses the rest):

  discs        atom_style sphere, 2D, fix nve/sphere disc: m = density pi r^2, I = m r^2/2;
               held discs (fixed = 1) are left out of the integration (their forces still
               computed), `hold = x`/`y` is fix setforce on that component
  time         velocity Verlet is ballast's centred scheme (C&S eqs 22-23): the same positions
               and, at whole steps, the same velocities; LAMMPS starts from v_0, ballast from
               v_{1/2}, so the initial velocities are v_{1/2} - dt/2 a_0 with a_0 LAMMPS's own
               forces at t = 0 (a `run 0`)
  normal law   power, nu = 1: F = k_n delta (hooke); power, nu = 3/2: F = k_n delta0^-1/2
               delta^3/2 = k_L a delta with a = sqrt(R_eff delta), so k_L = k_n / sqrt(delta0
               R_eff) per type pair (hertz); incremental (C&S): hooke, approximate
  dashpots     gamma_n (psi = 0) and beta k_n: pair granular `damping velocity`, eta_n
               constant (not scaled by the effective mass, as gran/hooke's gamma_n is);
               beta k_s: x_gamma = beta k_s / eta_n
  friction     tangential linear_history k_s, mu (gran/hooke/history when nothing else needs
               pair granular: its arm is r, as ballast's; pair granular's is r - delta/2)
  rolling      JYH Model 1 as `rolling sds` (harness/peer/rolling.py's mapping)
  global damp. C&S eqs 35-36 exactly: masses and inertias times s = 1 + alpha dt/2, gravity
               over s, and the drags -alpha m v, -alpha I omega at the half step (fix langevin
               at T = 0 with omega, whose translational drag fix addforce trims)
  walls        region plane + fix wall/gran/region per wall and disc material, moved and
               turned by equal-style variables of the step (ballast's `move`)
  stop rules   checked every check_every steps by the same Python that writes the outputs,
               inside LAMMPS (its PYTHON package), on LAMMPS's state

The run's state comes back through two dumps written at ballast's series rows (every
output_every steps and at each stage's end): per atom x, v, omega, f, torque and each wall
fix's contact (flag, force, point); per pair (compute pair/local) the normal and tangential
forces and the rolling pseudo-force.  read_frame() turns them into a Frame in ballast's
conventions (trajectory.py): the elastic forces from the overlap by the law, the dashpots
from the velocities LAMMPS's forces saw (v_{N-1/2} = v_N - dt/2 f_N/m, which LAMMPS's second
half kick inverts exactly).
"""
import hashlib
import json
import math
import os
import pickle
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np

from .. import REPO_ROOT, files
from .interface import APPROXIMATE, EXACT, REFUSED, Engine, Plan
from .outputs import Bodies, Laws, Measure
from . import scene as scenes
from .trajectory import Frame, Trajectory, concatenate, contacts_of, empty_contacts

LMP = "lmp"
# apt-get's command line for LAMMPS (a test gives another to see the skip path).
INSTALL = ("apt-get", "install", "-y", "-qq", "--no-install-recommends", "lammps")
HERE = Path(__file__).resolve().parent
STYLES = ("gran/hooke/history", "granular", "wall/gran/region")
# LAMMPS's fix langevin takes a rotational drag of SINERTIA m r^2 / damp (a sphere's 0.4); a
# disc's I is m r^2 / 2, so the drag -alpha I omega needs 1/damp = (0.5/0.4) alpha / s.
LANGEVIN_SINERTIA = 0.4
# Hertz needs one atom type per radius (k_L depends on R_eff): more radii than this and the
# pair table (n^2/2 coefficients) is no longer a translation worth making.
MAX_TYPES = 64
# A contact at the Coulomb (or rolling) cap: |F_s| >= mu |F_n| to this relative round-off.
CAP_ROUNDOFF = 1e-9
# The wall's plane is infinite, ballast's wall a segment: a contact point this far (relative
# to the wall's length) beyond an end is a contact ballast would not have made.
WALL_END_ROUNDOFF = 1e-9
# Passes of start_lines()'s fixed-point iteration for v_0: each divides the error by at least
# 1/(dt/2 |da/dv|) >= 2 at a stable step (dt/2 eta/m <= zeta dt omega/2 < 1/2 for the catalogue's
# damping ratios zeta <= 0.5), so 60 passes leave 2^-60 of the first correction, below round-off.
START_PASSES = 60
# The adapter reads a run through dumps of every disc and contact at each series row: at most this
# many disc-rows (about 100 MB of dumps with their contacts) before the rows are thinned (plan()).
DUMP_BUDGET = 1e6
# How many checks a stop rule is taken to need when the rows are thinned (the piles come to rest
# within 7-30 checks of 500 cycles in ballast; the count only sets the thinning, not the run).
STOP_CHECKS_GUESS = 20
SEED = 1                   # fix langevin's seed: at T = 0 its random force is 0 x random


def fmt(v):
    """A float written so that strtod reads back the same double."""
    return repr(float(v))


# ---------------------------------------------------------------------------------- LAMMPS itself

def install_lammps(install):
    """Run the command line install (apt-get install lammps), after an apt-get update if the
    first try fails (a machine that never ran one has no package lists); '' when it worked,
    else why not."""
    print("engines: installing LAMMPS (apt-get install lammps)", flush=True)
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


def lammps_problem(lmp=LMP, install=INSTALL, styles=STYLES):
    """Why LAMMPS cannot run ('' when it can), installing it first when lmp is missing: not
    installed and the install failed, or no `lmp -h` listing these styles of the GRANULAR
    package (pair or fix styles)."""
    if shutil.which(lmp) is None:
        failed = install_lammps(install)
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


# ---------------------------------------------------------------------------------- the plan

class Options:
    """What translate() chooses for a scene: the pair style, the atom types, the global
    damping's scale, the neighbour settings, and what the dumps hold."""

    def __init__(self, scene, granular, hertz, skin=None, binsize=0.0, nsq=False, dumps=True,
                 sort_every=0, sort_binsize=0.0):
        self.granular, self.hertz = granular, hertz
        r = scene.discs["r"]
        self.skin = 0.2 * float(r.max()) if skin is None else skin     # ballast's default skin
        self.binsize, self.nsq, self.dumps = binsize, nsq, dumps
        self.sort_every, self.sort_binsize = sort_every, sort_binsize
        self.alpha = scene.number("alpha")
        self.every = int(float(scene.setting("output_every")))     # the dumps' row spacing (plan())
        self.scale = 1 + self.alpha * scene.dt / 2                       # s = 1 + alpha dt/2
        keys = []
        for k, mat in enumerate(scene.disc_material):
            key = (mat, float(r[k]) if hertz else None)
            if key not in keys:
                keys.append(key)
        self.types = keys                                                # type t+1 = keys[t]
        self.type_of = [keys.index((mat, float(r[k]) if hertz else None)) + 1
                        for k, mat in enumerate(scene.disc_material)]


def normal_mapping(scene, plan):
    """The normal law's Feature; (hertz?, refused?)."""
    law = scene.setting("normal_law")
    if law == "incremental":
        plan.add("normal law: incremental (C&S eqs 14, 16, 18)", APPROXIMATE,
                 "hooke, F_n = k_n delta: the same force for a contact that forms at zero overlap and "
                 "turns no faster than its normal (sum of k_n n' dt = k_n delta); otherwise they differ "
                 "by k_n times the first step's penetration beyond touching and by the turning of the "
                 "normal (second order in the step)")
        return False
    nu = scene.number("nu")
    if nu == 1.0:
        plan.add("normal law: power, nu = 1", EXACT, "hooke k_n (F = k_n delta0 (delta/delta0) = k_n delta)")
        return False
    if nu == 1.5:
        plan.add("normal law: power, nu = 3/2", EXACT,
                 "hertz k_n / sqrt(delta0 R_eff) per type pair (F = k_n delta0^-1/2 delta^3/2 = "
                 "k_L sqrt(R_eff delta) delta); one atom type per radius")
        return True
    plan.add(f"normal law: power, nu = {nu:g}", REFUSED,
             "LAMMPS's normal models are hooke (nu = 1) and hertz (nu = 3/2, with sqrt(R_eff)); no "
             "other exponent")
    return False


class Lammps(Engine):
    """The LAMMPS adapter (the module docstring)."""
    name = "lammps"
    title = "LAMMPS"

    def __init__(self, lmp=LMP, install=INSTALL):
        self.lmp, self.install = lmp, install

    def problem(self):
        return lammps_problem(self.lmp, self.install)

    def version(self):
        try:
            text = subprocess.run([self.lmp, "-h"], capture_output=True, text=True).stdout
        except OSError:
            return ""
        m = re.search(r"Large-scale Atomic/Molecular Massively Parallel Simulator - (.*)", text)
        return m.group(1).strip() if m else ""

    def identity(self):
        exe = shutil.which(self.lmp)
        out = {"lmp": exe, "lmp_sha256": _sha256(exe) if exe else None}
        for p in sorted(HERE.glob("*.py")):
            out[str(p)] = _sha256(p)
        return out

    # ---- what maps -----------------------------------------------------------------------

    def plan(self, scene, command, **options):
        """The Plan of scene under command ('run' or 'exact'); options go to Options."""
        plan = Plan()
        if command == "exact":
            plan.add("command: exact (ballast's static solver)", REFUSED,
                     "an exact static solve of the contact network is ballast's own; LAMMPS integrates "
                     "the equations of motion and has no static solver")
            return plan
        integ = scene.setting("integrator")
        if integ == "gear5":
            plan.add("integrator: gear5", REFUSED, "LAMMPS's granular integrators are velocity Verlet only")
        else:
            plan.add(f"integrator: {integ}", EXACT,
                     "velocity Verlet (fix nve/sphere disc): the centred scheme's positions and whole-step "
                     "velocities; the start taken from ballast's v_1/2 (v_0 = v_1/2 - dt/2 a_0)"
                     if integ == "centred" else "velocity Verlet from v_0, as ballast's verlet")
        hertz = normal_mapping(scene, plan)
        gamma_n, psi, beta = scene.number("gamma_n"), scene.number("psi"), scene.number("beta")
        damped = gamma_n > 0 or beta > 0
        if gamma_n > 0 and psi != 0:
            plan.add(f"viscous normal damping gamma_n (delta/delta0)^psi, psi = {psi:g}", REFUSED,
                     "pair granular's damping models are constant (velocity), mass-scaled, "
                     "viscoelastic (a m_eff) or Tsuji: none is gamma_n (delta/delta0)^psi for psi != 0")
        elif damped:
            plan.add("contact dashpots (gamma_n, beta k_n, beta k_s)", EXACT,
                     "pair granular `damping velocity`: eta_n = gamma_n + beta k_n and x_gamma = beta k_s / "
                     "eta_n, constant per pair (gran/hooke's gamma_n would scale with m_eff); while a "
                     "contact slides LAMMPS caps spring + dashpot at mu |F_n + D_n|, ballast the spring "
                     "at mu F_n with no shear dashpot: the same while nothing slides")
        mats = scene.materials
        if any(m.cohesion > 0 for m in mats.values()):
            plan.add("cohesion", REFUSED, "LAMMPS's tangential models have no cohesion c in the Coulomb cap")
        friction = any(m.friction > 0 for m in mats.values())
        rolling = any(m.rolling > 0 for m in mats.values())
        if friction:
            plan.add("friction (incremental shear spring k_s, Coulomb cap)", APPROXIMATE,
                     "tangential linear_history k_s mu: LAMMPS keeps the shear displacement as a vector "
                     "and projects it on the new tangent plane each step, which shortens it by "
                     "cos(d theta); ballast turns the scalar F_s with the tangent: O(dt) (peer_check)"
                     + ("; pair granular applies F_s at r - delta/2, ballast at r: O(delta/r)"
                        if damped or rolling or hertz else ""))
        if rolling:
            model = scene.setting("rolling_model")
            if model == "model2":
                plan.add("rolling resistance: JYH Model 2 (elasto-brittle)", REFUSED,
                         "LAMMPS's rolling sds is elastic-plastic (Model 1); no model loses its "
                         "resistance for good when the moment passes M_0")
            else:
                plan.add("rolling resistance: JYH Model 1", EXACT,
                         "rolling sds k_roll = k_n delta^2/3, mu_roll = delta/3, gamma_roll = mu_n "
                         "delta^2/3 (harness/peer/rolling.py): exact below the cap and at it without "
                         "damping; neighbour lists all pairs, unsorted (a LAMMPS defect negates the "
                         "rolling history of a pair stored from its other side)")
                if hertz:
                    plan.add("rolling with the Hertz law", REFUSED,
                             "JYH's K_m = K_n B^2/12 takes ballast's power-law k_n; LAMMPS's k_roll "
                             "is a constant, not the Hertz tangent")
        alpha = scene.number("alpha")
        if alpha > 0:
            if integ != "centred":
                plan.add(f"global damping with the {integ} integrator", REFUSED,
                         "mapped for the centred scheme only (C&S eqs 35-36)")
            else:
                plan.add(f"global damping alpha = {alpha:g} (C&S eqs 34-36)", EXACT,
                         "m, I times s = 1 + alpha dt/2, gravity over s, and -alpha m v, -alpha I omega at "
                         "the half step: fix langevin at T = 0 with omega (damp = s/(1.25 alpha)) and fix "
                         "addforce +alpha m v/4 for the translational excess")
        held = scenes.held(scene)
        if any(h and h != {"x", "y", "rotation"} and "rotation" in h for h in held):
            plan.add("hold = rotation of a free disc", REFUSED,
                     "fix setforce holds force components, not a single disc's rotation")
        elif any(held):
            plan.add("held discs", EXACT, "out of fix nve/sphere (fixed = 1); fix setforce for x or y; "
                                          "pairs of two held discs excluded, as in ballast")
        gx, gy = scene.gravity()
        if gx or gy:
            ramps = [s.name for s in scene.stages if s.number("ramp")]
            plan.add("gravity" + (" with a ramp" if ramps else ""), EXACT,
                     "fix gravity with an equal-style magnitude: |g| gfac / s, gfac = (N - N0)/C in a "
                     "ramp stage (the core's (c + 1)/C)" if ramps else "fix gravity |g| / s")
        self._walls(scene, plan, rolling)
        self._stages(scene, plan)
        if scene.number("stress_width") > 0:
            plan.add("stress_grid.tsv (moving-average cells)", APPROXIMATE,
                     "not written: no check of the catalogue reads it")
        if len(scene.walls) and hertz:
            plan.add("Hertz contacts with a wall", REFUSED,
                     "fix wall/gran takes one coefficient set per fix, k_L depends on each radius")
        granular = damped or rolling or hertz
        opts = Options(scene, granular, hertz, nsq=rolling, **options)
        if len(opts.types) > MAX_TYPES:
            plan.add(f"{len(opts.types)} atom types", REFUSED,
                     f"more than {MAX_TYPES} (material, radius) classes for per-pair Hertz coefficients")
        plan.options["lammps"] = opts
        n = len(scene.discs["x"])
        # a stage a stop rule may end early counts as STOP_CHECKS_GUESS checks of its rule
        cycles = sum(min(st.cycles, STOP_CHECKS_GUESS * int(float(st.keys["check_every"])))
                     if _stop_rule(st) else st.cycles for st in scene.stages)
        rows = cycles / opts.every
        if n * rows > DUMP_BUDGET:
            thin = math.ceil(n * rows / DUMP_BUDGET)
            opts.every *= thin
            plan.add(f"series rows every {opts.every // thin} cycles", APPROXIMATE,
                     f"written every {opts.every} cycles (and at each stage's end) instead: the adapter "
                     f"reads LAMMPS's state through dumps of every disc and contact, and {n} discs x "
                     f"{rows:.0f} rows is more than {DUMP_BUDGET:.0e} disc-rows; a check over the whole "
                     "series sees these rows, one of its last row or final state the same")
        if rolling:
            every = opts.every
            for p in scene.probes:
                if p.quantity == "contact_theta_r" and every != 1:
                    plan.unexpressible[p.name] = ("theta_r is summed from the spins of every step; "
                                                  "this scene writes a row every " f"{every} steps")
        return plan

    def _walls(self, scene, plan, rolling):
        for k, w in enumerate(scene.walls):
            side = wall_side(scene, w)
            if side == 0:
                plan.add(f"wall {w.name} with discs on both sides", REFUSED,
                         "a LAMMPS region wall acts on one side")
        turning = {c.wall for s in scene.stages for c in s.controls if c.kind == "move"
                   and c.numbers(3)[2] != 0}
        for name in sorted(turning):
            if name not in scene.wall_sections:
                plan.add(f"turning wall {name} (generated)", REFUSED,
                         "its pivot P is the generator's; only [wall] sections give it")
            if rolling:
                plan.add(f"rolling against turning wall {name}", REFUSED,
                         "fix wall/gran's rolling displacement takes the particle's spin only, not the "
                         "wall's: ballast's theta_r = int (omega - omega_wall) dt has no counterpart")
        controls = {c.kind for s in scene.stages for c in s.controls}
        if "servo" in controls:
            plan.add("servo-controlled walls (stress target)", REFUSED,
                     "a region wall moves by an equal-style variable of the step; a servo needs the "
                     "wall's position to integrate a velocity computed from its own contact forces each "
                     "step, which LAMMPS's variables cannot hold (no state between steps) -- it would "
                     "take a fix of its own or a driver through the library interface")
        if "strain_rate" in controls:
            plan.add("strain-rate walls (logarithmic strain)", REFUSED,
                     "the rate x the current gap is a feedback of the state like a servo's")
        if scene.walls:
            moving = any(c.kind == "move" for s in scene.stages for c in s.controls)
            plan.add("walls" + (" moved and turned by stages" if moving else ""), EXACT,
                     "region plane + fix wall/gran/region (one per wall and disc material, ballast's "
                     "pair law 2 k_a k_b/(k_a + k_b)); move: displacement and angle as equal-style "
                     "variables of the step; the plane is infinite, ballast's wall a segment: each "
                     "contact is checked to lie within the wall's ends")

    def _stages(self, scene, plan):
        for s in scene.stages:
            if s.number("stop_servo") > 0:
                plan.add(f"stage {s.name}: stop_servo", REFUSED, "no servo walls (above)")
            if s.number("stop_ke") > 0 or s.number("stop_stress") > 0 or s.number("stop_unbalanced") > 0:
                plan.add(f"stage {s.name}: stop rule", EXACT,
                         "checked every check_every steps inside LAMMPS (its PYTHON package) by "
                         "harness/engines on LAMMPS's state, with the core's definitions")
        moving_stop = any((s.number("stop_ke") > 0 or s.number("stop_stress") > 0) and
                          any(c.kind == "move" for c in s.controls) for s in scene.stages)
        if moving_stop:
            plan.add("walls moving in a stage with a stop rule", EXACT,
                     "each stage's motion starts from the displacement LAMMPS reached")

    # ---- the run ---------------------------------------------------------------------------

    def simulate(self, scene, plan, work):
        work = files.make_dirs(work)
        opts = plan.options["lammps"]
        files.write_text(work / "data.lmp", data_text(scene, opts))
        with open(work / "context.pickle", "wb") as f:
            pickle.dump({"scene": scene, "options": opts}, f)
        text = translate(scene, opts, work)
        log = run_lmp(self.lmp, work, text)
        trajectory = trajectory_of(scene, opts, work, log)
        if not os.environ.get("BALLAST_KEEP_DUMPS"):
            # read whole into the run's files; the dumps are the bulk of a run folder
            for name in ("atoms.dump", "pairs.dump", "start.dump"):
                (work / name).unlink(missing_ok=True)
        return trajectory


def _sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


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


# ---------------------------------------------------------------------------------- translation

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
    out = [f"LAMMPS data file written by harness/engines/lammps.py from {scene.path}", "",
           f"{n} atoms", f"{len(opts.types)} atom types", "",
           f"{fmt(min(xs) - margin)} {fmt(max(xs) + margin)} xlo xhi",
           f"{fmt(min(ys) - margin)} {fmt(max(ys) + margin)} ylo yhi", "-0.5 0.5 zlo zhi", "",
           "Atoms # sphere", ""]
    for k in range(n):
        rho = scene.materials[scene.disc_material[k]].density * opts.scale
        out.append(f"{k + 1} {opts.type_of[k]} {fmt(2 * r[k])} {fmt(rho)} {fmt(x[k])} {fmt(y[k])} 0")
    out += ["", "Velocities", ""]
    out += [f"{k + 1} {fmt(d['vx'][k])} {fmt(d['vy'][k])} 0 0 0 {fmt(d['omega'][k])}" for k in range(n)]
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
    L.append("group           held id " + _ids(fixed) if fixed else "group           held empty")
    L.append("group           free subtract all held")
    for t, (mat, _) in enumerate(opts.types):
        L.append(f"group           t{t + 1} type {t + 1}")
    style = "nsq" if opts.nsq else "bin"
    L.append(f"neighbor        {fmt(opts.skin)} {style}")
    L.append("neigh_modify    delay 0 every 1 check yes"
             + (f" binsize {fmt(opts.binsize)}" if opts.binsize and not opts.nsq else "")
             + (" exclude group held held" if fixed else ""))
    L += pair_lines(scene, opts)
    L.append(f"timestep        {fmt(dt)}")
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
    moves = moving_walls(scene)
    for k, w in enumerate(scene.walls):
        side = wall_side(scene, w)
        (qx, qy), (ex, ey) = wall_line(scene, w)
        nx, ny = -ey * side, ex * side
        motion = ""
        if w.name in moves:
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


def moving_walls(scene):
    return {c.wall for s in scene.stages for c in s.controls if c.kind == "move"
            and any(v != 0 for v in c.numbers(3))}


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
    return stage.number("stop_ke") > 0 or stage.number("stop_stress") > 0 or stage.number("stop_unbalanced") > 0


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
        code = ("import sys\n    sys.path.insert(0, %r)\n    from harness.engines import lammps\n"
                "    return lammps.stop_check(%r, stage)" % (str(REPO_ROOT), str(work)))
        out += ["variable        stage equal 0",
                f"python          stoprule input 1 v_stage return v_met format ii here \"\"\"\n"
                f"def stoprule(stage):\n    {code}\n\"\"\"",
                "variable        met python stoprule"]
    moves = moving_walls(scene)
    first = [True]

    def run(steps):
        pre = "" if first[0] else " pre no post no"
        first[0] = False
        return ["variable        chunkend equal $(step+%d)" % steps, f"run             {steps}{pre}"]

    for g, stage in enumerate(scene.stages):
        out.append(f"# stage {stage.name}: {stage.cycles} cycles")
        out += motion_lines(scene, stage, moves)
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


def run_scene(lmp, ballast, scene_path, work, extra=(), sets=(), **options):
    """A ballast scene file through the translation and LAMMPS, without the adapter's dumps (the
    cross-checks of harness/peer add theirs as extra): resolved by the core in work, written as
    work/data.lmp and work/in.lmp and run there; LAMMPS's log figures (parse_log).
    RuntimeError naming the features LAMMPS cannot express, when the scene has any."""
    scene = scenes.read(scene_path, sets)
    scenes.resolve(scene, ballast, work)
    plan = Lammps(lmp).plan(scene, "run", dumps=False, **options)
    if plan.refused():
        raise RuntimeError("; ".join(f.line() for f in plan.refused()))
    opts = plan.options["lammps"]
    files.write_text(Path(work) / "data.lmp", data_text(scene, opts))
    return run_lmp(lmp, work, translate(scene, opts, work, extra))


# ---------------------------------------------------------------------------------- reading back

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
        segments at that step and the ramp factor."""
        order = np.argsort(atoms["id"])
        A = {k: v[order] for k, v in atoms.items() if k != "_step"}
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
        for k, h in enumerate(self.held):
            if "x" in h:
                hx[k] = 0.0
            if "y" in h:
                hy[k] = 0.0
        vx, vy, w = (np.where(self.fixed, 0.0, v) for v in (vx, vy, w))
        discs = self.disc_contacts(pairs, x, y, (hx, hy, hw), (vx, vy, w))
        contacts = concatenate(discs, contacts_of(self.wall_contacts(A, x, y, hx, hy, hw, walls, step)))
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

    def wall_contacts(self, A, x, y, hx, hy, hw, walls, step):
        rows = []
        for wk, fid in self.fixes:
            flag = A[f"f_{fid}[1]"]
            for i in np.flatnonzero(flag > 0):
                cx, cy = A[f"f_{fid}[5]"][i], A[f"f_{fid}[6]"][i]
                fx, fy = A[f"f_{fid}[2]"][i], A[f"f_{fid}[3]"][i]      # the force on the disc
                dx, dy = cx - x[i], cy - y[i]
                dist = math.hypot(dx, dy)
                ex, ey = dx / dist, dy / dist
                delta = self.r[i] - dist
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
                                 sliding=sliding))
                self.beyond += self.beyond_end(walls[wk], cx, cy)
        return rows

    def wall_velocity(self, wk, cx, cy, step):
        """The velocity of wall wk's point (cx, cy) in the stage that holds step: V + omega x (c - P)."""
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


def walls_at(scene, schedule, step):
    """Every wall's segment (ax, ay, bx, by) after `step` cycles: moved by each stage's velocity
    for its cycles and turned about its (moving) pivot (ballast's `move`). schedule: (stage,
    its actual cycles) in order."""
    dt = scene.dt
    out = []
    for w in scene.walls:
        px, py = pivot(scene, w)
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
        cs, sn = math.cos(th), math.sin(th)

        def move(qx, qy):
            rx, ry = qx - px, qy - py
            return px + dx + cs * rx - sn * ry, py + dy + sn * rx + cs * ry
        out.append(move(w.ax, w.ay) + move(w.bx, w.by))
    return out


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
    frame = reader.frame(atoms, pairs, walls_at(scene, schedule, step), gfac_at(scene, schedule, step))
    m = Measure(scene, frame, Laws(scene), Bodies(scene))
    st = scene.stages[stage]
    ee = m.elastic()
    ratio = m.kinetic() / ee if ee > 0 else math.inf
    met = st.number("stop_ke") <= 0 or ratio <= st.number("stop_ke")
    if st.number("stop_stress") > 0:
        mom = m.moments()
        prev = state["prev"].get(stage)
        state["prev"][stage] = mom
        if prev is None:
            met = False
        else:
            size = float(np.max(np.abs(mom)))
            change = float(np.max(np.abs(mom - prev))) / size if size > 0 else math.inf
            met = met and change <= st.number("stop_stress")
    if st.number("stop_unbalanced") > 0:
        met = met and m.unbalanced() <= st.number("stop_unbalanced")
    if met:
        stops[str(stage)] = step
        files.write_text(stops_path(work), json.dumps(stops))
    return 1 if met else 0


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
        f = reader.frame(atoms[step], pairs.get(step, {}), walls_at(scene, schedule, step),
                         gfac_at(scene, schedule, step))
        frames.append(f)
    final = frames[-1] if frames and frames[-1].step == total else reader.frame(
        atoms[max(atoms)], pairs.get(max(atoms), {}), walls_at(scene, schedule, max(atoms)), 1.0)
    beyond = reader.beyond
    stages = [{"name": s.name, "cycles": c, "max_cycles": s.cycles, "stop_rule": _stop_rule(s),
               "stopped": str(g) in stops} for g, (s, c) in enumerate(schedule)]
    notes = {"lammps_log": {k: log[k] for k in ("version", "builds", "dangerous")},
             "pair_style": "granular" if opts.granular else "gran/hooke/history",
             "atom_types": len(opts.types)}
    if beyond:
        notes["failure"] = (f"{beyond} wall contact(s) beyond a wall's end: LAMMPS's plane is infinite, "
                            "ballast's wall a segment")
    if log["dangerous"] > 0:
        notes["failure"] = f"{log['dangerous']} dangerous neighbour-list builds in LAMMPS"
    return Trajectory(frames, final, stages, total, log["total_seconds"], notes)
