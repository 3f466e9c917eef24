/*
 * energy.c — the energy audit of a run, and the guards that stop a run
 * whose energy runs away or whose overlaps exceed the budget.
 *
 * Balance, from the start (t_0, before the first cycle) to now:
 *
 *   W_walls + W_gravity = ΔE_k + ΔE_el + D_dashpot + D_friction + D_global
 *                         + D_rolling
 *                         + imbalance
 *
 *   E_k        Σ ½ m v_N² + ½ I ω_N², v_N the centred velocity (C&S eq. 31)
 *   E_el       stored in the contact springs: ½ F_n²/k_n (incremental law) or
 *              ∫ F_n dδ = k_n δ0² (δ/δ0)^(ν+1)/(ν+1) (power law), + ½ F_s²/k_s,
 *              + ½ M²/K_m of the rolling springs (JYH eq. 28)
 *   W_walls    Σ_cycles −(F̄·V + M̄ ω) Δt over the walls, F and M the resultant
 *              and moment about P of the discs' forces on the wall, F̄ the
 *              mean of their values at the two ends of the cycle
 *   W_gravity  Σ_cycles ḡ_fac m g·(x_N − x_{N−1}), ḡ_fac the mean of the
 *              factors at t_{N−1} and t_N; summed per interval of constant
 *              g_fac as g_fac m g·Δ(centre of mass)
 *   D_dashpot  Σ_cycles (D_n ṅ_N + D_s ṡ_N) Δt (C&S eqs 26–28, MLH eq. 3):
 *              the work of the dashpot forces on the motion at t_N, from
 *              their per-disc sums; the latest cycle counts half
 *   D_friction Σ_cycles F_max |slip|, slip = (|F_s trial| − F_max)/k_s, where
 *              the Coulomb limit (eq. 19) cuts the shear force
 *   D_rolling  Σ_cycles M_0 |plastic rolling| where Model 1 caps the rolling
 *              moment (JYH eq. 35), and M²/(2 K_m) of each rolling spring
 *              Model 2 breaks (eq. 36); the rolling dashpot (eq. 49c) is a
 *              contact dashpot, in D_dashpot
 *   D_global   Σ_cycles α (m v_N² + I ω_N²) Δt: eqs (35)–(36) are
 *              m (v_{N+1/2} − v_{N−1/2})/Δt = F − α m v_N; the latest
 *              cycle counts half (it is centred on the end)
 *
 * The imbalance is what the time discretisation creates or destroys (the
 * centred scheme conserves a shadow energy, not E_k + E_el), plus what the
 * contact law's choices do: a contact that opens with F_n > 0 under the
 * incremental law loses ½ F_n²/k_n.  It is reported, never hidden, and the
 * harness gates its share of the energy that went through the run.
 * Dissipation terms are separate fields, so a later one (rolling
 * resistance) adds a field and a term.
 */
#include <math.h>
#include <stdio.h>

#include "energy.h"
#include "integrate.h"
#include "measure.h"
#include "pairs.h"
#include "specimen.h"

/* Σ m g·x over the free discs (held discs do not move). */
static double gravity_potential(const struct bal_sim *s)
{
    double e = 0;
    for (int i = 0; i < s->n; i++)
        if (!s->fixed[i])
            e += bal_mass(s, i) * (s->g[0] * s->x[i] + s->g[1] * s->y[i]);
    return e;
}

static double global_loss(const struct bal_sim *s);
static double dashpot_loss(const struct bal_sim *s);

/* The kinetic energy at t_0.  The centred scheme holds v_{1/2}: before any
 * contact force exists v_0 = v_{1/2} − g_fac g Δt/2 (exact in free flight);
 * the other integrators hold v_0 itself. */
static double start_kinetic(const struct bal_sim *s)
{
    const double half = s->integ->staggered ? 0.5 * s->gfac * s->dt : 0;
    double e = 0;
    for (int i = 0; i < s->n; i++) {
        const double h = s->fixed[i] ? 0 : half;
        double vx = s->vx[i] - h * s->g[0], vy = s->vy[i] - h * s->g[1];
        const unsigned held = s->hold ? s->hold[i] : 0; /* held components never move */
        if (held & BAL_HOLD_X)
            vx = 0;
        if (held & BAL_HOLD_Y)
            vy = 0;
        e += 0.5 * bal_mass(s, i) * (vx * vx + vy * vy) + 0.5 * bal_inertia(s, i) * s->w[i] * s->w[i];
    }
    return e;
}

