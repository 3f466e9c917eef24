"""harness/peer/rolling.py (the case peer_rolling): the mapping of JYH's Model 1 onto LAMMPS's
pair granular `rolling sds` with hand values, the inputs it writes to both codes, the
conventions by which it reads their outputs, its figures and verdicts, and the skip path
when LAMMPS is absent (for peer_check too); harness/peer as a package run with python3 -m.
No LAMMPS run here; the skip path runs nothing either."""
import ast
import json
import math
import pathlib
import re
import subprocess
import sys

import numpy as np
import pytest

from harness.compare import RunStore, evaluate_check
from harness.errors import RunSkipped
from harness.peer import check, common, rolling
from harness.references import load_file
from harness.runner import Job, command
from harness.tables import load_run

ROOT = pathlib.Path(__file__).resolve().parents[2]
PEER = ROOT / "harness" / "peer"


# ---- the mapping ------------------------------------------------------------------------

def test_lammps_coefficients_of_delta_08_by_hand():
    m = rolling.lammps_rolling(0.8, 1e5, mu_n=100.0)
    assert m["k_roll"] == pytest.approx(1e5 * 0.64 / 3)          # 21333.3
    assert m["mu_roll"] == pytest.approx(0.8 / 3)                # 0.26667
    assert m["gamma_roll"] == pytest.approx(100.0 * 0.64 / 3)    # 21.333
    assert rolling.lammps_rolling(0.8, 1e5)["gamma_roll"] == 0.0


def test_two_discs_constants_by_hand_agree_in_both_codes():
    # r1 = 0.5, r2 = 0.75: JYH r = 2 r1 r2/(r1 + r2) = 0.6, B = 0.8 r = 0.48,
    # K_m = 1e5 * 0.48^2 / 12 = 1920, M_0 / F_n = B/6 = 0.08, mu_m = 100 * 0.48^2/12 = 1.92;
    # LAMMPS's R_eff = 0.3: k_roll R_eff^2 = 21333.3 * 0.09 = 1920, mu_roll R_eff = 0.08.
    c = rolling.contact_constants(0.8, 1e5, 0.5, 0.75, mu_n=100.0)
    assert (c["r"], c["R_eff"]) == pytest.approx((0.6, 0.3))
    assert (c["B"], c["K_m"], c["M0_per_Fn"], c["mu_m"]) == pytest.approx((0.48, 1920.0, 0.08, 1.92))
    assert c["k_roll_R2"] == pytest.approx(c["K_m"], rel=1e-15)
    assert c["mu_roll_R"] == pytest.approx(c["M0_per_Fn"], rel=1e-15)
    assert c["gamma_roll_R2"] == pytest.approx(c["mu_m"], rel=1e-15)


def test_a_flat_wall_takes_the_same_coefficients():
    # JYH r = 2 r1 = 1 against a wall (eq. 11b), B = 0.8; LAMMPS's R_eff = r1 = 0.5:
    # K_m = 1e5 * 0.64 / 12 = 5333.3 = k_roll * 0.25, M_0 / F_n = 0.8/6 = mu_roll * 0.5.
    c = rolling.contact_constants(0.8, 1e5, 0.5)
    assert (c["r"], c["R_eff"], c["B"]) == pytest.approx((1.0, 0.5, 0.8))
    assert c["K_m"] == pytest.approx(1e5 * 0.64 / 12) == pytest.approx(c["k_roll_R2"])
    assert c["M0_per_Fn"] == pytest.approx(0.8 / 6) == pytest.approx(c["mu_roll_R"])


@pytest.mark.parametrize("r1,r2", [(0.5, 0.5), (0.5, 0.75), (0.1, 7.0), (1e-3, 1.0)])
def test_one_atom_type_serves_every_pair_of_radii(r1, r2):
    c = rolling.contact_constants(0.3, 2e7, r1, r2, mu_n=5.0)
    assert c["r"] == pytest.approx(2 * c["R_eff"], rel=1e-15)
    assert c["k_roll_R2"] == pytest.approx(c["K_m"], rel=1e-14)
    assert c["mu_roll_R"] == pytest.approx(c["M0_per_Fn"], rel=1e-14)
    assert c["gamma_roll_R2"] == pytest.approx(c["mu_m"], rel=1e-14)


# ---- the inputs ------------------------------------------------------------------------------

def commands(text):
    return [line.split("#")[0].split() for line in text.splitlines() if line.split("#")[0].strip()]


