/*
 * grid.c — neighbour search: the candidate lists of disc–disc and disc–wall
 * pairs that the contact loops run over.
 *
 * Two modes.  With few discs every pair is a candidate: the list is built
 * once and never rebuilt, and the step pays nothing for a grid.  With many
 * discs a cell grid finds the pairs whose gap is below a Verlet skin, and
 * the lists are rebuilt only when some disc (or wall) has moved far enough
 * to close that skin (bal_grid_due, from the displacements the position
 * pass of integrate.c returns; when the two largest could have closed it,
 * it looks at the discs that moved most).  The cross-over
 * BAL_GRID_CROSSOVER was measured with `build/bench --grid` (docs/benchmarks.md).
 *
 * Cells are square with side 2 r_max + skin, so every candidate of a disc
 * lies in its own cell or the eight around it.  Discs are binned by a
 * counting sort.  For each disc i, in index order, its candidates j > i are
 * gathered and sorted by j, which leaves the whole list sorted by key
 * (i << 32 | j) without a global sort; the history of the old list is then
 * carried over by one linear merge (match_old and install, below).
 *
 * Memory: a rebuild writes the new list into a scratch of keys and pair
 * indices and carries the history over one column at a time, so it needs
 * about 21 bytes a candidate beside the list itself.  Lists grow by a
 * quarter, and only here, in a rebuild; the contact loops never allocate.
 *
 * Every BAL_REORDER_EVERY rebuilds the discs are re-sorted into the cell
 * order of their current positions (bal_grid_reorder), because flow
 * scatters neighbours across memory.  The rebuild that follows finds each
 * pair's history through the permutation.
 *
 * Kept whole (about 740 lines): the search, the merge that carries history
 * into the new list, the re-sort and the choice of skin all read and write
 * the same scratch (struct bal_rebuild_scratch) and the same invariant, the
 * list sorted by key with its history beside it; split, each part would have
 * to restate that invariant, and the merge is the one place history crosses
 * a rebuild (issue 30).
 */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grid.h"
#include "pairs.h"
#include "specimen.h"
#include "walls.h"

/* Most candidates one disc can have in a rebuild (grid.h). */
#define MAX_NEIGHBOURS BAL_MAX_NEIGHBOURS

void bal_grid_free(struct bal_grid *g)
{
    free(g->start);
    free(g->list);
    free(g->cell);
    memset(g, 0, sizeof *g);
}

/* Room for `need` pairs in list p (its own columns) — grown by a quarter,
 * so that a growing packing does not double its memory. */
static enum bal_status grow(struct bal_pairs *p, long need, struct bal_error *err)
{
    if (need <= p->cap)
        return BAL_OK;
    long cap = p->cap + p->cap / 4 + 64;
    if (cap < need)
        cap = need + need / 8 + 64;
    if (bal_pairs_reserve(p, cap))
        return bal_error(err, BAL_ENOMEM, "neighbour list: out of memory for %ld pairs", cap);
    return BAL_OK;
}

static enum bal_status grow_scratch(struct bal_rebuild_scratch *rs, long need,
                                    struct bal_error *err)
{
    if (need <= rs->cap)
        return BAL_OK;
    long cap = rs->cap + rs->cap / 4 + 64;
    if (cap < need)
        cap = need + need / 8 + 64;
    void *k = realloc(rs->key, (size_t)cap * sizeof *rs->key);
    if (k)
        rs->key = k;
    void *m = realloc(rs->map, (size_t)cap * sizeof *rs->map);
    if (m)
        rs->map = m;
    void *c = rs->col;
    if (cap > rs->col_cap) {
        c = realloc(rs->col, (size_t)cap * sizeof *rs->col);
        if (c) {
            rs->col = c;
            rs->col_cap = cap;
        }
    }
    void *b = realloc(rs->bytes, (size_t)cap * sizeof *rs->bytes);
    if (b)
        rs->bytes = b;
    if (!k || !m || !c || !b)
        return bal_error(err, BAL_ENOMEM, "neighbour list: out of memory for %ld pairs", cap);
    rs->cap = cap;
    return BAL_OK;
}

void bal_grid_scratch_free(struct bal_rebuild_scratch *rs)
{
    free(rs->key);
    free(rs->map);
    free(rs->col);
    free(rs->bytes);
    memset(rs, 0, sizeof *rs);
}

