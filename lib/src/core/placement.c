/* placement.c - see placement.h. */
#include "placement.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "status.h"
#include "vec3.h"

/* ---- point sets --------------------------------------------------------------------------- */

void point_set_free(struct point_set *ps)
{
    free(ps->pos);
    free(ps->normal);
    free(ps->layer);
    memset(ps, 0, sizeof *ps);
}

mixsph_status point_set_push(struct point_set *ps, const double pos[3], const double normal[3], int layer,
                             size_t max_points, char *err, size_t err_len)
{
    if (max_points && ps->n >= max_points)
        return status_set(err, err_len, MIXSPH_ERR_ARG, "placement: more than the limit of %zu points", max_points);
    if (ps->n == ps->cap) {
        const size_t cap = ps->cap ? 2 * ps->cap : 1024;
        double(*p)[3] = realloc(ps->pos, cap * sizeof *p);
        if (p) ps->pos = p;
        double(*n)[3] = p ? realloc(ps->normal, cap * sizeof *n) : NULL;
        if (n) ps->normal = n;
        int *l = n ? realloc(ps->layer, cap * sizeof *l) : NULL;
        if (!l) return status_set(err, err_len, MIXSPH_ERR_NOMEM, "placement: out of memory at %zu points", ps->n);
        ps->layer = l;
        ps->cap = cap;
    }
    memcpy(ps->pos[ps->n], pos, sizeof ps->pos[0]);
    if (normal) memcpy(ps->normal[ps->n], normal, sizeof ps->normal[0]);
    else memset(ps->normal[ps->n], 0, sizeof ps->normal[0]);
    ps->layer[ps->n] = layer;
    ps->n++;
    return MIXSPH_OK;
}

void point_set_keep(struct point_set *ps, size_t first, const struct mesh *m, int keep_inside)
{
    size_t kept = first;
    for (size_t k = first; k < ps->n; k++) {
        if (mesh_contains(m, ps->pos[k]) != (keep_inside != 0)) continue;
        memmove(ps->pos[kept], ps->pos[k], sizeof ps->pos[0]);
        memmove(ps->normal[kept], ps->normal[k], sizeof ps->normal[0]);
        ps->layer[kept++] = ps->layer[k];
    }
    ps->n = kept;
}

/* ---- the lattice -------------------------------------------------------------------------- */

/* The coordinate of site index i along an axis: one expression for every fill. */
static double site(double origin, double dx, long long i)
{
    return origin + ((double)i + 0.5) * dx;
}

/* The site indices [*first, *last] with lo <= site < hi along one axis; 0 if there are none. */
static int site_range(double origin, double dx, double lo, double hi, long long *first, long long *last)
{
    if (!(hi > lo)) return 0;
    long long i = (long long)floor((lo - origin) / dx - 0.5) - 1;
    while (site(origin, dx, i) < lo) i++;
    long long j = (long long)ceil((hi - origin) / dx - 0.5) + 1;
    while (j >= i && !(site(origin, dx, j) < hi)) j--;
    *first = i;
    *last = j;
    return j >= i;
}

static mixsph_status check_lattice(const struct lattice *L, const double lo[3], const double hi[3], const char *what,
                                   char *err, size_t err_len)
{
    if (!(L->dx > 0.0) || !isfinite(L->dx))
        return status_set(err, err_len, MIXSPH_ERR_ARG, "%s: dx = %g: a finite, positive spacing", what, L->dx);
    for (int d = 0; d < 3; d++) {
        if (!isfinite(L->origin[d]) || !isfinite(lo[d]) || !isfinite(hi[d]))
            return status_set(err, err_len, MIXSPH_ERR_ARG, "%s: axis %c: a non-finite bound or origin", what, "xyz"[d]);
        /* a bound on the sites of one axis, against an absurd box (and overflow of the indices) */
        if ((hi[d] - lo[d]) / L->dx > 1e7)
            return status_set(err, err_len, MIXSPH_ERR_ARG, "%s: axis %c: [%g, %g] spans more than 1e7 sites of %g",
                              what, "xyz"[d], lo[d], hi[d], L->dx);
    }
    return MIXSPH_OK;
}

