/* drucker_prager.h - the constitutive core of the elastic-perfectly-plastic granular law
 * (docs/model.md section 10): pure functions of one particle's stress, no globals, no allocation.
 *
 * Conventions. Plane strain in the (x, z) plane: the strain rate has no y component, the stress
 * has the out-of-plane normal component yy and no xy, yz. Cauchy stress, TENSION POSITIVE; the
 * pressure is positive in compression, p = -tr(sigma)/3 with the trace over all three normal
 * components. The stress is carried split, as the law uses it:
 *   sigma = s - p I,   s the deviator (s_xx + s_zz + s_yy = 0), p from the equation of state.
 * The yield condition and the return mapping act on the EFFECTIVE stress sigma' = s - p' I, whose
 * pressure p' = p - p_b - p_w the caller forms (p_b the background pressure, p_w the pore pressure
 * of a saturated medium, docs/model.md [PW]; the pore water carries no shear, so s is shared).
 *
 * (a) Elastic trial step, hypoelastic with the Jaumann rate (Bui et al. 2008):
 *       ds/dt = 2 G D' + W s - s W,   dp/dt = -K tr(D)
 *     D = (L + L^T)/2, W = (L - L^T)/2, L_ab = du_a/dx_b, D' = D - tr(D)/3 I (3D trace: D'_yy =
 *     -tr(D)/3 != 0 in plane strain). The spin term is integrated as a finite rotation,
 *       s_{n+1} = Q s_n Q^T + 2 G D' dt,   Q = (I - W dt/2)^-1 (I + W dt/2)
 *     (Hughes & Winget 1980): Q is exactly orthogonal, so a rigid rotation keeps the invariants
 *     of s to round-off (explicit Euler of W s - s W would grow |s| by (1 + (w dt)^2) per step);
 *     Q rotates by 2 atan(w dt/2) = w dt (1 - (w dt)^2/12 + ...), w = (du/dz - dw/dx)/2.
 *
 * (b) Drucker-Prager yield function, I1 = tr(sigma') = -3 p', J2 = s:s/2 (three normal components):
 *       f = sqrt(J2) + alpha_phi I1 - k_c,   plastic potential g = sqrt(J2) + alpha_psi I1.
 *     Matching, plane strain, Mohr-Coulomb at the limit state for the chosen dilatancy:
 *       alpha_psi = tan(psi) / sqrt(9 + 12 tan^2 psi)
 *       alpha_phi = sin(phi) / (3 (sqrt(1 - 3 alpha_psi^2) + sin(phi) alpha_psi))
 *       k_c       = c cos(phi) (1 - 3 alpha_phi alpha_psi) / sqrt(1 - 3 alpha_psi^2)
 *     Why: in plane-strain plastic flow at stationary stress the out-of-plane plastic strain rate
 *     is zero, so dg/dsigma_yy = 0, i.e. s_yy = -2 alpha_psi sqrt(J2). On that state f = 0 is
 *     exactly the Mohr-Coulomb line (sigma1 - sigma3)/2 = -(sigma1 + sigma3)/2 sin(phi) + c cos(phi)
 *     of the in-plane principal stresses, for any psi (derivation in docs/model.md section 10;
 *     Drucker & Prager 1952; Vermeer & de Borst 1984). psi = phi (associated) gives the usual
 *     alpha_phi = tan(phi)/sqrt(9 + 12 tan^2 phi), k_c = 3 c/sqrt(9 + 12 tan^2 phi) (Bui et al.
 *     2008; SPHinXsys); psi = 0 (the default, non-associated) gives alpha_phi = sin(phi)/3,
 *     k_c = c cos(phi). The associated formula used with psi = 0 would fail in plane strain at
 *     sin(phi_eff) = 3 tan(phi)/sqrt(9 + 12 tan^2 phi) (33.0 deg for phi = 35 deg), which is why
 *     the match follows psi. Ranges: 0 <= phi < 90 deg, 0 <= psi <= phi, c >= 0, phi > 0 or c > 0.
 *
 * (c) Return mapping (backward Euler, exact for the cone, perfectly plastic; de Souza Neto, Peric &
 *     Owen 2008, ch. 8, Drucker-Prager), for a trial state with f > 0:
 *       dlambda = f / (G + 9 K alpha_phi alpha_psi)
 *       s  <- s (1 - G dlambda / sqrt(J2)),   I1 <- I1 - 9 K alpha_psi dlambda   (p' up by 3 K alpha_psi dlambda)
 *     and, where G dlambda >= sqrt(J2) (the return would pass the cone's tip), the apex with the
 *     tension cut-off: s = 0, I1 = k_c / alpha_phi (p' = -k_c/(3 alpha_phi): zero for c = 0).
 *     With psi = 0 the cone return leaves p' unchanged; a trial beyond the apex in I1 then always
 *     goes to the apex. With psi > 0 the return changes p'; a caller that takes p from the equation
 *     of state must carry that plastic volume change into its density (or keep psi = 0), else it is
 *     lost at the next step.
 *
 * (d) Isotropic elasticity: K = E / (3 (1 - 2 nu)), G = E / (2 (1 + nu)), -1 < nu < 1/2, E > 0.
 * (e) P-wave speed c_p = sqrt((K + 4 G/3) / rho); with the pressure from a linear equation of state
 *     of sound speed c0, K = rho0 c0^2 (c_p^2 = c0^2 + 4 G / (3 rho)). Time step bound of the form of
 *     the paper's acoustic criterion (4), docs/model.md section 4: dt <= cfl 2 h / (c_p + |u|).
 * Static strain of a deposit of height H: eps = rho g H / E, to stay below
 * ELASTICITY_STATIC_STRAIN_MAX (small-strain hypoelasticity). */
