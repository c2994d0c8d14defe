/* sim.h - the simulation's creation (sim.c, on top of the library): from a case's text, from a
 * saved state; the object itself is sim_object.h. */
#ifndef MIXSPH_SIM_H
#define MIXSPH_SIM_H

#include "sim_object.h"

/** mixsph_sim_create_from_text polling `interrupt` (may be NULL) during the creation. */
mixsph_status sim_create_from_text(const char *json_text, const char *origin, const mixsph_override *ov, size_t n_ov,
                                   const mixsph_interrupt *interrupt, mixsph_sim **out, char *err, size_t err_len);
/** mixsph_sim_create_from_state polling `interrupt` (may be NULL) while the case is rebuilt (state.c). */
mixsph_status sim_create_from_state(const void *buf, size_t len, const mixsph_interrupt *interrupt, mixsph_sim **out,
                                    char *err, size_t err_len);

#endif
