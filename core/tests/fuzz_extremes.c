/*
 * fuzz_extremes.c — libFuzzer target for legal but extreme numbers (issue 18).
 *
 * Built and run by `make test-fuzz` with fuzz_scene.c.  Where that target
 * spends its inputs on the syntax, this one turns the fuzzer's bytes into a
 * well-formed scene, so that the coverage goes to the numbers: 1 to 8 [disc]
 * sections (sometimes a [fill] or a small [pile] besides), 1 to 3 materials,
 * up to 3 walls, 1 to 3 stages of a few cycles with walls moving, a probe of
 * every quantity, and settings.  Every number is drawn from the whole range
 * its key accepts (read from the key table, core/scene_keys.c, so that a
 * changed range is followed), biased toward the extremes: the bounds and
 * their neighbours, powers of ten from the smallest to the largest,
 * DBL_MIN, DBL_MAX, sqrt(DBL_MAX) and their neighbours, radii in ratios up
 * to the largest the format allows (1e-300 to DBL_MAX), kn up to 1e150; and
 * also moderate and plain numbers, so that ordinary scenes come out too and
 * the extremes meet ordinary partners.  Discs are placed touching, nearly
 * touching or far from an earlier disc or a wall, or anywhere.  The scene
 * is written as text ("%.17g": each number is read back exactly) and parsed
 * as file "fuzz.scene", which must take it (every value is in its key's
 * range), then goes through the checks of fuzz_common.h: validate, create
 * and run twice, every refusal naming its origin, every quantity of a run
 * that returns BAL_OK finite.  A legal scene this small runs in
 * milliseconds, so `core/tests/fuzz/run` gives this target a 3 s limit an
 * input: a time-step estimate that spins is a finding.
 *
 * BALLAST_FUZZ_PRINT=1 writes each scene to stderr before it is checked:
 * run the fuzzer on a saved input (`build/fuzz/fuzz_extremes FILE`) to get
 * the scene, which fuzz_scene replays (core/tests/fuzz/found/).
 * BALLAST_FUZZ_SKIP=ratio keeps every radius within a factor 100 of the
 * first disc's (no [pile] or [fill] of another size) and at most 1e302, to
 * hunt past the known hang and overflow of the time-step estimate's
 * coordination bound; fuzz_common.h lists the other switches.
 */
#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_common.h"

#define BIG DBL_MAX
#define MAX_DISCS 8
#define MAX_WALLS 3
#define MAX_MATERIALS 3
#define MAX_STAGES 3
#define MAX_CYCLES 6 /* per stage */

/* ---- the bytes ------------------------------------------------------------ */

struct src {
    const uint8_t *p;
    size_t n, i;
};

/* The next byte, 0 once they are used up (so a short input is a plain scene). */
static unsigned u8(struct src *s)
{
    return s->i < s->n ? s->p[s->i++] : 0;
}

static unsigned u16(struct src *s)
{
    const unsigned a = u8(s);
    return a | u8(s) << 8;
}

static uint64_t u64(struct src *s)
{
    uint64_t v = 0;
    for (int k = 0; k < 8; k++)
        v |= (uint64_t)u8(s) << (8 * k);
    return v;
}

/* 10^k as the nearest double (what the parser makes of "1e<k>"). */
static double pow10i(int k)
{
    char b[16];
    snprintf(b, sizeof b, "1e%d", k);
    return strtod(b, NULL);
}

static double clamp(double v, double lo, double hi)
{
    if (!isfinite(v))
        return v < 0 ? lo : hi;
    return v < lo ? lo : v > hi ? hi : v;
}

/* A computed number as the scene can hold it: the parser refuses subnormal
 * numbers (strtod's ERANGE, "expected one finite number"), so they become 0. */
static double tidy(double v)
{
    return v != 0 && !isnormal(v) && isfinite(v) ? 0 : v;
}

