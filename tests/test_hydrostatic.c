/* test_hydrostatic.c - water at rest in a closed tank (cases/hydrostatic_tank.json: 0.4 m wide,
 * H = 0.3 m deep, dx = 0.01, K = 6.25e5 Pa, cubic spline at h = 1.3 dx) run to t = 1 s: no
 * particle leaves, the particle volumes fill the tank, and the pressure field is hydrostatic
 * (docs/model.md sections 3 and 8: "hydrostatic pressure is right at walls").
 *
 * What is measured, at 11 instants t = 0.80, 0.82, ..., 1.00 s:
 * - the free surface z_s: the mean height of the top row of particles plus dx/2 (the particles
 *   start on the lattice (i + 1/2) dx, so z_s = H at t = 0);
 * - the SPH volume of the water, sum_i m_i / rho_i, against the area it fills, W z_s. Every
 *   particle is created with m_i = rho_i dx^2 (hydrostatic initial densities, sim.c), so the two
 *   are equal at t = 0; they stay equal only while the continuity density stays consistent with
 *   the particle positions (no density drift, no gap opening at the walls: a gap of 0.1 dx along
 *   the wetted boundary is 0.8% of the area);
 * - the pressure in layers of height dx (mean over the layer's particles) against
 *   rho0 g (z_s - z), z the layer's mean height.
 * Run as the case has it and with the density diffusion on (numerics.density_diffusion = 0.1). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <cmocka.h>

#include "mixsph.h"

#define TANK_WIDTH 0.4 /* W [m] */
#define DEPTH 0.3      /* H, the initial depth [m] */
#define RHO0 1000.0    /* [kg/m3] */
#define K_BULK 6.25e5  /* bulk modulus rho0 c^2 of the case [Pa] */
#define G 9.81         /* [m/s2] */
#define DX 0.01        /* [m] */
#define NLAYER 32      /* layers of height dx from the floor (the water is 30 deep) */

