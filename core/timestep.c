/*
 * timestep.c — the critical time-step estimate.
 *
 * Kept whole (about 670 lines, 90 of them the derivation below): one
 * estimate — the contacts at the start, the two bounds on the network and
 * the coordination bound — whose parts serve only each other.
 *
 * 1. The paper's estimate (C&S p. 53), kept for comparison.  BALL estimates
 *    the critical step from a single degree of freedom, a mass m on a spring
 *    k: Δt = 2 √(m/k).  bal_timestep_single_spring() takes, for every disc,
 *    the stiffest contact it can see (over every material present, discs and
 *    walls) and both kinds of degree of freedom,
 *
 *      translation:  2 √(m / k_n),  2 √(m / k_s)
 *      rotation:     2 √(I / (k_s R²))   (= 2 √(m / (2 k_s)) for I = m R²/2)
 *
 *    and returns the smallest over all discs.  It is not safe: a disc held by
 *    several springs, or a spring between two free discs, has a higher
 *    frequency (two discs between walls: √3 higher in the normal direction).
 *
 * 2. The estimate used (bal_timestep_estimate): a bound on the largest
 *    eigenfrequency of the contact network, and the leapfrog limit for it.
 *
 *    Linearised, the discs obey M ẍ = −K x with x = (u_i, v_i, θ_i) per free
 *    disc, and the leapfrog (C&S eqs 22-23) is stable for Δt < 2/ω_max,
 *    ω_max² = λ_max(M⁻¹K).  Each contact c between a and b, with unit
 *    normal n and tangent t, stores the energy
 *
 *      ½ k_n ((u_b − u_a)·n)²  +  ½ k_s ((u_b − u_a)·t − R_a θ_a − R_b θ_b)².
 *
 *    Cauchy–Schwarz with the masses as weights, (Σ c_p z_p)² ≤
 *    (Σ c_p²/w_p)(Σ w_p z_p²), bounds each term by a sum over the bodies:
 *
 *      normal:  k_n (1/m_a + 1/m_b) [m_a (u_a·n)² + m_b (u_b·n)²]
 *      shear:   k_s S [m_a (u_a·t)² + I_a θ_a² + (same for b)],
 *               S = 1/m_a + R_a²/I_a + 1/m_b + R_b²/I_b  (= 3/m_a + 3/m_b)
 *
 *    (a wall or held disc has 1/m = R²/I = 0 and no degrees of freedom).
 *    Summing over contacts, x·Kx ≤ Σ_a [m_a u_a·T_a u_a + I_a θ_a² Θ_a] with
 *
 *      T_a = Σ_c (A_c n nᵀ + B_c t tᵀ),  Θ_a = Σ_c B_c,
 *      A_c = k_n (1/m_a + 1/m_b),  B_c = k_s S,
 *
 *    so the Rayleigh quotient, hence ω_max², is at most
 *    max_a max(λ_max(T_a), Θ_a) — a block (2×2 + 1×1) Gershgorin bound.  It
 *    is exact for one spring (k/m, and 3 k_s/m for the shear–rotation pair
 *    of a disc on a wall), for two discs between walls in the normal
 *    direction (3 k_n/m) and for the normal springs of a triangular lattice
 *    (6 k_n/m at the M point of the zone boundary).  Only pairs with a shear
 *    force (tan φ_μ > 0 or c > 0) get B_c.  For the power law the stiffness
 *    at δ = δ0, ν k_n, is used, or at the largest overlap the scene's energy
 *    allows when nothing feeds it (pair_kn).
 *
 *    Which contacts.  Those present at the start: pairs whose gap is at most
 *    BAL_DT_GAP of the smaller radius (the catalogue's scenes start with
 *    bodies just touching, then load them).  A free disc with no such
 *    contact (a loose fill, a falling disc) is bounded by the largest
 *    coordination the sizes allow instead: N discs of the smallest radius r
 *    touching a disc of radius R without overlapping each other, N =
 *    ⌊π / asin(r/(R + r))⌋, each with the stiffest material, the lightest
 *    partner, and normals packed as closely as they can around one direction
 *    (λ_max(Σ n nᵀ) ≤ Λ, computed in coordination_lambda), and never more
 *    than the scene's other bodies (n − 1 discs + walls).  Since t tᵀ =
 *    I − n nᵀ, λ_max(T) ≤ B N + (A − B) Λ for A ≥ B, B N − (B − A)(N − Λ)
 *    otherwise, and Θ ≤ N B.  Six equal discs: Λ = 3.  A disc that starts
 *    with few contacts and gains many is not covered (the limitation of an
 *    estimate made once, at creation).
 *
 *    Damping.  The dashpots c = β k (and MLH's γ_n at δ = δ0) act on the
 *    velocities of the previous half step.  For x'' = −ω² x − 2ζω v_{N−1/2}
 *    the leapfrog's characteristic polynomial z² + (ω²Δt² − 2 + 2ζωΔt) z +
 *    (1 − 2ζωΔt) has its roots in the unit circle (Schur–Cohn) iff
 *    Δt < (2/ω)(√(1 + ζ²) − ζ).  With C = β_eff K, ζ = β_eff ω/2 for every
 *    mode; β_eff is the disc's largest (c_n + γ_n)/k_n or c_s/k_s.  Global
 *    damping (C&S eqs 35-36, time-centred) leaves the limit at 2/ω.
 *
 *    A second bound for the network (network_rho): ρ(|A|), the spectral
 *    radius of the entrywise absolute value of A = M^(-1/2) K M^(-1/2), is at
 *    least λ_max(A), and the Collatz–Wielandt quotient max_p (|A| d)_p / d_p
 *    bounds ρ(|A|) from above for every positive d; a power iteration drives
 *    d towards the Perron vector.  Where shear springs couple neighbours it
 *    is far tighter than the block bound (nine discs: 14.7 k/m against the
 *    true 14.0 and the block bound's 20.9); the block bound is tighter for
 *    frictionless triangular packings.  Both are upper bounds, so the
 *    network's step is the larger of the two limits (the spectral one with
 *    the network's largest damping ratio).
 *
 *    The estimate is BAL_DT_MARGIN = 0.95 times the smallest over free discs
 *    of 2/(ω (√(1+ζ²) + ζ)), with the network's part the better of the two
 *    bounds.
 */
