/* landslide_model.c - the LandslideWave model binding: which variables the FMU has, how each
 * reaches the mixsph library, which outputs it reads. The FMI life cycle, the simulation and the
 * FMU state are the generic glue's (fmi2_glue.c, through the seam fmi2_glue.h); the physics is
 * lib/ (docs/model.md). The variables, their value references, starts and bounds come from
 * modelDescription.xml through the generated fmu_variables.h.
 *
 * How the parameters reach the case (docs/fmu.md, docs/cases.md):
 *   - the physical ones (reservoir_level, phi, mu0, mu_thr, saturated, porosity, grain_density,
 *     tension_cutoff, plate_duration_scale, plate_stroke_scale, rheology, grain_bulk_modulus, nu,
 *     cohesion, bed_friction) are overrides "parameters.NAME"
 *     of the case's `parameters` block: a case declares there the names it lets a host set and
 *     uses them as "$NAME" values, so any case file that declares them works, whatever its
 *     media, bodies and walls are called. One the host sets and the case does not declare is an
 *     fmi2Error naming it (the glue checks). rheology, an Enumeration, reaches the case as its
 *     item's value, the number of the granular law in the case (media.NAME.law: 0 paper, 1
 *     elastic_plastic, docs/cases.md), which then ignores the parameters of the law it does not
 *     use (mu_thr, mu0, tension_cutoff, or nu, cohesion);
 *   - the numerical ones (dx, output_interval, pressure_smoothing, av_wall, implicit_viscosity) override the
 *     numerics and output keys every case has; threads is the library's thread count.
 * A parameter the host never sets gets no override: it keeps the case file's value, so an
 * instance with no parameter set runs exactly what `mixsph run CASE` runs.
 *
 * Outputs are the case's monitors of the names run_up (max_elevation), landslide_front
 * (front), water_kinetic_energy (kinetic_energy) and the library's diagnostics; a case without
 * one of those monitors gives NaN there. The input push_velocity drives the case's first moving
 * wall along its direction of travel (both asked of the library) while push_external is true. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "fmi2_glue.h"
#include "fmu_variables.h"

/* ---- parameters: value references and bounds from modelDescription.xml, case keys here ----- */

struct real_param {
    fmi2ValueReference vr;
    const char *name;
    const char *key; /* the case key the parameter overrides */
    double start, min, max;
};

#define CASE_PARAM(n) {VR_##n, #n, "parameters." #n, START_##n, MIN_##n, MAX_##n}
#define KEY_PARAM(n, key) {VR_##n, #n, key, START_##n, MIN_##n, MAX_##n}
enum {
    P_RESERVOIR_LEVEL,
    P_PHI,
    P_MU0,
    P_MU_THR,
    P_PLATE_DURATION_SCALE,
    P_PLATE_STROKE_SCALE,
    P_POROSITY,
    P_GRAIN_DENSITY,
    P_DX,
    P_OUTPUT_INTERVAL,
    P_PRESSURE_SMOOTHING,
    P_GRAIN_BULK_MODULUS,
    P_NU,
    P_COHESION,
    P_BED_FRICTION,
    N_REAL_PARAMS
};
static const struct real_param real_params[N_REAL_PARAMS] = {
    [P_RESERVOIR_LEVEL] = CASE_PARAM(reservoir_level),
    [P_PHI] = CASE_PARAM(phi),
    [P_MU0] = CASE_PARAM(mu0),
    [P_MU_THR] = CASE_PARAM(mu_thr),
    [P_PLATE_DURATION_SCALE] = CASE_PARAM(plate_duration_scale),
    [P_PLATE_STROKE_SCALE] = CASE_PARAM(plate_stroke_scale),
    [P_POROSITY] = CASE_PARAM(porosity),
    [P_GRAIN_DENSITY] = CASE_PARAM(grain_density),
    [P_DX] = KEY_PARAM(dx, "numerics.dx"),
    [P_OUTPUT_INTERVAL] = KEY_PARAM(output_interval, "output.monitor_interval"),
    [P_PRESSURE_SMOOTHING] = KEY_PARAM(pressure_smoothing, "numerics.pressure_smoothing"),
    [P_GRAIN_BULK_MODULUS] = CASE_PARAM(grain_bulk_modulus),
    [P_NU] = CASE_PARAM(nu),
    [P_COHESION] = CASE_PARAM(cohesion),
    [P_BED_FRICTION] = CASE_PARAM(bed_friction),
};

