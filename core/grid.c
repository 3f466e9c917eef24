/*
 * grid.c — neighbour search: the candidate lists of disc–disc and disc–wall
 * pairs that the contact loops run over.
 *
 * Two modes.  With few discs every pair is a candidate: the list is built
 * once and never rebuilt, and the step pays nothing for a grid.  With many
 * discs a cell grid finds the pairs whose gap is below a Verlet skin, and
 * the lists are rebuilt only when some disc (or wall) has moved far enough
 * to close that skin (integrate.c decides).  The cross-over
 * BAL_GRID_CROSSOVER was measured with `make bench-grid` (see README).
 *
 * Cells are square with side 2 r_max + skin, so every candidate of a disc
 * lies in its own cell or the eight around it.  Discs are binned by a
 * counting sort.  For each disc i, in index order, its candidates j > i are
 * gathered and sorted by j, which leaves the whole list sorted by key
 * (i << 32 | j) without a global sort; the history of the old list is then
 * carried over by one linear merge (contacts.c).
 *
 * Memory: lists grow by doubling, and only here, in a rebuild; the step
 * itself never allocates.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sim.h"

/* Most candidates one disc can have in a rebuild; a disc of radius r_min
 * cannot have more non-overlapping neighbours within 2 r_max + skin.  The
 * generator keeps radius ratios moderate; beyond this the rebuild fails. */
#define MAX_NEIGHBOURS 512

void bal_grid_free(struct bal_grid *g)
{
    free(g->start);
    free(g->list);
    free(g->cell);
    memset(g, 0, sizeof *g);
}

static enum bal_status grow(struct bal_pairs *p, long need, struct bal_error *err)
{
    if (need <= p->cap)
        return BAL_OK;
    long cap = p->cap ? p->cap : 64;
    while (cap < need)
        cap *= 2;
    if (bal_pairs_reserve(p, cap))
        return bal_error(err, BAL_ENOMEM, "neighbour list: out of memory for %ld pairs", cap);
    return BAL_OK;
}

static void swap_pairs(struct bal_pairs *a, struct bal_pairs *b)
{
    struct bal_pairs t = *a;
    *a = *b;
    *b = t;
}

static inline void push(struct bal_pairs *p, int i, int j)
{
    long c = p->n++;
    p->key[c] = ((uint64_t)(uint32_t)i << 32) | (uint32_t)j;
    p->i[c] = i;
    p->j[c] = j;
}

enum bal_status bal_grid_rebuild(struct bal_sim *s, struct bal_error *err)
{
    const int n = s->n;
    struct bal_pairs *fresh = &s->scratch_pp;

