/*
 * check_energy.c — suite "energy": the energy audit (energy.c) and the
 * guards that stop a run (overlap budget, energy runaway).
 *
 * Each test is a motion whose energy flow is known in closed form; the
 * audit must put each joule in the right term.  Bounds: where the centred
 * scheme is exact (free flight, a wall pressing a spring at constant speed
 * with the trapezoid rule) round-off; elsewhere the scheme's own error,
 * O(Δt) or O(Δt²), bounded from the step and stated at each test.
 */
#include <math.h>
#include <stdio.h>

#include "check_main.h"

static struct bal_energy audit(const struct tfx *f)
{
    struct bal_energy e;
    bal_energy_report(f->sim, &e);
    return e;
}

/* Free flight under gravity from rest and with a launch velocity: the
 * centred scheme is exact for constant force, so
 *   W_gravity = m g·(x_M − x_1) = ½ m (v_M² − v_1²)
 * to round-off (the arithmetic series Σ v_{N+1/2} = (M − 1)(v_1 + v_M)/2). */
START_TEST(energy_free_flight)
{
    struct tfx *f = tfx_newf("fall", "[settings]\ndt = 1e-3\ngravity = 0.5 -9.81\n"
                                     "[material m]\nkn = 1e4\ndensity = 2\n"
                                     "[disc d]\nx = 0 0\nr = 0.3\nv = 1.5 4\nmaterial = m\n"
                                     "[stage s]\ncycles = 1\n");
    t_steps(f, 1000);
    const struct bal_energy e = audit(f);
    ck_assert_int_eq(e.started, 1);
    ck_assert_double_gt(fabs(e.work_gravity), 1.0);
    ck_assert_double_eq_tol(e.kinetic - e.kinetic0, e.work_gravity, 1e-12 * fabs(e.work_gravity));
    ck_assert_double_eq_tol(e.imbalance, 0, 1e-12 * e.throughput);
    ck_assert_double_eq(e.work_walls, 0);
    ck_assert_double_eq(e.dissipated_global + e.dissipated_dashpot + e.dissipated_friction, 0);
}
END_TEST

/* The same with velocity Verlet and Gear's predictor-corrector: both are
 * exact for a constant force too (Gear for any polynomial motion up to
 * degree 5), and the audit reads their velocities at t_N through
 * bal_measure_velocity: the balance closes to round-off. */
START_TEST(energy_free_flight_integrators)
{
    static const char *const names[] = {"verlet", "gear5"};
    for (int k = 0; k < 2; k++) {
        struct tfx *f = tfx_newf("fall", "[settings]\ndt = 1e-3\ngravity = 0.5 -9.81\nintegrator = %s\n"
                                         "[material m]\nkn = 1e4\ndensity = 2\n"
                                         "[disc d]\nx = 0 0\nr = 0.3\nv = 1.5 4\nmaterial = m\n"
                                         "[stage s]\ncycles = 1\n", names[k]);
        t_steps(f, 1000);
        const struct bal_energy e = audit(f);
        ck_assert_double_gt(fabs(e.work_gravity), 1.0);
        ck_assert_msg(fabs(e.imbalance) <= 1e-11 * e.throughput, "%s: imbalance %g of %g", names[k],
                      e.imbalance, e.throughput);
        tfx_release(f);
    }
}
END_TEST

/* Gravity ramped from zero (MLH Sec. 4): each interval of constant g_fac
 * is summed on its own; free flight stays exact to round-off. */
START_TEST(energy_gravity_ramp)
{
    struct tfx *f = tfx_newf("ramp", "[settings]\ndt = 1e-3\ngravity = 0 -9.81\n"
                                     "[material m]\nkn = 1e4\ndensity = 2\n"
                                     "[disc d]\nx = 0 0\nr = 0.3\nv = 0 2\nmaterial = m\n"
                                     "[stage up]\ncycles = 500\nramp = 1\n"
                                     "[stage on]\ncycles = 500\n");
    ck_assert_int_eq(bal_sim_run(f->sim, NULL, NULL, &f->err), BAL_OK);
    const struct bal_energy e = audit(f);
    ck_assert_double_gt(fabs(e.work_gravity), 0.1);
    /* What is left is the second difference of g_fac in E_k at t_N:
     * below m g² Δt² (m = 2 π 0.09). */
    const double m = 2 * BAL_PI * 0.09;
    ck_assert_double_le(fabs(e.imbalance), m * 9.81 * 9.81 * 1e-6);
}
END_TEST

