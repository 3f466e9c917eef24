/*
 * grid.h — internal: the neighbour search that fills the candidate lists
 * (grid.c).
 */
#ifndef BAL_GRID_H
#define BAL_GRID_H

#include <stdint.h>

#include "state.h"

/* Build the candidate lists anew from the current positions, carrying the
 * contact history over; grows the lists (the only place that does). */
enum bal_status bal_grid_rebuild(struct bal_sim *s, struct bal_error *err);
/* Do the lists still hold every contact, after the discs moved by `moved`
 * (the position pass's; each block's in par.block_sums) and the walls by
 * their `disp`?  1: a rebuild is due (or the search cannot tell cheaply);
 * always 0 without the grid, whose one list holds every pair. */
int bal_grid_due(const struct bal_sim *s, struct bal_moves moved);
/* Re-sort the discs into cell order of their current positions, carrying
 * every per-disc array and the probes along, then rebuild the lists (their
 * history found through the permutation). */
enum bal_status bal_grid_reorder(struct bal_sim *s, struct bal_error *err);
/* The permutation that puts discs in row-major order of cells of side h
 * (order[new] = old); ties keep their order, so it is deterministic.
 * `keys` is scratch of n entries. */
void bal_grid_cell_order(const double *x, const double *y, int n, double h,
                         struct bal_cell_key *keys, int32_t *order);
/* Rebuilds between two re-sorts: the order decays only as discs flow, and a
 * re-sort costs about as much as a few rebuilds. */
#define BAL_REORDER_EVERY 20
/* Most candidates one disc can have in a rebuild; a disc of radius r_min
 * cannot have more non-overlapping neighbours within 2 r_max + skin.  The
 * generator keeps radius ratios moderate; beyond this the rebuild fails
 * (and sets s->crowded). */
#define BAL_MAX_NEIGHBOURS 512
void bal_grid_free(struct bal_grid *g);
void bal_grid_scratch_free(struct bal_rebuild_scratch *rs);
/* With fewer discs than this, `grid = auto` uses all pairs.  Measured with
 * `build/bench --grid cases/bench/dense.scene` (docs/benchmarks.md, "Neighbour search"):
 * the Verlet-listed grid was faster at every N >= 4, settled or falling
 * (1.2-1.5x at N = 4-16, 14x at N = 256), so all pairs serve only scenes of
 * two or three discs, whose single list is built once. */
#define BAL_GRID_CROSSOVER 4

#endif /* BAL_GRID_H */