/* Numbers a scene writer would use. */
static const double plain[] = {1, 0, 0.5, 2, 0.1, 10, 100, 1e3, 1e5, 0.3, 0.01, 1e-3, 3, 45, 90,
                               180, -1, -10, 9.81, 1e6};

/* A number in [lo, hi] (both finite, lo <= hi), biased toward the extremes:
 * 12 draws in 32 are a bound or its neighbour, a power of ten or m x 10^k
 * anywhere in the range, a neighbour of DBL_MIN, DBL_MAX, sqrt(DBL_MAX) and
 * the like, or any bit pattern; the rest are moderate or plain numbers (the
 * used-up input, all zero bytes, gives 1 or the bound nearest it).
 * Subnormal numbers are never drawn: the parser refuses them (strtod's
 * ERANGE), so they would only make the scene invalid. */
static double num(struct src *s, double lo, double hi)
{
    const unsigned mode = (u8(s) + 20) % 32;
    /* The smallest and largest magnitudes the range holds. */
    const double amax = fmax(fabs(lo), fabs(hi));
    const double amin = lo > 0 ? lo : hi < 0 ? -hi : DBL_MIN;
    double v = 0;
    switch (mode) {
    case 0:
        v = lo;
        break;
    case 1:
        v = hi;
        break;
    case 2:
        v = nextafter(lo, hi);
        break;
    case 3:
        v = nextafter(hi, lo);
        break;
    case 4:
    case 5:
    case 6:
    case 7: {
        /* ±10^k, k spread over the decades of the range */
        const int k0 = (int)floor(log10(amin)), k1 = (int)ceil(log10(amax));
        v = pow10i(k0 + (int)(u16(s) % (unsigned)(k1 - k0 + 1)));
        if (lo < 0 && (hi <= 0 || (u8(s) & 1)))
            v = -v;
        break;
    }
    case 8:
    case 9: {
        /* m × 10^k with a mantissa of three digits */
        const int k0 = (int)floor(log10(amin)), k1 = (int)ceil(log10(amax));
        const double m = 1 + (double)(u16(s) % 900) / 100;
        v = m * pow10i(k0 + (int)(u16(s) % (unsigned)(k1 - k0 + 1)));
        if (lo < 0 && (hi <= 0 || (u8(s) & 1)))
            v = -v;
        break;
    }
    case 10: {
        static const double edge[] = {DBL_MIN,          DBL_MAX,     1.4916681462400413e-154,
                                      1.3407807929942596e+154, DBL_EPSILON, 1 / DBL_EPSILON,
                                      1e-300, 1e300, 1e150, 1e-150, 9e153, 1e154};
        v = edge[u8(s) % (sizeof edge / sizeof edge[0])];
        if (u8(s) & 1)
            v = nextafter(v, (u8(s) & 1) ? INFINITY : 0);
        if (lo < 0 && (u8(s) & 1))
            v = -v;
        break;
    }
    case 11: {
        /* any bit pattern that is a normal number */
        uint64_t bits = u64(s);
        memcpy(&v, &bits, sizeof v);
        if (!isnormal(v))
            v = 1;
        break;
    }
    case 12:
    case 13:
    case 14:
    case 15:
    case 16:
    case 17:
    case 18:
    case 19: {
        /* a moderate m × 10^k, |k| <= 6 (half the draws are moderate or plain,
         * so that most scenes run and the extremes meet ordinary partners) */
        v = (1 + (double)(u16(s) % 900) / 100) * pow10i((int)(u8(s) % 13) - 6);
        if (lo < 0 && (hi <= 0 || (u8(s) & 1)))
            v = -v;
        break;
    }
    default:
        v = plain[u8(s) % (sizeof plain / sizeof plain[0])];
        break;
    }
    v = clamp(v, lo, hi);
    if (v != 0 && !isnormal(v))
        v = lo <= 0 && hi >= 0 ? 0 : amin;
    return v;
}

