#!/bin/sh
# same_outputs.sh — are two harness reports byte for byte the same, but for
# the clocks?  For a change that must not change results (a restructuring,
# a faster loop): run the tier into two reports folders, before and after,
#
#   BALLAST_REPORTS=/tmp/before python3 -m harness run --tier standard -j 2
#   ... change, rebuild ...
#   BALLAST_REPORTS=/tmp/after  python3 -m harness run --tier standard -j 2
#   sh core/bench/same_outputs.sh /tmp/before /tmp/after
#
# It compares every file of every run folder under runs/ (the same set of
# folders and files on both sides, or it fails), byte for byte after blanking
# only what measures time or names the build:
#   run.json       wall_seconds, particle_steps_per_s, timers
#   ballast.stdout the summary line's wall time
#   harness.json   wall_seconds, the binary's sha256, the run.json and
#                  ballast.stdout hashes among the outputs (both hold a wall time)
#   every file     the two reports folders' paths (each run names its own)
# Prints one line per differing file and a summary; exit 0 when none differs,
# 1 when some do, 2 on usage.
set -eu
if [ $# -ne 2 ] || [ ! -d "$1/runs" ] || [ ! -d "$2/runs" ]; then
    echo "usage: same_outputs.sh BEFORE_REPORTS AFTER_REPORTS (each with a runs/ folder)" >&2
    exit 2
fi
exec "${PYTHON:-/usr/bin/python3}" - "$1" "$2" <<'EOF'
import os, re, sys

before, after = (os.path.abspath(p) for p in sys.argv[1:3])

# (file name, pattern): each match is replaced by its key alone.
CLOCKS = [
    ("run.json", r'"wall_seconds": [^,\n]*'),
    ("run.json", r'"particle_steps_per_s": [^,\n]*'),
    ("run.json", r'"timers": \{[^}]*\}'),
    ("harness.json", r'"wall_seconds": [^,\n]*'),
    ("harness.json", r'"sha256": "[0-9a-f]*"'),
    ("harness.json", r'"run\.json": "[0-9a-f]*"'),
    ("harness.json", r'"ballast\.stdout": "[0-9a-f]*"'),
    ("ballast.stdout", r'wall [^ ]+ s'),
]

def normal(path):
    with open(path, "rb") as f:
        text = f.read()
    for root in (before, after):
        text = text.replace(root.encode(), b"REPORTS")
    name = os.path.basename(path)
    for file, pattern in CLOCKS:
        if file == name:
            text = re.sub(pattern.encode(), lambda m: m.group(0).split(b":")[0] + b": -"
                          if b":" in m.group(0) else b"wall - s", text)
    return text

def files(root):
    out = set()
    for d, _, names in os.walk(os.path.join(root, "runs")):
        for n in names:
            out.add(os.path.relpath(os.path.join(d, n), root))
    return out

fb, fa = files(before), files(after)
bad = 0
for rel in sorted(fb ^ fa):
    print("only in %s: %s" % (before if rel in fb else after, rel))
    bad += 1
common = sorted(fb & fa)
for rel in common:
    if normal(os.path.join(before, rel)) != normal(os.path.join(after, rel)):
        print("differs: %s" % rel)
        bad += 1
folders = {os.path.dirname(r) for r in common}
print("same_outputs: %d run folders, %d files compared, %d differ%s" %
      (len(folders), len(common), bad, "" if bad else " (identical but for the clocks)"))
sys.exit(1 if bad else 0)
EOF
