/* neighbours.c - see neighbours.h. */
#include "neighbours.h"

#include <stdlib.h>
#include <string.h>

#include "mixsph.h"
#include "team.h"

void neighbours_free(struct neighbours *NB)
{
    for (int d = 0; d < DIM; d++) free(NB->pos0[d]);
    free(NB->rng);
    const double skin = NB->skin;
    memset(NB, 0, sizeof *NB);
    NB->skin = skin;
}

static int grow(void **p, size_t n, size_t elem)
{
    void *q = realloc(*p, n * elem);
    if (!q) return -1;
    *p = q;
    return 0;
}

int neighbours_reserve(struct neighbours *NB, size_t cap)
{
    if (cap + 1 <= NB->cap_n) return 0;
    cap++;
    for (int d = 0; d < DIM; d++)
        if (grow((void **)&NB->pos0[d], cap, sizeof(double))) return -1;
    if (grow((void **)&NB->rng, 2 * NEIGHBOURS_RANGES * cap, sizeof(uint32_t))) return -1;
    NB->cap_n = cap;
    return 0;
}

int neighbours_build(struct neighbours *NB, const struct cells *C, const struct particles *P, size_t n, double rc,
                     int n_threads)
{
    if (neighbours_reserve(NB, P->cap) != 0) return -1;
    for (int d = 0; d < DIM; d++) memcpy(NB->pos0[d], P->pos[d], P->n * sizeof(double));
    return neighbours_relist(NB, C, n, rc, n_threads);
}

/* Squared distance between particles i and j of the positions x[d][.]. */
static inline double distance2(double *const x[DIM], size_t i, size_t j)
{
    double r2 = 0.0;
    for (int d = 0; d < DIM; d++) r2 += (x[d][i] - x[d][j]) * (x[d][i] - x[d][j]);
    return r2;
}

/* [b, e) trimmed to its first and last particle closer than rc to particle i (empty if none). */
static inline void trim(double *const x[DIM], size_t i, double rc2, size_t *b, size_t *e)
{
    size_t lo = *b, hi = *e;
    while (lo < hi && distance2(x, i, lo) >= rc2) lo++;
    while (hi > lo && distance2(x, i, hi - 1) >= rc2) hi--;
    *b = lo;
    *e = hi;
}

/* The arguments of the parallel loops of this file (core/team.h): the lists' build and the
 * gather lists' build share one (NB or the gather it builds, the grid, the squared cut-off), the
 * displacement check has its own. */
struct nb_loop {
    struct neighbours *NB;        /* the lists being built (relist) */
    const struct neighbours *cNB; /* their build positions (gather lists) */
    struct gather *G;
    const struct cells *C;
    const uint8_t *state;
    struct pair_list *L;          /* the pair list being built */
    double rc2;                   /* squared cut-off [m2] */
};

struct shift_loop {
    const struct neighbours *NB;
    const struct cells *C;
    const struct particles *P;
    double shift2_max; /* max squared displacement since the build [m2] */
    int outside;       /* | a particle left the grid */
};

static void relist_range(void *arg, size_t b, size_t e)
{
    const struct nb_loop *L = arg;
    struct neighbours *NB = L->NB;
    const struct cells *C = L->C;
    const double rc2 = L->rc2;
    for (size_t i = b; i < e; i++) {
        int c[DIM];
        cells_unindex(C, C->cell[i], c);
        uint32_t *r = NB->rng + 2 * NEIGHBOURS_RANGES * i;
        const int last = c[0] + C->kx < C->n[0] ? c[0] + C->kx : C->n[0] - 1;
        size_t b1 = i + 1, e1 = C->start[C->cell[i] - (size_t)c[0] + (size_t)last + 1];
        trim(NB->pos0, i, rc2, &b1, &e1);
        r[0] = (uint32_t)b1;
        r[1] = (uint32_t)e1;
        for (int k = 1; k < NEIGHBOURS_RANGES; k++) {
            const struct range up = cells_row(C, c, CELLS_ROWS_AROUND / 2 + k);
            size_t b2 = up.begin, e2 = up.end;
            trim(NB->pos0, i, rc2, &b2, &e2);
            r[2 * k] = (uint32_t)b2;
            r[2 * k + 1] = (uint32_t)e2;
        }
    }
}

