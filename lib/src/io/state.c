/* state.c - save and restore the complete state of a simulation (FMU get/set/serialise state,
 * checkpoint and restart). Public API of mixsph.h.
 *
 * Layout (native byte order, checked by a marker): a header "MIXSPHST", format version, byte
 * order marker, the dimension of the build (DIM); the case text, origin and overrides the simulation was created from; the
 * scalar state (time, step, time step, counters, output extremes and schedule); the walls'
 * displacement, velocity, external drive and work; the particle fields the particle-field table marks
 * PF_STATE and the simulation has, in table order, each as its name, component count, element
 * size and component arrays (a state of a build with other fields is refused naming the first
 * that differs); the neighbour lists' build positions; a 64-bit FNV-1a checksum of
 * all preceding bytes. Derived data (cell list, kernel, media constants) is rebuilt from the case
 * on load, so a restored simulation continues exactly as the saved one would have. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "integrate.h"
#include "particle_fields.h"
#include "sim_object.h"
#include "state.h"
#include "status.h"

#define STATE_MAGIC "MIXSPHST"
#define STATE_VERSION 9u /* 2: neighbour build positions (Verlet ranges); 3: implicit viscous increments;
                            4: the increments of the implicit step's first stage; 5: those of the
                            step before (the warm starts' extrapolation); 6: the particle fields of
                            the particle-field table, each named; 7: the walls' work; 8: the
                            excluded particles' count, mass and energy; 9: the dimension in the
                            header, the stress one field of SYM_N components */
#define STATE_ORDER 0x01020304u

/* ---- writer ------------------------------------------------------------------------------- */

struct writer {
    unsigned char *buf;
    size_t len, cap;
    int bad;
};

static void put(struct writer *w, const void *data, size_t n)
{
    if (w->bad || n == 0) return;
    if (w->len + n > w->cap) {
        size_t cap = w->cap ? w->cap : 4096;
        while (cap < w->len + n) cap *= 2;
        unsigned char *q = realloc(w->buf, cap);
        if (!q) {
            w->bad = 1;
            return;
        }
        w->buf = q;
        w->cap = cap;
    }
    memcpy(w->buf + w->len, data, n);
    w->len += n;
}

static void put_u64(struct writer *w, uint64_t v) { put(w, &v, sizeof v); }
static void put_f64(struct writer *w, double v) { put(w, &v, sizeof v); }

