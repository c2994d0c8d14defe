/* test_settling.c - grains under water (docs/model.md section 5, [PW] and "Note on the pore
 * pressure of submerged layers"; issue 45: "Grains that enter water settle").
 *
 * (a) A block of dry gravel resting on the floor of a tank of still water, at its hydrostatic
 * start (sim.c: every particle has the weight of the lattice column above it). Under
 * pore_pressure = free_surface the pore pressure of a grain is the water's, measured from the free
 * surface z_s = 0.3 m, and the skeleton carries its buoyant weight only:
 *     p_w = rho_w g (z_s - z),   sigma' = p - p_w = (rho0 - rho_w) g (z_g - z)
 * with rho0 = (1 - n) rho_s the dry mixture density (5) and z_g = 0.06 m the block's top (the
 * note's formula, from the geometry of the case, not from the particles). Tolerance 1e-9 of the
 * water's pressure at the floor: the two sides add the same terms in another order. Under
 * granular_column (the paper's) a dry medium has p_w = 0 and sigma' = p, the water's weight
 * included: the same check then fails by the water's pressure, rho_w g (z_s - z_g) = 2354 Pa at
 * least.
 *
 * (b) The same block released at rest with its bottom 0.06 m above the floor (0.14 m under the
 * surface) sinks to the bed, under both granular laws: denser than the water (1590 against 1000
 * kg/m3), it falls through it (no wall or grain below to hold it) and lies on the floor. Criterion
 * at t = 0.8 s (measured 2026-12-06, dx = 0.01, 2 threads: the lowest grain at z = 0.0088 m
 * (paper) / 0.0072 m (elastic-plastic), the floor's first row being at dx/2, the highest at
 * 0.046 / 0.052 m): every grain below where the block's bottom started (the block has
 * gone down by its own height at least) and the lowest within 1.5 dx of the floor (on it: the
 * first row of particles above a wall lies at dx/2). Under granular_column the block sinks too (a
 * submerged block is not held up; what granular_column changes is the strength (a)). The run at
 * dx = 0.01 is in the validation suite (`test_settling validation`); ./tools/do test runs the
 * same block at dx = 0.02 (test_block_sinks_short).
 *
 * (c) A value of pore_pressure that is not a choice is refused, naming the key.
 *
 * (d) A single grain released at the free surface sinks: not met under the mixture coupling of
 * grains and water (docs/model.md [WG]), a known failure (`test_settling known_failure
 * surface_grain`; below).
 *
 * (e) Under water_coupling "grains" (docs/model.md [GW]) a single grain released at the free
 * surface sinks, one on the bed stays, one of the water's density stays (test_grains_in_water_short). */
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
#include "pore_pressure.h"
#include "sim.h"

#define G_ACC 9.81
#define RHO_W 1000.0
#define RHO_S 2650.0
#define POR 0.4
#define Z_SURFACE 0.3 /* the water's free surface [m] */

/* A tank 0.4 m wide of water Z_SURFACE deep, a block of dry gravel (the slide flume's) between x_lo
 * and x_hi and between z_lo and z_hi (its sites take the place of the water's); `extra` is added to
 * the gravel's keys. */
