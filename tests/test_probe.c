/* test_probe.c - the pressure_probe monitor (lib/src/io/monitors.c, docs/model.md section 9): the
 * Shepard-normalised kernel interpolation of the fluid's pressure at a point, a sensor on a wall
 * read 1.5 h from it into the fluid, 0 where no fluid is near, and bad definitions refused with a
 * message naming the key.
 *
 * The tank of cases/hydrostatic_tank.json (water H = 0.3 m deep at rest, 0.4 m wide, dx = 0.01,
 * cubic spline at h = 1.3 dx) with probes added:
 *   mid     (0.2, 0.15)   a point in the water, 15 cm deep;
 *   deep    (0.13, 0.047) a point off the lattice's symmetry lines, near the floor (4.7 cm);
 *   side    (0.4, 0.1)    a sensor on the right wall: read at (0.4 - 1.5 h, 0.1);
 *   floor   (0.2, 0.0)    a sensor on the floor: read at (0.2, 1.5 h);
 *   corner  (0.4, 0.003)  a sensor on the right wall 3 mm above the floor (Lobovsky's P1):
 *                         read at (0.4 - 1.5 h, 0.003), its support cut by the floor;
 *   air     (0.2, 0.45)   15 cm above the water: dry.
 * Reference: the hydrostatic pressure rho0 g (z_s - z) at the height z the probe reads at. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "edit_text.h"

#include "case.h"
#include "mixsph.h"

#define RHO0 1000.0 /* [kg/m3] */
#define G 9.81      /* [m/s2] */
#define DEPTH 0.3   /* [m] */
#define DX 0.01     /* [m] */
#define H_SPH (1.3 * DX)
#define STANDOFF (1.5 * H_SPH) /* a wall probe's distance from the wall (monitors.c) */

static const char *const PROBES =
    "\"monitors\": {\n"
    "    \"mid\": { \"type\": \"pressure_probe\", \"x\": 0.2, \"z\": 0.15 },\n"
    "    \"deep\": { \"type\": \"pressure_probe\", \"x\": 0.13, \"z\": 0.047 },\n"
    "    \"side\": { \"type\": \"pressure_probe\", \"x\": 0.4, \"z\": 0.1, \"wall\": \"tank\" },\n"
    "    \"floor\": { \"type\": \"pressure_probe\", \"x\": 0.2, \"z\": 0.0, \"wall\": \"tank\" },\n"
    "    \"corner\": { \"type\": \"pressure_probe\", \"x\": 0.4, \"z\": 0.003, \"wall\": \"tank\" },\n"
    "    \"air\": { \"type\": \"pressure_probe\", \"x\": 0.2, \"z\": 0.45 },\n";

struct probe {
    const char *name;
    double z_read;  /* the height the probe reads at [m] */
    int near_wall;  /* its kernel support is cut by a wall (the floor) */
};
static const struct probe WET[] = {{"mid", 0.15, 0},       {"deep", 0.047, 0}, {"side", 0.1, 0},
                                   {"floor", STANDOFF, 0}, {"corner", 0.003, 1}};
#define N_WET (sizeof WET / sizeof WET[0])

/* The hydrostatic tank's text with the monitors block opened by `monitors` (caller frees). */
static char *tank_with(const char *monitors)
{
    char err[512], *text = NULL;
    if (case_read_file(MIXSPH_SOURCE_DIR "/cases/hydrostatic_tank.json", &text, err, sizeof err) != MIXSPH_OK)
        fail_msg("%s", err);
    char *out = edit_text(text, "\"monitors\": {\n", monitors);
    free(text);
    return out;
}

static double output(const mixsph_sim *s, const char *name)
{
    const long k = mixsph_sim_output_find(s, name);
    assert_true(k >= 0);
    return mixsph_sim_output_value(s, (size_t)k);
}

/* The free surface z_s: the mean height of the top row of water particles plus dx/2
 * (test_hydrostatic.c: z_s = H at t = 0). */
static double free_surface(const mixsph_sim *s)
{
    mixsph_particles_view v;
    assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
    double ztop = -INFINITY, sz = 0.0;
    int n = 0;
    for (size_t i = 0; i < v.n; i++)
        if (v.state[i] != MIXSPH_STATE_WALL) ztop = fmax(ztop, v.pos[v.dim - 1][i]);
    for (size_t i = 0; i < v.n; i++)
        if (v.state[i] != MIXSPH_STATE_WALL && v.pos[v.dim - 1][i] > ztop - 0.5 * DX) {
            sz += v.pos[v.dim - 1][i];
            n++;
        }
    assert_true(n >= 38); /* the top row has 40 particles */
    return sz / n + 0.5 * DX;
}

