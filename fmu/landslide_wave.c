/* landslide_wave.c - the LandslideWave FMU: FMI 2.0 co-simulation glue around the mixsph library.
 *
 * Glue only (value references -> mixsph calls); the physics is lib/ (Manenti et al. 2018, the
 * mixture model, as mixsph implements it). The variables, their value references, starts and
 * bounds come from modelDescription.xml through the generated fmu_variables.h.
 *
 * One struct instance owns everything of an instance (no mutable file-scope state), so several
 * instances live in one process independently. Life cycle:
 *   fmi2Instantiate          -> INSTANTIATED (parameters may be set, checked against min/max)
 *   fmi2EnterInitialization  -> INIT         (parameters and inputs may be set)
 *   fmi2ExitInitialization   -> STEP         (the simulation is created from the case file with
 *                                             the parameters that were set as overrides)
 *   fmi2DoStep               advances the simulation to the end of the communication step
 *                            (mixsph takes its own explicit steps and never shortens one, so on
 *                            return its time is in [t_end, t_end + dt))
 *   an error                 -> ERROR (fmi2Error; only Get*, FreeInstance, Reset, SetFMUstate)
 * Parameters that were never set keep the case file's own values (no override is passed), so an
 * instance with no parameter set runs exactly what `mixsph run CASE` runs.
 *
 * FMU state: fmi2GetFMUstate saves the library state (mixsph_sim_save_state) together with the
 * instance's parameters and inputs; fmi2SetFMUstate restores it (mixsph_sim_load_state when the
 * instance runs the same case and overrides, else a new simulation from the state).
 * Serialised: a header, the instance part, the library's own (checksummed) state bytes.
 *
 * Errors (out-of-range or inconsistent parameters, a missing case file, an unstable run, a call
 * in the wrong state) return fmi2Error with a message through the FMI logger, always logged
 * whatever the debug-logging setting. The library never exits, so neither does the FMU. */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "fmi2Functions.h"
#include "fmu_variables.h"
#include "mixsph.h"

#define FMU_PATH_LEN 4096
#define FMU_MSG_LEN 2048

/* ---- parameter tables (value references and bounds from modelDescription.xml) ------------- */

struct real_param {
    fmi2ValueReference vr;
    const char *name;
    double start, min, max;
};

#define REAL_PARAM(n) {VR_##n, #n, START_##n, MIN_##n, MAX_##n}
enum {
    P_RESERVOIR_LEVEL,
    P_PHI,
    P_MU0,
    P_MU_THR,
    P_DX,
    P_PLATE_DURATION_SCALE,
    P_PLATE_STROKE_SCALE,
    P_POROSITY,
    P_GRAIN_DENSITY,
    P_OUTPUT_INTERVAL,
    P_PRESSURE_SMOOTHING,
    N_REAL_PARAMS
};
static const struct real_param real_params[N_REAL_PARAMS] = {
    REAL_PARAM(reservoir_level), REAL_PARAM(phi),           REAL_PARAM(mu0),
    REAL_PARAM(mu_thr),          REAL_PARAM(dx),            REAL_PARAM(plate_duration_scale),
    REAL_PARAM(plate_stroke_scale), REAL_PARAM(porosity),   REAL_PARAM(grain_density),
    REAL_PARAM(output_interval), REAL_PARAM(pressure_smoothing)};

/* Case keys each real parameter overrides (up to 2; NULL-terminated). The plate scales are
 * handled apart (two parameters give two keys). */
static const char *const real_param_keys[N_REAL_PARAMS][3] = {
    [P_RESERVOIR_LEVEL] = {"parameters.reservoir_level", NULL, NULL},
    [P_PHI] = {"parameters.phi", NULL, NULL},
    [P_MU0] = {"parameters.mu0", NULL, NULL},
    [P_MU_THR] = {"parameters.mu_thr", NULL, NULL},
    [P_DX] = {"numerics.dx", NULL, NULL},
    [P_PLATE_DURATION_SCALE] = {NULL, NULL, NULL},
    [P_PLATE_STROKE_SCALE] = {NULL, NULL, NULL},
    [P_POROSITY] = {"media.slide.porosity", "media.slide_wet.porosity", NULL},
    [P_GRAIN_DENSITY] = {"media.slide.rho", "media.slide_wet.rho", NULL},
    [P_OUTPUT_INTERVAL] = {"output.monitor_interval", NULL, NULL},
    [P_PRESSURE_SMOOTHING] = {"numerics.pressure_smoothing", NULL, NULL},
};

/* Outputs read from the library by name. */
enum { O_RUN_UP, O_FRONT, O_KE, O_DT, O_LOST, O_FIXED, O_RUN_UP_Z, O_KE_WATER, N_OUTS };
static const char *const out_names[N_OUTS] = {"run_up",         "landslide_front", "kinetic_energy",      "dt",
                                              "lost_particles", "fixed_particles", "run_up_Z", "water_kinetic_energy"};

/* Boolean parameters: passed to the case as 0/1 overrides of `key` when the host sets them. */
enum { B_SATURATED, B_TENSION_CUTOFF, B_AV_WALL, N_BOOL_PARAMS };
static const struct {
    fmi2ValueReference vr;
    const char *name, *key;
    int start;
} bool_params[N_BOOL_PARAMS] = {
    {VR_saturated, "saturated", "parameters.saturated", START_saturated},
    {VR_tension_cutoff, "tension_cutoff", "parameters.tension_cutoff", START_tension_cutoff},
    {VR_av_wall, "av_wall", "numerics.av_wall", START_av_wall},
};

