/*
 * bench.c — the dense-packing benchmark behind `make bench`.
 *
 * Kept whole (about 1400 lines): one benchmark program, whose modes share
 * the packing, the settling, the timing and the reporting.
 *
 * For each N it loads the benchmark scene through the ordinary scene
 * machinery (setting fill.pack.n and fill.pack.columns), runs every stage
 * but the last untimed (the packing falls and settles under gravity), then
 * times the last stage's physics: a calibration run picks a step count that
 * takes about TARGET_SECONDS, and that many steps are timed REPEATS times.
 * It prints one line per N with the median, min and max of the repeats:
 *
 *   bench dense N=20000 steps=S particle_steps_per_s=MEDIAN min=MIN max=MAX contacts_per_disc=Z
 *
 * and appends the same figures to reports/bench/<host>/dense.csv.  This is a
 * benchmark, not a test: nothing here asserts a speed.
 *
 * usage: bench SCENE [N ...]      (default N: 5000 20000 80000)
 *        bench --grid SCENE       (all pairs against the cell grid, small N:
 *                                  where BAL_GRID_CROSSOVER comes from)
 *        bench --settling SCENE [N]  (the packing timed while it falls)
 *        bench --pair SCENE NA NB [ROUNDS]  (flat scaling in one process: timed
 *                                  runs alternate between the two packings)
 *        bench --threads SCENE N T [ROUNDS]  (OpenMP: timed runs alternate
 *                                  between 1 and T threads on one packing)
 *        bench --pile PILE_SCENE  (the L0 = 100 pile relaxed, 5 whole runs)
 *        bench --modules SCENE [N]       (what each optional module costs, one
 *                                         simulation per configuration from
 *                                         the same settled packing)
 *        bench --modules-base SCENE [N]  (only the configuration with every
 *                                         module off: run by bench-bare, the
 *                                         build without them, to compare)
 *        bench --modules-pack SCENE N FILE    (settle that packing once, save it)
 *        bench --modules-step SCENE FILE STEPS RUNS  (the all-off configuration
 *                                         from the saved packing, RUNS timed runs
 *                                         of STEPS cycles, bracketed for callgrind)
 *        bench --modules-summary CG_NORMAL COUNT_NORMAL CG_BARE COUNT_BARE WALL
 *                                        (what `make bench-modules-count` prints)
 *        bench --cost SCENE PERIOD WINDOW  (any scene file on one thread, the
 *                                         last WINDOW cycles of every PERIOD
 *                                         bracketed for callgrind: make bench-cost)
 *        bench --workload DENSE BIAXIAL PILE_POLY [ROUNDS]  (the catalogue's
 *                                         biaxial test and polydisperse pile
 *                                         against the race's dense scene,
 *                                         alternating: make bench)
 *        bench --biaxial BIAXIAL DELTA [SHEAR_CYCLES]  (one biaxial test of
 *                                         --workload, its shearing counted
 *                                         under callgrind)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "ballast.h"
#include "energy.h"
#include "state.h"

#define REPEATS 5
#define TARGET_SECONDS 2.0

/* Columns of the benchmark's lattice of n discs: square-ish. */
static long pack_columns(long n)
{
    return lround(sqrt(2.0 * (double)n));
}

/* The packing counts as settled when E_k < 1e-3 E_el: the discs then move
 * by far less than the skin between rebuilds, as in a static packing. */
#define SETTLED_EK_OVER_EE 1e-3
#define MAX_SETTLE_BLOCKS 4
/* ... per 100 rows of the packing (N/columns, about sqrt(N/2)): a taller
 * packing falls for longer and its pressure waves take longer to die.  At
 * 4 blocks for any height the 1 000 000-disc packing (707 rows) was timed
 * at E_k/E_el = 1.6e-3 and rebuilt every 40 cycles, which the 20 000-disc
 * packing it is compared with does not. */
static long settle_blocks_cap(long n)
{
    const double rows = (double)n / (double)pack_columns(n);
    return MAX_SETTLE_BLOCKS * (long)fmax(1, ceil(rows / 100 - 1e-9));
}

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double timed_steps(struct bal_sim *sim, long steps, struct bal_error *err)
{
    const double t0 = now();
    for (long k = 0; k < steps; k++)
        if (bal_sim_step(sim, err))
            return -1;
    return now() - t0;
}

/* Extra override ("settings.grid=on"), or NULL, and the seconds per repeat. */
struct options {
    const char *extra;
    const char *extra2;
    int flowing;            /* time the fall itself: no settling first */
    double seconds;
    int quiet;
    double median;
};

/* The benchmark scene with N discs (fill.pack.n, and a square-ish lattice of
 * columns) and the `max` overrides of `sets` (NULL entries skipped), then its
 * simulation.  Returns 0, or 1 with err set. */
static int load_scene(const char *path, long n, const char *const *sets, int max,
                      struct bal_scene *sc, struct bal_sim **sim, struct bal_error *err)
{
    char set[128];
    bal_scene_default(sc);
    int ok = bal_scene_load(sc, path, err) == BAL_OK;
    snprintf(set, sizeof set, "fill.pack.n=%ld", n);
    ok = ok && bal_scene_set(sc, set, err) == BAL_OK;
    snprintf(set, sizeof set, "fill.pack.columns=%ld", pack_columns(n));
    ok = ok && bal_scene_set(sc, set, err) == BAL_OK;
    for (int k = 0; k < max; k++)
        if (sets[k])
            ok = ok && bal_scene_set(sc, sets[k], err) == BAL_OK;
    ok = ok && bal_sim_create(sim, sc, err) == BAL_OK;
    return ok ? 0 : 1;
}

/* Disc–disc contacts now (touching candidates). */
static long count_contacts(const struct bal_sim *sim)
{
    long contacts = 0;
    for (long q = 0; q < sim->pp.n; q++)
        contacts += (sim->pp.flags[q] & BAL_PAIR_TOUCHING) != 0;
    return contacts;
}

/* A benchmark simulation made ready for timing: settled (unless the
 * options say flowing), in its last stage, timers zeroed, step count of a
 * timed run calibrated to o->seconds. */
struct prepared {
    struct bal_scene sc;
    struct bal_sim *sim;
    long settled;            /* cycles run before timing */
    double ek_ee;            /* E_k/E_el when the timing started */
    long steps;              /* cycles per timed run */
    long rebuilds0, reorders0;
};

static void prepared_free(struct prepared *p)
{
    bal_sim_free(p->sim);
    bal_scene_free(&p->sc);
    p->sim = NULL;
}

static int prepare(const char *path, long n, const struct options *o, struct prepared *p)
{
    struct bal_error err = {0};
    const char *const sets[] = {o->extra, o->extra2};
    memset(p, 0, sizeof *p);
    if (load_scene(path, n, sets, 2, &p->sc, &p->sim, &err)) {
        fprintf(stderr, "bench: %s\n", err.msg);
        prepared_free(p);
        return 1;
    }
    struct bal_sim *sim = p->sim;
    const struct bal_scene *sc = &p->sc;
    /* Settle on every core: the packing is bitwise the one a single thread
     * settles (struct bal_par, state.h), in less time.  Timed on one thread
     * (or as the caller then sets). */
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    cores = cores < 1 ? 1 : cores > BAL_MAX_THREADS ? BAL_MAX_THREADS : cores;
    bal_sim_set_threads(sim, (int)cores, &err);
    /* Settle: every stage but the last, untimed. */
    for (int g = 0; g + 1 < sc->n_stages; g++) {
        bal_sim_set_stage(sim, g);
        for (long c = 0; c < sc->stages[g].cycles; c++, p->settled++)
            if (bal_sim_step(sim, &err)) {
                fprintf(stderr, "bench: settling: %s\n", err.msg);
                prepared_free(p);
                return 1;
            }
    }
    /* Settled means the kinetic energy is a small share of the elastic
     * energy; a tall packing takes longer to get there, so settle on in
     * blocks of the first stage's length until it is (or give up and say
     * so in the output). */
    long extra = 0;
    while (!o->flowing && bal_measure_kinetic(sim) > SETTLED_EK_OVER_EE * bal_measure_elastic(sim) &&
           extra < settle_blocks_cap(n) * sc->stages[0].cycles) {
        for (long c = 0; c < sc->stages[0].cycles; c++, extra++, p->settled++)
            if (bal_sim_step(sim, &err)) {
                fprintf(stderr, "bench: settling: %s\n", err.msg);
                prepared_free(p);
                return 1;
            }
    }
    p->ek_ee = bal_measure_kinetic(sim) / bal_measure_elastic(sim);
    bal_sim_set_threads(sim, 1, &err);
    bal_sim_set_stage(sim, sc->n_stages - 1);

    /* Calibrate the step count. */
    p->steps = 50;
    const double t = timed_steps(sim, p->steps, &err);
    if (t < 0) {
        fprintf(stderr, "bench: %s\n", err.msg);
        prepared_free(p);
        return 1;
    }
    if (t > 0)
        p->steps = (long)fmax(100, o->seconds / (t / (double)p->steps));
    /* The timers printed cover the timed cycles only. */
    p->rebuilds0 = sim->rebuilds;
    p->reorders0 = sim->reorders;
    memset(&sim->timers, 0, sizeof sim->timers);
    return 0;
}

