"""The energy-audit gate: one declaration (case = *, variant = *) becomes a check per DEM
variant of every case; energy() reads the audit of run.json and refuses missing terms."""
import pytest

from harness import catalogue, references
from harness.__main__ import main
from harness.compare import RunStore, evaluate_check, folder_locator
from harness.errors import IniError
from harness.tests.fakes import spring_columns, write_run

EVERY = """\
[check audit]
case = *
variant = *
quantity = energy('relative_imbalance')
tolerance = interval
lo = 0
hi = 0.01
kind = analytic
provenance = conservation of energy
"""


def load_text(tmp_path, text):
    path = tmp_path / "x.ref"
    path.write_text(text)
    return references.load_file(path)


def test_every_run_variant_gets_its_copy(project, tmp_path):
    cases = catalogue.load()
    checks = references.expand(load_text(tmp_path, EVERY), cases)
    expected = [(c.name, v.name) for c in cases for v in c.variants if v.command == "run"]
    assert [(c.case, c.variant) for c in checks] == expected
    assert expected, "the fake catalogue has DEM variants"
    assert all(c.name == f"audit[{c.variant}]" for c in checks)
    references.validate(checks, cases)


def test_wildcard_case_needs_wildcard_variant_and_a_single_run_tolerance(project, tmp_path):
    cases = catalogue.load()
    with pytest.raises(IniError, match="variant = \\*"):
        references.expand(load_text(tmp_path, EVERY.replace("variant = *", "variant = soft")), cases)


def audit_store(tmp_path, energy):
    write_run(tmp_path / "runs" / "spring" / "soft", spring_columns(1), energy=energy)
    return RunStore(folder_locator(tmp_path / "runs"))


def one(tmp_path, text):
    return load_text(tmp_path, text.replace("case = *", "case = spring").replace("variant = *", "variant = soft"))[0]


@pytest.mark.parametrize("relative, passed", [(0.0, True), (0.004, True), (0.01, True), (0.0101, False)])
def test_gate_passes_and_fails_on_the_relative_imbalance(tmp_path, relative, passed):
    verdict = evaluate_check(one(tmp_path, EVERY), audit_store(tmp_path, {"relative_imbalance": relative}))
    assert verdict.passed is passed


@pytest.mark.parametrize("energy, words", [
    (None, "no energy audit"),
    ({"imbalance": 1}, "no term 'relative_imbalance'"),
    ({"relative_imbalance": None}, "not finite"),
])
def test_missing_or_broken_audit_is_a_failure_that_says_why(tmp_path, energy, words):
    verdict = evaluate_check(one(tmp_path, EVERY), audit_store(tmp_path, energy))
    assert verdict.passed is False and words in verdict.message


def test_report_tabulates_each_term_of_the_audit(project, runs, capsys):
    audit = {"kinetic0": 1.0, "elastic0": 0.0, "kinetic": 0.25, "elastic": 0.5, "work_walls": 2.0,
             "work_gravity": 0.0, "dissipated_dashpot": 1.5, "dissipated_friction": 0.625,
             "dissipated_global": 0.0, "imbalance": 0.125, "relative_imbalance": 0.0416015625}
    write_run(runs / "spring" / "soft", spring_columns(1), energy=audit)
    for variant, k in (("stiff", 2), ("stiffer", 3)):
        write_run(runs / "spring" / variant, spring_columns(k))
    main(["check"])
    assert main(["report"]) == 0
    capsys.readouterr()
    page = (project / "reports" / "cases" / "spring.html").read_text()       # the case's page holds its tables
    md = (project / "reports" / "cases" / "spring.md").read_text()
    assert "Energy audit" in page and "Energy audit" in md
    row = [line for line in md.splitlines() if line.startswith("| soft |") and "0.625" in line]
    assert row and "-0.75" in row[0] and "0.0416016" in row[0]
