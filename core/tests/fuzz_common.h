/*
 * fuzz_common.h — what both libFuzzer targets check once they hold a scene:
 * fuzz_scene.c (the fuzzer writes the scene text) and fuzz_extremes.c (the
 * fuzzer's bytes choose a well-formed scene of extreme numbers).  Included by
 * each target, which is one translation unit; the name keeps it out of the
 * Check binary (core/tests/check_*.c).
 *
 * Invariants.  Each abort()s when broken (libFuzzer records a crash and saves
 * the input), after a line "fuzz: invariant broken: ..." on stderr:
 *
 *   - every failure carries a message; a failed bal_sim_create hands out no
 *     simulation; a scene small enough to run twice gives bitwise the same
 *     outcome both times;
 *   - origin: a refusal by bal_scene_parse, bal_scene_validate or
 *     bal_sim_create starts with the file name and ':', then either a line
 *     number of the file (1 to its number of lines) or names the key or the
 *     disc it is about ("fuzz.scene: dt_fraction: ...", "... disc a ...").
 *     Refusals of the scene as a whole have no line, legitimately, and are
 *     let through: no [stage] section, no discs, more than 1e8 discs, discs
 *     spread over more than the largest number (the neighbour grid), and
 *     out of memory; so are --set errors (they name the --set);
 *   - finite: when bal_sim_run returns BAL_OK, every quantity the run reports
 *     is finite: each probe (bal_probes_value), bal_measure_kinetic,
 *     bal_measure_elastic, bal_measure_unbalanced, every field of
 *     bal_energy_report (relative may be +inf only when throughput is 0, as
 *     energy.c documents), and the time, dt, dt_estimate and dt_fraction of
 *     bal_sim_info (run.json writes them).
 *
 * BALLAST_FUZZ_SKIP (comma-separated) switches checks off, to hunt past a
 * known defect that is not fixed yet: "origin", "finite" (all of it),
 * "info" (the bal_sim_info part only), "same" (the determinism check);
 * BALLAST_FUZZ_KNOWN ('|'-separated) lets through only the broken
 * invariants whose text contains one of its parts ("time step inf|kinetic");
 * fuzz_extremes.c also reads "ratio".  BALLAST_FUZZ_STATS=1 prints at exit how
 * far the inputs got (parsed, valid, created, ran ok); BALLAST_FUZZ_VERBOSE=1
 * prints every refusal and failed run (to see where a generator's inputs end).
 */
#ifndef BALLAST_FUZZ_COMMON_H
#define BALLAST_FUZZ_COMMON_H

#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ballast.h"
#include "scene.h"
#include "specimen.h"
#include "state.h"

#define FUZZ_MAX_DISCS 2000
#define FUZZ_MAX_DISCS_ALL_PAIRS 200
#define FUZZ_MAX_CYCLES 20       /* cycles per stage when the simulation runs */
#define FUZZ_MAX_DISCS_TWICE 100 /* run twice and compare when this small */

/* ---- switches and counters ------------------------------------------- */

static int fuzz_skip(const char *what)
{
    static const char *skip;
    static int read;
    if (!read) {
        skip = getenv("BALLAST_FUZZ_SKIP");
        read = 1;
    }
    if (!skip)
        return 0;
    const size_t n = strlen(what);
    for (const char *p = skip; (p = strstr(p, what)) != NULL; p += n)
        if ((p == skip || p[-1] == ',') && (p[n] == '\0' || p[n] == ','))
            return 1;
    return 0;
}

enum { FUZZ_N_INPUTS, FUZZ_N_PARSED, FUZZ_N_VALID, FUZZ_N_SKIPPED, FUZZ_N_CREATED, FUZZ_N_RAN_OK,
       FUZZ_N_COUNTERS };
static long fuzz_counter[FUZZ_N_COUNTERS];

static void fuzz_print_stats(void)
{
    fprintf(stderr,
            "fuzz stats: %ld inputs, %ld parsed, %ld valid, %ld too big to run, %ld created, "
            "%ld ran ok\n",
            fuzz_counter[FUZZ_N_INPUTS], fuzz_counter[FUZZ_N_PARSED], fuzz_counter[FUZZ_N_VALID],
            fuzz_counter[FUZZ_N_SKIPPED], fuzz_counter[FUZZ_N_CREATED],
            fuzz_counter[FUZZ_N_RAN_OK]);
}

static void fuzz_count(int which)
{
    static int registered;
    if (!registered) {
        registered = 1;
        const char *st = getenv("BALLAST_FUZZ_STATS");
        if (st && *st && *st != '0')
            atexit(fuzz_print_stats);
    }
    fuzz_counter[which]++;
}

