/* test_case.c - case files (case.c, case_schema.c): every class of bad input is refused with a
 * message naming the file, the key path and what was expected; numeric overrides
 * (mixsph_override_parse and their application); reading from a file; a good case with an
 * override of numerics.dx gives the expected particle count; the key tables: each range, type,
 * variant and default of a row is what the reader enforces, and d50 is refused; the bundled Lobovsky
 * dam break's pressure monitors sit at the paper's sensors. */
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
#include "case_schema.h"
#include "mixsph.h"
#include "numerics_keys.h"
#include "sim_object.h"

#define ORIGIN "tiny.json"

/* A valid case; one key per line where the tests below alter it. */
static const char *const BASE =
    "{\n"                                                                                     /* 1 */
    "  \"name\": \"tiny\",\n"                                                                 /* 2 */
    "  \"gravity\": 9.81,\n"                                                                  /* 3 */
    "  \"numerics\": { \"dx\": 0.02, \"h_over_dx\": 1.3, \"cfl\": 0.1, \"cfl_visc\": 0.05,\n" /* 4 */
    "                \"t_end\": 0.1, \"wall_layers\": 3 },\n"                                 /* 5 */
    "  \"media\": {\n"                                                                        /* 6 */
    "    \"water\": { \"type\": \"fluid\", \"rho\": 1000.0, \"c\": 20.0, \"mu\": 1.0e-3, \"alpha_m\": 0.1 }\n"
    "  },\n"
    "  \"bodies\": {\n"
    "    \"pool\": { \"medium\": \"water\", \"polygon\": [[0.0, 0.0], [0.2, 0.0], [0.2, 0.1], [0.0, 0.1]] }\n"
    "  },\n"
    "  \"motions\": {\n"
    "    \"plate\": { \"t\": [0.0, 0.5, 1.0], \"vx\": [0.0, 0.1, 0.0], \"vz\": [0.0, 0.0, 0.0] }\n"
    "  },\n"
    "  \"walls\": {\n"
    "    \"tank\": { \"polyline\": [[0.0, 0.3], [0.0, 0.0], [0.2, 0.0], [0.2, 0.3]], \"fluid_side\": \"left\" },\n"
    "    \"paddle\": { \"polyline\": [[0.5, 0.3], [0.5, 0.0]], \"fluid_side\": \"right\", \"motion\": \"plate\",\n"
    "                \"slip\": \"free-slip\" }\n"
    "  },\n"
    "  \"monitors\": {\n"
    "    \"front\": { \"type\": \"front\", \"medium\": \"water\", \"direction\": \"+x\" }\n"
    "  },\n"
    "  \"output\": { \"monitor_interval\": 0.01 }\n"
    "}\n";

/* BASE with `old` (which must occur exactly once) replaced by `new_text`; caller frees. */
static char *edit(const char *old, const char *new_text) { return edit_text(BASE, old, new_text); }

/* Parse `json` (with overrides); 1 if the status is `expect` and the message contains every
 * string of the NULL-terminated list (what is missing is printed). */
static int error_matches(const char *json, const mixsph_override *ov, size_t n_ov, mixsph_status expect, ...)
{
    struct case_def c;
    char err[512] = "";
    const mixsph_status st = case_parse(json, ORIGIN, ov, n_ov, &c, err, sizeof err);
    print_message("  -> %s\n", err);
    if (st == MIXSPH_OK) case_free(&c);
    int ok = st == expect;
    if (!ok) print_error("status %d, expected %d\n", (int)st, (int)expect);
    va_list ap;
    va_start(ap, expect);
    for (const char *needle = va_arg(ap, const char *); needle; needle = va_arg(ap, const char *)) {
        if (!strstr(err, needle)) {
            print_error("message lacks \"%s\"\n", needle);
            ok = 0;
        }
    }
    va_end(ap);
    return ok;
}

#define EXPECT_ERROR(json, ...) \
    assert_true(error_matches((json), NULL, 0, MIXSPH_ERR_CASE, __VA_ARGS__, (const char *)NULL))

/* BASE edited once, expected to fail with the given message parts (freed before asserting). */
#define EXPECT_EDIT_ERROR(old, new_text, ...)                                                      \
    do {                                                                                           \
        char *j_ = edit((old), (new_text));                                                        \
        const int ok_ = error_matches(j_, NULL, 0, MIXSPH_ERR_CASE, __VA_ARGS__, (const char *)NULL); \
        free(j_);                                                                                  \
        assert_true(ok_);                                                                          \
    } while (0)

/* An override list applied to BASE, expected to fail with the given message parts. */
#define EXPECT_OVERRIDE_ERROR(ov, ...) \
    assert_true(error_matches(BASE, (ov), sizeof(ov) / sizeof((ov)[0]), MIXSPH_ERR_CASE, __VA_ARGS__, (const char *)NULL))

/* The base case is valid and read as written (the control for every test below). */
static void test_good_case(void **state)
{
    (void)state;
    struct case_def c;
    char err[512] = "";
    assert_int_equal(case_parse(BASE, ORIGIN, NULL, 0, &c, err, sizeof err), MIXSPH_OK);
    assert_string_equal(c.name, "tiny");
    assert_string_equal(c.origin, ORIGIN);
    assert_true(c.g == 9.81 && c.dx == 0.02 && c.h_over_dx == 1.3 && c.t_end == 0.1 && c.wall_layers == 3);
    assert_int_equal(c.n_media, 1);
    assert_true(c.media[0].rho0 == 1000.0 && c.media[0].c == 20.0 && c.media[0].alpha_m == 0.1);
    assert_int_equal(c.n_bodies, 1);
    assert_int_equal(c.bodies[0].medium, 0);
    assert_int_equal(c.bodies[0].polygon.n, 4);
    assert_int_equal(c.n_walls, 2);
    assert_int_equal(c.walls[0].side, 1);
    assert_int_equal(c.walls[0].motion, -1);
    assert_int_equal(c.walls[0].slip, WALL_NO_SLIP); /* the default */
    assert_int_equal(c.walls[1].side, -1);
    assert_int_equal(c.walls[1].motion, 0);
    assert_int_equal(c.walls[1].slip, WALL_FREE_SLIP);
    assert_int_equal(c.n_motions, 1);
    assert_int_equal(c.motions[0].n, 3);
    assert_true(c.motions[0].vx[1] == 0.1);
    assert_int_equal(c.n_monitors, 1);
    assert_int_equal(c.monitors[0].direction, 1);
    assert_true(c.monitor_interval == 0.01);
    case_free(&c);
    /* K instead of c: c = sqrt(K / rho) */
    char *j = edit("\"c\": 20.0", "\"K\": 4.0e5");
    assert_int_equal(case_parse(j, ORIGIN, NULL, 0, &c, err, sizeof err), MIXSPH_OK);
    assert_true(c.media[0].c == 20.0);
    case_free(&c);
    free(j);
}

/* case_number: the value a case gives a numeric key of its top level, numerics or output (the
 * file's, an override's or the default), and a clear refusal of any other key. */
static void test_case_number(void **state)
{
    (void)state;
    struct case_def c;
    char err[512] = "";
    const mixsph_override ov[] = {{"numerics.cfl", 0.05}, {"numerics.viscosity", 1}};
    assert_int_equal(case_parse(BASE, ORIGIN, ov, 2, &c, err, sizeof err), MIXSPH_OK);
    double v = NAN;
    assert_int_equal(case_number(&c, "numerics.dx", &v, err, sizeof err), MIXSPH_OK);
    assert_true(v == 0.02); /* the file's */
    assert_int_equal(case_number(&c, "numerics.cfl", &v, err, sizeof err), MIXSPH_OK);
    assert_true(v == 0.05); /* the override's */
    assert_int_equal(case_number(&c, "numerics.cfl_visc", &v, err, sizeof err), MIXSPH_OK);
    assert_true(v == c.cfl_visc && v > 0.0); /* the default */
    assert_int_equal(case_number(&c, "numerics.viscosity", &v, err, sizeof err), MIXSPH_OK);
    assert_true(v == 1.0); /* a choice: its value ("implicit") */
    assert_int_equal(case_number(&c, "gravity", &v, err, sizeof err), MIXSPH_OK);
    assert_true(v == 9.81);
    assert_int_equal(case_number(&c, "output.monitor_interval", &v, err, sizeof err), MIXSPH_OK);
    assert_true(v == c.monitor_interval);
    const char *refused[] = {"numerics.nope", "media.water.rho", "name", "numerics", "numericsx.cfl"};
    for (size_t k = 0; k < sizeof refused / sizeof refused[0]; k++) {
        assert_int_equal(case_number(&c, refused[k], &v, err, sizeof err), MIXSPH_ERR_ARG);
        assert_non_null(strstr(err, refused[k]));
    }
    case_free(&c);
}

