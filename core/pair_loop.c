/*
 * pair_loop.c — the disc–disc loop: the force–displacement law (the kernels
 * of laws.h) at every contact of the candidate list of pairs.c, once per
 * cycle, and the table of its variants (Cundall & Strack eqs 8–19, 24–28;
 * Matuttis, Luding & Herrmann eqs 2–3).  The disc–wall loop is
 * wall_loop.c's; how the list is shared between threads, threads.c's.
 *
 * Kept whole (about 780 lines, a third of them comments): each variant of
 * the table at the end compiles the passes above it with its own constant
 * MOD_* bits (inline functions, always inlined), so the passes and the
 * table must be one translation unit, and the passes read as one piece.
 *
 * For a contact between discs x and y (x = the lower index):
 *
 *   e  = (y − x)/D, t = (e2, −e1)                          C&S eqs (9)–(10)
 *   ṅ  = (ẋ − ẏ)·e                                          eq. (12)
 *   ṡ  = (ẋ − ẏ)·t − (θ̇_x R_x + θ̇_y R_y)                    eq. (13)
 *   F_n += k_n ṅ Δt  (incremental law)                      eqs (14), (16), (18)
 *   F_n  = k_n δ0 (δ/δ0)^ν, δ = R_x + R_y − D (power law)   MLH eq. (2)
 *   F_s += k_s ṡ Δt, |F_s| ≤ F_n tan φ_μ + c                 eqs (15), (17)–(19)
 *   D_n = c_n ṅ, D_s = c_s ṡ (0 while sliding)              eqs (26)–(28)
 *   D_n += γ_n ṅ (δ/δ0)^ψ (viscous normal force)           MLH eq. (3)
 *
 * F_n + D_n and F_s + D_s act on x in the directions −e and −t (Fig. 3);
 * the moment on x and on y is (F_s + D_s) R (the text after eq. 19).
 *
 * Choices the paper leaves open, written down here:
 * - A contact exists while D < R_x + R_y (eq. 8, strict); when it opens its
 *   history is reset to zero, so a new contact starts from F_n = F_s = 0 and
 *   its first increment is k_n ṅ Δt, exactly as in the worked example of
 *   Fig. 1 (eqs 1, 5–7).
 * - The incremental F_n never becomes tensile: it is kept ≥ 0 (cohesion acts
 *   only through the shear limit of eq. 19).  Dashpot forces are not
 *   clipped, as in the paper.
 * - The Coulomb limit uses the elastic F_n (eq. 19).
 * - A pair with tan φ_μ = 0 and c = 0 carries no shear force and no shear
 *   dashpot (it would slide at any tangential motion) and is not flagged
 *   as sliding.
 *
 * Velocities are those at t_{N−1/2} (C&S eqs 26–27 note the half step).
 *
 * Variants.  The loop is compiled once per combination of the normal law
 * and the optional sub-models (MOD_* bits: tangential, damping, rolling;
 * PAIR_VARIANT, twelve in all), and one is chosen when the simulation is
 * created (bal_pair_loop_select), so a scene without friction or damping
 * never runs their code or touches their history.  Within a variant, a
 * scene of one material, and one of one material with the linear power
 * law, get loops of their own (no test of the material or of ν at each
 * contact).
 *
 * Passes.  The list is taken in chunks of BAL_PAIRS_CHUNK candidates, three
 * passes each: which candidates touch (no branch on the answer), then D and
 * e of the touching ones two at a time (SSE2: the same IEEE results), then
 * the chain of kernels at each contact, in the list's order, so the force
 * sums add the same terms in the same order as one pass would
 * (docs/benchmarks.md, speed round two).  The chain is one_contact(), what
 * a contact adds to the sums add_side().
 *
 * Two at a time.  The linear power law (ν = 1) on discs of one material,
 * the catalogue's commonest (the race, the biaxial test, the piles), takes
 * its contacts two at a time in the third pass, D and e included
 * (two_at_a_time), with whatever sub-models the variant has (tangential
 * spring, dashpots and viscous damping, rolling resistance of Model 1 or
 * 2; issue 33; before it, the tangential spring alone): the kernels are the
 * _x2 twins of those the one-contact chain calls, compiled from the same
 * source (laws_lanes.h), so the same bits, and an edit of a kernel reaches
 * both.  The sums and the losses are then added contact by contact in the
 * list's order.  Every variant's loop is held to its one-contact run byte
 * for byte (check_contacts.c, contacts_every_variant_same_at_both_widths),
 * and the catalogue's case `coulomb` checks eq. (19) on scenes that run it.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "pair_loop.h"
#include "pairs.h"
#include "threads.h"

/* D = sqrt(D²) and e = (dx, dy)/D of the n touching contacts of a chunk,
 * in place (q holds D², then D; ex, ey hold dx, dy, then e): two contacts
 * per instruction where SSE2 exists (every x86-64), one otherwise; the same
 * correctly rounded results either way.  The arrays have room for one more
 * entry, padded with harmless values.  The square root and the two
 * divisions share one divider, which the packed instructions use about as
 * long as the scalar ones; in a pass of their own, many are in flight at
 * once (AVX, four at a time, was tried: no faster, docs/benchmarks.md). */
static inline __attribute__((always_inline)) void
unit_vectors(double *restrict q, double *restrict ex, double *restrict ey, int n)
{
#if defined(__SSE2__)
    q[n] = 1;
    ex[n] = ey[n] = 0;
    for (int k = 0; k < n; k += 2) {
        const __m128d d = _mm_sqrt_pd(_mm_loadu_pd(q + k));
        _mm_storeu_pd(q + k, d);
        _mm_storeu_pd(ex + k, _mm_div_pd(_mm_loadu_pd(ex + k), d));
        _mm_storeu_pd(ey + k, _mm_div_pd(_mm_loadu_pd(ey + k), d));
    }
#else
    for (int k = 0; k < n; k++) {
        q[k] = sqrt(q[k]);
        ex[k] /= q[k];
        ey[k] /= q[k];
    }
#endif
}

