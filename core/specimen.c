/*
 * specimen.c — the discs a scene generates, in scene order.
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
 *   [grains] n discs from a grading curve, placed at random without
 *           overlap in a rectangle (below);
 *   [import] the discs of a discs.tsv a run wrote, unchanged (read when the
 *           scene was parsed: import.c).
 *
 * The grading curve of [grains] is "percent finer" by area (in 2D, the
 * discs' area stands for the sieve's mass): F(d), the share of the discs'
 * area in discs of diameter <= d, is 0, 0.1, 0.5, 0.6, 1 at dmin, d10, d50,
 * d60, dmax and linear in between.  Diameters are drawn by number: a disc
 * of diameter d has area ∝ d², so the number density is n(d) ∝ F'(d)/d².
 * On a piece [a, b] of the curve with rise ΔF, F' = ΔF/(b − a) and the
 * piece holds the share ∝ ΔF/(b − a) ∫_a^b d⁻² dd = ΔF/(a b) of the
 * discs (also for a = b: a step of F, ΔF/a² discs of diameter a); within
 * it the number CDF is (1/a − 1/d)/(1/a − 1/b), inverted in closed form:
 *   d = 1 / (1/a − u (1/a − 1/b)),  u uniform in [0, 1).
 * One uniform picks the piece, one the diameter within it.  The numbers
 * come from GSL's gsl_rng_mt19937 seeded with the section's seed (the same
 * discs on every machine): first two per disc for the diameters, then two
 * per try for the places.  The discs are placed largest first (random
 * sequential addition: each at a uniform random place inside the region,
 * kept if it overlaps no disc placed before, tried up to `tries` times; a
 * cell grid of side dmax finds the neighbours), and numbered in that order.
 * Random sequential addition jams near an area fraction of 0.55 (equal
 * discs), so a dense specimen is placed loose in a tall region and then
 * compressed by its walls (the servo of walls.c).
 *
 * Scene order — [disc] sections first, then each [fill], [pile], [grains]
 * and [import], each kind in file order — is the disc's stable id: outputs
 * are written in it, and messages name a disc by it.  The functions at the
 * end turn an id back into a name (FILL.k) and into the scene line that
 * placed the disc.
 *
 * A new generator is a section in the key table, a count in
 * bal_specimen_count, a lay_* function called from bal_specimen_generate,
 * and its branch in the name and origin functions.
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

long bal_specimen_count(const struct bal_scene *sc)
{
    long n = sc->n_discs;
    for (int f = 0; f < sc->n_fills; f++)
        n += sc->fills[f].n;
    for (int p = 0; p < sc->n_piles; p++)
        n += bal_specimen_pile_count(&sc->piles[p]);
    for (int g = 0; g < sc->n_grains; g++)
        n += sc->grains[g].n;
    for (int i = 0; i < sc->n_imports; i++)
        n += sc->imports[i].n;
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
static int lay_fill(const struct bal_fill_def *fd, int mat, struct bal_specimen *d, int k)
{
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

/* Lay out a pile (struct bal_pile_def documents the rules) into the arrays
 * from index k on; returns the index after the last disc. */
static int lay_pile(const struct bal_pile_def *p, int mat, struct bal_specimen *d, int k)
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
 *                 layout; lay_pile itself still lays size_spread = 0, so the
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

/* The grading curve's points: diameters and shares finer by area. */
static void grading_points(const struct bal_grains_def *g, double d[5], double F[5])
{
    const double dd[5] = {g->dmin, g->d10, g->d50, g->d60, g->dmax};
    const double FF[5] = {0, 0.1, 0.5, 0.6, 1};
    memcpy(d, dd, sizeof dd);
    memcpy(F, FF, sizeof FF);
}

