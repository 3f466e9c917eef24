/*
 * check_sim.c — suite "sim": the staged run of sim.c — stages in order
 * with their wall motions and gravity ramp, the stop rules, and how
 * bal_sim_run ends (BAL_EUNSTABLE naming the disc and the step, BAL_EINTR).
 * The tests moved here from check_integrate.c unchanged.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check_main.h"

/* Closed forms evaluated here and the core's arithmetic differ by the
 * rounding of a few dozen O(1) operations: 1e-12 relative bounds that
 * with a wide margin. */
#define ROUNDOFF_REL 1e-12

#define ASSERT_REL(value, expected) \
    ck_assert_double_eq_tol((value), (expected), ROUNDOFF_REL * fabs(expected) + 1e-300)

/* ------------------------------------------------------------------ */
/* How a run ends                                                      */
/* ------------------------------------------------------------------ */

/* Stages run in order; each sets the wall motions of its moves; walls it
 * does not name rest.  left moves 7 cycles at 0.1 in `load`, rests 5 in
 * `hold`: P_x = 7 · 0.1 · Δt; 12 steps in all. */
START_TEST(integrate_run_stages)
{
    const double dt = 1.3e-3;
    struct tfx *f = tfx_newf("stages",
                             "[settings]\ndt = %.17g\n"
                             "[material m]\nkn = 1e4\ndensity = 2.385\n"
                             "[wall left]\np = -2 0\nangle = 90\nh1 = -1\nh2 = 1\nmaterial = m\n"
                             "[disc d]\nx = 0 0\nr = 0.5\nmaterial = m\n"
                             "[stage load]\ncycles = 7\nmove = left 0.1 0 0\n"
                             "[stage hold]\ncycles = 5\n",
                             dt);
    ck_assert_int_eq(bal_sim_run(f->sim, NULL, NULL, &f->err), BAL_OK);
    struct bal_run_info info;
    bal_sim_info(f->sim, &info);
    ck_assert_int_eq(info.steps, 12);
    ASSERT_REL(info.time, 12 * dt);
    ASSERT_REL(f->sim->walls[0].p[0], -2 + 7 * 0.1 * dt);
    ck_assert_double_eq(f->sim->walls[0].v[0], 0.0);
    ck_assert_int_eq(f->sim->stage, 1);
}
END_TEST

/* A disc sandwiched between two held discs, spinning, with a huge cohesion
 * (friction 0): the normal forces stay 0 and the two shear forces cancel,
 * so the disc only turns, on a rotational spring 2 k_s R² against
 * I = m R²/2.  Its critical step is 2√(I/(2 k_s R²)) = 2√(m/(4 k_s)) =
 * 0.0177; Δt = 0.5 multiplies the spin by ~4 k_s Δt²/m ≈ 3.2e3 a cycle, so
 * it overflows within ~90 cycles. */
static const char *const unstable_scene =
    "[settings]\ndt = 0.5\n"
    "[material m]\nkn = 1e4\nks = 1e4\nfriction = 0\ncohesion = 1.7e308\ndensity = 1\n"
    "[disc left]\nx = -1.9 0\nr = 1\nfixed = 1\nmaterial = m\n"
    "[disc free]\nx = 0 0\nr = 1\nomega = 1\nmaterial = m\n"
    "[disc right]\nx = 1.9 0\nr = 1\nfixed = 1\nmaterial = m\n";

/* BAL_EUNSTABLE: the message names the disc and the step it was caught at. */
START_TEST(integrate_unstable_names_disc_and_step)
{
    char text[1024];
    snprintf(text, sizeof text, "%s[stage s]\ncycles = 1000\n", unstable_scene);
    struct tfx *f = tfx_new(text, "unstable");
    const enum bal_status st = bal_sim_run(f->sim, NULL, NULL, &f->err);
    ck_assert_msg(st == BAL_EUNSTABLE, "status %d: %s", st, f->err.msg);
    ck_assert_int_eq(f->err.code, BAL_EUNSTABLE);
    struct bal_run_info info;
    bal_sim_info(f->sim, &info);
    ck_assert_int_lt(info.steps, 1000); /* stopped early */
    char step[64];
    snprintf(step, sizeof step, "at step %ld", info.steps);
    ck_assert_msg(t_contains(f->err.msg, "unstable: disc free:"), "%s", f->err.msg);
    ck_assert_msg(t_contains(f->err.msg, step), "'%s' lacks '%s'", f->err.msg, step);
    ck_assert(!isfinite(f->sim->w[t_slot(f, "free")]));
}
END_TEST

