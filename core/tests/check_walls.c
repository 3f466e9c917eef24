/*
 * check_walls.c — suite "walls": straight rigid walls (C&S Fig. 4, p. 53):
 * the closest point of the segment A = P + h1 e … B = P + h2 e, disc–wall
 * contacts on the interior and at the end points, the contact normal, the
 * wall resultant (probes wall_f1, wall_f2, wall_moment, wall_ecc), walls
 * moved by a stage, and the controllers a stage gives its walls.
 *
 * A disc–wall contact is a disc–disc contact whose body y is the wall's
 * closest point c, of radius 0: e_c = (c − x)/|c − x| points from the disc
 * centre to the wall, the force on the disc is −(F_n e_c + F_s t_c), the
 * force on the wall +(F_n e_c + F_s t_c), and the velocity of the wall at
 * c is V + ω × (c − P).  The wall resultant is that of the forces acting
 * on the wall at its own point c (A_w of C&S Fig. 1): the moment about P is
 * (c − P) × F and the eccentricity uses (c − P)·e.  (contacts.tsv reports
 * the contact point halfway between A_w and the disc's surface point A_D;
 * for a normal force on the interior the two give the same moment.)
 */
#include <math.h>
#include <stdio.h>

#include "check_main.h"

/* A few operations on O(1) numbers (see check_contacts.c): 1e-12 relative
 * is far above round-off and far below any error of a term or a sign. */
#define ROUNDOFF_REL 1e-12
/* Absolute round-off of O(1) coordinates after a few operations. */
#define ROUNDOFF_ABS 1e-14

#define ASSERT_REL(value, expected) \
    ck_assert_double_eq_tol((value), (expected), ROUNDOFF_REL * fabs(expected) + 1e-300)

/* The wall of these tests: P = (0.7, −0.3), α = 23.5°, h1 = −1.2, h2 = 2.6;
 * n = (−sin α, cos α) is its left normal. */
#define PX 0.7
#define PY (-0.3)
#define ALPHA_DEG 23.5
#define H1 (-1.2)
#define H2 2.6
#define KN 5.3e4
#define R 0.5
#define DT 1.3e-3

struct frame {
    double e[2], n[2];
};

static struct frame wall_frame(void)
{
    const double a = ALPHA_DEG * BAL_PI / 180;
    struct frame f = {{cos(a), sin(a)}, {-sin(a), cos(a)}};
    return f;
}

/* The point P + h e + d n. */
static void at(const struct frame *fr, double h, double d, double out[2])
{
    out[0] = PX + h * fr->e[0] + d * fr->n[0];
    out[1] = PY + h * fr->e[1] + d * fr->n[1];
}

/* A scene with the wall and the given [disc] sections (text), and probes of
 * the wall's resultant. */
static struct tfx *wall_scene(const char *settings, const char *discs)
{
    return tfx_newf("wall",
                    "[settings]\ndt = %.17g\n%s\n"
                    "[material g]\nkn = %.17g\nfriction = 0.9\ncohesion = 0\ndensity = 2.385\n"
                    "[material w]\nkn = %.17g\nfriction = 0.9\n"
                    "[wall w]\np = %.17g %.17g\nangle = %.17g\nh1 = %.17g\nh2 = %.17g\n"
                    "material = w\n"
                    "%s"
                    "[stage s]\ncycles = 1\n"
                    "[probe f1]\nquantity = wall_f1\na = w\n"
                    "[probe f2]\nquantity = wall_f2\na = w\n"
                    "[probe mom]\nquantity = wall_moment\na = w\n"
                    "[probe ecc]\nquantity = wall_ecc\na = w\n",
                    DT, settings, KN, KN, PX, PY, ALPHA_DEG, H1, H2, discs);
}

static int disc_text(char *buf, size_t size, const char *name, const double x[2],
                     const double v[2])
{
    return snprintf(buf, size, "[disc %s]\nx = %.17g %.17g\nr = %.17g\nv = %.17g %.17g\nmaterial = g\n",
                    name, x[0], x[1], R, v[0], v[1]);
}

/* bal_walls_closest: the foot of the perpendicular on the interior, the end
 * point beyond either end, on both sides of the wall. */
