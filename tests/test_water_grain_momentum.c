/* test_water_grain_momentum.c - the water-grain coupling conserves momentum (issue "A granular
 * stress that knows no time step": "total momentum conserved to round-off in a closed box";
 * docs/model.md section 10, "The water-grain coupling").
 *
 * A block of grains (0.1 x 0.1 m, dx = 0.01) flies at 1 m/s into a block of water at rest
 * (0.2 x 0.1 m) in the middle of a box whose one wall lies 1 m away. No gravity: it is the only
 * external force on the particles besides the walls', so without it the pair forces (pressure,
 * artificial viscosity, laminar viscosity, the grains' deviatoric stress), every one of which
 * forces.c adds to i and subtracts from j, are all there is. The test checks at every step that
 * no particle is within reach (2h) of a wall particle, so no wall force enters; then
 * sum_i m_i v_i over the water and the grains must stay what it was, to round-off, while the
 * grains run 8 cm into the water and set it moving (0.08 s, about 1,300-1,600 steps).
 *
 * Tolerance, in eps = DBL_EPSILON times the momentum scale S = sum_i m_i |v_i| (its largest value
 * over the run, 19-20 kg m/s per m) for N = 300 particles after n steps: eps S (N + 4 n).
 * N: each of the two sums of m v (at the start and now) rounds by at most (N - 1) eps S / 2
 * (recursive summation); 4 n: each step rounds every velocity in its two half kicks, at most
 * eps S in all, and the pair-force sums and the divisions by the masses, by eps times the pair
 * impulse dt sum_ij |f_ij|, which a brute-force sum of the pair terms at every 100th step put at
 * 0.005 to 0.07 S here, so 3 eps S covers them with room. Measured: the drift stays below 5.4e-14
 * kg m/s per m (about 12 eps S) and does not grow with the steps, 0.015-0.026 of the bound.
 * Sensitivity (measured by making forces.c subtract (1 + delta) times each pair force from j):
 * delta = 1e-13 drifts by 3-5e-12, 0.3-0.6 of the bound; delta = 1e-12 fails.
 *
 * The grains under both granular laws (the elastic-plastic one also with water_coupling "grains"),
 * each with the default numerics and with every switch
 * that changes what the pair force carries or the pressures it uses (ALL_SWITCHES):
 * elastic_plastic (the deviatoric stress of each grain enters the pair force; mu = 0, so water and
 * grains exchange no laminar viscous force), and the paper's law (its mixture viscosity,
 * harmonically averaged with the water's, couples them; no stress). Under the paper's law a
 * grain whose apparent viscosity reaches mu_thr is held and its velocity set to 0: a kinematic
 * constraint, an external force that does not conserve momentum (docs/model.md section 6). A
 * block moving rigidly has no strain rate, so all its grains would be held at the first step;
 * the paper-law block is sheared a little (random velocities of up to 0.05 m/s on the 1 m/s) and
 * momentum is compared over the steps before the first held grain (none is held in these runs).
 * With the implicit viscous step the exchange is conserved only to the solve's tolerance (the
 * last test). */
#include <float.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "sim.h"
#include "test_random.h"

/* The grains' medium (`grain`: the law's keys) at x in [0, 0.1], the water at x in [0.11, 0.31],
 * both z in [0, 0.1]; one far wall 1 m below; `numerics`: more numerics keys. */
static const char *box_case(const char *grain, const char *numerics)
{
    static char buf[2048];
    snprintf(buf, sizeof buf,
             "{ \"name\": \"water_grain_box\", \"gravity\": 0.0,"
             "  \"numerics\": { \"dx\": 0.01, \"h_over_dx\": 1.3, \"t_end\": 1.0, \"wall_layers\": 3 %s },"
             "  \"media\": { \"water\": { \"type\": \"fluid\", \"rho\": 1000.0, \"K\": 1.6e6, \"mu\": 1.0e-3,"
             "                            \"alpha_m\": 0.075 },"
             "              \"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.35,"
             "                          \"phi\": 35.0, %s } },"
             "  \"bodies\": { \"grains\": { \"medium\": \"sand\","
             "                              \"polygon\": [[0.0, 0.0], [0.1, 0.0], [0.1, 0.1], [0.0, 0.1]] },"
             "               \"pool\": { \"medium\": \"water\","
             "                           \"polygon\": [[0.11, 0.0], [0.31, 0.0], [0.31, 0.1], [0.11, 0.1]] } },"
             "  \"walls\": { \"far\": { \"polyline\": [[-1.0, -1.0], [1.4, -1.0]], \"fluid_side\": \"left\" } },"
             "  \"domain\": { \"x_min\": -1.2, \"x_max\": 1.6, \"z_min\": -1.2, \"z_max\": 1.2 } }",
             numerics, grain);
    return buf;
}

