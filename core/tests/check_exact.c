/*
 * check_exact.c — suite "exact": the exact static solver of stiff
 * frictionless networks (exact.c; Matuttis, Luding & Herrmann 2000,
 * Sec. 4.2).
 *
 * Conventions under test (exact.h): for contact c between body i and body j
 * with unit normal n from i to j, the compressive force F_c >= 0 pushes i
 * along −n and j along +n; the approach δ_c = (u_i − u_j)·n; F_c = k_c δ_c in
 * the limit of stiff contacts, independent of the scale of k.  Every free
 * disc balances Σ_c (±F_c n) + m g = 0.
 *
 * Every expected force below is derived by hand next to its test from the
 * balance of the free discs (plus, where the network is statically
 * indeterminate, the compatibility of the displacements); the 1717-disc
 * 30° pile, which has no closed form, is checked for balance, mirror
 * symmetry and the shape of network MLH describe.  Scene numbers are
 * non-round on purpose.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "check_main.h"
#include "exact.h"

/* A few floating-point operations on O(1) numbers: 1e-12 relative is far
 * above round-off and far below any wrong factor, sign or term. */
#define ROUNDOFF_REL 1e-12
/* The largest imbalance of a small network, relative to its largest
 * weight: a handful of roundings of O(1) numbers. */
#define RESIDUAL_SMALL 1e-12
/* The same for the 1717-disc pile: round-off grows with the condition
 * number of K (~ rows², with 34 rows), still far below any real force. */
#define RESIDUAL_PILE 1e-9

#define RHO 2.385
#define G 9.81
#define SIN30 0.5
#define COS30 0.86602540378443864676

#define ASSERT_REL(value, expected) \
    ck_assert_double_eq_tol((value), (expected), ROUNDOFF_REL * fabs(expected) + 1e-300)
/* For quantities whose exact value is 0, on the scale `scale`. */
#define ASSERT_ZERO(value, scale) ck_assert_double_eq_tol((value), 0.0, ROUNDOFF_REL * (scale))

static double mass(double r)
{
    return RHO * BAL_PI * r * r;
}

/* ------------------------------------------------------------------ */
/* Results pool: freed by the checked teardown when a test fails        */
/* ------------------------------------------------------------------ */

#define EX_POOL 4
static struct bal_exact ex_pool[EX_POOL];
static int ex_used[EX_POOL];

static struct bal_exact *ex_take(void)
{
    for (int k = 0; k < EX_POOL; k++) {
        if (!ex_used[k]) {
            ex_used[k] = 1;
            memset(&ex_pool[k], 0, sizeof ex_pool[k]);
            return &ex_pool[k];
        }
    }
    ck_abort_msg("exact result pool exhausted (%d)", EX_POOL);
    return NULL;
}

static void ex_teardown(void)
{
    for (int k = 0; k < EX_POOL; k++) {
        if (ex_used[k])
            bal_exact_free(&ex_pool[k]);
        ex_used[k] = 0;
    }
}

/* Solve and assert success. */
static struct bal_exact *solve(struct tfx *f)
{
    struct bal_exact *ex = ex_take();
    enum bal_status st = bal_exact_solve(f->sim, ex, &f->err);
    ck_assert_msg(st == BAL_OK, "exact solve failed: %s", f->err.msg);
    return ex;
}

/* Solve and expect a refusal whose message contains `needle`. */
static void solve_refused(struct tfx *f, const char *needle)
{
    struct bal_exact *ex = ex_take();
    enum bal_status st = bal_exact_solve(f->sim, ex, &f->err);
    ck_assert_msg(st == BAL_EINVAL, "expected BAL_EINVAL, got %d (%s)", (int)st, f->err.msg);
    ck_assert_msg(t_contains(f->err.msg, needle), "message '%s' lacks '%s'", f->err.msg, needle);
    ck_assert_int_eq(ex->n_contacts, 0); /* nothing left to free */
    ck_assert_ptr_null(ex->contacts);
}

static int wall_of(const struct tfx *f, const char *name)
{
    for (int k = 0; k < f->sim->n_walls; k++)
        if (strcmp(f->sim->walls[k].name, name) == 0)
            return k;
    ck_abort_msg("no wall '%s'", name);
    return -1;
}

/* The contact between disc `a` and body `b` (a disc, or a wall when
 * b_is_wall), asserting it is in the network. */
static const struct bal_exact_contact *contact(const struct tfx *f, const struct bal_exact *ex,
                                               const char *a, const char *b, int b_is_wall)
{
    int i = t_slot(f, a), j;
    if (b_is_wall) {
        j = wall_of(f, b);
    } else {
        j = t_slot(f, b);
        if (j < i) {
            const int t = i;
            i = j;
            j = t;
        }
    }
    for (long c = 0; c < ex->n_contacts; c++) {
        const struct bal_exact_contact *C = &ex->contacts[c];
        if (C->i == i && C->j == j && C->is_wall == b_is_wall)
            return C;
    }
    ck_abort_msg("no contact %s–%s in the network", a, b);
    return NULL;
}

/* Every free disc balances, support = weight, the contacts are sorted by
 * (i, is_wall, j), normals are unit vectors and forces non-negative. */
