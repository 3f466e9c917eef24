/*
 * scene.c — text scene → struct bal_scene, and --set overrides.
 *
 * Format (documented key by key in docs/scene-format.md, generated from
 * scene_keys.c):
 *
 *     # a comment runs to the end of the line
 *     [settings]
 *     dt_fraction = 0.1
 *     [material grain]
 *     kn = 1e9
 *     [disc x]
 *     x = 50 50
 *     ...
 *
 * Define, default, validate: bal_scene_default() gives an empty scene with
 * default settings; each new section starts from the defaults in the key
 * table (scene_keys.c); bal_scene_parse() checks syntax, types and ranges
 * line by line; bal_scene_validate() then checks what needs the whole file
 * (scene_validate.c).  Every message names the file, the line and the key
 * and says what was expected.
 *
 * Kept whole (about 800 lines): storage of the sections, the value parsers,
 * the name index and the line parser serve one reader, the text → struct
 * step, which the file and --set paths share; the key table (scene_keys.c)
 * and the whole-scene checks (scene_validate.c) are already apart.
 */
#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "import.h"
#include "scene.h"
#include "status.h"

/* Longest line a scene file may hold; longer lines are refused, not cut. */
#define LINE_MAX_CHARS 4096
/* Largest scene file read: a million discs written one [disc] section each
 * (harness/peer/race.py writes about 150 bytes a disc) with room to spare;
 * the largest scene of the catalogue is 34 kB.  A larger state belongs in
 * the data file of an [import] (import.c: up to 4 GB). */
#define SCENE_MAX_BYTES (256L << 20)

/* ------------------------------------------------------------------ */
/* Section storage                                                     */
/* ------------------------------------------------------------------ */

struct section_array {
    void **items;
    int *count;
    int *cap;
};

static struct section_array section_array(struct bal_scene *s,
                                          enum bal_section_kind k)
{
    struct section_array a = {NULL, NULL, NULL};
    switch (k) {
    case BAL_SEC_MATERIAL:
        a = (struct section_array){(void **)&s->materials, &s->n_materials, &s->cap_materials};
        break;
    case BAL_SEC_DISC:
        a = (struct section_array){(void **)&s->discs, &s->n_discs, &s->cap_discs};
        break;
    case BAL_SEC_WALL:
        a = (struct section_array){(void **)&s->walls, &s->n_walls, &s->cap_walls};
        break;
    case BAL_SEC_FILL:
        a = (struct section_array){(void **)&s->fills, &s->n_fills, &s->cap_fills};
        break;
    case BAL_SEC_PILE:
        a = (struct section_array){(void **)&s->piles, &s->n_piles, &s->cap_piles};
        break;
    case BAL_SEC_GRAINS:
        a = (struct section_array){(void **)&s->grains, &s->n_grains, &s->cap_grains};
        break;
    case BAL_SEC_IMPORT:
        a = (struct section_array){(void **)&s->imports, &s->n_imports, &s->cap_imports};
        break;
    case BAL_SEC_STAGE:
        a = (struct section_array){(void **)&s->stages, &s->n_stages, &s->cap_stages};
        break;
    case BAL_SEC_PROBE:
        a = (struct section_array){(void **)&s->probes, &s->n_probes, &s->cap_probes};
        break;
    case BAL_SEC_SETTINGS:
    case BAL_SEC_COUNT:
        break;
    }
    return a;
}

void *bal_scene_section(const struct bal_scene *s, enum bal_section_kind k, int i)
{
    struct section_array a = section_array((struct bal_scene *)s, k);
    if (k == BAL_SEC_SETTINGS)
        return (void *)&s->settings;
    return (char *)*a.items + (size_t)i * bal_scene_sections[k].size;
}

int bal_scene_count(const struct bal_scene *s, enum bal_section_kind k)
{
    if (k == BAL_SEC_SETTINGS)
        return 1;
    return *section_array((struct bal_scene *)s, k).count;
}

int bal_scene_find(const struct bal_scene *s, enum bal_section_kind sec,
                   const char *name)
{
    int n = bal_scene_count(s, sec);
    for (int i = 0; i < n; i++)
        if (strcmp(bal_scene_item_name(bal_scene_section(s, sec, i)), name) == 0)
            return i;
    return -1;
}

