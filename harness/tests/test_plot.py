"""harness plot and harness movie (harness/pictures.py) on real runs of bin/ballast, and the
report's snapshots and movie figures.

The run: a few discs dropped into a box (the scene below), snapshots every SNAPSHOT_DT of
simulated time.  Every test reads what was drawn back: the SVG parsed as XML, the PNG's and
the GIF's headers and the GIF's images counted block by block, the gnuplot script (--script)
with its data inline: the discs drawn are the run's, the bars' widths are F_n times one
factor, --at draws the frame nearest the time asked for.
"""
import math
import re
import shutil
import struct
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from harness import REPO_ROOT, bin_path, pictures
from harness.__main__ import main
from harness.errors import PictureError

SCENE = """
[settings]
gravity = 0 -9.81
alpha = 2
output_every = 500
beta = 2e-4

[material grain]
kn = 1e5
ks = 1e5
friction = 0.5
density = 2650

[fill heap]
n = 12
columns = 4
rmin = 0.01
rmax = 0.015
origin = 0 0.02
headroom = 0.05
box = 1
material = grain
wall_material = grain

[disc top]
x = 0.06 0.25
r = 0.015
material = grain

[disc pin]
x = 0.2 0.05
r = 0.01
fixed = 1
material = grain

[stage fall]
time = 2

[stage rest]
time = 1

[probe Ek]
quantity = energy_kinetic
"""
SNAPSHOT_DT = 0.5            # simulated seconds between snapshots: frames at 0, 0.5, ..., 3
N_DISCS = 14                 # the fill's 12, top and pin
needs_gnuplot = pytest.mark.skipif(not shutil.which("gnuplot"), reason="gnuplot is not installed")
pytestmark = needs_gnuplot


def ballast(*args):
    return subprocess.run([str(bin_path()), *map(str, args)], capture_output=True, text=True, timeout=120)


@pytest.fixture(scope="module")
def drop(tmp_path_factory):
    """A run folder of the scene with its snapshots."""
    root = tmp_path_factory.mktemp("drop")
    scene = root / "drop.scene"
    scene.write_text(SCENE)
    run = root / "run"
    run.mkdir()
    done = ballast("run", scene, "--out", run, "--set", f"settings.snapshot_dt={SNAPSHOT_DT}")
    assert done.returncode == 0, done.stderr
    return run


@pytest.fixture(scope="module")
def plain(tmp_path_factory):
    """A run folder of the scene without snapshots."""
    root = tmp_path_factory.mktemp("plain")
    scene = root / "drop.scene"
    scene.write_text(SCENE)
    run = root / "run"
    run.mkdir()
    done = ballast("run", scene, "--out", run)
    assert done.returncode == 0, done.stderr
    return run


def table(path):
    lines = Path(path).read_text().splitlines()
    head = lines[0].split("\t")
    return [dict(zip(head, line.split("\t"))) for line in lines[1:] if line]


def block(script, name):
    """The lines of data block $name of a gnuplot script."""
    text = Path(script).read_text()
    found = re.search(rf"^\${name} << EOD\n(.*?)^EOD$", text, re.S | re.M)
    return found.group(1).splitlines() if found else []


def bars(script, k=0):
    """The bars of $chains_k: (a, b, F_n, width, length) each."""
    out, lines = [], block(script, f"chains_{k}")
    for i, line in enumerate(lines):
        if line.startswith("# "):
            _, a, b, fn = line.split()
            c = [tuple(map(float, lines[i + j].split())) for j in (1, 2, 3, 4)]
            out.append((a, b, float(fn), math.dist(c[0], c[3]), math.dist(c[0], c[1])))
    return out


def compressive(contacts):
    return [c for c in contacts if float(c["fn"]) + float(c.get("dn") or 0) > 0]


def gif_images(data):
    """The number of images of a GIF, walking its blocks (raises on a malformed file)."""
    assert data[:6] in (b"GIF87a", b"GIF89a"), data[:6]
    flags = data[10]
    pos = 13 + (3 * 2 ** ((flags & 7) + 1) if flags & 0x80 else 0)
    images = 0
    while True:
        kind = data[pos]
        if kind == 0x3B:
            return images
        if kind == 0x21:                       # an extension: its label, then sub-blocks
            pos += 2
        elif kind == 0x2C:                     # an image: descriptor, colour table, LZW size, sub-blocks
            images += 1
            local = data[pos + 9]
            pos += 10 + (3 * 2 ** ((local & 7) + 1) if local & 0x80 else 0) + 1
        else:
            raise AssertionError(f"byte {pos}: block 0x{kind:02x} is not a GIF block")
        while data[pos]:
            pos += data[pos] + 1
        pos += 1


