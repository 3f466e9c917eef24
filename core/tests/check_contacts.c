/*
 * check_contacts.c — suite "contacts": the disc–disc force–displacement law
 * of Cundall & Strack (C&S) eqs (8)–(19) and (26)–(28), and the momentum
 * balance it implies.
 *
 * Conventions under test (C&S Figs 2–3): for a contact of discs x (the first
 * in the scene) and y, e = (y − x)/D, t = (e2, −e1);
 *   ṅ = (ẋ − ẏ)·e,  ṡ = (ẋ − ẏ)·t − (θ̇x Rx + θ̇y Ry)            eqs (12), (13)
 *   F_n += k_n ṅ Δt,  F_s += k_s ṡ Δt                        eqs (16)–(18)
 *   |F_s| ≤ F_n tan φ + c, smaller φ and c of the two         eq. (19)
 * F_n and F_s act on x along −e and −t, on y along +e and +t, and the moment
 * on both discs is F_s R (counter-clockwise positive).
 *
 * After one cycle from rest history (F_n = F_s = 0) the forces are a single
 * increment, so every expected value is one line of arithmetic on the scene's
 * numbers.  Positions at t_1 are x_0 + v_{1/2} Δt (eq. 22a), computed here in
 * closed form when the geometry matters.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check_main.h"

/* A handful of floating-point operations on O(1) numbers, each rounding at
 * ~1.1e-16 relative: 1e-12 relative is a generous bound on round-off yet
 * five orders below any wrong factor, sign or term the tests look for. */
#define ROUNDOFF_REL 1e-12

/* Scene numbers shared by the tests (non-round on purpose). */
#define RHO 2.385
#define RP 0.61
#define RQ 0.44
#define DT 1.3e-3
#define ANGLE_DEG 37.3

struct disc_spec {
    double x, y, r, vx, vy, omega;
    const char *material;
};

static double mass(double r)
{
    return RHO * BAL_PI * r * r;
}

static double inertia(double r)
{
    return 0.5 * mass(r) * r * r;
}

/* Two discs p (body x of the contact) and q (body y), one short stage. */
static struct tfx *two_discs(const char *settings, const char *materials, struct disc_spec p,
                             struct disc_spec q)
{
    return tfx_newf("pair",
                    "[settings]\ndt = %.17g\n%s\n%s\n"
                    "[disc p]\nx = %.17g %.17g\nr = %.17g\nv = %.17g %.17g\nomega = %.17g\n"
                    "material = %s\n"
                    "[disc q]\nx = %.17g %.17g\nr = %.17g\nv = %.17g %.17g\nomega = %.17g\n"
                    "material = %s\n"
                    "[stage s]\ncycles = 1\n",
                    DT, settings, materials, p.x, p.y, p.r, p.vx, p.vy, p.omega, p.material, q.x,
                    q.y, q.r, q.vx, q.vy, q.omega, q.material);
}

static void unit(double angle_deg, double e[2], double t[2])
{
    const double a = angle_deg * BAL_PI / 180;
    e[0] = cos(a);
    e[1] = sin(a);
    t[0] = e[1];  /* eq. (10): e turned clockwise */
    t[1] = -e[0];
}

#define ASSERT_REL(value, expected) \
    ck_assert_double_eq_tol((value), (expected), ROUNDOFF_REL * fabs(expected) + 1e-300)

/* ------------------------------------------------------------------ */
/* Sign conventions (C&S Fig. 3, eqs 9–18)                             */
/* ------------------------------------------------------------------ */

/* Discs approaching along e at 37.3°: ṅ = u_p + u_q; after cycle 1
 * F_n = k_n ṅ Δt; the force on p is −F_n e, on q +F_n e (apart). */
