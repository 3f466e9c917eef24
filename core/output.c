/*
 * output.c — the files a run writes.
 *
 *   series.tsv    header line of column names (cycle, time, then one column
 *                 per [probe], in file order), one row per output interval
 *   discs.tsv     final state of every disc, in scene order
 *   contacts.tsv  every touching contact of the final state
 *   walls.tsv     every wall of the final state: end points A, B and the
 *                 resultant the discs exert on it (C&S Table 1)
 *   stress.tsv    per disc: the stress tensor of MLH eq. (8), its principal
 *                 values and the angle of eq. (9) (measure.c states V)
 *   stress_grid.tsv  moving averages over overlapping cells, when the scene
 *                 sets stress_width
 *   run.json      version, build, scene, overrides, how the run ended,
 *                 steps, time step and its estimate, timings, energies
 *   snapshots/    the discs, contacts and walls at regular intervals, when
 *                 the scene asks (snapshots.c, vtk.c: they write the rows of
 *                 discs.tsv, contacts.tsv and walls.tsv through output.h)
 *
 * Numbers are printed with %.17g, so a file read back gives the same
 * doubles: outputs compare bitwise across runs.  Every file is written
 * under NAME.tmp and renamed when complete, so a reader never takes a
 * half-written file for a result.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "measure.h"
#include "output.h"
#include "scene_keys.h"
#include "specimen.h"
#include "walls.h"

#ifndef BAL_BUILD_FLAGS
#define BAL_BUILD_FLAGS "unknown"
#endif

void bal_output_disc_name(const struct bal_sim *s, int id, char *buf, size_t size)
{
    bal_specimen_disc_name(s->scene, id, buf, size);
}

void bal_output_series_header(const struct bal_sim *s, FILE *f)
{
    fputs("cycle\ttime", f);
    for (int p = 0; p < s->scene->n_probes; p++)
        fprintf(f, "\t%s", s->scene->probes[p].name);
    fputc('\n', f);
}

enum bal_status bal_output_series_row(const struct bal_sim *s, FILE *f, struct bal_error *err)
{
    /* Measured first, into the simulation's row buffer, so that a value
     * that is not finite stops the run before anything of the row is
     * written. */
    for (int p = 0; p < s->n_probes; p++) {
        const double v = bal_probes_value(s, p);
        if (!isfinite(v)) {
            const struct bal_probe_def *pd = &s->scene->probes[p];
            const int ki = bal_scene_key_index(BAL_SEC_PROBE, "quantity");
            return bal_error(err, BAL_EUNSTABLE,
                             "%s:%d: quantity: [probe %s]: the value is %g at step %ld, not a "
                             "finite number (the state overflowed: time step too large for the "
                             "stiffness, or values near the limits of a double?)",
                             s->scene->path, pd->key_line[ki] > 0 ? pd->key_line[ki] : pd->line,
                             pd->name, v, s->step);
        }
        s->row_values[p] = v;
    }
    fprintf(f, "%ld\t%.17g", s->step, s->time);
    for (int p = 0; p < s->n_probes; p++)
        fprintf(f, "\t%.17g", s->row_values[p]);
    fputc('\n', f);
    return BAL_OK;
}

FILE *bal_output_open(const char *dir, const char *name, struct bal_error *err)
{
    char path[1024];
    if (snprintf(path, sizeof path, "%s/%s.tmp", dir, name) >= (int)sizeof path) {
        bal_error(err, BAL_EIO, "%s/%s: cannot write: the path is longer than %zu characters",
                  dir, name, sizeof path - 1);
        return NULL;
    }
    FILE *f = fopen(path, "w");
    if (!f)
        bal_error(err, BAL_EIO, "%s: cannot write: %s", path, strerror(errno));
    return f;
}

enum bal_status bal_output_close(FILE *f, const char *dir, const char *name,
                                 struct bal_error *err)
{
    int bad = ferror(f);
    bad |= fclose(f) != 0;
    if (bad) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s.tmp", dir, name);
        remove(path);
        return bal_error(err, BAL_EIO, "%s: write failed", path);
    }
    return bal_output_commit(dir, name, err);
}