def png_size(data):
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


# ---------------------------------------------------------------- plot


def test_plot_draws_every_disc_and_each_compressive_contact_with_width_proportional_to_fn(drop, tmp_path, capsys):
    out, script = tmp_path / "final.svg", tmp_path / "final.gp"
    assert main(["plot", str(drop), "--out", str(out), "--script", str(script)]) == 0
    said = capsys.readouterr().out
    assert "final state" in said and f"{N_DISCS} discs" in said
    root = ET.parse(out).getroot()
    assert root.tag.endswith("svg") and root.findall(".//{http://www.w3.org/2000/svg}polygon")
    discs = table(drop / "discs.tsv")
    drawn = [line.split() for line in block(script, "discs_0") if not line.startswith("#")]
    assert len(drawn) == len(discs) == N_DISCS
    assert [float(d[0]) for d in drawn] == [float(d["x"]) for d in discs]
    assert [float(d[2]) for d in drawn] == [float(d["r"]) for d in discs]
    assert [int(d[4]) for d in drawn] == [int(d["fixed"]) for d in discs]      # the pin is held
    contacts = table(drop / "contacts.tsv")
    found = bars(script)
    assert len(found) == len(compressive(contacts)) > 0
    mean_r = sum(float(d["r"]) for d in discs) / len(discs)
    fmax = max(b[2] for b in found)
    for a, b, fn, width, length in found:
        assert width == pytest.approx(pictures.CHAIN_WIDTH_SHARE * mean_r * fn / fmax, rel=1e-9)
        assert length > 0
    assert f"{fmax:.4g}" in Path(script).read_text()      # the title states the largest force


def test_plot_bar_ends_are_the_disc_centres_and_the_wall_contact_point(drop, tmp_path):
    script = tmp_path / "p.gp"
    assert main(["plot", str(drop), "--out", str(tmp_path / "p.png"), "--script", str(script)]) == 0
    discs = {d["name"]: (float(d["x"]), float(d["y"])) for d in table(drop / "discs.tsv")}
    contacts = {(c["a"], c["b"]): c for c in compressive(table(drop / "contacts.tsv"))}
    lines = block(script, "chains_0")
    walls = 0
    for i, line in enumerate(lines):
        if not line.startswith("# "):
            continue
        _, a, b, _ = line.split()
        c = [tuple(map(float, lines[i + j].split())) for j in (1, 2, 3, 4)]
        start = ((c[0][0] + c[3][0]) / 2, (c[0][1] + c[3][1]) / 2)
        end = ((c[1][0] + c[2][0]) / 2, (c[1][1] + c[2][1]) / 2)
        contact = contacts[(a, b)]
        assert start == pytest.approx(discs[a], abs=1e-12)
        if contact["kind"] == "wall":
            walls += 1
            assert end == pytest.approx((float(contact["x"]), float(contact["y"])), abs=1e-12)
        else:
            assert end == pytest.approx(discs[b], abs=1e-12)
    assert walls > 0


def test_plot_png_and_colours(drop, tmp_path):
    for colour in pictures.COLOURS:
        out = tmp_path / f"{colour}.png"
        assert main(["plot", str(drop), "--out", str(out), "--colour", colour]) == 0
        w, h = png_size(out.read_bytes())
        assert w > 300 and h > 300


def test_plot_rotation_is_counted_from_the_first_snapshot_or_the_stage_asked(drop, tmp_path, capsys):
    script = tmp_path / "r.gp"
    assert main(["plot", str(drop), "--out", str(tmp_path / "r.png"), "--script", str(script)]) == 0
    theta0 = {d["name"]: float(d["theta"]) for d in table(drop / "snapshots" / "discs.000000.tsv")}
    final = table(drop / "discs.tsv")
    values = [float(line.split()[3]) for line in block(script, "discs_0") if not line.startswith("#")]
    assert values == pytest.approx([float(d["theta"]) - theta0[d["name"]] for d in final], abs=1e-12)
    assert "since frame 0" in capsys.readouterr().out
    # --since rest: the last snapshot at or before the first cycle of stage rest (t = 2 s)
    assert main(["plot", str(drop), "--out", str(tmp_path / "r.png"), "--script", str(script),
                 "--since", "rest"]) == 0
    index = table(drop / "snapshots" / "index.tsv")
    info = pictures.run_info(drop)
    start = info["stages"][0]["cycles"]
    frame = max((r for r in index if float(r["cycle"]) <= start), key=lambda r: float(r["cycle"]))
    assert 0 < int(frame["frame"]) < len(index) - 1
    assert f"frame {frame['frame']}:" in capsys.readouterr().out
    theta_ref = {d["name"]: float(d["theta"])
                 for d in table(drop / "snapshots" / f"discs.{int(frame['frame']):06d}.tsv")}
    values = [float(line.split()[3]) for line in block(script, "discs_0") if not line.startswith("#")]
    assert values == pytest.approx([float(d["theta"]) - theta_ref[d["name"]] for d in final], abs=1e-12)


