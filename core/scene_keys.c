/*
 * scene_keys.c — every key a scene file may contain, in one table.
 *
 * The parser, the range checks, `ballast keys` and the key list in the
 * key tables of docs/scene-format.md all read this table, so they cannot drift apart.  A default is
 * written as text and parsed like a value from a file; a key without a
 * default and with `required` set must be given.
 *
 * Paper references: C&S = Cundall & Strack (1979); MLH = Matuttis, Luding
 * & Herrmann (2000).
 */
#include <float.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "scene_keys.h"

#define BIG DBL_MAX
#define LBIG 2147483647.0
/* Largest stiffness: two materials combine as 2 k_a k_b / (k_a + k_b)
 * (build.c), whose product overflows to inf/inf = NaN above about 9e153
 * (found by fuzzing: kn = 1e155 gave a NaN time step). */
#define KBIG 1e150
/* Smallest stiffness, for the same product: 2 k_a k_b underflows to 0 below
 * about 1e-154 (found by fuzzing: kn = 1e-300 gave a pair stiffness of 0, a
 * NaN elastic energy and an infinite time-step estimate).  scene.c checks
 * ks against it too (ks may also be -1: equal to kn). */
#define KMIN 1e-150

/* A section's `given` has one bit per key of its kind. */
_Static_assert(BAL_KEYS_MAX <= 32, "struct bal_settings' given (uint32_t) has a bit per key");

#define S(field) offsetof(struct bal_settings, field)
#define M(field) offsetof(struct bal_material_def, field)
#define D(field) offsetof(struct bal_disc_def, field)
#define W(field) offsetof(struct bal_wall_def, field)
#define F(field) offsetof(struct bal_fill_def, field)
#define G(field) offsetof(struct bal_stage_def, field)
#define Q(field) offsetof(struct bal_pile_def, field)
#define R(field) offsetof(struct bal_grains_def, field)
#define I(field) offsetof(struct bal_import_def, field)
#define P(field) offsetof(struct bal_probe_def, field)
#define MV(field) offsetof(struct bal_move_def, field)

/* A controller's numbers are consecutive doubles of struct bal_move_def from
 * its key's offset on: `move` v[0], v[1], omega; `servo` sigma, gain, vmax;
 * `strain_rate` rate. */
_Static_assert(offsetof(struct bal_move_def, omega) == MV(v) + 2 * sizeof(double),
               "the numbers of `move` are consecutive doubles of struct bal_move_def");
_Static_assert(MV(gain) == MV(sigma) + sizeof(double) && MV(vmax) == MV(sigma) + 2 * sizeof(double),
               "the numbers of `servo` are consecutive doubles of struct bal_move_def");

