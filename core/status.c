/*
 * status.c — status codes and the one function every error passes through.
 *
 * bal_error() formats a message into the caller's struct bal_error and
 * returns the code, so a failing function can write
 *     return bal_error(err, BAL_EINVAL, "%s:%d: %s: ...", file, line, key);
 * Set a breakpoint on bal_error to stop at the first error of any kind.
 * There is no global error state: the message lives in the caller's struct.
 */
#include <float.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "ballast.h"
#include "status.h"

/* The fewest significant digits bal_num_text prints: %g's default. */
#define BAL_NUM_DIGITS_FROM 6

enum bal_status bal_error(struct bal_error *err, enum bal_status code,
                          const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
        err->code = code;
    }
    return code;
}

const char *bal_num_text(char buf[BAL_NUM_CHARS], double v)
{
    /* From the 6 digits of %g (20, not 2e+01), up to DBL_DECIMAL_DIG (17),
     * which always read back; the first that does is the text a user typed
     * (up to 15 digits). */
    for (int digits = BAL_NUM_DIGITS_FROM; digits <= DBL_DECIMAL_DIG; digits++) {
        snprintf(buf, BAL_NUM_CHARS, "%.*g", digits, v);
        if (strtod(buf, NULL) == v)
            break;
    }
    return buf;
}

const char *bal_strerror(enum bal_status code)
{
    switch (code) {
    case BAL_OK: return "ok";
    case BAL_EINVAL: return "invalid input";
    case BAL_ENOMEM: return "out of memory";
    case BAL_EIO: return "input/output error";
    case BAL_EUNSTABLE: return "unstable";
    case BAL_EINTR: return "interrupted";
    }
    return "unknown status";
}
