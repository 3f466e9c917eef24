/*
 * check_measure.c — suite "measure": what a run reports (measure.c,
 * output.c series rows): kinetic energy from velocities centred at t_N
 * (C&S eq. 31), elastic energy of the contact springs, the unbalanced-force
 * ratio ΔF/F of C&S Tables 1–3, contact counts, disc probes, series rows.
 *
 * Most expected values come from the closed forms of the two-disc worked
 * example (C&S Fig. 1, eqs 1–7; derived in check_integrate.c):
 *   F_A(1) = kvΔt, F_B(1) = 0;  F_A(2) = kvΔt(2 − ε), F_B(2) = 2εkvΔt;
 *   ẋ(1/2) = 0, ẋ(3/2) = εv, ẋ(5/2) = εv(3 − 3ε), ẏ = −ẋ;  ε = kΔt²/m.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <unistd.h>

#include "check_main.h"

/* A few dozen O(1) operations (see check_integrate.c). */
#define ROUNDOFF_REL 1e-12

#define ASSERT_REL(value, expected) \
    ck_assert_double_eq_tol((value), (expected), ROUNDOFF_REL * fabs(expected) + 1e-300)

/* The worked example's numbers (scenes/two_discs_tiny.scene). */
#define K 1e9
#define V 0.12
#define DT 0.01
#define MASS (1000 * BAL_PI * 50 * 50)
#define EPS (K * DT * DT / MASS)
#define F0 (K * V * DT)

/* δ = R1 + R2 − D is a difference of O(1) numbers: ~2e-16 absolute on
 * δ = 0.0285, ~1e-14 relative, and powers up to 2.5 multiply that by 2.5:
 * 1e-12 relative bounds the round-off of anything computed from δ. */
#define OVERLAP_REL 1e-12

static struct tfx *two_discs(void)
{
    struct tfx *f = tfx_parse("", "unused");
    ck_assert_int_eq(bal_scene_load(&f->sc, "scenes/two_discs_tiny.scene", &f->err), BAL_OK);
    ck_assert_msg(tfx_create(f) == BAL_OK, "%s", f->err.msg);
    return f;
}

/* Kinetic energy with velocities at t_N = mean of v_{N−1/2} and v_{N+1/2}
 * (eq. 31); discs do not rotate here.  After cycle 1: ẋ_1 = εv/2, so
 * E = 2 · ½ m (εv/2)²; after cycle 2: ẋ_2 = [εv + εv(3 − 3ε)]/2 =
 * εv(4 − 3ε)/2. */
START_TEST(measure_kinetic_centred)
{
    struct tfx *f = two_discs();
    ck_assert_double_eq(bal_measure_kinetic(f->sim), 0.0);
    t_steps(f, 1);
    const double v1 = EPS * V / 2;
    ASSERT_REL(bal_measure_kinetic(f->sim), MASS * v1 * v1);
    t_steps(f, 1);
    const double v2 = EPS * V * (4 - 3 * EPS) / 2;
    ASSERT_REL(bal_measure_kinetic(f->sim), MASS * v2 * v2);
}
END_TEST

/* Elastic energy of the incremental springs, F_n²/(2 k_n) per contact:
 * after cycle 2, (2 F_A² + F_B²)/(2k). */
START_TEST(measure_elastic_incremental)
{
    struct tfx *f = two_discs();
    t_steps(f, 2);
    const double fa = F0 * (2 - EPS), fb = 2 * EPS * F0;
    ASSERT_REL(bal_measure_elastic(f->sim), (2 * fa * fa + fb * fb) / (2 * K));
}
END_TEST

/* The power law stores ∫ k_n δ0 (δ/δ0)^ν dδ = k_n δ0² (δ/δ0)^{ν+1}/(ν+1).
 * Two discs at rest overlapping by δ = 0.61 + 0.44 − 1.0215 = 0.0285 along
 * a slanted line (ν = 1.5, δ0 = 0.013, k_n = 3.7e4); the contact opens at
 * cycle 1 with positions unchanged. */
START_TEST(measure_elastic_power_law)
{
    const double kn = 3.7e4, nu = 1.5, d0 = 0.013, dist = 1.0215, a = 0.651;
    struct tfx *f = tfx_newf("power",
                             "[settings]\ndt = 1e-5\nnormal_law = power\nnu = %.17g\n"
                             "delta0 = %.17g\n"
                             "[material m]\nkn = %.17g\ndensity = 2.385\n"
                             "[disc p]\nx = 0.35 -0.42\nr = 0.61\nmaterial = m\n"
                             "[disc q]\nx = %.17g %.17g\nr = 0.44\nmaterial = m\n"
                             "[stage s]\ncycles = 1\n",
                             nu, d0, kn, 0.35 + dist * cos(a), -0.42 + dist * sin(a));
    t_steps(f, 1);
    const double delta = 0.61 + 0.44 - dist;
    const struct bal_pairs *L;
    const long c = t_contact(f, "p", "q", &L);
    /* F_n = k_n δ0 (δ/δ0)^ν (MLH eq. 2). */
    const double fn = kn * d0 * pow(delta / d0, nu);
    ck_assert_double_eq_tol(L->fn[c], fn, OVERLAP_REL * fn);
    const double e = kn * d0 * d0 * pow(delta / d0, nu + 1) / (nu + 1);
    ck_assert_double_eq_tol(bal_measure_elastic(f->sim), e, OVERLAP_REL * e);
}
END_TEST