START_TEST(walls_closest_point)
{
    const struct frame fr = wall_frame();
    double x[2], v[2] = {0, 0};
    char discs[256];
    at(&fr, 0.9, 3.0, x); /* one disc far away: the scene needs a disc */
    disc_text(discs, sizeof discs, "d", x, v);
    struct tfx *f = wall_scene("", discs);
    const struct bal_wall *w = &f->sim->walls[0];
    static const struct {
        double h, d;       /* the point P + h e + d n */
        double hc;         /* expected closest point P + hc e */
    } cases[] = {
        {0.9, 0.35, 0.9},        /* interior, left side */
        {0.9, -0.35, 0.9},       /* interior, right side: walls are two-sided */
        {H2 + 0.25, 0.3, H2},    /* beyond B */
        {H1 - 0.4, -0.1, H1},    /* beyond A */
        {H2 - 1e-3, 0.2, H2 - 1e-3},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        double pt[2], c[2], cx, cy;
        at(&fr, cases[k].h, cases[k].d, pt);
        at(&fr, cases[k].hc, 0, c);
        const double d2 = bal_walls_closest(w, pt[0], pt[1], &cx, &cy);
        const double dh = cases[k].h - cases[k].hc;
        ck_assert_double_eq_tol(cx, c[0], ROUNDOFF_ABS);
        ck_assert_double_eq_tol(cy, c[1], ROUNDOFF_ABS);
        ck_assert_double_eq_tol(d2, dh * dh + cases[k].d * cases[k].d, ROUNDOFF_ABS);
    }
}
END_TEST

/* A disc overlapping the interior by 0.03, approaching along −n at 0.31:
 * e_c = −n, ṅ = 0.31, F_n = k_n ṅ Δt; the force on the disc is +F_n n, on
 * the wall −F_n n: F1 = F_n sin α, F2 = −F_n cos α; the contact point is
 * c = P + 0.9 e, so the moment about P is 0.9 e × (−F_n n) = −0.9 F_n and the
 * eccentricity (0.9 − (h1 + h2)/2) / ((h2 − h1)/2). */
START_TEST(walls_interior_contact)
{
    const struct frame fr = wall_frame();
    const double u = 0.31, h = 0.9;
    double x[2], v[2] = {-u * fr.n[0], -u * fr.n[1]};
    at(&fr, h, R - 0.03, x);
    char discs[256];
    disc_text(discs, sizeof discs, "d", x, v);
    struct tfx *f = wall_scene("", discs);
    t_steps(f, 1);

    const double fn = KN * u * DT;
    const int i = t_slot(f, "d");
    const struct bal_pairs *L;
    const long c = t_contact(f, "d", "w", &L);
    ck_assert_int_eq(L->flags[c], BAL_PAIR_TOUCHING);
    ASSERT_REL(L->fn[c], fn);
    ck_assert_double_eq_tol(pair_fs(L, c), 0.0, ROUNDOFF_REL * fn);
    ASSERT_REL(f->sim->f[3 * i], fn * fr.n[0]);
    ASSERT_REL(f->sim->f[3 * i + 1], fn * fr.n[1]);
    ASSERT_REL(t_probe_value(f, "f1"), -fn * fr.n[0]);
    ASSERT_REL(t_probe_value(f, "f2"), -fn * fr.n[1]);
    ASSERT_REL(t_probe_value(f, "mom"), -h * fn);
    ASSERT_REL(t_probe_value(f, "ecc"), (h - 0.5 * (H1 + H2)) / (0.5 * (H2 - H1)));
}
END_TEST

/* The wall is two-sided: a disc on the right (−n) side approaching along +n
 * is pushed along −n, and the wall feels +F_n n. */
START_TEST(walls_other_side)
{
    const struct frame fr = wall_frame();
    const double u = 0.22, h = -0.35;
    double x[2], v[2] = {u * fr.n[0], u * fr.n[1]};
    at(&fr, h, -(R - 0.02), x);
    char discs[256];
    disc_text(discs, sizeof discs, "d", x, v);
    struct tfx *f = wall_scene("", discs);
    t_steps(f, 1);
    const double fn = KN * u * DT;
    const int i = t_slot(f, "d");
    ASSERT_REL(f->sim->f[3 * i], -fn * fr.n[0]);
    ASSERT_REL(f->sim->f[3 * i + 1], -fn * fr.n[1]);
    ASSERT_REL(t_probe_value(f, "f1"), fn * fr.n[0]);
    ASSERT_REL(t_probe_value(f, "f2"), fn * fr.n[1]);
    ASSERT_REL(t_probe_value(f, "mom"), h * fn); /* h e × (F_n n) = h F_n */
}
END_TEST

/* Beyond the ends the closest point is the end point.  Disc `near` sits past
 * B at B + 0.3 e + 0.2 n, 0.3606 < R from B, and moves toward B at 0.21:
 * it touches the corner, e_c = (B − x)/|B − x|, F_n = k_n 0.21 Δt, pushed
 * radially away from B.  Disc `far` sits past A at A − 0.45 e − 0.3 n,
 * 0.5408 > R from A: no contact, although its distance to the wall's line
 * (0.3) is less than R. */
