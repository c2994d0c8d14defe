/* test_eos.c - the linearised Tait equation of state of eos.h (docs/model.md section 3):
 *   p = c0^2 (rho - rho0), and its inverse. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "eos.h"

/* (rho0, c) pairs: the two media of the erosive dam break (docs/validation/erosive_dambreak.md: water 1000 kg/m3, 36.1 m/s; saturated mixture
 * 1250 kg/m3, 36.1 m/s), the Vajont grains at 40 m/s and a small artificial one. */
static const double media[][2] = {{1000.0, 36.1}, {1250.0, 36.1}, {2650.0, 40.0}, {1.5, 0.3}};
#define N_MEDIA (sizeof media / sizeof media[0])

/* p(rho0) = 0 exactly: the reference density is the zero-pressure state. */
static void test_zero_at_rest(void **state)
{
    (void)state;
    for (size_t k = 0; k < N_MEDIA; k++) {
        const double rho0 = media[k][0], c = media[k][1];
        assert_true(eos_pressure(rho0, rho0, c) == 0.0);
        assert_true(eos_density(0.0, rho0, c) == rho0);
    }
}

/* Linear with slope dp/drho = c^2 on both sides of rho0 (tension allowed in the EOS). */
static void test_slope_is_c_squared(void **state)
{
    (void)state;
    for (size_t k = 0; k < N_MEDIA; k++) {
        const double rho0 = media[k][0], c = media[k][1];
        for (int s = -5; s <= 5; s++) {
            const double drho = 0.004 * s * rho0; /* +-2%: beyond the 1% of docs/model.md section 3 */
            const double p = eos_pressure(rho0 + drho, rho0, c);
            /* reference: c^2 drho (exact linear law); tolerance 1e-12 relative, round-off only
             * (rho0 + drho - rho0 loses up to eps rho0 / |drho| of drho) */
            assert_true(fabs(p - c * c * drho) <= 1e-12 * c * c * rho0);
            if (s != 0) {
                const double slope = (eos_pressure(rho0 + drho, rho0, c) - eos_pressure(rho0, rho0, c)) / drho;
                assert_true(fabs(slope - c * c) <= 1e-12 * c * c); /* same reference and tolerance, per drho */
            }
        }
    }
}

/* eos_density inverts eos_pressure, and the other way round. */
static void test_inverse(void **state)
{
    (void)state;
    for (size_t k = 0; k < N_MEDIA; k++) {
        const double rho0 = media[k][0], c = media[k][1];
        for (int s = -10; s <= 10; s++) {
            const double rho = rho0 * (1.0 + 0.003 * s);
            /* reference: identity; tolerance 1e-13 relative (two roundings of rho0-sized numbers) */
            assert_true(fabs(eos_density(eos_pressure(rho, rho0, c), rho0, c) - rho) <= 1e-13 * rho0);
            const double p = 1000.0 * s;
            assert_true(fabs(eos_pressure(eos_density(p, rho0, c), rho0, c) - p) <= 1e-12 * c * c * rho0);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_zero_at_rest),
        cmocka_unit_test(test_slope_is_c_squared),
        cmocka_unit_test(test_inverse),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