/* ------------------------------------------------------------------ */
/* Values                                                              */
/* ------------------------------------------------------------------ */

struct where {
    const char *file;
    int line;             /* 0: from --set */
};

static enum bal_status where_error(struct bal_error *err, struct where w,
                                   const char *key, const char *fmt,
                                   const char *detail)
{
    char what[BAL_MSG_MAX];
    snprintf(what, sizeof what, fmt, detail);
    if (w.line > 0)
        return bal_error(err, BAL_EINVAL, "%s:%d: %s: %s", w.file, w.line, key, what);
    return bal_error(err, BAL_EINVAL, "%s: --set %s: %s", w.file, key, what);
}

static char *trim(char *p)
{
    while (isspace((unsigned char)*p))
        p++;
    char *e = p + strlen(p);
    while (e > p && isspace((unsigned char)e[-1]))
        *--e = '\0';
    return p;
}

/* Parse one finite number from *p, advancing past it. */
static int parse_number(const char **p, double *out)
{
    while (isspace((unsigned char)**p))
        (*p)++;
    if (**p == '\0')
        return 0;
    char *end;
    errno = 0;
    double v = strtod(*p, &end);
    /* A subnormal result (ERANGE, but not zero) is a number like any other;
     * one that underflows to zero or overflows is refused. */
    if (end == *p || !isfinite(v) || (errno == ERANGE && v == 0))
        return 0;
    if (*end != '\0' && !isspace((unsigned char)*end))
        return 0;
    *p = end;
    *out = v;
    return 1;
}

static int at_end(const char *p)
{
    while (isspace((unsigned char)*p))
        p++;
    return *p == '\0';
}

static int valid_name(const char *v)
{
    if (!*v || strlen(v) >= BAL_NAME_MAX)
        return 0;
    for (const char *c = v; *c; c++)
        if (!(isalnum((unsigned char)*c) || *c == '_' || *c == '-'))
            return 0;
    return 1;
}

/* A body's name: a section's name, or NAME.k (k in decimal, without
 * leading zeros: one text per disc, as messages print it). */
static int valid_body(const char *v)
{
    const char *dot = strrchr(v, '.');
    if (!dot)
        return valid_name(v);
    char name[BAL_NAME_MAX];
    const size_t len = (size_t)(dot - v);
    if (len >= sizeof name)
        return 0;
    memcpy(name, v, len);
    name[len] = '\0';
    const char *k = dot + 1;
    if (!valid_name(name) || !*k || (k[0] == '0' && k[1]) || strlen(k) > 9)
        return 0;
    for (; *k; k++)
        if (*k < '0' || *k > '9')
            return 0;
    return 1;
}

static enum bal_status check_range(const struct bal_key *key, double v,
                                   struct where w, struct bal_error *err)
{
    if (v < key->min || v > key->max) {
        /* Each number in its shortest exact text (status.h): with %.6g,
         * rolling = 2.0000001 was "2 is out of range: expected 0 <= value
         * <= 2".  A bound at the end of the doubles (BIG) is no bound. */
        char range[3 * BAL_NUM_CHARS + 64], a[BAL_NUM_CHARS], lo[BAL_NUM_CHARS + 8] = "",
             hi[BAL_NUM_CHARS + 8] = "";
        if (key->min > -DBL_MAX)
            snprintf(lo, sizeof lo, "%s <= ", bal_num_text(a, key->min));
        if (key->max < DBL_MAX)
            snprintf(hi, sizeof hi, " <= %s", bal_num_text(a, key->max));
        snprintf(range, sizeof range, "%s is out of range: expected %svalue%s",
                 bal_num_text(a, v), lo, hi);
        return where_error(err, w, key->name, "%s", range);
    }
    return BAL_OK;
}

/* Store `value` into the key's field of `item`. */
static enum bal_status set_value(void *item, const struct bal_key *key,
                                 const char *value, struct where w,
                                 struct bal_error *err)
{
    char *field = (char *)item + key->offset;
    const char *p = value;
    double v[4];