static void test_invalid_json(void **state)
{
    (void)state;
    /* an extra comma on line 3 */
    EXPECT_EDIT_ERROR("\"gravity\": 9.81,", "\"gravity\": 9.81,,", ORIGIN ": line 3: ", "not valid JSON");
    /* an unterminated string on line 2 */
    EXPECT_EDIT_ERROR("\"name\": \"tiny\",", "\"name\": \"tiny,", ORIGIN ": line ", "not valid JSON");
    /* not an object */
    EXPECT_ERROR("[1, 2]", ORIGIN ": ", "must be a JSON object");
    EXPECT_ERROR("", ORIGIN ": line 1: not valid JSON");
}

static void test_missing_key(void **state)
{
    (void)state;
    EXPECT_EDIT_ERROR("\"dx\": 0.02, ", "", ORIGIN ": numerics.dx: missing (expected a number)");
    EXPECT_EDIT_ERROR("\"t_end\": 0.1, ", "", ORIGIN ": numerics.t_end: missing (expected a number)");
    EXPECT_EDIT_ERROR("\"type\": \"fluid\", ", "", ORIGIN ": media.water.type: missing (expected a string)");
    EXPECT_EDIT_ERROR(", \"fluid_side\": \"left\"", "", ORIGIN ": walls.tank.fluid_side: missing (expected a string)");
    EXPECT_EDIT_ERROR(", \"vz\": [0.0, 0.0, 0.0]", "", ORIGIN ": motions.plate.vz: missing (expected an array of numbers)");
    EXPECT_EDIT_ERROR("\"c\": 20.0, ", "", ORIGIN ": media.water: ", "exactly one of K", "or c");
}

static void test_wrong_type(void **state)
{
    (void)state;
    EXPECT_EDIT_ERROR("\"dx\": 0.02", "\"dx\": \"0.02\"", ORIGIN ": numerics.dx: expected a number");
    EXPECT_EDIT_ERROR("\"rho\": 1000.0", "\"rho\": [1000.0]", ORIGIN ": media.water.rho: expected a number");
    EXPECT_EDIT_ERROR("\"fluid_side\": \"left\"", "\"fluid_side\": 1", ORIGIN ": walls.tank.fluid_side: expected a string");
    EXPECT_EDIT_ERROR("[0.2, 0.0], [0.2, 0.1]", "[0.2], [0.2, 0.1]",
                      ORIGIN ": bodies.pool.polygon[1]: expected a point [x, z] of two numbers");
    EXPECT_EDIT_ERROR("\"vx\": [0.0, 0.1, 0.0]", "\"vx\": [0.0, \"fast\", 0.0]",
                      ORIGIN ": motions.plate.vx[1]: expected a number");
    EXPECT_EDIT_ERROR("\"output\": { \"monitor_interval\": 0.01 }", "\"output\": 0.01",
                      ORIGIN ": output: expected an object");
}

static void test_out_of_range(void **state)
{
    (void)state;
    EXPECT_EDIT_ERROR("\"dx\": 0.02", "\"dx\": 0", ORIGIN ": numerics.dx: 0 is out of range (expected 0 < x <= 10)");
    EXPECT_EDIT_ERROR("\"dx\": 0.02", "\"dx\": -0.01", ORIGIN ": numerics.dx: -0.01 is out of range");
    EXPECT_EDIT_ERROR("\"h_over_dx\": 1.3", "\"h_over_dx\": 5",
                      ORIGIN ": numerics.h_over_dx: 5 is out of range (expected 1 <= x <= 3)");
    EXPECT_EDIT_ERROR("\"rho\": 1000.0", "\"rho\": -1000.0", ORIGIN ": media.water.rho: -1000 is out of range");
    EXPECT_EDIT_ERROR("\"wall_layers\": 3", "\"wall_layers\": 2", ORIGIN ": numerics.wall_layers: ",
                      "do not cover the kernel support", "expected >= 3");
    EXPECT_EDIT_ERROR("\"wall_layers\": 3", "\"wall_layers\": 3.5", ORIGIN ": numerics.wall_layers: expected an integer");
    /* the arithmetic pair mean only with the implicit step (the explicit time step is sized for the harmonic one) */
    EXPECT_EDIT_ERROR("\"wall_layers\": 3", "\"wall_layers\": 3, \"viscosity_mean\": \"arithmetic\"",
                      ORIGIN ": numerics.viscosity_mean: \"arithmetic\" needs numerics.viscosity \"implicit\"");
    EXPECT_EDIT_ERROR("[0.2, 0.0], [0.2, 0.1]", "[0.2, 0.0], [0.2, 0.0]", ORIGIN ": bodies.pool.polygon[2]: repeats");
}

/* Keys at the top level: the key path is the key itself, as in the file and in an override
 * ("gravity", not "case.gravity"). */
static void test_top_level_key_paths(void **state)
{
    (void)state;
    EXPECT_EDIT_ERROR("\"name\": \"tiny\",", "", ORIGIN ": name: missing (expected a string)");
    EXPECT_EDIT_ERROR("\"gravity\": 9.81", "\"gravity\": true", ORIGIN ": gravity: expected a number");
    EXPECT_EDIT_ERROR("\"gravity\": 9.81", "\"gravity\": -9.81", ORIGIN ": gravity: -9.81 is out of range");
}

static void test_unknown_key(void **state)
{
    (void)state;
    EXPECT_EDIT_ERROR("\"dx\": 0.02", "\"dxx\": 0.02", ORIGIN ": numerics.dxx: unknown key");
    EXPECT_EDIT_ERROR("\"alpha_m\": 0.1", "\"alpha\": 0.1", ORIGIN ": media.water.alpha: unknown key");
    EXPECT_EDIT_ERROR("\"gravity\": 9.81", "\"gravty\": 9.81", ORIGIN ": gravty: unknown key");
    EXPECT_EDIT_ERROR("\"monitor_interval\"", "\"monitor_intervall\"", ORIGIN ": output.monitor_intervall: unknown key");
}

static void test_bad_reference_or_choice(void **state)
{
    (void)state;
    EXPECT_EDIT_ERROR("\"medium\": \"water\", \"polygon\"", "\"medium\": \"sand\", \"polygon\"",
                      ORIGIN ": bodies.pool.medium: 'sand' is not one of the media");
    EXPECT_EDIT_ERROR("\"motion\": \"plate\"", "\"motion\": \"plat\"",
                      ORIGIN ": walls.paddle.motion: 'plat' is not one of the motions");
    EXPECT_EDIT_ERROR("\"fluid_side\": \"left\"", "\"fluid_side\": \"up\"",
                      ORIGIN ": walls.tank.fluid_side: 'up'", "expected \"left\" or \"right\"");
    EXPECT_EDIT_ERROR("\"slip\": \"free-slip\"", "\"slip\": \"sticky\"", ORIGIN ": walls.paddle.slip: 'sticky'",
                      "expected \"no-slip\" or \"free-slip\"");
    EXPECT_EDIT_ERROR("\"type\": \"fluid\"", "\"type\": \"honey\"", ORIGIN ": media.water.type: 'honey'",
                      "expected \"fluid\"");
    EXPECT_EDIT_ERROR("\"direction\": \"+x\"", "\"direction\": \"up\"", ORIGIN ": monitors.front.direction: 'up'",
                      "expected \"+x\" or \"-x\"");
    EXPECT_EDIT_ERROR("\"type\": \"front\"", "\"type\": \"back\"", ORIGIN ": monitors.front.type: 'back'");
}

static void test_motion_arrays(void **state)
{
    (void)state;
    EXPECT_EDIT_ERROR("\"vx\": [0.0, 0.1, 0.0]", "\"vx\": [0.0, 0.1]", ORIGIN ": motions.plate: ",
                      "t, vx and vz must have the same length (3, 2, 3)");
    EXPECT_EDIT_ERROR("\"t\": [0.0, 0.5, 1.0]", "\"t\": [0.0, 0.5, 0.5]", ORIGIN ": motions.plate.t[2]: ",
                      "times must increase");
    EXPECT_EDIT_ERROR("\"t\": [0.0, 0.5, 1.0]", "\"t\": [0.0, -0.5, 1.0]", ORIGIN ": motions.plate.t[1]: ",
                      "times must increase");
    EXPECT_EDIT_ERROR("\"t\": [0.0, 0.5, 1.0], \"vx\": [0.0, 0.1, 0.0], \"vz\": [0.0, 0.0, 0.0]",
                      "\"t\": [], \"vx\": [], \"vz\": []", ORIGIN ": motions.plate.t: expected at least 1 number(s)");
}

