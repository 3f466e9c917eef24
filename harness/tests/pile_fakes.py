"""A hand-made pile final state with known answers, for the pile functions and figures.

Pile: x0 = 0, width l = 4; gravity [0, -2] so |g| = 2.  Discs (id name x y m fixed row):

    row 0, held:  0 p.0 (0.5)  1 p.1 (1.5)  2 p.2 (2.5)  3 p.3 (3.5)     X = .125 .375 .625 .875
    row 1, free:  4 p.4 (x=3, m=1)  5 p.5 (x=1, m=2)  6 p.6 (x=2, m=3)   X = .75 .25 .5
    row 2, free:  7 p.7 (x=1.5, m=1)  8 p.8 (x=2.5, m=1)

Free mass 8, so W = 16 and l / W = 1/4.  Stress (tension positive) of row 1, by x:

    p.5: sxx -4, szz -8, sxz 0     -> S_xx 1, S_zz 2, S_xz 0, S_max 2, S_min 1, phi 90, ratio 1/2
    p.6: sxx -2, szz -6, sxz -2    -> S_xx .5, S_zz 1.5, S_xz .5, S_max (4 + 2 sqrt 2)/4,
                                      S_min (4 - 2 sqrt 2)/4, phi 67.5
    p.4: sxx 2, szz -4, sxz 0      -> S_xx -.5, S_zz 1, S_xz 0, S_max 1, S_min -.5, phi 90, ratio -1/2

Contacts of the DEM run (force fn + dn) and the exact run (open column):

    pair       kind  angle  X      DEM        exact
    p.5 p.6    disc    0   .375    10 + .5    10        (exact lists it as p.6 p.5)
    p.6 p.4    disc    5   .625    4          5
    p.5 p.7    disc   15   .3125   2          2
    p.6 p.7    disc   60   .4375   1          1
    p.7 p.8    disc    0   .5      3          0 (open)
    p.6 p.8    disc   40   .5625   -          .5        (exact lists it as p.8 p.6)
    p.0 p.5    disc    0   .1875   6          6         held-free: counted in forces
    p.1 p.2    disc    0   .5      100        -         held-held: left out
    p.4 floor  wall  -90   .75     23         24
    p.4 side   wall    0   .875    2          2

So horizontal_contacts() is 3 in the DEM run (p.5-p.6, p.6-p.4, p.7-p.8) and 2 in the exact
run (p.7-p.8 is open); contact_error('exact') = 3/24 (p.7-p.8 against the floor's 24), with
kind='disc' 3/10, kind='wall' 1/24; from the exact run, contact_error('dem') = 3/23 (the
held pair's 100 is left out); contact_mismatch = 2 (p.7-p.8 and p.6-p.8).
"""
import json
import math
from pathlib import Path

from harness.tests.fakes import write_series

DISCS = [  # id, name, x, y, m, fixed, row
    (0, "p.0", 0.5, 0.5, 1, 1, 0), (1, "p.1", 1.5, 0.5, 1, 1, 0), (2, "p.2", 2.5, 0.5, 1, 1, 0),
    (3, "p.3", 3.5, 0.5, 1, 1, 0), (4, "p.4", 3.0, 1.4, 1, 0, 1), (5, "p.5", 1.0, 1.4, 2, 0, 1),
    (6, "p.6", 2.0, 1.4, 3, 0, 1), (7, "p.7", 1.5, 2.3, 1, 0, 2), (8, "p.8", 2.5, 2.3, 1, 0, 2),
]
STRESS = {4: (2.0, 0.0, -4.0), 5: (-4.0, 0.0, -8.0), 6: (-2.0, -2.0, -6.0)}   # id: sxx, sxz, szz

