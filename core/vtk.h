/*
 * vtk.h — internal: a snapshot as VTK XML PolyData, and the ParaView
 * collection of the frames (vtk.c).
 */
#ifndef BAL_VTK_H
#define BAL_VTK_H

#include <stdio.h>

#include "state.h"

/* The discs as points at their centres, in scene order, with point data radius, id,
 * velocity, omega, theta, force, torque, fixed. */
void bal_vtk_discs(const struct bal_sim *s, FILE *f);
/* The touching contacts as lines, in the order of contacts.tsv, with cell data fn, fs, mr
 * (with rolling resistance), sliding, rolling, kind. */
void bal_vtk_contacts(const struct bal_sim *s, FILE *f);
/* The walls as lines from end A to end B, with cell data f. */
void bal_vtk_walls(const struct bal_sim *s, FILE *f);
/* snapshots.pvd: the frames written so far, each at its simulated time, in three parts
 * (0 discs, 1 contacts, 2 walls). */
void bal_vtk_collection(const struct bal_sim *s, FILE *f);

#endif /* BAL_VTK_H */