def translated(tmp_path, state, box, dt, steps, **scene):
    """The LAMMPS input the translation (engines/lammps.py) writes for the scene rolling.py writes."""
    from harness.engines import lammps, scene as scenes
    path = tmp_path / "t.scene"
    path.write_text(common.ballast_scene(state, box, dt, steps, "t", rolling=rolling.DELTA, **scene))
    sc = scenes.read(path)
    scenes.resolve(sc, ROOT / "bin" / "ballast", tmp_path / "work")
    plan = lammps.Lammps().plan(sc, "run", dumps=False, skin=0.25)
    assert not plan.refused()
    return lammps.translate(sc, plan.options["lammps"])


def test_lammps_input_has_the_mapped_rolling_all_pairs_and_no_sorting(tmp_path):
    state = rolling.state_of([2.0, 5.0], [2.0, 2.0], [0.5, 0.75], [0.1, 0.0], [0.0, 0.0], [1.0, 0.0])
    text = translated(tmp_path, state, (0.0, 36.0, 0.0, 21.5), 7.9e-4, 500, mu=0.5, g=9.81)
    cmds = commands(text)
    coeff = next(c for c in cmds if c[0] == "pair_coeff")
    assert coeff == ["pair_coeff", "1", "1", "hooke", "100000.0", "0.0", "tangential", "linear_history",
                     "100000.0", "0.0", "0.5", "rolling", "sds", repr(1e5 * (0.8 * 0.8) / 3), "0.0",
                     repr(0.8 / 3), "damping", "velocity"]
    assert ["pair_style", "granular"] in cmds and ["atom_modify", "map", "array", "sort", "0", "0.0"] in cmds
    assert next(c for c in cmds if c[0] == "neighbor")[2] == "nsq"
    walls = [c for c in cmds if c[0] == "fix" and c[3] == "wall/gran/region"]
    assert len(walls) == 4 and {w[4] for w in walls} == {"granular"}
    for w in walls:
        assert w[w.index("rolling"):w.index("rolling") + 5] == coeff[11:16]
    assert next(c for c in cmds if c[:2] == ["fix", "integrate"])[-1] == "disc"


def test_lammps_input_walls_without_rolling_and_with_damping(tmp_path):
    state = rolling.state_of([0.49, 1.73], [1.0, 1.0], [0.5, 0.75], [0.0, 0.0], [0.0, 0.0], [3.0, 0.0])
    text = translated(tmp_path, state, (0.0, 2.47, 0.0, 3.0), 1e-4, 10, mu=0.0, g=0.0,
                      wall_rolling=0.0, beta=1e-3)
    cmds = commands(text)
    coeff = next(c for c in cmds if c[0] == "pair_coeff")
    assert coeff[5] == "100.0" and coeff[9] == "1.0"              # eta_n = beta k_n, x_gamma = 1
    assert float(coeff[14]) == pytest.approx(100.0 * 0.64 / 3)    # gamma_roll = eta_n delta^2/3
    walls = [c for c in cmds if c[0] == "fix" and c[3] == "wall/gran/region"]
    assert walls and all("rolling" not in w and w[7] == "100.0" for w in walls)   # eta_n


def sections(text):
    out = []
    for line in text.splitlines():
        line = line.split("#")[0].strip()
        if not line:
            continue
        if line.startswith("["):
            out.append((line, {}))
        else:
            k, v = (p.strip() for p in line.split("=", 1))
            out[-1][1][k] = v
    return out


def test_ballast_scene_with_rolling_damping_and_probes():
    state, box = rolling.two_disc_state(20.0)
    secs = sections(common.ballast_scene(state, box, 1e-4, 1200, "t", mu=0.0, g=0.0, rolling=0.8,
                                       wall_rolling=0.0, output_every=1, probes=rolling.TWO_PROBES,
                                       beta=1e-3))
    d = dict(secs)
    assert d["[settings]"]["rolling_model"] == "model1" and d["[settings]"]["beta"] == "0.001"
    assert d["[settings]"]["output_every"] == "1" and d["[settings]"]["gravity"] == "0 -0.0"
    assert d["[material grain]"]["rolling"] == "0.8" and "rolling" not in d["[material box]"]
    assert d["[probe m]"] == {"quantity": "contact_mr", "a": "d0", "b": "d1"}
    assert d["[probe w1]"] == {"quantity": "disc_omega", "a": "d1"}
    assert [h for h, _ in secs].index("[stage race]") < [h for h, _ in secs].index("[probe m]")
    plain = dict(sections(common.ballast_scene(state, box, 1e-4, 5, "t")))   # the race's: no rolling
    assert "rolling_model" not in plain["[settings]"] and "rolling" not in plain["[material grain]"]
    assert plain["[settings]"]["beta"] == "0"


