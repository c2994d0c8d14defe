/* test_fmu_dlopen.c - the LandslideWave FMU's shared library driven through dlopen, without
 * Python, as a C co-simulation master would: every FMI 2.0 function resolves; the resource
 * location in its URI spellings; doStep of any size gives the same trajectory; FMU state
 * save/restore and serialisation; two interleaved instances; errors reported through the logger;
 * a second landslide case through case_file.
 *
 *   test_fmu_dlopen STAGE_DIR     (the unpacked FMU: modelDescription.xml, binaries/, resources/)
 *
 * Small runs: the Vajont case at dx = 0.03 m, mu0 = 1 kPa s, to t <= 0.2 s. */
#define _XOPEN_SOURCE 700 /* realpath */
#include <dlfcn.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "fmi2Functions.h"

static const char *stage;
static void *lib;
static char guid[128];

/* value references (checked against modelDescription.xml by name below) */
enum {
    VR_PHI = 2,
    VR_MU0 = 3,
    VR_DX = 6,
    VR_CASE_FILE = 12,
    VR_PUSH_VELOCITY = 20,
    VR_PUSH_EXTERNAL = 21,
    VR_RUN_UP = 30,
    VR_MAX_RUN_UP = 31,
    VR_FRONT = 33,
    VR_KE = 34,
    VR_STEPS = 39,
    VR_RHEOLOGY = 50,
};

static const char *const all_functions[] = {
    "fmi2GetTypesPlatform", "fmi2GetVersion", "fmi2SetDebugLogging", "fmi2Instantiate", "fmi2FreeInstance",
    "fmi2SetupExperiment", "fmi2EnterInitializationMode", "fmi2ExitInitializationMode", "fmi2Terminate", "fmi2Reset",
    "fmi2GetReal", "fmi2GetInteger", "fmi2GetBoolean", "fmi2GetString", "fmi2SetReal", "fmi2SetInteger",
    "fmi2SetBoolean", "fmi2SetString", "fmi2GetFMUstate", "fmi2SetFMUstate", "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize", "fmi2SerializeFMUstate", "fmi2DeSerializeFMUstate", "fmi2GetDirectionalDerivative",
    "fmi2EnterEventMode", "fmi2NewDiscreteStates", "fmi2EnterContinuousTimeMode", "fmi2CompletedIntegratorStep",
    "fmi2SetTime", "fmi2SetContinuousStates", "fmi2GetDerivatives", "fmi2GetEventIndicators",
    "fmi2GetContinuousStates", "fmi2GetNominalsOfContinuousStates", "fmi2SetRealInputDerivatives",
    "fmi2GetRealOutputDerivatives", "fmi2DoStep", "fmi2CancelStep", "fmi2GetStatus", "fmi2GetRealStatus",
    "fmi2GetIntegerStatus", "fmi2GetBooleanStatus", "fmi2GetStringStatus", NULL};

/* dlsym's object pointer as a function pointer (ISO C has no direct conversion) */
typedef void (*any_fn)(void);
static any_fn sym(const char *name)
{
    void *p = dlsym(lib, name);
    any_fn f;
    memcpy(&f, &p, sizeof f);
    return f;
}
#define SYM(name) ((name##TYPE *)sym(#name))

/* ---- logger: counts messages per status ---------------------------------------------------- */

struct log_counts {
    int n[5];
    char last[1024];
};

static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    (void)instance;
    (void)category;
    struct log_counts *lc = env;
    if (!lc || status < 0 || status > 4) return;
    lc->n[status]++;
    va_list ap;
    va_start(ap, message);
    vsnprintf(lc->last, sizeof lc->last, message, ap);
    va_end(ap);
}

static fmi2CallbackFunctions callbacks(struct log_counts *lc)
{
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, lc};
    return cb;
}

/* ---- helpers ------------------------------------------------------------------------------ */

