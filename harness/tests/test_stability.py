"""Stability limits and extreme probes (harness/stability.py, harness/extremes.py) and their report section."""
import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from harness import extremes
from harness import stability as st
from harness.runner import Batch
from harness.report.html_page import stability_html
from harness.report.markdown import stability_markdown
from harness.tests.fakes import default_sigint

ROOT = Path(__file__).resolve().parents[2]
BIN = ROOT / "bin" / "ballast"
needs_bin = pytest.mark.skipif(not BIN.exists(), reason="bin/ballast not built")

INFO = """scene          x.scene
dt estimate    0.10233267079464885   (contact-network bound ..., disc 0)
dt single      0.12533141373155002   (min over discs of 2 sqrt(m/k), C&S p. 53; ratio 1.225)
dt contacts    3 at the start; 0 free discs bounded by coordination; omega 19.5441, zeta 0
dt fraction    0.097720502380583982
dt used        0.01
output every   5 cycles
stages         3 (1040 cycles)
stage          load 40 cycles 0.40000000000000002 s (cycles)
stage          hold 1000 cycles 10 s (time)
stage          skip 0 cycles 0 s (cycles)
"""


def test_parse_info():
    v = st.parse_info(INFO)
    # the stages as the core resolved them, in cycles at the scene's dt, whether given in
    # cycles or in time
    assert v == {"estimate": 0.10233267079464885, "single": 0.12533141373155002, "dt": 0.01, "output_every": 5,
                 "stages": [("load", 40), ("hold", 1000), ("skip", 0)]}


def test_parse_info_without_estimate_is_an_error():
    with pytest.raises(RuntimeError):
        st.parse_info("dt used 0.1\n")


def test_scaled_cycles_keep_the_physical_time():
    stages = [("load", 40), ("hold", 600), ("skip", 0), ("long", 400000)]
    # dt four times larger: a quarter of the cycles; at least one; the cap; zero stays zero
    assert st.scaled_cycles(stages, 0.01, 0.04, cap=20000) == \
        ["stage.load.cycles=10", "stage.hold.cycles=150", "stage.skip.cycles=0", "stage.long.cycles=20000"]
    assert st.scaled_cycles([("a", 3)], 0.01, 1.0) == ["stage.a.cycles=1"]


def _series(path, rows, head="cycle\ttime\tEk\tEe\tF"):
    path.write_text(head + "\n" + "\n".join("\t".join(str(x) for x in r) for r in rows) + "\n")


def test_series_energy_envelope_and_nonfinite(tmp_path):
    p = tmp_path / "series.tsv"
    _series(p, [(1, 0.1, 1.0, 2.0, -3), (2, 0.2, 0.5, 4.0, 5), (3, 0.3, "nan", 1.0, 0)])
    e, ek, bad = st.series_energy(p)
    assert (e, ek) == (4.5, 1.0)
    assert bad == "cycle 3 column Ek"
    assert st.series_envelope(p) == {"Ek": (0.5, 1.0), "Ee": (1.0, 4.0), "F": (-3.0, 5.0)}


def test_envelope_deviation_uses_the_baseline_scale_with_a_floor():
    base = {"Ee": (0.0, 1e7), "Fs": (-1e-8, 1e-8)}
    # Fs grows from round-off to 1e3: its scale is floored at 1e-9 of the largest (1e-2)
    col, dev = st.envelope_deviation({"Ee": (0.0, 1.1e7), "Fs": (-1e3, 1e3)}, base)
    assert col == "Fs" and dev == pytest.approx(1e5)
    col, dev = st.envelope_deviation({"Ee": (0.0, 1.5e7), "Fs": (-1e-8, 1e-8)}, base)
    assert col == "Ee" and dev == pytest.approx(0.5)


def test_largest_overlap_from_the_contact_point(tmp_path):
    (tmp_path / "discs.tsv").write_text("id\tname\tx\ty\tr\n0\ta\t0\t0\t1\n1\tb\t1.9\t0\t1\n")
    # disc pair: overlap 0.1, point 0.95 from a; wall contact of b: point 0.97 from its centre -> 0.06
    (tmp_path / "contacts.tsv").write_text("a\tb\tkind\tx\ty\n"
                                           "a\tb\tdisc\t0.95\t0\n"
                                           "b\tw\twall\t1.9\t-0.97\n")
    assert st.largest_overlap(tmp_path / "discs.tsv", tmp_path / "contacts.tsv") == pytest.approx(0.1)


