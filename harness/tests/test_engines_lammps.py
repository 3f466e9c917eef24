"""harness/engines/lammps.py for real: the collisions case through LAMMPS (a few seconds).

Runs only where LAMMPS is installed (`lmp` on PATH): `make test-peers` installs it first
(apt-get, as `make validate-peers` does); `make test` does not, so on a fresh Debian 12 (CI)
these tests are skipped with the reason below."""
import json
import pathlib
import shutil

import numpy as np
import pytest

import harness.families  # noqa: F401 -- the expression functions the collision checks use
from harness import catalogue, references
from harness.compare import RunStore, evaluate_check, folder_locator
from harness.engines.driver import make_run
from harness.engines import matrix
from harness.engines.lammps import Lammps
from harness.tables import read_series

ROOT = pathlib.Path(__file__).resolve().parents[2]
BALLAST = ROOT / "bin" / "ballast"
SCENE = ROOT / "cases" / "collisions" / "collision.scene"
pytestmark = [pytest.mark.skipif(shutil.which("lmp") is None,
                                 reason="LAMMPS is not installed (no lmp on PATH): make test-peers "
                                        "installs it; make test does not"),
              pytest.mark.skipif(not BALLAST.exists(), reason="bin/ballast not built")]
# The collisions' variants at dt = 2^-10 (case.txt): the linear spring, the spring-dashpot and Hertz.
VARIANTS = {"linear_10": ["settings.dt=0.0009765625", "stage.run.cycles=64"],
            "damped_10": ["settings.gamma_n=40", "settings.dt=0.0009765625", "stage.run.cycles=64"],
            "hertz_10": ["settings.nu=1.5", "material.disc.kn=50000", "settings.dt=0.0009765625",
                         "stage.run.cycles=64"]}
# The two engines do the same arithmetic in another order: their positions, velocities and
# forces agree to round-off (measured: 1e-15 of the positions, 3e-14 of the Hertz force).
ROUNDOFF = 1e-12


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("runs")
    import subprocess
    for name, sets in VARIANTS.items():
        out = root / "lammps" / "collisions" / name
        assert make_run(Lammps(), SCENE, sets, "run", out, BALLAST) == 0
        args = [str(BALLAST), "run", str(SCENE), "--out", str(root / "ballast" / "collisions" / name)]
        for s in sets:
            args += ["--set", s]
        subprocess.run(args, check=True, capture_output=True)
    return root


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_lammps_moves_the_colliding_discs_as_ballast_does_to_round_off(runs, variant):
    info = json.loads((runs / "lammps" / "collisions" / variant / "run.json").read_text())
    assert info["status"] == "ok" and info["engine"] == "lammps" and info["steps"] == 64
    a = read_series(runs / "lammps" / "collisions" / variant / "series.tsv")
    b = read_series(runs / "ballast" / "collisions" / variant / "series.tsv")
    assert a["cycle"].tolist() == b["cycle"].tolist()
    for column in ("x_a", "x_b", "v_a", "v_b", "Fn"):
        scale = max(1.0, float(np.max(np.abs(b[column]))))
        assert np.max(np.abs(a[column] - b[column])) <= ROUNDOFF * scale, column
    assert max(b["Fn"]) > 0                                     # they did collide


def test_the_collision_checks_pass_on_lammps_and_its_energy_audit_is_not_expressible(runs):
    cases = catalogue.select(catalogue.load(), ["collisions"])
    checks = [c for c in references.expand(references.load(), cases)
              if c.case == "collisions" and all(v in VARIANTS for v in c.run_variants)]
    store = RunStore(folder_locator(runs / "lammps"))
    results = {c.name: evaluate_check(c, store) for c in checks}
    audit = [v for n, v in results.items() if n.startswith("energy_audit")]
    others = [v for n, v in results.items() if not n.startswith("energy_audit")]
    assert len(audit) == 3 and {v.result for v in audit} == {"NOT EXPRESSIBLE"}
    assert len(others) == 7 and {v.result for v in others} == {"PASS"}, \
        [(v.check, v.message) for v in others if v.result != "PASS"]


