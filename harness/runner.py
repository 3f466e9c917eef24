"""Running bin/ballast: the one launcher of the harness's runs, in parallel, with progress lines.

run_all() runs a list of jobs, one subprocess per (case, variant) or sweep point.  Commands
whose runs depend on each other's results (the stability bisection: harness/stability.py)
give run_tasks() a list of tasks instead: each task is called with the Batch and starts
its runs one after another through Batch.launch (and asks `ballast info` through
Batch.ask).  Either way every run goes through run_one below, so every run gets the same
folder, record, resume and interrupt handling, and tasks run side by side on -j threads
whose count changes no result.

Each run gets a fresh folder (the old one is removed first) that is also its working
directory, so runs share no state and their results cannot depend on -j or on order.
After the run the folder holds the core's outputs plus ballast.stdout, ballast.stderr and,
written last (tmp file + rename), harness.json: the command, exit code, wall time, on
failure the cause, the run's identity (what made it: command, scene path and content hash,
--set overrides, the executable's hash, and the hash of every file the run reads: the
scene and the files its [import] sections name, as `ballast inputs` lists them), the
SHA-256 of every file the run left, and for a realisation of an [ensemble] its ensemble
and seed (the seed is also in the core's run.json, in its scene path or --set lines).

Interruption: SIGINT or SIGTERM stops the whole batch.  Jobs not yet started are dropped
(their folders untouched); running ones get SIGTERM (the core traps it, writes run.json
with status "interrupted" and exits 130), are waited for (SIGKILL after STOP_GRACE s)
and recorded as failed; then KeyboardInterrupt goes on to the caller (exit 130).

Resume (run_all(..., resume=True), `--resume` on the command line): a job whose folder
holds a complete successful run with the same identity, its files unchanged since, is not
run again; every other job is (see stale()).

Killed outright (SIGKILL): every run dies with the harness (harness/children.py) and keeps
the reports lock until it has (harness/lock.py), so a `--resume` at once is safe.  When the
harness cannot prepare or record a run folder (disk full, read-only), the run fails with
Outcome.io_error set, its half-written record removed; the command exits with status 3.

Kept whole (about 710 lines): one responsibility, launching runs and recording them, with
one registry of running processes (Running) that the launch, the interrupt handling, the
batch and its progress lines share; apart, each piece would reach into the others' state.
"""
import hashlib
import json
import os
import signal
import stat
import subprocess
import sys
import threading
import time
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from . import files
from .children import options as child_options
from .engines.driver import engines
from .errors import RunProblem, Stopped, WriteError
from .tables import (read_harness_record, read_run_json, removed_tables, run_failure, skip_reason,
                     unfinished_outputs)

STDERR_TAIL = 5
STOP_GRACE = 10.0    # seconds a terminated run has to write run.json and exit before SIGKILL
INTERRUPTED = (130, -signal.SIGINT, -signal.SIGTERM)   # how a run that was interrupted ends
POLL = 0.1           # seconds between the main thread's looks at the runs (see run_all)
STOPPED = "interrupted:"   # how the account of an interrupted batch begins (_stop; console.Transient keeps it)
PEER = Path(__file__).resolve().parent / "peer"
# The cross-checks against LAMMPS (modules of harness/peer, not the core): command -> (the
# module run with python3 -m, the files of harness/peer besides bin/ballast that decide its
# outputs).
PEER_COMMANDS = {
    "peer": ("harness.peer.check", ("check.py", "common.py", "../engines/lammps.py", "../engines/scene.py")),
    "peer_rolling": ("harness.peer.rolling", ("rolling.py", "common.py", "../engines/lammps.py",
                                              "../engines/scene.py")),
}


@dataclass
class Job:
    case: str
    variant: str
    scene: Path
    sets: list
    out: Path
    expected: float = 0.0   # expected seconds, for the ETA
    command: str = "run"    # the core's command: run (DEM) or exact (static solver)
    ensemble: str = ""      # a realisation of [ensemble NAME]: NAME, and its seed (in harness.json)
    seed: int = None
    probe: bool = False     # a sweep point that may lie past a stability limit: its unstable end
                            # (exit 1) is a measured limit, reported as such and not as a failure

    @property
    def label(self):
        return f"{self.case}/{self.variant}"