static void put_str(struct writer *w, const char *t)
{
    const size_t n = t ? strlen(t) : 0;
    put_u64(w, n);
    put(w, t, n);
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

/* ---- reader ------------------------------------------------------------------------------- */

struct reader {
    const unsigned char *buf;
    size_t len, pos;
    int bad;
};

static void get(struct reader *r, void *data, size_t n)
{
    if (r->bad || n > r->len - r->pos) {
        r->bad = 1;
        if (data && n) memset(data, 0, n);
        return;
    }
    if (n) memcpy(data, r->buf + r->pos, n);
    r->pos += n;
}

static uint64_t get_u64(struct reader *r)
{
    uint64_t v;
    get(r, &v, sizeof v);
    return v;
}

static double get_f64(struct reader *r)
{
    double v;
    get(r, &v, sizeof v);
    return v;
}

/* A string in place (not NUL-terminated): its start and length. */
static const char *get_str(struct reader *r, size_t *n)
{
    const uint64_t len = get_u64(r);
    if (r->bad || len > r->len - r->pos) {
        r->bad = 1;
        *n = 0;
        return "";
    }
    const char *t = (const char *)r->buf + r->pos;
    r->pos += (size_t)len;
    *n = (size_t)len;
    return t;
}

int state_dimension(const void *buf, size_t len)
{
    uint32_t head[3];
    if (!buf || len < 8 + sizeof head || memcmp(buf, STATE_MAGIC, 8) != 0) return 0;
    memcpy(head, (const unsigned char *)buf + 8, sizeof head);
    return head[1] == STATE_ORDER && (head[2] == 2 || head[2] == 3) ? (int)head[2] : 0;
}

/* ---- what is saved ------------------------------------------------------------------------ */

static void put_source(struct writer *w, const mixsph_sim *s)
{
    put(w, STATE_MAGIC, 8);
    const uint32_t head[3] = {STATE_VERSION, STATE_ORDER, DIM};
    put(w, head, sizeof head);
    put_str(w, s->case_text);
    put_str(w, s->case_origin);
    put_u64(w, s->n_ov);
    for (size_t k = 0; k < s->n_ov; k++) {
        put_str(w, s->ov_key[k]);
        put_f64(w, s->ov_value[k]);
    }
}

/* Scalars, walls and particles, in one order used by both directions: `io` copies between the
 * simulation's field and the stream (writer or reader). */
#define STATE_SCALARS(IO, s)                                           \
    IO(&(s)->phys.t, sizeof(s)->phys.t) IO(&(s)->phys.dt, sizeof(s)->phys.dt)              \
    IO(&(s)->phys.step, sizeof(s)->phys.step) IO(&(s)->phys.n_lost, sizeof(s)->phys.n_lost) \
    IO(&(s)->phys.n_clipped, sizeof(s)->phys.n_clipped) IO(&(s)->phys.n_excluded, sizeof(s)->phys.n_excluded) \
    IO(&(s)->phys.excluded_mass, sizeof(s)->phys.excluded_mass) IO(&(s)->phys.excluded_energy, sizeof(s)->phys.excluded_energy) \
    IO(&(s)->phys.n_fixed, sizeof(s)->phys.n_fixed) \
    IO(&(s)->out.n_samples, sizeof(s)->out.n_samples) IO(&(s)->out.next_sample, sizeof(s)->out.next_sample) \
    IO(&(s)->out.next_snapshot, sizeof(s)->out.next_snapshot) IO(&(s)->out.snap_index, sizeof(s)->out.snap_index) \
    IO(&(s)->work.viscous_last.iterations, sizeof(s)->work.viscous_last.iterations)                       \
    IO(&(s)->work.viscous_last.residual, sizeof(s)->work.viscous_last.residual)                           \
    IO(&(s)->work.viscous_iterations, sizeof(s)->work.viscous_iterations)

static void put_dynamic(struct writer *w, const mixsph_sim *s)
{
#define W(ptr, n) put(w, (ptr), (n));
    STATE_SCALARS(W, s)
#undef W
    put_u64(w, s->out.n);
    put(w, s->out.max, s->out.n * sizeof(double));
    put(w, s->out.tmax, s->out.n * sizeof(double));
    put(w, s->out.min, s->out.n * sizeof(double));
    put(w, s->out.tmin, s->out.n * sizeof(double));
    put_u64(w, s->cfg.n_monitors);
    put(w, s->out.profile_next, s->cfg.n_monitors * sizeof(size_t));
    put_u64(w, s->cfg.n_walls);
    for (size_t k = 0; k < s->cfg.n_walls; k++) {
        const struct wall_state *ws = &s->phys.walls.state[k];
        put(w, ws->o, sizeof ws->o);
        put(w, ws->v, sizeof ws->v);
        put(w, ws->a, sizeof ws->a);
        put(w, ws->ext_v, sizeof ws->ext_v);
        put_f64(w, ws->work);
        put_u64(w, (uint64_t)ws->ext);
    }
    const struct particles *P = &s->phys.P;
    put_u64(w, P->n);
    put_u64(w, s->phys.n_fluid);
    put_u64(w, s->phys.n_wall);
    for (size_t k = 0; k < particle_field_count; k++) {
        const struct particle_field *f = &particle_fields[k];
        if (!(f->where & PF_STATE) || !particle_field_present(f, P->features)) continue;
        put_str(w, f->name);
        put_u64(w, f->components);
        put_u64(w, particle_field_size(f->type));
        for (unsigned c = 0; c < f->components; c++)
            put(w, particles_array(P, f->member[c]), P->n * particle_field_size(f->type));
    }
    /* the neighbour lists' build positions: the lists (and the pair order) are rebuilt from them */
    for (int d = 0; d < DIM; d++) put(w, s->work.NB.pos0[d], P->n * sizeof(double));
    put_u64(w, s->work.NB.builds);
}

mixsph_status mixsph_sim_save_state(const mixsph_sim *s, void **buf, size_t *len)
{
    if (!s || !buf || !len) return MIXSPH_ERR_ARG;
    *buf = NULL;
    *len = 0;
    struct writer w = {0};
    put_source(&w, s);
    put_dynamic(&w, s);
    put_u64(&w, fnv1a(w.buf, w.len));
    if (w.bad) {
        free(w.buf);
        return MIXSPH_ERR_NOMEM;
    }
    *buf = w.buf;
    *len = w.len;
    return MIXSPH_OK;
}

void mixsph_state_free(void *buf) { free(buf); }

/* ---- loading ------------------------------------------------------------------------------ */

/* Check header and checksum; leave the reader after the header. */
static mixsph_status check_header(struct reader *r, char *err, size_t err_len)
{
    if (!r->buf || r->len < 8 + 12 + 8)
        return status_set(err, err_len, MIXSPH_ERR_ARG, "state: %zu bytes is too short to be a mixsph state", r->len);
    char magic[8];
    uint32_t head[3]; /* version, byte order, dimension: a state of another version is refused on its version */
    get(r, magic, 8);
    get(r, head, sizeof head);
    if (memcmp(magic, STATE_MAGIC, 8) != 0) return status_set(err, err_len, MIXSPH_ERR_ARG, "state: not a mixsph state (bad marker)");
    if (head[1] != STATE_ORDER)
        return status_set(err, err_len, MIXSPH_ERR_ARG, "state: saved on a machine of another byte order");
    if (head[0] != STATE_VERSION)
        return status_set(err, err_len, MIXSPH_ERR_ARG, "state: format version %u, this build reads version %u", head[0],
                          STATE_VERSION);
    if (head[2] != DIM)
        return status_set(err, err_len, MIXSPH_ERR_ARG, "state: saved by a %uD build, this build is %dD", head[2], DIM);
    uint64_t sum;
    memcpy(&sum, r->buf + r->len - 8, 8);
    if (sum != fnv1a(r->buf, r->len - 8))
        return status_set(err, err_len, MIXSPH_ERR_ARG, "state: checksum mismatch (truncated or corrupted)");
    r->len -= 8; /* the checksum is not part of the payload */
    return MIXSPH_OK;
}

void state_source_free(struct state_source *src)
{
    for (size_t k = 0; k < src->n_ov; k++) free(src->keys[k]);
    free(src->keys);
    free(src->values);
    free(src->text);
    free(src->origin);
    memset(src, 0, sizeof *src);
}

static char *copy_str(struct reader *r)
{
    size_t n;
    const char *t = get_str(r, &n);
    char *d = malloc(n + 1);
    if (!d) return NULL;
    memcpy(d, t, n);
    d[n] = '\0';
    return d;
}

static mixsph_status read_source(struct reader *r, struct state_source *src, char *err, size_t err_len)
{
    memset(src, 0, sizeof *src);
    src->text = copy_str(r);
    src->origin = copy_str(r);
    const uint64_t n_ov = get_u64(r);
    if (r->bad || n_ov > 4096) return status_set(err, err_len, MIXSPH_ERR_ARG, "state: malformed case section");
    src->keys = calloc(n_ov + 1, sizeof *src->keys);
    src->values = calloc(n_ov + 1, sizeof *src->values);
    if (!src->text || !src->origin || !src->keys || !src->values) return status_set(err, err_len, MIXSPH_ERR_NOMEM, "out of memory");
    for (size_t k = 0; k < n_ov; k++) {
        if (!(src->keys[k] = copy_str(r))) return status_set(err, err_len, MIXSPH_ERR_NOMEM, "out of memory");
        src->n_ov = k + 1;
        src->values[k] = get_f64(r);
    }
    if (r->bad) return status_set(err, err_len, MIXSPH_ERR_ARG, "state: malformed case section");
    return MIXSPH_OK;
}

static int state_same_case(const mixsph_sim *s, const char *text, const char *const *keys, const double *values, size_t n_ov)
{
    if (!s->case_text || strcmp(s->case_text, text) != 0 || s->n_ov != n_ov) return 0;
    for (size_t k = 0; k < n_ov; k++)
        if (strcmp(s->ov_key[k], keys[k]) != 0 || memcmp(&s->ov_value[k], &values[k], sizeof(double)) != 0) return 0;
    return 1;
}

/* Cells and neighbour lists from the build positions (the particles are in their build order). */
static mixsph_status state_relist(mixsph_sim *s)
{
    forces_forget_cache(s->work.forces);
    if (cells_index(&s->work.C, &s->phys.P, s->work.NB.pos0) != 0 ||
        neighbours_relist(&s->work.NB, &s->work.C, s->work.C.start[s->work.C.ncell], 2.0 * s->phys.h + s->work.NB.skin, SIM_THREADS(s)) != 0)
        return SIM_FAIL(s, MIXSPH_ERR_ARG, "state: particles not in cell order (or out of memory)");
    return integrate_build_gather_lists(s);
}

/* Read the dynamic part into s (same case, checked by the caller). On a malformed stream s may
 * be partly overwritten: the caller restores from its own copy. */
static mixsph_status read_dynamic(struct reader *r, mixsph_sim *s)
{
#define R(ptr, n) get(r, (ptr), (n));
    STATE_SCALARS(R, s)
#undef R
    if (get_u64(r) != s->out.n) return SIM_FAIL(s, MIXSPH_ERR_ARG, "state: output count differs from the case's");
    get(r, s->out.max, s->out.n * sizeof(double));
    get(r, s->out.tmax, s->out.n * sizeof(double));
    get(r, s->out.min, s->out.n * sizeof(double));
    get(r, s->out.tmin, s->out.n * sizeof(double));
    if (get_u64(r) != s->cfg.n_monitors) return SIM_FAIL(s, MIXSPH_ERR_ARG, "state: monitor count differs from the case's");
    get(r, s->out.profile_next, s->cfg.n_monitors * sizeof(size_t));
    if (get_u64(r) != s->cfg.n_walls) return SIM_FAIL(s, MIXSPH_ERR_ARG, "state: wall count differs from the case's");
    for (size_t k = 0; k < s->cfg.n_walls; k++) {
        struct wall_state *ws = &s->phys.walls.state[k];
        get(r, ws->o, sizeof ws->o);
        get(r, ws->v, sizeof ws->v);
        get(r, ws->a, sizeof ws->a);
        get(r, ws->ext_v, sizeof ws->ext_v);
        ws->work = get_f64(r);
        ws->ext = get_u64(r) != 0;
    }
    struct particles *P = &s->phys.P;
    const uint64_t n = get_u64(r), n_fluid = get_u64(r), n_wall = get_u64(r);
    if (r->bad || n != P->n || n_fluid != s->phys.n_fluid || n_wall != s->phys.n_wall)
        return SIM_FAIL(s, MIXSPH_ERR_ARG, "state: particle counts differ from the case's (%llu vs %zu)", (unsigned long long)n,
                        P->n);
    for (size_t k = 0; k < particle_field_count; k++) {
        const struct particle_field *f = &particle_fields[k];
        if (!(f->where & PF_STATE) || !particle_field_present(f, P->features)) continue;
        size_t len;
        const char *name = get_str(r, &len);
        const uint64_t components = get_u64(r), elem = get_u64(r);
        if (r->bad) break;
        if (len != strlen(f->name) || memcmp(name, f->name, len) != 0 || components != f->components ||
            elem != particle_field_size(f->type))
            return SIM_FAIL(s, MIXSPH_ERR_ARG,
                            "state: particle field '%.*s' (%llu x %llu bytes) where this build has '%s' (%u x %zu bytes)",
                            (int)(len < 64 ? len : 64), name, (unsigned long long)components, (unsigned long long)elem,
                            f->name, f->components, particle_field_size(f->type));
        for (unsigned c = 0; c < f->components; c++)
            get(r, particles_array(P, f->member[c]), P->n * particle_field_size(f->type));
    }
    for (int d = 0; d < DIM; d++) get(r, s->work.NB.pos0[d], P->n * sizeof(double));
    s->work.NB.builds = get_u64(r);
    if (r->bad || r->pos != r->len) return SIM_FAIL(s, MIXSPH_ERR_ARG, "state: malformed particle section");
    return state_relist(s);
}

mixsph_status mixsph_sim_load_state(mixsph_sim *s, const void *buf, size_t len)
{
    if (!s) return MIXSPH_ERR_ARG;
    struct reader r = {buf, len, 0, 0};
    mixsph_status st = check_header(&r, s->err, sizeof s->err);
    if (st != MIXSPH_OK) return st;
    struct state_source src;
    st = read_source(&r, &src, s->err, sizeof s->err);
    if (st == MIXSPH_OK && !state_same_case(s, src.text, (const char *const *)src.keys, src.values, src.n_ov))
        st = SIM_FAIL(s, MIXSPH_ERR_ARG,
                      "state: saved from another case or other overrides (%s) than this simulation's (%s); create a "
                      "new simulation from the state instead",
                      src.origin, s->case_origin);
    state_source_free(&src);
    if (st != MIXSPH_OK) return st;
    /* keep a copy so that a malformed payload leaves the simulation unchanged */
    mixsph_sim *keep = malloc(sizeof *keep);
    const size_t nb = s->phys.P.n * sizeof(double);
    double *pos0_kept[DIM];
    int no_memory = !keep;
    for (int d = 0; d < DIM; d++) no_memory |= !(pos0_kept[d] = malloc(nb + 1));
    struct particles Pk;
    if (no_memory || particles_copy(&Pk, &s->phys.P) != 0) {
        free(keep);
        for (int d = 0; d < DIM; d++) free(pos0_kept[d]);
        return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory");
    }
    for (int d = 0; d < DIM; d++) memcpy(pos0_kept[d], s->work.NB.pos0[d], nb);
    memcpy(keep, s, sizeof *s);
    st = read_dynamic(&r, s);
    if (st != MIXSPH_OK) {
        char msg[sizeof s->err];
        memcpy(msg, s->err, sizeof msg);
        struct particles P = s->phys.P;
        memcpy(s, keep, sizeof *s);
        s->phys.P = P;
        particles_copy_values(&s->phys.P, &Pk);
        for (int d = 0; d < DIM; d++) memcpy(s->work.NB.pos0[d], pos0_kept[d], nb);
        state_relist(s);
        memcpy(s->err, msg, sizeof msg);
    }
    particles_free(&Pk);
    free(keep);
    for (int d = 0; d < DIM; d++) free(pos0_kept[d]);
    return st;
}

mixsph_status state_read_source(const void *buf, size_t len, struct state_source *src, char *err, size_t err_len)
{
    memset(src, 0, sizeof *src);
    struct reader r = {buf, len, 0, 0};
    const mixsph_status st = check_header(&r, err, err_len);
    return st != MIXSPH_OK ? st : read_source(&r, src, err, err_len);
}
