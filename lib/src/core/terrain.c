/* terrain.c - see terrain.h. */
#include "terrain.h"

#include <ctype.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "file_read.h"
#include "status.h"
#include "text_words.h"

/* The largest grid file read: TERRAIN_MAX_NODES values of up to 24 characters. */
#define TERRAIN_MAX_BYTES (24 * TERRAIN_MAX_NODES + 4096)

void terrain_free(struct terrain *t)
{
    free(t->z);
    memset(t, 0, sizeof *t);
}

/* Check a grid's shape and allocate its heights. */
static mixsph_status terrain_alloc(struct terrain *t, size_t ncols, size_t nrows, double x0, double y0, double cell,
                                   const char *where, char *err, size_t err_len)
{
    memset(t, 0, sizeof *t);
    if (ncols < 2 || nrows < 2)
        return status_set(err, err_len, MIXSPH_ERR_CASE, "%s: %zu x %zu nodes: at least 2 x 2 make a cell", where, ncols,
                          nrows);
    if (ncols > TERRAIN_MAX_NODES / nrows)
        return status_set(err, err_len, MIXSPH_ERR_CASE, "%s: %zu x %zu nodes, more than the limit of %zu", where, ncols,
                          nrows, TERRAIN_MAX_NODES);
    if (!(cell > 0.0) || !isfinite(cell) || !isfinite(x0) || !isfinite(y0))
        return status_set(err, err_len, MIXSPH_ERR_CASE, "%s: cell size %g at (%g, %g): a finite, positive size", where,
                          cell, x0, y0);
    t->z = malloc(ncols * nrows * sizeof *t->z);
    if (!t->z) return status_set(err, err_len, MIXSPH_ERR_NOMEM, "%s: out of memory", where);
    t->ncols = ncols;
    t->nrows = nrows;
    t->x0 = x0;
    t->y0 = y0;
    t->cell = cell;
    return MIXSPH_OK;
}

mixsph_status terrain_from_heights(struct terrain *t, size_t ncols, size_t nrows, double x0, double y0, double cell,
                                   const double *z, char *err, size_t err_len)
{
    mixsph_status st = terrain_alloc(t, ncols, nrows, x0, y0, cell, "terrain", err, err_len);
    if (st == MIXSPH_OK) memcpy(t->z, z, ncols * nrows * sizeof *z);
    return st;
}

/* The header keys of an ESRI ASCII grid. */
enum { KEY_NCOLS, KEY_NROWS, KEY_XLLCORNER, KEY_XLLCENTER, KEY_YLLCORNER, KEY_YLLCENTER, KEY_CELLSIZE, KEY_NODATA, N_KEYS };
static const char *const esri_keys[N_KEYS] = {"ncols",     "nrows",     "xllcorner", "xllcenter",
                                              "yllcorner", "yllcenter", "cellsize",  "nodata_value"};

/* The header: words starting with a letter that are keys, each followed by its value on the
 * same line; stops before the first value of the grid. */
static mixsph_status read_header(const char *path, struct text_cursor *c, double value[N_KEYS], int seen[N_KEYS],
                                 char *err, size_t err_len)
{
    for (;;) {
        struct text_cursor before = *c;
        size_t len;
        const char *w = text_next_word(c, &len);
        double number;
        if (!w || !isalpha((unsigned char)w[0]) || text_word_number(w, len, &number)) {
            *c = before; /* the first value (nan, inf among them) */
            return MIXSPH_OK;
        }
        int key = 0;
        while (key < N_KEYS && !text_word_is(w, len, esri_keys[key])) key++;
        if (key == N_KEYS)
            return status_set(err, err_len, MIXSPH_ERR_CASE,
                              "%s:%zu: unknown header key '%.*s' (ncols, nrows, xllcorner or xllcenter, yllcorner or "
                              "yllcenter, cellsize, NODATA_value)",
                              path, c->line, TEXT_QUOTED(w, len));
        if (seen[key])
            return status_set(err, err_len, MIXSPH_ERR_CASE, "%s:%zu: header key '%s' given twice", path, c->line,
                              esri_keys[key]);
        const size_t line = c->line;
        const char *v = text_next_word(c, &len);
        if (!v || c->line != line || !text_word_number(v, len, &value[key]) || !isfinite(value[key]))
            return status_set(err, err_len, MIXSPH_ERR_CASE, "%s:%zu: header key '%s' needs a finite number on its line",
                              path, line, esri_keys[key]);
        seen[key] = 1;
    }
}

