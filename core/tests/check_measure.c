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
    return s;
}
