/*
 * check_scene.c — suite "scene": scene parsing, defaults, --set overrides,
 * validation, and the error statuses the scene functions return
 * (BAL_EINVAL with "file:line: key: ..." messages, BAL_EIO).
 *
 * The bad scenes are a table: each row is a scene text (or a file under
 * scenes/bad/), the status expected and a substring the message must hold —
 * the file name, the line and the key ("bad:3: frction:").
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check_main.h"

/* Values read back from text are the doubles strtod gives for the same text,
 * so comparisons of parsed values are exact up to one rounding: 1e-15
 * relative is far below any wrong value a test would catch. */
#define PARSE_REL 1e-15
/* Degrees → radians and the unit vector of a wall: one product and a cos
 * or sin of an O(1) angle, a few ulps: 1e-15 absolute. */
#define ANGLE_ABS 1e-15

/* A valid scene used by several tests. */
static const char *const good_scene =
    "# a comment line\n"                      /* 1 */
    "[settings]\n"                            /* 2 */
    "dt_fraction = 0.0385   # trailing\n"     /* 3 */
    "gravity = 0.25 -9.81\n"                  /* 4 */
    "normal_law = power\n"                    /* 5 */
    "nu = 1.5\n"                              /* 6 */
    "delta0 = 0.0213\n"                       /* 7 */
    "grid = off\n"                            /* 8 */
    "\n"                                      /* 9 */
    "[material grain]\n"                      /* 10 */
    "kn = 3.7e4\n"                            /* 11 */
    "friction = 0.42\n"                       /* 12 */
    "density = 2.385\n"                       /* 13 */
    "[material steel]\n"                      /* 14 */
    "kn = 9.1e4\n"                            /* 15 */
    "ks = 6.3e4\n"                            /* 16 */
    "[disc a]\n"                              /* 17 */
    "x = 0.35 -0.42\n"                        /* 18 */
    "r = 0.61\n"                              /* 19 */
    "v = 0.27 0.11\n"                         /* 20 */
    "theta = 37.5\n"                          /* 21 */
    "omega = -1.9\n"                          /* 22 */
    "material = grain\n"                      /* 23 */
    "[wall floor]\n"                          /* 24 */
    "p = -1.5 -2.25\n"                        /* 25 */
    "angle = 23.5\n"                          /* 26 */
    "h1 = -1.25\n"                            /* 27 */
    "h2 = 2.75\n"                             /* 28 */
    "material = steel\n"                      /* 29 */
    "[stage load]\n"                          /* 30 */
    "cycles = 17\n"                           /* 31 */
    "move = floor 0.125 -0.0625 0.015\n"      /* 32 */
    "[stage hold]\n"                          /* 33 */
    "cycles = 5\n"                            /* 34 */
    "[probe fa]\n"                            /* 35 */
    "quantity = wall_f2\n"                    /* 36 */
    "a = floor\n";                            /* 37 */

START_TEST(scene_defaults)
{
    /* The defaults of the key table as documented in ballast.h. */
    struct bal_scene sc;
    bal_scene_default(&sc);
    ck_assert_double_eq(sc.settings.dt, 0.0);
    ck_assert_double_eq_tol(sc.settings.dt_fraction, 0.1, 0.1 * PARSE_REL);
    ck_assert_double_eq(sc.settings.alpha, 0.0);
    ck_assert_double_eq(sc.settings.beta, 0.0);
    ck_assert_double_eq(sc.settings.gravity[0], 0.0);
    ck_assert_double_eq(sc.settings.gravity[1], 0.0);
    ck_assert_int_eq(sc.settings.normal_law, BAL_NORMAL_INCREMENTAL);
    ck_assert_double_eq(sc.settings.nu, 1.0);
    ck_assert_double_eq(sc.settings.delta0, 1.0);
    ck_assert_int_eq(sc.settings.grid, BAL_GRID_AUTO);
    ck_assert_double_eq(sc.settings.skin, 0.0);
    ck_assert_int_eq(sc.settings.output_every, 1);
    ck_assert_int_eq(sc.n_discs + sc.n_walls + sc.n_materials + sc.n_stages, 0);
    bal_scene_free(&sc);
}
END_TEST

/* Every default written in the key table is a value the parser accepts for
 * its own key (scene.c's apply_defaults ignores failures and relies on this
 * test to catch a bad table entry). */
START_TEST(scene_every_default_parses)
{
    int checked = 0;
    for (int k = 0; k < BAL_SEC_COUNT; k++) {
        for (int i = 0;; i++) {
            const struct bal_key *key = bal_scene_key_at((enum bal_section_kind)k, i);
            if (!key)
                break;
            if (!key->def || !*key->def)
                continue; /* required, or empty by default */
            char text[512];
            snprintf(text, sizeof text, "[%s%s]\n%s = %s\n", bal_scene_sections[k].name,
                     bal_scene_sections[k].named ? " sec" : "", key->name, key->def);
            struct bal_scene sc;
            struct bal_error err = {0};
            bal_scene_default(&sc);
            enum bal_status st = bal_scene_parse(&sc, text, "defaults", &err);
            bal_scene_free(&sc);
            ck_assert_msg(st == BAL_OK, "default of [%s] %s = '%s' refused: %s",
                          bal_scene_sections[k].name, key->name, key->def, err.msg);
            checked++;
        }
    }
    ck_assert_int_gt(checked, 20);
}
END_TEST

START_TEST(scene_parse_values)
{
    struct tfx *f = tfx_parse(good_scene, "good");
    const struct bal_scene *sc = &f->sc;
    ck_assert_int_eq(bal_scene_validate(sc, &f->err), BAL_OK);
    ck_assert_double_eq_tol(sc->settings.dt_fraction, 0.0385, 0.0385 * PARSE_REL);
    ck_assert_double_eq_tol(sc->settings.gravity[1], -9.81, 9.81 * PARSE_REL);
    ck_assert_int_eq(sc->settings.normal_law, BAL_NORMAL_POWER);
    ck_assert_int_eq(sc->settings.grid, BAL_GRID_OFF);
    ck_assert_int_eq(sc->n_materials, 2);
    ck_assert_double_eq(sc->materials[0].ks, -1.0); /* omitted: "= kn" marker */
    ck_assert_double_eq_tol(sc->materials[1].ks, 6.3e4, 6.3e4 * PARSE_REL);
    ck_assert_int_eq(sc->n_discs, 1);
    ck_assert_str_eq(sc->discs[0].name, "a");
    ck_assert_int_eq(sc->discs[0].line, 17);
    ck_assert_double_eq_tol(sc->discs[0].x[1], -0.42, 0.42 * PARSE_REL);
    ck_assert_double_eq_tol(sc->discs[0].theta, 37.5, 37.5 * PARSE_REL);
    ck_assert_str_eq(sc->discs[0].material, "grain");
    ck_assert_int_eq(sc->n_stages, 2);
    ck_assert_int_eq(sc->stages[0].cycles, 17);
    ck_assert_int_eq(sc->stages[0].n_moves, 1);
    ck_assert_str_eq(sc->stages[0].moves[0].wall, "floor");
    ck_assert_int_eq(sc->stages[0].moves[0].line, 32);
    ck_assert_double_eq_tol(sc->stages[0].moves[0].v[1], -0.0625, 0.0625 * PARSE_REL);
    ck_assert_double_eq_tol(sc->stages[0].moves[0].omega, 0.015, 0.015 * PARSE_REL);
    ck_assert_int_eq(sc->stages[0].moves[0].control, BAL_CONTROL_PRESCRIBED);
    ck_assert_int_eq(sc->n_probes, 1);
    ck_assert_int_eq(sc->probes[0].kind, BAL_PROBE_WALL_F2);
    ck_assert_str_eq(sc->probes[0].a, "floor");
}
END_TEST

/* Every wall controller's key names a controller, takes at most
 * BAL_CONTROL_VALUES_MAX numbers and BAL_CONTROL_WALLS_MAX other walls
 * after the wall's name (the parser's buffers), and stores its numbers
 * within struct bal_move_def; every controller has a key. */
START_TEST(scene_control_keys)
{
    int keys = 0;
    for (int i = 0;; i++) {
        const struct bal_key *key = bal_scene_key_at(BAL_SEC_STAGE, i);
        if (!key)
            break;
        if (key->type != BAL_KEY_CONTROL)
            continue;
        keys++;
        const int control = bal_scene_key_control(key->name);
        ck_assert_msg(control >= 0, "stage key %s names no controller", key->name);
        ck_assert_str_eq(bal_scene_key_for_control(control), key->name);
        ck_assert_msg(strncmp(key->choices, "WALL ", 5) == 0, "%s: form '%s'", key->name,
                      key->choices);
        size_t n = 0, walls = 0;
        for (const char *c = key->choices; (c = strchr(c, ' ')) != NULL; c++) {
            if (strncmp(c + 1, "WALL", 4) == 0)
                walls++;
            else
                n++;
        }
        ck_assert_msg(n >= 1 && n <= BAL_CONTROL_VALUES_MAX, "%s: %zu numbers", key->name, n);
        ck_assert_msg(walls <= BAL_CONTROL_WALLS_MAX, "%s: %zu walls", key->name, walls);
        ck_assert(key->offset + n * sizeof(double) <= sizeof(struct bal_move_def));
    }
    ck_assert_int_eq(keys, (int)bal_scene_n_controls);
}
END_TEST