START_TEST(contacts_normal_force_sign)
{
    const double kn = 3.7e4, up = 0.27, uq = 0.18;
    double e[2], t[2];
    unit(ANGLE_DEG, e, t);
    const double px = 0.35, py = -0.42, d0 = RP + RQ; /* touching, not in contact (eq. 8) */
    struct disc_spec p = {px, py, RP, up * e[0], up * e[1], 0, "m"};
    struct disc_spec q = {px + d0 * e[0], py + d0 * e[1], RQ, -uq * e[0], -uq * e[1], 0, "m"};
    char mat[128];
    snprintf(mat, sizeof mat, "[material m]\nkn = %.17g\nks = 2.9e4\ndensity = %.17g\n", kn, RHO);
    struct tfx *f = two_discs("", mat, p, q);
    const struct bal_pairs *L;
    const long c = t_contact(f, "p", "q", &L);
    ck_assert_int_eq(L->flags[c], 0); /* D = R_x + R_y: no contact at t_0 */
    t_steps(f, 1);

    const double fn = kn * (up + uq) * DT;
    const int ip = t_slot(f, "p"), iq = t_slot(f, "q");
    ck_assert_int_eq(L->flags[c] & BAL_PAIR_TOUCHING, BAL_PAIR_TOUCHING);
    ASSERT_REL(L->fn[c], fn);
    ck_assert_double_eq(L->fs[c], 0.0);
    const struct bal_sim *s = f->sim;
    ASSERT_REL(s->fx[ip], -fn * e[0]);
    ASSERT_REL(s->fy[ip], -fn * e[1]);
    ASSERT_REL(s->fx[iq], fn * e[0]);
    ASSERT_REL(s->fy[iq], fn * e[1]);
    ck_assert_double_eq(s->fx[ip] + s->fx[iq], 0.0); /* equal and opposite */
    ck_assert_double_eq(s->fy[ip] + s->fy[iq], 0.0);
    ck_assert(s->fx[ip] * e[0] + s->fy[ip] * e[1] < 0); /* pointing apart */
    ck_assert(s->fx[iq] * e[0] + s->fy[iq] * e[1] > 0);
    ck_assert_double_eq(s->tq[ip], 0.0);
    /* eq. (22): v_{3/2} = v_{1/2} + F/m Δt. */
    ASSERT_REL(s->vx[ip], up * e[0] - fn * e[0] / mass(RP) * DT);
    ASSERT_REL(s->vy[iq], -uq * e[1] + fn * e[1] / mass(RQ) * DT);
}
END_TEST

/* Pure tangential relative motion: p moves along +t, q along −t, overlapping
 * by 0.013.  At t_1 the line of centres r_1 = D0 e − (u_p + u_q) Δt t, so
 * e_1 = r_1/D_1, t_1 = (e_1y, −e_1x) and
 *   ṅ = (u_p + u_q) t·e_1 = −(u_p + u_q)² Δt / D_1 < 0  → F_n stays 0,
 *   ṡ = (u_p + u_q) t·t_1 = (u_p + u_q) D0 / D_1        → F_s = k_s ṡ Δt > 0.
 * Force on p is −F_s t_1 (it opposes p's motion), on q +F_s t_1; the moment
 * on each disc is +F_s R (counter-clockwise).  A large cohesion lifts the
 * Coulomb cap (F_n = 0) out of the way. */
START_TEST(contacts_shear_force_sign)
{
    const double ks = 2.9e4, up = 0.23, uq = 0.16, overlap = 0.013;
    double e[2], t[2];
    unit(ANGLE_DEG, e, t);
    const double px = 0.35, py = -0.42, d0 = RP + RQ - overlap;
    struct disc_spec p = {px, py, RP, up * t[0], up * t[1], 0, "m"};
    struct disc_spec q = {px + d0 * e[0], py + d0 * e[1], RQ, -uq * t[0], -uq * t[1], 0, "m"};
    char mat[160];
    snprintf(mat, sizeof mat,
             "[material m]\nkn = 3.7e4\nks = %.17g\nfriction = 0.5\ncohesion = 1e6\n"
             "density = %.17g\n",
             ks, RHO);
    struct tfx *f = two_discs("", mat, p, q);
    t_steps(f, 1);

    const double w = up + uq;
    const double r1[2] = {d0 * e[0] - w * DT * t[0], d0 * e[1] - w * DT * t[1]};
    const double d1 = hypot(r1[0], r1[1]);
    const double e1[2] = {r1[0] / d1, r1[1] / d1}, t1[2] = {e1[1], -e1[0]};
    const double sdot = w * d0 / d1;
    const double fs = ks * sdot * DT;

    const struct bal_pairs *L;
    const long c = t_contact(f, "p", "q", &L);
    const struct bal_sim *s = f->sim;
    const int ip = t_slot(f, "p"), iq = t_slot(f, "q");
    ck_assert_double_eq(L->fn[c], 0.0); /* ṅ < 0 from rest: clipped at 0, no tension */
    ck_assert(fs > 0);
    ASSERT_REL(L->fs[c], fs);
    ck_assert_int_eq(L->flags[c], BAL_PAIR_TOUCHING); /* sticking */
    ASSERT_REL(s->fx[ip], -fs * t1[0]);
    ASSERT_REL(s->fy[ip], -fs * t1[1]);
    ASSERT_REL(s->fx[iq], fs * t1[0]);
    ASSERT_REL(s->fy[iq], fs * t1[1]);
    ck_assert(s->fx[ip] * t[0] + s->fy[ip] * t[1] < 0); /* along −t on x */
    ASSERT_REL(s->tq[ip], fs * RP);
    ASSERT_REL(s->tq[iq], fs * RQ);
    ck_assert(s->tq[ip] > 0 && s->tq[iq] > 0);
    /* eq. (23): ω_{3/2} = ω_{1/2} + M/I Δt. */
    ASSERT_REL(s->w[ip], fs * RP / inertia(RP) * DT);
    ASSERT_REL(s->w[iq], fs * RQ / inertia(RQ) * DT);
}
END_TEST

