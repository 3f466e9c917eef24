/*
 * sim.h — internal: the simulation state and the module interfaces of the
 * step pipeline.  Not part of the public API; the Check tests include it.
 *
 * Layout.  Discs are struct-of-arrays in cell order: sorted along a
 * row-major cell grid at creation and again every BAL_REORDER_EVERY
 * rebuilds (grid.c), so that neighbours are near each other in memory.  The
 * sums the pair loop adds to (force and moment; the dashpots' share) keep a
 * disc's three together, so that in a packing larger than the cache the
 * loop has fewer streams to wait on.  `id[i]` is the disc's index in scene
 * order (discs of [disc] sections first, then those of each [fill]);
 * outputs are written in that order.  A re-sort renumbers the discs and
 * the keys of the candidate lists with them (new2old).
 *
 * Contacts.  Two flat candidate lists, disc–disc and disc–wall, each sorted
 * by key = (lo << 32) | hi (pair_key(); not stored: it is i and j).  A
 * candidate carries the contact's history (F_n for the incremental law,
 * F_s) in parallel arrays; a candidate whose bodies do not overlap has zero
 * history.  When the neighbour list is rebuilt, the new candidate list is
 * merged with the old one in one linear pass, so history survives rebuilds
 * (contacts.c).
 */
#ifndef BAL_SIM_H
#define BAL_SIM_H

#include <stdint.h>

#include "ballast.h"
#include "laws.h"

#define BAL_PI 3.14159265358979323846

/* A candidate list with its contact history.  Flags: bit 0 touching,
 * bit 1 sliding (|F_s| at the Coulomb limit).  The shear history (fs, ds)
 * exists only when `shear` is set and the normal dashpot (dn) only when
 * `damping` is: a frictionless, undamped scene carries neither, and its
 * rebuilds do not copy them.  The disc–disc list never stores its dashpot
 * forces (they are recomputed for reports: bal_contact_dashpots); the wall
 * list does.  Read F_s through pair_fs(). */
struct bal_pairs {
    long n, cap;
    uint8_t shear, damping; /* which optional columns exist */
    int32_t *i, *j;        /* disc index; j: disc index or wall index; sorted by
                            * pair_key() ascending */
    double *fn, *fs;       /* F_n (history of the incremental law), F_s */
    double *dn, *ds;       /* dashpot forces D_n, D_s of the last cycle */
    uint8_t *flags;
};

static inline double pair_fs(const struct bal_pairs *p, long c) { return p->fs ? p->fs[c] : 0.0; }

/* The sort key of candidate c, (i << 32) | j. */
static inline uint64_t pair_key(const struct bal_pairs *p, long c)
{
    return ((uint64_t)(uint32_t)p->i[c] << 32) | (uint32_t)p->j[c];
}


struct bal_wall {
    char name[BAL_NAME_MAX];
    double p[2];           /* point P */
    double alpha;          /* direction of e, radians */
    double e[2];           /* (cos α, sin α) */
    double h1, h2;         /* end multipliers */
    int material;
    double v[2], omega;    /* current motion (from the stage) */
    /* Resultant of the contact forces exerted by the discs on the wall,
     * accumulated in the last cycle. */
    double f[2];           /* F1, F2 */
    double moment;         /* about P, counter-clockwise */
    double fn_sum;         /* Σ F_n over its contacts */
    double fn_s_sum;       /* Σ F_n s, s = position of the contact along e from P */
    double disp;           /* largest displacement of any of its points since rebuild */
    double f_prev[2], moment_prev; /* f and moment of the cycle before (energy audit) */
};

struct bal_grid {
    double x0, y0, h;      /* origin and cell size */
    int nx, ny;
    long cells_cap;        /* allocated length of `start` */
    int32_t *start;        /* nx*ny + 1 offsets into `list` */
    int32_t *list;         /* disc indices sorted by cell */
    int32_t *cell;         /* cell of each disc (scratch) */
};

typedef void (*bal_pair_loop_fn)(struct bal_sim *s);

/* A disc's cell and its array slot, for sorting discs into cell order. */
struct bal_cell_key {
    long cell;
    int32_t slot;
};

