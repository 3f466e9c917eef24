/*
 * state.h — internal: the state of a simulation, struct bal_sim and its
 * parts, with the few inline helpers that read it.  Every module of the
 * step includes it; it has no functions of its own to call, so it sits
 * below them all.  The behaviour lives in the modules, each with its own
 * header (pairs.h, grid.h, pair_loop.h, wall_loop.h, walls.h, ...).  Not
 * part of the public API; the Check tests and the benchmark include it.
 *
 * Layout.  Discs are struct-of-arrays in cell order: sorted along a
 * row-major cell grid at creation and again every BAL_REORDER_EVERY
 * rebuilds (grid.c), so that neighbours are near each other in memory.  The
 * sums the pair loop adds to (force and moment; the dashpots' share) keep a
 * disc's three together, so that in a packing larger than the cache the
 * loop has fewer streams to wait on.  `id[i]` is the disc's index in scene
 * order (discs of [disc] sections first, then those of each generator in
 * the order of specimen.c's table: [fill], [pile], [grains], [import]);
 * outputs are written in that order.  A re-sort
 * renumbers the discs and the keys of the candidate lists with them
 * (new2old).
 *
 * Contacts.  Two flat candidate lists, disc–disc and disc–wall, each sorted
 * by key = (lo << 32) | hi (pair_key(); not stored: it is i and j).  A
 * candidate carries the contact's history (F_n for the incremental law,
 * F_s, the rolling M and θ_r; the wall list also its dashpot forces) in
 * parallel arrays, each only where the scene needs it; a candidate whose
 * bodies do not overlap has zero history.  The contact loops (pair_loop.c,
 * wall_loop.c) read and write them in place; when the neighbour list is
 * rebuilt, the new candidate list is merged with the old one in one linear
 * pass, so history survives rebuilds (grid.c, install: the only merge).
 */
#ifndef BAL_STATE_H
#define BAL_STATE_H

#include <stdint.h>

#include "ballast.h"
#include "laws.h"

struct bal_integrator_type;      /* a law of motion: integrate.h */
struct bal_wall_controller_type; /* how a stage drives a wall: walls.h */

#define BAL_PI 3.14159265358979323846

/* A candidate list with its contact history.  Flags: bit 0 touching,
 * bit 1 sliding (|F_s| at the Coulomb limit).  The shear history (fs, ds)
 * exists only when `shear` is set and the normal dashpot (dn) only when
 * `damping` is: a frictionless, undamped scene carries neither, and its
 * rebuilds do not copy them.  The disc–disc list never stores its dashpot
 * forces (they are recomputed for reports: bal_measure_dashpots); the wall
 * list does.  Read F_s through pair_fs(). */
struct bal_pairs {
    long n, cap;
    uint8_t shear, damping, rolling; /* which optional columns exist */
    int32_t *i, *j;        /* disc index; j: disc index or wall index; sorted by
                            * pair_key() ascending */
    double *fn, *fs;       /* F_n (history of the incremental law), F_s */
    double *dn, *ds;       /* dashpot forces D_n, D_s of the last cycle */
    double *mr, *tr;       /* rolling: the elastic moment M and the relative rotation
                            * θ_r accumulated since the contact formed (laws.h) */
    double *dm;            /* rolling: the dashpot's moment M_d of the last cycle (walls) */
    double *rb, *rk;       /* rolling, the disc–disc list: the pair's contact width B and
                            * rolling stiffness K_m (bal_law_roll_of), constants of the pair
                            * set by the loop's first cycle after each rebuild
                            * (pair_loop.c, roll_constants); the wall list leaves them unset */
    long rolled;           /* s->rebuilds when rb and rk were last set, -1: not since the
                            * columns were (re)allocated */
    uint8_t *flags;
};