/* The Boolean parameter of value reference vr, or -1. */
static int bool_param(fmi2ValueReference vr)
{
    for (int k = 0; k < N_BOOL_PARAMS; k++)
        if (bool_params[k].vr == vr) return k;
    return -1;
}

enum mode { MODE_INSTANTIATED, MODE_INIT, MODE_STEP, MODE_TERMINATED, MODE_ERROR };

/* The instance's settings: what a saved FMU state carries besides the library state. */
struct settings {
    double real[N_REAL_PARAMS];
    int real_set[N_REAL_PARAMS]; /* set by the host: passed to the case as an override */
    int flag[N_BOOL_PARAMS], flag_set[N_BOOL_PARAMS]; /* Boolean parameters (bool_params) */
    int threads;
    char case_file[FMU_PATH_LEN];
    double push_velocity; /* [m/s] along the plate's direction of travel */
    int push_external;
};

struct instance {
    char *name;
    fmi2CallbackFunctions cb;
    int logging_on;
    char resource_dir[FMU_PATH_LEN]; /* "" if the location could not be read */
    enum mode mode;
    struct settings set;
    double start_time;
    double time; /* communication time [s] */
    mixsph_sim *sim;
    long out[N_OUTS];
    char wall[64];         /* the moving wall driven by push_velocity ("" if the case has none) */
    double dir_x, dir_z;   /* unit direction of travel of that wall */
    int push_applied;      /* the library wall is currently driven externally */
    double push_applied_v; /* with this velocity */
    char msg[FMU_MSG_LEN];
};

/* A saved FMU state (fmi2FMUstate). */
struct fmu_state {
    struct settings set;
    double start_time, time;
    int push_applied;
    double push_applied_v;
    void *lib; /* library state (mixsph_sim_save_state, or a copy made by fmi2DeSerializeFMUstate) */
    size_t lib_len;
    int lib_copy; /* lib was allocated here (malloc), not by the library */
};

static void free_lib(struct fmu_state *fs)
{
    if (fs->lib_copy) free(fs->lib);
    else mixsph_state_free(fs->lib);
    fs->lib = NULL;
    fs->lib_copy = 0;
}

#define SER_MAGIC "LWFMUST1"

/* ---- logging ------------------------------------------------------------------------------ */

static void log_msg(struct instance *in, fmi2Status st, const char *cat, const char *fmt, ...)
{
    if (!in || !in->cb.logger) return;
    if (st < fmi2Error && !in->logging_on) return;
    char raw[FMU_MSG_LEN];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(raw, sizeof raw, fmt, ap);
    va_end(ap);
    /* The logger takes a printf format: escape '%'. */
    char *m = in->msg;
    size_t j = 0;
    for (size_t i = 0; raw[i] && j + 2 < sizeof in->msg; i++) {
        if (raw[i] == '%') m[j++] = '%';
        m[j++] = raw[i];
    }
    m[j] = '\0';
    in->cb.logger(in->cb.componentEnvironment, in->name ? in->name : "?", st, cat, m);
}

#define LOG_ERROR(in, ...) log_msg((in), fmi2Error, "logStatusError", __VA_ARGS__)
#define LOG_INFO(in, ...) log_msg((in), fmi2OK, "logInfo", __VA_ARGS__)

/* Enter the error state with a message; returns fmi2Error. */
static fmi2Status fail(struct instance *in, const char *fmt, ...)
{
    char buf[FMU_MSG_LEN];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    in->mode = MODE_ERROR;
    LOG_ERROR(in, "%s", buf);
    return fmi2Error;
}

/* An error that leaves the instance usable (a rejected value); returns fmi2Error. */
static fmi2Status reject(struct instance *in, const char *fmt, ...)
{
    char buf[FMU_MSG_LEN];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    LOG_ERROR(in, "%s", buf);
    return fmi2Error;
}

/* Check the instance pointer and the calling state. */
static int check(struct instance *in, const char *fn, int allowed_modes)
{
    if (!in) return 0;
    if (!(allowed_modes & (1 << in->mode))) {
        static const char *const names[] = {"instantiated", "initialization mode", "step mode", "terminated",
                                            "error"};
        LOG_ERROR(in, "%s: not allowed in %s", fn, names[in->mode]);
        return 0;
    }
    return 1;
}

#define M(x) (1 << (x))
#define M_ANY (M(MODE_INSTANTIATED) | M(MODE_INIT) | M(MODE_STEP) | M(MODE_TERMINATED) | M(MODE_ERROR))
#define M_ALIVE (M(MODE_INSTANTIATED) | M(MODE_INIT) | M(MODE_STEP) | M(MODE_TERMINATED))

/* ---- resource location -------------------------------------------------------------------- */

