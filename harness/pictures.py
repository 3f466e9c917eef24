"""Pictures and movies of any run: `harness plot RUN` and `harness movie RUN`, and the report's
figures of kinds `snapshots` and `movie` (case.txt; drawn through report/plots.py).

Kept whole (about 800 lines): reading a run's frames, laying out panels, scaling the chains and
colours over every panel drawn together, and writing one gnuplot script are one pipeline that
shares its scales and refusals; plot, movie and the report's two figure kinds all go through it.

A run folder (what `bin/ballast run SCENE --out DIR` writes) holds its final state --
discs.tsv, contacts.tsv, walls.tsv, run.json -- and, when the scene asks for them
(settings.snapshot_every = N cycles or snapshot_dt = T), snapshots/: index.tsv (frame, cycle,
time, stage; frame 0 the state at cycle 0, the last frame the final state) and per frame
discs.FFFFFF.tsv, contacts.FFFFFF.tsv and walls.FFFFFF.tsv, with the columns of the final files.

What a picture shows, drawn by gnuplot, one panel per state:

  discs   to scale: `with circles` (the radius in x-axis units) on equal axes (`set size
          ratio -1`), filled by --colour:
            rotation  theta minus theta at the reference (degrees, anticlockwise positive):
                      the first frame (the state at cycle 0) when the run has snapshots, the
                      last frame at or before the first cycle of a stage with --since STAGE,
                      and without snapshots theta as discs.tsv writes it (the scene's angles at
                      the start); diverging: blue clockwise, white none, red anticlockwise, on
                      a range +-R with R the ROTATION_QUANTILE of |rotation| over every disc
                      drawn rounded up to 1, 2 or 5 x 10^k (larger rotations saturate);
            speed     |v| from vx, vy, white to dark blue, from 0 to the SPEED_QUANTILE of |v|
                      rounded up;
            none      light grey;
          a held disc (fixed = 1) has a black border;
  walls   the segment from (ax, ay) to (bx, by) of each wall, thick grey;
  chains  each compressive contact (F_n = fn + dn > 0, the elastic force and its dashpot; a
          contact the exact solver marks open is not drawn): a black bar from the centre of one
          disc to the centre of the other (a disc-wall contact: from the disc's centre to the
          contact point) whose width is proportional to F_n: the largest F_n of all the panels
          drawn together is CHAIN_WIDTH_SHARE of the mean disc radius wide, in the plot's own
          units (the bars are drawn to scale like the discs).  Every title says that force.

The gnuplot script, its data inline ($discs_K: x y r colour fixed; $chains_K: a comment line
'# a b F_n' then the bar's four corners, one bar per block; $walls_K), can be kept with
--script FILE, to read or to edit and run again.  Each output is drawn in a scratch folder and
reaches its place whole (files.py).  Problems with the input -- a folder that is not a run, a
run without the snapshots asked for, a malformed table -- raise PictureError (exit 2) naming
the file.
"""
import base64
import html
import math
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import REPO_ROOT, files, reports_root
from .children import options as child_options
from .compare import evaluate, evaluate_array
from .errors import EvalError, PictureError, RunProblem, shown
from .expressions import Siblings
from .final_state import Table
from .tables import present, read_run_json

SNAPSHOTS = "snapshots"                 # the run folder's snapshot folder
INDEX_COLUMNS = ("frame", "cycle", "time", "stage")
DISC_COLUMNS = ("name", "x", "y", "r", "theta", "vx", "vy")
CONTACT_COLUMNS = ("a", "b", "kind", "x", "y", "fn")
WALL_COLUMNS = ("name", "ax", "ay", "bx", "by")
COLOURS = ("rotation", "speed", "none")

CHAIN_WIDTH_SHARE = 0.8     # the largest F_n's bar is this share of the mean radius wide: narrower
                            # than a disc, so two bars side by side and the discs under them stay apart
ROTATION_QUANTILE = 0.95    # the rotation scale spans +-(this quantile of |rotation|), rounded up: a
                            # shear band's few large rotations saturate rather than wash out the rest
SPEED_QUANTILE = 0.99       # the speed scale's top, for the same reason
MIN_ROTATION_RANGE = 1.0    # degrees: no narrower scale, so the round-off turns of a packing at rest stay white
MARGIN_SHARE = 0.03         # the blank border around the discs, a share of the larger side of their extent
MOVIE_DELAY = 50            # hundredths of a second between the frames of a GIF: two frames a second
PANEL_PX = 560              # the width of one panel of `plot` and `movie`, pixels
GRID_PANEL_PX = 300         # the width of one panel of a report grid (several frames and variants)
MOVIE_PANEL_PX = 360        # the width of one variant's panel of a report movie
FONT = "sans,10"
GIF_FONT = "DejaVuSans,9"   # the GIF terminal (libgd) finds TrueType fonts by file name
PALETTES = {"rotation": "set palette defined (-1 '#2166ac', -0.5 '#92c5de', 0 '#f7f7f7', 0.5 '#f4a582', 1 '#b2182b')",
            "speed": "set palette defined (0 '#f7fbff', 0.5 '#6baed6', 1 '#08306b')"}
