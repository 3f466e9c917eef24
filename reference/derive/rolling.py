#!/usr/bin/python3
"""Derive the reference values of the rolling-resistance law tester (reference/rolling.ref).

This script is the provenance of the numbers in reference/rolling.ref.  It does not run
ballast.  It reads cases/rolling/case.txt and the scenes its variants name (a minimal
reader, so they cannot disagree) and works the rolling law of Jiang, Yu & Harris (2005,
JYH) by hand along the prescribed motion, cycle by cycle, in exact rational arithmetic
(only the cosine of the wall's angle is a float, exact to an ulp):

1. Kinematics.  The wall tester (rolling_tester.scene): the disc is held (it neither moves
   nor turns) with its centre C = (0, R); the floor wall passes through P = (0, p) at the
   angle a (0 at the start).  Each cycle the floor moves first (P += V dt, a += omega dt:
   docs/physics.md, cycle order), so at cycle N the distance from C to the floor's line is
   (R - p) cos a and the overlap is
       d_N = R - (R - p) cos a = p + (R - p) (1 - cos a).
   The pair (rolling_pair.scene): a held disc pressed on a flywheel that turns at a constant
   omega and neither moves nor slows within rounding (asserted below): d is constant.
   Either way the relative rotation theta_r = int (omega_a - omega_b) dt (JYH eqs 12-13, 11
   for a wall) of the held disc a against the other body grows by -omega dt a cycle.
2. The normal force is the power law with nu = 1, delta0 = 1: F_n = k_n d (MLH eq. 2).
3. The rolling law, JYH Secs 2-3: the contact width B = delta r (eq. 24) with the common
   radius r = 2 R against a wall (eq. 11b), 2 r1 r2/(r1 + r2) for two discs (eq. 9b); the
   rolling stiffness K_m = k_n B^2/12 (eq. 29); the peak moment M_0 = F_n B/6 and
   theta_r0 = M_0/K_m = 2 F_n/(k_n B) (eq. 33).  Model 1 (eq. 35, the 'elasto-perfectly
   plastic model') as an incremental elasto-plastic spring: M_trial = M_{N-1} + K_m
   (theta_N - theta_{N-1}); if |M_trial| > M_0(F_n at N) the moment is M_0 with the sign of
   M_trial, and the plastic rotation (|M_trial| - M_0)/K_m is dissipated against M_0;
   unloading is elastic.  Model 2 (eq. 36, 'elasto-brittle'): once |M_trial| > M_0 the
   moment is 0 for good and the spring's energy M_trial^2/(2 K_m) is lost.  The elastic
   energy stored is k_n d^2/2 (the power law's int F_n dd) plus M^2/(2 K_m) (eq. 28:
   M = K_m theta_r, the work int M dtheta_r).

The references follow: the slope K_m over each elastic branch, the cycle where each cap
starts (where K_m theta_r first passes theta_r0 = 2 F_n/(k_n B): a cap that fell within
1e-6 of a step would make that cycle ambiguous, and is refused here), the plateau
M = F_n B/6 at both normal forces, the Model 2 loss and that it lasts, the energies.  At
the pair's constant F_n the closed forms hold as they stand (the loss of Model 1 is
M_0 (theta_r - theta_r0) exactly), and the pair's checks are written from them.

The case's figures draw the nominal reference lines K_m theta_r and +-M_0 at F_n = k_n x
(the press's overlap), printed in the header; harness/tests/test_rolling.py holds the
figures' numbers to nominal() here.

Usage: reference/derive/rolling.py > reference/rolling.ref
       reference/derive/rolling.py --cycles VARIANT   (the hand calculation, one row a cycle)
"""
import math
import os
import sys
from fractions import Fraction as Q

HERE = os.path.dirname(os.path.abspath(__file__))
CASE_DIR = os.path.join(HERE, "..", "..", "cases", "rolling")
CASE = os.path.join(CASE_DIR, "case.txt")
CASE_NAME = "rolling_tester"

AMBIGUOUS = Q(1, 10 ** 6)   # a cap decision closer than this share of a step's K_m dtheta is refused

