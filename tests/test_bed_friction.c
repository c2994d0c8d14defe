/* test_bed_friction.c - the Coulomb friction of a bed on grains (passes/bed_friction.h,
 * docs/model.md [BF]).
 *
 * The contact of one grain: a sliding grain gets tan(delta) N' against its slip, whatever shear
 * the law gave; a grain at rest whose other forces stay below the bound is held; the background
 * and pore pressures are no contact force; a wall never pulls. Then the short Coulomb block
 * (cases/coulomb_block.json, dx = 0.02, 0.6 s) under both granular laws: its centroid's speed
 * against the Coulomb block's, the criterion of the validation (tools/coulomb_block.py runs the
 * full set at dx and dx/2 in the validation suite). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "bed_friction.h"
#include "geometry.h"
#include "sim.h"
#include "sim_object.h"

/* A grain of 1 kg per m on a bed of normal (0, 1): the walls press it with N = 10 N per m and the
 * law's shear on it is +0.1 N per m along x; tan(delta) = 0.5. */
static struct bed_contact grain_on_bed(void)
{
    struct bed_contact c = {.tan_delta = 0.5, .mass = 1.0, .volume = 1e-4, .dt = 1e-3};
    c.wall_force[0] = 0.1;
    c.wall_force[DIM_UP] = 10.0;
    c.normal[DIM_UP] = 2.0;
    c.force[0] = 0.1;
    c.force[DIM_UP] = 10.0 - 9.81;
    return c;
}

static void test_sliding_grain_takes_the_kinetic_friction(void **state)
{
    (void)state;
    struct bed_contact c = grain_on_bed();
    c.velocity[0] = 1.0; /* sliding along +x */
    double ch[DIM];
    bed_friction_change(&c, ch);
    /* the wall's tangential force becomes -tan(delta) N = -5 (the law's +0.1 removed); exact
     * arithmetic of [BF], so to round-off */
    assert_true(fabs(c.wall_force[0] + ch[0] - (-5.0)) < 1e-12);
    assert_true(fabs(ch[DIM_UP]) < 1e-12); /* the normal force stays */
    /* a moving wall: the slip is relative to it (the grain at the wall's speed and no other force
     * along it is held: no friction) */
    c.wall_velocity[0] = 1.0;
    c.force[0] = c.wall_force[0];
    bed_friction_change(&c, ch);
    assert_true(fabs(c.wall_force[0] + ch[0]) < 1e-12);
}

static void test_grain_at_rest_is_held_below_the_bound(void **state)
{
    (void)state;
    struct bed_contact c = grain_on_bed();
    c.force[0] = 0.1 + 3.0; /* the law's shear and 3 N per m of other forces along x, below 5 */
    double ch[DIM];
    bed_friction_change(&c, ch);
    assert_true(fabs(c.force[0] + ch[0]) < 1e-12); /* held: no tangential force left */
    c.force[0] = 0.1 + 7.0; /* above the bound: it slides off with 7 - 5 */
    bed_friction_change(&c, ch);
    assert_true(fabs(c.force[0] + ch[0] - 2.0) < 1e-12);
}

static void test_pressures_are_no_contact_force(void **state)
{
    (void)state;
    struct bed_contact c = grain_on_bed();
    c.velocity[0] = 1.0;
    c.p_background = 1e4; /* 2 p_b V |n| = 2 1e4 1e-4 2 = 4 N per m of the 10 */
    c.pore_pressure = 5e3; /* and 2 N per m more */
    double ch[DIM];
    bed_friction_change(&c, ch);
    assert_true(fabs(c.wall_force[0] + ch[0] - (-0.5 * 4.0)) < 1e-12);
    /* a wall that would pull the grain (N' < 0) exerts no effective force on it */
    c.wall_force[DIM_UP] = 3.0;
    bed_friction_change(&c, ch);
    assert_true(fabs(c.wall_force[0] + ch[0]) < 1e-12);
    assert_true(fabs(c.wall_force[DIM_UP] + ch[DIM_UP] - 2.0 * (1e4 + 5e3) * 1e-4 * 2.0) < 1e-12);
}

