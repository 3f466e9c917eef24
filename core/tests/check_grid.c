/*
 * check_grid.c — suite "grid": the neighbour search (grid.c) and the
 * contact history that the candidate lists carry across rebuilds and
 * re-sorts (grid.c, install).
 *
 * With the cell grid, disc–disc candidates are the pairs whose gap is below
 * the Verlet skin at the last rebuild, disc–wall candidates likewise; the
 * lists are rebuilt when two discs (or a disc and a wall) may have closed
 * the skin (d_1 + d_2 ≥ skin, the two largest displacements since the
 * rebuild, or d_1 + wall displacement ≥ skin).  Without the
 * grid every pair is a candidate.  History (F_n, F_s, flags) follows a
 * contact through rebuilds, so results must not depend on the mode.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check_main.h"

/* The force law with identical inputs gives bitwise identical outputs; only
 * the order in which a disc's contact forces are summed differs between
 * modes (cell order vs scene order).  Each such sum rounds differently by
 * ~1e-16 relative; 1e-12 relative bounds that after a few hundred cycles. */
#define ROUNDOFF_REL 1e-12

static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

static struct bal_run_info info_of(const struct tfx *f)
{
    struct bal_run_info info;
    bal_sim_info(f->sim, &info);
    return info;
}

static const char *const fill_fmt =
    "[settings]\ngrid = %s\n"
    "[material g]\nkn = 1e5\ndensity = 1\n"
    "[fill pack]\nn = %d\ncolumns = 8\nrmin = 0.8\nrmax = 1.0\nmaterial = g\n"
    "[stage s]\ncycles = 1\n";

/* auto: all pairs below BAL_GRID_CROSSOVER discs, the grid from there on;
 * on and off force the mode. */
START_TEST(grid_mode_selection)
{
    const int n_lo = BAL_GRID_CROSSOVER - 1, n_hi = BAL_GRID_CROSSOVER;
    struct tfx *f = tfx_newf("auto", fill_fmt, "auto", n_lo);
    struct bal_run_info info = info_of(f);
    ck_assert_int_eq(info.grid_used, 0);
    ck_assert_int_eq(info.n_candidates, (long)n_lo * (n_lo - 1) / 2);
    tfx_release(f);
    f = tfx_newf("auto", fill_fmt, "auto", n_hi);
    ck_assert_int_eq(info_of(f).grid_used, 1);
    tfx_release(f);
    f = tfx_newf("on", fill_fmt, "on", 3);
    ck_assert_int_eq(info_of(f).grid_used, 1);
    tfx_release(f);
    f = tfx_newf("off", fill_fmt, "off", n_hi + 20);
    info = info_of(f);
    ck_assert_int_eq(info.grid_used, 0);
    ck_assert_int_eq(info.n_candidates, (long)(n_hi + 20) * (n_hi + 19) / 2);
}
END_TEST

/* The candidates the grid finds, compared with brute force over all pairs:
 * gap < skin for discs, closest distance < r + skin for walls; the list is
 * sorted by key with i < j.  Returns 1 when they agree. */
static int candidates_are_exact(const struct bal_sim *s, double skin, long *n_pairs, long *n_walls)
{
    long n_exp = 0;
    uint64_t *expect = malloc((size_t)s->n * (size_t)s->n * sizeof *expect);
    if (!expect)
        return 0;
    for (int i = 0; i < s->n; i++) {
        for (int j = i + 1; j < s->n; j++) {
            const double dx = s->x[j] - s->x[i], dy = s->y[j] - s->y[i];
            const double reach = s->r[i] + s->r[j] + skin;
            if (dx * dx + dy * dy < reach * reach)
                expect[n_exp++] = ((uint64_t)(uint32_t)i << 32) | (uint32_t)j;
        }
    }
    qsort(expect, (size_t)n_exp, sizeof *expect, cmp_u64);
    int ok = s->pp.n == n_exp;
    for (long c = 0; ok && c < n_exp; c++)
        ok = pair_key(&s->pp, c) == expect[c] && s->pp.i[c] < s->pp.j[c];
    free(expect);
    long nw = 0;
    for (int i = 0; i < s->n; i++) {
        for (int k = 0; k < s->n_walls; k++) {
            double cx, cy;
            const double d2 = bal_walls_closest(&s->walls[k], s->x[i], s->y[i], &cx, &cy);
            const double reach = s->r[i] + skin;
            if (d2 < reach * reach) {
                const uint64_t key = ((uint64_t)(uint32_t)i << 32) | (uint32_t)k;
                ok &= nw < s->pw.n && pair_key(&s->pw, nw) == key;
                nw++;
            }
        }
    }
    ok &= s->pw.n == nw;
    *n_pairs = n_exp;
    *n_walls = nw;
    return ok;
}

/* At creation (discs on the fill's lattice) and again after 300 cycles of
 * random motion under gravity (discs anywhere, rebuilt on the spot). */
START_TEST(grid_candidates_match_brute_force)
{
    const double skin = 0.35;
    struct tfx *f = tfx_new("[settings]\ngrid = on\nskin = 0.35\ngravity = 0 -9.81\n"
                            "[material g]\nkn = 1e5\nfriction = 0.4\ndensity = 1\n"
                            "[fill pack]\nn = 70\ncolumns = 9\nrmin = 0.3\nrmax = 0.5\n"
                            "vmax = 6\nseed = 11\nbox = 1\nheadroom = 0.2\nmaterial = g\n"
                            "wall_material = g\n"
                            "[stage s]\ncycles = 1\n",
                            "pack");
    long np = 0, nw = 0;
    ck_assert_msg(candidates_are_exact(f->sim, skin, &np, &nw), "at creation");
    ck_assert_int_gt(np, 70); /* the skin makes lattice neighbours candidates */
    ck_assert_int_gt(nw, 20);
    ck_assert_int_eq(f->sim->n_walls, 4);
    t_steps(f, 300);
    ck_assert_int_eq(bal_grid_rebuild(f->sim, &f->err), BAL_OK);
    ck_assert_msg(candidates_are_exact(f->sim, skin, &np, &nw), "after 300 cycles");
    ck_assert_int_gt(np, 70);
}
END_TEST

/* A sparse scene (discs up to 900 apart) makes the grid widen its cells
 * to keep their number near 2 per disc; the candidates must still be
 * exactly the pairs with gap < skin. */
