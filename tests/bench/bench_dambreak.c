/* bench_dambreak - speed of the solver on the water dam break (cases/dambreak_water.json).
 *
 *   bench_dambreak [--steps N] [--dx D]... [--threads T]... [--case FILE]
 *   bench_dambreak --output [--steps N] [--dx D]... [--threads T] [--snap-every K] [--out DIR]
 *   bench_dambreak --pairs [--case FILE --dx D]... [--threads T]... [--steps N] [--rounds R]
 *
 * For each resolution (default dx = 0.0035 and 0.00175: about 10k and 40k particles) and each
 * thread count (default 1 and 2): creates the case, takes 20 warm-up steps, then times N steps
 * (default 400) and reports particle-steps per second (fluid particles x steps / wall time),
 * per thread, the speed-up over one thread, and the wall time per simulated second. A
 * benchmark, not a test: it asserts nothing.
 *
 * --pairs: pair interactions per second per thread of several cases in one sitting, the runs
 * interleaved (R rounds, default 3; in each round every thread count, and for each every case),
 * so that a drift of the machine's speed favours none; each --case takes the --dx that follows
 * it. A case of either dimension (the library for both is linked): the 3D dam break
 * (cases/spheric_test2.json) against the 2D one. A pair interaction is an unordered pair of
 * particles closer than the kernel's support 2h, at least one of them not a wall particle (the
 * pairs the pair loops evaluate, in either dimension: wall-wall pairs are never evaluated),
 * counted from the particles' positions before and after the timed steps (their mean; h =
 * --h-over-dx times dx, default 1.3, set on the case too). It prints per run the pairs per
 * particle, M pair interactions per second per thread and the memory the simulation holds
 * (the process's resident size after creating it and its warm-up steps minus that before,
 * divided by all its particles, walls included), then per case and thread count the median over
 * the rounds, and every case's median over the first case's.
 *
 * --output: the cost of the outputs against the cost of stepping. For each resolution, on the
 * first thread count given (default 1): the case with an output folder (DIR, default a fresh
 * folder under /tmp, removed afterwards) and a snapshot every K steps (default 50; the snapshot
 * interval is set to K times the initial time step, so about K), 20 warm-up steps, then N
 * timed steps; the library's own clock of its writing (mixsph_sim_output_time) splits the wall
 * time into stepping, CSV snapshots and HDF5 snapshots (run.h5 + run.xdmf); then 3 checkpoints
 * are written and timed. It prints the time per step and per snapshot, the bytes per snapshot,
 * and the share of the run's wall time spent writing at the case's own snapshot interval. */
#define _DEFAULT_SOURCE /* getloadavg */
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

/* The process's resident size [bytes] (VmRSS of /proc/self/status; 0 where unreadable). */
static double resident_bytes(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    if (!f) return 0.0;
    char line[256];
    double kb = 0.0;
    while (fgets(line, sizeof line, f))
        if (strncmp(line, "VmRSS:", 6) == 0) kb = atof(line + 6);
    fclose(f);
    return 1024.0 * kb;
}

/* Unordered pairs of particles closer than rc, at least one of them not a wall particle: a
 * counting sort into cubic cells of side rc, each particle against the particles after it in its
 * own cell and against those of the cells of the half stencil after its own. */
