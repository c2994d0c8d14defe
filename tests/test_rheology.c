/* test_rheology.c - the mixture viscosity law (rheology.h; Manenti et al. 2018, eqs. (10) and
 * (12), Fig. 1; docs/model.md sections 5-6), every branch:
 *   rheology_regime:   mu_app >= mu_thr -> FIXED (mu_thr); mu0 < mu_app < mu_thr -> LIMITED (mu0);
 *                      mu_app <= mu0 -> FRICTIONAL (mu_app); mu0 >= mu_thr switches the limit off;
 *                      the mu1 rheology of Run 7 (mu_thr = mu1, mu0 = +inf);
 *   rheology_apparent: mu_thr where sqrt(II_D) < 1e-12 (or NaN), else eps_f mu_f + sigma' sin(phi) / (2 sqrt(II_D));
 *   rheology_sqrt_ii:  pure shear, pure extension, rigid rotation;
 *   rheology_effective_stress: sigma' = max(p - max(p_w, 0), 0).
 * The functions are pure: the expected values are computed by hand and compared to within a few
 * ulps (relative 1e-14) unless a comparison is exact by construction. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "geometry.h"
#include "rheology.h"

#define MU_THR 320.0e3 /* [Pa s] Vajont threshold viscosity (paper, Section 4) */
#define MU0 5.0e3      /* [Pa s] Vajont limiting viscosity */
#define REL 1e-14      /* relative tolerance of hand-computed values: a few ulps */

static void assert_close(double got, double want)
{
    if (!(fabs(got - want) <= REL * fabs(want))) {
        print_error("got %.17g, expected %.17g\n", got, want);
        fail();
    }
}

/* mu_app >= mu_thr: elastic-plastic, held fixed with mu = mu_thr, exactly at mu_thr included. */
static void test_regime_fixed(void **state)
{
    (void)state;
    const double apps[] = {MU_THR, MU_THR * (1.0 + 1e-15), 2.0 * MU_THR, 1e30, INFINITY};
    for (size_t k = 0; k < sizeof apps / sizeof apps[0]; k++) {
        double mu = -1.0;
        assert_int_equal(rheology_regime(apps[k], MU_THR, MU0, &mu), RHEOLOGY_FIXED);
        assert_true(mu == MU_THR); /* exact: the threshold itself is returned */
    }
}

/* mu0 < mu_app < mu_thr: frictional and limited, mobile with mu = mu0. */
static void test_regime_limited(void **state)
{
    (void)state;
    const double apps[] = {nextafter(MU0, INFINITY), 1.0001 * MU0, 100.0e3, nextafter(MU_THR, 0.0)};
    for (size_t k = 0; k < sizeof apps / sizeof apps[0]; k++) {
        double mu = -1.0;
        assert_int_equal(rheology_regime(apps[k], MU_THR, MU0, &mu), RHEOLOGY_LIMITED);
        assert_true(mu == MU0); /* exact */
    }
}

/* mu_app <= mu0: frictional, mobile with mu = mu_app, exactly at mu0 included. */
static void test_regime_frictional(void **state)
{
    (void)state;
    const double apps[] = {MU0, nextafter(MU0, 0.0), 1234.5, 1e-3, 0.0};
    for (size_t k = 0; k < sizeof apps / sizeof apps[0]; k++) {
        double mu = -1.0;
        assert_int_equal(rheology_regime(apps[k], MU_THR, MU0, &mu), RHEOLOGY_FRICTIONAL);
        assert_true(mu == apps[k]); /* exact: the apparent viscosity itself */
    }
}

/* mu0 >= mu_thr switches the limit off: the Table 1 runs use mu0 = mu_thr + 0.7 kPa s
 * (e.g. Run 2: 20 and 20.7 kPa s). Between mu_thr and mu0 a grain is FIXED (the threshold
 * comes first), below mu_thr it is FRICTIONAL with its own mu_app; LIMITED never occurs. */
