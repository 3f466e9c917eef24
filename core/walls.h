/*
 * walls.h — internal: straight rigid walls, their geometry and their motion
 * (walls.c).
 */
#ifndef BAL_WALLS_H
#define BAL_WALLS_H

#include "state.h"

/* Closest point of wall w to (x, y); returns squared distance. */
double bal_walls_closest(const struct bal_wall *w, double x, double y, double *cx, double *cy);
/* Unit normal from (x, y) to the closest point of wall w (the wall's own
 * normal when the point lies on it); returns the distance. */
double bal_walls_normal(const struct bal_wall *w, double x, double y, double *ex, double *ey);
/* Index of the wall named `name`, or -1. */
int bal_walls_find(const struct bal_sim *s, const char *name);
/* Move every wall by its velocity over one time step (eq. 22a for P and α). */
void bal_walls_move(struct bal_sim *s);

#endif /* BAL_WALLS_H */
