/* fmi2_glue.h - the seam between the generic FMI 2.0 co-simulation glue (fmi2_glue.c) and a
 * model binding (landslide_model.c), in the manner of modelica/Reference-FMUs: the glue owns the
 * instance, its life cycle, the logger, the calling-state checks, the mixsph simulation and the
 * FMU state; the binding says which variables exist and how they reach the library.
 *
 * The glue knows the library (it creates, steps, saves and restores a mixsph_sim) but no model:
 * no variable names, no case keys. The binding knows no FMI life cycle: it answers get/set of
 * one variable at a time, says what a simulation is created from, and looks up what it reads
 * once a simulation exists.
 *
 * The binding's per-instance data is one block of plain bytes (no pointers) of
 * fmu_binding.data_size: the glue allocates it, saves it with an FMU state and restores it with
 * the simulation, so a restored instance has the parameters and inputs of the saved one. */
#ifndef FMI2_GLUE_H
#define FMI2_GLUE_H
#include <stddef.h>

#include "fmi2Functions.h"
#include "mixsph.h"

#define FMU_PATH_LEN 4096
#define FMU_MSG_LEN 2048
#define FMU_MAX_OVERRIDES 32

#if defined(__MINGW32__)
/* the win64 binary's printf family is mingw's C99 one (__USE_MINGW_ANSI_STDIO) */
#define FMU_PRINTF(a, b) __attribute__((format(gnu_printf, a, b)))
#elif defined(__GNUC__)
#define FMU_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define FMU_PRINTF(a, b)
#endif

/* The FMI 2.0 co-simulation calling states. ERROR: a call failed, the instance can be restored
 * (fmi2SetFMUstate), reset or freed (fmi2Error); FATAL: it is unusable and may only be freed
 * (fmi2Fatal: out of memory part-way through a step, docs/fmu.md "Errors"). */
enum fmu_mode { FMU_MODE_INSTANTIATED, FMU_MODE_INIT, FMU_MODE_STEP, FMU_MODE_TERMINATED, FMU_MODE_ERROR, FMU_MODE_FATAL };

struct fmu_instance {
    char *name;
    fmi2CallbackFunctions cb;
    int logging_on;
    char resource_dir[FMU_PATH_LEN]; /* the unpacked FMU's resources/ folder; "" if not a local file URI */
    enum fmu_mode mode;
    double start_time;
    double time;     /* communication time [s] */
    mixsph_sim *sim; /* NULL until created (exit of initialization, or an output read in it) */
    void *data;      /* the binding's data (fmu_binding.data_size bytes) */
    char msg[FMU_MSG_LEN];
};

/* An override the binding asks for, with the FMU variable that asked (named in messages). */
struct fmu_override {
    const char *variable;
    mixsph_override ov; /* key: a static string */
};

/* What a simulation is created from. An override of "parameters.NAME" is checked against the
 * names the case declares in its parameters block: an undeclared one is an error naming the
 * variable, not a silently unused key. */
struct fmu_sim_request {
    const char *case_file; /* a name in the FMU's resources/ folder or an absolute path */
    struct fmu_override ov[FMU_MAX_OVERRIDES];
    size_t n_ov;
};

struct fmu_binding {
    const char *model_name; /* the modelIdentifier, for messages */
    const char *guid;       /* of modelDescription.xml: fmi2Instantiate refuses another */
    size_t data_size;
    void (*set_defaults)(void *data); /* the start values of modelDescription.xml */
    /* One variable by value reference: fmi2OK, or fmu_reject (an unknown or wrongly typed
     * reference, a value out of range) / fmu_fail. A setter of a parameter calls
     * fmu_parameter_settable first; a getter of an output calls fmu_need_simulation. */
    fmi2Status (*get_real)(struct fmu_instance *in, fmi2ValueReference vr, fmi2Real *value);
    fmi2Status (*get_integer)(struct fmu_instance *in, fmi2ValueReference vr, fmi2Integer *value);
    fmi2Status (*get_boolean)(struct fmu_instance *in, fmi2ValueReference vr, fmi2Boolean *value);
    fmi2Status (*get_string)(struct fmu_instance *in, fmi2ValueReference vr, fmi2String *value);
    fmi2Status (*set_real)(struct fmu_instance *in, fmi2ValueReference vr, fmi2Real value);
    fmi2Status (*set_integer)(struct fmu_instance *in, fmi2ValueReference vr, fmi2Integer value);
    fmi2Status (*set_boolean)(struct fmu_instance *in, fmi2ValueReference vr, fmi2Boolean value);
    fmi2Status (*set_string)(struct fmu_instance *in, fmi2ValueReference vr, fmi2String value);
    /* The case file and overrides of the parameters the host has set (those it has not set keep
     * the case's values, so no override is asked for them). */
    void (*request)(const struct fmu_instance *in, struct fmu_sim_request *req);
    /* A simulation was created or restored (in->sim): look up what the binding reads from it
     * and apply its settings (threads). */
    fmi2Status (*attach)(struct fmu_instance *in);
    /* Entering step mode: apply the inputs to the simulation. */
    fmi2Status (*apply_inputs)(struct fmu_instance *in);
};

/* The binding the FMU is built with (landslide_model.c). */
extern const struct fmu_binding fmu_model;

/* ---- glue services for the binding ---------------------------------------------------------- */

/* Log an error and enter the error state; returns fmi2Error. */
fmi2Status fmu_fail(struct fmu_instance *in, const char *fmt, ...) FMU_PRINTF(2, 3);
/* Log an error that leaves the instance usable (a refused value or call); returns fmi2Error. */
fmi2Status fmu_reject(struct fmu_instance *in, const char *fmt, ...) FMU_PRINTF(2, 3);
/* Log information (only with debug logging on). */
void fmu_log_info(struct fmu_instance *in, const char *fmt, ...) FMU_PRINTF(2, 3);
/* A fixed parameter may be set before fmi2ExitInitializationMode only; setting one drops a
 * simulation made for an output read in initialization mode (it is made again). */
fmi2Status fmu_parameter_settable(struct fmu_instance *in, const char *name);
/* Outputs need the simulation: in initialization mode it is created on first use. */
fmi2Status fmu_need_simulation(struct fmu_instance *in);

#endif
