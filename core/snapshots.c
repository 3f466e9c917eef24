/*
 * snapshots.c — the state of a run at regular intervals, to look at: with
 * settings.snapshot_every = N (cycles) or snapshot_dt = T (simulated time) a
 * run writes, into OUT/snapshots/,
 *
 *   index.tsv            frame, cycle, time, stage: a row per frame written
 *   discs.FFFFFF.tsv     the discs of frame FFFFFF (six digits, from 0): the
 *                        columns of discs.tsv but row, with the generator and
 *                        index each disc came from and the contact forces
 *                        and moment on it (output.h, bal_output_discs)
 *   contacts.FFFFFF.tsv  the touching contacts, as contacts.tsv
 *   walls.FFFFFF.tsv     the walls, as walls.tsv
 *
 * and with settings.vtk = 1 the same frame as VTK XML PolyData (vtk.c:
 * discs, contacts and walls .FFFFFF.vtp) and snapshots.pvd, the collection
 * that ParaView opens, with each frame's simulated time.
 *
 * Frames.  Frame 0 is the state the run starts from (cycle 0); then one at
 * every cycle of the schedule; and the final state of a run that completes
 * is always the last frame (once, when the schedule has it too).  Every N
 * cycles: cycles N, 2N, ...; every T of simulated time: frame k at cycle
 * ceil(k T / dt), to STEP_ROUNDING of a step as for a stage given in time
 * (build.c), so that the frames are T apart whatever the step.
 *
 * Every file is written under NAME.tmp and renamed when complete; index.tsv
 * and snapshots.pvd are rewritten (so renamed) after the frame's files are
 * in place, so a reader never sees a frame listed whose files are missing.
 * The run loop pays one comparison a cycle (s->step == s->snap.next, -1
 * when off); the table of frames is reserved at creation, so a frame
 * allocates nothing but what stdio does for its files.
 */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "output.h"
#include "scene.h"
#include "snapshots.h"
#include "status.h"
#include "vtk.h"

/* A frame in time is at ceil(k T / dt) cycles "to 1e-9 of a step": the
 * rounding of build.c for a stage given in time, so that the third frame of
 * T = 0.2 at dt = 0.1 is at cycle 6, not 7 ((3 x 0.2)/0.1 = 6.000000000000001
 * in doubles). */
#define STEP_ROUNDING 1e-9

enum bal_status bal_snapshots_setup(struct bal_sim *s, struct bal_error *err)
{
    const struct bal_scene *sc = s->scene;
    const struct bal_settings *st = &sc->settings;
    struct bal_snapshots *p = &s->snap;
    p->next = -1;
    p->every = st->snapshot_every;
    p->period = st->snapshot_dt;
    if (p->every == 0 && p->period == 0)
        return BAL_OK;
    double cycles = 0;
    for (int g = 0; g < sc->n_stages; g++)
        cycles += (double)s->log[g].max_cycles;
    /* Frame 0, the frames of the schedule within the stages' cycles (at most
     * one a cycle), the final state. */
    const double scheduled = p->every > 0 ? floor(cycles / (double)p->every)
                                          : fmin(cycles, floor(cycles * s->dt / p->period) + 1);
    const double frames = scheduled + 2;
    if (!(frames <= BAL_SNAPSHOT_FRAMES_MAX)) {
        char where[BAL_PATH_MAX + 64];
        bal_scene_settings_where(sc, p->every > 0 ? "snapshot_every" : "snapshot_dt", where,
                                 sizeof where);
        return bal_error(err, BAL_EINVAL,
                         "%s: %.0f frames in the stages' %.0f cycles; expected at most %ld "
                         "(frames are numbered in six digits): take them further apart",
                         where, frames, cycles, BAL_SNAPSHOT_FRAMES_MAX);
    }
    p->cap = (long)frames;
    p->frames = malloc((size_t)p->cap * sizeof *p->frames);
    if (!p->frames)
        return bal_error(err, BAL_ENOMEM, "%s: out of memory for %ld snapshots", sc->path, p->cap);
    return BAL_OK;
}

enum bal_status bal_sim_set_snapshots(struct bal_sim *s, const char *dir, struct bal_error *err)
{
    struct bal_snapshots *p = &s->snap;
    if (!p->frames)
        return BAL_OK; /* the scene takes no snapshots */
    if (snprintf(p->dir, sizeof p->dir, "%s/snapshots", dir) >= (int)sizeof p->dir) {
        p->dir[0] = '\0';
        return bal_error(err, BAL_EIO, "%s/snapshots: the path is longer than %d characters",
                         dir, BAL_SNAPSHOT_DIR_MAX - 1);
    }
    if (mkdir(p->dir, 0777) != 0 && errno != EEXIST)
        return bal_error(err, BAL_EIO, "%s: cannot create directory: %s", p->dir,
                         strerror(errno));
    p->n = 0;
    p->next = s->step; /* frame 0: the state the run starts from */
    return BAL_OK;
}

