/* test_viscous.c - the laminar viscous term (forces.c: Morris et al. 1997 Laplacian with the
 * pairwise harmonic-mean viscosity; MODEL.md section 7 asks for a check against an analytical
 * viscous flow) and no-slip moving walls (section 8), on a lid-driven long closed cavity.
 *
 * Oil (rho = 1000 kg/m3, mu = 10 Pa s, nu = 0.01 m2/s, no artificial viscosity, no gravity)
 * fills a closed channel of length L = 0.5 m and height H = 0.05 m whose lid slides at
 * U = 0.01 m/s (Re = U H / nu = 0.05). Far from the ends the developed flow is parallel with zero
 * net flux: Couette flow plus the pressure-driven back flow,
 *     u(z) = U eta (3 eta - 2),  eta = z / H,      dp/dx = mu d2u/dz2 = 6 mu U / H^2 = 240 Pa/m
 * (e.g. White, Viscous Fluid Flow, section 3-2; u(0) = 0, u(H) = U, integral of u over the height
 * = 0). The profile settles with the diffusion time H^2 / (pi^2 nu) = 0.025 s, so it is developed
 * long before t = 0.2 s; the ends only disturb the flow over about H from each end wall.
 *
 * Kernel: Wendland C2 (CHANNEL_KERNEL). With the default cubic spline the continuity density
 * drifts in this shear flow (no density diffusion in the solver): the mean pressure climbs from
 * the background 200 Pa to 240 Pa at t = 0.3 s and 313 Pa at 0.6 s, with a growing spurious
 * gradient along x, dp/dx = 291-319 Pa/m over 0.2-0.3 s (+21..+33%), and the velocity error grows
 * from 1.5% of U at t = 0.2 s to 2.5% at 0.3 s and 15% at 0.6 s (2.01% averaged over 0.2-0.3 s;
 * the same at dx = 0.002). With Wendland C2 the mean pressure stays within 206 Pa up to 0.4 s.
 *
 * Measured: the mean vx of the particles with 0.2 < x < 0.3 m in z-bins of dx, averaged over 11
 * instants t = 0.20, 0.21, ..., 0.30 s, against the mean of u(z_i) over the same samples; the
 * pressure gradient from a least-squares line p(x) of the particles at mid-depth
 * (0.02 < z < 0.03 m, 0.15 < x < 0.35 m) over the same instants. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>

#include "mixsph.h"

#define DX 0.0025  /* [m] */
#define H 0.05     /* channel height [m] */
#define U 0.01     /* lid speed [m/s] */
#define MU 10.0    /* [Pa s] */
#define NBIN 20    /* H / DX */
#define X0 0.2     /* measuring window [m] */
#define X1 0.3
#define N_TIMES 11 /* t = 0.20 ... 0.30 s */
#define CHANNEL_KERNEL "wendland_c2"

static const char *const CASE_TEXT =
    "{\n"
    "  \"name\": \"lid_driven_channel\",\n"
    "  \"gravity\": 0.0,\n"
    "  \"numerics\": { \"dx\": 0.0025, \"t_end\": 0.3, \"background_pressure\": 200.0, \"kernel\": \"" CHANNEL_KERNEL "\" },\n"
    "  \"media\": { \"oil\": { \"type\": \"fluid\", \"rho\": 1000.0, \"c\": 10.0, \"mu\": 10.0, \"alpha_m\": 0.0 } },\n"
    "  \"bodies\": { \"oil\": { \"medium\": \"oil\", \"polygon\": [[0.0, 0.0], [0.5, 0.0], [0.5, 0.05], [0.0, 0.05]] } },\n"
    "  \"walls\": {\n"
    "    \"box\": { \"polyline\": [[0.0, 0.05], [0.0, 0.0], [0.5, 0.0], [0.5, 0.05]], \"fluid_side\": \"left\", \"slip\": \"no-slip\" },\n"
    "    \"lid\": { \"polyline\": [[-0.1, 0.05], [0.6, 0.05]], \"fluid_side\": \"right\", \"slip\": \"no-slip\", \"motion\": \"slide\" }\n"
    "  },\n"
    "  \"motions\": { \"slide\": { \"t\": [0.0], \"vx\": [0.01], \"vz\": [0.0] } },\n"
    "  \"domain\": { \"x_min\": -0.15, \"x_max\": 0.7, \"z_min\": -0.02, \"z_max\": 0.08 }\n"
    "}\n";

