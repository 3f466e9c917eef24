"""Runs beyond one machine: export a batch for GNU parallel or a Slurm job array, run its
jobs there, gather the results back into reports/runs.

The harness has no scheduler of its own.  `export` writes, into a folder DIR that every
machine sees at the same path (a shared file system):

    DIR/manifest.json   the runs: case, variant, scene, --set lines, core command, seed, and
                        the SHA-256 of every file each run reads (`ballast inputs`); the
                        executable's path and SHA-256; the repository's path
    DIR/jobs.txt        one shell command per run, for GNU parallel (parallel < jobs.txt)
    DIR/slurm.sh        a Slurm job-array script (sbatch DIR/slurm.sh)
    DIR/runs/           where the jobs write: DIR/runs/<case>/<variant>/, as reports/runs
    DIR/slurm/          the array tasks' stdout and stderr

Each job is `harness/ballast-harness job DIR INDEX`: the one run of the manifest's INDEX,
made by runner.run_one exactly as `harness run` makes it (fresh folder, files written whole,
harness.json last, with the run's identity and the digests of its files), with --resume's
rule: a folder that already holds a complete run of the same identity is kept.  So a job
list or an array can be run again after a crash, a kill or a node failure, and redoes only
what is not finished.

The manifest is a file anyone who can write the shared folder can edit, and its names become
paths, so `job` and `gather` check it whole before they touch anything (load_manifest,
job_problem): a case, variant or ensemble that is not a name a case.txt can give (ini.NAME:
no '/', not '.' or '..'), two jobs with one folder, a command the catalogue does not know, a
scene that is not an absolute path, and the whole manifest is refused (exit 2).  A job's
folder must be DIR/runs/<case>/<variant> through no symbolic link, its scene a regular file,
and every file its run reads (the scene, its imports) the same bytes as at the export, or it
is refused before its folder is touched.

`gather DIR` then brings every finished run into reports/runs/<case>/<variant>/, the layout
`harness run` writes, so check, report and `validate --resume` use them unchanged.  A run is
taken only when it is finished and made by what the local `harness run` would use now: the
same case.txt variant (scene, --set lines, command), the same scene text, the same files read
(as the export recorded them, and as they are here) and the same executable
(runner.stale()); a run folder holding a symbolic link is not taken either; anything else -- not run, failed, half written, changed since,
made by another executable -- is listed with its reason and left where it is.  Each run is
copied into a hidden folder beside its destination, its digests checked, harness.json
written last, then renamed into place, so a gather that is killed leaves each destination
either as it was, absent, or whole.

Nothing here depends on where the jobs ran: the outputs of a run depend only on its scene,
--set lines and executable (tests/test_determinism.py), so the gathered outputs equal a local
run's byte for byte (wall-clock fields aside): tests/test_export.py checks it through GNU
parallel in `make test`, harness/tests/slurm/run through a one-node Slurm in `make test-slurm`.
"""
import json
import math
import os
import re
import shlex
import stat
from pathlib import Path

from . import REPO_ROOT, files
from .catalogue import COMMANDS
from .errors import CatalogueError
from .ini import NAME
from .engines.driver import engines
from .engines.matrix import engine_jobs, peers_root
from .runner import (PEER_COMMANDS, Inputs, Job, binary_identity, engine_identity, identity, inputs_change,
                     jobs_for, output_digests, run_one, sha256_of, stale)

FORMAT = "ballast-export 2"   # 2: each job lists the files its run reads, with their SHA-256
JOB_KEYS = {"case", "variant", "scene", "sets", "command", "expected", "ensemble", "seed", "inputs"}
NAME_RULE = re.compile(NAME)
SHA256 = re.compile(r"[0-9a-f]{64}")
MANIFEST, JOBS, SLURM = "manifest.json", "jobs.txt", "slurm.sh"
MAX_ARRAY = 1000          # array tasks at most (Slurm's default MaxArraySize is 1001: indices 0..1000)
HARNESS = REPO_ROOT / "harness" / "ballast-harness"


