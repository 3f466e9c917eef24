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
 *   BAL_ABS, BAL_COPYSIGN, BAL_SQRT, BAL_POW   fabs, copysign, sqrt, pow
 *
 * + − × / and the comparisons < > are C's own at both widths (for bal_v2,
 * GCC's vector extension: lane by lane, and a double operand acts in every
 * lane).  Each lane does the operations of the scalar kernel in the same
 * order, so the two widths give the same bits: write a kernel here as its
 * scalar form reads, with the operations above for what C's operators do
 * not do on vectors (a branch on a value is a BAL_SELECT, or a BAL_ANY
 * around work that only some lanes need).  The pair law (struct
 * bal_pair_law) and the chain's parameters are the same in both lanes: the
 * two-lane loop runs scenes of one material.  A loss the energy audit adds
 * up is returned per lane, with a mask of the lanes where it occurred, and
 * the caller adds it contact by contact in the list's order.
 *
 * The chain's other kernels (damping, rolling, the energies) are in laws.h,
 * one contact at a time: no two-lane loop runs them.
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

/* The names this width was compiled with, undefined, so that laws.h can
 * include this file again with those of the other width. */
#undef BAL_R
#undef BAL_M
#undef BAL_KIN
#undef BAL_W
#undef BAL_SPLAT
#undef BAL_ANY
#undef BAL_SELECT
#undef BAL_ABS
#undef BAL_COPYSIGN
#undef BAL_SQRT
#undef BAL_POW
