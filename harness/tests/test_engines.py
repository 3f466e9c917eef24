"""harness/engines: the adapter interface without LAMMPS.

- a fake engine that cannot express a feature: its run is status 'not_expressible' and every
  check that reads it (directly, through another variant, or a column the engine lists as
  unexpressible) is NOT EXPRESSIBLE -- never PASS, FAIL or SKIP;
- the LAMMPS translation of small scenes (what plan() maps, refuses; the input's lines);
- a round trip: an engine Trajectory written as ballast's files and read back by the harness's
  own readers with ballast's conventions.
The real LAMMPS runs are in test_engines_lammps.py (make test-peers)."""
import json
import math
import pathlib

import numpy as np
import pytest

from harness import final_state
from harness.compare import RunStore, evaluate_check, folder_locator
from harness.engines import lammps, outputs, scene as scenes
from harness.engines.driver import make_run
from harness.engines.interface import APPROXIMATE, EXACT, REFUSED, Engine, Plan
from harness.engines.trajectory import Frame, Trajectory, contacts_of
from harness.references import Check
from harness.tables import load_run

ROOT = pathlib.Path(__file__).resolve().parents[2]
BALLAST = ROOT / "bin" / "ballast"
TWO_DISCS = ROOT / "cases" / "two_discs" / "two_discs.scene"
COLLISION = ROOT / "cases" / "collisions" / "collision.scene"
needs_ballast = pytest.mark.skipif(not BALLAST.exists(), reason="bin/ballast not built (make bin/ballast)")


# ---- a fake engine ------------------------------------------------------------------------

class Fake(Engine):
    """An engine that cannot express global damping; otherwise it keeps every disc where it
    starts (no contacts), which is enough to write ballast's files."""
    name, title = "fake", "FakeDEM"

    def problem(self):
        return ""

    def identity(self):
        return {"fake": 1}

    def plan(self, scene, command):
        plan = Plan()
        if scene.number("alpha") > 0:
            plan.add(f"global damping alpha = {scene.number('alpha'):g}", REFUSED, "FakeDEM has no drag")
        plan.add("walls", EXACT, "kept where they are")
        plan.unexpressible["Ee"] = "FakeDEM keeps no springs"
        return plan

    def simulate(self, scene, plan, work):
        d = scene.discs
        walls = [(w.ax, w.ay, w.bx, w.by) for w in scene.walls]
        frames = [Frame(n, n * scene.dt, d["x"], d["y"], 0 * d["x"], 0 * d["x"], 0 * d["x"],
                        contacts_of([]), walls) for n in range(1, scene.total_cycles + 1)]
        stages = [{"name": s.name, "cycles": s.cycles, "max_cycles": s.cycles, "stop_rule": False,
                   "stopped": False} for s in scene.stages]
        return Trajectory(frames, frames[-1], stages, scene.total_cycles, 0.5)


def check(name, variant, quantity, lo=-1e300, hi=1e300, case="two_discs"):
    return Check(name=name, case=case, quantity=quantity, tolerance="interval",
                 tolerance_text="interval", kind="analytic", provenance="test", variant=variant,
                 lo=lo, hi=hi)


@needs_ballast
def test_a_feature_the_engine_cannot_express_makes_every_check_reading_it_not_expressible(tmp_path):
    root = tmp_path / "runs"
    assert make_run(Fake(), TWO_DISCS, ["settings.alpha=8"], "run", root / "two_discs" / "damped", BALLAST) == 0
    assert make_run(Fake(), TWO_DISCS, [], "run", root / "two_discs" / "plain", BALLAST) == 0
    info = json.loads((root / "two_discs" / "damped" / "run.json").read_text())
    assert info["status"] == "not_expressible" and "global damping alpha = 8: FakeDEM has no drag" in info["message"]
    assert info["message"].startswith("not expressible in FakeDEM")
    assert [f["status"] for f in info["features"]] == [REFUSED, EXACT]
    store = RunStore(folder_locator(root))
    direct = evaluate_check(check("c1", "damped", "last(Fn_B)"), store)
    # read through another variant (series() of a sibling): not expressible as well
    sibling = evaluate_check(check("c2", "plain", "last(series('damped', 'Fn_B'))"), store)
    for v in (direct, sibling):
        assert v.result == "NOT EXPRESSIBLE" and not v.passed and not v.skipped and not v.known
        assert "FakeDEM has no drag" in v.unexpressible and v.as_dict()["not_expressible"] == v.unexpressible
    # the expressible run is checked as any run: a pass, and a fail
    assert evaluate_check(check("c3", "plain", "last(Fn_B)", hi=1.0), store).result == "PASS"
    assert evaluate_check(check("c4", "plain", "last(Fn_B)", lo=1.0), store).result == "FAIL"
    # a column the engine cannot give: that check alone is not expressible, with the engine's reason
    v = evaluate_check(check("c5", "plain", "max(Ee) + last(Fn_B)"), store)
    assert v.result == "NOT EXPRESSIBLE" and "Ee: FakeDEM keeps no springs" in v.message
    # and the energy audit, which is ballast's own ledger
    v = evaluate_check(check("c6", "plain", "energy('relative_imbalance')"), store)
    assert v.result == "NOT EXPRESSIBLE" and "energy ledger" in v.message


