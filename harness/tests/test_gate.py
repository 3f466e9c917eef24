"""The gate: table layout, summary.json and junit.xml parse back, exit status, and `check` end to end."""
import json
import math
import xml.etree.ElementTree as ET

from harness.__main__ import main
from harness.compare import Verdict
from harness.gate import exit_status, fmt_number, junit, read_summary, table, write_junit, write_summary
from harness.tests.fakes import spring_columns, tree_snapshot, write_run, write_spring_runs


def v(check="c", passed=True, value=1.0, reference=1.0, case="spring", variant="soft", message="ok"):
    return Verdict(case, variant, check, "last(F)", value, reference, "rel 1e-09", "analytic",
                   "eq. (1) & <table 2>", passed, message)


def test_number_format_has_six_significant_digits():
    assert fmt_number(1.2345678901) == "1.23457"
    assert fmt_number(1.35e6) == "1.35e+06"
    assert fmt_number(None) == "-"
    assert fmt_number([1.0, 2.5]) == "1, 2.5"


def test_table_is_aligned_and_ends_with_the_tally():
    verdicts = [v("short"), v("a_much_longer_name", passed=False, value=123456.789, message="too big"),
                v("trendy", value=[1.0, 2.0], reference=None, variant="a b c")]
    text = table(verdicts)
    lines = text.splitlines()
    assert lines[-1] == "2 passed, 1 failed"
    header, rule, *rows = lines[:5]
    assert header.split() == ["CASE", "VARIANT", "CHECK", "VALUE", "REFERENCE", "TOLERANCE", "KIND", "RESULT"]
    result_col = header.index("RESULT")
    assert [r[result_col:result_col + 4] for r in rows] == ["PASS", "FAIL", "PASS"]
    value_end = header.index("VALUE") + len("VALUE")
    assert rows[1][:value_end].endswith("123457")          # right-aligned, 6 digits
    assert "FAIL spring/a_much_longer_name: too big" in text


def test_the_terminal_view_lists_only_what_did_not_pass():
    # Issue 32: a green gate of 1 300 checks printed 1 300 PASS rows, burying a failure.  The
    # default view (check and validate without -v) lists the FAIL (and KNOWN, SKIP) rows, then
    # how many passing rows it left out and the tally; verbose lists every row.
    verdicts = [v("short"), v("broken", passed=False, message="too big"), v("fine")]
    short = table(verdicts, verbose=False).splitlines()
    rows = [r for r in short[2:] if r.startswith("spring")]
    assert len(rows) == 1 and "broken" in rows[0] and rows[0].rstrip().endswith("FAIL")
    assert "(2 passing check(s) not listed: -v lists every row)" in short
    assert short[-1] == "2 passed, 1 failed"
    green = table([v("a"), v("b")], verbose=False).splitlines()
    assert green == ["(2 passing check(s) not listed: -v lists every row)", "2 passed, 0 failed"]
    assert len(table(verdicts, verbose=True).splitlines()) == len(short) + 2 - 1


def test_no_checks_is_not_a_pass():
    assert exit_status([]) == 1
    assert table([]).splitlines()[-1] == "0 passed, 0 failed"
    assert exit_status([v()]) == 0
    assert exit_status([v(), v("d", passed=False)]) == 1


def test_summary_json_round_trips(tmp_path):
    verdicts = [v(), v("bad", passed=False, value=None), v("nan", passed=False, value=math.nan),
                v("iv", reference=[None, 3.0]), v("tr", value=[1.0, 2.0], reference=None)]
    write_summary(verdicts, tmp_path / "summary.json")
    records = json.loads((tmp_path / "summary.json").read_text())      # strict JSON: no NaN
    assert [r["check"] for r in records] == ["c", "bad", "nan", "iv", "tr"]
    assert set(records[0]) == {"case", "variant", "check", "quantity", "value", "reference", "tolerance",
                               "kind", "provenance", "pass", "message"}
    assert records[2]["value"] is None and records[2]["pass"] is False
    assert read_summary(tmp_path / "summary.json")[3].reference == [None, 3.0]


