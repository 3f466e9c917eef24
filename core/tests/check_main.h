/*
 * check_main.h — the suites of the C unit tests and the helpers they share.
 *
 * One Check suite per core module (check_<module>.c defines suite_<module>),
 * all run by the single runner in check_main.c.  Select with Check's own
 * environment filters, e.g. CK_RUN_SUITE=contacts CK_RUN_CASE=sign.
 *
 * Fixtures.  A test builds its scenes and simulations through tfx_*: every
 * one comes from a small pool that the checked teardown tfx_teardown()
 * empties, so a test that fails half-way (Check longjmps out of it when
 * CK_FORK=no, as under `make test-sanitize`) still frees all it made.
 *
 * Expected values in the tests come from closed forms derived by hand from
 * Cundall & Strack (1979) (C&S) — the derivation is written next to each
 * test — never from output of the code under test.
 */
#ifndef CHECK_MAIN_H
#define CHECK_MAIN_H

#include <check.h>

#include "ballast.h"
#include "build.h"
#include "energy.h"
#include "grid.h"
#include "integrate.h"
#include "measure.h"
#include "pair_loop.h"
#include "pairs.h"
#include "scene.h"
#include "specimen.h"
#include "state.h"
#include "threads.h"
#include "timestep.h"
#include "wall_loop.h"
#include "walls.h"

Suite *suite_scene(void);
Suite *suite_contacts(void);
Suite *suite_walls(void);
Suite *suite_integrate(void);
Suite *suite_sim(void);
Suite *suite_timestep(void);
Suite *suite_grid(void);
Suite *suite_measure(void);
Suite *suite_exact(void);
Suite *suite_energy(void);
Suite *suite_threads(void);
Suite *suite_rolling(void);
Suite *suite_specimen(void);
Suite *suite_snapshots(void);

/* Room for the scene texts the tests format. */
#define T_TEXT_MAX 8192

/* One scene and (optionally) the simulation built from it. */
struct tfx {
    struct bal_scene sc;
    struct bal_sim *sim;     /* NULL until tfx_create succeeds */
    struct bal_error err;
    int used;
};

/* A fresh scene parsed from `text` (named `name` in messages); asserts that
 * the text parses.  No simulation yet. */
struct tfx *tfx_parse(const char *text, const char *name);
/* tfx_parse, then bal_sim_create; asserts both succeed.  It sets
 * settings.allow_overlap and force_dt: unit tests start bodies in contact
 * and pick their steps on purpose (the refusals are tested on their own). */
struct tfx *tfx_new(const char *text, const char *name);
/* Same, with the text formatted like printf (at most T_TEXT_MAX chars). */
struct tfx *tfx_newf(const char *name, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
/* bal_sim_create on a parsed fixture; returns the status (no assertion). */
enum bal_status tfx_create(struct tfx *f);
/* Free one fixture now (it may be reused by the pool). */
void tfx_release(struct tfx *f);
/* Checked teardown: free every fixture still held.  Add it to every TCase
 * with tcase_add_checked_fixture(tc, NULL, tfx_teardown). */
void tfx_teardown(void);

/* n calls of bal_sim_step, asserting each succeeds. */
void t_steps(struct tfx *f, long n);
/* Array slot of the disc named `name` (asserts it exists). */
int t_slot(const struct tfx *f, const char *name);
/* Index of the probe named `name` (asserts it exists). */
int t_probe(const struct tfx *f, const char *name);
/* Value of the probe named `name`. */
double t_probe_value(const struct tfx *f, const char *name);
/* The candidate of the contact between bodies `a` and `b` (disc or wall
 * names); asserts it is in the candidate lists.  *list receives the list. */
long t_contact(const struct tfx *f, const char *a, const char *b,
               const struct bal_pairs **list);
/* Does `haystack` contain `needle`?  (For error-message assertions.) */
int t_contains(const char *haystack, const char *needle);

#endif /* CHECK_MAIN_H */
