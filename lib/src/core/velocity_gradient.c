/* velocity_gradient.c - storage of the gathered velocity gradients. */
#include "velocity_gradient.h"

#include <stdlib.h>

int velocity_gradient_alloc(struct velocity_gradient *V, size_t cap)
{
    double **f[7] = {&V->dudx, &V->dudz, &V->dwdx, &V->dwdz, &V->lxx, &V->lxz, &V->lzz};
    int ok = 1;
    for (int k = 0; k < 7; k++) ok &= (*f[k] = calloc(cap + 1, sizeof(double))) != NULL;
    if (!ok) velocity_gradient_free(V);
    return ok ? 0 : -1;
}

void velocity_gradient_free(struct velocity_gradient *V)
{
    double **f[7] = {&V->dudx, &V->dudz, &V->dwdx, &V->dwdz, &V->lxx, &V->lxz, &V->lzz};
    for (int k = 0; k < 7; k++) {
        free(*f[k]);
        *f[k] = NULL;
    }
}
