/*
 * specimen.c — the discs a scene generates, in scene order.  Kept whole
 * (about 800 lines): see "Kept whole" below.
 *
 * A scene places discs one by one ([disc] sections) or by generators, laid
 * out here before the builder (build.c) sorts them into cell order:
 *
 *   [fill]  n discs on a square lattice of spacing 2 rmax, `columns` to a
 *           row, filled row by row from the region's lower-left corner;
 *           radii uniform in [rmin, rmax] and, with vmax > 0, speeds uniform
 *           in [0, vmax) in uniform directions, drawn from a SplitMix64
 *           generator seeded by the section (same seed, same discs on every
 *           platform; no global state);
 *   [pile]  equal discs on a triangular lattice (MLH Sec. 4, Fig. 2): row M
 *           holds L − 3M (30°) or L − M (60°) discs, each row at the lowest
 *           height where it touches the row below (struct bal_pile_def);
 *           with size_spread > 0, discs of random diameters on the same
 *           lattice (MLH Sec. 4.4; lay_pile_spread below).
 *   [grains] n discs from a grading curve (grading.c), placed at random
 *           without overlap in a rectangle (lay_grains below);
 *   [import] the discs of a discs.tsv a run wrote, unchanged (read when the
 *           scene was parsed: import.c).
 *
 * [grains] draws its numbers from GSL's gsl_rng_mt19937 seeded with the
 * section's seed (the same discs on every machine): first two per disc for
 * the diameters (bal_specimen_grading_diameter), then two per try for the
 * places.  The discs are placed largest first (random sequential addition:
 * each at a uniform random place inside the region, kept if it overlaps no
 * disc placed before, tried up to `tries` times; a cell grid of side dmax
 * finds the neighbours), and numbered in that order.  Random sequential
 * addition jams near an area fraction of 0.55 (equal discs), so a dense
 * specimen is placed loose in a tall region and then compressed by its
 * walls (the servo of walls.c).
 *
 * Scene order — [disc] sections first, then each [fill], [pile], [grains]
 * and [import], each kind in file order — is the disc's stable id: outputs
 * are written in it, and messages name a disc by it.  The table
 * `generators` near the end holds one row per generator kind (its section,
 * count, lay function, the keys its messages name, its material, its
 * random numbers); the count, the layout and the functions that turn an id
 * back into a name (FILL.k), a probe's NAME.k into an id and an id into the
 * scene line that placed the disc walk that table and name no kind.  A new
 * generator is its section in the key table (scene_keys.c) and its struct,
 * one row there and its lay function here.
 *
 * Kept as one file (about 790 lines): the lay functions and the table that
 * walks them are one responsibility, scene order, and the table needs every
 * lay function beside it; the grading curve's maths, which needs none of
 * it, is grading.c.
 *
 * Kept whole (about 790 lines): every function here turns the scene's
 * generator sections into discs in scene order or back (count, lay, name,
 * origin, find), all through the one generator table; split by generator,
 * each file would need the table's walk and scene order again.  The grading
 * curve's maths, which needs neither, is its own file (grading.c).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_rng.h>

#include "scene.h"
#include "specimen.h"
#include "status.h"
#include "state.h" /* BAL_PI */

/* ------------------------------------------------------------------ */
/* Counting                                                            */
/* ------------------------------------------------------------------ */

/* Discs in row M of a pile (0 when the pile has no row M). */
static long pile_row_count(const struct bal_pile_def *p, long M)
{
    const long n = p->L - (p->slope == 0 ? 3 : 1) * M;
    return n > 0 ? n : 0;
}

long bal_specimen_pile_rows(const struct bal_pile_def *p)
{
    long rows = 0;
    while (pile_row_count(p, rows) > 0)
        rows++;
    return rows;
}

long bal_specimen_pile_count(const struct bal_pile_def *p)
{
    long n = 0;
    for (long M = 0; pile_row_count(p, M) > 0; M++)
        n += pile_row_count(p, M);
    return n;
}

/* ------------------------------------------------------------------ */
/* Generators                                                          */
/* ------------------------------------------------------------------ */

/* A small, seedable generator (SplitMix64) kept in a local variable: no
 * global state, the same seed gives the same discs on every platform. */
