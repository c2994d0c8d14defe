/* drucker_prager.c - the elastic-perfectly-plastic Drucker-Prager law's constitutive core; the
 * equations, conventions and references are in drucker_prager.h and docs/model.md section 10. */
#include <math.h>

#include "drucker_prager.h"

#include "geometry.h"

const char *drucker_prager_elastic_constants(double E, double nu, double *K, double *G)
{
    if (!(E > 0.0) || !isfinite(E)) return "Young's modulus E must be a positive finite number of pascals";
    /* K > 0 and G > 0 need -1 < nu < 1/2; nu = 1/2 is the incompressible limit, K infinite */
    if (!(nu > -1.0 && nu < 0.5)) return "Poisson's ratio nu must lie in (-1, 0.5): K and G are positive only there";
    *K = E / (3.0 * (1.0 - 2.0 * nu));
    *G = E / (2.0 * (1.0 + nu));
    return NULL;
}

const char *drucker_prager_shear_from_bulk(double K, double nu, double *G)
{
    if (!(K > 0.0) || !isfinite(K)) return "bulk modulus K must be a positive finite number of pascals";
    if (!(nu > -1.0 && nu < 0.5)) return "Poisson's ratio nu must lie in (-1, 0.5): K and G are positive only there";
    *G = 3.0 * K * (1.0 - 2.0 * nu) / (2.0 * (1.0 + nu));
    return NULL;
}

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
    const char *why = drucker_prager_elastic_constants(E, nu, &m.K, &m.G);
    if (!why) why = drucker_prager_matching(phi, c, psi, &m.alpha_phi, &m.k_c, &m.alpha_psi);
    if (!why) *out = m;
    return why;
}

double drucker_prager_wave_speed(double K, double G, double rho)
{
    return sqrt((K + 4.0 * G / 3.0) / rho);
}

double drucker_prager_dt_bound(double cfl, double h, double speed, double K, double G, double rho)
{
    return cfl * 2.0 * h / (drucker_prager_wave_speed(K, G, rho) + speed);
}

double drucker_prager_static_strain(double rho, double g, double H, double E)
{
    return rho * g * H / E;
}

void drucker_prager_jaumann_deviator(struct drucker_prager_deviator *s, double dudx, double dudz, double dwdx,
                                     double dwdz, double G, double dt)
{
    /* Q = (I - W dt/2)^-1 (I + W dt/2) with W_xz = -W_zx = w: a rotation whose cosine and sine
     * are (1 - b^2)/(1 + b^2) and 2 b/(1 + b^2), b = w dt / 2; Q = [[cq, sq], [-sq, cq]]. */
    const double b = 0.25 * (dudz - dwdx) * dt;
    const double den = 1.0 + b * b;
    const double cq = (1.0 - b * b) / den, sq = 2.0 * b / den;
    /* Q s Q^T of the in-plane block [[xx, xz], [xz, zz]]; yy lies on the rotation axis */
    const double cc = cq * cq, ss = sq * sq, cs = cq * sq;
    const double xx = cc * s->xx + 2.0 * cs * s->xz + ss * s->zz;
    const double zz = ss * s->xx - 2.0 * cs * s->xz + cc * s->zz;
    const double xz = cs * (s->zz - s->xx) + (cc - ss) * s->xz;
    /* 2 G D' dt, D' the deviator of the 3D strain rate (D_yy = 0) */
    const double tr3 = (dudx + dwdz) / 3.0;
    const double g2 = 2.0 * G * dt;
    s->xx = xx + g2 * (dudx - tr3);
    s->zz = zz + g2 * (dwdz - tr3);
    s->xz = xz + g2 * 0.5 * (dudz + dwdx);
    s->yy = s->yy - g2 * tr3;
}

double drucker_prager_pressure_step(double p, double dudx, double dwdz, double K, double dt)
{
    return p - K * (dudx + dwdz) * dt;
}

double drucker_prager_sqrt_j2(const struct drucker_prager_deviator *s)
{
    return sqrt(0.5 * (s->xx * s->xx + s->zz * s->zz + s->yy * s->yy) + s->xz * s->xz);
}

double drucker_prager_yield(const struct drucker_prager_deviator *s, double p_eff,
                            const struct drucker_prager_material *m)
{
    return drucker_prager_sqrt_j2(s) - 3.0 * m->alpha_phi * p_eff - m->k_c; /* I1 = -3 p' */
}

enum drucker_prager_outcome drucker_prager_return(struct drucker_prager_deviator *s, double *p_eff,
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
        *p_eff += 3.0 * m->K * m->alpha_psi * dlambda;
        return DRUCKER_PRAGER_CONE;
    }
    /* The apex: reached only where alpha_phi > 0 (with alpha_phi = 0 the shrink is sqrt(J2) - k_c,
     * below sqrt(J2) for k_c > 0, and k_c = 0 is refused by the matching). */
    s->xx = s->zz = s->xz = s->yy = 0.0;
    *p_eff = -m->k_c / (3.0 * m->alpha_phi);
    return DRUCKER_PRAGER_APEX;
}
