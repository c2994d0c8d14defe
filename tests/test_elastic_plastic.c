/* test_elastic_plastic.c - the elastic-perfectly-plastic granular law (laws/elastic_plastic.c,
 * experimental) behind the material-law seam: its case keys, and a heap of dry sand (phi = 35 deg)
 * with slopes 5 degrees below phi on a no-slip floor, dx = 0.01, run with it for 2 s.
 *
 * The heap's criterion (issue "A granular stress that knows no time step"): every grain within
 * 0.1 dx of where it started over 2 s. Measured (12-06, one thread): 0.055 dx, the largest
 * displacement near the apex. It stands by its elastic stress and the dissipation of
 * docs/model.md [DP-AV]; without that dissipation (alpha_M = 0) a heap of 25-degree slopes
 * spreads by 4 dx in 2 s.
 *
 * Grains against walls: a block on a 30-degree incline of wall friction angle 15 degrees slides
 * as a block with the Coulomb block's acceleration.
 *
 * The rate-dependent friction (rate_dependent, laws/mu_i.h): its keys, and a block of grains in
 * steady simple shear through the law's update in a simulation, which must reach mu(I) p'. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "drucker_prager.h"
#include "known_failure.h"
#include "mu_i.h"
#include "sim.h"
#include "sim_passes.h"

#define DX 0.01

/* A heap: base 0.4 m, slopes of `slope_deg` on a no-slip floor; `extra` is added to the sand. */
static const char *heap_json_slope(const char *extra, double slope_deg)
{
    static char buf[2048];
    snprintf(buf, sizeof buf,
             "{ \"name\": \"heap_ep\", \"gravity\": 9.81, \"numerics\": { \"dx\": 0.01, \"t_end\": 2.0 },"
             "  \"media\": { \"sand\": { \"type\": \"granular\", \"law\": \"elastic_plastic\", \"rho\": 2650.0,"
             "    \"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0 %s } },"
             "  \"bodies\": { \"heap\": { \"medium\": \"sand\", \"polygon\": [[0.0, 0.0], [0.4, 0.0], [0.2, %.9g]] } },"
             "  \"walls\": { \"floor\": { \"polyline\": [[-0.05, 0.0], [0.45, 0.0]], \"fluid_side\": \"left\" } },"
             "  \"domain\": { \"x_min\": -0.15, \"x_max\": 0.55, \"z_min\": -0.05, \"z_max\": 0.25 } }",
             extra, 0.2 * tan(slope_deg * GEOM_PI / 180.0));
    return buf;
}

/* The heap of the tests below phi: slopes of 30 degrees (5 degrees below phi). */
static const char *heap_json(const char *extra) { return heap_json_slope(extra, 30.0); }

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
    assert_true(fabs(m->elastic.shear_modulus / (3.0 * K * 0.4 / 2.6) - 1.0) < 1e-14);
    /* psi = 0: alpha_phi = sin(phi) / 3 (drucker_prager.h) */
    assert_true(fabs(m->dp.alpha_phi - sin(35.0 * GEOM_PI / 180.0) / 3.0) < 1e-15);
    /* the dissipation [DP-AV]: alpha_M c = c_p, the P-wave speed */
    assert_true(fabs(m->alpha_m * m->c / sqrt((K + 4.0 / 3.0 * m->elastic.shear_modulus) / rho0) - 1.0) < 1e-14);
    mixsph_sim_destroy(s);
    /* refused: saturated without a pore fluid, a dilatancy, a paper-law key, the artificial
     * viscosity (a fixed numerical parameter of the law, not a case key) */
    const char *bad[] = {", \"saturated\": true", ", \"dilatancy\": 5", ", \"mu_thr\": 1e5", ", \"alpha_m\": 0.2"};
    const char *named[] = {"pore_fluid", "dilatancy", "mu_thr", "alpha_m"};
    for (size_t k = 0; k < 4; k++) {
        s = NULL;
        assert_int_equal(mixsph_sim_create_from_text(heap_json(bad[k]), "heap", NULL, 0, &s, err, sizeof err),
                         MIXSPH_ERR_CASE);
        assert_non_null(strstr(err, named[k]));
        assert_null(s);
    }
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Run the heap of case text `json` to t_end; the largest and the median displacement of its grains
 * [dx]. */