/* The row of key `name` of section `sec` in the key table. */
static const struct bal_key *key_of(enum bal_section_kind sec, const char *name)
{
    for (size_t i = 0; i < bal_scene_n_keys; i++)
        if (bal_scene_keys[i].section == sec && strcmp(bal_scene_keys[i].name, name) == 0)
            return &bal_scene_keys[i];
    fprintf(stderr, "fuzz_extremes: no key %s in section %d\n", name, (int)sec);
    abort();
}

/* A number for a key, from the whole range the key table gives it (so the
 * generator follows any change of a range); above 0 when `positive`. */
static double knum(struct src *s, enum bal_section_kind sec, const char *name, int positive)
{
    const struct bal_key *k = key_of(sec, name);
    return num(s, positive && k->min <= 0 ? DBL_MIN : k->min, k->max);
}

/* 0 about half the time, else knum (keys whose 0 means "off"). */
static double knum0(struct src *s, enum bal_section_kind sec, const char *name)
{
    return u8(s) & 1 ? knum(s, sec, name, 0) : 0;
}

/* ---- the scene text ----------------------------------------------------- */

struct text {
    char *b;
    size_t n, cap;
};

static void put(struct text *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void put(struct text *t, const char *fmt, ...)
{
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        const int k = vsnprintf(t->b + t->n, t->cap - t->n, fmt, ap);
        va_end(ap);
        if (k < 0)
            return;
        if ((size_t)k < t->cap - t->n) {
            t->n += (size_t)k;
            return;
        }
        char *b = realloc(t->b, 2 * t->cap + (size_t)k);
        if (!b)
            abort();
        t->b = b;
        t->cap = 2 * t->cap + (size_t)k;
    }
}

/* Integers of a LONG key up to 1e15, exactly. */
static void put_long(struct text *t, const char *key, double v)
{
    put(t, "%s = %.0f\n", key, v);
}

struct disc {
    double x, y, r;
};

struct wall {
    double px, py, angle, h1, h2;
};

/* ---- the generator ---------------------------------------------------------- */

/* Radius of disc i: anything, or the first disc's times a power of ten (the
 * ratio up to the whole range), or equal to an earlier one. */
static double radius(struct src *s, const struct disc *d, int i, int ratio_cap)
{
    const struct bal_key *key = key_of(BAL_SEC_DISC, "r");
    const double lo = fmax(key->min, DBL_MIN), hi = key->max;
    double r;
    const unsigned mode = i == 0 ? 0 : u8(s) % 4;
    if (mode == 0)
        r = num(s, lo, hi);
    else if (mode == 1)
        r = d[u8(s) % (unsigned)i].r;
    else
        r = d[0].r * pow10i((int)(u16(s) % 1233) - 616);
    r = clamp(r, lo, hi);
    if (ratio_cap) /* and no sum of two radii overflows */
        r = i == 0 ? fmin(r, 1e300) : clamp(r, fmax(lo, d[0].r / 100), fmin(hi, d[0].r * 100));
    return r;
}

/* Distance factors between centres, in units of the radii's sum. */
static const double gap[] = {1, 1, 1 + 1e-12, 1 + 1e-9, 1.005, 1.02, 1.5, 2, 10, 1e3, 1e9, 1e100};

