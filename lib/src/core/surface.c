/* surface.c - the pseudo-normals and the bucket index of an oriented surface, and its queries
 * (surface.h). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "surface.h"

#include "status.h"
#include "vec3.h"

void surface_free(struct surface *s)
{
    mesh_free(&s->mesh);
    free(s->vertex_normal);
    free(s->edge_normal);
    free(s->edge_boundary);
    free(s->vertex_boundary);
    free(s->cell_start);
    free(s->cell_triangle);
    free(s->empty_rings);
    free(s->triangle_lo);
    free(s->triangle_hi);
    free(s->plane_offset);
    memset(s, 0, sizeof *s);
}

static void normalise(double v[3])
{
    const double len = vec3_norm(v);
    if (len > 0.0)
        for (int d = 0; d < 3; d++) v[d] /= len;
}

/* An edge of a triangle, by its vertices in increasing order, for grouping the triangles that
 * share it. */
struct edge_use {
    size_t lo, hi;
    size_t slot; /* 3 t + e */
};

static int edge_use_order(const void *pa, const void *pb)
{
    const struct edge_use *a = pa, *b = pb;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    return a->slot < b->slot ? -1 : a->slot > b->slot;
}

/* The edges' pseudo-normals (the sum of the normals of the triangles using the edge) and the
 * boundary edges and vertices. */
static int build_edges(struct surface *s)
{
    const struct mesh *m = &s->mesh;
    const size_t ne = 3 * m->n_triangles;
    struct edge_use *use = malloc(ne * sizeof *use);
    if (!use) return -1;
    for (size_t t = 0; t < m->n_triangles; t++)
        for (int e = 0; e < 3; e++) {
            const size_t a = m->triangle[t][e], b = m->triangle[t][(e + 1) % 3];
            use[3 * t + e] = (struct edge_use){.lo = a < b ? a : b, .hi = a < b ? b : a, .slot = 3 * t + e};
        }
    qsort(use, ne, sizeof *use, edge_use_order);
    for (size_t i = 0; i < ne;) {
        size_t j = i;
        double sum[3] = {0.0, 0.0, 0.0};
        while (j < ne && use[j].lo == use[i].lo && use[j].hi == use[i].hi) {
            const double *n = m->normal[use[j].slot / 3];
            for (int d = 0; d < 3; d++) sum[d] += n[d];
            j++;
        }
        normalise(sum);
        for (size_t k = i; k < j; k++) {
            memcpy(s->edge_normal[use[k].slot], sum, sizeof sum);
            s->edge_boundary[use[k].slot] = j - i == 1;
            if (j - i == 1) s->vertex_boundary[use[i].lo] = s->vertex_boundary[use[i].hi] = 1;
        }
        i = j;
    }
    free(use);
    return 0;
}

/* The vertices' pseudo-normals: each triangle's normal weighted by its angle at the vertex. */
static void build_vertex_normals(struct surface *s)
{
    const struct mesh *m = &s->mesh;
    for (size_t t = 0; t < m->n_triangles; t++)
        for (int c = 0; c < 3; c++) {
            const double *p = m->vertex[m->triangle[t][c]], *q = m->vertex[m->triangle[t][(c + 1) % 3]],
                         *r = m->vertex[m->triangle[t][(c + 2) % 3]];
            double u[3], v[3];
            vec3_sub(q, p, u);
            vec3_sub(r, p, v);
            const double cosine = vec3_dot(u, v) / (vec3_norm(u) * vec3_norm(v));
            const double angle = acos(cosine < -1.0 ? -1.0 : cosine > 1.0 ? 1.0 : cosine);
            for (int d = 0; d < 3; d++) s->vertex_normal[m->triangle[t][c]][d] += angle * m->normal[t][d];
        }
    for (size_t v = 0; v < m->n_vertices; v++) normalise(s->vertex_normal[v]);
}

size_t surface_cell_of(const struct surface *s, int d, double x)
{
    const double f = floor((x - s->lo[d]) / s->cell);
    if (!(f > 0.0)) return 0; /* also NaN */
    return f >= (double)s->n[d] ? s->n[d] - 1 : (size_t)f;
}

static size_t cell_index(const struct surface *s, size_t i, size_t j, size_t k)
{
    return (k * s->n[1] + j) * s->n[0] + i;
}

/* The box of triangle t. */
static void triangle_box(const struct mesh *m, size_t t, double lo[3], double hi[3])
{
    for (int d = 0; d < 3; d++) {
        lo[d] = hi[d] = m->vertex[m->triangle[t][0]][d];
        for (int c = 1; c < 3; c++) {
            lo[d] = fmin(lo[d], m->vertex[m->triangle[t][c]][d]);
            hi[d] = fmax(hi[d], m->vertex[m->triangle[t][c]][d]);
        }
    }
}

