/* test_threads.c - results do not depend on the thread count (core/team.h, the pair loops' bands,
 * docs/performance.md): each bundled case that exercises a part of the step (water with walls;
 * the paper's granular law with the velocity-gradient gather and pressure smoothing; the implicit
 * viscous solver with its coarse preconditioner; the elastic solid's stresses; the erosive dam
 * break's two media) is run for a fixed number of steps on 1, 2 and 3 threads, and on a thread
 * count changed between steps; every particle's state must be the same bit for bit
 * (reference: the 1-thread run; tolerance: none). Three threads on a 2-core machine also check
 * that a descheduled thread changes nothing. Coarse resolutions keep each case within seconds. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "mixsph.h"

#define N_FIELDS 7

/* A run's particles, in storage order, and its clock. */
struct state {
    size_t n;
    uint64_t steps;
    double t;
    double *f[N_FIELDS]; /* x, z, vx, vz, rho, p, mu */
    uint32_t *id;
    uint8_t *st;
};

struct run_def {
    const char *name, *case_file;
    mixsph_override ov[4];
    size_t n_ov;
    int steps;
};

static const struct run_def RUNS[] = {
    {"water dam break", "dambreak_water.json", {{"numerics.dx", 0.01}}, 1, 300},
    {"Vajont V1, explicit", "vajont_padua.json", {{"numerics.dx", 0.04}}, 1, 300},
    {"Vajont V1, implicit, two-level", "vajont_padua.json", {{"numerics.dx", 0.04}, {"numerics.viscosity", 1}}, 2,
     40},
    {"elastic column", "elastic_column.json", {{"numerics.dx", 0.02}}, 1, 300},
    {"erosive dam break", "erosive_dambreak.json", {{"numerics.dx", 0.02}}, 1, 200},
};

/* threads[k] is the thread count from step k * steps / 3 on (a count changed between steps). */
static void run(const struct run_def *r, const int threads[3], struct state *q)
{
    char path[1024], err[512] = "";
    snprintf(path, sizeof path, "%s/cases/%s", MIXSPH_SOURCE_DIR, r->case_file);
    mixsph_sim *s = NULL;
    const mixsph_status st = mixsph_sim_create(path, r->ov, r->n_ov, &s, err, sizeof err);
    if (st != MIXSPH_OK) print_error("%s: %s\n", r->name, err);
    assert_int_equal(st, MIXSPH_OK);
    for (int k = 0; k < r->steps; k++) {
        if (k % ((r->steps + 2) / 3) == 0) assert_int_equal(mixsph_sim_set_threads(s, threads[k / ((r->steps + 2) / 3)]), MIXSPH_OK);
        const mixsph_status ss = mixsph_sim_step(s);
        if (ss != MIXSPH_OK) print_error("%s: %s\n", r->name, mixsph_sim_last_error(s));
        assert_int_equal(ss, MIXSPH_OK);
    }
    mixsph_particles_view v;
    assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
    q->n = v.n;
    q->steps = mixsph_sim_steps(s);
    q->t = mixsph_sim_time(s);
    const double *src[N_FIELDS] = {v.pos[0], v.pos[v.dim - 1], v.vel[0], v.vel[v.dim - 1], v.rho, v.p, v.mu};
    for (int k = 0; k < N_FIELDS; k++) {
        q->f[k] = malloc(v.n * sizeof(double) + 1);
        assert_non_null(q->f[k]);
        memcpy(q->f[k], src[k], v.n * sizeof(double));
    }
    q->id = malloc(v.n * sizeof(uint32_t) + 1);
    q->st = malloc(v.n + 1);
    assert_non_null(q->id);
    assert_non_null(q->st);
    memcpy(q->id, v.id, v.n * sizeof(uint32_t));
    memcpy(q->st, v.state, v.n);
    mixsph_sim_destroy(s);
}

static void state_free(struct state *q)
{
    for (int k = 0; k < N_FIELDS; k++) free(q->f[k]);
    free(q->id);
    free(q->st);
}

static void assert_same(const char *name, const char *what, const struct state *a, const struct state *b)
{
    static const char *const names[N_FIELDS] = {"x", "z", "vx", "vz", "rho", "p", "mu"};
    assert_int_equal(a->n, b->n);
    assert_int_equal(a->steps, b->steps);
    assert_memory_equal(&a->t, &b->t, sizeof a->t);
    assert_memory_equal(a->id, b->id, a->n * sizeof(uint32_t));
    assert_memory_equal(a->st, b->st, a->n);
    for (int k = 0; k < N_FIELDS; k++)
        for (size_t i = 0; i < a->n; i++)
            if (memcmp(&a->f[k][i], &b->f[k][i], sizeof(double)) != 0) {
                print_error("%s, %s: particle %u: %s = %.17g on 1 thread, %.17g\n", name, what, a->id[i], names[k],
                            a->f[k][i], b->f[k][i]);
                fail();
            }
}

static void test_thread_counts(void **state)
{
    (void)state;
    static const struct {
        const char *what;
        int threads[3];
    } variants[] = {{"2 threads", {2, 2, 2}}, {"3 threads", {3, 3, 3}}, {"2, then 1, then 3 threads", {2, 1, 3}}};
    for (size_t r = 0; r < sizeof RUNS / sizeof RUNS[0]; r++) {
        struct state ref;
        run(&RUNS[r], (const int[3]){1, 1, 1}, &ref);
        for (size_t v = 0; v < sizeof variants / sizeof variants[0]; v++) {
            struct state q;
            run(&RUNS[r], variants[v].threads, &q);
            assert_same(RUNS[r].name, variants[v].what, &ref, &q);
            state_free(&q);
        }
        print_message("%s: %zu particles, %d steps to t = %.4g s: the same bit for bit on 1, 2, 3 and changing threads\n",
                      RUNS[r].name, ref.n, RUNS[r].steps, ref.t);
        state_free(&ref);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_thread_counts)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
