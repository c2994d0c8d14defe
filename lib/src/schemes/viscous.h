/* viscous.h - the implicit viscous step (numerics.viscosity = "implicit"; docs/numerics.md
 * section 2b): the velocity under the viscous operator of the momentum equation, with the
 * operator (positions, viscosities, kernel factors) frozen over the step, by a two-stage SDIRK
 * whose stages are backward-Euler-like solves
 *     m_i u_i + kappa sum_j w_ij (u_i - u_j) = m_i w_i        for the unknown particles i,
 * w_ij >= 0 the couplings of the momentum pass (forces.h). Wall particles follow the unknowns
 * through the mirror of walls.h (their wall's velocity at the stage's time); which other
 * particles are unknowns the caller says (the scheme, by the material laws' rules): the rest
 * keep their velocities. The solver knows no physical rule. The
 * system is solved matrix-free by BiCGSTAB with a Jacobi or a two-level (Jacobi plus the coarse
 * correction of viscous_coarse.h) preconditioner, each stage warm-started from its increments of
 * the last two steps (kept per particle). Dot products are summed in fixed blocks, so results do not depend on the
 * thread count. */
#ifndef MIXSPH_VISCOUS_H
#define MIXSPH_VISCOUS_H
#include <stddef.h>

#include "forces.h"
#include "numerics_keys.h"
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

/* The solver's numerical parameters, fixed for a run: the `numerics` keys whose rows of
 * core/numerics_keys.def are read by VISCOUS, as the members those rows name. */
struct viscous_params {
#define NUMERICS_KEY NUMERICS_MEMBER_OF_VISCOUS
#include "numerics_keys.def"
#undef NUMERICS_KEY
};

struct viscous_solver *viscous_create(void);
void viscous_free(struct viscous_solver *V);

/** The implicit viscous step over dt from t (walls not yet moved): the two-stage SDIRK of
 *  docs/numerics.md, each stage a solve (m + gamma dt L) U = m w - gamma dt L u_B with the
 *  walls' mirror (M, rebuilt here at the current positions; the walls W) at
 *  the stage's time, warm-started from its increments of the last two steps. unknown[i] != 0:
 *  particle i's velocity is solved for; the others (walls aside) are prescribed at theirs.
 *  Updates P->vel of the unknowns, the increments (visc_dv, visc_d1 and those of the step
 *  before) and the wall particles' P->uv. The report sums the two stages' iterations and keeps
 *  the larger residual; a stage stops at ||r|| <= tolerance ||b|| or after max_iterations (vp).
 *  Returns -1 when out of memory, 0 otherwise (convergence is in the report). */
int viscous_step(struct viscous_solver *V, const struct forces *F, const struct pair_system *S,
                 struct wall_mirror *M, const struct walls *W, double t, double dt,
                 const unsigned char *unknown, const struct viscous_params *vp, struct viscous_report *report);

/** The viscous operator applied to the last step's solved velocity field (its wall rows as the
 *  mirror made them): lu[d] points at component d of sum_j w_ij (u_i - u_j) per particle, in the solver's
 *  scratch, valid until its next use. Returns -1 without a stored operator. */
int viscous_solution_operator(struct viscous_solver *V, const struct forces *F, const struct pair_system *S,
                              const double *lu[DIM]);

/** One backward-Euler solve, (m + dt L) u = m u* - dt L u_B, for the velocities of the
 *  particles mobile or held (P->vel: u* in, u out; P->visc_dv: the warm start in, the
 *  increment out) after forces_momentum stored the couplings, with the walls' mirror M as
 *  built and timed by the caller (NULL: the walls keep P->uv) and the preconditioner of enum
 *  viscous_preconditioner; tests of the solver. */
int viscous_solve(struct viscous_solver *V, const struct forces *F, const struct pair_system *S,
                  const struct wall_mirror *M, double dt, int preconditioner, double tolerance, int max_iterations,
                  struct viscous_report *report);

#endif
