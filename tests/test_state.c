/* test_state.c - state save/restore (state.c) and the external wall drive (sim.c, walls.c):
 * a restored state continues bit for bit as the original (in place and in a new simulation
 * created from the state alone), a state of another case or a damaged buffer is refused with a
 * message and leaves the simulation unchanged, and a wall driven by an external velocity moves
 * by exactly v t and takes a new velocity at once. Case: the Vajont Padua case (granular
 * landslide, water, moving plate) at a coarse dx, so every part of the state (grains, wall
 * motion, monitors) is exercised; the slope tank for the velocity jump. */
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

#define VAJONT MIXSPH_SOURCE_DIR "/cases/vajont_padua.json"
#define EROSIVE MIXSPH_SOURCE_DIR "/cases/erosive_dambreak.json"

/* The Vajont case's spacing here: coarse, as a saved state's completeness does not depend on it
 * (at 0.04 as at 0.03 m the grains held at t = 0 are mobilised within 5 ms; the plate moves and
 * the monitors record), and the test runs Vajont three times to 0.1 s: 1.1 s here, 2.9 s at 0.03 m,
 * 13 times that under ASan. */
#define STATE_DX 0.04

static mixsph_sim *make(double dx, double phi)
{
    const mixsph_override ov[2] = {{"numerics.dx", dx}, {"parameters.phi", phi}};
    mixsph_sim *s = NULL;
    char err[512];
    const mixsph_status st = mixsph_sim_create(VAJONT, ov, 2, &s, err, sizeof err);
    if (st != MIXSPH_OK) fprintf(stderr, "%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
    return s;
}

/* Bitwise equality of everything observable: time, step, dt, all particle fields (the order is
 * part of the state), every output's value and extremes. */
static int same(const mixsph_sim *a, const mixsph_sim *b)
{
    if (mixsph_sim_time(a) != mixsph_sim_time(b) || mixsph_sim_steps(a) != mixsph_sim_steps(b) ||
        mixsph_sim_dt(a) != mixsph_sim_dt(b))
        return 0;
    mixsph_particles_view u, v;
    mixsph_sim_particles_view(a, &u);
    mixsph_sim_particles_view(b, &v);
    if (u.n != v.n) return 0;
    const double *fu[7] = {u.pos[0], u.pos[u.dim - 1], u.vel[0], u.vel[u.dim - 1], u.rho, u.p, u.mu}, *fv[7] = {v.pos[0], v.pos[v.dim - 1], v.vel[0], v.vel[v.dim - 1], v.rho, v.p, v.mu};
    for (int k = 0; k < 7; k++)
        if (memcmp(fu[k], fv[k], u.n * sizeof(double)) != 0) return 0;
    if (memcmp(u.state, v.state, u.n) || memcmp(u.medium, v.medium, u.n) || memcmp(u.id, v.id, u.n * sizeof(uint32_t)))
        return 0;
    for (size_t k = 0; k < mixsph_sim_output_count(a); k++) {
        double ea[4], eb[4];
        mixsph_sim_output_extremes(a, k, &ea[0], &ea[1], &ea[2], &ea[3]);
        mixsph_sim_output_extremes(b, k, &eb[0], &eb[1], &eb[2], &eb[3]);
        const double va = mixsph_sim_output_value(a, k), vb = mixsph_sim_output_value(b, k);
        if (memcmp(ea, eb, sizeof ea) != 0 || memcmp(&va, &vb, sizeof va) != 0) return 0;
    }
    return 1;
}

/* A simulation created from the state alone, on the given threads, and run to t2 equals ref bit for
 * bit, and names the case file it came from. */
static void created_from_state_continues(const void *buf, size_t len, const mixsph_sim *ref, double t2, int threads,
                                         const char *origin)
{
    mixsph_sim *c = NULL;
    char err[512];
    assert_int_equal(mixsph_sim_create_from_state(buf, len, &c, err, sizeof err), MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(c, threads), MIXSPH_OK);
    assert_string_equal(mixsph_sim_case_origin(c), origin);
    assert_int_equal(mixsph_sim_advance_to(c, t2), MIXSPH_OK);
    assert_true(same(c, ref));
    mixsph_sim_destroy(c);
}

/* save at t1 = 0.05 s, run to t2 = 0.1 s (A); restore, run to t2 again (B): A == B bit for bit; a second
 * simulation created from the state alone and run to t2 equals A too. */
static void test_restore_continues_identically(void **state)
{
    (void)state;
    mixsph_sim *s = make(STATE_DX, 35.0), *ref = make(STATE_DX, 35.0);
    assert_int_equal(mixsph_sim_advance_to(s, 0.05), MIXSPH_OK);
    void *buf = NULL;
    size_t len = 0;
    assert_int_equal(mixsph_sim_save_state(s, &buf, &len), MIXSPH_OK);
    assert_non_null(buf);
    assert_true(len > 1000);
    assert_int_equal(mixsph_sim_advance_to(s, 0.1), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(ref, 0.1), MIXSPH_OK);
    assert_true(same(s, ref)); /* saving does not disturb the run */

    assert_int_equal(mixsph_sim_load_state(s, buf, len), MIXSPH_OK);
    assert_true(mixsph_sim_time(s) < 0.05 + 1e-3 && mixsph_sim_time(s) >= 0.05);
    assert_int_equal(mixsph_sim_advance_to(s, 0.1), MIXSPH_OK);
    assert_true(same(s, ref));

    created_from_state_continues(buf, len, ref, 0.1, 2, VAJONT); /* pair loops do not depend on the threads */
    mixsph_state_free(buf);
    mixsph_sim_destroy(s);
    mixsph_sim_destroy(ref);
}

/* The same with the implicit viscous step and rigid held grains, which are judged on the
 * accelerations of the last momentum pass (viscous.h): on the erosive dam break (a bed of held
 * grains under moving water) with the artificial viscosity between media and on separating pairs
 * too, so that those accelerations depend on the velocities, a state saved at 0.05 s (the water
 * starting to run over the bed, 38 grains held) and restored continues bit for bit to 0.07 s. */
static void test_restore_rigid_held_grains(void **state)
{
    (void)state;
    const mixsph_override ov[] = {{"numerics.dx", 0.02}, {"numerics.viscosity", 1.0}, {"numerics.held_grains", 1.0},
                                  {"numerics.av_mixed", 1.0}, {"numerics.av_separating", 1.0}};
    mixsph_sim *s = NULL, *ref = NULL;
    char err[512];
    assert_int_equal(mixsph_sim_create(EROSIVE, ov, 5, &s, err, sizeof err), MIXSPH_OK);
    assert_int_equal(mixsph_sim_create(EROSIVE, ov, 5, &ref, err, sizeof err), MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(ref, 1), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(s, 0.05), MIXSPH_OK);
    const long k_fixed = mixsph_sim_output_find(s, "fixed_particles");
    /* held grains to judge (38 at t = 0.05 s at this spacing; the save comes early so that the test
     * stays short under the sanitizers) */
    assert_true(k_fixed >= 0 && mixsph_sim_output_value(s, (size_t)k_fixed) > 0.0);
    void *buf = NULL;
    size_t len = 0;
    assert_int_equal(mixsph_sim_save_state(s, &buf, &len), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(s, 0.07), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(ref, 0.07), MIXSPH_OK);
    assert_int_equal(mixsph_sim_load_state(s, buf, len), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(s, 0.07), MIXSPH_OK);
    assert_true(same(s, ref));
    created_from_state_continues(buf, len, ref, 0.07, 1, EROSIVE);
    mixsph_state_free(buf);
    mixsph_sim_destroy(s);
    mixsph_sim_destroy(ref);
}

/* Refusals: another case's state, a flipped byte, a truncated buffer, garbage. Each leaves the
 * simulation as it was (it then continues exactly as an untouched twin). */
static void test_bad_states_are_refused(void **state)
{
    (void)state;
    mixsph_sim *s = make(STATE_DX, 35.0), *twin = make(STATE_DX, 35.0), *other = make(STATE_DX, 25.0);
    assert_int_equal(mixsph_sim_advance_to(s, 0.05), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(twin, 0.05), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(other, 0.02), MIXSPH_OK);
    void *buf = NULL;
    size_t len = 0;
    assert_int_equal(mixsph_sim_save_state(other, &buf, &len), MIXSPH_OK);

    assert_int_equal(mixsph_sim_load_state(s, buf, len), MIXSPH_ERR_ARG);
    assert_non_null(strstr(mixsph_sim_last_error(s), "another case"));

    unsigned char *bad = malloc(len);
    assert_non_null(bad);
    memcpy(bad, buf, len);
    bad[len / 2] ^= 0x10;
    assert_int_equal(mixsph_sim_load_state(other, bad, len), MIXSPH_ERR_ARG);
    assert_non_null(strstr(mixsph_sim_last_error(other), "checksum"));
    assert_int_equal(mixsph_sim_load_state(other, buf, len - 100), MIXSPH_ERR_ARG);
    assert_int_equal(mixsph_sim_load_state(other, "not a state at all, not a state", 31), MIXSPH_ERR_ARG);
    assert_non_null(strstr(mixsph_sim_last_error(other), "not a mixsph state"));
    mixsph_sim *c = NULL;
    char err[512] = "";
    assert_int_equal(mixsph_sim_create_from_state(bad, len, &c, err, sizeof err), MIXSPH_ERR_ARG);
    assert_null(c);
    assert_non_null(strstr(err, "checksum"));
    free(bad);
    mixsph_state_free(buf);

    assert_int_equal(mixsph_sim_advance_to(s, 0.1), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(twin, 0.1), MIXSPH_OK);
    assert_true(same(s, twin));
    mixsph_sim_destroy(s);
    mixsph_sim_destroy(twin);
    mixsph_sim_destroy(other);
}

/* Mean x of the plate's wall particles (medium = wall index of "plate", the second wall). */
static double plate_x(const mixsph_sim *s)
{
    mixsph_particles_view v;
    mixsph_sim_particles_view(s, &v);
    double sum = 0.0;
    size_t n = 0;
    for (size_t i = 0; i < v.n; i++)
        if (v.state[i] == MIXSPH_STATE_WALL && v.medium[i] == 1) {
            sum += v.pos[0][i];
            n++;
        }
    assert_true(n > 0);
    return sum / (double)n;
}

/* An external velocity replaces the plate's law: over [t0, t1] the plate moves by vx (t1 - t0)
 * (to rounding: reference is the exact displacement of a constant velocity); released, it
 * follows its law again (faster than the drive at t = 0.08 s, so it moves further). Bad
 * requests are refused. The drive is part of the saved state. */
static void test_external_wall_velocity(void **state)
{
    (void)state;
    mixsph_sim *s = make(STATE_DX, 35.0);
    assert_int_equal(mixsph_sim_set_wall_velocity(s, "bed", 0.1, 0.0), MIXSPH_ERR_ARG);
    assert_non_null(strstr(mixsph_sim_last_error(s), "fixed"));
    assert_int_equal(mixsph_sim_set_wall_velocity(s, "nope", 0.1, 0.0), MIXSPH_ERR_ARG);
    assert_non_null(strstr(mixsph_sim_last_error(s), "no such wall"));
    assert_int_equal(mixsph_sim_set_wall_velocity(s, "plate", NAN, 0.0), MIXSPH_ERR_ARG);
    assert_int_equal(mixsph_sim_set_wall_velocity(s, "plate", 0.05, 0.0), MIXSPH_OK);
    const double x0 = plate_x(s), t0 = mixsph_sim_time(s);
    assert_int_equal(mixsph_sim_advance_to(s, 0.05), MIXSPH_OK);
    const double moved = plate_x(s) - x0, expected = 0.05 * (mixsph_sim_time(s) - t0);
    assert_true(fabs(moved - expected) < 1e-9); /* constant velocity: exact up to rounding */

    void *buf = NULL;
    size_t len = 0;
    assert_int_equal(mixsph_sim_save_state(s, &buf, &len), MIXSPH_OK);
    mixsph_sim *c = NULL;
    assert_int_equal(mixsph_sim_create_from_state(buf, len, &c, NULL, 0), MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(c, 1), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(s, 0.08), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(c, 0.08), MIXSPH_OK);
    assert_true(same(s, c)); /* the restored simulation is still driven */
    mixsph_state_free(buf);

    assert_int_equal(mixsph_sim_release_wall_velocity(s, "plate"), MIXSPH_OK);
    const double x1 = plate_x(s), t1 = mixsph_sim_time(s);
    assert_int_equal(mixsph_sim_advance_to(s, 0.1), MIXSPH_OK);
    /* the law's speed over [0.08, 0.1] s is 0.167-0.209 m/s (cases/vajont_padua.json), over three times
     * the drive of 0.05 m/s */
    assert_true(plate_x(s) - x1 > 0.15 * (mixsph_sim_time(s) - t1));
    mixsph_sim_destroy(c);
    mixsph_sim_destroy(s);
}

/* Fastest fluid or granular particle [m/s]. */
static double fastest(const mixsph_sim *s)
{
    mixsph_particles_view v;
    mixsph_sim_particles_view(s, &v);
    double u = 0.0;
    for (size_t i = 0; i < v.n; i++)
        if (v.state[i] <= MIXSPH_STATE_FIXED) u = fmax(u, hypot(v.vel[0][i], v.vel[v.dim - 1][i]));
    return u;
}

/* A drive that jumps to a new speed takes effect at once: the ram's particles carry it before
 * the next step, and the grains held fixed against the ram are mobilised by it instead of being
 * kicked with mu_thr over a time step made for mu0. Case: cases/slope_tank.json (the FMU's test
 * case), its ram driven at U = 1.5 m/s along its law's direction from t = 0, when every grain is
 * held fixed, and again after a pause at rest. Reference: a grain shoved by a piston moving at U
 * moves at about U (momentum); bound 2 U. With the drive's stale state (the wall pass of the old
 * velocity) the fastest grain reached 27.6 m/s within 0.02 s, and the FMU's run failed at 0.1 s. */
static void test_external_velocity_jump(void **state)
{
    (void)state;
    const double U = 1.5, ux = 0.715 / hypot(0.715, 0.358), uz = -0.358 / hypot(0.715, 0.358);
    for (int pause = 0; pause < 2; pause++) {
        mixsph_sim *s = NULL;
        char err[512];
        const mixsph_status st = mixsph_sim_create(MIXSPH_SOURCE_DIR "/cases/slope_tank.json", NULL, 0, &s, err, sizeof err);
        if (st != MIXSPH_OK) fprintf(stderr, "%s\n", err);
        assert_int_equal(st, MIXSPH_OK);
        assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
        if (pause) {
            assert_int_equal(mixsph_sim_set_wall_velocity(s, "ram", 0.0, 0.0), MIXSPH_OK);
            assert_int_equal(mixsph_sim_advance_to(s, 0.05), MIXSPH_OK);
        }
        assert_int_equal(mixsph_sim_set_wall_velocity(s, "ram", U * ux, U * uz), MIXSPH_OK);
        mixsph_particles_view v;
        mixsph_sim_particles_view(s, &v);
        for (size_t i = 0; i < v.n; i++)
            if (v.state[i] == MIXSPH_STATE_WALL && v.medium[i] == 1) { /* the ram is the second wall */
                assert_true(v.vel[0][i] == U * ux);
                assert_true(v.vel[v.dim - 1][i] == U * uz);
            }
        const double t0 = mixsph_sim_time(s);
        double worst = 0.0;
        for (int k = 1; k <= 10; k++) {
            assert_int_equal(mixsph_sim_advance_to(s, t0 + 0.002 * k), MIXSPH_OK);
            worst = fmax(worst, fastest(s));
        }
        if (worst >= 2.0 * U) fprintf(stderr, "pause %d: fastest particle %g m/s\n", pause, worst);
        assert_true(worst < 2.0 * U);
        mixsph_sim_destroy(s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_restore_continues_identically),
        cmocka_unit_test(test_restore_rigid_held_grains),
        cmocka_unit_test(test_bad_states_are_refused),
        cmocka_unit_test(test_external_wall_velocity),
        cmocka_unit_test(test_external_velocity_jump),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