# Tolerances, each with its reason (measured values in docs/cases.md, rolling_tester).
# ballast's overlap R - distance is the difference of two numbers of size R: the distance
# carries a rounding of an ulp or so of R (u R = 8.3e-17, u = 2^-53), which is u R/d =
# 3.4e-13 of the overlap d = 2^-12 (1.7e-13 at 2^-11), and so of F_n and of M_0 = F_n B/6.
TOL_FN = 2e-12          # relative: a value proportional to one cycle's F_n (a few ulps of R over d)
# M and theta_r are sums of up to 854 equal increments (K_m dtheta, dtheta) from the last
# reversal: their rounding is below N u = 1e-13 of them.
TOL_SLOPE = 1e-13       # relative: the least-squares slope of such sums
TOL_ENERGY = 2e-12      # relative: k_n d^2/2 carries twice the overlap's relative rounding
# A capped cycle dissipates M_0 (|M_trial| - M_0)/K_m: a difference of two moments of size
# M_0 within one step's K_m dtheta.  The rounding of M_0 enters it as M_0 (e_{N-1} - e_N)/K_m
# (e_N the error of M_0 at cycle N), which telescopes over a plateau to M_0 (e_first -
# e_last)/K_m: relative to the plateau's loss, at least M_0 theta_r0, that is below
# 2 x 3.4e-13.
TOL_LOSS = 2e-12        # relative: dissipated_rolling of Model 1
TOL_LOST = 1e-13        # relative: Model 2's lost energy (K_m theta_b)^2/(2 K_m), theta_b a sum
TOL_SPLIT = 2e-15       # absolute on a relative difference: three products and two sums, a few u


def read_ini(path):
    """Sections of an ini-like file: {section: {key: [values]}} (comments stripped)."""
    sections, cur = {}, None
    for raw in open(path, encoding="utf-8"):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        if line.startswith("["):
            cur = line.strip("[]").strip()
            sections.setdefault(cur, {})
            continue
        key, value = (t.strip() for t in line.split("=", 1))
        sections[cur].setdefault(key, []).append(value)
    return sections


def read_variant(scene, sets, name):
    """One variant's parameters: its scene's numbers with its --set overrides applied."""
    sc = read_ini(scene)
    for s in sets:                                         # section.NAME.key=value or section.key=value
        key, value = (t.strip() for t in s.split("=", 1))
        parts = key.split(".")
        section = parts[0] if len(parts) == 2 else f"{parts[0]} {parts[1]}"
        if parts[0] == "stage" and parts[-1] == "move":
            sc[section]["move"] = [value]                  # --set replaces the wall's motion
        elif section in sc and parts[-1] in ("rolling_model", "rolling"):
            sc[section][parts[-1]] = [value]
        else:
            raise SystemExit(f"case.txt: variant {name}: the derivation does not know '{key}'")
    one = lambda sec, key, default=None: sc[sec][key][0] if key in sc[sec] else default
    assert one("settings", "normal_law") == "power" and Q(one("settings", "nu")) == 1
    assert Q(one("settings", "delta0")) == 1, "F_n = k_n d needs nu = 1, delta0 = 1"
    assert not any(k in sc["settings"] for k in ("alpha", "beta", "gamma_n", "gravity")), \
        "the hand calculation has no damping and no gravity"
    mats = {s.split()[1]: sc[s] for s in sc if s.startswith("material ")}
    assert len({m["kn"][0] for m in mats.values()}) == 1, "one k_n (the pair's is then k_n)"
    assert not any("friction" in m or "cohesion" in m for m in mats.values()), "no shear force"
    discs = {s.split()[1]: sc[s] for s in sc if s.startswith("disc ")}
    walls = {s.split()[1]: sc[s] for s in sc if s.startswith("wall ")}
    held = [n for n, d in discs.items() if d.get("fixed", ["0"])[0] == "1"]
    assert len(held) == 1, "one held disc"
    probe = sc["probe mr"]
    assert probe["a"][0] == held[0], "the moment is seen from the held disc (a of the probes)"
    other = probe["b"][0]
    vec = lambda sec, key: [Q(t) for t in sec[key][0].split()]
    p = dict(name=name, model=one("settings", "rolling_model"), dt=Q(one("settings", "dt")),
             kn=Q(next(iter(mats.values()))["kn"][0]))
    a = discs[held[0]]
    ra = Q(a["r"][0])
    if other in walls:
        # the wall tester: the disc on the floor, P straight under the centre
        w = walls[other]
        assert len(discs) == 1 and vec(a, "x") == [0, ra], "the disc's centre at (0, R)"
        assert vec(w, "p") == [0, 0] and Q(w["angle"][0]) == 0, "the floor through the origin, level"
        p.update(kind="wall", R=ra, r=2 * ra, delta=Q(mats[a["material"][0]]["rolling"][0]))
        moves = []
        for stage, sec in ((s.split()[1], sc[s]) for s in sc if s.startswith("stage ")):
            v, omega = Q(0), Q(0)
            for m in sec.get("move", []):
                words = m.split()
                assert words[0] == other and Q(words[1]) == 0, "the floor moves up or turns"
                v, omega = Q(words[2]), Q(words[3])
            moves.append((stage, int(sec["cycles"][0]), v, omega))
        p["moves"] = moves
        return p
    # the pair: the held disc pressed on a flywheel that turns at omega whatever the contact does
    b = discs[other]
    assert not walls and len(discs) == 2 and one("settings", "allow_overlap") == "1"
    rb, omega = Q(b["r"][0]), Q(b["omega"][0])
    xa, xb = vec(a, "x"), vec(b, "x")
    assert xa[1] == xb[1] and xb[0] > xa[0], "the flywheel to the right of the held disc"
    d = ra + rb - (xb[0] - xa[0])
    assert d > 0, "the pair overlaps from the start"
    delta = min(Q(mats[x["material"][0]]["rolling"][0]) for x in (a, b))   # the smaller of the two
    p.update(kind="pair", r=2 * ra * rb / (ra + rb), delta=delta, d=d)      # JYH eq. 9b
    p["moves"] = [(s.split()[1], int(sc[s]["cycles"][0]), Q(0), omega) for s in sc if s.startswith("stage ")]
    assert all("move" not in sc[s] for s in sc if s.startswith("stage "))
    # A flywheel: the moment must not change its spin, nor the force its place, within rounding
    # (each cycle's increment below half an ulp of what it is added to).
    rho = float(mats[b["material"][0]]["density"][0])
    mass = rho * math.pi * float(rb) ** 2
    inertia = mass * float(rb) ** 2 / 2
    b_, km = constants(p)
    m0, dt = float(p["kn"] * d * b_ / 6), float(p["dt"])
    cycles = sum(c for _, c, _, _ in p["moves"])
    assert m0 * dt / inertia < math.ulp(float(omega)) / 2, "the flywheel's spin would change"
    assert float(p["kn"] * d) * dt / mass * cycles * dt < math.ulp(float(xb[0])) / 2, "the flywheel would move"
    return p


