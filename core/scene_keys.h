/*
 * scene_keys.h — internal: the table of scene keys shared by the parser,
 * the range checks, `ballast keys` and the key tables of docs/scene-format.md
 * (scene_keys.c).
 *
 * A scene file is a sequence of sections.  `[settings]` appears at most
 * once; the other kinds are named (`[disc x]`) and may repeat.  Each key of
 * a section kind is one row of bal_scene_keys: its type, where it lives in
 * the section's struct, its default (as text, parsed like a value from a
 * file, so the table is the only place a default is written), its range and
 * a one-line doc.
 */
#ifndef BAL_SCENE_KEYS_H
#define BAL_SCENE_KEYS_H

#include <stddef.h>

#include "ballast.h"

enum bal_key_type {
    BAL_KEY_DOUBLE,   /* one finite number */
    BAL_KEY_LONG,     /* one integer */
    BAL_KEY_VEC2,     /* two finite numbers */
    BAL_KEY_NAME,     /* a name of another section (resolved in validate) */
    BAL_KEY_ENUM,     /* one word of `choices` (space separated), stored as int */
    BAL_KEY_CONTROL,  /* repeatable: a wall controller's line of a stage, "WALL" and its
                       * numbers (struct bal_move_def; see struct bal_key) */
    BAL_KEY_FILE,     /* a data file's path, relative to the scene's directory, read when
                       * the key is parsed: `choices` says what it holds ("discs", "walls";
                       * import.c), the section struct its data */
    BAL_KEY_FLAGS,    /* any of the words of `choices`, or "none", stored as an int with
                       * bit k for the k-th word */
    BAL_KEY_BODY      /* a disc or a wall: a name, or NAME.k for the k-th disc of the
                       * generator NAME (resolved in validate; specimen.c) */
};

enum bal_section_kind {
    BAL_SEC_SETTINGS, BAL_SEC_MATERIAL, BAL_SEC_DISC, BAL_SEC_WALL,
    BAL_SEC_FILL, BAL_SEC_PILE, BAL_SEC_GRAINS, BAL_SEC_IMPORT, BAL_SEC_STAGE, BAL_SEC_PROBE,
    BAL_SEC_COUNT
};

struct bal_key {
    enum bal_section_kind section;
    const char *name;
    enum bal_key_type type;
    size_t offset;          /* offset of the value in the section struct */
    const char *def;        /* default as text; NULL = required (or empty) */
    int required;           /* 1: validate refuses a section without it */
    double min, max;        /* inclusive range for numbers */
    const char *choices;    /* BAL_KEY_ENUM: the words; BAL_KEY_CONTROL: the form,
                             * "WALL" and one word per number, which go to consecutive
                             * doubles of struct bal_move_def from `offset` on */
    const char *doc;        /* one line for `ballast keys` and docs/scene-format.md */
};

/* The wall controller that each BAL_KEY_CONTROL key of a stage names. */
struct bal_control_key {
    const char *key;        /* the stage key */
    int control;            /* enum bal_wall_control */
};

/* Most numbers a wall controller's key takes after the wall's name. */
#define BAL_CONTROL_VALUES_MAX 8

struct bal_section_info {
    const char *name;       /* as written between the brackets */
    int named;              /* 1: "[kind NAME]" */
    size_t size;            /* sizeof the section struct */
    size_t given_offset;    /* offsetof(struct, given) */
    size_t key_line_offset; /* offsetof(struct, key_line) */
    const char *doc;
};

/* A key that the values of other keys make unused: whatever its value, the run is the
 * same (only run.json's "sets" and echoed settings say it was given).  `holds` says
 * whether that is so for one section of kind `section` (`item`, its struct) in scene s;
 * `why` says it in the scene's words.  `ballast info` lists the given keys a rule holds
 * for (bal_scene_print_unused), and the harness refuses to sweep them. */
struct bal_unused_rule {
    enum bal_section_kind section;
    const char *key;
    const char *why;
    int (*holds)(const struct bal_scene *s, const void *item);
};

extern const struct bal_key bal_scene_keys[];
extern const size_t bal_scene_n_keys;
extern const struct bal_section_info bal_scene_sections[BAL_SEC_COUNT];
extern const struct bal_control_key bal_scene_controls[];
extern const size_t bal_scene_n_controls;
extern const struct bal_unused_rule bal_scene_unused[];
extern const size_t bal_scene_n_unused;

/* Index of key `name` within its section kind, or -1. */
int bal_scene_key_index(enum bal_section_kind sec, const char *name);
/* The k-th key of a section kind (k = index within that kind). */
const struct bal_key *bal_scene_key_at(enum bal_section_kind sec, int k);
/* The controller a BAL_KEY_CONTROL key names, or -1; the key of a
 * controller, or NULL. */
int bal_scene_key_control(const char *key);
const char *bal_scene_key_for_control(int control);

#endif /* BAL_SCENE_KEYS_H */
