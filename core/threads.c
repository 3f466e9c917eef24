/*
 * threads.c — the disc–disc loop on several threads with the results of
 * one: how the candidate list is cut into ranges (once per list), and the
 * replay, after the loop, of what each range logged (every cycle).  The
 * loop itself, which runs a range and logs, is pair_loop.c's.
 *
 * The list is sorted by (i, j) with i < j, and the loop adds a contact's
 * force to the sums of i and j as it goes.  Range t of the list may add to
 * the sums of every disc up to the highest j of the ranges before it (its
 * zone, par.zone[t]) only through a log: those discs are also reached by
 * an earlier range, which must add first.  After the loop the logs are
 * replayed in range order, entry by entry, so each disc's sums add the same
 * terms in the same order as one thread going through the whole list: the
 * results are bitwise those of one thread, whatever the number of threads
 * (core/tests/check_threads.c).  The discs above the zone are the range's
 * own; it adds to them directly.  The sums over candidates (the friction
 * and rolling losses) are kept per chunk of the list and added up in order
 * by the loop, which is the same for any cut.
 *
 * The cut: ranges of whole chunks (BAL_PAIRS_CHUNK candidates), about as
 * many candidates each, at most one per thread and none shorter than
 * PAR_MIN_CHUNKS chunks; the logs are sized for the zones here, when the
 * list is new (after a rebuild), so the loop never allocates.  Where memory
 * runs out, the list stays one range (the serial loop needs no log).
 */
#include <stdlib.h>
#include <string.h>

#include "pairs.h"
#include "threads.h"

/* Ranges shorter than this many chunks are not worth a thread. */
#define PAR_MIN_CHUNKS 16

static int grow_log(struct bal_par *par, int t, long need)
{
    if (need <= par->log_cap[t])
        return 1;
    const long cap = need + need / 2 + 64;
    struct bal_sum_log *q = realloc(par->log[t], (size_t)cap * sizeof *q);
    if (!q)
        return 0;
    par->log[t] = q;
    par->log_cap[t] = cap;
    return 1;
}

void bal_threads_plan(struct bal_sim *s)
{
    struct bal_par *par = &s->par;
    const struct bal_pairs *p = &s->pp;
    const long chunks = bal_pairs_chunks(p->n);
    /* Each chunk's highest j, which the loop clears the sums up to: the
     * list is the same until the next rebuild, so it is found once here
     * rather than by a scan of the chunk every cycle. */
    for (long k = 0; k < chunks; k++) {
        const long c1 = (k + 1) * BAL_PAIRS_CHUNK < p->n ? (k + 1) * BAL_PAIRS_CHUNK : p->n;
        int32_t top = -1;
        for (long c = k * BAL_PAIRS_CHUNK; c < c1; c++)
            top = p->j[c] > top ? p->j[c] : top;
        par->chunk_top[k] = top;
    }
    int ranges = par->threads;
    if (ranges > chunks / PAR_MIN_CHUNKS)
        ranges = (int)(chunks / PAR_MIN_CHUNKS);
    if (ranges < 1)
        ranges = 1;
    par->start[0] = 0;
    for (int t = 1; t < ranges; t++)
        par->start[t] = chunks * t / ranges * BAL_PAIRS_CHUNK;
    par->start[ranges] = p->n;
    par->zone[0] = -1;
    par->planned = s->rebuilds;
    par->ranges = 1;
    if (ranges == 1)
        return; /* no zones, no logs: no pass over the list */
    int seen = -1; /* the highest j of the ranges so far */
    for (int t = 0; t < ranges; t++) {
        const int zone = seen;
        par->zone[t] = zone;
        long logged = 0;
        for (long c = par->start[t]; c < par->start[t + 1]; c++) {
            logged += (p->i[c] <= zone) + (p->j[c] <= zone);
            seen = p->j[c] > seen ? p->j[c] : seen;
        }
        if (t > 0 && !grow_log(par, t, logged)) {
            par->start[1] = p->n; /* one range after all */
            return;
        }
    }
    par->ranges = ranges;
}

void bal_threads_free(struct bal_par *par)
{
    for (int t = 0; t < BAL_MAX_THREADS; t++)
        free(par->log[t]);
    free(par->chunk_sums);
    free(par->chunk_top);
    free(par->chunk_roll);
    free(par->block_sums);
    memset(par, 0, sizeof *par);
}

/* The replay, compiled for each combination of the sums a scene keeps (the
 * moment with the tangential kernel, the dashpots' share with damping). */
static inline __attribute__((always_inline)) void
replay(struct bal_sim *restrict s, const int shear, const int damp)
{
    const struct bal_par *par = &s->par;
    double *restrict f = s->f;
    float *restrict dsh = s->dash;
    for (int t = 1; t < par->ranges; t++) {
        const struct bal_sum_log *restrict log = par->log[t];
        for (long e = 0; e < par->log_n[t]; e++) {
            const int k = log[e].k;
            f[3 * k] += log[e].fx;
            f[3 * k + 1] += log[e].fy;
            if (shear)
                f[3 * k + 2] += log[e].tq;
            if (damp) {
                dsh[3 * k] += log[e].dfx;
                dsh[3 * k + 1] += log[e].dfy;
                if (shear)
                    dsh[3 * k + 2] += log[e].dtq;
            }
        }
    }
}

void bal_threads_replay(struct bal_sim *s, int shear, int damp)
{
    if (shear && damp)
        replay(s, 1, 1);
    else if (shear)
        replay(s, 1, 0);
    else if (damp)
        replay(s, 0, 1);
    else
        replay(s, 0, 0);
}
