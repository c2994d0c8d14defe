/* test_particle_fields.c - the particle-field table (core/particle_fields.c) and what walks it:
 * every array of struct particles has exactly one row with consistent names; a row absent from
 * a simulation's features has no memory and no place in its state, and particles.c allocates,
 * pushes, permutes and copies exactly the present rows; the public field view shows the rows
 * marked for it with the arrays of the particles view; a state whose field list differs from
 * the build's is refused naming the field. (The files - run.h5, run.xdmf, snap_NNNN.csv - are
 * checked against the build before the table in tests/python/test_hdf5.py and by comparing runs,
 * see docs/development.md.) */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "mixsph.h"
#include "particle_fields.h"
#include "particles.h"
#include "sim.h"

#define DAMBREAK MIXSPH_SOURCE_DIR "/cases/dambreak_water.json"

static void test_every_member_has_one_row(void **state)
{
    (void)state;
    /* the arrays are the members from pos to the end of the struct (particles.h): their number,
     * and each one's offset at most once among the rows */
    const size_t first = offsetof(struct particles, pos), n_arrays = (sizeof(struct particles) - first) / sizeof(void *);
    assert_int_equal((sizeof(struct particles) - first) % sizeof(void *), 0);
    size_t seen = 0;
    unsigned char *hit = calloc(n_arrays, 1);
    for (size_t k = 0; k < particle_field_count; k++) {
        const struct particle_field *f = &particle_fields[k];
        assert_true(f->components >= 1 && f->components <= PARTICLE_FIELD_MAX_COMPONENTS);
        for (unsigned c = 0; c < f->components; c++) {
            const size_t at = f->member[c];
            assert_true(at >= first && (at - first) % sizeof(void *) == 0);
            const size_t slot = (at - first) / sizeof(void *);
            assert_true(slot < n_arrays);
            if (slot < n_arrays) assert_int_equal(hit[slot]++, 0);
            seen++;
        }
    }
    assert_int_equal(seen, n_arrays);
    free(hit);
}

static void test_rows_are_consistent(void **state)
{
    (void)state;
    size_t geometry = 0, keys = 0;
    for (size_t k = 0; k < particle_field_count; k++) {
        const struct particle_field *f = &particle_fields[k];
        assert_non_null(f->name);
        assert_non_null(f->unit);
        assert_non_null(f->description);
        /* one column name per component, none empty */
        char col[64];
        for (unsigned c = 0; c < f->components; c++) assert_true(particle_field_column(f, c, col, sizeof col)[0] != '\0');
        assert_string_equal(particle_field_column(f, f->components, col, sizeof col), "");
        if ((f->where & PF_CSV) && f->type == PF_F64) assert_true(f->csv_digits >= 6 && f->csv_digits <= 17);
        if (f->where & PF_GEOMETRY) {
            geometry++;
            assert_true(f->components == 2 && f->type == PF_F64 && (f->where & PF_HDF5));
        }
        if (f->where & PF_KEY) keys++;
        /* names unique; columns unique among the CSV rows */
        for (size_t j = 0; j < k; j++) {
            const struct particle_field *g = &particle_fields[j];
            assert_true(strcmp(f->name, g->name) != 0);
            if (!(f->where & g->where & PF_CSV)) continue;
            char a[64], b[64];
            for (unsigned c = 0; c < f->components; c++)
                for (unsigned d = 0; d < g->components; d++)
                    assert_true(strcmp(particle_field_column(f, c, a, sizeof a), particle_field_column(g, d, b, sizeof b)) != 0);
        }
    }
    assert_int_equal(geometry, 1);
    assert_int_equal(keys, 1);
}

/* The rows needing a feature: their arrays exist exactly when the particles have it, and the
 * present rows are pushed (zeroed), permuted and copied. */
