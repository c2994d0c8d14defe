/* fmi2_glue.c - generic FMI 2.0 co-simulation glue around a mixsph simulation: the instance, its
 * life cycle, the logger, the calling-state checks, the simulation's creation and stepping, the
 * FMU state and every fmi2 function. It knows no model: the variables, the case file and its
 * overrides come from the binding (fmi2_glue.h, the seam; landslide_model.c).
 *
 * One struct fmu_instance owns everything of an instance (no mutable file-scope state), so
 * several instances live in one process independently. Life cycle:
 *   fmi2Instantiate          -> INSTANTIATED (parameters may be set)
 *   fmi2EnterInitialization  -> INIT         (parameters and inputs may be set)
 *   fmi2ExitInitialization   -> STEP         (the simulation is created from the binding's case
 *                                             file and overrides; the inputs are applied)
 *   fmi2DoStep               advances the simulation to the end of the communication step
 *                            (mixsph takes its own explicit steps and never shortens one, so on
 *                            return its time is in [t_end, t_end + dt))
 *   an error                 -> ERROR (fmi2Error; only Get*, FreeInstance, Reset, SetFMUstate)
 *
 * FMU state: fmi2GetFMUstate saves the library state (mixsph_sim_save_state) together with the
 * binding's data (its parameters and inputs); fmi2SetFMUstate restores it (mixsph_sim_load_state
 * when the instance runs the same case and overrides, else a new simulation from the state).
 * Serialised: a header, the binding's data, the times, the library's own (checksummed) bytes.
 *
 * Errors return fmi2Error with a message through the FMI logger, always logged whatever the
 * debug-logging setting. The library never exits, so neither does the FMU. */
#include "fmi2_glue.h"

#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#if defined(_WIN32)
#include <windows.h>
#endif

/* ---- logging ------------------------------------------------------------------------------ */

static void log_message(struct fmu_instance *in, fmi2Status st, const char *category, const char *fmt, va_list ap)
{
    if (!in || !in->cb.logger) return;
    if (st < fmi2Error && !in->logging_on) return;
    char raw[FMU_MSG_LEN];
    vsnprintf(raw, sizeof raw, fmt, ap);
    /* The logger takes a printf format: escape '%'. */
    char *m = in->msg;
    size_t j = 0;
    for (size_t i = 0; raw[i] && j + 2 < sizeof in->msg; i++) {
        if (raw[i] == '%') m[j++] = '%';
        m[j++] = raw[i];
    }
    m[j] = '\0';
    in->cb.logger(in->cb.componentEnvironment, in->name ? in->name : "?", st, category, m);
}

static void log_error(struct fmu_instance *in, const char *fmt, ...) FMU_PRINTF(2, 3);
static void log_error(struct fmu_instance *in, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    log_message(in, fmi2Error, "logStatusError", fmt, ap);
    va_end(ap);
}

static void log_warning(struct fmu_instance *in, const char *fmt, ...) FMU_PRINTF(2, 3);
static void log_warning(struct fmu_instance *in, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    log_message(in, fmi2Warning, "logStatusWarning", fmt, ap);
    va_end(ap);
}

void fmu_log_info(struct fmu_instance *in, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    log_message(in, fmi2OK, "logInfo", fmt, ap);
    va_end(ap);
}

static void log_fatal(struct fmu_instance *in, const char *fmt, ...) FMU_PRINTF(2, 3);
static void log_fatal(struct fmu_instance *in, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    log_message(in, fmi2Fatal, "logStatusFatal", fmt, ap);
    va_end(ap);
}

/* Log a fatal error and make the instance unusable (FMU_MODE_FATAL); returns fmi2Fatal. */
static fmi2Status fmu_fatal(struct fmu_instance *in, const char *fmt, ...) FMU_PRINTF(2, 3);
static fmi2Status fmu_fatal(struct fmu_instance *in, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    in->mode = FMU_MODE_FATAL;
    log_message(in, fmi2Fatal, "logStatusFatal", fmt, ap);
    va_end(ap);
    return fmi2Fatal;
}

fmi2Status fmu_fail(struct fmu_instance *in, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    in->mode = FMU_MODE_ERROR;
    log_message(in, fmi2Error, "logStatusError", fmt, ap);
    va_end(ap);
    return fmi2Error;
}

