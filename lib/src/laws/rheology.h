/* rheology.h - the mixture viscosity law of Manenti et al. (2018), pure functions.
 *
 *   sqrt(II_D) = sqrt(1/2 (du/dx)^2 + 1/2 (dw/dz)^2 + 1/4 (du/dz + dw/dx)^2)
 *   mu_fr      = sigma' sin(phi) / (2 sqrt(II_D))                       (10)
 *   mu_app     = eps_f mu_f + mu_fr                                     (12), packing limit
 *   sigma'     = max(p - max(p_w, 0), 0)
 *
 * and the three regimes of the paper's Fig. 1 (docs/model.md section 6):
 *   mu_app >= mu_thr        -> elastic-plastic: held fixed, mu = mu_thr
 *   mu0 < mu_app < mu_thr   -> frictional, limited: mobile, mu = mu0
 *   mu_app <= mu0           -> frictional: mobile, mu = mu_app
 * mu0 >= mu_thr switches the limit off; the "mu1" rheology of Run 7 is mu_thr = mu1 without a
 * limit (mu0 = +inf). Where sqrt(II_D) < 1e-12 the apparent viscosity is taken as mu_thr. */
#ifndef MIXSPH_RHEOLOGY_H
#define MIXSPH_RHEOLOGY_H
#include <math.h>

#include "dim.h"

#define RHEOLOGY_II_MIN 1e-12 /* [1/s] below this strain rate the grains are at rest */

enum rheology_regime { RHEOLOGY_FRICTIONAL = 0, RHEOLOGY_LIMITED = 1, RHEOLOGY_FIXED = 2 };

/** sqrt(II_D) [1/s] of the strain rate D = (L + L^T) / 2 from the velocity gradient
 *  L[a DIM + b] = du_a/dx_b: II_D = D_ab D_ab / 2. */
static inline double rheology_sqrt_ii(const double L[DIM * DIM])
{
#if DIM == 2
    const double s = L[1] + L[2];
    return sqrt(0.5 * L[0] * L[0] + 0.5 * L[3] * L[3] + 0.25 * s * s);
#else
    double ii = 0.0;
    for (int a = 0; a < 3; a++) {
        ii += 0.5 * L[4 * a] * L[4 * a];
        for (int b = a + 1; b < 3; b++) {
            const double s = L[3 * a + b] + L[3 * b + a];
            ii += 0.25 * s * s;
        }
    }
    return sqrt(ii);
#endif
}

/** Effective stress sigma' [Pa] from the particle pressure p and the pore pressure p_w. */
static inline double rheology_effective_stress(double p, double p_w)
{
    const double s = p - (p_w > 0.0 ? p_w : 0.0);
    return s > 0.0 ? s : 0.0;
}

/** Apparent viscosity mu_app [Pa s] of (10) and (12); mu_thr where sqrt(II_D) < 1e-12. */
static inline double rheology_apparent(double sigma_eff, double sin_phi, double sqrt_ii, double eps_f_mu_f,
                                       double mu_thr)
{
    if (!(sqrt_ii >= RHEOLOGY_II_MIN)) return mu_thr;
    return eps_f_mu_f + sigma_eff * sin_phi / (2.0 * sqrt_ii);
}

/** The regime of Fig. 1 and the viscosity used [Pa s] (mu0 = INFINITY: no limit). */
static inline enum rheology_regime rheology_regime(double mu_app, double mu_thr, double mu0, double *mu)
{
    if (mu_app >= mu_thr) {
        *mu = mu_thr;
        return RHEOLOGY_FIXED;
    }
    if (mu_app > mu0) {
        *mu = mu0;
        return RHEOLOGY_LIMITED;
    }
    *mu = mu_app;
    return RHEOLOGY_FRICTIONAL;
}

#endif
