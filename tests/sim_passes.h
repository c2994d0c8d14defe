/* sim_passes.h - the single passes of a time step on a whole simulation, for white-box tests
 * that set up particles by hand and call one pass at a time (integrate.c strings them together
 * in a step). */
#ifndef MIXSPH_TEST_SIM_PASSES_H
#define MIXSPH_TEST_SIM_PASSES_H

#include "integrate.h"
#include "sim.h"

/* Density pass (and the grains' velocity gradient). Returns forces_density_rate's value. */
static inline int sim_density_pass(mixsph_sim *s)
{
    const struct pair_system S = sim_pair_system(s);
    return integrate_density_rates(s, &S);
}

/* Momentum pass. Returns forces_momentum's value. */
static inline int sim_momentum_pass(mixsph_sim *s)
{
    const struct pair_system S = sim_pair_system(s);
    return forces_momentum(s->work.forces, &S);
}

/* Regimes of the grains (the material laws' updates at the current state). */
static inline void sim_mixture_update(mixsph_sim *s) { integrate_update_laws(s, 0.0); }

/* SPHERA's pressure smoothing with the case's theta_P and the current dt. */
static inline void sim_smooth_pressure(mixsph_sim *s)
{
    const struct pair_system S = sim_pair_system(s);
    forces_smooth_pressure(s->work.forces, &S, s->scheme.pressure_smoothing * s->phys.dt / s->phys.h);
}

/* The acceleration (without gravity) and density rate particle j gives i. */
static inline void sim_pair_terms(mixsph_sim *s, size_t i, size_t j, double *ax, double *az, double *drho)
{
    const struct pair_system S = sim_pair_system(s);
    double a[DIM];
    forces_pair_for_test(&S, i, j, a, drho);
    *ax = a[0];
    *az = a[DIM_UP];
}

#endif
