/* test_density_bound.c - numerics.density_bound and numerics.excluded_max (lib/src/schemes/
 * integrate.c, docs/numerics.md section 2e): a particle whose updated density departs from its
 * medium's rho0 by more than the bound leaves the run as a lost particle does, is counted in
 * `excluded_particles` with its mass and energy in `excluded_mass` and `excluded_energy`, and the run goes on; past
 * excluded_max the step fails as unstable; with the bound 0 nothing is excluded; a medium
 * without tension has no lower side.
 *
 * The case: water at rest in a tank 0.4 m wide, 0.2 m deep, dx = 0.02 (200 particles), explicit
 * scheme. One particle of the top row is given a density below (or above) the bound by hand:
 * the continuity equation then keeps it there for the next step, so the update is beyond it. */
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
#include "sim_object.h"

#define G 9.81

static const char *const CASE_FMT =
    "{ \"name\": \"bound_tank\", \"gravity\": 9.81,\n"
    "  \"numerics\": { \"dx\": 0.02, \"t_end\": 1.0, \"density_diffusion\": 0 },\n"
    "  \"media\": { \"water\": { \"type\": \"fluid\", \"rho\": 1000.0, \"c\": 20.0, \"mu\": 1.0e-3, \"alpha_m\": 0.1 },\n"
    "             \"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.4, \"phi\": 35.0,\n"
    "                       \"mu_thr\": 320e3, \"mu0\": 5e3, \"tension_cutoff\": true } },\n"
    "  \"bodies\": { \"pool\": { \"medium\": \"%s\", \"polygon\": [[0.0, 0.0], [0.4, 0.0], [0.4, 0.2], [0.0, 0.2]] } },\n"
    "  \"walls\": { \"tank\": { \"polyline\": [[0.0, 0.5], [0.0, 0.0], [0.4, 0.0], [0.4, 0.5]], \"fluid_side\": \"left\" } },\n"
    "  \"output\": { \"monitor_interval\": 0.01 } }\n";

static mixsph_sim *create(const char *medium, const mixsph_override *ov, size_t n_ov)
{
    char text[4096];
    snprintf(text, sizeof text, CASE_FMT, medium);
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_status st = mixsph_sim_create_from_text(text, "bound_tank.json", ov, n_ov, &s, err, sizeof err);
    if (st != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
    return s;
}

static double output(mixsph_sim *s, const char *name)
{
    const long k = mixsph_sim_output_find(s, name);
    assert_true(k >= 0);
    return mixsph_sim_output_value(s, (size_t)k);
}

/* The particle of the top row nearest the tank's middle. */
static size_t top_middle(const mixsph_sim *s)
{
    const struct particles *P = &s->phys.P;
    size_t best = P->n;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] > MIXSPH_STATE_FIXED) continue; /* grains may be held fixed: still updated */
        if (best == P->n || P->pos[DIM_UP][i] > P->pos[DIM_UP][best] + 1e-9 ||
            (fabs(P->pos[DIM_UP][i] - P->pos[DIM_UP][best]) <= 1e-9 && fabs(P->pos[0][i] - 0.2) < fabs(P->pos[0][best] - 0.2)))
            best = i;
    }
    assert_true(best < P->n);
    return best;
}

static size_t index_of(const mixsph_sim *s, unsigned id)
{
    for (size_t i = 0; i < s->phys.P.n; i++)
        if (s->phys.P.id[i] == id) return i;
    fail();
    return 0;
}

/* Give particle i of s density `ratio` rho0; returns its id. */
static unsigned set_density(mixsph_sim *s, size_t i, double ratio)
{
    struct particles *P = &s->phys.P;
    P->rho[i] = ratio * s->cfg.media[P->medium[i]].rho0;
    return P->id[i];
}

/* Below the bound: excluded at the next step, counted, its energy kept; the run goes on. */
static void test_excluded_below(void **state)
{
    (void)state;
    mixsph_sim *s = create("water", NULL, 0);
    struct particles *P = &s->phys.P;
    const double mass0 = output(s, "mass");
    size_t i = top_middle(s);
    const unsigned id = set_density(s, i, 0.6); /* 0.6 rho0, beyond the default bound 0.3 */
    /* the explicit step drifts with v + dt/2 a and excludes the particle with that velocity and
     * its drifted height: the energy it takes away (reference: computed here from its state) */
    const double dt = s->phys.dt, m = P->m[i];
    const double vx = P->vel[0][i] + 0.5 * dt * P->acc[0][i], vz = P->vel[DIM_UP][i] + 0.5 * dt * P->acc[DIM_UP][i];
    assert_int_equal(mixsph_sim_step(s), MIXSPH_OK);
    i = index_of(s, id);
    assert_int_equal(P->state[i], MIXSPH_STATE_LOST);
    const double e_expected = m * (0.5 * (vx * vx + vz * vz) + G * P->pos[DIM_UP][i]);
    assert_true(output(s, "excluded_particles") == 1.0);
    assert_true(output(s, "lost_particles") == 0.0); /* lost: left the domain, a different count */
    /* reference: the sum above; tolerance: round-off of one product */
    assert_true(fabs(output(s, "excluded_energy") - e_expected) <= 1e-12 * fabs(e_expected));
    /* the mass output drops by the particle's mass exactly (reference: its m) */
    assert_true(fabs(output(s, "mass") - (mass0 - m)) <= 1e-12 * mass0);
    assert_true(output(s, "excluded_mass") == m);
    /* the run goes on without it, and no other particle goes beyond the bound */
    for (int k = 0; k < 100; k++) assert_int_equal(mixsph_sim_step(s), MIXSPH_OK);
    assert_true(output(s, "excluded_particles") == 1.0);
    mixsph_sim_destroy(s);
}

