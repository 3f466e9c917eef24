#!/usr/bin/python3
"""Write cases/biaxial/case.txt (the variants of 54+ tests are too many to keep by hand).

    /usr/bin/python3 cases/biaxial/make_case.py

The file it writes is committed; a test (harness/tests/test_biaxial_case.py) checks that it is
what this script writes.  Variant names follow harness/families/biaxial.py: <material>_s<kPa>
[_<suffix>]: m0 (no rolling resistance), m1_d<delta> (Model 1), m2_d<delta> (Model 2); the
suffix names another specimen (_r2, _r3: seeds; _e020, _e023, _e030: the density study) or
another specimen's density."""
from pathlib import Path

HERE = Path(__file__).resolve().parent
STRESSES = (100, 200, 400)
DELTAS = [round(0.1 * k, 1) for k in range(1, 17)]
MATERIALS = ["m0"] + [f"m1_d{d}" for d in DELTAS] + ["m2_d0.4"]
SEEDS = ("r2", "r3")                      # r1 is e025_r1, the specimen of every other test
DENSITY = ("e020", "e023", "e030")        # e025 is r1
SPECIMENS = ("e025_r1", "e025_r2", "e025_r3", "e020_r1", "e023_r1", "e030_r1")
RATE = 0.5                                # 1/s, biaxial.scene's
STANDARD_CYCLES = 250000                  # natural axial strain 0.15 (0.5 /s x 1.2e-6 s per cycle)
FULL_RATE = 1.0                           # 1/s, the full tier's (issue 33): the rate study (biaxial_rate) puts its
                                          # peak phi within 0.23 deg (no rolling) and 0.37 deg (delta = 1.6) of
                                          # 0.125 /s on three specimens, at half the cost of 0.5 /s
FULL_CYCLES = 250000                      # natural axial strain 0.30 at FULL_RATE (1 /s x 1.2e-6 s per cycle)
FULL_ROW = 1250                           # output_every at FULL_RATE: a row per 0.0015 strain, as at 0.5 /s
PEAK_CUT = 18300                          # shear cycles of m1_d0.4_s200_e020 to its peak (a check keeps it)
SNAPSHOT_DT = 0.04                        # s between the snapshots of the two tests the shear-band figures draw:
                                          # frame k at 0.04 k s, so nine frames over the shearing (0.02 to 0.32 s),
                                          # one at no rolling resistance's peak (0.042 s, 1.1 % axial strain)
SNAPSHOTS = ("m0", "m1_d1.6")             # no rolling resistance and Model 1 delta = 1.6, side by side
PAPER_BAND = ('"No attempt is to make in this paper to carry out DEM numerical simulations of shear band with '
              'the model." (JYH 2005, Sec. 1)')
WINDOW = {"standard": (0.10, 0.15), "full": (0.20, 0.30)}

PAPER_FIG11 = ('"Fig. 11 shows that all these three models predict a strain-softening and shear-dilant '
               'behaviour, which reflects one main feature of the medium-dense granular material." (JYH 2005, Sec. 5.2)')
PAPER_FIG12 = ('"the predicted peak (residual) internal friction angle phi deduced from the envelopes ... is equal to '
               '24.4, 26.5 and 29.0 (19.3, 20.7 and 23.0) for no rolling resistance, Model 2 and Model 1 material, '
               'respectively" (JYH 2005, Sec. 5.2)')
PAPER_FIG13 = ('"When delta is increased from 0.0 to 1.6, the peak (residual) phi changes from 24.4 (19.3) to 42.3 '
               '(35.8)." (JYH 2005, Sec. 5.2)')


def material_sets(mat):
    if mat == "m0":
        return ["material.grain.rolling=0"]     # the scene's value, written so setting() finds delta
    model, delta = mat.split("_d")
    sets = [f"material.grain.rolling={delta}"]
    if model == "m2":
        sets.append("settings.rolling_model=model2")
    return sets