@needs_ballast
def test_ballasts_known_discrepancy_within_tolerance_is_a_pass_in_the_other_engines_column(tmp_path):
    """A check listed as a known discrepancy (reference/known.tsv: why ballast differs from a
    paper) is FAIL in ballast's column once within its tolerance (the entry is stale), but the
    entry is ballast's: in another engine's column (matrix.evaluate) a value within the tolerance
    is a PASS that says so, and a miss is KNOWN as in ballast's.  Seen on biaxial_full's
    paper_peak_m1_d0.4_e025: LAMMPS's envelope 25.51 against JYH's 29.0 +- 3.5, ballast's 24.11."""
    from dataclasses import replace
    root = tmp_path / "runs"
    assert make_run(Fake(), TWO_DISCS, [], "run", root / "two_discs" / "plain", BALLAST) == 0
    store = RunStore(folder_locator(root))
    inside = replace(check("k1", "plain", "last(Fn_B)", hi=1e300), kind="paper", known="a reason")
    outside = replace(inside, name="k2", lo=1e299)
    mine, theirs = evaluate_check(inside, store), evaluate_check(inside, store, known_is_ours=False)
    assert mine.result == "FAIL" and "but within its tolerance now" in mine.message
    assert theirs.result == "PASS" and not theirs.known and "ballast lists a known discrepancy (a reason)" in theirs.message
    for own in (True, False):
        v = evaluate_check(outside, store, known_is_ours=own)
        assert v.result == "KNOWN" and v.known == "a reason"


def test_a_lammps_runs_identity_holds_the_adapters_files_not_the_reports():
    """The runner keeps a finished LAMMPS run while its identity holds (RESUME=1): the executable
    and the adapter's files decide the outputs, so each is in it; the agreement matrix and its
    questions only read finished runs, so a change to them keeps hours of runs (a biaxial test
    is 133-147 s of LAMMPS)."""
    ident = lammps.Lammps().identity()
    names = {pathlib.Path(k).name for k in ident if k.endswith(".py")}
    here = {p.name for p in pathlib.Path(lammps.__file__).parent.glob("*.py")}
    assert {"lammps.py", "lammps_input.py", "lammps_output.py", "driver.py", "scene.py"} <= names
    assert names == here - {"matrix.py", "questions.py"}
    assert "lmp_sha256" in ident


def test_a_not_expressible_run_is_neither_a_failure_nor_unfinished(tmp_path):
    from harness.tables import run_failure, unfinished_outputs
    info = {"status": "not_expressible", "message": "not expressible in X: y"}
    (tmp_path / "run.json").write_text(json.dumps(info))
    assert run_failure(tmp_path, info) is None
    assert unfinished_outputs(tmp_path, "lammps:run") == ""
    (tmp_path / "run.json").unlink()
    assert "run.json missing" in unfinished_outputs(tmp_path, "lammps:run")


# ---- the scene as the adapters read it ----------------------------------------------------

def test_set_lines_replace_keys_a_walls_motion_and_cycles_for_time(tmp_path):
    path = tmp_path / "s.scene"
    path.write_text("[settings]\ndt = 0.01\n[material m]\nkn = 5\n[stage a]\ntime = 2\n"
                    "move = w1 1 0 0\nmove = w2 0 1 0\n[probe p]\nquantity = n_contacts\n")
    s = scenes.read(path, ["settings.alpha=3", "material.m.kn=7", "stage.a.move=w1 0 0 2",
                           "stage.a.cycles=4"])
    assert s.number("alpha") == 3 and s.materials["m"].kn == 7 and s.materials["m"].ks == 7
    stage = s.stages[0]
    assert "time" not in stage.keys and stage.keys["cycles"] == "4"
    assert [(c.wall, c.words) for c in stage.controls] == [("w2", ["0", "1", "0"]), ("w1", ["0", "0", "2"])]
    with pytest.raises(scenes.SceneError, match="no \\[material q\\]"):
        scenes.read(path, ["material.q.kn=1"])


