/* cells.c - see cells.h. */
#include "cells.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mixsph.h"

int cells_init(struct cells *C, double x_min, double x_max, double z_min, double z_max, double size)
{
    return cells_init_columns(C, x_min, x_max, z_min, z_max, size, 1);
}

int cells_init_columns(struct cells *C, double x_min, double x_max, double z_min, double z_max, double size, int kx)
{
    memset(C, 0, sizeof *C);
    if (kx < 1) return -1;
    C->x0 = x_min;
    C->z0 = z_min;
    C->size = size;
    C->kx = kx;
    C->width = size / kx;
    const double nx = ceil((x_max - x_min) / C->width), nz = ceil((z_max - z_min) / size);
    if (!(nx >= 1 && nz >= 1) || nx * nz > 2e8) return -1;
    C->nx = (int)nx;
    C->nz = (int)nz;
    C->ncell = (size_t)C->nx * (size_t)C->nz;
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

long cells_build(struct cells *C, struct particles *P)
{
    const size_t n = P->n, nc = C->ncell;
    if (ensure(C, n) != 0) return -1;
    long lost = 0;
    const double invx = 1.0 / C->width, invz = 1.0 / C->size;
    for (size_t i = 0; i < n; i++) {
        uint32_t c = (uint32_t)nc;
        if (P->state[i] != MIXSPH_STATE_LOST) {
            const double fx = (P->x[i] - C->x0) * invx, fz = (P->z[i] - C->z0) * invz;
            if (fx >= 0.0 && fz >= 0.0 && fx < C->nx && fz < C->nz) {
                c = (uint32_t)((size_t)fz * (size_t)C->nx + (size_t)fx);
            } else {
                P->state[i] = MIXSPH_STATE_LOST; /* left the domain (or not finite) */
                P->vx[i] = P->vz[i] = 0.0;
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

int cells_index(struct cells *C, const struct particles *P, const double *x, const double *z)
{
    const size_t n = P->n, nc = C->ncell;
    if (ensure(C, n) != 0) return -1;
    const double invx = 1.0 / C->width, invz = 1.0 / C->size;
    memset(C->start, 0, (nc + 2) * sizeof *C->start);
    uint32_t prev = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t c = (uint32_t)nc;
        if (P->state[i] != MIXSPH_STATE_LOST) {
            const double fx = (x[i] - C->x0) * invx, fz = (z[i] - C->z0) * invz;
            if (!(fx >= 0.0 && fz >= 0.0 && fx < C->nx && fz < C->nz)) return -1;
            c = (uint32_t)((size_t)fz * (size_t)C->nx + (size_t)fx);
        }
        if (c < prev) return -1;
        prev = c;
        C->cell[i] = c;
        C->start[c + 1]++;
    }
    for (size_t c = 0; c <= nc; c++) C->start[c + 1] += C->start[c];
    return 0;
}
