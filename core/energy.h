/*
 * energy.h — internal: the energy audit of a run and the guards that stop
 * it (energy.c).
 */
#ifndef BAL_ENERGY_H
#define BAL_ENERGY_H

#include "state.h"

/* Take the baseline of the audit (after the first cycle). */
void bal_energy_begin(struct bal_sim *s);
/* Add the walls' work of this cycle (after the wall loop). */
void bal_energy_walls(struct bal_sim *s);
/* Add the losses of global damping and of the contact dashpots in this
 * cycle (after the velocity update). */
void bal_energy_global(struct bal_sim *s);
void bal_energy_dashpots(struct bal_sim *s);
/* Around a cycle in which g_fac changes (before it moves the discs, after
 * the velocity update): the gravity's work in intervals of constant g_fac. */
void bal_energy_gravity_before(struct bal_sim *s);
void bal_energy_gravity(struct bal_sim *s);
/* BAL_EUNSTABLE naming the worst contact if an overlap exceeds the budget. */
enum bal_status bal_energy_overlap(const struct bal_sim *s, struct bal_error *err);
/* BAL_EUNSTABLE if the run created more energy than settings.energy_guard
 * times the energy that went through it. */
enum bal_status bal_energy_guard(const struct bal_sim *s, struct bal_error *err);

#endif /* BAL_ENERGY_H */
