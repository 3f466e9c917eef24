"""Runs beyond one machine: export a batch for GNU parallel or a Slurm job array, run its
jobs there, gather the results back into reports/runs.

The harness has no scheduler of its own.  `export` writes, into a folder DIR that every
machine sees at the same path (a shared file system):

    DIR/manifest.json   the runs: case, variant, scene, --set lines, core command, seed;
                        the executable's path and SHA-256; the repository's path
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

`gather DIR` then brings every finished run into reports/runs/<case>/<variant>/, the layout
`harness run` writes, so check, report and `validate --resume` use them unchanged.  A run is
taken only when it is finished and made by what the local `harness run` would use now: the
same case.txt variant (scene, --set lines, command), the same scene text and the same
executable (runner.stale()); anything else -- not run, failed, half written, changed since,
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
import os
import shlex
from pathlib import Path

from . import REPO_ROOT, files
from .errors import CatalogueError
from .runner import Job, binary_identity, identity, jobs_for, output_digests, run_one, sha256_of, stale

FORMAT = "ballast-export 1"
MANIFEST, JOBS, SLURM = "manifest.json", "jobs.txt", "slurm.sh"
MAX_ARRAY = 1000          # array tasks at most (Slurm's default MaxArraySize is 1001: indices 0..1000)
HARNESS = REPO_ROOT / "harness" / "ballast-harness"


def export(cases, binary, folder, out):
    """Write the manifest, job list and array script of every variant of cases into folder;
    returns the jobs.  The runs already in folder/runs are left (a job keeps a finished one)."""
    folder = Path(folder).resolve()
    binary = Path(os.path.abspath(binary))
    digest = sha256_of(binary)
    if digest is None:
        raise CatalogueError(f"export: cannot read the executable {binary} (build it: make)")
    jobs = jobs_for(cases, folder / "runs")
    if not jobs:
        raise CatalogueError("export: no runs selected")
    relative = next((j for j in jobs if not Path(j.scene).is_absolute()), None)
    if relative:
        raise CatalogueError(f"export: {relative.label}: the scene path {relative.scene} is relative "
                             "(give BALLAST_CASES as an absolute path)")
    manifest = {"format": FORMAT, "repository": str(REPO_ROOT),
                "binary": {"path": str(binary), "sha256": digest},
                "jobs": [{"case": j.case, "variant": j.variant, "scene": str(j.scene),
                          "sets": list(j.sets), "command": j.command, "expected": j.expected,
                          "ensemble": j.ensemble, "seed": j.seed} for j in jobs]}
    files.make_dirs(folder / "runs")
    files.make_dirs(folder / "slurm")
    files.write_text(folder / MANIFEST, json.dumps(manifest, indent=1) + "\n")
    files.write_text(folder / JOBS, "".join(job_line(folder, i) + "\n" for i in range(len(jobs))))
    files.write_text(folder / SLURM, slurm_script(folder, cases, len(jobs)))
    os.chmod(folder / SLURM, 0o755)
    tasks = min(len(jobs), MAX_ARRAY)
    print(f"exported {len(jobs)} run(s) of {', '.join(c.name for c in cases)} to {folder}\n"
          f"  GNU parallel:  parallel -j N < {folder / JOBS}    (other machines: --sshlogin; docs/ensembles.md)\n"
          f"  Slurm:         sbatch {folder / SLURM}    ({tasks} array task(s))\n"
          f"  then:          {HARNESS} gather {folder}", file=out)
    return jobs


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
    """The manifest of an export folder, checked; CatalogueError naming the file if it is not one."""
    path = Path(folder) / MANIFEST
    try:
        manifest = json.loads(path.read_text())
    except FileNotFoundError:
        raise CatalogueError(f"{path}: no such file: not a folder written by `ballast-harness export`") from None
    except (OSError, ValueError) as exc:
        raise CatalogueError(f"{path}: cannot read it: {exc}") from None
    keys = {"case", "variant", "scene", "sets", "command", "expected", "ensemble", "seed"}
    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT or \
            not isinstance(manifest.get("jobs"), list) or \
            not all(isinstance(j, dict) and set(j) == keys for j in manifest["jobs"]) or \
            not isinstance(manifest.get("binary"), dict):
        raise CatalogueError(f"{path}: not a manifest of format '{FORMAT}'")
    return manifest


def manifest_jobs(manifest, runs):
    """The manifest's jobs, their outputs under runs/<case>/<variant>."""
    return [Job(j["case"], j["variant"], Path(j["scene"]), list(j["sets"]), Path(runs) / j["case"] / j["variant"],
                j["expected"], j["command"], j["ensemble"], j["seed"]) for j in manifest["jobs"]]


# ---------------------------------------------------------------- one job, where it runs

def run_job(folder, index, out):
    """Run the manifest's job INDEX into folder/runs (kept when already finished); its Outcome."""
    folder = Path(folder).resolve()
    manifest = load_manifest(folder)
    jobs = manifest_jobs(manifest, folder / "runs")
    if not 0 <= index < len(jobs):
        raise CatalogueError(f"{folder / MANIFEST}: no job {index} (it has jobs 0 to {len(jobs) - 1})")
    binary = Path(manifest["binary"]["path"])
    found = sha256_of(binary)
    if found != manifest["binary"]["sha256"]:
        raise CatalogueError(f"{folder / MANIFEST}: the executable {binary} "
                             f"{'is missing' if found is None else 'changed'} since the export "
                             "(export again, or rebuild what was exported)")
    job = jobs[index]
    outcome = run_one(job, binary, resume=True, binary_id={"path": str(binary), "sha256": found})
    if outcome.skipped:
        print(f"{job.label}: finished before, kept", file=out)
    elif outcome.ok:
        print(f"{job.label}: ok, {outcome.wall:.2f} s", file=out)
    else:
        print(f"{job.label}: FAILED: {outcome.cause}", file=out)
    return outcome


# ---------------------------------------------------------------- gathering

def gather(folder, cases, binary, runs_root, out):
    """Bring every finished run of the export folder into runs_root/<case>/<variant>.
    Returns (gathered, kept, refused): refused is [(label, why)], the runs not taken."""
    folder = Path(folder).resolve()
    manifest = load_manifest(folder)
    local = {j.label: j for j in jobs_for(cases, runs_root)}
    binary = Path(os.path.abspath(binary))
    binary_id = binary_identity(binary)
    gathered, kept, refused = [], [], []
    for remote in manifest_jobs(manifest, folder / "runs"):
        mine = local.get(remote.label)
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
        ident = identity(mine, binary, binary_id)
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
