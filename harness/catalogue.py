"""The case catalogue: cases/<family>/case.txt read into Case, Variant and Figure objects.

A case.txt holds one or more [case NAME] sections; the [variant] and [figure] sections
after a [case] belong to it.  load() reads every family folder (sorted by name, cases in
file order) and validates names, tiers and references between sections; select() picks
cases by name or by tier.

Figure kinds (`kind = ...`, default series) and their keys (FIGURE_KIND_KEYS; every kind
takes kind, title, variants and paper; variants default to all of the case's):

    series     series.tsv columns against a column:  x = COLUMN, y = COLUMN ...,
               xlabel, ylabel, xrange, yrange; and reference lines, repeatable:
               line = SLOPE INTERCEPT [TITLE] draws y = SLOPE x + INTERCEPT dashed
               (a line without a title is drawn like the one before it: +-M pairs)
    network    the force network of one variant's final state (C&S Fig. 5(b));
               exactly one variant
    profile    pile_S(component, row) against pile_X(row) per variant (MLH Figs 3, 6, 7):
               y = COMPONENT ... (xx zz xz max min phi ratio), row = M (default 1),
               xlabel, ylabel, xrange, yrange
    principal  the principal axes of the stress of every free disc of one variant's final
               state (MLH Fig. 3(d)); exactly one variant
    points     one point per variant at (x, y), joined in the order listed and labelled
               with the variant's name (error against cost): x = EXPR, y = EXPR (quantity
               expressions, as in reference/*.ref), logscale = xy | x | y | (empty: none),
               xlabel, ylabel, xrange, yrange
    curves     per variant, a curve of array expressions (JYH Fig. 11): x = EXPR,
               y = [LABEL;] EXPR (repeatable: one curve each), xlabel, ylabel, xrange, yrange
    errorbars  per variant a point (x, y) of quantity expressions; the variants that share an x
               make one point at the mean of their y with a bar from its least to its largest
               (the spread between specimens, JYH Fig. 13): x = EXPR, y = [LABEL;] EXPR
               (repeatable: one series each), paper_point = X Y LABEL (repeatable: a published
               value drawn beside, one legend entry per LABEL), xlabel, ylabel, xrange, yrange
    fit        per group of variants, the points (x, y) of its variants and their least-squares
               line (strength envelopes, JYH Fig. 12): group = LABEL; VARIANT VARIANT ...
               (repeatable, two or more variants each; no `variants` key), x = [LABEL;] EXPR
               and y = [LABEL;] EXPR (repeatable, paired in order: one line per pair and group),
               slope = number | asin (the legend gives the slope, or the angle whose sine it is),
               xlabel, ylabel, xrange, yrange
    snapshots  frames of the variants' snapshots drawn to scale (harness/pictures.py), one row
               per variant, one column per frame: show = network (force chains on grey discs)
               | rotation (discs coloured by their rotation) | both; first = [LABEL;] EXPR (a
               cycle: the first frame is the snapshot nearest it; default the first snapshot);
               frames = N (default 4: from the first frame to the last snapshot, evenly spread);
               since = STAGE (rotation since the last snapshot at or before the stage's first
               cycle; default the first snapshot); label = NAME; EXPR (an array expression over
               the last rows of series.tsv, as the biaxial family's per-row functions give:
               its value at each frame's cycle, interpolated, heads the panel)
    movie      an animated GIF of every snapshot of its variants, side by side: show, since and
               label as for snapshots; every = K (every K-th snapshot and the last; default 1)

A key that the figure's kind does not use is an error, as is an unknown kind.
[sweep NAME] sections declare the case's error-against-cost sweeps (keys in sweep_spec.py).
[ensemble NAME] sections declare many realisations of one scene, one variant per seed, named
NAME_s<seed> (ensembles.py); a figure's `variants` may name an ensemble for all of them.
"""
import ast
import math
import re
from dataclasses import dataclass, field, replace
from pathlib import Path

from . import TIERS, cases_root
from . import ensembles
from .errors import CatalogueError, IniError, shown
from .families.piles import COMPONENTS
from .ini import parse_file
from .sweep_spec import parse as parse_sweep