/* The bucket grid over the mesh's box (surface.h, "Index"). */
static int build_index(struct surface *s)
{
    const struct mesh *m = &s->mesh;
    double lo[3], hi[3], extent = 0.0, mean = 0.0;
    mesh_bounds(m, lo, hi);
    for (int d = 0; d < 3; d++) extent = fmax(extent, hi[d] - lo[d]);
    for (size_t t = 0; t < m->n_triangles; t++) {
        double tl[3], th[3], e = 0.0;
        triangle_box(m, t, tl, th);
        for (int d = 0; d < 3; d++) e = fmax(e, th[d] - tl[d]);
        mean += e / (double)m->n_triangles;
    }
    /* a margin, so that the mesh's highest coordinates fall inside the last bucket */
    const double pad = 1e-9 * extent + 1e-12;
    double cell = mean + 2.0 * pad;
    const double cap = 8.0 * (double)m->n_triangles + 64.0;
    for (;;) {
        double cells = 1.0;
        for (int d = 0; d < 3; d++) cells *= fmax(1.0, ceil((hi[d] - lo[d] + 2.0 * pad) / cell));
        if (cells <= cap) break;
        cell *= 1.25;
    }
    s->cell = cell;
    for (int d = 0; d < 3; d++) {
        s->lo[d] = lo[d] - pad;
        s->n[d] = (size_t)fmax(1.0, ceil((hi[d] - lo[d] + 2.0 * pad) / cell));
    }
    const size_t ncell = s->n[0] * s->n[1] * s->n[2];
    s->cell_start = calloc(ncell + 1, sizeof *s->cell_start);
    if (!s->cell_start) return -1;
    for (int pass = 0; pass < 2; pass++) { /* count, then fill */
        for (size_t t = 0; t < m->n_triangles; t++) {
            double tl[3], th[3];
            triangle_box(m, t, tl, th);
            size_t a[3], b[3];
            for (int d = 0; d < 3; d++) {
                a[d] = surface_cell_of(s, d, tl[d]);
                b[d] = surface_cell_of(s, d, th[d]);
            }
            for (size_t k = a[2]; k <= b[2]; k++)
                for (size_t j = a[1]; j <= b[1]; j++)
                    for (size_t i = a[0]; i <= b[0]; i++) {
                        const size_t c = cell_index(s, i, j, k);
                        if (pass == 0) s->cell_start[c + 1]++;
                        else s->cell_triangle[s->cell_start[c]++] = t;
                    }
        }
        if (pass == 0) {
            for (size_t c = 0; c < ncell; c++) s->cell_start[c + 1] += s->cell_start[c];
            s->cell_triangle = malloc((s->cell_start[ncell] + 1) * sizeof *s->cell_triangle);
            if (!s->cell_triangle) return -1;
        } else { /* filling advanced each start to the next bucket's: shift back */
            for (size_t c = ncell; c > 0; c--) s->cell_start[c] = s->cell_start[c - 1];
            s->cell_start[0] = 0;
        }
    }
    return 0;
}

/* For every bucket, the Chebyshev distance (in buckets) to the nearest one holding a triangle:
 * a breadth-first search from all of those over the 26 neighbours, capped at 65535. */
static int build_empty_rings(struct surface *s)
{
    const size_t ncell = s->n[0] * s->n[1] * s->n[2];
    size_t *queue = malloc(ncell * sizeof *queue);
    s->empty_rings = malloc(ncell * sizeof *s->empty_rings);
    if (!queue || !s->empty_rings) {
        free(queue);
        return -1;
    }
    size_t head = 0, tail = 0;
    for (size_t c = 0; c < ncell; c++) {
        const int full = s->cell_start[c + 1] > s->cell_start[c];
        s->empty_rings[c] = full ? 0 : UINT16_MAX;
        if (full) queue[tail++] = c;
    }
    while (head < tail) {
        const size_t c = queue[head++], i = c % s->n[0], j = c / s->n[0] % s->n[1], k = c / (s->n[0] * s->n[1]);
        const uint16_t next = s->empty_rings[c] == UINT16_MAX - 1 ? s->empty_rings[c] : (uint16_t)(s->empty_rings[c] + 1);
        for (int dk = -1; dk <= 1; dk++)
            for (int dj = -1; dj <= 1; dj++)
                for (int di = -1; di <= 1; di++) {
                    if ((di < 0 && i == 0) || (dj < 0 && j == 0) || (dk < 0 && k == 0) || (di > 0 && i + 1 == s->n[0]) ||
                        (dj > 0 && j + 1 == s->n[1]) || (dk > 0 && k + 1 == s->n[2]))
                        continue;
                    const size_t q = cell_index(s, (size_t)((long)i + di), (size_t)((long)j + dj), (size_t)((long)k + dk));
                    if (s->empty_rings[q] != UINT16_MAX) continue;
                    s->empty_rings[q] = next;
                    queue[tail++] = q;
                }
    }
    free(queue);
    return 0;
}

