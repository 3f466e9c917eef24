/*
 * import.c — the data files of an [import] section: a prepared state, read
 * once when the scene is parsed and loaded unchanged by every run that
 * imports it (STYLE.md: "a specimen is generated, then cached as data").
 *
 * Both are the tab-separated files a run writes (output.c): a header line
 * of column names, then one row per body.  Columns are found by name, so a
 * file with more columns (the run's m, row, forces) reads the same; blank
 * lines are skipped.
 *
 *   discs.tsv  x y r theta (degrees) are required; vx vy omega are read
 *              when present (the section's `velocities` uses them), fixed
 *              (0 or 1) when present.  One disc per row, in file order.
 *              Numbers are read with strtod: the run printed them with
 *              %.17g, so x, y, r come back as the same doubles; theta,
 *              written in degrees, comes back within an ulp or two of the
 *              radians it was.
 *   walls.tsv  name ax ay bx by are required: a wall from A to B (P = A,
 *              α = atan2(B − A), h1 = 0, h2 = |B − A|), with its name.
 *
 * Every error names the data file and its line ("PATH:LINE: x: expected a
 * finite number, got 'abc'"); scene.c puts the scene's file, line and key
 * in front.  A file that cannot be read in whole leaves the section as it
 * was (a failed --set must not change the scene).
 */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "import.h"
#include "specimen.h"

/* Largest data file read (a discs.tsv of 10 million discs is ~2 GB). */
#define IMPORT_MAX_BYTES (4L << 30)
/* Most columns a header may have. */
#define IMPORT_MAX_COLUMNS 64
/* Most walls a walls.tsv may hold: each is checked against the others by
 * name (pair by pair: 10 000 walls take 0.4 s, 200 000 would take 2.5
 * minutes) and every rebuild of the lists tests every disc against every
 * wall (grid.c).  A run writes the walls of its scene: four for a box. */
#define IMPORT_MAX_WALLS 10000

/* What a file that is not regular is, for the message. */
static const char *file_kind(mode_t mode)
{
    return S_ISFIFO(mode)  ? "a FIFO (named pipe)"
           : S_ISDIR(mode) ? "a directory"
           : S_ISCHR(mode) ? "a character device"
           : S_ISBLK(mode) ? "a block device"
           : S_ISSOCK(mode) ? "a socket"
                            : "a file of another kind";
}

char *bal_read_text_file(const char *path, long max_bytes, enum bal_status missing, long *len,
                         enum bal_status *st, char *msg, size_t size)
{
    /* A FIFO blocks an fopen until a writer comes, a terminal or
     * /dev/stdin until input ends, and /dev/zero never ends: only a regular
     * file is read.  stat() first, so that no device is even opened; then
     * open without blocking and fstat() what was opened, in case the path
     * changed in between. */
    struct stat sb;
    if (stat(path, &sb) != 0) {
        snprintf(msg, size, "%s: cannot open: %s", path, strerror(errno));
        *st = missing;
        return NULL;
    }
    int fd = -1;
    if (S_ISREG(sb.st_mode)) {
        fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
        if (fd < 0) {
            snprintf(msg, size, "%s: cannot open: %s", path, strerror(errno));
            *st = missing;
            return NULL;
        }
        if (fstat(fd, &sb) != 0)
            sb.st_mode = 0;
    }
    if (!S_ISREG(sb.st_mode)) {
        snprintf(msg, size, "%s: not a regular file: %s; expected a file of text", path,
                 file_kind(sb.st_mode));
        if (fd >= 0)
            close(fd);
        *st = BAL_EINVAL;
        return NULL;
    }
    if (sb.st_size > max_bytes) {
        snprintf(msg, size, "%s: %lld bytes; expected a file of at most %ld bytes", path,
                 (long long)sb.st_size, max_bytes);
        close(fd);
        *st = BAL_EINVAL;
        return NULL;
    }
    char *buf = malloc((size_t)sb.st_size + 1);
    if (!buf) {
        snprintf(msg, size, "%s: out of memory", path);
        close(fd);
        *st = BAL_ENOMEM;
        return NULL;
    }
    /* Up to the size fstat gave (a file that grows meanwhile is read as it
     * was); one that shrinks ends early, at its end. */
    size_t got = 0;
    int bad = 0;
    while (got < (size_t)sb.st_size) {
        const ssize_t r = read(fd, buf + got, (size_t)sb.st_size - got);
        if (r < 0 && errno == EINTR)
            continue;
        if (r < 0)
            bad = 1;
        if (r <= 0)
            break;
        got += (size_t)r;
    }
    close(fd);
    if (bad) {
        snprintf(msg, size, "%s: read error: %s", path, strerror(errno));
        free(buf);
        *st = BAL_EIO;
        return NULL;
    }
    buf[got] = '\0';
    *len = (long)got;
    return buf;
}

