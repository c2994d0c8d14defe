/* test_dim.c - the parts written once for any DIM, in the build's dimension (tests/CMakeLists.txt
 * builds this file in the 2D build and in the DIM = 3 build):
 *   - the kernels' normalisation: int W dV = 1 and int x (x) grad W dV = -I, by Gauss-Legendre
 *     quadrature of the radial integrals, exact for these piecewise polynomials (to 1e-10);
 *   - the neighbour and gather ranges against brute force on a random cloud (every pair closer
 *     than the cut-off exactly once in the half stencils, every neighbour in the gather ranges);
 *   - in 3D, the threads' blocks of the pair list: each particle in one block, no particle written
 *     by two blocks of one colour;
 *   - the Jaumann rotation of a stressed block spun about each axis (the out-of-plane one in 2D)
 *     against the exact rotation by the Hughes-Winget angle 2 atan(w dt / 2) per step. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "cells.h"
#include "elasticity.h"
#include "kernel.h"
#include "mixsph.h"
#include "neighbours.h"
#include "particles.h"
#include "test_random.h"

/* Gauss-Legendre, 5 points on [-1, 1]: exact for polynomials of degree <= 9. */
static const double GL_X[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
static const double GL_W[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
                               0.2369268850561891};

/* The area (2D) or surface (3D) of the unit sphere. */
static const double SPHERE = DIM == 2 ? 2.0 * GEOM_PI : 4.0 * GEOM_PI;

/* int_0^2h f(r) r^p dr over the pieces [0, h], [h, 2h] (the cubic spline's break). */
static double radial(const struct kernel *K, int which, int p)
{
    double s = 0.0;
    for (int piece = 0; piece < 2; piece++) {
        const double a = piece * K->h, b = a + K->h;
        for (int k = 0; k < 5; k++) {
            const double r = 0.5 * (a + b) + 0.5 * (b - a) * GL_X[k];
            const double f = which == 0 ? kernel_w(K, r) : kernel_f(K, r);
            s += 0.5 * (b - a) * GL_W[k] * f * pow(r, p);
        }
    }
    return s;
}

static void test_kernel_normalisation(void **state)
{
    (void)state;
    for (int type = 0; type < 2; type++) {
        const struct kernel K = kernel_make_type(0.013, type);
        /* reference: int W dV = S int W r^(D-1) dr = 1 (the normalisation a_d); tolerance 1e-10
         * (the quadrature is exact, what remains is round-off) */
        const double integral = SPHERE * radial(&K, 0, DIM - 1);
        /* reference: int x_a d_b W dV = -delta_ab, i.e. (S / D) int F r^(D+1) dr = -1, grad W = F x */
        const double moment = SPHERE / DIM * radial(&K, 1, DIM + 1);
        print_message("DIM %d, kernel %d: int W = %.15f, int x grad W = %.15f\n", DIM, type, integral, moment);
        assert_true(fabs(integral - 1.0) < 1e-10);
        assert_true(fabs(moment + 1.0) < 1e-10);
    }
}

static double dist2(const struct particles *P, size_t i, size_t j)
{
    double r2 = 0.0;
    for (int d = 0; d < DIM; d++) r2 += (P->pos[d][i] - P->pos[d][j]) * (P->pos[d][i] - P->pos[d][j]);
    return r2;
}

static int cmp_u64(const void *a, const void *b)
{
    const uint64_t p = *(const uint64_t *)a, q = *(const uint64_t *)b;
    return p < q ? -1 : p > q;
}

/* The pair (id_i, id_j) as one key, smaller id first. */
static uint64_t pair_key(const struct particles *P, size_t i, size_t j)
{
    const uint64_t a = P->id[i], b = P->id[j];
    return a < b ? a << 32 | b : b << 32 | a;
}

static void test_neighbours_brute_force(void **state)
{
    (void)state;
    const size_t n = DIM == 2 ? 3000 : 4000;
    const double rc = 0.1, lo[DIM] = {0.0};
    double box_hi[DIM]; /* 1 x (0.4) x 0.6 */
    for (int d = 0; d < DIM; d++) box_hi[d] = d == 0 ? 1.0 : d == DIM - 1 ? 0.6 : 0.4;
    struct particles P;
    memset(&P, 0, sizeof P);
    uint64_t seed = 12345;
    for (size_t k = 0; k < n; k++) {
        double p[DIM];
        for (int d = 0; d < DIM; d++) p[d] = test_random_uniform(&seed, lo[d], box_hi[d]);
        assert_true(particles_push(&P, p, 1000.0, 1.0, 0, MIXSPH_STATE_MOBILE) != (size_t)-1);
    }
    for (int kx = 1; kx <= 3; kx++) {
        struct cells C;
        struct neighbours NB = {0};
        struct gather G = {0};
        assert_int_equal(cells_init_columns(&C, lo, box_hi, rc, kx), 0);
        assert_true(cells_build(&C, &P) >= 0);
        const size_t active = C.start[C.ncell];
        assert_int_equal(active, n);
        assert_int_equal(neighbours_build(&NB, &C, &P, active, rc, 1), 0);
        /* reference: every pair closer than rc, by brute force */
        size_t n_ref = 0, cap = 64;
        uint64_t *ref = malloc(cap * sizeof *ref), *got = NULL;
        for (size_t i = 0; i < n; i++)
            for (size_t j = i + 1; j < n; j++)
                if (dist2(&P, i, j) < rc * rc) {
                    if (n_ref == cap) ref = realloc(ref, (cap *= 2) * sizeof *ref);
                    ref[n_ref++] = pair_key(&P, i, j);
                }
        got = malloc((n_ref + 1) * sizeof *got);
        size_t n_got = 0;
        for (size_t i = 0; i < n; i++)
            for (int r = 0; r < NEIGHBOURS_RANGES; r++)
                for (size_t j = NB.rng[2 * NEIGHBOURS_RANGES * i + 2 * r]; j < NB.rng[2 * NEIGHBOURS_RANGES * i + 2 * r + 1];
                     j++)
                    if (dist2(&P, i, j) < rc * rc) {
                        assert_true(n_got < n_ref + 1); /* more pairs than there are: a pair met twice */
                        got[n_got++] = pair_key(&P, i, j);
                    }
        qsort(ref, n_ref, sizeof *ref, cmp_u64);
        qsort(got, n_got, sizeof *got, cmp_u64);
        print_message("DIM %d, kx %d: %zu pairs within rc (brute force %zu)\n", DIM, kx, n_got, n_ref);
        assert_true(n_ref > 10 * n);
        assert_int_equal(n_got, n_ref);
        assert_memory_equal(got, ref, n_ref * sizeof *ref);
        /* the gather ranges hold every neighbour of a particle (itself included) */
        assert_int_equal(neighbours_gather_reserve(&G, P.cap), 0);
        for (size_t i = 0; i < n; i++) G.mode[i] = NEIGHBOURS_GATHER_ALL;
        assert_int_equal(neighbours_gather_build(&G, &NB, &C, P.state, active, rc, 1), 0);
        for (size_t i = 0; i < n; i += 7) {
            size_t in_ranges = 0, brute = 0;
            for (int r = 0; r < CELLS_ROWS_AROUND; r++)
                for (size_t j = G.rng[2 * CELLS_ROWS_AROUND * i + 2 * r]; j < G.rng[2 * CELLS_ROWS_AROUND * i + 2 * r + 1];
                     j++)
                    in_ranges += dist2(&P, i, j) < rc * rc;
            for (size_t j = 0; j < n; j++) brute += dist2(&P, i, j) < rc * rc;
            assert_int_equal(in_ranges, brute);
        }
        /* the pair list (the 3D pair loops' candidates): every pair closer than rc but those of two
         * wall particles, each once, ascending per particle; the same on 1 and 2 threads */
        uint8_t *state = malloc(n);
        for (size_t i = 0; i < n; i++) state[i] = P.id[i] % 3 == 0 ? MIXSPH_STATE_WALL : MIXSPH_STATE_MOBILE;
        size_t n_ref_list = 0;
        for (size_t k = 0; k < n_ref; k++)
            if ((ref[k] >> 32) % 3 != 0 || (ref[k] & 0xffffffffu) % 3 != 0) ref[n_ref_list++] = ref[k];
        struct pair_list PL[2] = {{0}, {0}};
        for (int t = 0; t < 2; t++) assert_int_equal(neighbours_pair_list_build(&PL[t], &NB, state, active, rc, t + 1), 0);
        assert_int_equal(PL[0].start[n], n_ref_list);
        assert_memory_equal(PL[0].start, PL[1].start, (n + 1) * sizeof *PL[0].start);
        assert_memory_equal(PL[0].j, PL[1].j, n_ref_list * sizeof *PL[0].j);
        n_got = 0;
        for (size_t i = 0; i < n; i++)
            for (uint32_t k = PL[0].start[i]; k < PL[0].start[i + 1]; k++) {
                assert_true(k == PL[0].start[i] || PL[0].j[k] > PL[0].j[k - 1]);
                got[n_got++] = pair_key(&P, i, PL[0].j[k]);
            }
        qsort(got, n_got, sizeof *got, cmp_u64);
        print_message("DIM %d, kx %d: %zu pairs in the pair list (%zu without wall-wall pairs)\n", DIM, kx, n_got,
                      n_ref_list);
        assert_memory_equal(got, ref, n_ref_list * sizeof *ref);
        for (int t = 0; t < 2; t++) neighbours_pair_list_free(&PL[t]);
        free(state);
        free(ref);
        free(got);
        neighbours_gather_free(&G);
        neighbours_free(&NB);
        cells_free(&C);
    }
    particles_free(&P);
}


#if DIM == 3
/* The threads' blocks of the 3D pair loops (neighbours.h) on random clouds in two boxes, one
 * longer along x (blocks cut along x) and one along y (cut along y), for kx = 1 and 2: every
 * active particle in exactly one block; two blocks of one colour never write the same particle
 * (a block writes its particles and their pair-list entries: the property that lets a colour's
 * blocks run in parallel and keeps results independent of the thread count); within a colour the
 * blocks by descending work (pair-list entries plus particles). */
static void test_pair_blocks(void **state)
{
    (void)state;
    const size_t n = 6000;
    const double rc = 0.1, lo[DIM] = {0.0};
    const double boxes[2][DIM] = {{1.0, 0.4, 0.6}, {0.4, 1.0, 0.6}};
    for (int box = 0; box < 2; box++)
        for (int kx = 1; kx <= 2; kx++) {
            struct particles P;
            memset(&P, 0, sizeof P);
            uint64_t seed = 777 + (uint64_t)box;
            for (size_t k = 0; k < n; k++) {
                double p[DIM];
                for (int d = 0; d < DIM; d++) p[d] = test_random_uniform(&seed, lo[d], boxes[box][d]);
                assert_true(particles_push(&P, p, 1000.0, 1.0, 0, MIXSPH_STATE_MOBILE) != (size_t)-1);
            }
            struct cells C;
            struct neighbours NB = {0};
            assert_int_equal(cells_init_columns(&C, lo, boxes[box], rc, kx), 0);
            assert_true(cells_build(&C, &P) >= 0);
            const size_t active = C.start[C.ncell];
            assert_int_equal(neighbours_build(&NB, &C, &P, active, rc, 2), 0);
            uint8_t *st = malloc(n);
            for (size_t i = 0; i < n; i++) st[i] = P.id[i] % 3 == 0 ? MIXSPH_STATE_WALL : MIXSPH_STATE_MOBILE;
            struct pair_list PL = {0};
            struct pair_blocks B = {0};
            assert_int_equal(neighbours_pair_list_build(&PL, &NB, st, active, rc, 2), 0);
            assert_int_equal(neighbours_pair_blocks_build(&B, &PL, &C), 0);
            assert_int_equal(B.axis, box == 0 ? 0 : 1);
            long *walked = calloc(n, sizeof *walked), *writer = malloc(n * sizeof *writer);
            for (int c = 0; c < NEIGHBOURS_COLOURS; c++) {
                for (size_t i = 0; i < n; i++) writer[i] = -1;
                assert_true(B.first[c + 1] > B.first[c] + 4); /* several blocks in every colour */
                uint64_t prev_work = UINT64_MAX;
                for (size_t b = B.first[c]; b < B.first[c + 1]; b++) {
                    uint64_t work = 0;
                    for (size_t q = 0; q < neighbours_block_ranges(&B, &C); q++) {
                        const struct range r = neighbours_block_range(&B, &C, b, q);
                        work += r.end - r.begin + PL.start[r.end] - PL.start[r.begin];
                        for (size_t i = r.begin; i < r.end; i++) {
                            walked[i]++;
                            assert_true(writer[i] == -1 || writer[i] == (long)b);
                            writer[i] = (long)b;
                            for (uint32_t k = PL.start[i]; k < PL.start[i + 1]; k++) {
                                const uint32_t j = PL.j[k];
                                if (writer[j] != -1 && writer[j] != (long)b)
                                    fail_msg("box %d, kx %d: particle %u written by blocks %ld and %zu of colour %d", box,
                                             kx, j, writer[j], b, c);
                                writer[j] = (long)b;
                            }
                        }
                    }
                    assert_true(work > 0 && work <= prev_work);
                    prev_work = work;
                }
            }
            for (size_t i = 0; i < n; i++) assert_int_equal(walked[i], 1);
            print_message("box %d, kx %d: axis %d, blocks per colour %zu %zu %zu %zu\n", box, kx, B.axis,
                          B.first[1] - B.first[0], B.first[2] - B.first[1], B.first[3] - B.first[2],
                          B.first[4] - B.first[3]);
            free(walked);
            free(writer);
            free(st);
            neighbours_pair_blocks_free(&B);
            neighbours_pair_list_free(&PL);
            neighbours_free(&NB);
            cells_free(&C);
            particles_free(&P);
        }
}
#endif

/* R s R^T of a full 3x3 s. */
static void rotate3(double R[3][3], const double s[3][3], double out[3][3])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            out[i][j] = 0.0;
            for (int k = 0; k < 3; k++)
                for (int l = 0; l < 3; l++) out[i][j] += R[i][k] * s[k][l] * R[j][l];
        }
}