static void heap_displacements(const char *json, double t_end, double *largest, double *median)
{
    mixsph_sim *s = NULL;
    char err[512] = "";
    assert_int_equal(mixsph_sim_create_from_text(json, "heap", NULL, 0, &s, err, sizeof err), MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
    const struct particles *P = &s->phys.P;
    const size_t n = P->n;
    double *x0 = calloc(n, sizeof *x0), *z0 = calloc(n, sizeof *z0), *d = calloc(n, sizeof *d);
    assert_true(x0 && z0 && d);
    for (size_t i = 0; i < n; i++) {
        x0[P->id[i]] = P->pos[0][i];
        z0[P->id[i]] = P->pos[DIM_UP][i];
    }
    assert_int_equal(mixsph_sim_advance_to(s, t_end), MIXSPH_OK);
    size_t k = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] == MIXSPH_STATE_WALL) continue;
        assert_int_equal(P->state[i], MIXSPH_STATE_MOBILE); /* no hold rule: no grain is held */
        d[k++] = hypot(P->pos[0][i] - x0[P->id[i]], P->pos[DIM_UP][i] - z0[P->id[i]]) / DX;
    }
    qsort(d, k, sizeof *d, cmp_double);
    *largest = d[k - 1];
    *median = d[k / 2];
    free(x0);
    free(z0);
    free(d);
    mixsph_sim_destroy(s);
}

static void test_heap_below_phi(void **state)
{
    (void)state;
    double worst, median;
    heap_displacements(heap_json(""), 2.0, &worst, &median);
    /* criterion (the issue): every grain within 0.1 dx of its start over 2 s; measured 0.055 dx */
    print_message("heap 5 deg below phi: largest displacement %.4f dx in 2 s\n", worst);
    assert_true(worst <= 0.1);
}

/* The same heap saturated (pore fluid water, 1000 kg/m3): yield on the effective stress of the pore
 * pressure [PW]. An infinite slope of the saturated medium stands while tan(beta) <= (rho_sat -
 * rho_f) / rho_sat tan(phi), 19.9 degrees here (rho_sat = 2072.5 kg/m3): the dry heap of 30-degree
 * slopes that stands above must fail saturated. */
static void test_saturated_heap_fails(void **state)
{
    (void)state;
    char json[2048];
    snprintf(json, sizeof json, "%s", heap_json(", \"saturated\": true, \"pore_fluid\": \"water\""));
    const char *media = "\"media\": { ";
    char *at = strstr(json, media);
    assert_non_null(at);
    const char *water = "\"water\": { \"type\": \"fluid\", \"rho\": 1000.0, \"K\": 1.6e6, \"mu\": 1e-3 }, ";
    char out[2560];
    snprintf(out, sizeof out, "%.*s%s%s%s", (int)(at - json), json, media, water, at + strlen(media));
    double worst, median;
    heap_displacements(out, 0.5, &worst, &median);
    print_message("saturated heap of 30-degree slopes: median displacement %.3f dx, largest %.3f dx in 0.5 s\n",
                  median, worst);
    /* it fails: half its grains move more than 0.5 dx in 0.5 s (the dry heap's largest displacement
     * is 0.006 dx in 2 s, its elastic settlement about 0.002 dx); measured 0.57 dx (12-07, the bed's
     * Coulomb contact holding its base grains; 1.9 dx with the bound of the law's own wall shear) */
    assert_true(median > 0.5);
}

/* A block of the same sand made cohesive (c = 10 kPa, against rho g H = 0.85 kPa, so that it is a
 * solid block and only the wall friction is plastic; a cohesionless block with free ends is in the
 * active Rankine state and spreads), 0.2 m long and 0.05 m thick, released from rest on a 30-degree
 * incline (aligned wall particles) of wall friction angle delta = 15 degrees. */
#define INCLINE_DEG 30.0
#define DELTA_DEG 15.0

