/* test_viscous.c - the laminar viscous term (forces.c: Morris et al. 1997 Laplacian with the
 * pairwise harmonic-mean viscosity; docs/model.md section 7: a check against an analytical
 * viscous flow) and no-slip moving walls (docs/model.md section 8), on a lid-driven long closed cavity.
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
 * Kernels. The channel is run three times (docs/model.md section 1):
 *   (a) Wendland C2 at h = 1.3 dx and (b) the default cubic spline at h = 1.5 dx: both must meet
 *       the analytical flow within 2% of U and dp/dx within 5% (measured: (a) 1.49% of U, dp/dx
 *       -1.2%; (b) 0.75% of U, dp/dx +2.5%; mean density within 6e-5 rho0 of rho0 in both);
 *   (c) the cubic spline at h = 1.3 dx (the smoothing length of the bundled cases) does not
 *       (measured: dp/dx 291-319 Pa/m over 0.2-0.3 s, +21..+33%; velocity error 1.5% of U at
 *       t = 0.2 s, 2.5% at 0.3 s, 15% at 0.6 s, 2.01% on the means over 0.2-0.3 s; the same at
 *       dx = 0.002).
 * Why: the zeroth-order error of the symmetric pressure gradient, times the absolute pressure.
 * The momentum equation's -1/rho_i sum_j V_j (p_i + p_j) grad_i W_ij (forces.c) contains
 * -2 p_i / rho_i sum_j V_j grad_i W_ij, which vanishes on the initial square lattice but not on
 * a lattice deformed by a curved velocity profile: with u'' != 0 the rows above and below a
 * particle are displaced unequally (by u' t z + u'' t z^2 / 2). Summed on such a lattice
 * (x_j = x_i + I dx + u' t z + u'' t z^2 / 2, z = J dx, u'' = 6 U / H^2), sum_j V_j F (x_i - x_j)
 * at mid-depth is -0.16, -0.20, -0.23 1/m at t = 0.2, 0.25, 0.3 s for the cubic spline at
 * h = 1.3 dx, -0.033..-0.041 at 1.5 dx and within +-0.005 for Wendland C2 at 1.3 dx: with the
 * 200 Pa background pressure of the case a spurious force equivalent to a pressure gradient of
 * 65, 80, 94 Pa/m, which the pressure field balances: dp/dx = 240 + that, i.e. 305-334 Pa/m
 * predicted against 291-319 Pa/m measured (cubic at 1.5 dx: 13-16 Pa/m predicted, +6 Pa/m
 * measured). Confirmed by changing only the background pressure (cubic, 1.3 dx, 0.2-0.3 s):
 * 50 Pa: dp/dx 255-270 Pa/m, velocity error 0.8-1.0% of U; 200 Pa: 291-319 Pa/m, 1.5-2.5%;
 * 1000 Pa: 463-571 Pa/m, 6.7-8.5%. Not the resolution (the deformation does not depend on dx),
 * not the Morris viscous operator (its lattice coefficient -sum_j V_j F z_ij^2 r^2/(r^2 + eta^2)
 * is 1.000 for the cubic spline at 1.3 dx, 0.963 for Wendland C2, within 1% of that up to a
 * shear strain of 0.3 for both; the eta term takes the cubic's 1.0105 to 1.000), not the eta
 * term, not the walls (the same walls pass with the other two kernels), and not cured by a
 * density diffusion term (delta-SPH with delta = 0.1 tried on a scratch build: no change) nor by
 * the partial pressure smoothing (theta_P = 0.1: no change).
 * A side effect: the continuity density of the cubic spline at 1.3 dx also
 * drifts in shear. The kernel sum of a square lattice sheared by a strain gamma
 * (x -> x + gamma z) is not invariant: sum_j dx^2 W(r_ij) / (its value at gamma = 0) - 1 =
 * C gamma^2, with C = 0.030 (cubic spline, h = 1.3 dx), 0.0047 (cubic, 1.5 dx), 0.0018 (cubic,
 * 2 dx), -0.001 (Wendland C2, 1.3 dx) at gamma = 0.2, and the continuity equation integrates
 * d/dt of it. In the channel gamma = (U t / H)(6 eta - 2), so the mean density rises by
 * C <gamma^2> = 4 C (U t / H)^2 (4.3e-4 rho0 at t = 0.3 s: the mean pressure climbs from 200 Pa
 * to 240 Pa at 0.3 s and 313 Pa at 0.6 s, which enlarges the error above).
 * Remedies belong to the operator (lib/src, not changed here): a pressure gradient that is exact
 * for a uniform pressure, e.g. -1/rho_i sum_j V_j (p_j - p_i) grad_i W_ij, or the symmetric form
 * with the kernel gradient corrected by L_i^-1 (Bonet & Lok 1999; the code already builds L_i for
 * the grains' strain rate), or particle shifting that keeps the lattice regular; or, in a case,
 * h >= 1.5 dx with the cubic spline, Wendland C2, or a background pressure no larger than needed.
 * (c) runs the cubic spline at 1.3 dx with the case's 200 Pa and with 1000 Pa of background
 * pressure and asserts both mechanisms: the excess of dp/dx in proportion to the mean pressure,
 * and the density drift; it fails when they change, which an operator change of this kind would
 * show (then the cubic spline at 1.3 dx belongs to (a) and (b)).
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
#define RHO0 1000.0 /* [kg/m3] */