/* Overrides applied to the JSON before validation. */
static void test_overrides(void **state)
{
    (void)state;
    struct case_def c;
    char err[512] = "";
    /* good: a number, an array element, an optional key absent from the file (added) */
    const mixsph_override good[] = {
        {"numerics.dx", 0.01}, {"motions.plate.vx.1", 0.3}, {"output.snapshot_interval", 0.05}, {"gravity", 1.5}};
    assert_int_equal(case_parse(BASE, ORIGIN, good, 4, &c, err, sizeof err), MIXSPH_OK);
    assert_true(c.dx == 0.01);
    assert_true(c.motions[0].vx[1] == 0.3);
    assert_true(c.snapshot_interval == 0.05);
    assert_true(c.g == 1.5);
    case_free(&c);

    const mixsph_override missing[] = {{"numerix.dx", 0.01}};
    EXPECT_OVERRIDE_ERROR(missing, ORIGIN ": override numerix.dx: no such key", "'numerix'");
    const mixsph_override bad_index[] = {{"motions.plate.vx.7", 0.01}};
    EXPECT_OVERRIDE_ERROR(bad_index, ORIGIN ": override motions.plate.vx.7: no such key", "'7'");
    /* a misspelt leaf is added, then refused by the validation as an unknown key */
    const mixsph_override typo[] = {{"numerics.dxx", 0.01}};
    EXPECT_OVERRIDE_ERROR(typo, ORIGIN ": numerics.dxx: unknown key");
    /* a string key takes a number only where it is a choice with numbers (numerics.viscosity) */
    const mixsph_override string[] = {{"walls.tank.fluid_side", 1.0}};
    EXPECT_OVERRIDE_ERROR(string, ORIGIN ": walls.tank.fluid_side: expected a string");
    const mixsph_override implicit[] = {{"numerics.viscosity", 1.0}};
    assert_int_equal(case_parse(BASE, ORIGIN, implicit, 1, &c, err, sizeof err), MIXSPH_OK);
    assert_int_equal(c.viscosity_implicit, 1);
    case_free(&c);
    const mixsph_override no_choice[] = {{"numerics.viscosity", 2.0}};
    EXPECT_OVERRIDE_ERROR(no_choice, ORIGIN ": numerics.viscosity: 2 is not the number of a choice", "\"implicit\"");
    const mixsph_override object[] = {{"numerics", 1.0}};
    EXPECT_OVERRIDE_ERROR(object, ORIGIN ": override numerics: ", "not a number or a Boolean");
    /* an override is validated like the file: out of range */
    const mixsph_override range[] = {{"numerics.dx", -1.0}};
    EXPECT_OVERRIDE_ERROR(range, ORIGIN ": numerics.dx: -1 is out of range");
    const mixsph_override nan_ov[] = {{"numerics.dx", NAN}};
    EXPECT_OVERRIDE_ERROR(nan_ov, ORIGIN ": override numerics.dx: ", "not finite");
}

/* "key=value" syntax. */
static void test_override_parse(void **state)
{
    (void)state;
    char err[256];
    mixsph_override ov;
    char ok[] = "numerics.dx=0.01";
    assert_int_equal(mixsph_override_parse(ok, &ov, err, sizeof err), MIXSPH_OK);
    assert_string_equal(ov.key, "numerics.dx");
    assert_true(ov.value == 0.01);
    char neg[] = "motions.plate.vx.3=-2.5e-1";
    assert_int_equal(mixsph_override_parse(neg, &ov, err, sizeof err), MIXSPH_OK);
    assert_string_equal(ov.key, "motions.plate.vx.3");
    assert_true(ov.value == -0.25);

    static const char *const no_eq[] = {"dx", "=3", "", NULL};
    for (const char *const *t = no_eq; *t; t++) {
        char buf[64];
        snprintf(buf, sizeof buf, "%s", *t);
        err[0] = '\0';
        assert_int_equal(mixsph_override_parse(buf, &ov, err, sizeof err), MIXSPH_ERR_ARG);
        print_message("  '%s' -> %s\n", *t, err);
        assert_non_null(strstr(err, "expected key=value"));
        assert_string_equal(buf, *t); /* the text is left as it was */
    }
    static const char *const bad_value[][2] = {
        {"dx=abc", "'abc'"}, {"dx=", "''"}, {"dx=1e999", "'1e999'"}, {"dx=nan", "'nan'"},
        {"dx=inf", "'inf'"}, {"dx=3x", "'3x'"},   {"a=b=1", "'b=1'"}, {NULL, NULL}};
    for (size_t k = 0; bad_value[k][0]; k++) {
        char buf[64];
        snprintf(buf, sizeof buf, "%s", bad_value[k][0]);
        err[0] = '\0';
        assert_int_equal(mixsph_override_parse(buf, &ov, err, sizeof err), MIXSPH_ERR_ARG);
        print_message("  '%s' -> %s\n", bad_value[k][0], err);
        assert_non_null(strstr(err, bad_value[k][1]));
        assert_non_null(strstr(err, "is not a finite number"));
        assert_string_equal(buf, bad_value[k][0]); /* the '=' is put back */
    }
}

/* Through the public API: a missing file, errors passed on by create, and the particle count
 * following an override of numerics.dx. */
static void test_create(void **state)
{
    (void)state;
    mixsph_sim *s = (mixsph_sim *)&s; /* not NULL: create must reset it */
    char err[512] = "";
    const char *missing = MIXSPH_SOURCE_DIR "/cases/no_such_case.json";
    assert_int_equal(mixsph_sim_create(missing, NULL, 0, &s, err, sizeof err), MIXSPH_ERR_IO);
    print_message("  -> %s\n", err);
    assert_null(s);
    assert_non_null(strstr(err, missing));
    assert_non_null(strstr(err, "cannot open"));

    /* a parse error comes back through create with the origin given */
    char *bad = edit("\"dx\": 0.02", "\"dx\": 0");
    assert_int_equal(mixsph_sim_create_from_text(bad, ORIGIN, NULL, 0, &s, err, sizeof err), MIXSPH_ERR_CASE);
    assert_null(s);
    assert_non_null(strstr(err, ORIGIN ": numerics.dx: 0 is out of range"));
    free(bad);
    /* errors found while building: no lattice site inside the body */
    bad = edit("[[0.0, 0.0], [0.2, 0.0], [0.2, 0.1], [0.0, 0.1]]", "[[0.052, 0.052], [0.053, 0.052], [0.053, 0.053]]");
    assert_int_equal(mixsph_sim_create_from_text(bad, ORIGIN, NULL, 0, &s, err, sizeof err), MIXSPH_ERR_CASE);
    print_message("  -> %s\n", err);
    assert_non_null(strstr(err, ORIGIN ": bodies: no particle fits"));
    free(bad);
    /* a domain that does not hold the particles */
    bad = edit("  \"output\"", "  \"domain\": { \"x_min\": 0.0, \"x_max\": 0.1, \"z_min\": -0.1, \"z_max\": 0.5 },\n  \"output\"");
    assert_int_equal(mixsph_sim_create_from_text(bad, ORIGIN, NULL, 0, &s, err, sizeof err), MIXSPH_ERR_CASE);
    print_message("  -> %s\n", err);
    assert_non_null(strstr(err, ORIGIN ": domain: a particle at"));
    free(bad);

    /* particle counts: the pool 0.2 x 0.1 holds (0.2/dx)(0.1/dx) lattice sites */
    assert_int_equal(mixsph_sim_create_from_text(BASE, ORIGIN, NULL, 0, &s, err, sizeof err), MIXSPH_OK);
    assert_int_equal(mixsph_sim_particles(s), 50);
    mixsph_sim_destroy(s);
    const mixsph_override fine = {"numerics.dx", 0.01};
    assert_int_equal(mixsph_sim_create_from_text(BASE, ORIGIN, &fine, 1, &s, err, sizeof err), MIXSPH_OK);
    assert_int_equal(mixsph_sim_particles(s), 200);
    mixsph_sim_destroy(s);

    /* from a file: the hydrostatic tank, 0.4 x 0.3 m of water */
    const char *tank = MIXSPH_SOURCE_DIR "/cases/hydrostatic_tank.json";
    assert_int_equal(mixsph_sim_create(tank, NULL, 0, &s, err, sizeof err), MIXSPH_OK);
    assert_int_equal(mixsph_sim_particles(s), 1200); /* dx = 0.01 */
    assert_string_equal(mixsph_sim_name(s), "hydrostatic_tank");
    mixsph_sim_destroy(s);
    const mixsph_override coarse = {"numerics.dx", 0.02};
    assert_int_equal(mixsph_sim_create(tank, &coarse, 1, &s, err, sizeof err), MIXSPH_OK);
    assert_int_equal(mixsph_sim_particles(s), 300);
    mixsph_sim_destroy(s);
    /* and its error messages name the file */
    const mixsph_override typo = {"numerix.dx", 0.02};
    assert_int_equal(mixsph_sim_create(tank, &typo, 1, &s, err, sizeof err), MIXSPH_ERR_CASE);
    assert_non_null(strstr(err, tank));
    assert_null(s);
    mixsph_sim_destroy(NULL); /* NULL-safe */
}

/* BASE with a max_elevation monitor "top", a profile "surface" rewritten at its maxima and a
 * full-scale map Z = 1000 z + 5 with the reference observed 105, still 55 (so d_eta% = 100
 * |Z - 105| / 50); `full_scale` replaces the map's inner text when not NULL. Caller frees. */
#define FS_MONITORS                                                                                           \
    "    \"top\": { \"type\": \"max_elevation\", \"medium\": \"water\", \"min_neighbours\": 0 },\n"                \
    "    \"surface\": { \"type\": \"profile\", \"medium\": \"water\", \"x_min\": 0.0, \"x_max\": 0.2, \"at_max_of\": \"top\" },\n" \
    "    \"front\": { \"type\": \"front\", \"medium\": \"water\", \"direction\": \"+x\" }\n"
