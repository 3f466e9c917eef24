/*
 * walls.c — straight rigid walls under strain control (Cundall & Strack,
 * Fig. 4 and p. 53).
 *
 * A wall is the segment from A = P + h1 e to B = P + h2 e with
 * e = (cos α, sin α).  Its motion is prescribed: P moves with velocity V and
 * the wall turns about P with angular velocity ω; the current stage of the
 * loading protocol sets V and ω.  Positions advance like the discs'
 * (eq. 22a): P_{N+1} = P_N + V Δt, α_{N+1} = α_N + ω Δt.
 *
 * A disc touches a wall when the distance from its centre to the closest
 * point of the segment is less than its radius; the closest point is the
 * foot of the perpendicular on the interior, or an end point beyond the
 * ends, so discs also collide with the wall's corners.  Walls are two-sided.
 */
#include <math.h>
#include <string.h>

#include "walls.h"

double bal_walls_closest(const struct bal_wall *w, double x, double y,
                         double *cx, double *cy)
{
    const double rx = x - w->p[0], ry = y - w->p[1];
    double h = rx * w->e[0] + ry * w->e[1];
    if (h < w->h1)
        h = w->h1;
    else if (h > w->h2)
        h = w->h2;
    *cx = w->p[0] + h * w->e[0];
    *cy = w->p[1] + h * w->e[1];
    const double dx = x - *cx, dy = y - *cy;
    return dx * dx + dy * dy;
}

int bal_walls_find(const struct bal_sim *s, const char *name)
{
    for (int k = 0; k < s->n_walls; k++)
        if (strcmp(s->walls[k].name, name) == 0)
            return k;
    return -1;
}

void bal_walls_move(struct bal_sim *s)
{
    const double dt = s->dt;
    for (int k = 0; k < s->n_walls; k++) {
        struct bal_wall *w = &s->walls[k];
        if (w->v[0] == 0 && w->v[1] == 0 && w->omega == 0)
            continue;
        w->p[0] += w->v[0] * dt;
        w->p[1] += w->v[1] * dt;
        if (w->omega != 0) {
            w->alpha += w->omega * dt;
            w->e[0] = cos(w->alpha);
            w->e[1] = sin(w->alpha);
        }
        /* Every point of a rigidly moving segment moves by at most what its
         * farther end moves, so this bounds the wall's displacement. */
        const double hmax = fmax(fabs(w->h1), fabs(w->h2));
        w->disp += hypot(w->v[0], w->v[1]) * dt + fabs(w->omega) * hmax * dt;
    }
}

double bal_walls_normal(const struct bal_wall *w, double x, double y, double *ex, double *ey)
{
    double cx, cy;
    const double d = sqrt(bal_walls_closest(w, x, y, &cx, &cy));
    if (d > 0) {
        *ex = (cx - x) / d;
        *ey = (cy - y) / d;
    } else {
        /* Centre exactly on the wall: along the wall's normal. */
        *ex = -w->e[1];
        *ey = w->e[0];
    }
    return d;
}
