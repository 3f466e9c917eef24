"""What `validate` prints (issue 32, item 4): a line or two per phase and every failure, KNOWN row
and finding, however many cases, sweeps, limits and probes the catalogue has; the detail of each
phase is in the report (and shown in passing on a terminal, console.Transient); `-v` prints it.

A default `make validate` printed 127 lines on a terminal when all passed: 37 of them the sweeps'
cheapest settings, 12 the stability limits and 57 the extreme probes, one line each."""
import io
import sys

import pytest

from harness import extremes, stability
from harness.__main__ import main
from harness.console import CLEAR, Transient
from harness.tests.test_sweep_cost import SWEEPS

CASES = 10       # extra cases, one variant each: a stability limit each
PROBES = 30      # extreme probes
# What a terminal shows: the runs (progress line, count), the verdict (2), the sweeps (progress
# line, count, one line), the stability limits (1), the probes (the one finding, p0 declared a
# stop and ran through, and a count), the report (1), what reports/ keeps (1), the last line.
PHASE_LINES = 13


class Terminal(io.StringIO):
    """stdout as a terminal: what is written, and isatty() true."""

    def isatty(self):
        return True


def visible(text):
    """The lines a terminal shows once text is written to it: each \\r goes back to the start of
    the line, ESC[K erases it (the progress and status lines redrawn in place)."""
    out = []
    for line in text.split("\n"):
        out.append(line.split("\r")[-1].replace("\x1b[K", ""))
    while out and out[-1] == "":
        out.pop()
    return out


def grown_project(project, monkeypatch):
    """The fake project with the sweeps of test_sweep_cost, CASES more cases, PROBES extreme
    probes, and a stand-in for `ballast info`'s stability estimate (the fake core prints none)."""
    case = project / "cases" / "springs" / "case.txt"
    extra = "".join(f"\n[case extra{i}]\ntier = quick\ntitle = extra case {i}\nchecks = nothing\nruntime = 1\n\n"
                    f"[variant only]\nscene = spring.scene\n" for i in range(CASES))
    case.write_text(case.read_text() + SWEEPS + extra)
    folder = project / "cases" / "extremes"
    folder.mkdir()
    (folder / "spring.scene").write_text("k = 1\nn = 10\n")
    (folder / "extremes.txt").write_text("".join(
        f"[probe p{i}]\ngroup = springs\nwhat = probe {i}\nscene = spring.scene\n"
        + ("expect = stop\n" if i == 0 else "") + "\n" for i in range(PROBES)))
    monkeypatch.setattr(stability, "info", lambda batch, scene, sets: {
        "estimate": 1.0, "single": 2.0, "dt": 0.1, "output_every": 1, "stages": [("run", 10)]})

    def run(batch, target, sets, folder):        # stable below 1.1 x the estimate (test_stability's model)
        dt = next((float(x.split("=", 1)[1]) for x in sets if x.startswith("settings.dt=")), 0.1)
        if dt >= 1.1:
            return stability.Trial(1, "non-finite state")
        return stability.Trial(0, energy_max=1.0, kinetic_max=1.0, overlap_max=0.0)
    monkeypatch.setattr(stability, "run", run)
    monkeypatch.setattr(extremes, "run", run)


def validate(monkeypatch, *argv, tty=True):
    out = Terminal() if tty else io.StringIO()
    monkeypatch.setattr(sys, "stdout", out)
    status = main(["validate", *argv])
    monkeypatch.setattr(sys, "stdout", sys.__stdout__)
    return status, out.getvalue()


def test_validate_prints_a_line_or_two_per_phase(project, monkeypatch):
    grown_project(project, monkeypatch)
    status, text = validate(monkeypatch)
    assert status == 0
    lines = visible(text)
    assert len(lines) <= PHASE_LINES, "\n".join(lines)
    assert lines[3] == "6 passed, 0 failed"                   # the verdict, before the sweeps and the rest
    assert any(ln.startswith(f"stability: {CASES + 1} limit(s) bisected, {CASES + 1} in [1, 1.25]")
               for ln in lines), lines
    assert any(ln.startswith("  finding springs/p0: declared 'stop'") for ln in lines), lines
    assert any(ln.startswith(f"extreme probes: {PROBES - 1} as declared, 1 finding(s)") for ln in lines), lines
    assert lines[-1].startswith("validate: ") and "passed, 0 failed" in lines[-1]
    for detail in ("error <= 0.01", "x estimate (", "springs/p7: "):      # each sweep, limit and probe
        assert detail not in "\n".join(lines), detail
    assert "springs/p7: " in text            # shown in passing on the terminal, then rubbed out


def test_validate_off_a_terminal_drops_the_detail(project, monkeypatch):
    grown_project(project, monkeypatch)
    status, text = validate(monkeypatch, tty=False)
    assert status == 0
    assert "springs/p7: " not in text and "error <= 0.01" not in text and "\r" not in text
    runs = 3 + CASES + 3             # a short batch (at most 60 runs) prints a line per run off a terminal,
    assert len(text.splitlines()) <= PHASE_LINES - 2 + runs, text      # not the two progress lines


def test_validate_verbose_prints_every_line(project, monkeypatch):
    grown_project(project, monkeypatch)
    status, text = validate(monkeypatch, "-v", tty=False)
    assert status == 0
    for detail in ("error <= 0.01", "x estimate (", "  springs/p7: ran through", "rel_last"):
        assert detail in text, detail


def test_transient_lines_replace_each_other_and_keep_what_is_asked():
    out = Terminal()
    detail = Transient(out, keep=lambda line: line.startswith("interrupted:"))
    print("one", file=detail)
    print("two" + "x" * 500, file=detail)        # cut to the terminal's width: it never wraps
    print("\ninterrupted: 1 run(s) stopped", file=detail)
    print("three", file=detail)
    detail.close()
    assert visible(out.getvalue()) == ["interrupted: 1 run(s) stopped"]
    assert all(len(seg) < 300 for seg in out.getvalue().split(CLEAR))
    plain = io.StringIO()
    detail = Transient(plain)
    print("one", file=detail)
    detail.close()
    assert plain.getvalue() == ""


@pytest.mark.parametrize("verbose", [False, True])
def test_validate_still_shows_every_failure(project, monkeypatch, verbose):
    case = project / "cases" / "springs" / "case.txt"
    case.write_text(case.read_text().replace("set = k=3", "set = k=3\nset = fail=4"))
    status, text = validate(monkeypatch, "--no-stability", *(["-v"] if verbose else []))
    assert status == 1
    lines = visible(text)
    assert any(ln.startswith("FAILED spring/stiffer: exit code 4") for ln in lines)
    assert any(ln.startswith("FAIL spring/trend_k:") for ln in lines)
    assert lines[-1].startswith("validate: 5 passed, 1 failed")