static const char *grains_json(double x_lo, double x_hi, double z_lo, double z_hi, const char *extra)
{
    static char buf[2048];
    snprintf(buf, sizeof buf,
             "{ \"name\": \"block_in_water\", \"gravity\": 9.81,"
             "  \"numerics\": { \"dx\": 0.01, \"t_end\": 1.0, \"viscosity\": \"implicit\" },"
             "  \"media\": { \"water\": { \"type\": \"fluid\", \"rho\": 1000.0, \"K\": 2.5e6, \"mu\": 1.0e-3,"
             "                            \"alpha_m\": 0.075 },"
             "              \"gravel\": { \"type\": \"granular\", \"rho\": 2650.0, \"K\": 4.24e6, \"porosity\": 0.4,"
             "                          \"phi\": 35.0, \"mu_thr\": 320.0e3, \"mu0\": 5.0e3, \"alpha_m\": 0.0 %s } },"
             "  \"bodies\": { \"block\": { \"medium\": \"gravel\","
             "                             \"polygon\": [[%.9g, %.9g], [%.9g, %.9g], [%.9g, %.9g], [%.9g, %.9g]] },"
             "               \"tank\": { \"medium\": \"water\", \"polygon\": [[0.0, 0.0], [0.4, 0.0], [0.4, 0.3], [0.0, 0.3]] } },"
             "  \"walls\": { \"box\": { \"polyline\": [[0.0, 0.5], [0.0, 0.0], [0.4, 0.0], [0.4, 0.5]],"
             "                        \"fluid_side\": \"left\" } },"
             "  \"domain\": { \"x_min\": -0.05, \"x_max\": 0.45, \"z_min\": -0.05, \"z_max\": 0.5 } }",
             extra, x_lo, z_lo, x_hi, z_lo, x_hi, z_hi, x_lo, z_hi);
    return buf;
}

/* The block of (a) and (b): 0.1 m wide from x = 0.15 m. */
static const char *tank_json(double z_lo, double z_hi, const char *extra)
{
    return grains_json(0.15, 0.25, z_lo, z_hi, extra);
}

static mixsph_sim *create_ok(const char *json)
{
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_status st = mixsph_sim_create_from_text(json, "block_in_water", NULL, 0, &s, err, sizeof err);
    if (st != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    return s;
}

static int is_grain(const mixsph_sim *s, size_t i)
{
    return s->phys.P.state[i] != MIXSPH_STATE_WALL && s->cfg.media[s->phys.P.medium[i]].law == LAW_MIXTURE_PAPER;
}

/* The largest |sigma' - (rho0 - rho_w) g (z_g - z)| over the grains [Pa], sigma' = p - p_b - p_w
 * with p_w from laws/pore_pressure.c at the start of the run. */
static double buoyant_weight_error(const char *extra, double z_g)
{
    mixsph_sim *s = create_ok(tank_json(0.0, z_g, extra));
    const struct particles *P = &s->phys.P;
    const struct law_setup setup = {.media = s->cfg.media, .n_media = s->cfg.n_media, .cap = P->n,
                                     .x_min = s->phys.domain[0], .x_max = s->phys.domain[1], .dx = s->phys.dx,
                                     .h = s->phys.h, .g = s->cfg.g, .p_background = s->cfg.p_background};
    struct pore_columns *C = pore_columns_create(&setup);
    assert_non_null(C);
    pore_columns_tops(C, P, s->cfg.media);
    const double rho0 = (1.0 - POR) * RHO_S; /* (5), dry: 1590 kg/m3 */
    double worst = 0.0;
    long grains = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (!is_grain(s, i)) continue;
        const struct medium *m = &s->cfg.media[P->medium[i]];
        const double pw = pore_pressure(C, m, P->pos[0][i], P->pos[DIM_UP][i]);
        const double sigma = P->p[i] - s->cfg.p_background - pw;
        const double want = (rho0 - RHO_W) * G_ACC * (z_g - P->pos[DIM_UP][i]);
        worst = fmax(worst, fabs(sigma - want));
        grains++;
    }
    assert_int_equal(grains, 60); /* 10 x 6 sites */
    pore_columns_free(C);
    mixsph_sim_destroy(s);
    return worst;
}

static void test_buoyant_weight(void **state)
{
    (void)state;
    const double z_g = 0.06, tol = 1e-9 * RHO_W * G_ACC * Z_SURFACE;
    const double e_surface = buoyant_weight_error("", z_g); /* the default: free_surface */
    const double e_column = buoyant_weight_error(", \"pore_pressure\": \"granular_column\"", z_g);
    print_message("largest |sigma' - (rho0 - rho_w) g (z_g - z)|: free_surface %.3g Pa (tolerance %.3g), "
                  "granular_column %.1f Pa\n", e_surface, tol, e_column);
    assert_true(e_surface <= tol);
    assert_true(e_column >= RHO_W * G_ACC * (Z_SURFACE - z_g)); /* the water's weight counted as the skeleton's */
}