#include <limits.h>
#include <math.h>
#include <stdlib.h>

#include "timestep.h"
#include "walls.h"

/* The estimate is this share of the bound 2/(ω (√(1+ζ²) + ζ)).  At the
 * bound itself the centred scheme is only marginally stable: its conserved
 * (shadow) energy ½ m v² + ½ k x² (1 − ω²Δt²/4) degenerates, so the energy
 * it shows can grow without limit in a short contact.  Measured: a linear
 * collision created as much energy as it had at 0.993 of the bound, a
 * damped one changed its rebound at 0.952 (harness stability).  5 % below
 * the bound, every case of the catalogue is stable. */
#define BAL_DT_MARGIN 0.95

/* A pair whose gap is at most this share of the smaller radius is a contact
 * at the start.  The catalogue's scenes place touching bodies at gap 0 (to
 * rounding); 1 % also takes in a lattice generated with a small clearance. */
#define BAL_DT_GAP 0.01

/* Cells of the start-up neighbour search, at most this many per disc. */
#define BAL_DT_CELLS_PER_DISC 4

double bal_timestep_single_spring(const struct bal_sim *s)
{
    double best = INFINITY;
    for (int i = 0; i < s->n; i++) {
        double kn = 0, ks = 0, km = 0;
        for (int m = 0; m < s->n_mat; m++) {
            const struct bal_pair_law *L = &s->law[s->mat[i] * s->n_mat + m];
            kn = fmax(kn, L->kn);
            ks = fmax(ks, L->ks);
            /* the stiffest rolling spring: against a wall, r = 2 R */
            km = fmax(km, bal_law_roll_of(L, 2 * s->r[i]).km);
        }
        if (s->normal_law == BAL_NORMAL_POWER)
            kn *= s->nu;
        const double m = bal_mass(s, i);
        double t = 2 * sqrt(m / kn);
        if (ks > 0) {
            t = fmin(t, 2 * sqrt(m / ks));
            t = fmin(t, 2 * sqrt(bal_inertia(s, i) / (ks * s->r[i] * s->r[i])));
        }
        if (km > 0)
            t = fmin(t, 2 * sqrt(bal_inertia(s, i) / km));
        best = fmin(best, t);
    }
    return best;
}

/* Per free disc: the 2×2 translational block T (xx, xy, yy), the rotational
 * sum Θ, the largest damping ratio β_eff and the number of contacts. */
