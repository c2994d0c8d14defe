/* test_granular.c - dry granular media with the mixture rheology (Manenti et al. 2018, eqs. (10),
 * (12) and Fig. 1; docs/model.md section 6: the three regimes of mu_thr and mu0). Dry sand:
 * rho_s = 2650 kg/m3, K_s = 4.24e6 Pa (c = 40 m/s), porosity 0.35 (mixture density
 * 1722.5 kg/m3), phi = 35 deg, on a no-slip floor.
 *
 * (a) A heap below the angle of repose stays at rest, held fixed. With the limiting viscosity
 *     active (mu0 < mu_thr) the model turns slowly deforming grains into a Newtonian fluid of
 *     viscosity mu0, so a heap below phi creeps (strain rate ~ tau / (2 mu0)): that is the model,
 *     not a defect, and this heap is run with the limit off (mu0 = 1e12 Pa s) and the threshold
 *     of Run 7, mu_thr = 5 kPa s.
 *     Every grain stays held fixed, and fixed grains are never drifted, so no particle can move:
 *     what this test can fail on is that all grains are evaluated (fixed_particles = number of
 *     grains at every sample) and that dt is the viscous bound of the fixed grains; test (a2)
 *     checks a heap that the rheology must hold with mobile grains. The test runs the full 1 s
 *     at dx = 0.01 (about 190 grains, 172k steps). Measured once at dx = 0.005 (744 grains + 360
 *     wall particles, 687,039 steps, 13 min on one core): no grain moved over the full 1 s, all
 *     744 fixed at every sample, while the fixed grains' pressures relax slowly (mean 517 -> 497 Pa
 *     at 0.2 s -> 439 Pa at 1 s, largest change of one grain 148 Pa at 0.2 s, 337 Pa at 1 s).
 * (a2) The same heap with MOBILE grains: mu_thr = 1e12 Pa s (the case reader's largest value; a
 *     grain is held fixed only where mu_app >= mu_thr, i.e. at an exactly zero strain rate, so
 *     after the first step none is) and the Vajont limiting viscosity mu0 = 5 kPa s. The
 *     reference is rest: below phi the rheology holds the heap, up to the creep of the limited
 *     regime, a Newtonian fluid of viscosity mu0. That creep is bounded by the lubrication
 *     estimate of a viscous layer of depth d on a slope S, surface speed rho g S d^2 / (2 mu0):
 *     with S = tan 25 deg, d up to the heap's height 0.093 m, at most 6.8 mm/s, i.e. 0.068 dx
 *     in 0.1 s. So the criterion is: every grain within 0.1 dx of its start over 0.1 s.
 *     THE MODEL DOES NOT MEET IT (measured, dx = 0.01, 186 grains): largest displacement 0.03,
 *     0.14, 0.32, 0.53, 0.76 dx at t = 0.02, 0.04, ..., 0.1 s (mean 0.005 -> 0.19 dx), kinetic
 *     energy growing from 0.0013 to 0.034 J, the fastest grains those at the apex; nearly the
 *     same with mu0 = 20 kPa s (0.70 dx at 0.1 s) and still 0.34 dx with phi = 60 deg, so it is
 *     neither the creep of mu0 nor the friction angle: by t = 0.01 s only 56 of the 186 grains
 *     are in the limited regime (mu = mu0), 124 are frictional (mu_app < mu0) and by 0.05 s 76
 *     have mu < 100 Pa s (presumably the start-up's acoustic velocity noise, c = 40 m/s, gives
 *     strain rates at which sigma' sin(phi) / (2 sqrt(II_D)) < mu0). The heap is then held only
 *     by the frictional stress; the likely cause, not verified, is that the Morris Laplacian with
 *     pairwise harmonic-mean viscosities (forces.c) is not the divergence of that stress where mu
 *     varies from grain to grain (mu_ij -> 0 next to any grain whose mu -> 0). The test asserts
 *     what holds today (all grains mobile after the first step, within 0.1 dx at t = 0.02 s, no
 *     grain through the floor) and the criterion over 0.1 s is kept as a known failure:
 *     `test_granular known_failure heap_mobile` (CTest test_granular_known_heap_mobile) passes
 *     while the heap moves as far as it does today (known_failure.h), so CTest reports both the
 *     day the rheology holds the heap and a heap that moves much farther.
 * (a3) The heap with the implicit viscous step and mu0 off (mu0 = mu_thr): the grains carry their
 *     full frictional viscosity. With mu_thr = 1e12 Pa s it stays at rest over 1 s (the criterion
 *     of (a2), met); with the Vajont mu_thr = 320 kPa s it holds until about 0.35 s and then
 *     slumps with the harmonic pair mean of the viscosities and held grains "solved" (a known
 *     failure, `test_granular known_failure heap_implicit_vajont`: the creep at mu_thr dilates the
 *     apex until it goes into tension), and stays at rest with the arithmetic mean
 *     (numerics.viscosity_mean = "arithmetic", met) and with rigid held grains
 *     (numerics.held_grains = "rigid", met), which keep the explicit scheme's rule for releasing a
 *     grain at rest: checked both ways on a column, which that rule collapses with mu0 = 5 kPa s
 *     and holds with mu0 off, as the explicit scheme does.
 * (b) A square column collapses with the Vajont rheology (mu_thr = 320 kPa s, mu0 = 5 kPa s):
 *     it spreads, stops, and its final surface is no steeper than phi; its run-out against the
 *     experiments' is a known failure at the test's resolution (see the comment of (b) below). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "known_failure.h"
#include "mixsph.h"

#define PI 3.14159265358979323846
#define PHI 35.0 /* [deg] */

static mixsph_sim *create(const char *text, const char *origin, double dx)
{
    const mixsph_override ov[] = {{"numerics.dx", dx}};
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_status st = mixsph_sim_create_from_text(text, origin, ov, 1, &s, err, sizeof err);
    if (st != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK); /* ctest -j runs tests side by side */
    return s;
}

