"""harness/peer (`make bench-peer`, the case peer_check): the pure functions of common.py,
check.py and race.py -- the ballast scene and the LAMMPS data file and input they write, the
ballast tables and LAMMPS logs and dumps they read, the force and contact conventions of the
cross-check, the figures they print.  No LAMMPS run here; two tests run bin/ballast for a
few steps (skipped when it is not built)."""
import json
import math
import pathlib
import re
import subprocess

import numpy as np
import pytest

from harness.errors import EvalError
from harness.peer import check, common, race

ROOT = pathlib.Path(__file__).resolve().parents[2]


DISCS_TSV = """id\tname\tx\ty\tr\ttheta\tvx\tvy\tomega\tm\tfixed\trow
0\tpack.0\t0.75\t0.75\t0.71446355575280451\t0\t-0.46814171083186601\t-0.81888515416587193\t0\t1.603651644687544\t0\t-1
1\tpack.1\t2.25\t0.75\t0.59619360480192629\t0\t-0.23386246907599348\t-1.5658418684568731\t0.5\t1.116669100882032\t0\t-1
"""

# walls.tsv of a 36 x 21.5 fill box, as ballast prints it (cos 90 deg is not 0).
WALLS_TSV = """name\tax\tay\tbx\tby\tf1\tf2\tmoment\tecc
pack_bottom\t0\t0\t36\t0\t0\t0\t0\t0
pack_right\t36\t0\t36\t21.5\t0\t0\t0\t0
pack_top\t0\t21.5\t36\t21.5\t0\t0\t0\t0
pack_left\t0\t0\t1.3164953090834046e-15\t21.5\t0\t0\t0\t0
"""

LOG = """LAMMPS (29 Sep 2021 - Update 2)
Reading data file ...
Setting up Verlet run ...
Step Atoms KinEng
       0    20000            0
    3000    20000   0.12345
Loop time of 6.61234 on 1 procs for 3000 steps with 20000 atoms

Performance: 35738.138 tau/day, 521.823 timesteps/s
Total # of neighbors = 49176
Ave neighs/atom = 2.4588000
Neighbor list builds = 486
Dangerous builds = 0
Total wall time: 0:00:07
"""

DUMP = """ITEM: TIMESTEP
0
ITEM: NUMBER OF ATOMS
2
ITEM: BOX BOUNDS ff ff pp
-2 38
-2 23.5
-0.5 0.5
ITEM: ATOMS id x y fx
1 0.75 0.75 0
2 2.25 0.75 0
ITEM: TIMESTEP
400
ITEM: NUMBER OF ATOMS
2
ITEM: BOX BOUNDS ff ff pp
-2 38
-2 23.5
-0.5 0.5
ITEM: ATOMS id x y fx
2 2.5 0.5 -1.5
1 1.0000000000000002 0.25 1.5
"""

LOCAL = """ITEM: TIMESTEP
400
ITEM: NUMBER OF ENTRIES
2
ITEM: BOX BOUNDS ff ff pp
-2 38
-2 23.5
-0.5 0.5
ITEM: ENTRIES c_ids[1] c_ids[2] c_pairs[1] c_pairs[2] c_pairs[3] c_pairs[4] c_pairs[5]
2 1 1 10 0 -2 2
1 3 1.4 0 0 0 0
"""


@pytest.fixture
def tsv(tmp_path):
    """write(text, name): the text as the file tmp_path/name (a ballast table); its path."""
    def write(text, name="table.tsv"):
        path = tmp_path / name
        path.write_text(text)
        return path
    return write


def state_of(x, y, r, vx=None, vy=None, omega=None, density=1.0):
    x, y, r = (np.asarray(a, dtype=float) for a in (x, y, r))
    zero = np.zeros_like(x)
    return {"x": x, "y": y, "r": r,
            "vx": zero.copy() if vx is None else np.asarray(vx, float),
            "vy": zero.copy() if vy is None else np.asarray(vy, float),
            "omega": zero.copy() if omega is None else np.asarray(omega, float),
            "m": density * math.pi * r * r}


# ---- reading ballast's outputs ---------------------------------------------------------

def test_disc_state_reads_discs_tsv_to_full_precision(tsv):
    s = common.disc_state(tsv(DISCS_TSV))
    assert s["r"][0] == 0.71446355575280451 and s["vy"][1] == -1.5658418684568731
    assert s["omega"].tolist() == [0.0, 0.5] and s["x"].tolist() == [0.75, 2.25]


