/*
 * laws_lanes.h — internal: the kernels of the contact law that the disc–disc
 * loop runs at two widths, one contact at a time and two at a time, written
 * once.  No include guard: laws.h includes this file twice, once per width,
 * with these names defined (and nothing else should include it):
 *
 *   BAL_R            the real: double, or bal_v2 (two doubles, one per lane)
 *   BAL_M            what a comparison of two BAL_R gives: int, or bal_v2m
 *   BAL_KIN          the kinematics: struct bal_kin, or struct bal_kin_x2
 *   BAL_W(name)      the kernel's name at this width: name, or name_x2
 *   BAL_SPLAT(x)     the double x in every lane
 *   BAL_ANY(m)       is m set in some lane?
 *   BAL_SELECT(m, a, b)  a where m is set, else b, lane by lane
 *   BAL_KEEP(m, x)   x where m is set, else +0 (one instruction on vectors,
 *                    where BAL_SELECT takes three); BAL_DROP(m, x): the
 *                    other way round
 *   BAL_ABS, BAL_COPYSIGN, BAL_SQRT, BAL_POW   fabs, copysign, sqrt, pow
 *
 * + − × / and the comparisons < > are C's own at both widths (for bal_v2,
 * GCC's vector extension: lane by lane, and a double operand acts in every
 * lane), and so is & of two masks.  Each lane does the operations of the
 * scalar kernel in the same order, so the two widths give the same bits:
 * write a kernel here as its scalar form reads, with the operations above
 * for what C's operators do not do on vectors (a branch on a value is a
 * BAL_SELECT, or a BAL_ANY around work that only some lanes need).  The
 * pair law (struct bal_pair_law) and the chain's parameters are the same in
 * both lanes: the two-lane loop runs scenes whose discs are of one
 * material.  A loss the energy audit adds up is returned per lane, with a
 * mask of the lanes where it occurred, and the caller adds it contact by
 * contact in the list's order; a flag a kernel sets is returned the same
 * way, as a mask.
 *
 * The kernels here are the whole chain but the energies (laws.h, one
 * contact at a time: the measures call them, no loop does); laws.h wraps
 * the ones that flag a contact or add to a loss in their one-contact form
 * (bal_law_tangential, bal_law_rolling, ...), which the disc–wall loop and
 * the measures call.
 */

/* ---------------------------------------------------------------- normal */

/* k_n δ0 (δ/δ0)^ν, with the common exponents written out (pow costs ten
 * times a product). */
static inline BAL_R BAL_W(bal_law_power_force)(double kn, BAL_R delta, double delta0, double nu)
{
    if (nu == 1.0)
        return kn * delta;
    if (nu == 1.5)
        return kn * delta * BAL_SQRT(delta / delta0);
    if (nu == 2.0)
        return kn * delta * (delta / delta0);
    return kn * delta0 * BAL_POW(delta / delta0, nu);
}

/* F_n at t_N from its history fn_prev (incremental law, kept ≥ 0) or from δ
 * (power law). */
static inline BAL_R BAL_W(bal_law_normal)(const struct bal_law_params *P,
                                          const struct bal_pair_law *L, const BAL_KIN *k,
                                          BAL_R fn_prev)
{
    if (P->normal_law == BAL_NORMAL_INCREMENTAL) {
        const BAL_R fn = fn_prev + L->kn * k->ndot * P->dt;
        return BAL_SELECT(fn < 0, BAL_SPLAT(0.0), fn);
    }
    return BAL_W(bal_law_power_force)(L->kn, k->delta, P->delta0, P->nu);
}

/* ------------------------------------------------------------ tangential */

/* The shear spring at t_N, F_s = fs_prev + k_s ṡ Δt, capped at the Coulomb
 * limit F_max = F_n tan φ_μ + c of the elastic F_n (eqs 15, 17–19): where
 * |F_s| > F_max, F_s = F_max with its sign, *slid is set and *loss holds
 * the slip's loss F_max (|F_s| − F_max)/k_s (the spring gives up
 * (|F_s| − F_max)/k_s of slip against F_max); elsewhere *slid is clear
 * and *loss is not to be read.  Returns F_s.  bal_law_tangential (laws.h) is
 * the one-contact form the loops call. */
static inline BAL_R BAL_W(bal_law_shear)(const struct bal_law_params *P,
                                         const struct bal_pair_law *L, const BAL_KIN *k,
                                         BAL_R fn, BAL_R fs_prev, BAL_R *loss, BAL_M *slid)
{
    BAL_R fs = fs_prev + L->ks * k->sdot * P->dt;
    const BAL_R fmax = fn * L->tan_phi + L->cohesion;
    const BAL_M slide = BAL_ABS(fs) > fmax;
    *slid = slide;
    *loss = BAL_SPLAT(0.0);
    if (BAL_ANY(slide)) {
        *loss = fmax * (BAL_ABS(fs) - fmax) / L->ks;
        fs = BAL_SELECT(slide, BAL_COPYSIGN(fmax, fs), fs);
    }
    return fs;
}

/* --------------------------------------------------------------- damping */

/* The coefficient γ_n (δ/δ0)^ψ of MLH eq. (3). */
static inline BAL_R BAL_W(bal_law_viscous)(const struct bal_law_params *P, BAL_R delta)
{
    if (P->gamma_n == 0)
        return BAL_SPLAT(0.0);
    if (P->psi == 0)
        return BAL_SPLAT(P->gamma_n);
    return P->gamma_n * BAL_POW(delta / P->delta0, P->psi);
}

