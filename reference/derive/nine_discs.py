#!/usr/bin/python3
"""Derive the reference values of the nine-disc cases (reference/nine_discs.ref).

This script is the provenance of the numbers in reference/nine_discs.ref.  It never
runs ballast.  It builds the linear spring network of Cundall & Strack's nine-disc
assembly (3 x 3 discs touching each other and four walls; normal springs k_n along the
line of centres, shear springs k_s at the contact with the rotation term of eq. 13,
three degrees of freedom per disc) and from it computes:

  * the exact static solution after the walls have moved inward by w: contact forces,
    in particular F_eq at contact C (d22-d23) and F_s/F_n at the corner-wall contact;
  * the eigenfrequencies of the network (M^-1 K) and the modes the symmetric
    compression excites;
  * the undamped response, integrated with the time-centred recurrence of C&S eqs
    (20)-(23a) applied to the linear system (u_N, v_{N-1/2}), cycle by cycle with the
    same wall motion as the scene: the mean, half-range and zero-crossing period of F_n
    at C over the same windows the checks use.

The linear model differs from the DEM only by geometric non-linearity: overlaps are
below 6e-4 of a radius and contact normals turn by less than 1e-4 rad, so relative
differences of order 1e-3 are the stated tolerance.  It holds while no contact slides,
which the references check (n_sliding = 0) wherever they rely on it.

Inputs are the numbers of cases/nine_discs/nine_discs.scene and the `set` lines of
cases/nine_discs/case.txt, read here with a minimal reader so the two cannot disagree.

Usage: reference/derive/nine_discs.py > reference/nine_discs.ref
"""
import math
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
CASE_DIR = os.path.join(HERE, "..", "..", "cases", "nine_discs")

TAN30 = 0.5773502691896258
TAN15 = 0.2679491924311227


# ---------------------------------------------------------------- inputs

def read_ini(path):
    """[kind name] sections -> {key: [values]}; '#' comments."""
    sections, order, cur = {}, [], None
    for raw in open(path):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        if line.startswith("["):
            cur = line.strip("[]").strip()
            sections[cur] = {}
            order.append(cur)
            continue
        key, value = (t.strip() for t in line.split("=", 1))
        sections[cur].setdefault(key, []).append(value)
    return sections, order


def variant_params(scene, case_txt, variant):
    """The parameters of one variant: scene values overridden by its `set` lines."""
    p = {
        "dt": float(scene["settings"]["dt"][0]),
        "kn": float(scene["material disc"]["kn"][0]),
        "ks": float(scene["material disc"]["ks"][0]),
        "rho": float(scene["material disc"]["density"][0]),
        "r": float(scene["disc d11"]["r"][0]),
        "load": int(scene["stage load"]["cycles"][0]),
        "hold": int(scene["stage hold"]["cycles"][0]),
        "distort": int(scene["stage distort"]["cycles"][0]),
        "v": float(scene["stage load"]["move"][0].split()[2]),   # bottom moves up at v
        "friction": float(scene["material disc"]["friction"][0]),
    }
    for entry in case_txt[f"variant {variant}"].get("set", []):
        key, value = entry.split("=", 1)
        if key == "settings.dt":
            p["dt"] = float(value)
        elif key == "material.disc.kn":
            p["kn"] = float(value)
        elif key == "material.disc.ks":
            p["ks"] = float(value)
        elif key == "material.disc.friction":
            p["friction"] = float(value)
        elif key == "stage.load.cycles":
            p["load"] = int(value)
        elif key == "stage.hold.cycles":
            p["hold"] = int(value)
        elif key == "stage.distort.cycles":
            p["distort"] = int(value)
        elif key == "stage.load.move" and value.startswith("bottom"):
            p["v"] = float(value.split()[2])
    return p


# ---------------------------------------------------------------- the spring network

WALL_NORMAL = {"bottom": (0.0, -1.0), "top": (0.0, 1.0), "left": (-1.0, 0.0), "right": (1.0, 0.0)}