def stress_sets(kpa):
    if kpa == 100:
        return []
    pa = kpa * 1000
    return [f"stage.consolidate.servo=spec_top {pa} 0.5 0.05 spec_left spec_right",
            f"stage.consolidate.servo=spec_bottom {pa} 0.5 0.05 spec_left spec_right",
            f"stage.consolidate.servo=spec_left {pa} 0.5 0.05 spec_bottom spec_top",
            f"stage.consolidate.servo=spec_right {pa} 0.5 0.05 spec_bottom spec_top",
            f"stage.shear.servo=spec_left {pa} 0.5 1 spec_bottom spec_top",
            f"stage.shear.servo=spec_right {pa} 0.5 1 spec_bottom spec_top"]


def specimen_sets(name):
    if name == "e025_r1":
        return []
    return [f"import.spec.discs=specimens/{name}/discs.tsv", f"import.spec.walls=specimens/{name}/walls.tsv"]


def full_sets():
    """The full tier's shearing: FULL_RATE to the natural axial strain 0.30, a row per 0.0015."""
    return [f"stage.shear.cycles={FULL_CYCLES}", f"stage.shear.strain_rate=spec_top {FULL_RATE:g} spec_bottom",
            f"settings.output_every={FULL_ROW}"]


def variant(name, mat, kpa, specimen="e025_r1", cycles=None, extra=(), comment=None):
    out = [f"[variant {name}]"]
    if comment:
        out.append(f"# {comment}")
    out.append("scene = biaxial.scene")
    sets = material_sets(mat) + stress_sets(kpa) + specimen_sets(specimen)
    if cycles is not None:
        sets.append(f"stage.shear.cycles={cycles}")
    sets += list(extra)
    out += [f"set = {s}" for s in sets]
    return "\n".join(out) + "\n"


def specimen_variant(name, specimen):
    return "\n".join([f"[variant {name}]",
                      "# the prepared specimen as imported: one cycle of consolidation, no shearing",
                      "scene = biaxial.scene"] +
                     [f"set = {s}" for s in specimen_sets(specimen) +
                      ["stage.consolidate.cycles=1", "stage.shear.cycles=0", "settings.output_every=1"]]) + "\n"


def curves(name, title, variants, y, ylabel, lo_hi=None):
    return "\n".join([f"[figure {name}]", "kind = curves", f"title = {title}", f"variants = {' '.join(variants)}",
                      "x = 100 * axial_strain()", f"y = {y}", "xlabel = axial strain (%)", f"ylabel = {ylabel}",
                      f"paper = {PAPER_FIG11}"]) + "\n"


def profile(name, title, variants):
    return "\n".join([f"[figure {name}]", "kind = curves", f"title = {title}", f"variants = {' '.join(variants)}",
                      "x = void_ratios(6)", "y = band_heights(6)", "xlabel = planar void ratio of the band (-)",
                      "ylabel = height of the band's middle / specimen height (-)",
                      '''paper = "The multi-layer undercompaction technique ... was used to prepare a type of medium-dense specimen with planar void ratio 0.25." (JYH 2005, Sec. 5.1)''']) + "\n"


def fig11(tier, names):
    return (curves(f"fig11a", f"Deviatoric stress against axial strain at 200 kPa (JYH Fig. 11(a))", names,
                   "(sigma_v() - sigma_h()) / 2 / 1000", "(sigma_v - sigma_h)/2 (kPa)") + "\n" +
            curves(f"fig11b", f"Volumetric strain against axial strain at 200 kPa, compression positive (JYH Fig. 11(b))",
                   names, "100 * volumetric_strain()", "volumetric strain eps_v + eps_h (%)"))


FIG11 = ["m0", "m2_d0.4", "m1_d0.4", "m1_d1.6"]     # JYH Fig. 11's materials and delta = 1.6


