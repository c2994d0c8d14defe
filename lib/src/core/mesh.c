/* mesh.c - see mesh.h. */
#include "mesh.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "status.h"
#include "vec3.h"

void mesh_free(struct mesh *m)
{
    free(m->vertex);
    free(m->triangle);
    free(m->normal);
    memset(m, 0, sizeof *m);
}

/* Grow an array of rows of `row` bytes to hold at least `need` rows (doubling). */
static int grow_rows(void **array, size_t *cap, size_t need, size_t row)
{
    if (need <= *cap) return 1;
    size_t cap2 = *cap ? *cap : 16;
    while (cap2 < need) cap2 *= 2;
    if (cap2 > SIZE_MAX / row) return 0;
    void *p = realloc(*array, cap2 * row);
    if (!p) return 0;
    *array = p;
    *cap = cap2;
    return 1;
}

mixsph_status mesh_add_vertex(struct mesh *m, const double p[3], size_t *index, char *err, size_t err_len)
{
    void *rows = m->vertex;
    if (!grow_rows(&rows, &m->vertex_cap, m->n_vertices + 1, sizeof m->vertex[0]))
        return status_set(err, err_len, MIXSPH_ERR_NOMEM, "mesh: out of memory at %zu vertices", m->n_vertices);
    m->vertex = rows;
    memcpy(m->vertex[m->n_vertices], p, sizeof m->vertex[0]);
    *index = m->n_vertices++;
    return MIXSPH_OK;
}

/* The unit normal of the triangle (a, b, c) by the right-hand rule; 0 when it has no area. */
static int triangle_normal(const double a[3], const double b[3], const double c[3], double n[3])
{
    double e1[3], e2[3];
    vec3_sub(b, a, e1);
    vec3_sub(c, a, e2);
    vec3_cross(e1, e2, n);
    const double len = vec3_norm(n);
    if (!(len > 0.0) || !isfinite(len)) return 0;
    for (int d = 0; d < 3; d++) n[d] /= len;
    return 1;
}

mixsph_status mesh_add_triangle(struct mesh *m, size_t a, size_t b, size_t c, char *err, size_t err_len)
{
    if (a >= m->n_vertices || b >= m->n_vertices || c >= m->n_vertices)
        return status_set(err, err_len, MIXSPH_ERR_ARG, "mesh: triangle (%zu, %zu, %zu) names a vertex beyond %zu", a,
                          b, c, m->n_vertices);
    double n[3];
    if (!triangle_normal(m->vertex[a], m->vertex[b], m->vertex[c], n))
        return status_set(err, err_len, MIXSPH_ERR_ARG,
                          "mesh: triangle %zu (vertices %zu, %zu, %zu) has no area (collinear or coincident vertices)",
                          m->n_triangles, a, b, c);
    if (m->n_triangles == m->triangle_cap) { /* the triangles and their normals share a capacity */
        void *tri = m->triangle, *nrm = m->normal;
        size_t cap_t = m->triangle_cap, cap_n = m->triangle_cap;
        const int grown = grow_rows(&tri, &cap_t, m->n_triangles + 1, sizeof m->triangle[0]) &&
                          grow_rows(&nrm, &cap_n, m->n_triangles + 1, sizeof m->normal[0]);
        m->triangle = tri;
        m->normal = nrm;
        if (!grown)
            return status_set(err, err_len, MIXSPH_ERR_NOMEM, "mesh: out of memory at %zu triangles", m->n_triangles);
        m->triangle_cap = cap_t;
    }
    m->triangle[m->n_triangles][0] = a;
    m->triangle[m->n_triangles][1] = b;
    m->triangle[m->n_triangles][2] = c;
    memcpy(m->normal[m->n_triangles], n, sizeof n);
    m->n_triangles++;
    return MIXSPH_OK;
}

/* Append the quad (a, b, c, d), counter-clockwise seen from its normal's side, as (a, b, c) and
 * (a, c, d); reversed when `reverse`. */
