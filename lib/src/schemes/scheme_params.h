/* scheme_params.h - the time schemes' parameters, set once from the case when the simulation is
 * created (sim.c): a step reads these, never the case. A definition only. */
#ifndef MIXSPH_SCHEME_PARAMS_H
#define MIXSPH_SCHEME_PARAMS_H
#include <stddef.h>

#include "forces.h"
#include "medium.h"
#include "viscous.h"

struct scheme_params {
    const struct medium *media;   /* the media, indexed by P->medium (the case's) */
    size_t n_media;
    int implicit;                 /* numerics.viscosity = "implicit": symplectic Euler around the
                                     implicit viscous step; else the explicit leapfrog */
    int held_grains_rigid;        /* numerics.held_grains = "rigid" (implicit scheme) */
    double cfl, cfl_visc;         /* the coefficients of criterion (4) */
    double p_background;          /* added by the equation of state [Pa] */
    double pressure_smoothing;    /* theta_P of the partial pressure smoothing (0: off) */
    double density_bound;         /* |rho/rho0 - 1| beyond which a particle is excluded (0: off) */
    long excluded_limit;          /* particles that may be excluded; one more stops the run */
    struct forces_params pair;    /* what the pair loops read */
    struct viscous_params viscous; /* the implicit viscous step's solver */
};

#endif
