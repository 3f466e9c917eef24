"""Stability limits and extreme probes (harness/stability.py) and their report section."""
import math
from pathlib import Path

import pytest

from harness import stability as st
from harness.report.html_page import stability_html
from harness.report.markdown import stability_markdown

ROOT = Path(__file__).resolve().parents[2]
BIN = ROOT / "bin" / "ballast"
needs_bin = pytest.mark.skipif(not BIN.exists(), reason="bin/ballast not built")

INFO = """scene          x.scene
dt estimate    0.10233267079464885   (contact-network bound ..., disc 0)
dt single      0.12533141373155002   (min over discs of 2 sqrt(m/k), C&S p. 53; ratio 1.225)
dt contacts    3 at the start; 0 free discs bounded by coordination; omega 19.5441, zeta 0
dt fraction    0.097720502380583982
dt used        0.01
"""


def test_parse_info():
    v = st.parse_info(INFO)
    assert v == {"estimate": 0.10233267079464885, "single": 0.12533141373155002, "dt": 0.01}


def test_parse_info_without_estimate_is_an_error():
    with pytest.raises(RuntimeError):
        st.parse_info("dt used 0.1\n")


def test_stage_cycles_and_overrides(tmp_path):
    scene = tmp_path / "a.scene"
    scene.write_text("[settings]\ndt = 0.01\n[stage load]\ncycles = 40  # comment\n[probe p]\ncycles = 9\n"
                     "[stage hold]\ncycles = 600\n[stage skip]\ncycles = 0\n")
    assert st.stage_cycles(scene, []) == [("load", 40), ("hold", 600), ("skip", 0)]
    assert st.stage_cycles(scene, ["stage.hold.cycles=1500", "material.m.kn=1"]) == \
        [("load", 40), ("hold", 1500), ("skip", 0)]


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
    """A fake ballast: stable iff dt < limit_dt (exit 1 above)."""
    calls = []
    monkeypatch.setattr(st, "info", lambda b, s, sets: {"estimate": estimate, "single": 2 * estimate, "dt": dt_case})
    monkeypatch.setattr(st, "stage_cycles", lambda s, sets: [("run", 100)])

    def run(binary, scene, sets, folder):
        dt = next((float(x.split("=", 1)[1]) for x in sets if x.startswith("settings.dt=")), dt_case)
        calls.append(dt)
        if dt >= limit_dt:
            return st.Trial(1, "non-finite state")
        return st.Trial(0, energy_max=1.0, kinetic_max=1.0, overlap_max=0.0)
    monkeypatch.setattr(st, "run", run)
    return calls


@pytest.mark.parametrize("limit", [0.3, 1.0 + 1e-9, 1.17, 5.5])
def test_bisection_brackets_the_limit(monkeypatch, tmp_path, limit):
    _model(monkeypatch, limit)
    lim = st.measure(Path("ballast"), st.Target("c", "v", Path("x.scene"), []), tmp_path)
    assert lim.limit < limit <= lim.unstable
    assert lim.unstable / lim.limit <= 1 + st.TOLERANCE
    assert lim.cause.startswith("exit 1")
    assert lim.single_ratio == pytest.approx(lim.limit / 2)
    assert list(tmp_path.iterdir()) == []       # trial folders removed


def test_bisection_reports_a_failing_baseline(monkeypatch, tmp_path):
    _model(monkeypatch, 0.05)                    # the case's own dt 0.1 fails
    lim = st.measure(Path("ballast"), st.Target("c", "v", Path("x.scene"), []), tmp_path)
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
    a, b = st.load_probes(tmp_path / "extremes.txt")
    assert (a.group, a.sets, a.energy_ratio, a.bounds, a.expect) == ("g1", ["material.m.kn=1"], 1.01,
                                                                      [("y", 0.0, 10.0)], "stable")
    assert b.expect == "stop" and math.isnan(b.energy_ratio)
    good = st.Trial(0, overlap_max=0.0, envelope={"y": (0.5, 1.0)})
    assert st.judge(a, good, 1.0, 1.005) == ("ran through, within its criteria", True)
    outcome, ok = st.judge(a, good, 1.0, 1.2)
    assert not ok and "E_out/E_in 1.2" in outcome
    outcome, ok = st.judge(a, st.Trial(0, overlap_max=0.0, envelope={"y": (-3.0, 1.0)}), 1.0, 1.0)
    assert not ok and "y in [-3" in outcome
    assert st.judge(b, st.Trial(1, "overlap budget exceeded at step 7"), 1, 1) == \
        ("stopped, exit 1: overlap budget exceeded at step 7", True)
    assert st.judge(b, good, 1.0, 1.0)[1] is False          # it should have stopped
    outcome, ok = st.judge(a, st.Trial(0, nonfinite="cycle 3 column Ek"), 1, 1)
    assert not ok and outcome.startswith("NON-FINITE")


def test_load_probes_rejects_unknown_keys(tmp_path):
    (tmp_path / "extremes.txt").write_text("[probe a]\ngroup = g\nwhat = w\nscene = s\ncolour = red\n")
    with pytest.raises(Exception, match="unknown key 'colour'"):
        st.load_probes(tmp_path / "extremes.txt")


def test_catalogue_extremes_file_loads():
    probes = st.load_probes(ROOT / "cases" / "extremes" / "extremes.txt")
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
    v = st.info(BIN, ROOT / "cases" / "two_discs" / "two_discs.scene", [])
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
