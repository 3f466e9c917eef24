/*
 * pairs.h — internal: the candidate lists, their storage and the queries on
 * a candidate (pairs.c).
 */
#ifndef BAL_PAIRS_H
#define BAL_PAIRS_H

#include <stddef.h>
#include <stdint.h>

#include "state.h"

/* Candidates per chunk of the disc–disc loop (pair_loop.c), each chunk with
 * its own friction sum (par.chunk_sums). */
#define BAL_PAIRS_CHUNK 256

/* Chunks of a list of n candidates. */
static inline long bal_pairs_chunks(long n) { return (n + BAL_PAIRS_CHUNK - 1) / BAL_PAIRS_CHUNK; }

/* Room for cap candidates in list p (its own columns); BAL_ENOMEM, the list
 * unchanged, if memory runs out. */
enum bal_status bal_pairs_reserve(struct bal_pairs *p, long cap);
void bal_pairs_free(struct bal_pairs *p);
/* The per-chunk sums of the disc–disc list, for its capacity (after every
 * reserve of s->pp). */
enum bal_status bal_pairs_reserve_chunks(struct bal_sim *s);
/* Position of `key` in the sorted list p, or -1 (binary search). */
long bal_pairs_find(const struct bal_pairs *p, uint64_t key);

/* Candidate index of the contact between two bodies (for each, whether it
 * is a wall and its slot or index), or -1; *list receives its list. */
long bal_pairs_find_contact(const struct bal_sim *s, int a_wall, int a, int b_wall, int b,
                            const struct bal_pairs **list);
/* Candidate c of the disc–disc list (walls = 0) or of the disc–wall list
 * (walls = 1): its overlap δ (negative: a gap), the smaller radius of its
 * bodies and their pair law. */
double bal_pairs_overlap(const struct bal_sim *s, int walls, long c, double *rmin,
                         const struct bal_pair_law **law);
/* The names of its bodies for messages: "A" and "disc B" or "wall W". */
void bal_pairs_names(const struct bal_sim *s, int walls, long c, char *a, size_t na, char *b,
                     size_t nb);

#endif /* BAL_PAIRS_H */