def standard():
    names = [f"{m}_s200_e020" for m in FIG11]
    parts = ["""[case biaxial]
tier = standard
title = Biaxial compression of JYH's specimen, reduced set (Jiang, Yu & Harris 2005, Sec. 5, Figs 11 and 13)
checks = the prepared specimens' planar void ratios (0.25 and 0.20) and their profiles over height; on the dense specimen e020 (the one that softens and dilates as JYH's "medium-dense" one does, see the density study) at sigma_h = 200 kPa to an axial strain of 0.15, no rolling resistance, Model 2 and Model 1 at delta = 0.4 and Model 1 at delta = 1.6: the servo holds sigma_h, the peak phi rises with delta with Model 2 between no rolling and Model 1, the residual phi rises with delta, residual below peak, dilation; the force network at the peak; the force network and the rotation field from the peak to the residual (the shear band) and a movie of the shearing, for no rolling resistance and delta = 1.6
runtime = 120
stability = no
"""]
    parts.append(specimen_variant("specimen_e025_r1", "e025_r1"))
    parts.append(specimen_variant("specimen_e020_r1", "e020_r1"))
    for m in FIG11:
        extra = [f"settings.snapshot_dt={SNAPSHOT_DT}"] if m in SNAPSHOTS else []
        parts.append(variant(f"{m}_s200_e020", m, 200, specimen="e020_r1", cycles=STANDARD_CYCLES, extra=extra))
    parts.append(variant("m1_d0.4_s200_e020_peak", "m1_d0.4", 200, specimen="e020_r1", cycles=PEAK_CUT,
                         comment="m1_d0.4_s200_e020 cut at its peak (runs are deterministic: its final state is "
                                 "that run's at the peak; a check keeps the cycle)"))
    parts.append(fig11("standard", names))
    parts.append(profile("void_profile", "Planar void ratio of 6 horizontal bands of the prepared specimens",
                         ["specimen_e025_r1", "specimen_e020_r1"]))
    parts.append("\n".join(["[figure network_peak]", "kind = network",
                            "title = Force network of Model 1, delta = 0.4, 200 kPa, specimen e020, at the peak",
                            "variants = m1_d0.4_s200_e020_peak"]) + "\n")
    parts.append(shear_band())
    return "\n".join(parts)


def shear_band():
    """The force network and the rotation field from the peak to the residual, and the movie of
    the shearing, for no rolling resistance and Model 1 delta = 1.6 (harness/pictures.py)."""
    names = " ".join(f"{m}_s200_e020" for m in SNAPSHOTS)
    common = [f"variants = {names}", "label = axial strain (%); 100 * axial_strain()"]
    frames = ["first = the peak; peak_cycle()", "frames = 3"]
    who = "no rolling resistance (top), Model 1 delta = 1.6 (bottom)"
    return "\n".join([
        "[figure shear_network]", "kind = snapshots",
        f"title = Force network from the peak of phi to the residual (200 kPa, e020): {who}",
        *common, "show = network", *frames, f"paper = {PAPER_BAND}", "",
        "[figure shear_rotation]", "kind = snapshots",
        f"title = Disc rotation since shearing began, from the peak of phi to the residual (200 kPa, e020): {who}",
        *common, "show = rotation", "since = shear", *frames, f"paper = {PAPER_BAND}", "",
        "[figure shear_movie]", "kind = movie",
        "title = The shearing (200 kPa, e020): no rolling resistance (left), Model 1 delta = 1.6 (right)",
        *common, "show = both", "since = shear"]) + "\n"


