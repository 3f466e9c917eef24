/*
 * build.c — a simulation's state from a validated scene: the steps of
 * bal_sim_create (sim.c), in the order it calls them.
 *
 *   settings   the scalars of [settings]; the number of discs, refused
 *              beyond BAL_MAX_DISCS, naming the generator that passes it
 *   materials  the contact parameters of every pair of materials
 *              (C&S eqs 16–19, 28)
 *   walls      [wall] sections, then four walls per boxed [fill], a floor
 *              per smooth [pile], four walls per boxed [grains] and the walls
 *              of each [import]
 *   discs      laid out in scene order (specimen.c), sorted into cell order
 *              when the grid is used; everything derived from them checked
 *              to be a finite number
 *   timestep   the critical-step estimate (timestep.c) and the step used,
 *              refused at or above the estimate unless forced
 *   lists      the first candidate lists (grid.c), and the overlaps at the
 *              start, refused unless the scene allows them
 *   probes     each [probe]'s bodies resolved to slots and wall indices
 *   stages     the log of each stage of the loading protocol; none begun
 *
 * Each step reads what the steps before it made and, on failure, leaves
 * the simulation for its caller to free whole.  All memory a run needs is
 * reserved here, or, for neighbour lists that outgrow their first size, in
 * a rebuild: the cycle never allocates.
 *
 * Kept whole (about 650 lines): the steps are one sequence, each reading
 * what the one before made and leaving a half-built simulation for
 * bal_sim_create to free; split, the order and that cleanup contract would
 * be spread over files.  The discs themselves are laid out in specimen.c.
 */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "build.h"
#include "pair_loop.h"
#include "grid.h"
#include "pairs.h"
#include "scene.h"
#include "specimen.h"
#include "status.h"
#include "timestep.h"
#include "walls.h"

/* Default Verlet skin as a share of the largest radius: a wider skin means
 * fewer rebuilds but more candidate pairs to test every cycle. */
#define SKIN_SHARE_OF_RMAX 0.2

static double *alloc_doubles(size_t n, int *ok)
{
    double *p = calloc(n ? n : 1, sizeof *p);
    if (!p)
        *ok = 0;
    return p;
}

enum bal_status bal_build_settings(struct bal_sim *s, const struct bal_scene *sc,
                                   struct bal_error *err)
{
    s->scene = sc;
    s->par.threads = 1;
    s->par.planned = -1;
    const struct bal_settings *st = &sc->settings;
    s->alpha = st->alpha;
    s->beta = st->beta;
    s->g[0] = st->gravity[0];
    s->g[1] = st->gravity[1];
    s->normal_law = st->normal_law;
    s->nu = st->nu;
    s->delta0 = st->delta0;
    s->has_damping = st->beta > 0 || st->gamma_n > 0;
    s->overlap_budget = st->overlap_budget > 0 ? st->overlap_budget : INFINITY;
    s->gamma_n = st->gamma_n;
    s->psi = st->psi;

    const long n_total = bal_specimen_count(sc);
    if (n_total > BAL_MAX_DISCS) {
        /* The generator that passes the limit, for its line. */
        char where[BAL_NAME_MAX + 600];
        bal_specimen_count_origin(sc, BAL_MAX_DISCS, where, sizeof where);
        return bal_error(err, BAL_EINVAL, "%s: the scene has %ld discs; at most %ld", where,
                         n_total, BAL_MAX_DISCS);
    }
    s->n = (int)n_total;
    return BAL_OK;
}

/* Fill the material-pair table (C&S eqs 19, 28).  Stiffnesses of two
 * different materials combine as springs in series scaled so that equal
 * materials give their own value: k = 2 k_a k_b / (k_a + k_b). */
static void build_laws(struct bal_sim *s, const struct bal_scene *sc)
{
    for (int a = 0; a < s->n_mat; a++) {
        for (int b = 0; b < s->n_mat; b++) {
            const struct bal_material_def *A = &sc->materials[a], *B = &sc->materials[b];
            const double ksa = A->ks < 0 ? A->kn : A->ks, ksb = B->ks < 0 ? B->kn : B->ks;
            struct bal_pair_law *L = &s->law[a * s->n_mat + b];
            L->kn = 2 * A->kn * B->kn / (A->kn + B->kn);
            L->ks = 2 * ksa * ksb / (ksa + ksb);
            L->tan_phi = fmin(A->friction, B->friction);
            L->cohesion = fmin(A->cohesion, B->cohesion);
            L->cn = s->beta * L->kn;
            L->cs = s->beta * L->ks;
            L->shear = L->tan_phi > 0 || L->cohesion > 0;
            if (L->shear)
                s->has_shear = 1;
            L->rolling = fmin(A->rolling, B->rolling);
            if (L->rolling > 0)
                s->has_rolling = 1;
        }
    }
}

