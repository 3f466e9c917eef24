"""What the core says of a scene: the lines of `ballast info SCENE --set ...`, read in one place.

The harness never reads a scene file for what the core derives from it (the step, the stages'
lengths, which keys a scene uses): a stage may be given in cycles or in simulated time
(`time = T`: ceil(T/dt) cycles at whatever dt the scene ends up with), an override may change
either, and only the core resolves them.  `ballast info` prints, among others:

    dt estimate    E   (...)
    dt single      S   (...)
    dt used        DT
    output every   N cycles                             between rows of series.tsv
    stage          NAME N cycles T s (time|cycles)     one line per stage, in file order
    unused         KEY (WHY)                            a key given (in the file or by --set)
                                                        that another key's value makes unused

parse() turns that into a dict; stability.py asks through the runner's batch (interruptible),
points.py with query(); refuse_bad_points() asks about every point of a sweep before any
of them runs (`harness study`, `harness sweep`, and the declared sweeps of `harness cost`).
"""
import re
import subprocess

from .errors import CatalogueError

OUTPUT_LINE = re.compile(r"^output every\s+(\d+) cycles$", re.M)
STAGE_LINE = re.compile(r"^stage\s+(\S+) (\d+) cycles (\S+) s \((time|cycles)\)$", re.M)
UNUSED_LINE = re.compile(r"^unused\s+(\S+) \((.*)\)$", re.M)
NUMBERS = (("estimate", "dt estimate"), ("single", "dt single"), ("dt", "dt used"), ("fraction", "dt fraction"))
QUERY_TIMEOUT = 120      # seconds: `ballast info` builds the scene once (0.5 s for the largest)


def command(binary, scene, sets):
    return [str(binary), "info", str(scene)] + [a for s in sets for a in ("--set", s)]


def parse(text):
    """{estimate, single, dt, fraction: floats (nan when absent), output_every: cycles (None when absent),
    stages: [(name, cycles, seconds, given_in)], unused: {key: why}} of the output of `ballast info`; a CatalogueError without 'dt used'."""
    values = {}
    for key, name in NUMBERS:
        m = re.search(rf"^{name}\s+(\S+)", text, re.M)
        values[key] = float(m.group(1)) if m else float("nan")
    if not re.search(r"^dt used\s+\S+", text, re.M):
        raise CatalogueError(f"cannot read 'dt used' from ballast info:\n{text}")
    m = OUTPUT_LINE.search(text)
    values["output_every"] = int(m.group(1)) if m else None
    values["stages"] = [(m.group(1), int(m.group(2)), float(m.group(3)), m.group(4))
                        for m in STAGE_LINE.finditer(text)]
    values["unused"] = {m.group(1): m.group(2) for m in UNUSED_LINE.finditer(text)}
    return values


def ask(binary, scene, sets):
    """(exit code, stdout, stderr) of `ballast info` of the scene with the overrides; a
    CatalogueError when it cannot be run."""
    cmd = command(binary, scene, sets)
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=QUERY_TIMEOUT,
                              stdin=subprocess.DEVNULL)
    except OSError as exc:
        raise CatalogueError(f"cannot start {binary}: {exc.strerror}") from None
    except subprocess.TimeoutExpired:
        raise CatalogueError(f"{' '.join(cmd)}: no answer in {QUERY_TIMEOUT} s") from None
    return done.returncode, done.stdout, done.stderr


def query(binary, scene, sets):
    """parse() of `ballast info` of the scene with the overrides; a CatalogueError (exit 2) with
    the core's own message (FILE:LINE: KEY: ...) when it refuses them."""
    returncode, stdout, stderr = ask(binary, scene, sets)
    if returncode != 0:
        raise CatalogueError(f"{' '.join(command(binary, scene, sets))}: exit {returncode}: {stderr.strip()}")
    return parse(stdout)


def refuse_bad_points(binary, points):
    """Before any run of a sweep, each point as the core reads it: points are (label, scene,
    sets, swept keys).  A CatalogueError (exit 2) when the core refuses a point's overrides
    (an unknown key, a value out of range: its own message), or when a swept key is unused at
    a point because of another key's value (`unused` lines of `ballast info`): its values
    would all give the same run, and a curve of them would show a parameter that does
    nothing.  One `ballast info` per point (it builds the scene: 0.5 s for the largest)."""
    for label, scene, sets, swept in points:
        returncode, stdout, stderr = ask(binary, scene, sets)
        if returncode != 0:
            raise CatalogueError(f"sweep point {label}: ballast refuses its overrides (exit {returncode}): "
                                 f"{stderr.strip()}")
        unused = parse(stdout)["unused"]
        for key in swept:
            if key in unused:
                raise CatalogueError(f"sweep point {label}: {key} is unused there ({unused[key]}): every "
                                     f"value of it gives the same run; sweep another key, or change the one "
                                     f"that makes it unused")