/* The rotation term of eq. (13): discs at rest, spinning, overlapping.
 * ṅ = 0, ṡ = −(θ̇p Rp + θ̇q Rq) = −(1.9·0.61 − 0.7·0.44) = −0.851, so
 * F_s = k_s ṡ Δt < 0: the force on p is −F_s t = +|F_s| t and both
 * moments F_s R are clockwise, braking p's counter-clockwise spin. */
START_TEST(contacts_rotation_term)
{
    const double ks = 2.9e4, wp = 1.9, wq = -0.7, overlap = 0.013;
    double e[2], t[2];
    unit(ANGLE_DEG, e, t);
    const double px = -0.15, py = 0.62, d0 = RP + RQ - overlap;
    struct disc_spec p = {px, py, RP, 0, 0, wp, "m"};
    struct disc_spec q = {px + d0 * e[0], py + d0 * e[1], RQ, 0, 0, wq, "m"};
    char mat[160];
    snprintf(mat, sizeof mat,
             "[material m]\nkn = 3.7e4\nks = %.17g\nfriction = 0.5\ncohesion = 1e6\n"
             "density = %.17g\n",
             ks, RHO);
    struct tfx *f = two_discs("", mat, p, q);
    t_steps(f, 1);

    const double sdot = -(wp * RP + wq * RQ);
    const double fs = ks * sdot * DT;
    const struct bal_pairs *L;
    const long c = t_contact(f, "p", "q", &L);
    const struct bal_sim *s = f->sim;
    const int ip = t_slot(f, "p"), iq = t_slot(f, "q");
    ck_assert_double_eq(L->fn[c], 0.0);
    ck_assert(fs < 0);
    ASSERT_REL(L->fs[c], fs);
    ASSERT_REL(s->fx[ip], -fs * t[0]);
    ASSERT_REL(s->fy[ip], -fs * t[1]);
    ASSERT_REL(s->fx[iq], fs * t[0]);
    ASSERT_REL(s->tq[ip], fs * RP);
    ASSERT_REL(s->tq[iq], fs * RQ);
    ASSERT_REL(s->w[ip], wp + fs * RP / inertia(RP) * DT);
    ASSERT_REL(s->w[iq], wq + fs * RQ / inertia(RQ) * DT);
}
END_TEST

/* ------------------------------------------------------------------ */
/* Friction cap and damping (eqs 19, 26–28)                            */
/* ------------------------------------------------------------------ */

/* Material a: tan φ 0.62, c 7.5; material b: tan φ 0.28, c 19.  The contact
 * takes the smaller of each: tan φ = 0.28 (from b), c = 7.5 (from a). */
#define CAP_KN 4.1e4
#define CAP_KS 3.3e4
#define CAP_MATS                                                                            \
    "[material a]\nkn = 4.1e4\nks = 3.3e4\nfriction = 0.62\ncohesion = 7.5\ndensity = 2.385\n" \
    "[material b]\nkn = 4.1e4\nks = 3.3e4\nfriction = 0.28\ncohesion = 19.0\ndensity = 2.385\n"
#define CAP_TAN 0.28
#define CAP_C 7.5
#define CAP_UP 0.27
#define CAP_UQ 0.18