@dataclass
class Outcome:
    job: Job
    ok: bool
    returncode: object
    wall: float
    cause: str = ""
    skipped: bool = False   # resumed: a complete run of the same identity was already there
    skip_reason: str = ""   # the run could not be made and says why (run.json status 'skipped')
    io_error: WriteError = None   # the harness could not prepare or record the folder (files.py)


def unrecorded(outcomes):
    """'' when every run folder was prepared and recorded; else one line naming the first that
    was not (the OS's reason) and how many more."""
    unwritten = [o.io_error for o in outcomes if o.io_error]
    if not unwritten:
        return ""
    return f"{unwritten[0]}" + (f" (and {len(unwritten) - 1} more run folder(s))" if len(unwritten) > 1 else "")


def jobs_for(cases, runs_root):
    """One Job per variant of each case, outputs in runs_root/<case>/<variant>."""
    return [Job(c.name, v.name, v.scene, list(v.sets), Path(runs_root) / c.name / v.name,
                c.runtime / len(c.variants), v.command, v.ensemble, v.seed)
            for c in cases for v in c.variants]


def command(job, binary):
    """The core's command line for a job."""
    if ":" in job.command:
        # A run of another engine (harness/engines), command ENGINE:COMMAND: the adapter, run from
        # the run's folder (hence PYTHONPATH), with the core resolving the scene's initial state.
        engine, what = job.command.split(":", 1)
        root = PEER.parent.parent
        return (["/usr/bin/env", f"PYTHONPATH={root}", "/usr/bin/python3", "-m", "harness.engines.run",
                 "--engine", engine, "--command", what, "--scene", str(job.scene), "--out", str(job.out),
                 "--ballast", str(binary)] + [a for kv in job.sets for a in ("--set", kv)])
    if job.command in PEER_COMMANDS:
        # A cross-code check against LAMMPS: a module of harness/peer, not the core, run from
        # the run's folder (hence PYTHONPATH) on the repository's bin/ballast, as identity() says.
        root = PEER.parent.parent
        return ["/usr/bin/env", f"PYTHONPATH={root}", "/usr/bin/python3", "-m",
                PEER_COMMANDS[job.command][0], "--ballast", str(root / "bin" / "ballast"),
                "--out", str(job.out)]
    cmd = [str(binary), job.command, str(job.scene), "--out", str(job.out)]
    for kv in job.sets:
        cmd += ["--set", kv]
    return cmd


class Running:
    """The live subprocesses, so an interrupt can stop them all.  Once stopping, a process
    registered late (started while the interrupt was being handled) is terminated at once."""

    def __init__(self):
        self._procs, self._lock = set(), threading.Lock()
        self.stopping = False

    def add(self, proc):
        with self._lock:
            self._procs.add(proc)
            if self.stopping:
                proc.terminate()

    def remove(self, proc):
        with self._lock:
            self._procs.discard(proc)

    def stop_starting(self):
        with self._lock:
            self.stopping = True

    def terminate(self):
        """SIGTERM to every live run; from now on runs are stopped as they start."""
        with self._lock:
            self.stopping = True
            for proc in self._procs:
                proc.terminate()

    def kill(self):
        with self._lock:
            for proc in self._procs:
                proc.kill()


def fresh_folder(path):
    """An empty folder at path (whatever was there is removed); WriteError if not."""
    files.remove_tree(path)
    files.make_dirs(path)


