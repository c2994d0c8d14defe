/* bench_dambreak - speed of the solver on the water dam break (cases/dambreak_water.json).
 *
 *   bench_dambreak [--steps N] [--dx D]... [--threads T]... [--case FILE]
 *
 * For each resolution (default dx = 0.0035 and 0.00175: about 10k and 40k particles) and each
 * thread count (default 1 and 2): creates the case, takes 20 warm-up steps, then times N steps
 * (default 400) and reports particle-steps per second (fluid particles x steps / wall time),
 * per thread, the speed-up over one thread, and the wall time per simulated second. A
 * benchmark, not a test: it asserts nothing. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

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

int main(int argc, char **argv)
{
    const char *case_path = MIXSPH_SOURCE_DIR "/cases/dambreak_water.json";
    double dxs[8] = {0.0035, 0.00175};
    int n_dx = 0, threads[8] = {1, 2}, n_thr = 0;
    long steps = 400;
    for (int a = 1; a < argc; a++) {
        if (a + 1 >= argc) {
            fprintf(stderr, "bench_dambreak: %s needs a value\n", argv[a]);
            return 2;
        }
        if (strcmp(argv[a], "--steps") == 0) steps = atol(argv[++a]);
        else if (strcmp(argv[a], "--dx") == 0 && n_dx < 8) dxs[n_dx++] = atof(argv[++a]);
        else if (strcmp(argv[a], "--threads") == 0 && n_thr < 8) threads[n_thr++] = atoi(argv[++a]);
        else if (strcmp(argv[a], "--case") == 0) case_path = argv[++a];
        else {
            fprintf(stderr, "usage: bench_dambreak [--steps N] [--dx D]... [--threads T]... [--case FILE]\n");
            return 2;
        }
    }
    if (n_dx == 0) n_dx = 2;
    if (n_thr == 0) n_thr = 2;
    if (steps < 1) steps = 1;
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
