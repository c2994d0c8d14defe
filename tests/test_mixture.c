/* test_mixture.c - the granular phase of the mixture model (Manenti et al. 2018, Section 2.1;
 * docs/model.md sections 5-6): case reading of granular media (case.c), the regime of every grain
 * and the fixed/mobile transitions both ways, the pressure of the fixed grains, the pore
 * pressure of a saturated bed (mixture.c), and the time step bound of fixed grains (integrate.c).
 *
 * The regime tests drive the internals directly (sim.h): they impose a linear velocity field
 * u = (G z, 0) on every particle (grains and walls), run the continuity pass (which gives the
 * velocity gradient and its correction matrix) and mixture_update. The first-order-corrected
 * gradient reproduces a linear field exactly, so every grain has sqrt(II_D) = G/2 and
 *     mu_app = eps_f mu_f + sigma' sin(phi) / G
 * with sigma' = p - p_w from the particle's own pressure: the expected regime and viscosity of
 * each grain follow by hand (rheology.h is tested on its own in test_rheology.c). */
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
#include "sim_passes.h"

#define G_ACC 9.81   /* [m/s2] */
#define DX 0.01      /* [m] */
#define RHO_S 2650.0 /* grain density [kg/m3] */
#define K_S 4.24e6   /* grain bulk modulus [Pa]: c = sqrt(K_s / rho_s) = 40 m/s */
#define POR 0.35     /* porosity n */
#define PHI 35.0     /* [deg] */
#define MU_THR 320e3 /* [Pa s] Vajont values */
#define MU0 5e3      /* [Pa s] */
#define REL 1e-9     /* relative tolerance where the code and the test sum the same terms in another order */

/* A 0.4 x 0.1 m bed of medium "sand" in a box (walls on three sides), dx = 0.01: 400 grains. */
static const char *const CASE_FMT =
    "{\n"
    "  \"name\": \"granular_bed\",\n"
    "  \"gravity\": 9.81,\n"
    "  \"numerics\": { \"dx\": 0.01, \"t_end\": 1.0 },\n"
    "  \"media\": { %s },\n"
    "  \"bodies\": { \"bed\": { \"medium\": \"sand\", \"polygon\": [[0.0, 0.0], [0.4, 0.0], [0.4, 0.1], [0.0, 0.1]] } },\n"
    "  \"walls\": { \"box\": { \"polyline\": [[0.0, 0.3], [0.0, 0.0], [0.4, 0.0], [0.4, 0.3]], \"fluid_side\": \"left\" } },\n"
    "  \"domain\": { \"x_min\": -0.05, \"x_max\": 0.45, \"z_min\": -0.05, \"z_max\": 0.3 }\n"
    "}\n";

#define WATER "\"water\": { \"type\": \"fluid\", \"rho\": 1000.0, \"c\": 40.0, \"mu\": 1.0e-3 }"
#define DRY_SAND                                                                                                      \
    "\"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0, "         \
    "\"mu_thr\": 320e3, \"mu0\": 5e3 }"
#define WET_SAND                                                                                                      \
    "\"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0, "         \
    "\"saturated\": true, \"pore_fluid\": \"water\", \"mu_thr\": 320e3, \"mu0\": 5e3 }"

static mixsph_status create(const char *media, mixsph_sim **s, char *err, size_t err_len)
{
    char text[4096];
    snprintf(text, sizeof text, CASE_FMT, media);
    const mixsph_status st = mixsph_sim_create_from_text(text, "granular_bed.json", NULL, 0, s, err, err_len);
    if (st == MIXSPH_OK) mixsph_sim_set_threads(*s, 2);
    return st;
}

