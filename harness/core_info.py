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
sweep_grid.py and sweep.py with query().
"""
import re
import subprocess

from .errors import CatalogueError

OUTPUT_LINE = re.compile(r"^output every\s+(\d+) cycles$", re.M)
STAGE_LINE = re.compile(r"^stage\s+(\S+) (\d+) cycles (\S+) s \((time|cycles)\)$", re.M)
UNUSED_LINE = re.compile(r"^unused\s+(\S+) \((.*)\)$", re.M)
NUMBERS = (("estimate", "dt estimate"), ("single", "dt single"), ("dt", "dt used"))
QUERY_TIMEOUT = 120      # seconds: `ballast info` builds the scene once (0.5 s for the largest)


def command(binary, scene, sets):
    return [str(binary), "info", str(scene)] + [a for s in sets for a in ("--set", s)]


def parse(text):
    """{estimate, single, dt: floats (nan when absent), output_every: cycles (None when absent),
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


def query(binary, scene, sets):
    """parse() of `ballast info` of the scene with the overrides; a CatalogueError (exit 2) with
    the core's own message (FILE:LINE: KEY: ...) when it refuses them."""
    cmd = command(binary, scene, sets)
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=QUERY_TIMEOUT,
                              stdin=subprocess.DEVNULL)
    except OSError as exc:
        raise CatalogueError(f"cannot start {binary}: {exc.strerror}") from None
    except subprocess.TimeoutExpired:
        raise CatalogueError(f"{' '.join(cmd)}: no answer in {QUERY_TIMEOUT} s") from None
    if done.returncode != 0:
        raise CatalogueError(f"{' '.join(cmd)}: exit {done.returncode}: {done.stderr.strip()}")
    return parse(done.stdout)
