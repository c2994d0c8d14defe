/* stl.c - see stl.h. */
#include "stl.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "file_read.h"
#include "status.h"
#include "text_words.h"

/* The largest STL file read: a binary file of STL_MAX_TRIANGLES, an ASCII one of about a
 * quarter as many triangles. */
#define STL_MAX_BYTES (84 + 50 * STL_MAX_TRIANGLES)

/* ---- merging vertices at equal coordinates ----------------------------------------------- */

/* An open-addressing table of the vertices this read added (from `first` on), keyed by their
 * coordinates' bits; slot = vertex index + 1, 0 empty. Kept at most half full. */
struct vertex_table {
    struct mesh *m;
    size_t first, cap, used;
    size_t *slot;
};

static uint64_t coordinate_hash(const double p[3])
{
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (int d = 0; d < 3; d++) {
        const double v = p[d] + 0.0; /* -0 and +0 alike */
        uint64_t bits;
        memcpy(&bits, &v, sizeof bits);
        h ^= bits + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
        h *= 0xBF58476D1CE4E5B9ull;
        h ^= h >> 31;
    }
    return h;
}

static size_t *table_find(struct vertex_table *t, const double p[3])
{
    size_t i = (size_t)coordinate_hash(p) & (t->cap - 1);
    for (;; i = (i + 1) & (t->cap - 1)) {
        const size_t s = t->slot[i];
        if (s == 0) return &t->slot[i];
        const double *q = t->m->vertex[s - 1];
        if (q[0] == p[0] && q[1] == p[1] && q[2] == p[2]) return &t->slot[i];
    }
}

static int table_grow(struct vertex_table *t)
{
    const size_t cap = t->cap ? 2 * t->cap : 1024;
    size_t *slot = calloc(cap, sizeof *slot);
    if (!slot) return 0;
    free(t->slot);
    t->slot = slot;
    t->cap = cap;
    for (size_t v = t->first; v < t->m->n_vertices; v++) *table_find(t, t->m->vertex[v]) = v + 1;
    return 1;
}

static mixsph_status table_vertex(struct vertex_table *t, const double p[3], size_t *index, char *err, size_t err_len)
{
    if (2 * (t->used + 1) > t->cap && !table_grow(t))
        return status_set(err, err_len, MIXSPH_ERR_NOMEM, "STL: out of memory at %zu vertices", t->used);
    size_t *s = table_find(t, p);
    if (*s) {
        *index = *s - 1;
        return MIXSPH_OK;
    }
    mixsph_status st = mesh_add_vertex(t->m, p, index, err, err_len);
    if (st != MIXSPH_OK) return st;
    *s = *index + 1;
    t->used++;
    return MIXSPH_OK;
}

/* Add one triangle read from a file: merged vertices, dropped when it has no area. */
static mixsph_status add_read_triangle(struct vertex_table *t, const double v[3][3], struct stl_read_report *r,
                                       char *err, size_t err_len)
{
    size_t idx[3];
    for (int k = 0; k < 3; k++) {
        mixsph_status st = table_vertex(t, v[k], &idx[k], err, err_len);
        if (st != MIXSPH_OK) return st;
    }
    r->triangles++;
    char why[160];
    mixsph_status st = mesh_add_triangle(t->m, idx[0], idx[1], idx[2], why, sizeof why);
    if (st == MIXSPH_ERR_ARG) r->degenerate_dropped++; /* no area: no normal, nothing to bound */
    else if (st != MIXSPH_OK) return status_set(err, err_len, st, "STL: %s", why);
    return MIXSPH_OK;
}

/* ---- binary ------------------------------------------------------------------------------- */

