/* terrain.h - a terrain as a regular grid of heights (an ESRI ASCII grid, the DEM format GIS
 * tools export), its height anywhere by bilinear interpolation and its triangulated surface.
 *
 * The grid's values are taken as heights at nodes: node (i, j) at (x0 + i cell, y0 + j cell),
 * i = 0 .. ncols - 1 eastwards, j = 0 .. nrows - 1 northwards. An ESRI grid's value is its
 * cell's, at the cell's centre: with `xllcorner` the nodes are the cells' centres, x0 = xllcorner
 * + cell / 2; with `xllcenter`, x0 = xllcenter (the same for y). The file's rows run north to
 * south. NODATA nodes hold NaN: a cell of the surface (between four nodes) touching one is no
 * part of it.
 *
 * The bilinear height and the triangulated surface (two planes per cell) agree on the nodes and
 * the cells' edges and differ inside a cell by at most |z00 - z10 - z01 + z11| / 4 (zero on a
 * plane): a lattice filled above the bilinear height may sit that much off the triangles. */
#ifndef MIXSPH_TERRAIN_H
#define MIXSPH_TERRAIN_H
#include <stddef.h>

#include "mesh.h"
#include "mixsph.h"

/* The most nodes read from one grid (8 bytes each: 512 MB), against a corrupt header. */
#define TERRAIN_MAX_NODES ((size_t)1 << 26)

struct terrain {
    size_t ncols, nrows; /* nodes along x (east) and y (north), at least 2 each */
    double x0, y0;       /* the south-west node [m] */
    double cell;         /* the nodes' spacing [m] */
    double *z;           /* heights [m], z[j * ncols + i], NaN where NODATA */
};

/** Read an ESRI ASCII grid: the header keys ncols, nrows, xllcorner or xllcenter, yllcorner or
 *  yllcenter, cellsize, optional NODATA_value (case-insensitive, one per line, any order), then
 *  nrows x ncols values, north row first, in any layout of whitespace. Errors name the file, the
 *  line and why (a missing, repeated or unknown key, a count below 2, a non-positive cell size,
 *  a word that is no number, a non-finite value, fewer or more values than the header's). */
mixsph_status terrain_read_esri_ascii(const char *path, struct terrain *t, char *err, size_t err_len);

/** A terrain from heights z[j * ncols + i] (copied; NaN: no data). */
mixsph_status terrain_from_heights(struct terrain *t, size_t ncols, size_t nrows, double x0, double y0, double cell,
                                   const double *z, char *err, size_t err_len);

void terrain_free(struct terrain *t);

/** The bilinear height at (x, y) [m]; NaN outside the grid or in a cell touching NODATA. */
double terrain_height(const struct terrain *t, double x, double y);

/** Append the terrain's surface to m: a vertex per node with data, two triangles per cell whose
 *  four nodes have data (split along the diagonal from its south-west to its north-east node),
 *  normals upward. */
mixsph_status terrain_to_mesh(const struct terrain *t, struct mesh *m, char *err, size_t err_len);

#endif
