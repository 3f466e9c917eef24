/*
 * ballast.h — the public interface of the ballast 2D DEM core.
 *
 * ballast implements the BALL scheme of Cundall & Strack (1979) for discs and
 * straight rigid walls.  Data flows through this header in order:
 *
 *   status and errors → scene (define, default, load, validate)
 *   → simulation life cycle (create, free) → stepping (step, run)
 *   → measurements → output
 *
 * Units are whatever the scene uses (the paper's examples use unitless
 * numbers); lengths, masses and times must only be consistent.  Angles in
 * scene files are degrees; inside the core they are radians.
 *
 * Sign conventions follow Cundall & Strack Figs 2–3: for a contact between
 * bodies x and y, e points from x to y, t = (e2, −e1) is e turned clockwise,
 * and F_n, F_s act on x in the directions −e and −t (compression positive).
 * Angular velocities and moments are positive counter-clockwise.
 *
 * No function here keeps global state; everything lives in the objects
 * passed in.  Every function that can fail returns an enum bal_status and
 * fills a struct bal_error with a message naming the place.
 */
#ifndef BALLAST_H
#define BALLAST_H

#include <signal.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#define BAL_VERSION "0.1.0"

/* ------------------------------------------------------------------ */
/* Status and errors                                                   */
/* ------------------------------------------------------------------ */

enum bal_status {
    BAL_OK = 0,        /* success */
    BAL_EINVAL,        /* invalid input: scene syntax, value out of range */
    BAL_ENOMEM,        /* allocation failed */
    BAL_EIO,           /* a file could not be read or written */
    BAL_EUNSTABLE,     /* the run blew up: a position or velocity is not finite */
    BAL_EINTR          /* interrupted by a signal */
};

#define BAL_MSG_MAX 640

struct bal_error {
    enum bal_status code;          /* the last status raised */
    char msg[BAL_MSG_MAX];         /* "file:line: key: what was expected" */
};

/* Fill err (if not NULL) with a formatted message and return code.  Every
 * error in the core passes through here: one breakpoint catches them all. */