def test_verdict():
    base = st.Trial(0, energy_max=10.0, kinetic_max=1.0, overlap_max=0.01, envelope={"F": (0.0, 5.0)})
    ok = st.Trial(0, energy_max=12.0, kinetic_max=1.5, overlap_max=0.012, envelope={"F": (0.0, 7.0)})
    assert st.verdict(ok, base) == ""
    assert st.verdict(st.Trial(1, "non-finite state"), base).startswith("exit 1")
    assert "energy" in st.verdict(st.Trial(0, energy_max=41.0, kinetic_max=1.0, envelope={"F": (0, 5)}), base)
    assert "E_k" in st.verdict(st.Trial(0, energy_max=12.0, kinetic_max=4.5, envelope={"F": (0, 5)}), base)
    assert "probe F" in st.verdict(st.Trial(0, energy_max=12.0, kinetic_max=1.0, envelope={"F": (-6.0, 5.0)}), base)
    assert "overlap" in st.verdict(st.Trial(0, energy_max=12.0, kinetic_max=1.0, overlap_max=0.07,
                                            envelope={"F": (0, 5)}), base)
    nan = st.Trial(0, nonfinite="cycle 4 column F")
    assert "non-finite" in st.verdict(nan, base)


def _model(monkeypatch, limit_dt, estimate=1.0, dt_case=0.1):
    """A fake ballast: stable iff dt < limit_dt (exit 1 above).  Returns the names of the
    folders it was asked to run into, as they come."""
    folders = []
    monkeypatch.setattr(st, "info", lambda b, s, sets: {"estimate": estimate, "single": 2 * estimate, "dt": dt_case,
                                                        "output_every": 1, "stages": [("run", 100)]})

    def run(batch, target, sets, folder):
        folders.append(Path(folder).name)
        dt = next((float(x.split("=", 1)[1]) for x in sets if x.startswith("settings.dt=")), dt_case)
        if dt >= limit_dt:
            return st.Trial(1, "non-finite state")
        return st.Trial(0, energy_max=1.0, kinetic_max=1.0, overlap_max=0.0)
    monkeypatch.setattr(st, "run", run)
    return folders


@pytest.mark.parametrize("limit", [0.3, 1.0 + 1e-9, 1.17, 5.5])
def test_bisection_brackets_the_limit(monkeypatch, tmp_path, limit):
    folders = _model(monkeypatch, limit)
    lim = st.measure(None, st.Target("c", "v", Path("x.scene"), []), tmp_path)
    assert lim.limit < limit <= lim.unstable
    assert lim.unstable / lim.limit <= 1 + st.TOLERANCE
    assert lim.cause.startswith("exit 1")
    assert lim.single_ratio == pytest.approx(lim.limit / 2)
    # one folder per run, named by its place in the bisection: the same names at every
    # attempt, so --resume finds the trials an interrupted attempt finished
    assert folders == ["base"] + [f"trial{k:02d}" for k in range(1, lim.trials + 1)]


def test_bisection_reports_a_failing_baseline(monkeypatch, tmp_path):
    _model(monkeypatch, 0.05)                    # the case's own dt 0.1 fails
    lim = st.measure(None, st.Target("c", "v", Path("x.scene"), []), tmp_path)
    assert math.isnan(lim.limit) and "baseline" in lim.note


def test_limit_rows_and_target():
    L = st.Limit("c", "v", estimate=2.0, single=3.0, dt_case=0.2, limit=1.1, unstable=1.11, cause="exit 1: x")
    (row,) = st.limit_rows([L])
    assert row["limit_fraction"] == "1.1" and row["in_target"] == "yes" and row["case_fraction"] == "0.1"
    assert row["limit_over_single"] == "0.7333"
    assert not st.in_target(0.99) and not st.in_target(1.26) and st.in_target(1.25)


EXTREMES = """[probe a]
group = g1
what = first
scene = s.scene
set = material.m.kn=1
energy_ratio = 1.01
bound = y 0 10

[probe b]
group = g2
what = second
scene = s.scene
expect = stop
"""


