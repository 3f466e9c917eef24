/*
 * exact.h — internal: the exact static solver for stiff frictionless
 * networks (Matuttis, Luding & Herrmann 2000, Sec. 4.2).
 *
 * For linear springs in the stiff limit (k_n → ∞, overlaps infinitesimal)
 * the static contact forces of a frictionless disc packing under gravity
 * follow from equilibrium and linear elasticity alone and do not depend on
 * the stiffness scale.  bal_exact_solve() takes the contact network of the
 * simulation's current positions (every disc–disc and disc–wall pair whose
 * gap is at most BAL_EXACT_TOUCH times the largest radius), and solves the
 * small-displacement equilibrium
 *
 *     K u = f,   K = Σ_c k_c b_c b_cᵀ,   f = m g on every free disc,
 *
 * with u the displacements (x, y) of the free discs (held discs and walls
 * do not move; frictionless discs carry no moment, so rotations drop out),
 * b_c the normal of contact c and k_c its normal stiffness from the
 * material table.  Only pairs with at least one free disc take part.
 * Contacts are unilateral: a closed contact that would carry tension is
 * opened and the system solved again, and an open contact whose bodies
 * would then overlap is closed again, until every closed contact is
 * compressive and no open one penetrates (an active-set iteration).  When
 * the active set repeats or K of the closed contacts is singular, the
 * solver continues with damped Newton steps on the convex energy
 * E(u) = ½ Σ k max(δ, 0)² − f·u (it falls at every step, so it cannot
 * cycle) and finishes with an exact solve.  K is banded when discs are
 * numbered row by row (the cell order of the simulation), and is
 * factorised with GSL's banded Cholesky.  Gravity is taken at full
 * strength (the ramp of a stage does not apply).
 */
#ifndef BAL_EXACT_H
#define BAL_EXACT_H

#include <stdint.h>

#include "state.h"

/* Two bodies count as touching in the reference lattice when their gap is
 * at most this share of the largest radius: lattices built from decimal
 * coordinates touch to within round-off, far below this. */
#define BAL_EXACT_TOUCH 1e-9

struct bal_exact_contact {
    int32_t i;          /* disc slot (array index in the simulation) */
    int32_t j;          /* disc slot, or wall index when is_wall */
    uint8_t is_wall;    /* 1: j is a wall */
    uint8_t open;       /* 1: opened by the unilateral iteration (fn = 0); a closed
                         * contact may also carry fn = 0 within round-off */
    double nx, ny;      /* unit normal from i to j */
    double fn;          /* normal force in the stiff limit, >= 0 */
};

struct bal_exact {
    long n_contacts;
    struct bal_exact_contact *contacts;   /* touching pairs, sorted by (i, is_wall, j) */
    long n_open;            /* contacts open in the solution */
    int iterations;         /* factorisations: active-set solves and damped steps */
    int bandwidth;          /* half-bandwidth of K in unknowns */
    double weight[2];       /* Σ m g over the free discs */
    double support[2];      /* Σ of the forces the free discs exert on held discs and walls */
    double residual;        /* max over free discs of |Σ forces + m g| / max |m g| */
    double seconds;         /* wall-clock time of the solve */
};

/* Solve for the current positions of s.  Refuses (BAL_EINVAL) a network
 * with friction or cohesion on any of its contacts, a power law with
 * nu != 1, a network that is a mechanism (K singular; the message names a
 * free disc), one that has no equilibrium without tension, or one whose
 * final network is a mechanism in neutral equilibrium.  Fills *out, which
 * bal_exact_free releases. */
enum bal_status bal_exact_solve(const struct bal_sim *s, struct bal_exact *out,
                                struct bal_error *err);
void bal_exact_free(struct bal_exact *e);

#endif /* BAL_EXACT_H */