def full():
    parts = ["""[case biaxial_full]
tier = full
title = Biaxial compression: the delta-phi curves of Jiang, Yu & Harris (2005), Sec. 5, Figs 11-13, with three specimens and a density study, sheared at 1 /s
checks = 54 tests (no rolling, Model 1 delta = 0.1 ... 1.6, Model 2 delta = 0.4; sigma_h = 100, 200, 400 kPa) on specimen e025_r1 to an axial strain of 0.30 at 1 /s (the rate study, biaxial_rate, measures what 1 /s costs against 0.125 /s); two more specimens (seeds) at delta = 0 and 1.6; the peak and residual envelope phi against JYH's, with the spread between specimens; phi rises with delta, Model 2 between, the envelopes of no rolling resistance through the origin; the residual window is residual; four initial void ratios; the force network at the peak
runtime = 1800
stability = no
"""]
    for spec in SPECIMENS:
        parts.append(specimen_variant(f"specimen_{spec}", spec))
    # the order is the order they run in: JYH Fig. 11's materials and delta = 1.6 first, then
    # the other specimens, the density study, then the other deltas (0.8, 1.2 before the rest),
    # so an interrupted full tier has the essentials.  (The halved-rate tests of issue 21 are
    # gone: biaxial_rate measures the rate on three specimens, issue 33.)
    first = FIG11
    rest = [m for m in MATERIALS if m not in FIG11]
    rest = [m for m in rest if m in ("m1_d0.8", "m1_d1.2")] + [m for m in rest if m not in ("m1_d0.8", "m1_d1.2")]
    for mat in first:
        for kpa in STRESSES:
            parts.append(variant(f"{mat}_s{kpa}", mat, kpa, extra=full_sets()))
    for seed in SEEDS:
        for mat in ("m0", "m1_d1.6"):
            for kpa in STRESSES:
                parts.append(variant(f"{mat}_s{kpa}_{seed}", mat, kpa, specimen=f"e025_{seed}", extra=full_sets(),
                                     comment=f"specimen e025_{seed} (another seed of [grains])"))
    for mat in FIG11:
        for kpa in STRESSES:
            parts.append(variant(f"{mat}_s{kpa}_e020", mat, kpa, specimen="e020_r1", extra=full_sets(),
                                 comment="density study: the dense specimen e020_r1, three stresses (envelopes)"))
    for dens in ("e023", "e030"):
        for mat in ("m0", "m1_d1.6"):
            parts.append(variant(f"{mat}_s200_{dens}", mat, 200, specimen=f"{dens}_r1", extra=full_sets(),
                                 comment=f"density study: specimen {dens}_r1"))
    for mat in rest:
        for kpa in STRESSES:
            parts.append(variant(f"{mat}_s{kpa}", mat, kpa, extra=full_sets()))
    parts.append(fig11("full", [f"{m}_s200" for m in FIG11]))
    lo, hi = WINDOW["full"]
    parts.append("\n".join([
        "[figure fig12]", "kind = fit", "title = Peak and residual strength envelopes (JYH Fig. 12)",
        "group = no rolling; m0_s100 m0_s200 m0_s400",
        "group = Model 1, delta 0.4; m1_d0.4_s100 m1_d0.4_s200 m1_d0.4_s400",
        "group = Model 2, delta 0.4; m2_d0.4_s100 m2_d0.4_s200 m2_d0.4_s400",
        "x = peak; at_peak(mean_stress(), rows=5) / 1000", "y = peak; at_peak(deviator(), rows=5) / 1000",
        f"x = residual; window_mean(mean_stress(), {lo}, {hi}) / 1000",
        f"y = residual; window_mean(deviator(), {lo}, {hi}) / 1000",
        "slope = asin", "xlabel = (sigma_v + sigma_h)/2 (kPa)", "ylabel = (sigma_v - sigma_h)/2 (kPa)",
        f"paper = {PAPER_FIG12}"]) + "\n")
    m1 = ["m0"] + [f"m1_d{d}" for d in DELTAS]
    members = [f"{m}_s100" for m in m1] + [f"{m}_s100_{s}" for m in ("m0", "m1_d1.6") for s in SEEDS]
    parts.append("\n".join([
        "[figure fig13]", "kind = errorbars",
        "title = Envelope phi against delta, Model 1 (JYH Fig. 13); bars: the three specimens at delta = 0 and 1.6",
        f"variants = {' '.join(members)}",
        "x = setting('material.grain.rolling')",
        "y = ballast peak; phi_envelope('peak', '_s100', '_s200', '_s400', rows=5)",
        f"y = ballast residual; phi_envelope('residual', '_s100', '_s200', '_s400', lo={lo}, hi={hi})",
        "paper_point = 0 24.4 JYH peak", "paper_point = 0.4 29.0 JYH peak", "paper_point = 1.6 42.3 JYH peak",
        "paper_point = 0 19.3 JYH residual", "paper_point = 0.4 23.0 JYH residual", "paper_point = 1.6 35.8 JYH residual",
        "paper_point = 0.4 26.5 JYH Model 2 peak", "paper_point = 0.4 20.7 JYH Model 2 residual",
        "xlabel = shape parameter delta (-)", "ylabel = phi (degrees)", "yrange = 0:50", f"paper = {PAPER_FIG13}"]) + "\n")
    dense = [f"{m}_s100_e020" for m in ("m0", "m1_d0.4", "m1_d1.6")]
    parts.append("\n".join([
        "[figure fig13_e020]", "kind = errorbars",
        "title = Envelope phi against delta, Model 1, on the dense specimen e020 (density study)",
        f"variants = {' '.join(dense)}", "x = setting('material.grain.rolling')",
        "y = ballast peak; phi_envelope('peak', '_s100', '_s200', '_s400', rows=5)",
        f"y = ballast residual; phi_envelope('residual', '_s100', '_s200', '_s400', lo={lo}, hi={hi})",
        "paper_point = 0 24.4 JYH peak", "paper_point = 0.4 29.0 JYH peak", "paper_point = 1.6 42.3 JYH peak",
        "paper_point = 0 19.3 JYH residual", "paper_point = 0.4 23.0 JYH residual", "paper_point = 1.6 35.8 JYH residual",
        "xlabel = shape parameter delta (-)", "ylabel = phi (degrees)", "yrange = 0:50"]) + "\n")
    study = [f"{m}_s200{sfx}" for m in ("m0", "m1_d1.6") for sfx in ("_e020", "_e023", "", "_e030")]
    parts.append("\n".join([
        "[figure density]", "kind = points",
        "title = Density study at 200 kPa: peak phi against the void ratio at the start of shearing (delta = 0, then 1.6)",
        f"variants = {' '.join(study)}", "x = initial_void_ratio()", "y = phi_peak(rows=5)",
        "xlabel = planar void ratio at the start of shearing (-)", "ylabel = peak phi (degrees)"]) + "\n")
    parts.append(profile("void_profiles", "Planar void ratio of 6 horizontal bands of each prepared specimen",
                         [f"specimen_{s}" for s in SPECIMENS]))
    return "\n".join(parts)


