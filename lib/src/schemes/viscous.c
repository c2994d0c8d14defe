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
 * velocity components share A and are iterated together, each with its own scalars (and its own
 * loops over the rows: each component's dot products are summed as one vectorised reduction);
 * the solve stops when sum_d ||r_d||^2 <= tol^2 sum_d ||b_d||^2. */
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
#define N_SUMS (3 * DIM) /* partial sums per block: up to three per component */

/* The solver's vectors, per active particle; a vector field takes DIM slots (component d of
 * field F is v[F + d]), a scalar field one:
 *   U   the iterate u (unknown rows; junk on the others until the end)
 *   U0  the prescribed field u_B during the set-up, then u* (for the increment)
 *   R   the residual b - A u          RH  the shadow residual r^_0
 *   PD  the search direction p        Y   M^-1 p        AY  A y
 *   S   the intermediate residual     Z   M^-1 s        T   A z
 *   B   the right-hand side b         MINV  the inverse of the Jacobi diagonal   MASS  m
 *   W   a stage's velocity w          G   its first guess
 *   US  u* (the velocity before the step) */
enum {
    VEC_U = 0, VEC_U0 = VEC_U + DIM, VEC_R = VEC_U0 + DIM, VEC_RH = VEC_R + DIM, VEC_PD = VEC_RH + DIM,
    VEC_Y = VEC_PD + DIM, VEC_AY = VEC_Y + DIM, VEC_S = VEC_AY + DIM, VEC_Z = VEC_S + DIM, VEC_T = VEC_Z + DIM,
    VEC_B = VEC_T + DIM, VEC_MINV = VEC_B + DIM, VEC_MASS = VEC_MINV + 1, VEC_W = VEC_MASS + 1, VEC_G = VEC_W + DIM,
    VEC_US = VEC_G + DIM, N_VEC = VEC_US + DIM
};

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

#define BLOCKS(n) ((long)(((n) + VISCOUS_BLOCK - 1) / VISCOUS_BLOCK))
#define BLOCK_RANGE(bk, n, i0, i1)                                   \
    const size_t i0 = (size_t)(bk) * VISCOUS_BLOCK;                  \
    const size_t i1 = i0 + VISCOUS_BLOCK < (n) ? i0 + VISCOUS_BLOCK : (n)

/* The operands of a solve that every pass needs. */
struct solve_ctx {
    struct viscous_solver *V;
    const struct forces *F;
    const struct pair_system *S;
    const struct wall_mirror *M; /* NULL: the wall rows keep P->uv */
    double dt;                   /* the stage's kappa */
    size_t n;
    const unsigned char *unknown; /* per particle: its velocity is solved for (else prescribed); NULL:
                                   * every mobile and held particle (viscous_solve) */
};

/* The parallel loops of this file (core/team.h) over rows or blocks of rows; a loop that needs
 * no more than the solve's operands takes the struct solve_ctx itself. */

/* The wall rows of the vector field at slot `vec`: the walls' velocity or 0. */
struct wall_rows_loop {
    const struct solve_ctx *c;
    int vec;           /* first slot of the field */
    int with_constant; /* the walls' own velocity (else 0) */
};

static void wall_rows_range(void *arg, size_t b, size_t e)
{
    const struct wall_rows_loop *L = arg;
    const struct particles *P = L->c->S->P;
    double **v = L->c->V->v;
    for (size_t i = b; i < e; i++)
        if (P->state[i] == MIXSPH_STATE_WALL)
            for (int d = 0; d < DIM; d++) v[L->vec + d][i] = L->with_constant ? P->uv[d][i] : 0.0;
}

/* Fill the wall rows of the field at slot `vec` from their unknown rows (with_constant: the whole
 * mirror map, else its linear part); without a mirror they are P->uv (with_constant) or 0. */
static void fill_wall_rows(const struct solve_ctx *c, int with_constant, int vec)
{
    double **v = c->V->v;
    if (c->M) {
        walls_mirror_fill(c->M, c->S->G, with_constant, &v[vec], c->S->n_threads);
        return;
    }
    struct wall_rows_loop L = {.c = c, .vec = vec, .with_constant = with_constant};
    team_for(c->S->n_threads, c->n, wall_rows_range, &L);
}

/* out = A in on the unknown rows (0 on the others) and its dot products (apply_a). */
struct apply_loop {
    const struct solve_ctx *c;
    int in, out;   /* slots of the fields */
    int dot, dot2; /* the fields dotted with out (-1: out itself) */
};

/* out = A in on the unknown rows (0 on the others); `in` is zero on the prescribed non-wall rows
 * and gets its wall rows filled (the linear part of the mirror). d receives per component d the
 * products (v[dot] . out) (d[d]; dot < 0: out itself), (v[dot2] . out) (d[DIM + d]) and
 * (out . out) (d[2 DIM + d]), summed in fixed blocks. */
static void apply_a_blocks(void *arg, size_t b0, size_t b1);
static int apply_a(const struct solve_ctx *c, int in, int out, int dot, int dot2, double d[N_SUMS])
{
    double **v = c->V->v;
    fill_wall_rows(c, 0, in);
    if (forces_viscous_apply(c->F, c->S, (const double *const *)&v[in], &v[out], NULL) != 0) return -1;
    const long nb = BLOCKS(c->n);
    struct apply_loop L = {.c = c, .in = in, .out = out, .dot = dot, .dot2 = dot2};
    team_for(c->S->n_threads, (size_t)nb, apply_a_blocks, &L);
    block_sums(c->V, nb, d);
    return 0;
}

static void apply_a_blocks(void *arg, size_t b0, size_t b1)
{
    const struct apply_loop *L = arg;
    const struct solve_ctx *c = L->c;
    double **v = c->V->v;
    const int in = L->in, out = L->out, dot = L->dot < 0 ? out : L->dot, dot2 = L->dot2 < 0 ? out : L->dot2;
    const unsigned char *mob = c->V->mobile;
    const double kappa = c->dt;
    for (size_t bk = b0; bk < b1; bk++) {
        BLOCK_RANGE(bk, c->n, i0, i1);
        double *part = c->V->partial + N_SUMS * bk;
        for (int d = 0; d < DIM; d++) {
            { /* restrict only here: the dot operands below may be `out` itself */
                double *restrict w = v[out + d];
                const double *restrict x = v[in + d], *restrict mass = v[VEC_MASS];
                for (size_t i = i0; i < i1; i++) {
                    const double keep = mob[i] ? 1.0 : 0.0;
                    w[i] = keep * (mass[i] * x[i] + kappa * w[i]);
                }
            }
            const double *o = v[out + d], *a = v[dot + d], *b = v[dot2 + d];
            double ta = 0.0, tb = 0.0, to = 0.0;
#pragma omp simd reduction(+ : ta, tb, to)
            for (size_t i = i0; i < i1; i++) {
                ta += a[i] * o[i];
                tb += b[i] * o[i];
                to += o[i] * o[i];
            }
            part[d] = ta;
            part[DIM + d] = tb;
            part[2 * DIM + d] = to;
        }
    }
}

/* Per-component dot products over the unknown rows, summed in fixed blocks: d[DIM k + c] is
 * (a_k . b_k) of component c of the fields at slots a[k], b[k], k < count <= 3. */
struct dots_loop {
    const struct solve_ctx *c;
    int count;
    const int *a, *b;
};

static void dots_blocks(void *arg, size_t b0, size_t b1)
{
    const struct dots_loop *L = arg;
    const struct solve_ctx *c = L->c;
    double **v = c->V->v;
    const unsigned char *mob = c->V->mobile;
    const int count = L->count, *a = L->a, *b = L->b;
    for (size_t bk = b0; bk < b1; bk++) {
        BLOCK_RANGE(bk, c->n, i0, i1);
        double t[N_SUMS] = {0.0};
        for (int k = 0; k < count; k++)
            for (int d = 0; d < DIM; d++) {
                const double *x = v[a[k] + d], *y = v[b[k] + d];
                double s = 0.0;
#pragma omp simd reduction(+ : s)
                for (size_t i = i0; i < i1; i++) {
                    const double keep = mob[i] ? 1.0 : 0.0;
                    s += keep * x[i] * y[i];
                }
                t[DIM * k + d] = s;
            }
        for (int k = 0; k < N_SUMS; k++) c->V->partial[N_SUMS * bk + k] = t[k];
    }
}

static void dots(const struct solve_ctx *c, int count, const int *a, const int *b, double *d)
{
    const long nb = BLOCKS(c->n);
    struct dots_loop L = {.c = c, .count = count, .a = a, .b = b};
    team_for(c->S->n_threads, (size_t)nb, dots_blocks, &L);
    double s[N_SUMS];
    block_sums(c->V, nb, s);
    for (int k = 0; k < DIM * count; k++) d[k] = s[k];
}

/* The sum over the components of a per-component sum (d[0 .. DIM)). */
static double component_total(const double *d)
{
    double t = 0.0;
    for (int k = 0; k < DIM; k++) t += d[k];
    return t;
}

/* For (m + kappa L) u = m w - kappa L u_B (kappa = c->dt, w = v[W] on the unknown rows):
 * the right-hand side b, the preconditioner 1 / (m + kappa diag L), the first guess
 * u0 = v[G] and its residual r0 = b - A u0 = m (w - u0) - kappa L u_full (u_full: u0 on
 * the unknown rows, the prescribed values and the walls' mirror of u_full elsewhere). Two passes
 * of the operator, one when u_B = 0. */
static void setup_first_range(void *arg, size_t b, size_t e)
{
    const struct solve_ctx *c = arg;
    const struct particles *P = c->S->P;
    double **v = c->V->v;
    unsigned char *mob = c->V->mobile;
    for (size_t i = b; i < e; i++) {
        /* the caller says which velocities are unknowns (the rest, walls aside, stay as they are) */
        mob[i] = c->unknown ? c->unknown[i] : P->state[i] <= MIXSPH_STATE_FIXED;
        v[VEC_MASS][i] = P->m[i];
        for (int d = 0; d < DIM; d++) {
            v[VEC_U0 + d][i] = mob[i] ? 0.0 : P->vel[d][i];
            v[VEC_U + d][i] = mob[i] ? v[VEC_G + d][i] : v[VEC_U0 + d][i];
        }
    }
}

/* Whether a prescribed velocity (v[U0]) is not zero. */
struct moving_loop {
    const struct solve_ctx *c;
    int moving; /* | over the threads */
};

static void prescribed_moving_range(void *arg, size_t b, size_t e)
{
    struct moving_loop *L = arg;
    double **v = L->c->V->v;
    int moving = 0;
    for (size_t i = b; i < e; i++)
        for (int d = 0; d < DIM; d++) moving |= v[VEC_U0 + d][i] != 0.0;
    team_or_int(&L->moving, moving);
}

static void setup_last_range(void *arg, size_t b, size_t e)
{
    const struct solve_ctx *c = arg;
    const struct particles *P = c->S->P;
    double **v = c->V->v;
    const unsigned char *mob = c->V->mobile;
    const double dt = c->dt;
    for (size_t i = b; i < e; i++) {
        if (!mob[i]) {
            for (int k = VEC_U; k <= VEC_MINV; k++)
                if (k < VEC_U0 || k >= VEC_U0 + DIM) v[k][i] = 0.0;
            continue;
        }
        const double m = P->m[i];
        for (int d = 0; d < DIM; d++) {
            v[VEC_B + d][i] = m * v[VEC_W + d][i] - dt * v[VEC_B + d][i];
            v[VEC_R + d][i] = v[VEC_RH + d][i] = m * (v[VEC_W + d][i] - v[VEC_U + d][i]) - dt * v[VEC_R + d][i];
            v[VEC_PD + d][i] = v[VEC_AY + d][i] = 0.0;
        }
        v[VEC_MINV][i] = 1.0 / (m + dt * v[VEC_MINV][i]);
    }
}

static int setup(const struct solve_ctx *c)
{
    double **v = c->V->v;
    team_for(c->S->n_threads, c->n, setup_first_range, (void *)c);
    fill_wall_rows(c, 1, VEC_U0);
    fill_wall_rows(c, 1, VEC_U);
    /* L u_B is zero when nothing prescribed moves (walls at rest, grains held fixed): one
     * operator pass fewer per stage */
    struct moving_loop L = {.c = c};
    team_for(c->S->n_threads, c->n, prescribed_moving_range, &L);
    if (L.moving) {
        if (forces_viscous_apply(c->F, c->S, (const double *const *)&v[VEC_U0], &v[VEC_B], NULL) != 0) return -1;
    } else {
        for (int d = 0; d < DIM; d++) memset(v[VEC_B + d], 0, c->n * sizeof(double));
    }
    if (forces_viscous_apply(c->F, c->S, (const double *const *)&v[VEC_U], &v[VEC_R], v[VEC_MINV]) != 0) return -1;
    team_for(c->S->n_threads, c->n, setup_last_range, (void *)c);
    return 0;
}

/* v[out] += the coarse correction of v[in] (two_level). */
static void coarse_correct(const struct solve_ctx *c, int in, int out)
{
    struct viscous_solver *V = c->V;
    if (V->preconditioner != VISCOUS_TWO_LEVEL) return;
    viscous_coarse_correct(V->coarse, V->mobile, (const double *const *)&V->v[in], &V->v[out], c->S->n_threads);
}

static double ratio(double a, double b) { return b != 0.0 ? a / b : 0.0; }

/* BiCGSTAB's vector passes over rows [b, e) or blocks [b0, b1), with their per-component
 * coefficients. */
struct direction_loop {
    const struct solve_ctx *c;
    double beta[DIM], omega[DIM];
};

static void direction_range(void *arg, size_t b, size_t e)
{
    /* p = r + beta (p - omega v), y = M^-1 p */
    const struct direction_loop *L = arg;
    double **v = L->c->V->v;
    const double *restrict minv = v[VEC_MINV];
    for (int d = 0; d < DIM; d++) {
        double *restrict p = v[VEC_PD + d], *restrict y = v[VEC_Y + d];
        const double *restrict r = v[VEC_R + d], *restrict ay = v[VEC_AY + d];
        const double beta = L->beta[d], omega = L->omega[d];
#pragma omp simd
        for (size_t i = b; i < e; i++) {
            p[i] = r[i] + beta * (p[i] - omega * ay[i]);
            y[i] = minv[i] * p[i];
        }
    }
}

/* The half step (coef: alpha) and the full step (coef: omega) of an iteration. */
struct step_loop {
    const struct solve_ctx *c;
    double coef[DIM];
};

static void half_step_blocks(void *arg, size_t b0, size_t b1)
{
    /* u += alpha y, s = r - alpha v, z = M^-1 s, (s, s) */
    const struct step_loop *L = arg;
    const size_t n = L->c->n;
    double **v = L->c->V->v;
    const double *restrict minv = v[VEC_MINV];
    for (size_t bk = b0; bk < b1; bk++) {
        BLOCK_RANGE(bk, n, i0, i1);
        double *part = L->c->V->partial + N_SUMS * bk;
        for (int k = 0; k < N_SUMS; k++) part[k] = 0.0;
        for (int d = 0; d < DIM; d++) {
            double *restrict u = v[VEC_U + d], *restrict s = v[VEC_S + d], *restrict z = v[VEC_Z + d];
            const double *restrict y = v[VEC_Y + d], *restrict r = v[VEC_R + d], *restrict ay = v[VEC_AY + d];
            const double alpha = L->coef[d];
            double t = 0.0;
#pragma omp simd reduction(+ : t)
            for (size_t i = i0; i < i1; i++) {
                u[i] += alpha * y[i];
                s[i] = r[i] - alpha * ay[i];
                z[i] = minv[i] * s[i];
                t += s[i] * s[i];
            }
            part[d] = t;
        }
    }
}

static void full_step_blocks(void *arg, size_t b0, size_t b1)
{
    /* u += omega z, r = s - omega t, (r, r), (r^, r) */
    const struct step_loop *L = arg;
    const size_t n = L->c->n;
    double **v = L->c->V->v;
    for (size_t bk = b0; bk < b1; bk++) {
        BLOCK_RANGE(bk, n, i0, i1);
        double *part = L->c->V->partial + N_SUMS * bk;
        for (int k = 0; k < N_SUMS; k++) part[k] = 0.0;
        for (int d = 0; d < DIM; d++) {
            double *restrict u = v[VEC_U + d], *restrict r = v[VEC_R + d];
            const double *restrict z = v[VEC_Z + d], *restrict s = v[VEC_S + d];
            const double *restrict t = v[VEC_T + d], *restrict h = v[VEC_RH + d];
            const double omega = L->coef[d];
            double rr = 0.0, hr = 0.0;
#pragma omp simd reduction(+ : rr, hr)
            for (size_t i = i0; i < i1; i++) {
                u[i] += omega * z[i];
                r[i] = s[i] - omega * t[i];
                rr += r[i] * r[i];
                hr += h[i] * r[i];
            }
            part[d] = rr;
            part[DIM + d] = hr;
        }
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
    const int rr[2] = {VEC_R, VEC_RH};
    dots(c, 2, rr, rr + 0, d); /* (r, r), (r^, r) with r^ = r */
    *r2 = component_total(d);
    double rho_new[DIM], rho[DIM], alpha[DIM], omega[DIM];
    for (int k = 0; k < DIM; k++) {
        rho_new[k] = d[k];
        rho[k] = alpha[k] = omega[k] = 1.0;
    }
    int it = 0;
    while (*r2 > tol2 && it < max_iterations) {
        /* p = r + beta (p - omega v), y = M^-1 p */
        struct direction_loop D = {.c = c};
        for (int k = 0; k < DIM; k++) {
            D.beta[k] = ratio(rho_new[k], rho[k]) * ratio(alpha[k], omega[k]);
            D.omega[k] = omega[k];
            rho[k] = rho_new[k];
        }
        team_for(c->S->n_threads, n, direction_range, &D);
        coarse_correct(c, VEC_PD, VEC_Y);
        if (apply_a(c, VEC_Y, VEC_AY, VEC_RH, -1, d) != 0) return -1; /* v = A y, (r^, v) */
        /* u += alpha y, s = r - alpha v, z = M^-1 s, (s, s) */
        struct step_loop H = {.c = c};
        for (int k = 0; k < DIM; k++) H.coef[k] = alpha[k] = ratio(rho[k], d[k]);
        team_for(c->S->n_threads, (size_t)nb, half_step_blocks, &H);
        block_sums(c->V, nb, d);
        it++;
        if (!(component_total(d) > tol2)) { /* converged at the half step */
            *r2 = component_total(d);
            break;
        }
        coarse_correct(c, VEC_S, VEC_Z);
        if (apply_a(c, VEC_Z, VEC_T, VEC_S, -1, d) != 0) return -1; /* t = A z, (s, t), (t, t) */
        /* u += omega z, r = s - omega t, (r, r), (r^, r) */
        struct step_loop Fs = {.c = c};
        for (int k = 0; k < DIM; k++) Fs.coef[k] = omega[k] = ratio(d[k], d[2 * DIM + k]);
        team_for(c->S->n_threads, (size_t)nb, full_step_blocks, &Fs);
        block_sums(c->V, nb, d);
        *r2 = component_total(d);
        for (int k = 0; k < DIM; k++) rho_new[k] = d[DIM + k];
    }
    return it;
}

/* One stage: (m + kappa L) u = m w - kappa L u_B from the guess v[G], w in v[W]; the solution in
 * v[U] (unknown rows). Returns -1 when out of memory. */
static int stage(const struct solve_ctx *c, double tolerance, int max_iterations, struct viscous_report *report)
{
    if (setup(c) != 0) return -1;
    struct viscous_solver *V = c->V;
    if (V->preconditioner == VISCOUS_TWO_LEVEL) {
        /* the groups and couplings hold for the step; the coarse operator depends on kappa */
        if (!V->coarse_built && viscous_coarse_build(V->coarse, c->F, c->S, V->mobile, c->n) != 0) return -1;
        V->coarse_built = 1;
        viscous_coarse_operator(V->coarse, V->v[VEC_MINV], V->mobile, c->dt, c->S->n_threads);
    }
    double **v = c->V->v;
    double d[N_SUMS];
    const int bb[1] = {VEC_B};
    dots(c, 1, bb, bb, d);
    const double b2 = component_total(d);
    double r2 = 0.0;
    int it = 0;
    if (b2 == 0.0) { /* no force and nothing moving: the solution is at rest */
        for (size_t i = 0; i < c->n; i++)
            for (int k = 0; k < DIM; k++) v[VEC_U + k][i] = 0.0;
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

/* The solution into the particles: velocities, the increment over u* (v[US]) for the next warm
 * start, and the walls' viscous velocity that goes with it. */
static void store_range(void *arg, size_t b, size_t e)
{
    const struct solve_ctx *c = arg;
    struct particles *P = c->S->P;
    double **v = c->V->v;
    const unsigned char *mob = c->V->mobile;
    for (size_t i = b; i < e; i++)
        for (int d = 0; d < DIM; d++)
            if (mob[i]) {
                P->visc_dv[d][i] = v[VEC_U + d][i] - v[VEC_US + d][i];
                P->vel[d][i] = v[VEC_U + d][i];
            } else {
                v[VEC_U + d][i] = P->state[i] == MIXSPH_STATE_WALL ? 0.0 : P->vel[d][i];
            }
}

static void store_walls_range(void *arg, size_t b, size_t e)
{
    const struct solve_ctx *c = arg;
    struct particles *P = c->S->P;
    double **v = c->V->v;
    for (size_t i = b; i < e; i++)
        if (P->state[i] == MIXSPH_STATE_WALL)
            for (int d = 0; d < DIM; d++) P->uv[d][i] = v[VEC_U + d][i];
}

static void store(const struct solve_ctx *c)
{
    team_for(c->S->n_threads, c->n, store_range, (void *)c);
    if (!c->M) return;
    fill_wall_rows(c, 1, VEC_U);
    team_for(c->S->n_threads, c->n, store_walls_range, (void *)c);
}

/* u* = P->vel into v[US] (all rows). */
static void load_velocities(const struct solve_ctx *c)
{
    const struct particles *P = c->S->P;
    double **v = c->V->v;
    for (int d = 0; d < DIM; d++) memcpy(v[VEC_US + d], P->vel[d], c->n * sizeof(double));
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
    for (size_t i = 0; i < n; i++)
        for (int d = 0; d < DIM; d++) {
            v[VEC_W + d][i] = P->vel[d][i];
            v[VEC_G + d][i] = P->vel[d][i] + P->visc_dv[d][i];
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
    if (forces_viscous_apply(F, S, (const double *const *)&v[VEC_U], &v[VEC_R], NULL) != 0) return -1;
    for (int d = 0; d < DIM; d++) lu[d] = v[VEC_R + d];
    return 0;
}

static void stage1_guess_range(void *arg, size_t b, size_t e);
static void stage2_guess_range(void *arg, size_t b, size_t e);

/* The second stage's velocity w = u* + w_factor (U1 - u*) and first guess. */
struct stage2_loop {
    const struct solve_ctx *c;
    double w_factor; /* (1 - gamma) / gamma */
};

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
    team_for(threads, n, stage1_guess_range, (void *)&c);
    walls_mirror_at(M, W, P, t, g * dt, threads);
    if (stage(&c, tolerance, max_iterations, report) != 0) return -1;
    /* stage 2: w = u* + (1 - gamma)/gamma (U1 - u*), first guess U1 + the second stage's own
     * change (U2 - U1 = dv - d1) extrapolated linearly from the last two steps; the increments
     * of the last step become those of the step before */
    struct stage2_loop L2 = {.c = &c, .w_factor = (1.0 - g) / g};
    team_for(threads, n, stage2_guess_range, &L2);
    walls_mirror_at(M, W, P, t, dt, threads);
    if (stage(&c, tolerance, max_iterations, report) != 0) return -1;
    store(&c);
    return 0;
}

static void stage1_guess_range(void *arg, size_t b, size_t e)
{
    const struct solve_ctx *c = arg;
    const struct particles *P = c->S->P;
    double **v = c->V->v;
    for (size_t i = b; i < e; i++)
        for (int d = 0; d < DIM; d++) {
            v[VEC_W + d][i] = v[VEC_US + d][i];
            v[VEC_G + d][i] = v[VEC_US + d][i] + 2.0 * P->visc_d1[d][i] - P->visc_d1p[d][i];
        }
}

static void stage2_guess_range(void *arg, size_t b, size_t e)
{
    const struct stage2_loop *L = arg;
    const struct solve_ctx *c = L->c;
    struct viscous_solver *V = c->V;
    const struct particles *P = c->S->P;
    struct particles *Pw = c->S->P;
    double **v = V->v;
    const double a = L->w_factor;
    for (size_t i = b; i < e; i++)
        for (int d = 0; d < DIM; d++) {
            v[VEC_W + d][i] = v[VEC_US + d][i] + a * (v[VEC_U + d][i] - v[VEC_US + d][i]);
            v[VEC_G + d][i] = v[VEC_U + d][i] + 2.0 * (P->visc_dv[d][i] - P->visc_d1[d][i]) -
                              (P->visc_dvp[d][i] - P->visc_d1p[d][i]);
            if (V->mobile[i]) {
                Pw->visc_dvp[d][i] = P->visc_dv[d][i];
                Pw->visc_d1p[d][i] = P->visc_d1[d][i];
                Pw->visc_d1[d][i] = v[VEC_U + d][i] - v[VEC_US + d][i];
            }
        }
}
