/*
 * vtk.c — a snapshot as VTK XML PolyData (ASCII), the files ParaView and
 * VisIt read, and the .pvd collection that gives each frame its simulated
 * time (snapshots.c writes them, with settings.vtk = 1).
 *
 *   discs.FFFFFF.vtp     a point per disc at its centre (z = 0), in scene
 *                        order, a vertex cell each; point data radius, id,
 *                        velocity (vx, vy, 0), omega, theta (degrees), force
 *                        (fx, fy, 0), torque, fixed: the columns of the
 *                        frame's discs.FFFFFF.tsv
 *   contacts.FFFFFF.vtp  a line per touching contact, in the rows' order of
 *                        contacts.FFFFFF.tsv: disc to disc from centre to
 *                        centre, disc to wall from the disc's centre to the
 *                        contact point; cell data fn, fs, mr (with rolling
 *                        resistance), sliding, rolling (0, 1 at the cap, 2
 *                        lost: Model 2; 0 without rolling resistance), kind
 *                        (0 disc, 1 wall)
 *   walls.FFFFFF.vtp     a line per wall from end A to end B; cell data f
 *                        (f1, f2, 0), the resultant of the discs on it
 *   snapshots.pvd        every frame written, three parts each (0 discs,
 *                        1 contacts, 2 walls), timestep = simulated time
 *
 * Every number is printed with %.17g, as in the TSV files, so a reader gets
 * the same doubles (harness/tests/test_vtk.py reads them back with VTK).
 * docs/paraview.md says how to draw the discs to scale.
 */
#include <stdio.h>

#include "measure.h"
#include "output.h"
#include "snapshots.h"
#include "vtk.h"

static void begin(FILE *f, long points, long verts, long lines)
{
    fputs("<?xml version=\"1.0\"?>\n"
          "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
          "<PolyData>\n", f);
    fprintf(f, "<Piece NumberOfPoints=\"%ld\" NumberOfVerts=\"%ld\" NumberOfLines=\"%ld\" "
               "NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n", points, verts, lines);
}

static void end(FILE *f)
{
    fputs("</Piece>\n</PolyData>\n</VTKFile>\n", f);
}

static void array_open(FILE *f, const char *type, const char *name, int components)
{
    fprintf(f, "<DataArray type=\"%s\"", type);
    if (name)
        fprintf(f, " Name=\"%s\"", name);
    if (components > 1)
        fprintf(f, " NumberOfComponents=\"%d\"", components);
    fputs(" format=\"ascii\">\n", f);
}

/* n values on one line. */
static void values(FILE *f, const double *v, int n)
{
    for (int q = 0; q < n; q++)
        fprintf(f, q ? " %.17g" : "%.17g", v[q]);
    fputc('\n', f);
}

/* The cells of n items of `per` points each, the points in order: the
 * connectivity 0, 1, 2, ... and the offsets per, 2 per, ... */
static void cells(FILE *f, const char *kind, long n, int per)
{
    fprintf(f, "<%s>\n", kind);
    array_open(f, "Int64", "connectivity", 1);
    for (long k = 0; k < n * per; k++)
        fprintf(f, "%ld\n", k);
    fputs("</DataArray>\n", f);
    array_open(f, "Int64", "offsets", 1);
    for (long k = 1; k <= n; k++)
        fprintf(f, "%ld\n", k * per);
    fputs("</DataArray>\n", f);
    fprintf(f, "</%s>\n", kind);
}

/* ------------------------------------------------------------------ */
/* Discs                                                               */
/* ------------------------------------------------------------------ */

/* What a disc's array holds: the components of the disc in array slot i. */
typedef void (*disc_get)(const struct bal_sim *s, int i, double *v);

static void disc_centre(const struct bal_sim *s, int i, double *v)
{
    v[0] = s->x[i], v[1] = s->y[i], v[2] = 0;
}

static void disc_radius(const struct bal_sim *s, int i, double *v)
{
    v[0] = s->r[i];
}

static void disc_id(const struct bal_sim *s, int i, double *v)
{
    v[0] = s->id[i];
}

static void disc_velocity(const struct bal_sim *s, int i, double *v)
{
    double w;
    bal_measure_velocity(s, i, &v[0], &v[1], &w);
    v[2] = 0;
}