/* ΔF/F: the largest force sum on a free disc over the largest contact
 * force.  Cycle 1: disc x feels F_A alone and F_A is the largest contact
 * force: 1.  Cycle 2: x feels F_A − F_B = kvΔt(2 − 3ε), the largest
 * contact force is F_A = F_C = kvΔt(2 − ε): (2 − 3ε)/(2 − ε). */
START_TEST(measure_unbalanced_ratio)
{
    struct tfx *f = two_discs();
    ck_assert_double_eq(t_probe_value(f, "dF_F"), 0.0); /* no contact yet */
    t_steps(f, 1);
    ASSERT_REL(t_probe_value(f, "dF_F"), 1.0);
    t_steps(f, 1);
    ASSERT_REL(bal_measure_unbalanced(f->sim), (2 - 3 * EPS) / (2 - EPS));
}
END_TEST

/* The force sum of ΔF/F includes the body force m g (C&S p. 52): a disc
 * of mass m = ρπR² (R = 0.3, ρ = 2.385) falling at 0.37 onto a floor it
 * touches gets F_n = k_n · 0.37 · Δt = 3.7 in cycle 1, against m g = 9.81 m
 * down: ΔF/F = |F_n − m g| / F_n. */
START_TEST(measure_unbalanced_with_gravity)
{
    const double kn = 1e4, dt = 1e-3, u = 0.37, g = 9.81, r = 0.3;
    struct tfx *f = tfx_newf("floor",
                             "[settings]\ndt = %.17g\ngravity = 0 %.17g\n"
                             "[material m]\nkn = %.17g\ndensity = 2.385\n"
                             "[wall floor]\np = -1 0\nangle = 0\nh1 = 0\nh2 = 2\nmaterial = m\n"
                             "[disc d]\nx = 0 %.17g\nr = %.17g\nv = 0 %.17g\nmaterial = m\n"
                             "[stage s]\ncycles = 1\n",
                             dt, -g, kn, r - 0.002, r, -u);
    t_steps(f, 1);
    const double fn = kn * u * dt, mg = 2.385 * BAL_PI * r * r * g;
    ASSERT_REL(bal_measure_unbalanced(f->sim), fabs(fn - mg) / fn);
}
END_TEST

/* n_contacts counts touching contacts: A and C after cycle 1, A, B, C
 * after cycle 2. */
START_TEST(measure_contact_count)
{
    struct tfx *f = tfx_parse("", "unused");
    ck_assert_int_eq(bal_scene_load(&f->sc, "scenes/two_discs_tiny.scene", &f->err), BAL_OK);
    ck_assert_int_eq(bal_scene_parse(&f->sc, "[probe nc]\nquantity = n_contacts\n", "extra",
                                     &f->err),
                     BAL_OK);
    ck_assert_msg(tfx_create(f) == BAL_OK, "%s", f->err.msg);
    ck_assert_double_eq(t_probe_value(f, "nc"), 0.0);
    t_steps(f, 1);
    ck_assert_double_eq(t_probe_value(f, "nc"), 2.0);
    t_steps(f, 1);
    ck_assert_double_eq(t_probe_value(f, "nc"), 3.0);
}
END_TEST

/* Disc probes: position at t_N, velocity centred at t_N, rotation in
 * degrees.  A free disc with v_{1/2} = (0.37, −0.21), ω = 0.83 under
 * gravity g = −9.81 in y: after N cycles y_N = y_0 + N v Δt + g Δt² N(N−1)/2,
 * v_y(t_N) = v_{1/2} + (N − ½) g Δt, θ_N = θ_0 + N ω Δt (in degrees). */
START_TEST(measure_disc_probes)
{
    const double dt = 2.7e-3, g = -9.81;
    struct tfx *f = tfx_newf("probes",
                             "[settings]\ndt = %.17g\ngravity = 0 %.17g\n"
                             "[material m]\nkn = 1e4\ndensity = 2.385\n"
                             "[disc d]\nx = 0.5 1.25\nr = 0.3\nv = 0.37 -0.21\ntheta = 12.5\n"
                             "omega = 0.83\nmaterial = m\n"
                             "[stage s]\ncycles = 1\n"
                             "[probe x]\nquantity = disc_x\na = d\n"
                             "[probe y]\nquantity = disc_y\na = d\n"
                             "[probe vx]\nquantity = disc_vx\na = d\n"
                             "[probe vy]\nquantity = disc_vy\na = d\n"
                             "[probe th]\nquantity = disc_theta\na = d\n"
                             "[probe om]\nquantity = disc_omega\na = d\n",
                             dt, g);
    const int n = 30;
    t_steps(f, n);
    ASSERT_REL(t_probe_value(f, "x"), 0.5 + n * 0.37 * dt);
    ASSERT_REL(t_probe_value(f, "y"), 1.25 + n * -0.21 * dt + g * dt * dt * n * (n - 1) / 2);
    ASSERT_REL(t_probe_value(f, "vx"), 0.37);
    ASSERT_REL(t_probe_value(f, "vy"), -0.21 + (n - 0.5) * g * dt);
    ASSERT_REL(t_probe_value(f, "th"), 12.5 + n * 0.83 * dt * 180 / BAL_PI);
    ASSERT_REL(t_probe_value(f, "om"), 0.83);
}
END_TEST

/* Series rows: header "cycle time <probes>", a row every output_every
 * cycles and after the last one; numbers printed so they read back
 * exactly. 11 cycles, output_every = 4: rows at 4, 8, 11. */
