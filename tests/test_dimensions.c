/* test_dimensions.c - the library for both dimensions (lib/src/sim_dimension.c: the 2D and 3D
 * builds in one binary, the executable's and the FMU's), through the public API only: a 2D and
 * a 3D case in one process, each in the build of its "dimensions" (their views are 2D and 3D,
 * and a second 2D run gives the same numbers); a 3D state and checkpoint come back in the 3D
 * build; a "dimensions" override and a bad value. That the 2D path is the 2D library's, bit for
 * bit, is checked by tools/bit_identity.py on the executable. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "mixsph.h"

#define CASE(name) MIXSPH_SOURCE_DIR "/cases/" name

static mixsph_sim *create(const char *path, const mixsph_override *ov, size_t n_ov)
{
    mixsph_sim *s = NULL;
    char err[1024] = "";
    const mixsph_status st = mixsph_sim_create(path, ov, n_ov, &s, err, sizeof err);
    if (st != MIXSPH_OK) fprintf(stderr, "%s: %s\n", path, err);
    assert_int_equal(st, MIXSPH_OK);
    return s;
}

static int view_dim(const mixsph_sim *s)
{
    mixsph_particles_view v;
    assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
    return v.dim;
}

/* A 2D and a 3D case side by side in one process, each stepped in its own build. */
static void test_two_and_three_dimensions_in_one_process(void **state)
{
    (void)state;
    const mixsph_override short_run = {"numerics.t_end", 0.01};
    mixsph_sim *two = create(CASE("hydrostatic_tank.json"), &short_run, 1);
    mixsph_sim *three = create(CASE("falling_block_3d.json"), &short_run, 1);
    assert_int_equal(view_dim(two), 2);
    assert_int_equal(view_dim(three), 3);
    assert_int_equal(mixsph_sim_particles(three), 10 * 10 * 10); /* the 0.1 m cube at dx = 0.01 */
    assert_int_equal(mixsph_sim_advance_to(two, 0.01), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(three, 0.01), MIXSPH_OK);
    assert_true(mixsph_sim_steps(two) > 0 && mixsph_sim_steps(three) > 0);
    /* the 3D cube falls freely: its top (max_elevation) 0.1 - dx/2 - g t^2 / 2 to within the
     * leapfrog's exactness for a constant acceleration and the top particles' own pressure
     * forces over 0.01 s (0.1 mm) */
    const long top = mixsph_sim_output_find(three, "top");
    assert_true(top >= 0);
    const double t = mixsph_sim_time(three);
    assert_true(fabs(mixsph_sim_output_value(three, (size_t)top) - (0.095 - 0.5 * 9.81 * t * t)) < 1e-4);
    /* the same 2D case again: the same numbers to the last bit (the 2D build's, deterministic) */
    mixsph_sim *again = create(CASE("hydrostatic_tank.json"), &short_run, 1);
    assert_int_equal(mixsph_sim_advance_to(again, 0.01), MIXSPH_OK);
    mixsph_particles_view a, b;
    assert_int_equal(mixsph_sim_particles_view(two, &a), MIXSPH_OK);
    assert_int_equal(mixsph_sim_particles_view(again, &b), MIXSPH_OK);
    assert_int_equal(a.n, b.n);
    for (int d = 0; d < 2; d++) assert_memory_equal(a.pos[d], b.pos[d], a.n * sizeof(double));
    assert_null(a.pos[2]);
    mixsph_sim_destroy(again);
    mixsph_sim_destroy(two);
    mixsph_sim_destroy(three);
    mixsph_sim_destroy(NULL);
}

/* A 3D state and a 3D checkpoint are loaded by the 3D build (their header says so). */
static void test_state_and_checkpoint_keep_their_dimension(void **state)
{
    (void)state;
    mixsph_sim *s = create(CASE("falling_block_3d.json"), NULL, 0);
    assert_int_equal(mixsph_sim_advance_to(s, 0.005), MIXSPH_OK);
    void *buf = NULL;
    size_t len = 0;
    assert_int_equal(mixsph_sim_save_state(s, &buf, &len), MIXSPH_OK);
    mixsph_sim *r = NULL;
    char err[512];
    assert_int_equal(mixsph_sim_create_from_state(buf, len, &r, err, sizeof err), MIXSPH_OK);
    mixsph_state_free(buf);
    assert_int_equal(view_dim(r), 3);
    assert_true(mixsph_sim_time(r) == mixsph_sim_time(s));
    mixsph_sim_destroy(r);

    char dir[] = "/tmp/test_dimensions_XXXXXX", path[128];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/checkpoint.h5", dir);
    assert_int_equal(mixsph_sim_write_checkpoint(s, path), MIXSPH_OK);
    assert_int_equal(mixsph_sim_create_from_checkpoint(path, &r, err, sizeof err), MIXSPH_OK);
    assert_int_equal(view_dim(r), 3);
    assert_true(mixsph_sim_time(r) == mixsph_sim_time(s));
    mixsph_sim_destroy(r);
    remove(path);
    rmdir(dir);
    /* not a state: the 2D build says why */
    const char junk[64] = "not a state";
    assert_int_equal(mixsph_sim_create_from_state(junk, sizeof junk, &r, err, sizeof err), MIXSPH_ERR_ARG);
    assert_null(r);
    mixsph_sim_destroy(s);
}

/* "dimensions" by override, and a value that is neither 2 nor 3. */
static void test_dimensions_override_and_bad_value(void **state)
{
    (void)state;
    /* the 2D tank told it is 3D: the 3D build refuses its 2D geometry, naming it */
    const mixsph_override three = {"dimensions", 3};
    mixsph_sim *s = NULL;
    char err[1024] = "";
    assert_int_equal(mixsph_sim_create(CASE("hydrostatic_tank.json"), &three, 1, &s, err, sizeof err), MIXSPH_ERR_CASE);
    assert_null(s);
    assert_non_null(strstr(err, "bodies.pool: a 3D polygon body needs y_min < y_max"));
    const mixsph_override four = {"dimensions", 4};
    assert_int_equal(mixsph_sim_create(CASE("hydrostatic_tank.json"), &four, 1, &s, err, sizeof err), MIXSPH_ERR_CASE);
    assert_non_null(strstr(err, "dimensions"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_two_and_three_dimensions_in_one_process),
        cmocka_unit_test(test_state_and_checkpoint_keep_their_dimension),
        cmocka_unit_test(test_dimensions_override_and_bad_value),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
