/* test_sim.c - the simulation object (sim.c, mixsph.h): no hidden shared state (two
 * simulations stepped in turn in one process give bit for bit what each gives alone), results
 * independent of the thread count and of how a run is cut into advance_to calls, instability
 * reported as MIXSPH_ERR_UNSTABLE with a message, output folders checked at once. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "mixsph.h"

/* A small dam break (150 water particles, dx = 0.02) in a closed tank: the column collapses,
 * hits the far wall, so every code path of a step (walls, artificial viscosity, free surface)
 * runs within a few hundred steps. */
static const char *const CASE_TEXT =
    "{\n"
    "  \"name\": \"small_dambreak\",\n"
    "  \"gravity\": 9.81,\n"
    "  \"numerics\": { \"dx\": 0.02, \"h_over_dx\": 1.3, \"cfl\": 0.1, \"cfl_visc\": 0.05, \"t_end\": 0.3, "
    "\"wall_layers\": 3 },\n"
    "  \"media\": { \"water\": { \"type\": \"fluid\", \"rho\": 1000.0, \"c\": 20.0, \"mu\": 1.0e-3, \"alpha_m\": 0.1 } },\n"
    "  \"bodies\": { \"column\": { \"medium\": \"water\", \"polygon\": [[0.0, 0.0], [0.2, 0.0], [0.2, 0.3], [0.0, 0.3]] } },\n"
    "  \"walls\": { \"tank\": { \"polyline\": [[0.0, 0.6], [0.0, 0.0], [0.6, 0.0], [0.6, 0.6]], \"fluid_side\": \"left\" } },\n"
    "  \"monitors\": { \"front\": { \"type\": \"front\", \"medium\": \"water\", \"direction\": \"+x\" } },\n"
    "  \"output\": { \"monitor_interval\": 0.01 }\n"
    "}\n";

#define N_STEPS 400
#define MAX_OUT 32

/* Everything observable of a simulation, particles sorted by id. */
struct snap {
    size_t n, n_out;
    double t, dt;
    uint64_t steps;
    double *f[7]; /* x, z, vx, vz, rho, p, mu by id */
    uint8_t *state, *medium;
    double out[MAX_OUT][5]; /* value, max, t_max, min, t_min */
};

static void snap_take(const mixsph_sim *s, struct snap *q)
{
    mixsph_particles_view v;
    assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
    memset(q, 0, sizeof *q);
    q->n = v.n;
    q->t = mixsph_sim_time(s);
    q->dt = mixsph_sim_dt(s);
    q->steps = mixsph_sim_steps(s);
    const double *src[7] = {v.pos[0], v.pos[v.dim - 1], v.vel[0], v.vel[v.dim - 1], v.rho, v.p, v.mu};
    for (int k = 0; k < 7; k++) {
        q->f[k] = calloc(v.n, sizeof(double));
        assert_non_null(q->f[k]);
    }
    q->state = calloc(v.n, 1);
    q->medium = calloc(v.n, 1);
    assert_non_null(q->state);
    assert_non_null(q->medium);
    for (size_t i = 0; i < v.n; i++) {
        const uint32_t id = v.id[i];
        assert_true(id < v.n);
        for (int k = 0; k < 7; k++) q->f[k][id] = src[k][i];
        q->state[id] = v.state[i];
        q->medium[id] = v.medium[i];
    }
    q->n_out = mixsph_sim_output_count(s);
    assert_true(q->n_out <= MAX_OUT);
    for (size_t k = 0; k < q->n_out; k++) {
        q->out[k][0] = mixsph_sim_output_value(s, k);
        mixsph_sim_output_extremes(s, k, &q->out[k][1], &q->out[k][2], &q->out[k][3], &q->out[k][4]);
    }
}

static void snap_free(struct snap *q)
{
    for (int k = 0; k < 7; k++) free(q->f[k]);
    free(q->state);
    free(q->medium);
    memset(q, 0, sizeof *q);
}