static void advance(mixsph_sim *s, double t)
{
    const mixsph_status st = mixsph_sim_advance_to(s, t);
    if (st != MIXSPH_OK) print_error("%s\n", mixsph_sim_last_error(s));
    assert_int_equal(st, MIXSPH_OK);
}

static size_t output(const mixsph_sim *s, const char *name)
{
    const long k = mixsph_sim_output_find(s, name);
    assert_true(k >= 0);
    return (size_t)k;
}

/* ---- (a) heap at rest ---------------------------------------------------------------------- */

#define HEAP_DX 0.01 /* [m] */
#define HEAP_T 1.0  /* [s] simulated, as the issue asks (validation suite) */
#define HEAP_T_SHORT 0.1 /* [s] the short version's (./tools/do test) */

/* The particles' current positions by id (caller frees *x0, *z0). */
static void positions_by_id(const mixsph_sim *s, double **x0, double **z0)
{
    mixsph_particles_view v;
    assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
    *x0 = calloc(v.n, sizeof **x0);
    *z0 = calloc(v.n, sizeof **z0);
    assert_non_null(*x0);
    assert_non_null(*z0);
    for (size_t i = 0; i < v.n; i++) {
        assert_true(v.id[i] < v.n);
        (*x0)[v.id[i]] = v.pos[0][i];
        (*z0)[v.id[i]] = v.pos[v.dim - 1][i];
    }
}

/* cases/granular_heap.json: a triangle of base 0.4 m and slopes of 25 deg (height 0.2 tan 25 =
 * 0.0933 m), below phi = 35 deg, with mu_thr and mu0 (its parameters) and further settings
 * overridden; snapshots off. */
static mixsph_sim *create_heap(double mu_thr, double mu0, const mixsph_override *more, size_t n_more)
{
    mixsph_override ov[8] = {{"parameters.mu_thr", mu_thr}, {"parameters.mu0", mu0}, {"output.snapshot_interval", 0.0}};
    size_t n = 3;
    for (size_t k = 0; k < n_more && n < 8; k++) ov[n++] = more[k];
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_status st = mixsph_sim_create(MIXSPH_SOURCE_DIR "/cases/granular_heap.json", ov, n, &s, err, sizeof err);
    if (st != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK); /* ctest -j runs tests side by side */
    return s;
}

/* The heap of (a) to t_end, sampled at every tenth of it. */
static void heap_at_rest(double t_end)
{
    mixsph_sim *s = create_heap(5.0e3, 1.0e12, NULL, 0);
    const size_t n = mixsph_sim_particles(s);
    const size_t out_fixed = output(s, "fixed_particles"), out_dt = output(s, "dt"), out_ke = output(s, "kinetic_energy");
    /* initial positions by id */
    double *x0, *z0;
    positions_by_id(s, &x0, &z0);
    mixsph_particles_view v;
    /* the time step is the viscous bound of the fixed grains with min(mu0, mu_thr) = 5 kPa s:
     * 0.05 * 2 h^2 rho / mu = 0.1 * 0.013^2 * 1722.5 / 5000 = 5.82e-6 s (h = 1.3 dx; rho within
     * 0.1% of the mixture density), not the acoustic 0.1 * 2h / c = 6.5e-5 s: the grains are
     * evaluated by the rheology (integrate.c); tolerance 1% */
    const double dt_vis = 0.05 * 2.0 * (1.3 * HEAP_DX) * (1.3 * HEAP_DX) * 1722.5 / 5.0e3;
    print_message("heap: %zu grains, dt = %.4g s (viscous bound %.4g s)\n", n, mixsph_sim_dt(s), dt_vis);
    assert_true(fabs(mixsph_sim_dt(s) - dt_vis) <= 0.01 * dt_vis);

    double worst = 0.0; /* largest displacement of any grain at any sample [m] */
    for (int k = 1; k <= 10; k++) {
        advance(s, 0.1 * k * t_end);
        assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
        double now = 0.0, p_mean = 0.0;
        for (size_t i = 0; i < v.n; i++) {
            if (v.state[i] == MIXSPH_STATE_WALL) continue;
            assert_true(v.state[i] != MIXSPH_STATE_LOST);
            now = fmax(now, hypot(v.pos[0][i] - x0[v.id[i]], v.pos[v.dim - 1][i] - z0[v.id[i]]));
            p_mean += v.p[i] / (double)n;
        }
        worst = fmax(worst, now);
        print_message("  t = %.2f s: %llu steps, dt = %.4g s, fixed %g of %zu, KE %.3g J, mean p %.1f Pa, "
                      "largest displacement %.3g dx\n",
                      mixsph_sim_time(s), (unsigned long long)mixsph_sim_steps(s), mixsph_sim_dt(s),
                      mixsph_sim_output_value(s, out_fixed), n, mixsph_sim_output_value(s, out_ke), p_mean, now / HEAP_DX);
        assert_true(fabs(mixsph_sim_dt(s) - dt_vis) <= 0.01 * dt_vis);
    }
    /* every grain was evaluated and held at every monitor sample (one every 0.01 s) */
    double fmax_, tmax, fmin_, tmin;
    mixsph_sim_output_extremes(s, out_fixed, &fmax_, &tmax, &fmin_, &tmin);
    assert_true(fmin_ == (double)n && fmax_ == (double)n);
    mixsph_sim_output_extremes(s, out_dt, &fmax_, &tmax, &fmin_, &tmin);
    assert_true(fmax_ <= 1.01 * dt_vis);
    /* reference: at rest (slope 25 deg < phi = 35 deg); tolerance 0.1 dx at every sample (issue) */
    assert_true(worst <= 0.1 * HEAP_DX);
    free(x0);
    free(z0);
    mixsph_sim_destroy(s);
}