struct momentum {
    double px, pz;  /* sum m v [kg m/s per m] */
    double scale;   /* sum m |v| */
};

static struct momentum total_momentum(const struct particles *P)
{
    struct momentum M = {0.0, 0.0, 0.0};
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] == MIXSPH_STATE_WALL) continue;
        M.px += P->m[i] * P->vel[0][i];
        M.pz += P->m[i] * P->vel[DIM_UP][i];
        M.scale += P->m[i] * hypot(P->vel[0][i], P->vel[DIM_UP][i]);
    }
    return M;
}

/* No particle within the support 2h of a wall particle: no wall force acts. */
static int clear_of_walls(const mixsph_sim *s)
{
    const struct particles *P = &s->phys.P;
    double zmin = INFINITY, zwall = -INFINITY;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] == MIXSPH_STATE_WALL) zwall = fmax(zwall, P->pos[DIM_UP][i]);
        else zmin = fmin(zmin, P->pos[DIM_UP][i]);
    }
    return zmin - zwall > sqrt(s->phys.K.r2max);
}

/* Kick the grains: vx = 1 m/s plus up to `jitter` m/s of random velocity in each component. */
static void launch_grains(mixsph_sim *s, double jitter)
{
    struct particles *P = &s->phys.P;
    uint64_t rng = 44;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] == MIXSPH_STATE_WALL || s->cfg.media[P->medium[i]].law == LAW_NEWTONIAN) continue;
        P->vel[0][i] = P->uv[0][i] = 1.0 + test_random_uniform(&rng, -jitter, jitter);
        P->vel[DIM_UP][i] = P->uv[DIM_UP][i] = test_random_uniform(&rng, -jitter, jitter);
    }
}

static size_t held_grains(const struct particles *P)
{
    size_t n = 0;
    for (size_t i = 0; i < P->n; i++) n += P->state[i] == MIXSPH_STATE_FIXED;
    return n;
}

/* Run the box of `grain` to t_end (or until the first held grain) and compare sum m v with the
 * start: with `roundoff`, asserting the round-off bound at every step; *largest_drift: the
 * largest |sum m v - its start| [kg m/s per m]. Returns the steps compared. */
