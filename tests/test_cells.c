/* test_cells.c - the cell list of cells.h: counting sort by cell, neighbour ranges, lost
 * particles. Neighbour lists from the three cells_row ranges are compared with an O(N^2) brute
 * force search within the support 2h (= the cell side), on random particles (fixed seed) plus
 * particles exactly on cell borders, in the last row and column, on the far edges of the grid
 * (outside: they must become lost) and at non-finite positions. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "cells.h"
#include "mixsph.h"
#include "neighbours.h"
#include "particles.h"

#include "test_random.h"

struct grid_spec {
    double x_min, x_max, z_min, z_max, size;
};

/* Random particles in and around the grid, plus the special positions. */
/* This file tests the 2D grid through its (x, z) coordinates; test_neighbours.c tests the
 * ranges for any DIM. */
_Static_assert(DIM == 2, "test_cells is the 2D grid's test");

static void coords_2d(const struct cells *C, double x, double z, int *ix, int *iz)
{
    const double p[2] = {x, z};
    int c[2];
    cells_coords(C, p, c);
    *ix = c[0];
    *iz = c[1];
}

static struct range row_2d(const struct cells *C, int ix, int iz, int drow)
{
    const int c[2] = {ix, iz};
    return cells_row(C, c, drow + 1);
}

static int init_columns_2d(struct cells *C, double x0, double x1, double z0, double z1, double size, int kx)
{
    const double lo[2] = {x0, z0}, hi[2] = {x1, z1};
    return cells_init_columns(C, lo, hi, size, kx);
}

static int init_2d(struct cells *C, double x0, double x1, double z0, double z1, double size)
{
    return init_columns_2d(C, x0, x1, z0, z1, size, 1);
}

static void make_particles(struct particles *P, const struct cells *C, uint64_t seed, size_t n_random)
{
    uint64_t s = seed;
    const double X1 = C->lo[0] + C->n[0] * C->size, Z1 = C->lo[1] + C->n[1] * C->size;
    assert_int_equal(particles_alloc(P, 16), 0);
    for (size_t k = 0; k < n_random; k++) {
        const double x = test_random_uniform(&s, C->lo[0] - 0.5 * C->size, X1 + 0.5 * C->size);
        const double z = test_random_uniform(&s, C->lo[1] - 0.5 * C->size, Z1 + 0.5 * C->size);
        const uint8_t st = k % 17 == 0 ? MIXSPH_STATE_WALL : k % 23 == 0 ? MIXSPH_STATE_FIXED : MIXSPH_STATE_MOBILE;
        assert_true(particles_push(P, (const double[DIM]){x, z}, 1000.0, 1.0, 0, st) != (size_t)-1);
    }
    /* on every vertical and horizontal cell border (the last ones, x = X1 and z = Z1, are outside) */
    for (int i = 0; i <= C->n[0]; i++) {
        for (int k = 0; k < 3; k++) {
            particles_push(P, (const double[DIM]){C->lo[0] + i * C->size, test_random_uniform(&s, C->lo[1], Z1)}, 1000.0, 1.0, 0, MIXSPH_STATE_MOBILE);
            particles_push(P, (const double[DIM]){C->lo[0] + i * C->size, C->lo[1] + (k % C->n[1]) * C->size}, 1000.0, 1.0, 0, MIXSPH_STATE_MOBILE);
        }
    }
    for (int l = 0; l <= C->n[1]; l++)
        for (int k = 0; k < 3; k++)
            particles_push(P, (const double[DIM]){test_random_uniform(&s, C->lo[0], X1), C->lo[1] + l * C->size}, 1000.0, 1.0, 0, MIXSPH_STATE_MOBILE);
    /* just inside the last column and row, and the far corner */
    for (int k = 0; k < 5; k++) {
        particles_push(P, (const double[DIM]){nextafter(X1, -INFINITY), test_random_uniform(&s, C->lo[1], Z1)}, 1000.0, 1.0, 0, MIXSPH_STATE_MOBILE);
        particles_push(P, (const double[DIM]){test_random_uniform(&s, C->lo[0], X1), nextafter(Z1, -INFINITY)}, 1000.0, 1.0, 0, MIXSPH_STATE_MOBILE);
    }
    particles_push(P, (const double[DIM]){nextafter(X1, -INFINITY), nextafter(Z1, -INFINITY)}, 1000.0, 1.0, 0, MIXSPH_STATE_MOBILE);
    particles_push(P, (const double[DIM]){C->lo[0], C->lo[1]}, 1000.0, 1.0, 0, MIXSPH_STATE_MOBILE);
    /* just outside the near edges, and not finite */
    particles_push(P, (const double[DIM]){nextafter(C->lo[0], -INFINITY), test_random_uniform(&s, C->lo[1], Z1)}, 1000.0, 1.0, 0, MIXSPH_STATE_MOBILE);
    particles_push(P, (const double[DIM]){test_random_uniform(&s, C->lo[0], X1), nextafter(C->lo[1], -INFINITY)}, 1000.0, 1.0, 0, MIXSPH_STATE_MOBILE);
    particles_push(P, (const double[DIM]){NAN, test_random_uniform(&s, C->lo[1], Z1)}, 1000.0, 1.0, 0, MIXSPH_STATE_MOBILE);
    particles_push(P, (const double[DIM]){test_random_uniform(&s, C->lo[0], X1), INFINITY}, 1000.0, 1.0, 0, MIXSPH_STATE_MOBILE);
    /* already lost before the build, inside the grid: stays lost, not counted again */
    particles_push(P, (const double[DIM]){0.5 * (C->lo[0] + X1), 0.5 * (C->lo[1] + Z1)}, 1000.0, 1.0, 0, MIXSPH_STATE_LOST);
    for (size_t i = 0; i < P->n; i++) {
        P->vel[0][i] = 1.0 + (double)i;
        P->vel[DIM_UP][i] = -2.0;
    }
}

