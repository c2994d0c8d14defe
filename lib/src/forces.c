/* forces.c - the continuity and momentum pair loops, eq. (3) of Manenti et al. (2018):
 *
 *   d rho_i/dt = rho_i sum_j V_j (u_i - u_j) . grad_i W_ij
 *   d u_i/dt   = -1/rho_i sum_j V_j (p_i + p_j) grad_i W_ij          (= -sum m_j (p_i+p_j)/(rho_i rho_j) gradW)
 *                - sum_j m_j Pi_ij grad_i W_ij                         (Monaghan, same fluid medium only)
 *                + 1/rho_i sum_j V_j (mu_i + mu_j) F r^2/(r^2 + eta^2) (u_i - u_j)   (Morris et al. 1997)
 *                + g
 * with V_j = m_j / rho_j (wall particles: V = dx^2, their extrapolated pressure, the fluid's own
 * density and viscosity, and their no-slip velocity in the viscous term). Every pairwise term
 * is antisymmetric (m_i a_ij = -m_j a_ji), so momentum is conserved between particles.
 * Two passes per step: continuity (with the newest velocities) before the EOS, momentum after;
 * see integrate.c for why. Gather form: each thread writes only particle i, so results do not
 * depend on the thread count. */
#include <math.h>

#include "sim.h"

/* Per-step constants of the pair loop. */
struct pair_ctx {
    struct kernel K;
    double eta2;                      /* 0.01 h^2 */
    double c[CASE_MAX_MEDIA];         /* sound speed per medium */
    double alpha[CASE_MAX_MEDIA];     /* artificial viscosity per medium (fluids only) */
};

static void pair_ctx_init(const mixsph_sim *s, struct pair_ctx *X)
{
    X->K = s->K;
    X->eta2 = 0.01 * s->h * s->h;
    for (size_t k = 0; k < s->cfg.n_media; k++) {
        X->c[k] = s->cfg.media[k].c;
        X->alpha[k] = s->cfg.media[k].kind == MEDIUM_FLUID ? s->cfg.media[k].alpha_m : 0.0;
    }
}

/* Momentum contribution of particle j to particle i (i not a wall): adds to (ax, az). */
static inline void pair_accumulate(const struct pair_ctx *X, const struct particles *P, size_t i, size_t j,
                                   double *ax, double *az)
{
    const double rx = P->x[i] - P->x[j], rz = P->z[i] - P->z[j];
    const double r2 = rx * rx + rz * rz;
    if (r2 >= X->K.r2max || j == i) return;
    const double F = kernel_f(&X->K, sqrt(r2));
    const double rhoi = P->rho[i];
    const int mi = P->medium[i];
    const int wall = P->state[j] == MIXSPH_STATE_WALL;
    const double vj = P->vol[j];
    const double dvx = P->vx[i] - P->vx[j], dvz = P->vz[i] - P->vz[j];
    const double vdotr = dvx * rx + dvz * rz;
    /* pressure */
    double fac = -vj * (P->p[i] + P->p[j]) * F / rhoi;
    /* artificial viscosity: fluid pairs of one medium, and fluid-wall pairs */
    const double alpha = X->alpha[mi];
    if (alpha > 0.0 && vdotr < 0.0 && (wall || P->medium[j] == mi)) {
        const double rhoj = wall ? rhoi : P->rho[j];
        const double mj = wall ? rhoi * vj : P->m[j];
        const double muij = X->K.h * vdotr / (r2 + X->eta2);
        const double pi_ij = -alpha * X->c[mi] * muij / (0.5 * (rhoi + rhoj));
        fac -= mj * pi_ij * F;
    }
    *ax += fac * rx;
    *az += fac * rz;
    /* laminar viscosity (Morris): walls use the fluid's viscosity and their mirror velocity */
    const double mui = P->mu[i], muj = wall ? mui : P->mu[j];
    if (mui + muj > 0.0) {
        const double uxj = wall ? P->uvx[j] : P->vx[j], uzj = wall ? P->uvz[j] : P->vz[j];
        const double vf = vj * (mui + muj) * F * r2 / ((r2 + X->eta2) * rhoi);
        *ax += vf * (P->vx[i] - uxj);
        *az += vf * (P->vz[i] - uzj);
    }
}