def test_load_probes_and_judge(tmp_path):
    (tmp_path / "extremes.txt").write_text(EXTREMES)
    a, b = extremes.load_probes(tmp_path / "extremes.txt")
    assert (a.group, a.sets, a.energy_ratio, a.bounds, a.expect) == ("g1", ["material.m.kn=1"], 1.01,
                                                                      [("y", 0.0, 10.0)], "stable")
    assert b.expect == "stop" and math.isnan(b.energy_ratio)
    good = st.Trial(0, overlap_max=0.0, envelope={"y": (0.5, 1.0)})
    assert extremes.judge(a, good, 1.0, 1.005) == ("ran through, within its criteria", True)
    outcome, ok = extremes.judge(a, good, 1.0, 1.2)
    assert not ok and "E_out/E_in 1.2" in outcome
    outcome, ok = extremes.judge(a, st.Trial(0, overlap_max=0.0, envelope={"y": (-3.0, 1.0)}), 1.0, 1.0)
    assert not ok and "y in [-3" in outcome
    assert extremes.judge(b, st.Trial(1, "overlap budget exceeded at step 7"), 1, 1) == \
        ("stopped, exit 1: overlap budget exceeded at step 7", True)
    assert extremes.judge(b, good, 1.0, 1.0)[1] is False          # it should have stopped
    outcome, ok = extremes.judge(a, st.Trial(0, nonfinite="cycle 3 column Ek"), 1, 1)
    assert not ok and outcome.startswith("NON-FINITE")


def test_load_probes_rejects_unknown_keys(tmp_path):
    (tmp_path / "extremes.txt").write_text("[probe a]\ngroup = g\nwhat = w\nscene = s\ncolour = red\n")
    with pytest.raises(Exception, match="unknown key 'colour'"):
        extremes.load_probes(tmp_path / "extremes.txt")


def test_catalogue_extremes_file_loads():
    probes = extremes.load_probes(ROOT / "cases" / "extremes" / "extremes.txt")
    assert len({p.name for p in probes}) == len(probes)
    for p in probes:
        assert p.scene.exists(), p.scene


def test_report_section(tmp_path):
    assert stability_markdown(tmp_path) == "" and stability_html(tmp_path) == ""
    L = st.Limit("two", "v<1>", estimate=2.0, single=3.0, dt_case=0.2, limit=1.3, unstable=1.31, cause="c")
    st.write_tsv(st.limit_rows([L]), st.LIMIT_COLUMNS, tmp_path / "stability.tsv")
    md, page = stability_markdown(tmp_path), stability_html(tmp_path)
    assert "## Stability limits" in md and "| two | v<1> |" in md and "| no |" in md
    assert "v&lt;1&gt;" in page and 'class="FAIL">no' in page


@needs_bin
def test_ballast_info_prints_both_estimates():
    v = st.info(Batch(BIN), ROOT / "cases" / "two_discs" / "two_discs.scene", [])
    # two discs between walls, frictionless: omega^2 = 3 k/m exactly; the single-spring
    # value (k_s = k_n by default) is 2 sqrt(m/(2k)): sqrt(3/2) larger than the bound, whose
    # 0.95 is the estimate (BAL_DT_MARGIN, core/timestep.c)
    assert v["single"] / v["estimate"] == pytest.approx(math.sqrt(1.5) / 0.95, rel=1e-12)
    assert v["dt"] == 0.01


def test_merge_tsv_replaces_rows_in_place(tmp_path):
    path = tmp_path / "t.tsv"
    st.merge_tsv([{"k": "a", "v": "1"}, {"k": "b", "v": "2"}], ("k", "v"), path, ("k",))
    st.merge_tsv([{"k": "c", "v": "3"}, {"k": "a", "v": "9"}], ("k", "v"), path, ("k",))
    assert st.read_tsv(path) == [{"k": "a", "v": "9"}, {"k": "b", "v": "2"}, {"k": "c", "v": "3"}]


# ---------------------------------------------------------------- through the runner (real bin/ballast)
#
# `harness stability` launches its trials through runner.py: an interrupt stops them (exit
# 130) and keeps the trials done in reports/stability-runs; `--resume` runs only the rest
# and writes the table an uninterrupted command writes; -j changes nothing.  A wrapper
# around bin/ballast makes one trial long while BALLAST_TEST_HOLD names its folder, so the
# test waits on files appearing, not on sleeps.