static const char *block_json(void)
{
    static char buf[2048];
    const double a = INCLINE_DEG * GEOM_PI / 180.0, tx = cos(a), tz = -sin(a), nx = sin(a), nz = cos(a);
    const double s0 = 0.1, s1 = 0.3, h = 0.05, len = 1.2;
#define PT(s, d) (s) * tx + (d) * nx, (s) * tz + (d) * nz
    snprintf(buf, sizeof buf,
             "{ \"name\": \"block_ep\", \"gravity\": 9.81,"
             "  \"numerics\": { \"dx\": 0.01, \"t_end\": 0.5, \"wall_placement\": \"aligned\" },"
             "  \"media\": { \"sand\": { \"type\": \"granular\", \"law\": \"elastic_plastic\", \"rho\": 2650.0,"
             "    \"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 35.0, \"cohesion\": 1e4 } },"
             "  \"bodies\": { \"block\": { \"medium\": \"sand\", \"polygon\": [[%.9g, %.9g], [%.9g, %.9g], [%.9g, %.9g],"
             "    [%.9g, %.9g]] } },"
             "  \"walls\": { \"incline\": { \"polyline\": [[%.9g, %.9g], [%.9g, %.9g]], \"fluid_side\": \"left\","
             "    \"friction\": %g } },"
             "  \"domain\": { \"x_min\": -0.2, \"x_max\": 1.25, \"z_min\": -0.8, \"z_max\": 0.3 } }",
             PT(s0, 0.0), PT(s1, 0.0), PT(s1, h), PT(s0, h), PT(-0.05, 0.0), PT(len, 0.0), DELTA_DEG);
#undef PT
    return buf;
}

/* The block's mean velocity along the slope, the standard deviation of its grains' velocities
 * along the slope and its length along the slope. */
static void block_state(const struct particles *P, double *u, double *u_std, double *length)
{
    const double a = INCLINE_DEG * GEOM_PI / 180.0;
    double su = 0.0, suu = 0.0, lo = INFINITY, hi = -INFINITY;
    size_t n = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] == MIXSPH_STATE_WALL) continue;
        const double ui = P->vel[0][i] * cos(a) - P->vel[DIM_UP][i] * sin(a), s = P->pos[0][i] * cos(a) - P->pos[DIM_UP][i] * sin(a);
        su += ui;
        suu += ui * ui;
        lo = fmin(lo, s);
        hi = fmax(hi, s);
        n++;
    }
    *u = su / (double)n;
    *u_std = sqrt(fmax(suu / (double)n - *u * *u, 0.0));
    *length = hi - lo;
}