static void place(struct src *s, struct disc *d, int i, const struct wall *w, int n_walls)
{
    const unsigned mode = u8(s) % 8;
    const double ang = 2 * BAL_PI * u8(s) / 256;
    double x = 0, y = 0;
    if (i == 0 && mode < 4) {
        x = 0;
        y = 0;
    } else if (mode < 5 && i > 0) {
        const struct disc *o = &d[u8(s) % (unsigned)i];
        const unsigned g = u8(s);
        const double f = g < 240 ? gap[g % (sizeof gap / sizeof gap[0])] : num(s, 1, BIG);
        const double dist = (d[i].r + o->r) * f;
        x = o->x + dist * cos(ang);
        y = o->y + dist * sin(ang);
    } else if (mode < 6 && n_walls > 0) {
        /* on (or just off) a wall, somewhere along it */
        const struct wall *W = &w[u8(s) % (unsigned)n_walls];
        const double a = W->angle * (BAL_PI / 180);
        const double t = W->h1 + (W->h2 - W->h1) * (u8(s) / 255.0);
        const double off = d[i].r * gap[u8(s) % (sizeof gap / sizeof gap[0])];
        const double side = (u8(s) & 1) ? 1 : -1;
        x = W->px + t * cos(a) - side * off * sin(a);
        y = W->py + t * sin(a) + side * off * cos(a);
    } else {
        x = knum(s, BAL_SEC_DISC, "x", 0);
        y = knum(s, BAL_SEC_DISC, "x", 0);
    }
    if (!isfinite(x) || !isfinite(y)) {
        x = knum(s, BAL_SEC_DISC, "x", 0);
        y = knum(s, BAL_SEC_DISC, "x", 0);
    }
    d[i].x = tidy(x);
    d[i].y = tidy(y);
}

