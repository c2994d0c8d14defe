/* test_sim3d.c - the whole library in its DIM = 3 build (compiled at DIM = 3 and linked to the
 * executable's 3D build: tests/CMakeLists.txt, MIXSPH_DIM3_TESTS):
 * 3D cases from text, their bodies (box, extruded polygon, closed STL, the domain below a level),
 * the hydrostatic initial state, every law and both viscous schemes on a falling block, monitors
 * with y, and a bit-identical restart. Until 3D walls come (lib/src/walls/) the cases have none:
 * a block of particles falls freely in its domain.
 *
 * The free-fall reference: with no wall, every force but gravity is a pair force, equal and
 * opposite between two particles (pair symmetry, docs/model.md), so the centre of mass falls as
 * z_c(t) = z_c(0) - g t^2 / 2 and keeps its horizontal place, whatever the law; the leapfrog's
 * kick-drift-kick integrates a constant acceleration exactly, so the only error is round-off. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "case.h"
#include "dim.h"
#include "edit_text.h"
#include "mesh.h"
#include "mixsph.h"
#include "stl.h"

#if DIM != 3
#error "test_sim3d is the DIM = 3 build's test"
#endif

#define G 9.81

/* A 3D case's text: `media` and `bodies` as JSON object members, extra top-level members `more`. */
static char *case_text(const char *media, const char *bodies, const char *numerics, const char *more)
{
    char *t = malloc(8192);
    snprintf(t, 8192,
             "{\"name\": \"t3d\", \"dimensions\": 3, \"gravity\": %g,"
             " \"numerics\": {\"dx\": 0.01, \"h_over_dx\": 1.3, \"cfl\": 0.1, \"t_end\": 0.05 %s},"
             " \"domain\": {\"x_min\": -0.2, \"x_max\": 0.3, \"y_min\": -0.2, \"y_max\": 0.3, \"z_min\": -0.5, \"z_max\": 0.3},"
             " \"media\": {%s}, \"bodies\": {%s}, \"walls\": {} %s}",
             G, numerics, media, bodies, more);
    return t;
}

#define WATER "\"water\": {\"type\": \"fluid\", \"rho\": 1000.0, \"K\": 6.25e5, \"mu\": 1.0e-3, \"alpha_m\": 0.1}"

static mixsph_sim *create(const char *text, mixsph_status want, const char *want_in_message)
{
    mixsph_sim *s = NULL;
    char err[1024] = "";
    const mixsph_status st = mixsph_sim_create_from_text(text, "t3d.json", NULL, 0, &s, err, sizeof err);
    if (st != want) fprintf(stderr, "status %d (%s), expected %d\n", st, err, want);
    assert_int_equal(st, want);
    if (want_in_message) {
        if (!strstr(err, want_in_message)) fprintf(stderr, "message: %s\n(expected to contain '%s')\n", err, want_in_message);
        assert_non_null(strstr(err, want_in_message));
    }
    return s;
}

/* The particles' positions, sorted (x, y, z), into a new array of 3 n doubles. */
static int cmp3(const void *a, const void *b)
{
    const double *p = a, *q = b;
    for (int d = 0; d < 3; d++)
        if (p[d] != q[d]) return p[d] < q[d] ? -1 : 1;
    return 0;
}

static double *sorted_positions(const mixsph_sim *s, size_t *n)
{
    mixsph_particles_view v;
    assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
    assert_int_equal(v.dim, 3);
    double *p = malloc(3 * v.n_fluid * sizeof *p);
    for (size_t i = 0; i < v.n_fluid; i++)
        for (int d = 0; d < 3; d++) p[3 * i + d] = v.pos[d][i];
    qsort(p, v.n_fluid, 3 * sizeof *p, cmp3);
    *n = v.n_fluid;
    return p;
}

/* A box 0.1 x 0.05 x 0.04 m at dx = 0.01 holds 10 x 5 x 4 lattice sites (its faces lie between
 * sites); the same body as an extruded polygon, a closed STL of the box and the domain below a
 * level give the very same sites. */