CASE_KEYS = {"tier", "title", "checks", "runtime", "stability"}
VARIANT_KEYS = {"scene", "set", "command", "label"}
COMMANDS = ("run", "exact", "peer", "peer_rolling")
FIGURE_KINDS = ("series", "network", "profile", "principal", "points", "curves", "errorbars", "fit",
                "snapshots", "movie")
_COMMON = {"kind", "title", "variants", "paper"}
_AXES = {"xlabel", "ylabel", "xrange", "yrange"}
FIGURE_KIND_KEYS = {
    "series": _COMMON | _AXES | {"x", "y", "line", "reference"},
    "network": _COMMON,
    "profile": _COMMON | _AXES | {"y", "row"},
    "principal": _COMMON,
    "points": _COMMON | _AXES | {"x", "y", "logscale"},
    "curves": _COMMON | _AXES | {"x", "y"},
    "errorbars": _COMMON | _AXES | {"x", "y", "paper_point"},
    "fit": (_COMMON - {"variants"}) | _AXES | {"group", "x", "y", "slope"},
    "snapshots": _COMMON | {"show", "first", "frames", "since", "label"},
    "movie": _COMMON | {"show", "since", "label", "every"},
}
SHOWS = ("network", "rotation", "both")   # snapshots, movie: chains on grey discs, discs coloured by rotation, both
SLOPES = ("number", "asin")
FIGURE_KEYS = set().union(*FIGURE_KIND_KEYS.values())
LOGSCALES = {"": "", "x": "x", "y": "y", "xy": "xy", "yx": "xy"}
PROFILE_XLABEL = "X = (x - x0) / l (-)"
PROFILE_YLABEL = "S (compression positive, units m g / l)"
NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
RANGE = re.compile(rf"^\s*({NUMBER})?\s*:\s*({NUMBER})?\s*$")


@dataclass
class Variant:
    name: str
    scene: Path
    sets: list
    command: str = "run"     # run: the DEM; exact: the exact static solver (ballast exact);
                             # peer: the cross-check against LAMMPS (harness/peer/check.py);
                             # peer_rolling: JYH's rolling against LAMMPS (harness/peer/rolling.py)
    ensemble: str = ""       # a realisation of [ensemble NAME]: NAME (and its seed); '' otherwise
    seed: int = None
    label: str = ""          # what a figure's legend calls it ('' : its name)


@dataclass
class Figure:
    name: str
    title: str
    variants: list
    x: str
    y: list
    xlabel: str
    ylabel: str
    xrange: str = ""         # gnuplot range 'lo:hi' (either side may be empty); '' = automatic
    yrange: str = ""
    line: int = 0
    kind: str = "series"     # one of FIGURE_KINDS (see the module docstring)
    paper: str = ""          # the paper's words the figure reproduces, shown beside it
    row: int = 1             # profile: the pile row M of S(M)
    logscale: str = ""       # points: '', 'x', 'y' or 'xy'
    lines: list = field(default_factory=list)   # series: (slope, intercept, title) reference lines
    labels: list = field(default_factory=list)   # curves, errorbars, fit: the legend label of each y
    xs: list = field(default_factory=list)       # fit: the x expression paired with each y
    groups: list = field(default_factory=list)   # fit: (label, [variants]) per group
    paper_points: list = field(default_factory=list)   # errorbars: (x, y, label) published values
    slope: str = "number"    # fit: how the legend gives a line's slope (SLOPES)
    names: dict = field(default_factory=dict)   # variant -> its legend label (the variants' `label`)
    references: list = field(default_factory=list)   # series: checks whose reference value is drawn
    show: str = ""           # snapshots, movie: one of SHOWS
    first: str = ""          # snapshots: the expression of the first frame's cycle ('' : the first snapshot)
    first_label: str = ""    # snapshots: what that cycle is ('the peak of phi')
    frames: int = 0          # snapshots: how many frames per variant
    since: str = ""          # snapshots, movie: the stage the rotation is counted from ('' : the first snapshot)
    label: str = ""          # snapshots, movie: the name of the panels' label quantity
    label_expr: str = ""     # snapshots, movie: its array expression over the last rows of series.tsv
    every: int = 1           # movie: every K-th snapshot


