/*
 * integrate.c — the law of motion, three ways, chosen per scene by
 * settings.integrator.  Each is a `struct bal_integrator_type` of two
 * halves: `positions` runs before the force evaluation of a cycle and
 * `velocities` after it (sim.c, the cycle).  Forces include the body
 * force m g scaled by the gravity ramp of the current stage (text after
 * C&S eq. 23a) and global damping C = α m, C* = α I (eq. 34), i.e. an
 * acceleration −α v, −α ω.  Held discs keep zero velocity and never move.
 *
 * centred (default) — the time-centred scheme of Cundall & Strack, eqs
 * (20)–(23a) with global damping in the form of eqs (35)–(36).  Velocities
 * live at half steps and positions at whole steps:
 *
 *   v_{N+1/2} = { v_{N−1/2} (1 − α Δt/2) + (ΣF_N/m + g) Δt } / (1 + α Δt/2)
 *   ω_{N+1/2} = { ω_{N−1/2} (1 − α Δt/2) + (ΣM_N/I) Δt } / (1 + α Δt/2)
 *   x_{N+1}   = x_N + v_{N+1/2} Δt,   θ_{N+1} = θ_N + ω_{N+1/2} Δt
 *
 * With α = 0 the update is eqs (22)–(23) exactly.  The initial velocities
 * of a scene are taken as v_{1/2}.  The contact law of cycle N reads
 * v_{N−1/2}.  Measurements want velocities at t_N, (v_{N−1/2} + v_{N+1/2})/2
 * (eq. 31); rather than keep a copy of v_{N−1/2} (24 bytes a disc),
 * bal_integrate_previous() recovers it from v_{N+1/2} and the force sums,
 * which stay in place until the next cycle.
 *
 * verlet — velocity Verlet, positions and velocities at whole steps.  With
 * A = ΣF/m + g and h = α Δt/2, cycle N is
 *
 *   positions:  v_{N−1/2} = v_{N−1} (1 − h) + A_{N−1} Δt/2   (first half kick)
 *               x_N       = x_{N−1} + v_{N−1/2} Δt
 *   forces at t_N from x_N and v_{N−1/2}
 *   velocities: v_N = (v_{N−1/2} + A_N Δt/2) / (1 + h)      (second half kick)
 *
 * The damping force −α m v is taken at the whole step v_N: explicitly in
 * the first half kick, implicitly (hence the division) in the second.  The
 * contact law reads v_{N−1/2} = v_{N−1} + a_{N−1} Δt/2, the velocity of the
 * first half kick (as LAMMPS' fix nve does): it is the exact mean velocity
 * over [t_{N−1}, t_N], so the incremental springs (F_n += k_n ṅ Δt,
 * F_s += k_s ṡ Δt) integrate the displacement increment to second order;
 * the dashpots see a velocity half a step old, as in the centred scheme.
 * The scene's initial velocities are v_0, the initial force sums zero (so
 * a_0 = g − α v_0: exact for discs that start apart).  Written out, the two
 * half kicks compose to eq. (35) and v_N = (v_{N−1/2} + v_{N+1/2})/2 is
 * eq. (31): the positions, the contact forces and the measured velocities
 * are those of the centred scheme in exact arithmetic; what differs is the
 * start (v_0 instead of v_{1/2}), the rounding, and that the stored
 * velocities are v_N.  A gravity ramp uses, in each half kick, the share
 * of the cycle in which the kick is taken.
 *
 * gear5 — Gear's predictor-corrector for second-order equations with six
 * values (x and its first five derivatives; Gear 1971, "Numerical initial
 * value problems in ordinary differential equations", Sec. 9.2; Allen &
 * Tildesley 1987, "Computer simulation of liquids", App. E, Table E.2),
 * the "fifth order Gear predictor-corrector" of MLH Sec. 5.3.  With scaled
 * derivatives r_k = x^(k) Δt^k / k! the predictor is the Taylor (Pascal)
 * step r_j ← Σ_{k≥j} C(k, j) r_k; the forces are evaluated at the
 * predicted x_N and v_N; the corrector adds c_k Δ to each r_k, where
 * Δ = a_N Δt²/2 − r_2^pred and
 *   c = (3/16, 251/360, 1, 11/18, 1/6, 1/60).
 * c_0 = 3/16 is Gear's value when the forces depend on the velocity (the
 * dashpots do; 3/20 for forces of the positions only).  Damping −α v and
 * the dashpots use the predicted v_N; so do the incremental springs, which
 * therefore integrate the displacement with an O(Δt) lag (first order).
 * Start: r_2 = (g − α v_0) Δt²/2 and r_3..r_5 = 0 on the first cycle
 * (exact for discs that start apart).  The forces are those of the
 * predicted positions; the stored positions and velocities after a cycle
 * are the corrected ones.  The derivative columns exist only for gear5.
 *
 * The position passes also track how far any disc has moved since the
 * neighbour lists were built, and return the two largest displacements
 * (each block's in par.block_sums): the cycle asks the neighbour search
 * whether the lists still hold (grid.c, bal_grid_due).
 *
 * Kept whole (about 740 lines, a third of them the derivations above): the
 * three laws of motion are rows of one table with the same two halves, and
 * they share the force-to-acceleration step, the gravity ramp, the held
 * components and the displacement tracking; a file per law would copy or
 * export those.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "integrate.h"

/* The two largest squared displacements since the last rebuild, kept in
 * the position loops: m1 >= m2.  Written as comparisons (min/max
 * instructions), not fmin/fmax, which are calls into libm here. */
