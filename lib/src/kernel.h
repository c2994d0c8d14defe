/* kernel.h - Wendland C2 kernel in 2D with compact support 2h (MODEL.md section 1).
 *
 *   W(r, h)   = a_d (1 - q/2)^4 (2q + 1),  q = r/h in [0, 2],  a_d = 7 / (4 pi h^2)
 *   grad_i W  = F(r) (x_i - x_j),          F = -5 a_d / h^2 (1 - q/2)^3
 *
 * F is the scalar the pair loops use: the gradient is F times the separation vector, so
 * no division by r is needed. */
#ifndef MIXSPH_KERNEL_H
#define MIXSPH_KERNEL_H
#include <math.h>

#define KERNEL_PI 3.14159265358979323846

struct kernel {
    double h;      /* smoothing length [m] */
    double h2;     /* h^2 */
    double r2max;  /* (2h)^2: squared support radius */
    double a_d;    /* normalisation 7/(4 pi h^2) */
    double f_fac;  /* -5 a_d / h^2 */
};

static inline struct kernel kernel_make(double h)
{
    struct kernel k;
    k.h = h;
    k.h2 = h * h;
    k.r2max = 4.0 * h * h;
    k.a_d = 7.0 / (4.0 * KERNEL_PI * h * h);
    k.f_fac = -5.0 * k.a_d / (h * h);
    return k;
}

/** W at distance r (0 beyond 2h). */
static inline double kernel_w(const struct kernel *k, double r)
{
    const double q = r / k->h;
    if (q >= 2.0) return 0.0;
    const double s = 1.0 - 0.5 * q;
    const double s2 = s * s;
    return k->a_d * s2 * s2 * (2.0 * q + 1.0);
}

/** F(r) with grad_i W = F (x_i - x_j) (0 beyond 2h). */
static inline double kernel_f(const struct kernel *k, double r)
{
    const double q = r / k->h;
    if (q >= 2.0) return 0.0;
    const double s = 1.0 - 0.5 * q;
    return k->f_fac * s * s * s;
}

#endif
