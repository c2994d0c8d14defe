/* test_drucker_prager.c - the constitutive core of the elastic-perfectly-plastic law
 * (drucker_prager.h; docs/model.md section 10), one material point at a time:
 *   elastic constants and wave speed against the textbook relations of isotropic elasticity;
 *   the plane-strain cone matching against its two closed forms (psi = phi: Bui et al. 2008;
 *   psi = 0: sin(phi)/3, c cos(phi)) and its input checks;
 *   the return mapping: inside untouched, outside onto the cone along the flow rule, beyond the
 *   apex to the apex (tension cut-off);
 *   the Jaumann update: a rigidly rotating stressed block keeps its invariants over ten turns and
 *   its components follow the exact rotation;
 *   an oedometric (uniaxial strain) elastic increment: sigma_h / sigma_v = nu / (1 - nu);
 *   a plane-strain biaxial compression driven to its limit state: the stresses lie on the
 *   Mohr-Coulomb line of phi and c, for dilatancy 0 (default), phi and in between.
 * Each assertion states its reference and tolerance. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "drucker_prager.h"
#include "time_step.h"
#include "geometry.h"

#define DEG (GEOM_PI / 180.0)
#define ULPS 1e-14 /* relative tolerance of closed forms evaluated two ways: a few ulps */

/* Sand of the SPHinXsys column collapse (Feng et al. 2024): the elastic constants used below. */
#define E_SAND 5.84e6 /* [Pa] */
#define NU_SAND 0.3

static void assert_rel(double got, double want, double rel, const char *what)
{
    if (!(fabs(got - want) <= rel * fabs(want))) {
        print_error("%s: got %.17g, expected %.17g (relative tolerance %g)\n", what, got, want, rel);
        fail();
    }
}

static void assert_abs(double got, double want, double tol, const char *what)
{
    if (!(fabs(got - want) <= tol)) {
        print_error("%s: got %.17g, expected %.17g (absolute tolerance %g)\n", what, got, want, tol);
        fail();
    }
}

static struct drucker_prager_material material_e(double E, double phi_deg, double c, double psi_deg)
{
    struct drucker_prager_material m;
    assert_null(drucker_prager_material(E, NU_SAND, phi_deg * DEG, c, psi_deg * DEG, &m));
    return m;
}

static struct drucker_prager_material material(double phi_deg, double c, double psi_deg)
{
    return material_e(E_SAND, phi_deg, c, psi_deg);
}

/* Deviator and pressure of a full plane-strain stress (tension positive). */
static void split(double sxx, double szz, double sxz, double syy, struct deviatoric_stress *s, double *p)
{
    *p = -(sxx + szz + syy) / 3.0;
    s->xx = sxx + *p;
    s->zz = szz + *p;
    s->xz = sxz;
    s->yy = syy + *p;
}

/* K, G from E, nu; E and nu recovered through the inverse relations E = 9KG/(3K + G),
 * nu = (3K - 2G)/(2(3K + G)) (any elasticity text), and G from K and nu the same; bad inputs
 * refused with nothing written. */
