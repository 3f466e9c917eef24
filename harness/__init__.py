"""ballast harness: runs the core's validation cases, checks them against references, reports.

This module holds only the locations the harness works in.  Every other module takes
its roots as arguments and falls back to these functions, so tests can point the whole
harness at a temporary directory, either by argument or by environment variable:

    BALLAST_CASES      catalogue root         (default <repo>/cases)
    BALLAST_REFERENCE  reference root         (default <repo>/reference)
    BALLAST_BIN        the core's executable  (default <repo>/bin/ballast)
    BALLAST_REPORTS    reports root           (default <repo>/reports)

<repo> is the folder holding this package.
"""
import os
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parent.parent
TIERS = ("quick", "standard", "full")


def _from_env(var, default):
    value = os.environ.get(var)
    return Path(value) if value else default


def cases_root():
    """The catalogue root: cases/<family>/case.txt."""
    return _from_env("BALLAST_CASES", REPO_ROOT / "cases")


def reference_root():
    """The reference root: reference/<family>.ref."""
    return _from_env("BALLAST_REFERENCE", REPO_ROOT / "reference")


def bin_path():
    """The core executable the runs use."""
    return _from_env("BALLAST_BIN", REPO_ROOT / "bin" / "ballast")


def reports_root():
    """Where runs, figures, summary.json, junit.xml and the report go."""
    return _from_env("BALLAST_REPORTS", REPO_ROOT / "reports")


def runs_root(reports=None):
    """reports/runs: one folder per case, one sub-folder per variant."""
    return Path(reports or reports_root()) / "runs"