fmi2Status fmu_reject(struct fmu_instance *in, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    log_message(in, fmi2Error, "logStatusError", fmt, ap);
    va_end(ap);
    return fmi2Error;
}

/* ---- calling states ----------------------------------------------------------------------- */

#define M(x) (1 << (x))
#define M_ANY (M(FMU_MODE_INSTANTIATED) | M(FMU_MODE_INIT) | M(FMU_MODE_STEP) | M(FMU_MODE_TERMINATED) | M(FMU_MODE_ERROR))
#define M_ALIVE (M(FMU_MODE_INSTANTIATED) | M(FMU_MODE_INIT) | M(FMU_MODE_STEP) | M(FMU_MODE_TERMINATED))

/* fmi2OK if the instance pointer is there and fn may be called in its state; else what fn
 * returns: fmi2Fatal for an instance made unusable by an earlier fmi2Fatal, fmi2Error otherwise. */
static fmi2Status check(struct fmu_instance *in, const char *fn, int allowed_modes)
{
    if (!in) return fmi2Error;
    if (in->mode == FMU_MODE_FATAL) {
        log_fatal(in, "%s: the instance is unusable since an earlier fmi2Fatal; only fmi2FreeInstance may be called", fn);
        return fmi2Fatal;
    }
    if (!(allowed_modes & M(in->mode))) {
        static const char *const names[] = {"instantiated", "initialization mode", "step mode", "terminated",
                                            "error"};
        log_error(in, "%s: not allowed in %s", fn, names[in->mode]);
        return fmi2Error;
    }
    return fmi2OK;
}

/* Return from the calling fmi2 function unless check() allows the call. */
#define CHECK(in, fn, allowed_modes)                                        \
    do {                                                                    \
        const fmi2Status check_status_ = check((in), (fn), (allowed_modes)); \
        if (check_status_ != fmi2OK) return check_status_;                  \
    } while (0)

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
#if defined(_WIN32)
    /* file:///C:/a/b names C:/a/b */
    if (isalpha((unsigned char)path[1]) && path[2] == ':') memmove(path, path + 1, j);
#endif
    return 0;
}

/* An absolute path of the platform: /a/b; on Windows also C:\a, C:/a and \\server\share. */
static int is_absolute(const char *path)
{
#if defined(_WIN32)
    if (isalpha((unsigned char)path[0]) && path[1] == ':' && (path[2] == '\\' || path[2] == '/')) return 1;
    if (path[0] == '\\') return 1;
#endif
    return path[0] == '/';
}

/* ---- the simulation ----------------------------------------------------------------------- */

/* The case file's path: absolute, or in the FMU's resources/ folder. */
static fmi2Status case_path(struct fmu_instance *in, const char *case_file, char *path, size_t len)
{
    if (!case_file || case_file[0] == '\0') return fmu_fail(in, "case_file is empty");
    if (is_absolute(case_file)) {
        if ((size_t)snprintf(path, len, "%s", case_file) >= len) return fmu_fail(in, "case_file '%s': path too long", case_file);
        return fmi2OK;
    }
    if (in->resource_dir[0] == '\0')
        return fmu_fail(in, "case_file '%s': the FMU's resource location is unknown (fmuResourceLocation not a file URI)",
                        case_file);
    if ((size_t)snprintf(path, len, "%s/%s", in->resource_dir, case_file) >= len)
        return fmu_fail(in, "case_file '%s': path too long", case_file);
    return fmi2OK;
}

/* Every override of "parameters.NAME" names a parameter the case declares: the library would
 * add an undeclared one as a key that nothing uses, and the host's value would silently do
 * nothing. */
static fmi2Status check_declared_parameters(struct fmu_instance *in, const char *path, const struct fmu_sim_request *req)
{
    static const char prefix[] = "parameters.";
    for (size_t k = 0; k < req->n_ov; k++) {
        const char *key = req->ov[k].ov.key;
        if (strncmp(key, prefix, sizeof prefix - 1) != 0) continue;
        const char *param = key + sizeof prefix - 1;
        char err[FMU_MSG_LEN];
        int declared = 0;
        if (mixsph_case_declares_parameter(path, param, &declared, err, sizeof err) != MIXSPH_OK)
            return fmu_fail(in, "cannot read the case file: %s", err);
        if (declared) continue;
        char names[1024];
        size_t n = 0;
        if (mixsph_case_parameter_names(path, names, sizeof names, &n, err, sizeof err) != MIXSPH_OK) names[0] = '\0';
        return fmu_fail(in,
                        "%s was set, but the case file %s does not declare it: its parameters block has no \"%s\" "
                        "(the override %s), so the value would not reach the case. The case declares %s%s. Leave "
                        "%s unset, or declare it in the case's parameters block and use it there as \"$%s\"",
                        req->ov[k].variable, path, param, key, n ? "only: " : "no parameters", n ? names : "", param,
                        param);
    }
    return fmi2OK;
}

