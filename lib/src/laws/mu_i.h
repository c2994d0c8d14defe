/* mu_i.h - the rate-dependent friction of the elastic-plastic granular law (docs/model.md
 * section 10, [MI]): the local mu(I) rheology (GDR MiDi 2004; Jop, Forterre & Pouliquen 2006)
 * put into the return mapping as an elasto-viscoplastic update solved in closed form per
 * particle (Dunatunga & Kamrin 2015, JFM 779:483). Pure functions of one particle; no globals.
 *
 * Friction coefficient of the inertial number I = gamma_p d / sqrt(p' / rho_s):
 *   mu(I) = mu_s + delta_mu / (1 + I0 / I) = mu_s + delta_mu I / (I + I0),
 * with mu the ratio sqrt(J2) / p' (drucker_prager.h: J2 = s:s/2 over the three normal components),
 * gamma_p the plastic shear rate [1/s] (the engineering shear rate of a simple shear: a deviator
 * relaxes by G dt gamma_p in sqrt(J2)), d the grain diameter [m], rho_s the grains' density.
 * mu_s is the static cone's 3 alpha_phi (psi = 0: sin(phi), the plane-strain match), so I -> 0 is
 * the rate-independent law.
 *
 * The update. After the elastic trial step, with tau_tr = sqrt(J2) of the trial deviator and the
 * static strength S_s = mu_s p' + k_c: a trial with tau_tr <= S_s is elastic. Otherwise the
 * plastic shear rate of the step gamma solves
 *   tau_tr - G dt gamma = S_s + delta_mu p' gamma / (gamma + xi),   xi = I0 sqrt(p' / rho_s) / d,
 * (I / (I + I0) = gamma / (gamma + xi)), i.e. with A = tau_tr - S_s > 0, B = G dt,
 *   B gamma^2 - b gamma - A xi = 0,   b = A - B xi - delta_mu p'.
 * The product of its roots is -A xi / B < 0: exactly one is positive, the consistent one (the
 * negative one would stiffen the trial), gamma = (b + sqrt(b^2 + 4 A B xi)) / (2 B), taken as
 * 2 A xi / (sqrt(b^2 + 4 A B xi) - b) where b < 0 (no cancellation). The deviator then returns
 * onto the cone of strength S_s + dS, dS = delta_mu p' gamma / (gamma + xi) (0 <= dS < A), which
 * the caller does with drucker_prager_return and the cohesion k_c + dS: dS = 0 (delta_mu = 0,
 * d = 0 or p' <= 0) is then the rate-independent return itself, bit for bit. */
#ifndef MIXSPH_MU_I_H
#define MIXSPH_MU_I_H

/** The rate part of the friction (read from media.<name> by the elastic-plastic law's keys). */
struct mu_i_params {
    int on;          /* the friction depends on the inertial number (else the static cone alone) */
    double delta_mu; /* mu_2 - mu_s [-] */
    double I0;       /* I_0 [-] */
};

/** mu(I) [-] of the static coefficient mu_s, delta_mu = mu_2 - mu_s and I0 at inertial number I >= 0. */
double mu_i_friction(double I, double mu_s, double delta_mu, double I0);

/** The inertial number I [-] of a plastic shear rate gamma_p [1/s], grain diameter d [m], effective
 *  pressure p_eff > 0 [Pa] and grains' density rho_s [kg/m3]. */
double mu_i_inertial_number(double gamma_p, double d, double p_eff, double rho_s);

/** The step's plastic shear rate gamma [1/s] (the positive root above) of a trial whose sqrt(J2)
 *  exceeds the static strength by excess > 0 [Pa], with G dt = g_dt [Pa s], rate strength
 *  delta_mu p_eff = dmu_p [Pa] and xi [1/s]; the rate-independent A / B when xi is infinite. */
double mu_i_plastic_shear_rate(double excess, double g_dt, double dmu_p, double xi);

/** The strength [Pa] the rate adds to the static cone this step, dS above: 0 when the trial's
 *  sqrt(J2) tau_trial [Pa] is within the static strength [Pa], when p_eff <= 0 or d = 0. */
double mu_i_strength_increment(double tau_trial, double static_strength, double p_eff, double g_dt, double d,
                               double rho_s, const struct mu_i_params *m);

#endif