/* Scratch of a rebuild: the new candidate list (its keys), where each new
 * pair sat in the old list, and one history column at a time while it is
 * carried over.  About 21 bytes per candidate, instead of a second copy of
 * the whole list. */
struct bal_rebuild_scratch {
    long cap;
    long col_cap;          /* `col` may be longer: the re-sort uses it as its buffer */
    uint64_t *key;         /* (i << 32) | j of each new pair */
    int32_t *map;          /* position of the same pair in the old list, or -1 */
    double *col;           /* one double column being gathered */
    uint8_t *bytes;        /* the flags column being gathered */
};

/* How a stage ended. */
struct bal_stage_log {
    long cycles;           /* cycles run */
    int stopped;           /* 1: its stop rule was met; 0: it ran all its cycles */
    double ke_over_ee;     /* E_k / E_el at the last check (-1: never checked) */
    double stress_change;  /* largest change of a disc's stress moment between the
                            * last two checks, over the largest (-1: never) */
};

/* Running sums of the energy audit (energy.c), from the first cycle. */
struct bal_audit {
    int started;           /* the baseline has been taken */
    int gravity;           /* the scene has gravity */
    long start_step;       /* step of the baseline */
    double ek0, ee0;       /* E_k and E_el at the baseline */
    double w_walls;        /* work of the walls on the discs */
    double w_gravity;      /* work of gravity up to the last change of g_fac */
    double g_last;         /* Σ m g·x of the free discs at the last change of g_fac */
    double gfac_last;      /* g_fac since then */
    int gravity_step;      /* this cycle changes g_fac: close it after the update */
    double d_dashpot;      /* dissipated by contact dashpots (disc pairs and walls) */
    double d_dashpot_last; /* ... in the latest cycle */
    double wall_dash;      /* Σ D·v_wall of the wall contacts' dashpots in this cycle */
    double glob_sum;       /* Σ (m v_N² + I ω_N²) of this cycle (centred integrator) */
    double dash_sum;       /* Σ (F^D·v_N + M^D ω_N) of this cycle (centred integrator) */
    double d_friction;     /* dissipated by sliding at the Coulomb limit */
    double d_global;       /* dissipated by global damping */
    double d_global_last;  /* ... in the latest cycle */
};

/* A probe with its bodies resolved: kind, and for each body whether it is a
 * wall and its array slot (disc) or wall index. */
struct bal_probe_ref {
    int kind;
    int a_wall, a;
    int b_wall, b;
};

/* A law of motion (integrate.c), chosen once by settings.integrator.  A
 * cycle calls `positions` before the force evaluation and `velocities`
 * after it; `previous` gives the velocities the contact law read in the last
 * cycle (for recomputing dashpot forces).  `staggered`: after a cycle the
 * stored velocities are v_{N+1/2}, so measurements at t_N average them with
 * `previous` (C&S eq. 31); otherwise the stored velocities are v_N. */
struct bal_integrator_type {
    const char *name;
    void (*positions)(struct bal_sim *s);
    void (*velocities)(struct bal_sim *s);
    void (*previous)(const struct bal_sim *s, int i, double *vx, double *vy, double *w);
    int staggered;
};

/* Several threads in one cycle (OpenMP), with results bitwise those of one
 * thread (contacts.c, integrate.c):
 * - the disc–disc list is cut into ranges of whole chunks, one per thread.
 *   Range t adds directly to the sums of the discs above zone[t], the
 *   highest j of the ranges before it, which no earlier range touches; what
 *   it adds to the others it logs, and the logs are replayed in range order
 *   after the loop.  Every disc's sums thus add the same terms in the same
 *   order as one thread going through the whole list;
 * - the sums over candidates (the friction loss) and over discs (the audit's
 *   sums of the velocity update) add up fixed blocks, then the blocks in
 *   order, whatever the number of threads. */