enum bal_status bal_build_materials(struct bal_sim *s, struct bal_error *err)
{
    const struct bal_scene *sc = s->scene;
    s->n_mat = sc->n_materials;
    s->law = calloc((size_t)s->n_mat * (size_t)s->n_mat, sizeof *s->law);
    if (!s->law)
        return bal_error(err, BAL_ENOMEM, "%s: out of memory", sc->path);
    build_laws(s, sc);
    return BAL_OK;
}

static long fill_rows(const struct bal_fill_def *f)
{
    return (f->n + f->columns - 1) / f->columns;
}

static void add_wall(struct bal_sim *s, const char *name, double px, double py,
                     double angle_rad, double h1, double h2, int material)
{
    struct bal_wall *w = &s->walls[s->n_walls++];
    memset(w, 0, sizeof *w);
    snprintf(w->name, sizeof w->name, "%s", name);
    w->p[0] = px;
    w->p[1] = py;
    w->alpha = angle_rad;
    w->e[0] = cos(angle_rad);
    w->e[1] = sin(angle_rad);
    w->h1 = h1;
    w->h2 = h2;
    w->material = material;
}

enum bal_status bal_build_walls(struct bal_sim *s, struct bal_error *err)
{
    const struct bal_scene *sc = s->scene;
    int n_walls = sc->n_walls;
    for (int f = 0; f < sc->n_fills; f++)
        n_walls += sc->fills[f].box ? 4 : 0;
    for (int p = 0; p < sc->n_piles; p++)
        n_walls += sc->piles[p].bottom == 0;
    for (int g = 0; g < sc->n_grains; g++)
        n_walls += sc->grains[g].box ? 4 : 0;
    for (int i = 0; i < sc->n_imports; i++)
        n_walls += sc->imports[i].n_walls;
    s->walls = calloc((size_t)(n_walls ? n_walls : 1), sizeof *s->walls);
    if (!s->walls)
        return bal_error(err, BAL_ENOMEM, "%s: out of memory", sc->path);
    for (int k = 0; k < sc->n_walls; k++) {
        const struct bal_wall_def *wd = &sc->walls[k];
        add_wall(s, wd->name, wd->p[0], wd->p[1], wd->angle * (BAL_PI / 180), wd->h1, wd->h2,
                 bal_scene_find(sc, BAL_SEC_MATERIAL, wd->material));
    }
    for (int f = 0; f < sc->n_fills; f++) {
        const struct bal_fill_def *fd = &sc->fills[f];
        if (!fd->box)
            continue;
        const int m = bal_scene_find(sc, BAL_SEC_MATERIAL, fd->wall_material);
        const double wd = (double)fd->columns * 2 * fd->rmax;
        const double ht = (double)fill_rows(fd) * 2 * fd->rmax + fd->headroom;
        const double ox = fd->origin[0], oy = fd->origin[1];
        char nm[2 * BAL_NAME_MAX];
        snprintf(nm, sizeof nm, "%s_bottom", fd->name);
        add_wall(s, nm, ox, oy, 0, 0, wd, m);
        snprintf(nm, sizeof nm, "%s_right", fd->name);
        add_wall(s, nm, ox + wd, oy, BAL_PI / 2, 0, ht, m);
        snprintf(nm, sizeof nm, "%s_top", fd->name);
        add_wall(s, nm, ox, oy + ht, 0, 0, wd, m);
        snprintf(nm, sizeof nm, "%s_left", fd->name);
        add_wall(s, nm, ox, oy, BAL_PI / 2, 0, ht, m);
    }

