/*
 * grading.c — the grading curve of a [grains] section: the diameters it
 * draws, its share finer, and whether its discs can be placed at all.
 *
 * The curve is "percent finer" by area (in 2D, the discs' area stands for
 * the sieve's mass): F(d), the share of the discs' area in discs of
 * diameter <= d, is 0, 0.1, 0.5, 0.6, 1 at dmin, d10, d50, d60, dmax and
 * linear in between.  Diameters are drawn by number: a disc of diameter d
 * has area ∝ d², so the number density is n(d) ∝ F'(d)/d².  On a piece
 * [a, b] of the curve with rise ΔF, F' = ΔF/(b − a) and the piece holds the
 * share ∝ ΔF/(b − a) ∫_a^b d⁻² dd = ΔF/(a b) of the discs (also for a = b:
 * a step of F, ΔF/a² discs of diameter a); within it the number CDF is
 * (1/a − 1/d)/(1/a − 1/b), inverted in closed form:
 *   d = 1 / (1/a − u (1/a − 1/b)),  u uniform in [0, 1).
 * One uniform picks the piece, one the diameter within it.  specimen.c
 * draws the uniforms and places the discs; this file is the curve's
 * maths alone, which the validation (bal_specimen_grains_check) and the
 * tests use without laying a specimen.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "specimen.h"
#include "status.h"

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

