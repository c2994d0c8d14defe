/* elasticity.h - isotropic hypoelasticity (plane strain in 2D), shared by the laws with a stress
 * state (elastic_solid.c, and the elastic trial of drucker_prager.c): the deviatoric stress, its
 * Jaumann-rate update, the constants from E and nu and the P-wave speed; pure functions.
 *
 * Conventions: Cauchy stress, tension positive; sigma = s - p I with s the deviator (traceless
 * over the three normal components; in 2D s_yy out of plane) and p > 0 in compression.
 *
 * Elastic step, Jaumann rate (Bui et al. 2008):
 *   ds/dt = 2 G D' + W s - s W,   D = (L + L^T)/2, W = (L - L^T)/2, L_ab = du_a/dx_b,
 *   D' = D - tr(D)/3 I with the 3D trace (in 2D D_yy = 0, so D'_yy = -tr(D)/3),
 * the spin integrated as a finite rotation s <- Q s Q^T + 2 G D' dt,
 *   Q = (I - W dt/2)^-1 (I + W dt/2)  (Hughes & Winget 1980; in 3D the Cayley-Rodrigues form
 *   Q = I + 2 (A + A^2) / (1 + |a|^2), A = W dt/2 with axial vector a),
 * exactly orthogonal, so a rigid rotation keeps the invariants of s to round-off.
 * K = E / (3 (1 - 2 nu)), G = E / (2 (1 + nu)); c_p = sqrt((K + 4 G/3) / rho). */
#ifndef MIXSPH_ELASTICITY_H
#define MIXSPH_ELASTICITY_H
#include <stddef.h>

#include "dim.h"

/* Largest static strain rho g H / E a case may have: the laws are small-strain ones, and 1 % is
 * the density variation the weakly compressible scheme allows (docs/model.md section 3). */
#define ELASTICITY_STATIC_STRAIN_MAX 0.01

/** The deviatoric stress [Pa], traceless (xx + zz + yy = 0); in 2D (plane strain) xx, zz, xz in
 *  the plane, yy out of it, xy = yz = 0. */
struct deviatoric_stress {
    double xx, zz, xz, yy;
#if DIM == 3
    double xy, yz;
#endif
};

/** The elastic constants of a medium with a stress (the elastic solid, the elastic-plastic law):
 *  read from media.<name> by their key tables, derived by their finish. */
struct elastic_params {
    double youngs_modulus; /* E [Pa] (the elastic solid) */
    double poisson;        /* nu [-] */
    double shear_modulus;  /* G [Pa] */
};

/** Particle i's stress from the stored components (stress[SYM_N], dim.h). */
static inline struct deviatoric_stress deviatoric_stress_load(double *const stress[SYM_N], size_t i)
{
    struct deviatoric_stress s = {.xx = stress[SYM_XX][i], .zz = stress[SYM_ZZ][i], .xz = stress[SYM_XZ][i],
                                  .yy = stress[SYM_YY][i]};
#if DIM == 3
    s.xy = stress[SYM_XY][i];
    s.yz = stress[SYM_YZ][i];
#endif
    return s;
}

/** Store s as particle i's stress. */
static inline void deviatoric_stress_store(const struct deviatoric_stress *s, double *const stress[SYM_N], size_t i)
{
    stress[SYM_XX][i] = s->xx;
    stress[SYM_XZ][i] = s->xz;
    stress[SYM_ZZ][i] = s->zz;
    stress[SYM_YY][i] = s->yy;
#if DIM == 3
    stress[SYM_XY][i] = s->xy;
    stress[SYM_YZ][i] = s->yz;
#endif
}

/** One medium's constants, made by drucker_prager_material. */
/** Bulk modulus K and shear modulus G [Pa] from Young's modulus E [Pa] and Poisson's ratio nu.
 *  NULL when done, else a message saying which value is out of range and why (nothing written). */
const char *elasticity_constants(double E, double nu, double *K, double *G);

/** Shear modulus G [Pa] that Poisson's ratio nu gives with the bulk modulus K [Pa], G = 3 K (1 - 2 nu) /
 *  (2 (1 + nu)): for a law whose pressure comes from the equation of state, K = rho0 c0^2 is fixed
 *  there. NULL when done, else a message saying which value is out of range (nothing written). */
const char *elasticity_shear_from_bulk(double K, double nu, double *G);

/** P-wave speed sqrt((K + 4G/3) / rho) [m/s]. */
double elasticity_wave_speed(double K, double G, double rho);

/** Static strain rho g H / E [-] of a deposit of height H [m]; compare with
 *  ELASTICITY_STATIC_STRAIN_MAX. */
double elasticity_static_strain(double rho, double g, double H, double E);

/** Elastic trial of the deviator over dt [s] (a): s <- Q s Q^T + 2 G D' dt from the velocity
 *  gradient L[a DIM + b] = du_a/dx_b [1/s] (core/velocity_gradient.h) and the shear modulus G [Pa]. */
void elasticity_jaumann_step(struct deviatoric_stress *s, const double L[DIM * DIM], double G, double dt);

/** Volumetric elastic step (for a law that integrates its pressure instead of taking it from the
 *  equation of state): p - K div(u) dt [Pa]. */
double elasticity_pressure_step(double p, const double L[DIM * DIM], double K, double dt);

#endif
