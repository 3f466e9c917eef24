"""Biaxial compression tests of Jiang, Yu & Harris (2005), Sec. 5 (JYH): the stresses, strains
and friction angles of a specimen between four walls, from series.tsv, and the strength envelope
through the same material at several confining stresses (other variants of the case).

The columns a biaxial run writes (COLUMNS; probes of core/probes.c):

    fy_top, fy_bottom        wall_f2 of the top and bottom walls: the y force of the discs on them
    fx_left, fx_right        wall_f1 of the side walls: the x force
    y_top, y_bottom, x_left, x_right
                             the walls' positions (their point P; the walls are horizontal and
                             vertical lines, so these are the specimen's boundaries)

Stresses, force per unit length over a unit thickness, COMPRESSION POSITIVE:

    sigma_v = (|fy_top| + |fy_bottom|) / 2 / (x_right - x_left)
    sigma_h = (|fx_left| + |fx_right|) / 2 / (y_top - y_bottom)
    s = (sigma_v + sigma_h) / 2, t = (sigma_v - sigma_h) / 2
                             JYH Fig. 12's "mean stress" and Fig. 11's "deviatoric stress"
    sin phi = t / s          "sin phi = (sigma_v - sigma_h)/(sigma_v + sigma_h)" (JYH Sec. 5.2)

Shearing.  Every per-row function gives the rows of the shearing, from its reference row on:
the first row whose cycle is at or after the start of the stage named `shear` in run.json
"stages" (the cycles the stages before it ran, summed), or, with start='NAME', of that stage,
or, with start=CYCLE, the first row at or after that cycle.  The core writes the row of a
stage's last cycle when output_every divides it: then the reference row is the state at the
start of shearing exactly; otherwise it is the first row written during the shearing.

Strains, measured from the reference row, COMPRESSION POSITIVE (a negative volumetric strain
is dilation): with H = y_top - y_bottom and W = x_right - x_left,

    axial      eps_a = ln(H0 / H)     (natural, the default: JYH drive the test at a constant
                                       "ratio of change of specimen height to its current
                                       height", so eps_a grows at the constant rate)
    lateral    eps_h = ln(W0 / W)
    volumetric eps_a + eps_h          JYH Fig. 11(b)'s "(eps_v + eps_h)"; natural strains add,
                                      so this is ln(A0 / A) of the specimen's area exactly
    measure='engineering': (H0 - H) / H0 and (W0 - W) / W0 instead.

Peak and residual (JYH Figs 11-13):

    peak        the row (rows=N: the N consecutive rows) of the largest mobilised phi
    residual    the mean over the rows whose axial strain (natural) lies in [lo, hi]; the window
                must lie inside the strains the run reached and hold WINDOW_MIN_ROWS rows.
                residual_drift(lo, hi) shows whether phi has settled there: the mean of phi over
                the window's upper half less that over its lower half.

Envelope (JYH Fig. 12): the points (s, t) of several variants at their peak (or over the
residual window) and the least-squares line t = s sin phi + c cos phi through them; phi_envelope
gives phi (degrees), cohesion_envelope c ("apparent cohesion", in the stress unit).  A variant
argument written as a bare confining-stress token, '_s200', names the variant this expression
is evaluated in with its own `_s<digits>` part replaced ('m1_d0.4_s100' -> 'm1_d0.4_s200'), so
one quantity serves every material of a trend check.

The expression functions (every one takes start=None as above; the arrays are the shearing rows):

    sigma_v(), sigma_h(), mean_stress(), deviator(), phi()
    axial_strain(measure), lateral_strain(measure), volumetric_strain(measure)
    shear_start()                          the cycle of the reference row
    phi_peak(rows=1), peak_cycle(rows=1), at_peak(arr, rows=1)
    phi_residual(lo, hi), window_mean(arr, lo, hi), residual_drift(lo, hi)
    dilation()                             max eps_vol - last eps_vol
    phi_envelope(kind, v1, v2, ..., lo=None, hi=None, rows=1)
    cohesion_envelope(kind, v1, v2, ..., lo=None, hi=None, rows=1)
    setting(key)                           the number a --set KEY=VALUE of this run gave key
    strain_rate(stage='shear')             the rate of the stage's `strain_rate` line, as a --set
                                           of this run gave it (1/s)
    fastest_within(tol, expr, reference, names)
                                           the rate study (issue 33): of the ensembles `names`
                                           (the same test at several strain rates, one
                                           realisation per specimen), the fastest rate r such
                                           that at r and at every slower rate of the list the
                                           mean over the specimens of expr less expr in the same
                                           specimen of ensemble `reference` is within tol in
                                           magnitude: the cheapest rate that keeps expr within
                                           tol of the reference

The specimen's density, from the final state (discs.tsv) inside the walls of the last row of
series.tsv: the planar void ratio e = (W H - A_s) / A_s with A_s = pi sum r^2 (the overlaps of
a packing under load, ~1e-3 of a diameter, are not subtracted), W and H between the walls'
lines; and its profile over height, the same ratio in `bands` horizontal bands of equal
height, each disc's area clipped to the band exactly (circular segments):

    void_ratio()                           e of the whole specimen
    initial_void_ratio(start=None)         e with the walls of the shearing's reference row (the
                                           consolidated state; the disc areas do not change)
    void_ratios(bands=6)                   e of each band, bottom to top (an array)
    band_heights(bands=6)                  the bands' mid-heights over H, 0 to 1 (an array)

Anything missing or unusable (a column, the stage, too few rows, a window outside the data, an
envelope through variants that cannot make one) raises EvalError, so a check FAILs with it.
"""
import math
import re
from dataclasses import dataclass

