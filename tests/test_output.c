/* test_output.c - the HDF5 run file, its XDMF sidecar, checkpoints and restart (output.c):
 * every particle field is in run.h5 with its shape, type and units, in id order and equal to
 * the simulation's particles; an unwritable output folder or run file is an error of
 * set_output_dir (before any step); a run continued from a checkpoint in the folder of the
 * interrupted run ends bit for bit like an uninterrupted one (final state, every snapshot of
 * run.h5, monitors.csv), one thread. Case: the water dam break at dx = 0.02 (706 particles with
 * the walls), t_end shortened to 0.2 s; runs of at most 0.12 s. */
#include <hdf5.h>
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

#define DAMBREAK MIXSPH_SOURCE_DIR "/cases/dambreak_water.json"

static mixsph_sim *make(double dx)
{
    const mixsph_override ov[2] = {{"numerics.dx", dx}, {"numerics.t_end", 0.2}};
    mixsph_sim *s = NULL;
    char err[512];
    const mixsph_status st = mixsph_sim_create(DAMBREAK, ov, 2, &s, err, sizeof err);
    if (st != MIXSPH_OK) fprintf(stderr, "%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
    return s;
}

/* A fresh folder under the system's temporary folder. */
static void temp_dir(char *buf, size_t n)
{
    const char *base = getenv("TMPDIR");
    snprintf(buf, n, "%s/mixsph_test_output_XXXXXX", base && *base ? base : "/tmp");
    assert_non_null(mkdtemp(buf));
}

static void remove_tree(const char *dir)
{
    char cmd[700];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

static char *read_text(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    const long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *t = malloc((size_t)n + 1);
    assert_non_null(t);
    assert_int_equal(fread(t, 1, (size_t)n, f), (size_t)n);
    t[n] = '\0';
    fclose(f);
    *len = (size_t)n;
    return t;
}

static void check_units(hid_t d, const char *want)
{
    const hid_t a = H5Aopen(d, "units", H5P_DEFAULT);
    assert_true(a >= 0);
    const hid_t t = H5Tcopy(H5T_C_S1);
    H5Tset_size(t, H5T_VARIABLE);
    H5Tset_cset(t, H5T_CSET_UTF8);
    char *v = NULL;
    assert_true(H5Aread(a, t, &v) >= 0);
    assert_string_equal(v, want);
    H5free_memory(v);
    H5Tclose(t);
    H5Aclose(a);
}

/* Read dataset `name` of group g: check its shape (n or n x m) and its class and size, return
 * its bytes (native type of the same size). */
static void *read_dataset(hid_t g, const char *name, size_t n, size_t m, H5T_class_t cls, size_t size, const char *units)
{
    const hid_t d = H5Dopen2(g, name, H5P_DEFAULT);
    assert_true(d >= 0);
    const hid_t sp = H5Dget_space(d);
    hsize_t dims[2] = {0, 0};
    const int rank = H5Sget_simple_extent_ndims(sp);
    assert_int_equal(rank, m ? 2 : 1);
    H5Sget_simple_extent_dims(sp, dims, NULL);
    assert_int_equal(dims[0], n);
    if (m) assert_int_equal(dims[1], m);
    const hid_t ft = H5Dget_type(d);
    assert_int_equal(H5Tget_class(ft), cls);
    assert_int_equal(H5Tget_size(ft), size);
    const hid_t mt = H5Tget_native_type(ft, H5T_DIR_ASCEND);
    void *buf = malloc(n * (m ? m : 1) * size);
    assert_non_null(buf);
    assert_true(H5Dread(d, mt, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0);
    check_units(d, units);
    H5Tclose(mt);
    H5Tclose(ft);
    H5Sclose(sp);
    H5Dclose(d);
    return buf;
}

static long long read_attr_ll(hid_t obj, const char *name)
{
    long long v = -1;
    const hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    assert_true(a >= 0);
    assert_true(H5Aread(a, H5T_NATIVE_LLONG, &v) >= 0);
    H5Aclose(a);
    return v;
}

/* run.h5 holds every field of every snapshot; the last one equals the particles, row = id. */
static void test_run_file_fields(void **state)
{
    (void)state;
    char dir[512], path[600];
    temp_dir(dir, sizeof dir);
    mixsph_sim *s = make(0.02);
    assert_int_equal(mixsph_sim_set_output_dir(s, dir), MIXSPH_OK);
    /* snapshots at 0, 0.05, 0.10: the last one at the step that reaches 0.10, where this stops */
    assert_int_equal(mixsph_sim_advance_to(s, 0.10), MIXSPH_OK);
    mixsph_particles_view v;
    mixsph_sim_particles_view(s, &v);
    const size_t n = v.n;
    /* the file is readable while the simulation still holds it open (flushed per snapshot); in
     * the same process HDF5 wants the same file-locking setting as the writer's (none) */
    snprintf(path, sizeof path, "%s/run.h5", dir);
    const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
#if H5_VERSION_GE(1, 10, 7)
    H5Pset_file_locking(fapl, 0, 1);
#endif
    const hid_t f = H5Fopen(path, H5F_ACC_RDONLY, fapl);
    H5Pclose(fapl);
    assert_true(f >= 0);
    assert_int_equal(read_attr_ll(f, "n_snapshots"), 3);
    const char *groups[3] = {"/snapshots/000000", "/snapshots/000001", "/snapshots/000002"};
    for (int k = 0; k < 3; k++) {
        const hid_t g = H5Gopen2(f, groups[k], H5P_DEFAULT);
        assert_true(g >= 0);
        assert_int_equal(read_attr_ll(g, "index"), k);
        assert_int_equal(read_attr_ll(g, "n"), (long long)n);
        double *pos = read_dataset(g, "position", n, 2, H5T_FLOAT, 8, "m");
        double *vel = read_dataset(g, "velocity", n, 2, H5T_FLOAT, 8, "m/s");
        double *rho = read_dataset(g, "density", n, 0, H5T_FLOAT, 8, "kg/m^3");
        double *p = read_dataset(g, "pressure", n, 0, H5T_FLOAT, 8, "Pa");
        double *mu = read_dataset(g, "viscosity", n, 0, H5T_FLOAT, 8, "Pa s");
        double *mass = read_dataset(g, "mass", n, 0, H5T_FLOAT, 8, "kg");
        uint8_t *medium = read_dataset(g, "medium", n, 0, H5T_INTEGER, 1, "1");
        uint8_t *st = read_dataset(g, "state", n, 0, H5T_INTEGER, 1, "1");
        uint32_t *id = read_dataset(g, "id", n, 0, H5T_INTEGER, 4, "1");
        for (size_t r = 0; r < n; r++) assert_int_equal(id[r], r); /* row = id */
        if (k == 2) { /* the current state: every value equal to the particles' */
            double t_snap = -1.0;
            const hid_t a = H5Aopen(g, "time", H5P_DEFAULT);
            assert_true(a >= 0 && H5Aread(a, H5T_NATIVE_DOUBLE, &t_snap) >= 0);
            H5Aclose(a);
            assert_true(t_snap == mixsph_sim_time(s));
            for (size_t i = 0; i < n; i++) {
                const size_t r = v.id[i];
                assert_memory_equal(&pos[2 * r], &v.pos[0][i], sizeof(double));
                assert_memory_equal(&pos[2 * r + 1], &v.pos[v.dim - 1][i], sizeof(double));
                assert_memory_equal(&vel[2 * r], &v.vel[0][i], sizeof(double));
                assert_memory_equal(&vel[2 * r + 1], &v.vel[v.dim - 1][i], sizeof(double));
                assert_memory_equal(&rho[r], &v.rho[i], sizeof(double));
                assert_memory_equal(&p[r], &v.p[i], sizeof(double));
                assert_memory_equal(&mu[r], &v.mu[i], sizeof(double));
                assert_int_equal(medium[r], v.medium[i]);
                assert_int_equal(st[r], v.state[i]);
                assert_true(mass[r] > 0.0);
            }
        }
        free(pos), free(vel), free(rho), free(p), free(mu), free(mass), free(medium), free(st), free(id);
        H5Gclose(g);
    }
    H5Fclose(f);
    /* the sidecar names the three snapshots */
    size_t len;
    snprintf(path, sizeof path, "%s/run.xdmf", dir);
    char *x = read_text(path, &len);
    assert_non_null(strstr(x, "CollectionType=\"Temporal\""));
    assert_non_null(strstr(x, "run.h5:/snapshots/000002/position"));
    assert_null(strstr(x, "/snapshots/000003/"));
    free(x);
    mixsph_sim_destroy(s);
    remove_tree(dir);
}

/* Unwritable places fail at set_output_dir (before any step) with a message naming them. */
static void test_unwritable_output(void **state)
{
    (void)state;
    mixsph_sim *s = make(0.02);
    /* a folder below a regular file: cannot be created */
    assert_int_equal(mixsph_sim_set_output_dir(s, "/dev/null/mixsph_out"), MIXSPH_ERR_IO);
    assert_non_null(strstr(mixsph_sim_last_error(s), "/dev/null/mixsph_out"));
    /* the run file cannot be created (a folder is in its way): the message names it */
    char dir[512], path[600];
    temp_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/run.h5", dir);
    assert_int_equal(mkdir(path, 0777), 0);
    assert_int_equal(mixsph_sim_set_output_dir(s, dir), MIXSPH_ERR_IO);
    assert_non_null(strstr(mixsph_sim_last_error(s), "run.h5"));
    assert_non_null(strstr(mixsph_sim_last_error(s), "HDF5"));
    assert_int_equal(mixsph_sim_steps(s), 0);
    /* stepping afterwards writes nothing there and works */
    assert_int_equal(mixsph_sim_step(s), MIXSPH_OK);
    /* a checkpoint in an impossible place */
    assert_int_equal(mixsph_sim_write_checkpoint(s, "/dev/null/x/checkpoint.h5"), MIXSPH_ERR_IO);
    assert_non_null(strstr(mixsph_sim_last_error(s), "checkpoint"));
    /* a file that is not a checkpoint */
    mixsph_sim *r = NULL;
    char err[512];
    assert_int_equal(mixsph_sim_create_from_checkpoint(DAMBREAK, &r, err, sizeof err), MIXSPH_ERR_ARG);
    assert_null(r);
    assert_non_null(strstr(err, "dambreak_water.json"));
    mixsph_sim_destroy(s);
    remove_tree(dir);
}

static void same_state(const mixsph_sim *a, const mixsph_sim *b)
{
    assert_true(mixsph_sim_time(a) == mixsph_sim_time(b));
    assert_int_equal(mixsph_sim_steps(a), mixsph_sim_steps(b));
    mixsph_particles_view u, v;
    mixsph_sim_particles_view(a, &u);
    mixsph_sim_particles_view(b, &v);
    assert_int_equal(u.n, v.n);
    const double *fu[7] = {u.pos[0], u.pos[u.dim - 1], u.vel[0], u.vel[u.dim - 1], u.rho, u.p, u.mu}, *fv[7] = {v.pos[0], v.pos[v.dim - 1], v.vel[0], v.vel[v.dim - 1], v.rho, v.p, v.mu};
    for (int k = 0; k < 7; k++) assert_memory_equal(fu[k], fv[k], u.n * sizeof(double));
    assert_memory_equal(u.id, v.id, u.n * sizeof(uint32_t));
    assert_memory_equal(u.state, v.state, u.n);
}

/* Every snapshot dataset of two run files, byte for byte. */
static void same_snapshots(const char *pa, const char *pb, int n_snap)
{
    const hid_t fa = H5Fopen(pa, H5F_ACC_RDONLY, H5P_DEFAULT), fb = H5Fopen(pb, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(fa >= 0 && fb >= 0);
    assert_int_equal(read_attr_ll(fa, "n_snapshots"), n_snap);
    assert_int_equal(read_attr_ll(fb, "n_snapshots"), n_snap);
    static const char *const fields[] = {"position", "velocity", "density", "pressure", "viscosity", "mass", "medium", "state", "id"};
    for (int k = 0; k < n_snap; k++) {
        char name[64];
        for (size_t j = 0; j < sizeof fields / sizeof *fields; j++) {
            snprintf(name, sizeof name, "/snapshots/%06d/%s", k, fields[j]);
            const hid_t da = H5Dopen2(fa, name, H5P_DEFAULT), db = H5Dopen2(fb, name, H5P_DEFAULT);
            assert_true(da >= 0 && db >= 0);
            const hsize_t sa = H5Dget_storage_size(da), sb = H5Dget_storage_size(db);
            assert_int_equal(sa, sb);
            unsigned char *ba = malloc(sa), *bb = malloc(sb);
            const hid_t ta = H5Dget_type(da);
            assert_true(H5Dread(da, ta, H5S_ALL, H5S_ALL, H5P_DEFAULT, ba) >= 0);
            assert_true(H5Dread(db, ta, H5S_ALL, H5S_ALL, H5P_DEFAULT, bb) >= 0);
            assert_memory_equal(ba, bb, sa);
            free(ba), free(bb);
            H5Tclose(ta);
            H5Dclose(da), H5Dclose(db);
        }
    }
    H5Fclose(fa), H5Fclose(fb);
}

/* Uninterrupted run A to 0.12 s; run B writes a checkpoint at 0.03 s, goes on to 0.08 s (one
 * more snapshot and more monitor rows) and dies; C restarts from the checkpoint in B's folder
 * and ends at 0.12 s: C's state, B's run.h5, run.xdmf and monitors.csv equal A's bit for bit. */
static void test_restart_equals_uninterrupted(void **state)
{
    (void)state;
    char da[512], db[512], ck[600], pa[600], pb[600];
    temp_dir(da, sizeof da);
    temp_dir(db, sizeof db);
    mixsph_sim *a = make(0.02), *b = make(0.02);
    assert_int_equal(mixsph_sim_set_output_dir(a, da), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(a, 0.12), MIXSPH_OK);

    assert_int_equal(mixsph_sim_set_output_dir(b, db), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(b, 0.03), MIXSPH_OK);
    snprintf(ck, sizeof ck, "%s/checkpoint.h5", db);
    const double wall_ck = mixsph_sim_run_wall_time(b); /* B's stepping time up to its checkpoint */
    assert_true(wall_ck > 0.0);
    assert_int_equal(mixsph_sim_write_checkpoint(b, ck), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(b, 0.08), MIXSPH_OK);
    mixsph_sim_destroy(b); /* the "crash": later snapshots and rows are in its files */

    mixsph_sim *c = NULL;
    char err[512];
    assert_int_equal(mixsph_sim_create_from_checkpoint(ck, &c, err, sizeof err), MIXSPH_OK);
    assert_true(mixsph_sim_time(c) >= 0.03 && mixsph_sim_time(c) < 0.031);
    /* the run's wall time carries over the restart: B's up to the checkpoint (not the work B
     * redid after it), then C's own on top */
    assert_true(mixsph_sim_run_wall_time(c) == wall_ck);
    assert_int_equal(mixsph_sim_set_threads(c, 1), MIXSPH_OK);
    assert_int_equal(mixsph_sim_resume_output_dir(c, db), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(c, 0.12), MIXSPH_OK);
    assert_true(mixsph_sim_run_wall_time(c) > wall_ck);
    same_state(a, c);
    mixsph_sim_destroy(a);
    mixsph_sim_destroy(c);

    snprintf(pa, sizeof pa, "%s/run.h5", da);
    snprintf(pb, sizeof pb, "%s/run.h5", db);
    same_snapshots(pa, pb, 3); /* t = 0, 0.05, 0.1 */
    size_t la, lb;
    snprintf(pa, sizeof pa, "%s/monitors.csv", da);
    snprintf(pb, sizeof pb, "%s/monitors.csv", db);
    char *ta = read_text(pa, &la), *tb = read_text(pb, &lb);
    assert_int_equal(la, lb);
    assert_memory_equal(ta, tb, la);
    free(ta), free(tb);
    snprintf(pa, sizeof pa, "%s/run.xdmf", da);
    snprintf(pb, sizeof pb, "%s/run.xdmf", db);
    ta = read_text(pa, &la), tb = read_text(pb, &lb);
    assert_string_equal(ta, tb);
    free(ta), free(tb);
    remove_tree(da);
    remove_tree(db);
}

/* A run file of another case (here: another dx) is not continued. */
static void test_resume_refuses_other_run(void **state)
{
    (void)state;
    char dir[512], ck[600];
    temp_dir(dir, sizeof dir);
    mixsph_sim *s = make(0.025);
    assert_int_equal(mixsph_sim_set_output_dir(s, dir), MIXSPH_OK);
    mixsph_sim_destroy(s);
    s = make(0.02);
    assert_int_equal(mixsph_sim_advance_to(s, 0.01), MIXSPH_OK);
    snprintf(ck, sizeof ck, "%s/ck.h5", dir);
    assert_int_equal(mixsph_sim_write_checkpoint(s, ck), MIXSPH_OK);
    mixsph_sim_destroy(s);
    char err[512];
    assert_int_equal(mixsph_sim_create_from_checkpoint(ck, &s, err, sizeof err), MIXSPH_OK);
    assert_int_equal(mixsph_sim_resume_output_dir(s, dir), MIXSPH_ERR_ARG);
    assert_non_null(strstr(mixsph_sim_last_error(s), "another case"));
    mixsph_sim_destroy(s);
    remove_tree(dir);
}

/* A simulation sent back by mixsph_sim_load_state rewrites its snapshots (same indices) without
 * error, and run.h5 then holds those of the new trajectory. */
static void test_load_state_rewrites_snapshots(void **state)
{
    (void)state;
    char dir[512], path[600];
    temp_dir(dir, sizeof dir);
    mixsph_sim *s = make(0.02);
    assert_int_equal(mixsph_sim_set_output_dir(s, dir), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(s, 0.03), MIXSPH_OK); /* snapshot 0 */
    void *buf = NULL;
    size_t len = 0;
    assert_int_equal(mixsph_sim_save_state(s, &buf, &len), MIXSPH_OK);
    assert_int_equal(mixsph_sim_advance_to(s, 0.10), MIXSPH_OK); /* snapshots 1, 2 */
    assert_int_equal(mixsph_sim_load_state(s, buf, len), MIXSPH_OK);
    mixsph_state_free(buf);
    assert_int_equal(mixsph_sim_advance_to(s, 0.05), MIXSPH_OK); /* snapshot 1 again */
    mixsph_particles_view v;
    mixsph_sim_particles_view(s, &v);
    const size_t n = v.n;
    snprintf(path, sizeof path, "%s/run.h5", dir);
    const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
#if H5_VERSION_GE(1, 10, 7)
    H5Pset_file_locking(fapl, 0, 1);
#endif
    const hid_t f = H5Fopen(path, H5F_ACC_RDONLY, fapl);
    H5Pclose(fapl);
    assert_true(f >= 0);
    assert_int_equal(read_attr_ll(f, "n_snapshots"), 2);
    const hid_t g = H5Gopen2(f, "/snapshots/000001", H5P_DEFAULT);
    double *pos = read_dataset(g, "position", n, 2, H5T_FLOAT, 8, "m");
    for (size_t i = 0; i < n; i++) assert_memory_equal(&pos[2 * v.id[i]], &v.pos[0][i], sizeof(double));
    free(pos);
    H5Gclose(g);
    H5Fclose(f);
    size_t xl;
    snprintf(path, sizeof path, "%s/run.xdmf", dir);
    char *x = read_text(path, &xl);
    assert_non_null(strstr(x, "/snapshots/000001/"));
    assert_null(strstr(x, "/snapshots/000002/"));
    free(x);
    mixsph_sim_destroy(s);
    remove_tree(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_run_file_fields),
        cmocka_unit_test(test_unwritable_output),
        cmocka_unit_test(test_restart_equals_uninterrupted),
        cmocka_unit_test(test_resume_refuses_other_run),
        cmocka_unit_test(test_load_state_rewrites_snapshots),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