GREY_DISC, DISC_BORDER, CHAIN_COLOUR, WALL_COLOUR = "#e3e3e3", "#8c8c8c", "#111111", "#555555"
PLOT_FORMATS = (".svg", ".png")
MOVIE_FORMATS = (".gif", ".html")


# ---------------------------------------------------------------- reading a run

@dataclass
class Frame:
    """One row of snapshots/index.tsv."""
    number: int
    cycle: float
    time: float
    stage: str

    def text(self):
        return f"frame {self.number}: cycle {self.cycle:.0f}, time {self.time:.6g}, stage {self.stage}"


@dataclass
class State:
    """What one panel draws: a frame of the snapshots or the final state."""
    label: str
    cycle: float
    time: float
    names: list
    x: np.ndarray
    y: np.ndarray
    r: np.ndarray
    theta: np.ndarray
    speed: np.ndarray
    fixed: np.ndarray
    chains: list        # (x0, y0, x1, y1, F_n, a, b) per compressive contact
    walls: list         # (ax, ay, bx, by) per wall


class _Sheet(Table):
    """A Table whose problems are PictureErrors (a run that cannot be drawn: exit 2)."""

    def numbers(self, name):
        try:
            return super().numbers(name)
        except EvalError as exc:
            raise PictureError(str(exc)) from None


def _table(path, needed):
    try:
        return _Sheet(path, needed)
    except EvalError as exc:
        raise PictureError(str(exc)) from None


def run_info(folder):
    """run.json of a run folder; PictureError when folder is not a run folder."""
    folder = Path(folder)
    if not folder.is_dir():
        raise PictureError(f"{shown(folder)}: no such folder (give a run folder: what bin/ballast run --out wrote)")
    if not (folder / "run.json").is_file():
        raise PictureError(f"{shown(folder)} is not a run folder: it has no run.json "
                           "(give a folder bin/ballast run --out wrote, e.g. reports/runs/CASE/VARIANT)")
    try:
        return read_run_json(folder)
    except RunProblem as exc:
        raise PictureError(str(exc)) from None


def read_state(folder, suffix, label, cycle, time):
    """The State of discs{suffix}, contacts{suffix} and walls{suffix} in folder."""
    folder = Path(folder)
    discs = _table(folder / f"discs{suffix}", DISC_COLUMNS)
    names = discs.text("name")
    x, y, r = discs.numbers("x"), discs.numbers("y"), discs.numbers("r")
    vx, vy = discs.numbers("vx"), discs.numbers("vy")
    fixed = discs.numbers("fixed") != 0 if discs.has("fixed") else np.zeros(len(names), dtype=bool)
    where = {name: i for i, name in enumerate(names)}
    if len(where) != len(names):
        raise PictureError(f"{discs.path}: two discs share a name")
    return State(label, cycle, time, names, x, y, r, discs.numbers("theta"), np.hypot(vx, vy), fixed,
                 _chains(folder / f"contacts{suffix}", where, x, y), _walls(folder / f"walls{suffix}"))


def _chains(path, where, x, y):
    """The compressive contacts of a contacts table as bars (x0, y0, x1, y1, F_n, a, b)."""
    t = _table(path, CONTACT_COLUMNS)
    a, b, kind = t.text("a"), t.text("b"), t.text("kind")
    fn = t.numbers("fn") + (t.numbers("dn") if t.has("dn") else 0.0)
    cx, cy = t.numbers("x"), t.numbers("y")
    closed = t.numbers("open") == 0 if t.has("open") else np.ones(len(t), dtype=bool)
    bars = []
    for k in range(len(t)):
        if not (fn[k] > 0 and closed[k]):
            continue
        if kind[k] == "wall":
            disc = a[k] if a[k] in where else b[k]
            if disc not in where:
                raise PictureError(f"{path}:{t.lines[k]}: neither '{a[k]}' nor '{b[k]}' is a disc of the state")
            i = where[disc]
            bars.append((x[i], y[i], cx[k], cy[k], fn[k], a[k], b[k]))
        else:
            missing = [n for n in (a[k], b[k]) if n not in where]
            if missing:
                raise PictureError(f"{path}:{t.lines[k]}: disc '{missing[0]}' is not in the state's discs")
            i, j = where[a[k]], where[b[k]]
            bars.append((x[i], y[i], x[j], y[j], fn[k], a[k], b[k]))
    return bars


def _walls(path):
    t = _table(path, WALL_COLUMNS)
    return list(zip(*(t.numbers(c) for c in ("ax", "ay", "bx", "by"))))


