/*
 * scene_validate.c — what a scene must satisfy as a whole, checked once
 * before a simulation is built from it (bal_scene_validate).
 *
 * The parser (scene.c) has checked each value against its key's type and
 * range; here come the checks that need more than one line: required keys,
 * references to other sections (materials, walls, bodies of probes and
 * moves), names that two bodies would share, settings that need another
 * (delta0 with the power law or psi), and a scene that would do nothing (no
 * stage, no disc).  Every message names the file, the line and the key, and
 * says what was expected.
 */
#include <stdio.h>
#include <string.h>

#include "import.h"
#include "scene.h"
#include "specimen.h"
#include "status.h"
#include "walls.h"

static int line_of(void *item, enum bal_section_kind k, const char *key)
{
    int ki = bal_scene_key_index(k, key);
    int l = ki >= 0 ? bal_scene_item_key_line(item, k)[ki] : 0;
    return l > 0 ? l : *bal_scene_item_line(item);
}

/* FAIL_AT(item, kind, key, fmt, args...): at least one argument after fmt. */
#define FAIL_AT(item, k, key, fmt, ...) \
    bal_error(err, BAL_EINVAL, "%s:%d: %s: " fmt, s->path, line_of(item, k, key), key, __VA_ARGS__)

static enum bal_status check_required(const struct bal_scene *s, enum bal_section_kind k,
                                      struct bal_error *err)
{
    int n = bal_scene_count(s, k);
    for (int i = 0; i < n; i++) {
        void *item = bal_scene_section(s, k, i);
        uint32_t given = *bal_scene_item_given(item, k);
        for (int ki = 0;; ki++) {
            const struct bal_key *key = bal_scene_key_at(k, ki);
            if (!key)
                break;
            if (key->required && !(given & (1u << ki))) {
                int line = k == BAL_SEC_SETTINGS ? s->settings.key_line[BAL_KEYS_MAX - 1]
                                                 : *bal_scene_item_line(item);
                return bal_error(err, BAL_EINVAL, "%s:%d: [%s %s]: %s: required key is missing (%s)",
                                 s->path, line, bal_scene_sections[k].name,
                                 k == BAL_SEC_SETTINGS ? "" : bal_scene_item_name(item), key->name,
                                 key->doc);
            }
        }
    }
    return BAL_OK;
}

static enum bal_status check_material_ref(const struct bal_scene *s, void *item,
                                          enum bal_section_kind k, const char *key,
                                          const char *value, int need_density,
                                          struct bal_error *err)
{
    int m = bal_scene_find(s, BAL_SEC_MATERIAL, value);
    if (m < 0)
        return FAIL_AT(item, k, key, "no [material %s] in the scene", value);
    if (need_density && !(s->materials[m].density > 0))
        return FAIL_AT(item, k, key,
                       "material '%s' has no density > 0, which a disc needs for its mass",
                       value);
    return BAL_OK;
}

static const char *const box_sides[] = {"_bottom", "_right", "_top", "_left"};

/* Is `name` a wall a generator makes: a boxed [fill]'s or [grains]'s, a
 * smooth [pile]'s floor, an [import]'s?  Its header line into *line. */
static int generated_wall(const struct bal_scene *s, const char *name, int *line)
{
    for (int k = 0; k < s->n_fills + s->n_grains; k++) {
        const int fill = k < s->n_fills;
        const char *sec = fill ? s->fills[k].name : s->grains[k - s->n_fills].name;
        if (!(fill ? s->fills[k].box : s->grains[k - s->n_fills].box))
            continue;
        for (int side = 0; side < 4; side++) {
            char nm[2 * BAL_NAME_MAX];
            snprintf(nm, sizeof nm, "%s%s", sec, box_sides[side]);
            if (strcmp(nm, name) == 0) {
                *line = fill ? s->fills[k].line : s->grains[k - s->n_fills].line;
                return 1;
            }
        }
    }
    for (int p = 0; p < s->n_piles; p++) {
        char nm[2 * BAL_NAME_MAX];
        snprintf(nm, sizeof nm, "%s_floor", s->piles[p].name);
        if (s->piles[p].bottom == 0 && strcmp(nm, name) == 0) {
            *line = s->piles[p].line;
            return 1;
        }
    }
    for (int i = 0; i < s->n_imports; i++)
        for (int k = 0; k < s->imports[i].n_walls; k++)
            if (strcmp(s->imports[i].wall_data[k].name, name) == 0) {
                *line = s->imports[i].line;
                return 1;
            }
    return 0;
}

