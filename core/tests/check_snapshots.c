/*
 * check_snapshots.c — suite "snapshots": the keys snapshot_every,
 * snapshot_dt and vtk (what is refused, with file, line and key), the
 * frames' schedule (frame 0 at cycle 0, every N cycles or every T of
 * simulated time, the final state once), the files of a frame (every one
 * renamed into place, none left under .tmp; index.tsv lists a frame only
 * once its files are in place), the rows against the final outputs, and
 * the disc forces against a closed form.
 *
 * The expected cycles and stages are worked out by hand in each test from
 * the schedule's rule (snapshots.c): never read from the code's output.
 */
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check_main.h"
#include "snapshots.h"

/* The folder a test writes into, made by the checked setup and emptied by
 * its teardown (also after a failed assertion). */
static char out_dir[64];

static void remove_tree(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return;
    char path[600];
    for (struct dirent *e = readdir(d); e; e = readdir(d)) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        struct stat st;
        if (lstat(path, &st) == 0 && S_ISDIR(st.st_mode))
            remove_tree(path);
        else
            remove(path);
    }
    closedir(d);
    rmdir(dir);
}

static void out_setup(void)
{
    snprintf(out_dir, sizeof out_dir, "/tmp/ballast-check-snapXXXXXX");
    ck_assert_msg(mkdtemp(out_dir) != NULL, "cannot make a temporary folder");
}

static void out_teardown(void)
{
    remove_tree(out_dir);
}

/* The whole text of out_dir/rel (NULL when it cannot be read); free it. */
static char *read_text(const char *rel)
{
    char path[600];
    snprintf(path, sizeof path, "%s/%s", out_dir, rel);
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    const long n = ftell(f);
    rewind(f);
    char *buf = malloc((size_t)n + 1);
    const size_t got = buf ? fread(buf, 1, (size_t)n, f) : 0;
    fclose(f);
    if (buf)
        buf[got] = '\0';
    return buf;
}

static int exists(const char *rel)
{
    char path[600];
    snprintf(path, sizeof path, "%s/%s", out_dir, rel);
    struct stat st;
    return stat(path, &st) == 0;
}

/* One disc at rest, no contact: stages `one` and `two` of c1 and c2 cycles, dt = 0.1,
 * with the settings lines `snap`. */
static struct tfx *lone_disc(const char *snap, long c1, long c2)
{
    return tfx_newf("lone",
                    "[settings]\ndt = 0.1\n%s"
                    "[material m]\nkn = 1e3\ndensity = 1\n"
                    "[disc a]\nx = 0 0\nr = 1\nmaterial = m\n"
                    "[stage one]\ncycles = %ld\n[stage two]\ncycles = %ld\n",
                    snap, c1, c2);
}

/* index.tsv as the schedule says it must read: the frames at `cycles` (n of
 * them), the first `in_one` in stage one, the time of each the sum of dt over
 * its cycles (s->time += dt, cycle by cycle). */
static void expected_index(char *buf, size_t size, const long *cycles, int n, int in_one)
{
    int at = snprintf(buf, size, "frame\tcycle\ttime\tstage\n");
    double t = 0;
    long c = 0;
    for (int k = 0; k < n; k++) {
        for (; c < cycles[k]; c++)
            t += 0.1;
        at += snprintf(buf + at, size - (size_t)at, "%d\t%ld\t%.17g\t%s\n", k, cycles[k], t,
                       k < in_one ? "one" : "two");
    }
}

static void run_with_snapshots(struct tfx *f)
{
    ck_assert_int_eq(bal_sim_set_snapshots(f->sim, out_dir, &f->err), BAL_OK);
    const enum bal_status st = bal_sim_run(f->sim, NULL, NULL, &f->err);
    ck_assert_msg(st == BAL_OK, "run: %s", f->err.msg);
}

static void check_index(const long *cycles, int n, int in_one)
{
    char want[2048];
    expected_index(want, sizeof want, cycles, n, in_one);
    char *got = read_text("snapshots/index.tsv");
    ck_assert_msg(got != NULL, "no snapshots/index.tsv");
    ck_assert_msg(strcmp(got, want) == 0, "index.tsv:\n%s\nexpected:\n%s", got, want);
    free(got);
}