def run_one(job, binary, running=None, resume=False, binary_id=None, inputs=None):
    """Run one job to completion; the Outcome says whether it produced usable outputs.
    With resume, a job whose folder already holds a complete run of the same identity is
    skipped (Outcome.skipped).  binary_id: binary_identity(binary), computed when None;
    inputs: the batch's Inputs (a fresh one when None)."""
    if running and running.stopping:
        return Outcome(job, False, None, 0.0, "interrupted before it started")
    ident = identity(job, binary, binary_identity(binary) if binary_id is None else binary_id,
                     inputs or Inputs(running))
    if resume and not stale(job, ident):
        record = read_harness_record(job.out)
        return Outcome(job, True, record.get("returncode"), 0.0, skipped=True)
    try:
        fresh_folder(job.out)
    except WriteError as exc:
        return Outcome(job, False, None, 0.0, f"cannot prepare the run folder: {exc}", io_error=exc)
    cmd = command(job, binary)
    start = time.monotonic()
    try:
        returncode, stdout, stderr = _execute(cmd, job.out, running)
    except OSError as exc:
        returncode, stdout, stderr = None, "", f"cannot start {binary}: {exc.strerror}"
    wall = time.monotonic() - start
    if running and returncode in INTERRUPTED:
        running.stop_starting()     # Ctrl-C reached the core's process group: start no other run
    try:
        files.write_text(job.out / "ballast.stdout", stdout)
        files.write_text(job.out / "ballast.stderr", stderr)
        cause = _cause(job, returncode, stderr)
        if cause and running and running.stopping:
            cause = "interrupted: " + cause
        outcome = Outcome(job, not cause, returncode, wall, cause)
        if not cause:
            outcome.skip_reason = skip_reason(read_run_json(job.out)) or ""
        _record(outcome, cmd, ident)
    except WriteError as exc:
        # no harness.json: the folder reads as unfinished, and --resume runs it again
        return Outcome(job, False, returncode, wall, f"cannot record the run: {exc}", io_error=exc)
    return outcome


# ---------------------------------------------------------------- identity and resume

def sha256_of(path):
    """Hex SHA-256 of a regular file's bytes, or None when it cannot be read or is no regular
    file (opened without blocking and checked before it is read: a FIFO would block forever)."""
    digest = hashlib.sha256()
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except OSError:
        return None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return None
        with os.fdopen(fd, "rb") as f:
            fd = None
            for block in iter(lambda: f.read(1 << 20), b""):
                digest.update(block)
    except OSError:
        return None
    finally:
        if fd is not None:
            os.close(fd)
    return digest.hexdigest()


def binary_identity(binary):
    """What identifies the executable: its path and the SHA-256 of its bytes (a rebuild that
    changes it changes the hash; `touch` or an identical relink does not)."""
    return {"path": str(binary), "sha256": sha256_of(binary)}


class Inputs:
    """The files a run of the core reads, by content: `ballast inputs SCENE --set ...` lists
    them as the core resolves them (the scene, and the discs and walls files of every
    [import], relative to the scene's folder; the core parses the scene, the harness never
    does), and each is hashed.  Within the object's life (a batch, an export, a gather) the
    core is asked once per (executable, scene, --set lines) and each file is read once per
    version (its path, inode, size and mtime): a realisation of an ensemble costs one short
    `ballast inputs`, the files it shares with the others are hashed once."""

    def __init__(self, running=None):
        self.running = running          # the batch's processes: an interrupt stops a listing too
        self._listings, self._digests = {}, {}
        self._lock = threading.Lock()

    def digests(self, binary, scene, sets):
        """{path: SHA-256 (None: unreadable or no regular file)} of every file a run of scene
        with sets reads, or a str saying why the core could not list them."""
        listing = self.listing(binary, scene, sets)
        if isinstance(listing, str):
            return listing
        return {path: self.digest(path) for path in listing}

    def listing(self, binary, scene, sets):
        """The paths `binary inputs scene --set ...` prints, or a str saying why it failed."""
        key = (str(binary), str(scene), tuple(sets))
        with self._lock:
            found = self._listings.get(key)
        if found is None:
            found = self._list(binary, scene, sets)
            with self._lock:
                self._listings[key] = found
        return found

    def _list(self, binary, scene, sets):
        try:
            if not stat.S_ISREG(os.stat(scene).st_mode):      # the core would block on a FIFO
                return f"{scene}: not a regular file"
        except OSError as exc:
            return f"{scene}: {exc.strerror}"
        cmd = [str(binary), "inputs", str(scene)] + [a for kv in sets for a in ("--set", kv)]
        try:
            code, stdout, stderr = _execute(cmd, None, self.running, query=True)
        except OSError as exc:
            return f"cannot start {binary}: {exc.strerror}"
        if code != 0:
            said = stderr.decode(errors="replace").strip().splitlines()
            return f"`{binary} inputs` exit code {code}" + (f": {said[-1]}" if said else "")
        return tuple(os.fsdecode(line) for line in stdout.split(b"\n") if line)

    def digest(self, path):
        """sha256_of(path), once per version of the file."""
        try:
            st = os.stat(path)
        except OSError:
            return None
        key = (path, st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns)
        with self._lock:
            if key in self._digests:
                return self._digests[key]
        found = sha256_of(path)
        with self._lock:
            self._digests[key] = found
        return found