def test_two_disc_state_balances_every_overlap():
    state, (xlo, xhi, ylo, yhi) = rolling.two_disc_state(20.0)
    (xa, xb), (ra, rb) = state["x"], state["r"]
    overlaps = (ra - (xa - xlo), ra + rb - (xb - xa), rb - (xhi - xb))
    assert overlaps == pytest.approx((rolling.TWO_OVERLAP,) * 3, abs=1e-15)
    assert state["omega"].tolist() == [20.0, 0.0] and state["y"][0] - rb > ylo and state["y"][0] + rb < yhi


# ---- reading the outputs ---------------------------------------------------------------------

CONTACTS = """a\tb\tkind\tx\ty\tnx\tny\tfn\tfs\tdn\tds\tsliding\tmr\tmd\ttheta_r\trolling
d1\td0\tdisc\t0.5\t0\t-1\t0\t10\t2\t0\t0\t0\t3\t0.5\t0.01\t1
d0\tbottom\twall\t0\t-0.5\t0\t-1\t5\t0\t0\t0\t0\t-1\t0\t-0.002\t0
"""


def test_ballast_forces_add_the_rolling_couples_and_take_lammps_arm(tmp_path):
    # d0 at the origin, d1 at (0.9, 0): overlap 0.6 + 0.6 - 0.9 = 0.3.  Row 1: a = d1 gets
    # fs r - (mr + md) = 2 * 0.6 - 3.5, b = d0 gets 2 * 0.6 + 3.5; at LAMMPS's arm each r is
    # r - 0.15.  Row 2: the wall couple -(mr + md) = +1 on d0.
    s = {"x": np.array([0.0, 0.9]), "y": np.zeros(2), "r": np.array([0.6, 0.6]), "m": np.zeros(2)}
    contacts = tmp_path / "contacts.tsv"
    contacts.write_text(CONTACTS)
    _, _, tq, pairs = common.ballast_forces(s, contacts, g=0.0)
    assert tq.tolist() == pytest.approx([1.2 + 3.5 + 1, 1.2 - 3.5])
    _, _, tq, _ = common.ballast_forces(s, contacts, g=0.0, arm="contact")
    assert tq.tolist() == pytest.approx([2 * 0.45 + 3.5 + 1, 2 * 0.45 - 3.5])
    assert pairs == {(0, 1): (10.0, -2.0)}
    assert rolling.ballast_couples(contacts) == {(0, 1): 3.5}     # on d0, the lower id


def test_lammps_couples_from_the_rolling_pseudo_force():
    # atoms 1 (r 0.5) at the origin and 2 (r 0.75) at (1.2, 0): R_eff = 0.3.  For (i, j) =
    # (2, 1), n = (1, 0) and F_roll = (0, 10): the couple on 2 is R_eff (n x F)_z = 3, on the
    # lower id (atom 1, 0-based 0) -3.
    atoms = {"id": np.array([1.0, 2.0]), "x": np.array([0.0, 1.2]), "y": np.zeros(2),
             "radius": np.array([0.5, 0.75])}
    local = {"c_ids[1]": np.array([2.0, 1.0]), "c_ids[2]": np.array([1.0, 2.0]),
             "c_pairs[2]": np.array([10.0, 0.0]), "c_pairs[6]": np.array([0.0, 0.0]),
             "c_pairs[7]": np.array([10.0, 0.0])}
    assert rolling.lammps_couples(local, atoms) == {(0, 1): pytest.approx(-3.0)}
    assert rolling.lammps_couples({}, atoms) == {}


def test_parse_frames_reads_every_frame_in_order():
    frame = "ITEM: TIMESTEP\n{s}\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS ff ff pp\n0 1\n0 1\n0 1\n" \
            "ITEM: ATOMS id omegaz\n1 {w}\n"
    frames = common.parse_frames(frame.format(s=0, w=1.5) + frame.format(s=1, w=2.5))
    assert [(f["_step"], f["omegaz"].tolist()) for f in frames] == [(0, [1.5]), (1, [2.5])]
    with pytest.raises(ValueError, match="cut short"):
        common.parse_frames(frame.format(s=0, w=1) + frame.format(s=1, w=2).rsplit("\n", 2)[0])


# ---- figures and verdicts --------------------------------------------------------------------