/* One timed run: particle-steps per second, or -1. */
static double timed_run(struct prepared *p)
{
    struct bal_error err = {0};
    const double t = timed_steps(p->sim, p->steps, &err);
    if (t < 0) {
        fprintf(stderr, "bench: %s\n", err.msg);
        return -1;
    }
    return (double)p->steps * (double)p->sim->n / t;
}

/* The memory and profile lines of a prepared simulation (the peak RSS is
 * the process's: with two simulations, both). */
static void report_details(const struct prepared *p)
{
    const struct bal_sim *sim = p->sim;
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    const long contacts = count_contacts(sim);
    const double rss = 1024.0 * (double)ru.ru_maxrss;
    double disc_bytes, pair_bytes;
    bal_sim_memory(sim, &disc_bytes, &pair_bytes);
    printf("# N=%d memory: held while stepping %.0f bytes/disc (%.0f per disc + %.0f for its "
           "pairs, %.1f bytes per contact); peak RSS %.1f MB = %.0f bytes/disc\n",
           sim->n, (disc_bytes + pair_bytes) / sim->n, disc_bytes / sim->n, pair_bytes / sim->n,
           pair_bytes / (double)(contacts > 0 ? contacts : 1), rss / 1e6, rss / sim->n);
    const struct bal_timers *t = &sim->timers;
    printf("# N=%d %ld candidate pairs (%.2f per disc), %ld contacts; timed cycles: "
           "positions %.2f neighbours %.2f contacts %.2f walls %.2f velocities %.2f s, "
           "%ld rebuilds, %ld re-sorts\n",
           sim->n, sim->pp.n, (double)sim->pp.n / sim->n, contacts, t->positions, t->neighbours,
           t->contacts, t->walls, t->velocities,
           sim->rebuilds - p->rebuilds0, sim->reorders - p->reorders0);
}

static int run_one(const char *path, long n, FILE *csv, struct options *o)
{
    struct prepared p;
    if (prepare(path, n, o, &p))
        return 1;
    struct bal_sim *sim = p.sim;
    double rate[REPEATS];
    for (int k = 0; k < REPEATS; k++)
        if ((rate[k] = timed_run(&p)) < 0) {
            prepared_free(&p);
            return 1;
        }
    qsort(rate, REPEATS, sizeof rate[0], cmp_double);

    long touching = 2 * count_contacts(sim);
    for (long c = 0; c < sim->pw.n; c++)
        touching += (sim->pw.flags[c] & BAL_PAIR_TOUCHING) != 0;
    const double z = (double)touching / (double)sim->n;
    o->median = rate[REPEATS / 2];
    if (!o->quiet) {
        printf("# N=%d settled for %ld cycles: E_k/E_el = %.2g, %ld rebuilds so far\n", sim->n,
               p.settled, p.ek_ee, p.rebuilds0);
        printf("bench %s N=%d steps=%ld particle_steps_per_s=%.4g min=%.4g max=%.4g "
               "contacts_per_disc=%.3f\n",
               o->flowing ? "settling" : "dense", sim->n, p.steps, rate[REPEATS / 2], rate[0],
               rate[REPEATS - 1], z);
    }
    fflush(stdout);
    if (csv)
        fprintf(csv, "%ld,%d,%ld,%.6g,%.6g,%.6g,%.4f,%ld\n", (long)time(NULL), sim->n, p.steps,
                rate[REPEATS / 2], rate[0], rate[REPEATS - 1], z, sim->rebuilds);
    if (!o->quiet)
        report_details(&p);
    prepared_free(&p);
    return 0;
}

/* Flat scaling, judged in one process: the packings of N_A and N_B discs
 * are settled, then timed runs alternate between them, `rounds` times, so
 * that this VM's drift (10-40 % over hours) falls on both alike.  Prints
 * each one's median, min and max, and the median of the per-round ratios
 * B/A. */
static int scaling_pair(const char *path, long na, long nb, int rounds)
{
    enum { MAX_ROUNDS = 64 };
    if (rounds < 1 || rounds > MAX_ROUNDS) {
        fprintf(stderr, "bench: --pair: 1 <= rounds <= %d\n", MAX_ROUNDS);
        return 2;
    }
    struct options o = {NULL, NULL, 0, TARGET_SECONDS, 0, 0};
    struct prepared p[2];
    if (prepare(path, na, &o, &p[0]))
        return 1;
    if (prepare(path, nb, &o, &p[1])) {
        prepared_free(&p[0]);
        return 1;
    }
    double rate[2][MAX_ROUNDS], ratio[MAX_ROUNDS];
    int rc = 0;
    for (int r = 0; r < rounds && rc == 0; r++) {
        for (int k = 0; k < 2 && rc == 0; k++)
            rc = (rate[k][r] = timed_run(&p[k])) < 0;
        if (rc == 0)
            ratio[r] = rate[1][r] / rate[0][r];
    }
    if (rc == 0) {
        qsort(ratio, (size_t)rounds, sizeof ratio[0], cmp_double);
        for (int k = 0; k < 2; k++) {
            qsort(rate[k], (size_t)rounds, sizeof rate[k][0], cmp_double);
            printf("# N=%d settled for %ld cycles: E_k/E_el = %.2g\n", p[k].sim->n, p[k].settled,
                   p[k].ek_ee);
            printf("bench pair N=%d steps=%ld particle_steps_per_s=%.4g min=%.4g max=%.4g\n",
                   p[k].sim->n, p[k].steps, rate[k][rounds / 2], rate[k][0], rate[k][rounds - 1]);
            report_details(&p[k]);
        }
        printf("bench pair ratio N=%d/N=%d median=%.3f min=%.3f max=%.3f rounds=%d\n",
               p[1].sim->n, p[0].sim->n, ratio[rounds / 2], ratio[0], ratio[rounds - 1], rounds);
    }
    prepared_free(&p[0]);
    prepared_free(&p[1]);
    return rc;
}

/* OpenMP: the settled N-disc packing, timed runs alternating between one
 * thread and `threads`, `rounds` times; each one's median, min and max, and
 * the median of the per-round speed-ups.  (Same results on any number of
 * threads: make test checks it bitwise.) */
static int threads_bench(const char *path, long n, int threads, int rounds)
{
    enum { MAX_ROUNDS = 64 };
    if (rounds < 1 || rounds > MAX_ROUNDS || threads < 2 || threads > BAL_MAX_THREADS) {
        fprintf(stderr, "bench: --threads: 2 <= threads <= %d, 1 <= rounds <= %d\n",
                BAL_MAX_THREADS, MAX_ROUNDS);
        return 2;
    }
    struct options o = {NULL, NULL, 0, TARGET_SECONDS, 0, 0};
    struct prepared p;
    if (prepare(path, n, &o, &p))
        return 1;
    struct bal_error err = {0};
    double rate[2][MAX_ROUNDS], gain[MAX_ROUNDS];
    const int count[2] = {1, threads};
    int rc = 0;
    for (int r = 0; r < rounds && rc == 0; r++) {
        for (int k = 0; k < 2 && rc == 0; k++) {
            rc = bal_sim_set_threads(p.sim, count[k], &err) != BAL_OK ||
                 (rate[k][r] = timed_run(&p)) < 0;
        }
        if (rc == 0)
            gain[r] = rate[1][r] / rate[0][r];
    }
    if (rc == 0) {
        qsort(gain, (size_t)rounds, sizeof gain[0], cmp_double);
        printf("# N=%d settled for %ld cycles: E_k/E_el = %.2g\n", p.sim->n, p.settled, p.ek_ee);
        for (int k = 0; k < 2; k++) {
            qsort(rate[k], (size_t)rounds, sizeof rate[k][0], cmp_double);
            printf("bench threads=%d N=%d steps=%ld particle_steps_per_s=%.4g min=%.4g max=%.4g\n",
                   count[k], p.sim->n, p.steps, rate[k][rounds / 2], rate[k][0],
                   rate[k][rounds - 1]);
        }
        printf("bench threads speed-up %d/1 N=%d median=%.3f min=%.3f max=%.3f rounds=%d\n",
               threads, p.sim->n, gain[rounds / 2], gain[0], gain[rounds - 1], rounds);
        report_details(&p);
    } else if (err.msg[0]) {
        fprintf(stderr, "bench: %s\n", err.msg);
    }
    prepared_free(&p);
    return rc;
}