START_TEST(measure_series_rows)
{
    const double dt = 2.7e-3;
    struct tfx *f = tfx_newf("series",
                             "[settings]\ndt = %.17g\noutput_every = 4\n"
                             "[material m]\nkn = 1e4\ndensity = 2.385\n"
                             "[disc d]\nx = 0.5 1.25\nr = 0.3\nv = 0.37 -0.21\nmaterial = m\n"
                             "[stage a]\ncycles = 6\n[stage b]\ncycles = 5\n"
                             "[probe x]\nquantity = disc_x\na = d\n"
                             "[probe ek]\nquantity = energy_kinetic\n",
                             dt);
    char *buf = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&buf, &len);
    ck_assert_ptr_nonnull(out);
    bal_output_series_header(f->sim, out);
    const enum bal_status st = bal_sim_run(f->sim, out, NULL, &f->err);
    fclose(out);
    long cycles[3] = {0};
    double times[3] = {0}, xs[3] = {0};
    int rows = 0, header_ok = strncmp(buf, "cycle\ttime\tx\tek\n", 16) == 0;
    for (char *line = strchr(buf, '\n'); line && line[1] && rows < 4; line = strchr(line + 1, '\n')) {
        if (rows < 3 && sscanf(line + 1, "%ld %lf %lf", &cycles[rows], &times[rows], &xs[rows]) != 3)
            break;
        rows++;
    }
    free(buf);
    ck_assert_int_eq(st, BAL_OK);
    ck_assert(header_ok);
    ck_assert_int_eq(rows, 3);
    const long expect[3] = {4, 8, 11};
    for (int r = 0; r < 3; r++) {
        ck_assert_int_eq(cycles[r], expect[r]);
        ASSERT_REL(times[r], expect[r] * dt);
        ASSERT_REL(xs[r], 0.5 + expect[r] * 0.37 * dt);
    }
}
END_TEST

/* ------------------------------------------------------------------ */
/* Stress of MLH eq. (8) and the probes of held discs and weight       */
/* ------------------------------------------------------------------ */

/* MLH eq. (8): σ_αβ = (1/V) Σ_c f_α^c l_β^c over the contacts of one disc,
 * f^c the force on the disc, l^c from its centre to the contact point (the
 * middle of the overlap: |l| = R − δ/2 for equal radii), V = 2√3 R²
 * (measure.c).  A compressive contact pushes the disc along −e (e towards
 * the neighbour) while l runs along +e, so f ⊗ l = −F l e ⊗ e: the core's
 * tensor is tension-positive, compression negative.
 *
 * The scenes are static: a free centre disc at rest among held discs with
 * set overlaps, no gravity, normal_law = power, ν = 1 (F = k_n δ); after one
 * cycle nothing has moved (v_{1/2} = 0), so every contact force is k_n δ of
 * the set overlap. */
#define ST_KN 3.7e4
#define ST_R 0.61
#define ST_RHO 2.385

/* Components of O(1) moments summed over ≤ 6 contacts, each from an overlap
 * with ~1e-14 relative round-off (OVERLAP_REL): 1e-12 of the largest
 * component bounds the error of every component, including those that
 * cancel to zero. */
#define STRESS_REL 1e-12
/* Angles from atan2 of such components, in degrees. */
#define ANGLE_TOL_DEG 1e-9

/* Everything bal_output_state writes, to clean the temporary directory. */
static const char *const state_files[] = {"stress.tsv", "stress_grid.tsv", "contacts.tsv",
                                          "discs.tsv", "walls.tsv"};

static void remove_state_dir(const char *dir)
{
    char path[1024];
    for (size_t k = 0; k < sizeof state_files / sizeof state_files[0]; k++) {
        snprintf(path, sizeof path, "%s/%s", dir, state_files[k]);
        remove(path);
    }
    rmdir(dir);
}

/* Split a TSV line in place into at most `max` fields; returns the count. */
static int split_tab(char *line, char **field, int max)
{
    int n = 0;
    line[strcspn(line, "\r\n")] = '\0';
    for (char *p = line; n < max;) {
        field[n++] = p;
        char *tab = strchr(p, '\t');
        if (!tab)
            break;
        *tab = '\0';
        p = tab + 1;
    }
    return n;
}

/* Read the row of `path` whose column `name` is `who`: the numbers in the
 * columns `cols` into out[].  Returns the number of such rows (1 expected);
 * columns missing from the header give NAN. */
static int read_tsv_row(const char *path, const char *who, int ncols, const char *const *cols,
                        double *out)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return -1;
    char *line = NULL;
    size_t cap = 0;
    char *field[64];
    int idx[16], name_col = -1, found = 0;
    for (int k = 0; k < ncols; k++) {
        idx[k] = -1;
        out[k] = NAN;
    }
    if (getline(&line, &cap, f) > 0) {
        const int n = split_tab(line, field, 64);
        for (int a = 0; a < n; a++) {
            if (strcmp(field[a], "name") == 0)
                name_col = a;
            for (int k = 0; k < ncols; k++)
                if (strcmp(field[a], cols[k]) == 0)
                    idx[k] = a;
        }
    }
    while (name_col >= 0 && getline(&line, &cap, f) > 0) {
        const int n = split_tab(line, field, 64);
        if (n <= name_col || strcmp(field[name_col], who) != 0)
            continue;
        found++;
        for (int k = 0; k < ncols; k++)
            if (idx[k] >= 0 && idx[k] < n)
                out[k] = strtod(field[idx[k]], NULL);
    }
    free(line);
    fclose(f);
    return found;
}

/* The stress.tsv row of disc `who` after bal_output_state into a fresh
 * temporary directory (removed again before returning). */
enum { S_V, S_XX, S_XZ, S_ZX, S_ZZ, S_MAX, S_MIN, S_PHI, S_N };