static void assert_balanced(const struct bal_exact *ex, double residual_max)
{
    const double w = hypot(ex->weight[0], ex->weight[1]);
    ck_assert_msg(ex->residual <= residual_max, "residual %g > %g", ex->residual, residual_max);
    ck_assert_double_eq_tol(ex->support[0], ex->weight[0], residual_max * w * 10);
    ck_assert_double_eq_tol(ex->support[1], ex->weight[1], residual_max * w * 10);
    long n_open = 0;
    for (long c = 0; c < ex->n_contacts; c++) {
        const struct bal_exact_contact *C = &ex->contacts[c];
        ck_assert(C->fn >= 0);
        ck_assert_double_eq_tol(hypot(C->nx, C->ny), 1.0, 1e-15);
        if (C->open) {
            ck_assert_double_eq(C->fn, 0.0);
            n_open++;
        }
        if (c > 0) {
            const struct bal_exact_contact *P = &ex->contacts[c - 1];
            ck_assert(P->i < C->i || (P->i == C->i && (P->is_wall < C->is_wall ||
                                                       (P->is_wall == C->is_wall && P->j < C->j))));
        }
    }
    ck_assert_int_eq(n_open, ex->n_open);
}

/* ------------------------------------------------------------------ */
/* Statically determinate networks                                     */
/* ------------------------------------------------------------------ */

/* Disc "top" (radius R) rests on held discs "left" and "right" (radius R)
 * whose centres lie at D = 2R from its centre, at ±30° from the vertical
 * below it.  Symmetry leaves the vertical balance only:
 *     2 F cos 30° = m g   →   F = m g / (2 cos 30°)   on each contact,
 * whatever k is.  The normal from top to left is (−sin 30°, −cos 30°).
 * The held discs touch each other (their distance is 2 D sin 30° = 2R);
 * a pair of held bodies is not part of the network, so it has 2 contacts. */
static struct tfx *on_two_held(double kn, const char *extra_material, const char *settings)
{
    const double r = 0.61, d = 2 * r, x0 = 0.35, y0 = 1.4;
    return tfx_newf("two_held",
                    "[settings]\ngravity = 0 %.17g\n%s\n"
                    "[material m]\nkn = %.17g\ndensity = %.17g\n%s\n"
                    "[disc top]\nx = %.17g %.17g\nr = %.17g\nmaterial = m\n"
                    "[disc left]\nx = %.17g %.17g\nr = %.17g\nmaterial = m\nfixed = 1\n"
                    "[disc right]\nx = %.17g %.17g\nr = %.17g\nmaterial = m\nfixed = 1\n"
                    "[stage s]\ncycles = 1\n",
                    -G, settings, kn, RHO, extra_material, x0, y0, r, x0 - d * SIN30,
                    y0 - d * COS30, r, x0 + d * SIN30, y0 - d * COS30, r);
}

START_TEST(exact_two_held_30_degrees)
{
    const double m = mass(0.61), F = m * G / (2 * COS30);
    struct tfx *f = on_two_held(3.7e4, "", "");
    const struct bal_exact *ex = solve(f);

    ck_assert_int_eq(ex->n_contacts, 2);
    ck_assert_int_eq(ex->n_open, 0);
    ck_assert_int_eq(ex->iterations, 1);
    const struct bal_exact_contact *L = contact(f, ex, "top", "left", 0);
    const struct bal_exact_contact *R = contact(f, ex, "top", "right", 0);
    ASSERT_REL(L->fn, F);
    ASSERT_REL(R->fn, F);
    /* Normals point from the lower slot to the higher one. */
    const double sx = L->i == t_slot(f, "top") ? 1 : -1;
    ASSERT_REL(L->nx, -SIN30 * sx);
    ASSERT_REL(L->ny, -COS30 * sx);
    ASSERT_ZERO(ex->weight[0], m * G);
    ASSERT_REL(ex->weight[1], -m * G);
    ASSERT_REL(ex->support[1], -m * G);
    ASSERT_ZERO(ex->support[0], m * G);
    assert_balanced(ex, RESIDUAL_SMALL);
    ck_assert(ex->seconds >= 0);
    ck_assert_int_eq(ex->bandwidth, 1); /* one free disc: x and y couple */
}
END_TEST

/* The same network with k 2e4 times stiffer: F = k δ with δ ∝ 1/k, so the
 * forces agree to round-off (and with the closed form above). */
START_TEST(exact_independent_of_k)
{
    const double F = mass(0.61) * G / (2 * COS30);
    struct tfx *soft = on_two_held(3.7e4, "", "");
    struct tfx *stiff = on_two_held(7.4e8, "", "");
    const struct bal_exact *a = solve(soft);
    const struct bal_exact *b = solve(stiff);
    ck_assert_int_eq(a->n_contacts, b->n_contacts);
    for (long c = 0; c < a->n_contacts; c++) {
        ASSERT_REL(a->contacts[c].fn, F);
        ASSERT_REL(b->contacts[c].fn, a->contacts[c].fn);
    }
    /* The linear power law (nu = 1) is the same law. */
    struct tfx *pw = on_two_held(3.7e4, "", "normal_law = power\nnu = 1\ndelta0 = 0.37");
    const struct bal_exact *p = solve(pw);
    for (long c = 0; c < p->n_contacts; c++)
        ASSERT_REL(p->contacts[c].fn, F);
}
END_TEST