static void test_block_on_incline(void **state)
{
    (void)state;
    mixsph_sim *s = NULL;
    char err[512] = "";
    assert_int_equal(mixsph_sim_create_from_text(block_json(), "block", NULL, 0, &s, err, sizeof err), MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
    double u, u_std, len0, len;
    block_state(&s->phys.P, &u, &u_std, &len0);
    /* the centroid velocity sampled every 0.05 s from 0.1 to 0.5 s, after the start's elastic
     * transient, and its least-squares slope */
    double st = 0.0, su = 0.0, stt = 0.0, stu = 0.0;
    int k = 0;
    for (double t = 0.1; t <= 0.5 + 1e-9; t += 0.05, k++) {
        assert_int_equal(mixsph_sim_advance_to(s, t), MIXSPH_OK);
        block_state(&s->phys.P, &u, &u_std, &len);
        st += t;
        su += u;
        stt += t * t;
        stu += t * u;
    }
    const double acc = (k * stu - st * su) / (k * stt - st * st);
    const double a = INCLINE_DEG * GEOM_PI / 180.0, delta = DELTA_DEG * GEOM_PI / 180.0;
    const double ref = 9.81 * (sin(a) - cos(a) * tan(delta)); /* a Coulomb block: 2.629 m/s2 */
    print_message("block on a %g-degree incline, delta %g: acceleration %.4f m/s2, reference %.4f (%+.2f %%); "
                  "velocity spread at 0.5 s %.3f of the mean; length %.4f -> %.4f m\n",
                  INCLINE_DEG, DELTA_DEG, acc, ref, 100.0 * (acc / ref - 1.0), u_std / u, len0, len);
    /* criterion (the issue): the Coulomb block's acceleration g (sin a - cos a tan delta) within 5 %;
     * measured (12-06) +1.0 % */
    assert_true(fabs(acc / ref - 1.0) <= 0.05);
    /* ... while it stays a block: at 0.5 s its grains' velocities along the slope within 5 % of
     * their mean (standard deviation: its elastic ringing; measured 3.0 %; a flowing cohesionless
     * block 19 %) and its length within 10 % of the start's (measured +2 %) */
    assert_true(u_std / u <= 0.05);
    assert_true(fabs(len / len0 - 1.0) <= 0.1);
    mixsph_sim_destroy(s);
}

/* The mean slope [deg] of a heap's two flanks: the top grain of every column dx wide, and a
 * least-squares line through the tops between 20 % and 80 % of the heap's height on each side of
 * its highest column. */
static double heap_flank_angle(const struct particles *P)
{
    enum { NB = 80 };
    const double x0 = -0.15;
    double top[NB];
    for (int b = 0; b < NB; b++) top[b] = -INFINITY;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] == MIXSPH_STATE_WALL) continue;
        const int b = (int)floor((P->pos[0][i] - x0) / DX);
        if (b >= 0 && b < NB && P->pos[DIM_UP][i] > top[b]) top[b] = P->pos[DIM_UP][i];
    }
    int apex = 0;
    for (int b = 1; b < NB; b++)
        if (top[b] > top[apex]) apex = b;
    const double H = top[apex];
    double sum = 0.0;
    for (int side = -1; side <= 1; side += 2) {
        double n = 0.0, sx = 0.0, sz = 0.0, sxx = 0.0, sxz = 0.0;
        for (int b = 0; b < NB; b++) {
            if ((b - apex) * side <= 0 || !(top[b] > 0.2 * H && top[b] < 0.8 * H)) continue;
            const double x = x0 + (b + 0.5) * DX;
            n += 1.0;
            sx += x;
            sz += top[b];
            sxx += x * x;
            sxz += x * top[b];
        }
        assert_true(n >= 2.0);
        sum += atan(fabs((n * sxz - sx * sz) / (n * sxx - sx * sx))) * 180.0 / GEOM_PI;
    }
    return 0.5 * sum;
}

/* A square block of grains, no gravity, a floor 8 dx below it (out of its particles' reach: a case
 * needs a wall); `extra` is added to the sand. */
static const char *shear_block_json(const char *extra)
{
    static char buf[1024];
    snprintf(buf, sizeof buf,
             "{ \"name\": \"shear_ep\", \"gravity\": 0, \"numerics\": { \"dx\": 0.01, \"t_end\": 1.0 },"
             "  \"media\": { \"sand\": { \"type\": \"granular\", \"law\": \"elastic_plastic\", \"rho\": 2650.0,"
             "    \"K\": 4.24e6, \"porosity\": 0.35, \"phi\": 32.0 %s } },"
             "  \"bodies\": { \"block\": { \"medium\": \"sand\", \"polygon\": [[0, 0], [0.2, 0], [0.2, 0.2], [0, 0.2]] } },"
             "  \"walls\": { \"floor\": { \"polyline\": [[-0.1, -0.08], [0.3, -0.08]], \"fluid_side\": \"left\" } },"
             "  \"domain\": { \"x_min\": -0.1, \"x_max\": 0.3, \"z_min\": -0.1, \"z_max\": 0.3 } }",
             extra);
    return buf;
}

/* The keys of rate_dependent: the defaults of Jop, Forterre & Pouliquen (2006) (delta_mu = 0.26,
 * I0 = 0.279, d = 0.5 mm), a given grain diameter kept, the static law untouched without it; refused
 * (naming the key): its parameters without it, a grain diameter with neither it nor the grains'
 * water coupling, and out-of-range values. */