/* The pair's normal dashpot coefficient μ_n = c_n + γ_n (δ/δ0)^ψ at overlap
 * δ: D_n = μ_n ṅ (C&S eq. 27, MLH eq. 3), and the rolling dashpot lives on
 * it (JYH eq. 49c). */
static inline BAL_R BAL_W(bal_law_dashpot_coef)(const struct bal_law_params *P,
                                                const struct bal_pair_law *L, BAL_R delta)
{
    return L->cn + BAL_W(bal_law_viscous)(P, delta);
}

/* D_s = c_s ṡ where the contact does not slide (C&S p. 52), 0 where it
 * does (slid: the mask bal_law_shear returned). */
static inline BAL_R BAL_W(bal_law_shear_dashpot_of)(const struct bal_pair_law *L, const BAL_KIN *k,
                                                    BAL_M slid)
{
    return BAL_DROP(slid, L->cs * k->sdot);
}

/* --------------------------------------------------------------- rolling */

/* The rolling parameters of a contact of common radius r (JYH eqs 24, 29):
 * the contact width B = δ r and the rolling stiffness K_m = K_n B²/12 (the
 * division by 12 written as a product with its reciprocal: the pair loop
 * avoids a division a contact; round-off of a few ulps). */
struct BAL_W(bal_roll) {
    BAL_R b;               /* contact width B */
    BAL_R km;              /* rolling stiffness K_m */
};

static inline struct BAL_W(bal_roll) BAL_W(bal_law_roll_of)(const struct bal_pair_law *L, BAL_R r)
{
    const BAL_R b = L->rolling * r;
    return (struct BAL_W(bal_roll)){b, L->kn * b * b * (1.0 / 12)};
}

/* The common radius 2 r1 r2/(r1 + r2) of two discs (eq. 9b). */
static inline BAL_R BAL_W(bal_law_common_radius)(BAL_R r1, BAL_R r2)
{
    return 2 * r1 * r2 / (r1 + r2);
}

/* The elastic rolling moment M at t_N from its history m_prev and the
 * increment of relative rotation dtheta = (ω_x − ω_y) Δt, with the elastic
 * F_n of this cycle (the cap M_0 = F_n B/6 of eq. 33 follows the current
 * normal force), in the lanes of `live` (the contacts that still have their
 * rolling resistance); 0 in the others.  Where |M| would pass M_0 (the mask
 * *capped): Model 1 (eq. 35) caps |M| at M_0, the capped spring giving up
 * (|M| − M_0)/K_m of plastic rolling against M_0, *loss = M_0 (|M| − M_0)/K_m;
 * Model 2 (eq. 36) loses M for good, *loss = M²/(2 K_m), the spring's
 * energy, and returns 0.  *loss is not to be read outside *capped.  The
 * caller flags the capped contacts (ROLLING, or BROKEN for Model 2). */
static inline BAL_R BAL_W(bal_law_roll_moment)(const struct bal_law_params *P,
                                               struct BAL_W(bal_roll) R, BAL_R fn, BAL_R dtheta,
                                               BAL_R m_prev, BAL_M live, BAL_R *loss,
                                               BAL_M *capped)
{
    BAL_R m = m_prev + R.km * dtheta;
    const BAL_R m0 = fn * R.b * (1.0 / 6);
    const BAL_M cap = (BAL_ABS(m) > m0) & live;
    *capped = cap;
    *loss = BAL_SPLAT(0.0);
    if (BAL_ANY(cap)) {
        if (P->rolling_model == BAL_ROLLING_MODEL2) {
            *loss = m * m / (2 * R.km);
            m = BAL_DROP(cap, m);
        } else {
            *loss = m0 * (BAL_ABS(m) - m0) / R.km;
            m = BAL_SELECT(cap, BAL_COPYSIGN(m0, m), m);
        }
    }
    return BAL_KEEP(live, m);
}

/* The rolling dashpot's moment M_d = μ_m θ̇_r, μ_m = μ_n B²/12 (eq. 49c),
 * with μ_n the pair's normal dashpot coefficient (bal_law_dashpot_coef), in
 * the lanes of `live`; 0 in the others: a contact that has lost its rolling
 * resistance (Model 2: its width B is gone, Sec. 3.1) has none, for μ_m is
 * the normal dashpots spread over B (eqs 44–47), and they go with it. */
static inline BAL_R BAL_W(bal_law_roll_dashpot)(BAL_R mu_n, struct BAL_W(bal_roll) R,
                                                BAL_R theta_dot, BAL_M live)
{
    return BAL_KEEP(live, mu_n * R.b * R.b * (1.0 / 12) * theta_dot);
}

/* The names this width was compiled with, undefined, so that laws.h can
 * include this file again with those of the other width. */
#undef BAL_R
#undef BAL_M
#undef BAL_KIN
#undef BAL_W
#undef BAL_SPLAT
#undef BAL_ANY
#undef BAL_SELECT
#undef BAL_KEEP
#undef BAL_DROP
#undef BAL_ABS
#undef BAL_COPYSIGN
#undef BAL_SQRT
#undef BAL_POW