static int hexval(int c)
{
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

/* file:///a/b, file:/a/b, file://localhost/a/b, with or without a trailing slash and with
 * %XX escapes -> /a/b. Returns 0 on success. */
static int uri_to_path(const char *uri, char *path, size_t len)
{
    if (!uri || strncmp(uri, "file:", 5) != 0) return -1;
    const char *p = uri + 5;
    if (strncmp(p, "//", 2) == 0) {
        p += 2;
        if (strncmp(p, "localhost/", 10) == 0) p += 9;
        else if (*p != '/') return -1; /* a remote host */
    }
    if (*p != '/') return -1;
    size_t j = 0;
    for (; *p; p++) {
        int c = (unsigned char)*p;
        if (c == '%' && hexval(p[1]) >= 0 && hexval(p[2]) >= 0) {
            c = hexval(p[1]) * 16 + hexval(p[2]);
            p += 2;
        }
        if (j + 1 >= len) return -1;
        path[j++] = (char)c;
    }
    while (j > 1 && path[j - 1] == '/') j--;
    path[j] = '\0';
    return 0;
}

/* ---- the simulation ----------------------------------------------------------------------- */

static void settings_default(struct settings *s)
{
    memset(s, 0, sizeof *s);
    for (int k = 0; k < N_REAL_PARAMS; k++) s->real[k] = real_params[k].start;
    for (int k = 0; k < N_BOOL_PARAMS; k++) s->flag[k] = bool_params[k].start;
    s->threads = START_threads;
    snprintf(s->case_file, sizeof s->case_file, "%s", START_case_file);
    s->push_velocity = START_push_velocity;
    s->push_external = START_push_external;
}

/* The overrides the settings give (keys are static strings). Returns their number. */
static size_t settings_overrides(const struct settings *s, mixsph_override *ov, size_t cap)
{
    size_t n = 0;
    for (int k = 0; k < N_REAL_PARAMS; k++) {
        if (!s->real_set[k]) continue;
        for (int j = 0; real_param_keys[k][j] && n < cap; j++) ov[n++] = (mixsph_override){real_param_keys[k][j], s->real[k]};
    }
    for (int k = 0; k < N_BOOL_PARAMS; k++)
        if (s->flag_set[k] && n < cap) ov[n++] = (mixsph_override){bool_params[k].key, s->flag[k] ? 1.0 : 0.0};
    /* Landslide kinematics: the plate's law v(t) becomes speed_scale v(t / time_scale); the
     * duration scales with time_scale, the stroke with speed_scale time_scale. */
    if ((s->real_set[P_PLATE_DURATION_SCALE] || s->real_set[P_PLATE_STROKE_SCALE]) && n + 2 <= cap) {
        const double ts = s->real[P_PLATE_DURATION_SCALE], ss = s->real[P_PLATE_STROKE_SCALE];
        ov[n++] = (mixsph_override){"motions.plate.time_scale", ts};
        ov[n++] = (mixsph_override){"motions.plate.speed_scale", ss / ts};
    }
    return n;
}

/* The moving wall of the case and its direction of travel (the velocity of largest magnitude in
 * its motion table), read from the case text. */
static void find_moving_wall(struct instance *in)
{
    in->wall[0] = '\0';
    in->dir_x = in->dir_z = 0.0;
    cJSON *root = cJSON_Parse(mixsph_sim_case_text(in->sim));
    if (!root) return;
    const cJSON *walls = cJSON_GetObjectItemCaseSensitive(root, "walls");
    const cJSON *motions = cJSON_GetObjectItemCaseSensitive(root, "motions");
    const cJSON *w;
    cJSON_ArrayForEach(w, walls)
    {
        const cJSON *mname = cJSON_GetObjectItemCaseSensitive(w, "motion");
        if (!cJSON_IsString(mname) || !w->string) continue;
        const cJSON *mo = cJSON_GetObjectItemCaseSensitive(motions, mname->valuestring);
        const cJSON *vx = cJSON_GetObjectItemCaseSensitive(mo, "vx"), *vz = cJSON_GetObjectItemCaseSensitive(mo, "vz");
        const int n = cJSON_GetArraySize(vx);
        double best = 0.0;
        for (int k = 0; k < n && k < cJSON_GetArraySize(vz); k++) {
            const cJSON *a = cJSON_GetArrayItem(vx, k), *b = cJSON_GetArrayItem(vz, k);
            if (!cJSON_IsNumber(a) || !cJSON_IsNumber(b)) continue;
            const double v = hypot(a->valuedouble, b->valuedouble);
            if (v > best) {
                best = v;
                in->dir_x = a->valuedouble / v;
                in->dir_z = b->valuedouble / v;
            }
        }
        if (best > 0.0) {
            snprintf(in->wall, sizeof in->wall, "%s", w->string);
            break;
        }
    }
    cJSON_Delete(root);
}

static void lookup_outputs(struct instance *in)
{
    for (int k = 0; k < N_OUTS; k++) in->out[k] = mixsph_sim_output_find(in->sim, out_names[k]);
}

/* Take over a simulation (created or restored): outputs, moving wall, threads. */
static fmi2Status adopt_sim(struct instance *in, mixsph_sim *sim)
{
    mixsph_sim_destroy(in->sim);
    in->sim = sim;
    lookup_outputs(in);
    find_moving_wall(in);
    if (mixsph_sim_set_threads(sim, in->set.threads) != MIXSPH_OK)
        return fail(in, "threads = %d: %s", in->set.threads, mixsph_sim_last_error(sim));
    return fmi2OK;
}

static fmi2Status create_sim(struct instance *in)
{
    char path[FMU_PATH_LEN];
    const char *cf = in->set.case_file;
    if (cf[0] == '\0') return fail(in, "case_file is empty");
    if (cf[0] == '/') {
        snprintf(path, sizeof path, "%s", cf);
    } else {
        if (in->resource_dir[0] == '\0')
            return fail(in, "case_file '%s': the FMU's resource location is unknown (fmuResourceLocation not a file URI)", cf);
        if ((size_t)snprintf(path, sizeof path, "%s/%s", in->resource_dir, cf) >= sizeof path)
            return fail(in, "case_file '%s': path too long", cf);
    }
    mixsph_override ov[32];
    const size_t n = settings_overrides(&in->set, ov, 32);
    char err[FMU_MSG_LEN];
    mixsph_sim *sim = NULL;
    const mixsph_status st = mixsph_sim_create(path, ov, n, &sim, err, sizeof err);
    if (st != MIXSPH_OK) return fail(in, "cannot create the simulation (%s): %s", mixsph_status_string(st), err);
    if (adopt_sim(in, sim) != fmi2OK) return fmi2Error;
    LOG_INFO(in, "%s: %zu particles + %zu wall particles, %zu overrides", path, mixsph_sim_particles(sim),
             mixsph_sim_wall_particles(sim), n);
    return fmi2OK;
}

/* Drive or release the moving wall according to the push inputs. */
static fmi2Status apply_push(struct instance *in)
{
    if (!in->sim) return fmi2OK;
    if (in->set.push_external) {
        if (in->wall[0] == '\0') return fail(in, "push_external: the case has no moving wall to push");
        if (in->push_applied && in->push_applied_v == in->set.push_velocity) return fmi2OK;
        const double v = in->set.push_velocity;
        if (mixsph_sim_set_wall_velocity(in->sim, in->wall, v * in->dir_x, v * in->dir_z) != MIXSPH_OK)
            return fail(in, "push_velocity: %s", mixsph_sim_last_error(in->sim));
        in->push_applied = 1;
        in->push_applied_v = v;
    } else if (in->push_applied) {
        if (mixsph_sim_release_wall_velocity(in->sim, in->wall) != MIXSPH_OK)
            return fail(in, "push_external: %s", mixsph_sim_last_error(in->sim));
        in->push_applied = 0;
    }
    return fmi2OK;
}

/* ---- common functions --------------------------------------------------------------------- */

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[])
{
    struct instance *in = c;
    if (!check(in, "fmi2SetDebugLogging", M_ANY)) return fmi2Error;
    (void)nCategories;
    (void)categories;
    in->logging_on = loggingOn ? 1 : 0;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn)
{
    (void)visible;
    if (!functions) return NULL;
    struct instance *in = calloc(1, sizeof *in);
    if (!in) return NULL;
    in->cb = *functions;
    in->logging_on = loggingOn ? 1 : 0;
    in->name = malloc(strlen(instanceName ? instanceName : "") + 1);
    if (!in->name) {
        free(in);
        return NULL;
    }
    strcpy(in->name, instanceName ? instanceName : "");
    if (fmuType != fmi2CoSimulation) {
        LOG_ERROR(in, "fmi2Instantiate: LandslideWave is a co-simulation FMU only (fmuType %d)", (int)fmuType);
        free(in->name);
        free(in);
        return NULL;
    }
    if (!fmuGUID || strcmp(fmuGUID, MIXSPH_FMU_GUID) != 0) {
        LOG_ERROR(in, "fmi2Instantiate: GUID %s does not match this binary's %s", fmuGUID ? fmuGUID : "(null)",
                  MIXSPH_FMU_GUID);
        free(in->name);
        free(in);
        return NULL;
    }
    if (uri_to_path(fmuResourceLocation, in->resource_dir, sizeof in->resource_dir) != 0) {
        in->resource_dir[0] = '\0';
        log_msg(in, fmi2Warning, "logStatusWarning",
                "fmuResourceLocation '%s' is not a local file URI: only absolute case_file paths will work",
                fmuResourceLocation ? fmuResourceLocation : "(null)");
    }
    settings_default(&in->set);
    in->mode = MODE_INSTANTIATED;
    return in;
}