/* A wall moving at constant speed V into a held disc through a linear
 * spring (power law, ν = 1): the spring stores ½ k δ², δ = V t; the wall's
 * work by the trapezoid rule over a force linear in time is exactly that.
 * Nothing moves but the wall, so the balance closes to round-off. */
START_TEST(energy_wall_work_trapezoid)
{
    struct tfx *f = tfx_newf("press", "[settings]\ndt = 1e-3\nnormal_law = power\n"
                                      "[material m]\nkn = 1e4\ndensity = 1\n"
                                      "[disc d]\nx = 0 0\nr = 0.5\nfixed = 1\nmaterial = m\n"
                                      "[wall w]\np = 0.5 -1\nangle = 90\nh1 = 0\nh2 = 2\nmaterial = m\n"
                                      "[stage s]\ncycles = 200\nmove = w -0.1 0 0\n");
    ck_assert_int_eq(bal_sim_run(f->sim, NULL, NULL, &f->err), BAL_OK);
    const struct bal_energy e = audit(f);
    const double delta = 0.1 * 200 * 1e-3;
    ck_assert_double_eq_tol(e.elastic, 0.5 * 1e4 * delta * delta, 1e-9 * e.elastic);
    ck_assert_double_gt(e.work_walls, 0);
    ck_assert_double_eq_tol(e.imbalance, 0, 1e-12 * e.throughput);
}
END_TEST

/* Global damping alone on a free spinning, sliding disc: eqs (35)–(36) are
 * m (v_{N+1/2} − v_{N−1/2})/Δt = −α m v_N, so the loss α m v_N² Δt per
 * cycle is the exact change of ½ m v² at the half steps; E_k at t_N (eq. 31)
 * differs from those by O((α Δt)²) of E_k: bound 1e-4 for α Δt = 1e-3. */
START_TEST(energy_global_damping)
{
    struct tfx *f = tfx_newf("glob", "[settings]\ndt = 1e-3\nalpha = 1\n"
                                     "[material m]\nkn = 1e4\ndensity = 2\n"
                                     "[disc d]\nx = 0 0\nr = 0.3\nv = 1 -2\nomega = 3\nmaterial = m\n"
                                     "[stage s]\ncycles = 1\n");
    t_steps(f, 3000);
    const struct bal_energy e = audit(f);
    ck_assert_double_gt(e.dissipated_global, 0.9 * e.kinetic0);
    ck_assert_double_le(fabs(e.imbalance), 1e-4 * e.throughput);
}
END_TEST

/* A disc thrown along a frictional floor, resting on it at its static
 * overlap m g/k, slides until it rolls (a disc cannot stop sliding without
 * spinning up: then it keeps 1/3 of its kinetic energy).  The slip under
 * F_max each cycle is exactly (|F_s trial| - F_max)/k_s = u Δt once the
 * shear spring is at the limit, so the audit closes to the scheme's O(Δt²)
 * after the first cycle (bound at the test). */
static struct bal_energy slide(double dt, double y, long cycles)
{
    struct tfx *f = tfx_newf("slide", "[settings]\ndt = %.17g\ngravity = 0 -9.81\nnormal_law = power\n"
                                      "[material m]\nkn = 1e5\nfriction = 0.4\ndensity = 2\n"
                                      "[disc d]\nx = 0 %.17g\nr = 0.5\nv = 3 0\nmaterial = m\n"
                                      "[wall floor]\np = -5 0\nangle = 0\nh1 = 0\nh2 = 20\nmaterial = m\n"
                                      "[stage s]\ncycles = 1\n", dt, y);
    t_steps(f, cycles);
    const struct bal_energy e = audit(f);
    tfx_release(f);
    return e;
}

