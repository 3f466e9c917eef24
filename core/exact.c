/*
 * exact.c — the exact static solver for stiff frictionless disc networks
 * (Matuttis, Luding & Herrmann 2000, Sec. 4.2); the interface and the
 * problem are described in exact.h.
 *
 * Kept whole (about 870 lines): one algorithm, the active-set and damped
 * Newton solve of one banded system, whose parts serve only each other.
 *
 * The network.  Every candidate pair of the simulation (s->pp, s->pw) whose
 * gap is at most BAL_EXACT_TOUCH r_max (overlaps included) and that has at
 * least one free body is a contact.  Pairs of two held bodies are left out:
 * neither moves, so their force is not determined by the free discs (and
 * takes no part in the balance of any free disc).  Friction and cohesion
 * are refused on these contacts only.
 *
 * The equations.  For contact c between body i and body j with unit normal
 * n from i to j, the approach is δ_c = (u_i − u_j)·n = b_cᵀ u (u_j = 0 for
 * a held disc or a wall), and a closed contact carries F_c = k_c δ_c,
 * pushing i along −n and j along +n.  The balance of every free disc,
 * Σ_c −F_c n + m g = 0, is K u = f with K = Σ_closed k_c b_c b_cᵀ and
 * f = m g.  Scaling every k_c by λ scales u by 1/λ and leaves F_c
 * unchanged: the forces are those of the stiff limit (exact.h).
 *
 * Unilateral contacts.  The solution minimises the convex potential
 *     E(u) = ½ Σ_c k_c max(δ_c, 0)² − f·u,
 * whose forces F_c = k_c max(δ_c, 0) are unique (each max(δ_c, 0) is
 * constant on the convex set of minima).  Two phases find it:
 *
 * 1. Primal–dual active set (full Newton steps on E).  Start with every
 *    contact closed; solve K u = f; open every closed contact with
 *    F_c < −tol (tension), close every open one with k_c δ_c > tol (it
 *    would penetrate); repeat until nothing changes.  tol = FORCE_TOL times
 *    the total weight, so round-off on a contact whose exact force is zero
 *    cannot flip it back and forth.  This takes a handful of solves (8 for
 *    the 1717-disc pile) but is not guaranteed to: it can cycle, and a
 *    step that opens several contacts at once can leave a mechanism (K
 *    singular) although the problem has a solution.
 * 2. When a set of open contacts repeats (compared by a 64-bit hash) or K
 *    becomes singular after the first solve, the iteration continues from
 *    the last solution by damped Newton steps on E: the step d solves
 *    K_A d = −∇E (A: the contacts not in tension), with K_A + REGULARISATION
 *    K_rest in its place when K_A is singular (still positive definite: the
 *    all-closed K was), and the step length minimises E exactly along d (E
 *    is piecewise quadratic in the step: a sweep over the sorted points
 *    where contacts open or close).  E decreases at every step, so nothing
 *    repeats.  When the imbalance |∇E| of every free disc is below tol,
 *    phase 1 takes over again from that set of contacts, and its exact
 *    solve gives the forces to round-off.  A step along which E falls
 *    without bound means that no compressive force network carries the
 *    load: BAL_EINVAL.  MAX_ITERATIONS solves in all, then BAL_EINVAL.
 *
 * The linear algebra.  Unknowns are (x, y) of the free discs in array
 * order (the cell order of the simulation, row by row), so K is banded
 * with half-bandwidth p = max over disc–disc contacts of 2 |a − b| + 1
 * (a, b the discs' numbers among the free discs).  It is stored as GSL's
 * symmetric band matrix, N × (p + 1) with A(j, d) = K(j + d, j), and
 * factorised with gsl_linalg_cholesky_band_decomp: O(N p²) per solve.
 * A mechanism (K singular: a free disc, or a group of them, that can move
 * without deforming any closed contact) shows as a non-positive pivot or a
 * pivot that round-off alone produced (L_jj² < PIVOT_TOL K_jj); the message
 * names the free disc of that unknown.  The simplest mechanism — a free
 * disc whose closed contacts do not span the plane — is found before the
 * factorisation and named directly.  A mechanism of the all-closed network,
 * or of the final set of closed contacts (a disc in neutral equilibrium,
 * such as a disc alone on a frictionless floor), is refused (BAL_EINVAL).
 *
 * All memory is allocated here with malloc and freed on every path; GSL
 * sees only views of it (gsl_matrix_view_array), so no GSL allocation can
 * fail.  No global state of the core is touched; see factor() for GSL's
 * error handler.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_vector.h>

#include "exact.h"
#include "scene_keys.h"
#include "specimen.h"
#include "status.h"
#include "walls.h"

/* Most solves (factorisations of K) of the whole iteration.  Phase 1 takes
 * a handful; phase 2 about one per contact it has to change. */