# ---- the LAMMPS translation of small scenes ------------------------------------------------

def resolved(tmp_path, path, sets=()):
    s = scenes.read(path, sets)
    return scenes.resolve(s, BALLAST, tmp_path / "work")


def cmds(text):
    return [l.split("#")[0].split() for l in text.splitlines() if l.split("#")[0].strip()]


@needs_ballast
def test_hertz_gets_one_type_per_radius_and_k_over_sqrt_delta0_r_eff(tmp_path):
    s = resolved(tmp_path, COLLISION, ["settings.nu=1.5", "material.disc.kn=50000", "settings.gamma_n=40"])
    plan = lammps.Lammps().plan(s, "run")
    assert not plan.refused() and plan.options["lammps"].types == [("disc", 1.0), ("disc", 0.75)]
    coeffs = {(c[1], c[2]): c for c in cmds(lammps.translate(s, plan.options["lammps"])) if c[0] == "pair_coeff"}
    for (i, j), ra, rb in ((("1", "1"), 1.0, 1.0), (("1", "2"), 1.0, 0.75), (("2", "2"), 0.75, 0.75)):
        c = coeffs[(i, j)]
        assert c[3] == "hertz" and float(c[4]) == 50000 / math.sqrt(1.0 * ra * rb / (ra + rb))
        assert c[5] == "40.0" and c[-2:] == ["damping", "velocity"]     # gamma_n, not scaled by m_eff
    assert "pair_style      granular" in lammps.translate(s, plan.options["lammps"])


@needs_ballast
def test_what_lammps_cannot_express_is_refused_feature_by_feature(tmp_path):
    engine = lammps.Lammps()
    refused = lambda sets, command="run": [f.name for f in engine.plan(resolved(tmp_path, COLLISION, sets),
                                                                       command).refused()]
    assert refused([]) == []
    assert refused(["settings.nu=2"]) == ["normal law: power, nu = 2"]
    assert refused(["settings.gamma_n=4", "settings.psi=0.5"]) == [
        "viscous normal damping gamma_n (delta/delta0)^psi, psi = 0.5"]
    assert refused(["settings.integrator=gear5"]) == ["integrator: gear5"]
    assert refused(["material.disc.rolling=0.5", "settings.rolling_model=model2"]) == [
        "rolling resistance: JYH Model 2 (elasto-brittle)"]
    assert refused(["material.disc.cohesion=1"]) == ["cohesion"]
    assert refused([], "exact") == ["command: exact (ballast's static solver)"]
    plan = engine.plan(resolved(tmp_path, TWO_DISCS, []), "run")
    assert [f.status for f in plan.features if f.name.startswith("normal law")] == [APPROXIMATE]


@needs_ballast
def test_global_damping_maps_exactly_through_mass_langevin_and_a_trim(tmp_path):
    s = resolved(tmp_path, TWO_DISCS, ["settings.alpha=10"])
    opts = lammps.Lammps().plan(s, "run").options["lammps"]
    h = 10 * 0.01 / 2
    assert opts.scale == 1 + h
    text = lammps.translate(s, opts)
    c = cmds(text)
    drag = next(x for x in c if x[:2] == ["fix", "drag"])
    # rotational drag -0.4 m' r^2 omega / damp = -alpha I omega: 1/damp = 1.25 alpha / s
    assert drag[3] == "langevin" and float(drag[6]) == pytest.approx((1 + h) / (1.25 * 10), rel=1e-15)
    assert drag[-2:] == ["omega", "yes"] and drag[4:6] == ["0.0", "0.0"]
    assert f"variable        trimx atom 2.5*mass/{1 + h!r}*vx" in text        # +alpha m v/4
    data = lammps.data_text(s, opts)
    assert f" {1000 * (1 + h)!r} " in data                                    # densities times s