START_TEST(walls_end_point_contact)
{
    const struct frame fr = wall_frame();
    const double u = 0.21;
    double xn[2], xf[2], b[2];
    at(&fr, H2 + 0.3, 0.2, xn);
    at(&fr, H1 - 0.45, -0.3, xf);
    at(&fr, H2, 0, b);
    const double dn = hypot(xn[0] - b[0], xn[1] - b[1]);
    const double ec[2] = {(b[0] - xn[0]) / dn, (b[1] - xn[1]) / dn};
    double vn[2] = {u * ec[0], u * ec[1]}, vf[2] = {0, 0};
    char discs[512];
    int len = disc_text(discs, sizeof discs, "near", xn, vn);
    disc_text(discs + len, sizeof discs - (size_t)len, "far", xf, vf);
    struct tfx *f = wall_scene("", discs);
    t_steps(f, 1);

    const double fn = KN * u * DT;
    const struct bal_pairs *L;
    long c = t_contact(f, "near", "w", &L);
    ck_assert_int_eq(L->flags[c], BAL_PAIR_TOUCHING);
    ASSERT_REL(L->fn[c], fn);
    const int in = t_slot(f, "near");
    ASSERT_REL(f->sim->f[3 * in], -fn * ec[0]);
    ASSERT_REL(f->sim->f[3 * in + 1], -fn * ec[1]);
    /* The contact point is B: moment about P is h2 e × F_wall. */
    const double fw[2] = {fn * ec[0], fn * ec[1]};
    ASSERT_REL(t_probe_value(f, "mom"), H2 * (fr.e[0] * fw[1] - fr.e[1] * fw[0]));
    ASSERT_REL(t_probe_value(f, "ecc"), (H2 - 0.5 * (H1 + H2)) / (0.5 * (H2 - H1)));

    c = t_contact(f, "far", "w", &L);
    ck_assert_int_eq(L->flags[c], 0);
    ck_assert_double_eq(f->sim->f[3 * (t_slot(f, "far"))], 0.0);
    ck_assert_double_eq(f->sim->f[3 * (t_slot(f, "far")) + 1], 0.0);
}
END_TEST

/* Two discs on the same side at h_a = −0.65 and h_b = 1.85, approaching at
 * 0.31 and 0.17: F_a = k_n 0.31 Δt, F_b = k_n 0.17 Δt; the wall resultant
 * is −(F_a + F_b) n, the moment −(h_a F_a + h_b F_b), the resultant normal
 * force acts at s = (h_a F_a + h_b F_b)/(F_a + F_b): eccentricity
 * (s − 0.7)/1.9 (C&S Table 1, footnote 1). */
START_TEST(walls_resultant_of_two_contacts)
{
    const struct frame fr = wall_frame();
    const double ha = -0.65, hb = 1.85, ua = 0.31, ub = 0.17;
    double xa[2], xb[2], va[2] = {-ua * fr.n[0], -ua * fr.n[1]}, vb[2] = {-ub * fr.n[0],
                                                                          -ub * fr.n[1]};
    at(&fr, ha, R - 0.01, xa);
    at(&fr, hb, R - 0.02, xb);
    char discs[512];
    int len = disc_text(discs, sizeof discs, "da", xa, va);
    disc_text(discs + len, sizeof discs - (size_t)len, "db", xb, vb);
    struct tfx *f = wall_scene("", discs);
    t_steps(f, 1);
    const double fa = KN * ua * DT, fb = KN * ub * DT;
    ASSERT_REL(t_probe_value(f, "f1"), -(fa + fb) * fr.n[0]);
    ASSERT_REL(t_probe_value(f, "f2"), -(fa + fb) * fr.n[1]);
    ASSERT_REL(t_probe_value(f, "mom"), -(ha * fa + hb * fb));
    const double s = (ha * fa + hb * fb) / (fa + fb);
    ASSERT_REL(t_probe_value(f, "ecc"), (s - 0.5 * (H1 + H2)) / (0.5 * (H2 - H1)));
}
END_TEST

/* A stage moves P with V and turns the wall about P with ω (C&S p. 53):
 * after N cycles P_N = P_0 + N V Δt and α_N = α_0 + N ω Δt. */
