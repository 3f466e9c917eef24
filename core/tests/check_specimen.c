/*
 * check_specimen.c — suite "specimen": the generators of specimen.c — the
 * [grains] generator (its grading curve by area, grading.c, its random
 * sequential addition, its seed), [import], a prepared state read back from
 * the files a run wrote, and the [pile] generator (its counts, its lattices,
 * the polydisperse pile); the [pile] section's bad input is in
 * check_scene.c's tables.
 *
 * The grading curve (grading.c): F(d), the share of the discs' area in
 * discs of diameter <= d, is 0, 0.1, 0.5, 0.6, 1 at dmin, d10, d50, d60,
 * dmax, linear in between; the generator draws diameters by number with
 * the density n(d) ∝ F'(d)/d².  A sample of N diameters estimates F at d_q
 * by the area-weighted share
 *   F̂(d_q) = Σ d_i² [d_i <= d_q] / Σ d_i²,
 * a ratio of two means, whose standard deviation is, to first order (the
 * delta method), σ = sqrt(E[(X − F Y)²] / N) / E[Y] with X = d² [d <= d_q],
 * Y = d², estimated from the sample itself.  The tests hold F̂ to 5σ of
 * 0.1, 0.5 and 0.6 (a false alarm once in 1.7 million), which a generator
 * that drew by area instead (n ∝ F') misses by tens of σ.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <gsl/gsl_rng.h>

#include "check_main.h"

/* A wide grading (dmax/dmin = 7), so that drawing by area or by number
 * differ by far more than the sampling error. */
static struct bal_grains_def wide_grading(void)
{
    struct bal_grains_def g;
    memset(&g, 0, sizeof g);
    g.dmin = 1.0;
    g.d10 = 1.5;
    g.d50 = 3.0;
    g.d60 = 3.6;
    g.dmax = 7.0;
    return g;
}

/* The area-weighted share of a sample below dq, and its delta-method σ. */
static void finer_by_area(const double *d, long n, double dq, double *share, double *sigma)
{
    double sx = 0, sy = 0;
    for (long i = 0; i < n; i++) {
        const double y = d[i] * d[i];
        sy += y;
        sx += d[i] <= dq ? y : 0;
    }
    const double F = sx / sy, ey = sy / (double)n;
    double v = 0;
    for (long i = 0; i < n; i++) {
        const double y = d[i] * d[i], x = d[i] <= dq ? y : 0;
        v += (x - F * y) * (x - F * y);
    }
    *share = F;
    *sigma = sqrt(v / (double)n / (double)n) / ey;
}

/* 40 000 diameters drawn as the generator draws them (two uniforms of
 * gsl_rng_mt19937 each): within [dmin, dmax], and their area-weighted
 * shares below d10, d50, d60 within 5σ of 0.1, 0.5, 0.6.  The curve itself
 * (bal_specimen_grading_finer) passes through its points. */
START_TEST(specimen_grading_by_area)
{
    const struct bal_grains_def g = wide_grading();
    const long n = 40000;
    double *d = malloc((size_t)n * sizeof *d);
    ck_assert_ptr_nonnull(d);
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 20211);
    double lo = INFINITY, hi = 0;
    for (long i = 0; i < n; i++) {
        const double u1 = gsl_rng_uniform(rng), u2 = gsl_rng_uniform(rng);
        d[i] = bal_specimen_grading_diameter(&g, u1, u2);
        lo = fmin(lo, d[i]);
        hi = fmax(hi, d[i]);
    }
    gsl_rng_free(rng);
    ck_assert(lo >= g.dmin && hi <= g.dmax);
    /* by number most discs are small: the smallest drawn is near dmin, and
     * some reach within 5 % of dmax (the last piece holds 2.6 % of the
     * discs by number) */
    ck_assert(lo < 1.01 * g.dmin);
    ck_assert(hi > 0.95 * g.dmax);
    const double q[3] = {0.1, 0.5, 0.6}, dq[3] = {g.d10, g.d50, g.d60};
    for (int k = 0; k < 3; k++) {
        double F, sigma;
        finer_by_area(d, n, dq[k], &F, &sigma);
        ck_assert_msg(fabs(F - q[k]) < 5 * sigma, "finer than %g by area: %g, expected %g +- 5 x %g",
                      dq[k], F, q[k], sigma);
        ck_assert(sigma < 0.01); /* the test has the power to see a wrong curve */
        ck_assert_double_eq_tol(bal_specimen_grading_finer(&g, dq[k]), q[k], 1e-15);
    }
    ck_assert_double_eq(bal_specimen_grading_finer(&g, g.dmin), 0.0);
    ck_assert_double_eq(bal_specimen_grading_finer(&g, g.dmax), 1.0);
    free(d);
}
END_TEST

/* The inverse in closed form: on a piece [a, b] the number CDF is
 * (1/a − 1/d)/(1/a − 1/b), so u2 = 0, 1/2, 1 give a, the harmonic mean
 * 2ab/(a + b), b; u1 picks the piece by its number share ΔF/(a b) (here
 * the first piece holds 0.1/1.5 over Σ ΔF/(a b) of the discs).  Equal
 * diameters (a step of the curve) give that diameter; dmin = dmax gives
 * one size. */
START_TEST(specimen_grading_inverse)
{
    struct bal_grains_def g = wide_grading();
    const double w[4] = {0.1 / (1.0 * 1.5), 0.4 / (1.5 * 3.0), 0.1 / (3.0 * 3.6), 0.4 / (3.6 * 7.0)};
    const double total = w[0] + w[1] + w[2] + w[3];
    const double first = w[0] / total, second = (w[0] + w[1]) / total;
    ck_assert_double_eq_tol(bal_specimen_grading_diameter(&g, 0.5 * first, 0), 1.0, 1e-15);
    ck_assert_double_eq_tol(bal_specimen_grading_diameter(&g, 0.5 * first, 0.5), 2 * 1.5 / 2.5,
                            1e-15);
    ck_assert_double_eq_tol(bal_specimen_grading_diameter(&g, 0.5 * (first + second), 0.5),
                            2 * 1.5 * 3.0 / 4.5, 1e-15);
    ck_assert_double_eq_tol(bal_specimen_grading_diameter(&g, 0.999999, 0.5), 2 * 3.6 * 7 / 10.6,
                            1e-15);
    ck_assert_double_eq_tol(bal_specimen_grading_diameter(&g, 0.999999, 1 - 1e-16), 7.0, 1e-14);
    g.d50 = g.d60 = 3.3; /* a step of 0.1 at 3.3 */
    const double w2[4] = {0.1 / 1.5, 0.4 / (1.5 * 3.3), 0.1 / (3.3 * 3.3), 0.4 / (3.3 * 7.0)};
    const double t2 = w2[0] + w2[1] + w2[2] + w2[3];
    const double in_step = (w2[0] + w2[1] + 0.5 * w2[2]) / t2;
    ck_assert_double_eq(bal_specimen_grading_diameter(&g, in_step, 0.77), 3.3);
    g.dmin = g.d10 = g.d50 = g.d60 = g.dmax = 2.5;
    for (double u = 0.05; u < 1; u += 0.1)
        ck_assert_double_eq(bal_specimen_grading_diameter(&g, u, 1 - u), 2.5);
}
END_TEST

