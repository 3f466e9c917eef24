/*
 * laws.h — internal: the contact law as a chain of small stateless kernels.
 *
 * Every touching contact, disc–disc or disc–wall, runs the same chain, in a
 * fixed order (the way LAMMPS's granular sub-models are organised):
 *
 *   normal      F_n: incremental k_n ṅ Δt (C&S eqs 14, 16, 18), kept ≥ 0,
 *               or the power law k_n δ0 (δ/δ0)^ν (MLH eq. 2)
 *               history: F_n (incremental law only; the power law writes it
 *               for reports)
 *   damping     D_n = (c_n + γ_n (δ/δ0)^ψ) ṅ (C&S eq. 27, MLH eq. 3),
 *               D_s = c_s ṡ while not sliding (eq. 28)          no history
 *   tangential  F_s += k_s ṡ Δt, |F_s| ≤ F_n tan φ_μ + c (eqs 15, 17–19);
 *               the slip's loss F_max |slip| for the energy audit
 *               history: F_s
 *   rolling     Jiang, Yu & Harris (2005), Secs 2–3: the contact width
 *               B = δ r (eq. 24) with the common radius r = 2 r1 r2/(r1 + r2)
 *               (eq. 9b; r = 2 r1 against a wall, eq. 11b); the rolling
 *               stiffness K_m = K_n B²/12 (eq. 29), the peak moment
 *               M_0 = F_n B/6 (eq. 33), the rolling dashpot μ_m = μ_n B²/12
 *               (eq. 49c).  The relative rotation θ_r accumulates
 *               dθ_r = dθ_1 − dθ_2 (eqs 12–13) and the elastic moment M
 *               follows it incrementally, M += K_m dθ_r, like the shear
 *               spring; Model 1 (eq. 35) caps |M| at M_0 (plastic rolling,
 *               unloading elastic from the cap), Model 2 (eq. 36) loses M
 *               for good once |M| would pass M_0 (|θ_r| > θ_r⁰ = M_0/K_m =
 *               2 F_n/(K_n B)): the contact width is gone until the contact
 *               opens and forms again, and the rolling dashpot μ_m, which
 *               lives on that width, with it.  The couples act on the rotations only
 *               (eq. 52): −(M + M_d) on x, +(M + M_d) on y, M_d = μ_m θ̇_r.
 *               history: M, θ_r; flags ROLLING (at the cap), BROKEN (Model 2)
 *
 * In ballast's notation JYH's K_n is the pair's k_n (for the power law with
 * ν ≠ 1 its coefficient k_n, not the tangent stiffness) and μ_n the pair's
 * normal dashpot c_n + γ_n (δ/δ0)^ψ.  JYH's Table 1 writes K_s in eq. (29);
 * the derivation (eqs 25–28) and eq. (49d) have K_n: a misprint.
 *
 * A kernel takes the contact's kinematics (struct bal_kin), its pair law
 * (struct bal_pair_law) and its own slice of history, and returns a force;
 * it reads no simulation state, so the loop that calls it decides layout,
 * threads and accumulation.  The disc–disc loop (pair_loop.c) calls it in
 * variants compiled without the kernels a scene switches off, so a scene
 * without friction or damping never runs their code or touches their
 * history; the disc–wall loop (wall_loop.c) calls every kernel (walls are
 * few).  The kernels are written once for both widths, one contact and
 * two at a time, in laws_lanes.h (see "the kernels of both widths" below):
 * an edit there reaches every loop.
 *
 * Adding a sub-model: one kernel in laws_lanes.h, written with its lane
 * operations (and here the stored energy of its spring, if it has one, for
 * the audit, and its one-contact wrapper if it flags), one history column in struct bal_pairs
 * (state.h) with its reserve line (pairs.c) and its gather line in the
 * rebuild's merge (grid.c, install), and one switch: a flag the disc–disc
 * loop is specialised on (a MOD_* bit and its PAIR_VARIANT rows in
 * pair_loop.c, where one_contact and two_at_a_time call it) and the
 * disc–wall loop tests.
 *
 * Sign conventions are those of ballast.h (C&S Figs 2–3): ṅ = (ẋ − ẏ)·e > 0
 * closes the contact; F_n + D_n and F_s + D_s act on x along −e and −t.
 */
