/* forces.h - the pair loops of the balance equations (docs/model.md sections 2 and 7): the
 * density rate (continuity), the velocity gradient of the grains, the momentum rate, and
 * SPHERA's partial pressure smoothing. They run over the particles sorted by cell and their
 * neighbour ranges (neighbours.h); the threading and the kernel-factor cache are private to
 * forces.c. A viscous solver or another momentum treatment plugs in here. */
#ifndef MIXSPH_FORCES_H
#define MIXSPH_FORCES_H
#include <stddef.h>
#include <stdint.h>

#include "bed_friction.h"
#include "case.h"
#include "cells.h"
#include "kernel.h"
#include "neighbours.h"
#include "numerics_keys.h"
#include "particles.h"
#include "velocity_gradient.h"

/* Entries past the active rows that a per-particle array handed to a pass must hold, finite and
 * neutral (the chunked pair loops read them with zero weight). */
#define FORCES_PAD 16

/* Constants of the pair terms: what the creation derives for them (sim.c), then the `numerics` keys
 * whose rows of core/numerics_keys.def are read by PAIR, as the members those rows name. */
struct forces_params {
    struct kernel K;
    double eta2;        /* eta^2 of the Morris and Monaghan terms [m2] */
    double g;           /* gravity [m/s2] */
    int stress;             /* the momentum pass adds the divergence of the particles' deviatoric
                               stress (P->stress; a law with LAW_HAS_STRESS) */
    int bed_friction;       /* the momentum pass replaces the shear of no-slip walls on grains by their
                               Coulomb friction (bed_friction.h) where a grain's law asks for it
                               (LAW_WALL_FRICTION, LAW_WALL_FRICTION_GIVEN) */
    struct bed_friction_table bed_mu; /* with bed_friction: each (wall, medium) pair's friction coefficient */
    int bed_per_medium;     /* with bed_friction: some wall gives two media different coefficients, so
                               the pass reads bed_mu rather than the wall particles' wall_friction */
    int grains_in_water;    /* a medium has LAW_GRAINS_IN_WATER: its pairs with fluid particles take the
                               water's interpolated pressure and Ergun's drag (docs/model.md [GW]) */
#define NUMERICS_KEY NUMERICS_MEMBER_OF_PAIR
#include "numerics_keys.def"
#undef NUMERICS_KEY
};

/* What the density diffusion acts on (numerics.density_diffusion_form, docs/numerics.md). */
enum density_diffusion_form {
    DENSITY_DIFFUSION_HYDROSTATIC = 0, /* rho_j - rho_i less rho0 g (z_i - z_j) / c^2 (Fourtakas et al. 2019) */
    DENSITY_DIFFUSION_MOLTENI = 1      /* rho_j - rho_i (Molteni & Colagrossi 2009) */
};

/* What a pass runs over. Particles 0 .. C->start[C->ncell] are the active ones. */
struct pair_system {
    struct particles *P;
    const struct cells *C;
    const struct neighbours *NB;
    const struct gather *G;   /* gather ranges (the velocity gradient of grains) */
    const struct medium *media;
    struct forces_params params;
    double dt;                /* the time step just taken [s] (the bed friction's stick force) */
    int n_threads;
};


/* Module state: the kernel-factor cache that the density pass fills and the momentum pass of the
 * same step reads, and the scratch sums of the passes. */
struct forces;

struct forces *forces_create(void);
void forces_free(struct forces *F);

/** Density rate drho of every particle and its count of same-medium neighbours (nneigh) from
 *  the current positions and velocities, with params.diffusion > 0 plus the density diffusion
 *  between particles of one medium (docs/numerics.md). Returns 1 if a non-finite value appeared at a mobile
 *  particle, -1 if a scratch array cannot be allocated, 0 otherwise. */
int forces_density_rate(struct forces *F, const struct pair_system *S);

/** Velocity gradient and correction matrix of every granular particle that is not a wall or
 *  lost, over its gather ranges (walls enter with their no-slip velocity). */
void forces_velocity_gradient(const struct pair_system *S, struct velocity_gradient *out);

/** forces_density_rate and forces_velocity_gradient(S, grad) in one parallel region (the same
 *  results: the gradient reads nothing the density pass writes). */
int forces_density_rate_gradient(struct forces *F, const struct pair_system *S, struct velocity_gradient *grad);

/** Acceleration P->acc of every particle, gravity included (without the viscous term when
 *  params.implicit_viscosity; the pass then stores the viscous couplings w_ij of the pairs). It
 *  reads the kernel factors of this step's forces_density_rate, so it must follow it. Returns 1 if a non-finite value appeared at a
 *  mobile particle, -1 when out of memory or without this step's density pass, 0 otherwise. */
int forces_momentum(struct forces *F, const struct pair_system *S);

/** The viscous operator of the last implicit momentum pass, out_i = sum_j w_ij (in_i - in_j)
 *  for every component, so that the viscous acceleration of a velocity field u is -out_i / m_i;
 *  with diag != NULL also its diagonal diag_i = sum_j w_ij. Arrays of the active particles.
 *  Returns -1 without a stored operator. */
int forces_viscous_apply(const struct forces *F, const struct pair_system *S, const double *const in[DIM],
                         double *const out[DIM], double *diag);

/** The couplings of the last implicit momentum pass summed between groups of particles (the
 *  coarse grid of viscous_coarse.h). group[i] >= 0 numbers particle i's group on a grid
 *  of groups_per_row groups per row, a group being whole cells of one cell row and at least kx
 *  columns wide (cells.h), so that a pair of i's half stencil (its own row forward, the row
 *  above) ends in i's group (slot 0), the next group of the row (slot 1) or one of the three
 *  above (slots 2, 3, 4: offsets groups_per_row - 1, groups_per_row, groups_per_row + 1);
 *  group[i] < 0 leaves i out. Adds w_ij of each such pair (once) to sums[5 group[i] + slot].
 *  Returns -1 without a stored operator. */
int forces_viscous_group_couplings(const struct forces *F, const struct pair_system *S, const int32_t *group,
                                   long groups_per_row, double *sums);

/** SPHERA's partial pressure smoothing with factor theta_P dt / h (docs/model.md section 3):
 *  pressures and densities of the non-wall particles relax toward their neighbours'. Returns -1
 *  if a scratch array cannot be allocated. */
int forces_smooth_pressure(struct forces *F, const struct pair_system *S, double theta_dt_over_h);

/** Whether the cache holds factors the next momentum pass will use (tests). */
int forces_cache_pending(const struct forces *F);
/** Drop the cached factors and viscous couplings (the particles were replaced, e.g. by a
 *  restored state). */
void forces_forget_cache(struct forces *F);
/** Whether the viscous couplings of the last implicit momentum pass are there. */
int forces_viscous_ready(const struct forces *F);

/** Test hook: the acceleration (without gravity) and the density rate particle j gives i (its
 *  density diffusion included), evaluated by the same pair code. */
void forces_pair_for_test(const struct pair_system *S, size_t i, size_t j, double a[DIM], double *drho);

#endif
