/* viscous.c - see viscous.h.
 *
 * Unknowns: the particles the caller names (the implicit scheme: the mobile ones and the grains
 * held fixed that take their forces, by the paper law's rule, mixture_paper.h); the others keep
 * their velocities; the wall particles follow the unknowns through
 * the mirror of walls.h, u_g = c_g + s_g sum_k a_gk u_k (with the wall's velocity at the end of
 * the step, so the boundary condition is implicit like the rest). With u = u_U + u_B, u_B the
 * prescribed values with the walls' mirror of them,
 *     A v = m v + dt L (v + s a v) restricted to the unknown rows (v zero on the prescribed),
 *     b = m u* - dt L u_B,
 * where (L v)_i = sum_j w_ij (v_i - v_j) is forces_viscous_apply and (s a v) fills the wall rows.
 * The mirror makes A non-symmetric (row i of a wall particle's neighbour sees the fluid around
 * that wall particle, not the reverse), so the solver is BiCGSTAB (van der Vorst 1992) with the
 * Jacobi diagonal m + dt sum_j w_ij as right preconditioner, with the coarse correction of
 * viscous_coarse.h added to it when numerics.viscous_preconditioner is "two_level". The two
 * velocity components share A and are iterated together, each with its own scalars; the solve
 * stops when
 * ||r_x||^2 + ||r_z||^2 <= tol^2 (||b_x||^2 + ||b_z||^2). */
#include "viscous.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mixsph.h"
#include "team.h"
#include "viscous_coarse.h"

/* Dot products are summed per block of this many particles, then over the blocks in order:
 * the same sums for any thread count. */
#define VISCOUS_BLOCK 2048
#define N_SUMS 6 /* partial sums per block */

/* The solver's vectors, per active particle (pairs: x and z components):
 *   U   the iterate u (unknown rows; junk on the others until the end)
 *   U0  the prescribed field u_B during the set-up, then u* (for the increment)
 *   R   the residual b - A u          RH  the shadow residual r^_0
 *   P   the search direction          Y   M^-1 p        V  A y
 *   S   the intermediate residual     Z   M^-1 s        T  A z
 *   B   the right-hand side b         MINV  the inverse of the Jacobi diagonal   MASS  m
 *   W   a stage's velocity w          G   its first guess
 *   US  u* (the velocity before the step) */
enum { UX, UZ, U0X, U0Z, RX, RZ, RHX, RHZ, PX, PZ, YX, YZ, VX, VZ, SX, SZ, ZX, ZZ, TX, TZ, BX, BZ, MINV, MASS,
       WX, WZ, GX, GZ, USX, USZ, N_VEC };

struct viscous_solver {
    double *v[N_VEC];
    unsigned char *mobile;
    double *partial;          /* per block: N_SUMS partial sums */
    size_t cap, cap_blocks;
    struct viscous_coarse *coarse; /* two_level: the coarse level, built once per step */
    int preconditioner;            /* enum viscous_preconditioner of the current solve */
    int coarse_built;              /* this step's coarse groups and couplings are in */
};

struct viscous_solver *viscous_create(void)
{
    struct viscous_solver *V = calloc(1, sizeof(struct viscous_solver));
    if (V && !(V->coarse = viscous_coarse_create())) {
        free(V);
        return NULL;
    }
    return V;
}

void viscous_free(struct viscous_solver *V)
{
    if (!V) return;
    for (int k = 0; k < N_VEC; k++) free(V->v[k]);
    free(V->mobile);
    free(V->partial);
    viscous_coarse_free(V->coarse);
    free(V);
}

static int reserve(struct viscous_solver *V, size_t n)
{
    const size_t nb = (n + VISCOUS_BLOCK - 1) / VISCOUS_BLOCK + 1;
    if (V->cap_blocks < nb) {
        double *q = realloc(V->partial, N_SUMS * nb * sizeof(double));
        if (!q) return -1;
        V->partial = q;
        V->cap_blocks = nb;
    }
    if (V->cap >= n + FORCES_PAD) return 0;
    const size_t cap = n + n / 4 + 64;
    for (int k = 0; k < N_VEC; k++) {
        double *q = realloc(V->v[k], cap * sizeof(double));
        if (!q) return -1;
        /* the operator's chunked pair loops read (with zero weights) a few rows past the active
         * ones: those must hold finite numbers, or 0 * NaN poisons a row's sum */
        memset(q, 0, cap * sizeof(double));
        V->v[k] = q;
    }
    unsigned char *m = realloc(V->mobile, cap);
    if (!m) return -1;
    V->mobile = m;
    V->cap = cap;
    return 0;
}