import numpy as np

from ..compare import evaluate
from ..errors import EvalError
from ..expressions import ensemble_members, register, sibling_run
from ..final_state import state

COLUMNS = ("fy_top", "fy_bottom", "fx_left", "fx_right", "y_top", "y_bottom", "x_left", "x_right")
SHEAR_STAGE = "shear"         # the stage whose start is the reference row, unless start= says
MEASURES = ("natural", "engineering")
KINDS = ("peak", "residual")
MIN_ROWS = 2                  # a shearing has at least this many rows
WINDOW_MIN_ROWS = 4           # a residual window holds at least this many (two per half)
STRESS_TOKEN = re.compile(r"_s\d+(?=_|$)")   # the confining-stress part of a variant name


# ---------------------------------------------------------------- stresses and strains

def stresses(cols):
    """sigma_v, sigma_h per row (compression positive) from the wall forces and positions."""
    width = cols["x_right"] - cols["x_left"]
    height = cols["y_top"] - cols["y_bottom"]
    for name, size in (("x_right - x_left", width), ("y_top - y_bottom", height)):
        bad = np.flatnonzero(~(size > 0))
        if bad.size:
            raise EvalError(f"the specimen's {name} is {size[bad[0]]:g}, not positive, at cycle "
                            f"{cols['cycle'][bad[0]]:g}")
    sv = (np.abs(cols["fy_top"]) + np.abs(cols["fy_bottom"])) / 2 / width
    sh = (np.abs(cols["fx_left"]) + np.abs(cols["fx_right"])) / 2 / height
    return sv, sh


def strain(length, measure="natural"):
    """Compression-positive strain of a length from its first value: ln(L0/L) or (L0 - L)/L0."""
    if measure not in MEASURES:
        raise EvalError(f"measure must be one of {', '.join(MEASURES)}, not {measure!r}")
    if measure == "natural":
        return np.log(length[0] / length)
    return (length[0] - length) / length[0]


def mobilised(sv, sh, cycle):
    """The mobilised friction angle per row, degrees: sin phi = (sv - sh) / (sv + sh)."""
    s = sv + sh
    bad = np.flatnonzero(~(s > 0))
    if bad.size:
        raise EvalError(f"phi(): sigma_v + sigma_h is {s[bad[0]]:g}, not positive, at cycle "
                        f"{cycle[bad[0]]:g}: no stress on the walls")
    return np.degrees(np.arcsin(np.clip((sv - sh) / s, -1.0, 1.0)))


# ---------------------------------------------------------------- the start of the shearing