/* Is (x, z) inside the grid? Independent of cells.c: comparisons with the grid's edges.
 * Returns 1 inside, 0 outside, -1 undecided: within a rounding of the far edges x0 + nx size or
 * z0 + nz size (cells.c computes (x - x0) / size, whose rounding may put such a point in the
 * last cell or out of the grid; either is right). */
static int inside(const struct cells *C, double x, double z)
{
    const double X1 = C->lo[0] + C->n[0] * C->size, Z1 = C->lo[1] + C->n[1] * C->size;
    const double tol = 1e-12 * C->size;
    if (!(x >= C->lo[0] && z >= C->lo[1] && x < X1 + tol && z < Z1 + tol)) return 0;
    if (x > X1 - tol || z > Z1 - tol) return -1;
    return 1;
}

static int cmp_u32(const void *a, const void *b)
{
    const uint32_t p = *(const uint32_t *)a, q = *(const uint32_t *)b;
    return p < q ? -1 : p > q;
}

/* Neighbour lists (ids within the support, self excluded) from the cell ranges and by brute
 * force must be equal for every particle in the grid. Returns the number of pairs found. */
static size_t check_neighbours(const struct cells *C, const struct particles *P)
{
    const size_t n_in = C->start[C->ncell];
    const double r2max = C->size * C->size; /* support 2h = cell side */
    uint32_t *a = malloc(P->n * sizeof *a), *b = malloc(P->n * sizeof *b);
    assert_non_null(a);
    assert_non_null(b);
    size_t pairs = 0;
    for (size_t i = 0; i < n_in; i++) {
        size_t na = 0, nb = 0;
        int ix, iz;
        coords_2d(C, P->pos[0][i], P->pos[DIM_UP][i], &ix, &iz);
        for (int row = -1; row <= 1; row++) {
            const struct range rg = row_2d(C, ix, iz, row);
            assert_true(rg.begin <= rg.end && rg.end <= n_in);
            for (size_t j = rg.begin; j < rg.end; j++) {
                const double rx = P->pos[0][i] - P->pos[0][j], rz = P->pos[DIM_UP][i] - P->pos[DIM_UP][j];
                if (j != i && rx * rx + rz * rz < r2max) a[na++] = P->id[j];
            }
        }
        for (size_t j = 0; j < P->n; j++) {
            if (j == i || P->state[j] == MIXSPH_STATE_LOST) continue;
            const double rx = P->pos[0][i] - P->pos[0][j], rz = P->pos[DIM_UP][i] - P->pos[DIM_UP][j];
            if (rx * rx + rz * rz < r2max) b[nb++] = P->id[j];
        }
        qsort(a, na, sizeof *a, cmp_u32);
        qsort(b, nb, sizeof *b, cmp_u32);
        /* reference: brute force, exactly (same arithmetic on the same pairs) */
        assert_int_equal(na, nb);
        assert_memory_equal(a, b, na * sizeof *a);
        pairs += na;
    }
    free(a);
    free(b);
    return pairs;
}