START_TEST(grid_candidates_sparse_scene)
{
    struct tfx *f = tfx_new("[settings]\ngrid = on\nskin = 0.25\n"
                            "[material g]\nkn = 1e5\ndensity = 1\n"
                            "[disc a]\nx = 0 0\nr = 0.5\nmaterial = g\n"
                            "[disc b]\nx = 1.1 0.3\nr = 0.45\nmaterial = g\n"
                            "[disc c]\nx = 900 -3\nr = 0.5\nmaterial = g\n"
                            "[disc d]\nx = 900.9 -2.6\nr = 0.35\nmaterial = g\n"
                            "[disc e]\nx = -40 870\nr = 0.5\nmaterial = g\n"
                            "[disc f]\nx = -40.2 871.05\nr = 0.4\nmaterial = g\n"
                            "[disc g]\nx = 450 450\nr = 0.5\nmaterial = g\n"
                            "[disc h]\nx = 451.5 450\nr = 0.5\nmaterial = g\n"
                            "[stage s]\ncycles = 1\n",
                            "sparse");
    const struct bal_sim *s = f->sim;
    /* a–b (gap 0.19), c–d (gap 0.13), e–f (gap 0.17) are within the skin;
     * g–h (gap 0.5) is not. */
    long n_exp = 0;
    int all_found = 1;
    for (int i = 0; i < s->n; i++) {
        for (int j = i + 1; j < s->n; j++) {
            const double dx = s->x[j] - s->x[i], dy = s->y[j] - s->y[i];
            const double reach = s->r[i] + s->r[j] + 0.25;
            if (dx * dx + dy * dy < reach * reach) {
                const struct bal_pairs *L;
                n_exp++;
                all_found &= bal_pairs_find_contact(s, 0, i, 0, j, &L) >= 0;
            }
        }
    }
    ck_assert_int_eq(info_of(f).grid_used, 1);
    ck_assert_int_eq(n_exp, 3);
    ck_assert(all_found);
    ck_assert_int_eq(s->pp.n, 3);
}
END_TEST

/* When the lists are rebuilt.  skin = 0.2, Δt = 1e-3, radii 0.5.  `mover`
 * (at the origin) alone runs at 0.7, the others rest: d_1 = 0.7 N Δt
 * reaches the skin first at N = ⌈285.7⌉ = 286, then every 286 cycles: 600
 * cycles → rebuilds at 286 and 572, plus the one at creation: 3.
 *
 * With a second mover, d_1 + d_2 reaching the skin is not enough: the two
 * must be able to touch, that is be less than r + r + d_1 + d_2 apart at
 * the rebuild, and not be a listed pair already.
 * - `a` 5 above, running at 0.4 (d_1 + d_2 = 1.1 N Δt = 0.2 at N = 182):
 *   too far to touch, so again the first rebuild is at 286.
 * - `a` at (1.3, 0) (gap 0.3 > skin: not listed), running at 0.4 across:
 *   1.1 N Δt > 0.3 first at N = ⌈272.7⌉ = 273; no rebuild at 272.
 * - `a` at (1.1, 0) (gap 0.1: listed), mover and `a` running apart along y
 *   at 0.45 each: d_1 + d_2 = 0.9 N Δt reaches the skin at N = ⌈222.2⌉ =
 *   223, but their pair is in the list; the rebuild comes when d_1 =
 *   0.45 N Δt reaches it, at N = ⌈444.4⌉ = 445.
 * A wall moving at 0.3 with the discs at rest: 0.3 N Δt ≥ 0.2 at N =
 * ⌈666.7⌉ = 667: 700 cycles → 2. */
START_TEST(grid_rebuild_when_skin_used_up)
{
    static const char *const movers =
        "[settings]\ngrid = on\nskin = 0.2\ndt = 1e-3\n"
        "[material g]\nkn = 1e5\ndensity = 1\n"
        "[disc mover]\nx = 0 0\nr = 0.5\nv = %s\nmaterial = g\n"
        "[disc a]\nx = %s\nr = 0.5\nv = %s\nmaterial = g\n"
        "[disc b]\nx = 5 5\nr = 0.5\nmaterial = g\n"
        "[stage s]\ncycles = 1\n";
    struct tfx *f = tfx_newf("one mover", movers, "0.7 0", "0 5", "0 0");
    ck_assert_int_eq(info_of(f).rebuilds, 1);
    t_steps(f, 285);
    ck_assert_int_eq(info_of(f).rebuilds, 1);
    t_steps(f, 1);
    ck_assert_int_eq(info_of(f).rebuilds, 2);
    t_steps(f, 600 - 286);
    ck_assert_int_eq(info_of(f).rebuilds, 3);
    tfx_release(f);

    f = tfx_newf("two movers far apart", movers, "0.7 0", "0 5", "0 -0.4");
    t_steps(f, 285);
    ck_assert_int_eq(info_of(f).rebuilds, 1);
    t_steps(f, 1);
    ck_assert_int_eq(info_of(f).rebuilds, 2);
    tfx_release(f);

    f = tfx_newf("two movers near", movers, "0.7 0", "1.3 0", "0 0.4");
    ck_assert_int_eq(f->sim->pp.n, 0); /* mover-a is not listed */
    t_steps(f, 272);
    ck_assert_int_eq(info_of(f).rebuilds, 1);
    t_steps(f, 1);
    ck_assert_int_eq(info_of(f).rebuilds, 2);
    tfx_release(f);

    f = tfx_newf("two listed movers", movers, "0 0.45", "1.1 0", "0 -0.45");
    const struct bal_pairs *listed;
    ck_assert_int_ge(t_contact(f, "mover", "a", &listed), 0);
    t_steps(f, 444);
    ck_assert_int_eq(info_of(f).rebuilds, 1);
    t_steps(f, 1);
    ck_assert_int_eq(info_of(f).rebuilds, 2);
    tfx_release(f);

    f = tfx_new("[settings]\ngrid = on\nskin = 0.2\ndt = 1e-3\n"
                "[material g]\nkn = 1e5\ndensity = 1\n"
                "[wall w]\np = 0 -3\nangle = 0\nh1 = -2\nh2 = 2\nmaterial = g\n"
                "[disc a]\nx = 0 0\nr = 0.5\nmaterial = g\n"
                "[disc b]\nx = 5 5\nr = 0.5\nmaterial = g\n"
                "[stage s]\ncycles = 700\nmove = w 0 0.3 0\n",
                "wall");
    t_steps(f, 666);
    ck_assert_int_eq(info_of(f).rebuilds, 1);
    t_steps(f, 1);
    ck_assert_int_eq(info_of(f).rebuilds, 2);
    t_steps(f, 700 - 667);
    ck_assert_int_eq(info_of(f).rebuilds, 2);
}
END_TEST

/* Past MAX_MOVERS = 32 movers (grid.c) the packing counts as flowing and
 * d_1 + d_2 >= skin rebuilds at once.  Discs 5 apart in a row, skin 0.2,
 * Δt = 1e-3, all running sideways to the row at 0.3: no two can touch, so
 * 32 of them rebuild first when one alone has moved the skin, 0.3 N Δt >=
 * 0.2 at N = ⌈666.7⌉ = 667; 33 of them when 0.6 N Δt >= 0.2, at N =
 * ⌈333.3⌉ = 334. */
START_TEST(grid_many_movers_rebuild)
{
    for (int movers = 32; movers <= 33; movers++) {
        char text[T_TEXT_MAX];
        int len = snprintf(text, sizeof text,
                           "[settings]\ngrid = on\nskin = 0.2\ndt = 1e-3\n"
                           "[material g]\nkn = 1e5\ndensity = 1\n[stage s]\ncycles = 1\n");
        for (int k = 0; k < movers; k++)
            len += snprintf(text + len, sizeof text - (size_t)len,
                            "[disc d%d]\nx = %d 0\nr = 0.5\nv = 0 0.3\nmaterial = g\n", k,
                            5 * k);
        ck_assert_int_lt(len, (int)sizeof text);
        struct tfx *f = tfx_new(text, "movers");
        const long first = movers == 32 ? 667 : 334;
        t_steps(f, first - 1);
        ck_assert_int_eq(info_of(f).rebuilds, 1);
        t_steps(f, 1);
        ck_assert_int_eq(info_of(f).rebuilds, 2);
        tfx_release(f);
    }
}
END_TEST