def stage_start(info, name):
    """The cycle at which stage `name` starts: the cycles of the stages before it (run.json)."""
    stages = info.get("stages")
    if not isinstance(stages, list) or not all(isinstance(g, dict) for g in stages):
        raise EvalError("run.json has no stages")
    names = [g.get("name") for g in stages]
    if name not in names:
        raise EvalError(f"run.json has no stage '{name}' (stages: {', '.join(map(str, names)) or 'none'}): "
                        f"name the shearing stage [stage {SHEAR_STAGE}], or give start='STAGE' or start=CYCLE")
    k = names.index(name)
    cycles = [g.get("cycles") for g in stages[:k + 1]]
    if not all(isinstance(c, int) and not isinstance(c, bool) and c >= 0 for c in cycles):
        raise EvalError(f"run.json: the stages up to '{name}' do not all give their cycles run")
    if cycles[-1] == 0:
        raise EvalError(f"stage '{name}' ran no cycles")
    return float(sum(cycles[:-1]))


def start_row(cycle, info, start=None):
    """Index of the reference row: the first row at or after the start of the shearing."""
    if start is None or isinstance(start, str):
        first = stage_start(info, SHEAR_STAGE if start is None else start)
    elif isinstance(start, (int, float)) and not isinstance(start, bool) and math.isfinite(start):
        first = float(start)
    else:
        raise EvalError(f"start must be a stage name or a cycle, not {start!r}")
    rows = np.flatnonzero(cycle >= first)
    if cycle.size - (rows[0] if rows.size else cycle.size) < MIN_ROWS:
        last = f"{cycle[-1]:g}" if cycle.size else "none"
        raise EvalError(f"fewer than {MIN_ROWS} rows at or after cycle {first:g}, the start of the "
                        f"shearing (last row: cycle {last})")
    return int(rows[0])


@dataclass
class Shearing:
    """The shearing rows of one run: cycle, sigma_v, sigma_h, height and width per row."""
    cycle: np.ndarray
    sv: np.ndarray
    sh: np.ndarray
    height: np.ndarray
    width: np.ndarray

    @property
    def s(self):
        return (self.sv + self.sh) / 2

    @property
    def t(self):
        return (self.sv - self.sh) / 2

    def phi(self):
        return mobilised(self.sv, self.sh, self.cycle)

    def axial(self, measure="natural"):
        return strain(self.height, measure)

    def lateral(self, measure="natural"):
        return strain(self.width, measure)

    def volumetric(self, measure="natural"):
        return self.axial(measure) + self.lateral(measure)


def shearing(columns, info, start=None):
    """The Shearing of a run's series columns and run.json."""
    missing = [c for c in COLUMNS if c not in columns]
    if missing:
        raise EvalError(f"column(s) missing from series.tsv: {', '.join(missing)} (a biaxial run "
                        f"writes {', '.join(COLUMNS)})")
    i = start_row(columns["cycle"], info, start)
    cols = {name: np.asarray(columns[name], dtype=float)[i:] for name in COLUMNS + ("cycle",)}
    sv, sh = stresses(cols)
    return Shearing(cols["cycle"], sv, sh, cols["y_top"] - cols["y_bottom"], cols["x_right"] - cols["x_left"])


# ---------------------------------------------------------------- peak and residual