static void test_body_shapes_fill_the_same_sites(void **state)
{
    (void)state;
    char *t = case_text(WATER, "\"b\": {\"medium\": \"water\", \"box_min\": [0, 0, 0], \"box_max\": [0.1, 0.05, 0.04]}", "", "");
    mixsph_sim *box = create(t, MIXSPH_OK, NULL);
    free(t);
    size_t n_box;
    double *p_box = sorted_positions(box, &n_box);
    assert_int_equal(n_box, 10 * 5 * 4);

    t = case_text(WATER,
                  "\"b\": {\"medium\": \"water\", \"polygon\": [[0, 0], [0.1, 0], [0.1, 0.04], [0, 0.04]],"
                  " \"y_min\": 0, \"y_max\": 0.05}", "", "");
    mixsph_sim *poly = create(t, MIXSPH_OK, NULL);
    free(t);
    size_t n_poly;
    double *p_poly = sorted_positions(poly, &n_poly);
    assert_int_equal(n_poly, n_box);
    assert_memory_equal(p_poly, p_box, 3 * n_box * sizeof *p_box);

    char dir[] = "/tmp/test_sim3d_XXXXXX", path[128], err[256];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/box.stl", dir);
    struct mesh m;
    memset(&m, 0, sizeof m);
    const double lo[3] = {0, 0, 0}, hi[3] = {0.1, 0.05, 0.04};
    assert_int_equal(mesh_add_box(&m, lo, hi, MESH_BOX_ALL, 0, err, sizeof err), MIXSPH_OK);
    assert_int_equal(stl_write(path, &m, 1, "box", err, sizeof err), MIXSPH_OK);
    mesh_free(&m);
    char bodies[256];
    snprintf(bodies, sizeof bodies, "\"b\": {\"medium\": \"water\", \"stl\": \"%s\"}", path);
    t = case_text(WATER, bodies, "", "");
    mixsph_sim *stl = create(t, MIXSPH_OK, NULL);
    free(t);
    size_t n_stl;
    double *p_stl = sorted_positions(stl, &n_stl);
    assert_int_equal(n_stl, n_box);
    assert_memory_equal(p_stl, p_box, 3 * n_box * sizeof *p_box);
    remove(path);
    rmdir(dir);

    /* the domain below z_max = 0.04 m: the domain's own box here is the body's */
    t = case_text(WATER, "\"b\": {\"medium\": \"water\", \"z_max\": 0.04}", "", "");
    char *u = strstr(t, "\"domain\"");
    const char dom[] = "\"domain\": {\"x_min\": 0, \"x_max\": 0.1, \"y_min\": 0, \"y_max\": 0.05, \"z_min\": 0, \"z_max\": 0.3},";
    char *rest = strstr(u, "},") + 2;
    char *t2 = malloc(strlen(t) + sizeof dom);
    snprintf(t2, strlen(t) + sizeof dom, "%.*s%s%s", (int)(u - t), t, dom, rest);
    mixsph_sim *level = create(t2, MIXSPH_OK, NULL);
    free(t);
    free(t2);
    size_t n_level;
    double *p_level = sorted_positions(level, &n_level);
    assert_int_equal(n_level, n_box);
    assert_memory_equal(p_level, p_box, 3 * n_box * sizeof *p_box);

    free(p_box), free(p_poly), free(p_stl), free(p_level);
    mixsph_sim_destroy(box), mixsph_sim_destroy(poly), mixsph_sim_destroy(stl), mixsph_sim_destroy(level);
}

/* Two overlapping bodies: a site belongs to the first listing it (as in 2D). */
static void test_overlap_goes_to_first_body(void **state)
{
    (void)state;
    char *t = case_text(WATER "," "\"oil\": {\"type\": \"fluid\", \"rho\": 800.0, \"K\": 6.25e5, \"mu\": 1.0e-3}",
                        "\"a\": {\"medium\": \"water\", \"box_min\": [0, 0, 0], \"box_max\": [0.1, 0.1, 0.05]},"
                        "\"b\": {\"medium\": \"oil\", \"box_min\": [0, 0, 0], \"box_max\": [0.1, 0.1, 0.1]}", "", "");
    mixsph_sim *s = create(t, MIXSPH_OK, NULL);
    free(t);
    mixsph_particles_view v;
    assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
    assert_int_equal(v.n_fluid, 10 * 10 * 10);
    size_t water = 0;
    for (size_t i = 0; i < v.n_fluid; i++) {
        water += v.medium[i] == 0;
        assert_true((v.medium[i] == 0) == (v.pos[2][i] < 0.05));
    }
    assert_int_equal(water, 10 * 10 * 5);
    mixsph_sim_destroy(s);
}

/* The initial pressure of each column is hydrostatic: p = rho0 g (depth of the particle's centre)
 * = rho0 g dx (k + 1/2) for the k-th site from the top (the fill's rule, the same as 2D's). */