def test_plot_at_draws_the_snapshot_nearest_the_time(drop, tmp_path, capsys):
    index = table(drop / "snapshots" / "index.tsv")
    times = [float(r["time"]) for r in index]
    assert len(index) >= 5
    for at, want in ((times[1] + 0.4 * (times[2] - times[1]), 1), (times[1] + 0.6 * (times[2] - times[1]), 2),
                     (-5.0, 0), (1e9, len(index) - 1)):
        script = tmp_path / "at.gp"
        assert main(["plot", str(drop), "--at", repr(at), "--out", str(tmp_path / "at.svg"),
                     "--script", str(script)]) == 0
        assert f"drew frame {want}:" in capsys.readouterr().out
        discs = table(drop / "snapshots" / f"discs.{want:06d}.tsv")
        drawn = [line.split() for line in block(script, "discs_0") if not line.startswith("#")]
        assert [float(d[1]) for d in drawn] == [float(d["y"]) for d in discs]
        assert len(bars(script)) == len(compressive(table(drop / "snapshots" / f"contacts.{want:06d}.tsv")))


def test_plot_default_output_is_in_the_run_folder(drop, capsys):
    for old in drop.glob("plot*.png"):
        old.unlink()
    assert main(["plot", str(drop)]) == 0
    assert png_size((drop / "plot.png").read_bytes())
    assert main(["plot", str(drop), "--at", "1"]) == 0
    assert png_size((drop / "plot.000002.png").read_bytes())


# ---------------------------------------------------------------- movie


def test_movie_gif_has_one_image_per_snapshot(drop, tmp_path, capsys):
    frames = len(table(drop / "snapshots" / "index.tsv"))
    out = tmp_path / "m.gif"
    assert main(["movie", str(drop), "--out", str(out)]) == 0
    assert gif_images(out.read_bytes()) == frames
    assert main(["movie", str(drop), "--out", str(out), "--every", "3", "--colour", "speed"]) == 0
    assert gif_images(out.read_bytes()) == len(range(0, frames, 3)) + (1 if (frames - 1) % 3 else 0)


def test_movie_html_player_holds_every_frame(drop, tmp_path):
    out = tmp_path / "m.html"
    assert main(["movie", str(drop), "--out", str(out), "--every", "2"]) == 0
    text = out.read_text()
    listed = re.search(r"const frames = \[(.*?)\];", text, re.S).group(1)
    frames = re.findall(r'"data:image/png;base64,([A-Za-z0-9+/=]+)"', listed)
    n = len(table(drop / "snapshots" / "index.tsv"))
    assert len(frames) == len(range(0, n, 2)) + (1 if (n - 1) % 2 else 0)
    import base64
    assert all(png_size(base64.b64decode(f)) for f in frames)
    assert "http" not in text.replace("http-equiv", "")      # nothing fetched from the network


# ---------------------------------------------------------------- refused


def refused(capsys, *argv):
    assert main(list(map(str, argv))) == 2
    return capsys.readouterr().err


