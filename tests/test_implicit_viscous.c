/* test_implicit_viscous.c - the implicit viscous step (viscous.c, numerics.viscosity =
 * "implicit"; docs/numerics.md) at time steps many times the explicit viscous limit.
 *
 * 1. Lid-driven closed channel (the flow of test_viscous.c, shorter): oil between a fixed floor
 *    and a lid sliding at U, closed ends, length L = 0.2 m, height H = 0.05 m. The developed flow
 *    far from the ends is Couette flow plus the pressure-driven (Poiseuille) back flow of zero
 *    net flux, u(z) = U eta (3 eta - 2), eta = z / H (e.g. White, Viscous Fluid Flow, section
 *    3-2). The viscosity is chosen so that the acoustic time step the implicit run takes is 20
 *    and 50 times the explicit viscous limit cfl_visc 2 h^2 rho / mu. The back flow is driven by a
 *    pressure gradient that builds by compression: in this weakly compressible fluid it spreads
 *    along the channel diffusively, with D = c^2 H^2 rho / (12 mu) (lubrication flow), so the run
 *    lasts about 6 L^2 / (pi^2 D) (0.4 s at mu = 330 Pa s, 1.2 s at 820 Pa s) before it is
 *    measured. The lid speed is small (1 mm/s) so that the pressure differences stay below 1 % of
 *    rho c^2. Norm: the largest over the z-bins of dx of |mean u_sph - mean u_exact| / U, over
 *    the particles with 0.08 < x < 0.12 m at the end.
 * 3. The two schemes on a granular run: the Vajont case (run V1) at dx = 0.03 m, explicit and
 *    implicit, agree on the max run-up and the landslide's final front within 3 mm (the
 *    tolerance the validation asks of the two schemes on this case, docs/validation/vajont.md).
 * 4. Restart: a run restored from a state saved mid-run continues exactly as the run itself (the
 *    warm start and the couplings come back with the state).
 * 2. Momentum: in a closed box with a no-slip floor and walls, the viscous solve changes the
 *    total momentum of the mobile particles only by the force of the wall particles (at the
 *    mirror velocities that go with the solution):
 *    sum_i m_i du_i = -dt sum_{i mobile} sum_{j} w_ij (u_i - u_j) (the pairs among mobile
 *    particles cancel), to the solver's tolerance. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "sim_passes.h"

#define DX 0.0025 /* [m] */
#define H 0.05    /* [m] */
#define U_LID 0.001 /* [m/s] */
#define NBIN 20   /* H / DX */

/* The channel runs the continuity equation (3a) as the paper writes it: its back flow is driven by
 * a compression gradient, and with the density diffusion at its default (0.1) the error of this
 * test was 6.9 % (20x) and 12.8 % (50x) of U (docs/numerics.md section 2c). */
static const char *const CHANNEL =
    "{ \"name\": \"lid_channel_implicit\", \"gravity\": 0.0,\n"
    "  \"numerics\": { \"dx\": 0.0025, \"t_end\": 2.0, \"background_pressure\": 200.0, \"viscosity\": \"implicit\",\n"
    "                 \"density_diffusion\": 0 },\n"
    "  \"media\": { \"oil\": { \"type\": \"fluid\", \"rho\": 1000.0, \"c\": 10.0, \"mu\": %g, \"alpha_m\": 0.0 } },\n"
    "  \"bodies\": { \"oil\": { \"medium\": \"oil\", \"polygon\": [[0.0, 0.0], [0.2, 0.0], [0.2, 0.05], [0.0, 0.05]] } },\n"
    "  \"walls\": { \"box\": { \"polyline\": [[0.0, 0.05], [0.0, 0.0], [0.2, 0.0], [0.2, 0.05]], \"fluid_side\": \"left\" },\n"
    "    \"lid\": { \"polyline\": [[-0.1, 0.05], [0.3, 0.05]], \"fluid_side\": \"right\", \"motion\": \"slide\" } },\n"
    "  \"motions\": { \"slide\": { \"t\": [0.0], \"vx\": [0.001], \"vz\": [0.0] } },\n"
    "  \"domain\": { \"x_min\": -0.15, \"x_max\": 0.4, \"z_min\": -0.02, \"z_max\": 0.08 } }\n";