#define FS_MAP "\"z_scale\": 1000.0, \"z_offset\": 5.0, \"unit\": \"m a.s.l.\", " \
               "\"reference\": { \"monitor\": \"top\", \"observed\": 105.0, \"still\": 55.0 }"

static char *full_scale_case(const char *monitors, const char *full_scale)
{
    char *a = edit("    \"front\": { \"type\": \"front\", \"medium\": \"water\", \"direction\": \"+x\" }\n",
                   monitors ? monitors : FS_MONITORS);
    char block[1024];
    snprintf(block, sizeof block, "  \"full_scale\": { %s },\n  \"output\"", full_scale ? full_scale : FS_MAP);
    char *b = edit_text(a, "  \"output\"", block);
    free(a);
    return b;
}

#define EXPECT_FULL_SCALE_ERROR(monitors, full_scale, ...)                                          \
    do {                                                                                           \
        char *j_ = full_scale_case((monitors), (full_scale));                                      \
        const int ok_ = error_matches(j_, NULL, 0, MIXSPH_ERR_CASE, __VA_ARGS__, (const char *)NULL); \
        free(j_);                                                                                  \
        assert_true(ok_);                                                                          \
    } while (0)

/* The optional full_scale key: every error names the key path and what was expected. */
static void test_full_scale_errors(void **state)
{
    (void)state;
    EXPECT_FULL_SCALE_ERROR(NULL, "\"z_offset\": 0.3", ORIGIN ": full_scale.z_scale: missing (expected a number)");
    EXPECT_FULL_SCALE_ERROR(NULL, "\"z_scale\": -2", ORIGIN ": full_scale.z_scale: -2 is out of range (expected 0 <");
    EXPECT_FULL_SCALE_ERROR(NULL, "\"z_scale\": 2, \"zoffset\": 1", ORIGIN ": full_scale.zoffset: unknown key");
    EXPECT_FULL_SCALE_ERROR(NULL, "\"z_scale\": 2, \"unit\": 3", ORIGIN ": full_scale.unit: expected a string");
    EXPECT_FULL_SCALE_ERROR(NULL, "\"z_scale\": 2, \"reference\": 3", ORIGIN ": full_scale.reference: expected an object");
    EXPECT_FULL_SCALE_ERROR(NULL, "\"z_scale\": 2, \"reference\": { \"monitor\": \"top\", \"observed\": 2, \"still\": 1, \"x\": 0 }",
                            ORIGIN ": full_scale.reference.x: unknown key");
    EXPECT_FULL_SCALE_ERROR(NULL, "\"z_scale\": 2, \"reference\": { \"observed\": 2, \"still\": 1 }",
                            ORIGIN ": full_scale.reference.monitor: missing (expected a string)");
    EXPECT_FULL_SCALE_ERROR(NULL, "\"z_scale\": 2, \"reference\": { \"monitor\": \"front\", \"observed\": 2, \"still\": 1 }",
                            ORIGIN ": full_scale.reference.monitor: 'front' is not one of the max_elevation monitors");
    EXPECT_FULL_SCALE_ERROR(NULL, "\"z_scale\": 2, \"reference\": { \"monitor\": \"top\", \"still\": 1 }",
                            ORIGIN ": full_scale.reference.observed: missing (expected a number)");
    EXPECT_FULL_SCALE_ERROR(NULL, "\"z_scale\": 2, \"reference\": { \"monitor\": \"top\", \"observed\": 1, \"still\": 2 }",
                            ORIGIN ": full_scale.reference: observed (1) must lie above still (2)");
    /* the derived output names must fit */
    EXPECT_FULL_SCALE_ERROR(
        "    \"a_monitor_name_of_forty_five_characters_xxxxx\": { \"type\": \"max_elevation\", \"medium\": \"water\" }\n",
        "\"z_scale\": 2", ORIGIN ": full_scale: the monitor name 'a_monitor_name_of_forty_five_characters_xxxxx' is too long",
        "(expected at most 41 characters)");
    /* at_max_of belongs to profiles and names a max_elevation monitor */
    EXPECT_FULL_SCALE_ERROR(
        "    \"top\": { \"type\": \"max_elevation\", \"medium\": \"water\", \"at_max_of\": \"top\" }\n", NULL,
        ORIGIN ": monitors.top.at_max_of: a max_elevation monitor does not take this key (only profile)");
    EXPECT_FULL_SCALE_ERROR(
        "    \"top\": { \"type\": \"max_elevation\", \"medium\": \"water\" },\n"
        "    \"surface\": { \"type\": \"profile\", \"medium\": \"water\", \"x_min\": 0.0, \"x_max\": 0.2, \"at_max_of\": \"fr\" }\n",
        NULL, ORIGIN ": monitors.surface.at_max_of: 'fr' is not one of the max_elevation monitors");
    EXPECT_FULL_SCALE_ERROR(
        "    \"top\": { \"type\": \"max_elevation\", \"medium\": \"water\" },\n"
        "    \"surface\": { \"type\": \"profile\", \"medium\": \"water\", \"x_min\": 0.0, \"x_max\": 0.2 }\n",
        NULL, ORIGIN ": monitors.surface.times: missing (expected an array of numbers)");
    /* full_scale is a top-level key: a misspelling is caught */
    EXPECT_EDIT_ERROR("  \"output\"", "  \"full_scal\": { \"z_scale\": 2 },\n  \"output\"", ORIGIN ": full_scal: unknown key");
}

/* The map, the error (13) and the outputs <m>_Z and <m>_d_eta of a running simulation. */
static void test_full_scale_map(void **state)
{
    (void)state;
    struct case_def c;
    char err[512] = "";
    char *j = full_scale_case(NULL, NULL);
    assert_int_equal(case_parse(j, ORIGIN, NULL, 0, &c, err, sizeof err), MIXSPH_OK);
    assert_true(c.full_scale.on && c.full_scale.ref_monitor == 0);
    assert_string_equal(c.full_scale.unit, "m a.s.l.");
    assert_int_equal(c.monitors[1].at_max_of, 0);
    assert_int_equal(c.monitors[1].n_times, 0);
    assert_true(fabs(case_full_scale_z(&c, 0.1) - 105.0) < 1e-12);
    assert_true(fabs(case_full_scale_error(&c, 95.0) - 20.0) < 1e-12); /* 100 |95 - 105| / 50 */
    case_free(&c);

    /* a simulation gets top_Z = 1000 top + 5 and top_d_eta from the highest top so far */
    mixsph_sim *s = NULL;
    assert_int_equal(mixsph_sim_create_from_text(j, ORIGIN, NULL, 0, &s, err, sizeof err), MIXSPH_OK);
    free(j);
    const long kt = mixsph_sim_output_find(s, "top"), kz = mixsph_sim_output_find(s, "top_Z"),
               ke = mixsph_sim_output_find(s, "top_d_eta");
    assert_true(kt >= 0 && kz > kt && ke > kz);
    assert_int_equal(mixsph_sim_output_find(s, "front_Z"), -1); /* only max_elevation monitors are mapped */
    assert_int_equal(mixsph_sim_advance_to(s, 0.03), MIXSPH_OK);
    const double top = mixsph_sim_output_value(s, (size_t)kt);
    assert_true(fabs(top - 0.09) < 0.02); /* the pool is 0.1 m deep, top particle centre 0.09 m */
    assert_true(fabs(mixsph_sim_output_value(s, (size_t)kz) - (1000.0 * top + 5.0)) < 1e-9);
    double mx, tmx, mn, tmn, zmx, d;
    mixsph_sim_output_extremes(s, (size_t)kt, &mx, &tmx, &mn, &tmn);
    mixsph_sim_output_extremes(s, (size_t)kz, &zmx, &d, &mn, &tmn);
    assert_true(fabs(zmx - (1000.0 * mx + 5.0)) < 1e-9);
    assert_true(fabs(mixsph_sim_output_value(s, (size_t)ke) - 100.0 * fabs(zmx - 105.0) / 50.0) < 1e-9);
    mixsph_sim_destroy(s);

    /* the Vajont case: Z = 1211.8 z + 0.3, Z_exp = 863, Z_still = 700, i.e. the lab-frame
     * d_eta% = 100 |z - 0.712| / 0.1345 of docs/cases.md (within 0.1 % for the paper's run-ups: the
     * map puts z = 0.712 at 863.1 and 0.1345 m at 163.0 m) */
    char *text = NULL;
    assert_int_equal(case_read_file(MIXSPH_SOURCE_DIR "/cases/vajont_padua.json", &text, err, sizeof err), MIXSPH_OK);
    assert_int_equal(case_parse(text, "vajont_padua.json", NULL, 0, &c, err, sizeof err), MIXSPH_OK);
    free(text);
    assert_true(c.full_scale.on);
    assert_string_equal(c.monitors[c.full_scale.ref_monitor].name, "run_up");
    const double paper_z[] = {0.718, 0.733, 0.708, 0.701, 0.702, 0.699};
    const double paper_Z[] = {870.3, 888.5, 858.2, 849.7, 850.9, 847.3}; /* Table 5 */
    for (size_t k = 0; k < 6; k++) {
        const double Z = case_full_scale_z(&c, paper_z[k]);
        assert_true(fabs(Z - paper_Z[k]) < 0.2);  /* the map is a fit to Table 5, within 0.2 m */
        assert_true(fabs(case_full_scale_error(&c, Z) - 100.0 * fabs(paper_z[k] - 0.712) / 0.1345) < 0.1);
    }
    case_free(&c);
}

