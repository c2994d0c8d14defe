/* bench_dambreak - speed of the solver on the water dam break (cases/dambreak_water.json).
 *
 *   bench_dambreak [--steps N] [--dx D]... [--threads T]... [--case FILE]
 *   bench_dambreak --output [--steps N] [--dx D]... [--threads T] [--snap-every K] [--out DIR]
 *
 * For each resolution (default dx = 0.0035 and 0.00175: about 10k and 40k particles) and each
 * thread count (default 1 and 2): creates the case, takes 20 warm-up steps, then times N steps
 * (default 400) and reports particle-steps per second (fluid particles x steps / wall time),
 * per thread, the speed-up over one thread, and the wall time per simulated second. A
 * benchmark, not a test: it asserts nothing.
 *
 * --output: the cost of the outputs against the cost of stepping. For each resolution, on the
 * first thread count given (default 1): the case with an output folder (DIR, default a fresh
 * folder under /tmp, removed afterwards) and a snapshot every K steps (default 50; the snapshot
 * interval is set to K times the initial time step, so about K), 20 warm-up steps, then N
 * timed steps; the library's own clock of its writing (mixsph_sim_output_time) splits the wall
 * time into stepping, CSV snapshots and HDF5 snapshots (run.h5 + run.xdmf); then 3 checkpoints
 * are written and timed. It prints the time per step and per snapshot, the bytes per snapshot,
 * and the share of the run's wall time spent writing at the case's own snapshot interval. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "mixsph.h"

#ifndef MIXSPH_SOURCE_DIR
#define MIXSPH_SOURCE_DIR "."
#endif

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static double file_size(const char *dir, const char *name)
{
    char path[1200];
    struct stat st;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return stat(path, &st) == 0 ? (double)st.st_size : 0.0;
}

/* Number and total size of the snap_NNNN.csv files of dir. */
static int csv_snapshots(const char *dir, double *bytes)
{
    int n = 0;
    *bytes = 0.0;
    for (;; n++) {
        char name[32];
        snprintf(name, sizeof name, "snap_%04d.csv", n);
        const double b = file_size(dir, name);
        if (b <= 0.0) break;
        *bytes += b;
    }
    return n;
}

static void remove_outputs(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d) return;
    struct dirent *e;
    char path[1400];
    while ((e = readdir(d)))
        if (e->d_name[0] != '.') {
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            remove(path);
        }
    closedir(d);
    rmdir(dir);
}

static int bench_output(const char *case_path, const double *dxs, int n_dx, int threads, long steps, long every,
                        const char *out)
{
    char dir[1024];
    const int own = !out;
    if (own) {
        snprintf(dir, sizeof dir, "/tmp/mixsph_bench_output_XXXXXX");
        if (!mkdtemp(dir)) {
            perror("bench_dambreak: mkdtemp");
            return 1;
        }
    }
    printf("output cost (%d thread%s, a snapshot every ~%ld steps; all particles incl. walls):\n", threads,
           threads == 1 ? "" : "s", every);
    printf("%-9s %-9s %-6s %-9s %-6s %-10s %-10s %-9s %-9s %-9s %-9s %-13s\n", "dx", "particles", "steps", "ms/step",
           "snaps", "csv_ms/sn", "h5_ms/sn", "csv_MB/sn", "h5_MB/sn", "ckpt_ms", "ckpt_MB", "write% @case");
    for (int d = 0; d < n_dx; d++) {
        char sub[1100];
        snprintf(sub, sizeof sub, "%s/dx%g", own ? dir : out, dxs[d]);
        char err[1024];
        mixsph_override ov[2] = {{"numerics.dx", dxs[d]}, {"output.snapshot_interval", 1.0}};
        mixsph_sim *s = NULL;
        if (mixsph_sim_create(case_path, ov, 1, &s, err, sizeof err) != MIXSPH_OK) {
            fprintf(stderr, "bench_dambreak: %s\n", err);
            return 1;
        }
        const double case_interval_dt = mixsph_sim_dt(s);
        mixsph_sim_destroy(s);
        ov[1].value = (double)every * case_interval_dt;
        if (mixsph_sim_create(case_path, ov, 2, &s, err, sizeof err) != MIXSPH_OK) {
            fprintf(stderr, "bench_dambreak: %s\n", err);
            return 1;
        }
        mixsph_sim_set_threads(s, threads);
        if (mixsph_sim_set_output_dir(s, sub) != MIXSPH_OK) {
            fprintf(stderr, "bench_dambreak: %s\n", mixsph_sim_last_error(s));
            mixsph_sim_destroy(s);
            return 1;
        }
        for (int w = 0; w < 20; w++) mixsph_sim_step(s);
        double csv0, h50, csv1, h51, ck0, ck1;
        double csv_bytes;
        mixsph_sim_output_time(s, &csv0, &h50, NULL);
        const int snaps0 = csv_snapshots(sub, &csv_bytes);
        const double h5_bytes0 = file_size(sub, "run.h5");
        const double t_sim0 = mixsph_sim_time(s), t0 = now();
        for (long st = 0; st < steps; st++) {
            if (mixsph_sim_step(s) != MIXSPH_OK) {
                fprintf(stderr, "bench_dambreak: %s\n", mixsph_sim_last_error(s));
                mixsph_sim_destroy(s);
                return 1;
            }
        }
        const double wall = now() - t0, sim = mixsph_sim_time(s) - t_sim0;
        mixsph_sim_output_time(s, &csv1, &h51, &ck0);
        double csv_bytes1;
        const int snaps = csv_snapshots(sub, &csv_bytes1) - snaps0;
        const double h5_bytes = file_size(sub, "run.h5") - h5_bytes0;
        char ck[1200];
        snprintf(ck, sizeof ck, "%s/checkpoint.h5", sub);
        for (int k = 0; k < 3; k++) mixsph_sim_write_checkpoint(s, ck);
        mixsph_sim_output_time(s, NULL, NULL, &ck1);
        const double csv_s = csv1 - csv0, h5_s = h51 - h50, step_s = (wall - csv_s - h5_s) / (double)steps;
        const double per_csv = snaps > 0 ? csv_s / snaps : 0.0, per_h5 = snaps > 0 ? h5_s / snaps : 0.0;
        /* at the case's own snapshot interval (0.05 s for the dam break): steps per snapshot from
         * the mean time step of the timed steps */
        const double case_snap = 0.05, steps_per_snap = case_snap / (sim / (double)steps);
        const double share = 100.0 * (per_csv + per_h5) / (per_csv + per_h5 + steps_per_snap * step_s);
        mixsph_particles_view v;
        mixsph_sim_particles_view(s, &v);
        printf("%-9g %-9zu %-6ld %-9.3f %-6d %-10.2f %-10.2f %-9.3f %-9.3f %-9.2f %-9.3f %.2f%% (%.0f steps/snap)\n",
               dxs[d], v.n, steps, 1e3 * step_s, snaps, 1e3 * per_csv, 1e3 * per_h5,
               snaps > 0 ? (csv_bytes1 - csv_bytes) / snaps / 1e6 : 0.0, snaps > 0 ? h5_bytes / snaps / 1e6 : 0.0,
               1e3 * (ck1 - ck0) / 3.0, file_size(sub, "checkpoint.h5") / 1e6, share, steps_per_snap);
        fflush(stdout);
        mixsph_sim_destroy(s);
        if (own) remove_outputs(sub);
    }
    if (own) rmdir(dir);
    return 0;
}

