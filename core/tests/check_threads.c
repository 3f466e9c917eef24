/*
 * check_threads.c — suite "threads": a cycle on several threads (OpenMP;
 * struct bal_par in state.h) gives bitwise the results of one thread.
 *
 * The disc–disc list is cut into ranges, one per thread; a range logs what
 * it adds to the discs an earlier range also reaches, and the logs are
 * replayed in range order, so every force sum adds the same terms in the
 * same order.  The sums over candidates and over discs add fixed blocks.
 * Nothing here is a tolerance: the arrays are compared byte for byte.
 */
#include <string.h>

#include "check_main.h"

/* A falling, colliding packing with every module of the dense benchmark:
 * friction with history, dashpots, global damping, gravity (6 times the
 * benchmark's, so that it packs within the test's cycles), a box.  12 000
 * discs give enough candidates for three ranges of at least
 * PAR_MIN_CHUNKS chunks. */
static const char *const packing_fmt =
    "[settings]\ndt = 0.0007926748447693654\nforce_dt = 1\ngravity = 0 -60\n"
    "alpha = 0.5\n%s"
    "[material grain]\nkn = 1e5\nks = 1e5\nfriction = %g\ndensity = 1\nrolling = %g\n"
    "[material box]\nkn = 1e5\nks = 1e5\nfriction = %g\n"
    "[fill pack]\nn = 12000\ncolumns = %d\nrmin = 0.5\nrmax = 0.75\nseed = 7\nbox = 1\n"
    "headroom = 2\nvmax = 2\nmaterial = grain\nwall_material = box\n"
    "[stage s]\ncycles = 100000\n";

#define CYCLES 1000

/* A variant of the packing: extra settings, the friction, the columns, the
 * grains' rolling resistance δ (JYH; 0: none). */
struct variant {
    const char *settings;
    double friction;
    int columns;
    double rolling;
};

static const struct variant dense = {"beta = 0.001\n", 0.5, 110, 0};
static const int cycle_of_counts[] = {3, 1, 2, 16};

/* Run the packing CYCLES cycles on `threads` threads (0: switching between
 * 3, 1, 2 and 16 every 37 cycles); the most candidates any range after the
 * first logged in one cycle into *logged. */
static struct tfx *run_on(const struct variant *v, int threads, long *logged)
{
    struct tfx *f = tfx_newf("threads", packing_fmt, v->settings, v->friction, v->rolling,
                             v->friction, v->columns);
    ck_assert_int_eq(bal_sim_set_threads(f->sim, threads ? threads : 3, &f->err), BAL_OK);
    *logged = 0;
    for (long k = 0; k < CYCLES; k++) {
        if (threads == 0 && k % 37 == 0)
            ck_assert_int_eq(bal_sim_set_threads(f->sim, cycle_of_counts[k / 37 % 4], &f->err),
                             BAL_OK);
        t_steps(f, 1);
        for (int t = 1; t < f->sim->par.ranges; t++)
            *logged = f->sim->par.log_n[t] > *logged ? f->sim->par.log_n[t] : *logged;
    }
    return f;
}

static void same_doubles(const double *a, const double *b, size_t n, const char *what, int threads)
{
    ck_assert_msg(memcmp(a, b, n * sizeof *a) == 0, "%s differs on %d threads", what, threads);
}

static void same_floats(const float *a, const float *b, size_t n, const char *what, int threads)
{
    ck_assert_msg(memcmp(a, b, n * sizeof *a) == 0, "%s differs on %d threads", what, threads);
}

/* Every array the cycle writes, byte for byte, after the same cycles on
 * one thread and on each count of `counts`. */
static void check_as_one(const struct variant *v, const int *counts, int n_counts,
                         long min_contacts, int shared)
{
    long logged;
    struct tfx *one = run_on(v, 1, &logged);
    const struct bal_sim *a = one->sim;
    ck_assert_int_eq(a->par.ranges, 1);
    long contacts = 0;
    for (long c = 0; c < a->pp.n; c++)
        contacts += (a->pp.flags[c] & BAL_PAIR_TOUCHING) != 0;
    ck_assert_int_gt(contacts, min_contacts); /* the discs collide: forces to sum */
    for (int q = 0; q < n_counts; q++) {
        const int th = counts[q];
        struct tfx *many = run_on(v, th, &logged);
        const struct bal_sim *b = many->sim;
        /* not vacuous: the list was cut, and discs shared between ranges */
        if (th)
            ck_assert_int_eq(b->par.ranges, th);
        else
            ck_assert_int_ge(b->par.ranges, 2); /* 16 asked for: as many as the list allows */
        ck_assert_int_gt(logged, 0);
        if (shared) {
            /* some disc is logged by two ranges: the ranges before t - 1
             * reach past the first disc of range t */
            int twice = 0;
            for (int t = 2; t < b->par.ranges; t++)
                twice |= b->par.zone[t - 1] >= b->pp.i[b->par.start[t]];
            ck_assert_msg(twice, "no disc is logged by two ranges: the test is vacuous");
        }
        const size_t n = (size_t)a->n;
        ck_assert_int_eq(a->n, b->n);
        same_doubles(a->x, b->x, n, "x", th);
        same_doubles(a->y, b->y, n, "y", th);
        same_doubles(a->th, b->th, n, "rotation", th);
        same_doubles(a->vx, b->vx, n, "v_x", th);
        same_doubles(a->vy, b->vy, n, "v_y", th);
        same_doubles(a->w, b->w, n, "omega", th);
        same_doubles(a->f, b->f, 3 * n, "force and moment sums", th);
        if (a->dash)
            same_floats(a->dash, b->dash, 3 * n, "dashpot sums", th);
        ck_assert_int_eq(a->pp.n, b->pp.n);
        ck_assert_int_eq(a->rebuilds, b->rebuilds);
        const size_t np = (size_t)a->pp.n;
        ck_assert(memcmp(a->pp.i, b->pp.i, np * sizeof *a->pp.i) == 0);
        ck_assert(memcmp(a->pp.j, b->pp.j, np * sizeof *a->pp.j) == 0);
        same_doubles(a->pp.fn, b->pp.fn, np, "F_n history", th);
        if (a->pp.fs)
            same_doubles(a->pp.fs, b->pp.fs, np, "F_s history", th);
        if (a->pp.mr) {
            same_doubles(a->pp.mr, b->pp.mr, np, "rolling moment history", th);
            same_doubles(a->pp.tr, b->pp.tr, np, "rolling rotation history", th);
        }
        ck_assert(memcmp(a->pp.flags, b->pp.flags, np) == 0);
        /* the energy audit's sums over candidates and discs */
        ck_assert(memcmp(&a->audit, &b->audit, sizeof a->audit) == 0);
        tfx_release(many);
    }
}

