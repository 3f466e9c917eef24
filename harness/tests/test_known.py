"""reference/known.tsv, the record of the catalogue's KNOWN discrepancies: it lists exactly the
`known =` checks of reference/, every report lists them (their cases run or not), a full-tier or
named check refreshes only the rows it evaluated, and a default-tier validate never writes it."""
from harness import REPO_ROOT, known, references
from harness.__main__ import main
from harness.tests.fakes import write_spring_runs

# a KNOWN check in the fake project's full-tier case `slow` and one in the quick case `spring`
KNOWN_REF = """\
[check known_slow]
case = slow
variant = only
quantity = last(F)
value = 999
tolerance = abs 1
kind = paper
provenance = a paper's number ballast does not reach

[check known_spring]
case = spring
variant = soft
quantity = last(F)
value = 999
tolerance = abs 1
kind = paper
provenance = a paper's number ballast does not reach
"""


def _record_rows(case, check, value):
    return {"case": case, "check": check, "paper": "999", "value": value, "tier": "full" if case == "slow" else "quick",
            "date": "2026-11-25", "commit": known.NOT_RECORDED, "reason": f"{check} differs: see the notes",
            "notes": "cases/extra/README.md", "source": "seeded by the test"}


def known_project(project):
    """The fake project with two KNOWN checks and their record."""
    ref = KNOWN_REF.replace("provenance = a paper's number ballast does not reach\n\n[check known_spring]",
                            "provenance = a paper's number ballast does not reach\n"
                            "known = known_slow differs: see the notes\n\n[check known_spring]")
    (project / "reference" / "extra.ref").write_text(ref + "known = known_spring differs: see the notes\n")
    record = known.record_path(project / "reference")
    record.write_text(known.text_of([_record_rows("slow", "known_slow", "17"),
                                     _record_rows("spring", "known_spring", "18")]))
    return record


def test_record_lists_exactly_the_known_checks_of_reference():
    checks = references.load(REPO_ROOT / "reference")
    wanted = {(c.case, c.name): c for c in checks if c.known}
    rows = known.load(known.record_path(REPO_ROOT / "reference"))
    assert wanted, "no KNOWN check in reference/: this test has nothing to hold"
    assert {(r["case"], r["check"]) for r in rows} == set(wanted), "a KNOWN check without a row, or a row without one"
    for r in rows:
        c = wanted[(r["case"], r["check"])]
        assert r["reason"] == c.known and float(r["paper"]) == c.value
        assert (REPO_ROOT / r["notes"]).is_file(), r["notes"]
        for key in ("value", "tier", "date", "commit", "source"):
            assert r[key], (r["check"], key)      # a number, a date, or 'not recorded': never blank
    assert rows == sorted(rows, key=lambda r: (r["case"], r["check"]))


def test_default_report_lists_every_known_discrepancy(project, runs, capsys):
    known_project(project)
    write_spring_runs(runs)
    assert main(["report"]) == 0          # the default tier: `slow` (full) is not in it
    md = (project / "reports" / "summary.md").read_text()
    page = (project / "reports" / "index.html").read_text()
    for check, value in (("known_slow", "17"), ("known_spring", "18")):
        line = next(ln for ln in md.splitlines() if f"| {check} |" in ln)
        assert f"| 999 | {value} | 2026-11-25 |" in line and f"{check} differs: see the notes" in line
        assert "](../cases/extra/README.md)" in line
        assert check in page
    assert page.count('href="../cases/extra/README.md"') == 2
    # the verdict leads, then the KNOWN list, then the cases
    assert md.index("passed") < md.index("## Known discrepancies (2)") < md.index("## Cases (1)")


def test_summary_lists_failures_before_the_known_list(project, runs, capsys):
    known_project(project)
    write_spring_runs(runs, ks=(("soft", 1), ("stiff", 3), ("stiffer", 3)))   # rel_last and the trend fail
    assert main(["report"]) == 0
    md = (project / "reports" / "summary.md").read_text()
    assert md.index("failed") < md.index("## Failures") < md.index("## Known discrepancies") < md.index("## Cases")
    assert "- **FAIL** spring/rel_last (stiff):" in md


def test_full_tier_check_refreshes_only_the_rows_it_evaluated(project, runs, capsys):
    record = known_project(project)
    write_spring_runs(runs)
    main(["check", "spring"])                         # named: spring's KNOWN row only
    out = capsys.readouterr().out
    assert "refreshed 1 KNOWN row(s) (known_spring)" in out
    rows = {r["check"]: r for r in known.load(record)}
    assert rows["known_spring"]["value"] == "10" and rows["known_spring"]["tier"] == "quick"
    assert rows["known_spring"]["date"] != "2026-11-25" and rows["known_spring"]["date"].endswith("UTC")
    assert rows["known_spring"]["commit"] != known.NOT_RECORDED
    assert rows["known_slow"] == _record_rows("slow", "known_slow", "17")     # not evaluated: untouched


def test_refresh_keeps_rows_not_measured_and_is_sorted(tmp_path):
    checks = references.load(REPO_ROOT / "reference")
    path = tmp_path / "known.tsv"
    path.write_text((REPO_ROOT / "reference" / "known.tsv").read_text())

    class V:
        case, check, value, skipped = "piles_poly_full", "paper_coordination_dip", 4.1234567, False

    class Skipped(V):
        case, check, value, skipped = "biaxial_full", "paper_peak_m0_e025", None, True

    done = known.refresh(path, checks, [V(), Skipped()], {"piles_poly_full": "full"}, commit="abc", date="D")
    assert done == [("piles_poly_full", "paper_coordination_dip")]
    old = known.load(REPO_ROOT / "reference" / "known.tsv")
    new = known.load(path)
    assert [r for r in new if r["check"] != V.check] == [r for r in old if r["check"] != V.check]
    row = next(r for r in new if r["check"] == V.check)
    assert (row["value"], row["date"], row["commit"], row["tier"]) == ("4.12346", "D", "abc", "full")
    assert path.read_text() == known.text_of(new)
    assert known.refresh(path, checks, [Skipped()], {}) == []           # nothing measured: nothing written


def test_default_validate_leaves_the_record_unchanged(project, capsys):
    record = known_project(project)
    before = record.read_bytes()
    main(["validate", "--no-sweeps", "--no-stability"])      # runs spring and evaluates known_spring
    out = capsys.readouterr().out
    assert "known_spring" in out                                # evaluated (KNOWN in the gate)...
    assert record.read_bytes() == before                        # ...and the committed record untouched
    main(["validate", "--tier", "full", "--no-sweeps", "--no-stability"])
    assert "refreshed 2 KNOWN row(s)" in capsys.readouterr().out
    assert record.read_bytes() != before