/* Sorted by cell, ranges consistent, lost at the end with zero velocity; the reordering is a
 * permutation carrying every field of a particle with its id. */
static void check_sort(const struct cells *C, const struct particles *P, const double *x_of_id, const double *z_of_id,
                       const uint8_t *state_of_id, size_t n_ids)
{
    const size_t n = P->n;
    assert_true(C->start[0] == 0);
    assert_true(C->start[C->ncell + 1] == n);
    for (size_t c = 0; c <= C->ncell; c++) assert_true(C->start[c] <= C->start[c + 1]);
    char *seen = calloc(n_ids, 1);
    assert_non_null(seen);
    for (size_t k = 0; k < n; k++) {
        const uint32_t id = P->id[k];
        assert_true(id < n_ids);
        assert_int_equal(seen[id], 0);
        seen[id] = 1;
        /* fields travel with the particle (bitwise; NaN compares by memcmp) */
        assert_memory_equal(&P->pos[0][k], &x_of_id[id], sizeof(double));
        assert_memory_equal(&P->pos[DIM_UP][k], &z_of_id[id], sizeof(double));
        const int where = state_of_id[id] == MIXSPH_STATE_LOST ? 0 : inside(C, x_of_id[id], z_of_id[id]);
        if (where == 1 || (where == -1 && P->state[k] != MIXSPH_STATE_LOST)) {
            assert_true(k < C->start[C->ncell]);
            assert_int_equal(P->state[k], state_of_id[id]);
            assert_true(P->vel[0][k] == 1.0 + (double)id); /* push order = id; velocity kept */
            /* its cell holds its position: cell c = iz nx + ix with the grid's own edges */
            const uint32_t c = C->cell[k];
            assert_true(c < C->ncell);
            assert_true(C->start[c] <= k && k < C->start[c + 1]);
            const int ix = (int)(c % (uint32_t)C->n[0]), iz = (int)(c / (uint32_t)C->n[0]);
            /* tolerance: a position on a border may fall on either side by one rounding */
            const double tol = 1e-12 * C->size;
            assert_true(P->pos[0][k] >= C->lo[0] + ix * C->size - tol && P->pos[0][k] < C->lo[0] + (ix + 1) * C->size + tol);
            assert_true(P->pos[DIM_UP][k] >= C->lo[1] + iz * C->size - tol && P->pos[DIM_UP][k] < C->lo[1] + (iz + 1) * C->size + tol);
            if (k > 0) assert_true(C->cell[k - 1] <= c);
            /* stable: particles of one cell keep their previous (here: id) order */
            if (k > C->start[c]) assert_true(P->id[k - 1] < id);
        } else {
            assert_true(k >= C->start[C->ncell]);
            assert_int_equal(P->state[k], MIXSPH_STATE_LOST);
            if (state_of_id[id] != MIXSPH_STATE_LOST) assert_true(P->vel[0][k] == 0.0 && P->vel[DIM_UP][k] == 0.0); /* newly lost */
        }
    }
    free(seen);
}

