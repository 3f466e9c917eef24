/*
 * probes.c — the value of each [probe] of the scene at the current cycle,
 * the columns of series.tsv.
 *
 * A probe reads one quantity of one body, of a contact between two bodies,
 * or of the whole scene (struct bal_probe_ref holds its bodies, resolved at
 * creation).  The values come from the state (positions, contact
 * histories, wall resultants), from the measurements (measure.c: velocities
 * at t_N, energies, ΔF/F) and from the energy audit (energy.c), all taken
 * after a cycle N, at t_N.
 *
 * Wall resultants (C&S Table 1): F1, F2 are the components of the force the
 * discs exert on the wall; the moment is about P, counter-clockwise; the
 * eccentricity e/(L/2) is the distance, along the wall, from the wall's
 * centre to the point where the resultant normal force acts, divided by
 * half the wall length (footnote 1 of Table 1).  wall_px, wall_py are the
 * wall's point P; wall_gap the distance from wall a to the midpoint of wall
 * b along a's normal (walls.c, bal_walls_gap: the distance between the
 * parallel walls of a box, as the controllers measure it); wall_stress the
 * normal stress a servo measured on the wall in the last cycle (the normal
 * force of its contact springs over its span, compression positive: at rest
 * the whole force; 0 when no servo drives the wall).  held_fx, held_fy sum the
 * contact forces on the discs held along the axis (fixed = 1, or a `hold`
 * with x or y); weight_x, weight_y the gravity on the discs free along it
 * (with the current ramp).
 */
#include <math.h>

#include "measure.h"
#include "pairs.h"
#include "walls.h"

/* Contacts whose flags include `flag` (touching, or sliding). */
static long count_contacts(const struct bal_sim *s, uint8_t flag)
{
    long n = 0;
    for (long c = 0; c < s->pp.n; c++)
        n += (s->pp.flags[c] & flag) != 0;
    for (long c = 0; c < s->pw.n; c++)
        n += (s->pw.flags[c] & flag) != 0;
    return n;
}