enum bal_status bal_output_commit(const char *dir, const char *name, struct bal_error *err)
{
    char from[1024], to[1024];
    snprintf(from, sizeof from, "%s/%s.tmp", dir, name);
    snprintf(to, sizeof to, "%s/%s", dir, name);
    if (rename(from, to) != 0)
        return bal_error(err, BAL_EIO, "%s: cannot rename to %s: %s", from, to, strerror(errno));
    return BAL_OK;
}

static void body_name(const struct bal_sim *s, int is_wall, int index, char *buf, size_t size)
{
    if (is_wall)
        snprintf(buf, size, "%s", s->walls[index].name);
    else
        bal_output_disc_name(s, s->id[index], buf, size);
}

/* With rolling resistance, a contact's row ends with its rolling moment M,
 * its rolling dashpot's M_d, its relative rotation θ_r (all oriented from
 * body a to body b, the couple on a being −(M + M_d)) and its rolling state
 * (1 at the cap, 2 lost: Model 2); a scene without rolling writes none of
 * these columns. */
static void rolling_columns(const struct bal_sim *s, const struct bal_pairs *p, long c, FILE *f)
{
    if (!p->rolling)
        return;
    fprintf(f, "\t%.17g\t%.17g\t%.17g\t%d", p->mr[c], bal_measure_rolling_dashpot(s, p, c),
            p->tr[c], (p->flags[c] & BAL_PAIR_BROKEN) ? 2 : (p->flags[c] & BAL_PAIR_ROLLING) ? 1 : 0);
}

void bal_output_contact_point(const struct bal_sim *s, int walls, long c, double *px, double *py,
                              double *nx, double *ny)
{
    if (walls) {
        const int i = s->pw.i[c];
        double ex, ey;
        const double d = bal_walls_normal(&s->walls[s->pw.j[c]], s->x[i], s->y[i], &ex, &ey);
        /* Halfway between the disc's surface point and the wall point
         * (C&S p. 49, contact A of Fig. 1). */
        const double at = 0.5 * (s->r[i] + d);
        *px = s->x[i] + at * ex;
        *py = s->y[i] + at * ey;
        *nx = ex;
        *ny = ey;
        return;
    }
    const int i = s->pp.i[c], j = s->pp.j[c];
    const double dx = s->x[j] - s->x[i], dy = s->y[j] - s->y[i];
    const double d = hypot(dx, dy), delta = s->r[i] + s->r[j] - d;
    const double ex = dx / d, ey = dy / d, at = s->r[i] - delta / 2;
    *px = s->x[i] + at * ex;
    *py = s->y[i] + at * ey;
    *nx = ex;
    *ny = ey;
}

void bal_output_contacts(const struct bal_sim *s, FILE *f)
{
    fputs("a\tb\tkind\tx\ty\tnx\tny\tfn\tfs\tdn\tds\tsliding", f);
    fputs(s->has_rolling ? "\tmr\tmd\ttheta_r\trolling\n" : "\n", f);
    char a[2 * BAL_NAME_MAX], b[2 * BAL_NAME_MAX];
    double px, py, ex, ey;
    for (long c = 0; c < s->pp.n; c++) {
        if (!(s->pp.flags[c] & BAL_PAIR_TOUCHING))
            continue;
        bal_output_contact_point(s, 0, c, &px, &py, &ex, &ey);
        body_name(s, 0, s->pp.i[c], a, sizeof a);
        body_name(s, 0, s->pp.j[c], b, sizeof b);
        double dn, ds;
        bal_measure_dashpots(s, &s->pp, c, &dn, &ds);
        fprintf(f, "%s\t%s\tdisc\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%d", a,
                b, px, py, ex, ey, s->pp.fn[c], pair_fs(&s->pp, c), dn, ds,
                (s->pp.flags[c] & BAL_PAIR_SLIDING) != 0);
        rolling_columns(s, &s->pp, c, f);
        fputc('\n', f);
    }
    for (long c = 0; c < s->pw.n; c++) {
        if (!(s->pw.flags[c] & BAL_PAIR_TOUCHING))
            continue;
        bal_output_contact_point(s, 1, c, &px, &py, &ex, &ey);
        body_name(s, 0, s->pw.i[c], a, sizeof a);
        fprintf(f, "%s\t%s\twall\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%d", a,
                s->walls[s->pw.j[c]].name, px, py, ex, ey, s->pw.fn[c], s->pw.fs[c], s->pw.dn[c],
                s->pw.ds[c], (s->pw.flags[c] & BAL_PAIR_SLIDING) != 0);
        rolling_columns(s, &s->pw, c, f);
        fputc('\n', f);
    }
}