struct dt_acc {
    double txx, txy, tyy, rot, beta;
    int n;
};

/* A contact at the start: discs a and b (b < 0: a wall of material wall_mat)
 * and the unit normal from a to b. */
struct dt_contact {
    int32_t a, b, wall_mat;
    double nx, ny;
};

struct dt_list {
    long n, cap;
    struct dt_contact *c;
};

static int list_add(struct dt_list *l, int a, int b, int wall_mat, double nx, double ny)
{
    if (l->n == l->cap) {
        const long cap = l->cap ? 2 * l->cap : 256;
        struct dt_contact *c = realloc(l->c, (size_t)cap * sizeof *c);
        if (!c)
            return -1;
        l->c = c;
        l->cap = cap;
    }
    l->c[l->n++] = (struct dt_contact){a, b, wall_mat, nx, ny};
    return 0;
}

/* The normal stiffness of a pair: its tangent stiffness dF/dδ (laws.h; for
 * the power law ν k_n (δ/δ0)^(ν−1)) taken at δ = δ0 unless the scene's
 * energy bounds the overlap.  In a scene that nothing feeds (no gravity, no
 * moving wall, no overlap at the start) no contact can store more than the
 * kinetic energy E at the start, so
 * k_n δ0² (δ/δ0)^(ν+1)/(ν+1) ≤ E bounds δ/δ0 — below 1 for a gentle
 * collision (the estimate was 3 times too cautious for the catalogue's
 * Hertz collisions), above 1 for a violent one (where δ0 was unsafe). */
static double pair_kn(const struct bal_sim *s, const struct bal_pair_law *L)
{
    double ratio = 1;
    if (s->normal_law == BAL_NORMAL_POWER && s->nu != 1 && s->start_energy > 0)
        ratio = pow((s->nu + 1) * s->start_energy / (L->kn * s->delta0 * s->delta0),
                    1 / (s->nu + 1));
    const struct bal_law_params P = bal_law_params_of(s);
    return bal_law_normal_stiffness(&P, L, ratio);
}

static double pair_beta(const struct bal_sim *s, const struct bal_pair_law *L)
{
    const double kn = pair_kn(s, L);
    double b = kn > 0 ? (L->cn + s->gamma_n) / kn : 0;
    if (L->shear && L->ks > 0)
        b = fmax(b, L->cs / L->ks);
    return b;
}

/* 1/m and R²/I of disc i, zero for a held disc (no degrees of freedom). */
static void disc_inv(const struct bal_sim *s, int i, double *inv_m, double *r2_i)
{
    if (s->fixed[i]) {
        *inv_m = *r2_i = 0;
        return;
    }
    *inv_m = 1 / bal_mass(s, i);
    *r2_i = s->r[i] * s->r[i] / bal_inertia(s, i);
}

/* 1/I of disc i, zero for a held disc. */
static double inv_inertia(const struct bal_sim *s, int i)
{
    return s->fixed[i] ? 0 : 1 / bal_inertia(s, i);
}

/* Add contact c to the rows of its free discs, with the rotational weight
 * γ (see bal_timestep_detail): the shear term adds k_s S_γ to the
 * translational row and γ k_s S_γ to the rotational one, S_γ = 1/m_a +
 * 1/m_b + (R_a²/I_a + R_b²/I_b)/γ. */
static void add_contact(const struct bal_sim *s, struct dt_acc *acc, const struct dt_contact *c,
                        double gamma)
{
    const int a = c->a, b = c->b;
    const int mb = b >= 0 ? s->mat[b] : c->wall_mat;
    const struct bal_pair_law *L = &s->law[s->mat[a] * s->n_mat + mb];
    double ia, ra, ib = 0, rb = 0;
    disc_inv(s, a, &ia, &ra);
    if (b >= 0)
        disc_inv(s, b, &ib, &rb);
    const double A = pair_kn(s, L) * (ia + ib);
    const double B = L->shear ? L->ks * (ia + ib + (ra + rb) / gamma) : 0;
    /* The rolling spring ½ K_m (θ_a − θ_b)² ≤ K_m (1/I_a + 1/I_b)
     * (I_a θ_a² + I_b θ_b²): its share of the rotational row. */
    const double rc = b >= 0 ? bal_law_common_radius(s->r[a], s->r[b]) : 2 * s->r[a];
    const double Kr = L->rolling > 0 ? bal_law_roll_of(L, rc).km * (inv_inertia(s, a) +
                                                                    (b >= 0 ? inv_inertia(s, b) : 0))
                                     : 0;
    const double beta = pair_beta(s, L);
    const double nx = c->nx, ny = c->ny;
    const int ends[2] = {a, b};
    for (int e = 0; e < 2; e++) {
        const int k = ends[e];
        if (k < 0 || s->fixed[k])
            continue;
        struct dt_acc *q = &acc[k];
        /* n nᵀ and t tᵀ = I − n nᵀ */
        q->txx += A * nx * nx + B * ny * ny;
        q->tyy += A * ny * ny + B * nx * nx;
        q->txy += (A - B) * nx * ny;
        q->rot += gamma * B + Kr;
        q->beta = fmax(q->beta, beta);
        q->n++;
    }
}