/* Angles are degrees in the file, radians inside (ballast.h). */
START_TEST(scene_angles_are_degrees)
{
    struct tfx *f = tfx_new(good_scene, "good");
    const double deg = BAL_PI / 180;
    ck_assert_double_eq_tol(f->sim->walls[0].alpha, 23.5 * deg, ANGLE_ABS);
    ck_assert_double_eq_tol(f->sim->walls[0].e[0], cos(23.5 * deg), ANGLE_ABS);
    ck_assert_double_eq_tol(f->sim->walls[0].e[1], sin(23.5 * deg), ANGLE_ABS);
    ck_assert_double_eq_tol(f->sim->th[t_slot(f, "a")], 37.5 * deg, ANGLE_ABS);
}
END_TEST

START_TEST(scene_set_overrides)
{
    struct tfx *f = tfx_parse(good_scene, "good");
    ck_assert_int_eq(bal_scene_set(&f->sc, "settings.dt=0.00125", &f->err), BAL_OK);
    ck_assert_int_eq(bal_scene_set(&f->sc, "disc.a.r = 0.77", &f->err), BAL_OK);
    ck_assert_int_eq(bal_scene_set(&f->sc, "material.steel.friction=0.19", &f->err), BAL_OK);
    ck_assert_int_eq(bal_scene_set(&f->sc, "stage.load.cycles=23", &f->err), BAL_OK);
    /* An override may replace a key the file gave (no "given twice"). */
    ck_assert_int_eq(bal_scene_set(&f->sc, "disc.a.r=0.79", &f->err), BAL_OK);
    ck_assert_double_eq_tol(f->sc.settings.dt, 0.00125, 0.00125 * PARSE_REL);
    ck_assert_double_eq_tol(f->sc.discs[0].r, 0.79, 0.79 * PARSE_REL);
    ck_assert_double_eq_tol(f->sc.materials[1].friction, 0.19, 0.19 * PARSE_REL);
    ck_assert_int_eq(f->sc.stages[0].cycles, 23);
    ck_assert_int_eq(bal_scene_validate(&f->sc, &f->err), BAL_OK);
}
END_TEST

START_TEST(scene_load_file)
{
    struct tfx *f = tfx_parse("", "unused");
    ck_assert_int_eq(bal_scene_load(&f->sc, "scenes/minimal.scene", &f->err), BAL_OK);
    ck_assert_str_eq(f->sc.path, "scenes/minimal.scene");
    ck_assert_int_eq(f->sc.n_discs, 1);
    ck_assert_double_eq_tol(f->sc.discs[0].r, 0.75, 0.75 * PARSE_REL);
    ck_assert_int_eq(tfx_create(f), BAL_OK);
}
END_TEST

/* BAL_EIO: a file that does not exist; the message names it. */
START_TEST(scene_missing_file_is_eio)
{
    struct bal_scene sc;
    struct bal_error err = {0};
    bal_scene_default(&sc);
    enum bal_status st = bal_scene_load(&sc, "scenes/no_such_file.scene", &err);
    bal_scene_free(&sc);
    ck_assert_int_eq(st, BAL_EIO);
    ck_assert_int_eq(err.code, BAL_EIO);
    ck_assert_msg(t_contains(err.msg, "scenes/no_such_file.scene: cannot open"), "%s", err.msg);
    ck_assert_str_eq(bal_strerror(BAL_EIO), "input/output error");
}
END_TEST

/* Issue 29, item 9: a FIFO as the scene or as an [import] data file
 * blocked in fopen until a writer came (forever, for a run); /dev/zero as
 * the scene was read until memory ran out.  Each is refused at once as not
 * a regular file (a hang fails the test by Check's timeout). */
START_TEST(scene_fifo_and_devices_refused)
{
    char dir[] = "/tmp/ballast_fifo_XXXXXX", fifo[64], text[256];
    ck_assert_ptr_nonnull(mkdtemp(dir));
    snprintf(fifo, sizeof fifo, "%s/pipe", dir);
    ck_assert_int_eq(mkfifo(fifo, 0600), 0);
    static const char *const data_files[] = {"discs", "walls"};
    for (int k = 0; k < 2; k++)
        for (int dev = 0; dev < 2; dev++) {
            const char *path = dev ? "/dev/zero" : fifo;
            snprintf(text, sizeof text, "[material m]\nkn = 1e5\ndensity = 2\n[import p]\n%s = %s\n",
                     data_files[k], path);
            struct bal_scene sc;
            struct bal_error err = {0};
            bal_scene_default(&sc);
            const enum bal_status st = bal_scene_parse(&sc, text, "bad", &err);
            bal_scene_free(&sc);
            char expect[160];
            snprintf(expect, sizeof expect, "bad:5: %s: %s: not a regular file: %s", data_files[k],
                     path, dev ? "a character device" : "a FIFO (named pipe)");
            ck_assert_int_eq(st, BAL_EINVAL);
            ck_assert_msg(t_contains(err.msg, expect), "'%s' lacks '%s'", err.msg, expect);
        }
    for (int dev = 0; dev < 3; dev++) {
        const char *path = dev == 0 ? fifo : dev == 1 ? "/dev/zero" : dir;
        struct bal_scene sc;
        struct bal_error err = {0};
        bal_scene_default(&sc);
        const enum bal_status st = bal_scene_load(&sc, path, &err);
        bal_scene_free(&sc);
        char expect[160];
        snprintf(expect, sizeof expect, "%s: not a regular file: %s", path,
                 dev == 0 ? "a FIFO (named pipe)" : dev == 1 ? "a character device" : "a directory");
        ck_assert_int_eq(st, BAL_EINVAL);
        ck_assert_msg(t_contains(err.msg, expect), "'%s' lacks '%s'", err.msg, expect);
    }
    unlink(fifo);
    rmdir(dir);
}
END_TEST

/* Issue 29, item 9 (what else hangs): "name used twice" passed over every
 * section of its kind, so 100 000 [disc] sections took 54 s to parse, and
 * a million (45 MB, within the scene's size limit) an hour and a half.
 * With the names hashed they parse at once (the case's timeout is 30 s, for
 * sanitized builds); a name used twice is still found, at its line, after
 * the table has grown many times over. */
START_TEST(scene_many_sections_parse_at_once)
{
    enum { N = 100000 };
    const size_t size = (size_t)N * 64 + 256;
    char *text = malloc(size);
    ck_assert_ptr_nonnull(text);
    int n = snprintf(text, size, "[material m]\nkn = 1e5\ndensity = 2\n");
    for (int k = 0; k < N; k++)
        n += snprintf(text + n, size - (size_t)n, "[disc d%d]\nx = %d 0\nr = 1\nmaterial = m\n",
                      k, 3 * k);
    struct bal_scene sc;
    struct bal_error err = {0};
    bal_scene_default(&sc);
    ck_assert_int_eq(bal_scene_parse(&sc, text, "many", &err), BAL_OK);
    ck_assert_int_eq(sc.n_discs, N);
    ck_assert_int_eq(bal_scene_find(&sc, BAL_SEC_DISC, "d77777"), 77777);
    bal_scene_free(&sc);
    /* the same name again at the end; and a second text parsed into a scene
     * sees the sections of the first */
    snprintf(text + n, size - (size_t)n, "[disc d4321]\n");
    bal_scene_default(&sc);
    ck_assert_int_eq(bal_scene_parse(&sc, text, "many", &err), BAL_EINVAL);
    bal_scene_free(&sc);
    char expect[64];
    snprintf(expect, sizeof expect, "many:%d: [disc d4321]: name used twice", 3 + 4 * N + 1);
    ck_assert_msg(t_contains(err.msg, expect), "'%s' lacks '%s'", err.msg, expect);
    bal_scene_default(&sc);
    ck_assert_int_eq(bal_scene_parse(&sc, "[material m]\nkn = 1\n", "one", &err), BAL_OK);
    ck_assert_int_eq(bal_scene_parse(&sc, "[disc a]\n[material m]\n", "two", &err), BAL_EINVAL);
    bal_scene_free(&sc);
    ck_assert_msg(t_contains(err.msg, "two:2: [material m]: name used twice"), "%s", err.msg);
    free(text);
}
END_TEST

START_TEST(scene_strerror_names_every_status)
{
    const enum bal_status all[] = {BAL_OK, BAL_EINVAL, BAL_ENOMEM, BAL_EIO, BAL_EUNSTABLE,
                                   BAL_EINTR};
    for (size_t k = 0; k < sizeof all / sizeof all[0]; k++) {
        ck_assert_ptr_nonnull(bal_strerror(all[k]));
        ck_assert_str_ne(bal_strerror(all[k]), "unknown status");
    }
}
END_TEST

/* `ballast keys`: every key of the table is listed, under its section. */
START_TEST(scene_print_keys_lists_every_key)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&buf, &len);
    ck_assert_ptr_nonnull(out);
    bal_scene_print_keys(out);
    fclose(out);
    int missing = 0;
    char first_missing[64] = "";
    for (size_t i = 0; i < bal_scene_n_keys; i++) {
        char needle[80];
        snprintf(needle, sizeof needle, "| `%s` |", bal_scene_keys[i].name);
        if (!strstr(buf, needle) && !missing++)
            snprintf(first_missing, sizeof first_missing, "%s", bal_scene_keys[i].name);
    }
    int sections = 0;
    for (int k = 0; k < BAL_SEC_COUNT; k++) {
        char needle[64];
        snprintf(needle, sizeof needle, "`[%s", bal_scene_sections[k].name);
        sections += strstr(buf, needle) != NULL;
    }
    free(buf);
    ck_assert_msg(missing == 0, "%d keys missing from the key list, first '%s'", missing,
                  first_missing);
    ck_assert_int_eq(sections, BAL_SEC_COUNT);
}
END_TEST

