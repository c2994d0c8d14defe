/* case.c - JSON case files (cJSON): overrides, "$name" parameters, reading and validation, motion
 * laws. Each section's keys (type, range, default, field) are the tables of case_schema.c, which
 * also make the key tables of docs/cases.md; here are the rules between keys. Every message has
 * the form "<file>: <key path>: <what was expected>". */
#include "case.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case_schema.h"
#include "law_registry.h"
#include "status.h"
#include "viscous.h"
#include "wall_surface.h"

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
        status_set(err, err_len, MIXSPH_ERR_ARG, "override '%s': value '%s' is not a finite number (a choice such as "
                   "numerics.viscosity takes its number: docs/cases.md)", text, eq + 1);
        *eq = '=';
        return MIXSPH_ERR_ARG;
    }
    out->key = text;
    out->value = v;
    return MIXSPH_OK;
}

static mixsph_status apply_override(const struct case_reader *r, cJSON *root, const mixsph_override *ov)
{
    char path[256];
    if (!ov->key || strlen(ov->key) >= sizeof path) return FAIL(r, "%s: override key missing or too long", r->origin);
    if (!isfinite(ov->value)) return FAIL(r, "%s: override %s: value is not finite", r->origin, ov->key);
    strcpy(path, ov->key);
    cJSON *node = root, *parent = NULL;
    for (char *save = NULL, *tok = strtok_r(path, ".", &save); tok; tok = strtok_r(NULL, ".", &save)) {
        parent = node;
        char *rest = save && *save ? save : NULL;
        if (!rest && cJSON_IsObject(node) && !cJSON_GetObjectItemCaseSensitive(node, tok)) {
            /* a parameter the case does not declare would reach nothing (no "$name" uses it) */
            if (node == cJSON_GetObjectItemCaseSensitive(root, "parameters"))
                return FAIL(r, "%s: override %s: the case declares no parameter '%s' in its parameters block, so the "
                               "value would change nothing", r->origin, ov->key, tok);
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
    } else if (cJSON_IsString(node)) {
        /* a choice that also takes its number (numerics.viscosity); validation refuses the rest */
        cJSON *num = cJSON_CreateNumber(ov->value);
        if (!num) return status_set(r->err, r->err_len, MIXSPH_ERR_NOMEM, "out of memory");
        num->string = node->string; /* the key's name moves to the new item */
        node->string = NULL;
        if (!parent || !cJSON_ReplaceItemViaPointer(parent, node, num)) {
            node->string = num->string;
            num->string = NULL;
            cJSON_Delete(num);
            return FAIL(r, "%s: override %s: the key is not a number or a Boolean", r->origin, ov->key);
        }
    } else {
        return FAIL(r, "%s: override %s: the key is not a number or a Boolean", r->origin, ov->key);
    }
    return MIXSPH_OK;
}

/* ---- sections ------------------------------------------------------------------------------
 * Each section is read by its table (case_schema.c: keys, types, ranges, defaults, fields); what
 * follows here are the rules between keys and the names that refer to other entries. */

#define TRY(expr)                         \
    do {                                  \
        mixsph_status st_ = (expr);       \
        if (st_ != MIXSPH_OK) return st_; \
    } while (0)

static const cJSON *item(const cJSON *obj, const char *key) { return cJSON_GetObjectItemCaseSensitive(obj, key); }

static const struct case_section *section(const char *id) { return case_schema_find(id); }

/* Names end up in CSV headers, file names, JSON and FMU variable lookups unquoted: a plain
 * identifier (a letter or '_', then letters, digits, '_' or '-') can be written anywhere safely. */
static int plain_identifier(const char *name)
{
    const unsigned char *c = (const unsigned char *)name;
    if (!((*c >= 'A' && *c <= 'Z') || (*c >= 'a' && *c <= 'z') || *c == '_')) return 0;
    for (c++; *c; c++)
        if (!((*c >= 'A' && *c <= 'Z') || (*c >= 'a' && *c <= 'z') || (*c >= '0' && *c <= '9') || *c == '_' ||
              *c == '-'))
            return 0;
    return 1;
}

#define NAME_RULE "a letter or '_', then letters, digits, '_' or '-'"

/* A name as a C string literal for a message (quotes, backslashes and control characters escaped),
 * cut short to fit. */
static void quoted_name(const char *name, char *buf, size_t len)
{
    size_t at = 0;
    buf[at++] = '"';
    for (const unsigned char *c = (const unsigned char *)name; *c && at + 8 < len; c++) {
        if (*c == '"' || *c == '\\') at += (size_t)snprintf(buf + at, len - at, "\\%c", *c);
        else if (*c == '\n') at += (size_t)snprintf(buf + at, len - at, "\\n");
        else if (*c < 0x20 || *c >= 0x7f) at += (size_t)snprintf(buf + at, len - at, "\\x%02x", *c);
        else buf[at++] = (char)*c;
    }
    snprintf(buf + at, len - at, "\"");
}

/* Name `name` of an entry of section `sec` ("media", ...) into dst. */
static mixsph_status copy_name(const struct case_reader *r, const char *sec, const char *name, char *dst)
{
    char q[2 * CASE_NAME_LEN + 16];
    quoted_name(name, q, sizeof q);
    if (strlen(name) == 0 || strlen(name) >= CASE_NAME_LEN)
        return FAIL(r, "%s: %s: the name %s must have 1 to %d characters", r->origin, sec, q, CASE_NAME_LEN - 1);
    if (!plain_identifier(name))
        return FAIL(r, "%s: %s: the name %s is not a plain identifier (expected " NAME_RULE ")", r->origin, sec, q);
    strcpy(dst, name);
    return MIXSPH_OK;
}

/* Entry `it` of a section of named entries ("media", ...): its key path, an object, a name. */
static mixsph_status entry(const struct case_reader *r, const cJSON *it, const char *sec, size_t n, size_t max,
                           char *path, size_t len, char *name)
{
    TRY(copy_name(r, sec, it->string, name)); /* first: the path would hold the name */
    snprintf(path, len, "%s.%s", sec, it->string);
    if (!cJSON_IsObject(it)) return FAIL(r, "%s: %s: expected an object", r->origin, path);
    if (n == max) return FAIL(r, "%s: %s: at most %zu entries", r->origin, sec, max);
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

static int find_wall(const struct case_def *c, const char *name)
{
    for (size_t i = 0; i < c->n_walls; i++)
        if (strcmp(c->walls[i].name, name) == 0) return (int)i;
    return -1;
}

static int find_monitor(const struct case_def *c, const char *name)
{
    for (size_t i = 0; i < c->n_monitors; i++)
        if (strcmp(c->monitors[i].name, name) == 0) return (int)i;
    return -1;
}

static mixsph_status read_numerics(const struct case_reader *r, const cJSON *root, struct case_def *c)
{
    TRY(case_schema_read(r, item(root, "numerics"), "numerics", section("numerics"), 0, c));
    if (c->wall_layers < (int)ceil(2.0 * c->h_over_dx))
        return FAIL(r, "%s: numerics.wall_layers: %d layers do not cover the kernel support 2h = %.2f dx (expected >= %d)",
                    r->origin, c->wall_layers, 2.0 * c->h_over_dx, (int)ceil(2.0 * c->h_over_dx));
    /* the coarse level of two_level is written for the groups of a 2D cell grid (viscous_coarse.h) */
    if (c->dimensions == 3 && c->viscous_preconditioner == VISCOUS_TWO_LEVEL) {
        if (item(item(root, "numerics"), "viscous_preconditioner"))
            return FAIL(r, "%s: numerics.viscous_preconditioner: \"two_level\" is 2D only (its coarse level groups the "
                           "cell rows of a 2D grid); a 3D case takes \"jacobi\", its default there", r->origin);
        c->viscous_preconditioner = VISCOUS_JACOBI;
    }
    if (c->viscosity_arithmetic && !c->viscosity_implicit)
        return FAIL(r, "%s: numerics.viscosity_mean: \"arithmetic\" needs numerics.viscosity \"implicit\" (the "
                       "explicit time step (4) is sized for the harmonic mean: a mobile grain beside a fixed one "
                       "would be coupled at about mu_thr / 2)",
                    r->origin);
    return MIXSPH_OK;
}

/* What a material law's finish may ask of the case entry it reads (laws/law.h). */
static int entry_given(const void *entry, const char *key) { return item(entry, key) != NULL; }

static const char *entry_text(const void *entry, const char *key)
{
    const cJSON *v = item(entry, key);
    return cJSON_IsString(v) ? v->valuestring : NULL;
}

static double entry_number(const void *entry, const char *key)
{
    const cJSON *v = item(entry, key);
    return cJSON_IsNumber(v) ? v->valuedouble : NAN;
}

/* A medium whose law is chosen by a number (a case parameter, "law": "$rheology": the FMU's
 * rheology) may also hold the keys of its type's other laws, so that one case file runs with
 * either law (docs/cases.md): each such key is checked by its own law's row (type, range) and not
 * used. A medium that names its law gets them refused by its law's table, as any unknown key.
 * *own: a copy of the entry without them, which the chosen law's table reads (a key that no law
 * of the type has stays, and that table refuses it). */
static mixsph_status drop_other_laws_keys(const struct case_reader *r, const cJSON *it, const char *path, int law,
                                          cJSON **own)
{
    *own = cJSON_Duplicate(it, 1);
    if (!*own) return status_set(r->err, r->err_len, MIXSPH_ERR_NOMEM, "out of memory");
    for (cJSON *k = (*own)->child, *next; k; k = next) {
        next = k->next;
        if (case_schema_key(law_get(law)->keys, k->string)) continue;
        const struct case_key *row = NULL;
        for (int id = 0; id < LAW_COUNT && !row; id++)
            if (id != law && strcmp(law_get(id)->type, law_get(law)->type) == 0)
                row = case_schema_key(law_get(id)->keys, k->string);
        if (!row) continue;
        struct medium unused;
        memset(&unused, 0, sizeof unused);
        const mixsph_status st = case_schema_read_key(r, *own, path, row, &unused);
        if (st != MIXSPH_OK) {
            cJSON_Delete(*own);
            *own = NULL;
            return st;
        }
        cJSON_Delete(cJSON_DetachItemViaPointer(*own, k));
    }
    return MIXSPH_OK;
}

/* A medium that names no law runs the one its keys imply (law_unnamed); a key of its type's first
 * law that the implied law has not is refused by name, with what would make it valid. */
static mixsph_status read_unnamed_law(const struct case_reader *r, const cJSON *entry, const char *path,
                                      struct medium *md)
{
    const int first = md->law;
    md->law = law_unnamed(first, entry_given, entry);
    if (md->law == first) return MIXSPH_OK;
    for (const cJSON *k = entry->child; k; k = k->next)
        if (!case_schema_key(law_get(md->law)->keys, k->string) && case_schema_key(law_get(first)->keys, k->string))
            return FAIL(r, "%s: %s.%s: a key of the %s law, which this medium does not run: with no \"law\" and "
                           "none of that law's required keys, it runs the %s law (docs/cases.md); name \"law\": "
                           "\"%s\" and give its keys, or remove %s", r->origin, path, k->string, law_get(first)->name,
                        law_get(md->law)->name, law_get(first)->name, k->string);
    return MIXSPH_OK;
}

/* A medium: its type selects its material law (laws/law_registry.h), whose key table it is read
 * by; a law with both K and c takes exactly one of them; then the law's own rules (finish). */
static mixsph_status read_medium(const struct case_reader *r, const cJSON *entry, const char *path, struct case_def *c,
                                 struct medium *md)
{
    struct case_choice types[LAW_COUNT + 1]; /* each type once, with its first law */
    size_t n_types = 0;
    for (int id = 0; id < LAW_COUNT; id++) {
        size_t k = 0;
        while (k < n_types && strcmp(types[k].name, law_get(id)->type) != 0) k++;
        if (k == n_types) types[n_types++] = (struct case_choice){law_get(id)->type, id};
    }
    types[n_types] = (struct case_choice){NULL, 0};
    const struct case_key type_key = {.key = "type", .type = CASE_CHOICE, .need = CASE_REQUIRED, .choices = types,
                                      .field = CASE_FIELD(medium, law)};
    TRY(case_schema_read_key(r, entry, path, &type_key, md));
    /* a type with several laws: its key `law` (a row of each of their tables) chooses one */
    const struct case_key *law_key = case_schema_key(law_get(md->law)->keys, "law");
    if (law_key && item(entry, "law")) TRY(case_schema_read_key(r, entry, path, law_key, md));
    else if (law_key) TRY(read_unnamed_law(r, entry, path, md));
    const struct material_law *law = law_get(md->law);
    cJSON *own = NULL; /* the entry without the other laws' keys, when a number chose the law */
    if (cJSON_IsNumber(item(entry, "law"))) TRY(drop_other_laws_keys(r, entry, path, md->law, &own));
    const cJSON *it = own ? own : entry;
    mixsph_status st = case_schema_read(r, it, path, law->keys, 0, md);
    if (st == MIXSPH_OK && case_schema_key(law->keys, "K") && case_schema_key(law->keys, "c") &&
        !item(it, "K") == !item(it, "c"))
        st = FAIL(r, "%s: %s: expected exactly one of K (bulk modulus, Pa) or c (sound speed, m/s)", r->origin, path);
    md->features = law->features;
    const struct law_finish_ctx ctx = {.media = c->media, .n_media = c->n_media + 1, .given = entry_given,
                                       .text = entry_text, .number = entry_number, .entry = it, .origin = r->origin,
                                       .path = path, .err = r->err, .err_len = r->err_len};
    if (st == MIXSPH_OK && law->finish) st = law->finish(md, &ctx);
    cJSON_Delete(own);
    return st;
}

static mixsph_status read_media(const struct case_reader *r, const cJSON *root, struct case_def *c)
{
    for (const cJSON *it = item(root, "media")->child; it; it = it->next) {
        char path[128];
        struct medium *md = &c->media[c->n_media < CASE_MAX_MEDIA ? c->n_media : 0];
        TRY(entry(r, it, "media", c->n_media, CASE_MAX_MEDIA, path, sizeof path, md->name));
        TRY(read_medium(r, it, path, c, md));
        c->n_media++;
    }
    if (c->n_media == 0) return FAIL(r, "%s: media: expected at least one medium", r->origin);
    return MIXSPH_OK;
}

/* A 3D body's corner key box_min or box_max: exactly three numbers [x, y, z]. */
static mixsph_status read_corner(const struct case_reader *r, const cJSON *it, const char *path, const char *key,
                                 double corner[3])
{
    double *v = NULL;
    size_t n = 0;
    TRY(case_schema_numbers(r, it, path, key, 3, &v, &n));
    for (size_t d = 0; d < 3 && n == 3; d++) corner[d] = v[d];
    free(v);
    if (n != 3) return FAIL(r, "%s: %s.%s: expected 3 numbers [x, y, z], got %zu", r->origin, path, key, n);
    return MIXSPH_OK;
}

/* The shape of a body (enum body_shape): a 2D case's is its polygon; a 3D case's body takes one
 * of polygon (with y_min and y_max), box_min with box_max, or stl, and with none of them is the
 * domain below its z_max. An STL path is resolved against the case file's folder. */
static mixsph_status read_body_shape(const struct case_reader *r, const cJSON *it, const char *path,
                                     const struct case_def *c, struct body *bd)
{
    const int polygon = item(it, "polygon") != NULL, box = item(it, "box_min") || item(it, "box_max"),
              stl = item(it, "stl") != NULL, across = item(it, "y_min") || item(it, "y_max");
    bd->shape = BODY_POLYGON;
    if (c->dimensions == 2) {
        if (box || stl || across)
            return FAIL(r, "%s: %s: box_min, box_max, stl, y_min and y_max are keys of a 3D case (this case has "
                           "dimensions 2)", r->origin, path);
        if (!polygon) return FAIL(r, "%s: %s.polygon: missing (expected an array of [x, z] points)", r->origin, path);
        return MIXSPH_OK;
    }
    if (polygon + box + stl > 1)
        return FAIL(r, "%s: %s: expected one shape: polygon (with y_min, y_max), box_min with box_max, or stl",
                    r->origin, path);
    if (across && !polygon)
        return FAIL(r, "%s: %s: y_min and y_max extrude a polygon (this body has none)", r->origin, path);
    if (polygon) {
        if (!item(it, "y_min") || !item(it, "y_max") || !(bd->y_max > bd->y_min))
            return FAIL(r, "%s: %s: a 3D polygon body needs y_min < y_max (its extrusion across y)", r->origin, path);
        return MIXSPH_OK;
    }
    if (box) {
        if (!item(it, "box_min") || !item(it, "box_max"))
            return FAIL(r, "%s: %s: a box needs both box_min and box_max", r->origin, path);
        TRY(read_corner(r, it, path, "box_min", bd->box_min));
        TRY(read_corner(r, it, path, "box_max", bd->box_max));
        for (int d = 0; d < 3; d++)
            if (!(bd->box_max[d] > bd->box_min[d]))
                return FAIL(r, "%s: %s: expected box_min < box_max on every axis (axis %c: %g, %g)", r->origin, path,
                            "xyz"[d], bd->box_min[d], bd->box_max[d]);
        bd->shape = BODY_BOX;
        return MIXSPH_OK;
    }
    if (stl) {
        const char *given = item(it, "stl")->valuestring; /* its length checked by its row */
        snprintf(bd->stl, sizeof bd->stl, "%s", given);
        const char *slash = strrchr(r->origin, '/');
        if (given[0] != '/' && slash) {
            const int dir_len = (int)(slash - r->origin);
            if (snprintf(bd->stl, sizeof bd->stl, "%.*s/%s", dir_len, r->origin, given) >= (int)sizeof bd->stl)
                return FAIL(r, "%s: %s.stl: the path with the case's folder is over %d characters", r->origin, path,
                            CASE_PATH_LEN - 1);
        }
        bd->shape = BODY_STL;
        return MIXSPH_OK;
    }
    if (!isfinite(bd->z_max) || !c->has_domain)
        return FAIL(r, "%s: %s: a 3D body without a shape (polygon, box_min/box_max or stl) fills the domain below "
                       "its z_max: it needs z_max and the case's domain", r->origin, path);
    bd->shape = BODY_BELOW_LEVEL;
    return MIXSPH_OK;
}

static mixsph_status read_bodies(const struct case_reader *r, const cJSON *root, struct case_def *c)
{
    for (const cJSON *it = item(root, "bodies")->child; it; it = it->next) {
        char path[128];
        struct body *bd = &c->bodies[c->n_bodies < CASE_MAX_BODIES ? c->n_bodies : 0];
        TRY(entry(r, it, "bodies", c->n_bodies, CASE_MAX_BODIES, path, sizeof path, bd->name));
        c->n_bodies++;
        TRY(case_schema_read(r, it, path, section("bodies"), 0, bd));
        const char *medium = item(it, "medium")->valuestring;
        bd->medium = find_medium(c, medium);
        if (bd->medium < 0) return FAIL(r, "%s: %s.medium: '%s' is not one of the media", r->origin, path, medium);
        TRY(read_body_shape(r, it, path, c, bd));
    }
    if (c->n_bodies == 0) return FAIL(r, "%s: bodies: expected at least one body", r->origin);
    return MIXSPH_OK;
}

/* Whether the case is three-dimensional: a build runs the cases of its own dimension. */
static int case_is_3d(const struct case_def *c) { return c->dimensions == 3; }

static mixsph_status read_motions(const struct case_reader *r, const cJSON *root, struct case_def *c)
{
    const cJSON *m = item(root, "motions");
    for (const cJSON *it = m ? m->child : NULL; it; it = it->next) {
        char path[128];
        struct motion *mo = &c->motions[c->n_motions < CASE_MAX_MOTIONS ? c->n_motions : 0];
        TRY(entry(r, it, "motions", c->n_motions, CASE_MAX_MOTIONS, path, sizeof path, mo->name));
        c->n_motions++;
        TRY(case_schema_read(r, it, path, section("motions"), 0, mo));
        size_t nt = 0, nx = 0, nz = 0, ny = 0;
        TRY(case_schema_numbers(r, it, path, "t", 1, &mo->t, &nt));
        TRY(case_schema_numbers(r, it, path, "vx", 1, &mo->vx, &nx));
        TRY(case_schema_numbers(r, it, path, "vz", 1, &mo->vz, &nz));
        if (nx != nt || nz != nt)
            return FAIL(r, "%s: %s: t, vx and vz must have the same length (%zu, %zu, %zu)", r->origin, path, nt, nx, nz);
        if (item(it, "vy")) {
            if (!case_is_3d(c)) return FAIL(r, "%s: %s.vy: a 2D case has no velocity across y", r->origin, path);
            TRY(case_schema_numbers(r, it, path, "vy", 1, &mo->vy, &ny));
            if (ny != nt) return FAIL(r, "%s: %s.vy: as many values as t (%zu, expected %zu)", r->origin, path, ny, nt);
        }
        for (size_t k = 1; k < nt; k++)
            if (!(mo->t[k] > mo->t[k - 1])) return FAIL(r, "%s: %s.t[%zu]: times must increase", r->origin, path, k);
        mo->n = nt;
        /* stroke_scale scales the displacement: with the duration stretched by time_scale, the
         * velocities scale by stroke_scale / time_scale */
        const cJSON *stroke = item(it, "stroke_scale");
        if (stroke) {
            if (item(it, "speed_scale")) return FAIL(r, "%s: %s: give speed_scale or stroke_scale, not both", r->origin, path);
            mo->speed_scale = stroke->valuedouble / mo->time_scale;
        }
    }
    return MIXSPH_OK;
}

/* The faces of a box wall: all but those its open_faces names (default: the top). */
static mixsph_status read_box_faces(const struct case_reader *r, const cJSON *it, const char *path, struct wall *wl)
{
    static const char *const names[] = {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"};
    const cJSON *open = item(it, "open_faces");
    const char *text = open ? open->valuestring : "z_max";
    wl->box_faces = MESH_BOX_ALL;
    if (strcmp(text, "none") == 0) return MIXSPH_OK;
    for (const char *at = text; *at;) {
        const size_t len = strcspn(at, ", ");
        int found = -1;
        for (int f = 0; f < 6; f++)
            if (len == strlen(names[f]) && strncmp(at, names[f], len) == 0) found = f;
        if (found < 0 && len > 0)
            return FAIL(r, "%s: %s.open_faces: '%.*s' is not a face (expected x_min, x_max, y_min, y_max, z_min, z_max "
                           "or none)", r->origin, path, (int)len, at);
        if (found >= 0) wl->box_faces &= ~(1u << found); /* MESH_BOX_XMIN = 1, ... in this order */
        at += len;
        at += strspn(at, ", ");
    }
    return MIXSPH_OK;
}

/* The form of a wall: the one geometry key its entry holds. */
static mixsph_status read_wall_form(const struct case_reader *r, const cJSON *it, const char *path, const struct case_def *c,
                                    struct wall *wl)
{
    static const struct { const char *key; int form; } forms[] = {{"polyline", WALL_FORM_POLYLINE}, {"box_min", WALL_FORM_BOX},
        {"box_max", WALL_FORM_BOX}, {"stl", WALL_FORM_STL}, {"terrain", WALL_FORM_TERRAIN}};
    const char *key = NULL;
    for (size_t k = 0; k < SCHEMA_COUNT(forms); k++) {
        if (!item(it, forms[k].key)) continue;
        if (key && wl->form != forms[k].form)
            return FAIL(r, "%s: %s: give one geometry (polyline, box_min and box_max, stl or terrain), not %s and %s",
                        r->origin, path, key, forms[k].key);
        if (!key) key = forms[k].key; /* the first, named in messages */
        wl->form = forms[k].form;
    }
    if (!key) return FAIL(r, "%s: %s: missing its geometry (expected polyline, box_min and box_max, stl or terrain)",
                          r->origin, path);
    if (wl->form != WALL_FORM_POLYLINE && !case_is_3d(c))
        return FAIL(r, "%s: %s.%s: a 3D geometry, and this case is 2D (its walls are polylines)", r->origin, path, key);
    static const char *const across_y[] = {"y_min", "y_max", "side_walls", "side_walls_z_max"};
    for (size_t k = 0; k < SCHEMA_COUNT(across_y) && wl->form == WALL_FORM_POLYLINE; k++) {
        const int given = item(it, across_y[k]) != NULL;
        if (given && !case_is_3d(c))
            return FAIL(r, "%s: %s.%s: only a 3D case extrudes a polyline across y (this case is 2D)", r->origin, path,
                        across_y[k]);
        if (!given && k < 2 && case_is_3d(c))
            return FAIL(r, "%s: %s.%s: missing (a polyline wall of a 3D case is extruded from y_min to y_max)",
                        r->origin, path, across_y[k]);
    }
    return MIXSPH_OK;
}

/* The folder of the case file named by origin, "" when it has none. */
static void case_folder(const char *origin, char *dir, size_t len)
{
    const char *slash = strrchr(origin, '/');
    const size_t n = slash ? (size_t)(slash - origin) : 0;
    snprintf(dir, len, "%.*s", (int)(n < len ? n : len - 1), origin);
    if (slash && n == 0) snprintf(dir, len, "/");
}

/* A 3D wall's surface, and a flume's side walls as the next wall. */
static mixsph_status build_wall_surface(const struct case_reader *r, const cJSON *it, const char *path,
                                        struct case_def *c, struct wall *wl)
{
    char dir[sizeof c->origin], why[384];
    case_folder(r->origin, dir, sizeof dir);
    if (wl->form == WALL_FORM_BOX) {
        double *lo = NULL, *hi = NULL;
        size_t n_lo = 0, n_hi = 0;
        mixsph_status st = case_schema_numbers(r, it, path, "box_min", 3, &lo, &n_lo);
        if (st == MIXSPH_OK) st = case_schema_numbers(r, it, path, "box_max", 3, &hi, &n_hi);
        if (st == MIXSPH_OK && (n_lo != 3 || n_hi != 3))
            st = FAIL(r, "%s: %s: box_min and box_max are points [x, y, z] (found %zu and %zu numbers)", r->origin, path,
                      n_lo, n_hi);
        for (int d = 0; d < 3 && st == MIXSPH_OK; d++) {
            wl->box_min[d] = lo[d];
            wl->box_max[d] = hi[d];
        }
        free(lo);
        free(hi);
        TRY(st);
        TRY(read_box_faces(r, it, path, wl));
    }
    if (wall_surface_build(wl, dir, why, sizeof why) != MIXSPH_OK)
        return FAIL(r, "%s: %s: %s", r->origin, path, why);
    if (wl->form != WALL_FORM_POLYLINE || wl->side_walls == WALL_SIDES_NONE) return MIXSPH_OK;
    if (wl->side_walls == WALL_SIDES_MIRROR) return MIXSPH_OK; /* images, no wall (walls/mirror_sides.h) */
    if (c->n_walls == CASE_MAX_WALLS)
        return FAIL(r, "%s: %s.side_walls: at most %d walls, with the side walls", r->origin, path, CASE_MAX_WALLS);
    struct wall *sides = &c->walls[c->n_walls];
    if (wall_side_walls(wl, sides, why, sizeof why) != MIXSPH_OK) return FAIL(r, "%s: %s.side_walls: %s", r->origin, path, why);
    if (find_wall(c, sides->name) >= 0)
        return FAIL(r, "%s: %s.side_walls: a wall is already named %s", r->origin, path, sides->name);
    c->n_walls++;
    return MIXSPH_OK;
}

/* The wall's friction angle on each medium (struct wall friction_of_medium_deg): its key `friction`
 * as a number for every medium, or as an object naming granular media (range checked by the
 * schema), the others taking the default (NaN: the grains' own phi; the paper law then takes none). */
static mixsph_status read_wall_friction(const struct case_reader *r, const cJSON *it, const char *path,
                                        const struct case_def *c, struct wall *wl)
{
    for (size_t k = 0; k < WALL_MEDIA_MAX; k++) wl->friction_of_medium_deg[k] = wl->friction_deg;
    const cJSON *by_name = item(it, "friction");
    if (!cJSON_IsObject(by_name)) return MIXSPH_OK;
    for (const cJSON *e = by_name->child; e; e = e->next) {
        const int k = find_medium(c, e->string);
        if (k < 0) return FAIL(r, "%s: %s.friction.%s: '%s' is not one of the media", r->origin, path, e->string, e->string);
        const struct medium *md = &c->media[k];
        if (!(md->features & (LAW_WALL_FRICTION | LAW_WALL_FRICTION_GIVEN)))
            return FAIL(r, "%s: %s.friction.%s: medium %s (type %s) takes no bed friction: a wall's friction acts on "
                           "granular media only", r->origin, path, e->string, md->name, law_get(md->law)->type);
        wl->friction_of_medium_deg[k] = e->valuedouble;
    }
    return MIXSPH_OK;
}

static mixsph_status read_walls(const struct case_reader *r, const cJSON *root, struct case_def *c)
{
    for (const cJSON *it = item(root, "walls")->child; it; it = it->next) {
        char path[128];
        struct wall *wl = &c->walls[c->n_walls < CASE_MAX_WALLS ? c->n_walls : 0];
        TRY(entry(r, it, "walls", c->n_walls, CASE_MAX_WALLS, path, sizeof path, wl->name));
        c->n_walls++;
        wl->friction_deg = NAN; /* not given: the grains' own phi */
        wl->y_min = wl->y_max = wl->side_walls_z_max = NAN;
        wl->side_walls = WALL_SIDES_NONE;
        TRY(read_wall_form(r, it, path, c, wl));
        TRY(case_schema_read(r, it, path, section("walls"), 1u << wl->form, wl));
        if (wl->form == WALL_FORM_POLYLINE && !item(it, "fluid_side"))
            return FAIL(r, "%s: %s.fluid_side: missing (expected a string)", r->origin, path);
        TRY(read_wall_friction(r, it, path, c, wl));
        const cJSON *file = item(it, wl->form == WALL_FORM_STL ? "stl" : "terrain"); /* its length checked */
        if (file && (wl->form == WALL_FORM_STL || wl->form == WALL_FORM_TERRAIN))
            snprintf(wl->file, sizeof wl->file, "%s", file->valuestring);
        wl->motion = -1;
        const cJSON *motion = item(it, "motion");
        if (motion) {
            wl->motion = find_motion(c, motion->valuestring);
            if (wl->motion < 0)
                return FAIL(r, "%s: %s.motion: '%s' is not one of the motions", r->origin, path, motion->valuestring);
        }
        if (case_is_3d(c)) TRY(build_wall_surface(r, it, path, c, wl));
    }
    /* a 3D case may have none (particles in the domain alone; 3D walls come with their own keys) */
    if (c->n_walls == 0 && c->dimensions == 2) return FAIL(r, "%s: walls: expected at least one wall", r->origin);
    return MIXSPH_OK;
}

/* The times of a profile (at most CASE_MAX_PROFILE_TIMES, increasing); none with at_max_of alone. */
static mixsph_status read_profile_times(const struct case_reader *r, const cJSON *it, const char *path,
                                        struct monitor_def *md)
{
    double *t = NULL;
    size_t nt = 0;
    if (!item(it, "at_max_of") || item(it, "times")) TRY(case_schema_numbers(r, it, path, "times", 1, &t, &nt));
    if (nt > CASE_MAX_PROFILE_TIMES) {
        free(t);
        return FAIL(r, "%s: %s.times: at most %d times", r->origin, path, CASE_MAX_PROFILE_TIMES);
    }
    for (size_t k = 0; k < nt; k++) md->times[k] = t[k];
    md->n_times = nt;
    free(t);
    for (size_t k = 1; k < nt; k++)
        if (!(md->times[k] > md->times[k - 1]))
            return FAIL(r, "%s: %s.times[%zu]: times must increase", r->origin, path, k);
    return MIXSPH_OK;
}

/* What a monitor takes in the case's dimension: the y keys in 3D only; in 3D, a pressure probe's
 * point is (x, y, z) (in the flow, or a sensor on a wall), a wall_pressure's region a box, and no
 * profile (x bins of a 2D section). */
static mixsph_status read_monitor_dimension(const struct case_reader *r, const cJSON *it, const char *path,
                                            const struct case_def *c, const struct monitor_def *md)
{
    const int across = item(it, "y") || item(it, "y_min") || item(it, "y_max");
    if (c->dimensions == 2) {
        if (across) return FAIL(r, "%s: %s: y, y_min and y_max are keys of a 3D case (this case has dimensions 2)",
                                r->origin, path);
        return MIXSPH_OK;
    }
    if (md->kind == MONITOR_PROFILE)
        return FAIL(r, "%s: %s: a profile monitor is 2D only (in 3D: max_elevation over a region with x and y "
                       "ranges, pressure_probe at a point, wall_pressure, kinetic_energy, front, wall_work)", r->origin, path);
    if (md->kind == MONITOR_PRESSURE_PROBE && !item(it, "y"))
        return FAIL(r, "%s: %s.y: missing (a 3D probe's point is x, y, z)", r->origin, path);
    if (md->kind == MONITOR_WAVE_GAUGE && !item(it, "y"))
        return FAIL(r, "%s: %s.y: missing (a 3D wave gauge's station is x, y)", r->origin, path);
    if (!(md->y_max > md->y_min)) return FAIL(r, "%s: %s: expected y_min < y_max", r->origin, path);
    return MIXSPH_OK;
}

static mixsph_status read_monitors(const struct case_reader *r, const cJSON *root, struct case_def *c)
{
    const struct case_section *sec = section("monitors");
    const char *at_max_of[CASE_MAX_MONITORS] = {NULL};
    const cJSON *m = item(root, "monitors");
    for (const cJSON *it = m ? m->child : NULL; it; it = it->next) {
        char path[128];
        struct monitor_def *md = &c->monitors[c->n_monitors < CASE_MAX_MONITORS ? c->n_monitors : 0];
        TRY(entry(r, it, "monitors", c->n_monitors, CASE_MAX_MONITORS, path, sizeof path, md->name));
        c->n_monitors++;
        md->medium = md->wall = -1;
        md->at_max_of = -1;
        md->x_min = md->y_min = md->z_min = -INFINITY; /* everywhere: the region of a monitor that takes none */
        md->x_max = md->y_max = md->z_max = INFINITY;
        md->point_y = 0.0;
        /* the type first: it says which keys the monitor takes */
        TRY(case_schema_read_key(r, it, path, case_schema_key(sec, "type"), md));
        if (md->kind == MONITOR_PROFILE || md->kind == MONITOR_RUNOUT) md->bin = c->dx;
        md->window = 2.0 * c->dx;
        md->quantile = 1.0;
        TRY(case_schema_read(r, it, path, sec, 1u << md->kind, md));
        if (!(md->x_max > md->x_min) || !(md->z_max > md->z_min))
            return FAIL(r, "%s: %s: expected x_min < x_max and z_min < z_max", r->origin, path);
        TRY(read_monitor_dimension(r, it, path, c, md));
        if (md->kind == MONITOR_WALL_PRESSURE || md->kind == MONITOR_WALL_WORK || md->kind == MONITOR_PRESSURE_PROBE) {
            const cJSON *w = item(it, "wall");
            if (!w && md->kind == MONITOR_PRESSURE_PROBE) continue; /* a point in the flow */
            if (!w) return FAIL(r, "%s: %s.wall: missing (expected a string)", r->origin, path);
            const char *wall = w->valuestring;
            md->wall = find_wall(c, wall);
            if (md->wall < 0) return FAIL(r, "%s: %s.wall: '%s' is not one of the walls", r->origin, path, wall);
            continue;
        }
        const char *medium = item(it, "medium")->valuestring;
        md->medium = find_medium(c, medium);
        if (md->medium < 0) return FAIL(r, "%s: %s.medium: '%s' is not one of the media", r->origin, path, medium);
        for (const char *const *x = case_monitor_extras(md->kind); *x; x++)
            if (strlen(md->name) + strlen(*x) >= CASE_NAME_LEN)
                return FAIL(r, "%s: %s: the name is too long for the monitor's output '%s%s' (expected at most %d "
                            "characters)", r->origin, path, md->name, *x, (int)(CASE_NAME_LEN - 1 - strlen(*x)));
        if (md->kind == MONITOR_RUNOUT && (!isfinite(md->x_min) || !isfinite(md->x_max)))
            return FAIL(r, "%s: %s: a runout monitor needs x_min and x_max (the span of its columns)", r->origin, path);
        if (md->kind == MONITOR_PROFILE) {
            if (!isfinite(md->x_min) || !isfinite(md->x_max))
                return FAIL(r, "%s: %s: a profile needs x_min and x_max", r->origin, path);
            const cJSON *a = item(it, "at_max_of");
            at_max_of[c->n_monitors - 1] = a ? a->valuestring : NULL;
            TRY(read_profile_times(r, it, path, md));
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

/* ---- full-scale report -------------------------------------------------------------------------
 * "full_scale": {"z_scale": 1211.8, "z_offset": 0.3, "unit": "m a.m.s.l.",
 *                "reference": {"monitor": "run_up", "observed": 863.0, "still": 700.0}}
 * Z = z_scale z + z_offset for every max_elevation monitor (output <m>_Z); with the reference,
 * the error (13) of Manenti et al. (2018) of the reference monitor's highest value (<m>_d_eta). */
static mixsph_status read_full_scale(const struct case_reader *r, const cJSON *root, struct case_def *c)
{
    struct full_scale *fs = &c->full_scale;
    fs->on = 0;
    fs->ref_monitor = -1;
    const cJSON *f = item(root, "full_scale");
    size_t n_scalar = 0;
    for (size_t k = 0; k < c->n_monitors; k++) {
        n_scalar += c->monitors[k].kind != MONITOR_PROFILE;
        for (const char *const *x = case_monitor_extras(c->monitors[k].kind); *x; x++) n_scalar++;
    }
    if (!f && n_scalar > CASE_MAX_SCALAR_OUTPUTS)
        return FAIL(r, "%s: monitors: %zu scalar outputs (expected at most %d; runout has 2, slide_impact 4, "
                    "the other scalar monitors 1)", r->origin, n_scalar, CASE_MAX_SCALAR_OUTPUTS);
    if (!f) return MIXSPH_OK;
    TRY(case_schema_read(r, f, "full_scale", section("full_scale"), 0, fs));
    for (size_t k = 0; k < c->n_monitors; k++) {
        if (c->monitors[k].kind != MONITOR_MAX_ELEVATION) continue;
        n_scalar++;
        if (strlen(c->monitors[k].name) + strlen(CASE_FULL_SCALE_SUFFIX_ERR) >= CASE_NAME_LEN)
            return FAIL(r, "%s: full_scale: the monitor name '%s' is too long for its full-scale outputs '%s%s', "
                        "'%s%s' (expected at most %d characters)", r->origin, c->monitors[k].name, c->monitors[k].name,
                        CASE_FULL_SCALE_SUFFIX_Z, c->monitors[k].name, CASE_FULL_SCALE_SUFFIX_ERR,
                        (int)(CASE_NAME_LEN - 1 - strlen(CASE_FULL_SCALE_SUFFIX_ERR)));
    }
    const cJSON *ref = item(f, "reference");
    if (ref) {
        TRY(case_schema_read(r, ref, "full_scale.reference", section("full_scale.reference"), 0, fs));
        const char *mon = item(ref, "monitor")->valuestring;
        fs->ref_monitor = find_monitor(c, mon);
        if (fs->ref_monitor < 0 || c->monitors[fs->ref_monitor].kind != MONITOR_MAX_ELEVATION)
            return FAIL(r, "%s: full_scale.reference.monitor: '%s' is not one of the max_elevation monitors", r->origin, mon);
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

mixsph_status case_number(const struct case_def *c, const char *key, double *value, char *err, size_t err_len)
{
    static const char *const own[] = {"numerics", "output"}; /* sections stored in struct case_def */
    const char *dot = strchr(key, '.');
    const struct case_section *sec = NULL;
    const char *name = key;
    if (!dot) {
        sec = case_schema_find("case");
    } else {
        for (size_t k = 0; k < sizeof own / sizeof own[0]; k++)
            if ((size_t)(dot - key) == strlen(own[k]) && strncmp(key, own[k], strlen(own[k])) == 0)
                sec = case_schema_find(own[k]);
        name = dot + 1;
    }
    const struct case_key *k = sec ? case_schema_key(sec, name) : NULL;
    if (!k || case_schema_stored_number(k, c, value) != 0)
        return status_set(err, err_len, MIXSPH_ERR_ARG,
                          "%s: not a numeric key of the case's top level, numerics or output", key);
    return MIXSPH_OK;
}

const char *const *case_monitor_extras(int kind)
{
    static const char *const none[] = {NULL};
    static const char *const runout[] = {"_height", NULL};
    static const char *const impact[] = {"_speed", "_thickness", "_mass", NULL};
    return kind == MONITOR_RUNOUT ? runout : kind == MONITOR_SLIDE_IMPACT ? impact : none;
}

double case_profile_bin_count(const struct monitor_def *md)
{
    return fmax(1.0, ceil((md->x_max - md->x_min) / md->bin));
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
static mixsph_status substitute(const struct case_reader *r, const cJSON *params, cJSON *node, char *path, size_t len)
{
    for (cJSON *it = node->child; it; it = it->next) {
        const size_t l0 = strlen(path);
        if (it->string) snprintf(path + l0, len - l0, "%s%s", l0 ? "." : "", it->string);
        if (cJSON_IsString(it) && it->valuestring[0] == '$') {
            const cJSON *p = params ? cJSON_GetObjectItemCaseSensitive(params, it->valuestring + 1) : NULL;
            if (!cJSON_IsNumber(p))
                return FAIL(r, "%s: %s: '%s' is not one of the numeric parameters", r->origin, path, it->valuestring);
            cJSON *num = cJSON_CreateNumber(p->valuedouble);
            if (!num) return status_set(r->err, r->err_len, MIXSPH_ERR_NOMEM, "out of memory");
            /* replace this very item (not the first of its name: that loops on a duplicate key) */
            num->string = it->string;
            it->string = NULL;
            if (!cJSON_ReplaceItemViaPointer(node, it, num)) {
                cJSON_Delete(num);
                return status_set(r->err, r->err_len, MIXSPH_ERR_NOMEM, "out of memory");
            }
            it = num;
        } else if (cJSON_IsObject(it) || cJSON_IsArray(it)) {
            TRY(substitute(r, params, it, path, len));
        }
        path[l0] = '\0';
    }
    return MIXSPH_OK;
}

static mixsph_status apply_parameters(const struct case_reader *r, cJSON *root)
{
    const cJSON *params = cJSON_GetObjectItemCaseSensitive(root, "parameters");
    if (params && !cJSON_IsObject(params)) return FAIL(r, "%s: parameters: expected an object of numbers", r->origin);
    for (const cJSON *p = params ? params->child : NULL; p; p = p->next)
        if (!cJSON_IsNumber(p) || !isfinite(p->valuedouble))
            return FAIL(r, "%s: parameters.%s: expected a number", r->origin, p->string);
    char path[512] = "";
    return substitute(r, params, root, path, sizeof path);
}

/* A body that lies wholly outside the case's domain would be dropped by the fill: refuse it. */
static mixsph_status read_domain_rules(const struct case_reader *r, const struct case_def *c)
{
    for (size_t k = 0; k < c->n_bodies && c->has_domain; k++) {
        const struct body *bd = &c->bodies[k];
        if (bd->shape != BODY_POLYGON) continue; /* a 3D box, STL or level: the fill says when none of it fits */
        double x0 = INFINITY, x1 = -INFINITY, z0 = INFINITY, z1 = -INFINITY;
        geom_grow_box(&bd->polygon, &x0, &x1, &z0, &z1);
        z0 = fmax(z0, bd->z_min);
        z1 = fmin(z1, bd->z_max);
        const double *d = c->domain, *dz = &c->domain[2 * DIM_UP];
        if (!(x1 > d[0] && x0 < d[1] && z1 > dz[0] && z0 < dz[1] && z1 > z0))
            return FAIL(r, "%s: bodies.%s: lies wholly outside the domain [%g, %g] x [%g, %g] (within its z_min..z_max)",
                        r->origin, bd->name, d[0], d[1], dz[0], dz[1]);
    }
    return MIXSPH_OK;
}

/* ---- duplicate keys --------------------------------------------------------------------------
 * cJSON keeps every member of an object, and which of two equal keys a lookup finds is an
 * accident of the parser: a key given twice is refused. */
static int name_cmp(const void *a, const void *b) { return strcmp(*(const char *const *)a, *(const char *const *)b); }

static mixsph_status refuse_duplicates(const struct case_reader *r, const cJSON *node, char *path, size_t len)
{
    size_t n = 0, k = 0;
    for (const cJSON *it = node->child; it; it = it->next) n++;
    if (cJSON_IsObject(node) && n > 1) {
        const char **names = malloc(n * sizeof *names);
        if (!names) return status_set(r->err, r->err_len, MIXSPH_ERR_NOMEM, "out of memory");
        for (const cJSON *it = node->child; it; it = it->next) names[k++] = it->string ? it->string : "";
        qsort(names, n, sizeof *names, name_cmp);
        for (k = 1; k < n && strcmp(names[k], names[k - 1]) != 0; k++) continue;
        if (k < n) {
            char q[2 * CASE_NAME_LEN + 16];
            quoted_name(names[k], q, sizeof q);
            const mixsph_status st = FAIL(r, "%s: %s: the key %s is given twice in one object (expected each key "
                                             "once)", r->origin, *path ? path : "the case", q);
            free(names);
            return st;
        }
        free(names);
    }
    k = 0;
    for (const cJSON *it = node->child; it; it = it->next, k++) {
        if (!cJSON_IsObject(it) && !cJSON_IsArray(it)) continue;
        const size_t l0 = strlen(path);
        if (it->string) snprintf(path + l0, len - l0, "%s%s", l0 ? "." : "", it->string);
        else snprintf(path + l0, len - l0, "[%zu]", k);
        TRY(refuse_duplicates(r, it, path, len));
        path[l0] = '\0';
    }
    return MIXSPH_OK;
}

static mixsph_status read_root(const struct case_reader *r, const cJSON *root, struct case_def *c)
{
    if (!cJSON_IsObject(root)) return FAIL(r, "%s: the case must be a JSON object", r->origin);
    TRY(case_schema_read(r, root, "", section("case"), 0, c));
    if (!plain_identifier(c->name)) {
        char q[2 * CASE_NAME_LEN + 16];
        quoted_name(c->name, q, sizeof q);
        return FAIL(r, "%s: name: %s is not a plain identifier (expected " NAME_RULE "; it names the output folder)",
                    r->origin, q);
    }
    if (c->dimensions != DIM)
        return FAIL(r, "%s: dimensions: the case is %dD, this build of the library is %dD (the mixsph executable and "
                       "the FMU hold both builds)", r->origin, c->dimensions, DIM);
    TRY(read_numerics(r, root, c));
    const cJSON *d = item(root, "domain");
    if (d) {
        TRY(case_schema_read(r, d, "domain", section("domain"), 0, c));
        if (!(c->domain[1] > c->domain[0]) || !(c->domain[2 * DIM_UP + 1] > c->domain[2 * DIM_UP]))
            return FAIL(r, "%s: domain: expected x_min < x_max and z_min < z_max", r->origin);
        const int across = item(d, "y_min") || item(d, "y_max");
        if (c->dimensions == 2 && across)
            return FAIL(r, "%s: domain: y_min and y_max are keys of a 3D case (this case has dimensions 2)", r->origin);
        if (c->dimensions == 3 && (!item(d, "y_min") || !item(d, "y_max") || !(c->domain_y[1] > c->domain_y[0])))
            return FAIL(r, "%s: domain: a 3D case's domain needs y_min < y_max", r->origin);
#if DIM == 3
        c->domain[2] = c->domain_y[0];
        c->domain[3] = c->domain_y[1];
#endif
        c->has_domain = 1;
    }
    TRY(read_media(r, root, c));
    TRY(read_bodies(r, root, c));
    TRY(read_motions(r, root, c));
    TRY(read_walls(r, root, c));
    TRY(read_monitors(r, root, c));
    TRY(read_full_scale(r, root, c));
    c->monitor_interval = c->t_end / 200.0;
    c->snapshot_interval = 0.0;
    const cJSON *o = item(root, "output");
    cJSON *none = o ? NULL : cJSON_CreateObject(); /* the output keys' defaults */
    if (!o && !none) return status_set(r->err, r->err_len, MIXSPH_ERR_NOMEM, "out of memory");
    const mixsph_status st = case_schema_read(r, o ? o : none, "output", section("output"), 0, c);
    cJSON_Delete(none);
    if (st != MIXSPH_OK) return st;
    return read_domain_rules(r, c);
}

mixsph_status case_parse(const char *json_text, const char *origin, const mixsph_override *ov, size_t n_ov,
                         struct case_def *c, char *err, size_t err_len)
{
    struct case_reader r = {origin ? origin : "(case)", err, err_len};
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
    char path[512] = "";
    mixsph_status st = refuse_duplicates(&r, root, path, sizeof path);
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
    for (size_t i = 0; i < CASE_MAX_WALLS; i++) {
        geom_free(&c->walls[i].line);
        surface_free(&c->walls[i].surface);
    }
    for (size_t i = 0; i < CASE_MAX_MOTIONS; i++) {
        free(c->motions[i].t);
        free(c->motions[i].vx);
        free(c->motions[i].vy);
        free(c->motions[i].vz);
        c->motions[i].t = c->motions[i].vx = c->motions[i].vy = c->motions[i].vz = NULL;
    }
}