def read_inputs():
    """{variant: parameters} of every variant of the case."""
    variants = {}
    for name, sec in read_ini(CASE).items():
        if name.startswith("variant "):
            v = name.split()[1]
            variants[v] = read_variant(os.path.join(CASE_DIR, sec["scene"][0]), sec.get("set", []), v)
    return variants


def constants(p):
    """B = delta r (eq. 24), r = 2 R against a wall (eq. 11b), 2 r1 r2/(r1 + r2) for two
    discs (eq. 9b); K_m = k_n B^2/12 (eq. 29)."""
    b = p["delta"] * p["r"]
    return b, p["kn"] * b * b / 12


def one_minus_cos(a):
    """1 - cos a = 2 sin^2(a/2), without the cancellation (a is exact: a dyadic rational)."""
    s = math.sin(float(a) / 2)
    return Q(2 * s * s)


def hand(p):
    """The law tester worked cycle by cycle: a list of rows (dicts), one per cycle."""
    b, km = constants(p)
    dt, model = p["dt"], p["model"]
    assert model in ("model1", "model2")
    P, a, theta, m, lost, broken = Q(0), Q(0), Q(0), Q(0), Q(0), False
    rows, cycle = [], 0
    for stage, cycles, v, omega in p["moves"]:
        for _ in range(cycles):
            cycle += 1
            # wall: the floor moves first (P up by V dt, turned by omega dt); pair: the flywheel
            # turns at omega; the held disc does not turn, so dtheta_r = -omega dt (eqs 12-13)
            dtheta = -omega * dt
            theta += dtheta
            if p["kind"] == "wall":
                P += v * dt
                a += omega * dt
                d = P + (p["R"] - P) * one_minus_cos(a)
            else:
                d = p["d"]
            assert d > 0, "the contact must stay closed"
            fn = p["kn"] * d                              # MLH eq. 2, nu = 1
            m0 = fn * b / 6                               # JYH eq. 33a
            state = 2 if broken else 0
            if not broken:
                trial = m + km * dtheta                   # JYH eq. 28, incrementally
                margin = abs(abs(trial) - m0)
                if dtheta != 0:
                    assert margin > AMBIGUOUS * km * abs(dtheta), \
                        f"cycle {cycle}: the cap falls within a millionth of a step; change the turn"
                if abs(trial) > m0:
                    if model == "model1":                 # eq. 35b: the plateau
                        lost += m0 * (abs(trial) - m0) / km
                        m = m0 if trial > 0 else -m0
                        state = 1
                    else:                                 # eq. 36b: lost for good
                        lost += trial * trial / (2 * km)
                        m, broken, state = Q(0), True, 2
                else:
                    m = trial
            rows.append(dict(cycle=cycle, stage=stage, theta=theta, d=d, fn=fn, m0=m0, m=m,
                             state=state, lost=lost, e_el=p["kn"] * d * d / 2 + m * m / (2 * km)))
    return rows