/* The keys other keys make unused (`ballast info`): every rule names a key
 * of its section kind (bal_scene_print_unused skips one that does not;
 * harness/tests/test_unused_keys.py runs each rule). */
START_TEST(scene_unused_rules_name_keys)
{
    ck_assert_uint_gt(bal_scene_n_unused, 0);
    for (size_t r = 0; r < bal_scene_n_unused; r++) {
        const struct bal_unused_rule *u = &bal_scene_unused[r];
        ck_assert_msg(bal_scene_key_index(u->section, u->key) >= 0, "rule %zu: no key '%s' in [%s]", r,
                      u->key, bal_scene_sections[u->section].name);
        ck_assert_msg(u->holds != NULL, "rule %zu: no condition", r);
        ck_assert_ptr_nonnull(u->why);
    }
    /* Listed: a key given (in the file or by --set) that a rule holds for,
     * named as --set names it; not listed: a default, or a rule that does
     * not hold. */
    struct tfx *f = tfx_parse("[settings]\ndt = 0.01\ndt_fraction = 0.2\nnu = 1.5\n"
                              "[material m]\nkn = 1\ndensity = 1\n"
                              "[disc a]\nx = 0 0\nr = 1\nmaterial = m\n"
                              "[stage load]\ncycles = 3\ncheck_every = 7\n"
                              "[stage rest]\ncycles = 3\ncheck_every = 7\nstop_ke = 1\n",
                              "unused");
    ck_assert_int_eq(bal_scene_set(&f->sc, "settings.psi=1", &f->err), BAL_OK);
    char *buf = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&buf, &len);
    ck_assert_ptr_nonnull(out);
    bal_scene_print_unused(&f->sc, out);
    fclose(out);
    ck_assert_str_eq(buf, "unused         settings.dt_fraction (settings.dt > 0 sets the step)\n"
                          "unused         settings.nu (settings.normal_law = incremental: nu is the "
                          "power law's)\n"
                          "unused         settings.psi (settings.gamma_n = 0: no viscous normal "
                          "dashpot)\n"
                          "unused         stage.load.check_every (the stage has no stop rule: stop_ke, "
                          "stop_stress, stop_servo and stop_unbalanced are 0)\n");
    free(buf);
}
END_TEST

/* ------------------------------------------------------------------ */
/* Bad scenes                                                          */
/* ------------------------------------------------------------------ */

/* A valid head for bad scenes that need a material and a disc: 7 lines. */
#define HEAD "[material m]\nkn = 1e5\ndensity = 2.385\n[disc a]\nx = 0 0\nr = 0.5\nmaterial = m\n"
#define STAGE "[stage s]\ncycles = 3\n"

struct bad_scene {
    const char *what;
    const char *text;
    char refused_by;      /* 'p': bal_scene_parse, 'v': bal_scene_validate, 'c': bal_sim_create */
    const char *expect;   /* substring of the message */
};

/* Bad lines of the wall controllers: after HEAD (7 lines) and BOX (lines
 * 8-27), four walls around the disc; the stage header is line 28. */
#define BOX "[wall bottom]\np = -2 -1\nangle = 0\nh1 = 0\nh2 = 4\nmaterial = m\n" \
            "[wall top]\np = -2 1\nangle = 0\nh1 = 0\nh2 = 4\nmaterial = m\n" \
            "[wall left]\np = -1 -2\nangle = 90\nh1 = 0\nh2 = 4\nmaterial = m\n" \
            "[wall right]\np = 1 -2\nangle = 90\nh1 = 0\nh2 = 4\nmaterial = m\n"
#define BOX_STAGE HEAD BOX "[stage s]\ncycles = 3\n"
/* A [grains g] section (lines 4-12 after a material of three lines): its
 * region size, its diameters dmin d10 d50 d60 dmax (lines 8-12), as text,
 * and more keys from line 13. */
#define GRAINS(d, size, more) \
    "[material m]\nkn = 1e5\ndensity = 2\n[grains g]\nsize = " size "\nn = 40\n" \
    "material = m\n" d more
#define D5(a, b, c, e, f) "dmin = " a "\nd10 = " b "\nd50 = " c "\nd60 = " e "\ndmax = " f "\n"
/* An [import p] section (line 4) after a material, and its keys. */
#define IMPORT(keys) "[material m]\nkn = 1e5\ndensity = 2\n[import p]\n" keys "material = m\n"