static double u_exact(double z)
{
    const double eta = z / H;
    return U * eta * (3.0 * eta - 2.0);
}

static void test_lid_driven_channel(void **state)
{
    (void)state;
    mixsph_sim *s = NULL;
    char err[512] = "";
    mixsph_status st = mixsph_sim_create_from_text(CASE_TEXT, "lid_driven_channel.json", NULL, 0, &s, err, sizeof err);
    if (st != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 2), MIXSPH_OK);
    assert_int_equal(mixsph_sim_particles(s), 200 * NBIN); /* the case is the one described above */

    double su[NBIN] = {0}, sa[NBIN] = {0}, sz[NBIN] = {0};
    long cnt[NBIN] = {0};
    double fx = 0, fp = 0, fxx = 0, fxp = 0; /* least-squares sums of p(x) at mid-depth */
    long fn = 0;
    double vmax = 0.0;
    for (int k = 0; k < N_TIMES; k++) {
        st = mixsph_sim_advance_to(s, 0.2 + 0.01 * k);
        if (st != MIXSPH_OK) print_error("%s\n", mixsph_sim_last_error(s));
        assert_int_equal(st, MIXSPH_OK);
        mixsph_particles_view v;
        assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
        for (size_t i = 0; i < v.n; i++) {
            if (v.state[i] == MIXSPH_STATE_WALL) continue;
            assert_int_equal(v.state[i], MIXSPH_STATE_MOBILE); /* none lost */
            vmax = fmax(vmax, hypot(v.vx[i], v.vz[i]));
            if (v.x[i] > X0 && v.x[i] < X1) {
                int b = (int)floor(v.z[i] / DX);
                assert_true(b >= 0 && b < NBIN); /* no particle crosses the floor or the lid */
                su[b] += v.vx[i];
                sa[b] += u_exact(v.z[i]);
                sz[b] += v.z[i];
                cnt[b]++;
            }
            if (v.z[i] > 0.02 && v.z[i] < 0.03 && v.x[i] > 0.15 && v.x[i] < 0.35) {
                fx += v.x[i];
                fp += v.p[i];
                fxx += v.x[i] * v.x[i];
                fxp += v.x[i] * v.p[i];
                fn++;
            }
        }
    }
    print_message("lid-driven channel, " CHANNEL_KERNEL " kernel, dx = %g m, %llu steps to t = %.4f s (dt = %.3g s), max speed %.4f m/s\n", DX,
                  (unsigned long long)mixsph_sim_steps(s), mixsph_sim_time(s), mixsph_sim_dt(s), vmax);
    print_message("   z [m]     samples   u_sph [m/s]   u_exact [m/s]   (u_sph - u_exact)/U\n");
    double worst = 0.0, flux = 0.0;
    for (int b = 0; b < NBIN; b++) {
        assert_true(cnt[b] > 0);
        const double us = su[b] / cnt[b], ua = sa[b] / cnt[b], e = (us - ua) / U;
        print_message("  %.5f   %6ld    %+.6f     %+.6f        %+.4f\n", sz[b] / cnt[b], cnt[b], us, ua, e);
        worst = fmax(worst, fabs(e));
        flux += us * DX;
    }
    const double grad = (fn * fxp - fx * fp) / (fn * fxx - fx * fx);
    const double grad_ref = 6.0 * MU * U / (H * H);
    print_message("largest |u_sph - u_exact| = %.2f%% of U; net flux %+.3e m2/s (U H = %.1e)\n", 100.0 * worst, flux, U * H);
    print_message("dp/dx at mid-depth = %.1f Pa/m (%ld samples), 6 mu U / H^2 = %.1f Pa/m (%+.2f%%)\n", grad, fn, grad_ref,
                  100.0 * (grad - grad_ref) / grad_ref);
    /* reference: u(z) = U eta (3 eta - 2) (header); tolerance 2% of U (issue: "analytical viscous
     * flow within 2%"), on the bin means over the 11 instants */
    assert_true(worst <= 0.02);
    /* reference: dp/dx = 6 mu U / H^2 = 240 Pa/m; tolerance 5% (issue) */
    assert_true(fabs(grad - grad_ref) <= 0.05 * grad_ref);
    mixsph_sim_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lid_driven_channel),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