def test_disc_state_refuses_held_discs(tsv):
    with pytest.raises(ValueError, match="held"):
        common.disc_state(tsv(DISCS_TSV.replace("\t0\t-1\n", "\t1\t-1\n", 1)))


def test_ballast_tables_refuse_ragged_rows_and_missing_columns(tsv):
    ragged = tsv(DISCS_TSV + "2\tpack.2\t1\t1\n", "discs.tsv")
    with pytest.raises(EvalError, match=r"discs.tsv:4: 4 fields, header has 12"):
        common.disc_state(ragged)
    with pytest.raises(EvalError, match="column.*missing.*omega"):
        common.disc_state(tsv(DISCS_TSV.replace("\tomega\t", "\tw\t"), "discs.tsv"))


def test_box_of_walls_snaps_the_vertical_walls_and_orders_the_sides(tsv):
    assert common.box_of_walls(tsv(WALLS_TSV)) == (0.0, 36.0, 0.0, 21.5)


def test_box_of_walls_refuses_a_tilted_wall_a_short_wall_and_a_fifth_wall(tsv):
    with pytest.raises(ValueError, match="neither"):
        common.box_of_walls(tsv(WALLS_TSV.replace("pack_top\t0\t21.5\t36\t21.5", "pack_top\t0\t21\t36\t21.5")))
    with pytest.raises(ValueError, match="span"):
        common.box_of_walls(tsv(WALLS_TSV.replace("pack_top\t0\t21.5\t36", "pack_top\t1\t21.5\t36")))
    with pytest.raises(ValueError, match="box of 4 walls"):
        common.box_of_walls(tsv(WALLS_TSV + "extra\t0\t10\t36\t10\t0\t0\t0\t0\n"))


def test_min_gaps_finds_the_closest_pair_and_the_closest_wall():
    s = state_of([1.0, 2.1, 5.0], [1.0, 1.0, 5.0], [0.5, 0.5, 0.5])
    gap, wall = common.min_gaps(s, (0.0, 10.0, 0.0, 10.0))
    assert gap == pytest.approx(0.1) and wall == pytest.approx(0.5)
    s["x"][1] = 1.9                                            # now they overlap
    assert common.min_gaps(s, (0.0, 10.0, 0.0, 10.0))[0] == pytest.approx(-0.1)
    s["x"][0] = 0.4                                            # and one crosses the left wall
    assert common.min_gaps(s, (0.0, 10.0, 0.0, 10.0))[1] == pytest.approx(-0.1)


# ---- writing the two codes' inputs ----------------------------------------------------

def sections(text):
    """A ballast scene -> [(header, {key: value})] in file order."""
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


def test_ballast_scene_lists_every_disc_exactly_with_the_race_physics(tsv):
    s = common.disc_state(tsv(DISCS_TSV))
    text = common.ballast_scene(s, (0.0, 36.0, 0.0, 21.5), 7.9e-4, 300, "t")
    secs = sections(text)
    settings = dict(secs)["[settings]"]
    assert settings["normal_law"] == "power" and settings["nu"] == "1" and settings["delta0"] == "1"
    assert settings["beta"] == settings["alpha"] == settings["gamma_n"] == "0"
    assert float(settings["dt"]) == 7.9e-4 and settings["gravity"] == "0 -9.81"
    assert dict(secs)["[material grain]"] == {"kn": "100000.0", "ks": "100000.0", "friction": "0.5",
                                               "density": "1.0"}
    assert "density" not in dict(secs)["[material box]"]
    discs = [(h, kv) for h, kv in secs if h.startswith("[disc ")]
    assert [h for h, _ in discs] == ["[disc d0]", "[disc d1]"]
    for k, (_, kv) in enumerate(discs):                       # strtod reads back the same doubles
        x, y = map(float, kv["x"].split())
        vx, vy = map(float, kv["v"].split())
        assert (x, y, float(kv["r"]), vx, vy, float(kv["omega"])) == \
            (s["x"][k], s["y"][k], s["r"][k], s["vx"][k], s["vy"][k], s["omega"][k])
        assert kv["material"] == "grain"
    walls = {h: kv for h, kv in secs if h.startswith("[wall ")}
    assert walls["[wall right]"] == {"p": "36.0 0.0", "angle": "90", "h1": "0", "h2": "21.5",
                                     "material": "box"}
    assert walls["[wall top]"]["p"] == "0.0 21.5" and walls["[wall top]"]["h2"] == "36.0"
    assert secs[-1] == ("[stage race]", {"cycles": "300"})