static fmi2Status create_simulation(struct fmu_instance *in)
{
    struct fmu_sim_request req;
    memset(&req, 0, sizeof req);
    fmu_model.request(in, &req);
    char path[FMU_PATH_LEN];
    if (case_path(in, req.case_file, path, sizeof path) != fmi2OK) return fmi2Error;
    if (check_declared_parameters(in, path, &req) != fmi2OK) return fmi2Error;
    mixsph_override ov[FMU_MAX_OVERRIDES];
    for (size_t k = 0; k < req.n_ov; k++) ov[k] = req.ov[k].ov;
    char err[FMU_MSG_LEN];
    mixsph_sim *sim = NULL;
    const mixsph_status st = mixsph_sim_create(path, ov, req.n_ov, &sim, err, sizeof err);
    if (st != MIXSPH_OK) return fmu_fail(in, "cannot create the simulation (%s): %s", mixsph_status_string(st), err);
    mixsph_sim_destroy(in->sim);
    in->sim = sim;
    if (fmu_model.attach(in) != fmi2OK) return fmi2Error;
    fmu_log_info(in, "%s: %zu particles + %zu wall particles, %zu overrides", path, mixsph_sim_particles(sim),
                 mixsph_sim_wall_particles(sim), req.n_ov);
    return fmi2OK;
}

fmi2Status fmu_need_simulation(struct fmu_instance *in)
{
    if (in->sim) return fmi2OK;
    if (in->mode == FMU_MODE_INIT) return create_simulation(in);
    return fmu_reject(in, "outputs are available from initialization mode on");
}

fmi2Status fmu_parameter_settable(struct fmu_instance *in, const char *name)
{
    if (in->mode != FMU_MODE_INSTANTIATED && in->mode != FMU_MODE_INIT)
        return fmu_reject(in, "%s is a fixed parameter: it can only be set before fmi2ExitInitializationMode", name);
    mixsph_sim_destroy(in->sim);
    in->sim = NULL;
    return fmi2OK;
}

/* ---- common functions --------------------------------------------------------------------- */

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[])
{
    struct fmu_instance *in = c;
    CHECK(in, "fmi2SetDebugLogging", M_ANY);
    (void)nCategories;
    (void)categories;
    in->logging_on = loggingOn ? 1 : 0;
    return fmi2OK;
}

/* The binary stays loaded until the process ends, whatever the host unloads: OpenMP's idle
 * worker threads outlive a multi-threaded run, waiting inside the OpenMP runtime for the next
 * parallel region, and unloading the code under them crashes the host (docs/fmu.md,
 * "Unloading"). On Linux the linker marks the .so so (-z nodelete, fmu/CMakeLists.txt); the
 * win64 DLL, which has GNU OpenMP linked in, pins itself here, before its first thread starts. */
static void keep_loaded(void)
{
#if defined(_WIN32)
    static const char inside_this_dll = 0; /* any address in the DLL names it */
    HMODULE self;
    GetModuleHandleExW(GET_MODULE_HANDLE_EX_FLAG_FROM_ADDRESS | GET_MODULE_HANDLE_EX_FLAG_PIN,
                       (LPCWSTR)(const void *)&inside_this_dll, &self);
#endif
}