/* A [grains] scene: the JYH grading (dmin 6, d10 6.4, d50 7.6, d60 8.32,
 * dmax 9: C_u = 1.3), 300 discs at an area fraction of about 0.4 (0.0136
 * of 0.034), in a box. */
static struct tfx *grains_scene(unsigned long seed, const char *more)
{
    return tfx_newf("grains",
                    "[material g]\nkn = 2e8\ndensity = 2650\n[material w]\nkn = 2e8\n"
                    "[grains spec]\nn = 300\norigin = 0.013 -0.027\nsize = 0.17 0.2\n"
                    "dmin = 0.006\nd10 = 0.0064\nd50 = 0.0076\nd60 = 0.00832\ndmax = 0.009\n"
                    "seed = %lu\nbox = 1\nwall_material = w\nmaterial = g\n%s"
                    "[stage s]\ncycles = 1\n",
                    seed, more);
}

/* Every disc lies inside the region and overlaps none (the random
 * sequential addition's rule, checked over all pairs); diameters within
 * [dmin, dmax], placed largest first; the box's walls are the region's
 * sides reaching dmax (the default overhang) beyond the corners. */
START_TEST(specimen_grains_placed)
{
    struct tfx *f = grains_scene(7, "");
    const struct bal_sim *s = f->sim;
    ck_assert_int_eq(s->n, 300);
    double prev = INFINITY;
    for (int k = 0; k < s->n; k++) {
        const int i = s->slot[k];
        const double r = s->r[i];
        ck_assert(2 * r >= 0.006 && 2 * r <= 0.009);
        ck_assert(r <= prev); /* scene order is placement order: largest first */
        prev = r;
        ck_assert(s->x[i] - r >= 0.013 && s->x[i] + r <= 0.013 + 0.17);
        ck_assert(s->y[i] - r >= -0.027 && s->y[i] + r <= -0.027 + 0.2);
        ck_assert_double_eq(s->vx[i], 0.0);
        for (int l = 0; l < k; l++) {
            const int j = s->slot[l];
            const double dx = s->x[i] - s->x[j], dy = s->y[i] - s->y[j];
            ck_assert(dx * dx + dy * dy >= (r + s->r[j]) * (r + s->r[j]));
        }
    }
    ck_assert_int_eq(s->n_walls, 4);
    static const char *const names[4] = {"spec_bottom", "spec_right", "spec_top", "spec_left"};
    for (int w = 0; w < 4; w++)
        ck_assert_str_eq(s->walls[w].name, names[w]);
    const struct bal_wall *bottom = &s->walls[0], *left = &s->walls[3];
    ck_assert_double_eq_tol(bottom->p[0] + bottom->h1 * bottom->e[0], 0.013 - 0.009, 1e-17);
    ck_assert_double_eq_tol(bottom->p[0] + bottom->h2 * bottom->e[0], 0.013 + 0.17 + 0.009, 1e-16);
    ck_assert_double_eq(bottom->p[1], -0.027);
    ck_assert_double_eq(left->p[0], 0.013);
    ck_assert_double_eq_tol(left->p[1] + left->h2 * left->e[1], -0.027 + 0.2 + 0.009, 1e-16);
    struct tfx *g = grains_scene(7, "overhang = 0\n");
    ck_assert_double_eq(g->sim->walls[0].h1, 0.0);
}
END_TEST

/* The seed: the same seed gives the same discs, bit for bit (GSL's
 * mt19937 is the same generator on every machine); another seed others. */
START_TEST(specimen_grains_seed)
{
    struct tfx *a = grains_scene(11, ""), *b = grains_scene(11, ""), *c = grains_scene(12, "");
    int differ = 0;
    for (int k = 0; k < 300; k++) {
        const int ia = a->sim->slot[k], ib = b->sim->slot[k], ic = c->sim->slot[k];
        ck_assert(a->sim->x[ia] == b->sim->x[ib] && a->sim->y[ia] == b->sim->y[ib] &&
                  a->sim->r[ia] == b->sim->r[ib]);
        differ += a->sim->x[ia] != c->sim->x[ic] || a->sim->r[ia] != c->sim->r[ic];
    }
    ck_assert_int_gt(differ, 290);
}
END_TEST

/* ------------------------------------------------------------------ */
/* [import]                                                            */
/* ------------------------------------------------------------------ */

/* A scratch directory under /tmp for the files of one test. */
static void scratch_dir(char *dir, size_t size)
{
    snprintf(dir, size, "/tmp/ballast_check_XXXXXX");
    ck_assert_ptr_nonnull(mkdtemp(dir));
}

static void remove_dir(const char *dir)
{
    static const char *const files[] = {"discs.tsv", "walls.tsv", "contacts.tsv", "import.scene"};
    char path[512];
    for (size_t k = 0; k < sizeof files / sizeof files[0]; k++) {
        snprintf(path, sizeof path, "%s/%s", dir, files[k]);
        unlink(path);
    }
    rmdir(dir);
}

/* The round trip: a run (the grains specimen, given rotations and
 * velocities and run for 30 cycles, so that they are arbitrary doubles)
 * writes discs.tsv and walls.tsv; a scene in the same directory imports
 * them by relative paths.  The imported discs are the run's, in the same
 * order: x, y, r bitwise (written with %.17g); θ, written in degrees, to
 * 4 ulps of the radians; with velocities = 1 the written velocities
 * (v_N) bitwise.  The walls come back with their names and their end
 * points (A = P, B = P + |B − A| e: 1e-16 of the box). */