# ---------------------------------------------------------------- the rate study (issue 33)
# The strain rate, the contact damping and density scaling against their cost, on the dense
# specimen e020 (the default tier's) at 200 kPa, no rolling resistance and Model 1 delta = 1.6,
# three specimens (e020_r1, r2, r3: e020's recipe, seeds 1-3) at each point: each point is an
# [ensemble] over the specimens, its realisation NAME_s<seed> on specimen e020_r<seed>.  The
# test is the default tier's (to a natural axial strain of 0.15, residual window [0.10, 0.15],
# peak over 5 rows of 0.0015 strain): what the study measures is the catalogue's own test.
STUDY_MATERIALS = ("m0", "m1_d1.6")
STUDY_RATES = (0.125, 0.25, 0.5, 1, 2, 4)   # 1/s; the slowest, 0.125, is the reference
STUDY_STRAIN = 0.15                           # the standard tier's strain
STUDY_DT = 1.2e-6                             # biaxial.scene's step
STUDY_SEEDS = "1-3"                           # specimens e020_r1 ... e020_r3
ROW_CYCLES = 2500                             # biaxial.scene's output_every: a row per 0.0015 strain at 0.5 /s
BETA = 2e-6                                   # biaxial.scene's contact dashpot (s)
BETA_FACTORS = (0.5, 2)                       # the damping study, at the catalogue's rate
DENSITY_FACTOR = 4                            # density scaling: rho x 4, dt x 2 (a power of 2: exact)
STUDY_WINDOW = WINDOW["standard"]


def study_cycles(rate):
    """Shear cycles to the study's strain at rate (a whole number for every rate of the study)."""
    cycles = STUDY_STRAIN / (rate * STUDY_DT)
    assert abs(cycles - round(cycles)) < 1e-6, rate
    return round(cycles)


def study_rows(rate):
    """output_every at rate: the same strain per row as 0.5 /s (2500 cycles), so that the peak's
    5 rows are the same strain, 0.0075, at every rate.  At 4 /s that is 312.5 cycles: 313 (a row
    0.16 % longer)."""
    return int(ROW_CYCLES * RATE / rate + 0.5)