def network(r):
    """Disc centres, and contacts (a, b) with b a disc or a wall name."""
    pos = {f"d{i}{j}": np.array([r + 2 * r * (j - 1), r + 2 * r * (i - 1)])
           for i in range(1, 4) for j in range(1, 4)}
    names = sorted(pos)
    contacts = [(a, b) for a in names for b in names
                if a < b and abs(np.linalg.norm(pos[a] - pos[b]) - 2 * r) < 1e-9]
    for a in names:
        x, y = pos[a]
        contacts += [(a, w) for w, hit in (("bottom", y == r), ("top", y == 5 * r),
                                           ("left", x == r), ("right", x == 5 * r)) if hit]
    return pos, names, contacts


def assemble(p):
    """K, M, the load per unit inward wall displacement b, and per contact the rows
    (Bn, Bs, cn, cs) with F_n = k_n (Bn.u + cn w), F_s = k_s (Bs.u + cs w)."""
    r = p["r"]
    pos, names, contacts = network(r)
    idx = {n: i for i, n in enumerate(names)}
    n = 3 * len(names)
    K, b = np.zeros((n, n)), np.zeros(n)
    rows = {}
    for a, other in contacts:
        ia = idx[a]
        Bn, Bs = np.zeros(n), np.zeros(n)
        if other in WALL_NORMAL:
            e = np.array(WALL_NORMAL[other])          # from the disc to the wall
            uw = -e                                    # unit inward wall displacement
            cn, cs = -uw @ e, -uw @ np.array([e[1], -e[0]])
        else:
            e = (pos[other] - pos[a]) / (2 * r)
            ib = idx[other]
            cn = cs = 0.0
        t = np.array([e[1], -e[0]])
        # Relative displacement of a with respect to b (C&S eqs 12-13).
        Bn[3 * ia:3 * ia + 2], Bs[3 * ia:3 * ia + 2], Bs[3 * ia + 2] = e, t, -r
        if other not in WALL_NORMAL:
            Bn[3 * ib:3 * ib + 2], Bs[3 * ib:3 * ib + 2], Bs[3 * ib + 2] = -e, -t, -r
        K += p["kn"] * np.outer(Bn, Bn) + p["ks"] * np.outer(Bs, Bs)
        b -= p["kn"] * cn * Bn + p["ks"] * cs * Bs
        rows[(a, other)] = (Bn, Bs, cn, cs)
    m = p["rho"] * math.pi * r * r
    M = np.tile([m, m, 0.5 * m * r * r], len(names))
    return K, M, b, rows


def forces(p, rows, u, w, key):
    Bn, Bs, cn, cs = rows[key]
    return p["kn"] * (Bn @ u + cn * w), p["ks"] * (Bs @ u + cs * w)


def static(p):
    """Exact static state after the walls moved load*v*dt inward."""
    K, M, b, rows = assemble(p)
    w = p["load"] * p["v"] * p["dt"]
    u = np.linalg.solve(K, b * w)
    return {key: forces(p, rows, u, w, key) for key in rows}, w


def modes(p):
    """Eigenfrequencies of M^-1 K excited by the symmetric load, strongest first."""
    K, M, b, _ = assemble(p)
    s = 1 / np.sqrt(M)
    vals, vecs = np.linalg.eigh(s[:, None] * K * s[None, :])
    load = s * b
    part = np.abs(vecs.T @ load)
    keep = part > 1e-9 * part.max()
    order = np.argsort(-part[keep])
    return np.sqrt(vals[keep][order]), part[keep][order] / part.max()


