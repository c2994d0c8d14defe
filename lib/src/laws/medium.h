/* medium.h - a medium's parameters as a material law reads them: the case reader fills them
 * from media.<name> (the rows of the law's key table, laws/law.h) and the law derives the rest
 * once (law->finish). The law of a medium is its `law` (enum law_id, chosen by the medium's
 * "type"); what it hands the pair loops is the per-particle viscosity P->mu and, for a law with
 * a stress state, the deviatoric stress of its particles (docs/model.md). */
#ifndef MIXSPH_MEDIUM_H
#define MIXSPH_MEDIUM_H

#include "drucker_prager_params.h"
#include "elasticity.h"
#include "granular.h"
#include "mixture_paper_params.h"
#include "mu_i.h"
#include "schema.h"

#define MEDIUM_NAME_LEN SCHEMA_NAME_LEN

/* The material laws (laws/law_registry.c holds one entry per law, in this order). */
enum law_id {
    LAW_NEWTONIAN = 0,     /* "fluid": Newtonian viscosity (laws/newtonian.c) */
    LAW_MIXTURE_PAPER = 1, /* "granular": the paper's KTGF mixture with mu_thr / mu0 (laws/mixture_paper.c) */
    LAW_ELASTIC_SOLID = 2, /* "elastic": a linear-elastic solid, Jaumann rate (laws/elastic_solid.c) */
    LAW_ELASTIC_PLASTIC = 3, /* "granular" with law "elastic_plastic": Drucker-Prager (laws/elastic_plastic.c) */
    LAW_COUNT
};

/* What a law asks of the step (bits of struct medium's `features`, copied from its law). */
enum law_feature {
    LAW_USES_GRADIENT = 1u, /* the velocity gradient of its particles is gathered every step */
    LAW_HAS_STRESS = 2u,    /* its particles carry a deviatoric stress (P->stress) */
    LAW_CAPS_TENSION = 4u,  /* its update bounds the tension the equation of state gives (a yield surface's
                               apex), so a density below rho0 is its grains parting, not a blow-up */
    LAW_DENSITY_DIFFUSION = 8u, /* its particles take the continuity pass's density diffusion (a fluid: a
                                   grain's density carries its packing or its elastic pressure, which
                                   diffused would let a standing heap creep; docs/numerics.md 2c) */
    LAW_WALL_FRICTION = 16u,    /* the shear a no-slip wall gives its particles is the wall's Coulomb
                                   friction (docs/model.md [BF]), delta the wall's friction or the
                                   medium's phi where the wall gives none */
    LAW_HOLDS_PARTICLES = 32u,  /* its update holds particles fixed (MIXSPH_STATE_FIXED) and returns how
                                   many; its finish says how a held particle is integrated (struct
                                   medium's held_takes_kicks, held_viscosity) */
    LAW_FLUID = 64u,            /* a fluid: the water that grains with LAW_GRAINS_IN_WATER sink in */
    LAW_GRAINS_IN_WATER = 128u, /* in its pairs with a LAW_FLUID particle its particle is a parcel of grains in
                                   the fluid (docs/model.md [GW]): it takes the fluid's pressure interpolated at
                                   it instead of its own, no deviatoric stress, the drag of the fluid through
                                   its grains, and leaves the fluid out of its density rate; set by a
                                   medium's finish (a granular law's key water_coupling = "grains") */
    LAW_WALL_FRICTION_GIVEN = 256u /* as LAW_WALL_FRICTION, at the no-slip walls that give their friction angle
                                      only (elsewhere the law's own no-slip shear: the paper's) */
};

struct medium {
    char name[MEDIUM_NAME_LEN];
    int law;           /* enum law_id */
    unsigned features; /* enum law_feature bits of its law */
    /* how the schemes integrate a particle its law holds fixed (LAW_HOLDS_PARTICLES; set by the
     * law's finish): whether it takes the kicks of its forces (it is never drifted), and the
     * viscosity [Pa s] it enters the explicit viscous bound of the time step (4) with */
    int held_takes_kicks;
    double held_viscosity;
    double rho0;       /* reference density [kg/m3]; granular: the mixture density (5) */
    double c;          /* sound speed of the equation of state [m/s]; granular: sqrt(K_s / rho_s) */
    double mu;         /* dynamic viscosity [Pa s]; granular: unused (set by the rheology) */
    double alpha_m;    /* Monaghan artificial viscosity coefficient [-] (granular: 0 unless given) */
    double bulk_modulus; /* K of the equation of state [Pa], c = sqrt(K / rho0) (a fluid's and the
                          * elastic solid's; the grains' K_s of the granular laws) */
    int tension_cutoff;  /* no tensile pressure, p >= background pressure: the equation of state's
                          * option (a granular key; off: the paper's model) */
    /* each law's own parameters (its module's header); a law reads its own and those it shares */
    struct granular_params granular;    /* the granular laws' grains and pores (granular.h) */
    struct mixture_paper_params paper;  /* the paper's law (mixture_paper_params.h) */
    struct elastic_params elastic;      /* the elastic solid and the elastic part of the
                                         * elastic-plastic law (elasticity.h) */
    struct drucker_prager_params dp;    /* the elastic-plastic law's cone (drucker_prager_params.h) */
    struct mu_i_params mu_i;            /* its rate-dependent friction, rate_dependent (mu_i.h) */
};

/** Whether a held particle of medium m takes the kicks of its forces; `rigid`: the implicit scheme
 *  holds every held particle at rest through its viscous step (numerics.held_grains = "rigid"). */
static inline int medium_held_kicked(const struct medium *m, int rigid) { return !rigid && m->held_takes_kicks; }

/** Whether a medium's pressure follows its equation of state into tension without bound (no
 *  tension_cutoff, no law that caps it): in such a medium a density far below rho0 means the
 *  discretisation has failed. */
static inline int medium_carries_tension(const struct medium *m)
{
    return !m->tension_cutoff && !(m->features & LAW_CAPS_TENSION);
}

#endif