/* Approach along e (ṅ = 0.45, so e stays fixed) with spins wp, wq. */
static struct tfx *cap_pair(const char *settings, const char *mp, const char *mq, double wp,
                            double wq, double e[2], double t[2])
{
    unit(ANGLE_DEG, e, t);
    const double px = 0.35, py = -0.42, d0 = RP + RQ;
    struct disc_spec p = {px, py, RP, CAP_UP * e[0], CAP_UP * e[1], wp, mp};
    struct disc_spec q = {px + d0 * e[0], py + d0 * e[1], RQ, -CAP_UQ * e[0], -CAP_UQ * e[1], wq,
                          mq};
    return two_discs(settings, CAP_MATS, p, q);
}

/* Spins −3.1, −2.2: ṡ = −(−3.1·0.61 − 2.2·0.44) = 2.859, trial
 * F_s = k_s ṡ Δt ≈ 122.6 > cap = F_n·0.28 + 7.5 ≈ 14.2: capped, sign kept,
 * sliding; the reverse spins give −cap.  Swapping the materials of the two
 * discs changes nothing. */
START_TEST(contacts_friction_cap_smaller_phi_and_c)
{
    static const struct {
        const char *mp, *mq;
        double wp, wq, sign;
    } cases[] = {
        {"a", "b", -3.1, -2.2, 1},
        {"a", "b", 3.1, 2.2, -1},
        {"b", "a", -3.1, -2.2, 1},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        double e[2], t[2];
        struct tfx *f = cap_pair("", cases[k].mp, cases[k].mq, cases[k].wp, cases[k].wq, e, t);
        t_steps(f, 1);
        const double fn = CAP_KN * (CAP_UP + CAP_UQ) * DT;
        const double sdot = -(cases[k].wp * RP + cases[k].wq * RQ);
        const double trial = CAP_KS * sdot * DT;
        const double cap = fn * CAP_TAN + CAP_C;
        ck_assert(fabs(trial) > cap);
        const struct bal_pairs *L;
        const long c = t_contact(f, "p", "q", &L);
        const struct bal_sim *s = f->sim;
        const int ip = t_slot(f, "p");
        ASSERT_REL(L->fn[c], fn);
        ASSERT_REL(L->fs[c], cases[k].sign * cap);
        ck_assert_int_eq(L->flags[c], BAL_PAIR_TOUCHING | BAL_PAIR_SLIDING);
        ASSERT_REL(s->fx[ip], -(fn * e[0] + cases[k].sign * cap * t[0]));
        ASSERT_REL(s->fy[ip], -(fn * e[1] + cases[k].sign * cap * t[1]));
        ASSERT_REL(s->tq[ip], cases[k].sign * cap * RP);
        ck_assert_double_eq(L->dn[c], 0.0);
        ck_assert_double_eq(L->ds[c], 0.0);
        tfx_release(f);
    }
}
END_TEST

/* Contact damping β (eq. 28): c_n = β k_n, c_s = β k_s.
 * Sticking (spins −0.05, 0.03: ṡ = 0.0173, F_s ≈ 0.74 < cap):
 *   D_n = β k_n ṅ, D_s = β k_s ṡ, force on p −[(F_n + D_n) e + (F_s + D_s) t],
 *   moment (F_s + D_s) R.
 * Sliding (spins −3.1, −2.2): D_s = 0 ("the viscous damping in the shear
 * direction is not applied when sliding occurs"), D_n unchanged, and the cap
 * uses the elastic F_n (eq. 19), not F_n + D_n. */
