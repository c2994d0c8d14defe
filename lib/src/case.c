/* case.c - JSON case files (cJSON): overrides, reading, validation. See case.h and
 * cases/README.md for the schema. Every message has the form
 *   "<file>: <key path>: <what was expected>". */
#include "case.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "status.h"

#define KERNEL_PI_ 3.14159265358979323846

struct reader {
    const char *origin;
    char *err;
    size_t err_len;
};

#define FAIL(r, ...) status_set((r)->err, (r)->err_len, MIXSPH_ERR_CASE, __VA_ARGS__)

/* ---- files ------------------------------------------------------------------------------ */

mixsph_status case_read_file(const char *path, char **text, char *err, size_t err_len)
{
    *text = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) return status_set(err, err_len, MIXSPH_ERR_IO, "%s: cannot open case file: %s", path, strerror(errno));
    if (fseek(f, 0, SEEK_END) != 0) {
        fclose(f);
        return status_set(err, err_len, MIXSPH_ERR_IO, "%s: cannot read case file", path);
    }
    long len = ftell(f);
    rewind(f);
    if (len < 0 || len > (1L << 28)) {
        fclose(f);
        return status_set(err, err_len, MIXSPH_ERR_IO, "%s: cannot read case file (size)", path);
    }
    char *buf = malloc((size_t)len + 1);
    if (!buf) {
        fclose(f);
        return status_set(err, err_len, MIXSPH_ERR_NOMEM, "%s: out of memory", path);
    }
    size_t got = fread(buf, 1, (size_t)len, f);
    fclose(f);
    if (got != (size_t)len) {
        free(buf);
        return status_set(err, err_len, MIXSPH_ERR_IO, "%s: short read", path);
    }
    buf[len] = '\0';
    *text = buf;
    return MIXSPH_OK;
}

/* ---- overrides ---------------------------------------------------------------------------- */

mixsph_status mixsph_override_parse(char *text, mixsph_override *out, char *err, size_t err_len)
{
    char *eq = text ? strchr(text, '=') : NULL;
    if (!eq || eq == text)
        return status_set(err, err_len, MIXSPH_ERR_ARG, "override '%s': expected key=value", text ? text : "(null)");
    *eq = '\0';
    char *end = NULL;
    errno = 0;
    double v = strtod(eq + 1, &end);
    if (eq[1] == '\0' || *end != '\0' || errno == ERANGE || !isfinite(v)) {
        status_set(err, err_len, MIXSPH_ERR_ARG, "override '%s': value '%s' is not a finite number", text, eq + 1);
        *eq = '=';
        return MIXSPH_ERR_ARG;
    }
    out->key = text;
    out->value = v;
    return MIXSPH_OK;
}

static mixsph_status apply_override(struct reader *r, cJSON *root, const mixsph_override *ov)
{
    char path[256];
    if (!ov->key || strlen(ov->key) >= sizeof path) return FAIL(r, "%s: override key missing or too long", r->origin);
    if (!isfinite(ov->value)) return FAIL(r, "%s: override %s: value is not finite", r->origin, ov->key);
    strcpy(path, ov->key);
    cJSON *node = root;
    for (char *save = NULL, *tok = strtok_r(path, ".", &save); tok; tok = strtok_r(NULL, ".", &save)) {
        char *rest = save && *save ? save : NULL;
        if (!rest && cJSON_IsObject(node) && !cJSON_GetObjectItemCaseSensitive(node, tok)) {
            /* a key with a default, absent from the file: add it (validation rejects unknown keys) */
            if (!cJSON_AddNumberToObject(node, tok, ov->value))
                return status_set(r->err, r->err_len, MIXSPH_ERR_NOMEM, "out of memory");
            return MIXSPH_OK;
        }
        if (cJSON_IsArray(node)) {
            char *end;
            long idx = strtol(tok, &end, 10);
            node = (*end == '\0' && idx >= 0) ? cJSON_GetArrayItem(node, (int)idx) : NULL;
        } else if (cJSON_IsObject(node)) {
            node = cJSON_GetObjectItemCaseSensitive(node, tok);
        } else {
            node = NULL;
        }
        if (!node) return FAIL(r, "%s: override %s: no such key in the case (at '%s')", r->origin, ov->key, tok);
    }
    if (cJSON_IsNumber(node)) {
        cJSON_SetNumberValue(node, ov->value);
    } else if (cJSON_IsBool(node)) {
        if (ov->value != 0.0 && ov->value != 1.0)
            return FAIL(r, "%s: override %s: a Boolean key takes 0 or 1", r->origin, ov->key);
        node->type = ov->value != 0.0 ? cJSON_True : cJSON_False;
    } else {
        return FAIL(r, "%s: override %s: the key is not a number or a Boolean", r->origin, ov->key);
    }
    return MIXSPH_OK;
}

/* ---- typed getters ------------------------------------------------------------------------ */

/* Reject keys an object does not know: a misspelt key would otherwise be silently ignored. */
static mixsph_status check_keys(struct reader *r, const cJSON *obj, const char *path, const char *const *allowed)
{
    for (const cJSON *it = obj->child; it; it = it->next) {
        int ok = 0;
        for (const char *const *a = allowed; *a; a++) ok |= strcmp(it->string, *a) == 0;
        if (!ok) return FAIL(r, "%s: %s%s%s: unknown key", r->origin, path, *path ? "." : "", it->string);
    }
    return MIXSPH_OK;
}

/* A number in [lo, hi] (lo_open: > lo). A missing optional key keeps *out. */
static mixsph_status get_num(struct reader *r, const cJSON *obj, const char *path, const char *key, int required,
                             double lo, int lo_open, double hi, double *out)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!it) return required ? FAIL(r, "%s: %s%s%s: missing (expected a number)", r->origin, path, *path ? "." : "", key) : MIXSPH_OK;
    if (!cJSON_IsNumber(it) || !isfinite(it->valuedouble))
        return FAIL(r, "%s: %s%s%s: expected a number", r->origin, path, *path ? "." : "", key);
    const double v = it->valuedouble;
    if ((lo_open ? v <= lo : v < lo) || v > hi) {
        if (isinf(hi)) return FAIL(r, "%s: %s%s%s: %g is out of range (expected %s %g)", r->origin, path, *path ? "." : "", key, v, lo_open ? ">" : ">=", lo);
        return FAIL(r, "%s: %s%s%s: %g is out of range (expected %g %s x <= %g)", r->origin, path, *path ? "." : "", key, v, lo, lo_open ? "<" : "<=", hi);
    }
    *out = v;
    return MIXSPH_OK;
}

