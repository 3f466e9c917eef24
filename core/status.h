/*
 * status.h — internal: numbers in messages (status.c).
 */
#ifndef BAL_STATUS_H
#define BAL_STATUS_H

/* Room for the longest text bal_num_text writes ("-2.2250738585072014e-308"). */
#define BAL_NUM_CHARS 32

/* The shortest %g text of v, of 6 significant digits or more, that reads
 * back (strtod) as v itself, in buf; returns buf.  A message that refuses a value beside its bound prints both
 * with it: two different doubles never print alike, so "2.0000001 is out of
 * range: expected 0 <= value <= 2" shows why, where %.6g printed "2" twice. */
const char *bal_num_text(char buf[BAL_NUM_CHARS], double v);
/* The same in a buffer of its own (a compound literal, alive to the end of
 * the enclosing block), for an argument of a message:
 *     bal_error(err, BAL_EINVAL, "got %s < %s", BAL_NUM(a), BAL_NUM(b)); */
#define BAL_NUM(v) bal_num_text((char[BAL_NUM_CHARS]){""}, (v))

#endif /* BAL_STATUS_H */