/* At t = 0 every particle holds the hydrostatic pressure of its lattice column, rho0 g (H - z_j)
 * (sim.c), and the probes read that linear field through the kernel. Reference: rho0 g (H - z).
 * Tolerance, away from walls: 0.005 rho0 g dx (0.49 Pa): the kernel-weighted centre of the
 * lattice sites around a point off their symmetry lines is off the point by at most 0.0035 dx
 * (computed for the cubic spline at h = 1.3 dx over a 21 x 21 grid of positions within a lattice
 * cell; the Shepard normalisation takes out the kernel sum's own lattice error). Near the floor (corner, 3 mm up): the support below the floor holds no fluid,
 * so the weighted centre of the fluid sites lies above the point, by less than dx/2 (the first
 * row is at dx/2): tolerance rho0 g dx/2. The dry probe reads exactly 0. */
static void test_probe_initial_field(void **state)
{
    (void)state;
    char *json = tank_with(PROBES), err[512] = "";
    mixsph_sim *s = NULL;
    if (mixsph_sim_create_from_text(json, "tank_probes.json", NULL, 0, &s, err, sizeof err) != MIXSPH_OK)
        fail_msg("%s", err);
    free(json);
    for (size_t k = 0; k < N_WET; k++) {
        const double p = output(s, WET[k].name), p_ref = RHO0 * G * (DEPTH - WET[k].z_read);
        const double tol = WET[k].near_wall ? 0.5 * RHO0 * G * DX : 0.005 * RHO0 * G * DX;
        print_message("t = 0: %-6s reads %9.3f Pa, rho0 g (H - z) = %9.3f Pa (%+.3f Pa, tolerance %.1f Pa)\n",
                      WET[k].name, p, p_ref, p - p_ref, tol);
        assert_true(fabs(p - p_ref) <= tol);
    }
    assert_true(output(s, "air") == 0.0);
    mixsph_sim_destroy(s);
}

/* The column run to t = 0.5 s, with the density diffusion off (as the case has it) and on: the
 * probes at t = 0.3, 0.4, 0.5 s against rho0 g (z_s - z), z_s the free surface measured then.
 * Tolerance (test_hydrostatic.c's, for the same reasons): 1.05 % of it (a column on the lattice
 * settles at p / 1.0105 with the cubic spline at h = 1.3 dx, kernel.h) plus rho0 g dx/2 (the
 * free surface of SPH is known to about half a spacing; near the floor, also the bound of the
 * shift of the probe's weighted centre, above). The probe in the air reads 0 at every sample
 * of the run (its largest value over the run is 0). */
static void run_column(const mixsph_override *ov, size_t n_ov)
{
    char *json = tank_with(PROBES), err[512] = "";
    mixsph_sim *s = NULL;
    if (mixsph_sim_create_from_text(json, "tank_probes.json", ov, n_ov, &s, err, sizeof err) != MIXSPH_OK)
        fail_msg("%s", err);
    free(json);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK); /* ctest -j runs tests side by side */
    double worst = 0.0;
    for (int i = 3; i <= 5; i++) {
        const mixsph_status st = mixsph_sim_advance_to(s, 0.1 * i);
        if (st != MIXSPH_OK) fail_msg("%s", mixsph_sim_last_error(s));
        const double zs = free_surface(s);
        for (size_t k = 0; k < N_WET; k++) {
            const double p = output(s, WET[k].name), p_ref = RHO0 * G * (zs - WET[k].z_read);
            const double tol = 0.0105 * p_ref + 0.5 * RHO0 * G * DX;
            print_message("t = %.2f s: %-6s reads %9.2f Pa, rho0 g (z_s - z) = %9.2f Pa (%+7.2f Pa, %.2f of the "
                          "tolerance)\n",
                          mixsph_sim_time(s), WET[k].name, p, p_ref, p - p_ref, fabs(p - p_ref) / tol);
            worst = fmax(worst, fabs(p - p_ref) / tol);
            assert_true(fabs(p - p_ref) <= tol);
        }
    }
    double max, t_max, min, t_min;
    const long air = mixsph_sim_output_find(s, "air");
    assert_true(air >= 0);
    mixsph_sim_output_extremes(s, (size_t)air, &max, &t_max, &min, &t_min);
    assert_true(max == 0.0 && min == 0.0);
    print_message("largest error %.2f of the tolerance; the air probe read 0 throughout\n", worst);
    mixsph_sim_destroy(s);
}

