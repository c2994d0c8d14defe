/* sim_dimension.c - the public API (mixsph.h) of the library for both dimensions: the library is
 * compiled twice, for DIM = 2 and DIM = 3 (core/dim.h), and both builds are linked into one
 * binary with distinct symbols (cmake/both_dimensions.cmake: the 3D build's symbols carry the
 * prefix dim3_, the 2D build's public functions dim2_). A simulation is created by the build of
 * its case's "dimensions" (2 by default; a saved state or checkpoint by the build that saved it)
 * and every later call goes to that build. The 2D build's code is the 2D library's, unchanged,
 * so a 2D case runs bit for bit as in the 2D library (docs/development.md, "Dimensions").
 *
 * A mixsph_sim here is a handle holding the dimension and the build's own simulation object. */
#include <cjson/cJSON.h>
#include <stdlib.h>
#include <string.h>

#include "case.h"
#include "mixsph.h"
#include "output.h"
#include "state.h"
#include "status.h"

/* a build's own simulation object (struct mixsph_sim of its sim_object.h) */
typedef struct sim_build sim_build;

struct mixsph_sim {
    int dim;          /* 2 or 3: the build that owns `build` */
    sim_build *build;
};

/* ---- the two builds' public functions ------------------------------------------------------ */

#define BOTH(ret, name, params) ret dim2_mixsph_##name params; ret dim3_mixsph_##name params;
BOTH(mixsph_status, sim_create_from_text, (const char *json_text, const char *origin, const mixsph_override *ov,
                                           size_t n_ov, sim_build **out, char *err, size_t err_len))
BOTH(mixsph_status, sim_create_interruptible, (const char *case_path, const mixsph_override *ov, size_t n_ov,
                                               const mixsph_interrupt *interrupt, sim_build **out, char *err,
                                               size_t err_len))
BOTH(mixsph_status, sim_create_from_state, (const void *buf, size_t len, sim_build **out, char *err, size_t err_len))
BOTH(mixsph_status, sim_create_from_checkpoint_interruptible, (const char *path, const mixsph_interrupt *interrupt,
                                                               sim_build **out, char *err, size_t err_len))
