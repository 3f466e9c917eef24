"""Runs beyond one machine (issue 22, item 5): export, job, gather (harness/export.py).

With the fake core: what export writes (manifest, one job line per run, a job-array script
bash accepts); jobs then gather give reports/runs exactly as `run` writes it (same bytes,
`run --resume` keeps them all, `check` reads them); gather takes nothing unfinished, changed,
made by another executable or by another case.txt, says why for each, exits 1, and leaves
their destinations alone; a gather killed while it copies leaves the old run or none, never
a part; bad export folders and indices are refused with the file named, exit 2.

With the real bin/ballast and GNU parallel (installed by .ci/install-deps): the exported job
list of the test ensemble run by `parallel -j 2`, killed part way and run again (finished
jobs kept), then gathered: the same bytes as a local `harness run` (wall clocks aside).
The Slurm path is tested for real by `make test-slurm` (harness/tests/slurm/run).
"""
import json
import os
import shutil
import signal
import subprocess
import time
from pathlib import Path

import pytest

from harness import export, files
from harness.__main__ import main
from harness.runner import output_digests
from harness.tests.fakes import tree_snapshot
from harness.tests.test_ensemble_runs import NAMES, catalogue_with_ensemble, needs_ballast, outputs

SPRINGS = "\n[ensemble k]\nscene = spring.scene\nset = k={seed}\nseeds = 1-4\n"
VARIANTS = ["soft", "stiff", "stiffer", "k_s1", "k_s2", "k_s3", "k_s4"]


@pytest.fixture
def springs(project):
    path = project / "cases" / "springs" / "case.txt"
    path.write_text(path.read_text() + SPRINGS)
    return project


def run_jobs(folder, indices):
    """`job FOLDER INDEX` for each index, in this process: their exit statuses."""
    return [main(["job", str(folder), str(i)]) for i in indices]


def raw(folder):
    """{file: bytes} of a run folder but harness.json."""
    return {p.name: p.read_bytes() for p in sorted(Path(folder).iterdir()) if p.name != "harness.json"}


def jobs_alive(folder):
    """pids of the processes whose command line names the export folder (its jobs)."""
    found = []
    for entry in Path("/proc").iterdir():
        try:
            if entry.name.isdigit() and str(folder).encode() in (entry / "cmdline").read_bytes():
                found.append(int(entry.name))
        except OSError:
            pass
    return found


def test_export_writes_a_job_per_run_and_an_array_script(springs, tmp_path, capsys):
    folder = tmp_path / "shared"
    assert main(["export", "spring", "--to", str(folder)]) == 0
    out = capsys.readouterr().out
    assert f"exported 7 run(s) of spring to {folder}" in out and "sbatch" in out and "gather" in out
    manifest = json.loads((folder / "manifest.json").read_text())
    assert [j["variant"] for j in manifest["jobs"]] == VARIANTS
    assert [j["seed"] for j in manifest["jobs"]] == [None] * 3 + [1, 2, 3, 4]
    assert manifest["jobs"][4]["sets"] == ["k=2"] and manifest["binary"]["path"] == str(springs / "bin" / "ballast")
    lines = (folder / "jobs.txt").read_text().splitlines()
    assert lines == [f"{export.HARNESS} job {folder} {i}" for i in range(7)]
    script = (folder / "slurm.sh").read_text()
    assert "#SBATCH --array=0-6\n" in script and 'seq "$SLURM_ARRAY_TASK_ID" 7 6' in script
    assert f"#SBATCH --output={folder}/slurm/%A_%a.out" in script and (folder / "slurm").is_dir()
    assert subprocess.run(["bash", "-n", str(folder / "slurm.sh")]).returncode == 0
    assert os.access(folder / "slurm.sh", os.X_OK)


def test_a_big_array_runs_several_jobs_per_task(springs, tmp_path, monkeypatch):
    monkeypatch.setattr(export, "MAX_ARRAY", 3)
    assert main(["export", "spring", "--to", str(tmp_path / "x")]) == 0
    script = (tmp_path / "x" / "slurm.sh").read_text()
    assert "#SBATCH --array=0-2\n" in script and 'seq "$SLURM_ARRAY_TASK_ID" 3 6' in script
    tasks = [subprocess.run(["bash", "-c", 'seq "$SLURM_ARRAY_TASK_ID" 3 6'], capture_output=True, text=True,
                            env={**os.environ, "SLURM_ARRAY_TASK_ID": str(t)}).stdout.split() for t in range(3)]
    assert sorted(int(i) for t in tasks for i in t) == list(range(7))       # every job once