/* Largest eigenvalue of the symmetric 2×2 [[a, b], [b, d]]. */
static double eig_max(double a, double b, double d)
{
    return 0.5 * (a + d) + sqrt(0.25 * (a - d) * (a - d) + b * b);
}

/* 2/(ω (√(1+ζ²) + ζ)), ζ = β ω/2: the leapfrog limit of a damped mode. */
static double damped_limit(double omega2, double beta)
{
    if (!(omega2 > 0))
        return INFINITY;
    const double w = sqrt(omega2), z = 0.5 * beta * w;
    return 2 / (w * (sqrt(1 + z * z) + z));
}

/* Coordinations up to this many neighbours get the exact packing sum
 * below; larger ones (radius ratios beyond about 1:20) its closed-form
 * bound, so the estimate costs a bounded amount per disc whatever the
 * radii (a ratio of 1e7 once looped 10^9 times here). */
#define BAL_DT_COORD_EXACT 64

/* N discs of radius r touching one of radius R, not overlapping each other:
 * their normals are at least 2a apart, a = asin(r/(R + r)).  Returns N (a
 * double: for a ratio of 1e300 it exceeds every integer type) and in
 * *lambda a bound on λ_max(Σ n nᵀ): in each half-plane the normals are at
 * least 2a apart, so Σ cos²φ is largest when they are packed at spacing 2a
 * around the direction; the best offset is searched on a fine grid (the sum
 * is a step function of the offset; 256 steps is more than the at most π/a
 * points that fit), and the whole is at most N.  Beyond BAL_DT_COORD_EXACT
 * neighbours the search is replaced by its bound: cos² rises then falls on
 * [−π/2, π/2], so a sum over points 2a apart is at most the integral over
 * the spacing plus the peak, π/(4a) + 1. */
static double coordination(double R, double r, double *lambda)
{
    const double a = asin(fmin(1.0, r / (R + r)));
    const double n = floor(BAL_PI / a + 1e-9);
    double best = 0;
    if (n > BAL_DT_COORD_EXACT) {
        best = BAL_PI / (4 * a) + 1;
    } else {
        const int m = (int)n;
        for (int k = 0; k <= 256; k++) {
            const double off = 2 * a * k / 256.0;
            double sum = 0;
            for (int j = -m; j <= m; j++) {
                const double phi = off + 2 * a * j;
                if (fabs(phi) <= 0.5 * BAL_PI) {
                    const double c = cos(phi);
                    sum += c * c;
                }
            }
            best = fmax(best, sum);
        }
    }
    *lambda = fmin(2 * best, n);
    return n;
}

/* The contacts at the start, found with a cell grid of side 2 r_max (1 +
 * BAL_DT_GAP).  Returns 0, or -1 if out of memory (the caller then bounds
 * every disc by its coordination, which is safe). */