static int stress_row(const struct tfx *f, const char *who, double out[S_N])
{
    static const char *const cols[S_N] = {"V", "sxx", "sxz", "szx", "szz", "smax", "smin", "phi"};
    char dir[] = "/tmp/ballast_check_XXXXXX";
    if (!mkdtemp(dir))
        return -2;
    struct bal_error err = {0};
    int found = -3;
    if (bal_output_state(f->sim, dir, &err) == BAL_OK) {
        char path[1024];
        snprintf(path, sizeof path, "%s/stress.tsv", dir);
        found = read_tsv_row(path, who, S_N, cols, out);
    }
    remove_state_dir(dir);
    return found;
}

/* A free centre disc c with held neighbours n0, n1, ... at the given angles
 * (degrees) and overlaps. */
static struct tfx *star_with(int n, const double *angle_deg, const double *overlap,
                             const char *settings)
{
    char text[T_TEXT_MAX];
    const double cx = 0.35, cy = -0.42;
    int len = snprintf(text, sizeof text,
                       "[settings]\ndt = 1e-5\nnormal_law = power\n%s"
                       "[material m]\nkn = %.17g\ndensity = %.17g\n"
                       "[disc c]\nx = %.17g %.17g\nr = %.17g\nmaterial = m\n"
                       "[stage s]\ncycles = 1\n",
                       settings, ST_KN, ST_RHO, cx, cy, ST_R);
    for (int k = 0; k < n; k++) {
        const double a = angle_deg[k] * BAL_PI / 180, d = 2 * ST_R - overlap[k];
        len += snprintf(text + len, sizeof text - (size_t)len,
                        "[disc n%d]\nx = %.17g %.17g\nr = %.17g\nfixed = 1\nmaterial = m\n", k,
                        cx + d * cos(a), cy + d * sin(a), ST_R);
    }
    ck_assert_int_lt(len, (int)sizeof text);
    return tfx_new(text, "star");
}

static struct tfx *star(int n, const double *angle_deg, const double *overlap)
{
    return star_with(n, angle_deg, overlap, "");
}

/* Six equal contacts at 60° (a hexagonal cell, rotated by 17.3°), overlap
 * δ = 0.0137: F = k_n δ, l = R − δ/2, and since Σ_c e_c ⊗ e_c = 3 I for six
 * directions 60° apart,
 *   σ = −(1/V) F l Σ e_c ⊗ e_c = −(3 F l / V) I,  V = 2√3 R²:
 * isotropic, σ_xx = σ_zz = σ_max = σ_min = −3Fl/V, σ_xz = σ_zx = 0.  (The
 * held ring discs also overlap each other — the hexagon's side equals its
 * radius, 2R − δ — which does not enter the centre disc's sum.) */
START_TEST(measure_stress_hexagonal_isotropic)
{
    const double delta = 0.0137;
    double ang[6], ov[6];
    for (int k = 0; k < 6; k++) {
        ang[k] = 17.3 + 60.0 * k;
        ov[k] = delta;
    }
    struct tfx *f = star(6, ang, ov);
    t_steps(f, 1);
    const double F = ST_KN * delta, l = ST_R - delta / 2, vol = 2 * sqrt(3.0) * ST_R * ST_R;
    const double sigma = -3 * F * l / vol, tol = STRESS_REL * fabs(sigma);

    /* the moments Σ f ⊗ l directly */
    const struct bal_sim *s = f->sim;
    double *m = malloc(4 * (size_t)s->n * sizeof *m);
    ck_assert_ptr_nonnull(m);
    bal_measure_moments(s, m);
    const int i = t_slot(f, "c");
    double mc[4];
    memcpy(mc, m + 4 * i, sizeof mc);
    free(m);
    ck_assert_double_eq_tol(bal_measure_disc_volume(ST_R), vol, 1e-15 * vol);
    ck_assert_double_eq_tol(mc[0] / vol, sigma, tol);
    ck_assert_double_eq_tol(mc[1] / vol, 0.0, tol);
    ck_assert_double_eq_tol(mc[2] / vol, 0.0, tol);
    ck_assert_double_eq_tol(mc[3] / vol, sigma, tol);

    /* the same through stress.tsv (written with %.17g: read back exactly) */
    double row[S_N];
    ck_assert_int_eq(stress_row(f, "c", row), 1);
    ck_assert_double_eq_tol(row[S_V], vol, 1e-15 * vol);
    ck_assert_double_eq_tol(row[S_XX], sigma, tol);
    ck_assert_double_eq_tol(row[S_ZZ], sigma, tol);
    ck_assert_double_eq_tol(row[S_XZ], 0.0, tol);
    ck_assert_double_eq_tol(row[S_ZX], 0.0, tol);
    ck_assert_double_eq_tol(row[S_MAX], sigma, tol);
    ck_assert_double_eq_tol(row[S_MIN], sigma, tol);
    ck_assert(sigma < 0); /* compression is negative */
}
END_TEST

/* Moving averages (stress_grid.tsv): cells of width W = 3.1 and height
 * H = 2.7 stepped by W contain free discs only, so in the hexagonal star
 * exactly one cell holds a disc, the centre one, and its stress is the
 * centre's moment over the cell area: σ = −(3 F l / (W H)) I.  Every other
 * cell is empty and is not written. */