static inline double pair_fs(const struct bal_pairs *p, long c) { return p->fs ? p->fs[c] : 0.0; }
static inline double pair_mr(const struct bal_pairs *p, long c) { return p->mr ? p->mr[c] : 0.0; }
static inline double pair_tr(const struct bal_pairs *p, long c) { return p->tr ? p->tr[c] : 0.0; }

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
    double v[2], omega;    /* velocity of P and angular velocity about P for the next
                            * move, set by its controller */
    const struct bal_wall_controller_type *controller; /* the current stage's, or NULL:
                            * the stage leaves the wall at rest (walls.c) */
    const struct bal_move_def *move; /* the stage's line for the wall: the controller's
                            * parameters (scene data), or NULL */
    /* What a controller keeps between cycles (walls.c), set when its stage
     * begins. */
    int other[BAL_CONTROL_WALLS_MAX]; /* indices of the walls its line names */
    double toward[2];      /* unit normal of the wall along which it moves: towards the
                            * discs (servo) or the other wall (strain_rate) */
    double vcap;           /* servo: the speed cap */
    double stress;         /* servo: the normal stress measured in the last cycle */
    double stress_error;   /* servo: |stress − target| / target of the last cycle
                            * (INFINITY before the first) */
    /* Resultant of the contact forces exerted by the discs on the wall,
     * accumulated in the last cycle. */
    double f[2];           /* F1, F2 */
    double moment;         /* about P, counter-clockwise */
    double fn_sum;         /* Σ F_n over its contacts */
    double fn_s_sum;       /* Σ F_n s, s = position of the contact along e from P */
    double dash_f[2], dash_m; /* the contact dashpots' share of f and of the moment about P
                            * (only in damped scenes, and in stages with a controller
                            * acting every cycle: wall_loop.c) */
    double stiffness;      /* Σ dF_n/dδ of its contacts (laws.h, bal_law_normal_stiffness):
                            * the servo's K (only in stages with a controller acting every
                            * cycle: wall_loop.c; at a servo's start, walls.c) */
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
    double servo_error;    /* the largest |stress − target|/target of the stage's servo
                            * walls at the last check (-1: never) */
    double unbalanced;     /* ΔF/F at the last check (-1: never) */
    long max_cycles;       /* the stage's cycles, or ceil(time/dt) (bal_build_stages) */
    int in_time;           /* 1: the stage was given in simulated time */
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
    double d_rolling;      /* dissipated by plastic rolling / lost rolling springs */
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

/* Several threads in one cycle (OpenMP), with results bitwise those of one
 * thread (pair_loop.c and threads.c, integrate.c):
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
    int32_t *chunk_top;          /* per chunk: its highest j (bal_threads_plan, once a list) */
    double *chunk_roll;          /* ... and the rolling loss (only with rolling) */
    long chunk_cap;
    double *block_sums;          /* per block of discs, 2 each: a pass's sums (integrate.c) */
    int one_lane;                /* 1: the pair loop runs every contact one at a time, never
                                  * two (tests compare the widths; pair_loop.c) */
    long two_lane[BAL_MAX_THREADS]; /* contacts range t has run two at a time, since creation */
};
#define BAL_DISC_BLOCK 4096          /* discs per block */

/* The two largest squared displacements of any disc since the lists were
 * built, d1_sq >= d2_sq (zero without the grid): what the position pass of
 * a cycle returns (integrate.c) and the neighbour search judges (grid.c,
 * bal_grid_due).  Each block's are in par.block_sums. */
struct bal_moves {
    double d1_sq, d2_sq;
};

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

/* One snapshot written: its cycle, simulated time and stage (index.tsv and
 * snapshots.pvd list them all, rewritten after each frame). */
struct bal_snapshot_frame {
    long cycle;
    double time;
    int stage;
};

/* Longest path of a run's snapshots folder, with its terminating zero (the
 * output writers build their paths in 1024 characters). */
#define BAL_SNAPSHOT_DIR_MAX 1000

/* The snapshots of a run (snapshots.c): when the next frame is due and the
 * frames written so far. */