static inline void track_moves(double d2, double *m1, double *m2)
{
    const double lo = d2 < *m1 ? d2 : *m1;
    *m2 = lo > *m2 ? lo : *m2;
    *m1 = d2 > *m1 ? d2 : *m1;
}

static inline int blocks_of(const struct bal_sim *s) { return s->n > 0 ? bal_disc_blocks(s->n) : 0; }

/* The two largest squared displacements, in a pass of their own (verlet and
 * gear5; centred keeps them in its position loop), and each block's. */
static struct bal_moves moved_scan(struct bal_sim *s)
{
    double m1 = 0, m2 = 0;
    if (s->use_grid)
        for (int b = 0; b < blocks_of(s); b++) {
            const int to = bal_block_end(s->n, b);
            double b1 = 0, b2 = 0;
            for (int i = b * BAL_DISC_BLOCK; i < to; i++)
                track_moves(bal_moved_sq(s, i), &b1, &b2);
            s->par.block_sums[2 * b] = b1;
            s->par.block_sums[2 * b + 1] = b2;
            track_moves(b1, &m1, &m2);
            track_moves(b2, &m1, &m2);
        }
    return (struct bal_moves){m1, m2};
}

/* ------------------------------------------------------------------ */
/* centred: C&S eqs (22)-(23a), (35)-(36)                              */
/* ------------------------------------------------------------------ */

/* The centred passes go through the discs in blocks of BAL_DISC_BLOCK; a
 * block's sums are its own, added up block after block, so that they are
 * the same on any number of threads (struct bal_par, state.h). */

/* Run body(s, b) for every block b, on s->par.threads threads. */
#define FOR_BLOCKS(s, b, body)                                                          \
    do {                                                                                \
        const int nb_ = blocks_of(s), th_ = (s)->par.threads < nb_ ? (s)->par.threads : nb_; \
        if (th_ > 1) {                                                                  \
            _Pragma("omp parallel for num_threads(th_) schedule(static)")               \
            for (int b = 0; b < nb_; b++)                                               \
                body;                                                                   \
        } else {                                                                        \
            for (int b = 0; b < nb_; b++)                                               \
                body;                                                                   \
        }                                                                               \
    } while (0)

/* Block b of the position pass; its two largest squared displacements since
 * the last rebuild into block_sums[2b], [2b + 1]. */