static void test_elastic_constants(void **state)
{
    (void)state;
    const double nus[] = {-0.5, 0.0, 0.2, 0.3, 0.45, 0.499};
    for (size_t k = 0; k < sizeof nus / sizeof nus[0]; k++) {
        double K = 0.0, G = 0.0;
        assert_null(elasticity_constants(E_SAND, nus[k], &K, &G));
        assert_rel(9.0 * K * G / (3.0 * K + G), E_SAND, ULPS, "E from K, G");
        assert_abs((3.0 * K - 2.0 * G) / (2.0 * (3.0 * K + G)), nus[k], ULPS, "nu from K, G");
        double G2 = 0.0;
        assert_null(elasticity_shear_from_bulk(K, nus[k], &G2));
        assert_rel(G2, G, ULPS, "G from K and nu");
    }
    double G3 = -7.0;
    assert_non_null(elasticity_shear_from_bulk(1e6, 0.5, &G3));
    assert_non_null(elasticity_shear_from_bulk(0.0, 0.3, &G3));
    assert_non_null(elasticity_shear_from_bulk(NAN, 0.3, &G3));
    assert_true(G3 == -7.0); /* nothing written */
    const double bad[][2] = {{E_SAND, 0.5}, {E_SAND, -1.0}, {E_SAND, 0.7}, {0.0, 0.3}, {-1.0, 0.3},
                             {NAN, 0.3},    {E_SAND, NAN},  {INFINITY, 0.3}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        double K = -7.0, G = -7.0;
        assert_non_null(elasticity_constants(bad[k][0], bad[k][1], &K, &G));
        assert_true(K == -7.0 && G == -7.0); /* nothing written */
    }
}

/* P-wave speed sqrt((K + 4G/3)/rho) against the constrained modulus M = E(1-nu)/((1+nu)(1-2nu));
 * the time-step bound cfl 2h / (c_p + |u|) of criterion (4); the static strain rho g H / E. */
static void test_wave_speed_and_bounds(void **state)
{
    (void)state;
    const double rho = 2040.0;
    struct drucker_prager_material m = material(35.0, 0.0, 0.0);
    const double M = E_SAND * (1.0 - NU_SAND) / ((1.0 + NU_SAND) * (1.0 - 2.0 * NU_SAND));
    const double cp = elasticity_wave_speed(m.K, m.G, rho);
    assert_rel(cp, sqrt(M / rho), ULPS, "c_p = sqrt(M / rho)");
    assert_rel(time_step_bound(0.1, 0.05, 0.013, cp, 2.0, rho, 0.0), 0.1 * 2.0 * 0.013 / (sqrt(M / rho) + 2.0), ULPS,
               "dt bound = cfl 2h / (c_p + |u|)");
    /* a 0.1 m column of this sand: 2040 * 9.81 * 0.1 / 5.84e6 = 3.43e-4, below the 1 % bound */
    const double eps = elasticity_static_strain(rho, 9.81, 0.1, E_SAND);
    assert_rel(eps, 2040.0 * 9.81 * 0.1 / 5.84e6, ULPS, "rho g H / E");
    assert_true(eps < ELASTICITY_STATIC_STRAIN_MAX);
}

/* The plane-strain match reduces to its closed forms: psi = phi gives Bui et al. (2008)'s
 * alpha = tan(phi)/sqrt(9 + 12 tan^2 phi), k = 3c/sqrt(9 + 12 tan^2 phi); psi = 0 gives
 * alpha = sin(phi)/3, k = c cos(phi) (docs/model.md section 10). Bad inputs refused. */