/* The short Coulomb block: cases/coulomb_block.json (45-degree ramp) with delta = 30 degrees at
 * dx = 0.02 to t = 0.6 s, under law `law` (0 the paper's, 1 elastic-plastic). Returns its
 * centroid's speed along the ramp over the Coulomb block's at the travel it has made. */
static double short_block_ratio(double law)
{
    const double a = 45.0 * GEOM_PI / 180.0, delta = 30.0 * GEOM_PI / 180.0;
    const mixsph_override ov[] = {{"parameters.law", law}, {"parameters.delta", 30.0}, {"numerics.dx", 0.02},
                                  {"numerics.t_end", 0.6}, {"output.snapshot_interval", 0.0}};
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_status st = mixsph_sim_create(MIXSPH_SOURCE_DIR "/cases/coulomb_block.json", ov,
                                               sizeof ov / sizeof ov[0], &s, err, sizeof err);
    if (st != MIXSPH_OK) fail_msg("%s", err);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
    const struct particles *P = &s->phys.P;
    double s0 = 0.0, s1 = 0.0, u = 0.0;
    size_t n = 0;
    for (size_t i = 0; i < P->n; i++)
        if (P->state[i] < MIXSPH_STATE_WALL) {
            s0 += P->pos[0][i] * cos(a) - P->pos[DIM_UP][i] * sin(a);
            n++;
        }
    assert_int_equal(mixsph_sim_advance_to(s, 0.6), MIXSPH_OK);
    size_t n1 = 0;
    for (size_t i = 0; i < P->n; i++)
        if (P->state[i] < MIXSPH_STATE_WALL) {
            s1 += P->pos[0][i] * cos(a) - P->pos[DIM_UP][i] * sin(a);
            u += P->vel[0][i] * cos(a) - P->vel[DIM_UP][i] * sin(a);
            n1++;
        }
    assert_int_equal(n1, n); /* none lost */
    const double travel = (s1 - s0) / (double)n, speed = u / (double)n;
    const double ref = sqrt(2.0 * 9.81 * (sin(a) - cos(a) * tan(delta)) * travel);
    print_message("short Coulomb block, law %g, 45-degree ramp, delta 30, dx 0.02, t 0.6 s: travel %.3f m, "
                  "speed %.3f m/s, Coulomb block %.3f m/s, ratio %.3f\n", law, travel, speed, ref, speed / ref);
    mixsph_sim_destroy(s);
    return speed / ref;
}

/* Criterion (issue 59): the Coulomb block's speed sqrt(2 g L (sin a - cos a tan delta)) within
 * 10 %. Measured (12-07): elastic-plastic 0.988, paper 0.987. Broken once on purpose: with the
 * law's own wall shear only bounded by tan(delta) N' (the elastic-plastic law's wall friction
 * before the contact) the elastic-plastic block is 1.158 and fails; the paper law then 1.023. */
static void test_short_block_elastic_plastic(void **state)
{
    (void)state;
    assert_true(fabs(short_block_ratio(1.0) - 1.0) <= 0.10);
}

static void test_short_block_paper(void **state)
{
    (void)state;
    assert_true(fabs(short_block_ratio(0.0) - 1.0) <= 0.10);
}

/* Two blocks of dry sand (phi 35, elastic-plastic) on one 45-degree ramp whose friction names each
 * medium (walls.ramp.friction = {"lower": 20, "upper": 30}): the lower block, s 0.6 to 0.9 along the
 * ramp, of medium "lower", the upper one, s 0 to 0.3, of medium "upper" (it slides slower, so the
 * two part); both 0.1 m thick, on a ramp from s = -0.15 to 2.4 (cases/coulomb_block.json's block and
 * ramp shortened, for the test's time). */