@needs_ballast
def test_walls_move_from_where_each_stage_found_them(tmp_path):
    s = resolved(tmp_path, TWO_DISCS, [])
    text = lammps.translate(s, lammps.Lammps().plan(s, "run").options["lammps"])
    assert "region          W0 plane 0.0 0.0 0.0 1.0 -6.123233995736766e-17 0.0 side in units box " \
           "move v_W0_dx v_W0_dy NULL" in text
    lines = text.splitlines()
    load, hold = lines.index("# stage load: 40 cycles"), lines.index("# stage hold: 600 cycles")
    # the displacement is read (immediate) before `start` moves on, then this stage's rate
    assert lines[load + 1] == "variable        W0_dx0 equal $(v_W0_dx:%.17g)"
    assert 'variable        W0_dx equal "v_W0_dx0+0.0012*(step-v_start)"' in lines[load:hold]
    assert 'variable        W0_dx equal "v_W0_dx0+0.0*(step-v_start)"' in lines[hold:]
    assert lammps.walls_at(s, [(s.stages[0], 40), (s.stages[1], 600)], 100)[0][0] == pytest.approx(0.048)


SERVO_BOX = ROOT / "harness" / "tests" / "data" / "servo_box.scene"
BIAXIAL = ROOT / "cases" / "biaxial" / "biaxial.scene"


@needs_ballast
def test_servo_and_strain_rate_walls_ride_carrier_atoms_moved_first_in_each_step(tmp_path):
    s = resolved(tmp_path, SERVO_BOX, [])
    plan = lammps.Lammps().plan(s, "run")
    assert plan.refused() == []
    status = {f.name: f.status for f in plan.features}
    assert status["servo-controlled walls (stress target)"] == EXACT
    assert status["strain-rate walls (logarithmic strain)"] == EXACT
    assert status["stage consolidate: stop_servo"] == EXACT
    # top and right are driven; bottom is the strain rate's target and left a span wall, but no
    # stage moves them: they stay plain static walls
    assert [s.walls[k].name for k in lammps.controlled_walls(s)] == ["top", "right"]
    opts = plan.options["lammps"]
    data = lammps.data_text(s, opts)
    assert "8 atoms" in data and "2 atom types" in data            # 6 discs and 2 carriers
    assert "7 2 1.9 1.0 2.0 6.1 0" in data                         # top's carrier at its midpoint
    text = lammps.translate(s, opts)
    lines = [l for l in text.splitlines() if l.startswith(("fix ", "variable        W", "region", "neigh"))]
    order = [l.split()[1] for l in lines if l.startswith("fix ")]
    assert order.index("carry") < order.index("integrate")           # the carriers move first
    assert "fix             carry carriers move variable NULL NULL NULL v_carry_vx v_carry_vy NULL" in text
    assert "exclude group carriers all" in text
    assert "variable        W1_dy equal y[7]-6.1" in text
    assert "move v_W1_dx v_W1_dy NULL" in next(l for l in lines if l.startswith("region          W1 "))
    stage = text[text.index("# stage consolidate"):text.index("# stage shear")]
    # the core's servo law: gain (sigma - S/L) L / (K dt), capped at vmax (here 1e-3 r_min / dt,
    # vmax = 0), the cap at the first step of the run (no wall loop has run yet)
    cap = repr(1e-3 * 0.95 / 0.001)
    assert 'variable        W1_raw equal "0.5*(4000.0-c_W1s[1]/abs(' in stage
    assert f'variable        W1_sp equal "(step==v_gstart+1)*{cap}+(1-(step==v_gstart+1))*(' in stage
    assert 'variable        W1_vx equal "0.0"' in stage and 'W1_vy equal "v_W1_sp*-1.0"' in stage
    shear = text[text.index("# stage shear"):]
    # the strain rate: rate (M_bottom - P_top).n n, n = (-0, 1): towards the bottom wall
    assert 'variable        W1_vy equal "0.5*(-6.1+(0.0-v_W1_dx)*-0.0+(0.0-v_W1_dy)*1.0)*1.0"' in shear
    # right's servo goes on from the consolidation's wall loop: no first-step case
    assert "W1_sp" not in shear and "W3_sp" in shear and "(step==v_gstart+1)" not in shear


@needs_ballast
def test_the_biaxial_tests_are_expressible_but_model_2(tmp_path):
    sets = ["stage.consolidate.cycles=1", "stage.shear.cycles=0"]
    refused = lambda extra: [f.name for f in lammps.Lammps().plan(resolved(tmp_path, BIAXIAL, sets + extra),
                                                                    "run").refused()]
    assert refused(["material.grain.rolling=0.4"]) == []
    assert refused(["material.grain.rolling=0.4", "settings.rolling_model=model2"]) == [
        "rolling resistance: JYH Model 2 (elasto-brittle)"]


