/* viscous.c - see viscous.h.
 *
 * Unknowns: the mobile particles and the grains held fixed (they take forces and kicks as in the
 * explicit scheme, they are only not drifted) among the active ones; wall particles and the
 * fixed grains of a hold_fixed medium (no forces) are prescribed. With u = u_U + u_B,
 *     A u_U = b,   A v = m v + dt L v restricted to the mobile rows (v zero on the prescribed),
 *     b = m u* - dt L u_B,
 * where (L v)_i = sum_j w_ij (v_i - v_j) is forces_viscous_apply. A is symmetric (w_ij = w_ji)
 * and positive definite (m > 0, L a weighted graph Laplacian). The two velocity components share
 * A and are iterated together, each with its own step lengths; the solve stops when
 * ||r_x||^2 + ||r_z||^2 <= tol^2 (||b_x||^2 + ||b_z||^2). */
#include "viscous.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mixsph.h"

/* Dot products are summed per block of this many particles, then over the blocks in order:
 * the same sums for any thread count. */
#define VISCOUS_BLOCK 2048

/* The solver's vectors, per active particle (pairs: x and z components):
 *   U   the iterate u (mobile rows; 0 on the prescribed ones)
 *   U0  the prescribed field u_B during the set-up, then u* (for the increment)
 *   R   the residual b - A u        Z  the preconditioned residual M^-1 r
 *   P   the search direction        Q  A p
 *   B   the right-hand side b       MINV  the inverse of the Jacobi diagonal   MASS  m */
enum { UX, UZ, U0X, U0Z, RX, RZ, ZX, ZZ, PX, PZ, QX, QZ, BX, BZ, MINV, MASS, N_VEC };

struct viscous_solver {
    double *v[N_VEC];
    unsigned char *mobile;
    double *partial;          /* per block: 4 partial sums */
    size_t cap, cap_blocks;
};

struct viscous_solver *viscous_create(void) { return calloc(1, sizeof(struct viscous_solver)); }

void viscous_free(struct viscous_solver *V)
{
    if (!V) return;
    for (int k = 0; k < N_VEC; k++) free(V->v[k]);
    free(V->mobile);
    free(V->partial);
    free(V);
}

static int reserve(struct viscous_solver *V, size_t n)
{
    const size_t nb = (n + VISCOUS_BLOCK - 1) / VISCOUS_BLOCK + 1;
    if (V->cap_blocks < nb) {
        double *q = realloc(V->partial, 4 * nb * sizeof(double));
        if (!q) return -1;
        V->partial = q;
        V->cap_blocks = nb;
    }
    if (V->cap >= n) return 0;
    const size_t cap = n + n / 4 + 64;
    for (int k = 0; k < N_VEC; k++) {
        double *q = realloc(V->v[k], cap * sizeof(double));
        if (!q) return -1;
        V->v[k] = q;
    }
    unsigned char *m = realloc(V->mobile, cap);
    if (!m) return -1;
    V->mobile = m;
    V->cap = cap;
    return 0;
}

/* Sum the per-block partial sums (4 per block) in block order. */
static void block_sums(const struct viscous_solver *V, long nb, double s[4])
{
    s[0] = s[1] = s[2] = s[3] = 0.0;
    for (long bk = 0; bk < nb; bk++)
        for (int k = 0; k < 4; k++) s[k] += V->partial[4 * bk + k];
}

#define BLOCKS(n) ((long)(((n) + VISCOUS_BLOCK - 1) / VISCOUS_BLOCK))
#define BLOCK_RANGE(bk, n, i0, i1)                                   \
    const size_t i0 = (size_t)(bk) * VISCOUS_BLOCK;                  \
    const size_t i1 = i0 + VISCOUS_BLOCK < (n) ? i0 + VISCOUS_BLOCK : (n)

