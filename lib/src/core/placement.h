/* placement.h - particle positions from 3D geometry: lattice sites inside a box, a closed mesh or
 * above a terrain, and points laid on a triangulated surface in layers. The signatures take 3D
 * points (x, y, z; z up) whatever the build's DIM: a 3D case places its particles with them.
 *
 * Lattice: the sites origin + ((i + 1/2) dx, (j + 1/2) dx, (k + 1/2) dx), the cubic lattice a
 * body's particles start on. Every fill keeps a site by the half-open rule lo <= s < hi on each
 * axis, so adjacent regions share no site and a site on a face is placed once.
 *
 * Inside a closed mesh: a column sweep. Each triangle that is not vertical is projected onto the
 * x-y plane and the lattice's vertical columns through it are found (the columns in its box,
 * then an exact-orientation test, ties broken by simulation of simplicity: the column is
 * perturbed by (eps, eps^2), and each edge's orientation is computed from its endpoints in one
 * canonical order, so that two triangles sharing an edge always agree which of them a column
 * hits). Each hit is a crossing at the plane's height, +1 entering (a face looking down), -1
 * leaving. A column's sites are inside where the sum of the crossings at or below them is not 0.
 * The sum over a whole column of a closed mesh is 0; a column where rounding near a vertex
 * broke that is classified site by site with mesh_contains (the winding number) instead. Cost:
 * O(triangles + columns hit + sites), against O(sites x triangles) for the winding number.
 *
 * On a surface: each triangle carries a square lattice of spacing dx in its own plane, the
 * lattice of the plane: its axes depend only on the plane's normal (u along the world axis
 * least aligned with the normal, projected; v = n x u) and its origin is the projection of a
 * common anchor point. Coplanar triangles (the halves of a box's face, the cells of a planar
 * terrain, the quads of an extruded segment) therefore carry one continuous lattice, and the
 * points on their shared edges coincide. Points within merge x dx of a point already placed by
 * the same call are dropped (a hash grid of cells of that size): with merge about 1e-6 this
 * removes only the copies on shared edges and corners; with merge 0.5 it also thins the seams
 * where the lattices of two planes meet (a box's edges, a curved terrain's creases). Layers are
 * placed surface first, so a point where two faces' layers meet keeps the surface's normal. */
#ifndef MIXSPH_PLACEMENT_H
#define MIXSPH_PLACEMENT_H
#include <stddef.h>

#include "mesh.h"
#include "mixsph.h"
#include "terrain.h"

struct point_set {
    size_t n, cap;
    double (*pos)[3];    /* [m] */
    double (*normal)[3]; /* unit outward normal of the surface the point was laid on; 0 for a lattice site */
    int *layer;          /* 0 on the surface, k in the k-th layer below it; -1 for a lattice site */
};

struct lattice {
    double dx;         /* the sites' spacing [m] */
    double origin[3];  /* site (i, j, k) at origin + (i + 1/2, j + 1/2, k + 1/2) dx [m] */
    size_t max_points; /* refuse a fill that would pass this many points in the set (0: no limit) */
};

struct surface_sampling {
    double dx;          /* the points' spacing in each plane, and between layers [m] */
    int layers;         /* layers, at least 1: the first, then layers - 1 each dx further in */
    double first_depth; /* the first layer's depth below the surface, along -normal [m] (0: on it) */
    double anchor[3];   /* a point every plane's lattice passes through, projected [m] */
    double merge;       /* drop a point within merge x dx of one already placed, in (0, 1) */
    size_t max_points;  /* as struct lattice's */
};

void point_set_free(struct point_set *ps);

/** Append a point (normal NULL: a lattice site). */
mixsph_status point_set_push(struct point_set *ps, const double pos[3], const double normal[3], int layer,
                             size_t max_points, char *err, size_t err_len);

/** Append the lattice sites in the box lo <= s < hi. */
mixsph_status lattice_fill_box(const struct lattice *L, const double lo[3], const double hi[3], struct point_set *out,
                               char *err, size_t err_len);

/** Append the lattice sites inside a closed mesh (the column sweep above; either orientation),
 *  column by column (z fastest, then x, then y; lattice_fill_box's order is x, y, z). */
mixsph_status lattice_fill_mesh(const struct lattice *L, const struct mesh *body, struct point_set *out, char *err,
                                size_t err_len);

/** Append the lattice sites of the box lo <= s < hi above the terrain (its bilinear height h(x, y)
 *  < z) and below z_max (z < z_max): the water of a reservoir over a DEM. No site where h is
 *  NaN (outside the grid, NODATA). */
mixsph_status lattice_fill_terrain(const struct lattice *L, const struct terrain *t, const double lo[3],
                                   const double hi[3], double z_max, struct point_set *out, char *err, size_t err_len);

/** Append the lattice sites of the box lo <= s < hi above a triangulated surface (the highest
 *  crossing of the site's vertical, at or below which the site is not) and below z_max: the same
 *  for a terrain given as an STL. No site on a vertical that misses the surface. */
mixsph_status lattice_fill_above_mesh(const struct lattice *L, const struct mesh *surface, const double lo[3],
                                      const double hi[3], double z_max, struct point_set *out, char *err,
                                      size_t err_len);

/** Keep the points of ps from index `first` on that are inside (keep_inside = 1) or outside (0)
 *  the closed mesh m, in their order (mesh_contains: O(triangles) per point). */
void point_set_keep(struct point_set *ps, size_t first, const struct mesh *m, int keep_inside);

/** Append points laid on every triangle of m (see above), with their triangle's normal and layer. */
mixsph_status surface_sample(const struct surface_sampling *S, const struct mesh *m, struct point_set *out, char *err,
                             size_t err_len);

#endif
