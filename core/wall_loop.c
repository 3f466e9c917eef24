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

/* The disc–wall list once, compiled for each combination of what the
 * scene keeps (roll: the rolling history; dashed: the dashpots' share of
 * the sums, s->dash; track: the walls' dashpot resultant and stiffness, for
 * a controller acting every cycle), with the simulation's arrays in
 * restrict locals: through s, the compiler reloaded each array's address,
 * and each wall's geometry, after every store to a sum (callgrind, the
 * biaxial test of make bench: 275 instructions a candidate, 32 a
 * particle-step).  The arithmetic is the one of the law (laws.h), in the
 * same order: the same bits.
 *
 * At touching contact c of disc i with wall W: the force +(ftn e + fts t)
 * on the wall and its opposite on the disc (C&S Fig. 3), the shear force's
 * moment on the disc, the rolling couple M + M_d (−(M + M_d) on the disc,
 * + on the wall: JYH eq. 52), the moment about P on the wall, and the
 * wall's Σ F_n and Σ F_n s (s along the wall from P); (cx, cy) is the
 * contact point on the wall. */
static inline __attribute__((always_inline)) void
wall_contacts(struct bal_sim *restrict s, const int roll, const int dashed, const int track)
{
    struct bal_pairs *p = &s->pw;
    const struct bal_law_params P = bal_law_params_of(s);
    const long n = p->n;
    const int32_t *restrict pi = p->i, *restrict pj = p->j;
    double *restrict pfn = p->fn, *restrict pfs = p->fs, *restrict pdn = p->dn,
                     *restrict pds = p->ds;
    double *restrict pmr = p->mr, *restrict ptr = p->tr, *restrict pdm = p->dm;
    uint8_t *restrict pflags = p->flags;
    const double *restrict x = s->x, *restrict y = s->y, *restrict r = s->r;
    const double *restrict vx = s->vx, *restrict vy = s->vy, *restrict w = s->w;
    const int32_t *restrict mat = s->mat;
    const int n_mat = s->n_mat;
    const struct bal_pair_law *restrict law = s->law;
    double *restrict f = s->f;
    float *restrict dash = s->dash;
    struct bal_wall *restrict walls = s->walls;
    const double sieve = s->overlap_sieve;
    double lost_fric = 0, lost_roll = 0, wall_dash = 0;
    int over = 0;
    for (long c = 0; c < n; c++) {
        const int i = pi[c];
        struct bal_wall *restrict W = &walls[pj[c]];
        double cx, cy;
        const double xi = x[i], yi = y[i], ri = r[i];
        const double d2 = bal_walls_closest(W, xi, yi, &cx, &cy);
        if (d2 >= ri * ri) {
            pfn[c] = pfs[c] = pdn[c] = pds[c] = 0;
            pflags[c] = 0;
            if (roll) {
                pmr[c] = ptr[c] = 0;
                if (pdm)
                    pdm[c] = 0;
            }
            continue;
        }
        const struct bal_pair_law *L = &law[mat[i] * n_mat + W->material];
        double ex, ey;
        const double dist = sqrt(d2);
        if (dist > 0) {
            ex = (cx - xi) / dist;
            ey = (cy - yi) / dist;
        } else {
            /* Centre exactly on the wall: push along the wall's normal. */
            ex = -W->e[1];
            ey = W->e[0];
        }
        const double tx = ey, ty = -ex;
        const double px = W->p[0], py = W->p[1], omega = W->omega;
        const double wvx = W->v[0] - omega * (cy - py);
        const double wvy = W->v[1] + omega * (cx - px);
        const double rvx = vx[i] - wvx, rvy = vy[i] - wvy;
        struct bal_kin k;
        k.ndot = rvx * ex + rvy * ey;
        k.sdot = rvx * tx + rvy * ty - w[i] * ri;
        k.delta = ri - dist;
        over |= k.delta > sieve;

        /* The chain of laws.h, every kernel: with the damping off its
         * coefficients are zero.  A frictionless, cohesionless pair carries
         * no shear force and no shear dashpot, as in the disc–disc loop. */
        const double fn = bal_law_normal(&P, L, &k, pfn[c]);
        const double dn = bal_law_normal_dashpot(&P, L, &k);
        uint8_t flags = roll ? (uint8_t)(BAL_PAIR_TOUCHING | (pflags[c] & BAL_PAIR_BROKEN))
                             : BAL_PAIR_TOUCHING;
        const double fs = L->shear ? bal_law_tangential(&P, L, &k, fn, pfs[c], &lost_fric, &flags)
                                   : 0.0;
        const double ds = (!L->shear || (flags & BAL_PAIR_SLIDING)) ? 0.0
                                                                     : bal_law_shear_dashpot(L, &k);
        /* Rolling against a wall: the common radius is 2 r (JYH eq. 11b),
         * the relative rotation the disc's against the wall's. */
        double mr = 0, md = 0;
        if (roll && L->rolling > 0) {
            const struct bal_roll R = bal_law_roll_of(L, 2 * ri);
            const double wrel = w[i] - omega;
            const double dtheta = wrel * P.dt;
            ptr[c] += dtheta;
            mr = bal_law_rolling(&P, R, fn, dtheta, pmr[c], &lost_roll, &flags);
            pmr[c] = mr;
            if (pdm) {
                md = bal_law_rolling_dashpot(&P, L, R, k.delta, wrel, flags);
                pdm[c] = md;
            }
        }
        if (dashed) {
            /* the dashpots' share on the disc, and their power on the wall
             * side (its velocity is prescribed): energy.c */
            dash[3 * i] -= (float)(dn * ex + ds * tx);
            dash[3 * i + 1] -= (float)(dn * ey + ds * ty);
            dash[3 * i + 2] += (float)(roll ? ds * ri - md : ds * ri);
            wall_dash += dn * (wvx * ex + wvy * ey) + ds * (wvx * tx + wvy * ty);
            if (roll)
                wall_dash += md * omega;
            /* ... and their resultant on the wall, for a controller that
             * changes the wall's velocity (walls.c, bal_walls_control) */
            if (track) {
                const double dfx = dn * ex + ds * tx, dfy = dn * ey + ds * ty;
                W->dash_f[0] += dfx;
                W->dash_f[1] += dfy;
                W->dash_m += (cx - px) * dfy - (cy - py) * dfx + (roll ? md : 0);
            }
        }
        pfn[c] = fn;
        pfs[c] = fs;
        pdn[c] = dn;
        pds[c] = ds;
        pflags[c] = flags;
        /* the forces and moments (ftn = F_n + D_n, fts = F_s + D_s) */
        const double ftn = fn + dn, fts = fs + ds;
        const double fcx = ftn * ex + fts * tx;
        const double fcy = ftn * ey + fts * ty;
        f[3 * i] -= fcx;
        f[3 * i + 1] -= fcy;
        f[3 * i + 2] += roll ? fts * ri - (mr + md) : fts * ri;
        W->f[0] += fcx;
        W->f[1] += fcy;
        W->moment += (cx - px) * fcy - (cy - py) * fcx;
        if (roll)
            W->moment += mr + md; /* the couple on the wall */
        const double along = (cx - px) * W->e[0] + (cy - py) * W->e[1];
        W->fn_sum += ftn;
        W->fn_s_sum += ftn * along;
        /* the servo's gain: dF_n/dδ of the wall's contacts (walls.c) */
        if (track)
            W->stiffness += bal_law_normal_stiffness(&P, L, fmax(k.delta, 0) / P.delta0);
    }
    s->over_budget |= over;
    s->audit.wall_dash = wall_dash;
    s->audit.d_friction += lost_fric;
    s->audit.d_rolling += lost_roll;
}

void bal_wall_loop_run(struct bal_sim *s)
{
    for (int k = 0; k < s->n_walls; k++) {
        struct bal_wall *W = &s->walls[k];
        W->f[0] = W->f[1] = W->moment = W->fn_sum = W->fn_s_sum = 0;
        W->dash_f[0] = W->dash_f[1] = W->dash_m = 0;
        W->stiffness = 0;
    }
    /* the dashpots' resultant and the contacts' stiffness per wall, for
     * walls whose controller sets their velocity every cycle (walls.c); not
     * kept otherwise */
    const int roll = s->pw.rolling != 0, dashed = s->dash != NULL;
    const int track = s->walls_controlled != 0;
    if (roll) {
        if (dashed)
            track ? wall_contacts(s, 1, 1, 1) : wall_contacts(s, 1, 1, 0);
        else
            track ? wall_contacts(s, 1, 0, 1) : wall_contacts(s, 1, 0, 0);
    } else {
        if (dashed)
            track ? wall_contacts(s, 0, 1, 1) : wall_contacts(s, 0, 1, 0);
        else
            track ? wall_contacts(s, 0, 0, 1) : wall_contacts(s, 0, 0, 0);
    }
}
