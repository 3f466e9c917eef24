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
 * Stress (MLH Sec. 3, eq. 8): σ_αβ = (1/V) Σ_c f_α^c l_β^c.  Per disc the
 * sum runs over its contacts, f^c the force on the disc (elastic plus
 * dashpot), l^c from its centre to the contact point (the middle of the
 * overlap; for a wall, halfway between the disc surface and the wall), and
 * V = 2 sqrt(3) r², the hexagonal cell of a disc in a triangular packing of
 * its own size.  Held discs and walls bear the reactions.  Probes held_fx,
 * held_fy sum the contact forces on held discs; weight_x, weight_y the
 * gravity on the free ones (with the current ramp).
 *
 * Elastic energy: the energy stored in the contact springs.  For the
 * incremental law the springs are k_n and k_s: F_n²/(2 k_n) + F_s²/(2 k_s).
 * For the power law the normal part is ∫ k_n δ0 (δ/δ0)^ν dδ
 * = k_n δ0² (δ/δ0)^{ν+1} / (ν+1).
 */
#include <math.h>
#include <string.h>

#include "sim.h"

/* Velocities of disc i at t_N: the mean of v_{N-1/2} and v_{N+1/2} (eq. 31);
 * before the first cycle, the initial ones. */
void bal_measure_velocity(const struct bal_sim *s, int i, double *vx, double *vy, double *w)
{
    if (!s->have_old) {
        *vx = s->vx[i];
        *vy = s->vy[i];
        *w = s->w[i];
        return;
    }
    double ox, oy, ow;
    bal_integrate_previous(s, i, &ox, &oy, &ow);
    *vx = 0.5 * (s->vx[i] + ox);
    *vy = 0.5 * (s->vy[i] + oy);
    *w = 0.5 * (s->w[i] + ow);
}

double bal_measure_kinetic(const struct bal_sim *s)
{
    double e = 0;
    for (int i = 0; i < s->n; i++) {
        double vx, vy, w;
        bal_measure_velocity(s, i, &vx, &vy, &w);
        e += 0.5 * bal_mass(s, i) * (vx * vx + vy * vy) + 0.5 * bal_inertia(s, i) * w * w;
    }
    return e;
}

double bal_measure_normal_energy(const struct bal_sim *s, const struct bal_pair_law *L, double fn,
                                 double delta)
{
    if (s->normal_law == BAL_NORMAL_INCREMENTAL)
        return fn * fn / (2 * L->kn);
    return L->kn * s->delta0 * s->delta0 * pow(delta / s->delta0, s->nu + 1) / (s->nu + 1);
}

/* ½ F_s²/k_s; a pair with k_s = 0 never carries a shear force. */
static double shear_energy(const struct bal_pair_law *L, double fs)
{
    return L->ks > 0 ? fs * fs / (2 * L->ks) : 0;
}

double bal_measure_elastic(const struct bal_sim *s)
{
    double e = 0;
    for (int walls = 0; walls < 2; walls++) {
        const struct bal_pairs *p = walls ? &s->pw : &s->pp;
        for (long c = 0; c < p->n; c++) {
            if (!(p->flags[c] & BAL_PAIR_TOUCHING))
                continue;
            double rmin;
            const struct bal_pair_law *L;
            const double delta = bal_pairs_overlap(s, walls, c, &rmin, &L);
            e += bal_measure_normal_energy(s, L, p->fn[c], delta);
            e += shear_energy(L, pair_fs(p, c));
        }
    }
    return e;
}

static double contact_force(const struct bal_sim *s, const struct bal_pairs *p, long c)
{
    double dn, ds;
    bal_contact_dashpots(s, p, c, &dn, &ds);
    return hypot(p->fn[c] + dn, pair_fs(p, c) + ds);
}

