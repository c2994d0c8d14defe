/* mu_i.c - the rate-dependent friction mu(I) of the elastic-plastic law and its closed-form
 * plastic shear rate; the equations and references are in mu_i.h and docs/model.md [MI]. */
#include <math.h>

#include "mu_i.h"

double mu_i_friction(double I, double mu_s, double delta_mu, double I0)
{
    return mu_s + delta_mu * I / (I + I0);
}

double mu_i_inertial_number(double gamma_p, double d, double p_eff, double rho_s)
{
    return gamma_p * d / sqrt(p_eff / rho_s);
}

double mu_i_plastic_shear_rate(double excess, double g_dt, double dmu_p, double xi)
{
    if (isinf(xi)) return excess / g_dt;
    const double b = excess - g_dt * xi - dmu_p;
    const double root = sqrt(b * b + 4.0 * excess * g_dt * xi);
    return b >= 0.0 ? (b + root) / (2.0 * g_dt) : 2.0 * excess * xi / (root - b);
}

double mu_i_strength_increment(double tau_trial, double static_strength, double p_eff, double g_dt, double d,
                               double rho_s, const struct mu_i_params *m)
{
    const double excess = tau_trial - static_strength;
    if (!(excess > 0.0) || !(p_eff > 0.0) || !(d > 0.0) || !(m->delta_mu > 0.0)) return 0.0;
    const double dmu_p = m->delta_mu * p_eff;
    const double xi = m->I0 * sqrt(p_eff / rho_s) / d; /* the shear rate at I = I0 */
    const double gamma = mu_i_plastic_shear_rate(excess, g_dt, dmu_p, xi);
    return dmu_p * gamma / (gamma + xi);
}