/* q = A p on the mobile rows (0 on the prescribed ones; p is zero there), and d = (p.q_x, p.q_z). */
static int apply_a(struct viscous_solver *V, const struct forces *F, const struct pair_system *S, double dt,
                   size_t n, double d[2])
{
    double **v = V->v;
    if (forces_viscous_apply(F, S, v[PX], v[PZ], v[QX], v[QZ], NULL) != 0) return -1;
    const unsigned char *mob = V->mobile;
    const long nb = BLOCKS(n);
#pragma omp parallel for schedule(static) num_threads(S->n_threads)
    for (long bk = 0; bk < nb; bk++) {
        BLOCK_RANGE(bk, n, i0, i1);
        double tx = 0.0, tz = 0.0;
        for (size_t i = i0; i < i1; i++) {
            const double keep = mob[i] ? 1.0 : 0.0;
            v[QX][i] = keep * (v[MASS][i] * v[PX][i] + dt * v[QX][i]);
            v[QZ][i] = keep * (v[MASS][i] * v[PZ][i] + dt * v[QZ][i]);
            tx += v[PX][i] * v[QX][i];
            tz += v[PZ][i] * v[QZ][i];
        }
        double *part = V->partial + 4 * bk;
        part[0] = tx;
        part[1] = tz;
        part[2] = part[3] = 0.0;
    }
    double t[4];
    block_sums(V, nb, t);
    d[0] = t[0];
    d[1] = t[1];
    return 0;
}

/* The right-hand side b = m u* - dt L u_B, the preconditioner 1 / (m + dt diag L), the first
 * guess u0 = u* plus the last increment, its residual r0 = b - A u0 = m (u* - u0) - dt L u_full
 * (u_full: u0 on the mobile rows, the prescribed values elsewhere), z0 = M^-1 r0 and p0 = z0.
 * d receives (|b|^2, |r0|^2, r0.z0 x, r0.z0 z). Two passes of the operator. */
static int setup(struct viscous_solver *V, const struct forces *F, const struct pair_system *S, double dt, size_t n,
                 double d[4])
{
    const struct particles *P = S->P;
    double **v = V->v;
    unsigned char *mob = V->mobile;
    /* U0: the prescribed velocities, zero on the mobile rows; U: u_full */
#pragma omp parallel for schedule(static) num_threads(S->n_threads)
    for (size_t i = 0; i < n; i++) {
        /* grains held fixed take their forces like mobile ones (they are only not drifted), but
         * those of a hold_fixed medium take none */
        mob[i] = P->state[i] == MIXSPH_STATE_MOBILE ||
                 (P->state[i] == MIXSPH_STATE_FIXED && !S->media[P->medium[i]].hold_fixed);
        const int wall = P->state[i] == MIXSPH_STATE_WALL;
        v[MASS][i] = P->m[i];
        v[U0X][i] = mob[i] ? 0.0 : (wall ? P->uvx[i] : P->vx[i]);
        v[U0Z][i] = mob[i] ? 0.0 : (wall ? P->uvz[i] : P->vz[i]);
        v[UX][i] = mob[i] ? P->vx[i] + P->visc_dvx[i] : v[U0X][i];
        v[UZ][i] = mob[i] ? P->vz[i] + P->visc_dvz[i] : v[U0Z][i];
    }
    if (forces_viscous_apply(F, S, v[U0X], v[U0Z], v[BX], v[BZ], v[MINV]) != 0) return -1;
    if (forces_viscous_apply(F, S, v[UX], v[UZ], v[RX], v[RZ], NULL) != 0) return -1;
    const long nb = BLOCKS(n);
#pragma omp parallel for schedule(static) num_threads(S->n_threads)
    for (long bk = 0; bk < nb; bk++) {
        BLOCK_RANGE(bk, n, i0, i1);
        double t[4] = {0.0, 0.0, 0.0, 0.0};
        for (size_t i = i0; i < i1; i++) {
            if (!mob[i]) {
                v[BX][i] = v[BZ][i] = v[MINV][i] = v[RX][i] = v[RZ][i] = 0.0;
                v[ZX][i] = v[ZZ][i] = v[PX][i] = v[PZ][i] = 0.0;
                v[UX][i] = v[UZ][i] = 0.0;
                continue;
            }
            const double m = P->m[i];
            v[BX][i] = m * P->vx[i] - dt * v[BX][i];
            v[BZ][i] = m * P->vz[i] - dt * v[BZ][i];
            v[MINV][i] = 1.0 / (m + dt * v[MINV][i]);
            v[RX][i] = m * (P->vx[i] - v[UX][i]) - dt * v[RX][i];
            v[RZ][i] = m * (P->vz[i] - v[UZ][i]) - dt * v[RZ][i];
            v[U0X][i] = P->vx[i]; /* u*, kept for the increment */
            v[U0Z][i] = P->vz[i];
            v[ZX][i] = v[PX][i] = v[MINV][i] * v[RX][i];
            v[ZZ][i] = v[PZ][i] = v[MINV][i] * v[RZ][i];
            t[0] += v[BX][i] * v[BX][i] + v[BZ][i] * v[BZ][i];
            t[1] += v[RX][i] * v[RX][i] + v[RZ][i] * v[RZ][i];
            t[2] += v[RX][i] * v[ZX][i];
            t[3] += v[RZ][i] * v[ZZ][i];
        }
        for (int k = 0; k < 4; k++) V->partial[4 * bk + k] = t[k];
    }
    block_sums(V, nb, d);
    return 0;
}

