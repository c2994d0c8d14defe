/* test_implicit_flows.c - analytical viscous flows run with the implicit viscous step
 * (numerics.viscosity = "implicit", viscous.h; docs/numerics.md) at time steps many times the
 * explicit viscous limit dt_visc = cfl_visc 2 h^2 rho / mu.
 *
 * The flows are parallel shear flows between two plates H = 0.05 m apart (20 particles at
 * dx = 0.0025 m, h = 1.3 dx), rho = 1000 kg/m3, no gravity. The channel is L = 0.4 m long and
 * closed at its ends (the code has no periodic boundary), so the flow is measured in a window
 * 0.18 < x < 0.22 m in its middle, before anything from the ends can arrive there: pressure
 * signals travel at most at the sound speed c = 10 m/s, i.e. 0.16 m in 0.016 s, and every flow
 * here is measured before t = 0.0125 s. Within that window and time the flow is the one of an
 * infinite channel.
 *
 * 1. Couette start-up: fluid at rest, the upper plate set moving at U at t = 0. With
 *    eta = z / H and tau1 = H^2 / (pi^2 nu) (e.g. Batchelor, An Introduction to Fluid Dynamics,
 *    section 4.3),
 *        u(z, t) = U eta + sum_{n>=1} 2 U (-1)^n / (n pi) sin(n pi eta) exp(-n^2 t / tau1).
 * 2. Poiseuille start-up: fluid at rest between fixed plates, a uniform body force f along x from
 *    t = 0; it tends to the Poiseuille profile u_s = f H^2 / (2 nu) eta (1 - eta):
 *        u(z, t) = u_s(z) - sum_{n odd} 4 f H^2 / (nu n^3 pi^3) sin(n pi eta) exp(-n^2 t / tau1).
 *    The code's gravity acts along -z only, so the body force is made by the equivalence of
 *    frames: the whole closed channel (floor, ends, lid) is accelerated at -f from rest, and the
 *    fluid velocity relative to it, vx + f t, is the flow of fixed plates under a body force f.
 * 3. Two-layer Couette: two fluids of viscosities mu and 1000 mu in layers of H / 2 each (the
 *    stiff one on top), the lid at U; the steady profile is linear in each layer with the same
 *    shear stress tau = U / (H/2 (1/mu_soft + 1/mu_stiff)) in both. Measured at t = 5 and 6 tau_soft,
 *    tau_soft = (H/2)^2 / (pi^2 nu_soft), when the start-up has decayed to e^-5 (0.4 % of U).
 *
 * Norm: the largest over the z-bins of width dx (20 bins) and over the sampling instants (for the
 * Couette start-up those from tau1 on; the earlier ones are a known failure, test_couette_early) of
 * |mean over the window's particles of (u_sph - u_exact(z_i, t))| / scale, with scale U for the
 * Couette flows and the steady centre-line speed f H^2 / (8 nu) for the Poiseuille flow.
 * Tolerance 2 % of the scale (the accuracy the issue of the implicit step asks). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "known_failure.h"
#include "sim.h"

#define PI 3.14159265358979323846
#define DX 0.0025   /* [m] */
#define H 0.05      /* plate distance [m] */
#define L 0.4       /* channel length [m] */
#define RHO 1000.0  /* [kg/m3] */
#define U 0.001     /* lid speed of the Couette flows [m/s] */
#define NBIN 20     /* H / DX */
#define X_LO 0.18   /* measuring window [m] */
#define X_HI 0.22
#define MAX_SAMPLES 6
#define SERIES_TERMS 400

/* The case: a channel of two layers (soft below z_interface, stiff above; one medium when they
 * are equal), the lid moving with motion "lid" and the floor and ends with motion "box". */