START_TEST(walls_stage_motion)
{
    const struct frame fr = wall_frame();
    double x[2], v[2] = {0, 0};
    at(&fr, 0.9, 3.0, x);
    char discs[256];
    disc_text(discs, sizeof discs, "d", x, v);
    char text[T_TEXT_MAX];
    snprintf(text, sizeof text,
             "[settings]\ndt = %.17g\n"
             "[material g]\nkn = 5.3e4\ndensity = 2.385\n"
             "[wall w]\np = %.17g %.17g\nangle = %.17g\nh1 = %.17g\nh2 = %.17g\nmaterial = g\n%s"
             "[stage s]\ncycles = 25\nmove = w 0.13 -0.07 0.21\n",
             DT, PX, PY, ALPHA_DEG, H1, H2, discs);
    struct tfx *f = tfx_new(text, "moving");
    const int n = 25;
    t_steps(f, n);
    const struct bal_wall *w = &f->sim->walls[0];
    /* n additions of O(1e-4) increments to O(1) values, each rounding by
     * ~1e-16: n · 1e-15 bounds the sum with a tenfold margin. */
    const double tol = n * 1e-15;
    ck_assert_double_eq_tol(w->p[0], PX + n * 0.13 * DT, tol);
    ck_assert_double_eq_tol(w->p[1], PY + n * -0.07 * DT, tol);
    const double alpha = ALPHA_DEG * BAL_PI / 180 + n * 0.21 * DT;
    ck_assert_double_eq_tol(w->alpha, alpha, tol);
    ck_assert_double_eq_tol(w->e[0], cos(alpha), tol);
    ck_assert_double_eq_tol(w->e[1], sin(alpha), tol);
}
END_TEST

/* Each stage gives the walls it names their controller and its parameters
 * (`move` names the prescribed one: V and ω as given); a wall the stage
 * does not name is at rest, with no controller, whatever the stage before
 * did.  Stage a moves w1 only, stage b w2 only, stage c neither. */
START_TEST(walls_stage_controllers)
{
    char text[T_TEXT_MAX];
    snprintf(text, sizeof text,
             "[settings]\ndt = %.17g\n"
             "[material g]\nkn = 5.3e4\ndensity = 2.385\n"
             "[wall w1]\np = 0 0\nangle = 0\nh1 = -1\nh2 = 1\nmaterial = g\n"
             "[wall w2]\np = 0 3\nangle = 90\nh1 = -1\nh2 = 1\nmaterial = g\n"
             "[disc d]\nx = 5 5\nr = 0.5\nmaterial = g\n"
             "[stage a]\ncycles = 3\nmove = w1 0.13 -0.07 0.21\n"
             "[stage b]\ncycles = 2\nmove = w2 -0.4 0.25 0\n"
             "[stage c]\ncycles = 1\n",
             DT);
    struct tfx *f = tfx_new(text, "controllers");
    struct bal_sim *s = f->sim;
    const struct bal_wall *w1 = &s->walls[0], *w2 = &s->walls[1];

    bal_sim_set_stage(s, 0);
    ck_assert_ptr_nonnull(w1->controller);
    ck_assert_str_eq(w1->controller->name, "prescribed");
    ck_assert_ptr_eq(w1->move, &f->sc.stages[0].moves[0]);
    ck_assert(w1->v[0] == 0.13 && w1->v[1] == -0.07 && w1->omega == 0.21);
    ck_assert_ptr_null(w2->controller);
    ck_assert(w2->v[0] == 0 && w2->v[1] == 0 && w2->omega == 0);
    ck_assert_int_eq(s->walls_controlled, 0); /* prescribed: nothing per cycle */

    bal_sim_set_stage(s, 1);
    ck_assert_ptr_null(w1->controller);
    ck_assert_ptr_null(w1->move);
    ck_assert(w1->v[0] == 0 && w1->v[1] == 0 && w1->omega == 0);
    ck_assert_str_eq(w2->controller->name, "prescribed");
    ck_assert(w2->v[0] == -0.4 && w2->v[1] == 0.25 && w2->omega == 0);

    /* The prescribed controller acts only when its stage begins: a cycle
     * (which runs the controllers after the wall forces) keeps V and ω. */
    t_steps(f, 2);
    ck_assert(w2->v[0] == -0.4 && w2->v[1] == 0.25 && w2->omega == 0);

    bal_sim_set_stage(s, 2);
    ck_assert_ptr_null(w1->controller);
    ck_assert_ptr_null(w2->controller);
    ck_assert(w2->v[0] == 0 && w2->v[1] == 0);
}
END_TEST