static const struct bad_scene bad_scenes[] = {
    {"unknown key", "[material m]\nkn = 1e5\nfrction = 0.3\n", 'p',
     "bad:3: frction: unknown key in [material]"},
    {"malformed number", "[material m]\nkn = 1e5x\n", 'p',
     "bad:2: kn: expected one finite number, got '1e5x'"},
    {"NaN", HEAD "[disc b]\nx = 2 0\nr = nan\n", 'p',
     "bad:10: r: expected one finite number, got 'nan'"},
    {"inf", "[material m]\nkn = inf\n", 'p', "bad:2: kn: expected one finite number, got 'inf'"},
    {"overflowing number", HEAD "[disc b]\nx = 1e400 0\n", 'p',
     "bad:9: x: expected two finite numbers"},
    {"one number for two", HEAD "[disc b]\nv = 0.5\n", 'p',
     "bad:9: v: expected two finite numbers"},
    {"negative radius", HEAD "[disc b]\nx = 2 0\nr = -0.5\n", 'p',
     "bad:10: r: -0.5 is out of range"},
    {"negative density", "[material m]\nkn = 1e5\ndensity = -2.385\n", 'p',
     "bad:3: density: -2.385 is out of range"},
    {"not an integer", HEAD "[stage s]\ncycles = 2.5\n", 'p',
     "bad:9: cycles: expected an integer, got '2.5'"},
    {"psi without delta0", "[settings]\ngamma_n = 2.5\npsi = 0.5\n" "[material g]\nkn = 1e3\ndensity = 1\n"
     "[disc a]\nx = 0 0\nr = 1\nmaterial = g\n[stage s]\ncycles = 1\n", 'v', "bad:3: delta0: required with psi"},
    {"negative cycles", HEAD "[stage s]\ncycles = -1\n", 'p', "bad:9: cycles: -1 is out of range"},
    {"unknown word", "[settings]\nnormal_law = hertz\n", 'p',
     "bad:2: normal_law: expected one of {incremental power}, got 'hertz'"},
    {"empty value", "[material m]\nkn =\n", 'p', "bad:2: kn: expected a value after '='"},
    {"no equals sign", "[material m]\nkn 1e5\n", 'p', "bad:2: expected 'key = value'"},
    {"key given twice", "[material m]\nkn = 1e5\nkn = 2e5\n", 'p',
     "bad:3: kn: given twice in this section (first on line 2)"},
    {"key outside a section", "# header comment\nkn = 1e5\n[material m]\n", 'p',
     "bad:2: kn: a key outside any section"},
    {"unknown section", "[material m]\nkn = 1e5\n[grain g]\n", 'p',
     "bad:3: [grain]: unknown section"},
    {"unnamed named section", "[disc]\n", 'p', "bad:1: [disc]: a name is required"},
    {"named settings", "[settings fast]\n", 'p', "bad:1: [settings]: takes no name"},
    {"settings twice", "[settings]\ndt = 0.1\n[settings]\n", 'p',
     "bad:3: [settings]: given twice (first on line 1)"},
    {"bad name", "[disc a.b]\n", 'p', "bad:1: [disc]: expected a name of letters"},
    {"broken header", "[disc a\n", 'p', "bad:1: expected a section header"},
    {"duplicate name", HEAD "[disc a]\n", 'p', "bad:8: [disc a]: name used twice"},
    {"name too long", "[disc abcdefghijklmnopqrstuvwxyzabcdefghijklmnopqrstuv]\n", 'p',
     "bad:1: [disc]: expected a name of letters, digits, '_' or '-' (at most 47)"},
    {"move with two numbers", HEAD "[stage s]\ncycles = 3\nmove = w 0.1 0.2\n", 'p',
     "bad:10: move: expected 'WALL v1 v2 omega'"},
    {"missing required key",
     "[material m]\nkn = 1e5\ndensity = 2.385\n[disc a]\nx = 0 0\nmaterial = m\n" STAGE, 'v',
     "bad:4: [disc a]: r: required key is missing"},
    {"missing kn", "[material m]\ndensity = 2.385\n[disc a]\nx = 0 0\nr = 1\nmaterial = m\n" STAGE,
     'v', "bad:1: [material m]: kn: required key is missing"},
    {"wall with h2 < h1",
     HEAD "[wall w]\np = 0 -1\nangle = 30\nh1 = 1.5\nh2 = -0.5\nmaterial = m\n" STAGE, 'v',
     "bad:12: h2: expected h2 > h1"},
    {"wall with h2 = h1",
     HEAD "[wall w]\np = 0 -1\nangle = 30\nh1 = 0.75\nh2 = 0.75\nmaterial = m\n" STAGE, 'v',
     "bad:12: h2: expected h2 > h1"},
    {"probe naming a missing body",
     HEAD STAGE "[probe p]\nquantity = disc_x\na = ghost\n", 'v',
     "bad:12: a: no disc or wall named 'ghost'"},
    {"contact probe naming a missing body",
     HEAD STAGE "[probe p]\nquantity = contact_fn\na = a\nb = ghost\n", 'v',
     "bad:13: b: no disc or wall named 'ghost'"},
    {"wall probe on a disc", HEAD STAGE "[probe p]\nquantity = wall_f1\na = a\n", 'v',
     "bad:12: a: 'a' is a disc; this quantity needs a wall"},
    {"contact probe of a body with itself",
     HEAD STAGE "[probe p]\nquantity = contact_fs\na = a\nb = a\n", 'v',
     "bad:13: b: a body cannot touch itself"},
    {"second body on a disc probe", HEAD STAGE "[probe p]\nquantity = disc_vx\na = a\nb = a\n",
     'v', "bad:13: b: only contact probes and wall_gap take a second body"},
    {"move naming a missing wall", HEAD "[stage s]\ncycles = 3\nmove = roof 0 -0.1 0\n", 'v',
     "bad:10: move: no wall named 'roof'"},
    {"no stages", HEAD, 'v', "bad: no [stage] section"},
    {"no discs", "[material m]\nkn = 1e5\n" STAGE, 'v', "bad: no discs"},
    {"material without density used by a disc",
     "[material m]\nkn = 1e5\n[disc a]\nx = 0 0\nr = 0.5\nmaterial = m\n" STAGE, 'v',
     "bad:6: material: material 'm' has no density > 0"},
    {"disc naming a missing material", HEAD "[disc b]\nx = 2 0\nr = 0.5\nmaterial = sand\n" STAGE,
     'v', "bad:11: material: no [material sand] in the scene"},
    {"zero shear stiffness", "[material m]\nkn = 1e5\nks = 0\ndensity = 2\n"
                             "[disc a]\nx = 0 0\nr = 1\nmaterial = m\n" STAGE,
     'v', "bad:3: ks: expected ks >= 1e-150"},
    {"power law nu without delta0", "[settings]\nnormal_law = power\nnu = 1.5\n" HEAD STAGE, 'v',
     "bad:3: delta0: required with normal_law = power and nu != 1"},
    {"fill with rmax < rmin",
     "[material m]\nkn = 1e5\ndensity = 2\n[fill f]\nn = 4\ncolumns = 2\nrmin = 0.5\n"
     "rmax = 0.25\nmaterial = m\n" STAGE,
     'v', "bad:8: rmax: expected rmax >= rmin"},
    {"stage without cycles", HEAD "[stage s]\nstop_ke = 1e-6\n", 'v',
     "bad:8: [stage s]: cycles: required key is missing"},
    {"discs overlapping at the start",
     "[material m]\nkn = 1e5\ndensity = 2\n[disc a]\nx = 0 0\nr = 0.5\nmaterial = m\n"
     "[disc b]\nx = 0.9 0\nr = 0.5\nmaterial = m\n" STAGE, 'c',
     "bad:5: x: disc a: overlaps disc b by 0.1 (0.2 of the smaller radius) at the start"},
    {"disc overlapping a wall at the start",
     "[material m]\nkn = 1e5\ndensity = 2\n[disc a]\nx = 0 0.25\nr = 0.5\nmaterial = m\n"
     "[wall floor]\np = -1 0\nangle = 0\nh1 = 0\nh2 = 2\nmaterial = m\n" STAGE, 'c',
     "bad:5: x: disc a: overlaps wall floor by 0.25"},
    /* Issue 18: errors about what the core derives from a disc name the
     * disc and the key that made it, not a time step the user never set. */
    {"overlap of generated discs names the generator",
     "[material m]\nkn = 1e5\ndensity = 2\n[disc a]\nx = 0.5 0.5\nr = 0.5\nmaterial = m\n"
     "fixed = 1\n[fill f]\nn = 2\ncolumns = 2\norigin = 0.25 0\nrmin = 0.5\nrmax = 0.5\n"
     "material = m\n" STAGE, 'c', "bad:12: origin: disc f.0 of [fill f]: overlaps disc a by 0.75"},
    {"held disc overlapped by a free one names the free one",
     "[material m]\nkn = 1e5\ndensity = 2\n[disc a]\nx = 0 0\nr = 0.5\nmaterial = m\nfixed = 1\n"
     "[disc b]\nx = 0.9 0\nr = 0.5\nmaterial = m\n" STAGE, 'c',
     "bad:10: x: disc b: overlaps disc a by 0.1"},
    {"mass underflows to zero",
     "[material m]\nkn = 1e5\ndensity = 1\n[disc a]\nx = 0 0\nr = 1e-170\nmaterial = m\n" STAGE,
     'c', "bad:6: r: disc a: its mass, density x pi r^2, is not a positive finite number"},
    {"mass overflows",
     "[material m]\nkn = 1e5\ndensity = 1e300\n[disc a]\nx = 0 0\nr = 1e10\nmaterial = m\n" STAGE,
     'c', "bad:6: r: disc a: its mass, density x pi r^2, is not a positive finite number"},
    {"moment of inertia underflows",
     "[material m]\nkn = 1e5\ndensity = 1e300\n[disc a]\nx = 0 0\nr = 1e-160\nmaterial = m\n"
     STAGE, 'c', "bad:6: r: disc a: its moment of inertia m r^2/2 is not a positive finite number"},
    {"mass of a generated disc underflows",
     "[material m]\nkn = 1e5\ndensity = 1\n[fill f]\nn = 3\ncolumns = 3\nrmin = 1e-170\n"
     "rmax = 1e-170\nmaterial = m\n" STAGE, 'c', "bad:7: rmin: disc f.0 of [fill f]: its mass"},
    {"kinetic energy overflows",
     "[material m]\nkn = 1e5\ndensity = 1\n[disc a]\nx = 0 0\nr = 1\nv = 1e300 0\n"
     "material = m\n" STAGE, 'c', "bad:7: v: disc a: its kinetic energy m |v|^2/2"},
    {"kinetic energies overflow only in their sum",
     "[material m]\nkn = 1e5\ndensity = 1\n[disc a]\nx = 0 0\nr = 1\nv = 1e154 0\n"
     "material = m\n[disc b]\nx = 5 0\nr = 1\nv = -1e154 0\nmaterial = m\n" STAGE, 'c',
     "bad:12: v: disc b: its kinetic energy m |v|^2/2 (or the scene's total) overflows"},
    {"rotational energy overflows",
     "[material m]\nkn = 1e5\ndensity = 1\n[disc a]\nx = 0 0\nr = 1\nomega = 1e200\n"
     "material = m\n" STAGE, 'c', "bad:7: omega: disc a: its rotational energy"},
    {"gravity potential overflows",
     "[settings]\ngravity = 0 -1e300\n[material m]\nkn = 1e5\ndensity = 1\n[disc a]\n"
     "x = 0 1e300\nr = 1\nmaterial = m\n" STAGE, 'c',
     "bad:7: x: disc a: its weight m g or its gravity potential m g.x"},
    {"stiffness too small for the mass",
     "[material m]\nkn = 1e-150\ndensity = 1e300\n[disc a]\nx = 0 0\nr = 1\nmaterial = m\n"
     "[disc b]\nx = 2 0\nr = 1\nmaterial = m\n" STAGE, 'c',
     "bad:2: kn: [material m]: the time step inf or its estimate inf (for disc a)"},
    {"stiffness below the product's range", "[material m]\nkn = 1e-300\n", 'p',
     "bad:2: kn: 1e-300 is out of range: expected 1e-150 <= value"},
    {"shear stiffness below the product's range", "[material m]\nkn = 1\nks = 1e-200\n", 'v',
     "bad:3: ks: expected ks >= 1e-150"},
    {"a number that underflows to zero", "[material m]\nkn = 1\ndensity = 1e-400\n", 'p',
     "bad:3: density: expected one finite number, got '1e-400'"},
    {"a subnormal density is a number, but no mass",
     "[material m]\nkn = 1e5\ndensity = 1e-310\n[disc a]\nx = 0 0\nr = 1e-10\nmaterial = m\n"
     STAGE, 'c', "bad:6: r: disc a: its mass, density x pi r^2, is not a positive finite number"},
    {"global damping that reverses the velocity",
     "[settings]\ndt = 1e-3\nalpha = 2000\n" HEAD STAGE, 'c',
     "bad:3: alpha: global damping alpha = 2000 with the time step 0.001 gives alpha dt = 2; "
     "expected alpha dt < 2"},
    {"a forced step beyond any ratio to the estimate",
     "[settings]\ndt = 1.7976931348623157e308\nforce_dt = 1\n" HEAD STAGE, 'c',
     "bad:2: dt: the time step 1.79769e+308 is beyond"},
    {"explicit time step above the estimate",
     "[settings]\ndt = 1\n[material m]\nkn = 1e5\ndensity = 2\n"
     "[disc a]\nx = 0 0\nr = 0.5\nmaterial = m\n" STAGE, 'c',
     "bad:2: dt: the time step 1 is at or above the stability estimate"},
    {"time-step fraction 1", "[settings]\ndt_fraction = 1\n" HEAD STAGE, 'c',
     "bad:2: dt_fraction: the time step"},
    {"fill box without wall material",
     "[material m]\nkn = 1e5\ndensity = 2\n[fill f]\nn = 4\ncolumns = 2\nrmin = 0.5\n"
     "rmax = 0.5\nmaterial = m\nbox = 1\n" STAGE,
     'v', "bad:4: wall_material: required with box = 1"},
    /* Issue 21: the wall controllers' lines and the servo stop rules. */
    {"servo without its span walls", BOX_STAGE "servo = top 1e3 0.5 0\n", 'p',
     "bad:34: servo: expected 'WALL sigma gain vmax WALL_A WALL_B' with three finite numbers "
     "and two wall names, got 'top 1e3 0.5 0'"},
    {"servo with a number for a wall (a name of digits)", BOX_STAGE
     "servo = top 1e3 0.5 0 left 7\n", 'v', "bad:34: servo: no wall named '7'"},
    {"servo with a wall for a number", BOX_STAGE "servo = top 1e3 left 0 right bottom\n", 'p',
     "bad:34: servo: expected 'WALL sigma gain vmax WALL_A WALL_B'"},
    {"servo with a bad wall name", BOX_STAGE "servo = top 1e3 0.5 0 left a.b\n", 'p',
     "bad:34: servo: expected 'WALL sigma gain vmax WALL_A WALL_B'"},
    {"strain_rate without its wall", BOX_STAGE "strain_rate = top 0.01\n", 'p',
     "bad:34: strain_rate: expected 'WALL rate WALL_TO' with one finite number and one wall "
     "name, got 'top 0.01'"},
    {"a wall driven twice", BOX_STAGE "move = top 0 -1 0\nservo = top 1e3 0.5 0 left right\n",
     'p', "bad:35: servo: wall 'top' is driven twice in this stage"},
    {"servo naming a missing span wall", BOX_STAGE "servo = top 1e3 0.5 0 left ghost\n", 'v',
     "bad:34: servo: no wall named 'ghost'"},
    {"servo spanning a disc", BOX_STAGE "servo = top 1e3 0.5 0 a right\n", 'v',
     "bad:34: servo: no wall named 'a'"},
    {"servo of a missing wall", BOX_STAGE "servo = lid 1e3 0.5 0 left right\n", 'v',
     "bad:34: servo: no wall named 'lid'"},
    {"servo with a gain of 2", BOX_STAGE "servo = top 1e3 2 0 left right\n", 'v',
     "bad:34: servo: the gain must be in (0, 2)"},
    {"servo with a gain of 0", BOX_STAGE "servo = top 1e3 0 0 left right\n", 'v',
     "bad:34: servo: the gain must be in (0, 2)"},
    {"servo with a tensile target", BOX_STAGE "servo = top -1e3 0.5 0 left right\n", 'v',
     "bad:34: servo: the target stress sigma must be > 0, got -1000"},
    {"servo with a negative cap", BOX_STAGE "servo = top 1e3 0.5 -1 left right\n", 'v',
     "bad:34: servo: the speed cap vmax must be >= 0"},
    {"servo spanning itself", BOX_STAGE "servo = top 1e3 0.5 0 top bottom\n", 'v',
     "bad:34: servo: the span is the distance between two other walls"},
    {"servo spanning one wall twice", BOX_STAGE "servo = top 1e3 0.5 0 left left\n", 'v',
     "bad:34: servo: the span is the distance between two other walls"},
    {"strain_rate towards itself", BOX_STAGE "strain_rate = top 0.01 top\n", 'v',
     "bad:34: strain_rate: wall 'top' cannot move towards itself"},
    {"strain_rate towards a missing wall", BOX_STAGE "strain_rate = top 0.01 floor\n", 'v',
     "bad:34: strain_rate: no wall named 'floor'"},
    {"stop_servo without a servo", BOX_STAGE "stop_servo = 0.01\nmove = top 0 -1 0\n", 'v',
     "bad:34: stop_servo: no wall of this stage has a servo"},
    {"strain rate of a whole gap per step",
     "[settings]\ndt = 1e-3\n" BOX_STAGE "strain_rate = top 1000 bottom\n", 'c',
     "bad:36: strain_rate: rate 1000 with the time step 0.001 gives rate dt = 1; expected "
     "rate dt < 1"},
    {"wall_gap without its second wall", BOX_STAGE "[probe g]\nquantity = wall_gap\na = top\n",
     'v', "bad:34: b: wall_gap needs a second wall in 'b'"},
    {"wall_gap to a disc", BOX_STAGE "[probe g]\nquantity = wall_gap\na = top\nb = a\n", 'v',
     "bad:37: b: no wall named 'a'"},
    {"wall_gap of a wall to itself", BOX_STAGE "[probe g]\nquantity = wall_gap\na = top\nb = top\n",
     'v', "bad:37: b: the gap of a wall to itself is 0"},
    {"wall_stress of a disc", BOX_STAGE "[probe g]\nquantity = wall_stress\na = a\n", 'v',
     "bad:36: a: 'a' is a disc; this quantity needs a wall"},
    /* Issue 21: the [grains] generator and [import] (data files under
     * scenes/import/, named relative to the directory of the scene: "bad"
     * has none, so the tests' own). */
    {"grains with d50 < d10", GRAINS(D5("1", "2", "1.5", "3", "4"), "4 4", "") STAGE, 'v',
     "bad:10: d50: expected dmin <= d10 <= d50 <= d60 <= dmax (the share finer by area rises "
     "with d), got d50 = 1.5 < d10 = 2"},
    {"grains with dmax < d60", GRAINS(D5("1", "2", "2.5", "3", "2.9"), "4 4", "") STAGE, 'v',
     "bad:12: dmax: expected dmin <= d10"},
    {"grains region narrower than dmax", GRAINS(D5("1", "2", "2.5", "3", "4"), "3.5 40", "") STAGE, 'v',
     "bad:5: size: the region 3.5 x 40 must be at least dmax = 4 wide and high"},
    {"grains box without wall material", GRAINS(D5("1", "2", "2.5", "3", "4"), "40 40", "box = 1\n") STAGE, 'v',
     "bad:4: wall_material: required with box = 1"},
    {"grains box wall named like a wall",
     GRAINS(D5("1", "2", "2.5", "3", "4"), "40 40", "box = 1\nwall_material = m\n")
     "[wall g_top]\np = 0 0\nangle = 0\nh1 = 0\nh2 = 1\nmaterial = m\n" STAGE, 'v',
     "bad:4: [grains g]: makes a wall 'g_top', but a disc or wall has that name already"},
    {"grains with too many discs for the region", GRAINS(D5("1", "2", "2.5", "3", "4"), "8 8", "tries = 200\n")
     STAGE, 'c', "bad:6: n: [grains g]: placed "},
    {"grains overhang below -1", GRAINS(D5("1", "2", "2.5", "3", "4"), "40 40", "overhang = -2\n") STAGE, 'p',
     "bad:13: overhang: -2 is out of range"},
    {"import of a missing file", IMPORT("discs = scenes/import/nothing.tsv\n") STAGE, 'p',
     "bad:5: discs: scenes/import/nothing.tsv: cannot open: No such file or directory"},
    {"import of a directory", IMPORT("discs = scenes/import\n") STAGE, 'p',
     "bad:5: discs: scenes/import: not a regular file"},
    {"import of a bad number", IMPORT("discs = scenes/import/bad_row.tsv\n") STAGE, 'p',
     "bad:5: discs: scenes/import/bad_row.tsv:3: y: expected a finite number, got 'abc'"},
    {"import without a column", IMPORT("discs = scenes/import/no_y.tsv\n") STAGE, 'p',
     "bad:5: discs: scenes/import/no_y.tsv:1: no column 'y' in the header"},
    {"import of a short row", IMPORT("discs = scenes/import/short_row.tsv\n") STAGE, 'p',
     "bad:5: discs: scenes/import/short_row.tsv:2: expected 6 columns as in the header, got 5"},
    {"import of a negative radius", IMPORT("discs = scenes/import/negative_r.tsv\n") STAGE, 'p',
     "bad:5: discs: scenes/import/negative_r.tsv:2: r: expected a radius > 0, got -0.25"},
    {"import of no disc", IMPORT("discs = scenes/import/header_only.tsv\n") STAGE, 'p',
     "bad:5: discs: scenes/import/header_only.tsv:1: no disc rows after the header"},
    {"import without its discs", IMPORT("walls = scenes/import/walls.tsv\nwall_material = m\n")
     STAGE, 'v', "bad:4: [import p]: discs: required key is missing"},
    {"import of velocities the file lacks",
     IMPORT("discs = scenes/import/no_velocities.tsv\nvelocities = 1\n") STAGE, 'v',
     "bad:6: velocities: the discs file scenes/import/no_velocities.tsv has no columns vx, vy, "
     "omega"},
    {"import of walls without their material",
     IMPORT("discs = scenes/import/discs.tsv\nwalls = scenes/import/walls.tsv\n") STAGE, 'v',
     "bad:4: wall_material: required with walls"},
    {"import of a wall named twice",
     IMPORT("discs = scenes/import/discs.tsv\nwalls = scenes/import/walls_twice.tsv\n") STAGE,
     'p', "bad:6: walls: scenes/import/walls_twice.tsv:3: name: wall 'floor' is also on line 2"},
    {"import of walls without a column",
     IMPORT("discs = scenes/import/discs.tsv\nwalls = scenes/import/walls_no_by.tsv\n") STAGE,
     'p', "bad:6: walls: scenes/import/walls_no_by.tsv:1: no column 'by'"},
    {"import of a wall of no length",
     IMPORT("discs = scenes/import/discs.tsv\nwalls = scenes/import/walls_no_length.tsv\n") STAGE,
     'p', "bad:6: walls: scenes/import/walls_no_length.tsv:2: bx: the wall 'floor' has A = B"},
    {"import of a wall named like a wall",
     IMPORT("discs = scenes/import/discs.tsv\nwalls = scenes/import/walls.tsv\n"
            "wall_material = m\n")
     "[wall roof]\np = 0 0\nangle = 0\nh1 = 0\nh2 = 1\nmaterial = m\n" STAGE, 'v',
     "bad:4: [import p]: makes a wall 'roof', but a disc or wall has that name already"},
    {"import of discs onto a wall",
     IMPORT("discs = scenes/import/discs.tsv\n")
     "[wall w]\np = 0 0.4\nangle = 0\nh1 = 0\nh2 = 1\nmaterial = m\n" STAGE, 'c',
     "bad:5: discs: disc p.0 of [import p] (line 2 of scenes/import/discs.tsv): overlaps wall w"},
    /* Issue 29, item 11: discs piled at one point pass the neighbour
     * lists' limit (512 a disc) before the start overlaps are checked; the
     * overlap is still bad input, named like any other. */
    {"600 imported discs at one point", IMPORT("discs = scenes/import/pile600.tsv\n") STAGE, 'c',
     "bad:5: discs: disc p.0 of [import p] (line 2 of scenes/import/pile600.tsv): overlaps disc "
     "p.1 by 1 (2 of the smaller radius) at the start"},
    /* Item 12: a [grains] that cannot fit is refused from the area alone
     * (2 x 20 x 20 / (sqrt 3 x 1^2) = 461.9 discs of diameter 1 at most),
     * before any disc is drawn; an origin where the doubles are too far
     * apart is named, not n. */
    {"grains of more discs than the densest packing holds",
     "[material m]\nkn = 1e5\ndensity = 2\n[grains g]\nsize = 20 20\nn = 462\nmaterial = m\n"
     D5("1", "1.2", "1.5", "1.6", "2") STAGE, 'v',
     "bad:6: n: [grains g]: 462 discs of diameter >= dmin = 1 cannot lie apart in the region "
     "20 x 20: at most 461 can"},
    {"grains of as many discs as the densest packing holds: tried, and jammed",
     "[material m]\nkn = 1e5\ndensity = 2\n[grains g]\nsize = 20 20\nn = 461\nmaterial = m\n"
     "tries = 100\n" D5("1", "1.2", "1.5", "1.6", "2") STAGE, 'c', "bad:6: n: [grains g]: placed "},
    {"grains at an origin where doubles are far apart",
     GRAINS(D5("1", "2", "2.5", "3", "4"), "40 40", "origin = 1e300 1e300\n") STAGE, 'v',
     "bad:13: origin: [grains g]: the region reaches x = 1e+300, where doubles are "
     "1.487016908477783e+284 apart, more than 1e-06 of the smallest radius dmin/2 = 0.5"},
    {"grains region reaching where doubles are far apart",
     GRAINS(D5("1", "2", "2.5", "3", "4"), "1e10 40", "") STAGE, 'v',
     "bad:5: size: [grains g]: the region reaches x = 1e+10, where doubles are "
     "1.9073486328125e-06 apart"},
    /* Item 13: a generator's discs are probed as NAME.k, as messages name
     * them; what such a name can get wrong. */
    {"probe of a generator's disc past its count",
     GRAINS(D5("1", "2", "2.5", "3", "4"), "40 40", "") STAGE "[probe p]\nquantity = disc_y\n"
     "a = g.40\n", 'v', "bad:17: a: no disc named 'g.40': [grains g] makes 40 discs, g.0 to g.39"},
    {"probe of NAME.k with a leading zero",
     GRAINS(D5("1", "2", "2.5", "3", "4"), "40 40", "") STAGE "[probe p]\nquantity = disc_y\n"
     "a = g.01\n", 'p', "bad:17: a: expected the name of a disc or a wall"},
    {"probe of a disc two generators could have made",
     GRAINS(D5("1", "2", "2.5", "3", "4"), "40 40", "")
     "[fill g]\nn = 2\ncolumns = 2\norigin = 100 0\nrmin = 0.5\nrmax = 0.5\nmaterial = m\n" STAGE
     "[probe p]\nquantity = contact_fn\na = g.0\nb = g.1\n", 'v',
     "bad:24: a: 'g.0' could be a disc of [fill g] or of [grains g]; expected generators of "
     "different names"},
    {"probe of a generator that does not exist", HEAD STAGE "[probe p]\nquantity = disc_x\n"
     "a = ghost.0\n", 'v', "bad:12: a: no disc or wall named 'ghost.0'"},
    /* Item 15: a refused value and its bound print differently (%.6g
     * printed "2 is out of range: expected 0 <= value <= 2"). */
    {"rolling just past its bound", "[material m]\nkn = 1e5\nrolling = 2.0000001\n", 'p',
     "bad:3: rolling: 2.0000001 is out of range: expected 0 <= value <= 2"},
    {"cycles one beyond the largest count", HEAD "[stage s]\ncycles = 1000000000000001\n", 'p',
     "bad:9: cycles: 1000000000000001 is out of range: expected 0 <= value <= 1e+15"},
    {"fill with rmax a hair below rmin",
     "[material m]\nkn = 1e5\ndensity = 2\n[fill f]\nn = 4\ncolumns = 2\nrmin = 0.5\n"
     "rmax = 0.4999999\nmaterial = m\n" STAGE,
     'v', "bad:8: rmax: expected rmax >= rmin, got 0.4999999 < 0.5"},
    {"wall with h2 a hair below h1",
     HEAD "[wall w]\np = 0 -1\nangle = 30\nh1 = 1.0000001\nh2 = 1\nmaterial = m\n" STAGE, 'v',
     "bad:12: h2: expected h2 > h1 (a wall of positive length), got h1 = 1.0000001, h2 = 1"},
    {"grains with d50 a hair below d10", GRAINS(D5("1", "2", "1.9999999", "3", "4"), "40 40", "")
     STAGE, 'v', "bad:10: d50: expected dmin <= d10 <= d50 <= d60 <= dmax (the share finer by "
     "area rises with d), got d50 = 1.9999999 < d10 = 2"},
    {"hold of an unknown component", HEAD "hold = x z\n" STAGE, 'p',
     "bad:8: hold: expected 'none' or words of {x y rotation}, got 'z'"},
    {"hold of a moving component", HEAD "hold = y\nv = 0 0.5\n" STAGE, 'v',
     "bad:8: hold: a held component cannot have a velocity"},
    {"hold of a spinning disc", HEAD "omega = 2\nhold = rotation x\n" STAGE, 'v',
     "bad:9: hold: a held component cannot have a velocity"},
    {"a partly held disc overlapping another at the start",
     HEAD "hold = x rotation\n[disc b]\nx = 0.9 0\nr = 0.5\nmaterial = m\n" STAGE, 'c',
     "bad:5: x: disc a: overlaps disc b by 0.1"},
    {"stop_servo out of range", BOX_STAGE "stop_servo = -0.01\n", 'p',
     "bad:34: stop_servo: -0.01 is out of range"},
    {"stop_unbalanced out of range", BOX_STAGE "stop_unbalanced = -1\n", 'p',
     "bad:34: stop_unbalanced: -1 is out of range"},
    /* Issue 29, items 5 and 6 (walls.c, bal_walls_check_steps): a wall that
     * would move more than a tenth of the smallest radius (0.5) in a cycle,
     * and a servo whose span walls leave no room for a disc (below the
     * smallest radius 0.5).
     * The box's lid (y = 1, 4 long) is line 14, the stage's line 34; dt =
     * 1e-3 (the estimate is 6.1e-3). */
    {"a prescribed wall that passes the discs in one step",
     BOX_STAGE "move = top 0 -1e6 0\n[settings]\ndt = 1e-3\n", 'c',
     "bad:34: move: wall 'top' would move 1000 in one time step"},
    {"a prescribed turn whose far end passes the discs in one step",
     BOX_STAGE "move = top 0 0 30\n[settings]\ndt = 1e-3\n", 'c',
     "bad:34: move: wall 'top' would move 0.12 in one time step (|V| dt + |omega| dt reach"},
    {"a servo whose cap passes the discs in one step",
     BOX_STAGE "servo = top 100 0.5 1e6 left right\n[settings]\ndt = 1e-3\n", 'c',
     "bad:34: servo: wall 'top' would move 1000 in one time step (vmax dt"},
    {"a strain rate whose first step is beyond a tenth of a radius",
     BOX_STAGE "strain_rate = top 60 bottom\n[settings]\ndt = 1e-3\n", 'c',
     "bad:34: strain_rate: wall 'top' would move 0.12 in one time step"},
    {"a servo whose span walls are on one line",
     BOX "[wall s1]\np = 0 5\nangle = 90\nh1 = 0\nh2 = 1\nmaterial = m\n"
     "[wall s2]\np = 1e-16 5\nangle = 90\nh1 = 0\nh2 = 1\nmaterial = m\n" HEAD
     "[stage s]\ncycles = 3\nservo = top 100 0.5 0 s1 s2\n", 'c',
     "bad:46: servo: wall 'top': its span gap(s1, s2) = "},
    {"a servo whose span walls are one wall",
     BOX "[wall s1]\np = 0 5\nangle = 90\nh1 = 0\nh2 = 1\nmaterial = m\n"
     "[wall s2]\np = 0 5\nangle = 90\nh1 = 0\nh2 = 1\nmaterial = m\n" HEAD
     "[stage s]\ncycles = 3\nservo = top 100 0.5 0 s1 s2\n", 'c',
     "bad:46: servo: wall 'top': its span gap(s1, s2) = 0 is below the smallest disc radius 0.5"},
};

