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
 * the discs' forces on the walls are known (bal_wall_loop_run) and the
 * audit has priced this cycle's wall motion with the velocity it moved with
 * (bal_energy_walls), bal_walls_control lets each controller with a
 * `control` function set its wall's V and ω for the next cycle; the next
 * cycle moves the wall with them (bal_walls_move), which also adds the
 * displacement the neighbour lists watch.
 *
 * Two walls A and B are `gap` = |(M_B − P_A)·n_A| apart, M_B the midpoint of
 * B and n_A = (−e2, e1) the normal of A: for the parallel walls of a box,
 * the distance between them.  A wall moves along its normal only: the
 * servo and the strain rate set V = speed × `toward` and leave ω = 0.
 *
 *   prescribed   `move = WALL v1 v2 omega`: V = (v1, v2) and ω as given,
 *                for the whole stage (C&S's strain control); nothing per
 *                cycle.
 *
 *   servo        `servo = WALL sigma gain vmax WALL_A WALL_B`: holds the
 *                normal stress σ_t = sigma (force per unit length per unit
 *                thickness, compression positive).  The wall's direction
 *                `toward` is its normal on the side of the discs' centroid
 *                when the stage begins.  In each cycle it measures
 *                  σ = −F·toward / L,  L = gap(WALL_A, WALL_B)
 *                (F the force of the discs' contact springs on it, without
 *                the dashpots' share: see below; the span L is the length
 *                of specimen it bears on: the left wall's is the distance
 *                between the top and bottom walls) and moves towards the
 *                discs with the speed
 *                  v = α (σ_t − σ) L / (K Δt),   |v| ≤ vmax,
 *                K = Σ k_n of its touching contacts (the tangent stiffness
 *                ν k_n (δ/δ0)^(ν−1) under the power law, laws.h), summed by
 *                the wall loop (wall_loop.c) with the force.  A wall with no
 *                contact (K = 0, σ = 0) approaches at vmax; vmax = 0 takes
 *                BAL_SERVO_CAP_SHARE of the smallest radius per step.
 *                Stability.  Take the wall as a massless controller on
 *                springs of total stiffness K whose other ends (the discs)
 *                stay put within a cycle: moving v Δt changes the force by
 *                K v Δt, the stress by α (σ_t − σ_N), so the error
 *                e_N = σ_t − σ_N obeys
 *                  e_{N+1} = (1 − α) e_N:
 *                it decays for 0 < α < 2 (|1 − α| < 1; refused otherwise),
 *                without changing sign (no overshoot) for α ≤ 1, and α = 1
 *                removes it in one cycle.  The discs' inertia breaks the
 *                "stay put": pushed, they move away over the packing's own
 *                period, many cycles long, so the force the wall feels
 *                relaxes and the servo follows the discs rather than
 *                overshooting them.  Two consequences: the error of the
 *                specimen as a whole decays more slowly than (1 − α)^N (the
 *                wall's contacts are in series with the packing, whose
 *                stiffness is smaller than K), and the wall's stress then
 *                oscillates with the discs (their kinetic energy, not the
 *                controller's): only damping (settings.alpha, beta) settles
 *                it.  0 < α < 2 is thus necessary, not sufficient; α ≤ 1
 *                keeps the controller itself from overshooting, and the
 *                check_walls tests hold a damped column to its closed form.
 *                Contact dashpots answer the wall's velocity within the
 *                cycle: c_n ṅ changes by c_n Δv, α c_n/(K Δt) = α β/Δt
 *                times the error, 35 for JYH's stiffness with β = 2e-5 at
 *                Δt = 2.8e-7; measured with them, the servo swings between
 *                its caps.  So σ is the springs' force (f − dash_f), which
 *                is the whole force once the specimen is at rest; the
 *                dashpots then damp the wall's contacts like any other.
 *                The energy audit prices the dashpots' loss with the wall's
 *                centred velocity (bal_walls_control).
 *
 *   strain_rate  `strain_rate = WALL rate WALL_TO`: moves along its normal
 *                towards WALL_TO (rate > 0; away for rate < 0) at the speed
 *                rate × gap(WALL, WALL_TO): the logarithmic strain rate of
 *                JYH Sec. 5.1, "the ratio of change of specimen height to
 *                its current height during each incremental time".  With
 *                WALL_TO at rest, in continuous time gap(t) = gap_0 e^{−rate t};
 *                the explicit update moves the wall by the speed of the
 *                cycle before, so gap_{N+1} = gap_N (1 − rate Δt) and
 *                gap_N = gap_0 (1 − rate Δt)^N = gap_0 e^{−rate t_N} (1 −
 *                N (rate Δt)²/2 + ...), refused for rate Δt >= 1.  Two
 *                facing walls each at rate/2 give the symmetric test (their
 *                gap then shrinks by (1 − rate Δt) per cycle too).
 *
 * A new controller is added without touching the cycle:
 *   1. a value of enum bal_wall_control and its parameters as fields of
 *      struct bal_move_def (ballast.h), consecutive doubles in the order its
 *      key takes them;
 *   2. its stage key: a row of type BAL_KEY_CONTROL in scene_keys.c, whose
 *      `choices` is its form ("WALL sigma gain vmax WALL_A WALL_B": after
 *      the first, a word that starts with WALL names another wall, the
 *      others are numbers) and `offset` where its first number goes, and
 *      the key's line in bal_scene_controls there, naming the enum value;
 *      the parser, the "one line per wall and stage" rule, the check that
 *      the walls it names exist, --set and `ballast keys` follow from the
 *      row;
 *   3. its entry in the table below and its functions: `check` refuses bad
 *      parameters (at validation, with the line's key), `start` takes them
 *      from w->move when the stage begins (the other walls are resolved in
 *      w->other), `control` sets w->v and w->omega from the wall's
 *      resultant of this cycle (w->f, w->moment, w->fn_sum, w->stiffness:
 *      wall_loop.c), its state (w->p, w->alpha) and the simulation's
 *      (s->dt, the other walls, the contacts).  Per-wall state it keeps between cycles is a field of
 *      struct bal_wall (state.h).
 * Walls that never move pay nothing: the stage leaves them without a
 * controller, bal_walls_move skips a wall at rest, and a stage in which no
 * controller acts per cycle (s->walls_controlled = 0) skips the pass.
 */
#include <math.h>
#include <stdio.h>
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

double bal_walls_overlap(const struct bal_wall *w, double x, double y, double r)
{
    double cx, cy;
    return r - sqrt(bal_walls_closest(w, x, y, &cx, &cy));
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
static void prescribed_start(struct bal_sim *s, struct bal_wall *w)
{
    (void)s;
    w->v[0] = w->move->v[0];
    w->v[1] = w->move->v[1];
    w->omega = w->move->omega;
}

double bal_walls_gap(const struct bal_wall *a, const struct bal_wall *b, double toward[2])
{
    const double mid = 0.5 * (b->h1 + b->h2);
    const double mx = b->p[0] + mid * b->e[0], my = b->p[1] + mid * b->e[1];
    const double nx = -a->e[1], ny = a->e[0];
    const double d = (mx - a->p[0]) * nx + (my - a->p[1]) * ny;
    if (toward) {
        toward[0] = d < 0 ? -nx : nx;
        toward[1] = d < 0 ? -ny : ny;
    }
    return fabs(d);
}

/* The speed along `toward` at which a servo's cap is set when its line
 * gives vmax = 0: this share of the smallest radius per time step.  A wall
 * that meets the discs at this speed overlaps them by at most that much in
 * the cycle before it reacts (0.1 % of a radius is 1/30 of the overlap of a
 * JYH contact at 400 kPa), and it crosses a gap of one radius in 1000
 * cycles. */
#define BAL_SERVO_CAP_SHARE 1e-3

/* servo: the stress its contacts bear over its span, and the speed that
 * removes the share `gain` of the error in one cycle (the header).  K is
 * w->stiffness: in every cycle of the stage the wall loop's (wall_loop.c),
 * which visits each of the wall's contacts anyway; when the stage begins,
 * contact_stiffness's. */
static void servo_control(struct bal_sim *s, struct bal_wall *w)
{
    const struct bal_move_def *mv = w->move;
    const double span = bal_walls_gap(&s->walls[w->other[0]], &s->walls[w->other[1]], NULL);
    /* The springs' force: the dashpots' share answers the wall's velocity
     * within the cycle (the header), and vanishes at rest. */
    const double force = -((w->f[0] - w->dash_f[0]) * w->toward[0] +
                           (w->f[1] - w->dash_f[1]) * w->toward[1]);
    const double stiffness = w->stiffness;
    w->stress = span > 0 ? force / span : 0;
    w->stress_error = fabs(w->stress - mv->sigma) / mv->sigma;
    double speed = w->vcap; /* no contact: approach at the cap */
    if (stiffness > 0)
        speed = mv->gain * (mv->sigma - w->stress) * span / (stiffness * s->dt);
    speed = fmax(-w->vcap, fmin(w->vcap, speed));
    w->v[0] = speed * w->toward[0];
    w->v[1] = speed * w->toward[1];
    w->omega = 0;
}

/* Σ dF_n/dδ of wall w's touching contacts (flagged by the last wall loop),
 * at their overlaps now, in the list's order, as the wall loop sums it: for
 * a servo's first speed, before any cycle of its stage has run the wall
 * loop with it. */
static double contact_stiffness(const struct bal_sim *s, const struct bal_wall *w)
{
    const int k = (int)(w - s->walls);
    const struct bal_law_params P = bal_law_params_of(s);
    const struct bal_pairs *p = &s->pw;
    double stiffness = 0;
    for (long c = 0; c < p->n; c++) {
        if (p->j[c] != k || !(p->flags[c] & BAL_PAIR_TOUCHING))
            continue;
        const int i = p->i[c];
        const double delta = bal_walls_overlap(w, s->x[i], s->y[i], s->r[i]);
        const struct bal_pair_law *L = &s->law[s->mat[i] * s->n_mat + w->material];
        stiffness += bal_law_normal_stiffness(&P, L, fmax(delta, 0) / P.delta0);
    }
    return stiffness;
}

static void servo_start(struct bal_sim *s, struct bal_wall *w)
{
    /* Towards the discs: the wall's normal on the side of their centroid. */
    double cx = 0, cy = 0;
    for (int i = 0; i < s->n; i++) {
        cx += s->x[i];
        cy += s->y[i];
    }
    cx /= s->n > 0 ? s->n : 1;
    cy /= s->n > 0 ? s->n : 1;
    const double nx = -w->e[1], ny = w->e[0];
    const double side = (cx - w->p[0]) * nx + (cy - w->p[1]) * ny;
    w->toward[0] = side < 0 ? -nx : nx;
    w->toward[1] = side < 0 ? -ny : ny;
    w->vcap = w->move->vmax > 0 ? w->move->vmax : BAL_SERVO_CAP_SHARE * s->r_min / s->dt;
    w->stress_error = INFINITY;
    w->stiffness = contact_stiffness(s, w);
    servo_control(s, w);
}

static int servo_check(const struct bal_move_def *mv, char *msg, size_t size)
{
    if (!(mv->sigma > 0))
        snprintf(msg, size, "the target stress sigma must be > 0, got %g", mv->sigma);
    else if (!(mv->gain > 0 && mv->gain < 2))
        snprintf(msg, size, "the gain must be in (0, 2) (the error of a cycle is (1 - gain) "
                            "times the last; <= 1 does not overshoot), got %g", mv->gain);
    else if (!(mv->vmax >= 0))
        snprintf(msg, size, "the speed cap vmax must be >= 0 (0: from the smallest radius), "
                            "got %g", mv->vmax);
    else if (strcmp(mv->walls[0], mv->walls[1]) == 0 || strcmp(mv->walls[0], mv->wall) == 0 ||
             strcmp(mv->walls[1], mv->wall) == 0)
        snprintf(msg, size, "the span is the distance between two other walls; got '%s' and "
                            "'%s' for wall '%s'", mv->walls[0], mv->walls[1], mv->wall);
    else
        return 0;
    return 1;
}

/* strain_rate: the speed rate × gap towards the other wall. */
static void strain_rate_control(struct bal_sim *s, struct bal_wall *w)
{
    const double gap = bal_walls_gap(w, &s->walls[w->other[0]], w->toward);
    const double speed = w->move->rate * gap;
    w->v[0] = speed * w->toward[0];
    w->v[1] = speed * w->toward[1];
    w->omega = 0;
}

static void strain_rate_start(struct bal_sim *s, struct bal_wall *w)
{
    strain_rate_control(s, w);
}

static int strain_rate_check(const struct bal_move_def *mv, char *msg, size_t size)
{
    if (strcmp(mv->walls[0], mv->wall) != 0)
        return 0;
    snprintf(msg, size, "wall '%s' cannot move towards itself", mv->wall);
    return 1;
}

static const struct bal_wall_controller_type controllers[] = {
    [BAL_CONTROL_PRESCRIBED] = {"prescribed", NULL, prescribed_start, NULL},
    [BAL_CONTROL_SERVO] = {"servo", servo_check, servo_start, servo_control},
    [BAL_CONTROL_STRAIN_RATE] = {"strain_rate", strain_rate_check, strain_rate_start,
                                 strain_rate_control},
};

#define N_CONTROLLERS ((int)(sizeof controllers / sizeof controllers[0]))

int bal_walls_check(const struct bal_move_def *mv, char *msg, size_t size)
{
    if (mv->control < 0 || mv->control >= N_CONTROLLERS || !controllers[mv->control].check)
        return 0;
    return controllers[mv->control].check(mv, msg, size);
}

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
        if (k < 0 || c < 0 || c >= N_CONTROLLERS)
            continue; /* refused by bal_scene_validate; the parser sets only known ones */
        struct bal_wall *w = &s->walls[k];
        w->controller = &controllers[c];
        w->move = mv;
        for (int q = 0; q < BAL_CONTROL_WALLS_MAX; q++)
            w->other[q] = *mv->walls[q] ? bal_walls_find(s, mv->walls[q]) : -1;
    }
    /* Every wall has its line before any starts: a controller's start may
     * read the other walls. */
    for (int k = 0; k < s->n_walls; k++)
        if (s->walls[k].controller)
            s->walls[k].controller->start(s, &s->walls[k]);
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
        if (!w->controller || !w->controller->control)
            continue;
        const double vx = w->v[0], vy = w->v[1], om = w->omega;
        w->controller->control(s, w);
        /* The energy audit prices the dashpots' loss at t_N with the discs'
         * centred velocities (v_{N-1/2} + v_{N+1/2})/2 (energy.c); a wall's
         * V_N is its v_{N-1/2}, the one it moved with, and the velocity just
         * set its v_{N+1/2}.  A prescribed wall keeps its velocity, so V_N
         * is its centred one; a wall whose velocity changes every cycle needs
         * the mean, else the loss is off by D·ΔV Δt/2 a cycle (a servo
         * bouncing between its caps "created" four times the energy its
         * walls put in). */
        if (s->dash)
            s->audit.wall_dash += 0.5 * (w->dash_f[0] * (w->v[0] - vx) +
                                         w->dash_f[1] * (w->v[1] - vy) + w->dash_m * (w->omega - om));
    }
}