#define MAX_ITERATIONS 1000

/* A closed contact is tensile when F_c < −FORCE_TOL W and an open one
 * penetrates when k_c δ_c > FORCE_TOL W, W = Σ |m g| over the free discs;
 * phase 2 has converged when no free disc is out of balance by more than
 * FORCE_TOL W.  Far above the round-off of a solve (~1e-16 times the
 * condition number of K times W) and far below any force the network
 * carries. */
#define FORCE_TOL 1e-9

/* A Cholesky pivot with L_jj² < PIVOT_TOL K_jj is round-off of a zero
 * pivot: K is singular (a mechanism).  Genuine pivots of a rigid network
 * are a fair share of the diagonal (the network is rigid, not nearly so). */
#define PIVOT_TOL 1e-10

/* A free disc's closed-contact normals span the plane when
 * det(Σ n nᵀ) > SPAN_TOL (tr Σ n nᵀ)²; det = Σ_{a<b} (n_a × n_b)², so this
 * refuses normals parallel to within about 3e-5 rad. */
#define SPAN_TOL 1e-9

/* Share of their stiffness the contacts outside A keep in the matrix of a
 * phase-2 step when K_A alone is singular: large enough that its pivots
 * stay far above PIVOT_TOL, small enough that the step follows K_A. */
#define REGULARISATION 1e-4

/* A contact's normal stiffness counted in K: closed, or a share of it. */
enum { OPEN_WEIGHTLESS = 0, OPEN_REGULARISED = 1 };

/* A point along a phase-2 step where a contact opens or closes. */
struct event {
    double t;
    long c;
};

/* The working state of one solve. */
struct work {
    long nc;                        /* contacts */
    struct bal_exact_contact *c;    /* the contacts (become out->contacts) */
    double *k;                      /* stiffness of each contact */
    int32_t *ui, *uj;               /* first unknown of body i / j, -1 if it does not move */
    uint8_t *closed;                /* contacts in K */
    double *delta;                  /* approach b_c·u of the current u */
    double *edir;                   /* b_c·d of a phase-2 step d */
    double *force;                  /* k_c δ_c (signed) of the current u */
    struct event *events;           /* line-search scratch */
    int32_t *unknown;               /* first unknown of slot i, -1 for held discs */
    int32_t *free_slot;             /* slot of the a-th free disc */
    int nf;                         /* free discs */
    size_t nu;                      /* unknowns, 2 nf */
    size_t p;                       /* half-bandwidth */
    double *band;                   /* nu × (p + 1) */
    double *diag;                   /* K_jj before factorising */
    double *f;                      /* m g of the free discs */
    double *u;                      /* current displacements */
    double *grad, *dir;             /* ∇E and the step of phase 2 */
    double *span;                   /* Σ n nᵀ (xx, xy, yy) per free disc, scratch */
    uint64_t *seen;                 /* hashes of the open sets of phase 1 */
    int n_seen;
};

static void work_free(struct work *w)
{
    free(w->c);
    free(w->k);
    free(w->ui);
    free(w->uj);
    free(w->closed);
    free(w->delta);
    free(w->edir);
    free(w->force);
    free(w->events);
    free(w->unknown);
    free(w->free_slot);
    free(w->band);
    free(w->diag);
    free(w->f);
    free(w->u);
    free(w->grad);
    free(w->dir);
    free(w->span);
    free(w->seen);
    memset(w, 0, sizeof *w);
}

static const char *scene_path(const struct bal_sim *s)
{
    return s->scene ? s->scene->path : "?";
}

static void disc_name(const struct bal_sim *s, int slot, char *buf, size_t size)
{
    bal_specimen_disc_name(s->scene, s->id[slot], buf, size);
}

/* Room for a disc name ("NAME" or "FILL.k") or "wall 'NAME'". */
#define NAME_BUF (2 * BAL_NAME_MAX + 32)

/* The second body of contact c, as "disc 'a'" or "wall 'w'", for messages. */
static void other_body(const struct bal_sim *s, const struct bal_exact_contact *c, char *buf)
{
    if (c->is_wall) {
        snprintf(buf, NAME_BUF, "wall '%.*s'", BAL_NAME_MAX, s->walls[c->j].name);
    } else {
        char nm[NAME_BUF];
        disc_name(s, c->j, nm, sizeof nm);
        snprintf(buf, NAME_BUF, "disc '%.*s'", 2 * BAL_NAME_MAX, nm);
    }
}