    switch (key->type) {
    case BAL_KEY_DOUBLE:
        if (!parse_number(&p, &v[0]) || !at_end(p))
            return where_error(err, w, key->name, "expected one finite number, got '%s'", value);
        if (check_range(key, v[0], w, err))
            return err->code;
        memcpy(field, &v[0], sizeof(double));
        return BAL_OK;
    case BAL_KEY_LONG: {
        if (!parse_number(&p, &v[0]) || !at_end(p) || v[0] != floor(v[0]))
            return where_error(err, w, key->name, "expected an integer, got '%s'", value);
        if (check_range(key, v[0], w, err))
            return err->code;
        long l = (long)v[0];
        memcpy(field, &l, sizeof l);
        return BAL_OK;
    }
    case BAL_KEY_VEC2:
        if (!parse_number(&p, &v[0]) || !parse_number(&p, &v[1]) || !at_end(p))
            return where_error(err, w, key->name, "expected two finite numbers, got '%s'", value);
        if (check_range(key, v[0], w, err) || check_range(key, v[1], w, err))
            return err->code;
        memcpy(field, v, 2 * sizeof(double));
        return BAL_OK;
    case BAL_KEY_NAME:
        if (*value && !valid_name(value))
            return where_error(err, w, key->name,
                               "expected a name of letters, digits, '_' or '-' "
                               "(at most 47), got '%s'", value);
        strcpy(field, value);
        return BAL_OK;
    case BAL_KEY_BODY:
        if (strlen(value) >= BAL_BODY_MAX || (*value && !valid_body(value)))
            return where_error(err, w, key->name,
                               "expected the name of a disc or a wall (letters, digits, '_' or "
                               "'-', at most 47), or NAME.k for the k-th disc of a generator, "
                               "got '%s'", value);
        strcpy(field, value);
        return BAL_OK;
    case BAL_KEY_ENUM: {
        size_t n = strlen(value);
        int idx = 0;
        for (const char *c = key->choices; *c;) {
            const char *e = strchr(c, ' ');
            size_t len = e ? (size_t)(e - c) : strlen(c);
            if (len == n && strncmp(c, value, n) == 0) {
                memcpy(field, &idx, sizeof idx);
                return BAL_OK;
            }
            idx++;
            c += len + (e ? 1 : 0);
        }
        /* The value goes in as an argument, never into a format: the list
         * of probe quantities alone is longer than half a message, and a
         * format cut short dropped the value (seen by reading, while fuzzing). */
        char msg[BAL_MSG_MAX];
        snprintf(msg, sizeof msg, "expected one of {%s}, got '%s'", key->choices, value);
        return where_error(err, w, key->name, "%s", msg);
    }
    case BAL_KEY_CONTROL: {
        /* A wall's name, then what the key's form (key->choices, e.g.
         * "WALL sigma gain vmax WALL_A WALL_B") has after "WALL": a word
         * that starts with WALL is the name of another wall, any other
         * word a finite number. */
        static const char *const counts[BAL_CONTROL_VALUES_MAX + 1] = {
            "no", "one", "two", "three", "four", "five", "six", "seven", "eight"};
        struct bal_stage_def *st = item;
        int n_values = 0, n_walls = 0;
        char is_wall[BAL_CONTROL_VALUES_MAX + BAL_CONTROL_WALLS_MAX];
        int n_words = 0;
        for (const char *c = key->choices; (c = strchr(c, ' ')) != NULL && n_words < (int)sizeof is_wall;) {
            c++;
            is_wall[n_words] = strncmp(c, "WALL", 4) == 0;
            n_walls += is_wall[n_words];
            n_values += !is_wall[n_words];
            n_words++;
        }
        double values[BAL_CONTROL_VALUES_MAX];
        char walls[BAL_CONTROL_WALLS_MAX][BAL_NAME_MAX + 1];
        char wall[BAL_NAME_MAX + 1], msg[BAL_MSG_MAX];
        int n_read = 0;
        if (sscanf(value, "%48s%n", wall, &n_read) != 1 || !valid_name(wall)) {
            snprintf(msg, sizeof msg, "expected '%s', got '%s'", key->choices, value);
            return where_error(err, w, key->name, "%s", msg);
        }
        p = value + n_read;
        int ok = 1, nv = 0, nw = 0;
        for (int k = 0; k < n_words && ok; k++) {
            if (!is_wall[k]) {
                ok = parse_number(&p, &values[nv++]);
                continue;
            }
            int got = 0;
            ok = sscanf(p, "%48s%n", walls[nw], &got) == 1 && valid_name(walls[nw]);
            p += got;
            nw++;
        }
        if (!ok || !at_end(p)) {
            char names[32] = "";
            if (n_walls > 0)
                snprintf(names, sizeof names, " and %s wall name%s", counts[n_walls],
                         n_walls > 1 ? "s" : "");
            snprintf(msg, sizeof msg, "expected '%s' with %s finite number%s%s, got '%s'",
                     key->choices, counts[n_values], n_values == 1 ? "" : "s", names, value);
            return where_error(err, w, key->name, "%s", msg);
        }
        /* In a file a wall has one line per stage, whatever its controller;
         * --set (line 0) replaces the wall's line, so a variant can change a
         * loading speed (or the controller). */
        struct bal_move_def *m = NULL;
        for (int i = 0; i < st->n_moves; i++) {
            if (strcmp(st->moves[i].wall, wall) != 0)
                continue;
            if (w.line > 0)
                return where_error(err, w, key->name,
                                   "wall '%s' is driven twice in this stage", wall);
            m = &st->moves[i];
        }
        if (!m) {
            if (st->n_moves >= BAL_MAX_MOVES)
                return where_error(err, w, key->name, "more than %s moves in one stage", "16");
            m = &st->moves[st->n_moves++];
        }
        memset(m, 0, sizeof *m);
        strcpy(m->wall, wall);
        m->line = w.line;
        m->control = bal_scene_key_control(key->name);
        memcpy((char *)m + key->offset, values, (size_t)n_values * sizeof(double));
        for (int k = 0; k < n_walls; k++)
            strcpy(m->walls[k], walls[k]);
        return BAL_OK;
    }
    case BAL_KEY_FILE: {
        /* The path as written; the file, relative to the scene's directory,
         * is read now into the section (import.c), and only a file read
         * whole replaces what the section held. */
        if (!*value) { /* the default: no file */
            *field = '\0';
            return BAL_OK;
        }
        if (strlen(value) >= BAL_PATH_MAX)
            return where_error(err, w, key->name, "%s", "expected a path of at most 511 characters");
        char path[2 * BAL_PATH_MAX + 1];
        const char *slash = strrchr(w.file, '/');
        if (value[0] == '/' || !slash)
            snprintf(path, sizeof path, "%s", value);
        else
            snprintf(path, sizeof path, "%.*s/%s", (int)(slash - w.file), w.file, value);
        char msg[BAL_MSG_MAX];
        const enum bal_status st = bal_import_read(item, key->choices, path, msg, sizeof msg);
        if (st != BAL_OK) {
            where_error(err, w, key->name, "%s", msg);
            err->code = st;
            return st;
        }
        strcpy(field, value);
        return BAL_OK;
    }
    case BAL_KEY_FLAGS: {
        /* "none", or words of key->choices separated by spaces: bit k for
         * the k-th word. */
        int bits = 0;
        char words[LINE_MAX_CHARS];
        snprintf(words, sizeof words, "%s", value);
        for (char *save = NULL, *word = strtok_r(words, " \t", &save); word;
             word = strtok_r(NULL, " \t", &save)) {
            if (strcmp(word, "none") == 0)
                continue;
            int idx = 0, found = -1;
            for (const char *c = key->choices; *c; idx++) {
                const char *e = strchr(c, ' ');
                const size_t len = e ? (size_t)(e - c) : strlen(c);
                if (len == strlen(word) && strncmp(c, word, len) == 0)
                    found = idx;
                c += len + (e ? 1 : 0);
            }
            if (found < 0) {
                char msg[BAL_MSG_MAX];
                snprintf(msg, sizeof msg, "expected 'none' or words of {%s}, got '%s'",
                         key->choices, word);
                return where_error(err, w, key->name, "%s", msg);
            }
            bits |= 1 << found;
        }
        memcpy(field, &bits, sizeof bits);
        return BAL_OK;
    }
    }
    return where_error(err, w, key->name, "%s", "unknown key type");
}