struct bal_sum_log {             /* what range t adds to disc k, logged */
    double fx, fy, tq;
    float dfx, dfy, dtq;
    int32_t k;
};
struct bal_par {
    int threads;                 /* asked for (bal_sim_set_threads); 1: serial */
    int ranges;                  /* ranges of the current disc–disc list */
    long planned;                /* s->rebuilds when the list was cut, -1: never */
    long start[BAL_MAX_THREADS + 1]; /* first candidate of each range */
    int zone[BAL_MAX_THREADS];   /* range t logs its sums for discs <= zone[t] */
    int over[BAL_MAX_THREADS];   /* range t saw an overlap past the sieve */
    struct bal_sum_log *log[BAL_MAX_THREADS];
    long log_n[BAL_MAX_THREADS], log_cap[BAL_MAX_THREADS];
    double *chunk_sums;          /* per chunk of candidates: the friction loss */
    long chunk_cap;
    double *block_sums;          /* per block of discs, 2 each: a pass's sums (integrate.c) */
};
#define BAL_DISC_BLOCK 4096          /* discs per block */

/* Blocks of n discs; at least one, so that block_sums always exists. */
static inline int bal_disc_blocks(int n)
{
    return n > 0 ? (n + BAL_DISC_BLOCK - 1) / BAL_DISC_BLOCK : 1;
}

/* One past the last disc of block b of n discs (its first is b BAL_DISC_BLOCK). */
static inline int bal_block_end(int n, int b)
{
    const int to = (b + 1) * BAL_DISC_BLOCK;
    return to < n ? to : n;
}

struct bal_sim {
    const struct bal_scene *scene;

    /* discs */
    int n;
    int32_t *id;                 /* scene-order index of array slot i */
    int32_t *slot;               /* array slot of scene-order index */
    double *x, *y, *th;          /* position, rotation */
    double *vx, *vy, *w;         /* velocities at t_{N-1/2} (t_{N+1/2} after a step) */
    double *r, *inv_m, *inv_i;   /* radius, 1/m, 1/I (m and I: bal_mass, bal_inertia) */
    double *f;                   /* force and moment sums of the last cycle, 3 per disc:
                                  * F_x, F_y, M (one array: one stream in the pair loop) */
    float *dash;                 /* the dashpots' part of them, 3 per disc: x, y, moment
                                  * (only with damping: the energy audit; float: it
                                  * needs 1e-6, not 1e-16; one array, not three: the
                                  * pair loop of a large packing reads fewer streams) */
    double *x_ref, *y_ref;       /* positions at the last rebuild */
    int32_t *mat;
    uint8_t *fixed;
    double r_max;

    /* walls */
    int n_walls;
    struct bal_wall *walls;

    /* materials */
    double *density;             /* per material: mass per area */
    int n_mat;
    struct bal_pair_law *law;    /* n_mat × n_mat */
    const struct bal_pair_law *disc_law; /* the law of every disc pair when all discs
                                  * are of one material (the pair loop then reads no
                                  * material column), else NULL */

    /* contacts and neighbours */
    struct bal_pairs pp, pw;     /* disc–disc, disc–wall candidates */
    struct bal_par par;          /* threads */
    struct bal_rebuild_scratch rs; /* the new list of a rebuild, one column at a time */
    struct bal_grid grid;
    int use_grid;
    double skin;
    long rebuilds;
    int need_rebuild;
    bal_pair_loop_fn pair_loop;

    /* settings */
    double dt, dt_estimate;
    double start_energy;         /* E_k at the start of a scene nothing feeds (no gravity,
                                  * no moving wall, no allowed overlap), else 0: bounds the
                                  * power law's overlap for the estimate (timestep.c) */
    double alpha, beta;
    double g[2];
    int normal_law;
    double nu, delta0;
    double gamma_n, psi;         /* viscous normal damping of MLH eq. (3) */
    int has_shear;               /* any material pair with k_s and a non-zero cap */
    int has_damping;             /* β > 0 */

    /* pile rows and stresses */
    int32_t *row;                /* row M of a pile disc, -1 otherwise; NULL without piles */
    double *moment;              /* 4 per disc: Σ_c f ⊗ l (xx, xy, yx, yy); only with a
                                  * stress stop rule (output allocates its own) */
    double *moment_prev;         /* the same at the previous check of a stop rule */