def test_jobs_then_gather_give_what_run_writes(springs, tmp_path, capsys):
    runs = springs / "reports" / "runs" / "spring"
    assert main(["run", "spring"]) == 0
    local_bytes = {v: raw(runs / v) for v in VARIANTS}
    shutil.rmtree(springs / "reports" / "runs")
    folder = tmp_path / "shared"
    assert main(["export", "spring", "--to", str(folder)]) == 0
    assert run_jobs(folder, range(7)) == [0] * 7
    assert run_jobs(folder, [2]) == [0]                              # again: kept, not redone
    assert "spring/stiffer: finished before, kept" in capsys.readouterr().out
    assert main(["gather", str(folder)]) == 0
    assert "7 run(s) gathered, 0 already here, 0 not gathered (of 7)" in capsys.readouterr().out
    for v in VARIANTS:
        assert raw(runs / v) == local_bytes[v], v                    # the fake core has no wall clock
        record = json.loads((runs / v / "harness.json").read_text())
        assert record["gathered_from"] == str(folder / "runs" / "spring" / v)
    assert json.loads((runs / "k_s3" / "harness.json").read_text())["seed"] == 3
    assert [p.name for p in runs.iterdir() if p.name.startswith(".")] == []
    gathered = {v: tree_snapshot(runs / v) for v in VARIANTS}
    assert main(["gather", str(folder)]) == 0                        # again: nothing to do
    assert "0 run(s) gathered, 7 already here" in capsys.readouterr().out
    assert {v: tree_snapshot(runs / v) for v in VARIANTS} == gathered
    assert main(["run", "spring", "--resume"]) == 0                  # the local runner takes them as its own
    assert "7 runs: 7 ok (7 kept from before), 0 failed" in capsys.readouterr().out
    assert main(["check", "spring"]) == 0


def test_gather_takes_only_finished_runs_of_what_would_run_here(springs, tmp_path, capsys):
    folder = tmp_path / "shared"
    assert main(["export", "spring", "--to", str(folder)]) == 0
    assert run_jobs(folder, [0, 1, 2, 3, 4, 5]) == [0] * 6           # k_s4 never runs
    remote = folder / "runs" / "spring"
    with open(remote / "stiff" / "series.tsv", "a") as f:            # changed after its run
        f.write("11\t1.1\t22\t121\n")
    (remote / "soft" / "discs.tsv.tmp").write_text("half")           # a writer stopped half way
    (remote / "k_s2" / "harness.json").unlink()                      # killed before its record
    case_txt = springs / "cases" / "springs" / "case.txt"
    case_txt.write_text(case_txt.read_text().replace("[variant stiffer]", "[variant stiffer]\nset = n=12"))
    capsys.readouterr()
    assert main(["gather", str(folder)]) == 1
    out = capsys.readouterr().out
    assert "NOT GATHERED spring/soft: its files changed since the run" in out
    assert "NOT GATHERED spring/stiff: its files changed since the run" in out
    assert "NOT GATHERED spring/stiffer: its case.txt variant changed since the export (export again)" in out
    assert "NOT GATHERED spring/k_s2: no harness.json (never run, or stopped before it finished)" in out
    assert "NOT GATHERED spring/k_s4: no harness.json" in out
    assert "2 run(s) gathered, 0 already here, 5 not gathered (of 7)" in out
    runs = springs / "reports" / "runs" / "spring"
    assert sorted(p.name for p in runs.iterdir()) == ["k_s1", "k_s3"]

    fake = springs / "bin" / "ballast"                               # rebuilt since the export
    fake.write_text(fake.read_text() + "# rebuilt\n")
    assert main(["job", str(folder), "6"]) == 2
    assert "the executable" in capsys.readouterr().err and not (remote / "k_s4").exists()
    assert main(["gather", str(folder)]) == 1
    out = capsys.readouterr().out
    assert "NOT GATHERED spring/k_s1: made by another command line, scene or executable" in out
    assert "0 run(s) gathered" in out


