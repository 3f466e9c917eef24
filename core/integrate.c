/*
 * integrate.c — the time-centred scheme of Cundall & Strack, eqs (20)–(23a)
 * with global damping in the form of eqs (35)–(36).
 *
 * Velocities live at half steps and positions at whole steps:
 *
 *   v_{N+1/2} = { v_{N−1/2} (1 − α Δt/2) + (ΣF_N/m + g) Δt } / (1 + α Δt/2)
 *   ω_{N+1/2} = { ω_{N−1/2} (1 − α Δt/2) + (ΣM_N/I) Δt } / (1 + α Δt/2)
 *   x_{N+1}   = x_N + v_{N+1/2} Δt,   θ_{N+1} = θ_N + ω_{N+1/2} Δt
 *
 * The body force m g is added to the force sum (text after eq. 23a),
 * scaled by the gravity ramp of the current stage; with
 * C = α m and C* = α I (eq. 34) the mass cancels.  With α = 0 the update is
 * eqs (22)–(23) exactly.  Held discs keep zero velocity.
 *
 * The position update also tracks how far any disc has moved since the
 * neighbour list was built, which decides when it is rebuilt (grid.c).
 *
 * Measurements want velocities at t_N, (v_{N-1/2} + v_{N+1/2})/2 (eq. 31);
 * rather than keep a copy of v_{N-1/2} (24 bytes a disc),
 * bal_integrate_previous() recovers it from v_{N+1/2} and the force sums,
 * which stay in place until the next cycle.
 */
#include <math.h>
#include <string.h>

#include "sim.h"

void bal_integrate_positions(struct bal_sim *s)
{
    const double dt = s->dt;
    const int n = s->n;
    double *restrict x = s->x, *restrict y = s->y, *restrict th = s->th;
    const double *restrict vx = s->vx, *restrict vy = s->vy, *restrict w = s->w;
    for (int i = 0; i < n; i++) {
        x[i] += vx[i] * dt;
        y[i] += vy[i] * dt;
        th[i] += w[i] * dt;
    }
    bal_walls_move(s);
    if (!s->use_grid)
        return;

    /* Rebuild when two discs may have closed the skin between them, or a
     * disc and a wall. */
    const double *restrict xr = s->x_ref, *restrict yr = s->y_ref;
    double d2max = 0;
    for (int i = 0; i < n; i++) {
        const double dx = x[i] - xr[i], dy = y[i] - yr[i];
        const double d2 = dx * dx + dy * dy;
        d2max = d2 > d2max ? d2 : d2max;
    }
    const double dmax = sqrt(d2max);
    double wmax = 0;
    for (int k = 0; k < s->n_walls; k++)
        wmax = fmax(wmax, s->walls[k].disp);
    if (2 * dmax >= s->skin || dmax + wmax >= s->skin)
        s->need_rebuild = 1;
}

void bal_integrate_previous(const struct bal_sim *s, int i, double *vx, double *vy, double *w)
{
    if (s->fixed[i]) {
        *vx = *vy = *w = 0;
        return;
    }
    const double dt = s->dt, half = s->alpha * dt / 2;
    const double ax = s->fx[i] * s->inv_m[i] * dt + s->g[0] * s->gfac * dt;
    const double ay = s->fy[i] * s->inv_m[i] * dt + s->g[1] * s->gfac * dt;
    const double aw = s->tq[i] * s->inv_i[i] * dt;
    if (half == 0) {
        *vx = s->vx[i] - ax;
        *vy = s->vy[i] - ay;
        *w = s->w[i] - aw;
        return;
    }
    *vx = (s->vx[i] * (1 + half) - ax) / (1 - half);
    *vy = (s->vy[i] * (1 + half) - ay) / (1 - half);
    *w = (s->w[i] * (1 + half) - aw) / (1 - half);
}

void bal_integrate_velocities(struct bal_sim *s)
{
    const int n = s->n;
    const double dt = s->dt;
    const double half = s->alpha * dt / 2;
    const double keep = 1 - half, scale = 1 / (1 + half);
    const double gxdt = s->g[0] * s->gfac * dt, gydt = s->g[1] * s->gfac * dt;
    double *restrict vx = s->vx, *restrict vy = s->vy, *restrict w = s->w;
    const double *restrict fx = s->fx, *restrict fy = s->fy, *restrict tq = s->tq;
    const double *restrict im = s->inv_m, *restrict ii = s->inv_i;
    const uint8_t *restrict fixed = s->fixed;
    if (half == 0) {
        for (int i = 0; i < n; i++) {
            if (fixed[i])
                continue;
            vx[i] += fx[i] * im[i] * dt + gxdt;
            vy[i] += fy[i] * im[i] * dt + gydt;
            w[i] += tq[i] * ii[i] * dt;
        }
        return;
    }
    for (int i = 0; i < n; i++) {
        if (fixed[i])
            continue;
        vx[i] = (vx[i] * keep + fx[i] * im[i] * dt + gxdt) * scale;
        vy[i] = (vy[i] * keep + fy[i] * im[i] * dt + gydt) * scale;
        w[i] = (w[i] * keep + tq[i] * ii[i] * dt) * scale;
    }
}
