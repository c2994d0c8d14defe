/**
 * @file mixsph.h
 * @brief Public C API of mixsph: a 2D weakly compressible SPH (WCSPH) simulator of water and
 *        granular mixtures (Manenti et al. 2018, the SPHERA mixture model with limiting viscosity).
 *
 * Everything a simulation needs lives in one opaque ::mixsph_sim object: create it from a JSON
 * case file (plus numeric key=value overrides), advance it to a time, read its outputs, destroy
 * it. The library keeps no mutable global state (several simulations may live in one process and
 * be stepped in any order), never prints and never exits: every call returns a ::mixsph_status
 * and the simulation keeps a readable message of the last error.
 */
#ifndef MIXSPH_H
#define MIXSPH_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Status codes, from one list, ordered by severity; the last, MIXSPH_ERR_INTERRUPTED, is no
 *  failure of the case: the host asked the call to stop (mixsph_interrupt). */
#define MIXSPH_STATUS_LIST(X)                                                         \
    X(MIXSPH_OK, "ok")                                                                \
    X(MIXSPH_ERR_ARG, "invalid argument")                                             \
    X(MIXSPH_ERR_CASE, "invalid case file")                                           \
    X(MIXSPH_ERR_IO, "input/output error")                                            \
    X(MIXSPH_ERR_UNSTABLE, "unstable run (non-finite value or collapsed time step)")  \
    X(MIXSPH_ERR_NOMEM, "out of memory")                                              \
    X(MIXSPH_ERR_INTERRUPTED, "interrupted by the host")

typedef enum {
#define MIXSPH_X_ENUM(name, text) name,
    MIXSPH_STATUS_LIST(MIXSPH_X_ENUM)
#undef MIXSPH_X_ENUM
} mixsph_status;

/** Short description of a status code (static string). */
const char *mixsph_status_string(mixsph_status st);

/** A numeric override of a case-file value: `key` is a dotted path such as
 *  "numerics.dx", "media.water.rho" or "motions.plate.vx.3" (array index). */
typedef struct {
    const char *key;
    double value;
} mixsph_override;

/** Parse "key=value" into an override (key points into `text`, which must outlive it;
 *  the '=' is replaced by a NUL). Returns MIXSPH_ERR_ARG with a message on bad syntax. */
mixsph_status mixsph_override_parse(char *text, mixsph_override *out, char *err, size_t err_len);

typedef struct mixsph_sim mixsph_sim;

/**
 * Create a simulation from a case file.
 * @param case_path JSON case file.
 * @param ov, n_ov  numeric overrides applied to the case before validation (may be NULL/0).
 * @param out       receives the simulation (NULL on failure).
 * @param err       buffer for the error message on failure (may be NULL).
 */
mixsph_status mixsph_sim_create(const char *case_path, const mixsph_override *ov, size_t n_ov,
                                mixsph_sim **out, char *err, size_t err_len);

/** As mixsph_sim_create, from JSON text held in memory; `origin` names it in messages. */
mixsph_status mixsph_sim_create_from_text(const char *json_text, const char *origin,
                                          const mixsph_override *ov, size_t n_ov,
                                          mixsph_sim **out, char *err, size_t err_len);

/**
 * A host's request to stop a long call. `requested(user)` returns nonzero once the host wants the
 * library to stop; the library polls it while it creates a simulation (every lattice row of the
 * bodies' and walls' fill, and between the phases of the creation) and before every step of
 * mixsph_sim_advance_to, and the call then returns MIXSPH_ERR_INTERRUPTED. A simulation stopped in
 * mixsph_sim_advance_to is at the end of a whole step (it can be saved or continued). The library
 * installs no signal handler: a host (the mixsph executable, the FMU) sets a flag in its own handler
 * and passes a function that reads it.
 */
typedef int (*mixsph_interrupt_fn)(void *user);
typedef struct {
    mixsph_interrupt_fn requested; /**< NULL: never interrupted */
    void *user;                    /**< passed to `requested` */
} mixsph_interrupt;

/** As mixsph_sim_create, polling `interrupt` (may be NULL) during the creation; the simulation
 *  keeps it for mixsph_sim_advance_to. */
mixsph_status mixsph_sim_create_interruptible(const char *case_path, const mixsph_override *ov, size_t n_ov,
                                              const mixsph_interrupt *interrupt, mixsph_sim **out, char *err,
                                              size_t err_len);

/** Poll `interrupt` (NULL: nothing) before every step of mixsph_sim_advance_to from now on. */
void mixsph_sim_set_interrupt(mixsph_sim *s, const mixsph_interrupt *interrupt);

/** Destroy a simulation and close its files (NULL-safe). */
void mixsph_sim_destroy(mixsph_sim *s);

/** Number of OpenMP threads used by this simulation (0 = OpenMP default). */
mixsph_status mixsph_sim_set_threads(mixsph_sim *s, int n_threads);