/* Two held discs are never candidates of each other (they never move); a
 * held and a free disc are.  Held discs touch in a row, free ones sit on
 * them: the grid's list is the brute-force list less the held-held pairs. */
START_TEST(grid_held_pairs_left_out)
{
    char text[4096];
    int len = snprintf(text, sizeof text,
                       "[settings]\ngrid = on\nskin = 0.2\n"
                       "[material g]\nkn = 1e5\ndensity = 1\n");
    for (int k = 0; k < 8; k++)
        len += snprintf(text + len, sizeof text - (size_t)len,
                        "[disc h%d]\nx = %d 0\nr = 0.5\nmaterial = g\nfixed = 1\n"
                        "[disc f%d]\nx = %g 0.95\nr = 0.5\nmaterial = g\n",
                        k, k, k, k + 0.5);
    snprintf(text + len, sizeof text - (size_t)len, "[stage s]\ncycles = 1\n");
    struct tfx *f = tfx_new(text, "held");
    const struct bal_sim *s = f->sim;
    ck_assert_int_eq(s->use_grid, 1);
    long expect = 0, held_pairs = 0;
    for (int i = 0; i < s->n; i++)
        for (int j = i + 1; j < s->n; j++) {
            const double dx = s->x[j] - s->x[i], dy = s->y[j] - s->y[i];
            const double reach = s->r[i] + s->r[j] + 0.2;
            if (dx * dx + dy * dy < reach * reach) {
                if (s->fixed[i] && s->fixed[j])
                    held_pairs++;
                else
                    expect++;
            }
        }
    ck_assert_int_eq(held_pairs, 7);
    ck_assert_int_eq(s->pp.n, expect);
    for (long c = 0; c < s->pp.n; c++)
        ck_assert(!(s->fixed[s->pp.i[c]] && s->fixed[s->pp.j[c]]));
}
END_TEST

/* The limit of a disc's candidates in a rebuild (MAX_NEIGHBOURS = 512 in
 * grid.c), at its edge.  600 discs of radius 0.5 in a row, touching (x =
 * 0.5 + k, exact in binary); disc k is a candidate of disc 0 while its
 * distance k < 1 + skin.  A skin of 511.5 gives disc 0 exactly 512
 * candidates: the list must be the brute-force one.  A skin of 512.5 gives
 * it 513: bal_sim_create must refuse the scene as bad input (issue 29: at
 * the start it is the scene's doing) and say why, at the line of the
 * generator's radii. */
START_TEST(grid_neighbour_limit)
{
    static const char *fmt = "[settings]\ngrid = on\nskin = %s\n"
                             "[material g]\nkn = 1e5\ndensity = 1\n"
                             "[fill row]\nn = 600\ncolumns = 600\nrmin = 0.5\nrmax = 0.5\n"
                             "material = g\n[stage s]\ncycles = 1\n";
    char text[512];
    snprintf(text, sizeof text, fmt, "511.5");
    struct tfx *f = tfx_new(text, "limit-512");
    const struct bal_sim *s = f->sim;
    long expect = 0, most = 0;
    for (int i = 0; i < s->n; i++) {
        long mine = 0;
        for (int j = 0; j < s->n; j++) {
            const double dx = s->x[j] - s->x[i], dy = s->y[j] - s->y[i];
            const double reach = s->r[i] + s->r[j] + 511.5;
            mine += s->id[j] > s->id[i] && dx * dx + dy * dy < reach * reach;
        }
        expect += mine;
        most = mine > most ? mine : most;
    }
    ck_assert_int_eq(most, 512);
    ck_assert_int_eq(s->pp.n, expect);

    snprintf(text, sizeof text, fmt, "512.5");
    struct tfx *g = tfx_parse(text, "limit-513");
    g->sc.settings.force_dt = 1;
    ck_assert_int_eq(tfx_create(g), BAL_EINVAL);
    ck_assert_msg(t_contains(g->err.msg, "limit-513:10: rmin: disc row.0 of [fill row]: has more "
                                         "than 512 neighbours within reach at the start"),
                  "%s", g->err.msg);
}
END_TEST

/* The tight case of d_1 + d_2: two discs flying head-on at each other, with
 * the gap at the rebuild just above the skin (so they are not candidates)
 * and no other disc moving.  Their first contact must be seen in the same
 * cycle as with every pair a candidate, for several skins and speeds. */
START_TEST(grid_head_on_contact_not_missed)
{
    static const char *const fmt =
        "[settings]\ngrid = %s\nskin = %g\ndt = 1e-4\n"
        "[material g]\nkn = 1e5\ndensity = 1\n"
        "[disc p]\nx = 0 0\nr = 0.5\nv = %g 0\nmaterial = g\n"
        "[disc q]\nx = %.17g 0\nr = 0.5\nv = %g 0\nmaterial = g\n"
        "[disc c]\nx = 0 9\nr = 0.5\nmaterial = g\n"
        "[disc d]\nx = 9 9\nr = 0.5\nmaterial = g\n"
        "[stage s]\ncycles = 1\n"
        "[probe fn]\nquantity = contact_fn\na = p\nb = q\n";
    const double skins[] = {0.05, 0.2, 0.3};
    const double speeds[][2] = {{1.0, -1.0}, {1.5, -0.25}, {0.1, -2.0}};
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
            const double skin = skins[a], gap = skin * 1.0001;
            char on_txt[1024], off_txt[1024];
            snprintf(on_txt, sizeof on_txt, fmt, "on", skin, speeds[b][0], 1.0 + gap,
                     speeds[b][1]);
            snprintf(off_txt, sizeof off_txt, fmt, "off", skin, speeds[b][0], 1.0 + gap,
                     speeds[b][1]);
            struct tfx *on = tfx_new(on_txt, "on"), *off = tfx_new(off_txt, "off");
            ck_assert_int_eq(on->sim->pp.n < off->sim->pp.n, 1); /* p-q not a candidate */
            const double closing = speeds[b][0] - speeds[b][1];
            const long until = (long)(3 * gap / closing / 1e-4) + 10;
            long first_on = -1, first_off = -1;
            for (long k = 1; k <= until && (first_on < 0 || first_off < 0); k++) {
                t_steps(on, 1);
                t_steps(off, 1);
                if (first_on < 0 && t_probe_value(on, "fn") > 0)
                    first_on = k;
                if (first_off < 0 && t_probe_value(off, "fn") > 0)
                    first_off = k;
            }
            ck_assert_int_gt(first_off, 0);
            ck_assert_int_eq(first_on, first_off);
            tfx_release(on);
            tfx_release(off);
        }
}
END_TEST

