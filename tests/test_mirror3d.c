/* test_mirror3d.c - water at rest beside mirror side walls (DIM = 3 build; tests/CMakeLists.txt,
 * MIXSPH_DIM3_TESTS): a column 0.2 m wide (x), 4 dx across (y in [0, 0.08] m) and H = 0.2 m deep in
 * an extruded polyline tank whose side_walls are "mirror" (walls/mirror_sides.h: the planes
 * y = 0 and y = 0.08 m are planes of symmetry, images instead of wall particles), dx = 0.02 m,
 * run to t = 0.4 s on one thread; and an elastic column (below). Both: 4.5 s on one thread
 * (12-08, load average 0.7).
 *
 * What is checked, at t = 0.2, 0.3 and 0.4 s:
 * - no particle of the run crosses a plane: every water particle has 0 < y < W, and every image
 *   (MIXSPH_STATE_IMAGE) lies beyond a plane (they exist: the first and last lanes are within
 *   2h of the planes);
 * - in each horizontal layer of height dx below the surface rows, the mean pressure of the lanes
 *   next to the planes (y < dx or y > W - dx) equals that of the inner lanes, and both equal
 *   hydrostatics; reference rho0 g (z_s - z), z_s the mean height of the top row plus dx / 2,
 *   tolerances at the assertions. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <cmocka.h>

#include "dim.h"
#include "mixsph.h"

#if DIM != 3
#error "test_mirror3d is the DIM = 3 build's test"
#endif

#define RHO0 1000.0 /* [kg/m3] */
#define G 9.81      /* [m/s2] */
#define DX 0.02     /* [m] */
#define W 0.08      /* the flume's width, 4 dx [m] */
#define NLAYER 16
/* the cubic lattice's bias of the SPH pressure gradient (test_tank3d.c): p / 0.9935 */
#define LATTICE_BIAS 0.0066

static const char *const CASE_TEXT =
    "{\"name\": \"mirror_column\", \"dimensions\": 3, \"gravity\": 9.81,"
    " \"numerics\": {\"dx\": 0.02, \"h_over_dx\": 1.3, \"cfl\": 0.1, \"cfl_visc\": 0.05, \"t_end\": 0.4,"
    "   \"wall_layers\": 3, \"density_diffusion\": 0, \"density_bound\": 0},"
    " \"domain\": {\"x_min\": -0.1, \"x_max\": 0.3, \"y_min\": -0.1, \"y_max\": 0.18, \"z_min\": -0.1, \"z_max\": 0.4},"
    " \"media\": {\"water\": {\"type\": \"fluid\", \"rho\": 1000.0, \"K\": 6.25e5, \"mu\": 1.0e-3, \"alpha_m\": 0.1}},"
    " \"bodies\": {\"column\": {\"medium\": \"water\", \"polygon\": [[0, 0], [0.2, 0], [0.2, 0.2], [0, 0.2]],"
    "   \"y_min\": 0.0, \"y_max\": 0.08}},"
    " \"walls\": {\"tank\": {\"polyline\": [[0, 0.3], [0, 0], [0.2, 0], [0.2, 0.3]], \"fluid_side\": \"left\","
    "   \"slip\": \"free-slip\", \"y_min\": 0.0, \"y_max\": 0.08, \"side_walls\": \"mirror\"}},"
    " \"monitors\": {}, \"output\": {\"monitor_interval\": 0.01}}";

