/*
 * main.c — the `ballast` command: the only place that parses the command
 * line, touches signals and maps a status to an exit code.
 *
 *   ballast run SCENE --out DIR [--set KEY=VALUE ...] [--threads N] [--vtk]
 *   ballast exact SCENE --out DIR [--set KEY=VALUE ...]
 *   ballast info SCENE [--set KEY=VALUE ...]
 *   ballast inputs SCENE [--set KEY=VALUE ...]
 *   ballast keys          (every scene key, as Markdown tables)
 *   ballast --version
 *
 * Exit codes: 0 success; 1 the run failed (unstable); 2 bad input or usage;
 * 3 input/output error; 4 out of memory; 130 interrupted.
 * A scene that fails to load or validate writes nothing.  A run that
 * starts writes run.json saying how it ended; discs.tsv, contacts.tsv and
 * walls.tsv appear only when the run completed, series.tsv too or when it
 * was interrupted (the rows so far; run.json says "complete": false).  The
 * snapshots folder (settings.snapshot_every or snapshot_dt) goes with
 * series.tsv: complete when the run completed, the frames so far when it was
 * interrupted, removed when it failed otherwise.
 * `run` ends with a one-line summary on stdout, and on a terminal shows
 * its progress on stderr once it has run for PROGRESS_AFTER seconds.
 */
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "ballast.h"
#include "exact.h"
#include "scene_keys.h"

static volatile sig_atomic_t stop_requested;

#define PROGRESS_AFTER 3.0 /* seconds of a run before its progress line appears */

/* The progress line on a terminal: redrawn in place (\r), the stage, its
 * cycles, the simulated time and the run's share done with the time left. */
static void show_progress(const struct bal_progress *p, void *ctx)
{
    int *shown = ctx;
    const double share = p->steps > 0 ? (double)p->step / (double)p->steps : 0;
    char left[48] = "";
    if (share > 0 && share < 1)
        snprintf(left, sizeof left, ", %.0f s left", p->wall_seconds * (1 - share) / share);
    fprintf(stderr, "\r\033[Kballast: stage %s (%d/%d) cycle %ld/%ld, t = %.6g s, %.0f %% of "
                    "%ld cycles%s", p->stage_name, p->stage + 1, p->n_stages, p->stage_cycle + 1,
            p->stage_cycles, p->time, 100 * share, p->steps, left);
    fflush(stderr);
    *shown = 1;
}

static void on_signal(int sig)
{
    (void)sig;
    stop_requested = 1;
}

static int exit_code(enum bal_status st)
{
    switch (st) {
    case BAL_OK: return 0;
    case BAL_EUNSTABLE: return 1;
    case BAL_EINVAL: return 2;
    case BAL_EIO: return 3;
    case BAL_ENOMEM: return 4;
    case BAL_EINTR: return 130;
    }
    return 1;
}

static int usage(void)
{
    fputs("usage: ballast run SCENE --out DIR [--set KEY=VALUE ...] [--threads N] [--vtk]\n"
          "       ballast exact SCENE --out DIR [--set KEY=VALUE ...]\n"
          "       ballast info SCENE [--set KEY=VALUE ...]\n"
          "       ballast inputs SCENE [--set KEY=VALUE ...]\n"
          "       ballast keys\n"
          "       ballast --version\n",
          stderr);
    return 2;
}

/* mkdir -p */
static int make_dirs(const char *path)
{
    char buf[1024];
    if (strlen(path) >= sizeof buf)
        return -1;
    strcpy(buf, path);
    for (char *p = buf + 1; *p; p++) {
        if (*p == '/') {
            *p = '\0';
            if (mkdir(buf, 0777) != 0 && errno != EEXIST)
                return -1;
            *p = '/';
        }
    }
    if (mkdir(buf, 0777) != 0 && errno != EEXIST)
        return -1;
    return 0;
}

struct args {
    const char *cmd, *scene, *out;
    int n_sets;
    char **sets;
    int threads; /* --threads N, checked; 0: not given */
    int vtk;     /* --vtk: settings.vtk = 1 */
};

