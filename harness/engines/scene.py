"""harness/engines/scene.py -- a ballast scene as another engine needs it: what the scene says
(settings, materials, stages, probes, per-disc materials and holds) and the state it starts
from (every disc and wall, the time step).

Two sources, each for what it is sure of:

- the scene's text, with the run's --set lines applied (read()): the keys an adapter maps
  (docs/scene-format.md; the defaults below are `ballast keys`'s);
- the core itself for the initial state (resolve()): `ballast run SCENE --set ... --set
  stage.S.cycles=0` for every stage writes discs.tsv, walls.tsv and run.json before any
  cycle, so the generators ([fill], [pile], [grains]), the imports, the time step from
  dt_fraction and the piles' geometry (run.json `piles`) are the core's own.  The initial
  state is an input of the comparison, not a result: both engines start from the same
  discs, bit for bit.

Only numpy, the standard library and the harness.
"""
import json
import math
import os
import subprocess
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import files
from ..final_state import Table
from ..ini import strip_comment

# `ballast keys`: the defaults of the [settings] keys an adapter reads.
SETTINGS_DEFAULTS = {
    "dt": "0", "dt_fraction": "0.1", "alpha": "0", "beta": "0", "gravity": "0 0",
    "normal_law": "incremental", "nu": "1", "delta0": "1", "gamma_n": "0", "psi": "0",
    "output_every": "1", "integrator": "centred", "rolling_model": "model1",
    "allow_overlap": "0", "force_dt": "0", "stress_width": "0",
}
MATERIAL_DEFAULTS = {"ks": "-1", "friction": "0", "cohesion": "0", "density": "0", "rolling": "0"}
STAGE_DEFAULTS = {"ramp": "0", "stop_ke": "0", "stop_stress": "0", "check_every": "100",
                  "output_at_end": "0", "stop_servo": "0", "stop_unbalanced": "0"}
# The controls of a stage line: a wall's prescribed motion, a stress servo, a strain rate.
CONTROLS = ("move", "servo", "strain_rate")
GENERATORS = ("fill", "pile", "grains", "import")
DISC_COLUMNS = ("id", "name", "x", "y", "r", "theta", "vx", "vy", "omega", "m", "fixed")


class SceneError(ValueError):
    """A scene an adapter cannot read (a malformed --set line, a disc of unknown material)."""


@dataclass
class Material:
    name: str
    kn: float
    ks: float            # the scene's ks, or kn when it gives none (ks = -1)
    friction: float
    cohesion: float
    density: float
    rolling: float


@dataclass
class Control:
    """One `move`, `servo` or `strain_rate` line of a stage: its kind, wall and numbers."""
    kind: str
    wall: str
    words: list

    def numbers(self, count):
        try:
            return [float(w) for w in self.words[:count]]
        except ValueError:
            raise SceneError(f"{self.kind} = {self.wall} {' '.join(self.words)}: not numbers") from None


@dataclass
class Stage:
    name: str
    cycles: int          # the stage's cycles (time / dt rounded up, as the core does)
    keys: dict           # every key of the stage with its default
    controls: list       # Control per move / servo / strain_rate line

    def number(self, key):
        return float(self.keys[key])


@dataclass
class Probe:
    name: str
    quantity: str
    a: str = ""
    b: str = ""


@dataclass
class Wall:
    name: str
    ax: float
    ay: float
    bx: float
    by: float
    material: str


@dataclass
class Scene:
    """A scene with its --set lines applied, and once resolved its initial state."""
    path: Path
    sets: list
    settings: dict
    materials: dict                      # name -> Material
    stages: list                         # Stage, in order
    probes: list                         # Probe, in order (the columns of series.tsv)
    disc_sections: dict                  # [disc NAME] -> its keys
    generators: dict                     # NAME -> (kind, its keys)
    wall_sections: dict                  # [wall NAME] -> its keys
    discs: dict = None                   # resolve(): discs.tsv columns (name: list, others: arrays)
    disc_material: list = None           # resolve(): each disc's material name
    walls: list = field(default_factory=list)   # resolve(): Wall per wall, in walls.tsv order
    dt: float = 0.0                      # resolve(): the step the core uses
    init_info: dict = None               # resolve(): the 0-cycle run's run.json

    def setting(self, key):
        return self.settings[key]

    def number(self, key):
        return float(self.settings[key])

    def gravity(self):
        gx, gy = (float(w) for w in self.settings["gravity"].split())
        return gx, gy

    @property
    def total_cycles(self):
        return sum(s.cycles for s in self.stages)