def test_ballast_scene_friction_can_be_switched_off(tsv):
    s = common.disc_state(tsv(DISCS_TSV))
    secs = dict(sections(common.ballast_scene(s, (0, 1, 0, 1), 1e-3, 5, "t", mu=0.0)))
    assert secs["[material grain]"]["friction"] == secs["[material box]"]["friction"] == "0.0"


def test_the_cross_check_scene_translates_to_the_cross_checks_lammps_physics(tsv, tmp_path):
    """The scene check.py writes, through the one translation (engines/lammps.py): the same
    discs in the data file, gran/hooke/history with the scene's k_n, k_t and mu (no damping:
    its arm is r, as ballast's), density/disc, the box walls as region planes on the discs'
    side, gravity, the scene's step, the check's neighbour settings, and the start from v_1/2."""
    from harness.engines import lammps, scene as scenes
    s = common.disc_state(tsv(DISCS_TSV))
    path = tmp_path / "t.scene"
    path.write_text(common.ballast_scene(s, (0.0, 36.0, 0.0, 21.5), 8e-4, 300, "t"))
    sc = scenes.read(path)
    scenes.resolve(sc, ROOT / "bin" / "ballast", tmp_path / "work")
    plan = lammps.Lammps().plan(sc, "run", dumps=False, **check.CHECK_NEIGHBOURS)
    assert not plan.refused()
    opts = plan.options["lammps"]
    lines = lammps.data_text(sc, opts).splitlines()
    atoms = lines[lines.index("Atoms # sphere") + 2:lines.index("Velocities") - 1]
    vels = [l for l in lines[lines.index("Velocities") + 2:] if l]
    assert len(atoms) == len(vels) == 2
    for k in range(2):
        i, t, d, rho, x, y, z = atoms[k].split()
        assert (int(i), int(t), float(rho), float(z)) == (k + 1, 1, 1.0, 0.0)
        assert float(d) / 2 == s["r"][k] and (float(x), float(y)) == (s["x"][k], s["y"][k])
        i, vx, vy, vz, wx, wy, wz = vels[k].split()
        assert (float(vx), float(vy), float(wz)) == (s["vx"][k], s["vy"][k], s["omega"][k])
    text = lammps.translate(sc, opts)
    cmds = [l.split("#")[0].split() for l in text.splitlines() if l.split("#")[0].strip()]
    first = {c[0] + (" " + c[3] if c[0] == "fix" else ""): c for c in cmds}
    assert first["pair_style"] == ["pair_style", "gran/hooke/history", "100000.0", "100000.0",
                                   "0.0", "0.0", "0.5", "0"]
    assert ["set", "type", "1", "density/disc", "1.0"] in cmds
    assert first["fix nve/sphere"][-1] == "disc" and "fix enforce2d" in first
    assert first["fix gravity"][4:] == ["v_gmag", "vector", "0.0", "-1.0", "0.0"]
    assert 'variable        gmag equal "9.81*v_gfac"' in text
    # each wall's plane through its P with the normal towards the discs (P and angle as the
    # core builds the wall: bottom and top at angle 0, right and left at 90)
    planes = np.array([[float(v) for v in c[3:9]] for c in cmds if c[0] == "region"])
    assert planes == pytest.approx(np.array([[0.0, 0.0, 0.0, 0.0, 1.0, 0.0], [36.0, 0.0, 0.0, -1.0, 0.0, 0.0],
                                             [0.0, 21.5, 0.0, 0.0, -1.0, 0.0], [0.0, 0.0, 0.0, 1.0, 0.0, 0.0]]),
                                   abs=1e-16)
    walls = [c for c in cmds if c[0] == "fix" and c[3] == "wall/gran/region"]
    assert len(walls) == 4 and all(w[4:11] == ["hooke/history", "100000.0", "100000.0", "0.0", "0.0",
                                               "0.5", "0"] for w in walls)
    assert first["neighbor"] == ["neighbor", "0.25", "bin"]
    assert first["atom_modify"] == ["atom_modify", "map", "array", "sort", "1000", "0.0"]
    assert first["timestep"] == ["timestep", "0.0008"] and ["run", "300"] in cmds
    assert "velocity        free set v_v0x v_v0y NULL" in text      # v_0 from v_1/2
    # the fixes that set forces come before enforce2d, which zeroes their z parts
    order = [c[3] for c in cmds if c[0] == "fix" and c[1] != "half"]
    assert order[-1] == "enforce2d"


