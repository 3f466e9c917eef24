"""docs/scene-format.md documents every scene key exactly as the core's key table has it.

The tables between <!-- keys:begin --> and <!-- keys:end --> must equal the
output of `bin/ballast keys`; regenerate them with `.ci/readme-keys`.
"""
import pathlib
import subprocess

ROOT = pathlib.Path(__file__).resolve().parents[2]
KEYS_DOC = ROOT / "docs" / "scene-format.md"


def test_scene_format_keys_match_core():
    ballast = ROOT / "bin" / "ballast"
    assert ballast.exists(), "build the core first (make bin/ballast)"
    keys = subprocess.run([str(ballast), "keys"], capture_output=True, text=True,
                          check=True).stdout
    text = KEYS_DOC.read_text()
    begin = text.index("<!-- keys:begin -->\n") + len("<!-- keys:begin -->\n")
    end = text.index("<!-- keys:end -->")
    assert text[begin:end] == keys, "docs/scene-format.md scene keys are stale: run .ci/readme-keys"