/* The history a rebuild carries over (grid.c, install: each new pair finds
 * itself in the old list, and every column is gathered from there).  A
 * packing with every history column (friction: F_s; rolling: M, θ_r; the
 * wall list also keeps the dashpots D_n, D_s, M_d) gets a distinct marker
 * in every column of every candidate, derived from the pair's scene ids;
 * then discs swap places, so that some pairs leave the lists and others
 * join, and the lists are rebuilt: a pair that was a candidate keeps its
 * markers in every column and its flags, a new one starts from zero.  Then
 * a re-sort (bal_grid_reorder) renumbers the discs: the markers follow the
 * pairs through the permutation, and the oriented rolling history changes
 * sign where the pair's two discs swapped order. */
static const char *const carry_scene =
    "[settings]\ngrid = on\ngravity = 0 -60\ndt = 0.0005\nbeta = 0.01\n"
    "[material g]\nkn = 1e5\nks = 0.8e5\nfriction = 0.5\ndensity = 1\nrolling = 0.5\n"
    "[material w]\nkn = 1e5\nks = 1e5\nfriction = 0.3\n"
    "[fill pack]\nn = 200\ncolumns = 20\nrmin = 0.5\nrmax = 0.75\nseed = 11\nbox = 1\n"
    "headroom = 1\nmaterial = g\nwall_material = w\n[stage s]\ncycles = 1\n";

/* The marker of column `col` for the pair of scene ids (a, b) (a wall: b is
 * its index plus 100 000), oriented: (b, a) gives its negative. */
static double marker(int a, int b, int col)
{
    const double m = 1 + (a < b ? a : b) * 1000.0 + (a < b ? b : a) + col * 1e8;
    return a < b ? m : -m;
}

/* The scene ids of candidate c of list p (walls: 100 000 + the wall). */
static void pair_ids(const struct bal_sim *s, const struct bal_pairs *p, int walls, long c,
                     int *a, int *b)
{
    *a = s->id[p->i[c]];
    *b = walls ? 100000 + p->j[c] : s->id[p->j[c]];
}

/* Mark every column of every candidate of both lists. */
static void mark(struct bal_sim *s)
{
    for (int walls = 0; walls < 2; walls++) {
        struct bal_pairs *p = walls ? &s->pw : &s->pp;
        for (long c = 0; c < p->n; c++) {
            int a, b;
            pair_ids(s, p, walls, c, &a, &b);
            p->fn[c] = marker(a, b, 1);
            p->fs[c] = marker(a, b, 2);
            p->mr[c] = marker(a, b, 3);
            p->tr[c] = marker(a, b, 4);
            if (p->damping) {
                p->dn[c] = marker(a, b, 5);
                p->ds[c] = marker(a, b, 6);
                p->dm[c] = marker(a, b, 7);
            }
            p->flags[c] = (uint8_t)(1 + (a + b) % 15);
        }
    }
}

/* Was the unordered pair of ids (a, b) among the n pairs of ids in was[]?
 * 1 in the same order, -1 turned round, 0 not. */
static int was_candidate(const int (*was)[2], long n, int a, int b)
{
    for (long k = 0; k < n; k++) {
        if (was[k][0] == a && was[k][1] == b)
            return 1;
        if (was[k][0] == b && was[k][1] == a)
            return -1;
    }
    return 0;
}

/* Every candidate of both lists: the markers of its ids (the rolling ones,
 * oriented, as the discs are ordered now) if it was a candidate before
 * (counted in *kept, and in *turned if its discs are now the other way
 * round), all zero otherwise (*fresh). */
static void check_carried(const struct bal_sim *s, const int (*was[2])[2], const long n_was[2],
                          long *kept, long *turned, long *fresh)
{
    for (int walls = 0; walls < 2; walls++) {
        const struct bal_pairs *p = walls ? &s->pw : &s->pp;
        for (long c = 0; c < p->n; c++) {
            int a, b;
            pair_ids(s, p, walls, c, &a, &b);
            const int order = was_candidate(was[walls], n_was[walls], a, b), old = order != 0;
            *kept += old;
            *turned += order < 0;
            *fresh += !old;
            const double fn = old ? fabs(marker(a, b, 1)) : 0, fs = old ? fabs(marker(a, b, 2)) : 0;
            ck_assert_double_eq(p->fn[c], fn);
            ck_assert_double_eq(p->fs[c], fs);
            /* θ_r = ∫(ω_x − ω_y): its sign goes with the pair's order */
            ck_assert_double_eq(p->mr[c], old ? marker(a, b, 3) : 0);
            ck_assert_double_eq(p->tr[c], old ? marker(a, b, 4) : 0);
            if (p->damping) {
                ck_assert_double_eq(p->dn[c], old ? fabs(marker(a, b, 5)) : 0);
                ck_assert_double_eq(p->ds[c], old ? fabs(marker(a, b, 6)) : 0);
                ck_assert_double_eq(p->dm[c], old ? fabs(marker(a, b, 7)) : 0);
            }
            ck_assert_int_eq(p->flags[c], old ? 1 + (a + b) % 15 : 0);
        }
    }
}

/* The ids of every candidate of both lists, and the markers made unsigned
 * but for the rolling columns (which a re-sort may negate): what
 * check_carried expects of a pair carried over. */
static void remember(struct bal_sim *s, int (*was[2])[2], long n_was[2])
{
    for (int walls = 0; walls < 2; walls++) {
        struct bal_pairs *p = walls ? &s->pw : &s->pp;
        n_was[walls] = p->n;
        was[walls] = malloc((size_t)(p->n > 0 ? p->n : 1) * sizeof *was[walls]);
        ck_assert_ptr_nonnull(was[walls]);
        for (long c = 0; c < p->n; c++) {
            int a, b;
            pair_ids(s, p, walls, c, &a, &b);
            was[walls][c][0] = a;
            was[walls][c][1] = b;
            p->fn[c] = fabs(p->fn[c]);
            p->fs[c] = fabs(p->fs[c]);
            if (p->damping) {
                p->dn[c] = fabs(p->dn[c]);
                p->ds[c] = fabs(p->ds[c]);
                p->dm[c] = fabs(p->dm[c]);
            }
        }
    }
}