/* A disc of radius r on a floor wall (y = 0, from x = −2 to 3): the
 * contact normal is (0, −1) from the disc to the wall and F = m g.  A
 * frictionless disc on a floor alone could slide (a mechanism), so a
 * vertical wall touches it on the left: its normal (−1, 0) is normal to
 * gravity and the horizontal balance gives F_side = 0. */
START_TEST(exact_disc_on_floor)
{
    const double r = 0.43, xc = 0.27, m = mass(r);
    struct tfx *f = tfx_newf("floor",
                             "[settings]\ngravity = 0 %.17g\n"
                             "[material m]\nkn = 2.9e5\ndensity = %.17g\n"
                             "[material w]\nkn = 6.1e5\n"
                             "[wall floor]\np = -2 0\nangle = 0\nh1 = 0\nh2 = 5\nmaterial = w\n"
                             "[wall side]\np = %.17g -1\nangle = 90\nh1 = 0\nh2 = 3\n"
                             "material = w\n"
                             "[disc d]\nx = %.17g %.17g\nr = %.17g\nmaterial = m\n"
                             "[stage s]\ncycles = 1\n",
                             -G, RHO, xc - r, xc, r, r);
    const struct bal_exact *ex = solve(f);
    ck_assert_int_eq(ex->n_contacts, 2);
    const struct bal_exact_contact *C = contact(f, ex, "d", "floor", 1);
    ASSERT_REL(C->fn, m * G);
    ASSERT_ZERO(C->nx, 1);
    ASSERT_REL(C->ny, -1.0);
    const struct bal_exact_contact *S = contact(f, ex, "d", "side", 1);
    ASSERT_REL(S->nx, -1.0);
    ASSERT_ZERO(S->fn, m * G);
    ck_assert_int_eq(S->open, 0);
    ASSERT_REL(ex->support[1], -m * G);
    assert_balanced(ex, RESIDUAL_SMALL);
}
END_TEST

/* A stack of two free discs of diameter 1 (r = 1/2):
 *   held h1 (0, 0), h2 (1, 0); free b (1/2, √3/2) on them;
 *   free t (1, √3) on b and on a held disc h4 of radius 0.3 at
 *   t + 0.8 (sin 30°, −cos 30°), which touches nothing else.
 * t: two contacts at ±30° from the vertical: F_tb = F_t4 = m g / √3.
 * b: the push of t, F_tb (−1/2, −√3/2), and the supports
 *   F_1 (1/2, √3/2) from h1, F_2 (−1/2, √3/2) from h2:
 *   x: −F_tb/2 + F_1/2 − F_2/2 = 0   →  F_1 − F_2 = F_tb = m g/√3
 *   y: √3/2 (F_1 + F_2 − F_tb) = m g  →  F_1 + F_2 = √3 m g
 *   →  F_1 = 2 m g/√3,  F_2 = m g/√3.
 * Support = weight = (0, −2 m g). */
START_TEST(exact_small_stack)
{
    const double r = 0.5, m = mass(r), s3 = sqrt(3.0);
    const double tx = 1, ty = s3, rh = 0.3;
    struct tfx *f = tfx_newf(
        "stack",
        "[settings]\ngravity = 0 %.17g\n"
        "[material m]\nkn = 4.4e6\ndensity = %.17g\n"
        "[disc h1]\nx = 0 0\nr = 0.5\nmaterial = m\nfixed = 1\n"
        "[disc h2]\nx = 1 0\nr = 0.5\nmaterial = m\nfixed = 1\n"
        "[disc b]\nx = 0.5 %.17g\nr = 0.5\nmaterial = m\n"
        "[disc t]\nx = %.17g %.17g\nr = 0.5\nmaterial = m\n"
        "[disc h4]\nx = %.17g %.17g\nr = %.17g\nmaterial = m\nfixed = 1\n"
        "[stage s]\ncycles = 1\n",
        -G, RHO, s3 / 2, tx, ty, tx + (r + rh) * SIN30, ty - (r + rh) * COS30, rh);
    const struct bal_exact *ex = solve(f);
    ck_assert_int_eq(ex->n_contacts, 4);
    ck_assert_int_eq(ex->n_open, 0);
    ASSERT_REL(contact(f, ex, "t", "b", 0)->fn, m * G / s3);
    ASSERT_REL(contact(f, ex, "t", "h4", 0)->fn, m * G / s3);
    ASSERT_REL(contact(f, ex, "b", "h1", 0)->fn, 2 * m * G / s3);
    ASSERT_REL(contact(f, ex, "b", "h2", 0)->fn, m * G / s3);
    ASSERT_REL(ex->weight[1], -2 * m * G);
    ASSERT_REL(ex->support[1], -2 * m * G);
    ASSERT_ZERO(ex->support[0], m * G);
    assert_balanced(ex, RESIDUAL_SMALL);
}
END_TEST

/* ------------------------------------------------------------------ */
/* Statically indeterminate networks                                   */
/* ------------------------------------------------------------------ */