def final_state(folder, info):
    """The final state of a run: discs.tsv, contacts.tsv, walls.tsv."""
    folder = Path(folder)
    if not present(folder / "discs.tsv"):        # plain, or gzipped by validate (compact.py)
        status = info.get("status", "?")
        raise PictureError(f"{shown(folder)} has no discs.tsv (run.json: status '{status}'"
                           + (f": {info['message']}" if info.get("message") else "") + ")")
    cycle, time = float(info.get("steps") or 0), float(info.get("time") or 0.0)
    return read_state(folder, ".tsv", f"final state: cycle {cycle:.0f}, time {time:.6g}", cycle, time)


def frames(folder):
    """The Frames of snapshots/index.tsv; PictureError when the run has none."""
    index = Path(folder) / SNAPSHOTS / "index.tsv"
    if not index.is_file():
        raise PictureError(f"{shown(folder)} has no snapshots ({shown(index)} missing): run its scene with "
                           "settings.snapshot_every = N (cycles) or snapshot_dt = T (simulated time)")
    t = _table(index, INDEX_COLUMNS)
    if not len(t):
        raise PictureError(f"{shown(index)}: no frames")
    numbers, cycles, times = t.numbers("frame"), t.numbers("cycle"), t.numbers("time")
    out = [Frame(int(n), c, s, g) for n, c, s, g in zip(numbers, cycles, times, t.text("stage"))]
    for k, f in enumerate(out):
        if numbers[k] != f.number or f.number < 0 or not (math.isfinite(f.cycle) and math.isfinite(f.time)):
            raise PictureError(f"{shown(index)}:{t.lines[k]}: frame, cycle or time is not a whole, finite number")
    return out


def frame_state(folder, frame):
    """The State of one snapshot frame."""
    return read_state(Path(folder) / SNAPSHOTS, f".{frame.number:06d}.tsv", frame.text(), frame.cycle, frame.time)


def nearest(found, value, key):
    """The element of found whose key is nearest value (the earlier one on a tie)."""
    return min(found, key=lambda f: (abs(key(f) - value), key(f)))


def reference_frame(found, info, stage):
    """The rotation reference of --since STAGE: the last frame at or before the stage's first
    cycle (the cycles of the stages before it, run.json), else the first frame."""
    stages = info.get("stages") if isinstance(info.get("stages"), list) else []
    names = [g.get("name") for g in stages if isinstance(g, dict)]
    if stage not in names:
        raise PictureError(f"the run has no stage '{stage}' (its stages: {', '.join(map(str, names)) or 'none'})")
    start = sum(float(g.get("cycles") or 0) for g in stages[:names.index(stage)])
    before = [f for f in found if f.cycle <= start]
    return before[-1] if before else found[0]


# ---------------------------------------------------------------- what a panel shows

@dataclass
class Panel:
    state: State
    colour: str                 # COLOURS
    values: np.ndarray = None   # per disc: the rotation or speed coloured (None: grey)
    chains: bool = True
    title: str = ""
    border: bool = True         # a thin grey ring round each disc (off in the report's small panels:
                                # at 2 or 3 pixels a disc, the rings drown the chains and swell the PNG)


def rotation(state, reference):
    """theta - theta of the reference State (None: theta as written), per disc, by name."""
    if reference is None:
        return state.theta.copy()
    theta0 = dict(zip(reference.names, reference.theta))
    missing = [n for n in state.names if n not in theta0]
    if missing:
        raise PictureError(f"disc '{missing[0]}' of {state.label} is not in the reference {reference.label}")
    return state.theta - np.array([theta0[n] for n in state.names])


def colour_values(state, colour, reference):
    if colour == "rotation":
        return rotation(state, reference)
    if colour == "speed":
        return state.speed
    return None


def nice_ceiling(value):
    """The smallest of 1, 2, 5 x 10^k at or above value (> 0)."""
    power = 10.0 ** math.floor(math.log10(value))
    return next(m * power for m in (1, 2, 5, 10) if m * power >= value * (1 - 1e-12))


@dataclass
class Scales:
    """What the panels drawn together share: the box, the largest F_n, the colour range."""
    box: tuple
    fmax: float
    mean_r: float
    crange: tuple = None

    @property
    def width_per_force(self):
        """A bar's width per unit F_n, in the plot's units."""
        return CHAIN_WIDTH_SHARE * self.mean_r / self.fmax if self.fmax > 0 else 0.0


