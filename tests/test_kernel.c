/* test_kernel.c - the Wendland C2 kernel of kernel.h (docs/model.md section 1):
 *   normalisation (continuous integral and lattice sum at h = 1.3 dx), first-order consistency
 *   of the SPH gradient on a lattice, compact support, F = W'(r)/r against a finite difference of
 *   W, continuity of F at the support edge and finiteness at r = 0. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "kernel.h"

/* sum over the lattice (k dx + ox, l dx + oz), |k|,|l| <= n, of dx^2 W(|x|): the discrete
 * integral of W around the origin with the lattice shifted by (ox, oz). */
static double lattice_sum_w(const struct kernel *K, double dx, double ox, double oz)
{
    const int n = (int)ceil(2.0 * K->h / dx) + 1;
    double s = 0.0;
    for (int l = -n; l <= n; l++)
        for (int k = -n; k <= n; k++) s += dx * dx * kernel_w(K, hypot(k * dx + ox, l * dx + oz));
    return s;
}

/* Continuous normalisation: int W dA = 1, evaluated on a lattice 200 times finer than h,
 * once centred and once shifted off the lattice. */
static void test_integral_is_one(void **state)
{
    (void)state;
    const struct kernel K = kernel_make(0.013);
    const double d = K.h / 200.0;
    /* reference: int_R2 W dA = 1 exactly (a_d = 7/(4 pi h^2)); the midpoint-like lattice
     * quadrature of a C2 compactly supported function converges far below 1e-6 at h/d = 200 */
    assert_true(fabs(lattice_sum_w(&K, d, 0.0, 0.0) - 1.0) < 1e-6);
    assert_true(fabs(lattice_sum_w(&K, d, 0.37 * d, 0.81 * d) - 1.0) < 1e-6);
}

/* Discrete normalisation: sum_j dx^2 W_ij over a square lattice around a lattice point.
 * Reference: 1 (partition of unity). At the solver's h = 1.3 dx (about 21 neighbours) the
 * lattice quadrature error of Wendland C2 is about 1% (1.0105 here, and a property of the
 * kernel on a square lattice, not of the code: the continuous integral above is 1 to 1e-6),
 * so the 1e-3 asked for in the issue only holds with more neighbours; both are checked. */
static void test_lattice_sum_is_one(void **state)
{
    (void)state;
    const double dx = 0.01;
    const struct kernel K13 = kernel_make(1.3 * dx), K30 = kernel_make(3.0 * dx);
    const double s13 = lattice_sum_w(&K13, dx, 0.0, 0.0), s30 = lattice_sum_w(&K30, dx, 0.0, 0.0);
    print_message("lattice sum of dx^2 W: %.9f at h = 1.3 dx, %.9f at h = 3 dx\n", s13, s30);
    /* reference 1; tolerance 1.5e-2: the lattice error at h = 1.3 dx (1.05e-2) with margin */
    assert_true(fabs(s13 - 1.0) < 1.5e-2);
    /* reference 1; tolerance 1e-3 (issue), reached with h = 3 dx (about 113 neighbours) */
    assert_true(fabs(s30 - 1.0) < 1e-3);
}

/* SPH gradient of f = a x + b z at a lattice point, h/dx given. */
static void sph_gradient(double h_over_dx, double a, double b, double *gx, double *gz)
{
    const double dx = 0.01, f0 = 3.0;
    const struct kernel K = kernel_make(h_over_dx * dx);
    const double xi = 10 * dx, zi = 7 * dx; /* a lattice point */
    const double fi = f0 + a * xi + b * zi;
    const int n = (int)ceil(2.0 * h_over_dx) + 1;
    *gx = *gz = 0.0;
    for (int l = -n; l <= n; l++) {
        for (int k = -n; k <= n; k++) {
            const double xj = xi + k * dx, zj = zi + l * dx;
            const double rx = xi - xj, rz = zi - zj;
            const double F = kernel_f(&K, hypot(rx, rz));
            const double fj = f0 + a * xj + b * zj;
            *gx += dx * dx * (fj - fi) * F * rx;
            *gz += dx * dx * (fj - fi) * F * rz;
        }
    }
}

/* SPH gradient of a linear field f = a x + b z at an interior lattice point:
 *   <grad f>_i = sum_j V_j (f_j - f_i) grad_i W_ij,  grad_i W_ij = F(r_ij) (x_i - x_j).
 * Sign: in the continuum, int (f(x') - f(x)) grad_x W(x - x') dx' = -int (f(x') - f(x))
 * grad_x' W dx' = +int W grad f dx' = grad f (integration by parts, W vanishing at 2h), so the
 * estimate is +grad f = (a, b), scaled on a lattice by the diagonal of
 * sum_j V_j (x_j - x_i) (x) grad_i W_ij, which tends to I. */