START_TEST(contacts_damping_sticking_and_sliding)
{
    const double beta = 2.1e-4;
    char settings[64];
    snprintf(settings, sizeof settings, "beta = %.17g", beta);
    const double ndot = CAP_UP + CAP_UQ;
    const double fn = CAP_KN * ndot * DT, dn = beta * CAP_KN * ndot;
    const double cap = fn * CAP_TAN + CAP_C;

    /* sticking */
    double e[2], t[2];
    struct tfx *f = cap_pair(settings, "a", "b", -0.05, 0.03, e, t);
    t_steps(f, 1);
    double sdot = -(-0.05 * RP + 0.03 * RQ);
    double fs = CAP_KS * sdot * DT, ds = beta * CAP_KS * sdot;
    ck_assert(fabs(fs) < cap);
    const struct bal_pairs *L;
    long c = t_contact(f, "p", "q", &L);
    int ip = t_slot(f, "p");
    ck_assert_int_eq(L->flags[c], BAL_PAIR_TOUCHING);
    ASSERT_REL(L->fn[c], fn);
    ASSERT_REL(L->dn[c], dn);
    ASSERT_REL(L->fs[c], fs);
    ASSERT_REL(L->ds[c], ds);
    ASSERT_REL(f->sim->fx[ip], -((fn + dn) * e[0] + (fs + ds) * t[0]));
    ASSERT_REL(f->sim->fy[ip], -((fn + dn) * e[1] + (fs + ds) * t[1]));
    ASSERT_REL(f->sim->tq[ip], (fs + ds) * RP);
    tfx_release(f);

    /* sliding */
    f = cap_pair(settings, "a", "b", -3.1, -2.2, e, t);
    t_steps(f, 1);
    c = t_contact(f, "p", "q", &L);
    ip = t_slot(f, "p");
    ck_assert_int_eq(L->flags[c], BAL_PAIR_TOUCHING | BAL_PAIR_SLIDING);
    ASSERT_REL(L->fn[c], fn);
    ASSERT_REL(L->dn[c], dn);
    ASSERT_REL(L->fs[c], cap);
    ck_assert_double_eq(L->ds[c], 0.0);
    ASSERT_REL(f->sim->fx[ip], -((fn + dn) * e[0] + cap * t[0]));
    ASSERT_REL(f->sim->fy[ip], -((fn + dn) * e[1] + cap * t[1]));
    ASSERT_REL(f->sim->tq[ip], cap * RP);
}
END_TEST

/* The sliding probe reads the flag; contact_fs reads F_s. */
START_TEST(contacts_sliding_probe)
{
    double e[2], t[2];
    unit(ANGLE_DEG, e, t);
    const double px = 0.35, py = -0.42, d0 = RP + RQ;
    char text[T_TEXT_MAX];
    snprintf(text, sizeof text,
             "[settings]\ndt = %.17g\n" CAP_MATS
             "[disc p]\nx = %.17g %.17g\nr = %.17g\nv = %.17g %.17g\nomega = -3.1\nmaterial = a\n"
             "[disc q]\nx = %.17g %.17g\nr = %.17g\nv = %.17g %.17g\nomega = -2.2\nmaterial = b\n"
             "[stage s]\ncycles = 1\n"
             "[probe slide]\nquantity = contact_sliding\na = q\nb = p\n"
             "[probe fs]\nquantity = contact_fs\na = q\nb = p\n",
             DT, px, py, RP, CAP_UP * e[0], CAP_UP * e[1], px + d0 * e[0], py + d0 * e[1], RQ,
             -CAP_UQ * e[0], -CAP_UQ * e[1]);
    struct tfx *f = tfx_new(text, "slide");
    ck_assert_double_eq(t_probe_value(f, "slide"), 0.0);
    t_steps(f, 1);
    const double cap = CAP_KN * (CAP_UP + CAP_UQ) * DT * CAP_TAN + CAP_C;
    ck_assert_double_eq(t_probe_value(f, "slide"), 1.0);
    /* The sign of F_s is that of the pair (x = p, the first disc), whatever
     * order the probe names the bodies in. */
    ASSERT_REL(t_probe_value(f, "fs"), cap);
}
END_TEST

/* Two materials: k = 2 k_a k_b / (k_a + k_b) (sim.c build_laws: springs in
 * series scaled so equal materials keep their value), and k_s = k_n when ks
 * is omitted.  k_a = 2.9e4, k_b = 6.1e4 → k = 3.9311...e4. */
START_TEST(contacts_pair_stiffness)
{
    const double ka = 2.9e4, kb = 6.1e4, k = 2 * ka * kb / (ka + kb);
    double e[2], t[2];
    unit(ANGLE_DEG, e, t);
    const double up = 0.27, uq = 0.18, wp = 0.41, px = 0.35, py = -0.42, d0 = RP + RQ;
    struct disc_spec p = {px, py, RP, up * e[0], up * e[1], wp, "a"};
    struct disc_spec q = {px + d0 * e[0], py + d0 * e[1], RQ, -uq * e[0], -uq * e[1], 0, "b"};
    struct tfx *f = two_discs("",
                              "[material a]\nkn = 2.9e4\nfriction = 0.9\ndensity = 2.385\n"
                              "[material b]\nkn = 6.1e4\nfriction = 0.9\ndensity = 2.385\n",
                              p, q);
    t_steps(f, 1);
    const struct bal_pairs *L;
    const long c = t_contact(f, "p", "q", &L);
    ASSERT_REL(L->fn[c], k * (up + uq) * DT);
    ASSERT_REL(L->fs[c], k * (-wp * RP) * DT); /* k_s = k_n: ks omitted */
    ck_assert_int_eq(L->flags[c], BAL_PAIR_TOUCHING);
}
END_TEST

