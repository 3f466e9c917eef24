"""Killed, full or shared, the harness loses nothing (issue 18, item 5), each for real.

- Killed: the harness alone gets SIGKILL at seeded random moments while it runs a small real
  catalogue (bin/ballast, two discs held for a million cycles per variant), then again
  during the `--resume` started at once after the first kill.  No run may outlive the
  harness, the last `--resume` must finish, and the outputs must equal those of an
  uninterrupted run byte for byte (wall-clock fields aside).
- Shared: a second harness on the same reports folder is refused (exit 75, naming the
  first's pid) while the first goes on unaffected; `list` is not held up; the runs keep the
  lock after the harness is gone.
- Full, read-only, or a file: every writing command ends with one line naming the path and
  the OS error, exit 3, no traceback, no NAME.tmp left, and the reports it had written
  before unchanged.  The disks are small tmpfs mounts (skipped where mounting is refused).
- Every file the harness writes under the project goes through NAME.tmp + rename.
"""
import builtins
import io
import os
import random
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from harness import lock
from harness.__main__ import main
from harness.children import options as child_options
from harness.errors import Busy
from harness.tests.fakes import env_for, tree_snapshot
from harness.tests.test_interrupt import comparable

REPO = Path(__file__).resolve().parents[2]
BALLAST = REPO / "bin" / "ballast"
needs_ballast = pytest.mark.skipif(not BALLAST.exists(), reason="bin/ballast not built")


def harness(env, *argv):
    """`python3 -m harness ARGV` in a session of its own (its runs share its process group)."""
    return subprocess.Popen([sys.executable, "-m", "harness", *argv], cwd=REPO,
                            env={**os.environ, **env, "PYTHONPATH": str(REPO)}, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)


