"""The gate: verdicts printed as an aligned table, written as summary.json and junit.xml.

gate() is the `check` command's work once the checks are chosen: evaluate them, print
the table (last line 'N passed, M failed', with ', K skipped' when some checks could not
be made: compare.py), write both files, return the exit status (0 iff at least one check
passes and none fails).
"""
import json
import xml.etree.ElementTree as ET
from pathlib import Path

from . import files
from .compare import Verdict, evaluate_all

COLUMNS = ("case", "variant", "check", "value", "reference", "tolerance", "kind", "result")
RIGHT = {"value", "reference"}


def fmt_number(x):
    """~6 significant digits; '-' for nothing; lists joined; intervals as [lo, hi]."""
    if x is None:
        return "-"
    if isinstance(x, (list, tuple)):
        return ", ".join(fmt_number(v) for v in x)
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return str(x)
    return f"{x:.6g}"


def fmt_reference(v):
    """The reference column: a number, or [lo, hi] for an interval."""
    if isinstance(v.reference, list):
        lo, hi = v.reference
        return f"[{'-inf' if lo is None else fmt_number(lo)}, {'+inf' if hi is None else fmt_number(hi)}]"
    return fmt_number(v.reference)


def row(v):
    return {"case": v.case, "variant": v.variant, "check": v.check, "value": fmt_number(v.value),
            "reference": fmt_reference(v), "tolerance": v.tolerance, "kind": v.kind,
            "result": v.result}


def tally(verdicts):
    """(passed, failed); a skipped check is neither (skipped()), nor a known discrepancy (known())."""
    passed = sum(v.passed for v in verdicts)
    return passed, len(verdicts) - passed - skipped(verdicts) - known(verdicts)


def known(verdicts):
    return sum(bool(v.known) for v in verdicts)


def skipped(verdicts):
    return sum(v.skipped for v in verdicts)


def counts_text(verdicts):
    """'N passed, M failed', and ', K skipped' when K > 0."""
    passed, failed = tally(verdicts)
    k, d = skipped(verdicts), known(verdicts)
    return (f"{passed} passed, {failed} failed" + (f", {k} skipped" if k else "")
            + (f", {d} known discrepanc{'y' if d == 1 else 'ies'} with a paper" if d else ""))


def table(verdicts, verbose=True):
    """The gate table as text: aligned columns, failure reasons, then 'N passed, M failed'.
    verbose=False (the terminal's default for check and validate): only the rows that did not
    pass (FAIL, KNOWN, SKIP), so a green gate of 1 300 checks prints a few lines, not 1 300;
    every row is in summary.json, junit.xml and summary.md either way."""
    shown = verdicts if verbose else [v for v in verdicts if v.result != "PASS" or v.known]
    rows = [row(v) for v in shown]
    widths = {c: max([len(c)] + [len(r[c]) for r in rows]) for c in COLUMNS}
    lines = []
    if rows:
        lines = [_line({c: c.upper() for c in COLUMNS}, widths), _line({c: "-" * widths[c] for c in COLUMNS}, widths)]
        lines += [_line(r, widths) for r in rows]
    if not verbose and len(shown) < len(verdicts):
        lines.append(f"({len(verdicts) - len(shown)} passing check(s) not listed: -v lists every row)")
    failures = [v for v in verdicts if v.result == "FAIL"]
    skips = {}
    for v in verdicts:
        if v.skipped:
            skips.setdefault((v.case, v.message), []).append(v.check)
    if failures or skips or known(verdicts):
        lines.append("")
        lines += [f"FAIL {v.case}/{v.check}: {v.message}" for v in failures]
        lines += [f"KNOWN {v.case}/{v.check}: {v.known}" for v in verdicts if v.known]
        lines += [f"SKIP {case} ({len(names)} check{'s' if len(names) > 1 else ''}): {message}"
                  for (case, message), names in skips.items()]
    if not verdicts:
        lines.append("no checks selected: nothing was verified")
    lines.append(counts_text(verdicts))
    return "\n".join(lines)