/* Sum the per-block partial sums in block order. */
static void block_sums(const struct viscous_solver *V, long nb, double s[N_SUMS])
{
    for (int k = 0; k < N_SUMS; k++) s[k] = 0.0;
    for (long bk = 0; bk < nb; bk++)
        for (int k = 0; k < N_SUMS; k++) s[k] += V->partial[N_SUMS * bk + k];
}

/* A block's partial sums (N_SUMS of them) into V->partial. */
static void put_partial(struct viscous_solver *V, long bk, double t0, double t1, double t2, double t3, double t4,
                        double t5)
{
    double *part = V->partial + N_SUMS * bk;
    part[0] = t0;
    part[1] = t1;
    part[2] = t2;
    part[3] = t3;
    part[4] = t4;
    part[5] = t5;
}

#define BLOCKS(n) ((long)(((n) + VISCOUS_BLOCK - 1) / VISCOUS_BLOCK))
#define BLOCK_RANGE(bk, n, i0, i1)                                   \
    const size_t i0 = (size_t)(bk) * VISCOUS_BLOCK;                  \
    const size_t i1 = i0 + VISCOUS_BLOCK < (n) ? i0 + VISCOUS_BLOCK : (n)

/* The operands of a solve that every pass needs. */
struct solve_ctx {
    struct viscous_solver *V;
    const struct forces *F;
    const struct pair_system *S;
    const struct wall_mirror *M; /* NULL: the wall rows keep P->uvx, P->uvz */
    double dt;                   /* the stage's kappa */
    size_t n;
    const unsigned char *unknown; /* per particle: its velocity is solved for (else prescribed); NULL:
                                   * every mobile and held particle (viscous_solve) */
};

/* The arguments of a parallel loop of this file (core/team.h): rows or blocks of rows. */
struct vloop {
    const struct solve_ctx *c;
    int with_constant;
    int in, out, dot, dot2; /* vector indices */
    int count;
    const int *a, *b;
    double k0, k1, k2, k3;  /* the loop's coefficients */
    double *vx, *vz;
    int flag;               /* | over the threads */
};

static void wall_rows_range(void *arg, size_t b, size_t e)
{
    const struct vloop *L = arg;
    const struct particles *P = L->c->S->P;
    const int with_constant = L->with_constant;
    double *vx = L->vx, *vz = L->vz;
    for (size_t i = b; i < e; i++)
        if (P->state[i] == MIXSPH_STATE_WALL) {
            vx[i] = with_constant ? P->uvx[i] : 0.0;
            vz[i] = with_constant ? P->uvz[i] : 0.0;
        }
}

/* Fill the wall rows of (vx, vz) from their unknown rows (with_constant: the whole mirror map,
 * else its linear part); without a mirror they are P->uvx, P->uvz (with_constant) or 0. */
static void fill_wall_rows(const struct solve_ctx *c, int with_constant, double *vx, double *vz)
{
    if (c->M) {
        walls_mirror_apply(c->M, c->S->G, with_constant, vx, vz, c->S->n_threads);
        return;
    }
    struct vloop L = {.c = c, .with_constant = with_constant, .vx = vx, .vz = vz};
    team_for(c->S->n_threads, c->n, wall_rows_range, &L);
}

/* out = A in on the unknown rows (0 on the others); `in` is zero on the prescribed non-wall rows
 * and gets its wall rows filled (the linear part of the mirror). With dot >= 0, d receives the
 * per-component products (v[dot] . out) and, with dot2 >= 0, (v[dot2] . out) too (d[2], d[3])
 * and (out . out) (d[4], d[5]), summed in fixed blocks. */
static void apply_a_blocks(void *arg, size_t b0, size_t b1);
static int apply_a(const struct solve_ctx *c, int in, int out, int dot, int dot2, double d[N_SUMS])
{
    double **v = c->V->v;
    fill_wall_rows(c, 0, v[in], v[in + 1]);
    if (forces_viscous_apply(c->F, c->S, (const double *const *)&v[in], &v[out], NULL) != 0) return -1;
    const long nb = BLOCKS(c->n);
    struct vloop L = {.c = c, .in = in, .out = out, .dot = dot, .dot2 = dot2};
    team_for(c->S->n_threads, (size_t)nb, apply_a_blocks, &L);
    block_sums(c->V, nb, d);
    return 0;
}