START_TEST(energy_friction_sliding)
{
    const double m = 2 * BAL_PI * 0.25, y = 0.5 - m * 9.81 / 1e5;
    const struct bal_energy e = slide(2e-4, y, 4000);
    ck_assert_double_gt(e.dissipated_friction, 0.3 * e.kinetic0);
    /* The audit starts at t_0: in the first cycle the shear spring goes from
     * zero to the Coulomb limit within one step of sliding at u = 3, which
     * the discrete slip accounts to within F_max u Δt; the rest is O(Δt²). */
    const double fmax = 0.4 * m * 9.81;
    ck_assert_double_le(fabs(e.imbalance), fmax * 3 * 2e-4 + 1e-6 * e.throughput);
}
END_TEST

/* The same disc dropped from an overlap of 0.01: it bounces along the
 * floor.  Each impact starts and ends inside a cycle, with friction acting
 * from its first increment: the audit's imbalance is first order in Δt
 * there (measured 4.3e-3, 2.1e-3, 1.1e-3 of the throughput at Δt = 2e-4,
 * 1e-4, 5e-5).  Checked: it falls with Δt at order >= 0.8. */
START_TEST(energy_friction_bouncing_order)
{
    const struct bal_energy a = slide(2e-4, 0.49, 4000), b = slide(1e-4, 0.49, 8000);
    ck_assert_double_gt(a.dissipated_friction, 0.1 * a.kinetic0);
    const double order = log2(fabs(a.imbalance) / fabs(b.imbalance));
    ck_assert_msg(order >= 0.8, "order %g (imbalances %g, %g)", order, a.imbalance, b.imbalance);
}
END_TEST

/* Two discs collide head-on through a linear spring with a dashpot
 * (C&S eq. 28, β): after they separate the lost kinetic energy is the
 * dashpot's.  Its force uses the velocity half a step old, but the audit
 * counts the work it does on the motion at t_N, so what is left is the
 * centred scheme's energy error in the spring, O((ω Δt)²) of the energy:
 * bound (ω Δt)² E_k0, ω² = k/m12 (measured: 2e-5 of the loss). */
START_TEST(energy_dashpot_collision)
{
    struct tfx *f = tfx_newf("hit", "[settings]\ndt = 1e-4\nbeta = 2e-3\nnormal_law = power\n"
                                    "[material m]\nkn = 1e4\nfriction = 0\ndensity = 1\n"
                                    "[disc a]\nx = -0.6 0\nr = 0.5\nv = 1 0\nmaterial = m\n"
                                    "[disc b]\nx = 0.6 0\nr = 0.5\nv = -1 0\nmaterial = m\n"
                                    "[stage s]\ncycles = 1\n");
    t_steps(f, 6000);
    const struct bal_energy e = audit(f);
    ck_assert_double_eq(e.elastic, 0); /* apart again */
    ck_assert_double_gt(e.dissipated_dashpot, 0.05 * e.kinetic0);
    const double w2dt2 = 1e4 / (0.5 * BAL_PI * 0.25) * 1e-8;
    ck_assert_double_le(fabs(e.imbalance), w2dt2 * e.kinetic0);
}
END_TEST

/* Overlap budget: a disc shot at a wall far too fast for its stiffness is
 * stopped at once, the message names the step, both bodies and the cause. */