/* What the refusals let through: touching bodies, two held discs that
 * overlap (MLH's bumpy bottoms with c < 0), and overlaps or steps the
 * scene allows or forces. */
START_TEST(scene_allowed_overlaps_and_forced_steps)
{
    static const char *const good[] = {
        "[material m]\nkn = 1e5\ndensity = 2\n[disc a]\nx = 0 0\nr = 0.5\nmaterial = m\n"
        "[disc b]\nx = 1 0\nr = 0.5\nmaterial = m\n" STAGE,
        "[material m]\nkn = 1e5\ndensity = 2\n[disc a]\nx = 0 0\nr = 0.5\nfixed = 1\nmaterial = m\n"
        "[disc b]\nx = 0.9 0\nr = 0.5\nfixed = 1\nmaterial = m\n" STAGE,
        "[settings]\nallow_overlap = 1\n[material m]\nkn = 1e5\ndensity = 2\n"
        "[disc a]\nx = 0 0\nr = 0.5\nmaterial = m\n[disc b]\nx = 0.9 0\nr = 0.5\nmaterial = m\n" STAGE,
        "[settings]\ndt = 1\nforce_dt = 1\n[material m]\nkn = 1e5\ndensity = 2\n"
        "[disc a]\nx = 0 0\nr = 0.5\nmaterial = m\n" STAGE,
    };
    for (size_t k = 0; k < sizeof good / sizeof good[0]; k++) {
        struct bal_scene sc;
        struct bal_error err = {0};
        struct bal_sim *sim = NULL;
        bal_scene_default(&sc);
        enum bal_status st = bal_scene_parse(&sc, good[k], "good", &err);
        if (st == BAL_OK)
            st = bal_sim_create(&sim, &sc, &err);
        bal_sim_free(sim);
        bal_scene_free(&sc);
        ck_assert_msg(st == BAL_OK, "scene %zu refused: %s", k, err.msg);
    }
}
END_TEST