static void test_matching_closed_forms(void **state)
{
    (void)state;
    const double phis[] = {10.0, 21.9, 30.0, 35.0, 45.0, 60.0};
    const double c = 12.5e3;
    for (size_t k = 0; k < sizeof phis / sizeof phis[0]; k++) {
        const double phi = phis[k] * DEG, t = tan(phi), root = sqrt(9.0 + 12.0 * t * t);
        double a, kc, ap;
        assert_null(drucker_prager_matching(phi, c, phi, &a, &kc, &ap));
        assert_rel(a, t / root, ULPS, "alpha_phi, associated");
        assert_rel(ap, t / root, ULPS, "alpha_psi, associated");
        assert_rel(kc, 3.0 * c / root, ULPS, "k_c, associated");
        assert_null(drucker_prager_matching(phi, c, 0.0, &a, &kc, &ap));
        assert_rel(a, sin(phi) / 3.0, ULPS, "alpha_phi, psi = 0");
        assert_true(ap == 0.0); /* exact: tan(0) = 0 */
        assert_rel(kc, c * cos(phi), ULPS, "k_c, psi = 0");
    }
    /* phi = 0 with cohesion: a von Mises cone of radius c in plane strain */
    double a, kc, ap;
    assert_null(drucker_prager_matching(0.0, c, 0.0, &a, &kc, &ap));
    assert_true(a == 0.0 && ap == 0.0);
    assert_rel(kc, c, ULPS, "k_c, phi = 0");
    const double bad[][3] = {{90.0, 0.0, 0.0}, {-1.0, c, 0.0},   {35.0, -1.0, 0.0}, {35.0, 0.0, 36.0},
                             {35.0, 0.0, -1.0}, {0.0, 0.0, 0.0}, {NAN, 0.0, 0.0},   {35.0, INFINITY, 0.0}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        double x = -7.0, y = -7.0, z = -7.0;
        assert_non_null(drucker_prager_matching(bad[k][0] * DEG, bad[k][1], bad[k][2] * DEG, &x, &y, &z));
        assert_true(x == -7.0 && y == -7.0 && z == -7.0);
    }
    struct drucker_prager_material m = {-7.0, -7.0, -7.0, -7.0, -7.0};
    assert_non_null(drucker_prager_material(E_SAND, 0.5, 35.0 * DEG, 0.0, 0.0, &m));
    assert_non_null(drucker_prager_material(E_SAND, 0.3, 35.0 * DEG, 0.0, 40.0 * DEG, &m));
    assert_true(m.K == -7.0 && m.alpha_phi == -7.0); /* nothing written */
}

/* Inside the cone the trial state is returned bit for bit (reference: the definition of an
 * elastic step); a state exactly at the origin with c = 0 is on the cone (f = 0) and also kept. */
static void test_return_inside(void **state)
{
    (void)state;
    const struct drucker_prager_material m = material(35.0, 5.0e3, 0.0);
    struct deviatoric_stress s;
    double p;
    split(-40.0e3, -90.0e3, 10.0e3, -65.0e3, &s, &p); /* p = 65 kPa, sqrt(J2) ~ 27 kPa < 0.57 p */
    assert_true(drucker_prager_yield(&s, p, &m) < 0.0);
    const struct deviatoric_stress s0 = s;
    const double p0 = p;
    assert_int_equal(drucker_prager_return(&s, &p, &m), DRUCKER_PRAGER_ELASTIC);
    assert_true(s.xx == s0.xx && s.zz == s0.zz && s.xz == s0.xz && s.yy == s0.yy && p == p0);
    const struct drucker_prager_material m0 = material(35.0, 0.0, 0.0);
    struct deviatoric_stress z = {0.0, 0.0, 0.0, 0.0};
    double pz = 0.0;
    assert_int_equal(drucker_prager_return(&z, &pz, &m0), DRUCKER_PRAGER_ELASTIC);
    assert_true(z.xx == 0.0 && z.zz == 0.0 && z.xz == 0.0 && z.yy == 0.0 && pz == 0.0);
}

/* psi = 0 (non-associated, the default): a trial outside the cone lands on it (|f| below 1e-12 of
 * sqrt(J2), round-off of a few operations on 1e5 Pa numbers), along the flow rule dg/dsigma = s /
 * (2 sqrt(J2)): the deviator scaled by one factor (each component to 1e-14 relative, so its
 * direction and tracelessness are kept), sqrt(J2) reduced by G dlambda = f (to 1e-12), the
 * pressure untouched (exact: no plastic volume change). */