def test_the_matrix_sets_both_engines_side_by_side_with_their_costs(runs, tmp_path):
    cases = catalogue.select(catalogue.load(), ["collisions"])
    cases[0].variants = [v for v in cases[0].variants if v.name in VARIANTS]
    checks = [c for c in references.expand(references.load(), cases)
              if all(v in VARIANTS for v in c.run_variants)]
    triples = matrix.evaluate(checks, cases, runs / "ballast", runs / "lammps")
    rows = matrix.rows_of(cases, triples, runs / "ballast", runs / "lammps", "lammps")
    totals = matrix.write(rows, "lammps", "LAMMPS", 0, tmp_path / "peers")
    assert totals["ballast"] == {"PASS": len(checks)}
    assert totals["engine"]["NOT EXPRESSIBLE"] == 3 and totals["engine"]["PASS"] == len(checks) - 3
    row = rows[0]
    assert row["ballast"]["particle_steps"] == row["engine"]["particle_steps"] == 3 * 2 * 64
    assert row["engine"]["seconds"] > 0 and row["ballast"]["seconds"] > 0
    text = (tmp_path / "peers" / "index.md").read_text()
    assert "| [collisions](#collisions) |" in text and "NOT EXPRESSIBLE" in text
    assert json.loads((tmp_path / "peers" / "matrix.json").read_text())["totals"] == totals


# ---- servo and strain-rate walls (harness/tests/data/servo_box.scene) -----------------------

SERVO_BOX = ROOT / "harness" / "tests" / "data" / "servo_box.scene"
# Measured: the walls' positions agree to 2e-15 of their largest value, their forces (sums of
# contact springs k_n delta, k_n = 1e5) to 3e-13, over 500 cycles.
SERVO_ROUNDOFF = 1e-11


def test_servo_and_strain_rate_walls_move_in_lammps_as_in_ballast_to_round_off(tmp_path):
    import subprocess
    out = tmp_path / "lammps"
    assert make_run(Lammps(), SERVO_BOX, [], "run", out, BALLAST) == 0
    subprocess.run([str(BALLAST), "run", str(SERVO_BOX), "--out", str(tmp_path / "ballast")],
                   check=True, capture_output=True)
    info = json.loads((out / "run.json").read_text())
    assert info["status"] == "ok", info.get("message")
    core = json.loads((tmp_path / "ballast" / "run.json").read_text())
    # the consolidation's stop_servo is met at the same check in both (cycle 200 of 400)
    assert [(g["cycles"], g["stopped"]) for g in info["stages"]] == \
           [(g["cycles"], g["stopped"]) for g in core["stages"]] == [(200, True), (300, False)]
    a, b = read_series(out / "series.tsv"), read_series(tmp_path / "ballast" / "series.tsv")
    assert a["cycle"].tolist() == b["cycle"].tolist() and len(b["cycle"]) == 500
    for column in ("y_top", "x_right", "fy_top", "fx_right", "fy_bottom", "ek"):
        scale = float(np.max(np.abs(b[column])))
        assert np.max(np.abs(a[column] - b[column])) <= SERVO_ROUNDOFF * scale, column
    # each stage's record of its rule's last check, as the core writes it (core/output.c): the
    # same entries, E_k/E_el and the servo error at cycle 200 to round-off, -1 where never checked
    mine, theirs = info["stages"], core["stages"]
    assert [sorted(g) for g in mine] == [sorted(g) for g in theirs]
    for g, h in zip(mine, theirs):
        for key in ("ke_over_ee", "stress_change", "servo_error"):
            if key in h:
                assert g[key] == pytest.approx(h[key], rel=SERVO_ROUNDOFF), key
    assert theirs[1]["ke_over_ee"] == theirs[1]["stress_change"] == -1
    # the servo moved the top wall down and the strain rate moved it on: not a wall at rest
    assert b["y_top"][-1] < b["y_top"][199] < 6.1 - 0.05
    assert "stress_top" in info["unexpressible"]


def test_exported_lammps_jobs_run_where_they_are_sent_and_gather_into_the_peers_runs(tmp_path, monkeypatch,
                                                                                     capsys):
    """`export collisions --engine lammps`, one job run as GNU parallel or Slurm would run it,
    then `gather`: the run lands in reports/peers/runs/lammps/collisions/<variant> (where `make
    validate-peers --resume` keeps it) with the job's bytes, the jobs not run are listed."""
    from harness.__main__ import main
    reports = tmp_path / "reports"
    monkeypatch.setenv("BALLAST_REPORTS", str(reports))
    folder = tmp_path / "shared"
    assert main(["export", "collisions", "--to", str(folder), "--engine", "lammps"]) == 0
    manifest = json.loads((folder / "manifest.json").read_text())
    index = [j["variant"] for j in manifest["jobs"]].index("linear_10")
    assert main(["job", str(folder), str(index)]) == 0
    job = folder / "runs" / "collisions" / "linear_10"
    assert json.loads((job / "run.json").read_text())["engine"] == "lammps"
    assert main(["gather", str(folder)]) == 1                      # the other 11 were not run
    out = capsys.readouterr().out
    assert f"1 run(s) gathered, 0 already here, {len(manifest['jobs']) - 1} not gathered" in out
    home = reports / "peers" / "runs" / "lammps" / "collisions" / "linear_10"
    assert (home / "series.tsv").read_bytes() == (job / "series.tsv").read_bytes()
    assert json.loads((home / "harness.json").read_text())["gathered_from"] == str(job)
    assert not (reports / "runs" / "collisions").exists()         # not taken for ballast's run


