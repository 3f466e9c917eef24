/*
 * sim.h — internal: the module interfaces of the step pipeline (being split
 * into one header per module).
 */
#ifndef BAL_SIM_H
#define BAL_SIM_H

#include "pairs.h"
#include "specimen.h"
#include "state.h"
#include "walls.h"

/* contacts.c */
bal_pair_loop_fn bal_contacts_select(int normal_law, int shear, int damping);
/* Cut the disc–disc list into ranges for s->par.threads threads (the pair
 * loop calls it after each rebuild); free what the threads hold. */
void bal_par_plan(struct bal_sim *s);
void bal_par_free(struct bal_par *par);
void bal_contacts_walls(struct bal_sim *s);
/* The coefficient γ_n (δ/δ0)^ψ of MLH eq. (3) at overlap δ, as the loops
 * compute it (for the dashpots that measure.c recomputes). */
double bal_contacts_viscous(const struct bal_sim *s, double delta);

/* grid.c */
enum bal_status bal_grid_rebuild(struct bal_sim *s, struct bal_error *err);
/* Do the lists still hold every contact, after the discs moved by `moved`
 * (the position pass's; each block's in par.block_sums) and the walls by
 * their `disp`?  1: a rebuild is due (or the search cannot tell cheaply);
 * always 0 without the grid, whose one list holds every pair. */
int bal_grid_due(const struct bal_sim *s, struct bal_moves moved);
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

/* integrate.c */
/* A law of motion (integrate.c), chosen once by settings.integrator.  A
 * cycle calls `positions` before the force evaluation and `velocities`
 * after it; `previous` gives the velocities the contact law read in the last
 * cycle (for recomputing dashpot forces).  `staggered`: after a cycle the
 * stored velocities are v_{N+1/2}, so measurements at t_N average them with
 * `previous` (C&S eq. 31); otherwise the stored velocities are v_N. */
struct bal_integrator_type {
    const char *name;
    struct bal_moves (*positions)(struct bal_sim *s);
    void (*velocities)(struct bal_sim *s);
    void (*previous)(const struct bal_sim *s, int i, double *vx, double *vy, double *w);
    int staggered;
};

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
/* The two halves of the law of motion of s->integ (one dispatch each); the
 * first returns how far the discs have moved since the lists were built. */
struct bal_moves bal_integrate_positions(struct bal_sim *s);
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
/* The dashpot forces D_n, D_s of contact c of list p in the last cycle:
 * stored for walls, recomputed for disc pairs from the geometry at t_N and
 * the velocities v_{N-1/2} (recovered), exactly as the cycle computed them.
 * Zero for a contact that is not touching. */
void bal_measure_dashpots(const struct bal_sim *s, const struct bal_pairs *p, long c, double *dn,
                          double *ds);
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
void bal_sim_contact_point(const struct bal_sim *s, int i, int is_wall, int j, double *px,
                           double *py);
/* Bytes the simulation holds while it steps (every array at its allocated
 * capacity), split into what scales with discs and with candidate pairs. */
void bal_sim_memory(const struct bal_sim *s, double *disc_bytes, double *pair_bytes);

#endif /* BAL_SIM_H */