/* Boolean parameters: passed to the case as 0/1 overrides of `key` when the host sets them. */
enum { B_SATURATED, B_TENSION_CUTOFF, B_AV_WALL, B_IMPLICIT_VISCOSITY, N_BOOL_PARAMS };
static const struct {
    fmi2ValueReference vr;
    const char *name, *key;
    int start;
} bool_params[N_BOOL_PARAMS] = {
    [B_SATURATED] = {VR_saturated, "saturated", "parameters.saturated", START_saturated},
    [B_TENSION_CUTOFF] = {VR_tension_cutoff, "tension_cutoff", "parameters.tension_cutoff", START_tension_cutoff},
    [B_AV_WALL] = {VR_av_wall, "av_wall", "numerics.av_wall", START_av_wall},
    [B_IMPLICIT_VISCOSITY] = {VR_implicit_viscosity, "implicit_viscosity", "numerics.viscosity", /* 0/1: its choices */
                              START_implicit_viscosity},
};

/* Enumeration parameters: passed to the case as their item's value when the host sets them. The
 * items' names (for messages) from MIN to MAX, as modelDescription.xml lists them. */
static const char *const rheology_items[] = {"paper", "elastic_plastic"};
_Static_assert(sizeof rheology_items / sizeof rheology_items[0] == MAX_rheology - MIN_rheology + 1,
               "rheology_items must name the Rheology items of modelDescription.xml");
enum { E_RHEOLOGY, N_ENUM_PARAMS };
static const struct {
    fmi2ValueReference vr;
    const char *name, *key;
    int start, min, max;
    const char *const *items;
} enum_params[N_ENUM_PARAMS] = {
    [E_RHEOLOGY] = {VR_rheology, "rheology", "parameters.rheology", START_rheology, MIN_rheology, MAX_rheology,
                    rheology_items},
};

/* Outputs read from the library by name. */
enum { O_RUN_UP, O_FRONT, O_KE, O_DT, O_LOST, O_FIXED, O_RUN_UP_Z, O_KE_WATER, O_EXCLUDED, N_OUTS };
static const char *const out_names[N_OUTS] = {
    [O_RUN_UP] = "run_up",       [O_FRONT] = "landslide_front",      [O_KE] = "kinetic_energy",
    [O_DT] = "dt",               [O_LOST] = "lost_particles",        [O_FIXED] = "fixed_particles",
    [O_RUN_UP_Z] = "run_up_Z",   [O_KE_WATER] = "water_kinetic_energy", [O_EXCLUDED] = "excluded_particles"};

/* The instance's data (the glue saves it with an FMU state): plain bytes, no pointers. */
struct landslide_data {
    double real[N_REAL_PARAMS];
    int real_set[N_REAL_PARAMS]; /* set by the host: passed to the case as an override */
    int flag[N_BOOL_PARAMS], flag_set[N_BOOL_PARAMS];
    int item[N_ENUM_PARAMS], item_set[N_ENUM_PARAMS];
    int threads;
    char case_file[FMU_PATH_LEN];
    double push_velocity; /* [m/s] along the moving wall's direction of travel */
    int push_external;
    int push_applied;      /* the library's wall is driven by push_velocity (the library state holds it too) */
    double push_applied_v; /* with this velocity [m/s] */
    /* looked up from the simulation by attach (derived, not settings) */
    long out[N_OUTS];
    long wall;           /* index of the moving wall pushed by push_velocity, -1 if the case has none */
    double dir_x, dir_z; /* its unit direction of travel */
};

static struct landslide_data *data_of(const struct fmu_instance *in)
{
    return in->data;
}

static int real_param_index(fmi2ValueReference vr)
{
    for (int k = 0; k < N_REAL_PARAMS; k++)
        if (real_params[k].vr == vr) return k;
    return -1;
}

static int bool_param_index(fmi2ValueReference vr)
{
    for (int k = 0; k < N_BOOL_PARAMS; k++)
        if (bool_params[k].vr == vr) return k;
    return -1;
}

static int enum_param_index(fmi2ValueReference vr)
{
    for (int k = 0; k < N_ENUM_PARAMS; k++)
        if (enum_params[k].vr == vr) return k;
    return -1;
}