static int contact_cmp(const void *pa, const void *pb)
{
    const struct bal_exact_contact *a = pa, *b = pb;
    if (a->i != b->i)
        return a->i < b->i ? -1 : 1;
    if (a->is_wall != b->is_wall)
        return a->is_wall < b->is_wall ? -1 : 1;
    return (a->j > b->j) - (a->j < b->j);
}

static void *alloc_array(size_t n, size_t size, int *ok)
{
    void *p = calloc(n ? n : 1, size);
    if (!p)
        *ok = 0;
    return p;
}

/* ------------------------------------------------------------------ */
/* The network                                                         */
/* ------------------------------------------------------------------ */

/* Append contact (i, j) to w->c if it touches; refuses coincident centres
 * and pairs with friction or cohesion. */
static enum bal_status add_contact(const struct bal_sim *s, struct work *w, long *cap, int i,
                                   int j, int is_wall, struct bal_error *err)
{
    const double touch = BAL_EXACT_TOUCH * s->r_max;
    double nx, ny, gap;
    int mat_j;
    if (!is_wall) {
        const double dx = s->x[j] - s->x[i], dy = s->y[j] - s->y[i];
        const double dist = sqrt(dx * dx + dy * dy);
        gap = dist - (s->r[i] + s->r[j]);
        if (gap > touch)
            return BAL_OK;
        if (!(dist > 0)) {
            char a[NAME_BUF], b[NAME_BUF];
            disc_name(s, i, a, sizeof a);
            disc_name(s, j, b, sizeof b);
            return bal_error(err, BAL_EINVAL,
                             "%s: exact solver: discs '%s' and '%s' have the same centre: "
                             "their contact has no normal",
                             scene_path(s), a, b);
        }
        nx = dx / dist;
        ny = dy / dist;
        mat_j = s->mat[j];
    } else {
        const struct bal_wall *W = &s->walls[j];
        double cx, cy;
        const double dist = sqrt(bal_walls_closest(W, s->x[i], s->y[i], &cx, &cy));
        gap = dist - s->r[i];
        if (gap > touch)
            return BAL_OK;
        if (dist > 0) {
            nx = (cx - s->x[i]) / dist;
            ny = (cy - s->y[i]) / dist;
        } else {
            /* Centre on the wall: its normal, as the contact law does (wall_loop.c). */
            nx = -W->e[1];
            ny = W->e[0];
        }
        mat_j = W->material;
    }
    const struct bal_pair_law *L = &s->law[s->mat[i] * s->n_mat + mat_j];
    if (L->tan_phi > 0 || L->cohesion > 0) {
        char a[NAME_BUF], b[NAME_BUF];
        const struct bal_exact_contact tmp = {.i = i, .j = j, .is_wall = (uint8_t)is_wall};
        disc_name(s, i, a, sizeof a);
        other_body(s, &tmp, b);
        char what[64];
        if (L->tan_phi > 0)
            snprintf(what, sizeof what, "friction (tan phi = %g)", L->tan_phi);
        else
            snprintf(what, sizeof what, "cohesion (c = %g)", L->cohesion);
        return bal_error(err, BAL_EINVAL,
                         "%s: exact solver: the contact of disc '%s' and %s has %s; the exact "
                         "solution is for frictionless, cohesionless contacts only",
                         scene_path(s), a, b, what);
    }
    if (w->nc == *cap) {
        long ncap = *cap ? 2 * *cap : 256;
        struct bal_exact_contact *nc = realloc(w->c, (size_t)ncap * sizeof *nc);
        double *nk = realloc(w->k, (size_t)ncap * sizeof *nk);
        if (nc)
            w->c = nc;
        if (nk)
            w->k = nk;
        if (!nc || !nk)
            return bal_error(err, BAL_ENOMEM, "%s: exact solver: out of memory for %ld contacts",
                             scene_path(s), ncap);
        *cap = ncap;
    }
    w->c[w->nc] = (struct bal_exact_contact){
        .i = i, .j = j, .is_wall = (uint8_t)is_wall, .open = 0, .nx = nx, .ny = ny, .fn = 0};
    w->k[w->nc] = L->kn;
    w->nc++;
    return BAL_OK;
}