def export(cases, binary, folder, out, engine=""):
    """Write the manifest, job list and array script of every variant of cases into folder;
    returns the jobs.  The runs already in folder/runs are left (a job keeps a finished one).
    engine: another engine's runs instead of the core's (harness/engines; `make
    validate-peers`'s runs): jobs of command ENGINE:COMMAND, and the manifest records that
    engine's identity (its executable, the adapter's files), which `job` and `gather` hold the
    runs to."""
    folder = Path(folder).resolve()
    binary = Path(os.path.abspath(binary))
    digest = sha256_of(binary)
    if digest is None:
        raise CatalogueError(f"export: cannot read the executable {binary} (build it: make)")
    if engine and engine not in engines():
        raise CatalogueError(f"export: no engine {engine!r} (engines: {', '.join(sorted(engines()))})")
    jobs = engine_jobs(engine, cases, folder / "runs") if engine else jobs_for(cases, folder / "runs")
    if not jobs:
        raise CatalogueError("export: no runs selected")
    relative = next((j for j in jobs if not Path(j.scene).is_absolute()), None)
    if relative:
        raise CatalogueError(f"export: {relative.label}: the scene path {relative.scene} is relative "
                             "(give BALLAST_CASES as an absolute path)")
    inputs = Inputs()
    read = [job_inputs(j, binary, inputs) for j in jobs]
    manifest = {"format": FORMAT, "repository": str(REPO_ROOT),
                "binary": {"path": str(binary), "sha256": digest},
                "engines": {engine: engine_identity(engine)} if engine else {},
                "jobs": [{"case": j.case, "variant": j.variant, "scene": str(j.scene),
                          "sets": list(j.sets), "command": j.command, "expected": j.expected,
                          "ensemble": j.ensemble, "seed": j.seed, "inputs": r} for j, r in zip(jobs, read)]}
    files.make_dirs(folder / "runs")
    files.make_dirs(folder / "slurm")
    files.write_text(folder / MANIFEST, json.dumps(manifest, indent=1) + "\n")
    files.write_text(folder / JOBS, "".join(job_line(folder, i) + "\n" for i in range(len(jobs))))
    files.write_text(folder / SLURM, slurm_script(folder, cases, len(jobs)))
    os.chmod(folder / SLURM, 0o755)
    tasks = min(len(jobs), MAX_ARRAY)
    print(f"exported {len(jobs)} {engines()[engine].title + ' ' if engine else ''}run(s) of "
          f"{', '.join(c.name for c in cases)} to {folder}\n"
          f"  GNU parallel:  parallel -j N < {folder / JOBS}    (other machines: --sshlogin; docs/ensembles.md)\n"
          f"  Slurm:         sbatch {folder / SLURM}    ({tasks} array task(s))\n"
          f"  then:          {HARNESS} gather {folder}", file=out)
    return jobs


def job_inputs(job, binary, inputs):
    """{path: SHA-256} of every file the job's run reads ({} for a cross-check against
    LAMMPS, which reads no scene of the catalogue); CatalogueError when they cannot be listed."""
    if job.command in PEER_COMMANDS:
        return {}
    read = inputs.digests(binary, job.scene, job.sets)
    if not isinstance(read, dict) or None in read.values():
        raise CatalogueError(f"export: {job.label}: {inputs_change({}, read)}")
    return read


def job_line(folder, index):
    """The shell command of one job: the harness's `job` command on the manifest's index."""
    return f"{shlex.quote(str(HARNESS))} job {shlex.quote(str(folder))} {index}"


def slurm_script(folder, cases, count):
    """A job-array script: task t runs the jobs t, t + T, t + 2T, ... (T tasks, at most MAX_ARRAY)."""
    tasks = min(count, MAX_ARRAY)
    name = "ballast-" + "-".join(c.name for c in cases)[:40]
    return f"""#!/bin/bash
# Slurm job array of {count} ballast run(s), written by `ballast-harness export` (docs/ensembles.md).
#   sbatch {folder / SLURM}          (sbatch's own options, e.g. -p PARTITION --time=1:00:00, win over these)
# then, when the array has ended:
#   {HARNESS} gather {folder}
# Array task t runs the manifest's jobs t, t + {tasks}, t + {2 * tasks}, ...  A job whose folder
# already holds a finished run of the same identity keeps it, so the array may be submitted again.
#SBATCH --job-name={name}
#SBATCH --array=0-{tasks - 1}
#SBATCH --ntasks=1
#SBATCH --cpus-per-task=1
#SBATCH --output={folder}/slurm/%A_%a.out
#SBATCH --error={folder}/slurm/%A_%a.err
set -u
status=0
for i in $(seq "$SLURM_ARRAY_TASK_ID" {tasks} {count - 1}); do
    {shlex.quote(str(HARNESS))} job {shlex.quote(str(folder))} "$i" || status=1
done
exit $status
"""