static void test_hydrostatic_columns(void **state)
{
    (void)state;
    char *t = case_text(WATER, "\"b\": {\"medium\": \"water\", \"box_min\": [0, 0, 0], \"box_max\": [0.05, 0.03, 0.1]}", "", "");
    mixsph_sim *s = create(t, MIXSPH_OK, NULL);
    free(t);
    mixsph_particles_view v;
    assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
    assert_int_equal(v.n_fluid, 5 * 3 * 10);
    for (size_t i = 0; i < v.n_fluid; i++) {
        const double depth = 0.1 - v.pos[2][i], want = 1000.0 * G * depth;
        /* reference: hydrostatics; tolerance: round-off of the column sums (1e-9 relative) */
        assert_true(fabs(v.p[i] - want) <= 1e-9 * want);
    }
    mixsph_sim_destroy(s);
}

struct centre {
    double x[3], mass;
};

static struct centre centre_of_mass(const mixsph_sim *s)
{
    mixsph_particles_view v;
    assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
    mixsph_particle_field m;
    assert_int_equal(mixsph_sim_particle_field_find(s, "mass", &m), MIXSPH_OK);
    struct centre c = {{0, 0, 0}, 0};
    for (size_t i = 0; i < v.n_fluid; i++) {
        const double mi = ((const double *)m.data[0])[i];
        c.mass += mi;
        for (int d = 0; d < 3; d++) c.x[d] += mi * v.pos[d][i];
    }
    for (int d = 0; d < 3; d++) c.x[d] /= c.mass;
    return c;
}

/* A block of each law (and scheme) falls freely for 0.03 s: finite, no particle lost, and its
 * centre of mass on the free-fall path of the scheme's integrator (the reference at the head of
 * the file), step by step: the leapfrog's z += v dt - g dt^2 / 2 (the exact parabola), the
 * implicit scheme's symplectic Euler v -= g dt, z += v dt (integrate.c), within 1e-9 m; its
 * horizontal place kept within 1e-12 m. The paper's law holds grains fixed (its rule at rest):
 * fixed grains do not fall, so for it the check is the held count and finiteness. */
static void falls_freely(const char *media, const char *numerics, int holds, int symplectic_euler)
{
    char *t = case_text(media, "\"b\": {\"medium\": \"m\", \"box_min\": [0, 0, 0], \"box_max\": [0.08, 0.06, 0.05]}",
                        numerics, "");
    mixsph_sim *s = create(t, MIXSPH_OK, NULL);
    free(t);
    assert_int_equal(mixsph_sim_set_threads(s, 2), MIXSPH_OK);
    const struct centre c0 = centre_of_mass(s);
    double z = c0.x[2], v = 0.0;
    while (mixsph_sim_time(s) < 0.03) {
        const double t0 = mixsph_sim_time(s);
        assert_int_equal(mixsph_sim_step(s), MIXSPH_OK);
        const double dt = mixsph_sim_time(s) - t0;
        if (symplectic_euler) {
            v -= G * dt;
            z += v * dt;
        } else {
            z += v * dt - 0.5 * G * dt * dt;
            v -= G * dt;
        }
    }
    const struct centre c1 = centre_of_mass(s);
    const long lost = mixsph_sim_output_find(s, "lost_particles");
    assert_true(lost >= 0);
    assert_true(mixsph_sim_output_value(s, (size_t)lost) == 0.0);
    if (!holds) {
        if (fabs(c1.x[2] - z) > 1e-9) fprintf(stderr, "%s: z_c %.12g, free fall %.12g\n", media, c1.x[2], z);
        assert_true(fabs(c1.x[2] - z) <= 1e-9);
        assert_true(fabs(c1.x[0] - c0.x[0]) <= 1e-12 && fabs(c1.x[1] - c0.x[1]) <= 1e-12);
    } else {
        const long fixed = mixsph_sim_output_find(s, "fixed_particles");
        assert_true(fixed >= 0 && mixsph_sim_output_value(s, (size_t)fixed) > 0.0);
        assert_true(isfinite(c1.x[2]) && c1.x[2] <= c0.x[2] + 1e-12);
    }
    mixsph_sim_destroy(s);
}

#define FLUID "\"m\": {\"type\": \"fluid\", \"rho\": 1000.0, \"K\": 6.25e5, \"mu\": 1.0e-3, \"alpha_m\": 0.1}"