static fmi2Component instantiate(const char *name, const char *uri, struct log_counts *lc)
{
    static fmi2CallbackFunctions cbs[16];
    static int k;
    fmi2CallbackFunctions *cb = &cbs[k++ % 16];
    *cb = callbacks(lc);
    return SYM(fmi2Instantiate)(name, fmi2CoSimulation, guid, uri, cb, fmi2False, fmi2False);
}

static void resource_uri(char *buf, size_t n, const char *prefix, const char *suffix)
{
    snprintf(buf, n, "%s%s/resources%s", prefix, stage, suffix);
}

/* Set up, set the coarse parameters (and phi), initialise. */
static void start(fmi2Component c, double phi, const struct log_counts *lc)
{
    const fmi2ValueReference vr[] = {VR_DX, VR_MU0, VR_PHI};
    const fmi2Real v[] = {0.03, 1000.0, phi};
    assert_int_equal(SYM(fmi2SetupExperiment)(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK);
    assert_int_equal(SYM(fmi2EnterInitializationMode)(c), fmi2OK);
    assert_int_equal(SYM(fmi2SetReal)(c, vr, 3, v), fmi2OK);
    if (SYM(fmi2ExitInitializationMode)(c) != fmi2OK) {
        fail_msg("fmi2ExitInitializationMode: %s", lc->last);
    }
}

struct out {
    double r[4];
    int steps;
};

static struct out outputs(fmi2Component c)
{
    const fmi2ValueReference vr[] = {VR_RUN_UP, VR_MAX_RUN_UP, VR_FRONT, VR_KE}, vs = VR_STEPS;
    struct out o;
    assert_int_equal(SYM(fmi2GetReal)(c, vr, 4, o.r), fmi2OK);
    assert_int_equal(SYM(fmi2GetInteger)(c, &vs, 1, &o.steps), fmi2OK);
    return o;
}

static void assert_same(struct out a, struct out b)
{
    assert_int_equal(a.steps, b.steps);
    for (int k = 0; k < 4; k++) assert_memory_equal(&a.r[k], &b.r[k], sizeof(double));
}

static void step_to(fmi2Component c, double t0, double t1, double h)
{
    for (double t = t0; t < t1 - 1e-12; t += h) assert_int_equal(SYM(fmi2DoStep)(c, t, h, fmi2True), fmi2OK);
}

/* ---- tests -------------------------------------------------------------------------------- */

/* The granular law through fmi2SetInteger (rheology is an Enumeration): a value that is no item's
 * is an fmi2Error with a message naming the parameter, the instance stays usable; elastic_plastic
 * runs another trajectory than the default paper law, and its state (the grains' stresses
 * included) restores to the same continuation. */
static void test_rheology(void **state)
{
    (void)state;
    char uri[4200];
    resource_uri(uri, sizeof uri, "file://", "");
    struct log_counts lc = {0};
    const fmi2ValueReference vr = VR_RHEOLOGY;
    fmi2Component paper = instantiate("paper", uri, &lc);
    assert_non_null(paper);
    start(paper, 35.0, &lc);
    step_to(paper, 0.0, 0.1, 0.02);
    const struct out ref = outputs(paper);
    SYM(fmi2FreeInstance)(paper);

    fmi2Component c = instantiate("ep", uri, &lc);
    assert_non_null(c);
    const fmi2Integer bad = 2, ep = 1;
    assert_int_equal(SYM(fmi2SetInteger)(c, &vr, 1, &bad), fmi2Error);
    assert_int_equal(lc.n[fmi2Error], 1);
    assert_non_null(strstr(lc.last, "rheology = 2 is not one of its items"));
    fmi2Integer got = -1;
    assert_int_equal(SYM(fmi2GetInteger)(c, &vr, 1, &got), fmi2OK);
    assert_int_equal(got, 0); /* unchanged: the paper law */
    assert_int_equal(SYM(fmi2SetInteger)(c, &vr, 1, &ep), fmi2OK);
    start(c, 35.0, &lc);
    step_to(c, 0.0, 0.06, 0.02);
    fmi2FMUstate s = NULL;
    assert_int_equal(SYM(fmi2GetFMUstate)(c, &s), fmi2OK);
    step_to(c, 0.06, 0.1, 0.02);
    const struct out first = outputs(c);
    assert_true(first.steps != ref.steps); /* the elastic law's P-wave time step */
    assert_true(first.r[2] != ref.r[2]);   /* another landslide front */
    assert_int_equal(SYM(fmi2SetFMUstate)(c, s), fmi2OK);
    step_to(c, 0.06, 0.1, 0.02);
    assert_same(first, outputs(c));
    assert_int_equal(SYM(fmi2GetInteger)(c, &vr, 1, &got), fmi2OK);
    assert_int_equal(got, 1);
    assert_int_equal(SYM(fmi2FreeFMUstate)(c, &s), fmi2OK);
    assert_int_equal(lc.n[fmi2Error], 1);
    SYM(fmi2FreeInstance)(c);
}

static void test_every_fmi2_function_resolves(void **state)
{
    (void)state;
    for (int k = 0; all_functions[k]; k++) {
        if (!dlsym(lib, all_functions[k])) fail_msg("%s is not exported", all_functions[k]);
    }
    assert_string_equal(SYM(fmi2GetVersion)(), "2.0");
    assert_string_equal(SYM(fmi2GetTypesPlatform)(), "default");
    /* only FMI functions are exported (the library inside stays hidden) */
    assert_null(dlsym(lib, "mixsph_sim_create"));
}

static void test_value_references_match_the_model_description(void **state)
{
    (void)state;
    char path[4096];
    snprintf(path, sizeof path, "%s/modelDescription.xml", stage);
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    static char xml[1 << 16];
    const size_t n = fread(xml, 1, sizeof xml - 1, f);
    fclose(f);
    xml[n] = '\0';
    const struct {
        const char *name;
        int vr;
    } vars[] = {{"phi", VR_PHI}, {"mu0", VR_MU0}, {"dx", VR_DX}, {"case_file", VR_CASE_FILE},
                {"push_velocity", VR_PUSH_VELOCITY}, {"push_external", VR_PUSH_EXTERNAL}, {"run_up", VR_RUN_UP},
                {"max_run_up", VR_MAX_RUN_UP}, {"landslide_front", VR_FRONT}, {"kinetic_energy", VR_KE},
                {"steps", VR_STEPS}, {"rheology", VR_RHEOLOGY}};
    for (size_t k = 0; k < sizeof vars / sizeof vars[0]; k++) {
        char want[128];
        snprintf(want, sizeof want, "name=\"%s\" valueReference=\"%d\"", vars[k].name, vars[k].vr);
        if (!strstr(xml, want)) fail_msg("modelDescription.xml has no %s", want);
    }
}

static void test_wrong_guid_and_wrong_kind_are_refused(void **state)
{
    (void)state;
    struct log_counts lc = {0};
    fmi2CallbackFunctions cb = callbacks(&lc);
    char uri[4200];
    resource_uri(uri, sizeof uri, "file://", "");
    assert_null(SYM(fmi2Instantiate)("x", fmi2CoSimulation, "{not-the-guid}", uri, &cb, fmi2False, fmi2False));
    assert_null(SYM(fmi2Instantiate)("x", fmi2ModelExchange, guid, uri, &cb, fmi2False, fmi2False));
    assert_int_equal(lc.n[fmi2Error], 2);
}

static void test_resource_uri_spellings_and_step_sizes(void **state)
{
    (void)state;
    const char *forms[][2] = {{"file://", ""}, {"file://", "/"}, {"file:", ""}, {"file:", "/"}, {"file://localhost", "/"}};
    const double steps[] = {0.05, 0.01, 0.013, 0.05, 0.05};
    struct out ref = {0};
    for (int k = 0; k < 5; k++) {
        char uri[4200];
        resource_uri(uri, sizeof uri, forms[k][0], forms[k][1]);
        struct log_counts lc = {0};
        fmi2Component c = instantiate("uri", uri, &lc);
        if (!c) fail_msg("fmi2Instantiate failed for %s", uri);
        start(c, 35.0, &lc);
        double t = 0.0;
        while (t < 0.05 - 1e-12) { /* communication steps of any size, the last one cut at 0.05 */
            const double h = fmin(steps[k], 0.05 - t);
            assert_int_equal(SYM(fmi2DoStep)(c, t, h, fmi2True), fmi2OK);
            t += h;
        }
        const struct out o = outputs(c);
        assert_true(o.steps > 100);
        if (k == 0) ref = o;
        else assert_same(ref, o);
        assert_int_equal(lc.n[fmi2Error], 0);
        assert_int_equal(SYM(fmi2Terminate)(c), fmi2OK);
        SYM(fmi2FreeInstance)(c);
    }
}

static void test_state_restore_and_serialize(void **state)
{
    (void)state;
    char uri[4200];
    resource_uri(uri, sizeof uri, "file://", "");
    struct log_counts lc = {0};
    fmi2Component a = instantiate("a", uri, &lc);
    assert_non_null(a);
    start(a, 30.0, &lc);
    step_to(a, 0.0, 0.1, 0.02);
    fmi2FMUstate s = NULL;
    assert_int_equal(SYM(fmi2GetFMUstate)(a, &s), fmi2OK);
    step_to(a, 0.1, 0.2, 0.02);
    const struct out first = outputs(a);
    assert_int_equal(SYM(fmi2SetFMUstate)(a, s), fmi2OK);
    step_to(a, 0.1, 0.2, 0.02);
    assert_same(first, outputs(a));

    size_t size = 0;
    assert_int_equal(SYM(fmi2SerializedFMUstateSize)(a, s, &size), fmi2OK);
    fmi2Byte *buf = malloc(size);
    assert_non_null(buf);
    assert_int_equal(SYM(fmi2SerializeFMUstate)(a, s, buf, size), fmi2OK);
    assert_int_equal(SYM(fmi2FreeFMUstate)(a, &s), fmi2OK);
    assert_null(s);

    /* into a fresh instance that was only instantiated */
    fmi2Component b = instantiate("b", uri, &lc);
    assert_non_null(b);
    fmi2FMUstate t = NULL;
    assert_int_equal(SYM(fmi2DeSerializeFMUstate)(b, buf, size, &t), fmi2OK);
    assert_int_equal(SYM(fmi2SetFMUstate)(b, t), fmi2OK);
    const fmi2ValueReference vphi = VR_PHI;
    double phi = 0.0;
    assert_int_equal(SYM(fmi2GetReal)(b, &vphi, 1, &phi), fmi2OK);
    assert_true(phi == 30.0);
    step_to(b, 0.1, 0.2, 0.05);
    assert_same(first, outputs(b));
    /* a truncated buffer is refused */
    assert_int_equal(SYM(fmi2DeSerializeFMUstate)(b, buf, size / 2, &t), fmi2Error);
    assert_int_equal(SYM(fmi2FreeFMUstate)(b, &t), fmi2OK);
    assert_int_equal(lc.n[fmi2Error], 1);
    free(buf);
    SYM(fmi2FreeInstance)(a);
    SYM(fmi2FreeInstance)(b);
}

static void test_interleaved_instances_match_solo_runs(void **state)
{
    (void)state;
    char uri[4200];
    resource_uri(uri, sizeof uri, "file:", "/");
    struct log_counts lc = {0};
    fmi2Component a = instantiate("a", uri, &lc), b = instantiate("b", uri, &lc);
    start(a, 35.0, &lc);
    start(b, 25.0, &lc);
    for (double t = 0.0; t < 0.15 - 1e-12; t += 0.03) {
        assert_int_equal(SYM(fmi2DoStep)(a, t, 0.03, fmi2True), fmi2OK);
        assert_int_equal(SYM(fmi2DoStep)(b, t, 0.03, fmi2True), fmi2OK);
    }
    const struct out oa = outputs(a), ob = outputs(b);
    SYM(fmi2FreeInstance)(a);
    SYM(fmi2FreeInstance)(b);
    for (int k = 0; k < 2; k++) {
        fmi2Component c = instantiate("solo", uri, &lc);
        start(c, k == 0 ? 35.0 : 25.0, &lc);
        step_to(c, 0.0, 0.15, 0.15);
        assert_same(k == 0 ? oa : ob, outputs(c));
        SYM(fmi2FreeInstance)(c);
    }
    assert_int_equal(lc.n[fmi2Error], 0);
}

static void test_errors_are_logged_not_fatal(void **state)
{
    (void)state;
    char uri[4200];
    resource_uri(uri, sizeof uri, "file://", "");
    struct log_counts lc = {0};
    fmi2Component c = instantiate("err", uri, &lc);
    const fmi2ValueReference vphi = VR_PHI, vdx = VR_DX;
    const double bad_phi = 95.0, nan_dx = NAN;
    assert_int_equal(SYM(fmi2SetReal)(c, &vphi, 1, &bad_phi), fmi2Error);
    assert_int_equal(lc.n[fmi2Error], 1);
    assert_non_null(strstr(lc.last, "phi"));
    assert_int_equal(SYM(fmi2SetReal)(c, &vdx, 1, &nan_dx), fmi2Error);
    assert_int_equal(lc.n[fmi2Error], 2);
    /* unknown value reference; doStep before initialisation */
    const fmi2ValueReference none = 9999;
    double v;
    assert_int_equal(SYM(fmi2GetReal)(c, &none, 1, &v), fmi2Error);
    assert_int_equal(SYM(fmi2DoStep)(c, 0.0, 0.1, fmi2True), fmi2Error);
    assert_int_equal(lc.n[fmi2Error], 4);
    /* a missing case file */
    const fmi2ValueReference vcase = 12;
    const fmi2String missing = "missing_case.json";
    assert_int_equal(SYM(fmi2SetupExperiment)(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK);
    assert_int_equal(SYM(fmi2EnterInitializationMode)(c), fmi2OK);
    assert_int_equal(SYM(fmi2SetString)(c, &vcase, 1, &missing), fmi2OK);
    assert_int_equal(SYM(fmi2ExitInitializationMode)(c), fmi2Error);
    assert_int_equal(lc.n[fmi2Error], 5);
    assert_non_null(strstr(lc.last, "missing_case.json"));
    /* reset gives a usable instance again */
    assert_int_equal(SYM(fmi2Reset)(c), fmi2OK);
    start(c, 35.0, &lc);
    assert_int_equal(SYM(fmi2DoStep)(c, 0.0, 0.01, fmi2True), fmi2OK);
    SYM(fmi2FreeInstance)(c);
    SYM(fmi2FreeInstance)(NULL);
}

/* Another landslide case by its resource name (cases/slope_tank.json: its walls and media are not
 * the Vajont ones): a parameter it declares is taken, one it does not is an error naming it, and
 * its moving wall (the "ram") is found and pushed. */
static void test_second_case_through_case_file(void **state)
{
    (void)state;
    char uri[4200];
    resource_uri(uri, sizeof uri, "file://", "");
    struct log_counts lc = {0};
    fmi2Component c = instantiate("slope", uri, &lc);
    assert_non_null(c);
    const fmi2ValueReference vcase = VR_CASE_FILE, vphi_mu0[] = {VR_PHI, VR_MU0};
    const fmi2String slope = "slope_tank.json";
    const fmi2Real phi_mu0[] = {30.0, 100.0};
    assert_int_equal(SYM(fmi2SetupExperiment)(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK);
    assert_int_equal(SYM(fmi2EnterInitializationMode)(c), fmi2OK);
    assert_int_equal(SYM(fmi2SetString)(c, &vcase, 1, &slope), fmi2OK);
    assert_int_equal(SYM(fmi2SetReal)(c, vphi_mu0, 2, phi_mu0), fmi2OK);
    assert_int_equal(SYM(fmi2ExitInitializationMode)(c), fmi2Error);
    assert_int_equal(lc.n[fmi2Error], 1);
    if (strncmp(lc.last, "mu0 was set", 11) != 0 || !strstr(lc.last, "parameters.mu0")) fail_msg("message: %s", lc.last);

    /* the declared one alone runs, and the ram takes the push */
    assert_int_equal(SYM(fmi2Reset)(c), fmi2OK);
    assert_int_equal(SYM(fmi2SetupExperiment)(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK);
    assert_int_equal(SYM(fmi2EnterInitializationMode)(c), fmi2OK);
    assert_int_equal(SYM(fmi2SetString)(c, &vcase, 1, &slope), fmi2OK);
    assert_int_equal(SYM(fmi2SetReal)(c, vphi_mu0, 1, phi_mu0), fmi2OK);
    if (SYM(fmi2ExitInitializationMode)(c) != fmi2OK) fail_msg("fmi2ExitInitializationMode: %s", lc.last);
    const fmi2ValueReference vpush = VR_PUSH_EXTERNAL, vv = VR_PUSH_VELOCITY;
    const fmi2Boolean on = fmi2True;
    const fmi2Real fast = 1.5;
    assert_int_equal(SYM(fmi2SetBoolean)(c, &vpush, 1, &on), fmi2OK);
    assert_int_equal(SYM(fmi2SetReal)(c, &vv, 1, &fast), fmi2OK);
    step_to(c, 0.0, 0.1, 0.05);
    assert_true(outputs(c).steps > 100);
    assert_int_equal(lc.n[fmi2Error], 1);
    SYM(fmi2FreeInstance)(c);
}

/* The GUID of the staged modelDescription.xml. */
static int read_guid(void)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/modelDescription.xml", stage);
    FILE *f = fopen(path, "r");
    if (!f) return -1;
    char line[4096];
    int ok = -1;
    while (ok && fgets(line, sizeof line, f)) {
        const char *p = strstr(line, "guid=\"");
        if (!p) continue;
        p += 6;
        const char *q = strchr(p, '"');
        if (q && (size_t)(q - p) < sizeof guid) {
            memcpy(guid, p, (size_t)(q - p));
            guid[q - p] = '\0';
            ok = 0;
        }
    }
    fclose(f);
    return ok;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: %s STAGE_DIR\n", argv[0]);
        return 2;
    }
    static char stage_abs[4096];
    if (!realpath(argv[1], stage_abs)) {
        fprintf(stderr, "%s: not found\n", argv[1]);
        return 1;
    }
    stage = stage_abs; /* the resource URIs need an absolute path */
    char so[4200];
    snprintf(so, sizeof so, "%s/binaries/linux64/LandslideWave.so", stage);
    lib = dlopen(so, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "dlopen %s: %s\n", so, dlerror());
        return 1;
    }
    if (read_guid() != 0) {
        fprintf(stderr, "no guid in %s/modelDescription.xml\n", stage);
        return 1;
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_fmi2_function_resolves),
        cmocka_unit_test(test_value_references_match_the_model_description),
        cmocka_unit_test(test_wrong_guid_and_wrong_kind_are_refused),
        cmocka_unit_test(test_resource_uri_spellings_and_step_sizes),
        cmocka_unit_test(test_state_restore_and_serialize),
        cmocka_unit_test(test_interleaved_instances_match_solo_runs),
        cmocka_unit_test(test_errors_are_logged_not_fatal),
        cmocka_unit_test(test_second_case_through_case_file),
        cmocka_unit_test(test_rheology),
    };
    /* no dlclose: the library stays mapped so that a leak report (ASan) can name its functions */
    return cmocka_run_group_tests(tests, NULL, NULL);
}