static mixsph_status get_str(struct reader *r, const cJSON *obj, const char *path, const char *key, int required,
                             const char **out)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!it) return required ? FAIL(r, "%s: %s%s%s: missing (expected a string)", r->origin, path, *path ? "." : "", key) : MIXSPH_OK;
    if (!cJSON_IsString(it)) return FAIL(r, "%s: %s%s%s: expected a string", r->origin, path, *path ? "." : "", key);
    *out = it->valuestring;
    return MIXSPH_OK;
}

static mixsph_status get_obj(struct reader *r, const cJSON *parent, const char *path, const char *key, int required,
                             const cJSON **out)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(parent, key);
    *out = NULL;
    if (!it) return required ? FAIL(r, "%s: %s%s%s: missing (expected an object)", r->origin, path, *path ? "." : "", key) : MIXSPH_OK;
    if (!cJSON_IsObject(it)) return FAIL(r, "%s: %s%s%s: expected an object", r->origin, path, *path ? "." : "", key);
    *out = it;
    return MIXSPH_OK;
}

/* An array of n finite numbers (n >= min_n). */
static mixsph_status get_numbers(struct reader *r, const cJSON *obj, const char *path, const char *key, size_t min_n,
                                 double **out, size_t *n)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!it) return FAIL(r, "%s: %s%s%s: missing (expected an array of numbers)", r->origin, path, *path ? "." : "", key);
    if (!cJSON_IsArray(it)) return FAIL(r, "%s: %s%s%s: expected an array of numbers", r->origin, path, *path ? "." : "", key);
    size_t len = (size_t)cJSON_GetArraySize(it);
    if (len < min_n) return FAIL(r, "%s: %s%s%s: expected at least %zu number(s)", r->origin, path, *path ? "." : "", key, min_n);
    double *v = calloc(len, sizeof *v);
    if (!v) return status_set(r->err, r->err_len, MIXSPH_ERR_NOMEM, "out of memory");
    size_t k = 0;
    for (const cJSON *e = it->child; e; e = e->next, k++) {
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble)) {
            free(v);
            return FAIL(r, "%s: %s%s%s[%zu]: expected a number", r->origin, path, *path ? "." : "", key, k);
        }
        v[k] = e->valuedouble;
    }
    *out = v;
    *n = len;
    return MIXSPH_OK;
}

/* An array of [x, z] points. */
static mixsph_status get_points(struct reader *r, const cJSON *obj, const char *path, const char *key, size_t min_n,
                                struct polyline *pl)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!it) return FAIL(r, "%s: %s%s%s: missing (expected an array of [x, z] points)", r->origin, path, *path ? "." : "", key);
    if (!cJSON_IsArray(it)) return FAIL(r, "%s: %s%s%s: expected an array of [x, z] points", r->origin, path, *path ? "." : "", key);
    size_t len = (size_t)cJSON_GetArraySize(it);
    if (len < min_n) return FAIL(r, "%s: %s%s%s: expected at least %zu [x, z] point(s)", r->origin, path, *path ? "." : "", key, min_n);
    pl->x = calloc(len, sizeof(double));
    pl->z = calloc(len, sizeof(double));
    pl->n = len;
    if (!pl->x || !pl->z) return status_set(r->err, r->err_len, MIXSPH_ERR_NOMEM, "out of memory");
    size_t k = 0;
    for (const cJSON *e = it->child; e; e = e->next, k++) {
        const cJSON *a = cJSON_IsArray(e) && cJSON_GetArraySize(e) == 2 ? e->child : NULL;
        if (!a || !cJSON_IsNumber(a) || !cJSON_IsNumber(a->next) || !isfinite(a->valuedouble) ||
            !isfinite(a->next->valuedouble))
            return FAIL(r, "%s: %s%s%s[%zu]: expected a point [x, z] of two numbers", r->origin, path, *path ? "." : "", key, k);
        pl->x[k] = a->valuedouble;
        pl->z[k] = a->next->valuedouble;
        if (k > 0 && pl->x[k] == pl->x[k - 1] && pl->z[k] == pl->z[k - 1])
            return FAIL(r, "%s: %s%s%s[%zu]: repeats the previous point", r->origin, path, *path ? "." : "", key, k);
    }
    return MIXSPH_OK;
}

static mixsph_status copy_name(struct reader *r, const char *path, const char *name, char *dst)
{
    if (strlen(name) == 0 || strlen(name) >= CASE_NAME_LEN)
        return FAIL(r, "%s: %s: name must have 1 to %d characters", r->origin, path, CASE_NAME_LEN - 1);
    strcpy(dst, name);
    return MIXSPH_OK;
}

static int find_medium(const struct case_def *c, const char *name)
{
    for (size_t i = 0; i < c->n_media; i++)
        if (strcmp(c->media[i].name, name) == 0) return (int)i;
    return -1;
}

static int find_motion(const struct case_def *c, const char *name)
{
    for (size_t i = 0; i < c->n_motions; i++)
        if (strcmp(c->motions[i].name, name) == 0) return (int)i;
    return -1;
}

#define TRY(expr)                                  \
    do {                                           \
        mixsph_status st_ = (expr);                \
        if (st_ != MIXSPH_OK) return st_;          \
    } while (0)

/* ---- sections ----------------------------------------------------------------------------- */

static mixsph_status get_bool(struct reader *r, const cJSON *obj, const char *path, const char *key, int *out);