mixsph_status lattice_fill_box(const struct lattice *L, const double lo[3], const double hi[3], struct point_set *out,
                               char *err, size_t err_len)
{
    mixsph_status st = check_lattice(L, lo, hi, "box fill", err, err_len);
    long long first[3], last[3];
    for (int d = 0; d < 3; d++)
        if (st == MIXSPH_OK && !site_range(L->origin[d], L->dx, lo[d], hi[d], &first[d], &last[d])) return MIXSPH_OK;
    for (long long k = first[2]; st == MIXSPH_OK && k <= last[2]; k++)
        for (long long j = first[1]; st == MIXSPH_OK && j <= last[1]; j++)
            for (long long i = first[0]; st == MIXSPH_OK && i <= last[0]; i++) {
                const double p[3] = {site(L->origin[0], L->dx, i), site(L->origin[1], L->dx, j),
                                     site(L->origin[2], L->dx, k)};
                st = point_set_push(out, p, NULL, -1, L->max_points, err, err_len);
            }
    return st;
}

mixsph_status lattice_fill_terrain(const struct lattice *L, const struct terrain *t, const double lo[3],
                                   const double hi[3], double z_max, struct point_set *out, char *err, size_t err_len)
{
    mixsph_status st = check_lattice(L, lo, hi, "terrain fill", err, err_len);
    long long first[3], last[3];
    for (int d = 0; d < 3; d++)
        if (st == MIXSPH_OK && !site_range(L->origin[d], L->dx, lo[d], hi[d], &first[d], &last[d])) return MIXSPH_OK;
    for (long long j = first[1]; st == MIXSPH_OK && j <= last[1]; j++)
        for (long long i = first[0]; st == MIXSPH_OK && i <= last[0]; i++) {
            const double x = site(L->origin[0], L->dx, i), y = site(L->origin[1], L->dx, j);
            const double ground = terrain_height(t, x, y);
            if (isnan(ground)) continue;
            for (long long k = first[2]; st == MIXSPH_OK && k <= last[2]; k++) {
                const double p[3] = {x, y, site(L->origin[2], L->dx, k)};
                if (p[2] > ground && p[2] < z_max) st = point_set_push(out, p, NULL, -1, L->max_points, err, err_len);
            }
        }
    return st;
}

/* The extent [*lo, *hi] along the first coordinate of the triangle c (2D points) on the line
 * where the second coordinate is r; 0 when the line misses it. Its rows are what the two
 * rasterisations below walk, so that a long thin triangle costs its rows and points, not its
 * bounding box. */
static int triangle_row_span(const double c[3][2], double r, double *lo, double *hi)
{
    *lo = INFINITY;
    *hi = -INFINITY;
    for (int k = 0; k < 3; k++) {
        const double *p = c[k], *q = c[(k + 1) % 3];
        if (r < fmin(p[1], q[1]) || r > fmax(p[1], q[1])) continue;
        if (p[1] == q[1]) {
            *lo = fmin(*lo, fmin(p[0], q[0]));
            *hi = fmax(*hi, fmax(p[0], q[0]));
        } else {
            const double x = p[0] + (r - p[1]) * (q[0] - p[0]) / (q[1] - p[1]);
            *lo = fmin(*lo, x);
            *hi = fmax(*hi, x);
        }
    }
    return *lo <= *hi;
}

/* ---- the column sweep --------------------------------------------------------------------- */

/* A mesh's crossings of the lattice's vertical columns, sorted by column then height. */
struct crossing {
    size_t column; /* (i - first_i) + columns_x (j - first_j) */
    double z;      /* [m] */
    int sign;      /* +1 entering going up (the face looks down), -1 leaving */
};

struct columns {
    long long first[2], last[2]; /* the columns' site indices along x and y */
    size_t nx, ny;
    struct crossing *crossing;
    size_t n, cap;
};