def scales(panels):
    states = [p.state for p in panels]
    if not any(s.names for s in states):
        raise PictureError(f"{states[0].label}: no discs to draw")
    x0 = min(float(np.min(s.x - s.r)) for s in states if s.names)
    x1 = max(float(np.max(s.x + s.r)) for s in states if s.names)
    y0 = min(float(np.min(s.y - s.r)) for s in states if s.names)
    y1 = max(float(np.max(s.y + s.r)) for s in states if s.names)
    pad = MARGIN_SHARE * max(x1 - x0, y1 - y0)
    fmax = max((c[4] for p in panels if p.chains for c in p.state.chains), default=0.0)
    mean_r = float(np.mean(np.concatenate([s.r for s in states])))
    out = Scales((x0 - pad, x1 + pad, y0 - pad, y1 + pad), fmax, mean_r)
    coloured = [p.values for p in panels if p.values is not None and p.values.size]
    if coloured:
        pooled = np.abs(np.concatenate(coloured))
        pooled = pooled[np.isfinite(pooled)]
        if panels[0].colour == "rotation":
            top = float(np.quantile(pooled, ROTATION_QUANTILE)) if pooled.size else 0.0
            r = nice_ceiling(max(top, MIN_ROTATION_RANGE))
            out.crange = (-r, r)
        else:
            top = float(np.quantile(pooled, SPEED_QUANTILE)) if pooled.size else 0.0
            out.crange = (0.0, nice_ceiling(top) if top > 0 else 1.0)
    return out


def scale_lines(s, colour=None, since=""):
    """What the scales mean, one short line each, for a title."""
    out = []
    if s.fmax > 0:
        out.append(f"bars: width proportional to F_n; the largest, {s.fmax:.4g}, drawn "
                   f"{CHAIN_WIDTH_SHARE * s.mean_r:.3g} wide ({CHAIN_WIDTH_SHARE:g} mean radius)")
    if s.crange and colour == "rotation":
        out.append(f"colour: rotation in degrees, anticlockwise positive, -{s.crange[1]:g} to {s.crange[1]:g}")
        if since:
            out.append(since)
    elif s.crange and colour == "speed":
        out.append(f"colour: speed |v|, 0 to {s.crange[1]:g}")
    return out


# ---------------------------------------------------------------- the gnuplot script

def gp_text(text):
    """A gnuplot double-quoted string (newlines as \\n)."""
    return '"' + str(text).replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


def gp_path(path):
    return "'" + str(path).replace("'", "''") + "'"


def bar_corners(x0, y0, x1, y1, width):
    """The four corners of a bar of width `width` from (x0, y0) to (x1, y1); None if it has no length."""
    length = math.hypot(x1 - x0, y1 - y0)
    if not length > 0 or not width > 0:
        return None
    px, py = -(y1 - y0) / length * width / 2, (x1 - x0) / length * width / 2
    return [(x0 + px, y0 + py), (x1 + px, y1 + py), (x1 - px, y1 - py), (x0 - px, y0 - py)]


def data_blocks(k, panel, s):
    """The data blocks of panel k: $discs_k, $chains_k (when it has bars), $walls_k (when it has walls)."""
    st = panel.state
    values = panel.values if panel.values is not None else np.zeros(len(st.names))
    lines = [f"$discs_{k} << EOD", "# x y r colour fixed"]
    lines += [f"{a!r} {b!r} {c!r} {v!r} {int(f)}" for a, b, c, v, f in zip(st.x, st.y, st.r, values, st.fixed)]
    lines.append("EOD")
    bars = []
    if panel.chains:
        for x0, y0, x1, y1, fn, a, b in st.chains:
            corners = bar_corners(x0, y0, x1, y1, fn * s.width_per_force)
            if corners:
                bars += [f"# {a} {b} {fn!r}"] + [f"{p!r} {q!r}" for p, q in corners] + [""]
    if bars:
        lines += [f"$chains_{k} << EOD", *bars, "EOD"]
    if st.walls:
        lines += [f"$walls_{k} << EOD"] + [f"{ax!r} {ay!r}\n{bx!r} {by!r}\n" for ax, ay, bx, by in st.walls] + ["EOD"]
    return lines, bool(bars)


def panel_commands(k, panel, s, has_bars, colourbox=True, tics=True):
    """The commands that draw panel k (after its data blocks)."""
    x0, x1, y0, y1 = s.box
    out = [f"set title {gp_text(panel.title or panel.state.label)}",
           f"set xrange [{x0!r}:{x1!r}]", f"set yrange [{y0!r}:{y1!r}]", "set size ratio -1", "unset key",
           "set clip two"]      # a wall whose both ends lie outside the box is still drawn
    out += ["set tics out nomirror scale 0.5", "set format x '%g'", "set format y '%g'"] if tics else ["unset tics"]
    border = f"border lc rgb '{DISC_BORDER}'" if panel.border else "noborder"
    if panel.values is not None and s.crange:
        out += [PALETTES[panel.colour], f"set cbrange [{s.crange[0]!r}:{s.crange[1]!r}]",
                "set colorbox" if colourbox else "unset colorbox", "set cbtics scale 0.5"]
        discs = (f"$discs_{k} using 1:2:3:($4 < {s.crange[0]!r} ? {s.crange[0]!r} : $4 > {s.crange[1]!r} ? "
                 f"{s.crange[1]!r} : $4) with circles lc palette lw 0.4 fs solid 1.0 {border}")
    else:
        out.append("unset colorbox")
        discs = f"$discs_{k} using 1:2:3 with circles fc rgb '{GREY_DISC}' lw 0.4 fs solid 1.0 {border}"
    clauses = [discs]
    if panel.state.fixed.any():
        clauses.append(f"$discs_{k} using 1:2:($5 > 0 ? $3 : 1/0) with circles lc rgb '#000000' lw 1.5 fs empty")
    if has_bars:
        clauses.append(f"$chains_{k} using 1:2 with filledcurves closed fs solid 1.0 noborder "
                       f"lc rgb '{CHAIN_COLOUR}'")
    if panel.state.walls:
        clauses.append(f"$walls_{k} using 1:2 with lines lw {2.5 if tics else 1.5} lc rgb '{WALL_COLOUR}'")
    out.append("plot " + ", \\\n     ".join(clauses))
    return out


