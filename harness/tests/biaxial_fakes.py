"""Synthetic biaxial runs with known answers, for the biaxial family and its figures.

A run has a row every EVERY cycles: stage 'consolidate' of CONSOLIDATE cycles (the specimen
W0 x H0, isotropic at sigma_h), then stage 'shear' of SHEAR cycles at a constant natural axial
strain rate: eps_a = RATE (cycle - CONSOLIDATE), H = H0 exp(-eps_a).  sigma_h is constant; the
deviator t = (sigma_v - sigma_h)/2 rises linearly from 0 to t_peak at eps_a = EPS_PEAK, falls
linearly to t_res at eps_a = EPS_RES and stays there.  The volumetric strain (natural) rises
as 0.3 eps_a up to EPS_COMPRESSED, then falls at slope 0.5 (dilation); the width follows:
W = W0 exp(-(eps_vol - eps_a)).  The wall forces are made from the stresses with the signs the
discs push the walls (top up, bottom down, left to -x, right to +x), so the abs() matters.

The rows fall on the strains exactly: EPS_PEAK, EPS_RES and the window edges are multiples of
RATE * EVERY.
"""
import json
from pathlib import Path

import numpy as np

from harness.tests.fakes import write_series

EVERY = 10
CONSOLIDATE = 100
SHEAR = 2000
RATE = 1e-4                     # natural axial strain per cycle: 1e-3 per row, 0.2 at the end
W0, H0 = 0.18, 0.3067           # JYH Sec. 5.1: 180 mm by 306.7 mm
EPS_PEAK, EPS_RES = 0.03, 0.08
EPS_COMPRESSED = 0.01


def deviator(eps, t_peak, t_res):
    """The piecewise-linear t(eps_a) of the module docstring."""
    rising = t_peak * eps / EPS_PEAK
    falling = t_peak + (t_res - t_peak) * (eps - EPS_PEAK) / (EPS_RES - EPS_PEAK)
    return np.where(eps <= EPS_PEAK, rising, np.where(eps <= EPS_RES, falling, t_res))


def volumetric(eps):
    return np.where(eps <= EPS_COMPRESSED, 0.3 * eps, 0.3 * EPS_COMPRESSED - 0.5 * (eps - EPS_COMPRESSED))


def columns(sigma_h, t_peak, t_res, consolidate=CONSOLIDATE, shear=SHEAR):
    """series.tsv columns of one synthetic test."""
    cycle = np.arange(EVERY, consolidate + shear + 1, EVERY, dtype=float)
    eps = np.maximum(cycle - consolidate, 0.0) * RATE
    # during the consolidation the specimen shrinks a little, isotropically, to W0 x H0
    settle = np.where(cycle < consolidate, 1e-3 * (consolidate - cycle) / consolidate, 0.0)
    height = H0 * np.exp(-eps) * (1 + settle)
    width = W0 * np.exp(-(volumetric(eps) - eps)) * (1 + settle)
    sv = sigma_h + 2 * deviator(eps, t_peak, t_res)
    fy, fx = sv * width, sigma_h * height
    return {"cycle": cycle, "time": cycle * 1e-3, "fy_top": fy, "fy_bottom": -fy, "fx_left": -fx,
            "fx_right": fx, "y_top": 0.01 + height, "y_bottom": np.full_like(cycle, 0.01),
            "x_left": np.full_like(cycle, -0.02), "x_right": width - 0.02}


def stages(consolidate=CONSOLIDATE, shear=SHEAR, name="shear"):
    return [{"name": "consolidate", "cycles": consolidate, "max_cycles": 10 * consolidate, "stop_rule": True,
             "stopped": True, "ke_over_ee": 1e-5, "stress_change": 1e-4},
            {"name": name, "cycles": shear, "max_cycles": shear, "stop_rule": False, "stopped": False,
             "ke_over_ee": -1, "stress_change": -1}]


def write_biaxial_run(folder, sigma_h=200e3, t_peak=100e3, t_res=60e3, cols=None, info=None, **kw):
    """A run folder with series.tsv and run.json (status ok, the two stages)."""
    folder = Path(folder)
    write_series(folder, columns(sigma_h, t_peak, t_res, **kw) if cols is None else cols)
    record = {"version": "fake", "status": "ok", "message": "", "steps": CONSOLIDATE + SHEAR, "dt": 1e-3,
              "wall_seconds": 1.0, "n_discs": 1008, "sets": [], "stages": stages()}
    record.update(info or {})
    (folder / "run.json").write_text(json.dumps(record))
    return folder


def on_line(sigma_h, slope, intercept):
    """t of the point on the line t = slope s + intercept whose s = sigma_h + t."""
    return (slope * sigma_h + intercept) / (1 - slope)