def identity(job, binary, binary_id, inputs=None):
    """Everything that decides a run's outputs: the core's command, the scene (path and the
    hash of its text), the --set overrides, the executable, and every file the run reads
    (`inputs`: {path: SHA-256} of the scene and of every file an [import] names, listed by
    the core: Inputs; inputs, an Inputs, caches them across a batch's runs).
    A cross-check against LAMMPS runs a script of harness/peer on the repository's
    bin/ballast: the hashes of the files it reads (PEER_COMMANDS) and of bin/ballast."""
    ident = {"command": job.command, "scene": str(job.scene), "scene_sha256": sha256_of(job.scene),
             "sets": list(job.sets), "binary": binary_id}
    if ":" in job.command:
        ident["engine"] = engine_identity(job.command.split(":", 1)[0])
    if job.command in PEER_COMMANDS:
        root = PEER.parent.parent
        ident["binary"] = {str(p): sha256_of(p) for p in
                           [PEER / name for name in PEER_COMMANDS[job.command][1]]
                           + [root / "bin" / "ballast"]}
    else:
        ident["inputs"] = (inputs or Inputs()).digests(binary, job.scene, job.sets)
    return ident


_ENGINE_IDS = {}


def engine_identity(name):
    """What decides another engine's outputs besides the scene (its executable, the adapter's
    files: harness/engines), once per engine and process."""
    if name not in _ENGINE_IDS:
        known = engines()
        _ENGINE_IDS[name] = known[name]().identity() if name in known else {"unknown engine": name}
    return _ENGINE_IDS[name]


def inputs_change(before, now):
    """Which input differs between two {path: SHA-256} ('' when none): 'PATH changed',
    'it reads PATH now', 'it no longer reads PATH'; a listing that failed (a str) says so."""
    for listing in (now, before):
        if not isinstance(listing, dict):
            return f"its inputs cannot be listed: {listing}"
    unreadable = [p for p, d in now.items() if d is None]
    if unreadable:
        return f"an input cannot be read: {unreadable[0]}"
    changed = [p for p in now if p in before and before[p] != now[p]]
    if changed:
        return f"an input changed since: {changed[0]}"
    new = [p for p in now if p not in before]
    if new:
        return f"it reads {new[0]} now"
    gone = [p for p in before if p not in now]
    return f"it no longer reads {gone[0]}" if gone else ""


def identity_change(recorded, ident):
    """Why a run recorded with identity `recorded` cannot stand for a run of ident ('' when
    it can): ident's inputs cannot be listed or read, or another command line, scene or
    executable made it, or an input differs (inputs_change)."""
    now = ident.get("inputs", {})
    if not isinstance(now, dict) or None in now.values():
        return inputs_change({}, now)
    if recorded == ident:
        return ""
    others = lambda i: {k: v for k, v in i.items() if k != "inputs"}
    if not isinstance(recorded, dict) or others(recorded) != others(ident):
        return "made by another command line, scene or executable"
    if "inputs" not in recorded:
        return "its record does not list the files it read (made by an older harness)"
    return inputs_change(recorded["inputs"], now)


def output_digests(folder):
    """{file name: SHA-256} of every file in a run folder except harness.json."""
    folder = Path(folder)
    return {p.name: sha256_of(p) for p in sorted(folder.iterdir())
            if p.is_file() and p.name != "harness.json"}