double bal_measure_unbalanced(const struct bal_sim *s)
{
    double fbig = 0;
    for (long c = 0; c < s->pp.n; c++)
        if (s->pp.flags[c] & BAL_PAIR_TOUCHING)
            fbig = fmax(fbig, contact_force(s, &s->pp, c));
    for (long c = 0; c < s->pw.n; c++)
        if (s->pw.flags[c] & BAL_PAIR_TOUCHING)
            fbig = fmax(fbig, contact_force(s, &s->pw, c));
    if (fbig == 0)
        return 0;
    double smax = 0;
    for (int i = 0; i < s->n; i++) {
        if (s->fixed[i])
            continue;
        const double m = bal_mass(s, i);
        const double sx = s->f[3 * i] + m * s->g[0], sy = s->f[3 * i + 1] + m * s->g[1];
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

double bal_measure_disc_volume(double r)
{
    return 2 * sqrt(3.0) * r * r;
}

/* Add f ⊗ l to the moment of disc i. */
static void add_moment(double *m, int i, double fx, double fy, double lx, double ly)
{
    m[4 * i + 0] += fx * lx;
    m[4 * i + 1] += fx * ly;
    m[4 * i + 2] += fy * lx;
    m[4 * i + 3] += fy * ly;
}

void bal_measure_moments(const struct bal_sim *s, double *m)
{
    memset(m, 0, 4 * (size_t)s->n * sizeof *m);
    for (long c = 0; c < s->pp.n; c++) {
        if (!(s->pp.flags[c] & BAL_PAIR_TOUCHING))
            continue;
        const int i = s->pp.i[c], j = s->pp.j[c];
        const double dx = s->x[j] - s->x[i], dy = s->y[j] - s->y[i];
        const double d = hypot(dx, dy), ex = dx / d, ey = dy / d;
        const double delta = s->r[i] + s->r[j] - d;
        double dn, ds;
        bal_contact_dashpots(s, &s->pp, c, &dn, &ds);
        const double ftn = s->pp.fn[c] + dn;
        const double fts = pair_fs(&s->pp, c) + ds;
        /* Force on j is ftn e + fts t, t = (ey, -ex); on i the opposite.  The
         * contact point lies on the line of centres, in the middle of the
         * overlap; l runs from each centre to it. */
        const double fx = ftn * ex + fts * ey, fy = ftn * ey - fts * ex;
        const double li = s->r[i] - delta / 2, lj = s->r[j] - delta / 2;
        add_moment(m, i, -fx, -fy, li * ex, li * ey);
        add_moment(m, j, fx, fy, -lj * ex, -lj * ey);
    }
    for (long c = 0; c < s->pw.n; c++) {
        if (!(s->pw.flags[c] & BAL_PAIR_TOUCHING))
            continue;
        const int i = s->pw.i[c];
        const struct bal_wall *W = &s->walls[s->pw.j[c]];
        double ex, ey;
        const double d = bal_walls_normal(W, s->x[i], s->y[i], &ex, &ey);
        const double ftn = s->pw.fn[c] + s->pw.dn[c], fts = s->pw.fs[c] + s->pw.ds[c];
        const double fx = ftn * ex + fts * ey, fy = ftn * ey - fts * ex;
        const double l = 0.5 * (s->r[i] + d);
        add_moment(m, i, -fx, -fy, l * ex, l * ey);
    }
}

double bal_measure_probe(const struct bal_sim *s, int probe)
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
    case BAL_PROBE_ENERGY_IMBALANCE: {
        struct bal_energy e;
        bal_energy_report(s, &e);
        switch (p->kind) {
        case BAL_PROBE_WORK_WALLS: return e.work_walls;
        case BAL_PROBE_WORK_GRAVITY: return e.work_gravity;
        case BAL_PROBE_DISSIPATED_DASHPOT: return e.dissipated_dashpot;
        case BAL_PROBE_DISSIPATED_FRICTION: return e.dissipated_friction;
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
        double f = 0;
        const int k = p->kind == BAL_PROBE_HELD_FX ? 0 : 1;
        for (int i = 0; i < s->n; i++)
            if (s->fixed[i])
                f += s->f[3 * i + k];
        return f;
    }
    case BAL_PROBE_WEIGHT_X:
    case BAL_PROBE_WEIGHT_Y: {
        double m = 0;
        for (int i = 0; i < s->n; i++)
            if (!s->fixed[i])
                m += bal_mass(s, i);
        return m * s->g[p->kind == BAL_PROBE_WEIGHT_X ? 0 : 1] * s->gfac;
    }
    }
    return NAN;
}