def stage_ends(p):
    """{stage: (first cycle, last cycle)}."""
    out, c = {}, 0
    for stage, cycles, _, _ in p["moves"]:
        out[stage] = (c + 1, c + cycles)
        c += cycles
    return out


def nominal(p):
    """The figures' reference lines: K_m, and M_0 at F_n = k_n x (each press's overlap)."""
    b, km = constants(p)
    if p["kind"] == "pair":
        return km, [p["kn"] * p["d"] * b / 6]
    levels, P = [], Q(0)
    for stage, cycles, v, omega in p["moves"]:
        if v != 0:
            P += v * p["dt"] * cycles
            levels.append(p["kn"] * P * b / 6)
    return km, levels


def caps(rows, first, last, state):
    """Cycles in [first, last] whose row has the given state and whose previous row has not."""
    out = []
    for prev, row in zip(rows, rows[1:]):
        if first <= row["cycle"] <= last and row["state"] == state and prev["state"] != state:
            out.append(row["cycle"])
    return out


def f(x):
    """A float for the .ref file."""
    return repr(float(x))


class Writer:
    """Writes one [check NAME_VARIANT] section of the .ref file per call."""

    def __init__(self, out):
        self.out = out

    def check(self, name, variant, quantity, provenance, value, tolerance):
        self.out(f"[check {name}_{variant}]\ncase = {CASE_NAME}\nvariant = {variant}\nquantity = {quantity}\n"
                 f"value = {value}\ntolerance = {tolerance}\nkind = analytic\nprovenance = {provenance}\n\n")


def main():
    variants = read_inputs()
    out = sys.stdout.write
    out("# reference/rolling.ref - what the rolling-resistance law tester is held to.\n")
    out("# GENERATED by reference/derive/rolling.py from cases/rolling/*.scene and\n")
    out("# cases/rolling/case.txt; do not edit by hand (make test checks that this file equals\n")
    out("# the script's output).  JYH = Jiang, Yu & Harris (2005).\n")
    walls = [p for p in variants.values() if p["kind"] == "wall"]
    ends = stage_ends(walls[0])
    out("# Wall variants, stages (cycles): " + ", ".join(f"{s} {a}-{b}" for s, (a, b) in ends.items()) + ".\n")
    for name, p in variants.items():
        b, km = constants(p)
        k, levels = nominal(p)
        theta0 = 2 * levels[0] * 6 / b / (p["kn"] * b)
        dtheta = max(abs(o) for _, _, _, o in p["moves"]) * p["dt"]
        out(f"# {name}: {p['kind']}, {p['model']}, r = {float(p['r']):g}, delta = {float(p['delta']):g}, "
            f"B = {float(b):g}, K_m = {float(k)!r}, M_0 = {', '.join(f(x) for x in levels)} at F_n = "
            f"{', '.join(f(x * 6 / b) for x in levels)} (nominal), theta_r0 = {float(theta0):.6g} = "
            f"{float(theta0 / dtheta):.2f} steps of {float(dtheta):g}.\n")
    out("\n")
    w = Writer(out)
    for name, p in variants.items():
        rows = hand(p)
        if p["kind"] == "pair":
            pair_checks(w, name, p, rows)
            continue
        assert stage_ends(p) == ends, "every wall variant has the same stages"
        if p["model"] == "model1":
            model1_checks(w, name, p, rows, ends)
        else:
            model2_checks(w, name, p, rows, ends)


def window(rows, first, last):
    return [r for r in rows if first <= r["cycle"] <= last]


FN_ROUNDING = ("Tolerance: F_n is known to u R/d = 3.4e-13 of itself (ballast's overlap is R minus a "
               "distance rounded to an ulp of R); a few ulps.")


