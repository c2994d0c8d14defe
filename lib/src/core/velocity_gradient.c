/* velocity_gradient.c - storage of the gathered velocity gradients. */
#include "velocity_gradient.h"

#include <stdlib.h>

int velocity_gradient_alloc(struct velocity_gradient *V, size_t cap)
{
    int ok = 1;
    for (int k = 0; k < DIM * DIM; k++) ok &= (V->g[k] = calloc(cap + 1, sizeof(double))) != NULL;
    for (int k = 0; k < VELOCITY_GRADIENT_L_N; k++) ok &= (V->l[k] = calloc(cap + 1, sizeof(double))) != NULL;
    if (!ok) velocity_gradient_free(V);
    return ok ? 0 : -1;
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
