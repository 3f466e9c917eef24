/*
 * check_specimen.c — suite "specimen": the [grains] generator (its grading
 * curve by area, its random sequential addition, its seed) and [import], a
 * prepared state read back from the files a run wrote.
 *
 * The grading curve (specimen.c): F(d), the share of the discs' area in
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
    return s;
}