/* A header count (ncols, nrows): a whole number of at least 2. */
static mixsph_status header_count(const char *path, const char *key, double value, size_t *count, char *err,
                                  size_t err_len)
{
    if (!(value >= 2.0) || value != floor(value) || value > (double)TERRAIN_MAX_NODES)
        return status_set(err, err_len, MIXSPH_ERR_CASE, "%s: %s = %g: a whole number from 2 to %zu", path, key, value,
                          TERRAIN_MAX_NODES);
    *count = (size_t)value;
    return MIXSPH_OK;
}

mixsph_status terrain_read_esri_ascii(const char *path, struct terrain *t, char *err, size_t err_len)
{
    memset(t, 0, sizeof *t);
    char *buf = NULL;
    size_t len = 0;
    mixsph_status st = file_read_all(path, TERRAIN_MAX_BYTES, &buf, &len, err, err_len);
    if (st != MIXSPH_OK) return st;
    struct text_cursor c = {.at = buf, .end = buf + len, .line = 1};
    double value[N_KEYS] = {0};
    int seen[N_KEYS] = {0};
    st = read_header(path, &c, value, seen, err, err_len);
    const int required[] = {KEY_NCOLS, KEY_NROWS, KEY_CELLSIZE};
    for (size_t k = 0; k < 3 && st == MIXSPH_OK; k++)
        if (!seen[required[k]])
            st = status_set(err, err_len, MIXSPH_ERR_CASE, "%s: the header has no '%s'", path, esri_keys[required[k]]);
    for (int axis = 0; axis < 2 && st == MIXSPH_OK; axis++) {
        const int corner = axis ? KEY_YLLCORNER : KEY_XLLCORNER, centre = corner + 1;
        if (seen[corner] == seen[centre])
            st = status_set(err, err_len, MIXSPH_ERR_CASE, "%s: the header needs one of '%s' and '%s', it has %s", path,
                            esri_keys[corner], esri_keys[centre], seen[corner] ? "both" : "neither");
    }
    size_t ncols = 0, nrows = 0;
    if (st == MIXSPH_OK) st = header_count(path, "ncols", value[KEY_NCOLS], &ncols, err, err_len);
    if (st == MIXSPH_OK) st = header_count(path, "nrows", value[KEY_NROWS], &nrows, err, err_len);
    if (st == MIXSPH_OK) {
        const double cell = value[KEY_CELLSIZE];
        /* the values are the cells' centres' */
        const double x0 = seen[KEY_XLLCORNER] ? value[KEY_XLLCORNER] + 0.5 * cell : value[KEY_XLLCENTER];
        const double y0 = seen[KEY_YLLCORNER] ? value[KEY_YLLCORNER] + 0.5 * cell : value[KEY_YLLCENTER];
        st = terrain_alloc(t, ncols, nrows, x0, y0, cell, path, err, err_len);
    }
    const size_t n = ncols * nrows;
    size_t last_line = c.line; /* of the last value read: where a truncated file ends */
    for (size_t k = 0; k < n && st == MIXSPH_OK; k++) {
        size_t wlen;
        const char *w = text_next_word(&c, &wlen);
        double z;
        if (w) last_line = c.line;
        if (!w)
            st = status_set(err, err_len, MIXSPH_ERR_CASE,
                            "%s:%zu: truncated: %zu values of the %zu x %zu the header declares", path, last_line, k,
                            nrows, ncols);
        else if (!text_word_number(w, wlen, &z))
            st = status_set(err, err_len, MIXSPH_ERR_CASE, "%s:%zu: value %zu (row %zu, column %zu): '%.*s' is no number",
                            path, c.line, k + 1, k / ncols + 1, k % ncols + 1, TEXT_QUOTED(w, wlen));
        else if (seen[KEY_NODATA] && z == value[KEY_NODATA])
            t->z[(nrows - 1 - k / ncols) * ncols + k % ncols] = NAN; /* rows north to south */
        else if (!isfinite(z))
            st = status_set(err, err_len, MIXSPH_ERR_CASE, "%s:%zu: value %zu (row %zu, column %zu) is not finite", path,
                            c.line, k + 1, k / ncols + 1, k % ncols + 1);
        else
            t->z[(nrows - 1 - k / ncols) * ncols + k % ncols] = z;
    }
    if (st == MIXSPH_OK) {
        size_t wlen;
        if (text_next_word(&c, &wlen))
            st = status_set(err, err_len, MIXSPH_ERR_CASE, "%s:%zu: more values than the %zu x %zu the header declares",
                            path, c.line, nrows, ncols);
    }
    free(buf);
    if (st != MIXSPH_OK) terrain_free(t);
    return st;
}