static void test_jaumann_rotation(void **state)
{
    (void)state;
    /* a traceless stress with every component nonzero (in 2D xy = yz = 0: plane strain) */
    const double s0[3][3] = {{-3.0e3, DIM == 3 ? 1.1e3 : 0.0, 2.0e3},
                             {DIM == 3 ? 1.1e3 : 0.0, 1.0e3, DIM == 3 ? -0.7e3 : 0.0},
                             {2.0e3, DIM == 3 ? -0.7e3 : 0.0, 2.0e3}};
    const double w = 3.0, dt = 1e-3, G = 1e7;
    const int steps = 1000;
    for (int axis = DIM == 2 ? 1 : 0; axis < (DIM == 2 ? 2 : 3); axis++) {
        /* the spin about `axis` (3D numbering x 0, y 1, z 2): L = W, W_ab = -eps_abk w e_k */
        double L3[3][3] = {{0.0}};
        const int a = (axis + 1) % 3, b = (axis + 2) % 3;
        L3[a][b] = -w;
        L3[b][a] = w;
        double L[DIM * DIM];
        const int map[3] = {0, DIM == 2 ? 2 : 1, 2}; /* component d -> 3D axis */
        for (int i = 0; i < DIM; i++)
            for (int j = 0; j < DIM; j++) L[i * DIM + j] = L3[map[i]][map[j]];
        struct deviatoric_stress s = {.xx = s0[0][0], .zz = s0[2][2], .xz = s0[0][2], .yy = s0[1][1]};
#if DIM == 3
        s.xy = s0[0][1];
        s.yz = s0[1][2];
#endif
        for (int k = 0; k < steps; k++) elasticity_jaumann_step(&s, L, G, dt);
        /* reference: the rotation exp(theta K), K = W / w, by theta = steps 2 atan(w dt / 2) */
        const double theta = steps * 2.0 * atan(0.5 * w * dt);
        double K[3][3], R[3][3], ref[3][3];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) K[i][j] = L3[i][j] / w;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                double k2 = 0.0;
                for (int m = 0; m < 3; m++) k2 += K[i][m] * K[m][j];
                R[i][j] = (i == j) + sin(theta) * K[i][j] + (1.0 - cos(theta)) * k2;
            }
        rotate3(R, s0, ref);
#if DIM == 3
        const double xy = s.xy, yz = s.yz;
#else
        const double xy = 0.0, yz = 0.0;
#endif
        const double got[3][3] = {{s.xx, xy, s.xz}, {xy, s.yy, yz}, {s.xz, yz, s.zz}};
        double err = 0.0;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) err = fmax(err, fabs(got[i][j] - ref[i][j]));
        print_message("DIM %d, spin about axis %d by %.3f rad: largest error %.3g Pa of 3e3\n", DIM, axis, theta, err);
        /* reference: the exact rotation; tolerance 1e-9 of the stress (round-off of 1000 steps) */
        assert_true(err < 1e-9 * 3e3);
        assert_true(fabs(ref[0][0] - s0[0][0]) > 100.0 || fabs(ref[2][2] - s0[2][2]) > 100.0); /* it did rotate */
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_kernel_normalisation),
        cmocka_unit_test(test_neighbours_brute_force),
#if DIM == 3
        cmocka_unit_test(test_pair_blocks),
#endif
        cmocka_unit_test(test_jaumann_rotation),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