/* Give a fresh section its defaults from the key table. */
static void apply_defaults(void *item, enum bal_section_kind k)
{
    for (int i = 0;; i++) {
        const struct bal_key *key = bal_scene_key_at(k, i);
        if (!key)
            break;
        if (key->def) {
            struct bal_error ignored;
            struct where w = {"(defaults)", 1};
            /* Defaults are in range by construction; a failure here is a bug
             * in the table, which the scene tests catch. */
            (void)set_value(item, key, key->def, w, &ignored);
        }
    }
    *bal_scene_item_given(item, k) = 0;
}

void bal_scene_default(struct bal_scene *s)
{
    memset(s, 0, sizeof *s);
    apply_defaults(&s->settings, BAL_SEC_SETTINGS);
}

void bal_scene_free(struct bal_scene *s)
{
    free(s->materials);
    free(s->discs);
    free(s->walls);
    free(s->fills);
    free(s->piles);
    free(s->grains);
    for (int i = 0; i < s->n_imports; i++)
        bal_import_free(&s->imports[i]);
    free(s->imports);
    free(s->stages);
    free(s->probes);
    memset(s, 0, sizeof *s);
}

/* The named sections of a scene being parsed, hashed by kind and name, so
 * that "name used twice" is one lookup a section: a pass over the sections
 * of its kind made a scene of 100 000 [disc] sections (4.5 MB) take 54 s to
 * parse, growing with the square of the count.  Open addressing, at most
 * half full. */
