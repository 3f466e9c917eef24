/*
 * measure.c — what a run reports of its state: velocities at t_N, the
 * energies, the dashpot forces, the unbalanced-force ratio of Cundall &
 * Strack Tables 1–3 and the stress moments of each disc.  The scene's
 * [probe] columns are read from here and from the energy audit (probes.c).
 *
 * Measurements are taken after a cycle N: forces, positions and contact
 * histories are those of t_N; velocities are centred at t_N as the mean of
 * v_{N−1/2} and v_{N+1/2} (C&S eq. 31), which the run keeps for the cycles
 * it reports.
 *
 * Stress (MLH Sec. 3, eq. 8): σ_αβ = (1/V) Σ_c f_α^c l_β^c.  Per disc the
 * sum runs over its contacts, f^c the force on the disc (elastic plus
 * dashpot), l^c from its centre to the contact point (the middle of the
 * overlap; for a wall, halfway between the disc surface and the wall), and
 * V = 2 sqrt(3) r², the hexagonal cell of a disc in a triangular packing of
 * its own size.  Held discs and walls bear the reactions.
 *
 * Dashpot forces of the last cycle: the disc–wall list stores them; the
 * disc–disc loop does not (16 bytes a candidate), so reports recompute them
 * from the geometry at t_N and the velocities the law read (integrate.c
 * recovers them), with the law's own kernels (laws.h), as the cycle
 * computed them.
 *
 * Elastic energy: the energy stored in the contact springs.  For the
 * incremental law the springs are k_n and k_s: F_n²/(2 k_n) + F_s²/(2 k_s).
 * For the power law the normal part is ∫ k_n δ0 (δ/δ0)^ν dδ
 * = k_n δ0² (δ/δ0)^{ν+1} / (ν+1).
 */
#include <math.h>
#include <string.h>

#include "integrate.h"
#include "measure.h"
#include "pairs.h"
#include "walls.h"

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
    const struct bal_law_params P = bal_law_params_of(s);
    return bal_law_normal_energy(&P, L, fn, delta);
}

double bal_measure_common_radius(const struct bal_sim *s, int walls, const struct bal_pairs *p,
                                 long c)
{
    const int i = p->i[c];
    return walls ? 2 * s->r[i] : bal_law_common_radius(s->r[i], s->r[p->j[c]]);
}

double bal_measure_elastic(const struct bal_sim *s)
{
    const struct bal_law_params P = bal_law_params_of(s);
    double e = 0;
    for (int walls = 0; walls < 2; walls++) {
        const struct bal_pairs *p = walls ? &s->pw : &s->pp;
        for (long c = 0; c < p->n; c++) {
            if (!(p->flags[c] & BAL_PAIR_TOUCHING))
                continue;
            double rmin;
            const struct bal_pair_law *L;
            const double delta = bal_pairs_overlap(s, walls, c, &rmin, &L);
            e += bal_law_normal_energy(&P, L, p->fn[c], delta);
            e += bal_law_shear_energy(L, pair_fs(p, c));
            if (p->rolling && L->rolling > 0)
                e += bal_law_rolling_energy(bal_law_roll_of(L, bal_measure_common_radius(s, walls, p, c)),
                                            p->mr[c]);
        }
    }
    return e;
}