/* Above the bound too (1.35 rho0), in a medium of either kind. */
static void test_excluded_above(void **state)
{
    (void)state;
    const char *media[] = {"water", "sand"};
    for (int k = 0; k < 2; k++) {
        mixsph_sim *s = create(media[k], NULL, 0);
        const unsigned id = set_density(s, top_middle(s), 1.35);
        assert_int_equal(mixsph_sim_step(s), MIXSPH_OK);
        assert_int_equal(s->phys.P.state[index_of(s, id)], MIXSPH_STATE_LOST);
        assert_true(output(s, "excluded_particles") == 1.0);
        mixsph_sim_destroy(s);
    }
}

/* A medium without tension (tension_cutoff) has no lower side: a grain at 0.5 rho0 stays. */
static void test_no_lower_side_without_tension(void **state)
{
    (void)state;
    mixsph_sim *s = create("sand", NULL, 0);
    const unsigned id = set_density(s, top_middle(s), 0.5);
    assert_int_equal(mixsph_sim_step(s), MIXSPH_OK);
    const size_t i = index_of(s, id);
    assert_int_not_equal(s->phys.P.state[i], MIXSPH_STATE_LOST);
    assert_true(s->phys.P.rho[i] < 0.7 * s->cfg.media[s->phys.P.medium[i]].rho0);
    assert_true(output(s, "excluded_particles") == 0.0);
    mixsph_sim_destroy(s);
}

/* density_bound 0: nothing is excluded (the paper's cases). */
static void test_bound_off(void **state)
{
    (void)state;
    const mixsph_override ov[] = {{"numerics.density_bound", 0.0}};
    mixsph_sim *s = create("water", ov, 1);
    const unsigned id = set_density(s, top_middle(s), 0.6);
    assert_int_equal(mixsph_sim_step(s), MIXSPH_OK);
    assert_int_not_equal(s->phys.P.state[index_of(s, id)], MIXSPH_STATE_LOST);
    assert_true(output(s, "excluded_particles") == 0.0);
    mixsph_sim_destroy(s);
}

/* Past excluded_max the step fails as unstable and says why: 0.01 of 200 particles allows 2. */
static void test_excluded_max(void **state)
{
    (void)state;
    mixsph_sim *s = create("water", NULL, 0);
    struct particles *P = &s->phys.P;
    size_t top[3], n = 0;
    const size_t first = top_middle(s);
    for (size_t i = 0; i < P->n && n < 3; i++) /* three particles of the top row */
        if (P->state[i] == MIXSPH_STATE_MOBILE && fabs(P->pos[DIM_UP][i] - P->pos[DIM_UP][first]) < 1e-9) top[n++] = i;
    assert_int_equal(n, 3);
    assert_int_equal(s->scheme.excluded_limit, 2);
    for (size_t k = 0; k < n; k++) set_density(s, top[k], 0.6);
    const mixsph_status st = mixsph_sim_step(s);
    const char *msg = mixsph_sim_last_error(s);
    print_message("%s\n", msg);
    assert_int_equal(st, MIXSPH_ERR_UNSTABLE);
    assert_non_null(strstr(msg, "numerics.excluded_max"));
    assert_non_null(strstr(msg, "t = "));
    assert_non_null(strstr(msg, "particle"));
    mixsph_sim_destroy(s);
}

/* Bad values are refused naming the key. */
static void test_bad_values(void **state)
{
    (void)state;
    const char *keys[] = {"numerics.density_bound", "numerics.density_bound", "numerics.excluded_max"};
    const double values[] = {-0.1, 1.0, 1.5};
    for (int k = 0; k < 3; k++) {
        char text[4096];
        snprintf(text, sizeof text, CASE_FMT, "water");
        const mixsph_override ov = {keys[k], values[k]};
        mixsph_sim *s = NULL;
        char err[512] = "";
        assert_int_equal(mixsph_sim_create_from_text(text, "bound_tank.json", &ov, 1, &s, err, sizeof err),
                         MIXSPH_ERR_CASE);
        assert_null(s);
        assert_non_null(strstr(err, strchr(keys[k], '.') + 1));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_excluded_below),
        cmocka_unit_test(test_excluded_above),
        cmocka_unit_test(test_no_lower_side_without_tension),
        cmocka_unit_test(test_bound_off),
        cmocka_unit_test(test_excluded_max),
        cmocka_unit_test(test_bad_values),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