START_TEST(measure_stress_grid_cell)
{
    const double delta = 0.0137, W = 3.1, H = 2.7;
    double ang[6], ov[6];
    for (int k = 0; k < 6; k++) {
        ang[k] = 17.3 + 60.0 * k;
        ov[k] = delta;
    }
    struct tfx *f = star_with(6, ang, ov,
                              "stress_width = 3.1\nstress_height = 2.7\nstress_step = 3.1\n");
    t_steps(f, 1);
    const double F = ST_KN * delta, l = ST_R - delta / 2;
    const double sigma = -3 * F * l / (W * H), tol = STRESS_REL * fabs(sigma);
    char dir[] = "/tmp/ballast_check_XXXXXX";
    ck_assert_ptr_nonnull(mkdtemp(dir));
    struct bal_error err = {0};
    ck_assert_int_eq(bal_output_state(f->sim, dir, &err), BAL_OK);
    char path[1024];
    snprintf(path, sizeof path, "%s/stress_grid.tsv", dir);
    FILE *g = fopen(path, "r");
    ck_assert_ptr_nonnull(g);
    char line[1024];
    ck_assert_ptr_nonnull(fgets(line, sizeof line, g));
    ck_assert(strncmp(line, "xc\tyc\tn\tsxx", 11) == 0);
    int rows = 0, n = 0;
    double v[7] = {0};
    while (fgets(line, sizeof line, g)) {
        rows++;
        ck_assert_int_eq(sscanf(line, "%lf %lf %d %lf %lf %lf %lf", &v[0], &v[1], &n, &v[2],
                                &v[3], &v[4], &v[5]),
                         7);
    }
    fclose(g);
    remove_state_dir(dir);
    ck_assert_int_eq(rows, 1);
    ck_assert_int_eq(n, 1);
    ck_assert_double_eq_tol(v[2], sigma, tol); /* sxx */
    ck_assert_double_eq_tol(v[3], 0.0, tol);   /* sxz */
    ck_assert_double_eq_tol(v[4], 0.0, tol);   /* szx */
    ck_assert_double_eq_tol(v[5], sigma, tol); /* szz */
}
END_TEST

/* Anisotropic: two contacts along e at a = 71.3° (overlap δ1 = 0.0137) and
 * two along t = (−sin a, cos a) (δ2 = 0.0052).  With F_k = k_n δ_k,
 * l_k = R − δ_k/2, X_k = 2 F_k l_k / V:
 *   σ = −X1 e ⊗ e − X2 t ⊗ t,
 *   σ_xx = −X1 cos²a − X2 sin²a,  σ_zz = −X1 sin²a − X2 cos²a,
 *   σ_xz = σ_zx = −(X1 − X2) sin a cos a;
 * principal values σ_max = −X2 (axis t, at a + 90° = 161.3°) and
 * σ_min = −X1 (axis e, at a), X1 > X2.
 *
 * The angle.  Eq. (9)'s first form, φ = arctan[(σ_max − σ_xx)/σ_xz], is the
 * axis of σ_max; applied to the core's tension-positive tensor that is the
 * least compressive axis, a + 90° — stress.tsv's phi (output.c: "the angle
 * of the major axis", i.e. of its smax).  MLH plot stresses compression
 * positive (Figs 3, 6, 7: S_max is the largest compression), where the
 * same formula gives the most compressive axis a; eq. (9)'s second form,
 * π/2 + ½ arctan[2σ_xz/(σ_xx − σ_zz)], gives a on either sign convention
 * here.  So MLH's φ = phi − 90° (mod 180°), the conversion harness/piles.py
 * applies; both are checked. */
START_TEST(measure_stress_anisotropic_principal)
{
    const double a_deg = 71.3, d1 = 0.0137, d2 = 0.0052;
    const double ang[4] = {a_deg, a_deg + 180, a_deg + 90, a_deg + 270};
    const double ov[4] = {d1, d1, d2, d2};
    struct tfx *f = star(4, ang, ov);
    t_steps(f, 1);
    const double vol = 2 * sqrt(3.0) * ST_R * ST_R, a = a_deg * BAL_PI / 180;
    const double X1 = 2 * ST_KN * d1 * (ST_R - d1 / 2) / vol;
    const double X2 = 2 * ST_KN * d2 * (ST_R - d2 / 2) / vol;
    const double ca = cos(a), sa = sin(a);
    const double sxx = -X1 * ca * ca - X2 * sa * sa, szz = -X1 * sa * sa - X2 * ca * ca;
    const double sxz = -(X1 - X2) * sa * ca, tol = STRESS_REL * X1;
    double row[S_N];
    ck_assert_int_eq(stress_row(f, "c", row), 1);
    ck_assert_double_eq_tol(row[S_XX], sxx, tol);
    ck_assert_double_eq_tol(row[S_ZZ], szz, tol);
    ck_assert_double_eq_tol(row[S_XZ], sxz, tol);
    ck_assert_double_eq_tol(row[S_ZX], sxz, tol); /* frictionless: symmetric (MLH Sec. 3) */
    ck_assert_double_eq_tol(row[S_MAX], -X2, tol);
    ck_assert_double_eq_tol(row[S_MIN], -X1, tol);
    /* the core's phi: axis of smax, a + 90° */
    ck_assert_double_eq_tol(row[S_PHI], a_deg + 90, ANGLE_TOL_DEG);
    /* eq. (9), first form, on the tension-positive tensor read back */
    double phi1 = atan((row[S_MAX] - row[S_XX]) / row[S_XZ]) * 180 / BAL_PI;
    phi1 = fmod(phi1 + 180, 180);
    ck_assert_double_eq_tol(phi1, row[S_PHI], ANGLE_TOL_DEG);
    /* MLH's φ (most compressive axis): a = phi − 90°, and the second form */
    const double phi2 =
        90 + 0.5 * atan(2 * row[S_XZ] / (row[S_XX] - row[S_ZZ])) * 180 / BAL_PI;
    ck_assert_double_eq_tol(fmod(row[S_PHI] + 90, 180), a_deg, ANGLE_TOL_DEG);
    ck_assert_double_eq_tol(phi2, a_deg, ANGLE_TOL_DEG);
}
END_TEST