const struct bal_key bal_scene_keys[] = {
    /* [settings] */
    {BAL_SEC_SETTINGS, "dt", BAL_KEY_DOUBLE, S(dt), "0", 0, 0, BIG, NULL,
     "time step; 0 = dt_fraction x the critical-step estimate"},
    {BAL_SEC_SETTINGS, "dt_fraction", BAL_KEY_DOUBLE, S(dt_fraction), "0.1", 0, 1e-9, 1, NULL,
     "fraction of the critical-step estimate (contact-network bound; ballast info prints it); "
     "below 1: 1 is refused unless force_dt = 1"},
    {BAL_SEC_SETTINGS, "alpha", BAL_KEY_DOUBLE, S(alpha), "0", 0, 0, BIG, NULL,
     "global damping alpha, C = alpha m, C* = alpha I (C&S eqs 34-36), 1/time"},
    {BAL_SEC_SETTINGS, "beta", BAL_KEY_DOUBLE, S(beta), "0", 0, 0, BIG, NULL,
     "contact damping beta, c_n = beta k_n, c_s = beta k_s (C&S eq. 28), time"},
    {BAL_SEC_SETTINGS, "gravity", BAL_KEY_VEC2, S(gravity), "0 0", 0, -BIG, BIG, NULL,
     "body-force acceleration g_1 g_2 (C&S p. 52)"},
    {BAL_SEC_SETTINGS, "normal_law", BAL_KEY_ENUM, S(normal_law), "incremental", 0, 0, 0,
     "incremental power",
     "incremental: F_n += k_n n' dt (C&S eqs 14, 16, 18); power: F_n = k_n d0 (d/d0)^nu (MLH eq. 2)"},
    {BAL_SEC_SETTINGS, "nu", BAL_KEY_DOUBLE, S(nu), "1", 0, 1, 3, NULL,
     "exponent nu of the power law (1 linear, 1.5 Hertz, 2 conical)"},
    {BAL_SEC_SETTINGS, "delta0", BAL_KEY_DOUBLE, S(delta0), "1", 0, 1e-300, BIG, NULL,
     "normalisation length delta0 of the power law"},
    {BAL_SEC_SETTINGS, "grid", BAL_KEY_ENUM, S(grid), "auto", 0, 0, 0, "auto on off",
     "neighbour search: auto = all pairs for few discs, a cell grid for many"},
    {BAL_SEC_SETTINGS, "skin", BAL_KEY_DOUBLE, S(skin), "0", 0, 0, BIG, NULL,
     "Verlet skin of the cell grid, length; 0 = 0.2 x the largest radius"},
    {BAL_SEC_SETTINGS, "skin_rule", BAL_KEY_ENUM, S(skin_rule), "fixed", 0, 0, 0, "fixed motion",
     "fixed: the skin above for the whole run; motion: it starts the run, then each rebuild "
     "chooses the skin from the measured motion (fewest expected cost per cycle)"},
    {BAL_SEC_SETTINGS, "output_every", BAL_KEY_LONG, S(output_every), "1", 0, 1, LBIG, NULL,
     "cycles between rows of series.tsv"},
    {BAL_SEC_SETTINGS, "snapshot_every", BAL_KEY_LONG, S(snapshot_every), "0", 0, 0, LBIG, NULL,
     "cycles between snapshots: the discs, contacts and walls in snapshots/ (docs/paraview.md); "
     "0 = none"},
    {BAL_SEC_SETTINGS, "snapshot_dt", BAL_KEY_DOUBLE, S(snapshot_dt), "0", 0, 0, BIG, NULL,
     "or the simulated time between snapshots (frame k at cycle ceil(k snapshot_dt / dt)); "
     "0 = none; not with snapshot_every"},
    {BAL_SEC_SETTINGS, "vtk", BAL_KEY_LONG, S(vtk), "0", 0, 0, 1, NULL,
     "1: each snapshot also as VTK XML PolyData with a ParaView .pvd collection (also `ballast "
     "run --vtk`); needs snapshot_every or snapshot_dt"},
    {BAL_SEC_SETTINGS, "gamma_n", BAL_KEY_DOUBLE, S(gamma_n), "0", 0, 0, BIG, NULL,
     "viscous normal damping gamma_n d' (d/d0)^psi of MLH eq. 3, mass/time"},
    {BAL_SEC_SETTINGS, "psi", BAL_KEY_DOUBLE, S(psi), "0", 0, 0, 3, NULL,
     "exponent psi of MLH eq. 3 (0: linear dashpot)"},
    {BAL_SEC_SETTINGS, "stress_width", BAL_KEY_DOUBLE, S(stress_width), "0", 0, 0, BIG, NULL,
     "moving-average stress cells (MLH Sec. 3): width; 0 = no stress_grid.tsv"},
    {BAL_SEC_SETTINGS, "stress_height", BAL_KEY_DOUBLE, S(stress_height), "0", 0, 0, BIG, NULL,
     "height of a stress cell; 0 = the width"},
    {BAL_SEC_SETTINGS, "stress_step", BAL_KEY_DOUBLE, S(stress_step), "0", 0, 0, BIG, NULL,
     "horizontal step between overlapping stress cells; 0 = the width"},
    {BAL_SEC_SETTINGS, "overlap_budget", BAL_KEY_DOUBLE, S(overlap_budget), "0.5", 0, 0, BIG, NULL,
     "stop the run when an overlap exceeds this share of the smaller radius of the pair; 0 = off"},
    {BAL_SEC_SETTINGS, "energy_guard", BAL_KEY_DOUBLE, S(energy_guard), "1", 0, 0, BIG, NULL,
     "stop the run when it has created this share of the energy that went through it; 0 = off"},
    {BAL_SEC_SETTINGS, "allow_overlap", BAL_KEY_LONG, S(allow_overlap), "0", 0, 0, 1, NULL,
     "1: bodies may overlap at the start (refused otherwise: the overlap is named)"},
    {BAL_SEC_SETTINGS, "force_dt", BAL_KEY_LONG, S(force_dt), "0", 0, 0, 1, NULL,
     "1: run with a time step at or above the stability estimate (refused otherwise)"},
    {BAL_SEC_SETTINGS, "integrator", BAL_KEY_ENUM, S(integrator), "centred", 0, 0, 0,
     "centred verlet gear5",
     "law of motion: centred (C&S eqs 22-23, 35-36), verlet (velocity Verlet), gear5 (Gear "
     "predictor-corrector, MLH Sec. 5.3)"},
    {BAL_SEC_SETTINGS, "rolling_model", BAL_KEY_ENUM, S(rolling_model), "model1", 0, 0, 0,
     "model1 model2",
     "rolling resistance of pairs with material rolling > 0: model1 elasto-plastic (JYH eq. 35), "
     "model2 elasto-brittle (eq. 36)"},

    /* [material NAME] */
    {BAL_SEC_MATERIAL, "kn", BAL_KEY_DOUBLE, M(kn), NULL, 1, KMIN, KBIG, NULL,
     "normal stiffness k_n, force/length (C&S eq. 16)"},
    {BAL_SEC_MATERIAL, "ks", BAL_KEY_DOUBLE, M(ks), "-1", 0, -1, KBIG, NULL,
     "shear stiffness k_s (C&S eq. 17); default: equal to kn"},
    {BAL_SEC_MATERIAL, "friction", BAL_KEY_DOUBLE, M(friction), "0", 0, 0, BIG, NULL,
     "tan(phi_mu); a contact uses the smaller of its two bodies' (C&S eq. 19)"},
    {BAL_SEC_MATERIAL, "cohesion", BAL_KEY_DOUBLE, M(cohesion), "0", 0, 0, BIG, NULL,
     "cohesion c, force; a contact uses the smaller of its two bodies' (C&S eq. 19)"},
    {BAL_SEC_MATERIAL, "density", BAL_KEY_DOUBLE, M(density), "0", 0, 0, BIG, NULL,
     "mass per unit area of a disc (m = density pi r^2); required for disc materials"},
    {BAL_SEC_MATERIAL, "rolling", BAL_KEY_DOUBLE, M(rolling), "0", 0, 0, 2, NULL,
     "shape parameter delta of rolling resistance, contact width B = delta r (JYH eq. 24); a pair "
     "uses the smaller of its two; 0 = none"},

    /* [disc NAME] */
    {BAL_SEC_DISC, "x", BAL_KEY_VEC2, D(x), NULL, 1, -BIG, BIG, NULL, "centre x_1 x_2"},
    {BAL_SEC_DISC, "r", BAL_KEY_DOUBLE, D(r), NULL, 1, 1e-300, BIG, NULL, "radius"},
    {BAL_SEC_DISC, "material", BAL_KEY_NAME, D(material), NULL, 1, 0, 0, NULL,
     "name of a [material] section"},
    {BAL_SEC_DISC, "v", BAL_KEY_VEC2, D(v), "0 0", 0, -BIG, BIG, NULL,
     "initial velocity (at t = dt/2, C&S eq. 22)"},
    {BAL_SEC_DISC, "theta", BAL_KEY_DOUBLE, D(theta), "0", 0, -BIG, BIG, NULL,
     "initial rotation, degrees"},
    {BAL_SEC_DISC, "omega", BAL_KEY_DOUBLE, D(omega), "0", 0, -BIG, BIG, NULL,
     "initial angular velocity, rad/time, counter-clockwise"},
    {BAL_SEC_DISC, "fixed", BAL_KEY_LONG, D(fixed), "0", 0, 0, 1, NULL,
     "1: the disc is held (its velocity stays zero; it still feels forces)"},
    {BAL_SEC_DISC, "hold", BAL_KEY_FLAGS, D(hold), NULL, 0, 0, 0, "x y rotation",
     "components of the disc's motion held at zero, e.g. 'x rotation' (all three: fixed = 1); "
     "the held coordinates stay, the others move (docs/physics.md)"},

    /* [wall NAME] */
    {BAL_SEC_WALL, "p", BAL_KEY_VEC2, W(p), NULL, 1, -BIG, BIG, NULL,
     "point P of the wall (C&S Fig. 4)"},
    {BAL_SEC_WALL, "angle", BAL_KEY_DOUBLE, W(angle), NULL, 1, -BIG, BIG, NULL,
     "alpha of the unit vector e = (cos alpha, sin alpha), degrees"},
    {BAL_SEC_WALL, "h1", BAL_KEY_DOUBLE, W(h1), NULL, 1, -BIG, BIG, NULL,
     "end A = P + h1 e"},
    {BAL_SEC_WALL, "h2", BAL_KEY_DOUBLE, W(h2), NULL, 1, -BIG, BIG, NULL,
     "end B = P + h2 e (h2 > h1)"},
    {BAL_SEC_WALL, "material", BAL_KEY_NAME, W(material), NULL, 1, 0, 0, NULL,
     "name of a [material] section (density unused)"},

    /* [fill NAME] */
    {BAL_SEC_FILL, "n", BAL_KEY_LONG, F(n), NULL, 1, 1, 100000000.0, NULL, "number of discs"},
    {BAL_SEC_FILL, "columns", BAL_KEY_LONG, F(columns), NULL, 1, 1, 100000000.0, NULL,
     "discs per lattice row (rows = ceil(n / columns))"},
    {BAL_SEC_FILL, "origin", BAL_KEY_VEC2, F(origin), "0 0", 0, -BIG, BIG, NULL,
     "lower-left corner of the lattice region"},
    {BAL_SEC_FILL, "rmin", BAL_KEY_DOUBLE, F(rmin), NULL, 1, 1e-300, BIG, NULL,
     "smallest radius (radii uniform in [rmin, rmax])"},
    {BAL_SEC_FILL, "rmax", BAL_KEY_DOUBLE, F(rmax), NULL, 1, 1e-300, BIG, NULL,
     "largest radius; the lattice spacing is 2 rmax"},
    {BAL_SEC_FILL, "headroom", BAL_KEY_DOUBLE, F(headroom), "0", 0, 0, BIG, NULL,
     "extra height of the box above the lattice"},
    {BAL_SEC_FILL, "vmax", BAL_KEY_DOUBLE, F(vmax), "0", 0, 0, BIG, NULL,
     "initial speeds uniform in [0, vmax), directions uniform"},
    {BAL_SEC_FILL, "seed", BAL_KEY_LONG, F(seed), "1", 0, 0, 4294967295.0, NULL,
     "seed of the generator (same seed, same discs)"},
    {BAL_SEC_FILL, "box", BAL_KEY_LONG, F(box), "0", 0, 0, 1, NULL,
     "1: add four walls around the region (named NAME_bottom/_right/_top/_left)"},
    {BAL_SEC_FILL, "material", BAL_KEY_NAME, F(material), NULL, 1, 0, 0, NULL,
     "material of the discs"},
    {BAL_SEC_FILL, "wall_material", BAL_KEY_NAME, F(wall_material), "", 0, 0, 0, NULL,
     "material of the box walls (required with box = 1)"},

    /* [pile NAME] */
    {BAL_SEC_PILE, "L", BAL_KEY_LONG, Q(L), NULL, 1, 1, 100000, NULL,
     "discs in the bottom row M = 0 (MLH Fig. 2)"},
    {BAL_SEC_PILE, "slope", BAL_KEY_ENUM, Q(slope), "30", 0, 0, 0, "30 60",
     "30: row M holds L - 3M discs; 60: L - M"},
    {BAL_SEC_PILE, "d", BAL_KEY_DOUBLE, Q(d), NULL, 1, 1e-300, BIG, NULL, "disc diameter d0"},
    {BAL_SEC_PILE, "origin", BAL_KEY_VEC2, Q(origin), "0 0", 0, -BIG, BIG, NULL,
     "left end of the base and floor height"},
    {BAL_SEC_PILE, "bottom", BAL_KEY_ENUM, Q(bottom), "smooth", 0, 0, 0, "smooth bumpy",
     "smooth: row 0 on a floor wall NAME_floor, corner stones held; bumpy: row 0 held"},
    {BAL_SEC_PILE, "c", BAL_KEY_DOUBLE, Q(c), "0", 0, -0.5, 1, NULL,
     "bumpy bottom: row 0 spacing d0 (1 + c) (MLH Sec. 4.1)"},
    {BAL_SEC_PILE, "size_spread", BAL_KEY_DOUBLE, Q(size_spread), "0", 0, 0, 1, NULL,
     "r_d < 1: each diameter d0 (1 + r), r uniform in [-r_d/2, r_d/2), held discs too (MLH "
     "Sec. 4.4); 0 = equal discs"},
    {BAL_SEC_PILE, "seed", BAL_KEY_LONG, Q(seed), "1", 0, 1, 4294967295.0, NULL,
     "seed of GSL's mt19937 that draws the diameters (same seed, same pile on every machine)"},
    {BAL_SEC_PILE, "material", BAL_KEY_NAME, Q(material), NULL, 1, 0, 0, NULL,
     "material of the discs"},
    {BAL_SEC_PILE, "wall_material", BAL_KEY_NAME, Q(wall_material), "", 0, 0, 0, NULL,
     "material of the floor (required with bottom = smooth)"},

    /* [grains NAME] */
    {BAL_SEC_GRAINS, "n", BAL_KEY_LONG, R(n), NULL, 1, 1, 100000000.0, NULL, "number of discs"},
    {BAL_SEC_GRAINS, "origin", BAL_KEY_VEC2, R(origin), "0 0", 0, -BIG, BIG, NULL,
     "lower-left corner of the region"},
    {BAL_SEC_GRAINS, "size", BAL_KEY_VEC2, R(size), NULL, 1, 1e-300, BIG, NULL,
     "width and height of the region (every disc lies inside it)"},
    {BAL_SEC_GRAINS, "dmin", BAL_KEY_DOUBLE, R(dmin), NULL, 1, 1e-300, BIG, NULL,
     "smallest diameter: 0 % of the discs' area is finer"},
    {BAL_SEC_GRAINS, "d10", BAL_KEY_DOUBLE, R(d10), NULL, 1, 1e-300, BIG, NULL,
     "diameter than which 10 % of the discs' area is finer (grading by area, linear between "
     "the given points)"},
    {BAL_SEC_GRAINS, "d50", BAL_KEY_DOUBLE, R(d50), NULL, 1, 1e-300, BIG, NULL,
     "... 50 % (the median by area)"},
    {BAL_SEC_GRAINS, "d60", BAL_KEY_DOUBLE, R(d60), NULL, 1, 1e-300, BIG, NULL,
     "... 60 % (C_u = d60/d10)"},
    {BAL_SEC_GRAINS, "dmax", BAL_KEY_DOUBLE, R(dmax), NULL, 1, 1e-300, BIG, NULL,
     "largest diameter: 100 % of the area is finer"},
    {BAL_SEC_GRAINS, "seed", BAL_KEY_LONG, R(seed), "1", 0, 0, 4294967295.0, NULL,
     "seed of GSL's gsl_rng_mt19937 (same seed, same discs on every machine; 0 is GSL's 4357)"},
    {BAL_SEC_GRAINS, "tries", BAL_KEY_LONG, R(tries), "100000", 0, 1, 1e7, NULL,
     "random places tried for one disc before the generator gives up (a larger region helps)"},
    {BAL_SEC_GRAINS, "box", BAL_KEY_LONG, R(box), "0", 0, 0, 1, NULL,
     "1: add four walls on the region's sides (named NAME_bottom/_right/_top/_left)"},
    {BAL_SEC_GRAINS, "overhang", BAL_KEY_DOUBLE, R(overhang), "-1", 0, -1, BIG, NULL,
     "how far each box wall reaches beyond the corners (so the side walls can move out); "
     "-1 = dmax"},
    {BAL_SEC_GRAINS, "material", BAL_KEY_NAME, R(material), NULL, 1, 0, 0, NULL,
     "material of the discs"},
    {BAL_SEC_GRAINS, "wall_material", BAL_KEY_NAME, R(wall_material), "", 0, 0, 0, NULL,
     "material of the box walls (required with box = 1)"},

    /* [import NAME] */
    {BAL_SEC_IMPORT, "discs", BAL_KEY_FILE, I(discs), NULL, 1, 0, 0, "discs",
     "a discs.tsv a run wrote (columns x y r theta, and vx vy omega fixed if present), relative "
     "to the scene's directory: its discs, in its order, named NAME.k"},
    {BAL_SEC_IMPORT, "walls", BAL_KEY_FILE, I(walls), "", 0, 0, 0, "walls",
     "a walls.tsv a run wrote (columns name ax ay bx by): its walls, from A to B, with their names"},
    {BAL_SEC_IMPORT, "material", BAL_KEY_NAME, I(material), NULL, 1, 0, 0, NULL,
     "material of the discs"},
    {BAL_SEC_IMPORT, "wall_material", BAL_KEY_NAME, I(wall_material), "", 0, 0, 0, NULL,
     "material of the walls (required with walls)"},
    {BAL_SEC_IMPORT, "velocities", BAL_KEY_LONG, I(velocities), "0", 0, 0, 1, NULL,
     "1: the discs start with the file's vx vy omega; 0: at rest"},

    /* [stage NAME] */
    {BAL_SEC_STAGE, "cycles", BAL_KEY_LONG, G(cycles), NULL, 0, 0, 1e15, NULL,
     "number of calculation cycles in this stage (0: the stage is skipped); this or time"},
    {BAL_SEC_STAGE, "time", BAL_KEY_DOUBLE, G(time), NULL, 0, 0, BIG, NULL,
     "or the stage's simulated time: ceil(time/dt) cycles, the same time whatever dt is"},
    {BAL_SEC_STAGE, "ramp", BAL_KEY_LONG, G(ramp), "0", 0, 0, 1, NULL,
     "1: gravity rises linearly from zero over this stage's cycles (MLH Sec. 4)"},
    {BAL_SEC_STAGE, "stop_ke", BAL_KEY_DOUBLE, G(stop_ke), "0", 0, 0, BIG, NULL,
     "stop the stage once E_k <= stop_ke E_el (0: off); cycles (or time) is then the most"},
    {BAL_SEC_STAGE, "stop_stress", BAL_KEY_DOUBLE, G(stop_stress), "0", 0, 0, BIG, NULL,
     "... and the disc stresses change by <= this share of the largest between checks"},
    {BAL_SEC_STAGE, "check_every", BAL_KEY_LONG, G(check_every), "100", 0, 1, 1e15, NULL,
     "cycles between checks of the stop rule"},
    {BAL_SEC_STAGE, "output_at_end", BAL_KEY_LONG, G(output_at_end), "0", 0, 0, 1, NULL,
     "1: write a series row after the stage's last cycle (its count or its stop rule), so the "
     "next stage's start is in series.tsv"},
    {BAL_SEC_STAGE, "stop_servo", BAL_KEY_DOUBLE, G(stop_servo), "0", 0, 0, BIG, NULL,
     "... and every servo wall of the stage is within this share of its target stress (0: off)"},
    {BAL_SEC_STAGE, "stop_unbalanced", BAL_KEY_DOUBLE, G(stop_unbalanced), "0", 0, 0, BIG, NULL,
     "... and the unbalanced-force ratio (probe unbalanced, C&S dF/F) is <= this (0: off)"},
    /* A wall controller's key (walls.c; bal_scene_controls says which): its
     * numbers go, in order, to consecutive doubles of struct bal_move_def
     * from `offset` on; the words of its form that start with WALL after
     * the first are the names of other walls (struct bal_move_def, walls). */
    {BAL_SEC_STAGE, "move", BAL_KEY_CONTROL, MV(v), NULL, 0, -BIG, BIG, "WALL v1 v2 omega",
     "repeatable: WALL v1 v2 omega; velocity of P and angular velocity about P (C&S p. 53); "
     "walls not named are at rest; --set replaces the named wall's motion"},
    {BAL_SEC_STAGE, "servo", BAL_KEY_CONTROL, MV(sigma), NULL, 0, -BIG, BIG,
     "WALL sigma gain vmax WALL_A WALL_B",
     "repeatable: the wall holds the normal stress sigma (the normal force of its contact springs "
     "over the distance between WALL_A and WALL_B), removing the share gain (0 < gain < 2; <= 1 "
     "monotone) of the error per cycle, at most vmax fast (0: 1e-3 of the smallest radius per "
     "step)"},
    {BAL_SEC_STAGE, "strain_rate", BAL_KEY_CONTROL, MV(rate), NULL, 0, -BIG, BIG,
     "WALL rate WALL_TO",
     "repeatable: the wall moves along its normal towards WALL_TO at rate x their distance "
     "(a logarithmic strain rate, 1/time; < 0 moves away)"},

    /* [probe NAME] */
    {BAL_SEC_PROBE, "quantity", BAL_KEY_ENUM, P(kind), NULL, 1, 0, 0,
     "contact_fn contact_fs contact_sliding wall_f1 wall_f2 wall_moment wall_ecc "
     "disc_x disc_y disc_vx disc_vy disc_theta disc_omega "
     "energy_kinetic energy_elastic work_walls work_gravity dissipated_dashpot "
     "dissipated_friction dissipated_global energy_imbalance unbalanced n_contacts n_sliding "
     "held_fx held_fy weight_x weight_y contact_mr contact_theta_r contact_rolling "
     "dissipated_rolling wall_px wall_py wall_gap wall_stress",
     "what the series column holds"},
    {BAL_SEC_PROBE, "a", BAL_KEY_BODY, P(a), "", 0, 0, 0, NULL,
     "body: the disc (disc_*), the wall (wall_*), or the first body of a contact; a "
     "generator's discs are NAME.k"},
    {BAL_SEC_PROBE, "b", BAL_KEY_BODY, P(b), "", 0, 0, 0, NULL,
     "second body of a contact (contact_*), or the second wall of wall_gap"},
};