/** Write monitors (monitors.csv) and particle snapshots (snap_NNNN.csv, and all of them in the
 *  HDF5 file run.h5 with its XDMF sidecar run.xdmf for ParaView) into `dir`, which is created if
 *  missing. Checked immediately: an unwritable folder or file is an error here (MIXSPH_ERR_IO). */
mixsph_status mixsph_sim_set_output_dir(mixsph_sim *s, const char *dir);

/**
 * Advance the simulation until its time reaches `t` (the solver takes its own explicit steps
 * and never shortens one to land on `t`, so the trajectory does not depend on how a run is cut
 * into calls; on return the time is in [t, t + dt)). Returns MIXSPH_ERR_UNSTABLE with a message
 * naming the particle, place and time if a non-finite value appears or the time step collapses;
 * the simulation must then be destroyed.
 */
mixsph_status mixsph_sim_advance_to(mixsph_sim *s, double t);

/** Advance by exactly one explicit time step. */
mixsph_status mixsph_sim_step(mixsph_sim *s);

/** Message of the last error of this simulation ("" if none). */
const char *mixsph_sim_last_error(const mixsph_sim *s);

double mixsph_sim_time(const mixsph_sim *s);      /**< simulated time [s] */
double mixsph_sim_end_time(const mixsph_sim *s);  /**< end time of the case [s] */
double mixsph_sim_dt(const mixsph_sim *s);        /**< last time step [s] */
uint64_t mixsph_sim_steps(const mixsph_sim *s);   /**< steps taken */
/** Wall-clock seconds this run has spent in mixsph_sim_step (and so advance_to), the outputs due at
 *  the case's intervals and the checkpoints written included: this process's time plus, after a
 *  restart from a checkpoint, the run's time up to that checkpoint (carried by it; NaN when the
 *  checkpoint was written by a build that did not record it). mixsph_sim_load_state leaves it
 *  alone (it is not physics). */
double mixsph_sim_run_wall_time(const mixsph_sim *s);
/** The implicit viscous step's cost (numerics.viscosity = "implicit"; 0 and 0 otherwise): the
 *  iterations of all its solves since t = 0 (carried by saved states) and the wall-clock seconds
 *  this process has spent in it (setting up and solving, within mixsph_sim_run_wall_time). */
mixsph_status mixsph_sim_viscous_cost(const mixsph_sim *s, uint64_t *iterations, double *wall_s);
size_t mixsph_sim_particles(const mixsph_sim *s); /**< fluid + granular particles */
size_t mixsph_sim_wall_particles(const mixsph_sim *s);
const char *mixsph_sim_name(const mixsph_sim *s);

/** Number of scalar outputs (monitors and diagnostics). */
size_t mixsph_sim_output_count(const mixsph_sim *s);
/** Name of output `k` (e.g. "kinetic_energy", "mass", or a monitor's name). */
const char *mixsph_sim_output_name(const mixsph_sim *s, size_t k);
/** Current value of output `k`, evaluated at the current state. */
double mixsph_sim_output_value(const mixsph_sim *s, size_t k);
/** Largest and smallest value of output `k` over the samples taken so far, and their times. */
void mixsph_sim_output_extremes(const mixsph_sim *s, size_t k, double *max, double *t_max,
                                double *min, double *t_min);
/** Index of an output by name, or -1. */
long mixsph_sim_output_find(const mixsph_sim *s, const char *name);

/** Read-only view of the core particle fields (for tools and tests): arrays of length n (fluid,
 *  granular and wall particles, told apart by `state`); the order changes every step (sorted by
 *  cell), `id` is stable. For wall particles `medium` is the wall's index. Every field of a
 *  simulation, those a material law or a scheme declares included, is read by name or index with
 *  mixsph_sim_particle_field.
 *  Positions and velocities have `dim` components (the library's build: 2 or 3), pos[d] and
 *  vel[d] for d < dim, the vertical one last (d = dim - 1, along which gravity acts): x, z in 2D,
 *  x, y, z in 3D; pos[d] and vel[d] for d >= dim are NULL. */
typedef struct {
    size_t n, n_fluid;
    int dim;                                      /* components of pos and vel: 2 or 3 */
    const double *pos[3], *vel[3];                /* m, m/s */
    const double *rho, *p, *mu;                   /* kg/m3, Pa, Pa s */
    const uint8_t *medium, *state;                /* medium index, MIXSPH_STATE_* */
    const uint32_t *id;
} mixsph_particles_view;

/* MIXSPH_STATE_IMAGE: the mirror image of a fluid or granular particle across a mirror side wall
 * (3D, a polyline's side_walls = "mirror"), not a particle of the run (its ids from the run's
 * particle count on); an image of a wall particle is a wall particle */
