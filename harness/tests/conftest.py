"""Fixtures: a fake project in a tmp dir, with the harness pointed at it by environment variables."""
import pytest

import harness.families  # noqa: F401 -- registers the families' expression functions, as the command line does
from harness.tests.fakes import env_for, make_project


@pytest.fixture
def project(tmp_path, monkeypatch):
    """A fake project (see fakes.py); BALLAST_CASES/REFERENCE/BIN/REPORTS point into it."""
    root = make_project(tmp_path / "project")
    for key, value in env_for(root).items():
        monkeypatch.setenv(key, value)
    return root


@pytest.fixture
def runs(project):
    """The runs root of the fake project (reports/runs)."""
    return project / "reports" / "runs"