/* The block of (b) under granular law number `law` (0 paper, 1 elastic_plastic: by number, so the
 * gravel keeps the paper law's keys) at resolution dx after t_end: its highest and lowest grain [m]
 * (printed every 0.1 s). */
static void sink(int law, double dx, double t_end, double *z_hi, double *z_lo)
{
    char extra[128];
    snprintf(extra, sizeof extra, ", \"law\": %d", law);
    const mixsph_override ov[] = {{"numerics.dx", dx}};
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_status st = mixsph_sim_create_from_text(tank_json(0.06, 0.12, extra), "block_in_water", ov, 1, &s, err,
                                                         sizeof err);
    if (st != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK); /* ctest -j runs tests side by side */
    const struct particles *P = &s->phys.P;
    for (int k = 1; k <= (int)lround(t_end / 0.1); k++) {
        assert_int_equal(mixsph_sim_advance_to(s, 0.1 * k), MIXSPH_OK);
        *z_hi = -INFINITY;
        *z_lo = INFINITY;
        for (size_t i = 0; i < P->n; i++) {
            if (P->state[i] == MIXSPH_STATE_WALL || P->medium[i] != 1) continue;
            assert_true(P->state[i] != MIXSPH_STATE_LOST);
            *z_hi = fmax(*z_hi, P->pos[DIM_UP][i]);
            *z_lo = fmin(*z_lo, P->pos[DIM_UP][i]);
        }
        print_message("  law %d, dx = %g m, t = %.1f s (%llu steps): grains between z = %.4f and %.4f m\n", law, dx,
                      mixsph_sim_time(s), (unsigned long long)mixsph_sim_steps(s), *z_lo, *z_hi);
    }
    mixsph_sim_destroy(s);
}

/* (b) at dx = 0.01 to t = 0.8 s, both laws (validation suite: `test_settling validation`). */
static void test_block_sinks(void **state)
{
    (void)state;
    const char *laws[] = {"paper", "elastic_plastic"};
    for (int k = 0; k < 2; k++) {
        double z_hi, z_lo;
        sink(k, 0.01, 0.8, &z_hi, &z_lo);
        print_message("%s: at t = 0.8 s the grains lie between z = %.4f and %.4f m (started 0.06-0.12 m)\n", laws[k],
                      z_lo, z_hi);
        assert_true(z_hi < 0.06);
        assert_true(z_lo < 1.5 * 0.01);
    }
}

/* (b), short (./tools/do test): the same block at dx = 0.02 (5 x 3 grains in a tank of 20 x 15
 * particles: a quarter of the particles and half the steps of dx = 0.01, 2.4 s for both laws),
 * with the criterion of (b) at that dx: every grain below where the block's bottom started, the
 * lowest within 1.5 dx of the floor. Measured (12-07): at t = 0.8 s the lowest grain at
 * z = 0.0137 m (paper) / 0.0191 m (elastic-plastic), the highest at 0.054 / 0.056 m; the block's
 * top crosses 0.06 m at about 0.5 s (paper) and 0.62 s (elastic-plastic); at dx = 0.01 at 0.45 and 0.6 s. */
static void test_block_sinks_short(void **state)
{
    (void)state;
    const char *laws[] = {"paper", "elastic_plastic"};
    const double dx = 0.02, t_end = 0.8;
    for (int k = 0; k < 2; k++) {
        double z_hi, z_lo;
        sink(k, dx, t_end, &z_hi, &z_lo);
        print_message("%s: at t = %.1f s the grains lie between z = %.4f and %.4f m (started 0.06-0.12 m)\n", laws[k],
                      t_end, z_lo, z_hi);
        assert_true(z_hi < 0.06);
        assert_true(z_lo < 1.5 * dx);
    }
}