def test_junit_is_well_formed(tmp_path):
    verdicts = [v(), v("bad", passed=False, message="x < y & z"), v("other", case="second")]
    write_junit(verdicts, tmp_path / "junit.xml")
    root = ET.parse(tmp_path / "junit.xml").getroot()
    assert root.tag == "testsuites" and root.get("tests") == "3" and root.get("failures") == "1"
    suites = root.findall("testsuite")
    assert [(s.get("name"), s.get("tests"), s.get("failures")) for s in suites] == [("spring", "2", "1"), ("second", "1", "0")]
    cases = suites[0].findall("testcase")
    assert [c.get("name") for c in cases] == ["c", "bad"]
    assert cases[0].find("failure") is None
    failure = cases[1].find("failure")
    assert failure.get("message") == "x < y & z" and "provenance: eq. (1) & <table 2>" in failure.text
    assert junit([]).startswith("<?xml")


# ---------------------------------------------------------------- `check` end to end

def check_cli(capsys, *args):
    status = main(["check", *args])
    return status, capsys.readouterr().out


def test_check_passes_on_right_outputs(project, runs, capsys):
    write_spring_runs(runs)
    status, out = check_cli(capsys)
    assert status == 0
    assert out.splitlines()[-1] == "6 passed, 0 failed"
    records = json.loads((project / "reports" / "summary.json").read_text())
    assert len(records) == 6 and all(r["pass"] for r in records)
    ET.parse(project / "reports" / "junit.xml")


def test_check_fails_on_a_wrong_output(project, runs, capsys):
    write_spring_runs(runs, (("soft", 1), ("stiff", 2.5), ("stiffer", 3)))
    status, out = check_cli(capsys)
    assert status == 1
    assert out.splitlines()[-1] == "4 passed, 2 failed"         # rel_last and ratio_k
    failed = {r["check"] for r in json.loads((project / "reports" / "summary.json").read_text()) if not r["pass"]}
    assert failed == {"rel_last", "ratio_k"}
    failures = ET.parse(project / "reports" / "junit.xml").getroot().iter("failure")
    assert len(list(failures)) == 2


def test_check_without_outputs_fails_every_check(project, capsys):
    status, out = check_cli(capsys)
    assert status == 1
    assert out.splitlines()[-1] == "0 passed, 6 failed"
    assert "run output missing" in out


def test_check_with_a_failed_run_fails(project, runs, capsys):
    write_spring_runs(runs)
    write_run(runs / "spring" / "soft", spring_columns(1), status="unstable")
    status, out = check_cli(capsys)
    assert status == 1 and "status 'unstable'" in out
    assert out.splitlines()[-1] == "1 passed, 5 failed"          # only rel_last reads stiff alone


def test_check_with_no_selected_checks_fails(project, capsys):
    status, out = check_cli(capsys, "slow")
    assert status == 1
    assert out.splitlines()[-1] == "0 passed, 0 failed"


def test_check_never_writes_reference(project, runs, capsys):
    write_spring_runs(runs, (("soft", 7), ("stiff", 2), ("stiffer", 3)))     # regression value now wrong
    before = tree_snapshot(project / "reference")
    check_cli(capsys)
    assert tree_snapshot(project / "reference") == before


def test_broken_reference_file_is_a_usage_error(project, capsys):
    ref = project / "reference" / "springs.ref"
    ref.write_text(ref.read_text().replace("tolerance = abs 1e-12", "tolerance = abz 1e-12"))
    assert main(["check"]) == 2
    assert "springs.ref:7: unknown tolerance 'abz'" in capsys.readouterr().err


# ---------------------------------------------------------------- SKIP: a run that could not be made

def skip(check="s", case="peer", message="skipped: LAMMPS is not installed"):
    return Verdict(case, "check", check, "last(x)", None, [None, 1.0], "interval", "exact", "p", False,
                   message, skipped=True)


