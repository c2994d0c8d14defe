/* velocity_gradient.h - the velocity gradient of a particle as the pair loops gather it (the
 * uncorrected G = sum_j V_j (u_j - u_i) (x) grad_i W and the correction matrix
 * L = sum_j V_j (x_j - x_i) (x) grad_i W, symmetric) and its first-order correction
 * grad u = G L^-1 (docs/model.md section 5), for every material law that asks for it. */
#ifndef MIXSPH_VELOCITY_GRADIENT_H
#define MIXSPH_VELOCITY_GRADIENT_H
#include <stddef.h>

/* Per particle, filled within a step for the particles whose law asks for it, not permuted. */
struct velocity_gradient {
    double *dudx, *dudz, *dwdx, *dwdz; /* [1/s] */
    double *lxx, *lxz, *lzz;           /* [-] */
};

#define VELOCITY_GRADIENT_DET_MIN 0.05 /* below this det L the correction is not applied */

/** The corrected gradient of particle i: g[0..3] = du/dx, du/dz, dw/dx, dw/dz [1/s] (G L^-1
 *  where det L > VELOCITY_GRADIENT_DET_MIN, G itself elsewhere: near free surfaces L degenerates). */
static inline void velocity_gradient_corrected(const struct velocity_gradient *V, size_t i, double g[4])
{
    double dudx = V->dudx[i], dudz = V->dudz[i], dwdx = V->dwdx[i], dwdz = V->dwdz[i];
    const double det = V->lxx[i] * V->lzz[i] - V->lxz[i] * V->lxz[i];
    if (det > VELOCITY_GRADIENT_DET_MIN) {
        const double a = V->lzz[i] / det, b = -V->lxz[i] / det, d = V->lxx[i] / det; /* L^-1 = [a b; b d] */
        const double ux = dudx * a + dudz * b, uz = dudx * b + dudz * d;
        const double wx = dwdx * a + dwdz * b, wz = dwdx * b + dwdz * d;
        dudx = ux;
        dudz = uz;
        dwdx = wx;
        dwdz = wz;
    }
    g[0] = dudx;
    g[1] = dudz;
    g[2] = dwdx;
    g[3] = dwdz;
}

/** Allocate the arrays for cap particles (zeroed); 0 on success (free with velocity_gradient_free). */
int velocity_gradient_alloc(struct velocity_gradient *V, size_t cap);
void velocity_gradient_free(struct velocity_gradient *V);

#endif