static enum bal_status build_network(const struct bal_sim *s, struct work *w,
                                     struct bal_error *err)
{
    long cap = 0;
    for (long q = 0; q < s->pp.n; q++) {
        const int i = s->pp.i[q], j = s->pp.j[q];
        if (s->fixed[i] && s->fixed[j])
            continue;
        const enum bal_status st = add_contact(s, w, &cap, i, j, 0, err);
        if (st)
            return st;
    }
    for (long q = 0; q < s->pw.n; q++) {
        const int i = s->pw.i[q];
        if (s->fixed[i])
            continue;
        const enum bal_status st = add_contact(s, w, &cap, i, s->pw.j[q], 1, err);
        if (st)
            return st;
    }
    /* Sort by (i, is_wall, j); each contact's stiffness rides along in its
     * fn field, which is filled only at the end. */
    if (w->nc > 1) {
        for (long c = 0; c < w->nc; c++)
            w->c[c].fn = w->k[c];
        qsort(w->c, (size_t)w->nc, sizeof *w->c, contact_cmp);
        for (long c = 0; c < w->nc; c++) {
            w->k[c] = w->c[c].fn;
            w->c[c].fn = 0;
        }
    }
    return BAL_OK;
}

/* ------------------------------------------------------------------ */
/* Assembly and factorisation                                          */
/* ------------------------------------------------------------------ */

/* K(r, q) += v for r, q unknowns (any order): lower band, A(q, r − q). */
static inline void band_add(struct work *w, size_t r, size_t q, double v)
{
    if (r < q) {
        const size_t t = r;
        r = q;
        q = t;
    }
    w->band[q * (w->p + 1) + (r - q)] += v;
}

/* K = Σ_closed k_c b_c b_cᵀ, plus REGULARISATION Σ_open k_c b_c b_cᵀ when
 * open_weight is OPEN_REGULARISED. */
static void assemble(struct work *w, int open_weight)
{
    memset(w->band, 0, w->nu * (w->p + 1) * sizeof *w->band);
    for (long c = 0; c < w->nc; c++) {
        const double k = w->closed[c]                     ? w->k[c]
                         : open_weight == OPEN_REGULARISED ? REGULARISATION * w->k[c]
                                                           : 0.0;
        if (k == 0)
            continue;
        const double b[2] = {w->c[c].nx, w->c[c].ny};
        const int32_t a = w->ui[c], z = w->uj[c];
        for (int al = 0; al < 2; al++) {
            for (int be = 0; be <= al; be++) {
                const double v = k * b[al] * b[be];
                if (a >= 0)
                    band_add(w, (size_t)a + (size_t)al, (size_t)a + (size_t)be, v);
                if (z >= 0)
                    band_add(w, (size_t)z + (size_t)al, (size_t)z + (size_t)be, v);
            }
        }
        if (a >= 0 && z >= 0)
            for (int al = 0; al < 2; al++)
                for (int be = 0; be < 2; be++)
                    band_add(w, (size_t)a + (size_t)al, (size_t)z + (size_t)be,
                             -k * b[al] * b[be]);
    }
    for (size_t q = 0; q < w->nu; q++)
        w->diag[q] = w->band[q * (w->p + 1)];
}

/* The first free disc whose closed contacts do not span the plane, or -1. */
static int loose_disc(struct work *w)
{
    double *m = w->span;
    memset(m, 0, (size_t)w->nf * 3 * sizeof *m);
    for (long c = 0; c < w->nc; c++) {
        if (!w->closed[c])
            continue;
        const double nx = w->c[c].nx, ny = w->c[c].ny;
        const int32_t ends[2] = {w->ui[c], w->uj[c]};
        for (int e = 0; e < 2; e++) {
            if (ends[e] < 0)
                continue;
            double *q = &m[3 * (ends[e] / 2)];
            q[0] += nx * nx;
            q[1] += nx * ny;
            q[2] += ny * ny;
        }
    }
    for (int a = 0; a < w->nf; a++) {
        const double *q = &m[3 * a];
        const double tr = q[0] + q[2], det = q[0] * q[2] - q[1] * q[1];
        if (!(det > SPAN_TOL * tr * tr))
            return w->free_slot[a];
    }
    return -1;
}

/* Factorise the assembled K in place.  Returns -1 when K is positive
 * definite, else the number of an unknown whose pivot vanished.
 *
 * GSL's band Cholesky reports an indefinite matrix through GSL_ERROR,
 * which calls the library-wide error handler, and the default handler
 * aborts the program.  No GSL routine factorises a band matrix and only
 * returns a status, so the handler must be off for this one call: it is
 * switched off and the caller's handler put back right after (GSL keeps
 * the handler in a process-wide variable; the core sets it nowhere else).
 * This is the one place the solver touches state outside its arguments,
 * and the reason two threads must not run it at the same time as other
 * GSL code that relies on the handler. */