/* What a variant of the disc–disc loop is compiled with (PAIR_VARIANT),
 * one bit each: the power law (else the incremental one), the tangential
 * kernel, the damping kernels, the rolling kernel (only with the tangential
 * one: it reads the spins that kernel reads).  A new sub-model is one more
 * bit.  MOD_ROLL2, rolling resistance of Model 2, is not a variant of the
 * table: a rolling variant's ranges are compiled for each model
 * (pair_range), so that Model 1, whose contacts are never BROKEN, reads no
 * BROKEN flag and masks no lane. */
enum { MOD_POWER = 1, MOD_SHEAR = 2, MOD_DAMP = 4, MOD_ROLL = 8, MOD_ROLL2 = 16 };

/* Zero the force sums of discs from..to (inclusive). */
static inline __attribute__((always_inline)) void
clear_sums(double *restrict f, float *restrict dsh, int from, int to, const int damp)
{
    for (int k = from; k <= to; k++) {
        f[3 * k] = 0;
        f[3 * k + 1] = 0;
        f[3 * k + 2] = 0;
        if (damp) {
            dsh[3 * k] = 0;
            dsh[3 * k + 1] = 0;
            dsh[3 * k + 2] = 0;
        }
    }
}

/* Where a run of chunks left off. */
struct range_state {
    long c0;     /* the next chunk */
    int cleared; /* the sums of discs 0..cleared are started (or not this range's) */
    int over;    /* an overlap past the sieve */
    long wide;   /* contacts run two at a time */
};

/* ------------------------------------------------------------------ */
/* One contact                                                         */
/* ------------------------------------------------------------------ */

/* What one contact adds to its discs' sums: −(fx, fy) to x's force and
 * +(fx, fy) to y's (Fig. 3), tqi and tqj to their moments, and the
 * dashpots' share of each (for the energy audit; float, as s->dash). */
struct contact_sums {
    double fx, fy, tqi, tqj;
    float dfx, dfy, dtqi, dtqj;
};

/* The chain of laws.h at touching contact c of discs i < j, from its
 * kinematics (k: δ and ṅ; e = (ex, ey); the relative velocity (rvx, rvy)):
 * normal → damping → tangential → rolling, each kernel only where the
 * variant (mods) has it.  Updates the contact's history in place, adds its
 * losses to *lost_fric and *lost_roll, returns what it adds to the sums. */
static inline __attribute__((always_inline)) struct contact_sums
one_contact(const struct bal_law_params *P, const struct bal_pair_law *L, const int mods,
            struct bal_kin k, long c, int i, int j, double ex, double ey, double rvx, double rvy,
            const double *restrict r, const double *restrict w, double *restrict pfn,
            double *restrict pfs, double *restrict pmr, double *restrict ptr,
            const double *restrict prb, const double *restrict prk, uint8_t *restrict pflags,
            double *lost_fric, double *lost_roll)
{
    const int shear = (mods & MOD_SHEAR) != 0, damp = (mods & MOD_DAMP) != 0;
    const int roll = (mods & MOD_ROLL) != 0, roll2 = (mods & MOD_ROLL2) != 0;
    const double fn = bal_law_normal(P, L, &k, pfn[c]);
    pfn[c] = fn;
    double ftn = fn, fts = 0, dn = 0, ds = 0;
    /* A contact's lost rolling resistance (Model 2) lasts while it does. */
    uint8_t flags = roll2 ? (uint8_t)(BAL_PAIR_TOUCHING | (pflags[c] & BAL_PAIR_BROKEN))
                          : BAL_PAIR_TOUCHING;
    double mu_n = 0; /* the normal dashpot's coefficient, which the rolling one also uses */
    if (damp) {
        mu_n = bal_law_dashpot_coef(P, L, k.delta);
        dn = mu_n * k.ndot;
        ftn += dn;
    }
    if (shear && L->shear) {
        const double tx = ey, ty = -ex;
        k.sdot = rvx * tx + rvy * ty - (w[i] * r[i] + w[j] * r[j]);
        const double fs = bal_law_tangential(P, L, &k, fn, pfs[c], lost_fric, &flags);
        pfs[c] = fs;
        fts = fs;
        if (damp && !(flags & BAL_PAIR_SLIDING)) {
            ds = bal_law_shear_dashpot(L, &k);
            fts += ds;
        }
    }
    /* The couple on y, +(M + M_d); on x the opposite (JYH eq. 52). */
    double mr = 0, md = 0;
    if (roll && L->rolling > 0) {
        const struct bal_roll R = {prb[c], prk[c]}; /* the pair's (roll_constants) */
        const double wrel = w[i] - w[j];
        const double dtheta = wrel * P->dt;
        ptr[c] += dtheta;
        mr = bal_law_rolling(P, R, fn, dtheta, pmr[c], lost_roll, &flags);
        pmr[c] = mr;
        if (damp) {
            md = bal_law_roll_dashpot(mu_n, R, wrel, !(flags & BAL_PAIR_BROKEN));
            mr += md;
        }
    }
    pflags[c] = flags;
    struct contact_sums a;
    /* Force on y is +(ftn e + fts t); on x the opposite (Fig. 3). */
    a.fx = ftn * ex + fts * ey;
    a.fy = ftn * ey - fts * ex;
    /* The moments on x and y: the shear force's, and the couple. */
    a.tqi = roll ? fts * r[i] - mr : fts * r[i];
    a.tqj = roll ? fts * r[j] + mr : fts * r[j];
    a.dfx = a.dfy = a.dtqi = a.dtqj = 0;
    if (damp) {
        /* the dashpots' share, for their work at t_N (energy.c) */
        a.dfx = (float)(dn * ex + ds * ey);
        a.dfy = (float)(dn * ey - ds * ex);
        a.dtqi = (float)(roll ? ds * r[i] - md : ds * r[i]);
        a.dtqj = (float)(roll ? ds * r[j] + md : ds * r[j]);
    }
    return a;
}