/* Blocks [b0, b1) of apply_a after the operator pass. */
static void apply_a_blocks(void *arg, size_t b0, size_t b1)
{
    const struct vloop *L = arg;
    const struct solve_ctx *c = L->c;
    double **v = c->V->v;
    const int in = L->in, out = L->out, dot = L->dot, dot2 = L->dot2;
    const unsigned char *mob = c->V->mobile;
    const double kappa = c->dt;
    const double *ox = v[out], *oz = v[out + 1];
    const double *ax = v[dot < 0 ? out : dot], *az = v[dot < 0 ? out + 1 : dot + 1];
    const double *bx = v[dot2 < 0 ? out : dot2], *bz = v[dot2 < 0 ? out + 1 : dot2 + 1];
    for (size_t bk = b0; bk < b1; bk++) {
        BLOCK_RANGE(bk, c->n, i0, i1);
        { /* restrict only here: the dot operands below may be `out` itself */
            double *restrict wx = v[out], *restrict wz = v[out + 1];
            const double *restrict ix = v[in], *restrict iz = v[in + 1], *restrict mass = v[MASS];
            for (size_t i = i0; i < i1; i++) {
                const double keep = mob[i] ? 1.0 : 0.0;
                wx[i] = keep * (mass[i] * ix[i] + kappa * wx[i]);
                wz[i] = keep * (mass[i] * iz[i] + kappa * wz[i]);
            }
        }
        double t0 = 0.0, t1 = 0.0, t2 = 0.0, t3 = 0.0, t4 = 0.0, t5 = 0.0;
#pragma omp simd reduction(+ : t0, t1, t2, t3, t4, t5)
        for (size_t i = i0; i < i1; i++) {
            t0 += ax[i] * ox[i];
            t1 += az[i] * oz[i];
            t2 += bx[i] * ox[i];
            t3 += bz[i] * oz[i];
            t4 += ox[i] * ox[i];
            t5 += oz[i] * oz[i];
        }
        put_partial(c->V, (long)bk, t0, t1, t2, t3, t4, t5);
    }
}

/* Per-component dot products over the unknown rows, summed in fixed blocks: d[2k], d[2k+1] are
 * (a_k . b_k) for the x and z parts of the vector pairs (a[k], b[k]), k < count <= 3. */
static void dots_blocks(void *arg, size_t b0, size_t b1)
{
    const struct vloop *L = arg;
    const struct solve_ctx *c = L->c;
    double **v = c->V->v;
    const unsigned char *mob = c->V->mobile;
    const int count = L->count, *a = L->a, *b = L->b;
    for (size_t bk = b0; bk < b1; bk++) {
        BLOCK_RANGE(bk, c->n, i0, i1);
        double t[N_SUMS] = {0.0};
        for (int k = 0; k < count; k++) {
            const double *ax = v[a[k]], *az = v[a[k] + 1], *bx = v[b[k]], *bz = v[b[k] + 1];
            double sx = 0.0, sz = 0.0;
#pragma omp simd reduction(+ : sx, sz)
            for (size_t i = i0; i < i1; i++) {
                const double keep = mob[i] ? 1.0 : 0.0;
                sx += keep * ax[i] * bx[i];
                sz += keep * az[i] * bz[i];
            }
            t[2 * k] = sx;
            t[2 * k + 1] = sz;
        }
        for (int k = 0; k < N_SUMS; k++) c->V->partial[N_SUMS * bk + k] = t[k];
    }
}

static void dots(const struct solve_ctx *c, int count, const int *a, const int *b, double *d)
{
    const long nb = BLOCKS(c->n);
    struct vloop L = {.c = c, .count = count, .a = a, .b = b};
    team_for(c->S->n_threads, (size_t)nb, dots_blocks, &L);
    double s[N_SUMS];
    block_sums(c->V, nb, s);
    for (int k = 0; k < 2 * count; k++) d[k] = s[k];
}

/* For (m + kappa L) u = m w - kappa L u_B (kappa = c->dt, w = v[WX], v[WZ] on the unknown rows):
 * the right-hand side b, the preconditioner 1 / (m + kappa diag L), the first guess
 * u0 = v[GX], v[GZ] and its residual r0 = b - A u0 = m (w - u0) - kappa L u_full (u_full: u0 on
 * the unknown rows, the prescribed values and the walls' mirror of u_full elsewhere). Two passes
 * of the operator, one when u_B = 0. */