def test_check_output_dumps_forces_torques_and_contacts_to_full_precision():
    text = check.CHECK_OUTPUT.replace("@steps@", "400")
    assert "%.17g" in text and "tqz" in text and "pair/local dist force p1 p2 p4" in text
    assert "property/local patom1 patom2" in text


# ---- reading LAMMPS ---------------------------------------------------------------------

def test_parse_lammps_log_reads_the_loop_time_and_the_neighbour_statistics():
    log = common.parse_lammps_log(LOG)
    assert log == {"version": "29 Sep 2021 - Update 2", "loop_seconds": 6.61234, "procs": 1,
                   "steps": 3000, "atoms": 20000, "builds": 486, "dangerous": 0,
                   "total_seconds": 6.61234, "total_steps": 3000}


def test_parse_lammps_log_takes_the_last_run_and_refuses_a_log_without_one():
    two = LOG.replace("Loop time of 6.61234 on 1 procs for 3000 steps",
                      "Loop time of 1.5 on 1 procs for 10 steps with 20000 atoms\n"
                      "Loop time of 6.61234 on 1 procs for 3000 steps")
    assert common.parse_lammps_log(two)["loop_seconds"] == 6.61234
    with pytest.raises(ValueError, match="Loop time"):
        common.parse_lammps_log(LOG.replace("Loop time", "Loop"))


def test_parse_dump_takes_the_last_frame_of_custom_and_local_dumps():
    d = common.parse_dump(DUMP)
    assert d["_step"] == 400 and d["id"].tolist() == [2, 1]
    assert d["x"][1] == 1.0000000000000002 and d["fx"].tolist() == [-1.5, 1.5]
    l = common.parse_dump(LOCAL)
    assert l["c_ids[1]"].tolist() == [2, 1] and l["c_pairs[4]"].tolist() == [-2, 0]
    with pytest.raises(ValueError, match="no frame"):
        common.parse_dump("")
    with pytest.raises(ValueError, match="rows"):
        common.parse_dump(DUMP.rsplit("\n", 2)[0] + "\n")


# ---- the cross-check's conventions --------------------------------------------------------

def contacts_tsv(*rows):
    head = "a\tb\tkind\tx\ty\tnx\tny\tfn\tfs\tdn\tds\tsliding\n"
    return head + "".join("\t".join(str(c) for c in row) + "\n" for row in rows)


def test_ballast_forces_follow_contacts_tsv_conventions(tsv):
    # d1 at (1, 0) touches d0 at the origin: a = d1, b = d0, e = (-1, 0) from a to b,
    # t_ab = (ny, -nx) = (0, 1).  Force on a = -fn e - fs t_ab = (10, -2); on b the opposite.
    # d0 also rests on a wall below it: e = (0, -1), t = (-1, 0): force on d0 = (3, 5).
    s = state_of([0.0, 1.0], [0.0, 0.0], [0.6, 0.6], density=0.0)
    text = contacts_tsv(("d1", "d0", "disc", 0.5, 0, -1, 0, 10, 2, 0, 0, 0),
                        ("d0", "bottom", "wall", 0, -0.55, 0, -1, 5, 3, 0, 0, 1))
    fx, fy, tq, pairs = common.ballast_forces(s, tsv(text), g=9.81)
    assert fx.tolist() == [-10 + 3, 10] and fy.tolist() == [2 + 5, -2]
    assert tq.tolist() == [2 * 0.6 + 3 * 0.6, 2 * 0.6]
    # f_t is the tangential force on the lower id along t = (e_y, -e_x), e from lower to
    # higher: e = (1, 0), t = (0, -1), and the force on d0 is (0, 2) -> f_t = -2.
    assert pairs == {(0, 1): (10.0, -2.0)}