const size_t bal_scene_n_keys = sizeof bal_scene_keys / sizeof bal_scene_keys[0];

/* Each wall controller's stage key (a BAL_KEY_CONTROL row above). */
const struct bal_control_key bal_scene_controls[] = {
    {"move", BAL_CONTROL_PRESCRIBED},
    {"servo", BAL_CONTROL_SERVO},
    {"strain_rate", BAL_CONTROL_STRAIN_RATE},
};

const size_t bal_scene_n_controls = sizeof bal_scene_controls / sizeof bal_scene_controls[0];

/* ------------------------------------------------------------------ */
/* Keys that other keys make unused                                    */
/* ------------------------------------------------------------------ */

/* Each condition below is where the core reads the key only on the other
 * branch; a rule is listed only when that is certain from the keys alone
 * (not from the discs a generator makes or the contacts a run meets).
 * harness/tests/test_unused_keys.py runs every rule twice with two values
 * of its key and requires the same outputs. */

static const struct bal_settings *settings_of(const void *item)
{
    return item;
}

/* build.c: dt = settings.dt if > 0, else dt_fraction × the estimate. */
static int step_given(const struct bal_scene *s, const void *item)
{
    (void)s;
    return settings_of(item)->dt > 0;
}

/* nu enters only the power law: laws.h (force, energy), timestep.c (ν k_n),
 * walls.c, exact.c, each under normal_law = power. */