def whole(value, fname, arg):
    """A whole-number argument (2 or 2.0, not 2.5)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not float(value).is_integer():
        raise EvalError(f"{fname}(): {arg} must be a whole number, not {value!r}")
    return int(value)


def peak_rows(phi, rows=1, fname="phi_peak"):
    """The rows (a slice) of the largest mean of phi over `rows` consecutive rows."""
    rows = whole(rows, fname, "rows")
    if not 1 <= rows <= phi.size:
        raise EvalError(f"{fname}(): rows must be 1 to {phi.size} (the shearing's rows), not {rows}")
    k = int(np.argmax(np.convolve(phi, np.ones(rows) / rows, mode="valid")))
    return slice(k, k + rows)


def window(eps, lo, hi, fname):
    """The rows whose axial strain lies in [lo, hi]: inside the data, at least WINDOW_MIN_ROWS."""
    if not lo < hi:
        raise EvalError(f"{fname}(): the window needs lo < hi, not [{lo:g}, {hi:g}]")
    if lo < eps.min() or hi > eps.max():
        raise EvalError(f"{fname}(): window [{lo:g}, {hi:g}] of axial strain outside the data "
                        f"(the shearing spans {eps.min():g} to {eps.max():g})")
    chosen = (eps >= lo) & (eps <= hi)
    if chosen.sum() < WINDOW_MIN_ROWS:
        raise EvalError(f"{fname}(): {int(chosen.sum())} row(s) in window [{lo:g}, {hi:g}], "
                        f"fewer than {WINDOW_MIN_ROWS}")
    return chosen


def drift(phi, eps, lo, hi):
    """Mean phi over the upper half [mid, hi] of the window less that over the lower [lo, mid)."""
    window(eps, lo, hi, "residual_drift")
    mid = (lo + hi) / 2
    lower, upper = phi[(eps >= lo) & (eps < mid)], phi[(eps >= mid) & (eps <= hi)]
    if lower.size < 2 or upper.size < 2:
        raise EvalError(f"residual_drift(): each half of window [{lo:g}, {hi:g}] needs two rows "
                        f"(has {lower.size} and {upper.size})")
    return float(upper.mean() - lower.mean())


def per_row(arr, test, fname):
    """arr as a float array of the shearing's rows (EvalError when it is not one)."""
    arr = np.asarray(arr, dtype=float)
    if arr.shape != test.cycle.shape:
        raise EvalError(f"{fname}(): the first argument must be a per-row array of the shearing "
                        f"({test.cycle.size} rows, e.g. mean_stress()), not of shape {arr.shape}")
    return arr


# ---------------------------------------------------------------- the strength envelope

def strength_point(test, kind, lo=None, hi=None, rows=1, fname="phi_envelope"):
    """(s, t) of one test at its peak or as the mean over the residual window."""
    if kind not in KINDS:
        raise EvalError(f"{fname}(): kind must be one of {', '.join(KINDS)}, not {kind!r}")
    if kind == "peak":
        if lo is not None or hi is not None:
            raise EvalError(f"{fname}(): a peak envelope takes no window (lo, hi)")
        chosen = peak_rows(test.phi(), rows, fname)
    else:
        if lo is None or hi is None:
            raise EvalError(f"{fname}(): a residual envelope needs its window: lo=..., hi=...")
        chosen = window(test.axial(), lo, hi, fname)
    return float(test.s[chosen].mean()), float(test.t[chosen].mean())


def envelope(points, fname="phi_envelope"):
    """(phi in degrees, c) of the least-squares line t = s sin phi + c cos phi through (s, t)."""
    s, t = np.array(points, dtype=float).reshape(-1, 2).T
    if s.size < 2 or not np.ptp(s) > 1e-12 * np.max(np.abs(s)):
        raise EvalError(f"{fname}(): needs two or more different mean stresses, has "
                        f"{', '.join(f'{x:g}' for x in s)}")
    slope, intercept = np.polyfit(s, t, 1)
    if not -1 < slope < 1:
        raise EvalError(f"{fname}(): the envelope's slope {slope:g} is no sine of an angle")
    angle = math.asin(slope)
    return math.degrees(angle), float(intercept / math.cos(angle))


def resolve(name, own):
    """A variant argument: a name, or a bare confining-stress token ('_s200') replacing the
    `_s<digits>` part of the variant the expression is evaluated in."""
    if not isinstance(name, str):
        raise EvalError(f"a variant must be a name in quotes, not {name!r}")
    if not STRESS_TOKEN.fullmatch(name):
        return name
    found = STRESS_TOKEN.findall(own or "")
    if len(found) != 1:
        raise EvalError(f"'{name}' replaces the confining-stress part '_s<digits>' of this variant's "
                        f"name, but '{own}' has {len(found)} such parts")
    return STRESS_TOKEN.sub(name, own)


def setting_of(info, key):
    """The number the last --set KEY=VALUE of run.json "sets" gave key."""
    sets = [s for s in info.get("sets") or [] if isinstance(s, str)]
    given = [s.split("=", 1)[1] for s in sets if s.split("=", 1)[0] == key and "=" in s]
    if not given:
        raise EvalError(f"setting(): the run has no --set {key}=... (its sets: {', '.join(sets) or 'none'})")
    try:
        return float(given[-1])
    except ValueError:
        raise EvalError(f"setting(): --set {key}={given[-1]} is not a number") from None