static void test_bad_value(void **state)
{
    (void)state;
    mixsph_sim *s = NULL;
    char err[512] = "";
    assert_int_equal(mixsph_sim_create_from_text(tank_json(0.0, 0.06, ", \"pore_pressure\": \"surface\""),
                                                 "block_in_water", NULL, 0, &s, err, sizeof err),
                     MIXSPH_ERR_CASE);
    assert_null(s);
    print_message("  refused: %s\n", err);
    assert_non_null(strstr(err, "media.gravel.pore_pressure"));
    /* water_coupling "grains" without the grains' diameter, and a diameter without it */
    const char *bad[] = {", \"law\": 1, \"water_coupling\": \"grains\"", ", \"law\": 1, \"grain_diameter\": 0.002"};
    for (int k = 0; k < 2; k++) {
        assert_int_equal(mixsph_sim_create_from_text(tank_json(0.0, 0.06, bad[k]), "block_in_water", NULL, 0, &s, err,
                                                     sizeof err),
                         MIXSPH_ERR_CASE);
        assert_null(s);
        print_message("  refused: %s\n", err);
        assert_non_null(strstr(err, "media.gravel.grain_diameter"));
    }
}

/* One grain of dry gravel in the water's top row (the site centred at x = 0.205 m, z = 0.295 m),
 * released at rest under granular law number `law`: its descent below where it started after
 * t_end [m], and how high it then lies above the highest water particle within dx of it across [m]. */
static double surface_grain_descent(int law, double t_end, double *above_water)
{
    char extra[128];
    snprintf(extra, sizeof extra, ", \"law\": %d", law);
    mixsph_sim *s = create_ok(grains_json(0.20, 0.21, 0.29, 0.30, extra));
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK); /* 1,300 particles: one thread is enough */
    assert_int_equal(mixsph_sim_advance_to(s, t_end), MIXSPH_OK);
    const struct particles *P = &s->phys.P;
    double zg = NAN, xg = NAN;
    for (size_t i = 0; i < P->n; i++)
        if (P->state[i] != MIXSPH_STATE_WALL && P->medium[i] == 1) {
            zg = P->pos[DIM_UP][i];
            xg = P->pos[0][i];
        }
    double top = -INFINITY;
    for (size_t i = 0; i < P->n; i++)
        if (P->state[i] != MIXSPH_STATE_WALL && P->medium[i] == 0 && fabs(P->pos[0][i] - xg) <= 0.01)
            top = fmax(top, P->pos[DIM_UP][i]);
    *above_water = zg - top;
    mixsph_sim_destroy(s);
    return 0.295 - zg;
}

/* (d) A single grain at the free surface sinks: the criterion of issue 45 (no grain rides the
 * surface) at the scale of one particle. Reference: a body of 1590 kg/m3 in water sinks (a
 * continuum has no state in which it floats); the criterion asks it to be at least 2 dx below
 * where it started after 0.5 s, under the water's top row (a heavier particle does that: a fluid
 * particle of 3000 kg/m3 in the same place goes down 0.020 m in 0.5 s, one of 5000 kg/m3 0.048 m;
 * docs/validation/slide_flume.md, "Why single grains ride the surface"). NOT MET (12-06): under
 * both laws the grain settles onto the water and lies on it, about 0.9 dx above the highest water
 * particle within dx of it across, its descent 0.0031 m (paper) and 0.0026 m (elastic-plastic)
 * after 0.5 s; so does a fluid particle of 1590 or 2000 kg/m3, with no granular law at all. Kept as
 * a known failure with today's band: the smaller descent of the two laws, 0.0026 m, +- 0.008 m. */