HOLD_WRAPPER = """#!/bin/sh
# bin/ballast; while $BALLAST_TEST_HOLD is set, the run whose --out ends in it goes on for
# 4e8 cycles (minutes) without series rows: the trial an interrupt catches.  Every run's
# --out is appended to $BALLAST_TEST_LOG when that is set.
if [ -n "$BALLAST_TEST_LOG" ] && [ "$1" = run ]; then echo "$4" >> "$BALLAST_TEST_LOG"; fi
if [ -n "$BALLAST_TEST_HOLD" ]; then
  case "$4" in *"$BALLAST_TEST_HOLD")
    exec "{bin}" "$@" --set settings.output_every=1000000000 --set stage.hold.cycles=400000000;;
  esac
fi
exec "{bin}" "$@"
"""
# With -j 1 the variants are bisected in turn: two_discs/undamped is done when the run held,
# damped's baseline (at the case's own dt: made long, it stays stable), is interrupted.
HELD = "limits/two_discs/damped/base"


@pytest.fixture(scope="module")
def hold_wrapper(tmp_path_factory):
    path = tmp_path_factory.mktemp("bin") / "ballast"
    path.write_text(HOLD_WRAPPER.replace("{bin}", str(BIN)))
    path.chmod(0o755)
    return path


def stability(reports, wrapper, *args, hold=None, log=None):
    env = dict(os.environ, BALLAST_REPORTS=str(reports), PYTHONPATH=str(ROOT))
    for var in ("BALLAST_CASES", "BALLAST_REFERENCE", "BALLAST_BIN", "BALLAST_TEST_HOLD", "BALLAST_TEST_LOG"):
        env.pop(var, None)
    if hold:
        env["BALLAST_TEST_HOLD"] = hold
    if log:
        env["BALLAST_TEST_LOG"] = str(log)
    argv = [sys.executable, "-m", "harness", "stability", "--no-extremes", "--bin", str(wrapper), *args]
    # SIGINT at its default in the harness (preexec_fn): a shell's background job (`make test &` in
    # a script, nohup) inherits SIGINT ignored, and Python then never raises KeyboardInterrupt.
    return subprocess.Popen(argv, env=env, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, start_new_session=True, preexec_fn=default_sigint)


def finished(proc, timeout=120):
    out, _ = proc.communicate(timeout=timeout)
    return proc.returncode, out


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory, hold_wrapper):
    reports = tmp_path_factory.mktemp("uninterrupted")
    code, out = finished(stability(reports, hold_wrapper, "two_discs", "-j", "1"))
    assert code == 0, out
    return reports


@needs_bin
def test_stability_leaves_no_trial_folder(uninterrupted):
    assert (uninterrupted / "stability.tsv").is_file()
    assert not (uninterrupted / "stability-runs").exists()