static void free_instance(struct fmu_instance *in)
{
    mixsph_sim_destroy(in->sim);
    free(in->data);
    free(in->name);
    free(in);
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn)
{
    (void)visible;
    keep_loaded();
    if (!functions) return NULL;
    struct fmu_instance *in = calloc(1, sizeof *in);
    if (!in) return NULL;
    in->cb = *functions;
    in->logging_on = loggingOn ? 1 : 0;
    in->name = malloc(strlen(instanceName ? instanceName : "") + 1);
    in->data = calloc(1, fmu_model.data_size);
    if (!in->name || !in->data) {
        free_instance(in);
        return NULL;
    }
    strcpy(in->name, instanceName ? instanceName : "");
    if (fmuType != fmi2CoSimulation) {
        log_error(in, "fmi2Instantiate: %s is a co-simulation FMU only (fmuType %d)", fmu_model.model_name, (int)fmuType);
        free_instance(in);
        return NULL;
    }
    if (!fmuGUID || strcmp(fmuGUID, fmu_model.guid) != 0) {
        log_error(in, "fmi2Instantiate: GUID %s does not match this binary's %s", fmuGUID ? fmuGUID : "(null)",
                  fmu_model.guid);
        free_instance(in);
        return NULL;
    }
    if (uri_to_path(fmuResourceLocation, in->resource_dir, sizeof in->resource_dir) != 0) {
        in->resource_dir[0] = '\0';
        log_warning(in, "fmuResourceLocation '%s' is not a local file URI: only absolute case_file paths will work",
                    fmuResourceLocation ? fmuResourceLocation : "(null)");
    }
    fmu_model.set_defaults(in->data);
    in->mode = FMU_MODE_INSTANTIATED;
    return in;
}

void fmi2FreeInstance(fmi2Component c)
{
    if (c) free_instance(c);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance, fmi2Real startTime,
                               fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    struct fmu_instance *in = c;
    (void)toleranceDefined;
    (void)tolerance;
    CHECK(in, "fmi2SetupExperiment", M(FMU_MODE_INSTANTIATED));
    if (!isfinite(startTime) || startTime != 0.0)
        return fmu_reject(in, "fmi2SetupExperiment: startTime %g: the case starts at t = 0", startTime);
    if (stopTimeDefined && !(isfinite(stopTime) && stopTime > startTime))
        return fmu_reject(in, "fmi2SetupExperiment: stopTime %g is not after startTime %g", stopTime, startTime);
    in->start_time = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    struct fmu_instance *in = c;
    CHECK(in, "fmi2EnterInitializationMode", M(FMU_MODE_INSTANTIATED));
    in->mode = FMU_MODE_INIT;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    struct fmu_instance *in = c;
    CHECK(in, "fmi2ExitInitializationMode", M(FMU_MODE_INIT));
    if (!in->sim && create_simulation(in) != fmi2OK) return fmi2Error;
    in->time = in->start_time;
    in->mode = FMU_MODE_STEP;
    return fmu_model.apply_inputs(in);
}

fmi2Status fmi2Terminate(fmi2Component c)
{
    struct fmu_instance *in = c;
    CHECK(in, "fmi2Terminate", M(FMU_MODE_STEP));
    in->mode = FMU_MODE_TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c)
{
    struct fmu_instance *in = c;
    CHECK(in, "fmi2Reset", M_ANY);
    mixsph_sim_destroy(in->sim);
    in->sim = NULL;
    memset(in->data, 0, fmu_model.data_size);
    fmu_model.set_defaults(in->data);
    in->start_time = in->time = 0.0;
    in->mode = FMU_MODE_INSTANTIATED;
    return fmi2OK;
}

/* ---- get and set: arrays here, one variable at a time in the binding ---------------------- */

/* The loop of every fmi2Get / fmi2Set: the state and the arrays checked, then the binding's
 * accessor for each value reference; the first refusal ends the call. */
#define FMU_ACCESS(fn, allowed, accessor, value_expr)                                        \
    do {                                                                                     \
        struct fmu_instance *in = c;                                                         \
        CHECK(in, fn, allowed);                                                              \
        if (nvr > 0 && (!vr || !value)) return fmu_reject(in, "%s: NULL array", fn);         \
        for (size_t i = 0; i < nvr; i++)                                                     \
            if (fmu_model.accessor(in, vr[i], value_expr) != fmi2OK) return fmi2Error;       \
        return fmi2OK;                                                                       \
    } while (0)

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[])
{
    FMU_ACCESS("fmi2GetReal", M_ANY, get_real, &value[i]);
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[])
{
    FMU_ACCESS("fmi2GetInteger", M_ANY, get_integer, &value[i]);
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[])
{
    FMU_ACCESS("fmi2GetBoolean", M_ANY, get_boolean, &value[i]);
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[])
{
    FMU_ACCESS("fmi2GetString", M_ANY, get_string, &value[i]);
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[])
{
    FMU_ACCESS("fmi2SetReal", M_ALIVE, set_real, value[i]);
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[])
{
    FMU_ACCESS("fmi2SetInteger", M_ALIVE, set_integer, value[i]);
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[])
{
    FMU_ACCESS("fmi2SetBoolean", M_ALIVE, set_boolean, value[i]);
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[])
{
    FMU_ACCESS("fmi2SetString", M_ALIVE, set_string, value[i]);
}