DEM_CONTACTS = [  # a, b, kind, x, angle (degrees), fn, dn
    ("p.5", "p.6", "disc", 1.5, 0, 10.0, 0.5), ("p.6", "p.4", "disc", 2.5, 5, 4.0, 0.0),
    ("p.5", "p.7", "disc", 1.25, 15, 2.0, 0.0), ("p.6", "p.7", "disc", 1.75, 60, 1.0, 0.0),
    ("p.7", "p.8", "disc", 2.0, 0, 3.0, 0.0), ("p.0", "p.5", "disc", 0.75, 0, 6.0, 0.0),
    ("p.1", "p.2", "disc", 2.0, 0, 100.0, 0.0),
    ("p.4", "floor", "wall", 3.0, -90, 23.0, 0.0), ("p.4", "side", "wall", 3.5, 0, 2.0, 0.0),
]
EXACT_CONTACTS = [  # a, b, kind, x, angle, fn, open
    ("p.6", "p.5", "disc", 1.5, 180, 10.0, 0), ("p.4", "p.6", "disc", 2.5, 185, 5.0, 0),
    ("p.5", "p.7", "disc", 1.25, 15, 2.0, 0), ("p.6", "p.7", "disc", 1.75, 60, 1.0, 0),
    ("p.7", "p.8", "disc", 2.0, 0, 0.0, 1), ("p.0", "p.5", "disc", 0.75, 0, 6.0, 0),
    ("p.8", "p.6", "disc", 2.25, 220, 0.5, 0),
    ("p.4", "floor", "wall", 3.0, -90, 24.0, 0), ("p.4", "side", "wall", 3.5, 0, 2.0, 0),
]
PILE = {"name": "p", "L": 4, "rows": 3, "discs": 9, "d": 1.0, "x0": 0.0, "width": 4.0}


def principal(sxx, sxz, szz):
    """smax, smin, phi as the core computes them (output.c, principal())."""
    plus, minus, star = 0.5 * (sxx + szz), 0.5 * (sxx - szz), sxz
    rad = math.hypot(minus, star)
    phi = math.degrees(0.5 * math.atan2(2 * star, sxx - szz))
    return plus + rad, plus - rad, phi + 180 if phi < 0 else phi


def _tsv(path, header, rows):
    text = "\t".join(header) + "\n" + "".join("\t".join(str(v) for v in row) + "\n" for row in rows)
    Path(path).write_text(text)


def write_pile_run(folder, exact=False, gravity=(0.0, -2.0), stress=True, pile=True, series=None):
    """The fake pile's run folder: run.json, series.tsv, discs.tsv, contacts.tsv, walls.tsv and,
    for a DEM run with stress=True, stress.tsv."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    info = {"version": "fake", "status": "ok", "message": "", "steps": 1000 if not exact else 0,
            "dt": 0.1, "wall_seconds": 2.0 if not exact else 0.5, "n_discs": len(DISCS)}
    if gravity is not None:
        info["gravity"] = list(gravity)
    if pile:
        info["piles"] = [PILE]
    (folder / "run.json").write_text(json.dumps(info))
    write_series(folder, series or {"cycle": [0, 1], "time": [0.0, 0.1], "Ek": [1.0, 0.5]})
    _tsv(folder / "discs.tsv", "id name x y r theta vx vy omega m fixed row".split(),
         [(i, name, x, y, 0.5, 0, 0, 0, 0, m, fixed, row) for i, name, x, y, m, fixed, row in DISCS])
    _tsv(folder / "walls.tsv", "name ax ay bx by f1 f2 moment ecc".split(),
         [("floor", -1, 0, 5, 0, 0, 0, 0, 0), ("side", 4, 0, 4, 3, 0, 0, 0, 0)])
    head = "a b kind x y nx ny fn fs dn ds sliding".split()
    rows = []
    for a, b, kind, x, angle, fn, last in (EXACT_CONTACTS if exact else DEM_CONTACTS):
        nx, ny = math.cos(math.radians(angle)), math.sin(math.radians(angle))
        rows.append((a, b, kind, x, 1.0, repr(nx), repr(ny), fn, 0, 0 if exact else last, 0, 0)
                    + ((last,) if exact else ()))
    _tsv(folder / "contacts.tsv", head + (["open"] if exact else []), rows)
    if stress and not exact:
        srows = []
        for i, name, x, y, m, fixed, row in DISCS:
            sxx, sxz, szz = STRESS.get(i, (-1.0, 0.0, -1.0))
            srows.append((i, name, x, y, row, fixed, math.pi / 4, sxx, sxz, sxz, szz, *principal(sxx, sxz, szz)))
        _tsv(folder / "stress.tsv", "id name x y row fixed V sxx sxz szx szz smax smin phi".split(), srows)
    return folder