/* The elastic energy at t_0: the power law's force is a function of the
 * overlap, so overlapping bodies (allowed by the scene) hold it already; the
 * incremental law starts every contact from F_n = 0 (no history): none. */
static double start_elastic(const struct bal_sim *s)
{
    if (s->normal_law != BAL_NORMAL_POWER)
        return 0;
    double e = 0;
    for (int walls = 0; walls < 2; walls++) {
        const struct bal_pairs *p = walls ? &s->pw : &s->pp;
        for (long c = 0; c < p->n; c++) {
            double rmin;
            const struct bal_pair_law *law;
            const double delta = bal_pairs_overlap(s, walls, c, &rmin, &law);
            if (delta > 0)
                e += bal_measure_normal_energy(s, law, 0, delta);
        }
    }
    return e;
}

/* The baseline at t_0, before the first cycle moves anything: every cycle
 * is then counted, the first included (where an impact that starts in
 * contact gains or loses most). */
void bal_energy_begin(struct bal_sim *s)
{
    struct bal_audit *a = &s->audit;
    *a = (struct bal_audit){0};
    a->started = 1;
    a->start_step = s->step;
    a->ek0 = start_kinetic(s);
    a->ee0 = start_elastic(s);
    a->gravity = s->g[0] != 0 || s->g[1] != 0;
    a->g_last = a->gravity ? gravity_potential(s) : 0;
    a->gfac_last = s->gfac;
    for (int k = 0; k < s->n_walls; k++) {
        struct bal_wall *W = &s->walls[k];
        W->f_prev[0] = W->f_prev[1] = W->moment_prev = 0; /* no force before the first cycle */
    }
}

/* g_fac changes at this cycle N (a ramp): the interval of constant g_fac
 * ends at x_{N-1}, the positions before the cycle moves them; the step
 * x_{N-1} -> x_N then feels the mean of the factors at its two ends (the
 * trapezoid rule, as for the walls: E_k at t_N balances it to
 * O(Δt² Δg_fac)).  Positions only: the same for every integrator. */
void bal_energy_gravity_before(struct bal_sim *s)
{
    struct bal_audit *a = &s->audit;
    if (!a->started || !a->gravity || s->gfac == a->gfac_last)
        return;
    const double before = gravity_potential(s);
    a->w_gravity += a->gfac_last * (before - a->g_last);
    a->g_last = before;
    a->gravity_step = 1;
}

void bal_energy_gravity(struct bal_sim *s)
{
    struct bal_audit *a = &s->audit;
    if (!a->gravity_step)
        return;
    const double now = gravity_potential(s);
    a->w_gravity += 0.5 * (a->gfac_last + s->gfac) * (now - a->g_last);
    a->g_last = now;
    a->gfac_last = s->gfac;
    a->gravity_step = 0;
}

/* The walls moved from t_{N-1} to t_N with their current velocities; the
 * force on them went from F_{N-1} to F_N: the trapezoid rule, exact for a
 * linear spring (the rectangle rule errs by ½ F_N V Δt a cycle, 1/M of the
 * work after M cycles of loading). */
void bal_energy_walls(struct bal_sim *s)
{
    double w = 0;
    for (int k = 0; k < s->n_walls; k++) {
        struct bal_wall *W = &s->walls[k];
        w -= 0.5 * ((W->f[0] + W->f_prev[0]) * W->v[0] + (W->f[1] + W->f_prev[1]) * W->v[1] +
                    (W->moment + W->moment_prev) * W->omega);
        W->f_prev[0] = W->f[0];
        W->f_prev[1] = W->f[1];
        W->moment_prev = W->moment;
    }
    s->audit.w_walls += w * s->dt;
}

/* The loss of this cycle, α (m v_N² + I ω_N²) Δt, is centred at t_N: half
 * of it belongs before t_N, half after.  The audit counts half of the first
 * cycle's and takes back half of the latest (bal_energy_report). */
void bal_energy_global(struct bal_sim *s)
{
    if (s->alpha == 0)
        return;
    const double loss = global_loss(s);
    s->audit.d_global += loss;
    s->audit.d_global_last = loss;
}