static void setup_first_range(void *arg, size_t b, size_t e)
{
    const struct solve_ctx *c = ((const struct vloop *)arg)->c;
    const struct particles *P = c->S->P;
    double **v = c->V->v;
    unsigned char *mob = c->V->mobile;
    for (size_t i = b; i < e; i++) {
        /* the caller says which velocities are unknowns (the rest, walls aside, stay as they are) */
        mob[i] = c->unknown ? c->unknown[i] : P->state[i] <= MIXSPH_STATE_FIXED;
        v[MASS][i] = P->m[i];
        v[U0X][i] = mob[i] ? 0.0 : P->vx[i];
        v[U0Z][i] = mob[i] ? 0.0 : P->vz[i];
        v[UX][i] = mob[i] ? v[GX][i] : v[U0X][i];
        v[UZ][i] = mob[i] ? v[GZ][i] : v[U0Z][i];
    }
}

static void prescribed_moving_range(void *arg, size_t b, size_t e)
{
    struct vloop *L = arg;
    double **v = L->c->V->v;
    int moving = 0;
    for (size_t i = b; i < e; i++) moving |= v[U0X][i] != 0.0 || v[U0Z][i] != 0.0;
    team_or_int(&L->flag, moving);
}

static void setup_last_range(void *arg, size_t b, size_t e)
{
    const struct solve_ctx *c = ((const struct vloop *)arg)->c;
    const struct particles *P = c->S->P;
    double **v = c->V->v;
    const unsigned char *mob = c->V->mobile;
    const double dt = c->dt;
    for (size_t i = b; i < e; i++) {
        if (!mob[i]) {
            for (int k = UX; k <= MINV; k++)
                if (k != U0X && k != U0Z) v[k][i] = 0.0;
            continue;
        }
        const double m = P->m[i];
        v[BX][i] = m * v[WX][i] - dt * v[BX][i];
        v[BZ][i] = m * v[WZ][i] - dt * v[BZ][i];
        v[MINV][i] = 1.0 / (m + dt * v[MINV][i]);
        v[RX][i] = v[RHX][i] = m * (v[WX][i] - v[UX][i]) - dt * v[RX][i];
        v[RZ][i] = v[RHZ][i] = m * (v[WZ][i] - v[UZ][i]) - dt * v[RZ][i];
        v[PX][i] = v[PZ][i] = v[VX][i] = v[VZ][i] = 0.0;
    }
}

static int setup(const struct solve_ctx *c)
{
    double **v = c->V->v;
    struct vloop L = {.c = c};
    team_for(c->S->n_threads, c->n, setup_first_range, &L);
    fill_wall_rows(c, 1, v[U0X], v[U0Z]);
    fill_wall_rows(c, 1, v[UX], v[UZ]);
    /* L u_B is zero when nothing prescribed moves (walls at rest, grains held fixed): one
     * operator pass fewer per stage */
    team_for(c->S->n_threads, c->n, prescribed_moving_range, &L);
    if (L.flag) {
        if (forces_viscous_apply(c->F, c->S, (const double *const *)&v[U0X], &v[BX], NULL) != 0) return -1;
    } else {
        memset(v[BX], 0, c->n * sizeof(double));
        memset(v[BZ], 0, c->n * sizeof(double));
    }
    if (forces_viscous_apply(c->F, c->S, (const double *const *)&v[UX], &v[RX], v[MINV]) != 0) return -1;
    team_for(c->S->n_threads, c->n, setup_last_range, &L);
    return 0;
}

/* v[out] += the coarse correction of v[in] (two_level; both components). */
static void coarse_correct(const struct solve_ctx *c, int in, int out)
{
    struct viscous_solver *V = c->V;
    if (V->preconditioner != VISCOUS_TWO_LEVEL) return;
    viscous_coarse_correct(V->coarse, V->mobile, V->v[in], V->v[in + 1], V->v[out], V->v[out + 1], c->S->n_threads);
}

static double ratio(double a, double b) { return b != 0.0 ? a / b : 0.0; }

/* BiCGSTAB's vector passes over rows [b, e) or blocks [b0, b1) (struct vloop: k0, k1 its
 * coefficients for the x and z components, k2, k3 the second ones). */