def terminal(path, size, gif_delay=MOVIE_DELAY):
    """The terminal line for an output path, by its extension."""
    w, h = size
    ext = Path(path).suffix.lower()
    if ext == ".svg":
        return f"set terminal svg size {w},{h} noenhanced font '{FONT}' background '#ffffff'"
    if ext == ".png":
        return f"set terminal pngcairo size {w},{h} noenhanced font '{FONT}'"
    if ext == ".gif":
        return f"set terminal gif animate delay {gif_delay} loop 0 optimize size {w},{h} noenhanced font '{GIF_FONT}'"
    raise PictureError(f"{path}: cannot draw a {ext or 'file without extension'}")


LINE_PX = 16          # a line of title text at the fonts above, pixels
GAP_PX = 12           # between two panels of a grid, and round its edges
COLOURBOX_PX = 70     # right of a grid's last column: the colour box and its labels


@dataclass
class Layout:
    """A page's size in pixels and, for a grid, where its panels go (gnuplot's multiplot
    `margins` and `spacing`, fractions of the page): every panel's plot area is the same size,
    panel_px wide and as high as the box's aspect makes it."""
    size: tuple
    margins: tuple = None
    spacing: tuple = None


def layout(s, columns, rows, panel_px, title_lines, colourbox, head_lines):
    x0, x1, y0, y1 = s.box
    panel_h = (y1 - y0) / (x1 - x0) * panel_px
    if rows * columns == 1:       # one plot with its tics and gnuplot's own margins
        return Layout((panel_px + (70 if colourbox else 10) + 60, int(panel_h + LINE_PX * title_lines + 60)))
    title_px = LINE_PX * title_lines + 6
    head_px = LINE_PX * (head_lines + 1) + 6     # gnuplot sets the page title a line below the top
    right_px = COLOURBOX_PX if colourbox else GAP_PX
    w = GAP_PX + columns * panel_px + (columns - 1) * GAP_PX + right_px
    h = head_px + rows * (title_px + panel_h) + (rows - 1) * GAP_PX + GAP_PX
    w, h = int(math.ceil(w)), int(math.ceil(h))
    return Layout((w, h), (GAP_PX / w, 1 - right_px / w, GAP_PX / h, 1 - (head_px + title_px) / h),
                  (GAP_PX / w, (GAP_PX + title_px) / h))


def page_commands(grid, s, figure_title, where):
    """Commands drawing one page: grid is a list of rows of (k, panel, has_bars); one panel is
    a plain plot, more a multiplot placed by the Layout where (colour box on the last column)."""
    rows, columns = len(grid), max(len(r) for r in grid)
    if rows * columns == 1:
        k, panel, has_bars = grid[0][0]
        return panel_commands(k, panel, s, has_bars)
    (l, r, b, t), (xs, ys) = where.margins, where.spacing
    out = [f"set multiplot layout {rows},{columns} title {gp_text(figure_title)} "
           f"margins {l!r},{r!r},{b!r},{t!r} spacing {xs!r},{ys!r}"]
    for row in grid:
        for c, (k, panel, has_bars) in enumerate(row):
            out += panel_commands(k, panel, s, has_bars, colourbox=(c == len(row) - 1), tics=False)
        out += ["set multiplot next"] * (columns - len(row))
    out.append("unset multiplot")
    return out


def draw(script, workdir):
    """Run gnuplot on script in workdir; RuntimeError with its complaint when it fails."""
    if not shutil.which("gnuplot"):
        raise RuntimeError("gnuplot not found (Debian: apt-get install gnuplot-nox)")
    path = Path(workdir) / "picture.gp"
    files.write_text(path, script)
    done = subprocess.run(["gnuplot", str(path)], capture_output=True, text=True, timeout=1800,
                          **child_options(keep_lock=False))
    if done.returncode != 0:
        raise RuntimeError("gnuplot failed: " + ((done.stderr.strip().splitlines() or ["exit %d" % done.returncode])[-1]))


