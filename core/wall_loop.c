/*
 * wall_loop.c — the disc–wall loop: the force–displacement law (the kernels
 * of laws.h, the same as the disc–disc loop's, pair_loop.c) at every
 * contact of the disc–wall candidate list, once per cycle, after the
 * disc–disc loop has started the discs' sums (Cundall & Strack, Fig. 4 and
 * p. 53).
 *
 * The wall is body y of the contact: its "radius" is zero, e points from
 * the disc's centre to the closest point c of the wall (walls.c,
 * bal_walls_closest), and the velocity of the wall's point c,
 * V + ω × (c − P), replaces ẏ and θ̇_y R_y in ṅ and ṡ (eqs 11–13).  A
 * frictionless, cohesionless pair carries no shear force and no shear
 * dashpot, as between discs; rolling resistance acts with the common
 * radius 2 r of a disc on a wall (JYH eq. 11b).
 *
 * Besides the discs' sums it keeps, per wall, what the walls' controllers
 * and the reports read: the resultant force and moment of its contacts
 * (C&S Table 1), Σ F_n and Σ F_n s (s along the wall), and, in a stage
 * whose controller acts every cycle (walls.c), the dashpots' share of the
 * resultant and the contacts' normal stiffness Σ dF_n/dδ (the servo's
 * gain).  Walls are few and so are their contacts: one generic loop serves
 * every law, with every kernel (a switched-off one has zero parameters).
 */
#include <math.h>

#include "wall_loop.h"
#include "walls.h"

/* What touching contact c of disc i with wall W adds to their sums: the
 * force +(ftn e + fts t) on the wall and its opposite on the disc (C&S
 * Fig. 3), the shear force's moment on the disc, the rolling couple
 * M + M_d (−(M + M_d) on the disc, + on the wall: JYH eq. 52), the moment
 * about P on the wall, and the wall's Σ F_n and Σ F_n s (s along the wall
 * from P); (cx, cy) is the contact point on the wall. */
static inline __attribute__((always_inline)) void
add_forces(struct bal_sim *s, struct bal_wall *W, int i, double ex, double ey, double cx,
           double cy, double ftn, double fts, double mr, double md, const int roll)
{
    const double tx = ey, ty = -ex, ri = s->r[i];
    const double fcx = ftn * ex + fts * tx;
    const double fcy = ftn * ey + fts * ty;
    s->f[3 * i] -= fcx;
    s->f[3 * i + 1] -= fcy;
    s->f[3 * i + 2] += roll ? fts * ri - (mr + md) : fts * ri;
    W->f[0] += fcx;
    W->f[1] += fcy;
    W->moment += (cx - W->p[0]) * fcy - (cy - W->p[1]) * fcx;
    if (roll)
        W->moment += mr + md; /* the couple on the wall */
    const double along = (cx - W->p[0]) * W->e[0] + (cy - W->p[1]) * W->e[1];
    W->fn_sum += ftn;
    W->fn_s_sum += ftn * along;
}