static mixsph_status read_numerics(struct reader *r, const cJSON *root, struct case_def *c)
{
    static const char *const keys[] = {"dx", "h_over_dx", "cfl", "cfl_visc", "t_end", "wall_layers", "background_pressure", "kernel", "pressure_smoothing",
                                        "fixed_bed_speed", "av_wall", "av_mixed", "av_separating", NULL};
    const cJSON *n;
    TRY(get_obj(r, root, "", "numerics", 1, &n));
    TRY(check_keys(r, n, "numerics", keys));
    c->h_over_dx = 1.3;
    c->cfl = 0.1;
    c->cfl_visc = 0.05;
    double layers = 3;
    TRY(get_num(r, n, "numerics", "dx", 1, 0.0, 1, 10.0, &c->dx));
    TRY(get_num(r, n, "numerics", "h_over_dx", 0, 1.0, 0, 3.0, &c->h_over_dx));
    TRY(get_num(r, n, "numerics", "cfl", 0, 0.0, 1, 1.0, &c->cfl));
    TRY(get_num(r, n, "numerics", "cfl_visc", 0, 0.0, 1, 1.0, &c->cfl_visc));
    TRY(get_num(r, n, "numerics", "t_end", 1, 0.0, 1, 1e6, &c->t_end));
    TRY(get_num(r, n, "numerics", "wall_layers", 0, 1.0, 0, 8.0, &layers));
    const char *kernel = "cubic_spline";
    TRY(get_str(r, n, "numerics", "kernel", 0, &kernel));
    if (strcmp(kernel, "cubic_spline") == 0) c->kernel = 0;
    else if (strcmp(kernel, "wendland_c2") == 0) c->kernel = 1;
    else return FAIL(r, "%s: numerics.kernel: '%s' (expected \"cubic_spline\" or \"wendland_c2\")", r->origin, kernel);
    c->p_background = 0.0;
    TRY(get_num(r, n, "numerics", "background_pressure", 0, 0.0, 0, 1e9, &c->p_background));
    c->pressure_smoothing = 0.0;
    TRY(get_num(r, n, "numerics", "pressure_smoothing", 0, 0.0, 0, 1.0, &c->pressure_smoothing));
    c->fixed_bed_speed = -1.0;
    TRY(get_num(r, n, "numerics", "fixed_bed_speed", 0, -1.0, 0, 100.0, &c->fixed_bed_speed));
    c->av_wall = 1;
    c->av_mixed = 0;
    c->av_separating = 0;
    TRY(get_bool(r, n, "numerics", "av_wall", &c->av_wall));
    TRY(get_bool(r, n, "numerics", "av_mixed", &c->av_mixed));
    TRY(get_bool(r, n, "numerics", "av_separating", &c->av_separating));
    c->wall_layers = (int)layers;
    if ((double)c->wall_layers != layers) return FAIL(r, "%s: numerics.wall_layers: expected an integer", r->origin);
    if (c->wall_layers < (int)ceil(2.0 * c->h_over_dx))
        return FAIL(r, "%s: numerics.wall_layers: %d layers do not cover the kernel support 2h = %.2f dx (expected >= %d)",
                    r->origin, c->wall_layers, 2.0 * c->h_over_dx, (int)ceil(2.0 * c->h_over_dx));
    return MIXSPH_OK;
}

static mixsph_status get_bool(struct reader *r, const cJSON *obj, const char *path, const char *key, int *out)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!it) return MIXSPH_OK;
    if (cJSON_IsNumber(it) && (it->valuedouble == 0.0 || it->valuedouble == 1.0)) { /* from a parameter */
        *out = it->valuedouble != 0.0;
        return MIXSPH_OK;
    }
    if (!cJSON_IsBool(it)) return FAIL(r, "%s: %s%s%s: expected true or false", r->origin, path, *path ? "." : "", key);
    *out = cJSON_IsTrue(it);
    return MIXSPH_OK;
}

/* Sound speed from exactly one of K (bulk modulus, with density rho_pure) or c. */
static mixsph_status read_sound_speed(struct reader *r, const cJSON *it, const char *path, double rho_pure, double *c)
{
    const int has_k = cJSON_HasObjectItem(it, "K"), has_c = cJSON_HasObjectItem(it, "c");
    if (has_k == has_c) return FAIL(r, "%s: %s: expected exactly one of K (bulk modulus, Pa) or c (sound speed, m/s)", r->origin, path);
    if (has_k) {
        double k = 0;
        TRY(get_num(r, it, path, "K", 1, 0.0, 1, 1e12, &k));
        *c = sqrt(k / rho_pure);
        return MIXSPH_OK;
    }
    return get_num(r, it, path, "c", 1, 0.0, 1, 1e5, c);
}

