/* viscous_coarse.c - see viscous_coarse.h.
 *
 * Groups live on a grid of (groups per cell row + 2) x (cell rows + 2) entries, padded by one
 * empty group on every side so that a group's eight neighbours are always grid entries; the
 * groups holding unknowns are numbered 0 .. n_active - 1 ("compact"), and A_c is kept as each
 * compact group's eight neighbours with the weights -A_c(I, J) / A_c(I, I). */
#include "viscous_coarse.h"
#include "team.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Group width in search radii (kx cell columns each). One radius is the narrowest for which a
 * pair's two groups are neighbours on the grid; two radii were measured no better (fewer, coarser
 * groups remove less of the error: docs/numerics.md). */
#define COARSE_WIDTH_KX 1
/* Symmetric Gauss-Seidel sweeps approximating A_c^-1. Measured: a second sweep saves no wall
 * time (the iterations drop by less than the sweep costs). */
#define COARSE_SWEEPS 1
#define COARSE_NEIGHBOURS 8
#define COARSE_SLOTS 5 /* coupling sums per group (forces_viscous_group_couplings) */

struct viscous_coarse {
    long stride;              /* grid entries per row: groups per cell row + 2 */
    size_t size;              /* grid entries: stride * (cell rows + 2) */
    int32_t *group;           /* per particle: its group's grid entry, -1 if not an unknown */
    double *w;                /* per grid entry: COARSE_SLOTS sums of couplings */
    int32_t *compact;         /* per grid entry: its compact number, -1 without unknowns */
    size_t *entry;            /* per compact group: its grid entry */
    size_t *first, *last;     /* and its particle range [first, last) */
    int32_t *nb;              /* per compact group: COARSE_NEIGHBOURS compact neighbours (n_active: none) */
    double *nw;               /* and their weights -A_c(I, J) / A_c(I, I) */
    double *inv_diag;         /* 1 / A_c(I, I) */
    double *b[DIM], *e[DIM];  /* a restricted residual and its coarse correction (per component; n_active + 1) */
    size_t n_active, cap_size, cap_particles, cap_active;
};

struct viscous_coarse *viscous_coarse_create(void) { return calloc(1, sizeof(struct viscous_coarse)); }

void viscous_coarse_free(struct viscous_coarse *K)
{
    if (!K) return;
    void *arrays[] = {K->group, K->w, K->compact, K->entry, K->first, K->last, K->nb, K->nw, K->inv_diag};
    for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; k++) free(arrays[k]);
    for (int d = 0; d < DIM; d++) {
        free(K->b[d]);
        free(K->e[d]);
    }
    free(K);
}

#if DIM == 2 /* the coarse level is written for a 2D grid (viscous_coarse_build) */

/* Resize *p to n elements of `size` bytes. */
static int grow(void **p, size_t n, size_t size)
{
    void *q = realloc(*p, n * size);
    if (!q) return -1;
    *p = q;
    return 0;
}

/* The arrays for n particles (with the pair loops' padding) and a grid of `size` entries. */
static int reserve(struct viscous_coarse *K, size_t n, size_t size)
{
    if (K->cap_particles < n + FORCES_PAD) {
        const size_t cap = n + n / 4 + FORCES_PAD;
        if (grow((void **)&K->group, cap, sizeof(int32_t))) return -1;
        K->cap_particles = cap;
    }
    if (K->cap_size < size) {
        if (grow((void **)&K->w, COARSE_SLOTS * size, sizeof(double)) ||
            grow((void **)&K->compact, size, sizeof(int32_t)))
            return -1;
        K->cap_size = size;
    }
    /* at most one group with unknowns per grid entry, and the "no neighbour" entry */
    if (K->cap_active < size + 1) {
        const size_t cap = size + 1;
        if (grow((void **)&K->entry, cap, sizeof(size_t)) || grow((void **)&K->first, cap, sizeof(size_t)) ||
            grow((void **)&K->last, cap, sizeof(size_t)) ||
            grow((void **)&K->nb, COARSE_NEIGHBOURS * cap, sizeof(int32_t)) ||
            grow((void **)&K->nw, COARSE_NEIGHBOURS * cap, sizeof(double)) ||
            grow((void **)&K->inv_diag, cap, sizeof(double)))
            return -1;
        for (int k = 0; k < DIM; k++)
            if (grow((void **)&K->b[k], cap, sizeof(double)) || grow((void **)&K->e[k], cap, sizeof(double)))
                return -1;
        K->cap_active = cap;
    }
    return 0;
}