/* ---- the table-driven reader (case_schema.c) --------------------------------------------------- */

/* BASE with a granular medium "sand" after the water; `extra` is added to its keys. Caller frees. */
static char *with_sand(const char *extra)
{
    char sand[512];
    snprintf(sand, sizeof sand,
             "\"alpha_m\": 0.1 },\n    \"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, "
             "\"porosity\": 0.35, \"phi\": 35.0, \"mu_thr\": 320e3%s }\n",
             extra);
    return edit("\"alpha_m\": 0.1 }\n", sand);
}

/* Every number of numerics below its range is refused with the key and the range of its table row. */
static void test_table_ranges(void **state)
{
    (void)state;
    const struct case_section *s = case_schema_find("numerics");
    assert_non_null(s);
    size_t checked = 0;
    for (size_t i = 0; i < s->n_keys; i++) {
        const struct case_key *k = &s->keys[i];
        if (k->type != CASE_NUMBER && k->type != CASE_INTEGER) continue;
        char key[96], range[96], want[256];
        snprintf(key, sizeof key, "numerics.%s", k->key);
        case_schema_range_text(k, 0, range, sizeof range);
        snprintf(want, sizeof want, ORIGIN ": %s: %g is out of range (expected %s)", key, k->lo - 1.0, range);
        const mixsph_override ov = {key, k->lo - 1.0};
        assert_true(error_matches(BASE, &ov, 1, MIXSPH_ERR_CASE, want, (const char *)NULL));
        checked++;
    }
    assert_true(checked >= 9);
    /* upper ends, open and closed, in other sections */
    EXPECT_EDIT_ERROR("\"alpha_m\": 0.1", "\"alpha_m\": 11", ORIGIN ": media.water.alpha_m: 11 is out of range (expected 0 <= x <= 10)");
    char *j = with_sand(", \"porosity_x\": 1");
    assert_true(error_matches(j, NULL, 0, MIXSPH_ERR_CASE, ORIGIN ": media.sand.porosity_x: unknown key", (const char *)NULL));
    free(j);
    j = edit("\"alpha_m\": 0.1 }\n", "\"alpha_m\": 0.1 },\n    \"sand\": { \"type\": \"granular\", \"rho\": 2650.0, "
             "\"K\": 4.24e6, \"porosity\": 0.96, \"phi\": 35.0, \"mu_thr\": 320e3 }\n");
    assert_true(error_matches(j, NULL, 0, MIXSPH_ERR_CASE,
                              ORIGIN ": media.sand.porosity: 0.96 is out of range (expected 0 < x <= 0.95)", (const char *)NULL));
    free(j);
    EXPECT_EDIT_ERROR("\"direction\": \"+x\"", "\"direction\": \"+x\", \"min_neighbours\": 101",
                      ORIGIN ": monitors.front.min_neighbours: 101 is out of range (expected 0 <= x <= 100)");
}

static void test_table_types(void **state)
{
    (void)state;
    EXPECT_EDIT_ERROR("\"wall_layers\": 3", "\"wall_layers\": 3, \"av_wall\": \"yes\"",
                      ORIGIN ": numerics.av_wall: expected true or false");
    EXPECT_EDIT_ERROR("\"wall_layers\": 3", "\"wall_layers\": 3, \"av_mixed\": 2", ORIGIN ": numerics.av_mixed: expected true or false");
    EXPECT_EDIT_ERROR("\"wall_layers\": 3", "\"wall_layers\": \"3\"", ORIGIN ": numerics.wall_layers: expected an integer");
    EXPECT_EDIT_ERROR("\"direction\": \"+x\"", "\"direction\": \"+x\", \"min_neighbours\": 2.5",
                      ORIGIN ": monitors.front.min_neighbours: expected an integer");
    EXPECT_EDIT_ERROR("\"wall_layers\": 3", "\"wall_layers\": 3, \"kernel\": 1", ORIGIN ": numerics.kernel: expected a string");
    EXPECT_EDIT_ERROR("\"wall_layers\": 3", "\"wall_layers\": 3, \"kernel\": \"gauss\"",
                      ORIGIN ": numerics.kernel: 'gauss' (expected \"cubic_spline\" or \"wendland_c2\")");
    EXPECT_EDIT_ERROR("\"medium\": \"water\", \"polygon\"", "\"medium\": 1, \"polygon\"", ORIGIN ": bodies.pool.medium: expected a string");
    EXPECT_EDIT_ERROR("\"name\": \"tiny\"", "\"name\": \"\"", ORIGIN ": name: expected 1 to 47 characters");
    EXPECT_EDIT_ERROR("\"name\": \"tiny\"", "\"name\": \"tiny\", \"description\": 3", ORIGIN ": description: expected a string");
    EXPECT_EDIT_ERROR("\"monitors\": {", "\"monitors\": { \"bad\": 3,", ORIGIN ": monitors.bad: expected an object");
}

/* A key of another variant (monitor type) is refused, naming the types that take it. */
static void test_table_variants(void **state)
{
    (void)state;
    EXPECT_EDIT_ERROR("\"type\": \"front\", \"medium\": \"water\", \"direction\": \"+x\"",
                      "\"type\": \"max_elevation\", \"medium\": \"water\", \"direction\": \"+x\"",
                      ORIGIN ": monitors.front.direction: a max_elevation monitor does not take this key (only front, runout "
                      "or slide_impact)");
    EXPECT_EDIT_ERROR("\"type\": \"front\", \"medium\": \"water\", \"direction\": \"+x\"",
                      "\"type\": \"kinetic_energy\", \"medium\": \"water\", \"min_neighbours\": 3",
                      ORIGIN ": monitors.front.min_neighbours: a kinetic_energy monitor does not take this key "
                      "(only front, max_elevation, profile, runout, wave_gauge or slide_impact)");
    EXPECT_EDIT_ERROR("\"type\": \"front\", \"medium\": \"water\", \"direction\": \"+x\"",
                      "\"type\": \"wall_pressure\", \"wall\": \"tank\", \"medium\": \"water\"",
                      ORIGIN ": monitors.front.medium: a wall_pressure monitor does not take this key");
    EXPECT_EDIT_ERROR("\"type\": \"front\", \"medium\": \"water\", \"direction\": \"+x\"", "\"type\": \"wall_pressure\"",
                      ORIGIN ": monitors.front.wall: missing (expected a string)");
    EXPECT_EDIT_ERROR("\"type\": \"front\", \"medium\": \"water\", \"direction\": \"+x\"", "\"type\": \"wall_work\"",
                      ORIGIN ": monitors.front.wall: missing (expected a string)");
    /* a pressure probe takes a wall (a sensor on it) but needs none; it needs its point */
    EXPECT_EDIT_ERROR("\"type\": \"front\", \"medium\": \"water\", \"direction\": \"+x\"",
                      "\"type\": \"pressure_probe\", \"x\": 0.1", ORIGIN ": monitors.front.z: missing (expected a number)");
    EXPECT_EDIT_ERROR("\"type\": \"front\", \"medium\": \"water\", \"direction\": \"+x\"",
                      "\"type\": \"wall_pressure\", \"wall\": \"tank\", \"x\": 0.1",
                      ORIGIN ": monitors.front.x: a wall_pressure monitor does not take this key (only pressure_probe or "
                      "wave_gauge)");
    EXPECT_EDIT_ERROR("\"type\": \"front\", \"medium\": \"water\", \"direction\": \"+x\"",
                      "\"type\": \"front\", \"direction\": \"+x\"", ORIGIN ": monitors.front.medium: missing (expected a string)");
}