static mixsph_sim *create_ok(const char *media)
{
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_status st = create(media, &s, err, sizeof err);
    if (st != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    return s;
}

/* The case must be refused with a message naming `key`. */
static void expect_error(const char *media, const char *key)
{
    mixsph_sim *s = NULL;
    char err[512] = "";
    assert_int_equal(create(media, &s, err, sizeof err), MIXSPH_ERR_CASE);
    assert_null(s);
    print_message("  refused: %s\n", err);
    assert_non_null(strstr(err, key));
}

static int is_grain(const mixsph_sim *s, size_t i)
{
    return s->phys.P.state[i] != MIXSPH_STATE_WALL && s->cfg.media[s->phys.P.medium[i]].law == LAW_MIXTURE_PAPER;
}

static void assert_rel(double got, double want, double rel)
{
    if (!(fabs(got - want) <= rel * fabs(want))) {
        print_error("got %.17g, expected %.17g\n", got, want);
        fail();
    }
}

/* ---- (a) case reading ---------------------------------------------------------------------- */

static void test_parse_dry(void **state)
{
    (void)state;
    mixsph_sim *s = create_ok(DRY_SAND);
    const struct medium *m = &s->cfg.media[0];
    assert_int_equal(m->law, LAW_MIXTURE_PAPER);
    assert_rel(m->rho0, (1.0 - POR) * RHO_S, 1e-15);   /* (5), dry: (1 - n) rho_s = 1722.5 */
    assert_rel(m->c, sqrt(K_S / RHO_S), 1e-15);         /* sqrt(K_s / rho_s) = 40 m/s, not of the mixture */
    assert_rel(m->granular.sin_phi, sin(PHI * GEOM_PI / 180.0), 1e-15);
    assert_true(m->paper.eps_f_mu_f == 0.0);                  /* no pore fluid */
    assert_int_equal(m->granular.saturated, 0);
    assert_true(m->paper.mu_thr == MU_THR && m->paper.mu0 == MU0);
    assert_int_equal(m->paper.mu1_mode, 0);
    /* particles: 40 x 10 grains at the mixture density (hydrostatic p / c^2 <= 1.7 kg/m3 above it) */
    assert_int_equal(mixsph_sim_particles(s), 400);
    for (size_t i = 0; i < s->phys.P.n; i++) {
        if (!is_grain(s, i)) continue;
        assert_true(s->phys.P.rho[i] >= m->rho0 && s->phys.P.rho[i] <= m->rho0 + 1.7);
        assert_rel(s->phys.P.m[i], s->phys.P.rho[i] * DX * DX, 1e-15);
    }
    mixsph_sim_destroy(s);
    /* no mu0: no limit (+inf) */
    s = create_ok("\"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"c\": 40.0, \"porosity\": 0.35, \"phi\": 35.0, "
                  "\"mu_thr\": 20e3 }");
    assert_true(isinf(s->cfg.media[0].paper.mu0) && s->cfg.media[0].paper.mu_thr == 20e3);
    assert_rel(s->cfg.media[0].c, 40.0, 1e-15);
    mixsph_sim_destroy(s);
}

static void test_parse_saturated(void **state)
{
    (void)state;
    mixsph_sim *s = create_ok(WATER ", " WET_SAND);
    const struct medium *m = &s->cfg.media[1];
    assert_int_equal(m->law, LAW_MIXTURE_PAPER);
    assert_int_equal(m->granular.saturated, 1);
    assert_int_equal(m->granular.pore_fluid, 0);
    assert_rel(m->rho0, POR * 1000.0 + (1.0 - POR) * RHO_S, 1e-15); /* (5), saturated: 2072.5 kg/m3 */
    assert_true(m->granular.rho_f == 1000.0);
    assert_rel(m->paper.eps_f_mu_f, POR * 1.0e-3, 1e-15);                 /* eps_f mu_f of (12) */
    assert_rel(m->c, 40.0, 1e-15);                                  /* sqrt(K_s / rho_s) */
    mixsph_sim_destroy(s);
}

static void test_parse_mu1(void **state)
{
    (void)state;
    /* Run 7's rheology: mu1 alone = a threshold without limit */
    mixsph_sim *s = create_ok("\"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.35, "
                              "\"phi\": 35.0, \"mu1\": 5e3 }");
    const struct medium *m = &s->cfg.media[0];
    assert_int_equal(m->paper.mu1_mode, 1);
    assert_true(m->paper.mu_thr == 5e3 && isinf(m->paper.mu0));
    /* at rest every grain is held fixed with mu = mu1 */
    assert_int_equal(s->phys.n_fixed, 400);
    for (size_t i = 0; i < s->phys.P.n; i++)
        if (is_grain(s, i)) assert_true(s->phys.P.mu[i] == 5e3);
    mixsph_sim_destroy(s);
    /* with mu_thr or mu0 beside it: refused */
    expect_error("\"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0, "
                 "\"mu1\": 5e3, \"mu_thr\": 20e3 }",
                 "mu1");
    expect_error("\"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0, "
                 "\"mu1\": 5e3, \"mu0\": 1e3 }",
                 "mu1");
}

static void test_parse_errors(void **state)
{
    (void)state;
    /* saturated without a pore fluid */
    expect_error(WATER ", \"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.35, "
                 "\"phi\": 35.0, \"saturated\": true, \"mu_thr\": 320e3 }",
                 "media.sand.pore_fluid");
    /* pore fluid that is not a fluid (a granular medium), or not defined (before this one) */
    expect_error("\"gravel\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0, "
                 "\"mu_thr\": 320e3 }, "
                 "\"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0, "
                 "\"saturated\": true, \"pore_fluid\": \"gravel\", \"mu_thr\": 320e3 }",
                 "media.sand.pore_fluid");
    expect_error("\"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0, "
                 "\"saturated\": true, \"pore_fluid\": \"water\", \"mu_thr\": 320e3 }",
                 "media.sand.pore_fluid");
    /* the paper's law named without a threshold viscosity (a medium naming no law and giving
     * none runs the elastic-plastic law: test_case); both K and c; a key of fluids only */
    expect_error("\"sand\": { \"type\": \"granular\", \"law\": \"paper\", \"rho\": 2650.0, \"K\": 4.24e6, "
                 "\"porosity\": 0.35, \"phi\": 35.0 }",
                 "mu_thr");
    expect_error("\"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"c\": 40.0, \"porosity\": 0.35, "
                 "\"phi\": 35.0, \"mu_thr\": 320e3 }",
                 "media.sand");
    expect_error("\"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0, "
                 "\"mu_thr\": 320e3, \"mu\": 1.0 }",
                 "mu");
}

/* ---- (b) regimes and transitions ----------------------------------------------------------- */

/* u = (G z, 0) on every particle (walls' viscous velocity included), then the continuity pass
 * and the mixture update, from the pressure of the grains' own density (integrate_pressure_and_derived). */
static void impose_shear(mixsph_sim *s, double G)
{
    struct particles *P = &s->phys.P;
    for (size_t i = 0; i < P->n; i++) {
        P->vel[0][i] = P->uv[0][i] = G * P->pos[DIM_UP][i];
        P->vel[DIM_UP][i] = P->uv[DIM_UP][i] = 0.0;
    }
    integrate_pressure_and_derived(s);
}

static void update(mixsph_sim *s)
{
    assert_int_equal(sim_density_pass(s), 0);
    sim_mixture_update(s);
}

struct counts {
    long fixed, limited, frictional;
};

/* Check every grain against the regime of Fig. 1 for mu_app = eps_f mu_f + (p - p_w) sin(phi) / G
 * (p_w given per grain, NULL for dry); p0 is the pressure of every particle before the update. */
static struct counts check_regimes(const mixsph_sim *s, double G, const double *p0, const double *pw)
{
    const struct particles *P = &s->phys.P;
    struct counts c = {0, 0, 0};
    for (size_t i = 0; i < P->n; i++) {
        if (!is_grain(s, i)) continue;
        const struct medium *m = &s->cfg.media[P->medium[i]];
        double sig = p0[i] - (pw ? pw[i] : 0.0);
        sig = sig > 0.0 ? sig : 0.0;
        /* G = 0: sqrt(II_D) = 0 < 1e-12, mu_app is taken as mu_thr */
        const double app = G > 0.0 ? m->paper.eps_f_mu_f + sig * m->granular.sin_phi / G : m->paper.mu_thr;
        if (app >= m->paper.mu_thr) {
            assert_int_equal(P->state[i], MIXSPH_STATE_FIXED);
            assert_true(P->mu[i] == m->paper.mu_thr);
            assert_true(P->vel[0][i] == 0.0 && P->vel[DIM_UP][i] == 0.0 && P->uv[0][i] == 0.0 && P->uv[DIM_UP][i] == 0.0); /* held */
            c.fixed++;
            continue;
        }
        assert_int_equal(P->state[i], MIXSPH_STATE_MOBILE);
        assert_true(P->vel[0][i] == G * P->pos[DIM_UP][i] && P->vel[DIM_UP][i] == 0.0); /* a mobile grain keeps its velocity */
        assert_true(P->p[i] == p0[i]);        /* and its pressure */
        if (app > m->paper.mu0) {
            assert_true(P->mu[i] == m->paper.mu0);
            c.limited++;
        } else {
            /* tolerance: the corrected gradient reproduces u = G z up to round-off */
            assert_rel(P->mu[i], app, REL);
            c.frictional++;
        }
    }
    return c;
}

static double *save_p(const mixsph_sim *s)
{
    double *p = malloc(s->phys.P.n * sizeof *p);
    assert_non_null(p);
    memcpy(p, s->phys.P.p, s->phys.P.n * sizeof *p);
    return p;
}

/* Pressure of the fixed grains: sum_j (p_j + rho_j g (z_j - z_i)) W_ij / sum_j W_ij over the
 * mobile grains j within 2h (brute force over all particles), else the grain's own. */
static long check_fixed_pressure(const mixsph_sim *s, const double *p0)
{
    const struct particles *P = &s->phys.P;
    long n_extra = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (!is_grain(s, i) || P->state[i] != MIXSPH_STATE_FIXED) continue;
        double sw = 0.0, sp = 0.0;
        for (size_t j = 0; j < P->n; j++) {
            if (!is_grain(s, j) || P->state[j] != MIXSPH_STATE_MOBILE) continue;
            const double r2 = (P->pos[0][i] - P->pos[0][j]) * (P->pos[0][i] - P->pos[0][j]) + (P->pos[DIM_UP][i] - P->pos[DIM_UP][j]) * (P->pos[DIM_UP][i] - P->pos[DIM_UP][j]);
            if (r2 >= s->phys.K.r2max) continue;
            const double w = kernel_w(&s->phys.K, sqrt(r2));
            sw += w;
            sp += (p0[j] + P->rho[j] * G_ACC * (P->pos[DIM_UP][j] - P->pos[DIM_UP][i])) * w;
        }
        if (sw > 0.0) {
            assert_rel(P->p[i], sp / sw, REL);
            n_extra++;
        } else {
            assert_true(P->p[i] == p0[i]);
        }
        assert_true(isfinite(P->p[i]) && P->p[i] > 0.0);
    }
    return n_extra;
}