static int start_contacts(const struct bal_sim *s, struct dt_list *l)
{
    const int n = s->n;
    double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
    for (int i = 0; i < n; i++) {
        x0 = fmin(x0, s->x[i]);
        y0 = fmin(y0, s->y[i]);
        x1 = fmax(x1, s->x[i]);
        y1 = fmax(y1, s->y[i]);
    }
    /* A spread that overflows (x = ±1e308: the grid refuses the scene later)
     * has no cells: bound every disc by its coordination instead. */
    if (!(isfinite(x1 - x0) && isfinite(y1 - y0)) && n > 0)
        return -1;
    double h = 2 * s->r_max * (1 + BAL_DT_GAP);
    const double cells_max = (double)BAL_DT_CELLS_PER_DISC * n + 16;
    while (((x1 - x0) / h + 1) * ((y1 - y0) / h + 1) > cells_max)
        h *= 2;
    /* At most cells_max cells (the loop above), so both fit an int. */
    const int nx = bal_cell_index((x1 - x0) / h, INT_MAX - 1) + 1;
    const int ny = bal_cell_index((y1 - y0) / h, INT_MAX - 1) + 1;
    const long nc = (long)nx * ny;
    int32_t *start = calloc((size_t)nc + 1, sizeof *start);
    int32_t *list = malloc((size_t)(n ? n : 1) * sizeof *list);
    int32_t *cell = malloc((size_t)(n ? n : 1) * sizeof *cell);
    int status = 0;
    if (!start || !list || !cell)
        status = -1;
    for (int i = 0; status == 0 && i < n; i++) {
        const int cx = bal_cell_index((s->x[i] - x0) / h, nx);
        const int cy = bal_cell_index((s->y[i] - y0) / h, ny);
        cell[i] = (int32_t)((long)cy * nx + cx);
        start[cell[i] + 1]++;
    }
    if (status == 0) {
        for (long c = 0; c < nc; c++)
            start[c + 1] += start[c];
        for (int i = 0; i < n; i++)
            list[start[cell[i]]++] = i;
        for (long c = nc; c > 0; c--)
            start[c] = start[c - 1];
        start[0] = 0;
    }
    for (int i = 0; status == 0 && i < n; i++) {
        const int cx = cell[i] % nx, cy = cell[i] / nx;
        for (int gy = cy - 1; gy <= cy + 1; gy++)
            for (int gx = cx - 1; gx <= cx + 1; gx++) {
                if (gx < 0 || gy < 0 || gx >= nx || gy >= ny)
                    continue;
                const long g = (long)gy * nx + gx;
                for (int32_t q = start[g]; status == 0 && q < start[g + 1]; q++) {
                    const int j = list[q];
                    if (j <= i || (s->fixed[i] && s->fixed[j]))
                        continue;
                    const double dx = s->x[j] - s->x[i], dy = s->y[j] - s->y[i];
                    const double d = sqrt(dx * dx + dy * dy);
                    const double gap = d - s->r[i] - s->r[j];
                    if (gap > BAL_DT_GAP * fmin(s->r[i], s->r[j]) || d == 0)
                        continue;
                    status = list_add(l, i, j, 0, dx / d, dy / d);
                }
            }
    }
    free(start);
    free(list);
    free(cell);

    for (int i = 0; status == 0 && i < n; i++) {
        if (s->fixed[i])
            continue;
        for (int k = 0; status == 0 && k < s->n_walls; k++) {
            double ex, ey;
            const double d = bal_walls_normal(&s->walls[k], s->x[i], s->y[i], &ex, &ey);
            if (d - s->r[i] > BAL_DT_GAP * s->r[i])
                continue;
            status = list_add(l, i, -1, s->walls[k].material, ex, ey);
        }
    }
    return status;
}

/* The coordination of a disc: N and the bound on λ_max(Σ n nᵀ), from
 * coordination(); computed once per disc, not once per weight γ (about
 * 8 000 cosines each). */
struct dt_coord {
    double n;
    double lambda;
};

/* The coordination bound of free disc i (see the header), with the
 * rotational weight γ. */
static double coordination_omega2(const struct bal_sim *s, int i, struct dt_coord co,
                                  double inv_m_max, double gamma, double *beta)
{
    double lambda = co.lambda, n = co.n;
    /* ... and no more contacts than the scene has other bodies (two discs
     * colliding: one partner, so the bound is that of one spring) */
    const double others = (double)s->n - 1 + s->n_walls;
    if (n > others) {
        n = others;
        lambda = fmin(lambda, others);
    }
    double ia, ra;
    disc_inv(s, i, &ia, &ra);
    double A = 0, B = 0, R = 0;
    *beta = 0;
    for (int m = 0; m < s->n_mat; m++) {
        const struct bal_pair_law *L = &s->law[s->mat[i] * s->n_mat + m];
        /* the lightest free disc as partner: 1/m and R²/I = 2/m */
        A = fmax(A, pair_kn(s, L) * (ia + inv_m_max));
        if (L->shear)
            B = fmax(B, L->ks * (ia + inv_m_max + (ra + 2 * inv_m_max) / gamma));
        /* rolling: K_m (1/I_i + 1/I_j) with the common radius at most 2 R of
         * either disc, so K_m/I ≤ k_n δ² (2R)²/12 / (m R²/2) = (2/3) k_n δ²/m */
        if (L->rolling > 0)
            R = fmax(R, 2.0 / 3 * L->kn * L->rolling * L->rolling * (ia + inv_m_max));
        *beta = fmax(*beta, pair_beta(s, L));
    }
    const double t = A >= B ? B * n + (A - B) * lambda : B * n - (B - A) * (n - lambda);
    return fmax(t, (gamma * B + R) * n);
}