/* A disc of radius r rests on two collinear floor walls that overlap under
 * it (both touch it at the same point, normal (0, −1)), of materials whose
 * pair stiffnesses with the disc are k_a and k_b; two side walls touching
 * it left and right keep it from sliding (their contacts are normal to
 * gravity).  The disc sinks by v, both springs shorten by v:
 *   F_a = k_a v,  F_b = k_b v,  F_a + F_b = m g
 *   →  F_a = m g k_a/(k_a + k_b),  F_b = m g k_b/(k_a + k_b).
 * k_c is the pair law's kn (build.c); the scene makes k_a ≠ k_b. */
START_TEST(exact_load_shared_by_stiffness)
{
    const double r = 0.52, xc = 0.1, m = mass(r);
    struct tfx *f = tfx_newf(
        "shared",
        "[settings]\ngravity = 0 %.17g\n"
        "[material m]\nkn = 3.3e4\ndensity = %.17g\n"
        "[material wa]\nkn = 1.1e4\n[material wb]\nkn = 9.7e4\n"
        "[wall fa]\np = -3 0\nangle = 0\nh1 = 0\nh2 = 3.2\nmaterial = wa\n"
        "[wall fb]\np = -0.2 0\nangle = 0\nh1 = 0\nh2 = 3\nmaterial = wb\n"
        "[wall left]\np = %.17g 0\nangle = 90\nh1 = 0\nh2 = 2\nmaterial = wa\n"
        "[wall right]\np = %.17g 0\nangle = 90\nh1 = 0\nh2 = 2\nmaterial = wa\n"
        "[disc d]\nx = %.17g %.17g\nr = %.17g\nmaterial = m\n"
        "[stage s]\ncycles = 1\n",
        -G, RHO, xc - r, xc + r, xc, r, r);
    const struct bal_sim *s = f->sim;
    const int md = s->mat[t_slot(f, "d")];
    const double ka = s->law[md * s->n_mat + s->walls[wall_of(f, "fa")].material].kn;
    const double kb = s->law[md * s->n_mat + s->walls[wall_of(f, "fb")].material].kn;
    ck_assert(fabs(ka - kb) > 0.1 * ka);
    const struct bal_exact *ex = solve(f);
    ck_assert_int_eq(ex->n_contacts, 4);
    ASSERT_REL(contact(f, ex, "d", "fa", 1)->fn, m * G * ka / (ka + kb));
    ASSERT_REL(contact(f, ex, "d", "fb", 1)->fn, m * G * kb / (ka + kb));
    ASSERT_ZERO(contact(f, ex, "d", "left", 1)->fn, m * G);
    ASSERT_ZERO(contact(f, ex, "d", "right", 1)->fn, m * G);
    assert_balanced(ex, RESIDUAL_SMALL);
}
END_TEST

/* A pyramid of diameter-1 discs with equal k: held h1 (0, 0), h2 (1, 0),
 * h3 (2, 0); free b1 (1/2, √3/2), b2 (3/2, √3/2) touching each other, and
 * free t (1, √3) on both.  By mirror symmetry u_t = (0, −w), u_b1 = (−a, −v),
 * u_b2 = (a, −v).  Approaches (F = k δ):
 *   t–b1:  δ = −a/2 + √3/2 (w − v)     b1–h1: δ =  a/2 + √3/2 v
 *   b1–h2: δ = −a/2 + √3/2 v           b1–b2: δ = −2a
 * t: √3/2 · 2 F_tb = m g → F_tb = m g/√3.
 * b1, x: −F_tb/2 + (F_h1 − F_h2)/2 − F_bb = 0, with F_h1 − F_h2 = k a and
 *   F_bb = −2 k a:  −F_tb/2 + k a/2 + 2 k a = 0  →  k a = F_tb/5, so in the
 *   all-closed (linear) solution F_bb = −2 m g/(5√3) < 0: tension.
 * The unilateral solution opens b1–b2 (F_bb = 0); then x: k a = F_tb and
 *   F_h1 − F_h2 = m g/√3, y: F_h1 + F_h2 = F_tb + 2 m g/√3 = √3 m g, so
 *   F_h1 = 2 m g/√3, F_h2 = m g/√3 (both compressive), and the open
 *   contact separates (δ = −2a < 0): no contact to re-close.  Two solves. */
START_TEST(exact_unilateral_opens_tensile_contact)
{
    const double m = mass(0.5), s3 = sqrt(3.0);
    struct tfx *f = tfx_newf("pyramid",
                             "[settings]\ngravity = 0 %.17g\n"
                             "[material m]\nkn = 8.8e5\ndensity = %.17g\n"
                             "[disc h1]\nx = 0 0\nr = 0.5\nmaterial = m\nfixed = 1\n"
                             "[disc h2]\nx = 1 0\nr = 0.5\nmaterial = m\nfixed = 1\n"
                             "[disc h3]\nx = 2 0\nr = 0.5\nmaterial = m\nfixed = 1\n"
                             "[disc b1]\nx = 0.5 %.17g\nr = 0.5\nmaterial = m\n"
                             "[disc b2]\nx = 1.5 %.17g\nr = 0.5\nmaterial = m\n"
                             "[disc t]\nx = 1 %.17g\nr = 0.5\nmaterial = m\n"
                             "[stage s]\ncycles = 1\n",
                             -G, RHO, s3 / 2, s3 / 2, s3);
    const struct bal_exact *ex = solve(f);
    ck_assert_int_eq(ex->n_contacts, 7);
    ck_assert_int_eq(ex->n_open, 1);
    ck_assert_int_eq(ex->iterations, 2);
    const struct bal_exact_contact *bb = contact(f, ex, "b1", "b2", 0);
    ck_assert_int_eq(bb->open, 1);
    ck_assert_double_eq(bb->fn, 0.0);
    ASSERT_REL(contact(f, ex, "t", "b1", 0)->fn, m * G / s3);
    ASSERT_REL(contact(f, ex, "t", "b2", 0)->fn, m * G / s3);
    ASSERT_REL(contact(f, ex, "b1", "h1", 0)->fn, 2 * m * G / s3);
    ASSERT_REL(contact(f, ex, "b1", "h2", 0)->fn, m * G / s3);
    ASSERT_REL(contact(f, ex, "b2", "h3", 0)->fn, 2 * m * G / s3);
    ASSERT_REL(contact(f, ex, "b2", "h2", 0)->fn, m * G / s3);
    ASSERT_REL(ex->support[1], -3 * m * G);
    assert_balanced(ex, RESIDUAL_SMALL);
}
END_TEST