def stored_outputs(record):
    """{file name: SHA-256} a run folder should hold: the outputs harness.json lists, with each
    table validate gzipped (its "compacted" entry: compact.py) as NAME.gz and its digest."""
    outputs = dict(record.get("outputs") or {})
    for name, digest in ((record.get("compacted") or {}).get("gzip") or {}).items():
        outputs.pop(name, None)
        outputs[name + ".gz"] = digest
    return outputs


def stale(job, ident):
    """Why job.out cannot stand for a run of ident ('' when it can): it must hold harness.json
    saying the run succeeded with exactly this identity (every input it read unchanged:
    identity_change), every file it lists unchanged (a table validate gzipped as its .gz:
    stored_outputs; a run whose tables validate removed is made again), no
    other output file, and complete outputs (run.json status ok, the expected files, no .tmp)."""
    record = read_harness_record(job.out)
    if record is None:
        return "no harness.json (never run, or stopped before it finished)"
    if not record.get("ok"):
        return "the last attempt failed"
    changed = identity_change(record.get("identity"), ident)
    if changed:
        return changed
    removed = removed_tables(job.out, record)
    if removed:
        return removed
    recorded = record.get("outputs")
    if not isinstance(recorded, dict) or output_digests(job.out) != stored_outputs(record):
        return "its files changed since the run"
    try:
        info = read_run_json(job.out)
    except RunProblem as problem:
        return str(problem)
    if skip_reason(info):
        return "skipped last time: try again"
    return run_failure(job.out, info) or unfinished_outputs(job.out, job.command)


def _execute(cmd, cwd, running, query=False):
    """Run cmd in cwd to its end as a child of the harness (children.py), registered in running
    while it lives: (exit code, stdout, stderr).  query: a short read-only question of the core
    (`ballast inputs`), which writes nothing, so it need not die with the harness nor hold the
    reports lock: started without children.py's preexec_fn, which doubles the cost of a start
    (4.8 against 2.4 ms), and its stdout returned as bytes (paths, os.fsdecode'd by the caller)."""
    options = {} if query else {"text": True, "errors": "replace", **child_options()}
    proc = subprocess.Popen(cmd, cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, **options)
    if running:
        running.add(proc)
    try:
        stdout, stderr = proc.communicate()
    finally:
        if running:
            running.remove(proc)
    return proc.returncode, stdout, stderr


def _cause(job, returncode, stderr):
    """Why the run failed ('' when it did not): exit code and last stderr lines, or bad outputs."""
    if returncode != 0:
        how = "could not start" if returncode is None else (
            f"killed by signal {-returncode}" if returncode < 0 else f"exit code {returncode}")
        tail = stderr.strip().splitlines()[-STDERR_TAIL:]
        return how + "".join(f"\n    {line}" for line in tail)
    try:
        info = read_run_json(job.out)
    except RunProblem as problem:
        return f"exit code 0 but {problem}"
    failure = run_failure(job.out, info)
    if failure:
        return failure
    unfinished = unfinished_outputs(job.out, job.command)
    return f"exit code 0 but {unfinished}" if unfinished else ""


def _record(outcome, cmd, ident):
    """harness.json, written last and whole (tmp file + rename): the runner's own account of
    the run, its identity and the digests of its files (what resume compares)."""
    folder = outcome.job.out
    record = {"case": outcome.job.case, "variant": outcome.job.variant, "command": cmd,
              "returncode": outcome.returncode, "wall_seconds": round(outcome.wall, 6),
              "ok": outcome.ok, "cause": outcome.cause, "kind": outcome.job.command,
              "identity": ident, "outputs": output_digests(folder)}
    if outcome.job.ensemble:
        record.update(ensemble=outcome.job.ensemble, seed=outcome.job.seed)
    files.write_text(folder / "harness.json", json.dumps(record, indent=1) + "\n")


LONG_BATCH = 60      # a batch of more runs than this gets progress lines, not a line per run
PERIOD = 30.0        # seconds between those lines off a terminal (on one, the line is redrawn)