int neighbours_relist(struct neighbours *NB, const struct cells *C, size_t n, double rc, int n_threads)
{
    struct nb_loop L = {.NB = NB, .C = C, .rc2 = rc * rc};
    team_for_dynamic(n_threads > 0 ? n_threads : 1, n, relist_range, &L);
    NB->builds++;
    return 0;
}

static void shift_range(void *arg, size_t b, size_t e)
{
    struct shift_loop *L = arg;
    const struct neighbours *NB = L->NB;
    const struct cells *C = L->C;
    const struct particles *P = L->P;
    double m = 0.0;
    int out = 0;
    double lo[DIM], hi[DIM];
    for (int d = 0; d < DIM; d++) {
        lo[d] = C->lo[d];
        hi[d] = cells_hi(C, d);
    }
    for (size_t i = b; i < e; i++) {
        double d2 = 0.0;
        for (int d = 0; d < DIM; d++) {
            const double dd = P->pos[d][i] - NB->pos0[d][i];
            d2 += dd * dd;
            out |= !(P->pos[d][i] >= lo[d] && P->pos[d][i] < hi[d]);
        }
        m = d2 > m ? d2 : m;
    }
    team_max_double(&L->shift2_max, m);
    team_or_int(&L->outside, out);
}

double neighbours_max_shift2(const struct neighbours *NB, const struct cells *C, const struct particles *P, size_t n,
                             int *outside, int n_threads)
{
    struct shift_loop L = {.NB = NB, .C = C, .P = P};
    team_for(n_threads > 0 ? n_threads : 1, n, shift_range, &L);
    *outside = L.outside;
    return L.shift2_max;
}

void neighbours_gather_free(struct gather *G)
{
    free(G->rng);
    free(G->mode);
    free(G->start);
    free(G->list);
    memset(G, 0, sizeof *G);
}

int neighbours_gather_reserve(struct gather *G, size_t cap)
{
    if (cap + 1 <= G->cap_n) return 0;
    cap++;
    if (grow((void **)&G->rng, 2 * CELLS_ROWS_AROUND * cap, sizeof(uint32_t)) || grow((void **)&G->mode, cap, 1) ||
        grow((void **)&G->start, cap + 1, sizeof(size_t)))
        return -1;
    G->cap_n = cap;
    return 0;
}

/* Non-wall neighbours of wall particle i within rc over its ranges: counted or written. */
static inline size_t wall_scan(const struct gather *G, double *const x[DIM], const uint8_t *state, size_t i, double rc2,
                               uint32_t *out)
{
    size_t k = 0;
    const uint32_t *r = G->rng + 2 * CELLS_ROWS_AROUND * i;
    for (int q = 0; q < 2 * CELLS_ROWS_AROUND; q += 2)
        for (size_t j = r[q]; j < r[q + 1]; j++) {
            if (state[j] == MIXSPH_STATE_WALL) continue;
            if (distance2(x, i, j) < rc2) {
                if (out) out[k] = (uint32_t)j;
                k++;
            }
        }
    return k;
}

/* Particles [b, e)'s gather ranges and, for wall particles, their neighbour counts (in
 * G->start + 1): one loop, since a count reads only its own particle's ranges. */
static void gather_ranges_range(void *arg, size_t i0, size_t i1)
{
    const struct nb_loop *L = arg;
    struct gather *G = L->G;
    const struct cells *C = L->C;
    const uint8_t *state = L->state;
    const double rc2 = L->rc2;
    double *const *x = L->cNB->pos0;
    size_t *cnt = G->start + 1;
    for (size_t i = i0; i < i1; i++) {
        uint32_t *r = G->rng + 2 * CELLS_ROWS_AROUND * i;
        if (G->mode[i] == NEIGHBOURS_GATHER_NONE) {
            memset(r, 0, 2 * CELLS_ROWS_AROUND * sizeof *r);
            cnt[i] = 0;
            continue;
        }
        int c[DIM];
        cells_unindex(C, C->cell[i], c);
        for (int row = 0; row < CELLS_ROWS_AROUND; row++) {
            const struct range g = cells_row(C, c, row);
            size_t b = g.begin, e = g.end;
            trim(x, i, rc2, &b, &e);
            r[2 * row] = (uint32_t)b;
            r[2 * row + 1] = (uint32_t)e;
        }
        cnt[i] = state[i] == MIXSPH_STATE_WALL ? wall_scan(G, x, state, i, rc2, NULL) : 0;
    }
}

