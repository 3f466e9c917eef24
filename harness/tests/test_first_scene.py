"""docs/first-scene.md, the newcomer's walkthrough (issue 23), run as written: its scene through
the real bin/ballast, the output line it shows against the one ballast prints (the wall-clock
time masked), its gnuplot command, which must draw a PNG, and every number its description of
the run quotes against the run's own series.tsv.  So the page cannot drift."""
import math
import re
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BALLAST = ROOT / "bin" / "ballast"
PAGE = ROOT / "docs" / "first-scene.md"
PLACEHOLDER = "/path/to/ballast/bin/ballast"      # the page's stand-in for the repository's bin/ballast


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
    run = block(text, "first-scene-run")           # the page's own commands, in the scene's folder,
    assert run.startswith(f"BALLAST={PLACEHOLDER}\n"), run   # with the placeholder as a reader fills it in
    done = subprocess.run(["sh", "-e", "-c", run.replace(PLACEHOLDER, str(BALLAST))], cwd=tmp_path,
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


WORDS = {"one": 1, "two": 2, "three": 3, "four": 4, "five": 5, "six": 6, "seven": 7, "eight": 8,
         "nine": 9, "ten": 10, "eleven": 11, "twelve": 12}
NUMBER = r"(\d+(?:\.\d+)?(?:e-?\d+)?|" + "|".join(WORDS) + r")"


def as_quoted(word):
    """A quoted number, and its tolerance: half a unit in its last quoted digit, so the quoted
    figure must be the measured value rounded to the digits the page gives (0.14 for 0.1416;
    4e-10 for 4.1e-10; "nine" for 9.4)."""
    if word in WORDS:
        return WORDS[word], 0.5
    mantissa, _, exponent = word.partition("e")
    decimals = len(mantissa.partition(".")[2])
    return float(word), 0.5 * 10.0 ** (-decimals + (int(exponent) if exponent else 0))


def measured(scene_text, header, rows):
    """What the page's description of the run says, measured on the run: each a pattern that
    quotes one number and the value it must round to."""
    time = [r[1] for r in rows]
    ek = [r[2] for r in rows]
    height = [r[3] for r in rows]
    # landing: the first row at which the height of `top` stops falling (the next row is higher)
    land = next(i for i in range(1, len(rows) - 1) if height[i] < height[i - 1] and height[i + 1] > height[i])
    start = float(re.search(r"\[disc top\][^\[]*?\nx = \S+ (\S+)", scene_text).group(1))
    return [
        (r"falls from " + NUMBER + " m", start),
        (r"lands on the heap at about " + NUMBER + " s", time[land]),
        (r"the rows are " + NUMBER + " s apart", time[1] - time[0]),
        (r"comes to rest at about " + NUMBER + " m", height[-1]),
        (r"peaks at about " + NUMBER + " J", max(ek)),
        (r"peaks at about[^:]*?at the landing and ends at about " + NUMBER, ek[-1]),
        (r"falls by " + NUMBER + " orders of magnitude", math.log10(max(ek) / ek[-1])),
        (r"over the " + NUMBER + " seconds", time[-1]),
        (r"column " + NUMBER + r"\)", 1 + header.index("Ek")),
    ], land, max(range(len(ek)), key=ek.__getitem__)


@pytest.mark.skipif(not BALLAST.exists(), reason="bin/ballast not built")
def test_every_number_the_page_quotes_is_the_runs(tmp_path):
    """Each number of the page's description of the run ("lands on the heap at about 0.14 s",
    "comes to rest at about 0.175 m", ...) is compared with the run's series.tsv, to half a unit
    in its last quoted digit; a number in that paragraph that no pattern here checks fails too.
    The page once said the disc lands "after about 0.4 s": the run's rows show 0.14 s."""
    text = PAGE.read_text()
    scene = block(text, "first-scene")
    (tmp_path / "drop.scene").write_text(scene)
    subprocess.run([str(BALLAST), "run", "drop.scene", "--out", "drop"], cwd=tmp_path, check=True,
                   capture_output=True, timeout=120)
    lines = (tmp_path / "drop" / "series.tsv").read_text().splitlines()
    assert lines[0] == "cycle\ttime\tEk\theight"
    rows = [[float(v) for v in line.split("\t")] for line in lines[1:]]
    prose = " ".join(text.split("<!-- first-scene-numbers: begin -->", 1)[1]
                     .split("<!-- first-scene-numbers: end -->", 1)[0].split())
    checks, land, peak = measured(scene, lines[0].split("\t"), rows)
    assert peak == land, "the kinetic energy's peak row is not the landing row, as the page says"
    checked = []
    for pattern, value in checks:
        found = re.search(pattern, prose)
        assert found, f"docs/first-scene.md no longer says /{pattern}/: update this test with the page"
        quoted, tolerance = as_quoted(found.group(1))
        assert abs(quoted - value) <= tolerance, \
            f"docs/first-scene.md says {found.group(0)!r}, the run shows {value:.4g} (tolerance {tolerance:g})"
        checked.append(found.span(1))
    unchecked = [m.group(0) for m in re.finditer(r"\b" + NUMBER + r"\b", prose)
                 if not any(a <= m.start() < b for a, b in checked)]
    assert not unchecked, f"docs/first-scene.md quotes numbers no check compares with the run: {unchecked}"