void bal_measure_dashpots(const struct bal_sim *s, const struct bal_pairs *p, long c, double *dn,
                          double *ds)
{
    *dn = *ds = 0;
    if (!(p->flags[c] & BAL_PAIR_TOUCHING))
        return;
    if (p != &s->pp) {
        *dn = p->dn ? p->dn[c] : 0;
        *ds = p->ds ? p->ds[c] : 0;
        return;
    }
    if (!s->has_damping)
        return;
    const int i = p->i[c], j = p->j[c];
    const struct bal_pair_law *L = &s->law[s->mat[i] * s->n_mat + s->mat[j]];
    const double dx = s->x[j] - s->x[i], dy = s->y[j] - s->y[i];
    const double dist = sqrt(dx * dx + dy * dy), ex = dx / dist, ey = dy / dist;
    double vxi, vyi, wi, vxj, vyj, wj;
    bal_integrate_previous(s, i, &vxi, &vyi, &wi);
    bal_integrate_previous(s, j, &vxj, &vyj, &wj);
    const double rvx = vxi - vxj, rvy = vyi - vyj;
    const struct bal_law_params P = bal_law_params_of(s);
    struct bal_kin k;
    k.ndot = rvx * ex + rvy * ey;
    k.delta = s->r[i] + s->r[j] - dist;
    *dn = bal_law_normal_dashpot(&P, L, &k); /* the cycle's own kernels (laws.h) */
    if (s->has_shear && L->shear && !(p->flags[c] & BAL_PAIR_SLIDING)) {
        k.sdot = rvx * ey - rvy * ex - (wi * s->r[i] + wj * s->r[j]);
        *ds = bal_law_shear_dashpot(L, &k);
    }
}

double bal_measure_rolling_dashpot(const struct bal_sim *s, const struct bal_pairs *p, long c)
{
    if (!p->rolling || !s->has_damping || !(p->flags[c] & BAL_PAIR_TOUCHING))
        return 0;
    if (p != &s->pp)
        return p->dm ? p->dm[c] : 0;
    const int i = p->i[c], j = p->j[c];
    const struct bal_pair_law *L = &s->law[s->mat[i] * s->n_mat + s->mat[j]];
    if (!(L->rolling > 0))
        return 0;
    double vxi, vyi, wi, vxj, vyj, wj;
    bal_integrate_previous(s, i, &vxi, &vyi, &wi);
    bal_integrate_previous(s, j, &vxj, &vyj, &wj);
    const double dx = s->x[j] - s->x[i], dy = s->y[j] - s->y[i];
    const double dist = sqrt(dx * dx + dy * dy); /* as the cycle computes it */
    const struct bal_law_params P = bal_law_params_of(s);
    const struct bal_roll R = bal_law_roll_of(L, bal_law_common_radius(s->r[i], s->r[j]));
    return bal_law_rolling_dashpot(&P, L, R, s->r[i] + s->r[j] - dist, wi - wj, p->flags[c]);
}

static double contact_force(const struct bal_sim *s, const struct bal_pairs *p, long c)
{
    double dn, ds;
    bal_measure_dashpots(s, p, c, &dn, &ds);
    return hypot(p->fn[c] + dn, pair_fs(p, c) + ds);
}

double bal_measure_unbalanced_of(const struct bal_sim *s, double *largest)
{
    double fbig = 0;
    for (long c = 0; c < s->pp.n; c++)
        if (s->pp.flags[c] & BAL_PAIR_TOUCHING)
            fbig = fmax(fbig, contact_force(s, &s->pp, c));
    for (long c = 0; c < s->pw.n; c++)
        if (s->pw.flags[c] & BAL_PAIR_TOUCHING)
            fbig = fmax(fbig, contact_force(s, &s->pw, c));
    *largest = fbig;
    if (fbig == 0)
        return 0;
    double smax = 0;
    for (int i = 0; i < s->n; i++) {
        if (s->fixed[i])
            continue;
        const double m = bal_mass(s, i);
        double sx = s->f[3 * i] + m * s->g[0], sy = s->f[3 * i + 1] + m * s->g[1];
        /* a held component is balanced by its hold */
        const unsigned held = s->hold ? s->hold[i] : 0;
        if (held & BAL_HOLD_X)
            sx = 0;
        if (held & BAL_HOLD_Y)
            sy = 0;
        smax = fmax(smax, hypot(sx, sy));
    }
    return smax / fbig;
}

double bal_measure_unbalanced(const struct bal_sim *s)
{
    double largest;
    return bal_measure_unbalanced_of(s, &largest);
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
        bal_measure_dashpots(s, &s->pp, c, &dn, &ds);
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