@needs_ballast
def test_every_full_tier_scene_is_expressible_in_lammps_but_model_2s(tmp_path):
    """What `make validate-peers TIER=full` would run (docs/engines.md, the full tier): every
    variant of the full-tier cases, one realisation per ensemble (the others differ by the seed
    only), through LAMMPS's plan: refused only Model 2's biaxial tests; the cross-checks of
    harness/peer are ballast against LAMMPS already."""
    from harness import catalogue, cases_root
    counts, refused = {}, set()
    for case in catalogue.load(cases_root()):
        if case.tier != "full":
            continue
        for v in case.variants:
            if v.ensemble and v.seed != case.ensemble(v.ensemble).seeds[0]:
                continue
            if v.command not in ("run", "exact"):
                counts["cross-check"] = counts.get("cross-check", 0) + 1
                continue
            plan = lammps.Lammps().plan(resolved(tmp_path / case.name / v.name, v.scene, v.sets), v.command)
            names = [f.name for f in plan.refused()]
            key = "refused" if names else "expressible"
            counts[key] = counts.get(key, 0) + 1
            refused.update(names)
            assert not names or "model2" in " ".join(v.sets), (case.name, v.name, names)
    assert refused == {"rolling resistance: JYH Model 2 (elasto-brittle)"}
    assert counts["expressible"] >= 100 and counts["refused"] == 6 and counts["cross-check"] == 2


def test_the_gravity_ramp_is_the_cores_c_plus_one_over_c():
    class S:
        def __init__(self, cycles, ramp):
            self.cycles, self.keys = cycles, {"ramp": str(ramp)}

        def number(self, key):
            return float(self.keys[key])

    class Sc:
        stages = [S(10, 0), S(4000, 1), S(5, 0)]
    expr = lammps.gfac_expr(Sc, [0, 10, 4010])
    value = lambda step: eval(expr.replace("step", str(step)))    # LAMMPS's booleans are Python's here
    assert [value(n) for n in (5, 10, 11, 12, 4010, 4011)] == [1, 1, 1 / 4000, 2 / 4000, 1, 1]


# ---- round trip: a trajectory as ballast's files -------------------------------------------

@needs_ballast
def test_a_trajectory_comes_back_through_ballasts_readers_with_ballasts_conventions(tmp_path):
    """Two discs x (50, 0) and y (149.9, 0), r = 50: overlap 0.1, F_n = 1e8 + dashpot 5; x
    also touches the left wall (its line x = 0) with overlap 0.02.  What the files say must be
    what the frame says, in ballast's conventions."""
    s = resolved(tmp_path, TWO_DISCS, [])
    x, y = np.array([50.0, 149.9]), np.zeros(2)
    rows = [dict(a=0, b=1, wall=0, nx=1.0, ny=0.0, px=99.95, py=0.0, delta=0.1, fn=1e8, dn=5.0, fs=2.0, ds=1.0),
            dict(a=0, b=0, wall=1, nx=-1.0, ny=0.0, px=-0.01 + 0.0, py=0.0, delta=0.02, fn=2e7, dn=0.0,
                 fs=0.0, ds=0.0)]
    walls = [(w.ax, w.ay, w.bx, w.by) for w in s.walls]
    frame = Frame(1, 0.01, x, y, np.array([0.1, -0.1]), np.zeros(2), np.zeros(2), contacts_of(rows), walls)
    traj = Trajectory([frame], frame, [{"name": "load", "cycles": 1, "max_cycles": 40, "stop_rule": False,
                                        "stopped": False}], 1, 0.25)
    out = tmp_path / "out"
    plan = Plan()
    outputs.write(s, plan, traj, out, {"engine": "test"}, 1.0)
    run = load_run(out)
    assert run.info["status"] == "ok" and run.info["particle_steps"] == 2 and run.info["engine_seconds"] == 0.25
    assert run.columns["Fn_B"].tolist() == [1e8] and run.columns["Fn_A"].tolist() == [2e7]
    e_el = 1e8 ** 2 / 2e9 + 2.0 ** 2 / 2e9 + 2e7 ** 2 / 2e9          # F_n^2/(2 k_n) + F_s^2/(2 k_s)
    assert run.columns["Ek"][0] == pytest.approx(2 * 0.5 * s.discs["m"][0] * 0.01)
    assert run.columns["Ee"][0] == pytest.approx(e_el, rel=1e-15)
    assert "Ee" not in run.info["unexpressible"] and "energy" in run.info["unexpressible"]
    st = final_state.state(run)
    forces = st.contacts()
    byname = {tuple(sorted(c["key"])): c for c in forces}
    assert byname[("x", "y")]["force"] == 1e8 + 5.0
    # contacts.tsv: the force on a is -(fn + dn) e - (fs + ds) t, t = (ny, -nx)
    t = final_state.Table(out / "contacts.tsv", ("a", "b", "kind", "nx", "fn", "fs", "dn", "ds"))
    assert t.text("a") == ["x", "x"] and t.text("b") == ["y", "left"] and t.numbers("ds").tolist() == [1.0, 0.0]
    walls = final_state.Table(out / "walls.tsv", ("name", "f1", "f2"))
    assert walls.numbers("f1").tolist() == [-2e7, 0.0]             # the disc pushes the left wall to -x
    stress = final_state.Table(out / "stress.tsv", ("name", "sxx", "szz", "V"))
    # disc y: f = (fn + dn) e on y, l = -(r - delta/2) e: sxx = -(1e8 + 5)(50 - 0.05)/V
    v = 2 * math.sqrt(3) * 50 ** 2
    assert stress.numbers("sxx")[1] == pytest.approx(-(1e8 + 5) * 49.95 / v, rel=1e-14)
    assert stress.numbers("szz")[1] == pytest.approx((2.0 + 1.0) * 0.0, abs=1e-6)