static FILE *open_csv(void)
{
    char host[128] = "unknown", dir[256], path[320];
    gethostname(host, sizeof host - 1);
    mkdir("reports", 0777);
    mkdir("reports/bench", 0777);
    snprintf(dir, sizeof dir, "reports/bench/%s", host);
    mkdir(dir, 0777);
    snprintf(path, sizeof path, "%s/dense.csv", dir);
    struct stat st;
    const int fresh = stat(path, &st) != 0;
    FILE *f = fopen(path, "a");
    if (f && fresh)
        fputs("unix_time,n,steps,median,min,max,contacts_per_disc,rebuilds\n", f);
    return f;
}

/* Where does the cell grid start to pay?  Time the same settled packing
 * with grid = off (all pairs) and grid = on for small N. */
static int grid_crossover(const char *path)
{
    static const long sizes[] = {4, 8, 16, 24, 32, 48, 64, 96, 128, 192, 256};
    /* settled: time the packing at rest; falling: time the first cycles of
     * the fall (settle stage cut to one cycle), when rebuilds are frequent. */
    static const char *const phase[] = {NULL, "stage.settle.cycles=1"};
    static const char *const phase_name[] = {"settled", "falling"};
    for (int p = 0; p < 2; p++) {
        printf("grid cross-over, %s packing (particle-steps/s, median of %d)\n", phase_name[p],
               REPEATS);
        printf("%6s %12s %12s %8s\n", "N", "all_pairs", "grid", "grid/all");
        for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
            struct options off = {"settings.grid=off", phase[p], 0, 0.2, 1, 0};
            struct options on = {"settings.grid=on", phase[p], 0, 0.2, 1, 0};
            if (run_one(path, sizes[k], NULL, &off) || run_one(path, sizes[k], NULL, &on))
                return 1;
            printf("%6ld %12.4g %12.4g %8.3f\n", sizes[k], off.median, on.median,
                   on.median / off.median);
            fflush(stdout);
        }
    }
    return 0;
}

/* The pile of MLH Sec. 4.3 (cases/piles/pile30_bumpy.scene with L = 100,
 * 1717 discs, frictionless), relaxed from the lattice under a gravity ramp
 * until its stop rule holds: each repeat is a whole run from scratch. */
static int pile_bench(const char *path)
{
    double rate[REPEATS];
    long steps = 0;
    int n = 0;
    for (int k = 0; k < REPEATS; k++) {
        struct bal_scene sc;
        struct bal_error err = {0};
        struct bal_sim *sim = NULL;
        bal_scene_default(&sc);
        if (bal_scene_load(&sc, path, &err) || bal_scene_set(&sc, "pile.p.L=100", &err) ||
            bal_sim_create(&sim, &sc, &err) || bal_sim_run(sim, NULL, NULL, &err)) {
            fprintf(stderr, "bench: %s\n", err.msg);
            bal_sim_free(sim);
            bal_scene_free(&sc);
            return 1;
        }
        rate[k] = (double)sim->step * sim->n / sim->wall_seconds;
        steps = sim->step;
        n = sim->n;
        bal_sim_free(sim);
        bal_scene_free(&sc);
    }
    qsort(rate, REPEATS, sizeof rate[0], cmp_double);
    printf("bench pile N=%d steps=%ld particle_steps_per_s=%.4g min=%.4g max=%.4g\n", n, steps,
           rate[REPEATS / 2], rate[0], rate[REPEATS - 1]);
    return 0;
}

/* ------------------------------------------------------------------ */
/* What each optional module costs (issue 6, item 6)                    */
/* ------------------------------------------------------------------ */

/* One configuration of the module benchmark: overrides on the dense scene. */
struct module_config {
    const char *name;
    const char *sets[4];
};

/* The modules are chosen when a simulation is created, so every
 * configuration is its own simulation, started from the same settled
 * packing (frictionless, settled by global damping: the bare build can make
 * it too): positions and rotations copied by scene-order id from one
 * reference run, velocities zero.  All use the power law (its force needs
 * no history); ν = 1 is the linear baseline.  A frictionless or undamped
 * copy of a frictional packing would flow, so the timed cycles use a time
 * step 1e-4 of the scene's: the packing stays put (no rebuilds), and every
 * configuration does its per-cycle work on the same contacts — the cost of
 * a cycle does not depend on Δt. */
#define MODULES_DT_FACTOR 1e-4
static const struct module_config module_configs[] = {
    {"base (frictionless, undamped, linear)", {"material.grain.friction=0", "material.box.friction=0",
                                               "settings.beta=0", "settings.alpha=0"}},
    {"+ tangential history (friction 0.5)", {"settings.beta=0", "settings.alpha=0", NULL, NULL}},
    {"+ contact damping (beta)", {"material.grain.friction=0", "material.box.friction=0",
                                  "settings.alpha=0", NULL}},
    {"+ global damping (alpha)", {"material.grain.friction=0", "material.box.friction=0",
                                  "settings.beta=0", NULL}},
    {"+ nonlinear normal law (nu = 3/2)", {"material.grain.friction=0", "material.box.friction=0",
                                           "settings.beta=0", "settings.alpha=0"}},
    /* rolling resistance rides on the tangential history (the loop that
     * has it): compare with "+ tangential history" */
    {"+ tangential + rolling (JYH Model 1, delta 1.6)",
     {"settings.beta=0", "settings.alpha=0", "material.grain.rolling=1.6", NULL}},
    {"+ tangential + rolling (JYH Model 2, delta 1.6)",
     {"settings.beta=0", "settings.alpha=0", "material.grain.rolling=1.6",
      "settings.rolling_model=model2"}},
    {"all on (rolling not)", {NULL, NULL, NULL, NULL}},
    {"all on, rolling Model 1 delta 1.6", {"material.grain.rolling=1.6", NULL, NULL, NULL}},
};

static int load_config(const char *path, long n, const struct module_config *c, int nonlinear,
                       struct bal_scene *sc, struct bal_sim **sim, struct bal_error *err)
{
    const char *sets[8] = {"settings.normal_law=power"};
    int k = 1;
    if (nonlinear) {
        sets[k++] = "settings.nu=1.5";
        sets[k++] = "settings.delta0=1";
    }
    for (int q = 0; c && q < 4 && c->sets[q]; q++)
        sets[k++] = c->sets[q];
    return load_scene(path, n, sets, k, sc, sim, err);
}

/* The reference packing of the module costs: frictionless and without
 * dashpots, settled by global damping alone, so that the bare build (which
 * has only that pair loop) settles exactly the same packing. */
static const struct module_config modules_settled = {
    "frictionless, global damping",
    {"material.grain.friction=0", "material.box.friction=0", "settings.beta=0", NULL}};

/* The N-disc packing of configuration `how`, settled: every stage but the
 * last, then blocks of the first stage's length until E_k < 1e-3 E_el, at
 * most `blocks` of them.  Returned in scene order: x, y and θ of disc id k
 * at xyt[3k], xyt[3k + 1], xyt[3k + 2] (malloc'd). */