@dataclass
class Case:
    name: str
    family: str
    folder: Path
    tier: str
    title: str
    checks: str
    runtime: float
    stability: bool = True   # `stability = no`: its variants have no time-step limit to find
                             # (held bodies, prescribed motion), so the stability finder skips them
    path: str = ""
    line: int = 0
    variants: list = field(default_factory=list)
    figures: list = field(default_factory=list)
    sweeps: list = field(default_factory=list)     # [sweep NAME] sections as sweep_spec.Sweep (error against cost)
    ensembles: list = field(default_factory=list)  # [ensemble NAME] sections as ensembles.Ensemble

    @property
    def source(self):
        """'file:line' of the [case] header."""
        return f"{shown(self.path)}:{self.line}"

    def variant(self, name):
        """The variant called name, or None."""
        return next((v for v in self.variants if v.name == name), None)

    def variant_names(self):
        return [v.name for v in self.variants]

    def ensemble(self, name):
        """The [ensemble] called name, or None."""
        return next((e for e in self.ensembles if e.name == name), None)

    def ensemble_members(self):
        """{ensemble name: its realisations' variant names, in seed order}."""
        return {e.name: list(e.members) for e in self.ensembles}

    def variant_summary(self):
        """The variants in a few words: plain ones by name, an ensemble as NAME_s[seeds]."""
        words, shown_ensembles = [], set()
        for v in self.variants:
            if not v.ensemble:
                words.append(v.name)
            elif v.ensemble not in shown_ensembles:
                shown_ensembles.add(v.ensemble)
                words.append(f"{v.ensemble}_s[{ensembles.seeds_text(self.ensemble(v.ensemble).seeds)}]")
        return " ".join(words)


def tier_rank(tier):
    """quick < standard < full."""
    return TIERS.index(tier)


def load(root=None):
    """Every case of the catalogue, in order (families sorted, cases in file order)."""
    root = Path(root or cases_root())
    cases, seen = [], {}
    for path in sorted(root.glob("*/case.txt")):
        for case in load_file(path):
            if case.name in seen:
                raise IniError(case.path, case.line, f"case '{case.name}' already defined at {seen[case.name]}")
            seen[case.name] = case.source
            cases.append(case)
    return cases


def load_file(path):
    """The cases of one case.txt."""
    cases = []
    for section in parse_file(path):
        if section.kind == "case":
            cases.append(_case(section, Path(path)))
        elif not cases:
            raise section.error(f"[{section.kind} {section.name}] comes before any [case]")
        elif section.kind == "variant":
            _add_variant(cases[-1], section)
        elif section.kind == "figure":
            _add_figure(cases[-1], section)
        elif section.kind == "sweep":
            cases[-1].sweeps.append(parse_sweep(section))
        elif section.kind == "ensemble":
            _add_ensemble(cases[-1], section)
        else:
            raise section.error(f"unknown section kind '{section.kind}' "
                                "(known: case, variant, ensemble, figure, sweep)")
    for case in cases:
        _finish(case)
    return cases


def _case(section, path):
    section.check_keys(CASE_KEYS)
    tier = section.require("tier")
    if tier not in TIERS:
        raise section.error(f"tier must be one of {', '.join(TIERS)}, not '{tier}'", section.entry("tier").line)
    runtime = section.number("runtime")
    if runtime is None:
        raise section.error("[case] needs 'runtime = <expected seconds>'")
    stability = section.get("stability", "yes")
    if stability not in ("yes", "no"):
        raise section.error(f"stability must be yes or no, not '{stability}'",
                            section.entry("stability").line)
    return Case(name=section.name, family=path.parent.name, folder=path.parent, tier=tier,
                title=section.require("title"), checks=section.require("checks"),
                runtime=runtime, stability=stability == "yes", path=section.path,
                line=section.line)


def _add_variant(case, section):
    section.check_keys(VARIANT_KEYS)
    _not_an_ensembles_name(case, section, section.name)
    if case.variant(section.name):
        raise section.error(f"variant '{section.name}' defined twice in case '{case.name}'")
    for entry in section.all("set"):
        if "=" not in entry.value:
            raise section.error(f"'set' needs KEY=VALUE, got '{entry.value}'", entry.line)
    sets = [e.value for e in section.all("set")]
    command = section.get("command", "run")
    if command not in COMMANDS:
        raise section.error(f"command must be one of {', '.join(COMMANDS)}, not '{command}'")
    case.variants.append(Variant(section.name, case.folder / section.require("scene"), sets, command,
                                 label=section.get("label", "")))


