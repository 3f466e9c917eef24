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
 *
 * Guards.  No wall may move more than BAL_WALL_STEP_SHARE of the smallest
 * disc radius in one step, and no servo may divide by a span below the
 * smallest radius: what the scene alone decides is refused when the
 * simulation is built (bal_walls_check_steps, naming the stage's line);
 * the rest is caught once a controller sets the velocity (or its servo
 * measures the span), and the run stops before the wall moves
 * (s->wall_fault, checked by the cycle in sim.c).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "scene_keys.h"
#include "walls.h"

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
        w->disp += bal_walls_step(w, w->v[0], w->v[1], w->omega, dt);
    }
}

double bal_walls_step(const struct bal_wall *w, double vx, double vy, double omega, double dt)
{
    const double hmax = fmax(fabs(w->h1), fabs(w->h2));
    return hypot(vx, vy) * dt + fabs(omega) * hmax * dt;
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
/* Guards: how far a wall may move in a cycle, how close a servo's span */
/* ------------------------------------------------------------------ */

/* The most a wall may move in one time step, as a share of the smallest
 * disc radius.  A wall that moves d in a cycle gives a disc it meets up to
 * d of new overlap before the contact can answer (its force acts from the
 * next cycle on); a wall that moves a diameter in a cycle can pass through
 * a disc without ever touching it, and the run used to end "ok" with the
 * specimen behind the wall (issue 29, item 5: a servo with vmax dt = 24 in
 * a 10 x 10 box).  Why a tenth:
 *   - DEM contacts work at overlaps of 1e-3 to a few 1e-2 of a radius
 *     (JYH's at 400 kPa: 3e-2), built up over tens of cycles; a tenth in
 *     one cycle is already several working overlaps at once;
 *   - it is a fifth of the default overlap budget (0.5, energy.c): a disc
 *     pinned by such a wall reaches the budget within a few cycles, and the
 *     overlap guard stops the run on it rather than let the wall pass (at
 *     the usual dt ~ 0.2 sqrt(m/k), a wall at d per cycle drives a pinned
 *     disc to an overlap of about d/0.2 = 5 d);
 *   - the catalogue's walls move at most 4.0e-4 of the smallest radius a
 *     cycle (biaxial's shear servos: vmax = 1 m/s, dt = 1.2e-6 s, r_min =
 *     3.0 mm; prepare.scene 2.9e-4, nine_discs_speed 2.2e-4), 250 times
 *     below. */
#define BAL_WALL_STEP_SHARE 0.1

static double step_limit(const struct bal_sim *s)
{
    return BAL_WALL_STEP_SHARE * s->r_min; /* INFINITY without discs: nothing to pass */
}

/* The smallest span a servo may divide its force by: the smallest disc
 * radius.  A disc between walls closer than that overlaps each by more than
 * half its radius, beyond the default overlap budget (0.5, energy.c): no
 * disc is between them as a contact, and as the span goes to 0 the "stress"
 * force/span grows without bound (issue 29: a span of 1e-16 gave 5e16, with
 * the energy imbalance at 0.44 of the throughput; a span of 0 measured 0).  Not
 * the diameter: a column of discs that exactly fits its walls (the span one
 * diameter, give or take the round-off of the walls' directions) is a
 * servo's ordinary work (check_walls' walls_servo_column).  Without discs,
 * any positive span. */
static double span_min(const struct bal_sim *s)
{
    return s->n > 0 ? s->r_min : 0;
}

static int span_ok(const struct bal_sim *s, double span)
{
    return span > 0 && span >= span_min(s);
}

/* Record the first fault of a cycle; the next cycle stops the run before
 * the wall moves (sim.c). */
static void trip(struct bal_sim *s, const struct bal_wall *w, enum bal_wall_fault kind)
{
    if (s->wall_fault)
        return;
    s->wall_fault = 1 + (int)(w - s->walls);
    s->wall_fault_kind = kind;
}

/* The velocity a controller has just set: beyond the limit, trip. */
static void guard_step(struct bal_sim *s, const struct bal_wall *w)
{
    if (!(bal_walls_step(w, w->v[0], w->v[1], w->omega, s->dt) <= step_limit(s)))
        trip(s, w, BAL_WALL_FAULT_STEP);
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
    if (!span_ok(s, span))
        trip(s, w, BAL_WALL_FAULT_SPAN); /* the span walls closed on each other */
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
     * read the other walls.  A fault of the stage before is that stage's. */
    s->wall_fault = 0;
    for (int k = 0; k < s->n_walls; k++)
        if (s->walls[k].controller) {
            s->walls[k].controller->start(s, &s->walls[k]);
            guard_step(s, &s->walls[k]);
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
        if (!w->controller || !w->controller->control)
            continue;
        const double vx = w->v[0], vy = w->v[1], om = w->omega;
        w->controller->control(s, w);
        guard_step(s, w);
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

/* ------------------------------------------------------------------ */
/* Refusals once the time step is known, and the run-time guard's error */
/* ------------------------------------------------------------------ */

/* Does a stage before g name wall `name` (and so may have moved it)? */
static int named_before(const struct bal_scene *sc, int g, const char *name)
{
    for (int h = 0; h < g; h++)
        for (int m = 0; m < sc->stages[h].n_moves; m++)
            if (strcmp(sc->stages[h].moves[m].wall, name) == 0)
                return 1;
    return 0;
}

enum bal_status bal_walls_check_steps(const struct bal_sim *s, struct bal_error *err)
{
    const struct bal_scene *sc = s->scene;
    const double limit = step_limit(s);
    for (int g = 0; g < sc->n_stages; g++) {
        const struct bal_stage_def *st = &sc->stages[g];
        for (int m = 0; m < st->n_moves; m++) {
            const struct bal_move_def *mv = &st->moves[m];
            const int k = bal_walls_find(s, mv->wall);
            if (k < 0)
                continue; /* refused by bal_scene_validate */
            const struct bal_wall *w = &s->walls[k];
            const char *key = bal_scene_key_for_control(mv->control);
            const int line = mv->line > 0 ? mv->line : st->line;
            const int other = *mv->walls[0] ? bal_walls_find(s, mv->walls[0]) : -1;
            const int other2 = *mv->walls[1] ? bal_walls_find(s, mv->walls[1]) : -1;
            /* The walls as the scene put them, if no earlier stage moved them. */
            const int as_built = !named_before(sc, g, mv->wall) &&
                                 (other < 0 || !named_before(sc, g, mv->walls[0])) &&
                                 (other2 < 0 || !named_before(sc, g, mv->walls[1]));
            double step = -1;
            char how[96] = "";
            switch (mv->control) {
            case BAL_CONTROL_PRESCRIBED:
                step = bal_walls_step(w, mv->v[0], mv->v[1], mv->omega, s->dt);
                snprintf(how, sizeof how, "|V| dt + |omega| dt reach, its far end %g from P",
                         fmax(fabs(w->h1), fabs(w->h2)));
                break;
            case BAL_CONTROL_SERVO:
                if (mv->vmax > 0) { /* vmax = 0: BAL_SERVO_CAP_SHARE of r_min, far below */
                    step = mv->vmax * s->dt;
                    snprintf(how, sizeof how, "vmax dt");
                }
                if (as_built && other >= 0 && other2 >= 0) {
                    const double span = bal_walls_gap(&s->walls[other], &s->walls[other2], NULL);
                    if (!span_ok(s, span))
                        return bal_error(err, BAL_EINVAL,
                                         "%s:%d: %s: wall '%s': its span gap(%s, %s) = %g is "
                                         "below the smallest disc radius %g; expected walls a "
                                         "disc fits between (the servo's stress is its force "
                                         "over the span)", sc->path, line, key, mv->wall,
                                         mv->walls[0], mv->walls[1], span, span_min(s));
                }
                break;
            case BAL_CONTROL_STRAIN_RATE:
                if (as_built && other >= 0) {
                    step = fabs(mv->rate) * s->dt * bal_walls_gap(w, &s->walls[other], NULL);
                    snprintf(how, sizeof how, "|rate| dt gap(%s, %s), the gap %g", mv->wall,
                             mv->walls[0], bal_walls_gap(w, &s->walls[other], NULL));
                }
                break;
            default:
                break;
            }
            if (step > limit)
                return bal_error(err, BAL_EINVAL,
                                 "%s:%d: %s: wall '%s' would move %.6g in one time step (%s, dt "
                                 "= %g): %.4g of the smallest disc radius %g; expected at most "
                                 "%g of it (a disc the wall meets gains that much overlap in a "
                                 "cycle; a wall that moves a diameter passes through discs)",
                                 sc->path, line, key, mv->wall, step, how, s->dt,
                                 step / s->r_min, s->r_min, BAL_WALL_STEP_SHARE);
        }
    }
    return BAL_OK;
}

enum bal_status bal_walls_fault(const struct bal_sim *s, struct bal_error *err)
{
    const struct bal_wall *w = &s->walls[s->wall_fault - 1];
    const struct bal_move_def *mv = w->move;
    const char *key = mv ? bal_scene_key_for_control(mv->control) : "?";
    const struct bal_stage_def *st = s->stage >= 0 ? &s->scene->stages[s->stage] : NULL;
    const int line = mv && mv->line > 0 ? mv->line : st ? st->line : 0;
    if (s->wall_fault_kind == BAL_WALL_FAULT_SPAN)
        return bal_error(err, BAL_EUNSTABLE,
                         "%s: wall '%s' at step %ld: its servo's span gap(%s, %s) = %g has closed "
                         "below the smallest disc radius %g: no disc fits between those walls "
                         "(%s:%d: %s)", s->scene->path, w->name, s->step, mv->walls[0],
                         mv->walls[1],
                         bal_walls_gap(&s->walls[w->other[0]], &s->walls[w->other[1]], NULL),
                         span_min(s), s->scene->path, line, key);
    const double step = bal_walls_step(w, w->v[0], w->v[1], w->omega, s->dt);
    return bal_error(err, BAL_EUNSTABLE,
                     "%s: wall '%s' at step %ld: its %s would move it %.6g in one time step, "
                     "%.4g of the smallest disc radius %g, beyond the limit %g of it (a disc "
                     "it meets gains that much overlap in a cycle; a wall that moves a "
                     "diameter passes through discs) (%s:%d: %s)", s->scene->path, w->name, s->step,
                     w->controller ? w->controller->name : "controller", step, step / s->r_min,
                     s->r_min, BAL_WALL_STEP_SHARE, s->scene->path, line, key);
}