static mixsph_status add_quad(struct mesh *m, size_t a, size_t b, size_t c, size_t d, int reverse, char *err,
                              size_t err_len)
{
    mixsph_status st = reverse ? mesh_add_triangle(m, a, c, b, err, err_len) : mesh_add_triangle(m, a, b, c, err, err_len);
    if (st != MIXSPH_OK) return st;
    return reverse ? mesh_add_triangle(m, a, d, c, err, err_len) : mesh_add_triangle(m, a, c, d, err, err_len);
}

mixsph_status mesh_add_box(struct mesh *m, const double lo[3], const double hi[3], unsigned faces, int inward,
                           char *err, size_t err_len)
{
    for (int d = 0; d < 3; d++)
        if (!(hi[d] > lo[d]) || !isfinite(lo[d]) || !isfinite(hi[d]))
            return status_set(err, err_len, MIXSPH_ERR_ARG, "box: axis %c: [%g, %g] is not a finite, non-empty range",
                              "xyz"[d], lo[d], hi[d]);
    /* corner k has x = hi when bit 0 of k is set, y when bit 1, z when bit 2 */
    size_t v[8];
    for (int k = 0; k < 8; k++) {
        const double p[3] = {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]};
        mixsph_status st = mesh_add_vertex(m, p, &v[k], err, err_len);
        if (st != MIXSPH_OK) return st;
    }
    /* each face's corners counter-clockwise seen from outside */
    static const struct {
        unsigned bit;
        int c[4];
    } face[6] = {
        {MESH_BOX_XMIN, {0, 4, 6, 2}}, {MESH_BOX_XMAX, {1, 3, 7, 5}}, {MESH_BOX_YMIN, {0, 1, 5, 4}},
        {MESH_BOX_YMAX, {2, 6, 7, 3}}, {MESH_BOX_ZMIN, {0, 2, 3, 1}}, {MESH_BOX_ZMAX, {4, 5, 7, 6}},
    };
    for (int f = 0; f < 6; f++) {
        if (!(faces & face[f].bit)) continue;
        mixsph_status st =
            add_quad(m, v[face[f].c[0]], v[face[f].c[1]], v[face[f].c[2]], v[face[f].c[3]], inward, err, err_len);
        if (st != MIXSPH_OK) return st;
    }
    return MIXSPH_OK;
}

/* Append the vertices (x_k, y, z_k) of a polyline; *first receives the index of the first. */
static mixsph_status add_polyline_vertices(struct mesh *m, const struct polyline *line, double y, size_t *first,
                                           char *err, size_t err_len)
{
    for (size_t k = 0; k < line->n; k++) {
        const double p[3] = {line->x[k], y, line->z[k]};
        size_t index = 0;
        mixsph_status st = mesh_add_vertex(m, p, &index, err, err_len);
        if (st != MIXSPH_OK) return st;
        if (k == 0) *first = index;
    }
    return MIXSPH_OK;
}

/* Check the arguments shared by both extrusions: the width and every segment's length (segment
 * k from vertex k to k + 1, the closing one too when `closed`). */
static mixsph_status check_extrusion(const struct polyline *line, int closed, double y0, double y1, const char *what,
                                     char *err, size_t err_len)
{
    if (!(y1 > y0) || !isfinite(y0) || !isfinite(y1))
        return status_set(err, err_len, MIXSPH_ERR_ARG, "%s: the width [%g, %g] is not a finite, non-empty range", what,
                          y0, y1);
    if (line->n < (closed ? 3u : 2u))
        return status_set(err, err_len, MIXSPH_ERR_ARG, "%s: %zu vertices (at least %d)", what, line->n, closed ? 3 : 2);
    for (size_t k = 0; k < line->n; k++) {
        if (!isfinite(line->x[k]) || !isfinite(line->z[k]))
            return status_set(err, err_len, MIXSPH_ERR_ARG, "%s: vertex %zu is not finite", what, k);
        const size_t next = k + 1 < line->n ? k + 1 : 0;
        if (next == 0 && !closed) break;
        if (line->x[k] == line->x[next] && line->z[k] == line->z[next])
            return status_set(err, err_len, MIXSPH_ERR_ARG, "%s: segment %zu (vertices %zu, %zu) has zero length", what,
                              k, k, next);
    }
    return MIXSPH_OK;
}

