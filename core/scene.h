/*
 * scene.h — internal: a parsed scene's sections, found by kind and name
 * (scene.c), for the validation (scene_validate.c) and for the modules that
 * build a simulation from the scene.
 */
#ifndef BAL_SCENE_H
#define BAL_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include "scene_keys.h"

/* Index of the named material / disc / wall / stage in s, or -1. */
int bal_scene_find(const struct bal_scene *s, enum bal_section_kind sec,
                   const char *name);
/* Section i of kind k (the settings for BAL_SEC_SETTINGS), and how many
 * sections of kind k the scene has (1 for the settings). */
void *bal_scene_section(const struct bal_scene *s, enum bal_section_kind k, int i);
int bal_scene_count(const struct bal_scene *s, enum bal_section_kind k);

/* Where the [settings] key `key` was given, for a message in the parser's forms: "FILE:LINE:
 * KEY" from the scene file, "FILE: --set KEY" from an override (or not given). */
void bal_scene_settings_where(const struct bal_scene *s, const char *key, char *buf, size_t size);

/* What every section struct shares: a named one starts with its name and
 * the line of its header; every one ends with BAL_SECTION_TAIL, which keys
 * were given and on which lines (at the offsets of the section table). */
static inline char *bal_scene_item_name(void *item)
{
    return (char *)item;
}

static inline int *bal_scene_item_line(void *item)
{
    return (int *)((char *)item + BAL_NAME_MAX);
}

static inline uint32_t *bal_scene_item_given(void *item, enum bal_section_kind k)
{
    return (uint32_t *)((char *)item + bal_scene_sections[k].given_offset);
}

static inline int *bal_scene_item_key_line(void *item, enum bal_section_kind k)
{
    return (int *)((char *)item + bal_scene_sections[k].key_line_offset);
}

#endif /* BAL_SCENE_H */