static void test_column_beside_mirror_walls(void **state)
{
    (void)state;
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_status created = mixsph_sim_create_from_text(CASE_TEXT, "mirror_column", NULL, 0, &s, err, sizeof err);
    if (created != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(created, MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
    assert_int_equal(mixsph_sim_particles(s), 10 * 4 * 10);
    double worst_lane = 0.0, worst_rel = 0.0;
    for (int k = 0; k < 3; k++) {
        const double t = 0.2 + 0.1 * k;
        const mixsph_status st = mixsph_sim_advance_to(s, t);
        if (st != MIXSPH_OK) print_error("%s\n", mixsph_sim_last_error(s));
        assert_int_equal(st, MIXSPH_OK);
        mixsph_particles_view v;
        assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
        double ztop = -INFINITY;
        size_t images = 0, water = 0;
        for (size_t i = 0; i < v.n; i++) {
            const double y = v.pos[1][i];
            if (v.state[i] == MIXSPH_STATE_IMAGE) {
                images++;
                assert_true(y < 0.0 || y > W);
                continue;
            }
            if (v.state[i] == MIXSPH_STATE_WALL) continue;
            assert_int_equal(v.state[i], MIXSPH_STATE_MOBILE);
            water++;
            if (!(y > 0.0 && y < W)) print_error("particle %u at y = %g crossed a mirror plane\n", v.id[i], y);
            assert_true(y > 0.0 && y < W);
            ztop = fmax(ztop, v.pos[2][i]);
        }
        assert_int_equal(water, 400);
        assert_true(images >= 200); /* the lanes y = dx/2 and W - dx/2, each imaged (also the 2nd lanes, 1.5 dx < 2h) */
        double sz_top = 0.0, sp[2][NLAYER] = {{0}}, sz[2][NLAYER] = {{0}};
        int n_top = 0, cnt[2][NLAYER] = {{0}};
        for (size_t i = 0; i < v.n; i++) {
            if (v.state[i] != MIXSPH_STATE_MOBILE) continue;
            const double y = v.pos[1][i], z = v.pos[2][i];
            if (z > ztop - 0.5 * DX) {
                sz_top += z;
                n_top++;
            }
            const int near = y < DX || y > W - DX, b = (int)floor(z / DX);
            assert_true(b >= 0 && b < NLAYER);
            sp[near][b] += v.p[i];
            sz[near][b] += z;
            cnt[near][b]++;
        }
        const double zs = sz_top / n_top + 0.5 * DX;
        for (int b = 0; b < NLAYER; b++) {
            if (cnt[0][b] == 0 || cnt[1][b] == 0) continue;
            const double z = (sz[0][b] + sz[1][b]) / (cnt[0][b] + cnt[1][b]), p_ref = RHO0 * G * (zs - z);
            if (zs - z <= 2.0 * DX) continue; /* the surface rows */
            const double p_in = sp[0][b] / cnt[0][b], p_near = sp[1][b] / cnt[1][b];
            /* reference: the inner lanes' pressure (a plane of symmetry exerts no force of its own);
             * tolerance 1 % of the local hydrostatic pressure (issue 57's criterion for a probe) */
            worst_lane = fmax(worst_lane, fabs(p_near - p_in) / p_ref);
            assert_true(fabs(p_near - p_in) <= 0.01 * p_ref);
            /* reference: hydrostatics, rho0 g (z_s - z); tolerance as test_tank3d.c: 1 % plus the
             * lattice bias plus the head of half a spacing (the SPH surface is defined to dx / 2) */
            const double tol = (0.01 + LATTICE_BIAS) * p_ref + 0.5 * RHO0 * G * DX;
            for (int near = 0; near < 2; near++) {
                const double p = sp[near][b] / cnt[near][b];
                worst_rel = fmax(worst_rel, fabs(p - p_ref) / p_ref);
                assert_true(fabs(p - p_ref) <= tol);
            }
        }
        print_message("t = %.1f s: %zu images, surface z_s = %.4f m\n", t, images, zs);
    }
    print_message("lanes next to the mirror planes against the inner lanes: within %.3f %% of rho0 g (z_s - z); "
                  "layers against hydrostatics within %.2f %%\n", 100.0 * worst_lane, 100.0 * worst_rel);
    mixsph_sim_destroy(s);
}

/* An elastic column (a law with a stress and the velocity gradient: the images carry the stress
 * mirrored, and the set's growth by the images reaches the gradient's arrays, which overran
 * before they grew with it) at rest between the same planes, 0.2 m tall, to t = 0.015 s (about
 * 350 steps): it runs, no particle crosses a plane, and in each layer below the top rows the
 * lanes next to the planes carry the inner lanes' pressure within 1 % of rho0 g (z_s - z)
 * (reference: the inner lanes, as above). */
static const char *const ELASTIC_TEXT =
    "{\"name\": \"mirror_elastic\", \"dimensions\": 3, \"gravity\": 9.81,"
    " \"numerics\": {\"dx\": 0.02, \"h_over_dx\": 1.3, \"cfl\": 0.1, \"cfl_visc\": 0.05, \"t_end\": 0.015,"
    "   \"wall_layers\": 3, \"density_diffusion\": 0, \"density_bound\": 0},"
    " \"domain\": {\"x_min\": -0.1, \"x_max\": 0.3, \"y_min\": -0.1, \"y_max\": 0.18, \"z_min\": -0.1, \"z_max\": 0.4},"
    " \"media\": {\"solid\": {\"type\": \"elastic\", \"rho\": 2000.0, \"E\": 1.0e7, \"nu\": 0.3, \"alpha_m\": 0.2}},"
    " \"bodies\": {\"column\": {\"medium\": \"solid\", \"polygon\": [[0, 0], [0.2, 0], [0.2, 0.2], [0, 0.2]],"
    "   \"y_min\": 0.0, \"y_max\": 0.08}},"
    " \"walls\": {\"tank\": {\"polyline\": [[0, 0.3], [0, 0], [0.2, 0], [0.2, 0.3]], \"fluid_side\": \"left\","
    "   \"slip\": \"free-slip\", \"y_min\": 0.0, \"y_max\": 0.08, \"side_walls\": \"mirror\"}},"
    " \"monitors\": {}, \"output\": {\"monitor_interval\": 0.01}}";

static void test_elastic_column_beside_mirror_walls(void **state)
{
    (void)state;
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_status created = mixsph_sim_create_from_text(ELASTIC_TEXT, "mirror_elastic", NULL, 0, &s, err, sizeof err);
    if (created != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(created, MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
    const mixsph_status st = mixsph_sim_advance_to(s, 0.015);
    if (st != MIXSPH_OK) print_error("%s\n", mixsph_sim_last_error(s));
    assert_int_equal(st, MIXSPH_OK);
    mixsph_particles_view v;
    assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
    double sp[2][NLAYER] = {{0}}, ztop = -INFINITY;
    int cnt[2][NLAYER] = {{0}};
    for (size_t i = 0; i < v.n; i++) {
        if (v.state[i] != MIXSPH_STATE_MOBILE && v.state[i] != MIXSPH_STATE_FIXED) continue;
        const double y = v.pos[1][i], z = v.pos[2][i];
        assert_true(y > 0.0 && y < W);
        ztop = fmax(ztop, z);
        const int near = y < DX || y > W - DX, b = (int)floor(z / DX);
        assert_true(b >= 0 && b < NLAYER);
        sp[near][b] += v.p[i];
        cnt[near][b]++;
    }
    const double rho0 = 2000.0;
    double worst = 0.0;
    for (int b = 0; b < NLAYER; b++) {
        const double z = (b + 0.5) * DX, p_ref = rho0 * G * (ztop + 0.5 * DX - z);
        if (cnt[0][b] == 0 || cnt[1][b] == 0 || ztop + 0.5 * DX - z <= 2.0 * DX) continue;
        const double diff = fabs(sp[1][b] / cnt[1][b] - sp[0][b] / cnt[0][b]);
        worst = fmax(worst, diff / p_ref);
        assert_true(diff <= 0.01 * p_ref); /* reference: the inner lanes; tolerance 1 % of rho0 g (z_s - z) */
    }
    print_message("elastic column: lanes next to the planes against the inner lanes within %.3f %% of rho0 g (z_s - z)\n",
                  100.0 * worst);
    mixsph_sim_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_column_beside_mirror_walls),
        cmocka_unit_test(test_elastic_column_beside_mirror_walls),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