/* The quads of the segments of an extruded polyline whose vertices start at `bottom` (y0) and
 * `top` (y1), normals to its side (+1 left of travel). With y1 > y0, the quad of segment k
 * (bottom_k, bottom_k+1, top_k+1, top_k) has the normal (-ez, 0, ex) / |e| for e = p_k+1 - p_k,
 * the left normal of geometry.h. */
static mixsph_status add_extrusion_quads(struct mesh *m, size_t n, int closed, size_t bottom, size_t top, int side,
                                         char *err, size_t err_len)
{
    const size_t segments = closed ? n : n - 1;
    for (size_t k = 0; k < segments; k++) {
        const size_t next = (k + 1) % n;
        mixsph_status st = add_quad(m, bottom + k, bottom + next, top + next, top + k, side < 0, err, err_len);
        if (st != MIXSPH_OK) return st;
    }
    return MIXSPH_OK;
}

mixsph_status mesh_add_extruded_polyline(struct mesh *m, const struct polyline *line, int side, double y0, double y1,
                                         char *err, size_t err_len)
{
    if (side != 1 && side != -1)
        return status_set(err, err_len, MIXSPH_ERR_ARG, "extruded polyline: side %d (+1 or -1)", side);
    mixsph_status st = check_extrusion(line, 0, y0, y1, "extruded polyline", err, err_len);
    size_t bottom = 0, top = 0;
    if (st == MIXSPH_OK) st = add_polyline_vertices(m, line, y0, &bottom, err, err_len);
    if (st == MIXSPH_OK) st = add_polyline_vertices(m, line, y1, &top, err, err_len);
    if (st == MIXSPH_OK) st = add_extrusion_quads(m, line->n, 0, bottom, top, side, err, err_len);
    return st;
}

/* Twice the signed area of the triangle (a, b, c) of the x-z plane: positive counter-clockwise
 * (x right, z up). */
static double cross2(const struct polyline *p, size_t a, size_t b, size_t c)
{
    return (p->x[b] - p->x[a]) * (p->z[c] - p->z[a]) - (p->z[b] - p->z[a]) * (p->x[c] - p->x[a]);
}

/* Is vertex q inside or on the counter-clockwise triangle (a, b, c)? */
static int in_triangle2(const struct polyline *p, size_t a, size_t b, size_t c, size_t q)
{
    return cross2(p, a, b, q) >= 0.0 && cross2(p, b, c, q) >= 0.0 && cross2(p, c, a, q) >= 0.0;
}

/* The caps of a prism: ear clipping of the polygon (its vertex k is bottom + k at y0 and top + k
 * at y1), the triangles emitted counter-clockwise in (x, z) at y0 (normal -y) and reversed at y1
 * (normal +y). `ccw`: the polygon's orientation; a clockwise one is walked backwards. An ear is a
 * convex vertex whose triangle holds no other remaining vertex (on its boundary included, so
 * that a reflex vertex touching the diagonal blocks it). O(n^3) in the worst case: a cap has
 * the few vertices of a case's 2D body. */
