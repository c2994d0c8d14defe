/* monitors.h - the scalar outputs sampled during a run (diagnostics and the case's monitors),
 * the profile files and the CSV particle snapshots (docs/output.md). */
#ifndef MIXSPH_MONITORS_H
#define MIXSPH_MONITORS_H
#include <stddef.h>

#include "sim_object.h"

/** Names and kinds of the outputs from the case (after creation); MIXSPH_ERR_CASE, with a
 *  message, for a pressure probe off its wall or outside the domain. */
mixsph_status monitors_init(mixsph_sim *s);
/** Current value of output k. */
double monitors_value(const mixsph_sim *s, size_t k);
/** Take a sample of every output (extremes, a row of monitors.csv). */
mixsph_status monitors_sample(mixsph_sim *s);
/** Write the profiles that are due. */
mixsph_status monitors_profiles(mixsph_sim *s);
/** Start monitors.csv in the output folder. */
mixsph_status monitors_open(mixsph_sim *s);
/** Write snap_NNNN.csv. */
mixsph_status monitors_snapshot(mixsph_sim *s);

#endif