/* The contact dashpots' loss in this cycle: the work their forces D do on
 * the motion at t_N, Σ_c (D_n ṅ_N + D_s ṡ_N) Δt = −Σ_i (F^D_i·v_N + M^D_i ω_N) Δt
 * − Σ_wall contacts D·V_wall Δt.  Their forces use the velocity half a step
 * old (C&S eqs 26–27), so the loss measured with that old velocity would
 * differ from the work they really do by O(Δt): the audit counts the work. */
static double dashpot_loss(const struct bal_sim *s)
{
    double p = 0;
    if (s->integ->staggered) /* the centred update summed it in its own pass */
        return -(s->audit.dash_sum + s->audit.wall_dash) * s->dt;
    for (int i = 0; i < s->n; i++) {
        double vx, vy, w;
        bal_measure_velocity(s, i, &vx, &vy, &w);
        p += (double)s->dash[3 * i] * vx + (double)s->dash[3 * i + 1] * vy +
             (double)s->dash[3 * i + 2] * w;
    }
    return -(p + s->audit.wall_dash) * s->dt;
}

void bal_energy_dashpots(struct bal_sim *s)
{
    if (!s->dash)
        return;
    const double loss = dashpot_loss(s);
    s->audit.d_dashpot += loss;
    s->audit.d_dashpot_last = loss;
}

static double global_loss(const struct bal_sim *s)
{
    if (s->integ->staggered) /* the centred update summed it in its own pass */
        return s->alpha * s->audit.glob_sum * s->dt;
    double d = 0;
    for (int i = 0; i < s->n; i++) {
        if (s->fixed[i])
            continue;
        double vx, vy, w;
        bal_measure_velocity(s, i, &vx, &vy, &w); /* v_N, whatever the integrator */
        d += bal_mass(s, i) * (vx * vx + vy * vy) + bal_inertia(s, i) * w * w;
    }
    return s->alpha * d * s->dt;
}

void bal_energy_report(const struct bal_sim *s, struct bal_energy *e)
{
    const struct bal_audit *a = &s->audit;
    *e = (struct bal_energy){0};
    if (!a->started)
        return;
    e->started = 1;
    e->from_step = a->start_step;
    e->kinetic0 = a->ek0;
    e->elastic0 = a->ee0;
    e->kinetic = bal_measure_kinetic(s);
    e->elastic = bal_measure_elastic(s);
    e->work_walls = a->w_walls;
    e->work_gravity = a->w_gravity;
    if (a->gravity)
        e->work_gravity += a->gfac_last * (gravity_potential(s) - a->g_last);
    e->dissipated_dashpot = a->d_dashpot - 0.5 * a->d_dashpot_last;
    e->dissipated_friction = a->d_friction;
    e->dissipated_rolling = a->d_rolling;
    e->dissipated_global = a->d_global - 0.5 * a->d_global_last;
    e->imbalance = e->work_walls + e->work_gravity -
                   (e->kinetic - e->kinetic0 + e->elastic - e->elastic0 + e->dissipated_dashpot +
                    e->dissipated_friction + e->dissipated_global + e->dissipated_rolling);
    /* The energy that went through the run: what it started with and every
     * work and loss, each counted once. */
    e->throughput = e->kinetic0 + e->elastic0 + fabs(e->work_walls) + fabs(e->work_gravity);
    e->relative = e->throughput > 0 ? fabs(e->imbalance) / e->throughput
                                    : (e->imbalance == 0 ? 0 : INFINITY);
}

/* Why the audit is not finite: the first disc whose share of the gravity
 * potential, or contact whose stored energy, overflows; else the audit's
 * running sums (the kinetic energies are finite: check_finite ran first). */