struct bal_snapshots {
    long next;             /* the cycle of the next frame, the one test the run loop
                            * makes per cycle; -1: none (snapshots off, or no folder) */
    long every;            /* settings.snapshot_every; 0: frames in simulated time */
    double period;         /* settings.snapshot_dt; 0: frames in cycles */
    long n, cap;           /* frames written; room in `frames` (reserved at creation
                            * for every frame the stages can have) */
    struct bal_snapshot_frame *frames;
    char dir[BAL_SNAPSHOT_DIR_MAX]; /* the folder, OUT/snapshots; "" until named */
};

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
    uint8_t *fixed;              /* 1: held (every component of its motion) */
    uint8_t *hold;               /* BAL_HOLD_* bits of the components held at zero of a partly
                                  * held disc (0 for the others); NULL when no disc is partly
                                  * held, so the passes of other scenes test nothing */
    double r_max, r_min;         /* largest and smallest radius */

    /* walls */
    int n_walls;
    struct bal_wall *walls;
    int walls_controlled;        /* walls of this stage whose controller acts in every
                                  * cycle: 0 lets a cycle skip them all (walls.c) */
    int wall_fault;              /* a wall's run-time guard tripped (walls.c): 1 + its index,
                                  * else 0; the next cycle stops the run before it moves */
    int wall_fault_kind;         /* enum bal_wall_fault of that wall (walls.h) */

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
    double skin;                 /* the Verlet skin of the lists in use */
    int skin_rule;               /* enum bal_skin_rule: with motion, each rebuild chooses the
                                  * skin (grid.c, motion_skin) from the next two */
    double moved_sq;             /* the largest squared displacement of a disc since the lists
                                  * were built, as of the last position pass */
    double skin_edge;            /* candidates per unit of skin at the edge of the last
                                  * search's skin (its outer half); 0: not measured */
    long built_step;             /* s->step when the lists were built */
    int crowded;                 /* 1 + the slot of the disc whose candidates passed
                                  * BAL_MAX_NEIGHBOURS in the rebuild that just failed on
                                  * it (grid.c), else 0: the builder names it */
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
    int has_damping;             /* β > 0 or γ_n > 0 */
    int has_rolling;             /* any material pair with rolling δ > 0 (JYH) */

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

    /* snapshots (snapshots.c) */
    struct bal_snapshots snap;

    /* progress */
    long step;
    double time;
    int stage;
    double wall_seconds;
    /* bal_sim_set_progress: called from bal_sim_run every progress_seconds */
    void (*progress)(const struct bal_progress *, void *);
    void *progress_ctx;
    double progress_seconds;
};

/* Mass and moment of inertia of disc i: the same expressions as at creation
 * (m = density π r², I = m r²/2), so they are bitwise the stored values of
 * old; storing them would cost 16 bytes a disc. */
static inline double bal_mass(const struct bal_sim *s, int i)
{
    return s->density[s->mat[i]] * BAL_PI * s->r[i] * s->r[i];
}

/* The parameters of the contact-law chain (laws.h) that do not depend on
 * the pair, as the loops read them. */
static inline struct bal_law_params bal_law_params_of(const struct bal_sim *s)
{
    return (struct bal_law_params){s->normal_law, s->nu,  s->delta0,
                                   s->gamma_n,    s->psi, s->dt,
                                   s->scene->settings.rolling_model};
}

static inline double bal_inertia(const struct bal_sim *s, int i)
{
    return 0.5 * bal_mass(s, i) * s->r[i] * s->r[i];
}

/* The cell, 0 to n - 1, of a point c cell sizes from a grid's origin: the
 * conversion to int is range-checked (a point beyond the grid, or not a
 * number, takes the nearest edge cell; a double beyond INT_MAX converted
 * without the check is undefined behaviour). */
static inline int bal_cell_index(double c, int n)
{
    return c >= 0 ? (c < n ? (int)c : n - 1) : 0;
}

/* Squared displacement of disc i since the lists were built. */
static inline double bal_moved_sq(const struct bal_sim *s, int i)
{
    const double dx = s->x[i] - s->x_ref[i], dy = s->y[i] - s->y_ref[i];
    return dx * dx + dy * dy;
}

#endif /* BAL_STATE_H */