#ifndef BAL_LAWS_H
#define BAL_LAWS_H

#include <math.h>
#include <stdint.h>

#include "ballast.h"

/* Contact parameters of one pair of materials (C&S eqs 16–19, 28). */
struct bal_pair_law {
    double kn, ks;         /* stiffnesses of the contact */
    double tan_phi;        /* smaller tan φ_μ of the two */
    double cohesion;       /* smaller c of the two */
    double cn, cs;         /* dashpots β k_n, β k_s */
    int shear;             /* 1 if tan φ_μ > 0 or c > 0: the pair has a shear force */
    double rolling;        /* the smaller δ of the two (JYH eq. 24); 0: no rolling law */
};

/* The parameters of the chain that do not depend on the pair. */
struct bal_law_params {
    int normal_law;        /* enum bal_normal_law */
    double nu, delta0;     /* power law (MLH eq. 2) */
    double gamma_n, psi;   /* viscous normal damping (MLH eq. 3) */
    double dt;             /* the time step: the incremental springs' Δt */
    int rolling_model;     /* enum bal_rolling_model */
};

/* The kinematics of one touching contact at t_N. */
struct bal_kin {
    double delta;          /* overlap R_x + R_y − D (or R − distance for a wall) */
    double ndot;           /* ṅ, eq. (12) */
    double sdot;           /* ṡ, eq. (13): set only where the tangential kernel runs */
};

#define BAL_PAIR_TOUCHING 1u
#define BAL_PAIR_SLIDING 2u
#define BAL_PAIR_ROLLING 4u  /* Model 1: the rolling moment is at its cap M_0 */
#define BAL_PAIR_BROKEN 8u   /* Model 2: the contact has lost its rolling resistance */

/* ------------------------------------------------- the kernels of both widths */

/* The kernels of the chain (the normal law, the dashpots, the shear spring
 * and its Coulomb cap, the rolling spring and its cap, the rolling dashpot)
 * are written once, in laws_lanes.h, on an abstract real BAL_R with a few
 * lane operations, and
 * compiled here twice: for one contact (BAL_R = double: bal_law_normal,
 * bal_law_shear, ...) and, where SSE2 exists (every x86-64), for two
 * (BAL_R = bal_v2, a GCC vector of two doubles: bal_law_normal_x2, ...).
 * The operations are IEEE's, lane by lane, so the two widths give the same
 * bits (-ffp-contract=off; core/tests/check_contacts.c holds every variant
 * of the loop to it), and an edit of a kernel moves both. */

/* One contact: the lane operations are the scalar ones. */
#define BAL_R double
#define BAL_M int                          /* a comparison's result */
#define BAL_KIN struct bal_kin
#define BAL_W(name) name                   /* the kernel's name at this width */
#define BAL_SPLAT(x) (x)                   /* a constant in every lane */
#define BAL_ANY(m) (m)                     /* is the mask set in some lane? */
#define BAL_SELECT(m, a, b) ((m) ? (a) : (b))
#define BAL_KEEP(m, x) ((m) ? (x) : 0.0)   /* x where the mask is set, else +0 */
#define BAL_DROP(m, x) ((m) ? 0.0 : (x))   /* +0 where the mask is set, else x */
#define BAL_ABS(x) fabs(x)
#define BAL_COPYSIGN(mag, sgn) copysign(mag, sgn)
#define BAL_SQRT(x) sqrt(x)
#define BAL_POW(x, e) pow(x, e)
#include "laws_lanes.h" /* undefines the names above at its end */

#if defined(__SSE2__)
#include <emmintrin.h>
#define BAL_X2 1 /* the two-lane kernels exist */

/* Two contacts: two doubles in one SSE2 register (GCC's vector extension:
 * + − × / and the comparisons act lane by lane; a comparison gives a mask
 * of all-ones or zero per lane). */
typedef __m128d bal_v2;
typedef long long bal_v2m __attribute__((vector_size(16)));

/* The kinematics of two touching contacts (struct bal_kin, lane by lane). */
struct bal_kin_x2 {
    bal_v2 delta, ndot, sdot;
};