/* With a series file the last cycle writes a row and is checked: a run
 * shorter than the periodic finiteness check still ends in BAL_EUNSTABLE. */
START_TEST(integrate_unstable_short_run_with_series)
{
    char text[1024];
    snprintf(text, sizeof text, "%s[stage s]\ncycles = 200\n", unstable_scene);
    struct tfx *f = tfx_new(text, "unstable");
    char *buf = NULL;
    size_t len = 0;
    FILE *series = open_memstream(&buf, &len);
    ck_assert_ptr_nonnull(series);
    const enum bal_status st = bal_sim_run(f->sim, series, NULL, &f->err);
    fclose(series);
    free(buf);
    ck_assert_msg(st == BAL_EUNSTABLE, "status %d: %s", st, f->err.msg);
    /* the energy guard, checked at every row, sees it first */
    ck_assert_msg(t_contains(f->err.msg, "disc free:") || t_contains(f->err.msg, "energy runaway"),
                  "%s", f->err.msg);
}
END_TEST

/* Without a series file (library use: the benchmark, tests) the same short
 * run must not report success with a non-finite state: bal_sim_run "stops
 * early, with a status, ... when the state stops being finite" (sim.c) and
 * BAL_EUNSTABLE means "the run blew up" (ballast.h). */
START_TEST(integrate_unstable_short_run_without_series)
{
    char text[1024];
    snprintf(text, sizeof text, "%s[stage s]\ncycles = 200\n", unstable_scene);
    struct tfx *f = tfx_new(text, "unstable");
    const enum bal_status st = bal_sim_run(f->sim, NULL, NULL, &f->err);
    const int finite = isfinite(f->sim->w[t_slot(f, "free")]);
    ck_assert_msg(!finite, "the scene did not blow up: the test is vacuous");
    ck_assert_msg(st == BAL_EUNSTABLE,
                  "bal_sim_run returned %d (%s) although the state is not finite", st,
                  bal_strerror(st));
}
END_TEST

/* BAL_EINTR: a stop flag already set when the run starts. */
START_TEST(integrate_interrupted)
{
    struct tfx *f = tfx_new("[material m]\nkn = 1e4\ndensity = 2.385\n"
                            "[disc d]\nx = 0 0\nr = 0.5\nv = 0.1 0\nmaterial = m\n"
                            "[stage s]\ncycles = 100\n",
                            "stop");
    volatile sig_atomic_t stop = 1;
    const enum bal_status st = bal_sim_run(f->sim, NULL, &stop, &f->err);
    ck_assert_int_eq(st, BAL_EINTR);
    ck_assert_int_eq(f->err.code, BAL_EINTR);
    ck_assert_msg(t_contains(f->err.msg, "stop: interrupted at step 0"), "%s", f->err.msg);
    ck_assert_int_eq(f->sim->step, 0);
    ck_assert_double_eq(f->sim->x[0], 0.0);
}
END_TEST

/* ------------------------------------------------------------------ */
/* Stages: gravity ramp, stop rules, skipped stages (MLH Secs 3–4)     */
/* ------------------------------------------------------------------ */

/* ramp = 1: in cycle k = 1..n of the stage gravity is scaled by k/n
 * ("gravity is slowly increased from zero", MLH Sec. 4).  A free disc from
 * v_{1/2} = v0 (eq. 22 with m g k/n added):
 *   v_{k+1/2} = v0 + g Δt Σ_{i≤k} i/n = v0 + g Δt k(k+1)/(2n),
 * so after the ramp stage v = v0 + g Δt (n+1)/2 — half the unramped gain
 * plus half a step — and
 *   x_n = x0 + Δt Σ_{k=0}^{n−1} v_{k+1/2} = x0 + n v0 Δt + g Δt² (n² − 1)/6.
 * A following stage without ramp adds the full g Δt per cycle:
 *   v = V_n + m g Δt,  x = x_n + m V_n Δt + g Δt² m(m − 1)/2. */