def elastic_slope(w, label, variant, km, first, last, rows, what):
    span = window(rows, first, last)
    assert all(r["state"] == 0 for r in span[1:]) and len(span) > 50
    w.check(label, variant, f"fit_slope(between(theta_r, {first}, {last}), between(mr, {first}, {last}))",
            f"JYH eqs 28-29: M = K_m theta_r with K_m = k_n B^2/12 = {f(km)}, the least-squares slope of M "
            f"against theta_r over cycles {first}-{last}, {what}. Tolerance: round-off; M and theta_r "
            "are sums of at most 854 equal increments (K_m dtheta, dtheta), rounded to below N u = 1e-13.",
            f(km), f"rel {TOL_SLOPE:g}")


def model1_checks(w, v, p, rows, ends):
    b, km = constants(p)
    _, nominal_m0 = nominal(p)
    by = {r["cycle"]: r for r in rows}
    t1, bk, rs, t2, b2, rl = (ends[s] for s in ("twist", "back", "raise", "twist2", "back2", "release"))
    onsets = [caps(rows, *stage, 1) for stage in (t1, bk, t2, b2)]
    assert all(len(c) == 1 for c in onsets), "one plateau per twist"
    cap1, cap2, cap3, _ = (c[0] for c in onsets)
    # the slopes: loading from zero, unloading from the cap, and at F_n2 from -M_0(F_n1)
    elastic_slope(w, "slope_load", v, km, t1[0] - 1, cap1 - 1, rows,
                  "the first twist, from theta_r = 0 to the cap")
    elastic_slope(w, "slope_unload", v, km, t1[1], cap2 - 1, rows,
                  "unloading from +M_0 (the last capped cycle of the twist) through zero towards -M_0")
    elastic_slope(w, "slope_after_raise", v, km, rs[1], cap3 - 1, rows,
                  "after F_n was doubled: from -M_0(F_n1) up to +M_0(F_n2) (K_m does not depend on F_n)")
    # where the caps start
    for label, cycle, stage, what in (("cap_onset_load", cap1, t1, "the first twist, at F_n1"),
                                      ("cap_onset_after_raise", cap3, t2, "the twist after the raise, at F_n2")):
        r, prev = by[cycle], by[cycle - 1]
        trial = prev["m"] + km * (r["theta"] - prev["theta"])
        w.check(label, v, f"min(cycle[(state == 1) & (cycle >= {stage[0]})])",
                f"JYH eqs 33, 35: the moment reaches M_0 = F_n B/6 where K_m theta_r passes it, in {what}; "
                f"worked cycle by cycle along the wall's motion: M = {f(prev['m'])} < M_0 = {f(prev['m0'])} at "
                f"cycle {cycle - 1}, M_trial = {f(trial)} > M_0 = {f(r['m0'])} at cycle {cycle}. Tolerance: "
                "none, a cycle number; no cap falls within 1e-6 of a step's increment K_m dtheta (the "
                "derivation refuses that).", cycle, "abs 0")
    # the plateau on every capped cycle: M/F_n = B/6
    w.check("plateau_ratio_max", v, "max(abs(mr[state == 1]) / fn[state == 1])",
            f"JYH eqs 33a, 35b: on the plateau M = M_0 = F_n B/6 with the F_n of the same cycle, at both "
            f"normal forces and while the wall's turn raises F_n (the moment follows F_n); B/6 = {f(b / 6)}. "
            "The largest |M|/F_n over every capped cycle. Tolerance: M_0 and F_n carry the same rounding; "
            "a few u.", f(b / 6), f"rel {TOL_FN:g}")
    w.check("plateau_ratio_min", v, "min(abs(mr[state == 1]) / fn[state == 1])",
            "As plateau_ratio_max: the smallest |M|/F_n over every capped cycle.", f(b / 6), f"rel {TOL_FN:g}")
    # the plateau levels at the end of each twist, and the moment held while F_n rises
    for label, cycle, level, what in (
            ("plateau_F1_pos", t1[1], 0, "+M_0 at F_n1, end of the first twist"),
            ("plateau_F1_neg", bk[1], 0, "-M_0 at F_n1, end of the twist back"),
            ("plateau_F2_pos", t2[1], 1, "+M_0 at F_n2 = 2 F_n1, end of the twist after the raise"),
            ("plateau_F2_neg", b2[1], 1, "-M_0 at F_n2, end of the second twist back")):
        r = by[cycle]
        assert r["state"] == 1
        w.check(label, v, f"at(mr, {cycle})",
                f"JYH eq. 35b: M = M_0 = F_n B/6 ({what}), F_n = k_n d with d = p + (R - p)(1 - cos a) = "
                f"{f(r['d'])} for the wall at height p and angle a of cycle {cycle}: F_n = {f(r['fn'])}, "
                f"M_0 = {f(r['m0'])} (the nominal {f(nominal_m0[level])} at the press's overlap, before the "
                f"turn raised F_n). {FN_ROUNDING}", f(r["m"]), f"rel {TOL_FN:g}")
    r = by[rs[1]]
    assert r["m"] == by[bk[1]]["m"] and r["state"] == 0
    w.check("raise_holds_moment", v, f"at(mr, {rs[1]})",
            f"JYH eq. 28 read incrementally: M changes with theta_r only. Doubling F_n with the rotation "
            f"held raises the cap to M_0 = {f(r['m0'])} but leaves M at -M_0(F_n1) = {f(r['m'])}, the value "
            f"of cycle {bk[1]}. {FN_ROUNDING}", f(r["m"]), f"rel {TOL_FN:g}")
    # energies
    e1, last = by[t1[1]], rows[-1]
    theta0 = nominal_m0[0] / km
    w.check("dissipated_first_twist", v, f"at(d_roll, {t1[1]})",
            f"JYH eq. 35b: plastic rolling dissipates M_0 per unit of plastic rotation. Nominally, over the "
            f"first twist, M_0 (theta_r - theta_r0) = {f(nominal_m0[0])} x {f(e1['theta'] - theta0)} = "
            f"{f(nominal_m0[0] * (e1['theta'] - theta0))}; worked cycle by cycle as the sum of M_0 (|M_trial| "
            f"- M_0)/K_m, M_0 with the F_n of the cycle (the turn raises it): {f(e1['lost'])}. Tolerance: the "
            "rounding of M_0 enters each cycle's plastic rotation as the difference of consecutive cycles' "
            "errors, which telescopes over the plateau to the first and last: below 2 x 3.4e-13 of the "
            "loss.", f(e1["lost"]), f"rel {TOL_LOSS:g}")
    w.check("dissipated_total", v, "last(d_roll)",
            "JYH eq. 35b: every capped cycle dissipates M_0 (|M_trial| - M_0)/K_m, M_0 with the F_n of the "
            "cycle; summed over the four plateaus (two at F_n1, two at F_n2), worked cycle by cycle. "
            "Unloading and the raise dissipate nothing (elastic). Tolerance: as dissipated_first_twist.",
            f(last["lost"]), f"rel {TOL_LOSS:g}")
    step = km * (by[rl[0]]["theta"] - by[rl[0] - 1]["theta"])
    w.check("moment_released", v, "last(mr)",
            f"JYH eq. 28: the release turns back {rl[1] - rl[0] + 1} cycles from the plateau -M_0(F_n2) = "
            f"{f(by[b2[1]]['m'])}, each adding K_m dtheta = {f(step)}, so M ends at {f(last['m'])}, "
            f"{float(abs(last['m']) / step):.2f} increments from zero (the release turns back the nominal "
            "theta_r0 at F_n2; the turn had raised M_0 above its nominal value). Tolerance: absolute, 2e-12 of "
            "M_0(F_n2) (the plateau's rounding, carried over).",
            f(last["m"]), f"abs {TOL_FN * float(abs(by[b2[1]]['m'])):.3g}")
    energy_checks(w, v, p, rows, "the elastic part of the rolling spring has been unloaded (M = "
                  f"{f(last['m'])}), so the elastic energy is back to the normal spring's")