static void set_defaults(void *data)
{
    struct landslide_data *d = data;
    for (int k = 0; k < N_REAL_PARAMS; k++) d->real[k] = real_params[k].start;
    for (int k = 0; k < N_BOOL_PARAMS; k++) d->flag[k] = bool_params[k].start;
    for (int k = 0; k < N_ENUM_PARAMS; k++) d->item[k] = enum_params[k].start;
    d->threads = START_threads;
    snprintf(d->case_file, sizeof d->case_file, "%s", START_case_file);
    d->push_velocity = START_push_velocity;
    d->push_external = START_push_external;
    d->wall = -1;
}

/* ---- the simulation ----------------------------------------------------------------------- */

/* every parameter set at once fits in one request */
_Static_assert(N_REAL_PARAMS + N_BOOL_PARAMS + N_ENUM_PARAMS <= FMU_MAX_OVERRIDES,
               "FMU_MAX_OVERRIDES too small for the parameters");

static void request(const struct fmu_instance *in, struct fmu_sim_request *req)
{
    const struct landslide_data *d = data_of(in);
    req->case_file = d->case_file;
    req->n_ov = 0;
    for (int k = 0; k < N_REAL_PARAMS; k++)
        if (d->real_set[k]) req->ov[req->n_ov++] = (struct fmu_override){real_params[k].name, {real_params[k].key, d->real[k]}};
    for (int k = 0; k < N_BOOL_PARAMS; k++)
        if (d->flag_set[k])
            req->ov[req->n_ov++] = (struct fmu_override){bool_params[k].name, {bool_params[k].key, d->flag[k] ? 1.0 : 0.0}};
    for (int k = 0; k < N_ENUM_PARAMS; k++)
        if (d->item_set[k])
            req->ov[req->n_ov++] = (struct fmu_override){enum_params[k].name, {enum_params[k].key, (double)d->item[k]}};
}

static fmi2Status attach(struct fmu_instance *in)
{
    struct landslide_data *d = data_of(in);
    d->case_file[sizeof d->case_file - 1] = '\0'; /* a deserialised state is bytes from outside */
    for (int k = 0; k < N_OUTS; k++) d->out[k] = mixsph_sim_output_find(in->sim, out_names[k]);
    d->wall = -1;
    d->dir_x = d->dir_z = 0.0;
    for (size_t k = 0; k < mixsph_sim_wall_count(in->sim) && d->wall < 0; k++)
        if (mixsph_sim_wall_moves(in->sim, k) &&
            mixsph_sim_wall_travel_direction(in->sim, k, &d->dir_x, &d->dir_z) == MIXSPH_OK)
            d->wall = (long)k;
    if (mixsph_sim_set_threads(in->sim, d->threads) != MIXSPH_OK)
        return fmu_fail(in, "threads = %d: %s", d->threads, mixsph_sim_last_error(in->sim));
    return fmi2OK;
}

/* Drive or release the moving wall according to the push inputs. */
static fmi2Status apply_push(struct fmu_instance *in)
{
    struct landslide_data *d = data_of(in);
    if (!in->sim) return fmi2OK;
    if (d->push_external) {
        if (d->wall < 0) return fmu_fail(in, "push_external: the case has no moving wall to push");
        if (d->push_applied && d->push_applied_v == d->push_velocity) return fmi2OK;
        const double v = d->push_velocity;
        if (mixsph_sim_set_wall_velocity(in->sim, mixsph_sim_wall_name(in->sim, (size_t)d->wall), v * d->dir_x,
                                         v * d->dir_z) != MIXSPH_OK)
            return fmu_fail(in, "push_velocity: %s", mixsph_sim_last_error(in->sim));
        d->push_applied = 1;
        d->push_applied_v = v;
    } else if (d->push_applied) {
        if (mixsph_sim_release_wall_velocity(in->sim, mixsph_sim_wall_name(in->sim, (size_t)d->wall)) != MIXSPH_OK)
            return fmu_fail(in, "push_external: %s", mixsph_sim_last_error(in->sim));
        d->push_applied = 0;
    }
    return fmi2OK;
}

/* ---- get ---------------------------------------------------------------------------------- */

static double output_value(const struct fmu_instance *in, int k)
{
    const long idx = data_of(in)->out[k];
    return idx >= 0 ? mixsph_sim_output_value(in->sim, (size_t)idx) : NAN;
}

/* Maximum of output k over the samples, and its time; before the first sample, the current
 * value and time. */