static mixsph_sim *create(const char *fmt, double mu)
{
    char text[4096];
    snprintf(text, sizeof text, fmt, mu);
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_status st = mixsph_sim_create_from_text(text, "implicit_test.json", NULL, 0, &s, err, sizeof err);
    if (st != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK); /* ctest -j runs tests side by side */
    return s;
}

/* Run the channel at viscosity mu to t_end; the largest bin error / U, and the ratio of the time
 * step taken to the explicit viscous limit. */
static double channel_error(double mu, double t_end, double *dt_ratio)
{
    mixsph_sim *s = create(CHANNEL, mu);
    uint64_t iterations = 0;
    int most = 0;
    while (mixsph_sim_time(s) < t_end) {
        const mixsph_status st = mixsph_sim_step(s);
        if (st != MIXSPH_OK) print_error("%s\n", mixsph_sim_last_error(s));
        assert_int_equal(st, MIXSPH_OK);
        iterations += (uint64_t)s->work.viscous_last.iterations;
        if (s->work.viscous_last.iterations > most) most = s->work.viscous_last.iterations;
    }
    const double dt_visc = s->cfg.cfl_visc * 2.0 * s->phys.h * s->phys.h * 1000.0 / mu;
    *dt_ratio = s->phys.dt / dt_visc;
    double su[NBIN] = {0}, sa[NBIN] = {0};
    long cnt[NBIN] = {0};
    const struct particles *P = &s->phys.P;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] == MIXSPH_STATE_WALL) continue;
        assert_int_equal(P->state[i], MIXSPH_STATE_MOBILE); /* none lost */
        if (P->pos[0][i] < 0.08 || P->pos[0][i] > 0.12) continue;
        const int b = (int)floor(P->pos[DIM_UP][i] / DX);
        assert_true(b >= 0 && b < NBIN);
        const double eta = P->pos[DIM_UP][i] / H;
        su[b] += P->vel[0][i];
        sa[b] += U_LID * eta * (3.0 * eta - 2.0);
        cnt[b]++;
    }
    double worst = 0.0;
    for (int b = 0; b < NBIN; b++) {
        assert_true(cnt[b] > 0);
        worst = fmax(worst, fabs(su[b] - sa[b]) / cnt[b] / U_LID);
    }
    print_message("mu = %g Pa s: %llu steps to t = %.3f s, dt = %.3g s = %.1f x the explicit viscous limit, "
                  "%.1f solver iterations per step (at most %d); largest |u - u_exact| = %.2f%% of U\n",
                  mu, (unsigned long long)mixsph_sim_steps(s), mixsph_sim_time(s), s->phys.dt, *dt_ratio,
                  (double)iterations / (double)mixsph_sim_steps(s), most, 100.0 * worst);
    mixsph_sim_destroy(s);
    return worst;
}

static void test_channel_20x(void **state)
{
    (void)state;
    double ratio;
    const double e = channel_error(330.0, 0.4, &ratio);
    assert_true(ratio >= 20.0); /* the time step the test is about */
    /* reference: u = U eta (3 eta - 2) (header); tolerance 2 % of U */
    assert_true(e <= 0.02);
}

/* 50 times the explicit limit: the diffusive build-up of the back flow's pressure gradient takes
 * 1.2 s at this viscosity (header; 15 s of CPU). In the validation suite (`test_implicit_viscous
 * validation`); ./tools/do test keeps test_channel_20x, the same flow, reference and tolerance at
 * 20 times the limit (0.4 s). */
static void test_channel_50x(void **state)
{
    (void)state;
    double ratio;
    const double e = channel_error(820.0, 1.2, &ratio);
    assert_true(ratio >= 50.0);
    /* reference: u = U eta (3 eta - 2) (header); tolerance 2 % of U */
    assert_true(e <= 0.02);
}