def test_a_gather_killed_while_it_copies_leaves_the_old_run_or_none(springs, tmp_path, monkeypatch, capsys):
    folder = tmp_path / "shared"
    assert main(["export", "spring", "--to", str(folder)]) == 0
    assert run_jobs(folder, range(7)) == [0] * 7
    runs = springs / "reports" / "runs" / "spring"
    assert main(["run", "spring"]) == 0                             # a local run of soft, stiff, ... first
    (runs / "k_s1" / "series.tsv").write_text("tampered")          # so gather has to replace k_s1
    old = tree_snapshot(runs / "k_s1")
    shutil.rmtree(runs / "k_s2")                                    # and to create k_s2
    copied = []
    real_copy = files.copy

    def copy_then_die(source, path):
        copied.append(path)
        if len(copied) == 3:
            raise KeyboardInterrupt                                 # the kill, half way through k_s1
        real_copy(source, path)
    monkeypatch.setattr(files, "copy", copy_then_die)
    assert main(["gather", str(folder)]) == 130
    assert tree_snapshot(runs / "k_s1") == old                      # untouched
    assert not (runs / "k_s2").exists()
    assert not (runs / ".k_s1.gathering" / "harness.json").exists()  # the part copy is no result
    monkeypatch.setattr(files, "copy", real_copy)
    capsys.readouterr()
    assert main(["gather", str(folder)]) == 0
    assert "2 run(s) gathered, 5 already here" in capsys.readouterr().out
    assert [p.name for p in runs.iterdir() if p.name.startswith(".")] == []
    assert output_digests(runs / "k_s1") == output_digests(folder / "runs" / "spring" / "k_s1")


def test_bad_export_folders_and_indices_are_refused(springs, tmp_path, capsys):
    assert main(["job", str(tmp_path / "nowhere"), "0"]) == 2
    assert f"{tmp_path / 'nowhere' / 'manifest.json'}: no such file" in capsys.readouterr().err
    folder = tmp_path / "shared"
    assert main(["export", "spring", "--to", str(folder)]) == 0
    assert main(["job", str(folder), "7"]) == 2
    assert "no job 7 (it has jobs 0 to 6)" in capsys.readouterr().err
    (folder / "manifest.json").write_text('{"format": "something else"}')
    assert main(["gather", str(folder)]) == 2
    assert f"not a manifest of format '{export.FORMAT}'" in capsys.readouterr().err
    (folder / "manifest.json").write_text('{"jobs": [')
    assert main(["job", str(folder), "0"]) == 2
    assert "manifest.json: cannot read it" in capsys.readouterr().err
    assert main(["export", "nosuchcase", "--to", str(folder)]) == 2


def test_an_engines_runs_export_with_its_identity_and_run_only_on_that_engine(springs, tmp_path, capsys):
    """`export --engine lammps`: the jobs of command lammps:run, the manifest holding LAMMPS's
    identity (its executable, the adapter's files: what the runner records); a job whose engine
    changed since is refused before anything is written, and so is an unknown engine."""
    from harness.runner import engine_identity
    folder = tmp_path / "shared"
    assert main(["export", "spring", "--to", str(folder), "--engine", "lammps"]) == 0
    assert f"exported 7 LAMMPS run(s) of spring to {folder}" in capsys.readouterr().out
    manifest = json.loads((folder / "manifest.json").read_text())
    assert manifest["format"] == "ballast-export 2"
    assert {j["command"] for j in manifest["jobs"]} == {"lammps:run"}
    assert manifest["engines"] == {"lammps": json.loads(json.dumps(engine_identity("lammps")))}
    assert any(k.endswith("harness/engines/lammps_input.py") for k in manifest["engines"]["lammps"])
    # the scene's files are the job's inputs, as for the core's runs
    assert all(j["scene"] in j["inputs"] for j in manifest["jobs"])
    # LAMMPS (or an adapter file) changed since the export: refused, nothing written
    recorded = manifest["engines"]["lammps"]
    recorded["lmp_sha256"] = "0" * 64
    (folder / "manifest.json").write_text(json.dumps(manifest))
    assert main(["job", str(folder), "0"]) == 2
    assert "the engine's executable changed since the export (export again)" in capsys.readouterr().err
    assert not (folder / "runs" / "spring" / "soft").exists()
    # a job naming an engine the manifest has no identity for, or no engine at all
    for command, why in (("other:run", "none of run, exact"), ("lammps:tea", "none of run, exact")):
        manifest["jobs"][0]["command"] = command
        (folder / "manifest.json").write_text(json.dumps(manifest))
        assert main(["job", str(folder), "1"]) == 2
        assert why in capsys.readouterr().err
    manifest["jobs"][0]["command"] = "lammps:run"
    manifest["engines"] = {}
    (folder / "manifest.json").write_text(json.dumps(manifest))
    assert main(["job", str(folder), "1"]) == 2
    assert "its engine 'lammps' has no identity in the manifest's engines" in capsys.readouterr().err
    assert main(["export", "spring", "--to", str(folder), "--engine", "nosuch"]) == 2
    assert "no engine 'nosuch'" in capsys.readouterr().err