static int settle_packing(const char *path, long n, const char *what,
                          const struct module_config *how, long blocks, double **xyt, int *n_out)
{
    struct bal_scene sc;
    struct bal_sim *ref = NULL;
    struct bal_error err = {0};
    int rc = load_config(path, n, how, 0, &sc, &ref, &err);
    long settle = 0;
    for (int g = 0; rc == 0 && g + 1 < sc.n_stages; g++) {
        bal_sim_set_stage(ref, g);
        for (long c = 0; rc == 0 && c < sc.stages[g].cycles; c++, settle++)
            rc = bal_sim_step(ref, &err) != BAL_OK;
    }
    while (rc == 0 && bal_measure_kinetic(ref) > SETTLED_EK_OVER_EE * bal_measure_elastic(ref) &&
           settle < blocks * sc.stages[0].cycles)
        for (long c = 0; rc == 0 && c < sc.stages[0].cycles; c++, settle++)
            rc = bal_sim_step(ref, &err) != BAL_OK;
    *xyt = rc ? NULL : malloc(3 * sizeof **xyt * (size_t)ref->n);
    if (rc == 0 && *xyt == NULL) {
        snprintf(err.msg, sizeof err.msg, "out of memory");
        rc = 1;
    }
    if (rc) {
        fprintf(stderr, "bench: settling: %s\n", err.msg);
    } else {
        printf("# %s: N=%d packing settled for %ld cycles (%s) (E_k/E_el = %.2g); each "
               "configuration starts from it at rest\n",
               what, ref->n, settle, how->name, bal_measure_kinetic(ref) / bal_measure_elastic(ref));
        for (int i = 0; i < ref->n; i++) {
            double *p = *xyt + 3 * (size_t)ref->id[i];
            p[0] = ref->x[i], p[1] = ref->y[i], p[2] = ref->th[i];
        }
        *n_out = ref->n;
    }
    bal_sim_free(ref);
    bal_scene_free(&sc);
    return rc;
}

/* The settled packing saved by `--modules-pack`, so that the short runs of
 * bench-modules-count do not each settle it again: a header line with N,
 * then the 3N doubles of settle_packing, in this machine's byte order. */
#define PACK_MAGIC "ballast-packing-1"

static int write_packing(const char *file, const double *xyt, int n)
{
    FILE *f = fopen(file, "wb");
    int ok = f && fprintf(f, "%s %d\n", PACK_MAGIC, n) > 0 &&
             fwrite(xyt, sizeof *xyt, 3 * (size_t)n, f) == 3 * (size_t)n;
    ok = f && fclose(f) == 0 && ok;
    if (!ok)
        fprintf(stderr, "bench: %s: cannot write the packing\n", file);
    return !ok;
}

static int read_packing(const char *file, double **xyt, int *n)
{
    char magic[32] = "";
    FILE *f = fopen(file, "rb");
    int ok = f && fscanf(f, "%31s %d", magic, n) == 2 && strcmp(magic, PACK_MAGIC) == 0 &&
             *n > 0 && fgetc(f) == '\n';
    *xyt = ok ? malloc(3 * sizeof **xyt * (size_t)*n) : NULL;
    ok = ok && *xyt && fread(*xyt, sizeof **xyt, 3 * (size_t)*n, f) == 3 * (size_t)*n;
    if (f)
        fclose(f);
    if (!ok) {
        fprintf(stderr, "bench: %s: not a packing written by bench --modules-pack\n", file);
        free(*xyt);
        *xyt = NULL;
    }
    return !ok;
}

/* Configuration c of the N-disc scene, started from the packing at rest
 * with a time step dt_factor times the scene's, in its last stage. */
static int start_config(const char *path, long n, const struct module_config *c, int nonlinear,
                        const double *xyt, int nn, double dt_factor, struct bal_scene *sc,
                        struct bal_sim **sim, struct bal_error *err)
{
    if (load_config(path, n, c, nonlinear, sc, sim, err))
        return 1;
    if ((*sim)->n != nn) {
        snprintf(err->msg, sizeof err->msg, "the packing has %d discs, the scene %d", nn,
                 (*sim)->n);
        return 1;
    }
    struct bal_sim *s = *sim;
    for (int k = 0; k < nn; k++) {
        const int to = s->slot[k];
        s->x[to] = xyt[3 * (size_t)k];
        s->y[to] = xyt[3 * (size_t)k + 1];
        s->th[to] = xyt[3 * (size_t)k + 2];
        s->vx[to] = s->vy[to] = s->w[to] = 0;
    }
    s->need_rebuild = 1;
    s->dt *= dt_factor;
    bal_sim_set_stage(s, sc->n_stages - 1);
    return 0;
}

#ifdef BAL_BARE
#define BUILD_NAME "bare"
#else
#define BUILD_NAME "normal"
#endif

static int modules_bench(const char *path, long n, int base_only)
{
    double *xyt = NULL;
    int nn = 0;
    if (settle_packing(path, n, "module costs", &modules_settled, MAX_SETTLE_BLOCKS + 1, &xyt, &nn))
        return 1;
    struct bal_error err = {0};
    const size_t n_cfg = base_only ? 1 : sizeof module_configs / sizeof module_configs[0];
    for (size_t k = 0; k < n_cfg; k++) {
        if (getenv("BAL_BENCH_ONLY") && (int)k != atoi(getenv("BAL_BENCH_ONLY")))
            continue; /* one configuration (its index), to repeat it */
        const struct module_config *c = &module_configs[k];
        struct bal_scene sc;
        struct bal_sim *sim = NULL;
        if (start_config(path, n, c, k == 4, xyt, nn, MODULES_DT_FACTOR, &sc, &sim, &err)) {
            fprintf(stderr, "bench: %s\n", err.msg);
            bal_sim_free(sim);
            bal_scene_free(&sc);
            free(xyt);
            return 1;
        }
        long steps = 50;
        double t = timed_steps(sim, steps, &err);
        if (t > 0)
            steps = (long)fmax(100, TARGET_SECONDS / (t / (double)steps));
        double rate[REPEATS];
        for (int r = 0; r < REPEATS && t >= 0; r++) {
            t = timed_steps(sim, steps, &err);
            rate[r] = (double)steps * (double)sim->n / t;
        }
        if (t < 0) {
            fprintf(stderr, "bench: %s: %s\n", c->name, err.msg);
            bal_sim_free(sim);
            bal_scene_free(&sc);
            free(xyt);
            return 1;
        }
        qsort(rate, REPEATS, sizeof rate[0], cmp_double);
        printf("bench module build=%s config=\"%s\" N=%d particle_steps_per_s=%.4g min=%.4g "
               "max=%.4g contacts=%ld rebuilds=%ld\n",
               BUILD_NAME, c->name, sim->n, rate[REPEATS / 2], rate[0], rate[REPEATS - 1],
               count_contacts(sim), sim->rebuilds);
        fflush(stdout);
        bal_sim_free(sim);
        bal_scene_free(&sc);
    }
    free(xyt);
    return 0;
}

/* ------------------------------------------------------------------ */
/* The all-off scene, counted and timed: `make bench-modules-count`     */
/* ------------------------------------------------------------------ */

/* Wall-clock repeats of one build spread by ±25 % on a shared VM, so the
 * normal and the bare build are compared by what does not depend on the
 * machine's load: the instructions of the timed cycles, counted by
 * callgrind.  bench --modules-step brackets its timed cycles with
 * callgrind's client requests (no-ops outside valgrind): run under
 *   valgrind --tool=callgrind --instr-atstart=no --collect-atstart=no
 * only those cycles are counted, after warm-up cycles that fill the
 * simulated caches; the packing comes from a file (--modules-pack), so
 * nothing is settled under valgrind. */
#if defined(__has_include)
#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define HAVE_CALLGRIND 1
#endif
#endif
#ifndef HAVE_CALLGRIND
#define CALLGRIND_START_INSTRUMENTATION
#define CALLGRIND_STOP_INSTRUMENTATION
#define CALLGRIND_TOGGLE_COLLECT
#endif

#define WARMUP_STEPS 20 /* the first cycle rebuilds the pair list */
#define MAX_STEP_REPEATS 64

/* FNV-1a over the bits of every disc's position, rotation and velocities in
 * scene order: the two builds did the same arithmetic if these agree. */
static unsigned long long state_checksum(const struct bal_sim *s)
{
    unsigned long long h = 1469598103934665603ULL;
    for (int k = 0; k < s->n; k++) {
        const int i = s->slot[k];
        const double v[6] = {s->x[i], s->y[i], s->th[i], s->vx[i], s->vy[i], s->w[i]};
        const unsigned char *b = (const unsigned char *)v;
        for (size_t q = 0; q < sizeof v; q++)
            h = (h ^ b[q]) * 1099511628211ULL;
    }
    return h;
}

/* The all-off configuration from the packing in `pack`: WARMUP_STEPS
 * cycles, then `repeats` timed runs of `steps` cycles.  One line:
 *   bench count build=B N= steps= repeats= particle_steps= contacts= pairs=
 *       rebuilds= timed_rebuilds= checksum= times=t1,t2,...
 * (particle_steps counts every timed cycle, times are seconds per run). */