def test_ballast_forces_add_gravity_and_dashpots(tsv):
    s = state_of([0.0, 1.0], [0.0, 0.0], [0.5, 0.5], density=2.0)
    fx, fy, tq, pairs = common.ballast_forces(s, tsv(contacts_tsv(
        ("d0", "d1", "disc", 0.5, 0, 1, 0, 4, 0, 1, 0.5, 0))), g=10.0)
    assert fx.tolist() == [-5, 5] and tq.tolist() == [0.25, 0.25]
    assert fy.tolist() == pytest.approx([0.5 - 10 * s["m"][0], -0.5 - 10 * s["m"][1]])
    assert pairs == {(0, 1): (4.0, -0.0)}
    assert common.ballast_forces(s, tsv(contacts_tsv(), "none.tsv"), g=1.0)[3] == {}


def test_lammps_pairs_use_the_same_convention_as_ballast():
    # The contact of the test above as LAMMPS reports it: atom 2 (d1) is i, its
    # tangential force is (0, -2), so on atom 1 (d0) it is (0, 2): f_t = -2 again.
    atoms = {"id": np.array([1.0, 2.0]), "x": np.array([0.0, 1.0]), "y": np.array([0.0, 0.0])}
    local = {"c_ids[1]": np.array([2.0, 1.0]), "c_ids[2]": np.array([1.0, 2.0]),
             "c_pairs[2]": np.array([10.0, 0.0]), "c_pairs[3]": np.array([0.0, 0.0]),
             "c_pairs[4]": np.array([-2.0, 0.0])}
    assert common.lammps_pairs(local, atoms) == {(0, 1): (10.0, -2.0)}
    local["c_ids[1]"], local["c_ids[2]"] = local["c_ids[2]"].copy(), local["c_ids[1]"].copy()
    local["c_pairs[4]"] = np.array([2.0, 0.0])                # i = atom 1 now
    assert common.lammps_pairs(local, atoms) == {(0, 1): (10.0, -2.0)}
    assert common.lammps_pairs({}, atoms) == {}


def discs_tsv(s):
    rows = ["id\tname\tx\ty\tr\ttheta\tvx\tvy\tomega\tm\tfixed\trow"]
    for k in range(len(s["x"])):
        rows.append("\t".join([str(k), f"d{k}"] + [repr(float(s[c][k])) for c in
                    ("x", "y", "r")] + ["0"] + [repr(float(s[c][k])) for c in
                    ("vx", "vy", "omega", "m")] + ["0", "-1"]))
    return "\n".join(rows) + "\n"


def agreeing_runs(folder):
    """Two touching discs and a free one; ballast's outputs (discs.tsv, contacts.tsv in
    folder) and LAMMPS's agree."""
    init = state_of([0.0, 1.0, 5.0], [0.0, 0.0, 0.0], [0.6, 0.6, 0.5], vx=[0, 0, 1.0])
    final = {k: v.copy() for k, v in init.items()}
    final["omega"] = np.array([0.1, 0.1, 0.0])
    final["vy"][2] = -common.G * 1e-3 / 2                          # free flight for one step of 1e-3
    ctext = contacts_tsv(("d0", "d1", "disc", 0.5, 0, 1, 0, 10, 2, 0, 0, 0))
    (folder / "contacts.tsv").write_text(ctext)
    (folder / "discs.tsv").write_text(discs_tsv(final))
    fx, fy, tq, _ = common.ballast_forces(final, folder / "contacts.tsv")
    atoms = {"id": np.array([3.0, 1.0, 2.0]), "_step": 1}
    perm = [2, 0, 1]                                           # LAMMPS's dump order
    for name, col in (("x", "x"), ("y", "y"), ("vx", "vx"), ("vy", "vy"), ("omegaz", "omega"),
                      ("mass", "m")):
        atoms[name] = final[col][perm].copy()
    atoms["fx"], atoms["fy"], atoms["tqz"] = fx[perm], fy[perm], tq[perm]
    local = {"c_ids[1]": np.array([1.0]), "c_ids[2]": np.array([2.0]),
             "c_pairs[2]": np.array([10.0]), "c_pairs[3]": np.array([0.0]),
             "c_pairs[4]": np.array([2.0])}
    return init, folder, atoms, local


