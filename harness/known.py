"""The record of the catalogue's KNOWN discrepancies with the papers: reference/known.tsv.

A `kind = paper` check with `known = REASON` (docs/cases.md) is KNOWN in the gate only when its
case is run; all of them are in full-tier cases today, so a default report would never mention
them.  The record keeps, per KNOWN check, the paper's value, ballast's last measured value and
when, where (tier, commit) it was measured, the reason and the case notes, so that every report
lists them all.

It is a committed file.  refresh() rewrites it only when asked (`check`/`validate --tier full`,
or `check`/`validate` given case names: __main__.py), and then only the rows of the checks that
were evaluated (a value was measured); the other rows are left as they were.  Rows are sorted by
(case, check) and the file is rewritten only when its text changes, so it stays deterministic.
"""
import csv
import io
import subprocess
from datetime import datetime, timezone
from pathlib import Path

from . import REPO_ROOT, files
from .children import options as child_options

RECORD_NAME = "known.tsv"
COLUMNS = ("case", "check", "paper", "value", "tier", "date", "commit", "reason", "notes", "source")
NOT_RECORDED = "not recorded"   # a value, date or commit nobody wrote down: never invented


def record_path(reference_root):
    return Path(reference_root) / RECORD_NAME


def known_checks(checks):
    """The checks of reference/ that carry `known = REASON`, sorted by (case, check)."""
    return sorted((c for c in checks if c.known), key=lambda c: (c.case, c.name))


def notes_of(check):
    """The case notes of a check's family: cases/<family>/README.md (family = its .ref file's name)."""
    return f"cases/{Path(check.path).stem}/README.md"


def load(path):
    """The record's rows (dicts of COLUMNS), or [] when there is no record."""
    path = Path(path)
    if not path.is_file():
        return []
    lines = [ln for ln in path.read_text(encoding="utf-8").splitlines() if ln and not ln.startswith("#")]
    rows = list(csv.DictReader(lines, delimiter="\t", quoting=csv.QUOTE_NONE))
    return [{k: (r.get(k) or "") for k in COLUMNS} for r in rows]


HEADER = ("# The catalogue's KNOWN discrepancies with the papers (harness/known.py, docs/cases.md).\n"
          "# One row per `known = REASON` check of reference/*.ref. value/date/commit/tier: ballast's last\n"
          "# measurement; rewritten by `check`/`validate --tier full` (or given case names) for the checks\n"
          "# it evaluated, never by a default-tier validate. 'not recorded': nobody wrote it down.\n"
          "# source: where the value comes from (a row seeded by hand says which text quotes it).\n")


def text_of(rows):
    out = io.StringIO()
    w = csv.writer(out, delimiter="\t", quoting=csv.QUOTE_NONE, escapechar="\\", lineterminator="\n")
    w.writerow(COLUMNS)
    for r in sorted(rows, key=lambda r: (r["case"], r["check"])):
        w.writerow([str(r.get(k, "")).replace("\t", " ").replace("\n", " ") for k in COLUMNS])
    return HEADER + out.getvalue()


def git_commit(root=REPO_ROOT):
    """`git rev-parse HEAD`, or 'unknown'."""
    try:
        done = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True,
                              timeout=10, **child_options(keep_lock=False))
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return done.stdout.strip() if done.returncode == 0 and done.stdout.strip() else "unknown"


def _fmt(x):
    return f"{x:.6g}" if isinstance(x, (int, float)) and not isinstance(x, bool) else str(x)


def refresh(path, checks, verdicts, tiers, commit=None, date=None):
    """Rewrite the record at path: one row per KNOWN check of checks (a new one 'not recorded', a
    row whose check is no longer KNOWN dropped); the rows of the verdicts that measured a value get
    that value, the date (UTC), the commit and the tier of the case (tiers: case -> tier).  Returns
    the (case, check) pairs refreshed; writes nothing when none was measured or the text is unchanged."""
    old = {(r["case"], r["check"]): r for r in load(path)}
    measured = {(v.case, v.check): v for v in verdicts if v.value is not None and not v.skipped}
    rows, done = [], []
    for c in known_checks(checks):
        key = (c.case, c.name)
        row = dict(old.get(key) or {"value": NOT_RECORDED, "tier": tiers.get(c.case, ""), "date": NOT_RECORDED,
                                    "commit": NOT_RECORDED, "source": NOT_RECORDED})
        row.update(case=c.case, check=c.name, paper=_fmt(c.value), reason=c.known, notes=notes_of(c))
        v = measured.get(key)
        if v is not None:
            row.update(value=_fmt(v.value), tier=tiers.get(c.case, ""),
                       date=date or datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
                       commit=commit or git_commit(), source="measured by the harness's check")
            done.append(key)
        rows.append(row)
    if not done:            # nothing measured: the committed file is not touched
        return done
    text = text_of(rows)
    path = Path(path)
    if not path.is_file() or path.read_text(encoding="utf-8") != text:
        files.write_text(path, text)
    return done