static long factor(struct work *w)
{
    gsl_matrix_view A = gsl_matrix_view_array(w->band, w->nu, w->p + 1);
    gsl_error_handler_t *previous = gsl_set_error_handler_off();
    const int status = gsl_linalg_cholesky_band_decomp(&A.matrix);
    gsl_set_error_handler(previous);
    if (status != GSL_SUCCESS) {
        /* Columns before the failing one hold L_jj = sqrt(pivot) > 0; the
         * failing column is the first whose diagonal is not positive. */
        for (size_t q = 0; q < w->nu; q++)
            if (!(w->band[q * (w->p + 1)] > 0))
                return (long)q;
        return 0;
    }
    for (size_t q = 0; q < w->nu; q++) {
        const double l = w->band[q * (w->p + 1)];
        if (!(l * l >= PIVOT_TOL * w->diag[q]))
            return (long)q;
    }
    return -1;
}

/* x = K⁻¹ rhs with the factor in w->band. */
static void back_solve(struct work *w, const double *rhs, double *x)
{
    gsl_matrix_const_view L = gsl_matrix_const_view_array(w->band, w->nu, w->p + 1);
    gsl_vector_const_view b = gsl_vector_const_view_array(rhs, w->nu);
    gsl_vector_view v = gsl_vector_view_array(x, w->nu);
    /* Cannot fail: the sizes match by construction. */
    (void)gsl_linalg_cholesky_band_solve(&L.matrix, &b.vector, &v.vector);
}

/* ------------------------------------------------------------------ */
/* The two phases                                                      */
/* ------------------------------------------------------------------ */

/* out[c] = b_c·v = (v_i − v_j)·n for every contact. */
static void project(const struct work *w, const double *v, double *out)
{
    for (long c = 0; c < w->nc; c++) {
        const double nx = w->c[c].nx, ny = w->c[c].ny;
        double d = 0;
        if (w->ui[c] >= 0)
            d += v[w->ui[c]] * nx + v[w->ui[c] + 1] * ny;
        if (w->uj[c] >= 0)
            d -= v[w->uj[c]] * nx + v[w->uj[c] + 1] * ny;
        out[c] = d;
    }
}

