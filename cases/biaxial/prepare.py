#!/usr/bin/python3
"""Prepare the JYH biaxial specimens: cases/biaxial/specimens/<name>/{discs.tsv,walls.tsv,
specimen.txt}.  Run from the repository root after `make`:

    /usr/bin/python3 cases/biaxial/prepare.py            # every specimen of SPECIMENS
    /usr/bin/python3 cases/biaxial/prepare.py e025_r1    # one of them

Deterministic: the same scene, seed and friction give the same files bitwise (bin/ballast is;
this script only copies columns and does arithmetic).  Never run by `make validate`: the
cases import the committed files.

Method (README.md of this folder): prepare.scene places the 1008 discs at random in a loose
box (no gravity) and closes the four frictionless walls on servos to PREP_STRESS with the
interparticle friction mu_prep; a lower mu_prep locks a denser packing (the "reduced
friction" method, an equivalent of multi-layer undercompaction: without gravity there is no
density gradient to undo).  mu_prep per specimen was chosen by trying values (the table
below), not to reach a friction angle: the target is the void ratio.

Planar void ratio e = (area inside the walls - area of the discs) / area of the discs, the
discs' area pi sum r^2 (overlaps, ~5e-4 d at 100 kPa, are ignored), the walls' lines the
specimen's sides.  The profile: the same ratio in 6 horizontal bands of equal height, each
disc's area clipped to the band exactly (circular segments).
"""
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from harness.families.biaxial import void_ratios_of  # noqa: E402

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
BANDS = 6
# name: (seed of [grains], mu_prep, delta_prep).  e025: the paper's medium-dense e = 0.25
# (mu_prep = 0.4, tried among 0, 0.1, 0.2, 0.3, 0.4, 0.45, 0.5, 1, 2, 10 on seed 1: e = 0.202,
# 0.229, 0.234, 0.244, 0.249, 0.249, 0.258, 0.264, 0.258, 0.263), the same recipe for every
# seed; r1, r2, r3: different specimens (seeds).  The density study, seed 1: e020 (mu_prep 0,
# the densest this method gives), e023 (0.1), e030 (loose: friction alone locks no looser
# than e ~ 0.26, so mu_prep = 1 with rolling resistance delta_prep = 1.0 during the
# preparation only; the tests then run with their own delta).  e020_r2, e020_r3: e020's recipe
# with seeds 2 and 3, the three specimens of the rate study (case biaxial_rate, issue 33).
SPECIMENS = {
    "e025_r1": (1, 0.4, 0.0),
    "e025_r2": (2, 0.4, 0.0),
    "e025_r3": (3, 0.4, 0.0),
    "e020_r1": (1, 0.0, 0.0),
    "e020_r2": (2, 0.0, 0.0),
    "e020_r3": (3, 0.0, 0.0),
    "e023_r1": (1, 0.1, 0.0),
    "e030_r1": (1, 1.0, 1.0),
}


def void_profile(y, r, box, bands=BANDS):
    """(e of the whole specimen, [e of each band from the bottom up]) inside box (xl, xr, yb, yt):
    the harness's own function (harness/families/biaxial.py), so the report and the checks
    compute the same numbers."""
    e, per = void_ratios_of(y, r, box, bands)
    return e, list(per)


def read_tsv(path):
    lines = Path(path).read_text().splitlines()
    names = lines[0].split("\t")
    return names, [ln.split("\t") for ln in lines[1:] if ln.strip()]


def prepare(name, seed, mu, delta):
    out = HERE / "specimens" / name
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [str(ROOT / "bin" / "ballast"), "run", str(HERE / "prepare.scene"), "--out", tmp,
               "--set", f"grains.spec.seed={seed}", "--set", f"material.grain.friction={mu!r}",
               "--set", f"material.grain.rolling={delta!r}"]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        dn, drows = read_tsv(Path(tmp) / "discs.tsv")
        wn, wrows = read_tsv(Path(tmp) / "walls.tsv")
        info = json.loads((Path(tmp) / "run.json").read_text())
    keep = ["x", "y", "r", "theta"]
    idx = [dn.index(k) for k in keep]
    out.mkdir(parents=True, exist_ok=True)
    (out / "discs.tsv").write_text("\t".join(keep) + "\n" + "".join("\t".join(row[i] for i in idx) + "\n" for row in drows))
    wk = ["name", "ax", "ay", "bx", "by"]
    widx = [wn.index(k) for k in wk]
    (out / "walls.tsv").write_text("\t".join(wk) + "\n" + "".join("\t".join(row[i] for i in widx) + "\n" for row in wrows))
    walls = {row[0]: [float(row[i]) for i in widx[1:]] for row in wrows}
    box = (walls["spec_left"][0], walls["spec_right"][0], walls["spec_bottom"][1], walls["spec_top"][1])
    x, y, r = (np.array([float(row[dn.index(k)]) for row in drows]) for k in ("x", "y", "r"))
    e, prof = void_profile(y, r, box)
    stage = info["stages"][0]
    text = (f"specimen {name}: [grains] seed {seed}, mu_prep {mu}, delta_prep {delta}, prepare.scene (cycles {stage['cycles']}, "
            f"stopped {stage['stopped']}, servo error {stage['servo_error']:.3g}, unbalanced {stage['unbalanced']:.3g})\n"
            f"width {1000 * (box[1] - box[0]):.2f} mm, height {1000 * (box[3] - box[2]):.2f} mm, discs {len(r)}\n"
            f"planar void ratio e = {e:.4f}\n"
            f"bands (bottom to top): {' '.join(f'{v:.4f}' for v in prof)}; range {min(prof):.4f} to {max(prof):.4f}\n")
    (out / "specimen.txt").write_text(text)
    print(text, end="")


def main(argv):
    names = argv or list(SPECIMENS)
    for name in names:
        if name not in SPECIMENS:
            sys.exit(f"prepare.py: no specimen '{name}' (have: {', '.join(SPECIMENS)})")
        prepare(name, *SPECIMENS[name])


if __name__ == "__main__":
    main(sys.argv[1:])