static void direction_range(void *arg, size_t b, size_t e)
{
    /* p = r + beta (p - omega v), y = M^-1 p; k0, k1 = beta, k2, k3 = omega */
    const struct vloop *L = arg;
    double **v = L->c->V->v;
    double *restrict px = v[PX], *restrict pz = v[PZ], *restrict yx = v[YX], *restrict yz = v[YZ];
    const double *restrict rx = v[RX], *restrict rz = v[RZ], *restrict vx = v[VX], *restrict vz = v[VZ];
    const double *restrict minv = v[MINV];
    const double b0 = L->k0, b1 = L->k1, w0 = L->k2, w1 = L->k3;
#pragma omp simd
    for (size_t i = b; i < e; i++) {
        px[i] = rx[i] + b0 * (px[i] - w0 * vx[i]);
        pz[i] = rz[i] + b1 * (pz[i] - w1 * vz[i]);
        yx[i] = minv[i] * px[i];
        yz[i] = minv[i] * pz[i];
    }
}

static void half_step_blocks(void *arg, size_t b0, size_t b1)
{
    /* u += alpha y, s = r - alpha v, z = M^-1 s, (s, s); k0, k1 = alpha */
    const struct vloop *L = arg;
    const size_t n = L->c->n;
    double **v = L->c->V->v;
    double *restrict ux = v[UX], *restrict uz = v[UZ], *restrict sx = v[SX], *restrict sz = v[SZ];
    double *restrict zx = v[ZX], *restrict zz = v[ZZ];
    const double *restrict yx = v[YX], *restrict yz = v[YZ], *restrict rx = v[RX], *restrict rz = v[RZ];
    const double *restrict vx = v[VX], *restrict vz = v[VZ], *restrict minv = v[MINV];
    const double a0 = L->k0, a1 = L->k1;
    for (size_t bk = b0; bk < b1; bk++) {
        BLOCK_RANGE(bk, n, i0, i1);
        double t0 = 0.0, t1 = 0.0;
#pragma omp simd reduction(+ : t0, t1)
        for (size_t i = i0; i < i1; i++) {
            ux[i] += a0 * yx[i];
            uz[i] += a1 * yz[i];
            sx[i] = rx[i] - a0 * vx[i];
            sz[i] = rz[i] - a1 * vz[i];
            zx[i] = minv[i] * sx[i];
            zz[i] = minv[i] * sz[i];
            t0 += sx[i] * sx[i];
            t1 += sz[i] * sz[i];
        }
        put_partial(L->c->V, (long)bk, t0, t1, 0.0, 0.0, 0.0, 0.0);
    }
}

static void full_step_blocks(void *arg, size_t b0, size_t b1)
{
    /* u += omega z, r = s - omega t, (r, r), (r^, r); k0, k1 = omega */
    const struct vloop *L = arg;
    const size_t n = L->c->n;
    double **v = L->c->V->v;
    double *restrict ux = v[UX], *restrict uz = v[UZ], *restrict rx = v[RX], *restrict rz = v[RZ];
    const double *restrict zx = v[ZX], *restrict zz = v[ZZ], *restrict sx = v[SX], *restrict sz = v[SZ];
    const double *restrict tx = v[TX], *restrict tz = v[TZ], *restrict hx = v[RHX], *restrict hz = v[RHZ];
    const double w0 = L->k0, w1 = L->k1;
    for (size_t bk = b0; bk < b1; bk++) {
        BLOCK_RANGE(bk, n, i0, i1);
        double t0 = 0.0, t1 = 0.0, t2 = 0.0, t3 = 0.0;
#pragma omp simd reduction(+ : t0, t1, t2, t3)
        for (size_t i = i0; i < i1; i++) {
            ux[i] += w0 * zx[i];
            uz[i] += w1 * zz[i];
            rx[i] = sx[i] - w0 * tx[i];
            rz[i] = sz[i] - w1 * tz[i];
            t0 += rx[i] * rx[i];
            t1 += rz[i] * rz[i];
            t2 += hx[i] * rx[i];
            t3 += hz[i] * rz[i];
        }
        put_partial(L->c->V, (long)bk, t0, t1, t2, t3, 0.0, 0.0);
    }
}

/* BiCGSTAB from the set-up's u0, r0 (= r^_0), right-preconditioned by M^-1; per iteration two
 * operator passes and three vector passes, each with its dot products. Returns the iterations,
 * -1 when out of memory; *r2 receives the final ||r||^2. */
