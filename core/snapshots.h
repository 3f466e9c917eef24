/*
 * snapshots.h — internal: the snapshots of a run (snapshots.c), for the
 * life cycle in sim.c.
 */
#ifndef BAL_SNAPSHOTS_H
#define BAL_SNAPSHOTS_H

#include <stddef.h>

#include "state.h"

/* At creation, after the stages' cycles are known: the schedule of
 * settings.snapshot_every or snapshot_dt and room for every frame the run can
 * have (a scene whose frames would pass BAL_SNAPSHOT_FRAMES_MAX is refused,
 * naming the key).  No frame is due until bal_sim_set_snapshots names a
 * folder. */
enum bal_status bal_snapshots_setup(struct bal_sim *s, struct bal_error *err);
/* The frame of the current state: its files, then snapshots.pvd (with vtk)
 * and index.tsv rewritten to list it; the next frame's cycle in s->snap.next.
 * Called by the run loop when s->step == s->snap.next. */
enum bal_status bal_snapshots_frame(struct bal_sim *s, struct bal_error *err);
/* The final state as the last frame, unless the last frame written is of this
 * cycle (or snapshots are off). */
enum bal_status bal_snapshots_last(struct bal_sim *s, struct bal_error *err);

/* The name of a frame's file: PART.FFFFFF.EXT ("discs", 12, "tsv": discs.000012.tsv). */
void bal_snapshots_name(char *buf, size_t size, const char *part, long frame, const char *ext);

/* Frames are numbered in six digits (discs.FFFFFF.tsv): at most a million, which
 * is 3 million files in one folder (6 with vtk). */
#define BAL_SNAPSHOT_FRAMES_MAX 1000000L

#endif /* BAL_SNAPSHOTS_H */
