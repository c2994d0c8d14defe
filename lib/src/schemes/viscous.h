/* viscous.h - the implicit viscous step (numerics.viscosity = "implicit"; docs/numerics.md
 * section 2b): the velocity under the viscous operator of the momentum equation, with the
 * operator (positions, viscosities, kernel factors) frozen over the step, by a two-stage SDIRK
 * whose stages are backward-Euler-like solves
 *     m_i u_i + kappa sum_j w_ij (u_i - u_j) = m_i w_i        for the unknown particles i,
 * w_ij >= 0 the couplings of the momentum pass (forces.h). Wall particles follow the unknowns
 * through the mirror of walls.h (their wall's velocity at the stage's time); grains held fixed
 * are prescribed at rest when numerics.held_grains is "rigid" or their medium hold_fixed. The
 * system is solved matrix-free by BiCGSTAB with a Jacobi or a two-level (Jacobi plus the coarse
 * correction of viscous_coarse.h) preconditioner, each stage warm-started from its increments of
 * the last two steps (kept per particle). Dot products are summed in fixed blocks, so results do not depend on the
 * thread count. */
#ifndef MIXSPH_VISCOUS_H
#define MIXSPH_VISCOUS_H
#include <stddef.h>

#include "forces.h"
#include "walls.h"

struct viscous_solver;

/* numerics.viscous_preconditioner (the values of its case-file choices). */
enum viscous_preconditioner { VISCOUS_JACOBI = 0, VISCOUS_TWO_LEVEL = 1 };

/* The outcome of one solve. */
struct viscous_report {
    int iterations;    /* BiCGSTAB iterations */
    double residual;   /* final ||b - A u|| / ||b|| (0 when b = 0) */
    int converged;     /* residual <= tolerance */
};

struct viscous_solver *viscous_create(void);
void viscous_free(struct viscous_solver *V);

/** The implicit viscous step over dt from t (walls not yet moved): the two-stage SDIRK of
 *  docs/numerics.md, each stage a solve (m + gamma dt L) U = m w - gamma dt L u_B with the
 *  walls' mirror (M, rebuilt here at the current positions) at the stage's time, warm-started
 *  from its increments of the last two steps. Updates P->vx, P->vz, the increments
 *  (visc_dv*, visc_d1* and those of the step before) and the wall particles' uvx, uvz. The
 *  report sums the two stages' iterations and keeps the larger residual. Stops a stage at
 *  ||r|| <= tolerance ||b|| or after max_iterations. With rigid held grains (cfg->held_grains_rigid)
 *  these are prescribed at rest and then, if judge_dt > 0, get the velocity one explicit step of
 *  judge_dt of their forces gives them (the other forces' P->ax, P->az and the viscous force of the
 *  solved field), on which the regime decision judges them. Returns -1 when out of memory, 0
 *  otherwise (convergence is in the report). */
int viscous_step(struct viscous_solver *V, const struct forces *F, const struct pair_system *S,
                 struct wall_mirror *M, const struct case_def *cfg, const struct wall_state *ws, double t, double dt,
                 double judge_dt, double tolerance, int max_iterations, struct viscous_report *report);

/** One backward-Euler solve, (m + dt L) u = m u* - dt L u_B, for the mobile particles'
 *  velocities (P->vx, P->vz: u* in, u out; P->visc_dvx, visc_dvz: the warm start in, the
 *  increment out) after forces_momentum stored the couplings, with the walls' mirror M as
 *  built and timed by the caller (NULL: the walls keep uvx, uvz) and the preconditioner of enum
 *  viscous_preconditioner; tests of the solver. */
int viscous_solve(struct viscous_solver *V, const struct forces *F, const struct pair_system *S,
                  const struct wall_mirror *M, double dt, int preconditioner, double tolerance, int max_iterations,
                  struct viscous_report *report);

#endif
