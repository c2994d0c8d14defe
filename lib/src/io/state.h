/* state.h - what a saved state holds besides the simulation's data (io/state.c; the state itself
 * is saved and loaded through mixsph_sim_save_state / mixsph_sim_load_state of mixsph.h): the
 * case it was made from, so that a simulation can be created anew from it (sim.c). */
#ifndef MIXSPH_STATE_H
#define MIXSPH_STATE_H
#include <stddef.h>

#include "mixsph.h"

/* The case source stored in a state: text and origin copied (NUL-terminated), overrides. */
struct state_source {
    char *text, *origin;
    size_t n_ov;
    char **keys;
    double *values;
};

/** Check a state's header and read its case source (free with state_source_free, also after an
 *  error). Errors: MIXSPH_ERR_ARG for a buffer that is no state of this build, with a message. */
mixsph_status state_read_source(const void *buf, size_t len, struct state_source *src, char *err, size_t err_len);
void state_source_free(struct state_source *src);

/** The dimension (2 or 3) of the build that saved a state, read from its header; 0 for a buffer
 *  that is no state of this machine's byte order. Any build reads it (the dispatcher of the
 *  library for both dimensions, sim_dimension.c, picks the build that loads the state). */
int state_dimension(const void *buf, size_t len);

#endif