static int modules_step(const char *path, const char *pack, long steps, int repeats)
{
    double *xyt = NULL;
    int nn = 0;
    if (steps < 1 || repeats < 1 || repeats > MAX_STEP_REPEATS) {
        fprintf(stderr, "bench: --modules-step: steps >= 1, 1 <= repeats <= %d\n",
                MAX_STEP_REPEATS);
        return 2;
    }
    if (read_packing(pack, &xyt, &nn))
        return 1;
    struct bal_scene sc;
    struct bal_sim *sim = NULL;
    struct bal_error err = {0};
    double t[MAX_STEP_REPEATS];
    long rebuilds0 = 0;
    int rc = start_config(path, nn, &module_configs[0], 0, xyt, nn, MODULES_DT_FACTOR, &sc, &sim,
                          &err);
    if (rc == 0) {
        CALLGRIND_START_INSTRUMENTATION;
        rc = timed_steps(sim, WARMUP_STEPS, &err) < 0;
        rebuilds0 = sim->rebuilds;
        CALLGRIND_TOGGLE_COLLECT;
        for (int r = 0; r < repeats && rc == 0; r++)
            rc = (t[r] = timed_steps(sim, steps, &err)) < 0;
        CALLGRIND_TOGGLE_COLLECT;
        CALLGRIND_STOP_INSTRUMENTATION;
    }
    if (rc) {
        fprintf(stderr, "bench: %s\n", err.msg);
    } else {
        printf("bench count build=%s N=%d steps=%ld repeats=%d particle_steps=%.0f contacts=%ld "
               "pairs=%ld rebuilds=%ld timed_rebuilds=%ld checksum=%016llx times=",
               BUILD_NAME, sim->n, steps, repeats, (double)steps * repeats * sim->n,
               count_contacts(sim), sim->pp.n, sim->rebuilds, sim->rebuilds - rebuilds0,
               state_checksum(sim));
        for (int r = 0; r < repeats; r++)
            printf("%s%.6g", r ? "," : "", t[r]);
        printf("\n");
    }
    bal_sim_free(sim);
    bal_scene_free(&sc);
    free(xyt);
    return rc;
}

/* ------------------------------------------------------------------ */
/* The cost model: `make bench-cost` (core/bench/cost.py)                */
/* ------------------------------------------------------------------ */

/* Any scene file (the race scenes of harness/peer/race.py), run through its
 * stages on one thread as bal_sim_run does (with its energy guard every
 * 256 cycles; a scene of the race writes one series row, at its end, which
 * is left out), with callgrind collecting only windows of the run: the last
 * `window` cycles of every `period`, after COST_WARM instrumented cycles
 * that fill the simulated caches.  The windows sample a run whose cost
 * changes as it goes (the settling packing); the rest runs uninstrumented.
 * One line:
 *   bench cost N= steps= counted_steps= particle_steps= rebuilds=
 *       counted_rebuilds= counted_reorders= pairs_per_disc= contacts_per_disc=
 *       wall_contacts_per_disc= sliding_per_disc=
 * (particle_steps = N x counted_steps; the per-disc figures are means over
 * the end of each window). */
#define COST_WARM 3
#define COST_GUARD_EVERY 256 /* ENERGY_CHECK_EVERY of sim.c */

static int cost_run(const char *path, long period, long window)
{
    if (period < window + COST_WARM || window < 1) {
        fprintf(stderr, "bench: --cost: period >= window + %d, window >= 1\n", COST_WARM);
        return 2;
    }
    struct bal_scene sc;
    struct bal_sim *sim = NULL;
    struct bal_error err = {0};
    bal_scene_default(&sc);
    int rc = bal_scene_load(&sc, path, &err) != BAL_OK || bal_sim_create(&sim, &sc, &err) != BAL_OK ||
             bal_sim_set_threads(sim, 1, &err) != BAL_OK;
    long step = 0, counted = 0, rebuilds = 0, reorders = 0, rb0 = 0, ro0 = 0, samples = 0;
    double pairs = 0, contacts = 0, walls = 0, sliding = 0;
    for (int g = 0; rc == 0 && g < sc.n_stages; g++) {
        bal_sim_set_stage(sim, g);
        for (long c = 0; rc == 0 && c < sc.stages[g].cycles; c++, step++) {
            const long ph = step % period;
            if (ph == period - window - COST_WARM)
                CALLGRIND_START_INSTRUMENTATION;
            if (ph == period - window) {
                CALLGRIND_TOGGLE_COLLECT;
                rb0 = sim->rebuilds, ro0 = sim->reorders;
            }
            rc = bal_sim_step(sim, &err) != BAL_OK;
            if (rc == 0 && sim->step % COST_GUARD_EVERY == 0)
                rc = bal_energy_guard(sim, &err) != BAL_OK;
            if (ph == period - 1) {
                CALLGRIND_TOGGLE_COLLECT;
                CALLGRIND_STOP_INSTRUMENTATION;
                counted += window;
                rebuilds += sim->rebuilds - rb0;
                reorders += sim->reorders - ro0;
                long w = 0, sl = 0;
                for (long q = 0; q < sim->pw.n; q++)
                    w += (sim->pw.flags[q] & BAL_PAIR_TOUCHING) != 0;
                for (long q = 0; q < sim->pp.n; q++)
                    sl += (sim->pp.flags[q] & BAL_PAIR_SLIDING) != 0;
                pairs += (double)sim->pp.n / sim->n;
                contacts += (double)count_contacts(sim) / sim->n;
                walls += (double)w / sim->n;
                sliding += (double)sl / sim->n;
                samples++;
            }
        }
    }
    if (rc) {
        fprintf(stderr, "bench: %s\n", err.msg);
    } else if (samples == 0) {
        fprintf(stderr, "bench: --cost: %s: no window of %ld cycles in %ld\n", path, period, step);
        rc = 1;
    } else {
        printf("bench cost N=%d steps=%ld counted_steps=%ld particle_steps=%.0f rebuilds=%ld "
               "counted_rebuilds=%ld counted_reorders=%ld pairs_per_disc=%.4f "
               "contacts_per_disc=%.4f wall_contacts_per_disc=%.5f sliding_per_disc=%.4f\n",
               sim->n, step, counted, (double)counted * sim->n, sim->rebuilds, rebuilds, reorders,
               pairs / samples, contacts / samples, walls / samples, sliding / samples);
    }
    bal_sim_free(sim);
    bal_scene_free(&sc);
    return rc;
}

/* One `bench count` line, parsed. */
struct count_line {
    char build[16];
    int n;
    long steps;
    int repeats;
    double particle_steps;
    long contacts, pairs, rebuilds, timed_rebuilds;
    char checksum[24];
    double times[MAX_STEP_REPEATS];
};

static const char *field(const char *line, const char *key)
{
    const size_t len = strlen(key);
    for (const char *p = strstr(line, key); p; p = strstr(p + 1, key))
        if ((p == line || p[-1] == ' ') && p[len] == '=')
            return p + len + 1;
    return NULL;
}

static int parse_count_line(const char *line, struct count_line *c)
{
    const char *f[10] = {field(line, "build"),    field(line, "N"),
                         field(line, "steps"),    field(line, "repeats"),
                         field(line, "particle_steps"), field(line, "contacts"),
                         field(line, "pairs"),    field(line, "rebuilds"),
                         field(line, "timed_rebuilds"), field(line, "checksum")};
    const char *times = field(line, "times");
    if (strncmp(line, "bench count ", 12) != 0 || !times)
        return 1;
    for (int k = 0; k < 10; k++)
        if (!f[k])
            return 1;
    if (sscanf(f[0], "%15s", c->build) != 1 || sscanf(f[9], "%23s", c->checksum) != 1)
        return 1;
    c->n = atoi(f[1]);
    c->steps = atol(f[2]);
    c->repeats = atoi(f[3]);
    c->particle_steps = atof(f[4]);
    c->contacts = atol(f[5]);
    c->pairs = atol(f[6]);
    c->rebuilds = atol(f[7]);
    c->timed_rebuilds = atol(f[8]);
    if (c->repeats < 1 || c->repeats > MAX_STEP_REPEATS || c->n < 1 || c->steps < 1)
        return 1;
    for (int r = 0; r < c->repeats; r++) {
        char *end;
        c->times[r] = strtod(times, &end);
        if (end == times || c->times[r] <= 0)
            return 1;
        times = *end == ',' ? end + 1 : end;
    }
    return 0;
}

