/* cells.c - see cells.h. */
#include "cells.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mixsph.h"

int cells_init(struct cells *C, const double lo[DIM], const double hi[DIM], double size)
{
    return cells_init_columns(C, lo, hi, size, 1);
}

int cells_init_columns(struct cells *C, const double lo[DIM], const double hi[DIM], double size, int kx)
{
    memset(C, 0, sizeof *C);
    if (kx < 1) return -1;
    C->size = size;
    C->kx = kx;
    C->width = size / kx;
    double cells = 1.0;
    for (int d = 0; d < DIM; d++) {
        C->lo[d] = lo[d];
        const double n = ceil((hi[d] - lo[d]) / (d == 0 ? C->width : size));
        if (!(n >= 1)) return -1;
        cells *= n;
        if (cells > 2e8) return -1;
        C->n[d] = (int)n;
    }
    C->layer = 1;
    for (int d = 0; d < DIM - 1; d++) C->layer *= (size_t)C->n[d];
    C->ncell = C->layer * (size_t)C->n[DIM_UP];
    C->start = calloc(C->ncell + 2, sizeof *C->start);
    return C->start ? 0 : -1;
}

void cells_free(struct cells *C)
{
    free(C->start);
    free(C->cell);
    free(C->perm);
    free(C->scratch);
    memset(C, 0, sizeof *C);
}

static int ensure(struct cells *C, size_t n)
{
    if (n <= C->cap) return 0;
    size_t cap = n + n / 4 + 64;
    uint32_t *cell = realloc(C->cell, cap * sizeof *cell);
    if (!cell) return -1;
    C->cell = cell;
    size_t *perm = realloc(C->perm, cap * sizeof *perm);
    if (!perm) return -1;
    C->perm = perm;
    void *s = realloc(C->scratch, cap * sizeof(double));
    if (!s) return -1;
    C->scratch = s;
    C->cap = cap;
    return 0;
}

/* The cell number of position i (pos[d][i]), or ncell when it lies outside the grid (or is not
 * finite). */
static inline uint32_t cell_of(const struct cells *C, double *const pos[DIM], size_t i)
{
    size_t c = 0;
    for (int d = DIM - 1; d >= 0; d--) {
        const double f = (pos[d][i] - C->lo[d]) * (d == 0 ? 1.0 / C->width : 1.0 / C->size);
        if (!(f >= 0.0 && f < C->n[d])) return (uint32_t)C->ncell;
        c = c * (size_t)C->n[d] + (size_t)f;
    }
    return (uint32_t)c;
}

long cells_build(struct cells *C, struct particles *P)
{
    const size_t n = P->n, nc = C->ncell;
    if (ensure(C, n) != 0) return -1;
    long lost = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t c = (uint32_t)nc;
        if (P->state[i] != MIXSPH_STATE_LOST) {
            c = cell_of(C, P->pos, i);
            if (c == nc) {
                P->state[i] = MIXSPH_STATE_LOST; /* left the domain (or not finite) */
                for (int d = 0; d < DIM; d++) P->vel[d][i] = 0.0;
                lost++;
            }
        }
        C->cell[i] = c;
    }
    /* counting sort: histogram, exclusive prefix sum, stable scatter */
    memset(C->start, 0, (nc + 2) * sizeof *C->start);
    for (size_t i = 0; i < n; i++) C->start[C->cell[i] + 1]++;
    for (size_t c = 0; c <= nc; c++) C->start[c + 1] += C->start[c];
    size_t *next = C->start; /* reuse as insertion cursors, then shift back */
    for (size_t i = 0; i < n; i++) C->perm[next[C->cell[i]]++] = i;
    for (size_t c = nc + 1; c > 0; c--) C->start[c] = C->start[c - 1];
    C->start[0] = 0;
    particles_permute(P, C->perm, C->scratch);
    for (size_t c = 0; c <= nc; c++)
        for (size_t k = C->start[c]; k < C->start[c + 1]; k++) C->cell[k] = (uint32_t)c;
    return lost;
}

int cells_index(struct cells *C, const struct particles *P, double *const pos[DIM])
{
    const size_t n = P->n, nc = C->ncell;
    if (ensure(C, n) != 0) return -1;
    memset(C->start, 0, (nc + 2) * sizeof *C->start);
    uint32_t prev = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t c = (uint32_t)nc;
        if (P->state[i] != MIXSPH_STATE_LOST) {
            c = cell_of(C, pos, i);
            if (c == nc) return -1;
        }
        if (c < prev) return -1;
        prev = c;
        C->cell[i] = c;
        C->start[c + 1]++;
    }
    for (size_t c = 0; c <= nc; c++) C->start[c + 1] += C->start[c];
    return 0;
}
