/*
 * check_timestep.c — suite "timestep": the critical time-step estimate
 * (C&S p. 53: a mass m on a spring k has the critical step 2√(m/k)).
 *
 * For each disc ballast takes the stiffest contact it can have (its own
 * material against every material of the scene, discs and walls, with the
 * pair stiffness k = 2 k_a k_b/(k_a + k_b)) and the three single-spring
 * systems
 *   2√(m/k_n),  2√(m/k_s),  2√(I/(k_s R²)),   m = ρπR², I = mR²/2,
 * and the scene's estimate is the smallest over all discs.  The step used is
 * dt_fraction × estimate unless dt is given.
 */
#include <math.h>
#include <stdio.h>

#include "check_main.h"

/* The estimate is a square root and a few products: 1e-14 relative is a
 * generous bound on round-off and catches any wrong factor. */
#define ROUNDOFF_REL 1e-14

#define ASSERT_REL(value, expected) \
    ck_assert_double_eq_tol((value), (expected), ROUNDOFF_REL * fabs(expected))

#define RHO 2.385

static double single_spring_estimate(double r, double kn, double ks)
{
    const double m = RHO * BAL_PI * r * r, inertia = 0.5 * m * r * r;
    return fmin(2 * sqrt(m / kn), fmin(2 * sqrt(m / ks), 2 * sqrt(inertia / (ks * r * r))));
}

static double series(double a, double b)
{
    return 2 * a * b / (a + b);
}

struct run_info_pair {
    double estimate, dt, fraction;
};

static struct run_info_pair info_of(const struct tfx *f)
{
    struct bal_run_info info;
    bal_sim_info(f->sim, &info);
    struct run_info_pair p = {info.dt_estimate, info.dt, info.dt_fraction};
    return p;
}

/* One material; discs of radius 0.43 and 0.61.  k_n = 5.3e4 > 2 k_s = 3.4e4,
 * so the normal spring binds (2√(m/k_n) < 2√(m/(2k_s))), on the lighter
 * disc. */
START_TEST(timestep_single_material_normal_binds)
{
    const double kn = 5.3e4, ks = 1.7e4;
    struct tfx *f = tfx_newf("ts",
                             "[material m]\nkn = %.17g\nks = %.17g\nfriction = 0.3\n"
                             "density = %.17g\n"
                             "[disc a]\nx = 0 0\nr = 0.61\nmaterial = m\n"
                             "[disc b]\nx = 3 0\nr = 0.43\nmaterial = m\n"
                             "[stage s]\ncycles = 1\n",
                             kn, ks, RHO);
    const double expected = fmin(single_spring_estimate(0.61, kn, ks),
                                 single_spring_estimate(0.43, kn, ks));
    const double m = RHO * BAL_PI * 0.43 * 0.43;
    ASSERT_REL(expected, 2 * sqrt(m / kn)); /* the derivation's claim */
    const struct run_info_pair p = info_of(f);
    ASSERT_REL(p.estimate, expected);
    ASSERT_REL(p.dt, 0.1 * expected); /* default dt_fraction 0.1 */
}
END_TEST

/* k_n = 2.2e4 < 2 k_s = 3.8e4: the rotational spring binds,
 * 2√(I/(k_s R²)) = 2√(m/(2 k_s)). */
START_TEST(timestep_single_material_rotation_binds)
{
    const double kn = 2.2e4, ks = 1.9e4;
    struct tfx *f = tfx_newf("ts",
                             "[material m]\nkn = %.17g\nks = %.17g\nfriction = 0.3\n"
                             "density = %.17g\n"
                             "[disc a]\nx = 0 0\nr = 0.61\nmaterial = m\n"
                             "[disc b]\nx = 3 0\nr = 0.43\nmaterial = m\n"
                             "[stage s]\ncycles = 1\n",
                             kn, ks, RHO);
    const double m = RHO * BAL_PI * 0.43 * 0.43;
    const double expected = single_spring_estimate(0.43, kn, ks);
    ASSERT_REL(expected, 2 * sqrt(m / (2 * ks)));
    ASSERT_REL(info_of(f).estimate, expected);
}
END_TEST

/* A soft disc material against a stiff wall material: the disc's stiffest
 * contact is the disc–wall pair, k = 2 k_soft k_stiff/(k_soft + k_stiff) for
 * both k_n and k_s — larger than its own k, smaller than the wall's.  (The
 * stiff material comes first in the file, so "the last material seen" or
 * "the disc's own material" would both give a different answer.) */