static char *two_block_case(double dx, double t_end)
{
    const double c = cos(45.0 * GEOM_PI / 180.0), sn = sin(45.0 * GEOM_PI / 180.0);
    double x[2][4], z[2][4];
    const double s0[2] = {0.6, 0.0}, corner_s[4] = {0.0, 0.3, 0.3, 0.0}, corner_d[4] = {0.0, 0.0, 0.1, 0.1};
    for (int b = 0; b < 2; b++)
        for (int k = 0; k < 4; k++) {
            const double s = s0[b] + corner_s[k], d = corner_d[k];
            x[b][k] = s * c + d * sn;
            z[b][k] = -s * sn + d * c;
        }
    const char *medium = "{ \"type\": \"granular\", \"law\": \"elastic_plastic\", \"rho\": 2650.0, "
                         "\"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0, \"saturated\": false, "
                         "\"pore_pressure\": \"granular_column\" }";
    char *text = malloc(4096);
    if (!text) return NULL;
    snprintf(text, 4096,
             "{ \"name\": \"two_blocks\", \"gravity\": 9.81,\n"
             "  \"numerics\": { \"dx\": %g, \"t_end\": %g, \"wall_placement\": \"aligned\" },\n"
             "  \"media\": { \"lower\": %s, \"upper\": %s },\n"
             "  \"bodies\": {\n"
             "    \"lower_block\": { \"medium\": \"lower\", \"polygon\": [[%.9f, %.9f], [%.9f, %.9f], [%.9f, %.9f], [%.9f, %.9f]] },\n"
             "    \"upper_block\": { \"medium\": \"upper\", \"polygon\": [[%.9f, %.9f], [%.9f, %.9f], [%.9f, %.9f], [%.9f, %.9f]] } },\n"
             "  \"walls\": { \"ramp\": { \"polyline\": [[%.9f, %.9f], [%.9f, %.9f]], \"fluid_side\": \"left\",\n"
             "             \"slip\": \"no-slip\", \"friction\": { \"lower\": 20, \"upper\": 30 } } },\n"
             "  \"domain\": { \"x_min\": -0.3, \"x_max\": 2.0, \"z_min\": -1.9, \"z_max\": 0.45 },\n"
             "  \"output\": { \"monitor_interval\": 0.01 } }\n",
             dx, t_end, medium, medium, x[0][0], z[0][0], x[0][1], z[0][1], x[0][2], z[0][2], x[0][3], z[0][3],
             x[1][0], z[1][0], x[1][1], z[1][1], x[1][2], z[1][2], x[1][3], z[1][3], -0.15 * c, 0.15 * sn, 2.4 * c,
             -2.4 * sn);
    return text;
}

/* Each wall-medium pair's coefficient reaches the momentum pass's table (bed_friction.h): the two
 * the ramp names, tan(20) and tan(30), exactly as bed_friction_coefficient gives them. */
/* The two-block case at spacing dx to t_end, created (failing the test if it is refused). */
static mixsph_sim *two_block_sim(double dx, double t_end)
{
    char *text = two_block_case(dx, t_end);
    assert_non_null(text);
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_status st = mixsph_sim_create_from_text(text, "two_blocks", NULL, 0, &s, err, sizeof err);
    free(text);
    if (st != MIXSPH_OK) fail_msg("%s", err);
    return s;
}

static void test_friction_per_medium_reaches_the_step(void **state)
{
    (void)state;
    mixsph_sim *s = two_block_sim(0.04, 0.01);
    const double *mu = s->scheme.pair.bed_mu.mu;
    assert_true(s->scheme.pair.bed_friction);
    assert_true(s->scheme.pair.bed_per_medium); /* the ramp's two angles: the pass reads the table */
    assert_true(mu[0 * BED_FRICTION_SIDE + 0] == tan(20.0 * GEOM_PI / 180.0)); /* wall 0 on medium 0, lower */
    assert_true(mu[0 * BED_FRICTION_SIDE + 1] == tan(30.0 * GEOM_PI / 180.0)); /* on medium 1, upper */
    mixsph_sim_destroy(s);
    assert_true(bed_friction_coefficient(NAN) == BED_FRICTION_OWN);
    assert_true(bed_friction_coefficient(90.0) == BED_FRICTION_NONE);
    assert_true(bed_friction_coefficient(0.0) == 0.0);
}

/* The two blocks at dx = 0.02 to t = 0.6 s: each block's centroid speed along the ramp over its
 * own Coulomb block's, sqrt(2 g L (sin a - cos a tan delta)) at the travel L it has made, in
 * ratio[0] (lower, delta 20) and ratio[1] (upper, delta 30); swapped[b] the same against the
 * other block's delta. */