/* Add one side of a contact to disc k's sums: x's (minus: the force
 * subtracted) or y's.  In a range that logs (a range after the first on
 * several threads: struct bal_par), a disc of its zone gets a log entry
 * instead, replayed after the loop (threads.c); a − b is a + (−b) exactly,
 * so the replay adds the same (but for the sign of a NaN: a run with one
 * stops anyway). */
static inline __attribute__((always_inline)) void
add_side(double *restrict f, float *restrict dsh, int k, const int minus,
         const struct contact_sums *a, double tq, float dtq, const int mods, const int logged,
         int zone, struct bal_sum_log *restrict log, long *n_log)
{
    const int shear = (mods & MOD_SHEAR) != 0, damp = (mods & MOD_DAMP) != 0;
    if (logged && k <= zone) {
        log[(*n_log)++] = minus ? (struct bal_sum_log){-a->fx, -a->fy, tq, -a->dfx, -a->dfy, dtq, k}
                                : (struct bal_sum_log){a->fx, a->fy, tq, a->dfx, a->dfy, dtq, k};
        return;
    }
    double *restrict fk = f + 3 * (size_t)k;
    if (minus) {
        fk[0] -= a->fx;
        fk[1] -= a->fy;
    } else {
        fk[0] += a->fx;
        fk[1] += a->fy;
    }
    if (shear)
        fk[2] += tq;
    if (damp) {
        float *restrict dk = dsh + 3 * (size_t)k;
        if (minus) {
            dk[0] -= a->dfx;
            dk[1] -= a->dfy;
        } else {
            dk[0] += a->dfx;
            dk[1] += a->dfy;
        }
        if (shear)
            dk[2] += dtq;
    }
}

/* ------------------------------------------------------------------ */
/* Two contacts at a time                                              */
/* ------------------------------------------------------------------ */

#if defined(BAL_X2)
/* The flags of a pair of contacts in one word: contact a's in bits 0-7,
 * contact b's in bits 8-15 (two bytes kept apart cost the loop a register
 * each, and spills).  FL2(flag): the flag in both; fl2_lanes(bits, flag):
 * the flag in the contacts whose bit is set in a movemask's bits (bit 0:
 * a, bit 1: b). */
#define FL2(flag) ((unsigned)(flag) * 0x101u)
static inline __attribute__((always_inline)) unsigned fl2_lanes(int bits, unsigned flag)
{
    return (unsigned)((bits & 1) | (bits & 2) << 7) * flag;
}

/* The lanes of a pair of contacts whose flags (fl2) do not say BROKEN
 * (Model 2: the rolling resistance is gone), as a mask: a table indexed by
 * the two flags (a mask built lane by lane cost 17 instructions a pair of
 * contacts, callgrind). */
static inline __attribute__((always_inline)) bal_v2m live_x2(unsigned fl2)
{
    static const bal_v2m live[4] = {{-1, -1}, {0, -1}, {-1, 0}, {0, 0}};
    _Static_assert(BAL_PAIR_BROKEN == 8, "live_x2 reads the BROKEN flag as bits 3 and 11");
    return live[((fl2 >> 3) & 1) | ((fl2 >> 10) & 2)];
}

/* What lane l of a pair of contacts, of discs i < j, adds to their sums:
 * −(F_x, F_y) to i's force and +(F_x, F_y) to j's (fxy: the two as one
 * pair of lanes), the moments tqi and tqj; with damping the dashpots' share
 * of each, in float as s->dash (dxy: the force's share, (F_x, F_y) of the
 * contact, and dtq: i's moment, j's moment, in the two low floats).  The
 * same additions to the same sums as add_side() on i, then on j; the
 * floats two at a time where they are adjacent (IEEE's operations lane by
 * lane: the same bits). */
static inline __attribute__((always_inline)) void
add_contact_x2(double *restrict f, float *restrict dsh, int i, int j, __m128d fxy, double tqi,
               double tqj, __m128 dxy, __m128 dtq, const int mods)
{
    const int shear = (mods & MOD_SHEAR) != 0, damp = (mods & MOD_DAMP) != 0;
    double *restrict fi = f + 3 * (size_t)i, *restrict fj = f + 3 * (size_t)j;
    _mm_storeu_pd(fi, _mm_sub_pd(_mm_loadu_pd(fi), fxy));
    _mm_storeu_pd(fj, _mm_add_pd(_mm_loadu_pd(fj), fxy));
    if (shear) {
        fi[2] += tqi;
        fj[2] += tqj;
    }
    if (damp) {
        float *restrict di = dsh + 3 * (size_t)i, *restrict dj = dsh + 3 * (size_t)j;
        const __m128 z = _mm_setzero_ps();
        _mm_storel_pi((__m64 *)di, _mm_sub_ps(_mm_loadl_pi(z, (const __m64 *)di), dxy));
        _mm_storel_pi((__m64 *)dj, _mm_add_ps(_mm_loadl_pi(z, (const __m64 *)dj), dxy));
        if (shear) {
            _mm_store_ss(di + 2, _mm_add_ss(_mm_load_ss(di + 2), dtq));
            _mm_store_ss(dj + 2,
                         _mm_add_ss(_mm_load_ss(dj + 2), _mm_shuffle_ps(dtq, dtq, 1)));
        }
    }
}