def duration(seconds):
    """A time left, as people read it: '45 s', '12 min 05 s', '3 h 20 min'."""
    seconds = max(0, int(round(seconds)))
    if seconds < 60:
        return f"{seconds} s"
    if seconds < 3600:
        return f"{seconds // 60} min {seconds % 60:02d} s"
    return f"{seconds // 3600} h {seconds % 3600 // 60:02d} min"


def rate_text(runs, seconds):
    """Runs per minute, or per hour when fewer than one a minute."""
    if runs <= 0 or seconds <= 0:
        return "- runs/min"
    per_minute = runs * 60.0 / seconds
    return f"{per_minute:.3g} runs/min" if per_minute >= 1 else f"{per_minute * 60:.3g} runs/h"


def limit_found(outcome):
    """Whether a failed run is a sweep point past its stability limit: a probing job (Job.probe)
    whose run.json says the core ended it as unstable (its run-time guards)."""
    if not outcome.job.probe or outcome.ok or outcome.skipped:
        return False
    try:
        return read_run_json(outcome.job.out).get("status") == "unstable"
    except (RunProblem, OSError):
        return False


class Progress:
    """What the runs have done so far, on out.

    A short batch (at most long_batch runs): one line per run, '[done/total] case/variant
    1.23 s  ETA 4 s', redrawn in place (\\r) on a terminal, plain lines otherwise.

    A long batch (an ensemble of hundreds of realisations): one status line, '[done/total]
    46 %  12.3 runs/min  13 min 20 s left  (last case/variant 4.71 s; 2 failed, 10 kept)',
    redrawn after every run on a terminal; off a terminal (a log, CI) printed after the first
    run, then at most once every `period` seconds, and at the end.

    Either way a failed or skipped run's cause is printed at once, on a line of its own, and so
    is a sweep point past its stability limit unless limits is False (validate's default view:
    the closing line counts them, the report tabulates them); the rate counts the runs that ran (not those kept by --resume) over the time since the start;
    the time left scales the elapsed time by the expected run times (case.txt `runtime`) of
    what is left against what has finished."""

    def __init__(self, jobs, out, tty=None, long_batch=LONG_BATCH, period=PERIOD, clock=time.monotonic,
                 limits=True):
        self.total, self.done, self.out = len(jobs), 0, out
        self.show_limits = limits
        self.expected_total = sum(j.expected for j in jobs)
        self.expected_done = 0.0
        self.tty = out.isatty() if tty is None else tty
        self.long = self.total > long_batch
        self.period, self.clock = period, clock
        self.start = clock()
        self.ran = self.kept = self.failed = self.limits = 0
        self.last_line = None       # when the last periodic line was printed (long batches off a tty)

    def eta(self):
        """Seconds left, scaled from the expected run times of what has finished."""
        elapsed = self.clock() - self.start
        if self.done >= self.total:
            return 0.0
        if self.expected_done > 0:
            return elapsed * (self.expected_total - self.expected_done) / self.expected_done
        return elapsed / max(self.done, 1) * (self.total - self.done)

    def finished(self, outcome):
        self.done += 1
        if outcome.skipped:     # took no time: leaves the ETA to the runs that do
            self.kept += 1
            self.expected_total -= outcome.job.expected
            if self.long:
                self._status(outcome)
                return
            self._write(f"[{self.done}/{self.total}] {outcome.job.label}  done before, kept (--resume)",
                        keep=not self.tty)
            return
        self.ran += 1
        self.expected_done += outcome.job.expected
        if limit_found(outcome):
            self.limits += 1
            if self.show_limits:
                self._write(f"LIMIT {outcome.job.label}: past its stability limit, the guards stopped it "
                            f"(a measured point of the sweep, not a failure): {outcome.cause}", keep=True)
        elif not outcome.ok:
            self.failed += 1
            self._write(f"FAILED {outcome.job.label}: {outcome.cause}", keep=True)
        if outcome.skip_reason:
            self._write(f"SKIPPED {outcome.job.label}: {outcome.skip_reason}", keep=True)
        if self.long:
            self._status(outcome)
            return
        line = f"[{self.done}/{self.total}] {outcome.job.label}  {outcome.wall:.2f} s  ETA {self.eta():.0f} s"
        self._write(line + ("" if outcome.ok else "  LIMIT" if limit_found(outcome) else "  FAILED"),
                    keep=not self.tty)

    def status_line(self, last=None):
        """The long batch's line: done/total, per cent, rate, time left, the last run."""
        elapsed = self.clock() - self.start
        percent = 100.0 * self.done / self.total if self.total else 100.0
        counts = ([f"{self.failed} failed"] if self.failed else []) + ([f"{self.kept} kept"] if self.kept else [])
        counts += [f"{self.limits} past their limit"] if self.limits else []
        notes = [f"last {last.job.label} {last.wall:.2f} s"] if last is not None and not last.skipped else []
        notes += [", ".join(counts)] if counts else []
        tail = f"  ({'; '.join(notes)})" if notes else ""
        return (f"[{self.done}/{self.total}] {percent:.0f} %  {rate_text(self.ran, elapsed)}  "
                f"{duration(self.eta())} left{tail}")

    def _status(self, outcome):
        if self.tty:
            self._write(self.status_line(outcome), keep=False)
            return
        now = self.clock()
        if self.last_line is None or now - self.last_line >= self.period or self.done == self.total:
            self.last_line = now
            self._write(self.status_line(outcome), keep=True)

    def close(self, outcomes):
        limits = sum(limit_found(o) for o in outcomes)
        failed = sum(not o.ok for o in outcomes) - limits
        if self.tty and self.total:
            self.out.write("\n")
        elapsed = self.clock() - self.start
        skipped = sum(o.skipped for o in outcomes)
        kept = f" ({skipped} kept from before)" if skipped else ""
        rate = f", {rate_text(self.ran, elapsed)}" if self.long else ""
        beyond = f", {limits} past their stability limit (measured, not failures)" if limits else ""
        self._write(f"{len(outcomes)} runs: {len(outcomes) - failed - limits} ok{kept}{beyond}, {failed} failed "
                    f"({elapsed:.1f} s{rate})", keep=True)

    def _write(self, text, keep):
        prefix = "\r\x1b[K" if self.tty else ""
        self.out.write(prefix + text + ("\n" if keep else ""))
        self.out.flush()