struct name_slot {
    int kind; /* -1: empty */
    int item; /* index within its kind */
};

struct name_index {
    struct name_slot *slot;
    size_t cap; /* a power of two */
    size_t used;
};

static uint64_t name_hash(enum bal_section_kind k, const char *name)
{
    uint64_t h = 1469598103934665603ULL ^ (uint64_t)k; /* FNV-1a */
    for (const unsigned char *c = (const unsigned char *)name; *c; c++)
        h = (h ^ *c) * 1099511628211ULL;
    return h;
}

static int index_find(const struct name_index *ix, const struct bal_scene *s,
                      enum bal_section_kind k, const char *name)
{
    if (ix->cap == 0)
        return -1;
    for (size_t h = name_hash(k, name) & (ix->cap - 1);; h = (h + 1) & (ix->cap - 1)) {
        const struct name_slot *e = &ix->slot[h];
        if (e->kind < 0)
            return -1;
        if (e->kind == (int)k &&
            strcmp(bal_scene_item_name(bal_scene_section(s, k, e->item)), name) == 0)
            return e->item;
    }
}

/* Add item i of kind k; 0, or -1 when out of memory. */
static int index_add(struct name_index *ix, const struct bal_scene *s, enum bal_section_kind k,
                     int i)
{
    if (2 * (ix->used + 1) > ix->cap) {
        struct name_index bigger = {NULL, ix->cap ? 2 * ix->cap : 64, 0};
        bigger.slot = malloc(bigger.cap * sizeof *bigger.slot);
        if (!bigger.slot)
            return -1;
        for (size_t h = 0; h < bigger.cap; h++)
            bigger.slot[h].kind = -1;
        for (size_t h = 0; h < ix->cap; h++)
            if (ix->slot[h].kind >= 0)
                (void)index_add(&bigger, s, (enum bal_section_kind)ix->slot[h].kind,
                                ix->slot[h].item);
        free(ix->slot);
        *ix = bigger;
    }
    const char *name = bal_scene_item_name(bal_scene_section(s, k, i));
    size_t h = name_hash(k, name) & (ix->cap - 1);
    while (ix->slot[h].kind >= 0)
        h = (h + 1) & (ix->cap - 1);
    ix->slot[h] = (struct name_slot){(int)k, i};
    ix->used++;
    return 0;
}