/* (a) over the full 1 s (validation suite, `test_granular validation`: 172k steps). */
static void test_heap_at_rest(void **state)
{
    (void)state;
    heap_at_rest(HEAP_T);
}

/* (a), short: the same checks over the first 0.1 s (17k steps). A grain the rheology does not
 * evaluate, or releases, shows at the first sample (0.01 s): fixed grains are never drifted and a
 * released one moves from then on; what the long run adds is the slow relaxation of the fixed
 * grains' pressures (header), under which every grain stays held. */
static void test_heap_at_rest_short(void **state)
{
    (void)state;
    heap_at_rest(HEAP_T_SHORT);
}

/* ---- (a2) heap of mobile grains ------------------------------------------------------------ */

#define MOBILE_MU_THR 1.0e12 /* [Pa s]: the case reader's largest value, never reached while moving */
#define MOBILE_MU0 5.0e3     /* [Pa s]: the Vajont limiting viscosity */
#define MOBILE_T 0.1         /* [s]: the lubrication creep of mu0 stays below 0.068 dx (header) */
#define MOBILE_T_NOW 0.02    /* [s]: the part of it the model meets today (header) */

/* Run the heap of mobile grains to t_end, sampling every 0.01 s; returns the largest
 * displacement of any grain [m] at any sample up to t_end. Asserts the premise at every sample:
 * no grain held fixed after the first step, every grain at mu <= mu0, none lost or through the
 * floor. */
static double mobile_heap(double t_end)
{
    mixsph_sim *s = create_heap(MOBILE_MU_THR, MOBILE_MU0, NULL, 0);
    const size_t n = mixsph_sim_particles(s);
    const size_t out_fixed = output(s, "fixed_particles"), out_ke = output(s, "kinetic_energy");
    double *x0, *z0;
    positions_by_id(s, &x0, &z0);
    mixsph_particles_view v;
    double worst = 0.0;
    for (int k = 1; k <= (int)lround(t_end / 0.01); k++) {
        advance(s, 0.01 * k);
        assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
        double now = 0.0, mean = 0.0;
        int limited = 0;
        for (size_t i = 0; i < v.n; i++) {
            if (v.state[i] == MIXSPH_STATE_WALL) continue;
            assert_int_equal(v.state[i], MIXSPH_STATE_MOBILE); /* premise: mobile grains */
            assert_true(v.mu[i] <= MOBILE_MU0);                 /* regimes "limited" or "frictional" */
            assert_true(v.pos[v.dim - 1][i] > 0.0);                          /* none through the floor */
            const double d = hypot(v.pos[0][i] - x0[v.id[i]], v.pos[v.dim - 1][i] - z0[v.id[i]]);
            now = fmax(now, d);
            mean += d / (double)n;
            limited += v.mu[i] == MOBILE_MU0;
        }
        assert_true(mixsph_sim_output_value(s, out_fixed) == 0.0);
        worst = fmax(worst, now);
        print_message("  t = %.2f s: %llu steps, largest displacement %.3f dx, mean %.4f dx, %d of %zu grains at mu0, "
                      "KE %.3g J\n",
                      mixsph_sim_time(s), (unsigned long long)mixsph_sim_steps(s), now / HEAP_DX, mean / HEAP_DX, limited,
                      n, mixsph_sim_output_value(s, out_ke));
    }
    free(x0);
    free(z0);
    mixsph_sim_destroy(s);
    return worst;
}

/* (a2) what the model meets today: mobile grains, at rest to 0.1 dx over the first 0.02 s. */
static void test_heap_mobile(void **state)
{
    (void)state;
    const double worst = mobile_heap(MOBILE_T_NOW);
    /* reference: at rest (slope 25 deg < phi = 35 deg, up to the creep of mu0: below 0.014 dx by
     * t = 0.02 s, header); tolerance 0.1 dx (issue). Over the first 0.02 s only: the model
     * leaves it at t = 0.035 s (header) */
    assert_true(worst <= 0.1 * HEAP_DX);
}

/* Today's band of test_heap_mobile_at_rest: the largest displacement over 0.1 s, 0.759452 dx,
 * measured on 2026-12-06 (GCC 12, -O3, aa173ae with these tests), the same to 6 digits at 1
 * and 2 threads. Margin 20 % of the value (0.61-0.91 dx): the run is deterministic, so
 * the margin is what counts as a change, wide because the heap's motion is a growing instability
 * (kinetic energy x26 over 0.1 s) that small changes of the numerics shift, and still well clear
 * of the criterion (0.1 dx). */
#define HEAP_MOBILE_MEASURED 0.7595
#define HEAP_MOBILE_MARGIN 0.20
/* (a2) the criterion: at rest to 0.1 dx over 0.1 s. A known failure (header). */
static void test_heap_mobile_at_rest(void **state)
{
    (void)state;
    const double worst = mobile_heap(MOBILE_T);
    /* reference: at rest (slope 25 deg < phi = 35 deg, up to the creep of mu0: below 0.068 dx
     * by t = 0.1 s, header); tolerance 0.1 dx (issue). Not met: today's band is the measured
     * largest displacement, HEAP_MOBILE_MEASURED, +- HEAP_MOBILE_MARGIN */
    known_failure_check("heap_mobile", worst <= 0.1 * HEAP_DX, worst / HEAP_DX,
                        HEAP_MOBILE_MEASURED * (1.0 - HEAP_MOBILE_MARGIN), HEAP_MOBILE_MEASURED * (1.0 + HEAP_MOBILE_MARGIN));
}

/* ---- (a3) the heap with the implicit viscous step and no limiting viscosity ------------------ */