static void test_fluid_explicit_falls_freely(void **state)
{
    (void)state;
    falls_freely(FLUID, ", \"density_diffusion\": 0.1, \"density_bound\": 0.05", 0, 0);
}

static void test_fluid_implicit_falls_freely(void **state)
{
    (void)state;
    falls_freely("\"m\": {\"type\": \"fluid\", \"rho\": 1000.0, \"K\": 6.25e5, \"mu\": 1.0, \"alpha_m\": 0.1}",
                 ", \"viscosity\": \"implicit\"", 0, 1);
}

static void test_elastic_falls_freely(void **state)
{
    (void)state;
    falls_freely("\"m\": {\"type\": \"elastic\", \"rho\": 2000.0, \"E\": 1.0e7, \"nu\": 0.3, \"alpha_m\": 0.2}", "", 0, 0);
}

static void test_elastic_plastic_falls_freely(void **state)
{
    (void)state;
    falls_freely("\"m\": {\"type\": \"granular\", \"law\": \"elastic_plastic\", \"rho\": 2650.0, \"K\": 4.24e6,"
                 " \"porosity\": 0.35, \"phi\": 35.0, \"nu\": 0.3}", "", 0, 0);
}

static void test_paper_law_holds_grains(void **state)
{
    (void)state;
    falls_freely("\"m\": {\"type\": \"granular\", \"tension_cutoff\": false, \"rho\": 2650.0, \"K\": 4.24e6,"
                 " \"porosity\": 0.35, \"phi\": 35.0, \"mu_thr\": 1000.0, \"mu0\": 100.0}", "", 1, 0);
}

/* Monitors in 3D: a max_elevation over a box region with x and y ranges (the block's top: 0.05 -
 * dx/2 at t = 0; a region beside the block in y sees nothing), a probe at (x, y, z) inside the
 * block reading its hydrostatic pressure (0.025 m deep: rho g 0.025 within the kernel sum's
 * smoothing of the linear profile, 2 %); and the 2D-only monitors refused by name. */
static void test_monitors(void **state)
{
    (void)state;
    char *t = case_text(WATER, "\"b\": {\"medium\": \"water\", \"box_min\": [0, 0, 0], \"box_max\": [0.1, 0.1, 0.05]}", "",
                        ", \"monitors\": {"
                        "\"top\": {\"type\": \"max_elevation\", \"medium\": \"water\", \"x_min\": 0, \"x_max\": 0.1,"
                        " \"y_min\": 0, \"y_max\": 0.1},"
                        "\"beside\": {\"type\": \"max_elevation\", \"medium\": \"water\", \"y_min\": 0.2, \"y_max\": 0.3},"
                        "\"probe\": {\"type\": \"pressure_probe\", \"x\": 0.05, \"y\": 0.05, \"z\": 0.025}}");
    mixsph_sim *s = create(t, MIXSPH_OK, NULL);
    free(t);
    assert_int_equal(mixsph_sim_step(s), MIXSPH_OK);
    const double top = mixsph_sim_output_value(s, (size_t)mixsph_sim_output_find(s, "top"));
    assert_true(fabs(top - 0.045) < 1e-3); /* one step of fall: under 1 mm */
    assert_true(isnan(mixsph_sim_output_value(s, (size_t)mixsph_sim_output_find(s, "beside"))));
    const double p = mixsph_sim_output_value(s, (size_t)mixsph_sim_output_find(s, "probe"));
    assert_true(fabs(p - 1000.0 * G * 0.025) <= 0.02 * 1000.0 * G * 0.025);
    mixsph_sim_destroy(s);

    const char *refused[][2] = {
        {", \"monitors\": {\"p\": {\"type\": \"profile\", \"medium\": \"water\", \"x_min\": 0, \"x_max\": 1, \"times\": [0.01]}}",
         "monitors.p: a profile monitor is 2D only"},
        {", \"monitors\": {\"p\": {\"type\": \"pressure_probe\", \"x\": 0.05, \"z\": 0.02}}", "monitors.p.y: missing"},
        {", \"monitors\": {\"p\": {\"type\": \"max_elevation\", \"medium\": \"water\", \"y_min\": 0.1, \"y_max\": 0}}",
         "expected y_min < y_max"},
    };
    for (size_t k = 0; k < sizeof refused / sizeof refused[0]; k++) {
        t = case_text(WATER, "\"b\": {\"medium\": \"water\", \"box_min\": [0, 0, 0], \"box_max\": [0.1, 0.1, 0.05]}", "",
                      refused[k][0]);
        assert_null(create(t, MIXSPH_ERR_CASE, refused[k][1]));
        free(t);
    }
}

