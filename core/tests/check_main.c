/*
 * check_main.c — the single runner of the C unit tests, and the fixture
 * pool and helpers declared in check_main.h.
 *
 * Every suite is added to one SRunner; srunner_run_all honours Check's
 * CK_RUN_SUITE / CK_RUN_CASE (and CK_VERBOSITY, CK_FORK) environment
 * variables.  The exit status is non-zero when any test fails.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check_main.h"

/* ------------------------------------------------------------------ */
/* Fixture pool                                                        */
/* ------------------------------------------------------------------ */

/* Most fixtures one test holds at once (the convergence studies keep a
 * handful; the rest hold one or two). */
#define POOL_SIZE 16

static struct tfx pool[POOL_SIZE];

static struct tfx *take(void)
{
    for (int k = 0; k < POOL_SIZE; k++) {
        if (!pool[k].used) {
            memset(&pool[k], 0, sizeof pool[k]);
            pool[k].used = 1;
            bal_scene_default(&pool[k].sc);
            return &pool[k];
        }
    }
    ck_abort_msg("fixture pool exhausted (%d): release fixtures in loops", POOL_SIZE);
    return NULL;
}

void tfx_release(struct tfx *f)
{
    if (!f || !f->used)
        return;
    bal_sim_free(f->sim);
    f->sim = NULL;
    bal_scene_free(&f->sc);
    f->used = 0;
}

void tfx_teardown(void)
{
    for (int k = 0; k < POOL_SIZE; k++)
        tfx_release(&pool[k]);
}

struct tfx *tfx_parse(const char *text, const char *name)
{
    struct tfx *f = take();
    enum bal_status st = bal_scene_parse(&f->sc, text, name, &f->err);
    ck_assert_msg(st == BAL_OK, "scene %s does not parse: %s", name, f->err.msg);
    return f;
}

enum bal_status tfx_create(struct tfx *f)
{
    return bal_sim_create(&f->sim, &f->sc, &f->err);
}

struct tfx *tfx_new(const char *text, const char *name)
{
    struct tfx *f = tfx_parse(text, name);
    /* Unit tests place bodies in contact and pick steps on purpose: the
     * refusals of bal_sim_create are tested on their own (check_scene.c). */
    f->sc.settings.allow_overlap = 1;
    f->sc.settings.force_dt = 1;
    enum bal_status st = tfx_create(f);
    ck_assert_msg(st == BAL_OK, "scene %s: bal_sim_create failed: %s", name, f->err.msg);
    return f;
}

struct tfx *tfx_newf(const char *name, const char *fmt, ...)
{
    char text[T_TEXT_MAX];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    ck_assert_msg(n > 0 && n < (int)sizeof text, "scene text %s too long (%d)", name, n);
    return tfx_new(text, name);
}

/* ------------------------------------------------------------------ */
/* Helpers                                                             */
/* ------------------------------------------------------------------ */

void t_steps(struct tfx *f, long n)
{
    for (long k = 0; k < n; k++) {
        enum bal_status st = bal_sim_step(f->sim, &f->err);
        ck_assert_msg(st == BAL_OK, "step %ld failed: %s", k, f->err.msg);
    }
}

int t_slot(const struct tfx *f, const char *name)
{
    int id = bal_scene_find(&f->sc, BAL_SEC_DISC, name);
    ck_assert_msg(id >= 0, "no disc '%s'", name);
    return f->sim->slot[id];
}

int t_probe(const struct tfx *f, const char *name)
{
    for (int p = 0; p < f->sc.n_probes; p++)
        if (strcmp(f->sc.probes[p].name, name) == 0)
            return p;
    ck_abort_msg("no probe '%s'", name);
    return -1;
}

double t_probe_value(const struct tfx *f, const char *name)
{
    return bal_probes_value(f->sim, t_probe(f, name));
}

static void resolve(const struct tfx *f, const char *name, int *is_wall, int *index)
{
    int id = bal_scene_find(&f->sc, BAL_SEC_DISC, name);
    if (id >= 0) {
        *is_wall = 0;
        *index = f->sim->slot[id];
        return;
    }
    for (int k = 0; k < f->sim->n_walls; k++) {
        if (strcmp(f->sim->walls[k].name, name) == 0) {
            *is_wall = 1;
            *index = k;
            return;
        }
    }
    ck_abort_msg("no body '%s'", name);
}

long t_contact(const struct tfx *f, const char *a, const char *b, const struct bal_pairs **list)
{
    int aw = 0, ai = 0, bw = 0, bi = 0;
    resolve(f, a, &aw, &ai);
    resolve(f, b, &bw, &bi);
    long c = bal_pairs_find_contact(f->sim, aw, ai, bw, bi, list);
    ck_assert_msg(c >= 0, "no candidate for the contact %s–%s", a, b);
    return c;
}

int t_contains(const char *haystack, const char *needle)
{
    return strstr(haystack, needle) != NULL;
}

/* ------------------------------------------------------------------ */
/* Runner                                                              */
/* ------------------------------------------------------------------ */

int main(void)
{
    SRunner *sr = srunner_create(suite_scene());
    srunner_add_suite(sr, suite_contacts());
    srunner_add_suite(sr, suite_walls());
    srunner_add_suite(sr, suite_integrate());
    srunner_add_suite(sr, suite_sim());
    srunner_add_suite(sr, suite_timestep());
    srunner_add_suite(sr, suite_grid());
    srunner_add_suite(sr, suite_measure());
    srunner_add_suite(sr, suite_exact());
    srunner_add_suite(sr, suite_energy());
    srunner_add_suite(sr, suite_threads());
    srunner_add_suite(sr, suite_rolling());
    srunner_add_suite(sr, suite_specimen());
    srunner_add_suite(sr, suite_snapshots());
    srunner_run_all(sr, CK_ENV); /* CK_VERBOSITY, default normal */
    const int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
