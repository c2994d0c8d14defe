/* test_fmu_fatal.c - fmi2Fatal where an instance is unusable, fmi2Error where it can be reset
 * (FMI 2.0 section 2.1.3; docs/fmu.md, "Errors"), on the FMU's linux64 binary through dlopen.
 *
 *   test_fmu_fatal STAGE_DIR     (the unpacked FMU: binaries/, resources/)
 *
 * Out of memory during a step: this executable defines malloc, calloc, realloc and aligned_alloc
 * (exported, so the FMU's binary, loaded later, binds to them) and, once armed, fails every
 * allocation called from inside the FMU's binary (its caller's address is in it, dladdr), while
 * the test itself, cmocka and libgomp allocate as usual. A step then returns fmi2Fatal with a
 * logged fmi2Fatal message, every later call on the instance but fmi2FreeInstance returns
 * fmi2Fatal, the instance can be freed, and another instance of the same binary runs normally.
 * An unstable run, by contrast, is fmi2Error, after which fmi2Reset gives a usable instance.
 *
 * Not built with the sanitizers (they bring their own malloc). */
#define _GNU_SOURCE /* dladdr */
#include <dlfcn.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "fmi2Functions.h"
#include "fmu_variables.h"

/* ---- allocation failures for the FMU's binary -------------------------------------------- */

void *__libc_malloc(size_t n);
void *__libc_calloc(size_t n, size_t size);
void *__libc_realloc(void *p, size_t n);
void *__libc_memalign(size_t align, size_t n);

static volatile int fail_fmu_allocations;
static void *fmu_base; /* the FMU binary's load address (dli_fbase) */
static int failed_allocations;

static int from_fmu(const void *caller)
{
    if (!fail_fmu_allocations || !fmu_base) return 0;
    Dl_info info;
    if (!dladdr(caller, &info) || info.dli_fbase != fmu_base) return 0;
    failed_allocations++;
    return 1;
}

void *malloc(size_t n) { return from_fmu(__builtin_return_address(0)) ? NULL : __libc_malloc(n); }
void *calloc(size_t n, size_t size) { return from_fmu(__builtin_return_address(0)) ? NULL : __libc_calloc(n, size); }
void *realloc(void *p, size_t n) { return from_fmu(__builtin_return_address(0)) ? NULL : __libc_realloc(p, n); }
void *aligned_alloc(size_t align, size_t n)
{
    return from_fmu(__builtin_return_address(0)) ? NULL : __libc_memalign(align, n);
}

/* ---- the FMU -------------------------------------------------------------------------------- */

static const char *stage;
static void *lib;
static fmi2Status last_status;
static char last_message[2048];

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    (void)env, (void)name, (void)category;
    va_list ap;
    va_start(ap, message);
    vsnprintf(last_message, sizeof last_message, message, ap);
    va_end(ap);
    last_status = status;
    if (getenv("FMU_TEST_VERBOSE")) fprintf(stderr, "[%d] %s\n", (int)status, last_message);
}

typedef void (*any_fn)(void);
static any_fn sym(const char *name)
{
    any_fn f;
    *(void **)&f = dlsym(lib, name);
    assert_non_null(f);
    return f;
}
#define FN(type, name) ((type *)sym(name))

static const fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};

static fmi2Component running(const char *name, fmi2Boolean implicit, const char *case_file)
{
    char uri[4200];
    snprintf(uri, sizeof uri, "file://%s/resources", stage);
    fmi2Component c =
        FN(fmi2InstantiateTYPE, "fmi2Instantiate")(name, fmi2CoSimulation, MIXSPH_FMU_GUID, uri, &callbacks, 0, 0);
    assert_non_null(c);
    const fmi2ValueReference vr[] = {VR_dx, VR_mu0}, vr_b = VR_implicit_viscosity, vr_s = VR_case_file;
    const fmi2Real v[] = {0.03, 1000.0};
    assert_int_equal(FN(fmi2SetupExperimentTYPE, "fmi2SetupExperiment")(c, 0, 0.0, 0.0, 0, 0.0), fmi2OK);
    assert_int_equal(FN(fmi2EnterInitializationModeTYPE, "fmi2EnterInitializationMode")(c), fmi2OK);
    assert_int_equal(FN(fmi2SetRealTYPE, "fmi2SetReal")(c, vr, 2, v), fmi2OK);
    assert_int_equal(FN(fmi2SetBooleanTYPE, "fmi2SetBoolean")(c, &vr_b, 1, &implicit), fmi2OK);
    if (case_file) assert_int_equal(FN(fmi2SetStringTYPE, "fmi2SetString")(c, &vr_s, 1, &case_file), fmi2OK);
    assert_int_equal(FN(fmi2ExitInitializationModeTYPE, "fmi2ExitInitializationMode")(c), fmi2OK);
    return c;
}

static fmi2Status step(fmi2Component c, double t, double h)
{
    return FN(fmi2DoStepTYPE, "fmi2DoStep")(c, t, h, fmi2True);
}

