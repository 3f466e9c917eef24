"""Fake run outputs, a fake core executable and a small fake project for the tests.

The fake project has one family 'springs' with case 'spring' (variants soft, stiff,
stiffer: a linear spring F = k * cycle, Ek = k * cycle**2 / 2) and one family 'slow'
with case 'slow' (tier full).  Its reference file exercises every tolerance kind.
The fake core (FAKE_BIN) reads 'key = value' scenes and --set KEY=VALUE overrides; its
`inputs` lists the scene and the file of each `reads = FILE` line (as an [import]'s).
"""
import json
import os
import signal
import stat
from pathlib import Path

FAKE_BIN = '''#!/usr/bin/python3
"""Fake ballast: run SCENE --out DIR [--set KEY=VALUE ...]; info SCENE [--set ...] (every key known);
inputs SCENE [--set ...]."""
import json, math, os, sys, time
args = sys.argv[1:]
if args and args[0] == "info":
    print("dt used        0.1\\noutput every   1 cycles\\nstage          run 10 cycles 1 s (cycles)"); sys.exit(0)
if args[:1] == ["inputs"] and len(args) > 1:    # the scene, and each `reads = FILE` (beside it)
    print(args[1])
    for line in open(args[1]):
        key, _, value = line.partition("=")
        if key.strip() == "reads":
            print(os.path.join(os.path.dirname(args[1]), value.strip()))
    sys.exit(0)
if not args or args[0] != "run":
    print("ballast: usage: run SCENE --out DIR", file=sys.stderr); sys.exit(2)
scene, out, sets = args[1], None, []
i = 2
while i < len(args):
    if args[i] == "--out": out = args[i + 1]
    elif args[i] == "--set": sets.append(args[i + 1])
    i += 2
p = {"k": "1", "n": "10", "fail": "0", "nan": "0", "sleep": "0", "status": "ok", "omit": "", "series": "1",
     "drop": "", "tmp": ""}
for line in open(scene):
    if "=" in line:
        key, value = line.split("=", 1); p[key.strip()] = value.strip()
for kv in sets:
    key, value = kv.split("=", 1); p[key.split(".")[-1]] = value
time.sleep(float(p["sleep"]))
if int(p["fail"]):
    print("starting", file=sys.stderr)
    print(scene + ":3: fail: asked to fail", file=sys.stderr); sys.exit(int(p["fail"]))
os.makedirs(out, exist_ok=True)
k, n = float(p["k"]), int(p["n"])
cols = ["cycle", "time", "F", "Ek"]
if p["omit"]: cols.remove(p["omit"])
def write(name, text):     # as the core: whole (tmp + rename); on an I/O error no tmp, exit 3
    tmp = os.path.join(out, name + ".tmp")
    try:
        with open(tmp, "w") as f: f.write(text)
        os.rename(tmp, os.path.join(out, name))
    except OSError as exc:
        if os.path.exists(tmp): os.unlink(tmp)
        print("ballast: %s: %s" % (os.path.join(out, name), exc.strerror), file=sys.stderr); sys.exit(3)
if p["series"] == "1":
    rows = []
    for c in range(1, n + 1):
        v = {"cycle": c, "time": c * 0.1, "F": k * c, "Ek": 0.5 * k * c * c}
        if int(p["nan"]) and c == n: v["F"] = float("nan")
        rows.append("\\t".join("%.17g" % v[x] for x in cols))
    write("series.tsv", "\\t".join(cols) + "\\n" + "\\n".join(rows) + "\\n")
info = {"version": "fake", "scene": scene, "sets": sets, "status": p["status"], "message": "",
        "steps": n, "dt": 0.1, "dt_estimate": 0.2, "dt_fraction": 0.5, "wall_seconds": 0.01,
        "n_discs": 2, "n_walls": 2, "particle_steps_per_s": 1e6}
for name in ("stress.tsv", "contacts.tsv", "discs.tsv", "walls.tsv"):   # the final state, as the core
    if name != p["drop"]:                                                # writes it (drop=NAME: not)
        write(name, "id\\tname\\n")
if p["tmp"]:                                                             # tmp=NAME: leave NAME.tmp behind
    open(os.path.join(out, p["tmp"] + ".tmp"), "w").write("half")
write("run.json", json.dumps(info))
'''

CASE_TXT = """\
# the spring family
[case spring]
tier = quick
title = A linear spring
checks = F = k x at every cycle; trend in k
runtime = 3

[variant soft]
scene = spring.scene
set = k=1

[variant stiff]
scene = spring.scene
set = k=2

[variant stiffer]
scene = spring.scene
set = k=3

[figure force]
title = Spring force
variants = soft stiff
x = cycle
y = F
ylabel = F
xrange = 0:
"""