def _not_an_ensembles_name(case, section, name):
    """A plain variant's or a new ensemble's name must not be an ensemble's, nor one it keeps
    for its realisations (NAME_s<digits>)."""
    for ens in case.ensembles:
        where = f"ensemble '{ens.name}' ({shown(ens.path)}:{ens.line})"
        if name == ens.name:
            raise section.error(f"'{name}' is already the name of {where}")
        if ensembles.claims(ens.name, name):
            raise section.error(f"'{name}' is a name {where} keeps for its realisations ({ens.name}_s<seed>)")


def _add_ensemble(case, section):
    """[ensemble NAME]: one variant per seed, NAME_s<seed> (ensembles.py)."""
    _not_an_ensembles_name(case, section, section.name)
    for variant in case.variants:
        if variant.name == section.name or ensembles.claims(section.name, variant.name):
            raise section.error(f"ensemble '{section.name}' would name its realisations {section.name}_s<seed>, "
                                f"but the case already has a variant '{variant.name}'")
    ens = ensembles.parse(section)
    case.ensembles.append(ens)
    for seed in ens.seeds:
        name, scene, sets = ens.realisation(seed)
        case.variants.append(Variant(name, case.folder / scene, sets, ens.command, ens.name, seed))


def _add_figure(case, section):
    section.check_keys(FIGURE_KEYS)
    if any(f.name == section.name for f in case.figures):
        raise section.error(f"figure '{section.name}' defined twice in case '{case.name}'")
    kind = section.get("kind", "series")
    if kind not in FIGURE_KINDS:
        raise section.error(f"figure kind must be one of {', '.join(FIGURE_KINDS)}, not '{kind}'")
    allowed = FIGURE_KIND_KEYS[kind]
    for e in section.entries:
        if e.key not in allowed:
            raise section.error(f"'{e.key}' does not apply to a {kind} figure "
                                f"(its keys: {', '.join(sorted(allowed))})", e.line)
    common = dict(name=section.name, title=section.get("title", section.name), line=section.line,
                  kind=kind, paper=" ".join(e.value for e in section.all("paper")))
    case.figures.append(FIGURE_MAKERS[kind](section, common))


def _one_variant(section, common):
    """network and principal: exactly one variant, no axes."""
    variants = section.require("variants").split()
    if len(variants) != 1:
        raise section.error(f"a {common['kind']} figure shows exactly one variant")
    return Figure(variants=variants, x="", y=[], xlabel="", ylabel="", **common)


def _series(section, common):
    return Figure(variants=section.get("variants", "").split(), x=section.require("x"),
                  y=section.require("y").split(), xlabel=section.get("xlabel", section.require("x")),
                  ylabel=section.get("ylabel", ""), xrange=_range(section, "xrange"),
                  yrange=_range(section, "yrange"), lines=[_line(section, e) for e in section.all("line")],
                  references=[w for e in section.all("reference") for w in e.value.split()],
                  **common)


def _line(section, entry):
    """A reference line 'SLOPE INTERCEPT [TITLE]': (slope, intercept, title), both numbers finite."""
    words = entry.value.split(None, 2)
    try:
        slope, intercept = (float(w) for w in words[:2])
        if not math.isfinite(slope) or not math.isfinite(intercept):
            raise ValueError
    except ValueError:
        raise section.error(f"'line' must be 'SLOPE INTERCEPT [title]' (two finite numbers first), "
                            f"not '{entry.value}'", entry.line) from None
    return slope, intercept, words[2] if len(words) > 2 else ""


def _profile(section, common):
    components = section.require("y").split()
    for c in components:
        if c not in COMPONENTS:
            raise section.error(f"profile component must be one of {', '.join(COMPONENTS)}, not '{c}'",
                                section.entry("y").line)
    row = section.number("row", 1.0)
    if not row.is_integer() or row < 0:
        raise section.error(f"'row' must be a pile row number (0, 1, 2, ...), not '{section.get('row')}'",
                            section.entry("row").line)
    return Figure(variants=section.get("variants", "").split(), x="", y=components,
                  xlabel=section.get("xlabel", PROFILE_XLABEL), ylabel=section.get("ylabel", PROFILE_YLABEL),
                  xrange=_range(section, "xrange"), yrange=_range(section, "yrange"), row=int(row), **common)


