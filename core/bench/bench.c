/*
 * bench.c — the dense-packing benchmark behind `make bench`.
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
 *        bench --pile PILE_SCENE  (the L0 = 100 pile relaxed, 5 whole runs)
 *        bench --modules SCENE [N]       (what each optional module costs, one
 *                                         simulation per configuration from
 *                                         the same settled packing)
 *        bench --modules-base SCENE [N]  (only the configuration with every
 *                                         module off: run by bench-bare, the
 *                                         build without them, to compare)
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
#include "sim.h"

#define REPEATS 5
#define TARGET_SECONDS 2.0
/* The packing counts as settled when E_k < 1e-3 E_el: the discs then move
 * by far less than the skin between rebuilds, as in a static packing. */
#define SETTLED_EK_OVER_EE 1e-3
#define MAX_SETTLE_BLOCKS 4

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
        if (bal_sim_cycle(sim, err))
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
    snprintf(set, sizeof set, "fill.pack.columns=%ld", lround(sqrt(2.0 * (double)n)));
    ok = ok && bal_scene_set(sc, set, err) == BAL_OK;
    for (int k = 0; k < max; k++)
        if (sets[k])
            ok = ok && bal_scene_set(sc, sets[k], err) == BAL_OK;
    ok = ok && bal_sim_create(sim, sc, err) == BAL_OK;
    return ok ? 0 : 1;
}

