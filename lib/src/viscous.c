/* viscous.c - see viscous.h.
 *
 * Unknowns: the mobile particles (state MOBILE) among the active ones; everything else in the
 * active range (wall particles, grains held fixed) is prescribed. With u = u_U + u_B,
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

/* s[0..3] = (a0.b0, a1.b1, a2.b2, a3.b3) over [0, n), in fixed blocks (a2, b2, a3, b3 may be
 * NULL: their sums are 0). */
static void dots4(struct viscous_solver *V, size_t n, const double *a0, const double *b0, const double *a1,
                  const double *b1, const double *a2, const double *b2, const double *a3, const double *b3,
                  int n_threads, double s[4])
{
    const long nb = (long)((n + VISCOUS_BLOCK - 1) / VISCOUS_BLOCK);
    double *part = V->partial;
#pragma omp parallel for schedule(static) num_threads(n_threads)
    for (long bk = 0; bk < nb; bk++) {
        const size_t i0 = (size_t)bk * VISCOUS_BLOCK, i1 = i0 + VISCOUS_BLOCK < n ? i0 + VISCOUS_BLOCK : n;
        double t0 = 0.0, t1 = 0.0, t2 = 0.0, t3 = 0.0;
        for (size_t i = i0; i < i1; i++) {
            t0 += a0[i] * b0[i];
            t1 += a1[i] * b1[i];
            if (a2) t2 += a2[i] * b2[i];
            if (a3) t3 += a3[i] * b3[i];
        }
        part[4 * bk] = t0;
        part[4 * bk + 1] = t1;
        part[4 * bk + 2] = t2;
        part[4 * bk + 3] = t3;
    }
    s[0] = s[1] = s[2] = s[3] = 0.0;
    for (long bk = 0; bk < nb; bk++)
        for (int k = 0; k < 4; k++) s[k] += part[4 * bk + k];
}

/* q = A v on the mobile rows (0 on the prescribed ones); v is zero on the prescribed rows. */
static int apply_a(struct viscous_solver *V, const struct forces *F, const struct pair_system *S, double dt,
                   size_t n, const double *vx, const double *vz, double *qx, double *qz)
{
    if (forces_viscous_apply(F, S, vx, vz, qx, qz) != 0) return -1;
    const double *mass = V->v[MASS];
    const unsigned char *mob = V->mobile;
#pragma omp parallel for schedule(static) num_threads(S->n_threads)
    for (size_t i = 0; i < n; i++) {
        const double keep = mob[i] ? 1.0 : 0.0;
        qx[i] = keep * (mass[i] * vx[i] + dt * qx[i]);
        qz[i] = keep * (mass[i] * vz[i] + dt * qz[i]);
    }
    return 0;
}

/* The right-hand side b, the preconditioner, the first guess (u* plus the last increment) and
 * its residual. Returns -1 when the operator is missing. */
