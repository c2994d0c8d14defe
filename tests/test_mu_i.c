/* test_mu_i.c - the rate-dependent friction mu(I) of the elastic-plastic law (laws/mu_i.h;
 * docs/model.md [MI]), one material point at a time:
 *   the curve mu(I) and the inertial number against their definitions (Jop, Forterre & Pouliquen
 *   2006);
 *   the closed-form plastic shear rate: the positive root of the quadratic, which satisfies the
 *   yield condition tau_tr - G dt gamma = S_s + delta_mu p' gamma / (gamma + xi) to round-off on
 *   both of its branches, while the other root is negative;
 *   I -> 0 (d = 0, delta_mu = 0, p' <= 0) is the rate-independent return bit for bit, and a small
 *   d tends to it;
 *   a material point sheared at a known rate reaches sqrt(J2) = mu(I) p', I of that rate.
 * Each assertion states its reference and tolerance. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "drucker_prager.h"
#include "geometry.h"
#include "mu_i.h"

#define DEG (GEOM_PI / 180.0)

/* Jop, Forterre & Pouliquen (2006), glass beads: the defaults of the keys */
#define DELTA_MU 0.26
#define I0_JOP 0.279
#define RHO_S 2650.0 /* [kg/m3] */

static void assert_rel(double got, double want, double rel, const char *what)
{
    if (!(fabs(got - want) <= rel * fabs(want))) {
        print_error("%s: got %.17g, expected %.17g (relative tolerance %g)\n", what, got, want, rel);
        fail();
    }
}

static const struct mu_i_params rate = {.on = 1, .delta_mu = DELTA_MU, .I0 = I0_JOP};

/* mu(0) = mu_s, mu(I0) = mu_s + delta_mu / 2, mu -> mu_2 as I grows; I = gamma d / sqrt(p / rho_s)
 * (definitions; tolerance: a few ulps) */
static void test_curve(void **state)
{
    (void)state;
    const double mu_s = sin(32.0 * DEG);
    assert_true(mu_i_friction(0.0, mu_s, DELTA_MU, I0_JOP) == mu_s);
    assert_rel(mu_i_friction(I0_JOP, mu_s, DELTA_MU, I0_JOP), mu_s + 0.5 * DELTA_MU, 1e-15, "mu(I0)");
    assert_rel(mu_i_friction(1e9, mu_s, DELTA_MU, I0_JOP), mu_s + DELTA_MU, 1e-9, "mu(large I)");
    assert_rel(mu_i_inertial_number(10.0, 1e-3, 2650.0, RHO_S), 10.0 * 1e-3 / 1.0, 1e-15, "I at p = rho_s");
}

/* The yield condition's residual relative to the trial's excess at the returned rate. */
static double residual(double excess, double g_dt, double dmu_p, double xi, double gamma)
{
    return fabs(excess - g_dt * gamma - dmu_p * gamma / (gamma + xi)) / excess;
}

/* The root over four decades of each of A, B xi and delta_mu p' (both signs of b): positive, on the
 * yield condition to 1e-13 of the excess (round-off of a quadratic's terms of a few ulps each), and
 * the other root (the product of the roots is -A xi / B) negative. */
static void test_root_is_the_consistent_one(void **state)
{
    (void)state;
    const double g_dt = 4.6e6 * 1e-4; /* G dt of the column's sand [Pa s] */
    int negative_b = 0, positive_b = 0;
    for (int a = -2; a <= 2; a++)
        for (int x = -2; x <= 2; x++)
            for (int m = -2; m <= 2; m++) {
                const double excess = 100.0 * pow(10.0, a), xi = 10.0 * pow(10.0, x), dmu_p = 300.0 * pow(10.0, m);
                const double b = excess - g_dt * xi - dmu_p;
                negative_b += b < 0.0;
                positive_b += b >= 0.0;
                const double gamma = mu_i_plastic_shear_rate(excess, g_dt, dmu_p, xi);
                assert_true(gamma > 0.0 && gamma < excess / g_dt); /* the rate part takes a share of the excess */
                assert_true(residual(excess, g_dt, dmu_p, xi, gamma) < 1e-13);
                const double other = -excess * xi / (g_dt * gamma);
                assert_true(other < 0.0);
            }
    assert_true(negative_b > 0 && positive_b > 0); /* both branches of the closed form taken */
    /* xi infinite (d = 0): the rate-independent return's A / B exactly */
    assert_true(mu_i_plastic_shear_rate(250.0, g_dt, 300.0, INFINITY) == 250.0 / g_dt);
}

/* A trial state outside the static cone (phi 32, psi 0, sand of E 5.84 MPa). */
static void trial(struct deviatoric_stress *s, double *p_eff, struct drucker_prager_material *m)
{
    assert_null(drucker_prager_material(5.84e6, 0.3, 32.0 * DEG, 0.0, 0.0, m));
    *p_eff = 2000.0;
    *s = (struct deviatoric_stress){.xx = 300.0, .zz = -500.0, .xz = 1500.0, .yy = 200.0};
}

/* The cone widened by the increment, returned as elastic_plastic.c does. */
static double rate_return(struct deviatoric_stress *s, double *p_eff, struct drucker_prager_material m, double dt,
                          double d, const struct mu_i_params *r)
{
    const double tau = drucker_prager_sqrt_j2(s), S_s = 3.0 * m.alpha_phi * *p_eff + m.k_c;
    const double dS = mu_i_strength_increment(tau, S_s, *p_eff, m.G * dt, d, RHO_S, r);
    m.k_c += dS;
    drucker_prager_return(s, p_eff, &m);
    return dS;
}

