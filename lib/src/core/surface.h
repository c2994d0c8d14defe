/* surface.h - an oriented triangulated surface ready for a wall's queries, in double-precision 3D
 * (x, y, z; z up) whatever the build's DIM: the signed distance of a point (positive on the side
 * the triangles' normals point to, the front), the normal there, and the first crossing of a
 * segment from the front to the back.
 *
 * Sign: by the angle-weighted pseudo-normal of the nearest feature (Baerentzen & Aanaes 2005,
 * IEEE Trans. Vis. Comput. Graph. 11, 243): a face's normal inside it; on an edge the sum of its
 * faces' normals; at a vertex the sum of its faces' normals weighted by their angles there. Near
 * an edge or a vertex the nearest face's own normal can give the wrong side (a point outside the
 * corner of a box seen from its bottom face); the pseudo-normal never does on a consistently
 * oriented surface, closed or open. An edge of one triangle only is a boundary edge (an open
 * surface's rim, a tank's top): a point whose nearest feature lies on one is `at_boundary`, and
 * its side is that of the plane of the boundary edge's face.
 *
 * Index: a uniform grid of cubic buckets over the mesh's box, each listing the triangles whose
 * boxes overlap it. The nearest triangle is searched in shells of buckets around the point's,
 * until the nearest found is closer than any bucket not searched yet (a bound from the point's
 * place in its bucket), starting at the first shell with a triangle (a distance transform of the
 * empty buckets): a point near the surface (a wall particle, a fluid particle beside a wall) looks
 * at the triangles of a few buckets whatever the mesh's size. A point far from the surface needs
 * many shells (measured: tests/bench/bench_walls3d.c, docs/performance.md); a caller that only
 * asks whether the surface is within some distance uses surface_signed_distance_within. The bucket side starts at the mean of the triangles' largest extents
 * and grows until the grid has at most 8 buckets per triangle (plus 64): few empty buckets on a
 * surface of even triangles; a mesh of very uneven triangles lists many small ones per bucket. */
#ifndef MIXSPH_SURFACE_H
#define MIXSPH_SURFACE_H
#include <stddef.h>
#include <stdint.h>

#include "mesh.h"
#include "mixsph.h"

struct surface {
    struct mesh mesh;               /* the triangles (owned), normals toward the front */
    double (*vertex_normal)[3];     /* unit angle-weighted pseudo-normal of each vertex */
    double (*edge_normal)[3];       /* [3 t + e]: unit pseudo-normal of edge e (ab, bc, ca) of triangle t */
    unsigned char *edge_boundary;   /* [3 t + e]: 1 when the edge has no other triangle */
    unsigned char *vertex_boundary; /* 1 when the vertex lies on a boundary edge */
    double lo[3];                   /* the buckets' grid: corner [m] */
    double cell;                    /* side of a bucket [m] */
    size_t n[3];                    /* buckets along x, y, z */
    size_t *cell_start;             /* bucket c lists cell_triangle[cell_start[c] .. cell_start[c + 1]) */
    size_t *cell_triangle;
    uint16_t *empty_rings;          /* per bucket: the shells of buckets around it holding no triangle */
    double (*triangle_lo)[3];       /* per triangle: its box's low corner [m] */
    double (*triangle_hi)[3];       /* and high corner [m] */
    double *plane_offset;           /* per triangle: n . x of its plane [m] */
};

/* The point of a surface nearest to a query point, and what the surface is there. */
struct surface_point {
    double closest[3];  /* [m] */
    double normal[3];   /* unit pseudo-normal of the nearest feature, toward the front */
    size_t triangle;    /* a triangle holding the closest point */
    int at_boundary;    /* the closest point lies on a boundary edge */
};

/** Take over mesh m (left empty) and build the pseudo-normals and the bucket index. An empty mesh
 *  is refused (MIXSPH_ERR_ARG); out of memory: MIXSPH_ERR_NOMEM. */
mixsph_status surface_build(struct surface *s, struct mesh *m, char *err, size_t err_len);

/** Free a surface and leave it empty (a zero-initialised surface is an empty one). */
void surface_free(struct surface *s);

/** The signed distance from p to the surface [m] (< 0 behind it), and where (may be NULL). */
double surface_signed_distance(const struct surface *s, const double p[3], struct surface_point *at);

/** The same within max_distance: +INFINITY (and `at` untouched) when no point of the surface is
 *  that close. Cheap for a far point, whose exact distance can take many shells of buckets. */
double surface_signed_distance_within(const struct surface *s, const double p[3], double max_distance,
                                      struct surface_point *at);

/** May a point of the surface lie within `reach` of p? 0 only when none does; 1 when some
 *  triangle's box and plane both do (a superset of the exact answer: a triangle's box and plane
 *  are never farther than the triangle, and a bounding box is exact for a face of an axis-aligned
 *  box). For a filter whose false positives cost only time, such as the crossing guard's near-wall
 *  flag: a few bounds per triangle of the buckets within reach instead of the nearest triangle's
 *  search (docs/performance.md, "The queries of a 3D wall"). A NaN coordinate counts as near. */
int surface_may_be_within(const struct surface *s, const double p[3], double reach);

/** Does the segment a -> b cross the surface from its front to its back (within [a, b], a
 *  crossing through an edge counted)? Then *t receives the fraction of a -> b at the first such
 *  crossing and n the unit normal of the triangle crossed. */
int surface_first_crossing(const struct surface *s, const double a[3], const double b[3], double *t, double n[3]);

/** The bucket along axis d holding coordinate x, clamped to the grid. */
size_t surface_cell_of(const struct surface *s, int d, double x);

#endif
