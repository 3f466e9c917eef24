#!/usr/bin/python3
"""Derive the reference values of the coulomb case (reference/coulomb.ref).

This script is the provenance of the numbers in reference/coulomb.ref.  It does not run
ballast.  It reads the few numbers it needs from cases/coulomb/spin.scene and
cases/coulomb/packing.scene (with a minimal reader, so they cannot disagree) and works the
law of Cundall & Strack (1979) by hand:

1. spin.scene.  Disc b (radius r, mass m = rho pi r^2, I = m r^2 / 2) is pressed between
   the held discs a and c with the same overlap delta = 2 r - y_b at both contacts, spinning
   at omega_0 (the scene's omega: C&S eq. 22 gives velocities at half steps, so omega_0 is
   omega_{1/2}).  The power law with nu = 1 gives F_n = k_n delta at both contacts (MLH
   eq. 2); the normal forces on b cancel, so b stays put and delta stays.  The tangent is
   t = (1, 0) at both contacts and the held discs do not turn, so both see the slip rate
   s' = -omega r (C&S eq. 13), and in cycle N the shear spring would reach
   F_s = F_s,prev - k_s omega_{N-1/2} r dt (eq. 18).  Cycle 1 starts from F_s = 0 and the
   increment k_s omega_0 r dt is above the cap F_max = F_n tan(phi) (eq. 19, c = 0): it is
   capped at -F_max, and every later cycle adds to it while omega > 0, so both contacts
   slide in every cycle, each giving b the moment -F_max r.  Hence, with the time-centred
   update (C&S eq. 23),
       omega_{N+1/2} = omega_0 - N alpha dt,   alpha = 2 F_max r / I,
   until omega would change sign; the series reports omega_N = (omega_{N-1/2} +
   omega_{N+1/2})/2 = omega_0 - (N - 1/2) alpha dt.  The capped spring gives up the slip
   (|F_s| - F_max)/k_s against F_max: in cycle 1, F_max (k_s omega_0 r dt - F_max)/k_s; in
   cycle n > 1, F_max omega_{n-1/2} r dt; two contacts, so after N cycles the friction loss is
       2 F_max (k_s omega_0 r dt - F_max)/k_s + 2 F_max r dt sum_{n=2..N} (omega_0 - (n-1) alpha dt).
2. packing.scene.  Every sliding contact carries |F_s| = F_n tan(phi) + c (eq. 19), whatever
   the packing does: the cap sets F_s to F_max with its sign.

The tolerances: the closed forms above are exact for the scheme; what separates ballast's
numbers from them is the rounding of each cycle's operations, at most N ulps of omega_0 after
N cycles (1000 x 2.8e-14 here), far below 1e-10 relative; a 10 % change of the cap changes
every quantity by about 10 %.

Usage: reference/derive/coulomb.py > reference/coulomb.ref
"""
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
CASE_DIR = os.path.join(HERE, "..", "..", "cases", "coulomb")
SPIN = os.path.join(CASE_DIR, "spin.scene")
PACKING = os.path.join(CASE_DIR, "packing.scene")

ROUNDOFF = 1e-10    # relative: the rounding of 1000 cycles against a difference of O(100)
EXACT = 1e-12       # absolute, on ratios and counts of order 1: a few operations' rounding
LEAST_SLIDING = 20  # the packing's guard: a quarter of the 77 measured at the time of writing


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


def number(sc, section, key, default=None):
    if key not in sc.get(section, {}):
        return default
    return float(sc[section][key][0])