@contextmanager
def sigterm_as_interrupt():
    """Within: SIGTERM raises KeyboardInterrupt in the main thread, like SIGINT, so a
    terminated harness stops its runs instead of leaving them orphaned.  Only when the
    handler is still the default one and we are in the main thread (else a no-op)."""
    if threading.current_thread() is not threading.main_thread() or \
            signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL:
        yield
        return

    def interrupt(signum, frame):
        raise KeyboardInterrupt
    signal.signal(signal.SIGTERM, interrupt)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)


class Batch:
    """The runs of one command: the executable (hashed once), --resume, and the live processes,
    so that an interrupt stops all of them.  launch() is how every run starts."""

    def __init__(self, binary, resume=False):
        self.binary, self.resume = binary, resume
        self.binary_id = binary_identity(binary)
        self.running = Running()
        self.inputs = Inputs(self.running)     # the files the runs read, listed and hashed once
        self.outcomes = []          # every launch's Outcome, in the order they ended
        self.refused = 0            # queries (ask) not started because the batch was stopping
        self._lock = threading.Lock()

    def launch(self, job):
        """Run one job (run_one) and return its Outcome.  Once the batch is stopping, raise
        Stopped (holding the Outcome) instead, so a task that launches runs in turn ends."""
        outcome = run_one(job, self.binary, self.running, self.resume, self.binary_id, self.inputs)
        with self._lock:
            self.outcomes.append(outcome)
        if self.running.stopping:
            raise Stopped(f"{job.label}: {outcome.cause or 'stopped with its batch'}", outcome)
        return outcome

    def ask(self, cmd):
        """A short query of the core that writes no folder (`ballast info`): (exit code, stdout,
        stderr).  Its process is one of the batch's, so an interrupt stops it as it stops a run."""
        if self.running.stopping:
            with self._lock:
                self.refused += 1
            raise Stopped(" ".join(map(str, cmd)))
        return _execute(cmd, None, self.running)