static void run_grid(const struct grid_spec *g, uint64_t seed, size_t n_random)
{
    struct cells C;
    struct particles P;
    memset(&P, 0, sizeof P);
    assert_int_equal(init_2d(&C, g->x_min, g->x_max, g->z_min, g->z_max, g->size), 0);
    /* the grid covers the box with whole cells */
    assert_true(C.n[0] == (int)ceil((g->x_max - g->x_min) / g->size));
    assert_true(C.lo[0] + C.n[0] * C.size >= g->x_max && C.lo[1] + C.n[1] * C.size >= g->z_max);
    make_particles(&P, &C, seed, n_random);
    const size_t n = P.n;
    double *x = malloc(n * sizeof *x), *z = malloc(n * sizeof *z);
    uint8_t *st = malloc(n);
    assert_non_null(x);
    assert_non_null(z);
    assert_non_null(st);
    long expect_lost = 0, undecided = 0;
    for (size_t i = 0; i < n; i++) {
        assert_int_equal(P.id[i], i);
        x[i] = P.pos[0][i];
        z[i] = P.pos[DIM_UP][i];
        st[i] = P.state[i];
        if (st[i] == MIXSPH_STATE_LOST) continue;
        expect_lost += inside(&C, x[i], z[i]) == 0;
        undecided += inside(&C, x[i], z[i]) == -1;
    }
    assert_true(expect_lost >= 6); /* the test set does contain particles outside */
    const long lost = cells_build(&C, &P);
    if (!(lost >= expect_lost && lost <= expect_lost + undecided))
        print_message("lost %ld, expected %ld (+ up to %ld undecided)\n", lost, expect_lost, undecided);
    assert_true(lost >= expect_lost && lost <= expect_lost + undecided);
    check_sort(&C, &P, x, z, st, n);
    const size_t pairs = check_neighbours(&C, &P);
    assert_true(pairs > 10 * n); /* non-trivial: about pi (2h)^2 density neighbours each */

    /* move every particle a little (some leave, none come back) and build again: the newly
     * lost are counted once, the ones lost before are not counted again */
    uint64_t s = seed ^ 0x5555u;
    for (size_t k = 0; k < n; k++) {
        const uint32_t id = P.id[k];
        if (P.state[k] != MIXSPH_STATE_LOST) {
            P.pos[0][k] += test_random_uniform(&s, -0.3, 0.3) * C.size;
            P.pos[DIM_UP][k] += test_random_uniform(&s, -0.3, 0.3) * C.size;
            P.vel[0][k] = 1.0 + (double)id;
        }
        x[id] = P.pos[0][k];
        z[id] = P.pos[DIM_UP][k];
        st[id] = P.state[k];
    }
    long expect2 = 0, undecided2 = 0;
    for (size_t i = 0; i < n; i++) {
        if (st[i] == MIXSPH_STATE_LOST) continue;
        expect2 += inside(&C, x[i], z[i]) == 0;
        undecided2 += inside(&C, x[i], z[i]) == -1;
    }
    /* rebuild from a shuffled order, so stability is checked against ids again: sort by id */
    size_t *perm = malloc(n * sizeof *perm);
    double *scratch = malloc(n * sizeof *scratch);
    assert_non_null(perm);
    assert_non_null(scratch);
    for (size_t k = 0; k < n; k++) perm[P.id[k]] = k;
    particles_permute(&P, perm, scratch);
    for (size_t k = 0; k < n; k++) assert_int_equal(P.id[k], k);
    const long lost2 = cells_build(&C, &P);
    assert_true(lost2 >= expect2 && lost2 <= expect2 + undecided2);
    check_sort(&C, &P, x, z, st, n);
    check_neighbours(&C, &P);
    print_message("grid %d x %d, %zu particles: %ld lost, then %ld more, %zu neighbour pairs\n", C.n[0], C.n[1], n, lost,
                  lost2, pairs);
    free(perm);
    free(scratch);
    free(x);
    free(z);
    free(st);
    particles_free(&P);
    cells_free(&C);
}