def study_ensemble(name, mat, rate, beta=BETA, extra=(), comment=None):
    sets = (material_sets(mat) + stress_sets(200) +
            ["import.spec.discs=specimens/e020_r{seed}/discs.tsv", "import.spec.walls=specimens/e020_r{seed}/walls.tsv",
             f"stage.shear.cycles={study_cycles(rate)}", f"stage.shear.strain_rate=spec_top {rate:g} spec_bottom",
             f"settings.output_every={study_rows(rate)}", f"settings.beta={beta:g}"] + list(extra))
    out = [f"[ensemble {name}]"] + ([f"# {comment}"] if comment else []) + ["scene = biaxial.scene"]
    return "\n".join(out + [f"set = {s}" for s in sets] + [f"seeds = {STUDY_SEEDS}"]) + "\n"


def rate_name(mat, rate):
    return f"{mat}_rate{rate:g}"


def beta_name(mat, factor):
    return f"{mat}_beta_x{factor:g}"


def density_variant(mat):
    """Density scaling: rho x 4 with dt x 2 (the same fraction of the critical step), beta x 2 (the
    same damping ratio) and the servos' vmax / 2 (the same cap per cycle: a servo's step is per
    cycle, docs/physics.md), at 0.5 /s: per cycle the same motion as 1 /s unscaled."""
    f = DENSITY_FACTOR
    root = f ** 0.5
    sets = (material_sets(mat) +
            [f"stage.consolidate.servo={w} 200000 0.5 {0.05 / root:g} {a} {b}" for w, a, b in
             (("spec_top", "spec_left", "spec_right"), ("spec_bottom", "spec_left", "spec_right"),
              ("spec_left", "spec_bottom", "spec_top"), ("spec_right", "spec_bottom", "spec_top"))] +
            [f"stage.shear.servo={w} 200000 0.5 {1 / root:g} spec_bottom spec_top" for w in ("spec_left", "spec_right")] +
            specimen_sets("e020_r1") +
            [f"material.grain.density={2650 * f:g}", f"settings.dt={STUDY_DT * root:g}",
             f"stage.shear.cycles={study_cycles(RATE * root)}", f"stage.shear.strain_rate=spec_top {RATE:g} spec_bottom",
             f"settings.output_every={study_rows(RATE * root)}", f"settings.beta={BETA * root:g}"])
    return "\n".join([f"[variant {mat}_density_x{f}]",
                      f"# density x {f} at 0.5 /s, dt x {root:g}, beta x {root:g}, servo vmax / {root:g}, "
                      f"specimen e020_r1: against {rate_name(mat, RATE * root)}_s1",
                      "scene = biaxial.scene"] + [f"set = {s}" for s in sets]) + "\n"