static int parse_args(int argc, char **argv, struct args *a)
{
    memset(a, 0, sizeof *a);
    if (argc < 2)
        return 0;
    a->cmd = argv[1];
    a->sets = calloc((size_t)argc, sizeof *a->sets);
    if (!a->sets)
        return 0;
    for (int k = 2; k < argc; k++) {
        if (strcmp(argv[k], "--out") == 0 && k + 1 < argc)
            a->out = argv[++k];
        else if (strcmp(argv[k], "--set") == 0 && k + 1 < argc)
            a->sets[a->n_sets++] = argv[++k];
        else if (strcmp(argv[k], "--threads") == 0 && k + 1 < argc) {
            const char *v = argv[++k];
            char *end;
            const long t = strtol(v, &end, 10);
            if (*end || end == v || t < 1 || t > BAL_MAX_THREADS) {
                fprintf(stderr, "ballast: --threads %s: not a whole number from 1 to %d\n", v,
                        BAL_MAX_THREADS);
                return 0;
            }
            a->threads = (int)t;
        }
        else if (strcmp(argv[k], "--vtk") == 0)
            a->vtk = 1;
        else if (argv[k][0] != '-' && !a->scene)
            a->scene = argv[k];
        else {
            fprintf(stderr, "ballast: unexpected argument '%s'\n", argv[k]);
            return 0;
        }
    }
    return 1;
}

static enum bal_status load(struct bal_scene *sc, const struct args *a, struct bal_error *err)
{
    bal_scene_default(sc);
    if (bal_scene_load(sc, a->scene, err))
        return err->code;
    for (int k = 0; k < a->n_sets; k++)
        if (bal_scene_set(sc, a->sets[k], err))
            return err->code;
    /* --vtk: the snapshots as VTK files too, which needs snapshots. */
    if (a->vtk && sc->settings.snapshot_every == 0 && sc->settings.snapshot_dt == 0)
        return bal_error(err, BAL_EINVAL,
                         "%s: --vtk needs snapshots: give settings.snapshot_every (cycles) or "
                         "snapshot_dt (simulated time), in the scene or by --set", sc->path);
    if (a->vtk)
        sc->settings.vtk = 1;
    return bal_scene_validate(sc, err);
}

static int cmd_info(const struct args *a)
{
    struct bal_scene sc;
    struct bal_error err = {0};
    struct bal_sim *sim = NULL;
    if (load(&sc, a, &err) || bal_sim_create(&sim, &sc, &err)) {
        fprintf(stderr, "%s\n", err.msg);
        bal_scene_free(&sc);
        return exit_code(err.code);
    }
    struct bal_run_info in;
    bal_sim_info(sim, &in);
    long cycles = 0;
    for (int g = 0; g < sc.n_stages; g++)
        cycles += bal_sim_stage_cycles(sim, g);
    printf("scene          %s\n", sc.path);
    printf("discs          %d\n", in.n_discs);
    printf("walls          %d\n", in.n_walls);
    printf("materials      %d\n", sc.n_materials);
    printf("normal law     %s\n", sc.settings.normal_law == BAL_NORMAL_POWER ? "power" : "incremental");
    printf("neighbours     %s (%ld candidate pairs)\n", in.grid_used ? "cell grid" : "all pairs",
           in.n_candidates);
    struct bal_dt_detail dd;
    bal_sim_dt_detail(sim, &dd);
    printf("dt estimate    %.17g   (contact-network bound 2/(omega (sqrt(1+zeta^2)+zeta)), %s %d)\n",
           in.dt_estimate, dd.spectral ? "spectral bound; disc" : "block bound; disc", dd.binding_disc);
    printf("dt single      %.17g   (min over discs of 2 sqrt(m/k), C&S p. 53; ratio %.4g)\n",
           dd.single_spring, dd.single_spring / in.dt_estimate);
    printf("dt contacts    %ld at the start; %d free discs bounded by coordination; omega %.6g, zeta %.4g\n",
           dd.contacts, dd.coordination_discs, dd.omega, dd.zeta);
    printf("dt fraction    %.17g\n", in.dt_fraction);
    printf("dt used        %.17g\n", in.dt);
    /* The cycles between series rows: a trial at another dt keeps the rows'
     * simulated times by scaling them (harness/stability.py). */
    printf("output every   %ld cycles\n", sc.settings.output_every);
    printf("stages         %d (%ld cycles)\n", sc.n_stages, cycles);
    /* One line per stage, its cycles and the simulated time they cover at
     * this dt (a sweep over dt keeps the time: harness/sweep_grid.py). */
    for (int g = 0; g < sc.n_stages; g++)
        printf("stage          %s %ld cycles %.17g s (%s)\n", sc.stages[g].name,
               bal_sim_stage_cycles(sim, g), (double)bal_sim_stage_cycles(sim, g) * in.dt,
               bal_sim_stage_in_time(sim, g) ? "time" : "cycles");
    /* The keys given that other keys make unused (a sweep over one is refused). */
    bal_scene_print_unused(&sc, stdout);
    bal_sim_free(sim);
    bal_scene_free(&sc);
    return 0;
}