def page_script(pages, s, out_path, title, panel_px, gif_delay=MOVIE_DELAY, outputs=None):
    """The whole script: every panel's data, then each page (a list of grid rows of Panels),
    drawn to out_path (one file; a GIF has one frame per page) or, given outputs, page k to
    outputs[k]."""
    blocks, grids, k = [], [], 0
    for page in pages:
        grid = []
        for row in page:
            cells = []
            for panel in row:
                lines, has_bars = data_blocks(k, panel, s)
                blocks += lines
                cells.append((k, panel, has_bars))
                k += 1
            grid.append(cells)
        grids.append(grid)
    rows, columns = len(pages[0]), max(len(r) for r in pages[0])
    single = rows * columns == 1
    colourbox = any(p.values is not None for page in pages for row in page for p in row)
    title_lines = 1 + max(str(p.title).count("\n") for page in pages for row in page for p in row)
    where = layout(s, columns, rows, panel_px, title_lines, colourbox, 0 if single else 1 + str(title).count("\n"))
    lines = [terminal(outputs[0] if outputs else out_path, where.size, gif_delay)]
    if not outputs:
        lines.append(f"set output {gp_path(out_path)}")
    lines += blocks + ["set style fill solid 1.0"]
    for n, grid in enumerate(grids):
        if outputs:
            lines.append(f"set output {gp_path(outputs[n])}")
        page_title = title if not single else ""
        lines += page_commands(grid, s, page_title, where)
    lines += ["unset output", ""]
    return "\n".join(lines)


# ---------------------------------------------------------------- output paths

def guard(path):
    """Refuse an output inside the repository but outside its reports folder: the pictures of a
    run never go into the catalogue's (or any committed) tree."""
    path = Path(path).resolve()
    repo = REPO_ROOT.resolve()
    allowed = [reports_root().resolve(), (REPO_ROOT / "reports").resolve()]
    if (path == repo or repo in path.parents) and not any(a == path or a in path.parents for a in allowed):
        raise PictureError(f"{shown(path)}: will not write into the repository's tree outside reports/; "
                           "give --out a path elsewhere")
    if path.is_dir():
        raise PictureError(f"{shown(path)} is a folder: give --out a file name")
    return path


def output_path(run, out, default, formats, what):
    path = Path(out) if out else Path(run) / default
    if path.suffix.lower() not in formats:
        raise PictureError(f"{path}: a {what} is written as {' or '.join(formats)} (by the extension of --out)")
    if not path.parent.is_dir():
        raise PictureError(f"{shown(path.parent)}: no such folder for --out")
    return guard(path)


def publish(drawn, path):
    """Copy a drawing gnuplot made in the scratch folder to its place, whole."""
    if not drawn.is_file() or drawn.stat().st_size == 0:
        raise RuntimeError(f"gnuplot wrote no {drawn.suffix} file")
    files.copy(drawn, path)


# ---------------------------------------------------------------- harness plot

def _reference(run, info, found, colour, since):
    """(the State rotations are counted from or None, what it is) for --colour and --since."""
    if colour != "rotation":
        return None, ""
    if not found:
        return None, "theta as discs.tsv writes it (no snapshots)"
    frame = reference_frame(found, info, since) if since else found[0]
    return frame_state(run, frame), (f"since {frame.text()}" + (f" (the last snapshot before stage {since} began)"
                                                                if since else ""))


def plot(run, at=None, out=None, colour="rotation", since=None, script=None):
    """Draw one state of a run: the final state, or with at the snapshot nearest that time.
    Returns the lines to print."""
    run = Path(run)
    info = run_info(run)
    if colour not in COLOURS:
        raise PictureError(f"--colour must be one of {', '.join(COLOURS)}, not '{colour}'")
    if at is not None and not math.isfinite(at):
        raise PictureError(f"--at must be a finite time, not {at}")
    has_snapshots = (run / SNAPSHOTS / "index.tsv").is_file()
    found = frames(run) if (at is not None or since or has_snapshots) else None
    said = []
    if at is not None:
        frame = nearest(found, at, lambda f: f.time)
        state = frame_state(run, frame)
        said.append(f"drew {frame.text()}, the snapshot nearest --at {at:g} "
                    f"(the snapshots run from time {found[0].time:g} to {found[-1].time:g})")
        default = f"plot.{frame.number:06d}.png"
    else:
        state = final_state(run, info)
        said.append(f"drew the {state.label} (discs.tsv, contacts.tsv, walls.tsv)")
        default = "plot.png"
    if not state.names:
        raise PictureError(f"{shown(run)}: {state.label}: no discs to draw")
    path = output_path(run, out, default, PLOT_FORMATS, "plot")
    reference, since_text = _reference(run, info, found, colour, since)
    panel = Panel(state, colour, colour_values(state, colour, reference))
    s = scales([panel])
    panel.title = "\n".join([f"{shown(run)}: {state.label}"] + scale_lines(s, colour, since_text))
    if since_text:
        said.append(f"rotation {since_text}")
    _render([[[panel]]], s, "", path, PANEL_PX, script)
    said.append(f"wrote {shown(path)} ({len(state.names)} discs, {len(state.chains)} compressive contacts, "
                f"{len(state.walls)} walls)")
    return said