void bal_wall_loop_run(struct bal_sim *s)
{
    struct bal_pairs *p = &s->pw;
    const struct bal_law_params P = bal_law_params_of(s);
    for (int k = 0; k < s->n_walls; k++) {
        struct bal_wall *W = &s->walls[k];
        W->f[0] = W->f[1] = W->moment = W->fn_sum = W->fn_s_sum = 0;
        W->dash_f[0] = W->dash_f[1] = W->dash_m = 0;
        W->stiffness = 0;
    }
    double lost_fric = 0, lost_roll = 0, wall_dash = 0;
    const int roll = p->rolling;
    /* the dashpots' resultant and the contacts' stiffness per wall, for
     * walls whose controller sets their velocity every cycle (walls.c); not
     * kept otherwise */
    const int track = s->walls_controlled != 0;
    for (long c = 0; c < p->n; c++) {
        const int i = p->i[c];
        struct bal_wall *W = &s->walls[p->j[c]];
        double cx, cy;
        const double d2 = bal_walls_closest(W, s->x[i], s->y[i], &cx, &cy);
        const double ri = s->r[i];
        if (d2 >= ri * ri) {
            p->fn[c] = p->fs[c] = p->dn[c] = p->ds[c] = 0;
            p->flags[c] = 0;
            if (roll) {
                p->mr[c] = p->tr[c] = 0;
                if (p->dm)
                    p->dm[c] = 0;
            }
            continue;
        }
        const struct bal_pair_law *L = &s->law[s->mat[i] * s->n_mat + W->material];
        double ex, ey;
        const double dist = sqrt(d2);
        if (dist > 0) {
            ex = (cx - s->x[i]) / dist;
            ey = (cy - s->y[i]) / dist;
        } else {
            /* Centre exactly on the wall: push along the wall's normal. */
            ex = -W->e[1];
            ey = W->e[0];
        }
        const double tx = ey, ty = -ex;
        const double wvx = W->v[0] - W->omega * (cy - W->p[1]);
        const double wvy = W->v[1] + W->omega * (cx - W->p[0]);
        const double rvx = s->vx[i] - wvx, rvy = s->vy[i] - wvy;
        struct bal_kin k;
        k.ndot = rvx * ex + rvy * ey;
        k.sdot = rvx * tx + rvy * ty - s->w[i] * ri;
        k.delta = ri - dist;
        if (k.delta > s->overlap_sieve)
            s->over_budget = 1;

        /* The chain of laws.h, every kernel: with the damping off its
         * coefficients are zero.  A frictionless, cohesionless pair carries
         * no shear force and no shear dashpot, as in the disc–disc loop. */
        const double fn = bal_law_normal(&P, L, &k, p->fn[c]);
        const double dn = bal_law_normal_dashpot(&P, L, &k);
        uint8_t flags = roll ? (uint8_t)(BAL_PAIR_TOUCHING | (p->flags[c] & BAL_PAIR_BROKEN))
                             : BAL_PAIR_TOUCHING;
        const double fs = L->shear ? bal_law_tangential(&P, L, &k, fn, p->fs[c], &lost_fric, &flags)
                                   : 0.0;
        const double ds = (!L->shear || (flags & BAL_PAIR_SLIDING)) ? 0.0
                                                                     : bal_law_shear_dashpot(L, &k);
        /* Rolling against a wall: the common radius is 2 r (JYH eq. 11b),
         * the relative rotation the disc's against the wall's. */
        double mr = 0, md = 0;
        if (roll && L->rolling > 0) {
            const struct bal_roll R = bal_law_roll_of(L, 2 * ri);
            const double wrel = s->w[i] - W->omega;
            const double dtheta = wrel * P.dt;
            p->tr[c] += dtheta;
            mr = bal_law_rolling(&P, R, fn, dtheta, p->mr[c], &lost_roll, &flags);
            p->mr[c] = mr;
            if (p->dm) {
                md = bal_law_rolling_dashpot(&P, L, R, k.delta, wrel, flags);
                p->dm[c] = md;
            }
        }
        if (s->dash) {
            /* the dashpots' share on the disc, and their power on the wall
             * side (its velocity is prescribed): energy.c */
            s->dash[3 * i] -= (float)(dn * ex + ds * tx);
            s->dash[3 * i + 1] -= (float)(dn * ey + ds * ty);
            s->dash[3 * i + 2] += (float)(roll ? ds * ri - md : ds * ri);
            wall_dash += dn * (wvx * ex + wvy * ey) + ds * (wvx * tx + wvy * ty);
            if (roll)
                wall_dash += md * W->omega;
            /* ... and their resultant on the wall, for a controller that
             * changes the wall's velocity (walls.c, bal_walls_control) */
            if (track) {
                const double dfx = dn * ex + ds * tx, dfy = dn * ey + ds * ty;
                W->dash_f[0] += dfx;
                W->dash_f[1] += dfy;
                W->dash_m += (cx - W->p[0]) * dfy - (cy - W->p[1]) * dfx + (roll ? md : 0);
            }
        }
        p->fn[c] = fn;
        p->fs[c] = fs;
        p->dn[c] = dn;
        p->ds[c] = ds;
        p->flags[c] = flags;
        add_forces(s, W, i, ex, ey, cx, cy, fn + dn, fs + ds, mr, md, roll);
        /* the servo's gain: dF_n/dδ of the wall's contacts (walls.c) */
        if (track)
            W->stiffness += bal_law_normal_stiffness(&P, L, fmax(k.delta, 0) / P.delta0);
    }
    s->audit.wall_dash = wall_dash;
    s->audit.d_friction += lost_fric;
    s->audit.d_rolling += lost_roll;
}