    for (int p = 0; p < sc->n_piles; p++) {
        const struct bal_pile_def *pd = &sc->piles[p];
        if (pd->bottom != 0)
            continue;
        /* The floor under row 0, reaching a diameter beyond the corner stones. */
        char nm[2 * BAL_NAME_MAX];
        snprintf(nm, sizeof nm, "%s_floor", pd->name);
        add_wall(s, nm, pd->origin[0], pd->origin[1], 0, -pd->d, (double)(pd->L + 1) * pd->d,
                 bal_scene_find(sc, BAL_SEC_MATERIAL, pd->wall_material));
    }
    for (int g = 0; g < sc->n_grains; g++) {
        const struct bal_grains_def *gd = &sc->grains[g];
        if (!gd->box)
            continue;
        /* The region's sides, each reaching `overhang` beyond the corners, so
         * that a side wall that moves out leaves no gap at a corner. */
        const int m = bal_scene_find(sc, BAL_SEC_MATERIAL, gd->wall_material);
        const double o = gd->overhang < 0 ? gd->dmax : gd->overhang;
        const double ox = gd->origin[0], oy = gd->origin[1], wd = gd->size[0], ht = gd->size[1];
        char nm[2 * BAL_NAME_MAX];
        snprintf(nm, sizeof nm, "%s_bottom", gd->name);
        add_wall(s, nm, ox, oy, 0, -o, wd + o, m);
        snprintf(nm, sizeof nm, "%s_right", gd->name);
        add_wall(s, nm, ox + wd, oy, BAL_PI / 2, -o, ht + o, m);
        snprintf(nm, sizeof nm, "%s_top", gd->name);
        add_wall(s, nm, ox, oy + ht, 0, -o, wd + o, m);
        snprintf(nm, sizeof nm, "%s_left", gd->name);
        add_wall(s, nm, ox, oy, BAL_PI / 2, -o, ht + o, m);
    }
    for (int i = 0; i < sc->n_imports; i++) {
        const struct bal_import_def *im = &sc->imports[i];
        const int m = bal_scene_find(sc, BAL_SEC_MATERIAL, im->wall_material);
        for (int k = 0; k < im->n_walls; k++) {
            /* From A to B: P = A, h1 = 0, h2 = |B - A| (import.c). */
            const struct bal_import_wall *w = &im->wall_data[k];
            const double dx = w->b[0] - w->a[0], dy = w->b[1] - w->a[1];
            add_wall(s, w->name, w->a[0], w->a[1], atan2(dy, dx), 0, hypot(dx, dy), m);
        }
    }
    return BAL_OK;
}

/* Everything the run derives from a disc's data must be a finite double:
 * its mass and moment of inertia (positive, with finite inverses), its
 * kinetic energy, its weight and its share of the gravity potential, and
 * the sums of these over the scene (which the energy audit and the probes
 * write).  A value that overflows or underflows is refused here, naming the
 * disc and the key that made it, rather than found as a non-finite column
 * after the run, or as a time step of 0 with no origin. */
static enum bal_status check_derived(const struct bal_sim *s, struct bal_error *err)
{
    const struct bal_scene *sc = s->scene;
    double ek = 0, eg = 0;
    for (int i = 0; i < s->n; i++) {
        const double m = bal_mass(s, i), in = bal_inertia(s, i);
        const double e = 0.5 * m * (s->vx[i] * s->vx[i] + s->vy[i] * s->vy[i]);
        const double spin = 0.5 * in * s->w[i] * s->w[i];
        const double g = m * (s->g[0] * s->x[i] + s->g[1] * s->y[i]);
        const double weight = m * hypot(s->g[0], s->g[1]);
        char where[3 * BAL_NAME_MAX + 600];
        const char *what = NULL;
        enum bal_disc_prop prop = BAL_DISC_SIZE;
        if (!(m > 0 && isfinite(m) && isfinite(s->inv_m[i])))
            what = "its mass, density x pi r^2, is not a positive finite number (the radius "
                   "or the material's density is too small or too large)";
        else if (!(in > 0 && isfinite(in) && isfinite(s->inv_i[i])))
            what = "its moment of inertia m r^2/2 is not a positive finite number (the radius or "
                   "the material's density is too small or too large)";
        else if (!isfinite(e) || !isfinite(ek + e))
            what = "its kinetic energy m |v|^2/2 (or the scene's total) overflows a double",
            prop = BAL_DISC_SPEED;
        else if (!isfinite(spin) || !isfinite(ek + e + spin))
            what = "its rotational energy I omega^2/2 (or the scene's total) overflows a double",
            prop = BAL_DISC_SPIN;
        else if (!isfinite(g) || !isfinite(weight) || (!s->fixed[i] && !isfinite(eg + g)))
            what = "its weight m g or its gravity potential m g.x (or the scene's total) "
                   "overflows a double",
            prop = BAL_DISC_PLACE;
        if (what) {
            bal_specimen_disc_origin(sc, s->id[i], prop, where, sizeof where);
            return bal_error(err, BAL_EINVAL, "%s: %s", where, what);
        }
        ek += e + spin;
        if (!s->fixed[i])
            eg += g;
    }
    return BAL_OK;
}