# ---------------------------------------------------------------------------------- reading

def _apply_set(sections, line):
    """One --set KEY=VALUE on the parsed sections: settings.KEY, or KIND.NAME.KEY; a stage's
    move/servo/strain_rate replaces that wall's line (the core's rule), cycles replaces time
    and time cycles."""
    key, sep, value = line.partition("=")
    if not sep:
        raise SceneError(f"--set {line}: expected KEY=VALUE")
    parts = key.strip().split(".")
    value = strip_comment(value)
    if len(parts) == 2 and parts[0] == "settings":
        kind, name, k = "settings", None, parts[1]
    elif len(parts) >= 3:
        kind, name, k = parts[0], ".".join(parts[1:-1]), parts[-1]
    else:
        raise SceneError(f"--set {line}: expected settings.KEY or KIND.NAME.KEY")
    found = [s for s in sections if s["kind"] == kind and (name is None or s["name"] == name)]
    if not found:
        if kind != "settings":
            raise SceneError(f"--set {line}: the scene has no [{kind} {name}]")
        sections.append({"kind": "settings", "name": "", "entries": []})
        found = sections[-1:]
    section = found[0]
    entries = section["entries"]
    if kind == "stage" and k in CONTROLS:
        wall = value.split()[0] if value.split() else ""
        entries[:] = [(ek, ev) for ek, ev in entries
                      if not (ek in CONTROLS and ev.split()[:1] == [wall])]
        entries.append((k, value))
        return
    drop = {k} | ({"cycles", "time"} if kind == "stage" and k in ("cycles", "time") else set())
    entries[:] = [(ek, ev) for ek, ev in entries if ek not in drop]
    entries.append((k, value))


def parse_sections(text, path):
    """A scene's sections in file order: {"kind", "name" ('' for [settings]), "entries": [(key,
    value)]} ('#' starts a comment; the core has accepted the scene, resolve() runs it first)."""
    sections = []
    for number, raw in enumerate(text.splitlines(), start=1):
        line = strip_comment(raw)
        if not line:
            continue
        if line.startswith("[") and line.endswith("]"):
            words = line[1:-1].split()
            sections.append({"kind": words[0], "name": " ".join(words[1:]), "entries": []})
            continue
        key, sep, value = line.partition("=")
        if not sep or not sections:
            raise SceneError(f"{path}:{number}: expected 'key = value' in a section, got '{line}'")
        sections[-1]["entries"].append((key.strip(), value.strip()))
    return sections


def read(path, sets=()):
    """The scene at path with --set lines applied: its settings, materials, stages, probes
    and bodies' sections (the initial state comes from resolve())."""
    path = Path(path)
    sections = parse_sections(path.read_text(encoding="utf-8-sig"), path)
    if not any(s["kind"] == "settings" for s in sections):
        sections.insert(0, {"kind": "settings", "name": "", "entries": []})
    for line in sets:
        _apply_set(sections, line)

    def keys(section, defaults=None):
        out = dict(defaults or {})
        for k, v in section["entries"]:
            if k not in CONTROLS:
                out[k] = v
        return out

    settings = keys(next(s for s in sections if s["kind"] == "settings"), SETTINGS_DEFAULTS)
    materials = {}
    for s in sections:
        if s["kind"] == "material":
            m = keys(s, MATERIAL_DEFAULTS)
            if "kn" not in m:
                raise SceneError(f"{path}: [material {s['name']}] has no kn")
            kn, ks = float(m["kn"]), float(m["ks"])
            materials[s["name"]] = Material(s["name"], kn, kn if ks < 0 else ks, float(m["friction"]),
                                            float(m["cohesion"]), float(m["density"]), float(m["rolling"]))
    stages = [Stage(s["name"], -1, keys(s, STAGE_DEFAULTS),
                    [Control(k, v.split()[0], v.split()[1:]) for k, v in s["entries"] if k in CONTROLS])
              for s in sections if s["kind"] == "stage"]
    probes = []
    for s in sections:
        if s["kind"] == "probe":
            k = keys(s)
            probes.append(Probe(s["name"], k.get("quantity", ""), k.get("a", ""), k.get("b", "")))
    return Scene(path=path, sets=list(sets), settings=settings, materials=materials, stages=stages,
                 probes=probes,
                 disc_sections={s["name"]: keys(s) for s in sections if s["kind"] == "disc"},
                 generators={s["name"]: (s["kind"], keys(s)) for s in sections if s["kind"] in GENERATORS},
                 wall_sections={s["name"]: keys(s) for s in sections if s["kind"] == "wall"})


