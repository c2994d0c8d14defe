/* body_sites.c - the lattice sites of a 3D case's bodies (body_sites.h). */
#include "body_sites.h"

#include <math.h>
#include <string.h>

#include "mesh.h"
#include "status.h"
#include "stl.h"

/* Keep the points of ps from `first` on whose z lies in the body's range and, for a polygon, whose
 * (x, z) lies inside it; in their order. */
static void keep_in_body(struct point_set *ps, size_t first, const struct body *bd)
{
    size_t kept = first;
    for (size_t q = first; q < ps->n; q++) {
        const double *p = ps->pos[q];
        if (!(p[2] >= bd->z_min && p[2] <= bd->z_max)) continue;
        if (bd->shape == BODY_POLYGON && !geom_inside_polygon(&bd->polygon, p[0], p[2])) continue;
        memcpy(ps->pos[kept], p, sizeof ps->pos[kept]);
        memcpy(ps->normal[kept], ps->normal[q], sizeof ps->normal[kept]);
        ps->layer[kept] = ps->layer[q];
        kept++;
    }
    ps->n = kept;
}

mixsph_status body_sites(const struct case_def *c, size_t b, const struct lattice *L, struct point_set *out, char *err,
                         size_t err_len)
{
    const struct body *bd = &c->bodies[b];
    const size_t first = out->n;
    double lo[3], hi[3];
    mixsph_status st = MIXSPH_OK;
    switch (bd->shape) {
    case BODY_BOX:
        st = lattice_fill_box(L, bd->box_min, bd->box_max, out, err, err_len);
        break;
    case BODY_POLYGON: {
        double x0 = INFINITY, x1 = -INFINITY, z0 = INFINITY, z1 = -INFINITY;
        geom_grow_box(&bd->polygon, &x0, &x1, &z0, &z1);
        /* the box of the extrusion, one spacing wider so that sites on its outline are tested */
        lo[0] = x0 - L->dx, lo[1] = bd->y_min, lo[2] = fmax(z0, bd->z_min) - L->dx;
        hi[0] = x1 + L->dx, hi[1] = bd->y_max, hi[2] = fmin(z1, bd->z_max) + L->dx;
        st = lattice_fill_box(L, lo, hi, out, err, err_len);
        break;
    }
    case BODY_STL: {
        struct mesh m;
        memset(&m, 0, sizeof m);
        char msg[512];
        st = stl_read(bd->stl, &m, NULL, msg, sizeof msg);
        if (st == MIXSPH_OK) st = mesh_check_closed(&m, bd->stl, msg, sizeof msg);
        if (st != MIXSPH_OK) {
            mesh_free(&m);
            return status_set(err, err_len, MIXSPH_ERR_CASE, "%s: bodies.%s.stl: %s", c->origin, bd->name, msg);
        }
        st = lattice_fill_mesh(L, &m, out, err, err_len);
        mesh_free(&m);
        break;
    }
    case BODY_BELOW_LEVEL:
        lo[0] = c->domain[0], lo[1] = c->domain_y[0], lo[2] = fmax(c->domain[2 * DIM_UP], bd->z_min);
        hi[0] = c->domain[1], hi[1] = c->domain_y[1], hi[2] = fmin(c->domain[2 * DIM_UP + 1], bd->z_max) + L->dx;
        st = lattice_fill_box(L, lo, hi, out, err, err_len);
        break;
    default:
        return status_set(err, err_len, MIXSPH_ERR_CASE, "%s: bodies.%s: unknown shape", c->origin, bd->name);
    }
    if (st != MIXSPH_OK) return st;
    keep_in_body(out, first, bd);
    return MIXSPH_OK;
}