static void test_transitions(void **state)
{
    (void)state;
    mixsph_sim *s = create_ok(DRY_SAND);
    struct particles *P = &s->phys.P;
    const long n = 400;
    const size_t out_fixed = (size_t)mixsph_sim_output_find(s, "fixed_particles");

    /* at rest after creation: strain rate 0 -> mu_app = mu_thr -> every grain FIXED */
    assert_int_equal(s->phys.n_fixed, n);
    assert_true(mixsph_sim_output_value(s, out_fixed) == (double)n);
    for (size_t i = 0; i < P->n; i++) {
        if (!is_grain(s, i)) continue;
        assert_int_equal(P->state[i], MIXSPH_STATE_FIXED);
        assert_true(P->mu[i] == MU_THR);
    }
    /* (4): fixed grains bound dt with min(mu0, mu_thr) = mu0: 0.05 2 h^2 rho / mu0 (5.82e-6 s at
     * h = 0.013 m, rho = 1722.5), below the acoustic 0.1 2h / c = 6.5e-5 s; tolerance: round-off */
    double dt_ref = 0.1 * 2.0 * s->phys.h / s->phys.c_max;
    for (size_t i = 0; i < P->n; i++)
        if (is_grain(s, i)) dt_ref = fmin(dt_ref, 0.05 * 2.0 * s->phys.h * s->phys.h * P->rho[i] / MU0);
    print_message("dt at rest: %.6g s (bound of the fixed grains with mu0: %.6g s)\n", s->phys.dt, dt_ref);
    assert_rel(s->phys.dt, dt_ref, 1e-14);

    /* strong shear G = 0.1 1/s: mu_app = p sin(phi) / G <= 1700 * 0.574 / 0.1 = 9.7e3 < mu_thr:
     * every grain mobile, FRICTIONAL near the top (p < 872 Pa) and LIMITED (mu0) below */
    impose_shear(s, 0.1);
    double *p0 = save_p(s);
    update(s);
    struct counts c = check_regimes(s, 0.1, p0, NULL);
    print_message("G = 0.1 1/s:   %ld fixed, %ld limited, %ld frictional\n", c.fixed, c.limited, c.frictional);
    assert_int_equal(c.fixed, 0);
    assert_true(c.limited > 0 && c.frictional > 0);
    assert_int_equal(s->phys.n_fixed, 0);
    free(p0);

    /* back to rest: every grain FIXED again with mu = mu_thr */
    impose_shear(s, 0.0);
    p0 = save_p(s);
    update(s);
    c = check_regimes(s, 0.0, p0, NULL);
    assert_int_equal(c.fixed, n);
    assert_int_equal(s->phys.n_fixed, n);
    free(p0);

    /* creeping shear G = 1e-6 1/s (sqrt(II_D) = 5e-7 >= 1e-12): mu_app >= 84 * 0.574 / 1e-6 =
     * 4.8e7 >= mu_thr: FIXED, and the (nonzero) velocities are zeroed */
    impose_shear(s, 1e-6);
    p0 = save_p(s);
    update(s);
    c = check_regimes(s, 1e-6, p0, NULL);
    assert_int_equal(c.fixed, n);
    free(p0);

    /* moderate shear G = 0.002 1/s: mu_app >= mu_thr where p >= 1116 Pa (about 0.066 m deep):
     * the deep grains stay fixed, the shallow ones are mobilised (LIMITED); the pressure of the
     * fixed grains next to mobile ones follows them */
    impose_shear(s, 0.002);
    p0 = save_p(s);
    update(s);
    c = check_regimes(s, 0.002, p0, NULL);
    print_message("G = 0.002 1/s: %ld fixed, %ld limited, %ld frictional\n", c.fixed, c.limited, c.frictional);
    assert_true(c.fixed > 0 && c.limited > 0);
    assert_int_equal(s->phys.n_fixed, c.fixed);
    const long n_extra = check_fixed_pressure(s, p0);
    print_message("  %ld fixed grains took the pressure of mobile neighbours\n", n_extra);
    assert_true(n_extra > 0);
    /* the extrapolation is hydrostatic: within 5% of the grain's own pressure (the hydrostatic
     * state it was created in; tolerance: kernel sums truncated at the free surface) */
    for (size_t i = 0; i < P->n; i++)
        if (is_grain(s, i) && P->state[i] == MIXSPH_STATE_FIXED) assert_true(fabs(P->p[i] - p0[i]) <= 0.05 * p0[i]);
    free(p0);
    mixsph_sim_destroy(s);
}