static void gather_list_range(void *arg, size_t b, size_t e)
{
    const struct nb_loop *L = arg;
    const struct gather *G = L->G;
    const uint8_t *state = L->state;
    for (size_t i = b; i < e; i++)
        if (state[i] == MIXSPH_STATE_WALL) wall_scan(G, L->cNB->pos0, state, i, L->rc2, G->list + G->start[i]);
}

int neighbours_gather_build(struct gather *G, const struct neighbours *NB, const struct cells *C, const uint8_t *state,
                            size_t n, double rc, int n_threads)
{
    struct nb_loop L = {.cNB = NB, .G = G, .C = C, .state = state, .rc2 = rc * rc};
    n_threads = n_threads > 0 ? n_threads : 1;
    team_for_dynamic(n_threads, n, gather_ranges_range, &L);
    G->start[0] = 0;
    for (size_t i = 0; i < n; i++) G->start[i + 1] += G->start[i];
    const size_t total = G->start[n];
    if (total + NEIGHBOURS_PAD > G->cap_list) {
        const size_t cap = total + total / 4 + NEIGHBOURS_PAD + 64;
        if (grow((void **)&G->list, cap, sizeof(uint32_t))) return -1;
        G->cap_list = cap;
    }
    team_for_dynamic(n_threads, n, gather_list_range, &L);
    return 0;
}

void neighbours_pair_list_free(struct pair_list *L)
{
    free(L->start);
    free(L->j);
    memset(L, 0, sizeof *L);
}

/* Particle i's entries of the pair list: counted (out NULL) or written. */
static inline size_t pair_scan(const struct neighbours *NB, const uint8_t *state, size_t i, double rc2, uint32_t *out)
{
    double *const *x = NB->pos0;
    const uint32_t *r = NB->rng + 2 * NEIGHBOURS_RANGES * i;
    const int wall_i = state[i] == MIXSPH_STATE_WALL;
    size_t k = 0;
    for (int q = 0; q < 2 * NEIGHBOURS_RANGES; q += 2)
        for (size_t j = r[q]; j < r[q + 1]; j++) {
            if (wall_i && state[j] == MIXSPH_STATE_WALL) continue;
            if (distance2(x, i, j) < rc2) {
                if (out) out[k] = (uint32_t)j;
                k++;
            }
        }
    return k;
}

static void pair_count_range(void *arg, size_t b, size_t e)
{
    const struct nb_loop *L = arg;
    uint32_t *cnt = L->L->start + 1;
    for (size_t i = b; i < e; i++) cnt[i] = (uint32_t)pair_scan(L->cNB, L->state, i, L->rc2, NULL);
}

static void pair_fill_range(void *arg, size_t b, size_t e)
{
    const struct nb_loop *L = arg;
    for (size_t i = b; i < e; i++) pair_scan(L->cNB, L->state, i, L->rc2, L->L->j + L->L->start[i]);
}