void fmi2FreeInstance(fmi2Component c)
{
    struct instance *in = c;
    if (!in) return;
    mixsph_sim_destroy(in->sim);
    free(in->name);
    free(in);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance, fmi2Real startTime,
                               fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    struct instance *in = c;
    (void)toleranceDefined;
    (void)tolerance;
    if (!check(in, "fmi2SetupExperiment", M(MODE_INSTANTIATED))) return fmi2Error;
    if (!isfinite(startTime) || startTime != 0.0)
        return reject(in, "fmi2SetupExperiment: startTime %g: the case starts at t = 0", startTime);
    if (stopTimeDefined && !(isfinite(stopTime) && stopTime > startTime))
        return reject(in, "fmi2SetupExperiment: stopTime %g is not after startTime %g", stopTime, startTime);
    in->start_time = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    struct instance *in = c;
    if (!check(in, "fmi2EnterInitializationMode", M(MODE_INSTANTIATED))) return fmi2Error;
    in->mode = MODE_INIT;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    struct instance *in = c;
    if (!check(in, "fmi2ExitInitializationMode", M(MODE_INIT))) return fmi2Error;
    if (!in->sim && create_sim(in) != fmi2OK) return fmi2Error;
    in->time = in->start_time;
    in->mode = MODE_STEP;
    return apply_push(in);
}

fmi2Status fmi2Terminate(fmi2Component c)
{
    struct instance *in = c;
    if (!check(in, "fmi2Terminate", M(MODE_STEP))) return fmi2Error;
    in->mode = MODE_TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c)
{
    struct instance *in = c;
    if (!check(in, "fmi2Reset", M_ANY)) return fmi2Error;
    mixsph_sim_destroy(in->sim);
    in->sim = NULL;
    settings_default(&in->set);
    in->start_time = in->time = 0.0;
    in->push_applied = 0;
    in->mode = MODE_INSTANTIATED;
    return fmi2OK;
}

/* ---- get ---------------------------------------------------------------------------------- */

