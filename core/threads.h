/*
 * threads.h — internal: the disc–disc loop on several threads, bitwise as
 * on one (threads.c; struct bal_par in state.h).
 */
#ifndef BAL_THREADS_H
#define BAL_THREADS_H

#include "state.h"

/* Cut the disc–disc list into ranges for s->par.threads threads and size
 * their logs (the pair loop calls it after each rebuild). */
void bal_threads_plan(struct bal_sim *s);
/* Add what the ranges after the first logged to the discs' sums, in range
 * order (after the loop; shear: the logs carry moments, damp: the
 * dashpots' share). */
void bal_threads_replay(struct bal_sim *s, int shear, int damp);
/* Free what the threads hold. */
void bal_threads_free(struct bal_par *par);

#endif /* BAL_THREADS_H */