/* The path a run opens for the value of a file key (BAL_KEY_FILE): the rule
 * of scene.c's BAL_KEY_FILE case, relative to the directory of the scene's
 * path (sc->path, which --set lines resolve against too), an absolute value
 * as written.  harness/tests/test_hardening_inputs.py checks that each path
 * printed here is the one the core opens (its error names it). */
static void input_path(const struct bal_scene *sc, const char *value, char *out, size_t size)
{
    const char *slash = strrchr(sc->path, '/');
    if (value[0] == '/' || !slash)
        snprintf(out, size, "%s", value);
    else
        snprintf(out, size, "%.*s/%s", (int)(slash - sc->path), sc->path, value);
}

/* Every file a run of the scene (with its --set lines) reads, one per line,
 * as the run opens it: the scene, then the file of every file key of every
 * [import], each once.  The harness hashes them into a run's identity
 * (harness/runner.py), so a resumed or gathered run is stale once a file it
 * read has changed.  Bad input: the message and exit code of `info`; a path
 * that one line cannot hold is refused (exit 2) before anything is printed. */
static int cmd_inputs(const struct args *a)
{
    struct bal_scene sc;
    struct bal_error err = {0};
    if (load(&sc, a, &err)) {
        fprintf(stderr, "%s\n", err.msg);
        bal_scene_free(&sc);
        return exit_code(err.code);
    }
    int n_keys = 0;
    for (size_t k = 0; k < bal_scene_n_keys; k++) {
        if (bal_scene_keys[k].type != BAL_KEY_FILE)
            continue;
        if (bal_scene_keys[k].section != BAL_SEC_IMPORT) {
            /* a file key of another section: this command must learn to list it */
            fprintf(stderr, "ballast inputs: the file key '%s' of [%s] is not listed (core/main.c)\n",
                    bal_scene_keys[k].name, bal_scene_sections[bal_scene_keys[k].section].name);
            bal_scene_free(&sc);
            return 1;
        }
        n_keys++;
    }
    const int most = 1 + sc.n_imports * n_keys;
    char(*paths)[2 * BAL_PATH_MAX + 1] = calloc((size_t)most, sizeof *paths);
    if (!paths) {
        fprintf(stderr, "ballast inputs: out of memory\n");
        bal_scene_free(&sc);
        return 4;
    }
    int n = 0;
    snprintf(paths[n++], sizeof *paths, "%s", a->scene);
    for (int i = 0; i < sc.n_imports; i++)
        for (size_t k = 0; k < bal_scene_n_keys; k++) {
            const struct bal_key *key = &bal_scene_keys[k];
            const char *value = (const char *)&sc.imports[i] + key->offset;
            if (key->type == BAL_KEY_FILE && *value) /* "": not given, no file */
                input_path(&sc, value, paths[n++], sizeof *paths);
        }
    int rc = 0;
    for (int k = 0; k < n && rc == 0; k++)
        if (strchr(paths[k], '\n')) {
            fprintf(stderr, "ballast inputs: %s: a path with a line break cannot be listed one per "
                            "line\n", paths[k]);
            rc = 2;
        }
    for (int k = 0; k < n && rc == 0; k++) {
        int seen = 0;
        for (int j = 0; j < k; j++)
            seen |= strcmp(paths[j], paths[k]) == 0;
        if (!seen)
            printf("%s\n", paths[k]);
    }
    if (rc == 0 && fflush(stdout) != 0) {
        fprintf(stderr, "ballast inputs: cannot write: %s\n", strerror(errno));
        rc = 3;
    }
    free(paths);
    bal_scene_free(&sc);
    return rc;
}