# ---- the rolling tester: rolling against a turning floor, run in the floor's frame ------------

TESTER = ROOT / "cases" / "rolling" / "rolling_tester.scene"
# M_0 = F_n B/6 at the first press (rolling_tester.scene): the scale of the moment.
TESTER_M0 = 40.0
# Both engines compute the overlap as R - (R - p) cos(angle), a difference of two numbers of size
# R = 0.75 that leaves d = 2^-12 .. 2^-11: one ulp of R is 3.4e-13 of F_n (reference/derive/
# rolling.py's FN_ROUNDING), and each engine's rotation adds its own ulps (measured: F_n within
# 3.9e-13 of the exact overlap in LAMMPS, 6.5e-13 in ballast). So F_n, and M = K_m theta_r until
# the cap and mu_roll R F_n at it, may differ by about three ulps of R: 1e-12 of F_n (measured
# 9.1e-13 of M_0 and of F_n at most, over the 4183 cycles).  theta_r is a sum of the same dyadic
# increments of the spin in both (omega - omega_wall = -omega_wall): equal to the bit.
TESTER_ROUNDOFF = 2e-12


def test_the_rolling_tester_runs_in_the_floors_frame_with_ballasts_moment(tmp_path):
    """model1_d16 (the floor pressed, turned about the contact point, raised, turned again):
    LAMMPS's rolling displacement takes the disc's spin only, so the run is made in the floor's
    frame, where the floor stands still and the held disc moves about P at -omega_wall; its
    moment, theta_r, cap flags and F_n, written back in the lab, are ballast's to round-off."""
    import subprocess
    out = tmp_path / "lammps"
    assert make_run(Lammps(), TESTER, [], "run", out, BALLAST) == 0
    info = json.loads((out / "run.json").read_text())
    assert info["status"] == "ok", info.get("message")
    assert any(f["name"].endswith("run in the wall's frame") and f["status"] == "exact"
               for f in info["features"])
    subprocess.run([str(BALLAST), "run", str(TESTER), "--out", str(tmp_path / "ballast")],
                   check=True, capture_output=True)
    a, b = read_series(out / "series.tsv"), read_series(tmp_path / "ballast" / "series.tsv")
    assert a["cycle"].tolist() == b["cycle"].tolist() and len(b["cycle"]) == 4183
    assert np.max(np.abs(a["mr"] - b["mr"])) <= TESTER_ROUNDOFF * TESTER_M0
    assert np.max(np.abs(a["fn"] - b["fn"]) / b["fn"]) <= TESTER_ROUNDOFF
    assert a["theta_r"].tolist() == b["theta_r"].tolist()
    assert a["state"].tolist() == b["state"].tolist()
    # not a contact at rest: the moment went through both plateaus of both normal forces
    assert max(b["mr"]) > 80 and min(b["mr"]) < -80 and max(b["state"]) == 1
    # the contact, written back in the lab: its normal turned with the floor as ballast's did
    ca = (out / "contacts.tsv").read_text().splitlines()[1].split("\t")
    cb = (tmp_path / "ballast" / "contacts.tsv").read_text().splitlines()[1].split("\t")
    for column in (3, 4, 5, 6):                             # x, y, nx, ny
        assert abs(float(ca[column]) - float(cb[column])) <= 1e-15


@pytest.mark.parametrize("sets,reason", [
    (["material.grain.friction=0.5"], "without friction"),
    (["disc.d.fixed=0"], "every disc is held")])
def test_the_floors_frame_is_taken_only_where_it_is_exact(tmp_path, sets, reason):
    """The frame change is refused, and says why, with friction (not measured) and with a free
    disc (in the floor's frame it would need the frame's inertial forces)."""
    assert make_run(Lammps(), TESTER, sets, "run", tmp_path, BALLAST) == 0
    info = json.loads((tmp_path / "run.json").read_text())
    assert info["status"] == "not_expressible" and reason in info["message"], info["message"]