START_TEST(integrate_gravity_ramp)
{
    const double dt = 2.7e-3, g[2] = {0.25, -9.81}, v0[2] = {0.37, 1.9};
    const double x0[2] = {-0.35, 1.15};
    const long n = 37, m = 11;
    for (int with_next = 0; with_next < 2; with_next++) {
        struct tfx *f = tfx_newf("ramp",
                                 "[settings]\ndt = %.17g\ngravity = %.17g %.17g\n"
                                 "[material m]\nkn = 1e4\ndensity = 2.385\n"
                                 "[disc d]\nx = %.17g %.17g\nr = 0.3\nv = %.17g %.17g\n"
                                 "material = m\n"
                                 "[stage up]\ncycles = %ld\nramp = 1\n%s",
                                 dt, g[0], g[1], x0[0], x0[1], v0[0], v0[1], n,
                                 with_next ? "[stage on]\ncycles = 11\n" : "");
        ck_assert_int_eq(bal_sim_run(f->sim, NULL, NULL, &f->err), BAL_OK);
        const int i = t_slot(f, "d");
        const struct bal_sim *s = f->sim;
        for (int k = 0; k < 2; k++) {
            const double vn = v0[k] + g[k] * dt * (double)(n + 1) / 2;
            const double xn = x0[k] + (double)n * v0[k] * dt + g[k] * dt * dt * (double)(n * n - 1) / 6;
            const double v = with_next ? vn + (double)m * g[k] * dt : vn;
            const double x = with_next ? xn + (double)m * vn * dt + g[k] * dt * dt * (double)(m * (m - 1)) / 2
                                       : xn;
            ASSERT_REL(k ? s->vy[i] : s->vx[i], v);
            ASSERT_REL(k ? s->y[i] : s->x[i], x);
        }
        ck_assert_double_eq(s->gfac, 1.0); /* the ramp ends with its stage */
        ck_assert_int_eq(s->log[0].cycles, n);
        ck_assert_int_eq(s->log[0].stopped, 0);
        tfx_release(f);
    }
}
END_TEST

/* Stop rules (MLH Sec. 3: "the kinetic energy has to be orders of
 * magnitude smaller than the elastic energy ... and the stresses no longer
 * vary").  A scene whose measures are closed forms:
 *   - a held disc h (R = 0.61) pressed by a floor wall moving up at
 *     v_w = 0.0173: overlap δ_N = δ_i + N v_w Δt after cycle N (δ_i = 0.0011),
 *     F = k_n δ (ν = 1), elastic energy E_el = k_n δ²/2;
 *   - a free disc f (R = 0.44) coasting at u = 0.23 with no contact and no
 *     gravity: E_k = m_f u²/2, exactly (its centred velocity is u).
 * Checks every C = 7 cycles; at check j (cycle jC):
 *   E_k/E_el = m_f u² / (k_n δ_j²),
 *   the stress moment of h (measure.c): f = (0, F), l = (0, −(R − δ/2)),
 *   μ_j = −k_n δ_j (R − δ_j/2) (the only non-zero component), and the
 *   change recorded is |μ_j − μ_{j−1}| / |μ_j| (∞ at the first check,
 *   which has nothing to compare with).
 * Both measures fall monotonically with j, so a threshold is first met at
 * the first j where the closed form is below it; the rule with both
 * thresholds stops at the later of the two.  Thresholds are set between
 * consecutive closed-form values, at least 2.4% from either — round-off
 * (δ accumulates < 200 additions of 2e-5 to O(1) coordinates: < 1e-10
 * relative) cannot move a stop. */
#define SR_KN 3.7e4
#define SR_R 0.61
#define SR_RF 0.44
#define SR_RHO 2.385
#define SR_U 0.23
#define SR_DI 0.0011
#define SR_VW 0.0173
#define SR_DT 1.3e-3
#define SR_C 7
/* The values recorded in the log: ratios of closed forms evaluated from
 * positions that carry < 1e-10 relative round-off (see above). */
#define SR_LOG_REL 1e-9

static double sr_delta(long j)
{
    return SR_DI + (double)(j * SR_C) * SR_VW * SR_DT;
}

static double sr_ke_over_ee(long j)
{
    const double mf = SR_RHO * BAL_PI * SR_RF * SR_RF, d = sr_delta(j);
    return mf * SR_U * SR_U / (SR_KN * d * d);
}

static double sr_stress_change(long j)
{
    const double d = sr_delta(j), dp = sr_delta(j - 1);
    const double mu = SR_KN * d * (SR_R - d / 2), mup = SR_KN * dp * (SR_R - dp / 2);
    return fabs(mu - mup) / mu;
}

/* First check j at which the rule (thresholds 0 = off) holds; 0 if none up
 * to check jmax. */