def time_centred(p):
    """F_n at C, cycle by cycle, of the linear network under the scene's wall motion."""
    K, M, b, rows = assemble(p)
    dt, v = p["dt"], p["v"]
    u, vel, w = np.zeros(K.shape[0]), np.zeros(K.shape[0]), 0.0
    fc = []
    for cycle in range(1, p["load"] + p["hold"] + 1):
        u = u + vel * dt                               # eq. (22a)
        w = w + (v * dt if cycle <= p["load"] else 0)  # walls move to t_N
        f = b * w - K @ u
        vel = vel + f / M * dt                         # eq. (22)
        fc.append(forces(p, rows, u, w, ("d22", "d23"))[0])
    return np.array(fc)


def window_stats(fc, start):
    """mean, half-range and mean period (cycles) of fc over cycles > start."""
    x = fc[start:]
    y = x - x.mean()
    up = np.flatnonzero((y[:-1] < 0) & (y[1:] >= 0))
    return x.mean(), (x.max() - x.min()) / 2, float(np.mean(np.diff(up)))


# ---------------------------------------------------------------- output

def check(out, name, case, variant, quantity, kind, provenance, value=None, tolerance=None,
          lo=None, hi=None, variants=None):
    out(f"[check {name}]\ncase = {case}\n")
    out(f"variants = {variants}\n" if variants else f"variant = {variant}\n")
    out(f"quantity = {quantity}\n")
    if value is not None:
        out(f"value = {value!r}\n")
    if lo is not None:
        out(f"lo = {lo!r}\n")
    if hi is not None:
        out(f"hi = {hi!r}\n")
    out(f"tolerance = {tolerance}\nkind = {kind}\nprovenance = {provenance}\n\n")


LINEAR = ("Linear spring network of the same nine discs solved by reference/derive/nine_discs.py "
          "(normal and shear springs, disc rotations; independent of ballast). Tolerance 1e-3: the "
          "linear model neglects overlaps (< 6e-4 R) and the turning of contact normals (< 1e-4 rad).")