/* ------------------------------------------------------------------ */
/* Refusals                                                            */
/* ------------------------------------------------------------------ */

static void quiet_handler(const char *reason, const char *file, int line, int gsl_errno)
{
    (void)reason;
    (void)file;
    (void)line;
    (void)gsl_errno;
}

/* A free disc on a single held disc straight below it can roll off
 * sideways: K is singular.  Refused, naming the free disc. */
START_TEST(exact_mechanism_one_contact)
{
    struct tfx *f = tfx_newf("mech1",
                             "[settings]\ngravity = 0 %.17g\n"
                             "[material m]\nkn = 1e5\ndensity = %.17g\n"
                             "[disc base]\nx = 0 0\nr = 0.5\nmaterial = m\nfixed = 1\n"
                             "[disc wobbly]\nx = 0 1\nr = 0.5\nmaterial = m\n"
                             "[stage s]\ncycles = 1\n",
                             -G, RHO);
    solve_refused(f, "'wobbly'");
    ck_assert(t_contains(f->err.msg, "mechanism"));
}
END_TEST

/* A mechanism of two discs that each look held: a and b lie side by side
 * on a floor and touch each other.  Each has a vertical and a horizontal
 * contact, but the pair can slide sideways together; the factorisation
 * finds the zero pivot.  The GSL error handler is restored. */
START_TEST(exact_mechanism_pair)
{
    struct tfx *f = tfx_newf("mech2",
                             "[settings]\ngravity = 0 %.17g\n"
                             "[material m]\nkn = 1e5\ndensity = %.17g\n"
                             "[wall floor]\np = -3 0\nangle = 0\nh1 = 0\nh2 = 6\nmaterial = m\n"
                             "[disc a]\nx = 0 0.5\nr = 0.5\nmaterial = m\n"
                             "[disc b]\nx = 1 0.5\nr = 0.5\nmaterial = m\n"
                             "[stage s]\ncycles = 1\n",
                             -G, RHO);
    gsl_error_handler_t *before = gsl_set_error_handler(quiet_handler);
    struct bal_exact *ex = ex_take();
    const enum bal_status st = bal_exact_solve(f->sim, ex, &f->err);
    gsl_error_handler_t *after = gsl_set_error_handler(before);
    ck_assert(after == quiet_handler);
    ck_assert_int_eq(st, BAL_EINVAL);
    ck_assert_msg(t_contains(f->err.msg, "mechanism"), "%s", f->err.msg);
    ck_assert_msg(t_contains(f->err.msg, "'a'") || t_contains(f->err.msg, "'b'"), "%s",
                  f->err.msg);
    ck_assert_ptr_null(ex->contacts);
}
END_TEST

/* A free disc touching nothing falls: refused as a mechanism too. */
START_TEST(exact_mechanism_floating)
{
    struct tfx *f = tfx_newf("float",
                             "[settings]\ngravity = 0 %.17g\n"
                             "[material m]\nkn = 1e5\ndensity = %.17g\n"
                             "[disc base]\nx = 0 0\nr = 0.5\nmaterial = m\nfixed = 1\n"
                             "[disc cloud]\nx = 0.3 2\nr = 0.5\nmaterial = m\n"
                             "[stage s]\ncycles = 1\n",
                             -G, RHO);
    solve_refused(f, "'cloud'");
}
END_TEST

/* A disc hanging from a held disc above it, between held discs to its
 * left and right: the all-closed K is regular, but the contact above is in
 * tension (F = −m g); opened, nothing holds the disc up and it falls
 * without bound: no compressive equilibrium, refused naming the disc. */
START_TEST(exact_no_equilibrium_without_tension)
{
    struct tfx *f = tfx_newf("hanging",
                             "[settings]\ngravity = 0 %.17g\n"
                             "[material m]\nkn = 1e5\ndensity = %.17g\n"
                             "[disc top]\nx = 0 1\nr = 0.5\nmaterial = m\nfixed = 1\n"
                             "[disc left]\nx = -1 0\nr = 0.5\nmaterial = m\nfixed = 1\n"
                             "[disc right]\nx = 1 0\nr = 0.5\nmaterial = m\nfixed = 1\n"
                             "[disc bob]\nx = 0 0\nr = 0.5\nmaterial = m\n"
                             "[stage s]\ncycles = 1\n",
                             -G, RHO);
    solve_refused(f, "no equilibrium without tension");
    ck_assert_msg(t_contains(f->err.msg, "'bob'"), "%s", f->err.msg);
}
END_TEST

