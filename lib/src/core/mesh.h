/* mesh.h - triangle meshes in three dimensions (x, y, z; z up), in double precision: the input
 * geometry of 3D cases (walls, bodies, terrain), whatever the build's DIM.
 *
 * A triangle's vertices are ordered counter-clockwise seen from the side its normal points to
 * (the right-hand rule: n = (v1 - v0) x (v2 - v0) / |...|), the outside of a closed body. The
 * builders share vertices between triangles, so that a closed mesh is closed by its indices too
 * (mesh_check_closed).
 *
 * Inside test: the generalised winding number (the solid angle the mesh subtends at the point
 * over 4 pi, Van Oosterom & Strackee's formula per triangle). Chosen over a ray cast because it
 * has no degenerate case (a ray through an edge or a vertex, or grazing a face, needs a tie rule
 * that rounding can break and a wrong parity flips a whole ray) and degrades gracefully on a
 * mesh with a small gap (the number drops near the gap instead of flipping). Cost: one atan2 and
 * about 40 flops per triangle per point, O(triangles). Filling a body's lattice uses the cheaper
 * column sweep of placement.h, which falls back to this test where a column is inconsistent.
 *
 * Distance: brute force over the triangles, O(triangles) per point (Ericson's closest point on a
 * triangle, about 60 flops each): meant for checks and for placing a few thousand points; a
 * spatial index comes when a case needs many queries on a large mesh. */
#ifndef MIXSPH_MESH_H
#define MIXSPH_MESH_H
#include <stddef.h>

#include "geometry.h"
#include "mixsph.h"

struct mesh {
    size_t n_vertices, n_triangles;
    size_t vertex_cap, triangle_cap; /* allocated rows */
    double (*vertex)[3];             /* [m] */
    size_t (*triangle)[3];           /* vertex indices, counter-clockwise seen from outside */
    double (*normal)[3];             /* unit outward normal of each triangle */
};

/* The faces of an axis-aligned box, for mesh_add_box. */
enum {
    MESH_BOX_XMIN = 1, MESH_BOX_XMAX = 2, MESH_BOX_YMIN = 4, MESH_BOX_YMAX = 8, MESH_BOX_ZMIN = 16,
    MESH_BOX_ZMAX = 32,
    MESH_BOX_ALL = 63,
    MESH_BOX_OPEN_TOP = MESH_BOX_ALL & ~MESH_BOX_ZMAX /* a tank */
};

/** Free a mesh's arrays and leave it empty (a zero-initialised mesh is an empty one). */
void mesh_free(struct mesh *m);

/** Append a vertex; *index receives its index. */
mixsph_status mesh_add_vertex(struct mesh *m, const double p[3], size_t *index, char *err, size_t err_len);

/** Append the triangle (a, b, c) of existing vertices and its normal. A triangle of zero area
 *  (no normal) is refused with MIXSPH_ERR_ARG naming its vertices. */
mixsph_status mesh_add_triangle(struct mesh *m, size_t a, size_t b, size_t c, char *err, size_t err_len);

/** Append the faces `faces` (MESH_BOX_* bits) of the box [lo, hi], two triangles each, 8
 *  vertices shared. Normals point out of the box, or into it with `inward` (a tank's walls,
 *  whose fluid is inside). MESH_BOX_ALL, outward: the closed box of 12 triangles. */
mixsph_status mesh_add_box(struct mesh *m, const double lo[3], const double hi[3], unsigned faces, int inward,
                           char *err, size_t err_len);

/** Append the extrusion of the open polyline `line` of the x-z plane across y in [y0, y1]: one
 *  quad (two triangles) per segment, normal (nx, 0, nz) = geom_side_normal(line, side, ...) of
 *  the segment (side +1: left of the direction of travel). */
mixsph_status mesh_add_extruded_polyline(struct mesh *m, const struct polyline *line, int side, double y0, double y1,
                                         char *err, size_t err_len);

/** Append the closed prism of the simple polygon `poly` (x-z plane, closed implicitly, either
 *  orientation) extruded across y in [y0, y1]: the side quads and the two caps (ear clipping),
 *  normals outward. A self-intersecting polygon is refused, naming two segments that cross.
 *  Collinear vertices are dropped from the caps, leaving a T-junction on the cap's edge (closed in space, not by
 *  indices). */
mixsph_status mesh_add_extruded_polygon(struct mesh *m, const struct polyline *poly, double y0, double y1, char *err,
                                        size_t err_len);

/** Reverse every triangle's orientation and normal (outward <-> inward). */
void mesh_flip(struct mesh *m);

/** The box of the vertices; lo = +inf, hi = -inf for an empty mesh. */
void mesh_bounds(const struct mesh *m, double lo[3], double hi[3]);

/** The volume enclosed by a closed mesh, by the divergence theorem (sum of the signed
 *  tetrahedra of the triangles and the origin) [m3]; negative for an inward-oriented mesh. */
double mesh_volume(const struct mesh *m);

/** The area of the mesh's triangles [m2]. */
double mesh_area(const struct mesh *m);

/** Is the mesh closed and consistently oriented by its indices: every edge used by exactly two
 *  triangles, once in each direction? On failure returns MIXSPH_ERR_ARG and names an edge, the
 *  triangle using it and how often it is used in each direction. */
mixsph_status mesh_check_closed(const struct mesh *m, const char *name, char *err, size_t err_len);

/** The generalised winding number of the mesh at p: 1 inside a closed outward mesh, 0 outside
 *  (-1 inside an inward one), fractional near a gap; on the surface itself it is undefined
 *  (returned as 0.5 when p is a vertex). */
double mesh_winding_number(const struct mesh *m, const double p[3]);

/** Is p inside the closed mesh (|winding number| > 1/2)? */
int mesh_contains(const struct mesh *m, const double p[3]);

/** The unsigned distance from p to the mesh [m]; *triangle (if non-NULL) receives the nearest
 *  triangle and closest (if non-NULL) the nearest point. INFINITY for an empty mesh. */
double mesh_distance(const struct mesh *m, const double p[3], size_t *triangle, double closest[3]);

/* Which part of a triangle (a, b, c) holds the point nearest to a given one (mesh_closest_feature). */
enum mesh_feature {
    MESH_AT_FACE = 0,
    MESH_AT_VERTEX_A, MESH_AT_VERTEX_B, MESH_AT_VERTEX_C,
    MESH_AT_EDGE_AB, MESH_AT_EDGE_BC, MESH_AT_EDGE_CA
};

/** The point of triangle (a, b, c) nearest to p, and the part of the triangle it lies on (enum
 *  mesh_feature): its interior, a vertex or an edge (the Voronoi region of Ericson's test). */
int mesh_closest_feature(const double p[3], const double a[3], const double b[3], const double c[3],
                         double closest[3]);

/** The point of triangle (a, b, c) nearest to p (Ericson, Real-Time Collision Detection 5.1.5). */
void mesh_closest_on_triangle(const double p[3], const double a[3], const double b[3], const double c[3],
                              double closest[3]);

#endif