static void test_surface_grain_sinks(void **state)
{
    (void)state;
    const char *laws[] = {"paper", "elastic_plastic"};
    double worst = INFINITY;
    for (int k = 0; k < 2; k++) {
        double above;
        const double d = surface_grain_descent(k, 0.5, &above);
        print_message("%s: a grain released in the top row has gone down %.4f m after 0.5 s and lies %.4f m above "
                      "the highest water particle within dx of it across\n", laws[k], d, above);
        worst = fmin(worst, d);
    }
    known_failure_check("a dry gravel grain released at the free surface, its descent after 0.5 s [m] (the smaller "
                        "of the two laws)",
                        worst >= 0.02, worst, -0.005, 0.011);
}

/* The water_coupling "grains" of the elastic-plastic law (docs/model.md [GW]) with grains of d = 2 mm;
 * `more` is added to the gravel's keys (e.g. saturated). */
#define GRAINS_IN_WATER ", \"law\": 1, \"water_coupling\": \"grains\", \"grain_diameter\": 0.002"

/* One grain particle at the lattice site of spacing dx centred at (x, z), its grains of density
 * rho_s, released at rest: its height [m] and vertical velocity [m/s] after t_end (printed every
 * 0.1 s; z_at, unless NULL, receives the height at t = 0.1 k, k = 1 .. t_end / 0.1). */