/* Pass 3 of a loop of the linear power law on discs of one material (the
 * catalogue's commonest: the race, the biaxial test, the piles), in the
 * chunks that do not log, two contacts at a time: the same kinematics as
 * the one-contact pass, lane by lane, and the _x2 kernels of laws_lanes.h
 * in one_contact()'s order, so the same bits; the force sums are then
 * added contact by contact in the list's order, and the losses of sliding
 * and rolling contacts too.  Returns the contacts done (nt rounded down to
 * even); the one-contact pass does the last.  The variant's bits (mods)
 * leave out what it does not run, as in one_contact().  whole: the
 * material runs every sub-model of the variant (a shear force, rolling
 * resistance) and no viscous damping (γ_n = 0), as constants
 * (two_at_a_time chooses; otherwise the loop tested them at each pair of
 * contacts, and reloaded what they crowded out of the registers). */
static inline __attribute__((always_inline)) int
two_at_a_time_of(struct bal_sim *restrict s, const struct bal_law_params *params, const int mods,
                 const int whole, long c0, const int32_t *restrict tc,
                 const double *restrict tq, const double *restrict tdx,
                 const double *restrict tdy, int nt, double budget, int *over,
                 double *lost_fric, double *lost_roll)
{
    const int damp = (mods & MOD_DAMP) != 0, roll = (mods & MOD_ROLL) != 0;
    const int roll2 = (mods & MOD_ROLL2) != 0;
    /* The law's parameters in locals: through pointers, the compiler
     * reloaded (and broadcast) each one after every store to the sums. */
    struct bal_law_params P_ = *params;
    if (whole)
        P_.gamma_n = 0; /* (it is: a constant for the compiler) */
    const struct bal_law_params *P = &P_;
    const struct bal_pair_law L_ = *s->disc_law, *L = &L_;
    const int shear = (mods & MOD_SHEAR) && (whole || L->shear);
    const int rolling = roll && (whole || L->rolling > 0);
    const struct bal_pairs *p = &s->pp;
    const int32_t *restrict pi = p->i, *restrict pj = p->j;
    double *restrict pfn = p->fn, *restrict pfs = p->fs;
    double *restrict pmr = p->mr, *restrict ptr = p->tr;
    const double *restrict prb = p->rb, *restrict prk = p->rk;
    uint8_t *restrict pflags = p->flags;
    const double *restrict r = s->r, *restrict vx = s->vx, *restrict vy = s->vy;
    const double *restrict w = s->w;
    double *restrict f = s->f;
    float *restrict dsh = s->dash;
    const bal_v2 zero = bal_v2_splat(0.0);
    int ov = 0;
    const int n2 = nt & ~1;
    for (int q = 0; q < n2; q += 2) {
        const long ca = c0 + tc[q], cb = c0 + tc[q + 1];
        const int ia = pi[ca], ja = pj[ca], ib = pi[cb], jb = pj[cb];
        const bal_v2 ri = {r[ia], r[ib]}, rj = {r[ja], r[jb]};
        /* D and e here rather than in pass 2 (the same operations) */
        const bal_v2 dist = bal_v2_sqrt(_mm_loadu_pd(tq + q));
        const bal_v2 ex = _mm_loadu_pd(tdx + q) / dist, ey = _mm_loadu_pd(tdy + q) / dist;
        const bal_v2 rvx = (bal_v2){vx[ia], vx[ib]} - (bal_v2){vx[ja], vx[jb]};
        const bal_v2 rvy = (bal_v2){vy[ia], vy[ib]} - (bal_v2){vy[ja], vy[jb]};
        struct bal_kin_x2 k;
        k.ndot = rvx * ex + rvy * ey;
        k.delta = (ri + rj) - dist;
        ov |= bal_v2_bits(k.delta > budget);

        /* The chain of one_contact(), lane by lane: normal -> damping ->
         * tangential -> rolling. */
        const bal_v2 fn = bal_law_normal_x2(P, L, &k, (bal_v2){pfn[ca], pfn[cb]});
        pfn[ca] = fn[0];
        pfn[cb] = fn[1];
        bal_v2 ftn = fn, fts = zero, dn = zero, ds = zero, mu_n = zero;
        /* A contact's lost rolling resistance (Model 2) lasts while it does. */
        unsigned fl = FL2(BAL_PAIR_TOUCHING);
        if (roll2)
            fl |= (pflags[ca] | (unsigned)pflags[cb] << 8) & FL2(BAL_PAIR_BROKEN);
        if (damp) {
            mu_n = bal_law_dashpot_coef_x2(P, L, k.delta);
            dn = mu_n * k.ndot;
            ftn = fn + dn;
        }
        /* the spins of i and of j (loaded once for ṡ and θ̇_r) */
        const bal_v2 wi = (shear || rolling) ? (bal_v2){w[ia], w[ib]} : zero;
        const bal_v2 wj = (shear || rolling) ? (bal_v2){w[ja], w[jb]} : zero;
        if (shear) {
            const bal_v2 tx = ey, ty = -ex;
            k.sdot = rvx * tx + rvy * ty - (wi * ri + wj * rj);
            bal_v2 loss;
            bal_v2m slid;
            const bal_v2 fs =
                bal_law_shear_x2(P, L, &k, fn, (bal_v2){pfs[ca], pfs[cb]}, &loss, &slid);
            const int slide = bal_v2_bits(slid);
            if (slide) {
                /* the slip's losses, contact by contact in the list's order */
                if (slide & 1)
                    *lost_fric += loss[0];
                if (slide & 2)
                    *lost_fric += loss[1];
                fl |= fl2_lanes(slide, BAL_PAIR_SLIDING);
            }
            pfs[ca] = fs[0];
            pfs[cb] = fs[1];
            fts = fs;
            if (damp) {
                /* D_s where the contact does not slide: F_s + D_s there, F_s
                 * alone elsewhere (not F_s + 0, which would turn −0 into +0) */
                ds = bal_law_shear_dashpot_of_x2(L, &k, slid);
                fts = bal_v2_select(slid, fs, fs + ds);
            }
        }
        /* The couple on y, +(M + M_d); on x the opposite (JYH eq. 52). */
        bal_v2 mr = zero, md = zero;
        if (rolling) {
            /* the pair's B and K_m (roll_constants) */
            const struct bal_roll_x2 R = {{prb[ca], prb[cb]}, {prk[ca], prk[cb]}};
            const bal_v2 wrel = wi - wj;
            const bal_v2 dtheta = wrel * P->dt;
            const bal_v2 tr = (bal_v2){ptr[ca], ptr[cb]} + dtheta;
            ptr[ca] = tr[0];
            ptr[cb] = tr[1];
            bal_v2 loss;
            bal_v2m capped;
            /* Model 1: every lane (no contact is ever BROKEN) */
            bal_v2m live = roll2 ? live_x2(fl) : (bal_v2m){-1, -1};
            mr = bal_law_roll_moment_x2(P, R, fn, dtheta, (bal_v2){pmr[ca], pmr[cb]}, live, &loss,
                                        &capped);
            const int cap = bal_v2_bits(capped);
            if (cap) {
                /* the losses, contact by contact in the list's order */
                const unsigned flag = P->rolling_model == BAL_ROLLING_MODEL2 ? BAL_PAIR_BROKEN
                                                                              : BAL_PAIR_ROLLING;
                if (cap & 1)
                    *lost_roll += loss[0];
                if (cap & 2)
                    *lost_roll += loss[1];
                fl |= fl2_lanes(cap, flag);
                if (P->rolling_model == BAL_ROLLING_MODEL2)
                    live &= ~capped; /* broken now */
            }
            pmr[ca] = mr[0];
            pmr[cb] = mr[1];
            if (damp) {
                md = bal_law_roll_dashpot_x2(mu_n, R, wrel, live);
                mr = mr + md;
            }
        }
        pflags[ca] = (uint8_t)fl;
        pflags[cb] = (uint8_t)(fl >> 8);
        /* The force +(F_n e + F_s t) on j, the opposite on i (Fig. 3); the
         * moments: the shear force's, and the couple. */
        const bal_v2 fcx = ftn * ex + fts * ey;
        const bal_v2 fcy = ftn * ey - fts * ex;
        const bal_v2 tqi = roll ? fts * ri - mr : fts * ri;
        const bal_v2 tqj = roll ? fts * rj + mr : fts * rj;
        bal_v2 dfx = zero, dfy = zero, dtqi = zero, dtqj = zero;
        if (damp) {
            /* the dashpots' share, for their work at t_N (energy.c) */
            dfx = dn * ex + ds * ey;
            dfy = dn * ey - ds * ex;
            dtqi = roll ? ds * ri - md : ds * ri;
            dtqj = roll ? ds * rj + md : ds * rj;
        }
        /* contact a's sums, then contact b's; the dashpots' shares in
         * float, (F_x, F_y) of a and of b, and the moments of i and j of a
         * and of b, each as a pair of adjacent floats */
        const __m128d fxya = _mm_unpacklo_pd(fcx, fcy), fxyb = _mm_unpackhi_pd(fcx, fcy);
        __m128 dxya = _mm_setzero_ps(), dxyb = dxya, dtqa = dxya, dtqb = dxya;
        if (damp) {
            dxya = _mm_unpacklo_ps(_mm_cvtpd_ps(dfx), _mm_cvtpd_ps(dfy));
            dxyb = _mm_movehl_ps(dxya, dxya);
            dtqa = _mm_unpacklo_ps(_mm_cvtpd_ps(dtqi), _mm_cvtpd_ps(dtqj));
            dtqb = _mm_movehl_ps(dtqa, dtqa);
        }
        add_contact_x2(f, dsh, ia, ja, fxya, tqi[0], tqj[0], dxya, dtqa, mods);
        add_contact_x2(f, dsh, ib, jb, fxyb, tqi[1], tqj[1], dxyb, dtqb, mods);
    }
    *over |= ov != 0;
    return n2;
}