static uint64_t mix64(uint64_t z)
{
    z += 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Order-independent hash of the set of open contacts. */
static uint64_t open_hash(const struct work *w)
{
    uint64_t h = 0x6A09E667F3BCC909ull;
    for (long c = 0; c < w->nc; c++)
        if (!w->closed[c])
            h ^= mix64((uint64_t)c);
    return h;
}

static int seen(const struct work *w, uint64_t h)
{
    for (int t = 0; t < w->n_seen; t++)
        if (w->seen[t] == h)
            return 1;
    return 0;
}

/* Phase 1: open the closed contacts in tension and close the open ones
 * that penetrate, under the forces w->force.  Returns the number changed. */
static long flip(struct work *w, double tol)
{
    long changed = 0;
    for (long c = 0; c < w->nc; c++) {
        if (w->closed[c] ? w->force[c] < -tol : w->force[c] > tol) {
            w->closed[c] = !w->closed[c];
            changed++;
        }
    }
    return changed;
}

/* ∇E = Σ_c k_c max(δ_c, 0) b_c − f into w->grad (minus the net force on
 * each free disc); returns the largest |∇E| of a free disc. */
static double gradient(struct work *w)
{
    for (size_t q = 0; q < w->nu; q++)
        w->grad[q] = -w->f[q];
    for (long c = 0; c < w->nc; c++) {
        const double F = w->k[c] * fmax(w->delta[c], 0.0);
        if (F == 0)
            continue;
        const double fx = F * w->c[c].nx, fy = F * w->c[c].ny;
        if (w->ui[c] >= 0) {
            w->grad[w->ui[c]] += fx;
            w->grad[w->ui[c] + 1] += fy;
        }
        if (w->uj[c] >= 0) {
            w->grad[w->uj[c]] -= fx;
            w->grad[w->uj[c] + 1] -= fy;
        }
    }
    double worst = 0;
    for (int a = 0; a < w->nf; a++)
        worst = fmax(worst, hypot(w->grad[2 * a], w->grad[2 * a + 1]));
    return worst;
}

static int event_cmp(const void *pa, const void *pb)
{
    const struct event *a = pa, *b = pb;
    return (a->t > b->t) - (a->t < b->t);
}

/* The step length t >= 0 that minimises E(u + t d), given δ = B u in
 * w->delta, e = B d in w->edir and fd = f·d.  Along the step
 *     E'(t) = Σ_c k_c max(δ_c + t e_c, 0) e_c − f·d
 * is piecewise linear and non-decreasing, with a kink where a contact
 * closes (δ_c < 0 < e_c, at t = −δ_c/e_c) or opens (e_c < 0 < δ_c); sweep
 * the pieces in order for its zero.  INFINITY when E falls without bound. */
static double line_search(struct work *w, double fd)
{
    double a = -fd, S = 0; /* E'(t) = a + S t on the current piece */
    long n_active = 0, ne = 0;
    for (long c = 0; c < w->nc; c++) {
        const double d = w->delta[c], e = w->edir[c], k = w->k[c];
        if (e == 0)
            continue;
        if (d > 0 || (d == 0 && e > 0)) {
            a += k * d * e;
            S += k * e * e;
            n_active++;
        }
        const double tb = -d / e;
        if (tb > 0)
            w->events[ne++] = (struct event){tb, c};
    }
    qsort(w->events, (size_t)ne, sizeof *w->events, event_cmp);
    double t_lo = 0;
    for (long q = 0; q < ne; q++) {
        if (S > 0 && -a / S <= w->events[q].t)
            return fmax(-a / S, t_lo);
        if (S <= 0 && a >= 0)
            return t_lo;
        const long c = w->events[q].c;
        const double d = w->delta[c], e = w->edir[c], k = w->k[c];
        const double sign = e > 0 ? 1.0 : -1.0; /* closes : opens */
        a += sign * k * d * e;
        S += sign * k * e * e;
        n_active += e > 0 ? 1 : -1;
        if (n_active == 0) { /* no round-off left over */
            a = -fd;
            S = 0;
        }
        t_lo = w->events[q].t;
    }
    if (S > 0)
        return fmax(-a / S, t_lo);
    return a >= 0 ? t_lo : INFINITY;
}

static long count_open(const struct work *w)
{
    long n = 0;
    for (long c = 0; c < w->nc; c++)
        n += !w->closed[c];
    return n;
}

/* The free disc of the largest |v|. */
static int largest(const struct work *w, const double *v)
{
    int best = 0;
    for (int a = 1; a < w->nf; a++)
        if (hypot(v[2 * a], v[2 * a + 1]) > hypot(v[2 * best], v[2 * best + 1]))
            best = a;
    return w->free_slot[best];
}

enum failure { ALL_CLOSED_MECHANISM, FINAL_MECHANISM, UNBOUNDED };

static enum bal_status refuse(const struct bal_sim *s, const struct work *w, int slot,
                              enum failure why, struct bal_error *err)
{
    char nm[NAME_BUF];
    disc_name(s, slot, nm, sizeof nm);
    switch (why) {
    case ALL_CLOSED_MECHANISM:
        return bal_error(err, BAL_EINVAL,
                         "%s: exact solver: disc '%s' can move without deforming a contact "
                         "(a mechanism: the stiffness matrix is singular); every free disc "
                         "needs contacts that hold it in both directions",
                         scene_path(s), nm);
    case FINAL_MECHANISM:
        return bal_error(err, BAL_EINVAL,
                         "%s: exact solver: in the static solution (%ld of %ld contacts open) "
                         "disc '%s' can move without deforming a closed contact (a mechanism "
                         "in neutral equilibrium, such as a disc alone on a frictionless "
                         "floor); its forces are not those of a stiff network",
                         scene_path(s), count_open(w), w->nc, nm);
    case UNBOUNDED:
        break;
    }
    return bal_error(err, BAL_EINVAL,
                     "%s: exact solver: no equilibrium without tension: once the contacts in "
                     "tension open, disc '%s' moves away without bound",
                     scene_path(s), nm);
}

/* ------------------------------------------------------------------ */
/* Entry points                                                        */
/* ------------------------------------------------------------------ */

void bal_exact_free(struct bal_exact *e)
{
    if (!e)
        return;
    free(e->contacts);
    memset(e, 0, sizeof *e);
}

static double seconds_since(const struct timespec *t0)
{
    struct timespec t1;
    clock_gettime(CLOCK_MONOTONIC, &t1);
    return (double)(t1.tv_sec - t0->tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0->tv_nsec);
}

/* The active-set iteration (phases 1 and 2 above); on success w->closed
 * and w->force hold the solution. */
static enum bal_status iterate(const struct bal_sim *s, struct work *w, double tol,
                               int *iterations, struct bal_error *err)
{
    int damped = 0;       /* in phase 2 */
    int first = 1;        /* no solve has succeeded yet */
    int from_damped = 0;  /* phase 1 resumed from a converged phase 2, not yet solved */
    w->seen[w->n_seen++] = open_hash(w);
    for (;;) {
        if (*iterations >= MAX_ITERATIONS)
            return bal_error(err, BAL_EINVAL,
                             "%s: exact solver: the active-set iteration did not settle in "
                             "%d solves (%ld of %ld contacts open at the end)",
                             scene_path(s), MAX_ITERATIONS, count_open(w), w->nc);
        if (!damped) {
            /* Phase 1: a full step, K u = f on the closed contacts. */
            int loose = loose_disc(w);
            if (loose < 0) {
                assemble(w, OPEN_WEIGHTLESS);
                ++*iterations;
                const long bad = factor(w);
                if (bad >= 0)
                    loose = w->free_slot[bad / 2];
            }
            if (loose >= 0) {
                if (first)
                    return refuse(s, w, loose, ALL_CLOSED_MECHANISM, err);
                if (from_damped)
                    return refuse(s, w, loose, FINAL_MECHANISM, err);
                damped = 1; /* from the last solution, still in w->u */
                continue;
            }
            back_solve(w, w->f, w->u);
            first = from_damped = 0;
            project(w, w->u, w->delta);
            for (long c = 0; c < w->nc; c++)
                w->force[c] = w->k[c] * w->delta[c];
            if (flip(w, tol) == 0)
                return BAL_OK;
            const uint64_t h = open_hash(w);
            if (seen(w, h)) {
                damped = 1; /* cycling: from this solution */
                continue;
            }
            if (w->n_seen <= MAX_ITERATIONS)
                w->seen[w->n_seen++] = h;
            continue;
        }

        /* Phase 2: a damped Newton step on E. */
        project(w, w->u, w->delta);
        const double imbalance = gradient(w);
        for (long c = 0; c < w->nc; c++)
            w->closed[c] = w->k[c] * w->delta[c] >= -tol;
        if (imbalance <= tol) {
            damped = 0;
            from_damped = 1;
            continue;
        }
        assemble(w, OPEN_WEIGHTLESS);
        ++*iterations;
        if (factor(w) >= 0) {
            assemble(w, OPEN_REGULARISED);
            ++*iterations;
            const long bad = factor(w);
            if (bad >= 0) /* not expected: the all-closed K was positive definite */
                return refuse(s, w, w->free_slot[bad / 2], ALL_CLOSED_MECHANISM, err);
        }
        for (size_t q = 0; q < w->nu; q++)
            w->grad[q] = -w->grad[q];
        back_solve(w, w->grad, w->dir);
        project(w, w->dir, w->edir);
        double fd = 0;
        for (size_t q = 0; q < w->nu; q++)
            fd += w->f[q] * w->dir[q];
        const double t = line_search(w, fd);
        if (!isfinite(t))
            return refuse(s, w, largest(w, w->dir), UNBOUNDED, err);
        for (size_t q = 0; q < w->nu; q++)
            w->u[q] += t * w->dir[q];
    }
}

enum bal_status bal_exact_solve(const struct bal_sim *s, struct bal_exact *out,
                                struct bal_error *err)
{
    struct timespec t0;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    memset(out, 0, sizeof *out);

    if (s->normal_law == BAL_NORMAL_POWER && s->nu != 1.0)
        return bal_error(err, BAL_EINVAL,
                         "%s:%d: nu: exact solver: the power law with nu = %s is not linear; "
                         "the exact solution needs linear springs (nu = 1 or the incremental "
                         "law)",
                         scene_path(s),
                         s->scene->settings.key_line[bal_scene_key_index(BAL_SEC_SETTINGS, "nu")],
                         BAL_NUM(s->nu));

    /* Its unknowns are the free discs' two displacements: a disc held along
     * one axis only (`hold`) would need one; not built. */
    for (int i = 0; s->hold && i < s->n; i++)
        if (s->hold[i] & (BAL_HOLD_X | BAL_HOLD_Y)) {
            const int id = s->id[i];
            const struct bal_disc_def *d = &s->scene->discs[id]; /* only [disc]s hold */
            return bal_error(err, BAL_EINVAL,
                             "%s:%d: hold: exact solver: disc %s is held along one axis only; "
                             "the exact solution takes free and fully held (fixed = 1) discs",
                             scene_path(s),
                             d->key_line[bal_scene_key_index(BAL_SEC_DISC, "hold")], d->name);
        }

    struct work w;
    memset(&w, 0, sizeof w);
    enum bal_status st = build_network(s, &w, err);
    if (st)
        goto fail;

    /* Unknowns: (x, y) of the free discs in array order. */
    int ok = 1;
    const size_t nc = (size_t)w.nc;
    w.unknown = alloc_array((size_t)s->n, sizeof *w.unknown, &ok);
    w.free_slot = alloc_array((size_t)s->n, sizeof *w.free_slot, &ok);
    w.ui = alloc_array(nc, sizeof *w.ui, &ok);
    w.uj = alloc_array(nc, sizeof *w.uj, &ok);
    w.closed = alloc_array(nc, sizeof *w.closed, &ok);
    w.delta = alloc_array(nc, sizeof *w.delta, &ok);
    w.edir = alloc_array(nc, sizeof *w.edir, &ok);
    w.force = alloc_array(nc, sizeof *w.force, &ok);
    w.events = alloc_array(nc, sizeof *w.events, &ok);
    w.seen = alloc_array(MAX_ITERATIONS + 1, sizeof *w.seen, &ok);
    if (!ok) {
        st = bal_error(err, BAL_ENOMEM, "%s: exact solver: out of memory", scene_path(s));
        goto fail;
    }
    double wmax = 0, wsum = 0;
    for (int i = 0; i < s->n; i++) {
        if (s->fixed[i]) {
            w.unknown[i] = -1;
            continue;
        }
        w.free_slot[w.nf] = i;
        w.unknown[i] = 2 * w.nf++;
        const double gx = bal_mass(s, i) * s->g[0], gy = bal_mass(s, i) * s->g[1];
        out->weight[0] += gx;
        out->weight[1] += gy;
        wmax = fmax(wmax, hypot(gx, gy));
        wsum += hypot(gx, gy);
    }
    w.nu = 2 * (size_t)w.nf;
    w.p = w.nu > 1 ? 1 : 0;
    for (long c = 0; c < w.nc; c++) {
        w.ui[c] = w.unknown[w.c[c].i];
        w.uj[c] = w.c[c].is_wall ? -1 : w.unknown[w.c[c].j];
        w.closed[c] = 1;
        if (w.ui[c] >= 0 && w.uj[c] >= 0) {
            const size_t d = (size_t)labs((long)w.ui[c] - (long)w.uj[c]) + 1;
            if (d > w.p)
                w.p = d;
        }
    }
    out->bandwidth = (int)w.p;

    if (w.nf > 0) {
        w.band = alloc_array(w.nu * (w.p + 1), sizeof *w.band, &ok);
        w.diag = alloc_array(w.nu, sizeof *w.diag, &ok);
        w.f = alloc_array(w.nu, sizeof *w.f, &ok);
        w.u = alloc_array(w.nu, sizeof *w.u, &ok);
        w.grad = alloc_array(w.nu, sizeof *w.grad, &ok);
        w.dir = alloc_array(w.nu, sizeof *w.dir, &ok);
        w.span = alloc_array(3 * (size_t)w.nf, sizeof *w.span, &ok);
        if (!ok) {
            st = bal_error(err, BAL_ENOMEM,
                           "%s: exact solver: out of memory for the band matrix (%zu x %zu)",
                           scene_path(s), w.nu, w.p + 1);
            goto fail;
        }
        for (int a = 0; a < w.nf; a++) {
            const int i = w.free_slot[a];
            w.f[2 * a] = bal_mass(s, i) * s->g[0];
            w.f[2 * a + 1] = bal_mass(s, i) * s->g[1];
        }
        st = iterate(s, &w, FORCE_TOL * wsum, &out->iterations, err);
        if (st)
            goto fail;
    }

    /* Results: stiff-limit forces, support, residual (w.grad as scratch). */
    for (size_t q = 0; q < w.nu; q++)
        w.grad[q] = 0;
    for (long c = 0; c < w.nc; c++) {
        struct bal_exact_contact *C = &w.c[c];
        C->open = (uint8_t)!w.closed[c];
        C->fn = w.closed[c] && w.force[c] > 0 ? w.force[c] : 0;
        out->n_open += C->open;
        const double fx = C->fn * C->nx, fy = C->fn * C->ny;
        if (w.ui[c] >= 0) {
            w.grad[w.ui[c]] -= fx;
            w.grad[w.ui[c] + 1] -= fy;
        } else {
            out->support[0] -= fx; /* i held: the free disc j pushes it along −n */
            out->support[1] -= fy;
        }
        if (w.uj[c] >= 0) {
            w.grad[w.uj[c]] += fx;
            w.grad[w.uj[c] + 1] += fy;
        } else {
            out->support[0] += fx; /* a held disc or a wall j, pushed along +n */
            out->support[1] += fy;
        }
    }
    double res = 0;
    for (int a = 0; a < w.nf; a++)
        res = fmax(res, hypot(w.grad[2 * a] + w.f[2 * a], w.grad[2 * a + 1] + w.f[2 * a + 1]));
    out->residual = wmax > 0 ? res / wmax : res;
    out->n_contacts = w.nc;
    out->contacts = w.c;
    w.c = NULL;
    work_free(&w);
    out->seconds = seconds_since(&t0);
    return BAL_OK;

fail:
    work_free(&w);
    memset(out, 0, sizeof *out);
    return st;
}