static long sr_first(double stop_ke, double stop_stress, long jmax)
{
    for (long j = 1; j <= jmax; j++) {
        const int ke = stop_ke <= 0 || sr_ke_over_ee(j) <= stop_ke;
        const int st = stop_stress <= 0 || (j >= 2 && sr_stress_change(j) <= stop_stress);
        if (ke && st)
            return j;
    }
    return 0;
}

/* `after`: the stages that follow the pressing stage. */
#define SR_AFTER "[stage after]\ncycles = 5\n"

static struct tfx *sr_scene(long cycles, double stop_ke, double stop_stress, const char *after)
{
    const double yh = 0.8;
    return tfx_newf("stop",
                    "[settings]\ndt = %.17g\nnormal_law = power\n"
                    "[material m]\nkn = %.17g\ndensity = %.17g\n"
                    "[wall floor]\np = -1 %.17g\nangle = 0\nh1 = 0\nh2 = 2.7\nmaterial = m\n"
                    "[disc h]\nx = 0.35 %.17g\nr = %.17g\nfixed = 1\nmaterial = m\n"
                    "[disc f]\nx = 0.35 5\nr = %.17g\nv = %.17g 0\nmaterial = m\n"
                    "[stage press]\ncycles = %ld\nmove = floor 0 %.17g 0\n"
                    "stop_ke = %.17g\nstop_stress = %.17g\ncheck_every = %d\n%s",
                    SR_DT, SR_KN, SR_RHO, yh - SR_R + SR_DI, yh, SR_R, SR_RF, SR_U, cycles, SR_VW,
                    stop_ke, stop_stress, SR_C, after);
}

START_TEST(integrate_stop_rule)
{
    static const struct {
        double stop_ke, stop_stress;
        long expect_j;   /* the check the closed forms stop at */
    } cases[] = {
        {0.35, 0, 9},        /* E_k/E_el: 0.3725 at j = 8, 0.3274 at j = 9 */
        {0, 0.0513, 13},     /* change: 0.05254 at j = 12, 0.04991 at j = 13 */
        {0.35, 0.0513, 13},  /* both: the later */
        {0.2, 0.0513, 14},   /* E_k/E_el: 0.2095 at j = 13, 0.1900 at j = 14 */
    };
    const long max_cycles = 200;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        const long j = sr_first(cases[k].stop_ke, cases[k].stop_stress, max_cycles / SR_C);
        ck_assert_int_eq(j, cases[k].expect_j); /* the closed forms, as commented */
        struct tfx *f = sr_scene(max_cycles, cases[k].stop_ke, cases[k].stop_stress, SR_AFTER);
        ck_assert_int_eq(bal_sim_run(f->sim, NULL, NULL, &f->err), BAL_OK);
        const struct bal_stage_log *log = f->sim->log;
        ck_assert_int_eq(log[0].stopped, 1);
        ck_assert_int_eq(log[0].cycles, j * SR_C);
        ck_assert_double_eq_tol(log[0].ke_over_ee, sr_ke_over_ee(j), SR_LOG_REL * sr_ke_over_ee(j));
        if (cases[k].stop_stress > 0)
            ck_assert_double_eq_tol(log[0].stress_change, sr_stress_change(j),
                                    SR_LOG_REL * sr_stress_change(j));
        else
            ck_assert_double_eq(log[0].stress_change, -1.0); /* never measured */
        /* the next stage runs in full, with the wall at rest */
        ck_assert_int_eq(log[1].cycles, 5);
        ck_assert_int_eq(log[1].stopped, 0);
        ck_assert_int_eq(f->sim->step, j * SR_C + 5);
        ck_assert_double_eq_tol(f->sim->walls[0].p[1], 0.8 - SR_R + sr_delta(j), 1e-12);
        tfx_release(f);
    }
}
END_TEST

/* Each stage's stress rule starts afresh: its first check has nothing to
 * compare with, even though the previous stage left a snapshot.  After
 * `press` stops at j = 13, `rest` holds the wall still, so every moment
 * stays μ_13 exactly: a comparison with the previous stage's snapshot would
 * give 0 and stop at its first check (cycle 3); the rule stops at its second
 * check (cycle 6) with the change exactly 0 and E_k/E_el at δ_13. */