/* Cell side a power of two: borders are exact binary numbers. */
static void test_exact_grid(void **state)
{
    (void)state;
    const struct grid_spec g = {-0.5, 0.75, 0.0, 0.6, 0.125}; /* 10 x 5 cells, top row partial */
    run_grid(&g, 12345u, 3000);
}

/* The solver's cell side 2h = 2.6 dx: borders are rounded. */
static void test_rounded_grid(void **state)
{
    (void)state;
    const double dx = 0.01;
    const struct grid_spec g = {0.013, 0.5, -0.1, 0.3, 2.0 * 1.3 * dx};
    run_grid(&g, 987654321u, 4000);
}

/* A grid of a single cell and one of a single row: the ranges clamp at every edge. */
static void test_degenerate_grids(void **state)
{
    (void)state;
    const struct grid_spec one = {0.0, 0.1, 0.0, 0.1, 0.1};
    run_grid(&one, 7u, 200);
    const struct grid_spec row = {0.0, 1.0, 0.0, 0.05, 0.1};
    run_grid(&row, 8u, 600);
}

/* Empty set: all ranges empty. */
static void test_empty(void **state)
{
    (void)state;
    struct cells C;
    struct particles P;
    memset(&P, 0, sizeof P);
    assert_int_equal(init_2d(&C, 0.0, 1.0, 0.0, 1.0, 0.25), 0);
    assert_int_equal(particles_alloc(&P, 16), 0);
    assert_int_equal(cells_build(&C, &P), 0);
    for (size_t c = 0; c <= C.ncell + 1; c++) assert_true(C.start[c] == 0);
    const struct range r = row_2d(&C, 1, 1, 0);
    assert_true(r.begin == r.end);
    particles_free(&P);
    cells_free(&C);
    /* a box of zero width cannot hold a grid */
    assert_int_equal(init_2d(&C, 0.0, 0.0, 0.0, 1.0, 0.25), -1);
    cells_free(&C);
}

/* Is j in [r[0], r[1]) or [r[2], r[3]) ... (n_ranges ranges)? */
static int in_ranges(const uint32_t *r, int n_ranges, size_t j)
{
    int hits = 0;
    for (int k = 0; k < n_ranges; k++) hits += j >= r[2 * k] && j < r[2 * k + 1];
    return hits;
}

/* Neighbour ranges (neighbours.c) on narrow columns: after every particle has moved by less
 * than skin/2 since the build (random directions, fixed seed), each pair closer than 2h is met
 * exactly once by the half-stencil ranges (in i's ranges or in j's, never both: the symmetric
 * pair loops count each pair once), every particle's gather ranges hold each neighbour closer
 * than 2h exactly once, and a wall particle's list holds exactly its non-wall neighbours closer
 * than 2h + skin at the build. Reference: brute force over all pairs. */