START_TEST(specimen_import_round_trip)
{
    struct tfx *f = grains_scene(3, "");
    struct bal_sim *s = f->sim;
    /* arbitrary doubles: rotations, spins and velocities set by hand, then
     * 30 cycles (the discs move and turn; none touches another) */
    for (int i = 0; i < s->n; i++) {
        s->th[i] = 0.37 * i + 1.0 / 3;
        s->w[i] = 0.01 * (i % 7) - 0.029;
        s->vx[i] = 1e-3 * sin(i);
        s->vy[i] = 1e-3 * cos(3.0 * i);
    }
    t_steps(f, 30);
    char dir[64];
    scratch_dir(dir, sizeof dir);
    ck_assert_int_eq(bal_output_state(s, dir, &f->err), BAL_OK);

    char text[1024], name[128];
    snprintf(text, sizeof text,
             "[material g]\nkn = 2e8\ndensity = 2650\n[material w]\nkn = 2e8\n"
             "[import prep]\ndiscs = discs.tsv\nwalls = walls.tsv\nmaterial = g\n"
             "wall_material = w\nvelocities = 1\n[stage s]\ncycles = 1\n");
    snprintf(name, sizeof name, "%s/import.scene", dir);
    struct tfx *g = tfx_new(text, name);
    const struct bal_sim *t = g->sim;
    ck_assert_int_eq(t->n, s->n);
    char nm[2 * BAL_NAME_MAX];
    bal_specimen_disc_name(&g->sc, 17, nm, sizeof nm);
    ck_assert_str_eq(nm, "prep.17");
    for (int k = 0; k < s->n; k++) {
        const int i = s->slot[k], j = t->slot[k];
        ck_assert_msg(t->x[j] == s->x[i] && t->y[j] == s->y[i] && t->r[j] == s->r[i],
                      "disc %d: (%.17g, %.17g, %.17g) read back as (%.17g, %.17g, %.17g)", k,
                      s->x[i], s->y[i], s->r[i], t->x[j], t->y[j], t->r[j]);
        ck_assert_double_eq_tol(t->th[j], s->th[i], 4 * 2.3e-16 * fmax(1, fabs(s->th[i])));
        double vx, vy, w;
        bal_measure_velocity(s, i, &vx, &vy, &w);
        /* the imported discs start with v_N as the centred scheme's v_{1/2} */
        ck_assert(t->vx[j] == vx && t->vy[j] == vy && t->w[j] == w);
    }
    ck_assert(s->th[s->slot[5]] != 0); /* the shaking turned the discs */
    ck_assert_int_eq(t->n_walls, 4);
    for (int w = 0; w < 4; w++) {
        const struct bal_wall *a = &s->walls[w], *b = &t->walls[w];
        ck_assert_str_eq(b->name, a->name);
        for (int e = 0; e < 2; e++) {
            const double ha = a->p[e] + a->h1 * a->e[e], hb = a->p[e] + a->h2 * a->e[e];
            ck_assert_double_eq_tol(b->p[e] + b->h1 * b->e[e], ha, 1e-16);
            ck_assert_double_eq_tol(b->p[e] + b->h2 * b->e[e], hb, 2e-16);
        }
    }
    /* velocities = 0: at rest */
    snprintf(text, sizeof text,
             "[material g]\nkn = 2e8\ndensity = 2650\n[import prep]\ndiscs = %s/discs.tsv\n"
             "material = g\n[stage s]\ncycles = 1\n", dir);
    struct tfx *h = tfx_new(text, "absolute");
    for (int k = 0; k < h->sim->n; k++)
        ck_assert(h->sim->vx[k] == 0 && h->sim->vy[k] == 0 && h->sim->w[k] == 0);
    ck_assert_int_eq(h->sim->n_walls, 0);
    remove_dir(dir);
}
END_TEST

/* A failed --set of a data file leaves the section as it was (its path and
 * its data); a good one replaces both. */
START_TEST(specimen_import_set)
{
    struct tfx *f = tfx_parse("[material m]\nkn = 1e5\ndensity = 2\n[import p]\n"
                              "discs = scenes/import/discs.tsv\nmaterial = m\n[stage s]\ncycles = 1\n",
                              "import");
    struct bal_import_def *m = &f->sc.imports[0];
    ck_assert_int_eq(m->n, 2);
    const double *data = m->disc_data;
    ck_assert_double_eq(data[BAL_IMPORT_X], 0.5);
    ck_assert_double_eq(data[BAL_IMPORT_THETA], 12.5);
    ck_assert_double_eq(data[BAL_IMPORT_VY], -0.2);
    ck_assert_int_eq(m->disc_row[1], 3);
    ck_assert_int_eq(bal_scene_set(&f->sc, "import.p.discs=scenes/import/bad_row.tsv", &f->err),
                     BAL_EINVAL);
    ck_assert_msg(t_contains(f->err.msg, "import: --set discs: scenes/import/bad_row.tsv:3: y:"),
                  "%s", f->err.msg);
    ck_assert_str_eq(m->discs, "scenes/import/discs.tsv");
    ck_assert_ptr_eq(m->disc_data, data);
    ck_assert_int_eq(m->n, 2);
    ck_assert_int_eq(bal_scene_set(&f->sc, "import.p.discs=scenes/import/no_velocities.tsv",
                                   &f->err), BAL_OK);
    ck_assert_int_eq(m->n, 1);
    ck_assert_int_eq(m->velocity_columns, 0);
    ck_assert_str_eq(m->discs, "scenes/import/no_velocities.tsv");
}
END_TEST

/* Issue 29, item 10: a UTF-8 byte-order mark before the header (a file
 * saved by a spreadsheet or an editor) is no part of the first column's
 * name: "no column 'x' in the header" was the message for a header that
 * visibly had x.  The files read as the same files without it. */
START_TEST(specimen_import_byte_order_mark)
{
    struct tfx *f = tfx_parse("[material m]\nkn = 1e5\ndensity = 2\n[import p]\n"
                              "discs = scenes/import/bom_discs.tsv\n"
                              "walls = scenes/import/bom_walls.tsv\nmaterial = m\n"
                              "wall_material = m\n[stage s]\ncycles = 1\n", "bom");
    const struct bal_import_def *m = &f->sc.imports[0];
    ck_assert_int_eq(m->n, 2);
    ck_assert_double_eq(m->disc_data[BAL_IMPORT_X], 0.5);
    ck_assert_double_eq(m->disc_data[BAL_IMPORT_COLUMNS + BAL_IMPORT_X], 1.5);
    ck_assert_double_eq(m->disc_data[BAL_IMPORT_COLUMNS + BAL_IMPORT_R], 0.3);
    ck_assert_int_eq(m->n_walls, 1);
    ck_assert_str_eq(m->wall_data[0].name, "floor");
    ck_assert_double_eq(m->wall_data[0].b[0], 3);
}
END_TEST

/* Item 11: discs piled at one point, more than the neighbour lists hold
 * for one disc (BAL_MAX_NEIGHBOURS), from every generator that can pile
 * them (the [import] is in check_scene.c's table; [pile] and [grains] lay
 * discs apart by construction): the start overlap is bad input, named at
 * the line that placed the disc, as any start overlap is; with overlaps
 * allowed, the crowd itself is, at that line too.  It was "more than 512
 * neighbours within reach at step 0" with no line, and BAL_EUNSTABLE. */