/* ------------------------------------------------------------------ */
/* The schedule                                                        */
/* ------------------------------------------------------------------ */

/* Every 5 cycles of 7 + 5: frame 0 at cycle 0 (stage one, the first), 5 (one),
 * 10 (two), and the final state at 12, not a multiple of 5, as the last frame. */
START_TEST(snapshots_every_n_cycles_and_the_final_state)
{
    struct tfx *f = lone_disc("snapshot_every = 5\n", 7, 5);
    run_with_snapshots(f);
    const long cycles[] = {0, 5, 10, 12};
    check_index(cycles, 4, 2);
    ck_assert(exists("snapshots/discs.000003.tsv"));
    ck_assert(!exists("snapshots/discs.000004.tsv"));
}
END_TEST

/* Every 5 cycles of 5 + 5: the final state at 10 is a frame of the schedule,
 * written once. */
START_TEST(snapshots_final_state_not_repeated)
{
    struct tfx *f = lone_disc("snapshot_every = 5\n", 5, 5);
    run_with_snapshots(f);
    const long cycles[] = {0, 5, 10};
    check_index(cycles, 3, 2);
    ck_assert(!exists("snapshots/discs.000003.tsv"));
}
END_TEST

/* Every T = 0.25 of simulated time at dt = 0.1: frame k at cycle ceil(2.5 k):
 * 3, 5, 8, 10, then the final state at 12.  T = 0.2: ceil(2 k) = 2, 4, 6, 8, 10,
 * 12 (12, the end, once); for k = 3, (3 x 0.2)/0.1 is 6.000000000000001 in
 * doubles, whose ceiling, 7, the rounding to 1e-9 of a step must not take. */
START_TEST(snapshots_every_t_of_simulated_time)
{
    struct tfx *f = lone_disc("snapshot_dt = 0.25\n", 7, 5);
    run_with_snapshots(f);
    const long quarter[] = {0, 3, 5, 8, 10, 12};
    check_index(quarter, 6, 3);
    out_teardown();
    out_setup();
    f = lone_disc("snapshot_dt = 0.2\n", 7, 5);
    run_with_snapshots(f);
    const long fifth[] = {0, 2, 4, 6, 8, 10, 12};
    check_index(fifth, 7, 4);
}
END_TEST

/* A period shorter than the step: a frame every cycle, no cycle twice. */
START_TEST(snapshots_period_below_the_step)
{
    struct tfx *f = lone_disc("snapshot_dt = 0.04\n", 2, 1);
    run_with_snapshots(f);
    const long cycles[] = {0, 1, 2, 3};
    check_index(cycles, 4, 3);
}
END_TEST

/* Off (the default), the run loop's one test never holds: next is -1; on, it is
 * -1 too until a folder is named, and nothing is written without one. */
START_TEST(snapshots_off_costs_one_comparison)
{
    struct tfx *f = lone_disc("", 7, 5);
    ck_assert_int_eq(f->sim->snap.next, -1);
    ck_assert_ptr_null(f->sim->snap.frames);
    ck_assert_int_eq(bal_sim_set_snapshots(f->sim, out_dir, &f->err), BAL_OK);
    ck_assert_int_eq(f->sim->snap.next, -1);
    ck_assert_int_eq(bal_sim_run(f->sim, NULL, NULL, &f->err), BAL_OK);
    ck_assert(!exists("snapshots"));
    struct tfx *g = lone_disc("snapshot_every = 5\n", 7, 5);
    ck_assert_int_eq(g->sim->snap.next, -1);
    ck_assert_int_eq(bal_sim_run(g->sim, NULL, NULL, &g->err), BAL_OK);
    ck_assert(!exists("snapshots"));
}
END_TEST

/* ------------------------------------------------------------------ */
/* The files                                                           */
/* ------------------------------------------------------------------ */