static void check_refused(const struct bad_scene *b)
{
    struct bal_scene sc;
    struct bal_error err = {0};
    bal_scene_default(&sc);
    enum bal_status st = bal_scene_parse(&sc, b->text, "bad", &err);
    char stage = 'p';
    if (st == BAL_OK) {
        stage = 'v';
        st = bal_scene_validate(&sc, &err);
    }
    /* bal_sim_create validates too: it must refuse the scene as well; and
     * what only a built simulation can see (overlaps, the time step against
     * the estimate) it refuses itself ('c'). */
    enum bal_status st_create = BAL_OK;
    if (stage == 'v' && st != BAL_OK) {
        struct bal_sim *sim = NULL;
        struct bal_error err2 = {0};
        st_create = bal_sim_create(&sim, &sc, &err2);
        bal_sim_free(sim);
    } else if (stage == 'v') {
        struct bal_sim *sim = NULL;
        stage = 'c';
        st = bal_sim_create(&sim, &sc, &err);
        bal_sim_free(sim);
    }
    bal_scene_free(&sc);
    ck_assert_msg(st == BAL_EINVAL, "%s: status %d, message '%s'", b->what, st, err.msg);
    ck_assert_int_eq(err.code, BAL_EINVAL);
    ck_assert_msg(stage == b->refused_by, "%s: refused at stage %c, expected %c (p parse, "
                  "v validate, c create)", b->what, stage, b->refused_by);
    ck_assert_msg(t_contains(err.msg, b->expect), "%s: message '%s' lacks '%s'", b->what, err.msg,
                  b->expect);
    if (stage == 'v')
        ck_assert_msg(st_create == BAL_EINVAL, "%s: bal_sim_create accepted it", b->what);
}

