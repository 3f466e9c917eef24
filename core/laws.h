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
 *
 * A kernel takes the contact's kinematics (struct bal_kin), its pair law
 * (struct bal_pair_law) and its own slice of history, and returns a force;
 * it reads no simulation state, so the loop that calls it decides layout,
 * threads and accumulation.  The disc–disc loop (contacts.c) calls it in
 * variants compiled without the kernels a scene switches off, so a scene
 * without friction or damping never runs their code or touches their
 * history; the disc–wall loop calls every kernel (walls are few).
 *
 * Adding a sub-model: one kernel here (with the stored energy of its spring,
 * if it has one, for the audit), one history column in struct bal_pairs
 * (state.h) with its reserve/merge lines (pairs.c), and one switch: a flag
 * the disc–disc loop is specialised on (PAIR_VARIANT in contacts.c) and the
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
};

/* The parameters of the chain that do not depend on the pair. */
struct bal_law_params {
    int normal_law;        /* enum bal_normal_law */
    double nu, delta0;     /* power law (MLH eq. 2) */
    double gamma_n, psi;   /* viscous normal damping (MLH eq. 3) */
    double dt;             /* the time step: the incremental springs' Δt */
};

/* The kinematics of one touching contact at t_N. */
struct bal_kin {
    double delta;          /* overlap R_x + R_y − D (or R − distance for a wall) */
    double ndot;           /* ṅ, eq. (12) */
    double sdot;           /* ṡ, eq. (13): set only where the tangential kernel runs */
};

#define BAL_PAIR_TOUCHING 1u
#define BAL_PAIR_SLIDING 2u

/* ---------------------------------------------------------------- normal */

/* k_n δ0 (δ/δ0)^ν, with the common exponents written out (pow costs ten
 * times a product). */
static inline double bal_law_power_force(double kn, double delta, double delta0, double nu)
{
    if (nu == 1.0)
        return kn * delta;
    if (nu == 1.5)
        return kn * delta * sqrt(delta / delta0);
    if (nu == 2.0)
        return kn * delta * (delta / delta0);
    return kn * delta0 * pow(delta / delta0, nu);
}

/* F_n at t_N from its history fn_prev (incremental law) or from δ. */
static inline double bal_law_normal(const struct bal_law_params *P, const struct bal_pair_law *L,
                                    const struct bal_kin *k, double fn_prev)
{
    if (P->normal_law == BAL_NORMAL_INCREMENTAL) {
        const double fn = fn_prev + L->kn * k->ndot * P->dt;
        return fn < 0 ? 0 : fn;
    }
    return bal_law_power_force(L->kn, k->delta, P->delta0, P->nu);
}

/* The energy the normal spring stores: F_n²/(2 k_n) for the incremental law,
 * ∫ F_n dδ = k_n δ0² (δ/δ0)^(ν+1)/(ν+1) for the power law. */
static inline double bal_law_normal_energy(const struct bal_law_params *P,
                                           const struct bal_pair_law *L, double fn, double delta)
{
    if (P->normal_law == BAL_NORMAL_INCREMENTAL)
        return fn * fn / (2 * L->kn);
    return L->kn * P->delta0 * P->delta0 * pow(delta / P->delta0, P->nu + 1) / (P->nu + 1);
}

/* --------------------------------------------------------------- damping */

/* The coefficient γ_n (δ/δ0)^ψ of MLH eq. (3). */
static inline double bal_law_viscous(const struct bal_law_params *P, double delta)
{
    if (P->gamma_n == 0)
        return 0;
    if (P->psi == 0)
        return P->gamma_n;
    return P->gamma_n * pow(delta / P->delta0, P->psi);
}

/* D_n = (c_n + γ_n (δ/δ0)^ψ) ṅ. */
static inline double bal_law_normal_dashpot(const struct bal_law_params *P,
                                            const struct bal_pair_law *L, const struct bal_kin *k)
{
    return (L->cn + bal_law_viscous(P, k->delta)) * k->ndot;
}

/* D_s = c_s ṡ.  It acts only while the contact does not slide (C&S p. 52):
 * the callers run it after the tangential kernel, and only when that left
 * the contact unflagged (so a sliding contact's F_s is not even added a
 * zero, which would turn its −0 into +0). */
static inline double bal_law_shear_dashpot(const struct bal_pair_law *L, const struct bal_kin *k)
{
    return L->cs * k->sdot;
}

/* ------------------------------------------------------------ tangential */

/* F_s at t_N from its history fs_prev, capped at the Coulomb limit of the
 * elastic F_n (eq. 19).  A capped spring gives up (|F_s| − F_max)/k_s of
 * slip against F_max: added to *lost; the contact is flagged sliding. */
static inline double bal_law_tangential(const struct bal_law_params *P,
                                        const struct bal_pair_law *L, const struct bal_kin *k,
                                        double fn, double fs_prev, double *lost, uint8_t *flags)
{
    double fs = fs_prev + L->ks * k->sdot * P->dt;
    const double fmax = fn * L->tan_phi + L->cohesion;
    if (fabs(fs) > fmax) {
        *lost += fmax * (fabs(fs) - fmax) / L->ks;
        fs = copysign(fmax, fs);
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

#endif /* BAL_LAWS_H */