/* Is a before b, x then y then z? The canonical order of an edge's endpoints. */
static int vertex_before(const double a[3], const double b[3])
{
    if (a[0] != b[0]) return a[0] < b[0];
    if (a[1] != b[1]) return a[1] < b[1];
    return a[2] < b[2];
}

/* The orientation of q against the projected edge p -> r: *value the plain determinant (twice
 * the signed area of p, r, q in x-y, used for heights), the returned sign that of q perturbed
 * by (eps, eps^2) (never 0 for an edge of non-zero projected length). Computed with the endpoints
 * in their canonical order and negated for the other, so that both triangles of an edge see one
 * value. */
static int edge_side(const double p[3], const double r[3], const double q[2], double *value)
{
    const int swap = vertex_before(r, p);
    const double *a = swap ? r : p, *b = swap ? p : r;
    const double ex = b[0] - a[0], ey = b[1] - a[1];
    double det = ex * (q[1] - a[1]) - ey * (q[0] - a[0]);
    int sign = det > 0.0 ? 1 : det < 0.0 ? -1 : 0;
    if (sign == 0) sign = ey != 0.0 ? (ey < 0.0 ? 1 : -1) : (ex > 0.0 ? 1 : -1); /* d det = -ey eps + ex eps^2 */
    if (swap) {
        det = -det;
        sign = -sign;
    }
    *value = det;
    return sign;
}

static mixsph_status push_crossing(struct columns *c, size_t column, double z, int sign, char *err, size_t err_len)
{
    if (c->n == c->cap) {
        const size_t cap = c->cap ? 2 * c->cap : 1024;
        struct crossing *more = realloc(c->crossing, cap * sizeof *more);
        if (!more) return status_set(err, err_len, MIXSPH_ERR_NOMEM, "column sweep: out of memory");
        c->crossing = more;
        c->cap = cap;
    }
    c->crossing[c->n++] = (struct crossing){.column = column, .z = z, .sign = sign};
    return MIXSPH_OK;
}

static int compare_crossings(const void *pa, const void *pb)
{
    const struct crossing *a = pa, *b = pb;
    if (a->column != b->column) return a->column < b->column ? -1 : 1;
    return (a->z > b->z) - (a->z < b->z);
}

/* The crossings of the mesh with the columns of the lattice whose sites lie in the x-y box
 * [lo, hi) (0 columns: *c stays empty). */