int viscous_solve(struct viscous_solver *V, const struct forces *F, const struct pair_system *S, double dt,
                  double tolerance, int max_iterations, struct viscous_report *report)
{
    struct particles *P = S->P;
    const size_t n = S->C->start[S->C->ncell];
    report->iterations = 0;
    report->residual = 0.0;
    report->converged = 1;
    if (reserve(V, n) != 0) return -1;
    double d[4];
    if (setup(V, F, S, dt, n, d) != 0) return -1;
    double **v = V->v;
    const double b2 = d[0];
    double r2 = d[1], rz_x = d[2], rz_z = d[3];
    const double tol2 = tolerance * tolerance * b2;
    if (b2 == 0.0) { /* no force and nothing moving: the solution is at rest */
        for (size_t i = 0; i < n; i++) v[UX][i] = v[UZ][i] = 0.0;
        r2 = 0.0;
    }
    const long nb = BLOCKS(n);
    int it = 0;
    while (r2 > tol2 && it < max_iterations) {
        double pq[2];
        if (apply_a(V, F, S, dt, n, pq) != 0) return -1;
        const double ax = pq[0] > 0.0 ? rz_x / pq[0] : 0.0, az = pq[1] > 0.0 ? rz_z / pq[1] : 0.0;
#pragma omp parallel for schedule(static) num_threads(S->n_threads)
        for (long bk = 0; bk < nb; bk++) {
            BLOCK_RANGE(bk, n, i0, i1);
            double t[4] = {0.0, 0.0, 0.0, 0.0};
            for (size_t i = i0; i < i1; i++) {
                v[UX][i] += ax * v[PX][i];
                v[UZ][i] += az * v[PZ][i];
                v[RX][i] -= ax * v[QX][i];
                v[RZ][i] -= az * v[QZ][i];
                v[ZX][i] = v[MINV][i] * v[RX][i];
                v[ZZ][i] = v[MINV][i] * v[RZ][i];
                t[0] += v[RX][i] * v[ZX][i];
                t[1] += v[RZ][i] * v[ZZ][i];
                t[2] += v[RX][i] * v[RX][i] + v[RZ][i] * v[RZ][i];
            }
            for (int k = 0; k < 4; k++) V->partial[4 * bk + k] = t[k];
        }
        block_sums(V, nb, d);
        const double bx = rz_x > 0.0 ? d[0] / rz_x : 0.0, bz = rz_z > 0.0 ? d[1] / rz_z : 0.0;
        rz_x = d[0];
        rz_z = d[1];
        r2 = d[2];
        it++;
        if (!(r2 > tol2)) break; /* converged: no next direction needed */
#pragma omp parallel for schedule(static) num_threads(S->n_threads)
        for (size_t i = 0; i < n; i++) {
            v[PX][i] = v[ZX][i] + bx * v[PX][i];
            v[PZ][i] = v[ZZ][i] + bz * v[PZ][i];
        }
    }
    report->iterations = it;
    report->residual = b2 > 0.0 ? sqrt(r2 / b2) : sqrt(r2);
    report->converged = r2 <= tol2;
    const unsigned char *mob = V->mobile;
#pragma omp parallel for schedule(static) num_threads(S->n_threads)
    for (size_t i = 0; i < n; i++) {
        if (!mob[i]) continue;
        P->visc_dvx[i] = v[UX][i] - v[U0X][i];
        P->visc_dvz[i] = v[UZ][i] - v[U0Z][i];
        P->vx[i] = v[UX][i];
        P->vz[i] = v[UZ][i];
    }
    return 0;
}
