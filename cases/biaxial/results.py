#!/usr/bin/python3
"""Print the biaxial results tables from the runs of a full tier (reports/runs/biaxial_full, or
$BALLAST_REPORTS/runs): the delta-phi table (envelope peak and residual, paper beside ballast,
the spread over the three specimens at delta = 0 and 1.6), the per-test angles and the density
study.  Run from the repository root:

    /usr/bin/python3 cases/biaxial/results.py
"""
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
import harness.families  # noqa: E402,F401 -- registers the expression functions
from harness.compare import RunStore, evaluate, folder_locator  # noqa: E402

CASE = "biaxial_full"
LO, HI = 0.20, 0.30
PAPER = {"m0": (24.4, 19.3), "m1_d0.4": (29.0, 23.0), "m2_d0.4": (26.5, 20.7), "m1_d1.6": (42.3, 35.8)}
STORE = RunStore(folder_locator(Path(os.environ.get("BALLAST_REPORTS", "reports")) / "runs"))


def ev(variant, expr):
    try:
        return evaluate(expr, STORE.get(CASE, variant), lambda other: STORE.get(CASE, other))
    except Exception:                 # noqa: BLE001 -- a table cell, not a check
        return "n/a"


def f(x, fmt="{:.1f}"):
    return fmt.format(x) if isinstance(x, float) else str(x)


def envelope(mat, suffix=""):
    v = f"{mat}_s100{suffix}"
    return (ev(v, "phi_envelope('peak', '_s100', '_s200', '_s400', rows=5)"),
            ev(v, f"phi_envelope('residual', '_s100', '_s200', '_s400', lo={LO}, hi={HI})"),
            ev(v, "cohesion_envelope('peak', '_s100', '_s200', '_s400', rows=5) / 1000"))


def main():
    mats = ["m0"] + [f"m1_d{round(0.1 * k, 1)}" for k in range(1, 17)] + ["m2_d0.4"]
    print("| material | JYH peak / residual | ballast e025 peak / residual (envelope) | c peak (kPa) | spread over 3 specimens (peak; residual) | ballast e020 peak / residual |")
    print("|---|---|---|---|---|---|")
    for m in mats:
        p, r, c = envelope(m)
        paper = PAPER.get(m)
        spread = ""
        if m in ("m0", "m1_d1.6"):
            pk = [envelope(m, s) for s in ("", "_r2", "_r3")]
            if all(isinstance(x[0], float) and isinstance(x[1], float) for x in pk):
                ps, rs = [x[0] for x in pk], [x[1] for x in pk]
                spread = (f"{min(ps):.1f}–{max(ps):.1f} (range {max(ps) - min(ps):.1f}); "
                          f"{min(rs):.1f}–{max(rs):.1f} (range {max(rs) - min(rs):.1f})")
        dense = ""
        if m in PAPER:
            dp, dr, _ = envelope(m, "_e020")
            dense = f"{f(dp)} / {f(dr)}"
        print(f"| {m} | {'%.1f / %.1f' % paper if paper else ''} | {f(p)} / {f(r)} | {f(c)} | {spread} | {dense} |")
    print()
    print("| test | phi peak (rows=5) | phi residual | residual_drift(0.20, 0.30) | eps_a at peak | dilation | max(abs(sigma_h/target-1)) |")
    print("|---|---|---|---|---|---|---|")
    for m in ("m0", "m2_d0.4", "m1_d0.4", "m1_d1.6"):
        for s in (100, 200, 400):
            v = f"{m}_s{s}"
            print(f"| {v} | {f(ev(v, 'phi_peak(rows=5)'))} | {f(ev(v, f'phi_residual({LO}, {HI})'))} | "
                  f"{f(ev(v, f'residual_drift({LO}, {HI})'), '{:.2f}')} | {f(ev(v, 'at_peak(axial_strain(), rows=5)'), '{:.3f}')} | "
                  f"{f(ev(v, 'dilation()'), '{:.3f}')} | {f(ev(v, f'max(abs(sigma_h() / {s}e3 - 1))'), '{:.3f}')} |")
    print()
    print("| density study, 200 kPa | e at shearing | m0 peak / residual | m1_d1.6 peak / residual | m0 dilation | m0 eps_a at peak |")
    print("|---|---|---|---|---|---|")
    for sfx in ("_e020", "_e023", "", "_e030"):
        e0 = ev(f"m0_s200{sfx}", "initial_void_ratio()")
        cells = []
        for m in ("m0", "m1_d1.6"):
            v = f"{m}_s200{sfx}"
            cells.append(f"{f(ev(v, 'phi_peak(rows=5)'))} / {f(ev(v, f'phi_residual({LO}, {HI})'))}")
        print(f"| {sfx or '_e025'} | {f(e0, '{:.4f}')} | {cells[0]} | {cells[1]} | {f(ev(f'm0_s200{sfx}', 'dilation()'), '{:.3f}')} | "
              f"{f(ev(f'm0_s200{sfx}', 'at_peak(axial_strain(), rows=5)'), '{:.3f}')} |")

if __name__ == "__main__":
    main()