static double count_pairs(const mixsph_particles_view *v, double rc)
{
    const int dim = v->dim;
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int d = 0; d < dim; d++) {
        lo[d] = hi[d] = v->pos[d][0];
        for (size_t i = 1; i < v->n; i++) {
            if (v->pos[d][i] < lo[d]) lo[d] = v->pos[d][i];
            if (v->pos[d][i] > hi[d]) hi[d] = v->pos[d][i];
        }
    }
    long nc[3] = {1, 1, 1};
    for (int d = 0; d < dim; d++) nc[d] = (long)((hi[d] - lo[d]) / rc) + 1;
    const size_t ncell = (size_t)(nc[0] * nc[1] * nc[2]);
    size_t *start = calloc(ncell + 1, sizeof *start), *order = malloc(v->n * sizeof *order);
    size_t *cell = malloc(v->n * sizeof *cell);
    if (!start || !order || !cell) {
        free(start), free(order), free(cell);
        return -1.0;
    }
    for (size_t i = 0; i < v->n; i++) {
        long c[3] = {0, 0, 0};
        for (int d = 0; d < dim; d++) c[d] = (long)((v->pos[d][i] - lo[d]) / rc);
        cell[i] = (size_t)((c[2] * nc[1] + c[1]) * nc[0] + c[0]);
        start[cell[i] + 1]++;
    }
    for (size_t c = 0; c < ncell; c++) start[c + 1] += start[c];
    size_t *fill = malloc(ncell * sizeof *fill);
    if (!fill) {
        free(start), free(order), free(cell);
        return -1.0;
    }
    memcpy(fill, start, ncell * sizeof *fill);
    for (size_t i = 0; i < v->n; i++) order[fill[cell[i]]++] = i;
    free(fill);
    const double rc2 = rc * rc;
    double pairs = 0.0;
    for (long cz = 0; cz < nc[2]; cz++)
        for (long cy = 0; cy < nc[1]; cy++)
            for (long cx = 0; cx < nc[0]; cx++) {
                const size_t c0 = (size_t)((cz * nc[1] + cy) * nc[0] + cx);
                /* the cells at or after this one in storage order among its 3^dim neighbours */
                for (long dz = -1; dz <= 1; dz++)
                    for (long dy = -1; dy <= 1; dy++)
                        for (long dxc = -1; dxc <= 1; dxc++) {
                            const long x = cx + dxc, y = cy + dy, z = cz + dz;
                            if (x < 0 || y < 0 || z < 0 || x >= nc[0] || y >= nc[1] || z >= nc[2]) continue;
                            const size_t c1 = (size_t)((z * nc[1] + y) * nc[0] + x);
                            if (c1 < c0) continue;
                            for (size_t a = start[c0]; a < start[c0 + 1]; a++) {
                                const size_t i = order[a];
                                for (size_t b = c1 == c0 ? a + 1 : start[c1]; b < start[c1 + 1]; b++) {
                                    const size_t j = order[b];
                                    if (v->state[i] == MIXSPH_STATE_WALL && v->state[j] == MIXSPH_STATE_WALL) continue;
                                    double r2 = 0.0;
                                    for (int d = 0; d < dim; d++) {
                                        const double e = v->pos[d][i] - v->pos[d][j];
                                        r2 += e * e;
                                    }
                                    pairs += r2 < rc2;
                                }
                            }
                        }
            }
    free(start), free(order), free(cell);
    return pairs;
}

static int compare_doubles(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *x, int n)
{
    qsort(x, (size_t)n, sizeof *x, compare_doubles);
    return n % 2 ? x[n / 2] : 0.5 * (x[n / 2 - 1] + x[n / 2]);
}

enum { PAIRS_MAX_CASES = 4, PAIRS_MAX_THREADS = 8, PAIRS_MAX_ROUNDS = 16 };

static int bench_pairs(const char *const *cases, const double *dxs, int n_case, const int *threads, int n_thr,
                       long steps, int rounds, double h_over_dx)
{
    static double rate[PAIRS_MAX_CASES][PAIRS_MAX_THREADS][PAIRS_MAX_ROUNDS];
    printf("%-5s %-28s %-3s %-8s %-9s %-9s %-8s %-7s %-8s %-13s %-10s %-11s %s\n", "round", "case", "dim", "dx",
           "particles", "walls", "threads", "steps", "wall_s", "pairs/particle", "Mpairs/s/th", "bytes/part", "load1");
    for (int r = 0; r < rounds; r++)
        for (int k = 0; k < n_thr; k++)
            for (int c = 0; c < n_case; c++) {
                char err[1024];
                mixsph_override ov[2] = {{"numerics.dx", dxs[c]}, {"numerics.h_over_dx", h_over_dx}};
                mixsph_sim *s = NULL;
                double load = 0.0;
                getloadavg(&load, 1);
                const double rss0 = resident_bytes();
                if (mixsph_sim_create(cases[c], ov, 2, &s, err, sizeof err) != MIXSPH_OK) {
                    fprintf(stderr, "bench_dambreak: %s\n", err);
                    return 1;
                }
                mixsph_sim_set_threads(s, threads[k]);
                for (int w = 0; w < 20; w++) mixsph_sim_step(s);
                const double rss = resident_bytes() - rss0;
                const double rc = 2.0 * h_over_dx * dxs[c];
                mixsph_particles_view v;
                mixsph_sim_particles_view(s, &v);
                const size_t n_all = v.n;
                const int dim = v.dim;
                const double pairs0 = count_pairs(&v, rc);
                const double t0 = now();
                for (long st = 0; st < steps; st++) {
                    if (mixsph_sim_step(s) != MIXSPH_OK) {
                        fprintf(stderr, "bench_dambreak: %s\n", mixsph_sim_last_error(s));
                        mixsph_sim_destroy(s);
                        return 1;
                    }
                }
                const double wall = now() - t0;
                mixsph_sim_particles_view(s, &v);
                const double pairs = 0.5 * (pairs0 + count_pairs(&v, rc));
                rate[c][k][r] = pairs * (double)steps / wall / threads[k];
                const char *name = strrchr(cases[c], '/') ? strrchr(cases[c], '/') + 1 : cases[c];
                printf("%-5d %-28s %-3d %-8g %-9zu %-9zu %-8d %-7ld %-8.3f %-13.2f %-10.3f %-11.0f %.2f\n", r, name, dim,
                       dxs[c], mixsph_sim_particles(s), mixsph_sim_wall_particles(s), threads[k], steps, wall,
                       2.0 * pairs / (double)mixsph_sim_particles(s), rate[c][k][r] / 1e6, rss / (double)n_all, load);
                fflush(stdout);
                mixsph_sim_destroy(s);
            }
    printf("\nmedian over %d rounds: M pair interactions per second per thread (and over the first case's)\n",
           rounds);
    for (int k = 0; k < n_thr; k++) {
        double ref = 0.0;
        for (int c = 0; c < n_case; c++) {
            const double m = median(rate[c][k], rounds);
            if (c == 0) ref = m;
            const char *name = strrchr(cases[c], '/') ? strrchr(cases[c], '/') + 1 : cases[c];
            printf("threads %d  %-28s dx %-8g %8.3f  (x%.2f)\n", threads[k], name, dxs[c], m / 1e6, m / ref);
        }
    }
    return 0;
}