/* The event totals of a callgrind output file (its `events:` line and its
 * `totals:` line, or `summary:` without one); returns the number of events,
 * 0 on failure. */
#define MAX_EVENTS 16
static int read_callgrind(const char *file, char names[][8], double *totals)
{
    char line[1024];
    int n_names = 0, n_totals = 0;
    FILE *f = fopen(file, "r");
    while (f && fgets(line, sizeof line, f)) {
        char *save = NULL;
        if (strncmp(line, "events:", 7) == 0)
            for (char *w = strtok_r(line + 7, " \n", &save); w && n_names < MAX_EVENTS;
                 w = strtok_r(NULL, " \n", &save))
                snprintf(names[n_names++], 8, "%s", w);
        else if (strncmp(line, "totals:", 7) == 0 ||
                 (strncmp(line, "summary:", 8) == 0 && n_totals == 0)) {
            n_totals = 0; /* totals: wins over summary: */
            for (char *w = strtok_r(strchr(line, ':') + 1, " \n", &save); w && n_totals < MAX_EVENTS;
                 w = strtok_r(NULL, " \n", &save))
                totals[n_totals++] = atof(w);
        }
    }
    if (f)
        fclose(f);
    if (n_names == 0 || n_totals != n_names) {
        fprintf(stderr, "bench: %s: no callgrind event totals\n", file);
        return 0;
    }
    return n_names;
}

static double event(char names[][8], const double *totals, int n, const char *name)
{
    for (int k = 0; k < n; k++)
        if (strcmp(names[k], name) == 0)
            return totals[k];
    return NAN;
}

static int read_count_file(const char *file, struct count_line *lines, int max)
{
    char line[4096];
    int n = 0;
    FILE *f = fopen(file, "r");
    if (!f) {
        fprintf(stderr, "bench: %s: cannot read\n", file);
        return -1;
    }
    while (n < max && fgets(line, sizeof line, f))
        if (parse_count_line(line, &lines[n]) == 0)
            n++;
    fclose(f);
    return n;
}

static int same_work(const struct count_line *a, const struct count_line *b)
{
    return a->n == b->n && a->steps == b->steps && a->repeats == b->repeats &&
           a->contacts == b->contacts && a->pairs == b->pairs && a->rebuilds == b->rebuilds &&
           a->timed_rebuilds == b->timed_rebuilds && strcmp(a->checksum, b->checksum) == 0;
}

#define MAX_PAIRS 64
#define WITHIN 0.03 /* "within a few percent": the bound this summary judges by */

/* The summary of bench-modules-count: instructions (and simulated cache
 * misses) per particle-step of each build from callgrind, then the pinned
 * wall-clock pairs.  Arguments: the callgrind output and the count line of
 * the normal build, the same of the bare build, the file of alternating
 * wall-clock lines (normal, bare, normal, ...). */
static int modules_summary(char **arg)
{
    static const char *const build[2] = {"normal", "bare"};
    static const char *const shown[] = {"Ir", "D1mr", "D1mw", "DLmr", "DLmw"};
    char names[2][MAX_EVENTS][8];
    double tot[2][MAX_EVENTS];
    struct count_line cg[2];
    double per[2][5];
    for (int b = 0; b < 2; b++) {
        const int ne = read_callgrind(arg[2 * b], names[b], tot[b]);
        if (ne == 0)
            return 1;
        if (read_count_file(arg[2 * b + 1], &cg[b], 1) != 1 || strcmp(cg[b].build, build[b]) != 0) {
            fprintf(stderr, "bench: no %s-build count in %s\n", build[b], arg[2 * b + 1]);
            return 1;
        }
        for (int e = 0; e < 5; e++)
            per[b][e] = event(names[b], tot[b], ne, shown[e]) / cg[b].particle_steps;
    }
    const int same = same_work(&cg[0], &cg[1]);
    printf("# callgrind, timed cycles only: N=%d, %ld cycles after %d warm-up, %ld contacts, "
           "%ld rebuilds in the timed cycles; same work in both builds (contacts, rebuilds, "
           "checksum %s): %s\n",
           cg[0].n, cg[0].steps * cg[0].repeats, WARMUP_STEPS, cg[0].contacts,
           cg[0].timed_rebuilds, cg[0].checksum, same ? "yes" : "NO");
    printf("%-28s %12s %12s %10s\n", "per particle-step", "normal", "bare", "normal/bare");
    for (int e = 0; e < 5; e++) {
        printf("%-28s %12.3f %12.3f", shown[e], per[0][e], per[1][e]);
        if (per[1][e] > 0)
            printf(" %10.4f\n", per[0][e] / per[1][e]);
        else
            printf(" %10s\n", per[0][e] > 0 ? "inf" : "-");
    }
    const double ir_ratio = per[0][0] / per[1][0];
    printf("bench count instructions normal/bare=%.4f within_%.0f%%=%s\n", ir_ratio, 100 * WITHIN,
           fabs(ir_ratio - 1) <= WITHIN ? "yes" : "NO");

    struct count_line *wall = malloc(2 * MAX_PAIRS * sizeof *wall);
    const int nw = wall ? read_count_file(arg[4], wall, 2 * MAX_PAIRS) : -1;
    if (nw < 2) {
        fprintf(stderr, "bench: %s: no wall-clock pairs\n", arg[4]);
        free(wall);
        return 1;
    }
    const int pairs = nw / 2;
    double all[2][MAX_PAIRS * MAX_STEP_REPEATS], ratio[MAX_PAIRS];
    int n_all[2] = {0, 0}, ok = 1;
    for (int p = 0; p < pairs; p++) {
        double best[2];
        for (int b = 0; b < 2; b++) {
            const struct count_line *c = &wall[2 * p + b];
            ok = ok && strcmp(c->build, build[b]) == 0 && same_work(c, &wall[0]);
            best[b] = INFINITY;
            for (int r = 0; r < c->repeats; r++) {
                all[b][n_all[b]++] = c->times[r];
                best[b] = fmin(best[b], c->times[r]);
            }
        }
        ratio[p] = best[0] / best[1];
    }
    if (!ok)
        printf("# WARNING: the wall-clock runs are not alternating normal/bare, or did different "
               "work\n");
    const double ps = (double)wall[0].n * (double)wall[0].steps; /* per run */
    printf("# wall clock, pinned to one core: %d alternating pairs of processes, each %d runs of "
           "%ld cycles (N=%d); particle-steps/s over all %d runs of a build:\n",
           pairs, wall[0].repeats, wall[0].steps, wall[0].n, n_all[0]);
    printf("%-28s %12s %12s %10s\n", "", "normal", "bare", "bare/normal");
    double best[2], median[2];
    for (int b = 0; b < 2; b++) {
        qsort(all[b], (size_t)n_all[b], sizeof all[b][0], cmp_double);
        best[b] = ps / all[b][0];
        median[b] = ps / all[b][n_all[b] / 2];
    }
    printf("%-28s %12.4g %12.4g %10.4f\n", "best (least disturbed)", best[0], best[1],
           best[1] / best[0]);
    printf("%-28s %12.4g %12.4g %10.4f\n", "median", median[0], median[1], median[1] / median[0]);
    qsort(ratio, (size_t)pairs, sizeof ratio[0], cmp_double);
    printf("# per pair, time of the normal build / time of the bare build (best run of each "
           "process): median %.4f, quartiles %.4f %.4f, range %.4f .. %.4f\n",
           ratio[pairs / 2], ratio[pairs / 4], ratio[(3 * pairs) / 4], ratio[0], ratio[pairs - 1]);
    const double wall_ratio = best[1] / best[0];
    printf("bench count wall_min normal/bare=%.4f within_%.0f%%=%s\n", wall_ratio, 100 * WITHIN,
           fabs(wall_ratio - 1) <= WITHIN ? "yes" : "NO");
    free(wall);
    return !same || !ok;
}

/* ------------------------------------------------------------------ */
/* The catalogue's own workload against the race (issue 33)             */
/* ------------------------------------------------------------------ */

/* The dense race scene of `make bench-peer` (harness/peer/race.py,
 * settle_dense), made in this process: the N-disc packing of dense.scene
 * settled with the race's normal law and without friction (its damping
 * kept) until E_k < 1e-3 E_el (the race allows 40 000 cycles: RACE_SETTLE
 * blocks of the settle stage's 6 000), then raced from rest with the
 * scene's friction, the power law with ν = 1, no damping, the skin chosen
 * from the motion (the race's ballast settings). */
