"""Force-network pictures in the manner of Cundall & Strack (1979), Fig. 5(b).

"contact forces are displayed graphically ... by plotting rectangles through the
contacts and with the orientation of the contact forces.  The lengths of the
rectangles are equal to the sum of the radii of the discs in contact and the widths
are proportional to the magnitudes of the contact forces."

From a run folder's final state (discs.tsv, contacts.tsv, walls.tsv) this writes a
gnuplot script: discs as circles, walls as thick lines, and per contact a filled
rectangle centred on the contact point, turned to the direction of the contact force
(F_n along the normal plus F_s along the tangent, dashpots included), of length
R_a + R_b (R of the disc for a wall contact) and of width proportional to |F|, the
largest force drawn WIDEST_SHARE of the largest radius wide.
"""
import math
from pathlib import Path

import numpy as np

WIDEST_SHARE = 0.6   # width of the largest force's rectangle, as a share of the largest radius


def read_table(path):
    """A tab-separated file with a header line, as a list of dicts (strings)."""
    lines = Path(path).read_text(encoding="utf-8").splitlines()
    if not lines:
        raise ValueError(f"{path}: empty")
    head = lines[0].split("\t")
    return [dict(zip(head, line.split("\t"))) for line in lines[1:] if line]


def rectangles(discs, contacts):
    """Corner lists of the force rectangles, and the largest force."""
    radius = {d["name"]: float(d["r"]) for d in discs}
    forces = []
    for c in contacts:
        nx, ny = float(c["nx"]), float(c["ny"])
        fn = float(c["fn"]) + float(c.get("dn", 0) or 0)
        fs = float(c["fs"]) + float(c.get("ds", 0) or 0)
        # Force on body b: fn along n plus fs along t = (ny, -nx) (C&S Fig. 3).
        fx, fy = fn * nx + fs * ny, fn * ny - fs * nx
        length = radius.get(c["a"], 0.0) + radius.get(c["b"], 0.0)
        forces.append((float(c["x"]), float(c["y"]), fx, fy, length))
    fmax = max((math.hypot(f[2], f[3]) for f in forces), default=0.0)
    rmax = max(radius.values(), default=1.0)
    boxes = []
    for x, y, fx, fy, length in forces:
        f = math.hypot(fx, fy)
        if f == 0 or fmax == 0:
            continue
        ux, uy = fx / f, fy / f
        half_w = 0.5 * WIDEST_SHARE * rmax * f / fmax
        half_l = 0.5 * length
        corners = [(x + sl * half_l * ux - sw * half_w * uy, y + sl * half_l * uy + sw * half_w * ux)
                   for sl, sw in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
        boxes.append(corners)
    return boxes, fmax


def script(folder, title, png, svg, size="800,800"):
    """The gnuplot script for the network of one run folder (raises ValueError if unreadable)."""
    folder = Path(folder)
    discs = read_table(folder / "discs.tsv")
    contacts = read_table(folder / "contacts.tsv")
    walls = read_table(folder / "walls.tsv") if (folder / "walls.tsv").is_file() else []
    boxes, fmax = rectangles(discs, contacts)
    xs = [float(d["x"]) for d in discs]
    ys = [float(d["y"]) for d in discs]
    rmax = max(float(d["r"]) for d in discs)
    x0, x1 = min(xs) - 2 * rmax, max(xs) + 2 * rmax
    y0, y1 = min(ys) - 2 * rmax, max(ys) + 2 * rmax
    q = lambda s: "'" + str(s).replace("'", "''") + "'"
    lines = [f"set terminal pngcairo size {size} noenhanced font 'sans,10'", f"set output {q(png)}",
             "set size ratio -1", "unset key", f"set title {q(f'{title} (largest force {fmax:.4g})')}",
             f"set xrange [{x0!r}:{x1!r}]", f"set yrange [{y0!r}:{y1!r}]"]
    for k, w in enumerate(walls, start=1):
        lines.append(f"set arrow {k} from {float(w['ax'])!r},{float(w['ay'])!r} to "
                     f"{float(w['bx'])!r},{float(w['by'])!r} nohead lw 3 lc rgb '#444444'")
    for k, corners in enumerate(boxes, start=1):
        pts = " to ".join(f"{x!r},{y!r}" for x, y in corners + corners[:1])
        lines.append(f"set object {k} polygon from {pts} fillstyle solid 1.0 noborder "
                     f"fillcolor rgb '#c0392b' front")
    data = "\n".join(f"{float(d['x'])!r} {float(d['y'])!r} {float(d['r'])!r}" for d in discs)
    lines += ["$discs << EOD", data, "EOD",
              "plot $discs using 1:2:3 with circles lc rgb '#2c3e50' lw 1",
              f"set terminal svg size {size} noenhanced font 'sans,10' background '#ffffff'",
              f"set output {q(svg)}", "replot", "unset output", ""]
    return "\n".join(lines)