def test_a_matrix_of_some_cases_replaces_only_their_rows(tmp_path):
    from harness.engines import matrix

    def row(case, result):
        return {"case": case, "title": case, "tier": "quick", "not_expressible": {},
                "ballast": {"particle_steps": 1.0, "seconds": 1.0, "runs": 1, "variants": 1},
                "engine": {"particle_steps": 1.0, "seconds": 2.0, "runs": 1, "variants": 1},
                "checks": [{"check": "c", "variant": "v", "quantity": "q", "reference": 1.0,
                            "tolerance": "rel 1", "kind": "analytic",
                            "ballast": {"result": "PASS", "value": 1.0, "message": ""},
                            "engine": {"result": result, "value": None, "message": "why"}}]}
    out = tmp_path / "peers"
    matrix.write([row("collisions", "PASS"), row("two_discs", "FAIL")], "lammps", "LAMMPS", 0, out)
    rows = matrix.merged([row("two_discs", "NOT EXPRESSIBLE")], "lammps", out)
    assert [r["case"] for r in rows] == ["collisions", "two_discs"]           # the catalogue's order
    totals = matrix.write(rows, "lammps", "LAMMPS", 0, out)
    assert totals["engine"] == {"PASS": 1, "NOT EXPRESSIBLE": 1} and totals["ballast"] == {"PASS": 2}
    assert matrix.merged([row("two_discs", "PASS")], "other", out) == [row("two_discs", "PASS")]


class Stage:
    def __init__(self, **rules):
        self.rules = rules

    def number(self, key):
        return self.rules.get(key, 0.0)


def test_a_lammps_stage_record_is_the_cores_with_its_last_checks_values():
    """run.json's stages from LAMMPS carry what the core's carry (core/output.c): E_k/E_el and the
    stress change of the rule's last check (-1 never checked; null not finite: the first check of
    a stress rule), the servo and unbalanced entries only where the stage has those rules; a
    check of the catalogue reads them (piles_poly_full's full_at_rest: stress_change < 1e-5)."""
    from harness.engines.lammps_output import finite_or_none, stage_log
    assert stage_log(Stage(), {}) == {"ke_over_ee": -1, "stress_change": -1}
    rest = Stage(stop_ke=1e-8, stop_stress=1e-5)
    assert stage_log(rest, {"ke_over_ee": 3e-11, "stress_change": 9e-6}) == \
        {"ke_over_ee": 3e-11, "stress_change": 9e-6}
    assert stage_log(Stage(stop_servo=0.01, stop_unbalanced=1e-3), {"ke_over_ee": 0.2, "servo_error": 0.5}) == \
        {"ke_over_ee": 0.2, "stress_change": -1, "stop_servo": 0.01, "servo_error": 0.5,
         "stop_unbalanced": 1e-3, "unbalanced": -1}
    assert finite_or_none(math.inf) is None and finite_or_none(2.0) == 2.0