static mixsph_status read_granular(struct reader *r, const cJSON *it, const char *path, struct case_def *c, struct medium *md)
{
    static const char *const keys[] = {"type", "rho", "K", "c", "porosity", "phi", "d50", "saturated", "pore_fluid",
                                       "mu_thr", "mu0", "mu1", "tension_cutoff", "hold_fixed", "alpha_m", NULL};
    TRY(check_keys(r, it, path, keys));
    md->kind = MEDIUM_GRANULAR;
    TRY(get_num(r, it, path, "rho", 1, 0.0, 1, 1e5, &md->rho_grain));
    TRY(read_sound_speed(r, it, path, md->rho_grain, &md->c));
    TRY(get_num(r, it, path, "porosity", 1, 0.0, 1, 0.95, &md->porosity));
    TRY(get_num(r, it, path, "phi", 1, 0.0, 1, 89.0, &md->phi_deg));
    md->sin_phi = sin(md->phi_deg * KERNEL_PI_ / 180.0);
    md->d50 = 0.0;
    TRY(get_num(r, it, path, "d50", 0, 0.0, 0, 10.0, &md->d50));
    md->saturated = 0;
    TRY(get_bool(r, it, path, "saturated", &md->saturated));
    md->pore_fluid = -1;
    const char *fluid = NULL;
    TRY(get_str(r, it, path, "pore_fluid", 0, &fluid));
    if (fluid) {
        md->pore_fluid = find_medium(c, fluid);
        if (md->pore_fluid < 0 || c->media[md->pore_fluid].kind != MEDIUM_FLUID)
            return FAIL(r, "%s: %s.pore_fluid: '%s' is not a fluid medium defined before this one", r->origin, path, fluid);
    }
    if (md->saturated && md->pore_fluid < 0)
        return FAIL(r, "%s: %s.pore_fluid: missing (a saturated medium needs the name of its pore fluid)", r->origin, path);
    const double n = md->porosity;
    if (md->saturated) {
        const struct medium *f = &c->media[md->pore_fluid];
        md->rho_f = f->rho0;
        md->eps_f_mu_f = n * f->mu;
        md->rho0 = n * f->rho0 + (1.0 - n) * md->rho_grain; /* (5), saturated */
    } else {
        md->rho_f = 0.0;
        md->eps_f_mu_f = 0.0;
        md->rho0 = (1.0 - n) * md->rho_grain; /* (5), dry */
    }
    const int has_mu1 = cJSON_HasObjectItem(it, "mu1");
    md->mu0 = INFINITY;
    if (has_mu1) {
        if (cJSON_HasObjectItem(it, "mu_thr") || cJSON_HasObjectItem(it, "mu0"))
            return FAIL(r, "%s: %s.mu1: the mu1 rheology (Run 7) replaces mu_thr and mu0: give mu1 alone", r->origin, path);
        TRY(get_num(r, it, path, "mu1", 1, 0.0, 1, 1e12, &md->mu_thr));
        md->mu1_mode = 1;
    } else {
        TRY(get_num(r, it, path, "mu_thr", 1, 0.0, 1, 1e12, &md->mu_thr));
        TRY(get_num(r, it, path, "mu0", 0, 0.0, 1, 1e12, &md->mu0));
    }
    md->tension_cutoff = 0;
    TRY(get_bool(r, it, path, "tension_cutoff", &md->tension_cutoff));
    md->hold_fixed = 0;
    TRY(get_bool(r, it, path, "hold_fixed", &md->hold_fixed));
    md->mu = 0.0;
    md->alpha_m = 0.0;
    TRY(get_num(r, it, path, "alpha_m", 0, 0.0, 0, 10.0, &md->alpha_m));
    return MIXSPH_OK;
}

static mixsph_status read_media(struct reader *r, const cJSON *root, struct case_def *c)
{
    static const char *const keys[] = {"type", "rho", "K", "c", "mu", "alpha_m", NULL};
    const cJSON *m;
    TRY(get_obj(r, root, "", "media", 1, &m));
    for (const cJSON *it = m->child; it; it = it->next) {
        char path[128];
        snprintf(path, sizeof path, "media.%s", it->string);
        if (!cJSON_IsObject(it)) return FAIL(r, "%s: %s: expected an object", r->origin, path);
        if (c->n_media == CASE_MAX_MEDIA) return FAIL(r, "%s: media: at most %d media", r->origin, CASE_MAX_MEDIA);
        struct medium *md = &c->media[c->n_media];
        TRY(copy_name(r, path, it->string, md->name));
        const char *type = NULL;
        TRY(get_str(r, it, path, "type", 1, &type));
        if (strcmp(type, "granular") == 0) {
            TRY(read_granular(r, it, path, c, md));
            c->n_media++;
            continue;
        }
        if (strcmp(type, "fluid") != 0)
            return FAIL(r, "%s: %s.type: '%s' is not a known medium type (expected \"fluid\" or \"granular\")", r->origin, path, type);
        TRY(check_keys(r, it, path, keys));
        md->kind = MEDIUM_FLUID;
        TRY(get_num(r, it, path, "rho", 1, 0.0, 1, 1e5, &md->rho0));
        TRY(read_sound_speed(r, it, path, md->rho0, &md->c));
        md->mu = 0.0;
        md->alpha_m = 0.0;
        TRY(get_num(r, it, path, "mu", 0, 0.0, 0, 1e9, &md->mu));
        TRY(get_num(r, it, path, "alpha_m", 0, 0.0, 0, 10.0, &md->alpha_m));
        c->n_media++;
    }
    if (c->n_media == 0) return FAIL(r, "%s: media: expected at least one medium", r->origin);
    return MIXSPH_OK;
}

static mixsph_status read_bodies(struct reader *r, const cJSON *root, struct case_def *c)
{
    static const char *const keys[] = {"medium", "polygon", "z_min", "z_max", NULL};
    const cJSON *b;
    TRY(get_obj(r, root, "", "bodies", 1, &b));
    for (const cJSON *it = b->child; it; it = it->next) {
        char path[128];
        snprintf(path, sizeof path, "bodies.%s", it->string);
        if (!cJSON_IsObject(it)) return FAIL(r, "%s: %s: expected an object", r->origin, path);
        if (c->n_bodies == CASE_MAX_BODIES) return FAIL(r, "%s: bodies: at most %d bodies", r->origin, CASE_MAX_BODIES);
        struct body *bd = &c->bodies[c->n_bodies++];
        TRY(copy_name(r, path, it->string, bd->name));
        TRY(check_keys(r, it, path, keys));
        const char *medium = NULL;
        TRY(get_str(r, it, path, "medium", 1, &medium));
        bd->medium = find_medium(c, medium);
        if (bd->medium < 0) return FAIL(r, "%s: %s.medium: '%s' is not one of the media", r->origin, path, medium);
        TRY(get_points(r, it, path, "polygon", 3, &bd->polygon));
        bd->z_min = -INFINITY;
        bd->z_max = INFINITY;
        TRY(get_num(r, it, path, "z_min", 0, -1e9, 0, 1e9, &bd->z_min));
        TRY(get_num(r, it, path, "z_max", 0, -1e9, 0, 1e9, &bd->z_max));
    }
    if (c->n_bodies == 0) return FAIL(r, "%s: bodies: expected at least one body", r->origin);
    return MIXSPH_OK;
}