static void test_regime_limit_off(void **state)
{
    (void)state;
    const double thr = 20.0e3, mu0 = thr + 700.0; /* [Pa s] Table 1, Run 2 */
    double mu = -1.0;
    assert_int_equal(rheology_regime(thr + 350.0, thr, mu0, &mu), RHEOLOGY_FIXED); /* between mu_thr and mu0 */
    assert_true(mu == thr);
    assert_int_equal(rheology_regime(mu0, thr, mu0, &mu), RHEOLOGY_FIXED); /* at mu0 */
    assert_true(mu == thr);
    assert_int_equal(rheology_regime(thr, thr, mu0, &mu), RHEOLOGY_FIXED); /* at mu_thr */
    assert_true(mu == thr);
    const double below[] = {nextafter(thr, 0.0), 19.0e3, 5.0e3, 1.0};
    for (size_t k = 0; k < sizeof below / sizeof below[0]; k++) {
        assert_int_equal(rheology_regime(below[k], thr, mu0, &mu), RHEOLOGY_FRICTIONAL);
        assert_true(mu == below[k]);
    }
    /* mu0 = mu_thr exactly is also "off" (mu0 >= mu_thr) */
    assert_int_equal(rheology_regime(nextafter(thr, 0.0), thr, thr, &mu), RHEOLOGY_FRICTIONAL);
    assert_true(mu == nextafter(thr, 0.0));
}

/* The mu1 rheology of Run 7 (green line of Fig. 1): mu_thr = mu1 = 5 kPa s, no limit (mu0 = +inf). */
static void test_regime_mu1(void **state)
{
    (void)state;
    const double mu1 = 5.0e3; /* [Pa s] Run 7 */
    double mu = -1.0;
    assert_int_equal(rheology_regime(mu1, mu1, INFINITY, &mu), RHEOLOGY_FIXED);
    assert_true(mu == mu1);
    assert_int_equal(rheology_regime(1e9, mu1, INFINITY, &mu), RHEOLOGY_FIXED);
    assert_true(mu == mu1);
    assert_int_equal(rheology_regime(4999.0, mu1, INFINITY, &mu), RHEOLOGY_FRICTIONAL);
    assert_true(mu == 4999.0);
    assert_int_equal(rheology_regime(0.5, mu1, INFINITY, &mu), RHEOLOGY_FRICTIONAL);
    assert_true(mu == 0.5);
}

/* sqrt(II_D) -> 0: below 1e-12 1/s (and for NaN) the apparent viscosity is mu_thr, whatever the
 * stress; from 1e-12 on it is eps_f mu_f + sigma' sin(phi) / (2 sqrt(II_D)). */
static void test_apparent(void **state)
{
    (void)state;
    const double sin_phi = sin(35.0 * GEOM_PI / 180.0); /* 0.573576436351046 */
    const double sigma = 1000.0;                      /* [Pa] */
    const double epsmu = 0.35 * 1.0e-3;               /* eps_f mu_f [Pa s]: porosity 0.35, water */
    assert_true(rheology_apparent(sigma, sin_phi, 0.0, epsmu, MU_THR) == MU_THR);
    assert_true(rheology_apparent(sigma, sin_phi, 9.9e-13, epsmu, MU_THR) == MU_THR);
    assert_true(rheology_apparent(sigma, sin_phi, nextafter(RHEOLOGY_II_MIN, 0.0), epsmu, MU_THR) == MU_THR);
    assert_true(rheology_apparent(sigma, sin_phi, NAN, epsmu, MU_THR) == MU_THR);
    assert_true(rheology_apparent(0.0, sin_phi, 0.0, epsmu, MU_THR) == MU_THR);
    /* at and above the cut-off: the formula. 1000 Pa * 0.5736 / (2 * 1e-12) = 2.8679e14 Pa s */
    assert_close(rheology_apparent(sigma, sin_phi, 1e-12, epsmu, MU_THR), epsmu + 1000.0 * sin_phi / 2e-12);
    /* numbers by hand: sigma' = 1000 Pa, phi = 35 deg, sqrt(II_D) = 2 1/s, eps_f mu_f = 3.5e-4 Pa s:
     * 1000 * 0.573576436351046 / 4 + 3.5e-4 = 143.394459087761 Pa s */
    assert_true(fabs(rheology_apparent(sigma, sin_phi, 2.0, epsmu, MU_THR) - 143.394459087761) <= 1e-9);
    /* phi = 30 deg (sin = 1/2), sigma' = 8000 Pa, sqrt(II_D) = 0.1 1/s, dry: 8000 * 0.5 / 0.2 = 20000 Pa s */
    assert_close(rheology_apparent(8000.0, 0.5, 0.1, 0.0, MU_THR), 20000.0);
    /* no effective stress (e.g. liquefied): only the pore fluid's share is left */
    assert_close(rheology_apparent(0.0, sin_phi, 3.0, epsmu, MU_THR), epsmu);
    /* chained with the regimes: 20000 Pa s is LIMITED with the Vajont values, 143 Pa s FRICTIONAL */
    double mu;
    assert_int_equal(rheology_regime(rheology_apparent(8000.0, 0.5, 0.1, 0.0, MU_THR), MU_THR, MU0, &mu), RHEOLOGY_LIMITED);
    assert_true(mu == MU0);
    assert_int_equal(rheology_regime(rheology_apparent(sigma, sin_phi, 2.0, epsmu, MU_THR), MU_THR, MU0, &mu),
                     RHEOLOGY_FRICTIONAL);
    assert_true(fabs(mu - 143.394459087761) <= 1e-9);
}