/* ---- (c) pore pressure --------------------------------------------------------------------- */

/* A saturated flat bed at rest (cos^2 alpha = 1): p_w = rho_f g (z_top - z) with z_top the top
 * particle of the column + dx/2 = 0.1 m, and sigma' = p - p_w (the buoyant weight of the grains).
 * Imposing G = 0.1 1/s makes every grain mobile and FRICTIONAL (mu_app <= 0.1 m * 1072.5 * 9.81
 * * 0.574 / 0.1 = 6.0e3, just above mu0 at the bottom), so mu reveals sigma' grain by grain. */
static void test_pore_pressure(void **state)
{
    (void)state;
    mixsph_sim *s = create_ok(WATER ", " WET_SAND);
    const struct particles *P = &s->phys.P;
    impose_shear(s, 0.1);
    double *p0 = save_p(s);
    double *pw = calloc(P->n, sizeof *pw);
    assert_non_null(pw);
    double ztop = -INFINITY;
    for (size_t i = 0; i < P->n; i++)
        if (is_grain(s, i)) ztop = fmax(ztop, P->pos[DIM_UP][i] + 0.5 * DX);
    assert_rel(ztop, 0.1, 1e-12);
    for (size_t i = 0; i < P->n; i++)
        if (is_grain(s, i)) pw[i] = 1000.0 * G_ACC * (ztop - P->pos[DIM_UP][i]);
    update(s);
    const struct counts c = check_regimes(s, 0.1, p0, pw);
    print_message("saturated bed, G = 0.1 1/s: %ld fixed, %ld limited, %ld frictional\n", c.fixed, c.limited, c.frictional);
    assert_int_equal(c.fixed, 0);
    assert_true(c.frictional > 0);
    /* one column: sigma' back from mu, against the buoyant weight (rho_mix - rho_f) g (z_top - z) */
    print_message("   z [m]    p [Pa]   p_w [Pa]   sigma' from mu [Pa]   (rho_mix - rho_f) g (z_top - z) [Pa]\n");
    const struct medium *m = &s->cfg.media[1];
    for (int k = 9; k >= 0; k--) {
        for (size_t i = 0; i < P->n; i++) {
            if (!is_grain(s, i) || fabs(P->pos[0][i] - 0.205) > 1e-9 || fabs(P->pos[DIM_UP][i] - (k + 0.5) * DX) > 1e-9) continue;
            if (P->mu[i] == m->paper.mu0) {
                print_message("  %.3f  %8.2f  %8.2f     (limited: mu = mu0)\n", P->pos[DIM_UP][i], p0[i], pw[i]);
                continue;
            }
            const double sig = (P->mu[i] - m->paper.eps_f_mu_f) * 0.1 / m->granular.sin_phi;
            print_message("  %.3f  %8.2f  %8.2f     %8.2f               %8.2f\n", P->pos[DIM_UP][i], p0[i], pw[i], sig,
                          (m->rho0 - 1000.0) * G_ACC * (ztop - P->pos[DIM_UP][i]));
        }
    }
    free(p0);
    free(pw);
    mixsph_sim_destroy(s);

    /* the same bed dry: no pore pressure, sigma' = p (mu_app up to 9.7e3: some grains LIMITED) */
    s = create_ok(DRY_SAND);
    impose_shear(s, 0.1);
    p0 = save_p(s);
    update(s);
    const struct counts d = check_regimes(s, 0.1, p0, NULL);
    assert_true(d.limited > c.limited); /* the dry bed is stiffer: more grains at the limit */
    free(p0);
    mixsph_sim_destroy(s);
}