static void test_rate_keys(void **state)
{
    (void)state;
    mixsph_sim *s = NULL;
    char err[512] = "";
    assert_int_equal(mixsph_sim_create_from_text(shear_block_json(", \"rate_dependent\": true"), "shear", NULL, 0, &s,
                                                 err, sizeof err), MIXSPH_OK);
    const struct medium *m = &s->cfg.media[0];
    assert_true(m->mu_i.on && m->mu_i.delta_mu == 0.26 && m->mu_i.I0 == 0.279 && m->granular.grain_diameter == 0.5e-3);
    mixsph_sim_destroy(s);
    assert_int_equal(mixsph_sim_create_from_text(shear_block_json(", \"rate_dependent\": true, \"grain_diameter\": 0.004, "
                                                                  "\"delta_mu\": 0.3, \"I0\": 0.5"),
                                                 "shear", NULL, 0, &s, err, sizeof err), MIXSPH_OK);
    m = &s->cfg.media[0];
    assert_true(m->mu_i.on && m->mu_i.delta_mu == 0.3 && m->mu_i.I0 == 0.5 && m->granular.grain_diameter == 0.004);
    mixsph_sim_destroy(s);
    assert_int_equal(mixsph_sim_create_from_text(shear_block_json(""), "shear", NULL, 0, &s, err, sizeof err), MIXSPH_OK);
    assert_false(s->cfg.media[0].mu_i.on);
    mixsph_sim_destroy(s);
    const char *bad[] = {", \"delta_mu\": 0.3", ", \"I0\": 0.3", ", \"grain_diameter\": 0.001",
                         ", \"rate_dependent\": true, \"I0\": 0", ", \"rate_dependent\": true, \"delta_mu\": -0.1",
                         ", \"rate_dependent\": true, \"grain_diameter\": 0"};
    const char *named[] = {"delta_mu", "I0", "grain_diameter", "I0", "delta_mu", "grain_diameter"};
    for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
        s = NULL;
        assert_int_equal(mixsph_sim_create_from_text(shear_block_json(bad[k]), "shear", NULL, 0, &s, err, sizeof err),
                         MIXSPH_ERR_CASE);
        assert_non_null(strstr(err, named[k]));
        assert_null(s);
    }
}

/* The block in simple shear at a known rate, u = gammadot (z - 0.1), its particles held in place and
 * their pressure set to p' = 2 kPa: the density pass gathers the velocity gradient (the corrected
 * gradient of a linear field is exact), and the law's update runs 2000 steps of 1e-4 s. The grain
 * at the centre, 10 dx from the edges, then carries the steady simple shear of the mu(I) rheology,
 * sqrt(J2) = mu(I) p', I = gammadot d / sqrt(p' / rho_s) = 0.23 here (Jop et al. 2006; mu_i.h).
 * Tolerance 1e-6: the spin tilts the steady deviator from the strain rate by an angle of order
 * sqrt(J2) / G (test_mu_i: 7e-8 at a material point); mu_s, the law without the rate term, is
 * 18 % below. */