/* Every file of every frame listed, renamed into place: the folder holds
 * index.tsv and 3 TSV files per frame, nothing else, no .tmp; with vtk = 1
 * (loop index 1) also snapshots.pvd and 3 VTK files per frame. */
START_TEST(snapshots_files_complete_none_tmp)
{
    const int vtk = _i;
    struct tfx *f = lone_disc(vtk ? "snapshot_every = 5\nvtk = 1\n" : "snapshot_every = 5\n", 7, 5);
    run_with_snapshots(f);
    char dir[600];
    snprintf(dir, sizeof dir, "%s/snapshots", out_dir);
    DIR *d = opendir(dir);
    ck_assert_ptr_nonnull(d);
    int files = 0, tmp = 0;
    for (struct dirent *e = readdir(d); e; e = readdir(d)) {
        if (e->d_name[0] == '.')
            continue;
        files++;
        tmp += strstr(e->d_name, ".tmp") != NULL;
    }
    closedir(d);
    ck_assert_int_eq(tmp, 0);
    ck_assert_int_eq(files, vtk ? 2 + 6 * 4 : 1 + 3 * 4);
    ck_assert(exists("snapshots/snapshots.pvd") == vtk);
    static const char *const parts[] = {"discs", "contacts", "walls"};
    char name[64];
    for (long k = 0; k < 4; k++)
        for (int q = 0; q < 3; q++)
            for (int v = 0; v <= vtk; v++) {
                snprintf(name, sizeof name, "snapshots/%s.%06ld.%s", parts[q], k, v ? "vtp" : "tsv");
                ck_assert_msg(exists(name), "%s missing", name);
            }
}
END_TEST

/* A frame whose file cannot be put in place (a folder stands at its name)
 * stops the run with BAL_EIO naming the file, and index.tsv still lists only
 * the frames whose files are all there: frame 0. */
START_TEST(snapshots_failed_frame_not_listed)
{
    struct tfx *f = lone_disc("snapshot_every = 5\n", 7, 5);
    char path[600];
    snprintf(path, sizeof path, "%s/snapshots", out_dir);
    ck_assert_int_eq(mkdir(path, 0777), 0);
    snprintf(path, sizeof path, "%s/snapshots/contacts.000001.tsv", out_dir);
    ck_assert_int_eq(mkdir(path, 0777), 0);
    snprintf(path, sizeof path, "%s/snapshots/contacts.000001.tsv/keep", out_dir);
    FILE *keep = fopen(path, "w");
    ck_assert_ptr_nonnull(keep);
    fclose(keep);
    ck_assert_int_eq(bal_sim_set_snapshots(f->sim, out_dir, &f->err), BAL_OK);
    const enum bal_status st = bal_sim_run(f->sim, NULL, NULL, &f->err);
    ck_assert_msg(st == BAL_EIO, "status %d: %s", st, f->err.msg);
    ck_assert_msg(t_contains(f->err.msg, "contacts.000001.tsv.tmp: cannot rename"), "%s",
                  f->err.msg);
    const long cycles[] = {0};
    check_index(cycles, 1, 1);
    ck_assert(exists("snapshots/discs.000001.tsv")); /* written before it, not listed */
}
END_TEST

/* The last frame's contacts and walls are the final contacts.tsv and
 * walls.tsv byte for byte, and its discs their columns (output.c writes
 * both): a pile of discs in a box, so that there are contacts. */
