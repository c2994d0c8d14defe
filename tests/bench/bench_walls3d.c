/* bench_walls3d.c - the cost of a 3D wall's queries (DIM = 3 build; a benchmark, not a test):
 * the signed distance (the near-wall flag, the placement, the monitors) and the segment crossing
 * (the crossing guard, once per step for each particle near a wall), on a box tank of 10
 * triangles and on a wavy terrain of 200 x 200 nodes (79 202 triangles), against the brute-force
 * distance over every triangle (mesh_distance). Prints nanoseconds per query.
 *
 *     build-dim3/bench_walls3d
 *
 * Run it on an idle machine; docs/performance.md keeps the numbers with the machine's load. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "mesh.h"
#include "surface.h"
#include "terrain.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double uniform(unsigned long *seed, double lo, double hi)
{
    *seed = *seed * 6364136223846793005ul + 1442695040888963407ul;
    return lo + (hi - lo) * (double)(*seed >> 11) / 9007199254740992.0;
}

/* n points: x, y uniform in [lo, hi], z = base(x, y) + uniform in [dz0, dz1]. */
static double *points(size_t n, const double lo[2], const double hi[2], const struct terrain *t, double dz0, double dz1)
{
    double *p = malloc(3 * n * sizeof *p);
    unsigned long seed = 7;
    for (size_t k = 0; k < n; k++) {
        p[3 * k] = uniform(&seed, lo[0], hi[0]);
        p[3 * k + 1] = uniform(&seed, lo[1], hi[1]);
        p[3 * k + 2] = (t ? terrain_height(t, p[3 * k], p[3 * k + 1]) : 0.0) + uniform(&seed, dz0, dz1);
    }
    return p;
}

static void time_distance(const char *what, const struct surface *s, const double *p, size_t n)
{
    double sum = 0.0;
    const double t0 = now();
    for (size_t k = 0; k < n; k++) sum += surface_signed_distance(s, p + 3 * k, NULL);
    const double t1 = now();
    printf("%-46s %9.0f ns per query (checksum %.6g)\n", what, 1e9 * (t1 - t0) / (double)n, sum);
}

static void time_within(const char *what, const struct surface *s, const double *p, size_t n, double reach)
{
    long near = 0;
    const double t0 = now();
    for (size_t k = 0; k < n; k++) near += isfinite(surface_signed_distance_within(s, p + 3 * k, reach, NULL));
    const double t1 = now();
    printf("%-46s %9.0f ns per query (%ld within %g m)\n", what, 1e9 * (t1 - t0) / (double)n, near, reach);
}

static void time_may_be_within(const char *what, const struct surface *s, const double *p, size_t n, double reach)
{
    long near = 0;
    const double t0 = now();
    for (size_t k = 0; k < n; k++) near += surface_may_be_within(s, p + 3 * k, reach);
    const double t1 = now();
    printf("%-46s %9.0f ns per query (%ld flagged within %g m)\n", what, 1e9 * (t1 - t0) / (double)n, near, reach);
}

static void time_crossing(const char *what, const struct surface *s, const double *p, size_t n, double step)
{
    long hits = 0;
    const double t0 = now();
    for (size_t k = 0; k < n; k++) {
        const double *a = p + 3 * k, b[3] = {a[0] + 0.3 * step, a[1] - 0.2 * step, a[2] - step};
        double t, nrm[3];
        hits += surface_first_crossing(s, a, b, &t, nrm);
    }
    const double t1 = now();
    printf("%-46s %9.0f ns per query (%ld crossings)\n", what, 1e9 * (t1 - t0) / (double)n, hits);
}

static void time_brute(const char *what, const struct mesh *m, const double *p, size_t n)
{
    double sum = 0.0;
    const double t0 = now();
    for (size_t k = 0; k < n; k++) sum += mesh_distance(m, p + 3 * k, NULL, NULL);
    const double t1 = now();
    printf("%-46s %9.0f ns per query (checksum %.6g)\n", what, 1e9 * (t1 - t0) / (double)n, sum);
}