static void test_return_cone_non_associated(void **state)
{
    (void)state;
    const double cs[] = {0.0, 20.0e3};
    for (size_t k = 0; k < 2; k++) {
        const struct drucker_prager_material m = material(35.0, cs[k], 0.0);
        struct deviatoric_stress s;
        double p;
        split(-20.0e3, -180.0e3, 30.0e3, -70.0e3, &s, &p); /* every component of s nonzero */
        const double f0 = drucker_prager_yield(&s, p, &m);
        assert_true(f0 > 0.0);
        const struct deviatoric_stress s0 = s;
        const double p0 = p, j0 = drucker_prager_sqrt_j2(&s0);
        assert_int_equal(drucker_prager_return(&s, &p, &m), DRUCKER_PRAGER_CONE);
        assert_abs(drucker_prager_yield(&s, p, &m), 0.0, 1e-12 * j0, "f after the return");
        assert_true(p == p0);
        const double r = s.xx / s0.xx;
        assert_true(r > 0.0 && r < 1.0);
        assert_rel(s.zz / s0.zz, r, ULPS, "radial return, zz");
        assert_rel(s.xz / s0.xz, r, ULPS, "radial return, xz");
        assert_rel(s.yy / s0.yy, r, ULPS, "radial return, yy");
        assert_rel(j0 - drucker_prager_sqrt_j2(&s), f0, 1e-12, "sqrt(J2) reduced by G dlambda = f");
    }
}

/* psi > 0: the return lands on the yield cone (|f| < 1e-12 sqrt(J2)) and its correction follows
 * the elastic stiffness applied to dg/dsigma = s/(2 sqrt(J2)) + alpha_psi I: the deviator radial,
 * and the pressure raised by 3 K alpha_psi dlambda while sqrt(J2) drops by G dlambda, so
 * dp / (-d sqrt(J2)) = 3 K alpha_psi / G (to 1e-12 relative). */
static void test_return_cone_dilatant(void **state)
{
    (void)state;
    const double psis[] = {10.0, 35.0};
    for (size_t k = 0; k < 2; k++) {
        const struct drucker_prager_material m = material(35.0, 10.0e3, psis[k]);
        struct deviatoric_stress s;
        double p;
        split(-30.0e3, -260.0e3, -40.0e3, -120.0e3, &s, &p);
        assert_true(drucker_prager_yield(&s, p, &m) > 0.0);
        const struct deviatoric_stress s0 = s;
        const double p0 = p, j0 = drucker_prager_sqrt_j2(&s0);
        assert_int_equal(drucker_prager_return(&s, &p, &m), DRUCKER_PRAGER_CONE);
        assert_abs(drucker_prager_yield(&s, p, &m), 0.0, 1e-12 * j0, "f after the return");
        const double r = s.xx / s0.xx;
        assert_rel(s.zz / s0.zz, r, ULPS, "radial deviator, zz");
        assert_rel(s.xz / s0.xz, r, ULPS, "radial deviator, xz");
        assert_rel(s.yy / s0.yy, r, ULPS, "radial deviator, yy");
        assert_true(p > p0);
        assert_rel((p - p0) / (j0 - drucker_prager_sqrt_j2(&s)), 3.0 * m.K * m.alpha_psi / m.G, 1e-12,
                   "flow direction: dp / d sqrt(J2)");
    }
}

/* Beyond the apex: the apex with the tension cut-off (s = 0, p' = -k_c / (3 alpha_phi), exactly;
 * 0 for a cohesionless medium). With psi = 0 every trial whose mean stress is beyond the apex goes
 * there whatever its shear; with psi > 0 a trial just beyond the apex in p' but with a large
 * shear goes back onto the cone (its dilatant return raises p' past the apex), as the flow rule says. */