static uint32_t le32(const unsigned char *b)
{
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

static double le_float(const unsigned char *b)
{
    const uint32_t bits = le32(b);
    float f;
    memcpy(&f, &bits, sizeof f);
    return (double)f;
}

static mixsph_status read_binary(const char *path, const unsigned char *buf, size_t len, struct vertex_table *t,
                                 struct stl_read_report *r, char *err, size_t err_len)
{
    const uint64_t n = le32(buf + 80), expected = 84 + 50 * n;
    if (n == 0) return status_set(err, err_len, MIXSPH_ERR_CASE, "%s: binary STL declaring 0 triangles", path);
    if (n > STL_MAX_TRIANGLES)
        return status_set(err, err_len, MIXSPH_ERR_CASE,
                          "%s: binary STL declaring %llu triangles, more than the limit of %zu (a corrupt header?)",
                          path, (unsigned long long)n, STL_MAX_TRIANGLES);
    if (len < expected)
        return status_set(err, err_len, MIXSPH_ERR_CASE,
                          "%s: truncated binary STL: the header declares %llu triangles (%llu bytes) but the file has "
                          "%zu bytes (triangle %llu is incomplete)",
                          path, (unsigned long long)n, (unsigned long long)expected, len,
                          (unsigned long long)((len - 84) / 50));
    if (len > expected)
        return status_set(err, err_len, MIXSPH_ERR_CASE,
                          "%s: binary STL with %llu bytes after the %llu triangles its header declares (not an STL?)",
                          path, (unsigned long long)(len - expected), (unsigned long long)n);
    for (uint64_t k = 0; k < n; k++) {
        const unsigned char *rec = buf + 84 + 50 * k + 12; /* past the file's normal */
        double v[3][3];
        for (int a = 0; a < 3; a++)
            for (int d = 0; d < 3; d++) {
                v[a][d] = le_float(rec + 12 * a + 4 * d);
                if (!isfinite(v[a][d]))
                    return status_set(err, err_len, MIXSPH_ERR_CASE,
                                      "%s: triangle %llu: vertex %d has a non-finite %c coordinate", path,
                                      (unsigned long long)k, a + 1, "xyz"[d]);
            }
        mixsph_status st = add_read_triangle(t, (const double(*)[3])v, r, err, err_len);
        if (st != MIXSPH_OK) return st;
    }
    return MIXSPH_OK;
}

/* ---- ASCII -------------------------------------------------------------------------------- */

struct ascii_reader {
    const char *path;
    struct text_cursor text;
    char *err;
    size_t err_len;
};

static mixsph_status expect(struct ascii_reader *a, const char *keyword)
{
    size_t len = 0;
    const char *w = text_next_word(&a->text, &len);
    if (text_word_is(w, len, keyword)) return MIXSPH_OK;
    return status_set(a->err, a->err_len, MIXSPH_ERR_CASE, "%s:%zu: expected '%s', found '%.*s'%s", a->path, a->text.line,
                      keyword, TEXT_QUOTED(w, len), w ? "" : " (truncated)");
}

/* A number: the whole word must be one; `finite`: refuse nan and inf. */
static mixsph_status number(struct ascii_reader *a, const char *what, int finite, double *value)
{
    size_t len = 0;
    const char *w = text_next_word(&a->text, &len);
    if (text_word_number(w, len, value)) {
        if (!finite || isfinite(*value)) return MIXSPH_OK;
        return status_set(a->err, a->err_len, MIXSPH_ERR_CASE, "%s:%zu: non-finite %s '%.*s'", a->path, a->text.line,
                          what, TEXT_QUOTED(w, len));
    }
    return status_set(a->err, a->err_len, MIXSPH_ERR_CASE, "%s:%zu: expected a number (%s), found '%.*s'%s", a->path,
                      a->text.line, what, TEXT_QUOTED(w, len), w ? "" : " (truncated)");
}

/* solid NAME / { facet normal n n n / outer loop / 3 x (vertex x y z) / endloop / endfacet } /
 * endsolid [NAME], possibly several solids. The facet's normal may be anything numeric (it is
 * not used; some writers put nan for their slivers). */
static mixsph_status read_ascii(struct ascii_reader *a, struct vertex_table *t, struct stl_read_report *r)
{
    size_t len = 0;
    const char *w = text_next_word(&a->text, &len); /* "solid", checked by the caller */
    text_skip_line(&a->text);                       /* the solid's name */
    for (;;) {
        w = text_next_word(&a->text, &len);
        if (text_word_is(w, len, "endsolid")) {
            text_skip_line(&a->text);
            w = text_next_word(&a->text, &len);
            if (!w) break;
            if (!text_word_is(w, len, "solid"))
                return status_set(a->err, a->err_len, MIXSPH_ERR_CASE, "%s:%zu: expected 'solid' or the end, found '%.*s'",
                                  a->path, a->text.line, TEXT_QUOTED(w, len));
            text_skip_line(&a->text);
            continue;
        }
        if (!text_word_is(w, len, "facet"))
            return status_set(a->err, a->err_len, MIXSPH_ERR_CASE, "%s:%zu: expected 'facet' or 'endsolid', found '%.*s'%s",
                              a->path, a->text.line, TEXT_QUOTED(w, len), w ? "" : " (truncated)");
        if (r->triangles >= STL_MAX_TRIANGLES)
            return status_set(a->err, a->err_len, MIXSPH_ERR_CASE, "%s:%zu: more than the limit of %zu triangles", a->path,
                              a->text.line, STL_MAX_TRIANGLES);
        mixsph_status st = expect(a, "normal");
        double ignored, v[3][3];
        for (int d = 0; d < 3 && st == MIXSPH_OK; d++) st = number(a, "normal component", 0, &ignored);
        if (st == MIXSPH_OK) st = expect(a, "outer");
        if (st == MIXSPH_OK) st = expect(a, "loop");
        for (int k = 0; k < 3 && st == MIXSPH_OK; k++) {
            st = expect(a, "vertex");
            for (int d = 0; d < 3 && st == MIXSPH_OK; d++) st = number(a, "coordinate", 1, &v[k][d]);
        }
        if (st == MIXSPH_OK) st = expect(a, "endloop");
        if (st == MIXSPH_OK) st = expect(a, "endfacet");
        if (st == MIXSPH_OK) st = add_read_triangle(t, (const double(*)[3])v, r, a->err, a->err_len);
        if (st != MIXSPH_OK) return st;
    }
    if (r->triangles == 0)
        return status_set(a->err, a->err_len, MIXSPH_ERR_CASE, "%s: ASCII STL without any facet", a->path);
    return MIXSPH_OK;
}

/* ---- reading and writing ------------------------------------------------------------------ */

static int starts_with_solid(const char *buf, size_t len)
{
    size_t i = 0;
    while (i < len && isspace((unsigned char)buf[i])) i++;
    return len - i >= 5 && text_word_is(buf + i, 5, "solid") && (len - i == 5 || isspace((unsigned char)buf[i + 5]));
}

mixsph_status stl_read(const char *path, struct mesh *m, struct stl_read_report *report, char *err, size_t err_len)
{
    struct stl_read_report r = {0};
    char *buf = NULL;
    size_t len = 0;
    mixsph_status st = file_read_all(path, STL_MAX_BYTES, &buf, &len, err, err_len);
    if (st != MIXSPH_OK) return st;
    struct vertex_table t = {.m = m, .first = m->n_vertices};
    const int ascii = starts_with_solid(buf, len) && memchr(buf, '\0', len) == NULL;
    if (ascii) {
        struct ascii_reader a = {.path = path, .text = {.at = buf, .end = buf + len, .line = 1}, .err = err, .err_len = err_len};
        st = read_ascii(&a, &t, &r);
    } else if (len < 84) {
        st = status_set(err, err_len, MIXSPH_ERR_CASE,
                        "%s: not an STL file: no ASCII 'solid' at the start, and %zu bytes are fewer than a binary "
                        "STL's 84-byte header",
                        path, len);
    } else {
        r.binary = 1;
        st = read_binary(path, (const unsigned char *)buf, len, &t, &r, err, err_len);
    }
    if (st == MIXSPH_OK && r.triangles == r.degenerate_dropped)
        st = status_set(err, err_len, MIXSPH_ERR_CASE, "%s: all %zu triangles have zero area", path, r.triangles);
    free(t.slot);
    free(buf);
    if (report) *report = r;
    return st;
}

static void put_le32(unsigned char *b, uint32_t v)
{
    for (int i = 0; i < 4; i++) b[i] = (unsigned char)(v >> (8 * i));
}

static void put_le_float(unsigned char *b, double v)
{
    const float f = (float)v;
    uint32_t bits;
    memcpy(&bits, &f, sizeof bits);
    put_le32(b, bits);
}

mixsph_status stl_write(const char *path, const struct mesh *m, int binary, const char *name, char *err,
                        size_t err_len)
{
    if (m->n_triangles > UINT32_MAX)
        return status_set(err, err_len, MIXSPH_ERR_ARG, "%s: %zu triangles do not fit an STL file", path, m->n_triangles);
    FILE *f = fopen(path, binary ? "wb" : "w");
    if (!f) return status_set(err, err_len, MIXSPH_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
    int ok = 1;
    if (binary) {
        unsigned char head[84] = {0}, rec[50] = {0};
        snprintf((char *)head, 80, "%s", name ? name : "mixsph");
        put_le32(head + 80, (uint32_t)m->n_triangles);
        ok = fwrite(head, 1, sizeof head, f) == sizeof head;
        for (size_t t = 0; t < m->n_triangles && ok; t++) {
            for (int d = 0; d < 3; d++) put_le_float(rec + 4 * d, m->normal[t][d]);
            for (int k = 0; k < 3; k++)
                for (int d = 0; d < 3; d++) put_le_float(rec + 12 + 12 * k + 4 * d, m->vertex[m->triangle[t][k]][d]);
            ok = fwrite(rec, 1, sizeof rec, f) == sizeof rec;
        }
    } else {
        ok = fprintf(f, "solid %s\n", name ? name : "mixsph") > 0;
        for (size_t t = 0; t < m->n_triangles && ok; t++) {
            const double *n = m->normal[t];
            ok = fprintf(f, "  facet normal %.17g %.17g %.17g\n    outer loop\n", n[0], n[1], n[2]) > 0;
            for (int k = 0; k < 3 && ok; k++) {
                const double *v = m->vertex[m->triangle[t][k]];
                ok = fprintf(f, "      vertex %.17g %.17g %.17g\n", v[0], v[1], v[2]) > 0;
            }
            ok = ok && fprintf(f, "    endloop\n  endfacet\n") > 0;
        }
        ok = ok && fprintf(f, "endsolid %s\n", name ? name : "mixsph") > 0;
    }
    if (fclose(f) != 0) ok = 0;
    return ok ? MIXSPH_OK : status_set(err, err_len, MIXSPH_ERR_IO, "%s: write error", path);
}