static int bicgstab(const struct solve_ctx *c, double tol2, int max_iterations, double *r2)
{
    const size_t n = c->n;
    const long nb = BLOCKS(n);
    double d[N_SUMS];
    const int rr[2] = {RX, RHX};
    dots(c, 2, rr, rr + 0, d); /* (r, r), (r^, r) with r^ = r */
    *r2 = d[0] + d[1];
    double rho_new[2] = {d[0], d[1]};
    double rho[2] = {1.0, 1.0}, alpha[2] = {1.0, 1.0}, omega[2] = {1.0, 1.0};
    int it = 0;
    while (*r2 > tol2 && it < max_iterations) {
        double beta[2];
        for (int k = 0; k < 2; k++) {
            beta[k] = ratio(rho_new[k], rho[k]) * ratio(alpha[k], omega[k]);
            rho[k] = rho_new[k];
        }
        /* p = r + beta (p - omega v), y = M^-1 p */
        {
            struct vloop L = {.c = c, .k0 = beta[0], .k1 = beta[1], .k2 = omega[0], .k3 = omega[1]};
            team_for(c->S->n_threads, n, direction_range, &L);
        }
        coarse_correct(c, PX, YX);
        if (apply_a(c, YX, VX, RHX, -1, d) != 0) return -1; /* v = A y, (r^, v) */
        for (int k = 0; k < 2; k++) alpha[k] = ratio(rho[k], d[k]);
        /* u += alpha y, s = r - alpha v, z = M^-1 s, (s, s) */
        {
            struct vloop L = {.c = c, .k0 = alpha[0], .k1 = alpha[1]};
            team_for(c->S->n_threads, (size_t)nb, half_step_blocks, &L);
        }
        block_sums(c->V, nb, d);
        it++;
        if (!(d[0] + d[1] > tol2)) { /* converged at the half step */
            *r2 = d[0] + d[1];
            break;
        }
        coarse_correct(c, SX, ZX);
        if (apply_a(c, ZX, TX, SX, -1, d) != 0) return -1; /* t = A z, (s, t), (t, t) */
        omega[0] = ratio(d[0], d[4]);
        omega[1] = ratio(d[1], d[5]);
        /* u += omega z, r = s - omega t, (r, r), (r^, r) */
        {
            struct vloop L = {.c = c, .k0 = omega[0], .k1 = omega[1]};
            team_for(c->S->n_threads, (size_t)nb, full_step_blocks, &L);
        }
        block_sums(c->V, nb, d);
        *r2 = d[0] + d[1];
        rho_new[0] = d[2];
        rho_new[1] = d[3];
    }
    return it;
}

/* One stage: (m + kappa L) u = m w - kappa L u_B from the guess v[GX], v[GZ], w in v[WX], v[WZ];
 * the solution in v[UX], v[UZ] (unknown rows). Returns -1 when out of memory. */
static int stage(const struct solve_ctx *c, double tolerance, int max_iterations, struct viscous_report *report)
{
    if (setup(c) != 0) return -1;
    struct viscous_solver *V = c->V;
    if (V->preconditioner == VISCOUS_TWO_LEVEL) {
        /* the groups and couplings hold for the step; the coarse operator depends on kappa */
        if (!V->coarse_built && viscous_coarse_build(V->coarse, c->F, c->S, V->mobile, c->n) != 0) return -1;
        V->coarse_built = 1;
        viscous_coarse_operator(V->coarse, V->v[MINV], V->mobile, c->dt, c->S->n_threads);
    }
    double **v = c->V->v;
    double d[6];
    const int bb[1] = {BX};
    dots(c, 1, bb, bb, d);
    const double b2 = d[0] + d[1];
    double r2 = 0.0;
    int it = 0;
    if (b2 == 0.0) { /* no force and nothing moving: the solution is at rest */
        for (size_t i = 0; i < c->n; i++) v[UX][i] = v[UZ][i] = 0.0;
    } else {
        it = bicgstab(c, tolerance * tolerance * b2, max_iterations, &r2);
        if (it < 0) return -1;
    }
    const double residual = b2 > 0.0 ? sqrt(r2 / b2) : sqrt(r2);
    report->iterations += it;
    /* fmax would drop a NaN, and the failure message would then read "residual 0" */
    report->residual = isnan(residual) ? residual : fmax(report->residual, residual);
    report->converged = report->converged && r2 <= tolerance * tolerance * b2;
    return 0;
}

/* The solution into the particles: velocities, the increment over u* (v[USX]) for the next warm
 * start, and the walls' viscous velocity that goes with it. */