# ---------------------------------------------------------------- reading a manifest

def load_manifest(folder):
    """The manifest of an export folder, checked; CatalogueError naming the file if it is not
    one, or if any job is not one `export` writes (job_problem): a manifest is a file anyone
    who can write the shared folder may have edited, and its names become paths."""
    path = Path(folder) / MANIFEST
    try:
        manifest = json.loads(path.read_text())
    except FileNotFoundError:
        raise CatalogueError(f"{path}: no such file: not a folder written by `ballast-harness export`") from None
    except (OSError, ValueError) as exc:
        raise CatalogueError(f"{path}: cannot read it: {exc}") from None
    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT or \
            not isinstance(manifest.get("jobs"), list) or \
            not all(isinstance(j, dict) and set(j) == JOB_KEYS for j in manifest["jobs"]) or \
            not isinstance(manifest.get("binary"), dict) or \
            not isinstance(manifest.setdefault("engines", {}), dict):
        raise CatalogueError(f"{path}: not a manifest of format '{FORMAT}' (export again)")
    for name, ident in manifest["engines"].items():
        if name not in engines() or not isinstance(ident, dict):
            raise CatalogueError(f"{path}: its engines must be {{name: identity}} of {', '.join(sorted(engines()))}; "
                                 f"got {name!r}; refused, nothing run")
    binary = manifest["binary"]
    if not isinstance(binary.get("path"), str) or not os.path.isabs(binary["path"]) or "\0" in binary["path"] \
            or not isinstance(binary.get("sha256"), str) or not SHA256.fullmatch(binary["sha256"]):
        raise CatalogueError(f"{path}: its binary must be an absolute path and a SHA-256; refused, nothing run")
    first = {}
    for index, job in enumerate(manifest["jobs"]):
        why = job_problem(job)
        if not why and ":" in job["command"] and job["command"].split(":", 1)[0] not in manifest["engines"]:
            why = f"its engine {job['command'].split(':', 1)[0]!r} has no identity in the manifest's engines"
        if why:
            raise CatalogueError(f"{path}: job {index}: {why}; refused, nothing run or written")
        label = (job["case"], job["variant"])
        if label in first:
            raise CatalogueError(f"{path}: job {index}: {'/'.join(label)} is job {first[label]} too (both would "
                                 "write one folder); refused, nothing run or written")
        first[label] = index
    return manifest


def job_problem(job):
    """Why a manifest's job is not one that `export` writes ('' when it is).  Its case and
    variant name its folder DIR/runs/<case>/<variant>: they must be names a case.txt can give
    (ini.NAME: no '/', not '.' or '..', no leading '.'), so that folder is inside DIR/runs;
    its ensemble likewise.  Its scene is an absolute path (the catalogue's, at export), its
    --set lines strings a command line can hold, its command one of the catalogue's, its
    inputs {path: SHA-256} naming the scene (a cross-check against LAMMPS: none)."""
    for key in ("case", "variant"):
        if not isinstance(job[key], str) or not NAME_RULE.fullmatch(job[key]):
            return (f"its {key} {job[key]!r} is not a name a case.txt can give (letters, digits, '_', '.', '-'; "
                    "no '/', not starting with '.' or '-'): its folder would not be one under DIR/runs")
    if not isinstance(job["ensemble"], str) or (job["ensemble"] and not NAME_RULE.fullmatch(job["ensemble"])):
        return f"its ensemble {job['ensemble']!r} is not a name a case.txt can give"
    if job["seed"] is not None and (type(job["seed"]) is not int or job["seed"] < 0):
        return f"its seed {job['seed']!r} is not a whole number >= 0"
    command = job["command"]
    engine, _, what = command.rpartition(":") if isinstance(command, str) else ("", "", command)
    if what not in COMMANDS or (":" in command and engine not in engines()):
        return (f"its command {command!r} is none of {', '.join(COMMANDS)}, nor ENGINE:COMMAND of one of them "
                f"(engines: {', '.join(sorted(engines()))})")
    scene = job["scene"]
    if not isinstance(scene, str) or not os.path.isabs(scene) or "\0" in scene:
        return f"its scene {scene!r} is not an absolute path"
    if not isinstance(job["sets"], list) or not all(isinstance(kv, str) and "\0" not in kv for kv in job["sets"]):
        return "its sets are not a list of KEY=VALUE strings"
    expected = job["expected"]
    if type(expected) not in (int, float) or not math.isfinite(expected) or expected < 0:
        return f"its expected run time {expected!r} is not a number >= 0"
    inputs = job["inputs"]
    if not isinstance(inputs, dict) or not all(isinstance(p, str) and isinstance(d, str) and SHA256.fullmatch(d)
                                               for p, d in inputs.items()):
        return "its inputs are not {path: SHA-256}"
    if job["command"] not in PEER_COMMANDS and scene not in inputs:
        return "its inputs do not list its scene"
    return ""