def test_refusals_exit_2_and_write_nothing(drop, plain, tmp_path, capsys):
    out = tmp_path / "x.png"
    assert "is not a run folder" in refused(capsys, "plot", tmp_path, "--out", out)
    assert "no such folder" in refused(capsys, "plot", tmp_path / "nowhere", "--out", out)
    err = refused(capsys, "plot", plain, "--at", "1", "--out", out)
    assert "has no snapshots" in err and "snapshots/index.tsv" in err and "snapshot_dt" in err
    assert "has no snapshots" in refused(capsys, "movie", plain, "--out", tmp_path / "m.gif")
    assert "has no snapshots" in refused(capsys, "plot", plain, "--since", "rest", "--out", out)
    assert "no stage 'shear'" in refused(capsys, "plot", drop, "--since", "shear", "--out", out)
    assert ".svg or .png" in refused(capsys, "plot", drop, "--out", tmp_path / "x.jpg")
    assert ".gif or .html" in refused(capsys, "movie", drop, "--out", tmp_path / "x.png")
    assert "finite" in refused(capsys, "plot", drop, "--at", "nan", "--out", out)
    assert "1 or more" in refused(capsys, "movie", drop, "--every", "0", "--out", tmp_path / "m.gif")
    assert "outside reports/" in refused(capsys, "plot", drop, "--out", REPO_ROOT / "cases" / "x.png")
    assert "outside reports/" in refused(capsys, "plot", drop, "--out", out, "--script", REPO_ROOT / "x.gp")
    assert not (REPO_ROOT / "cases" / "x.png").exists() and not (REPO_ROOT / "x.gp").exists()
    assert not list(tmp_path.glob("x.*")) and not list(tmp_path.glob("m.*"))


def test_a_malformed_snapshot_is_named(drop, tmp_path, capsys):
    broken = tmp_path / "broken"
    shutil.copytree(drop, broken)
    index = broken / "snapshots" / "index.tsv"
    lines = index.read_text().splitlines()
    index.write_text("\n".join(lines[:2] + [lines[2].replace("\t", "\tx", 1)] + lines[3:]) + "\n")
    err = refused(capsys, "movie", broken, "--out", tmp_path / "m.gif")
    assert "index.tsv:3" in err
    index.write_text("\n".join(lines) + "\n")
    (broken / "snapshots" / "contacts.000001.tsv").unlink()
    assert "contacts.000001.tsv missing" in refused(capsys, "movie", broken, "--out", tmp_path / "m.gif")


def test_reference_frame_is_the_last_snapshot_at_or_before_the_stage():
    found = [pictures.Frame(k, c, c / 10, g) for k, (c, g) in enumerate([(0, "a"), (40, "a"), (80, "b"), (120, "b")])]
    info = {"stages": [{"name": "a", "cycles": 80}, {"name": "b", "cycles": 60}]}
    assert pictures.reference_frame(found, info, "b").number == 2          # a snapshot at the start itself
    info["stages"][0]["cycles"] = 79
    assert pictures.reference_frame(found, info, "b").number == 1          # else the one before it
    assert pictures.reference_frame(found, info, "a").number == 0
    with pytest.raises(PictureError, match="no stage 'c'"):
        pictures.reference_frame(found, info, "c")
    assert pictures.nearest(found, 60, lambda f: f.cycle).number == 1      # a tie: the earlier


# ---------------------------------------------------------------- the report's figures

CASE = """[case drop]
tier = quick
title = Discs dropped into a box
checks = none
runtime = 1

[variant a]
scene = drop.scene

[variant b]
scene = drop.scene
label = bee

[figure grid]
kind = snapshots
title = The drop
variants = a b
{keys}

[figure anim]
kind = movie
title = The drop, animated
variants = a b
every = 2
"""


def case_text(**keys):
    """CASE with the grid's keys: these defaults, changed or added by keys."""
    grid = {"show": "both", "first": "the start; 0", "frames": "3", "since": "rest", "label": "Ek; Ek", **keys}
    return CASE.format(keys="\n".join(f"{k} = {v}" for k, v in grid.items()))


@pytest.fixture
def drop_project(drop, tmp_path, monkeypatch):
    """A catalogue of one case whose two variants' runs are the drop run (copied)."""
    root = tmp_path / "project"
    (root / "cases" / "drop").mkdir(parents=True)
    (root / "reference").mkdir()
    (root / "cases" / "drop" / "drop.scene").write_text(SCENE)
    index = table(drop / "snapshots" / "index.tsv")
    (root / "cases" / "drop" / "case.txt").write_text(case_text(first=f"one second in; {index[2]['cycle']}"))
    for v in ("a", "b"):
        shutil.copytree(drop, root / "reports" / "runs" / "drop" / v)
    for key, sub in (("BALLAST_CASES", "cases"), ("BALLAST_REFERENCE", "reference"), ("BALLAST_REPORTS", "reports")):
        monkeypatch.setenv(key, str(root / sub))
    return root