    /* stages */
    double gfac;                 /* share of gravity applied now (the ramp) */
    struct bal_stage_log *log;   /* one per stage of the scene */

    /* probes */
    int n_probes;
    struct bal_probe_ref *probes;
    double *row_values;          /* n_probes: a series row measured before it is written */
    int have_old;                /* a cycle has run with a staggered integrator: the
                                  * stored velocities are v_{N+1/2}, v_{N-1/2} can be
                                  * recovered, measurements average them (eq. 31) */

    /* law of motion (integrate.c) */
    const struct bal_integrator_type *integ;
    double *gear;                /* gear5 only, else NULL: BAL_GEAR_COLUMNS columns of n */
    int gear_started;            /* gear5: the start-up derivatives are set */

    /* where the time goes (wall-clock seconds per phase of the cycle) */
    struct bal_timers {
        double positions, neighbours, contacts, walls, velocities;
    } timers;
    long reorders;               /* times the discs were re-sorted into cell order */
    int32_t *new2old;            /* n entries: the permutation of the last re-sort */
    int reordered;               /* 1: the lists still number discs as before the re-sort */

    /* energy audit and guards */
    struct bal_audit audit;
    double overlap_budget;       /* share of the smaller radius; INFINITY = off */
    double overlap_sieve;        /* overlap_budget x the smallest radius of the scene */
    int over_budget;             /* a contact loop saw an overlap beyond the budget */

    /* progress */
    long step;
    double time;
    int stage;
    double wall_seconds;
};

/* Mass and moment of inertia of disc i: the same expressions as at creation
 * (m = density π r², I = m r²/2), so they are bitwise the stored values of
 * old; storing them would cost 16 bytes a disc. */
static inline double bal_mass(const struct bal_sim *s, int i)
{
    return s->density[s->mat[i]] * BAL_PI * s->r[i] * s->r[i];
}

static inline double bal_inertia(const struct bal_sim *s, int i)
{
    return 0.5 * bal_mass(s, i) * s->r[i] * s->r[i];
}

/* contacts.c */
enum bal_status bal_pairs_reserve(struct bal_pairs *p, long cap);
void bal_pairs_free(struct bal_pairs *p);
void bal_pairs_merge_history(struct bal_pairs *fresh, const struct bal_pairs *old);
/* Position of `key` in the sorted list p, or -1 (binary search). */
long bal_pairs_find(const struct bal_pairs *p, uint64_t key);
bal_pair_loop_fn bal_contacts_select(int shear, int damping);
/* Cut the disc–disc list into ranges for s->par.threads threads (the pair
 * loop calls it after each rebuild); reserve the per-chunk sums for the
 * list's capacity (after every reserve of s->pp); free it all. */
void bal_par_plan(struct bal_sim *s);
enum bal_status bal_par_reserve_chunks(struct bal_sim *s);
void bal_par_free(struct bal_par *par);
void bal_contacts_walls(struct bal_sim *s);
/* The dashpot forces D_n, D_s of contact c of list p in the last cycle:
 * stored for walls, recomputed for disc pairs from the geometry at t_N and
 * the velocities v_{N-1/2} (recovered), exactly as the cycle computed them.
 * Zero for a contact that is not touching. */
void bal_contact_dashpots(const struct bal_sim *s, const struct bal_pairs *p, long c,
                          double *dn, double *ds);

/* The cell, 0 to n - 1, of a point c cell sizes from a grid's origin: the
 * conversion to int is range-checked (a point beyond the grid, or not a
 * number, takes the nearest edge cell; a double beyond INT_MAX converted
 * without the check is undefined behaviour). */
static inline int bal_cell_index(double c, int n)
{
    return c >= 0 ? (c < n ? (int)c : n - 1) : 0;
}