START_TEST(specimen_crowded_start_is_bad_input)
{
    enum { N = 600 }; /* more than the 512 candidates the lists hold for one disc (grid.h) */
    const size_t size = 64 + (size_t)N * 96;
    char *text = malloc(size);
    ck_assert_ptr_nonnull(text);
    for (int kind = 0; kind < 3; kind++) {
        /* 0: [disc] sections, 1: one-disc [fill]s, 2: [disc]s with overlaps allowed */
        int n = snprintf(text, size, "%s[material m]\nkn = 1e5\ndensity = 2\n",
                         kind == 2 ? "[settings]\nallow_overlap = 1\n" : "");
        for (int k = 0; k < N; k++)
            n += snprintf(text + n, size - (size_t)n,
                          kind == 1 ? "[fill f%d]\nn = 1\ncolumns = 1\norigin = 0.5 0.5\nrmin = 0.5\n"
                                      "rmax = 0.5\nmaterial = m\n"
                                    : "[disc d%d]\nx = 1 1\nr = 0.5\nmaterial = m\n", k);
        snprintf(text + n, size - (size_t)n, "[stage s]\ncycles = 1\n");
        struct tfx *f = tfx_parse(text, "crowd");
        ck_assert_int_eq(tfx_create(f), BAL_EINVAL);
        /* some disc of the crowd, at its line (after the 3 lines of the
         * material, and 2 of the settings when given) */
        const char *expect = kind == 0 ? ": x: disc d" : kind == 1 ? ": origin: disc f" : ": x: disc d";
        ck_assert_msg(strncmp(f->err.msg, "crowd:", 6) == 0 && t_contains(f->err.msg, expect),
                      "kind %d: %s", kind, f->err.msg);
        if (kind < 2)
            ck_assert_msg(t_contains(f->err.msg, "overlaps disc ") &&
                          t_contains(f->err.msg, " by 1 (2 of the smaller radius) at the start"),
                          "kind %d: %s", kind, f->err.msg);
        else
            ck_assert_msg(t_contains(f->err.msg, "has more than 512 neighbours within reach at "
                                                 "the start"), "%s", f->err.msg);
        tfx_release(f);
    }
    free(text);
}
END_TEST

/* Item 13: a generator's discs are named NAME.k in every message, and a
 * probe names them so: [fill], [pile], [grains] and [import].  A probe of
 * each disc by the name bal_specimen_disc_name gives it reads that disc;
 * and the probes read the discs the layout rules put there (fill: the
 * lattice of pitch 2 rmax from the origin; pile: bottom row from origin +
 * d/2, one d apart, on the floor; import: the file's rows). */
#define GENERATED                                                                              \
    "[material m]\nkn = 1e5\ndensity = 2\n"                                                   \
    "[fill f]\nn = 6\ncolumns = 3\norigin = 0 30\nrmin = 0.5\nrmax = 0.5\nmaterial = m\n"      \
    "[pile q]\nL = 4\nd = 1\norigin = 50 0\nmaterial = m\nwall_material = m\n"                 \
    "[grains g]\nsize = 20 20\nn = 10\nmaterial = m\ndmin = 1\nd10 = 1.2\nd50 = 1.5\n"         \
    "d60 = 1.6\ndmax = 2\n"                                                                     \
    "[import p]\ndiscs = scenes/import/discs.tsv\nmaterial = m\n"                              \
    "[stage s]\ncycles = 1\n"

START_TEST(specimen_generated_discs_probed)
{
    struct tfx *names = tfx_parse(GENERATED, "generated");
    const long n = bal_specimen_count(&names->sc);
    ck_assert_int_eq(n, 6 + 5 + 10 + 2);
    char text[T_TEXT_MAX];
    int len = snprintf(text, sizeof text, "%s", GENERATED
                       "[probe fy]\nquantity = disc_y\na = f.4\n[probe fx]\nquantity = disc_x\n"
                       "a = f.4\n[probe qx]\nquantity = disc_x\na = q.3\n[probe qy]\n"
                       "quantity = disc_y\na = q.3\n[probe px]\nquantity = disc_x\na = p.1\n"
                       "[probe pr]\nquantity = contact_fn\na = p.0\nb = q_floor\n");
    for (int id = 0; id < n; id++) {
        char name[2 * BAL_NAME_MAX];
        bal_specimen_disc_name(&names->sc, id, name, sizeof name);
        len += snprintf(text + len, sizeof text - (size_t)len,
                        "[probe x%d]\nquantity = disc_x\na = %s\n[probe y%d]\nquantity = disc_y\n"
                        "a = %s\n", id, name, id, name);
        ck_assert_int_lt(len, (int)sizeof text);
    }
    struct tfx *f = tfx_new(text, "generated");
    t_steps(f, 1);
    const struct bal_sim *s = f->sim;
    for (int id = 0; id < n; id++) {
        char px[16], py[16];
        snprintf(px, sizeof px, "x%d", id);
        snprintf(py, sizeof py, "y%d", id);
        ck_assert_double_eq(t_probe_value(f, px), s->x[s->slot[id]]);
        ck_assert_double_eq(t_probe_value(f, py), s->y[s->slot[id]]);
    }
    /* f.4: row 1, column 1 (3 columns); at rest (no gravity, touching) */
    ck_assert_double_eq(t_probe_value(f, "fx"), 0 + 0.5 + 1 * 1.0);
    ck_assert_double_eq(t_probe_value(f, "fy"), 30 + 0.5 + 1 * 1.0);
    ck_assert_double_eq(t_probe_value(f, "qx"), 50 + 0.5 + 3 * 1.0);
    ck_assert_double_eq(t_probe_value(f, "qy"), 0.5);
    ck_assert_double_eq(t_probe_value(f, "px"), 1.5);
    ck_assert_double_eq(t_probe_value(f, "pr"), 0); /* p.0 is nowhere near the floor */
}
END_TEST

/* A pile scene's materials (as the bad-input table of check_scene.c
 * writes them) and a stage of three cycles. */
#define PILE_HEAD "[material g]\nkn = 1e5\ndensity = 2.385\n[material w]\nkn = 2e5\n"
#define STAGE "[stage s]\ncycles = 3\n"
/* Degrees → radians and the unit vector of a wall: one product and a cos
 * or sin of an O(1) angle, a few ulps: 1e-15 absolute. */
#define ANGLE_ABS 1e-15

/* ------------------------------------------------------------------ */
/* The [pile] generator (MLH Sec. 4, Fig. 2)                           */
/* ------------------------------------------------------------------ */