/* A box of oil at rest under gravity with a shear velocity field imposed (white box), one step. */
static const char *const BOX =
    "{ \"name\": \"box_implicit\", \"gravity\": 9.81,\n"
    "  \"numerics\": { \"dx\": 0.005, \"t_end\": 1.0, \"viscosity\": \"implicit\", \"viscous_tolerance\": 1e-10 },\n"
    "  \"media\": { \"oil\": { \"type\": \"fluid\", \"rho\": 1000.0, \"c\": 20.0, \"mu\": %g, \"alpha_m\": 0.0 } },\n"
    "  \"bodies\": { \"oil\": { \"medium\": \"oil\", \"polygon\": [[0.0, 0.0], [0.1, 0.0], [0.1, 0.05], [0.0, 0.05]] } },\n"
    "  \"walls\": { \"box\": { \"polyline\": [[0.0, 0.1], [0.0, 0.0], [0.1, 0.0], [0.1, 0.1]], \"fluid_side\": \"left\" } },\n"
    "  \"domain\": { \"x_min\": -0.05, \"x_max\": 0.15, \"z_min\": -0.05, \"z_max\": 0.15 } }\n";

/* The box with its shear field and the operator at its positions (the momentum pass stores the
 * couplings). */
static mixsph_sim *box_with_shear(void)
{
    mixsph_sim *s = create(BOX, 50.0);
    struct particles *P = &s->phys.P;
    const size_t n = s->work.C.start[s->work.C.ncell];
    for (size_t i = 0; i < n; i++) /* a shear field that the walls resist */
        if (P->state[i] == MIXSPH_STATE_MOBILE) {
            P->vel[0][i] = P->uv[0][i] = 0.1 * sin(40.0 * P->pos[DIM_UP][i]);
            P->vel[DIM_UP][i] = P->uv[DIM_UP][i] = 0.05 * cos(30.0 * P->pos[0][i]);
        }
    assert_true(sim_density_pass(s) >= 0);
    integrate_pressure_and_derived(s);
    assert_int_equal(sim_momentum_pass(s), 0);
    return s;
}

/* One backward-Euler solve of the box over `factor` times the explicit viscous limit, with the
 * walls' mirror; returns the report. */
static struct viscous_report box_solve(mixsph_sim *s, double factor, int preconditioner)
{
    const size_t n = s->work.C.start[s->work.C.ncell];
    const struct pair_system S = sim_pair_system(s);
    struct viscous_solver *V = viscous_create();
    assert_non_null(V);
    struct viscous_report rep;
    const double dt = factor * s->cfg.cfl_visc * 2.0 * s->phys.h * s->phys.h * 1000.0 / 50.0;
    struct wall_mirror *M = walls_mirror_create();
    assert_non_null(M);
    assert_int_equal(walls_mirror_build(M, &s->phys.walls, &s->phys.K, &s->work.G, &s->phys.P, n, 1), 0);
    walls_mirror_at(M, &s->phys.walls, &s->phys.P, s->phys.t, dt, 1);
    assert_int_equal(viscous_solve(V, s->work.forces, &S, M, dt, preconditioner, 1e-10, 1000, &rep), 0);
    viscous_free(V);
    walls_mirror_free(M);
    return rep;
}