START_TEST(grid_rebuild_carries_every_column)
{
    struct tfx *f = tfx_new(carry_scene, "carry");
    struct bal_sim *s = f->sim;
    ck_assert_int_eq(s->use_grid, 1);
    t_steps(f, 800); /* it lands: pairs near and in contact */
    ck_assert_ptr_nonnull(s->pp.mr);
    ck_assert_ptr_nonnull(s->pw.dm); /* every column exists */
    ck_assert_int_eq(s->pp.damping, 0); /* (disc pairs' dashpots are recomputed, not kept) */
    for (int step = 0; step < 2; step++) {
        mark(s);
        int (*was[2])[2];
        long n_was[2];
        remember(s, was, n_was);
        if (step == 0) {
            /* discs far apart swap places: pairs leave the lists and others join */
            for (int k = 0; k < 40; k++) {
                const int i = k, j = s->n - 1 - k;
                const double x = s->x[i], y = s->y[i];
                s->x[i] = s->x[j];
                s->y[i] = s->y[j];
                s->x[j] = x;
                s->y[j] = y;
            }
            ck_assert_int_eq(bal_grid_rebuild(s, &f->err), BAL_OK);
        } else {
            ck_assert_int_eq(bal_grid_reorder(s, &f->err), BAL_OK);
        }
        long kept = 0, turned = 0, fresh = 0;
        check_carried(s, (const int (**)[2])was, n_was, &kept, &turned, &fresh);
        free(was[0]);
        free(was[1]);
        /* measured: 128 of 238 kept, 99 new, 110 gone; then all 227 kept, 56 turned */
        ck_assert_int_gt(kept, 100);
        if (step == 0) {
            ck_assert_int_gt(fresh, 20);                      /* pairs joined: from zero */
            ck_assert_int_gt(n_was[0] + n_was[1] - kept, 20); /* and pairs left */
        } else {
            ck_assert_int_eq(fresh, 0);  /* a re-sort keeps every pair */
            ck_assert_int_gt(turned, 0); /* and turned some round: θ_r and M change sign */
        }
    }
}
END_TEST

/* A sticking frictional contact (p pressed against q, p spinning slowly:
 * |F_s| ≈ 0.2 F_n < 0.8 F_n; the collision lasts ~0.03, longer than the
 * 48 cycles of 1e-4 looked at) among a few distant discs, grid on.  A rebuild
 * — called directly, or forced through need_rebuild — must leave F_n, F_s
 * and the flags of the contact untouched, and the run must match the same
 * scene run with grid = off. */
static const char *const sticking_fmt =
    "[settings]\ngrid = %s\ndt = 1e-4\n"
    "[material g]\nkn = 1e4\nks = 0.8e4\nfriction = 0.8\ndensity = 2.385\n"
    "[disc f1]\nx = 9.5 0.2\nr = 0.5\nmaterial = g\n"
    "[disc q]\nx = 0.99 0.013\nr = 0.5\nv = -0.05 0\nmaterial = g\n"
    "[disc f2]\nx = -0.3 8.7\nr = 0.45\nmaterial = g\n"
    "[disc p]\nx = 0 0\nr = 0.5\nv = 0.05 0\nomega = 0.05\nmaterial = g\n"
    "[disc f3]\nx = 9.1 9.3\nr = 0.55\nmaterial = g\n"
    "[stage s]\ncycles = 1\n"
    "[probe fn]\nquantity = contact_fn\na = p\nb = q\n"
    "[probe fs]\nquantity = contact_fs\na = p\nb = q\n"
    "[probe slide]\nquantity = contact_sliding\na = p\nb = q\n";

START_TEST(grid_history_survives_rebuild)
{
    struct tfx *on = tfx_newf("on", sticking_fmt, "on");
    struct tfx *off = tfx_newf("off", sticking_fmt, "off");
    ck_assert_int_eq(info_of(on).grid_used, 1);
    ck_assert_int_eq(info_of(off).grid_used, 0);
    t_steps(on, 8);
    t_steps(off, 8);
    const double fn = t_probe_value(on, "fn"), fs = t_probe_value(on, "fs");
    ck_assert(fn > 0);
    ck_assert(fs != 0);
    ck_assert_double_eq(t_probe_value(on, "slide"), 0.0);

    const long before = info_of(on).rebuilds;
    ck_assert_int_eq(bal_grid_rebuild(on->sim, &on->err), BAL_OK);
    ck_assert_int_eq(info_of(on).rebuilds, before + 1);
    ck_assert_double_eq(t_probe_value(on, "fn"), fn);
    ck_assert_double_eq(t_probe_value(on, "fs"), fs);
    const struct bal_pairs *L;
    const long c = t_contact(on, "p", "q", &L);
    ck_assert_int_eq(L->flags[c], BAL_PAIR_TOUCHING);

    /* Keep going, forcing a rebuild every 5 cycles in the grid run. */
    for (int k = 0; k < 8; k++) {
        on->sim->need_rebuild = 1;
        t_steps(on, 5);
        t_steps(off, 5);
        const double fn_off = t_probe_value(off, "fn"), fs_off = t_probe_value(off, "fs");
        ck_assert_double_eq_tol(t_probe_value(on, "fn"), fn_off, ROUNDOFF_REL * fabs(fn_off));
        ck_assert_double_eq_tol(t_probe_value(on, "fs"), fs_off, ROUNDOFF_REL * fabs(fs_off));
    }
    ck_assert_int_ge(info_of(on).rebuilds, before + 9);
    ck_assert_double_eq(t_probe_value(on, "slide"), 0.0);
    ck_assert(t_probe_value(on, "fs") != 0);
}
END_TEST

/* A small random packing falling under gravity in a box (a [fill]),
 * grid = on against grid = off: the same contacts and, disc by disc in
 * scene order, the same positions and velocities to round-off after 400
 * cycles (the difference can only come from the order of force sums). */
/* dt: 0.1 of the single-spring estimate, the step the test was written for
 * (the network bound of timestep.c is 4x smaller). */
static const char *const packing_fmt =
    "[settings]\ngrid = %s\ngravity = 0 -9.81\ndt = 0.00075788534449010318\n"
    "[material g]\nkn = 1e5\nks = 0.8e5\nfriction = 0.5\ndensity = 1\n"
    "[material w]\nkn = 1e5\nfriction = 0.3\n"
    "[fill pack]\nn = 60\ncolumns = 8\nrmin = 0.9\nrmax = 1.0\nvmax = 4.0\nseed = 7\nbox = 1\n"
    "material = g\nwall_material = w\n"
    "[stage s]\ncycles = 400\n";

/* Positions are O(10), velocities O(1): 1e-9 absolute is ~1e-10 relative,
 * far above the ~1e-15 round-off a different summation order leaves after
 * a few hundred cycles, far below a missed or doubled contact (a force of
 * ~1 for one cycle moves a disc by F Δt²/m ~ 1e-7). */
#define AGREE_ABS 1e-9

START_TEST(grid_on_off_agree_on_packing)
{
    struct tfx *on = tfx_newf("on", packing_fmt, "on");
    struct tfx *off = tfx_newf("off", packing_fmt, "off");
    ck_assert_int_eq(bal_sim_run(on->sim, NULL, NULL, &on->err), BAL_OK);
    ck_assert_int_eq(bal_sim_run(off->sim, NULL, NULL, &off->err), BAL_OK);
    const struct bal_sim *a = on->sim, *b = off->sim;
    ck_assert_int_eq(a->n, b->n);
    double worst = 0;
    for (int id = 0; id < a->n; id++) {
        const int i = a->slot[id], j = b->slot[id];
        worst = fmax(worst, fabs(a->x[i] - b->x[j]));
        worst = fmax(worst, fabs(a->y[i] - b->y[j]));
        worst = fmax(worst, fabs(a->vx[i] - b->vx[j]));
        worst = fmax(worst, fabs(a->vy[i] - b->vy[j]));
        worst = fmax(worst, fabs(a->w[i] - b->w[j]));
    }
    long ca = 0, cb = 0;
    for (long c = 0; c < a->pp.n; c++)
        ca += (a->pp.flags[c] & BAL_PAIR_TOUCHING) != 0;
    for (long c = 0; c < b->pp.n; c++)
        cb += (b->pp.flags[c] & BAL_PAIR_TOUCHING) != 0;
    ck_assert_int_eq(ca, cb);
    ck_assert_int_gt(ca, 5); /* the packing has disc–disc contacts */
    for (long c = 0; c < a->pw.n; c++)
        ca += (a->pw.flags[c] & BAL_PAIR_TOUCHING) != 0;
    for (long c = 0; c < b->pw.n; c++)
        cb += (b->pw.flags[c] & BAL_PAIR_TOUCHING) != 0;
    ck_assert_int_eq(ca, cb);
    ck_assert_int_gt(info_of(on).rebuilds, 3); /* the grid was rebuilt */
    ck_assert_msg(worst < AGREE_ABS, "grid on/off differ by %g", worst);
}
END_TEST