static void two_block_ratios(double ratio[2], double swapped[2])
{
    const double a = 45.0 * GEOM_PI / 180.0, delta[2] = {20.0 * GEOM_PI / 180.0, 30.0 * GEOM_PI / 180.0};
    mixsph_sim *s = two_block_sim(0.02, 0.6);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
    const struct particles *P = &s->phys.P;
    double s0[2] = {0.0, 0.0}, s1[2] = {0.0, 0.0}, u[2] = {0.0, 0.0};
    size_t n0[2] = {0, 0}, n1[2] = {0, 0};
    for (size_t i = 0; i < P->n; i++)
        if (P->state[i] < MIXSPH_STATE_WALL) {
            s0[P->medium[i]] += P->pos[0][i] * cos(a) - P->pos[DIM_UP][i] * sin(a);
            n0[P->medium[i]]++;
        }
    assert_int_equal(mixsph_sim_advance_to(s, 0.6), MIXSPH_OK);
    for (size_t i = 0; i < P->n; i++)
        if (P->state[i] < MIXSPH_STATE_WALL) {
            s1[P->medium[i]] += P->pos[0][i] * cos(a) - P->pos[DIM_UP][i] * sin(a);
            u[P->medium[i]] += P->vel[0][i] * cos(a) - P->vel[DIM_UP][i] * sin(a);
            n1[P->medium[i]]++;
        }
    for (int b = 0; b < 2; b++) {
        assert_int_equal(n1[b], n0[b]); /* none lost */
        const double travel = (s1[b] - s0[b]) / (double)n0[b], speed = u[b] / (double)n0[b];
        const double ref = sqrt(2.0 * 9.81 * (sin(a) - cos(a) * tan(delta[b])) * travel);
        const double other = sqrt(2.0 * 9.81 * (sin(a) - cos(a) * tan(delta[1 - b])) * travel);
        ratio[b] = speed / ref;
        swapped[b] = speed / other;
        print_message("two blocks, 45-degree ramp, dx 0.02, t 0.6 s: %s block (delta %g): travel %.3f m, speed "
                      "%.3f m/s, Coulomb block %.3f m/s, ratio %.3f (%.3f against the other's delta)\n",
                      b == 0 ? "lower" : "upper", delta[b] * 180.0 / GEOM_PI, travel, speed, ref, ratio[b], swapped[b]);
    }
    mixsph_sim_destroy(s);
}

/* Criterion (issue 59, as the Coulomb block's): each block within 10 % of its own Coulomb speed.
 * Against the other block's delta the speeds differ by sqrt(4.41 / 2.93) = 1.23 (the Coulomb
 * accelerations of delta 20 and 30 on 45 degrees), so a wall that gave both media one delta
 * (either) or swapped them would fail one of the two assertions. Measured (12-07): 1.006 and
 * 0.988 (1.234 and 0.805 against the other's delta). Broken once on purpose: with the table
 * giving every medium the first one's delta (20) the upper block is 1.191 and fails. */
static void test_two_media_slide_at_their_own_coulomb_speeds(void **state)
{
    (void)state;
    double ratio[2], swapped[2];
    two_block_ratios(ratio, swapped);
    assert_true(fabs(ratio[0] - 1.0) <= 0.10);
    assert_true(fabs(ratio[1] - 1.0) <= 0.10);
    assert_true(fabs(swapped[0] - 1.0) > 0.10 && fabs(swapped[1] - 1.0) > 0.10); /* the test can tell them apart */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sliding_grain_takes_the_kinetic_friction),
        cmocka_unit_test(test_grain_at_rest_is_held_below_the_bound),
        cmocka_unit_test(test_pressures_are_no_contact_force),
        cmocka_unit_test(test_short_block_elastic_plastic),
        cmocka_unit_test(test_short_block_paper),
        cmocka_unit_test(test_friction_per_medium_reaches_the_step),
        cmocka_unit_test(test_two_media_slide_at_their_own_coulomb_speeds),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
