/*
 * contacts.h — internal: the force–displacement law at every contact, and
 * the threads that share the disc–disc loop (contacts.c).
 */
#ifndef BAL_CONTACTS_H
#define BAL_CONTACTS_H

#include "state.h"

/* The disc–disc loop compiled for this normal law (enum bal_normal_law),
 * with or without the tangential, the damping and the rolling kernels
 * (laws.h); chosen once per simulation. */
bal_pair_loop_fn bal_contacts_select(int normal_law, int shear, int damping, int rolling);
/* The disc–wall contacts of the cycle: their forces on the discs' sums and
 * the resultants on the walls (after the disc–disc loop started the sums). */
void bal_contacts_walls(struct bal_sim *s);

/* Cut the disc–disc list into ranges for s->par.threads threads (the pair
 * loop calls it after each rebuild); free what the threads hold. */
void bal_par_plan(struct bal_sim *s);
void bal_par_free(struct bal_par *par);

#endif /* BAL_CONTACTS_H */