/* Is `name` a disc (NAME.k for a generator's, specimen.c), a wall, or a
 * wall a generator makes? */
static int body_exists(const struct bal_scene *s, const char *name, int *is_wall)
{
    char why[BAL_MSG_MAX / 2];
    if (bal_specimen_find_disc(s, name, why, sizeof why) >= 0) {
        *is_wall = 0;
        return 1;
    }
    int line;
    if (bal_scene_find(s, BAL_SEC_WALL, name) >= 0 || generated_wall(s, name, &line)) {
        *is_wall = 1;
        return 1;
    }
    return 0;
}

/* Why no body has this name ("no disc or wall named 'x'", or what is
 * wrong with a NAME.k), into why. */
static const char *no_body(const struct bal_scene *s, const char *name, char *why, size_t size)
{
    (void)bal_specimen_find_disc(s, name, why, size);
    return why;
}

/* Probes and moves find bodies by name, so a disc, a wall and the walls a
 * generator makes (fill and grains boxes, smooth pile floors, imports) must
 * not share one (else the first found wins silently; seen by reading, while
 * fuzzing). */
static enum bal_status check_body_names(const struct bal_scene *s, struct bal_error *err)
{
    for (int i = 0; i < s->n_walls; i++)
        if (bal_scene_find(s, BAL_SEC_DISC, s->walls[i].name) >= 0)
            return bal_error(err, BAL_EINVAL, "%s:%d: [wall %s]: a disc has this name too; "
                             "probes and moves need one body per name",
                             s->path, s->walls[i].line, s->walls[i].name);
    /* Each generated wall against the named bodies and the generated walls
     * before it: the sections in file order of their kinds, as the builder
     * makes them. */
    char seen_name[2 * BAL_NAME_MAX];
    for (int pass = 0; pass < 4; pass++) {
        const int count = pass == 0 ? s->n_fills : pass == 1 ? s->n_piles
                        : pass == 2 ? s->n_grains : s->n_imports;
        for (int k = 0; k < count; k++) {
            const char *kind = pass == 0 ? "fill" : pass == 1 ? "pile" : pass == 2 ? "grains" : "import";
            const char *name = pass == 0 ? s->fills[k].name : pass == 1 ? s->piles[k].name
                             : pass == 2 ? s->grains[k].name : s->imports[k].name;
            const int line = pass == 0 ? s->fills[k].line : pass == 1 ? s->piles[k].line
                           : pass == 2 ? s->grains[k].line : s->imports[k].line;
            int n_made = 0;
            if (pass == 0 || pass == 2)
                n_made = (pass == 0 ? s->fills[k].box : s->grains[k].box) ? 4 : 0;
            else if (pass == 1)
                n_made = s->piles[k].bottom == 0;
            else
                n_made = s->imports[k].n_walls;
            for (int w = 0; w < n_made; w++) {
                if (pass == 3)
                    snprintf(seen_name, sizeof seen_name, "%s", s->imports[k].wall_data[w].name);
                else
                    snprintf(seen_name, sizeof seen_name, "%s%s", name,
                             pass == 1 ? "_floor" : box_sides[w]);
                int clash = bal_scene_find(s, BAL_SEC_DISC, seen_name) >= 0 ||
                            bal_scene_find(s, BAL_SEC_WALL, seen_name) >= 0;
                /* ... or a generated wall made before it */
                int first_line = 0;
                struct bal_scene before = *s;
                before.n_fills = pass == 0 ? k : s->n_fills;
                before.n_piles = pass < 1 ? 0 : pass == 1 ? k : s->n_piles;
                before.n_grains = pass < 2 ? 0 : pass == 2 ? k : s->n_grains;
                before.n_imports = pass < 3 ? 0 : k;
                clash |= generated_wall(&before, seen_name, &first_line);
                if (!clash && pass == 3)
                    for (int q = 0; q < w; q++)
                        clash |= strcmp(s->imports[k].wall_data[q].name, seen_name) == 0;
                if (clash)
                    return bal_error(err, BAL_EINVAL, "%s:%d: [%s %s]: makes a wall '%s', but a "
                                     "disc or wall has that name already",
                                     s->path, line, kind, name, seen_name);
            }
        }
    }
    return BAL_OK;
}

