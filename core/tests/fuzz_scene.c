/*
 * fuzz_scene.c — libFuzzer target for the scene parser and what follows it.
 *
 * Built and run by `make test-fuzz` (clang -fsanitize=fuzzer,address,undefined).
 * One input is a scene file, optionally followed by a line "%%" and then
 * --set assignments, one a line:
 *
 *     [settings]
 *     ...
 *     %%
 *     settings.dt_fraction=0.2
 *     stage.run.cycles=5
 *
 * Each input goes through bal_scene_parse, every bal_scene_set (a failed one
 * must leave the scene usable, so the rest are still applied),
 * bal_scene_validate and, when the scene is valid and small, bal_sim_create,
 * bal_sim_run over the stages with their cycles capped, the probes and the
 * energy audit, then everything is freed.  Bad input must give an error
 * status with a message, never a crash, a hang, a leak or undefined
 * behaviour.
 *
 * The simulation is skipped when it would be too big for a fuzzing
 * iteration (memory or time), which is a limit of this harness, not of
 * ballast: more than FUZZ_MAX_DISCS discs (counted as bal_sim_create counts
 * them: [disc] sections, fill n, bal_specimen_pile_count), more than
 * FUZZ_MAX_DISCS_ALL_PAIRS with grid = off (every pair is a candidate).
 */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ballast.h"
#include "specimen.h"
#include "state.h"

#define FUZZ_MAX_DISCS 2000
#define FUZZ_MAX_DISCS_ALL_PAIRS 200
#define FUZZ_MAX_CYCLES 20      /* cycles per stage when the simulation runs */
#define FUZZ_MAX_SETS 16
#define FUZZ_MAX_DISCS_TWICE 100 /* run twice and compare when this small */

static long count_discs(const struct bal_scene *s)
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

/* A failed bal_scene_set must leave the scene as it was. */
struct snapshot {
    struct bal_scene head;
    void *arrays[7];
};

static void snapshot_take(struct snapshot *sn, const struct bal_scene *s)
{
    sn->head = *s;
    const void *src[7] = {s->materials, s->discs, s->walls, s->fills, s->piles, s->stages,
                          s->probes};
    const size_t bytes[7] = {
        (size_t)s->n_materials * sizeof *s->materials, (size_t)s->n_discs * sizeof *s->discs,
        (size_t)s->n_walls * sizeof *s->walls,         (size_t)s->n_fills * sizeof *s->fills,
        (size_t)s->n_piles * sizeof *s->piles,         (size_t)s->n_stages * sizeof *s->stages,
        (size_t)s->n_probes * sizeof *s->probes};
    for (int k = 0; k < 7; k++) {
        sn->arrays[k] = malloc(bytes[k] + 1);
        if (sn->arrays[k] && bytes[k])
            memcpy(sn->arrays[k], src[k], bytes[k]);
    }
}

static void snapshot_check_free(struct snapshot *sn, const struct bal_scene *s)
{
    const void *now[7] = {s->materials, s->discs, s->walls, s->fills, s->piles, s->stages,
                          s->probes};
    const size_t bytes[7] = {
        (size_t)s->n_materials * sizeof *s->materials, (size_t)s->n_discs * sizeof *s->discs,
        (size_t)s->n_walls * sizeof *s->walls,         (size_t)s->n_fills * sizeof *s->fills,
        (size_t)s->n_piles * sizeof *s->piles,         (size_t)s->n_stages * sizeof *s->stages,
        (size_t)s->n_probes * sizeof *s->probes};
    if (memcmp(&sn->head, s, sizeof *s) != 0)
        abort(); /* a failed --set changed the settings or the section counts */
    for (int k = 0; k < 7; k++) {
        if (sn->arrays[k] && bytes[k] && memcmp(sn->arrays[k], now[k], bytes[k]) != 0)
            abort(); /* a failed --set changed a section */
        free(sn->arrays[k]);
    }
}

/* Everything a run leaves that must be the same on a second run of the
 * same scene (same scene and seed = bitwise-identical outputs). */
struct outcome {
    enum bal_status create, run;
    long steps;
    double ek, ee, dt;
    struct bal_energy e;
};