static mixsph_status read_motions(struct reader *r, const cJSON *root, struct case_def *c)
{
    static const char *const keys[] = {"t", "vx", "vz", "speed_scale", "time_scale", "stroke_scale", NULL};
    const cJSON *m;
    TRY(get_obj(r, root, "", "motions", 0, &m));
    if (!m) return MIXSPH_OK;
    for (const cJSON *it = m->child; it; it = it->next) {
        char path[128];
        snprintf(path, sizeof path, "motions.%s", it->string);
        if (!cJSON_IsObject(it)) return FAIL(r, "%s: %s: expected an object", r->origin, path);
        if (c->n_motions == CASE_MAX_MOTIONS) return FAIL(r, "%s: motions: at most %d", r->origin, CASE_MAX_MOTIONS);
        struct motion *mo = &c->motions[c->n_motions++];
        TRY(copy_name(r, path, it->string, mo->name));
        TRY(check_keys(r, it, path, keys));
        size_t nt = 0, nx = 0, nz = 0;
        TRY(get_numbers(r, it, path, "t", 1, &mo->t, &nt));
        TRY(get_numbers(r, it, path, "vx", 1, &mo->vx, &nx));
        TRY(get_numbers(r, it, path, "vz", 1, &mo->vz, &nz));
        if (nx != nt || nz != nt) return FAIL(r, "%s: %s: t, vx and vz must have the same length (%zu, %zu, %zu)", r->origin, path, nt, nx, nz);
        for (size_t k = 1; k < nt; k++)
            if (!(mo->t[k] > mo->t[k - 1])) return FAIL(r, "%s: %s.t[%zu]: times must increase", r->origin, path, k);
        mo->n = nt;
        mo->speed_scale = 1.0;
        mo->time_scale = 1.0;
        TRY(get_num(r, it, path, "speed_scale", 0, 0.0, 0, 1e3, &mo->speed_scale));
        TRY(get_num(r, it, path, "time_scale", 0, 0.0, 1, 1e3, &mo->time_scale));
        /* stroke_scale scales the displacement: with the duration stretched by time_scale, the
         * velocities scale by stroke_scale / time_scale */
        if (cJSON_GetObjectItemCaseSensitive(it, "stroke_scale")) {
            if (cJSON_GetObjectItemCaseSensitive(it, "speed_scale"))
                return FAIL(r, "%s: %s: give speed_scale or stroke_scale, not both", r->origin, path);
            double stroke = 1.0;
            TRY(get_num(r, it, path, "stroke_scale", 1, 0.0, 1, 1e3, &stroke));
            mo->speed_scale = stroke / mo->time_scale;
        }
    }
    return MIXSPH_OK;
}

static mixsph_status read_walls(struct reader *r, const cJSON *root, struct case_def *c)
{
    static const char *const keys[] = {"polyline", "fluid_side", "motion", "slip", NULL};
    const cJSON *w;
    TRY(get_obj(r, root, "", "walls", 1, &w));
    for (const cJSON *it = w->child; it; it = it->next) {
        char path[128];
        snprintf(path, sizeof path, "walls.%s", it->string);
        if (!cJSON_IsObject(it)) return FAIL(r, "%s: %s: expected an object", r->origin, path);
        if (c->n_walls == CASE_MAX_WALLS) return FAIL(r, "%s: walls: at most %d walls", r->origin, CASE_MAX_WALLS);
        struct wall *wl = &c->walls[c->n_walls++];
        TRY(copy_name(r, path, it->string, wl->name));
        TRY(check_keys(r, it, path, keys));
        TRY(get_points(r, it, path, "polyline", 2, &wl->line));
        const char *side = NULL, *slip = "no-slip", *motion = NULL;
        TRY(get_str(r, it, path, "fluid_side", 1, &side));
        if (strcmp(side, "left") == 0) wl->side = 1;
        else if (strcmp(side, "right") == 0) wl->side = -1;
        else return FAIL(r, "%s: %s.fluid_side: '%s' (expected \"left\" or \"right\" of the polyline's direction)", r->origin, path, side);
        TRY(get_str(r, it, path, "slip", 0, &slip));
        if (strcmp(slip, "no-slip") == 0) wl->slip = WALL_NO_SLIP;
        else if (strcmp(slip, "free-slip") == 0) wl->slip = WALL_FREE_SLIP;
        else return FAIL(r, "%s: %s.slip: '%s' (expected \"no-slip\" or \"free-slip\")", r->origin, path, slip);
        wl->motion = -1;
        TRY(get_str(r, it, path, "motion", 0, &motion));
        if (motion) {
            wl->motion = find_motion(c, motion);
            if (wl->motion < 0) return FAIL(r, "%s: %s.motion: '%s' is not one of the motions", r->origin, path, motion);
        }
    }
    if (c->n_walls == 0) return FAIL(r, "%s: walls: expected at least one wall", r->origin);
    return MIXSPH_OK;
}

static int find_wall(const struct case_def *c, const char *name)
{
    for (size_t i = 0; i < c->n_walls; i++)
        if (strcmp(c->walls[i].name, name) == 0) return (int)i;
    return -1;
}

static int find_monitor(const struct case_def *c, const char *name);