/* skin_rule = motion: the skin follows the motion, and the lists still
 * hold every contact.  A packing of 300 discs falls from its lattice onto
 * the floor of its box and piles up.  After every cycle each pair of discs
 * that touches, and each disc touching a wall, is looked up in the lists
 * (all pairs, by brute force: nothing of the grid's own arithmetic).  The
 * skin must have grown past twice its first value while the discs fall,
 * stay within the rule's bounds (0.05 to 1 r_max), and the rebuilds be
 * fewer than with the fixed skin of the same scene; after the first 400
 * cycles the run must also be the all-pairs run to round-off (AGREE_ABS). */
static const char *const falling_fmt = /* grid, skin_rule, dt, rmin, rmax */
    "[settings]\ngrid = %s\nskin_rule = %s\ngravity = 0 -9.81\n"
    "dt = %.17g\n"
    "[material g]\nkn = 1e5\nks = 0.8e5\nfriction = 0.5\ndensity = 1\n"
    "[material w]\nkn = 1e5\nfriction = 0.3\n"
    "[fill pack]\nn = 300\ncolumns = 20\nrmin = %g\nrmax = %g\nvmax = 4.0\nseed = 11\n"
    "box = 1\nmaterial = g\nwall_material = w\n"
    "[stage s]\ncycles = 1\n";

/* Every touching pair and disc–wall contact of s is a candidate. */
static long unlisted_contacts(const struct bal_sim *s, long *touching)
{
    long missed = 0;
    for (int i = 0; i < s->n; i++) {
        for (int j = i + 1; j < s->n; j++) {
            const double dx = s->x[j] - s->x[i], dy = s->y[j] - s->y[i];
            const double rs = s->r[i] + s->r[j];
            if (dx * dx + dy * dy >= rs * rs)
                continue;
            ++*touching;
            missed += bal_pairs_find(&s->pp, ((uint64_t)(uint32_t)i << 32) | (uint32_t)j) < 0;
        }
        for (int k = 0; k < s->n_walls; k++) {
            double cx, cy;
            if (bal_walls_closest(&s->walls[k], s->x[i], s->y[i], &cx, &cy) >= s->r[i] * s->r[i])
                continue;
            ++*touching;
            missed += bal_pairs_find(&s->pw, ((uint64_t)(uint32_t)i << 32) | (uint32_t)k) < 0;
        }
    }
    return missed;
}

START_TEST(grid_motion_skin_misses_no_contact)
{
    const double dt = 0.00075788534449010318;
    struct tfx *on = tfx_newf("motion", falling_fmt, "on", "motion", dt, 0.7, 1.0);
    struct tfx *off = tfx_newf("off", falling_fmt, "off", "fixed", dt, 0.7, 1.0);
    struct tfx *fixed = tfx_newf("fixed", falling_fmt, "on", "fixed", dt, 0.7, 1.0);
    const struct bal_sim *a = on->sim, *b = off->sim;
    const double first = info_of(on).skin, r_max = a->r_max;
    ck_assert_double_eq_tol(first, 0.2 * r_max, 1e-15);
    t_steps(on, 400);
    t_steps(off, 400);
    double worst = 0;
    for (int id = 0; id < a->n; id++) {
        const int i = a->slot[id], j = b->slot[id];
        worst = fmax(worst, fabs(a->x[i] - b->x[j]) + fabs(a->y[i] - b->y[j]));
        worst = fmax(worst, fabs(a->vx[i] - b->vx[j]) + fabs(a->vy[i] - b->vy[j]));
    }
    ck_assert_msg(worst < AGREE_ABS, "motion skin and all pairs differ by %g", worst);
    double widest = first, narrowest = first;
    long missed = 0, touching = 0;
    for (int k = 0; k < 3600; k++) {
        t_steps(on, 1);
        missed += unlisted_contacts(a, &touching);
        widest = fmax(widest, a->skin);
        narrowest = fmin(narrowest, a->skin);
    }
    t_steps(fixed, 4000);
    ck_assert_int_eq(missed, 0);
    ck_assert_int_gt(touching, 3600 * 150); /* piled up: 0.74 contacts a disc a cycle */
    ck_assert_msg(widest > 2 * first, "the skin grew to %g only (first %g)", widest, first);
    ck_assert(widest <= 1.0 * r_max && narrowest >= 0.05 * r_max);
    ck_assert_int_lt(info_of(on).rebuilds, info_of(fixed).rebuilds);
    ck_assert_double_eq(info_of(fixed).skin, first);
}
END_TEST

/* skin_rule = motion with a wide grading: radii 0.06 to 1, so that a skin of
 * r_max would let a disc of r_min have ((0.06 + 1 + 1)/0.06)² ≈ 1180 discs
 * of its size within reach, past the rebuild's limit of 512.  The rule's
 * widest skin is then 16 r_min − r_min − r_max = −0.1, raised to its floor
 * 0.05 r_max: over 6000 cycles (134 rebuilds) the skin only shrinks from
 * its first 0.2 r_max, the run never meets the limit, and every contact is
 * listed. */
START_TEST(grid_motion_skin_stays_narrow_for_a_wide_grading)
{
    struct tfx *f = tfx_newf("wide", falling_fmt, "on", "motion", 1e-4, 0.06, 1.0);
    const struct bal_sim *s = f->sim;
    const double r_max = s->r_max; /* (the fill's largest draw, just under 1) */
    ck_assert(15 * s->r_min - r_max < 0.05 * r_max);
    ck_assert_double_eq_tol(s->skin, 0.2 * r_max, 1e-15);
    double widest = 0, narrowest = 1;
    long missed = 0, touching = 0;
    for (int k = 0; k < 6000; k++) {
        t_steps(f, 1);
        missed += unlisted_contacts(s, &touching);
        if (k > 0) {
            widest = fmax(widest, s->skin);
            narrowest = fmin(narrowest, s->skin);
        }
    }
    ck_assert_int_gt(info_of(f).rebuilds, 3);
    ck_assert_double_eq_tol(narrowest, 0.05 * r_max, 1e-15);
    ck_assert(widest <= 0.2 * r_max);
    ck_assert_int_eq(missed, 0);
    ck_assert_int_gt(touching, 10000); /* 17 712 touching pair-cycles: the check is not empty */
}
END_TEST