static void out_of_memory_in_a_step_is_fatal(void **state)
{
    (void)state;
    /* the implicit viscous solver is made on the first step: that step allocates */
    fmi2Component c = running("oom", fmi2True, NULL);
    fail_fmu_allocations = 1;
    failed_allocations = 0;
    const fmi2Status st = step(c, 0.0, 0.01);
    fail_fmu_allocations = 0;
    assert_true(failed_allocations > 0);
    assert_int_equal(st, fmi2Fatal);
    assert_int_equal(last_status, fmi2Fatal);
    assert_non_null(strstr(last_message, "out of memory"));

    /* unusable: every call but fmi2FreeInstance is fmi2Fatal, with memory to spare again */
    const fmi2ValueReference vr = VR_run_up;
    fmi2Real r;
    fmi2FMUstate fs = NULL;
    assert_int_equal(step(c, 0.01, 0.01), fmi2Fatal);
    assert_int_equal(FN(fmi2GetRealTYPE, "fmi2GetReal")(c, &vr, 1, &r), fmi2Fatal);
    assert_int_equal(FN(fmi2GetFMUstateTYPE, "fmi2GetFMUstate")(c, &fs), fmi2Fatal);
    assert_int_equal(FN(fmi2ResetTYPE, "fmi2Reset")(c), fmi2Fatal);
    assert_int_equal(FN(fmi2TerminateTYPE, "fmi2Terminate")(c), fmi2Fatal);
    assert_int_equal(last_status, fmi2Fatal);
    FN(fmi2FreeInstanceTYPE, "fmi2FreeInstance")(c);

    /* another instance of the binary is not affected */
    c = running("after", fmi2True, NULL);
    assert_int_equal(step(c, 0.0, 0.01), fmi2OK);
    FN(fmi2FreeInstanceTYPE, "fmi2FreeInstance")(c);
}

/* text with the number after the first "key": replaced by value (in place; text has room) */
static void set_number(char *text, size_t cap, const char *key, const char *value)
{
    char *k = strstr(text, key);
    assert_non_null(k);
    char *v = strchr(k + strlen(key), ':');
    assert_non_null(v);
    v++;
    const size_t old = strspn(v, " 0123456789.eE+-");
    const size_t tail = strlen(v + old) + 1;
    assert_true((size_t)(v - text) + strlen(value) + tail + 1 <= cap);
    memmove(v + 1 + strlen(value), v + old, tail);
    v[0] = ' ';
    memcpy(v + 1, value, strlen(value));
}

static void an_unstable_run_is_an_error_and_reset_recovers(void **state)
{
    (void)state;
    /* the Vajont case with time-step coefficients far too large blows up within 0.5 s */
    char src[4200], path[] = "/tmp/mixsph_fatal_XXXXXX";
    snprintf(src, sizeof src, "%s/resources/vajont_padua.json", stage);
    FILE *in = fopen(src, "rb");
    assert_non_null(in);
    static char text[1 << 16];
    const size_t n = fread(text, 1, sizeof text - 64, in);
    fclose(in);
    text[n] = '\0';
    set_number(text, sizeof text, "\"cfl\"", "1.0");
    set_number(text, sizeof text, "\"cfl_visc\"", "1.0");
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    FILE *out = fdopen(fd, "wb");
    fputs(text, out);
    fclose(out);

    fmi2Component c = running("unstable", fmi2False, path);
    assert_int_equal(step(c, 0.0, 0.5), fmi2Error);
    assert_int_equal(last_status, fmi2Error);
    assert_non_null(strstr(last_message, "unstable"));
    assert_int_equal(step(c, 0.5, 0.1), fmi2Error); /* the error state */
    /* fmi2Reset: back to instantiated, the start values, then a normal run */
    assert_int_equal(FN(fmi2ResetTYPE, "fmi2Reset")(c), fmi2OK);
    const fmi2ValueReference vr = VR_dx;
    const fmi2Real dx = 0.03;
    assert_int_equal(FN(fmi2SetupExperimentTYPE, "fmi2SetupExperiment")(c, 0, 0.0, 0.0, 0, 0.0), fmi2OK);
    assert_int_equal(FN(fmi2EnterInitializationModeTYPE, "fmi2EnterInitializationMode")(c), fmi2OK);
    assert_int_equal(FN(fmi2SetRealTYPE, "fmi2SetReal")(c, &vr, 1, &dx), fmi2OK);
    assert_int_equal(FN(fmi2ExitInitializationModeTYPE, "fmi2ExitInitializationMode")(c), fmi2OK);
    assert_int_equal(step(c, 0.0, 0.02), fmi2OK);
    FN(fmi2FreeInstanceTYPE, "fmi2FreeInstance")(c);
    remove(path);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_fmu_fatal STAGE_DIR\n");
        return 2;
    }
    static char stage_abs[4096]; /* the resource URI needs an absolute path */
    if (!realpath(argv[1], stage_abs)) {
        perror(argv[1]);
        return 1;
    }
    stage = stage_abs;
    char so[4200];
    snprintf(so, sizeof so, "%s/binaries/linux64/%s.so", stage, MIXSPH_FMU_MODEL_NAME);
    lib = dlopen(so, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "test_fmu_fatal: %s\n", dlerror());
        return 1;
    }
    Dl_info info;
    if (!dladdr(dlsym(lib, "fmi2Instantiate"), &info)) return 1;
    fmu_base = info.dli_fbase;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(out_of_memory_in_a_step_is_fatal),
        cmocka_unit_test(an_unstable_run_is_an_error_and_reset_recovers),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
