/*
 * wall_loop.h — internal: the force–displacement law at every disc–wall
 * contact (wall_loop.c).
 */
#ifndef BAL_WALL_LOOP_H
#define BAL_WALL_LOOP_H

#include "state.h"

/* The disc–wall contacts of the cycle: their forces on the discs' sums
 * (after the disc–disc loop started them), their history, and the
 * resultants on the walls (struct bal_wall: f, moment, fn_sum, fn_s_sum;
 * dash_f, dash_m and stiffness while a controller acts every cycle). */
void bal_wall_loop_run(struct bal_sim *s);

#endif /* BAL_WALL_LOOP_H */