/* Absent keys get the defaults of their table rows. */
static void test_table_defaults(void **state)
{
    (void)state;
    struct case_def c;
    char err[512] = "";
    char *j = edit("\"numerics\": { \"dx\": 0.02, \"h_over_dx\": 1.3, \"cfl\": 0.1, \"cfl_visc\": 0.05,\n"
                   "                \"t_end\": 0.1, \"wall_layers\": 3 },",
                   "\"numerics\": { \"dx\": 0.02, \"t_end\": 0.1 },");
    char *k = edit_text(j, "\"output\": { \"monitor_interval\": 0.01 }", "\"output\": { }");
    free(j);
    j = edit_text(k, "\"gravity\": 9.81,\n", "");
    free(k);
    k = edit_text(j, "\"alpha_m\": 0.1 }\n", "\"alpha_m\": 0.1 },\n    \"sand\": { \"type\": \"granular\", \"rho\": 2650.0, "
                  "\"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0, \"mu_thr\": 320e3 }\n");
    free(j);
    assert_int_equal(case_parse(k, ORIGIN, NULL, 0, &c, err, sizeof err), MIXSPH_OK);
    free(k);
    assert_true(c.g == 9.81);
    assert_true(c.h_over_dx == 1.3 && c.cfl == 0.1 && c.cfl_visc == 0.05 && c.wall_layers == 3);
    assert_true(c.eta2_over_h2 == 0.01);
    assert_int_equal(c.kernel, 0);
    assert_true(c.p_background == 0.0 && c.pressure_smoothing == 0.0 && c.fixed_bed_speed == -1.0);
    assert_true(c.av_wall == 1 && c.av_mixed == 0 && c.av_separating == 0);
    assert_true(c.monitor_interval == 0.1 / 200.0 && c.snapshot_interval == 0.0);
    assert_true(c.bodies[0].z_min == -INFINITY && c.bodies[0].z_max == INFINITY);
    assert_int_equal(c.walls[0].slip, WALL_NO_SLIP);
    assert_true(c.motions[0].speed_scale == 1.0 && c.motions[0].time_scale == 1.0);
    assert_int_equal(c.monitors[0].min_neighbours, 3);
    assert_true(c.monitors[0].x_min == -INFINITY && c.monitors[0].z_max == INFINITY);
    const struct medium *sand = &c.media[1];
    assert_int_equal(sand->law, LAW_MIXTURE_PAPER);
    assert_true(sand->paper.mu0 == INFINITY && sand->alpha_m == 0.0);
    assert_true(sand->granular.saturated == 0 && sand->tension_cutoff == 0 && sand->paper.hold_fixed == 0 && sand->granular.pore_fluid == -1);
    assert_true(sand->rho0 == (1.0 - 0.35) * 2650.0);
    case_free(&c);
    /* the front's direction and a full_scale unit */
    j = edit("\"direction\": \"+x\"", "\"min_neighbours\": 0");
    k = edit_text(j, "  \"output\"", "  \"full_scale\": { \"z_scale\": 2 },\n  \"output\"");
    free(j);
    assert_int_equal(case_parse(k, ORIGIN, NULL, 0, &c, err, sizeof err), MIXSPH_OK);
    free(k);
    assert_int_equal(c.monitors[0].direction, 1);
    assert_int_equal(c.monitors[0].min_neighbours, 0);
    assert_string_equal(c.full_scale.unit, "m");
    assert_true(c.full_scale.z_offset == 0.0 && c.full_scale.z_scale == 2.0);
    case_free(&c);
}

/* d50 changes nothing in the model, so a case may not give it. */
static void test_d50_refused(void **state)
{
    (void)state;
    char *j = with_sand(", \"d50\": 0.004");
    assert_true(error_matches(j, NULL, 0, MIXSPH_ERR_CASE, ORIGIN ": media.sand.d50: not used by the model",
                              "has no grain size", (const char *)NULL));
    free(j);
    /* nor through an override */
    j = with_sand("");
    const mixsph_override ov = {"media.sand.d50", 0.004};
    assert_true(error_matches(j, &ov, 1, MIXSPH_ERR_CASE, ORIGIN ": media.sand.d50: not used by the model", (const char *)NULL));
    free(j);
    /* the granular medium without it is fine */
    struct case_def c;
    char err[512] = "";
    j = with_sand("");
    assert_int_equal(case_parse(j, ORIGIN, NULL, 0, &c, err, sizeof err), MIXSPH_OK);
    free(j);
    case_free(&c);
}

/* A granular medium's law chosen by its number (its place in the list: 0 paper, 1 elastic_plastic,
 * as a case parameter or an override gives it): the medium may hold both laws' keys, those of the
 * law not chosen checked (type, range) and not used; named, the other law's keys are refused. */
static void test_granular_law_by_number(void **state)
{
    (void)state;
    struct case_def c;
    char err[512] = "";
    char *j = with_sand(", \"law\": 1, \"nu\": 0.25, \"cohesion\": 10.0, \"mu0\": 5e3, \"tension_cutoff\": true");
    assert_int_equal(case_parse(j, ORIGIN, NULL, 0, &c, err, sizeof err), MIXSPH_OK);
    free(j);
    const struct medium *m = &c.media[1];
    assert_int_equal(m->law, LAW_ELASTIC_PLASTIC);
    assert_true(m->elastic.poisson == 0.25 && m->dp.cohesion == 10.0);
    assert_true(m->paper.mu_thr == 0.0 && m->paper.mu0 == 0.0 && m->tension_cutoff == 0); /* the paper's keys: not used */
    case_free(&c);
    j = with_sand(", \"law\": 0, \"nu\": 0.25, \"cohesion\": 10.0");
    assert_int_equal(case_parse(j, ORIGIN, NULL, 0, &c, err, sizeof err), MIXSPH_OK);
    m = &c.media[1];
    assert_int_equal(m->law, LAW_MIXTURE_PAPER);
    assert_true(m->paper.mu_thr == 320e3 && m->elastic.poisson == 0.0 && m->dp.cohesion == 0.0);
    case_free(&c);
    /* an override of the number chooses the other law */
    const mixsph_override to_ep = {"media.sand.law", 1.0};
    assert_int_equal(case_parse(j, ORIGIN, &to_ep, 1, &c, err, sizeof err), MIXSPH_OK);
    assert_int_equal(c.media[1].law, LAW_ELASTIC_PLASTIC);
    case_free(&c);
    free(j);
    /* the other law's keys are checked: a value out of its range, a key of no granular law, a
     * number that is no law's */
    j = with_sand(", \"law\": 1, \"mu0\": -5");
    assert_true(error_matches(j, NULL, 0, MIXSPH_ERR_CASE, ORIGIN ": media.sand.mu0: -5 is out of range",
                              (const char *)NULL));
    free(j);
    j = with_sand(", \"law\": 0, \"nu\": 0.6");
    assert_true(error_matches(j, NULL, 0, MIXSPH_ERR_CASE, "media.sand.nu: 0.6 is out of range", (const char *)NULL));
    free(j);
    j = with_sand(", \"law\": 1, \"bogus\": 1");
    assert_true(error_matches(j, NULL, 0, MIXSPH_ERR_CASE, "media.sand.bogus: unknown key", (const char *)NULL));
    free(j);
    j = with_sand(", \"law\": 2");
    assert_true(error_matches(j, NULL, 0, MIXSPH_ERR_CASE, "media.sand.law: 2 is not the number of a choice",
                              "(or 0, 1)", (const char *)NULL));
    free(j);
    /* named: the paper's mu_thr is refused by the elastic-plastic table, nu by the paper's */
    j = with_sand(", \"law\": \"elastic_plastic\"");
    assert_true(error_matches(j, NULL, 0, MIXSPH_ERR_CASE, "media.sand.mu_thr: unknown key", (const char *)NULL));
    free(j);
    j = with_sand(", \"law\": \"paper\", \"nu\": 0.3");
    assert_true(error_matches(j, NULL, 0, MIXSPH_ERR_CASE, "media.sand.nu: unknown key", (const char *)NULL));
    free(j);
}

/* A granular medium that names no law: with mu_thr (or mu1), the paper's law, as every case written
 * for it; with only what a new user knows (rho, K or c, porosity, phi), the elastic-plastic law; a
 * key of the paper's law without its mu_thr is refused by name; "law": "paper" still needs mu_thr. */
static void test_granular_law_unnamed(void **state)
{
    (void)state;
    struct case_def c;
    char err[512] = "";
    char *j = with_sand("");
    assert_int_equal(case_parse(j, ORIGIN, NULL, 0, &c, err, sizeof err), MIXSPH_OK);
    assert_int_equal(c.media[1].law, LAW_MIXTURE_PAPER);
    case_free(&c);
    free(j);
    char *plain = edit("\"alpha_m\": 0.1 }\n",
                 "\"alpha_m\": 0.1 },\n    \"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, "
                 "\"porosity\": 0.35, \"phi\": 35.0 }\n");
    assert_int_equal(case_parse(plain, ORIGIN, NULL, 0, &c, err, sizeof err), MIXSPH_OK);
    assert_int_equal(c.media[1].law, LAW_ELASTIC_PLASTIC);
    case_free(&c);
    free(plain);
    j = edit("\"alpha_m\": 0.1 }\n", "\"alpha_m\": 0.1 },\n    \"sand\": { \"type\": \"granular\", \"rho\": 2650.0, "
                                       "\"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0, \"mu0\": 5e3 }\n");
    assert_true(error_matches(j, NULL, 0, MIXSPH_ERR_CASE, "media.sand.mu0: a key of the paper law",
                              "runs the elastic_plastic law", (const char *)NULL));
    free(j);
    j = edit("\"alpha_m\": 0.1 }\n", "\"alpha_m\": 0.1 },\n    \"sand\": { \"type\": \"granular\", \"rho\": 2650.0, "
                                       "\"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0, \"law\": \"paper\" }\n");
    assert_true(error_matches(j, NULL, 0, MIXSPH_ERR_CASE, "media.sand.mu_thr: missing", (const char *)NULL));
    free(j);
}

/* Every table row is well formed: a key once per section, a meaning, a field only where the
 * type has one, choices for a choice, a finite default inside the range. */
