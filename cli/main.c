/* mixsph - run a case file.
 *
 *   mixsph run CASE.json [--set key=value]... [--out DIR] [--threads N] [--quiet]
 *              [--checkpoint-every SECONDS] [--no-csv] [--fixed-threads]
 *   mixsph run --restart CHECKPOINT [--out DIR] [--threads N] [--quiet] [--checkpoint-every SECONDS]
 *              [--no-csv] [--fixed-threads]
 *
 * Progress on a terminal (simulated time, steps, steps/s, ETA); at the end a readable summary
 * on stdout and summary.json in the output folder. SIGINT or SIGTERM (Ctrl-C) stops the run before
 * the next time step with a checkpoint, and the creation of the simulation at once (the library
 * polls the flag the handler sets; a second signal kills at once). Exit codes: 0 ok, 2 bad usage or
 * input, 3 unstable run, 4 out of memory or output failure, 128 + the signal (130 SIGINT, 143
 * SIGTERM) stopped by a signal. */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "mixsph.h"

#ifdef _OPENMP
#include <omp.h>
#endif

#define MAX_SETS 64

static void usage(FILE *f)
{
    fprintf(f,
            "usage: mixsph run CASE.json [--set key=value]... [--out DIR] [--threads N] [--quiet]\n"
            "                  [--checkpoint-every SECONDS] [--no-csv] [--fixed-threads]\n"
            "       mixsph run --restart CHECKPOINT [--out DIR] [--threads N] [--quiet] [--checkpoint-every SECONDS]\n"
            "                  [--no-csv] [--fixed-threads]\n"
            "  --set key=value   override a numeric case value, e.g. --set numerics.dx=0.01\n"
            "  --out DIR         output folder (default: out/<case name>)\n"
            "  --threads N       OpenMP threads (default: all cores); the run drops to 1 thread while that\n"
            "                    measures faster (another process busy on the cores), results unchanged\n"
            "  --fixed-threads   always N threads\n"
            "  --quiet           no progress line\n"
            "  --checkpoint-every SECONDS\n"
            "                    write DIR/checkpoint.h5 every SECONDS of wall time (0: at every progress\n"
            "                    step, t_end/1000); it replaces the previous one atomically\n"
            "  --restart FILE    continue the run saved in checkpoint FILE (the case and overrides come from\n"
            "                    it); output folder: --out, default the checkpoint's folder, whose files\n"
            "                    (monitors.csv, run.h5, snapshots) are continued from the checkpoint's time\n"
            "  --no-csv          particle snapshots only in run.h5 (no snap_NNNN.csv)\n");
}

/* The signal that asked the run to stop (SIGINT, SIGTERM), 0 if none. */
static volatile sig_atomic_t stop_signal = 0;

static void on_stop_signal(int sig) { stop_signal = sig; }

/* The library's interrupt poll (mixsph_interrupt): has a stop signal arrived? */
static int stop_requested(void *user)
{
    (void)user;
    return stop_signal != 0;
}