# ---------------------------------------------------------------- GNU parallel, for real

@needs_ballast
def test_gnu_parallel_runs_the_exported_list_to_the_bytes_of_a_local_run(tmp_path):
    assert shutil.which("parallel"), "GNU parallel is missing: sh .ci/install-deps installs it"
    env = catalogue_with_ensemble(tmp_path, settle=40000)
    local, gathered, folder = tmp_path / "local", tmp_path / "gathered", tmp_path / "shared"
    with pytest.MonkeyPatch.context() as mp:
        for key, value in env.items():
            mp.setenv(key, value)
        mp.setenv("BALLAST_REPORTS", str(local))
        assert main(["run", "-j", "2"]) == 0
        assert main(["export", "packing", "--to", str(folder)]) == 0

        # parallel -j 2 on the list, killed (its whole process group) once 2 runs are recorded
        remote = folder / "runs" / "packing"
        first = subprocess.Popen(["parallel", "-j", "2"], stdin=open(folder / "jobs.txt"),
                                 stdout=subprocess.PIPE, stderr=subprocess.STDOUT, start_new_session=True)
        deadline = time.monotonic() + 120
        while sum((remote / n / "harness.json").exists() for n in NAMES) < 2:
            assert first.poll() is None and time.monotonic() < deadline, first.communicate()[0]
            time.sleep(0.01)
        os.killpg(first.pid, signal.SIGKILL)
        first.communicate()
        while jobs_alive(folder):                   # a job parallel had started may outlive it: let it end
            assert time.monotonic() < deadline, jobs_alive(folder)
            time.sleep(0.05)
        done = [n for n in NAMES if (remote / n / "harness.json").exists()]
        assert 2 <= len(done) < len(NAMES)
        before = {n: tree_snapshot(remote / n) for n in done}
        mp.setenv("BALLAST_REPORTS", str(gathered))
        assert main(["gather", str(folder)]) == 1                  # what is not finished is not taken
        assert sorted(p.name for p in (gathered / "runs" / "packing").iterdir()) == sorted(done)

        again = subprocess.run(["parallel", "-j", "2"], stdin=open(folder / "jobs.txt"), capture_output=True,
                               text=True, timeout=300)
        assert again.returncode == 0, again.stdout + again.stderr
        assert again.stdout.count("finished before, kept") == len(done)
        for n in done:
            assert tree_snapshot(remote / n) == before[n]
        assert main(["gather", str(folder)]) == 0
    for n in NAMES:
        assert outputs(gathered / "runs" / "packing" / n) == outputs(local / "runs" / "packing" / n), n


def test_gather_with_another_catalogue_says_so(springs, tmp_path, monkeypatch, capsys):
    folder = tmp_path / "shared"
    assert main(["export", "spring", "--to", str(folder)]) == 0
    assert run_jobs(folder, range(7)) == [0] * 7
    shutil.copytree(springs / "cases", tmp_path / "elsewhere")
    monkeypatch.setenv("BALLAST_CASES", str(tmp_path / "elsewhere"))
    capsys.readouterr()
    assert main(["gather", str(folder)]) == 1
    out = capsys.readouterr().out
    assert f"NOT GATHERED spring/soft: its scene is {tmp_path / 'elsewhere' / 'springs' / 'spring.scene'} here" in out
    assert "0 run(s) gathered, 0 already here, 7 not gathered" in out


def test_a_run_that_changes_while_it_is_copied_is_not_gathered(springs, tmp_path, monkeypatch, capsys):
    """A job still writing (run twice at once, say): the copy's digests differ from the record."""
    folder = tmp_path / "shared"
    assert main(["export", "spring", "--to", str(folder)]) == 0
    assert run_jobs(folder, range(7)) == [0] * 7
    real_copy = files.copy

    def copy_a_changed_file(source, path):
        real_copy(source, path)
        if path.parent.name == ".k_s2.gathering" and path.name == "series.tsv":
            path.write_text("changed under the copy\n")
    monkeypatch.setattr(files, "copy", copy_a_changed_file)
    capsys.readouterr()
    assert main(["gather", str(folder)]) == 1
    out = capsys.readouterr().out
    assert "NOT GATHERED spring/k_s2: its files changed while they were copied" in out
    assert "6 run(s) gathered, 0 already here, 1 not gathered" in out
    runs = springs / "reports" / "runs" / "spring"
    assert sorted(p.name for p in runs.iterdir()) == sorted(set(VARIANTS) - {"k_s2"})
