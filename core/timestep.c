/*
 * timestep.c — the critical time-step estimate (Cundall & Strack p. 53).
 *
 * BALL estimates the critical step from a single degree of freedom, a mass m
 * on a spring k: Δt_crit = 2 √(m/k).  ballast takes, for every disc, the
 * stiffest contact it can see (over every material present, discs and
 * walls) and both kinds of degree of freedom:
 *
 *   translation:  2 √(m / k_n),  2 √(m / k_s)
 *   rotation:     2 √(I / (k_s R²))   (a shear spring at the rim; for a
 *                 solid disc I = m R²/2, so this is 2 √(m / (2 k_s)))
 *
 * and returns the smallest over all discs.  For the power law the
 * stiffness at δ = δ0 is used (k_n ν).  This is the paper's estimate for one
 * spring; a disc pressed by several contacts at once has a higher
 * frequency, which is why scenes use a fraction of it (issue 6 measures how
 * safe this is).
 */
#include <math.h>

#include "sim.h"

double bal_timestep_estimate(const struct bal_sim *s)
{
    double best = INFINITY;
    for (int i = 0; i < s->n; i++) {
        double kn = 0, ks = 0;
        for (int m = 0; m < s->n_mat; m++) {
            const struct bal_pair_law *L = &s->law[s->mat[i] * s->n_mat + m];
            kn = fmax(kn, L->kn);
            ks = fmax(ks, L->ks);
        }
        if (s->normal_law == BAL_NORMAL_POWER)
            kn *= s->nu;
        const double m = bal_mass(s, i);
        double t = 2 * sqrt(m / kn);
        if (ks > 0) {
            t = fmin(t, 2 * sqrt(m / ks));
            t = fmin(t, 2 * sqrt(bal_inertia(s, i) / (ks * s->r[i] * s->r[i])));
        }
        best = fmin(best, t);
    }
    return best;
}