def spin():
    """The spin scene's numbers and the closed forms of item 1."""
    sc = read_ini(SPIN)
    assert sc["settings"]["normal_law"] == ["power"] and number(sc, "settings", "nu") == 1
    assert number(sc, "settings", "beta") == 0 and number(sc, "settings", "alpha") == 0
    assert "gravity" not in sc["settings"]
    mat = "material " + sc["disc b"]["material"][0]
    kn, ks = number(sc, mat, "kn"), number(sc, mat, "ks")
    tan_phi, coh = number(sc, mat, "friction"), number(sc, mat, "cohesion", 0.0)
    assert coh == 0
    rho = number(sc, mat, "density")
    r = number(sc, "disc b", "r")
    assert number(sc, "disc a", "r") == r and number(sc, "disc c", "r") == r
    ya = [float(t) for t in sc["disc a"]["x"][0].split()][1]
    yb = [float(t) for t in sc["disc b"]["x"][0].split()][1]
    yc = [float(t) for t in sc["disc c"]["x"][0].split()][1]
    assert ya == 0 and yc - yb == yb      # the same overlap at both contacts
    omega0 = number(sc, "disc b", "omega")
    dt = number(sc, "settings", "dt")
    cycles = int(number(sc, "stage spin", "cycles"))
    delta = 2 * r - yb
    fn = kn * delta
    fmax = fn * tan_phi
    m = rho * math.pi * r * r
    inertia = m * r * r / 2
    alpha = 2 * fmax * r / inertia
    assert ks * omega0 * r * dt > fmax, "the cap must act from the first cycle"
    assert omega0 - cycles * alpha * dt > 0, "the run must end before the disc stops"
    loss = 2 * fmax * (ks * omega0 * r * dt - fmax) / ks
    loss += 2 * fmax * r * dt * sum(omega0 - (n - 1) * alpha * dt for n in range(2, cycles + 1))
    return dict(kn=kn, ks=ks, tan_phi=tan_phi, r=r, m=m, inertia=inertia, omega0=omega0, dt=dt,
                cycles=cycles, delta=delta, fn=fn, fmax=fmax, alpha=alpha, yb=yb, loss=loss)


def packing():
    sc = read_ini(PACKING)
    mat = "material " + sc["fill pack"]["material"][0]
    return dict(tan_phi=number(sc, mat, "friction"), coh=number(sc, mat, "cohesion", 0.0),
                n=int(number(sc, "fill pack", "n")))


def check(name, variant, quantity, provenance, value=None, tolerance=None, lo=None, hi=None):
    lines = [f"[check {name}]", "case = coulomb", f"variant = {variant}", f"quantity = {quantity}"]
    if value is not None:
        lines.append(f"value = {value!r}")
    if lo is not None:
        lines.append(f"lo = {lo!r}")
    if hi is not None:
        lines.append(f"hi = {hi!r}")
    lines += [f"tolerance = {tolerance}", "kind = analytic", f"provenance = {provenance}", ""]
    print("\n".join(lines))