/* The heap of (a2) with numerics.viscosity = "implicit" and mu0 off, so the grains carry their
 * full frictional viscosity up to mu_thr, which no explicit step could take (dt ~ rho h^2 / mu).
 * Returns the largest displacement [m] at any 0.05 s sample to t_end; *mobile_least receives the
 * fewest mobile grains at a sample (the heap is not merely held fixed). */
static double implicit_heap(double mu_thr, int arithmetic_mean, int rigid, double t_end, size_t *mobile_least)
{
    const mixsph_override ov[] = {
        {"numerics.viscosity", 1.0}, {"numerics.viscosity_mean", arithmetic_mean}, {"numerics.held_grains", rigid}};
    mixsph_sim *s = create_heap(mu_thr, mu_thr, ov, 3);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
    double *x0, *z0;
    positions_by_id(s, &x0, &z0);
    mixsph_particles_view v;
    double worst = 0.0;
    *mobile_least = SIZE_MAX;
    for (int k = 1; k <= (int)lround(t_end / 0.05); k++) {
        advance(s, 0.05 * k);
        assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
        double now = 0.0;
        size_t mobile = 0, grains = 0;
        for (size_t i = 0; i < v.n; i++) {
            if (v.state[i] == MIXSPH_STATE_WALL) continue;
            assert_true(v.state[i] != MIXSPH_STATE_LOST);
            now = fmax(now, hypot(v.pos[0][i] - x0[v.id[i]], v.pos[v.dim - 1][i] - z0[v.id[i]]));
            mobile += v.state[i] == MIXSPH_STATE_MOBILE;
            grains++;
        }
        worst = fmax(worst, now);
        if (mobile < *mobile_least) *mobile_least = mobile;
        print_message("  mu_thr = mu0 = %g Pa s: t = %.2f s, %llu steps, largest displacement %.3f dx, %zu of %zu "
                      "grains mobile\n",
                      mu_thr, mixsph_sim_time(s), (unsigned long long)mixsph_sim_steps(s), now / HEAP_DX, mobile, grains);
    }
    free(x0);
    free(z0);
    mixsph_sim_destroy(s);
    return worst;
}

/* mu_thr = 1e12 Pa s: only grains at an exactly zero strain rate are held, the rest carry
 * sigma' sin(phi) / (2 sqrt(II_D)) uncapped. Measured: 68 of 186 grains mobile, none moved by
 * 0.001 dx over 1 s. */
static void test_heap_implicit_frictional(void **state)
{
    (void)state;
    size_t mobile = 0;
    const double worst = implicit_heap(1.0e12, 0, 0, 1.0, &mobile);
    assert_true(mobile > 0); /* the rheology holds mobile grains, not only fixed ones */
    /* reference: at rest (slope 25 deg < phi = 35 deg; no creep without mu0); tolerance 0.1 dx
     * (issue) over 1 s */
    assert_true(worst <= 0.1 * HEAP_DX);
}

/* Today's band of test_heap_implicit_vajont: the largest displacement over 1 s, 3.05896 dx,
 * measured on 2026-12-06 (GCC 12, -O3, aa173ae with these tests), the same to 6 digits at 1
 * and 2 threads. Margin 25 % of the value (2.29-3.82 dx): wider than the mobile heap's
 * because the slump follows a release at about 0.35 s (header) and what 1 s shows of it moves
 * with the moment of that release; far from the criterion (0.1 dx). */
#define HEAP_VAJONT_MEASURED 3.059
#define HEAP_VAJONT_MARGIN 0.25
/* mu_thr = 320 kPa s (the Vajont case's), held grains "solved" (unknowns of the viscous solve at
 * mu_thr): within the step a held grain is a fluid of viscosity mu_thr, so the heap creeps at
 * about rho g S d^2 / (2 mu_thr) ~ 1e-4 m/s and about half its grains, those whose creep gives
 * mu_app < mu_thr, are mobile. Measured: the creep dilates the apex, whose grains' pressure falls
 * from 54 Pa at 0.05 s to 23 Pa at 0.34 s and below zero at 0.35 s (sigma' = 0, mu = 0); within
 * 0.05 s every grain is mobile and the heap slumps, 3.1 dx by t = 1 s. With mu_thr = mu0 = 3.2 MPa s
 * the held count follows the same course ten times slower (96 held at 3.0 s as at 0.30 s here):
 * the creep, not the step, brings it down. A known failure:
 * `test_granular known_failure heap_implicit_vajont`. */
static void test_heap_implicit_vajont(void **state)
{
    (void)state;
    size_t mobile = 0;
    const double worst = implicit_heap(320.0e3, 0, 0, 1.0, &mobile);
    /* reference: at rest (slope 25 deg < phi = 35 deg); tolerance 0.1 dx (issue) over 1 s. Not
     * met: today's band is the measured largest displacement, HEAP_VAJONT_MEASURED, +-
     * HEAP_VAJONT_MARGIN */
    known_failure_check("heap_implicit_vajont", worst <= 0.1 * HEAP_DX, worst / HEAP_DX,
                        HEAP_VAJONT_MEASURED * (1.0 - HEAP_VAJONT_MARGIN), HEAP_VAJONT_MEASURED * (1.0 + HEAP_VAJONT_MARGIN));
}

/* The same heap with rigid held grains (numerics.held_grains = "rigid"): prescribed at rest in the
 * viscous solve and judged on the velocity one explicit time step of their forces gives them, as
 * the explicit scheme judges them. Measured: all 186 grains held to 1 s, none moved; the explicit
 * scheme at its own time step (9.1e-8 s) holds all 186 too, fastest speed 2.8e-7 m/s over 0.6 s.
 * Held grains are not drifted, so what this test checks is the release rule: that it releases no
 * grain of a heap below phi. The two column tests below check that it does release grains where
 * the explicit rule does (mu0 = 5 kPa s), and not where it does not (mu0 off). */