static const char *const CHANNEL =
    "{ \"name\": \"implicit_flow\", \"gravity\": 0.0,\n"
    "  \"numerics\": { \"dx\": 0.0025, \"t_end\": 1.0, \"background_pressure\": 200.0, \"viscosity\": \"implicit\","
    " \"viscous_tolerance\": 1e-8, \"viscous_max_iterations\": 2000 },\n"
    "  \"media\": { \"soft\": { \"type\": \"fluid\", \"rho\": 1000.0, \"c\": 10.0, \"mu\": %.17g, \"alpha_m\": 0.0 },\n"
    "             \"stiff\": { \"type\": \"fluid\", \"rho\": 1000.0, \"c\": 10.0, \"mu\": %.17g, \"alpha_m\": 0.0 } },\n"
    "  \"bodies\": { \"lower\": { \"medium\": \"soft\", \"polygon\": [[0.0, 0.0], [0.4, 0.0], [0.4, %.17g], [0.0, %.17g]] },\n"
    "              \"upper\": { \"medium\": \"%s\", \"polygon\": [[0.0, %.17g], [0.4, %.17g], [0.4, 0.05], [0.0, 0.05]] } },\n"
    "  \"walls\": { \"box\": { \"polyline\": [[0.0, 0.05], [0.0, 0.0], [0.4, 0.0], [0.4, 0.05]], \"fluid_side\": \"left\","
    " \"motion\": \"box\" },\n"
    "    \"lid\": { \"polyline\": [[-0.1, 0.05], [0.5, 0.05]], \"fluid_side\": \"right\", \"motion\": \"lid\" } },\n"
    "  \"motions\": { \"lid\": { \"t\": [0.0, 1.0], \"vx\": [%.17g, %.17g], \"vz\": [0.0, 0.0] },\n"
    "               \"box\": { \"t\": [0.0, 1.0], \"vx\": [0.0, %.17g], \"vz\": [0.0, 0.0] } },\n"
    "  \"monitors\": { \"lid_work\": { \"type\": \"wall_work\", \"wall\": \"lid\" } },\n"
    "  \"domain\": { \"x_min\": -0.15, \"x_max\": 0.55, \"z_min\": -0.02, \"z_max\": 0.08 } }\n";

/* One flow: its media, the plates' motions, its exact solution and when to compare. */
struct flow {
    const char *name;
    double mu_soft, mu_stiff; /* [Pa s] */
    double z_interface;       /* top of the soft layer [m] (H: one layer) */
    double lid_vx;            /* lid speed [m/s] relative to the box */
    double frame_accel;       /* f [m/s2]: box and lid accelerate at -f */
    double scale;             /* of the norm [m/s] */
    double (*exact)(const struct flow *f, double z, double t);
    int n_samples;
    double t_sample[MAX_SAMPLES]; /* [s] */
};

static double tau1(double mu, double height) { return height * height * RHO / (PI * PI * mu); }

static double couette_startup(const struct flow *f, double z, double t)
{
    const double eta = z / H, s = t / tau1(f->mu_soft, H);
    double u = U * eta;
    for (int n = 1; n <= SERIES_TERMS; n++)
        u += 2.0 * U * (n % 2 ? -1.0 : 1.0) / (n * PI) * sin(n * PI * eta) * exp(-(double)n * n * s);
    return u;
}

static double poiseuille_startup(const struct flow *f, double z, double t)
{
    const double nu = f->mu_soft / RHO, eta = z / H, s = t / tau1(f->mu_soft, H);
    double u = f->frame_accel * H * H / (2.0 * nu) * eta * (1.0 - eta);
    for (int n = 1; n <= SERIES_TERMS; n += 2)
        u -= 4.0 * f->frame_accel * H * H / (nu * n * n * n * PI * PI * PI) * sin(n * PI * eta) *
             exp(-(double)n * n * s);
    return u;
}

static double two_layer_couette(const struct flow *f, double z, double t)
{
    (void)t;
    const double zi = f->z_interface;
    const double stress = U / (zi / f->mu_soft + (H - zi) / f->mu_stiff);
    return z <= zi ? stress * z / f->mu_soft : stress * zi / f->mu_soft + stress * (z - zi) / f->mu_stiff;
}

static mixsph_sim *create_with(const struct flow *f, const mixsph_override *ov, size_t n_ov)
{
    char text[4096];
    const int layered = f->z_interface < H;
    const double zi = layered ? f->z_interface : 0.5 * H; /* one medium: two bodies of the same */
    const double end = 1.0;                              /* the motions' table end [s] */
    const double lid0 = f->lid_vx, lid1 = f->lid_vx - f->frame_accel * end;
    snprintf(text, sizeof text, CHANNEL, f->mu_soft, f->mu_stiff, zi, zi, layered ? "stiff" : "soft", zi, zi, lid0,
             lid1, -f->frame_accel * end);
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_status st = mixsph_sim_create_from_text(text, "implicit_flow.json", ov, n_ov, &s, err, sizeof err);
    if (st != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK); /* ctest -j runs tests side by side */
    return s;
}

