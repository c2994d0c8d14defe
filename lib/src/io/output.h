/* output.h - particle snapshots and checkpoints: the run's HDF5 file (run.h5) with its XDMF
 * sidecar (run.xdmf, a time series of point clouds for ParaView), the CSV snapshots
 * (snap_NNNN.csv, written by monitors.c) and checkpoint files for restart. The layout of the
 * files is described at the top of output.c and in README.md. */
#ifndef MIXSPH_OUTPUT_H
#define MIXSPH_OUTPUT_H

#include <stddef.h>

#include "mixsph.h"

struct output; /* the open run file of one simulation (owned by mixsph_sim, field h5) */

/** Create (resume = 0) or continue (resume = 1) the run file run.h5 and its sidecar run.xdmf in
 *  s->out_dir. Continuing keeps the snapshots of this run taken before the restored state
 *  (index < s->snap_index) and drops later ones (they will be written again); a run.h5 of
 *  another case or overrides is refused (MIXSPH_ERR_ARG). Errors: MIXSPH_ERR_IO with a message. */
mixsph_status output_open(mixsph_sim *s, int resume);

/** Continue monitors.csv in s->out_dir after a restore: keep the header and the first
 *  s->n_samples rows (those taken before the saved state), open it for appending as
 *  s->monitor_csv (a missing file is started anew). */
mixsph_status output_resume_monitors(mixsph_sim *s);

/** Take a snapshot now: snap_NNNN.csv (monitors_snapshot, unless s->csv_snapshots_off) and a
 *  group of run.h5, then flush the
 *  file and rewrite the sidecar, so that a run killed later leaves every snapshot so far
 *  readable. Advances s->snap_index. */
mixsph_status output_snapshot(mixsph_sim *s);

/** Read a checkpoint file (mixsph_sim_write_checkpoint): the saved state (*state, malloc'd, *len
 *  bytes; the caller frees it) and the run's wall time up to it (*run_wall_s, NAN when the file
 *  does not say). Errors: MIXSPH_ERR_ARG (not readable, not a mixsph checkpoint), MIXSPH_ERR_IO,
 *  MIXSPH_ERR_NOMEM, with a message naming the file. */
mixsph_status output_read_checkpoint(const char *path, unsigned char **state, size_t *len, double *run_wall_s,
                                     char *err, size_t err_len);

/** Close the run file (NULL-safe; s->h5 becomes NULL). */
void output_close(mixsph_sim *s);

#endif