static double output_of(const mixsph_sim *s, const char *name)
{
    const long k = mixsph_sim_output_find(s, name);
    assert_true(k >= 0);
    return mixsph_sim_output_value(s, (size_t)k);
}

/* In 3D (cases/hydrostatic_tank_3d.json: water H = 0.24 m deep at rest in a 0.2 x 0.12 m box
 * tank, dx = 0.02): a sensor on the tank's wall x = 0.2 at (y, z) = (0.06, 0.1) read 1.5 h into
 * the water, and the wall_pressure of the wall's first layer around it (the sites x = 0.21,
 * y = 0.05 and 0.07, z = 0.09). References: hydrostatics. The probe at t = 0 reads rho0 g
 * (H - 0.1) within test_probe_initial_field's tolerance 0.005 rho0 g dx (the point lies on the
 * lattice's symmetry planes in y and z, and the pressure varies along z only). The wall's
 * pressure after one step is the extrapolation p_w = sum_j (p_j + rho_j g (z_j - z_w)) W_wj /
 * sum_j W_wj of the hydrostatic water (docs/model.md [WP]), rho0 g (H - z_w) but for the water's
 * compression rho_j / rho0 - 1 = p_j / K, under 0.4 % here: tolerance 1 % of it. */
static void test_probe_on_a_3d_wall(void **state)
{
    (void)state;
    char err[512], *text = NULL;
    if (case_read_file(MIXSPH_SOURCE_DIR "/cases/hydrostatic_tank_3d.json", &text, err, sizeof err) != MIXSPH_OK)
        fail_msg("%s", err);
    char *json = edit_text(text, "\"monitors\": {\n",
                           "\"monitors\": {\n"
                           "    \"side\": { \"type\": \"pressure_probe\", \"wall\": \"tank\", \"x\": 0.2, \"y\": 0.06, \"z\": 0.1 },\n"
                           "    \"side_wall\": { \"type\": \"wall_pressure\", \"wall\": \"tank\", \"x_min\": 0.19, \"x_max\": 0.23,"
                           " \"y_min\": 0.04, \"y_max\": 0.08, \"z_min\": 0.08, \"z_max\": 0.1 },\n");
    free(text);
    mixsph_sim *s = NULL;
    if (mixsph_sim_create_from_text(json, "tank3d_probes.json", NULL, 0, &s, err, sizeof err) != MIXSPH_OK)
        fail_msg("%s", err);
    free(json);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
    const double H = 0.24, dx = 0.02;
    const double p_probe = output_of(s, "side"), p_probe_ref = 1000.0 * G * (H - 0.1);
    print_message("3D: the wall sensor reads %.3f Pa at t = 0, rho0 g (H - z) = %.3f Pa\n", p_probe, p_probe_ref);
    assert_true(fabs(p_probe - p_probe_ref) <= 0.005 * 1000.0 * G * dx);
    assert_int_equal(mixsph_sim_step(s), MIXSPH_OK);
    const double p_wall = output_of(s, "side_wall"), p_wall_ref = 1000.0 * G * (H - 0.09);
    print_message("3D: the wall's first layer reads %.3f Pa after a step, rho0 g (H - z_w) = %.3f Pa\n", p_wall,
                  p_wall_ref);
    assert_true(fabs(p_wall - p_wall_ref) <= 0.01 * p_wall_ref);
    mixsph_sim_destroy(s);
}