/* A disc on a floor under two held discs that touch it at 45° above-left
 * and above-right.  All closed, symmetry gives u = (0, −v) and approaches
 * δ_floor = v, δ_upper = −v sin 45° < 0: both upper contacts are in
 * tension and open.  The solution is the disc on the floor alone (F = m g),
 * in neutral equilibrium sideways: the stiff network of its closed
 * contacts is a mechanism, which the solver refuses (exact.h). */
START_TEST(exact_neutral_mechanism_refused)
{
    const double r = 0.5, rh = 0.3, d = (r + rh) * sqrt(0.5);
    struct tfx *f = tfx_newf("neutral",
                             "[settings]\ngravity = 0 %.17g\n"
                             "[material m]\nkn = 1e5\ndensity = %.17g\n"
                             "[wall floor]\np = -3 0\nangle = 0\nh1 = 0\nh2 = 6\nmaterial = m\n"
                             "[disc puck]\nx = 0 %.17g\nr = %.17g\nmaterial = m\n"
                             "[disc ul]\nx = %.17g %.17g\nr = %.17g\nmaterial = m\nfixed = 1\n"
                             "[disc ur]\nx = %.17g %.17g\nr = %.17g\nmaterial = m\nfixed = 1\n"
                             "[stage s]\ncycles = 1\n",
                             -G, RHO, r, r, -d, r + d, rh, d, r + d, rh);
    solve_refused(f, "neutral equilibrium");
    ck_assert_msg(t_contains(f->err.msg, "'puck'"), "%s", f->err.msg);
}
END_TEST

/* Friction or cohesion on a contact of the network, and the power law with
 * nu != 1, are refused. */
START_TEST(exact_refuses_friction_cohesion_power)
{
    struct tfx *f = on_two_held(3.7e4, "friction = 0.3", "");
    solve_refused(f, "friction (tan phi = 0.3)");
    ck_assert_msg(t_contains(f->err.msg, "'top'"), "%s", f->err.msg);
    tfx_release(f);
    f = on_two_held(3.7e4, "cohesion = 0.2", "");
    solve_refused(f, "cohesion (c = 0.2)");
    tfx_release(f);
    f = on_two_held(3.7e4, "", "normal_law = power\nnu = 1.5\ndelta0 = 0.37");
    solve_refused(f, "nu = 1.5");
    tfx_release(f);
    /* the refused value as it differs from 1 (issue 29: %g printed "nu = 1
     * is not linear") */
    f = on_two_held(3.7e4, "", "normal_law = power\nnu = 1.0000001\ndelta0 = 0.37");
    solve_refused(f, "nu = 1.0000001 is not linear");
}
END_TEST

/* Friction between two held discs only does not matter: the frictionless
 * free disc's contacts use the smaller tan φ of the pair (0). */
START_TEST(exact_friction_between_held_discs_ignored)
{
    const double r = 0.5, m = mass(r);
    struct tfx *f = tfx_newf("held_friction",
                             "[settings]\ngravity = 0 %.17g\n"
                             "[material rough]\nkn = 1e5\nfriction = 0.7\ndensity = %.17g\n"
                             "[material smooth]\nkn = 1e5\ndensity = %.17g\n"
                             "[disc l]\nx = 0 0\nr = 0.5\nmaterial = rough\nfixed = 1\n"
                             "[disc r]\nx = 1 0\nr = 0.5\nmaterial = rough\nfixed = 1\n"
                             "[disc top]\nx = 0.5 %.17g\nr = 0.5\nmaterial = smooth\n"
                             "[stage s]\ncycles = 1\n",
                             -G, RHO, RHO, COS30);
    const struct bal_exact *ex = solve(f);
    ck_assert_int_eq(ex->n_contacts, 2);
    ASSERT_REL(contact(f, ex, "top", "l", 0)->fn, m * G / (2 * COS30));
}
END_TEST

/* ------------------------------------------------------------------ */
/* The 30° pile of MLH Fig. 2 with L0 = 100: 1717 discs                */
/* ------------------------------------------------------------------ */

#define PILE_L 100
#define PILE_TEXT_MAX (1 << 18)
static char pile_text[PILE_TEXT_MAX];

/* Row M (M = 0 … 33) has L − 3M discs of diameter 1 at x = 1.5 M + k,
 * y = M √3/2 (each row sits in the hollows of the one below and is 1.5
 * shorter on each side: a 30° slope); row 0 is held.  N = Σ (L − 3M) =
 * 34·100 − 3·(33·34/2) = 1717. */