def _render(pages, s, title, path, panel_px, script, gif_delay=MOVIE_DELAY):
    """Draw pages to path (svg, png, gif: one file; html: PNG frames in a self-contained player)."""
    with tempfile.TemporaryDirectory(prefix="ballast-picture-") as workdir:
        work = Path(workdir)
        if path.suffix.lower() == ".html":
            outputs = [work / f"frame_{n:04d}.png" for n in range(len(pages))]
            text = page_script(pages, s, None, title, panel_px, outputs=outputs)
        else:
            drawn = work / f"picture{path.suffix.lower()}"
            text = page_script(pages, s, drawn, title, panel_px, gif_delay)
        if script:
            files.write_text(guard(script), text)
        draw(text, work)
        if path.suffix.lower() == ".html":
            labels = ["; ".join(p.state.label for row in page for p in row) for page in pages]
            files.write_text(path, player(title, outputs, labels))
        else:
            publish(drawn, path)


# ---------------------------------------------------------------- harness movie

def chosen_frames(found, every):
    """Every `every`-th frame from the first, and the last always."""
    if every < 1:
        raise PictureError(f"--every must be 1 or more, not {every}")
    picked = found[::every]
    return picked if picked[-1] is found[-1] else picked + [found[-1]]


def movie(run, out=None, every=1, colour="rotation", since=None, script=None):
    """An animation of a run's snapshots: a GIF, or PNG frames in a self-contained HTML player."""
    run = Path(run)
    info = run_info(run)
    if colour not in COLOURS:
        raise PictureError(f"--colour must be one of {', '.join(COLOURS)}, not '{colour}'")
    found = frames(run)
    picked = chosen_frames(found, every)
    path = output_path(run, out, "movie.gif", MOVIE_FORMATS, "movie")
    reference, since_text = _reference(run, info, found, colour, since)
    panels = []
    for frame in picked:
        state = frame_state(run, frame)
        panels.append(Panel(state, colour, colour_values(state, colour, reference)))
    s = scales(panels)
    for p in panels:
        p.title = "\n".join([f"{shown(run)}: {p.state.label}"] + scale_lines(s, colour, since_text))
    _render([[[p]] for p in panels], s, shown(run), path, PANEL_PX, script)
    return [f"drew {len(panels)} of the {len(found)} snapshots (every {every}, and the last)"
            + (f"; rotation {since_text}" if since_text else ""), f"wrote {shown(path)}"]


# ---------------------------------------------------------------- the report's figures

def _variant_frames(case, figure, variant, store, notes):
    """(run folder, Run, Frames, the rotation reference State or None, what it is) of one variant
    of a snapshots or movie figure; None (and a note) when it cannot be drawn."""
    try:
        run = store.get(case.name, variant)
        found = frames(run.folder)
        reference = None
        if figure.show in ("rotation", "both"):
            frame = reference_frame(found, run.info, figure.since) if figure.since else found[0]
            reference = (frame_state(run.folder, frame), frame)
    except (RunProblem, PictureError) as problem:
        notes.append(f"{variant}: not drawn: {problem}")
        return None
    return run, found, reference


def _label_at(figure, run, siblings, notes, variant):
    """A function cycle -> the panel's label text (from the figure's `label`), or to ''."""
    if not figure.label_expr:
        return lambda cycle: ""
    try:
        values = evaluate_array(figure.label_expr, run, siblings)
    except EvalError as problem:
        notes.append(f"{variant}: no {figure.label}: {problem}")
        return lambda cycle: ""
    cycles = np.asarray(run.columns["cycle"], dtype=float)[-values.size:] if values.size else np.array([])
    if values.size == 0 or cycles.size != values.size:
        notes.append(f"{variant}: no {figure.label}: {values.size} values against {cycles.size} rows")
        return lambda cycle: ""

    def label(cycle):
        if not cycles[0] <= cycle <= cycles[-1]:
            return f"{figure.label} = -"
        return f"{figure.label} = {float(np.interp(cycle, cycles, values)):#.3g}"
    return label


def _panel(figure, state, reference, title):
    colour = "none" if figure.show == "network" else "rotation"
    values = rotation(state, reference[0]) if colour == "rotation" else None
    return Panel(state, colour, values, chains=figure.show in ("network", "both"), title=title, border=False)


def _since_text(figure, references):
    """The rotation reference of the figure's variants, in words."""
    if figure.show == "network" or not references:
        return ""
    cycles = [f"{f.cycle:.0f}" for _, (_, f) in references]
    where = (f"cycle {cycles[0]}" if len(set(cycles)) == 1 else
             "cycle " + ", ".join(f"{c} ({v})" for c, (v, _) in zip(cycles, references)))
    if figure.since:
        return f"since stage {figure.since} began (the last snapshot before: {where})"
    return f"since the first snapshot ({where})"