static mixsph_status read_monitors(struct reader *r, const cJSON *root, struct case_def *c)
{
    static const char *const keys[] = {"type", "medium", "wall", "direction", "x_min", "x_max", "z_min", "z_max",
                                       "min_neighbours", "bin", "times", "at_max_of", NULL};
    const char *at_max_of[CASE_MAX_MONITORS] = {NULL};
    const cJSON *m;
    TRY(get_obj(r, root, "", "monitors", 0, &m));
    if (!m) return MIXSPH_OK;
    for (const cJSON *it = m->child; it; it = it->next) {
        char path[128];
        snprintf(path, sizeof path, "monitors.%s", it->string);
        if (!cJSON_IsObject(it)) return FAIL(r, "%s: %s: expected an object", r->origin, path);
        if (c->n_monitors == CASE_MAX_MONITORS) return FAIL(r, "%s: monitors: at most %d", r->origin, CASE_MAX_MONITORS);
        struct monitor_def *md = &c->monitors[c->n_monitors++];
        TRY(copy_name(r, path, it->string, md->name));
        TRY(check_keys(r, it, path, keys));
        const char *type = NULL, *medium = NULL, *dir = "+x", *wall = NULL;
        TRY(get_str(r, it, path, "type", 1, &type));
        if (strcmp(type, "profile") != 0 && cJSON_HasObjectItem(it, "at_max_of"))
            return FAIL(r, "%s: %s.at_max_of: only a profile takes at_max_of", r->origin, path);
        md->medium = md->wall = -1;
        md->at_max_of = -1;
        md->x_min = md->z_min = -INFINITY;
        md->x_max = md->z_max = INFINITY;
        double mn = 3;
        TRY(get_num(r, it, path, "min_neighbours", 0, 0.0, 0, 100.0, &mn));
        md->min_neighbours = (int)mn;
        TRY(get_num(r, it, path, "x_min", 0, -1e9, 0, 1e9, &md->x_min));
        TRY(get_num(r, it, path, "x_max", 0, -1e9, 0, 1e9, &md->x_max));
        TRY(get_num(r, it, path, "z_min", 0, -1e9, 0, 1e9, &md->z_min));
        TRY(get_num(r, it, path, "z_max", 0, -1e9, 0, 1e9, &md->z_max));
        if (!(md->x_max > md->x_min) || !(md->z_max > md->z_min))
            return FAIL(r, "%s: %s: expected x_min < x_max and z_min < z_max", r->origin, path);
        if (strcmp(type, "wall_pressure") == 0) {
            md->kind = MONITOR_WALL_PRESSURE;
            TRY(get_str(r, it, path, "wall", 1, &wall));
            md->wall = find_wall(c, wall);
            if (md->wall < 0) return FAIL(r, "%s: %s.wall: '%s' is not one of the walls", r->origin, path, wall);
            continue;
        }
        TRY(get_str(r, it, path, "medium", 1, &medium));
        md->medium = find_medium(c, medium);
        if (md->medium < 0) return FAIL(r, "%s: %s.medium: '%s' is not one of the media", r->origin, path, medium);
        if (strcmp(type, "front") == 0) {
            md->kind = MONITOR_FRONT;
            TRY(get_str(r, it, path, "direction", 0, &dir));
            if (strcmp(dir, "+x") == 0) md->direction = 1;
            else if (strcmp(dir, "-x") == 0) md->direction = -1;
            else return FAIL(r, "%s: %s.direction: '%s' (expected \"+x\" or \"-x\")", r->origin, path, dir);
        } else if (strcmp(type, "max_elevation") == 0) {
            md->kind = MONITOR_MAX_ELEVATION;
        } else if (strcmp(type, "kinetic_energy") == 0) {
            md->kind = MONITOR_KINETIC_ENERGY;
        } else if (strcmp(type, "profile") == 0) {
            md->kind = MONITOR_PROFILE;
            if (!isfinite(md->x_min) || !isfinite(md->x_max))
                return FAIL(r, "%s: %s: a profile needs x_min and x_max", r->origin, path);
            md->bin = c->dx;
            TRY(get_num(r, it, path, "bin", 0, 0.0, 1, 1e3, &md->bin));
            TRY(get_str(r, it, path, "at_max_of", 0, &at_max_of[c->n_monitors - 1]));
            double *t = NULL;
            size_t nt = 0;
            if (!at_max_of[c->n_monitors - 1] || cJSON_HasObjectItem(it, "times"))
                TRY(get_numbers(r, it, path, "times", 1, &t, &nt));
            if (nt > CASE_MAX_PROFILE_TIMES) {
                free(t);
                return FAIL(r, "%s: %s.times: at most %d times", r->origin, path, CASE_MAX_PROFILE_TIMES);
            }
            for (size_t k = 0; k < nt; k++) md->times[k] = t[k];  /* nt = 0: at_max_of only */
            md->n_times = nt;
            free(t);
            for (size_t k = 1; k < nt; k++)
                if (!(md->times[k] > md->times[k - 1])) return FAIL(r, "%s: %s.times[%zu]: times must increase", r->origin, path, k);
        } else {
            return FAIL(r,
                        "%s: %s.type: '%s' (expected \"front\", \"max_elevation\", \"kinetic_energy\", \"profile\" or "
                        "\"wall_pressure\")",
                        r->origin, path, type);
        }
    }
    /* at_max_of may name a monitor listed later in the file */
    for (size_t k = 0; k < c->n_monitors; k++) {
        if (!at_max_of[k]) continue;
        const int j = find_monitor(c, at_max_of[k]);
        if (j < 0 || c->monitors[j].kind != MONITOR_MAX_ELEVATION)
            return FAIL(r, "%s: monitors.%s.at_max_of: '%s' is not one of the max_elevation monitors", r->origin,
                        c->monitors[k].name, at_max_of[k]);
        c->monitors[k].at_max_of = j;
    }
    return MIXSPH_OK;
}

static int find_monitor(const struct case_def *c, const char *name)
{
    for (size_t i = 0; i < c->n_monitors; i++)
        if (strcmp(c->monitors[i].name, name) == 0) return (int)i;
    return -1;
}

/* ---- full-scale report -------------------------------------------------------------------------
 * "full_scale": {"z_scale": 1211.8, "z_offset": 0.3, "unit": "m a.m.s.l.",
 *                "reference": {"monitor": "run_up", "observed": 863.0, "still": 700.0}}
 * Z = z_scale z + z_offset for every max_elevation monitor (output <m>_Z); with the reference,
 * the error (13) of Manenti et al. (2018) of the reference monitor's highest value (<m>_d_eta). */
