/* law_registry.h - the material laws by id and by the medium type that selects them. */
#ifndef MIXSPH_LAW_REGISTRY_H
#define MIXSPH_LAW_REGISTRY_H

#include "law.h"

/** The law of id `id` (enum law_id), NULL if none. */
const struct material_law *law_get(int id);

/** The fastest wave of the media [m/s] (the acoustic bound of the time step). */
double law_max_wave_speed(const struct medium *media, size_t n_media);

#endif