def main():
    s, p = spin(), packing()
    first, last = 100, s["cycles"]
    omega_last = s["omega0"] - (last - 0.5) * s["alpha"] * s["dt"]
    print("# reference/coulomb.ref — what the coulomb case is held to.")
    print("# GENERATED by reference/derive/coulomb.py from cases/coulomb/spin.scene and")
    print("# packing.scene; do not edit by hand (make test checks that this file equals the script's output).")
    print(f"# spin: delta = {s['delta']!r}, F_n = k_n delta = {s['fn']!r}, F_max = tan(phi) F_n = {s['fmax']!r};")
    print(f"#   m = {s['m']!r}, I = {s['inertia']!r}, alpha = 2 F_max r / I = {s['alpha']!r};")
    print(f"#   omega_N = omega_0 - (N - 1/2) alpha dt: slope {-s['alpha'] * s['dt']!r}, "
          f"intercept {s['omega0'] + 0.5 * s['alpha'] * s['dt']!r} (the figure's line);")
    print(f"#   the disc would stop at cycle {s['omega0'] / (s['alpha'] * s['dt']):.1f}; the run ends at {last}.")
    print()
    eq19 = ("C&S 1979 eq. (19): |F_s| is capped at F_max = F_n tan(phi_mu) + c, the sign kept; "
            "reference/derive/coulomb.py, item 1")
    check("spin_normal_force_max", "spin", "max(max(fn_ab), max(fn_bc))",
          f"MLH eq. (2) with nu = 1: F_n = k_n delta = {s['kn']:g} x {s['delta']!r} at both contacts "
          "in every cycle (disc b does not move). Tolerance: one product's rounding.",
          value=s["fn"], tolerance="rel 1e-12")
    check("spin_normal_force_min", "spin", "min(min(fn_ab), min(fn_bc))",
          "As spin_normal_force_max: the least F_n of both contacts over the run.",
          value=s["fn"], tolerance="rel 1e-12")
    check("spin_cap_every_cycle", "spin",
          f"max(max(abs(abs(fs_ab) / fn_ab - {s['tan_phi']!r})), max(abs(abs(fs_bc) / fn_bc - {s['tan_phi']!r})))",
          f"{eq19}: both contacts slide in every cycle (the first increment k_s omega_0 r dt = "
          f"{s['ks'] * s['omega0'] * s['r'] * s['dt']:g} is above F_max = {s['fmax']:g}, and omega stays "
          "positive), so |F_s|/F_n = tan(phi) in every row. Tolerance: the rounding of one multiply "
          "and one divide; a 10 % change of the cap gives 0.05.",
          value=0.0, tolerance=f"abs {EXACT!r}")
    check("spin_both_slide", "spin", "min(sliding)",
          f"{eq19}: both contacts of disc b slide in every cycle (n_sliding = 2 on every row).",
          value=2.0, tolerance="abs 0")
    check("spin_disc_stays", "spin", "max(abs(x_b)) + max(abs(y_b - " + repr(s["yb"]) + "))",
          "The normal forces on b (and its two shear forces) are computed from the same doubles at "
          "both contacts and are equal and opposite: b's centre does not move at all.",
          value=0.0, tolerance=f"abs {EXACT!r}")
    check("spin_deceleration", "spin",
          f"(at(omega_b, {first}) - at(omega_b, {last})) / ({last - first} * run('dt'))",
          f"{eq19}: each contact gives b the moment -F_max r, so omega falls at alpha = 2 F_max r / I = "
          f"{s['alpha']!r} (I = rho pi r^4 / 2). Tolerance: the rounding of {last} cycles, at most "
          f"{last} ulps of omega_0 against a difference of {s['alpha'] * (last - first) * s['dt']:.1f}.",
          value=s["alpha"], tolerance=f"rel {ROUNDOFF!r}")
    check("spin_omega_end", "spin", f"at(omega_b, {last})",
          f"{eq19} and the time-centred update (C&S eq. 23): omega_(N+1/2) = omega_0 - N alpha dt from "
          "omega_(1/2) = omega_0 (the scene's omega, C&S eq. 22), and the series reports the mean of the "
          f"two half steps: omega_N = omega_0 - (N - 1/2) alpha dt at N = {last}. Tolerance as "
          "spin_deceleration.",
          value=omega_last, tolerance=f"rel {ROUNDOFF!r}")
    check("spin_friction_loss", "spin", "last(friction)",
          f"{eq19}: the capped spring gives up the slip (|F_s| - F_max)/k_s against F_max: "
          "F_max (k_s omega_0 r dt - F_max)/k_s in cycle 1 and F_max omega_(n-1/2) r dt in cycle n > 1, at "
          f"two contacts, summed over the {last} cycles (reference/derive/coulomb.py). Tolerance as "
          "spin_deceleration.",
          value=s["loss"], tolerance=f"rel {ROUNDOFF!r}")
    check("spin_final_cap", "spin", f"coulomb_error({s['tan_phi']!r})",
          f"{eq19}: in the final state (contacts.tsv) both disc-disc contacts slide, at |F_s| = "
          "F_n tan(phi). Tolerance: the rounding of one multiply-add.",
          value=0.0, tolerance=f"abs {EXACT!r}")
    check("spin_final_sliding", "spin", "sliding_contacts()",
          f"{eq19}: both disc-disc contacts slide in the final state.",
          value=2.0, tolerance="abs 0")
    check("packing_cap", "packing", f"coulomb_error({p['tan_phi']!r}, {p['coh']!r})",
          f"{eq19}, item 2: every disc-disc contact the final state marks sliding carries "
          f"|F_s| = F_n tan(phi) + c (tan(phi) = {p['tan_phi']:g}, c = {p['coh']:g}); the largest relative "
          "difference. Tolerance: the rounding of one multiply-add; a 10 % change of the cap gives 0.1.",
          value=0.0, tolerance=f"abs {EXACT!r}")
    check("packing_sliding", "packing", "sliding_contacts()",
          f"A guard that packing_cap is not about a handful of contacts: a packing landing without "
          f"damping has many contacts at the cap. At least {LEAST_SLIDING} of its disc-disc contacts "
          f"slide in the final state (measured 77 of 244 at the time of writing; at most 3 per disc, "
          f"{3 * p['n']}, in a packing of {p['n']} discs).",
          lo=float(LEAST_SLIDING), hi=float(3 * p["n"]), tolerance="interval")


if __name__ == "__main__":
    main()