BOTH(void, sim_destroy, (sim_build *s))
BOTH(void, sim_set_interrupt, (sim_build *s, const mixsph_interrupt *interrupt))
BOTH(mixsph_status, sim_set_threads, (sim_build *s, int n_threads))
BOTH(mixsph_status, sim_set_output_dir, (sim_build *s, const char *dir))
BOTH(mixsph_status, sim_advance_to, (sim_build *s, double t))
BOTH(mixsph_status, sim_step, (sim_build *s))
BOTH(const char *, sim_last_error, (const sim_build *s))
BOTH(double, sim_time, (const sim_build *s))
BOTH(double, sim_end_time, (const sim_build *s))
BOTH(double, sim_dt, (const sim_build *s))
BOTH(uint64_t, sim_steps, (const sim_build *s))
BOTH(double, sim_run_wall_time, (const sim_build *s))
BOTH(mixsph_status, sim_viscous_cost, (const sim_build *s, uint64_t *iterations, double *wall_s))
BOTH(size_t, sim_particles, (const sim_build *s))
BOTH(size_t, sim_wall_particles, (const sim_build *s))
BOTH(const char *, sim_name, (const sim_build *s))
BOTH(size_t, sim_output_count, (const sim_build *s))
BOTH(const char *, sim_output_name, (const sim_build *s, size_t k))
BOTH(double, sim_output_value, (const sim_build *s, size_t k))
BOTH(void, sim_output_extremes, (const sim_build *s, size_t k, double *max, double *t_max, double *min, double *t_min))
BOTH(long, sim_output_find, (const sim_build *s, const char *name))
BOTH(mixsph_status, sim_particles_view, (const sim_build *s, mixsph_particles_view *v))
BOTH(size_t, sim_particle_field_count, (const sim_build *s))
BOTH(mixsph_status, sim_particle_field, (const sim_build *s, size_t k, mixsph_particle_field *f))
BOTH(mixsph_status, sim_particle_field_find, (const sim_build *s, const char *name, mixsph_particle_field *f))
BOTH(mixsph_status, sim_set_wall_velocity, (sim_build *s, const char *wall, double vx, double vz))
BOTH(mixsph_status, sim_release_wall_velocity, (sim_build *s, const char *wall))
BOTH(mixsph_status, sim_save_state, (const sim_build *s, void **buf, size_t *len))
BOTH(mixsph_status, sim_load_state, (sim_build *s, const void *buf, size_t len))
BOTH(mixsph_status, sim_write_checkpoint, (sim_build *s, const char *path))
BOTH(mixsph_status, sim_resume_output_dir, (sim_build *s, const char *dir))
BOTH(mixsph_status, sim_set_csv_snapshots, (sim_build *s, int on))
BOTH(void, sim_output_time, (const sim_build *s, double *csv_s, double *hdf5_s, double *checkpoint_s))
BOTH(const char *, sim_case_text, (const sim_build *s))
BOTH(const char *, sim_case_origin, (const sim_build *s))
BOTH(size_t, sim_medium_count, (const sim_build *s))
BOTH(const char *, sim_medium_name, (const sim_build *s, size_t k))
BOTH(const char *, sim_medium_law, (const sim_build *s, size_t k))
BOTH(size_t, sim_wall_count, (const sim_build *s))
BOTH(const char *, sim_wall_name, (const sim_build *s, size_t k))
BOTH(int, sim_wall_moves, (const sim_build *s, size_t k))
BOTH(mixsph_status, sim_wall_travel_direction, (const sim_build *s, size_t k, double *ux, double *uz))
BOTH(mixsph_status, sim_case_number, (const sim_build *s, const char *key, double *value))
/* functions of no simulation: the 2D build's */
const char *dim2_mixsph_status_string(mixsph_status st);
mixsph_status dim2_mixsph_override_parse(char *text, mixsph_override *out, char *err, size_t err_len);
void dim2_mixsph_state_free(void *buf);
mixsph_status dim2_mixsph_case_declares_parameter(const char *case_path, const char *name, int *declared, char *err,
                                                  size_t err_len);
mixsph_status dim2_mixsph_case_parameter_names(const char *case_path, char *names, size_t names_len, size_t *n,
                                               char *err, size_t err_len);
#undef BOTH

/* A call of a simulation's function in the build that owns it; a NULL simulation goes to the 2D
 * build, which answers it as the 2D library does. */
#define BUILD(s) ((s) ? (s)->build : NULL)
#define CALL(s, name, ...) \
    ((s) && (s)->dim == 3 ? dim3_mixsph_##name(BUILD(s), __VA_ARGS__) : dim2_mixsph_##name(BUILD(s), __VA_ARGS__))
#define CALL0(s, name) ((s) && (s)->dim == 3 ? dim3_mixsph_##name(BUILD(s)) : dim2_mixsph_##name(BUILD(s)))

/* ---- the dimension of a case ---------------------------------------------------------------- */

/* The dimension a case asks for: an override of "dimensions", else the file's key (a number, or
 * "$name" of one of its parameters), else 2. A value other than 3 goes to the 2D build, whose
 * case reader refuses any value but 2 with the key's message. */
static int case_dimension(const char *text, const mixsph_override *ov, size_t n_ov)
{
    for (size_t k = n_ov; ov && k-- > 0;)
        if (ov[k].key && strcmp(ov[k].key, "dimensions") == 0) return ov[k].value == 3.0 ? 3 : 2;
    cJSON *root = text ? cJSON_Parse(text) : NULL;
    const cJSON *d = cJSON_GetObjectItemCaseSensitive(root, "dimensions");
    if (cJSON_IsString(d) && d->valuestring[0] == '$')
        d = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(root, "parameters"), d->valuestring + 1);
    const int dim = cJSON_IsNumber(d) && d->valuedouble == 3.0 ? 3 : 2;
    cJSON_Delete(root);
    return dim;
}