static enum bal_status audit_not_finite(const struct bal_sim *s, const struct bal_energy *e,
                                        struct bal_error *err)
{
    for (int i = 0; i < s->n; i++) {
        if (s->fixed[i] || isfinite(bal_mass(s, i) * (s->g[0] * s->x[i] + s->g[1] * s->y[i])))
            continue;
        char name[2 * BAL_NAME_MAX];
        bal_specimen_disc_name(s->scene, s->id[i], name, sizeof name);
        return bal_error(err, BAL_EUNSTABLE,
                         "%s: disc %s: its gravity potential m g.x is not finite at step %ld "
                         "(gravity or position near the limits of a double?)",
                         s->scene->path, name, s->step);
    }
    for (int walls = 0; walls < 2; walls++) {
        const struct bal_pairs *p = walls ? &s->pw : &s->pp;
        for (long c = 0; c < p->n; c++) {
            if (!(p->flags[c] & BAL_PAIR_TOUCHING))
                continue;
            double rmin;
            const struct bal_pair_law *L;
            const double delta = bal_pairs_overlap(s, walls, c, &rmin, &L);
            const double fs = pair_fs(p, c);
            if (isfinite(bal_measure_normal_energy(s, L, p->fn[c], delta) + fs * fs / L->ks))
                continue;
            char a[2 * BAL_NAME_MAX], b[3 * BAL_NAME_MAX];
            bal_pairs_names(s, walls, c, a, sizeof a, b, sizeof b);
            return bal_error(err, BAL_EUNSTABLE,
                             "%s: the energy stored in the contact of disc %s and %s is not "
                             "finite at step %ld (force %g: stiffness or load near the limits "
                             "of a double?)",
                             s->scene->path, a, b, s->step, p->fn[c]);
        }
    }
    return bal_error(err, BAL_EUNSTABLE,
                     "%s: the energy audit is not finite at step %ld (work of the walls %g, of "
                     "gravity %g; dissipated %g, %g, %g): values near the limits of a double?",
                     s->scene->path, s->step, e->work_walls, e->work_gravity,
                     e->dissipated_dashpot, e->dissipated_friction, e->dissipated_global);
}

enum bal_status bal_energy_guard(const struct bal_sim *s, struct bal_error *err)
{
    if (!s->audit.started)
        return BAL_OK;
    struct bal_energy e;
    bal_energy_report(s, &e);
    /* Every term the run writes (run.json, the energy probes) must be a
     * number, whether or not the runaway guard is on. */
    const double terms[] = {e.kinetic0, e.elastic0, e.kinetic, e.elastic, e.work_walls,
                            e.work_gravity, e.dissipated_dashpot, e.dissipated_friction,
                            e.dissipated_global, e.dissipated_rolling, e.imbalance, e.throughput};
    for (size_t k = 0; k < sizeof terms / sizeof terms[0]; k++)
        if (!isfinite(terms[k]))
            return audit_not_finite(s, &e, err);
    const double limit = s->scene->settings.energy_guard;
    if (limit <= 0)
        return BAL_OK;
    /* Created energy (a negative imbalance) beyond `limit` times what went
     * through the run: the scheme is feeding the motion. */
    if (-e.imbalance > limit * e.throughput && -e.imbalance > 0)
        return bal_error(err, BAL_EUNSTABLE,
                         "%s: energy runaway at step %ld: the run created %.6g of energy, %.3g "
                         "times the %.6g that went through it (limit %g, settings.energy_guard); "
                         "E_k = %.6g, E_el = %.6g (time step too large for the stiffness?)",
                         s->scene->path, s->step, -e.imbalance,
                         e.throughput > 0 ? -e.imbalance / e.throughput : INFINITY, e.throughput,
                         limit, e.kinetic, e.elastic);
    return BAL_OK;
}

/* The contact of list p with the largest overlap relative to its smaller
 * radius, after a contact loop flagged one beyond the budget. */
enum bal_status bal_energy_overlap(const struct bal_sim *s, struct bal_error *err)
{
    const double budget = s->scene->settings.overlap_budget;
    double worst = -1, share = 0;
    long wc = -1;
    int wall = 0;
    for (int walls = 0; walls < 2; walls++) {
        const struct bal_pairs *p = walls ? &s->pw : &s->pp;
        for (long c = 0; c < p->n; c++) {
            double rmin;
            const struct bal_pair_law *law;
            const double delta = bal_pairs_overlap(s, walls, c, &rmin, &law);
            if (delta / rmin > worst) {
                worst = delta / rmin;
                share = delta;
                wc = c;
                wall = walls;
            }
        }
    }
    if (wc < 0 || worst <= budget)
        return BAL_OK; /* only the sieve was passed: no pair is beyond its own budget */
    char a[2 * BAL_NAME_MAX], b[3 * BAL_NAME_MAX];
    bal_pairs_names(s, wall, wc, a, sizeof a, b, sizeof b);
    return bal_error(err, BAL_EUNSTABLE,
                     "%s: overlap beyond the budget at step %ld: disc %s and %s overlap by %.6g, "
                     "%.3g of the smaller radius (limit %g, settings.overlap_budget) "
                     "(impact too fast or time step too large for the stiffness?)",
                     s->scene->path, s->step, a, b, share, worst, budget);
}