static void test_return_apex(void **state)
{
    (void)state;
    const struct drucker_prager_material dry = material(35.0, 0.0, 0.0);
    struct deviatoric_stress s;
    double p;
    split(5.0e3, -1.0e3, 8.0e3, 2.0e3, &s, &p); /* p = -2 kPa: in tension */
    assert_int_equal(drucker_prager_return(&s, &p, &dry), DRUCKER_PRAGER_APEX);
    assert_true(s.xx == 0.0 && s.zz == 0.0 && s.xz == 0.0 && s.yy == 0.0 && p == 0.0);

    const struct drucker_prager_material coh = material(30.0, 10.0e3, 0.0);
    const double p_apex = -coh.k_c / (3.0 * coh.alpha_phi); /* = -c cot(phi) = -17.3 kPa */
    assert_rel(p_apex, -10.0e3 / tan(30.0 * DEG), ULPS, "apex of psi = 0 at -c cot(phi)");
    const double shears[] = {0.0, 1.0e3, 1.0e5};
    for (size_t k = 0; k < 3; k++) {
        split(-5.0e3 + shears[k], -5.0e3 - shears[k], 0.5 * shears[k], -5.0e3, &s, &p);
        p = p_apex - 1.0; /* one pascal beyond the apex */
        assert_int_equal(drucker_prager_return(&s, &p, &coh), DRUCKER_PRAGER_APEX);
        assert_true(s.xx == 0.0 && s.zz == 0.0 && s.xz == 0.0 && s.yy == 0.0);
        assert_true(p == p_apex); /* exact: the same expression */
    }
    const struct drucker_prager_material dil = material(30.0, 10.0e3, 20.0);
    const double pa = -dil.k_c / (3.0 * dil.alpha_phi);
    split(-5.0e3, -5.0e3, 0.0, -5.0e3, &s, &p);
    p = pa - 1.0; /* isotropic, beyond the apex: no shear to return along */
    assert_int_equal(drucker_prager_return(&s, &p, &dil), DRUCKER_PRAGER_APEX);
    assert_true(p == pa);
    split(-5.0e3 + 1.0e5, -5.0e3 - 1.0e5, 0.0, -5.0e3, &s, &p);
    p = pa - 1.0;
    assert_int_equal(drucker_prager_return(&s, &p, &dil), DRUCKER_PRAGER_CONE);
    assert_true(p > pa);
    assert_abs(drucker_prager_yield(&s, p, &dil), 0.0, 1e-12 * 1.0e5, "f after a dilatant return near the apex");
}

/* Rigid rotation u = -Omega z, w = Omega x (counter-clockwise from x to z; D = 0, W_xz = -Omega).
 * Reference: a stress carried by a rigid rotation is R(t) sigma0 R(t)^T, R(t) = exp(W t) (the
 * Jaumann rate is objective), so its invariants stay those of sigma0.
 * (1) Ten turns at Omega dt = 2e-3 (31,416 steps), the elastic step and the return mapping every
 *     step (the state is inside the cone): sqrt(J2), the in-plane determinant, s_yy and p kept to
 *     1e-10 relative (round-off of 3e4 orthogonal products; explicit Euler of the spin term would
 *     grow sqrt(J2) by exp(N (2 Omega dt)^2 / 2) - 1 = 29 %).
 * (2) An eighth of a turn (pi/4) in 10,000 steps: every component against R sigma0 R^T at the
 *     exact angle within 1e-8 of sqrt(J2): the Hughes-Winget rotation lags by (Omega dt)^2 / 12 of
 *     the angle turned (4e-10 rad here; components off by at most twice that times |s|); the sense
 *     of rotation is tested too (at pi/4 a rotation the wrong way gives s_xz of the other sign). */