/* grid.c */
/* Squared displacement of disc i since the lists were built. */
static inline double bal_moved_sq(const struct bal_sim *s, int i)
{
    const double dx = s->x[i] - s->x_ref[i], dy = s->y[i] - s->y_ref[i];
    return dx * dx + dy * dy;
}
enum bal_status bal_grid_rebuild(struct bal_sim *s, struct bal_error *err);
/* Called when the two largest displacements since the last rebuild, d_1
 * >= d_2, reach the skin together: is there a pair outside the list that
 * can touch now?  1 if so (or if it cannot tell cheaply), 0 if the lists
 * still hold every contact.  Reads the displacement maxima of each block of
 * discs from par.block_sums (the position pass's). */
int bal_grid_lists_broken(const struct bal_sim *s, double d1);
/* Re-sort the discs into cell order of their current positions, carrying
 * every per-disc array and the probes along, then rebuild the lists (their
 * history found through the permutation). */
enum bal_status bal_grid_reorder(struct bal_sim *s, struct bal_error *err);
void bal_grid_scratch_free(struct bal_rebuild_scratch *rs);
/* The permutation that puts discs in row-major order of cells of side h
 * (order[new] = old); ties keep their order, so it is deterministic.
 * `keys` is scratch of n entries. */
void bal_grid_cell_order(const double *x, const double *y, int n, double h,
                         struct bal_cell_key *keys, int32_t *order);
/* Rebuilds between two re-sorts: the order decays only as discs flow, and a
 * re-sort costs about as much as a few rebuilds. */
#define BAL_REORDER_EVERY 20
void bal_grid_free(struct bal_grid *g);
/* With fewer discs than this, `grid = auto` uses all pairs.  Measured with
 * `build/bench --grid cases/bench/dense.scene` (README, "Neighbour search"):
 * the Verlet-listed grid was faster at every N >= 4, settled or falling
 * (1.2-1.5x at N = 4-16, 14x at N = 256), so all pairs serve only scenes of
 * two or three discs, whose single list is built once. */
#define BAL_GRID_CROSSOVER 4

/* walls.c */
void bal_walls_move(struct bal_sim *s);
/* Closest point of wall w to (x, y); returns squared distance. */
double bal_walls_closest(const struct bal_wall *w, double x, double y,
                         double *cx, double *cy);
/* Unit normal from (x, y) to the closest point of wall w (the wall's own
 * normal when the point lies on it); returns the distance. */
double bal_walls_normal(const struct bal_wall *w, double x, double y, double *ex, double *ey);

/* integrate.c */
/* Set s->integ from the scene and reserve what it needs (gear5: its
 * derivative columns); after the discs exist. */
enum bal_status bal_integrate_setup(struct bal_sim *s, struct bal_error *err);
void bal_integrate_free(struct bal_sim *s);
/* After bal_grid_reorder: carry the integrator's per-disc columns along the
 * permutation s->new2old. */
void bal_integrate_reordered(struct bal_sim *s);
/* Per-disc columns of gear5: scaled derivatives r2..r5 of x, y, θ (12), the
 * predicted velocities the contact law read (3), one scratch column. */
#define BAL_GEAR_COLUMNS 16
/* The two halves of the law of motion of s->integ (one dispatch each). */
void bal_integrate_positions(struct bal_sim *s);
void bal_integrate_velocities(struct bal_sim *s);
/* The velocities of disc i that the contact law read in the last cycle:
 * centred and verlet v_{N-1/2} (recovered from the stored velocities and
 * the force sums by inverting the last update), gear5 the predicted v_N. */
void bal_integrate_previous(const struct bal_sim *s, int i, double *vx, double *vy, double *w);

/* energy.c */
/* Take the baseline of the audit (after the first cycle). */
void bal_energy_begin(struct bal_sim *s);
/* Add the walls' work of this cycle (after the wall loop). */
void bal_energy_walls(struct bal_sim *s);
/* Add the losses of global damping and of the contact dashpots in this
 * cycle (after the velocity update). */
void bal_energy_global(struct bal_sim *s);
void bal_energy_dashpots(struct bal_sim *s);
/* Around a cycle in which g_fac changes (before it moves the discs, after
 * the velocity update): the gravity's work in intervals of constant g_fac. */