static mixsph_sim *create(const struct flow *f) { return create_with(f, NULL, 0); }

/* The largest bin error / scale at the current time. */
static double profile_error(const struct flow *f, const mixsph_sim *s)
{
    const struct particles *P = &s->phys.P;
    const double t = mixsph_sim_time(s), frame_vx = -f->frame_accel * t;
    double diff[NBIN] = {0};
    long cnt[NBIN] = {0};
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] == MIXSPH_STATE_WALL) continue;
        assert_int_equal(P->state[i], MIXSPH_STATE_MOBILE); /* none lost */
        if (P->pos[0][i] < X_LO || P->pos[0][i] > X_HI) continue;
        const int b = (int)floor(P->pos[DIM_UP][i] / DX);
        assert_true(b >= 0 && b < NBIN);
        diff[b] += (P->vel[0][i] - frame_vx) - f->exact(f, P->pos[DIM_UP][i], t);
        cnt[b]++;
    }
    double worst = 0.0;
    for (int b = 0; b < NBIN; b++) {
        assert_true(cnt[b] > 0);
        worst = fmax(worst, fabs(diff[b] / cnt[b]) / f->scale);
    }
    return worst;
}

/* Run the flow through its sampling instants; the largest error / scale over those in
 * [t_lo, t_hi] tau1 (all are run and printed). The time step must be at least ratio_min times the
 * explicit viscous limit of the stiffest medium. */
static double flow_error_between(const struct flow *f, double ratio_min, double t_lo, double t_hi)
{
    mixsph_sim *s = create(f);
    double worst = 0.0;
    uint64_t iterations = 0;
    int most = 0;
    for (int k = 0; k < f->n_samples; k++) {
        while (mixsph_sim_time(s) < f->t_sample[k]) {
            const mixsph_status st = mixsph_sim_step(s);
            if (st != MIXSPH_OK) print_error("%s\n", mixsph_sim_last_error(s));
            assert_int_equal(st, MIXSPH_OK);
            iterations += (uint64_t)s->work.viscous_last.iterations;
            if (s->work.viscous_last.iterations > most) most = s->work.viscous_last.iterations;
        }
        const double e = profile_error(f, s);
        const double in_tau1 = mixsph_sim_time(s) / tau1(f->mu_soft, H);
        const int counted = f->t_sample[k] >= t_lo * tau1(f->mu_soft, H) && f->t_sample[k] <= t_hi * tau1(f->mu_soft, H);
        print_message("%s: t = %.3g s = %.2f tau1, error %.2f%% of the scale%s\n", f->name, mixsph_sim_time(s),
                      in_tau1, 100.0 * e, counted ? "" : " (not in this test's norm)");
        if (counted) worst = fmax(worst, e);
    }
    const double mu_max = fmax(f->mu_soft, f->z_interface < H ? f->mu_stiff : 0.0);
    const double dt_visc = s->cfg.cfl_visc * 2.0 * s->phys.h * s->phys.h * RHO / mu_max;
    const double ratio = s->phys.dt / dt_visc;
    print_message("%s: dt = %.3g s = %.1f x the explicit viscous limit = %.3f tau1, %.1f solver iterations per step "
                  "(at most %d); largest error %.2f%%\n",
                  f->name, s->phys.dt, ratio, s->phys.dt / tau1(f->mu_soft, H),
                  (double)iterations / (double)mixsph_sim_steps(s), most, 100.0 * worst);
    assert_true(ratio >= ratio_min); /* the time step the test is about */
    mixsph_sim_destroy(s);
    return worst;
}

static double flow_error(const struct flow *f, double ratio_min) { return flow_error_between(f, ratio_min, 0.0, INFINITY); }

/* The Couette start-up at viscosity mu, sampled at 0.25, 0.5, 1, 2, 4 tau1. */
static struct flow couette_flow(double mu)
{
    const double t1 = tau1(mu, H);
    return (struct flow){.name = "Couette start-up", .mu_soft = mu, .mu_stiff = mu, .z_interface = H, .lid_vx = U,
                         .scale = U, .exact = couette_startup, .n_samples = 5,
                         .t_sample = {0.25 * t1, 0.5 * t1, t1, 2.0 * t1, 4.0 * t1}};
}

/* The Poiseuille start-up at viscosity mu with a centre-line speed of 1 mm/s, sampled at 0.25,
 * 0.5, 1, 2, 4, 8 tau1 (the last within 0.04 % of the steady profile). */