static inline enum bal_status push(struct bal_rebuild_scratch *rs, long *n, int i, int j,
                                   struct bal_error *err)
{
    if (*n + 1 > rs->cap && grow_scratch(rs, *n + 1, err))
        return err->code;
    rs->key[*n] = ((uint64_t)(uint32_t)i << 32) | (uint32_t)j;
    (*n)++;
    return BAL_OK;
}

/* Where each new pair sat in the old list.  Normally both lists number the
 * discs alike and one linear pass matches them; right after a re-sort the
 * old list still uses the old numbers, so each new pair is translated back
 * through the permutation and looked up by binary search. */
static void match_old(const struct bal_sim *s, const struct bal_pairs *old,
                      struct bal_rebuild_scratch *rs, long n, int walls)
{
    if (!s->reordered) {
        long a = 0;
        for (long c = 0; c < n; c++) {
            const uint64_t k = rs->key[c];
            while (a < old->n && pair_key(old, a) < k)
                a++;
            rs->map[c] = (int32_t)(a < old->n && pair_key(old, a) == k ? a : -1);
        }
        return;
    }
    for (long c = 0; c < n; c++) {
        const int ni = (int)(rs->key[c] >> 32), nj = (int)(rs->key[c] & 0xffffffffu);
        int i = s->new2old[ni], j = walls ? nj : s->new2old[nj];
        if (!walls && j < i) {
            const int t = i;
            i = j;
            j = t;
        }
        rs->map[c] = (int32_t)bal_pairs_find(old, ((uint64_t)(uint32_t)i << 32) | (uint32_t)j);
    }
}

static void gather(double *column, struct bal_rebuild_scratch *rs, long n)
{
    for (long c = 0; c < n; c++)
        rs->col[c] = rs->map[c] >= 0 ? column[rs->map[c]] : 0.0;
    memcpy(column, rs->col, (size_t)n * sizeof *column);
}

/* Replace list p by the n new pairs in rs, carrying the history over. */
static enum bal_status install(const struct bal_sim *s, struct bal_pairs *p,
                               struct bal_rebuild_scratch *rs, long n, int walls,
                               struct bal_error *err)
{
    if (n <= 0) {
        p->n = 0;
        return BAL_OK;
    }
    match_old(s, p, rs, n, walls);
    if (grow(p, n, err))
        return err->code;
    gather(p->fn, rs, n);
    if (p->shear)
        gather(p->fs, rs, n);
    if (p->damping) {
        gather(p->dn, rs, n);
        gather(p->ds, rs, n);
    }
    if (p->rolling) {
        gather(p->mr, rs, n);
        gather(p->tr, rs, n);
        if (p->damping)
            gather(p->dm, rs, n);
        /* A re-sort can turn a pair round (its lower slot becomes the
         * higher).  F_s keeps its meaning (ṡ is the same seen from either
         * disc), but the rolling history is oriented, θ_r = ∫(ω_x − ω_y):
         * it changes sign with the order. */
        if (s->reordered && !walls)
            for (long c = 0; c < n; c++) {
                const int ni = (int)(rs->key[c] >> 32), nj = (int)(rs->key[c] & 0xffffffffu);
                if (rs->map[c] >= 0 && s->new2old[ni] > s->new2old[nj]) {
                    p->mr[c] = -p->mr[c];
                    p->tr[c] = -p->tr[c];
                }
            }
    }
    for (long c = 0; c < n; c++)
        rs->bytes[c] = rs->map[c] >= 0 ? p->flags[rs->map[c]] : 0;
    memcpy(p->flags, rs->bytes, (size_t)n * sizeof *p->flags);
    for (long c = 0; c < n; c++) {
        p->i[c] = (int32_t)(rs->key[c] >> 32);
        p->j[c] = (int32_t)(rs->key[c] & 0xffffffffu);
    }
    p->n = n;
    return BAL_OK;
}

/* The grid cell (column cx, row cy) of the point (x, y); the last cell
 * takes the far edge. */
static inline void cell_of(double x, double y, const struct bal_grid *g, double inv_h, int *cx,
                           int *cy)
{
    *cx = bal_cell_index((x - g->x0) * inv_h, g->nx);
    *cy = bal_cell_index((y - g->y0) * inv_h, g->ny);
}