/* The whole data file, NUL-terminated, or NULL with the reason in msg. */
static char *read_file(const char *path, long *len, enum bal_status *st, char *msg, size_t size)
{
    char *buf = bal_read_text_file(path, IMPORT_MAX_BYTES, BAL_EINVAL, len, st, msg, size);
    if (buf && memchr(buf, '\0', (size_t)*len)) {
        snprintf(msg, size, "%s: contains a NUL byte; not a data file", path);
        free(buf);
        *st = BAL_EINVAL;
        return NULL;
    }
    return buf;
}

/* A line cut into its tab-separated fields (in place). */
struct fields {
    int n;
    char *f[IMPORT_MAX_COLUMNS];
};

static int split(char *line, struct fields *out)
{
    out->n = 0;
    for (char *p = line;;) {
        if (out->n == IMPORT_MAX_COLUMNS)
            return 0;
        out->f[out->n++] = p;
        char *tab = strchr(p, '\t');
        if (!tab)
            break;
        *tab = '\0';
        p = tab + 1;
    }
    /* a Windows line end */
    char *last = out->f[out->n - 1];
    const size_t l = strlen(last);
    if (l > 0 && last[l - 1] == '\r')
        last[l - 1] = '\0';
    return 1;
}

static int is_blank(const char *s)
{
    for (; *s; s++)
        if (*s != ' ' && *s != '\t' && *s != '\r')
            return 0;
    return 1;
}

/* Cuts buf into lines; calls row(ctx, fields, line number) for the header
 * (the first line that is not blank) and for every other line that is not
 * blank.  Stops at the first non-zero return. */
struct reader {
    const char *path;
    char *msg;
    size_t size;
    int column[IMPORT_MAX_COLUMNS]; /* index of each wanted column in a row, or -1 */
    int n_columns;                  /* fields of the header */
};

static int find_columns(struct reader *r, const struct fields *h, const char *const *names,
                        int n_names, int n_required, int line)
{
    for (int k = 0; k < n_names; k++) {
        r->column[k] = -1;
        for (int c = 0; c < h->n; c++)
            if (strcmp(h->f[c], names[k]) == 0)
                r->column[k] = c;
        if (r->column[k] < 0 && k < n_required) {
            snprintf(r->msg, r->size, "%s:%d: no column '%s' in the header (expected the columns "
                                      "a run writes)", r->path, line, names[k]);
            return 1;
        }
    }
    r->n_columns = h->n;
    return 0;
}

/* One finite number from a whole field. */
static int number(struct reader *r, const char *field, const char *column, int line, double *out)
{
    char *end;
    errno = 0;
    const double v = strtod(field, &end);
    if (end == field || *end != '\0' || !isfinite(v) || (errno == ERANGE && v == 0)) {
        snprintf(r->msg, r->size, "%s:%d: %s: expected a finite number, got '%.40s'", r->path,
                 line, column, field);
        return 1;
    }
    *out = v;
    return 0;
}

