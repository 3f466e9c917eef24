"""Every exception type of the harness, in one module that imports nothing of the harness.

Each type says what went wrong in a way the command line (harness/__main__.py) turns into
an exit status, or a check (harness/compare.py) into a FAIL with its reason:

    IniError        a malformed case.txt, .ref or extremes.txt: 'file:line: what'   exit 2
    CatalogueError  a catalogue problem not tied to one line (an unknown case name) exit 2
    PictureError    a run that cannot be drawn (not a run folder, no snapshots)     exit 2
    RunProblem      a run's outputs cannot be used: missing, failed or malformed    a FAIL
    RunSkipped      a run that says it could not run (an outside tool is missing)   a SKIP
    EvalError       a quantity could not be evaluated to one finite number          a FAIL
    WriteError      the harness could not change a file of its own                  exit 3
    Busy            another harness holds the reports folder's lock                 exit 75
    Stopped         a batch of runs is stopping (an interrupt): start nothing more  exit 130

They live here, below every other module, so that any module can raise or catch any of
them without importing the module that happens to raise it (which is how compare.py and
piles.py once came to import each other).
"""
import os
from pathlib import Path


def shown(path):
    """path as people want to read it: relative to the working directory when inside it."""
    relative = os.path.relpath(path)
    return str(path) if relative.startswith("..") else relative


class IniError(ValueError):
    """A malformed file; str() is 'file:line: what is wrong'."""

    def __init__(self, path, line, message):
        super().__init__(f"{shown(path)}:{line}: {message}")
        self.path, self.line, self.message = path, line, message


class CatalogueError(ValueError):
    """A catalogue problem that is not tied to one line (e.g. an unknown case name)."""


class PictureError(ValueError):
    """A run folder that `plot` or `movie` cannot draw: not a run, no snapshots where they are
    asked for, a malformed table (named file:line), a bad option value."""


class RunProblem(Exception):
    """A run's outputs cannot be used: missing, failed, or malformed."""


class RunSkipped(RunProblem):
    """A run that could not be made and says why in run.json (status 'skipped'): the
    cross-checks against LAMMPS where LAMMPS is absent and cannot be installed.  Its checks
    are SKIP, neither PASS nor FAIL; anything else that keeps a check from its value is a
    FAIL (RunProblem)."""


class RunNotExpressible(RunProblem):
    """A run another engine could not make because the scene uses something that engine cannot
    express (run.json status 'not_expressible', harness/engines): every check that reads it is
    "not expressible in ENGINE", never a PASS, a FAIL or a SKIP."""


class EvalError(Exception):
    """A quantity could not be evaluated to one finite number."""


class WriteError(OSError):
    """An OSError while the harness changed a file of its own.  filename is the file meant
    (not its .tmp), so the message says what the user will look for (files.failure makes one)."""
    action = "write"

    def __str__(self):
        return f"cannot {self.action} {self.filename}: {self.strerror}"


class Busy(Exception):
    """Another harness holds the lock of this reports folder (harness/lock.py)."""

    def __init__(self, path, holder):
        super().__init__(path, holder)
        self.path, self.holder = Path(path), holder

    def __str__(self):
        pid, command = self.holder
        folder = self.path.parent
        if pid is None:
            what = f"another harness (pid unknown) is using {folder} (lock {self.path}): wait for it to finish"
        elif _alive(pid):
            what = (f"another harness (pid {pid}, `{command}`) is using {folder} (lock {self.path}): "
                    f"wait for it to finish or stop it (kill {pid})")
        else:
            what = (f"runs of a harness that has ended (pid {pid}, `{command}`) still hold {self.path}: "
                    f"wait for them to end (`pgrep -f {folder}` lists them)")
        return what + ", then run this command again"


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


class Stopped(RuntimeError):
    """A run or query was not started, or was stopped, because its batch is stopping (Ctrl-C,
    SIGTERM: harness/runner.py).  A task that launches several runs in turn (a stability
    bisection) ends with it.  outcome: the runner's Outcome of that run (None for a query)."""

    def __init__(self, what, outcome=None):
        super().__init__(f"interrupted: {what}")
        self.outcome = outcome