    /* --- disc–disc candidates ------------------------------------- */
    fresh->n = 0;
    if (!s->use_grid) {
        long need = (long)n * (n - 1) / 2;
        if (grow(fresh, need, err))
            return err->code;
        for (int i = 0; i < n; i++)
            for (int j = i + 1; j < n; j++)
                push(fresh, i, j);
    } else {
        struct bal_grid *g = &s->grid;
        double x0 = s->x[0], x1 = s->x[0], y0 = s->y[0], y1 = s->y[0];
        for (int i = 1; i < n; i++) {
            x0 = fmin(x0, s->x[i]);
            x1 = fmax(x1, s->x[i]);
            y0 = fmin(y0, s->y[i]);
            y1 = fmax(y1, s->y[i]);
        }
        if (!(isfinite(x0) && isfinite(x1) && isfinite(y0) && isfinite(y1)))
            return bal_error(err, BAL_EUNSTABLE,
                             "neighbour grid: a disc position is not finite at step %ld",
                             s->step);
        double h = 2 * s->r_max + s->skin;
        /* A sparse scene spread over a large area would need many empty
         * cells; widen the cells so there are at most about 2 per disc. */
        double cells = ((x1 - x0) / h + 1) * ((y1 - y0) / h + 1);
        if (cells > 2.0 * n + 16)
            h *= sqrt(cells / (2.0 * n + 16));
        int nx = (int)((x1 - x0) / h) + 1, ny = (int)((y1 - y0) / h) + 1;
        long nc = (long)nx * ny;
        if (nc + 1 > g->cells_cap) {
            int32_t *st = realloc(g->start, (size_t)(nc + 1) * sizeof *st);
            if (!st)
                return bal_error(err, BAL_ENOMEM, "neighbour grid: out of memory");
            g->start = st;
            g->cells_cap = nc + 1;
        }
        g->x0 = x0;
        g->y0 = y0;
        g->h = h;
        g->nx = nx;
        g->ny = ny;
        memset(g->start, 0, (size_t)(nc + 1) * sizeof *g->start);
        const double inv_h = 1 / h;
        for (int i = 0; i < n; i++) {
            int cx = (int)((s->x[i] - x0) * inv_h), cy = (int)((s->y[i] - y0) * inv_h);
            cx = cx < nx ? cx : nx - 1;
            cy = cy < ny ? cy : ny - 1;
            g->cell[i] = cy * nx + cx;
            g->start[g->cell[i] + 1]++;
        }
        for (long c = 0; c < nc; c++)
            g->start[c + 1] += g->start[c];
        /* Fill cells; `list` positions taken from a running copy. */
        for (int i = 0; i < n; i++)
            g->list[g->start[g->cell[i]]++] = i;
        for (long c = nc; c > 0; c--)
            g->start[c] = g->start[c - 1];
        g->start[0] = 0;

        int32_t nb[MAX_NEIGHBOURS];
        for (int i = 0; i < n; i++) {
            const int ci = g->cell[i], cx = ci % nx, cy = ci / nx;
            int k = 0;
            for (int yy = cy - 1; yy <= cy + 1; yy++) {
                if (yy < 0 || yy >= ny)
                    continue;
                for (int xx = cx - 1; xx <= cx + 1; xx++) {
                    if (xx < 0 || xx >= nx)
                        continue;
                    const int c = yy * nx + xx;
                    for (int a = g->start[c]; a < g->start[c + 1]; a++) {
                        const int j = g->list[a];
                        if (j <= i)
                            continue;
                        const double dx = s->x[j] - s->x[i], dy = s->y[j] - s->y[i];
                        const double reach = s->r[i] + s->r[j] + s->skin;
                        if (dx * dx + dy * dy < reach * reach) {
                            if (k == MAX_NEIGHBOURS)
                                return bal_error(err, BAL_EUNSTABLE,
                                                 "neighbour grid: disc %d has more than %d "
                                                 "neighbours at step %ld (piled up?)",
                                                 s->id[i], MAX_NEIGHBOURS, s->step);
                            nb[k++] = j;
                        }
                    }
                }
            }
            /* Insertion sort: k is small. */
            for (int a = 1; a < k; a++) {
                int32_t v = nb[a];
                int b = a - 1;
                while (b >= 0 && nb[b] > v) {
                    nb[b + 1] = nb[b];
                    b--;
                }
                nb[b + 1] = v;
            }
            if (fresh->n + k > fresh->cap && grow(fresh, fresh->n + k, err))
                return err->code;
            for (int a = 0; a < k; a++)
                push(fresh, i, nb[a]);
        }
    }
    bal_pairs_merge_history(fresh, &s->pp);
    swap_pairs(&s->pp, fresh);

    /* --- disc–wall candidates ------------------------------------- */
    fresh = &s->scratch_pw;
    fresh->n = 0;
    if (grow(fresh, s->pw.n, err))
        return err->code;
    for (int i = 0; i < n; i++) {
        for (int k = 0; k < s->n_walls; k++) {
            if (s->use_grid) {
                double cx, cy;
                const double d2 = bal_walls_closest(&s->walls[k], s->x[i], s->y[i], &cx, &cy);
                const double reach = s->r[i] + s->skin;
                if (d2 >= reach * reach)
                    continue;
            }
            if (fresh->n + 1 > fresh->cap && grow(fresh, fresh->n + 1, err))
                return err->code;
            push(fresh, i, k);
        }
    }
    bal_pairs_merge_history(fresh, &s->pw);
    swap_pairs(&s->pw, fresh);

    if (s->use_grid) {
        memcpy(s->x_ref, s->x, (size_t)n * sizeof *s->x);
        memcpy(s->y_ref, s->y, (size_t)n * sizeof *s->y);
        for (int k = 0; k < s->n_walls; k++)
            s->walls[k].disp = 0;
    }
    s->need_rebuild = 0;
    s->rebuilds++;
    return BAL_OK;
}