static mixsph_status add_caps(struct mesh *m, const struct polyline *p, int ccw, size_t bottom, size_t top, char *err,
                              size_t err_len)
{
    const size_t n = p->n;
    size_t *ring = malloc(n * sizeof *ring);
    if (!ring) return status_set(err, err_len, MIXSPH_ERR_NOMEM, "extruded polygon: out of memory");
    for (size_t k = 0; k < n; k++) ring[k] = ccw ? k : n - 1 - k;
    double scale = 0.0; /* the polygon's extent, for the collinearity tolerance */
    for (size_t k = 0; k < n; k++) scale = fmax(scale, fmax(fabs(p->x[k] - p->x[0]), fabs(p->z[k] - p->z[0])));
    const double flat = 1e-12 * scale * scale;
    size_t left = n;
    mixsph_status st = MIXSPH_OK;
    while (left >= 3 && st == MIXSPH_OK) {
        size_t ear = left, flat_vertex = left;
        for (size_t i = 0; i < left && ear == left; i++) {
            const size_t a = ring[(i + left - 1) % left], b = ring[i], c = ring[(i + 1) % left];
            const double area2 = cross2(p, a, b, c);
            if (fabs(area2) <= flat) {
                if (flat_vertex == left) flat_vertex = i;
                continue;
            }
            if (area2 < 0.0) continue; /* reflex */
            int blocked = 0;
            for (size_t j = 0; j < left && !blocked; j++) {
                const size_t q = ring[j];
                if (q != a && q != b && q != c) blocked = in_triangle2(p, a, b, c, q);
            }
            if (!blocked) ear = i;
        }
        size_t drop = ear;
        if (ear < left) {
            const size_t a = ring[(ear + left - 1) % left], b = ring[ear], c = ring[(ear + 1) % left];
            st = mesh_add_triangle(m, bottom + a, bottom + b, bottom + c, err, err_len);
            if (st == MIXSPH_OK) st = mesh_add_triangle(m, top + a, top + c, top + b, err, err_len);
        } else if (flat_vertex < left) {
            drop = flat_vertex; /* a collinear vertex: no triangle, the cap's edge spans it */
        } else {
            st = status_set(err, err_len, MIXSPH_ERR_ARG,
                            "extruded polygon: no ear left among %zu vertices (is the polygon self-intersecting?)",
                            left);
            break;
        }
        memmove(ring + drop, ring + drop + 1, (left - drop - 1) * sizeof *ring);
        left--;
    }
    free(ring);
    return st;
}

mixsph_status mesh_add_extruded_polygon(struct mesh *m, const struct polyline *poly, double y0, double y1, char *err,
                                        size_t err_len)
{
    mixsph_status st = check_extrusion(poly, 1, y0, y1, "extruded polygon", err, err_len);
    if (st != MIXSPH_OK) return st;
    /* simple: no two segments that do not share a vertex meet (touching counts; overlapping
     * collinear segments are not caught), O(n^2) for the few vertices of a case's body */
    const size_t n = poly->n;
    for (size_t a = 0; a < n; a++)
        for (size_t b = a + 2; b < n; b++) {
            if (a == 0 && b == n - 1) continue; /* neighbours through the closing segment */
            double at;
            if (geom_path_crosses(poly->x[a], poly->z[a], poly->x[(a + 1) % n], poly->z[(a + 1) % n], poly->x[b],
                                  poly->z[b], poly->x[(b + 1) % n], poly->z[(b + 1) % n], &at))
                return status_set(err, err_len, MIXSPH_ERR_ARG,
                                  "extruded polygon: segments %zu and %zu cross (the polygon must be simple)", a, b);
        }
    double twice_area = 0.0; /* shoelace, positive counter-clockwise in (x, z) */
    for (size_t i = 0, j = poly->n - 1; i < poly->n; j = i++) twice_area += poly->x[j] * poly->z[i] - poly->x[i] * poly->z[j];
    if (twice_area == 0.0)
        return status_set(err, err_len, MIXSPH_ERR_ARG, "extruded polygon: the polygon has no area");
    /* counter-clockwise: the inside is left of travel, so the outward side is the right (-1) */
    const int ccw = twice_area > 0.0, outward_side = ccw ? -1 : 1;
    size_t bottom = 0, top = 0;
    st = add_polyline_vertices(m, poly, y0, &bottom, err, err_len);
    if (st == MIXSPH_OK) st = add_polyline_vertices(m, poly, y1, &top, err, err_len);
    if (st == MIXSPH_OK) st = add_extrusion_quads(m, poly->n, 1, bottom, top, outward_side, err, err_len);
    if (st == MIXSPH_OK) st = add_caps(m, poly, ccw, bottom, top, err, err_len);
    return st;
}

void mesh_flip(struct mesh *m)
{
    for (size_t t = 0; t < m->n_triangles; t++) {
        const size_t b = m->triangle[t][1];
        m->triangle[t][1] = m->triangle[t][2];
        m->triangle[t][2] = b;
        for (int d = 0; d < 3; d++) m->normal[t][d] = -m->normal[t][d];
    }
}

void mesh_bounds(const struct mesh *m, double lo[3], double hi[3])
{
    for (int d = 0; d < 3; d++) {
        lo[d] = INFINITY;
        hi[d] = -INFINITY;
    }
    for (size_t v = 0; v < m->n_vertices; v++)
        for (int d = 0; d < 3; d++) {
            lo[d] = fmin(lo[d], m->vertex[v][d]);
            hi[d] = fmax(hi[d], m->vertex[v][d]);
        }
}