/* Disc counts (MLH Sec. 4): row M holds L − 3M discs (slope 30) or L − M
 * (slope 60), so
 *   H30 = int((L − 1)/3) + 1,  N30 = H30 (L − 3 (H30 − 1)/2),
 *   H60 = L,                   N60 = L (L + 1)/2,
 * e.g. L = 16 → N30 = 6 · 8.5 = 51 (the exact-solution pile of Sec. 4.2),
 * L = 100 → N30 = 34 · 50.5 = 1717 (Sec. 4.3).  In integers,
 * N30 = H30 (2L − 3 (H30 − 1)) / 2. */
static long pile_n30(long L)
{
    const long H = (L - 1) / 3 + 1;
    return H * (2 * L - 3 * (H - 1)) / 2;
}

START_TEST(scene_pile_counts)
{
    ck_assert_int_eq(pile_n30(16), 51);
    ck_assert_int_eq(pile_n30(100), 1717);
    for (long L = 1; L <= 101; L++) {
        struct bal_pile_def p;
        memset(&p, 0, sizeof p);
        p.L = L;
        p.d = 0.83;
        p.slope = 0;
        ck_assert_msg(bal_specimen_pile_count(&p) == pile_n30(L), "slope 30, L = %ld: %ld discs", L,
                      bal_specimen_pile_count(&p));
        p.slope = 1;
        ck_assert_msg(bal_specimen_pile_count(&p) == L * (L + 1) / 2, "slope 60, L = %ld: %ld discs", L,
                      bal_specimen_pile_count(&p));
    }
}
END_TEST

/* Lattice tolerances.  Positions are sums and square roots of O(1)–O(100)
 * numbers, each row built from the one below: a distance of O(d) carries
 * a few ulps of the coordinates (≤ ~1e-14 for x up to ~100 d), so 1e-12 d
 * is a round-off bound, far below any misplaced disc. */
#define LATTICE_REL 1e-12

/* Checks shared by every pile: for each disc of row M > 0, no disc of row
 * M − 1 is closer than d (no overlap), and its `supports` (the two nearest
 * discs of row M − 1) lie at exactly d when `seated` (each disc in a
 * hollow); otherwise at least one disc of the row touches the row below
 * (each row at the lowest height where it does not overlap).  Rows are
 * symmetric about the pile's centre xc and at one height each; row M has
 * `per_row(M)` discs.  Returns the number of rows. */
static int check_pile_rows(const struct bal_sim *s, double d, double xc, int seated, int slope60,
                           long L)
{
    const double tol = LATTICE_REL * d;
    int rows = 0;
    for (int i = 0; i < s->n; i++)
        rows = s->row[i] + 1 > rows ? s->row[i] + 1 : rows;
    for (int M = 0; M < rows; M++) {
        long count = 0;
        double xsum = 0, y = NAN;
        int touching = 0;
        for (int i = 0; i < s->n; i++) {
            if (s->row[i] != M)
                continue;
            count++;
            xsum += s->x[i] - xc;
            if (isnan(y))
                y = s->y[i];
            ck_assert_double_eq_tol(s->y[i], y, tol); /* one height per row */
            if (M == 0)
                continue;
            double near1 = INFINITY, near2 = INFINITY;
            for (int j = 0; j < s->n; j++) {
                if (s->row[j] != M - 1)
                    continue;
                const double dist = hypot(s->x[j] - s->x[i], s->y[j] - s->y[i]);
                ck_assert_msg(dist >= d - tol, "row %d: disc at x = %g overlaps the row below by %g",
                              M, s->x[i], d - dist);
                if (dist < near1) {
                    near2 = near1;
                    near1 = dist;
                } else if (dist < near2) {
                    near2 = dist;
                }
            }
            if (seated) {
                ck_assert_msg(fabs(near1 - d) <= tol && fabs(near2 - d) <= tol,
                              "row %d, x = %g: supports at %.17g and %.17g, expected d = %.17g", M,
                              s->x[i], near1, near2, d);
            }
            touching |= fabs(near1 - d) <= tol;
        }
        ck_assert_int_eq(count, L - (slope60 ? 1 : 3) * M);
        ck_assert_double_eq_tol(xsum / (double)count, 0.0, tol); /* symmetric about xc */
        if (M > 0)
            ck_assert_msg(touching, "row %d floats above the row below", M);
    }
    return rows;
}

/* Height of row M above row 0 when every row sits in the hollows of the
 * row below at horizontal spacing s: each step is √(d² − s²/4); for s = d
 * the triangular lattice, √3/2 d. */
static double seated_height(int M, double d, double s)
{
    return M * sqrt(d * d - s * s / 4);
}

/* Smooth bottom, slope 30, L = 16 (MLH Sec. 4.2): 51 discs named heap.k
 * after the scene's own [disc] sections; row 0 on the floor wall heap_floor
 * (y = origin_y, spanning the base) at spacing d, centres at
 * origin + (R + k d, R); only the two corner stones held; the rows above
 * on a triangular lattice (row spacing √3/2 d, supports at d). */
START_TEST(scene_pile_smooth_lattice)
{
    const double d = 0.83, ox = -1.7, oy = 0.45, r = d / 2;
    const long L = 16;
    struct tfx *f = tfx_newf("pile",
                             "[material g]\nkn = 1e5\ndensity = 2.385\n"
                             "[material floor]\nkn = 2e5\n"
                             "[disc lone]\nx = -9 9\nr = 0.3\nmaterial = g\n"
                             "[pile heap]\nL = %ld\nd = %.17g\norigin = %.17g %.17g\n"
                             "material = g\nwall_material = floor\n"
                             "[stage s]\ncycles = 1\n",
                             L, d, ox, oy);
    const struct bal_sim *s = f->sim;
    ck_assert_int_eq(s->n, 1 + 51);
    /* names: [disc] sections first, then heap.0 … heap.50 */
    char name[2 * BAL_NAME_MAX], want[2 * BAL_NAME_MAX];
    bal_output_disc_name(s, 0, name, sizeof name);
    ck_assert_str_eq(name, "lone");
    for (int k = 0; k < 51; k++) {
        bal_output_disc_name(s, 1 + k, name, sizeof name);
        snprintf(want, sizeof want, "heap.%d", k);
        ck_assert_str_eq(name, want);
    }
    /* the floor */
    ck_assert_int_eq(s->n_walls, 1);
    ck_assert_str_eq(s->walls[0].name, "heap_floor");
    const struct bal_wall *w = &s->walls[0];
    ck_assert_double_eq_tol(w->e[0], 1.0, ANGLE_ABS);
    ck_assert_double_eq_tol(w->e[1], 0.0, ANGLE_ABS);
    ck_assert_double_eq_tol(w->p[1], oy, LATTICE_REL);
    ck_assert(w->p[0] + w->h1 * w->e[0] <= ox);                  /* reaches past */
    ck_assert(w->p[0] + w->h2 * w->e[0] >= ox + (double)L * d); /* both ends */
    /* row 0 and the held corner stones */
    int held = 0;
    double xmin = INFINITY, xmax = -INFINITY;
    for (int i = 0; i < s->n; i++) {
        if (s->row[i] != 0)
            continue;
        const double k = (s->x[i] - ox - r) / d;
        ck_assert_double_eq_tol(k, round(k), LATTICE_REL * L);
        ck_assert_double_eq_tol(s->y[i], oy + r, LATTICE_REL); /* resting on the floor */
        xmin = fmin(xmin, s->x[i]);
        xmax = fmax(xmax, s->x[i]);
    }
    ck_assert_double_eq_tol(xmin, ox + r, LATTICE_REL);
    ck_assert_double_eq_tol(xmax, ox + r + (double)(L - 1) * d, LATTICE_REL * L);
    for (int i = 0; i < s->n; i++) {
        if (!s->fixed[i])
            continue;
        held++;
        ck_assert_int_eq(s->row[i], 0);
        ck_assert(s->x[i] == xmin || s->x[i] == xmax);
    }
    ck_assert_int_eq(held, 2);
    ck_assert_int_eq(s->row[t_slot(f, "lone")], -1);
    const double xc = ox + r + 0.5 * (double)(L - 1) * d;
    ck_assert_int_eq(check_pile_rows(s, d, xc, 1, 0, L), 6);
    for (int i = 0; i < s->n; i++)
        if (s->row[i] > 0)
            ck_assert_double_eq_tol(s->y[i] - (oy + r), seated_height(s->row[i], d, d),
                                    LATTICE_REL * L);
    /* Nothing overlaps at the start: no contact carries a force. */
    t_steps(f, 1);
    ck_assert_double_eq(bal_measure_elastic(s), 0.0);
}
END_TEST