/* Pass 3 two at a time (two_at_a_time_of), compiled apart for a material
 * that runs the whole of the variant without viscous damping (the biaxial
 * test, the piles, the race). */
static inline __attribute__((always_inline)) int
two_at_a_time(struct bal_sim *restrict s, const struct bal_law_params *params, const int mods,
              long c0, const int32_t *restrict tc, const double *restrict tq,
              const double *restrict tdx, const double *restrict tdy, int nt, double budget,
              int *over, double *lost_fric, double *lost_roll)
{
    const struct bal_pair_law *L = s->disc_law;
    const int whole = (!(mods & MOD_SHEAR) || L->shear) && (!(mods & MOD_ROLL) || L->rolling > 0) &&
                      (!(mods & MOD_DAMP) || params->gamma_n == 0);
    if (whole)
        return two_at_a_time_of(s, params, mods, 1, c0, tc, tq, tdx, tdy, nt, budget, over,
                                lost_fric, lost_roll);
    return two_at_a_time_of(s, params, mods, 0, c0, tc, tq, tdx, tdy, nt, budget, over,
                            lost_fric, lost_roll);
}
#endif

/* ------------------------------------------------------------------ */
/* A range of the list                                                 */
/* ------------------------------------------------------------------ */

/* A range of the disc–disc list (all of it on one thread; see struct
 * bal_par in state.h for several).  The loop starts the cycle's force sums.
 * It runs in chunks of BAL_PAIRS_CHUNK candidates; before a chunk, the sums
 * of every disc up to the chunk's highest j are zeroed (pairs are sorted by
 * i and j > i, so no disc above the highest j seen has been touched yet),
 * the rest at the end.  The sums' lines are then fetched once, by the loop
 * that fills them, and not also by a clearing pass of their own, which in a
 * packing larger than the cache cost a trip to memory per line.  The order
 * of the additions is unchanged.  (Clearing inside the per-pair loop, at
 * each new highest j, made the 20 000-disc benchmark 25 % slower: the
 * compiler turns the clearing into memset calls, and a call in the loop
 * costs the loop its registers.)
 *
 * Range t never writes the sums of the discs up to zone = par.zone[t]
 * directly (the ranges before it clear them, possibly at the same time):
 * it logs what it adds to them (`logged` chunks: those whose first i is in
 * the zone; threads.c).  The last range clears the sums no candidate
 * reached.  Each chunk's friction loss goes to par.chunk_sums.
 *
 * range_chunks: the chunks of range t from st.c0 on, while their first i is
 * in the zone (`logged`), or to the end of the range.  Each chunk runs the
 * three passes of the header; the third is one_contact() and add_side() at
 * each touching contact, or two_at_a_time() where the variant allows.
 * Kept whole (about 130 lines, a third of them the columns and parameters
 * read into locals): with pass 1 as an inline function of its own, the
 * compiled loops ran 3 % more instructions (callgrind: loop_inc_sd 1.157e9
 * against 1.124e9 on the dense scene's 5 000 discs for 3 000 cycles,
 * loop_pow_s 3.4 % more on the same packing with the linear law). */