static int setup(struct viscous_solver *V, const struct forces *F, const struct pair_system *S, double dt, size_t n)
{
    const struct particles *P = S->P;
    double **v = V->v;
    unsigned char *mob = V->mobile;
    /* the prescribed velocities, zero on the mobile rows, into U0 */
#pragma omp parallel for schedule(static) num_threads(S->n_threads)
    for (size_t i = 0; i < n; i++) {
        mob[i] = P->state[i] == MIXSPH_STATE_MOBILE;
        const int wall = P->state[i] == MIXSPH_STATE_WALL;
        v[MASS][i] = P->m[i];
        v[U0X][i] = mob[i] ? 0.0 : (wall ? P->uvx[i] : P->vx[i]);
        v[U0Z][i] = mob[i] ? 0.0 : (wall ? P->uvz[i] : P->vz[i]);
    }
    if (forces_viscous_apply(F, S, v[U0X], v[U0Z], v[BX], v[BZ]) != 0) return -1;
    if (forces_viscous_apply(F, S, NULL, NULL, v[MINV], NULL) != 0) return -1;
#pragma omp parallel for schedule(static) num_threads(S->n_threads)
    for (size_t i = 0; i < n; i++) {
        if (!mob[i]) {
            v[BX][i] = v[BZ][i] = v[MINV][i] = 0.0;
            v[UX][i] = v[UZ][i] = 0.0;
            continue;
        }
        v[BX][i] = P->m[i] * P->vx[i] - dt * v[BX][i];
        v[BZ][i] = P->m[i] * P->vz[i] - dt * v[BZ][i];
        v[MINV][i] = 1.0 / (P->m[i] + dt * v[MINV][i]);
        v[U0X][i] = P->vx[i]; /* u*, kept for the increment */
        v[U0Z][i] = P->vz[i];
        v[UX][i] = P->vx[i] + P->visc_dvx[i];
        v[UZ][i] = P->vz[i] + P->visc_dvz[i];
    }
    if (apply_a(V, F, S, dt, n, v[UX], v[UZ], v[RX], v[RZ]) != 0) return -1;
#pragma omp parallel for schedule(static) num_threads(S->n_threads)
    for (size_t i = 0; i < n; i++) {
        v[RX][i] = v[BX][i] - v[RX][i];
        v[RZ][i] = v[BZ][i] - v[RZ][i];
        v[ZX][i] = v[MINV][i] * v[RX][i];
        v[ZZ][i] = v[MINV][i] * v[RZ][i];
        v[PX][i] = v[ZX][i];
        v[PZ][i] = v[ZZ][i];
    }
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
    if (setup(V, F, S, dt, n) != 0) return -1;
    double **v = V->v;
    double d[4];
    dots4(V, n, v[BX], v[BX], v[BZ], v[BZ], v[RX], v[RX], v[RZ], v[RZ], S->n_threads, d);
    const double b2 = d[0] + d[1];
    double r2 = d[2] + d[3];
    dots4(V, n, v[RX], v[ZX], v[RZ], v[ZZ], NULL, NULL, NULL, NULL, S->n_threads, d);
    double rz_x = d[0], rz_z = d[1];
    const double tol2 = tolerance * tolerance * b2;
    if (b2 == 0.0) { /* no force and nothing moving: the solution is at rest */
        for (size_t i = 0; i < n; i++) v[UX][i] = v[UZ][i] = 0.0;
        r2 = 0.0;
    }
    int it = 0;
    while (r2 > tol2 && it < max_iterations) {
        if (apply_a(V, F, S, dt, n, v[PX], v[PZ], v[QX], v[QZ]) != 0) return -1;
        dots4(V, n, v[PX], v[QX], v[PZ], v[QZ], NULL, NULL, NULL, NULL, S->n_threads, d);
        const double ax = d[0] > 0.0 ? rz_x / d[0] : 0.0, az = d[1] > 0.0 ? rz_z / d[1] : 0.0;
#pragma omp parallel for schedule(static) num_threads(S->n_threads)
        for (size_t i = 0; i < n; i++) {
            v[UX][i] += ax * v[PX][i];
            v[UZ][i] += az * v[PZ][i];
            v[RX][i] -= ax * v[QX][i];
            v[RZ][i] -= az * v[QZ][i];
            v[ZX][i] = v[MINV][i] * v[RX][i];
            v[ZZ][i] = v[MINV][i] * v[RZ][i];
        }
        dots4(V, n, v[RX], v[ZX], v[RZ], v[ZZ], v[RX], v[RX], v[RZ], v[RZ], S->n_threads, d);
        const double bx = rz_x > 0.0 ? d[0] / rz_x : 0.0, bz = rz_z > 0.0 ? d[1] / rz_z : 0.0;
        rz_x = d[0];
        rz_z = d[1];
        r2 = d[2] + d[3];
#pragma omp parallel for schedule(static) num_threads(S->n_threads)
        for (size_t i = 0; i < n; i++) {
            v[PX][i] = v[ZX][i] + bx * v[PX][i];
            v[PZ][i] = v[ZZ][i] + bz * v[PZ][i];
        }
        it++;
    }
    report->iterations = it;
    report->residual = b2 > 0.0 ? sqrt(r2 / b2) : sqrt(r2);
    report->converged = r2 <= tol2;
    if (!(report->residual == report->residual)) report->converged = 0; /* NaN */
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
