/* budget.c - see budget.h. The estimates are "about": a body's particles are its area (clipped to
 * its z_min..z_max) over dx^2, which the lattice fill meets to within its boundary rows; overlapping
 * bodies count twice, so the estimate errs on the high side only there (tests/test_budget.c: within
 * 10 % for the bundled cases). The steps use the largest time step criterion (4) allows at rest at
 * the reference density (integrate.h), so the estimate is a lower bound up to the density
 * variation of a weakly compressible run (about 1 %): a case it refuses would take about that
 * many steps or more. */
#include "budget.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "case_schema.h"
#include "geometry.h"
#include "law_registry.h"
#include "mesh.h"
#include "stl.h"
#include "time_step.h"
#include "status.h"

/* Bytes one particle adds to one snapshot: a row of snap_NNNN.csv (ten fields of 1-13 characters,
 * about 90 bytes) and its values in run.h5 (seven doubles and three small integers, about 70). */
#define BUDGET_SNAPSHOT_BYTES_PER_PARTICLE 160.0
/* ... and in 3D the y columns more: y and v_y (about 26 bytes of CSV, 16 of run.h5) */
#define BUDGET_SNAPSHOT_BYTES_3D 40.0

/* Lattice sites of the box [x0, x1] x [z0, z1] at spacing dx, as the fills scan it (one site of
 * margin on each side). */
static double box_sites(double x0, double x1, double z0, double z1, double dx)
{
    return (floor((x1 - x0) / dx) + 3.0) * (floor((z1 - z0) / dx) + 3.0);
}

/* Particles of body k of a 2D case. */
static double body_particles(const struct case_def *c, size_t k)
{
    const struct body *bd = &c->bodies[k];
    return geom_polygon_area_in_band(&bd->polygon, bd->z_min, bd->z_max) / (c->dx * c->dx);
}

/* The box [lo, hi] a 3D body lies in (an STL body: its mesh's bounds, from the file; an unreadable
 * file gives an empty box, and the fill then says why) and its volume [m3]. */
static double body_box3(const struct case_def *c, size_t k, double lo[3], double hi[3])
{
    const struct body *bd = &c->bodies[k];
    double volume = NAN;
    switch (bd->shape) {
    case BODY_POLYGON:
        lo[1] = bd->y_min, hi[1] = bd->y_max;
        lo[0] = lo[2] = INFINITY, hi[0] = hi[2] = -INFINITY;
        geom_grow_box(&bd->polygon, &lo[0], &hi[0], &lo[2], &hi[2]);
        volume = geom_polygon_area_in_band(&bd->polygon, bd->z_min, bd->z_max) * (bd->y_max - bd->y_min);
        break;
    case BODY_BOX:
        memcpy(lo, bd->box_min, 3 * sizeof *lo);
        memcpy(hi, bd->box_max, 3 * sizeof *hi);
        break;
    case BODY_STL: {
        struct mesh m;
        memset(&m, 0, sizeof m);
        char msg[256];
        if (stl_read(bd->stl, &m, NULL, msg, sizeof msg) == MIXSPH_OK && m.n_triangles > 0) {
            mesh_bounds(&m, lo, hi);
            volume = fabs(mesh_volume(&m));
        } else {
            lo[0] = lo[1] = lo[2] = hi[0] = hi[1] = hi[2] = 0.0;
        }
        mesh_free(&m);
        break;
    }
    default: /* BODY_BELOW_LEVEL: the domain below the level */
        lo[0] = c->domain[0], hi[0] = c->domain[1];
        lo[1] = c->domain_y[0], hi[1] = c->domain_y[1];
        lo[2] = c->domain[2 * DIM_UP], hi[2] = c->domain[2 * DIM_UP + 1];
        break;
    }
    lo[2] = fmax(lo[2], bd->z_min);
    hi[2] = fmin(hi[2], bd->z_max);
    if (isnan(volume)) volume = fmax(0.0, hi[0] - lo[0]) * fmax(0.0, hi[1] - lo[1]) * fmax(0.0, hi[2] - lo[2]);
    return volume;
}

/* Wall particles of wall k: a strip of wall_layers rows behind its length (2D), a sheet of
 * wall_layers layers behind its surface (3D). */