def model2_checks(w, v, p, rows, ends):
    b, km = constants(p)
    t1 = ends["twist"]
    cb = next(r["cycle"] for r in rows if r["state"] == 2)
    by = {r["cycle"]: r for r in rows}
    prev, r = by[cb - 1], by[cb]
    elastic_slope(w, "slope_load", v, km, t1[0] - 1, cb - 1, rows,
                  "the first twist, from theta_r = 0 until the rolling resistance is lost")
    trial = prev["m"] + km * (r["theta"] - prev["theta"])
    w.check("lost_at", v, "min(cycle[state == 2])",
            f"JYH eq. 36b: the rolling resistance is lost once theta_r > theta_r0 = 2 F_n/(k_n B): at cycle "
            f"{cb - 1} K_m theta_r = {f(prev['m'])} <= M_0 = {f(prev['m0'])}, at cycle {cb} K_m theta_r = "
            f"{f(trial)} > M_0 = {f(r['m0'])} (theta_r = {f(r['theta'])} > theta_r0 = {f(r['m0'] / km)}). "
            "Tolerance: none, a cycle number; the cap does not fall within 1e-6 of a step's increment.",
            cb, "abs 0")
    w.check("zero_after_loss", v, f"max(abs(after(mr, {cb - 1})))",
            "JYH eq. 36b: M = 0 from the loss on, through the twist back, the doubled F_n and the later "
            "twists (the contact never opens, so its width does not come back). Tolerance: none, the "
            "moment is set to zero.", "0", "abs 0")
    w.check("stays_lost", v, f"min(after(state, {cb - 1}))",
            "JYH eq. 36b: the contact stays flagged lost (contact_rolling = 2) on every later cycle. "
            "Tolerance: none, a flag.", "2", "abs 0")
    lost = rows[-1]["lost"]
    assert lost == r["lost"]
    w.check("lost_energy", v, "last(d_roll)",
            f"JYH eqs 28, 36b: when the width is lost, the rolling spring's energy M_trial^2/(2 K_m) = "
            f"K_m theta_b^2/2 of the cycle of the loss (theta_b = {f(r['theta'])}) goes to "
            f"dissipated_rolling: {f(lost)}, and nothing is added later. The continuum value is "
            f"M_0^2/(2 K_m) = F_n^2/(6 k_n) = {f(r['m0'] ** 2 / (2 * km))}: the scheme resolves the loss to "
            f"the first step past theta_r0, {float(r['theta'] / (r['m0'] / km) - 1):.2%} beyond it, so "
            f"{float(lost / (r['m0'] ** 2 / (2 * km)) - 1):.2%} more energy. "
            "Tolerance: round-off of theta_b, a sum of equal increments.", f(lost), f"rel {TOL_LOST:g}")
    energy_checks(w, v, p, rows, "the rolling spring is lost, so the elastic energy is the normal spring's")