static int incremental_law(const struct bal_scene *s, const void *item)
{
    (void)s;
    return settings_of(item)->normal_law == BAL_NORMAL_INCREMENTAL;
}

/* delta0 enters the power law and MLH's dashpot γ_n (δ/δ0)^ψ, which is
 * γ_n when ψ = 0 and nothing when γ_n = 0 (laws.h, bal_law_viscous). */
static int no_delta0_term(const struct bal_scene *s, const void *item)
{
    const struct bal_settings *st = settings_of(item);
    return incremental_law(s, item) && (st->gamma_n == 0 || st->psi == 0);
}

/* psi: only in γ_n (δ/δ0)^ψ (laws.h). */
static int no_viscous_dashpot(const struct bal_scene *s, const void *item)
{
    (void)s;
    return settings_of(item)->gamma_n == 0;
}

/* stress_height and stress_step: only for stress_grid.tsv (output.c). */
static int no_stress_grid(const struct bal_scene *s, const void *item)
{
    (void)s;
    return settings_of(item)->stress_width == 0;
}

/* skin and skin_rule: only with the cell grid; grid = off lists every pair
 * once and never rebuilds (build.c, grid.c). */
static int no_cell_grid(const struct bal_scene *s, const void *item)
{
    (void)s;
    return settings_of(item)->grid == BAL_GRID_OFF;
}