static void test_heap_implicit_vajont_rigid(void **state)
{
    (void)state;
    size_t mobile = 0;
    const double worst = implicit_heap(320.0e3, 0, 1, 1.0, &mobile);
    /* reference: at rest (slope 25 deg < phi = 35 deg); tolerance 0.1 dx (issue) over 1 s */
    assert_true(worst <= 0.1 * HEAP_DX);
}

/* The same heap with numerics.viscosity_mean = "arithmetic": a pair of grains is coupled with
 * (mu_i + mu_j) / 2 instead of the harmonic mean, which is below twice the smaller viscosity, so
 * a grain with little effective stress (the surface, grains in tension) no longer decouples its
 * neighbours. Measured: 70-72 of 186 grains mobile, 0.005 dx at 1 s (harmonic: 3.1 dx). What makes
 * the Vajont-mu_thr heap slump is therefore the harmonic mean, not the implicit step. The same
 * setting is too stiff elsewhere: a square column hardly collapses (run-out 0.05 r0 against the
 * experiments' 1.2, docs/validation/granular.md), so neither mean is the frictional response. */
static void test_heap_implicit_vajont_arithmetic(void **state)
{
    (void)state;
    size_t mobile = 0;
    const double worst = implicit_heap(320.0e3, 1, 0, 1.0, &mobile);
    assert_true(mobile > 0); /* held by mobile grains too, not only by fixed ones */
    /* reference: at rest (slope 25 deg < phi = 35 deg); tolerance 0.1 dx (issue) over 1 s */
    assert_true(worst <= 0.1 * HEAP_DX);
}

/* The rigid held grains keep the explicit scheme's rule for releasing a grain at rest, with its
 * dependence on mu0 (docs/model.md section 6: a grain at the free face of a body at rest is
 * released when sin(phi) / (4 CFL_vis) min(mu0, mu_thr) / mu_thr < 1, in order of magnitude: 0.045
 * with the Vajont mu0 = 5 kPa s, 2.9 with mu0 off). On cases/column_collapse.json at dx = 0.0125
 * (256 grains) to t = 0.3 s (2.1 collapse times sqrt(H0 / g)), implicit, held grains rigid;
 * *advance_m receives the front's advance [m], the return value the fewest grains held at a 0.01 s
 * sample. */
static size_t rigid_column(double mu0, double *advance_m)
{
    const mixsph_override ov[] = {{"numerics.dx", 0.0125},      {"numerics.viscosity", 1.0},
                                  {"numerics.held_grains", 1.0}, {"parameters.mu0", mu0},
                                  {"output.snapshot_interval", 0.0}};
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_status st = mixsph_sim_create(MIXSPH_SOURCE_DIR "/cases/column_collapse.json", ov, 5, &s, err, sizeof err);
    if (st != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK); /* ctest -j runs tests side by side */
    const size_t out_front = output(s, "front"), out_fixed = output(s, "fixed_particles");
    const double front0 = mixsph_sim_output_value(s, out_front);
    size_t held_least = SIZE_MAX;
    for (int k = 1; k <= 30; k++) {
        advance(s, 0.01 * k);
        const size_t held = (size_t)mixsph_sim_output_value(s, out_fixed);
        if (held < held_least) held_least = held;
    }
    *advance_m = mixsph_sim_output_value(s, out_front) - front0;
    print_message("rigid held grains, mu0 = %g Pa s: front advanced %.4f m (%.2f r0) by t = 0.3 s, fewest held %zu of %zu\n",
                  mu0, *advance_m, *advance_m / 0.2, held_least, mixsph_sim_particles(s));
    mixsph_sim_destroy(s);
    return held_least;
}

/* mu0 = 5 kPa s: the column collapses. Measured: front advanced 0.75 r0 by 0.3 s (the explicit
 * scheme: 0.91 r0; both run out to about 1.3 r0 at dx = 0.01, docs/validation/granular.md). */
static void test_column_rigid_collapses(void **state)
{
    (void)state;
    double advance_m = 0.0;
    rigid_column(5.0e3, &advance_m);
    /* reference: a column of aspect ratio 1 runs out 1.2-1.8 r0 (experiments, (b) below), most of
     * it by 2 collapse times; the criterion only separates collapsing from held: more than 0.5 r0 */
    assert_true(advance_m > 0.5 * 0.2);
}

/* mu0 off (mu0 = mu_thr): no grain is released and the column stands, as with the explicit scheme
 * at its own time step (measured at dx = 0.01: all 400 grains held to 0.15 s, the fastest at
 * 6.9e-6 m/s). */
static void test_column_rigid_mu0_off_held(void **state)
{
    (void)state;
    double advance_m = 1.0;
    const size_t held_least = rigid_column(320.0e3, &advance_m);
    /* reference: the explicit scheme's rule (comment of rigid_column): every grain held at every
     * sample, the front not moved */
    assert_int_equal(held_least, 256);
    assert_true(advance_m == 0.0);
}

/* ---- (b) column collapse ------------------------------------------------------------------- */