static void test_rate_in_simple_shear(void **state)
{
    (void)state;
    mixsph_sim *s = NULL;
    char err[512] = "";
    const double gammadot = 20.0, d = 0.01, p_eff = 2000.0, dt = 1e-4;
    char extra[128];
    snprintf(extra, sizeof extra, ", \"rate_dependent\": true, \"grain_diameter\": %g", d);
    assert_int_equal(mixsph_sim_create_from_text(shear_block_json(extra), "shear", NULL, 0, &s, err, sizeof err),
                     MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
    struct particles *P = &s->phys.P;
    size_t centre = 0;
    for (size_t i = 0; i < P->n; i++) {
        P->p[i] = p_eff + s->cfg.p_background;
        P->vel[0][i] = P->uv[0][i] = gammadot * (P->pos[DIM_UP][i] - 0.1); /* uv: the pair loops' velocity */
        for (int a = 1; a < DIM; a++) P->vel[a][i] = P->uv[a][i] = 0.0;
        if (hypot(P->pos[0][i] - 0.1, P->pos[DIM_UP][i] - 0.1) < hypot(P->pos[0][centre] - 0.1, P->pos[DIM_UP][centre] - 0.1))
            centre = i;
        for (int c = 0; c < SYM_N; c++) P->stress[c][i] = 0.0;
    }
    for (int k = 0; k < 2000; k++) {
        assert_int_equal(sim_density_pass(s), 0);
        integrate_update_laws(s, dt);
    }
    const struct medium *m = &s->cfg.media[0];
    const double I = mu_i_inertial_number(gammadot, d, p_eff, m->granular.rho_grain);
    const double want = mu_i_friction(I, 3.0 * m->dp.alpha_phi, m->mu_i.delta_mu, m->mu_i.I0);
    const struct deviatoric_stress sc = deviatoric_stress_load(P->stress, centre);
    const double got = drucker_prager_sqrt_j2(&sc) / p_eff;
    print_message("block in simple shear at %g 1/s, d = %g m: sqrt(J2)/p' = %.9f at its centre, mu(I = %.4f) = "
                  "%.9f, mu_s = %.6f\n", gammadot, d, got, I, want, 3.0 * m->dp.alpha_phi);
    assert_true(fabs(got / want - 1.0) <= 1e-6);
    mixsph_sim_destroy(s);
}

/* A heap of 45-degree slopes, 10 degrees steeper than phi, fails; the criterion (the issue): it
 * comes to rest at its repose angle, phi = 35 degrees in plane strain (docs/model.md section 10),
 * within 3 degrees. NOT MET (12-06): after 3 s its flanks stand at 26.5 degrees and 31 % of its
 * grains are faster than 1 mm/s. Kept as a known failure with today's band. */
static void test_repose_after_failure(void **state)
{
    (void)state;
    mixsph_sim *s = NULL;
    char err[512] = "";
    assert_int_equal(mixsph_sim_create_from_text(heap_json_slope("", 45.0), "heap", NULL, 0, &s, err, sizeof err),
                     MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
    const double start = heap_flank_angle(&s->phys.P);
    assert_int_equal(mixsph_sim_advance_to(s, 3.0), MIXSPH_OK);
    const double angle = heap_flank_angle(&s->phys.P);
    size_t moving = 0, n = 0;
    for (size_t i = 0; i < s->phys.P.n; i++) {
        if (s->phys.P.state[i] == MIXSPH_STATE_WALL) continue;
        n++;
        moving += hypot(s->phys.P.vel[0][i], s->phys.P.vel[DIM_UP][i]) > 1e-3;
    }
    print_message("heap of 45-degree slopes (%.1f on the lattice): flanks at %.2f degrees after 3 s, %.1f %% of "
                  "the grains faster than 1 mm/s\n", start, angle, 100.0 * (double)moving / (double)n);
    const int met = fabs(angle - 35.0) <= 3.0 && (double)moving <= 0.05 * (double)n;
    /* today's band: 26.5 degrees +- 4 */
    known_failure_check("elastic-plastic heap 10 degrees steeper than phi, flank angle after 3 s [deg]", met, angle,
                        22.5, 30.5);
    mixsph_sim_destroy(s);
}

/* `test_elastic_plastic` runs the tests the law meets; `test_elastic_plastic known_failure repose`
 * the criterion it does not meet yet (a slow test of its own in CTest). */
int main(int argc, char **argv)
{
    if (argc > 2 && strcmp(argv[1], "known_failure") == 0) {
        if (strcmp(argv[2], "repose") == 0) {
            const struct CMUnitTest known[] = {cmocka_unit_test(test_repose_after_failure)};
            return cmocka_run_group_tests(known, NULL, NULL);
        }
        fprintf(stderr, "test_elastic_plastic: unknown known_failure '%s' (repose)\n", argv[2]);
        return 2;
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_keys),
        cmocka_unit_test(test_heap_below_phi),
        cmocka_unit_test(test_saturated_heap_fails),
        cmocka_unit_test(test_block_on_incline),
        cmocka_unit_test(test_rate_keys),
        cmocka_unit_test(test_rate_in_simple_shear),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