static void centred_positions_block(struct bal_sim *s, int b)
{
    const double dt = s->dt;
    const int from = b * BAL_DISC_BLOCK, to = bal_block_end(s->n, b);
    double *restrict x = s->x, *restrict y = s->y, *restrict th = s->th;
    const double *restrict vx = s->vx, *restrict vy = s->vy, *restrict w = s->w;
    const double *restrict xr = s->x_ref, *restrict yr = s->y_ref;
    double m1 = 0, m2 = 0;
    if (s->use_grid) {
        /* the displacement since the last rebuild in the same pass (the
         * expression of bal_moved_sq, on this loop's own pointers); two
         * discs at a time where SSE2 exists (the same IEEE operations lane
         * by lane), the largest kept disc by disc in order */
        int i = from;
#if defined(__SSE2__)
        const __m128d vdt = _mm_set1_pd(dt);
        for (; i + 1 < to; i += 2) {
            const __m128d xi = _mm_loadu_pd(x + i) + _mm_loadu_pd(vx + i) * vdt;
            const __m128d yi = _mm_loadu_pd(y + i) + _mm_loadu_pd(vy + i) * vdt;
            _mm_storeu_pd(x + i, xi);
            _mm_storeu_pd(y + i, yi);
            _mm_storeu_pd(th + i, _mm_loadu_pd(th + i) + _mm_loadu_pd(w + i) * vdt);
            const __m128d dx = xi - _mm_loadu_pd(xr + i), dy = yi - _mm_loadu_pd(yr + i);
            const __m128d d2 = dx * dx + dy * dy;
            track_moves(d2[0], &m1, &m2);
            track_moves(d2[1], &m1, &m2);
        }
#endif
        for (; i < to; i++) {
            x[i] += vx[i] * dt;
            y[i] += vy[i] * dt;
            th[i] += w[i] * dt;
            const double dx = x[i] - xr[i], dy = y[i] - yr[i];
            track_moves(dx * dx + dy * dy, &m1, &m2);
        }
    } else {
        for (int i = from; i < to; i++) {
            x[i] += vx[i] * dt;
            y[i] += vy[i] * dt;
            th[i] += w[i] * dt;
        }
    }
    s->par.block_sums[2 * b] = m1;
    s->par.block_sums[2 * b + 1] = m2;
}

static struct bal_moves centred_positions(struct bal_sim *s)
{
    FOR_BLOCKS(s, b, centred_positions_block(s, b));
    /* the two largest of all: the same whatever the blocks */
    double m1 = 0, m2 = 0;
    for (int b = 0; b < blocks_of(s); b++) {
        track_moves(s->par.block_sums[2 * b], &m1, &m2);
        track_moves(s->par.block_sums[2 * b + 1], &m1, &m2);
    }
    return (struct bal_moves){m1, m2};
}

/* A partly held disc's held components were zero in the last cycle too
 * (the force on them went into the hold, not into a velocity): the
 * `previous` of a scene with partly held discs (integrators_held below). */
static inline void zero_held(const struct bal_sim *s, int i, double *vx, double *vy, double *w)
{
    const unsigned h = s->hold[i];
    if (h & BAL_HOLD_X)
        *vx = 0;
    if (h & BAL_HOLD_Y)
        *vy = 0;
    if (h & BAL_HOLD_ROTATION)
        *w = 0;
}

