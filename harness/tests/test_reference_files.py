"""Generated reference files equal the output of their derivation scripts.

A reference value must come from its stated derivation, never from a hand
edit: every reference/derive/NAME.py that writes reference/NAME.ref is run
here and its output compared with the committed file, byte for byte.
"""
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPTS = sorted((ROOT / "reference" / "derive").glob("*.py"))


@pytest.mark.parametrize("script", SCRIPTS, ids=[s.stem for s in SCRIPTS])
def test_reference_matches_derivation(script):
    ref = ROOT / "reference" / f"{script.stem}.ref"
    assert ref.exists(), f"{script} has no {ref}"
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                         check=True, cwd=ROOT).stdout
    assert out == ref.read_text(), (
        f"{ref.name} differs from the output of {script.relative_to(ROOT)}; "
        f"regenerate it with: {script.relative_to(ROOT)} > {ref.relative_to(ROOT)}")


def test_there_is_a_derivation():
    assert SCRIPTS, "no derivation scripts found"