def rate_study():
    lo, hi = STUDY_WINDOW
    ref = {m: rate_name(m, STUDY_RATES[0]) for m in STUDY_MATERIALS}
    parts = [f"""[case biaxial_rate]
tier = full
title = Biaxial compression: the strain rate, the contact damping and density scaling against their cost, three specimens at each point (issue 33)
checks = the default tier's test (specimen e020, 200 kPa, axial strain 0.15) at strain rates 0.125 ... 4 /s, no rolling resistance and Model 1 delta = 1.6, on three specimens each: peak and residual phi and the dilation against the slowest rate, specimen by specimen, with the spread between specimens; the catalogue's 0.5 /s within 1 degree of 0.125 /s; the contact damping x 0.5 and x 2 at 0.5 /s; density x 4 at 0.5 /s is 1 /s cycle for cycle
runtime = 900
stability = no
"""]
    # the slowest rates first: the longest runs start first
    for rate in STUDY_RATES:
        for mat in STUDY_MATERIALS:
            parts.append(study_ensemble(rate_name(mat, rate), mat, rate))
    for factor in BETA_FACTORS:
        for mat in STUDY_MATERIALS:
            parts.append(study_ensemble(beta_name(mat, factor), mat, RATE, beta=BETA * factor,
                                        comment=f"contact damping beta x {factor:g} at the catalogue's 0.5 /s"))
    for mat in STUDY_MATERIALS:
        parts.append(density_variant(mat))
    cost = "log10(mean(over(this_ensemble(), \"run('steps') * run('n_discs')\")))"
    quantities = (("peak", "phi_peak(rows=5)"), ("residual", f"phi_residual({lo}, {hi})"))
    for mat in STUDY_MATERIALS:
        label = "no rolling resistance" if mat == "m0" else "Model 1, delta = 1.6"
        ys = [f"y = {q}; {e} - same_seed('{ref[mat]}', '{e}')" for q, e in quantities]
        for q, e in quantities:
            floor = f"sd(over('{ref[mat]}', '{e}'))"
            ys += [f"y = {q}: + sd of 3 specimens at 0.125 /s; {floor}", f"y = {q}: - sd; -{floor}"]
        parts.append("\n".join([
            f"[figure rate_phi_{mat}]", "kind = errorbars",
            f"title = Rate study, {label}, 200 kPa: phi against the test's cost",
            f"variants = {' '.join(rate_name(mat, r) for r in STUDY_RATES)}",
            f"x = {cost}"] + ys + [
            "xlabel = log10 particle-steps (4, 2, 1, 0.5, 0.25, 0.125 /s from the left)",
            "ylabel = phi - phi(0.125 /s), same specimen (deg)"]) + "\n")
    names = {m: "[" + ", ".join(f"'{rate_name(m, r)}'" for r in STUDY_RATES) + "]" for m in STUDY_MATERIALS}
    dil = ["[figure rate_dilation]", "kind = curves",
           "title = Rate study, 200 kPa: dilation against the test's cost",
           f"variants = {ref['m0']}_s1",
           f"x = log10(means({names['m0']}, \"run('steps') * run('n_discs')\"))"]
    for mat in STUDY_MATERIALS:
        floor = f"100 * sd(over('{ref[mat]}', 'dilation()'))"
        dil += [f"y = {mat}; 100 * paired_means({names[mat]}, '{ref[mat]}', 'dilation()')",
                f"y = {mat}: + sd of 3 specimens at 0.125 /s; [{floor}] * {len(STUDY_RATES)}",
                f"y = {mat}: - sd; [-{floor}] * {len(STUDY_RATES)}"]
    dil += ["xlabel = log10 particle-steps of m0 (4 ... 0.125 /s from the left)",
            "ylabel = dilation - dilation(0.125 /s), mean of 3 (% points)"]
    parts.append("\n".join(dil) + "\n")
    damp = ["[figure damping]", "kind = curves",
            "title = Damping study at 0.5 /s, 200 kPa: phi against the contact dashpot",
            f"variants = {ref['m0']}_s1", f"x = [{', '.join(f'{f:g}' for f in (BETA_FACTORS[0], 1, BETA_FACTORS[1]))}]"]
    for mat in STUDY_MATERIALS:
        group = "[" + ", ".join(f"'{n}'" for n in (beta_name(mat, BETA_FACTORS[0]), rate_name(mat, RATE),
                                                  beta_name(mat, BETA_FACTORS[1]))) + "]"
        for q, e in quantities:
            damp.append(f"y = {mat} {q}; paired_means({group}, '{ref[mat]}', '{e}')")
    damp += ["xlabel = beta / 2e-6 s, at the same cost (-)",
             "ylabel = phi - phi(0.125 /s), mean of 3 (deg)"]
    parts.append("\n".join(damp) + "\n")
    return "\n".join(parts)


HEADER = """# Biaxial compression tests of Jiang, Yu & Harris (2005), Sec. 5 (JYH) -- WRITTEN BY
# make_case.py (run it after changing it; a test compares).  Scene: biaxial.scene (one test:
# import a prepared specimen, consolidate isotropically, shear).  Specimens: specimens/,
# made by prepare.py (never by the harness).  References: reference/biaxial.ref.
# README.md of this folder has every choice and the results.

"""


def text():
    return HEADER + standard() + "\n" + full() + "\n" + rate_study()


if __name__ == "__main__":
    (HERE / "case.txt").write_text(text())