static void test_absent_rows_have_no_memory(void **state)
{
    (void)state;
    unsigned all = 0; /* every feature a row needs */
    for (size_t k = 0; k < particle_field_count; k++) all |= particle_fields[k].needs;
    const unsigned cases[] = {0u, PARTICLE_FEATURE_IMPLICIT_VISCOUS, all};
    for (size_t t = 0; t < sizeof cases / sizeof cases[0]; t++) {
        const unsigned features = cases[t];
        struct particles P;
        memset(&P, 0, sizeof P);
        P.features = features;
        assert_int_equal(particles_alloc(&P, 4), 0);
        size_t absent = 0;
        for (size_t k = 0; k < particle_field_count; k++) {
            const struct particle_field *f = &particle_fields[k];
            for (unsigned c = 0; c < f->components; c++) {
                const void *a = particles_array(&P, f->member[c]);
                if (particle_field_present(f, features)) assert_non_null(a);
                else {
                    assert_null(a);
                    absent++;
                }
            }
        }
        if (features == all) assert_int_equal(absent, 0);
        if (features == 0) assert_true(absent > 0); /* the implicit scheme's increments at least */
        for (size_t i = 0; i < 40; i++) /* past cap: the arrays grow */
            assert_int_equal(particles_push(&P, (const double[DIM]){(double)i, -(double)i}, 1000.0, 1.0, (uint8_t)(i % 3), 0), i);
        const int implicit = (features & PARTICLE_FEATURE_IMPLICIT_VISCOUS) != 0;
        if (implicit) {
            for (size_t i = 0; i < 40; i++) assert_true(P.visc_dv[0][i] == 0.0);
            for (size_t i = 0; i < 40; i++) P.visc_dv[0][i] = 0.5 * (double)i;
        }
        size_t perm[40];
        for (size_t k = 0; k < 40; k++) perm[k] = 39 - k;
        double scratch[40];
        particles_permute(&P, perm, scratch);
        struct particles Q;
        assert_int_equal(particles_copy(&Q, &P), 0);
        for (size_t k = 0; k < 40; k++) {
            const size_t i = 39 - k;
            assert_true(Q.pos[0][k] == (double)i && Q.pos[DIM_UP][k] == -(double)i && Q.id[k] == i && Q.medium[k] == i % 3);
            if (implicit) assert_true(Q.visc_dv[0][k] == 0.5 * (double)i);
        }
        assert_true(implicit ? Q.visc_dv[0] != NULL : Q.visc_dv[0] == NULL);
        particles_free(&Q);
        particles_free(&P);
    }
}

/* The dam break at dx = 0.05 m, explicit, or with its numerics made implicit. */
static mixsph_sim *make(int implicit)
{
    char *text = NULL, err[512];
    assert_int_equal(case_read_file(DAMBREAK, &text, err, sizeof err), MIXSPH_OK);
    if (implicit) {
        char *at = strchr(strstr(text, "\"numerics\""), '{') + 1;
        const char *add = " \"viscosity\": \"implicit\",";
        char *t = malloc(strlen(text) + strlen(add) + 1);
        sprintf(t, "%.*s%s%s", (int)(at - text), text, add, at);
        free(text);
        text = t;
    }
    const mixsph_override ov = {"numerics.dx", 0.05};
    mixsph_sim *s = NULL;
    const mixsph_status st = mixsph_sim_create_from_text(text, "dambreak.json", &ov, 1, &s, err, sizeof err);
    if (st != MIXSPH_OK) fprintf(stderr, "%s\n", err);
    assert_int_equal(st, MIXSPH_OK);
    free(text);
    assert_int_equal(mixsph_sim_set_threads(s, 1), MIXSPH_OK);
    return s;
}

static void test_view_shows_the_view_rows(void **state)
{
    (void)state;
    mixsph_sim *s = make(0);
    assert_int_equal(mixsph_sim_step(s), MIXSPH_OK);
    size_t rows = 0;
    for (size_t k = 0; k < particle_field_count; k++)
        rows += (particle_fields[k].where & PF_VIEW) && particle_field_present(&particle_fields[k], s->phys.P.features);
    assert_int_equal(mixsph_sim_particle_field_count(s), rows);
    mixsph_particles_view v;
    assert_int_equal(mixsph_sim_particles_view(s, &v), MIXSPH_OK);
    mixsph_particle_field f;
    assert_int_equal(mixsph_sim_particle_field_find(s, "velocity", &f), MIXSPH_OK);
    assert_true(f.components == 2 && f.type == MIXSPH_FIELD_F64 && f.n == v.n);
    assert_ptr_equal(f.data[0], v.vel[0]);
    assert_ptr_equal(f.data[1], v.vel[v.dim - 1]);
    assert_string_equal(f.columns, "vx,vz");
    assert_string_equal(f.unit, "m/s");
    assert_int_equal(mixsph_sim_particle_field_find(s, "id", &f), MIXSPH_OK);
    assert_true(f.type == MIXSPH_FIELD_U32 && f.data[0] == (const void *)v.id);
    assert_int_equal(mixsph_sim_particle_field_find(s, "state", &f), MIXSPH_OK);
    assert_true(f.type == MIXSPH_FIELD_U8 && f.data[0] == (const void *)v.state);
    assert_int_equal(mixsph_sim_particle_field_find(s, "viscosity", &f), MIXSPH_OK);
    assert_string_equal(f.owner, "law");
    /* by index, in table order; past the end, or a field not in the view: refused */
    assert_int_equal(mixsph_sim_particle_field(s, 0, &f), MIXSPH_OK);
    assert_string_equal(f.name, "position");
    assert_ptr_equal(f.data[0], v.pos[0]);
    assert_int_equal(mixsph_sim_particle_field(s, rows, &f), MIXSPH_ERR_ARG);
    assert_int_equal(mixsph_sim_particle_field_find(s, "acceleration", &f), MIXSPH_ERR_ARG);
    assert_int_equal(mixsph_sim_particle_field_find(s, "nonsense", &f), MIXSPH_ERR_ARG);
    assert_int_equal(mixsph_sim_particle_field_count(NULL), 0);
    mixsph_sim_destroy(s);
}