/* Rotational weights tried: every one gives a bound, the smallest is used.
 * The best for equal discs: 1 (two discs between walls), (√5 − 1)/2
 * (triangular lattice), √2 − 1 (square lattice). */
static const double gammas[] = {1.0, 0.8, 0.7, 0.618, 0.55, 0.5, 0.45, 0.414, 0.38, 0.33, 0.28,
                                0.24, 0.2};
#define N_GAMMAS (int)(sizeof gammas / sizeof gammas[0])

/* The matrix |A| of the start network, A = M^(-1/2) K M^(-1/2) over the
 * (x, y, θ) of every free disc: the 3×3 diagonal blocks summed over each
 * disc's contacts (then taken absolute), and for each contact between two
 * free discs its cross block, taken absolute when used.  Blocks of contact
 * c between a and b, normal n (from a to b), tangent t = (−n_y, n_x):
 *   a's diagonal:  k_n [n nᵀ, 0; 0, 0] + k_s [t tᵀ, R_a t; R_a tᵀ, R_a²]
 *   b's diagonal:  k_n [n nᵀ, 0; 0, 0] + k_s [t tᵀ, −R_b t; −R_b tᵀ, R_b²]
 *   a–b cross:     [−k_n n nᵀ − k_s t tᵀ, k_s R_b t; −k_s R_a tᵀ, k_s R_a R_b]
 * (from the energy ½ k_n ((u_b − u_a)·n)² + ½ k_s ((u_b − u_a)·t − R_a θ_a −
 * R_b θ_b)²; k_s only for pairs with a shear force). */
static void contact_blocks(const struct bal_sim *s, const struct dt_contact *c, double da[9],
                           double db[9], double cab[9])
{
    const int a = c->a, b = c->b;
    const int mb = b >= 0 ? s->mat[b] : c->wall_mat;
    const struct bal_pair_law *L = &s->law[s->mat[a] * s->n_mat + mb];
    const double kn = pair_kn(s, L), ks = L->shear ? L->ks : 0;
    const double n[2] = {c->nx, c->ny}, t[2] = {-c->ny, c->nx};
    const double ra = s->r[a], rb = b >= 0 ? s->r[b] : 0;
    for (int p = 0; p < 2; p++)
        for (int q = 0; q < 2; q++) {
            const double nn = kn * n[p] * n[q], tt = ks * t[p] * t[q];
            da[3 * p + q] = db[3 * p + q] = nn + tt;
            cab[3 * p + q] = -nn - tt;
        }
    for (int p = 0; p < 2; p++) {
        da[3 * p + 2] = da[6 + p] = ks * ra * t[p];
        db[3 * p + 2] = db[6 + p] = -ks * rb * t[p];
        cab[3 * p + 2] = ks * rb * t[p];
        cab[6 + p] = -ks * ra * t[p];
    }
    da[8] = ks * ra * ra;
    db[8] = ks * rb * rb;
    cab[8] = ks * ra * rb;
    /* The rolling spring ½ K_m (θ_a − θ_b)² (JYH eq. 28; r = 2 r_a against
     * a wall). */
    if (L->rolling > 0) {
        const double km = bal_law_roll_of(L, b >= 0 ? bal_law_common_radius(ra, rb) : 2 * ra).km;
        da[8] += km;
        db[8] += km;
        cab[8] -= km;
    }
}

/* Steps of the power iteration for the spectral radius of |A|: at most
 * BAL_DT_POWER_STEPS, and fewer for a large network so that the work stays
 * about BAL_DT_POWER_WORK block products (every step's bound is valid; a
 * million-disc network gets BAL_DT_POWER_MIN steps, about a second). */
