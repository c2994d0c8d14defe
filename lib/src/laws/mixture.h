/* mixture.h - the granular phase of the mixture model (docs/model.md sections 5-6): strain rate
 * from the velocity gradient, pore pressure, effective stress, the regime of every granular
 * particle (the viscosity law itself is in rheology.h) and the pressure of the grains held
 * fixed; SPHERA's fixed bed as an option. A rheology variant changes rheology.h (the law) and,
 * if it needs other inputs than the strain rate and the effective stress, mixture.c. */
#ifndef MIXSPH_MIXTURE_H
#define MIXSPH_MIXTURE_H
#include <stddef.h>

#include "case.h"
#include "forces.h"
#include "kernel.h"
#include "neighbours.h"
#include "particles.h"

/* Module state: the velocity gradient the pair loops fill for the grains, and the columns of
 * the pore pressure and of the fixed bed. */
struct mixture;

/** Set up for up to `cap` particles over the domain's x range [x_min, x_max] at spacing dx and
 *  smoothing length h (the case gives the media, gravity and options). NULL when out of memory. */
struct mixture *mixture_create(const struct case_def *cfg, size_t cap, double x_min, double x_max, double dx, double h);
void mixture_free(struct mixture *M);

/** The arrays the velocity-gradient pass (forces.h) fills, one entry per particle. */
struct velocity_gradient *mixture_gradient(struct mixture *M);

/** Regime, viscosity and state of every granular particle among the first n (sorted by cell,
 *  gather ranges in G), from this step's velocity gradient and pressures; fixed grains get the
 *  pressure of the mobile grains around them. Returns the number of grains held fixed. */
long mixture_update(struct mixture *M, const struct kernel *K, const struct gather *G, struct particles *P, size_t n,
                    int n_threads);

#endif
