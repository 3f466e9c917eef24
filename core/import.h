/*
 * import.h — internal: the data files of an [import] section, a discs.tsv
 * and a walls.tsv a run wrote, read into the scene (import.c).
 */
#ifndef BAL_IMPORT_H
#define BAL_IMPORT_H

#include <stddef.h>

#include "ballast.h"

/* Read the data file at `path` (what: "discs" or "walls") into imp,
 * replacing what it held only on success.  On failure returns BAL_EINVAL
 * (missing file, bad row, missing column) or BAL_EIO / BAL_ENOMEM, with
 * "PATH:LINE: what was expected" in msg; the caller prefixes the scene's
 * file, line and key. */
enum bal_status bal_import_read(struct bal_import_def *imp, const char *what, const char *path,
                                char *msg, size_t size);
/* The whole of the regular file at `path`, NUL-terminated (its length in
 * *len), or NULL with *st and "PATH: why" in msg: `missing` for a file
 * that cannot be opened; BAL_EINVAL for one that is not a regular file (a
 * FIFO, a device, a directory) or is larger than max_bytes; BAL_EIO,
 * BAL_ENOMEM.  Never blocks on what it is given: the scene file and the
 * data files of [import] are read with it.  Free the text with free(). */
char *bal_read_text_file(const char *path, long max_bytes, enum bal_status missing, long *len,
                         enum bal_status *st, char *msg, size_t size);
/* Release the data of imp (its arrays; the keys stay). */
void bal_import_free(struct bal_import_def *imp);
/* Did the discs.tsv have the columns vx, vy, omega?  (velocities = 1 needs them.) */
int bal_import_has_velocities(const struct bal_import_def *imp);

#endif /* BAL_IMPORT_H */