static void test_table_rows(void **state)
{
    (void)state;
    size_t n = 0;
    for (size_t s = 0; case_schema_section(s); s++) {
        const struct case_section *sec = case_schema_section(s);
        assert_ptr_equal(case_schema_find(sec->id), sec);
        for (size_t i = 0; i < sec->n_keys; i++, n++) {
            const struct case_key *k = &sec->keys[i];
            print_message("  %s.%s\n", sec->id, k->key);
            assert_ptr_equal(case_schema_key(sec, k->key), k);
            assert_true(k->meaning && *k->meaning);
            assert_true(k->type != CASE_CHOICE || k->choices);
            assert_true(k->need != CASE_SOMETIMES || k->need_text);
            assert_true(!k->only || sec->variants);
            assert_true(!k->field || (k->type != CASE_NAME && k->type != CASE_NUMBERS && k->type != CASE_OBJECT));
            assert_true(k->type != CASE_STRING || !k->field || (k->hi > 0 && k->hi < CASE_NAME_LEN)); /* fits its field */
            assert_true(k->type != CASE_INTEGER || (k->lo >= -1e6 && k->hi <= 1e6));                  /* fits an int */
            /* an infinite default means "no limit" (mu0) or "everywhere" (regions) */
            if (k->has_def && (k->type == CASE_NUMBER || k->type == CASE_INTEGER) && !isinf(k->def)) {
                assert_true(k->lo_open ? k->def > k->lo : k->def >= k->lo);
                assert_true(k->hi_open ? k->def < k->hi : k->def <= k->hi);
            }
        }
    }
    assert_true(n > 60);
}

/* The parameters block: "$name" values take the parameter's value, an override of
 * parameters.NAME moves them, and names the block does not declare are refused (an override of
 * one would reach nothing; a "$name" without a parameter has no value). */
static void test_parameters(void **state)
{
    (void)state;
    char *j = edit("\"gravity\": 9.81", "\"parameters\": { \"g\": 9.5 }, \"gravity\": \"$g\"");
    struct case_def c;
    char err[512] = "";
    assert_int_equal(case_parse(j, ORIGIN, NULL, 0, &c, err, sizeof err), MIXSPH_OK);
    assert_true(c.g == 9.5);
    case_free(&c);
    const mixsph_override moved[] = {{"parameters.g", 3.0}};
    assert_int_equal(case_parse(j, ORIGIN, moved, 1, &c, err, sizeof err), MIXSPH_OK);
    assert_true(c.g == 3.0);
    case_free(&c);
    const mixsph_override undeclared[] = {{"parameters.phi", 30.0}};
    assert_true(error_matches(j, undeclared, 1, MIXSPH_ERR_CASE, ORIGIN ": override parameters.phi: ",
                              "declares no parameter 'phi'", (const char *)NULL));
    free(j);
    j = edit("\"gravity\": 9.81", "\"parameters\": { \"g\": 9.5 }, \"gravity\": \"$h\"");
    assert_true(error_matches(j, NULL, 0, MIXSPH_ERR_CASE, "gravity", "'$h'", (const char *)NULL));
    free(j);
}

/* The bundled Lobovsky dam break (cases/dambreak_lobovsky.json; docs/validation/dambreak_lobovsky.md):
 * its four wall_pressure monitors P1-P4 sit on the tank's downstream wall (x = 1.61 m) around the
 * paper's sensor heights, 3, 15, 30 and 80 mm, and at dx = 0.01 and 0.005 each window holds at
 * least one particle of the wall's first layer (a window without one would read NaN for the whole
 * run); the pressure probes P1_probe-P4_probe are sensors on that wall at those heights, dry at
 * t = 0 (the water is 1 m away); parameters.H sets the column's height (0.6 x H of water: 1,800 particles at H = 0.3 and
 * 3,600 at H = 0.6, dx = 0.01). */
static void test_lobovsky_case(void **state)
{
    (void)state;
    char err[1024], *text = NULL;
    const char *path = MIXSPH_SOURCE_DIR "/cases/dambreak_lobovsky.json";
    assert_int_equal(case_read_file(path, &text, err, sizeof err), MIXSPH_OK);
    struct case_def c;
    if (case_parse(text, path, NULL, 0, &c, err, sizeof err) != MIXSPH_OK) fail_msg("%s", err);
    const char *names[] = {"P1", "P2", "P3", "P4"};
    const double z_sensor[] = {0.003, 0.015, 0.030, 0.080}, x_wall = 1.61;
    for (size_t k = 0; k < 4; k++) {
        const struct monitor_def *md = NULL;
        for (size_t m = 0; m < c.n_monitors; m++)
            if (strcmp(c.monitors[m].name, names[k]) == 0) md = &c.monitors[m];
        assert_non_null(md);
        assert_int_equal(md->kind, MONITOR_WALL_PRESSURE);
        assert_string_equal(c.walls[md->wall].name, "tank");
        assert_true(md->z_min < z_sensor[k] && z_sensor[k] < md->z_max);
        assert_true(md->x_min < x_wall && x_wall < md->x_max);
        /* and the probe at the sensor: on the same wall, at the sensor's height */
        char probe[CASE_NAME_LEN];
        snprintf(probe, sizeof probe, "%s_probe", names[k]);
        md = NULL;
        for (size_t m = 0; m < c.n_monitors; m++)
            if (strcmp(c.monitors[m].name, probe) == 0) md = &c.monitors[m];
        assert_non_null(md);
        assert_int_equal(md->kind, MONITOR_PRESSURE_PROBE);
        assert_string_equal(c.walls[md->wall].name, "tank");
        assert_true(md->point_x == x_wall && md->point_z == z_sensor[k]);
    }
    case_free(&c);
    free(text);
    const double dxs[] = {0.01, 0.005};
    for (size_t d = 0; d < 2; d++) {
        const mixsph_override ov = {"numerics.dx", dxs[d]};
        mixsph_sim *s = NULL;
        if (mixsph_sim_create(path, &ov, 1, &s, err, sizeof err) != MIXSPH_OK) fail_msg("%s", err);
        for (size_t k = 0; k < 4; k++) {
            const long o = mixsph_sim_output_find(s, names[k]);
            assert_true(o >= 0);
            assert_true(isfinite(mixsph_sim_output_value(s, (size_t)o)));
            char probe[CASE_NAME_LEN];
            snprintf(probe, sizeof probe, "%s_probe", names[k]);
            const long q = mixsph_sim_output_find(s, probe);
            assert_true(q >= 0);
            assert_true(mixsph_sim_output_value(s, (size_t)q) == 0.0); /* dry until the front arrives */
        }
        mixsph_sim_destroy(s);
    }
    mixsph_sim *s = NULL;
    assert_int_equal(mixsph_sim_create(path, NULL, 0, &s, err, sizeof err), MIXSPH_OK);
    assert_int_equal(mixsph_sim_particles(s), 1800);
    mixsph_sim_destroy(s);
    const mixsph_override tall = {"parameters.H", 0.6};
    assert_int_equal(mixsph_sim_create(path, &tall, 1, &s, err, sizeof err), MIXSPH_OK);
    assert_int_equal(mixsph_sim_particles(s), 3600);
    mixsph_sim_destroy(s);
}

/* Each row of core/numerics_keys.def that a struct of the step reads (in the order of the
 * numerics table, which is the rows' order): 1 if a struct reads it, 0 if only the creation. */
#define READ_BY_STEP(type, member, read_by, as, ...)                                     \
    (0 NUMERICS_IF_READ_BY(read_by, SCHEME, +1) NUMERICS_IF_READ_BY(read_by, PAIR, +1) \
       NUMERICS_IF_READ_BY(read_by, VISCOUS, +1)),
static const int numerics_read_by_step[] = {
#define NUMERICS_KEY READ_BY_STEP
#include "numerics_keys.def"
#undef NUMERICS_KEY
};

/* A value of a key's type, inside its range and not its default (BASE's for the keys it gives). */
static double other_value(const struct case_key *k, double now)
{
    if (k->type == CASE_BOOL) return now == 0.0 ? 1.0 : 0.0;
    if (k->type == CASE_CHOICE) {
        for (const struct case_choice *c = k->choices; c->name; c++)
            if (c->value != (int)now) return c->value;
        return now;
    }
    const double v = now > k->lo ? 0.5 * (k->lo + now) : now + fmin(1.0, 0.5 * (k->hi - now));
    return k->type == CASE_INTEGER ? ceil(v) : v;
}

/* Every numerics key a struct of the step reads arrives there when the simulation is created: each
 * set to a value other than its default, the struct's member equals the case's (the copy of sim.c
 * is generated from the same rows); and the derived eta2 follows eta2_over_h2. */