/* Remove an earlier run's outputs from dir (with_json: run.json too, and
 * first: a run killed while this runs must not leave an old run.json saying
 * ok beside a missing series), or, after a failed run, the outputs it had
 * finished, so that only run.json, saying why, remains (and series.tsv with
 * the snapshots folder when keep_series). */
static void remove_outputs(const char *dir, int with_json, int keep_series)
{
    if (!keep_series)
        bal_output_remove_snapshots(dir);
    const char *names[] = {"run.json", "series.tsv", "discs.tsv", "contacts.tsv", "walls.tsv",
                           "stress.tsv", "stress_grid.tsv"};
    for (size_t k = with_json ? 0 : 1; k < sizeof names / sizeof names[0]; k++) {
        if (k == 1 && keep_series)
            continue;
        char p[1200];
        snprintf(p, sizeof p, "%s/%s", dir, names[k]);
        remove(p);
        snprintf(p, sizeof p, "%s/%s.tmp", dir, names[k]);
        remove(p);
    }
}

/* What `run` and `exact` share: the scene loaded and validated, the
 * simulation created, the output folder made and emptied of an earlier
 * run's results (so nothing stale is read as new).  Returns -1 when ready,
 * else the exit code, having said why and freed what it made. */
static int prepare(const struct args *a, const char *cmd, struct bal_scene *sc,
                   struct bal_sim **sim)
{
    struct bal_error err = {0};
    *sim = NULL;
    if (!a->out) {
        fprintf(stderr, "ballast %s: --out DIR is required\n", cmd);
        return 2;
    }
    struct stat out_st;
    if (stat(a->out, &out_st) == 0 && !S_ISDIR(out_st.st_mode)) {
        fprintf(stderr, "ballast %s: --out %s is not a directory\n", cmd, a->out);
        return 2;
    }
    if (load(sc, a, &err) || bal_sim_create(sim, sc, &err) ||
        (a->threads && bal_sim_set_threads(*sim, a->threads, &err))) {
        fprintf(stderr, "%s\n", err.msg);
        bal_sim_free(*sim);
        *sim = NULL;
        bal_scene_free(sc);
        return exit_code(err.code);
    }
    if (make_dirs(a->out) != 0) {
        fprintf(stderr, "ballast: %s: cannot create directory: %s\n", a->out, strerror(errno));
        bal_sim_free(*sim);
        bal_scene_free(sc);
        return 3;
    }
    remove_outputs(a->out, 1, 0);
    return -1;
}

/* The one line a run ends with: how it ended, its cycles, the simulated
 * and the wall-clock time, and the energy imbalance (run.json has more). */
static void summary(const struct bal_sim *sim, enum bal_status st, int kept)
{
    struct bal_run_info in;
    struct bal_energy en;
    bal_sim_info(sim, &in);
    bal_energy_report(sim, &en);
    printf("ballast run: %s%s, %ld cycles, %.6g s simulated (dt %.6g), wall %.3g s, "
           "energy imbalance %.3g of the energy through the run\n",
           st == BAL_OK ? "ok" : bal_strerror(st), kept ? " (series.tsv so far kept)" : "",
           in.steps, in.time, in.dt, in.wall_seconds, en.relative);
    fflush(stdout);
}