START_TEST(energy_overlap_budget)
{
    struct tfx *f = tfx_newf("fast", "[settings]\ndt = 1e-4\nnormal_law = power\n"
                                     "[material m]\nkn = 1e2\ndensity = 1\n"
                                     "[disc bullet]\nx = 0 0\nr = 0.5\nv = 100 0\nmaterial = m\n"
                                     "[wall target]\np = 1 -1\nangle = 90\nh1 = 0\nh2 = 2\nmaterial = m\n"
                                     "[stage s]\ncycles = 100000\n");
    const enum bal_status st = bal_sim_run(f->sim, NULL, NULL, &f->err);
    ck_assert_msg(st == BAL_EUNSTABLE, "status %d: %s", st, f->err.msg);
    ck_assert_msg(t_contains(f->err.msg, "overlap beyond the budget"), "%s", f->err.msg);
    ck_assert_msg(t_contains(f->err.msg, "bullet") && t_contains(f->err.msg, "target"), "%s",
                  f->err.msg);
    /* caught within the step that crossed 0.5 r: the overlap is at most
     * 0.5 r + v Δt */
    ck_assert_msg(f->sim->step < 100000, "never caught");
    ck_assert_double_le(f->sim->x[0] + 0.5 - 1, 0.5 * 0.5 + 100 * 1e-4 + 1e-12);
}
END_TEST

/* With the budget off (0) the same impact runs through and the disc bounces. */
START_TEST(energy_overlap_budget_off)
{
    struct tfx *f = tfx_newf("fast", "[settings]\ndt = 1e-4\nnormal_law = power\noverlap_budget = 0\n"
                                     "[material m]\nkn = 1e4\ndensity = 1\n"
                                     "[disc bullet]\nx = 0 0\nr = 0.5\nv = 50 0\nmaterial = m\n"
                                     "[wall target]\np = 1 -1\nangle = 90\nh1 = 0\nh2 = 2\nmaterial = m\n"
                                     "[stage s]\ncycles = 2000\n");
    ck_assert_int_eq(bal_sim_run(f->sim, NULL, NULL, &f->err), BAL_OK);
    ck_assert_double_lt(f->sim->vx[0], 0);
}
END_TEST

/* The loop's sieve compares overlaps with the budget times the scene's
 * smallest radius; two large discs pressed together by 0.3 of their radius
 * pass it (a small disc far away sets the sieve at 0.05) but are within
 * their own budget (0.5 r): the run must go on. */
START_TEST(energy_overlap_sieve_false_alarm)
{
    struct tfx *f = tfx_newf("sieve", "[settings]\ndt = 1e-4\nnormal_law = power\n"
                                      "[material m]\nkn = 1e4\ndensity = 1\n"
                                      "[disc a]\nx = 0 0\nr = 1\nmaterial = m\n"
                                      "[disc b]\nx = 1.7 0\nr = 1\nmaterial = m\n"
                                      "[disc tiny]\nx = 10 10\nr = 0.1\nmaterial = m\n"
                                      "[stage s]\ncycles = 50\n");
    ck_assert_int_eq(bal_sim_run(f->sim, NULL, NULL, &f->err), BAL_OK);
    ck_assert_int_eq(f->sim->over_budget, 0);
}
END_TEST

/* Energy runaway: a chain of discs pressed between walls with a time step
 * above the critical one (2 sqrt(m/k) of one spring, here 1.3 times it)
 * gains energy geometrically; the guard stops it with its cause before a
 * NaN appears, naming the created energy. */
START_TEST(energy_runaway_guard)
{
    char text[T_TEXT_MAX];
    int len = snprintf(text, sizeof text,
                       "[settings]\ndt_fraction = 1\nnormal_law = power\noverlap_budget = 0\n"
                       "[material m]\nkn = 1e4\ndensity = 1\n");
    for (int k = 0; k < 8; k++)
        len += snprintf(text + len, sizeof text - (size_t)len,
                        "[disc d%d]\nx = %.17g 0\nr = 0.5\nv = %g 0\nmaterial = m\n", k,
                        0.999 * k, k % 2 ? 0.01 : -0.01);
    snprintf(text + len, sizeof text - (size_t)len, "[stage s]\ncycles = 100000\n");
    struct tfx *f = tfx_parse(text, "runaway");
    f->sc.settings.dt = 0;
    f->sc.settings.allow_overlap = 1;
    f->sc.settings.force_dt = 1;
    ck_assert_int_eq(tfx_create(f), BAL_OK);
    /* 1.3 x the single-spring limit, whatever the estimate says */
    const double m = BAL_PI * 0.25, k = 1e4;
    f->sim->dt = 1.3 * 2 * sqrt(m / (2 * k));
    const enum bal_status st = bal_sim_run(f->sim, NULL, NULL, &f->err);
    ck_assert_msg(st == BAL_EUNSTABLE, "status %d: %s", st, f->err.msg);
    ck_assert_msg(t_contains(f->err.msg, "energy runaway") || t_contains(f->err.msg, "not finite"),
                  "%s", f->err.msg);
}
END_TEST