double mesh_volume(const struct mesh *m)
{
    /* V = 1/3 int x.n dA = 1/6 sum v0 . (v1 x v2); taken about the box's centre, which makes it
     * independent of where the mesh sits (less cancellation far from the origin) */
    double lo[3], hi[3], centre[3];
    mesh_bounds(m, lo, hi);
    for (int d = 0; d < 3; d++) centre[d] = m->n_vertices ? 0.5 * (lo[d] + hi[d]) : 0.0;
    double six_v = 0.0;
    for (size_t t = 0; t < m->n_triangles; t++) {
        double a[3], b[3], c[3], bc[3];
        vec3_sub(m->vertex[m->triangle[t][0]], centre, a);
        vec3_sub(m->vertex[m->triangle[t][1]], centre, b);
        vec3_sub(m->vertex[m->triangle[t][2]], centre, c);
        vec3_cross(b, c, bc);
        six_v += vec3_dot(a, bc);
    }
    return six_v / 6.0;
}

double mesh_area(const struct mesh *m)
{
    double area = 0.0;
    for (size_t t = 0; t < m->n_triangles; t++) {
        double ab[3], ac[3], n[3];
        vec3_sub(m->vertex[m->triangle[t][1]], m->vertex[m->triangle[t][0]], ab);
        vec3_sub(m->vertex[m->triangle[t][2]], m->vertex[m->triangle[t][0]], ac);
        vec3_cross(ab, ac, n);
        area += 0.5 * sqrt(vec3_dot(n, n));
    }
    return area;
}

/* A directed edge of a triangle, keyed by its undirected vertex pair. */
struct edge_use {
    size_t lo, hi, triangle;
    int forward; /* runs lo -> hi in its triangle */
};

static int compare_edges(const void *pa, const void *pb)
{
    const struct edge_use *a = pa, *b = pb;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    return (a->triangle > b->triangle) - (a->triangle < b->triangle);
}

mixsph_status mesh_check_closed(const struct mesh *m, const char *name, char *err, size_t err_len)
{
    if (m->n_triangles == 0) return status_set(err, err_len, MIXSPH_ERR_ARG, "%s: no triangles", name);
    const size_t n = 3 * m->n_triangles;
    struct edge_use *e = malloc(n * sizeof *e);
    if (!e) return status_set(err, err_len, MIXSPH_ERR_NOMEM, "%s: out of memory", name);
    for (size_t t = 0; t < m->n_triangles; t++)
        for (int k = 0; k < 3; k++) {
            const size_t a = m->triangle[t][k], b = m->triangle[t][(k + 1) % 3];
            e[3 * t + k] = (struct edge_use){.lo = a < b ? a : b, .hi = a < b ? b : a, .triangle = t, .forward = a < b};
        }
    qsort(e, n, sizeof *e, compare_edges);
    mixsph_status st = MIXSPH_OK;
    for (size_t i = 0; i < n && st == MIXSPH_OK;) {
        size_t j = i;
        int forward = 0, backward = 0;
        for (; j < n && e[j].lo == e[i].lo && e[j].hi == e[i].hi; j++) *(e[j].forward ? &forward : &backward) += 1;
        if (forward != 1 || backward != 1)
            st = status_set(err, err_len, MIXSPH_ERR_ARG,
                            "%s: not closed: the edge between vertices %zu and %zu (of triangle %zu) is used by %d "
                            "triangle(s) from %zu to %zu and %d back (a closed, consistently oriented mesh: one each way)",
                            name, e[i].lo, e[i].hi, e[i].triangle, forward, e[i].lo, e[i].hi, backward);
        i = j;
    }
    free(e);
    return st;
}