/* Bit for bit equal (memcmp: also NaN outputs, e.g. a monitor with no particle, compare). */
static void snap_assert_equal(const struct snap *a, const struct snap *b)
{
    static const char *const names[7] = {"x", "z", "vx", "vz", "rho", "p", "mu"};
    assert_int_equal(a->n, b->n);
    assert_int_equal(a->steps, b->steps);
    assert_memory_equal(&a->t, &b->t, sizeof a->t);
    assert_memory_equal(&a->dt, &b->dt, sizeof a->dt);
    for (int k = 0; k < 7; k++) {
        if (memcmp(a->f[k], b->f[k], a->n * sizeof(double)) != 0) {
            for (size_t i = 0; i < a->n; i++)
                if (memcmp(&a->f[k][i], &b->f[k][i], sizeof(double)) != 0) {
                    print_error("particle %zu: %s = %.17g vs %.17g\n", i, names[k], a->f[k][i], b->f[k][i]);
                    break;
                }
            fail();
        }
    }
    assert_memory_equal(a->state, b->state, a->n);
    assert_memory_equal(a->medium, b->medium, a->n);
    assert_int_equal(a->n_out, b->n_out);
    assert_memory_equal(a->out, b->out, a->n_out * sizeof a->out[0]);
}

static mixsph_sim *create(const mixsph_override *ov, size_t n_ov, int threads)
{
    mixsph_sim *s = NULL;
    char err[512] = "";
    const mixsph_status st = mixsph_sim_create_from_text(CASE_TEXT, "small_dambreak.json", ov, n_ov, &s, err, sizeof err);
    if (st != MIXSPH_OK) print_error("%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, threads), MIXSPH_OK);
    return s;
}

static void step_n(mixsph_sim *s, int n)
{
    for (int k = 0; k < n; k++) {
        const mixsph_status st = mixsph_sim_step(s);
        if (st != MIXSPH_OK) print_error("%s\n", mixsph_sim_last_error(s));
        assert_int_equal(st, MIXSPH_OK);
    }
}

/* One simulation alone: N_STEPS steps. */
static void solo(const mixsph_override *ov, size_t n_ov, int threads, struct snap *q)
{
    mixsph_sim *s = create(ov, n_ov, threads);
    step_n(s, N_STEPS);
    snap_take(s, q);
    mixsph_sim_destroy(s);
}

/* Two simulations advanced in turn, unevenly (1 step of a, then 3 of b, ...), each compared
 * with its solo run. */
static void interleaved(const mixsph_override *ova, size_t na, const mixsph_override *ovb, size_t nb)
{
    struct snap sa, sb, ia, ib;
    solo(ova, na, 1, &sa);
    solo(ovb, nb, 2, &sb);
    mixsph_sim *a = create(ova, na, 1), *b = create(ovb, nb, 2);
    int ka = 0, kb = 0;
    while (ka < N_STEPS || kb < N_STEPS) {
        if (ka < N_STEPS) {
            step_n(a, 1);
            ka++;
        }
        const int m = kb + 3 <= N_STEPS ? 3 : N_STEPS - kb;
        step_n(b, m);
        kb += m;
    }
    snap_take(a, &ia);
    snap_take(b, &ib);
    /* reference: the solo runs, bit for bit (no state shared between instances) */
    snap_assert_equal(&ia, &sa);
    snap_assert_equal(&ib, &sb);
    mixsph_sim_destroy(a);
    mixsph_sim_destroy(b);
    snap_free(&sa);
    snap_free(&sb);
    snap_free(&ia);
    snap_free(&ib);
}

/* The run does something: the front moves; outputs are found by name. */
static void test_run_moves(void **state)
{
    (void)state;
    mixsph_sim *s = create(NULL, 0, 1);
    const long front = mixsph_sim_output_find(s, "front");
    assert_true(front >= 0);
    assert_int_equal(mixsph_sim_output_find(s, "no_such_output"), -1);
    assert_string_equal(mixsph_sim_output_name(s, (size_t)front), "front");
    assert_null(mixsph_sim_output_name(s, mixsph_sim_output_count(s)));
    assert_true(isnan(mixsph_sim_output_value(s, mixsph_sim_output_count(s))));
    step_n(s, N_STEPS);
    const double f1 = mixsph_sim_output_value(s, (size_t)front);
    print_message("front at %.4f m at t = %.4f s\n", f1, mixsph_sim_time(s));
    /* the column (right face at x = 0.2) collapses: not a reference, a liveness check */
    assert_true(f1 > 0.25);
    assert_int_equal(mixsph_sim_steps(s), N_STEPS);
    assert_true(mixsph_sim_time(s) > 0.0 && mixsph_sim_dt(s) > 0.0);
    mixsph_sim_destroy(s);
}

/* Monitors are defined from t = 0: the initial front is the column's last lattice column,
 * x = 0.2 - dx/2, both as the current value before any step and as the t = 0 sample. */
static void test_outputs_at_start(void **state)
{
    (void)state;
    mixsph_sim *s = create(NULL, 0, 1);
    const size_t front = (size_t)mixsph_sim_output_find(s, "front");
    const size_t mass = (size_t)mixsph_sim_output_find(s, "mass");
    /* mass: 10 columns of 15 particles of m = rho dx^2, rho = rho0 + p / c^2 from the hydrostatic
     * pressure at the particle, p = rho0 g dx (k + 1/2) for the k-th from the top (docs/model.md
     * section 1): M = 10 rho0 dx^2 (15 + g dx sum_k (k + 1/2) / c^2) = 60.22072 kg/m;
     * tolerance: round-off */
    const double dx = 0.02, rho0 = 1000.0, g = 9.81, c = 20.0;
    const double m_ref = 10.0 * rho0 * dx * dx * (15.0 + g * dx * 112.5 / (c * c));
    assert_true(fabs(mixsph_sim_output_value(s, mass) - m_ref) < 1e-12 * m_ref);
    const double f0 = mixsph_sim_output_value(s, front);
    step_n(s, 1);
    double fmax, tmax, fmin, tmin;
    mixsph_sim_output_extremes(s, front, &fmax, &tmax, &fmin, &tmin);
    print_message("front before the first step: %g m; extremes after it: min %g (t = %g), max %g (t = %g)\n", f0, fmin,
                  tmin, fmax, tmax);
    /* reference: the lattice, x = (9 + 1/2) dx; tolerance: round-off */
    assert_true(fabs(f0 - 0.19) < 1e-12);
    assert_true(fabs(fmin - 0.19) < 1e-12 && tmin == 0.0);
    mixsph_sim_destroy(s);
}

static void test_two_instances_same_case(void **state)
{
    (void)state;
    interleaved(NULL, 0, NULL, 0);
}

static void test_two_instances_different_cases(void **state)
{
    (void)state;
    const mixsph_override b[] = {{"gravity", 5.0}, {"media.water.alpha_m", 0.3}, {"numerics.dx", 0.025}};
    interleaved(NULL, 0, b, 3);
}

/* Bit-identical for 1 and 2 threads (the pair loops give each particle its contributions in
 * an order that does not depend on the thread count). */
static void test_thread_count(void **state)
{
    (void)state;
    struct snap s1, s2;
    solo(NULL, 0, 1, &s1);
    solo(NULL, 0, 2, &s2);
    snap_assert_equal(&s1, &s2);
    snap_free(&s1);
    snap_free(&s2);
}

/* advance_to(T) in one call, in 37 calls, and step by step until t >= T: the same trajectory
 * (the solver never shortens a step to land on T). */
static void test_advance_in_pieces(void **state)
{
    (void)state;
    const double T = 0.1;
    mixsph_sim *a = create(NULL, 0, 1), *b = create(NULL, 0, 1), *c = create(NULL, 0, 1);
    assert_int_equal(mixsph_sim_advance_to(a, T), MIXSPH_OK);
    for (int k = 1; k <= 37; k++) assert_int_equal(mixsph_sim_advance_to(b, T * k / 37.0), MIXSPH_OK);
    while (mixsph_sim_time(c) < T) step_n(c, 1);
    assert_true(mixsph_sim_time(a) >= T && mixsph_sim_time(a) < T + mixsph_sim_dt(a) * 1.5);
    /* advancing to a time already passed does nothing */
    const uint64_t steps = mixsph_sim_steps(a);
    assert_int_equal(mixsph_sim_advance_to(a, 0.5 * T), MIXSPH_OK);
    assert_int_equal(mixsph_sim_steps(a), steps);
    struct snap sa, sb, sc;
    snap_take(a, &sa);
    snap_take(b, &sb);
    snap_take(c, &sc);
    snap_assert_equal(&sa, &sb);
    snap_assert_equal(&sa, &sc);
    snap_free(&sa);
    snap_free(&sb);
    snap_free(&sc);
    /* bad arguments */
    assert_int_equal(mixsph_sim_advance_to(a, NAN), MIXSPH_ERR_ARG);
    assert_non_null(strstr(mixsph_sim_last_error(a), "not finite"));
    assert_int_equal(mixsph_sim_set_threads(a, -1), MIXSPH_ERR_ARG);
    assert_int_equal(mixsph_sim_advance_to(NULL, 1.0), MIXSPH_ERR_ARG);
    mixsph_sim_destroy(a);
    mixsph_sim_destroy(b);
    mixsph_sim_destroy(c);
}

/* CFL = 1 (10 times the paper's 0.1) takes the leapfrog beyond its acoustic stability limit:
 * the run blows up within a few dozen steps and must say so. */
static void test_unstable(void **state)
{
    (void)state;
    const mixsph_override ov[] = {{"numerics.cfl", 1.0}};
    mixsph_sim *s = create(ov, 1, 1);
    assert_string_equal(mixsph_sim_last_error(s), "");
    const mixsph_status st = mixsph_sim_advance_to(s, 0.3);
    char msg[1024];
    snprintf(msg, sizeof msg, "%s", mixsph_sim_last_error(s));
    const double t = mixsph_sim_time(s);
    print_message("status %d after %llu steps, t = %g s: %s\n", (int)st, (unsigned long long)mixsph_sim_steps(s), t,
                  msg);
    mixsph_sim_destroy(s);
    assert_int_equal(st, MIXSPH_ERR_UNSTABLE);
    assert_true(t < 0.3);
    /* the message names the time and, as mixsph.h promises, the particle */
    assert_non_null(strstr(msg, "t = "));
    assert_non_null(strstr(msg, "particle"));
}

/* Output folders: refused at once when they cannot be created or written. */
/* The kinetic_energy monitor: the kinetic energy of one medium in a region. In a water-only case
 * over the whole domain it is the kinetic_energy diagnostic (reference: the same sum, so equal
 * to the last bit); restricted to x <= 0.1 m it is positive and smaller. */
static void test_kinetic_energy_monitor(void **state)
{
    (void)state;
    const char *from = "\"front\": { \"type\": \"front\", \"medium\": \"water\", \"direction\": \"+x\" }";
    const char *to = "\"ke\": { \"type\": \"kinetic_energy\", \"medium\": \"water\" }, "
                     "\"ke_left\": { \"type\": \"kinetic_energy\", \"medium\": \"water\", \"x_max\": 0.1 }";
    const char *at = strstr(CASE_TEXT, from);
    assert_non_null(at);
    char *text = malloc(strlen(CASE_TEXT) + strlen(to) + 1);
    assert_non_null(text);
    memcpy(text, CASE_TEXT, (size_t)(at - CASE_TEXT));
    strcpy(text + (at - CASE_TEXT), to);
    strcat(text, at + strlen(from));
    mixsph_sim *s = NULL;
    char err[512];
    assert_int_equal(mixsph_sim_create_from_text(text, "ke.json", NULL, 0, &s, err, sizeof err), MIXSPH_OK);
    free(text);
    for (int k = 0; k < 200; k++) assert_int_equal(mixsph_sim_step(s), MIXSPH_OK);
    const long all = mixsph_sim_output_find(s, "kinetic_energy"), ke = mixsph_sim_output_find(s, "ke"),
               left = mixsph_sim_output_find(s, "ke_left");
    assert_true(all >= 0 && ke >= 0 && left >= 0);
    const double e_all = mixsph_sim_output_value(s, (size_t)all), e = mixsph_sim_output_value(s, (size_t)ke),
                 e_left = mixsph_sim_output_value(s, (size_t)left);
    print_message("kinetic energy %.6g J/m, of water %.6g, of water at x <= 0.1 m %.6g\n", e_all, e, e_left);
    assert_true(e_all > 0.0);
    assert_true(e == e_all);
    assert_true(e_left > 0.0 && e_left < e);
    mixsph_sim_destroy(s);
}

static void test_output_dir(void **state)
{
    (void)state;
    mixsph_sim *s = create(NULL, 0, 1);
    assert_int_equal(mixsph_sim_set_output_dir(s, "/proc/forbidden"), MIXSPH_ERR_IO);
    print_message("  -> %s\n", mixsph_sim_last_error(s));
    assert_non_null(strstr(mixsph_sim_last_error(s), "/proc/forbidden"));
    assert_int_equal(mixsph_sim_set_output_dir(s, "/proc/forbidden/deeper/still"), MIXSPH_ERR_IO);
    assert_int_equal(mixsph_sim_set_output_dir(s, ""), MIXSPH_ERR_ARG);

    char dir[] = "/tmp/mixsph_test_sim_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char file[256], sub[256], csv[300];
    /* a regular file in the way */
    snprintf(file, sizeof file, "%s/plain_file", dir);
    FILE *f = fopen(file, "w");
    assert_non_null(f);
    fclose(f);
    assert_int_equal(mixsph_sim_set_output_dir(s, file), MIXSPH_ERR_IO);
    print_message("  -> %s\n", mixsph_sim_last_error(s));
    /* a writable nested folder: created, monitors.csv written with a header and samples */
    snprintf(sub, sizeof sub, "%s/a/b", dir);
    assert_int_equal(mixsph_sim_set_output_dir(s, sub), MIXSPH_OK);
    step_n(s, 100);
    snprintf(csv, sizeof csv, "%s/monitors.csv", sub);
    f = fopen(csv, "r");
    assert_non_null(f);
    char line[512] = "";
    assert_non_null(fgets(line, sizeof line, f));
    assert_memory_equal(line, "t,step,", 7);
    assert_non_null(strstr(line, ",front"));
    int rows = 0;
    while (fgets(line, sizeof line, f)) rows++;
    fclose(f);
    assert_true(rows >= 2); /* the sample at t = 0 and at least one more (monitor_interval 0.01 s) */
    mixsph_sim_destroy(s);
    remove(csv);
    rmdir(sub);
    snprintf(sub, sizeof sub, "%s/a", dir);
    rmdir(sub);
    remove(file);
    rmdir(dir);
}

/* numerics.lattice_z0 puts a layer boundary of the particle lattice at a given height, so a body
 * whose flat top is that height is filled to it at any dx: the highest water particle sits at
 * level - dx/2 for levels on and off the multiples of dx (reference: the lattice's definition,
 * z = offset + (k + 1/2) dx; tolerance 1e-9 dx, rounding of the offset). Without the key the
 * top is the multiple of dx + dx/2 below the level (the plain lattice). */
static double top_water_z(double level, int anchored)
{
    char text[2048];
    snprintf(text, sizeof text,
             "{\"name\": \"level\", \"parameters\": {\"level\": %.17g}, \"gravity\": 9.81,\n"
             " \"numerics\": {\"dx\": 0.02, \"t_end\": 0.1, \"wall_layers\": 3%s},\n"
             " \"media\": {\"water\": {\"type\": \"fluid\", \"rho\": 1000.0, \"c\": 20.0, \"mu\": 1.0e-3, \"alpha_m\": 0.1}},\n"
             " \"bodies\": {\"pool\": {\"medium\": \"water\", \"z_max\": \"$level\",\n"
             "   \"polygon\": [[0.0, 0.0], [0.6, 0.0], [0.6, 0.6], [0.0, 0.6]]}},\n"
             " \"walls\": {\"tank\": {\"polyline\": [[0.0, 0.6], [0.0, 0.0], [0.6, 0.0], [0.6, 0.6]], \"fluid_side\": \"left\"}},\n"
             " \"output\": {\"monitor_interval\": 0.01}}\n",
             level, anchored ? ", \"lattice_z0\": \"$level\"" : "");
    mixsph_sim *s = NULL;
    char err[512];
    assert_int_equal(mixsph_sim_create_from_text(text, "level.json", NULL, 0, &s, err, sizeof err), MIXSPH_OK);
    mixsph_particles_view v;
    assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
    double top = -INFINITY;
    for (size_t i = 0; i < v.n; i++)
        if (v.state[i] != MIXSPH_STATE_WALL) top = fmax(top, v.pos[v.dim - 1][i]);
    mixsph_sim_destroy(s);
    return top;
}

static void test_lattice_at_level(void **state)
{
    (void)state;
    const double dx = 0.02, levels[] = {0.30, 0.305, 0.3113, 0.319, 0.2401};
    for (size_t k = 0; k < sizeof levels / sizeof *levels; k++) {
        assert_true(fabs(top_water_z(levels[k], 1) - (levels[k] - 0.5 * dx)) < 1e-9 * dx);
        const double plain = top_water_z(levels[k], 0); /* highest (j + 1/2) dx at or below the level */
        assert_true(fabs(plain - (floor(levels[k] / dx - 0.5 + 1e-9) + 0.5) * dx) < 1e-9 * dx);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_run_moves),
        cmocka_unit_test(test_outputs_at_start),
        cmocka_unit_test(test_two_instances_same_case),
        cmocka_unit_test(test_two_instances_different_cases),
        cmocka_unit_test(test_thread_count),
        cmocka_unit_test(test_advance_in_pieces),
        cmocka_unit_test(test_unstable),
        cmocka_unit_test(test_output_dir),
        cmocka_unit_test(test_kinetic_energy_monitor),
        cmocka_unit_test(test_lattice_at_level),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