#endif

int viscous_coarse_build(struct viscous_coarse *K, const struct forces *F, const struct pair_system *S,
                         const unsigned char *unknown, size_t n)
{
    const struct cells *C = S->C;
#if DIM != 2
    /* the groups and their 5-slot stencil are those of a 2D grid of cell rows: the coarse level
     * of a 3D run is not written (numerics.viscous_preconditioner "jacobi" there) */
    (void)F;
    (void)unknown;
    (void)n;
    (void)C;
    (void)K;
    return -1;
#else
    const long nx = C->n[0], nz = C->n[DIM_UP];
    const long width = (long)COARSE_WIDTH_KX * C->kx;
    const long per_row = (nx + width - 1) / width;
    K->stride = per_row + 2;
    K->size = (size_t)K->stride * (size_t)(nz + 2);
    if (reserve(K, n, K->size) != 0) return -1;
    for (size_t id = 0; id < K->size; id++) K->compact[id] = -1;
    K->n_active = 0;
    for (long row = 0; row < nz; row++)
        for (long gx = 0; gx < per_row; gx++) {
            const size_t row0 = (size_t)row * (size_t)nx;
            const long col1 = gx * width + width < nx ? gx * width + width : nx;
            const size_t b = C->start[row0 + (size_t)(gx * width)], e = C->start[row0 + (size_t)col1];
            const size_t id = (size_t)(row + 1) * (size_t)K->stride + (size_t)(gx + 1);
            int any = 0;
            for (size_t i = b; i < e; i++) {
                K->group[i] = unknown[i] ? (int32_t)id : -1;
                any |= unknown[i];
            }
            if (!any) continue;
            K->compact[id] = (int32_t)K->n_active;
            K->entry[K->n_active] = id;
            K->first[K->n_active] = b;
            K->last[K->n_active] = e;
            memset(K->w + COARSE_SLOTS * id, 0, COARSE_SLOTS * sizeof(double));
            K->n_active++;
        }
    for (size_t i = n; i < n + FORCES_PAD; i++) K->group[i] = -1;
    if (forces_viscous_group_couplings(F, S, K->group, K->stride, K->w) != 0) return -1;
    for (int d = 0; d < DIM; d++) K->e[d][K->n_active] = 0.0; /* the "no neighbour" entry */
    return 0;
#endif
}

/* With P a group's value on each of its unknowns and A = m + kappa L,
 *   A_c(I, I) = sum_{i in I} (m_i + kappa sum_j w_ij) - 2 kappa sum_{pairs inside I} w_ij,
 *   A_c(I, J) = -kappa sum_{i in I, j in J} w_ij,
 * the couplings to prescribed particles and walls kept in the diagonal as if those were at rest
 * (the walls' mirror is left out: this only preconditions). */
/* The coarse operator's loop over the groups (core/team.h). */
struct coarse_operator_loop {
    struct viscous_coarse *K;
    const double *minv;           /* the Jacobi diagonal's inverse */
    const unsigned char *unknown;
    double kappa;
};