def test_compare_finds_agreement_and_passes(tmp_path):
    init, run, atoms, local = agreeing_runs(tmp_path)
    c = common.compare(init, run, atoms, local, dt=1e-3)
    assert all(c[k] == 0 for k in common.FIGURES)
    assert (c["contacts_ballast"], c["contacts_lammps"], c["contacts_only_one"]) == (1, 1, 0)
    assert c["touched"] == 2 and c["fscale"] == 10 and c["n"] == 3
    assert common.check_verdict(c, check.TOL_EXACT)


def test_compare_measures_differences_in_the_stated_units(tmp_path):
    init, run, atoms, local = agreeing_runs(tmp_path)
    mean_d = 2 * np.mean(init["r"])
    atoms["x"][1] += 1e-6                                      # atom 1 = d0 moved
    atoms["tqz"][2] += 0.5                                     # atom 2 = d1's torque
    local["c_pairs[4]"] = np.array([2.01])                    # its shear force
    c = common.compare(init, run, atoms, local, dt=1e-3)
    assert c["max_dx"] == pytest.approx(1e-6 / mean_d)
    assert c["max_dT"] == pytest.approx(0.5 / (10 * np.mean(init["r"])))
    assert c["max_dfs"] == pytest.approx(0.001) and c["max_dfn"] == 0
    assert not common.check_verdict(c, check.TOL_FRICTION)


def test_compare_fails_when_a_contact_is_in_one_code_only_or_lammps_lost_an_atom(tmp_path):
    init, run, atoms, local = agreeing_runs(tmp_path)
    local["c_pairs[2]"] = np.array([0.0])                     # LAMMPS: not touching
    c = common.compare(init, run, atoms, local, dt=1e-3)
    assert c["contacts_only_one"] == 1 and not common.check_verdict(c, check.TOL_FRICTION)
    init, run, atoms, local = agreeing_runs(tmp_path)
    atoms = {k: (v[:2] if k != "_step" else v) for k, v in atoms.items()}
    with pytest.raises(ValueError, match="lost"):
        common.compare(init, run, atoms, local, dt=1e-3)


def test_check_verdict_needs_contacts_and_finite_figures():
    c = dict.fromkeys(common.FIGURES, 0.0)
    c.update(contacts_ballast=3, contacts_only_one=0, mass_rel=0.0)
    assert common.check_verdict(c, check.TOL_EXACT)
    assert not common.check_verdict(dict(c, contacts_ballast=0), check.TOL_EXACT)
    assert not common.check_verdict(dict(c, max_dv=float("nan")), check.TOL_FRICTION)
    assert not common.check_verdict(dict(c, max_dx=2e-10), check.TOL_EXACT)
    assert common.check_verdict(dict(c, max_dx=2e-10), check.TOL_FRICTION)
    assert not common.check_verdict(dict(c, mass_rel=1e-12), check.TOL_EXACT)


def test_tolerances_are_ordered_round_off_below_friction():
    assert all(check.TOL_EXACT[k] < check.TOL_FRICTION[k] for k in common.FIGURES)
    assert 0.5 < check.TOL_RATIO < 1                            # first order: 0.5 expected


def test_convergence_and_the_check_line():
    full = dict.fromkeys(common.FIGURES, 1e-7)
    half = dict(full, max_dx=4.5e-8, max_dF=6e-8)
    assert check.convergence(full, half) == pytest.approx((0.45, 0.6))
    c = dict(full, n=300, step=400, contacts_ballast=11, contacts_lammps=11, sliding=7, touched=233)
    line = check.check_line(c, True, "friction=0.5", " ratio_dx=0.45")
    assert line == ("peer check friction=0.5 N=300 steps=400 max_dx=1e-07 max_dv=1e-07 "
                    "max_dF=1e-07 max_dT=1e-07 max_dfn=1e-07 max_dfs=1e-07 contacts=11/11 "
                    "sliding=7 touched=233 ratio_dx=0.45 PASS")
    assert check.check_line(c, False, "x").endswith(" FAIL")


# ---- timing figures -------------------------------------------------------------------------