/* The incremental law never pulls (F_n ≥ 0); a contact that opens (eq. 8)
 * loses its history: overlapping discs moving apart get no force at all. */
START_TEST(contacts_no_tension_and_reset)
{
    double e[2], t[2];
    unit(ANGLE_DEG, e, t);
    const double px = 0.35, py = -0.42, d0 = RP + RQ - 0.0021;
    /* Relative speed 0.75 apart: the overlap 0.0021 is gone after 3 cycles
     * (3 · 0.75 · 1.3e-3 = 0.0029). */
    struct disc_spec p = {px, py, RP, -0.45 * e[0], -0.45 * e[1], 0.3, "m"};
    struct disc_spec q = {px + d0 * e[0], py + d0 * e[1], RQ, 0.3 * e[0], 0.3 * e[1], 0, "m"};
    struct tfx *f = two_discs(
        "", "[material m]\nkn = 3.7e4\nfriction = 0.4\ncohesion = 3.5\ndensity = 2.385\n", p, q);
    const struct bal_pairs *L;
    const long c = t_contact(f, "p", "q", &L);
    t_steps(f, 1);
    ck_assert_int_eq(L->flags[c] & BAL_PAIR_TOUCHING, BAL_PAIR_TOUCHING);
    ck_assert_double_eq(L->fn[c], 0.0);
    ck_assert(L->fs[c] != 0.0); /* the cohesion holds the shear spring */
    t_steps(f, 2);
    ck_assert_int_eq(L->flags[c], 0);
    ck_assert_double_eq(L->fn[c], 0.0);
    ck_assert_double_eq(L->fs[c], 0.0);
    ck_assert_double_eq(f->sim->fx[t_slot(f, "p")], 0.0);
}
END_TEST

/* ------------------------------------------------------------------ */
/* Momentum balance                                                    */
/* ------------------------------------------------------------------ */

/* Three discs in oblique frictional collisions with spins, no walls, no
 * gravity (a meets c, then b, partly at the same time).
 *
 * Linear momentum.  Each contact adds −f to x and +f to y in the same
 * floating-point value, so Σ m v changes only by round-off of the velocity
 * update: conserved to round-off.
 *
 * Angular momentum about the origin.  With positions at whole steps and
 * velocities at half steps, define after cycle N (arrays hold x_N, v_{N+1/2})
 *   L_N = Σ m x_N × v_{N+1/2} + I ω_{N+1/2}.
 * Since x_{N−1} × v_{N−1/2} = x_N × v_{N−1/2} (x_N − x_{N−1} ∥ v_{N−1/2}),
 *   L_N − L_{N−1} = Δt [Σ x_N × F_N + Σ M_N]   exactly, by eqs (22)–(23).
 * For one contact, −f on x and +f on y, f = F_n e + F_s t:
 *   x × (−f) + y × f = D e × (F_n e + F_s t) = −D F_s   (e × t = −1),
 * and the moments add F_s R_x + F_s R_y (C&S: M = F_s R at the full radius),
 * so   L_N − L_{N−1} = Δt Σ_contacts F_s (R_x + R_y − D) = Δt Σ F_s δ.
 * The scheme therefore does not conserve angular momentum: it changes by
 * Δt Σ F_s δ, the moment of F_s over the overlap — small (δ ≪ R) but not
 * round-off.  The test checks that identity to round-off and that the
 * change is far above round-off. */