/* Wrap a build's new simulation in a handle (on failure the build's is destroyed). */
static mixsph_status wrap(mixsph_status st, int dim, sim_build *b, mixsph_sim **out, char *err, size_t err_len)
{
    if (st != MIXSPH_OK) return st;
    mixsph_sim *s = malloc(sizeof *s);
    if (!s) {
        if (dim == 3) dim3_mixsph_sim_destroy(b);
        else dim2_mixsph_sim_destroy(b);
        return status_set(err, err_len, MIXSPH_ERR_NOMEM, "out of memory");
    }
    *s = (mixsph_sim){dim, b};
    *out = s;
    return MIXSPH_OK;
}

/* ---- creation ----------------------------------------------------------------------------- */

mixsph_status mixsph_sim_create_from_text(const char *json_text, const char *origin, const mixsph_override *ov,
                                          size_t n_ov, mixsph_sim **out, char *err, size_t err_len)
{
    if (!out) return dim2_mixsph_sim_create_from_text(json_text, origin, ov, n_ov, NULL, err, err_len);
    *out = NULL;
    sim_build *b = NULL;
    const int dim = case_dimension(json_text, ov, n_ov);
    const mixsph_status st = dim == 3 ? dim3_mixsph_sim_create_from_text(json_text, origin, ov, n_ov, &b, err, err_len)
                                      : dim2_mixsph_sim_create_from_text(json_text, origin, ov, n_ov, &b, err, err_len);
    return wrap(st, dim, b, out, err, err_len);
}

mixsph_status mixsph_sim_create_interruptible(const char *case_path, const mixsph_override *ov, size_t n_ov,
                                              const mixsph_interrupt *interrupt, mixsph_sim **out, char *err,
                                              size_t err_len)
{
    if (!out || !case_path) return dim2_mixsph_sim_create_interruptible(case_path, ov, n_ov, interrupt, NULL, err, err_len);
    *out = NULL;
    /* the file is read here for its dimension and again by the build (which names it in its
     * messages); a case file is small */
    char *text = NULL;
    int dim = 2;
    if (case_read_file(case_path, &text, err, err_len) == MIXSPH_OK) dim = case_dimension(text, ov, n_ov);
    free(text);
    sim_build *b = NULL;
    const mixsph_status st =
        dim == 3 ? dim3_mixsph_sim_create_interruptible(case_path, ov, n_ov, interrupt, &b, err, err_len)
                 : dim2_mixsph_sim_create_interruptible(case_path, ov, n_ov, interrupt, &b, err, err_len);
    return wrap(st, dim, b, out, err, err_len);
}

mixsph_status mixsph_sim_create(const char *case_path, const mixsph_override *ov, size_t n_ov, mixsph_sim **out,
                                char *err, size_t err_len)
{
    return mixsph_sim_create_interruptible(case_path, ov, n_ov, NULL, out, err, err_len);
}

mixsph_status mixsph_sim_create_from_state(const void *buf, size_t len, mixsph_sim **out, char *err, size_t err_len)
{
    if (!out) return dim2_mixsph_sim_create_from_state(buf, len, NULL, err, err_len);
    *out = NULL;
    const int dim = state_dimension(buf, len) == 3 ? 3 : 2; /* not a state: the 2D build says why */
    sim_build *b = NULL;
    const mixsph_status st = dim == 3 ? dim3_mixsph_sim_create_from_state(buf, len, &b, err, err_len)
                                      : dim2_mixsph_sim_create_from_state(buf, len, &b, err, err_len);
    return wrap(st, dim, b, out, err, err_len);
}