static void disc_omega(const struct bal_sim *s, int i, double *v)
{
    double vx, vy;
    bal_measure_velocity(s, i, &vx, &vy, &v[0]);
}

static void disc_theta(const struct bal_sim *s, int i, double *v)
{
    v[0] = s->th[i] * (180 / BAL_PI); /* degrees, as discs.tsv */
}

static void disc_force(const struct bal_sim *s, int i, double *v)
{
    v[0] = s->f[3 * i], v[1] = s->f[3 * i + 1], v[2] = 0;
}

static void disc_torque(const struct bal_sim *s, int i, double *v)
{
    v[0] = s->f[3 * i + 2];
}

static void disc_fixed(const struct bal_sim *s, int i, double *v)
{
    v[0] = s->fixed[i];
}

/* One array over the discs in scene order (NULL name: the points). */
static void disc_array(const struct bal_sim *s, FILE *f, const char *type, const char *name,
                       int components, disc_get get)
{
    double v[3];
    array_open(f, type, name, components);
    for (int k = 0; k < s->n; k++) {
        get(s, s->slot[k], v);
        values(f, v, components);
    }
    fputs("</DataArray>\n", f);
}

void bal_vtk_discs(const struct bal_sim *s, FILE *f)
{
    begin(f, s->n, s->n, 0);
    fputs("<PointData Scalars=\"radius\" Vectors=\"velocity\">\n", f);
    disc_array(s, f, "Float64", "radius", 1, disc_radius);
    disc_array(s, f, "Int32", "id", 1, disc_id);
    disc_array(s, f, "Float64", "velocity", 3, disc_velocity);
    disc_array(s, f, "Float64", "omega", 1, disc_omega);
    disc_array(s, f, "Float64", "theta", 1, disc_theta);
    disc_array(s, f, "Float64", "force", 3, disc_force);
    disc_array(s, f, "Float64", "torque", 1, disc_torque);
    disc_array(s, f, "Int32", "fixed", 1, disc_fixed);
    fputs("</PointData>\n<Points>\n", f);
    disc_array(s, f, "Float64", NULL, 3, disc_centre);
    fputs("</Points>\n", f);
    cells(f, "Verts", s->n, 1);
    end(f);
}

/* ------------------------------------------------------------------ */
/* Contacts                                                            */
/* ------------------------------------------------------------------ */

/* What a contact's array holds: `n` numbers of the touching candidate c of the
 * disc–disc (walls 0) or disc–wall list (walls 1). */
typedef void (*contact_get)(const struct bal_sim *s, int walls, long c, double *v);

static const struct bal_pairs *list_of(const struct bal_sim *s, int walls)
{
    return walls ? &s->pw : &s->pp;
}

/* Both ends of the line: the disc's centre, and the other disc's centre or
 * the contact point with the wall. */
static void contact_ends(const struct bal_sim *s, int walls, long c, double *v)
{
    const struct bal_pairs *p = list_of(s, walls);
    const int i = p->i[c];
    v[0] = s->x[i], v[1] = s->y[i], v[2] = 0;
    if (walls) {
        double nx, ny;
        bal_output_contact_point(s, 1, c, &v[3], &v[4], &nx, &ny);
    } else {
        v[3] = s->x[p->j[c]], v[4] = s->y[p->j[c]];
    }
    v[5] = 0;
}

static void contact_fn(const struct bal_sim *s, int walls, long c, double *v)
{
    v[0] = list_of(s, walls)->fn[c];
}

static void contact_fs(const struct bal_sim *s, int walls, long c, double *v)
{
    v[0] = walls ? s->pw.fs[c] : pair_fs(&s->pp, c); /* as contacts.tsv */
}

static void contact_mr(const struct bal_sim *s, int walls, long c, double *v)
{
    v[0] = list_of(s, walls)->mr[c];
}

static void contact_sliding(const struct bal_sim *s, int walls, long c, double *v)
{
    v[0] = (list_of(s, walls)->flags[c] & BAL_PAIR_SLIDING) != 0;
}

static void contact_rolling(const struct bal_sim *s, int walls, long c, double *v)
{
    const uint8_t fl = list_of(s, walls)->flags[c];
    v[0] = (fl & BAL_PAIR_BROKEN) ? 2 : (fl & BAL_PAIR_ROLLING) ? 1 : 0;
}