def test_race_line_prints_medians_spreads_ratio_and_the_best_settings():
    best = {"skin": 0.0625, "binsize": 0, "sort_every": 100}
    line = race.race_line("dense", 20000, 3000, [3e7, 2.8e7, 3.5e7, 3.2e7, 3.1e7],
                          [9e6, 9.1e6, 8.5e6, 9.2e6, 9.05e6], best)
    assert line == ("peer dense N=20000 steps=3000 ballast=3.1e+07 [2.8e+07..3.5e+07] "
                    "lammps=9.05e+06 [8.5e+06..9.2e+06] ratio=3.43 "
                    "lammps_best=skin=0.0625,binsize=default,sort=100")
    assert race.settings_label(dict(best, binsize=1.5625)) == "skin=0.0625,binsize=1.562,sort=100"
    assert race.spread([3.0, 1.0, 2.0]) == (2.0, 1.0, 3.0)


def test_append_csv_writes_the_header_once(tmp_path):
    path = tmp_path / "bench" / "host" / "peer.csv"
    race.append_csv(path, ["a", "b"], [1, 2])
    race.append_csv(path, ["a", "b"], [3, "x"])
    assert path.read_text() == "a,b\n1,2\n3,x\n"
    race.append_csv(path, ["a", "b", "c"], [4, 5, 6])            # a new column: a new file
    assert path.read_text() == "a,b,c\n4,5,6\n"
    assert (path.parent / "peer.csv.old").read_text() == "a,b\n1,2\n3,x\n"


def test_sweep_plan_skins_binsizes_and_sorts():
    skins, binsizes, sorts = race.sweep_plan(1.25, 0.75)
    assert skins == pytest.approx([0.0625, 0.125, 0.25, 0.5])
    assert binsizes(0.25) == [0, 1.75]                          # default, then the full cutoff
    assert sorts == [0, 100, 1000]
    q = race.sweep_plan(1.25, 0.75, quick=True)
    assert len(q[0]) == 2 and q[2] == [0, 1000]


def test_docstring_and_constants_agree_on_the_race():
    doc = race.__doc__
    assert "python3 -m harness.peer.race [--quick]" in doc and "peer dense N=20000" in doc
    assert race.RACE_N == 20000 and race.REPEATS == 5 and common.CHECK_N == 300


# ---- the integrator convention the half-kick shift relies on ---------------------------

@pytest.mark.skipif(not (ROOT / "bin" / "ballast").exists(), reason="bin/ballast not built")
def test_ballast_runs_the_written_scene_and_moves_a_free_disc_by_v_half(tmp_path):
    """A free disc under gravity: x_N = x_0 + N dt v_{1/2} - g dt^2 N (N - 1) / 2, the
    sequence LAMMPS's velocity Verlet gives from v_0 = v_{1/2} + g dt / 2."""
    s = state_of([1.0, 4.0], [2.0, 2.0], [0.5, 0.6], vx=[0.3, -0.2], vy=[1.0, 0.0])
    dt, n = 1e-3, 3
    scene = tmp_path / "t.scene"
    scene.write_text(common.ballast_scene(s, (0.0, 6.0, 0.0, 6.0), dt, n, "test"))
    out = tmp_path / "out"
    subprocess.run([str(ROOT / "bin" / "ballast"), "run", str(scene), "--out", str(out)],
                   check=True, capture_output=True)
    final = common.disc_state(out / "discs.tsv")
    assert final["x"] == pytest.approx(s["x"] + n * dt * s["vx"], abs=1e-15)
    assert final["y"] == pytest.approx(s["y"] + n * dt * s["vy"] - 9.81 * dt * dt * n * (n - 1) / 2,
                                       abs=1e-15)
    assert final["m"] == pytest.approx(math.pi * s["r"] ** 2, rel=1e-15)


def test_race_scenes_give_ballast_its_motion_skin_and_the_cross_check_keeps_the_default(tmp_path):
    """The race writes skin_rule = motion (ballast's own choice of skin, issue 24); the
    cross-check's scenes write no skin_rule (the core's default, fixed); ballast reads it
    back into run.json's skin."""
    s = state_of([1.0, 4.0], [2.0, 2.0], [0.5, 0.6])
    assert race.RACE_SKIN_RULE == "motion"
    r = race.Race("settling", tmp_path / "race", s, (0.0, 6.0, 0.0, 6.0), 1e-3, 5,
                  common.Codes(ROOT / "bin" / "ballast"))
    secs = dict(sections(r.scene(5).read_text()))
    assert secs["[settings]"]["skin_rule"] == "motion"
    assert "skin_rule" not in dict(sections(common.ballast_scene(s, (0, 6, 0, 6), 1e-3, 5, "t")))["[settings]"]
    out = tmp_path / "out"
    subprocess.run([str(ROOT / "bin" / "ballast"), "run", str(r.scene(5)), "--out", str(out),
                    "--set", "settings.grid=on"], check=True, capture_output=True)
    run = json.loads((out / "run.json").read_text())
    assert run["skin"] == pytest.approx(0.2 * 0.6, rel=1e-15)  # the first skin: no rebuild yet