static uint64_t splitmix64(uint64_t *state)
{
    uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static double uniform01(uint64_t *state)
{
    return (double)(splitmix64(state) >> 11) * (1.0 / 9007199254740992.0);
}

/* The discs of the [disc] sections, from index k on; returns the index
 * after the last. */
static int lay_discs(const struct bal_scene *sc, struct bal_specimen *d, int k)
{
    for (int i = 0; i < sc->n_discs; i++, k++) {
        const struct bal_disc_def *dd = &sc->discs[i];
        d->x[k] = dd->x[0];
        d->y[k] = dd->x[1];
        d->r[k] = dd->r;
        d->vx[k] = dd->v[0];
        d->vy[k] = dd->v[1];
        d->th[k] = dd->theta * (BAL_PI / 180);
        d->w[k] = dd->omega;
        d->mat[k] = bal_scene_find(sc, BAL_SEC_MATERIAL, dd->material);
        /* Holding every component is holding the disc: fixed = 1, with
         * everything that goes with it (no pair of held discs, no weight). */
        const unsigned hold = (unsigned)dd->hold & BAL_HOLD_ALL;
        d->fixed[k] = (uint8_t)(dd->fixed != 0 || hold == BAL_HOLD_ALL);
        d->hold[k] = (uint8_t)(d->fixed[k] ? 0 : hold);
    }
    return k;
}

/* A [fill] lattice from index k on; returns the index after the last disc. */
static int lay_fill(const struct bal_scene *sc, const void *section, int mat,
                    struct bal_specimen *d, int k, struct bal_error *err)
{
    (void)sc;
    (void)err; /* a lattice allocates nothing and cannot fail */
    const struct bal_fill_def *fd = section;
    uint64_t rng = (uint64_t)fd->seed;
    const double pitch = 2 * fd->rmax;
    for (long q = 0; q < fd->n; q++, k++) {
        const long row = q / fd->columns, col = q % fd->columns;
        d->x[k] = fd->origin[0] + fd->rmax + (double)col * pitch;
        d->y[k] = fd->origin[1] + fd->rmax + (double)row * pitch;
        d->r[k] = fd->rmin + (fd->rmax - fd->rmin) * uniform01(&rng);
        if (fd->vmax > 0) {
            const double speed = fd->vmax * uniform01(&rng);
            const double dir = 2 * BAL_PI * uniform01(&rng);
            d->vx[k] = speed * cos(dir);
            d->vy[k] = speed * sin(dir);
        }
        d->mat[k] = mat;
    }
    return k;
}

/* Lay out a pile of equal discs (struct bal_pile_def documents the rules)
 * into the arrays from index k on; returns the index after the last disc. */
static int lay_pile_equal(const struct bal_pile_def *p, int mat, struct bal_specimen *d, int k)
{
    const double dd = p->d, r = 0.5 * dd;
    const double s0 = p->bottom == 1 ? dd * (1 + p->c) : dd;
    const double s = p->bottom == 1 ? dd * fmax(1.0, 1 + p->c) : dd;
    const double xc = p->origin[0] + r + 0.5 * (double)(p->L - 1) * s0;
    int below = k;                   /* first disc of the previous row */
    long n_below = 0;
    for (long M = 0; pile_row_count(p, M) > 0; M++) {
        const long n = pile_row_count(p, M);
        const double spacing = M == 0 ? s0 : s;
        double y = p->origin[1] + r;
        if (M > 0) {
            /* The lowest height at which no disc of this row overlaps one of
             * the row below: touching in the hollows, exactly. */
            y = -INFINITY;
            for (long a = 0; a < n; a++) {
                const double x = xc + ((double)a - 0.5 * (double)(n - 1)) * spacing;
                for (long b = 0; b < n_below; b++) {
                    const double dx = fabs(x - d->x[below + b]);
                    if (dx < dd)
                        y = fmax(y, d->y[below + b] + sqrt(dd * dd - dx * dx));
                }
            }
            if (!isfinite(y))
                y = d->y[below] + dd;
        }
        const int first = k;
        for (long a = 0; a < n; a++, k++) {
            d->x[k] = xc + ((double)a - 0.5 * (double)(n - 1)) * spacing;
            d->y[k] = y;
            d->r[k] = r;
            d->mat[k] = mat;
            d->row[k] = (int32_t)M;
            d->fixed[k] = M == 0 && (p->bottom == 1 || a == 0 || a == n - 1);
        }
        below = first;
        n_below = n;
    }
    return k;
}

/* ------------------------------------------------------------------ */
/* The polydisperse pile (MLH Sec. 4.4)                                */
/* ------------------------------------------------------------------ */

/* MLH: "we change the particle size of each particle slightly to the
 * diameter d_i = d0 (1 + r_d^i), where r_d^i is a random number
 * homogeneously distributed in the interval [−r_d/2, r_d/2]".  The choices
 * the sentence leaves open, and ballast's:
 *
 *   which discs   every disc of the pile, the held ones of a bumpy bottom
 *                 and the corner stones of a smooth one too (the literal
 *                 reading of "each particle");
 *   the numbers   gsl_rng_mt19937 seeded with the pile's `seed` (GSL's own
 *                 integer generator: the same stream on every machine), one
 *                 gsl_rng_uniform u in [0, 1) per disc in scene order (row 0
 *                 left to right, then row 1, ...), r = r_d (u − 1/2);
 *   held row 0    bumpy: at the equal-disc pile's places (the centres on one
 *                 line, spacing d0 (1 + c)), only the sizes changed; they may
 *                 overlap (held discs never move).  smooth: each disc on the
 *                 floor (centre at its own radius above it);
 *   free rows     each disc as close to its lattice site as it can be without
 *                 overlapping its neighbours in the row: the x that minimise
 *                 Σ (x_a − X_a)² subject to x_{a+1} − x_a ≥ r_a + r_{a+1}
 *                 (separate_row), then the row at the lowest height where no
 *                 disc of it overlaps a disc below, as for equal discs.  With
 *                 equal discs no constraint binds and this is lay_pile's
 *                 layout; lay_pile_equal still lays size_spread = 0, so the
 *                 monodisperse piles are unchanged bit for bit.
 *
 * The pile's base width and its x0 in run.json stay those of the
 * equal-disc pile: X = (x − x0)/l is measured on the same lattice. */

/* The x of one row: the least-squares projection of the lattice sites X
 * onto the rows without overlap, x_{a+1} − x_a ≥ g_a = r_a + r_{a+1}.  With
 * G_a = Σ_{b<a} g_b and y_a = x_a − G_a the constraints read y_a ≤ y_{a+1}:
 * the isotonic regression of X_a − G_a, solved exactly by pooling adjacent
 * violators (each pool at the mean of its members).  Mirror-symmetric, and
 * the identity when no constraint binds.  work holds 3 n doubles. */
static void separate_row(const double *X, const double *r, long n, double *x, double *work)
{
    double *G = work, *sum = work + n, *count = work + 2 * n;
    long pools = 0;
    G[0] = 0;
    for (long a = 1; a < n; a++)
        G[a] = G[a - 1] + (r[a - 1] + r[a]);
    for (long a = 0; a < n; a++) {
        sum[pools] = X[a] - G[a];
        count[pools] = 1;
        pools++;
        /* merge while the last pool's mean is below the one before it */
        while (pools > 1 && sum[pools - 1] * count[pools - 2] < sum[pools - 2] * count[pools - 1]) {
            sum[pools - 2] += sum[pools - 1];
            count[pools - 2] += count[pools - 1];
            pools--;
        }
    }
    for (long q = 0, a = 0; q < pools; q++) {
        const double mean = sum[q] / count[q];
        for (long m = 0; m < (long)count[q]; m++, a++)
            x[a] = mean + G[a];
    }
}

/* A pile whose discs have random diameters (size_spread > 0; the choices
 * above).  Returns the index after the last disc, or -1 when out of memory. */
static int lay_pile_spread(const struct bal_pile_def *p, int mat, struct bal_specimen *d, int k)
{
    const double dd = p->d, r0 = 0.5 * dd;
    const double s0 = p->bottom == 1 ? dd * (1 + p->c) : dd;
    const double s = p->bottom == 1 ? dd * fmax(1.0, 1 + p->c) : dd;
    const double xc = p->origin[0] + r0 + 0.5 * (double)(p->L - 1) * s0;
    const long total = bal_specimen_pile_count(p);
    double *X = malloc(4 * (size_t)p->L * sizeof *X);
    gsl_error_handler_t *previous = gsl_set_error_handler_off();
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_set_error_handler(previous);
    if (!X || !rng) {
        free(X);
        if (rng)
            gsl_rng_free(rng);
        return -1;
    }
    gsl_rng_set(rng, p->seed);
    for (long q = 0; q < total; q++)
        d->r[k + q] = r0 * (1 + p->size_spread * (gsl_rng_uniform(rng) - 0.5));
    gsl_rng_free(rng);

    const int start = k;
    for (long M = 0; pile_row_count(p, M) > 0; M++) {
        const long n = pile_row_count(p, M);
        const double spacing = M == 0 ? s0 : s;
        const int first = k;
        for (long a = 0; a < n; a++)
            X[a] = xc + ((double)a - 0.5 * (double)(n - 1)) * spacing;
        if (M == 0 && p->bottom == 1) {
            for (long a = 0; a < n; a++)
                d->x[first + a] = X[a];
        } else {
            separate_row(X, d->r + first, n, d->x + first, X + p->L);
        }
        for (long a = 0; a < n; a++, k++) {
            const double ra = d->r[k];
            double y = p->origin[1] + (p->bottom == 1 ? r0 : ra);
            if (M > 0) {
                y = -INFINITY;
                for (int b = start; b < first; b++) {
                    const double reach = ra + d->r[b], dx = fabs(d->x[k] - d->x[b]);
                    if (dx < reach)
                        y = fmax(y, d->y[b] + sqrt(reach * reach - dx * dx));
                }
            }
            d->y[k] = y;
            d->mat[k] = mat;
            d->row[k] = (int32_t)M;
            d->fixed[k] = M == 0 && (p->bottom == 1 || a == 0 || a == n - 1);
        }
        if (M > 0) { /* one height per row: the highest any of its discs needs */
            double y = -INFINITY;
            for (int q = first; q < k; q++)
                y = fmax(y, d->y[q]);
            if (!isfinite(y)) /* nothing below within reach (not for these lattices) */
                y = d->y[first - 1] + dd;
            for (int q = first; q < k; q++)
                d->y[q] = y;
        }
    }
    free(X);
    return k;
}

/* A [pile]: equal discs, or with size_spread > 0 random diameters; returns
 * the index after the last disc, or -1 with err filled. */
static int lay_pile(const struct bal_scene *sc, const void *section, int mat,
                    struct bal_specimen *d, int k, struct bal_error *err)
{
    const struct bal_pile_def *p = section;
    k = p->size_spread > 0 ? lay_pile_spread(p, mat, d, k) : lay_pile_equal(p, mat, d, k);
    if (k < 0)
        bal_error(err, BAL_ENOMEM, "%s:%d: [pile %s]: out of memory for its layout", sc->path,
                  p->line, p->name);
    return k;
}

/* ------------------------------------------------------------------ */
/* Random placement from a grading curve (the curve itself: grading.c)  */
/* ------------------------------------------------------------------ */

static int descending(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? 1 : x > y ? -1 : 0;
}

/* A [grains] specimen (the file's header) from index k on; returns the index
 * after the last disc, or -1 with err filled. */
static int lay_grains(const struct bal_scene *sc, const void *section, int mat,
                      struct bal_specimen *d, int k, struct bal_error *err)
{
    const struct bal_grains_def *g = section;
    const long n = g->n;
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    double *dia = malloc((size_t)n * sizeof *dia);
    /* a cell grid of side dmax over the region: head of each cell's list,
     * next disc of each disc's */
    const double cell = g->dmax;
    const long nx = (long)fmin(ceil(g->size[0] / cell), 1e6) + 1;
    const long ny = (long)fmin(ceil(g->size[1] / cell), 1e6) + 1;
    const int too_many = (double)nx * (double)ny > 4.0 * (double)n + 1e6;
    long *head = too_many ? NULL : malloc((size_t)(nx * ny) * sizeof *head);
    long *next = malloc((size_t)n * sizeof *next);
    if (!rng || !dia || !next || (!too_many && !head)) {
        gsl_rng_free(rng);
        free(dia);
        free(head);
        free(next);
        bal_error(err, BAL_ENOMEM, "%s:%d: [grains %s]: out of memory for %ld discs", sc->path,
                  g->line, g->name, n);
        return -1;
    }
    if (too_many) {
        free(dia);
        free(next);
        gsl_rng_free(rng);
        const int ki = bal_scene_key_index(BAL_SEC_GRAINS, "size");
        bal_error(err, BAL_EINVAL, "%s:%d: size: [grains %s]: the region %g x %g holds %g cells "
                  "of side dmax = %g, more than 4 per disc: expected a region near the size the "
                  "discs need", sc->path, g->key_line[ki] > 0 ? g->key_line[ki] : g->line, g->name,
                  g->size[0], g->size[1], (double)nx * (double)ny, g->dmax);
        return -1;
    }
    gsl_rng_set(rng, g->seed);
    for (long q = 0; q < n; q++) {
        const double u1 = gsl_rng_uniform(rng);
        const double u2 = gsl_rng_uniform(rng);
        dia[q] = bal_specimen_grading_diameter(g, u1, u2);
    }
    qsort(dia, (size_t)n, sizeof *dia, descending);
    for (long c = 0; c < nx * ny; c++)
        head[c] = -1;
    const double x0 = g->origin[0], y0 = g->origin[1];
    double area = 0;
    const int first = k;
    for (long q = 0; q < n; q++) {
        const double r = 0.5 * dia[q];
        const double wx = g->size[0] - 2 * r, wy = g->size[1] - 2 * r;
        int placed = 0;
        double x = 0, y = 0;
        for (long t = 0; t < g->tries && !placed; t++) {
            x = x0 + r + gsl_rng_uniform(rng) * wx;
            y = y0 + r + gsl_rng_uniform(rng) * wy;
            const long cx = (long)((x - x0) / cell), cy = (long)((y - y0) / cell);
            placed = 1;
            /* a disc that overlaps this one has its centre within r + dmax/2
             * <= dmax: in this cell or a neighbour */
            for (long jy = cy - 1; jy <= cy + 1 && placed; jy++) {
                if (jy < 0 || jy >= ny)
                    continue;
                for (long jx = cx - 1; jx <= cx + 1 && placed; jx++) {
                    if (jx < 0 || jx >= nx)
                        continue;
                    for (long o = head[jy * nx + jx]; o >= 0 && placed; o = next[o]) {
                        const double dx = x - d->x[first + o], dy = y - d->y[first + o];
                        const double rs = r + d->r[first + o];
                        placed = dx * dx + dy * dy >= rs * rs;
                    }
                }
            }
        }
        if (!placed) {
            const int ki = bal_scene_key_index(BAL_SEC_GRAINS, "n");
            bal_error(err, BAL_EINVAL,
                      "%s:%d: n: [grains %s]: placed %ld of %ld discs (area fraction %.3g of the "
                      "region), then found no place for one of diameter %g in %ld tries; expected "
                      "a larger region (size), fewer discs (n) or more tries (random sequential "
                      "addition jams near an area fraction of 0.55)",
                      sc->path, g->key_line[ki] > 0 ? g->key_line[ki] : g->line, g->name, q, n,
                      area / (g->size[0] * g->size[1]), dia[q], g->tries);
            gsl_rng_free(rng);
            free(dia);
            free(head);
            free(next);
            return -1;
        }
        const long c = (long)((x - x0) / cell) + nx * (long)((y - y0) / cell);
        next[q] = head[c];
        head[c] = q;
        d->x[k] = x;
        d->y[k] = y;
        d->r[k] = r;
        d->mat[k] = mat;
        area += BAL_PI * r * r;
        k++;
    }
    gsl_rng_free(rng);
    free(dia);
    free(head);
    free(next);
    return k;
}

/* The discs of an [import] from index k on; returns the index after the
 * last. */
static int lay_import(const struct bal_scene *sc, const void *section, int mat,
                      struct bal_specimen *d, int k, struct bal_error *err)
{
    (void)sc;
    (void)err; /* the discs were read with the scene */
    const struct bal_import_def *m = section;
    for (long q = 0; q < m->n; q++, k++) {
        const double *row = m->disc_data + q * BAL_IMPORT_COLUMNS;
        d->x[k] = row[BAL_IMPORT_X];
        d->y[k] = row[BAL_IMPORT_Y];
        d->r[k] = row[BAL_IMPORT_R];
        d->th[k] = row[BAL_IMPORT_THETA] * (BAL_PI / 180);
        if (m->velocities) {
            d->vx[k] = row[BAL_IMPORT_VX];
            d->vy[k] = row[BAL_IMPORT_VY];
            d->w[k] = row[BAL_IMPORT_OMEGA];
        }
        d->fixed[k] = row[BAL_IMPORT_FIXED] != 0;
        if (d->fixed[k]) /* held: at rest, as a [disc] with fixed = 1 must be */
            d->vx[k] = d->vy[k] = d->w[k] = 0;
        d->mat[k] = mat;
    }
    return k;
}

/* ------------------------------------------------------------------ */
/* The generators                                                      */
/* ------------------------------------------------------------------ */

static long fill_count(const void *section)
{
    return ((const struct bal_fill_def *)section)->n;
}

static long pile_count(const void *section)
{
    return bal_specimen_pile_count(section);
}

static long grains_count(const void *section)
{
    return ((const struct bal_grains_def *)section)->n;
}

static long import_count(const void *section)
{
    return ((const struct bal_import_def *)section)->n;
}

/* " (line N of FILE)": the data file's line of disc k of an [import]. */
static void import_detail(const void *section, long k, char *buf, size_t size)
{
    const struct bal_import_def *m = section;
    snprintf(buf, size, " (line %d of %s)", m->disc_row[k], m->discs);
}

/* One generator kind: everything the walk from scene order back to the
 * scene, the count and the layout need, so that none of them names a kind.
 * Its sections are items of the scene's section arrays (bal_scene_section),
 * which start with their name and header line and end with BAL_SECTION_TAIL. */
struct generator {
    enum bal_section_kind kind;
    /* discs one section makes */
    long (*count)(const void *section);
    /* lay the section's discs from index k on with material index mat; the
     * index after the last, or -1 with err filled */
    int (*lay)(const struct bal_scene *sc, const void *section, int mat, struct bal_specimen *d,
               int k, struct bal_error *err);
    /* the key a message names for each enum bal_disc_prop of a disc it made
     * (place, size, speed, spin), and the key that sets the count */
    const char *prop_key[4];
    const char *count_key;
    size_t material;          /* offsetof the material's name in the section struct */
    const char *rng;          /* the random numbers it draws (docs only) */
    /* appended to a disc's origin, or NULL */
    void (*origin_detail)(const void *section, long k, char *buf, size_t size);
};

/* The generators in scene order: after the [disc] sections (one disc each,
 * not a generator), each row's sections in file order.  A new generator is
 * its section in the key table (scene_keys.c) and its struct (ballast.h),
 * one row here and its lay function.
 *
 * Two random-number generators, kept because the outputs must stay byte for
 * byte: [fill] has drawn from SplitMix64 since it was written, [pile]'s
 * size_spread and [grains] from GSL's mt19937.  Either stream is part of
 * the catalogue's outputs (the dense benchmark is a [fill]; the polydisperse
 * piles and the biaxial specimens are the others), so moving a generator to
 * the other family would change every disc it lays.  Both are seeded by the
 * section alone and give the same numbers on every machine. */
static const struct generator generators[] = {
    {BAL_SEC_FILL, fill_count, lay_fill, {"origin", "rmin", "vmax", "vmax"}, "n",
     offsetof(struct bal_fill_def, material), "SplitMix64 (seed)", NULL},
    {BAL_SEC_PILE, pile_count, lay_pile, {"origin", "d", "d", "d"}, "L",
     offsetof(struct bal_pile_def, material), "gsl_rng_mt19937 (seed), with size_spread > 0",
     NULL},
    {BAL_SEC_GRAINS, grains_count, lay_grains, {"origin", "dmin", "n", "n"}, "n",
     offsetof(struct bal_grains_def, material), "gsl_rng_mt19937 (seed)", NULL},
    {BAL_SEC_IMPORT, import_count, lay_import, {"discs", "discs", "discs", "discs"}, "discs",
     offsetof(struct bal_import_def, material), "none (the file's discs)", import_detail},
};

#define N_GENERATORS ((int)(sizeof generators / sizeof generators[0]))

/* Where a disc of scene order id comes from: section `section` of
 * generators[gen], its disc k; or gen = -1 for the [disc] section `section`
 * (k = 0), or section = -1 past the last disc. */
struct disc_place {
    int gen;
    int section;
    long k;
};

static struct disc_place locate(const struct bal_scene *sc, long id)
{
    if (id < sc->n_discs)
        return (struct disc_place){-1, (int)id, 0};
    long k = id - sc->n_discs;
    for (int g = 0; g < N_GENERATORS; g++) {
        const int n_sec = bal_scene_count(sc, generators[g].kind);
        for (int q = 0; q < n_sec; q++) {
            const long n = generators[g].count(bal_scene_section(sc, generators[g].kind, q));
            if (k < n)
                return (struct disc_place){g, q, k};
            k -= n;
        }
    }
    return (struct disc_place){-1, -1, 0};
}

/* The line of key `key` of a section, or its header line when the key was
 * left at its default (or given by --set). */
static int key_line_of(void *item, enum bal_section_kind kind, const char *key)
{
    const int ki = bal_scene_key_index(kind, key);
    const int line = ki >= 0 ? bal_scene_item_key_line(item, kind)[ki] : 0;
    return line > 0 ? line : *bal_scene_item_line(item);
}

long bal_specimen_count(const struct bal_scene *sc)
{
    long n = sc->n_discs;
    for (int g = 0; g < N_GENERATORS; g++)
        for (int q = 0; q < bal_scene_count(sc, generators[g].kind); q++)
            n += generators[g].count(bal_scene_section(sc, generators[g].kind, q));
    return n;
}

void bal_specimen_count_origin(const struct bal_scene *sc, long limit, char *buf, size_t size)
{
    snprintf(buf, size, "%s", sc->path);
    if (limit < sc->n_discs)
        return;
    const struct disc_place at = locate(sc, limit);
    if (at.gen < 0)
        return;
    const struct generator *gen = &generators[at.gen];
    void *item = bal_scene_section(sc, gen->kind, at.section);
    snprintf(buf, size, "%s:%d: %s: [%s %s]", sc->path, key_line_of(item, gen->kind, gen->count_key),
             gen->count_key, bal_scene_sections[gen->kind].name, bal_scene_item_name(item));
}

static double *alloc_doubles(size_t n, int *ok)
{
    double *p = calloc(n ? n : 1, sizeof *p);
    if (!p)
        *ok = 0;
    return p;
}

enum bal_status bal_specimen_generate(const struct bal_scene *sc, int n, struct bal_specimen *d,
                                      struct bal_error *err)
{
    int ok = 1;
    d->x = alloc_doubles((size_t)n, &ok);
    d->y = alloc_doubles((size_t)n, &ok);
    d->r = alloc_doubles((size_t)n, &ok);
    d->vx = alloc_doubles((size_t)n, &ok);
    d->vy = alloc_doubles((size_t)n, &ok);
    d->th = alloc_doubles((size_t)n, &ok);
    d->w = alloc_doubles((size_t)n, &ok);
    d->mat = calloc((size_t)(n ? n : 1), sizeof *d->mat);
    d->fixed = calloc((size_t)(n ? n : 1), sizeof *d->fixed);
    d->hold = calloc((size_t)(n ? n : 1), sizeof *d->hold);
    d->row = malloc((size_t)(n ? n : 1) * sizeof *d->row);
    if (!ok || !d->mat || !d->fixed || !d->hold || !d->row)
        return bal_error(err, BAL_ENOMEM, "%s: out of memory for %d discs", sc->path, n);
    for (int i = 0; i < n; i++)
        d->row[i] = -1;
    int k = lay_discs(sc, d, 0);
    for (int g = 0; g < N_GENERATORS; g++) {
        const struct generator *gen = &generators[g];
        for (int q = 0; q < bal_scene_count(sc, gen->kind); q++) {
            const void *item = bal_scene_section(sc, gen->kind, q);
            const int mat = bal_scene_find(sc, BAL_SEC_MATERIAL, (const char *)item + gen->material);
            k = gen->lay(sc, item, mat, d, k, err);
            if (k < 0)
                return err->code;
        }
    }
    return BAL_OK;
}

void bal_specimen_free(struct bal_specimen *d)
{
    free(d->x);
    free(d->y);
    free(d->r);
    free(d->vx);
    free(d->vy);
    free(d->th);
    free(d->w);
    free(d->mat);
    free(d->fixed);
    free(d->hold);
    free(d->row);
}

/* ------------------------------------------------------------------ */
/* Scene order back to the scene: names and origins                    */
/* ------------------------------------------------------------------ */

void bal_specimen_disc_name(const struct bal_scene *sc, int id, char *buf, size_t size)
{
    const struct disc_place at = locate(sc, id);
    if (at.section < 0)
        snprintf(buf, size, "?%d", id);
    else if (at.gen < 0)
        snprintf(buf, size, "%s", sc->discs[at.section].name);
    else
        snprintf(buf, size, "%s.%ld",
                 bal_scene_item_name(bal_scene_section(sc, generators[at.gen].kind, at.section)),
                 at.k);
}

const char *bal_specimen_disc_source(const struct bal_scene *sc, int id, long *index)
{
    const struct disc_place at = locate(sc, id);
    *index = at.section < 0 ? -1 : at.k;
    if (at.section < 0)
        return "?";
    if (at.gen < 0)
        return sc->discs[at.section].name;
    return bal_scene_item_name(bal_scene_section(sc, generators[at.gen].kind, at.section));
}

long bal_specimen_find_disc(const struct bal_scene *sc, const char *name, char *why, size_t size)
{
    const char *dot = strrchr(name, '.');
    if (!dot) {
        const int i = bal_scene_find(sc, BAL_SEC_DISC, name);
        if (i < 0)
            snprintf(why, size, "no disc or wall named '%s'", name);
        return i;
    }
    /* NAME.k: the generators in scene order, counting the discs before */
    char gen[BAL_NAME_MAX];
    const size_t len = (size_t)(dot - name);
    snprintf(gen, sizeof gen, "%.*s", (int)(len < sizeof gen ? len : sizeof gen - 1), name);
    char *end;
    const long k = strtol(dot + 1, &end, 10);
    long first = sc->n_discs, found = -1, count = 0;
    const char *kind = NULL, *also = NULL;
    for (int g = 0; g < N_GENERATORS; g++) {
        const enum bal_section_kind sec = generators[g].kind;
        for (int q = 0; q < bal_scene_count(sc, sec); q++) {
            void *item = bal_scene_section(sc, sec, q);
            const char *nm = bal_scene_item_name(item);
            const long n = generators[g].count(item);
            if (strlen(nm) == len && strncmp(nm, name, len) == 0) {
                if (kind)
                    also = bal_scene_sections[sec].name;
                else {
                    kind = bal_scene_sections[sec].name;
                    found = first;
                    count = n;
                }
            }
            first += n;
        }
    }
    if (!kind) {
        /* "[fill], [pile], [grains] or [import]": the table's kinds */
        char kinds[256] = "";
        size_t used = 0;
        for (int g = 0; g < N_GENERATORS && used < sizeof kinds; g++)
            used += (size_t)snprintf(kinds + used, sizeof kinds - used, "%s[%s]",
                                     g == 0 ? "" : g == N_GENERATORS - 1 ? " or " : ", ",
                                     bal_scene_sections[generators[g].kind].name);
        snprintf(why, size, "no disc or wall named '%s' (NAME.k names the k-th disc of the "
                 "generator NAME: no %s is named '%s')", name, kinds, gen);
        return -1;
    }
    if (also) {
        snprintf(why, size, "'%s' could be a disc of [%s %s] or of [%s %s]; expected "
                 "generators of different names", name, kind, gen, also, gen);
        return -1;
    }
    if (*end || k < 0 || k >= count) {
        snprintf(why, size, "no disc named '%s': [%s %s] makes %ld discs, %s.0 to %s.%ld",
                 name, kind, gen, count, gen, gen, count - 1);
        return -1;
    }
    return found + k;
}

void bal_specimen_disc_origin(const struct bal_scene *sc, int id, enum bal_disc_prop prop,
                              char *buf, size_t size)
{
    /* The key of each property in a [disc] section (the generators': their rows). */
    static const char *const disc_keys[] = {
        [BAL_DISC_PLACE] = "x", [BAL_DISC_SIZE] = "r", [BAL_DISC_SPEED] = "v",
        [BAL_DISC_SPIN] = "omega",
    };
    const struct disc_place at = locate(sc, id);
    if (at.section < 0) {
        snprintf(buf, size, "%s: disc %d", sc->path, id);
        return;
    }
    if (at.gen < 0) {
        struct bal_disc_def *d = &sc->discs[at.section];
        const char *key = disc_keys[prop];
        snprintf(buf, size, "%s:%d: %s: disc %s", sc->path, key_line_of(d, BAL_SEC_DISC, key),
                 key, d->name);
        return;
    }
    const struct generator *gen = &generators[at.gen];
    void *item = bal_scene_section(sc, gen->kind, at.section);
    const char *key = gen->prop_key[prop];
    const char *nm = bal_scene_item_name(item);
    const int used = snprintf(buf, size, "%s:%d: %s: disc %s.%ld of [%s %s]", sc->path,
                              key_line_of(item, gen->kind, key), key, nm, at.k,
                              bal_scene_sections[gen->kind].name, nm);
    if (gen->origin_detail && used >= 0 && (size_t)used < size)
        gen->origin_detail(item, at.k, buf + used, size - (size_t)used);
}
