/* viscous.h - the implicit viscous step (numerics.viscosity = "implicit"; docs/numerics.md):
 * backward Euler for the velocity under the viscous operator of the momentum equation, with the
 * operator (positions, viscosities, kernel factors) frozen over the step,
 *     m_i u_i + dt sum_j w_ij (u_i - u_j) = m_i u*_i        for the mobile particles i,
 * u* the velocity after the step's other forces, w_ij >= 0 the couplings of the momentum pass
 * (forces.h). Wall particles (at their no-slip mirror or free-slip velocity) and grains held
 * fixed enter as prescribed velocities. The system is symmetric positive definite; it is solved
 * matrix-free by a Jacobi-preconditioned conjugate gradient, warm-started from the last step's
 * viscous increment (kept per particle). Dot products are summed in fixed blocks, so results do
 * not depend on the thread count. */
#ifndef MIXSPH_VISCOUS_H
#define MIXSPH_VISCOUS_H
#include <stddef.h>

#include "forces.h"

struct viscous_solver;

/* The outcome of one solve. */
struct viscous_report {
    int iterations;    /* conjugate-gradient iterations */
    double residual;   /* final ||b - A u|| / ||b|| (0 when b = 0) */
    int converged;     /* residual <= tolerance */
};

struct viscous_solver *viscous_create(void);
void viscous_free(struct viscous_solver *V);

/** Solve for the mobile particles' velocities (P->vx, P->vz, updated in place; P->visc_dvx,
 *  visc_dvz receive the increment for the next warm start) after forces_momentum stored the
 *  couplings. Stops at ||r|| <= tolerance ||b|| or after max_iterations. Returns -1 when out of
 *  memory, 0 otherwise (convergence is in the report). */
int viscous_solve(struct viscous_solver *V, const struct forces *F, const struct pair_system *S, double dt,
                  double tolerance, int max_iterations, struct viscous_report *report);

#endif
