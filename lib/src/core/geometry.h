/* geometry.h - polygons and polylines in the x-z plane: point in polygon, signed distance to
 * a wall polyline, and the segment crossing test used to keep particles out of walls. */
#ifndef MIXSPH_GEOMETRY_H
#define MIXSPH_GEOMETRY_H
#include <stddef.h>

#define GEOM_PI 3.14159265358979323846 /* the one definition of pi in the library */

struct polyline {
    size_t n;     /* vertices */
    double *x;    /* [m] */
    double *z;    /* [m] */
};

/** Even-odd point-in-polygon test (the polygon is closed implicitly). */
int geom_inside_polygon(const struct polyline *poly, double x, double z);

/** Distance from (x,z) to an open polyline, signed: positive on the side `side` (+1: left of
 *  the direction of travel, -1: right). *at_end is set when the nearest point is one of the two
 *  open ends (the point lies beyond the polyline, not beside it). */
double geom_signed_distance(const struct polyline *line, int side, double x, double z, int *at_end);

/** The unit normal of an open polyline toward its side `side` at the point nearest to (x, z) (at a
 *  shared vertex, the mean direction of both segments' normals). */
void geom_side_normal(const struct polyline *line, int side, double x, double z, double *nx, double *nz);

/** Does the path a->b cross segment c->d? On a crossing returns 1 and the fraction s in [0,1]
 *  of the path at which it happens. */
int geom_path_crosses(double ax, double az, double bx, double bz, double cx, double cz, double dx,
                      double dz, double *s);

/** Area of the part of a polygon (closed implicitly, simple or not: the shoelace formula) that
 *  lies in the band z_min <= z <= z_max (either may be infinite) [m2]. */
double geom_polygon_area_in_band(const struct polyline *poly, double z_min, double z_max);

/** Grow the box [*x0, *x1] x [*z0, *z1] to hold every vertex of p (start it at +inf, -inf). */
void geom_grow_box(const struct polyline *p, double *x0, double *x1, double *z0, double *z1);

/** Length of an open polyline [m]. */
double geom_polyline_length(const struct polyline *line);

/** The vertical offset of the particle lattice, z = offset + (k + 1/2) dx, that puts a layer
 *  boundary at height z0: z0 minus the nearest multiple of dx, in [-dx/2, dx/2]. Exactly 0 when
 *  z0 is a multiple of dx to within 1e-9 dx, so an aligned z0 leaves the lattice bit for bit as
 *  the plain (k + 1/2) dx one. */
double geom_lattice_z_offset(double z0, double dx);

void geom_free(struct polyline *p);

#endif