@needs_bin
def test_interrupted_stability_resumes_to_the_uninterrupted_table(tmp_path, hold_wrapper, uninterrupted):
    reports = tmp_path / "reports"
    work = reports / "stability-runs"
    proc = stability(reports, hold_wrapper, "two_discs", "-j", "1", hold=HELD)
    try:
        deadline = time.monotonic() + 120
        while not (work / HELD / "series.tsv.tmp").exists():       # the held run is in its time-step loop
            assert proc.poll() is None, f"stability ended early: {proc.communicate()[0]}"
            assert time.monotonic() < deadline, "the held run never started"
            time.sleep(0.01)
        os.killpg(proc.pid, signal.SIGINT)
        code, out = finished(proc, 60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert code == 130, out
    assert "interrupted: 1 run(s) stopped, 5 not started" in out       # the bisections of the 5 variants left
    assert not (reports / "stability.tsv").exists()
    held = json.loads((work / HELD / "harness.json").read_text())
    assert not held["ok"] and held["cause"].startswith("interrupted: exit code 130")
    undamped = work / "limits" / "two_discs" / "undamped"
    ok = {p.name: json.loads((p / "harness.json").read_text())["ok"] for p in sorted(undamped.iterdir())}
    assert len(ok) == 8 and ok["base"] and ok["trial01"] and not all(ok.values())   # unstable trials: exit 1

    log = tmp_path / "runs.log"
    code, out = finished(stability(reports, hold_wrapper, "two_discs", "-j", "1", "--resume", log=log))
    assert code == 0, out
    assert (reports / "stability.tsv").read_text() == (uninterrupted / "stability.tsv").read_text()
    ran = [Path(line) for line in log.read_text().splitlines()]
    # undamped's successful runs were kept; its failed ones (the unstable trials: exit 1) ran
    # again; damped's bisection ran from its baseline on
    assert [p.name for p in ran if p.parent.name == "undamped"] == [name for name, good in ok.items() if not good]
    assert [p.name for p in ran if p.parent.name == "damped"][:2] == ["base", "trial01"]
    assert not work.exists()                                      # removed once the command ended


@needs_bin
def test_stability_results_do_not_depend_on_j(tmp_path, hold_wrapper):
    tables = []
    for jobs in ("1", "2"):
        reports = tmp_path / f"j{jobs}"
        code, out = finished(stability(reports, hold_wrapper, "two_discs", "collisions", "--one-per-case",
                                       "-j", jobs))
        assert code == 0, out
        tables.append((reports / "stability.tsv").read_text())
    assert tables[0] == tables[1] and tables[0].count("\n") == 3


# ---------------------------------------------------------------- stages given in time (issue 29, item 7)
#
# The stages' lengths come from `ballast info`, never from the scene text: a scene whose
# stages are given as `time = T` (as docs/first-scene.md teaches) was bisected with every
# stage at 0 cycles, and reported a limit of 64 x the estimate and more "with no unstable
# step".  two_discs.scene (dt = 0.01: load 40 cycles, hold 600) written with its stages in
# time is the same run, so its bisection must be the same, trial for trial; so must the
# cycle scene with a stage's time given by an override.

@needs_bin
def test_a_scene_with_its_stages_in_time_bisects_as_in_cycles(tmp_path):
    cycles_scene = ROOT / "cases" / "two_discs" / "two_discs.scene"
    text = cycles_scene.read_text()
    assert "cycles = 40\n" in text and "cycles = 600\n" in text
    time_scene = tmp_path / "two_discs_time.scene"
    time_scene.write_text(text.replace("cycles = 40\n", "time = 0.4\n").replace("cycles = 600\n", "time = 6\n"))
    batch = Batch(BIN)
    limits = [st.measure(batch, st.Target("t", name, scene, sets), tmp_path / name, cap=1000)
              for name, scene, sets in (("cycles", cycles_scene, []), ("time", time_scene, []),
                                        ("override", cycles_scene, ["stage.hold.time=6"]))]
    base = json.loads((tmp_path / "time" / "base" / "run.json").read_text())
    assert base["steps"] == 640                                  # 40 + 600 cycles at dt = 0.01
    steps = [[(f, why == "stable") for f, why in lim.log] for lim in limits]   # (the causes name the scene)
    for lim, trials in zip(limits, steps):
        assert math.isfinite(lim.limit) and math.isfinite(lim.unstable) and not lim.note, lim
        assert trials == steps[0] and (lim.limit, lim.unstable) == (limits[0].limit, limits[0].unstable)


@needs_bin
def test_the_first_scene_has_a_limit(tmp_path):
    """docs/first-scene.md's drop: one stage of `time = 4`, a series row every 500 cycles.
    Read from the scene text its stage had 0 cycles: every trial ran nothing and the
    bisection reported 69 x the estimate "with no unstable step".  With its stages from the
    core but the case's output_every kept, a trial at 10 x the case's dt wrote a row every
    0.47 s, missed the impact between two rows and was called unstable for energy lost
    (0.36 x the estimate, below the step ballast itself takes safely).  The limit must be
    found by the core's own guard, at or above the estimate."""
    from harness.tests.test_first_scene import PAGE, block
    scene = tmp_path / "drop.scene"
    scene.write_text(block(PAGE.read_text(), "first-scene"))
    lim = st.measure(Batch(BIN), st.Target("first", "drop", scene, []), tmp_path / "drop")
    assert math.isfinite(lim.unstable) and not lim.note, lim
    assert lim.cause.startswith("exit 1") and lim.limit >= 1, lim


def test_scaled_output_keeps_the_rows_simulated_times():
    assert st.scaled_output(500, 1e-4, 1e-3) == "settings.output_every=50"
    assert st.scaled_output(500, 1e-4, 1e-1) == "settings.output_every=1"      # at least every cycle
    assert st.scaled_output(1, 0.04, 0.01) == "settings.output_every=4"
