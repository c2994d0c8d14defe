/* scheme_params.h - the time schemes' parameters, set once from the case when the simulation is
 * created (sim.c): a step reads these, never the case. A definition only. */
#ifndef MIXSPH_SCHEME_PARAMS_H
#define MIXSPH_SCHEME_PARAMS_H
#include <stddef.h>

#include "forces.h"
#include "medium.h"
#include "numerics_keys.h"
#include "viscous.h"

struct scheme_params {
    const struct medium *media;   /* the media, indexed by P->medium (the case's) */
    size_t n_media;
    int implicit;                 /* numerics.viscosity = "implicit": symplectic Euler around the
                                     implicit viscous step; else the explicit leapfrog */
    long excluded_limit;          /* particles that may be excluded; one more stops the run */
    /* the `numerics` keys whose rows of core/numerics_keys.def are read by SCHEME, as the members
     * those rows name */
#define NUMERICS_KEY NUMERICS_MEMBER_OF_SCHEME
#include "numerics_keys.def"
#undef NUMERICS_KEY
    struct forces_params pair;    /* what the pair loops read */
    struct viscous_params viscous; /* the implicit viscous step's solver */
};

#endif