static inline __attribute__((always_inline)) struct range_state
range_chunks(struct bal_sim *restrict s, int t, struct range_state st, const int mods,
             const int logged, const int linear, const int one)
{
    /* The list's columns in locals: through p, the compiler reloaded each
     * column's address from the struct after every store to another. */
    const struct bal_pairs *p = &s->pp;
    const int32_t *restrict pi = p->i, *restrict pj = p->j;
    double *restrict pfn = p->fn, *restrict pfs = p->fs;
    double *restrict pmr = p->mr, *restrict ptr = p->tr;
    const double *restrict prb = p->rb, *restrict prk = p->rk;
    uint8_t *restrict pflags = p->flags;
    const long pn = p->n;
    const double *restrict x = s->x, *restrict y = s->y;
    const double *restrict vx = s->vx, *restrict vy = s->vy, *restrict w = s->w;
    const double *restrict r = s->r;
    const int32_t *restrict mat = s->mat;
    double *restrict f = s->f;
    float *restrict dsh = s->dash;
    /* The chain's parameters, read once: the kernels (laws.h) take them in
     * registers. */
    const int shear = (mods & MOD_SHEAR) != 0, damp = (mods & MOD_DAMP) != 0;
    const int roll = (mods & MOD_ROLL) != 0;
    struct bal_law_params P = bal_law_params_of(s);
    /* A constant here: each variant runs one normal law, and a power-law
     * variant without damping or friction never reads a velocity. */
    P.normal_law = mods & MOD_POWER ? BAL_NORMAL_POWER : BAL_NORMAL_INCREMENTAL;
    if (linear)
        P.nu = 1; /* (it is: a constant for the compiler) */
    if (roll) /* the same: pair_range chose the ranges of the scene's model */
        P.rolling_model = mods & MOD_ROLL2 ? BAL_ROLLING_MODEL2 : BAL_ROLLING_MODEL1;
    const int n_mat = s->n_mat;
    const struct bal_pair_law *restrict laws = s->law;
    const struct bal_pair_law *restrict one_law = s->disc_law;
    /* The overlap budget is a share of the smaller radius of each pair: the
     * loop compares with that share of the scene's smallest radius (one
     * compare), and only if some overlap passes it are the pairs judged one
     * by one (energy.c). */
    const double budget = s->overlap_sieve;
    double *restrict chunk_sums = s->par.chunk_sums;
    const int32_t *restrict chunk_top = s->par.chunk_top;
    double *restrict chunk_roll = s->par.chunk_roll;
    const long end = s->par.start[t + 1];
    const int zone = logged ? s->par.zone[t] : -1;
    struct bal_sum_log *restrict log = logged ? s->par.log[t] : NULL;
    long n_log = logged ? s->par.log_n[t] : 0;
    /* Two at a time: the commonest law, in the chunks that do not log,
     * unless a test asks for one contact at a time (par.one_lane). */
#if defined(BAL_X2)
    const int pairs = (mods & MOD_POWER) && linear && one && !logged && !s->par.one_lane;
#else
    const int pairs = 0;
#endif
    int cleared = st.cleared, over = st.over;
    long c0 = st.c0, wide = st.wide;
    for (; c0 < end && (!logged || pi[c0] <= zone); c0 += BAL_PAIRS_CHUNK) {
        const long c1 = c0 + BAL_PAIRS_CHUNK < pn ? c0 + BAL_PAIRS_CHUNK : pn;
        const int top = chunk_top[c0 / BAL_PAIRS_CHUNK];
        if (top > cleared) {
            clear_sums(f, dsh, cleared + 1, top, damp);
            cleared = top;
        }
        double lost_fric = 0, lost_roll = 0; /* energy audit (energy.c) */
        /* Pass 1: which candidates touch (eq. 8).  A short loop without
         * branches on the answer; the touching ones are gathered, with
         * their dx, dy and D^2, for the two passes below. */
        int32_t tc[BAL_PAIRS_CHUNK + 1];
        double tdx[BAL_PAIRS_CHUNK + 1], tdy[BAL_PAIRS_CHUNK + 1], tq[BAL_PAIRS_CHUNK + 1];
        int nt = 0;
        for (long c = c0; c < c1; c++) {
            const int i = pi[c], j = pj[c];
            const double dx = x[j] - x[i], dy = y[j] - y[i];
            const double rs = r[i] + r[j];
            const double d2 = dx * dx + dy * dy;
            const int touch = !(d2 >= rs * rs); /* (a NaN counts as touching) */
            tc[nt] = (int32_t)(c - c0);
            tdx[nt] = dx;
            tdy[nt] = dy;
            tq[nt] = d2;
            nt += touch;
            /* Not in contact: history is reset.  A candidate that did not
             * touch in the last cycle either has none to reset (flags 0:
             * F_n = F_s = 0), and is not written, so the near pairs of a
             * wide skin cost the loop no stores.  (The rolling history is
             * reset always: a re-sort negates it, which turns a zero into
             * −0.  Resetting it only in a list's first cycle and then by
             * the flags, as the others, ran 1.5 more instructions a
             * particle-step and 5 % more CPU time on the biaxial test of
             * Model 1: docs/benchmarks.md.) */
            if (!touch & (roll || pflags[c])) {
                pfn[c] = 0;
                pflags[c] = 0;
                if (shear)
                    pfs[c] = 0;
                if (roll)
                    pmr[c] = ptr[c] = 0;
            }
        }
        /* Pass 2: D and e of the touching ones, several per instruction
         * (the contacts taken two at a time take theirs in pass 3, and the
         * last one, if odd, here). */
        int q0 = 0;
        if (!pairs)
            unit_vectors(tq, tdx, tdy, nt);
        else if (nt & 1)
            unit_vectors(tq + nt - 1, tdx + nt - 1, tdy + nt - 1, 1);
        /* Pass 3: the law at each touching contact, in the list's order. */
#if defined(BAL_X2)
        if (pairs) {
            q0 = two_at_a_time(s, &P, mods, c0, tc, tq, tdx, tdy, nt, budget, &over, &lost_fric,
                               &lost_roll);
            wide += q0;
        }
#endif
        for (int q = q0; q < nt; q++) {
            const long c = c0 + tc[q];
            const int i = pi[c], j = pj[c];
            const double rs = r[i] + r[j];
            const struct bal_pair_law *L = one ? one_law : &laws[mat[i] * n_mat + mat[j]];
            const double dist = tq[q], ex = tdx[q], ey = tdy[q];
            const double rvx = vx[i] - vx[j], rvy = vy[i] - vy[j];
            struct bal_kin k;
            k.ndot = rvx * ex + rvy * ey;
            k.delta = rs - dist;
            k.sdot = 0; /* set by one_contact where the tangential kernel runs */
            over |= k.delta > budget; /* a first sieve; bal_energy_overlap judges each pair */
            const struct contact_sums a =
                one_contact(&P, L, mods, k, c, i, j, ex, ey, rvx, rvy, r, w, pfn, pfs, pmr, ptr,
                            prb, prk, pflags, &lost_fric, &lost_roll);
            add_side(f, dsh, i, 1, &a, a.tqi, a.dtqi, mods, logged, zone, log, &n_log);
            add_side(f, dsh, j, 0, &a, a.tqj, a.dtqj, mods, logged, zone, log, &n_log);
        }
        if (shear)
            chunk_sums[c0 / BAL_PAIRS_CHUNK] = lost_fric;
        if (roll)
            chunk_roll[c0 / BAL_PAIRS_CHUNK] = lost_roll;
    }
    if (logged)
        s->par.log_n[t] = n_log;
    return (struct range_state){c0, cleared, over, wide};
}