/* Bumpy bottom, slope 60 and 30: all of row 0 held at spacing d (1 + c),
 * no floor wall.  c = 1/15 (MLH Sec. 4.1, wide): rows above at the same
 * spacing s = d (1 + c), seated in the hollows, height steps √(d² − s²/4).
 * c = 0: the triangular lattice.  c = −1/150 (squeezed): rows above at
 * spacing d, row 1 no longer in symmetric hollows; it still touches row 0
 * and overlaps nothing. */
START_TEST(scene_pile_bumpy_lattice)
{
    static const struct {
        double c;
        int slope60, seated;
        long L, n;
    } cases[] = {
        {1.0 / 15, 0, 1, 19, 70},   /* 19 16 13 10 7 4 1 */
        {0.0, 1, 1, 7, 28},         /* MLH Fig. 2, L_0 = 7 */
        {0.0, 0, 1, 100, 1717},     /* MLH Sec. 4.3 */
        {-1.0 / 150, 0, 0, 19, 70},
    };
    const double d = 0.0015, ox = 0.0125, oy = -0.0071, r = d / 2;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        struct tfx *f = tfx_newf("bumpy",
                                 "[material g]\nkn = 1e5\ndensity = 2.385\n"
                                 "[pile base]\nL = %ld\nslope = %s\nd = %.17g\n"
                                 "origin = %.17g %.17g\nbottom = bumpy\nc = %.17g\nmaterial = g\n"
                                 "[stage s]\ncycles = 1\n",
                                 cases[k].L, cases[k].slope60 ? "60" : "30", d, ox, oy, cases[k].c);
        const struct bal_sim *s = f->sim;
        ck_assert_int_eq(s->n, cases[k].n);
        ck_assert_int_eq(s->n_walls, 0);
        const double s0 = d * (1 + cases[k].c);
        int held = 0;
        for (int i = 0; i < s->n; i++) {
            ck_assert_int_eq(s->fixed[i], s->row[i] == 0); /* all of row 0, nothing else */
            held += s->fixed[i];
            if (s->row[i] == 0) {
                const double q = (s->x[i] - ox - r) / s0;
                ck_assert_double_eq_tol(q, round(q), LATTICE_REL * (double)cases[k].L);
                ck_assert_double_eq_tol(s->y[i], oy + r, LATTICE_REL * d);
            }
        }
        ck_assert_int_eq(held, cases[k].L);
        const double xc = ox + r + 0.5 * (double)(cases[k].L - 1) * s0;
        check_pile_rows(s, d, xc, cases[k].seated, cases[k].slope60, cases[k].L);
        if (cases[k].seated) {
            const double sp = fmax(d, s0);
            for (int i = 0; i < s->n; i++)
                ck_assert_double_eq_tol(s->y[i] - (oy + r), seated_height(s->row[i], d, sp),
                                        LATTICE_REL * d * (double)cases[k].L);
        }
        tfx_release(f);
    }
}
END_TEST


/* The boundary cases are accepted: a smooth pile of L = 3 (two corner
 * stones and one free disc), a bumpy pile of L = 1 without a floor. */
START_TEST(scene_pile_smallest)
{
    struct tfx *f = tfx_new(PILE_HEAD "[pile p]\nL = 3\nd = 0.83\nmaterial = g\n"
                                      "wall_material = w\n" STAGE,
                            "small");
    ck_assert_int_eq(f->sim->n, 3);
    ck_assert_int_eq(f->sim->n_walls, 1);
    int held = 0;
    for (int i = 0; i < f->sim->n; i++)
        held += f->sim->fixed[i];
    ck_assert_int_eq(held, 2);
    f = tfx_new(PILE_HEAD "[pile p]\nL = 1\nd = 0.83\nbottom = bumpy\nmaterial = g\n" STAGE,
                "one");
    ck_assert_int_eq(f->sim->n, 1);
    ck_assert_int_eq(f->sim->n_walls, 0);
    ck_assert_int_eq(f->sim->fixed[0], 1);
}
END_TEST

/* ------------------------------------------------------------------ */
/* The polydisperse pile (MLH Sec. 4.4): size_spread and seed          */
/* ------------------------------------------------------------------ */

/* The discs a pile scene generates, in scene order (no simulation built:
 * the generator alone). */
struct spread_pile {
    struct tfx *f;
    struct bal_specimen d;
    long n;
};