void bal_output_discs(const struct bal_sim *s, FILE *f, int snapshot)
{
    fputs(snapshot ? "id\tname\tgenerator\tindex\tx\ty\tr\ttheta\tvx\tvy\tomega\tfx\tfy\ttorque\tm\t"
                     "fixed\n"
                   : "id\tname\tx\ty\tr\ttheta\tvx\tvy\tomega\tm\tfixed\trow\n",
          f);
    char name[2 * BAL_NAME_MAX];
    for (int k = 0; k < s->n; k++) {
        const int i = s->slot[k];
        double vx, vy, w;
        bal_measure_velocity(s, i, &vx, &vy, &w);
        bal_output_disc_name(s, k, name, sizeof name);
        fprintf(f, "%d\t%s", k, name);
        if (snapshot) {
            long index;
            const char *generator = bal_specimen_disc_source(s->scene, k, &index);
            fprintf(f, "\t%s\t%ld", generator, index);
        }
        fprintf(f, "\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g", s->x[i], s->y[i], s->r[i],
                s->th[i] * (180 / BAL_PI), vx, vy, w);
        if (snapshot)
            fprintf(f, "\t%.17g\t%.17g\t%.17g", s->f[3 * i], s->f[3 * i + 1], s->f[3 * i + 2]);
        fprintf(f, "\t%.17g\t%d", bal_mass(s, i), s->fixed[i]);
        if (!snapshot)
            fprintf(f, "\t%d", s->row ? s->row[i] : -1);
        fputc('\n', f);
    }
}

void bal_output_walls(const struct bal_sim *s, FILE *f)
{
    fputs("name\tax\tay\tbx\tby\tf1\tf2\tmoment\tecc\n", f);
    for (int k = 0; k < s->n_walls; k++) {
        const struct bal_wall *W = &s->walls[k];
        const double mid = 0.5 * (W->h1 + W->h2), half = 0.5 * (W->h2 - W->h1);
        const double ecc = W->fn_sum != 0 ? (W->fn_s_sum / W->fn_sum - mid) / half : 0;
        fprintf(f, "%s\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\n", W->name,
                W->p[0] + W->h1 * W->e[0], W->p[1] + W->h1 * W->e[1], W->p[0] + W->h2 * W->e[0],
                W->p[1] + W->h2 * W->e[1], W->f[0], W->f[1], W->moment, ecc);
    }
}

/* Principal values and the angle of the major axis, counter-clockwise from
 * the horizontal in [0, 180) degrees (MLH eq. 9, closed form of the 2 x 2
 * symmetric eigenproblem on the symmetric part of the tensor). */
static void principal(double xx, double xz, double zx, double zz, double *smax, double *smin,
                      double *phi)
{
    const double plus = 0.5 * (xx + zz), minus = 0.5 * (xx - zz), star = 0.5 * (xz + zx);
    const double rad = hypot(minus, star);
    *smax = plus + rad;
    *smin = plus - rad;
    double a = 0.5 * atan2(2 * star, xx - zz) * (180 / BAL_PI);
    *phi = a < 0 ? a + 180 : a;
}

static void write_stress(const struct bal_sim *s, const double *moment, FILE *f)
{
    fputs("id\tname\tx\ty\trow\tfixed\tV\tsxx\tsxz\tszx\tszz\tsmax\tsmin\tphi\n", f);
    char name[2 * BAL_NAME_MAX];
    for (int k = 0; k < s->n; k++) {
        const int i = s->slot[k];
        const double v = bal_measure_disc_volume(s->r[i]);
        const double *m = &moment[4 * i];
        double smax, smin, phi;
        principal(m[0] / v, m[1] / v, m[2] / v, m[3] / v, &smax, &smin, &phi);
        bal_output_disc_name(s, k, name, sizeof name);
        fprintf(f, "%d\t%s\t%.17g\t%.17g\t%d\t%d\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\n",
                k, name, s->x[i], s->y[i], s->row ? s->row[i] : -1, s->fixed[i], v, m[0] / v,
                m[1] / v, m[2] / v,
                m[3] / v, smax, smin, phi);
    }
}