/* Issue 18: a run that reports ok reports only numbers.  A disc pressed on
 * a wall, its contact's force then set beyond what F_n²/(2 k_n) can hold in
 * a double: the audit is not finite, and the guard stops the run naming the
 * contact, whether or not the runaway guard is on (energy_guard = 0). */
START_TEST(energy_guard_not_finite)
{
    for (int off = 0; off < 2; off++) {
        struct tfx *f = tfx_newf("inf", "[settings]\ndt = 1e-4\nenergy_guard = %d\n"
                                        "[material m]\nkn = 1e4\ndensity = 1\n"
                                        "[disc a]\nx = 0 0.499\nr = 0.5\nmaterial = m\n"
                                        "[wall w]\np = -1 0\nangle = 0\nh1 = 0\nh2 = 2\nmaterial = m\n"
                                        "[stage s]\ncycles = 10\n",
                                        off ? 0 : 1);
        t_steps(f, 2);
        ck_assert_int_eq(bal_energy_guard(f->sim, &f->err), BAL_OK);
        const struct bal_pairs *list;
        const long c = t_contact(f, "a", "w", &list);
        ck_assert(list->flags[c] & BAL_PAIR_TOUCHING);
        f->sim->pw.fn[c] = 1e160; /* 1e320 / 2e4 is not a double */
        ck_assert_int_eq(bal_energy_guard(f->sim, &f->err), BAL_EUNSTABLE);
        ck_assert_msg(t_contains(f->err.msg, "inf: the energy stored in the contact of disc a and "
                                             "wall w is not finite at step 2"),
                      "%s", f->err.msg);
        tfx_release(f);
    }
}
END_TEST

/* The disc's share of the gravity potential, m g.x, overflowing while its
 * position and speed are finite, is named too. */
START_TEST(energy_guard_gravity_not_finite)
{
    struct tfx *f = tfx_newf("far", "[settings]\ndt = 1e-4\ngravity = 0 -1e300\n"
                                    "[material m]\nkn = 1e4\ndensity = 1\n"
                                    "[disc a]\nx = 0 0\nr = 0.5\nmaterial = m\n"
                                    "[stage s]\ncycles = 10\n");
    t_steps(f, 1);
    f->sim->y[0] = 1e300;
    f->sim->vy[0] = 0;
    ck_assert_int_eq(bal_energy_guard(f->sim, &f->err), BAL_EUNSTABLE);
    ck_assert_msg(t_contains(f->err.msg, "far: disc a: its gravity potential m g.x is not finite"),
                  "%s", f->err.msg);
}
END_TEST

Suite *suite_energy(void)
{
    Suite *s = suite_create("energy");
    TCase *tc = tcase_create("audit");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, energy_free_flight);
    tcase_add_test(tc, energy_free_flight_integrators);
    tcase_add_test(tc, energy_gravity_ramp);
    tcase_add_test(tc, energy_wall_work_trapezoid);
    tcase_add_test(tc, energy_global_damping);
    tcase_add_test(tc, energy_friction_sliding);
    tcase_add_test(tc, energy_friction_bouncing_order);
    tcase_add_test(tc, energy_dashpot_collision);
    suite_add_tcase(s, tc);
    tc = tcase_create("guards");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, energy_overlap_budget);
    tcase_add_test(tc, energy_overlap_budget_off);
    tcase_add_test(tc, energy_overlap_sieve_false_alarm);
    tcase_add_test(tc, energy_runaway_guard);
    tcase_add_test(tc, energy_guard_not_finite);
    tcase_add_test(tc, energy_guard_gravity_not_finite);
    suite_add_tcase(s, tc);
    return s;
}