SLOW_TXT = """\
[case slow]
tier = full
title = A slow case
checks = nothing much
runtime = 100

[variant only]
scene = spring.scene
"""

REF_TXT = """\
# references for the spring family
[check abs_at2]
case = spring
variant = soft
quantity = at(F, 2)
value = 2          # hand calculation
tolerance = abs 1e-12
kind = analytic
provenance = F = k x with k = 1, x = 2

[check rel_last]
case = spring
variant = stiff
quantity = last(F)
value = 20
tolerance = rel 1e-9
kind = exact
provenance = F = k x with k = 2, x = 10

[check interval_ek]
case = spring
variant = soft
quantity = max(Ek)
tolerance = interval
lo = 0
hi = 100
kind = paper
provenance = a plausible range
provenance = (second line)

[check trend_k]
case = spring
quantity = last(F)
tolerance = trend increasing
variants = soft stiff stiffer
kind = analytic
provenance = F grows with k

[check ratio_k]
case = spring
variant = stiff
quantity = last(F)
other = last(F)
other_variant = soft
value = 2
tolerance = ratio 1e-12
kind = analytic
provenance = F is linear in k

[check regress_mean]
case = spring
variant = soft
quantity = mean(F)
value = 5.5   # regression value, keep this comment
tolerance = rel 1e-12
kind = regression
provenance = recorded from the first run
"""


def write_fake_bin(path):
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(FAKE_BIN)
    path.chmod(path.stat().st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)
    return path


def make_project(root):
    """The fake project under root: cases/, reference/, reports/, bin/ballast."""
    root = Path(root)
    for family, text in (("springs", CASE_TXT), ("slow", SLOW_TXT)):
        folder = root / "cases" / family
        folder.mkdir(parents=True)
        (folder / "case.txt").write_text(text)
        (folder / "spring.scene").write_text("k = 1\nn = 10\n")
    (root / "reference").mkdir()
    (root / "reference" / "springs.ref").write_text(REF_TXT)
    (root / "reports").mkdir()
    write_fake_bin(root / "bin" / "ballast")
    return root


def spring_columns(k, n=10):
    cycles = list(range(1, n + 1))
    return {"cycle": cycles, "time": [c * 0.1 for c in cycles],
            "F": [k * c for c in cycles], "Ek": [0.5 * k * c * c for c in cycles]}


def write_series(folder, columns):
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    names = list(columns)
    rows = zip(*(columns[n] for n in names))
    text = "\t".join(names) + "\n" + "".join("\t".join("%.17g" % x for x in r) + "\n" for r in rows)
    (folder / "series.tsv").write_text(text)


def write_run(folder, columns=None, status="ok", **info):
    """A run folder with run.json (status, info) and, when columns is given, series.tsv."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    record = {"version": "fake", "status": status, "message": "" if status == "ok" else "it blew up",
              "steps": 10, "dt": 0.1, "wall_seconds": 0.5, "n_discs": 2}
    record.update(info)
    (folder / "run.json").write_text(json.dumps(record))
    if columns is not None:
        write_series(folder, columns)
    return folder


def write_spring_runs(runs_root, ks=(("soft", 1), ("stiff", 2), ("stiffer", 3))):
    """Correct outputs for every variant of case 'spring'."""
    for variant, k in ks:
        write_run(Path(runs_root) / "spring" / variant, spring_columns(k))


def tree_snapshot(root):
    """{relative path: (bytes, mtime_ns)} of every file under root."""
    root = Path(root)
    return {str(p.relative_to(root)): (p.read_bytes(), p.stat().st_mtime_ns)
            for p in sorted(root.rglob("*")) if p.is_file()}


def env_for(root):
    """The environment variables that point the harness at a fake project."""
    root = Path(root)
    return {"BALLAST_CASES": str(root / "cases"), "BALLAST_REFERENCE": str(root / "reference"),
            "BALLAST_BIN": str(root / "bin" / "ballast"), "BALLAST_REPORTS": str(root / "reports"),
            "PATH": os.environ.get("PATH", "")}


def default_sigint():
    """For a test's Popen(preexec_fn=...): SIGINT back to its default disposition in the child
    before exec. A shell's background job (`make test &` in a script, nohup) inherits SIGINT
    ignored, and a Python harness then never raises KeyboardInterrupt."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