/* Moving averages (MLH Sec. 3): cells of width W and height H, stepped by
 * `step` horizontally (so they overlap when step < W) and by H vertically,
 * over the free discs; σ_cell = Σ_{discs with centre in the cell} Σ_c f ⊗ l / (W H). */
static void write_stress_grid(const struct bal_sim *s, const double *moment, FILE *f)
{
    const struct bal_settings *st = &s->scene->settings;
    const double w = st->stress_width, h = st->stress_height > 0 ? st->stress_height : w;
    const double step = st->stress_step > 0 ? st->stress_step : w;
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    for (int i = 0; i < s->n; i++) {
        x0 = fmin(x0, s->x[i]);
        x1 = fmax(x1, s->x[i]);
        y0 = fmin(y0, s->y[i]);
        y1 = fmax(y1, s->y[i]);
    }
    fputs("xc\tyc\tn\tsxx\tsxz\tszx\tszz\tsmax\tsmin\tphi\n", f);
    for (double yb = y0 - 0.5 * h; yb <= y1; yb += h) {
        for (double xb = x0 - 0.5 * w; xb <= x1; xb += step) {
            double m[4] = {0, 0, 0, 0};
            int n = 0;
            for (int i = 0; i < s->n; i++) {
                if (s->fixed[i] || s->x[i] < xb || s->x[i] >= xb + w || s->y[i] < yb ||
                    s->y[i] >= yb + h)
                    continue;
                for (int a = 0; a < 4; a++)
                    m[a] += moment[4 * i + a];
                n++;
            }
            if (n == 0)
                continue;
            for (int a = 0; a < 4; a++)
                m[a] /= w * h;
            double smax, smin, phi;
            principal(m[0], m[1], m[2], m[3], &smax, &smin, &phi);
            fprintf(f, "%.17g\t%.17g\t%d\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\n",
                    xb + 0.5 * w, yb + 0.5 * h, n, m[0], m[1], m[2], m[3], smax, smin, phi);
        }
    }
}

enum bal_status bal_output_state(const struct bal_sim *s, const char *dir, struct bal_error *err)
{
    /* The stress files need the moments of the final state (output runs
     * outside the step loop, so it may allocate). */
    double *moment = malloc((size_t)(4 * s->n + 4) * sizeof *moment);
    if (!moment)
        return bal_error(err, BAL_ENOMEM, "%s: out of memory for the stresses", dir);
    bal_measure_moments(s, moment);
    FILE *g = bal_output_open(dir, "stress.tsv", err);
    enum bal_status st = g ? BAL_OK : err->code;
    if (st == BAL_OK) {
        write_stress(s, moment, g);
        st = bal_output_close(g, dir, "stress.tsv", err);
    }
    if (st == BAL_OK && s->scene->settings.stress_width > 0) {
        g = bal_output_open(dir, "stress_grid.tsv", err);
        st = g ? BAL_OK : err->code;
        if (st == BAL_OK) {
            write_stress_grid(s, moment, g);
            st = bal_output_close(g, dir, "stress_grid.tsv", err);
        }
    }
    free(moment);
    if (st != BAL_OK)
        return st;
    FILE *f = bal_output_open(dir, "contacts.tsv", err);
    if (!f)
        return err->code;
    bal_output_contacts(s, f);
    if (bal_output_close(f, dir, "contacts.tsv", err))
        return err->code;
    f = bal_output_open(dir, "discs.tsv", err);
    if (!f)
        return err->code;
    bal_output_discs(s, f, 0);
    if (bal_output_close(f, dir, "discs.tsv", err))
        return err->code;
    f = bal_output_open(dir, "walls.tsv", err);
    if (!f)
        return err->code;
    bal_output_walls(s, f);
    return bal_output_close(f, dir, "walls.tsv", err);
}

