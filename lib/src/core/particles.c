/* particles.c - see particles.h. */
#include "particles.h"

#include <stdlib.h>
#include <string.h>

#include "mixsph.h"

#define PARTICLES_PAD 8

static int grow(void **ptr, size_t cap, size_t elem)
{
    void *q = realloc(*ptr, cap * elem);
    if (!q) return -1;
    *ptr = q;
    return 0;
}

int particles_alloc(struct particles *P, size_t cap)
{
    if (cap < 16) cap = 16;
    int bad = 0;
    /* PARTICLES_PAD zeroed elements past cap: the vectorised pair loops may read (never write)
     * up to 7 elements past a range */
#define X(f)                                                                  \
    bad |= grow((void **)&P->f, cap + PARTICLES_PAD, sizeof(double));         \
    if (!bad) memset(P->f + P->cap, 0, (cap + PARTICLES_PAD - P->cap) * sizeof(double));
    PARTICLES_DOUBLE_FIELDS(X)
#undef X
    bad |= grow((void **)&P->medium, cap, 1);
    bad |= grow((void **)&P->state, cap, 1);
    bad |= grow((void **)&P->nneigh, cap, sizeof(uint16_t));
    bad |= grow((void **)&P->id, cap, sizeof(uint32_t));
    if (bad) return -1;
    P->cap = cap;
    return 0;
}

void particles_free(struct particles *P)
{
#define X(f) free(P->f);
    PARTICLES_DOUBLE_FIELDS(X)
#undef X
    free(P->medium);
    free(P->state);
    free(P->nneigh);
    free(P->id);
    memset(P, 0, sizeof *P);
}

size_t particles_push(struct particles *P, double x, double z, double rho, double m, uint8_t medium, uint8_t state)
{
    if (P->n == P->cap && particles_alloc(P, 2 * P->cap) != 0) return (size_t)-1;
    const size_t i = P->n++;
#define X(f) P->f[i] = 0.0;
    PARTICLES_DOUBLE_FIELDS(X)
#undef X
    P->x[i] = x;
    P->z[i] = z;
    P->rho[i] = rho;
    P->m[i] = m;
    P->vol[i] = m / rho;
    P->medium[i] = medium;
    P->state[i] = state;
    P->tag[i] = state == MIXSPH_STATE_WALL ? -1.0 : (double)medium;
    P->inv_rho[i] = 1.0 / rho;
    P->inv_m[i] = m > 0.0 && state != MIXSPH_STATE_WALL ? 1.0 / m : 0.0;
    P->nneigh[i] = 0;
    P->id[i] = (uint32_t)i;
    return i;
}

void particles_permute(struct particles *P, const size_t *perm, void *scratch)
{
    const size_t n = P->n;
    if (n == 0) return;
    double *d = scratch;
#define X(f)                                          \
    for (size_t k = 0; k < n; k++) d[k] = P->f[perm[k]]; \
    memcpy(P->f, d, n * sizeof(double));
    PARTICLES_DOUBLE_FIELDS(X)
#undef X
    uint8_t *b = scratch;
    for (size_t k = 0; k < n; k++) b[k] = P->medium[perm[k]];
    memcpy(P->medium, b, n);
    for (size_t k = 0; k < n; k++) b[k] = P->state[perm[k]];
    memcpy(P->state, b, n);
    uint16_t *s = scratch;
    for (size_t k = 0; k < n; k++) s[k] = P->nneigh[perm[k]];
    memcpy(P->nneigh, s, n * sizeof(uint16_t));
    uint32_t *u = scratch;
    for (size_t k = 0; k < n; k++) u[k] = P->id[perm[k]];
    memcpy(P->id, u, n * sizeof(uint32_t));
}

int particles_copy(struct particles *dst, const struct particles *src)
{
    memset(dst, 0, sizeof *dst);
    if (particles_alloc(dst, src->cap) != 0) return -1;
    dst->n = src->n;
#define X(f) memcpy(dst->f, src->f, src->n * sizeof(double));
    PARTICLES_DOUBLE_FIELDS(X)
#undef X
    memcpy(dst->medium, src->medium, src->n);
    memcpy(dst->state, src->state, src->n);
    memcpy(dst->nneigh, src->nneigh, src->n * sizeof(uint16_t));
    memcpy(dst->id, src->id, src->n * sizeof(uint32_t));
    return 0;
}
