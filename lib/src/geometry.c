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

double geom_signed_distance(const struct polyline *line, int side, double x, double z, int *at_end)
{
    double best = INFINITY, sign = 1.0;
    int end = 0;
    for (size_t k = 0; k + 1 < line->n; k++) {
        const double ax = line->x[k], az = line->z[k];
        const double ex = line->x[k + 1] - ax, ez = line->z[k + 1] - az;
        const double len2 = ex * ex + ez * ez;
        double t = ((x - ax) * ex + (z - az) * ez) / len2;
        if (t < 0.0) t = 0.0;
        if (t > 1.0) t = 1.0;
        const double px = ax + t * ex, pz = az + t * ez;
        const double d = hypot(x - px, z - pz);
        if (d < best - 1e-14) {
            best = d;
            /* side of the segment's line; at a shared vertex use the mean of both normals */
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
            sign = (dot >= 0.0 ? 1.0 : -1.0) * (double)side;
            end = is_end;
        }
    }
    if (at_end) *at_end = end;
    return sign * best;
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

void geom_free(struct polyline *p)
{
    free(p->x);
    free(p->z);
    p->x = p->z = NULL;
    p->n = 0;
}
