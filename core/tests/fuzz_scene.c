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
 * behaviour; the invariants of fuzz_common.h hold too (a refusal names its
 * line, key or disc; a run that returns BAL_OK reports only finite numbers;
 * two runs agree bit for bit).  fuzz_extremes.c feeds the same checks with
 * scenes of extreme numbers; this target replays the regression scenes
 * (core/tests/fuzz/regress/) and the scenes it finds (fuzz/found/).
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

#include "fuzz_common.h"

#define FUZZ_MAX_SETS 16

/* A failed bal_scene_set must leave the scene as it was. */
struct snapshot {
    struct bal_scene head;
    void *arrays[9];
};

static void snapshot_take(struct snapshot *sn, const struct bal_scene *s)
{
    sn->head = *s;
    const void *src[9] = {s->materials, s->discs, s->walls,   s->fills,  s->piles,
                          s->grains,    s->imports, s->stages, s->probes};
    const size_t bytes[9] = {
        (size_t)s->n_materials * sizeof *s->materials, (size_t)s->n_discs * sizeof *s->discs,
        (size_t)s->n_walls * sizeof *s->walls,         (size_t)s->n_fills * sizeof *s->fills,
        (size_t)s->n_piles * sizeof *s->piles,         (size_t)s->n_grains * sizeof *s->grains,
        (size_t)s->n_imports * sizeof *s->imports,     (size_t)s->n_stages * sizeof *s->stages,
        (size_t)s->n_probes * sizeof *s->probes};
    for (int k = 0; k < 9; k++) {
        sn->arrays[k] = malloc(bytes[k] + 1);
        if (sn->arrays[k] && bytes[k])
            memcpy(sn->arrays[k], src[k], bytes[k]);
    }
}

static void snapshot_check_free(struct snapshot *sn, const struct bal_scene *s)
{
    const void *now[9] = {s->materials, s->discs, s->walls,   s->fills,  s->piles,
                          s->grains,    s->imports, s->stages, s->probes};
    const size_t bytes[9] = {
        (size_t)s->n_materials * sizeof *s->materials, (size_t)s->n_discs * sizeof *s->discs,
        (size_t)s->n_walls * sizeof *s->walls,         (size_t)s->n_fills * sizeof *s->fills,
        (size_t)s->n_piles * sizeof *s->piles,         (size_t)s->n_grains * sizeof *s->grains,
        (size_t)s->n_imports * sizeof *s->imports,     (size_t)s->n_stages * sizeof *s->stages,
        (size_t)s->n_probes * sizeof *s->probes};
    if (memcmp(&sn->head, s, sizeof *s) != 0)
        abort(); /* a failed --set changed the settings or the section counts */
    for (int k = 0; k < 9; k++) {
        if (sn->arrays[k] && bytes[k] && memcmp(sn->arrays[k], now[k], bytes[k]) != 0)
            abort(); /* a failed --set changed a section */
        free(sn->arrays[k]);
    }
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
    fuzz_count(FUZZ_N_INPUTS);
    enum bal_status st = bal_scene_parse(&sc, text, "fuzz.scene", &err);
    /* BAL_EIO: a data file an [import] names could not be read */
    if (st != BAL_OK && ((st != BAL_EINVAL && st != BAL_EIO) || !err.msg[0]) && st != BAL_ENOMEM)
        fuzz_fail("bal_scene_parse failed (%d) without a message", st);
    if (st != BAL_OK)
        fuzz_check_origin(&err, st, "bal_scene_parse", "fuzz.scene", text);
    if (st == BAL_OK) {
        fuzz_count(FUZZ_N_PARSED);
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
                fuzz_fail("bal_scene_set failed (%d) without a message", ss);
            if (ss != BAL_OK)
                snapshot_check_free(&sn, &sc);
            else
                for (int k = 0; k < 9; k++)
                    free(sn.arrays[k]);
            line = nl ? nl + 1 : NULL;
        }
        fuzz_validate_and_run(&sc, text);
    }
    bal_scene_free(&sc);
    free(text);
    return 0;
}