double mesh_winding_number(const struct mesh *m, const double p[3])
{
    double solid_angle = 0.0;
    for (size_t t = 0; t < m->n_triangles; t++) {
        double a[3], b[3], c[3], bc[3];
        vec3_sub(m->vertex[m->triangle[t][0]], p, a);
        vec3_sub(m->vertex[m->triangle[t][1]], p, b);
        vec3_sub(m->vertex[m->triangle[t][2]], p, c);
        const double la = vec3_norm(a), lb = vec3_norm(b), lc = vec3_norm(c);
        if (la == 0.0 || lb == 0.0 || lc == 0.0) return 0.5; /* p is a vertex: on the surface */
        vec3_cross(b, c, bc);
        /* Van Oosterom & Strackee (1983): tan(omega / 2) = a.(b x c) / (|a||b||c| + (a.b)|c|
         * + (a.c)|b| + (b.c)|a|), the signed solid angle of the triangle seen from p */
        const double num = vec3_dot(a, bc);
        const double den = la * lb * lc + vec3_dot(a, b) * lc + vec3_dot(a, c) * lb + vec3_dot(b, c) * la;
        solid_angle += 2.0 * atan2(num, den);
    }
    /* a.(b x c) > 0 when p sees the triangle's back: the outward mesh's inside counts +1 */
    return solid_angle / (4.0 * GEOM_PI);
}

int mesh_contains(const struct mesh *m, const double p[3])
{
    return fabs(mesh_winding_number(m, p)) > 0.5;
}

int mesh_closest_feature(const double p[3], const double a[3], const double b[3], const double c[3],
                         double closest[3])
{
    double ab[3], ac[3], ap[3], bp[3], cp[3];
    vec3_sub(b, a, ab);
    vec3_sub(c, a, ac);
    vec3_sub(p, a, ap);
    const double d1 = vec3_dot(ab, ap), d2 = vec3_dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) { /* vertex a */
        memcpy(closest, a, 3 * sizeof *a);
        return MESH_AT_VERTEX_A;
    }
    vec3_sub(p, b, bp);
    const double d3 = vec3_dot(ab, bp), d4 = vec3_dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) { /* vertex b */
        memcpy(closest, b, 3 * sizeof *b);
        return MESH_AT_VERTEX_B;
    }
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) { /* edge ab */
        vec3_axpy(a, d1 / (d1 - d3), ab, closest);
        return MESH_AT_EDGE_AB;
    }
    vec3_sub(p, c, cp);
    const double d5 = vec3_dot(ab, cp), d6 = vec3_dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) { /* vertex c */
        memcpy(closest, c, 3 * sizeof *c);
        return MESH_AT_VERTEX_C;
    }
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) { /* edge ac */
        vec3_axpy(a, d2 / (d2 - d6), ac, closest);
        return MESH_AT_EDGE_CA;
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) { /* edge bc */
        double bc[3];
        vec3_sub(c, b, bc);
        vec3_axpy(b, (d4 - d3) / ((d4 - d3) + (d5 - d6)), bc, closest);
        return MESH_AT_EDGE_BC;
    }
    const double denom = 1.0 / (va + vb + vc); /* the face, by its barycentric coordinates */
    double q[3];
    vec3_axpy(a, vb * denom, ab, q);
    vec3_axpy(q, vc * denom, ac, closest);
    return MESH_AT_FACE;
}

void mesh_closest_on_triangle(const double p[3], const double a[3], const double b[3], const double c[3],
                              double closest[3])
{
    (void)mesh_closest_feature(p, a, b, c, closest);
}

double mesh_distance(const struct mesh *m, const double p[3], size_t *triangle, double closest[3])
{
    double best = INFINITY, best_point[3] = {NAN, NAN, NAN};
    size_t best_triangle = 0;
    for (size_t t = 0; t < m->n_triangles; t++) {
        double q[3], pq[3];
        mesh_closest_on_triangle(p, m->vertex[m->triangle[t][0]], m->vertex[m->triangle[t][1]],
                                 m->vertex[m->triangle[t][2]], q);
        vec3_sub(q, p, pq);
        const double d2 = vec3_dot(pq, pq);
        if (d2 < best) {
            best = d2;
            best_triangle = t;
            memcpy(best_point, q, sizeof q);
        }
    }
    if (triangle) *triangle = best_triangle;
    if (closest) memcpy(closest, best_point, sizeof best_point);
    return sqrt(best);
}
