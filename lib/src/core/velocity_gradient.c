/* velocity_gradient.c - storage of the gathered velocity gradients. */
#include "velocity_gradient.h"

#include <stdlib.h>
#include <string.h>

int velocity_gradient_alloc(struct velocity_gradient *V, size_t cap)
{
    V->cap = cap;
    int ok = 1;
    for (int k = 0; k < DIM * DIM; k++) ok &= (V->g[k] = calloc(cap + 1, sizeof(double))) != NULL;
    for (int k = 0; k < VELOCITY_GRADIENT_L_N; k++) ok &= (V->l[k] = calloc(cap + 1, sizeof(double))) != NULL;
    if (!ok) velocity_gradient_free(V);
    return ok ? 0 : -1;
}

/* a[0 .. old] kept, the rest to new zeroed; NULL when out of memory (a then freed) */
static double *grow(double *a, size_t old, size_t cap)
{
    double *r = realloc(a, (cap + 1) * sizeof *r);
    if (!r) {
        free(a);
        return NULL;
    }
    memset(r + old + 1, 0, (cap - old) * sizeof *r);
    return r;
}

int velocity_gradient_reserve(struct velocity_gradient *V, size_t n)
{
    if (n <= V->cap) return 0;
    const size_t cap = n + n / 4 + 64;
    int ok = 1;
    for (int k = 0; k < DIM * DIM; k++) ok &= (V->g[k] = grow(V->g[k], V->cap, cap)) != NULL;
    for (int k = 0; k < VELOCITY_GRADIENT_L_N; k++) ok &= (V->l[k] = grow(V->l[k], V->cap, cap)) != NULL;
    if (!ok) {
        velocity_gradient_free(V);
        return -1;
    }
    V->cap = cap;
    return 0;
}

void velocity_gradient_free(struct velocity_gradient *V)
{
    for (int k = 0; k < DIM * DIM; k++) {
        free(V->g[k]);
        V->g[k] = NULL;
    }
    for (int k = 0; k < VELOCITY_GRADIENT_L_N; k++) {
        free(V->l[k]);
        V->l[k] = NULL;
    }
}