void bal_scene_settings_where(const struct bal_scene *s, const char *key, char *buf, size_t size)
{
    const int line = s->settings.key_line[bal_scene_key_index(BAL_SEC_SETTINGS, key)];
    if (line > 0)
        snprintf(buf, size, "%s:%d: %s", s->path, line, key);
    else
        snprintf(buf, size, "%s: --set %s", s->path, key);
}

/* Snapshots are taken every so many cycles or every so much simulated time, not both; the
 * VTK files are written at the snapshots' frames, so vtk = 1 needs one of the two. */
static enum bal_status check_snapshots(const struct bal_scene *s, struct bal_error *err)
{
    const struct bal_settings *st = &s->settings;
    char where[BAL_PATH_MAX + 64], other[BAL_PATH_MAX + 64];
    if (st->snapshot_every > 0 && st->snapshot_dt > 0) {
        bal_scene_settings_where(s, "snapshot_dt", where, sizeof where);
        bal_scene_settings_where(s, "snapshot_every", other, sizeof other);
        return bal_error(err, BAL_EINVAL,
                         "%s: snapshots every %s of simulated time and every %ld cycles (%s): "
                         "give one of snapshot_every and snapshot_dt, the other 0",
                         where, BAL_NUM(st->snapshot_dt), st->snapshot_every, other);
    }
    if (st->vtk && st->snapshot_every == 0 && st->snapshot_dt == 0) {
        bal_scene_settings_where(s, "vtk", where, sizeof where);
        return bal_error(err, BAL_EINVAL,
                         "%s: vtk = 1 needs snapshots: give snapshot_every (cycles) or "
                         "snapshot_dt (simulated time); the VTK files are written at their frames",
                         where);
    }
    return BAL_OK;
}

enum bal_status bal_scene_validate(const struct bal_scene *s, struct bal_error *err)
{
    for (int k = 0; k < BAL_SEC_COUNT; k++)
        if (check_required(s, (enum bal_section_kind)k, err))
            return err->code;

    const struct bal_settings *st = &s->settings;
    const int delta0_given = (st->given & (1u << bal_scene_key_index(BAL_SEC_SETTINGS, "delta0"))) != 0;
    if (st->normal_law == BAL_NORMAL_POWER && st->nu != 1.0 && !delta0_given)
        return bal_error(err, BAL_EINVAL,
                         "%s:%d: delta0: required with normal_law = power and nu != 1 "
                         "(the force scale k_n delta0 depends on it)",
                         s->path, st->key_line[bal_scene_key_index(BAL_SEC_SETTINGS, "nu")]);
    if (st->gamma_n > 0 && st->psi != 0 && !delta0_given)
        return bal_error(err, BAL_EINVAL,
                         "%s:%d: delta0: required with psi != 0 (the dashpot "
                         "gamma_n (delta/delta0)^psi depends on it, MLH eq. 3)",
                         s->path, st->key_line[bal_scene_key_index(BAL_SEC_SETTINGS, "psi")]);

    if (check_snapshots(s, err))
        return err->code;