enum bal_status bal_build_discs(struct bal_sim *s, struct bal_error *err)
{
    const struct bal_scene *sc = s->scene;
    const struct bal_settings *st = &sc->settings;
    const int n = s->n;
    struct bal_specimen d = {0};
    if (bal_specimen_generate(sc, n, &d, err)) {
        bal_specimen_free(&d);
        return err->code;
    }
    s->r_max = 0;
    for (int i = 0; i < n; i++)
        s->r_max = fmax(s->r_max, d.r[i]);
    s->use_grid = st->grid == BAL_GRID_ON || (st->grid == BAL_GRID_AUTO && n >= BAL_GRID_CROSSOVER);
    s->skin = st->skin > 0 ? st->skin : SKIN_SHARE_OF_RMAX * s->r_max;
    s->skin_rule = st->skin_rule;
    double r_min = INFINITY;
    for (int i = 0; i < n; i++)
        r_min = fmin(r_min, d.r[i]);
    s->r_min = r_min;
    s->overlap_sieve = s->overlap_budget * r_min; /* INFINITY when the budget is off */

    int ok = 1;
    double **arrays[] = {&s->x, &s->y, &s->th, &s->vx, &s->vy, &s->w, &s->r,
                         &s->inv_m, &s->inv_i, &s->x_ref, &s->y_ref};
    for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; k++)
        *arrays[k] = alloc_doubles((size_t)n, &ok);
    s->f = alloc_doubles(3 * (size_t)n, &ok);
    if (s->has_damping) {
        const size_t nf = (size_t)(n ? n : 1);
        s->dash = calloc(3 * nf, sizeof *s->dash);
        ok = ok && s->dash;
    }
    s->density = alloc_doubles((size_t)s->n_mat, &ok);
    for (int m = 0; ok && m < s->n_mat; m++)
        s->density[m] = sc->materials[m].density;
    s->id = calloc((size_t)(n ? n : 1), sizeof *s->id);
    s->slot = calloc((size_t)(n ? n : 1), sizeof *s->slot);
    s->mat = calloc((size_t)(n ? n : 1), sizeof *s->mat);
    s->fixed = calloc((size_t)(n ? n : 1), sizeof *s->fixed);
    int partly_held = 0;
    for (int i = 0; i < n; i++)
        partly_held |= d.hold[i] != 0;
    s->hold = partly_held ? calloc((size_t)n, sizeof *s->hold) : NULL;
    s->grid.cell = calloc((size_t)(n ? n : 1), sizeof *s->grid.cell);
    s->grid.list = calloc((size_t)(n ? n : 1), sizeof *s->grid.list);
    s->row = sc->n_piles ? calloc((size_t)(n ? n : 1), sizeof *s->row) : NULL;
    int stress_rule = 0;
    for (int g = 0; g < sc->n_stages; g++)
        stress_rule |= sc->stages[g].stop_stress > 0;
    s->moment = stress_rule ? calloc((size_t)(4 * n + 4), sizeof *s->moment) : NULL;
    s->moment_prev = stress_rule ? calloc((size_t)(4 * n + 4), sizeof *s->moment_prev) : NULL;
    s->new2old = calloc((size_t)(n ? n : 1), sizeof *s->new2old);
    if (!ok || !s->id || !s->slot || !s->mat || !s->fixed || (partly_held && !s->hold) ||
        !s->grid.cell || !s->grid.list ||
        (sc->n_piles && !s->row) || (stress_rule && (!s->moment || !s->moment_prev)) || !s->new2old) {
        bal_specimen_free(&d);
        return bal_error(err, BAL_ENOMEM, "%s: out of memory for %d discs", sc->path, n);
    }
    if (s->use_grid) {
        struct bal_cell_key *keys = malloc((size_t)n * sizeof *keys);
        if (!keys) {
            bal_specimen_free(&d);
            return bal_error(err, BAL_ENOMEM, "%s: out of memory", sc->path);
        }
        bal_grid_cell_order(d.x, d.y, n, 2 * s->r_max + s->skin, keys, s->id);
        free(keys);
    } else {
        for (int i = 0; i < n; i++)
            s->id[i] = i;
    }
    for (int i = 0; i < n; i++) {
        const int k = s->id[i];
        s->slot[k] = i;
        s->x[i] = d.x[k];
        s->y[i] = d.y[k];
        s->r[i] = d.r[k];
        s->vx[i] = d.vx[k];
        s->vy[i] = d.vy[k];
        s->th[i] = d.th[k];
        s->w[i] = d.w[k];
        s->mat[i] = d.mat[k];
        s->fixed[i] = d.fixed[k];
        if (s->hold)
            s->hold[i] = d.hold[k];
        if (s->row)
            s->row[i] = d.row[k];
        s->inv_m[i] = 1 / bal_mass(s, i);
        s->inv_i[i] = 1 / bal_inertia(s, i);
    }
    bal_specimen_free(&d);
    s->disc_law = n > 0 ? &s->law[s->mat[0] * s->n_mat + s->mat[0]] : NULL;
    for (int i = 1; i < n && s->disc_law; i++)
        if (s->mat[i] != s->mat[0])
            s->disc_law = NULL;

    return check_derived(s, err);
}

