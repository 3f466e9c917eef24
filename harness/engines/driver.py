"""harness/engines/driver.py -- what every engine's run shares (harness/engines/__init__.py):
make_run(), and the adapters by name (engines())."""
import json
import time
from pathlib import Path

from .. import files
from . import outputs, scene as scenes
from .interface import not_expressible_message
from .lammps import Lammps


def make_run(engine, scene_path, sets, command, out, ballast):
    """One run of a variant in engine into out: ballast's output files and run.json (status
    'ok', 'not_expressible' or 'skipped' when the engine cannot run at all).  Returns the
    exit status (0: the run is usable as its status says; 1: the engine failed)."""
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
    return {Lammps.name: Lammps}
