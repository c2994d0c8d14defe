/* test_budget.c - the resource budget (budget.c): its estimates are what creation then asks for.
 * For every bundled case at its own dx and at half of it (where budgets matter: finer runs):
 * - the particle estimate (the bodies' clipped areas over dx^2) is within LATTICE_TOLERANCE of the
 *   lattice sites inside each body counted one body at a time (the rows along the outline are what
 *   differs), and at least the particles created less that tolerance: overlapping bodies count twice
 *   (Vajont's reservoir holds the lower slide, so there the estimate is about 1.4 times the count),
 *   so the estimate errs high, never low, and a case within its limit has at most that many;
 * - the wall particles created are within LATTICE_TOLERANCE of their estimate (length x layers / dx;
 *   the corners differ), and the lattice sites scanned are at least all particles;
 * - the first time step is at most the estimate's up to the density variation a weakly
 *   compressible run allows (the estimate takes the reference density; the hydrostatic start
 *   compresses the deepest particles by well under DENSITY_VARIATION at Mach 0.1), so the step
 *   estimate is a lower bound on the steps up to it.
 * Also the clipped polygon area against a
 * hand computation. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "budget.h"
#include "geometry.h"
#include "sim.h"

#define LATTICE_TOLERANCE 0.05 /* relative, see the head of the file */
#define DENSITY_VARIATION 0.05  /* relative; WCSPH keeps |rho - rho0| / rho0 near Mach^2 = 1 % */

static void area_in_band(void **state)
{
    (void)state;
    /* the triangle (0,0), (2,0), (0,2): area 2; below z = 1: 2 - 0.5 = 1.5; between 0.5 and 1: the
     * trapezoid of widths 1.5 and 1, 0.5 high = 0.625 */
    double x[] = {0.0, 2.0, 0.0}, z[] = {0.0, 0.0, 2.0};
    const struct polyline tri = {3, x, z};
    assert_float_equal(geom_polygon_area_in_band(&tri, -INFINITY, INFINITY), 2.0, 1e-12);
    assert_float_equal(geom_polygon_area_in_band(&tri, -INFINITY, 1.0), 1.5, 1e-12);
    assert_float_equal(geom_polygon_area_in_band(&tri, 0.5, 1.0), 0.625, 1e-12);
    assert_float_equal(geom_polygon_area_in_band(&tri, 3.0, 4.0), 0.0, 1e-12);
}

/* Lattice sites inside body k, as the fill places them (sim.c), counted for this body alone. */
static double body_sites(const struct case_def *c, size_t k)
{
    const struct body *bd = &c->bodies[k];
    double x0 = INFINITY, x1 = -INFINITY, z0 = INFINITY, z1 = -INFINITY, n = 0.0;
    geom_grow_box(&bd->polygon, &x0, &x1, &z0, &z1);
    for (long kk = (long)floor(z0 / c->dx) - 1; kk <= (long)ceil(z1 / c->dx) + 1; kk++)
        for (long i = (long)floor(x0 / c->dx) - 1; i <= (long)ceil(x1 / c->dx) + 1; i++) {
            const double x = (i + 0.5) * c->dx, z = (kk + 0.5) * c->dx;
            n += z >= bd->z_min && z <= bd->z_max && geom_inside_polygon(&bd->polygon, x, z);
        }
    return n;
}

static void check_case(const char *file, double dx_factor)
{
    char path[512], err[1024];
    snprintf(path, sizeof path, "%s/cases/%s", MIXSPH_SOURCE_DIR, file);
    char *text = NULL;
    assert_int_equal(case_read_file(path, &text, err, sizeof err), MIXSPH_OK);
    struct case_def c;
    assert_int_equal(case_parse(text, path, NULL, 0, &c, err, sizeof err), MIXSPH_OK);
    const mixsph_override ov = {"numerics.dx", c.dx * dx_factor};
    case_free(&c);
    assert_int_equal(case_parse(text, path, &ov, 1, &c, err, sizeof err), MIXSPH_OK);
    struct budget b;
    budget_estimate(&c, &b);
    mixsph_sim *s = NULL;
    if (mixsph_sim_create_from_text(text, path, &ov, 1, &s, err, sizeof err) != MIXSPH_OK) fail_msg("%s", err);
    const double n = (double)mixsph_sim_particles(s), nw = (double)mixsph_sim_wall_particles(s);
    printf("%-22s dx = %-6g particles %7.0f (estimate %9.1f), wall particles %6.0f (estimate %8.1f), "
           "sites %.3g, first dt / estimate %.4f\n", file, c.dx, n, b.particles, nw, b.wall_particles,
           b.lattice_sites, mixsph_sim_dt(s) / (c.t_end / b.steps));
    double sites = 0.0;
    for (size_t k = 0; k < c.n_bodies; k++) sites += body_sites(&c, k);
    printf("%-22s   sites inside the bodies one at a time %.0f\n", "", sites);
    assert_true(fabs(b.particles - sites) <= LATTICE_TOLERANCE * sites);
    assert_true(b.particles >= (1.0 - LATTICE_TOLERANCE) * n);
    assert_true(fabs(b.wall_particles - nw) <= LATTICE_TOLERANCE * nw);
    assert_true(b.lattice_sites >= n + nw);
    assert_true(mixsph_sim_dt(s) <= c.t_end / b.steps * (1.0 + DENSITY_VARIATION));
    mixsph_sim_destroy(s);
    case_free(&c);
    free(text);
}

static void bundled_cases(void **state)
{
    (void)state;
    const char *files[] = {"dambreak_water.json", "dambreak_lobovsky.json", "erosive_dambreak.json",
                           "hydrostatic_tank.json", "slope_tank.json", "vajont_padua.json"};
    for (size_t k = 0; k < sizeof files / sizeof files[0]; k++) {
        check_case(files[k], 1.0);
        check_case(files[k], 0.5);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(area_in_band), cmocka_unit_test(bundled_cases)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