/* rolling_model: only for a pair with rolling > 0, whose rolling is the
 * smaller of its two materials' (build.c, laws.h). */
static int no_rolling(const struct bal_scene *s, const void *item)
{
    (void)item;
    for (int m = 0; m < s->n_materials; m++)
        if (s->materials[m].rolling > 0)
            return 0;
    return 1;
}

/* check_every: only for a stage with a stop rule (sim.c, has_stop_rule). */
static int no_stop_rule(const struct bal_scene *s, const void *item)
{
    (void)s;
    const struct bal_stage_def *g = item;
    return !(g->stop_ke > 0 || g->stop_stress > 0 || g->stop_servo > 0 || g->stop_unbalanced > 0);
}

/* A generator's box walls (build.c, bal_build_walls): headroom and
 * wall_material of [fill], overhang and wall_material of [grains] only
 * with box = 1; the floor of [pile] only with bottom = smooth, c only with
 * bottom = bumpy (specimen.c). */
static int fill_without_box(const struct bal_scene *s, const void *item)
{
    (void)s;
    return !((const struct bal_fill_def *)item)->box;
}

static int grains_without_box(const struct bal_scene *s, const void *item)
{
    (void)s;
    return !((const struct bal_grains_def *)item)->box;
}

static int pile_bumpy(const struct bal_scene *s, const void *item)
{
    (void)s;
    return ((const struct bal_pile_def *)item)->bottom == 1;
}