def rate_of(info, stage="shear"):
    """The rate of the last --set stage.STAGE.strain_rate=WALL RATE WALL_TO of run.json "sets"."""
    key = f"stage.{stage}.strain_rate"
    sets = [s for s in info.get("sets") or [] if isinstance(s, str)]
    given = [s.split("=", 1)[1] for s in sets if s.split("=", 1)[0] == key and "=" in s]
    if not given:
        raise EvalError(f"strain_rate(): the run has no --set {key}=WALL RATE WALL_TO")
    words = given[-1].split()
    try:
        return float(words[1])
    except (IndexError, ValueError):
        raise EvalError(f"strain_rate(): --set {key}={given[-1]} gives no rate (WALL RATE WALL_TO)") from None


def fastest_within_of(rates, errors, tol):
    """The largest rate r such that every rate <= r has |error| <= tol; None when the slowest
    rate's error is already beyond tol."""
    best = None
    for rate, error in sorted(zip(rates, errors)):
        if not abs(error) <= tol:
            break
        best = rate
    return best


# ---------------------------------------------------------------- the expression functions

# ---------------------------------------------------------------- the void ratio

def segment_below(y, yc, r):
    """The area of each disc (centre height yc, radius r) below the line at height y."""
    h = np.clip(y - (yc - r), 0.0, 2 * r)
    return r * r * np.arccos(np.clip((r - h) / r, -1.0, 1.0)) - (r - h) * np.sqrt(np.maximum(2 * r * h - h * h, 0.0))


def void_ratios_of(yc, r, box, bands):
    """(e of the box, [e per band, bottom to top]) of discs (yc, r) in box (x_left, x_right,
    y_bottom, y_top)."""
    xl, xr, yb, yt = box
    if not (xr > xl and yt > yb):
        raise EvalError(f"void ratio: the walls enclose no area (x {xl:g} to {xr:g}, y {yb:g} to {yt:g})")
    solid = math.pi * float(np.sum(r * r))
    if not solid > 0:
        raise EvalError("void ratio: no disc area")
    edges = np.linspace(yb, yt, bands + 1)
    per = []
    for lo, hi in zip(edges[:-1], edges[1:]):
        s = float(np.sum(segment_below(hi, yc, r) - segment_below(lo, yc, r)))
        if not s > 0:
            raise EvalError(f"void ratio: band {lo:g} to {hi:g} holds no disc")
        per.append(((xr - xl) * (hi - lo) - s) / s)
    return ((xr - xl) * (yt - yb) - solid) / solid, np.array(per)


NAMES = ("sigma_v", "sigma_h", "mean_stress", "deviator", "phi", "axial_strain", "lateral_strain",
         "volumetric_strain", "shear_start", "phi_peak", "peak_cycle", "at_peak", "phi_residual",
         "window_mean", "residual_drift", "dilation", "phi_envelope", "cohesion_envelope", "setting",
         "void_ratio", "void_ratios", "band_heights", "initial_void_ratio", "strain_rate", "fastest_within")