static unsigned long run_box_drift(const char *grain, const char *numerics, double jitter, double t_end, int roundoff,
                                   double *largest_drift)
{
    mixsph_sim *s = NULL;
    char err[512] = "";
    assert_int_equal(mixsph_sim_create_from_text(box_case(grain, numerics), "box", NULL, 0, &s, err, sizeof err),
                     MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
    launch_grains(s, jitter);
    const struct particles *P = &s->phys.P;
    const struct momentum M0 = total_momentum(P);
    size_t n_summed = 0;
    for (size_t i = 0; i < P->n; i++) n_summed += P->state[i] != MIXSPH_STATE_WALL;
    double scale = M0.scale, worst = 0.0, worst_drift = 0.0;
    unsigned long steps = 0;
    size_t water_moving = 0;
    while (mixsph_sim_time(s) < t_end) {
        assert_int_equal(mixsph_sim_step(s), MIXSPH_OK);
        if (held_grains(P) > 0) break; /* the paper law's constraint acts from here on */
        steps++;
        assert_true(clear_of_walls(s));
        const struct momentum M = total_momentum(P);
        scale = fmax(scale, M.scale);
        const double drift = hypot(M.px - M0.px, M.pz - M0.pz);
        /* reference: M0 (no external force); tolerance: eps S (N + 4 n) (head of file) */
        const double bound = DBL_EPSILON * scale * ((double)n_summed + 4.0 * (double)steps);
        worst = fmax(worst, drift / bound);
        worst_drift = fmax(worst_drift, drift);
        if (roundoff) assert_true(drift <= bound);
    }
    for (size_t i = 0; i < P->n; i++)
        water_moving += P->state[i] != MIXSPH_STATE_WALL && s->cfg.media[P->medium[i]].law == LAW_NEWTONIAN &&
                        P->vel[0][i] > 0.01;
    print_message("%s%s: %lu steps to t = %.4f s, |P0| = %.6f kg m/s/m, S = %.6f, largest drift %.3g kg m/s/m, "
                  "largest drift / bound = %.3g, water particles pushed above 1 cm/s: %zu\n",
                  grain, numerics, steps, mixsph_sim_time(s), hypot(M0.px, M0.pz), scale, worst_drift, worst, water_moving);
    /* the blocks met: momentum went from the grains into the water */
    assert_true(water_moving > 20);
    mixsph_sim_destroy(s);
    *largest_drift = worst_drift;
    return steps;
}

static unsigned long run_box(const char *grain, const char *numerics, double jitter, double t_end)
{
    double drift;
    return run_box_drift(grain, numerics, jitter, t_end, 1, &drift);
}

/* The numerics switches that change what the pair force carries or the pressures it is made of:
 * the artificial viscosity between the media and between separating particles too, SPHERA's
 * pressure smoothing, the density diffusion (within the water). */
static const char *const ALL_SWITCHES =
    ", \"av_mixed\": true, \"av_separating\": true, \"pressure_smoothing\": 0.4, \"density_diffusion\": 0.1";

/* 0.08 s: the grains have run 8 cm into the water; nothing comes near the wall. */
static void test_elastic_plastic_grains(void **state)
{
    (void)state;
    assert_true(run_box("\"law\": \"elastic_plastic\"", "", 0.0, 0.08) > 1000);
    assert_true(run_box("\"law\": \"elastic_plastic\"", ALL_SWITCHES, 0.0, 0.08) > 1000);
}

/* The same with water_coupling "grains" (docs/model.md [GW]): the grain's side of a grain-water pair
 * takes the water's interpolated pressure instead of its own and Ergun's drag acts between them;
 * both stay pair forces added to i and subtracted from j, so the same round-off bound holds. */
static void test_grains_in_water(void **state)
{
    (void)state;
    const char *grains = "\"law\": \"elastic_plastic\", \"water_coupling\": \"grains\", \"grain_diameter\": 0.002";
    assert_true(run_box(grains, "", 0.0, 0.08) > 1000);
    assert_true(run_box(grains, ALL_SWITCHES, 0.0, 0.08) > 1000);
}

/* The paper's law with the Vajont mu_thr and mu0 = 1 Pa s (a viscous time step near the acoustic
 * one); sheared by the random velocities, no grain reaches mu_thr in these 0.08 s (checked: the
 * comparison stops at the first held grain, and it must come after the blocks met). */
static void test_paper_grains(void **state)
{
    (void)state;
    assert_true(run_box("\"mu_thr\": 320e3, \"mu0\": 1.0", "", 0.05, 0.08) > 1000);
    assert_true(run_box("\"mu_thr\": 320e3, \"mu0\": 1.0", ALL_SWITCHES, 0.05, 0.08) > 1000);
}

/* The implicit viscous step (numerics.viscosity = "implicit") solves the viscous exchange with
 * BiCGSTAB to a relative residual (numerics.viscous_tolerance, 1e-6 by default): the pairs' couplings
 * are symmetric, but an inexact solution is not momentum-neutral, so sum m v drifts by what the
 * solve leaves, not by round-off. Measured (this box, paper law, mu0 = 100 Pa s, 0.08 s, ~1,270
 * steps): largest drift 6.3e-6 kg m/s per m at tolerance 1e-6 (3.6e-7 of the momentum), 4.5e-7 at
 * 1e-8, 7.0e-9 at 1e-10, 2.7e-11 at 1e-12. Asserted: the drift at 1e-6 is more than the round-off
 * bound of the explicit runs can explain (1e-10 S, S = 19.6), and it falls at least 100-fold from
 * tolerance 1e-6 to 1e-10 (measured 890-fold), i.e. it is the solve's. */
static void test_implicit_viscosity_conserves_to_its_tolerance(void **state)
{
    (void)state;
    const char *paper = "\"mu_thr\": 320e3, \"mu0\": 100.0";
    double loose, tight;
    run_box_drift(paper, ", \"viscosity\": \"implicit\"", 0.05, 0.08, 0, &loose);
    run_box_drift(paper, ", \"viscosity\": \"implicit\", \"viscous_tolerance\": 1e-10", 0.05, 0.08, 0, &tight);
    print_message("implicit viscosity: largest drift %.3g (tolerance 1e-6), %.3g (1e-10) kg m/s per m\n", loose, tight);
    assert_true(loose > 1e-10 * 19.6);
    assert_true(tight < 1e-2 * loose);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_elastic_plastic_grains),
        cmocka_unit_test(test_grains_in_water),
        cmocka_unit_test(test_paper_grains),
        cmocka_unit_test(test_implicit_viscosity_conserves_to_its_tolerance),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