START_TEST(integrate_stop_rule_per_stage)
{
    struct tfx *f = sr_scene(200, 0, 0.0513,
                             "[stage rest]\ncycles = 100\nstop_stress = 0.0513\ncheck_every = 3\n");
    ck_assert_int_eq(bal_sim_run(f->sim, NULL, NULL, &f->err), BAL_OK);
    const struct bal_stage_log *log = f->sim->log;
    ck_assert_int_eq(log[0].cycles, 13 * SR_C);
    ck_assert_int_eq(log[1].stopped, 1);
    ck_assert_int_eq(log[1].cycles, 6);
    ck_assert_double_eq(log[1].stress_change, 0.0);
    ck_assert_double_eq_tol(log[1].ke_over_ee, sr_ke_over_ee(13), SR_LOG_REL * sr_ke_over_ee(13));
    ck_assert_int_eq(f->sim->step, 13 * SR_C + 6);
}
END_TEST

/* A rule never met runs all its cycles and says so: thresholds below every
 * value reached, 40 cycles (checks at 7 … 35, the last is j = 5); the log
 * keeps the measures of that last check.  And check_every defaults to 100:
 * a rule met at every check stops at cycle 100 of 250. */
START_TEST(integrate_stop_rule_never_met)
{
    struct tfx *f = sr_scene(40, 0.01, 1e-6, SR_AFTER);
    ck_assert_int_eq(bal_sim_run(f->sim, NULL, NULL, &f->err), BAL_OK);
    const struct bal_stage_log *log = f->sim->log;
    ck_assert_int_eq(log[0].stopped, 0);
    ck_assert_int_eq(log[0].cycles, 40);
    ck_assert_double_eq_tol(log[0].ke_over_ee, sr_ke_over_ee(5), SR_LOG_REL * sr_ke_over_ee(5));
    ck_assert_double_eq_tol(log[0].stress_change, sr_stress_change(5),
                            SR_LOG_REL * sr_stress_change(5));
    ck_assert_int_eq(f->sim->step, 45);
    tfx_release(f);

    f = tfx_newf("default",
                 "[settings]\ndt = %.17g\nnormal_law = power\n"
                 "[material m]\nkn = %.17g\ndensity = %.17g\n"
                 "[wall floor]\np = -1 0.1911\nangle = 0\nh1 = 0\nh2 = 2.7\nmaterial = m\n"
                 "[disc h]\nx = 0.35 0.8\nr = %.17g\nfixed = 1\nmaterial = m\n"
                 "[disc f]\nx = 0.35 5\nr = %.17g\nv = %.17g 0\nmaterial = m\n"
                 "[stage s]\ncycles = 250\nstop_ke = 1e9\n",
                 SR_DT, SR_KN, SR_RHO, SR_R, SR_RF, SR_U);
    ck_assert_int_eq(bal_sim_run(f->sim, NULL, NULL, &f->err), BAL_OK);
    ck_assert_int_eq(f->sim->log[0].stopped, 1);
    ck_assert_int_eq(f->sim->log[0].cycles, 100);
    ck_assert_int_eq(f->sim->step, 100);
}
END_TEST

/* No rule of equilibrium is met while nothing touches (issue 29, item 4):
 * 30 discs 3 diameters apart falling freely under gravity, no contact all
 * run long, and a servo lid far above them (vmax = 0: 1e-3 of a radius a
 * cycle, so it never reaches them).  Each rule alone, checked every 10
 * cycles for 200: ΔF/F is 0/0-like (the largest contact force is 0: it
 * was 0, met at the first check), the stress moments are all zero (change
 * over size was 0/0 = 0, met at the second check), the servo's error is 1
 * with nothing touching (met by stop_servo = 1 at the first check), E_k/E_el
 * has no elastic energy.  None stops the stage, and each log holds INFINITY
 * (run.json: null), not a ratio of zero. */
