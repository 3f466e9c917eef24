"""docs/first-scene.md, the newcomer's walkthrough (issue 23), run as written: its scene through
the real bin/ballast, the output line it shows against the one ballast prints (the wall-clock
time masked), and its gnuplot command, which must draw a PNG.  So the page cannot drift."""
import re
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BALLAST = ROOT / "bin" / "ballast"
PAGE = ROOT / "docs" / "first-scene.md"


def block(text, name):
    """The fenced block between <!-- NAME: begin --> and <!-- NAME: end -->."""
    inner = text.split(f"<!-- {name}: begin -->", 1)[1].split(f"<!-- {name}: end -->", 1)[0]
    return re.search(r"```[a-z]*\n(.*?)```", inner, re.S).group(1)


def wall_masked(line):
    return re.sub(r"wall \S+ s", "wall - s", line.strip())


@pytest.mark.skipif(not BALLAST.exists(), reason="bin/ballast not built")
def test_the_first_scene_runs_as_the_page_says(tmp_path):
    text = PAGE.read_text()
    (tmp_path / "drop.scene").write_text(block(text, "first-scene"))
    done = subprocess.run([str(BALLAST), "run", "drop.scene", "--out", "drop"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert wall_masked(done.stdout) == wall_masked(block(text, "first-scene-output")), \
        "docs/first-scene.md shows another output line than ballast prints: rerun the page's scene and update it"
    header = (tmp_path / "drop" / "series.tsv").read_text().splitlines()[0]
    assert header == "cycle\ttime\tEk\theight"
    if shutil.which("gnuplot"):
        command = re.search(r'gnuplot -e "(.*?)"', text, re.S).group(1)
        subprocess.run(["gnuplot", "-e", " ".join(command.split())], cwd=tmp_path, check=True, timeout=60)
        assert (tmp_path / "height.png").stat().st_size > 1000