/* A 0.2 x 0.2 m column (aspect ratio a = H0 / r0 = 1) against a left wall on a no-slip floor, run
 * until the kinetic energy has fallen below 2% of its maximum (cap 1.2 s). The run-out is
 * measured between the outermost grain's centre now and the column's last grain's centre at t = 0.
 * Reference: dry granular columns collapsing in a channel (quasi-2D) spread to a normalised
 * run-out (r_inf - r0) / r0 = lambda a on the linear branch (small a), with lambda = 1.2 for sand,
 * rice and sugar (Lube et al. 2005, Phys. Rev. E 72, 041301) and 1.8 for glass beads (Lajeunesse
 * et al. 2005, Phys. Fluids 17, 103302), both fits as collected by Lagree, Staron & Popinet 2011,
 * J. Fluid Mech. 686, 378, eq. (3.1): at a = 1 the band 1.2 to 1.8. Tolerance: the kernel support
 * 2h = 2.6 dx on either side (0.16 r0 at dx = 0.0125), to which SPH resolves a front; the
 * criterion is therefore 1.04 <= run-out <= 1.96.
 * THE MODEL DOES NOT MEET IT at the resolution of the test: 1.00 r0 at dx = 0.0125 (r0 / 16);
 * 1.16 r0 at dx = 0.01 (r0 / 20), so the run-out is not converged in dx and grows toward the
 * experiments with resolution. The criterion is kept as a known failure (test_column_runout, run
 * by `test_granular known_failure column_runout`, CTest test_granular_known_column_runout);
 * test_column_collapse asserts what is defensible at this resolution: the run-out lies between
 * half the column width (it spreads) and the glass-bead edge of the band (1.96: no more mobile
 * than the most mobile experiment), the deposit stops and is no steeper than phi.
 * The deposit does not freeze: with mu0 = 5 kPa s the slowly shearing grains are a Newtonian
 * fluid of viscosity mu0 and keep creeping (docs/model.md section 6), so "stopped" is the KE
 * criterion.
 * Measured (2 threads on the shared 2-core machine):
 *   dx = 0.01   (400 grains): KE < 2% at t = 0.57 s (97,870 steps, 110 s wall, 92 s CPU), front
 *               0.427 m (moved 1.16 r0); creeping on: front 0.460 m at 1.0 s, 0.468 m at 1.2 s,
 *               KE 0.009-0.013 J against a maximum of 5.7 J at 0.14 s;
 *   dx = 0.0125 (256 grains, used here): KE < 2% at t = 0.53 s (58,241 steps, 44 s wall, 39 s
 *               CPU), front 0.393 m (moved 1.0 r0), height 0.146 m, steepest slope 24.7 deg.
 * So the model gives a run-out of 1.0 r0 (dx = 0.0125) to 1.16 r0 (dx = 0.01) when it stops, 17%
 * and 3% short of the band's lower edge (1.2 r0, Lube et al.), and creeps on to 1.34 r0 at 1.2 s (dx = 0.01). */

#define COL_DX 0.0125 /* the resolution of the criterion (validation suite) */
#define COL_DX_SHORT 0.025 /* the short version's (./tools/do test) */
#define COL_W 0.2     /* column width r0 [m] */
#define COL_H 0.2     /* column height [m]: aspect ratio a = 1 */
#define COL_TMAX 1.2  /* [s] cap */
#define NSURF 64      /* surface bins of 2 dx */

/* The paper's continuity equation (3a): the run-out band below was measured with it. With the
 * density diffusion at its default (0.1, between grains too) the run-out was 1.453 r0, inside the
 * experiments' band (docs/numerics.md section 2c): a numerical option's effect, not the model's. */
static const char *const COLUMN_CASE =
    "{\n"
    "  \"name\": \"column_collapse\",\n"
    "  \"gravity\": 9.81,\n"
    "  \"numerics\": { \"dx\": 0.0125, \"t_end\": 1.2, \"density_diffusion\": 0 },\n"
    "  \"media\": { \"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0, "
    "\"mu_thr\": 320.0e3, \"mu0\": 5.0e3 } },\n"
    "  \"bodies\": { \"column\": { \"medium\": \"sand\", \"polygon\": [[0.0, 0.0], [0.2, 0.0], [0.2, 0.2], [0.0, 0.2]] } },\n"
    "  \"walls\": { \"box\": { \"polyline\": [[0.0, 0.3], [0.0, 0.0], [0.8, 0.0]], \"fluid_side\": \"left\", \"slip\": \"no-slip\" } },\n"
    "  \"domain\": { \"x_min\": -0.05, \"x_max\": 0.85, \"z_min\": -0.05, \"z_max\": 0.4 },\n"
    "  \"monitors\": { \"front\": { \"type\": \"front\", \"medium\": \"sand\", \"direction\": \"+x\" } },\n"
    "  \"output\": { \"monitor_interval\": 0.01 }\n"
    "}\n";

/* Run the column collapse at resolution dx and return its run-out (r_inf - r0) / r0; asserts that
 * no grain crosses the wall or the floor, that it stops (KE criterion) and that its final surface
 * is no steeper than phi. */