mixsph_status mixsph_sim_create_from_checkpoint_interruptible(const char *path, const mixsph_interrupt *interrupt,
                                                              mixsph_sim **out, char *err, size_t err_len)
{
    if (!out || !path) return dim2_mixsph_sim_create_from_checkpoint_interruptible(path, interrupt, NULL, err, err_len);
    *out = NULL;
    /* the state in the checkpoint says its dimension; the file is read twice (here, then by the
     * build), which costs a fraction of the restart's own setup */
    unsigned char *state = NULL;
    size_t len = 0;
    double run_wall = 0.0;
    int dim = 2;
    if (output_read_checkpoint(path, &state, &len, &run_wall, err, err_len) == MIXSPH_OK)
        dim = state_dimension(state, len) == 3 ? 3 : 2;
    free(state);
    sim_build *b = NULL;
    const mixsph_status st = dim == 3 ? dim3_mixsph_sim_create_from_checkpoint_interruptible(path, interrupt, &b, err, err_len)
                                      : dim2_mixsph_sim_create_from_checkpoint_interruptible(path, interrupt, &b, err, err_len);
    return wrap(st, dim, b, out, err, err_len);
}

mixsph_status mixsph_sim_create_from_checkpoint(const char *path, mixsph_sim **out, char *err, size_t err_len)
{
    return mixsph_sim_create_from_checkpoint_interruptible(path, NULL, out, err, err_len);
}

void mixsph_sim_destroy(mixsph_sim *s)
{
    if (!s) return;
    if (s->dim == 3) dim3_mixsph_sim_destroy(s->build);
    else dim2_mixsph_sim_destroy(s->build);
    free(s);
}

/* ---- functions of no simulation -------------------------------------------------------------- */

const char *mixsph_status_string(mixsph_status st) { return dim2_mixsph_status_string(st); }

mixsph_status mixsph_override_parse(char *text, mixsph_override *out, char *err, size_t err_len)
{
    return dim2_mixsph_override_parse(text, out, err, err_len);
}

void mixsph_state_free(void *buf) { dim2_mixsph_state_free(buf); }

mixsph_status mixsph_case_declares_parameter(const char *case_path, const char *name, int *declared, char *err,
                                             size_t err_len)
{
    return dim2_mixsph_case_declares_parameter(case_path, name, declared, err, err_len);
}

mixsph_status mixsph_case_parameter_names(const char *case_path, char *names, size_t names_len, size_t *n, char *err,
                                          size_t err_len)
{
    return dim2_mixsph_case_parameter_names(case_path, names, names_len, n, err, err_len);
}

/* ---- a simulation's functions: its build's ------------------------------------------------- */