    for (int i = 0; i < s->n_discs; i++) {
        struct bal_disc_def *d = &s->discs[i];
        if (check_material_ref(s, d, BAL_SEC_DISC, "material", d->material, 1, err))
            return err->code;
        if (d->fixed && (d->v[0] != 0 || d->v[1] != 0 || d->omega != 0))
            return FAIL_AT(d, BAL_SEC_DISC, "fixed", "%s",
                           "a held disc cannot have a velocity (v and omega must be 0)");
        if (((d->hold & BAL_HOLD_X) && d->v[0] != 0) || ((d->hold & BAL_HOLD_Y) && d->v[1] != 0) ||
            ((d->hold & BAL_HOLD_ROTATION) && d->omega != 0))
            return FAIL_AT(d, BAL_SEC_DISC, "hold", "%s",
                           "a held component cannot have a velocity (v1 with x, v2 with y, omega "
                           "with rotation must be 0)");
    }
    for (int i = 0; i < s->n_walls; i++) {
        struct bal_wall_def *w = &s->walls[i];
        if (!(w->h2 > w->h1))
            return FAIL_AT(w, BAL_SEC_WALL, "h2", "expected h2 > h1 (a wall of positive length), "
                                                  "got h1 = %s, h2 = %s", BAL_NUM(w->h1), BAL_NUM(w->h2));
        if (check_material_ref(s, w, BAL_SEC_WALL, "material", w->material, 0, err))
            return err->code;
    }
    for (int i = 0; i < s->n_fills; i++) {
        struct bal_fill_def *f = &s->fills[i];
        if (!(f->rmax >= f->rmin))
            return FAIL_AT(f, BAL_SEC_FILL, "rmax", "expected rmax >= rmin, got %s < %s",
                           BAL_NUM(f->rmax), BAL_NUM(f->rmin));
        if (check_material_ref(s, f, BAL_SEC_FILL, "material", f->material, 1, err))
            return err->code;
        if (f->box) {
            if (!*f->wall_material)
                return FAIL_AT(f, BAL_SEC_FILL, "wall_material", "%s", "required with box = 1");
            if (check_material_ref(s, f, BAL_SEC_FILL, "wall_material", f->wall_material, 0, err))
                return err->code;
        }
    }
    for (int i = 0; i < s->n_piles; i++) {
        struct bal_pile_def *p = &s->piles[i];
        if (check_material_ref(s, p, BAL_SEC_PILE, "material", p->material, 1, err))
            return err->code;
        if (!(p->size_spread < 1))
            return FAIL_AT(p, BAL_SEC_PILE, "size_spread", "expected 0 <= size_spread < 1 "
                           "(diameters d (1 + r), |r| <= size_spread/2), got %s", BAL_NUM(p->size_spread));
        if (p->bottom == 0) {
            if (!*p->wall_material)
                return FAIL_AT(p, BAL_SEC_PILE, "wall_material", "%s",
                               "required with bottom = smooth (the floor's material)");
            if (check_material_ref(s, p, BAL_SEC_PILE, "wall_material", p->wall_material, 0, err))
                return err->code;
            if (p->L < 3)
                return FAIL_AT(p, BAL_SEC_PILE, "L", "%s",
                               "a smooth bottom needs L >= 3 (two corner stones and a free disc)");
        }
    }
    for (int i = 0; i < s->n_grains; i++) {
        struct bal_grains_def *g = &s->grains[i];
        /* The grading curve rises: dmin <= d10 <= d50 <= d60 <= dmax. */
        const double d[5] = {g->dmin, g->d10, g->d50, g->d60, g->dmax};
        static const char *const names[5] = {"dmin", "d10", "d50", "d60", "dmax"};
        for (int k = 1; k < 5; k++)
            if (!(d[k] >= d[k - 1]))
                return FAIL_AT(g, BAL_SEC_GRAINS, names[k],
                               "expected dmin <= d10 <= d50 <= d60 <= dmax (the share finer "
                               "by area rises with d), got %s = %s < %s = %s",
                               names[k], BAL_NUM(d[k]), names[k - 1], BAL_NUM(d[k - 1]));
        if (!(g->size[0] >= g->dmax && g->size[1] >= g->dmax))
            return FAIL_AT(g, BAL_SEC_GRAINS, "size",
                           "the region %s x %s must be at least dmax = %s wide and high",
                           BAL_NUM(g->size[0]), BAL_NUM(g->size[1]), BAL_NUM(g->dmax));
        const char *key = NULL;
        char why[BAL_MSG_MAX / 2];
        if (bal_specimen_grains_check(g, &key, why, sizeof why))
            return FAIL_AT(g, BAL_SEC_GRAINS, key, "%s", why);
        if (check_material_ref(s, g, BAL_SEC_GRAINS, "material", g->material, 1, err))
            return err->code;
        if (g->box) {
            if (!*g->wall_material)
                return FAIL_AT(g, BAL_SEC_GRAINS, "wall_material", "%s", "required with box = 1");
            if (check_material_ref(s, g, BAL_SEC_GRAINS, "wall_material", g->wall_material, 0, err))
                return err->code;
        }
    }
    for (int i = 0; i < s->n_imports; i++) {
        struct bal_import_def *m = &s->imports[i];
        if (check_material_ref(s, m, BAL_SEC_IMPORT, "material", m->material, 1, err))
            return err->code;
        if (*m->walls) {
            if (!*m->wall_material)
                return FAIL_AT(m, BAL_SEC_IMPORT, "wall_material", "%s",
                               "required with walls (the imported walls' material)");
            if (check_material_ref(s, m, BAL_SEC_IMPORT, "wall_material", m->wall_material, 0, err))
                return err->code;
        }
        if (m->velocities && !bal_import_has_velocities(m))
            return FAIL_AT(m, BAL_SEC_IMPORT, "velocities",
                           "the discs file %s has no columns vx, vy, omega to start from", m->discs);
    }
    for (int i = 0; i < s->n_materials; i++) {
        struct bal_material_def *m = &s->materials[i];
        if (!(m->ks >= 1e-150 || m->ks == -1))
            return FAIL_AT(m, BAL_SEC_MATERIAL, "ks", "expected ks >= 1e-150, like kn (or omit it "
                                                      "for ks = kn), got %s", BAL_NUM(m->ks));
    }
    if (check_body_names(s, err))
        return err->code;
    if (s->n_stages == 0)
        return bal_error(err, BAL_EINVAL, "%s: no [stage] section: the run would never start; "
                                          "add e.g. [stage run] with cycles = N", s->path);
    const uint32_t cycles_bit = 1u << bal_scene_key_index(BAL_SEC_STAGE, "cycles");
    const uint32_t time_bit = 1u << bal_scene_key_index(BAL_SEC_STAGE, "time");
    for (int i = 0; i < s->n_stages; i++) {
        struct bal_stage_def *g = &s->stages[i];
        int servos = 0;
        /* A stage's length: in cycles or in simulated time, one of them. */
        if ((g->given & cycles_bit) && (g->given & time_bit))
            return FAIL_AT(g, BAL_SEC_STAGE, "time", "[stage %s] gives both cycles and time; "
                           "expected one of them (time: the cycles follow from dt)", g->name);
        if (!(g->given & (cycles_bit | time_bit)))
            return bal_error(err, BAL_EINVAL, "%s:%d: [stage %s]: cycles: required key is missing "
                             "(give the stage's length as cycles = N, or as time = T in seconds "
                             "of simulated time)", s->path, g->line, g->name);
        for (int m = 0; m < g->n_moves; m++) {
            const struct bal_move_def *mv = &g->moves[m];
            const char *key = bal_scene_key_for_control(mv->control);
            /* A line from --set has no line of its own: the stage's header. */
            const int line = mv->line > 0 ? mv->line : g->line;
            int is_wall = 0;
            if (!body_exists(s, mv->wall, &is_wall) || !is_wall)
                return bal_error(err, BAL_EINVAL, "%s:%d: %s: no wall named '%s'", s->path,
                                 line, key, mv->wall);
            for (int q = 0; q < BAL_CONTROL_WALLS_MAX; q++)
                if (*mv->walls[q] && (!body_exists(s, mv->walls[q], &is_wall) || !is_wall))
                    return bal_error(err, BAL_EINVAL, "%s:%d: %s: no wall named '%s'", s->path,
                                     line, key, mv->walls[q]);
            char why[BAL_MSG_MAX / 2];
            if (bal_walls_check(mv, why, sizeof why))
                return bal_error(err, BAL_EINVAL, "%s:%d: %s: %s", s->path, line, key, why);
            servos += mv->control == BAL_CONTROL_SERVO;
        }
        if (g->stop_servo > 0 && servos == 0)
            return FAIL_AT(g, BAL_SEC_STAGE, "stop_servo", "%s",
                           "no wall of this stage has a servo to be within the tolerance");
    }
    for (int i = 0; i < s->n_probes; i++) {
        struct bal_probe_def *p = &s->probes[i];
        int k = p->kind, wa = 0, wb = 0;
        char why[BAL_MSG_MAX / 2];
        int contact = bal_probe_is_contact(k);
        int wall = bal_probe_is_wall(k);
        int disc = k >= BAL_PROBE_DISC_X && k <= BAL_PROBE_DISC_OMEGA;
        if (contact || wall || disc) {
            if (!*p->a)
                return FAIL_AT(p, BAL_SEC_PROBE, "a", "%s", "this quantity needs a body in 'a'");
            if (!body_exists(s, p->a, &wa))
                return FAIL_AT(p, BAL_SEC_PROBE, "a", "%s", no_body(s, p->a, why, sizeof why));
            if (wall && !wa)
                return FAIL_AT(p, BAL_SEC_PROBE, "a", "'%s' is a disc; this quantity needs a wall",
                               p->a);
            if (disc && wa)
                return FAIL_AT(p, BAL_SEC_PROBE, "a", "'%s' is a wall; this quantity needs a disc",
                               p->a);
        }
        if (contact) {
            if (!*p->b)
                return FAIL_AT(p, BAL_SEC_PROBE, "b", "%s", "a contact probe needs a second body in 'b'");
            if (!body_exists(s, p->b, &wb))
                return FAIL_AT(p, BAL_SEC_PROBE, "b", "%s", no_body(s, p->b, why, sizeof why));
            if (wa && wb)
                return FAIL_AT(p, BAL_SEC_PROBE, "b", "%s", "two walls never make a contact");
            if (strcmp(p->a, p->b) == 0)
                return FAIL_AT(p, BAL_SEC_PROBE, "b", "%s", "a body cannot touch itself");
        } else if (k == BAL_PROBE_WALL_GAP) {
            if (!*p->b)
                return FAIL_AT(p, BAL_SEC_PROBE, "b", "%s", "wall_gap needs a second wall in 'b'");
            if (!body_exists(s, p->b, &wb) || !wb)
                return FAIL_AT(p, BAL_SEC_PROBE, "b", "no wall named '%s'", p->b);
            if (strcmp(p->a, p->b) == 0)
                return FAIL_AT(p, BAL_SEC_PROBE, "b", "%s", "the gap of a wall to itself is 0");
        } else if (*p->b) {
            return FAIL_AT(p, BAL_SEC_PROBE, "b", "%s",
                           "only contact probes and wall_gap take a second body");
        }
    }
    if (s->n_discs == 0 && s->n_fills == 0 && s->n_piles == 0 && s->n_grains == 0 &&
        s->n_imports == 0)
        return bal_error(err, BAL_EINVAL,
                         "%s: no discs: add [disc NAME], [fill NAME], [pile NAME], [grains NAME] "
                         "or [import NAME] sections", s->path);
    return BAL_OK;
}

