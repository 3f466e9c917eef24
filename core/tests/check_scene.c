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
    ck_assert_int_eq(sc->n_probes, 1);
    ck_assert_int_eq(sc->probes[0].kind, BAL_PROBE_WALL_F2);
    ck_assert_str_eq(sc->probes[0].a, "floor");
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

/* ------------------------------------------------------------------ */
/* Bad scenes                                                          */
/* ------------------------------------------------------------------ */

/* A valid head for bad scenes that need a material and a disc: 7 lines. */
#define HEAD "[material m]\nkn = 1e5\ndensity = 2.385\n[disc a]\nx = 0 0\nr = 0.5\nmaterial = m\n"
#define STAGE "[stage s]\ncycles = 3\n"

struct bad_scene {
    const char *what;
    const char *text;
    char refused_by;      /* 'p': bal_scene_parse, 'v': bal_scene_validate */
    const char *expect;   /* substring of the message */
};

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
     'v', "bad:13: b: only contact probes take a second body"},
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
     'v', "bad:3: ks: expected ks > 0"},
    {"power law nu without delta0", "[settings]\nnormal_law = power\nnu = 1.5\n" HEAD STAGE, 'v',
     "bad:3: delta0: required with normal_law = power and nu != 1"},
    {"fill with rmax < rmin",
     "[material m]\nkn = 1e5\ndensity = 2\n[fill f]\nn = 4\ncolumns = 2\nrmin = 0.5\n"
     "rmax = 0.25\nmaterial = m\n" STAGE,
     'v', "bad:8: rmax: expected rmax >= rmin"},
    {"fill box without wall material",
     "[material m]\nkn = 1e5\ndensity = 2\n[fill f]\nn = 4\ncolumns = 2\nrmin = 0.5\n"
     "rmax = 0.5\nmaterial = m\nbox = 1\n" STAGE,
     'v', "bad:4: wall_material: required with box = 1"},
};

START_TEST(scene_bad_scene_refused)
{
    const struct bad_scene *b = &bad_scenes[_i];
    struct bal_scene sc;
    struct bal_error err = {0};
    bal_scene_default(&sc);
    enum bal_status st = bal_scene_parse(&sc, b->text, "bad", &err);
    char stage = 'p';
    if (st == BAL_OK) {
        stage = 'v';
        st = bal_scene_validate(&sc, &err);
    }
    /* bal_sim_create validates too: it must refuse the scene as well. */
    enum bal_status st_create = BAL_OK;
    if (stage == 'v' && st != BAL_OK) {
        struct bal_sim *sim = NULL;
        struct bal_error err2 = {0};
        st_create = bal_sim_create(&sim, &sc, &err2);
        bal_sim_free(sim);
    }
    bal_scene_free(&sc);
    ck_assert_msg(st == BAL_EINVAL, "%s: status %d, message '%s'", b->what, st, err.msg);
    ck_assert_int_eq(err.code, BAL_EINVAL);
    ck_assert_msg(stage == b->refused_by, "%s: refused by %s, expected by %s", b->what,
                  stage == 'p' ? "parse" : "validate", b->refused_by == 'p' ? "parse" : "validate");
    ck_assert_msg(t_contains(err.msg, b->expect), "%s: message '%s' lacks '%s'", b->what, err.msg,
                  b->expect);
    if (stage == 'v')
        ck_assert_msg(st_create == BAL_EINVAL, "%s: bal_sim_create accepted it", b->what);
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

Suite *suite_scene(void)
{
    Suite *s = suite_create("scene");

    TCase *tc = tcase_create("parse");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, scene_defaults);
    tcase_add_test(tc, scene_every_default_parses);
    tcase_add_test(tc, scene_parse_values);
    tcase_add_test(tc, scene_angles_are_degrees);
    tcase_add_test(tc, scene_set_overrides);
    tcase_add_test(tc, scene_load_file);
    tcase_add_test(tc, scene_print_keys_lists_every_key);
    suite_add_tcase(s, tc);

    tc = tcase_create("errors");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_loop_test(tc, scene_bad_scene_refused, 0,
                        (int)(sizeof bad_scenes / sizeof bad_scenes[0]));
    tcase_add_loop_test(tc, scene_bad_file_refused, 0,
                        (int)(sizeof bad_files / sizeof bad_files[0]));
    tcase_add_loop_test(tc, scene_bad_set_refused, 0, (int)(sizeof bad_sets / sizeof bad_sets[0]));
    tcase_add_test(tc, scene_long_line_refused);
    tcase_add_test(tc, scene_missing_file_is_eio);
    tcase_add_test(tc, scene_strerror_names_every_status);
    suite_add_tcase(s, tc);
    return s;
}
