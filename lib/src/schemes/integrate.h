/* integrate.h - the time step: criterion (4) and the leapfrog (docs/model.md section 4,
 * docs/numerics.md), and the rebuild of the neighbour lists it triggers. It is the one place
 * that orders the passes of a step (forces.h, mixture.h, walls.h). */
#ifndef MIXSPH_INTEGRATE_H
#define MIXSPH_INTEGRATE_H

#include "sim.h"

/** Sort the particles by cell (marking those that left the domain lost) and rebuild the pair
 *  ranges, the gather lists and the near-wall flags. */
mixsph_status integrate_rebuild_lists(mixsph_sim *s);

/** The gather lists (grains: all their neighbours; walls: their non-wall ones) and the
 *  near-wall flags, from the pair ranges' last build. */
mixsph_status integrate_build_gather_lists(mixsph_sim *s);

/** The density pass and, with granular media, the grains' velocity gradient, over S (from
 *  sim_pair_system). Returns 1 if a non-finite rate appeared at a mobile particle, -1 when out of
 *  memory, 0 otherwise. */
int integrate_density_rates(mixsph_sim *s, const struct pair_system *S);

/** The next time step from criterion (4). */
double integrate_time_step(const mixsph_sim *s);

/** Criterion (4) for one particle: the acoustic bound cfl 2 h / (c_max + |u|) and, when mu > 0,
 *  the viscous bound cfl_visc 2 h^2 rho / mu [s]. integrate_time_step takes its minimum over the
 *  particles; the case's resource budget (budget.c) estimates the number of steps with it. */
static inline double integrate_particle_dt(double cfl, double cfl_visc, double h, double c_max, double speed,
                                           double rho, double mu)
{
    double d = cfl * 2.0 * h / (c_max + speed);
    if (mu > 0.0) {
        const double dv = cfl_visc * 2.0 * h * h * rho / mu;
        if (dv < d) d = dv;
    }
    return d;
}

/** Pressure from the equation of state and the fields derived from the density and the medium
 *  (1/rho, volume m/rho, artificial-viscosity coefficient) of every non-wall particle. */
void integrate_pressure_and_derived(mixsph_sim *s);

/** The rates at the current state (density pass, grains' regimes, wall extrapolation, momentum
 *  pass) as at the end of a step, for the initial state. */
mixsph_status integrate_initial_rates(mixsph_sim *s);

/** One leapfrog step of s->dt. */
mixsph_status integrate_step(mixsph_sim *s);

#endif