START_TEST(contacts_momentum_balance)
{
    struct tfx *f = tfx_new("[settings]\ndt_fraction = 0.05\n"
                            "[material m]\nkn = 2.3e5\nks = 1.1e5\nfriction = 0.45\n"
                            "density = 2.385\n"
                            "[disc a]\nx = -1.3 0.21\nr = 1.1\nv = 0.83 0.05\nomega = 1.7\n"
                            "material = m\n"
                            "[disc b]\nx = 1.2 -0.35\nr = 0.9\nv = -0.61 0.12\nomega = -0.9\n"
                            "material = m\n"
                            "[disc c]\nx = -1.0 2.5\nr = 0.7\nv = 0.1 -1.5\nomega = 2.3\n"
                            "material = m\n"
                            "[stage s]\ncycles = 3000\n",
                            "momentum");
    struct bal_sim *s = f->sim;
    double p0[2] = {0, 0}, l0 = 0, pscale = 0, lscale = 0;
    for (int i = 0; i < s->n; i++) {
        p0[0] += s->m[i] * s->vx[i];
        p0[1] += s->m[i] * s->vy[i];
        pscale += s->m[i] * hypot(s->vx[i], s->vy[i]);
        l0 += s->m[i] * (s->x[i] * s->vy[i] - s->y[i] * s->vx[i]) + s->inertia[i] * s->w[i];
        lscale += s->m[i] * hypot(s->x[i], s->y[i]) * hypot(s->vx[i], s->vy[i]) +
                  s->inertia[i] * fabs(s->w[i]);
    }
    double defect = 0, negative_fn = 0;
    long touching = 0, sliding = 0;
    for (int n = 0; n < 3000; n++) {
        t_steps(f, 1);
        for (long c = 0; c < s->pp.n; c++) {
            if (!(s->pp.flags[c] & BAL_PAIR_TOUCHING))
                continue;
            const int i = s->pp.i[c], j = s->pp.j[c];
            const double delta = s->r[i] + s->r[j] - hypot(s->x[j] - s->x[i], s->y[j] - s->y[i]);
            defect += s->dt * s->pp.fs[c] * delta;
            touching++;
            sliding += (s->pp.flags[c] & BAL_PAIR_SLIDING) != 0;
            negative_fn = fmin(negative_fn, s->pp.fn[c]);
        }
    }
    double p[2] = {0, 0}, l = 0;
    for (int i = 0; i < s->n; i++) {
        p[0] += s->m[i] * s->vx[i];
        p[1] += s->m[i] * s->vy[i];
        l += s->m[i] * (s->x[i] * s->vy[i] - s->y[i] * s->vx[i]) + s->inertia[i] * s->w[i];
    }
    /* The run must exercise what it claims: contacts, sticking and sliding. */
    ck_assert_int_gt(touching, 20);
    ck_assert_int_gt(sliding, 0);
    ck_assert_int_gt(touching - sliding, 0);
    ck_assert_double_eq(negative_fn, 0.0);
    /* Round-off of 3000 velocity updates of O(pscale) momenta: ~3000 · 1e-16
     * relative at most; 1e-12 relative bounds it with margin. */
    const double momentum_tol = 1e-12 * pscale;
    ck_assert_double_eq_tol(p[0], p0[0], momentum_tol);
    ck_assert_double_eq_tol(p[1], p0[1], momentum_tol);
    /* The identity L − L0 = Δt Σ F_s δ holds to the same round-off (on the
     * scale of the terms of L). */
    const double angmom_tol = 1e-12 * lscale;
    ck_assert_double_eq_tol(l - l0, defect, angmom_tol);
    /* ... and the change is real, not round-off: > 1e6 × the tolerance. */
    ck_assert_msg(fabs(l - l0) > 1e6 * angmom_tol, "L changed by only %g", l - l0);
}
END_TEST

Suite *suite_contacts(void)
{
    Suite *s = suite_create("contacts");

    TCase *tc = tcase_create("sign");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, contacts_normal_force_sign);
    tcase_add_test(tc, contacts_shear_force_sign);
    tcase_add_test(tc, contacts_rotation_term);
    tcase_add_test(tc, contacts_pair_stiffness);
    tcase_add_test(tc, contacts_no_tension_and_reset);
    suite_add_tcase(s, tc);

    tc = tcase_create("friction");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, contacts_friction_cap_smaller_phi_and_c);
    tcase_add_test(tc, contacts_damping_sticking_and_sliding);
    tcase_add_test(tc, contacts_sliding_probe);
    suite_add_tcase(s, tc);

    tc = tcase_create("momentum");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, contacts_momentum_balance);
    suite_add_tcase(s, tc);
    return s;
}