def damping_checks(out, scene, case_txt):
    case = "nine_discs_damping"
    p = variant_params(scene, case_txt, "both")
    st, w = static(p)
    f_eq = st[("d22", "d23")][0]
    fn_w, fs_w = st[("d11", "bottom")]
    out(f"# {case}: k_n = k_s = {p['kn']:g}, tan phi = {p['friction']:g}, dt = {p['dt']:g}, "
        f"walls moved {w!r} inward.\n# Exact static F_eq at C = {f_eq!r}; "
        f"corner-wall F_s/F_n = {fs_w / fn_w!r}.\n\n")
    for v in ("both", "contact_only", "global_only"):
        check(out, f"{v}_eq_C", case, v, "last(Fn_C)", "exact",
              "C&S p. 55: 'the damping does not affect the equilibrium value of the force'. F_eq from "
              "the exact static solution. " + LINEAR, value=f_eq, tolerance="rel 1e-3")
    for v in ("undamped", "both", "contact_only", "global_only"):
        check(out, f"{v}_no_sliding", case, v, "max(n_sliding)", "exact",
              "Precondition of the exact solution, which assumes sticking contacts: with tan phi = 1 "
              f"the largest static F_s/F_n is {abs(fs_w / fn_w):.4f} (corner-wall), so no contact may "
              "slide.", tolerance="interval", hi=0.0)
    check(out, "wall_shear", case, "both", "last(Fs_wall) / last(Fn_wall)", "exact",
          "C&S p. 55: 'shear forces appear along the walls as a result of relative movement between "
          "discs and walls, even though the walls move towards each other uniformly.' F_s/F_n at the "
          "contact of corner disc d11 with the bottom wall, from the exact static solution. " + LINEAR,
          value=fs_w / fn_w, tolerance="rel 1e-3")

    pu = variant_params(scene, case_txt, "undamped")
    mean, amp, period = window_stats(time_centred(pu), pu["load"])
    out(f"# undamped: the linear recurrence gives mean {mean!r}, half-range {amp!r} "
        f"({amp / f_eq:.4f} F_eq), period {period:.4f} cycles.\n\n")
    check(out, "undamped_mean", case, "undamped", f"mean(after(Fn_C, {pu['load']}))", "exact",
          "C&S p. 55: 'The force oscillates about the equilibrium value F_eq'. Mean of F_n at C after "
          "the walls stop, from the linear network integrated with the time-centred scheme of eqs "
          "(20)-(23a) cycle by cycle. " + LINEAR, value=mean, tolerance="rel 1e-3")
    check(out, "undamped_amplitude", case, "undamped", f"amp(after(Fn_C, {pu['load']}))", "exact",
          "Half-range of the undamped oscillation at C after the stop, from the same linear "
          "recurrence. Tolerance 5e-3: sampled extremes of a two-mode signal shift by more than its "
          "mean does. " + LINEAR, value=amp, tolerance="rel 5e-3")
    p30 = variant_params(scene, case_txt, "undamped_phi30")
    check(out, "undamped_amplitude_paper", case, "undamped_phi30",
          f"amp(after(Fn_C, {p30['load']})) / mean(after(Fn_C, {p30['load']}))", "paper",
          "C&S p. 55, Fig. 6 curve 1: 'The force oscillates about the equilibrium value F_eq with an "
          "amplitude of approximately 0.15 F_eq.' With the paper's tan 30 deg. Tolerance +-0.05: a value "
          "read off a figure, for a time step the paper does not give (the amplitude scales with "
          "|sin(omega T/2)|/(omega T/2), T = 40 dt). With tan phi = 1 (no sliding) ballast gives the "
          f"larger {amp / f_eq:.3f} F_eq (undamped_amplitude): sliding at the corner-wall contacts during "
          "the overshoot dissipates energy.", tolerance="interval", lo=0.10, hi=0.20)
    for v in ("both", "contact_only", "global_only"):
        check(out, f"{v}_settled", case, v, f"amp(after(Fn_C, {pu['load'] + pu['hold'] - 200})) / {f_eq!r}",
              "analytic", "With a modal damping ratio of about 0.2 at omega = 21.1 the oscillation decays as "
              "exp(-4.2 t); after t = 13 it is below 1e-20 of F_eq. Tolerance 1e-4 leaves room for the "
              "geometric non-linearity. C&S p. 55: damping 'does, however, reduce the number of "
              "calculation cycles needed to reach equilibrium.'", tolerance="interval", hi=1e-4)
    check(out, "undamped_persists", case, "undamped",
          f"amp(after(Fn_C, {pu['load'] + pu['hold'] - 200})) / {f_eq!r}", "analytic",
          "Without damping and without sliding nothing dissipates energy (C&S p. 53: 'Energy is "
          "dissipated in the model only through friction, contact and global damping'), so the "
          f"oscillation keeps its amplitude ({amp / f_eq:.3f} F_eq by the linear recurrence); at least "
          "half of it must remain.", tolerance="interval", lo=0.5 * amp / f_eq)
    check(out, "separate_damping_alike", case, "contact_only",
          f"settle(Fn_C, {f_eq!r}, 0.01) / settle(series('global_only', 'Fn_C'), {f_eq!r}, 0.01)", "paper",
          "C&S p. 55: 'Similar curves are obtained if contact and global damping are used separately.' "
          "Cycles until F_n at C stays within 1 % of F_eq, contact damping alone over global damping "
          "alone, both set to a modal damping ratio of 0.2 (case.txt). Tolerance: within a factor 2.",
          tolerance="interval", lo=0.5, hi=2.0)
    return f_eq