static double output_value(const struct instance *in, int k)
{
    return in->out[k] >= 0 ? mixsph_sim_output_value(in->sim, (size_t)in->out[k]) : NAN;
}

/* Maximum of output k over the samples, and its time; before the first sample, the current
 * value and time. */
static void output_max(const struct instance *in, int k, double *max, double *t_max)
{
    *max = *t_max = NAN;
    if (in->out[k] < 0) return;
    mixsph_sim_output_extremes(in->sim, (size_t)in->out[k], max, t_max, NULL, NULL);
    if (isnan(*max)) {
        *max = output_value(in, k);
        *t_max = mixsph_sim_time(in->sim);
    }
}

static int real_param_index(fmi2ValueReference vr)
{
    for (int k = 0; k < N_REAL_PARAMS; k++)
        if (real_params[k].vr == vr) return k;
    return -1;
}

/* Outputs need the simulation: in initialization mode it is created on first use. */
static fmi2Status need_sim(struct instance *in)
{
    if (in->sim) return fmi2OK;
    if (in->mode == MODE_INIT) return create_sim(in);
    return reject(in, "outputs are available from initialization mode on");
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[])
{
    struct instance *in = c;
    if (!check(in, "fmi2GetReal", M_ANY)) return fmi2Error;
    if (nvr > 0 && (!vr || !value)) return reject(in, "fmi2GetReal: NULL array");
    for (size_t i = 0; i < nvr; i++) {
        const int p = real_param_index(vr[i]);
        if (p >= 0) {
            value[i] = in->set.real[p];
            continue;
        }
        if (vr[i] == VR_push_velocity) {
            value[i] = in->set.push_velocity;
            continue;
        }
        double t;
        switch (vr[i]) {
        case VR_run_up:
        case VR_max_run_up:
        case VR_time_of_max_run_up:
        case VR_landslide_front:
        case VR_kinetic_energy:
        case VR_water_kinetic_energy:
        case VR_dt:
        case VR_max_run_up_Z:
            if (need_sim(in) != fmi2OK) return fmi2Error;
            break;
        default: return reject(in, "fmi2GetReal: no Real variable with value reference %u", vr[i]);
        }
        switch (vr[i]) {
        case VR_run_up: value[i] = output_value(in, O_RUN_UP); break;
        case VR_max_run_up: output_max(in, O_RUN_UP, &value[i], &t); break;
        case VR_time_of_max_run_up: output_max(in, O_RUN_UP, &t, &value[i]); break;
        case VR_landslide_front: value[i] = output_value(in, O_FRONT); break;
        case VR_kinetic_energy: value[i] = output_value(in, O_KE); break;
        case VR_water_kinetic_energy: value[i] = output_value(in, O_KE_WATER); break;
        case VR_dt: value[i] = output_value(in, O_DT); break;
        case VR_max_run_up_Z: output_max(in, O_RUN_UP_Z, &value[i], &t); break;
        default: break;
        }
    }
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[])
{
    struct instance *in = c;
    if (!check(in, "fmi2GetInteger", M_ANY)) return fmi2Error;
    if (nvr > 0 && (!vr || !value)) return reject(in, "fmi2GetInteger: NULL array");
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] == VR_threads) {
            value[i] = in->set.threads;
            continue;
        }
        if (vr[i] != VR_fixed_particles && vr[i] != VR_lost_particles && vr[i] != VR_steps)
            return reject(in, "fmi2GetInteger: no Integer variable with value reference %u", vr[i]);
        if (need_sim(in) != fmi2OK) return fmi2Error;
        double v = vr[i] == VR_steps               ? (double)mixsph_sim_steps(in->sim)
                   : vr[i] == VR_fixed_particles ? output_value(in, O_FIXED)
                                                 : output_value(in, O_LOST);
        value[i] = isfinite(v) && v < 2147483647.0 ? (fmi2Integer)v : -1;
    }
    return fmi2OK;
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[])
{
    struct instance *in = c;
    if (!check(in, "fmi2GetBoolean", M_ANY)) return fmi2Error;
    if (nvr > 0 && (!vr || !value)) return reject(in, "fmi2GetBoolean: NULL array");
    for (size_t i = 0; i < nvr; i++) {
        const int b = bool_param(vr[i]);
        if (b >= 0) value[i] = in->set.flag[b] ? fmi2True : fmi2False;
        else if (vr[i] == VR_push_external) value[i] = in->set.push_external ? fmi2True : fmi2False;
        else return reject(in, "fmi2GetBoolean: no Boolean variable with value reference %u", vr[i]);
    }
    return fmi2OK;
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[])
{
    struct instance *in = c;
    if (!check(in, "fmi2GetString", M_ANY)) return fmi2Error;
    if (nvr > 0 && (!vr || !value)) return reject(in, "fmi2GetString: NULL array");
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] != VR_case_file) return reject(in, "fmi2GetString: no String variable with value reference %u", vr[i]);
        value[i] = in->set.case_file;
    }
    return fmi2OK;
}

/* ---- set ---------------------------------------------------------------------------------- */

/* Parameters may be set before the simulation exists (instantiated, initialization mode); a
 * parameter set in initialization mode after outputs were read re-creates it. */
