/* law_registry.h - the material laws by id and by the medium type that selects them. */
#ifndef MIXSPH_LAW_REGISTRY_H
#define MIXSPH_LAW_REGISTRY_H

#include "law.h"

/** The law of id `id` (enum law_id), NULL if none. */
const struct material_law *law_get(int id);

/** The law a medium runs when it names none (its key `law` absent): `law` is the first law of its
 *  type (read from its `type`), `given(entry, key)` tells whether the medium's entry has a key.
 *  A granular medium runs the paper's law when it gives the paper's calibrated viscosities
 *  (mu_thr or mu1), as every case written for it does; without them, the elastic-plastic law,
 *  whose parameters are all the material's own (rho, K or c, porosity, phi): a medium written
 *  with only what a new user knows runs (docs/cases.md, "Which law a granular medium runs"). */
int law_unnamed(int law, int (*given)(const void *entry, const char *key), const void *entry);

/** The fastest wave of the media [m/s] (the acoustic bound of the time step). */
double law_max_wave_speed(const struct medium *media, size_t n_media);

#endif