START_TEST(threads_bitwise_as_one)
{
    const int counts[] = {2, 3};
    check_as_one(&dense, counts, 2, 2000, 0);
}
END_TEST

/* A packing 4 rows deep and 3 000 discs wide: a range (16 chunks, ~1 800
 * discs) is shorter than the reach of its candidates (the row above), so
 * on 4 threads some discs get logged sums from two ranges, replayed in
 * their order. */
START_TEST(threads_bitwise_ranges_shorter_than_reach)
{
    const struct variant wide = {"beta = 0.001\n", 0.5, 3000, 0};
    const int counts[] = {4};
    check_as_one(&wide, counts, 1, 2000, 1);
}
END_TEST

/* The other end of the modules: the power law without friction or
 * dashpots (another pair-loop variant, no shear or dashpot sums), under
 * velocity Verlet, whose passes stay on one thread. */
START_TEST(threads_bitwise_power_law_verlet)
{
    const struct variant bare = {"normal_law = power\nintegrator = verlet\n", 0, 110, 0};
    const int counts[] = {2};
    check_as_one(&bare, counts, 1, 2000, 0);
}
END_TEST

/* Rolling resistance (JYH Model 1, δ = 1.6, with the rolling dashpot): its
 * couples go to the moment sums through the same logs, its losses through
 * per-chunk sums of their own. */
START_TEST(threads_bitwise_rolling)
{
    const struct variant rolling = {"beta = 0.001\nrolling_model = model1\n", 0.5, 110, 1.6};
    const int counts[] = {2, 3};
    check_as_one(&rolling, counts, 2, 2000, 0);
}
END_TEST

/* The count changed between cycles (3, 1, 2, 16, ... every 37 cycles), as
 * the benchmark does when it settles on every core and times on one. */
START_TEST(threads_bitwise_when_switched)
{
    const int counts[] = {0};
    check_as_one(&dense, counts, 1, 2000, 0);
}
END_TEST

/* A thread count outside 1..BAL_MAX_THREADS is refused, and leaves the
 * count as it was. */
START_TEST(threads_count_checked)
{
    struct tfx *f = tfx_newf("threads", packing_fmt, dense.settings, dense.friction,
                             dense.rolling, dense.friction, dense.columns);
    ck_assert_int_eq(bal_sim_set_threads(f->sim, 0, &f->err), BAL_EINVAL);
    ck_assert_msg(t_contains(f->err.msg, "threads"), "%s", f->err.msg);
    ck_assert_int_eq(bal_sim_set_threads(f->sim, BAL_MAX_THREADS + 1, &f->err), BAL_EINVAL);
    ck_assert_int_eq(f->sim->par.threads, 1);
    ck_assert_int_eq(bal_sim_set_threads(f->sim, BAL_MAX_THREADS, &f->err), BAL_OK);
    t_steps(f, 2); /* more threads asked for than the list has ranges for */
    ck_assert_int_le(f->sim->par.ranges, BAL_MAX_THREADS);
    ck_assert_int_ge(f->sim->par.ranges, 1);
}
END_TEST

Suite *suite_threads(void)
{
    Suite *s = suite_create("threads");
    TCase *tc = tcase_create("bitwise");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, threads_bitwise_as_one);
    tcase_add_test(tc, threads_bitwise_ranges_shorter_than_reach);
    tcase_add_test(tc, threads_bitwise_power_law_verlet);
    tcase_add_test(tc, threads_bitwise_when_switched);
    tcase_add_test(tc, threads_bitwise_rolling);
    tcase_add_test(tc, threads_count_checked);
    suite_add_tcase(s, tc);
    return s;
}