/* Continuity contribution of j to i (without the rho_i factor) and same-medium neighbours. */
static inline void pair_continuity(const struct kernel *K, const struct particles *P, size_t i, size_t j, double *drho,
                                   int *nn)
{
    const double rx = P->x[i] - P->x[j], rz = P->z[i] - P->z[j];
    const double r2 = rx * rx + rz * rz;
    if (r2 >= K->r2max || j == i) return;
    const double F = kernel_f(K, sqrt(r2));
    const double vdotr = (P->vx[i] - P->vx[j]) * rx + (P->vz[i] - P->vz[j]) * rz;
    *drho += P->vol[j] * vdotr * F;
    *nn += P->state[j] != MIXSPH_STATE_WALL && P->medium[j] == P->medium[i];
}

/* Density rate and neighbour counts of every mobile particle, from the current positions and
 * velocities. Returns 1 if a non-finite value appeared. */
int forces_continuity(mixsph_sim *s)
{
    struct particles *P = &s->P;
    const struct cells *C = &s->C;
    const struct kernel K = s->K;
    const size_t n = C->start[C->ncell];
    int bad = 0;
#pragma omp parallel for schedule(static) reduction(| : bad) num_threads(SIM_THREADS(s))
    for (size_t i = 0; i < n; i++) {
        if (P->state[i] != MIXSPH_STATE_MOBILE) continue;
        double drho = 0.0;
        int nn = 0;
        int ix, iz;
        cells_coords(C, P->x[i], P->z[i], &ix, &iz);
        for (int row = -1; row <= 1; row++) {
            const struct range rg = cells_row(C, ix, iz, row);
            for (size_t j = rg.begin; j < rg.end; j++) pair_continuity(&K, P, i, j, &drho, &nn);
        }
        P->drho[i] = P->rho[i] * drho;
        P->nneigh[i] = (uint16_t)(nn < 65535 ? nn : 65535);
        bad |= !isfinite(drho);
    }
    return bad;
}

/* Acceleration of every mobile particle. Returns 1 if a non-finite value appeared. */
int forces_compute(mixsph_sim *s)
{
    struct particles *P = &s->P;
    const struct cells *C = &s->C;
    struct pair_ctx X;
    pair_ctx_init(s, &X);
    const double g = s->cfg.g;
    const size_t n = C->start[C->ncell];
    int bad = 0;
#pragma omp parallel for schedule(static) reduction(| : bad) num_threads(SIM_THREADS(s))
    for (size_t i = 0; i < n; i++) {
        if (P->state[i] != MIXSPH_STATE_MOBILE) continue;
        double ax = 0.0, az = 0.0;
        int ix, iz;
        cells_coords(C, P->x[i], P->z[i], &ix, &iz);
        for (int row = -1; row <= 1; row++) {
            const struct range rg = cells_row(C, ix, iz, row);
            for (size_t j = rg.begin; j < rg.end; j++) pair_accumulate(&X, P, i, j, &ax, &az);
        }
        P->ax[i] = ax;
        P->az[i] = az - g;
        bad |= !isfinite(ax + az);
    }
    return bad;
}

/* Test hook: the acceleration particle j gives particle i (no gravity). */
void forces_pair_for_test(const mixsph_sim *s, size_t i, size_t j, double *ax, double *az, double *drho)
{
    struct pair_ctx X;
    pair_ctx_init(s, &X);
    int nn = 0;
    *ax = *az = *drho = 0.0;
    pair_accumulate(&X, &s->P, i, j, ax, az);
    pair_continuity(&X.K, &s->P, i, j, drho, &nn);
}