static struct tfx *pile(void)
{
    size_t len = 0;
    int n = 0;
    len += (size_t)snprintf(pile_text + len, PILE_TEXT_MAX - len,
                            "[settings]\ngravity = 0 %.17g\n"
                            "[material m]\nkn = 1e6\ndensity = %.17g\n",
                            -G, RHO);
    for (int M = 0; PILE_L - 3 * M > 0; M++) {
        for (int k = 0; k < PILE_L - 3 * M; k++, n++) {
            len += (size_t)snprintf(pile_text + len, PILE_TEXT_MAX - len,
                                    "[disc d%d_%d]\nx = %.17g %.17g\nr = 0.5\nmaterial = m\n%s",
                                    M, k, 1.5 * M + k, M * (sqrt(3.0) / 2),
                                    M == 0 ? "fixed = 1\n" : "");
            ck_assert(len < PILE_TEXT_MAX);
        }
    }
    len += (size_t)snprintf(pile_text + len, PILE_TEXT_MAX - len, "[stage s]\ncycles = 1\n");
    ck_assert(len < PILE_TEXT_MAX);
    ck_assert_int_eq(n, 1717);
    return tfx_new(pile_text, "pile");
}

/* The horizontal contact of row M whose midpoint is at x, or NULL. */
static const struct bal_exact_contact *horizontal(const struct bal_sim *s,
                                                  const struct bal_exact *ex, int M, double x)
{
    for (long c = 0; c < ex->n_contacts; c++) {
        const struct bal_exact_contact *C = &ex->contacts[c];
        if (C->is_wall)
            continue;
        const double cx = 0.5 * (s->x[C->i] + s->x[C->j]), cy = 0.5 * (s->y[C->i] + s->y[C->j]);
        if (fabs(C->ny) < 1e-9 && fabs(cy - M * (sqrt(3.0) / 2)) < 1e-6 && fabs(cx - x) < 1e-6)
            return C;
    }
    return NULL;
}

/* The pile solves in a handful of factorisations, and its balance holds to
 * round-off.  The forces of the unilateral problem are unique (the
 * potential is convex and each max(δ_c, 0) is constant on the set of its
 * minima), so the mirror image about x = 49.5 of every contact carries the
 * same force.  The contacts counted by hand: 2 below each of the 1617 free
 * discs, and L − 3M − 1 horizontal ones in rows M = 1 … 33 (1584), 4818 in
 * all (the 99 between held discs of row 0 are not in the network).
 * MLH Sec. 4.2 (Fig. 5, linear law): the contact network has a diamond
 * region in the centre — horizontal contacts open — and is triangular at
 * the shoulders; checked in row 1 (discs at x = 1.5 … 97.5, horizontal
 * contacts at x = 2 … 97) at the centre (x = 49, next to the axis 49.5)
 * and at the left shoulder (x = 3).  Prints one line with the timing. */
START_TEST(exact_pile_1717)
{
    struct tfx *f = pile();
    const struct bal_sim *s = f->sim;
    const struct bal_exact *ex = solve(f);
    printf("exact: pile L0 = %d: %d discs, %ld contacts, %d solves, %ld open, "
           "half-bandwidth %d, residual %.2g, %.3f s\n",
           PILE_L, s->n, ex->n_contacts, ex->iterations, ex->n_open, ex->bandwidth,
           ex->residual, ex->seconds);
    /* Its speed is a benchmark figure, printed above, never asserted: the
     * iteration count stands for the work instead. */
    ck_assert_int_le(ex->iterations, 20);
    ck_assert_int_eq(ex->n_contacts, 4818);
    assert_balanced(ex, RESIDUAL_PILE);
    const double mg = mass(0.5) * G;
    ASSERT_REL(ex->weight[1], -1617 * mg);

    /* Mirror symmetry. */
    const double xm = (PILE_L - 1) / 2.0;
    for (long c = 0; c < ex->n_contacts; c++) {
        const struct bal_exact_contact *C = &ex->contacts[c];
        const double cx = 0.5 * (s->x[C->i] + s->x[C->j]), cy = 0.5 * (s->y[C->i] + s->y[C->j]);
        long mirror = -1;
        for (long q = 0; q < ex->n_contacts && mirror < 0; q++) {
            const struct bal_exact_contact *Q = &ex->contacts[q];
            const double qx = 0.5 * (s->x[Q->i] + s->x[Q->j]);
            const double qy = 0.5 * (s->y[Q->i] + s->y[Q->j]);
            if (fabs(qx - (2 * xm - cx)) < 1e-6 && fabs(qy - cy) < 1e-6)
                mirror = q;
        }
        ck_assert(mirror >= 0);
        ck_assert_int_eq(ex->contacts[mirror].open, C->open);
        ck_assert_double_eq_tol(ex->contacts[mirror].fn, C->fn, RESIDUAL_PILE * mg * 10);
    }

    /* Diamond centre, triangular shoulders (row 1 spans x = 1.5 … 97.5). */
    const struct bal_exact_contact *centre = horizontal(s, ex, 1, 49);
    const struct bal_exact_contact *shoulder = horizontal(s, ex, 1, 3);
    ck_assert_ptr_nonnull(centre);
    ck_assert_ptr_nonnull(shoulder);
    ck_assert_int_eq(centre->open, 1);
    ck_assert_int_eq(shoulder->open, 0);
    ck_assert(shoulder->fn > 0);
}
END_TEST