static double wall_particles(const struct case_def *c, size_t k)
{
    if (c->dimensions == 3) return mesh_area(&c->walls[k].surface.mesh) * c->wall_layers / (c->dx * c->dx);
    return geom_polyline_length(&c->walls[k].line) * c->wall_layers / c->dx;
}

/* Lattice sites scanned for wall k: its bounding box grown by the depth of its layers (walls.c). */
static double wall_sites(const struct case_def *c, size_t k)
{
    const double depth = c->wall_layers * c->dx;
    if (c->dimensions == 3) {
        double lo[3], hi[3], sites = 1.0;
        mesh_bounds(&c->walls[k].surface.mesh, lo, hi);
        for (int d = 0; d < 3; d++) sites *= fmax(0.0, floor((hi[d] - lo[d] + 2.0 * depth) / c->dx)) + 3.0;
        return sites;
    }
    double x0 = INFINITY, x1 = -INFINITY, z0 = INFINITY, z1 = -INFINITY;
    geom_grow_box(&c->walls[k].line, &x0, &x1, &z0, &z1);
    return box_sites(x0 - depth, x1 + depth, z0 - depth, z1 + depth, c->dx);
}

/* The largest time step criterion (4) allows with every particle at rest at its medium's
 * reference density, a fixed grain counted with the largest viscosity it can have once mobile
 * (as integrate_time_step counts it). */
static double largest_time_step(const struct case_def *c)
{
    const double h = c->h_over_dx * c->dx;
    double c_max, dt = INFINITY;
    c_max = law_max_wave_speed(c->media, c->n_media);
    for (size_t k = 0; k < c->n_media; k++) {
        const struct medium *m = &c->media[k];
        double mu = law_get(m->law)->viscosity_bound(m);
        if (c->viscosity_implicit) mu = 0.0;
        dt = fmin(dt, time_step_bound(c->cfl, c->cfl_visc, h, c_max, 0.0, m->rho0, mu));
    }
    return dt;
}

void budget_estimate(const struct case_def *c, struct budget *b)
{
    memset(b, 0, sizeof *b);
    double x0 = INFINITY, x1 = -INFINITY, z0 = INFINITY, z1 = -INFINITY;
    if (c->dimensions == 3) {
        /* a 3D body: its volume over dx^3; the fill scans each body's box (placement.h) */
        for (size_t k = 0; k < c->n_bodies; k++) {
            double lo[3], hi[3];
            b->particles += body_box3(c, k, lo, hi) / (c->dx * c->dx * c->dx);
            double sites = 1.0;
            for (int d = 0; d < 3; d++) sites *= fmax(0.0, floor((hi[d] - lo[d]) / c->dx)) + 3.0;
            b->lattice_sites += sites;
        }
    } else {
        for (size_t k = 0; k < c->n_bodies; k++) {
            b->particles += body_particles(c, k);
            geom_grow_box(&c->bodies[k].polygon, &x0, &x1, &z0, &z1);
        }
        if (c->n_bodies > 0) b->lattice_sites = box_sites(x0, x1, z0, z1, c->dx);
    }
    for (size_t k = 0; k < c->n_walls; k++) {
        b->wall_particles += wall_particles(c, k);
        b->lattice_sites += wall_sites(c, k);
    }
    b->steps = c->t_end / largest_time_step(c);
    b->monitor_rows = floor(c->t_end / c->monitor_interval) + 1.0;
    if (c->snapshot_interval > 0.0)
        b->snapshot_bytes = (floor(c->t_end / c->snapshot_interval) + 1.0) * (b->particles + b->wall_particles) *
                            (BUDGET_SNAPSHOT_BYTES_PER_PARTICLE + (c->dimensions - 2) * BUDGET_SNAPSHOT_BYTES_3D);
}

/* "over the limit of 1e7 (numerics.max_particles)" */
#define OVER "over the limit of %s (%s)"

/* Is the estimate within the limit? (A non-finite estimate is not.) */
static int within(double estimate, double limit) { return estimate <= limit; }

static void num(double v, char *buf, size_t len) { case_schema_number_text(v, buf, len); }