static int pile_smooth(const struct bal_scene *s, const void *item)
{
    return !pile_bumpy(s, item);
}

const struct bal_unused_rule bal_scene_unused[] = {
    {BAL_SEC_SETTINGS, "dt_fraction", "settings.dt > 0 sets the step", step_given},
    {BAL_SEC_SETTINGS, "nu", "settings.normal_law = incremental: nu is the power law's",
     incremental_law},
    {BAL_SEC_SETTINGS, "delta0",
     "settings.normal_law = incremental, and gamma_n = 0 or psi = 0: no (delta/delta0) term",
     no_delta0_term},
    {BAL_SEC_SETTINGS, "psi", "settings.gamma_n = 0: no viscous normal dashpot",
     no_viscous_dashpot},
    {BAL_SEC_SETTINGS, "stress_height", "settings.stress_width = 0: no stress cells",
     no_stress_grid},
    {BAL_SEC_SETTINGS, "stress_step", "settings.stress_width = 0: no stress cells",
     no_stress_grid},
    {BAL_SEC_SETTINGS, "skin", "settings.grid = off: every pair, no Verlet list", no_cell_grid},
    {BAL_SEC_SETTINGS, "skin_rule", "settings.grid = off: every pair, no Verlet list",
     no_cell_grid},
    {BAL_SEC_SETTINGS, "rolling_model", "no material has rolling > 0", no_rolling},
    {BAL_SEC_STAGE, "check_every",
     "the stage has no stop rule: stop_ke, stop_stress, stop_servo and stop_unbalanced are 0",
     no_stop_rule},
    {BAL_SEC_FILL, "headroom", "box = 0: no box walls", fill_without_box},
    {BAL_SEC_FILL, "wall_material", "box = 0: no box walls", fill_without_box},
    {BAL_SEC_GRAINS, "overhang", "box = 0: no box walls", grains_without_box},
    {BAL_SEC_GRAINS, "wall_material", "box = 0: no box walls", grains_without_box},
    {BAL_SEC_PILE, "wall_material", "bottom = bumpy: no floor wall", pile_bumpy},
    {BAL_SEC_PILE, "c", "bottom = smooth: c spaces a bumpy row 0", pile_smooth},
};

