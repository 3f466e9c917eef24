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
               turned by equal-style variables of the step (ballast's `move`); a servo or
               strain-rate wall (and a moving wall such a controller measures) follows a
               carrier atom that fix move variable moves by x += dt v, v the core's controller
               law evaluated first in each step from the state of the step before
  turning wall with rolling: the run is made in the wall's frame (the one wall, every disc held):
               the wall a static plane, the held discs moved rigidly by fix move variable with
               spin -omega_wall, the state rotated back into the lab by the reader
  stop rules   checked every check_every steps by the same Python that writes the outputs,
               inside LAMMPS (its PYTHON package), on LAMMPS's state

The run's state comes back through two dumps written at ballast's series rows (every
output_every steps and at each stage's end): per atom x, v, omega, f, torque and each wall
fix's contact (flag, force, point); per pair (compute pair/local) the normal and tangential
forces and the rolling pseudo-force.  lammps_output.Reader turns them into a Frame in
ballast's conventions (trajectory.py): the elastic forces from the overlap by the law, the
dashpots from the velocities LAMMPS's forces saw (v_{N-1/2} = v_N - dt/2 f_N/m, which
LAMMPS's second half kick inverts exactly).

This module decides what is expressible (Lammps.plan) and runs LAMMPS; lammps_input.py writes
its input (data_text, translate), lammps_output.py reads its run back.
"""
import hashlib
import math
import os
import pickle
import re
import shutil
import subprocess
from pathlib import Path

from .. import files
from . import scene as scenes
from .interface import APPROXIMATE, EXACT, REFUSED, Engine, Plan
from .lammps_input import (_stop_rule, controlled_walls, data_text, fmt, frame_wall,  # noqa: F401
                           gfac_expr, pair_law, rolling_sds, translate, wall_side)
from .lammps_output import (last_frame, parse_dump, parse_frames, parse_log, run_lmp,  # noqa: F401
                            trajectory_of, walls_at)

LMP = "lmp"
# apt-get's command line for LAMMPS (a test gives another to see the skip path).
INSTALL = ("apt-get", "install", "-y", "-qq", "--no-install-recommends", "lammps")
HERE = Path(__file__).resolve().parent
# harness/engines' modules that only read finished runs (the agreement matrix and its
# questions): not part of a run's identity
REPORT_SIDE = frozenset({"matrix.py", "questions.py"})
STYLES = ("gran/hooke/history", "granular", "wall/gran/region")
# Hertz needs one atom type per radius (k_L depends on R_eff): more radii than this and the
# pair table (n^2/2 coefficients) is no longer a translation worth making.
MAX_TYPES = 64
# The adapter reads a run through dumps of every disc and contact at each series row: at most this
# many disc-rows (about 100 MB of dumps with their contacts) before the rows are thinned (plan()).
DUMP_BUDGET = 1e6
# How many checks a stop rule is taken to need when the rows are thinned (the piles come to rest
# within 7-30 checks of 500 cycles in ballast; the count only sets the thinning, not the run).
STOP_CHECKS_GUESS = 20


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
        self.frame = None          # the wall whose frame the run is made in (lammps_input.frame_wall)
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
        """What decides a LAMMPS run's outputs besides its scene: the executable and every file
        of harness/engines but the report's (REPORT_SIDE: they read finished runs, make none;
        a change to them must not redo hours of runs)."""
        exe = shutil.which(self.lmp)
        out = {"lmp": exe, "lmp_sha256": _sha256(exe) if exe else None}
        for p in sorted(HERE.glob("*.py")):
            if p.name not in REPORT_SIDE:
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
        opts.frame = plan.options.pop("frame", None)              # _rolling_turning()
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
                self._rolling_turning(scene, plan, name)
        controls = {c.kind for s in scene.stages for c in s.controls}
        carried = {scene.walls[k].name for k in controlled_walls(scene)}
        for name in sorted(carried & turning):
            plan.add(f"turning wall {name} under a controller", REFUSED,
                     "a carried wall (servo, strain rate, or a wall they measure) moves along its "
                     "carrier atom only: it does not turn")
        if "servo" in controls:
            plan.add("servo-controlled walls (stress target)", EXACT,
                     "the core's law v = clip(alpha (sigma_t - S/L) L/(K dt), vmax) towards the discs, "
                     "S and K the springs' normal force k_n delta and stiffness k_n summed over the wall's "
                     "contacts of the step before, L the span gap; the wall's region follows a carrier "
                     "atom that fix move variable moves by x += dt v, v evaluated first in each step")
        if "strain_rate" in controls:
            plan.add("strain-rate walls (logarithmic strain)", EXACT,
                     "v = rate (M_TO - P_W).n n of the step before, through the wall's carrier atom as "
                     "for a servo")
        if scene.walls:
            moving = any(c.kind == "move" for s in scene.stages for c in s.controls)
            plan.add("walls" + (" moved and turned by stages" if moving else ""), EXACT,
                     "region plane + fix wall/gran/region (one per wall and disc material, ballast's "
                     "pair law 2 k_a k_b/(k_a + k_b)); move: displacement and angle as equal-style "
                     "variables of the step; the plane is infinite, ballast's wall a segment: each "
                     "contact is checked to lie within the wall's ends")

    def _rolling_turning(self, scene, plan, name):
        """Rolling against turning wall `name`: in the wall's own frame where that is exact
        (lammps_input.frame_wall(): the one wall, every disc held; and no friction or dashpots,
        the only forces the frame change was measured with), else refused."""
        refused = ("fix wall/gran's rolling displacement takes the particle's spin only, not the "
                   "wall's: ballast's theta_r = int (omega - omega_wall) dt has no counterpart")
        k = frame_wall(scene)
        if k is None:
            plan.add(f"rolling against turning wall {name}", REFUSED,
                     refused + "; the run is made in the wall's frame only where that wall is the "
                     "scene's one wall, moved by `move` alone, every disc is held (fixed = 1) and no "
                     "stage has a stop rule")
            return
        others = [what for what, on in (
            ("friction", any(m.friction > 0 for m in scene.materials.values())),
            ("contact dashpots", scene.number("gamma_n") > 0 or scene.number("beta") > 0)) if on]
        if others:
            plan.add(f"rolling against turning wall {name}", REFUSED,
                     refused + "; the run in the wall's frame is taken without " + " and ".join(others)
                     + " only (the only contact forces it was measured with)")
            return
        plan.add(f"rolling against turning wall {name}: run in the wall's frame", EXACT,
                 "the wall stands still as a plane through P0 and every held disc moves rigidly, "
                 "X' = P0 + R(-theta)(X - P0 - d), d and theta the wall's displacement and angle as "
                 "step formulas (fix move variable), spin -omega_wall (set per stage): the contact's "
                 "overlap, normal, moment and theta_r = int (omega - omega_wall) dt are ballast's to "
                 "round-off (the turned rather than the lab overlap: 1 ulp of the disc's place); "
                 "positions, points and forces are rotated back into the lab")
        plan.options["frame"] = k

    def _stages(self, scene, plan):
        for s in scene.stages:
            if s.number("stop_servo") > 0:
                plan.add(f"stage {s.name}: stop_servo", EXACT,
                         "every servo wall's |S/L - sigma_t|/sigma_t at the check, from LAMMPS's state, "
                         "as the core's stop rule")
            if _stop_rule(s):
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
        for name in ("stops.json", "checks.json"):       # the stop rules' records are this run's
            (work / name).unlink(missing_ok=True)
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
