/* cells.h - cell-linked list by counting sort. Cells are square with side 2h (the kernel
 * support), numbered row by row; the particles are reordered by cell every step, so the
 * neighbours of a particle in cell (ix, iz) are three contiguous ranges: cells ix-1..ix+1 of
 * rows iz-1, iz, iz+1. Particles outside the domain are marked lost and sorted to the end. */
#ifndef MIXSPH_CELLS_H
#define MIXSPH_CELLS_H
#include <stddef.h>
#include <stdint.h>

#include "particles.h"

struct cells {
    double x0, z0;      /* lower-left corner of the grid [m] */
    double size;        /* cell side [m] */
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

/** Set up a grid covering [x_min, x_max] x [z_min, z_max] with cells of the given size. */
int cells_init(struct cells *C, double x_min, double x_max, double z_min, double z_max, double size);
void cells_free(struct cells *C);

/** Mark particles outside the grid as lost (returns how many were newly lost), compute cells,
 *  sort the particles by cell (stable) and fill the ranges. Returns -1 on allocation failure. */
long cells_build(struct cells *C, struct particles *P);

/** Cell of a position inside the grid. */
static inline void cells_coords(const struct cells *C, double x, double z, int *ix, int *iz)
{
    *ix = (int)((x - C->x0) / C->size);
    *iz = (int)((z - C->z0) / C->size);
}

/** Particles in cells ix-1..ix+1 of row iz+drow (an empty range outside the grid). */
static inline struct range cells_row(const struct cells *C, int ix, int iz, int drow)
{
    struct range r = {0, 0};
    const int row = iz + drow;
    if (row < 0 || row >= C->nz) return r;
    const int a = ix > 0 ? ix - 1 : 0;
    const int b = ix + 1 < C->nx ? ix + 1 : C->nx - 1;
    const size_t base = (size_t)row * (size_t)C->nx;
    r.begin = C->start[base + (size_t)a];
    r.end = C->start[base + (size_t)b + 1];
    return r;
}

#endif
