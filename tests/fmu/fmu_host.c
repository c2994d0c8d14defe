/* fmu_host.c - a minimal FMI 2.0 co-simulation master in C, built for Linux and, cross-compiled
 * with mingw-w64, for Windows (run under Wine): it loads the unpacked FMU's binary of its own
 * platform, runs the Vajont case and prints the outputs at every communication point, so that
 * tests/python/test_fmu_win64.py can compare the win64 DLL's run with the linux64 .so's.
 *
 *   fmu_host UNPACKED_FMU STOP_TIME DX THREADS
 *
 * UNPACKED_FMU is the folder of modelDescription.xml, binaries/ and resources/ (a native path:
 * on Windows C:\... or Z:\...). Prints "time,<outputs...>" lines with 17 significant digits,
 * one per 0.01 s communication step. The binary is then unloaded, loaded again and run again:
 * a second run that differs from the first, or a crash in the unload, fails the host.
 * Exit status 0 on success; errors are printed to stderr. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(_WIN32)
#include <windows.h>
#else
#include <dlfcn.h>
#endif

#include "fmi2Functions.h"
#include "fmu_variables.h" /* value references and the GUID, generated from modelDescription.xml */

#if defined(_WIN32)
#define PLATFORM "win64"
#define SUFFIX ".dll"
#define SEP '\\'
#else
#define PLATFORM "linux64"
#define SUFFIX ".so"
#define SEP '/'
#endif

#define COMM_STEP 0.01
#define MAX_ROWS 10000
#define N_REAL 6
#define N_INT 3

static const fmi2ValueReference out_real[N_REAL] = {VR_run_up,         VR_max_run_up, VR_time_of_max_run_up,
                                                    VR_landslide_front, VR_kinetic_energy, VR_dt};
static const fmi2ValueReference out_int[N_INT] = {VR_fixed_particles, VR_lost_particles, VR_steps};

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    (void)env;
    va_list ap;
    va_start(ap, message);
    fprintf(stderr, "[%s %d %s] ", name, (int)status, category);
    vfprintf(stderr, message, ap);
    fputc('\n', stderr);
    va_end(ap);
}

struct binary {
#if defined(_WIN32)
    HMODULE handle;
#else
    void *handle;
#endif
};

typedef void (*any_fn)(void);

static any_fn sym(struct binary *b, const char *name)
{
#if defined(_WIN32)
    any_fn f = (any_fn)(void (*)(void))GetProcAddress(b->handle, name);
#else
    any_fn f;
    *(void **)&f = dlsym(b->handle, name);
#endif
    if (!f) fprintf(stderr, "fmu_host: %s not exported\n", name);
    return f;
}