static mixsph_status read_full_scale(struct reader *r, const cJSON *root, struct case_def *c)
{
    static const char *const keys[] = {"z_scale", "z_offset", "unit", "reference", NULL};
    static const char *const rkeys[] = {"monitor", "observed", "still", NULL};
    struct full_scale *fs = &c->full_scale;
    fs->on = 0;
    fs->ref_monitor = -1;
    const cJSON *f, *ref;
    TRY(get_obj(r, root, "", "full_scale", 0, &f));
    size_t n_scalar = 0;
    for (size_t k = 0; k < c->n_monitors; k++) n_scalar += c->monitors[k].kind != MONITOR_PROFILE;
    if (!f) return MIXSPH_OK;
    TRY(check_keys(r, f, "full_scale", keys));
    fs->z_offset = 0.0;
    TRY(get_num(r, f, "full_scale", "z_scale", 1, 0.0, 1, 1e9, &fs->z_scale));
    TRY(get_num(r, f, "full_scale", "z_offset", 0, -1e9, 0, 1e9, &fs->z_offset));
    const char *unit = "m";
    TRY(get_str(r, f, "full_scale", "unit", 0, &unit));
    if (strlen(unit) >= CASE_NAME_LEN)
        return FAIL(r, "%s: full_scale.unit: expected at most %d characters", r->origin, CASE_NAME_LEN - 1);
    strcpy(fs->unit, unit);
    for (size_t k = 0; k < c->n_monitors; k++) {
        if (c->monitors[k].kind != MONITOR_MAX_ELEVATION) continue;
        n_scalar++;
        if (strlen(c->monitors[k].name) + strlen(CASE_FULL_SCALE_SUFFIX_ERR) >= CASE_NAME_LEN)
            return FAIL(r, "%s: full_scale: the monitor name '%s' is too long for its full-scale outputs '%s%s', "
                        "'%s%s' (expected at most %d characters)", r->origin, c->monitors[k].name, c->monitors[k].name,
                        CASE_FULL_SCALE_SUFFIX_Z, c->monitors[k].name, CASE_FULL_SCALE_SUFFIX_ERR,
                        (int)(CASE_NAME_LEN - 1 - strlen(CASE_FULL_SCALE_SUFFIX_ERR)));
    }
    TRY(get_obj(r, f, "full_scale", "reference", 0, &ref));
    if (ref) {
        TRY(check_keys(r, ref, "full_scale.reference", rkeys));
        const char *mon = NULL;
        TRY(get_str(r, ref, "full_scale.reference", "monitor", 1, &mon));
        fs->ref_monitor = find_monitor(c, mon);
        if (fs->ref_monitor < 0 || c->monitors[fs->ref_monitor].kind != MONITOR_MAX_ELEVATION)
            return FAIL(r, "%s: full_scale.reference.monitor: '%s' is not one of the max_elevation monitors", r->origin, mon);
        TRY(get_num(r, ref, "full_scale.reference", "observed", 1, -1e9, 0, 1e9, &fs->observed));
        TRY(get_num(r, ref, "full_scale.reference", "still", 1, -1e9, 0, 1e9, &fs->still));
        if (!(fs->observed > fs->still))
            return FAIL(r, "%s: full_scale.reference: observed (%g) must lie above still (%g), in full-scale units",
                        r->origin, fs->observed, fs->still);
        n_scalar++;
    }
    if (n_scalar > CASE_MAX_SCALAR_OUTPUTS)
        return FAIL(r, "%s: full_scale: %zu scalar monitors and full-scale outputs (expected at most %d; "
                    "fewer max_elevation monitors)", r->origin, n_scalar, CASE_MAX_SCALAR_OUTPUTS);
    fs->on = 1;
    return MIXSPH_OK;
}

double case_full_scale_z(const struct case_def *c, double z)
{
    return c->full_scale.on ? c->full_scale.z_scale * z + c->full_scale.z_offset : z;
}

double case_full_scale_error(const struct case_def *c, double Z)
{
    const struct full_scale *fs = &c->full_scale;
    if (!fs->on || fs->ref_monitor < 0) return NAN;
    return 100.0 * fabs(Z - fs->observed) / (fs->observed - fs->still);
}

/* ---- parameters ----------------------------------------------------------------------------
 * "parameters": {"reservoir_level": 0.46, ...} names numbers that other values use as the string
 * "$reservoir_level" (e.g. the water's z_max and the saturated part of a landslide), so one
 * override (--set parameters.reservoir_level=0.40) moves all of them. Substituted after the
 * overrides, before validation. */
static mixsph_status substitute(struct reader *r, const cJSON *params, cJSON *node, char *path, size_t len)
{
    for (cJSON *it = node->child; it; it = it->next) {
        const size_t l0 = strlen(path);
        if (it->string) snprintf(path + l0, len - l0, "%s%s", l0 ? "." : "", it->string);
        if (cJSON_IsString(it) && it->valuestring[0] == '$') {
            const cJSON *p = params ? cJSON_GetObjectItemCaseSensitive(params, it->valuestring + 1) : NULL;
            if (!cJSON_IsNumber(p))
                return FAIL(r, "%s: %s: '%s' is not one of the numeric parameters", r->origin, path, it->valuestring);
            cJSON *num = cJSON_CreateNumber(p->valuedouble);
            const int ok = num && (it->string ? cJSON_ReplaceItemInObjectCaseSensitive(node, it->string, num)
                                              : cJSON_ReplaceItemViaPointer(node, it, num));
            if (!ok) return status_set(r->err, r->err_len, MIXSPH_ERR_NOMEM, "out of memory");
            it = num;
        } else if (cJSON_IsObject(it) || cJSON_IsArray(it)) {
            TRY(substitute(r, params, it, path, len));
        }
        path[l0] = '\0';
    }
    return MIXSPH_OK;
}

static mixsph_status apply_parameters(struct reader *r, cJSON *root)
{
    const cJSON *params = cJSON_GetObjectItemCaseSensitive(root, "parameters");
    if (params && !cJSON_IsObject(params)) return FAIL(r, "%s: parameters: expected an object of numbers", r->origin);
    for (const cJSON *p = params ? params->child : NULL; p; p = p->next)
        if (!cJSON_IsNumber(p) || !isfinite(p->valuedouble))
            return FAIL(r, "%s: parameters.%s: expected a number", r->origin, p->string);
    char path[512] = "";
    return substitute(r, params, root, path, sizeof path);
}

