/*
 * pair_loop.h — internal: the force–displacement law at every disc–disc
 * contact (pair_loop.c).
 */
#ifndef BAL_PAIR_LOOP_H
#define BAL_PAIR_LOOP_H

#include "state.h"

/* The disc–disc loop compiled for this normal law (enum bal_normal_law),
 * with or without the tangential, the damping and the rolling kernels
 * (laws.h); chosen once per simulation (s->pair_loop).  Each call runs one
 * cycle's contacts: it starts every disc's force sums from zero and adds
 * the contacts' forces, updates their history and adds their losses to the
 * energy audit. */
bal_pair_loop_fn bal_pair_loop_select(int normal_law, int shear, int damping, int rolling);

#endif /* BAL_PAIR_LOOP_H */