int main(int argc, char **argv)
{
    const char *case_path = MIXSPH_SOURCE_DIR "/cases/dambreak_water.json";
    double dxs[8] = {0.0035, 0.00175};
    int n_dx = 0, threads[8] = {1, 2}, n_thr = 0;
    long steps = 400, every = 50;
    int output = 0, pairs = 0, rounds = 3, n_case = 0;
    const char *out = NULL, *cases[PAIRS_MAX_CASES];
    double case_dx[PAIRS_MAX_CASES], h_over_dx = 1.3;
    for (int a = 1; a < argc; a++) {
        if (strcmp(argv[a], "--output") == 0) {
            output = 1;
            continue;
        }
        if (strcmp(argv[a], "--pairs") == 0) {
            pairs = 1;
            continue;
        }
        if (a + 1 >= argc) {
            fprintf(stderr, "bench_dambreak: %s needs a value\n", argv[a]);
            return 2;
        }
        if (strcmp(argv[a], "--steps") == 0) steps = atol(argv[++a]);
        else if (strcmp(argv[a], "--dx") == 0 && pairs && n_case > 0) case_dx[n_case - 1] = atof(argv[++a]);
        else if (strcmp(argv[a], "--dx") == 0 && n_dx < 8) dxs[n_dx++] = atof(argv[++a]);
        else if (strcmp(argv[a], "--threads") == 0 && n_thr < 8) threads[n_thr++] = atoi(argv[++a]);
        else if (strcmp(argv[a], "--case") == 0 && pairs && n_case < PAIRS_MAX_CASES) {
            cases[n_case] = argv[++a];
            case_dx[n_case++] = 0.0;
        } else if (strcmp(argv[a], "--case") == 0) case_path = argv[++a];
        else if (strcmp(argv[a], "--rounds") == 0) rounds = atoi(argv[++a]);
        else if (strcmp(argv[a], "--h-over-dx") == 0) h_over_dx = atof(argv[++a]);
        else if (strcmp(argv[a], "--snap-every") == 0) every = atol(argv[++a]);
        else if (strcmp(argv[a], "--out") == 0) out = argv[++a];
        else {
            fprintf(stderr, "usage: bench_dambreak [--steps N] [--dx D]... [--threads T]... [--case FILE]\n"
                            "       bench_dambreak --pairs [--case FILE --dx D]... [--threads T]... [--steps N] "
                            "[--rounds R] [--h-over-dx H]\n"
                            "       bench_dambreak --output [--steps N] [--dx D]... [--threads T] [--snap-every K] "
                            "[--out DIR]\n");
            return 2;
        }
    }
    if (n_dx == 0) n_dx = 2;
    if (n_thr == 0) n_thr = 2;
    if (steps < 1) steps = 1;
    if (pairs) {
        if (n_case == 0) {
            cases[0] = MIXSPH_SOURCE_DIR "/cases/dambreak_water.json", case_dx[0] = 0.0025;
            cases[1] = MIXSPH_SOURCE_DIR "/cases/spheric_test2.json", case_dx[1] = 0.04;
            n_case = 2;
        }
        for (int c = 0; c < n_case; c++)
            if (!(case_dx[c] > 0.0)) {
                fprintf(stderr, "bench_dambreak: --pairs: --case %s needs a --dx after it\n", cases[c]);
                return 2;
            }
        if (rounds < 1 || rounds > PAIRS_MAX_ROUNDS || n_thr > PAIRS_MAX_THREADS) {
            fprintf(stderr, "bench_dambreak: --rounds takes 1 to %d, --threads at most %d values\n", PAIRS_MAX_ROUNDS,
                    PAIRS_MAX_THREADS);
            return 2;
        }
        return bench_pairs(cases, case_dx, n_case, threads, n_thr, steps, rounds, h_over_dx);
    }
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