static int cmd_run(const struct args *a)
{
    struct bal_scene sc;
    struct bal_error err = {0};
    struct bal_sim *sim = NULL;
    const int early = prepare(a, "run", &sc, &sim);
    if (early >= 0)
        return early;

    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);

    int shown = 0;
    if (isatty(STDERR_FILENO))
        bal_sim_set_progress(sim, show_progress, &shown, PROGRESS_AFTER);

    char tmp[1200];
    snprintf(tmp, sizeof tmp, "%s/series.tsv.tmp", a->out);
    FILE *series = fopen(tmp, "w");
    enum bal_status st;
    int kept = 0; /* an interrupted run's series, the rows so far */
    if (!series) {
        st = bal_error(&err, BAL_EIO, "%s: cannot write: %s", tmp, strerror(errno));
    } else if ((st = bal_sim_set_snapshots(sim, a->out, &err)) != BAL_OK) {
        fclose(series);
    } else {
        bal_output_series_header(sim, series);
        st = bal_sim_run(sim, series, &stop_requested, &err);
        int bad = ferror(series);
        bad |= fclose(series) != 0;
        if (st == BAL_OK && bad)
            st = bal_error(&err, BAL_EIO, "%s: write failed", tmp);
        struct bal_error cerr = {0};
        if (st == BAL_EINTR && !bad && bal_output_commit(a->out, "series.tsv", &cerr) == BAL_OK)
            kept = 1;
        if (st == BAL_OK)
            st = bal_output_commit(a->out, "series.tsv", &err);
        if (st == BAL_OK)
            st = bal_output_state(sim, a->out, &err);
    }
    if (shown)
        fputs("\n", stderr);
    if (st != BAL_OK)
        remove_outputs(a->out, 0, kept);
    struct bal_error jerr = {0};
    enum bal_status js = bal_output_run_json(sim, a->out, sc.path, a->n_sets, a->sets, st,
                                             st == BAL_OK ? "" : err.msg, &jerr);
    if (st != BAL_OK)
        fprintf(stderr, "%s\n", err.msg);
    if (js != BAL_OK)
        fprintf(stderr, "%s\n", jerr.msg);
    summary(sim, st, kept);
    bal_sim_free(sim);
    bal_scene_free(&sc);
    return exit_code(st != BAL_OK ? st : js);
}

/* The exact static solution of the scene's initial positions (MLH Sec. 4.2):
 * contacts.tsv with the stiff-limit forces (and an `open` column), discs.tsv,
 * a one-row series.tsv (iterations, open contacts, weight, support, residual)
 * and run.json (with the solve's wall-clock time), all via temporary names. */