/* sqrt(II_D) = sqrt(1/2 (du/dx)^2 + 1/2 (dw/dz)^2 + 1/4 (du/dz + dw/dx)^2). */
static void test_sqrt_ii(void **state)
{
    (void)state;
    /* pure shear u = g z: D_xz = g/2, sqrt(II_D) = sqrt(g^2/4) = g/2 */
    assert_close(rheology_sqrt_ii((const double[]){0.0, 3.0, 0.0, 0.0}), 1.5);
    assert_close(rheology_sqrt_ii((const double[]){0.0, -3.0, 0.0, 0.0}), 1.5);
    assert_close(rheology_sqrt_ii((const double[]){0.0, 0.0, 3.0, 0.0}), 1.5); /* w = g x: the same shear */
    /* pure extension u = a x, w = -a z (divergence-free): sqrt(a^2/2 + a^2/2) = a */
    assert_close(rheology_sqrt_ii((const double[]){2.5, 0.0, 0.0, -2.5}), 2.5);
    /* rigid rotation u = w z, w = -w x: no strain rate at all (exactly 0) */
    assert_true(rheology_sqrt_ii((const double[]){0.0, 4.0, -4.0, 0.0}) == 0.0);
    /* rotation plus shear: only the symmetric part counts, du/dz + dw/dx = 1 -> 1/2 */
    assert_close(rheology_sqrt_ii((const double[]){0.0, 4.5, -3.5, 0.0}), 0.5);
    /* everything at once: 1/2 + 1/2 * 4 + 1/4 * 9 = 4.75 */
    assert_close(rheology_sqrt_ii((const double[]){1.0, 1.0, 2.0, 2.0}), sqrt(4.75));
    assert_true(rheology_sqrt_ii((const double[]){0.0, 0.0, 0.0, 0.0}) == 0.0);
}

/* sigma' = max(p - max(p_w, 0), 0). */
static void test_effective_stress(void **state)
{
    (void)state;
    assert_true(rheology_effective_stress(5000.0, 0.0) == 5000.0);     /* dry: p_w = 0 */
    assert_true(rheology_effective_stress(5000.0, 2000.0) == 3000.0);  /* saturated: p - p_w */
    assert_true(rheology_effective_stress(5000.0, 5000.0) == 0.0);     /* p_w = p */
    assert_true(rheology_effective_stress(5000.0, 7000.0) == 0.0);     /* p_w > p: no negative stress */
    assert_true(rheology_effective_stress(5000.0, -2000.0) == 5000.0); /* negative p_w taken as 0 */
    assert_true(rheology_effective_stress(-300.0, 0.0) == 0.0);        /* tension: no friction */
    assert_true(rheology_effective_stress(-300.0, -1000.0) == 0.0);    /* p_w < 0 does not lift a negative p */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_regime_fixed),     cmocka_unit_test(test_regime_limited),
        cmocka_unit_test(test_regime_frictional), cmocka_unit_test(test_regime_limit_off),
        cmocka_unit_test(test_regime_mu1),       cmocka_unit_test(test_apparent),
        cmocka_unit_test(test_sqrt_ii),          cmocka_unit_test(test_effective_stress),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