double bal_specimen_grading_diameter(const struct bal_grains_def *g, double u1, double u2)
{
    double d[5], F[5], w[4], total = 0;
    grading_points(g, d, F);
    for (int k = 0; k < 4; k++) {
        w[k] = (F[k + 1] - F[k]) / (d[k] * d[k + 1]); /* its share of the discs, by number */
        total += w[k];
    }
    /* the piece: the first whose cumulative share passes u1 (the last, for
     * a u1 that rounding carries past them all) */
    int k = 0;
    for (double acc = w[0] / total; k < 3 && !(u1 < acc); acc += w[++k] / total)
        ;
    const double a = d[k], b = d[k + 1];
    if (!(b > a))
        return a;
    const double dia = 1 / (1 / a - u2 * (1 / a - 1 / b));
    return dia < a ? a : dia > b ? b : dia; /* rounding at the ends */
}

double bal_specimen_grading_finer(const struct bal_grains_def *g, double dia)
{
    double d[5], F[5];
    grading_points(g, d, F);
    if (dia < d[0])
        return 0;
    for (int k = 0; k < 4; k++)
        if (dia < d[k + 1])
            return F[k] + (F[k + 1] - F[k]) * (dia - d[k]) / (d[k + 1] - d[k]);
    return 1;
}

/* The spacing of doubles at a position of a [grains] region may be at most
 * this share of the smallest radius: an overlap of 1e-3 of the radius (a
 * stiff contact) is then resolved to 1e-3 of itself, and discs placed at
 * random are placed apart.  At origin = 1e300 the spacing is 1.5e284 and
 * every disc landed on the same point. */
#define GRAINS_POSITION_RESOLUTION 1e-6

int bal_specimen_grains_check(const struct bal_grains_def *g, const char **key, char *why,
                              size_t size)
{
    const double r_min = 0.5 * g->dmin;
    for (int a = 0; a < 2; a++) {
        /* The side of the region farther from 0, where the doubles are
         * widest apart. */
        const double end = g->origin[a] + g->size[a];
        const double far = fabs(end) > fabs(g->origin[a]) ? end : g->origin[a];
        const double spacing = nextafter(fabs(far), INFINITY) - fabs(far);
        const double at_origin = nextafter(fabs(g->origin[a]), INFINITY) - fabs(g->origin[a]);
        if (spacing <= GRAINS_POSITION_RESOLUTION * r_min)
            continue;
        /* the origin's doing unless the origin alone is fine */
        *key = at_origin <= GRAINS_POSITION_RESOLUTION * r_min ? "size" : "origin";
        if (!isfinite(end))
            snprintf(why, size, "[grains %s]: the region's far side %s = origin + size is "
                     "beyond the largest double; expected a region nearer 0", g->name,
                     a ? "y" : "x");
        else
            snprintf(why, size, "[grains %s]: the region reaches %s = %s, where doubles are "
                     "%s apart, more than %g of the smallest radius dmin/2 = %s: positions "
                     "there lose their precision (the discs would be placed on top of each "
                     "other); expected a region nearer 0 or larger discs", g->name,
                     a ? "y" : "x", BAL_NUM(far), BAL_NUM(spacing),
                     GRAINS_POSITION_RESOLUTION, BAL_NUM(r_min));
        return 1;
    }
    /* n discs of radius r_i >= r_min inside the region, apart: shrunk to
     * r_min about their centres they still are, with the centres in the
     * (size_x - dmin) x (size_y - dmin) rectangle at distances >= dmin.
     * Oler's inequality (1961) bounds such a set of points: n <= (2/sqrt 3)
     * A/dmin^2 + P/(2 dmin) + 1 (A, P the rectangle's area and perimeter),
     * which is below n_max = 2 size_x size_y / (sqrt 3 dmin^2), the
     * hexagonal packing fraction pi/(2 sqrt 3) of the region's area over
     * the area of a disc of diameter dmin: n <= n_max for any grading (by
     * at least 0.15 of a disc, far above the rounding of n_max up to
     * n = 1e8).  (Random sequential addition jams long before, near 0.55.) */
    const double n_max = 2 * g->size[0] * g->size[1] / (sqrt(3.0) * g->dmin * g->dmin);
    if ((double)g->n > n_max) {
        *key = "n";
        snprintf(why, size, "[grains %s]: %ld discs of diameter >= dmin = %s cannot lie apart "
                 "in the region %s x %s: at most %.0f can (the densest packing, hexagonal, "
                 "covers pi/(2 sqrt 3) of the area: n <= 2 size_x size_y / (sqrt 3 dmin^2)); "
                 "expected fewer discs or a larger region", g->name, g->n, BAL_NUM(g->dmin),
                 BAL_NUM(g->size[0]), BAL_NUM(g->size[1]), floor(n_max));
        return 1;
    }
    return 0;
}