def manifest_jobs(manifest, runs):
    """The manifest's jobs, their outputs under runs/<case>/<variant>."""
    return [Job(j["case"], j["variant"], Path(j["scene"]), list(j["sets"]), Path(runs) / j["case"] / j["variant"],
                j["expected"], j["command"], j["ensemble"], j["seed"]) for j in manifest["jobs"]]


# ---------------------------------------------------------------- one job, where it runs

def unlinked(runs, job):
    """'' when job.out is DIR/runs/<case>/<variant> with no symbolic link on the way (below
    DIR/runs, which may be one), else what it leads to: a link would take the job's writes,
    or gather's reads, to another folder."""
    real = os.path.realpath(job.out)
    if real == os.path.join(os.path.realpath(runs), job.case, job.variant):
        return ""
    return f"{job.out} is a symbolic link, or lies under one, to {real}"


def scene_problem(scene):
    """'' when the scene is a regular file (a FIFO would block the core), else why not."""
    try:
        mode = os.stat(scene).st_mode
    except OSError as exc:
        return f"its scene {scene}: {exc.strerror}"
    return "" if stat.S_ISREG(mode) else f"its scene {scene} is not a regular file"


def run_job(folder, index, out):
    """Run the manifest's job INDEX into folder/runs (kept when already finished); its Outcome.
    Before anything is written: the manifest checked (load_manifest), the job's folder
    DIR/runs/<case>/<variant> with no symbolic link, the executable and every file the run
    reads (its scene, the files its [import] sections name) the ones the export recorded."""
    folder = Path(folder).resolve()
    manifest = load_manifest(folder)
    jobs = manifest_jobs(manifest, folder / "runs")
    if not 0 <= index < len(jobs):
        raise CatalogueError(f"{folder / MANIFEST}: no job {index} (it has jobs 0 to {len(jobs) - 1})")
    job = jobs[index]
    where = f"{folder / MANIFEST}: job {index} ({job.label})"
    why = unlinked(folder / "runs", job) or scene_problem(job.scene)
    if why:
        raise CatalogueError(f"{where}: {why}; refused, nothing run or written")
    binary = Path(manifest["binary"]["path"])
    found = sha256_of(binary)
    if found != manifest["binary"]["sha256"]:
        raise CatalogueError(f"{folder / MANIFEST}: the executable {binary} "
                             f"{'is missing' if found is None else 'changed'} since the export "
                             "(export again, or rebuild what was exported)")
    if ":" in job.command:
        engine = job.command.split(":", 1)[0]
        changed = engine_change(manifest["engines"][engine], engine_identity(engine))
        if changed:
            raise CatalogueError(f"{where}: {changed} since the export (export again); refused, nothing "
                                 "run or written")
    inputs = Inputs()
    if job.command not in PEER_COMMANDS:
        changed = inputs_change(manifest["jobs"][index]["inputs"], inputs.digests(binary, job.scene, job.sets))
        if changed:
            raise CatalogueError(f"{where}: {changed}, against what the export recorded (export again); "
                                 "refused, nothing run or written")
    outcome = run_one(job, binary, resume=True, binary_id={"path": str(binary), "sha256": found}, inputs=inputs)
    if outcome.skipped:
        print(f"{job.label}: finished before, kept", file=out)
    elif outcome.ok:
        print(f"{job.label}: ok, {outcome.wall:.2f} s", file=out)
    else:
        print(f"{job.label}: FAILED: {outcome.cause}", file=out)
    return outcome


def engine_change(recorded, now):
    """What differs between an engine's identity at the export and here ('' when nothing):
    its executable or an adapter file (harness/engines)."""
    for key in sorted(set(recorded) | set(now)):
        if recorded.get(key) != now.get(key):
            what = {"lmp": "executable's path", "lmp_sha256": "executable"}.get(key, f"adapter file {key}")
            return f"the engine's {what} changed"
    return ""


