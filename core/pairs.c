/*
 * pairs.c — the candidate lists: their storage, finding a pair in them, and
 * what a candidate is (its overlap, its bodies' names for messages).
 *
 * A list (struct bal_pairs, state.h) holds the pairs the neighbour search
 * found (grid.c), sorted by key = (i << 32) | j, with the history of each
 * contact in parallel columns: F_n, F_s and the dashpot forces, each column
 * only when the scene needs it.  The disc–disc list numbers a pair by its
 * discs' array slots (i < j); the disc–wall list by the disc's slot and the
 * wall's index.  Columns grow only in a rebuild (grid.c), never in the
 * contact loops (pair_loop.c, wall_loop.c), which read and write them in place.
 *
 * The disc–disc loop runs in chunks of BAL_PAIRS_CHUNK candidates and keeps
 * one friction sum per chunk (struct bal_par); that array is sized with the
 * list, here, so that the loop never allocates.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pairs.h"
#include "specimen.h"
#include "walls.h"

static int grow_array(void **a, size_t cap, size_t size)
{
    void *q = realloc(*a, cap * size);
    if (!q)
        return 0;
    *a = q;
    return 1;
}

enum bal_status bal_pairs_reserve(struct bal_pairs *p, long cap)
{
    if (cap <= p->cap)
        return BAL_OK;
    const size_t c = (size_t)cap;
    int ok = grow_array((void **)&p->i, c, sizeof *p->i) &&
             grow_array((void **)&p->j, c, sizeof *p->j) &&
             grow_array((void **)&p->fn, c, sizeof *p->fn) &&
             grow_array((void **)&p->flags, c, sizeof *p->flags);
    if (ok && p->shear)
        ok = grow_array((void **)&p->fs, c, sizeof *p->fs);
    if (ok && p->damping)
        ok = grow_array((void **)&p->dn, c, sizeof *p->dn) &&
             grow_array((void **)&p->ds, c, sizeof *p->ds);
    if (ok && p->rolling)
        ok = grow_array((void **)&p->mr, c, sizeof *p->mr) &&
             grow_array((void **)&p->tr, c, sizeof *p->tr) &&
             (!p->damping || grow_array((void **)&p->dm, c, sizeof *p->dm)) &&
             grow_array((void **)&p->rb, c, sizeof *p->rb) &&
             grow_array((void **)&p->rk, c, sizeof *p->rk);
    p->rolled = -1; /* rb and rk: set them again before the loop reads them */
    if (!ok)
        return BAL_ENOMEM;
    p->cap = cap;
    return BAL_OK;
}

void bal_pairs_free(struct bal_pairs *p)
{
    const uint8_t shear = p->shear, damping = p->damping, rolling = p->rolling;
    free(p->i);
    free(p->j);
    free(p->fn);
    free(p->fs);
    free(p->dn);
    free(p->ds);
    free(p->mr);
    free(p->tr);
    free(p->dm);
    free(p->rb);
    free(p->rk);
    free(p->flags);
    memset(p, 0, sizeof *p);
    p->rolled = -1;
    p->shear = shear;
    p->damping = damping;
    p->rolling = rolling;
}

enum bal_status bal_pairs_reserve_chunks(struct bal_sim *s)
{
    struct bal_par *par = &s->par;
    const long need = bal_pairs_chunks(s->pp.cap) + 1;
    if (need <= par->chunk_cap)
        return BAL_OK;
    double *q = realloc(par->chunk_sums, (size_t)need * sizeof *q);
    if (!q)
        return BAL_ENOMEM;
    par->chunk_sums = q;
    int32_t *top = realloc(par->chunk_top, (size_t)need * sizeof *top);
    if (!top)
        return BAL_ENOMEM;
    par->chunk_top = top;
    if (s->pp.rolling) {
        q = realloc(par->chunk_roll, (size_t)need * sizeof *q);
        if (!q)
            return BAL_ENOMEM;
        par->chunk_roll = q;
    }
    par->chunk_cap = need;
    return BAL_OK;
}

long bal_pairs_find(const struct bal_pairs *p, uint64_t key)
{
    long lo = 0, hi = p->n;
    while (lo < hi) {
        const long mid = lo + (hi - lo) / 2;
        if (pair_key(p, mid) < key)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < p->n && pair_key(p, lo) == key ? lo : -1;
}

long bal_pairs_find_contact(const struct bal_sim *s, int a_wall, int a, int b_wall, int b,
                            const struct bal_pairs **list)
{
    if (a_wall && b_wall)
        return -1;
    if (a_wall || b_wall) {
        const int disc = a_wall ? b : a, wall = a_wall ? a : b;
        *list = &s->pw;
        return bal_pairs_find(&s->pw, ((uint64_t)(uint32_t)disc << 32) | (uint32_t)wall);
    }
    const int lo = a < b ? a : b, hi = a < b ? b : a;
    *list = &s->pp;
    return bal_pairs_find(&s->pp, ((uint64_t)(uint32_t)lo << 32) | (uint32_t)hi);
}

double bal_pairs_overlap(const struct bal_sim *s, int walls, long c, double *rmin,
                         const struct bal_pair_law **law)
{
    const struct bal_pairs *p = walls ? &s->pw : &s->pp;
    const int i = p->i[c], j = p->j[c];
    if (walls) {
        *rmin = s->r[i];
        *law = &s->law[s->mat[i] * s->n_mat + s->walls[j].material];
        return bal_walls_overlap(&s->walls[j], s->x[i], s->y[i], s->r[i]);
    }
    *rmin = fmin(s->r[i], s->r[j]);
    *law = &s->law[s->mat[i] * s->n_mat + s->mat[j]];
    return s->r[i] + s->r[j] - hypot(s->x[j] - s->x[i], s->y[j] - s->y[i]);
}

void bal_pairs_names(const struct bal_sim *s, int walls, long c, char *a, size_t na, char *b,
                     size_t nb)
{
    const struct bal_pairs *p = walls ? &s->pw : &s->pp;
    bal_specimen_disc_name(s->scene, s->id[p->i[c]], a, na);
    if (walls) {
        snprintf(b, nb, "wall %s", s->walls[p->j[c]].name);
        return;
    }
    char d[2 * BAL_NAME_MAX];
    bal_specimen_disc_name(s->scene, s->id[p->j[c]], d, sizeof d);
    snprintf(b, nb, "disc %s", d);
}