static void test_gradient_of_linear_field(void **state)
{
    (void)state;
    const double a = 2.5, b = -1.75;
    double gx, gz, gx30, gz30, ux, uz;
    sph_gradient(1.3, a, b, &gx, &gz);
    sph_gradient(3.0, a, b, &gx30, &gz30);
    print_message("SPH gradient of (%g x %+g z): (%.9f, %.9f) at h = 1.3 dx, (%.9f, %.9f) at h = 3 dx\n", a, b, gx,
                  gz, gx30, gz30);
    /* reference (a, b); tolerance 3%: the lattice error of the uncorrected gradient at h = 1.3 dx
     * (the diagonal of sum_j V_j (x_j - x_i) (x) grad W is 0.974 there; the 1e-3 needs
     * more neighbours or the L_i^-1 correction of docs/model.md section 5) */
    assert_true(fabs(gx - a) < 3e-2 * fabs(a));
    assert_true(fabs(gz - b) < 3e-2 * fabs(b));
    /* reference (a, b); tolerance 1e-3 relative (issue), reached with h = 3 dx */
    assert_true(fabs(gx30 - a) < 1e-3 * fabs(a));
    assert_true(fabs(gz30 - b) < 1e-3 * fabs(b));
    /* the lattice is symmetric: the gradient of f = x has no z component and the same gain in x
     * and z (reference: exact by symmetry; tolerance: round-off of ~50 terms) */
    sph_gradient(1.3, 1.0, 0.0, &ux, &uz);
    assert_true(fabs(uz) < 1e-12);
    assert_true(fabs(gx / a - gz / b) < 1e-12);
    assert_true(fabs(ux - gx / a) < 1e-12);
}

/* Compact support: W = F = 0 for r >= 2h, W > 0 just inside. */
static void test_support(void **state)
{
    (void)state;
    const struct kernel K = kernel_make(0.013);
    const double r2h = 2.0 * K.h;
    assert_true(kernel_w(&K, r2h) == 0.0);
    assert_true(kernel_f(&K, r2h) == 0.0);
    assert_true(kernel_w(&K, 1.5 * r2h) == 0.0);
    assert_true(kernel_f(&K, 1.5 * r2h) == 0.0);
    assert_true(kernel_w(&K, 100.0) == 0.0);
    assert_true(kernel_w(&K, 0.99 * r2h) > 0.0);
    assert_true(kernel_f(&K, 0.99 * r2h) < 0.0); /* W decreasing: F = W'/r < 0 inside */
    assert_true(K.r2max == 4.0 * K.h * K.h);
}

/* F(r) = W'(r) / r against a central finite difference of W, over the whole support;
 * F continuous at 2h (goes to 0), finite at r = 0 (W'(0) = 0); W(0) and F(0) from the formulas
 * in kernel.h. */
static void check_derivative(int type, double w0_coef, double f0_coef, double end_order)
{
    const struct kernel K = kernel_make_type(0.013, type);
    const double h = K.h;
    for (int k = 1; k < 40; k++) {
        const double r = k * 2.0 * h / 40.0, e = 1e-6 * h;
        if (type == KERNEL_CUBIC_SPLINE && fabs(r - h) < 2.0 * e) continue; /* W'' jumps at q = 1 */
        const double dw = (kernel_w(&K, r + e) - kernel_w(&K, r - e)) / (2.0 * e);
        const double F = kernel_f(&K, r);
        /* reference: analytic W'(r)/r; tolerance 1e-6 relative to max |F| = |F(0)|, the
         * truncation (e^2 W''') plus round-off (eps W / e) of the central difference */
        assert_true(fabs(F - dw / r) < 1e-6 * fabs(kernel_f(&K, 0.0)));
    }
    /* W(0) = a_d w0_coef with a_d the normalisation of kernel.h */
    assert_true(fabs(kernel_w(&K, 0.0) - w0_coef / (GEOM_PI * h * h)) < 1e-12 * kernel_w(&K, 0.0));
    /* F(0) finite, so W'(r) = F r -> 0 at r = 0 */
    const double f0 = kernel_f(&K, 0.0);
    assert_true(isfinite(f0));
    assert_true(fabs(f0 - f0_coef / (GEOM_PI * h * h) / (h * h)) < 1e-12 * fabs(f0));
    assert_true(fabs(kernel_f(&K, 1e-9 * h) - f0) < 1e-8 * fabs(f0));
    /* continuity at 2h: F(2h - e) -> 0 like e^end_order */
    const double fe = kernel_f(&K, 2.0 * h * (1.0 - 1e-4));
    assert_true(fabs(fe) < 10.0 * pow(1e-4, end_order) * fabs(f0));
    assert_true(fabs(kernel_w(&K, 2.0 * h * (1.0 - 1e-4))) < 1e-11 * kernel_w(&K, 0.0));
}

static void test_derivative_cubic_spline(void **state)
{
    (void)state;
    /* W(0) = 10/(7 pi h^2); F(0) = -3 * 10/(7 pi h^2) / h^2; F ~ (2 - q)^2 at the edge */
    check_derivative(KERNEL_CUBIC_SPLINE, 10.0 / 7.0, -30.0 / 7.0, 2.0);
}

static void test_derivative_wendland(void **state)
{
    (void)state;
    /* W(0) = 7/(4 pi h^2); F(0) = -5 * 7/(4 pi h^2) / h^2; F ~ (1 - q/2)^3 at the edge */
    check_derivative(KERNEL_WENDLAND_C2, 7.0 / 4.0, -35.0 / 4.0, 3.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_integral_is_one),
        cmocka_unit_test(test_lattice_sum_is_one),
        cmocka_unit_test(test_gradient_of_linear_field),
        cmocka_unit_test(test_support),
        cmocka_unit_test(test_derivative_cubic_spline),
        cmocka_unit_test(test_derivative_wendland),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