/* ---- (c) tension cut-off (an option, not the paper's model) ------------------------------- */

/* Grains stretched 1 % below and compressed 1 % above the mixture density: with the cut-off the
 * stretched ones get the background pressure (0 here) instead of c^2 (rho - rho0) < 0 (linear EOS,
 * docs/model.md section 3), the compressed ones keep c^2 (rho - rho0); without it both follow the EOS. */
static void check_tension(const char *media, int cutoff)
{
    mixsph_sim *s = create_ok(media);
    struct particles *P = &s->phys.P;
    const struct medium *m = &s->cfg.media[0];
    assert_int_equal(m->tension_cutoff, cutoff);
    for (size_t i = 0; i < P->n; i++)
        if (is_grain(s, i)) P->rho[i] = m->rho0 * (P->pos[DIM_UP][i] < 0.05 ? 0.99 : 1.01);
    integrate_pressure_and_derived(s);
    long stretched = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (!is_grain(s, i)) continue;
        const double eos = m->c * m->c * (P->rho[i] - m->rho0); /* -688.9 or +688.9 Pa */
        if (P->pos[DIM_UP][i] < 0.05) {
            stretched++;
            if (cutoff) assert_true(P->p[i] == 0.0);
            else assert_rel(P->p[i], eos, 1e-12);
        } else {
            assert_rel(P->p[i], eos, 1e-12);
        }
    }
    assert_int_equal(stretched, 200);
    mixsph_sim_destroy(s);
}

