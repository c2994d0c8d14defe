/* test_diffusion.c - the density diffusion of the continuity pass (numerics.density_diffusion =
 * delta, numerics.density_diffusion_form; forces.c, docs/numerics.md section 2c):
 *   D_i = 2 delta h c_i sum_j V_j psi_ij (-F_ij),  j of i's medium, walls excluded,
 *   psi_ij = rho_j - rho_i - rho0 g (z_i - z_j) / c_i^2   ("hydrostatic", rho0 of i's medium)
 *   psi_ij = rho_j - rho_i                                 ("molteni"),
 * F_ij = W'(r)/r (grad_i W = F (x_i - x_j), kernel.h). Checked:
 * - the case keys, their defaults and their errors;
 * - in a closed box of two fluids with random densities, at rest (so the density rate is the
 *   diffusion alone), every particle's rate, and the sum of its pair terms from the test hook,
 *   against a brute-force sum over all pairs written from the formula above, in both forms;
 * - that it moves density and creates none: sum_i V_i D_i over each medium is 0 to round-off;
 * - that the hydrostatic form leaves the hydrostatic initial state of the tank at rest, where the
 *   whole-difference form does not.
 * A column at rest run for 1 s with the diffusion on: tests/test_hydrostatic.c. */
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
#include "test_random.h"

#define G_ACC 9.81
#define DX 0.01

/* Water and a lighter fluid side by side in a closed box (walls on three sides), gravity on. */
static const char *const BOX_FMT =
    "{\n"
    "  \"name\": \"diffusion_box\",\n"
    "  \"gravity\": 9.81,\n"
    "  \"numerics\": { \"dx\": 0.01, \"t_end\": 0.1%s },\n"
    "  \"media\": {\n"
    "    \"water\": { \"type\": \"fluid\", \"rho\": 1000.0, \"K\": 6.25e5, \"mu\": 1.0e-3, \"alpha_m\": 0.1 },\n"
    "    \"oil\": { \"type\": \"fluid\", \"rho\": 800.0, \"c\": 20.0, \"mu\": 0.05, \"alpha_m\": 0.1 }\n"
    "  },\n"
    "  \"bodies\": {\n"
    "    \"left\": { \"medium\": \"water\", \"polygon\": [[0.0, 0.0], [0.1, 0.0], [0.1, 0.2], [0.0, 0.2]] },\n"
    "    \"right\": { \"medium\": \"oil\", \"polygon\": [[0.1, 0.0], [0.2, 0.0], [0.2, 0.2], [0.1, 0.2]] }\n"
    "  },\n"
    "  \"walls\": { \"box\": { \"polyline\": [[0.0, 0.3], [0.0, 0.0], [0.2, 0.0], [0.2, 0.3]], \"fluid_side\": \"left\" } }\n"
    "}\n";

static const char *const TANK_PATH = MIXSPH_SOURCE_DIR "/cases/hydrostatic_tank.json";

static uint64_t rng_state;

static double uniform(double a, double b) { return test_random_uniform(&rng_state, a, b); }

static mixsph_status create_box(const char *extra, mixsph_sim **s, char *err, size_t len)
{
    char text[4096];
    snprintf(text, sizeof text, BOX_FMT, extra);
    return mixsph_sim_create_from_text(text, "diffusion_box.json", NULL, 0, s, err, len);
}