static const char *const CASE_FMT =
    "{\n"
    "  \"name\": \"lid_driven_channel\",\n"
    "  \"gravity\": 0.0,\n"
    "  \"numerics\": { \"dx\": 0.0025, \"h_over_dx\": %.2f, \"t_end\": 0.3, \"background_pressure\": %.1f, \"kernel\": \"%s\" },\n"
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

struct channel_result {
    double worst;    /* largest |u_sph - u_exact| / U over the bins (means over the instants) */
    double grad;     /* dp/dx at mid-depth [Pa/m] */
    double drho[N_TIMES]; /* mean density of the oil minus rho0, over rho0, at each instant */
    double p_mean;   /* mean pressure of the oil over the instants [Pa] */
};

/* Run the channel with the given kernel, h/dx and background pressure [Pa] to t = 0.3 s and
 * measure (header). */
static void run_channel(const char *kernel, double h_over_dx, double p_b, struct channel_result *res)
{
    char text[2048];
    snprintf(text, sizeof text, CASE_FMT, h_over_dx, p_b, kernel);
    mixsph_sim *s = NULL;
    char err[512] = "";
    mixsph_status st = mixsph_sim_create_from_text(text, "lid_driven_channel.json", NULL, 0, &s, err, sizeof err);
    if (st != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK); /* ctest -j runs tests side by side */
    assert_int_equal(mixsph_sim_particles(s), 200 * NBIN); /* the case is the one described above */

    double su[NBIN] = {0}, sa[NBIN] = {0}, sz[NBIN] = {0};
    long cnt[NBIN] = {0};
    double fx = 0, fp = 0, fxx = 0, fxp = 0; /* least-squares sums of p(x) at mid-depth */
    long fn = 0;
    double vmax = 0.0, sp_all = 0.0;
    long n_all = 0;
    for (int k = 0; k < N_TIMES; k++) {
        st = mixsph_sim_advance_to(s, 0.2 + 0.01 * k);
        if (st != MIXSPH_OK) print_error("%s\n", mixsph_sim_last_error(s));
        assert_int_equal(st, MIXSPH_OK);
        mixsph_particles_view v;
        assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
        double srho = 0.0;
        long nf = 0;
        for (size_t i = 0; i < v.n; i++) {
            if (v.state[i] == MIXSPH_STATE_WALL) continue;
            assert_int_equal(v.state[i], MIXSPH_STATE_MOBILE); /* none lost */
            vmax = fmax(vmax, hypot(v.vel[0][i], v.vel[v.dim - 1][i]));
            srho += v.rho[i];
            nf++;
            sp_all += v.p[i];
            n_all++;
            if (v.pos[0][i] > X0 && v.pos[0][i] < X1) {
                int b = (int)floor(v.pos[v.dim - 1][i] / DX);
                assert_true(b >= 0 && b < NBIN); /* no particle crosses the floor or the lid */
                su[b] += v.vel[0][i];
                sa[b] += u_exact(v.pos[v.dim - 1][i]);
                sz[b] += v.pos[v.dim - 1][i];
                cnt[b]++;
            }
            if (v.pos[v.dim - 1][i] > 0.02 && v.pos[v.dim - 1][i] < 0.03 && v.pos[0][i] > 0.15 && v.pos[0][i] < 0.35) {
                fx += v.pos[0][i];
                fp += v.p[i];
                fxx += v.pos[0][i] * v.pos[0][i];
                fxp += v.pos[0][i] * v.p[i];
                fn++;
            }
        }
        res->drho[k] = srho / nf / RHO0 - 1.0;
    }
    res->p_mean = sp_all / n_all;
    print_message("lid-driven channel, %s kernel, h = %.2f dx, background pressure %g Pa, dx = %g m, %llu steps to t = %.4f s (dt = %.3g s), "
                  "max speed %.4f m/s\n",
                  kernel, h_over_dx, p_b, DX, (unsigned long long)mixsph_sim_steps(s), mixsph_sim_time(s), mixsph_sim_dt(s), vmax);
    print_message("   z [m]     samples   u_sph [m/s]   u_exact [m/s]   (u_sph - u_exact)/U\n");
    double worst = 0.0, flux = 0.0;
    for (int b = 0; b < NBIN; b++) {
        assert_true(cnt[b] > 0);
        const double us = su[b] / cnt[b], ua = sa[b] / cnt[b], e = (us - ua) / U;
        print_message("  %.5f   %6ld    %+.6f     %+.6f        %+.4f\n", sz[b] / cnt[b], cnt[b], us, ua, e);
        worst = fmax(worst, fabs(e));
        flux += us * DX;
    }
    res->worst = worst;
    res->grad = (fn * fxp - fx * fp) / (fn * fxx - fx * fx);
    const double grad_ref = 6.0 * MU * U / (H * H);
    print_message("largest |u_sph - u_exact| = %.2f%% of U; net flux %+.3e m2/s (U H = %.1e)\n", 100.0 * worst, flux, U * H);
    print_message("dp/dx at mid-depth = %.1f Pa/m (%ld samples), 6 mu U / H^2 = %.1f Pa/m (%+.2f%%)\n", res->grad, fn,
                  grad_ref, 100.0 * (res->grad - grad_ref) / grad_ref);
    print_message("mean density - rho0: %+.3e rho0 at t = 0.2 s, %+.3e rho0 at t = 0.3 s; mean pressure %.1f Pa\n",
                  res->drho[0], res->drho[N_TIMES - 1], res->p_mean);
    mixsph_sim_destroy(s);
}