double bal_probes_value(const struct bal_sim *s, int probe)
{
    const struct bal_probe_ref *p = &s->probes[probe];
    switch (p->kind) {
    case BAL_PROBE_CONTACT_FN:
    case BAL_PROBE_CONTACT_FS:
    case BAL_PROBE_CONTACT_SLIDING: {
        const struct bal_pairs *list = NULL;
        const long c = bal_pairs_find_contact(s, p->a_wall, p->a, p->b_wall, p->b, &list);
        if (c < 0 || !(list->flags[c] & BAL_PAIR_TOUCHING))
            return 0;
        if (p->kind == BAL_PROBE_CONTACT_FN)
            return list->fn[c];
        if (p->kind == BAL_PROBE_CONTACT_FS)
            return pair_fs(list, c);
        return (list->flags[c] & BAL_PAIR_SLIDING) ? 1 : 0;
    }
    case BAL_PROBE_CONTACT_MR:
    case BAL_PROBE_CONTACT_THETA_R:
    case BAL_PROBE_CONTACT_ROLLING: {
        /* The rolling moment M (elastic; JYH eq. 28, capped by eq. 35) that
         * body b exerts on body a is −M: the probe gives M, positive when a
         * turns counter-clockwise against b.  θ_r is accumulated since the
         * contact formed; `rolling` is 1 at the cap (Model 1), 2 once the
         * resistance is lost (Model 2). */
        const struct bal_pairs *list = NULL;
        const long c = bal_pairs_find_contact(s, p->a_wall, p->a, p->b_wall, p->b, &list);
        if (c < 0 || !(list->flags[c] & BAL_PAIR_TOUCHING))
            return 0;
        /* The list orders the pair as (lower slot, higher) or (disc, wall):
         * seen from the other body the signs turn. */
        const int flip = !p->a_wall && !p->b_wall ? p->a > p->b : p->a_wall;
        if (p->kind == BAL_PROBE_CONTACT_ROLLING)
            return (list->flags[c] & BAL_PAIR_BROKEN) ? 2 : (list->flags[c] & BAL_PAIR_ROLLING) ? 1 : 0;
        const double v = p->kind == BAL_PROBE_CONTACT_MR ? pair_mr(list, c) : pair_tr(list, c);
        return flip ? -v : v;
    }
    case BAL_PROBE_WALL_F1:
        return s->walls[p->a].f[0];
    case BAL_PROBE_WALL_F2:
        return s->walls[p->a].f[1];
    case BAL_PROBE_WALL_MOMENT:
        return s->walls[p->a].moment;
    case BAL_PROBE_WALL_PX:
        return s->walls[p->a].p[0];
    case BAL_PROBE_WALL_PY:
        return s->walls[p->a].p[1];
    case BAL_PROBE_WALL_GAP:
        return bal_walls_gap(&s->walls[p->a], &s->walls[p->b], NULL);
    case BAL_PROBE_WALL_STRESS: {
        /* What the wall's servo measured in the last cycle; 0 for a wall no
         * servo drives in the current stage. */
        const struct bal_wall *W = &s->walls[p->a];
        return W->move && W->move->control == BAL_CONTROL_SERVO ? W->stress : 0;
    }
    case BAL_PROBE_WALL_ECC: {
        const struct bal_wall *W = &s->walls[p->a];
        if (W->fn_sum == 0)
            return 0;
        const double mid = 0.5 * (W->h1 + W->h2), half = 0.5 * (W->h2 - W->h1);
        return (W->fn_s_sum / W->fn_sum - mid) / half;
    }
    case BAL_PROBE_DISC_X:
        return s->x[p->a];
    case BAL_PROBE_DISC_Y:
        return s->y[p->a];
    case BAL_PROBE_DISC_VX:
    case BAL_PROBE_DISC_VY:
    case BAL_PROBE_DISC_OMEGA: {
        double vx, vy, w;
        bal_measure_velocity(s, p->a, &vx, &vy, &w);
        return p->kind == BAL_PROBE_DISC_VX ? vx : p->kind == BAL_PROBE_DISC_VY ? vy : w;
    }
    case BAL_PROBE_DISC_THETA:
        return s->th[p->a] * (180 / BAL_PI);
    case BAL_PROBE_ENERGY_KINETIC:
        return bal_measure_kinetic(s);
    case BAL_PROBE_ENERGY_ELASTIC:
        return bal_measure_elastic(s);
    case BAL_PROBE_WORK_WALLS:
    case BAL_PROBE_WORK_GRAVITY:
    case BAL_PROBE_DISSIPATED_DASHPOT:
    case BAL_PROBE_DISSIPATED_FRICTION:
    case BAL_PROBE_DISSIPATED_GLOBAL:
    case BAL_PROBE_DISSIPATED_ROLLING:
    case BAL_PROBE_ENERGY_IMBALANCE: {
        struct bal_energy e;
        bal_energy_report(s, &e);
        switch (p->kind) {
        case BAL_PROBE_WORK_WALLS: return e.work_walls;
        case BAL_PROBE_WORK_GRAVITY: return e.work_gravity;
        case BAL_PROBE_DISSIPATED_DASHPOT: return e.dissipated_dashpot;
        case BAL_PROBE_DISSIPATED_FRICTION: return e.dissipated_friction;
        case BAL_PROBE_DISSIPATED_ROLLING: return e.dissipated_rolling;
        case BAL_PROBE_DISSIPATED_GLOBAL: return e.dissipated_global;
        default: return e.imbalance;
        }
    }
    case BAL_PROBE_UNBALANCED:
        return bal_measure_unbalanced(s);
    case BAL_PROBE_N_CONTACTS:
        return (double)count_contacts(s, BAL_PAIR_TOUCHING);
    case BAL_PROBE_N_SLIDING:
        return (double)count_contacts(s, BAL_PAIR_SLIDING);
    case BAL_PROBE_HELD_FX:
    case BAL_PROBE_HELD_FY: {
        /* the discs held along the axis: fixed ones, and partly held ones
         * whose hold includes it */
        double f = 0;
        const int k = p->kind == BAL_PROBE_HELD_FX ? 0 : 1;
        const unsigned axis = k == 0 ? BAL_HOLD_X : BAL_HOLD_Y;
        for (int i = 0; i < s->n; i++)
            if (s->fixed[i] || (s->hold && (s->hold[i] & axis)))
                f += s->f[3 * i + k];
        return f;
    }
    case BAL_PROBE_WEIGHT_X:
    case BAL_PROBE_WEIGHT_Y: {
        /* the discs free along the axis */
        double m = 0;
        const unsigned axis = p->kind == BAL_PROBE_WEIGHT_X ? BAL_HOLD_X : BAL_HOLD_Y;
        for (int i = 0; i < s->n; i++)
            if (!s->fixed[i] && !(s->hold && (s->hold[i] & axis)))
                m += bal_mass(s, i);
        return m * s->g[p->kind == BAL_PROBE_WEIGHT_X ? 0 : 1] * s->gfac;
    }
    }
    return NAN;
}