/* The kinetic energy at the start when nothing can feed the scene more
 * (no gravity, no wall moved in any stage, no overlap allowed at the
 * start), else 0 (no bound).  A wall that a controller other than the
 * prescribed one drives may move. */
static double start_energy(const struct bal_sim *s, const struct bal_scene *sc)
{
    if (s->g[0] != 0 || s->g[1] != 0 || sc->settings.allow_overlap)
        return 0;
    for (int g = 0; g < sc->n_stages; g++)
        for (int m = 0; m < sc->stages[g].n_moves; m++) {
            const struct bal_move_def *mv = &sc->stages[g].moves[m];
            if (mv->control != BAL_CONTROL_PRESCRIBED || mv->v[0] != 0 || mv->v[1] != 0 ||
                mv->omega != 0)
                return 0;
        }
    double e = 0, px = 0, py = 0, m = 0;
    int held = 0;
    for (int i = 0; i < s->n; i++) {
        held |= s->fixed[i] || (s->hold && s->hold[i]);
        if (s->fixed[i])
            continue;
        const double mi = bal_mass(s, i);
        e += 0.5 * mi * (s->vx[i] * s->vx[i] + s->vy[i] * s->vy[i]) +
             0.5 * bal_inertia(s, i) * s->w[i] * s->w[i];
        px += mi * s->vx[i];
        py += mi * s->vy[i];
        m += mi;
    }
    /* Without walls or held discs (partly held ones included) the momentum
     * is conserved: the motion of the centre of mass can never go into a
     * contact. */
    if (!held && s->n_walls == 0 && m > 0)
        e -= 0.5 * (px * px + py * py) / m;
    return e > 0 ? e : 0;
}

