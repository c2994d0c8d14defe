/* test_threshold_monitors.c - the threshold monitors (lib/src/io/threshold_monitors.c,
 * docs/cases.md "monitors"): runout, wave_gauge, slide_impact and speed checked against
 * analytic values on hand-made particle sets at t = 0 (bodies on the lattice, velocities set by
 * the test), and bad definitions refused with a message naming the key. Runs in well under a
 * second: no time step is taken. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "mixsph.h"
#include "monitors.h"
#include "sim_object.h"

#define DX 0.01     /* [m] */
#define RHO0 1000.0 /* [kg/m3] */

/* A case of one fluid `w` and a heavier one `g` (the monitors do not look at the law) with the
 * given bodies and monitors, on a long floor. */
static mixsph_sim *make(const char *bodies, const char *monitors)
{
    char json[8192], err[512] = "";
    snprintf(json, sizeof json,
             "{ \"name\": \"threshold_monitors\", \"gravity\": 9.81,\n"
             "  \"numerics\": { \"dx\": %g, \"t_end\": 0.1, \"density_diffusion\": 0, \"density_bound\": 0 },\n"
             "  \"media\": { \"w\": { \"type\": \"fluid\", \"rho\": %g, \"K\": 6.25e5, \"mu\": 1e-3, \"alpha_m\": 0.1 },\n"
             "             \"g\": { \"type\": \"fluid\", \"rho\": 2000, \"K\": 6.25e5, \"mu\": 1e-3, \"alpha_m\": 0.1 } },\n"
             "  \"bodies\": { %s },\n"
             "  \"walls\": { \"floor\": { \"polyline\": [[-1.5, 0.0], [1.5, 0.0]], \"fluid_side\": \"left\" } },\n"
             "  \"domain\": { \"x_min\": -1.6, \"x_max\": 1.6, \"z_min\": -0.1, \"z_max\": 2.0 },\n"
             "  \"monitors\": { %s } }",
             DX, RHO0, bodies, monitors);
    mixsph_sim *s = NULL;
    if (mixsph_sim_create_from_text(json, "threshold_monitors.json", NULL, 0, &s, err, sizeof err) != MIXSPH_OK)
        fail_msg("%s", err);
    mixsph_sim_set_threads(s, 1);
    return s;
}

static double output(const mixsph_sim *s, const char *name)
{
    const long k = mixsph_sim_output_find(s, name);
    if (k < 0) fail_msg("no output %s", name);
    return mixsph_sim_output_value(s, (size_t)k);
}

/* A case that must be refused, with a message containing `what`. */
static void refused(const char *bodies, const char *monitors, const char *what)
{
    char json[8192], err[512] = "";
    snprintf(json, sizeof json,
             "{ \"name\": \"threshold_monitors\", \"gravity\": 9.81,\n"
             "  \"numerics\": { \"dx\": %g, \"t_end\": 0.1 },\n"
             "  \"media\": { \"w\": { \"type\": \"fluid\", \"rho\": %g, \"K\": 6.25e5, \"mu\": 1e-3, \"alpha_m\": 0.1 } },\n"
             "  \"bodies\": { %s },\n"
             "  \"walls\": { \"floor\": { \"polyline\": [[-1.5, 0.0], [1.5, 0.0]], \"fluid_side\": \"left\" } },\n"
             "  \"monitors\": { %s } }",
             DX, RHO0, bodies, monitors);
    mixsph_sim *s = NULL;
    assert_int_equal(mixsph_sim_create_from_text(json, "refused.json", NULL, 0, &s, err, sizeof err), MIXSPH_ERR_CASE);
    print_message("refused: %s\n", err);
    if (!strstr(err, what)) fail_msg("expected '%s' in: %s", what, err);
}

/* Two triangular deposits of slope 1/2 on the floor, h(x) = 0.5 (1 - |x|) for |x| <= 1, one on
 * each side of x = 0, with a run-out monitor looking each way. Reference: the thickness reaches
 * the threshold 0.02 m at |x| = 1 - 0.02 / 0.5 = 0.96 m; the lattice rounds a column's thickness
 * to within dx/2 of h (rows of particles dx apart), so |x| to within (dx/2) / slope = dx; the
 * thickest column is 0.5 m within dx/2 + the spread of a particle over two columns (dx). */