/* One run from a fresh load: the outputs of every communication point into rows (a string). */
static int run(const char *dir, double stop, double dx, int threads, char *rows, size_t len)
{
    char path[4096], uri[4200];
    snprintf(path, sizeof path, "%s%cbinaries%c%s%c%s%s", dir, SEP, SEP, PLATFORM, SEP, MIXSPH_FMU_MODEL_NAME, SUFFIX);
    struct binary b;
#if defined(_WIN32)
    b.handle = LoadLibraryA(path);
#else
    b.handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
#endif
    if (!b.handle) {
#if defined(_WIN32)
        fprintf(stderr, "fmu_host: cannot load %s (error %lu)\n", path, (unsigned long)GetLastError());
#else
        fprintf(stderr, "fmu_host: cannot load %s: %s\n", path, dlerror());
#endif
        return 1;
    }
    /* file:///C:/dir/resources or file:///dir/resources */
    size_t j = (size_t)snprintf(uri, sizeof uri, "file://%s", dir[0] == '/' ? "" : "/");
    for (const char *p = dir; *p && j + 2 < sizeof uri; p++) uri[j++] = *p == '\\' ? '/' : *p;
    uri[j] = '\0';
    strncat(uri, "/resources", sizeof uri - strlen(uri) - 1);

    fmi2InstantiateTYPE *instantiate = (fmi2InstantiateTYPE *)sym(&b, "fmi2Instantiate");
    fmi2FreeInstanceTYPE *free_instance = (fmi2FreeInstanceTYPE *)sym(&b, "fmi2FreeInstance");
    fmi2SetupExperimentTYPE *setup = (fmi2SetupExperimentTYPE *)sym(&b, "fmi2SetupExperiment");
    fmi2EnterInitializationModeTYPE *enter = (fmi2EnterInitializationModeTYPE *)sym(&b, "fmi2EnterInitializationMode");
    fmi2ExitInitializationModeTYPE *exit_init = (fmi2ExitInitializationModeTYPE *)sym(&b, "fmi2ExitInitializationMode");
    fmi2SetRealTYPE *set_real = (fmi2SetRealTYPE *)sym(&b, "fmi2SetReal");
    fmi2SetIntegerTYPE *set_integer = (fmi2SetIntegerTYPE *)sym(&b, "fmi2SetInteger");
    fmi2GetRealTYPE *get_real = (fmi2GetRealTYPE *)sym(&b, "fmi2GetReal");
    fmi2GetIntegerTYPE *get_integer = (fmi2GetIntegerTYPE *)sym(&b, "fmi2GetInteger");
    fmi2DoStepTYPE *do_step = (fmi2DoStepTYPE *)sym(&b, "fmi2DoStep");
    fmi2TerminateTYPE *terminate = (fmi2TerminateTYPE *)sym(&b, "fmi2Terminate");
    if (!instantiate || !free_instance || !setup || !enter || !exit_init || !set_real || !set_integer || !get_real ||
        !get_integer || !do_step || !terminate)
        return 1;

    const fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c = instantiate("host", fmi2CoSimulation, MIXSPH_FMU_GUID, uri, &cb, fmi2False, fmi2False);
    if (!c) {
        fprintf(stderr, "fmu_host: fmi2Instantiate failed (resources %s)\n", uri);
        return 1;
    }
    const fmi2ValueReference vr_dx = VR_dx, vr_threads = VR_threads;
    const fmi2Integer n_threads = threads;
    int bad = setup(c, fmi2False, 0.0, 0.0, fmi2True, stop) != fmi2OK || enter(c) != fmi2OK ||
              set_real(c, &vr_dx, 1, &dx) != fmi2OK || set_integer(c, &vr_threads, 1, &n_threads) != fmi2OK ||
              exit_init(c) != fmi2OK;
    size_t used = 0;
    rows[0] = '\0';
    const int n_steps = (int)(stop / COMM_STEP + 0.5);
    for (int k = 0; k < n_steps && !bad; k++) {
        const double t = k * COMM_STEP;
        fmi2Real r[N_REAL];
        fmi2Integer n[N_INT];
        bad = do_step(c, t, COMM_STEP, fmi2True) != fmi2OK || get_real(c, out_real, N_REAL, r) != fmi2OK ||
              get_integer(c, out_int, N_INT, n) != fmi2OK;
        if (bad) break;
        used += (size_t)snprintf(rows + used, len - used, "%.17g", t + COMM_STEP);
        for (int i = 0; i < N_REAL; i++) used += (size_t)snprintf(rows + used, len - used, ",%.17g", r[i]);
        for (int i = 0; i < N_INT; i++) used += (size_t)snprintf(rows + used, len - used, ",%d", (int)n[i]);
        used += (size_t)snprintf(rows + used, len - used, "\n");
        if (used >= len) {
            fprintf(stderr, "fmu_host: too many rows\n");
            bad = 1;
        }
    }
    if (!bad) bad = terminate(c) != fmi2OK;
    free_instance(c);
#if defined(_WIN32)
    FreeLibrary(b.handle);
#else
    dlclose(b.handle);
#endif
    return bad;
}

int main(int argc, char **argv)
{
    if (argc != 5) {
        fprintf(stderr, "usage: fmu_host UNPACKED_FMU STOP_TIME DX THREADS\n");
        return 2;
    }
    const double stop = atof(argv[2]), dx = atof(argv[3]);
    const int threads = atoi(argv[4]);
    const size_t len = (size_t)MAX_ROWS * 256;
    char *first = malloc(len), *second = malloc(len);
    if (!first || !second) return 1;
    if (run(argv[1], stop, dx, threads, first, len) != 0) return 1;
    fputs("time,run_up,max_run_up,time_of_max_run_up,landslide_front,kinetic_energy,dt,fixed_particles,"
          "lost_particles,steps\n",
          stdout);
    fputs(first, stdout);
    fflush(stdout);
    /* loaded again after the unload: the same run */
    if (run(argv[1], stop, dx, threads, second, len) != 0) return 1;
    if (strcmp(first, second) != 0) {
        fprintf(stderr, "fmu_host: the run after reloading differs from the first\n");
        return 1;
    }
    free(first);
    free(second);
    return 0;
}
