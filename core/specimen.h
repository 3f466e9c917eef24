/*
 * specimen.h — internal: the discs a scene generates, in scene order
 * (specimen.c).
 */
#ifndef BAL_SPECIMEN_H
#define BAL_SPECIMEN_H

#include <stddef.h>
#include <stdint.h>

#include "ballast.h"

/* Most discs a scene may make (array indices are int32_t). */
#define BAL_MAX_DISCS 100000000L

/* The discs of a scene in scene order ([disc] sections, then each [fill],
 * [pile], [grains], [import]), before the builder sorts them into cell order: one
 * column per property, n entries each. */
struct bal_specimen {
    double *x, *y, *r, *vx, *vy, *th, *w;
    int32_t *mat;                /* material index in the scene */
    uint8_t *fixed;              /* 1: held */
    uint8_t *hold;               /* BAL_HOLD_* bits of a partly held disc, else 0 */
    int32_t *row;                /* row M of a pile disc, -1 otherwise */
};

/* Discs the scene makes: its [disc] sections and what its generators lay
 * (may exceed BAL_MAX_DISCS: the builder refuses that). */
long bal_specimen_count(const struct bal_scene *sc);
/* "FILE:LINE: KEY: [KIND NAME]" of the key that sets the count of the
 * generator whose discs carry the scene past `limit` discs (the one that
 * makes disc `limit` in scene order), or FILE alone when none does (for the
 * builder's message when a scene makes too many discs). */
void bal_specimen_count_origin(const struct bal_scene *sc, long limit, char *buf, size_t size);
/* Number of rows and of discs a [pile] generates. */
long bal_specimen_pile_rows(const struct bal_pile_def *p);
long bal_specimen_pile_count(const struct bal_pile_def *p);
/* Lay out the n discs of the scene into d (which it allocates; free with
 * bal_specimen_free, also after a failure). */
enum bal_status bal_specimen_generate(const struct bal_scene *sc, int n, struct bal_specimen *d,
                                      struct bal_error *err);
void bal_specimen_free(struct bal_specimen *d);

/* The diameter of a [grains] grading curve for the uniforms u1 (which piece
 * of the curve) and u2 (where in it), u1, u2 in [0, 1): the inverse of the
 * number distribution whose area distribution is the curve (grading.c). */
double bal_specimen_grading_diameter(const struct bal_grains_def *g, double u1, double u2);
/* The curve itself: the share of the area in discs of diameter <= d. */
double bal_specimen_grading_finer(const struct bal_grains_def *g, double d);

/* Can a [grains] section's discs be placed at all?  0; or 1 with the key
 * to blame in *key ("n", "origin" or "size") and why in `why`: more discs
 * of diameter dmin than the densest packing puts in the region, or a
 * region where the spacing of doubles is not small against the smallest
 * radius (grading.c).  Validation asks it, before anything is drawn. */
int bal_specimen_grains_check(const struct bal_grains_def *g, const char **key, char *why,
                              size_t size);

/* The name of the disc with scene-order index id: its [disc] name, or
 * FILL.k / PILE.k for the k-th disc a generator made. */
void bal_specimen_disc_name(const struct bal_scene *sc, int id, char *buf, size_t size);
/* The section the disc with scene-order index id came from, and its index among that
 * section's discs in *index: a [disc]'s name and 0, or the generator's name and k (the disc
 * it names NAME.k). */
const char *bal_specimen_disc_source(const struct bal_scene *sc, int id, long *index);
/* The scene-order index of the disc a probe names: a [disc]'s name, or
 * NAME.k, the k-th disc of the [fill], [pile], [grains] or [import] named
 * NAME (as bal_specimen_disc_name names it).  -1 with the reason in `why`
 * ("no disc or wall named ...", k past the generator's discs, or two
 * generators of that name). */
long bal_specimen_find_disc(const struct bal_scene *sc, const char *name, char *why, size_t size);
/* A property of a disc, for naming where the scene set it. */
enum bal_disc_prop { BAL_DISC_PLACE, BAL_DISC_SIZE, BAL_DISC_SPEED, BAL_DISC_SPIN };
/* "FILE:LINE: KEY: disc NAME" of the key that set property `prop` of the
 * disc with scene-order index id: its [disc] key, or the key of the [fill]
 * or [pile] that generated it (the section's header line when the key was
 * left at its default). */
void bal_specimen_disc_origin(const struct bal_scene *sc, int id, enum bal_disc_prop prop,
                              char *buf, size_t size);

#endif /* BAL_SPECIMEN_H */