def bind(run, sibling=None):
    """The family's functions, bound to run (and, for the envelopes, its siblings)."""
    own = run.folder.name if run.folder is not None else None

    def specimen(start=None, of=run):
        return shearing(of.columns, of.info, start)

    def points(kind, variants, lo, hi, rows, start, fname):
        if len(variants) < 2:
            raise EvalError(f"{fname}(): needs two or more variants, has {len(variants)}")
        names = [resolve(v, own) for v in variants]
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise EvalError(f"{fname}(): variant(s) {', '.join(twice)} named twice")
        out = []
        for name in names:
            other = run if name == own else sibling_run(sibling, name, fname)
            try:
                out.append(strength_point(specimen(start, other), kind, lo, hi, rows, fname))
            except EvalError as exc:
                raise EvalError(f"{fname}(): variant '{name}': {exc}") from None
        return out

    def sigma_v(start=None):
        """sigma_v per row (JYH Sec. 5.1: "vertical stress value sigma_v on boundary")."""
        return specimen(start).sv

    def sigma_h(start=None):
        """sigma_h per row, the confining stress JYH hold constant."""
        return specimen(start).sh

    def mean_stress(start=None):
        """s = (sigma_v + sigma_h) / 2, JYH Fig. 12's "mean stress"."""
        return specimen(start).s

    def deviator(start=None):
        """t = (sigma_v - sigma_h) / 2, JYH Fig. 11(a)'s "deviatoric stress"."""
        return specimen(start).t

    def phi(start=None):
        """The mobilised angle per row, degrees: sin phi = (sigma_v - sigma_h)/(sigma_v + sigma_h)."""
        return specimen(start).phi()

    def axial_strain(measure="natural", start=None):
        """eps_a = ln(H0/H) (or (H0 - H)/H0), compression positive."""
        return specimen(start).axial(measure)

    def lateral_strain(measure="natural", start=None):
        """eps_h = ln(W0/W) (or (W0 - W)/W0), compression positive."""
        return specimen(start).lateral(measure)

    def volumetric_strain(measure="natural", start=None):
        """eps_a + eps_h (JYH Fig. 11(b)), compression positive: negative is dilation."""
        return specimen(start).volumetric(measure)

    def shear_start(start=None):
        """The cycle of the reference row."""
        return float(specimen(start).cycle[0])

    def phi_peak(rows=1, start=None):
        """The peak friction angle: the largest phi (mean over `rows` consecutive rows)."""
        angles = specimen(start).phi()
        return float(angles[peak_rows(angles, rows, "phi_peak")].mean())

    def peak_cycle(rows=1, start=None):
        """The cycle of the peak (the middle row of the `rows` rows)."""
        t = specimen(start)
        chosen = peak_rows(t.phi(), rows, "peak_cycle")
        return float(t.cycle[(chosen.start + chosen.stop - 1) // 2])

    def at_peak(arr, rows=1, start=None):
        """A per-row array's value at the peak (its mean over the peak's rows)."""
        t = specimen(start)
        return float(per_row(arr, t, "at_peak")[peak_rows(t.phi(), rows, "at_peak")].mean())

    def phi_residual(lo, hi, start=None):
        """The residual friction angle: the mean phi over the rows with lo <= eps_a <= hi."""
        t = specimen(start)
        return float(t.phi()[window(t.axial(), lo, hi, "phi_residual")].mean())

    def window_mean(arr, lo, hi, start=None):
        """A per-row array's mean over the rows with lo <= eps_a <= hi."""
        t = specimen(start)
        return float(per_row(arr, t, "window_mean")[window(t.axial(), lo, hi, "window_mean")].mean())

    def residual_drift(lo, hi, start=None):
        """phi's mean over the window's upper half less its mean over the lower half (degrees):
        about zero once the residual state is reached."""
        t = specimen(start)
        return drift(t.phi(), t.axial(), lo, hi)

    def dilation(start=None):
        """max eps_vol - last eps_vol: how far the specimen dilated after its largest compression
        (JYH Fig. 11: "strain-softening and shear-dilant behaviour")."""
        eps = specimen(start).volumetric()
        return float(eps.max() - eps[-1])

    def phi_envelope(kind, *variants, lo=None, hi=None, rows=1, start=None):
        """phi (degrees) of the least-squares envelope t = s sin phi + c cos phi (JYH Fig. 12)."""
        return envelope(points(kind, variants, lo, hi, rows, start, "phi_envelope"), "phi_envelope")[0]

    def cohesion_envelope(kind, *variants, lo=None, hi=None, rows=1, start=None):
        """c, the envelope's "apparent cohesion" (JYH Sec. 5.2), in the stress unit."""
        return envelope(points(kind, variants, lo, hi, rows, start, "cohesion_envelope"), "cohesion_envelope")[1]

    def setting(key):
        """The number a --set KEY=VALUE of this run gave key (e.g. a material's delta)."""
        return setting_of(run.info, key)

    def strain_rate(stage="shear"):
        """The strain rate this run's --set gave the stage (1/s)."""
        return rate_of(run.info, stage)

    def fastest_within(tol, expr, reference, names):
        """The cheapest rate of the study within tol of the reference (module docstring)."""
        if isinstance(names, str) or not isinstance(names, (list, tuple)) or not names:
            raise EvalError("fastest_within(): names must be a list of ensembles, e.g. ['m0_rate0.5', ...]")
        if not (isinstance(tol, (int, float)) and tol >= 0):
            raise EvalError(f"fastest_within(): tol must be a number >= 0, not {tol!r}")

        def value(variant):
            try:
                return float(evaluate(expr, sibling_run(sibling, variant, "fastest_within"), sibling))
            except EvalError as exc:
                raise EvalError(f"fastest_within(): '{variant}': {exc}") from None

        base = {v[len(reference) + 2:]: value(v) for v in ensemble_members(sibling, reference, "fastest_within")}
        rates, errors = [], []
        for name in names:
            members = ensemble_members(sibling, name, "fastest_within")
            seeds = [v[len(name) + 2:] for v in members]
            if sorted(seeds) != sorted(base):
                raise EvalError(f"fastest_within(): ensembles '{name}' and '{reference}' have different seeds")
            ratesof = {rate_of(sibling_run(sibling, v, "fastest_within").info) for v in members}
            if len(ratesof) != 1:
                raise EvalError(f"fastest_within(): the realisations of '{name}' have different strain rates")
            rates.append(ratesof.pop())
            errors.append(float(np.mean([value(v) - base[k] for v, k in zip(members, seeds)])))
        if len(set(rates)) != len(rates):
            raise EvalError("fastest_within(): two ensembles have the same strain rate")
        best = fastest_within_of(rates, errors, tol)
        if best is None:
            raise EvalError(f"fastest_within(): even the slowest rate, {min(rates):g} /s, is beyond {tol:g} "
                            "of the reference")
        return best

    def density(bands):
        bands = whole(bands, "void_ratios", "bands")
        if not 1 <= bands <= 100:
            raise EvalError(f"void_ratios(): bands must be 1 to 100, not {bands}")
        missing = [c for c in ("x_left", "x_right", "y_bottom", "y_top") if c not in run.columns]
        if missing or not len(run.columns["cycle"]):
            raise EvalError(f"void ratio: series.tsv lacks the walls' positions ({', '.join(missing) or 'no rows'})")
        box = tuple(float(run.columns[c][-1]) for c in ("x_left", "x_right", "y_bottom", "y_top"))
        d = state(run).discs()
        return void_ratios_of(d["y"], d["r"], box, bands)

    def void_ratio():
        """The planar void ratio of the final state: (area inside the walls - disc area) / disc area."""
        return float(density(1)[0])

    def initial_void_ratio(start=None):
        """The planar void ratio at the start of the shearing (its reference row's walls)."""
        t = specimen(start)
        r = state(run).discs()["r"]
        solid = math.pi * float(np.sum(r * r))
        return float((t.width[0] * t.height[0] - solid) / solid)

    def void_ratios(bands=6):
        """The void ratio of `bands` horizontal bands of equal height, bottom to top."""
        return density(bands)[1]

    def band_heights(bands=6):
        """The mid-heights of the bands of void_ratios(bands), over the specimen's height."""
        bands = whole(bands, "band_heights", "bands")
        if not 1 <= bands <= 100:
            raise EvalError(f"band_heights(): bands must be 1 to 100, not {bands}")
        return (np.arange(bands) + 0.5) / bands

    return {"void_ratio": void_ratio, "initial_void_ratio": initial_void_ratio, "void_ratios": void_ratios, "band_heights": band_heights,
            "sigma_v": sigma_v, "sigma_h": sigma_h, "mean_stress": mean_stress, "deviator": deviator,
            "phi": phi, "axial_strain": axial_strain, "lateral_strain": lateral_strain,
            "volumetric_strain": volumetric_strain, "shear_start": shear_start, "phi_peak": phi_peak,
            "peak_cycle": peak_cycle, "at_peak": at_peak, "phi_residual": phi_residual,
            "window_mean": window_mean, "residual_drift": residual_drift, "dilation": dilation,
            "phi_envelope": phi_envelope, "cohesion_envelope": cohesion_envelope, "setting": setting,
            "strain_rate": strain_rate, "fastest_within": fastest_within}


register("biaxial", NAMES, bind)