enum bal_status bal_build_timestep(struct bal_sim *s, struct bal_error *err)
{
    const struct bal_scene *sc = s->scene;
    const struct bal_settings *st = &sc->settings;
    s->start_energy = start_energy(s, sc);
    struct bal_dt_detail dd;
    bal_timestep_detail(s, &dd);
    s->dt_estimate = dd.estimate;
    s->dt = st->dt > 0 ? st->dt : st->dt_fraction * s->dt_estimate;
    if (!(s->dt > 0 && isfinite(s->dt) && s->dt_estimate > 0 && isfinite(s->dt_estimate))) {
        /* The masses are finite and positive (check_derived), so the step
         * or its estimate (which run.json writes, and dt_fraction divides
         * by) leaves the doubles only through the stiffness: name the
         * material of the disc that sets the estimate. */
        const int id = dd.binding_disc >= 0 ? dd.binding_disc : 0;
        const struct bal_material_def *m = &sc->materials[s->mat[s->slot[id]]];
        const int ki = bal_scene_key_index(BAL_SEC_MATERIAL, "kn");
        char disc[2 * BAL_NAME_MAX];
        bal_specimen_disc_name(sc, id, disc, sizeof disc);
        return bal_error(err, BAL_EINVAL,
                         "%s:%d: kn: [material %s]: the time step %g or its estimate %g (for "
                         "disc %s) is not a positive finite number; expected a stiffness whose "
                         "ratio to the masses is within the range of a double",
                         sc->path, m->key_line[ki] > 0 ? m->key_line[ki] : m->line, m->name, s->dt,
                         dd.estimate, disc);
    }
    if (!isfinite(s->dt / s->dt_estimate))
        /* Only a forced step can be this large. */
        return bal_error(err, BAL_EINVAL,
                         "%s:%d: dt: the time step %g is beyond %g times the stability estimate; "
                         "expected a step whose ratio to the estimate is a finite number",
                         sc->path, st->key_line[bal_scene_key_index(BAL_SEC_SETTINGS, "dt")], st->dt,
                         DBL_MAX);
    if (!(s->alpha * s->dt < 2))
        /* Global damping -alpha m v over a step alpha dt >= 2 reverses the
         * velocity (the centred update's factor 1 - alpha dt/2 <= 0) and the
         * velocity at t_N can no longer be recovered (a division by it). */
        return bal_error(err, BAL_EINVAL,
                         "%s:%d: alpha: global damping alpha = %s with the time step %s gives "
                         "alpha dt = %s; expected alpha dt < 2 (alpha < %s)",
                         sc->path, st->key_line[bal_scene_key_index(BAL_SEC_SETTINGS, "alpha")],
                         BAL_NUM(st->alpha), BAL_NUM(s->dt), BAL_NUM(s->alpha * s->dt),
                         BAL_NUM(2 / s->dt));
    if (s->dt >= s->dt_estimate && !st->force_dt) {
        const char *key = st->dt > 0 ? "dt" : "dt_fraction";
        const int line = st->key_line[bal_scene_key_index(BAL_SEC_SETTINGS, key)];
        char where[32] = ""; /* no line: the key was not given (its default) */
        if (line > 0)
            snprintf(where, sizeof where, ":%d", line);
        return bal_error(err, BAL_EINVAL,
                         "%s%s: %s: the time step %s is at or above the stability estimate "
                         "%s (bin/ballast info); expected a smaller one, or settings.force_dt "
                         "= 1 to run it anyway", sc->path, where, key, BAL_NUM(s->dt),
                         BAL_NUM(s->dt_estimate));
    }
    return BAL_OK;
}

/* Touching within this share of the smaller radius is contact, not an
 * overlap (the text a run writes, %.17g, comes back to within an ulp). */
#define TOUCH_SHARE 1e-9

/* The overlap of disc slot i with disc slot j (wall = 0) or wall j, for
 * check_overlaps' message: "FILE:LINE: KEY: disc A: overlaps disc B by
 * ...", from the line that placed the free disc. */
static enum bal_status overlap_error(const struct bal_sim *s, int i, int j, int wall,
                                     double delta, double rmin, struct bal_error *err)
{
    char a[2 * BAL_NAME_MAX], b[3 * BAL_NAME_MAX];
    bal_specimen_disc_name(s->scene, s->id[i], a, sizeof a);
    if (wall) {
        snprintf(b, sizeof b, "wall %s", s->walls[j].name);
    } else {
        char d[2 * BAL_NAME_MAX];
        bal_specimen_disc_name(s->scene, s->id[j], d, sizeof d);
        snprintf(b, sizeof b, "disc %s", d);
    }
    if (s->fixed[i]) /* name the free disc first */
        snprintf(b, sizeof b, "disc %s", a);
    /* Where the (free) disc was placed is where the overlap was written. */
    char where[3 * BAL_NAME_MAX + 600];
    bal_specimen_disc_origin(s->scene, s->id[s->fixed[i] ? j : i], BAL_DISC_PLACE, where,
                             sizeof where);
    return bal_error(err, BAL_EINVAL,
                     "%s: overlaps %s by %.6g (%.3g of the smaller radius) at the start; "
                     "expected bodies apart or touching, or settings.allow_overlap = 1",
                     where, b, delta, delta / rmin);
}

/* Bodies that overlap at the start are refused unless the scene allows it:
 * an overlap nobody meant is a typo, and it starts the run with energy the
 * scene never declared.  Two held discs may overlap (they never move: MLH's
 * bumpy bottoms with c < 0); touching within 1e-9 of the radius is contact. */