static double column_collapse(double dx)
{
    mixsph_sim *s = create(COLUMN_CASE, "column_collapse.json", dx);
    const size_t n = mixsph_sim_particles(s);
    const size_t side = (size_t)lround(COL_W / dx);
    assert_int_equal(n, side * side); /* 16 x 16 grains at dx = 0.0125 */
    const double surf_bin = 2.0 * dx;
    const size_t out_ke = output(s, "kinetic_energy"), out_front = output(s, "front"), out_fixed = output(s, "fixed_particles");
    const double front0 = mixsph_sim_output_value(s, out_front);
    double ke_max = 0.0, t_ke_max = 0.0, ke = 0.0;
    int stopped = 0;
    print_message("   t [s]   front [m]   KE [J]    fixed grains\n");
    for (int k = 1; k <= (int)lround(COL_TMAX / 0.01); k++) {
        advance(s, 0.01 * k);
        ke = mixsph_sim_output_value(s, out_ke);
        if (ke > ke_max) {
            ke_max = ke;
            t_ke_max = mixsph_sim_time(s);
        }
        if (k % 10 == 0)
            print_message("  %.3f    %.4f    %.4g    %g\n", mixsph_sim_time(s), mixsph_sim_output_value(s, out_front), ke,
                          mixsph_sim_output_value(s, out_fixed));
        if (ke_max > 0.0 && ke < 0.02 * ke_max && mixsph_sim_time(s) > t_ke_max) {
            stopped = 1;
            break;
        }
    }
    const double front = mixsph_sim_output_value(s, out_front);
    print_message("t = %.3f s (%llu steps): front %.4f m (moved %.4f m = %.2f r0), KE %.4g J (max %.4g J at %.3f s)\n",
                  mixsph_sim_time(s), (unsigned long long)mixsph_sim_steps(s), front, front - front0,
                  (front - front0) / COL_W, ke, ke_max, t_ke_max);

    /* free surface: top particle (centre + dx/2) in bins of 2 dx from the wall */
    mixsph_particles_view v;
    assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
    double top[NSURF];
    for (int b = 0; b < NSURF; b++) top[b] = -INFINITY;
    for (size_t i = 0; i < v.n; i++) {
        if (v.state[i] == MIXSPH_STATE_WALL) continue;
        assert_true(v.state[i] != MIXSPH_STATE_LOST);
        assert_true(v.pos[0][i] > 0.0 && v.pos[v.dim - 1][i] > 0.0); /* nobody through the wall or the floor */
        const int b = (int)floor(v.pos[0][i] / surf_bin);
        assert_true(b >= 0 && b < NSURF);
        top[b] = fmax(top[b], v.pos[v.dim - 1][i] + 0.5 * dx);
    }
    /* steepest slope over a baseline of 4 bins (4 x 2 dx = 0.1 m, bin centre to bin centre) where
     * both bins hold grains; the final height is the highest top */
    double slope_max = 0.0, x_slope = 0.0, height = 0.0;
    for (int b = 0; b + 4 < NSURF; b++) {
        if (isfinite(top[b])) height = fmax(height, top[b]);
        if (!isfinite(top[b]) || !isfinite(top[b + 4])) continue;
        const double sl = fabs(top[b + 4] - top[b]) / (4.0 * surf_bin);
        if (sl > slope_max) {
            slope_max = sl;
            x_slope = (b + 2.5) * surf_bin;
        }
    }
    print_message("final surface (top of the grains in bins of %.3f m):\n", surf_bin);
    for (int b = 0; b < NSURF && isfinite(top[b]); b++) print_message("  x = %.2f m: %.3f m\n", (b + 0.5) * surf_bin, top[b]);
    print_message("final height %.3f m (%.2f H0); steepest slope %.1f deg at x = %.2f m (phi = %.0f deg)\n", height,
                  height / COL_H, atan(slope_max) * 180.0 / PI, x_slope, PHI);
    print_message("run-out (x_inf - r0) / r0 = %.2f (front particle against the column's last particle); experiments "
                  "give 1.2 a (Lube et al. 2005) to 1.8 a (Lajeunesse et al. 2005), a = 1\n",
                  (front - front0) / COL_W);

    /* it stopped: KE below 2% of its maximum before the cap */
    assert_true(stopped);
    /* reference: a deposit at rest is no steeper than the angle of internal friction phi = 35 deg
     * (Coulomb); method above; no tolerance beyond the 4-bin baseline */
    assert_true(slope_max <= tan(PHI * PI / 180.0));
    mixsph_sim_destroy(s);
    return (front - front0) / COL_W;
}

/* The experiments' band at a = 1 (comment above): lambda = 1.2 (Lube) to 1.8 (Lajeunesse). */
#define RUNOUT_LO 1.2
#define RUNOUT_HI 1.8
#define FRONT_TOL (2.0 * 1.3 * COL_DX / COL_W) /* 2h / r0: the front is resolved to the kernel support */

/* (b) what holds at this resolution: it spreads, but no farther than the most mobile experiment.
 * In the validation suite (`test_granular validation`). */
static void test_column_collapse(void **state)
{
    (void)state;
    const double runout = column_collapse(COL_DX);
    /* reference: at least half the column width (it spreads) and at most the glass-bead edge of
     * the experiments' band, 1.8 a (Lajeunesse et al. 2005), plus 2h / r0 (comment above) */
    assert_true(runout > 0.5);
    assert_true(runout <= RUNOUT_HI + FRONT_TOL);
}

/* (b), short: the same collapse at dx = 0.025 (8 x 8 grains; the time step is the viscous bound of
 * mu0, proportional to dx^2, so the run costs 1/16 of the one at dx = 0.0125), with the same
 * criteria re-derived for that resolution: it stops, its surface is no steeper than phi over
 * 4 bins of 2 dx, and its run-out lies between half the column width and the glass-bead edge of
 * the experiments' band plus the kernel support 2h / r0 = 0.325 at this dx. Measured (12-07, one
 * thread, 0.6 s): KE < 2 % at t = 0.37 s (10,065 steps), run-out 0.71 r0 (the trend in dx: 0.71,
 * 0.99, 1.16 r0 at dx = 0.025, 0.0125, 0.01), steepest slope 21.3 deg. A column without friction
 * runs to the end of the floor (3 r0) and one held by the rheology does not spread: both fail. */
static void test_column_collapse_short(void **state)
{
    (void)state;
    const double runout = column_collapse(COL_DX_SHORT);
    const double front_tol = 2.0 * 1.3 * COL_DX_SHORT / COL_W;
    /* reference: at least half the column width (it spreads) and at most 1.8 a (Lajeunesse et al.
     * 2005, the most mobile experiment), plus 2h / r0 = 0.325 */
    assert_true(runout > 0.5);
    assert_true(runout <= RUNOUT_HI + front_tol);
}

/* Today's band of test_column_runout: the run-out, 0.992966 r0,
 * measured on 2026-12-06 (GCC 12, -O3, aa173ae with these tests), the same to 6 digits at 1
 * and 2 threads. Margin 0.04 r0 (0.64 dx; band 0.953-1.033 r0): the run-out of a
 * collapse that stops is a settled quantity, so a fraction of a particle spacing is a change;
 * the band ends below the criterion's lower edge (1.2 - 0.163 = 1.037 r0). */
