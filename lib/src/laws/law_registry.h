/* law_registry.h - the material laws by id and by the medium type that selects them. */
#ifndef MIXSPH_LAW_REGISTRY_H
#define MIXSPH_LAW_REGISTRY_H

#include "law.h"

/** The law of id `id` (enum law_id), NULL if none. */
const struct material_law *law_get(int id);

/** Whether a particle of medium m held fixed takes the kicks of its forces (law.h: held_kicked;
 *  every held particle does under a law that says nothing). */
int law_held_kicked(const struct medium *m, int rigid);

/** The viscosity a held particle of medium m enters the time step (4) with (law.h:
 *  held_viscosity; its own viscosity bound under a law that says nothing). */
double law_held_viscosity(const struct medium *m);

/** The fastest wave of the media [m/s] (the acoustic bound of the time step). */
double law_max_wave_speed(const struct medium *media, size_t n_media);

#endif