mixsph_status surface_build(struct surface *s, struct mesh *m, char *err, size_t err_len)
{
    memset(s, 0, sizeof *s);
    if (m->n_triangles == 0) return status_set(err, err_len, MIXSPH_ERR_ARG, "a surface needs at least one triangle");
    s->mesh = *m;
    memset(m, 0, sizeof *m);
    const size_t nt = s->mesh.n_triangles, nv = s->mesh.n_vertices;
    s->vertex_normal = calloc(nv, sizeof *s->vertex_normal);
    s->edge_normal = calloc(3 * nt, sizeof *s->edge_normal);
    s->edge_boundary = calloc(3 * nt, 1);
    s->vertex_boundary = calloc(nv, 1);
    s->triangle_lo = malloc(nt * sizeof *s->triangle_lo);
    s->triangle_hi = malloc(nt * sizeof *s->triangle_hi);
    s->plane_offset = malloc(nt * sizeof *s->plane_offset);
    if (!s->vertex_normal || !s->edge_normal || !s->edge_boundary || !s->vertex_boundary || !s->triangle_lo ||
        !s->triangle_hi || !s->plane_offset || build_edges(s) != 0 || build_index(s) != 0 || build_empty_rings(s) != 0) {
        surface_free(s);
        return status_set(err, err_len, MIXSPH_ERR_NOMEM, "out of memory (a surface of %zu triangles)", nt);
    }
    build_vertex_normals(s);
    for (size_t t = 0; t < nt; t++) {
        triangle_box(&s->mesh, t, s->triangle_lo[t], s->triangle_hi[t]);
        s->plane_offset[t] = vec3_dot(s->mesh.normal[t], s->mesh.vertex[s->mesh.triangle[t][0]]);
    }
    return MIXSPH_OK;
}

/* The pseudo-normal of feature f (enum mesh_feature) of triangle t, and whether it is on the
 * boundary. */
static const double *feature_normal(const struct surface *s, size_t t, int f, int *boundary)
{
    const size_t *v = s->mesh.triangle[t];
    switch (f) {
    case MESH_AT_VERTEX_A: *boundary = s->vertex_boundary[v[0]]; return s->vertex_normal[v[0]];
    case MESH_AT_VERTEX_B: *boundary = s->vertex_boundary[v[1]]; return s->vertex_normal[v[1]];
    case MESH_AT_VERTEX_C: *boundary = s->vertex_boundary[v[2]]; return s->vertex_normal[v[2]];
    case MESH_AT_EDGE_AB: *boundary = s->edge_boundary[3 * t]; return s->edge_normal[3 * t];
    case MESH_AT_EDGE_BC: *boundary = s->edge_boundary[3 * t + 1]; return s->edge_normal[3 * t + 1];
    case MESH_AT_EDGE_CA: *boundary = s->edge_boundary[3 * t + 2]; return s->edge_normal[3 * t + 2];
    default: *boundary = 0; return s->mesh.normal[t];
    }
}

/* How far p lies outside the grid along each axis (0 within its slab) [m]. */
static void outside_grid(const struct surface *s, const double p[3], double out[3])
{
    for (int d = 0; d < 3; d++) {
        const double hi = s->lo[d] + (double)s->n[d] * s->cell;
        out[d] = p[d] < s->lo[d] ? s->lo[d] - p[d] : p[d] > hi ? p[d] - hi : 0.0;
    }
}

/* A lower bound of the distance from p to every bucket outside the box of buckets c -+ r (those
 * not searched yet): beyond a face of the box (one not on the grid's edge) a bucket is at least
 * that face's gap from p along its axis, and along the others at least p's distance outside the
 * grid. INFINITY when the box covers the grid. */
