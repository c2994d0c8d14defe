/* test_smoothing.c - the partial pressure smoothing (option numerics.pressure_smoothing = theta_P,
 * forces_smooth_pressure in forces.c; SPHERA's "pressure smoothing" of Di Monaco et al. 2011):
 *   p_i += theta_P c dt / h * sum_j B_ij W_ij V_j / sum_j W_ij V_j,
 *   B_ij = p_j - p_i + (rho_i + rho_j)/2 g (z_j - z_i),  j over the non-wall neighbours,
 * and rho_i follows through the EOS. Checked in a tank of water at rest (0.4 x 0.3 m, dx = 0.01):
 * the case key and its errors; every particle's new pressure against a brute-force sum over all
 * pairs; a hydrostatic field left unchanged (walls and free surface included); the densities
 * consistent with the EOS afterwards; and a checkerboard pressure noise damped by the factor the
 * kernel predicts on the lattice. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "kernel.h"
#include "mixsph.h"
#include "sim_passes.h"

#define DX 0.01
#define G_ACC 9.81
#define RHO0 1000.0
#define THETA 0.4
#define F_STEP 0.5 /* theta_P c dt / h of the smoothing steps below (dt chosen for it) */

static const char *const CASE_FMT =
    "{\n"
    "  \"name\": \"smoothing_tank\",\n"
    "  \"gravity\": 9.81,\n"
    "  \"numerics\": { \"dx\": 0.01, \"t_end\": 1.0%s },\n"
    "  \"media\": { \"water\": { \"type\": \"fluid\", \"rho\": 1000.0, \"K\": 6.25e5, \"mu\": 1.0e-3, \"alpha_m\": 0.1 } },\n"
    "  \"bodies\": { \"pool\": { \"medium\": \"water\", \"polygon\": [[0.0, 0.0], [0.4, 0.0], [0.4, 0.3], [0.0, 0.3]] } },\n"
    "  \"walls\": { \"tank\": { \"polyline\": [[0.0, 0.5], [0.0, 0.0], [0.4, 0.0], [0.4, 0.5]], \"fluid_side\": \"left\" } }\n"
    "}\n";

static mixsph_status create(const char *extra, mixsph_sim **s, char *err, size_t len)
{
    char text[2048];
    snprintf(text, sizeof text, CASE_FMT, extra);
    const mixsph_status st = mixsph_sim_create_from_text(text, "smoothing_tank.json", NULL, 0, s, err, len);
    if (st == MIXSPH_OK) mixsph_sim_set_threads(*s, 2);
    return st;
}

static mixsph_sim *create_ok(const char *extra)
{
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_status st = create(extra, &s, err, sizeof err);
    if (st != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    return s;
}

static void test_case_key(void **state)
{
    (void)state;
    mixsph_sim *s = create_ok("");
    assert_true(s->cfg.pressure_smoothing == 0.0); /* default: off */
    mixsph_sim_destroy(s);
    s = create_ok(", \"pressure_smoothing\": 0.4");
    assert_true(s->cfg.pressure_smoothing == 0.4);
    mixsph_sim_destroy(s);
    const char *bad[] = {", \"pressure_smoothing\": -0.1", ", \"pressure_smoothing\": 1.5",
                         ", \"pressure_smoothing\": \"strong\""};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        char err[512] = "";
        mixsph_sim *t = NULL;
        assert_int_equal(create(bad[k], &t, err, sizeof err), MIXSPH_ERR_CASE);
        assert_null(t);
        print_message("  refused: %s\n", err);
        assert_non_null(strstr(err, "numerics.pressure_smoothing"));
    }
}

/* The new pressure of every non-wall particle by a brute-force sum over all non-wall pairs. */
static double *brute_force(const mixsph_sim *s, double f)
{
    const struct particles *P = &s->phys.P;
    double *out = calloc(P->n, sizeof *out);
    assert_non_null(out);
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] == MIXSPH_STATE_WALL) continue;
        double a = 0.0, u = 0.0;
        for (size_t j = 0; j < P->n; j++) {
            if (j == i || P->state[j] == MIXSPH_STATE_WALL) continue;
            const double r = hypot(P->pos[0][i] - P->pos[0][j], P->pos[DIM_UP][i] - P->pos[DIM_UP][j]);
            const double w = kernel_w(&s->phys.K, r) * P->m[j] / P->rho[j];
            a += (P->p[j] - P->p[i] + 0.5 * (P->rho[i] + P->rho[j]) * G_ACC * (P->pos[DIM_UP][j] - P->pos[DIM_UP][i])) * w;
            u += w;
        }
        out[i] = P->p[i] + f * s->cfg.media[0].c * a / u;
    }
    return out;
}

/* One smoothing step with theta_P c dt / h = F_STEP; checks it against the brute force and the
 * EOS afterwards; returns the pressures before it (caller frees). */
