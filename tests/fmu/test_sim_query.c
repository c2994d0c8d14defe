/* test_sim_query.c - the library queries the FMU asks (lib/src/io/sim_query.c, the last section of
 * mixsph.h): a case's walls, whether they move and which way, and the parameters a case file
 * declares. On the two landslide cases the FMU runs, cases/vajont_padua.json and
 * cases/slope_tank.json, whose walls and motions are named differently, and on the water dam
 * break, which has no moving wall and no parameters block. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "mixsph.h"

#define CASE(name) MIXSPH_SOURCE_DIR "/cases/" name

/* The case at coarse spacing (particle generation only; nothing is stepped). */
static mixsph_sim *coarse(const char *path)
{
    const mixsph_override ov[] = {{"numerics.dx", 0.03}};
    char err[1024] = "";
    mixsph_sim *s = NULL;
    if (mixsph_sim_create(path, ov, 1, &s, err, sizeof err) != MIXSPH_OK) fail_msg("%s: %s", path, err);
    return s;
}

/* Wall k is called `name`, moves or not as `moves` says, and (if it moves) travels along the
 * unit vector of (vx, vz), the fastest row of its motion table as written in the case file. */
static void assert_wall(const mixsph_sim *s, size_t k, const char *name, int moves, double vx, double vz)
{
    assert_string_equal(mixsph_sim_wall_name(s, k), name);
    assert_int_equal(mixsph_sim_wall_moves(s, k), moves);
    double ux = NAN, uz = NAN;
    const mixsph_status st = mixsph_sim_wall_travel_direction(s, k, &ux, &uz);
    if (!moves) {
        assert_int_equal(st, MIXSPH_ERR_ARG);
        assert_true(ux == 0.0 && uz == 0.0);
        return;
    }
    assert_int_equal(st, MIXSPH_OK);
    const double speed = hypot(vx, vz);
    /* the same division of the same numbers: exactly equal */
    assert_true(ux == vx / speed);
    assert_true(uz == vz / speed);
}

static void test_walls_of_the_two_landslide_cases(void **state)
{
    (void)state;
    mixsph_sim *vajont = coarse(CASE("vajont_padua.json"));
    assert_int_equal(mixsph_sim_wall_count(vajont), 2);
    assert_wall(vajont, 0, "bed", 0, 0.0, 0.0);
    assert_wall(vajont, 1, "plate", 1, 0.6220, -0.056540); /* its top speed, held from 0.30 to 0.60 s */
    assert_null(mixsph_sim_wall_name(vajont, 2));
    assert_int_equal(mixsph_sim_wall_moves(vajont, 2), 0);
    mixsph_sim_destroy(vajont);

    mixsph_sim *slope = coarse(CASE("slope_tank.json"));
    assert_int_equal(mixsph_sim_wall_count(slope), 2);
    assert_wall(slope, 0, "basin", 0, 0.0, 0.0);
    assert_wall(slope, 1, "ram", 1, 0.715, -0.358);
    mixsph_sim_destroy(slope);

    mixsph_sim *dambreak = coarse(CASE("dambreak_water.json"));
    for (size_t k = 0; k < mixsph_sim_wall_count(dambreak); k++) assert_int_equal(mixsph_sim_wall_moves(dambreak, k), 0);
    mixsph_sim_destroy(dambreak);
}

static void test_declared_parameters(void **state)
{
    (void)state;
    char err[1024] = "";
    int declared = -1;
    assert_int_equal(mixsph_case_declares_parameter(CASE("vajont_padua.json"), "porosity", &declared, err, sizeof err), MIXSPH_OK);
    assert_int_equal(declared, 1);
    assert_int_equal(mixsph_case_declares_parameter(CASE("vajont_padua.json"), "dx", &declared, err, sizeof err), MIXSPH_OK);
    assert_int_equal(declared, 0); /* a numerics key, not a parameter */
    assert_int_equal(mixsph_case_declares_parameter(CASE("slope_tank.json"), "mu_thr", &declared, err, sizeof err), MIXSPH_OK);
    assert_int_equal(declared, 0);
    assert_int_equal(mixsph_case_declares_parameter(CASE("dambreak_water.json"), "phi", &declared, err, sizeof err), MIXSPH_OK);
    assert_int_equal(declared, 0); /* no parameters block at all */

    char names[512];
    size_t n = 0;
    assert_int_equal(mixsph_case_parameter_names(CASE("slope_tank.json"), names, sizeof names, &n, err, sizeof err), MIXSPH_OK);
    assert_string_equal(names, "reservoir_level, phi, porosity, grain_density, saturated, plate_duration_scale, "
                               "plate_stroke_scale, bed_friction");
    assert_int_equal(n, 8);
    assert_int_equal(mixsph_case_parameter_names(CASE("dambreak_water.json"), names, sizeof names, &n, err, sizeof err), MIXSPH_OK);
    assert_string_equal(names, "");
    assert_int_equal(n, 0);
    /* a buffer too short: cut, terminated, and the count is still all of them */
    char short_buf[10];
    assert_int_equal(mixsph_case_parameter_names(CASE("slope_tank.json"), short_buf, sizeof short_buf, &n, err, sizeof err), MIXSPH_OK);
    assert_string_equal(short_buf, "reservoir");
    assert_int_equal(n, 8);
}

static void test_unreadable_cases_are_errors_with_a_message(void **state)
{
    (void)state;
    char err[1024] = "";
    int declared = -1;
    assert_int_equal(mixsph_case_declares_parameter(CASE("no_such_case.json"), "phi", &declared, err, sizeof err), MIXSPH_ERR_IO);
    assert_non_null(strstr(err, "no_such_case.json"));
    assert_int_equal(declared, 0);
    char names[64];
    size_t n = 99;
    assert_int_equal(mixsph_case_parameter_names(CASE("README.md"), names, sizeof names, &n, err, sizeof err), MIXSPH_ERR_CASE);
    assert_non_null(strstr(err, "not valid JSON"));
    assert_int_equal(n, 0);
    assert_int_equal(mixsph_case_declares_parameter(NULL, "phi", &declared, err, sizeof err), MIXSPH_ERR_ARG);
    assert_int_equal(mixsph_sim_wall_count(NULL), 0);
    assert_null(mixsph_sim_wall_name(NULL, 0));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_walls_of_the_two_landslide_cases),
        cmocka_unit_test(test_declared_parameters),
        cmocka_unit_test(test_unreadable_cases_are_errors_with_a_message),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
