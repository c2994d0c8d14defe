/* wall_surface.h - the triangulated surface of a 3D wall from its form in the case (wall_def.h):
 * a polyline extruded across y, a box, an STL file or a terrain grid, with its normals turned to
 * the fluid; and the side walls of an extruded polyline (a flume) as a wall of their own. */
#ifndef MIXSPH_WALL_SURFACE_H
#define MIXSPH_WALL_SURFACE_H
#include <stddef.h>

#include "mixsph.h"
#include "wall_def.h"

/** Build wl->surface from wl's form; a file name is taken relative to case_dir (NULL or "": the
 *  working directory) unless it is absolute. Errors name the file or the geometry and why; the
 *  caller adds the key. */
mixsph_status wall_surface_build(struct wall *wl, const char *case_dir, char *err, size_t err_len);

/** The side walls of the extruded polyline `flume` (its side_walls not WALL_SIDES_NONE): a wall
 *  named "<flume>_sides" made of the two planes y = y_min and y = y_max over the polyline's x
 *  range, from its lowest point to side_walls_z_max, fluid between them, with the slip condition
 *  side_walls and the flume's friction; fixed. Its surface is built. */
mixsph_status wall_side_walls(const struct wall *flume, struct wall *sides, char *err, size_t err_len);

#endif