int neighbours_pair_list_build(struct pair_list *PL, const struct neighbours *NB, const uint8_t *state, size_t n,
                               double rc, int n_threads)
{
    PL->valid = 0;
    if (n + 1 > PL->cap_n) {
        const size_t cap = n + n / 4 + 64;
        if (grow((void **)&PL->start, cap + 1, sizeof(uint32_t))) return -1;
        PL->cap_n = cap;
    }
    struct nb_loop L = {.cNB = NB, .state = state, .L = PL, .rc2 = rc * rc};
    n_threads = n_threads > 0 ? n_threads : 1;
    team_for_dynamic(n_threads, n, pair_count_range, &L); /* a particle's count fits: its ranges are uint32 */
    uint64_t total = 0;
    PL->start[0] = 0;
    for (size_t i = 0; i < n; i++) {
        total += PL->start[i + 1];
        if (total > UINT32_MAX) return -1;
        PL->start[i + 1] = (uint32_t)total;
    }
    if (total + NEIGHBOURS_PAD > PL->cap_j) {
        const size_t cap = total + total / 4 + NEIGHBOURS_PAD + 64;
        if (grow((void **)&PL->j, cap, sizeof(uint32_t))) return -1;
        PL->cap_j = cap;
    }
    team_for_dynamic(n_threads, n, pair_fill_range, &L);
    memset(PL->j + total, 0, NEIGHBOURS_PAD * sizeof(uint32_t));
    PL->n = n;
    PL->builds = NB->builds;
    PL->valid = 1;
    return 0;
}

#if DIM == 3
void neighbours_pair_blocks_free(struct pair_blocks *B)
{
    free(B->block);
    memset(B, 0, sizeof *B);
}

/* A block's place in the schedule: its colour, then its work (descending), then its place in the
 * grid, so that the order is total and depends on nothing but the lists. */
struct block_key {
    uint64_t work;
    uint32_t colour, place;
};

static int block_key_cmp(const void *a, const void *b)
{
    const struct block_key *p = a, *q = b;
    if (p->colour != q->colour) return p->colour < q->colour ? -1 : 1;
    if (p->work != q->work) return p->work > q->work ? -1 : 1;
    return p->place < q->place ? -1 : p->place > q->place;
}

int neighbours_pair_blocks_build(struct pair_blocks *B, const struct pair_list *L, const struct cells *C)
{
    /* the longer of x and y, in search radii; 2 radii per block along it */
    B->axis = (size_t)C->n[0] > (size_t)C->kx * (size_t)C->n[1] ? 0 : 1;
    const uint32_t width = B->axis == 0 ? 2u * (uint32_t)C->kx : 2u;
    const uint32_t cells = (uint32_t)C->n[B->axis], layers = (uint32_t)C->n[DIM_UP];
    const size_t per_layer = (cells + width - 1) / width, total = per_layer * layers;
    struct block_key *key = malloc((total > 0 ? total : 1) * sizeof *key);
    if (!key) return -1;
    if (total > B->cap) {
        free(B->block);
        B->block = malloc(total * sizeof *B->block);
        B->cap = B->block ? total : 0;
        if (!B->block) {
            free(key);
            return -1;
        }
    }
    size_t kept = 0;
    for (uint32_t z = 0; z < layers; z++)
        for (uint32_t a = 0; a < per_layer; a++) {
            const size_t b = kept;
            B->block[b][0] = a * width;
            B->block[b][1] = a * width + width < cells ? a * width + width : cells;
            B->block[b][2] = z;
            uint64_t particles = 0, entries = 0;
            for (size_t k = 0; k < neighbours_block_ranges(B, C); k++) {
                const struct range r = neighbours_block_range(B, C, b, k);
                particles += r.end - r.begin;
                entries += (uint64_t)L->start[r.end] - L->start[r.begin];
            }
            if (particles == 0) continue;
            key[b] = (struct block_key){.work = entries + particles, .colour = (z & 1u) * 2u + (a & 1u),
                                        .place = (uint32_t)b};
            kept++;
        }
    qsort(key, kept, sizeof *key, block_key_cmp);
    /* reorder the blocks by their keys (a copy through the keys' places, which are the old indices) */
    uint32_t(*old)[3] = malloc((kept > 0 ? kept : 1) * sizeof *old);
    if (!old) {
        free(key);
        return -1;
    }
    memcpy(old, B->block, kept * sizeof *old);
    for (int c = 0; c <= NEIGHBOURS_COLOURS; c++) B->first[c] = 0;
    for (size_t k = 0; k < kept; k++) {
        memcpy(B->block[k], old[key[k].place], sizeof *old);
        B->first[key[k].colour + 1]++;
    }
    for (int c = 0; c < NEIGHBOURS_COLOURS; c++) B->first[c + 1] += B->first[c];
    free(old);
    free(key);
    B->builds = L->builds;
    return 0;
}
#endif