static void json_string(FILE *f, const char *v)
{
    fputc('"', f);
    for (const unsigned char *c = (const unsigned char *)v; *c; c++) {
        if (*c == '"' || *c == '\\')
            fprintf(f, "\\%c", *c);
        else if (*c < 0x20)
            fprintf(f, "\\u%04x", *c);
        else
            fputc(*c, f);
    }
    fputc('"', f);
}

static void json_number(FILE *f, double v)
{
    if (isfinite(v))
        fprintf(f, "%.17g", v);
    else
        fputs("null", f);
}

enum bal_status bal_output_run_json(const struct bal_sim *s, const char *dir,
                                    const char *scene_path, int n_sets, char *const *sets,
                                    enum bal_status status, const char *message,
                                    struct bal_error *err)
{
    FILE *f = bal_output_open(dir, "run.json", err);
    if (!f)
        return err->code;
    fputs("{\n  \"version\": ", f);
    json_string(f, BAL_VERSION);
    fputs(",\n  \"build\": ", f);
    json_string(f, BAL_BUILD_FLAGS);
    fputs(",\n  \"scene\": ", f);
    json_string(f, scene_path);
    fputs(",\n  \"sets\": [", f);
    for (int k = 0; k < n_sets; k++) {
        if (k)
            fputs(", ", f);
        json_string(f, sets[k]);
    }
    fputs("],\n  \"status\": ", f);
    json_string(f, status == BAL_OK ? "ok" : bal_strerror(status));
    fputs(",\n  \"message\": ", f);
    json_string(f, message ? message : "");
    /* false: the run did not reach its end (an interrupted run keeps the
     * series.tsv written so far, and nothing else) */
    fprintf(f, ",\n  \"complete\": %s", status == BAL_OK ? "true" : "false");
    if (s) {
        /* The counters of bal_sim_info, read from the state (output.c sits
         * below the life cycle in sim.c, which writes series rows here). */
        fprintf(f, ",\n  \"steps\": %ld,\n  \"time\": ", s->step);
        json_number(f, s->time);
        fputs(",\n  \"dt\": ", f);
        json_number(f, s->dt);
        fputs(",\n  \"dt_estimate\": ", f);
        json_number(f, s->dt_estimate);
        fputs(",\n  \"dt_fraction\": ", f);
        json_number(f, s->dt / s->dt_estimate);
        fputs(",\n  \"wall_seconds\": ", f);
        json_number(f, s->wall_seconds);
        fprintf(f, ",\n  \"n_discs\": %d,\n  \"n_walls\": %d,\n  \"grid\": %s,\n"
                   "  \"rebuilds\": %ld,\n  \"candidates\": %ld,\n  \"particle_steps_per_s\": ",
                s->n, s->n_walls, s->use_grid ? "true" : "false", s->rebuilds, s->pp.n);
        json_number(f, s->wall_seconds > 0 ? (double)s->step * s->n / s->wall_seconds : 0);
        fputs(",\n  \"skin\": ", f);
        json_number(f, s->skin);
        fprintf(f, ",\n  \"gravity\": [%.17g, %.17g]", s->g[0], s->g[1]);
        fprintf(f, ",\n  \"threads\": %d", s->par.threads);
        fprintf(f, ",\n  \"timers\": {\"positions\": %.6g, \"neighbours\": %.6g, \"contacts\": %.6g, "
                   "\"walls\": %.6g, \"velocities\": %.6g}, \"reorders\": %ld",
                s->timers.positions, s->timers.neighbours, s->timers.contacts, s->timers.walls,
                s->timers.velocities, s->reorders);
        fputs(",\n  \"energy_kinetic\": ", f);
        json_number(f, bal_measure_kinetic(s));
        fputs(",\n  \"energy_elastic\": ", f);
        json_number(f, bal_measure_elastic(s));
        struct bal_energy en;
        bal_energy_report(s, &en);
        fprintf(f, ",\n  \"energy\": {\"from_step\": %ld", en.from_step);
        const struct { const char *name; double v; } terms[] = {
            {"kinetic0", en.kinetic0}, {"elastic0", en.elastic0}, {"kinetic", en.kinetic},
            {"elastic", en.elastic}, {"work_walls", en.work_walls},
            {"work_gravity", en.work_gravity}, {"dissipated_dashpot", en.dissipated_dashpot},
            {"dissipated_friction", en.dissipated_friction},
            {"dissipated_global", en.dissipated_global}, {"imbalance", en.imbalance},
            {"throughput", en.throughput}, {"relative_imbalance", en.relative}};
        for (size_t k = 0; k < sizeof terms / sizeof terms[0]; k++) {
            fprintf(f, ", \"%s\": ", terms[k].name);
            json_number(f, terms[k].v);
        }
        if (s->has_rolling) { /* a scene without rolling keeps the run.json it had */
            fputs(", \"dissipated_rolling\": ", f);
            json_number(f, en.dissipated_rolling);
        }
        fputs("}", f);
        fputs(",\n  \"unbalanced\": ", f);
        json_number(f, bal_measure_unbalanced(s));
        const struct bal_scene *sc = s->scene;
        fputs(",\n  \"stages\": [", f);
        for (int g = 0; g < sc->n_stages; g++) {
            fprintf(f, "%s\n    {\"name\": ", g ? "," : "");
            json_string(f, sc->stages[g].name);
            const struct bal_stage_def *st = &sc->stages[g];
            fprintf(f, ", \"cycles\": %ld, \"max_cycles\": %ld, \"stop_rule\": %s, \"stopped\": %s, "
                       "\"ke_over_ee\": ",
                    s->log[g].cycles, s->log[g].max_cycles,
                    (st->stop_ke > 0 || st->stop_stress > 0 || st->stop_servo > 0 ||
                     st->stop_unbalanced > 0) ? "true" : "false",
                    s->log[g].stopped ? "true" : "false");
            json_number(f, s->log[g].ke_over_ee);
            if (st->given & (1u << bal_scene_key_index(BAL_SEC_STAGE, "time")))
                fprintf(f, ", \"stage_time\": %.17g", st->time);
            fputs(", \"stress_change\": ", f);
            json_number(f, s->log[g].stress_change);
            /* The servo and unbalanced rules only where a stage has them: a
             * scene without keeps the run.json it had. */
            if (st->stop_servo > 0) {
                fprintf(f, ", \"stop_servo\": %.17g, \"servo_error\": ", st->stop_servo);
                json_number(f, s->log[g].servo_error);
            }
            if (st->stop_unbalanced > 0) {
                fprintf(f, ", \"stop_unbalanced\": %.17g, \"unbalanced\": ", st->stop_unbalanced);
                json_number(f, s->log[g].unbalanced);
            }
            fputs("}", f);
        }
        fputs("\n  ],\n  \"piles\": [", f);
        for (int p = 0; p < sc->n_piles; p++) {
            const struct bal_pile_def *pd = &sc->piles[p];
            const double s0 = pd->bottom == 1 ? pd->d * (1 + pd->c) : pd->d;
            const long rows = bal_specimen_pile_rows(pd);
            fprintf(f, "%s\n    {\"name\": ", p ? "," : "");
            json_string(f, pd->name);
            fprintf(f, ", \"L\": %ld, \"rows\": %ld, \"discs\": %ld, \"d\": %.17g, \"x0\": %.17g, "
                       "\"width\": %.17g",
                    pd->L, rows, bal_specimen_pile_count(pd), pd->d, pd->origin[0],
                    (double)(pd->L - 1) * s0 + pd->d);
            /* A polydisperse pile names its realisation: the spread and the
             * seed of its diameters, whether the scene or a --set gave them
             * (an equal-disc pile keeps the run.json it had). */
            if (pd->size_spread > 0)
                fprintf(f, ", \"size_spread\": %.17g, \"seed\": %lu", pd->size_spread, pd->seed);
            fputs("}", f);
        }
        fputs("\n  ]", f);
    }
    fputs("\n}\n", f);
    return bal_output_close(f, dir, "run.json", err);
}