/* The chunks of a range that log (at its start; only ranges after the
 * first have any): out of line, so that the loop of the others has no call
 * in it and keeps its registers (with the call, the 20 000-disc benchmark
 * lost 7 %). */
static __attribute__((noinline)) struct range_state
logged_chunks(struct bal_sim *restrict s, int t, struct range_state st, const int mods)
{
    return range_chunks(s, t, st, mods, 1, 0, 0);
}

static inline __attribute__((always_inline)) void
pair_range_of(struct bal_sim *restrict s, int t, const int mods)
{
    struct range_state st = {s->par.start[t], s->par.zone[t], 0, 0};
    s->par.log_n[t] = 0;
    if (t > 0)
        st = logged_chunks(s, t, st, mods);
    /* The loop compiled for the common cases too: one material (no test for
     * it at each contact), and with it the linear power law (no test of ν at
     * each contact, no call of pow in the loop).  The logged chunks of the
     * ranges after the first keep the general loop: they are few. */
    const int linear = (mods & MOD_POWER) && s->nu == 1.0, one = s->disc_law != NULL;
    if (linear && one)
        st = range_chunks(s, t, st, mods, 0, 1, 1);
    else if (one)
        st = range_chunks(s, t, st, mods, 0, 0, 1);
    else
        st = range_chunks(s, t, st, mods, 0, 0, 0);
    if (t == s->par.ranges - 1)
        clear_sums(s->f, s->dash, st.cleared + 1, s->n - 1, (mods & MOD_DAMP) != 0);
    s->par.over[t] = st.over;
    s->par.two_lane[t] += st.wide;
}

/* Range t, compiled for the scene's model of rolling resistance in a
 * rolling variant (MOD_ROLL2 for Model 2). */
static inline __attribute__((always_inline)) void
pair_range(struct bal_sim *restrict s, int t, const int mods)
{
    if ((mods & MOD_ROLL) && bal_law_params_of(s).rolling_model == BAL_ROLLING_MODEL2)
        pair_range_of(s, t, mods | MOD_ROLL2);
    else
        pair_range_of(s, t, mods);
}

/* The rolling width B and stiffness K_m of every candidate of the disc–disc
 * list (pp.rb, pp.rk), set once a list, before its first cycle (pair_loop,
 * which then sets pp.rolled): they are
 * constants of the pair (its radii and its pair law, which do not change
 * during a run), so the loop does not compute the common radius, its
 * division and K_m at each contact every cycle.  The same kernels
 * (bal_law_common_radius, bal_law_roll_of in laws_lanes.h) on the same
 * operands as the loop computed them with, so the same bits.  A pair
 * without rolling resistance (δ = 0) gets B = K_m = 0, which the loop
 * does not read. */