def energy_checks(w, v, p, rows, what):
    b, km = constants(p)
    last = rows[-1]
    w.check("elastic_energy_end", v, "last(e_el)",
            f"JYH eq. 28 and MLH eq. 2: the stored energy is k_n d^2/2 + M^2/(2 K_m). At the end {what}: "
            f"k_n d^2/2 = {f(p['kn'] * last['d'] ** 2 / 2)} (d = {f(last['d'])}) plus M^2/(2 K_m) = "
            f"{f(last['m'] ** 2 / (2 * km))}. Tolerance: twice the overlap's relative rounding (3.4e-13).",
            f(last["e_el"]), f"rel {TOL_ENERGY:g}")
    w.check("elastic_energy_split", v,
            f"max(abs(e_el - fn ** 2 / {f(2 * p['kn'])} - mr ** 2 / {f(2 * km)}) / e_el)",
            "JYH eq. 28 and MLH eq. 2: on every cycle the elastic energy is the normal spring's F_n^2/(2 k_n) "
            "plus the rolling spring's M^2/(2 K_m) (the work of M = K_m theta_r), from the same cycle's F_n "
            "and M: the rolling energy is stored while elastic and goes when M does. The largest relative "
            "difference over all cycles. Tolerance: round-off of three products and two sums, a few u.",
            "0", f"abs {TOL_SPLIT:g}")