static mixsph_status sweep_columns(const struct lattice *L, const struct mesh *m, const double lo[2],
                                   const double hi[2], struct columns *c, char *err, size_t err_len)
{
    memset(c, 0, sizeof *c);
    for (int d = 0; d < 2; d++)
        if (!site_range(L->origin[d], L->dx, lo[d], hi[d], &c->first[d], &c->last[d])) return MIXSPH_OK;
    c->nx = (size_t)(c->last[0] - c->first[0] + 1);
    c->ny = (size_t)(c->last[1] - c->first[1] + 1);
    for (size_t t = 0; t < m->n_triangles; t++) {
        const double *A = m->vertex[m->triangle[t][0]], *B = m->vertex[m->triangle[t][1]], *C = m->vertex[m->triangle[t][2]];
        const double area2 = (B[0] - A[0]) * (C[1] - A[1]) - (B[1] - A[1]) * (C[0] - A[0]);
        if (area2 == 0.0) continue; /* vertical: no column crosses it */
        const int orientation = area2 > 0.0 ? 1 : -1;
        const double projected[3][2] = {{A[0], A[1]}, {B[0], B[1]}, {C[0], C[1]}};
        const double y_lo = fmin(A[1], fmin(B[1], C[1])), y_hi = fmax(A[1], fmax(B[1], C[1]));
        long long j0 = (long long)floor((y_lo - L->origin[1]) / L->dx - 0.5);
        long long j1 = (long long)ceil((y_hi - L->origin[1]) / L->dx - 0.5);
        if (j0 < c->first[1]) j0 = c->first[1];
        if (j1 > c->last[1]) j1 = c->last[1];
        for (long long j = j0; j <= j1; j++) {
            double x_lo, x_hi; /* the row's span, widened by a site: the exact test below decides */
            if (!triangle_row_span(projected, site(L->origin[1], L->dx, j), &x_lo, &x_hi)) continue;
            long long i0 = (long long)floor((x_lo - L->origin[0]) / L->dx - 0.5) - 1;
            long long i1 = (long long)ceil((x_hi - L->origin[0]) / L->dx - 0.5) + 1;
            if (i0 < c->first[0]) i0 = c->first[0];
            if (i1 > c->last[0]) i1 = c->last[0];
            for (long long i = i0; i <= i1; i++) {
                const double q[2] = {site(L->origin[0], L->dx, i), site(L->origin[1], L->dx, j)};
                double wa, wb, wc; /* each vertex's weight: the opposite edge's determinant */
                if (edge_side(B, C, q, &wa) != orientation || edge_side(C, A, q, &wb) != orientation ||
                    edge_side(A, B, q, &wc) != orientation)
                    continue;
                const double w = wa + wb + wc;
                /* relative to A: exact on a level face, so a site on it is kept by the rule
                 * lo <= z exactly (on a sloping face round-off decides) */
                const double z = A[2] + (w != 0.0 ? (wb * (B[2] - A[2]) + wc * (C[2] - A[2])) / w : 0.0);
                const size_t column = (size_t)(i - c->first[0]) + c->nx * (size_t)(j - c->first[1]);
                /* the normal's z has the sign of the projected area: looking down (-) enters */
                mixsph_status st = push_crossing(c, column, z, -orientation, err, err_len);
                if (st != MIXSPH_OK) return st;
            }
        }
    }
    qsort(c->crossing, c->n, sizeof *c->crossing, compare_crossings);
    return MIXSPH_OK;
}

/* Which sites of a column a fill keeps: inside the closed mesh, or above the highest crossing. */
enum column_rule { INSIDE_BODY, ABOVE_SURFACE };

/* The sites of column (i, j) with z in [zlo, zhi) and below z_max that `rule` keeps, given the
 * column's n > 0 crossings cr. */
static mixsph_status fill_column(const struct lattice *L, const struct mesh *m, enum column_rule rule, long long i,
                                 long long j, const struct crossing *cr, size_t n, double zlo, double zhi,
                                 double z_max, struct point_set *out, char *err, size_t err_len)
{
    long long first, last;
    if (!site_range(L->origin[2], L->dx, zlo, fmin(zhi, z_max), &first, &last)) return MIXSPH_OK;
    int total = 0;
    for (size_t k = 0; k < n; k++) total += cr[k].sign;
    const double x = site(L->origin[0], L->dx, i), y = site(L->origin[1], L->dx, j);
    size_t below = 0; /* crossings at or below the site */
    int winding = 0;
    for (long long k = first; k <= last; k++) {
        const double p[3] = {x, y, site(L->origin[2], L->dx, k)};
        while (below < n && cr[below].z <= p[2]) winding += cr[below++].sign;
        int keep;
        if (rule == ABOVE_SURFACE) keep = cr[n - 1].z < p[2]; /* above the highest crossing */
        else if (total == 0) keep = winding != 0;
        else keep = mesh_contains(m, p); /* rounding broke this column's crossings */
        if (keep) {
            mixsph_status st = point_set_push(out, p, NULL, -1, L->max_points, err, err_len);
            if (st != MIXSPH_OK) return st;
        }
    }
    return MIXSPH_OK;
}