#define SAME(x, y) (memcmp(&(x), &(y), sizeof(x)) == 0) /* bitwise, NaN too */

static int same_outcome(const struct outcome *a, const struct outcome *b)
{
    const struct bal_energy *p = &a->e, *q = &b->e;
    return a->create == b->create && a->run == b->run && a->steps == b->steps &&
           SAME(a->ek, b->ek) && SAME(a->ee, b->ee) && SAME(a->dt, b->dt) &&
           p->started == q->started && p->from_step == q->from_step &&
           SAME(p->kinetic, q->kinetic) && SAME(p->elastic, q->elastic) &&
           SAME(p->work_walls, q->work_walls) && SAME(p->work_gravity, q->work_gravity) &&
           SAME(p->dissipated_dashpot, q->dissipated_dashpot) &&
           SAME(p->dissipated_friction, q->dissipated_friction) &&
           SAME(p->dissipated_global, q->dissipated_global) && SAME(p->imbalance, q->imbalance);
}

static void simulate(struct bal_scene *sc, struct outcome *out)
{
    long n = count_discs(sc);
    if (n > FUZZ_MAX_DISCS)
        return;
    if (sc->settings.grid == BAL_GRID_OFF && n > FUZZ_MAX_DISCS_ALL_PAIRS)
        return;
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
        if (sim)
            abort(); /* a failed create must not hand out a simulation */
        if (!err.msg[0])
            abort(); /* every error carries a message */
        return;
    }
    FILE *series = fopen("/dev/null", "w");
    if (series)
        bal_output_series_header(sim, series);
    enum bal_status st = bal_sim_run(sim, series, NULL, &err);
    if (st != BAL_OK && !err.msg[0])
        abort();
    /* A couple of free cycles after the protocol, as the tests do. */
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
        struct bal_error ignored;
        (void)bal_output_series_row(sim, series, &ignored);
        fclose(series);
    }
    bal_sim_free(sim);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* A C string: the parser reads up to the first NUL, as it would from a
     * caller; bal_scene_load refuses NUL bytes itself. */
    char *text = malloc(size + 1);
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = '\0';

    /* Split off the --set lines after a line "%%". */
    char *sets = NULL;
    if (strncmp(text, "%%\n", 3) == 0) {
        text[0] = '\0';
        sets = text + 3;
    } else {
        char *sep = strstr(text, "\n%%\n");
        if (sep) {
            sep[1] = '\0';
            sets = sep + 4;
        }
    }

    struct bal_scene sc;
    struct bal_error err = {0};
    bal_scene_default(&sc);
    enum bal_status st = bal_scene_parse(&sc, text, "fuzz.scene", &err);
    if (st != BAL_OK && (st != BAL_EINVAL || !err.msg[0]) && st != BAL_ENOMEM)
        abort();
    if (st == BAL_OK) {
        int n_sets = 0;
        for (char *line = sets; line && *line && n_sets < FUZZ_MAX_SETS; n_sets++) {
            char *nl = strchr(line, '\n');
            if (nl)
                *nl = '\0';
            struct bal_error serr = {0};
            struct snapshot sn;
            snapshot_take(&sn, &sc);
            enum bal_status ss = bal_scene_set(&sc, line, &serr);
            if (ss != BAL_OK && !serr.msg[0])
                abort();
            if (ss != BAL_OK)
                snapshot_check_free(&sn, &sc);
            else
                for (int k = 0; k < 7; k++)
                    free(sn.arrays[k]);
            line = nl ? nl + 1 : NULL;
        }
        if (bal_scene_validate(&sc, &err) == BAL_OK) {
            /* Twice when small: the second run must repeat the first bit
             * for bit. */
            struct outcome a, b;
            memset(&a, 0, sizeof a);
            memset(&b, 0, sizeof b);
            simulate(&sc, &a);
            if (count_discs(&sc) <= FUZZ_MAX_DISCS_TWICE) {
                simulate(&sc, &b);
                if (!same_outcome(&a, &b))
                    abort(); /* not deterministic */
            }
        } else if (!err.msg[0]) {
            abort();
        }
    }
    bal_scene_free(&sc);
    free(text);
    return 0;
}