START_TEST(snapshots_last_frame_is_the_final_state)
{
    struct tfx *f = tfx_newf("box",
                             "[settings]\ngravity = 0 -9.81\nbeta = 1e-3\nsnapshot_every = 40\n"
                             "[material m]\nkn = 1e5\nfriction = 0.5\ndensity = 1\n"
                             "[fill f]\nn = 12\ncolumns = 4\nrmin = 0.5\nrmax = 0.5\nbox = 1\n"
                             "material = m\nwall_material = m\nseed = 7\n"
                             "[stage fall]\ncycles = 150\n");
    run_with_snapshots(f);
    ck_assert_int_eq(bal_output_state(f->sim, out_dir, &f->err), BAL_OK);
    char *final = read_text("contacts.tsv"), *frame = read_text("snapshots/contacts.000004.tsv");
    ck_assert_ptr_nonnull(final);
    ck_assert_ptr_nonnull(frame);
    ck_assert_msg(strchr(final, '\n') != strrchr(final, '\n'), "no contact to compare");
    ck_assert_str_eq(frame, final);
    free(final);
    free(frame);
    final = read_text("walls.tsv");
    frame = read_text("snapshots/walls.000004.tsv");
    ck_assert_str_eq(frame, final);
    free(final);
    free(frame);
    ck_assert(!exists("snapshots/contacts.000005.tsv"));
    /* the discs: x of disc f.3 (id 3) in the fifth column of the frame, the third of discs.tsv */
    frame = read_text("snapshots/discs.000004.tsv");
    final = read_text("discs.tsv");
    const char *header = "id\tname\tgenerator\tindex\tx\ty\tr\ttheta\tvx\tvy\tomega\tfx\tfy\t"
                         "torque\tm\tfixed\n";
    ck_assert(strncmp(frame, header, strlen(header)) == 0);
    char row[64], want[128];
    const int i = f->sim->slot[3];
    snprintf(row, sizeof row, "\n3\tf.3\tf\t3\t%.17g\t%.17g\t", f->sim->x[i], f->sim->y[i]);
    ck_assert_msg(t_contains(frame, row), "no row '%s'", row + 1);
    snprintf(want, sizeof want, "\n3\tf.3\t%.17g\t%.17g\t", f->sim->x[i], f->sim->y[i]);
    ck_assert_msg(t_contains(final, want), "discs.tsv has no row '%s'", want + 1);
    free(final);
    free(frame);
}
END_TEST

/* fx, fy and torque of the first two rows of a frame's discs file. */
static void frame_forces(const char *rel, double *fx, double *fy, double *tq)
{
    char *text = read_text(rel);
    ck_assert_msg(text != NULL, "no %s", rel);
    const char *line = strchr(text, '\n') + 1;
    for (int k = 0; k < 2; k++, line = strchr(line, '\n') + 1) {
        /* id name generator index x y r theta vx vy omega | fx fy torque m fixed */
        const char *p = line;
        for (int col = 0; col < 11; col++)
            p = strchr(p, '\t') + 1;
        const int got = sscanf(p, "%lf\t%lf\t%lf", &fx[k], &fy[k], &tq[k]);
        ck_assert_msg(got == 3, "%s: row %d: '%.60s'", rel, k, line);
    }
    free(text);
}

/* The forces of a frame: two discs of radius 1 overlapping by delta = 2 - 1.9
 * = 0.1 under the linear power law (nu = 1, delta0 = 1: F_n = k_n delta, MLH
 * eq. 2) push each other apart with k_n delta = 100 along x in the first
 * cycle (b starts at rest, v_{1/2} = 0, so x_1 = x_0: C&S eq. 23); a is held
 * (a pair of held discs is not a candidate); no moment (no friction), and
 * the gravity the law of motion adds is not in fx fy. */
START_TEST(snapshots_disc_forces_closed_form)
{
    struct tfx *f = tfx_newf("pair",
                             "[settings]\ndt = 1e-3\nnormal_law = power\nnu = 1\ndelta0 = 1\n"
                             "gravity = 0 -9.81\nsnapshot_every = 1\n"
                             "[material m]\nkn = 1e3\ndensity = 1\n"
                             "[disc a]\nx = 0 0\nr = 1\nfixed = 1\nmaterial = m\n"
                             "[disc b]\nx = 1.9 0\nr = 1\nmaterial = m\n"
                             "[stage s]\ncycles = 2\n");
    run_with_snapshots(f);
    const double kd = 1e3 * (2 - 1.9);
    double fx[2], fy[2], tq[2];
    frame_forces("snapshots/discs.000001.tsv", fx, fy, tq);
    ck_assert_double_eq_tol(fx[0], -kd, 1e-12 * kd);
    ck_assert_double_eq_tol(fx[1], kd, 1e-12 * kd);
    ck_assert_double_eq(fy[0], 0.0);
    ck_assert_double_eq(fy[1], 0.0);
    ck_assert_double_eq(tq[0], 0.0);
    ck_assert_double_eq(tq[1], 0.0);
    /* frame 0, before the first cycle: no force has been computed yet */
    frame_forces("snapshots/discs.000000.tsv", fx, fy, tq);
    for (int k = 0; k < 2; k++) {
        ck_assert_double_eq(fx[k], 0.0);
        ck_assert_double_eq(fy[k], 0.0);
        ck_assert_double_eq(tq[k], 0.0);
    }
}
END_TEST