enum { MIXSPH_STATE_MOBILE = 0, MIXSPH_STATE_FIXED = 1, MIXSPH_STATE_WALL = 2, MIXSPH_STATE_LOST = 3, MIXSPH_STATE_IMAGE = 4 };

mixsph_status mixsph_sim_particles_view(const mixsph_sim *s, mixsph_particles_view *v);

/** Element type of a particle field's arrays. */
typedef enum { MIXSPH_FIELD_F64, MIXSPH_FIELD_U8, MIXSPH_FIELD_U16, MIXSPH_FIELD_U32 } mixsph_field_type;

#define MIXSPH_FIELD_MAX_COMPONENTS 6

/** One per-particle field of a simulation, as its snapshots hold it: `name` is the dataset's
 *  name in run.h5 (e.g. "velocity"), `columns` its components' names as snap_NNNN.csv heads
 *  them, comma-separated (e.g. "vx,vz"); data[c] is component c, an array of mixsph_sim_particles
 *  + mixsph_sim_wall_particles values in storage order (valid until the next step). */
typedef struct {
    const char *name, *columns, *unit, *description;
    const char *owner; /**< "core", "scheme" or "law" */
    unsigned components;
    mixsph_field_type type;
    size_t n;
    const void *data[MIXSPH_FIELD_MAX_COMPONENTS];
} mixsph_particle_field;

/** Number of particle fields this simulation shows (those of its snapshots and its material
 *  laws' or schemes' public fields; 0 for NULL). */
size_t mixsph_sim_particle_field_count(const mixsph_sim *s);
/** Field k (0 <= k < mixsph_sim_particle_field_count, in the order of run.h5);
 *  MIXSPH_ERR_ARG out of range. */
mixsph_status mixsph_sim_particle_field(const mixsph_sim *s, size_t k, mixsph_particle_field *f);
/** The field named `name` (its run.h5 name); MIXSPH_ERR_ARG when this simulation has none. */
mixsph_status mixsph_sim_particle_field_find(const mixsph_sim *s, const char *name, mixsph_particle_field *f);

/* ---- external wall motion (co-simulation input) ------------------------------------------- */

/** Replace the prescribed motion law of the moving wall `wall` (its name in the case) by the
 *  constant velocity (vx, vz) [m/s] from now on, until mixsph_sim_release_wall_velocity (a wall
 *  is a polyline of the vertical x-z plane and moves in it, in 3D too). Only
 *  walls that have a motion in the case can be driven. Returns MIXSPH_ERR_ARG for an unknown or
 *  fixed wall or a non-finite velocity. */
mixsph_status mixsph_sim_set_wall_velocity(mixsph_sim *s, const char *wall, double vx, double vz);
/** Give the wall back to its prescribed motion law (no-op if it was not driven). */
mixsph_status mixsph_sim_release_wall_velocity(mixsph_sim *s, const char *wall);

/* ---- state: save, restore, restart --------------------------------------------------------- */

/**
 * Serialise the complete state of a simulation (the case text and overrides that created it,
 * time, step, time step, every particle field, the walls' positions and external velocities, the
 * outputs' extremes and the output schedule) into a buffer allocated by the library
 * (*buf, *len; release it with mixsph_state_free). Continuing from a restored state gives the
 * same trajectory as continuing the original (bit-identical with the same thread count; the
 * pair loops are thread-count independent, so with any count). The format is versioned and
 * checksummed; it is meant for the same build on the same machine type (native byte order).
 */
mixsph_status mixsph_sim_save_state(const mixsph_sim *s, void **buf, size_t *len);
void mixsph_state_free(void *buf);

/** Restore a state saved from a simulation of the same case and overrides (checked: otherwise
 *  MIXSPH_ERR_ARG and the simulation is unchanged). Output files and thread count are kept. */
mixsph_status mixsph_sim_load_state(mixsph_sim *s, const void *buf, size_t len);

/** Create a simulation from a saved state alone (restart): the case is rebuilt from the text
 *  stored in the state, then the state is loaded. */
mixsph_status mixsph_sim_create_from_state(const void *buf, size_t len, mixsph_sim **out, char *err,
                                           size_t err_len);

/** Write a checkpoint: an HDF5 file holding the state of mixsph_sim_save_state (dataset
 *  /state) with the time and step as attributes. It is written to `path`.tmp and renamed to
 *  `path`, so a crash leaves either the previous checkpoint or the new one, never half of one. */
mixsph_status mixsph_sim_write_checkpoint(mixsph_sim *s, const char *path);

/** Create a simulation from a checkpoint file (restart). A missing file or one that is not a
 *  mixsph checkpoint is MIXSPH_ERR_ARG, a failed read MIXSPH_ERR_IO. */
