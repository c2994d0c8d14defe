/* pore_pressure.h - what the granular laws share about the water in their pores (docs/model.md
 * section 5): the pore fluid of a saturated medium and its mixture density (5), and the pore
 * pressure [PW] of a grain, hydrostatic below the top of the wet column of the grain's column dx
 * wide (scaled by cos^2 of the top's local slope). A medium's key pore_pressure says what the wet
 * column is:
 *   free_surface    (the default): the particles of any fluid medium and of any saturated
 *                   granular medium, so a grain under water takes the pressure of the water above
 *                   it, a dry medium too (the water fills its pores once it is submerged);
 *   granular_column (the paper's [PW], set by the bundled cases of the paper's tables): the
 *                   particles of the saturated granular media only; a dry medium has none. */
#ifndef MIXSPH_PORE_PRESSURE_H
#define MIXSPH_PORE_PRESSURE_H
#include <stddef.h>

#include "law.h"

enum pore_pressure_mode {
    PORE_FREE_SURFACE = 0,   /* below the free surface of the water and saturated grains */
    PORE_GRANULAR_COLUMN = 1 /* below the top of the saturated granular column (the paper's) */
};

static const struct case_choice pore_pressure_modes[] = {
    {"free_surface", PORE_FREE_SURFACE}, {"granular_column", PORE_GRANULAR_COLUMN}, {NULL, 0}};

/* The row of media.<name>.pore_pressure, in the key table of every granular law. */
#define PORE_PRESSURE_KEY                                                                                             \
    {.key = "pore_pressure", .type = CASE_CHOICE, SCHEMA_DEF(PORE_FREE_SURFACE), .choices = pore_pressure_modes,      \
     .numeric_choice = CASE_CHOICE_BY_VALUE, .field = CASE_FIELD(medium, granular.pore_pressure),                              \
     .meaning = "what the pore pressure p_w [PW] is measured from: free_surface (0), the top of the water and "       \
                "saturated grains above the grain, a dry medium's grains under water included; granular_column (1), " \
                "the top of the saturated grains only, a dry medium none (the paper's; its bundled cases set it)"}

/* Per column dx wide from the domain's x_min, the tops of the two wet columns. */
struct pore_columns {
    double x_min, dx, g;
    size_t nbins;
    double *ztop;    /* [m] of the saturated granular particles; -inf where the column holds none */
    double *wet_top; /* [m] of the fluid and saturated granular particles; -inf where none */
    double *wet_rho; /* [kg/m3] the density of the fluid of the particle at wet_top (a fluid's own, a
                        saturated grain's pore fluid's) */
};

/** Columns over the domain of `setup`; NULL when out of memory. */
struct pore_columns *pore_columns_create(const struct law_setup *setup);
void pore_columns_free(struct pore_columns *C);

/** The tops of every column: the highest particle (not a wall, not lost) of a saturated granular
 *  medium (ztop), of a fluid or saturated granular medium (wet_top), plus dx/2. */
void pore_columns_tops(struct pore_columns *C, const struct particles *P, const struct medium *media);

/** The pore pressure [PW] [Pa] at (x, z) of a particle of granular medium m (0 above the top of
 *  its wet column, and for a dry medium under granular_column). */
double pore_pressure(const struct pore_columns *C, const struct medium *m, double x, double z);

/** A granular medium's key pore_fluid (a fluid medium defined before it; required when saturated)
 *  and what follows from it: pore_fluid, rho_f and the mixture density rho0 of (5), saturated
 *  or dry. A message naming the key on error. */
mixsph_status pore_fluid_finish(struct medium *md, const struct law_finish_ctx *ctx);

#endif