enum bal_status bal_error(struct bal_error *err, enum bal_status code,
                          const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* A short name for a status ("ok", "invalid input", ...). */
const char *bal_strerror(enum bal_status code);

/* ------------------------------------------------------------------ */
/* Scene: plain data filled from a scene file                          */
/* ------------------------------------------------------------------ */

#define BAL_NAME_MAX 48
/* A body a probe names: a section's name, or NAME.k for the k-th disc of a
 * generator (a name of 47 characters, a dot and up to 9 digits: k <
 * BAL_MAX_DISCS = 1e8). */
#define BAL_BODY_MAX 64
#define BAL_MAX_MOVES 16
#define BAL_KEYS_MAX 32   /* most keys one section kind has ([settings]: one fewer, its last
                           * key_line slot holds its header's line); at most the bits of
                           * `given` */

/* Every section struct ends with these: which keys were given (bit k for the
 * k-th key of its kind in the key table) and on which line. */
#define BAL_SECTION_TAIL uint32_t given; int key_line[BAL_KEYS_MAX]

enum bal_normal_law {
    BAL_NORMAL_INCREMENTAL = 0, /* C&S eqs (14), (16), (18): F_n += k_n ṅ Δt */
    BAL_NORMAL_POWER = 1        /* MLH eq. (2): F_n = k_n δ0 (δ/δ0)^ν */
};

enum bal_grid_mode {
    BAL_GRID_AUTO = 0, /* all pairs below the measured cross-over, else grid */
    BAL_GRID_ON = 1,   /* always a cell grid with a Verlet skin */
    BAL_GRID_OFF = 2   /* always all pairs (built once, never rebuilt) */
};

enum bal_skin_rule {
    BAL_SKIN_FIXED = 0,  /* the skin as given (or 0.2 r_max) for the whole run */
    BAL_SKIN_MOTION = 1  /* re-chosen at every rebuild from the measured motion (grid.c) */
};

enum bal_integrator {
    BAL_INTEGRATOR_CENTRED = 0, /* C&S eqs (20)-(23a), (35)-(36): v at half steps */
    BAL_INTEGRATOR_VERLET = 1,  /* velocity Verlet: x and v at whole steps */
    BAL_INTEGRATOR_GEAR5 = 2    /* Gear's 6-value predictor-corrector (MLH Sec. 5.3) */
};

enum bal_rolling_model {
    BAL_ROLLING_MODEL1 = 0,     /* JYH eq. (35): elasto-perfectly plastic, |M| <= M_0 */
    BAL_ROLLING_MODEL2 = 1      /* JYH eq. (36): elasto-brittle, M = 0 once |θ_r| > θ_r⁰ */
};

struct bal_settings {
    double dt;            /* time step; 0 = dt_fraction × estimate (default 0) */
    double dt_fraction;   /* fraction of the critical-step estimate (0.1) */
    double alpha;         /* global damping α, C&S eq. (34), 1/time (0) */
    double beta;          /* contact damping β, C&S eq. (28), time (0) */
    double gravity[2];    /* body-force acceleration g_i (0 0) */
    int normal_law;       /* enum bal_normal_law (incremental) */
    double nu;            /* exponent ν of the power law (1) */
    double delta0;        /* normalisation δ0 of the power law, length (1) */
    int grid;             /* enum bal_grid_mode (auto) */
    double skin;          /* Verlet skin, length; 0 = auto (0) */
    int skin_rule;        /* enum bal_skin_rule (fixed); with motion, `skin` is the first one */
    long output_every;    /* cycles between series rows (1) */
    double gamma_n;       /* viscous normal damping γ_n of MLH eq. (3), mass/time (0) */
    double psi;           /* exponent ψ of MLH eq. (3) (0) */
    double stress_width;  /* moving-average stress cells: width, 0 = off (0) */
    double stress_height; /* cell height (0 = the width) */
    double stress_step;   /* horizontal step between overlapping cells (0 = the width) */
    double overlap_budget; /* stop when an overlap exceeds this share of the smaller radius (0.5; 0 = off) */
    double energy_guard;  /* stop when the run creates this share of its energy throughput (1; 0 = off) */
    long allow_overlap;   /* 1: discs may overlap each other or walls at the start (0) */
    long force_dt;        /* 1: accept a time step at or above the stability estimate (0) */
    int integrator;       /* enum bal_integrator (centred) */
    int rolling_model;    /* enum bal_rolling_model, for pairs with rolling > 0 (model1) */
    long snapshot_every;  /* cycles between snapshots (snapshots.c); 0 = off (0) */
    double snapshot_dt;   /* simulated time between snapshots; 0 = off (0); not with
                           * snapshot_every */
    long vtk;             /* 1: each snapshot also as VTK XML PolyData (vtk.c) (0) */
    BAL_SECTION_TAIL;
};

struct bal_material_def {
    char name[BAL_NAME_MAX];
    int line;             /* line of the section header, for messages */
    double kn;            /* normal stiffness k_n, force/length (required) */
    double ks;            /* shear stiffness k_s, force/length (= kn) */
    double friction;      /* tan φ_μ (0) */
    double cohesion;      /* c of eq. (19), force (0) */
    double density;       /* mass per area (per unit thickness) (required for discs) */
    double rolling;       /* shape parameter δ of JYH eq. (24), B = δ r; 0: no rolling
                           * resistance (a pair uses the smaller of its two) (0) */
    BAL_SECTION_TAIL;
};

struct bal_disc_def {
    char name[BAL_NAME_MAX];
    int line;
    double x[2];          /* centre */
    double r;             /* radius (required) */
    double v[2];          /* initial velocity (at t_{1/2}) (0 0) */
    double theta;         /* rotation, degrees (0) */
    double omega;         /* angular velocity, rad/time (0) */
    char material[BAL_NAME_MAX];
    long fixed;           /* 1: held in place (velocity stays zero) (0) */
    int hold;             /* BAL_HOLD_* bits: components of the motion held at zero (none);
                           * all three are fixed = 1 */
    BAL_SECTION_TAIL;
};

/* The components of a disc's motion `hold` can keep at zero. */
#define BAL_HOLD_X 1u         /* v_x: x stays */
#define BAL_HOLD_Y 2u         /* v_y: y stays */
#define BAL_HOLD_ROTATION 4u  /* ω: θ stays */
#define BAL_HOLD_ALL 7u

struct bal_wall_def {
    char name[BAL_NAME_MAX];
    int line;
    double p[2];          /* point P of C&S Fig. 4 */
    double angle;         /* α of e = (cos α, sin α), degrees */
    double h1, h2;        /* end multipliers: A = P + h1 e, B = P + h2 e */
    char material[BAL_NAME_MAX];
    BAL_SECTION_TAIL;
};

/* A generator: n discs with radii uniform in [rmin, rmax] on a square lattice
 * of spacing 2 rmax, `columns` per row, filled row by row from (x0, y0); with
 * box = walls, four walls enclose the lattice region. */
struct bal_fill_def {
    char name[BAL_NAME_MAX];
    int line;
    long n;               /* number of discs (required) */
    long columns;         /* lattice columns (required) */
    double origin[2];     /* lower-left corner of the region (0 0) */
    double rmin, rmax;    /* radius range (required) */
    double headroom;      /* extra height above the lattice inside the box (0) */
    double vmax;          /* initial speeds uniform in [0, vmax), random direction (0) */
    unsigned long seed;   /* PRNG seed (1) */
    long box;             /* 1: enclose with four walls (0) */
    char material[BAL_NAME_MAX];
    char wall_material[BAL_NAME_MAX];
    BAL_SECTION_TAIL;
};

/* A generator: a pile of equal discs on a triangular lattice (MLH Sec. 4,
 * Fig. 2).  Row M = 0 has L discs; row M holds L − 3M (slope 30) or L − M
 * (slope 60).  Bottom `smooth`: row 0 rests on a floor wall NAME_floor with
 * only its two corner stones held; `bumpy`: row 0 is held at spacing
 * d (1 + c) and the rows above sit in its hollows (spacing max(d, d(1 + c))),
 * each row at the lowest height where it does not overlap the row below.
 * With size_spread = r_d > 0 (MLH Sec. 4.4) every disc, held or free, has
 * its own diameter d (1 + r), r uniform in [−r_d/2, r_d/2) from GSL's
 * mt19937 seeded with `seed`, drawn in scene order; specimen.c says where
 * the discs then go. */
struct bal_pile_def {
    char name[BAL_NAME_MAX];
    int line;
    long L;               /* discs in row 0 (required) */
    int slope;            /* 0: 30 degrees, 1: 60 degrees (30) */
    double d;             /* diameter (required) */
    double origin[2];     /* left end of the base, floor height (0 0) */
    int bottom;           /* 0: smooth, 1: bumpy (smooth) */
    double c;             /* spacing factor of row 0 on a bumpy bottom (0) */
    double size_spread;   /* r_d of MLH Sec. 4.4, 0 <= r_d < 1 (0: equal discs) */
    unsigned long seed;   /* seed of the diameters' generator, 1 ... 2^32 - 1 (1) */
    char material[BAL_NAME_MAX];
    char wall_material[BAL_NAME_MAX];
    BAL_SECTION_TAIL;
};

/* A generator: n discs placed at random without overlap (random sequential
 * addition, the largest first) in the rectangle from `origin` of the given
 * size, with diameters from a grading curve given by area ("percent finer"
 * by area in 2D): the share of the discs' area in discs of diameter <= d is
 * 0, 0.1, 0.5, 0.6, 1 at dmin, d10, d50, d60, dmax, linear in between
 * (grading.c; specimen.c places them); with box = 1, four walls NAME_bottom/_right/_top/_left on
 * the rectangle's sides, each reaching `overhang` beyond the corners. */
struct bal_grains_def {
    char name[BAL_NAME_MAX];
    int line;
    long n;               /* number of discs (required) */
    double origin[2];     /* lower-left corner of the region (0 0) */
    double size[2];       /* width and height of the region (required) */
    double dmin, d10, d50, d60, dmax; /* the grading curve (required) */
    unsigned long seed;   /* seed of GSL's gsl_rng_mt19937 (1) */
    long tries;           /* random places tried for one disc before refusing (100000) */
    long box;             /* 1: enclose with four walls (0) */
    double overhang;      /* how far the box walls reach beyond the corners; -1: dmax (-1) */
    char material[BAL_NAME_MAX];
    char wall_material[BAL_NAME_MAX];
    BAL_SECTION_TAIL;
};

/* Longest path of a data file a scene names. */
#define BAL_PATH_MAX 512

/* Columns of an imported disc, in struct bal_import_def's disc_data. */
enum { BAL_IMPORT_X, BAL_IMPORT_Y, BAL_IMPORT_R, BAL_IMPORT_THETA, BAL_IMPORT_VX, BAL_IMPORT_VY,
       BAL_IMPORT_OMEGA, BAL_IMPORT_FIXED, BAL_IMPORT_COLUMNS };

/* A wall of an imported walls.tsv: its name and end points A, B. */
struct bal_import_wall {
    char name[BAL_NAME_MAX];
    double a[2], b[2];
    int row;              /* line of the data file */
};

/* A prepared state: the discs of a discs.tsv and the walls of a walls.tsv a
 * run wrote, loaded unchanged.  The files are read when their keys are
 * parsed (scene.c, import.c), so the scene holds their data. */
struct bal_import_def {
    char name[BAL_NAME_MAX];
    int line;
    char discs[BAL_PATH_MAX]; /* discs.tsv, relative to the scene's directory (required) */
    char walls[BAL_PATH_MAX]; /* walls.tsv, likewise ("": no walls) */
    char material[BAL_NAME_MAX];
    char wall_material[BAL_NAME_MAX];
    long velocities;      /* 1: read vx vy omega; 0: the discs start at rest (0) */
    /* read from the files (owned by the scene, freed by bal_scene_free): */
    long n;               /* discs */
    int velocity_columns; /* 1: the discs.tsv has vx, vy, omega */
    double *disc_data;    /* n x BAL_IMPORT_COLUMNS */
    int *disc_row;        /* the data file's line of each disc */
    int n_walls;
    struct bal_import_wall *wall_data;
    BAL_SECTION_TAIL;
};

/* How a stage drives a wall: its controller (walls.c), named by the stage
 * key that gives the wall's line. */
enum bal_wall_control {
    BAL_CONTROL_PRESCRIBED = 0, /* `move`: P moves with v, the wall turns about P with omega */
    BAL_CONTROL_SERVO = 1,      /* `servo`: the wall holds a target normal stress */
    BAL_CONTROL_STRAIN_RATE = 2 /* `strain_rate`: the gap to another wall shrinks at a rate */
};

/* Most other walls a controller's line names (the servo's two span walls). */
#define BAL_CONTROL_WALLS_MAX 2

/* A stage's line for one wall: its controller and the controller's
 * parameters, in the order its key takes them after the wall's name: its
 * numbers go to consecutive doubles from the key's offset, the other walls
 * it names to `walls`, in order. */
struct bal_move_def {
    char wall[BAL_NAME_MAX];  /* wall name */
    int line;
    int control;              /* enum bal_wall_control (prescribed) */
    char walls[BAL_CONTROL_WALLS_MAX][BAL_NAME_MAX]; /* servo: the two walls whose
                               * distance is the span; strain_rate: the wall it moves
                               * towards (walls[0]) */
    double v[2];              /* prescribed: velocity of P */
    double omega;             /* prescribed: angular velocity about P, rad/time */
    double sigma;             /* servo: target normal stress, force/length (per unit
                               * thickness), compression positive */
    double gain;              /* servo: share α of the stress error removed per cycle */
    double vmax;              /* servo: speed cap, length/time; 0: BAL_SERVO_CAP_SHARE of the
                               * smallest radius per time step (walls.c) */
    double rate;              /* strain_rate: -d(gap)/dt / gap, 1/time (> 0 compresses) */
};

struct bal_stage_def {
    char name[BAL_NAME_MAX];
    int line;
    long cycles;              /* number of cycles, or the most when a stop rule is set */
    double time;              /* or the stage's simulated time: ceil(time/dt) cycles (one of
                               * the two is given; bal_sim_stage_cycles resolves them) */
    long ramp;                /* 1: gravity rises linearly from 0 over the stage (0) */
    double stop_ke;           /* stop when E_k <= stop_ke E_el (0: off) */
    double stop_stress;       /* ... and the stresses change by <= this (0: off) */
    double stop_servo;        /* ... and every servo wall is within this share of its
                               * target stress (0: off) */
    double stop_unbalanced;   /* ... and ΔF/F (bal_measure_unbalanced) <= this (0: off) */
    long check_every;         /* cycles between checks of the stop rule (100) */
    long output_at_end;       /* 1: a series row after the stage's last cycle (0) */
    int n_moves;              /* walls the stage drives; the others stay at rest */
    struct bal_move_def moves[BAL_MAX_MOVES];
    BAL_SECTION_TAIL;
};

enum bal_probe_kind {
    BAL_PROBE_CONTACT_FN, BAL_PROBE_CONTACT_FS, BAL_PROBE_CONTACT_SLIDING,
    BAL_PROBE_WALL_F1, BAL_PROBE_WALL_F2, BAL_PROBE_WALL_MOMENT, BAL_PROBE_WALL_ECC,
    BAL_PROBE_DISC_X, BAL_PROBE_DISC_Y, BAL_PROBE_DISC_VX, BAL_PROBE_DISC_VY,
    BAL_PROBE_DISC_THETA, BAL_PROBE_DISC_OMEGA,
    BAL_PROBE_ENERGY_KINETIC, BAL_PROBE_ENERGY_ELASTIC,
    BAL_PROBE_WORK_WALLS, BAL_PROBE_WORK_GRAVITY, BAL_PROBE_DISSIPATED_DASHPOT,
    BAL_PROBE_DISSIPATED_FRICTION, BAL_PROBE_DISSIPATED_GLOBAL, BAL_PROBE_ENERGY_IMBALANCE,
    BAL_PROBE_UNBALANCED, BAL_PROBE_N_CONTACTS, BAL_PROBE_N_SLIDING,
    BAL_PROBE_HELD_FX, BAL_PROBE_HELD_FY, BAL_PROBE_WEIGHT_X, BAL_PROBE_WEIGHT_Y,
    BAL_PROBE_CONTACT_MR, BAL_PROBE_CONTACT_THETA_R, BAL_PROBE_CONTACT_ROLLING,
    BAL_PROBE_DISSIPATED_ROLLING,
    BAL_PROBE_WALL_PX, BAL_PROBE_WALL_PY, BAL_PROBE_WALL_GAP, BAL_PROBE_WALL_STRESS,
    BAL_PROBE_COUNT
};

/* Does a probe of this kind read one wall (body a; wall_gap also b)? */
static inline int bal_probe_is_wall(int kind)
{
    return (kind >= BAL_PROBE_WALL_F1 && kind <= BAL_PROBE_WALL_ECC) ||
           (kind >= BAL_PROBE_WALL_PX && kind <= BAL_PROBE_WALL_STRESS);
}

/* Does a probe of this kind read one contact (bodies a and b)? */
static inline int bal_probe_is_contact(int kind)
{
    return kind <= BAL_PROBE_CONTACT_SLIDING ||
           (kind >= BAL_PROBE_CONTACT_MR && kind <= BAL_PROBE_CONTACT_ROLLING);
}

struct bal_probe_def {
    char name[BAL_NAME_MAX];  /* column name in series.tsv */
    int line;
    int kind;                 /* enum bal_probe_kind */
    char a[BAL_BODY_MAX];     /* first body (disc or wall name, or NAME.k) */
    char b[BAL_BODY_MAX];     /* second body, for contact probes */
    BAL_SECTION_TAIL;
};

struct bal_scene {
    char path[512];                 /* file the scene came from */
    struct bal_settings settings;
    int n_materials, n_discs, n_walls, n_fills, n_piles, n_grains, n_imports, n_stages, n_probes;
    int cap_materials, cap_discs, cap_walls, cap_fills, cap_piles, cap_grains, cap_imports,
        cap_stages, cap_probes;
    struct bal_material_def *materials;
    struct bal_disc_def *discs;
    struct bal_wall_def *walls;
    struct bal_fill_def *fills;
    struct bal_pile_def *piles;
    struct bal_grains_def *grains;
    struct bal_import_def *imports;
    struct bal_stage_def *stages;
    struct bal_probe_def *probes;
};

/* Fill s with defaults and no bodies. */
void bal_scene_default(struct bal_scene *s);
/* Read a scene file into s (which bal_scene_default has prepared). */
enum bal_status bal_scene_load(struct bal_scene *s, const char *path,
                               struct bal_error *err);
/* Read a scene from a string; `name` stands for the file in messages. */
enum bal_status bal_scene_parse(struct bal_scene *s, const char *text,
                                const char *name, struct bal_error *err);
/* Apply one override "section[.name].key=value", as from --set. */
enum bal_status bal_scene_set(struct bal_scene *s, const char *assignment,
                              struct bal_error *err);
/* Check everything once: ranges, references, stages; names file:line:key. */
enum bal_status bal_scene_validate(const struct bal_scene *s,
                                   struct bal_error *err);
/* Release what the scene owns. */
void bal_scene_free(struct bal_scene *s);
/* Print every key of every section with default, range and doc (docs/scene-format.md). */
void bal_scene_print_keys(FILE *out);
/* Print, one line "unused         KEY (WHY)" each, the keys the scene gives (in its file or
 * by an override) that the values of other keys make unused (`ballast info`; the table
 * bal_scene_unused of scene_keys.c). */
void bal_scene_print_unused(const struct bal_scene *s, FILE *out);

/* ------------------------------------------------------------------ */
/* Simulation life cycle                                               */
/* ------------------------------------------------------------------ */

struct bal_sim;

/* Build the state from a validated scene; all memory is reserved here. */
enum bal_status bal_sim_create(struct bal_sim **sim, const struct bal_scene *s,
                               struct bal_error *err);
void bal_sim_free(struct bal_sim *sim);

/* ------------------------------------------------------------------ */
/* Stepping                                                            */
/* ------------------------------------------------------------------ */

/* Per-run counters and timings. */
struct bal_run_info {
    long steps;               /* cycles completed */
    double time;              /* simulated time */
    double dt;                /* time step used */
    double dt_estimate;       /* critical-step estimate */
    double dt_fraction;       /* dt / dt_estimate */
    double wall_seconds;      /* wall-clock time spent stepping */
    long rebuilds;            /* neighbour-list rebuilds */
    double skin;              /* the Verlet skin of the last rebuild */
    int grid_used;            /* 1 when the cell grid is in use */
    int n_discs, n_walls;
    long n_candidates;        /* candidate disc–disc pairs (last rebuild) */
};

/* The energy audit of a run, from the first cycle (energy.c):
 * work_walls + work_gravity = (kinetic - kinetic0) + (elastic - elastic0)
 *                             + dissipated_* + imbalance. */
struct bal_energy {
    int started;                  /* 0 before the first cycle: all zero */
    long from_step;               /* step of the baseline */
    double kinetic0, elastic0;    /* E_k, E_el at the baseline */
    double kinetic, elastic;      /* now */
    double work_walls, work_gravity;
    double dissipated_dashpot, dissipated_friction, dissipated_global;
    double dissipated_rolling;    /* plastic rolling (Model 1), lost rolling springs (Model 2) */
    double imbalance;             /* > 0: energy lost unaccounted; < 0: created */
    double throughput;            /* kinetic0 + elastic0 + |work_walls| + |work_gravity| */
    double relative;              /* |imbalance| / throughput */
};

/* The audit now. */
void bal_energy_report(const struct bal_sim *sim, struct bal_energy *e);

/* Add wall-clock seconds spent on the simulation outside bal_sim_run (the
 * exact solver's solve), reported as run.json's wall_seconds. */
void bal_sim_add_seconds(struct bal_sim *sim, double seconds);

/* Advance one cycle (C&S calculation cycle): move discs and walls to t_N,
 * find contacts, apply the force–displacement law at t_N, update the
 * velocities to t_{N+1/2}.  The scene must outlive the simulation. */
enum bal_status bal_sim_step(struct bal_sim *sim, struct bal_error *err);

/* Select stage `stage` (index into the scene's stages): its walls'
 * controllers and their parameters. */
void bal_sim_set_stage(struct bal_sim *sim, int stage);
/* Run the cycles on this many threads (1, the default, to BAL_MAX_THREADS;
 * OpenMP).  The results are bitwise those of one thread. */
#define BAL_MAX_THREADS 16
enum bal_status bal_sim_set_threads(struct bal_sim *sim, int threads, struct bal_error *err);

/* Run every stage of the loading protocol, writing a row to `series` (may be
 * NULL) every output_every cycles.  `stop` (may be NULL) is polled between
 * cycles; when it becomes non-zero the run ends with BAL_EINTR. */
enum bal_status bal_sim_run(struct bal_sim *sim, FILE *series,
                            volatile const sig_atomic_t *stop, struct bal_error *err);

/* Snapshots (settings.snapshot_every or snapshot_dt): bal_sim_run writes the state's frames
 * into dir/snapshots (made here; snapshots.c), the first of the state it starts from, the
 * last of the final state of a run that completes.  Without this call, or for a scene
 * without snapshots (then nothing is made), it writes none. */
enum bal_status bal_sim_set_snapshots(struct bal_sim *sim, const char *dir, struct bal_error *err);

/* The cycles stage g runs at most: its `cycles`, or ceil(time/dt) for a
 * stage given in simulated time (to 1e-9 of a step: a time that is a whole
 * number of steps in exact arithmetic is that number of cycles). */
long bal_sim_stage_cycles(const struct bal_sim *sim, int stage);
/* 1: stage g was given in simulated time (`time`), 0: in cycles. */
int bal_sim_stage_in_time(const struct bal_sim *sim, int stage);

/* What a progress report sees: the stage running, its cycles so far and at
 * most, the cycles and the simulated time of the whole run so far. */
struct bal_progress {
    int stage, n_stages;
    const char *stage_name;
    long stage_cycle, stage_cycles;
    long step, steps;            /* the run's cycles so far, and at most */
    double time, wall_seconds;
};
/* Call `report` from bal_sim_run about every `seconds` of wall-clock time
 * (the clock is read once every 1024 cycles; NULL: no reports).  The
 * callback only reads; the simulation's results do not depend on it. */
void bal_sim_set_progress(struct bal_sim *sim, void (*report)(const struct bal_progress *, void *),
                          void *ctx, double seconds);

void bal_sim_info(const struct bal_sim *sim, struct bal_run_info *info);
/* Bytes the simulation holds while it steps (every array at its allocated
 * capacity), split into what scales with discs and with candidate pairs. */
void bal_sim_memory(const struct bal_sim *sim, double *disc_bytes, double *pair_bytes);
/* For callers that see the simulation only through this header (the
 * command writing the exact solver's contacts): the scene-order index of
 * the disc in array slot i; the name of wall k; the C&S contact point of
 * disc i with disc j, or with wall j when is_wall (as in contacts.tsv). */
int bal_sim_disc_id(const struct bal_sim *sim, int i);
const char *bal_sim_wall_name(const struct bal_sim *sim, int k);
void bal_sim_contact_point(const struct bal_sim *sim, int i, int is_wall, int j, double *px,
                           double *py);

/* The critical-step estimate and how it was reached (timestep.c). */
struct bal_dt_detail {
    double estimate;          /* contact-network bound: the step dt_fraction scales */
    double single_spring;     /* C&S p. 53, 2 sqrt(m/k) of the stiffest single spring */
    long contacts;            /* contacts at the start (gap <= 1 % of the smaller radius) */
    int coordination_discs;   /* free discs without any, bounded by their coordination */
    int binding_disc;         /* scene-order index of the disc that sets the estimate (-1:
                               * the network's spectral bound sets it) */
    int spectral;             /* 1: the spectral bound of the start network was the better */
    double omega, zeta;       /* its frequency bound and damping ratio */
};
void bal_sim_dt_detail(const struct bal_sim *sim, struct bal_dt_detail *d);

/* ------------------------------------------------------------------ */
/* Measurements                                                        */
/* ------------------------------------------------------------------ */

/* The value of probe k of the scene (its index in file order) at the
 * current cycle (probes.c). */
double bal_probes_value(const struct bal_sim *sim, int k);
double bal_measure_kinetic(const struct bal_sim *sim);
double bal_measure_elastic(const struct bal_sim *sim);
/* ΔF/F of C&S Tables 1–3: largest force sum on any free disc over the
 * largest contact force (0 when there is no contact). */
double bal_measure_unbalanced(const struct bal_sim *sim);

/* ------------------------------------------------------------------ */
/* Output                                                              */
/* ------------------------------------------------------------------ */

/* Write the series header (cycle, time, probe names) / one row. */
void bal_output_series_header(const struct bal_sim *sim, FILE *f);
/* The row is written only when every probe value is finite; otherwise
 * BAL_EUNSTABLE names the probe (file:line). */
enum bal_status bal_output_series_row(const struct bal_sim *sim, FILE *f, struct bal_error *err);
/* Name of disc `id` (scene order): its [disc] name, or FILL.k. */
void bal_output_disc_name(const struct bal_sim *sim, int id, char *buf, size_t size);
/* Write contacts.tsv, discs.tsv and walls.tsv of the final state into dir. */
enum bal_status bal_output_state(const struct bal_sim *sim, const char *dir,
                                 struct bal_error *err);

/* Write run.json into dir (via a temporary name): version, build, scene,
 * the --set overrides, how the run ended, steps, time step and estimate,
 * timings and energies.  `sim` may be NULL when the run never started. */
enum bal_status bal_output_run_json(const struct bal_sim *sim, const char *dir,
                                    const char *scene_path, int n_sets,
                                    char *const *sets, enum bal_status status,
                                    const char *message, struct bal_error *err);

/* Remove dir/snapshots, the snapshots of an earlier or a failed run (the files snapshots.c
 * writes, then the folder if that empties it). */
void bal_output_remove_snapshots(const char *dir);

/* Rename dir/name.tmp to dir/name: outputs appear only when complete. */
enum bal_status bal_output_commit(const char *dir, const char *name,
                                  struct bal_error *err);

#endif /* BALLAST_H */