/* The scene the bytes choose. */
static void generate(struct src *s, struct text *t, int ratio_cap)
{
    struct disc d[MAX_DISCS];
    struct wall w[MAX_WALLS];
    /* settings */
    const unsigned flags = u16(s);
    const int power = flags & 1, nu_given = (flags >> 1) & 1;
    put(t, "[settings]\n");
    if ((flags >> 2) & 1) {
        put(t, "dt = %.17g\n", knum(s, BAL_SEC_SETTINGS, "dt", 0));
        put(t, "force_dt = %u\n", u8(s) & 1);
    }
    if ((flags >> 3) & 1)
        put(t, "dt_fraction = %.17g\n", knum(s, BAL_SEC_SETTINGS, "dt_fraction", 0));
    if ((flags >> 4) & 1)
        put(t, "alpha = %.17g\n", knum0(s, BAL_SEC_SETTINGS, "alpha"));
    if ((flags >> 5) & 1)
        put(t, "beta = %.17g\n", knum0(s, BAL_SEC_SETTINGS, "beta"));
    if ((flags >> 6) & 1)
        put(t, "gravity = %.17g %.17g\n", knum0(s, BAL_SEC_SETTINGS, "gravity"),
            knum0(s, BAL_SEC_SETTINGS, "gravity"));
    if (power) {
        put(t, "normal_law = power\n");
        if (nu_given)
            put(t, "nu = %.17g\n", knum(s, BAL_SEC_SETTINGS, "nu", 0));
    }
    const int psi = (flags >> 7) & 1;
    if (psi)
        put(t, "psi = %.17g\n", knum(s, BAL_SEC_SETTINGS, "psi", 0));
    if (power || psi)
        put(t, "delta0 = %.17g\n", knum(s, BAL_SEC_SETTINGS, "delta0", 1));
    if ((flags >> 8) & 1)
        put(t, "gamma_n = %.17g\n", knum0(s, BAL_SEC_SETTINGS, "gamma_n"));
    static const char *const grids[] = {"auto", "on", "off", "auto"};
    put(t, "grid = %s\n", grids[(flags >> 9) & 3]);
    if ((flags >> 11) & 1)
        put(t, "skin = %.17g\n", knum0(s, BAL_SEC_SETTINGS, "skin"));
    if ((flags >> 12) & 1) {
        put(t, "overlap_budget = %.17g\n", knum0(s, BAL_SEC_SETTINGS, "overlap_budget"));
        put(t, "energy_guard = %.17g\n", knum0(s, BAL_SEC_SETTINGS, "energy_guard"));
    }
    if ((flags >> 13) & 1)
        put(t, "allow_overlap = 1\n");
    static const char *const integ[] = {"centred", "verlet", "gear5", "centred"};
    put(t, "integrator = %s\n", integ[(flags >> 14) & 3]);
    if (u8(s) % 8 == 0)
        put_long(t, "output_every", 1 + (double)(u8(s) % 4));

    /* materials: m0 always has a density (the discs need one) */
    const int n_mat = 1 + (int)(u8(s) % MAX_MATERIALS);
    for (int m = 0; m < n_mat; m++) {
        put(t, "[material m%d]\nkn = %.17g\n", m, knum(s, BAL_SEC_MATERIAL, "kn", 1));
        const unsigned f = u8(s);
        if (f & 1)
            put(t, "ks = %.17g\n", knum(s, BAL_SEC_MATERIAL, "ks", 1));
        if (f & 2)
            put(t, "friction = %.17g\n", knum0(s, BAL_SEC_MATERIAL, "friction"));
        if (f & 4)
            put(t, "cohesion = %.17g\n", knum0(s, BAL_SEC_MATERIAL, "cohesion"));
        put(t, "density = %.17g\n", knum(s, BAL_SEC_MATERIAL, "density", 1));
    }

    /* walls */
    const int n_walls = (int)(u8(s) % (MAX_WALLS + 2)) % (MAX_WALLS + 1);
    for (int k = 0; k < n_walls; k++) {
        struct wall *W = &w[k];
        const unsigned f = u8(s);
        if (f & 1) {
            W->px = knum(s, BAL_SEC_WALL, "p", 0);
            W->py = knum(s, BAL_SEC_WALL, "p", 0);
        } else {
            W->px = 0;
            W->py = -(double)(f >> 1 & 3);
        }
        static const double angles[] = {0, 90, 180, 45, -90, 30, 1e-300, 360};
        W->angle = (f & 8) ? knum(s, BAL_SEC_WALL, "angle", 0) : angles[u8(s) % 8];
        if (f & 16) {
            W->h1 = knum(s, BAL_SEC_WALL, "h1", 0);
            W->h2 = W->h1 + num(s, DBL_MIN, BIG);
        } else {
            const double half = num(s, DBL_MIN, BIG);
            W->h1 = -half;
            W->h2 = half;
        }
        if (!(W->h2 > W->h1) || !isfinite(W->h2)) {
            if (W->h1 == BIG)
                W->h1 = nextafter(BIG, 0);
            W->h2 = nextafter(W->h1, BIG);
        }
        W->h1 = tidy(W->h1);
        W->h2 = tidy(W->h2);
        if (!(W->h2 > W->h1))
            W->h2 = W->h1 < 0 ? 0 : W->h1 > 0 ? nextafter(W->h1, BIG) : DBL_MIN;
        put(t, "[wall w%d]\np = %.17g %.17g\nangle = %.17g\n", k, W->px, W->py, W->angle);
        put(t, "h1 = %.17g\nh2 = %.17g\nmaterial = m%d\n", W->h1, W->h2,
            (int)(u8(s) % (unsigned)n_mat));
    }

    /* discs */
    const int n_discs = 1 + (int)(u8(s) % MAX_DISCS);
    for (int i = 0; i < n_discs; i++) {
        d[i].r = radius(s, d, i, ratio_cap);
        place(s, d, i, w, n_walls);
        const unsigned f = u8(s);
        put(t, "[disc d%d]\nx = %.17g %.17g\nr = %.17g\nmaterial = m%d\n", i, d[i].x, d[i].y,
            d[i].r, (f & 1) ? (int)(u8(s) % (unsigned)n_mat) : 0);
        if (f & 2) {
            put(t, "fixed = 1\n");
        } else {
            if (f & 4) {
                if (f & 8) {
                    /* towards the first disc, at a speed from the whole range */
                    const double dx = d[0].x - d[i].x, dy = d[0].y - d[i].y;
                    const double len = hypot(dx, dy);
                    const double sp = num(s, 0, key_of(BAL_SEC_DISC, "v")->max);
                    double vx = len > 0 ? sp * (dx / len) : sp, vy = len > 0 ? sp * (dy / len) : 0;
                    if (!isfinite(vx) || !isfinite(vy))
                        vx = vy = 0;
                    put(t, "v = %.17g %.17g\n", tidy(vx), tidy(vy));
                } else {
                    put(t, "v = %.17g %.17g\n", knum0(s, BAL_SEC_DISC, "v"),
                        knum0(s, BAL_SEC_DISC, "v"));
                }
            }
            if (f & 16)
                put(t, "omega = %.17g\n", knum(s, BAL_SEC_DISC, "omega", 0));
        }
        if (f & 32)
            put(t, "theta = %.17g\n", knum(s, BAL_SEC_DISC, "theta", 0));
    }

    /* sometimes a fill or a pile besides (a few discs more) */
    int fill_box = 0, pile_floor = 0;
    const unsigned gen = u8(s);
    if (gen % 8 == 1) {
        const unsigned f = u8(s);
        const long n = 1 + (long)(u8(s) % 4);
        const double rmin = ratio_cap ? d[0].r : knum(s, BAL_SEC_FILL, "rmin", 1);
        const double rmax = (f & 1) || ratio_cap ? rmin
                                                 : clamp(rmin * pow10i((int)(u8(s) % 40)), rmin,
                                                         key_of(BAL_SEC_FILL, "rmax")->max);
        put(t, "[fill f]\nn = %ld\n", n);
        put_long(t, "columns", (f & 2) ? 1e8 : (double)(1 + u8(s) % 3));
        put(t, "rmin = %.17g\nrmax = %.17g\nmaterial = m0\n", rmin, rmax);
        if (f & 4)
            put(t, "origin = %.17g %.17g\n", knum(s, BAL_SEC_FILL, "origin", 0),
                knum(s, BAL_SEC_FILL, "origin", 0));
        else
            put(t, "origin = %.17g %.17g\n", clamp(-1e3 * d[0].r, -BIG, BIG),
                clamp(1e3 * d[0].r, -BIG, BIG));
        if (f & 8)
            put(t, "headroom = %.17g\n", knum0(s, BAL_SEC_FILL, "headroom"));
        if (f & 16)
            put(t, "vmax = %.17g\n", knum0(s, BAL_SEC_FILL, "vmax"));
        put_long(t, "seed", (double)u16(s));
        if (f & 32) {
            fill_box = 1;
            put(t, "box = 1\nwall_material = m%d\n", (int)(u8(s) % (unsigned)n_mat));
        }
    } else if (gen % 8 == 2) {
        const unsigned f = u8(s);
        put(t, "[pile q]\nL = %u\nslope = %s\nd = %.17g\nmaterial = m0\n", 3 + (f & 1),
            (f & 2) ? "60" : "30", ratio_cap ? 2 * d[0].r : knum(s, BAL_SEC_PILE, "d", 1));
        if (f & 4)
            put(t, "origin = %.17g %.17g\n", knum(s, BAL_SEC_PILE, "origin", 0),
                knum(s, BAL_SEC_PILE, "origin", 0));
        else
            put(t, "origin = 0 %.17g\n", clamp(-1e3 * d[0].r, -BIG, BIG));
        if (f & 8) {
            put(t, "bottom = bumpy\nc = %.17g\n", knum(s, BAL_SEC_PILE, "c", 0));
        } else {
            pile_floor = 1;
            put(t, "wall_material = m%d\n", (int)(u8(s) % (unsigned)n_mat));
        }
    }

    /* stages, moving the walls now and then */
    const int n_stages = 1 + (int)(u8(s) % MAX_STAGES);
    for (int g = 0; g < n_stages; g++) {
        const unsigned f = u8(s);
        put(t, "[stage s%d]\n", g);
        put_long(t, "cycles", (double)(1 + u8(s) % MAX_CYCLES));
        if (f & 1)
            put(t, "ramp = 1\n");
        if (f & 2) {
            put(t, "stop_ke = %.17g\n", knum0(s, BAL_SEC_STAGE, "stop_ke"));
            put(t, "stop_stress = %.17g\n", knum0(s, BAL_SEC_STAGE, "stop_stress"));
            put_long(t, "check_every", (f & 4) ? 1e15 : (double)(1 + u8(s) % 3));
        }
        for (int k = 0; k < n_walls; k++)
            if (u8(s) & 1)
                put(t, "move = w%d %.17g %.17g %.17g\n", k, knum0(s, BAL_SEC_STAGE, "move"),
                    knum0(s, BAL_SEC_STAGE, "move"), knum0(s, BAL_SEC_STAGE, "move"));
        if (fill_box && (f & 8))
            put(t, "move = f_bottom %.17g %.17g %.17g\n", knum0(s, BAL_SEC_STAGE, "move"),
                knum0(s, BAL_SEC_STAGE, "move"), knum0(s, BAL_SEC_STAGE, "move"));
        if (pile_floor && (f & 16))
            put(t, "move = q_floor %.17g %.17g %.17g\n", knum0(s, BAL_SEC_STAGE, "move"),
                knum0(s, BAL_SEC_STAGE, "move"), knum0(s, BAL_SEC_STAGE, "move"));
    }

    /* a probe of every quantity, with the bodies it needs */
    for (int k = 0; k < BAL_PROBE_COUNT; k++) {
        char q[32];
        fuzz_quantity_name(k, q, sizeof q);
        const int contact = k <= BAL_PROBE_CONTACT_SLIDING;
        const int wall = k >= BAL_PROBE_WALL_F1 && k <= BAL_PROBE_WALL_ECC;
        const int disc = k >= BAL_PROBE_DISC_X && k <= BAL_PROBE_DISC_OMEGA;
        if (wall && n_walls == 0)
            continue;
        if (contact) {
            /* disc–disc and disc–wall */
            if (n_discs > 1)
                put(t, "[probe %s_dd]\nquantity = %s\na = d0\nb = d1\n", q, q);
            if (n_walls > 0)
                put(t, "[probe %s_dw]\nquantity = %s\na = d%d\nb = w0\n", q, q, n_discs - 1);
        } else if (wall) {
            put(t, "[probe %s_w]\nquantity = %s\na = w%d\n", q, q, n_walls - 1);
        } else if (disc) {
            put(t, "[probe %s_d0]\nquantity = %s\na = d0\n", q, q);
            if (n_discs > 1)
                put(t, "[probe %s_dn]\nquantity = %s\na = d%d\n", q, q, n_discs - 1);
        } else {
            put(t, "[probe %s]\nquantity = %s\n", q, q);
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static int ratio_cap = -1, print = 0;
    if (ratio_cap < 0) {
        ratio_cap = fuzz_skip("ratio");
        const char *p = getenv("BALLAST_FUZZ_PRINT");
        print = p && *p && *p != '0';
    }
    struct src s = {data, size, 0};
    struct text t = {malloc(4096), 0, 4096};
    if (!t.b)
        return 0;
    t.b[0] = '\0';
    generate(&s, &t, ratio_cap);
    if (print)
        fprintf(stderr, "---- fuzz.scene\n%s----\n", t.b);

    fuzz_count(FUZZ_N_INPUTS);
    struct bal_scene sc;
    struct bal_error err = {0};
    bal_scene_default(&sc);
    const enum bal_status st = bal_scene_parse(&sc, t.b, "fuzz.scene", &err);
    if (st != BAL_OK) {
        /* The generator writes only known keys with values in their ranges
         * (scene_keys.c), "%.17g": the parser must take every one. */
        if (!err.msg[0])
            fuzz_fail("bal_scene_parse failed (%d) without a message", st);
        fuzz_check_origin(&err, st, "bal_scene_parse", "fuzz.scene", t.b);
        if (st != BAL_ENOMEM)
            fuzz_fail("bal_scene_parse refused a scene of legal values: %s", err.msg);
    } else {
        fuzz_count(FUZZ_N_PARSED);
        fuzz_validate_and_run(&sc, t.b);
    }
    bal_scene_free(&sc);
    free(t.b);
    return 0;
}