static void test_runout_triangle(void **state)
{
    (void)state;
    mixsph_sim *s = make("\"right\": { \"medium\": \"w\", \"polygon\": [[0.0, 0.0], [1.0, 0.0], [0.0, 0.5]] },"
                         "\"left\": { \"medium\": \"w\", \"polygon\": [[-1.0, 0.0], [0.0, 0.0], [0.0, 0.5]] }",
                         "\"run_r\": { \"type\": \"runout\", \"medium\": \"w\", \"x_min\": 0.0, \"x_max\": 1.2, "
                         "\"threshold\": 0.02, \"min_neighbours\": 0 },"
                         "\"run_l\": { \"type\": \"runout\", \"medium\": \"w\", \"x_min\": -1.2, \"x_max\": 0.0, "
                         "\"threshold\": 0.02, \"direction\": \"-x\", \"min_neighbours\": 0 },"
                         "\"run_thick\": { \"type\": \"runout\", \"medium\": \"w\", \"x_min\": 0.0, \"x_max\": 1.2, "
                         "\"threshold\": 0.6, \"min_neighbours\": 0 }");
    const double r = output(s, "run_r"), l = output(s, "run_l"), hr = output(s, "run_r_height");
    print_message("run-out +x %.5f m, -x %.5f m (reference +-0.96 m, tolerance dx); height %.5f m (0.5 m)\n", r, l, hr);
    assert_true(fabs(r - 0.96) <= DX);
    assert_true(fabs(l + 0.96) <= DX);
    assert_true(fabs(hr - 0.5) <= 1.5 * DX);
    /* no column is 0.6 m thick: no deposit, NaN */
    assert_true(isnan(output(s, "run_thick")) && isnan(output(s, "run_thick_height")));
    mixsph_sim_destroy(s);
}

/* A pool 0.3 m deep (still level 0.3) with a bump 5 cm high over 0.7 <= x <= 0.8 and a detached
 * drop (3 x 3 particles) 0.2 m above the pool at x = 0.2. The lattice's rows lie dx apart from
 * z = dx/2, so the top row's centre + dx/2 is the polygon's top exactly (to round-off): the gauge
 * at the bump reads 0.05 m, the one under the drop 0 (the drop lies beyond the 2 dx gap). With
 * the gap rule removed, the gauge would read the drop's top there, 0.23 m (its particles have
 * enough neighbours of their own to pass min_neighbours). */
static void test_wave_gauge_pool(void **state)
{
    (void)state;
    mixsph_sim *s = make("\"pool\": { \"medium\": \"w\", \"polygon\": [[-1.0, 0.0], [1.0, 0.0], [1.0, 0.3], [0.8, 0.3], "
                         "[0.8, 0.35], [0.7, 0.35], [0.7, 0.3], [-1.0, 0.3]] },"
                         "\"drop\": { \"medium\": \"w\", \"polygon\": [[0.185, 0.5], [0.215, 0.5], [0.215, 0.53], [0.185, 0.53]] }",
                         "\"g_bump\": { \"type\": \"wave_gauge\", \"medium\": \"w\", \"x\": 0.75, \"still\": 0.3 },"
                         "\"g_drop\": { \"type\": \"wave_gauge\", \"medium\": \"w\", \"x\": 0.2, \"still\": 0.3 },"
                         "\"g_flat\": { \"type\": \"wave_gauge\", \"medium\": \"w\", \"x\": -0.5, \"still\": 0.3, \"window\": 0.05 },"
                         "\"g_dry\": { \"type\": \"wave_gauge\", \"medium\": \"w\", \"x\": 1.4, \"still\": 0.3 }");
    const double bump = output(s, "g_bump"), drop = output(s, "g_drop"), flat = output(s, "g_flat");
    print_message("eta: bump %.6f m (0.05), under the drop %.6f m (0), flat %.6f m (0)\n", bump, drop, flat);
    assert_true(fabs(bump - 0.05) <= 1e-9);
    assert_true(fabs(drop) <= 1e-9);
    assert_true(fabs(flat) <= 1e-9);
    assert_true(isnan(output(s, "g_dry"))); /* no water within the window */
    mixsph_sim_destroy(s);
}