/* skin_rule = motion against one projectile: the lists a rebuild makes are
 * searched with the skin the trigger then waits for.  A row of 50 held
 * discs (radius 0.5, 1 apart: touching no one) and a disc p of radius 0.5
 * above disc 10 of the row, gap 0.25, falling at 0.9 (no gravity, dt =
 * 1e-3).  First skin 0.2 r_max = 0.1: p has moved it at N = ⌈0.1/9e-4⌉ =
 * 112 (d = 0.1008), the lists are rebuilt, and the rule widens the skin by
 * its largest step, to 0.2 (nothing lies in the outer half of the old skin,
 * so the rule sees no cost in a wider one).  The gap is then 0.1492: inside
 * the new skin, outside the old one.  p touches the row at N = ⌈0.25/9e-4⌉
 * = 278; the next rebuild would come only at N = 112 + 223 = 335.  So the
 * pair must be listed by the rebuild at 112 — a search with the old skin
 * would miss the contact for 57 cycles. */
START_TEST(grid_motion_skin_lists_a_projectile)
{
    char txt[T_TEXT_MAX];
    int len = snprintf(txt, sizeof txt,
                       "[settings]\ngrid = on\nskin_rule = motion\ndt = 1e-3\n"
                       "[material g]\nkn = 1e5\ndensity = 1\n[stage s]\ncycles = 1\n"
                       "[disc p]\nx = 10 1.25\nr = 0.5\nv = 0 -0.9\nmaterial = g\n");
    for (int k = 0; k < 50; k++)
        len += snprintf(txt + len, sizeof txt - (size_t)len,
                        "[disc row%d]\nx = %d 0\nr = 0.5\nfixed = 1\nmaterial = g\n", k, k);
    ck_assert_int_lt(len, (int)sizeof txt);
    struct tfx *f = tfx_new(txt, "projectile");
    const struct bal_sim *s = f->sim;
    ck_assert_double_eq_tol(s->skin, 0.1, 1e-15);
    const long built = info_of(f).rebuilds;
    long missed = 0, touching = 0, first_touch = -1;
    for (int k = 1; k <= 400; k++) {
        t_steps(f, 1);
        if (k == 111)
            ck_assert_int_eq(info_of(f).rebuilds, built);
        if (k == 112) {
            ck_assert_int_eq(info_of(f).rebuilds, built + 1);
            ck_assert_double_eq_tol(s->skin, 0.2, 1e-15);
        }
        const long before = touching;
        missed += unlisted_contacts(s, &touching);
        if (touching > before && first_touch < 0)
            first_touch = k;
    }
    ck_assert_int_eq(first_touch, 278);
    ck_assert_int_eq(missed, 0);
}
END_TEST

/* Rattlers in cages, where the lists outlive d_1 + d_2 >= skin.  Three
 * cages 12 apart, each a ring of 8 held discs (radius 0.5, ring radius
 * 1.8), with a free disc of radius 0.4 flying about inside: gap 0.9 to
 * the ring, skin 0.2.  The three often have moved 0.1 or more at once, far
 * apart, so d_1 + d_2 reaches the skin long before any can touch a disc it
 * is not listed with.  (The ring does not move, so a rattler reaches an
 * unlisted ring disc only after moving the skin, which rebuilds anyway;
 * the test of a contact found by looking at the movers is the next one.)
 * The test counts the cycles in which d_1 + d_2 had reached the skin
 * without a rebuild, which must be many, and the run must still be the
 * all-pairs run (to round-off, AGREE_ABS). */
START_TEST(grid_rattlers_keep_their_lists)
{
    char base[T_TEXT_MAX - 64], on_txt[T_TEXT_MAX], off_txt[T_TEXT_MAX];
    int len = snprintf(base, sizeof base,
                       "[material g]\nkn = 1e5\ndensity = 1\n[stage s]\ncycles = 1\n");
    const double speeds[3][2] = {{3.1, 1.3}, {-2.2, 2.9}, {0.7, -3.4}};
    for (int c = 0; c < 3; c++) {
        for (int k = 0; k < 8; k++)
            len += snprintf(base + len, sizeof base - (size_t)len,
                            "[disc c%dk%d]\nx = %.17g %.17g\nr = 0.5\nfixed = 1\nmaterial = g\n",
                            c, k, 12.0 * c + 1.8 * cos(k * BAL_PI / 4), 1.8 * sin(k * BAL_PI / 4));
        len += snprintf(base + len, sizeof base - (size_t)len,
                        "[disc r%d]\nx = %d 0\nr = 0.4\nv = %g %g\nmaterial = g\n", c, 12 * c,
                        speeds[c][0], speeds[c][1]);
    }
    ck_assert_int_lt(len, (int)sizeof base);
    snprintf(on_txt, sizeof on_txt, "[settings]\ngrid = on\nskin = 0.2\ndt = 1e-4\n%s", base);
    snprintf(off_txt, sizeof off_txt, "[settings]\ngrid = off\ndt = 1e-4\n%s", base);
    struct tfx *on = tfx_new(on_txt, "on"), *off = tfx_new(off_txt, "off");
    const struct bal_sim *a = on->sim, *b = off->sim;
    long kept = 0, touching = 0;
    for (int k = 0; k < 20000; k++) {
        t_steps(on, 1);
        t_steps(off, 1);
        double d1 = 0, d2 = 0;
        for (int i = 0; i < a->n; i++) {
            const double d = hypot(a->x[i] - a->x_ref[i], a->y[i] - a->y_ref[i]);
            d2 = d > d1 ? d1 : d > d2 ? d : d2;
            d1 = d > d1 ? d : d1;
        }
        kept += d1 + d2 >= 0.2;
        for (long c = 0; c < b->pp.n; c++)
            touching += (b->pp.flags[c] & BAL_PAIR_TOUCHING) != 0;
    }
    double worst = 0;
    for (int id = 0; id < a->n; id++) {
        const int i = a->slot[id], j = b->slot[id];
        worst = fmax(worst, fabs(a->x[i] - b->x[j]) + fabs(a->y[i] - b->y[j]));
        worst = fmax(worst, fabs(a->vx[i] - b->vx[j]) + fabs(a->vy[i] - b->vy[j]));
    }
    ck_assert_msg(worst < AGREE_ABS, "grid on/off differ by %g", worst);
    ck_assert_int_gt(touching, 100);        /* the rattlers hit their rings */
    ck_assert_int_gt(kept, 1000);           /* lists kept past d_1 + d_2 >= skin */
    ck_assert_int_gt(info_of(on).rebuilds, 20);
}
END_TEST