static void momentum_only_changed_by_walls(int preconditioner)
{
    mixsph_sim *s = box_with_shear();
    struct particles *P = &s->phys.P;
    const size_t n = s->work.C.start[s->work.C.ncell];
    double *ux0 = calloc(n, sizeof(double)), *uz0 = calloc(n, sizeof(double));
    assert_non_null(ux0);
    assert_non_null(uz0);
    for (size_t i = 0; i < n; i++) {
        ux0[i] = P->vel[0][i];
        uz0[i] = P->vel[DIM_UP][i];
    }
    const double factor = 10.0; /* times the explicit viscous limit */
    const struct viscous_report rep = box_solve(s, factor, preconditioner);
    const double dt = factor * s->cfg.cfl_visc * 2.0 * s->phys.h * s->phys.h * 1000.0 / 50.0;
    const struct pair_system S = sim_pair_system(s);
    assert_true(rep.converged);
    /* momentum change of the mobile particles, and the force of the walls from the new field */
    double *ux = calloc(n, sizeof(double)), *uz = calloc(n, sizeof(double));
    double *lx = calloc(n, sizeof(double)), *lz = calloc(n, sizeof(double));
    assert_true(ux && uz && lx && lz);
    double dpx = 0.0, dpz = 0.0, scale = 0.0;
    for (size_t i = 0; i < n; i++) {
        const int wall = P->state[i] == MIXSPH_STATE_WALL;
        ux[i] = wall ? P->uv[0][i] : P->vel[0][i];
        uz[i] = wall ? P->uv[DIM_UP][i] : P->vel[DIM_UP][i];
        if (P->state[i] != MIXSPH_STATE_MOBILE) continue;
        dpx += P->m[i] * (P->vel[0][i] - ux0[i]);
        dpz += P->m[i] * (P->vel[DIM_UP][i] - uz0[i]);
        scale += P->m[i] * hypot(ux0[i], uz0[i]);
    }
    const double *const u[DIM] = {ux, uz};
    double *const lu[DIM] = {lx, lz};
    assert_int_equal(forces_viscous_apply(s->work.forces, &S, u, lu, NULL), 0);
    double fx = 0.0, fz = 0.0;
    for (size_t i = 0; i < n; i++)
        if (P->state[i] == MIXSPH_STATE_MOBILE) {
            fx -= dt * lx[i];
            fz -= dt * lz[i];
        }
    print_message("momentum change (%.6e, %.6e), wall impulse (%.6e, %.6e), sum |m u| %.3e, %d iterations, "
                  "residual %.2e\n", dpx, dpz, fx, fz, scale, rep.iterations, rep.residual);
    /* reference: the pairs among mobile particles cancel exactly (w_ij = w_ji), so the change is
     * the walls' impulse; tolerance: the solver's (1e-10 relative) on the momentum scale sum m|u|,
     * times 100 for the round-off of the sums */
    assert_true(fabs(dpx - fx) <= 1e-8 * scale);
    assert_true(fabs(dpz - fz) <= 1e-8 * scale);
    assert_true(fabs(fx) > 1e-3 * scale); /* the walls do act: the check is not 0 = 0 */
    free(ux0);
    free(uz0);
    free(ux);
    free(uz);
    free(lx);
    free(lz);
    mixsph_sim_destroy(s);
}

static void test_momentum_only_changed_by_walls(void **state)
{
    (void)state;
    momentum_only_changed_by_walls(VISCOUS_JACOBI);
}

static void test_momentum_only_changed_by_walls_two_level(void **state)
{
    (void)state;
    momentum_only_changed_by_walls(VISCOUS_TWO_LEVEL);
}

/* The two preconditioners solve the same system: the box at 1000 times the explicit limit (the
 * regime of a slow landslide at the acoustic step, where the error Jacobi leaves is smooth). */
static void test_two_level_same_solution_fewer_iterations(void **state)
{
    (void)state;
    const double factor = 1000.0;
    mixsph_sim *a = box_with_shear(), *b = box_with_shear();
    const struct viscous_report ra = box_solve(a, factor, VISCOUS_JACOBI);
    const struct viscous_report rb = box_solve(b, factor, VISCOUS_TWO_LEVEL);
    assert_true(ra.converged && rb.converged);
    const size_t n = a->work.C.start[a->work.C.ncell];
    double diff = 0.0, scale = 0.0;
    for (size_t i = 0; i < n; i++)
        if (a->phys.P.state[i] == MIXSPH_STATE_MOBILE) {
            diff = fmax(diff, hypot(a->phys.P.vel[0][i] - b->phys.P.vel[0][i], a->phys.P.vel[DIM_UP][i] - b->phys.P.vel[DIM_UP][i]));
            scale = fmax(scale, hypot(a->phys.P.vel[0][i], a->phys.P.vel[DIM_UP][i]));
        }
    print_message("jacobi %d iterations, two_level %d; largest difference %.2e of the largest speed %.2e\n",
                  ra.iterations, rb.iterations, diff, scale);
    /* reference: both solutions of the same linear system to a relative residual of 1e-10; the
     * error is at most cond(A) times that, and cond(A) <= 1 + kappa max_i sum_j 2 w_ij / m_i is
     * about 1e4 here, so 1e-5 of the largest speed bounds their difference */
    assert_true(diff <= 1e-5 * scale);
    /* the coarse level exists to remove the smooth error: it must save iterations */
    assert_true(rb.iterations < ra.iterations);
    mixsph_sim_destroy(a);
    mixsph_sim_destroy(b);
}