# ---------------------------------------------------------------------------------- resolving

def resolve(scene, ballast, work):
    """The scene's initial state from the core: a run of every stage at 0 cycles into
    work/init (discs.tsv, walls.tsv, run.json); sets scene.discs, disc_material, walls, dt,
    init_info and each stage's cycles.  Raises SceneError when the core refuses the scene."""
    init = Path(work) / "init"
    files.make_dirs(init)
    args = [str(ballast), "run", str(scene.path), "--out", str(init)]
    for line in scene.sets:
        args += ["--set", line]
    for stage in scene.stages:
        args += ["--set", f"stage.{stage.name}.cycles=0"]
    res = subprocess.run(args, capture_output=True, text=True, env=dict(os.environ, OMP_NUM_THREADS="1"))
    if res.returncode != 0:
        raise SceneError(f"ballast refused the scene ({res.returncode}): {res.stderr.strip()}")
    info = json.loads((init / "run.json").read_text())
    scene.init_info = info
    scene.dt = float(info["dt"])
    for stage in scene.stages:
        if "cycles" in stage.keys:
            stage.cycles = int(float(stage.keys["cycles"]))
        elif "time" in stage.keys:
            stage.cycles = int(math.ceil(float(stage.keys["time"]) / scene.dt))
        else:
            raise SceneError(f"[stage {stage.name}] has neither cycles nor time")
    t = Table(init / "discs.tsv", DISC_COLUMNS)
    discs = {k: np.array(t.numbers(k), dtype=float) for k in DISC_COLUMNS if k != "name"}
    discs["name"] = t.text("name")
    discs["row"] = np.array(t.numbers("row"), dtype=float) if t.has("row") else np.full(len(t), -1.0)
    scene.discs = discs
    scene.disc_material = [disc_material(scene, name) for name in discs["name"]]
    w = Table(init / "walls.tsv", ("name", "ax", "ay", "bx", "by"))
    names = w.text("name")
    cols = [w.numbers(k) for k in ("ax", "ay", "bx", "by")]
    scene.walls = [Wall(names[k], *(float(c[k]) for c in cols), wall_material(scene, names[k]))
                   for k in range(len(names))]
    return scene


def disc_material(scene, name):
    """The material of a disc called name: its [disc] section's, or its generator's (NAME.k)."""
    if name in scene.disc_sections:
        return scene.disc_sections[name]["material"]
    generator = name.rsplit(".", 1)[0]
    if generator in scene.generators:
        return scene.generators[generator][1]["material"]
    raise SceneError(f"disc '{name}': no [disc] section or generator gives its material")


def wall_material(scene, name):
    """The material of a wall: its [wall] section's, or the wall_material of the generator
    that made it (a box's NAME_bottom ..., a pile's NAME_floor, an import's walls)."""
    if name in scene.wall_sections:
        return scene.wall_sections[name]["material"]
    for gen, (kind, keys) in scene.generators.items():
        if "wall_material" in keys and (name.startswith(gen + "_") or kind == "import"):
            return keys["wall_material"]
    raise SceneError(f"wall '{name}': no [wall] section or generator gives its material")


def held(scene):
    """Per disc, the components held at zero as a set of 'x', 'y', 'rotation' (fixed = all)."""
    out = []
    for name, fixed in zip(scene.discs["name"], scene.discs["fixed"]):
        if fixed:
            out.append({"x", "y", "rotation"})
            continue
        words = scene.disc_sections.get(name, {}).get("hold", "")
        out.append(set(words.split()) - {"none"})
    return out