static mixsph_sim *box_ok(const char *extra)
{
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_status st = create_box(extra, &s, err, sizeof err);
    if (st != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    return s;
}

static void test_case_keys(void **state)
{
    (void)state;
    mixsph_sim *s = box_ok("");
    assert_true(s->cfg.density_diffusion == 0.1); /* the documented default */
    assert_int_equal(s->cfg.density_diffusion_form, DENSITY_DIFFUSION_HYDROSTATIC);
    mixsph_sim_destroy(s);
    s = box_ok(", \"density_diffusion\": 0, \"density_diffusion_form\": \"molteni\"");
    assert_true(s->cfg.density_diffusion == 0.0);
    assert_int_equal(s->cfg.density_diffusion_form, DENSITY_DIFFUSION_MOLTENI);
    mixsph_sim_destroy(s);
    const char *bad[] = {", \"density_diffusion\": -0.1", ", \"density_diffusion\": 2",
                         ", \"density_diffusion\": \"on\"", ", \"density_diffusion_form\": \"antuono\""};
    const char *key[] = {"numerics.density_diffusion", "numerics.density_diffusion", "numerics.density_diffusion",
                         "numerics.density_diffusion_form"};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        char err[512] = "";
        mixsph_sim *t = NULL;
        assert_int_equal(create_box(bad[k], &t, err, sizeof err), MIXSPH_ERR_CASE);
        assert_null(t);
        print_message("  refused: %s\n", err);
        assert_non_null(strstr(err, key[k]));
    }
}

/* The box at rest with every density perturbed by up to 1 % and every particle moved by up to
 * 0.3 dx (so that the pairs are not those of the lattice), lists rebuilt, EOS applied. */
static mixsph_sim *box_at_rest(const char *extra)
{
    mixsph_sim *s = box_ok(extra);
    mixsph_sim_set_threads(s, 2);
    rng_state = 45;
    struct particles *P = &s->phys.P;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] != MIXSPH_STATE_MOBILE) continue;
        P->pos[0][i] += uniform(-0.3, 0.3) * DX;
        P->pos[DIM_UP][i] += uniform(-0.3, 0.3) * DX;
        P->vel[0][i] = P->uv[0][i] = P->vel[DIM_UP][i] = P->uv[DIM_UP][i] = 0.0;
        P->rho[i] *= 1.0 + uniform(-0.01, 0.01);
    }
    assert_int_equal(integrate_rebuild_lists(s), MIXSPH_OK);
    integrate_pressure_and_derived(s);
    return s;
}

/* D_i by the formula, summed over all j (O(N^2)); also sum_j |terms| for the tolerance. */
static double brute_force(const mixsph_sim *s, size_t i, int hydrostatic, double *abs_sum)
{
    const struct particles *P = &s->phys.P;
    const double c = s->cfg.media[P->medium[i]].c, h = s->phys.h;
    const double hyd = hydrostatic ? s->cfg.media[P->medium[i]].rho0 * G_ACC / (c * c) : 0.0;
    double sum = 0.0, a = 0.0;
    for (size_t j = 0; j < P->n; j++) {
        if (j == i || P->state[j] == MIXSPH_STATE_WALL || P->medium[j] != P->medium[i]) continue;
        const double rx = P->pos[0][i] - P->pos[0][j], rz = P->pos[DIM_UP][i] - P->pos[DIM_UP][j], r = hypot(rx, rz);
        if (r >= 2.0 * h) continue;
        const double F = kernel_f(&s->phys.K, r);
        const double psi = P->rho[j] - P->rho[i] - hyd * rz;
        const double term = 2.0 * s->cfg.density_diffusion * h * c * P->m[j] / P->rho[j] * psi * (-F);
        sum += term;
        a += fabs(term);
    }
    *abs_sum = a;
    return sum;
}