static enum bal_status new_section(struct bal_scene *s, enum bal_section_kind k,
                                   const char *name, struct where w, struct name_index *ix,
                                   void **out, struct bal_error *err)
{
    if (k == BAL_SEC_SETTINGS) {
        if (s->settings.key_line[BAL_KEYS_MAX - 1] != 0)
            return bal_error(err, BAL_EINVAL, "%s:%d: [settings]: given twice (first on line %d)",
                             w.file, w.line, s->settings.key_line[BAL_KEYS_MAX - 1]);
        /* The last key_line slot of settings records its header line. */
        s->settings.key_line[BAL_KEYS_MAX - 1] = w.line;
        *out = &s->settings;
        return BAL_OK;
    }
    if (!valid_name(name))
        return bal_error(err, BAL_EINVAL,
                         "%s:%d: [%s]: expected a name of letters, digits, '_' or '-' "
                         "(at most 47), got '%s'",
                         w.file, w.line, bal_scene_sections[k].name, name);
    if (index_find(ix, s, k, name) >= 0)
        return bal_error(err, BAL_EINVAL, "%s:%d: [%s %s]: name used twice",
                         w.file, w.line, bal_scene_sections[k].name, name);
    struct section_array a = section_array(s, k);
    size_t size = bal_scene_sections[k].size;
    if (*a.count == *a.cap) {
        int cap = *a.cap ? 2 * *a.cap : 8;
        void *p = realloc(*a.items, (size_t)cap * size);
        if (!p)
            return bal_error(err, BAL_ENOMEM, "%s:%d: out of memory", w.file, w.line);
        *a.items = p;
        *a.cap = cap;
    }
    void *item = (char *)*a.items + (size_t)(*a.count) * size;
    memset(item, 0, size);
    (*a.count)++;
    strcpy(bal_scene_item_name(item), name);
    *bal_scene_item_line(item) = w.line;
    apply_defaults(item, k);
    if (index_add(ix, s, k, *a.count - 1))
        return bal_error(err, BAL_ENOMEM, "%s:%d: out of memory", w.file, w.line);
    *out = item;
    return BAL_OK;
}

static enum bal_status assign(void *item, enum bal_section_kind k,
                              const char *key_name, const char *value,
                              struct where w, struct bal_error *err)
{
    int ki = bal_scene_key_index(k, key_name);
    if (ki < 0) {
        char msg[BAL_MSG_MAX / 2];
        int n = snprintf(msg, sizeof msg, "unknown key in [%s]; expected one of:",
                         bal_scene_sections[k].name);
        for (int i = 0; n > 0 && (size_t)n < sizeof msg; i++) {
            const struct bal_key *kk = bal_scene_key_at(k, i);
            if (!kk)
                break;
            n += snprintf(msg + n, sizeof msg - (size_t)n, " %s", kk->name);
        }
        return where_error(err, w, key_name, "%s", msg);
    }
    const struct bal_key *key = bal_scene_key_at(k, ki);
    uint32_t *given = bal_scene_item_given(item, k);
    if ((*given & (1u << ki)) && key->type != BAL_KEY_CONTROL && w.line > 0) {
        char first[32];
        snprintf(first, sizeof first, "%d", bal_scene_item_key_line(item, k)[ki]);
        return where_error(err, w, key_name, "given twice in this section (first on line %s)",
                           first);
    }
    if (set_value(item, key, value, w, err))
        return err->code;
    *given |= 1u << ki;
    bal_scene_item_key_line(item, k)[ki] = w.line;
    /* A stage's length is cycles or time: an override (--set, no line)
     * of the one replaces the other, so a sweep can give a stage in time. */
    if (k == BAL_SEC_STAGE && w.line <= 0 &&
        (strcmp(key->name, "cycles") == 0 || strcmp(key->name, "time") == 0)) {
        const int other = bal_scene_key_index(k, strcmp(key->name, "cycles") == 0 ? "time" : "cycles");
        *given &= ~(1u << other);
    }
    return BAL_OK;
}

/* ------------------------------------------------------------------ */
/* Parsing                                                             */
/* ------------------------------------------------------------------ */

static int section_kind(const char *word)
{
    for (int k = 0; k < BAL_SEC_COUNT; k++)
        if (strcmp(bal_scene_sections[k].name, word) == 0)
            return k;
    return -1;
}