# ---- rolling against a static wall in the lab: the wall's couple from the disc's torque ---------

ROLLING_FLOOR = ROOT / "harness" / "tests" / "data" / "rolling_floor.scene"
# The moments are K_m theta_r (theta_r the same dyadic sums of the spin in both) or the cap
# mu_roll R F_n, F_n = k_n delta with delta a difference of coordinates of size 1: a few ulps of
# the overlap, 1e-13 of M_0 = 106.7 each (measured 1.1e-11 at the floor, the disc's torque less
# the other contact's couple, and 2.7e-12 between the discs).
FLOOR_ROUNDOFF = 1e-12


def test_a_static_walls_rolling_moment_is_the_discs_torque_less_its_other_couples(tmp_path):
    """rolling_floor.scene: a spun disc between a floor and a held disc, both contacts with JYH
    Model 1 and the floor's reaching its cap. LAMMPS's wall fix reports no torque, so the floor's
    moment is read as the disc's torque less the disc-disc contact's couple; it was 0 before."""
    import subprocess
    out = tmp_path / "lammps"
    assert make_run(Lammps(), ROLLING_FLOOR, [], "run", out, BALLAST) == 0
    info = json.loads((out / "run.json").read_text())
    assert info["status"] == "ok", info.get("message")
    subprocess.run([str(BALLAST), "run", str(ROLLING_FLOOR), "--out", str(tmp_path / "ballast")],
                   check=True, capture_output=True)
    a, b = read_series(out / "series.tsv"), read_series(tmp_path / "ballast" / "series.tsv")
    m0 = 409600 / 1024 * 1.6 / 6                   # F_n B/6 at the floor, B = delta 2 r
    assert np.max(np.abs(b["m_floor"])) == pytest.approx(m0)         # the floor's contact capped ...
    assert 0 < np.sum(b["cap_floor"]) < len(b["cap_floor"])          # ... for a while, then elastic
    for column in ("m_floor", "m_top"):
        assert np.max(np.abs(a[column] - b[column])) <= FLOOR_ROUNDOFF * m0, column
    assert a["cap_floor"].tolist() == b["cap_floor"].tolist()


def test_a_rolling_walls_moment_with_friction_takes_out_the_wall_fixs_lever_r(tmp_path):
    """rolling_floor.scene with friction 0.5: the floor's tangential force (sliding at mu F_n at
    the first row) is in the disc's torque too, and LAMMPS's wall fix applies it at the lever r
    (not pair granular's r - delta/2).  Read back with r - delta/2, the floor's moment was its
    cap plus mu F_n delta/2 (9.2e-4 of M_0 here) at the first row, above its own cap M_0 =
    (delta_roll/3) r |F_n|.  The two engines' trajectories part after the first step (pair
    granular's lever r - delta/2 between the discs, ballast's r): so the first row against
    ballast, and every row against the cap of LAMMPS's own normal force."""
    import subprocess
    sets = ["material.grain.friction=0.5"]
    out = tmp_path / "lammps"
    assert make_run(Lammps(), ROLLING_FLOOR, sets, "run", out, BALLAST) == 0
    info = json.loads((out / "run.json").read_text())
    assert info["status"] == "ok", info.get("message")
    subprocess.run([str(BALLAST), "run", str(ROLLING_FLOOR), "--out", str(tmp_path / "ballast"),
                    "--set", sets[0]], check=True, capture_output=True)
    a, b = read_series(out / "series.tsv"), read_series(tmp_path / "ballast" / "series.tsv")
    m0 = 409600 / 1024 * 1.6 / 6
    assert abs(b["fs_floor"][0]) == pytest.approx(0.5 * b["fn_floor"][0])     # sliding at the start
    assert abs(a["m_floor"][0] - b["m_floor"][0]) <= FLOOR_ROUNDOFF * m0
    cap = 1.6 / 3 * 0.5 * np.abs(a["fn_floor"])
    capped = a["cap_floor"] > 0
    assert 0 < np.sum(capped) < len(capped)
    assert np.max(np.abs(np.abs(a["m_floor"][capped]) - cap[capped])) <= FLOOR_ROUNDOFF * m0
    assert np.all(np.abs(a["m_floor"][~capped]) < cap[~capped])