/* The 60° pile of MLH Fig. 2 with L = 30 (row M has L − M discs at
 * x = M/2 + k, y = M √3/2; row 0 held): 465 discs, 435 free.  Here the
 * full-step iteration reaches a singular K after a few solves, so the
 * damped phase of exact.c carries the solution (found by scanning
 * L = 2 … 60; with the linear power law and alpha damping, a DEM run of
 * this pile converges to these forces as 1/k: 3.5e-3 m g at k = 1e6,
 * 3.5e-4 m g at 1e7).
 * The solution opens every horizontal contact: a diamond network in which
 * each free disc stands on its two neighbours below, statically
 * determinate.  The balance of disc (M, k) with W = m g, pushed by its
 * upper-left neighbour with A and its upper-right one with B, and held by
 * F_L (below-left) and F_R (below-right), all at 30° from the vertical:
 *   x: (A − B + F_L − F_R) sin 30° = 0,  y: (F_L + F_R − A − B) cos 30° = W
 *   →  F_L = B + W/(2 cos 30°),  F_R = A + W/(2 cos 30°):
 * force runs down straight lines of contacts and grows by W/√3 per disc.
 * The line through the below-left contact of (M, k) holds the discs
 * (M + j, k), j = 0 … L − M − k − 1, and that through its below-right
 * contact holds (M + j, k − j), j = 0 … k, so
 *   F_L(M, k) = (L − M − k) W/√3,   F_R(M, k) = (k + 1) W/√3.
 * Contacts: 2 × 435 below, Σ_{M=1}^{29} (L − M − 1) = 406 horizontal. */
#define PILE60_L 30

START_TEST(exact_pile_60_damped_phase)
{
    char *text = pile_text;
    size_t len = 0;
    len += (size_t)snprintf(text + len, PILE_TEXT_MAX - len,
                            "[settings]\ngravity = 0 %.17g\n"
                            "[material m]\nkn = 3e5\ndensity = %.17g\n",
                            -G, RHO);
    for (int M = 0; M < PILE60_L; M++)
        for (int k = 0; k < PILE60_L - M; k++) {
            len += (size_t)snprintf(text + len, PILE_TEXT_MAX - len,
                                    "[disc d%d_%d]\nx = %.17g %.17g\nr = 0.5\nmaterial = m\n%s",
                                    M, k, 0.5 * M + k, M * (sqrt(3.0) / 2),
                                    M == 0 ? "fixed = 1\n" : "");
            ck_assert(len < PILE_TEXT_MAX);
        }
    snprintf(text + len, PILE_TEXT_MAX - len, "[stage s]\ncycles = 1\n");
    struct tfx *f = tfx_new(text, "pile60");
    const struct bal_sim *s = f->sim;
    const struct bal_exact *ex = solve(f);
    ck_assert_int_eq(s->n, 465);
    ck_assert_int_eq(ex->n_contacts, 870 + 406);
    ck_assert_int_eq(ex->n_open, 406);
    assert_balanced(ex, RESIDUAL_PILE);
    const double W = mass(0.5) * G, s3 = sqrt(3.0);
    long n_below = 0;
    for (long c = 0; c < ex->n_contacts; c++) {
        const struct bal_exact_contact *C = &ex->contacts[c];
        const int up = s->y[C->i] > s->y[C->j] ? C->i : C->j;
        const int down = up == C->i ? C->j : C->i;
        if (fabs(s->y[up] - s->y[down]) < 0.5) {
            ck_assert_int_eq(C->open, 1); /* horizontal */
            ck_assert_double_eq(C->fn, 0.0);
            continue;
        }
        const int M = (int)lround(s->y[up] / (s3 / 2)), k = (int)lround(s->x[up] - 0.5 * M);
        const double expected = (s->x[down] < s->x[up] ? PILE60_L - M - k : k + 1) * W / s3;
        ck_assert_double_eq_tol(C->fn, expected, RESIDUAL_PILE * W * PILE60_L);
        n_below++;
    }
    ck_assert_int_eq(n_below, 870);
}
END_TEST

Suite *suite_exact(void)
{
    Suite *s = suite_create("exact");

    TCase *tc = tcase_create("determinate");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_checked_fixture(tc, NULL, ex_teardown);
    tcase_add_test(tc, exact_two_held_30_degrees);
    tcase_add_test(tc, exact_independent_of_k);
    tcase_add_test(tc, exact_disc_on_floor);
    tcase_add_test(tc, exact_small_stack);
    suite_add_tcase(s, tc);

    tc = tcase_create("indeterminate");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_checked_fixture(tc, NULL, ex_teardown);
    tcase_add_test(tc, exact_load_shared_by_stiffness);
    tcase_add_test(tc, exact_unilateral_opens_tensile_contact);
    suite_add_tcase(s, tc);

    tc = tcase_create("refusals");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_checked_fixture(tc, NULL, ex_teardown);
    tcase_add_test(tc, exact_mechanism_one_contact);
    tcase_add_test(tc, exact_mechanism_pair);
    tcase_add_test(tc, exact_mechanism_floating);
    tcase_add_test(tc, exact_no_equilibrium_without_tension);
    tcase_add_test(tc, exact_neutral_mechanism_refused);
    tcase_add_test(tc, exact_refuses_friction_cohesion_power);
    tcase_add_test(tc, exact_friction_between_held_discs_ignored);
    suite_add_tcase(s, tc);

    tc = tcase_create("pile");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_checked_fixture(tc, NULL, ex_teardown);
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, exact_pile_1717);
    tcase_add_test(tc, exact_pile_60_damped_phase);
    suite_add_tcase(s, tc);

    return s;
}
