/*
 * walls.h — internal: straight rigid walls, their geometry, their motion
 * and the controllers that drive them (walls.c).
 */
#ifndef BAL_WALLS_H
#define BAL_WALLS_H

#include <stddef.h>

#include "state.h"

/* Closest point of wall w to (x, y); returns squared distance.  Inline: the
 * disc–wall loop calls it at every candidate of every cycle (wall_loop.c). */
static inline double bal_walls_closest(const struct bal_wall *w, double x, double y, double *cx,
                                       double *cy)
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
/* The overlap of a disc of radius r at (x, y) with wall w: r less the
 * distance to the wall's closest point (negative: a gap). */
double bal_walls_overlap(const struct bal_wall *w, double x, double y, double r);
/* Unit normal from (x, y) to the closest point of wall w (the wall's own
 * normal when the point lies on it); returns the distance. */
double bal_walls_normal(const struct bal_wall *w, double x, double y, double *ex, double *ey);
/* Index of the wall named `name`, or -1. */
int bal_walls_find(const struct bal_sim *s, const char *name);
/* Move every wall by its velocity over one time step (eq. 22a for P and α). */
void bal_walls_move(struct bal_sim *s);

/* A wall's controller: how a stage drives the wall, chosen by the stage key
 * that names it (the table in walls.c, indexed by enum bal_wall_control).
 * `check` (may be NULL) refuses parameters it cannot work with, writing why
 * into msg (bal_scene_validate names the line and key); `start` takes the
 * parameters of the stage's line (w->move) when the stage begins, the other
 * walls the line names resolved in w->other; `control`, unless NULL, runs in
 * every cycle once the cycle's wall forces are known, and sets the velocity
 * of the wall's next move. */
struct bal_wall_controller_type {
    const char *name;
    int (*check)(const struct bal_move_def *mv, char *msg, size_t size);
    void (*start)(struct bal_sim *s, struct bal_wall *w);
    void (*control)(struct bal_sim *s, struct bal_wall *w);
};

/* Does the controller of line mv refuse its parameters?  1 with the reason
 * in msg, else 0 (bal_scene_validate). */
int bal_walls_check(const struct bal_move_def *mv, char *msg, size_t size);
/* The distance from wall a to the midpoint of wall b, along a's normal (for
 * the parallel walls of a box, the distance between them); toward (may be
 * NULL) receives a's unit normal on b's side. */
double bal_walls_gap(const struct bal_wall *a, const struct bal_wall *b, double toward[2]);

/* How far any point of wall w moves in one time step dt with velocity
 * (vx, vy) of P and angular velocity omega about P: |V| dt + |ω| dt reach,
 * reach the farther end's distance from P (a bound: every point of a rigidly
 * moving segment moves by at most what its farther end moves). */
double bal_walls_step(const struct bal_wall *w, double vx, double vy, double omega, double dt);

/* What a wall's run-time guard found (state.h: wall_fault_kind). */
enum bal_wall_fault {
    BAL_WALL_FAULT_STEP = 1, /* its controller set a step beyond the limit */
    BAL_WALL_FAULT_SPAN      /* its servo's span closed below the smallest radius */
};
/* Once the time step is known (bal_sim_create): refuse, naming FILE:LINE:
 * KEY of the stage's line, a wall whose step in one cycle would exceed
 * BAL_WALL_STEP_SHARE of the smallest disc radius (prescribed |V| dt + |ω|
 * dt reach, servo vmax dt, strain_rate |rate| dt gap), and a servo whose span
 * is below the smallest disc radius; the last two only where the walls
 * involved are where the scene put them when the stage begins (no earlier
 * stage names them).  The run-time guard covers the rest. */
enum bal_status bal_walls_check_steps(const struct bal_sim *s, struct bal_error *err);
/* The error of a tripped run-time guard (s->wall_fault): BAL_EUNSTABLE,
 * naming the wall, the step and the stage's line. */
enum bal_status bal_walls_fault(const struct bal_sim *s, struct bal_error *err);

/* Stage g begins: each wall it names gets its controller and parameters;
 * the others are at rest, with none. */
void bal_walls_stage(struct bal_sim *s, const struct bal_stage_def *g);
/* After the wall forces of the cycle (bal_wall_loop_run) and the audit of
 * the walls' work (bal_energy_walls): every controller that acts per cycle
 * sets its wall's velocity for the next cycle. */
void bal_walls_control(struct bal_sim *s);

#endif /* BAL_WALLS_H */