/* Two movers that meet before either has moved the skin, two cells apart.
 * A row of 50 discs at rest (touching, no force) keeps the grid fine; p
 * and q, radius 0.5, fly head-on above it at 0.9 and -0.8 with a gap of
 * 0.35 (skin 0.2: not listed).  d_p + d_q reaches the skin at N = 1177
 * with no contact possible yet; they touch once 1.7e-4 N > 0.35, at N =
 * ⌈2058.8⌉ = 2059, when d_p = 0.185 and d_q = 0.165 (d_p reaches the skin
 * only at N = 2223).  The rebuild must come in that cycle (the contact seen
 * as with all pairs), and not before.  Their centres are 1.35 apart, more
 * than a cell (h = 2 r_max + skin = 1.2, or wider): p is put near the right
 * edge of a cell, so that q is two cells further, where only a search of
 * two cells around each mover finds it.
 * The grid's origin and cell size come from a first build of the scene
 * (p and q do not change them: they lie inside the row's extent). */
START_TEST(grid_movers_meet_two_cells_apart)
{
    static const char *const fmt = "[settings]\ngrid = %s\nskin = 0.2\ndt = 1e-4\n"
                                   "[material g]\nkn = 1e5\ndensity = 1\n"
                                   "[fill row]\nn = 50\ncolumns = 50\nrmin = 0.5\nrmax = 0.5\n"
                                   "material = g\n"
                                   "[disc p]\nx = %.17g 3\nr = 0.5\nv = 0.9 0\nmaterial = g\n"
                                   "[disc q]\nx = %.17g 3\nr = 0.5\nv = -0.8 0\nmaterial = g\n"
                                   "[stage s]\ncycles = 1\n"
                                   "[probe fn]\nquantity = contact_fn\na = p\nb = q\n";
    struct tfx *first = tfx_newf("layout", fmt, "on", 20.0, 21.35);
    const double x0 = first->sim->grid.x0, h = first->sim->grid.h;
    tfx_release(first);
    const double xp = x0 + 15.95 * h, xq = xp + 1.35;
    struct tfx *on = tfx_newf("on", fmt, "on", xp, xq), *off = tfx_newf("off", fmt, "off", xp, xq);
    const struct bal_grid *g = &on->sim->grid;
    ck_assert_double_eq(g->x0, x0);
    ck_assert_double_eq(g->h, h);
    const int p = t_slot(on, "p"), q = t_slot(on, "q");
    ck_assert_int_eq((int)((on->sim->x[q] - g->x0) / g->h), (int)((on->sim->x[p] - g->x0) / g->h) + 2);
    long first_on = -1, first_off = -1;
    for (long k = 1; k <= 2200 && (first_on < 0 || first_off < 0); k++) {
        t_steps(on, 1);
        t_steps(off, 1);
        if (k == 2058)
            ck_assert_int_eq(info_of(on).rebuilds, 1);
        if (first_on < 0 && t_probe_value(on, "fn") > 0)
            first_on = k;
        if (first_off < 0 && t_probe_value(off, "fn") > 0)
            first_off = k;
    }
    ck_assert_int_eq(first_off, 2059);
    ck_assert_int_eq(first_on, first_off);
    ck_assert_int_eq(info_of(on).rebuilds, 2);
}
END_TEST

/* Re-sorting the discs into cell order (bal_grid_reorder) renumbers every
 * array and the contact lists but is no physics: a frictional packing
 * settling under gravity, re-sorted every 7 cycles, keeps each disc (by its
 * scene id) where the un-sorted run has it, its contact count and its shear
 * history.  Only the order in which forces are summed changes, so the two
 * runs agree to round-off (REORDER_REL of the box size), not bitwise. */
#define REORDER_REL 1e-9
START_TEST(grid_reorder_is_no_physics)
{
    static const char *const text =
        /* dt: 0.2 of the single-spring estimate, the step the test was
         * written for (the network bound of timestep.c is 9.5x smaller) */
        "[settings]\ndt = 0.0007951906360993612\ngravity = 0 -9.81\nbeta = 0.001\ngrid = on\n"
        "[material g]\nkn = 1e5\nfriction = 0.5\ndensity = 1\n"
        "[material b]\nkn = 1e5\nfriction = 0.5\n"
        "[fill pack]\nn = 300\ncolumns = 24\nrmin = 0.5\nrmax = 0.75\nseed = 7\nbox = 1\n"
        "vmax = 2\nmaterial = g\nwall_material = b\n[stage s]\ncycles = 1\n";
    struct tfx *a = tfx_new(text, "plain"), *b = tfx_new(text, "sorted");
    for (int k = 0; k < 700; k++) {
        t_steps(a, 1);
        if (k % 7 == 6)
            ck_assert_int_eq(bal_grid_reorder(b->sim, &b->err), BAL_OK);
        t_steps(b, 1);
    }
    const struct bal_sim *sa = a->sim, *sb = b->sim;
    ck_assert_int_ge(sb->reorders, 20);
    int moved = 0;
    for (int id = 0; id < sa->n; id++) {
        const int i = sa->slot[id], j = sb->slot[id];
        ck_assert_double_eq_tol(sa->x[i], sb->x[j], REORDER_REL * 40);
        ck_assert_double_eq_tol(sa->y[i], sb->y[j], REORDER_REL * 40);
        moved += i != j;
    }
    ck_assert_int_gt(moved, 0); /* the re-sort did renumber discs */
    long ca = 0, cb = 0;
    double fa = 0, fb = 0;
    for (long c = 0; c < sa->pp.n; c++)
        if (sa->pp.flags[c] & BAL_PAIR_TOUCHING) {
            ca++;
            fa += fabs(pair_fs(&sa->pp, c));
        }
    for (long c = 0; c < sb->pp.n; c++)
        if (sb->pp.flags[c] & BAL_PAIR_TOUCHING) {
            cb++;
            fb += fabs(pair_fs(&sb->pp, c));
        }
    ck_assert_int_eq(ca, cb);
    ck_assert_int_gt(ca, 20); /* contacts with shear history exist */
    ck_assert_double_eq_tol(fa, fb, 1e-6 * fa);
}
END_TEST

Suite *suite_grid(void)
{
    Suite *s = suite_create("grid");
    TCase *tc = tcase_create("candidates");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, grid_mode_selection);
    tcase_add_test(tc, grid_candidates_match_brute_force);
    tcase_add_test(tc, grid_candidates_sparse_scene);
    tcase_add_test(tc, grid_rebuild_when_skin_used_up);
    tcase_add_test(tc, grid_head_on_contact_not_missed);
    tcase_add_test(tc, grid_held_pairs_left_out);
    tcase_add_test(tc, grid_neighbour_limit);
    tcase_add_test(tc, grid_many_movers_rebuild);
    suite_add_tcase(s, tc);

    tc = tcase_create("history");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, grid_rebuild_carries_every_column);
    tcase_add_test(tc, grid_history_survives_rebuild);
    tcase_add_test(tc, grid_on_off_agree_on_packing);
    tcase_add_test(tc, grid_rattlers_keep_their_lists);
    tcase_add_test(tc, grid_motion_skin_misses_no_contact);
    tcase_add_test(tc, grid_motion_skin_lists_a_projectile);
    tcase_add_test(tc, grid_motion_skin_stays_narrow_for_a_wide_grading);
    tcase_add_test(tc, grid_movers_meet_two_cells_apart);
    tcase_add_test(tc, grid_reorder_is_no_physics);
    suite_add_tcase(s, tc);
    return s;
}