static void operator_range(void *arg, size_t a0, size_t a1)
{
    const struct coarse_operator_loop *L = arg;
    struct viscous_coarse *K = L->K;
    const double *minv = L->minv;
    const unsigned char *unknown = L->unknown;
    const double kappa = L->kappa;
    const long s = K->stride;
    const long off[4] = {1, s - 1, s, s + 1}; /* slots 1..4 of the couplings */
    for (size_t a = a0; a < a1; a++) {
        double d = 0.0;
        for (size_t i = K->first[a]; i < K->last[a]; i++)
            if (unknown[i]) d += 1.0 / minv[i];
        const size_t id = K->entry[a];
        d -= 2.0 * kappa * K->w[COARSE_SLOTS * id];
        K->inv_diag[a] = 1.0 / d;
        int32_t *nb = K->nb + COARSE_NEIGHBOURS * a;
        double *nw = K->nw + COARSE_NEIGHBOURS * a;
        for (int k = 0; k < 4; k++) {
            const size_t up = id + (size_t)off[k], down = id - (size_t)off[k];
            const int32_t cu = K->compact[up], cd = K->compact[down];
            nb[2 * k] = cu >= 0 ? cu : (int32_t)K->n_active;
            nw[2 * k] = cu >= 0 ? kappa * K->w[COARSE_SLOTS * id + 1 + k] / d : 0.0;
            nb[2 * k + 1] = cd >= 0 ? cd : (int32_t)K->n_active;
            nw[2 * k + 1] = cd >= 0 ? kappa * K->w[COARSE_SLOTS * down + 1 + k] / d : 0.0;
        }
    }
}

void viscous_coarse_operator(struct viscous_coarse *K, const double *minv, const unsigned char *unknown,
                             double kappa, int threads)
{
    struct coarse_operator_loop L = {.K = K, .minv = minv, .unknown = unknown, .kappa = kappa};
    team_for(threads, K->n_active, operator_range, &L);
}

/* One symmetric Gauss-Seidel sweep of A_c e = b for one component. */
static void sweep(const struct viscous_coarse *K, const double *restrict b, double *restrict e)
{
    const size_t n = K->n_active;
    for (int pass = 0; pass < 2; pass++)
        for (size_t k = 0; k < n; k++) {
            const size_t a = pass == 0 ? k : n - 1 - k;
            const int32_t *nb = K->nb + COARSE_NEIGHBOURS * a;
            const double *nw = K->nw + COARSE_NEIGHBOURS * a;
            double sum = K->inv_diag[a] * b[a];
            for (int q = 0; q < COARSE_NEIGHBOURS; q++) sum += nw[q] * e[nb[q]];
            e[a] = sum;
        }
}

/* The correction's region (core/team.h): out += P A_c^-1 P^T in, per component. */
struct coarse_correct_region {
    struct viscous_coarse *K;
    const unsigned char *unknown;
    const double *const *in; /* DIM components */
    double *const *out;
};

/* P^T sums a group's rows; the components' sweeps (sequential each) run side by side. */
static void correct_region(void *arg, int tid, int nth)
{
    const struct coarse_correct_region *L = arg;
    struct viscous_coarse *K = L->K;
    const unsigned char *unknown = L->unknown;
    size_t a0, a1;
    team_share(K->n_active, tid, nth, &a0, &a1);
    for (size_t a = a0; a < a1; a++)
        for (int d = 0; d < DIM; d++) {
            double s = 0.0;
            for (size_t i = K->first[a]; i < K->last[a]; i++) s += L->in[d][i];
            K->b[d][a] = s;
            K->e[d][a] = 0.0;
        }
    team_barrier();
    for (int comp = tid; comp < DIM; comp += nth)
        for (int k = 0; k < COARSE_SWEEPS; k++) sweep(K, K->b[comp], K->e[comp]);
    team_barrier();
    for (size_t a = a0; a < a1; a++)
        for (int d = 0; d < DIM; d++) {
            const double e = K->e[d][a];
            for (size_t i = K->first[a]; i < K->last[a]; i++)
                if (unknown[i]) L->out[d][i] += e;
        }
}

void viscous_coarse_correct(struct viscous_coarse *K, const unsigned char *unknown, const double *const in[DIM],
                            double *const out[DIM], int threads)
{
    struct coarse_correct_region L = {.K = K, .unknown = unknown, .in = in, .out = out};
    team_run(threads, correct_region, &L);
}