#define COLUMN_RUNOUT_MEASURED 0.993
#define COLUMN_RUNOUT_MARGIN 0.04
/* (b) the criterion: within the experiments' band, to 2h. A known failure (comment above). */
static void test_column_runout(void **state)
{
    (void)state;
    const double runout = column_collapse(COL_DX);
    print_message("run-out %.3f r0 against the experiments' %.1f to %.1f r0, tolerance 2h = %.3f r0\n", runout, RUNOUT_LO,
                  RUNOUT_HI, FRONT_TOL);
    /* reference: lambda a with lambda = 1.2 (Lube et al. 2005) to 1.8 (Lajeunesse et al. 2005),
     * a = 1; tolerance 2h / r0 = 0.16 (the kernel support). Not met: today's band is the
     * measured run-out, COLUMN_RUNOUT_MEASURED, +- COLUMN_RUNOUT_MARGIN */
    known_failure_check("column_runout", runout >= RUNOUT_LO - FRONT_TOL && runout <= RUNOUT_HI + FRONT_TOL, runout,
                        COLUMN_RUNOUT_MEASURED - COLUMN_RUNOUT_MARGIN, COLUMN_RUNOUT_MEASURED + COLUMN_RUNOUT_MARGIN);
}

/* Today's band of test_column_runout_short: the run-out at dx = 0.025, 0.707774 r0, measured on
 * 2026-12-07 (GCC 12, -O3, one thread; results do not depend on it). The same margin as the long
 * run's in particle spacings, 0.64 dx (0.08 r0 at this dx; band 0.628-0.788 r0), which ends below
 * the criterion's lower edge at this dx, 1.2 - 0.325 = 0.875 r0. It is what makes the short run
 * fail when the friction changes: the friction angle 25 deg instead of 35 runs out 1.29 r0,
 * 15 deg 1.85 r0, both within test_column_collapse_short's bounds. */
#define COLUMN_RUNOUT_SHORT_MEASURED 0.708
#define COLUMN_RUNOUT_SHORT_MARGIN (0.64 * COL_DX_SHORT / COL_W)
/* (b), short: the criterion at dx = 0.025, to 2h = 0.325 r0. A known failure (comment above). */
static void test_column_runout_short(void **state)
{
    (void)state;
    const double runout = column_collapse(COL_DX_SHORT), front_tol = 2.0 * 1.3 * COL_DX_SHORT / COL_W;
    print_message("run-out %.4f r0 against the experiments' %.1f to %.1f r0, tolerance 2h = %.3f r0\n", runout, RUNOUT_LO,
                  RUNOUT_HI, front_tol);
    /* reference: lambda a with lambda = 1.2 (Lube et al. 2005) to 1.8 (Lajeunesse et al. 2005),
     * a = 1; tolerance 2h / r0 = 0.325 at this dx. Not met: today's band is the measured run-out,
     * COLUMN_RUNOUT_SHORT_MEASURED, +- COLUMN_RUNOUT_SHORT_MARGIN */
    known_failure_check("column_runout_short", runout >= RUNOUT_LO - front_tol && runout <= RUNOUT_HI + front_tol, runout,
                        COLUMN_RUNOUT_SHORT_MEASURED - COLUMN_RUNOUT_SHORT_MARGIN,
                        COLUMN_RUNOUT_SHORT_MEASURED + COLUMN_RUNOUT_SHORT_MARGIN);
}

/* `test_granular` runs the tests the model meets; `test_granular known_failure NAME` one of the
 * criteria it does not meet yet (header): heap_mobile, heap_implicit_vajont or column_runout.
 * CTest runs each of these on its own; each passes while its criterion is not met and its value
 * stays in today's band (known_failure.h), so it reports both the day the model meets the
 * criterion and a regression. */
int main(int argc, char **argv)
{
    if (argc > 2 && strcmp(argv[1], "known_failure") == 0) {
        if (strcmp(argv[2], "heap_mobile") == 0) {
            const struct CMUnitTest known[] = {cmocka_unit_test(test_heap_mobile_at_rest)};
            return cmocka_run_group_tests(known, NULL, NULL);
        }
        if (strcmp(argv[2], "heap_implicit_vajont") == 0) {
            const struct CMUnitTest known[] = {cmocka_unit_test(test_heap_implicit_vajont)};
            return cmocka_run_group_tests(known, NULL, NULL);
        }
        if (strcmp(argv[2], "column_runout") == 0) {
            const struct CMUnitTest known[] = {cmocka_unit_test(test_column_runout)};
            return cmocka_run_group_tests(known, NULL, NULL);
        }
        if (strcmp(argv[2], "column_runout_short") == 0) {
            const struct CMUnitTest known[] = {cmocka_unit_test(test_column_runout_short)};
            return cmocka_run_group_tests(known, NULL, NULL);
        }
        fprintf(stderr,
                "test_granular: unknown known_failure '%s' (heap_mobile, heap_implicit_vajont, column_runout, "
                "column_runout_short)\n",
                argv[2]);
        return 2;
    }
    if (argc > 1 && strcmp(argv[1], "validation") == 0) {
        /* the long versions (CTest test_granular_validation, label validation: ./tools/do validate) */
        const struct CMUnitTest long_tests[] = {
            cmocka_unit_test(test_heap_at_rest),
            cmocka_unit_test(test_column_collapse),
        };
        return cmocka_run_group_tests(long_tests, NULL, NULL);
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_heap_at_rest_short),
        cmocka_unit_test(test_heap_mobile),
        cmocka_unit_test(test_heap_implicit_frictional),
        cmocka_unit_test(test_heap_implicit_vajont_arithmetic),
        cmocka_unit_test(test_heap_implicit_vajont_rigid),
        cmocka_unit_test(test_column_rigid_collapses),
        cmocka_unit_test(test_column_rigid_mu0_off_held),
        cmocka_unit_test(test_column_collapse_short),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