static double unsearched_bound(const struct surface *s, const double p[3], const size_t c[3], size_t r,
                               const double out[3])
{
    double best = INFINITY;
    for (int d = 0; d < 3; d++) {
        double across = 0.0;
        for (int e = 0; e < 3; e++)
            if (e != d) across += out[e] * out[e];
        if (c[d] > r) { /* buckets below the box along d */
            const double gap = p[d] - (s->lo[d] + (double)(c[d] - r) * s->cell);
            best = fmin(best, sqrt(fmax(gap, 0.0) * fmax(gap, 0.0) + across));
        }
        if (c[d] + r + 1 < s->n[d]) { /* buckets above it */
            const double gap = s->lo[d] + (double)(c[d] + r + 1) * s->cell - p[d];
            best = fmin(best, sqrt(fmax(gap, 0.0) * fmax(gap, 0.0) + across));
        }
    }
    return best;
}

/* The nearest of the triangles of bucket (i, j, k) to p, if nearer than *best2. */
static void search_bucket(const struct surface *s, const double p[3], size_t i, size_t j, size_t k, double *best2,
                          size_t *best_t, int *best_f, double best_point[3])
{
    const struct mesh *m = &s->mesh;
    const size_t cell = cell_index(s, i, j, k);
    for (size_t q = s->cell_start[cell]; q < s->cell_start[cell + 1]; q++) {
        const size_t t = s->cell_triangle[q];
        double x[3], px[3];
        const int f = mesh_closest_feature(p, m->vertex[m->triangle[t][0]], m->vertex[m->triangle[t][1]],
                                           m->vertex[m->triangle[t][2]], x);
        vec3_sub(x, p, px);
        const double d2 = vec3_dot(px, px);
        if (d2 < *best2) {
            *best2 = d2;
            *best_t = t;
            *best_f = f;
            memcpy(best_point, x, sizeof x);
        }
    }
}

double surface_signed_distance_within(const struct surface *s, const double p[3], double max_distance,
                                      struct surface_point *at)
{
    if (s->mesh.n_triangles == 0) return INFINITY;
    size_t c[3], reach = 0;
    double out[3];
    outside_grid(s, p, out);
    for (int d = 0; d < 3; d++) {
        c[d] = surface_cell_of(s, d, p[d]);
        const size_t far = c[d] > s->n[d] - 1 - c[d] ? c[d] : s->n[d] - 1 - c[d];
        if (far > reach) reach = far;
    }
    double best2 = INFINITY, best_point[3] = {0.0, 0.0, 0.0};
    size_t best_t = 0;
    int best_f = MESH_AT_FACE;
    /* the shells of buckets at Chebyshev distance r from c, clipped to the grid; those nearer than
     * the first bucket with a triangle are empty */
    const size_t first = s->empty_rings[cell_index(s, c[0], c[1], c[2])];
    if (first > 0 && unsearched_bound(s, p, c, first - 1, out) > max_distance) return INFINITY;
    for (size_t r = first; r <= reach; r++) {
        size_t a[3], b[3];
        for (int d = 0; d < 3; d++) {
            a[d] = c[d] >= r ? c[d] - r : 0;
            b[d] = c[d] + r < s->n[d] ? c[d] + r : s->n[d] - 1;
        }
        for (size_t k = a[2]; k <= b[2]; k++)
            for (size_t j = a[1]; j <= b[1]; j++) {
                const int jk_on_shell = k + r == c[2] || k == c[2] + r || j + r == c[1] || j == c[1] + r;
                if (jk_on_shell) {
                    for (size_t i = a[0]; i <= b[0]; i++) search_bucket(s, p, i, j, k, &best2, &best_t, &best_f, best_point);
                    continue;
                }
                if (c[0] >= r) search_bucket(s, p, c[0] - r, j, k, &best2, &best_t, &best_f, best_point);
                if (r > 0 && c[0] + r < s->n[0]) search_bucket(s, p, c[0] + r, j, k, &best2, &best_t, &best_f, best_point);
            }
        const double bound = unsearched_bound(s, p, c, r, out);
        if (best2 < INFINITY && sqrt(best2) <= bound) break;
        if (best2 == INFINITY && bound > max_distance) return INFINITY;
        if (best2 < INFINITY && bound > max_distance && sqrt(best2) > max_distance) return INFINITY;
    }
    const double dist = sqrt(best2);
    if (dist > max_distance) return INFINITY;
    int boundary;
    const double *n = feature_normal(s, best_t, best_f, &boundary);
    double pq[3];
    vec3_sub(p, best_point, pq);
    const double side = vec3_dot(pq, n);
    if (at) {
        memcpy(at->closest, best_point, sizeof best_point);
        memcpy(at->normal, n, 3 * sizeof *n);
        at->triangle = best_t;
        at->at_boundary = boundary;
    }
    return side < 0.0 ? -dist : dist;
}

double surface_signed_distance(const struct surface *s, const double p[3], struct surface_point *at)
{
    return surface_signed_distance_within(s, p, INFINITY, at);
}