def _expression(section, key):
    """A quantity expression (syntax checked here, so the error names file:line)."""
    text = section.require(key)
    try:
        ast.parse(text, mode="eval")
    except SyntaxError as exc:
        raise section.error(f"'{key}' is not an expression: {exc.msg}", section.entry(key).line) from None
    return text


def _points(section, common):
    x, y = _expression(section, "x"), _expression(section, "y")
    logscale = section.get("logscale", "")
    if logscale not in LOGSCALES:
        raise section.error(f"'logscale' must be xy, x, y or empty, not '{logscale}'", section.entry("logscale").line)
    return Figure(variants=section.get("variants", "").split(), x=x, y=[y], xlabel=section.get("xlabel", x),
                  ylabel=section.get("ylabel", y), xrange=_range(section, "xrange"),
                  yrange=_range(section, "yrange"), logscale=LOGSCALES[logscale], **common)


def _labelled(section, key):
    """Every `key = [LABEL;] EXPR` of the section: (labels, expressions), the label defaulting to
    the expression; at least one.  A quantity never holds ';', so the first one ends the label."""
    entries = section.all(key)
    if not entries:
        raise section.error(f"[{section.kind} {section.name}] needs '{key} = [LABEL;] EXPR'")
    labels, exprs = [], []
    for e in entries:
        label, sep, text = e.value.partition(";")
        label, text = (label.strip(), text.strip()) if sep else ("", label.strip())
        if not text:
            raise section.error(f"'{key}' is empty", e.line)
        try:
            ast.parse(text, mode="eval")
        except SyntaxError as exc:
            raise section.error(f"'{key}' is not an expression: {exc.msg}", e.line) from None
        labels.append(label or text)
        exprs.append(text)
    return labels, exprs


def _axes(section, x, ylabel):
    """The axis keys of the expression kinds."""
    return dict(xlabel=section.get("xlabel", x), ylabel=section.get("ylabel", ylabel),
                xrange=_range(section, "xrange"), yrange=_range(section, "yrange"))


def _curves(section, common):
    x = _expression(section, "x")
    labels, ys = _labelled(section, "y")
    return Figure(variants=section.get("variants", "").split(), x=x, y=ys, labels=labels,
                  **_axes(section, x, ", ".join(labels)), **common)


def _errorbars(section, common):
    x = _expression(section, "x")
    labels, ys = _labelled(section, "y")
    published = []
    for e in section.all("paper_point"):
        words = e.value.split(None, 2)
        try:
            published.append((float(words[0]), float(words[1]), words[2]))
        except (ValueError, IndexError):
            raise section.error(f"'paper_point' must be 'X Y LABEL' (two numbers, then the legend), "
                                f"not '{e.value}'", e.line) from None
    return Figure(variants=section.get("variants", "").split(), x=x, y=ys, labels=labels,
                  paper_points=published, **_axes(section, x, ", ".join(labels)), **common)


def _fit(section, common):
    groups = []
    for e in section.all("group"):
        label, sep, names = e.value.partition(";")
        if not sep or not label.strip() or len(names.split()) < 2:
            raise section.error(f"'group' must be 'LABEL; VARIANT VARIANT ...' (two or more variants), "
                                f"not '{e.value}'", e.line)
        groups.append((label.strip(), names.split()))
    if not groups:
        raise section.error(f"[figure {section.name}] needs 'group = LABEL; VARIANT VARIANT ...'")
    _, xs = _labelled(section, "x")
    labels, ys = _labelled(section, "y")
    if len(xs) != len(ys):
        raise section.error(f"a fit figure pairs each 'x' with a 'y': it has {len(xs)} x and {len(ys)} y")
    slope = section.get("slope", "number")
    if slope not in SLOPES:
        raise section.error(f"'slope' must be one of {', '.join(SLOPES)}, not '{slope}'", section.entry("slope").line)
    variants = list(dict.fromkeys(v for _, names in groups for v in names))
    return Figure(variants=variants, x=xs[0], y=ys, labels=labels, xs=xs, groups=groups, slope=slope,
                  **_axes(section, xs[0], ys[0]), **common)