def speed_checks(out, scene, case_txt, f_eq):
    case = "nine_discs_speed"
    pairs = (("k135_v004", "k135_v012"), ("k15_v012", "k15_v036"))
    stats = {}
    for slow, fast in pairs:
        for v in (slow, fast):
            p = variant_params(scene, case_txt, v)
            mean, amp, period = window_stats(time_centred(p), p["load"])
            om, part = modes(p)
            omega_d = 2 / p["dt"] * math.asin(om[0] * p["dt"] / 2)
            stats[v] = (p, mean, amp, period, om[0], omega_d)
            st, _ = static(p)
            out(f"# {v}: k_n = {p['kn']:g}, dt = {p['dt']:g}, v = {p['v']:g} for {p['load']} cycles; "
                f"static F_C = {st[('d22', 'd23')][0]!r}; dominant mode omega = {om[0]!r} "
                f"(next {om[1]!r}, weight {part[1]:.3f}); linear recurrence: mean {mean!r}, "
                f"half-range {amp!r}, period {period!r} cycles.\n")
    out("\n")
    for v, (p, mean, amp, period, omega, omega_d) in stats.items():
        start = p["load"]
        check(out, f"{v}_mean", case, v, f"mean(after(Fn_C, {start}))", "exact",
              "Each speed is loaded to the same equilibrium force (C&S p. 56: 'The deformations for the "
              "two tests have been chosen such that about the same equilibrium force results'). Mean "
              "of F_n at C after loading, from the linear recurrence. " + LINEAR,
              value=mean, tolerance="rel 1e-3")
        check(out, f"{v}_amplitude", case, v, f"amp(after(Fn_C, {start}))", "exact",
              "Half-range of the oscillation after loading, from the linear recurrence. Tolerance 5e-3 "
              "as for nine_discs_damping. " + LINEAR, value=amp, tolerance="rel 5e-3")
        check(out, f"{v}_period", case, v, f"period(after(Fn_C, {start}))", "analytic",
              "C&S p. 56: 'whereas the frequencies are about the same'. The period in cycles of the "
              f"dominant symmetric mode, omega = {omega:.5f} from the stiffness and mass matrices, with "
              f"the time-centred scheme's frequency omega_d = (2/dt) asin(omega dt/2) = {omega_d:.5f}: "
              f"2 pi/(omega_d dt). Tolerance 1 %: a second mode (weight about 0.17) shifts the "
              "crossings.", value=2 * math.pi / (omega_d * p["dt"]), tolerance="rel 1e-2")
    for slow, fast in pairs:
        check(out, f"amplitude_grows_{fast}", case, None,
              f"amp(after(Fn_C, last(cycle) - 800))", "paper",
              "C&S p. 56: 'the amplitude of the oscillations occurring at the end of loading increases "
              "with the speed of loading.' Half-range over the last 800 cycles, slow then fast.",
              tolerance="trend increasing", variants=f"{slow} {fast}")