/* The disc–disc candidates of every disc, from the grid just binned, into
 * rs (count of them).  The three cells of a row are adjacent in `list`: one
 * range each.  Every disc of the nine cells is tested and stored, and k
 * moves on only for a candidate: whether j > i and whether it is near are
 * both unpredictable, and as branches they cost the rebuild about half its
 * time.  With `band` (skin_rule = motion) it also counts, in *edge, the
 * candidates in the outer half of the skin; without, that code is not
 * compiled in. */
static inline __attribute__((always_inline)) enum bal_status
search(struct bal_sim *s, double inv_h, long *count, long *edge, const int band,
       struct bal_error *err)
{
    const struct bal_grid *g = &s->grid;
    struct bal_rebuild_scratch *rs = &s->rs;
    const int n = s->n, nx = g->nx, ny = g->ny;
    /* nb has room for one store past the limit. */
    int32_t nb[MAX_NEIGHBOURS + 1];
    int any_fixed = 0;
    for (int i = 0; i < n; i++)
        any_fixed |= s->fixed[i];
    const double *restrict x = s->x, *restrict y = s->y, *restrict r = s->r;
    const double skin = s->skin, half = 0.5 * skin;
    long near = 0;
    for (int i = 0; i < n; i++) {
        /* its cell again, rather than two divisions of g->cell[i] */
        int cx, cy;
        cell_of(x[i], y[i], g, inv_h, &cx, &cy);
        const int xlo = cx > 0 ? cx - 1 : 0, xhi = cx + 1 < nx ? cx + 1 : nx - 1;
        const int ylo = cy > 0 ? cy - 1 : 0, yhi = cy + 1 < ny ? cy + 1 : ny - 1;
        const double xi = x[i], yi = y[i], ri = r[i];
        /* Two held discs never move: their contact is no part of the
         * dynamics (rare: tested as a branch, after the rest). */
        const int held = any_fixed && s->fixed[i];
        int k = 0;
        for (int yy = ylo; yy <= yhi; yy++) {
            const int a1 = g->start[yy * nx + xhi + 1];
            for (int a = g->start[yy * nx + xlo]; a < a1; a++) {
                const int j = g->list[a];
                const double dx = x[j] - xi, dy = y[j] - yi;
                const double rs2 = ri + r[j], reach = rs2 + skin, d2 = dx * dx + dy * dy;
                int keep = (j > i) & (d2 < reach * reach);
                if (held)
                    keep &= !s->fixed[j];
                if (band)
                    near += keep & (d2 < (rs2 + half) * (rs2 + half));
                nb[k] = j;
                k += keep;
                if (k == MAX_NEIGHBOURS + 1) {
                    s->crowded = i + 1;
                    char name[2 * BAL_NAME_MAX];
                    bal_specimen_disc_name(s->scene, s->id[i], name, sizeof name);
                    return bal_error(err, BAL_EUNSTABLE,
                                     "%s: disc %s has more than %d neighbours within "
                                     "reach at step %ld (piled up?)",
                                     s->scene->path, name, MAX_NEIGHBOURS, s->step);
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
        for (int a = 0; a < k; a++)
            if (push(rs, count, i, nb[a], err))
                return err->code;
    }
    if (band)
        *edge = *count - near;
    return BAL_OK;
}

/* ------------------------------------------------------------------ */
/* The skin from the measured motion (skin_rule = motion)              */
/* ------------------------------------------------------------------ */

/* A rebuild's cost per disc, in units of the pair loop's cost for one more
 * candidate in one cycle.  Calibrated on the settling race scene of
 * bench-peer (20 000 discs falling, 2026-11-27, docs/benchmarks.md): at skin
 * 0.15 a rebuild took 69 ns a disc and the pair loop 7.1 ns an average
 * candidate (9.7), but the candidates a wider skin adds do not touch and
 * cost about a third of the average: with 10 the rule chose half the best
 * fixed skin (5.15 against 5.5e7 particle-steps/s), with 25 it matched it
 * (5.48e7; 40 gave 5.49e7). */
#define REBUILD_COST_IN_CANDIDATES 25.0
/* The rule's bounds, as shares of the largest radius, and its largest step
 * (a factor) from one rebuild to the next. */
#define SKIN_LO 0.05
#define SKIN_HI 1.0
#define SKIN_STEP 2.0

/* The largest displacement of a wall since the lists were built. */
static double walls_moved(const struct bal_sim *s)
{
    double wmax = 0;
    for (int k = 0; k < s->n_walls; k++)
        wmax = fmax(wmax, s->walls[k].disp);
    return wmax;
}

/* The widest skin the rule may choose: SKIN_HI r_max, and no wider than
 * keeps the candidates of a disc of the smallest radius within half of
 * MAX_NEIGHBOURS (discs of radius r_min packed around it out to r_min +
 * r_max + skin: ((r_min + r_max + skin)/r_min)² <= MAX_NEIGHBOURS/2), so that
 * a wide grading never meets the rebuild's limit because of the rule; but
 * never below SKIN_LO r_max. */
static double motion_skin_max(const struct bal_sim *s)
{
    const double crowd = sqrt(0.5 * MAX_NEIGHBOURS) * s->r_min - s->r_min - s->r_max;
    return fmax(fmin(SKIN_HI * s->r_max, crowd), SKIN_LO * s->r_max);
}

/* The skin of the next lists.  A cycle costs about
 *
 *     J(s) = C N / T(s) + n(s)          (in candidate-cycles)
 *
 * C = REBUILD_COST_IN_CANDIDATES, N discs, n(s) candidates, T(s) the cycles
 * between rebuilds.  The lists break when two discs have closed the skin
 * between them (or a disc and a wall): T(s) = s/u, with u = (the larger of
 * 2 d_1 and d_1 + the walls' largest displacement) / (cycles since the last
 * rebuild), measured now.  J'(s) = 0 at
 *
 *     s = sqrt(C N u / n'(s)),
 *
 * n'(s) the candidates per unit of skin at the edge of the skin, which the
 * last search measured (its outer half: skin_edge).  The rule uses only
 * positions and counts, never the clock, so a run is the same on any
 * machine and thread count; what it changes is when rebuilds happen, never
 * which contacts the lists hold (bal_grid_due reads the skin they were
 * built with). */
static double motion_skin(const struct bal_sim *s)
{
    const long cycles = s->step - s->built_step;
    if (cycles <= 0 || s->skin_edge <= 0)
        return s->skin;
    const double d1 = sqrt(s->moved_sq), wmax = walls_moved(s);
    const double u = fmax(2 * d1, d1 + wmax) / (double)cycles;
    double skin = sqrt(REBUILD_COST_IN_CANDIDATES * s->n * u / s->skin_edge);
    if (!isfinite(skin))
        return s->skin;
    skin = fmin(fmax(skin, s->skin / SKIN_STEP), s->skin * SKIN_STEP);
    return fmin(fmax(skin, SKIN_LO * s->r_max), motion_skin_max(s));
}

enum bal_status bal_grid_rebuild(struct bal_sim *s, struct bal_error *err)
{
    const int n = s->n;
    struct bal_rebuild_scratch *rs = &s->rs;
    long count = 0;
    s->crowded = 0;

    /* --- disc–disc candidates ------------------------------------- */
    if (!s->use_grid) {
        if (grow_scratch(rs, (long)n * (n - 1) / 2, err))
            return err->code;
        for (int i = 0; i < n; i++)
            for (int j = i + 1; j < n; j++)
                if (!(s->fixed[i] && s->fixed[j]) && push(rs, &count, i, j, err))
                    return err->code;
    } else {
        struct bal_grid *g = &s->grid;
        if (s->skin_rule == BAL_SKIN_MOTION)
            s->skin = motion_skin(s);
        double x0 = s->x[0], x1 = s->x[0], y0 = s->y[0], y1 = s->y[0];
        for (int i = 1; i < n; i++) { /* comparisons: fmin/fmax are libm calls */
            const double xi = s->x[i], yi = s->y[i];
            x0 = xi < x0 ? xi : x0;
            x1 = xi > x1 ? xi : x1;
            y0 = yi < y0 ? yi : y0;
            y1 = yi > y1 ? yi : y1;
        }
        if (!(isfinite(x0) && isfinite(x1) && isfinite(y0) && isfinite(y1))) {
            int bad = 0;
            while (bad < n - 1 && isfinite(s->x[bad] + s->y[bad]))
                bad++;
            char name[2 * BAL_NAME_MAX];
            bal_specimen_disc_name(s->scene, s->id[bad], name, sizeof name);
            return bal_error(err, BAL_EUNSTABLE,
                             "%s: disc %s: its position is not finite at step %ld (neighbour grid)",
                             s->scene->path, name, s->step);
        }
        if (!(isfinite(x1 - x0) && isfinite(y1 - y0)))
            return bal_error(err, BAL_EUNSTABLE,
                             "%s: neighbour grid: the discs spread over more than the largest "
                             "number (x %g to %g, y %g to %g) at step %ld", s->scene->path, x0,
                             x1, y0, y1, s->step);
        double h = 2 * s->r_max + s->skin;
        /* A sparse scene spread over a large area would need many empty
         * cells; widen the cells so there are at most about 2 per disc. */
        double cells = ((x1 - x0) / h + 1) * ((y1 - y0) / h + 1);
        if (cells > 2.0 * n + 16)
            h *= sqrt(cells / (2.0 * n + 16));
        /* A long thin sparse scene keeps too many cells along its long side
         * after that; widen further (the candidates do not depend on h; the
         * cell counts must fit an int).  Seen while fixing a fuzzing finding. */
        while (((x1 - x0) / h + 1) * ((y1 - y0) / h + 1) > 8.0 * n + 64 && isfinite(h))
            h *= 2;
        /* At most 8 n + 64 cells (the loop above), so both fit an int. */
        int nx = bal_cell_index((x1 - x0) / h, INT_MAX - 1) + 1;
        int ny = bal_cell_index((y1 - y0) / h, INT_MAX - 1) + 1;
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
            int cx, cy;
            cell_of(s->x[i], s->y[i], g, inv_h, &cx, &cy);
            g->cell[i] = cy * nx + cx;
            g->start[g->cell[i] + 1]++;
        }
        for (long c = 0; c < nc; c++)
            g->start[c + 1] += g->start[c];
        for (int i = 0; i < n; i++)
            g->list[g->start[g->cell[i]]++] = i;
        for (long c = nc; c > 0; c--)
            g->start[c] = g->start[c - 1];
        g->start[0] = 0;

        if (s->skin_rule == BAL_SKIN_MOTION) {
            long edge = 0;
            if (search(s, inv_h, &count, &edge, 1, err))
                return err->code;
            /* candidates in the outer half of the skin, per unit of skin */
            s->skin_edge = (double)(edge > 0 ? edge : 1) / (0.5 * s->skin);
        } else if (search(s, inv_h, &count, NULL, 0, err))
            return err->code;
    }
    if (install(s, &s->pp, rs, count, 0, err))
        return err->code;
    if (bal_pairs_reserve_chunks(s))
        return bal_error(err, BAL_ENOMEM, "neighbour list: out of memory for %ld pairs",
                         s->pp.cap);

    /* --- disc–wall candidates ------------------------------------- */
    count = 0;
    for (int i = 0; i < n; i++) {
        for (int k = 0; k < s->n_walls; k++) {
            if (s->use_grid) {
                const struct bal_wall *W = &s->walls[k];
                const double reach = s->r[i] + s->skin;
                /* The distance to the wall's line first: most discs are far
                 * from most walls, and the segment is no closer than its line. */
                if (fabs((s->y[i] - W->p[1]) * W->e[0] - (s->x[i] - W->p[0]) * W->e[1]) >= reach)
                    continue;
                double cx, cy;
                if (bal_walls_closest(W, s->x[i], s->y[i], &cx, &cy) >= reach * reach)
                    continue;
            }
            if (push(rs, &count, i, k, err))
                return err->code;
        }
    }
    if (install(s, &s->pw, rs, count, 1, err))
        return err->code;
    s->reordered = 0;

    if (s->use_grid) {
        memcpy(s->x_ref, s->x, (size_t)n * sizeof *s->x);
        memcpy(s->y_ref, s->y, (size_t)n * sizeof *s->y);
        for (int k = 0; k < s->n_walls; k++)
            s->walls[k].disp = 0;
    }
    s->need_rebuild = 0;
    s->built_step = s->step;
    s->rebuilds++;
    return BAL_OK;
}

/* ------------------------------------------------------------------ */
/* When the lists break                                                 */
/* ------------------------------------------------------------------ */

/* At most this many discs are looked at one by one (below); with more the
 * packing is flowing, and a rebuild is due anyway. */
#define MAX_MOVERS 32

/* Can mover m, displaced by dm < skin since the rebuild, touch a disc j it
 * is not listed with?  Only if d_m + d_j >= skin (else the gap of at least
 * the skin that kept them apart is still open) and their distance at the
 * rebuild is below r_m + r_j + d_m + d_j.  Such a j lay within 2 r_max +
 * 2 skin < 2 h of m at the rebuild, so within two cells of m's cell then. */
static int mover_can_touch(const struct bal_sim *s, int m, double dm)
{
    const struct bal_grid *g = &s->grid;
    const double need = s->skin - dm;
    int cx, cy;
    cell_of(s->x_ref[m], s->y_ref[m], g, 1 / g->h, &cx, &cy);
    const int xlo = cx > 1 ? cx - 2 : 0, xhi = cx + 2 < g->nx ? cx + 2 : g->nx - 1;
    const int ylo = cy > 1 ? cy - 2 : 0, yhi = cy + 2 < g->ny ? cy + 2 : g->ny - 1;
    for (int yy = ylo; yy <= yhi; yy++) {
        const int a1 = g->start[yy * g->nx + xhi + 1];
        for (int a = g->start[yy * g->nx + xlo]; a < a1; a++) {
            const int j = g->list[a];
            const double dj2 = j == m ? 0 : bal_moved_sq(s, j);
            if (dj2 < need * need)
                continue;
            const double dx = s->x_ref[j] - s->x_ref[m], dy = s->y_ref[j] - s->y_ref[m];
            /* a margin of 1e-9 for the rounding of the distances */
            const double reach = (s->r[m] + s->r[j] + dm + sqrt(dj2)) * (1 + 1e-9);
            if (dx * dx + dy * dy >= reach * reach)
                continue;
            /* (m moved, so it is not held: the pair would be listed) */
            const int lo = m < j ? m : j, hi = m < j ? j : m;
            if (bal_pairs_find(&s->pp, ((uint64_t)(uint32_t)lo << 32) | (uint32_t)hi) < 0)
                return 1;
        }
    }
    return 0;
}

/* d_1 + d_2 >= skin says only that two discs somewhere have moved far;
 * in a large packing they are mostly rattlers far apart, each in its own
 * cage.  A pair that can touch has d_i + d_j >= skin, so one of them has
 * moved at least skin/2: those discs (the movers) lie in blocks whose
 * largest displacement is at least that, and each is checked against the
 * discs around it. */
static int lists_broken(const struct bal_sim *s, double d1)
{
    const double skin = s->skin, half_sq = 0.25 * skin * skin;
    if (d1 >= skin)
        return 1;
    const int blocks = bal_disc_blocks(s->n);
    int movers = 0;
    for (int b = 0; b < blocks; b++) {
        if (s->par.block_sums[2 * b] < half_sq)
            continue;
        const int to = bal_block_end(s->n, b);
        for (int m = b * BAL_DISC_BLOCK; m < to; m++) {
            const double dm2 = bal_moved_sq(s, m);
            if (dm2 < half_sq)
                continue;
            if (++movers > MAX_MOVERS || mover_can_touch(s, m, sqrt(dm2)))
                return 1;
        }
    }
    return 0;
}

/* ------------------------------------------------------------------ */
/* Re-sorting discs into cell order                                     */
/* ------------------------------------------------------------------ */

static int cell_key_cmp(const void *a, const void *b)
{
    const struct bal_cell_key *p = a, *q = b;
    if (p->cell != q->cell)
        return p->cell < q->cell ? -1 : 1;
    return (p->slot > q->slot) - (p->slot < q->slot);
}

/* Cell index along one axis of an offset d >= 0; far (or non-finite)
 * offsets share the last cell, so the key never overflows (found by
 * fuzzing: a disc at x = 7e109 made the conversion undefined).  The order is
 * only for memory locality; ordinary scenes never reach the cap. */
static long cell_coord(double d, double h)
{
    const double c = d / h;
    return c < 1e9 ? (long)c : 1000000000L;
}

void bal_grid_cell_order(const double *x, const double *y, int n, double h,
                         struct bal_cell_key *keys, int32_t *order)
{
    double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY;
    for (int i = 0; i < n; i++) {
        x0 = fmin(x0, x[i]);
        y0 = fmin(y0, y[i]);
        x1 = fmax(x1, x[i]);
    }
    const long nx = cell_coord(x1 - x0, h) + 1;
    for (int i = 0; i < n; i++)
        keys[i] = (struct bal_cell_key){cell_coord(y[i] - y0, h) * nx + cell_coord(x[i] - x0, h), i};
    qsort(keys, (size_t)n, sizeof *keys, cell_key_cmp);
    for (int i = 0; i < n; i++)
        order[i] = keys[i].slot;
}

/* a[new] = a[new2old[new]]; the rebuild scratch column is the buffer. */
static void permute_doubles(struct bal_sim *s, double *a, int stride)
{
    double *t = s->rs.col;
    for (int i = 0; i < s->n; i++)
        for (int k = 0; k < stride; k++)
            t[(long)stride * i + k] = a[(long)stride * s->new2old[i] + k];
    memcpy(a, t, (size_t)s->n * (size_t)stride * sizeof *a);
}

static void permute_int32(struct bal_sim *s, int32_t *a)
{
    int32_t *t = (int32_t *)s->rs.col;
    for (int i = 0; i < s->n; i++)
        t[i] = a[s->new2old[i]];
    memcpy(a, t, (size_t)s->n * sizeof *a);
}

static void permute_uint8(struct bal_sim *s, uint8_t *a)
{
    uint8_t *t = (uint8_t *)s->rs.col;
    for (int i = 0; i < s->n; i++)
        t[i] = a[s->new2old[i]];
    memcpy(a, t, (size_t)s->n * sizeof *a);
}

enum bal_status bal_grid_reorder(struct bal_sim *s, struct bal_error *err)
{
    const int n = s->n;
    if (n >= 2) {
        /* The sort keys (2 doubles a disc) and the permutation buffer live
         * in the rebuild scratch column; the force sums need 3 a disc,
         * stress moments 4. */
        const long need = (s->moment_prev ? 4L : 3L) * n;
        if (need > s->rs.col_cap) {
            double *c = realloc(s->rs.col, (size_t)need * sizeof *c);
            if (!c)
                return bal_error(err, BAL_ENOMEM, "re-sort: out of memory for %d discs", n);
            s->rs.col = c;
            s->rs.col_cap = need;
        }
        bal_grid_cell_order(s->x, s->y, n, 2 * s->r_max + s->skin,
                            (struct bal_cell_key *)s->rs.col, s->new2old);

        double *columns[] = {s->x, s->y, s->th, s->vx, s->vy, s->w, s->r, s->inv_m, s->inv_i};
        for (size_t k = 0; k < sizeof columns / sizeof columns[0]; k++)
            permute_doubles(s, columns[k], 1);
        permute_doubles(s, s->f, 3);
        if (s->moment_prev)
            permute_doubles(s, s->moment_prev, 4);
        permute_int32(s, s->id);
        permute_int32(s, s->mat);
        if (s->row)
            permute_int32(s, s->row);
        permute_uint8(s, s->fixed);
        if (s->hold)
            permute_uint8(s, s->hold);
        for (int i = 0; i < n; i++)
            s->slot[s->id[i]] = i;
        for (int k = 0; k < s->n_probes; k++) {
            struct bal_probe_ref *p = &s->probes[k];
            const int disc_a = !p->a_wall && (bal_probe_is_contact(p->kind) ||
                                              (p->kind >= BAL_PROBE_DISC_X &&
                                               p->kind <= BAL_PROBE_DISC_OMEGA));
            const int disc_b = !p->b_wall && bal_probe_is_contact(p->kind);
            const int old_a = p->a, old_b = p->b;
            for (int i = 0; i < n && (disc_a || disc_b); i++) {
                if (disc_a && s->new2old[i] == old_a)
                    p->a = i;
                if (disc_b && s->new2old[i] == old_b)
                    p->b = i;
            }
        }
        s->reordered = 1;
        s->reorders++;
    }
    return bal_grid_rebuild(s, err);
}

/* A pair left out of the list had a gap of at least the skin when it was
 * built, and the gap of discs i and j closes by at most d_i + d_j <= d_1 +
 * d_2 (the two largest displacements of distinct discs), so the list holds
 * every contact until d_1 + d_2 reaches the skin.  (The usual 2 d_1 rebuilds
 * twice as often when a single rattler moves.)  Then the movers are looked
 * at one by one (lists_broken): two rattlers far apart cannot touch, and in
 * a large packing there are always some.  A disc and a wall: d_1 + the
 * wall's largest displacement. */
int bal_grid_due(const struct bal_sim *s, struct bal_moves moved)
{
    if (!s->use_grid)
        return 0;
    const double d1 = sqrt(moved.d1_sq), d2 = sqrt(moved.d2_sq), wmax = walls_moved(s);
    return d1 + wmax >= s->skin || (d1 + d2 >= s->skin && lists_broken(s, d1));
}