static void install_stop_handlers(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND | SA_RESTART; /* a second signal has its default effect */
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

static int exit_code(mixsph_status st)
{
    switch (st) {
    case MIXSPH_OK: return 0;
    case MIXSPH_ERR_ARG:
    case MIXSPH_ERR_CASE: return 2;
    case MIXSPH_ERR_UNSTABLE: return 3;
    default: return 4;
    }
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static void fmt_duration(double s, char *buf, size_t n)
{
    if (!isfinite(s) || s < 0) snprintf(buf, n, "--");
    else if (s < 60) snprintf(buf, n, "%.0fs", s);
    else if (s < 3600) snprintf(buf, n, "%dm%02ds", (int)(s / 60), (int)fmod(s, 60));
    else snprintf(buf, n, "%dh%02dm", (int)(s / 3600), (int)fmod(s / 60, 60));
}

/* A JSON string: quotes, backslashes and control characters escaped. */
static void json_string(FILE *f, const char *v)
{
    fputc('"', f);
    for (const unsigned char *c = (const unsigned char *)v; *c; c++) {
        if (*c == '"' || *c == '\\') fprintf(f, "\\%c", *c);
        else if (*c < 0x20) fprintf(f, "\\u%04x", *c);
        else fputc(*c, f);
    }
    fputc('"', f);
}

static void json_number(FILE *f, double v)
{
    if (isfinite(v)) fprintf(f, "%.17g", v); /* round-trips exactly */
    else fprintf(f, "null");
}

/* The full-scale report of the case (key full_scale): outputs <m>_Z (full-scale elevation of the
 * max_elevation monitor m) and <m>_d_eta (the error (13) of Manenti et al. 2018 of its maximum).
 * Returns 1 and the indices of m, <m>_Z and <m>_d_eta for the k-th output named <m>_d_eta. */
static int full_scale_outputs(const mixsph_sim *s, size_t k, long *km, long *kz)
{
    static const char suffix[] = "_d_eta";
    const char *name = mixsph_sim_output_name(s, k);
    const size_t n = strlen(name), ns = sizeof suffix - 1;
    if (n <= ns || strcmp(name + n - ns, suffix) != 0) return 0;
    char base[128];
    if (n - ns + 3 > sizeof base) return 0;
    memcpy(base, name, n - ns);
    base[n - ns] = '\0';
    *km = mixsph_sim_output_find(s, base);
    strcat(base, "_Z");
    *kz = mixsph_sim_output_find(s, base);
    return *km >= 0 && *kz >= 0;
}

/* summary.json. The rates cover the work of this process: from simulated time t0 and step
 * step0 (not 0 after --restart) to now, in `wall` seconds. */
static int write_summary(const char *dir, const mixsph_sim *s, const char *case_path, const char *restart, int threads,
                         double wall, double t0, unsigned long long step0, const char *status_text)
{
    char path[1100];
    snprintf(path, sizeof path, "%s/summary.json", dir);
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    const double psteps = (double)mixsph_sim_particles(s) * (double)(mixsph_sim_steps(s) - step0);
    const double simulated = mixsph_sim_time(s) - t0;
    fprintf(f, "{\n  \"case\": ");
    json_string(f, mixsph_sim_name(s));
    fprintf(f, ",\n  \"case_file\": ");
    json_string(f, case_path);
    fprintf(f, ",\n  \"status\": \"%s\",\n", status_text);
    fprintf(f, "  \"particles\": %zu,\n  \"wall_particles\": %zu,\n  \"steps\": %llu,\n", mixsph_sim_particles(s),
            mixsph_sim_wall_particles(s), (unsigned long long)mixsph_sim_steps(s));
    fprintf(f, "  \"threads\": %d,\n  \"simulated_time_s\": ", threads);
    json_number(f, mixsph_sim_time(s));
    if (restart) { /* this process continued a checkpoint: where it started */
        fprintf(f, ",\n  \"restarted_from\": ");
        json_string(f, restart);
        fprintf(f, ",\n  \"restart_time_s\": ");
        json_number(f, t0);
        fprintf(f, ",\n  \"restart_step\": %llu", step0);
    }
    fprintf(f, ",\n  \"wall_time_s\": ");
    json_number(f, wall);
    fprintf(f, ",\n  \"run_wall_time_s\": "); /* the whole run's stepping, pieces before a restart included */
    json_number(f, mixsph_sim_run_wall_time(s));
    fprintf(f, ",\n  \"particle_steps_per_s\": ");
    json_number(f, wall > 0 ? psteps / wall : NAN);
    fprintf(f, ",\n  \"wall_s_per_simulated_s\": ");
    json_number(f, simulated > 0 ? wall / simulated : NAN);
    uint64_t visc_iterations = 0;
    double visc_wall = 0.0;
    mixsph_sim_viscous_cost(s, &visc_iterations, &visc_wall);
    if (visc_iterations > 0) { /* the implicit viscous step: its iterations and its share of the time */
        fprintf(f, ",\n  \"viscous_iterations_per_step\": ");
        json_number(f, mixsph_sim_steps(s) > 0 ? (double)visc_iterations / (double)mixsph_sim_steps(s) : NAN);
        fprintf(f, ",\n  \"viscous_solve_wall_time_s\": ");
        json_number(f, visc_wall);
        fprintf(f, ",\n  \"viscous_solve_fraction\": ");
        json_number(f, wall > 0 ? visc_wall / wall : NAN);
    }
    /* the law each medium ran: the one it names, or the one its keys imply (docs/cases.md) */
    fprintf(f, ",\n  \"media\": {");
    for (size_t k = 0; k < mixsph_sim_medium_count(s); k++) {
        fprintf(f, "%s", k ? ", " : "");
        json_string(f, mixsph_sim_medium_name(s, k));
        fprintf(f, ": {\"law\": ");
        json_string(f, mixsph_sim_medium_law(s, k));
        fprintf(f, "}");
    }
    fprintf(f, "}");
    /* the numerics the run used (the case file's, its overrides' or the defaults) */
    static const char *const numerics[] = {"dx", "h_over_dx", "cfl", "cfl_visc", "viscosity", "pressure_smoothing"};
    fprintf(f, ",\n  \"numerics\": {");
    for (size_t k = 0; k < sizeof numerics / sizeof numerics[0]; k++) {
        char key[64];
        double v = NAN;
        snprintf(key, sizeof key, "numerics.%s", numerics[k]);
        mixsph_sim_case_number(s, key, &v);
        fprintf(f, "%s\"%s\": ", k ? ", " : "", numerics[k]);
        json_number(f, v);
    }
    fprintf(f, "}");
    fprintf(f, ",\n  \"outputs\": {\n");
    const size_t n = mixsph_sim_output_count(s);
    for (size_t k = 0; k < n; k++) {
        double mx, tmx, mn, tmn;
        mixsph_sim_output_extremes(s, k, &mx, &tmx, &mn, &tmn);
        fprintf(f, "    \"%s\": {\"final\": ", mixsph_sim_output_name(s, k));
        json_number(f, mixsph_sim_output_value(s, k));
        fprintf(f, ", \"max\": ");
        json_number(f, mx);
        fprintf(f, ", \"t_max\": ");
        json_number(f, tmx);
        fprintf(f, ", \"min\": ");
        json_number(f, mn);
        fprintf(f, ", \"t_min\": ");
        json_number(f, tmn);
        fprintf(f, "}%s\n", k + 1 < n ? "," : "");
    }
    fprintf(f, "  },\n  \"full_scale\": [");
    int first = 1;
    for (size_t k = 0; k < n; k++) {
        long km, kz;
        if (!full_scale_outputs(s, k, &km, &kz)) continue;
        double mx, tmx, mn, tmn, zmx, ztmx;
        mixsph_sim_output_extremes(s, (size_t)km, &mx, &tmx, &mn, &tmn);
        mixsph_sim_output_extremes(s, (size_t)kz, &zmx, &ztmx, &mn, &tmn);
        fprintf(f, "%s\n    {\"monitor\": \"%s\", \"max\": ", first ? "" : ",", mixsph_sim_output_name(s, (size_t)km));
        json_number(f, mx);
        fprintf(f, ", \"t_max\": ");
        json_number(f, tmx);
        fprintf(f, ", \"Z_max\": ");
        json_number(f, zmx);
        fprintf(f, ", \"d_eta_percent\": ");
        json_number(f, mixsph_sim_output_value(s, k));
        fprintf(f, "}");
        first = 0;
    }
    fprintf(f, "%s]\n}\n", first ? "" : "\n  ");
    return fclose(f) == 0 ? 0 : -1;
}

/* The thread governor: runs on fewer threads when they measure faster. The step's parallel loops
 * meet at barriers; when another busy process shares the cores, a barrier waits for a thread the
 * system has descheduled, and with OpenMP's default (spinning) wait policy a 2-thread run on 2
 * cores beside one busy process was 15-60 times slower than on an idle machine, and 6-10 times
 * slower than 1 thread beside the same process (docs/performance.md, "Under load"). Results do not
 * depend on the thread count, so the CLI may change it between steps: it times the steps in windows
 * of GOV_WINDOW_S of wall time, and now and then (GOV_FIRST_S after the start or after a switch,
 * then twice as long after each probe that kept the count, up to GOV_MAX_S; at once when a window
 * is GOV_DROP times slower than the one after the last probe) runs one window on the other count
 * (1 or the --threads asked for) and keeps it when its steps per second are GOV_GAIN times more.
 * A probe costs at most one window at the slower count. It starts on 1 thread when other tasks
 * are running on the cores the threads would need (the kernel's count of runnable tasks): its
 * first window cannot be cut short, and a spinning 2-thread step beside two busy processes took
 * 10-20 s. --fixed-threads turns it off. */
#define GOV_WINDOW_S 0.1
#define GOV_FIRST_S 1.0
#define GOV_MAX_S 32.0
#define GOV_GAIN 1.1
#define GOV_DROP 0.5

struct governor {
    int on;                /* more than one thread asked for and no --fixed-threads */
    int max, cur;          /* threads asked for, threads in use */
    int probing;           /* the window in progress runs on the other count */
    double acc_s;          /* stepping wall time of the window in progress */
    long acc_steps;        /* its steps */
    double rate, rate_ref; /* steps/s of the last window on cur; of the first after the last probe */
    double next_probe, interval;
    long switches;
};

/* How many cores no other task is running on now (-1 when unknown): online cores minus the
 * runnable tasks of /proc/stat (procs_running) besides the calling thread. */
static int cores_idle_now(void)
{
    FILE *f = fopen("/proc/stat", "r");
    if (!f) return -1;
    char line[256];
    long running = -1;
    while (fgets(line, sizeof line, f))
        if (sscanf(line, "procs_running %ld", &running) == 1) break;
    fclose(f);
    const long cores = sysconf(_SC_NPROCESSORS_ONLN);
    if (running < 1 || cores < 1) return -1;
    return (int)(cores - (running - 1));
}

/* idle: cores_idle_now() read before the simulation's first parallel region (afterwards the
 * process's own spinning threads would count as other tasks). */
static void governor_init(struct governor *g, mixsph_sim *s, int threads, int fixed, int idle)
{
    memset(g, 0, sizeof *g);
    g->max = threads;
#ifdef _OPENMP
    if (g->max == 0) g->max = omp_get_max_threads();
#endif
    if (g->max < 1) g->max = 1;
    g->cur = g->max;
    g->on = !fixed && g->max > 1;
    g->interval = GOV_FIRST_S;
    g->next_probe = now() + GOV_FIRST_S;
    if (g->on && idle >= 0 && idle < g->max) { /* the cores are shared: start on 1 */
        g->cur = 1;
        mixsph_sim_set_threads(s, 1);
    }
}

static void governor_window_done(mixsph_sim *s, struct governor *g, double t)
{
    const double rate = (double)g->acc_steps / g->acc_s;
    g->acc_s = 0.0;
    g->acc_steps = 0;
    if (g->probing) {
        const int other = g->cur == g->max ? 1 : g->max;
        g->probing = 0;
        if (rate > GOV_GAIN * g->rate) { /* the other count is faster: keep it */
            g->cur = other;
            g->rate = g->rate_ref = rate;
            g->interval = GOV_FIRST_S;
            g->switches++;
        } else {
            mixsph_sim_set_threads(s, g->cur);
            g->rate_ref = g->rate;
            g->interval = fmin(2.0 * g->interval, GOV_MAX_S);
        }
        g->next_probe = t + g->interval;
        return;
    }
    g->rate = rate;
    if (g->rate_ref <= 0.0) g->rate_ref = rate;
    if (t >= g->next_probe || rate < GOV_DROP * g->rate_ref) {
        g->probing = 1;
        mixsph_sim_set_threads(s, g->cur == g->max ? 1 : g->max);
    }
}

/* mixsph_sim_advance_to(s, target) (the same steps), timing each step for the governor. */
static mixsph_status advance_governed(mixsph_sim *s, double target, struct governor *g)
{
    if (!g->on) return mixsph_sim_advance_to(s, target);
    mixsph_status st = MIXSPH_OK;
    while (st == MIXSPH_OK && mixsph_sim_time(s) < target && !stop_signal) {
        const double t0 = now();
        st = mixsph_sim_step(s);
        const double t1 = now();
        g->acc_s += t1 - t0;
        g->acc_steps++;
        if (g->acc_s >= GOV_WINDOW_S) governor_window_done(s, g, t1);
    }
    return st;
}

static int cmd_run(int argc, char **argv)
{
    const int cores_idle = cores_idle_now();
    const char *case_path = NULL, *out_dir = NULL, *restart = NULL;
    double ckpt_every = -1.0; /* wall seconds between checkpoints, < 0: none */
    mixsph_override sets[MAX_SETS];
    size_t n_sets = 0;
    int threads = 0, quiet = 0, no_csv = 0, fixed_threads = 0;
    char err[1024];
    for (int a = 0; a < argc; a++) {
        const char *arg = argv[a];
        if (strcmp(arg, "--set") == 0 || strcmp(arg, "--out") == 0 || strcmp(arg, "--threads") == 0 ||
            strcmp(arg, "--restart") == 0 || strcmp(arg, "--checkpoint-every") == 0) {
            if (a + 1 >= argc) {
                fprintf(stderr, "mixsph: %s needs a value\n", arg);
                return 2;
            }
            char *val = argv[++a];
            if (strcmp(arg, "--out") == 0) {
                out_dir = val;
            } else if (strcmp(arg, "--restart") == 0) {
                restart = val;
            } else if (strcmp(arg, "--checkpoint-every") == 0) {
                char *end;
                ckpt_every = strtod(val, &end);
                if (*end || !(ckpt_every >= 0.0 && ckpt_every < 1e9)) {
                    fprintf(stderr, "mixsph: --checkpoint-every: '%s' is not a number of seconds >= 0\n", val);
                    return 2;
                }
            } else if (strcmp(arg, "--threads") == 0) {
                char *end;
                long v = strtol(val, &end, 10);
                if (*end || v < 1 || v > 1024) {
                    fprintf(stderr, "mixsph: --threads: '%s' is not a thread count (1..1024)\n", val);
                    return 2;
                }
                threads = (int)v;
            } else {
                if (n_sets == MAX_SETS) {
                    fprintf(stderr, "mixsph: at most %d --set options\n", MAX_SETS);
                    return 2;
                }
                if (mixsph_override_parse(val, &sets[n_sets], err, sizeof err) != MIXSPH_OK) {
                    fprintf(stderr, "mixsph: --set: %s\n", err);
                    return 2;
                }
                n_sets++;
            }
        } else if (strcmp(arg, "--quiet") == 0) {
            quiet = 1;
        } else if (strcmp(arg, "--no-csv") == 0) {
            no_csv = 1;
        } else if (strcmp(arg, "--fixed-threads") == 0) {
            fixed_threads = 1;
        } else if (arg[0] == '-') {
            fprintf(stderr, "mixsph: unknown option '%s'\n", arg);
            usage(stderr);
            return 2;
        } else if (!case_path) {
            case_path = arg;
        } else {
            fprintf(stderr, "mixsph: more than one case file ('%s', '%s')\n", case_path, arg);
            return 2;
        }
    }
    if (restart && (case_path || n_sets > 0)) {
        fprintf(stderr, "mixsph: --restart takes the case and its overrides from the checkpoint: give no case file "
                        "and no --set\n");
        return 2;
    }
    if (!case_path && !restart) {
        fprintf(stderr, "mixsph: run: no case file given\n");
        usage(stderr);
        return 2;
    }
    mixsph_sim *s = NULL;
    install_stop_handlers();
    const mixsph_interrupt interrupt = {stop_requested, NULL};
    mixsph_status st = restart ? mixsph_sim_create_from_checkpoint_interruptible(restart, &interrupt, &s, err, sizeof err)
                               : mixsph_sim_create_interruptible(case_path, sets, n_sets, &interrupt, &s, err, sizeof err);
    if (st == MIXSPH_ERR_INTERRUPTED) {
        fprintf(stderr, "mixsph: stopped by signal %d while creating the simulation (%s)\n", (int)stop_signal, err);
        return 128 + (int)stop_signal;
    }
    if (st != MIXSPH_OK) {
        fprintf(stderr, "mixsph: %s\n", err);
        return exit_code(st);
    }
    if (restart) case_path = mixsph_sim_case_origin(s);
    char dir[1024];
    if (out_dir) {
        snprintf(dir, sizeof dir, "%s", out_dir);
    } else if (restart) { /* the checkpoint's folder */
        snprintf(dir, sizeof dir, "%s", restart);
        char *slash = strrchr(dir, '/');
        if (slash == dir) dir[1] = '\0';
        else if (slash) *slash = '\0';
        else snprintf(dir, sizeof dir, ".");
    } else {
        snprintf(dir, sizeof dir, "out/%s", mixsph_sim_name(s));
    }
    char ckpt[1100];
    snprintf(ckpt, sizeof ckpt, "%s/checkpoint.h5", dir);
    if (no_csv) mixsph_sim_set_csv_snapshots(s, 0);
    if ((st = mixsph_sim_set_threads(s, threads)) != MIXSPH_OK ||
        (st = restart ? mixsph_sim_resume_output_dir(s, dir) : mixsph_sim_set_output_dir(s, dir)) != MIXSPH_OK) {
        fprintf(stderr, "mixsph: %s\n", mixsph_sim_last_error(s));
        mixsph_sim_destroy(s);
        return exit_code(st);
    }
    const int tty = !quiet && isatty(STDERR_FILENO);
    if (!quiet)
        fprintf(stderr, "mixsph: %s: %zu particles + %zu wall particles, t_end = %g s, output in %s\n", mixsph_sim_name(s),
                mixsph_sim_particles(s), mixsph_sim_wall_particles(s), mixsph_sim_end_time(s), dir);
    if (!quiet && restart)
        fprintf(stderr, "mixsph: restarting from %s at t = %.6g s, step %llu\n", restart, mixsph_sim_time(s),
                (unsigned long long)mixsph_sim_steps(s));
    const double t_end = mixsph_sim_end_time(s), t0 = now(), sim_t0 = mixsph_sim_time(s);
    const unsigned long long step0 = mixsph_sim_steps(s); /* rates count this process's work only */
    double last_print = 0.0, last_ckpt = t0;
    unsigned long long ckpt_step = mixsph_sim_steps(s);
    const int chunks = 1000;
    struct governor gov;
    governor_init(&gov, s, threads, fixed_threads, cores_idle);
    for (int c = 1; c <= chunks && st == MIXSPH_OK && !stop_signal; c++) {
        st = advance_governed(s, t_end * c / chunks, &gov);
        if (st == MIXSPH_ERR_INTERRUPTED) st = MIXSPH_OK; /* a signal, between two steps: stopped below */
        if (st == MIXSPH_OK && ckpt_every >= 0.0 && c < chunks && mixsph_sim_steps(s) > ckpt_step &&
            now() - last_ckpt >= ckpt_every) {
            st = mixsph_sim_write_checkpoint(s, ckpt);
            last_ckpt = now();
            ckpt_step = mixsph_sim_steps(s);
        }
        const double el = now() - t0;
        if (tty && (el - last_print > 0.5 || c == chunks)) {
            last_print = el;
            const double ts = mixsph_sim_time(s);
            char eta[32];
            fmt_duration(ts > sim_t0 ? el * (t_end - ts) / (ts - sim_t0) : NAN, eta, sizeof eta);
            fprintf(stderr, "\r  t = %.4f / %.4f s  steps %llu  %.0f steps/s  dt %.3g s  ETA %s   ", ts, t_end,
                    (unsigned long long)mixsph_sim_steps(s), (double)(mixsph_sim_steps(s) - step0) / (el > 0 ? el : 1),
                    mixsph_sim_dt(s), eta);
        }
    }
    if (tty) fprintf(stderr, "\n");
    if (!quiet && gov.on)
        fprintf(stderr, "mixsph: %d threads asked, %d in use at the end, %ld switches of the thread count\n", gov.max,
                gov.cur, gov.switches);
    const double wall = now() - t0;
    const int stopped = stop_signal && st == MIXSPH_OK && mixsph_sim_time(s) < t_end;
    if (stopped) {
        st = mixsph_sim_write_checkpoint(s, ckpt);
        if (st == MIXSPH_OK)
            fprintf(stderr, "mixsph: stopped by signal %d at t = %.6g s; continue with: mixsph run --restart %s\n",
                    (int)stop_signal, mixsph_sim_time(s), ckpt);
    }
    if (st != MIXSPH_OK) fprintf(stderr, "mixsph: %s\n", mixsph_sim_last_error(s));
    if (write_summary(dir, s, case_path, restart, threads, wall, sim_t0, step0,
                      st != MIXSPH_OK ? mixsph_status_string(st) : stopped ? "stopped" : "ok") != 0) {
        fprintf(stderr, "mixsph: %s/summary.json: cannot write\n", dir);
        if (st == MIXSPH_OK) st = MIXSPH_ERR_IO;
    }
    const double psteps = (double)mixsph_sim_particles(s) * (double)(mixsph_sim_steps(s) - step0);
    printf("%s: %s, %zu particles, %llu steps, %.2f s wall, %.3g particle-steps/s, t = %.4g s\n", mixsph_sim_name(s),
           st != MIXSPH_OK ? "FAILED" : stopped ? "STOPPED" : "done", mixsph_sim_particles(s), (unsigned long long)mixsph_sim_steps(s), wall,
           wall > 0 ? psteps / wall : 0.0, mixsph_sim_time(s));
    printf("  media:");
    for (size_t k = 0; k < mixsph_sim_medium_count(s); k++)
        printf("%s %s (law %s)", k ? "," : "", mixsph_sim_medium_name(s, k), mixsph_sim_medium_law(s, k));
    printf("\n");
    for (size_t k = 0; k < mixsph_sim_output_count(s); k++) {
        double mx, tmx, mn, tmn;
        mixsph_sim_output_extremes(s, k, &mx, &tmx, &mn, &tmn);
        printf("  %-18s final %-12.6g max %-12.6g (t = %.4g s)  min %-12.6g (t = %.4g s)\n", mixsph_sim_output_name(s, k),
               mixsph_sim_output_value(s, k), mx, tmx, mn, tmn);
    }
    for (size_t k = 0; k < mixsph_sim_output_count(s); k++) {
        long km, kz;
        if (!full_scale_outputs(s, k, &km, &kz)) continue;
        double mx, tmx, mn, tmn, zmx;
        mixsph_sim_output_extremes(s, (size_t)km, &mx, &tmx, &mn, &tmn);
        mixsph_sim_output_extremes(s, (size_t)kz, &zmx, &tmn, &mn, &tmn);
        printf("  %s: max %.4g at t = %.4g s, full scale Z = %.1f, d_eta = %.1f %% (error (13))\n",
               mixsph_sim_output_name(s, (size_t)km), mx, tmx, zmx, mixsph_sim_output_value(s, k));
    }
    printf("  summary: %s/summary.json, monitors: %s/monitors.csv\n", dir, dir);
    mixsph_sim_destroy(s);
    return st == MIXSPH_OK && stopped ? 128 + (int)stop_signal : exit_code(st);
}

int main(int argc, char **argv)
{
    if (argc >= 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) {
        usage(stdout);
        return 0;
    }
    if (argc >= 2 && strcmp(argv[1], "--version") == 0) {
        printf("mixsph 0.1.0\n");
        return 0;
    }
    if (argc < 2 || strcmp(argv[1], "run") != 0) {
        if (argc >= 2) fprintf(stderr, "mixsph: unknown command '%s'\n", argv[1]);
        usage(stderr);
        return 2;
    }
    return cmd_run(argc - 2, argv + 2);
}