static __attribute__((noinline)) void roll_constants(struct bal_sim *restrict s)
{
    struct bal_pairs *p = &s->pp;
    const int32_t *restrict pi = p->i, *restrict pj = p->j;
    double *restrict prb = p->rb, *restrict prk = p->rk;
    const double *restrict r = s->r;
    const int32_t *restrict mat = s->mat;
    const int n_mat = s->n_mat;
    for (long c = 0; c < p->n; c++) {
        const int i = pi[c], j = pj[c];
        const struct bal_pair_law *L =
            s->disc_law ? s->disc_law : &s->law[mat[i] * n_mat + mat[j]];
        const struct bal_roll R = bal_law_roll_of(L, bal_law_common_radius(r[i], r[j]));
        prb[c] = R.b;
        prk[c] = R.km;
    }
}

/* The whole list: its ranges, on as many threads, then the logs replayed in
 * range order (threads.c) and the chunks' losses added in order. */
static inline __attribute__((always_inline)) void
pair_loop(struct bal_sim *restrict s, void (*on_threads)(struct bal_sim *), const int mods)
{
    struct bal_par *par = &s->par;
    if (par->planned != s->rebuilds)
        bal_threads_plan(s);
    /* The first cycle of a list with rolling resistance: its constants. */
    const int first = (mods & MOD_ROLL) && s->pp.rolled != s->rebuilds;
    if (first)
        roll_constants(s);
    const int ranges = par->ranges;
    if (ranges == 1)
        pair_range(s, 0, mods);
    else
        on_threads(s);
    int over = par->over[0];
    if (ranges > 1) {
        for (int t = 1; t < ranges; t++)
            over |= par->over[t];
        bal_threads_replay(s, (mods & MOD_SHEAR) != 0, (mods & MOD_DAMP) != 0);
    }
    const long chunks = bal_pairs_chunks(s->pp.n);
    if (mods & MOD_SHEAR) {
        double lost_fric = 0;
        for (long k = 0; k < chunks; k++)
            lost_fric += par->chunk_sums[k];
        s->audit.d_friction += lost_fric;
    }
    if (mods & MOD_ROLL) {
        double lost_roll = 0;
        for (long k = 0; k < chunks; k++)
            lost_roll += par->chunk_roll[k];
        s->audit.d_rolling += lost_roll;
    }
    s->over_budget |= over;
    if (first)
        s->pp.rolled = s->rebuilds;
}

/* ------------------------------------------------------------------ */
/* The variants                                                        */
/* ------------------------------------------------------------------ */

/* Each variant with its parallel region in a function of its own: in the
 * same function, the region's shared variables cost the serial loop 10 %
 * (the compiler no longer keeps them in registers). */
#define PAIR_VARIANT(name, mods)                                              \
    static __attribute__((noinline)) void name##_threads(struct bal_sim *s) \
    {                                                                        \
        const int ranges = s->par.ranges;                                    \
        _Pragma("omp parallel for num_threads(ranges) schedule(static, 1)") \
        for (int t = 0; t < ranges; t++)                                     \
            pair_range(s, t, mods);                                          \
    }                                                                        \
    static void name(struct bal_sim *s) { pair_loop(s, name##_threads, mods); }

/* The variants: one per combination of the normal law and the optional
 * sub-models (MOD_* bits), each compiled without the code and history of
 * what it leaves out.  The normal law stays a compile-time choice: made a
 * run-time test inside the loop, the compiler evaluated both laws and the
 * power-law loop read every disc's velocity for the incremental law's ṅ
 * (34 % more data reads, 10 % more time on 20 000 frictionless discs).
 *
 * BAL_BARE: the build without optional modules, for `make bench-modules`
 * only: every scene gets the frictionless, undamped power-law loop, so a
 * scene that switches the modules off can be timed against code that does
 * not have them. */
#ifdef BAL_BARE
PAIR_VARIANT(loop_pow, MOD_POWER)

bal_pair_loop_fn bal_pair_loop_select(int normal_law, int shear, int damping, int rolling)
{
    (void)normal_law, (void)shear, (void)damping, (void)rolling;
    return loop_pow;
}
#else
PAIR_VARIANT(loop_inc, 0)
PAIR_VARIANT(loop_pow, MOD_POWER)
PAIR_VARIANT(loop_inc_s, MOD_SHEAR)
PAIR_VARIANT(loop_pow_s, MOD_POWER | MOD_SHEAR)
PAIR_VARIANT(loop_inc_d, MOD_DAMP)
PAIR_VARIANT(loop_pow_d, MOD_POWER | MOD_DAMP)
PAIR_VARIANT(loop_inc_sd, MOD_SHEAR | MOD_DAMP)
PAIR_VARIANT(loop_pow_sd, MOD_POWER | MOD_SHEAR | MOD_DAMP)
PAIR_VARIANT(loop_inc_sr, MOD_SHEAR | MOD_ROLL)
PAIR_VARIANT(loop_pow_sr, MOD_POWER | MOD_SHEAR | MOD_ROLL)
PAIR_VARIANT(loop_inc_sdr, MOD_SHEAR | MOD_DAMP | MOD_ROLL)
PAIR_VARIANT(loop_pow_sdr, MOD_POWER | MOD_SHEAR | MOD_DAMP | MOD_ROLL)

/* Rolling only with the tangential kernel: the caller asks for shear when
 * it asks for rolling (build.c), so the table has no variant without. */
bal_pair_loop_fn bal_pair_loop_select(int normal_law, int shear, int damping, int rolling)
{
    static const bal_pair_loop_fn table[16] = {
        loop_inc,   loop_pow,   loop_inc_s,  loop_pow_s,  loop_inc_d, loop_pow_d,
        loop_inc_sd, loop_pow_sd, NULL,      NULL,        loop_inc_sr, loop_pow_sr,
        NULL,        NULL,        loop_inc_sdr, loop_pow_sdr};
    const int mods = (normal_law == BAL_NORMAL_POWER ? MOD_POWER : 0) | (shear ? MOD_SHEAR : 0) |
                     (damping ? MOD_DAMP : 0) | (rolling ? MOD_ROLL | MOD_SHEAR : 0);
    return table[mods];
}
#endif
