/* particles.h - struct-of-arrays particle storage (fluid, granular and wall particles in one
 * set, told apart by `state`), growth and permutation (the cell sort reorders them at each
 * rebuild of the neighbour ranges). Every array member has its row in the particle-field table
 * (particle_fields.c), which everything that treats the fields alike walks: a member without a
 * row is neither allocated nor permuted nor saved (test_particle_fields checks every member has
 * one). */
#ifndef MIXSPH_PARTICLES_H
#define MIXSPH_PARTICLES_H
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "dim.h"

/* A vector field: DIM component arrays. The 2D build still also names them (x, z) while the
 * code moves to components (transitional). */
#if DIM == 2
#define PARTICLES_VECTOR(v, a, b) union { double *v[DIM]; struct { double *a, *b; }; }
#define PARTICLES_STRESS(s) union { double *s[SYM_N]; struct { double *sxx, *sxz, *szz, *syy; }; }
#else
#define PARTICLES_VECTOR(v, a, b) double *v[DIM]
#define PARTICLES_STRESS(s) double *s[SYM_N]
#endif

struct particles {
    size_t n, cap;
    unsigned features;    /* PARTICLE_FEATURE_* of the simulation: the table rows it has (set before
                           * the first particles_alloc; the arrays of the other rows stay NULL) */
    PARTICLES_VECTOR(pos, x, z);    /* position [m] */
    PARTICLES_VECTOR(vel, vx, vz);  /* velocity [m/s]; walls: the wall's prescribed velocity */
    PARTICLES_VECTOR(uv, uvx, uvz); /* velocity seen by viscous terms [m/s]: walls: no-slip mirror velocity */
    double *rho;          /* density [kg/m3] */
    double *p;            /* pressure [Pa]; walls: extrapolated (Adami et al. 2012) */
    double *m;            /* mass [kg] (per unit depth in 2D) */
    double *vol;          /* volume m/rho [m^DIM, per unit depth in 2D] */
    double *mu;           /* dynamic viscosity [Pa s] */
    PARTICLES_VECTOR(acc, ax, az); /* acceleration [m/s2] */
    double *drho;         /* density rate [kg/m3/s] */
    double *tag;          /* medium index as a number, -1 for walls (branch-free pair loops) */
    double *inv_rho;      /* 1 / rho [m3/kg] */
    double *inv_m;        /* 1 / m [1/kg]; 0 for walls (they take no acceleration) */
    double *avc;          /* alpha_M c h of the particle's medium [m2/s]; 0 if no artificial viscosity */
    PARTICLES_VECTOR(visc_dv, visc_dvx, visc_dvz);   /* velocity change of the last implicit viscous
                                                      * step [m/s] (its warm start) */
    PARTICLES_VECTOR(visc_d1, visc_d1x, visc_d1z);   /* ... of that step's first stage (viscous.h) [m/s] */
    PARTICLES_VECTOR(visc_dvp, visc_dvpx, visc_dvpz); /* visc_dv of the step before the last (the warm
                                                       * starts' linear extrapolation) [m/s] */
    PARTICLES_VECTOR(visc_d1p, visc_d1px, visc_d1pz); /* visc_d1 of the step before the last [m/s] */
    PARTICLES_STRESS(stress); /* deviatoric stress [Pa] (tension positive), SYM_N components in the
                               * order of dim.h (in 2D with the out-of-plane yy of plane strain);
                               * laws with LAW_HAS_STRESS, 0 elsewhere and on walls */
    double *wall_rough;   /* wall particles: 1 on a no-slip wall, 0 on a free-slip one; 0 for the
                           * others [-] (a wall's friction applies to rough walls only) */
    PARTICLES_VECTOR(wall_n, wall_nx, wall_nz); /* free-slip wall particles: their wall's unit normal
                                                 * toward the solid, across which they mirror the stress
                                                 * of the solid they meet (no shear); 0 for the others
                                                 * (a no-slip wall takes the stress as it is) */
    double *wall_friction; /* wall particles: tan(delta) of their wall's friction angle, or -1 where
                            * the wall takes the friction angle of the grains it meets; 0 for the
                            * others [-] (docs/model.md [DP-W]) */
    uint8_t *medium;      /* index into the case's media; for wall particles the wall's index
                           * (read it through particles_wall_index) */
    uint8_t *state;       /* MIXSPH_STATE_* */
    uint16_t *nneigh;     /* neighbours of the same medium within 2h (last force pass) */
    uint32_t *id;         /* stable id */
};

/* The array of struct particles at byte offset `member` (a particle_field's member[c]; copied
 * out as bytes: the member is a typed pointer). */
static inline void *particles_array(const struct particles *P, size_t member)
{
    void *a;
    memcpy(&a, (const char *)P + member, sizeof a);
    return a;
}

/** The wall a wall particle belongs to (its `medium` field holds the wall's index). */
static inline size_t particles_wall_index(const struct particles *P, size_t i) { return P->medium[i]; }

/** Allocate room for cap particles (first call: n = 0; later calls grow, keeping the particles),
 *  the arrays of the table's rows present with P->features. Returns 0 on success. */
int particles_alloc(struct particles *P, size_t cap);
void particles_free(struct particles *P);
/** Append one particle at pos with zero velocity and rates; returns its index or (size_t)-1. */
size_t particles_push(struct particles *P, const double pos[DIM], double rho, double m, uint8_t medium,
                      uint8_t state);
/** Reorder: new particle k is old particle perm[k]. `scratch` holds n doubles. */
void particles_permute(struct particles *P, const size_t *perm, void *scratch);
/** Deep copy (dst must be zeroed or freed). Returns 0 on success. */
int particles_copy(struct particles *dst, const struct particles *src);
/** Copy the values of src's n particles into dst (same features, dst->cap >= src->n). */
void particles_copy_values(struct particles *dst, const struct particles *src);

#endif