static struct flow poiseuille_flow(double mu)
{
    const double t1 = tau1(mu, H), nu = mu / RHO, u_centre = 0.001;
    return (struct flow){.name = "Poiseuille start-up", .mu_soft = mu, .mu_stiff = mu, .z_interface = H,
                         .frame_accel = 8.0 * nu * u_centre / (H * H), .scale = u_centre,
                         .exact = poiseuille_startup, .n_samples = 6,
                         .t_sample = {0.25 * t1, 0.5 * t1, t1, 2.0 * t1, 4.0 * t1, 8.0 * t1}};
}

/* mu = 330 and 820 Pa s make the acoustic step (cfl 0.1, h / c) 20 and 50 times dt_visc. The
 * Couette start-up is checked from t = tau1 on here; before that see test_couette_early. */
static void test_couette_20x(void **state)
{
    (void)state;
    const struct flow f = couette_flow(330.0);
    /* reference: the series solution (header); tolerance 2 % of U */
    assert_true(flow_error_between(&f, 20.0, 1.0, INFINITY) <= 0.02);
}

static void test_couette_50x(void **state)
{
    (void)state;
    const struct flow f = couette_flow(820.0);
    /* reference: the series solution (header); tolerance 2 % of U */
    assert_true(flow_error_between(&f, 50.0, 1.0, INFINITY) <= 0.02);
}

/* The Couette start-up before tau1 (0.25 and 0.5 tau1: 3 and 6 steps at 20x, 2 and 3 at 50x)
 * does not meet 2 % (measured 3.3 % and 4.9 % of U at the first instant): the impulsive start
 * excites every mode, and the viscous step's SDIRK2 (viscous.c), second order, still carries
 * them a few % off over its first steps. A known failure (known_failure.h), so that the
 * tolerance stays what the criterion asks. */
/* Today's band of test_couette_early: the largest error before tau1 [% of U], measured at 20x
 * 3.316102139 and at 50x 4.925835592, the same to 10 digits at 1 and 2 threads (GCC 12, -O3; the
 * flow is smooth, not sensitive to rounding). Margin 5 % of the value (0.17 and 0.25 % of U): far
 * above rounding, far below the distance to the criterion (1.3 and 2.9 % of U), so a change of
 * the scheme or the solver that moves the early error by a twentieth shows. */
#define COUETTE_EARLY_20X 3.3161
#define COUETTE_EARLY_50X 4.9258
#define COUETTE_EARLY_MARGIN 0.05
static void test_couette_early(void **state)
{
    (void)state;
    const struct flow f20 = couette_flow(330.0), f50 = couette_flow(820.0);
    const double e20 = flow_error_between(&f20, 20.0, 0.0, 0.99), e50 = flow_error_between(&f50, 50.0, 0.0, 0.99);
    /* reference: the series solution (header); tolerance 2 % of U, both flows. Not met: today's
     * bands are the measured errors [% of U], COUETTE_EARLY_20X and _50X, +- COUETTE_EARLY_MARGIN */
    const int met = e20 <= 0.02 && e50 <= 0.02;
    known_failure_check("couette_early 20x", met, 100.0 * e20, COUETTE_EARLY_20X * (1.0 - COUETTE_EARLY_MARGIN),
                        COUETTE_EARLY_20X * (1.0 + COUETTE_EARLY_MARGIN));
    known_failure_check("couette_early 50x", met, 100.0 * e50, COUETTE_EARLY_50X * (1.0 - COUETTE_EARLY_MARGIN),
                        COUETTE_EARLY_50X * (1.0 + COUETTE_EARLY_MARGIN));
}

static void test_poiseuille_20x(void **state)
{
    (void)state;
    const struct flow f = poiseuille_flow(330.0);
    /* reference: the series solution (header); tolerance 2 % of the centre-line speed */
    assert_true(flow_error(&f, 20.0) <= 0.02);
}

static void test_poiseuille_50x(void **state)
{
    (void)state;
    const struct flow f = poiseuille_flow(820.0);
    /* reference: the series solution (header); tolerance 2 % of the centre-line speed */
    assert_true(flow_error(&f, 50.0) <= 0.02);
}

