/*
 * measure.c — what a run reports: probes of contacts, walls and discs, the
 * energies, and the unbalanced-force ratio of Cundall & Strack Tables 1–3.
 *
 * Measurements are taken after a cycle N: forces, positions and contact
 * histories are those of t_N; velocities are centred at t_N as the mean of
 * v_{N−1/2} and v_{N+1/2} (C&S eq. 31), which the run keeps for the cycles
 * it reports.
 *
 * Wall resultants (Table 1): F1, F2 are the components of the force the
 * discs exert on the wall; the moment is about P, counter-clockwise; the
 * eccentricity e/(L/2) is the distance, along the wall, from the wall's
 * centre to the point where the resultant normal force acts, divided by
 * half the wall length (footnote 1 of Table 1).
 *
 * Elastic energy: the energy stored in the contact springs.  For the
 * incremental law the springs are k_n and k_s: F_n²/(2 k_n) + F_s²/(2 k_s).
 * For the power law the normal part is ∫ k_n δ0 (δ/δ0)^ν dδ
 * = k_n δ0² (δ/δ0)^{ν+1} / (ν+1).
 */
#include <math.h>

#include "sim.h"

static double centred(const struct bal_sim *s, const double *now, const double *old, int i)
{
    return s->have_old ? 0.5 * (now[i] + old[i]) : now[i];
}

double bal_measure_kinetic(const struct bal_sim *s)
{
    double e = 0;
    for (int i = 0; i < s->n; i++) {
        const double vx = centred(s, s->vx, s->vx_old, i);
        const double vy = centred(s, s->vy, s->vy_old, i);
        const double w = centred(s, s->w, s->w_old, i);
        e += 0.5 * s->m[i] * (vx * vx + vy * vy) + 0.5 * s->inertia[i] * w * w;
    }
    return e;
}

static double normal_energy(const struct bal_sim *s, const struct bal_pair_law *L, double fn,
                            double delta)
{
    if (s->normal_law == BAL_NORMAL_INCREMENTAL)
        return fn * fn / (2 * L->kn);
    return L->kn * s->delta0 * s->delta0 * pow(delta / s->delta0, s->nu + 1) / (s->nu + 1);
}

double bal_measure_elastic(const struct bal_sim *s)
{
    double e = 0;
    for (long c = 0; c < s->pp.n; c++) {
        if (!(s->pp.flags[c] & BAL_PAIR_TOUCHING))
            continue;
        const int i = s->pp.i[c], j = s->pp.j[c];
        const struct bal_pair_law *L = &s->law[s->mat[i] * s->n_mat + s->mat[j]];
        const double delta = s->r[i] + s->r[j] - hypot(s->x[j] - s->x[i], s->y[j] - s->y[i]);
        e += normal_energy(s, L, s->pp.fn[c], delta);
        e += s->pp.fs[c] * s->pp.fs[c] / (2 * L->ks);
    }
    for (long c = 0; c < s->pw.n; c++) {
        if (!(s->pw.flags[c] & BAL_PAIR_TOUCHING))
            continue;
        const int i = s->pw.i[c];
        const struct bal_wall *W = &s->walls[s->pw.j[c]];
        const struct bal_pair_law *L = &s->law[s->mat[i] * s->n_mat + W->material];
        double cx, cy;
        const double delta = s->r[i] - sqrt(bal_walls_closest(W, s->x[i], s->y[i], &cx, &cy));
        e += normal_energy(s, L, s->pw.fn[c], delta);
        e += s->pw.fs[c] * s->pw.fs[c] / (2 * L->ks);
    }
    return e;
}

static double contact_force(const struct bal_pairs *p, long c)
{
    return hypot(p->fn[c] + p->dn[c], p->fs[c] + p->ds[c]);
}

double bal_measure_unbalanced(const struct bal_sim *s)
{
    double fbig = 0;
    for (long c = 0; c < s->pp.n; c++)
        if (s->pp.flags[c] & BAL_PAIR_TOUCHING)
            fbig = fmax(fbig, contact_force(&s->pp, c));
    for (long c = 0; c < s->pw.n; c++)
        if (s->pw.flags[c] & BAL_PAIR_TOUCHING)
            fbig = fmax(fbig, contact_force(&s->pw, c));
    if (fbig == 0)
        return 0;
    double smax = 0;
    for (int i = 0; i < s->n; i++) {
        if (s->fixed[i])
            continue;
        const double sx = s->fx[i] + s->m[i] * s->g[0], sy = s->fy[i] + s->m[i] * s->g[1];
        smax = fmax(smax, hypot(sx, sy));
    }
    return smax / fbig;
}

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

double bal_measure_probe(const struct bal_sim *s, int probe)
{
    const struct bal_probe_ref *p = &s->probes[probe];
    switch (p->kind) {
    case BAL_PROBE_CONTACT_FN:
    case BAL_PROBE_CONTACT_FS:
    case BAL_PROBE_CONTACT_SLIDING: {
        const struct bal_pairs *list = NULL;
        const long c = bal_sim_find_contact(s, p->a_wall, p->a, p->b_wall, p->b, &list);
        if (c < 0 || !(list->flags[c] & BAL_PAIR_TOUCHING))
            return 0;
        if (p->kind == BAL_PROBE_CONTACT_FN)
            return list->fn[c];
        if (p->kind == BAL_PROBE_CONTACT_FS)
            return list->fs[c];
        return (list->flags[c] & BAL_PAIR_SLIDING) ? 1 : 0;
    }
    case BAL_PROBE_WALL_F1:
        return s->walls[p->a].f[0];
    case BAL_PROBE_WALL_F2:
        return s->walls[p->a].f[1];
    case BAL_PROBE_WALL_MOMENT:
        return s->walls[p->a].moment;
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
        return centred(s, s->vx, s->vx_old, p->a);
    case BAL_PROBE_DISC_VY:
        return centred(s, s->vy, s->vy_old, p->a);
    case BAL_PROBE_DISC_THETA:
        return s->th[p->a] * (180 / BAL_PI);
    case BAL_PROBE_DISC_OMEGA:
        return centred(s, s->w, s->w_old, p->a);
    case BAL_PROBE_ENERGY_KINETIC:
        return bal_measure_kinetic(s);
    case BAL_PROBE_ENERGY_ELASTIC:
        return bal_measure_elastic(s);
    case BAL_PROBE_UNBALANCED:
        return bal_measure_unbalanced(s);
    case BAL_PROBE_N_CONTACTS:
        return (double)count_contacts(s, BAL_PAIR_TOUCHING);
    case BAL_PROBE_N_SLIDING:
        return (double)count_contacts(s, BAL_PAIR_SLIDING);
    }
    return NAN;
}