/* A slide on a 45-degree ramp descending towards +x: a parallelogram T = 0.1 m thick normal to the
 * ramp, L = 0.4 m along it, its lowest corner at z = 0.3 (the lattice's lowest particle's lower
 * edge a little above). Every particle's velocity is set to (2, -2) m/s: V_s = 2 sqrt(2) exactly.
 * Thickness: the particle centres lie inside the slab, and the extreme ones within
 * (dx/2)(sin + cos) = 0.71 dx of its faces, so their span lies in [T - 1.42 dx, T] and
 * s = span + dx in [T - 0.42 dx, T + dx]. Mass: rho0 T L (the parallelogram's
 * area), within the lattice's count error, taken as its perimeter times dx/2. With `still`
 * below the front the impact has not happened (NaN); above it, it has. Once taken (a sample),
 * the values stay when the slide changes. */
/* A pool 0.3 m deep whose column at 0 <= x <= 0.4 holds a layer of the other medium `g` at
 * 0.1 <= z <= 0.15 (grains lying in the water): the gauge at x = 0.2 follows the column through
 * it and reads the water's surface, 0 (to round-off, as above); a gauge that stopped at the
 * layer would read the lower water's top, -0.2 m. */
static void test_wave_gauge_through_grains(void **state)
{
    (void)state;
    mixsph_sim *s = make("\"low\": { \"medium\": \"w\", \"polygon\": [[0.0, 0.0], [0.4, 0.0], [0.4, 0.1], [0.0, 0.1]] },"
                         "\"layer\": { \"medium\": \"g\", \"polygon\": [[0.0, 0.1], [0.4, 0.1], [0.4, 0.15], [0.0, 0.15]] },"
                         "\"high\": { \"medium\": \"w\", \"polygon\": [[0.0, 0.15], [0.4, 0.15], [0.4, 0.3], [0.0, 0.3]] }",
                         "\"gauge\": { \"type\": \"wave_gauge\", \"medium\": \"w\", \"x\": 0.2, \"still\": 0.3 }");
    const double eta = output(s, "gauge");
    print_message("eta through a layer of grains: %.6f m (0)\n", eta);
    assert_true(fabs(eta) <= 1e-9);
    mixsph_sim_destroy(s);
}

static void test_slide_impact_ramp(void **state)
{
    (void)state;
    const double c = sqrt(0.5), T = 0.1, L = 0.4;
    char body[512];
    /* corners: bottom-front (0.5, 0.3), up the ramp by L: (0.5 - L c, 0.3 + L c), then normal by T */
    snprintf(body, sizeof body,
             "\"slide\": { \"medium\": \"w\", \"polygon\": [[0.5, 0.3], [%.9f, %.9f], [%.9f, %.9f], [%.9f, %.9f]] }",
             0.5 + T * c, 0.3 + T * c, 0.5 - L * c + T * c, 0.3 + L * c + T * c, 0.5 - L * c, 0.3 + L * c);
    mixsph_sim *s = make(body, "\"hit\": { \"type\": \"slide_impact\", \"medium\": \"w\", \"still\": 0.32, \"angle\": 45, "
                               "\"min_neighbours\": 0 },"
                               "\"dry\": { \"type\": \"slide_impact\", \"medium\": \"w\", \"still\": 0.2, \"angle\": 45 }");
    struct particles *P = &s->phys.P;
    for (size_t i = 0; i < P->n; i++)
        if (P->state[i] != MIXSPH_STATE_WALL) {
            P->vel[0][i] = 2.0;
            P->vel[DIM_UP][i] = -2.0;
        }
    const double v = output(s, "hit_speed"), th = output(s, "hit_thickness"), m = output(s, "hit_mass");
    print_message("impact at t = %g s: V_s %.6f m/s (2 sqrt 2), s %.5f m (0.1 - 0.42 dx to 0.1 + dx), m %.3f kg/m (%.3f +- %.3f)\n",
                  output(s, "hit"), v, th, m, RHO0 * T * L, RHO0 * (T + L) * DX);
    assert_true(output(s, "hit") == 0.0);
    assert_true(fabs(v - 2.0 * sqrt(2.0)) <= 1e-12);
    assert_true(th >= T - 0.42 * DX && th <= T + DX);
    assert_true(fabs(m - RHO0 * T * L) <= RHO0 * (T + L) * DX); /* perimeter 2 (T + L) times dx/2 */
    assert_true(isnan(output(s, "dry")) && isnan(output(s, "dry_speed")));
    /* taken once: a sample keeps the values; the slide stopping afterwards does not change them */
    assert_int_equal(monitors_sample(s), MIXSPH_OK);
    for (size_t i = 0; i < P->n; i++) P->vel[0][i] = P->vel[DIM_UP][i] = 0.0;
    assert_true(output(s, "hit_speed") == v);
    mixsph_sim_destroy(s);
}