/* I -> 0: no rate strength where the inertial number vanishes or has no meaning (d = 0, delta_mu = 0,
 * p' <= 0), and then the state is the rate-independent return's bit for bit (memcmp); a grain of
 * 1 nm tends to it (its increment, of order delta_mu d sqrt(p' rho_s) / I0 gamma, below 1e-6 of
 * the excess). */
static void test_static_limit(void **state)
{
    (void)state;
    const struct mu_i_params flat = {.on = 1, .delta_mu = 0.0, .I0 = I0_JOP};
    struct deviatoric_stress s0, s1;
    struct drucker_prager_material m;
    double p0, p1;
    const double dt = 1e-4;
    for (int k = 0; k < 3; k++) {
        trial(&s0, &p0, &m);
        if (k == 2) p0 = -10.0; /* beyond the apex: the cut-off alone */
        s1 = s0;
        p1 = p0;
        drucker_prager_return(&s0, &p0, &m);
        const double dS = rate_return(&s1, &p1, m, dt, k == 0 ? 0.0 : 1e-3, k == 1 ? &flat : &rate);
        assert_true(dS == 0.0);
        assert_memory_equal(&s0, &s1, sizeof s0);
        assert_memory_equal(&p0, &p1, sizeof p0);
    }
    trial(&s0, &p0, &m);
    const double excess = drucker_prager_yield(&s0, p0, &m);
    s1 = s0;
    p1 = p0;
    drucker_prager_return(&s0, &p0, &m);
    const double dS = rate_return(&s1, &p1, m, dt, 1e-9, &rate);
    assert_true(dS > 0.0 && dS < 1e-6 * excess);
    assert_rel(drucker_prager_sqrt_j2(&s1), drucker_prager_sqrt_j2(&s0), 1e-6, "sqrt(J2), d = 1 nm");
}

/* One step: the returned state lies on mu(I) p' with I of the step's own plastic rate gamma =
 * (tau_tr - tau) / (G dt) (the definition of the update; tolerance 1e-12: the rate is a difference
 * of the trial and the returned sqrt(J2), which loses the digits of their ratio). */
static void test_one_step_on_the_curve(void **state)
{
    (void)state;
    struct deviatoric_stress s;
    struct drucker_prager_material m;
    double p;
    const double dt = 1e-4, d = 5e-3;
    trial(&s, &p, &m);
    const double tau_tr = drucker_prager_sqrt_j2(&s);
    rate_return(&s, &p, m, dt, d, &rate);
    const double tau = drucker_prager_sqrt_j2(&s), gamma = (tau_tr - tau) / (m.G * dt);
    const double I = mu_i_inertial_number(gamma, d, p, RHO_S);
    assert_true(I > 0.01); /* a rate that matters: mu(I) above mu_s by more than 1 % of delta_mu */
    assert_rel(tau / p, mu_i_friction(I, 3.0 * m.alpha_phi, DELTA_MU, I0_JOP), 1e-12, "sqrt(J2) / p' on mu(I)");
}

/* A material point sheared at a known rate: u = gammadot z (L_xz = gammadot, with its spin) from
 * rest at p' = 2 kPa, 4000 steps of 1e-4 s (it yields at the first step: G dt gammadot = 4.5 kPa).
 * Steady simple shear of the mu(I) rheology: sqrt(J2) = mu(I) p', I = gammadot d / sqrt(p' / rho_s)
 * (Jop et al. 2006), here I = 0.23. Tolerance 1e-6 (measured 7e-8): the spin tilts the steady
 * deviator from the strain rate, so that its plastic shear rate is gammadot to second order only.
 * The static law's mu_s is 18 % below: dropping the rate term fails. */
static void test_known_shear_rate(void **state)
{
    (void)state;
    struct deviatoric_stress s = {0};
    struct drucker_prager_material m;
    assert_null(drucker_prager_material(5.84e6, 0.3, 32.0 * DEG, 0.0, 0.0, &m));
    const double dt = 1e-4, gammadot = 20.0, d = 1e-2, p_eff = 2000.0;
    double L[DIM * DIM] = {0};
    L[0 * DIM + (DIM - 1)] = gammadot; /* du_x / dz */
    for (int k = 0; k < 4000; k++) {
        elasticity_jaumann_step(&s, L, m.G, dt);
        double p = p_eff;
        rate_return(&s, &p, m, dt, d, &rate);
    }
    const double I = mu_i_inertial_number(gammadot, d, p_eff, RHO_S);
    const double want = mu_i_friction(I, 3.0 * m.alpha_phi, DELTA_MU, I0_JOP);
    print_message("steady shear at %g 1/s, d = %g m: I = %.4f, sqrt(J2)/p' = %.9f, mu(I) = %.9f, mu_s = %.6f\n",
                  gammadot, d, I, drucker_prager_sqrt_j2(&s) / p_eff, want, 3.0 * m.alpha_phi);
    assert_rel(drucker_prager_sqrt_j2(&s) / p_eff, want, 1e-6, "steady shear: sqrt(J2) / p' = mu(I)");
    assert_true(want > 1.1 * 3.0 * m.alpha_phi);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_curve),         cmocka_unit_test(test_root_is_the_consistent_one),
        cmocka_unit_test(test_static_limit),  cmocka_unit_test(test_one_step_on_the_curve),
        cmocka_unit_test(test_known_shear_rate),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