static void test_tension_cutoff(void **state)
{
    (void)state;
    check_tension(DRY_SAND, 0); /* default: off, the paper's model */
    check_tension("\"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0, "
                  "\"mu_thr\": 320e3, \"mu0\": 5e3, \"tension_cutoff\": true }",
                  1);
    expect_error("\"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0, "
                 "\"mu_thr\": 320e3, \"tension_cutoff\": 2 }",
                 "media.sand.tension_cutoff");
}

/* ---- (d) held fixed grains (option hold_fixed, SPHERA's momentum routine) ------------------ */

/* The bed at rest, every grain FIXED: one whole step. A fixed grain is never drifted; without the
 * option it receives its forces and the two half kicks (docs/model.md section 6's reading), so the
 * grains still fixed after the step carry v = dt/2 a from the second kick (their forces do not
 * balance exactly at the free surface and the walls); with `hold_fixed` it gets no acceleration
 * (SPHERA zeroes the acceleration of a particle with mu = mu_thr), so v stays exactly 0. */
static void check_hold(const char *media, int hold)
{
    mixsph_sim *s = create_ok(media);
    struct particles *P = &s->phys.P;
    assert_int_equal(s->cfg.media[0].paper.hold_fixed, hold);
    assert_int_equal(s->phys.n_fixed, 400);
    double *x0 = calloc(P->n, sizeof *x0), *z0 = calloc(P->n, sizeof *z0);
    assert_true(x0 && z0);
    for (size_t i = 0; i < P->n; i++) {
        x0[P->id[i]] = P->pos[0][i];
        z0[P->id[i]] = P->pos[DIM_UP][i];
    }
    assert_int_equal(integrate_step(s), MIXSPH_OK);
    long fixed = 0, moving = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (!is_grain(s, i)) continue;
        assert_true(P->pos[0][i] == x0[P->id[i]] && P->pos[DIM_UP][i] == z0[P->id[i]]); /* fixed at the step's start: not drifted */
        if (P->state[i] != MIXSPH_STATE_FIXED) continue;
        fixed++;
        if (P->vel[0][i] != 0.0 || P->vel[DIM_UP][i] != 0.0) moving++;
    }
    print_message("hold_fixed = %d: %ld grains fixed after one step, %ld of them with a nonzero velocity\n", hold, fixed,
                  moving);
    assert_true(fixed > 0);
    if (hold) assert_int_equal(moving, 0);
    else assert_true(moving > 0);
    free(x0);
    free(z0);
    mixsph_sim_destroy(s);
}

static void test_hold_fixed(void **state)
{
    (void)state;
    check_hold(DRY_SAND, 0); /* default: off */
    check_hold("\"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0, "
               "\"mu_thr\": 320e3, \"mu0\": 5e3, \"hold_fixed\": true }",
               1);
    expect_error("\"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0, "
                 "\"mu_thr\": 320e3, \"hold_fixed\": \"yes\" }",
                 "media.sand.hold_fixed");
    /* the grains' Monaghan coefficient (numerics.av_mixed, test_forces.c): 0-10 */
    expect_error("\"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0, "
                 "\"mu_thr\": 320e3, \"alpha_m\": -0.1 }",
                 "media.sand.alpha_m");
}

/* ---- (d2) a grain thrown clear: the density of a particle alone ----------------------------- */

/* The bed's top right grain leaves it at 40 m/s with the density of a grain already far from the
 * others (1.001 m W(0), W(0) the kernel's value at r = 0). The continuity equation, which has no
 * self term, takes its density below m W(0) in one step (asserted: the rate times the step), where
 * the summation density sum_j m_j W_ij cannot go (its own term alone is m W(0)): the step clamps
 * it there instead of ending the run with a non-positive density (docs/numerics.md 2d). Only a
 * medium with the tension cut-off has the floor. */
