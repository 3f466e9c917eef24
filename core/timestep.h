/*
 * timestep.h — internal: the critical time-step estimate (timestep.c).
 */
#ifndef BAL_TIMESTEP_H
#define BAL_TIMESTEP_H

#include "state.h"

/* The step used by dt_fraction: the leapfrog limit for a bound on the
 * largest eigenfrequency of the contact network at the start. */
double bal_timestep_estimate(const struct bal_sim *s);
/* C&S p. 53: 2 sqrt(m/k) of the stiffest single spring, for comparison. */
double bal_timestep_single_spring(const struct bal_sim *s);
/* Both, and how the estimate was reached (bal_sim_dt_detail, `ballast info`). */
void bal_timestep_detail(const struct bal_sim *s, struct bal_dt_detail *d);

#endif /* BAL_TIMESTEP_H */
