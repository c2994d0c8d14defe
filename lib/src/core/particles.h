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

struct particles {
    size_t n, cap;
    unsigned features;    /* PARTICLE_FEATURE_* of the simulation: the table rows it has (set before
                           * the first particles_alloc; the arrays of the other rows stay NULL) */
    double *pos[DIM];    /* position [m] */
    double *vel[DIM];  /* velocity [m/s]; walls: the wall's prescribed velocity */
    double *uv[DIM]; /* velocity seen by viscous terms [m/s]: walls: no-slip mirror velocity */
    double *rho;          /* density [kg/m3] */
    double *p;            /* pressure [Pa]; walls: extrapolated (Adami et al. 2012) */
    double *m;            /* mass [kg] (per unit depth in 2D) */
    double *vol;          /* volume m/rho [m^DIM, per unit depth in 2D] */
    double *mu;           /* dynamic viscosity [Pa s] */
    double *acc[DIM]; /* acceleration [m/s2] */
    double *drho;         /* density rate [kg/m3/s] */
    double *tag;          /* medium index as a number, -1 for walls (branch-free pair loops) */
    double *inv_rho;      /* 1 / rho [m3/kg] */
    double *inv_m;        /* 1 / m [1/kg]; 0 for walls (they take no acceleration) */
    double *avc;          /* alpha_M c h of the particle's medium [m2/s]; 0 if no artificial viscosity */
    double *visc_dv[DIM];   /* velocity change of the last implicit viscous
                                                      * step [m/s] (its warm start) */
    double *visc_d1[DIM];   /* ... of that step's first stage (viscous.h) [m/s] */
    double *visc_dvp[DIM]; /* visc_dv of the step before the last (the warm
                                                       * starts' linear extrapolation) [m/s] */
    double *visc_d1p[DIM]; /* visc_d1 of the step before the last [m/s] */
    double *stress[SYM_N]; /* deviatoric stress [Pa] (tension positive), SYM_N components in the
                               * order of dim.h (in 2D with the out-of-plane yy of plane strain);
                               * laws with LAW_HAS_STRESS, 0 elsewhere and on walls */
    double *wall_rough;   /* wall particles: 1 on a no-slip wall, 0 on a free-slip one; 0 for the
                           * others [-] (a wall's friction applies to rough walls only) */
    double *wall_n[DIM]; /* free-slip wall particles: their wall's unit normal toward the fluid
                          * (walls_set_normals), across which they mirror the fluid's velocity and
                          * the stress of the solid they meet (no shear); 0 for the others (a
                          * no-slip wall takes the stress as it is) */
    double *wall_friction; /* wall particles: tan(delta) of their wall's friction angle on every medium, or
                            * -1 where the wall takes the friction angle of the grains it meets, -2 where
                            * it bounds nothing; 0 for the others [-] (docs/model.md [BF]); the momentum
                            * pass reads it unless some wall gives its media different angles */
    double *pore_p;       /* grains: the pore pressure p_w [PW] >= 0 their law's last update measured,
                           * which the bed friction's normal force leaves out [Pa]; 0 for the others */
    uint8_t *medium;      /* index into the case's media; for wall particles the wall's index
                           * (read it through particles_wall_index) */
    uint8_t *state;       /* MIXSPH_STATE_* */
    uint16_t *nneigh;     /* neighbours of the same medium within 2h (last force pass) */
    uint32_t *id;         /* stable id */
    uint32_t *image_of;   /* a mirror image (3D mirror side walls, walls/mirror_sides.h): 1 + the id of
                           * the particle it images; 0 for the others; NULL without mirror side walls */
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

/** Whether particle i is a mirror image (walls/mirror_sides.h), not a particle of the run. */
static inline int particles_is_image(const struct particles *P, size_t i) { return P->image_of && P->image_of[i] != 0; }

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
