/*
 * measure.h — internal: what a run reports of its state (measure.c).
 */
#ifndef BAL_MEASURE_H
#define BAL_MEASURE_H

#include "state.h"

/* The dashpot forces D_n, D_s of contact c of list p in the last cycle:
 * stored for walls, recomputed for disc pairs from the geometry at t_N and
 * the velocities v_{N-1/2} (recovered), exactly as the cycle computed them.
 * Zero for a contact that is not touching. */
void bal_measure_dashpots(const struct bal_sim *s, const struct bal_pairs *p, long c, double *dn,
                          double *ds);
/* The rolling dashpot's moment M_d of contact c of list p in the last cycle
 * (JYH eq. 49c): stored for walls, recomputed for disc pairs as the cycle
 * computed it; 0 without rolling resistance or damping. */
double bal_measure_rolling_dashpot(const struct bal_sim *s, const struct bal_pairs *p, long c);
/* The common radius of contact c (JYH eq. 9b; 2 r against a wall, eq. 11b). */
double bal_measure_common_radius(const struct bal_sim *s, int walls, const struct bal_pairs *p,
                                 long c);
/* Velocities of disc i at t_N (eq. 31), recovered after a cycle. */
void bal_measure_velocity(const struct bal_sim *s, int i, double *vx, double *vy, double *w);
/* Per disc, Σ_c f^c ⊗ l^c over its contacts (MLH eq. 8 without 1/V), into
 * m[4 i .. 4 i + 3] = xx, xz, zx, zz (z vertical). */
void bal_measure_moments(const struct bal_sim *s, double *m);
/* ΔF/F of C&S Tables 1–3 (bal_measure_unbalanced), and in *largest the F
 * it divides by: the largest contact force.  With no contact carrying force
 * (*largest = 0) the ratio is undefined and 0 is returned, as the probe
 * `unbalanced` writes it; an equilibrium rule must read *largest (sim.c). */
double bal_measure_unbalanced_of(const struct bal_sim *s, double *largest);
/* The volume V_i of MLH eq. (8) for one disc: the hexagonal cell of a disc of
 * its size in a triangular packing, 2 sqrt(3) r^2. */
double bal_measure_disc_volume(double r);
/* The energy stored by the normal spring of a contact with pair law L:
 * F_n²/(2 k_n) for the incremental law, ∫ F_n dδ at overlap δ for the power law. */
double bal_measure_normal_energy(const struct bal_sim *s, const struct bal_pair_law *L, double fn,
                                 double delta);

#endif /* BAL_MEASURE_H */