static mixsph_status read_root(struct reader *r, const cJSON *root, struct case_def *c)
{
    static const char *const keys[] = {"name", "description", "parameters", "gravity", "numerics", "domain", "media",
                                       "bodies", "walls", "motions", "monitors", "full_scale", "output", NULL};
    static const char *const dkeys[] = {"x_min", "x_max", "z_min", "z_max", NULL};
    static const char *const okeys[] = {"monitor_interval", "snapshot_interval", NULL};
    if (!cJSON_IsObject(root)) return FAIL(r, "%s: the case must be a JSON object", r->origin);
    TRY(check_keys(r, root, "", keys));
    const char *name = NULL, *desc = NULL;
    TRY(get_str(r, root, "", "name", 1, &name));
    TRY(copy_name(r, "name", name, c->name));
    TRY(get_str(r, root, "", "description", 0, &desc));
    c->g = 9.81;
    TRY(get_num(r, root, "", "gravity", 0, 0.0, 0, 100.0, &c->g));
    TRY(read_numerics(r, root, c));
    const cJSON *d;
    TRY(get_obj(r, root, "", "domain", 0, &d));
    if (d) {
        TRY(check_keys(r, d, "domain", dkeys));
        for (int k = 0; k < 4; k++) TRY(get_num(r, d, "domain", dkeys[k], 1, -1e9, 0, 1e9, &c->domain[k]));
        if (!(c->domain[1] > c->domain[0]) || !(c->domain[3] > c->domain[2]))
            return FAIL(r, "%s: domain: expected x_min < x_max and z_min < z_max", r->origin);
        c->has_domain = 1;
    }
    TRY(read_media(r, root, c));
    TRY(read_bodies(r, root, c));
    TRY(read_motions(r, root, c));
    TRY(read_walls(r, root, c));
    TRY(read_monitors(r, root, c));
    TRY(read_full_scale(r, root, c));
    const cJSON *o;
    TRY(get_obj(r, root, "", "output", 0, &o));
    c->monitor_interval = c->t_end / 200.0;
    c->snapshot_interval = 0.0;
    if (o) {
        TRY(check_keys(r, o, "output", okeys));
        TRY(get_num(r, o, "output", "monitor_interval", 0, 0.0, 1, 1e6, &c->monitor_interval));
        TRY(get_num(r, o, "output", "snapshot_interval", 0, 0.0, 0, 1e6, &c->snapshot_interval));
    }
    return MIXSPH_OK;
}

mixsph_status case_parse(const char *json_text, const char *origin, const mixsph_override *ov, size_t n_ov,
                         struct case_def *c, char *err, size_t err_len)
{
    struct reader r = {origin ? origin : "(case)", err, err_len};
    memset(c, 0, sizeof *c);
    snprintf(c->origin, sizeof c->origin, "%s", r.origin);
    if (!json_text) return FAIL(&r, "%s: no case text", r.origin);
    const char *where = NULL;
    cJSON *root = cJSON_ParseWithOpts(json_text, &where, 1);
    if (!root) {
        size_t line = 1;
        for (const char *p = json_text; where && p < where; p++) line += *p == '\n';
        return FAIL(&r, "%s: line %zu: not valid JSON", r.origin, line);
    }
    mixsph_status st = MIXSPH_OK;
    for (size_t k = 0; k < n_ov && st == MIXSPH_OK; k++) st = apply_override(&r, root, &ov[k]);
    if (st == MIXSPH_OK) st = apply_parameters(&r, root);
    if (st == MIXSPH_OK) st = read_root(&r, root, c);
    cJSON_Delete(root);
    if (st != MIXSPH_OK) case_free(c);
    return st;
}

void case_free(struct case_def *c)
{
    for (size_t i = 0; i < CASE_MAX_BODIES; i++) geom_free(&c->bodies[i].polygon);
    for (size_t i = 0; i < CASE_MAX_WALLS; i++) geom_free(&c->walls[i].line);
    for (size_t i = 0; i < CASE_MAX_MOTIONS; i++) {
        free(c->motions[i].t);
        free(c->motions[i].vx);
        free(c->motions[i].vz);
        c->motions[i].t = c->motions[i].vx = c->motions[i].vz = NULL;
    }
}

/* ---- motion laws ------------------------------------------------------------------------- */

/* Interval k and fraction f of law time tl: t[k] <= tl < t[k+1]; k = -1 before, n-1 after. */
static void motion_locate(const struct motion *m, double tl, size_t *k, double *f, int *outside)
{
    *outside = 0;
    if (m->n == 1 || tl <= m->t[0]) {
        *k = 0;
        *f = 0.0;
        *outside = 1;
        return;
    }
    if (tl >= m->t[m->n - 1]) {
        *k = m->n - 1;
        *f = 0.0;
        *outside = 1;
        return;
    }
    size_t lo = 0, hi = m->n - 1;
    while (hi - lo > 1) {
        size_t mid = (lo + hi) / 2;
        if (m->t[mid] <= tl) lo = mid;
        else hi = mid;
    }
    *k = lo;
    *f = (tl - m->t[lo]) / (m->t[lo + 1] - m->t[lo]);
}

void case_motion_velocity(const struct motion *m, double t, double *vx, double *vz)
{
    size_t k;
    double f;
    int outside;
    motion_locate(m, t / m->time_scale, &k, &f, &outside);
    if (outside) {
        *vx = m->speed_scale * m->vx[k];
        *vz = m->speed_scale * m->vz[k];
        return;
    }
    *vx = m->speed_scale * (m->vx[k] + f * (m->vx[k + 1] - m->vx[k]));
    *vz = m->speed_scale * (m->vz[k] + f * (m->vz[k + 1] - m->vz[k]));
}

void case_motion_acceleration(const struct motion *m, double t, double *ax, double *az)
{
    size_t k;
    double f;
    int outside;
    motion_locate(m, t / m->time_scale, &k, &f, &outside);
    if (outside) {
        *ax = *az = 0.0;
        return;
    }
    const double dt = (m->t[k + 1] - m->t[k]) * m->time_scale;
    *ax = m->speed_scale * (m->vx[k + 1] - m->vx[k]) / dt;
    *az = m->speed_scale * (m->vz[k + 1] - m->vz[k]) / dt;
}
