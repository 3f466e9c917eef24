/*
 * build.h — internal: the steps that build a simulation's state from a
 * validated scene (build.c), in the order bal_sim_create calls them.  Each
 * reads what the steps before it made; on failure the caller frees the
 * simulation whole.
 */
#ifndef BAL_BUILD_H
#define BAL_BUILD_H

#include "state.h"

/* The scalars of [settings]; the number of discs (at most BAL_MAX_DISCS). */
enum bal_status bal_build_settings(struct bal_sim *s, const struct bal_scene *sc,
                                   struct bal_error *err);
/* The contact parameters of every pair of materials. */
enum bal_status bal_build_materials(struct bal_sim *s, struct bal_error *err);
/* The walls: [wall] sections, fill boxes, pile floors. */
enum bal_status bal_build_walls(struct bal_sim *s, struct bal_error *err);
/* The discs in cell order, and what is derived from them (checked finite). */
enum bal_status bal_build_discs(struct bal_sim *s, struct bal_error *err);
/* The time step from the critical-step estimate. */
enum bal_status bal_build_timestep(struct bal_sim *s, struct bal_error *err);
/* The first candidate lists; overlaps at the start refused unless allowed. */
enum bal_status bal_build_lists(struct bal_sim *s, struct bal_error *err);
/* The probes' bodies as slots and wall indices. */
enum bal_status bal_build_probes(struct bal_sim *s, struct bal_error *err);
/* The stages' log; no stage selected yet. */
enum bal_status bal_build_stages(struct bal_sim *s, struct bal_error *err);

#endif /* BAL_BUILD_H */