/* Bad 3D input, refused with the key and why. */
static void test_refused_inputs(void **state)
{
    (void)state;
    const char *bodies[][2] = {
        {"\"b\": {\"medium\": \"water\", \"polygon\": [[0, 0], [0.1, 0], [0.1, 0.1]]}", "a 3D polygon body needs y_min < y_max"},
        {"\"b\": {\"medium\": \"water\", \"box_min\": [0, 0, 0]}", "a box needs both box_min and box_max"},
        {"\"b\": {\"medium\": \"water\", \"box_min\": [0, 0], \"box_max\": [1, 1, 1]}", "bodies.b.box_min: expected at least 3"},
        {"\"b\": {\"medium\": \"water\", \"box_min\": [0, 0, 0], \"box_max\": [0.1, 0, 0.1]}", "expected box_min < box_max"},
        {"\"b\": {\"medium\": \"water\", \"stl\": \"no_such_file.stl\"}", "bodies.b.stl"},
        {"\"b\": {\"medium\": \"water\"}", "fills the domain below its z_max"},
        {"\"b\": {\"medium\": \"water\", \"box_min\": [0, 0, 0], \"box_max\": [1, 1, 1], \"stl\": \"a.stl\"}", "expected one shape"},
    };
    for (size_t k = 0; k < sizeof bodies / sizeof bodies[0]; k++) {
        char *t = case_text(WATER, bodies[k][0], "", "");
        assert_null(create(t, MIXSPH_ERR_CASE, bodies[k][1]));
        free(t);
    }
    /* a 2D case reaching the 3D build */
    const char *two = "{\"name\": \"t\", \"numerics\": {\"dx\": 0.01, \"t_end\": 0.1}, \"media\": {" WATER "},"
                      " \"bodies\": {\"b\": {\"medium\": \"water\", \"polygon\": [[0, 0], [1, 0], [1, 1]]}},"
                      " \"walls\": {\"w\": {\"polyline\": [[0, 0], [1, 0]], \"fluid_side\": \"left\"}}}";
    assert_null(create(two, MIXSPH_ERR_CASE, "dimensions: the case is 2D, this build of the library is 3D"));
    /* the domain needs y; two_level is 2D only; polyline walls are not placed in 3D yet */
    char *t = case_text(WATER, "\"b\": {\"medium\": \"water\", \"box_min\": [0, 0, 0], \"box_max\": [0.1, 0.1, 0.1]}",
                        ", \"viscosity\": \"implicit\", \"viscous_preconditioner\": \"two_level\"", "");
    assert_null(create(t, MIXSPH_ERR_CASE, "numerics.viscous_preconditioner: \"two_level\" is 2D only"));
    free(t);
}

/* A state saved at t1 and loaded into a new simulation continues bit for bit (positions and
 * velocities at t2 equal to the last bit), on 2 threads. */
static void test_restart_is_bit_identical(void **state)
{
    (void)state;
    char *t = case_text(WATER, "\"b\": {\"medium\": \"water\", \"box_min\": [0, 0, 0], \"box_max\": [0.08, 0.06, 0.05]}",
                        ", \"density_diffusion\": 0.1", "");
    mixsph_sim *a = create(t, MIXSPH_OK, NULL);
    free(t);
    assert_int_equal(mixsph_sim_set_threads(a, 2), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(a, 0.01), MIXSPH_OK);
    void *buf = NULL;
    size_t len = 0;
    assert_int_equal(mixsph_sim_save_state(a, &buf, &len), MIXSPH_OK);
    mixsph_sim *b = NULL;
    char err[512];
    assert_int_equal(mixsph_sim_create_from_state(buf, len, &b, err, sizeof err), MIXSPH_OK);
    mixsph_state_free(buf);
    assert_int_equal(mixsph_sim_set_threads(b, 1), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(a, 0.02), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(b, 0.02), MIXSPH_OK);
    assert_int_equal(mixsph_sim_steps(a), mixsph_sim_steps(b));
    mixsph_particles_view va, vb;
    assert_int_equal(mixsph_sim_particles_view(a, &va), MIXSPH_OK);
    assert_int_equal(mixsph_sim_particles_view(b, &vb), MIXSPH_OK);
    assert_int_equal(va.n, vb.n);
    for (int d = 0; d < 3; d++) {
        assert_memory_equal(va.pos[d], vb.pos[d], va.n * sizeof(double));
        assert_memory_equal(va.vel[d], vb.vel[d], va.n * sizeof(double));
    }
    mixsph_sim_destroy(a);
    mixsph_sim_destroy(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_body_shapes_fill_the_same_sites),
        cmocka_unit_test(test_overlap_goes_to_first_body),
        cmocka_unit_test(test_hydrostatic_columns),
        cmocka_unit_test(test_fluid_explicit_falls_freely),
        cmocka_unit_test(test_fluid_implicit_falls_freely),
        cmocka_unit_test(test_elastic_falls_freely),
        cmocka_unit_test(test_elastic_plastic_falls_freely),
        cmocka_unit_test(test_paper_law_holds_grains),
        cmocka_unit_test(test_monitors),
        cmocka_unit_test(test_probe_on_a_3d_wall),
        cmocka_unit_test(test_refused_inputs),
        cmocka_unit_test(test_restart_is_bit_identical),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