static void contact_kind(const struct bal_sim *s, int walls, long c, double *v)
{
    (void)s, (void)c;
    v[0] = walls;
}

/* One array over the touching contacts, disc–disc then disc–wall, `n`
 * numbers each (NULL name: the points, two per contact). */
static void contact_array(const struct bal_sim *s, FILE *f, const char *type, const char *name,
                          int components, int n, contact_get get)
{
    double v[6];
    array_open(f, type, name, components);
    for (int walls = 0; walls < 2; walls++) {
        const struct bal_pairs *p = list_of(s, walls);
        for (long c = 0; c < p->n; c++) {
            if (!(p->flags[c] & BAL_PAIR_TOUCHING))
                continue;
            get(s, walls, c, v);
            values(f, v, n);
        }
    }
    fputs("</DataArray>\n", f);
}

void bal_vtk_contacts(const struct bal_sim *s, FILE *f)
{
    long n = 0;
    for (int walls = 0; walls < 2; walls++) {
        const struct bal_pairs *p = list_of(s, walls);
        for (long c = 0; c < p->n; c++)
            n += (p->flags[c] & BAL_PAIR_TOUCHING) != 0;
    }
    begin(f, 2 * n, 0, n);
    fputs("<CellData Scalars=\"fn\">\n", f);
    contact_array(s, f, "Float64", "fn", 1, 1, contact_fn);
    contact_array(s, f, "Float64", "fs", 1, 1, contact_fs);
    if (s->has_rolling)
        contact_array(s, f, "Float64", "mr", 1, 1, contact_mr);
    contact_array(s, f, "Int32", "sliding", 1, 1, contact_sliding);
    contact_array(s, f, "Int32", "rolling", 1, 1, contact_rolling);
    contact_array(s, f, "Int32", "kind", 1, 1, contact_kind);
    fputs("</CellData>\n<Points>\n", f);
    contact_array(s, f, "Float64", NULL, 3, 6, contact_ends);
    fputs("</Points>\n", f);
    cells(f, "Lines", n, 2);
    end(f);
}

/* ------------------------------------------------------------------ */
/* Walls                                                               */
/* ------------------------------------------------------------------ */

void bal_vtk_walls(const struct bal_sim *s, FILE *f)
{
    begin(f, 2 * (long)s->n_walls, 0, s->n_walls);
    fputs("<CellData Vectors=\"f\">\n", f);
    array_open(f, "Float64", "f", 3);
    for (int k = 0; k < s->n_walls; k++)
        values(f, (const double[3]){s->walls[k].f[0], s->walls[k].f[1], 0}, 3);
    fputs("</DataArray>\n</CellData>\n<Points>\n", f);
    array_open(f, "Float64", NULL, 3);
    for (int k = 0; k < s->n_walls; k++) {
        const struct bal_wall *W = &s->walls[k];
        /* A and B as walls.tsv writes them */
        values(f, (const double[6]){W->p[0] + W->h1 * W->e[0], W->p[1] + W->h1 * W->e[1], 0,
                                    W->p[0] + W->h2 * W->e[0], W->p[1] + W->h2 * W->e[1], 0}, 6);
    }
    fputs("</DataArray>\n</Points>\n", f);
    cells(f, "Lines", s->n_walls, 2);
    end(f);
}

/* ------------------------------------------------------------------ */
/* The collection                                                      */
/* ------------------------------------------------------------------ */

void bal_vtk_collection(const struct bal_sim *s, FILE *f)
{
    static const char *const parts[] = {"discs", "contacts", "walls"};
    fputs("<?xml version=\"1.0\"?>\n"
          "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
          "<Collection>\n", f);
    char name[64];
    for (long k = 0; k < s->snap.n; k++)
        for (int q = 0; q < 3; q++) {
            bal_snapshots_name(name, sizeof name, parts[q], k, "vtp");
            fprintf(f, "<DataSet timestep=\"%.17g\" group=\"\" part=\"%d\" name=\"%s\" file=\"%s\"/>\n",
                    s->snap.frames[k].time, q, parts[q], name);
        }
    fputs("</Collection>\n</VTKFile>\n", f);
}