/* The accuracy assertions of (a) and (b). */
static void assert_accurate(const struct channel_result *r)
{
    /* reference: u(z) = U eta (3 eta - 2) (header); tolerance 2% of U (issue: "analytical viscous
     * flow within 2%"), on the bin means over the 11 instants */
    assert_true(r->worst <= 0.02);
    /* reference: dp/dx = 6 mu U / H^2 = 240 Pa/m; tolerance 5% (issue) */
    const double grad_ref = 6.0 * MU * U / (H * H);
    assert_true(fabs(r->grad - grad_ref) <= 0.05 * grad_ref);
}

/* (a) Wendland C2 at h = 1.3 dx. */
static void test_channel_wendland(void **state)
{
    (void)state;
    struct channel_result r;
    run_channel("wendland_c2", 1.3, 200.0, &r);
    assert_accurate(&r);
}

/* (b) the default kernel, the cubic spline, at h = 1.5 dx. */
static void test_channel_cubic_h15(void **state)
{
    (void)state;
    struct channel_result r;
    run_channel("cubic_spline", 1.5, 200.0, &r);
    assert_accurate(&r);
}

/* (c) the cubic spline at h = 1.3 dx: the error grows with the absolute pressure, and the density
 * drifts with the shear of the lattice (header). */
static void test_channel_cubic_h13_mechanism(void **state)
{
    (void)state;
    struct channel_result r, r5;
    run_channel("cubic_spline", 1.3, 200.0, &r);
    run_channel("cubic_spline", 1.3, 1000.0, &r5);
    /* reference: the cause (header): the pressure gradient's zeroth-order error is proportional to
     * the absolute pressure, so the excess of dp/dx over 6 mu U / H^2 grows with the mean pressure:
     * (dp/dx - 240)_1000 / (dp/dx - 240)_200 = p_mean,1000 / p_mean,200 (background pressures
     * 1000 and 200 Pa); tolerance 25%: the deformation of the lattice, which sets the error, is
     * that of the flow, and the flow differs between the two runs by their velocity errors
     * (2% and 8% of U) */
    const double grad_ref = 6.0 * MU * U / (H * H);
    const double ratio = (r5.grad - grad_ref) / (r.grad - grad_ref), p_ratio = r5.p_mean / r.p_mean;
    print_message("dp/dx excess %.1f Pa/m (background 1000 Pa) over %.1f Pa/m (200 Pa) = %.2f; mean pressures %.1f / "
                  "%.1f Pa = %.2f\n",
                  r5.grad - grad_ref, r.grad - grad_ref, ratio, r5.p_mean, r.p_mean, p_ratio);
    assert_true(r.grad - grad_ref > 0.05 * grad_ref); /* the error (c) is about, beyond the 5% of (a), (b) */
    assert_true(fabs(ratio - p_ratio) <= 0.25 * p_ratio);
    /* reference: the mean continuity density rises as the kernel sum of the sheared lattice,
     * C <gamma^2> = 4 C (U t / H)^2 with C = 0.030 (header; 1.9e-4 at t = 0.2 s, 4.3e-4 at
     * 0.3 s); tolerance 25%: the prediction ignores the end regions (H from each end wall, 20% of
     * the oil, where the strain is not that of the parallel flow) and the start-up of the profile
     * (developed after about H^2 / (pi^2 nu) = 0.025 s, a strain deficit of up to 12%, 25% in
     * gamma^2, at t = 0.2 s). Fails if the drift changes: then the cubic spline at 1.3 dx may meet
     * the 2% of (a) and (b) and belongs there. */
    for (int k = 0; k < N_TIMES; k += N_TIMES - 1) {
        const double t = 0.2 + 0.01 * k, g = U * t / H;
        const double pred = 4.0 * 0.030 * g * g;
        print_message("t = %.2f s: mean density rise %.3e rho0, predicted 4 C (U t / H)^2 = %.3e (%+.1f%%)\n", t, r.drho[k],
                      pred, 100.0 * (r.drho[k] - pred) / pred);
        assert_true(fabs(r.drho[k] - pred) <= 0.25 * pred);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_channel_wendland),
        cmocka_unit_test(test_channel_cubic_h15),
        cmocka_unit_test(test_channel_cubic_h13_mechanism),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
