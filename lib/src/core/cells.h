/* cells.h - cell-linked list by counting sort. Rows of height `size` (the search radius) are
 * cut into columns of width size / kx, numbered row by row; the particles are reordered by cell
 * (stable), so the neighbours of a particle in cell (ix, iz) are three contiguous ranges:
 * columns ix-kx..ix+kx of rows iz-1, iz, iz+1. The simulation sorts when it rebuilds its
 * neighbour ranges (neighbours.h). Particles outside the domain are marked lost and sorted to
 * the end. */
#ifndef MIXSPH_CELLS_H
#define MIXSPH_CELLS_H
#include <stddef.h>
#include <stdint.h>

#include "particles.h"

struct cells {
    double x0, z0;      /* lower-left corner of the grid [m] */
    double size;        /* row height, the neighbour search radius [m] */
    double width;       /* column width: size / kx [m] */
    int kx;             /* columns per search radius: a particle's neighbours lie within kx columns */
    int nx, nz;         /* cells per row, rows */
    size_t ncell;
    size_t *start;      /* ncell + 2: particles of cell c are start[c] .. start[c+1]-1; lost at the end */
    uint32_t *cell;     /* per particle: its cell (ncell for lost particles) */
    size_t *perm;       /* scratch: the sort permutation */
    void *scratch;      /* scratch for permuting fields */
    size_t cap;         /* particle capacity of the per-particle arrays */
};

struct range {
    size_t begin, end;
};

/** Set up a grid covering [x_min, x_max] x [z_min, z_max] with square cells of the given size. */
int cells_init(struct cells *C, double x_min, double x_max, double z_min, double z_max, double size);
/** As cells_init with cells of height `size` and width size / kx: a row of cells is sorted by
 *  column, so the neighbours of a particle in a row are one contiguous range of 2 kx + 1
 *  columns, only (2 kx + 1) / kx search radii wide (kx = 1: 3 radii). */
int cells_init_columns(struct cells *C, double x_min, double x_max, double z_min, double z_max, double size, int kx);
void cells_free(struct cells *C);

/** Mark particles outside the grid as lost (returns how many were newly lost), compute cells,
 *  sort the particles by cell (stable) and fill the ranges. Returns -1 on allocation failure. */
long cells_build(struct cells *C, struct particles *P);

/** Cells and ranges of particles already sorted by cell at the given positions (a restored
 *  state): nothing is moved. Particles outside the grid must be at the end, marked lost.
 *  Returns -1 if the order is not sorted or on allocation failure. */
int cells_index(struct cells *C, const struct particles *P, const double *x, const double *z);

/** Cell of a position inside the grid. */
static inline void cells_coords(const struct cells *C, double x, double z, int *ix, int *iz)
{
    *ix = (int)((x - C->x0) / C->width);
    *iz = (int)((z - C->z0) / C->size);
}

/** Particles in cells ix-kx..ix+kx of row iz+drow (an empty range outside the grid). */
static inline struct range cells_row(const struct cells *C, int ix, int iz, int drow)
{
    struct range r = {0, 0};
    const int row = iz + drow;
    if (row < 0 || row >= C->nz) return r;
    const int a = ix > C->kx ? ix - C->kx : 0;
    const int b = ix + C->kx < C->nx ? ix + C->kx : C->nx - 1;
    const size_t base = (size_t)row * (size_t)C->nx;
    r.begin = C->start[base + (size_t)a];
    r.end = C->start[base + (size_t)b + 1];
    return r;
}

#endif
