"""harness/engines/trajectory.py -- what an engine adapter hands back: the state of a run at
each output row and at its end, in ballast's conventions, whatever engine made it.

A Frame is the state after cycle `step` (t_N = step dt):

    discs     x, y and the velocities at t_N (vx, vy, omega: ballast's (v_{N-1/2} + v_{N+1/2})/2,
              which is velocity Verlet's v_N), in the scene's disc order;
    contacts  one row per touching contact, numpy arrays by column (CONTACT_FIELDS):
              a        the disc (its index)
              b        the other disc's index, or the wall's index when wall is true
              nx, ny   the unit vector from a to b (to a wall: from a's centre to the contact)
              px, py   the contact point: the middle of the overlap (ballast's stress arm)
              delta    the overlap
              fn, dn   the elastic normal force and the normal dashpot, repulsive positive
              fs, ds   the elastic shear force and the shear dashpot: the force on a is
                       -(fn + dn) e - (fs + ds) t, t = (ny, -nx), e = (nx, ny) (C&S Figs 2-3)
              sliding  1 where the Coulomb cap acts
              mr, md   the rolling moment M and its dashpot M_d: a gets the couple -(mr + md)
              theta_r  the relative rotation since the contact formed (0 without rolling)
              rolling  1 at the rolling cap (JYH Model 1)
    walls     (ax, ay, bx, by) of every wall at t_N, in walls.tsv order
    gfac      the gravity ramp's factor in that cycle (1 outside a ramp)

A Trajectory is the frames of every series row (the cycles ballast writes rows at), the last
state, each stage's cycles (and whether a stop rule ended it), the steps run and the engine's
own time for them.
"""
from dataclasses import dataclass, field

import numpy as np

CONTACT_FIELDS = ("a", "b", "wall", "nx", "ny", "px", "py", "delta", "fn", "fs", "dn", "ds",
                  "sliding", "mr", "md", "theta_r", "rolling")


def empty_contacts():
    return {k: np.zeros(0, dtype=int if k in ("a", "b", "wall", "sliding", "rolling") else float)
            for k in CONTACT_FIELDS}


def contacts_of(rows):
    """Contact columns from a list of dicts (missing fields 0)."""
    if not rows:
        return empty_contacts()
    out = {}
    for k in CONTACT_FIELDS:
        kind = int if k in ("a", "b", "wall", "sliding", "rolling") else float
        out[k] = np.array([r.get(k, 0) for r in rows], dtype=kind)
    return out


def concatenate(first, second):
    """Two sets of contact columns as one."""
    return {k: np.concatenate([first[k], second[k]]) for k in CONTACT_FIELDS}


@dataclass
class Frame:
    step: int
    time: float
    x: np.ndarray
    y: np.ndarray
    vx: np.ndarray
    vy: np.ndarray
    omega: np.ndarray
    contacts: dict
    walls: list
    gfac: float = 1.0


@dataclass
class Trajectory:
    frames: list                  # Frame per series row, in order
    final: Frame                  # the state at the end of the run
    stages: list                  # {"name", "cycles", "max_cycles", "stopped"} per stage
    steps: int
    engine_seconds: float         # the engine's own time for the steps (its log)
    notes: dict = field(default_factory=dict)   # engine facts for run.json