#define BAL_DT_POWER_STEPS 400
#define BAL_DT_POWER_MIN 10
#define BAL_DT_POWER_WORK 4e7

/* An upper bound on λ_max(A) of the start network: ρ(|A|) ≥ ρ(A) (|A|
 * dominates A entrywise), and for any positive d the Collatz–Wielandt bound
 * max_p (|A| d)_p / d_p ≥ ρ(|A|).  d follows the power iteration of
 * |A| + σI (the shift keeps d positive and breaks the period of a
 * bipartite network); every step's bound is valid and the smallest is
 * returned, so stopping early only loosens it.  It is tighter than the block
 * bound where shear springs couple neighbours (square packings: 14.7 k/m
 * against the true 14.0 and the block bound's 20.9 for the nine discs);
 * the block bound is tighter for frictionless triangular packings, so the
 * caller takes the better of the two.  Returns INFINITY when out of
 * memory. */
static double network_rho(const struct bal_sim *s, const struct dt_list *l)
{
    const int n = s->n;
    double *diag = calloc((size_t)(n ? n : 1) * 9, sizeof *diag);
    double *sq = malloc((size_t)(n ? n : 1) * 3 * sizeof *sq); /* 1/√M per dof */
    double *d = malloc((size_t)(n ? n : 1) * 3 * sizeof *d);
    double *y = malloc((size_t)(n ? n : 1) * 3 * sizeof *y);
    double best = INFINITY;
    if (!diag || !sq || !d || !y)
        goto out;
    for (int i = 0; i < n; i++) {
        double ia, ra;
        disc_inv(s, i, &ia, &ra);
        sq[3 * i] = sq[3 * i + 1] = sqrt(ia);
        sq[3 * i + 2] = s->fixed[i] ? 0 : sqrt(1 / bal_inertia(s, i));
    }
    for (long k = 0; k < l->n; k++) {
        double da[9], db[9], cab[9];
        contact_blocks(s, &l->c[k], da, db, cab);
        for (int e = 0; e < 9; e++) {
            diag[9 * l->c[k].a + e] += da[e];
            if (l->c[k].b >= 0)
                diag[9 * l->c[k].b + e] += db[e];
        }
    }
    /* scale and take absolute values of the diagonal blocks */
    for (int i = 0; i < n; i++)
        for (int p = 0; p < 3; p++)
            for (int q = 0; q < 3; q++)
                diag[9 * i + 3 * p + q] = fabs(diag[9 * i + 3 * p + q]) * sq[3 * i + p] * sq[3 * i + q];
    for (int k = 0; k < 3 * n; k++)
        d[k] = 1;
    double sigma = -1;
    const double work = 3.0 * n + 2.0 * (double)l->n;
    const int steps = (int)fmax(BAL_DT_POWER_MIN, fmin(BAL_DT_POWER_STEPS, BAL_DT_POWER_WORK / work));
    for (int it = 0; it < steps; it++) {
        for (int i = 0; i < n; i++)
            for (int p = 0; p < 3; p++) {
                double v = 0;
                for (int q = 0; q < 3; q++)
                    v += diag[9 * i + 3 * p + q] * d[3 * i + q];
                y[3 * i + p] = v;
            }
        for (long k = 0; k < l->n; k++) {
            const int a = l->c[k].a, b = l->c[k].b;
            if (b < 0 || s->fixed[a] || s->fixed[b])
                continue;
            double da[9], db[9], cab[9];
            contact_blocks(s, &l->c[k], da, db, cab);
            for (int p = 0; p < 3; p++)
                for (int q = 0; q < 3; q++) {
                    const double v = fabs(cab[3 * p + q]) * sq[3 * a + p] * sq[3 * b + q];
                    y[3 * a + p] += v * d[3 * b + q];
                    y[3 * b + q] += v * d[3 * a + p];
                }
        }
        double bound = 0, norm = 0;
        for (int k = 0; k < 3 * n; k++) {
            bound = fmax(bound, y[k] / d[k]);
            norm = fmax(norm, y[k]);
        }
        best = fmin(best, bound);
        if (!(norm > 0))
            break; /* no springs at all */
        if (sigma < 0)
            sigma = 0.25 * bound;
        for (int k = 0; k < 3 * n; k++)
            d[k] = (y[k] + sigma * d[k]) / (norm + sigma);
    }
out:
    free(diag);
    free(sq);
    free(d);
    free(y);
    return best;
}