def test_extend_skin_goes_past_an_end_only_while_the_end_is_fastest():
    skins = [0.1, 0.2, 0.4]
    assert race.extend_skin(skins, [1, 2, 3], 0.01, 1.0) == pytest.approx(0.6)
    assert race.extend_skin(skins, [3, 2, 1], 0.01, 1.0) == pytest.approx(0.05)
    assert race.extend_skin(skins, [1, 3, 2], 0.01, 1.0) is None
    assert race.extend_skin(skins + [0.6], [1, 2, 3, 2.5], 0.01, 1.0) is None   # 0.6 was slower
    assert race.extend_skin(skins, [1, 2, 3], 0.01, 0.5) is None                # at the limit
    assert race.extend_skin(skins, [3, 2, 1], 0.08, 1.0) is None


class FakeRace:
    """Race.lammps() without LAMMPS: the rate is a function of the settings."""

    def __init__(self, rate):
        self.name, self.n = "fake", 4
        self.state = {"r": np.array([0.5, 0.75, 0.5, 0.75])}    # mean diameter 1.25, r_max 0.75
        self.rate, self.calls = rate, []

    def lammps(self, steps, s):
        self.calls.append(dict(s))
        dangerous = 1 if s["skin"] < 0.05 else 0
        return self.rate(s), {"builds": 7, "dangerous": dangerous}


def test_sweep_keeps_the_fastest_settings_and_records_every_try(tmp_path, capsys):
    # fastest at skin 0.75 (past the planned 0.5), the explicit bin size, no sorting
    rate = lambda s: (10 - abs(s["skin"] - 0.75) + (1 if s["binsize"] else 0)
                      + (0.5 if s["sort_every"] == 0 else 0))
    fake = FakeRace(rate)
    best, tried = race.sweep(fake, 100, False, tmp_path, 123)
    assert best == {"skin": pytest.approx(0.75), "binsize": pytest.approx(2.25), "sort_every": 0}
    skins = [c["skin"] for c in fake.calls]
    assert skins[:4] == pytest.approx([0.0625, 0.125, 0.25, 0.5])
    assert skins[4:6] == pytest.approx([0.75, 1.125])             # extended while the end was best
    assert len(fake.calls) == 6 + 1 + 2                           # skins, one bin size, two sorts
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 9 and lines[0].startswith("peer sweep fake skin=0.0625,binsize=default,sort=1000")
    csv = (tmp_path / "peer_sweep.csv").read_text().splitlines()
    assert csv[0].startswith("unix_time,scene,n,steps,skin") and len(csv) == 10


def test_sweep_never_keeps_settings_with_dangerous_builds(tmp_path, capsys):
    fake = FakeRace(lambda s: 1.0 / s["skin"])                    # the smaller the faster ...
    best, _ = race.sweep(fake, 100, True, tmp_path, 1)
    assert best["skin"] >= 0.05                                    # ... but below 0.05 dangerous


def test_check_outputs_one_row_per_figure():
    """check.py writes the cross-check as a run: one series row, a column per figure
    of each run, the ratios, and run.json saying whether it passed."""
    fig = {k: 0.5 * (i + 1) for i, k in enumerate(common.FIGURES)}
    res = {"friction0": dict(fig, n=300, step=400), "friction": dict(fig, n=300, step=400),
           "half_dt": dict(fig, n=300, step=800), "ratio_dx": 0.455, "ratio_dF": 0.404}
    series, info = check.check_outputs(res, True)
    head, row = series.splitlines()
    names, values = head.split("\t"), [float(v) for v in row.split("\t")]
    assert names[:2] == ["cycle", "time"] and len(names) == len(values)
    assert values[names.index("friction_max_dx")] == fig["max_dx"]
    assert values[names.index("ratio_dF")] == 0.404
    assert info["status"] == "ok" and info["steps"] == 400
    assert check.check_outputs(res, False)[1]["status"] == "failed"
