/* viscous_coarse.h - the coarse level of the implicit viscous solve's two-level preconditioner
 * (numerics.viscous_preconditioner = "two_level"; docs/numerics.md section 2b).
 *
 * Jacobi alone leaves the smooth part of the error to the Krylov iterations, and with the
 * acoustic time step the viscous operator couples over many smoothing lengths in a slow
 * landslide (kappa sum_j w_ij >> m_i in the granular mass), so that part dominates the iteration count. The
 * coarse level removes it with an aggregation (piecewise-constant) correction: the unknowns are
 * grouped by cells (whole cells of one cell row, one search radius wide, so that the half stencil
 * of a pair loop reaches only five groups), the Galerkin operator A_c = P^T A P is assembled from
 * the pair couplings and the Jacobi diagonal, and A_c^-1 is approximated by one symmetric
 * Gauss-Seidel sweep from zero, a fixed linear map as a Krylov preconditioner must be. Added to
 * the Jacobi step (additive two-level Schwarz): y = D^-1 r + P A_c^-1 P^T r. */
#ifndef MIXSPH_VISCOUS_COARSE_H
#define MIXSPH_VISCOUS_COARSE_H
#include <stddef.h>

#include "forces.h"

struct viscous_coarse;

struct viscous_coarse *viscous_coarse_create(void);
void viscous_coarse_free(struct viscous_coarse *K);

/** The groups of the unknowns (unknown[i] != 0, i < n active particles sorted by the cells of S)
 *  and the couplings between them, from the last implicit momentum pass. Once per step: the
 *  couplings do not change within it. Returns -1 when out of memory or without couplings. */
int viscous_coarse_build(struct viscous_coarse *K, const struct forces *F, const struct pair_system *S,
                         const unsigned char *unknown, size_t n);

/** A_c for a stage's kappa, from the Jacobi inverse diagonal minv_i = 1 / (m_i + kappa sum_j w_ij)
 *  of the unknowns. After viscous_coarse_build. */
void viscous_coarse_operator(struct viscous_coarse *K, const double *minv, const unsigned char *unknown,
                             double kappa, int threads);

/** out += P A_c^-1 P^T in (DIM components each) on the unknown rows (in zero on the others). */
void viscous_coarse_correct(struct viscous_coarse *K, const unsigned char *unknown, const double *const in[DIM],
                            double *const out[DIM], int threads);

#endif