static void check_against_formula(const char *extra, int hydrostatic)
{
    mixsph_sim *s = box_at_rest(extra);
    const struct particles *P = &s->phys.P;
    assert_int_equal(sim_density_pass(s), 0);
    double worst = 0.0, cons[2] = {0.0, 0.0}, cons_abs[2] = {0.0, 0.0};
    size_t n = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] == MIXSPH_STATE_WALL) {
            assert_true(P->drho[i] == 0.0); /* walls take no diffusion */
            continue;
        }
        double a;
        const double want = brute_force(s, i, hydrostatic, &a);
        /* reference: the formula; tolerance 1e-12 of the sum of |terms| (the same terms summed
         * in another order) */
        assert_true(fabs(P->drho[i] - want) <= 1e-12 * a);
        worst = fmax(worst, fabs(P->drho[i] - want) / (a > 0.0 ? a : 1.0));
        /* the test hook's pair terms (forces_pair_for_test, which test_forces.c checks against
         * (3a)) add up to the same rate; same tolerance */
        double hook = 0.0;
        for (size_t j = 0; j < P->n; j++) {
            double ax, az, dr;
            sim_pair_terms(s, i, j, &ax, &az, &dr);
            hook += dr;
        }
        assert_true(fabs(hook - want) <= 1e-12 * a);
        const double vi = P->m[i] / P->rho[i];
        cons[P->medium[i]] += vi * P->drho[i];
        cons_abs[P->medium[i]] += fabs(vi * P->drho[i]);
        n++;
    }
    print_message("%s form: %zu particles against the brute-force sum (largest difference %.2e of the sum of "
                  "|terms|); sum V D per medium %.2e, %.2e (sum |V D| %.2e, %.2e)\n",
                  hydrostatic ? "hydrostatic" : "molteni", n, worst, cons[0], cons[1], cons_abs[0], cons_abs[1]);
    for (int k = 0; k < 2; k++) {
        assert_true(cons_abs[k] > 0.0);
        /* reference: 0 (psi_ji = -psi_ij: the diffusion moves density within a medium and
         * creates none); tolerance 1e-13 of sum |V_i D_i|: round-off of a few thousand terms */
        assert_true(fabs(cons[k]) <= 1e-13 * cons_abs[k]);
    }
    mixsph_sim_destroy(s);
}

static void test_formula_and_conservation(void **state)
{
    (void)state;
    check_against_formula("", 1);
    check_against_formula(", \"density_diffusion\": 0.3, \"density_diffusion_form\": \"molteni\"", 0);
}

/* The tank's initial state (hydrostatic densities rho0 + rho0 g (H - z) / c^2, at rest): the
 * density rate is the diffusion alone. Reference: 0 (a column at rest must stay so). Tolerance:
 * a rate that would move no particle's pressure by more than 1 % of rho0 g dx in 1 s,
 * |D_i| c^2 (1 s) <= 0.01 rho0 g dx (the hydrostatic form removes exactly the lattice's density
 * differences, so only round-off remains); the whole-difference form diffuses the hydrostatic
 * gradient itself where the stencil is one-sided (floor, walls, surface) and must fail it. */
static double max_rate_at_rest(int form)
{
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_override ov[] = {{"numerics.density_diffusion", 0.1}, {"numerics.density_diffusion_form", form}};
    const mixsph_status st = mixsph_sim_create(TANK_PATH, ov, 2, &s, err, sizeof err);
    if (st != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    assert_int_equal(sim_density_pass(s), 0);
    double worst = 0.0;
    for (size_t i = 0; i < s->phys.P.n; i++)
        if (s->phys.P.state[i] != MIXSPH_STATE_WALL) worst = fmax(worst, fabs(s->phys.P.drho[i]));
    mixsph_sim_destroy(s);
    return worst;
}

static void test_column_at_rest(void **state)
{
    (void)state;
    const double c2 = 6.25e5 / 1000.0; /* the tank's K / rho0 */
    const double bound = 0.01 * 1000.0 * G_ACC * DX / c2;
    const double hydro = max_rate_at_rest(DENSITY_DIFFUSION_HYDROSTATIC), molteni = max_rate_at_rest(DENSITY_DIFFUSION_MOLTENI);
    print_message("largest |drho/dt| at rest: hydrostatic form %.3e, molteni form %.3e kg/m3/s (bound %.3e)\n", hydro,
                  molteni, bound);
    assert_true(hydro <= bound);
    assert_true(molteni > bound); /* the bound tells the forms apart */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_case_keys),
        cmocka_unit_test(test_formula_and_conservation),
        cmocka_unit_test(test_column_at_rest),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
