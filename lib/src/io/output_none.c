/* output_none.c - output.h and the checkpoint functions of mixsph.h for a library built without
 * HDF5 (the FMU's binaries, fmu/CMakeLists.txt: they carry no HDF5, and an FMU writes no run
 * files; its states are kept in memory by state.c). In place of output.c, chosen by CMake.
 *
 * An output folder (mixsph_sim_set_output_dir, _resume_output_dir) and checkpoint files need
 * HDF5: asking for them is MIXSPH_ERR_IO saying that this build has no HDF5. Stepping, the
 * monitors in memory and states (mixsph_sim_save_state / _load_state) work as in the full
 * library. */
#include "output.h"

#include <math.h>
#include <stddef.h>

#include "sim_object.h"
#include "status.h"

#define NO_HDF5 "this build of the mixsph library has no HDF5 (the FMU's): "

mixsph_status output_open(mixsph_sim *s, int resume)
{
    (void)resume;
    return SIM_FAIL(s, MIXSPH_ERR_IO, NO_HDF5 "no output folder (%s): run files are HDF5 files", s->out.dir);
}

/* Never reached: output_open fails, so no output folder is ever set. */
mixsph_status output_resume_monitors(mixsph_sim *s)
{
    return SIM_FAIL(s, MIXSPH_ERR_IO, NO_HDF5 "no output folder");
}

mixsph_status output_snapshot(mixsph_sim *s)
{
    return SIM_FAIL(s, MIXSPH_ERR_IO, NO_HDF5 "no snapshots");
}

void output_close(mixsph_sim *s) { (void)s; }

mixsph_status mixsph_sim_write_checkpoint(mixsph_sim *s, const char *path)
{
    if (!s) return MIXSPH_ERR_ARG;
    return SIM_FAIL(s, MIXSPH_ERR_IO, NO_HDF5 "cannot write the checkpoint %s (checkpoints are HDF5 files)",
                    path ? path : "(null)");
}

mixsph_status output_read_checkpoint(const char *path, unsigned char **state, size_t *len, double *run_wall_s,
                                     char *err, size_t err_len)
{
    *state = NULL;
    *len = 0;
    *run_wall_s = NAN;
    return status_set(err, err_len, MIXSPH_ERR_IO, NO_HDF5 "cannot read the checkpoint %s (checkpoints are HDF5 files)",
                      path ? path : "(null)");
}

mixsph_status mixsph_sim_set_csv_snapshots(mixsph_sim *s, int on)
{
    if (!s) return MIXSPH_ERR_ARG;
    s->out.csv_snapshots_off = !on;
    return MIXSPH_OK;
}

/* Nothing is ever written. */
void mixsph_sim_output_time(const mixsph_sim *s, double *csv_s, double *hdf5_s, double *checkpoint_s)
{
    (void)s;
    if (csv_s) *csv_s = 0.0;
    if (hdf5_s) *hdf5_s = 0.0;
    if (checkpoint_s) *checkpoint_s = 0.0;
}