static void test_neighbour_ranges(void **state)
{
    (void)state;
    const double h = 0.013, skin = 0.3 * h, rc = 2.0 * h + skin;
    for (int kx = 1; kx <= 8; kx *= 2) {
        struct cells C;
        struct particles P;
        memset(&P, 0, sizeof P);
        assert_int_equal(init_columns_2d(&C, 0.0, 0.5, 0.0, 0.3, rc, kx), 0);
        assert_true(C.width * kx == C.size);
        assert_int_equal(particles_alloc(&P, 3000), 0);
        uint64_t seed = 99u + (uint64_t)kx;
        for (int i = 0; i < 2500; i++) {
            const uint8_t st = i % 7 == 0 ? MIXSPH_STATE_WALL : MIXSPH_STATE_MOBILE;
            particles_push(&P, (const double[DIM]){test_random_uniform(&seed, 0.01, 0.49), test_random_uniform(&seed, 0.01, 0.29)}, 1000.0, 1.0, 0, st);
        }
        /* particles on column and row borders */
        for (int k = 0; k < 40; k++)
            particles_push(&P, (const double[DIM]){C.lo[0] + (k % 10 + 1) * C.width, C.lo[1] + (k % 5 + 1) * C.size}, 1000.0, 1.0, 0,
                           MIXSPH_STATE_MOBILE);
        assert_int_equal(cells_build(&C, &P), 0);
        const size_t n = C.start[C.ncell];
        struct neighbours NB;
        struct gather G;
        memset(&NB, 0, sizeof NB);
        memset(&G, 0, sizeof G);
        NB.skin = skin;
        assert_int_equal(neighbours_build(&NB, &C, &P, n, rc, 2), 0);
        assert_int_equal(neighbours_gather_reserve(&G, P.cap), 0);
        memset(G.mode, NEIGHBOURS_GATHER_ALL, n);
        assert_int_equal(neighbours_gather_build(&G, &NB, &C, P.state, n, rc, 2), 0);
        /* wall lists: exactly the non-wall particles closer than rc at the build */
        for (size_t i = 0; i < n; i++) {
            if (P.state[i] != MIXSPH_STATE_WALL) continue;
            size_t expect = 0;
            for (size_t j = 0; j < n; j++) {
                const double rx = P.pos[0][i] - P.pos[0][j], rz = P.pos[DIM_UP][i] - P.pos[DIM_UP][j];
                expect += P.state[j] != MIXSPH_STATE_WALL && rx * rx + rz * rz < rc * rc;
            }
            assert_int_equal(G.start[i + 1] - G.start[i], expect);
            for (size_t k = G.start[i]; k < G.start[i + 1]; k++) assert_int_not_equal(P.state[G.list[k]], MIXSPH_STATE_WALL);
        }
        /* move every particle by less than skin / 2 */
        for (size_t i = 0; i < n; i++) {
            const double a = test_random_uniform(&seed, 0.0, 6.283185307179586), d = test_random_uniform(&seed, 0.0, 0.4999 * skin);
            P.pos[0][i] += d * cos(a);
            P.pos[DIM_UP][i] += d * sin(a);
        }
        int outside = 1;
        const double shift2 = neighbours_max_shift2(&NB, &C, &P, n, &outside, 2);
        assert_true(4.0 * shift2 < skin * skin);
        assert_int_equal(outside, 0);
        size_t pairs = 0;
        for (size_t i = 0; i < n; i++)
            for (size_t j = 0; j < n; j++) {
                if (j == i) continue;
                const double rx = P.pos[0][i] - P.pos[0][j], rz = P.pos[DIM_UP][i] - P.pos[DIM_UP][j];
                if (rx * rx + rz * rz >= 4.0 * h * h) continue;
                assert_int_equal(in_ranges(G.rng + 6 * i, 3, j), 1);
                if (j < i) continue;
                pairs++;
                assert_int_equal(in_ranges(NB.rng + 4 * i, 2, j) + in_ranges(NB.rng + 4 * j, 2, i), 1);
            }
        print_message("kx = %d: %zu pairs within 2h, each met once\n", kx, pairs);
        assert_true(pairs > 10000);
        neighbours_free(&NB);
        neighbours_gather_free(&G);
        particles_free(&P);
        cells_free(&C);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_exact_grid),
        cmocka_unit_test(test_rounded_grid),
        cmocka_unit_test(test_degenerate_grids),
        cmocka_unit_test(test_empty),
        cmocka_unit_test(test_neighbour_ranges),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
