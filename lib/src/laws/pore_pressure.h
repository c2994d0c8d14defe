/* pore_pressure.h - what the granular laws share about saturated media (docs/model.md section 5):
 * the pore fluid of a saturated medium and its mixture density (5), and the pore pressure [PW],
 * hydrostatic below the top of the saturated granular column of the particle's column dx wide,
 * scaled by cos^2 of the top's local slope. */
#ifndef MIXSPH_PORE_PRESSURE_H
#define MIXSPH_PORE_PRESSURE_H
#include <stddef.h>

#include "law.h"

/* The tops of the saturated granular columns, per column dx wide from the domain's x_min. */
struct pore_columns {
    double x_min, dx, g;
    size_t nbins;
    double *ztop; /* [m]; -inf where the column holds no saturated grain */
};

/** Columns over the domain of `setup`; NULL when out of memory. */
struct pore_columns *pore_columns_create(const struct law_setup *setup);
void pore_columns_free(struct pore_columns *C);

/** The top of every column: the highest particle (not a wall, not lost) of any saturated medium
 *  plus dx/2. */
void pore_columns_tops(struct pore_columns *C, const struct particles *P, const struct medium *media);

/** The pore pressure [PW] [Pa] at (x, z) of a particle of saturated medium m (0 above its top). */
double pore_pressure(const struct pore_columns *C, const struct medium *m, double x, double z);

/** A granular medium's key pore_fluid (a fluid medium defined before it; required when saturated)
 *  and what follows from it: pore_fluid, rho_f and the mixture density rho0 of (5), saturated
 *  or dry. A message naming the key on error. */
mixsph_status pore_fluid_finish(struct medium *md, const struct law_finish_ctx *ctx);

#endif