void bal_energy_gravity_before(struct bal_sim *s);
void bal_energy_gravity(struct bal_sim *s);
/* BAL_EUNSTABLE naming the worst contact if an overlap exceeds the budget. */
enum bal_status bal_energy_overlap(const struct bal_sim *s, struct bal_error *err);
/* BAL_EUNSTABLE if the run created more energy than settings.energy_guard
 * times the energy that went through it. */
enum bal_status bal_energy_guard(const struct bal_sim *s, struct bal_error *err);

/* timestep.c */
double bal_timestep_estimate(const struct bal_sim *s);
double bal_timestep_single_spring(const struct bal_sim *s);
void bal_timestep_detail(const struct bal_sim *s, struct bal_dt_detail *d);

/* measure.c */
/* Velocities of disc i at t_N (eq. 31), recovered after a cycle. */
void bal_measure_velocity(const struct bal_sim *s, int i, double *vx, double *vy, double *w);
/* Per disc, Σ_c f^c ⊗ l^c over its contacts (MLH eq. 8 without 1/V), into
 * m[4 i .. 4 i + 3] = xx, xz, zx, zz (z vertical). */
void bal_measure_moments(const struct bal_sim *s, double *m);
/* The volume V_i of MLH eq. (8) for one disc: the hexagonal cell of a disc of
 * its size in a triangular packing, 2 sqrt(3) r^2. */
double bal_measure_disc_volume(double r);
/* The energy stored by the normal spring of a contact with pair law L:
 * F_n²/(2 k_n) for the incremental law, ∫ F_n dδ at overlap δ for the power law. */
double bal_measure_normal_energy(const struct bal_sim *s, const struct bal_pair_law *L, double fn,
                                 double delta);

/* sim.c */
/* Scene-order index of the disc in slot i; name of wall k; the C&S contact
 * point of disc i with disc or wall j (as in contacts.tsv). */
int bal_sim_disc_id(const struct bal_sim *s, int i);
const char *bal_sim_wall_name(const struct bal_sim *s, int k);
/* Candidate c of the disc–disc list (walls = 0) or of the disc–wall list
 * (walls = 1): its overlap δ (negative: a gap), the smaller radius of its
 * bodies and their pair law; and the names of its bodies for messages,
 * "A" and "disc B" or "wall W". */
double bal_sim_overlap(const struct bal_sim *s, int walls, long c, double *rmin,
                       const struct bal_pair_law **law);
void bal_sim_pair_names(const struct bal_sim *s, int walls, long c, char *a, size_t na, char *b,
                        size_t nb);
void bal_sim_contact_point(const struct bal_sim *s, int i, int is_wall, int j, double *px,
                           double *py);
/* Most discs a scene may make (array indices are int32_t). */
#define BAL_MAX_DISCS 100000000L
/* A property of a disc, for naming where the scene set it. */
enum bal_disc_prop { BAL_DISC_PLACE, BAL_DISC_SIZE, BAL_DISC_SPEED, BAL_DISC_SPIN };
/* "FILE:LINE: KEY: disc NAME" of the key that set property `prop` of the
 * disc with scene-order index id: its [disc] key, or the key of the [fill]
 * or [pile] that generated it (the section's header line when the key was
 * left at its default). */
void bal_sim_disc_origin(const struct bal_scene *sc, int id, enum bal_disc_prop prop, char *buf,
                         size_t size);
/* Bytes the simulation holds while it steps (every array at its allocated
 * capacity), split into what scales with discs and with candidate pairs. */
void bal_sim_memory(const struct bal_sim *s, double *disc_bytes, double *pair_bytes);
/* Number of rows and of discs a [pile] generates. */
long bal_sim_pile_rows(const struct bal_pile_def *p);
long bal_sim_pile_count(const struct bal_pile_def *p);
enum bal_status bal_sim_cycle(struct bal_sim *s, struct bal_error *err);
/* Candidate index of the contact between two bodies, or -1. */
long bal_sim_find_contact(const struct bal_sim *s, int a_wall, int a, int b_wall, int b,
                          const struct bal_pairs **list);

#endif /* BAL_SIM_H */