static void store_range(void *arg, size_t b, size_t e)
{
    const struct solve_ctx *c = ((const struct vloop *)arg)->c;
    struct particles *P = c->S->P;
    double **v = c->V->v;
    const unsigned char *mob = c->V->mobile;
    for (size_t i = b; i < e; i++) {
        if (mob[i]) {
            P->visc_dvx[i] = v[UX][i] - v[USX][i];
            P->visc_dvz[i] = v[UZ][i] - v[USZ][i];
            P->vx[i] = v[UX][i];
            P->vz[i] = v[UZ][i];
        } else {
            v[UX][i] = P->state[i] == MIXSPH_STATE_WALL ? 0.0 : P->vx[i];
            v[UZ][i] = P->state[i] == MIXSPH_STATE_WALL ? 0.0 : P->vz[i];
        }
    }
}

static void store_walls_range(void *arg, size_t b, size_t e)
{
    const struct solve_ctx *c = ((const struct vloop *)arg)->c;
    struct particles *P = c->S->P;
    double **v = c->V->v;
    for (size_t i = b; i < e; i++)
        if (P->state[i] == MIXSPH_STATE_WALL) {
            P->uvx[i] = v[UX][i];
            P->uvz[i] = v[UZ][i];
        }
}

static void store(const struct solve_ctx *c)
{
    struct vloop L = {.c = c};
    team_for(c->S->n_threads, c->n, store_range, &L);
    if (!c->M) return;
    fill_wall_rows(c, 1, c->V->v[UX], c->V->v[UZ]);
    team_for(c->S->n_threads, c->n, store_walls_range, &L);
}

/* u* = P->vx, P->vz into v[USX], v[USZ] (all rows). */
static void load_velocities(const struct solve_ctx *c)
{
    const struct particles *P = c->S->P;
    double **v = c->V->v;
    memcpy(v[USX], P->vx, c->n * sizeof(double));
    memcpy(v[USZ], P->vz, c->n * sizeof(double));
}

int viscous_solve(struct viscous_solver *V, const struct forces *F, const struct pair_system *S,
                  const struct wall_mirror *M, double dt, int preconditioner, double tolerance, int max_iterations,
                  struct viscous_report *report)
{
    const size_t n = S->C->start[S->C->ncell];
    *report = (struct viscous_report){.converged = 1};
    if (reserve(V, n) != 0) return -1;
    V->preconditioner = preconditioner;
    V->coarse_built = 0;
    const struct solve_ctx c = {.V = V, .F = F, .S = S, .M = M, .dt = dt, .n = n};
    const struct particles *P = S->P;
    double **v = V->v;
    load_velocities(&c);
    for (size_t i = 0; i < n; i++) {
        v[WX][i] = P->vx[i];
        v[WZ][i] = P->vz[i];
        v[GX][i] = P->vx[i] + P->visc_dvx[i];
        v[GZ][i] = P->vz[i] + P->visc_dvz[i];
    }
    if (stage(&c, tolerance, max_iterations, report) != 0) return -1;
    store(&c);
    return 0;
}

/* The two-stage, stiffly accurate SDIRK of Alexander (1977) with gamma = 1 + 1/sqrt 2:
 *   (m + gamma dt L) U1 = m u*,                                 walls at t + gamma dt,
 *   (m + gamma dt L) U2 = m (u* + (1 - gamma)/gamma (U1 - u*)),  walls at t + dt,   u = U2.
 * Second order and L-stable like TR-BDF2, and its amplification (1 + (2 gamma - 1) z) /
 * (1 + gamma z)^2 of a mode with z = dt lambda stays positive for every z >= 0. That matters
 * here: the drift uses the viscous step's result (symplectic Euler), and a factor D < 0 makes
 * kick-drift-with-damping unstable for any pressure stiffness (its trace-determinant condition
 * 1 + D > |1 + D - D omega^2 dt^2| fails), as TR-BDF2 (gamma = 2 - sqrt 2, D -> -0.2 at
 * z = 10) and the other root gamma = 1 - 1/sqrt 2 of this scheme (D < 0 for z > 2.4) do: the
 * lid-driven closed channel grew without bound with either from t = 0.03 s. */
#define SDIRK_GAMMA 1.7071067811865475 /* 1 + 1/sqrt 2 */