static void test_probe_settled_column(void **state)
{
    (void)state;
    run_column(NULL, 0);
}

static void test_probe_settled_column_diffusion(void **state)
{
    (void)state;
    const mixsph_override ov[] = {{"numerics.density_diffusion", 0.1}};
    run_column(ov, 1);
}

/* Creating the tank with the monitors block opened by `monitors` fails with MIXSPH_ERR_CASE and
 * a message holding every string of the NULL-terminated list. */
static int create_fails(const char *monitors, ...)
{
    char *json = tank_with(monitors), err[512] = "";
    mixsph_sim *s = NULL;
    const mixsph_status st = mixsph_sim_create_from_text(json, "tank_probes.json", NULL, 0, &s, err, sizeof err);
    free(json);
    mixsph_sim_destroy(s);
    print_message("  -> %s\n", err);
    int ok = st == MIXSPH_ERR_CASE && s == NULL;
    va_list ap;
    va_start(ap, monitors);
    for (const char *needle = va_arg(ap, const char *); needle; needle = va_arg(ap, const char *))
        if (!strstr(err, needle)) {
            print_error("message lacks \"%s\"\n", needle);
            ok = 0;
        }
    va_end(ap);
    return ok;
}

#define EXPECT_REFUSED(monitors, ...) assert_true(create_fails((monitors), __VA_ARGS__, (const char *)NULL))

/* Bad probe definitions: each refused at creation, the message naming the monitor and the key. */
static void test_probe_refused(void **state)
{
    (void)state;
    EXPECT_REFUSED("\"monitors\": { \"P\": { \"type\": \"pressure_probe\", \"z\": 0.1 },\n",
                   "tank_probes.json: monitors.P.x: missing");
    EXPECT_REFUSED("\"monitors\": { \"P\": { \"type\": \"pressure_probe\", \"x\": 0.1 },\n",
                   "tank_probes.json: monitors.P.z: missing");
    EXPECT_REFUSED("\"monitors\": { \"P\": { \"type\": \"pressure_probe\", \"x\": \"left\", \"z\": 0.1 },\n",
                   "monitors.P.x: expected a number");
    EXPECT_REFUSED("\"monitors\": { \"P\": { \"type\": \"pressure_probe\", \"x\": 0.4, \"z\": 0.1, \"wall\": \"dam\" },\n",
                   "monitors.P.wall: 'dam' is not one of the walls");
    EXPECT_REFUSED("\"monitors\": { \"P\": { \"type\": \"pressure_probe\", \"x\": 0.4, \"z\": 0.1, \"medium\": \"water\" },\n",
                   "monitors.P.medium: a pressure_probe monitor does not take this key");
    EXPECT_REFUSED("\"monitors\": { \"P\": { \"type\": \"pressure_probe\", \"x\": 0.4, \"z\": 0.1, \"z_max\": 0.2 },\n",
                   "monitors.P.z_max: a pressure_probe monitor does not take this key");
    /* a sensor 2 cm inside the water is not on the wall (within dx/2) */
    EXPECT_REFUSED("\"monitors\": { \"P\": { \"type\": \"pressure_probe\", \"x\": 0.38, \"z\": 0.1, \"wall\": \"tank\" },\n",
                   "tank_probes.json: monitors.P: the point (0.38, 0.1) is not on the wall 'tank'", "0.02 m from it");
    /* beyond the wall's open top end (z = 0.5) */
    EXPECT_REFUSED("\"monitors\": { \"P\": { \"type\": \"pressure_probe\", \"x\": 0.4, \"z\": 0.503, \"wall\": \"tank\" },\n",
                   "monitors.P: the point (0.4, 0.503) is not on the wall 'tank'", "beyond its end");
    /* a point outside the domain (the bounding box of the tank, with room above) */
    EXPECT_REFUSED("\"monitors\": { \"P\": { \"type\": \"pressure_probe\", \"x\": 3.0, \"z\": 0.1 },\n",
                   "tank_probes.json: monitors.P: the point the probe reads at, (3, 0.1), is outside the domain");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_probe_initial_field),
        cmocka_unit_test(test_probe_settled_column),
        cmocka_unit_test(test_probe_settled_column_diffusion),
        cmocka_unit_test(test_probe_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
