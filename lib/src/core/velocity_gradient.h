/* velocity_gradient.h - the velocity gradient of a particle as the pair loops gather it (the
 * uncorrected G = sum_j V_j (u_j - u_i) (x) grad_i W and the correction matrix
 * L = sum_j V_j (x_j - x_i) (x) grad_i W, symmetric) and its first-order correction
 * grad u = G L^-1 (docs/model.md section 5), for every material law that asks for it. */
#ifndef MIXSPH_VELOCITY_GRADIENT_H
#define MIXSPH_VELOCITY_GRADIENT_H
#include <stddef.h>

#include "dim.h"

/* The independent components of L, row by row of its upper triangle (xx, xz, zz in 2D). */
#define VELOCITY_GRADIENT_L_N (DIM * (DIM + 1) / 2)

/* Index of L's component (a, b), a <= b. */
static inline int velocity_gradient_l_index(int a, int b) { return a * DIM - a * (a - 1) / 2 + (b - a); }

/* Per particle, filled within a step for the particles whose law asks for it, not permuted. */
struct velocity_gradient {
    double *g[DIM * DIM];             /* G: component a * DIM + b is d u_a / d x_b [1/s] */
    double *l[VELOCITY_GRADIENT_L_N]; /* L [-] */
    size_t cap;                       /* particles the arrays hold */
};

#define VELOCITY_GRADIENT_DET_MIN 0.05 /* below this det L the correction is not applied */

/* Inverse of particle i's L into inv[a][b] and whether det L > VELOCITY_GRADIENT_DET_MIN (else
 * inv is not set). */
static inline int velocity_gradient_l_inverse(const struct velocity_gradient *V, size_t i, double inv[DIM][DIM])
{
#if DIM == 2
    const double lxx = V->l[0][i], lxz = V->l[1][i], lzz = V->l[2][i];
    const double det = lxx * lzz - lxz * lxz;
    if (!(det > VELOCITY_GRADIENT_DET_MIN)) return 0;
    inv[0][0] = lzz / det;
    inv[0][1] = inv[1][0] = -lxz / det;
    inv[1][1] = lxx / det;
#else
    double m[3][3];
    for (int a = 0; a < 3; a++)
        for (int b = a; b < 3; b++) m[a][b] = m[b][a] = V->l[velocity_gradient_l_index(a, b)][i];
    const double c00 = m[1][1] * m[2][2] - m[1][2] * m[1][2], c01 = m[0][2] * m[1][2] - m[0][1] * m[2][2];
    const double c02 = m[0][1] * m[1][2] - m[0][2] * m[1][1], c11 = m[0][0] * m[2][2] - m[0][2] * m[0][2];
    const double c12 = m[0][2] * m[0][1] - m[0][0] * m[1][2], c22 = m[0][0] * m[1][1] - m[0][1] * m[0][1];
    const double det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
    if (!(det > VELOCITY_GRADIENT_DET_MIN)) return 0;
    inv[0][0] = c00 / det;
    inv[0][1] = inv[1][0] = c01 / det;
    inv[0][2] = inv[2][0] = c02 / det;
    inv[1][1] = c11 / det;
    inv[1][2] = inv[2][1] = c12 / det;
    inv[2][2] = c22 / det;
#endif
    return 1;
}

/** The corrected gradient of particle i: g[a * DIM + b] = d u_a / d x_b [1/s] (G L^-1 where
 *  det L > VELOCITY_GRADIENT_DET_MIN, G itself elsewhere: near free surfaces L degenerates). */
static inline void velocity_gradient_corrected(const struct velocity_gradient *V, size_t i, double g[DIM * DIM])
{
    double inv[DIM][DIM];
    if (velocity_gradient_l_inverse(V, i, inv)) {
        for (int a = 0; a < DIM; a++)
            for (int b = 0; b < DIM; b++) {
                double s = 0.0;
                for (int c = 0; c < DIM; c++) s += V->g[a * DIM + c][i] * inv[c][b];
                g[a * DIM + b] = s;
            }
    } else {
        for (int k = 0; k < DIM * DIM; k++) g[k] = V->g[k][i];
    }
}

/** Allocate the arrays for cap particles (zeroed); 0 on success (free with velocity_gradient_free). */
int velocity_gradient_alloc(struct velocity_gradient *V, size_t cap);
/* Room for n particles (the set grows: the images of mirror side walls, walls/mirror_sides.h),
 * the values of the first cap kept; nothing when it has it. Returns 0, -1 when out of memory. */
int velocity_gradient_reserve(struct velocity_gradient *V, size_t n);
void velocity_gradient_free(struct velocity_gradient *V);

#endif