static void output_max(const struct fmu_instance *in, int k, double *max, double *t_max)
{
    const long idx = data_of(in)->out[k];
    *max = *t_max = NAN;
    if (idx < 0) return;
    mixsph_sim_output_extremes(in->sim, (size_t)idx, max, t_max, NULL, NULL);
    if (isnan(*max)) {
        *max = output_value(in, k);
        *t_max = mixsph_sim_time(in->sim);
    }
}

static fmi2Status get_real(struct fmu_instance *in, fmi2ValueReference vr, fmi2Real *value)
{
    const struct landslide_data *d = data_of(in);
    const int p = real_param_index(vr);
    if (p >= 0) {
        *value = d->real[p];
        return fmi2OK;
    }
    if (vr == VR_push_velocity) {
        *value = d->push_velocity;
        return fmi2OK;
    }
    double t;
    switch (vr) {
    case VR_run_up:
    case VR_max_run_up:
    case VR_time_of_max_run_up:
    case VR_landslide_front:
    case VR_kinetic_energy:
    case VR_water_kinetic_energy:
    case VR_dt:
    case VR_max_run_up_Z:
        if (fmu_need_simulation(in) != fmi2OK) return fmi2Error;
        break;
    default: return fmu_reject(in, "fmi2GetReal: no Real variable with value reference %u", vr);
    }
    switch (vr) {
    case VR_run_up: *value = output_value(in, O_RUN_UP); break;
    case VR_max_run_up: output_max(in, O_RUN_UP, value, &t); break;
    case VR_time_of_max_run_up: output_max(in, O_RUN_UP, &t, value); break;
    case VR_landslide_front: *value = output_value(in, O_FRONT); break;
    case VR_kinetic_energy: *value = output_value(in, O_KE); break;
    case VR_water_kinetic_energy: *value = output_value(in, O_KE_WATER); break;
    case VR_dt: *value = output_value(in, O_DT); break;
    case VR_max_run_up_Z: output_max(in, O_RUN_UP_Z, value, &t); break;
    default: break;
    }
    return fmi2OK;
}

static fmi2Status get_integer(struct fmu_instance *in, fmi2ValueReference vr, fmi2Integer *value)
{
    if (vr == VR_threads) {
        *value = data_of(in)->threads;
        return fmi2OK;
    }
    const int e = enum_param_index(vr);
    if (e >= 0) {
        *value = data_of(in)->item[e];
        return fmi2OK;
    }
    if (vr != VR_fixed_particles && vr != VR_lost_particles && vr != VR_excluded_particles && vr != VR_steps)
        return fmu_reject(in, "fmi2GetInteger: no Integer variable with value reference %u", vr);
    if (fmu_need_simulation(in) != fmi2OK) return fmi2Error;
    const double v = vr == VR_steps                ? (double)mixsph_sim_steps(in->sim)
                     : vr == VR_fixed_particles    ? output_value(in, O_FIXED)
                     : vr == VR_excluded_particles ? output_value(in, O_EXCLUDED)
                                                   : output_value(in, O_LOST);
    *value = isfinite(v) && v < 2147483647.0 ? (fmi2Integer)v : -1;
    return fmi2OK;
}

static fmi2Status get_boolean(struct fmu_instance *in, fmi2ValueReference vr, fmi2Boolean *value)
{
    const struct landslide_data *d = data_of(in);
    const int b = bool_param_index(vr);
    if (b >= 0) *value = d->flag[b] ? fmi2True : fmi2False;
    else if (vr == VR_push_external) *value = d->push_external ? fmi2True : fmi2False;
    else return fmu_reject(in, "fmi2GetBoolean: no Boolean variable with value reference %u", vr);
    return fmi2OK;
}

static fmi2Status get_string(struct fmu_instance *in, fmi2ValueReference vr, fmi2String *value)
{
    if (vr != VR_case_file) return fmu_reject(in, "fmi2GetString: no String variable with value reference %u", vr);
    *value = data_of(in)->case_file;
    return fmi2OK;
}

/* ---- set ---------------------------------------------------------------------------------- */