const size_t bal_scene_n_unused = sizeof bal_scene_unused / sizeof bal_scene_unused[0];

#define SEC(type) sizeof(struct type), offsetof(struct type, given), \
    offsetof(struct type, key_line)

const struct bal_section_info bal_scene_sections[BAL_SEC_COUNT] = {
    {"settings", 0, SEC(bal_settings), "global settings of the run (at most once)"},
    {"material", 1, SEC(bal_material_def), "a group of physical properties (C&S p. 53)"},
    {"disc", 1, SEC(bal_disc_def), "one disc"},
    {"wall", 1, SEC(bal_wall_def), "a straight rigid wall (C&S Fig. 4)"},
    {"fill", 1, SEC(bal_fill_def), "a generator of many discs on a lattice"},
    {"pile", 1, SEC(bal_pile_def), "a generator of a pile on a triangular lattice (MLH Fig. 2)"},
    {"grains", 1, SEC(bal_grains_def),
     "a generator of discs from a grading curve, placed at random without overlap"},
    {"import", 1, SEC(bal_import_def),
     "a prepared state: the discs and walls of the files a run wrote"},
    {"stage", 1, SEC(bal_stage_def), "a stage of the loading protocol, run in file order"},
    {"probe", 1, SEC(bal_probe_def), "a column of series.tsv, in file order"},
};