START_TEST(scene_bad_scene_refused)
{
    check_refused(&bad_scenes[_i]);
}
END_TEST

/* The same kind of errors from files: the message names the path. */
struct bad_file {
    const char *path;
    const char *expect;
};

static const struct bad_file bad_files[] = {
    {"scenes/bad/unknown_key.scene", "scenes/bad/unknown_key.scene:4: frction: unknown key"},
    {"scenes/bad/nan_radius.scene", "scenes/bad/nan_radius.scene:8: r: expected one finite number"},
    {"scenes/bad/wall_h2_le_h1.scene", "scenes/bad/wall_h2_le_h1.scene:10: h2: expected h2 > h1"},
    {"scenes/bad/move_missing_wall.scene",
     "scenes/bad/move_missing_wall.scene:13: move: no wall named 'roof'"},
};

START_TEST(scene_bad_file_refused)
{
    const struct bad_file *b = &bad_files[_i];
    struct bal_scene sc;
    struct bal_error err = {0};
    bal_scene_default(&sc);
    enum bal_status st = bal_scene_load(&sc, b->path, &err);
    if (st == BAL_OK)
        st = bal_scene_validate(&sc, &err);
    bal_scene_free(&sc);
    ck_assert_msg(st == BAL_EINVAL, "%s: status %d, message '%s'", b->path, st, err.msg);
    ck_assert_msg(t_contains(err.msg, b->expect), "message '%s' lacks '%s'", err.msg, b->expect);
}
END_TEST

/* --set overrides that name something the scene does not have. */
struct bad_set {
    const char *assignment;
    const char *expect;
};

static const struct bad_set bad_sets[] = {
    {"grain.kn=1", "good: --set grain.kn=1: unknown section 'grain'"},
    {"disc.ghost.r=1", "good: --set disc.ghost.r=1: no [disc ghost] in the scene"},
    {"disc.a.radius=1", "good: --set radius: unknown key in [disc]"},
    {"settings.dtt=0.1", "good: --set dtt: unknown key in [settings]"},
    {"settings.dt=-0.5", "good: --set dt: -0.5 is out of range"},
    {"disc.a.r=abc", "good: --set r: expected one finite number, got 'abc'"},
    {"disc.a.r=", "good: --set r: expected a value after '='"},
    {"settings", "good: --set settings: expected KEY=VALUE"},
    {"disc.a=1", "good: --set disc.a=1: expected disc.NAME.key"},
    {"dt=1", "good: --set dt: expected section.key or section.name.key"},
};

START_TEST(scene_bad_set_refused)
{
    const struct bad_set *b = &bad_sets[_i];
    struct tfx *f = tfx_parse(good_scene, "good");
    enum bal_status st = bal_scene_set(&f->sc, b->assignment, &f->err);
    ck_assert_msg(st == BAL_EINVAL, "%s: status %d", b->assignment, st);
    ck_assert_msg(t_contains(f->err.msg, b->expect), "message '%s' lacks '%s'", f->err.msg,
                  b->expect);
}
END_TEST

/* A line longer than the parser takes is refused, not cut. */
START_TEST(scene_long_line_refused)
{
    const size_t n = 5000;
    char *text = malloc(n + 64);
    ck_assert_ptr_nonnull(text);
    int head = snprintf(text, n + 64, "[material m]\n# ");
    memset(text + head, 'x', n);
    text[head + (int)n] = '\0';
    struct bal_scene sc;
    struct bal_error err = {0};
    bal_scene_default(&sc);
    enum bal_status st = bal_scene_parse(&sc, text, "long", &err);
    bal_scene_free(&sc);
    free(text);
    ck_assert_int_eq(st, BAL_EINVAL);
    ck_assert_msg(t_contains(err.msg, "long:2: line longer than"), "%s", err.msg);
}
END_TEST

/* ------------------------------------------------------------------ */
/* The [pile] section's bad input (its generator: check_specimen.c)   */
/* ------------------------------------------------------------------ */

/* Pile scenes the validator must refuse. */
#define PILE_HEAD "[material g]\nkn = 1e5\ndensity = 2.385\n[material w]\nkn = 2e5\n"

static const struct bad_scene bad_piles[] = {
    {"smooth bottom without wall_material",
     PILE_HEAD "[pile p]\nL = 5\nd = 0.83\nmaterial = g\n" STAGE, 'v',
     "bad:6: wall_material: required with bottom = smooth"},
    {"smooth bottom with L < 3",
     PILE_HEAD "[pile p]\nL = 2\nd = 0.83\nmaterial = g\nwall_material = w\n" STAGE, 'v',
     "bad:7: L: a smooth bottom needs L >= 3"},
    {"unknown slope", PILE_HEAD "[pile p]\nL = 5\nslope = 45\n", 'p',
     "bad:8: slope: expected one of {30 60}, got '45'"},
    {"unknown bottom", PILE_HEAD "[pile p]\nbottom = rough\n", 'p',
     "bad:7: bottom: expected one of {smooth bumpy}, got 'rough'"},
    {"wall_material naming no material",
     PILE_HEAD "[pile p]\nL = 5\nd = 0.83\nmaterial = g\nwall_material = steel\n" STAGE, 'v',
     "bad:10: wall_material: no [material steel] in the scene"},
    {"pile without d", PILE_HEAD "[pile p]\nL = 5\nmaterial = g\nwall_material = w\n" STAGE, 'v',
     "bad:6: [pile p]: d: required key is missing"},
    {"c beyond its range", PILE_HEAD "[pile p]\nc = 1.5\n", 'p', "bad:7: c: 1.5 is out of range"},
    {"negative size_spread", PILE_HEAD "[pile p]\nsize_spread = -0.1\n", 'p',
     "bad:7: size_spread: -0.1 is out of range"},
    {"size_spread beyond its range", PILE_HEAD "[pile p]\nsize_spread = 1.5\n", 'p',
     "bad:7: size_spread: 1.5 is out of range"},
    {"size_spread of 1 (a diameter could reach d/2)",
     PILE_HEAD "[pile p]\nL = 5\nd = 0.83\nbottom = bumpy\nsize_spread = 1\nmaterial = g\n" STAGE, 'v',
     "bad:10: size_spread: expected 0 <= size_spread < 1"},
    {"seed 0 (GSL's mt19937 would take 4357)", PILE_HEAD "[pile p]\nseed = 0\n", 'p',
     "bad:7: seed: 0 is out of range"},
    {"seed beyond 32 bits", PILE_HEAD "[pile p]\nseed = 4294967296\n", 'p',
     "bad:7: seed: 4294967296 is out of range: expected 1 <= value <= 4294967295"},
    {"seed not whole", PILE_HEAD "[pile p]\nseed = 2.5\n", 'p',
     "bad:7: seed: expected an integer, got '2.5'"},
    {"size_spread not a number", PILE_HEAD "[pile p]\nsize_spread = 1/30\n", 'p',
     "bad:7: size_spread: expected one finite number, got '1/30'"},
};