def distortion_checks(out, scene, case_txt):
    case = "nine_discs_distortion"
    for v in ("ks23_phi15", "ks1_phi15", "ks23_phi30", "ks1_phi30"):
        p = variant_params(scene, case_txt, v)
        check(out, f"{v}_coulomb", case, v,
              f"max(abs(Fs_C) - {p['friction']!r} * Fn_C) / max(Fn_C)", "analytic",
              "C&S eq. (19): |F_s| <= F_n tan phi_mu + c, c = 0, at contact C over the whole test. "
              "Tolerance: round-off of the cap (1e-12 of the largest force).",
              tolerance="interval", hi=1e-12)
    p = variant_params(scene, case_txt, "ks1_phi30")
    start = p["load"] + p["hold"]
    half = start + p["distort"] // 2
    check(out, "phi15_Fn_coincide", case, "ks1_phi15",
          f"max(abs(after(Fn_C, {start}) - after(series('ks23_phi15', 'Fn_C'), {start}))) / max(Fn_C)",
          "paper", "C&S p. 56: 'The curves for k_s/k_n = 2/3 and k_s/k_n = 1 nearly coincide for the case "
          "that phi_mu = 15 deg.' Largest difference of F_n at C during distortion, over the largest F_n. "
          "'Nearly coincide' is taken as within 5 %.", tolerance="interval", hi=0.05)
    check(out, "phi15_Fs_coincide_after_slip", case, "ks1_phi15",
          f"max(abs(after(Fs_C, {half}) - after(series('ks23_phi15', 'Fs_C'), {half}))) / max(abs(Fs_C))",
          "paper", "C&S p. 56: 'slip sets in early and controls the shear force for a major portion of "
          "the test; as soon as slip sets in, the shear force is determined solely by the normal "
          "force.' Largest difference of F_s at C over the second half of the distortion, over the "
          "largest |F_s|; within 5 %.", tolerance="interval", hi=0.05)
    check(out, "phi30_separate", case, "ks1_phi30",
          f"max(abs(after(Fn_C, {start}) - after(series('ks23_phi30', 'Fn_C'), {start}))) / max(Fn_C)",
          "paper", "C&S p. 56: for phi_mu = 30 deg 'the curves for k_s/k_n = 2/3 and for k_s/k_n = 1 are "
          "seen to deviate significantly'. The same measure as phi15_Fn_coincide must exceed its 5 %.",
          tolerance="interval", lo=0.05)
    check(out, "phi30_compression_lower", case, "ks1_phi30",
          f"at(Fn_C, {start}) / at(series('ks23_phi30', 'Fn_C'), {start})", "paper",
          "C&S p. 56: 'For the case of the high shear stiffness, k_s/k_n = 1, the value for F_n resulting "
          "from undistorted compression is less than for the case that k_s/k_n = 2/3'. Ratio at the "
          "start of distortion below 1.", tolerance="interval", hi=1.0)
    check(out, "phi30_exceeds_later", case, "ks1_phi30",
          f"max(after(Fn_C, {start}) - after(series('ks23_phi30', 'Fn_C'), {start})) / max(Fn_C)", "paper",
          "C&S p. 56: 'as shearing proceeds, the normal force for the case that k_s/k_n = 1 increases "
          "beyond the one for k_s/k_n = 2/3'. Largest excess during distortion, over the largest F_n; "
          "at least 1 %.", tolerance="interval", lo=0.01)
    check(out, "phi30_slip_at_C", case, "ks1_phi30", "last(Sl_C)", "paper",
          "C&S p. 56: '... to reach a maximum ... after which slip sets in'. Contact C slides at the end "
          "of the distortion.", tolerance="interval", lo=1.0, hi=1.0)
    check(out, "phi30_falls_back", case, "ks1_phi30", "(max(Fn_C) - last(Fn_C)) / max(Fn_C)", "paper",
          "C&S p. 56: '... after which slip sets in and the force falls back.' F_n at C ends below its "
          "maximum. (The paper's maximum, 25.6e8, is not comparable: its compression before distortion "
          "is not given; ballast's is about 3.7e7 after 40 cycles at 0.12.)",
          tolerance="interval", lo=1e-6)
    check(out, "wall_shear_grows_with_ks", case, "ks1_phi30",
          f"abs(at(Fs_wall, {start})) / abs(at(series('ks23_phi30', 'Fs_wall'), {start}))", "paper",
          "C&S p. 56: 'shear stresses develop at the boundaries as a result of movement of discs along the "
          "walls. These shear stresses carry part of the load and are higher, the higher the ratio of "
          "k_s to k_n.' Corner-wall shear force at the end of compression, k_s/k_n = 1 over 2/3.",
          tolerance="interval", lo=1.0)


def main():
    scene, _ = read_ini(os.path.join(CASE_DIR, "nine_discs.scene"))
    case_txt, _ = read_ini(os.path.join(CASE_DIR, "case.txt"))
    out = sys.stdout.write
    out("# reference/nine_discs.ref — what the nine-disc cases are held to (C&S 1979, Figs 5-9).\n")
    out("# GENERATED by reference/derive/nine_discs.py from cases/nine_discs/; do not edit by hand\n")
    out("# (make test checks that this file equals the script's output).\n\n")
    f_eq = damping_checks(out, scene, case_txt)
    speed_checks(out, scene, case_txt, f_eq)
    distortion_checks(out, scene, case_txt)


if __name__ == "__main__":
    main()