def test_two_disc_figures_and_verdicts():
    cycle = np.arange(0.0, 1201.0)
    m = np.minimum(cycle * 0.5, 80.0)
    m[300:] = 40.0
    capped = ((cycle >= 160) & (cycle < 300)).astype(float)
    capped[700] = 1                                          # a turning point touching the cap
    w0, w1 = np.full(1201, 20.0), np.zeros(1201)
    frames = {int(s): {"_step": int(s), "id": np.array([2.0, 1.0]), "omegaz": np.array([0.0, 20.0]),
                       "tqz": np.array([m[int(s)], -m[int(s)]])} for s in cycle}
    frames[600]["omegaz"] = np.array([0.0, 20.0 + 1e-9])
    c = rolling.two_disc_figures(cycle, m, capped, w0, w1, frames, m0=80.0, omega0=20.0)
    assert c["compared"] == 1200 and c["max_dM"] == 0 and c["max_dw"] == pytest.approx(5e-11)
    assert (c["peak"], c["capped"], c["plastic_end"]) == (1.0, 141, 299)
    assert rolling.two_disc_verdict(c)
    assert not rolling.two_disc_verdict(dict(c, max_dw=2e-10))
    assert not rolling.two_disc_verdict(dict(c, plastic_end=1100))  # never unloaded
    assert not rolling.two_disc_verdict(c, damped=True)             # damped must stay elastic
    assert rolling.two_disc_verdict(dict(c, capped=0, peak=0.42, plastic_end=-1), damped=True)


def test_collision_figures_want_first_order_in_the_overlap():
    runs = {1: dict(diff=1.4e-3, overlap=4.66e-3, capped=60, sliding=46),
            4: dict(diff=0.69e-3, overlap=2.3e-3, capped=59, sliding=46),
            16: dict(diff=0.348e-3, overlap=1.2e-3, capped=59, sliding=46)}
    c = rolling.collision_figures(runs)
    assert (c["ratio_k4"], c["ratio_k16"]) == pytest.approx((0.69 / 1.4, 0.348 / 0.69))
    assert c["bound"] == pytest.approx(4.66e-3 / 1.0)               # overlap / (2 r_min)
    assert rolling.collision_verdict(c)
    runs[16]["diff"] = 0.69e-3                                      # does not fall: O(1)
    assert not rolling.collision_verdict(rolling.collision_figures(runs))


def test_check_outputs_one_column_per_figure():
    res = {"two_discs": dict(max_dM=1e-14, max_dw=2e-14, peak=1.0, capped=196, plastic_end=215),
           "two_damped": dict(max_dM=1e-15, max_dw=2e-15, peak=0.42, capped=0),
           "packing": dict({k: 1e-12 for k in rolling.PACK_FIGURES}, contacts_ballast=17,
                           contacts_only_one=0, rolling_contacts=17, at_cap=3, n=300),
           "collision": {"diff_k1": 1.4e-3, "diff_k4": 7e-4, "diff_k16": 3.5e-4, "ratio_k4": 0.5,
                         "ratio_k16": 0.5, "bound": 4.7e-3, "capped": 60, "sliding": 46},
           "friction_packing": {k: 1e-3 for k in rolling.PACK_FIGURES}}
    series, info = rolling.check_outputs(res, True)
    head, row = series.splitlines()
    names, values = head.split("\t"), [float(v) for v in row.split("\t")]
    assert names[:2] == ["cycle", "time"] and len(names) == len(values) == len(set(names))
    assert values[names.index("two_discs_plastic_end")] == 215
    assert values[names.index("collision_ratio_k16")] == 0.5
    assert values[names.index("packing_max_dM")] == 1e-12
    assert info["status"] == "ok" and info["n_discs"] == 300
    assert rolling.check_outputs(res, False)[1]["status"] == "failed"


def test_every_column_the_references_read_is_written():
    """reference/peer_rolling.ref reads only columns that check_outputs() writes."""
    ref = (ROOT / "reference" / "peer_rolling.ref").read_text()
    read = set(re.findall(r"last\((\w+)\)", ref))
    written = {f"{t}_{k}" for t, k in rolling.COLUMNS}
    assert read and read <= written


# ---- the skip path: no LAMMPS -------------------------------------------------------------

@pytest.fixture
def no_lammps(tmp_path):
    """Codes with no lmp on PATH and an install that fails."""
    return common.Codes(ROOT / "bin" / "ballast", "lmp-that-is-not-installed",
                        (str(tmp_path / "no-apt-get"), "install", "lammps"))