/* The generator and index columns: a [disc] is its own generator, index 0;
 * the discs of a [fill] are its 0, 1, ... in scene order after the [disc]s. */
START_TEST(snapshots_generator_and_index)
{
    struct tfx *f = tfx_newf("gens",
                             "[settings]\nsnapshot_every = 10\n"
                             "[material m]\nkn = 1e3\ndensity = 1\n"
                             "[disc lone]\nx = 10 10\nr = 0.5\nmaterial = m\n"
                             "[fill g]\nn = 2\ncolumns = 2\nrmin = 0.5\nrmax = 0.5\nmaterial = m\n"
                             "[stage s]\ncycles = 1\n");
    run_with_snapshots(f);
    char *text = read_text("snapshots/discs.000000.tsv");
    ck_assert_ptr_nonnull(text);
    ck_assert_msg(t_contains(text, "\n0\tlone\tlone\t0\t10\t10\t0.5\t"), "%s", text);
    ck_assert_msg(t_contains(text, "\n1\tg.0\tg\t0\t"), "%s", text);
    ck_assert_msg(t_contains(text, "\n2\tg.1\tg\t1\t"), "%s", text);
    free(text);
}
END_TEST

/* ------------------------------------------------------------------ */
/* The keys                                                            */
/* ------------------------------------------------------------------ */

#define LONE_BODY "[material m]\nkn = 1e3\ndensity = 1\n[disc a]\nx = 0 0\nr = 1\nmaterial = m\n" \
                  "[stage s]\ncycles = 10\n"

/* Refused with the file, line and key (validate for the pairs of keys, the
 * parser for a value out of range, create for too many frames). */
static const struct {
    const char *what, *text, *set, *expect;
} refused[] = {
    {"both", "[settings]\nsnapshot_every = 5\nsnapshot_dt = 0.5\n" LONE_BODY, NULL,
     "bad:3: snapshot_dt: snapshots every 0.5 of simulated time and every 5 cycles (bad:2: "
     "snapshot_every)"},
    {"both, one by --set", "[settings]\nsnapshot_every = 5\n" LONE_BODY, "settings.snapshot_dt=0.5",
     "bad: --set snapshot_dt: snapshots every 0.5 of simulated time and every 5 cycles (bad:2: "
     "snapshot_every)"},
    {"vtk alone", "[settings]\nvtk = 1\n" LONE_BODY, NULL,
     "bad:2: vtk: vtk = 1 needs snapshots: give snapshot_every (cycles) or snapshot_dt"},
    {"vtk by --set", LONE_BODY, "settings.vtk=1", "bad: --set vtk: vtk = 1 needs snapshots"},
    {"negative every", "[settings]\nsnapshot_every = -1\n" LONE_BODY, NULL,
     "bad:2: snapshot_every: -1 is out of range"},
    {"negative period", "[settings]\nsnapshot_dt = -0.1\n" LONE_BODY, NULL,
     "bad:2: snapshot_dt: -0.1 is out of range"},
    {"vtk 2", "[settings]\nvtk = 2\n" LONE_BODY, NULL, "bad:2: vtk: 2 is out of range"},
    {"too many frames", "[settings]\ndt = 0.1\nsnapshot_every = 1\n" LONE_BODY, "stage.s.cycles=2000000",
     "bad:3: snapshot_every: 2000002 frames in the stages' 2000000 cycles; expected at most 1000000"},
    {"too many frames in time", "[settings]\ndt = 0.1\nsnapshot_dt = 0.1\n" LONE_BODY,
     "stage.s.cycles=2000000", "bad:3: snapshot_dt: 2000002 frames in the stages' 2000000 cycles"},
};