static void test_jaumann_rigid_rotation(void **state)
{
    (void)state;
    const struct drucker_prager_material m = material(35.0, 0.0, 0.0);
    const double omega = 2.0, dt = 1e-3; /* Omega dt = 2e-3 */
    struct deviatoric_stress s0;
    double p0;
    split(-150.0e3, -300.0e3, 50.0e3, -240.0e3, &s0, &p0); /* every component of s nonzero */
    assert_true(drucker_prager_yield(&s0, p0, &m) < 0.0);
    const double j0 = drucker_prager_sqrt_j2(&s0);
    const double det0 = s0.xx * s0.zz - s0.xz * s0.xz;

    struct deviatoric_stress s = s0;
    double p = p0;
    const long n_turns = (long)llround(10.0 * 2.0 * GEOM_PI / (omega * dt));
    for (long k = 0; k < n_turns; k++) {
        elasticity_jaumann_step(&s, (const double[]){0.0, -omega, omega, 0.0}, m.G, dt);
        p = elasticity_pressure_step(p, (const double[]){0.0, 0.0, 0.0, 0.0}, m.K, dt);
        assert_int_equal(drucker_prager_return(&s, &p, &m), DRUCKER_PRAGER_ELASTIC);
    }
    assert_rel(drucker_prager_sqrt_j2(&s), j0, 1e-10, "sqrt(J2) after ten turns");
    assert_rel(s.xx * s.zz - s.xz * s.xz, det0, 1e-10, "in-plane determinant after ten turns");
    assert_rel(s.yy, s0.yy, 1e-10, "s_yy after ten turns");
    assert_true(p == p0); /* exact: tr D = 0 */

    const double dt8 = (0.25 * GEOM_PI / omega) / 10000.0;
    s = s0;
    for (int k = 0; k < 10000; k++) elasticity_jaumann_step(&s, (const double[]){0.0, -omega, omega, 0.0}, m.G, dt8);
    const double c = cos(0.25 * GEOM_PI), sn = sin(0.25 * GEOM_PI); /* R = [[c, -sn], [sn, c]] */
    const double xx = c * c * s0.xx - 2.0 * c * sn * s0.xz + sn * sn * s0.zz;
    const double zz = sn * sn * s0.xx + 2.0 * c * sn * s0.xz + c * c * s0.zz;
    const double xz = c * sn * (s0.xx - s0.zz) + (c * c - sn * sn) * s0.xz;
    assert_abs(s.xx, xx, 1e-8 * j0, "s_xx after pi/4");
    assert_abs(s.zz, zz, 1e-8 * j0, "s_zz after pi/4");
    assert_abs(s.xz, xz, 1e-8 * j0, "s_xz after pi/4");
    assert_true(s.yy == s0.yy); /* exact: y is the rotation axis */
}

/* Oedometric (uniaxial strain) elastic loading from a stress-free state: dw/dz = -1e-3 1/s over
 * 100 steps of 1e-3 s (vertical strain -1e-4), no lateral strain. Reference (plane strain, linear
 * isotropic elasticity): sigma_h / sigma_v = nu / (1 - nu), sigma_yy = sigma_h, sigma_v = M eps_v
 * with M = E (1 - nu) / ((1 + nu)(1 - 2 nu)); all to 1e-12 relative (a linear update summed 100
 * times). The ratio tests that D' takes the 3D trace: with the in-plane trace it would be
 * (K - G)/(K + G) = 0.37 for nu = 0.3 instead of 0.43. */
static void test_oedometric_ratio(void **state)
{
    (void)state;
    const double nus[] = {0.2, 0.3, 0.45};
    for (size_t k = 0; k < 3; k++) {
        double K, G;
        assert_null(elasticity_constants(E_SAND, nus[k], &K, &G));
        struct deviatoric_stress s = {0.0, 0.0, 0.0, 0.0};
        double p = 0.0;
        const double rate = -1e-3, dt = 1e-3;
        for (int n = 0; n < 100; n++) {
            elasticity_jaumann_step(&s, (const double[]){0.0, 0.0, 0.0, rate}, G, dt);
            p = elasticity_pressure_step(p, (const double[]){0.0, 0.0, 0.0, rate}, K, dt);
        }
        const double sv = s.zz - p, sh = s.xx - p, sy = s.yy - p;
        const double nu = nus[k], M = E_SAND * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
        assert_rel(sh / sv, nu / (1.0 - nu), 1e-12, "oedometric sigma_h / sigma_v");
        assert_rel(sy, sh, 1e-12, "oedometric sigma_yy = sigma_h");
        assert_rel(sv, M * rate * dt * 100.0, 1e-12, "oedometric sigma_v = M eps_v");
        assert_abs(s.xx + s.zz + s.yy, 0.0, 1e-12 * fabs(sv), "deviator traceless");
    }
}