#define RACE_N 20000
#define RACE_SETTLE 7
static const struct module_config race_settled = {
    "frictionless, the scene's damping", {"material.grain.friction=0", "material.box.friction=0",
                                          NULL, NULL}};
static const struct module_config race_config = {
    "race", {"settings.beta=0", "settings.alpha=0", "settings.skin_rule=motion", NULL}};

/* The biaxial test of cases/biaxial/case.txt, variants m0_s200_e020 (no
 * rolling resistance) and m1_d1.6_s200_e020 (Model 1, δ = 1.6): specimen
 * e020, σ_h = 200 kPa, consolidated to its stop rule (the fixed preparation,
 * untimed), then BIAXIAL_SHEAR_CYCLES cycles of shearing, of which all but
 * the first BIAXIAL_UNTIMED are timed.  The sets are case.txt's (make_case.py
 * writes them); the catalogue runs 250 000 (default tier) or 500 000 (full)
 * cycles of shearing, this a slice of its start. */
#define BIAXIAL_SHEAR_CYCLES 41984 /* 41 x 1024: the timed window is whole reports */
#define BIAXIAL_SHEAR_TEXT "41984"  /* the same, for the scene's set */
#define BIAXIAL_UNTIMED 1024       /* bal_sim_run's clock is read every 1024 cycles */
static const char *const biaxial_sets[] = {
    "stage.consolidate.servo=spec_top 200000 0.5 0.05 spec_left spec_right",
    "stage.consolidate.servo=spec_bottom 200000 0.5 0.05 spec_left spec_right",
    "stage.consolidate.servo=spec_left 200000 0.5 0.05 spec_bottom spec_top",
    "stage.consolidate.servo=spec_right 200000 0.5 0.05 spec_bottom spec_top",
    "stage.shear.servo=spec_left 200000 0.5 1 spec_bottom spec_top",
    "stage.shear.servo=spec_right 200000 0.5 1 spec_bottom spec_top",
    "import.spec.discs=specimens/e020_r1/discs.tsv",
    "import.spec.walls=specimens/e020_r1/walls.tsv",
};

/* The sets of one biaxial test: biaxial_sets, the rolling resistance, the
 * shearing's length; returns how many. */
#define BIAXIAL_SETS 16
static int biaxial_variant(const char *sets[BIAXIAL_SETS], const char *rolling, const char *shear)
{
    const int n = (int)(sizeof biaxial_sets / sizeof biaxial_sets[0]);
    for (int k = 0; k < n; k++)
        sets[k] = biaxial_sets[k];
    sets[n] = rolling;
    sets[n + 1] = shear ? shear : "stage.shear.cycles=" BIAXIAL_SHEAR_TEXT;
    return n + 2;
}

enum { W_RACE, W_BIAX_M0, W_BIAX_M1, W_POLY, W_KINDS };
static const char *const workload_name[W_KINDS] = {"race_dense", "biaxial_m0_s200_e020",
                                                   "biaxial_m1_d1.6_s200_e020", "pile_poly_L100"};

/* Where the shear stage's timed window starts: bal_sim_run's first progress
 * report in that stage (after its first 1024 cycles).  Under callgrind
 * (--instr-atstart=no --collect-atstart=no), the window is what it counts. */
struct stage_clock {
    int stage;
    long step;
    double cpu;
};

/* The CPU time of the calling thread: the workload's runs are timed by it,
 * not by the wall clock, which on a shared machine also counts the time
 * another process has the core (on an idle machine the two agree). */
static double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void stage_clock_report(const struct bal_progress *p, void *ctx)
{
    struct stage_clock *c = ctx;
    if (p->stage == c->stage && c->step < 0) {
        c->step = p->step;
        c->cpu = cpu_now();
        CALLGRIND_START_INSTRUMENTATION;
        CALLGRIND_TOGGLE_COLLECT;
    }
}

/* What one whole run measured. */
struct run_figures {
    double rate;       /* particle-steps/s of the timed cycles */
    long timed, steps; /* cycles timed, cycles run */
    long first_stage;  /* cycles of the first stage (its stop rule) */
    int n;
    long rebuilds;
    double contacts;   /* disc–disc contacts per disc at the end */
};

/* One whole run of a catalogue scene through bal_sim_run, as `ballast run`
 * runs it (series rows written, to /dev/null), on one thread.  With
 * timed_stage >= 0 the rate is that of that stage's cycles after its first
 * 1024, else of the whole run; in CPU seconds (cpu_now). */
static int workload_run(const char *path, const char *const *sets, int n_sets, const char *extra,
                        int timed_stage, struct run_figures *out)
{
    struct bal_scene sc;
    struct bal_sim *sim = NULL;
    struct bal_error err = {0};
    struct stage_clock clock = {timed_stage, -1, 0};
    double cpu0 = 0, cpu1 = 0;
    FILE *series = fopen("/dev/null", "w");
    bal_scene_default(&sc);
    int rc = !series || bal_scene_load(&sc, path, &err) != BAL_OK;
    for (int k = 0; rc == 0 && k < n_sets; k++)
        rc = bal_scene_set(&sc, sets[k], &err) != BAL_OK;
    rc = rc || (extra && bal_scene_set(&sc, extra, &err) != BAL_OK) ||
         bal_sim_create(&sim, &sc, &err) != BAL_OK;
    if (rc == 0) {
        if (timed_stage >= 0)
            bal_sim_set_progress(sim, stage_clock_report, &clock, 0);
        bal_output_series_header(sim, series);
        cpu0 = cpu_now();
        rc = bal_sim_run(sim, series, NULL, &err) != BAL_OK;
        cpu1 = cpu_now();
        if (clock.step >= 0) {
            CALLGRIND_TOGGLE_COLLECT;
            CALLGRIND_STOP_INSTRUMENTATION;
        }
    }
    if (rc == 0 && timed_stage >= 0 && clock.step < 0) {
        snprintf(err.msg, sizeof err.msg, "%s: stage %d has fewer than %d cycles", path,
                 timed_stage, BIAXIAL_UNTIMED);
        rc = 1;
    }
    if (rc) {
        fprintf(stderr, "bench: %s\n", series ? err.msg : "/dev/null: cannot open");
    } else {
        out->steps = sim->step;
        out->timed = timed_stage >= 0 ? sim->step - clock.step : sim->step;
        const double seconds = cpu1 - (timed_stage >= 0 ? clock.cpu : cpu0);
        out->n = sim->n;
        out->rate = (double)out->timed * sim->n / seconds;
        out->first_stage = sc.n_stages > 0 ? sim->log[0].cycles : 0;
        out->rebuilds = sim->rebuilds;
        out->contacts = (double)count_contacts(sim) / sim->n;
    }
    if (series)
        fclose(series);
    bal_sim_free(sim);
    bal_scene_free(&sc);
    return rc;
}

static void print_spread(const char *key, double *v, int n)
{
    qsort(v, (size_t)n, sizeof v[0], cmp_double);
    printf(" %s=%.4g min=%.4g max=%.4g", key, v[n / 2], v[0], v[n - 1]);
}

/* One biaxial test of the workload (rolling: the δ of material grain;
 * shear: its cycles of shearing, or NULL for the workload's), its line; the
 * timed window is what callgrind counts when run under it with
 * --instr-atstart=no --collect-atstart=no (the profile of docs/benchmarks.md). */
static int biaxial_one(const char *biaxial, const char *rolling, const char *shear)
{
    char set[64], cycles[64];
    const char *sets[BIAXIAL_SETS];
    snprintf(set, sizeof set, "material.grain.rolling=%s", rolling);
    if (shear)
        snprintf(cycles, sizeof cycles, "stage.shear.cycles=%s", shear);
    const int n = biaxial_variant(sets, set, shear ? cycles : NULL);
    struct run_figures fig;
    if (workload_run(biaxial, sets, n, NULL, 1, &fig))
        return 1;
    printf("bench biaxial rolling=%s N=%d steps=%ld particle_steps_per_s=%.4g consolidation=%ld "
           "rebuilds=%ld contacts_per_disc=%.3f\n", rolling, fig.n, fig.timed, fig.rate,
           fig.first_stage, fig.rebuilds, fig.contacts);
    return 0;
}