static double *smooth_checked(mixsph_sim *s)
{
    struct particles *P = &s->phys.P;
    const double c = s->cfg.media[0].c;
    s->phys.dt = F_STEP * s->phys.h / (THETA * c);
    double *before = malloc(P->n * sizeof *before);
    assert_non_null(before);
    memcpy(before, P->p, P->n * sizeof *before);
    double *want = brute_force(s, F_STEP / c);
    sim_smooth_pressure(s);
    double worst = 0.0;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] == MIXSPH_STATE_WALL) {
            assert_true(P->p[i] == before[i]); /* walls are not smoothed */
            continue;
        }
        /* the same terms summed in another order: round-off of pressures up to 3 kPa */
        worst = fmax(worst, fabs(P->p[i] - want[i]));
        assert_true(fabs(P->p[i] - want[i]) <= 1e-9 * 3000.0);
        /* the EOS still holds: p = c^2 (rho - rho0) (background pressure 0 here) */
        assert_true(fabs(P->p[i] - c * c * (P->rho[i] - RHO0)) <= 1e-9 * 3000.0);
        assert_true(fabs(P->inv_rho[i] * P->rho[i] - 1.0) <= 1e-15);
    }
    print_message("  largest difference from the brute-force sum: %.3g Pa\n", worst);
    free(want);
    return before;
}

/* A hydrostatic field is a fixed point: B_ij vanishes up to the O(g dz drho) of the mean density,
 * so no particle's pressure moves by more than 1 % of rho g dx (0.98 Pa) in one step of weight
 * 0.5, neither inside nor at the walls or the free surface where the kernel sums are one-sided. */
static void test_hydrostatic_fixed_point(void **state)
{
    (void)state;
    mixsph_sim *s = create_ok(", \"pressure_smoothing\": 0.4");
    double *before = smooth_checked(s);
    double worst = 0.0;
    for (size_t i = 0; i < s->phys.P.n; i++)
        if (s->phys.P.state[i] != MIXSPH_STATE_WALL) worst = fmax(worst, fabs(s->phys.P.p[i] - before[i]));
    print_message("hydrostatic tank: largest pressure change %.3g Pa (rho g dx = %.3g Pa)\n", worst, RHO0 * G_ACC * DX);
    assert_true(worst <= 0.01 * RHO0 * G_ACC * DX);
    free(before);
    mixsph_sim_destroy(s);
}

/* Checkerboard noise d_i = A (-1)^(ix + iz) on the hydrostatic field. Inside (farther than 2h
 * from the walls and the surface) the kernel mean of the neighbours' noise is -kappa d_i on the
 * lattice, kappa = -sum_{j != i} (-1)^(jx + jz) W_ij / sum_{j != i} W_ij (computed here from the
 * kernel), so one step multiplies it by 1 - F (1 + kappa) (the volumes differ by the density's
 * 0.5 %, hence a 1 % tolerance on the factor). */
static void test_checkerboard_damped(void **state)
{
    (void)state;
    mixsph_sim *s = create_ok(", \"pressure_smoothing\": 0.4");
    struct particles *P = &s->phys.P;
    const double A = 100.0, c = s->cfg.media[0].c;
    double *hyd = malloc(P->n * sizeof *hyd);
    assert_non_null(hyd);
    memcpy(hyd, P->p, P->n * sizeof *hyd);
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] == MIXSPH_STATE_WALL) continue;
        const long ix = lround(P->pos[0][i] / DX - 0.5), iz = lround(P->pos[DIM_UP][i] / DX - 0.5);
        P->rho[i] += ((ix + iz) % 2 ? -A : A) / (c * c);
    }
    integrate_pressure_and_derived(s);
    double sw = 0.0, sa = 0.0;
    for (int a = -3; a <= 3; a++)
        for (int b = -3; b <= 3; b++) {
            if (a == 0 && b == 0) continue;
            const double w = kernel_w(&s->phys.K, hypot(a, b) * DX);
            sw += w;
            sa += ((a + b) % 2 ? -1.0 : 1.0) * w;
        }
    const double kappa = -sa / sw, factor = 1.0 - F_STEP * (1.0 + kappa);
    double *before = smooth_checked(s);
    const double margin = 2.0 * s->phys.h + DX;
    double s0 = 0.0, s1 = 0.0;
    long n_in = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] == MIXSPH_STATE_WALL) continue;
        if (P->pos[0][i] < margin || P->pos[0][i] > 0.4 - margin || P->pos[DIM_UP][i] < margin || P->pos[DIM_UP][i] > 0.3 - margin) continue;
        s0 += (before[i] - hyd[i]) * (before[i] - hyd[i]);
        s1 += (P->p[i] - hyd[i]) * (P->p[i] - hyd[i]);
        n_in++;
    }
    const double ratio = sqrt(s1 / s0);
    print_message("checkerboard noise: kappa = %.4f, rms ratio %.4f over %ld inner particles (expected %.4f)\n", kappa,
                  ratio, n_in, factor);
    assert_true(n_in > 300);
    assert_true(fabs(ratio - factor) <= 0.01 * factor);
    free(before);
    free(hyd);
    mixsph_sim_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_case_key),
        cmocka_unit_test(test_hydrostatic_fixed_point),
        cmocka_unit_test(test_checkerboard_damped),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