#ifndef MIXSPH_DRUCKER_PRAGER_H
#define MIXSPH_DRUCKER_PRAGER_H

#include "elasticity.h"


struct drucker_prager_material {
    double K, G;      /* bulk and shear modulus [Pa] */
    double alpha_phi; /* friction coefficient of the cone [-] */
    double k_c;       /* cohesion of the cone [Pa] */
    double alpha_psi; /* dilatancy coefficient of the plastic potential [-] */
};

/** What the return mapping did. */
enum drucker_prager_outcome {
    DRUCKER_PRAGER_ELASTIC = 0, /* inside or on the cone: untouched */
    DRUCKER_PRAGER_CONE = 1,    /* returned onto the cone's mantle */
    DRUCKER_PRAGER_APEX = 2     /* returned to the apex: tension cut-off */
};

/** Plane-strain matched cone (b) from the friction angle phi [rad], cohesion c [Pa] and dilatancy
 *  angle psi [rad]. NULL when done, else a message naming the value out of range (nothing written). */
const char *drucker_prager_matching(double phi, double c, double psi, double *alpha_phi, double *k_c,
                                    double *alpha_psi);

/** All constants of a medium from E [Pa], nu, phi [rad], c [Pa], psi [rad]: NULL when done, else the
 *  message of the first check that failed (out untouched). */
const char *drucker_prager_material(double E, double nu, double phi, double c, double psi,
                                    struct drucker_prager_material *out);

/** sqrt(J2) [Pa] of a deviator, J2 = (s_xx^2 + s_zz^2 + s_yy^2)/2 + s_xz^2. */
double drucker_prager_sqrt_j2(const struct deviatoric_stress *s);

/** Yield function f [Pa] of (b) at deviator s and effective pressure p_eff [Pa] (compression
 *  positive): f <= 0 inside or on the cone. */
double drucker_prager_yield(const struct deviatoric_stress *s, double p_eff,
                            const struct drucker_prager_material *m);

/** Return mapping (c) of the effective trial state (s, *p_eff) in place. */
enum drucker_prager_outcome drucker_prager_return(struct deviatoric_stress *s, double *p_eff,
                                                  const struct drucker_prager_material *m);

#endif