static int run_one(const char *path, long n, FILE *csv, struct options *o)
{
    struct bal_scene sc;
    struct bal_error err = {0};
    struct bal_sim *sim = NULL;
    const char *const sets[] = {o->extra, o->extra2};
    if (load_scene(path, n, sets, 2, &sc, &sim, &err)) {
        fprintf(stderr, "bench: %s\n", err.msg);
        bal_scene_free(&sc);
        return 1;
    }

    /* Settle: every stage but the last, untimed. */
    for (int g = 0; g + 1 < sc.n_stages; g++) {
        bal_sim_set_stage(sim, g);
        for (long c = 0; c < sc.stages[g].cycles; c++)
            if (bal_sim_cycle(sim, &err)) {
                fprintf(stderr, "bench: settling: %s\n", err.msg);
                bal_sim_free(sim);
                bal_scene_free(&sc);
                return 1;
            }
    }
    /* Settled means the kinetic energy is a small share of the elastic
     * energy; a tall packing takes longer to get there, so settle on in
     * blocks of the first stage's length until it is (or give up and say
     * so in the output). */
    long extra = 0;
    while (!o->flowing && bal_measure_kinetic(sim) > SETTLED_EK_OVER_EE * bal_measure_elastic(sim) &&
           extra < MAX_SETTLE_BLOCKS * sc.stages[0].cycles) {
        for (long c = 0; c < sc.stages[0].cycles; c++, extra++)
            if (bal_sim_cycle(sim, &err)) {
                fprintf(stderr, "bench: settling: %s\n", err.msg);
                bal_sim_free(sim);
                bal_scene_free(&sc);
                return 1;
            }
    }
    const double ek_ee = bal_measure_kinetic(sim) / bal_measure_elastic(sim);
    bal_sim_set_stage(sim, sc.n_stages - 1);
    /* The timers printed below cover the timed cycles only. */
    const long rebuilds0 = sim->rebuilds, reorders0 = sim->reorders;
    memset(&sim->timers, 0, sizeof sim->timers);

    /* Calibrate the step count, then time the repeats. */
    long steps = 50;
    double t = timed_steps(sim, steps, &err);
    if (t > 0)
        steps = (long)fmax(100, o->seconds / (t / (double)steps));
    double rate[REPEATS];
    for (int k = 0; k < REPEATS; k++) {
        t = timed_steps(sim, steps, &err);
        if (t < 0) {
            fprintf(stderr, "bench: %s\n", err.msg);
            bal_sim_free(sim);
            bal_scene_free(&sc);
            return 1;
        }
        rate[k] = (double)steps * (double)sim->n / t;
    }
    qsort(rate, REPEATS, sizeof rate[0], cmp_double);

    long touching = 0;
    for (long c = 0; c < sim->pp.n; c++)
        touching += 2 * ((sim->pp.flags[c] & BAL_PAIR_TOUCHING) != 0);
    for (long c = 0; c < sim->pw.n; c++)
        touching += (sim->pw.flags[c] & BAL_PAIR_TOUCHING) != 0;
    const double z = (double)touching / (double)sim->n;
    o->median = rate[REPEATS / 2];
    if (!o->quiet)
        printf("# N=%d settled for %ld cycles: E_k/E_el = %.2g, %ld rebuilds so far\n", sim->n,
               sc.stages[0].cycles + extra, ek_ee, sim->rebuilds);
    if (!o->quiet)
        printf("bench %s N=%d steps=%ld particle_steps_per_s=%.4g min=%.4g max=%.4g "
           "contacts_per_disc=%.3f\n",
           o->flowing ? "settling" : "dense", sim->n, steps, rate[REPEATS / 2], rate[0],
           rate[REPEATS - 1], z);
    fflush(stdout);
    if (csv)
        fprintf(csv, "%ld,%d,%ld,%.6g,%.6g,%.6g,%.4f,%ld\n", (long)time(NULL), sim->n, steps,
                rate[REPEATS / 2], rate[0], rate[REPEATS - 1], z, sim->rebuilds);
    if (!o->quiet) {
        struct rusage ru;
        getrusage(RUSAGE_SELF, &ru);
        long contacts = 0;
        for (long c = 0; c < sim->pp.n; c++)
            contacts += (sim->pp.flags[c] & BAL_PAIR_TOUCHING) != 0;
        const double rss = 1024.0 * (double)ru.ru_maxrss;
        double disc_bytes, pair_bytes;
        bal_sim_memory(sim, &disc_bytes, &pair_bytes);
        printf("# N=%d memory: held while stepping %.0f bytes/disc (%.0f per disc + %.0f for its "
               "pairs, %.1f bytes per contact); peak RSS %.1f MB = %.0f bytes/disc\n",
               sim->n, (disc_bytes + pair_bytes) / sim->n, disc_bytes / sim->n,
               pair_bytes / sim->n, pair_bytes / (double)(contacts > 0 ? contacts : 1), rss / 1e6,
               rss / sim->n);
        printf("# N=%d %ld candidate pairs (%.2f per disc), %ld contacts; timed cycles: "
               "positions %.2f neighbours %.2f contacts %.2f walls %.2f velocities %.2f s, "
               "%ld rebuilds, %ld re-sorts\n",
               sim->n, sim->pp.n, (double)sim->pp.n / sim->n, contacts, sim->timers.positions,
               sim->timers.neighbours, sim->timers.contacts, sim->timers.walls,
               sim->timers.velocities, sim->rebuilds - rebuilds0, sim->reorders - reorders0);
    }
    bal_sim_free(sim);
    bal_scene_free(&sc);
    return 0;
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
    {"all on", {NULL, NULL, NULL, NULL}},
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

static int modules_bench(const char *path, long n, int base_only)
{
    struct bal_scene ref_sc;
    struct bal_sim *ref = NULL;
    struct bal_error err = {0};
    /* The reference packing: frictionless and without dashpots, settled by
     * global damping alone, so that the bare build (which has only that
     * pair loop) settles exactly the same packing. */
    static const struct module_config settled = {
        "settled", {"material.grain.friction=0", "material.box.friction=0", "settings.beta=0", NULL}};
    if (load_config(path, n, &settled, 0, &ref_sc, &ref, &err)) {
        fprintf(stderr, "bench: %s\n", err.msg);
        bal_scene_free(&ref_sc);
        return 1;
    }
    long settle = 0;
    for (int g = 0; g + 1 < ref_sc.n_stages; g++) {
        bal_sim_set_stage(ref, g);
        for (long c = 0; c < ref_sc.stages[g].cycles; c++, settle++)
            if (bal_sim_cycle(ref, &err)) {
                fprintf(stderr, "bench: settling: %s\n", err.msg);
                return 1;
            }
    }
    while (bal_measure_kinetic(ref) > SETTLED_EK_OVER_EE * bal_measure_elastic(ref) &&
           settle < (MAX_SETTLE_BLOCKS + 1) * ref_sc.stages[0].cycles)
        for (long c = 0; c < ref_sc.stages[0].cycles; c++, settle++)
            if (bal_sim_cycle(ref, &err)) {
                fprintf(stderr, "bench: settling: %s\n", err.msg);
                return 1;
            }
    printf("# module costs: N=%d packing settled for %ld cycles (frictionless, global damping) "
           "(E_k/E_el = %.2g); each configuration starts from it at rest\n",
           ref->n, settle, bal_measure_kinetic(ref) / bal_measure_elastic(ref));
    const size_t n_cfg = base_only ? 1 : sizeof module_configs / sizeof module_configs[0];
    for (size_t k = 0; k < n_cfg; k++) {
        if (getenv("BAL_BENCH_ONLY") && (int)k != atoi(getenv("BAL_BENCH_ONLY")))
            continue; /* one configuration (its index), to repeat it */
        const struct module_config *c = &module_configs[k];
        struct bal_scene sc;
        struct bal_sim *sim = NULL;
        if (load_config(path, n, c, k == 4, &sc, &sim, &err) || sim->n != ref->n) {
            fprintf(stderr, "bench: %s\n", err.msg);
            bal_sim_free(sim);
            bal_scene_free(&sc);
            return 1;
        }
        for (int i = 0; i < ref->n; i++) {
            const int to = sim->slot[ref->id[i]];
            sim->x[to] = ref->x[i];
            sim->y[to] = ref->y[i];
            sim->th[to] = ref->th[i];
            sim->vx[to] = sim->vy[to] = sim->w[to] = 0;
        }
        sim->need_rebuild = 1;
        sim->dt = ref->dt * 1e-4;
        bal_sim_set_stage(sim, sc.n_stages - 1);
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
            return 1;
        }
        qsort(rate, REPEATS, sizeof rate[0], cmp_double);
        long contacts = 0;
        for (long q = 0; q < sim->pp.n; q++)
            contacts += (sim->pp.flags[q] & BAL_PAIR_TOUCHING) != 0;
        printf("bench module build=%s config=\"%s\" N=%d particle_steps_per_s=%.4g min=%.4g "
               "max=%.4g contacts=%ld rebuilds=%ld\n",
#ifdef BAL_BARE
               "bare",
#else
               "full",
#endif
               c->name, sim->n, rate[REPEATS / 2], rate[0], rate[REPEATS - 1], contacts,
               sim->rebuilds);
        fflush(stdout);
        bal_sim_free(sim);
        bal_scene_free(&sc);
    }
    bal_sim_free(ref);
    bal_scene_free(&ref_sc);
    return 0;
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
