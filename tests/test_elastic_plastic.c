/* test_elastic_plastic.c - the elastic-perfectly-plastic granular law (laws/elastic_plastic.c,
 * experimental) behind the material-law seam: its case keys, and the heap of
 * cases/granular_heap.json (dry sand, phi = 35 deg, slopes of 25 deg, on a no-slip floor,
 * dx = 0.01) run with it for 2 s.
 *
 * The heap's criterion (issue "A granular stress that knows no time step"): every grain within
 * 0.1 dx of where it started over 2 s. NOT MET: measured (12-06) 0.28 dx at 2 s, the largest
 * displacements at the floor near the heap's middle, where grains sit at 0.0065 m/s while the
 * median grain moves 0.055 dx in all; before the floor took the grains' stress (laws/law.h) the
 * heap spread over its frictionless floor by 2.9 dx. Kept as a known failure with today's band. */
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
#include "sim.h"

#define DX 0.01

static const char *heap_json(const char *extra)
{
    static char buf[2048];
    snprintf(buf, sizeof buf,
             "{ \"name\": \"heap_ep\", \"gravity\": 9.81, \"numerics\": { \"dx\": 0.01, \"t_end\": 2.0 },"
             "  \"media\": { \"sand\": { \"type\": \"granular\", \"law\": \"elastic_plastic\", \"rho\": 2650.0,"
             "    \"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0 %s } },"
             "  \"bodies\": { \"heap\": { \"medium\": \"sand\", \"polygon\": [[0.0, 0.0], [0.4, 0.0], [0.2, 0.0932615]] } },"
             "  \"walls\": { \"floor\": { \"polyline\": [[-0.05, 0.0], [0.45, 0.0]], \"fluid_side\": \"left\" } },"
             "  \"domain\": { \"x_min\": -0.15, \"x_max\": 0.55, \"z_min\": -0.05, \"z_max\": 0.25 } }",
             extra);
    return buf;
}

static void test_keys(void **state)
{
    (void)state;
    mixsph_sim *s = NULL;
    char err[512] = "";
    assert_int_equal(mixsph_sim_create_from_text(heap_json(""), "heap", NULL, 0, &s, err, sizeof err), MIXSPH_OK);
    const struct medium *m = &s->cfg.media[0];
    assert_int_equal(m->law, LAW_ELASTIC_PLASTIC);
    /* references: rho0 = (1 - n) rho_s (5); K = rho0 c^2 with c = sqrt(K_s / rho_s); G from nu = 0.3 */
    const double rho0 = 0.65 * 2650.0, K = rho0 * 4.24e6 / 2650.0;
    assert_true(fabs(m->rho0 / rho0 - 1.0) < 1e-14 && fabs(m->bulk_modulus / K - 1.0) < 1e-14);
    assert_true(fabs(m->shear_modulus / (3.0 * K * 0.4 / 2.6) - 1.0) < 1e-14);
    /* psi = 0: alpha_phi = sin(phi) / 3 (drucker_prager.h) */
    assert_true(fabs(m->alpha_phi - sin(35.0 * GEOM_PI / 180.0) / 3.0) < 1e-15);
    mixsph_sim_destroy(s);
    /* refused: saturated (the pore pressure is the paper law's), a dilatancy, a paper-law key */
    const char *bad[] = {", \"saturated\": true", ", \"dilatancy\": 5", ", \"mu_thr\": 1e5"};
    const char *named[] = {"saturated", "dilatancy", "mu_thr"};
    for (size_t k = 0; k < 3; k++) {
        s = NULL;
        assert_int_equal(mixsph_sim_create_from_text(heap_json(bad[k]), "heap", NULL, 0, &s, err, sizeof err),
                         MIXSPH_ERR_CASE);
        assert_non_null(strstr(err, named[k]));
        assert_null(s);
    }
}

static void test_heap_below_phi(void **state)
{
    (void)state;
    mixsph_sim *s = NULL;
    char err[512] = "";
    assert_int_equal(mixsph_sim_create_from_text(heap_json(""), "heap", NULL, 0, &s, err, sizeof err), MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 2), MIXSPH_OK);
    const struct particles *P = &s->phys.P;
    const size_t n = P->n;
    double *x0 = calloc(n, sizeof *x0), *z0 = calloc(n, sizeof *z0);
    assert_true(x0 && z0);
    for (size_t i = 0; i < n; i++) {
        x0[P->id[i]] = P->x[i];
        z0[P->id[i]] = P->z[i];
    }
    assert_int_equal(mixsph_sim_advance_to(s, 2.0), MIXSPH_OK);
    double worst = 0.0;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] == MIXSPH_STATE_WALL) continue;
        assert_int_equal(P->state[i], MIXSPH_STATE_MOBILE); /* no hold rule: no grain is held */
        worst = fmax(worst, hypot(P->x[i] - x0[P->id[i]], P->z[i] - z0[P->id[i]]) / DX);
    }
    /* criterion: every grain within 0.1 dx over 2 s; measured 0.28 dx (12-06), band +-25 % */
    known_failure_check("elastic-plastic heap below phi, largest displacement [dx]", worst <= 0.1, worst, 0.21, 0.35);
    free(x0);
    free(z0);
    mixsph_sim_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_keys),
        cmocka_unit_test(test_heap_below_phi),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
