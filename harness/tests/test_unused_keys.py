"""Keys that other keys make unused (issue 29, item 14), on the real bin/ballast.

The core keeps the rules in one table (bal_scene_unused, core/scene_keys.c); `ballast info`
lists each key given that a rule holds for ("unused  KEY (WHY)"), and `harness sweep` refuses
to sweep such a key (core_info.refuse_bad_points).  A rule there is a claim that the key's
value cannot change the run, so each is tried here: the scene below run with two values of
the key, the rule holding, must give the same outputs bit for bit (run.json but for the
overrides it echoes, the wall clock and the skin it reports); and, the rule not holding, the
two values must differ, so that the scene is one where the key would show.  The table and
this test cannot part: a scene where every rule holds must list exactly RULES.
"""
import json
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BIN = ROOT / "bin" / "ballast"
pytestmark = pytest.mark.skipif(not BIN.exists(), reason="bin/ballast not built")

# Discs falling for 0.73 s: a fill in its box, grains onto a floor, a pile on its own floor
# (in contact from the start: every contact law acts).
SCENE = """\
[settings]
gravity = 0 -10
dt_fraction = 0.5

[material grain]
kn = 1e5
friction = 0.5
density = 1

[material wall]
kn = 1e5
friction = 0.5

[material soft]
kn = 2e4
friction = 0.3

[wall floor]
p = -30 -0.5
angle = 0
h1 = 0
h2 = 60
material = wall

[fill pack]
n = 9
columns = 3
rmin = 0.4
rmax = 0.5
vmax = 0.5
box = 1
material = grain
wall_material = wall

[grains g]
n = 5
origin = 10 0
size = 4 4
dmin = 0.5
d10 = 0.6
d50 = 0.8
d60 = 0.85
dmax = 1
material = grain
wall_material = wall

[pile p]
L = 4
d = 1
origin = -10 0
material = grain
wall_material = wall

[stage fall]
cycles = 3000

[probe ek]
quantity = energy_kinetic

[probe ee]
quantity = energy_elastic
"""

DT = "settings.dt=0.0002"        # below the scene's estimate 4.85e-4 (ballast info)
# (held: overrides under which the rule holds, key, two values, control: overrides under
# which it does not)
RULES = [
    ([DT], "settings.dt_fraction", ("0.3", "0.5"), []),
    ([], "settings.nu", ("1", "2"), ["settings.normal_law=power", "settings.delta0=0.01"]),
    (["settings.gamma_n=0.5"], "settings.delta0", ("0.01", "0.02"),
     ["settings.gamma_n=0.5", "settings.psi=1"]),
    (["settings.psi=1"], "settings.delta0", ("0.01", "0.02"), ["settings.gamma_n=0.5", "settings.psi=1"]),
    ([], "settings.psi", ("0", "1"), ["settings.gamma_n=0.5", "settings.delta0=0.01"]),
    ([], "settings.stress_height", ("0.5", "1"), ["settings.stress_width=1"]),
    ([], "settings.stress_step", ("0.5", "1"), ["settings.stress_width=1"]),
    (["settings.grid=off"], "settings.skin", ("0.01", "0.3"), ["settings.grid=on"]),
    (["settings.grid=off"], "settings.skin_rule", ("fixed", "motion"), ["settings.grid=on", "settings.skin=0.01"]),
    ([], "settings.rolling_model", ("model1", "model2"),
     ["material.grain.rolling=0.5", "material.wall.rolling=0.5"]),
    ([], "stage.fall.check_every", ("10", "37"), ["stage.fall.stop_ke=1e9"]),
    (["fill.pack.box=0"], "fill.pack.headroom", ("0", "0.5"), []),
    (["fill.pack.box=0"], "fill.pack.wall_material", ("wall", "soft"), []),
    ([], "grains.g.overhang", ("-1", "0.5"), ["grains.g.box=1"]),
    ([], "grains.g.wall_material", ("wall", "soft"), ["grains.g.box=1"]),
    (["pile.p.bottom=bumpy"], "pile.p.wall_material", ("wall", "soft"), []),
    ([], "pile.p.c", ("0", "0.2"), ["pile.p.bottom=bumpy"]),
]
OUTPUTS = ("series.tsv", "discs.tsv", "contacts.tsv", "walls.tsv", "stress.tsv", "stress_grid.tsv")
ECHOED = ("sets", "wall_seconds", "timers", "particle_steps_per_s", "skin")


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    path = tmp_path_factory.mktemp("unused") / "unused.scene"
    path.write_text(SCENE)
    return path


def ballast(*args):
    return subprocess.run([str(BIN), *map(str, args)], capture_output=True, text=True, timeout=120)


def unused(scene, sets):
    done = ballast("info", scene, *[a for s in sets for a in ("--set", s)])
    assert done.returncode == 0, done.stderr
    return [line.split()[1] for line in done.stdout.splitlines() if line.startswith("unused ")]


def outcome(scene, sets, out):
    done = ballast("run", scene, "--out", out, *[a for s in sets for a in ("--set", s)])
    assert done.returncode == 0, done.stderr
    record = {k: v for k, v in json.loads((Path(out) / "run.json").read_text()).items() if k not in ECHOED}
    return record, {name: (Path(out) / name).read_bytes() for name in OUTPUTS if (Path(out) / name).exists()}


@pytest.mark.parametrize("held, key, values, control", RULES, ids=[f"{r[1]}-{i}" for i, r in enumerate(RULES)])
def test_an_unused_key_changes_nothing(scene, tmp_path, held, key, values, control):
    a, b = (held + [f"{key}={v}"] for v in values)
    assert key in unused(scene, a) and key in unused(scene, b)
    assert outcome(scene, a, tmp_path / "a") == outcome(scene, b, tmp_path / "b")
    if control is not None:
        c, d = (control + [f"{key}={v}"] for v in values)
        assert key not in unused(scene, c)
        assert outcome(scene, c, tmp_path / "c") != outcome(scene, d, tmp_path / "d"), \
            f"{key} changes nothing even where it is used: the scene cannot show the rule"


def test_every_rule_of_the_core_is_tried_here(scene):
    """With every rule holding (the pile's two rules in turn: its bottom is smooth or bumpy)
    and every key given, info lists exactly the keys above."""
    listed = set()
    for bottom in ("smooth", "bumpy"):
        sets = [DT, "fill.pack.box=0", "settings.grid=off", f"pile.p.bottom={bottom}"]
        sets += sorted({f"{key}={values[0]}" for _, key, values, _ in RULES})
        listed |= set(unused(scene, sets))
    assert sorted(listed) == sorted({key for _, key, _, _ in RULES})


def test_a_key_not_given_is_not_listed(scene):
    """info lists the keys the scene gives: a default left alone is not the user's choice."""
    assert unused(scene, []) == ["grains.g.wall_material"]