static inline bal_v2 bal_v2_splat(double x) { return (bal_v2){x, x}; }
/* the mask's lanes as bits 0 and 1 of an int, and whether any is set */
static inline int bal_v2_bits(bal_v2m m) { return _mm_movemask_pd((__m128d)m); }
static inline int bal_v2_any(bal_v2m m) { return bal_v2_bits(m) != 0; }
static inline bal_v2 bal_v2_select(bal_v2m m, bal_v2 a, bal_v2 b)
{
    return (bal_v2)((m & (bal_v2m)a) | (~m & (bal_v2m)b));
}
/* x where m is set, +0 (all bits clear) elsewhere; and the other way round */
static inline bal_v2 bal_v2_keep(bal_v2m m, bal_v2 x) { return (bal_v2)(m & (bal_v2m)x); }
static inline bal_v2 bal_v2_drop(bal_v2m m, bal_v2 x) { return _mm_andnot_pd((__m128d)m, x); }
static inline bal_v2m bal_v2_sign(void) { return (bal_v2m)bal_v2_splat(-0.0); }
static inline bal_v2 bal_v2_abs(bal_v2 x) { return (bal_v2)(~bal_v2_sign() & (bal_v2m)x); }
/* |mag| with the sign of sgn, as copysign */
static inline bal_v2 bal_v2_copysign(bal_v2 mag, bal_v2 sgn)
{
    return (bal_v2)((~bal_v2_sign() & (bal_v2m)mag) | (bal_v2_sign() & (bal_v2m)sgn));
}
static inline bal_v2 bal_v2_sqrt(bal_v2 x) { return _mm_sqrt_pd(x); }
static inline bal_v2 bal_v2_pow(bal_v2 x, double e) { return (bal_v2){pow(x[0], e), pow(x[1], e)}; }

#define BAL_R bal_v2
#define BAL_M bal_v2m
#define BAL_KIN struct bal_kin_x2
#define BAL_W(name) name##_x2
#define BAL_SPLAT(x) bal_v2_splat(x)
#define BAL_ANY(m) bal_v2_any(m)
#define BAL_SELECT(m, a, b) bal_v2_select(m, a, b)
#define BAL_KEEP(m, x) bal_v2_keep(m, x)
#define BAL_DROP(m, x) bal_v2_drop(m, x)
#define BAL_ABS(x) bal_v2_abs(x)
#define BAL_COPYSIGN(mag, sgn) bal_v2_copysign(mag, sgn)
#define BAL_SQRT(x) bal_v2_sqrt(x)
#define BAL_POW(x, e) bal_v2_pow(x, e)
#include "laws_lanes.h" /* undefines the names above at its end */
#endif /* __SSE2__ */

/* ---------------------------------------------------------------- normal */

/* bal_law_power_force (k_n δ0 (δ/δ0)^ν) and bal_law_normal (F_n at t_N):
 * laws_lanes.h, below. */

/* The energy the normal spring stores: F_n²/(2 k_n) for the incremental law,
 * ∫ F_n dδ = k_n δ0² (δ/δ0)^(ν+1)/(ν+1) for the power law. */
static inline double bal_law_normal_energy(const struct bal_law_params *P,
                                           const struct bal_pair_law *L, double fn, double delta)
{
    if (P->normal_law == BAL_NORMAL_INCREMENTAL)
        return fn * fn / (2 * L->kn);
    return L->kn * P->delta0 * P->delta0 * pow(delta / P->delta0, P->nu + 1) / (P->nu + 1);
}

/* The normal spring's tangent stiffness dF_n/dδ at δ/δ0 = ratio: k_n for the
 * incremental law and the linear power law, ν k_n (δ/δ0)^(ν−1) otherwise.
 * The stress servo's gain (walls.c) and the step estimate (timestep.c). */
static inline double bal_law_normal_stiffness(const struct bal_law_params *P,
                                              const struct bal_pair_law *L, double ratio)
{
    if (P->normal_law != BAL_NORMAL_POWER || P->nu == 1.0)
        return L->kn;
    return P->nu * L->kn * pow(ratio, P->nu - 1);
}

/* --------------------------------------------------------------- damping */