int main(void)
{
    char err[256];
    const size_t n = 1000000;
    /* a tank 3.22 x 1 x 1 m (the SPHERIC dam break's), open top */
    {
        struct mesh m = {0};
        struct surface s;
        const double lo[3] = {0, 0, 0}, hi[3] = {3.22, 1.0, 1.0};
        if (mesh_add_box(&m, lo, hi, MESH_BOX_OPEN_TOP, 1, err, sizeof err) != MIXSPH_OK ||
            surface_build(&s, &m, err, sizeof err) != MIXSPH_OK) {
            fprintf(stderr, "%s\n", err);
            return 1;
        }
        const double a[2] = {0.0, 0.0}, b[2] = {3.22, 1.0};
        double *near = points(n, a, b, NULL, -0.02, 0.06), *all = points(n, a, b, NULL, 0.0, 1.0);
        time_distance("tank, 10 triangles: distance near the bottom", &s, near, n);
        time_distance("tank: distance anywhere inside", &s, all, n);
        time_within("tank: within 0.15 m? (anywhere inside)", &s, all, n, 0.15);
        time_may_be_within("tank: may be within 0.15 m? (anywhere inside)", &s, all, n, 0.15);
        time_crossing("tank: crossing of a step near the bottom", &s, near, n, 0.002);
        free(near);
        free(all);
        surface_free(&s);
        mesh_free(&m);
    }
    /* a wavy terrain, 200 x 200 nodes 0.05 m apart (10 x 10 m), heights of +-0.5 m */
    {
        const size_t nc = 200;
        double *z = malloc(nc * nc * sizeof *z);
        for (size_t j = 0; j < nc; j++)
            for (size_t i = 0; i < nc; i++) z[j * nc + i] = 0.3 * sin(0.7 * (double)i * 0.05) * cos(0.9 * (double)j * 0.05) + 0.2 * sin(2.3 * (double)(i + j) * 0.05);
        struct terrain t = {0};
        struct mesh m = {0}, copy = {0};
        struct surface s;
        if (terrain_from_heights(&t, nc, nc, 0.0, 0.0, 0.05, z, err, sizeof err) != MIXSPH_OK ||
            terrain_to_mesh(&t, &m, err, sizeof err) != MIXSPH_OK || terrain_to_mesh(&t, &copy, err, sizeof err) != MIXSPH_OK ||
            surface_build(&s, &m, err, sizeof err) != MIXSPH_OK) {
            fprintf(stderr, "%s\n", err);
            return 1;
        }
        printf("terrain: %zu triangles, %zu x %zu x %zu buckets of %.3g m\n", s.mesh.n_triangles, s.n[0], s.n[1], s.n[2],
               s.cell);
        const double a[2] = {0.1, 0.1}, b[2] = {9.85, 9.85};
        double *near = points(n, a, b, &t, -0.02, 0.06), *high = points(n / 10, a, b, &t, 0.5, 2.0);
        time_distance("terrain: distance within 0.06 m of it", &s, near, n);
        time_distance("terrain: distance 0.5 to 2 m above it", &s, high, n / 100);
        time_within("terrain: within 0.15 m? (near it)", &s, near, n, 0.15);
        time_within("terrain: within 0.15 m? (0.5 to 2 m above)", &s, high, n / 10, 0.15);
        time_may_be_within("terrain: may be within 0.15 m? (near it)", &s, near, n, 0.15);
        time_may_be_within("terrain: may be within 0.15 m? (0.5 to 2 m above)", &s, high, n / 10, 0.15);
        time_crossing("terrain: crossing of a step near it", &s, near, n, 0.002);
        time_brute("terrain: brute-force distance (mesh_distance)", &copy, near, 200);
        free(near);
        free(high);
        free(z);
        surface_free(&s);
        mesh_free(&m);
        mesh_free(&copy);
        terrain_free(&t);
    }
    return 0;
}