/* The tank as the case has it (no density diffusion), or with the overrides ov. */
static void run_tank(const mixsph_override *ov, size_t n_ov)
{
    mixsph_sim *s = NULL;
    char err[512] = "";
    const char *path = MIXSPH_SOURCE_DIR "/cases/hydrostatic_tank.json";
    assert_int_equal(mixsph_sim_create(path, ov, n_ov, &s, err, sizeof err), MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK); /* ctest -j runs tests side by side */
    const size_t n = mixsph_sim_particles(s);
    assert_int_equal(n, 1200); /* the case is the one described above: 40 x 30 particles */
    const size_t out_mass = (size_t)mixsph_sim_output_find(s, "mass"), lost = (size_t)mixsph_sim_output_find(s, "lost_particles");
    const size_t vmax = (size_t)mixsph_sim_output_find(s, "max_speed");

    /* the particle masses, by id, from m = rho dx^2 at creation; checked against the mass output */
    mixsph_particles_view v;
    assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
    double *mass = calloc(v.n, sizeof *mass), m_total = 0.0, v_total = 0.0;
    assert_non_null(mass);
    for (size_t i = 0; i < v.n; i++) {
        if (v.state[i] == MIXSPH_STATE_WALL) continue;
        assert_true(v.id[i] < v.n);
        mass[v.id[i]] = v.rho[i] * DX * DX;
        m_total += mass[v.id[i]];
        v_total += mass[v.id[i]] / v.rho[i];
    }
    assert_true(fabs(m_total - mixsph_sim_output_value(s, out_mass)) <= 1e-12 * m_total);
    assert_true(fabs(v_total - TANK_WIDTH * DEPTH) <= 1e-12 * v_total);

    /* tolerance of the volume check: a tenth of the water's compression, the mean pressure
     * rho0 g H / 2 over K (0.24% of the volume): the check tells a density field that carries the
     * compression from one that does not, and catches a gap of 0.003 dx along the walls */
    const double vol_tol = 0.1 * RHO0 * G * DEPTH / (2.0 * K_BULK);
    double worst_vol = 0.0, worst_p = 0.0, worst_bottom = 0.0;
    for (int k = 0; k <= 10; k++) {
        const double t = 0.8 + 0.02 * k;
        const mixsph_status st = mixsph_sim_advance_to(s, t);
        if (st != MIXSPH_OK) print_error("%s\n", mixsph_sim_last_error(s));
        assert_int_equal(st, MIXSPH_OK);
        assert_true(mixsph_sim_output_value(s, lost) == 0.0);
        assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
        double vol = 0.0, ztop = -INFINITY;
        for (size_t i = 0; i < v.n; i++) {
            if (v.state[i] == MIXSPH_STATE_WALL) continue;
            /* none lost, none outside the tank */
            assert_int_equal(v.state[i], MIXSPH_STATE_MOBILE);
            assert_true(v.pos[0][i] > 0.0 && v.pos[0][i] < TANK_WIDTH && v.pos[v.dim - 1][i] > 0.0);
            vol += mass[v.id[i]] / v.rho[i];
            ztop = fmax(ztop, v.pos[v.dim - 1][i]);
        }
        double sz_top = 0.0, sp[NLAYER] = {0}, sz[NLAYER] = {0};
        int n_top = 0, cnt[NLAYER] = {0};
        for (size_t i = 0; i < v.n; i++) {
            if (v.state[i] == MIXSPH_STATE_WALL) continue;
            if (v.pos[v.dim - 1][i] > ztop - 0.5 * DX) {
                sz_top += v.pos[v.dim - 1][i];
                n_top++;
            }
            const int b = (int)floor(v.pos[v.dim - 1][i] / DX);
            assert_true(b >= 0 && b < NLAYER);
            sp[b] += v.p[i];
            sz[b] += v.pos[v.dim - 1][i];
            cnt[b]++;
        }
        assert_true(n_top >= 38); /* the top row has 40 particles */
        const double zs = sz_top / n_top + 0.5 * DX;
        /* reference: the area the water fills, W z_s; tolerance vol_tol (above) */
        const double e_vol = vol / (TANK_WIDTH * zs) - 1.0;
        assert_true(fabs(e_vol) <= vol_tol);
        worst_vol = fmax(worst_vol, fabs(e_vol));
        /* reference: p = rho0 g (z_s - z) in every layer (the compression of the water changes
         * it by less than rho0 g H / (2 K) = 0.24%); tolerance: the lattice bias of the SPH
         * gradient with the cubic spline at h = 1.3 dx (1.05% of the pressure: the column settles
         * at p / 1.0105, kernel.h) plus the head of half a particle spacing, rho0 g dx / 2 = 49 Pa
         * (the free surface of SPH is defined to about dx/2: the top row's particles see a
         * truncated kernel) */
        double e_bottom = 0.0;
        for (int b = 0; b < NLAYER; b++) {
            if (cnt[b] == 0) continue;
            const double z = sz[b] / cnt[b], p = sp[b] / cnt[b], p_ref = RHO0 * G * (zs - z);
            const double tol = 0.0105 * p_ref + 0.5 * RHO0 * G * DX;
            worst_p = fmax(worst_p, fabs(p - p_ref) / tol);
            if (b == 0) e_bottom = (p - p_ref) / p_ref;
            assert_true(fabs(p - p_ref) <= tol);
        }
        worst_bottom = fmax(worst_bottom, fabs(e_bottom));
        print_message("t = %.3f s: surface z_s = %.6f m, sum m/rho = %.7f m2 = W z_s %+.2e, bottom layer p %+.2f%%, "
                      "max speed %.4f m/s\n",
                      mixsph_sim_time(s), zs, vol, e_vol, 100.0 * e_bottom, mixsph_sim_output_value(s, vmax));
    }
    print_message("largest volume error %.2e (tolerance %.2e); largest layer pressure error %.2f of its tolerance; "
                  "bottom layer within %.2f%% of rho0 g (z_s - z)\n",
                  worst_vol, vol_tol, worst_p, 100.0 * worst_bottom);
    free(mass);
    mixsph_sim_destroy(s);
}

static void test_hydrostatic_tank(void **state)
{
    (void)state;
    run_tank(NULL, 0);
}

/* The same column, references and tolerances with the density diffusion on at its default
 * coefficient (docs/numerics.md section 2c): it must leave the column at rest. */
static void test_hydrostatic_tank_diffusion(void **state)
{
    (void)state;
    const mixsph_override ov[] = {{"numerics.density_diffusion", 0.1}};
    run_tank(ov, 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hydrostatic_tank),
        cmocka_unit_test(test_hydrostatic_tank_diffusion),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