START_TEST(snapshots_keys_refused)
{
    struct bal_scene sc;
    struct bal_error err = {0};
    bal_scene_default(&sc);
    enum bal_status st = bal_scene_parse(&sc, refused[_i].text, "bad", &err);
    if (st == BAL_OK && refused[_i].set)
        st = bal_scene_set(&sc, refused[_i].set, &err);
    if (st == BAL_OK) {
        struct bal_sim *sim = NULL;
        sc.settings.force_dt = 1;
        st = bal_sim_create(&sim, &sc, &err);
        bal_sim_free(sim);
    }
    bal_scene_free(&sc);
    ck_assert_msg(st == BAL_EINVAL, "%s: status %d (%s)", refused[_i].what, st, err.msg);
    ck_assert_msg(t_contains(err.msg, refused[_i].expect), "%s: '%s' lacks '%s'", refused[_i].what,
                  err.msg, refused[_i].expect);
}
END_TEST

/* The defaults (off), and one of the two given with the other 0 is accepted. */
START_TEST(snapshots_keys_defaults_and_accepted)
{
    struct bal_scene sc;
    bal_scene_default(&sc);
    ck_assert_int_eq(sc.settings.snapshot_every, 0);
    ck_assert_double_eq(sc.settings.snapshot_dt, 0.0);
    ck_assert_int_eq(sc.settings.vtk, 0);
    bal_scene_free(&sc);
    struct tfx *f = tfx_new("[settings]\nsnapshot_every = 0\nsnapshot_dt = 0.5\nvtk = 1\n" LONE_BODY,
                            "ok");
    ck_assert_int_eq(f->sim->snap.every, 0);
    ck_assert_double_eq(f->sim->snap.period, 0.5);
}
END_TEST

/* Every section kind has room for its keys: a bit of `given` and a slot of
 * key_line each ([settings] one fewer: its last slot holds its header's line). */
START_TEST(snapshots_keys_fit_the_section_tail)
{
    for (int k = 0; k < BAL_SEC_COUNT; k++) {
        int n = 0;
        while (bal_scene_key_at((enum bal_section_kind)k, n))
            n++;
        const int room = k == BAL_SEC_SETTINGS ? BAL_KEYS_MAX - 1 : BAL_KEYS_MAX;
        ck_assert_msg(n <= room, "[%s] has %d keys, room for %d", bal_scene_sections[k].name, n, room);
    }
}
END_TEST

Suite *suite_snapshots(void)
{
    Suite *s = suite_create("snapshots");
    TCase *tc = tcase_create("schedule");
    tcase_add_checked_fixture(tc, out_setup, out_teardown);
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, snapshots_every_n_cycles_and_the_final_state);
    tcase_add_test(tc, snapshots_final_state_not_repeated);
    tcase_add_test(tc, snapshots_every_t_of_simulated_time);
    tcase_add_test(tc, snapshots_period_below_the_step);
    tcase_add_test(tc, snapshots_off_costs_one_comparison);
    suite_add_tcase(s, tc);
    tc = tcase_create("files");
    tcase_add_checked_fixture(tc, out_setup, out_teardown);
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_loop_test(tc, snapshots_files_complete_none_tmp, 0, 2);
    tcase_add_test(tc, snapshots_failed_frame_not_listed);
    tcase_add_test(tc, snapshots_last_frame_is_the_final_state);
    tcase_add_test(tc, snapshots_disc_forces_closed_form);
    tcase_add_test(tc, snapshots_generator_and_index);
    suite_add_tcase(s, tc);
    tc = tcase_create("keys");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_loop_test(tc, snapshots_keys_refused, 0, (int)(sizeof refused / sizeof refused[0]));
    tcase_add_test(tc, snapshots_keys_defaults_and_accepted);
    tcase_add_test(tc, snapshots_keys_fit_the_section_tail);
    suite_add_tcase(s, tc);
    return s;
}
