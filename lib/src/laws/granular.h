/* granular.h - the parameters of a granular medium that its laws share (the paper's mixture and
 * the elastic-plastic law): its grains, its pores and their fluid, its friction angle. Read from
 * media.<name> by the laws' key tables and derived by their finish (mixture_paper.c,
 * elastic_plastic.c); the pore pressure (pore_pressure.h) reads them. A definition only. */
#ifndef MIXSPH_GRANULAR_H
#define MIXSPH_GRANULAR_H

struct granular_params {
    double rho_grain;  /* density of the grains rho_s [kg/m3] */
    double porosity;   /* n = eps_f at the packing limit [-] */
    double phi_deg;    /* angle of internal friction [deg] */
    double sin_phi;
    int saturated;     /* pores filled with the pore fluid (else dry) */
    int pore_fluid;    /* index of the pore fluid medium (saturated media), -1 if none */
    double rho_f;      /* density of the pore fluid [kg/m3] (0 if dry) */
    int pore_pressure; /* what the pore pressure is measured from (enum pore_pressure_mode, pore_pressure.h) */
    int water_coupling;    /* how its particles meet a fluid's (enum granular_water_coupling) */
    double grain_diameter; /* d of the grains [m] (the drag of water_coupling "grains") */
    double drag_viscous;   /* Ergun's viscous drag factor 150 (1-n)^2 / (n d^2) [1/m2]: beta = it mu_f + ... */
    double drag_inertial;  /* ... + its inertial factor 1.75 (1-n) / d [1/m] times rho_f |u_f - u_s| */
};

/* How a granular medium's particles meet a fluid's (its key water_coupling; docs/model.md [WG], [GW]). */
enum granular_water_coupling {
    WATER_COUPLING_MIXTURE = 0, /* as one continuum: its own pressure and stress in the pair (the paper's) */
    WATER_COUPLING_GRAINS = 1   /* a parcel of grains in the water: LAW_GRAINS_IN_WATER (medium.h) */
};

#endif