static enum bal_status write_exact(const struct bal_sim *sim, const struct bal_exact *ex,
                                   const char *dir, struct bal_error *err)
{
    /* discs.tsv and walls.tsv of the initial state; its contacts.tsv (no DEM
     * forces yet) and stress.tsv (zeros) are replaced or removed below. */
    if (bal_output_state(sim, dir, err))
        return err->code;
    char path[1200];
    snprintf(path, sizeof path, "%s/stress.tsv", dir);
    remove(path);
    snprintf(path, sizeof path, "%s/contacts.tsv.tmp", dir);
    FILE *f = fopen(path, "w");
    if (!f)
        return bal_error(err, BAL_EIO, "%s: cannot write: %s", path, strerror(errno));
    fputs("a\tb\tkind\tx\ty\tnx\tny\tfn\tfs\tdn\tds\tsliding\topen\n", f);
    char a[2 * BAL_NAME_MAX], b[2 * BAL_NAME_MAX];
    for (long c = 0; c < ex->n_contacts; c++) {
        const struct bal_exact_contact *k = &ex->contacts[c];
        bal_output_disc_name(sim, bal_sim_disc_id(sim, k->i), a, sizeof a);
        if (k->is_wall)
            snprintf(b, sizeof b, "%s", bal_sim_wall_name(sim, k->j));
        else
            bal_output_disc_name(sim, bal_sim_disc_id(sim, k->j), b, sizeof b);
        double px, py;
        bal_sim_contact_point(sim, k->i, k->is_wall, k->j, &px, &py);
        fprintf(f, "%s\t%s\t%s\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t0\t0\t0\t0\t%d\n", a, b,
                k->is_wall ? "wall" : "disc", px, py, k->nx, k->ny, k->fn, k->open);
    }
    int bad = ferror(f);
    bad |= fclose(f) != 0;
    if (bad)
        return bal_error(err, BAL_EIO, "%s: write failed", path);
    if (bal_output_commit(dir, "contacts.tsv", err))
        return err->code;
    snprintf(path, sizeof path, "%s/series.tsv.tmp", dir);
    f = fopen(path, "w");
    if (!f)
        return bal_error(err, BAL_EIO, "%s: cannot write: %s", path, strerror(errno));
    /* The solve's wall-clock time goes to run.json (wall_seconds), not here:
     * the same scene must give the same bytes. */
    fprintf(f, "cycle\ttime\titerations\tn_open\tn_contacts\tweight_x\tweight_y\t"
               "support_x\tsupport_y\tresidual\tbandwidth\n");
    fprintf(f, "0\t0\t%d\t%ld\t%ld\t%.17g\t%.17g\t%.17g\t%.17g\t%.17g\t%d\n", ex->iterations,
            ex->n_open, ex->n_contacts, ex->weight[0], ex->weight[1], ex->support[0],
            ex->support[1], ex->residual, ex->bandwidth);
    bad = ferror(f);
    bad |= fclose(f) != 0;
    if (bad)
        return bal_error(err, BAL_EIO, "%s: write failed", path);
    return bal_output_commit(dir, "series.tsv", err);
}

static int cmd_exact(const struct args *a)
{
    struct bal_scene sc;
    struct bal_error err = {0};
    struct bal_sim *sim = NULL;
    const int early = prepare(a, "exact", &sc, &sim);
    if (early >= 0)
        return early;
    struct bal_exact ex = {0};
    enum bal_status st = bal_exact_solve(sim, &ex, &err);
    if (st == BAL_OK)
        st = write_exact(sim, &ex, a->out, &err);
    if (st != BAL_OK)
        remove_outputs(a->out, 0, 0);
    bal_sim_add_seconds(sim, ex.seconds);
    struct bal_error jerr = {0};
    enum bal_status js = bal_output_run_json(sim, a->out, sc.path, a->n_sets, a->sets, st,
                                             st == BAL_OK ? "" : err.msg, &jerr);
    if (st != BAL_OK)
        fprintf(stderr, "%s\n", err.msg);
    if (js != BAL_OK)
        fprintf(stderr, "%s\n", jerr.msg);
    bal_exact_free(&ex);
    bal_sim_free(sim);
    bal_scene_free(&sc);
    return exit_code(st != BAL_OK ? st : js);
}

int main(int argc, char **argv)
{
    if (argc == 2 && strcmp(argv[1], "--version") == 0) {
        printf("ballast %s\n", BAL_VERSION);
        return 0;
    }
    if (argc == 2 && strcmp(argv[1], "keys") == 0) {
        bal_scene_print_keys(stdout);
        return 0;
    }
    struct args a;
    int ok = parse_args(argc, argv, &a);
    int rc;
    if (!ok || !a.scene)
        rc = usage();
    else if (strcmp(a.cmd, "run") == 0)
        rc = cmd_run(&a);
    else if (strcmp(a.cmd, "exact") == 0)
        rc = cmd_exact(&a);
    else if (strcmp(a.cmd, "info") == 0)
        rc = cmd_info(&a);
    else if (strcmp(a.cmd, "inputs") == 0)
        rc = cmd_inputs(&a);
    else
        rc = usage();
    free(a.sets);
    return rc;
}