static enum bal_status parse_text(struct bal_scene *s, const char *text, const char *name,
                                  struct name_index *ix, struct bal_error *err)
{
    snprintf(s->path, sizeof s->path, "%s", name);
    struct where w = {s->path, 0};
    void *item = NULL;
    enum bal_section_kind kind = BAL_SEC_SETTINGS;
    char line[LINE_MAX_CHARS + 2];

    const char *p = text;
    /* A UTF-8 byte-order mark, which some editors put at the start of a
     * file, is not part of the first line. */
    if (strncmp(p, "\xEF\xBB\xBF", 3) == 0)
        p += 3;
    while (*p) {
        w.line++;
        const char *nl = strchr(p, '\n');
        size_t len = nl ? (size_t)(nl - p) : strlen(p);
        if (len > LINE_MAX_CHARS)
            return bal_error(err, BAL_EINVAL, "%s:%d: line longer than %d characters",
                             w.file, w.line, LINE_MAX_CHARS);
        memcpy(line, p, len);
        line[len] = '\0';
        p += len + (nl ? 1 : 0);
        if (memchr(line, '\0', len) != NULL && strlen(line) != len)
            return bal_error(err, BAL_EINVAL, "%s:%d: NUL byte in the file", w.file, w.line);

        char *hash = strchr(line, '#');
        if (hash)
            *hash = '\0';
        char *l = trim(line);
        if (*l == '\0')
            continue;

        if (*l == '[') {
            char *close = strchr(l, ']');
            if (!close || !at_end(close + 1))
                return bal_error(err, BAL_EINVAL,
                                 "%s:%d: expected a section header '[kind name]', got '%s'",
                                 w.file, w.line, l);
            *close = '\0';
            char *inner = trim(l + 1);
            char *sp = inner;
            while (*sp && !isspace((unsigned char)*sp))
                sp++;
            char *sec_name = "";
            if (*sp) {
                *sp = '\0';
                sec_name = trim(sp + 1);
            }
            int k = section_kind(inner);
            if (k < 0)
                return bal_error(err, BAL_EINVAL,
                                 "%s:%d: [%s]: unknown section; expected one of settings, "
                                 "material, disc, wall, fill, pile, grains, import, stage, probe",
                                 w.file, w.line, inner);
            if (bal_scene_sections[k].named && !*sec_name)
                return bal_error(err, BAL_EINVAL, "%s:%d: [%s]: a name is required: [%s NAME]",
                                 w.file, w.line, inner, inner);
            if (!bal_scene_sections[k].named && *sec_name)
                return bal_error(err, BAL_EINVAL, "%s:%d: [%s]: takes no name, got '%s'",
                                 w.file, w.line, inner, sec_name);
            kind = (enum bal_section_kind)k;
            if (new_section(s, kind, sec_name, w, ix, &item, err))
                return err->code;
            continue;
        }

        char *eq = strchr(l, '=');
        if (!eq)
            return bal_error(err, BAL_EINVAL, "%s:%d: expected 'key = value', got '%s'",
                             w.file, w.line, l);
        *eq = '\0';
        char *key = trim(l);
        char *value = trim(eq + 1);
        if (!item)
            return bal_error(err, BAL_EINVAL,
                             "%s:%d: %s: a key outside any section; start with a "
                             "header such as [settings]", w.file, w.line, key);
        if (*value == '\0')
            return where_error(err, w, key, "%s", "expected a value after '='");
        if (assign(item, kind, key, value, w, err))
            return err->code;
    }
    return BAL_OK;
}

enum bal_status bal_scene_parse(struct bal_scene *s, const char *text,
                                const char *name, struct bal_error *err)
{
    /* The sections the scene holds already (a second text parsed into it)
     * are in the index from the start. */
    struct name_index ix = {NULL, 0, 0};
    enum bal_status st = BAL_OK;
    for (int k = 0; k < BAL_SEC_COUNT && st == BAL_OK; k++)
        for (int i = 0; bal_scene_sections[k].named && i < bal_scene_count(s, k) && st == BAL_OK;
             i++)
            if (index_add(&ix, s, (enum bal_section_kind)k, i))
                st = bal_error(err, BAL_ENOMEM, "%s: out of memory", name);
    if (st == BAL_OK)
        st = parse_text(s, text, name, &ix, err);
    free(ix.slot);
    return st;
}