static void centred_previous(const struct bal_sim *s, int i, double *vx, double *vy, double *w)
{
    if (s->fixed[i]) {
        *vx = *vy = *w = 0;
        return;
    }
    const double dt = s->dt, half = s->alpha * dt / 2;
    const double ax = s->f[3 * i] * s->inv_m[i] * dt + s->g[0] * s->gfac * dt;
    const double ay = s->f[3 * i + 1] * s->inv_m[i] * dt + s->g[1] * s->gfac * dt;
    const double aw = s->f[3 * i + 2] * s->inv_i[i] * dt;
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


/* The velocity update, and in the same pass the two sums the energy audit
 * needs at t_N, v_N = (v_{N-1/2} + v_{N+1/2})/2 (energy.c): with global
 * damping Σ (m v_N² + I ω_N²), with dashpots Σ (F^D·v_N + M^D ω_N) — both
 * in registers here, where a pass of their own would recover v_{N-1/2} from
 * the force sums again.  Compiled in four variants, as the pair loops; one
 * block at a time, its sums into block_sums[2b], [2b + 1]. */
/* One disc of the velocity update (centred_block's arrays and constants in
 * c). */
struct centred_args {
    double *restrict vx, *restrict vy, *restrict w;
    const double *restrict f, *restrict im, *restrict ii;
    const float *restrict dsh;
    const uint8_t *restrict fixed, *restrict hold;
    double dt, keep, scale, gxdt, gydt;
};

static inline __attribute__((always_inline)) void
centred_one(const struct centred_args *c, int i, const int damped, const int dashpots,
            const int held, double *glob, double *dash)
{
    double *restrict vx = c->vx, *restrict vy = c->vy, *restrict w = c->w;
    const double *restrict f = c->f, *restrict im = c->im, *restrict ii = c->ii;
    const uint8_t *restrict hold = c->hold;
    const double dt = c->dt, keep = c->keep, scale = c->scale, gxdt = c->gxdt, gydt = c->gydt;
    if (c->fixed[i])
        return;
    const double ox = vx[i], oy = vy[i], ow = w[i];
    if (damped) {
        vx[i] = (ox * keep + f[3 * i] * im[i] * dt + gxdt) * scale;
        vy[i] = (oy * keep + f[3 * i + 1] * im[i] * dt + gydt) * scale;
        w[i] = (ow * keep + f[3 * i + 2] * ii[i] * dt) * scale;
    } else {
        vx[i] = ox + (f[3 * i] * im[i] * dt + gxdt);
        vy[i] = oy + (f[3 * i + 1] * im[i] * dt + gydt);
        w[i] = ow + f[3 * i + 2] * ii[i] * dt;
    }
    if (held && hold[i]) {
        /* held components stay at zero (ox etc. are zero already): the
         * position pass then adds nothing to the held coordinates */
        if (hold[i] & BAL_HOLD_X)
            vx[i] = 0;
        if (hold[i] & BAL_HOLD_Y)
            vy[i] = 0;
        if (hold[i] & BAL_HOLD_ROTATION)
            w[i] = 0;
    }
    /* twice v_N */
    const double cx = ox + vx[i], cy = oy + vy[i], cw = ow + w[i];
    if (damped)
        *glob += (cx * cx + cy * cy) / im[i] + cw * cw / ii[i];
    if (dashpots) {
        const float *restrict dsh = c->dsh;
        *dash += (double)dsh[3 * i] * cx + (double)dsh[3 * i + 1] * cy + (double)dsh[3 * i + 2] * cw;
    }
}

static inline __attribute__((always_inline)) void
centred_block(struct bal_sim *s, int b, const int damped, const int dashpots, const int held)
{
    const int from = b * BAL_DISC_BLOCK, to = bal_block_end(s->n, b);
    const double dt = s->dt;
    const double half = s->alpha * dt / 2;
    const double keep = 1 - half, scale = 1 / (1 + half);
    const double gxdt = s->g[0] * s->gfac * dt, gydt = s->g[1] * s->gfac * dt;
    double *restrict vx = s->vx, *restrict vy = s->vy, *restrict w = s->w;
    const double *restrict f = s->f;
    const double *restrict im = s->inv_m, *restrict ii = s->inv_i;
    const float *restrict dsh = s->dash;
    const uint8_t *restrict fixed = s->fixed;
    const struct centred_args c = {vx, vy, w, f, im, ii, dsh, fixed, s->hold,
                                   dt, keep, scale, gxdt, gydt};
    double glob = 0, dash = 0;
    int i = from;
#if defined(__SSE2__)
    /* Two discs at a time where neither is fixed nor held (SSE2: the same
     * IEEE operations lane by lane), the sums added disc by disc in
     * order; the others, and the last, one at a time below. */
    if (!held) {
        const __m128d vdt = _mm_set1_pd(dt);
        for (; i + 1 < to; i += 2) {
            if (fixed[i] | fixed[i + 1]) {
                centred_one(&c, i, damped, dashpots, 0, &glob, &dash);
                centred_one(&c, i + 1, damped, dashpots, 0, &glob, &dash);
                continue;
            }
            const __m128d ox = _mm_loadu_pd(vx + i), oy = _mm_loadu_pd(vy + i);
            const __m128d ow = _mm_loadu_pd(w + i);
            const __m128d imi = _mm_loadu_pd(im + i), iii = _mm_loadu_pd(ii + i);
            const __m128d fx = {f[3 * i], f[3 * i + 3]}, fy = {f[3 * i + 1], f[3 * i + 4]};
            const __m128d fw = {f[3 * i + 2], f[3 * i + 5]};
            __m128d nx, ny, nw;
            if (damped) {
                nx = (ox * keep + fx * imi * vdt + gxdt) * scale;
                ny = (oy * keep + fy * imi * vdt + gydt) * scale;
                nw = (ow * keep + fw * iii * vdt) * scale;
            } else {
                nx = ox + (fx * imi * vdt + gxdt);
                ny = oy + (fy * imi * vdt + gydt);
                nw = ow + fw * iii * vdt;
            }
            _mm_storeu_pd(vx + i, nx);
            _mm_storeu_pd(vy + i, ny);
            _mm_storeu_pd(w + i, nw);
            /* twice v_N */
            const __m128d cx = ox + nx, cy = oy + ny, cw = ow + nw;
            if (damped) {
                const __m128d t = (cx * cx + cy * cy) / imi + cw * cw / iii;
                glob += t[0];
                glob += t[1];
            }
            if (dashpots) {
                const __m128d d0 = {(double)dsh[3 * i], (double)dsh[3 * i + 3]};
                const __m128d d1 = {(double)dsh[3 * i + 1], (double)dsh[3 * i + 4]};
                const __m128d d2 = {(double)dsh[3 * i + 2], (double)dsh[3 * i + 5]};
                const __m128d t = d0 * cx + d1 * cy + d2 * cw;
                dash += t[0];
                dash += t[1];
            }
        }
    }
#endif
    for (; i < to; i++)
        centred_one(&c, i, damped, dashpots, held, &glob, &dash);
    s->par.block_sums[2 * b] = glob;
    s->par.block_sums[2 * b + 1] = dash;
}

static inline __attribute__((always_inline)) void
centred_update(struct bal_sim *s, const int damped, const int dashpots, const int held)
{
    FOR_BLOCKS(s, b, centred_block(s, b, damped, dashpots, held));
    double glob = 0, dash = 0;
    for (int b = 0; b < blocks_of(s); b++) {
        glob += s->par.block_sums[2 * b];
        dash += s->par.block_sums[2 * b + 1];
    }
    s->audit.glob_sum = 0.25 * glob;
    s->audit.dash_sum = 0.5 * dash;
}

/* The variants with partly held discs, out of line: the usual four keep
 * the code they had. */
static __attribute__((noinline)) void centred_velocities_held(struct bal_sim *s)
{
    const int damped = s->alpha != 0, dashpots = s->dash != NULL;
    if (damped && dashpots)
        centred_update(s, 1, 1, 1);
    else if (damped)
        centred_update(s, 1, 0, 1);
    else if (dashpots)
        centred_update(s, 0, 1, 1);
    else
        centred_update(s, 0, 0, 1);
}

static void centred_velocities(struct bal_sim *s)
{
    const int damped = s->alpha != 0, dashpots = s->dash != NULL;
    if (s->hold)
        centred_velocities_held(s);
    else if (damped && dashpots)
        centred_update(s, 1, 1, 0);
    else if (damped)
        centred_update(s, 1, 0, 0);
    else if (dashpots)
        centred_update(s, 0, 1, 0);
    else
        centred_update(s, 0, 0, 0);
}

/* ------------------------------------------------------------------ */
/* verlet: velocity Verlet, damping at whole steps                     */
/* ------------------------------------------------------------------ */

/* First half kick with the force sums of the last cycle, then the drift;
 * `held`: the variant that keeps the held components of partly held discs
 * at zero (their coordinates then stay). */
static inline __attribute__((always_inline)) struct bal_moves
verlet_positions_with(struct bal_sim *s, const int held)
{
    const int n = s->n;
    const double dt = s->dt, hdt = dt / 2;
    const double keep = 1 - s->alpha * dt / 2;
    const double gx = s->g[0] * s->gfac, gy = s->g[1] * s->gfac;
    double *restrict x = s->x, *restrict y = s->y, *restrict th = s->th;
    double *restrict vx = s->vx, *restrict vy = s->vy, *restrict w = s->w;
    const double *restrict f = s->f;
    const double *restrict im = s->inv_m, *restrict ii = s->inv_i;
    const uint8_t *restrict fixed = s->fixed;
    const uint8_t *restrict hold = s->hold;
    for (int i = 0; i < n; i++) {
        if (fixed[i])
            continue;
        vx[i] = vx[i] * keep + (f[3 * i] * im[i] + gx) * hdt;
        vy[i] = vy[i] * keep + (f[3 * i + 1] * im[i] + gy) * hdt;
        w[i] = w[i] * keep + f[3 * i + 2] * ii[i] * hdt;
        if (held && hold[i]) {
            if (hold[i] & BAL_HOLD_X)
                vx[i] = 0;
            if (hold[i] & BAL_HOLD_Y)
                vy[i] = 0;
            if (hold[i] & BAL_HOLD_ROTATION)
                w[i] = 0;
        }
        x[i] += vx[i] * dt;
        y[i] += vy[i] * dt;
        th[i] += w[i] * dt;
    }
    return moved_scan(s);
}

static __attribute__((noinline)) struct bal_moves verlet_positions_held(struct bal_sim *s)
{
    return verlet_positions_with(s, 1);
}

static struct bal_moves verlet_positions(struct bal_sim *s)
{
    return s->hold ? verlet_positions_held(s) : verlet_positions_with(s, 0);
}

/* Second half kick with the force sums of this cycle. */
static inline __attribute__((always_inline)) void verlet_velocities_with(struct bal_sim *s,
                                                                         const int held)
{
    const int n = s->n;
    const double hdt = s->dt / 2;
    const double scale = 1 / (1 + s->alpha * s->dt / 2);
    const double gx = s->g[0] * s->gfac, gy = s->g[1] * s->gfac;
    double *restrict vx = s->vx, *restrict vy = s->vy, *restrict w = s->w;
    const double *restrict f = s->f;
    const double *restrict im = s->inv_m, *restrict ii = s->inv_i;
    const uint8_t *restrict fixed = s->fixed;
    const uint8_t *restrict hold = s->hold;
    for (int i = 0; i < n; i++) {
        if (fixed[i])
            continue;
        vx[i] = (vx[i] + (f[3 * i] * im[i] + gx) * hdt) * scale;
        vy[i] = (vy[i] + (f[3 * i + 1] * im[i] + gy) * hdt) * scale;
        w[i] = (w[i] + f[3 * i + 2] * ii[i] * hdt) * scale;
        if (held && hold[i]) {
            if (hold[i] & BAL_HOLD_X)
                vx[i] = 0;
            if (hold[i] & BAL_HOLD_Y)
                vy[i] = 0;
            if (hold[i] & BAL_HOLD_ROTATION)
                w[i] = 0;
        }
    }
}

static __attribute__((noinline)) void verlet_velocities_held(struct bal_sim *s)
{
    verlet_velocities_with(s, 1);
}

static void verlet_velocities(struct bal_sim *s)
{
    if (s->hold)
        verlet_velocities_held(s);
    else
        verlet_velocities_with(s, 0);
}

/* v_{N-1/2}, by inverting the second half kick. */
static void verlet_previous(const struct bal_sim *s, int i, double *vx, double *vy, double *w)
{
    if (s->fixed[i]) {
        *vx = *vy = *w = 0;
        return;
    }
    const double hdt = s->dt / 2, undo = 1 + s->alpha * s->dt / 2;
    *vx = s->vx[i] * undo - (s->f[3 * i] * s->inv_m[i] + s->g[0] * s->gfac) * hdt;
    *vy = s->vy[i] * undo - (s->f[3 * i + 1] * s->inv_m[i] + s->g[1] * s->gfac) * hdt;
    *w = s->w[i] * undo - s->f[3 * i + 2] * s->inv_i[i] * hdt;
}

/* ------------------------------------------------------------------ */
/* gear5: Gear's six-value predictor-corrector                         */
/* ------------------------------------------------------------------ */

/* Column offsets (in units of n) into s->gear: r2..r5 of x, y, θ; the
 * predicted velocities; scratch. */
enum { GEAR_R2 = 0, GEAR_R3 = 3, GEAR_R4 = 6, GEAR_R5 = 9, GEAR_VP = 12, GEAR_SCRATCH = 15 };

/* Corrector coefficients for second-order equations, six values, forces
 * that depend on the velocity (Allen & Tildesley 1987, Table E.2). */
#define GEAR_C0 (3.0 / 16.0)
#define GEAR_C1 (251.0 / 360.0)
#define GEAR_C3 (11.0 / 18.0)
#define GEAR_C4 (1.0 / 6.0)
#define GEAR_C5 (1.0 / 60.0)

static inline double *gear_col(const struct bal_sim *s, int c)
{
    return s->gear + (size_t)c * (size_t)s->n;
}

/* The Taylor step of one coordinate q with velocity v and scaled
 * derivatives r2..r5 (each line uses only values not yet advanced). */
static inline void gear_predict(double *q, double *v, double *r2, double *r3, double *r4,
                                double *r5, double dt, double inv_dt)
{
    *q += *v * dt + *r2 + *r3 + *r4 + *r5;
    *v += (2 * *r2 + 3 * *r3 + 4 * *r4 + 5 * *r5) * inv_dt;
    *r2 += 3 * *r3 + 6 * *r4 + 10 * *r5;
    *r3 += 4 * *r4 + 10 * *r5;
    *r4 += 5 * *r5;
}

static inline void gear_correct(double *q, double *v, double *r2, double *r3, double *r4,
                                double *r5, double acc, double half_dt2, double inv_dt)
{
    const double d = acc * half_dt2 - *r2;
    *q += GEAR_C0 * d;
    *v += GEAR_C1 * d * inv_dt;
    *r2 += d;
    *r3 += GEAR_C3 * d;
    *r4 += GEAR_C4 * d;
    *r5 += GEAR_C5 * d;
}

/* Start-up: a_0 without contact forces, higher derivatives zero. */
static void gear_start(struct bal_sim *s)
{
    const double half_dt2 = s->dt * s->dt / 2;
    double *r2x = gear_col(s, GEAR_R2), *r2y = gear_col(s, GEAR_R2 + 1);
    double *r2t = gear_col(s, GEAR_R2 + 2);
    for (int i = 0; i < s->n; i++) {
        if (s->fixed[i])
            continue;
        r2x[i] = (s->g[0] * s->gfac - s->alpha * s->vx[i]) * half_dt2;
        r2y[i] = (s->g[1] * s->gfac - s->alpha * s->vy[i]) * half_dt2;
        r2t[i] = -s->alpha * s->w[i] * half_dt2;
        /* a held component keeps all its derivatives at zero: the predictor
         * then leaves it, and the corrector skips it */
        const unsigned h = s->hold ? s->hold[i] : 0;
        if (h & BAL_HOLD_X)
            r2x[i] = 0;
        if (h & BAL_HOLD_Y)
            r2y[i] = 0;
        if (h & BAL_HOLD_ROTATION)
            r2t[i] = 0;
    }
    s->gear_started = 1;
}

static struct bal_moves gear_positions(struct bal_sim *s)
{
    if (!s->gear_started)
        gear_start(s);
    const int n = s->n;
    const double dt = s->dt, inv_dt = 1 / s->dt;
    double *q[3] = {s->x, s->y, s->th}, *v[3] = {s->vx, s->vy, s->w};
    for (int k = 0; k < 3; k++) {
        double *restrict qk = q[k], *restrict vk = v[k];
        double *restrict r2 = gear_col(s, GEAR_R2 + k), *restrict r3 = gear_col(s, GEAR_R3 + k);
        double *restrict r4 = gear_col(s, GEAR_R4 + k), *restrict r5 = gear_col(s, GEAR_R5 + k);
        double *restrict vp = gear_col(s, GEAR_VP + k);
        const uint8_t *restrict fixed = s->fixed;
        for (int i = 0; i < n; i++) {
            if (fixed[i])
                continue;
            gear_predict(&qk[i], &vk[i], &r2[i], &r3[i], &r4[i], &r5[i], dt, inv_dt);
            vp[i] = vk[i];
        }
    }
    return moved_scan(s);
}

static inline __attribute__((always_inline)) void gear_velocities_with(struct bal_sim *s,
                                                                       const int held)
{
    const int n = s->n;
    const double half_dt2 = s->dt * s->dt / 2, inv_dt = 1 / s->dt, alpha = s->alpha;
    double *q[3] = {s->x, s->y, s->th}, *v[3] = {s->vx, s->vy, s->w};
    const double *inv[3] = {s->inv_m, s->inv_m, s->inv_i};
    const double g[3] = {s->g[0] * s->gfac, s->g[1] * s->gfac, 0};
    for (int k = 0; k < 3; k++) {
        double *restrict qk = q[k], *restrict vk = v[k];
        double *restrict r2 = gear_col(s, GEAR_R2 + k), *restrict r3 = gear_col(s, GEAR_R3 + k);
        double *restrict r4 = gear_col(s, GEAR_R4 + k), *restrict r5 = gear_col(s, GEAR_R5 + k);
        const double *restrict fk = s->f + k, *restrict ik = inv[k];
        const uint8_t *restrict fixed = s->fixed;
        const uint8_t *restrict hold = s->hold;
        const unsigned bit = 1u << k; /* BAL_HOLD_X, _Y, _ROTATION (asserted below) */
        const double gk = g[k];
        for (int i = 0; i < n; i++) {
            if (fixed[i] || (held && (hold[i] & bit)))
                continue;
            const double acc = fk[3 * i] * ik[i] + gk - alpha * vk[i];
            gear_correct(&qk[i], &vk[i], &r2[i], &r3[i], &r4[i], &r5[i], acc, half_dt2, inv_dt);
        }
    }
}

_Static_assert(BAL_HOLD_X == 1u << 0 && BAL_HOLD_Y == 1u << 1 && BAL_HOLD_ROTATION == 1u << 2,
               "gear5 finds the hold bit of coordinate k (x, y, θ) as 1 << k");

static __attribute__((noinline)) void gear_velocities_held(struct bal_sim *s)
{
    gear_velocities_with(s, 1);
}

static void gear_velocities(struct bal_sim *s)
{
    if (s->hold)
        gear_velocities_held(s);
    else
        gear_velocities_with(s, 0);
}

static void gear_previous(const struct bal_sim *s, int i, double *vx, double *vy, double *w)
{
    *vx = gear_col(s, GEAR_VP)[i];
    *vy = gear_col(s, GEAR_VP + 1)[i];
    *w = gear_col(s, GEAR_VP + 2)[i];
}

/* ------------------------------------------------------------------ */
/* The table, the dispatch and the life cycle                          */
/* ------------------------------------------------------------------ */

static const struct bal_integrator_type integrators[] = {
    [BAL_INTEGRATOR_CENTRED] = {"centred", centred_positions, centred_velocities,
                                centred_previous, 1},
    [BAL_INTEGRATOR_VERLET] = {"verlet", verlet_positions, verlet_velocities, verlet_previous, 0},
    [BAL_INTEGRATOR_GEAR5] = {"gear5", gear_positions, gear_velocities, gear_previous, 0},
};

/* With partly held discs: the velocities the contact law read are zero in
 * the held components (centred and verlet recover them by inverting the
 * last update, which the hold overrode; gear5 stores them, zero).  A table
 * of its own, so that the reports of other scenes test nothing. */
static void centred_previous_held(const struct bal_sim *s, int i, double *vx, double *vy, double *w)
{
    centred_previous(s, i, vx, vy, w);
    zero_held(s, i, vx, vy, w);
}

static void verlet_previous_held(const struct bal_sim *s, int i, double *vx, double *vy, double *w)
{
    verlet_previous(s, i, vx, vy, w);
    zero_held(s, i, vx, vy, w);
}

static const struct bal_integrator_type integrators_held[] = {
    [BAL_INTEGRATOR_CENTRED] = {"centred", centred_positions, centred_velocities,
                                centred_previous_held, 1},
    [BAL_INTEGRATOR_VERLET] = {"verlet", verlet_positions, verlet_velocities,
                               verlet_previous_held, 0},
    [BAL_INTEGRATOR_GEAR5] = {"gear5", gear_positions, gear_velocities, gear_previous, 0},
};

struct bal_moves bal_integrate_positions(struct bal_sim *s) { return s->integ->positions(s); }

void bal_integrate_velocities(struct bal_sim *s) { s->integ->velocities(s); }

void bal_integrate_previous(const struct bal_sim *s, int i, double *vx, double *vy, double *w)
{
    s->integ->previous(s, i, vx, vy, w);
}

enum bal_status bal_integrate_setup(struct bal_sim *s, struct bal_error *err)
{
    const int which = s->scene->settings.integrator;
    s->integ = &(s->hold ? integrators_held : integrators)[which >= 0 && which <= BAL_INTEGRATOR_GEAR5
                                                                  ? which
                                                                  : 0];
    s->par.block_sums = calloc(2 * (size_t)bal_disc_blocks(s->n), sizeof(double));
    if (!s->par.block_sums)
        return bal_error(err, BAL_ENOMEM, "%s: out of memory (%d discs)", s->scene->path, s->n);
    if (which != BAL_INTEGRATOR_GEAR5)
        return BAL_OK;
    const size_t n = (size_t)(s->n ? s->n : 1);
    s->gear = calloc(BAL_GEAR_COLUMNS * n, sizeof *s->gear);
    if (!s->gear)
        return bal_error(err, BAL_ENOMEM, "%s: out of memory for gear5 (%d discs)",
                         s->scene->path, s->n);
    return BAL_OK;
}

void bal_integrate_free(struct bal_sim *s)
{
    free(s->gear);
    s->gear = NULL;
}

void bal_integrate_reordered(struct bal_sim *s)
{
    if (!s->gear || s->n < 2)
        return;
    const int n = s->n;
    double *restrict t = gear_col(s, GEAR_SCRATCH);
    for (int c = 0; c < GEAR_SCRATCH; c++) {
        double *restrict a = gear_col(s, c);
        for (int i = 0; i < n; i++)
            t[i] = a[s->new2old[i]];
        memcpy(a, t, (size_t)n * sizeof *a);
    }
}
