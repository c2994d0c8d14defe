/* kernel.h - the SPH kernels in DIM dimensions with compact support 2h (docs/model.md section 1),
 * q = r/h; the normalisation a_d makes W integrate to 1 over the plane (2D) or space (3D):
 *
 * cubic B-spline (default; the kernel of SPHERA), a_d = 10 / (7 pi h^2) in 2D, 1 / (pi h^3) in 3D:
 *   W = a_d (1 - 3/2 q^2 + 3/4 q^3)   q < 1        F = a_d/h^2 (-3 + 9/4 q)
 *   W = a_d/4 (2 - q)^3               1 <= q < 2   F = -3/4 a_d/h^2 (2 - q)^2 / q
 * Wendland C2, a_d = 7 / (4 pi h^2) in 2D, 21 / (16 pi h^3) in 3D:
 *   W = a_d (1 - q/2)^4 (2q + 1)                   F = -5 a_d/h^2 (1 - q/2)^3
 *
 * grad_i W = F (x_i - x_j): F is the scalar the pair loops use (no division by r needed).
 * On a square lattice with h = 1.3 dx the SPH gradient of a linear field comes out at 1.0105 of
 * the exact one with the cubic spline and at 0.974 with Wendland C2; the hydrostatic pressure a
 * column settles to is off by about the inverse (-1% and +4%), hence the default.
 *
 * This is the only implementation of the kernel: every loop (the vectorised pair loops of
 * forces.c, the wall extrapolation, the pressure of fixed grains) calls kernel_w_q / kernel_f_q.
 * They are written without branches (selects, 0 beyond 2h) so that they vectorise inside
 * `omp simd` loops; `wendland` is meant to be a compile-time constant at the call (loops are
 * specialised per kernel once, outside the loop), kernel_w / kernel_f dispatch at run time. */
#ifndef MIXSPH_KERNEL_H
#define MIXSPH_KERNEL_H
#include <math.h>

#include "dim.h"
#include "geometry.h"

enum kernel_type { KERNEL_CUBIC_SPLINE = 0, KERNEL_WENDLAND_C2 = 1 };

struct kernel {
    int type;      /* enum kernel_type */
    double h;      /* smoothing length [m] */
    double inv_h;  /* 1 / h [1/m] */
    double r2max;  /* (2h)^2: squared support radius [m2] */
    double a_d;    /* normalisation of W [1/m^DIM] */
    double f_fac;  /* a_d / h^2 times the law's leading factor (see kernel_f_q) [1/m^(DIM+2)] */
};

static inline struct kernel kernel_make_type(double h, int type)
{
    struct kernel k;
    k.type = type;
    k.h = h;
    k.inv_h = 1.0 / h;
    k.r2max = 4.0 * h * h;
#if DIM == 2
    k.a_d = type == KERNEL_WENDLAND_C2 ? 7.0 / (4.0 * GEOM_PI * h * h) : 10.0 / (7.0 * GEOM_PI * h * h);
#else
    k.a_d = type == KERNEL_WENDLAND_C2 ? 21.0 / (16.0 * GEOM_PI * h * h * h) : 1.0 / (GEOM_PI * h * h * h);
#endif
    k.f_fac = (type == KERNEL_WENDLAND_C2 ? -5.0 * k.a_d : k.a_d) / (h * h);
    return k;
}

/** The default kernel (cubic B-spline). */
static inline struct kernel kernel_make(double h) { return kernel_make_type(h, KERNEL_CUBIC_SPLINE); }

/** q = r / h of a squared distance. */
static inline double kernel_q(const struct kernel *k, double r2) { return sqrt(r2) * k->inv_h; }

/** W at q = r/h (0 for q >= 2), branch-free. */
static inline double kernel_w_q(const struct kernel *k, double q, const int wendland)
{
    if (wendland) {
        double s = 1.0 - 0.5 * q;
        s = s > 0.0 ? s : 0.0;
        return k->a_d * s * s * s * s * (2.0 * q + 1.0);
    }
    double t = 2.0 - q;
    t = t > 0.0 ? t : 0.0;
    const double inner = 1.0 - 1.5 * q * q + 0.75 * q * q * q, outer = 0.25 * t * t * t;
    return k->a_d * (q < 1.0 ? inner : outer);
}

/** F at q = r/h with grad_i W = F (x_i - x_j) (0 for q >= 2), branch-free. */
static inline double kernel_f_q(const struct kernel *k, double q, const int wendland)
{
    if (wendland) {
        double s = 1.0 - 0.5 * q;
        s = s > 0.0 ? s : 0.0;
        return k->f_fac * s * s * s;
    }
    double t = 2.0 - q;
    t = t > 0.0 ? t : 0.0;
    const double inner = -3.0 + 2.25 * q;
    const double outer = -0.75 * t * t / (q > 1.0 ? q : 1.0);
    return k->f_fac * (q < 1.0 ? inner : outer);
}

/** W at distance r (0 from 2h on: q = r / h is exact at r = 2h), for the kernel's own type. */
static inline double kernel_w(const struct kernel *k, double r)
{
    const double q = r / k->h;
    return k->type == KERNEL_WENDLAND_C2 ? kernel_w_q(k, q, 1) : kernel_w_q(k, q, 0);
}

/** F(r) with grad_i W = F (x_i - x_j) (0 from 2h on), for the kernel's own type. */
static inline double kernel_f(const struct kernel *k, double r)
{
    const double q = r / k->h;
    return k->type == KERNEL_WENDLAND_C2 ? kernel_f_q(k, q, 1) : kernel_f_q(k, q, 0);
}

#endif