enum bal_status bal_scene_load(struct bal_scene *s, const char *path,
                               struct bal_error *err)
{
    /* Only a regular file, never a FIFO or a device (import.c): an fopen
     * of a FIFO waited for a writer forever, and /dev/zero was read until
     * memory ran out. */
    char msg[BAL_MSG_MAX];
    enum bal_status st = BAL_OK;
    long n = 0;
    char *buf = bal_read_text_file(path, SCENE_MAX_BYTES, BAL_EIO, &n, &st, msg, sizeof msg);
    if (!buf)
        return bal_error(err, st, "%s", msg);
    if (memchr(buf, '\0', (size_t)n)) {
        free(buf);
        return bal_error(err, BAL_EINVAL, "%s: contains a NUL byte; not a scene file", path);
    }
    st = bal_scene_parse(s, buf, path, err);
    free(buf);
    return st;
}

enum bal_status bal_scene_set(struct bal_scene *s, const char *assignment,
                              struct bal_error *err)
{
    struct where w = {s->path, 0};
    char buf[LINE_MAX_CHARS];
    if (strlen(assignment) >= sizeof buf)
        return bal_error(err, BAL_EINVAL, "%s: --set: assignment too long", s->path);
    strcpy(buf, assignment);
    char *eq = strchr(buf, '=');
    if (!eq)
        return bal_error(err, BAL_EINVAL, "%s: --set %s: expected KEY=VALUE", s->path, assignment);
    *eq = '\0';
    char *path = trim(buf);
    char *value = trim(eq + 1);
    char *dot1 = strchr(path, '.');
    if (!dot1)
        return bal_error(err, BAL_EINVAL,
                         "%s: --set %s: expected section.key or section.name.key", s->path, path);
    *dot1 = '\0';
    int k = section_kind(path);
    if (k < 0)
        return bal_error(err, BAL_EINVAL, "%s: --set %s: unknown section '%s'", s->path,
                         assignment, path);
    char *rest = dot1 + 1;
    void *item;
    char *key;
    if (bal_scene_sections[k].named) {
        char *dot2 = strchr(rest, '.');
        if (!dot2)
            return bal_error(err, BAL_EINVAL, "%s: --set %s: expected %s.NAME.key", s->path,
                             assignment, path);
        *dot2 = '\0';
        int i = bal_scene_find(s, (enum bal_section_kind)k, rest);
        if (i < 0)
            return bal_error(err, BAL_EINVAL, "%s: --set %s: no [%s %s] in the scene", s->path,
                             assignment, path, rest);
        item = bal_scene_section(s, (enum bal_section_kind)k, i);
        key = dot2 + 1;
    } else {
        item = &s->settings;
        key = rest;
    }
    if (*value == '\0')
        return where_error(err, w, key, "%s", "expected a value after '='");
    return assign(item, (enum bal_section_kind)k, key, value, w, err);
}

/* ------------------------------------------------------------------ */
/* Keys that other keys make unused                                    */
/* ------------------------------------------------------------------ */

/* `ballast info`'s "unused" lines (the rules are scene_keys.c's table), in
 * the table's order, each section in file
 * order; the key as --set names it (settings.KEY, KIND.NAME.KEY). */
void bal_scene_print_unused(const struct bal_scene *s, FILE *out)
{
    for (size_t r = 0; r < bal_scene_n_unused; r++) {
        const struct bal_unused_rule *u = &bal_scene_unused[r];
        const struct bal_section_info *sec = &bal_scene_sections[u->section];
        const int ki = bal_scene_key_index(u->section, u->key);
        if (ki < 0) /* a rule naming no key (check_scene.c tests the table) */
            continue;
        for (int i = 0; i < bal_scene_count(s, u->section); i++) {
            void *item = bal_scene_section(s, u->section, i);
            if (!(*bal_scene_item_given(item, u->section) & (1u << ki)) || !u->holds(s, item))
                continue;
            if (sec->named)
                fprintf(out, "unused         %s.%s.%s (%s)\n", sec->name, bal_scene_item_name(item),
                        u->key, u->why);
            else
                fprintf(out, "unused         %s.%s (%s)\n", sec->name, u->key, u->why);
        }
    }
}