static fmi2Status param_settable(struct instance *in, const char *name)
{
    if (in->mode != MODE_INSTANTIATED && in->mode != MODE_INIT)
        return reject(in, "%s is a fixed parameter: it can only be set before fmi2ExitInitializationMode", name);
    mixsph_sim_destroy(in->sim);
    in->sim = NULL;
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[])
{
    struct instance *in = c;
    if (!check(in, "fmi2SetReal", M_ALIVE)) return fmi2Error;
    if (nvr > 0 && (!vr || !value)) return reject(in, "fmi2SetReal: NULL array");
    for (size_t i = 0; i < nvr; i++) {
        const double v = value[i];
        const int p = real_param_index(vr[i]);
        if (p >= 0) {
            const struct real_param *rp = &real_params[p];
            if (param_settable(in, rp->name) != fmi2OK) return fmi2Error;
            if (!isfinite(v) || v < rp->min || v > rp->max)
                return reject(in, "%s = %g is out of range [%g, %g]", rp->name, v, rp->min, rp->max);
            in->set.real[p] = v;
            in->set.real_set[p] = 1;
            continue;
        }
        if (vr[i] == VR_push_velocity) {
            if (!isfinite(v) || v < MIN_push_velocity || v > MAX_push_velocity)
                return reject(in, "push_velocity = %g m/s is out of range [%g, %g]", v, (double)MIN_push_velocity,
                              (double)MAX_push_velocity);
            in->set.push_velocity = v;
            if (in->mode == MODE_STEP && apply_push(in) != fmi2OK) return fmi2Error;
            continue;
        }
        return reject(in, "fmi2SetReal: no settable Real variable with value reference %u", vr[i]);
    }
    return fmi2OK;
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[])
{
    struct instance *in = c;
    if (!check(in, "fmi2SetInteger", M_ALIVE)) return fmi2Error;
    if (nvr > 0 && (!vr || !value)) return reject(in, "fmi2SetInteger: NULL array");
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] != VR_threads) return reject(in, "fmi2SetInteger: no settable Integer variable with value reference %u", vr[i]);
        if (param_settable(in, "threads") != fmi2OK) return fmi2Error;
        if (value[i] < MIN_threads || value[i] > MAX_threads)
            return reject(in, "threads = %d is out of range [%d, %d]", (int)value[i], MIN_threads, MAX_threads);
        in->set.threads = value[i];
    }
    return fmi2OK;
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[])
{
    struct instance *in = c;
    if (!check(in, "fmi2SetBoolean", M_ALIVE)) return fmi2Error;
    if (nvr > 0 && (!vr || !value)) return reject(in, "fmi2SetBoolean: NULL array");
    for (size_t i = 0; i < nvr; i++) {
        const int b = bool_param(vr[i]);
        if (b >= 0) {
            if (param_settable(in, bool_params[b].name) != fmi2OK) return fmi2Error;
            in->set.flag[b] = value[i] ? 1 : 0;
            in->set.flag_set[b] = 1;
        } else if (vr[i] == VR_push_external) {
            in->set.push_external = value[i] ? 1 : 0;
            if (in->mode == MODE_STEP && apply_push(in) != fmi2OK) return fmi2Error;
        } else {
            return reject(in, "fmi2SetBoolean: no settable Boolean variable with value reference %u", vr[i]);
        }
    }
    return fmi2OK;
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[])
{
    struct instance *in = c;
    if (!check(in, "fmi2SetString", M_ALIVE)) return fmi2Error;
    if (nvr > 0 && (!vr || !value)) return reject(in, "fmi2SetString: NULL array");
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] != VR_case_file) return reject(in, "fmi2SetString: no settable String variable with value reference %u", vr[i]);
        if (param_settable(in, "case_file") != fmi2OK) return fmi2Error;
        if (!value[i] || strlen(value[i]) >= sizeof in->set.case_file)
            return reject(in, "case_file: NULL or longer than %zu characters", sizeof in->set.case_file - 1);
        snprintf(in->set.case_file, sizeof in->set.case_file, "%s", value[i]);
    }
    return fmi2OK;
}

