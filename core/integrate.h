/*
 * integrate.h — internal: the law of motion, three ways, as a table of
 * types chosen by settings.integrator (integrate.c).
 */
#ifndef BAL_INTEGRATE_H
#define BAL_INTEGRATE_H

#include "state.h"

/* A law of motion, chosen once by settings.integrator.  A cycle calls
 * `positions` before the force evaluation (it returns how far the discs
 * have moved since the lists were built) and `velocities` after it; `previous` gives the velocities the contact law read in the last
 * cycle (for recomputing dashpot forces).  `staggered`: after a cycle the
 * stored velocities are v_{N+1/2}, so measurements at t_N average them with
 * `previous` (C&S eq. 31); otherwise the stored velocities are v_N. */
struct bal_integrator_type {
    const char *name;
    struct bal_moves (*positions)(struct bal_sim *s);
    void (*velocities)(struct bal_sim *s);
    void (*previous)(const struct bal_sim *s, int i, double *vx, double *vy, double *w);
    int staggered;
};

/* Set s->integ from the scene and reserve what it needs (gear5: its
 * derivative columns); after the discs exist. */
enum bal_status bal_integrate_setup(struct bal_sim *s, struct bal_error *err);
void bal_integrate_free(struct bal_sim *s);
/* After bal_grid_reorder: carry the integrator's per-disc columns along the
 * permutation s->new2old. */
void bal_integrate_reordered(struct bal_sim *s);
/* Per-disc columns of gear5: scaled derivatives r2..r5 of x, y, θ (12), the
 * predicted velocities the contact law read (3), one scratch column. */
#define BAL_GEAR_COLUMNS 16
/* The two halves of the law of motion of s->integ (one dispatch each); the
 * first returns how far the discs have moved since the lists were built. */
struct bal_moves bal_integrate_positions(struct bal_sim *s);
void bal_integrate_velocities(struct bal_sim *s);
/* The velocities of disc i that the contact law read in the last cycle:
 * centred and verlet v_{N-1/2} (recovered from the stored velocities and
 * the force sums by inverting the last update), gear5 the predicted v_N. */
void bal_integrate_previous(const struct bal_sim *s, int i, double *vx, double *vy, double *w);

#endif /* BAL_INTEGRATE_H */