def test_a_skipped_check_is_neither_pass_nor_fail():
    verdicts = [v(), skip("a"), skip("b")]
    lines = table(verdicts).splitlines()
    assert lines[-1] == "1 passed, 0 failed, 2 skipped"
    result_col = lines[0].index("RESULT")
    assert [r[result_col:result_col + 4] for r in lines[2:5]] == ["PASS", "SKIP", "SKIP"]
    assert "SKIP peer (2 checks): skipped: LAMMPS is not installed" in lines   # one line per reason
    assert not any(line.startswith("FAIL") for line in lines)
    assert exit_status(verdicts) == 0
    assert exit_status([skip()]) == 1                   # nothing verified is not a pass
    assert exit_status([skip(), v("d", passed=False)]) == 1


def test_a_skip_round_trips_and_is_a_junit_skip(tmp_path):
    write_summary([v(), skip()], tmp_path / "summary.json")
    records = json.loads((tmp_path / "summary.json").read_text())
    assert "skip" not in records[0] and records[1]["skip"] is True and records[1]["pass"] is False
    back = read_summary(tmp_path / "summary.json")
    assert [x.result for x in back] == ["PASS", "SKIP"]
    root = ET.fromstring(junit([v(), skip(case="spring")]).split("?>", 1)[1])
    suite = root.find("testsuite")
    assert suite.get("skipped") == "1" and suite.get("failures") == "0"
    assert suite.findall("testcase")[1].find("skipped").get("message") == "skipped: LAMMPS is not installed"


def test_check_skips_the_checks_of_a_run_that_says_it_was_skipped(project, runs, capsys):
    write_spring_runs(runs)
    write_run(runs / "spring" / "soft", spring_columns(1), status="skipped",
              message="LAMMPS is not installed")
    status, out = check_cli(capsys)
    assert out.splitlines()[-1] == "1 passed, 0 failed, 5 skipped"   # rel_last reads stiff alone
    assert "SKIP spring (5 checks): skipped: LAMMPS is not installed" in out
    assert status == 0
    records = json.loads((project / "reports" / "summary.json").read_text())
    assert sum(r.get("skip", False) for r in records) == 5


def test_a_known_discrepancy_is_shown_and_neither_passes_nor_fails(tmp_path):
    """A paper check with `known = REASON` that misses its paper value is KNOWN: printed with its
    reason, counted apart, not failing the gate; one that agrees after all FAILs (strict), so the
    docs that discuss the discrepancy cannot outlive it.  Only kind = paper may be known."""
    from harness import references
    from harness.compare import Verdict, evaluate_check
    from harness.gate import counts_text, exit_status, table
    import pytest
    from harness.errors import IniError
    text = ("[check phi]\ncase = c\nvariant = v\nquantity = 1 + 0 * 20\nvalue = 24.4\ntolerance = abs 1.9\n"
            "kind = paper\nprovenance = JYH Sec. 5.2\nknown = ballast's specimen is looser: cases/biaxial/README.md\n")
    path = tmp_path / "x.ref"
    path.write_text(text)
    check = references.load(tmp_path)[0]
    import numpy as np
    from harness.tables import Run

    from harness.compare import RunStore
    run = Run(folder=None, info={"status": "ok", "dt": 1.0}, columns={"cycle": np.arange(3.0), "time": np.arange(3.0)})

    class Store(RunStore):
        def __init__(self):
            super().__init__(lambda c, v: tmp_path)

        def get(self, case, variant):
            return run
    v = evaluate_check(check, Store())
    assert v.result == "KNOWN" and not v.passed and "looser" in v.message
    ok = Verdict("c", "v", "other", "q", 1.0, 1.0, "abs 0", "exact", "p", True, "")
    assert counts_text([ok, v]) == "1 passed, 0 failed, 1 known discrepancy with a paper"
    assert exit_status([ok, v]) == 0
    assert "KNOWN c/phi: ballast's specimen is looser" in table([ok, v])
    path.write_text(text.replace("value = 24.4", "value = 1.5"))
    agrees = evaluate_check(references.load(tmp_path)[0], Store())
    assert agrees.result == "FAIL" and "remove 'known'" in agrees.message
    path.write_text(text.replace("kind = paper", "kind = exact"))
    with pytest.raises(IniError, match="for kind = paper only"):
        references.load(tmp_path)