START_TEST(scene_pile_refused)
{
    const struct bad_scene *b = &bad_piles[_i];
    struct tfx *f = tfx_parse("", "unused");
    enum bal_status st = bal_scene_parse(&f->sc, b->text, "bad", &f->err);
    char stage = 'p';
    if (st == BAL_OK) {
        stage = 'v';
        st = bal_scene_validate(&f->sc, &f->err);
    }
    ck_assert_msg(st == BAL_EINVAL, "%s: status %d, message '%s'", b->what, st, f->err.msg);
    ck_assert_msg(stage == b->refused_by, "%s: refused by %c, expected %c", b->what, stage,
                  b->refused_by);
    ck_assert_msg(t_contains(f->err.msg, b->expect), "%s: message '%s' lacks '%s'", b->what,
                  f->err.msg, b->expect);
    if (stage == 'v')
        ck_assert_int_eq(tfx_create(f), BAL_EINVAL);
}
END_TEST

/* ------------------------------------------------------------------ */
/* Fuzzing findings (make test-fuzz; docs/fuzzing.md)                   */
/* ------------------------------------------------------------------ */

/* Each finding of the fuzzing work (docs/fuzzing.md says which the fuzzer
 * found and which were found by reading next to them), as a small scene
 * under fuzz/regress/ (the fuzz run replays the same files): the stage that
 * must refuse it ('p' parse, 'c' create; 'o' = accepted and runs), the status
 * and a part of the message.  Under `make test-sanitize` these also prove
 * the undefined behaviour and the use after free are gone. */
static const struct fuzz_case {
    const char *file;
    char stage;
    enum bal_status status;
    const char *expect;
} fuzz_cases[] = {
    {"fuzz/regress/far_disc.scene", 'o', BAL_OK, ""},
    {"fuzz/regress/thin_sparse.scene", 'o', BAL_OK, ""},
    {"fuzz/regress/extent_overflow.scene", 'c', BAL_EUNSTABLE,
     "extent_overflow.scene: neighbour grid: the discs spread over more than the largest number"},
    {"fuzz/regress/dt_infinite.scene", 'c', BAL_EINVAL,
     "dt_infinite.scene:14: r: disc a: its mass, density x pi r^2, is not a positive finite"},
    /* issue 18: the extremes fuzzer (fuzz_extremes.c) */
    {"fuzz/regress/coordination_hang.scene", 'o', BAL_OK, ""},
    {"fuzz/regress/coordination_overflow.scene", 'o', BAL_OK, ""},
    {"fuzz/regress/coordination_sum_overflow.scene", 'c', BAL_EINVAL,
     "coordination_sum_overflow.scene:12: r: disc big: its mass"},
    {"fuzz/regress/mass_underflow.scene", 'c', BAL_EINVAL,
     "mass_underflow.scene:9: r: disc a: its mass"},
    {"fuzz/regress/speed_1e300.scene", 'c', BAL_EINVAL,
     "speed_1e300.scene:9: v: disc a: its kinetic energy"},
    {"fuzz/regress/gravity_max.scene", 'c', BAL_EINVAL,
     "gravity_max.scene:12: x: disc a: its weight m g or its gravity potential"},
    {"fuzz/regress/theta_overflow.scene", 'c', BAL_EINVAL,
     "theta_overflow.scene:9: omega: disc a: its rotational energy"},
    {"fuzz/regress/alpha_dt_2.scene", 'c', BAL_EINVAL,
     "alpha_dt_2.scene:7: alpha: global damping alpha = 1 with the time step 2 gives alpha dt = 2"},
    {"fuzz/regress/kn_underflow.scene", 'p', BAL_EINVAL,
     "kn_underflow.scene:9: kn: 1e-300 is out of range"},
    {"fuzz/regress/kn_underflow_estimate.scene", 'p', BAL_EINVAL,
     "kn_underflow_estimate.scene:8: kn: 1e-300 is out of range"},
    {"fuzz/regress/force_dt_max.scene", 'o', BAL_OK, ""},
    {"fuzz/regress/kn_overflow.scene", 'p', BAL_EINVAL,
     "kn_overflow.scene:4: kn: 1e+155 is out of range: expected 1e-150 <= value <= 1e+150"},
    {"fuzz/regress/enum_long_message.scene", 'p', BAL_EINVAL,
     "wall_gap wall_stress}, got 'no_such_quantity'"},
    {"fuzz/regress/name_clash.scene", 'c', BAL_EINVAL,
     "name_clash.scene:6: [fill f]: makes a wall 'f_top', but a disc or wall has that name"},
    {"fuzz/regress/disc_wall_clash.scene", 'c', BAL_EINVAL,
     "disc_wall_clash.scene:10: [wall a]: a disc has this name too"},
};

START_TEST(scene_fuzz_regression)
{
    const struct fuzz_case *c = &fuzz_cases[_i];
    struct tfx *f = tfx_parse("", c->file);
    enum bal_status st = bal_scene_load(&f->sc, c->file, &f->err);
    char stage = 'p';
    if (st == BAL_OK) {
        stage = 'c';
        st = tfx_create(f);
    }
    if (st == BAL_OK) {
        stage = 'o';
        for (int k = 0; k < 5 && st == BAL_OK; k++)
            st = bal_sim_step(f->sim, &f->err);
    }
    ck_assert_msg(stage == c->stage && st == c->status,
                  "%s: stage %c status %d (expected %c, %d): %s", c->file, stage, st, c->stage,
                  c->status, f->err.msg);
    ck_assert_msg(t_contains(f->err.msg, c->expect), "%s: message '%s' lacks '%s'", c->file,
                  f->err.msg, c->expect);
    if (st == BAL_OK && f->sim->use_grid) {
        /* The cells stay few however far apart the discs are. */
        const long cells = (long)f->sim->grid.nx * f->sim->grid.ny;
        ck_assert_msg(cells <= 8L * f->sim->n + 64, "%s: %ld cells for %d discs", c->file, cells,
                      f->sim->n);
    }
}
END_TEST

Suite *suite_scene(void)
{
    Suite *s = suite_create("scene");

    TCase *tc = tcase_create("parse");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, scene_defaults);
    tcase_add_test(tc, scene_every_default_parses);
    tcase_add_test(tc, scene_parse_values);
    tcase_add_test(tc, scene_angles_are_degrees);
    tcase_add_test(tc, scene_control_keys);
    tcase_add_test(tc, scene_set_overrides);
    tcase_add_test(tc, scene_load_file);
    tcase_add_test(tc, scene_print_keys_lists_every_key);
    tcase_add_test(tc, scene_unused_rules_name_keys);
    suite_add_tcase(s, tc);

    tc = tcase_create("errors");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_loop_test(tc, scene_bad_scene_refused, 0,
                        (int)(sizeof bad_scenes / sizeof bad_scenes[0]));
    tcase_add_loop_test(tc, scene_bad_file_refused, 0,
                        (int)(sizeof bad_files / sizeof bad_files[0]));
    tcase_add_loop_test(tc, scene_bad_set_refused, 0, (int)(sizeof bad_sets / sizeof bad_sets[0]));
    tcase_add_test(tc, scene_long_line_refused);
    tcase_add_test(tc, scene_allowed_overlaps_and_forced_steps);
    tcase_add_test(tc, scene_missing_file_is_eio);
    tcase_add_test(tc, scene_fifo_and_devices_refused);
    tcase_add_test(tc, scene_strerror_names_every_status);
    suite_add_tcase(s, tc);

    tc = tcase_create("scale");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_set_timeout(tc, 30);
    tcase_add_test(tc, scene_many_sections_parse_at_once);
    suite_add_tcase(s, tc);

    tc = tcase_create("pile");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_loop_test(tc, scene_pile_refused, 0, (int)(sizeof bad_piles / sizeof bad_piles[0]));
    suite_add_tcase(s, tc);

    tc = tcase_create("fuzz");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_loop_test(tc, scene_fuzz_regression, 0,
                        (int)(sizeof fuzz_cases / sizeof fuzz_cases[0]));
    suite_add_tcase(s, tc);
    return s;
}