static fmi2Status set_real(struct fmu_instance *in, fmi2ValueReference vr, fmi2Real v)
{
    struct landslide_data *d = data_of(in);
    const int p = real_param_index(vr);
    if (p >= 0) {
        const struct real_param *rp = &real_params[p];
        if (fmu_parameter_settable(in, rp->name) != fmi2OK) return fmi2Error;
        if (!isfinite(v) || v < rp->min || v > rp->max)
            return fmu_reject(in, "%s = %g is out of range [%g, %g]", rp->name, v, rp->min, rp->max);
        d->real[p] = v;
        d->real_set[p] = 1;
        return fmi2OK;
    }
    if (vr == VR_push_velocity) {
        if (!isfinite(v) || v < MIN_push_velocity || v > MAX_push_velocity)
            return fmu_reject(in, "push_velocity = %g m/s is out of range [%g, %g]", v, (double)MIN_push_velocity,
                              (double)MAX_push_velocity);
        d->push_velocity = v;
        return in->mode == FMU_MODE_STEP ? apply_push(in) : fmi2OK;
    }
    return fmu_reject(in, "fmi2SetReal: no settable Real variable with value reference %u", vr);
}

/* An Enumeration parameter: one of its items' values. */
static fmi2Status set_enum(struct fmu_instance *in, int e, fmi2Integer v)
{
    if (fmu_parameter_settable(in, enum_params[e].name) != fmi2OK) return fmi2Error;
    if (v < enum_params[e].min || v > enum_params[e].max) {
        char items[256];
        size_t at = 0;
        items[0] = '\0';
        for (int k = enum_params[e].min; k <= enum_params[e].max && at < sizeof items; k++)
            at += (size_t)snprintf(items + at, sizeof items - at, "%s%d (%s)", k > enum_params[e].min ? ", " : "", k,
                                   enum_params[e].items[k - enum_params[e].min]);
        return fmu_reject(in, "%s = %d is not one of its items: %s", enum_params[e].name, (int)v, items);
    }
    struct landslide_data *d = data_of(in);
    d->item[e] = v;
    d->item_set[e] = 1;
    return fmi2OK;
}

static fmi2Status set_integer(struct fmu_instance *in, fmi2ValueReference vr, fmi2Integer v)
{
    const int e = enum_param_index(vr);
    if (e >= 0) return set_enum(in, e, v);
    if (vr != VR_threads) return fmu_reject(in, "fmi2SetInteger: no settable Integer variable with value reference %u", vr);
    if (fmu_parameter_settable(in, "threads") != fmi2OK) return fmi2Error;
    if (v < MIN_threads || v > MAX_threads)
        return fmu_reject(in, "threads = %d is out of range [%d, %d]", (int)v, MIN_threads, MAX_threads);
    data_of(in)->threads = v;
    return fmi2OK;
}

static fmi2Status set_boolean(struct fmu_instance *in, fmi2ValueReference vr, fmi2Boolean v)
{
    struct landslide_data *d = data_of(in);
    const int b = bool_param_index(vr);
    if (b >= 0) {
        if (fmu_parameter_settable(in, bool_params[b].name) != fmi2OK) return fmi2Error;
        d->flag[b] = v ? 1 : 0;
        d->flag_set[b] = 1;
        return fmi2OK;
    }
    if (vr == VR_push_external) {
        d->push_external = v ? 1 : 0;
        return in->mode == FMU_MODE_STEP ? apply_push(in) : fmi2OK;
    }
    return fmu_reject(in, "fmi2SetBoolean: no settable Boolean variable with value reference %u", vr);
}

static fmi2Status set_string(struct fmu_instance *in, fmi2ValueReference vr, fmi2String v)
{
    struct landslide_data *d = data_of(in);
    if (vr != VR_case_file) return fmu_reject(in, "fmi2SetString: no settable String variable with value reference %u", vr);
    if (fmu_parameter_settable(in, "case_file") != fmi2OK) return fmi2Error;
    if (!v || strlen(v) >= sizeof d->case_file)
        return fmu_reject(in, "case_file: NULL or longer than %zu characters", sizeof d->case_file - 1);
    snprintf(d->case_file, sizeof d->case_file, "%s", v);
    return fmi2OK;
}

const struct fmu_binding fmu_model = {
    .model_name = MIXSPH_FMU_MODEL_NAME,
    .guid = MIXSPH_FMU_GUID,
    .data_size = sizeof(struct landslide_data),
    .set_defaults = set_defaults,
    .get_real = get_real,
    .get_integer = get_integer,
    .get_boolean = get_boolean,
    .get_string = get_string,
    .set_real = set_real,
    .set_integer = set_integer,
    .set_boolean = set_boolean,
    .set_string = set_string,
    .request = request,
    .attach = attach,
    .apply_inputs = apply_push,
};