/* Probes held_fx, held_fy (Σ of the force sums of held discs) and weight_x,
 * weight_y (Σ m g over free discs, times the ramp).  A free disc c
 * (R = 0.44) rests on held a (R = 0.61, at 235° from c, overlap 0.0137) and
 * held b (R = 0.53, at 310°, overlap 0.0089); a also presses into a floor
 * wall by 0.0061; a and b do not touch (gap 0.077); a free disc e flies
 * elsewhere.  Gravity (0.37, −9.81), ν = 1.  After one cycle from rest:
 *   held_f = k_n δ_a u_a + k_n δ_b u_b + k_n δ_w (0, 1),
 * u the unit vector from c to the held disc (c pushes it away), and
 *   weight = (m_c + m_e) g. */
START_TEST(measure_held_and_weight_probes)
{
    const double g[2] = {0.37, -9.81}, ra = 0.61, rb = 0.53, rc = 0.44, re = 0.29;
    const double da = 0.0137, db = 0.0089, dw = 0.0061;
    const double c[2] = {0.35, 1.6};
    const double ua[2] = {cos(235 * BAL_PI / 180), sin(235 * BAL_PI / 180)};
    const double ub[2] = {cos(310 * BAL_PI / 180), sin(310 * BAL_PI / 180)};
    const double a[2] = {c[0] + (rc + ra - da) * ua[0], c[1] + (rc + ra - da) * ua[1]};
    const double b[2] = {c[0] + (rc + rb - db) * ub[0], c[1] + (rc + rb - db) * ub[1]};
    ck_assert(hypot(b[0] - a[0], b[1] - a[1]) > ra + rb + 0.05);
    struct tfx *f = tfx_newf(
        "held",
        "[settings]\ndt = 1e-5\nnormal_law = power\ngravity = %.17g %.17g\n"
        "[material m]\nkn = %.17g\ndensity = %.17g\n"
        "[wall floor]\np = -1.5 %.17g\nangle = 0\nh1 = 0\nh2 = 3\nmaterial = m\n"
        "[disc c]\nx = %.17g %.17g\nr = %.17g\nmaterial = m\n"
        "[disc a]\nx = %.17g %.17g\nr = %.17g\nfixed = 1\nmaterial = m\n"
        "[disc b]\nx = %.17g %.17g\nr = %.17g\nfixed = 1\nmaterial = m\n"
        "[disc e]\nx = 3.5 4.2\nr = %.17g\nmaterial = m\n"
        "[stage s]\ncycles = 1\n"
        "[probe hx]\nquantity = held_fx\n[probe hy]\nquantity = held_fy\n"
        "[probe wx]\nquantity = weight_x\n[probe wy]\nquantity = weight_y\n",
        g[0], g[1], ST_KN, ST_RHO, a[1] - ra + dw, c[0], c[1], rc, a[0], a[1], ra, b[0], b[1], rb,
        re);
    t_steps(f, 1);
    const double fa = ST_KN * da, fb = ST_KN * db, fw = ST_KN * dw;
    const double hx = fa * ua[0] + fb * ub[0], hy = fa * ua[1] + fb * ub[1] + fw;
    const double mfree = ST_RHO * BAL_PI * (rc * rc + re * re);
    const double scale = fa + fb + fw;
    ck_assert_double_eq_tol(t_probe_value(f, "hx"), hx, STRESS_REL * scale);
    ck_assert_double_eq_tol(t_probe_value(f, "hy"), hy, STRESS_REL * scale);
    ASSERT_REL(t_probe_value(f, "wx"), mfree * g[0]);
    ASSERT_REL(t_probe_value(f, "wy"), mfree * g[1]);
}
END_TEST

/* weight_y follows the gravity ramp: a stage of n = 5 cycles with ramp = 1
 * applies the share (k + 1)/n in its cycle k (0-based), and the series row
 * written after that cycle reads m g (k + 1)/n; the following stage applies
 * all of it. */
START_TEST(measure_weight_follows_ramp)
{
    const double gy = -9.81, r = 0.44;
    struct tfx *f = tfx_newf("ramp",
                             "[settings]\ndt = 1.3e-3\ngravity = 0 %.17g\n"
                             "[material m]\nkn = 1e4\ndensity = %.17g\n"
                             "[disc d]\nx = 0.5 1.25\nr = %.17g\nmaterial = m\n"
                             "[stage up]\ncycles = 5\nramp = 1\n[stage on]\ncycles = 2\n"
                             "[probe wy]\nquantity = weight_y\n",
                             gy, ST_RHO, r);
    char *buf = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&buf, &len);
    ck_assert_ptr_nonnull(out);
    bal_output_series_header(f->sim, out);
    const enum bal_status st = bal_sim_run(f->sim, out, NULL, &f->err);
    fclose(out);
    long cycle[8] = {0};
    double w[8] = {0};
    int rows = 0;
    for (char *line = strchr(buf, '\n'); line && line[1] && rows < 8; line = strchr(line + 1, '\n')) {
        double time;
        if (sscanf(line + 1, "%ld %lf %lf", &cycle[rows], &time, &w[rows]) != 3)
            break;
        rows++;
    }
    free(buf);
    ck_assert_int_eq(st, BAL_OK);
    ck_assert_int_eq(rows, 7);
    const double mg = ST_RHO * BAL_PI * r * r * gy;
    for (int k = 0; k < 7; k++) {
        ck_assert_int_eq(cycle[k], k + 1);
        ASSERT_REL(w[k], k < 5 ? mg * (k + 1) / 5.0 : mg);
    }
}
END_TEST