/* Plane-strain biaxial compression of a stiffer (dense) sand, E = 50 MPa, nu = 0.3: lateral stress
 * sigma_xx held at -100 kPa, the sample shortened
 * vertically at dw/dz = -1 1/s with dt = 2e-6 s to 10 % strain (50,000 steps), the lateral strain
 * rate chosen every step so the elastic trial keeps sigma_xx at its target; pressure integrated
 * with K (elasticity_pressure_step), then the return mapping. At the limit state the in-plane
 * principal stresses sigma_xx (minor, compression) and sigma_zz (major) must lie on the Mohr-Coulomb
 * line of the medium's phi and c (reference: the Mohr-Coulomb criterion, which the plane-strain
 * match reproduces exactly at stationary plastic flow; docs/model.md section 10):
 *   (sigma_xx - sigma_zz)/2 = -(sigma_xx + sigma_zz)/2 sin(phi) + c cos(phi)
 * to 1e-6 of the left side (the out-of-plane stress approaches its limit value as
 * exp(-G eps_p / sqrt(J2)), below 1e-15 after 10 % strain here, so the residual is round-off). The associated-form cone used with psi = 0 would miss by
 * 5 % at phi = 35 deg (phi_eff = 33.0 deg), so the tolerance separates the matchings. */
static void test_biaxial_mohr_coulomb(void **state)
{
    (void)state;
    const double cases[][3] = {{35.0, 0.0, 0.0}, {30.0, 10.0e3, 0.0}, {35.0, 0.0, 35.0}, {25.0, 5.0e3, 10.0},
                               {21.9, 0.0, 0.0}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        const double phi = cases[k][0] * DEG, c = cases[k][1];
        const struct drucker_prager_material m = material_e(50.0e6, cases[k][0], c, cases[k][2]);
        const double lambda = m.K - 2.0 * m.G / 3.0, M = m.K + 4.0 * m.G / 3.0;
        const double target = -100.0e3, dt = 2e-6, dwdz = -1.0;
        struct deviatoric_stress s = {0.0, 0.0, 0.0, 0.0};
        double p = -target; /* isotropic start on the confining stress */
        for (int n = 0; n < 50000; n++) {
            const double sxx = s.xx - p;
            const double dudx = (target - sxx - lambda * dwdz * dt) / (M * dt);
            elasticity_jaumann_step(&s, (const double[]){dudx, 0.0, 0.0, dwdz}, m.G, dt);
            p = elasticity_pressure_step(p, (const double[]){dudx, 0.0, 0.0, dwdz}, m.K, dt);
            drucker_prager_return(&s, &p, &m);
        }
        const double sxx = s.xx - p, szz = s.zz - p;
        assert_true(szz < sxx && sxx < 0.0);
        const double t = 0.5 * (sxx - szz), mean = 0.5 * (sxx + szz);
        assert_rel(t, -mean * sin(phi) + c * cos(phi), 1e-6, "biaxial limit state on the Mohr-Coulomb line");
        /* the driver's own check: it corrects the return's change of sigma_xx one step late, so
         * sigma_xx stays off its target by one step's plastic correction (under 1 %) */
        assert_rel(sxx, target, 1e-2, "lateral stress held");
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_elastic_constants),     cmocka_unit_test(test_wave_speed_and_bounds),
        cmocka_unit_test(test_matching_closed_forms), cmocka_unit_test(test_return_inside),
        cmocka_unit_test(test_return_cone_non_associated), cmocka_unit_test(test_return_cone_dilatant),
        cmocka_unit_test(test_return_apex),           cmocka_unit_test(test_jaumann_rigid_rotation),
        cmocka_unit_test(test_oedometric_ratio),      cmocka_unit_test(test_biaxial_mohr_coulomb),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