static int valid_wall_name(const char *v)
{
    if (!*v || strlen(v) >= BAL_NAME_MAX)
        return 0;
    for (const char *c = v; *c; c++)
        if (!((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') ||
              *c == '_' || *c == '-'))
            return 0;
    return 1;
}

static const char *const disc_columns[] = {"x", "y", "r", "theta", "vx", "vy", "omega", "fixed"};
static const char *const wall_columns[] = {"name", "ax", "ay", "bx", "by"};

/* The next line of text that is not blank, split into fields (p moves past
 * it, line counts it): 1; 0 at the end of the text; -1 when it has too many
 * columns (r->msg says so). */
static int next_row(struct reader *r, char **p, int *line, struct fields *fl)
{
    while (**p || *line == 0) {
        (*line)++;
        char *nl = strchr(*p, '\n');
        if (nl)
            *nl = '\0';
        char *cur = *p;
        *p = nl ? nl + 1 : *p + strlen(*p);
        if (is_blank(cur)) {
            if (!nl)
                return 0;
            continue;
        }
        if (!split(cur, fl)) {
            snprintf(r->msg, r->size, "%s:%d: more than %d columns", r->path, *line,
                     IMPORT_MAX_COLUMNS);
            return -1;
        }
        return 1;
    }
    return 0;
}

static enum bal_status read_discs(struct bal_import_def *imp, struct reader *r, char *text)
{
    long n = 0, cap = 0;
    double *data = NULL;
    int *rows = NULL;
    int header = 0, line = 0, velocity_columns = 0;
    enum bal_status st = BAL_OK;
    char *p = text;
    struct fields fl;
    int got;
    while ((got = next_row(r, &p, &line, &fl)) > 0) {
        if (!header) {
            header = 1;
            if (find_columns(r, &fl, disc_columns, BAL_IMPORT_COLUMNS, 4, line)) {
                st = BAL_EINVAL;
                break;
            }
            velocity_columns = r->column[BAL_IMPORT_VX] >= 0 && r->column[BAL_IMPORT_VY] >= 0 &&
                               r->column[BAL_IMPORT_OMEGA] >= 0;
            continue;
        }
        if (fl.n != r->n_columns) {
            snprintf(r->msg, r->size, "%s:%d: expected %d columns as in the header, got %d",
                     r->path, line, r->n_columns, fl.n);
            st = BAL_EINVAL;
            break;
        }
        if (n == BAL_MAX_DISCS) { /* before memory for more: 68 bytes a row of 8 */
            snprintf(r->msg, r->size, "%s:%d: more than %ld discs, the most a scene may hold",
                     r->path, line, BAL_MAX_DISCS);
            st = BAL_EINVAL;
            break;
        }
        if (n == cap) {
            cap = cap ? 2 * cap : 1024;
            double *d = realloc(data, (size_t)cap * BAL_IMPORT_COLUMNS * sizeof *d);
            int *q = d ? realloc(rows, (size_t)cap * sizeof *q) : NULL;
            if (d)
                data = d;
            if (q)
                rows = q;
            if (!d || !q) {
                snprintf(r->msg, r->size, "%s:%d: out of memory", r->path, line);
                st = BAL_ENOMEM;
                break;
            }
        }
        double *row = data + n * BAL_IMPORT_COLUMNS;
        int bad = 0;
        for (int k = 0; k < BAL_IMPORT_COLUMNS && !bad; k++) {
            row[k] = 0;
            if (r->column[k] >= 0)
                bad = number(r, fl.f[r->column[k]], disc_columns[k], line, &row[k]);
        }
        if (!bad && !(row[BAL_IMPORT_R] > 0)) {
            snprintf(r->msg, r->size, "%s:%d: r: expected a radius > 0, got %.17g", r->path, line,
                     row[BAL_IMPORT_R]);
            bad = 1;
        }
        if (!bad && row[BAL_IMPORT_FIXED] != 0 && row[BAL_IMPORT_FIXED] != 1) {
            snprintf(r->msg, r->size, "%s:%d: fixed: expected 0 or 1, got %.17g", r->path, line,
                     row[BAL_IMPORT_FIXED]);
            bad = 1;
        }
        if (bad) {
            st = BAL_EINVAL;
            break;
        }
        rows[n++] = line;
    }
    if (got < 0)
        st = BAL_EINVAL;
    if (st == BAL_OK && !header) {
        snprintf(r->msg, r->size, "%s:1: empty: expected a header line and a row per disc", r->path);
        st = BAL_EINVAL;
    } else if (st == BAL_OK && n == 0) {
        snprintf(r->msg, r->size, "%s:%d: no disc rows after the header", r->path, line);
        st = BAL_EINVAL;
    }
    if (st != BAL_OK) {
        free(data);
        free(rows);
        return st;
    }
    free(imp->disc_data);
    free(imp->disc_row);
    imp->disc_data = data;
    imp->disc_row = rows;
    imp->n = n;
    imp->velocity_columns = velocity_columns;
    return BAL_OK;
}

static enum bal_status read_walls(struct bal_import_def *imp, struct reader *r, char *text)
{
    int n = 0, cap = 0;
    struct bal_import_wall *walls = NULL;
    int header = 0, line = 0;
    enum bal_status st = BAL_OK;
    char *p = text;
    struct fields fl;
    int got;
    while ((got = next_row(r, &p, &line, &fl)) > 0) {
        if (!header) {
            header = 1;
            if (find_columns(r, &fl, wall_columns, 5, 5, line)) {
                st = BAL_EINVAL;
                break;
            }
            continue;
        }
        if (fl.n != r->n_columns) {
            snprintf(r->msg, r->size, "%s:%d: expected %d columns as in the header, got %d",
                     r->path, line, r->n_columns, fl.n);
            st = BAL_EINVAL;
            break;
        }
        if (n == IMPORT_MAX_WALLS) {
            snprintf(r->msg, r->size, "%s:%d: more than %d walls (a rebuild tests every disc "
                     "against every wall)", r->path, line, IMPORT_MAX_WALLS);
            st = BAL_EINVAL;
            break;
        }
        if (n == cap) {
            cap = cap ? 2 * cap : 16;
            struct bal_import_wall *q = realloc(walls, (size_t)cap * sizeof *q);
            if (!q) {
                snprintf(r->msg, r->size, "%s:%d: out of memory", r->path, line);
                st = BAL_ENOMEM;
                break;
            }
            walls = q;
        }
        struct bal_import_wall *w = &walls[n];
        const char *name = fl.f[r->column[0]];
        if (!valid_wall_name(name)) {
            snprintf(r->msg, r->size, "%s:%d: name: expected a name of letters, digits, '_' or '-' "
                                      "(at most 47), got '%.60s'", r->path, line, name);
            st = BAL_EINVAL;
            break;
        }
        for (int k = 0; k < n && st == BAL_OK; k++)
            if (strcmp(walls[k].name, name) == 0) {
                snprintf(r->msg, r->size, "%s:%d: name: wall '%s' is also on line %d", r->path,
                         line, name, walls[k].row);
                st = BAL_EINVAL;
            }
        if (st != BAL_OK)
            break;
        strcpy(w->name, name);
        w->row = line;
        double v[4];
        int bad = 0;
        for (int k = 0; k < 4 && !bad; k++)
            bad = number(r, fl.f[r->column[k + 1]], wall_columns[k + 1], line, &v[k]);
        if (!bad && !(hypot(v[2] - v[0], v[3] - v[1]) > 0)) {
            snprintf(r->msg, r->size, "%s:%d: bx: the wall '%s' has A = B: no length", r->path,
                     line, name);
            bad = 1;
        }
        if (bad) {
            st = BAL_EINVAL;
            break;
        }
        w->a[0] = v[0];
        w->a[1] = v[1];
        w->b[0] = v[2];
        w->b[1] = v[3];
        n++;
    }
    if (got < 0)
        st = BAL_EINVAL;
    if (st == BAL_OK && !header) {
        snprintf(r->msg, r->size, "%s:1: empty: expected a header line and a row per wall", r->path);
        st = BAL_EINVAL;
    }
    if (st != BAL_OK) {
        free(walls);
        return st;
    }
    free(imp->wall_data);
    imp->wall_data = walls;
    imp->n_walls = n;
    return BAL_OK;
}

enum bal_status bal_import_read(struct bal_import_def *imp, const char *what, const char *path,
                                char *msg, size_t size)
{
    enum bal_status st = BAL_OK;
    long len = 0;
    char *text = read_file(path, &len, &st, msg, size);
    if (!text)
        return st;
    struct reader r = {.path = path, .msg = msg, .size = size};
    /* A UTF-8 byte-order mark, which some editors and spreadsheets put at
     * the start of a file, is not part of the first column's name (the
     * scene parser skips it too). */
    char *start = strncmp(text, "\xEF\xBB\xBF", 3) == 0 ? text + 3 : text;
    st = strcmp(what, "discs") == 0 ? read_discs(imp, &r, start) : read_walls(imp, &r, start);
    free(text);
    return st;
}

void bal_import_free(struct bal_import_def *imp)
{
    free(imp->disc_data);
    free(imp->disc_row);
    free(imp->wall_data);
    imp->disc_data = NULL;
    imp->disc_row = NULL;
    imp->wall_data = NULL;
    imp->n = 0;
    imp->n_walls = 0;
}

int bal_import_has_velocities(const struct bal_import_def *imp)
{
    return imp->velocity_columns;
}