/* bal_law_viscous (γ_n (δ/δ0)^ψ), bal_law_dashpot_coef (μ_n = c_n + γ_n
 * (δ/δ0)^ψ) and bal_law_shear_dashpot_of: laws_lanes.h, above. */

/* D_n = (c_n + γ_n (δ/δ0)^ψ) ṅ. */
static inline double bal_law_normal_dashpot(const struct bal_law_params *P,
                                            const struct bal_pair_law *L, const struct bal_kin *k)
{
    return bal_law_dashpot_coef(P, L, k->delta) * k->ndot;
}

/* D_s = c_s ṡ.  It acts only while the contact does not slide (C&S p. 52):
 * the callers run it after the tangential kernel, and only when that left
 * the contact unflagged (so a sliding contact's F_s is not even added a
 * zero, which would turn its −0 into +0). */
static inline double bal_law_shear_dashpot(const struct bal_pair_law *L, const struct bal_kin *k)
{
    return bal_law_shear_dashpot_of(L, k, 0);
}

/* ------------------------------------------------------------ tangential */

/* F_s at t_N from its history fs_prev, capped at the Coulomb limit of the
 * elastic F_n (eq. 19): bal_law_shear (laws_lanes.h, below), with the slip's
 * loss F_max (|F_s| − F_max)/k_s added to *lost and the contact flagged
 * sliding where the cap acts. */
static inline double bal_law_tangential(const struct bal_law_params *P,
                                        const struct bal_pair_law *L, const struct bal_kin *k,
                                        double fn, double fs_prev, double *lost, uint8_t *flags)
{
    double loss;
    int slid;
    const double fs = bal_law_shear(P, L, k, fn, fs_prev, &loss, &slid);
    if (slid) {
        *lost += loss;
        *flags |= BAL_PAIR_SLIDING;
    }
    return fs;
}

/* The energy the shear spring stores, F_s²/(2 k_s) (a pair without a shear
 * force has F_s = 0). */
static inline double bal_law_shear_energy(const struct bal_pair_law *L, double fs)
{
    return L->ks > 0 ? fs * fs / (2 * L->ks) : 0;
}

/* --------------------------------------------------------------- rolling */

/* struct bal_roll (B, K_m), bal_law_roll_of, bal_law_common_radius, and the
 * kernels bal_law_roll_moment and bal_law_roll_dashpot: laws_lanes.h, above.
 * M_0 = F_n B/6 (JYH eq. 33) and μ_m = μ_n B²/12 (eq. 49c) are computed in
 * the kernels. */

/* The elastic rolling moment M at t_N (bal_law_roll_moment) of one contact,
 * with its flags: a contact flagged BROKEN (Model 2) carries no moment; one
 * capped is flagged ROLLING (Model 1: its loss to plastic rolling added to
 * *lost) or BROKEN (Model 2: its spring's energy M²/(2 K_m) added). */
static inline double bal_law_rolling(const struct bal_law_params *P, struct bal_roll R, double fn,
                                     double dtheta, double m_prev, double *lost, uint8_t *flags)
{
    double loss;
    int capped;
    const double m = bal_law_roll_moment(P, R, fn, dtheta, m_prev, !(*flags & BAL_PAIR_BROKEN),
                                         &loss, &capped);
    if (capped) {
        *lost += loss;
        *flags |= P->rolling_model == BAL_ROLLING_MODEL2 ? BAL_PAIR_BROKEN : BAL_PAIR_ROLLING;
    }
    return m;
}

/* The rolling dashpot's moment M_d = μ_m θ̇_r (bal_law_roll_dashpot) of one
 * contact at overlap δ, with its flags after the rolling kernel (none if
 * BROKEN). */
static inline double bal_law_rolling_dashpot(const struct bal_law_params *P,
                                             const struct bal_pair_law *L, struct bal_roll R,
                                             double delta, double theta_dot, uint8_t flags)
{
    return bal_law_roll_dashpot(bal_law_dashpot_coef(P, L, delta), R, theta_dot,
                                !(flags & BAL_PAIR_BROKEN));
}

/* The energy the rolling spring stores, M²/(2 K_m). */
static inline double bal_law_rolling_energy(struct bal_roll R, double m)
{
    return R.km > 0 ? m * m / (2 * R.km) : 0;
}

#endif /* BAL_LAWS_H */
