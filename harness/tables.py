"""Reading one run's outputs: series.tsv (columns as numpy arrays) and run.json.

load_run() gathers a run folder into a Run, or raises RunProblem with a message that
says exactly what is missing or wrong; the checks turn that message into a FAIL.
harness.json is the runner's own record of a run (command, exit code, wall time).
A table that validate stored gzipped (NAME.gz beside no NAME: harness/compact.py) is read
through read_text as the table itself.
"""
import gzip
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import RunNotExpressible, RunProblem, RunSkipped


@dataclass
class Run:
    folder: Path
    info: dict
    columns: dict

    @property
    def names(self):
        return list(self.columns)


def read_text(path):
    """The text of an output table: path, or path + '.gz' decompressed when path is absent (a
    table validate stored gzipped: compact.py).  An OSError when neither can be read."""
    path = Path(path)
    packed = path.with_name(path.name + ".gz")
    if not path.exists() and packed.is_file():
        try:
            return gzip.decompress(packed.read_bytes()).decode("utf-8")
        except (EOFError, gzip.BadGzipFile, ValueError) as exc:     # a cut or corrupt file
            raise OSError(5, f"unreadable gzip file {packed.name}: {exc}", str(packed)) from None
    return path.read_text(encoding="utf-8")


def present(path):
    """Whether an output table is there, plain or gzipped (read_text reads it)."""
    path = Path(path)
    return path.is_file() or path.with_name(path.name + ".gz").is_file()


def read_series(path):
    """series.tsv (or series.tsv.gz: read_text) as {column name: float array}, in header order."""
    path = Path(path)
    try:
        lines = read_text(path).splitlines()
    except OSError as exc:
        raise RunProblem(f"series.tsv missing or unreadable: {path} ({exc.strerror})") from None
    if not lines:
        raise RunProblem(f"{path}:1: series.tsv is empty (no header)")
    names = _header(path, lines[0])
    rows = [_row(path, number, line, len(names))
            for number, line in enumerate(lines[1:], start=2) if line.strip()]
    data = np.array(rows, dtype=float).reshape(len(rows), len(names))
    return {name: data[:, i] for i, name in enumerate(names)}


def _header(path, line):
    names = [n.strip() for n in line.split("\t")]
    if names[:2] != ["cycle", "time"]:
        raise RunProblem(f"{path}:1: header must start with 'cycle<TAB>time', got {names[:2]}")
    if len(set(names)) != len(names) or "" in names:
        raise RunProblem(f"{path}:1: empty or repeated column name in header")
    return names


def _row(path, number, line, width):
    fields = line.split("\t")
    if len(fields) != width:
        raise RunProblem(f"{path}:{number}: {len(fields)} fields, header has {width}")
    try:
        return [float(f) for f in fields]
    except ValueError:
        raise RunProblem(f"{path}:{number}: not a number in '{line.strip()}'") from None


def read_json(path):
    """A JSON object from path; RunProblem if missing or malformed."""
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise RunProblem(f"{path.name} missing: {path}") from None
    except (OSError, ValueError) as exc:
        raise RunProblem(f"{path.name} unreadable: {path}: {exc}") from None
    if not isinstance(data, dict):
        raise RunProblem(f"{path.name} is not a JSON object: {path}")
    return data


def read_run_json(folder):
    """run.json of a run folder, as a dict (RunProblem if missing or malformed)."""
    return read_json(Path(folder) / "run.json")


def read_harness_record(folder):
    """The runner's record (harness.json) of a run folder, or None when absent or unreadable."""
    try:
        return read_json(Path(folder) / "harness.json")
    except RunProblem:
        return None


def skip_reason(info):
    """Why the run could not be made, when its run.json says so (status 'skipped'), else
    None.  Only the cross-checks against LAMMPS skip (harness/peer/common.py skip_outputs)."""
    if info.get("status") != "skipped":
        return None
    return info.get("message") or "no reason given"


def not_expressible(info):
    """What another engine could not express of the run's scene, when its run.json says so
    (status 'not_expressible', harness/engines), else None."""
    if info.get("status") != "not_expressible":
        return None
    return info.get("message") or "no reason given"


