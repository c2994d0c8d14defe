/* geometry.c - see geometry.h. */
#include "geometry.h"

#include <math.h>
#include <stdlib.h>

int geom_inside_polygon(const struct polyline *poly, double x, double z)
{
    int inside = 0;
    for (size_t i = 0, j = poly->n - 1; i < poly->n; j = i++) {
        const double xi = poly->x[i], zi = poly->z[i], xj = poly->x[j], zj = poly->z[j];
        if ((zi > z) != (zj > z)) {
            const double xc = xi + (z - zi) * (xj - xi) / (zj - zi);
            if (x < xc) inside = !inside;
        }
    }
    return inside;
}

/* The point of an open polyline nearest to (x, z): its distance; the left normal there (unit on a
 * segment, at a shared vertex the sum of both segments' unit normals); the side of the line
 * (x, z) is on (+1 left, -1 right); and whether the point is one of the two open ends. */
struct nearest {
    double distance, nx, nz, left;
    int at_end;
};

static struct nearest nearest_on_polyline(const struct polyline *line, double x, double z)
{
    struct nearest r = {.distance = INFINITY, .nx = 0.0, .nz = 0.0, .left = 1.0, .at_end = 0};
    for (size_t k = 0; k + 1 < line->n; k++) {
        const double ax = line->x[k], az = line->z[k];
        const double ex = line->x[k + 1] - ax, ez = line->z[k + 1] - az;
        const double len2 = ex * ex + ez * ez;
        double t = ((x - ax) * ex + (z - az) * ez) / len2;
        if (t < 0.0) t = 0.0;
        if (t > 1.0) t = 1.0;
        const double px = ax + t * ex, pz = az + t * ez;
        const double d = hypot(x - px, z - pz);
        if (d < r.distance - 1e-14) {
            r.distance = d;
            double nx = -ez / sqrt(len2), nz = ex / sqrt(len2); /* left normal */
            int is_end = 0;
            if (t <= 0.0 && k > 0) {
                const double fx = ax - line->x[k - 1], fz = az - line->z[k - 1];
                const double fl = hypot(fx, fz);
                nx += -fz / fl;
                nz += fx / fl;
            } else if (t >= 1.0 && k + 2 < line->n) {
                const double fx = line->x[k + 2] - line->x[k + 1], fz = line->z[k + 2] - line->z[k + 1];
                const double fl = hypot(fx, fz);
                nx += -fz / fl;
                nz += fx / fl;
            } else if ((t <= 0.0 && k == 0) || (t >= 1.0 && k + 2 == line->n)) {
                is_end = 1;
            }
            const double dot = (x - px) * nx + (z - pz) * nz;
            r.nx = nx;
            r.nz = nz;
            r.left = dot >= 0.0 ? 1.0 : -1.0;
            r.at_end = is_end;
        }
    }
    return r;
}

double geom_signed_distance(const struct polyline *line, int side, double x, double z, int *at_end)
{
    const struct nearest r = nearest_on_polyline(line, x, z);
    if (at_end) *at_end = r.at_end;
    return r.left * (double)side * r.distance;
}

void geom_side_normal(const struct polyline *line, int side, double x, double z, double *nx, double *nz)
{
    const struct nearest r = nearest_on_polyline(line, x, z);
    const double len = hypot(r.nx, r.nz);
    *nx = len > 0.0 ? (double)side * r.nx / len : 0.0;
    *nz = len > 0.0 ? (double)side * r.nz / len : 0.0;
}

int geom_path_crosses(double ax, double az, double bx, double bz, double cx, double cz, double dx,
                      double dz, double *s)
{
    const double rx = bx - ax, rz = bz - az; /* path */
    const double qx = dx - cx, qz = dz - cz; /* segment */
    const double den = rx * qz - rz * qx;
    if (den == 0.0) return 0; /* parallel: moving along the wall never crosses it */
    const double wx = cx - ax, wz = cz - az;
    const double t = (wx * qz - wz * qx) / den; /* along the path */
    const double u = (wx * rz - wz * rx) / den; /* along the segment */
    if (t < 0.0 || t > 1.0 || u < 0.0 || u > 1.0) return 0;
    *s = t;
    return 1;
}

/* Clip the polygon (xs, zs, n points) to the half-plane sign * (z - level) >= 0 (Sutherland-Hodgman)
 * into (xo, zo); returns the number of points, at most 2 n. */
static size_t clip_half_plane(const double *xs, const double *zs, size_t n, double level, double sign, double *xo,
                              double *zo)
{
    size_t m = 0;
    for (size_t i = 0, j = n - 1; i < n; j = i++) {
        const double dj = sign * (zs[j] - level), di = sign * (zs[i] - level);
        if ((dj >= 0.0) != (di >= 0.0)) { /* the edge j -> i crosses the level */
            const double f = dj / (dj - di);
            xo[m] = xs[j] + f * (xs[i] - xs[j]);
            zo[m++] = level;
        }
        if (di >= 0.0) {
            xo[m] = xs[i];
            zo[m++] = zs[i];
        }
    }
    return m;
}

double geom_polygon_area_in_band(const struct polyline *poly, double z_min, double z_max)
{
    const size_t n = poly->n, cap = 4 * n + 4;
    if (n < 3 || !(z_max > z_min)) return 0.0;
    double *buf = malloc(4 * cap * sizeof *buf);
    if (!buf) return NAN;
    double *x1 = buf, *z1 = buf + cap, *x2 = buf + 2 * cap, *z2 = buf + 3 * cap;
    size_t m = n;
    const double *xs = poly->x, *zs = poly->z;
    if (isfinite(z_min)) {
        m = clip_half_plane(xs, zs, m, z_min, 1.0, x1, z1);
        xs = x1;
        zs = z1;
    }
    if (isfinite(z_max) && m > 0) {
        m = clip_half_plane(xs, zs, m, z_max, -1.0, x2, z2);
        xs = x2;
        zs = z2;
    }
    double twice = 0.0;
    for (size_t i = 0, j = m ? m - 1 : 0; i < m; j = i++) twice += xs[j] * zs[i] - xs[i] * zs[j];
    free(buf);
    return 0.5 * fabs(twice);
}

void geom_grow_box(const struct polyline *p, double *x0, double *x1, double *z0, double *z1)
{
    for (size_t k = 0; k < p->n; k++) {
        *x0 = fmin(*x0, p->x[k]);
        *x1 = fmax(*x1, p->x[k]);
        *z0 = fmin(*z0, p->z[k]);
        *z1 = fmax(*z1, p->z[k]);
    }
}

double geom_polyline_length(const struct polyline *line)
{
    double len = 0.0;
    for (size_t k = 0; k + 1 < line->n; k++) len += hypot(line->x[k + 1] - line->x[k], line->z[k + 1] - line->z[k]);
    return len;
}

double geom_lattice_z_offset(double z0, double dx)
{
    const double off = z0 - dx * round(z0 / dx);
    return fabs(off) < 1e-9 * dx ? 0.0 : off;
}

void geom_free(struct polyline *p)
{
    free(p->x);
    free(p->z);
    p->x = p->z = NULL;
    p->n = 0;
}