static void spread_pile_make(struct spread_pile *p, const char *name, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static void spread_pile_make(struct spread_pile *p, const char *name, const char *fmt, ...)
{
    static char text[4096];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    p->f = tfx_parse(text, name);
    ck_assert_int_eq(bal_scene_validate(&p->f->sc, &p->f->err), BAL_OK);
    p->n = bal_specimen_count(&p->f->sc);
    ck_assert_int_eq(bal_specimen_generate(&p->f->sc, (int)p->n, &p->d, &p->f->err), BAL_OK);
}

static void spread_pile_free(struct spread_pile *p)
{
    bal_specimen_free(&p->d);
    tfx_release(p->f);
}

/* The distribution of the diameters: d_i = d0 (1 + q_i), q_i uniform in
 * [−r_d/2, r_d/2).  15251 discs (L = 301), r_d = 0.2.  Bounds exactly (up
 * to the rounding of r0 (1 + q)); the mean, the variance r_d²/12 and the
 * ten bin counts within 5 standard errors of a uniform sample of that size:
 * SE(mean) = r_d/√(12 N), SE(variance) = √(4/45) (r_d/2)²/√N, SE(bin) =
 * √(N 0.1 0.9).  The numbers are fixed by the seed; 5 standard errors is
 * the statistical tolerance, which a correct generator fails with any
 * seed with probability below 1e-6 per moment (and the extremes within
 * 10 r_d/N of the bounds, e^-10).  Two seeds are tried. */
START_TEST(scene_pile_spread_distribution)
{
    const double d0 = 0.83, rd = 0.2, r0 = d0 / 2, a = rd / 2;
    const unsigned long seeds[] = {20261125, 7};
    for (size_t k = 0; k < sizeof seeds / sizeof seeds[0]; k++) {
        struct spread_pile p;
        spread_pile_make(&p, "spread",
                         "[material g]\nkn = 1e5\ndensity = 2.385\n"
                         "[pile p]\nL = 301\nd = %.17g\nbottom = bumpy\nsize_spread = %.17g\n"
                         "seed = %lu\nmaterial = g\n[stage s]\ncycles = 1\n",
                         d0, rd, seeds[k]);
        const long N = p.n;
        ck_assert_int_eq(N, pile_n30(301));
        double sum = 0, sum2 = 0, lo = INFINITY, hi = -INFINITY;
        long bins[10] = {0};
        for (long i = 0; i < N; i++) {
            const double q = p.d.r[i] / r0 - 1;
            ck_assert_msg(q >= -a - 1e-15 && q < a + 1e-15, "disc %ld: q = %.17g", i, q);
            sum += q;
            lo = fmin(lo, q);
            hi = fmax(hi, q);
            int b = (int)floor((q + a) / rd * 10);
            bins[b < 0 ? 0 : b > 9 ? 9 : b]++;
        }
        const double mean = sum / (double)N;
        for (long i = 0; i < N; i++) {
            const double q = p.d.r[i] / r0 - 1;
            sum2 += (q - mean) * (q - mean);
        }
        const double var = sum2 / (double)(N - 1), sq = sqrt((double)N);
        ck_assert_msg(fabs(mean) <= 5 * rd / sqrt(12.0) / sq, "mean %g", mean);
        ck_assert_msg(fabs(var - rd * rd / 12) <= 5 * sqrt(4.0 / 45) * a * a / sq,
                      "variance %g, expected %g", var, rd * rd / 12);
        for (int b = 0; b < 10; b++)
            ck_assert_msg(fabs((double)bins[b] - 0.1 * (double)N) <= 5 * sqrt(0.09 * (double)N),
                          "bin %d holds %ld of %ld", b, bins[b], N);
        ck_assert_msg(lo < -a + 10 * rd / (double)N && hi > a - 10 * rd / (double)N,
                      "extremes %g %g", lo, hi);
        spread_pile_free(&p);
    }
}
END_TEST

/* The numbers are GSL's mt19937: with seed 5489 its first three outputs are
 * those of Matsumoto & Nishimura's reference mt19937ar (init_genrand(5489)):
 * 3499211612, 581869302, 3890346734, each u = k / 2^32 (gsl_rng_uniform).
 * So the first three discs (row 0, from the left) have exactly these radii
 * on every machine.  The same seed gives the same pile bit for bit; another
 * seed another; and with size_spread = 0 the seed changes nothing. */
START_TEST(scene_pile_spread_seed)
{
    const double d0 = 1, rd = 0.5, r0 = 0.5;
    const char *scene = "[material g]\nkn = 1e5\ndensity = 1.2732395447351628\n"
                        "[pile p]\nL = 22\nd = 1\nbottom = bumpy\nsize_spread = %.17g\n"
                        "seed = %lu\nmaterial = g\n[stage s]\ncycles = 1\n";
    struct spread_pile p, q;
    spread_pile_make(&p, "seed", scene, rd, 5489ul);
    const double ref[3] = {3499211612.0, 581869302.0, 3890346734.0};
    for (int i = 0; i < 3; i++)
        ck_assert_double_eq(p.d.r[i], r0 * (1 + rd * (ref[i] / 4294967296.0 - 0.5)));
    (void)d0;
    spread_pile_make(&q, "seed", scene, rd, 5489ul);
    const size_t bytes = (size_t)p.n * sizeof(double);
    ck_assert(memcmp(p.d.r, q.d.r, bytes) == 0);
    ck_assert(memcmp(p.d.x, q.d.x, bytes) == 0);
    ck_assert(memcmp(p.d.y, q.d.y, bytes) == 0);
    spread_pile_free(&q);
    spread_pile_make(&q, "seed", scene, rd, 5490ul);
    long same = 0;
    for (long i = 0; i < p.n; i++)
        same += p.d.r[i] == q.d.r[i];
    ck_assert_int_eq(same, 0);
    spread_pile_free(&q);
    spread_pile_free(&p);
    /* size_spread = 0: equal discs, whatever the seed */
    spread_pile_make(&p, "seed", scene, 0.0, 1ul);
    spread_pile_make(&q, "seed", scene, 0.0, 99ul);
    ck_assert(memcmp(p.d.x, q.d.x, (size_t)p.n * sizeof(double)) == 0);
    ck_assert(memcmp(p.d.y, q.d.y, (size_t)p.n * sizeof(double)) == 0);
    for (long i = 0; i < p.n; i++)
        ck_assert(p.d.r[i] == r0 && q.d.r[i] == r0);
    spread_pile_free(&q);
    spread_pile_free(&p);
}
END_TEST

/* The layout (specimen.c, lay_pile_spread), for bumpy bottoms with c = 0,
 * −1/150 and 1/15, a 60° pile and a smooth bottom:
 *   - the held row: bumpy, every disc at its lattice site on the line
 *     oy + d/2; smooth, each disc on the floor (y = oy + r_i), the two
 *     corner stones held;
 *   - nothing overlaps that may not (only held discs may), and the
 *     simulation builds (bal_sim_create refuses overlaps);
 *   - each row M ≥ 1 at one height, resting on the one below: its lowest
 *     clearance over the discs below is zero;
 *   - each free row is the least-squares projection of its lattice sites
 *     X_a onto x_{a+1} − x_a ≥ r_a + r_{a+1}: the optimality conditions of
 *     that convex problem hold (feasibility; the prefix sums P_a =
 *     Σ_{b≤a} (x_b − X_b) are ≤ 0, the multipliers −P_a; P_{n−1} = 0; and
 *     P_a = 0 wherever neighbours a, a + 1 do not touch).
 * Tolerance: 1e-12 d for distances (LATTICE_REL); 1e-11 d for the prefix
 * sums, which add up to 100 displacements computed from sums of 100
 * diameters. */
START_TEST(scene_pile_spread_layout)
{
    static const struct {
        double c, rd;
        int slope60, smooth;
        long L;
        unsigned long seed;
    } cases[] = {
        {0.0, 1.0 / 30, 0, 0, 100, 3},   /* MLH Sec. 4.4, Fig. 8(b) */
        {0.0, 2.0 / 3000, 0, 0, 100, 4}, /* Fig. 8(a) */
        {-1.0 / 150, 0.05, 0, 0, 22, 5},
        {1.0 / 15, 0.1, 0, 0, 19, 6},
        {0.0, 0.3, 1, 0, 12, 7},
        {0.0, 0.2, 0, 1, 16, 8},
    };
    const double d = 0.83, ox = -1.7, oy = 0.45, r0 = d / 2;
    const double tol = LATTICE_REL * d;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        const int smooth = cases[k].smooth;
        const long L = cases[k].L;
        char text[1024];
        snprintf(text, sizeof text,
                 "[material g]\nkn = 1e5\ndensity = 2.385\n[material w]\nkn = 1e5\n"
                 "[pile p]\nL = %ld\nslope = %s\nd = %.17g\norigin = %.17g %.17g\nbottom = %s\n"
                 "c = %.17g\nsize_spread = %.17g\nseed = %lu\nmaterial = g\nwall_material = w\n"
                 "[stage s]\ncycles = 1\n",
                 L, cases[k].slope60 ? "60" : "30", d, ox, oy, smooth ? "smooth" : "bumpy",
                 cases[k].c, cases[k].rd, cases[k].seed);
        struct spread_pile p;
        spread_pile_make(&p, "layout", "%s", text);
        const struct bal_specimen *D = &p.d;
        const double c = smooth ? 0 : cases[k].c;
        const double s0 = d * (1 + c), s = d * fmax(1.0, 1 + c);
        const double xc = ox + r0 + 0.5 * (double)(L - 1) * s0;
        int rows = 0;
        for (long i = 0; i < p.n; i++)
            rows = D->row[i] + 1 > rows ? D->row[i] + 1 : rows;
        long first = 0;
        for (int M = 0; M < rows; M++) {
            const long n = L - (cases[k].slope60 ? 1 : 3) * M;
            ck_assert_int_eq(D->row[first], M);
            ck_assert_int_eq(D->row[first + n - 1], M);
            const double spacing = M == 0 ? s0 : s;
            for (long a = 0; a < n; a++) {
                const long i = first + a;
                const double X = xc + ((double)a - 0.5 * (double)(n - 1)) * spacing;
                if (M == 0) {
                    ck_assert_int_eq(D->fixed[i], !smooth || a == 0 || a == n - 1);
                    ck_assert_double_eq_tol(D->y[i], oy + (smooth ? D->r[i] : r0), tol);
                    if (!smooth)
                        ck_assert_double_eq_tol(D->x[i], X, tol);
                } else {
                    ck_assert_int_eq(D->fixed[i], 0);
                    ck_assert_double_eq(D->y[i], D->y[first]); /* one height per row */
                }
            }
            if (M > 0) { /* resting on the row below, overlapping nothing below */
                /* (one assertion per row: Check marks every passing one) */
                double clearance = INFINITY, worst = INFINITY;
                for (long a = first; a < first + n; a++)
                    for (long b = 0; b < first; b++) {
                        const double gap = hypot(D->x[a] - D->x[b], D->y[a] - D->y[b]) -
                                           (D->r[a] + D->r[b]);
                        worst = fmin(worst, gap);
                        if (D->row[b] == M - 1)
                            clearance = fmin(clearance, gap);
                    }
                ck_assert_msg(worst >= -tol, "case %zu, row %d overlaps a disc below by %g", k, M,
                              -worst);
                ck_assert_msg(fabs(clearance) <= tol, "case %zu, row %d floats %g above the row below",
                              k, M, clearance);
            }
            if (M > 0 || smooth) { /* the projection's optimality conditions */
                double P = 0;
                for (long a = 0; a < n; a++) {
                    const long i = first + a;
                    P += D->x[i] - (xc + ((double)a - 0.5 * (double)(n - 1)) * spacing);
                    ck_assert_msg(P <= 10 * tol, "case %zu, row %d: prefix sum %g > 0", k, M, P);
                    if (a == n - 1) {
                        ck_assert_msg(fabs(P) <= 10 * tol, "case %zu, row %d: P_n = %g", k, M, P);
                        break;
                    }
                    const double gap = D->x[i + 1] - D->x[i] - (D->r[i] + D->r[i + 1]);
                    ck_assert_msg(gap >= -tol, "case %zu, row %d: discs %ld, %ld overlap", k, M, i,
                                  i + 1);
                    if (gap > tol)
                        ck_assert_msg(fabs(P) <= 10 * tol,
                                      "case %zu, row %d: slack gap after disc %ld but P = %g", k, M,
                                      i, P);
                }
            }
            first += n;
        }
        ck_assert_int_eq(first, p.n);
        spread_pile_free(&p);
        /* The simulation builds: no overlap it would refuse. */
        struct tfx *f = tfx_new(text, "layout");
        ck_assert_int_eq(f->sim->n, (int)p.n);
        tfx_release(f);
    }
}
END_TEST

Suite *suite_specimen(void)
{
    Suite *s = suite_create("specimen");
    TCase *tc = tcase_create("grains");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, specimen_grading_by_area);
    tcase_add_test(tc, specimen_grading_inverse);
    tcase_add_test(tc, specimen_grains_placed);
    tcase_add_test(tc, specimen_grains_seed);
    suite_add_tcase(s, tc);

    tc = tcase_create("import");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, specimen_import_round_trip);
    tcase_add_test(tc, specimen_import_set);
    tcase_add_test(tc, specimen_import_byte_order_mark);
    tcase_add_test(tc, specimen_crowded_start_is_bad_input);
    tcase_add_test(tc, specimen_generated_discs_probed);
    suite_add_tcase(s, tc);
    tc = tcase_create("pile");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, scene_pile_counts);
    tcase_add_test(tc, scene_pile_smooth_lattice);
    tcase_add_test(tc, scene_pile_bumpy_lattice);
    tcase_add_test(tc, scene_pile_smallest);
    tcase_add_test(tc, scene_pile_spread_distribution);
    tcase_add_test(tc, scene_pile_spread_seed);
    tcase_add_test(tc, scene_pile_spread_layout);
    suite_add_tcase(s, tc);
    return s;
}