static void test_numerics_reach_the_step(void **state)
{
    (void)state;
    const struct case_section *sec = case_schema_find("numerics");
    assert_int_equal(sec->n_keys, sizeof numerics_read_by_step / sizeof numerics_read_by_step[0]);
    struct case_def base;
    char err[512] = "";
    assert_int_equal(case_parse(BASE, ORIGIN, NULL, 0, &base, err, sizeof err), MIXSPH_OK);
    mixsph_override ov[64];
    char keys[64][64];
    size_t n = 0;
    for (size_t i = 0; i < sec->n_keys; i++) {
        const struct case_key *k = &sec->keys[i];
        if (!numerics_read_by_step[i] && strcmp(k->key, "eta2_over_h2") != 0) continue;
        assert_true(n < 64);
        double now = 0.0;
        assert_int_equal(case_schema_stored_number(k, &base, &now), 0);
        snprintf(keys[n], sizeof keys[n], "numerics.%s", k->key);
        ov[n] = (mixsph_override){keys[n], other_value(k, now)};
        print_message("  %s = %g (was %g)\n", ov[n].key, ov[n].value, now);
        assert_true(ov[n].value != now);
        n++;
    }
    case_free(&base);
    assert_true(n >= 17);
    mixsph_sim *s = NULL;
    assert_int_equal(mixsph_sim_create_from_text(BASE, ORIGIN, ov, n, &s, err, sizeof err), MIXSPH_OK);
    const struct case_def *c = &s->cfg;
    for (size_t k = 0; k < n; k++) {
        double got = 0.0;
        assert_int_equal(case_number(c, ov[k].key, &got, err, sizeof err), MIXSPH_OK);
        assert_true(got == ov[k].value);
    }
#define CHECK_COPIED(type, member, read_by, as, ...)                                   \
    NUMERICS_IF_READ_BY(read_by, SCHEME, assert_true(s->scheme.as == c->member);)      \
    NUMERICS_IF_READ_BY(read_by, PAIR, assert_true(s->scheme.pair.as == c->member);)   \
    NUMERICS_IF_READ_BY(read_by, VISCOUS, assert_true(s->scheme.viscous.as == c->member);)
#define NUMERICS_KEY CHECK_COPIED
#include "numerics_keys.def"
#undef NUMERICS_KEY
    assert_true(s->scheme.pair.eta2 == c->eta2_over_h2 * s->phys.h * s->phys.h && c->eta2_over_h2 != 0.01);
    mixsph_sim_destroy(s);
}

/* The 3D wall forms and the y components are refused by a 2D case, naming the key and why; a
 * wall takes one geometry, and only its own form's keys. */
static void test_wall_forms_in_2d(void **state)
{
    (void)state;
    const char *tank = "\"polyline\": [[0.0, 0.3], [0.0, 0.0], [0.2, 0.0], [0.2, 0.3]], \"fluid_side\": \"left\"";
    EXPECT_EDIT_ERROR(tank, "\"box_min\": [0, 0, 0], \"box_max\": [1, 1, 1]",
                      ORIGIN ": walls.tank.box_min: a 3D geometry, and this case is 2D");
    EXPECT_EDIT_ERROR(tank, "\"stl\": \"tank.stl\"", ORIGIN ": walls.tank.stl: a 3D geometry, and this case is 2D");
    EXPECT_EDIT_ERROR(tank, "\"terrain\": \"dem.asc\"", ORIGIN ": walls.tank.terrain: a 3D geometry, and this case is 2D");
    EXPECT_EDIT_ERROR("\"fluid_side\": \"left\" }", "\"fluid_side\": \"left\", \"y_min\": 0, \"y_max\": 1 }",
                      ORIGIN ": walls.tank.y_min: only a 3D case extrudes a polyline across y");
    EXPECT_EDIT_ERROR("\"fluid_side\": \"left\" }", "\"fluid_side\": \"left\", \"side_walls\": \"free-slip\" }",
                      ORIGIN ": walls.tank.side_walls: only a 3D case extrudes a polyline across y");
    EXPECT_EDIT_ERROR("\"vz\": [0.0, 0.0, 0.0]", "\"vy\": [0.0, 0.0, 0.0], \"vz\": [0.0, 0.0, 0.0]",
                      ORIGIN ": motions.plate.vy: a 2D case has no velocity across y");
    EXPECT_EDIT_ERROR("\"fluid_side\": \"left\" }", "\"fluid_side\": \"left\", \"stl\": \"a.stl\" }",
                      ORIGIN ": walls.tank: give one geometry (polyline, box_min and box_max, stl or terrain), not "
                             "polyline and stl");
    EXPECT_EDIT_ERROR(tank, "\"slip\": \"no-slip\"",
                      ORIGIN ": walls.tank: missing its geometry (expected polyline, box_min and box_max, stl or terrain)");
    EXPECT_EDIT_ERROR("\"fluid_side\": \"left\" }", "\"fluid_side\": \"left\", \"open_faces\": \"none\" }",
                      ORIGIN ": walls.tank.open_faces: a polyline wall does not take this key (only box)");
}

/* A wall's friction per medium (walls.<name>.friction as an object, docs/cases.md): the media it
 * names take theirs, the others the default (NaN: the grains' own phi); the number form gives every
 * medium its value. Refused with the key and why: a name that is no medium, a medium that takes no
 * bed friction (a fluid), a value out of range or not a number, neither a number nor an object. */
static void test_wall_friction_per_medium(void **state)
{
    (void)state;
    struct case_def c;
    char err[512] = "";
    const char *tank_end = "\"fluid_side\": \"left\" },";
    char *sand = with_sand("");
    char *j = edit_text(sand, tank_end, "\"fluid_side\": \"left\", \"friction\": { \"sand\": 25 } },");
    assert_int_equal(case_parse(j, ORIGIN, NULL, 0, &c, err, sizeof err), MIXSPH_OK);
    assert_true(isnan(c.walls[0].friction_deg));
    assert_true(isnan(c.walls[0].friction_of_medium_deg[0]) && c.walls[0].friction_of_medium_deg[1] == 25.0);
    assert_true(isnan(c.walls[1].friction_of_medium_deg[1])); /* the paddle names none */
    case_free(&c);
    const mixsph_override named = {"walls.tank.friction.sand", 28.0};
    assert_int_equal(case_parse(j, ORIGIN, &named, 1, &c, err, sizeof err), MIXSPH_OK);
    assert_true(c.walls[0].friction_of_medium_deg[1] == 28.0);
    case_free(&c);
    free(j);
    j = edit_text(sand, tank_end, "\"fluid_side\": \"left\", \"friction\": 30 },");
    assert_int_equal(case_parse(j, ORIGIN, NULL, 0, &c, err, sizeof err), MIXSPH_OK);
    assert_true(c.walls[0].friction_deg == 30.0 && c.walls[0].friction_of_medium_deg[0] == 30.0 &&
                c.walls[0].friction_of_medium_deg[1] == 30.0);
    case_free(&c);
    free(j);
    static const struct {
        const char *value, *message;
    } refused[] = {
        {"{ \"gravel\": 25 }", ORIGIN ": walls.tank.friction.gravel: 'gravel' is not one of the media"},
        {"{ \"water\": 25 }", ORIGIN ": walls.tank.friction.water: medium water (type fluid) takes no bed friction"},
        {"{ \"sand\": 95 }", ORIGIN ": walls.tank.friction.sand: 95 is out of range (expected 0 <= x <= 90)"},
        {"{ \"sand\": \"steep\" }", ORIGIN ": walls.tank.friction.sand: expected a number"},
        {"[25]", ORIGIN ": walls.tank.friction: expected a number, or an object of numbers by name"},
        {"-1", ORIGIN ": walls.tank.friction: -1 is out of range (expected 0 <= x <= 90)"},
    };
    for (size_t k = 0; k < sizeof refused / sizeof refused[0]; k++) {
        char with[160];
        snprintf(with, sizeof with, "\"fluid_side\": \"left\", \"friction\": %s },", refused[k].value);
        j = edit_text(sand, tank_end, with);
        const int ok = error_matches(j, NULL, 0, MIXSPH_ERR_CASE, refused[k].message, (const char *)NULL);
        free(j);
        assert_true(ok);
    }
    free(sand);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_good_case),
        cmocka_unit_test(test_case_number),
        cmocka_unit_test(test_invalid_json),
        cmocka_unit_test(test_missing_key),
        cmocka_unit_test(test_wrong_type),
        cmocka_unit_test(test_out_of_range),
        cmocka_unit_test(test_top_level_key_paths),
        cmocka_unit_test(test_unknown_key),
        cmocka_unit_test(test_bad_reference_or_choice),
        cmocka_unit_test(test_motion_arrays),
        cmocka_unit_test(test_wall_forms_in_2d),
        cmocka_unit_test(test_overrides),
        cmocka_unit_test(test_override_parse),
        cmocka_unit_test(test_create),
        cmocka_unit_test(test_lobovsky_case),
        cmocka_unit_test(test_full_scale_errors),
        cmocka_unit_test(test_full_scale_map),
        cmocka_unit_test(test_table_ranges),
        cmocka_unit_test(test_table_types),
        cmocka_unit_test(test_table_variants),
        cmocka_unit_test(test_table_defaults),
        cmocka_unit_test(test_d50_refused),
        cmocka_unit_test(test_granular_law_by_number),
        cmocka_unit_test(test_granular_law_unnamed),
        cmocka_unit_test(test_wall_friction_per_medium),
        cmocka_unit_test(test_table_rows),
        cmocka_unit_test(test_numerics_reach_the_step),
        cmocka_unit_test(test_parameters),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