START_TEST(integrate_stop_rule_nothing_touches)
{
    static const char *const rules[] = {"stop_unbalanced = 1e-3", "stop_stress = 1e-3",
                                        "stop_servo = 1", "stop_ke = 1e9"};
    for (size_t k = 0; k < sizeof rules / sizeof rules[0]; k++) {
        char text[T_TEXT_MAX];
        int len = snprintf(text, sizeof text,
                           "[settings]\ndt = 1e-3\ngravity = 0 -9.81\n"
                           "[material m]\nkn = 1e5\ndensity = 2.385\n"
                           "[wall lid]\np = -5 100\nangle = 0\nh1 = 0\nh2 = 30\nmaterial = m\n"
                           "[wall left]\np = -10 -50\nangle = 90\nh1 = 0\nh2 = 200\nmaterial = m\n"
                           "[wall right]\np = 30 -50\nangle = 90\nh1 = 0\nh2 = 200\n"
                           "material = m\n");
        for (int d = 0; d < 30; d++)
            len += snprintf(text + len, sizeof text - (size_t)len,
                            "[disc d%d]\nx = %d %d\nr = 0.5\nmaterial = m\n", d, 3 * (d % 6),
                            3 * (d / 6));
        snprintf(text + len, sizeof text - (size_t)len,
                 "[stage fall]\ncycles = 200\ncheck_every = 10\n%s\n"
                 "servo = lid 100 0.5 0 left right\n",
                 rules[k]);
        struct tfx *f = tfx_new(text, "free_fall");
        ck_assert_int_eq(bal_sim_run(f->sim, NULL, NULL, &f->err), BAL_OK);
        const struct bal_sim *s = f->sim;
        ck_assert_double_eq(bal_measure_elastic(s), 0.0); /* nothing touched */
        const struct bal_stage_log *log = &s->log[0];
        ck_assert_msg(!log->stopped, "%s: stopped at cycle %ld", rules[k], log->cycles);
        ck_assert_int_eq(log->cycles, 200);
        ck_assert(isinf(log->ke_over_ee));
        if (k == 0)
            ck_assert(isinf(log->unbalanced));
        if (k == 1)
            ck_assert(isinf(log->stress_change));
        if (k == 2)
            ck_assert(isinf(log->servo_error));
        tfx_release(f);
    }
}
END_TEST

/* A stage with cycles = 0 is skipped: no cycle, no check of its stop rule,
 * its ramp and wall motion never applied (log: 0 cycles, not stopped, the
 * measures −1 = never checked).  The next stage then runs at full gravity
 * with the wall at rest: v = v0 + 9 g Δt. */
START_TEST(integrate_stage_zero_cycles_skipped)
{
    const double dt = 1.3e-3, gy = -9.81, vy0 = 0.41;
    struct tfx *f = tfx_newf("skip",
                             "[settings]\ndt = %.17g\ngravity = 0 %.17g\n"
                             "[material m]\nkn = 1e4\ndensity = 2.385\n"
                             "[wall w]\np = -3 -3\nangle = 0\nh1 = 0\nh2 = 1\nmaterial = m\n"
                             "[disc d]\nx = 0.5 1.25\nr = 0.3\nv = 0 %.17g\nmaterial = m\n"
                             "[stage none]\ncycles = 0\nramp = 1\nstop_ke = 1e9\ncheck_every = 1\n"
                             "move = w 0.5 0.25 0\n"
                             "[stage run]\ncycles = 9\n",
                             dt, gy, vy0);
    ck_assert_int_eq(bal_sim_run(f->sim, NULL, NULL, &f->err), BAL_OK);
    const struct bal_sim *s = f->sim;
    ck_assert_int_eq(s->log[0].cycles, 0);
    ck_assert_int_eq(s->log[0].stopped, 0);
    ck_assert_double_eq(s->log[0].ke_over_ee, -1.0);
    ck_assert_double_eq(s->log[0].stress_change, -1.0);
    ck_assert_int_eq(s->log[1].cycles, 9);
    ck_assert_int_eq(s->step, 9);
    ck_assert_double_eq(s->walls[0].p[0], -3.0);
    ck_assert_double_eq(s->walls[0].p[1], -3.0);
    ASSERT_REL(s->vy[t_slot(f, "d")], vy0 + 9 * gy * dt);
}
END_TEST

Suite *suite_sim(void)
{
    Suite *s = suite_create("sim");

    TCase *tc = tcase_create("run");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, integrate_run_stages);
    tcase_add_test(tc, integrate_unstable_names_disc_and_step);
    tcase_add_test(tc, integrate_unstable_short_run_with_series);
    tcase_add_test(tc, integrate_unstable_short_run_without_series);
    tcase_add_test(tc, integrate_interrupted);
    suite_add_tcase(s, tc);

    tc = tcase_create("stages");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, integrate_gravity_ramp);
    tcase_add_test(tc, integrate_stop_rule);
    tcase_add_test(tc, integrate_stop_rule_per_stage);
    tcase_add_test(tc, integrate_stop_rule_never_met);
    tcase_add_test(tc, integrate_stop_rule_nothing_touches);
    tcase_add_test(tc, integrate_stage_zero_cycles_skipped);
    suite_add_tcase(s, tc);
    return s;
}