static mixsph_status fill_columns(const struct lattice *L, const struct mesh *m, enum column_rule rule,
                                  const double lo[3], const double hi[3], double z_max, struct point_set *out,
                                  char *err, size_t err_len)
{
    struct columns c;
    mixsph_status st = sweep_columns(L, m, lo, hi, &c, err, err_len);
    /* a column without crossings is outside any body and misses any surface: only the columns
     * with crossings are walked */
    for (size_t at = 0, end; at < c.n && st == MIXSPH_OK; at = end) {
        const size_t column = c.crossing[at].column;
        for (end = at; end < c.n && c.crossing[end].column == column;) end++;
        st = fill_column(L, m, rule, c.first[0] + (long long)(column % c.nx), c.first[1] + (long long)(column / c.nx),
                         c.crossing + at, end - at, lo[2], hi[2], z_max, out, err, err_len);
    }
    free(c.crossing);
    return st;
}

mixsph_status lattice_fill_mesh(const struct lattice *L, const struct mesh *body, struct point_set *out, char *err,
                                size_t err_len)
{
    double lo[3], hi[3];
    mesh_bounds(body, lo, hi);
    if (body->n_triangles == 0) return status_set(err, err_len, MIXSPH_ERR_ARG, "mesh fill: the mesh has no triangles");
    for (int d = 0; d < 3; d++) hi[d] = nextafter(hi[d], INFINITY); /* a site on the top face is tested too */
    mixsph_status st = check_lattice(L, lo, hi, "mesh fill", err, err_len);
    if (st != MIXSPH_OK) return st;
    return fill_columns(L, body, INSIDE_BODY, lo, hi, INFINITY, out, err, err_len);
}

mixsph_status lattice_fill_above_mesh(const struct lattice *L, const struct mesh *surface, const double lo[3],
                                      const double hi[3], double z_max, struct point_set *out, char *err,
                                      size_t err_len)
{
    mixsph_status st = check_lattice(L, lo, hi, "fill above a surface", err, err_len);
    if (st != MIXSPH_OK) return st;
    return fill_columns(L, surface, ABOVE_SURFACE, lo, hi, z_max, out, err, err_len);
}

/* ---- points on a surface ------------------------------------------------------------------ */

/* The points placed by one call, hashed by cells of the merge distance: a point is dropped when
 * one of them lies closer. Open addressing on the cell's integer coordinates; a cell's points
 * are chained through `next`. */
struct merge_grid {
    double cell;    /* the merge distance [m] */
    size_t first;   /* the set's first point of this call */
    size_t cap;     /* slots, a power of 2 */
    size_t used;
    long long (*key)[3];
    size_t *head;   /* per slot: its cell's last point + 1, 0 for an empty slot */
    size_t *next;   /* per point from `first`: the previous point of its cell + 1, 0 at the end */
    size_t next_cap;
};

static size_t cell_slot(const struct merge_grid *g, const long long key[3])
{
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (int d = 0; d < 3; d++) {
        h ^= (uint64_t)key[d] + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
        h *= 0xBF58476D1CE4E5B9ull;
    }
    size_t i = (size_t)(h ^ (h >> 31)) & (g->cap - 1);
    while (g->head[i] && memcmp(g->key[i], key, sizeof g->key[i]) != 0) i = (i + 1) & (g->cap - 1);
    return i;
}

static void cell_of(const struct merge_grid *g, const double p[3], long long key[3])
{
    for (int d = 0; d < 3; d++) key[d] = (long long)floor(p[d] / g->cell);
}

/* Is a point of this call within the merge distance of p? */
static int merge_near(const struct merge_grid *g, const struct point_set *ps, const double p[3])
{
    if (g->used == 0) return 0;
    long long key[3], around[3];
    cell_of(g, p, key);
    for (int a = -1; a <= 1; a++)
        for (int b = -1; b <= 1; b++)
            for (int c = -1; c <= 1; c++) {
                around[0] = key[0] + a;
                around[1] = key[1] + b;
                around[2] = key[2] + c;
                for (size_t k = g->head[cell_slot(g, around)]; k; k = g->next[k - 1 - g->first]) {
                    double d[3];
                    vec3_sub(ps->pos[k - 1], p, d);
                    if (vec3_dot(d, d) < g->cell * g->cell) return 1;
                }
            }
    return 0;
}

