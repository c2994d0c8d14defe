/* cells.h - cell-linked list by counting sort. The grid's rows run along x: a row is cut into
 * columns of width size / kx, and rows are `size` (the search radius) apart along every other axis
 * (z in 2D; y and z in 3D). Cells are numbered along x first and along the vertical last, and the
 * particles are reordered by cell (stable), so the neighbours of a particle in cell c lie in
 * contiguous ranges, one per neighbouring row: columns c[0]-kx..c[0]+kx of the rows whose other
 * coordinates differ from c's by at most one (3 rows in 2D, 9 in 3D). A layer (all the rows of one
 * vertical index) is a contiguous block of cells: the threads' bands are made of layers
 * (forces.c). The simulation sorts when it rebuilds its neighbour ranges (neighbours.h).
 * Particles outside the domain are marked lost and sorted to the end. */
#ifndef MIXSPH_CELLS_H
#define MIXSPH_CELLS_H
#include <stddef.h>
#include <stdint.h>

#include "dim.h"
#include "particles.h"

/* Rows around a row: each coordinate but x differs by -1, 0 or 1 (3^(DIM-1) of them). */
#define CELLS_ROWS_AROUND (DIM == 2 ? 3 : 9)

struct cells {
    double lo[DIM];     /* lower corner of the grid [m] */
    double size;        /* row spacing, the neighbour search radius [m] */
    double width;       /* column width: size / kx [m] */
    int kx;             /* columns per search radius: a particle's neighbours lie within kx columns */
    int n[DIM];         /* cells along each axis: n[0] columns per row, n[DIM_UP] layers */
    size_t layer;       /* cells per layer (n[0] ... n[DIM - 2]) */
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

/** Set up a grid covering the box [lo, hi] with cubic (square) cells of the given size. */
int cells_init(struct cells *C, const double lo[DIM], const double hi[DIM], double size);
/** As cells_init with rows `size` apart and columns size / kx wide: a row of cells is sorted by
 *  column, so the neighbours of a particle in a row are one contiguous range of 2 kx + 1
 *  columns, only (2 kx + 1) / kx search radii wide (kx = 1: 3 radii). */
int cells_init_columns(struct cells *C, const double lo[DIM], const double hi[DIM], double size, int kx);
void cells_free(struct cells *C);

/** The upper corner of the grid along axis d [m]. */
static inline double cells_hi(const struct cells *C, int d)
{
    return C->lo[d] + C->n[d] * (d == 0 ? C->width : C->size);
}

/** Mark particles outside the grid as lost (returns how many were newly lost), compute cells,
 *  sort the particles by cell (stable) and fill the ranges. Returns -1 on allocation failure. */
long cells_build(struct cells *C, struct particles *P);

/** Cells and ranges of particles already sorted by cell at the given positions pos[d][i] (a
 *  restored state): nothing is moved. Particles outside the grid must be at the end, marked lost.
 *  Returns -1 if the order is not sorted or on allocation failure. */
int cells_index(struct cells *C, const struct particles *P, double *const pos[DIM]);

/** Cell coordinates of a position inside the grid. */
static inline void cells_coords(const struct cells *C, const double pos[DIM], int c[DIM])
{
    c[0] = (int)((pos[0] - C->lo[0]) / C->width);
    for (int d = 1; d < DIM; d++) c[d] = (int)((pos[d] - C->lo[d]) / C->size);
}

/** Cell coordinates of cell number k. */
static inline void cells_unindex(const struct cells *C, size_t k, int c[DIM])
{
    for (int d = 0; d < DIM; d++) {
        c[d] = (int)(k % (size_t)C->n[d]);
        k /= (size_t)C->n[d];
    }
}

/** Particles in columns c[0]-kx..c[0]+kx of the row that row number `around` (0 ..
 *  CELLS_ROWS_AROUND - 1) of cell c names: the row whose coordinate d > 0 is c[d] + (digit d-1 of
 *  `around` in base 3) - 1 (around = CELLS_ROWS_AROUND / 2: c's own row). An empty range outside
 *  the grid. */
static inline struct range cells_row(const struct cells *C, const int c[DIM], int around)
{
    struct range r = {0, 0};
    size_t base = 0;
    for (int d = DIM - 1; d > 0; d--) {
        int step = around;
        for (int e = 1; e < d; e++) step /= 3;
        const int row = c[d] + step % 3 - 1;
        if (row < 0 || row >= C->n[d]) return r;
        base = base * (size_t)C->n[d] + (size_t)row;
    }
    base *= (size_t)C->n[0];
    const int a = c[0] > C->kx ? c[0] - C->kx : 0;
    const int b = c[0] + C->kx < C->n[0] ? c[0] + C->kx : C->n[0] - 1;
    r.begin = C->start[base + (size_t)a];
    r.end = C->start[base + (size_t)b + 1];
    return r;
}

#endif