def test_report_draws_the_snapshot_grid_and_shows_the_movie(drop_project, drop):
    assert main(["report", "drop", "--tier", "full"]) == 0
    figures = drop_project / "reports" / "figures"
    assert png_size((figures / "drop_grid.png").read_bytes())
    n = len(table(drop / "snapshots" / "index.tsv"))
    assert gif_images((figures / "drop_anim.gif").read_bytes()) == len(range(0, n, 2)) + (1 if (n - 1) % 2 else 0)
    assert not list(figures.glob("*.svg"))          # grids and movies are raster only
    reports = drop_project / "reports"
    for page, up in ((reports / "index.html", ""), (reports / "cases" / "drop.html", "../")):
        text = page.read_text()
        assert f'src="{up}figures/drop_grid.png"' in text and f'src="{up}figures/drop_anim.gif"' in text
    assert "(../figures/drop_anim.gif)" in (reports / "cases" / "drop.md").read_text()


def test_snapshot_grid_frames_run_from_first_to_the_last(drop_project, drop, tmp_path):
    from harness import catalogue
    from harness.compare import RunStore, folder_locator
    case = catalogue.select(catalogue.load(drop_project / "cases"), ["drop"])[0]
    figure = next(f for f in case.figures if f.name == "grid")
    store = RunStore(folder_locator(drop_project / "reports" / "runs"))
    png = tmp_path / "grid.png"
    text, notes = pictures.snapshots_script(case, figure, store, tmp_path, png, None)
    assert not notes
    script = tmp_path / "grid.gp"
    script.write_text(text)
    index = table(drop / "snapshots" / "index.tsv")
    last = len(index) - 1
    want = sorted({round(2 + (last - 2) * k / 2) for k in range(3)})   # frames 2 .. last, three of them
    for k, frame in enumerate(want * 2):                                # variant a's row, then b's
        discs = table(drop / "snapshots" / f"discs.{frame:06d}.tsv")
        drawn = [line.split() for line in block(script, f"discs_{k}") if not line.startswith("#")]
        assert [float(d[1]) for d in drawn] == [float(d["y"]) for d in discs]
    assert not block(script, f"discs_{2 * len(want)}")
    # the label: series.tsv's Ek at the frame's cycle; the first frame says what it is nearest
    series = table(drop / "series.tsv")
    import numpy as np
    ek = float(np.interp(float(index[2]["cycle"]), [float(r["cycle"]) for r in series],
                         [float(r["Ek"]) for r in series]))
    assert f"Ek = {ek:#.3g}, nearest one second in" in text and "bee, cycle" in text
    # rotation since the start of stage rest, for both rows
    assert "since stage rest began" in text
    assert main(["report", "drop", "--tier", "full"]) == 0


@pytest.mark.parametrize("key, value, message", [("show", "sideways", "'show' must be one of network, rotation, both"),
                                                  ("frames", "0", "'frames' must be a whole number, 1 or more"),
                                                  ("frames", "2.5", "'frames' must be a whole number"),
                                                  ("first", "one; (", "'first' is not an expression")])
def test_catalogue_refuses_bad_snapshot_figure_keys(drop_project, capsys, key, value, message):
    (drop_project / "cases" / "drop" / "case.txt").write_text(case_text(**{key: value}))
    assert main(["report", "drop", "--tier", "full"]) == 2
    err = capsys.readouterr().err
    assert message in err and "case.txt:" in err


def test_tensile_and_open_contacts_are_not_drawn(drop, tmp_path, capsys):
    """F_n = fn + dn: a contact whose dashpot pulls harder than its spring pushes is not drawn,
    nor one the exact solver marks open."""
    run = tmp_path / "run"
    shutil.copytree(drop, run)
    lines = (run / "contacts.tsv").read_text().splitlines()
    head = lines[0].split("\t")
    rows = [line.split("\t") for line in lines[1:]]
    assert len(rows) >= 3
    fn, dn = head.index("fn"), head.index("dn")
    rows[0][dn] = repr(-2 * float(rows[0][fn]))                     # pulled apart by its dashpot
    head.append("open")
    for k, row in enumerate(rows):
        row.append("1" if k == 1 else "0")                           # opened
    (run / "contacts.tsv").write_text("\n".join("\t".join(r) for r in [head] + rows) + "\n")
    script = tmp_path / "p.gp"
    assert main(["plot", str(run), "--out", str(tmp_path / "p.png"), "--script", str(script)]) == 0
    drawn = {(a, b) for a, b, *_ in bars(script)}
    assert len(drawn) == len(rows) - 2
    assert (rows[0][0], rows[0][1]) not in drawn and (rows[1][0], rows[1][1]) not in drawn
    assert f"{len(rows) - 2} compressive contacts" in capsys.readouterr().out