/* Hash point `index` of ps (the last one pushed). */
static mixsph_status merge_insert(struct merge_grid *g, const struct point_set *ps, size_t index, char *err,
                                  size_t err_len)
{
    if (2 * (g->used + 1) > g->cap) { /* rehash into twice the slots, at most half full */
        struct merge_grid bigger = *g;
        bigger.cap = g->cap ? 2 * g->cap : 4096;
        bigger.key = malloc(bigger.cap * sizeof *bigger.key);
        bigger.head = calloc(bigger.cap, sizeof *bigger.head);
        if (!bigger.key || !bigger.head) {
            free(bigger.key);
            free(bigger.head);
            return status_set(err, err_len, MIXSPH_ERR_NOMEM, "surface points: out of memory");
        }
        for (size_t s = 0; s < g->cap; s++)
            if (g->head[s]) {
                const size_t to = cell_slot(&bigger, g->key[s]);
                memcpy(bigger.key[to], g->key[s], sizeof bigger.key[to]);
                bigger.head[to] = g->head[s];
            }
        free(g->key);
        free(g->head);
        *g = bigger;
    }
    const size_t at = index - g->first;
    if (at >= g->next_cap) {
        const size_t cap = g->next_cap ? 2 * g->next_cap : 4096;
        size_t *next = realloc(g->next, cap * sizeof *next);
        if (!next) return status_set(err, err_len, MIXSPH_ERR_NOMEM, "surface points: out of memory");
        g->next = next;
        g->next_cap = cap;
    }
    long long key[3];
    cell_of(g, ps->pos[index], key);
    const size_t s = cell_slot(g, key);
    if (!g->head[s]) {
        memcpy(g->key[s], key, sizeof g->key[s]);
        g->used++;
    }
    g->next[at] = g->head[s];
    g->head[s] = index + 1;
    return MIXSPH_OK;
}

/* The lattice of a triangle's plane: its axes u, v (u x v = n) depend only on the normal n, and
 * its origin is the anchor projected onto the plane. u is the world axis least aligned with n,
 * made perpendicular; of axes within 1e-9 of the least, the first, so that normals differing by
 * round-off (coplanar triangles) choose the same one. */
struct plane_lattice {
    double origin[3], u[3], v[3];
};

static struct plane_lattice plane_lattice(const double n[3], const double on_plane[3], const double anchor[3])
{
    struct plane_lattice pl;
    const double least = fmin(fabs(n[0]), fmin(fabs(n[1]), fabs(n[2])));
    int axis = 0;
    while (fabs(n[axis]) > least + 1e-9) axis++;
    double e[3] = {0.0, 0.0, 0.0};
    e[axis] = 1.0;
    vec3_axpy(e, -n[axis], n, pl.u);
    const double len = vec3_norm(pl.u);
    for (int d = 0; d < 3; d++) pl.u[d] /= len;
    vec3_cross(n, pl.u, pl.v);
    double rel[3];
    vec3_sub(anchor, on_plane, rel);
    vec3_axpy(anchor, -vec3_dot(rel, n), n, pl.origin);
    return pl;
}

/* The lattice points of one triangle's plane that lie on it (within 1e-9 dx of its edges),
 * moved `depth` along -n, pushed unless a point of this call is within the merge distance. */