static enum bal_status check_overlaps(const struct bal_sim *s, struct bal_error *err)
{
    if (s->scene->settings.allow_overlap)
        return BAL_OK;
    for (int walls = 0; walls < 2; walls++) {
        const struct bal_pairs *p = walls ? &s->pw : &s->pp;
        for (long c = 0; c < p->n; c++) {
            const int i = p->i[c], j = p->j[c];
            if (s->fixed[i] && (walls || s->fixed[j]))
                continue;
            double rmin;
            const struct bal_pair_law *law;
            const double delta = bal_pairs_overlap(s, walls, c, &rmin, &law);
            if (delta > TOUCH_SHARE * rmin)
                return overlap_error(s, i, j, walls, delta, rmin, err);
        }
    }
    return BAL_OK;
}

/* The first rebuild failed on disc slot i, with more candidates than the
 * lists hold (BAL_MAX_NEIGHBOURS, grid.c).  At the start that is the
 * scene's doing, and bad input: discs piled on one another (600 imported
 * discs at one point, say), refused as any overlap at the start is, with
 * the first body in slot order that i overlaps (check_overlaps never ran:
 * it reads the lists that could not be built); or, where nothing overlaps,
 * radii too far apart for the lists (a disc of r_min cannot have that many
 * neighbours within 2 r_max + skin otherwise), named at the disc's line. */
static enum bal_status crowded_at_start(const struct bal_sim *s, int i, struct bal_error *err)
{
    if (!s->scene->settings.allow_overlap) {
        for (int j = 0; j < s->n; j++) {
            if (j == i || (s->fixed[i] && s->fixed[j]))
                continue;
            const double rmin = fmin(s->r[i], s->r[j]);
            const double delta = s->r[i] + s->r[j] - hypot(s->x[j] - s->x[i], s->y[j] - s->y[i]);
            if (delta > TOUCH_SHARE * rmin)
                return overlap_error(s, i < j ? i : j, i < j ? j : i, 0, delta, rmin, err);
        }
        for (int k = 0; k < s->n_walls && !s->fixed[i]; k++) {
            double cx, cy;
            const double delta =
                s->r[i] - sqrt(bal_walls_closest(&s->walls[k], s->x[i], s->y[i], &cx, &cy));
            if (delta > TOUCH_SHARE * s->r[i])
                return overlap_error(s, i, k, 1, delta, s->r[i], err);
        }
    }
    char where[3 * BAL_NAME_MAX + 600];
    bal_specimen_disc_origin(s->scene, s->id[i], s->scene->settings.allow_overlap ? BAL_DISC_PLACE
                             : BAL_DISC_SIZE, where, sizeof where);
    return bal_error(err, BAL_EINVAL,
                     "%s: has more than %d neighbours within reach at the start, more than the "
                     "neighbour lists hold; expected fewer discs within r + r_max + skin of one "
                     "(r_min %.6g, r_max %.6g, skin %.6g): discs apart, radii closer to each "
                     "other or a smaller settings.skin",
                     where, BAL_MAX_NEIGHBOURS, s->r_min, s->r_max, s->skin);
}

enum bal_status bal_build_lists(struct bal_sim *s, struct bal_error *err)
{
    /* The rolling law runs in the variants with the tangential kernel (it
     * reads the spins those read), so a scene with rolling resistance gets
     * them even without friction; a frictionless pair skips the tangential
     * kernel inside them (L->shear). */
    s->pp.shear = (uint8_t)(s->has_shear || s->has_rolling);
    s->pp.damping = 0; /* disc-pair dashpots are recomputed for reports */
    s->pp.rolling = (uint8_t)s->has_rolling;
    s->pw.shear = 1;
    s->pw.damping = 1;
    s->pw.rolling = (uint8_t)s->has_rolling;
    s->pair_loop = bal_pair_loop_select(s->normal_law, s->has_shear || s->has_rolling,
                                        s->has_damping, s->has_rolling);
    if (bal_grid_rebuild(s, err))
        return s->crowded ? crowded_at_start(s, s->crowded - 1, err) : err->code;
    return check_overlaps(s, err);
}