static void test_two_layer_couette(void **state)
{
    (void)state;
    const double mu = 33.0, t_soft = tau1(mu, 0.5 * H);
    const struct flow f = {.name = "two-layer Couette 1:1000", .mu_soft = mu, .mu_stiff = 1000.0 * mu,
                           .z_interface = 0.5 * H, .lid_vx = U, .scale = U, .exact = two_layer_couette,
                           .n_samples = 2, .t_sample = {5.0 * t_soft, 6.0 * t_soft}};
    /* reference: the steady two-layer profile (header); tolerance 2 % of U; the time step is at
     * least 20 times the explicit limit of the stiff layer */
    assert_true(flow_error(&f, 20.0) <= 0.02);
}

/* `test_implicit_flows` runs the tests the scheme meets; `test_implicit_flows known_failure
 * couette_early` the criterion it does not meet yet: it passes while the criterion is not met and
 * the errors stay in today's band (known_failure.h). */
/* The lid's work on the fluid in the Couette start-up (monitor wall_work) under the implicit
 * scheme, whose viscous force is solved outside the momentum pass, against the explicit scheme
 * (1/20 of the step), where it is in it. Context, not a reference: the series solution of the
 * infinite channel, the shear stress on the lid mu du/dz(H, t) = mu U / H (1 + 2 sum_n
 * exp(-n^2 t / tau1)) over its wetted length L and time,
 *     W(t) = mu U^2 L / H (t + 2 tau1 sum_n (1 - exp(-n^2 t / tau1)) / n^2),
 * a lower bound here: near the closed ends the return flow the ends force adds shear. */
static void test_lid_work(void **state)
{
    (void)state;
    const double mu = 330.0;
    const struct flow f = couette_flow(mu);
    const double t1 = tau1(mu, H);
    double work[2], series[2];
    for (int explicit_scheme = 0; explicit_scheme <= 1; explicit_scheme++) {
        const mixsph_override ov = {.key = "numerics.viscosity", .value = 0.0};
        mixsph_sim *s = create_with(&f, explicit_scheme ? &ov : NULL, explicit_scheme ? 1 : 0);
        const long k = mixsph_sim_output_find(s, "lid_work");
        assert_true(k >= 0);
        assert_int_equal(mixsph_sim_advance_to(s, 2.0 * t1), MIXSPH_OK);
        const double t = mixsph_sim_time(s);
        double w = t;
        for (int n = 1; n <= SERIES_TERMS; n++) w += 2.0 * t1 * (1.0 - exp(-(double)n * n * t / t1)) / ((double)n * n);
        series[explicit_scheme] = w * mu * U * U * L / H;
        work[explicit_scheme] = mixsph_sim_output_value(s, (size_t)k);
        print_message("lid work to %.3g s (%.2f tau1), %s scheme (%llu steps): %.5g J/m, series %.5g J/m (%+.2f %%)\n", t,
                      t / t1, explicit_scheme ? "explicit" : "implicit", (unsigned long long)mixsph_sim_steps(s),
                      work[explicit_scheme], series[explicit_scheme], 100.0 * (work[explicit_scheme] / series[explicit_scheme] - 1.0));
        mixsph_sim_destroy(s);
        /* at least the infinite channel's (tolerance 2 %: the start-up's few % of U, test_couette_early) */
        assert_true(work[explicit_scheme] >= 0.98 * series[explicit_scheme]);
    }
    /* the two schemes' work per unit of their own series within 5 % (measured 4.7 %: the implicit
     * step's start-up error before tau1, test_couette_early); without the solved viscous force
     * on the lid the implicit work would be 0 */
    assert_true(fabs((work[0] / series[0]) / (work[1] / series[1]) - 1.0) <= 0.05);
}

int main(int argc, char **argv)
{
    if (argc > 2 && strcmp(argv[1], "known_failure") == 0) {
        if (strcmp(argv[2], "couette_early") == 0) {
            const struct CMUnitTest known[] = {cmocka_unit_test(test_couette_early)};
            return cmocka_run_group_tests(known, NULL, NULL);
        }
        fprintf(stderr, "test_implicit_flows: unknown known_failure '%s' (couette_early)\n", argv[2]);
        return 2;
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lid_work),
        cmocka_unit_test(test_couette_20x),
        cmocka_unit_test(test_couette_50x),
        cmocka_unit_test(test_poiseuille_20x),
        cmocka_unit_test(test_poiseuille_50x),
        cmocka_unit_test(test_two_layer_couette),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