/* ---- co-simulation ------------------------------------------------------------------------ */

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    struct fmu_instance *in = c;
    (void)noSetFMUStatePriorToCurrentPoint;
    CHECK(in, "fmi2DoStep", M(FMU_MODE_STEP));
    if (!isfinite(currentCommunicationPoint) || !isfinite(communicationStepSize) || communicationStepSize < 0.0)
        return fmu_reject(in, "fmi2DoStep: communication point %g and step %g must be finite, the step >= 0",
                          currentCommunicationPoint, communicationStepSize);
    const double t_end = currentCommunicationPoint + communicationStepSize;
    const mixsph_status st = mixsph_sim_advance_to(in->sim, t_end);
    /* Out of memory part-way through a step: the simulation's arrays may be resized and not yet
     * filled, and neither a restored state nor a reset can be relied on to find memory in a
     * process that has none; every other failure (an unstable run, ...) leaves a simulation that
     * fmi2SetFMUstate or fmi2Reset can replace. */
    if (st == MIXSPH_ERR_NOMEM)
        return fmu_fatal(in, "fmi2DoStep to t = %g s: %s: %s; the instance is unusable (free it)", t_end,
                         mixsph_status_string(st), mixsph_sim_last_error(in->sim));
    if (st != MIXSPH_OK)
        return fmu_fail(in, "fmi2DoStep to t = %g s: %s: %s", t_end, mixsph_status_string(st), mixsph_sim_last_error(in->sim));
    in->time = t_end;
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component c)
{
    struct fmu_instance *in = c;
    CHECK(in, "fmi2CancelStep", M_ANY);
    return fmu_reject(in, "fmi2CancelStep: doStep is synchronous, nothing to cancel");
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    struct fmu_instance *in = c;
    CHECK(in, "fmi2GetStatus", M_ANY);
    if (s == fmi2DoStepStatus && value) {
        *value = in->mode == FMU_MODE_ERROR ? fmi2Error : fmi2OK;
        return fmi2OK;
    }
    return fmu_reject(in, "fmi2GetStatus: status kind %d not provided", (int)s);
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    struct fmu_instance *in = c;
    CHECK(in, "fmi2GetRealStatus", M_ANY);
    if (s == fmi2LastSuccessfulTime && value) {
        *value = in->time;
        return fmi2OK;
    }
    return fmu_reject(in, "fmi2GetRealStatus: status kind %d not provided", (int)s);
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    struct fmu_instance *in = c;
    (void)value;
    CHECK(in, "fmi2GetIntegerStatus", M_ANY);
    return fmu_reject(in, "fmi2GetIntegerStatus: status kind %d not provided", (int)s);
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    struct fmu_instance *in = c;
    CHECK(in, "fmi2GetBooleanStatus", M_ANY);
    if (s == fmi2Terminated && value) {
        *value = fmi2False;
        return fmi2OK;
    }
    return fmu_reject(in, "fmi2GetBooleanStatus: status kind %d not provided", (int)s);
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value)
{
    struct fmu_instance *in = c;
    CHECK(in, "fmi2GetStringStatus", M_ANY);
    if (s == fmi2PendingStatus && value) {
        *value = "";
        return fmi2OK;
    }
    return fmu_reject(in, "fmi2GetStringStatus: status kind %d not provided", (int)s);
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[])
{
    struct fmu_instance *in = c;
    (void)vr, (void)nvr, (void)order, (void)value;
    CHECK(in, "fmi2SetRealInputDerivatives", M_ANY);
    return fmu_reject(in, "fmi2SetRealInputDerivatives: not supported (canInterpolateInputs = false)");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[])
{
    struct fmu_instance *in = c;
    (void)vr, (void)nvr, (void)order, (void)value;
    CHECK(in, "fmi2GetRealOutputDerivatives", M_ANY);
    return fmu_reject(in, "fmi2GetRealOutputDerivatives: not supported (maxOutputDerivativeOrder = 0)");
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown, const fmi2Real dvKnown[],
                                        fmi2Real dvUnknown[])
{
    struct fmu_instance *in = c;
    (void)vUnknown_ref, (void)nUnknown, (void)vKnown_ref, (void)nKnown, (void)dvKnown, (void)dvUnknown;
    CHECK(in, "fmi2GetDirectionalDerivative", M_ANY);
    return fmu_reject(in, "fmi2GetDirectionalDerivative: not supported (providesDirectionalDerivative = false)");
}