/* `make bench`'s lines for the catalogue's heavy work: the biaxial test at
 * δ = 0 and Model 1 δ = 1.6 and one polydisperse L0 = 100 pile, each with
 * its ratio to the dense race scene measured in the same process.  The
 * four alternate, round by round (race, biaxial m0, biaxial m1, pile), so
 * that the machine's drift falls on all alike; each ratio is taken within
 * its round, and the line gives the median, min and max over the rounds. */
static int workload_bench(const char *dense, const char *biaxial, const char *poly, int rounds)
{
    enum { MAX_ROUNDS = 32 };
    if (rounds < 1 || rounds > MAX_ROUNDS) {
        fprintf(stderr, "bench: --workload: 1 <= rounds <= %d\n", MAX_ROUNDS);
        return 2;
    }
    double *xyt = NULL;
    int nn = 0;
    if (settle_packing(dense, RACE_N, "race_dense", &race_settled, RACE_SETTLE, &xyt, &nn))
        return 1;
    struct bal_scene sc;
    struct bal_sim *race = NULL;
    struct bal_error err = {0};
    int rc = start_config(dense, RACE_N, &race_config, 0, xyt, nn, 1.0, &sc, &race, &err);
    free(xyt);
    long steps = 50;
    double t = rc ? -1 : timed_steps(race, steps, &err); /* (wall clock: calibration only) */
    if (t > 0)
        steps = (long)fmax(100, TARGET_SECONDS / (t / (double)steps));
    rc = rc || t < 0;
    const char *m0[BIAXIAL_SETS], *m1[BIAXIAL_SETS];
    const int n_biax = biaxial_variant(m0, "material.grain.rolling=0", NULL);
    biaxial_variant(m1, "material.grain.rolling=1.6", NULL);
    double rate[W_KINDS][MAX_ROUNDS], ratio[W_KINDS][MAX_ROUNDS];
    struct run_figures fig[W_KINDS] = {{0}};
    for (int r = 0; r < rounds && rc == 0; r++) {
        const double c0 = cpu_now();
        rc = timed_steps(race, steps, &err) < 0;
        rate[W_RACE][r] = (double)steps * race->n / (cpu_now() - c0);
        rc = rc || workload_run(biaxial, m0, n_biax, NULL, 1, &fig[W_BIAX_M0]);
        rate[W_BIAX_M0][r] = fig[W_BIAX_M0].rate;
        rc = rc || workload_run(biaxial, m1, n_biax, NULL, 1, &fig[W_BIAX_M1]);
        rate[W_BIAX_M1][r] = fig[W_BIAX_M1].rate;
        rc = rc || workload_run(poly, NULL, 0, NULL, -1, &fig[W_POLY]);
        rate[W_POLY][r] = fig[W_POLY].rate;
        for (int w = 0; w < W_KINDS; w++)
            ratio[w][r] = rate[w][r] / rate[W_RACE][r];
        fprintf(stderr, "bench: workload round %d of %d done\n", r + 1, rounds);
    }
    if (rc) {
        if (err.msg[0])
            fprintf(stderr, "bench: %s\n", err.msg);
    } else {
        printf("# workload: %d rounds, each the race scene for %ld cycles, then one whole run of "
               "each workload scene, in turn on one thread; rates in particle-steps per CPU second "
               "of the thread; ratio = rate / the race's rate of the same round\n", rounds, steps);
        printf("# %s: %s from rest, friction on, power law nu = 1, no damping, skin_rule = motion; "
               "%ld rebuilds, %.3f contacts per disc at the end\n", workload_name[W_RACE], dense,
               race->rebuilds, (double)count_contacts(race) / race->n);
        for (int w = W_BIAX_M0; w <= W_BIAX_M1; w++)
            printf("# %s: %s consolidated in %ld cycles (its stop rule, untimed), then %d cycles "
                   "of shearing, the last %ld timed; %ld rebuilds, %.3f contacts per disc at the "
                   "end\n", workload_name[w], biaxial, fig[w].first_stage, BIAXIAL_SHEAR_CYCLES,
                   fig[w].timed, fig[w].rebuilds, fig[w].contacts);
        printf("# %s: %s, one whole realisation (seed 1) to its stop rule, timed whole: %ld cycles "
               "(ramp %ld), %ld rebuilds\n", workload_name[W_POLY], poly, fig[W_POLY].steps,
               fig[W_POLY].first_stage, fig[W_POLY].rebuilds);
        printf("bench %s N=%d steps=%ld", workload_name[W_RACE], race->n, steps);
        print_spread("particle_steps_per_s", rate[W_RACE], rounds);
        printf("\n");
        for (int w = W_BIAX_M0; w < W_KINDS; w++) {
            printf("bench %s N=%d steps=%ld", workload_name[w], fig[w].n, fig[w].timed);
            print_spread("particle_steps_per_s", rate[w], rounds);
            print_spread("ratio_to_race", ratio[w], rounds);
            printf("\n");
        }
    }
    bal_sim_free(race);
    bal_scene_free(&sc);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fputs("usage: bench SCENE [N ...]\n       bench --grid SCENE\n", stderr);
        return 2;
    }
    if (strcmp(argv[1], "--grid") == 0 && argc == 3)
        return grid_crossover(argv[2]);
    if (strcmp(argv[1], "--pile") == 0 && argc == 3)
        return pile_bench(argv[2]);
    if (strcmp(argv[1], "--modules") == 0 && argc >= 3)
        return modules_bench(argv[2], argc > 3 ? atol(argv[3]) : 20000, 0);
    if (strcmp(argv[1], "--modules-base") == 0 && argc >= 3)
        return modules_bench(argv[2], argc > 3 ? atol(argv[3]) : 20000, 1);
    if (strcmp(argv[1], "--modules-pack") == 0 && argc == 5) {
        double *xyt = NULL;
        int nn = 0;
        int rc = settle_packing(argv[2], atol(argv[3]), "module costs", &modules_settled,
                                MAX_SETTLE_BLOCKS + 1, &xyt, &nn) ||
                 write_packing(argv[4], xyt, nn);
        free(xyt);
        return rc;
    }
    if (strcmp(argv[1], "--modules-step") == 0 && argc == 6)
        return modules_step(argv[2], argv[3], atol(argv[4]), atoi(argv[5]));
    if (strcmp(argv[1], "--pair") == 0 && (argc == 5 || argc == 6))
        return scaling_pair(argv[2], atol(argv[3]), atol(argv[4]), argc == 6 ? atoi(argv[5]) : 9);
    if (strcmp(argv[1], "--threads") == 0 && (argc == 5 || argc == 6))
        return threads_bench(argv[2], atol(argv[3]), atoi(argv[4]), argc == 6 ? atoi(argv[5]) : 9);
    if (strcmp(argv[1], "--cost") == 0 && argc == 5)
        return cost_run(argv[2], atol(argv[3]), atol(argv[4]));
    if (strcmp(argv[1], "--biaxial") == 0 && (argc == 4 || argc == 5))
        return biaxial_one(argv[2], argv[3], argc == 5 ? argv[4] : NULL);
    if (strcmp(argv[1], "--workload") == 0 && (argc == 5 || argc == 6))
        return workload_bench(argv[2], argv[3], argv[4], argc == 6 ? atoi(argv[5]) : REPEATS);
    if (strcmp(argv[1], "--modules-summary") == 0 && argc == 7)
        return modules_summary(argv + 2);
    if (strcmp(argv[1], "--settling") == 0 && argc >= 3) {
        /* The same packing timed while it falls from the lattice (settle
         * stage cut to one cycle): flow, frequent rebuilds and re-sorts. */
        const long n = argc > 3 ? atol(argv[3]) : 20000;
        struct options o = {"stage.settle.cycles=1", NULL, 1, TARGET_SECONDS, 0, 0};
        return run_one(argv[2], n, NULL, &o);
    }
    long sizes[16] = {5000, 20000, 80000};
    int n_sizes = 3;
    if (argc > 2) {
        n_sizes = 0;
        for (int k = 2; k < argc && n_sizes < 16; k++)
            sizes[n_sizes++] = atol(argv[k]);
    }
    FILE *csv = open_csv();
    int rc = 0;
    for (int k = 0; k < n_sizes && rc == 0; k++)
        rc = run_one(argv[1], sizes[k], csv, &(struct options){NULL, NULL, 0, TARGET_SECONDS, 0, 0});
    if (csv)
        fclose(csv);
    return rc;
}