int main(int argc, char **argv)
{
    const char *case_path = MIXSPH_SOURCE_DIR "/cases/dambreak_water.json";
    double dxs[8] = {0.0035, 0.00175};
    int n_dx = 0, threads[8] = {1, 2}, n_thr = 0;
    long steps = 400, every = 50;
    int output = 0;
    const char *out = NULL;
    for (int a = 1; a < argc; a++) {
        if (strcmp(argv[a], "--output") == 0) {
            output = 1;
            continue;
        }
        if (a + 1 >= argc) {
            fprintf(stderr, "bench_dambreak: %s needs a value\n", argv[a]);
            return 2;
        }
        if (strcmp(argv[a], "--steps") == 0) steps = atol(argv[++a]);
        else if (strcmp(argv[a], "--dx") == 0 && n_dx < 8) dxs[n_dx++] = atof(argv[++a]);
        else if (strcmp(argv[a], "--threads") == 0 && n_thr < 8) threads[n_thr++] = atoi(argv[++a]);
        else if (strcmp(argv[a], "--case") == 0) case_path = argv[++a];
        else if (strcmp(argv[a], "--snap-every") == 0) every = atol(argv[++a]);
        else if (strcmp(argv[a], "--out") == 0) out = argv[++a];
        else {
            fprintf(stderr, "usage: bench_dambreak [--steps N] [--dx D]... [--threads T]... [--case FILE]\n"
                            "       bench_dambreak --output [--steps N] [--dx D]... [--threads T] [--snap-every K] "
                            "[--out DIR]\n");
            return 2;
        }
    }
    if (n_dx == 0) n_dx = 2;
    if (n_thr == 0) n_thr = 2;
    if (steps < 1) steps = 1;
    if (output) return bench_output(case_path, dxs, n_dx, n_thr > 0 && threads[0] > 0 ? threads[0] : 1, steps,
                                     every > 0 ? every : 1, out);
    printf("%-10s %-9s %-8s %-8s %-14s %-16s %-9s %-12s\n", "dx", "particles", "threads", "steps", "wall_s",
           "Mparticle-steps/s", "per_thread", "wall_s/sim_s");
    for (int d = 0; d < n_dx; d++) {
        double base = 0.0;
        for (int k = 0; k < n_thr; k++) {
            char err[1024];
            mixsph_override ov = {"numerics.dx", dxs[d]};
            mixsph_sim *s = NULL;
            if (mixsph_sim_create(case_path, &ov, 1, &s, err, sizeof err) != MIXSPH_OK) {
                fprintf(stderr, "bench_dambreak: %s\n", err);
                return 1;
            }
            mixsph_sim_set_threads(s, threads[k]);
            for (int w = 0; w < 20; w++) mixsph_sim_step(s);
            const double t_sim0 = mixsph_sim_time(s), t0 = now();
            for (long st = 0; st < steps; st++) {
                if (mixsph_sim_step(s) != MIXSPH_OK) {
                    fprintf(stderr, "bench_dambreak: %s\n", mixsph_sim_last_error(s));
                    mixsph_sim_destroy(s);
                    return 1;
                }
            }
            const double wall = now() - t0, sim = mixsph_sim_time(s) - t_sim0;
            const double rate = (double)mixsph_sim_particles(s) * (double)steps / wall;
            if (k == 0) base = rate;
            printf("%-10g %-9zu %-8d %-8ld %-14.3f %-16.3f %-9.3f %-12.1f", dxs[d], mixsph_sim_particles(s), threads[k],
                   steps, wall, rate / 1e6, rate / 1e6 / threads[k], wall / sim);
            if (k > 0) printf("  speed-up x%.2f", rate / base);
            printf("\n");
            fflush(stdout);
            mixsph_sim_destroy(s);
        }
    }
    return 0;
}