static void test_density_of_a_particle_alone(void **state)
{
    (void)state;
    mixsph_sim *s = create_ok("\"sand\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.35, "
                              "\"phi\": 35.0, \"mu_thr\": 320e3, \"mu0\": 5e3, \"tension_cutoff\": true }");
    struct particles *P = &s->phys.P;
    size_t top = P->n;
    for (size_t i = 0; i < P->n; i++)
        if (is_grain(s, i) && (top == P->n || P->pos[0][i] + P->pos[DIM_UP][i] > P->pos[0][top] + P->pos[DIM_UP][top])) top = i;
    const unsigned id = P->id[top];
    const double floor_rho = P->m[top] * kernel_w(&s->phys.K, 0.0);
    P->rho[top] = 1.001 * floor_rho;
    P->vel[0][top] = P->vel[DIM_UP][top] = 40.0 / sqrt(2.0);
    integrate_pressure_and_derived(s);
    const double dt = s->phys.dt;
    assert_int_equal(integrate_step(s), MIXSPH_OK);
    size_t k = 0;
    while (P->id[k] != id) k++;
    print_message("grain %u: rho = %.6g, m W(0) = %.6g, unclamped %.6g (drho %.6g, dt %.3g s)\n", id, P->rho[k],
                  floor_rho, 1.001 * floor_rho + dt * P->drho[k], P->drho[k], dt);
    assert_true(1.001 * floor_rho + dt * P->drho[k] < floor_rho); /* the continuity equation alone crosses it */
    assert_true(P->rho[k] == floor_rho);
    for (size_t i = 0; i < P->n; i++)
        if (is_grain(s, i)) assert_true(P->rho[i] >= P->m[i] * kernel_w(&s->phys.K, 0.0));
    mixsph_sim_destroy(s);
}

/* ---- (e) fixed bed (numerics.fixed_bed_speed, SPHERA's rule) ------------------------------- */

#define V_FB 0.0125 /* [m/s] the fixed-bed speed of SPHERA's erosive dam-break input */