/* The max run-up and the final landslide front of Vajont V1 at dx = 0.03 with one scheme. */
static void vajont_run(double viscosity, double *run_up, double *front, uint64_t *steps)
{
    const mixsph_override ov[] = {{"numerics.dx", 0.03}, {"numerics.viscosity", viscosity}};
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_status st = mixsph_sim_create(MIXSPH_SOURCE_DIR "/cases/vajont_padua.json", ov, 2, &s, err, sizeof err);
    if (st != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(s, mixsph_sim_end_time(s)), MIXSPH_OK);
    const long k = mixsph_sim_output_find(s, "run_up"), f = mixsph_sim_output_find(s, "landslide_front");
    assert_true(k >= 0 && f >= 0);
    double t_max, lo, t_lo;
    mixsph_sim_output_extremes(s, (size_t)k, run_up, &t_max, &lo, &t_lo);
    *front = mixsph_sim_output_value(s, (size_t)f);
    *steps = mixsph_sim_steps(s);
    mixsph_sim_destroy(s);
}

static void test_schemes_agree_on_vajont(void **state)
{
    (void)state;
    double ru_e, fr_e, ru_i, fr_i;
    uint64_t n_e, n_i;
    vajont_run(0.0, &ru_e, &fr_e, &n_e);
    vajont_run(1.0, &ru_i, &fr_i, &n_i);
    print_message("Vajont V1, dx = 0.03: explicit %llu steps, run-up %.4f m, front %.4f m; implicit %llu steps, "
                  "run-up %.4f m, front %.4f m\n", (unsigned long long)n_e, ru_e, fr_e, (unsigned long long)n_i, ru_i,
                  fr_i);
    assert_true(n_i < n_e); /* the implicit run takes the longer time step */
    /* reference: the explicit scheme; tolerance 3 mm (header) */
    assert_true(fabs(ru_i - ru_e) <= 0.003);
    assert_true(fabs(fr_i - fr_e) <= 0.003);
}

/* A restored state continues bit-identically (implicit Vajont at dx = 0.04, one thread). */
static void test_restore_continues_identically(void **state)
{
    (void)state;
    const mixsph_override ov[] = {{"numerics.dx", 0.04}, {"numerics.viscosity", 1.0}};
    mixsph_sim *s = NULL, *t = NULL;
    char err[512] = "";
    assert_int_equal(mixsph_sim_create(MIXSPH_SOURCE_DIR "/cases/vajont_padua.json", ov, 2, &s, err, sizeof err),
                     MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(s, 0.3), MIXSPH_OK);
    void *buf = NULL;
    size_t len = 0;
    assert_int_equal(mixsph_sim_save_state(s, &buf, &len), MIXSPH_OK);
    assert_int_equal(mixsph_sim_create_from_state(buf, len, &t, err, sizeof err), MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(t, 1), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(s, 0.5), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(t, 0.5), MIXSPH_OK);
    assert_true(mixsph_sim_steps(s) == mixsph_sim_steps(t));
    mixsph_particles_view a, b;
    assert_int_equal(mixsph_sim_particles_view(s, &a), MIXSPH_OK);
    assert_int_equal(mixsph_sim_particles_view(t, &b), MIXSPH_OK);
    assert_true(a.n == b.n);
    size_t differ = 0;
    for (size_t i = 0; i < a.n; i++)
        differ += a.id[i] != b.id[i] || a.pos[0][i] != b.pos[0][i] || a.pos[a.dim - 1][i] != b.pos[b.dim - 1][i] || a.vel[0][i] != b.vel[0][i] ||
                  a.vel[a.dim - 1][i] != b.vel[b.dim - 1][i] || a.p[i] != b.p[i];
    print_message("restored run: %llu steps, %zu of %zu particles differ\n", (unsigned long long)mixsph_sim_steps(t),
                  differ, a.n);
    assert_true(differ == 0); /* reference: the uninterrupted run; tolerance: bit-identical */
    mixsph_state_free(buf);
    mixsph_sim_destroy(s);
    mixsph_sim_destroy(t);
}

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "validation") == 0) {
        /* the long version (CTest test_implicit_viscous_validation, label validation) */
        const struct CMUnitTest long_tests[] = {cmocka_unit_test(test_channel_50x)};
        return cmocka_run_group_tests(long_tests, NULL, NULL);
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_momentum_only_changed_by_walls),
        cmocka_unit_test(test_momentum_only_changed_by_walls_two_level),
        cmocka_unit_test(test_two_level_same_solution_fewer_iterations),
        cmocka_unit_test(test_restore_continues_identically),
        cmocka_unit_test(test_schemes_agree_on_vajont),
        cmocka_unit_test(test_channel_20x),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