START_TEST(timestep_stiffest_partner_wall)
{
    /* First set: 2 k_s > k_n for the pair, the rotational spring binds;
     * second: k_n > 2 k_s, the normal spring binds. */
    static const double sets[2][4] = {{2.2e4, 1.9e4, 9.7e4, 8.1e4}, {2.2e4, 0.6e4, 9.7e4, 1.5e4}};
    for (int k = 0; k < 2; k++) {
        const double kn_soft = sets[k][0], ks_soft = sets[k][1];
        const double kn_stiff = sets[k][2], ks_stiff = sets[k][3];
        struct tfx *f = tfx_newf("ts",
                                 "[material stiff]\nkn = %.17g\nks = %.17g\n"
                                 "[material soft]\nkn = %.17g\nks = %.17g\ndensity = %.17g\n"
                                 "[wall w]\np = 0 -5\nangle = 0\nh1 = -1\nh2 = 1\n"
                                 "material = stiff\n"
                                 "[disc a]\nx = 0 0\nr = 0.43\nmaterial = soft\n"
                                 "[stage s]\ncycles = 1\n",
                                 kn_stiff, ks_stiff, kn_soft, ks_soft, RHO);
        const double kn = series(kn_soft, kn_stiff), ks = series(ks_soft, ks_stiff);
        const double m = RHO * BAL_PI * 0.43 * 0.43;
        const double expected = single_spring_estimate(0.43, kn, ks);
        ASSERT_REL(expected, k == 0 ? 2 * sqrt(m / (2 * ks)) : 2 * sqrt(m / kn));
        ck_assert(expected < single_spring_estimate(0.43, kn_soft, ks_soft));
        ASSERT_REL(info_of(f).estimate, expected);
        tfx_release(f);
    }
}
END_TEST

/* Two disc materials: the light soft disc (r = 0.43) sees at most the
 * soft–stiff pair; the heavier stiff disc (r = 0.61) sees its own stiff
 * material.  The estimate is the smaller of the two discs' values. */
START_TEST(timestep_stiffest_partner_discs)
{
    const double kn_soft = 2.2e4, kn_stiff = 9.7e4;
    struct tfx *f = tfx_newf("ts",
                             "[material stiff]\nkn = %.17g\ndensity = %.17g\n"
                             "[material soft]\nkn = %.17g\ndensity = %.17g\n"
                             "[disc a]\nx = 0 0\nr = 0.43\nmaterial = soft\n"
                             "[disc b]\nx = 3 0\nr = 0.61\nmaterial = stiff\n"
                             "[stage s]\ncycles = 1\n",
                             kn_stiff, RHO, kn_soft, RHO);
    const double k_pair = series(kn_soft, kn_stiff); /* ks = kn when omitted */
    const double ta = single_spring_estimate(0.43, k_pair, k_pair);
    const double tb = single_spring_estimate(0.61, kn_stiff, kn_stiff);
    ASSERT_REL(info_of(f).estimate, fmin(ta, tb));
}
END_TEST

/* dt_fraction scales the estimate; an explicit dt overrides both. */
START_TEST(timestep_fraction_and_explicit_dt)
{
    const char *const body = "[material m]\nkn = 5.3e4\nks = 1.7e4\ndensity = 2.385\n"
                             "[disc a]\nx = 0 0\nr = 0.61\nmaterial = m\n"
                             "[stage s]\ncycles = 1\n";
    const double expected = single_spring_estimate(0.61, 5.3e4, 1.7e4);

    struct tfx *f = tfx_newf("ts", "[settings]\ndt_fraction = 0.0385\n%s", body);
    struct run_info_pair p = info_of(f);
    ASSERT_REL(p.estimate, expected);
    ASSERT_REL(p.dt, 0.0385 * expected);
    ASSERT_REL(p.fraction, 0.0385);
    tfx_release(f);

    f = tfx_newf("ts", "[settings]\ndt = 1.234e-3\ndt_fraction = 0.0385\n%s", body);
    p = info_of(f);
    ck_assert_double_eq(p.dt, 1.234e-3);
    ck_assert_double_eq(f->sim->dt, 1.234e-3);
    ASSERT_REL(p.estimate, expected); /* still reported */
    ASSERT_REL(p.fraction, 1.234e-3 / expected);
}
END_TEST

/* Power law F = k_n δ0 (δ/δ0)^ν: the normal stiffness at δ = δ0 is ν k_n
 * (timestep.c).  ν = 1.5, k_n = 5.3e4, k_s = 1.7e4: 2√(m/(1.5 k_n)). */
START_TEST(timestep_power_law_stiffness)
{
    const double kn = 5.3e4, ks = 1.7e4, nu = 1.5;
    struct tfx *f = tfx_newf("ts",
                             "[settings]\nnormal_law = power\nnu = %.17g\ndelta0 = 0.013\n"
                             "[material m]\nkn = %.17g\nks = %.17g\ndensity = %.17g\n"
                             "[disc a]\nx = 0 0\nr = 0.43\nmaterial = m\n"
                             "[stage s]\ncycles = 1\n",
                             nu, kn, ks, RHO);
    ASSERT_REL(info_of(f).estimate, single_spring_estimate(0.43, nu * kn, ks));
}
END_TEST

Suite *suite_timestep(void)
{
    Suite *s = suite_create("timestep");
    TCase *tc = tcase_create("estimate");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, timestep_single_material_normal_binds);
    tcase_add_test(tc, timestep_single_material_rotation_binds);
    tcase_add_test(tc, timestep_stiffest_partner_wall);
    tcase_add_test(tc, timestep_stiffest_partner_discs);
    tcase_add_test(tc, timestep_fraction_and_explicit_dt);
    tcase_add_test(tc, timestep_power_law_stiffness);
    suite_add_tcase(s, tc);
    return s;
}