static int descending(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? 1 : x > y ? -1 : 0;
}

/* A [grains] specimen (the file's header) from index k on; returns the index
 * after the last disc, or -1 with err filled. */
static int lay_grains(const struct bal_scene *sc, const struct bal_grains_def *g, int mat,
                      struct bal_specimen *d, int k, struct bal_error *err)
{
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
static int lay_import(const struct bal_import_def *m, int mat, struct bal_specimen *d, int k)
{
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
    for (int f = 0; f < sc->n_fills; f++)
        k = lay_fill(&sc->fills[f], bal_scene_find(sc, BAL_SEC_MATERIAL, sc->fills[f].material),
                     d, k);
    for (int p = 0; p < sc->n_piles; p++) {
        const struct bal_pile_def *pd = &sc->piles[p];
        const int mat = bal_scene_find(sc, BAL_SEC_MATERIAL, pd->material);
        k = pd->size_spread > 0 ? lay_pile_spread(pd, mat, d, k) : lay_pile(pd, mat, d, k);
        if (k < 0)
            return bal_error(err, BAL_ENOMEM, "%s:%d: [pile %s]: out of memory for its layout",
                             sc->path, pd->line, pd->name);
    }
    for (int g = 0; g < sc->n_grains; g++) {
        k = lay_grains(sc, &sc->grains[g],
                       bal_scene_find(sc, BAL_SEC_MATERIAL, sc->grains[g].material), d, k, err);
        if (k < 0)
            return err->code;
    }
    for (int i = 0; i < sc->n_imports; i++)
        k = lay_import(&sc->imports[i],
                       bal_scene_find(sc, BAL_SEC_MATERIAL, sc->imports[i].material), d, k);
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
    if (id < sc->n_discs) {
        snprintf(buf, size, "%s", sc->discs[id].name);
        return;
    }
    long k = id - sc->n_discs;
    for (int f = 0; f < sc->n_fills; f++) {
        if (k < sc->fills[f].n) {
            snprintf(buf, size, "%s.%ld", sc->fills[f].name, k);
            return;
        }
        k -= sc->fills[f].n;
    }
    for (int p = 0; p < sc->n_piles; p++) {
        const long n = bal_specimen_pile_count(&sc->piles[p]);
        if (k < n) {
            snprintf(buf, size, "%s.%ld", sc->piles[p].name, k);
            return;
        }
        k -= n;
    }
    for (int g = 0; g < sc->n_grains; g++) {
        if (k < sc->grains[g].n) {
            snprintf(buf, size, "%s.%ld", sc->grains[g].name, k);
            return;
        }
        k -= sc->grains[g].n;
    }
    for (int i = 0; i < sc->n_imports; i++) {
        if (k < sc->imports[i].n) {
            snprintf(buf, size, "%s.%ld", sc->imports[i].name, k);
            return;
        }
        k -= sc->imports[i].n;
    }
    snprintf(buf, size, "?%d", id);
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
    for (int pass = 0; pass < 4; pass++) {
        const int n_sec = pass == 0 ? sc->n_fills : pass == 1 ? sc->n_piles
                        : pass == 2 ? sc->n_grains : sc->n_imports;
        for (int q = 0; q < n_sec; q++) {
            const char *nm = pass == 0 ? sc->fills[q].name : pass == 1 ? sc->piles[q].name
                           : pass == 2 ? sc->grains[q].name : sc->imports[q].name;
            const long n = pass == 0 ? sc->fills[q].n : pass == 1 ? bal_specimen_pile_count(&sc->piles[q])
                         : pass == 2 ? sc->grains[q].n : sc->imports[q].n;
            const char *kd = pass == 0 ? "fill" : pass == 1 ? "pile" : pass == 2 ? "grains" : "import";
            if (strlen(nm) == len && strncmp(nm, name, len) == 0) {
                if (kind)
                    also = kd;
                else {
                    kind = kd;
                    found = first;
                    count = n;
                }
            }
            first += n;
        }
    }
    if (!kind) {
        snprintf(why, size, "no disc or wall named '%s' (NAME.k names the k-th disc of the "
                 "generator NAME: no [fill], [pile], [grains] or [import] is named '%s')", name,
                 gen);
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
    /* The key of each property in a [disc], a [fill] and a [pile] section. */
    static const char *const keys[][3] = {
        [BAL_DISC_PLACE] = {"x", "origin", "origin"},
        [BAL_DISC_SIZE] = {"r", "rmin", "d"},
        [BAL_DISC_SPEED] = {"v", "vmax", "d"},
        [BAL_DISC_SPIN] = {"omega", "vmax", "d"},
    };
    if (id < sc->n_discs) {
        const struct bal_disc_def *d = &sc->discs[id];
        const char *key = keys[prop][0];
        const int ki = bal_scene_key_index(BAL_SEC_DISC, key);
        const int line = ki >= 0 && d->key_line[ki] > 0 ? d->key_line[ki] : d->line;
        snprintf(buf, size, "%s:%d: %s: disc %s", sc->path, line, key, d->name);
        return;
    }
    long k = id - sc->n_discs;
    for (int f = 0; f < sc->n_fills; f++, k -= sc->fills[f - 1].n) {
        const struct bal_fill_def *fd = &sc->fills[f];
        if (k >= fd->n)
            continue;
        const char *key = keys[prop][1];
        const int ki = bal_scene_key_index(BAL_SEC_FILL, key);
        const int line = ki >= 0 && fd->key_line[ki] > 0 ? fd->key_line[ki] : fd->line;
        snprintf(buf, size, "%s:%d: %s: disc %s.%ld of [fill %s]", sc->path, line, key, fd->name,
                 k, fd->name);
        return;
    }
    for (int p = 0; p < sc->n_piles; p++) {
        const struct bal_pile_def *pd = &sc->piles[p];
        const long n = bal_specimen_pile_count(pd);
        if (k >= n) {
            k -= n;
            continue;
        }
        const char *key = keys[prop][2];
        const int ki = bal_scene_key_index(BAL_SEC_PILE, key);
        const int line = ki >= 0 && pd->key_line[ki] > 0 ? pd->key_line[ki] : pd->line;
        snprintf(buf, size, "%s:%d: %s: disc %s.%ld of [pile %s]", sc->path, line, key, pd->name,
                 k, pd->name);
        return;
    }
    for (int g = 0; g < sc->n_grains; g++) {
        const struct bal_grains_def *gd = &sc->grains[g];
        if (k >= gd->n) {
            k -= gd->n;
            continue;
        }
        const char *key = prop == BAL_DISC_SIZE ? "dmin" : prop == BAL_DISC_PLACE ? "origin" : "n";
        const int ki = bal_scene_key_index(BAL_SEC_GRAINS, key);
        const int line = ki >= 0 && gd->key_line[ki] > 0 ? gd->key_line[ki] : gd->line;
        snprintf(buf, size, "%s:%d: %s: disc %s.%ld of [grains %s]", sc->path, line, key, gd->name,
                 k, gd->name);
        return;
    }
    for (int i = 0; i < sc->n_imports; i++) {
        const struct bal_import_def *m = &sc->imports[i];
        if (k >= m->n) {
            k -= m->n;
            continue;
        }
        /* the scene's line of the file, and the file's line of the disc */
        const int ki = bal_scene_key_index(BAL_SEC_IMPORT, "discs");
        const int line = ki >= 0 && m->key_line[ki] > 0 ? m->key_line[ki] : m->line;
        snprintf(buf, size, "%s:%d: discs: disc %s.%ld of [import %s] (line %d of %s)", sc->path,
                 line, m->name, k, m->name, m->disc_row[k], m->discs);
        return;
    }
    snprintf(buf, size, "%s: disc %d", sc->path, id);
}