int surface_may_be_within(const struct surface *s, const double p[3], double reach)
{
    if (s->mesh.n_triangles == 0) return 0;
    /* a triangle within reach of p has its box within reach: that box meets the cube p -+ reach
     * inside the grid, so the triangle is listed in a bucket of the cube's range (clamped) */
    size_t a[3], b[3];
    for (int d = 0; d < 3; d++) {
        const double grid_hi = s->lo[d] + (double)s->n[d] * s->cell;
        if (isnan(p[d])) return 1;
        if (p[d] + reach < s->lo[d] || p[d] - reach > grid_hi) return 0;
        a[d] = surface_cell_of(s, d, p[d] - reach);
        b[d] = surface_cell_of(s, d, p[d] + reach);
    }
    const double reach2 = reach * reach;
    for (size_t k = a[2]; k <= b[2]; k++)
        for (size_t j = a[1]; j <= b[1]; j++)
            for (size_t i = a[0]; i <= b[0]; i++) {
                const size_t cell = cell_index(s, i, j, k);
                for (size_t q = s->cell_start[cell]; q < s->cell_start[cell + 1]; q++) {
                    const size_t t = s->cell_triangle[q];
                    const double *lo = s->triangle_lo[t], *hi = s->triangle_hi[t];
                    double gap2 = 0.0;
                    for (int d = 0; d < 3; d++) {
                        const double g = p[d] < lo[d] ? lo[d] - p[d] : p[d] > hi[d] ? p[d] - hi[d] : 0.0;
                        gap2 += g * g;
                    }
                    if (gap2 > reach2) continue;
                    if (fabs(vec3_dot(s->mesh.normal[t], p) - s->plane_offset[t]) > reach) continue;
                    return 1;
                }
            }
    return 0;
}

int surface_first_crossing(const struct surface *s, const double a[3], const double b[3], double *t_hit, double n[3])
{
    const struct mesh *m = &s->mesh;
    if (m->n_triangles == 0) return 0;
    size_t lo[3], hi[3];
    for (int d = 0; d < 3; d++) {
        const double grid_hi = s->lo[d] + (double)s->n[d] * s->cell;
        if (fmax(a[d], b[d]) < s->lo[d] || fmin(a[d], b[d]) > grid_hi) return 0;
        lo[d] = surface_cell_of(s, d, fmin(a[d], b[d]));
        hi[d] = surface_cell_of(s, d, fmax(a[d], b[d]));
    }
    /* Moeller & Trumbore (1997), J. Graphics Tools 2: a + t (b - a) = v0 + u e1 + v e2. With
     * n = e1 x e2, det = e1 . (dir x e2) = -dir . n > 0 is a crossing from the front to the back. A
     * crossing through an edge or a vertex is counted by the tolerance on u and v. */
    const double tol = 1e-9;
    double dir[3], best = INFINITY;
    size_t best_t = 0;
    vec3_sub(b, a, dir);
    for (size_t k = lo[2]; k <= hi[2]; k++)
        for (size_t j = lo[1]; j <= hi[1]; j++)
            for (size_t i = lo[0]; i <= hi[0]; i++) {
                const size_t cell = cell_index(s, i, j, k);
                for (size_t q = s->cell_start[cell]; q < s->cell_start[cell + 1]; q++) {
                    const size_t t = s->cell_triangle[q];
                    const double *v0 = m->vertex[m->triangle[t][0]];
                    double e1[3], e2[3], pv[3], tv[3], qv[3];
                    vec3_sub(m->vertex[m->triangle[t][1]], v0, e1);
                    vec3_sub(m->vertex[m->triangle[t][2]], v0, e2);
                    vec3_cross(dir, e2, pv);
                    const double det = vec3_dot(e1, pv);
                    if (!(det > 0.0)) continue; /* back to front, parallel, or no step */
                    vec3_sub(a, v0, tv);
                    const double u = vec3_dot(tv, pv) / det;
                    if (u < -tol || u > 1.0 + tol) continue;
                    vec3_cross(tv, e1, qv);
                    const double v = vec3_dot(dir, qv) / det;
                    if (v < -tol || u + v > 1.0 + tol) continue;
                    const double t_cross = vec3_dot(e2, qv) / det;
                    if (t_cross < 0.0 || t_cross > 1.0 || !(t_cross < best)) continue;
                    best = t_cross;
                    best_t = t;
                }
            }
    if (!(best <= 1.0)) return 0;
    *t_hit = best;
    memcpy(n, m->normal[best_t], 3 * sizeof *n);
    return 1;
}