/* ---- co-simulation ------------------------------------------------------------------------ */

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    struct instance *in = c;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (!check(in, "fmi2DoStep", M(MODE_STEP))) return fmi2Error;
    if (!isfinite(currentCommunicationPoint) || !isfinite(communicationStepSize) || communicationStepSize < 0.0)
        return reject(in, "fmi2DoStep: communication point %g and step %g must be finite, the step >= 0",
                      currentCommunicationPoint, communicationStepSize);
    const double t_end = currentCommunicationPoint + communicationStepSize;
    const mixsph_status st = mixsph_sim_advance_to(in->sim, t_end);
    if (st != MIXSPH_OK)
        return fail(in, "fmi2DoStep to t = %g s: %s: %s", t_end, mixsph_status_string(st), mixsph_sim_last_error(in->sim));
    in->time = t_end;
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component c)
{
    struct instance *in = c;
    if (!check(in, "fmi2CancelStep", M_ANY)) return fmi2Error;
    return reject(in, "fmi2CancelStep: doStep is synchronous, nothing to cancel");
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    struct instance *in = c;
    if (!check(in, "fmi2GetStatus", M_ANY)) return fmi2Error;
    if (s == fmi2DoStepStatus && value) {
        *value = in->mode == MODE_ERROR ? fmi2Error : fmi2OK;
        return fmi2OK;
    }
    return reject(in, "fmi2GetStatus: status kind %d not provided", (int)s);
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    struct instance *in = c;
    if (!check(in, "fmi2GetRealStatus", M_ANY)) return fmi2Error;
    if (s == fmi2LastSuccessfulTime && value) {
        *value = in->time;
        return fmi2OK;
    }
    return reject(in, "fmi2GetRealStatus: status kind %d not provided", (int)s);
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    struct instance *in = c;
    (void)value;
    if (!check(in, "fmi2GetIntegerStatus", M_ANY)) return fmi2Error;
    return reject(in, "fmi2GetIntegerStatus: status kind %d not provided", (int)s);
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    struct instance *in = c;
    if (!check(in, "fmi2GetBooleanStatus", M_ANY)) return fmi2Error;
    if (s == fmi2Terminated && value) {
        *value = fmi2False;
        return fmi2OK;
    }
    return reject(in, "fmi2GetBooleanStatus: status kind %d not provided", (int)s);
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value)
{
    struct instance *in = c;
    if (!check(in, "fmi2GetStringStatus", M_ANY)) return fmi2Error;
    if (s == fmi2PendingStatus && value) {
        *value = "";
        return fmi2OK;
    }
    return reject(in, "fmi2GetStringStatus: status kind %d not provided", (int)s);
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[])
{
    struct instance *in = c;
    (void)vr, (void)nvr, (void)order, (void)value;
    if (!check(in, "fmi2SetRealInputDerivatives", M_ANY)) return fmi2Error;
    return reject(in, "fmi2SetRealInputDerivatives: not supported (canInterpolateInputs = false)");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[])
{
    struct instance *in = c;
    (void)vr, (void)nvr, (void)order, (void)value;
    if (!check(in, "fmi2GetRealOutputDerivatives", M_ANY)) return fmi2Error;
    return reject(in, "fmi2GetRealOutputDerivatives: not supported (maxOutputDerivativeOrder = 0)");
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown, const fmi2Real dvKnown[],
                                        fmi2Real dvUnknown[])
{
    struct instance *in = c;
    (void)vUnknown_ref, (void)nUnknown, (void)vKnown_ref, (void)nKnown, (void)dvKnown, (void)dvUnknown;
    if (!check(in, "fmi2GetDirectionalDerivative", M_ANY)) return fmi2Error;
    return reject(in, "fmi2GetDirectionalDerivative: not supported (providesDirectionalDerivative = false)");
}

/* ---- model exchange: not provided (exported because hosts resolve every function) --------- */

static fmi2Status no_model_exchange(fmi2Component c, const char *fn)
{
    struct instance *in = c;
    if (in) LOG_ERROR(in, "%s: LandslideWave is a co-simulation FMU (no model exchange)", fn);
    return fmi2Error;
}

fmi2Status fmi2EnterEventMode(fmi2Component c)
{
    return no_model_exchange(c, "fmi2EnterEventMode");
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c)
{
    return no_model_exchange(c, "fmi2EnterContinuousTimeMode");
}

fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *eventInfo)
{
    (void)eventInfo;
    return no_model_exchange(c, "fmi2NewDiscreteStates");
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSetFMUStatePriorToCurrentPoint, fmi2Boolean *enterEventMode, fmi2Boolean *terminateSimulation)
{
    (void)noSetFMUStatePriorToCurrentPoint;
    (void)enterEventMode;
    (void)terminateSimulation;
    return no_model_exchange(c, "fmi2CompletedIntegratorStep");
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time)
{
    (void)time;
    return no_model_exchange(c, "fmi2SetTime");
}

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx)
{
    (void)x;
    (void)nx;
    return no_model_exchange(c, "fmi2SetContinuousStates");
}

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real derivatives[], size_t nx)
{
    (void)derivatives;
    (void)nx;
    return no_model_exchange(c, "fmi2GetDerivatives");
}

fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real eventIndicators[], size_t ni)
{
    (void)eventIndicators;
    (void)ni;
    return no_model_exchange(c, "fmi2GetEventIndicators");
}

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx)
{
    (void)x;
    (void)nx;
    return no_model_exchange(c, "fmi2GetContinuousStates");
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x_nominal[], size_t nx)
{
    (void)x_nominal;
    (void)nx;
    return no_model_exchange(c, "fmi2GetNominalsOfContinuousStates");
}

/* ---- FMU state ---------------------------------------------------------------------------- */

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    struct instance *in = c;
    if (!check(in, "fmi2GetFMUstate", M(MODE_STEP) | M(MODE_TERMINATED))) return fmi2Error;
    if (!FMUstate) return reject(in, "fmi2GetFMUstate: NULL state pointer");
    struct fmu_state *fs = *FMUstate; /* a state given back is overwritten */
    if (!fs && !(fs = calloc(1, sizeof *fs))) return reject(in, "fmi2GetFMUstate: out of memory");
    void *buf = NULL;
    size_t len = 0;
    const mixsph_status st = mixsph_sim_save_state(in->sim, &buf, &len);
    if (st != MIXSPH_OK) {
        if (!*FMUstate) free(fs);
        return reject(in, "fmi2GetFMUstate: %s", mixsph_sim_last_error(in->sim));
    }
    free_lib(fs);
    fs->lib = buf;
    fs->lib_len = len;
    fs->set = in->set;
    fs->start_time = in->start_time;
    fs->time = in->time;
    fs->push_applied = in->push_applied;
    fs->push_applied_v = in->push_applied_v;
    *FMUstate = fs;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate)
{
    struct instance *in = c;
    if (!check(in, "fmi2SetFMUstate", M_ANY)) return fmi2Error;
    const struct fmu_state *fs = FMUstate;
    if (!fs || !fs->lib) return reject(in, "fmi2SetFMUstate: NULL state");
    /* Same case and overrides: load in place; else (another instance's parameters, or no
     * simulation yet) build the simulation from the state. */
    mixsph_status st = MIXSPH_ERR_ARG;
    if (in->sim) st = mixsph_sim_load_state(in->sim, fs->lib, fs->lib_len);
    if (st != MIXSPH_OK) {
        char err[FMU_MSG_LEN];
        mixsph_sim *sim = NULL;
        st = mixsph_sim_create_from_state(fs->lib, fs->lib_len, &sim, err, sizeof err);
        /* a state that cannot be loaded leaves the instance as it was */
        if (st != MIXSPH_OK) return reject(in, "fmi2SetFMUstate: %s", err);
        in->set = fs->set;
        if (adopt_sim(in, sim) != fmi2OK) return fmi2Error;
    } else {
        in->set = fs->set;
        if (mixsph_sim_set_threads(in->sim, in->set.threads) != MIXSPH_OK)
            return fail(in, "fmi2SetFMUstate: threads: %s", mixsph_sim_last_error(in->sim));
    }
    in->start_time = fs->start_time;
    in->time = fs->time;
    in->push_applied = fs->push_applied; /* the library state holds the wall's drive */
    in->push_applied_v = fs->push_applied_v;
    in->mode = MODE_STEP;
    LOG_INFO(in, "state restored at t = %g s (communication time %g s)", mixsph_sim_time(in->sim), in->time);
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    (void)c;
    if (!FMUstate || !*FMUstate) return fmi2OK;
    struct fmu_state *fs = *FMUstate;
    free_lib(fs);
    free(fs);
    *FMUstate = NULL;
    return fmi2OK;
}