/* A disc at rest against a wall that moves with V = (0.13, −0.07) and turns
 * at ω = 0.21 about P.  After cycle 1 (wall moved first, as in eq. 1):
 *   P1 = P0 + V Δt, α1 = α0 + ω Δt, c = P1 + h e1 with h = (x − P1)·e1,
 *   e_c = (c − x)/|c − x|, t_c = (e_c2, −e_c1),
 *   wall velocity at c: V + ω (−(c − P1)_2, (c − P1)_1),
 *   ṅ = (0 − V_c)·e_c, ṡ = (0 − V_c)·t_c,
 *   F_n = k_n ṅ Δt, F_s = k_s ṡ Δt (below the cap: sticking).
 * The disc feels −(F_n e_c + F_s t_c) and the moment F_s R; the wall
 * +(F_n e_c + F_s t_c) and the moment (c − P1) × F about P. */
START_TEST(walls_moving_wall_contact)
{
    const struct frame fr = wall_frame();
    const double vw[2] = {0.13, -0.07}, om = 0.21;
    double x[2], v[2] = {0, 0};
    at(&fr, 1.4, 0.48, x);
    char discs[256];
    disc_text(discs, sizeof discs, "d", x, v);
    char text[T_TEXT_MAX];
    snprintf(text, sizeof text,
             "[settings]\ndt = %.17g\n"
             "[material g]\nkn = %.17g\nfriction = 0.9\ndensity = 2.385\n"
             "[wall w]\np = %.17g %.17g\nangle = %.17g\nh1 = %.17g\nh2 = %.17g\nmaterial = g\n%s"
             "[stage s]\ncycles = 1\nmove = w %.17g %.17g %.17g\n"
             "[probe f1]\nquantity = wall_f1\na = w\n"
             "[probe f2]\nquantity = wall_f2\na = w\n"
             "[probe mom]\nquantity = wall_moment\na = w\n",
             DT, KN, PX, PY, ALPHA_DEG, H1, H2, discs, vw[0], vw[1], om);
    struct tfx *f = tfx_new(text, "moving");
    t_steps(f, 1);

    const double p1[2] = {PX + vw[0] * DT, PY + vw[1] * DT};
    const double a1 = ALPHA_DEG * BAL_PI / 180 + om * DT;
    const double e1[2] = {cos(a1), sin(a1)};
    const double h = (x[0] - p1[0]) * e1[0] + (x[1] - p1[1]) * e1[1];
    const double c[2] = {p1[0] + h * e1[0], p1[1] + h * e1[1]};
    const double dist = hypot(c[0] - x[0], c[1] - x[1]);
    const double ec[2] = {(c[0] - x[0]) / dist, (c[1] - x[1]) / dist};
    const double tc[2] = {ec[1], -ec[0]};
    const double vc[2] = {vw[0] - om * (c[1] - p1[1]), vw[1] + om * (c[0] - p1[0])};
    const double ndot = -(vc[0] * ec[0] + vc[1] * ec[1]);
    const double sdot = -(vc[0] * tc[0] + vc[1] * tc[1]);
    const double fn = KN * ndot * DT, fs = KN * sdot * DT;
    ck_assert(fn > 0);
    ck_assert(fabs(fs) < 0.9 * fn);

    const struct bal_pairs *L;
    const long k = t_contact(f, "d", "w", &L);
    const int i = t_slot(f, "d");
    ck_assert_int_eq(L->flags[k], BAL_PAIR_TOUCHING);
    ASSERT_REL(L->fn[k], fn);
    ASSERT_REL(pair_fs(L, k), fs);
    const double fw[2] = {fn * ec[0] + fs * tc[0], fn * ec[1] + fs * tc[1]};
    ASSERT_REL(f->sim->f[3 * i], -fw[0]);
    ASSERT_REL(f->sim->f[3 * i + 1], -fw[1]);
    ASSERT_REL(f->sim->f[3 * i + 2], fs * R);
    ASSERT_REL(t_probe_value(f, "f1"), fw[0]);
    ASSERT_REL(t_probe_value(f, "f2"), fw[1]);
    ASSERT_REL(t_probe_value(f, "mom"), (c[0] - p1[0]) * fw[1] - (c[1] - p1[1]) * fw[0]);
}
END_TEST

Suite *suite_walls(void)
{
    Suite *s = suite_create("walls");
    TCase *tc = tcase_create("geometry");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, walls_closest_point);
    tcase_add_test(tc, walls_stage_motion);
    tcase_add_test(tc, walls_stage_controllers);
    suite_add_tcase(s, tc);

    tc = tcase_create("contact");
    tcase_add_checked_fixture(tc, NULL, tfx_teardown);
    tcase_add_test(tc, walls_interior_contact);
    tcase_add_test(tc, walls_other_side);
    tcase_add_test(tc, walls_end_point_contact);
    tcase_add_test(tc, walls_resultant_of_two_contacts);
    tcase_add_test(tc, walls_moving_wall_contact);
    suite_add_tcase(s, tc);
    return s;
}