def pair_checks(w, v, p, rows):
    """The pair at a constant F_n: the closed forms of JYH hold as they stand (no wall turns)."""
    b, km = constants(p)
    fn = p["kn"] * p["d"]
    m0 = fn * b / 6
    theta0 = 2 * fn / (p["kn"] * b)                     # eq. 33b
    dtheta = rows[0]["theta"]
    onset = math.floor(theta0 / dtheta) + 1            # the first cycle with theta_r > theta_r0
    assert theta0 / dtheta - (onset - 1) > AMBIGUOUS and rows[onset - 1]["state"] != 0
    assert all(r["state"] == 0 for r in rows[:onset - 1])
    last = rows[-1]
    geometry = (f"r = 2 r1 r2/(r1 + r2) = {f(p['r'])} (eq. 9b), B = delta r = {f(b)} (eq. 24), F_n = k_n d = "
                f"{f(fn)} (d = {f(p['d'])}, constant: the flywheel neither moves nor slows)")
    w.check("slope_load", v, f"fit_slope(between(theta_r, 1, {onset - 1}), between(mr, 1, {onset - 1}))",
            f"JYH eqs 28-29 for two discs: M = K_m theta_r, K_m = k_n B^2/12 = {f(km)} with {geometry}. The "
            f"least-squares slope of M against theta_r over cycles 1-{onset - 1}, below theta_r0. Tolerance: "
            "round-off of sums of equal increments.", f(km), f"rel {TOL_SLOPE:g}")
    name = "cap_onset" if p["model"] == "model1" else "lost_at"
    state = 1 if p["model"] == "model1" else 2
    w.check(name, v, f"min(cycle[state == {state}])",
            f"JYH eq. 33b: theta_r0 = 2 F_n/(k_n B) = {f(theta0)} = {float(theta0 / dtheta):.4f} cycles of "
            f"dtheta = {f(dtheta)}, so the first cycle past it is {onset}; there Model "
            f"{'1 caps M (eq. 35b)' if state == 1 else '2 loses M (eq. 36b)'}. Tolerance: none, a cycle number.",
            onset, "abs 0")
    if p["model"] == "model1":
        for which, fn_ in (("max", "largest"), ("min", "smallest")):
            w.check(f"plateau_{which}", v, f"{which}(abs(mr[state == 1]))",
                    f"JYH eq. 35b: M = M_0 = F_n B/6 = {f(m0)} on every capped cycle ({geometry}); the {fn_} "
                    "|M| of them. Tolerance: the rounding of F_n B/6, a few u.", f(m0), "rel 1e-14")
        plastic = last["theta"] - theta0
        assert last["lost"] == m0 * plastic
        w.check("dissipated", v, "last(d_roll)",
                f"JYH eq. 35b: plastic rolling dissipates M_0 per unit of plastic rotation, exactly at a "
                f"constant F_n: M_0 (theta_r - theta_r0) = {f(m0)} x {f(plastic)} = {f(last['lost'])} (the "
                f"scheme dissipates the overshoot of the first capped cycle against M_0, so no step error). "
                "Tolerance: each cycle's plastic rotation (|M_trial| - M_0)/K_m is rounded to u M_0/(K_m "
                "dtheta) = 1.5e-14 of itself.", f(last["lost"]), "rel 1e-13")
        end = "M = M_0 at the end of the twist"
    else:
        w.check("zero_after_loss", v, f"max(abs(after(mr, {onset - 1})))",
                "JYH eq. 36b: M = 0 from the loss on (the contact never opens). Tolerance: none.", "0", "abs 0")
        w.check("stays_lost", v, f"min(after(state, {onset - 1}))",
                "JYH eq. 36b: the contact stays flagged lost (contact_rolling = 2). Tolerance: none.", "2", "abs 0")
        tb = rows[onset - 1]["theta"]
        w.check("lost_energy", v, "last(d_roll)",
                f"JYH eqs 28, 36b: the lost spring's energy K_m theta_b^2/2 at the first cycle past theta_r0, "
                f"theta_b = {onset} dtheta = {f(tb)}: {f(last['lost'])} (the continuum M_0^2/(2 K_m) = "
                f"F_n^2/(6 k_n) = {f(m0 ** 2 / (2 * km))}). Tolerance: round-off of theta_b.",
                f(last["lost"]), f"rel {TOL_LOST:g}")
        end = "M = 0 after the loss"
    w.check("elastic_energy_end", v, "last(e_el)",
            f"JYH eq. 28 and MLH eq. 2: the stored energy is k_n d^2/2 + M^2/(2 K_m), {end}: "
            f"{f(last['e_el'])}. Tolerance: a few u.", f(last["e_el"]), "rel 1e-14")
    w.check("elastic_energy_split", v,
            f"max(abs(e_el - fn ** 2 / {f(2 * p['kn'])} - mr ** 2 / {f(2 * km)}) / e_el)",
            "JYH eq. 28 and MLH eq. 2: on every cycle E_el = F_n^2/(2 k_n) + M^2/(2 K_m). Tolerance: "
            "round-off of three products and two sums, a few u.", "0", f"abs {TOL_SPLIT:g}")


def print_cycles(name):
    p = read_inputs()[name]
    print("cycle\tstage\ttheta_r\td\tfn\tm0\tm\tstate\tlost\te_el")
    for r in hand(p):
        print("\t".join([str(r["cycle"]), r["stage"]] + [repr(float(r[k])) for k in
                        ("theta", "d", "fn", "m0", "m")] + [str(r["state"]), repr(float(r["lost"])),
                                                            repr(float(r["e_el"]))]))


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--cycles":
        print_cycles(sys.argv[2])
    else:
        main()