def snapshots_script(case, figure, store, workdir, png, svg):
    """A grid of frames (rows: variants, columns: frames from `first` to the last snapshot) as a
    PNG only (a vector grid of thousands of discs would weigh megabytes).  (script, notes)."""
    notes, rows, references = [], [], []
    siblings = Siblings(lambda other: store.get(case.name, other), case.ensemble_members())
    for variant in figure.variants:
        got = _variant_frames(case, figure, variant, store, notes)
        if got is None:
            continue
        run, found, reference = got
        start = 0
        if figure.first:
            try:
                cycle = evaluate(figure.first, run, siblings)
            except EvalError as problem:
                notes.append(f"{variant}: not drawn: {figure.first_label}: {problem}")
                continue
            start = found.index(nearest(found, cycle, lambda f: f.cycle))
        picks = sorted(set(int(round(k)) for k in np.linspace(start, len(found) - 1, figure.frames)))
        label = _label_at(figure, run, siblings, notes, variant)
        name = figure.names.get(variant, variant)
        row = []
        for n, k in enumerate(picks):
            state = frame_state(run.folder, found[k])
            head = f"{name}, cycle {found[k].cycle:.0f}"
            tail = label(found[k].cycle)
            if n == 0 and figure.first:
                tail = (tail + ", " if tail else "") + f"nearest {figure.first_label}"
            row.append(_panel(figure, state, reference, f"{head}\n{tail}" if tail else head))
        if reference:
            references.append((name, reference))
        rows.append(row)
    if not rows:
        return None, notes + ["nothing to draw"]
    s = scales([p for row in rows for p in row])
    title = "\n".join([figure.title] + scale_lines(s, rows[0][0].colour, _since_text(figure, references)))
    return page_script([rows], s, png, title, GRID_PANEL_PX), notes


def movie_script(case, figure, store, workdir, gif, svg):
    """An animated GIF: per snapshot (every `every`-th and the last), the variants side by side;
    a variant with fewer snapshots shows its last one to the end.  (script, notes)."""
    notes, runs, references = [], [], []
    siblings = Siblings(lambda other: store.get(case.name, other), case.ensemble_members())
    for variant in figure.variants:
        got = _variant_frames(case, figure, variant, store, notes)
        if got is None:
            continue
        run, found, reference = got
        name = figure.names.get(variant, variant)
        runs.append((name, run, chosen_frames(found, figure.every), reference,
                     _label_at(figure, run, siblings, notes, variant)))
        if reference:
            references.append((name, reference))
    if not runs:
        return None, notes + ["nothing to draw"]
    length = max(len(picked) for _, _, picked, _, _ in runs)
    pages = []
    for k in range(length):
        row = []
        for name, run, picked, reference, label in runs:
            frame = picked[min(k, len(picked) - 1)]
            tail = label(frame.cycle)
            head = f"{name}, cycle {frame.cycle:.0f}, time {frame.time:.4g}"
            row.append(_panel(figure, frame_state(run.folder, frame), reference,
                              f"{head}\n{tail}" if tail else head))
        pages.append([row])
    s = scales([p for page in pages for p in page[0]])
    title = "\n".join([figure.title] + scale_lines(s, pages[0][0][0].colour, _since_text(figure, references)))
    return page_script(pages, s, gif, title, MOVIE_PANEL_PX), notes


PLAYER = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>body{{font-family:system-ui,sans-serif;margin:1em 2em}} img{{max-width:100%;border:1px solid #ddd}}
#label{{font-family:monospace}}</style></head><body>
<h1>{title}</h1>
<p><button id="play" type="button">play</button>
<input id="slider" type="range" min="0" max="{last}" value="0" aria-label="frame">
<span id="label"></span></p>
<img id="frame" alt="a frame of the movie" src="{first}">
<script>
const frames = [{frames}];
const labels = [{labels}];
const img = document.getElementById("frame"), slider = document.getElementById("slider");
const label = document.getElementById("label"), button = document.getElementById("play");
let timer = null;
function show(k) {{ img.src = frames[k]; slider.value = k; label.textContent = labels[k]; }}
slider.addEventListener("input", () => show(Number(slider.value)));
button.addEventListener("click", () => {{
  if (timer) {{ clearInterval(timer); timer = null; button.textContent = "play"; return; }}
  button.textContent = "pause";
  timer = setInterval(() => show((Number(slider.value) + 1) % frames.length), {delay});
}});
show(0);
</script></body></html>
"""


def player(title, pngs, labels):
    """A self-contained HTML page showing the PNG frames with a slider and a play button."""
    uris = ["data:image/png;base64," + base64.b64encode(Path(p).read_bytes()).decode() for p in pngs]
    js = lambda s: '"' + s.replace("\\", "\\\\").replace('"', '\\"').replace("<", "\\u003c") + '"'
    return PLAYER.format(title=html.escape(title), last=len(uris) - 1, first=uris[0],
                         frames=",\n".join(js(u) for u in uris), labels=", ".join(js(t) for t in labels),
                         delay=MOVIE_DELAY * 10)
