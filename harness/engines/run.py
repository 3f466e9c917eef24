"""harness/engines/run.py -- one run of a scene in another engine, written like a ballast run.

    /usr/bin/python3 -m harness.engines.run --engine lammps --scene SCENE [--set KEY=VALUE ...]
        [--command run|exact] --out DIR [--ballast BIN] [--lmp LMP]

What the runner starts for a job of command ENGINE:COMMAND (harness/runner.py); the outputs
are ballast's files and run.json (harness/engines/__init__.py, make_run).  Exit status 0 when
the folder holds a usable run (ok, not expressible, or skipped: the engine cannot run here),
1 when the engine failed (its message on stderr and in run.json).
"""
import argparse
import json
import sys
import traceback
from pathlib import Path

from .. import REPO_ROOT, files
from .driver import engines, make_run


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--engine", required=True, choices=sorted(engines()))
    ap.add_argument("--scene", required=True, type=Path)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--command", default="run",
                    help="the variant's command: run, exact, or a cross-check's (peer, peer_rolling)")
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--ballast", type=Path, default=REPO_ROOT / "bin" / "ballast",
                    help="the core that resolves the scene's initial state (default bin/ballast)")
    ap.add_argument("--lmp", default="lmp", help="LAMMPS's executable (lammps engine)")
    a = ap.parse_args(argv)
    engine = engines()[a.engine](a.lmp) if a.engine == "lammps" else engines()[a.engine]()
    try:
        return make_run(engine, a.scene.absolute(), a.set, a.command, a.out.absolute(), a.ballast.absolute())
    except Exception as exc:      # the engine's failure is this run's: said, and recorded whole
        traceback.print_exc()
        info = {"engine": a.engine, "status": "failed", "message": f"{type(exc).__name__}: {exc}",
                "scene": str(a.scene), "sets": a.set, "steps": 0, "n_discs": 0}
        files.make_dirs(a.out)
        files.write_text(a.out / "run.json", json.dumps(info, indent=1) + "\n")
        return 1


if __name__ == "__main__":
    sys.exit(main())