int viscous_solution_operator(struct viscous_solver *V, const struct forces *F, const struct pair_system *S,
                              const double *lu[DIM])
{
    double **v = V->v;
    if (forces_viscous_apply(F, S, (const double *const *)&v[UX], &v[RX], NULL) != 0) return -1;
    for (int d = 0; d < DIM; d++) lu[d] = v[RX + d];
    return 0;
}

static void stage1_guess_range(void *arg, size_t b, size_t e);
static void stage2_guess_range(void *arg, size_t b, size_t e);

int viscous_step(struct viscous_solver *V, const struct forces *F, const struct pair_system *S,
                 struct wall_mirror *M, const struct walls *W, double t, double dt,
                 const unsigned char *unknown, const struct viscous_params *vp, struct viscous_report *report)
{
    const size_t n = S->C->start[S->C->ncell];
    *report = (struct viscous_report){.converged = 1};
    if (reserve(V, n) != 0) return -1;
    V->preconditioner = vp->preconditioner;
    V->coarse_built = 0;
    const double g = SDIRK_GAMMA;
    const double tolerance = vp->tolerance;
    const int max_iterations = vp->max_iterations;
    const struct solve_ctx c = {.V = V, .F = F, .S = S, .M = M, .dt = g * dt, .n = n, .unknown = unknown};
    const struct particles *P = S->P;
    const int threads = S->n_threads;
    if (walls_mirror_build(M, W, &S->params.K, S->G, P, n, threads) != 0) return -1;
    load_velocities(&c);
    /* stage 1: w = u*, first guess u* + the first-stage increment extrapolated linearly from
     * the last two steps (closer than the last increment alone where the flow changes smoothly;
     * measured in docs/numerics.md) */
    struct vloop L = {.c = &c, .k0 = (1.0 - g) / g};
    team_for(threads, n, stage1_guess_range, &L);
    walls_mirror_at(M, W, P, t, g * dt, threads);
    if (stage(&c, tolerance, max_iterations, report) != 0) return -1;
    /* stage 2: w = u* + (1 - gamma)/gamma (U1 - u*), first guess U1 + the second stage's own
     * change (U2 - U1 = dv - d1) extrapolated linearly from the last two steps; the increments
     * of the last step become those of the step before */
    team_for(threads, n, stage2_guess_range, &L);
    walls_mirror_at(M, W, P, t, dt, threads);
    if (stage(&c, tolerance, max_iterations, report) != 0) return -1;
    store(&c);
    return 0;
}

static void stage1_guess_range(void *arg, size_t b, size_t e)
{
    const struct solve_ctx *c = ((const struct vloop *)arg)->c;
    const struct particles *P = c->S->P;
    double **v = c->V->v;
    for (size_t i = b; i < e; i++) {
        v[WX][i] = v[USX][i];
        v[WZ][i] = v[USZ][i];
        v[GX][i] = v[USX][i] + 2.0 * P->visc_d1x[i] - P->visc_d1px[i];
        v[GZ][i] = v[USZ][i] + 2.0 * P->visc_d1z[i] - P->visc_d1pz[i];
    }
}

/* k0 = (1 - gamma) / gamma */
static void stage2_guess_range(void *arg, size_t b, size_t e)
{
    const struct vloop *L = arg;
    const struct solve_ctx *c = L->c;
    struct viscous_solver *V = c->V;
    const struct particles *P = c->S->P;
    struct particles *Pw = c->S->P;
    double **v = V->v;
    const double a = L->k0;
    for (size_t i = b; i < e; i++) {
        v[WX][i] = v[USX][i] + a * (v[UX][i] - v[USX][i]);
        v[WZ][i] = v[USZ][i] + a * (v[UZ][i] - v[USZ][i]);
        v[GX][i] = v[UX][i] + 2.0 * (P->visc_dvx[i] - P->visc_d1x[i]) - (P->visc_dvpx[i] - P->visc_d1px[i]);
        v[GZ][i] = v[UZ][i] + 2.0 * (P->visc_dvz[i] - P->visc_d1z[i]) - (P->visc_dvpz[i] - P->visc_d1pz[i]);
        if (V->mobile[i]) {
            Pw->visc_dvpx[i] = P->visc_dvx[i];
            Pw->visc_dvpz[i] = P->visc_dvz[i];
            Pw->visc_d1px[i] = P->visc_d1x[i];
            Pw->visc_d1pz[i] = P->visc_d1z[i];
            Pw->visc_d1x[i] = v[UX][i] - v[USX][i];
            Pw->visc_d1z[i] = v[UZ][i] - v[USZ][i];
        }
    }
}