/* Serialised: magic, size of struct settings, the instance part, the library state length and
 * bytes. Same build on the same machine type (the library state says so too). */
static size_t ser_size(const struct fmu_state *fs)
{
    return 8 + sizeof(uint64_t) + sizeof fs->set + 2 * sizeof(double) + sizeof(int) + sizeof(double) +
           sizeof(uint64_t) + fs->lib_len;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size)
{
    struct instance *in = c;
    if (!check(in, "fmi2SerializedFMUstateSize", M_ANY)) return fmi2Error;
    if (!FMUstate || !size) return reject(in, "fmi2SerializedFMUstateSize: NULL argument");
    *size = ser_size(FMUstate);
    return fmi2OK;
}

#define SER_PUT(p, x) (memcpy((p), &(x), sizeof(x)), (p) += sizeof(x))
#define SER_GET(p, x) (memcpy(&(x), (p), sizeof(x)), (p) += sizeof(x))

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serializedState[], size_t size)
{
    struct instance *in = c;
    if (!check(in, "fmi2SerializeFMUstate", M_ANY)) return fmi2Error;
    const struct fmu_state *fs = FMUstate;
    if (!fs || !serializedState) return reject(in, "fmi2SerializeFMUstate: NULL argument");
    if (size < ser_size(fs)) return reject(in, "fmi2SerializeFMUstate: buffer of %zu bytes, %zu needed", size, ser_size(fs));
    unsigned char *p = (unsigned char *)serializedState;
    memcpy(p, SER_MAGIC, 8);
    p += 8;
    const uint64_t set_size = sizeof fs->set, lib_len = fs->lib_len;
    SER_PUT(p, set_size);
    SER_PUT(p, fs->set);
    SER_PUT(p, fs->start_time);
    SER_PUT(p, fs->time);
    SER_PUT(p, fs->push_applied);
    SER_PUT(p, fs->push_applied_v);
    SER_PUT(p, lib_len);
    memcpy(p, fs->lib, fs->lib_len);
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size, fmi2FMUstate *FMUstate)
{
    struct instance *in = c;
    if (!check(in, "fmi2DeSerializeFMUstate", M_ANY)) return fmi2Error;
    if (!serializedState || !FMUstate) return reject(in, "fmi2DeSerializeFMUstate: NULL argument");
    struct fmu_state tmp;
    memset(&tmp, 0, sizeof tmp);
    const unsigned char *p = (const unsigned char *)serializedState;
    uint64_t set_size = 0, lib_len = 0;
    if (size < ser_size(&tmp) || memcmp(p, SER_MAGIC, 8) != 0)
        return reject(in, "fmi2DeSerializeFMUstate: not a LandslideWave state (%zu bytes)", size);
    p += 8;
    SER_GET(p, set_size);
    if (set_size != sizeof tmp.set) return reject(in, "fmi2DeSerializeFMUstate: state of another build of the FMU");
    SER_GET(p, tmp.set);
    SER_GET(p, tmp.start_time);
    SER_GET(p, tmp.time);
    SER_GET(p, tmp.push_applied);
    SER_GET(p, tmp.push_applied_v);
    SER_GET(p, lib_len);
    tmp.set.case_file[sizeof tmp.set.case_file - 1] = '\0';
    if (lib_len != size - ser_size(&tmp)) return reject(in, "fmi2DeSerializeFMUstate: truncated or padded state");
    struct fmu_state *fs = *FMUstate; /* a state given back is re-used */
    const int reuse = fs != NULL;
    if (!fs) fs = calloc(1, sizeof *fs);
    void *lib = malloc(lib_len ? lib_len : 1);
    if (!fs || !lib) {
        if (!reuse) free(fs);
        free(lib);
        return reject(in, "fmi2DeSerializeFMUstate: out of memory");
    }
    if (reuse) free_lib(fs);
    *fs = tmp;
    memcpy(lib, p, lib_len);
    fs->lib = lib;
    fs->lib_len = lib_len;
    fs->lib_copy = 1;
    *FMUstate = fs;
    return fmi2OK;
}