def _line(cells, widths):
    parts = [cells[c].rjust(widths[c]) if c in RIGHT else cells[c].ljust(widths[c]) for c in COLUMNS]
    return "  ".join(parts).rstrip()


def write_summary(verdicts, path):
    """summary.json: a list of one record per check."""
    _write(path, json.dumps([v.as_dict() for v in verdicts], indent=1, allow_nan=False) + "\n")


def read_summary(path):
    """The verdicts of a summary.json."""
    return [Verdict.from_dict(d) for d in json.loads(Path(path).read_text(encoding="utf-8"))]


def junit(verdicts):
    """junit.xml text: one testsuite per case, one testcase per check, <failure> on failure,
    <skipped> on a skip."""
    root = ET.Element("testsuites", name="ballast", tests=str(len(verdicts)), failures=str(tally(verdicts)[1]))
    for case in dict.fromkeys(v.case for v in verdicts):
        mine = [v for v in verdicts if v.case == case]
        suite = ET.SubElement(root, "testsuite", name=case, tests=str(len(mine)),
                              failures=str(tally(mine)[1]), errors="0", skipped=str(skipped(mine) + known(mine)))
        for v in mine:
            _testcase(suite, v)
    ET.indent(root)
    return ET.tostring(root, encoding="unicode", xml_declaration=True) + "\n"


def _testcase(suite, v):
    case = ET.SubElement(suite, "testcase", classname=f"{v.case}.{v.variant.replace(' ', '+')}", name=v.check)
    detail = (f"quantity: {v.quantity}\nvalue: {fmt_number(v.value)}\nreference: {fmt_reference(v)}\n"
              f"tolerance: {v.tolerance}\nkind: {v.kind}\nprovenance: {v.provenance}\n{v.message}")
    if v.passed:
        ET.SubElement(case, "system-out").text = detail
    elif v.skipped:
        ET.SubElement(case, "skipped", message=v.message).text = detail
    elif v.known:       # JUnit has no "expected failure": a skip that says what it is
        ET.SubElement(case, "skipped", message=f"KNOWN DISCREPANCY: {v.known}").text = detail
    else:
        ET.SubElement(case, "failure", message=v.message, type="check").text = detail


def write_junit(verdicts, path):
    _write(path, junit(verdicts))


def _write(path, text):
    """Write text whole (files.write_text: a temporary file, then rename)."""
    path = Path(path)
    files.make_dirs(path.parent)
    files.write_text(path, text)


def exit_status(verdicts):
    """0 iff at least one check passes and none fails (skipped checks do neither)."""
    passed, failed = tally(verdicts)
    return 0 if passed and not failed else 1


def gate(checks, store, reports_dir, out, keep_others=False, verbose=True, on_verdicts=None):
    """Evaluate checks, print the table to out, write summary.json and junit.xml; the exit status
    (of these checks).  keep_others (a subset of the cases was asked for): summary.json and
    junit.xml keep the verdicts an earlier gate wrote for the other cases, so checking one case
    updates its part and leaves the rest.  on_verdicts: called with the verdicts once evaluated
    (the refresh of reference/known.tsv: __main__.py)."""
    verdicts = evaluate_all(checks, store)
    if on_verdicts:
        on_verdicts(verdicts)
    print(table(verdicts, verbose), file=out)
    summary = Path(reports_dir) / "summary.json"
    written = verdicts
    if keep_others:
        mine = {v.case for v in verdicts}
        try:
            saved = read_summary(summary) if summary.is_file() else []
        except (ValueError, KeyError, TypeError):
            saved = []
        written = [v for v in saved if v.case not in mine] + verdicts
    write_summary(written, summary)
    write_junit(written, Path(reports_dir) / "junit.xml")
    return exit_status(verdicts)