static mixsph_sim *create_fixed_bed(double v_fb)
{
    char text[4096];
    snprintf(text, sizeof text, CASE_FMT, DRY_SAND);
    const mixsph_override ov = {"numerics.fixed_bed_speed", v_fb};
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_status st = mixsph_sim_create_from_text(text, "granular_bed.json", &ov, 1, &s, err, sizeof err);
    if (st != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    mixsph_sim_set_threads(s, 2);
    return s;
}

/* The bed's top three rows (z >= 0.065 m) slide at 0.05 m/s > V_FB, the rest is at rest; in
 * x < 0.1 m the sliding grains are marked FIXED (held at the last decision: they count as at
 * rest). All velocities are set before the continuity pass, so the strain rates are those of
 * this field. */
static void slide_top(mixsph_sim *s)
{
    struct particles *P = &s->phys.P;
    for (size_t i = 0; i < P->n; i++) {
        const double u = is_grain(s, i) && P->pos[DIM_UP][i] >= 0.065 ? 0.05 : 0.0;
        P->vel[0][i] = P->uv[0][i] = u;
        P->vel[DIM_UP][i] = P->uv[DIM_UP][i] = 0.0;
        if (is_grain(s, i)) P->state[i] = u > 0.0 && P->pos[0][i] < 0.1 ? MIXSPH_STATE_FIXED : MIXSPH_STATE_MOBILE;
    }
    integrate_pressure_and_derived(s);
}

/* The same bed with and without the fixed bed. Expected by brute force from the rule: in each
 * column 2h wide from the domain's x_min, the top is the highest grain at rest or FIXED before
 * the update (ties: first in memory order); a grain more than 2h below it is frozen: FIXED,
 * velocity 0, mu = mu_thr, p = p_top + rho0 g (z_top - z) with the top's final pressure, and the
 * density of that pressure. Every other grain ends exactly as without the option. Here the tops
 * are z = 0.095 m (x < 0.1 m) and 0.055 m elsewhere, 2h = 0.026 m. */
static void test_fixed_bed(void **state)
{
    (void)state;
    mixsph_sim *off = create_ok(DRY_SAND), *on = create_fixed_bed(V_FB);
    assert_true(off->cfg.fixed_bed_speed < 0.0); /* default: off */
    assert_true(on->cfg.fixed_bed_speed == V_FB);
    struct particles *P = &on->phys.P, *Q = &off->phys.P;
    assert_int_equal(P->n, Q->n);
    const size_t n = P->n;
    /* the same start: the creation's regime decision already froze grains of `on` (all at rest) */
    for (size_t i = 0; i < n; i++) {
        assert_int_equal(P->id[i], Q->id[i]);
        P->rho[i] = Q->rho[i];
    }
    slide_top(off);
    slide_top(on);
    const double two_h = 2.0 * on->phys.h, x0 = on->phys.domain[0];
    uint8_t *st0 = malloc(n);
    long *top = malloc(n * sizeof *top);
    assert_true(st0 && top);
    memcpy(st0, P->state, n);
    for (size_t i = 0; i < n; i++) {
        top[i] = -1;
        if (!is_grain(on, i)) continue;
        const double col = floor((P->pos[0][i] - x0) / two_h);
        for (size_t j = 0; j < n; j++) {
            if (!is_grain(on, j) || floor((P->pos[0][j] - x0) / two_h) != col) continue;
            const int rest = st0[j] == MIXSPH_STATE_FIXED || hypot(P->vel[0][j], P->vel[DIM_UP][j]) <= V_FB;
            if (rest && (top[i] < 0 || P->pos[DIM_UP][j] > P->pos[DIM_UP][top[i]])) top[i] = (long)j;
        }
    }
    update(off);
    update(on);
    const struct medium *m = &on->cfg.media[0];
    long frozen_left = 0, frozen_right = 0, others = 0;
    for (size_t i = 0; i < n; i++) {
        if (!is_grain(on, i)) continue;
        assert_true(top[i] >= 0); /* every column of the bed has grains at rest */
        const size_t k = (size_t)top[i];
        /* the top: 0.095 m in the columns with held grains (x < 0.1 m, and the column across x = 0.1 m) */
        const int high = fabs(P->pos[DIM_UP][k] - 0.095) < 1e-9;
        assert_true(high || fabs(P->pos[DIM_UP][k] - 0.055) < 1e-9);
        if (P->pos[0][i] < 0.1) assert_true(high);
        if (P->pos[DIM_UP][i] < P->pos[DIM_UP][k] - two_h) {
            assert_int_equal(P->state[i], MIXSPH_STATE_FIXED);
            assert_true(P->vel[0][i] == 0.0 && P->vel[DIM_UP][i] == 0.0 && P->mu[i] == m->paper.mu_thr);
            const double p = P->p[k] + m->rho0 * G_ACC * (P->pos[DIM_UP][k] - P->pos[DIM_UP][i]);
            assert_rel(P->p[i], p, REL);
            assert_rel(P->rho[i], m->rho0 + p / (m->c * m->c), 1e-12);
            if (high) frozen_left++;
            else frozen_right++;
        } else { /* the regime as without the option */
            assert_int_equal(P->state[i], Q->state[i]);
            assert_true(P->mu[i] == Q->mu[i] && P->vel[0][i] == Q->vel[0][i] && P->rho[i] == Q->rho[i]);
            if (P->state[i] == MIXSPH_STATE_MOBILE) {
                assert_true(P->p[i] == Q->p[i]);
            } else { /* held: from its mobile neighbours (frozen grains are not mobile ones) */
                double sw = 0.0, sp = 0.0;
                for (size_t j = 0; j < n; j++) {
                    if (!is_grain(on, j) || P->state[j] != MIXSPH_STATE_MOBILE) continue;
                    const double r2 = (P->pos[0][i] - P->pos[0][j]) * (P->pos[0][i] - P->pos[0][j]) + (P->pos[DIM_UP][i] - P->pos[DIM_UP][j]) * (P->pos[DIM_UP][i] - P->pos[DIM_UP][j]);
                    if (r2 >= on->phys.K.r2max) continue;
                    const double w = kernel_w(&on->phys.K, sqrt(r2));
                    sw += w;
                    sp += (P->p[j] + P->rho[j] * G_ACC * (P->pos[DIM_UP][j] - P->pos[DIM_UP][i])) * w;
                }
                assert_true(sw > 0.0);
                assert_rel(P->p[i], sp / sw, REL);
            }
            others++;
        }
    }
    print_message("fixed bed: %ld grains frozen below z = 0.069 m (top 0.095 m), %ld below z = 0.029 m (top 0.055 m), "
                  "%ld others\n", frozen_left, frozen_right, others);
    assert_true(frozen_left > 0 && frozen_right > 0 && others > 0);
    assert_int_equal(frozen_left + frozen_right + others, 400);
    free(st0);
    free(top);
    mixsph_sim_destroy(off);
    mixsph_sim_destroy(on);
    char text[4096];
    snprintf(text, sizeof text, CASE_FMT, DRY_SAND);
    char err[512] = "";
    mixsph_sim *s = NULL;
    const mixsph_override bad = {"numerics.fixed_bed_speed", -2.0};
    assert_int_equal(mixsph_sim_create_from_text(text, "granular_bed.json", &bad, 1, &s, err, sizeof err), MIXSPH_ERR_CASE);
    print_message("  refused: %s\n", err);
    assert_non_null(strstr(err, "numerics.fixed_bed_speed"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parse_dry),      cmocka_unit_test(test_parse_saturated),
        cmocka_unit_test(test_parse_mu1),      cmocka_unit_test(test_parse_errors),
        cmocka_unit_test(test_transitions),    cmocka_unit_test(test_pore_pressure),
        cmocka_unit_test(test_tension_cutoff), cmocka_unit_test(test_hold_fixed),
        cmocka_unit_test(test_density_of_a_particle_alone),
        cmocka_unit_test(test_fixed_bed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
