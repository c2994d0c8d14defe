/* integrate.h - the time step: criterion (4) and the leapfrog (docs/model.md section 4,
 * docs/numerics.md), and the rebuild of the neighbour lists it triggers. It is the one place
 * that orders the passes of a step (forces.h, mixture.h, walls.h). */
#ifndef MIXSPH_INTEGRATE_H
#define MIXSPH_INTEGRATE_H

#include "sim_object.h"

/** What the pair loops of forces.h run over, from the simulation's current parts and options. */
struct pair_system sim_pair_system(mixsph_sim *s);

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

/** The material laws' per-step updates (laws/law.h) over law_dt [s] (0: at the current state,
 *  nothing advanced), after this step's density pass, equation of state and velocity gradient. */
void integrate_update_laws(mixsph_sim *s, double law_dt);

/** The next time step from criterion (4). */
double integrate_time_step(const mixsph_sim *s);

/** Pressure from the equation of state and the fields derived from the density and the medium
 *  (1/rho, volume m/rho, artificial-viscosity coefficient) of every non-wall particle. */
void integrate_pressure_and_derived(mixsph_sim *s);

/** The rates at the current state (density pass, grains' regimes, wall extrapolation, momentum
 *  pass) as at the end of a step, for the initial state. */
mixsph_status integrate_initial_rates(mixsph_sim *s);

/** One leapfrog step of s->phys.dt. */
mixsph_status integrate_step(mixsph_sim *s);

#endif
