/*
 * output.h — internal: the tables of a state and the atomic file writing
 * that the final outputs (output.c) and the snapshots (snapshots.c, vtk.c)
 * share, so that a snapshot's rows are those of the final files.
 */
#ifndef BAL_OUTPUT_H
#define BAL_OUTPUT_H

#include <stdio.h>

#include "state.h"

/* dir/name.tmp opened for writing, or NULL with the error set. */
FILE *bal_output_open(const char *dir, const char *name, struct bal_error *err);
/* Close f (opened by bal_output_open) and rename dir/name.tmp to dir/name; on a write
 * error the .tmp is removed and nothing is renamed. */
enum bal_status bal_output_close(FILE *f, const char *dir, const char *name,
                                 struct bal_error *err);

/* The rows of discs.tsv (snapshot 0): id name x y r theta vx vy omega m fixed row; of a
 * snapshot's discs (snapshot 1): id name generator index x y r theta vx vy omega fx fy
 * torque m fixed, fx fy torque being the sums of the contact forces and moments on the
 * disc of the last cycle (what the law of motion adds gravity and global damping to). */
void bal_output_discs(const struct bal_sim *s, FILE *f, int snapshot);
/* The rows of contacts.tsv: every touching contact. */
void bal_output_contacts(const struct bal_sim *s, FILE *f);
/* The rows of walls.tsv. */
void bal_output_walls(const struct bal_sim *s, FILE *f);

/* The point and the unit normal (from the disc to the other body) of the touching
 * contact c of the disc–disc list (walls 0) or of the disc–wall list (walls 1), as
 * contacts.tsv writes them. */
void bal_output_contact_point(const struct bal_sim *s, int walls, long c, double *px, double *py,
                              double *nx, double *ny);

#endif /* BAL_OUTPUT_H */
