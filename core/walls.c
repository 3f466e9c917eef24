/*
 * walls.c — straight rigid walls (Cundall & Strack, Fig. 4 and p. 53): their
 * geometry, their motion, and the controllers that set that motion.
 *
 * A wall is the segment from A = P + h1 e to B = P + h2 e with
 * e = (cos α, sin α).  P moves with velocity V and the wall turns about P
 * with angular velocity ω; positions advance like the discs' (eq. 22a):
 * P_{N+1} = P_N + V Δt, α_{N+1} = α_N + ω Δt.
 *
 * A disc touches a wall when the distance from its centre to the closest
 * point of the segment is less than its radius; the closest point is the
 * foot of the perpendicular on the interior, or an end point beyond the
 * ends, so discs also collide with the wall's corners.  Walls are two-sided.
 *
 * Controllers.  Each stage of the loading protocol drives the walls it
 * names through a controller from the table at the end of this file (a
 * struct bal_wall_controller_type, chosen by the stage key that names the
 * wall, as settings.integrator chooses a law of motion).  When the stage
 * begins, `start` takes the parameters of the wall's line; a wall the stage
 * does not name is at rest and has no controller.  In every cycle, once
 * the discs' forces on the walls are known (bal_contacts_walls) and the
 * audit has priced this cycle's wall motion with the velocity it moved with
 * (bal_energy_walls), bal_walls_control lets each controller with a
 * `control` function set its wall's V and ω for the next cycle; the next
 * cycle moves the wall with them (bal_walls_move), which also adds the
 * displacement the neighbour lists watch.
 *
 *   prescribed  `move = WALL v1 v2 omega`: V = (v1, v2) and ω as given, for
 *               the whole stage (C&S's strain control); nothing per cycle.
 *
 * A new controller (a servo on a target stress, a strain rate) is added
 * without touching the cycle:
 *   1. a value of enum bal_wall_control and its parameters as fields of
 *      struct bal_move_def (ballast.h), consecutive doubles in the order its
 *      key takes them;
 *   2. its stage key: a row of type BAL_KEY_CONTROL in scene_keys.c, whose
 *      `choices` is its form ("WALL sigma gain vmax") and `offset` where
 *      its first number goes, and the key's line in bal_scene_controls
 *      there, naming the enum value; the parser, the "one line per wall and
 *      stage" rule, --set and `ballast keys` follow from the row;
 *   3. its entry in the table below and its functions: `start` takes the
 *      parameters from w->move, `control` sets w->v and w->omega from the
 *      wall's resultant of this cycle (w->f, w->moment, w->fn_sum), its
 *      state (w->p, w->alpha) and the simulation's (s->dt, the other
 *      walls).  Per-wall state it keeps between cycles is a field of
 *      struct bal_wall (state.h).
 * Walls that never move pay nothing: the stage leaves them without a
 * controller, bal_walls_move skips a wall at rest, and a stage in which no
 * controller acts per cycle (s->walls_controlled = 0) skips the pass.
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

/* ------------------------------------------------------------------ */
/* Controllers                                                         */
/* ------------------------------------------------------------------ */

/* prescribed: the velocity of the stage's line, for the whole stage. */
static void prescribed_start(struct bal_wall *w, const struct bal_move_def *mv)
{
    w->v[0] = mv->v[0];
    w->v[1] = mv->v[1];
    w->omega = mv->omega;
}

static const struct bal_wall_controller_type controllers[] = {
    [BAL_CONTROL_PRESCRIBED] = {"prescribed", prescribed_start, NULL},
};

void bal_walls_stage(struct bal_sim *s, const struct bal_stage_def *g)
{
    for (int k = 0; k < s->n_walls; k++) {
        struct bal_wall *w = &s->walls[k];
        w->v[0] = w->v[1] = 0;
        w->omega = 0;
        w->controller = NULL;
        w->move = NULL;
    }
    for (int m = 0; m < g->n_moves; m++) {
        const struct bal_move_def *mv = &g->moves[m];
        const int k = bal_walls_find(s, mv->wall);
        const int c = mv->control;
        if (k < 0 || c < 0 || c >= (int)(sizeof controllers / sizeof controllers[0]))
            continue; /* refused by bal_scene_validate; the parser sets only known ones */
        struct bal_wall *w = &s->walls[k];
        w->controller = &controllers[c];
        w->move = mv;
        w->controller->start(w, mv);
    }
    s->walls_controlled = 0;
    for (int k = 0; k < s->n_walls; k++)
        s->walls_controlled += s->walls[k].controller && s->walls[k].controller->control;
}

void bal_walls_control(struct bal_sim *s)
{
    if (!s->walls_controlled)
        return; /* no wall of this stage changes its velocity as it goes */
    for (int k = 0; k < s->n_walls; k++) {
        struct bal_wall *w = &s->walls[k];
        if (w->controller && w->controller->control)
            w->controller->control(s, w);
    }
}