/* A block of N particles given the speeds 1, 2, ..., N m/s (in a scrambled order, half of them
 * along z): the largest is N, the 0.99 quantile the ceil(0.99 N)-th smallest, i.e. ceil(0.99 N);
 * the 0.5 quantile ceil(N/2). Exact (the bisection snaps to a particle's value). */
static void test_speed_quantile(void **state)
{
    (void)state;
    mixsph_sim *s = make("\"block\": { \"medium\": \"w\", \"polygon\": [[0.0, 0.0], [0.3, 0.0], [0.3, 0.2], [0.0, 0.2]] }",
                         "\"vmax\": { \"type\": \"speed\", \"medium\": \"w\" },"
                         "\"v99\": { \"type\": \"speed\", \"medium\": \"w\", \"quantile\": 0.99 },"
                         "\"v50\": { \"type\": \"speed\", \"medium\": \"w\", \"quantile\": 0.5 }");
    struct particles *P = &s->phys.P;
    size_t n = 0;
    for (size_t i = 0; i < P->n; i++) n += P->state[i] != MIXSPH_STATE_WALL;
    size_t k = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] == MIXSPH_STATE_WALL) continue;
        const double u = (double)((k * 7919) % n + 1); /* 7919 is prime, n = 600: a permutation */
        P->vel[0][i] = k % 2 ? u : 0.0;
        P->vel[DIM_UP][i] = k % 2 ? 0.0 : -u;
        k++;
    }
    print_message("%zu particles: max %g, q0.99 %g, q0.5 %g m/s\n", n, output(s, "vmax"), output(s, "v99"), output(s, "v50"));
    assert_int_equal(n, 600);
    assert_true(output(s, "vmax") == (double)n);
    assert_true(output(s, "v99") == ceil(0.99 * (double)n));
    assert_true(output(s, "v50") == ceil(0.5 * (double)n));
    mixsph_sim_destroy(s);
}

static void test_bad_definitions(void **state)
{
    (void)state;
    const char *pool = "\"pool\": { \"medium\": \"w\", \"polygon\": [[0.0, 0.0], [0.4, 0.0], [0.4, 0.3], [0.0, 0.3]] }";
    refused(pool, "\"r\": { \"type\": \"runout\", \"medium\": \"w\", \"x_min\": 0.0, \"x_max\": 1.0 }", "threshold");
    refused(pool, "\"r\": { \"type\": \"runout\", \"medium\": \"w\", \"threshold\": 0.02 }", "x_min and x_max");
    refused(pool, "\"g\": { \"type\": \"wave_gauge\", \"medium\": \"w\", \"x\": 0.2 }", "still");
    refused(pool, "\"g\": { \"type\": \"wave_gauge\", \"medium\": \"w\", \"x\": 0.2, \"still\": 0.3, \"x_min\": 0.0 }",
            "does not take this key");
    refused(pool, "\"i\": { \"type\": \"slide_impact\", \"medium\": \"w\", \"still\": 0.3, \"angle\": 90 }", "angle");
    refused(pool, "\"v\": { \"type\": \"speed\", \"medium\": \"w\", \"quantile\": 0 }", "quantile");
    refused(pool,
            "\"a_name_long_enough_to_leave_no_room_for_it\": { \"type\": \"slide_impact\", \"medium\": \"w\", "
            "\"still\": 0.3, \"angle\": 45 }",
            "too long");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_runout_triangle),  cmocka_unit_test(test_wave_gauge_pool),
        cmocka_unit_test(test_wave_gauge_through_grains),
        cmocka_unit_test(test_slide_impact_ramp), cmocka_unit_test(test_speed_quantile),
        cmocka_unit_test(test_bad_definitions),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