/* output_at_end = 1 on a stage adds a row after its last cycle: 11 cycles,
 * output_every = 4, the first stage of 6 asking for it: rows at 4, 6, 8, 11;
 * and after a stage that its stop rule ends early. */
START_TEST(measure_series_row_at_stage_end)
{
    struct tfx *f = tfx_new("[settings]\ndt = 2.7e-3\noutput_every = 4\n"
                            "[material m]\nkn = 1e4\ndensity = 2.385\n"
                            "[disc d]\nx = 0.5 1.25\nr = 0.3\nv = 0.37 -0.21\nmaterial = m\n"
                            "[stage a]\ncycles = 6\noutput_at_end = 1\n[stage b]\ncycles = 5\n"
                            "[probe x]\nquantity = disc_x\na = d\n",
                            "ends");
    char *buf = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&buf, &len);
    ck_assert_ptr_nonnull(out);
    ck_assert_int_eq(bal_sim_run(f->sim, out, NULL, &f->err), BAL_OK);
    fclose(out);
    long cycles[8] = {0};
    int rows = 0;
    /* bal_sim_run writes rows only (the header is bal_output_series_header's) */
    for (char *line = buf; line && *line && rows < 8; line = strchr(line, '\n'), line = line ? line + 1 : NULL)
        if (sscanf(line, "%ld", &cycles[rows]) == 1)
            rows++;
    free(buf);
    ck_assert_int_eq(rows, 4);
    ck_assert_int_eq(cycles[0], 4);
    ck_assert_int_eq(cycles[1], 6);
    ck_assert_int_eq(cycles[2], 8);
    ck_assert_int_eq(cycles[3], 11);
}
END_TEST

/* Issue 23: a stage given in simulated time runs ceil(time/dt) cycles, to
 * 1e-9 of a step (0.0162 with dt 2.7e-3 is 6 cycles although 0.0162/2.7e-3
 * is 6.000000000000001 in doubles), so changing dt keeps the time; a time
 * between two steps takes the next; --set of one replaces the other. */
START_TEST(measure_stage_in_time)
{
    static const char *scene = "[settings]\ndt = %s\n"
                               "[material m]\nkn = 1e4\ndensity = 2.385\n"
                               "[disc d]\nx = 0.5 1.25\nr = 0.3\nmaterial = m\n"
                               "[stage a]\ntime = %s\n[stage b]\ncycles = 5\n";
    struct { const char *dt, *time; long cycles; } cases[] = {
        {"2.7e-3", "0.0162", 6}, {"1.35e-3", "0.0162", 12}, {"2.7e-3", "0.0163", 7},
        {"0.1", "0.3", 3}, {"2.7e-3", "0", 0},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        struct tfx *f = tfx_newf("time", scene, cases[k].dt, cases[k].time);
        ck_assert_int_eq(bal_sim_stage_cycles(f->sim, 0), cases[k].cycles);
        ck_assert_int_eq(bal_sim_stage_cycles(f->sim, 1), 5);
        ck_assert_int_eq(bal_sim_run(f->sim, NULL, NULL, &f->err), BAL_OK);
        struct bal_run_info in;
        bal_sim_info(f->sim, &in);
        ck_assert_int_eq(in.steps, cases[k].cycles + 5);
        tfx_release(f);
    }
    /* An override of cycles replaces time, and of time replaces cycles. */
    struct tfx *f = tfx_parse("[settings]\ndt = 0.1\nforce_dt = 1\n[material m]\nkn = 1e4\ndensity = 2.385\n"
                              "[disc d]\nx = 0.5 1.25\nr = 0.3\nmaterial = m\n"
                              "[stage a]\ntime = 0.3\n[stage b]\ncycles = 5\n", "set");
    ck_assert_int_eq(bal_scene_set(&f->sc, "stage.a.cycles=4", &f->err), BAL_OK);
    ck_assert_int_eq(bal_scene_set(&f->sc, "stage.b.time=0.2", &f->err), BAL_OK);
    ck_assert_int_eq(bal_scene_validate(&f->sc, &f->err), BAL_OK);
    ck_assert_int_eq(tfx_create(f), BAL_OK);
    ck_assert_int_eq(bal_sim_stage_cycles(f->sim, 0), 4);
    ck_assert_int_eq(bal_sim_stage_cycles(f->sim, 1), 2);
}
END_TEST

/* Both lengths, or none, are refused with the file, the line and the key;
 * a time of more than 1e15 steps too. */
START_TEST(measure_stage_length_refused)
{
    static const char *head = "[settings]\ndt = 1e-3\n[material m]\nkn = 1e4\ndensity = 2.385\n"
                              "[disc d]\nx = 0.5 1.25\nr = 0.3\nmaterial = m\n";
    char text[512];
    snprintf(text, sizeof text, "%s[stage a]\ncycles = 3\ntime = 0.3\n", head);
    struct tfx *f = tfx_parse(text, "both");
    ck_assert_int_eq(bal_scene_validate(&f->sc, &f->err), BAL_EINVAL);
    ck_assert_msg(t_contains(f->err.msg, "both:12: time:") && t_contains(f->err.msg, "both cycles and time"),
                  "%s", f->err.msg);
    tfx_release(f);
    snprintf(text, sizeof text, "%s[stage a]\nramp = 1\n", head);
    f = tfx_parse(text, "none");
    ck_assert_int_eq(bal_scene_validate(&f->sc, &f->err), BAL_EINVAL);
    ck_assert_msg(t_contains(f->err.msg, "none:10: [stage a]: cycles: required"), "%s", f->err.msg);
    tfx_release(f);
    snprintf(text, sizeof text, "%s[stage a]\ntime = 1e20\n", head);
    f = tfx_parse(text, "long");
    ck_assert_int_eq(bal_scene_validate(&f->sc, &f->err), BAL_OK);
    ck_assert_int_eq(tfx_create(f), BAL_EINVAL);
    ck_assert_msg(t_contains(f->err.msg, "long:11: time:"), "%s", f->err.msg);
}
END_TEST