# ---------------------------------------------------------------- gathering

def gather(folder, cases, binary, runs_root, out, reports=None):
    """Bring every finished run of the export folder into runs_root/<case>/<variant> (an
    engine's run: into reports/peers/runs/ENGINE/<case>/<variant>, where `make validate-peers`
    keeps them; reports: the reports folder, default runs_root's parent).  Returns (gathered,
    kept, refused): refused is [(label, why)], the runs not taken."""
    folder = Path(folder).resolve()
    manifest = load_manifest(folder)
    remotes = manifest_jobs(manifest, folder / "runs")
    linked = next((why for why in (unlinked(folder / "runs", r) for r in remotes) if why), "")
    if linked:
        raise CatalogueError(f"{folder}: {linked}; refused, nothing gathered")
    local = {(j.command, j.label): j for j in jobs_for(cases, runs_root)}
    peers = peers_root(reports or Path(runs_root).parent) / "runs"
    for engine in manifest["engines"]:
        local.update({(j.command, j.label): j for j in engine_jobs(engine, cases, peers / engine)})
    binary = Path(os.path.abspath(binary))
    binary_id = binary_identity(binary)
    inputs = Inputs()
    gathered, kept, refused = [], [], []
    for remote, entry in zip(remotes, manifest["jobs"]):
        mine = local.get((remote.command, remote.label))
        if mine is None and any(label == remote.label for _, label in local):
            refused.append((remote.label, "its case.txt variant changed since the export (export again)"))
            continue
        if mine is None:
            refused.append((remote.label, "no such variant in the catalogue now"))
            continue
        if str(mine.scene) != str(remote.scene):
            refused.append((remote.label, f"its scene is {mine.scene} here, {remote.scene} in the export "
                                          "(gather with the catalogue that was exported)"))
            continue
        if (mine.sets, mine.command) != (remote.sets, remote.command):
            refused.append((remote.label, "its case.txt variant changed since the export (export again)"))
            continue
        ident = identity(mine, binary, binary_id, inputs)
        changed = "" if mine.command in PEER_COMMANDS else inputs_change(entry["inputs"], ident["inputs"])
        if changed:
            refused.append((remote.label, f"{changed}, against what the export recorded (export again)"))
            continue
        why = stale(remote, ident)
        if why:
            refused.append((remote.label, why))
            continue
        if not stale(mine, ident) and output_digests(mine.out) == output_digests(remote.out):
            kept.append(remote.label)
            continue
        changed = copy_run(remote.out, mine.out)
        if changed:
            refused.append((remote.label, changed))
            continue
        gathered.append(remote.label)
    for label, why in refused:
        print(f"NOT GATHERED {label}: {why}", file=out)
    print(f"gather {folder}: {len(gathered)} run(s) gathered, {len(kept)} already here, "
          f"{len(refused)} not gathered (of {len(manifest['jobs'])})", file=out)
    return gathered, kept, refused


def copy_run(source, dest):
    """dest becomes a copy of the finished run folder source: files copied into a hidden
    sibling, checked against the digests of source's harness.json, harness.json written last
    (noting where it came from), then renamed into place.  Returns '' when done, or why not
    (dest then left as it was)."""
    record = json.loads((source / "harness.json").read_text())
    staging = dest.with_name(f".{dest.name}.gathering")
    old = dest.with_name(f".{dest.name}.old")
    if any(path.is_symlink() for path in source.iterdir()):
        return "its folder holds a symbolic link (a job writes none)"
    files.remove_tree(staging)
    files.make_dirs(staging)
    for path in sorted(source.iterdir()):
        if path.is_file() and path.name != "harness.json":
            files.copy(path, staging / path.name)
    if output_digests(staging) != record["outputs"]:
        files.remove_tree(staging)
        return "its files changed while they were copied (is a job still running?)"
    record["gathered_from"] = str(source)
    files.write_text(staging / "harness.json", json.dumps(record, indent=1) + "\n")
    files.remove_tree(old)
    try:
        if dest.exists():
            os.rename(dest, old)
        os.rename(staging, dest)
    except OSError as exc:
        raise files.failure("write", dest, exc) from exc
    files.remove_tree(old)
    return ""