static double single_grain_heights(double x, double z, double dx, double rho_s, const char *extra, double t_end,
                                   double *vz, double *z_at)
{
    const mixsph_override ov[] = {{"numerics.dx", dx}, {"media.gravel.rho", rho_s}};
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_status st = mixsph_sim_create_from_text(grains_json(x - 0.5 * dx, x + 0.5 * dx, z - 0.5 * dx,
                                                                     z + 0.5 * dx, extra),
                                                         "block_in_water", ov, 2, &s, err, sizeof err);
    if (st != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
    const struct particles *P = &s->phys.P;
    double zg = NAN;
    long grains = 0;
    *vz = NAN;
    for (int k = 1; k <= (int)lround(t_end / 0.1); k++) {
        assert_int_equal(mixsph_sim_advance_to(s, 0.1 * k), MIXSPH_OK);
        grains = 0;
        for (size_t i = 0; i < P->n; i++)
            if (P->state[i] != MIXSPH_STATE_WALL && P->medium[i] == 1) {
                assert_true(P->state[i] != MIXSPH_STATE_LOST);
                zg = P->pos[DIM_UP][i];
                *vz = P->vel[DIM_UP][i];
                grains++;
            }
        print_message("    t = %.1f s: z = %.4f m, vz = %.4f m/s\n", mixsph_sim_time(s), zg, *vz);
        if (z_at) z_at[k - 1] = zg;
    }
    assert_int_equal(grains, 1);
    mixsph_sim_destroy(s);
    return zg;
}

static double single_grain(double x, double z, double dx, double rho_s, const char *extra, double t_end, double *vz)
{
    return single_grain_heights(x, z, dx, rho_s, extra, t_end, vz, NULL);
}

#define SATURATED ", \"saturated\": true, \"pore_fluid\": \"water\""

/* Ergun's terminal slip [m/s] of a parcel of grains in still water whose submerged weight per unit
 * volume is `load` [N/m3]: load = beta(u) u with beta of docs/model.md [GW] (n = POR, d = 2 mm,
 * mu_w = 1e-3 Pa s). */
static double ergun_terminal_slip(double load)
{
    const double d = 0.002, mu = 1.0e-3;
    const double a = 150.0 * (1.0 - POR) * (1.0 - POR) * mu / (POR * d * d), b = 1.75 * (1.0 - POR) * RHO_W / d;
    return (-a + sqrt(a * a + 4.0 * b * load)) / (2.0 * b);
}

/* (e) Grains in water (water_coupling "grains", docs/model.md [GW]), one grain particle of the
 * gravel (d = 2 mm) in the tank at dx = 0.02 (0.5 s; the four runs about 5 s on one thread):
 * - released in the water's top row it sinks, saturated (mixture density 1990 kg/m3, twice the
 *   water's) and dry (1590 kg/m3). Reference: Ergun's terminal slip u_t of the parcel under its
 *   buoyant weight (1 - n)(rho_s - rho_w) g, the same for both ([GW-S]: the water counts a dry
 *   parcel by its solids' volume; ergun_terminal_slip: 0.108 m/s); its descent after t = 0.5 s within
 *   [0.4, 1.5] u_t t: the lower factor for the start from rest and the water's numerical viscosity
 *   (its artificial viscosity, as the flow around one particle sees it: docs/validation/
 *   slide_flume.md, "Why single grains ride the surface"), the upper for the kernel's share of
 *   the water around a lone grain, 0.73 of a full support (the drag is beta times it, u up to
 *   1.3 u_t). Measured 12-07: 0.0459 m (0.85 u_t t) saturated, 0.0550 m (1.02 u_t t) dry (0.0240 m
 *   before [GW-S], when the dry parcel's buoyancy was its whole volume's and u_t 0.078 m/s). The dry
 *   grain goes down at least as far as the saturated one: the same buoyant weight and drag, less
 *   inertia (its mass lacks the pore water's), and it takes from the water only its solids'
 *   volume (this fails without [GW-S]: 0.0240 against 0.0459 m). The
 *   water_coupling "mixture" grain in the same place goes down 0.011 m (saturated; 0.2 u_t t) and
 *   lies on the water (test (d), the known failure, at dx = 0.01).
 * - saturated, on the floor (the bottom row), it stays: within 0.1 dx over 0.5 s (the bed holds
 *   its buoyant weight; measured: 0.0000 m).
 * - a grain of the water's density (saturated, grains of 1000 kg/m3) at mid-depth stays: within
 *   0.05 dx over 0.5 s (Archimedes: no net force; measured below 1e-4 m, 0.005 dx). */
static void test_grains_in_water_short(void **state)
{
    (void)state;
    const double dx = 0.02, t = 0.5, x = 0.2 + 0.5 * dx, z_top = Z_SURFACE - 0.5 * dx;
    double vz = NAN;
    const struct {
        const char *what, *extra;
        double rho_mix, load;
    } sinking[] = {{"saturated", GRAINS_IN_WATER SATURATED, POR * RHO_W + (1.0 - POR) * RHO_S,
                    (POR * RHO_W + (1.0 - POR) * RHO_S - RHO_W) * G_ACC},
                   {"dry", GRAINS_IN_WATER, (1.0 - POR) * RHO_S, (1.0 - POR) * (RHO_S - RHO_W) * G_ACC}};
    double descent_of[2];
    for (int k = 0; k < 2; k++) {
        const double u_t = ergun_terminal_slip(sinking[k].load);
        const double descent = z_top - single_grain(x, z_top, dx, RHO_S, sinking[k].extra, t, &vz);
        descent_of[k] = descent;
        print_message("%s grain (%.0f kg/m3) from the top row: down %.4f m after %.1f s (%.2f u_t t, u_t = %.4f m/s)\n",
                      sinking[k].what, sinking[k].rho_mix, descent, t, descent / (u_t * t), u_t);
        assert_true(descent >= 0.4 * u_t * t);
        assert_true(descent <= 1.5 * u_t * t);
        assert_true(vz < 0.0);
    }
    assert_true(descent_of[1] >= descent_of[0]); /* the dry parcel: the same buoyant weight, less inertia */
    const double z_bed = 0.5 * dx;
    const double z_rest = single_grain(x, z_bed, dx, RHO_S, GRAINS_IN_WATER SATURATED, t, &vz);
    print_message("saturated grain on the floor: moved %.5f m in %.1f s\n", z_rest - z_bed, t);
    assert_true(fabs(z_rest - z_bed) <= 0.1 * dx);
    const double z_mid = 0.15;
    const double z_neutral = single_grain(x, z_mid, dx, RHO_W, GRAINS_IN_WATER SATURATED, t, &vz);
    print_message("grain of the water's density at mid-depth: moved %.5f m in %.1f s\n", z_neutral - z_mid, t);
    assert_true(fabs(z_neutral - z_mid) <= 0.05 * dx);
}

/* (f) A dry grain sinks as fast at every spacing (issue 59 criterion 5 at dx and dx/2 asks it of the
 * grains a splash leaves in the water column; docs/validation/grains_settle.md, "Designs for grains
 * that sink at every spacing"): one grain particle of the dry gravel (d = 2 mm) released at rest
 * at mid-depth, centred at (0.2 + dx/2, 0.2 + dx/2), at dx = 0.02, 0.01 and 0.005; its mean speed
 * over 0.1-0.4 s. Reference: Ergun's terminal slip u_t = 0.108 m/s of test (e), which does not
 * depend on dx; the criterion: the speed at dx = 0.005 at least 0.9 of that at dx = 0.02. NOT MET
 * (12-07): with [GW-S] 0.110 / 0.087 / 0.057 m/s (1.03 / 0.81 / 0.53 u_t), the ratio 0.518 (the
 * water still flows around a body one particle across, against its artificial viscosity, which is
 * proportional to dx; with d = 4 mm 0.51, and 0.10 before [GW-S]); a known failure with today's
 * band 0.45-0.60. Validation suite (45 s on one thread). */
static void test_grain_sinks_at_every_spacing(void **state)
{
    (void)state;
    const double dxs[] = {0.02, 0.01, 0.005};
    double speed[3];
    for (int k = 0; k < 3; k++) {
        const double dx = dxs[k], c = 0.2 + 0.5 * dx;
        double vz, z_at[4];
        single_grain_heights(c, c, dx, RHO_S, GRAINS_IN_WATER, 0.4, &vz, z_at);
        speed[k] = (z_at[0] - z_at[3]) / 0.3;
        print_message("dx = %.3f: the dry grain sinks at %.4f m/s over 0.1-0.4 s (%.2f u_t)\n", dx, speed[k],
                      speed[k] / ergun_terminal_slip((1.0 - POR) * (RHO_S - RHO_W) * G_ACC));
    }
    const double ratio = speed[2] / speed[0];
    known_failure_check("a dry grain's sinking speed at dx = 0.005 over that at dx = 0.02", ratio >= 0.9, ratio, 0.45,
                        0.60);
}

/* `test_settling` runs the tests the model meets; `test_settling known_failure surface_grain` the
 * criterion it does not meet yet (a test of its own in CTest). */
int main(int argc, char **argv)
{
    if (argc > 2 && strcmp(argv[1], "known_failure") == 0) {
        if (strcmp(argv[2], "surface_grain") == 0) {
            const struct CMUnitTest known[] = {cmocka_unit_test(test_surface_grain_sinks)};
            return cmocka_run_group_tests(known, NULL, NULL);
        }
        fprintf(stderr, "test_settling: unknown known_failure '%s' (surface_grain)\n", argv[2]);
        return 2;
    }
    if (argc > 1 && strcmp(argv[1], "validation") == 0) {
        /* the long version (CTest test_settling_validation, label validation: ./tools/do validate) */
        const struct CMUnitTest long_tests[] = {cmocka_unit_test(test_block_sinks),
                                                cmocka_unit_test(test_grain_sinks_at_every_spacing)};
        return cmocka_run_group_tests(long_tests, NULL, NULL);
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_buoyant_weight),
        cmocka_unit_test(test_block_sinks_short),
        cmocka_unit_test(test_bad_value),
        cmocka_unit_test(test_grains_in_water_short),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