def run_failure(folder, info):
    """Why a run that wrote run.json still failed, or None when it succeeded (a skipped run
    did not fail: its checks are SKIP, see load_run; nor did one another engine could not
    express: its checks say so)."""
    if info.get("status") not in ("ok", "skipped", "not_expressible"):
        message = info.get("message") or "no message"
        return f"run failed: status '{info.get('status')}': {message} ({folder})"
    record = read_harness_record(folder)
    if record and record.get("returncode") not in (0, None):
        return f"run failed: ballast exited with code {record['returncode']} ({folder})"
    return None


# The files a complete run leaves, by the core's command (main.c, output.c, and for the
# cross-checks against LAMMPS harness/peer/check.py and rolling.py).
EXPECTED_OUTPUTS = {"run": ("series.tsv", "stress.tsv", "contacts.tsv", "discs.tsv", "walls.tsv", "run.json"),
                    "exact": ("series.tsv", "contacts.tsv", "discs.tsv", "walls.tsv", "run.json"),
                    "peer": ("series.tsv", "run.json"),
                    "peer_rolling": ("series.tsv", "run.json")}
# A run of another engine (command ENGINE:COMMAND, harness/engines): run.json always; the rest
# when it says 'ok' (load_run reads series.tsv; one that could not be expressed has no more).
ENGINE_OUTPUTS = ("run.json",)


def unfinished_outputs(folder, command=None, record=None):
    """Why a run folder's outputs are incomplete ('' when they are not): a NAME.tmp left behind
    (a writer stopped before its rename), or a file the command always writes missing -- unless
    record (its harness.json) says validate removed it after its report (removed_tables).
    Without a command (no harness.json) only the leftovers are looked at (load_run reads
    series.tsv and run.json itself)."""
    folder = Path(folder)
    try:
        leftovers = sorted(p.name for p in folder.iterdir() if p.name.endswith(".tmp"))
    except OSError as exc:
        return f"unfinished outputs: cannot list {folder} ({exc.strerror})"
    if leftovers:
        return f"unfinished outputs: {', '.join(leftovers)} left behind ({folder})"
    removed = ((record or {}).get("compacted") or {}).get("removed") or {}
    expected = EXPECTED_OUTPUTS.get(command, ENGINE_OUTPUTS if command and ":" in command else ())
    missing = [n for n in expected if not present(folder / n) and n not in removed]
    if missing:
        return f"unfinished outputs: {', '.join(missing)} missing ({folder})"
    return ""


def removed_tables(folder, record, name=None):
    """Why a run's tables are gone, when validate removed them after its report (compact.py),
    else ''; with name, only when that file is one of them."""
    removed = ((record or {}).get("compacted") or {}).get("removed")
    if not removed or (name is not None and name not in removed):
        return ""
    case = (record or {}).get("case") or "CASE"
    what = name or ", ".join(sorted(n for n in removed if n.endswith(".tsv")) or sorted(removed))
    return (f"{what} of {folder} was removed after the report of the validate that made the run, which "
            f"kept its results; `harness run {case}` makes it again, and `validate --keep-outputs` keeps it")


def load_run(folder):
    """A successful run's outputs; RunProblem says what is missing or failed, RunSkipped
    why a run that could not be made was not."""
    folder = Path(folder)
    if not folder.is_dir():
        raise RunProblem(f"run output missing: {folder} does not exist (run the case first)")
    record = read_harness_record(folder)
    if record and not record.get("ok", True):
        raise RunProblem(f"run failed: {record.get('cause') or 'no cause recorded'} ({folder})")
    info = read_run_json(folder)
    failure = (run_failure(folder, info) or removed_tables(folder, record, "series.tsv")
               or unfinished_outputs(folder, record.get("kind") if record else None, record))
    if failure:
        raise RunProblem(failure)
    refused = not_expressible(info)
    if refused:
        raise RunNotExpressible(refused)
    skipped = skip_reason(info)
    if skipped:
        raise RunSkipped(f"skipped: {skipped} ({folder})")
    return Run(folder, info, read_series(folder / "series.tsv"))


def is_finite_number(value):
    """True for a real number that is neither NaN nor infinite."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