int bal_scene_key_index(enum bal_section_kind sec, const char *name)
{
    int k = 0;
    for (size_t i = 0; i < bal_scene_n_keys; i++) {
        if (bal_scene_keys[i].section != sec)
            continue;
        if (strcmp(bal_scene_keys[i].name, name) == 0)
            return k;
        k++;
    }
    return -1;
}

int bal_scene_key_control(const char *key)
{
    for (size_t i = 0; i < bal_scene_n_controls; i++)
        if (strcmp(bal_scene_controls[i].key, key) == 0)
            return bal_scene_controls[i].control;
    return -1;
}

const char *bal_scene_key_for_control(int control)
{
    for (size_t i = 0; i < bal_scene_n_controls; i++)
        if (bal_scene_controls[i].control == control)
            return bal_scene_controls[i].key;
    return NULL;
}

const struct bal_key *bal_scene_key_at(enum bal_section_kind sec, int k)
{
    for (size_t i = 0; i < bal_scene_n_keys; i++) {
        if (bal_scene_keys[i].section != sec)
            continue;
        if (k-- == 0)
            return &bal_scene_keys[i];
    }
    return NULL;
}

/* The key list of `ballast keys` and docs/scene-format.md: one Markdown table per
 * section kind. */
void bal_scene_print_keys(FILE *out)
{
    static const char *const type_names[] = {"number", "integer", "two numbers", "name",
                                             "word", NULL, "file", "words", "body"};
    for (int k = 0; k < BAL_SEC_COUNT; k++) {
        const struct bal_section_info *sec = &bal_scene_sections[k];
        fprintf(out, "\n`[%s%s]` — %s\n\n", sec->name, sec->named ? " NAME" : "", sec->doc);
        fprintf(out, "| key | type | default | range | meaning |\n|---|---|---|---|---|\n");
        for (int i = 0;; i++) {
            const struct bal_key *key = bal_scene_key_at((enum bal_section_kind)k, i);
            if (!key)
                break;
            char range[96] = "";
            /* A word's choices are printed whole (the probe quantities are
             * longer than any fixed buffer kept for a numeric range). */
            const char *shown = range;
            if (key->type == BAL_KEY_ENUM)
                shown = key->choices;
            else if (key->type == BAL_KEY_FLAGS)
                snprintf(range, sizeof range, "none, or any of: %s", key->choices);
            else if (key->type == BAL_KEY_DOUBLE || key->type == BAL_KEY_LONG) {
                char lo[32] = "", hi[32] = "";
                if (key->min > -1e300)
                    snprintf(lo, sizeof lo, "%g", key->min);
                if (key->max < 1e300)
                    snprintf(hi, sizeof hi, "%g", key->max);
                if (*lo || *hi)
                    snprintf(range, sizeof range, "[%s, %s]", *lo ? lo : "-inf", *hi ? hi : "inf");
            }
            /* A controller's key shows its form ("WALL v1 v2 omega") as its type. */
            const char *type = key->type == BAL_KEY_CONTROL ? key->choices : type_names[key->type];
            fprintf(out, "| `%s` | %s | %s | %s | %s |\n", key->name, type,
                    key->def ? (*key->def ? key->def : "(none)") : (key->required ? "required" : "(none)"),
                    shown, key->doc);
        }
    }
}