def test_lammps_problem_says_why(no_lammps, capsys):
    problem = common.lammps_problem(no_lammps)
    assert "LAMMPS is not installed (no `lmp-that-is-not-installed` on PATH)" in problem
    assert "no-apt-get install lammps` failed" in problem


def test_a_lammps_without_the_styles_is_a_problem(tmp_path):
    fake = tmp_path / "lmp"
    fake.write_text("#!/bin/sh\necho 'Installed packages:'\necho 'GRANULAR'\necho 'gran/hooke'\n")
    fake.chmod(0o755)
    codes = common.Codes(ROOT / "bin" / "ballast", str(fake))
    assert "lacks the GRANULAR package's granular" in common.lammps_problem(codes, ("granular",))
    assert "gran/hooke/history" in common.lammps_problem(codes)


@pytest.mark.skipif(not (ROOT / "bin" / "ballast").exists(), reason="bin/ballast not built")
def test_without_lammps_the_case_is_skipped_not_failed(no_lammps, tmp_path, capsys):
    out = tmp_path / "run"
    assert rolling.run(out, no_lammps) == 0
    assert "peer rolling: skipped: LAMMPS is not installed" in capsys.readouterr().out
    info = json.loads((out / "run.json").read_text())
    assert info["status"] == "skipped" and "LAMMPS is not installed" in info["message"]
    assert (out / "series.tsv").read_text() == "cycle\ttime\n"
    assert not (out / "work").exists()                         # nothing ran
    with pytest.raises(RunSkipped, match="skipped: LAMMPS is not installed"):
        load_run(out)


def test_a_skipped_run_makes_its_checks_skip(tmp_path):
    folder = tmp_path / "peer_rolling" / "check"
    folder.mkdir(parents=True)
    series, info = common.skip_outputs("LAMMPS is not installed")
    common.write_outputs(folder, series, info)
    first = load_file(ROOT / "reference" / "peer_rolling.ref")[0]
    verdict = evaluate_check(first, RunStore(lambda case, variant: tmp_path / case / variant))
    assert verdict.skipped and verdict.result == "SKIP" and not verdict.passed
    assert "LAMMPS is not installed" in verdict.message


def test_the_cross_check_skips_too(no_lammps, tmp_path):
    out = tmp_path / "check"
    assert check.run(out, no_lammps) == 0
    assert json.loads((out / "run.json").read_text())["status"] == "skipped"
    assert not (out / "ballast").exists() and not (out / "work").exists()   # nothing ran


# ---- harness/peer as a package ----------------------------------------------------------------

def test_the_package_edits_no_sys_path_and_reassigns_no_global():
    """The modules share common.py by import: none edits sys.path, declares a global or sets
    an attribute of another module (the binary is an argument, Codes)."""
    imported = subprocess.run(
        [sys.executable, "-c", "import sys; before = list(sys.path); "
         "import harness.peer.race, harness.peer.rolling, harness.peer.check; "
         "print(sys.path == before)"], cwd=ROOT, capture_output=True, text=True, check=True)
    assert imported.stdout.strip() == "True"
    for path in PEER.glob("*.py"):
        tree = ast.parse(path.read_text())
        modules = {alias.asname or alias.name for node in ast.walk(tree)
                   if isinstance(node, (ast.Import, ast.ImportFrom)) for alias in node.names}
        assert not [n for n in ast.walk(tree) if isinstance(n, ast.Global)], path.name
        for node in ast.walk(tree):
            targets = node.targets if isinstance(node, ast.Assign) else []
            for t in targets:
                assert not (isinstance(t, ast.Attribute) and isinstance(t.value, ast.Name)
                            and t.value.id in modules), f"{path.name}:{node.lineno}"


def test_the_runners_command_line_runs_the_modules_from_the_run_folder(tmp_path):
    """The case commands run `python3 -m harness.peer.MODULE` with the run's folder as the
    working directory (runner._execute): the module must be found from there, and get
    the repository's bin/ballast."""
    for kind, module in (("peer", "check"), ("peer_rolling", "rolling")):
        job = Job(kind, "check", tmp_path / "x.scene", [], tmp_path / kind, command=kind)
        cmd = command(job, "some/other/ballast")
        assert cmd[cmd.index("-m") + 1] == f"harness.peer.{module}"
        assert cmd[cmd.index("--ballast") + 1] == str(ROOT / "bin" / "ballast")
        done = subprocess.run(cmd + ["--help"], cwd=tmp_path, capture_output=True, text=True)
        assert done.returncode == 0 and "--lmp" in done.stdout, done.stderr
    assert math.isclose(rolling.KN, common.KN) and rolling.MU == common.MU