void bal_snapshots_name(char *buf, size_t size, const char *part, long frame, const char *ext)
{
    snprintf(buf, size, "%s.%06ld.%s", part, frame, ext);
}

/* The frame after cycle `step`. */
static long next_cycle(const struct bal_snapshots *p, long step, double dt)
{
    if (p->every > 0)
        return (step / p->every + 1) * p->every;
    /* A period of at most one step: a frame every cycle. */
    if (p->period <= dt)
        return step + 1;
    /* The first k whose cycle ceil(k T / dt) is past step: frames k' <= step dt / T
     * are at or before it; the loop corrects the rounding of that guess. */
    double k = floor((double)step * dt / p->period) + 1, c;
    while ((c = ceil(k * p->period / dt - STEP_ROUNDING)) <= (double)step)
        k++;
    return (long)c;
}

static void disc_rows(const struct bal_sim *s, FILE *f)
{
    bal_output_discs(s, f, 1);
}

static void index_rows(const struct bal_sim *s, FILE *f)
{
    fputs("frame\tcycle\ttime\tstage\n", f);
    for (long k = 0; k < s->snap.n; k++) {
        const struct bal_snapshot_frame *fr = &s->snap.frames[k];
        fprintf(f, "%ld\t%ld\t%.17g\t%s\n", k, fr->cycle, fr->time,
                s->scene->n_stages > 0 ? s->scene->stages[fr->stage].name : "");
    }
}

typedef void (*rows_fn)(const struct bal_sim *s, FILE *f);

static enum bal_status write_file(const struct bal_sim *s, const char *name, rows_fn rows,
                                  struct bal_error *err)
{
    FILE *f = bal_output_open(s->snap.dir, name, err);
    if (!f)
        return err->code;
    rows(s, f);
    return bal_output_close(f, s->snap.dir, name, err);
}

enum bal_status bal_snapshots_frame(struct bal_sim *s, struct bal_error *err)
{
    static const struct {
        const char *part;
        rows_fn tsv, vtk;
    } parts[] = {{"discs", disc_rows, bal_vtk_discs},
                 {"contacts", bal_output_contacts, bal_vtk_contacts},
                 {"walls", bal_output_walls, bal_vtk_walls}};
    struct bal_snapshots *p = &s->snap;
    if (p->n >= p->cap)
        return bal_error(err, BAL_EINVAL,
                         "%s: snapshots: frame %ld is past the %ld the stages' cycles have room "
                         "for (bal_sim_run called twice?)", s->scene->path, p->n, p->cap);
    const int vtk = s->scene->settings.vtk != 0;
    char name[64];
    for (size_t q = 0; q < sizeof parts / sizeof parts[0]; q++) {
        bal_snapshots_name(name, sizeof name, parts[q].part, p->n, "tsv");
        if (write_file(s, name, parts[q].tsv, err))
            return err->code;
        if (!vtk)
            continue;
        bal_snapshots_name(name, sizeof name, parts[q].part, p->n, "vtp");
        if (write_file(s, name, parts[q].vtk, err))
            return err->code;
    }
    /* Listed once its files are in place. */
    p->frames[p->n++] = (struct bal_snapshot_frame){s->step, s->time, s->stage >= 0 ? s->stage : 0};
    if (vtk && write_file(s, "snapshots.pvd", bal_vtk_collection, err))
        return err->code;
    if (write_file(s, "index.tsv", index_rows, err))
        return err->code;
    p->next = next_cycle(p, s->step, s->dt);
    return BAL_OK;
}

enum bal_status bal_snapshots_last(struct bal_sim *s, struct bal_error *err)
{
    const struct bal_snapshots *p = &s->snap;
    if (p->next < 0 || (p->n > 0 && p->frames[p->n - 1].cycle == s->step))
        return BAL_OK;
    return bal_snapshots_frame(s, err);
}

/* A file of the snapshots folder: index.tsv, snapshots.pvd, a frame's file,
 * or one of them under its temporary name. */
static int snapshot_file(const char *name)
{
    static const char *const starts[] = {"index.tsv", "snapshots.pvd", "discs.", "contacts.",
                                         "walls."};
    for (size_t k = 0; k < sizeof starts / sizeof starts[0]; k++)
        if (strncmp(name, starts[k], strlen(starts[k])) == 0)
            return 1;
    return 0;
}

void bal_output_remove_snapshots(const char *dir)
{
    char folder[1024], path[1400];
    if (snprintf(folder, sizeof folder, "%s/snapshots", dir) >= (int)sizeof folder)
        return;
    DIR *d = opendir(folder);
    if (!d)
        return;
    for (struct dirent *e = readdir(d); e; e = readdir(d)) {
        if (!snapshot_file(e->d_name))
            continue;
        snprintf(path, sizeof path, "%s/%s", folder, e->d_name);
        remove(path);
    }
    closedir(d);
    rmdir(folder); /* stays if it holds files the snapshots did not write */
}
