"""Running bin/ballast: one subprocess per (case, variant), in parallel, with progress lines.

Each run gets a fresh folder (the old one is removed first) that is also its working
directory, so runs share no state and their results cannot depend on -j or on order.
After the run the folder holds the core's outputs plus ballast.stdout, ballast.stderr and
harness.json (the command, exit code, wall time and, on failure, the cause).
"""
import json
import os
import shutil
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path

from .tables import RunProblem, read_run_json, run_failure

STDERR_TAIL = 5


@dataclass
class Job:
    case: str
    variant: str
    scene: Path
    sets: list
    out: Path
    expected: float = 0.0   # expected seconds, for the ETA
    command: str = "run"    # the core's command: run (DEM) or exact (static solver)

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


def jobs_for(cases, runs_root):
    """One Job per variant of each case, outputs in runs_root/<case>/<variant>."""
    return [Job(c.name, v.name, v.scene, list(v.sets), Path(runs_root) / c.name / v.name,
                c.runtime / len(c.variants), v.command)
            for c in cases for v in c.variants]


def command(job, binary):
    """The core's command line for a job."""
    if job.command == "peer":
        # The cross-code check against LAMMPS: a Python script, not the core.
        race = Path(__file__).resolve().parent.parent / "bench" / "peer" / "race.py"
        return ["/usr/bin/python3", str(race), "--check-only", "--out", str(job.out)]
    cmd = [str(binary), job.command, str(job.scene), "--out", str(job.out)]
    for kv in job.sets:
        cmd += ["--set", kv]
    return cmd


class Running:
    """The live subprocesses, so an interrupt can stop them all."""

    def __init__(self):
        self._procs, self._lock = set(), threading.Lock()

    def add(self, proc):
        with self._lock:
            self._procs.add(proc)

    def remove(self, proc):
        with self._lock:
            self._procs.discard(proc)

    def terminate(self):
        with self._lock:
            for proc in self._procs:
                proc.terminate()


def fresh_folder(path):
    """An empty folder at path (whatever was there is removed)."""
    path = Path(path)
    if path.exists():
        shutil.rmtree(path)
    path.mkdir(parents=True)


def run_one(job, binary, running=None):
    """Run one job to completion; the Outcome says whether it produced usable outputs."""
    try:
        fresh_folder(job.out)
    except OSError as exc:
        return Outcome(job, False, None, 0.0, f"cannot prepare {job.out}: {exc}")
    cmd = command(job, binary)
    start = time.monotonic()
    try:
        returncode, stdout, stderr = _execute(cmd, job.out, running)
    except OSError as exc:
        returncode, stdout, stderr = None, "", f"cannot start {binary}: {exc.strerror}"
    wall = time.monotonic() - start
    (job.out / "ballast.stdout").write_text(stdout, encoding="utf-8")
    (job.out / "ballast.stderr").write_text(stderr, encoding="utf-8")
    cause = _cause(job, returncode, stderr)
    outcome = Outcome(job, not cause, returncode, wall, cause)
    _record(outcome, cmd)
    return outcome


def _execute(cmd, cwd, running):
    proc = subprocess.Popen(cmd, cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, errors="replace")
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
        return run_failure(job.out, read_run_json(job.out)) or ""
    except RunProblem as problem:
        return f"exit code 0 but {problem}"


def _record(outcome, cmd):
    """harness.json: the runner's own account of the run."""
    record = {"case": outcome.job.case, "variant": outcome.job.variant, "command": cmd,
              "returncode": outcome.returncode, "wall_seconds": round(outcome.wall, 6),
              "ok": outcome.ok, "cause": outcome.cause}
    (outcome.job.out / "harness.json").write_text(json.dumps(record, indent=1) + "\n", encoding="utf-8")


class Progress:
    """'[done/total] case/variant  1.23 s  ETA 4 s': redrawn with \\r on a tty, plain lines otherwise."""

    def __init__(self, jobs, out, tty=None):
        self.total, self.done, self.out = len(jobs), 0, out
        self.expected_total = sum(j.expected for j in jobs)
        self.expected_done = 0.0
        self.tty = out.isatty() if tty is None else tty
        self.start = time.monotonic()

    def eta(self):
        """Seconds left, scaled from the expected run times of what has finished."""
        elapsed = time.monotonic() - self.start
        if self.done >= self.total:
            return 0.0
        if self.expected_done > 0:
            return elapsed * (self.expected_total - self.expected_done) / self.expected_done
        return elapsed / max(self.done, 1) * (self.total - self.done)

    def finished(self, outcome):
        self.done += 1
        self.expected_done += outcome.job.expected
        if not outcome.ok:
            self._write(f"FAILED {outcome.job.label}: {outcome.cause}", keep=True)
        line = f"[{self.done}/{self.total}] {outcome.job.label}  {outcome.wall:.2f} s  ETA {self.eta():.0f} s"
        self._write(line + ("" if outcome.ok else "  FAILED"), keep=not self.tty)

    def close(self, outcomes):
        failed = sum(not o.ok for o in outcomes)
        if self.tty and self.total:
            self.out.write("\n")
        elapsed = time.monotonic() - self.start
        self._write(f"{len(outcomes)} runs: {len(outcomes) - failed} ok, {failed} failed ({elapsed:.1f} s)", keep=True)

    def _write(self, text, keep):
        prefix = "\r\x1b[K" if self.tty else ""
        self.out.write(prefix + text + ("\n" if keep else ""))
        self.out.flush()


def run_all(jobs, binary, workers=None, out=sys.stdout, tty=None):
    """Run jobs in parallel (workers defaults to os.cpu_count()); Outcomes in job order."""
    workers = max(1, workers or os.cpu_count() or 1)
    progress, running = Progress(jobs, out, tty), Running()
    outcomes = {}
    pool = ThreadPoolExecutor(max_workers=workers)
    try:
        futures = {pool.submit(run_one, job, binary, running): i for i, job in enumerate(jobs)}
        for future in as_completed(futures):
            outcomes[futures[future]] = future.result()
            progress.finished(outcomes[futures[future]])
    except KeyboardInterrupt:
        pool.shutdown(wait=False, cancel_futures=True)
        running.terminate()
        raise
    pool.shutdown()
    ordered = [outcomes[i] for i in range(len(jobs))]
    progress.close(ordered)
    return ordered


def sweep_jobs(case, variant, key, values, sweeps_root):
    """One Job per value: the variant with KEY=value appended, outputs in sweeps_root/<case>/<KEY>=<V>."""
    return [Job(case.name, f"{key}={v}", variant.scene, list(variant.sets) + [f"{key}={v}"],
                Path(sweeps_root) / case.name / f"{key}={v}", case.runtime / len(case.variants),
                variant.command)
            for v in values]
