/* body_sites.h - the lattice sites of a 3D case's bodies (case.h, enum body_shape): a box, a
 * polygon of the x-z plane extruded across y, the inside of a closed STL surface, or the domain
 * below a level. The sites are those of the cubic lattice of placement.h; sim.c merges the
 * bodies' sites (a site belongs to the first body listing it), drops those the walls block and
 * gives them the hydrostatic state, as for a 2D case's polygons. */
#ifndef MIXSPH_BODY_SITES_H
#define MIXSPH_BODY_SITES_H
#include <stddef.h>

#include "case.h"
#include "placement.h"

/** Append to `out` the sites of the lattice L inside body b of the 3D case c, clipped to the
 *  body's z_min <= z <= z_max (every shape: a box keeps lattice_fill_box's half-open rule on its
 *  faces, a polygon geom_inside_polygon's rule). MIXSPH_ERR_CASE for an STL file that cannot be
 *  read or is not closed, naming the body; MIXSPH_ERR_NOMEM past L->max_points. */
mixsph_status body_sites(const struct case_def *c, size_t b, const struct lattice *L, struct point_set *out, char *err,
                         size_t err_len);

#endif