static mixsph_status sample_triangle(const struct surface_sampling *S, const struct mesh *m, size_t t, int layer,
                                     struct merge_grid *g, struct point_set *out, char *err, size_t err_len)
{
    const double *n = m->normal[t];
    const double *corner[3] = {m->vertex[m->triangle[t][0]], m->vertex[m->triangle[t][1]], m->vertex[m->triangle[t][2]]};
    const struct plane_lattice pl = plane_lattice(n, corner[0], S->anchor);
    double c2[3][2], lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int k = 0; k < 3; k++) {
        double rel[3];
        vec3_sub(corner[k], pl.origin, rel);
        c2[k][0] = vec3_dot(rel, pl.u);
        c2[k][1] = vec3_dot(rel, pl.v);
        for (int d = 0; d < 2; d++) {
            lo[d] = fmin(lo[d], c2[k][d]);
            hi[d] = fmax(hi[d], c2[k][d]);
        }
    }
    /* each edge's inward unit normal in the plane (the triangle is counter-clockwise in u, v) */
    double edge_n[3][2], edge_c[3];
    for (int k = 0; k < 3; k++) {
        const double *a = c2[k], *b = c2[(k + 1) % 3];
        const double ex = b[0] - a[0], ey = b[1] - a[1], len = hypot(ex, ey);
        edge_n[k][0] = -ey / len;
        edge_n[k][1] = ex / len;
        edge_c[k] = edge_n[k][0] * a[0] + edge_n[k][1] * a[1];
    }
    if ((hi[0] - lo[0]) / S->dx > 1e7 || (hi[1] - lo[1]) / S->dx > 1e7)
        return status_set(err, err_len, MIXSPH_ERR_ARG, "surface points: triangle %zu spans more than 1e7 points of %g",
                          t, S->dx);
    const double slack = 1e-9 * S->dx, depth = S->first_depth + layer * S->dx;
    const long long j0 = (long long)ceil(lo[1] / S->dx - 1e-9), j1 = (long long)floor(hi[1] / S->dx + 1e-9);
    for (long long j = j0; j <= j1; j++) {
        double s_lo, s_hi; /* the row's span, widened by a point: the test below decides */
        if (!triangle_row_span((const double(*)[2])c2, fmin(fmax((double)j * S->dx, lo[1]), hi[1]), &s_lo, &s_hi))
            continue;
        const long long i0 = (long long)ceil(s_lo / S->dx) - 1, i1 = (long long)floor(s_hi / S->dx) + 1;
        for (long long i = i0; i <= i1; i++) {
            const double s = (double)i * S->dx, r = (double)j * S->dx;
            int on = 1;
            for (int k = 0; k < 3 && on; k++) on = edge_n[k][0] * s + edge_n[k][1] * r - edge_c[k] >= -slack;
            if (!on) continue;
            double p[3];
            vec3_axpy(pl.origin, s, pl.u, p);
            vec3_axpy(p, r, pl.v, p);
            vec3_axpy(p, -depth, n, p);
            if (merge_near(g, out, p)) continue;
            mixsph_status st = point_set_push(out, p, n, layer, S->max_points, err, err_len);
            if (st == MIXSPH_OK) st = merge_insert(g, out, out->n - 1, err, err_len);
            if (st != MIXSPH_OK) return st;
        }
    }
    return MIXSPH_OK;
}

mixsph_status surface_sample(const struct surface_sampling *S, const struct mesh *m, struct point_set *out, char *err,
                             size_t err_len)
{
    if (!(S->dx > 0.0) || !isfinite(S->dx) || S->layers < 1 || !(S->merge > 0.0 && S->merge < 1.0) ||
        !isfinite(S->first_depth) || !isfinite(S->anchor[0]) || !isfinite(S->anchor[1]) || !isfinite(S->anchor[2]))
        return status_set(err, err_len, MIXSPH_ERR_ARG,
                          "surface points: dx = %g (positive), layers = %d (at least 1), merge = %g (in (0, 1)), "
                          "first_depth = %g and the anchor finite",
                          S->dx, S->layers, S->merge, S->first_depth);
    struct merge_grid g = {.cell = S->merge * S->dx, .first = out->n};
    mixsph_status st = MIXSPH_OK;
    for (int layer = 0; layer < S->layers && st == MIXSPH_OK; layer++) /* the surface first: its points win */
        for (size_t t = 0; t < m->n_triangles && st == MIXSPH_OK; t++)
            st = sample_triangle(S, m, t, layer, &g, out, err, err_len);
    free(g.key);
    free(g.head);
    free(g.next);
    return st;
}