void bal_timestep_detail(const struct bal_sim *s, struct bal_dt_detail *d)
{
    d->single_spring = bal_timestep_single_spring(s);
    d->estimate = 0;
    d->contacts = 0;
    d->coordination_discs = 0;
    d->binding_disc = -1;
    d->omega = 0;
    d->zeta = 0;
    d->spectral = 0;
    struct dt_list list = {0, 0, NULL};
    struct dt_acc *acc = calloc((size_t)(s->n ? s->n : 1), sizeof *acc);
    struct dt_coord *co = calloc((size_t)(s->n ? s->n : 1), sizeof *co); /* n = 0: not yet */
    const int found = acc ? start_contacts(s, &list) : -1;
    if (found == 0)
        d->contacts = list.n;
    double r_min = INFINITY, inv_m_max = 0;
    for (int i = 0; i < s->n; i++) {
        r_min = fmin(r_min, s->r[i]);
        if (!s->fixed[i])
            inv_m_max = fmax(inv_m_max, 1 / bal_mass(s, i));
    }
    /* Two parts, each with its best weight γ: the discs with contacts at
     * the start (the network) and those bounded by their coordination. */
    struct part {
        double est, omega, zeta;
        int binding;
    } net = {0, 0, 0, -1}, coord = {0, 0, 0, -1};
    int n_coord = 0;
    double beta_net = 0;
    for (int g = 0; g < N_GAMMAS; g++) {
        const double gamma = gammas[g];
        if (acc) {
            for (int i = 0; i < s->n; i++)
                acc[i] = (struct dt_acc){0, 0, 0, 0, 0, 0};
            if (found == 0)
                for (long c = 0; c < list.n; c++)
                    add_contact(s, acc, &list.c[c], gamma);
        }
        struct part pn = {INFINITY, 0, 0, -1}, pc = {INFINITY, 0, 0, -1};
        n_coord = 0;
        for (int i = 0; i < s->n; i++) {
            if (s->fixed[i])
                continue;
            double w2, beta;
            struct part *p;
            if (found == 0 && acc[i].n > 0) {
                const struct dt_acc *c = &acc[i];
                w2 = fmax(eig_max(c->txx, c->txy, c->tyy), c->rot);
                beta = c->beta;
                beta_net = fmax(beta_net, beta);
                p = &pn;
            } else {
                struct dt_coord ci;
                if (co && co[i].n > 0) {
                    ci = co[i];
                } else {
                    ci.n = coordination(s->r[i], r_min, &ci.lambda);
                    if (co)
                        co[i] = ci;
                }
                w2 = coordination_omega2(s, i, ci, inv_m_max, gamma, &beta);
                n_coord++;
                p = &pc;
            }
            const double t = damped_limit(w2, beta);
            if (t < p->est)
                *p = (struct part){t, sqrt(w2), 0.5 * beta * sqrt(w2), s->id[i]};
        }
        if (pn.est > net.est)
            net = pn;
        if (pc.est > coord.est)
            coord = pc;
    }
    /* The spectral bound of the network, with its largest damping ratio. */
    if (found == 0 && list.n > 0) {
        const double rho = network_rho(s, &list);
        const double t = damped_limit(rho, beta_net);
        if (t > net.est) {
            net = (struct part){t, sqrt(rho), 0.5 * beta_net * sqrt(rho), -1};
            d->spectral = 1;
        }
    }
    const struct part *use = coord.est < net.est ? &coord : &net;
    if (use == &coord)
        d->spectral = 0;
    d->estimate = BAL_DT_MARGIN * use->est;
    d->omega = use->omega;
    d->zeta = use->zeta;
    d->binding_disc = use->binding;
    d->coordination_discs = n_coord;
    free(acc);
    free(co);
    free(list.c);
    /* Every disc held: nothing moves; keep the single-spring value so that
     * dt_fraction still means something. */
    if (!isfinite(d->estimate) || d->estimate <= 0)
        d->estimate = d->single_spring;
}

double bal_timestep_estimate(const struct bal_sim *s)
{
    struct bal_dt_detail d;
    bal_timestep_detail(s, &d);
    return d.estimate;
}

void bal_sim_dt_detail(const struct bal_sim *s, struct bal_dt_detail *d)
{
    bal_timestep_detail(s, d);
}