def _stop(futures, pool, batch, out):
    """After an interrupt: drop the tasks not started, terminate the live runs and wait for
    their threads to record them (SIGKILL after STOP_GRACE s, or at a second interrupt)."""
    pool.shutdown(wait=False, cancel_futures=True)
    batch.running.terminate()
    live = [f for f in futures if not f.cancelled()]     # a cancelled future never counts as done
    try:
        deadline = time.monotonic() + STOP_GRACE
        while wait(live, timeout=POLL)[1] and time.monotonic() < deadline:
            pass
    except KeyboardInterrupt:
        pass
    if wait(live, timeout=0)[1]:
        batch.running.kill()
        wait(live)
    stopped = sum(not o.ok and o.cause.startswith("interrupted:") for o in batch.outcomes)
    # Not started: the tasks cancelled before a thread took them, and those a thread took once
    # the batch was stopping (an interrupt seen late by the main thread, under load), whose
    # first run or first query (a bisection's `ballast info`) was refused.
    dropped = len(futures) - len(live) + batch.refused + \
        sum(o.cause == "interrupted before it started" for o in batch.outcomes)
    print(f"\n{STOPPED} {stopped} run(s) stopped, {dropped} not started; their folders hold no result "
          "(--resume redoes only these)", file=out, flush=True)


def run_tasks(tasks, binary, workers=None, out=sys.stdout, resume=False, done=None):
    """Run tasks in parallel (workers defaults to os.cpu_count()): each task(batch) starts its
    runs through batch.launch and returns a result.  Results in task order; done(i, result),
    when given, is called in the main thread as task i ends (tasks ending together in task
    order).  A task that raised has its exception raised when every task has ended (the
    first by task order).  resume: keep every run whose folder already holds a complete run
    of the same identity.  SIGINT/SIGTERM: stop every run (see the module's docstring), say
    how many on out, then KeyboardInterrupt."""
    workers = max(1, workers or os.cpu_count() or 1)
    batch = Batch(binary, resume)
    results, errors = {}, {}
    pool = ThreadPoolExecutor(max_workers=workers)
    futures = {}
    with sigterm_as_interrupt():
        try:
            for i, task in enumerate(tasks):
                futures[pool.submit(task, batch)] = i
            pending = set(futures)
            while pending:
                # Poll, not block: Python runs a signal's handler in the main thread only, and a
                # signal the kernel gave to a worker thread would not wake a blocked main thread.
                ended, pending = wait(pending, timeout=POLL, return_when=FIRST_COMPLETED)
                for future in sorted(ended, key=futures.get):
                    i = futures[future]
                    if future.exception() is not None:
                        errors[i] = future.exception()
                        continue
                    results[i] = future.result()
                    if done:
                        done(i, results[i])
        except KeyboardInterrupt:
            _stop(list(futures), pool, batch, out)
            raise
    pool.shutdown()
    if errors:
        raise errors[min(errors)]
    return [results[i] for i in range(len(tasks))]


def _single(job):
    """The task of one job: its Outcome, also when the batch is stopping."""
    def task(batch):
        try:
            return batch.launch(job)
        except Stopped as stop:
            return stop.outcome
    return task


def run_all(jobs, binary, workers=None, out=sys.stdout, tty=None, resume=False, limits=True):
    """Run jobs in parallel (workers defaults to os.cpu_count()); Outcomes in job order, each
    job's progress line printed as it ends.  resume: keep the jobs whose folder already holds
    a complete run of the same identity.  limits: a line for each sweep point past its stability
    limit (Progress).  SIGINT/SIGTERM: stop every run (see the module's docstring), then
    KeyboardInterrupt."""
    progress = Progress(jobs, out, tty, limits=limits)
    outcomes = run_tasks([_single(job) for job in jobs], binary, workers, out, resume,
                         lambda i, outcome: progress.finished(outcome))
    progress.close(outcomes)
    return outcomes