def _snapshots(section, common):
    """snapshots and movie: the frames of the variants' snapshots (harness/pictures.py)."""
    show = section.get("show", "network" if common["kind"] == "snapshots" else "both")
    if show not in SHOWS:
        raise section.error(f"'show' must be one of {', '.join(SHOWS)}, not '{show}'", section.entry("show").line)
    out = Figure(variants=section.get("variants", "").split(), x="", y=[], xlabel="", ylabel="", show=show,
                 since=section.get("since", ""), **common)
    for key, least, default in (("frames", 1, 4), ("every", 1, 1)):
        value = section.number(key, float(default))
        if not value.is_integer() or value < least:
            raise section.error(f"'{key}' must be a whole number, {least} or more, not '{section.get(key)}'",
                                section.entry(key).line)
        setattr(out, key, int(value))
    if section.entry("first"):
        (out.first_label,), (out.first,) = _labelled(section, "first")
    if section.entry("label"):
        (out.label,), (out.label_expr,) = _labelled(section, "label")
    return out


FIGURE_MAKERS = {"series": _series, "network": _one_variant, "profile": _profile,
                 "principal": _one_variant, "points": _points, "curves": _curves,
                 "errorbars": _errorbars, "fit": _fit, "snapshots": _snapshots, "movie": _snapshots}


def _range(section, key):
    """An optional axis range 'lo:hi' (numbers; either may be omitted), normalised."""
    entry = section.entry(key)
    if entry is None:
        return ""
    match = RANGE.match(entry.value)
    if not match:
        raise section.error(f"'{key}' must be 'lo:hi' (numbers, either may be empty), not '{entry.value}'", entry.line)
    return f"{match.group(1) or ''}:{match.group(2) or ''}"


def _finish(case):
    """Whole-case checks: at least one variant; figures name existing variants (an ensemble's
    name stands for its realisations)."""
    if not case.variants:
        raise IniError(case.path, case.line, f"case '{case.name}' has no [variant] or [ensemble]")
    members = case.ensemble_members()
    for figure in case.figures:
        figure.variants = [v for name in figure.variants for v in members.get(name, [name])]
        if figure.kind in ("network", "principal") and len(figure.variants) != 1:
            raise IniError(case.path, figure.line, f"a {figure.kind} figure shows exactly one variant, "
                           f"not the {len(figure.variants)} realisations of an ensemble")
        for name in figure.variants:
            if not case.variant(name):
                raise IniError(case.path, figure.line,
                               f"figure '{figure.name}' names unknown variant '{name}'")
        figure.variants = figure.variants or case.variant_names()
        figure.names = {v.name: v.label for v in case.variants if v.label}


def ensembles_of(cases):
    """{case name: {ensemble name: its realisations' variant names}} of the cases that declare
    ensembles (for compare.RunStore: the expression functions over an ensemble)."""
    return {c.name: c.ensemble_members() for c in cases if c.ensembles}


def first_realisations(cases, n):
    """The cases with each [ensemble] cut to its first n seeds, its other realisations dropped
    from the variants (0: all of them): the agreement matrix's REALISATIONS."""
    if not n:
        return cases
    out = []
    for case in cases:
        if not case.ensembles:
            out.append(case)
            continue
        keep = {name for e in case.ensembles for name in e.members[:n]}
        cut = [replace(e, seeds=e.seeds[:n], members=e.members[:n]) for e in case.ensembles]
        out.append(replace(case, variants=[v for v in case.variants if not v.ensemble or v.name in keep],
                           ensembles=cut))
    return out


def select(cases, names=(), tier="standard"):
    """The named cases (any tier), or, with no names, every case of tier <= tier."""
    by_name = {c.name: c for c in cases}
    unknown = [n for n in names if n not in by_name]
    if unknown:
        raise CatalogueError(f"unknown case(s): {', '.join(unknown)} (known: {', '.join(by_name)})")
    if names:
        return [by_name[n] for n in dict.fromkeys(names)]
    return [c for c in cases if tier_rank(c.tier) <= tier_rank(tier)]