static void fuzz_verbose(const char *where, const struct bal_error *err)
{
    static int v = -1;
    if (v < 0) {
        const char *e = getenv("BALLAST_FUZZ_VERBOSE");
        v = e && *e && *e != '0';
    }
    if (v)
        fprintf(stderr, "fuzz: %s: %s\n", where, err->msg);
}

/* Is the failure `what` one of BALLAST_FUZZ_KNOWN ('|'-separated parts of
 * failure texts, to hunt past a known defect more narrowly than
 * BALLAST_FUZZ_SKIP)? */
static int fuzz_known(const char *what)
{
    const char *k = getenv("BALLAST_FUZZ_KNOWN");
    while (k && *k) {
        const size_t n = strcspn(k, "|");
        char part[256];
        snprintf(part, sizeof part, "%.*s", (int)n, k);
        if (n > 0 && strstr(what, part))
            return 1;
        k += n + (k[n] == '|');
    }
    return 0;
}

/* An invariant is broken: say which on stderr and abort (libFuzzer records a
 * crash), unless it is a known one (then the caller goes on). */
static void fuzz_fail(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static void fuzz_fail(const char *fmt, ...)
{
    char what[BAL_MSG_MAX + 256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    if (fuzz_known(what))
        return;
    fprintf(stderr, "fuzz: invariant broken: %s\n", what);
    abort();
}

/* ---- origin of a refusal ---------------------------------------------- */

/* Does p start with "KEY:" for a key of the scene format? */
static int fuzz_names_key(const char *p)
{
    const size_t n = strcspn(p, ": ");
    if (n == 0 || p[n] != ':')
        return 0;
    for (size_t i = 0; i < bal_scene_n_keys; i++)
        if (strlen(bal_scene_keys[i].name) == n && strncmp(bal_scene_keys[i].name, p, n) == 0)
            return 1;
    return 0;
}

static long fuzz_lines(const char *text)
{
    long n = 1;
    for (const char *c = text; *c; c++)
        n += *c == '\n';
    return n;
}

/* The refusal err (from `where`) of the scene `text`, read as file `path`,
 * must say where it comes from (see the header). */
static void fuzz_check_origin(const struct bal_error *err, enum bal_status st, const char *where,
                              const char *path, const char *text)
{
    fuzz_verbose(where, err);
    if (fuzz_skip("origin") || st == BAL_ENOMEM)
        return;
    static const char *const whole[] = {
        " no [stage] section", " no discs:", " discs; at most",
        " neighbour grid: the discs spread over more than the largest number", " --set "};
    const char *msg = err->msg;
    const size_t np = strlen(path);
    if (strncmp(msg, path, np) != 0 || msg[np] != ':') {
        fuzz_fail("%s: the message does not start with '%s:': %s", where, path, msg);
        return;
    }
    const char *p = msg + np + 1;
    if (*p >= '0' && *p <= '9') {
        char *end;
        const long line = strtol(p, &end, 10);
        if (*end != ':') {
            fuzz_fail("%s: a line number not followed by ':': %s", where, msg);
            return;
        }
        if (line > fuzz_lines(text)) {
            fuzz_fail("%s: line %ld, but the file has %ld: %s", where, line, fuzz_lines(text),
                      msg);
            return;
        }
        if (line >= 1)
            return;
        p = end + 1; /* line 0: it must name the key or the disc instead */
    }
    while (*p == ' ')
        p++;
    if (fuzz_names_key(p) || strstr(msg, "disc ") != NULL)
        return;
    for (size_t k = 0; k < sizeof whole / sizeof whole[0]; k++)
        if (strstr(msg, whole[k]))
            return;
    fuzz_fail("%s: the message names no line, key or disc: %s", where, msg);
}

/* ---- every reported quantity finite ------------------------------------- */

/* The k-th word of the probe key's list of quantities. */
static void fuzz_quantity_name(int k, char *buf, size_t size)
{
    snprintf(buf, size, "?");
    for (size_t i = 0; i < bal_scene_n_keys; i++) {
        const struct bal_key *key = &bal_scene_keys[i];
        if (key->section != BAL_SEC_PROBE || strcmp(key->name, "quantity") != 0)
            continue;
        const char *c = key->choices;
        for (int j = 0; j < k && c; j++) {
            c = strchr(c, ' ');
            if (c)
                c++;
        }
        if (c)
            snprintf(buf, size, "%.*s", (int)strcspn(c, " "), c);
    }
}

static void fuzz_check_finite(const struct bal_sim *sim, const struct bal_scene *sc)
{
    if (fuzz_skip("finite"))
        return;
    for (int p = 0; p < sc->n_probes; p++) {
        const double v = bal_probes_value(sim, p);
        if (!isfinite(v)) {
            char q[32];
            fuzz_quantity_name(sc->probes[p].kind, q, sizeof q);
            fuzz_fail("run ok, but probe %s (quantity %s) is %g", sc->probes[p].name, q, v);
        }
    }
    const struct {
        const char *name;
        double v;
    } m[] = {{"bal_measure_kinetic", bal_measure_kinetic(sim)},
             {"bal_measure_elastic", bal_measure_elastic(sim)},
             {"bal_measure_unbalanced", bal_measure_unbalanced(sim)}};
    for (size_t k = 0; k < sizeof m / sizeof m[0]; k++)
        if (!isfinite(m[k].v))
            fuzz_fail("run ok, but %s is %g", m[k].name, m[k].v);
    struct bal_energy e;
    bal_energy_report(sim, &e);
    const struct {
        const char *name;
        double v;
    } f[] = {{"kinetic0", e.kinetic0},
             {"elastic0", e.elastic0},
             {"kinetic", e.kinetic},
             {"elastic", e.elastic},
             {"work_walls", e.work_walls},
             {"work_gravity", e.work_gravity},
             {"dissipated_dashpot", e.dissipated_dashpot},
             {"dissipated_friction", e.dissipated_friction},
             {"dissipated_global", e.dissipated_global},
             {"imbalance", e.imbalance},
             {"throughput", e.throughput},
             {"relative", e.throughput == 0 && e.relative == INFINITY ? 0 : e.relative}};
    for (size_t k = 0; k < sizeof f / sizeof f[0]; k++)
        if (!isfinite(f[k].v))
            fuzz_fail("run ok, but the energy report's %s is %g", f[k].name, f[k].v);
    if (fuzz_skip("info"))
        return;
    struct bal_run_info info;
    bal_sim_info(sim, &info);
    const struct {
        const char *name;
        double v;
    } r[] = {{"time", info.time},
             {"dt", info.dt},
             {"dt_estimate", info.dt_estimate},
             {"dt_fraction", info.dt_fraction}};
    for (size_t k = 0; k < sizeof r / sizeof r[0]; k++)
        if (!isfinite(r[k].v))
            fuzz_fail("run ok, but bal_sim_info's %s is %g", r[k].name, r[k].v);
}

/* ---- one scene, created and run ------------------------------------------ */

static long fuzz_count_discs(const struct bal_scene *s)
{
    long n = s->n_discs;
    for (int f = 0; f < s->n_fills; f++) {
        n += s->fills[f].n;
        if (n > FUZZ_MAX_DISCS)
            return n;
    }
    for (int p = 0; p < s->n_piles; p++) {
        /* bal_specimen_pile_count loops over the rows: at most L of them. */
        n += bal_specimen_pile_count(&s->piles[p]);
        if (n > FUZZ_MAX_DISCS)
            return n;
    }
    return n;
}

/* Everything a run leaves that must be the same on a second run of the
 * same scene (same scene and seed = bitwise-identical outputs). */
struct fuzz_outcome {
    enum bal_status create, run;
    long steps;
    double ek, ee, dt;
    struct bal_energy e;
};

#define FUZZ_SAME(x, y) (memcmp(&(x), &(y), sizeof(x)) == 0) /* bitwise, NaN too */

static int fuzz_same_outcome(const struct fuzz_outcome *a, const struct fuzz_outcome *b)
{
    const struct bal_energy *p = &a->e, *q = &b->e;
    return a->create == b->create && a->run == b->run && a->steps == b->steps &&
           FUZZ_SAME(a->ek, b->ek) && FUZZ_SAME(a->ee, b->ee) && FUZZ_SAME(a->dt, b->dt) &&
           p->started == q->started && p->from_step == q->from_step &&
           FUZZ_SAME(p->kinetic, q->kinetic) && FUZZ_SAME(p->elastic, q->elastic) &&
           FUZZ_SAME(p->work_walls, q->work_walls) &&
           FUZZ_SAME(p->work_gravity, q->work_gravity) &&
           FUZZ_SAME(p->dissipated_dashpot, q->dissipated_dashpot) &&
           FUZZ_SAME(p->dissipated_friction, q->dissipated_friction) &&
           FUZZ_SAME(p->dissipated_global, q->dissipated_global) &&
           FUZZ_SAME(p->imbalance, q->imbalance);
}

/* The scene is valid; sc->path and text are the file it was read from. */
static void fuzz_simulate(struct bal_scene *sc, const char *text, struct fuzz_outcome *out)
{
    long n = fuzz_count_discs(sc);
    if (n > FUZZ_MAX_DISCS || (sc->settings.grid == BAL_GRID_OFF && n > FUZZ_MAX_DISCS_ALL_PAIRS)) {
        fuzz_count(FUZZ_N_SKIPPED);
        return;
    }
    /* Keep the run short: a few cycles per stage, the stop rules still
     * checked (check_every capped likewise), series rows rarely. */
    for (int g = 0; g < sc->n_stages; g++) {
        if (sc->stages[g].cycles > FUZZ_MAX_CYCLES)
            sc->stages[g].cycles = FUZZ_MAX_CYCLES;
        if (sc->stages[g].check_every > FUZZ_MAX_CYCLES)
            sc->stages[g].check_every = 1 + sc->stages[g].check_every % FUZZ_MAX_CYCLES;
    }
    struct bal_error err = {0};
    struct bal_sim *sim = NULL;
    if ((out->create = bal_sim_create(&sim, sc, &err)) != BAL_OK) {
        if (sim) {
            fuzz_fail("bal_sim_create failed (%d) but handed out a simulation", out->create);
            bal_sim_free(sim);
        }
        if (!err.msg[0])
            fuzz_fail("bal_sim_create failed (%d) without a message", out->create);
        fuzz_check_origin(&err, out->create, "bal_sim_create", sc->path, text);
        return;
    }
    fuzz_count(FUZZ_N_CREATED);
    FILE *series = fopen("/dev/null", "w");
    if (series)
        bal_output_series_header(sim, series);
    enum bal_status st = bal_sim_run(sim, series, NULL, &err);
    if (st != BAL_OK && !err.msg[0])
        fuzz_fail("bal_sim_run failed (%d) without a message", st);
    if (st != BAL_OK)
        fuzz_verbose("bal_sim_run", &err);
    if (st == BAL_OK) {
        fuzz_count(FUZZ_N_RAN_OK);
        fuzz_check_finite(sim, sc);
    }
    /* A couple of free cycles after the protocol, as the tests do (steps
     * check nothing: their quantities are not held to be finite). */
    for (int k = 0; st == BAL_OK && k < 3; k++)
        st = bal_sim_step(sim, &err);
    for (int p = 0; p < sc->n_probes; p++)
        (void)bal_probes_value(sim, p);
    (void)bal_measure_unbalanced(sim);
    bal_energy_report(sim, &out->e);
    struct bal_run_info info;
    bal_sim_info(sim, &info);
    out->run = st;
    out->steps = info.steps;
    out->dt = info.dt;
    out->ek = bal_measure_kinetic(sim);
    out->ee = bal_measure_elastic(sim);
    char name[2 * BAL_NAME_MAX];
    for (int i = 0; i < info.n_discs && i < 4; i++)
        bal_output_disc_name(sim, i, name, sizeof name);
    if (series) {
        /* after the free cycles: may refuse a value that is not finite, with a message */
        struct bal_error rerr = {0};
        if (bal_output_series_row(sim, series, &rerr) != BAL_OK && !rerr.msg[0])
            fuzz_fail("bal_output_series_row failed without a message");
        fclose(series);
    }
    bal_sim_free(sim);
}

/* A parsed scene (text: the file it was parsed from): validate, then create
 * and run it, twice when small (the second run must repeat the first bit for
 * bit). */
static void fuzz_validate_and_run(struct bal_scene *sc, const char *text)
{
    struct bal_error err = {0};
    const enum bal_status st = bal_scene_validate(sc, &err);
    if (st != BAL_OK) {
        if (!err.msg[0])
            fuzz_fail("bal_scene_validate failed (%d) without a message", st);
        fuzz_check_origin(&err, st, "bal_scene_validate", sc->path, text);
        return;
    }
    fuzz_count(FUZZ_N_VALID);
    struct fuzz_outcome a, b;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    fuzz_simulate(sc, text, &a);
    if (fuzz_count_discs(sc) <= FUZZ_MAX_DISCS_TWICE) {
        fuzz_simulate(sc, text, &b);
        if (!fuzz_skip("same") && !fuzz_same_outcome(&a, &b))
            fuzz_fail("two runs of the same scene differ");
    }
}

#endif
