"""harness/engines: other DEM engines through ballast's catalogue (docs/engines.md).

An engine adapter takes a case's scene, with the variant's --set lines and command, and
either makes the run in its engine and brings it back in ballast's output formats
(series.tsv, discs.tsv, contacts.tsv, walls.tsv, stress.tsv, run.json), so that the case's
own checks and references (reference/*.ref, harness/compare.py) apply unchanged, or says,
feature by feature, what of the scene its engine cannot express.  A run it cannot make is
written as run.json with status 'not_expressible' and the reasons; every check that reads
it is then "not expressible in ENGINE" (compare.py), never a pass, a fail or a skip.

The interface (Engine) is four methods:

    problem()            why the engine cannot run at all ('' when it can): not installed,
                         missing styles; installing it first where the adapter knows how
    identity()           what decides its outputs besides the scene: its executable and the
                         adapter's own files (runner.identity: --resume reruns on a change)
    plan(scene, command) a Plan: one Feature per scene feature, each 'exact' (the same
                         discrete equations, to round-off), 'approximate' (the same physics, a
                         stated difference) or 'refused' (not expressible, with why)
    simulate(scene, plan, work)
                         the run, as a Trajectory (harness/engines/trajectory.py): the
                         state at every output row and at the end, contacts and walls
                         included, each engine's quantities in ballast's conventions

and make_run() (below) does the rest the same for every engine: the scene read and its
initial state from the core (scene.py), the plan, and either the not-expressible run.json or
the trajectory turned into ballast's files (outputs.py).

Adapters: lammps.py (Debian's `lammps`).  docs/engines.md says what a LIGGGHTS or YADE
adapter would need.
"""
import json
import time
from dataclasses import dataclass, field
from pathlib import Path

from .. import files

EXACT, APPROXIMATE, REFUSED = "exact", "approximate", "refused"


@dataclass(frozen=True)
class Feature:
    """One feature of a scene and how an engine expresses it.

    name: what the scene uses ('normal law: power, nu = 1.5', 'global damping alpha = 8');
    status: EXACT, APPROXIMATE or REFUSED; how: the mapping (or why it is refused)."""
    name: str
    status: str
    how: str

    def line(self):
        return f"{self.name}: {self.status}: {self.how}"


@dataclass
class Plan:
    """How an engine expresses one scene: a Feature per feature, and the probe columns (or
    run.json fields read by expression functions) it cannot give, {name: why}."""
    features: list = field(default_factory=list)
    unexpressible: dict = field(default_factory=dict)
    options: dict = field(default_factory=dict)     # the adapter's own choices (styles, types)

    def add(self, name, status, how):
        self.features.append(Feature(name, status, how))

    def refused(self):
        return [f for f in self.features if f.status == REFUSED]

    def approximate(self):
        return [f for f in self.features if f.status == APPROXIMATE]


class Engine:
    """The adapter interface (the module docstring); name is the word of the run's command
    (ENGINE:COMMAND, e.g. lammps:run), title what reports call the engine."""
    name = ""
    title = ""

    def problem(self):
        raise NotImplementedError

    def identity(self):
        raise NotImplementedError

    def version(self):
        return ""

    def plan(self, scene, command):
        raise NotImplementedError

    def simulate(self, scene, plan, work):
        raise NotImplementedError


def not_expressible_message(engine, plan):
    """The one-line reason a run could not be made: every refused feature."""
    refused = plan.refused()
    return f"not expressible in {engine.title}: " + "; ".join(f"{f.name}: {f.how}" for f in refused)


def make_run(engine, scene_path, sets, command, out, ballast):
    """One run of a variant in engine into out: ballast's output files and run.json (status
    'ok', 'not_expressible' or 'skipped' when the engine cannot run at all).  Returns the
    exit status (0: the run is usable as its status says; 1: the engine failed)."""
    from . import outputs, scene as scenes
    out = files.make_dirs(out)
    base = {"engine": engine.name, "engine_title": engine.title, "scene": str(scene_path),
            "sets": list(sets), "command": command}
    problem = engine.problem()
    if problem:
        _write_info(out, dict(base, status="skipped", message=problem, steps=0, n_discs=0))
        return 0
    base["engine_version"] = engine.version()
    if command not in ("run", "exact"):
        # harness/peer's cross-checks: ballast against LAMMPS already, with no scene of their own
        message = (f"not expressible in {engine.title}: command {command}: the case is itself a "
                   "cross-check of ballast against LAMMPS (harness/peer), whose runs are of both "
                   "engines; it has no scene of its own to translate")
        _write_info(out, dict(base, status="not_expressible", message=message, steps=0, n_discs=0))
        return 0
    scene = scenes.read(scene_path, sets)
    scenes.resolve(scene, ballast, out / "work")
    plan = engine.plan(scene, command)
    base["features"] = [f.__dict__ for f in plan.features]
    if plan.refused():
        _write_info(out, dict(base, status="not_expressible", message=not_expressible_message(engine, plan),
                              steps=0, n_discs=len(scene.discs["x"])))
        return 0
    start = time.monotonic()
    trajectory = engine.simulate(scene, plan, out / "work")
    wall = time.monotonic() - start
    outputs.write(scene, plan, trajectory, out, base, wall)
    return 0


def _write_info(out, info):
    files.write_text(Path(out) / "run.json", json.dumps(info, indent=1) + "\n")


def engines():
    """The adapters by name."""
    from .lammps import Lammps
    return {Lammps.name: Lammps}