/* The progress report is called during a long run with what it says, and
 * reading it changes nothing: positions bitwise those of a run without. */
struct progress_seen { int calls; long last_step, steps; };
static void count_progress(const struct bal_progress *p, void *ctx)
{
    struct progress_seen *seen = ctx;
    seen->calls++;
    ck_assert_int_ge(p->step, seen->last_step);
    ck_assert_int_le(p->stage_cycle, p->stage_cycles);
    seen->last_step = p->step;
    seen->steps = p->steps;
}

START_TEST(measure_progress_reports_change_nothing)
{
    static const char *scene = "[settings]\ndt = 1e-3\n[material m]\nkn = 1e4\ndensity = 2.385\n"
                               "[disc d]\nx = 0.5 1.25\nr = 0.3\nv = 0.1 0\nmaterial = m\n"
                               "[disc e]\nx = 1.05 1.25\nr = 0.3\nmaterial = m\n"
                               "[stage a]\ncycles = 3000\n[stage b]\ntime = 3\n";
    struct tfx *a = tfx_new(scene, "plain"), *b = tfx_new(scene, "watched");
    struct progress_seen seen = {0, 0, 0};
    bal_sim_set_progress(b->sim, count_progress, &seen, 0); /* every 1024 cycles */
    ck_assert_int_eq(bal_sim_run(a->sim, NULL, NULL, &a->err), BAL_OK);
    ck_assert_int_eq(bal_sim_run(b->sim, NULL, NULL, &b->err), BAL_OK);
    ck_assert_int_eq(seen.calls, 2 + 2); /* 3000 and 3000 cycles: at 1024 and 2048 of each */
    ck_assert_int_eq(seen.steps, 6000);
    const int i = t_slot(a, "d"), j = t_slot(b, "d");
    ck_assert(memcmp(&a->sim->x[i], &b->sim->x[j], sizeof(double)) == 0);
    ck_assert(memcmp(&a->sim->vx[i], &b->sim->vx[j], sizeof(double)) == 0);
}
END_TEST

/* Issue 18: a series row is written only when every probe value is a
 * number; otherwise nothing of it is written and the probe is named by its
 * file, line and key. */
START_TEST(measure_series_row_not_finite)
{
    struct tfx *f = tfx_new("[settings]\ndt = 1e-3\n"
                            "[material m]\nkn = 1e4\ndensity = 2.385\n"
                            "[disc d]\nx = 0.5 1.25\nr = 0.3\nmaterial = m\n"
                            "[stage a]\ncycles = 6\n"
                            "[probe ek]\nquantity = energy_kinetic\n"
                            "[probe x]\nquantity = disc_x\na = d\n",
                            "rows");
    t_steps(f, 1);
    char *buf = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&buf, &len);
    ck_assert_ptr_nonnull(out);
    ck_assert_int_eq(bal_output_series_row(f->sim, out, &f->err), BAL_OK);
    fflush(out);
    const size_t one_row = len;
    ck_assert_uint_gt(one_row, 0);
    f->sim->x[t_slot(f, "d")] = INFINITY;
    ck_assert_int_eq(bal_output_series_row(f->sim, out, &f->err), BAL_EUNSTABLE);
    fclose(out);
    ck_assert_uint_eq(len, one_row); /* nothing of the second row */
    ck_assert_msg(t_contains(f->err.msg, "rows:15: quantity: [probe x]: the value is inf at step 1"),
                  "%s", f->err.msg);
    free(buf);
}
END_TEST

Suite *suite_measure(void)
{
    Suite *s = suite_create("measure");
    TCase *tc = tcase_create("energy");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, measure_kinetic_centred);
    tcase_add_test(tc, measure_elastic_incremental);
    tcase_add_test(tc, measure_elastic_power_law);
    suite_add_tcase(s, tc);

    tc = tcase_create("probes");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, measure_unbalanced_ratio);
    tcase_add_test(tc, measure_unbalanced_with_gravity);
    tcase_add_test(tc, measure_contact_count);
    tcase_add_test(tc, measure_disc_probes);
    tcase_add_test(tc, measure_series_rows);
    suite_add_tcase(s, tc);

    tc = tcase_create("stress");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, measure_stress_hexagonal_isotropic);
    tcase_add_test(tc, measure_stress_grid_cell);
    tcase_add_test(tc, measure_stress_anisotropic_principal);
    tcase_add_test(tc, measure_held_and_weight_probes);
    tcase_add_test(tc, measure_weight_follows_ramp);
    tcase_add_test(tc, measure_series_row_not_finite);
    tcase_add_test(tc, measure_series_row_at_stage_end);
    tcase_add_test(tc, measure_stage_in_time);
    tcase_add_test(tc, measure_stage_length_refused);
    tcase_add_test(tc, measure_progress_reports_change_nothing);
    suite_add_tcase(s, tc);
    return s;
}