mixsph_status mixsph_sim_create_from_checkpoint(const char *path, mixsph_sim **out, char *err, size_t err_len);
/** As mixsph_sim_create_from_checkpoint, polling `interrupt` (may be NULL) while the case is rebuilt. */
mixsph_status mixsph_sim_create_from_checkpoint_interruptible(const char *path, const mixsph_interrupt *interrupt,
                                                              mixsph_sim **out, char *err, size_t err_len);

/** As mixsph_sim_set_output_dir for a simulation restored from a checkpoint, continuing the
 *  run's files in `dir`: monitors.csv keeps its rows up to the restored state and is appended
 *  to; run.h5 (if there) must hold the same case and overrides: its snapshots up to the restored
 *  state are kept, later ones (written by the interrupted run after its checkpoint) are dropped
 *  and written again as the run continues. Without earlier files they are started anew. */
mixsph_status mixsph_sim_resume_output_dir(mixsph_sim *s, const char *dir);

/** Write the particle snapshots also as CSV files snap_NNNN.csv (on = 1, the default) or only
 *  into run.h5 (on = 0; the CSV files cost 10-30 times as much to write). */
mixsph_status mixsph_sim_set_csv_snapshots(mixsph_sim *s, int on);

/** Wall time this simulation has spent writing CSV snapshots, HDF5 snapshots (with the XDMF
 *  sidecar) and checkpoints [s] (any pointer may be NULL). */
void mixsph_sim_output_time(const mixsph_sim *s, double *csv_s, double *hdf5_s, double *checkpoint_s);

/** The JSON text and origin (file name) the simulation was created from (for metadata). */
const char *mixsph_sim_case_text(const mixsph_sim *s);
const char *mixsph_sim_case_origin(const mixsph_sim *s);

/* ---- queries: walls and case parameters (for hosts such as the FMU) ------------------------ */

/** Number of walls of the case (the "walls" object, in file order). */
size_t mixsph_sim_wall_count(const mixsph_sim *s);
/** Name of wall `k` as the case names it (the name mixsph_sim_set_wall_velocity takes), or NULL
 *  when k >= mixsph_sim_wall_count. */
const char *mixsph_sim_wall_name(const mixsph_sim *s, size_t k);
/** Number of media of the case (the "media" object, in file order). */
size_t mixsph_sim_medium_count(const mixsph_sim *s);
/** Name of medium `k` as the case names it, or NULL when k >= mixsph_sim_medium_count. */
const char *mixsph_sim_medium_name(const mixsph_sim *s, size_t k);
/** The material law medium `k` runs ("newtonian", "paper", "elastic_plastic", "linear"): the one
 *  its `law` names or, when it names none, the one its keys imply (docs/cases.md); NULL when k is
 *  out of range. */
const char *mixsph_sim_medium_law(const mixsph_sim *s, size_t k);
/** 1 if wall `k` has a prescribed motion in the case (it can be driven by
 *  mixsph_sim_set_wall_velocity), 0 if it is fixed or k is out of range. */
int mixsph_sim_wall_moves(const mixsph_sim *s, size_t k);
/** The direction of travel of moving wall `k`: the unit vector (*ux, *uz) of the fastest row of
 *  its motion law's velocity table (the first one if several tie), before the law's scales.
 *  MIXSPH_ERR_ARG (and 0, 0) for a fixed wall, a k out of range or a law that never moves. */
mixsph_status mixsph_sim_wall_travel_direction(const mixsph_sim *s, size_t k, double *ux, double *uz);

/** Whether the case file `case_path` declares `name` in its `parameters` block, i.e. lets a host
 *  set it by the override "parameters.NAME" (*declared = 1) or not (0; also when the case has no
 *  such block). An override of an undeclared parameter is refused by mixsph_sim_create
 *  (MIXSPH_ERR_CASE); a host that maps its own parameters onto a case's asks first, to give its
 *  own message. MIXSPH_ERR_IO or MIXSPH_ERR_CASE, with a message
 *  in err, when the file cannot be read or is not JSON. */
mixsph_status mixsph_case_declares_parameter(const char *case_path, const char *name, int *declared, char *err,
                                             size_t err_len);
/** The value simulation s uses for a numeric key of its case's top level, `numerics` or `output`
 *  (e.g. "numerics.cfl": the case file's, an override's or the default; a choice as its number).
 *  MIXSPH_ERR_ARG for another key. */
mixsph_status mixsph_sim_case_number(const mixsph_sim *s, const char *key, double *value);

/** The names the case file `case_path` declares in its `parameters` block, in file order,
 *  separated by ", " into names[names_len] (cut short if it does not fit), and their number in *n
 *  ("" and 0 when it declares none). Errors as mixsph_case_declares_parameter. */
mixsph_status mixsph_case_parameter_names(const char *case_path, char *names, size_t names_len, size_t *n,
                                          char *err, size_t err_len);

#ifdef __cplusplus
}
#endif
#endif