/* The cell holding coordinate u (node units from the first node) among n nodes, and the
 * fraction across it; 0 outside [0, n - 1]. The last node belongs to the last cell. */
static int locate(double u, size_t n, size_t *cell, double *fraction)
{
    if (!(u >= 0.0 && u <= (double)(n - 1))) return 0;
    size_t i = (size_t)u;
    if (i > n - 2) i = n - 2;
    *cell = i;
    *fraction = u - (double)i;
    return 1;
}

double terrain_height(const struct terrain *t, double x, double y)
{
    size_t i, j;
    double fx, fy;
    if (!locate((x - t->x0) / t->cell, t->ncols, &i, &fx) || !locate((y - t->y0) / t->cell, t->nrows, &j, &fy))
        return NAN;
    const double *row = t->z + j * t->ncols + i, *north = row + t->ncols;
    /* a NaN corner makes the height NaN, whatever its weight */
    return (1.0 - fy) * ((1.0 - fx) * row[0] + fx * row[1]) + fy * ((1.0 - fx) * north[0] + fx * north[1]);
}

mixsph_status terrain_to_mesh(const struct terrain *t, struct mesh *m, char *err, size_t err_len)
{
    const size_t n = t->ncols * t->nrows;
    size_t *vertex = malloc(n * sizeof *vertex); /* the mesh vertex of each node, SIZE_MAX without data */
    if (!vertex) return status_set(err, err_len, MIXSPH_ERR_NOMEM, "terrain: out of memory");
    mixsph_status st = MIXSPH_OK;
    for (size_t j = 0; j < t->nrows && st == MIXSPH_OK; j++)
        for (size_t i = 0; i < t->ncols && st == MIXSPH_OK; i++) {
            const size_t k = j * t->ncols + i;
            vertex[k] = SIZE_MAX;
            if (isnan(t->z[k])) continue;
            const double p[3] = {t->x0 + (double)i * t->cell, t->y0 + (double)j * t->cell, t->z[k]};
            st = mesh_add_vertex(m, p, &vertex[k], err, err_len);
        }
    for (size_t j = 0; j + 1 < t->nrows && st == MIXSPH_OK; j++)
        for (size_t i = 0; i + 1 < t->ncols && st == MIXSPH_OK; i++) {
            /* south-west, south-east, north-east, north-west: counter-clockwise seen from above */
            const size_t k = j * t->ncols + i;
            const size_t sw = vertex[k], se = vertex[k + 1], ne = vertex[k + 1 + t->ncols], nw = vertex[k + t->ncols];
            if (sw == SIZE_MAX || se == SIZE_MAX || ne == SIZE_MAX || nw == SIZE_MAX) continue;
            st = mesh_add_triangle(m, sw, se, ne, err, err_len);
            if (st == MIXSPH_OK) st = mesh_add_triangle(m, sw, ne, nw, err, err_len);
        }
    free(vertex);
    return st;
}