void mixsph_sim_set_interrupt(mixsph_sim *s, const mixsph_interrupt *interrupt) { CALL(s, sim_set_interrupt, interrupt); }
mixsph_status mixsph_sim_set_threads(mixsph_sim *s, int n_threads) { return CALL(s, sim_set_threads, n_threads); }
mixsph_status mixsph_sim_set_output_dir(mixsph_sim *s, const char *dir) { return CALL(s, sim_set_output_dir, dir); }
mixsph_status mixsph_sim_advance_to(mixsph_sim *s, double t) { return CALL(s, sim_advance_to, t); }
mixsph_status mixsph_sim_step(mixsph_sim *s) { return CALL0(s, sim_step); }
const char *mixsph_sim_last_error(const mixsph_sim *s) { return CALL0(s, sim_last_error); }
double mixsph_sim_time(const mixsph_sim *s) { return CALL0(s, sim_time); }
double mixsph_sim_end_time(const mixsph_sim *s) { return CALL0(s, sim_end_time); }
double mixsph_sim_dt(const mixsph_sim *s) { return CALL0(s, sim_dt); }
uint64_t mixsph_sim_steps(const mixsph_sim *s) { return CALL0(s, sim_steps); }
double mixsph_sim_run_wall_time(const mixsph_sim *s) { return CALL0(s, sim_run_wall_time); }
mixsph_status mixsph_sim_viscous_cost(const mixsph_sim *s, uint64_t *iterations, double *wall_s)
{
    return CALL(s, sim_viscous_cost, iterations, wall_s);
}
size_t mixsph_sim_particles(const mixsph_sim *s) { return CALL0(s, sim_particles); }
size_t mixsph_sim_wall_particles(const mixsph_sim *s) { return CALL0(s, sim_wall_particles); }
const char *mixsph_sim_name(const mixsph_sim *s) { return CALL0(s, sim_name); }
size_t mixsph_sim_output_count(const mixsph_sim *s) { return CALL0(s, sim_output_count); }
const char *mixsph_sim_output_name(const mixsph_sim *s, size_t k) { return CALL(s, sim_output_name, k); }
double mixsph_sim_output_value(const mixsph_sim *s, size_t k) { return CALL(s, sim_output_value, k); }
void mixsph_sim_output_extremes(const mixsph_sim *s, size_t k, double *max, double *t_max, double *min, double *t_min)
{
    CALL(s, sim_output_extremes, k, max, t_max, min, t_min);
}
long mixsph_sim_output_find(const mixsph_sim *s, const char *name) { return CALL(s, sim_output_find, name); }
mixsph_status mixsph_sim_particles_view(const mixsph_sim *s, mixsph_particles_view *v)
{
    return CALL(s, sim_particles_view, v);
}
size_t mixsph_sim_particle_field_count(const mixsph_sim *s) { return CALL0(s, sim_particle_field_count); }
mixsph_status mixsph_sim_particle_field(const mixsph_sim *s, size_t k, mixsph_particle_field *f)
{
    return CALL(s, sim_particle_field, k, f);
}
mixsph_status mixsph_sim_particle_field_find(const mixsph_sim *s, const char *name, mixsph_particle_field *f)
{
    return CALL(s, sim_particle_field_find, name, f);
}
mixsph_status mixsph_sim_set_wall_velocity(mixsph_sim *s, const char *wall, double vx, double vz)
{
    return CALL(s, sim_set_wall_velocity, wall, vx, vz);
}
mixsph_status mixsph_sim_release_wall_velocity(mixsph_sim *s, const char *wall)
{
    return CALL(s, sim_release_wall_velocity, wall);
}
mixsph_status mixsph_sim_save_state(const mixsph_sim *s, void **buf, size_t *len)
{
    return CALL(s, sim_save_state, buf, len);
}
mixsph_status mixsph_sim_load_state(mixsph_sim *s, const void *buf, size_t len)
{
    return CALL(s, sim_load_state, buf, len);
}
mixsph_status mixsph_sim_write_checkpoint(mixsph_sim *s, const char *path) { return CALL(s, sim_write_checkpoint, path); }
mixsph_status mixsph_sim_resume_output_dir(mixsph_sim *s, const char *dir) { return CALL(s, sim_resume_output_dir, dir); }
mixsph_status mixsph_sim_set_csv_snapshots(mixsph_sim *s, int on) { return CALL(s, sim_set_csv_snapshots, on); }
void mixsph_sim_output_time(const mixsph_sim *s, double *csv_s, double *hdf5_s, double *checkpoint_s)
{
    CALL(s, sim_output_time, csv_s, hdf5_s, checkpoint_s);
}
const char *mixsph_sim_case_text(const mixsph_sim *s) { return CALL0(s, sim_case_text); }
const char *mixsph_sim_case_origin(const mixsph_sim *s) { return CALL0(s, sim_case_origin); }
size_t mixsph_sim_medium_count(const mixsph_sim *s) { return CALL0(s, sim_medium_count); }
const char *mixsph_sim_medium_name(const mixsph_sim *s, size_t k) { return CALL(s, sim_medium_name, k); }
const char *mixsph_sim_medium_law(const mixsph_sim *s, size_t k) { return CALL(s, sim_medium_law, k); }
size_t mixsph_sim_wall_count(const mixsph_sim *s) { return CALL0(s, sim_wall_count); }
const char *mixsph_sim_wall_name(const mixsph_sim *s, size_t k) { return CALL(s, sim_wall_name, k); }
int mixsph_sim_wall_moves(const mixsph_sim *s, size_t k) { return CALL(s, sim_wall_moves, k); }
mixsph_status mixsph_sim_wall_travel_direction(const mixsph_sim *s, size_t k, double *ux, double *uz)
{
    return CALL(s, sim_wall_travel_direction, k, ux, uz);
}
mixsph_status mixsph_sim_case_number(const mixsph_sim *s, const char *key, double *value)
{
    return CALL(s, sim_case_number, key, value);
}