/* ---- model exchange: not provided (exported because hosts resolve every function) --------- */

static fmi2Status no_model_exchange(fmi2Component c, const char *fn)
{
    struct fmu_instance *in = c;
    if (in) log_error(in, "%s: %s is a co-simulation FMU (no model exchange)", fn, fmu_model.model_name);
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

/* A saved FMU state (fmi2FMUstate). */
struct fmu_state {
    void *data; /* a copy of the binding's data (fmu_model.data_size bytes) */
    double start_time, time;
    void *lib;  /* library state (mixsph_sim_save_state, or a copy made by fmi2DeSerializeFMUstate) */
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

static void free_state(struct fmu_state *fs)
{
    if (!fs) return;
    free_lib(fs);
    free(fs->data);
    free(fs);
}

/* A new, empty state with room for the binding's data, or NULL. */
static struct fmu_state *new_state(void)
{
    struct fmu_state *fs = calloc(1, sizeof *fs);
    if (fs && !(fs->data = calloc(1, fmu_model.data_size))) {
        free(fs);
        fs = NULL;
    }
    return fs;
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    struct fmu_instance *in = c;
    CHECK(in, "fmi2GetFMUstate", M(FMU_MODE_STEP) | M(FMU_MODE_TERMINATED));
    if (!FMUstate) return fmu_reject(in, "fmi2GetFMUstate: NULL state pointer");
    struct fmu_state *fs = *FMUstate; /* a state given back is overwritten */
    if (!fs && !(fs = new_state())) return fmu_reject(in, "fmi2GetFMUstate: out of memory");
    void *buf = NULL;
    size_t len = 0;
    const mixsph_status st = mixsph_sim_save_state(in->sim, &buf, &len);
    if (st != MIXSPH_OK) {
        if (!*FMUstate) free_state(fs);
        return fmu_reject(in, "fmi2GetFMUstate: %s", mixsph_sim_last_error(in->sim));
    }
    free_lib(fs);
    fs->lib = buf;
    fs->lib_len = len;
    memcpy(fs->data, in->data, fmu_model.data_size);
    fs->start_time = in->start_time;
    fs->time = in->time;
    *FMUstate = fs;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate)
{
    struct fmu_instance *in = c;
    CHECK(in, "fmi2SetFMUstate", M_ANY);
    const struct fmu_state *fs = FMUstate;
    if (!fs || !fs->lib) return fmu_reject(in, "fmi2SetFMUstate: NULL state");
    /* Same case and overrides: load in place; else (another instance's parameters, or no
     * simulation yet) build the simulation from the state. */
    mixsph_status st = MIXSPH_ERR_ARG;
    if (in->sim) st = mixsph_sim_load_state(in->sim, fs->lib, fs->lib_len);
    if (st != MIXSPH_OK) {
        char err[FMU_MSG_LEN];
        mixsph_sim *sim = NULL;
        st = mixsph_sim_create_from_state(fs->lib, fs->lib_len, &sim, err, sizeof err);
        /* a state that cannot be loaded leaves the instance as it was */
        if (st != MIXSPH_OK) return fmu_reject(in, "fmi2SetFMUstate: %s", err);
        mixsph_sim_destroy(in->sim);
        in->sim = sim;
    }
    /* the binding's data as saved: its inputs as applied then, which the library state holds */
    memcpy(in->data, fs->data, fmu_model.data_size);
    if (fmu_model.attach(in) != fmi2OK) return fmi2Error;
    in->start_time = fs->start_time;
    in->time = fs->time;
    in->mode = FMU_MODE_STEP;
    fmu_log_info(in, "state restored at t = %g s (communication time %g s)", mixsph_sim_time(in->sim), in->time);
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    (void)c;
    if (!FMUstate || !*FMUstate) return fmi2OK;
    free_state(*FMUstate);
    *FMUstate = NULL;
    return fmi2OK;
}

/* Serialised: magic, the size of the binding's data and the data, the start and communication
 * times, the library state's length and bytes. Same build on the same machine type (the
 * library state says so too). */
#define SER_MAGIC "MXFMUST2"

static size_t ser_size(size_t lib_len)
{
    return 8 + sizeof(uint64_t) + fmu_model.data_size + 2 * sizeof(double) + sizeof(uint64_t) + lib_len;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size)
{
    struct fmu_instance *in = c;
    CHECK(in, "fmi2SerializedFMUstateSize", M_ANY);
    if (!FMUstate || !size) return fmu_reject(in, "fmi2SerializedFMUstateSize: NULL argument");
    *size = ser_size(((const struct fmu_state *)FMUstate)->lib_len);
    return fmi2OK;
}

#define SER_PUT(p, x) (memcpy((p), &(x), sizeof(x)), (p) += sizeof(x))
#define SER_GET(p, x) (memcpy(&(x), (p), sizeof(x)), (p) += sizeof(x))

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serializedState[], size_t size)
{
    struct fmu_instance *in = c;
    CHECK(in, "fmi2SerializeFMUstate", M_ANY);
    const struct fmu_state *fs = FMUstate;
    if (!fs || !serializedState) return fmu_reject(in, "fmi2SerializeFMUstate: NULL argument");
    if (size < ser_size(fs->lib_len))
        return fmu_reject(in, "fmi2SerializeFMUstate: buffer of %zu bytes, %zu needed", size, ser_size(fs->lib_len));
    unsigned char *p = (unsigned char *)serializedState;
    memcpy(p, SER_MAGIC, 8);
    p += 8;
    const uint64_t data_size = fmu_model.data_size, lib_len = fs->lib_len;
    SER_PUT(p, data_size);
    memcpy(p, fs->data, fmu_model.data_size);
    p += fmu_model.data_size;
    SER_PUT(p, fs->start_time);
    SER_PUT(p, fs->time);
    SER_PUT(p, lib_len);
    memcpy(p, fs->lib, fs->lib_len);
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size, fmi2FMUstate *FMUstate)
{
    struct fmu_instance *in = c;
    CHECK(in, "fmi2DeSerializeFMUstate", M_ANY);
    if (!serializedState || !FMUstate) return fmu_reject(in, "fmi2DeSerializeFMUstate: NULL argument");
    const unsigned char *p = (const unsigned char *)serializedState;
    if (size < ser_size(0) || memcmp(p, SER_MAGIC, 8) != 0)
        return fmu_reject(in, "fmi2DeSerializeFMUstate: not a %s state (%zu bytes)", fmu_model.model_name, size);
    p += 8;
    uint64_t data_size = 0, lib_len = 0;
    SER_GET(p, data_size);
    if (data_size != fmu_model.data_size)
        return fmu_reject(in, "fmi2DeSerializeFMUstate: state of another build of the FMU");
    const unsigned char *data = p;
    p += fmu_model.data_size;
    double start_time, time;
    SER_GET(p, start_time);
    SER_GET(p, time);
    SER_GET(p, lib_len);
    if (lib_len != size - ser_size(0)) return fmu_reject(in, "fmi2DeSerializeFMUstate: truncated or padded state");
    struct fmu_state *fs = *FMUstate; /* a state given back is re-used */
    const int reuse = fs != NULL;
    if (!fs) fs = new_state();
    void *lib = malloc(lib_len ? lib_len : 1);
    if (!fs || !lib) {
        if (!reuse) free_state(fs);
        free(lib);
        return fmu_reject(in, "fmi2DeSerializeFMUstate: out of memory");
    }
    free_lib(fs);
    memcpy(fs->data, data, fmu_model.data_size);
    fs->start_time = start_time;
    fs->time = time;
    memcpy(lib, p, lib_len);
    fs->lib = lib;
    fs->lib_len = lib_len;
    fs->lib_copy = 1;
    *FMUstate = fs;
    return fmi2OK;
}