mixsph_status budget_check(const struct case_def *c, char *err, size_t err_len)
{
    struct budget b;
    budget_estimate(c, &b);
    char est[32], lim[32], val[32];
    num(c->dx, val, sizeof val);
    num(c->max_particles, lim, sizeof lim);
    if (!within(b.particles, c->max_particles)) {
        num(b.particles, est, sizeof est);
        return status_set(err, err_len, MIXSPH_ERR_CASE, "%s: numerics.dx: %s m gives about %s particles, " OVER,
                          c->origin, val, est, lim, "numerics.max_particles");
    }
    if (!within(b.particles + b.wall_particles, c->max_particles)) {
        size_t w = 0; /* name the wall that asks for the most */
        for (size_t k = 1; k < c->n_walls; k++)
            if (wall_particles(c, k) > wall_particles(c, w)) w = k;
        char wl[32], len[32];
        num(b.particles + b.wall_particles, est, sizeof est);
        num(wall_particles(c, w), wl, sizeof wl);
        if (c->dimensions == 3) {
            num(mesh_area(&c->walls[w].surface.mesh), len, sizeof len);
            return status_set(err, err_len, MIXSPH_ERR_CASE,
                              "%s: walls.%s: %s m2 of surface with %d layers at dx = %s m gives about %s wall "
                              "particles, about %s particles in all, " OVER,
                              c->origin, c->walls[w].name, len, c->wall_layers, val, wl, est, lim, "numerics.max_particles");
        }
        num(geom_polyline_length(&c->walls[w].line), len, sizeof len);
        return status_set(err, err_len, MIXSPH_ERR_CASE,
                          "%s: walls.%s.polyline: %s m long with %d layers at dx = %s m gives about %s wall "
                          "particles, about %s particles in all, " OVER,
                          c->origin, c->walls[w].name, len, c->wall_layers, val, wl, est, lim, "numerics.max_particles");
    }
    if (!within(b.lattice_sites, c->max_lattice_sites)) {
        num(b.lattice_sites, est, sizeof est);
        num(c->max_lattice_sites, lim, sizeof lim);
        return status_set(err, err_len, MIXSPH_ERR_CASE,
                          "%s: numerics.dx: %s m gives about %s lattice sites to scan in the bounding boxes of the "
                          "bodies and walls, " OVER,
                          c->origin, val, est, lim, "numerics.max_lattice_sites");
    }
    for (size_t k = 0; k < c->n_monitors; k++) {
        const struct monitor_def *md = &c->monitors[k];
        if (md->kind != MONITOR_PROFILE && md->kind != MONITOR_RUNOUT) continue;
        const double bins = case_profile_bin_count(md);
        if (within(bins, c->max_profile_bins)) continue;
        num(md->bin, val, sizeof val);
        num(bins, est, sizeof est);
        num(c->max_profile_bins, lim, sizeof lim);
        return status_set(err, err_len, MIXSPH_ERR_CASE,
                          "%s: monitors.%s.bin: %s m over the width %g m gives about %s bins, " OVER, c->origin,
                          md->name, val, md->x_max - md->x_min, est, lim, "output.max_profile_bins");
    }
    if (!within(b.monitor_rows, c->max_monitor_rows)) {
        num(c->monitor_interval, val, sizeof val);
        num(b.monitor_rows, est, sizeof est);
        num(c->max_monitor_rows, lim, sizeof lim);
        return status_set(err, err_len, MIXSPH_ERR_CASE,
                          "%s: output.monitor_interval: %s s to t_end = %g s gives about %s rows of monitors.csv, " OVER,
                          c->origin, val, c->t_end, est, lim, "output.max_monitor_rows");
    }
    if (!within(b.snapshot_bytes, c->max_snapshot_bytes)) {
        num(c->snapshot_interval, val, sizeof val);
        num(b.snapshot_bytes, est, sizeof est);
        num(c->max_snapshot_bytes, lim, sizeof lim);
        return status_set(err, err_len, MIXSPH_ERR_CASE,
                          "%s: output.snapshot_interval: %s s to t_end = %g s gives about %s bytes of particle "
                          "snapshots, " OVER,
                          c->origin, val, c->t_end, est, lim, "output.max_snapshot_bytes");
    }
    if (!within(b.steps, c->max_steps)) {
        num(c->t_end, val, sizeof val);
        num(b.steps, est, sizeof est);
        num(c->max_steps, lim, sizeof lim);
        return status_set(err, err_len, MIXSPH_ERR_CASE,
                          "%s: numerics.t_end: %s s gives about %s time steps (criterion (4) at dx = %g m), " OVER,
                          c->origin, val, est, c->dx, lim, "numerics.max_steps");
    }
    return MIXSPH_OK;
}