static enum bal_status resolve_body(const struct bal_sim *s, const struct bal_scene *sc,
                                    const char *name, int *is_wall, int *index)
{
    char why[BAL_MSG_MAX / 2];
    const long i = bal_specimen_find_disc(sc, name, why, sizeof why);
    if (i >= 0 && i < s->n) {
        *is_wall = 0;
        *index = s->slot[i];
        return BAL_OK;
    }
    int k = bal_walls_find(s, name);
    if (k >= 0) {
        *is_wall = 1;
        *index = k;
        return BAL_OK;
    }
    return BAL_EINVAL;
}

enum bal_status bal_build_probes(struct bal_sim *s, struct bal_error *err)
{
    const struct bal_scene *sc = s->scene;
    s->n_probes = sc->n_probes;
    s->probes = calloc((size_t)(sc->n_probes ? sc->n_probes : 1), sizeof *s->probes);
    s->row_values = calloc((size_t)(sc->n_probes ? sc->n_probes : 1), sizeof *s->row_values);
    if (!s->probes || !s->row_values)
        return bal_error(err, BAL_ENOMEM, "%s: out of memory", sc->path);
    for (int p = 0; p < sc->n_probes; p++) {
        const struct bal_probe_def *pd = &sc->probes[p];
        struct bal_probe_ref *pr = &s->probes[p];
        pr->kind = pd->kind;
        if (*pd->a && resolve_body(s, sc, pd->a, &pr->a_wall, &pr->a))
            return bal_error(err, BAL_EINVAL, "%s:%d: a: no body '%s'", sc->path, pd->line, pd->a);
        if (*pd->b && resolve_body(s, sc, pd->b, &pr->b_wall, &pr->b))
            return bal_error(err, BAL_EINVAL, "%s:%d: b: no body '%s'", sc->path, pd->line, pd->b);
    }
    return BAL_OK;
}

enum bal_status bal_build_stages(struct bal_sim *s, struct bal_error *err)
{
    const struct bal_scene *sc = s->scene;
    s->log = calloc((size_t)(sc->n_stages ? sc->n_stages : 1), sizeof *s->log);
    if (!s->log)
        return bal_error(err, BAL_ENOMEM, "%s: out of memory", sc->path);
    for (int g = 0; g < sc->n_stages; g++) {
        const struct bal_stage_def *st = &sc->stages[g];
        s->log[g] = (struct bal_stage_log){0, 0, -1, -1, -1, -1, st->cycles, 0};
        if (st->given & (1u << bal_scene_key_index(BAL_SEC_STAGE, "time"))) {
            /* ceil to 1e-9 of a step: time = 0.3 with dt = 0.1 is 3 cycles,
             * not 4 because 0.3/0.1 = 3.0000000000000004. */
            const double n = ceil(st->time / s->dt - 1e-9);
            const int ki = bal_scene_key_index(BAL_SEC_STAGE, "time");
            if (!(n <= 1e15))
                return bal_error(err, BAL_EINVAL,
                                 "%s:%d: time: [stage %s]: time %s with the time step %s is %s "
                                 "cycles; expected at most 1e15", sc->path,
                                 st->key_line[ki] > 0 ? st->key_line[ki] : st->line, st->name,
                                 BAL_NUM(st->time), BAL_NUM(s->dt), BAL_NUM(st->time / s->dt));
            s->log[g].max_cycles = n > 0 ? (long)n : 0;
            s->log[g].in_time = 1;
        }
        /* A strain rate whose step rate dt reaches 1 would carry the wall
         * onto (or past) the other in one cycle (walls.c). */
        for (int m = 0; m < sc->stages[g].n_moves; m++) {
            const struct bal_move_def *mv = &sc->stages[g].moves[m];
            if (mv->control == BAL_CONTROL_STRAIN_RATE && !(mv->rate * s->dt < 1))
                return bal_error(err, BAL_EINVAL,
                                 "%s:%d: strain_rate: rate %s with the time step %s gives rate "
                                 "dt = %s; expected rate dt < 1 (the gap shrinks by 1 - rate dt "
                                 "a cycle)", sc->path, mv->line > 0 ? mv->line : sc->stages[g].line,
                                 BAL_NUM(mv->rate), BAL_NUM(s->dt), BAL_NUM(mv->rate * s->dt));
        }
    }
    s->stage = -1; /* none yet: bal_sim_run or bal_sim_step selects the first */
    s->gfac = 1;
    return BAL_OK;
}
