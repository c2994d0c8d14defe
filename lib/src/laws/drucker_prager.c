/* drucker_prager.c - the elastic-perfectly-plastic Drucker-Prager law's constitutive core; the
 * equations, conventions and references are in drucker_prager.h and docs/model.md section 10. */
#include <math.h>

#include "drucker_prager.h"

#include "geometry.h"

const char *drucker_prager_matching(double phi, double c, double psi, double *alpha_phi, double *k_c,
                                    double *alpha_psi)
{
    const double right = 0.5 * GEOM_PI;
    if (!(phi >= 0.0 && phi < right)) return "friction angle phi must lie in [0, 90) degrees";
    if (!(c >= 0.0) || !isfinite(c)) return "cohesion c must be a finite number of pascals, 0 or more";
    if (!(psi >= 0.0 && psi <= phi))
        return "dilatancy angle psi must lie in [0, phi]: a material that dilates faster than its friction allows "
               "has no plane-strain Mohr-Coulomb match";
    if (!(phi > 0.0 || c > 0.0)) return "phi = 0 and c = 0 leave the material no strength: give a friction angle or a cohesion";
    const double tpsi = tan(psi);
    const double apsi = tpsi / sqrt(9.0 + 12.0 * tpsi * tpsi);
    const double root = sqrt(1.0 - 3.0 * apsi * apsi); /* > 0: 3 apsi^2 < 1/4 for any psi < 90 deg */
    const double aphi = sin(phi) / (3.0 * (root + sin(phi) * apsi));
    *alpha_phi = aphi;
    *alpha_psi = apsi;
    *k_c = c * cos(phi) * (1.0 - 3.0 * aphi * apsi) / root;
    return NULL;
}

const char *drucker_prager_material(double E, double nu, double phi, double c, double psi,
                                    struct drucker_prager_material *out)
{
    struct drucker_prager_material m;
    const char *why = elasticity_constants(E, nu, &m.K, &m.G);
    if (!why) why = drucker_prager_matching(phi, c, psi, &m.alpha_phi, &m.k_c, &m.alpha_psi);
    if (!why) *out = m;
    return why;
}

double drucker_prager_sqrt_j2(const struct deviatoric_stress *s)
{
#if DIM == 2
    return sqrt(0.5 * (s->xx * s->xx + s->zz * s->zz + s->yy * s->yy) + s->xz * s->xz);
#else
    return sqrt(0.5 * (s->xx * s->xx + s->zz * s->zz + s->yy * s->yy) + s->xz * s->xz + s->xy * s->xy + s->yz * s->yz);
#endif
}

double drucker_prager_yield(const struct deviatoric_stress *s, double p_eff,
                            const struct drucker_prager_material *m)
{
    return drucker_prager_sqrt_j2(s) - 3.0 * m->alpha_phi * p_eff - m->k_c; /* I1 = -3 p' */
}

enum drucker_prager_outcome drucker_prager_return(struct deviatoric_stress *s, double *p_eff,
                                                  const struct drucker_prager_material *m)
{
    const double f = drucker_prager_yield(s, *p_eff, m);
    if (!(f > 0.0)) return DRUCKER_PRAGER_ELASTIC;
    const double rj2 = drucker_prager_sqrt_j2(s);
    const double dlambda = f / (m->G + 9.0 * m->K * m->alpha_phi * m->alpha_psi);
    const double shrink = m->G * dlambda;
    if (shrink < rj2) {
        const double r = 1.0 - shrink / rj2;
        s->xx *= r;
        s->zz *= r;
        s->xz *= r;
        s->yy *= r;
#if DIM == 3
        s->xy *= r;
        s->yz *= r;
#endif
        *p_eff += 3.0 * m->K * m->alpha_psi * dlambda;
        return DRUCKER_PRAGER_CONE;
    }
    /* The apex: reached only where alpha_phi > 0 (with alpha_phi = 0 the shrink is sqrt(J2) - k_c,
     * below sqrt(J2) for k_c > 0, and k_c = 0 is refused by the matching). */
    s->xx = s->zz = s->xz = s->yy = 0.0;
#if DIM == 3
    s->xy = s->yz = 0.0;
#endif
    *p_eff = -m->k_c / (3.0 * m->alpha_phi);
    return DRUCKER_PRAGER_APEX;
}