def live(pgid):
    """The processes of group pgid that are not dead: [(pid, name)], from /proc."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        name, rest = stat[stat.index("(") + 1:stat.rindex(")")], stat[stat.rindex(")") + 2:].split()
        if int(rest[2]) == pgid and rest[0] not in "ZX":
            found.append((int(entry.name), name))
    return found


def tmp_files(root):
    return sorted(str(p) for p in Path(root).rglob("*.tmp"))


# ---------------------------------------------------------------- killed (real core)

HOLD = 1_000_000          # cycles of the hold stage: a few tenths of a second per run
VARIANTS = (("undamped", ()), ("damped", ("settings.alpha=10", "settings.beta=0.005")),
            ("global_only", ("settings.alpha=8",)), ("contact_only", ("settings.beta=0.02",)))
TRIALS, KILLS = 4, 2      # each trial: KILLS kills (the run, then its --resume), then a --resume to the end
DEATH = 0.2               # seconds the runs of a killed harness may take to die (they get SIGKILL at once)
SEED = 20261125


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    """A catalogue of one case: the two discs of cases/two_discs, four variants, held long."""
    root = tmp_path_factory.mktemp("tiny")
    folder = root / "cases" / "tiny"
    folder.mkdir(parents=True)
    (folder / "two_discs.scene").write_bytes((REPO / "cases" / "two_discs" / "two_discs.scene").read_bytes())
    text = "[case tiny]\ntier = quick\ntitle = two discs held long\nchecks = none\nruntime = 1\n"
    for name, sets in VARIANTS:
        text += f"\n[variant {name}]\nscene = two_discs.scene\nset = stage.hold.cycles={HOLD}\n" + \
            "set = settings.output_every=100000\n" + "".join(f"set = {s}\n" for s in sets)
    (folder / "case.txt").write_text(text)
    (root / "reference").mkdir()
    return {"BALLAST_CASES": str(root / "cases"), "BALLAST_REFERENCE": str(root / "reference"),
            "BALLAST_BIN": str(BALLAST)}


@pytest.fixture(scope="module")
def uninterrupted(tiny, tmp_path_factory):
    """(reports root, wall seconds) of the catalogue run once, not interrupted."""
    reports = tmp_path_factory.mktemp("uninterrupted")
    start = time.monotonic()
    proc = harness({**tiny, "BALLAST_REPORTS": str(reports)}, "run", "-j", "2")
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, out + err
    return reports, time.monotonic() - start


def kill_outright(proc, env, moment):
    """SIGKILL the harness alone moment seconds from now, start `run --resume` at once, then
    require that no run of the killed harness outlives it by more than DEATH.  Returns the
    resume and whether runs were alive at the kill."""
    time.sleep(moment)
    alive = [p for p in live(proc.pid) if p[0] != proc.pid]
    proc.send_signal(signal.SIGKILL)
    proc.communicate()
    resume = harness(env, "run", "-j", "2", "--resume")
    deadline = time.monotonic() + DEATH
    while live(proc.pid):
        assert time.monotonic() < deadline, f"runs outlived the killed harness: {live(proc.pid)}"
        time.sleep(0.005)
    return resume, bool(alive)


@needs_ballast
def test_a_harness_killed_outright_takes_its_runs_along_and_resumes_to_the_same_bytes(tiny, uninterrupted,
                                                                                      tmp_path):
    expected, wall = uninterrupted
    rng = random.Random(SEED)
    caught = 0
    for trial in range(TRIALS):
        reports = tmp_path / f"trial{trial}"
        env = {**tiny, "BALLAST_REPORTS": str(reports)}
        proc = harness(env, "run", "-j", "2")
        for _ in range(KILLS):
            proc, alive = kill_outright(proc, env, rng.uniform(0.0, wall))
            caught += alive
        out, err = proc.communicate(timeout=120)
        assert proc.returncode == 0, f"trial {trial}: the last --resume failed:\n{out}{err}"
        assert "4 runs: 4 ok" in out and "Traceback" not in err
        assert tmp_files(reports) == []
        for name, _ in VARIANTS:
            assert comparable(reports / "runs" / "tiny" / name, reports) == \
                comparable(expected / "runs" / "tiny" / name, expected), f"trial {trial}: {name}"
    assert caught >= 2, "too few kills found runs alive: the test did not test much"


def test_the_runs_keep_the_lock_until_they_end(tmp_path, monkeypatch):
    """After the harness is gone, a run it started still holds the reports lock: nothing can
    empty the folder it writes into."""
    monkeypatch.setattr(lock, "WAIT", 0.1)
    with lock.reports_lock(tmp_path, "run"):
        child = subprocess.Popen(["sleep", "30"], **child_options())
    try:
        with pytest.raises(Busy):
            with lock.reports_lock(tmp_path, "check"):
                pass
    finally:
        child.kill()
        child.wait()
    with lock.reports_lock(tmp_path, "check"):
        pass


# ---------------------------------------------------------------- shared (fake core)

def test_a_second_harness_on_the_same_reports_is_refused_and_the_first_goes_on(project, capsys):
    scene = project / "cases" / "springs" / "spring.scene"
    scene.write_text(scene.read_text() + "sleep = 1.5\n")        # 4.5 s at -j 1: time to refuse three
    env, lockfile = env_for(project), project / "reports" / ".harness.lock"
    first = harness(env, "run", "spring", "-j", "1")
    deadline = time.monotonic() + 30
    while not (lockfile.exists() and lockfile.read_text().startswith(f"{first.pid} run")):
        assert first.poll() is None and time.monotonic() < deadline, first.communicate()
        time.sleep(0.01)
    others = [harness(env, *argv) for argv in (["run", "spring"], ["check"], ["report"])]
    listing = subprocess.run([sys.executable, "-m", "harness", "list"], cwd=REPO, capture_output=True, text=True,
                             env={**os.environ, **env, "PYTHONPATH": str(REPO)}, timeout=30)
    assert listing.returncode == 0, listing.stderr                # list writes nothing: no lock
    for other in others:
        out, err = other.communicate(timeout=30)
        assert other.returncode == 75, out + err
        assert err.count("\n") == 1 and "Traceback" not in err, err
        assert f"another harness (pid {first.pid}, `run`) is using {project / 'reports'} (lock {lockfile})" in err
        assert f"kill {first.pid}" in err and "then run this command again" in err
    assert first.poll() is None, "the first harness ended before the others were refused: the test proves nothing"
    out, err = first.communicate(timeout=60)
    assert first.returncode == 0 and "3 runs: 3 ok, 0 failed" in out, out + err
    assert lockfile.read_text() == ""                               # released, and says nobody holds it
    assert main(["check", "spring"]) == 0                           # the first's runs, whole and its own
    assert "6 passed, 0 failed" in capsys.readouterr().out


# ---------------------------------------------------------------- full, read-only, a file

@pytest.fixture
def mount():
    """mount(path, options): a tmpfs at path, unmounted after the test; skips where not allowed."""
    made = []

    def do(path, options):
        path.mkdir(parents=True, exist_ok=True)
        try:
            done = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(path)],
                                  capture_output=True, text=True, timeout=30)
        except OSError as exc:
            pytest.skip(f"cannot run mount: {exc}")
        if done.returncode != 0:
            pytest.skip(f"mounting a tmpfs is not permitted here: {done.stderr.strip()}")
        made.append(path)
        return path
    yield do
    for path in reversed(made):
        if subprocess.run(["umount", str(path)], capture_output=True).returncode != 0:
            subprocess.run(["umount", "-l", str(path)], capture_output=True)


def remount(path, options):
    subprocess.run(["mount", "-o", f"remount,{options}", str(path)], check=True, capture_output=True)


def fill(folder):
    """Fill the file system of folder to the last page."""
    fd = os.open(folder / "filler", os.O_WRONLY | os.O_CREAT, 0o644)
    try:
        for chunk in (1 << 16, 1 << 12):
            try:
                while True:
                    os.write(fd, b"\0" * chunk)
            except OSError:
                pass
    finally:
        os.close(fd)


def refused(capsys, argv, status=3):
    """Run the harness in-process: require exit status and one line on stderr; that line."""
    code = main(argv)
    captured = capsys.readouterr()
    refused.out, err = captured.out, captured.err
    assert "Traceback" not in err and err.count("\n") == 1, err
    assert code == status, err
    return err.strip()


REPORT_FILES = ("summary.json", "junit.xml", "summary.md", "index.html")
NO_SPACE = re.compile(r"ballast-harness: cannot write (/\S+): No space left on device")


def test_a_full_disk_stops_check_report_validate_and_sweep_with_one_line(project, mount, capsys):
    reports = mount(project / "reports", "size=4m")
    assert main(["validate", "--no-stability"]) == 0
    before = {name: (reports / name).read_bytes() for name in REPORT_FILES}
    fill(reports)
    capsys.readouterr()
    assert refused(capsys, ["check"]) == f"ballast-harness: cannot write {reports / 'summary.json'}: " \
                                         "No space left on device"
    for argv in (["report"], ["validate", "--resume", "--no-stability"],
                 ["sweep", "spring", "--variant", "soft", "--set", "k=4,5"]):
        line = refused(capsys, argv)
        match = NO_SPACE.fullmatch(line.split(" (and ")[0])
        assert match and Path(match.group(1)).is_relative_to(reports), line
        assert tmp_files(reports) == [], argv
        assert {name: (reports / name).read_bytes() for name in REPORT_FILES} == before, argv
    assert "sweeps/spring/k=4/ballast.stderr" in line                 # the sweep's runs could not be recorded


def test_a_full_disk_stops_run_with_one_line(project, mount, capsys):
    reports = mount(project / "reports", "size=64k")
    fill(reports)
    line = refused(capsys, ["run", "spring"])
    soft = reports / "runs" / "spring" / "soft"
    assert f"FAILED spring/soft: cannot record the run: cannot write {soft / 'ballast.stderr'}" in refused.out
    assert line == f"ballast-harness: cannot write {soft / 'ballast.stderr'}: No space left on device " \
                   "(and 2 more run folder(s))"
    assert tmp_files(reports) == [] and not (soft / "harness.json").exists()     # --resume will redo it


WRITERS = (["run"], ["check"], ["report"], ["validate"], ["rebaseline", "spring"], ["cost"],
           ["sweep", "spring", "--variant", "soft", "--set", "k=4"], ["stability", "--extremes-only"])


def test_a_read_only_reports_folder_stops_every_writing_command_with_one_line(project, mount, capsys):
    reports = mount(project / "reports", "size=4m")
    assert main(["validate", "--no-stability"]) == 0
    remount(reports, "ro")
    before = tree_snapshot(reports)
    capsys.readouterr()
    for argv in WRITERS:
        assert refused(capsys, argv) == \
            f"ballast-harness: cannot write {reports / '.harness.lock'}: Read-only file system", argv
    assert main(["list"]) == 0
    assert tree_snapshot(reports) == before


def test_a_read_only_runs_folder_stops_run_with_one_line(project, mount, capsys):
    runs = mount(project / "reports" / "runs", "ro,size=64k")
    line = refused(capsys, ["run", "spring"])
    assert line == f"ballast-harness: cannot write {runs / 'spring'}: Read-only file system (and 2 more run folder(s))"
    assert tmp_files(project / "reports") == []


def test_a_reports_path_that_is_a_file_stops_every_writing_command_with_one_line(project, monkeypatch, capsys):
    blocker = project / "reports.txt"
    blocker.write_text("not a folder\n")
    monkeypatch.setenv("BALLAST_REPORTS", str(blocker))
    before = sorted(p.name for p in project.iterdir())
    for argv in WRITERS:
        assert refused(capsys, argv) == f"ballast-harness: cannot write {blocker}: Not a directory", argv
    assert blocker.read_text() == "not a folder\n" and sorted(p.name for p in project.iterdir()) == before


# ---------------------------------------------------------------- every write whole

def test_every_file_the_harness_writes_goes_through_a_tmp_file(project, monkeypatch, capsys):
    """Opened for writing under the project: only NAME.tmp files (renamed over NAME after), so
    a kill never leaves a report, a record or a reference cut short."""
    opened, real = [], io.open

    def spy(file, mode="r", *args, **kwargs):
        if isinstance(file, (str, os.PathLike)) and set(mode) & set("wax+"):
            opened.append(Path(file))
        return real(file, mode, *args, **kwargs)
    monkeypatch.setattr(io, "open", spy)
    monkeypatch.setattr(builtins, "open", spy)
    assert main(["validate", "--no-stability"]) == 0                  # run, check, cost, report
    assert main(["sweep", "spring", "--variant", "soft", "--set", "k=1,2"]) == 0
    ref = project / "reference" / "springs.ref"
    text = ref.read_text().replace("value = 5.5 ", "value = 5.4 ")     # an old value to rewrite
    with real(ref, "w") as f:
        f.write(text)
    assert main(["rebaseline", "spring"]) == 0
    mine = [p for p in opened if p.is_relative_to(project)]
    assert {p.name for p in mine} >= {"index.html.tmp", "summary.md.tmp", "summary.json.tmp", "junit.xml.tmp",
                                      "harness.json.tmp", "ballast.stdout.tmp", "springs.ref.tmp"}
    assert [p for p in mine if not p.name.endswith(".tmp")] == []
    assert tmp_files(project) == []