static uint64_t fnv1a(const unsigned char *p, size_t n)
{
    uint64_t h = 1469598103934665603ull;
    for (size_t k = 0; k < n; k++) {
        h ^= p[k];
        h *= 1099511628211ull;
    }
    return h;
}

/* Whether a state buffer holds the length-prefixed name (count: 0 or 1). */
static int state_names(const void *buf, size_t len, const char *name)
{
    const unsigned char *p = buf;
    const uint64_t n = strlen(name);
    int hits = 0;
    for (size_t k = 0; k + 8 + n <= len; k++)
        if (memcmp(p + k, &n, 8) == 0 && memcmp(p + k + 8, name, n) == 0) hits++;
    return hits;
}

/* The state holds the present rows only (an explicit run: no implicit increments), named: one
 * renamed (checksum made good again) is refused naming it, the simulation unchanged. */
static void test_state_holds_the_present_rows_by_name(void **state)
{
    (void)state;
    mixsph_sim *e = make(0), *i = make(1);
    assert_null(e->phys.P.visc_dv[0]);
    assert_non_null(i->phys.P.visc_dv[0]);
    assert_int_equal(mixsph_sim_step(e), MIXSPH_OK);
    assert_int_equal(mixsph_sim_step(i), MIXSPH_OK);
    void *be, *bi;
    size_t le, li;
    assert_int_equal(mixsph_sim_save_state(e, &be, &le), MIXSPH_OK);
    assert_int_equal(mixsph_sim_save_state(i, &bi, &li), MIXSPH_OK);
    /* each row the simulation has is in its state (as its name: length, then text) */
    for (size_t k = 0; k < particle_field_count; k++) {
        const struct particle_field *f = &particle_fields[k];
        if (!(f->where & PF_STATE)) continue;
        assert_int_equal(state_names(be, le, f->name), particle_field_present(f, e->phys.P.features));
        assert_int_equal(state_names(bi, li, f->name), particle_field_present(f, i->phys.P.features));
        if (f->needs == PARTICLE_FEATURE_IMPLICIT_VISCOUS) /* the implicit scheme's: only there */
            assert_true(state_names(bi, li, f->name) == 1 && state_names(be, le, f->name) == 0);
    }
    /* rename "density" (its name in the state: length, then the text) */
    unsigned char *p = be, *hit = NULL;
    for (size_t k = 8; k + 7 < le && !hit; k++)
        if (memcmp(p + k, "density", 7) == 0 && p[k - 8] == 7) hit = p + k;
    assert_non_null(hit);
    hit[6] = 'X';
    const uint64_t sum = fnv1a(p, le - 8);
    memcpy(p + le - 8, &sum, 8);
    const double t = mixsph_sim_time(e);
    assert_int_equal(mixsph_sim_load_state(e, be, le), MIXSPH_ERR_ARG);
    assert_non_null(strstr(mixsph_sim_last_error(e), "'densitX'"));
    assert_non_null(strstr(mixsph_sim_last_error(e), "'density'"));
    assert_true(mixsph_sim_time(e) == t);
    assert_int_equal(mixsph_sim_step(e), MIXSPH_OK);
    mixsph_state_free(be);
    mixsph_state_free(bi);
    mixsph_sim_destroy(e);
    mixsph_sim_destroy(i);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_member_has_one_row),
        cmocka_unit_test(test_rows_are_consistent),
        cmocka_unit_test(test_absent_rows_have_no_memory),
        cmocka_unit_test(test_view_shows_the_view_rows),
        cmocka_unit_test(test_state_holds_the_present_rows_by_name),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
