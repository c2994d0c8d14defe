/* walls.c - walls from polylines (docs/model.md section 8).
 *
 * Treatment: layers of dummy wall particles behind each polyline, as deep as the kernel support,
 * on the global lattice (i + 1/2) dx or in rows aligned with each segment (numerics.wall_placement);
 * their pressure is extrapolated from the fluid (Adami, Hu & Adams 2012, J. Comput. Phys. 231, eq. 27):
 *     p_w = [ sum_f p_f W_wf + (g - a_w) . sum_f rho_f (x_w - x_f) W_wf ] / sum_f W_wf
 * clamped at 0 (no suction at walls), and their velocity in viscous terms is the no-slip mirror
 * 2 v_wall - v~ (v~ the kernel average of the fluid velocity); on a free-slip wall the mirror image
 * of the fluid across the wall, v~ - 2 ((v~ - v_wall) . n) n, in every pair term (viscous,
 * continuity, artificial viscosity), so that no pair term sees a tangential jump across it; their
 * density (used by the artificial viscosity only) is the kernel average of the fluid's.
 * Moving walls (the Vajont plate) translate with a prescribed piecewise-linear velocity law.
 * On top of the pressure barrier, a geometric guarantee: a particle whose step would cross a
 * wall segment (in the wall's frame) is put back on the fluid side at 0.1 dx and loses its
 * velocity component into the wall; such corrections are counted (the diagnostic wall_corrections). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "walls.h"

#include "geometry.h"
#include "mixsph.h"
#include "team.h"

/* a . b, summed in the order of the components (the 2D code's a[0] b[0] + a[1] b[1]) */
static inline double dot(const double a[DIM], const double b[DIM])
{
    double s = a[0] * b[0];
    for (int d = 1; d < DIM; d++) s += a[d] * b[d];
    return s;
}

/* A vector of the walls' x-z plane (walls.h) as a DIM vector. */
static inline void from_plane(double x, double z, double v[DIM])
{
    for (int d = 0; d < DIM; d++) v[d] = 0.0;
    v[0] = x;
    v[DIM_UP] = z;
}

/* How a free-slip wall particle's mirror image of the fluid, v~ - 2 ((v~ - v_w) . n) n, changes
 * when its wall's velocity changes by dv: by 2 (dv . n) n (n = P->wall_n). */
static void mirror_shift(const struct particles *P, size_t i, const double dv[DIM], double shift[DIM])
{
    double n[DIM];
    for (int d = 0; d < DIM; d++) n[d] = P->wall_n[d][i];
    const double dvn = dot(dv, n);
    for (int d = 0; d < DIM; d++) shift[d] = 2.0 * dvn * n[d];
}

#if DIM == 2
double walls_distance(const struct walls *W, size_t w, const double pos[DIM], int *at_end)
{
    const struct wall *wl = &W->def[w];
    const double *o = W->state[w].o;
    return geom_signed_distance(&wl->line, wl->side, pos[0] - o[0], pos[DIM_UP] - o[DIM_UP], at_end);
}

void walls_normal(const struct walls *W, size_t w, const double pos[DIM], double n[DIM])
{
    const struct wall *wl = &W->def[w];
    const double *o = W->state[w].o;
    double nx, nz;
    geom_side_normal(&wl->line, wl->side, pos[0] - o[0], pos[DIM_UP] - o[DIM_UP], &nx, &nz);
    from_plane(nx, nz, n);
}

int walls_near(const struct walls *W, size_t w, const double pos[DIM], double reach)
{
    int at_end;
    return !(fabs(walls_distance(W, w, pos, &at_end)) > reach); /* NaN counts as near */
}
#else
/* The signed distance of pos to wall w where it is now, and its nearest point in its own frame. */
static double surface_query(const struct walls *W, size_t w, const double pos[DIM], struct surface_point *at)
{
    const double *o = W->state[w].o;
    const double p[3] = {pos[0] - o[0], pos[1] - o[1], pos[2] - o[2]};
    return surface_signed_distance(&W->def[w].surface, p, at);
}

double walls_distance(const struct walls *W, size_t w, const double pos[DIM], int *at_end)
{
    struct surface_point at;
    const double d = surface_query(W, w, pos, &at);
    *at_end = at.at_boundary;
    return d;
}

void walls_normal(const struct walls *W, size_t w, const double pos[DIM], double n[DIM])
{
    struct surface_point at;
    surface_query(W, w, pos, &at);
    for (int d = 0; d < DIM; d++) n[d] = at.normal[d];
}

int walls_near(const struct walls *W, size_t w, const double pos[DIM], double reach)
{
    const double *o = W->state[w].o;
    const double p[3] = {pos[0] - o[0], pos[1] - o[1], pos[2] - o[2]};
    return surface_may_be_within(&W->def[w].surface, p, reach);
}
#endif

void walls_init(struct walls *W, const struct wall *def, size_t n, const struct motion *motions, int layers,
                int placement, double lattice_z0, double g, double rho_alone)
{
    *W = (struct walls){.n = n, .def = def, .motions = motions, .layers = layers, .placement = placement,
                        .lattice_z0 = lattice_z0, .g = g, .rho_alone = rho_alone};
    for (size_t w = 0; w < n; w++) {
        const int mo = def[w].motion;
        if (mo < 0) continue;
        motion_velocity(&motions[mo], 0.0, W->state[w].v);
        motion_acceleration(&motions[mo], 0.0, W->state[w].a);
    }
}

/* The next step sees the wall as if it had had its new velocity at the last wall pass: without
 * this a grain held fixed beside a wall that jumps to a new speed keeps its state (its strain rate
 * reads the old mirror) and then takes the new velocity difference with the viscosity mu_thr,
 * over a time step made for mu0 (an impulsive push of 1.5 m/s threw such grains at 20 m/s). */
void walls_change_velocity(struct walls *W, size_t w, const double v[DIM], const double a[DIM], struct particles *P)
{
    struct wall_state *ws = &W->state[w];
    const int noslip = W->def[w].slip == WALL_NO_SLIP;
    double dv[DIM];
    for (int d = 0; d < DIM; d++) {
        dv[d] = v[d] - ws->v[d];
        ws->v[d] = v[d];
        ws->a[d] = a[d];
    }
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] != MIXSPH_STATE_WALL || particles_wall_index(P, i) != w) continue;
        if (noslip) {
            for (int d = 0; d < DIM; d++) {
                P->vel[d][i] = v[d];
                P->uv[d][i] += 2.0 * dv[d]; /* d u_g / d v_w = 2 I */
            }
        } else {
            double shift[DIM];
            mirror_shift(P, i, dv, shift);
            for (int d = 0; d < DIM; d++) {
                P->vel[d][i] += shift[d];
                P->uv[d][i] += shift[d];
            }
        }
    }
}

#if DIM == 2 /* the placement along polylines (walls.h) */

/* Whether (x, z) lies behind a fixed wall before w, within the layers' depth: among fixed walls a
 * site is filled once (a site behind two walls). */
static int behind_earlier_fixed_wall(const struct walls *W, size_t w, double x, double z, double depth)
{
    if (W->def[w].motion >= 0) return 0;
    for (size_t v = 0; v < w; v++) {
        if (W->def[v].motion >= 0) continue;
        int at_end = 0;
        const double d = geom_signed_distance(&W->def[v].line, W->def[v].side, x, z, &at_end);
        if (!at_end && d < 0.0 && d >= -depth) return 1;
    }
    return 0;
}

/* Append one wall particle of wall w at (x, z) with volume vol: its index, or -1 out of memory. */
static long push_wall_particle(const struct wall_state *ws, size_t w, double x, double z, double vol,
                               struct particles *P)
{
    const double pos[DIM] = {x, z};
    const size_t j = particles_push(P, pos, 1000.0, 0.0, (uint8_t)w, MIXSPH_STATE_WALL);
    if (j == (size_t)-1) return -1;
    P->vol[j] = vol;
    P->m[j] = 0.0;
    for (int d = 0; d < DIM; d++) P->vel[d][j] = P->uv[d][j] = ws[w].v[d];
    return (long)j;
}

/* Segment k of a polyline: its start (ax, az), unit tangent (tx, tz), fluid-side unit normal
 * (nx, nz) and length. */
struct segment {
    double ax, az, tx, tz, nx, nz, len;
    int side; /* the wall's fluid side, +1 left of the direction of travel, -1 right */
};

static struct segment segment_of(const struct wall *wl, size_t k)
{
    struct segment g;
    g.ax = wl->line.x[k];
    g.az = wl->line.z[k];
    const double ex = wl->line.x[k + 1] - g.ax, ez = wl->line.z[k + 1] - g.az;
    g.len = hypot(ex, ez);
    g.tx = ex / g.len;
    g.tz = ez / g.len;
    g.nx = -g.tz * wl->side;
    g.nz = g.tx * wl->side;
    g.side = wl->side;
    return g;
}

/* Does the wall turn toward its fluid side from segment a to the next, b? Then the solid's angle
 * at their vertex exceeds 180 degrees (the bottom of a valley) and the rows behind the two
 * segments leave a fan-shaped gap there; otherwise (an edge) they overlap. */
static int turns_toward_fluid(const struct segment *a, const struct segment *b)
{
    return (a->tx * b->tz - a->tz * b->tx) * a->side > 0.0;
}

/* At an edge shared with segment o, a row particle (x, z) at `depth` behind its own segment is
 * left to o's rows when it also lies behind o, within o's span, at a smaller depth: the overlap
 * of the two strips is split along the bisector. */
static int owned_by_other(const struct segment *o, double x, double z, double depth)
{
    const double rx = x - o->ax, rz = z - o->az;
    const double behind = -(rx * o->nx + rz * o->nz), along = rx * o->tx + rz * o->tz;
    return behind > 0.0 && behind < depth && along >= 0.0 && along <= o->len;
}

/* Whether a wall particle of wall w from index `first` on lies within dist of (x, z): at an edge the
 * bisector split can leave two particles of the two strips nearly on top of each other. */
static int near_placed(const struct particles *P, size_t first, double x, double z, double dist)
{
    const double *px = P->pos[0], *pz = P->pos[DIM_UP];
    for (size_t j = first; j < P->n; j++)
        if ((px[j] - x) * (px[j] - x) + (pz[j] - z) * (pz[j] - z) < dist * dist) return 1;
    return 0;
}

/* Aligned placement: on every segment, wall_layers rows at (l + 1/2) dx behind it, with
 * N = max(1, round(L / dx)) particles each at (m + 1/2) L / N along it (volume L / N x dx); at
 * an edge the strips' overlap is split along the bisector (and of two particles closer than
 * dx / 2 there, the second is dropped); at the bottom of a valley the gap is
 * filled by a fan: rings at radius (l + 1/2) dx with round(theta r / dx) particles each. So the
 * first row is dx/2 behind the wall line everywhere, as on a wall along the lattice, and a wall
 * at an angle to the lattice is not a staircase. */
static long walls_generate_aligned(const struct walls *W, double dx, const mixsph_interrupt *interrupt,
                                   struct particles *P)
{
    const struct wall_state *ws = W->state;
    const double depth = W->layers * dx;
    long added = 0;
    for (size_t w = 0; w < W->n; w++) {
        const struct wall *wl = &W->def[w];
        const size_t nseg = wl->line.n - 1, first = P->n;
        for (size_t k = 0; k < nseg; k++) {
            if (interrupt && interrupt->requested && interrupt->requested(interrupt->user)) return WALLS_INTERRUPTED;
            const struct segment g = segment_of(wl, k);
            const struct segment prev = k > 0 ? segment_of(wl, k - 1) : g;
            const int has_next = k + 1 < nseg;
            const struct segment next = has_next ? segment_of(wl, k + 1) : g;
            const int edge_before = k > 0 && !turns_toward_fluid(&prev, &g);
            const int edge_after = has_next && !turns_toward_fluid(&g, &next);
            const long n_along = lround(g.len / dx) > 1 ? lround(g.len / dx) : 1;
            const double ds = g.len / (double)n_along;
            for (int l = 0; l < W->layers; l++) {
                const double d = (l + 0.5) * dx;
                for (long m = 0; m < n_along; m++) {
                    const double s = (m + 0.5) * ds;
                    const double x = g.ax + s * g.tx - d * g.nx, z = g.az + s * g.tz - d * g.nz;
                    if (edge_before && owned_by_other(&prev, x, z, d)) continue;
                    if (edge_after && owned_by_other(&next, x, z, d)) continue;
                    const int at_edge = (edge_before && s < depth + dx) || (edge_after && s > g.len - depth - dx);
                    if (at_edge && near_placed(P, first, x, z, 0.5 * dx)) continue;
                    if (behind_earlier_fixed_wall(W, w, x, z, depth)) continue;
                    if (push_wall_particle(ws, w, x, z, ds * dx, P) < 0) return -1;
                    added++;
                }
            }
            if (!has_next || edge_after) continue;
            /* the fan at the valley's vertex, from -n of this segment to -n of the next */
            const double vx = next.ax, vz = next.az;
            const double c = g.nx * next.nx + g.nz * next.nz;
            const double theta = acos(c < -1.0 ? -1.0 : c > 1.0 ? 1.0 : c);
            double ux = -next.nx - c * -g.nx, uz = -next.nz - c * -g.nz; /* -n_next minus its part along -n */
            const double un = hypot(ux, uz);
            if (!(un > 0.0)) continue;
            ux /= un;
            uz /= un;
            for (int l = 0; l < W->layers; l++) {
                const double r = (l + 0.5) * dx;
                const long n_arc = lround(theta * r / dx);
                for (long j = 0; j < n_arc; j++) {
                    const double phi = (j + 0.5) * theta / (double)n_arc;
                    const double x = vx + r * (cos(phi) * -g.nx + sin(phi) * ux);
                    const double z = vz + r * (cos(phi) * -g.nz + sin(phi) * uz);
                    if (behind_earlier_fixed_wall(W, w, x, z, depth)) continue;
                    if (push_wall_particle(ws, w, x, z, theta * r / (double)n_arc * dx, P) < 0) return -1;
                    added++;
                }
            }
        }
    }
    return added;
}

static long walls_generate_lattice(const struct walls *W, double dx, const mixsph_interrupt *interrupt,
                                   struct particles *P)
{
    const struct wall_state *ws = W->state;
    const double depth = W->layers * dx, z_off = geom_lattice_z_offset(W->lattice_z0, dx);
    long added = 0;
    for (size_t w = 0; w < W->n; w++) {
        const struct wall *wl = &W->def[w];
        double xmin = INFINITY, xmax = -INFINITY, zmin = INFINITY, zmax = -INFINITY;
        for (size_t k = 0; k < wl->line.n; k++) {
            xmin = fmin(xmin, wl->line.x[k]);
            xmax = fmax(xmax, wl->line.x[k]);
            zmin = fmin(zmin, wl->line.z[k]);
            zmax = fmax(zmax, wl->line.z[k]);
        }
        const long i0 = (long)floor((xmin - depth) / dx) - 1, i1 = (long)ceil((xmax + depth) / dx) + 1;
        const long k0 = (long)floor((zmin - depth - z_off) / dx) - 1, k1 = (long)ceil((zmax + depth - z_off) / dx) + 1;
        for (long k = k0; k <= k1; k++) {
            if (interrupt && interrupt->requested && interrupt->requested(interrupt->user)) return WALLS_INTERRUPTED;
            for (long i = i0; i <= i1; i++) {
                const double x = (i + 0.5) * dx, z = z_off + (k + 0.5) * dx;
                int at_end = 0;
                const double d = geom_signed_distance(&wl->line, wl->side, x, z, &at_end);
                if (at_end || d >= 0.0 || d < -depth) continue;
                if (behind_earlier_fixed_wall(W, w, x, z, depth)) continue;
                if (push_wall_particle(ws, w, x, z, dim_cell_volume(dx), P) < 0) return -1;
                added++;
            }
        }
    }
    return added;
}
#else /* DIM == 3: the lattice sites behind each wall's surface */

/* Whether the lattice site pos, at signed distance d from a wall's surface whose nearest point is
 * `at`, is one of that wall's particles: behind the surface within the layers' depth, or in
 * front of it where the wall blocks the bodies' sites (walls_site_blocked). Without the second
 * part a surface lying up to dx/2 in front of a lattice plane left an empty layer between the
 * wall's particles and the water's (a whole one where the surface is a lattice plane): the
 * water moved into it, onto the surface, where the crossing guard put particles back every step
 * and lined them up along the edges, and they merged there (docs/validation/spheric_test2.md). */
static int wall_site(double d, const struct surface_point *at, double depth, double dx)
{
    return d >= -depth && (d < 0.0 || walls_site_blocked(d, at->at_boundary, dx));
}

/* Whether pos is a site of a fixed wall before w: among fixed walls a site is filled once. At
 * t = 0 a wall's frame is the case's. */
static int behind_earlier_fixed_wall(const struct walls *W, size_t w, const double pos[3], double depth, double dx)
{
    if (W->def[w].motion >= 0) return 0;
    for (size_t v = 0; v < w; v++) {
        if (W->def[v].motion >= 0) continue;
        struct surface_point at;
        const double d = surface_signed_distance(&W->def[v].surface, pos, &at);
        if (wall_site(d, &at, depth, dx)) return 1;
    }
    return 0;
}

/* The buckets of surface s's grid grown by m buckets on every side (N[d] = n[d] + 2 m of them)
 * that lie within m buckets of one holding a triangle: the only ones whose lattice sites can be
 * within m bucket sides of the surface. A box dilation, axis by axis. NULL when out of memory. */
static unsigned char *buckets_near_surface(const struct surface *s, size_t m, size_t N[3])
{
    for (int d = 0; d < 3; d++) N[d] = s->n[d] + 2 * m;
    const size_t total = N[0] * N[1] * N[2], stride[3] = {1, N[0], N[0] * N[1]};
    unsigned char *mask = calloc(total, 1), *grown = calloc(total, 1);
    if (!mask || !grown) {
        free(mask);
        free(grown);
        return NULL;
    }
    for (size_t k = 0; k < s->n[2]; k++)
        for (size_t j = 0; j < s->n[1]; j++)
            for (size_t i = 0; i < s->n[0]; i++) {
                const size_t c = (k * s->n[1] + j) * s->n[0] + i;
                if (s->cell_start[c + 1] > s->cell_start[c]) mask[(k + m) * stride[2] + (j + m) * stride[1] + i + m] = 1;
            }
    for (int a = 0; a < 3; a++) {
        memset(grown, 0, total);
        for (size_t c = 0; c < total; c++) {
            if (!mask[c]) continue;
            const size_t at = c / stride[a] % N[a];
            const size_t lo = at >= m ? at - m : 0, hi = at + m < N[a] ? at + m : N[a] - 1;
            for (size_t q = lo; q <= hi; q++) grown[c + (q - at) * stride[a]] = 1; /* unsigned wrap: exact */
        }
        unsigned char *t = mask;
        mask = grown;
        grown = t;
    }
    free(grown);
    return mask;
}

/* The lattice indices whose sites (l + 1/2) dx + off lie in [b0, b1): first .. end - 1. */
static void sites_in(double b0, double b1, double off, double dx, long *first, long *end)
{
    *first = (long)ceil((b0 - off) / dx - 0.5);
    *end = (long)ceil((b1 - off) / dx - 0.5);
}

/* Every lattice site (i + 1/2) dx, (j + 1/2) dx, z_off + (k + 1/2) dx within the layers' depth
 * behind a wall's surface (-depth <= d < 0, d the signed distance) or blocked for the bodies in
 * front of it (wall_site), bucket by bucket of its
 * grid near the surface. Beyond an open edge the rule keeps the sites behind the edge's face
 * within depth of the edge (a quarter cylinder), so two surfaces meeting at an edge (a flume's
 * bed and its side walls) leave no gap between their layers. */
static long walls_generate_lattice(const struct walls *W, double dx, const mixsph_interrupt *interrupt,
                                   struct particles *P)
{
    const double depth = W->layers * dx, z_off = geom_lattice_z_offset(W->lattice_z0, dx);
    const double off[3] = {0.0, 0.0, z_off};
    long added = 0;
    for (size_t w = 0; w < W->n; w++) {
        const struct surface *s = &W->def[w].surface;
        const size_t m = (size_t)ceil(depth / s->cell);
        size_t N[3];
        unsigned char *near = buckets_near_surface(s, m, N);
        if (!near) return -1;
        for (size_t K = 0; K < N[2]; K++)
            for (size_t J = 0; J < N[1]; J++) {
                if (interrupt && interrupt->requested && interrupt->requested(interrupt->user)) {
                    free(near);
                    return WALLS_INTERRUPTED;
                }
                for (size_t I = 0; I < N[0]; I++) {
                    if (!near[(K * N[1] + J) * N[0] + I]) continue;
                    const size_t at[3] = {I, J, K};
                    long first[3], end[3];
                    for (int d = 0; d < 3; d++) {
                        const double b0 = s->lo[d] + ((double)at[d] - (double)m) * s->cell;
                        const double b1 = s->lo[d] + ((double)at[d] + 1.0 - (double)m) * s->cell;
                        sites_in(b0, b1, off[d], dx, &first[d], &end[d]);
                    }
                    for (long k = first[2]; k < end[2]; k++)
                        for (long j = first[1]; j < end[1]; j++)
                            for (long i = first[0]; i < end[0]; i++) {
                                const double pos[3] = {(i + 0.5) * dx, (j + 0.5) * dx, z_off + (k + 0.5) * dx};
                                struct surface_point at;
                                const double d = surface_signed_distance(s, pos, &at);
                                if (!wall_site(d, &at, depth, dx) || behind_earlier_fixed_wall(W, w, pos, depth, dx)) continue;
                                const size_t p = particles_push(P, pos, 1000.0, 0.0, (uint8_t)w, MIXSPH_STATE_WALL);
                                if (p == (size_t)-1) {
                                    free(near);
                                    return -1;
                                }
                                P->vol[p] = dim_cell_volume(dx);
                                P->m[p] = 0.0;
                                for (int c = 0; c < DIM; c++) P->vel[c][p] = P->uv[c][p] = W->state[w].v[c];
                                added++;
                            }
                }
            }
        free(near);
    }
    return added;
}
#endif

long walls_generate(const struct walls *W, double dx, const mixsph_interrupt *interrupt, struct particles *P)
{
#if DIM == 2
    if (W->placement == WALL_PLACEMENT_ALIGNED) return walls_generate_aligned(W, dx, interrupt, P);
#else
    if (W->placement == WALL_PLACEMENT_ALIGNED) return WALLS_NOT_IN_3D;
#endif
    return walls_generate_lattice(W, dx, interrupt, P);
}

/* The velocity of a moving wall at the end of the step from t_from by dt: its motion law's, or
 * an external velocity (co-simulation input), which is constant over the step. */
static void step_end_velocity(const struct motion *m, const struct wall_state *ws, double t_from, double dt,
                              double v[DIM])
{
    if (ws->ext) {
        for (int d = 0; d < DIM; d++) v[d] = ws->ext_v[d];
    } else {
        motion_velocity(m, t_from + dt, v);
    }
}

/* Move the walls from t_from by dt: each moving wall translates by its velocity at mid-step
 * (exact for a law linear over the step), then takes the velocity and acceleration at t+dt. Its
 * work on the particles grows by the force it exerts on them times its displacement: minus the
 * force on it, the sum over its particles of what the last momentum pass left in their
 * accelerations (forces_momentum: a wall particle keeps the force). */
void walls_move(struct walls *W, struct particles *P, double t_from, double dt)
{
    struct wall_state *wstate = W->state;
    int moving = 0;
    double shift[WALLS_MAX][DIM] = {{0}}, force[WALLS_MAX][DIM] = {{0}}, dv[WALLS_MAX][DIM] = {{0}};
    for (size_t w = 0; w < W->n; w++) {
        const int mo = W->def[w].motion;
        if (mo < 0) continue;
        const struct motion *m = &W->motions[mo];
        struct wall_state *ws = &wstate[w];
        double v[DIM]; /* the velocity over the step */
        for (int d = 0; d < DIM; d++) dv[w][d] = -ws->v[d];
        step_end_velocity(m, ws, t_from, dt, ws->v);
        for (int d = 0; d < DIM; d++) dv[w][d] += ws->v[d];
        if (ws->ext) {
            for (int d = 0; d < DIM; d++) {
                v[d] = ws->v[d];
                ws->a[d] = 0.0;
            }
        } else {
            motion_velocity(m, t_from + 0.5 * dt, v);
            motion_acceleration(m, t_from + dt, ws->a);
        }
        for (int d = 0; d < DIM; d++) {
            shift[w][d] = v[d] * dt;
            ws->o[d] += shift[w][d];
        }
        moving = 1;
    }
    if (!moving) return;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] != MIXSPH_STATE_WALL || particles_is_image(P, i)) continue; /* an image follows its source */
        const size_t w = particles_wall_index(P, i);
        if (W->def[w].motion < 0) continue;
        for (int d = 0; d < DIM; d++) {
            force[w][d] += P->acc[d][i];
            P->pos[d][i] += shift[w][d];
        }
        if (W->def[w].slip == WALL_NO_SLIP) {
            for (int d = 0; d < DIM; d++) P->vel[d][i] = wstate[w].v[d];
        } else { /* the mirror of the last wall pass, about the wall's new velocity */
            double vs[DIM];
            mirror_shift(P, i, dv[w], vs);
            for (int d = 0; d < DIM; d++) P->vel[d][i] += vs[d];
        }
    }
    for (size_t w = 0; w < W->n; w++) wstate[w].work -= dot(force[w], shift[w]);
}

#if DIM == 2
void walls_keep_fluid_side(const struct walls *W, const double (*o_old)[DIM], double gap, const double p0[DIM],
                           double p1[DIM], double v[DIM], long *clips)
{
    for (int pass = 0; pass < 4; pass++) {
        int hit = 0;
        for (size_t w = 0; w < W->n && !hit; w++) {
            const struct wall *wl = &W->def[w];
            const struct wall_state *ws = &W->state[w];
            /* the path a -> b in the frame of the wall, and its step */
            double a[DIM], b[DIM], step[DIM];
            for (int d = 0; d < DIM; d++) {
                a[d] = p0[d] - o_old[w][d];
                b[d] = p1[d] - ws->o[d];
                step[d] = b[d] - a[d];
            }
            for (size_t k = 0; k + 1 < wl->line.n; k++) {
                const double cx = wl->line.x[k], cz = wl->line.z[k];
                const double ex = wl->line.x[k + 1] - cx, ez = wl->line.z[k + 1] - cz;
                double sc;
                if (!geom_path_crosses(a[0], a[DIM_UP], b[0], b[DIM_UP], cx, cz, cx + ex, cz + ez, &sc)) continue;
                /* fluid-side unit normal of this segment */
                const double len = hypot(ex, ez);
                double n[DIM];
                from_plane(-ez / len * wl->side, ex / len * wl->side, n);
                /* only a crossing from the fluid side into the wall counts */
                if (dot(step, n) >= 0.0) continue;
                double dv[DIM];
                for (int d = 0; d < DIM; d++) {
                    p1[d] = a[d] + sc * step[d] + gap * n[d] + ws->o[d];
                    dv[d] = v[d] - ws->v[d];
                }
                const double vn = dot(dv, n);
                if (vn < 0.0)
                    for (int d = 0; d < DIM; d++) v[d] -= vn * n[d];
                (*clips)++;
                hit = 1;
                break;
            }
        }
        if (!hit) return;
    }
}
#else
/* In 3D the first crossing of the step's path from the front of a wall's surface to its back
 * (surface_first_crossing, over the few triangles of the buckets the path passes). */
void walls_keep_fluid_side(const struct walls *W, const double (*o_old)[DIM], double gap, const double p0[DIM],
                           double p1[DIM], double v[DIM], long *clips)
{
    for (int pass = 0; pass < 4; pass++) {
        int hit = 0;
        for (size_t w = 0; w < W->n && !hit; w++) {
            const struct wall_state *ws = &W->state[w];
            double a[3], b[3], step[3], n[3], t;
            for (int d = 0; d < DIM; d++) {
                a[d] = p0[d] - o_old[w][d];
                b[d] = p1[d] - ws->o[d];
                step[d] = b[d] - a[d];
            }
            if (!surface_first_crossing(&W->def[w].surface, a, b, &t, n)) continue;
            double dv[DIM];
            for (int d = 0; d < DIM; d++) {
                p1[d] = a[d] + t * step[d] + gap * n[d] + ws->o[d];
                dv[d] = v[d] - ws->v[d];
            }
            const double vn = dot(dv, n);
            if (vn < 0.0)
                for (int d = 0; d < DIM; d++) v[d] -= vn * n[d];
            (*clips)++;
            hit = 1;
        }
        if (!hit) return;
    }
}
#endif

/* The kernel weight of a non-wall neighbour j from wall particle i in the extrapolation onto i;
 * r = x_i - x_j. */
static inline double extrapolation_weight(const struct kernel *K, int wendland, const double r[DIM])
{
    const double q = kernel_q(K, dot(r, r));
    return wendland ? kernel_w_q(K, q, 1) : kernel_w_q(K, q, 0);
}

/* r = x_i - x_j of particles i and j. */
static inline void separation(const struct particles *P, size_t i, size_t j, double r[DIM])
{
    for (int d = 0; d < DIM; d++) r[d] = P->pos[d][i] - P->pos[d][j];
}

/* A free-slip wall particle's velocity: the mirror image across the wall (unit normal n, 0 for
 * none) of the fluid's velocity v, about the wall's velocity: the tangential part kept, the normal
 * part relative to the wall reversed. With the wall's own velocity instead, the continuity
 * equation and the artificial viscosity saw a jump of the tangential velocity across the wall,
 * and the artificial viscosity of the wall pairs was a tangential drag (docs/model.md section 8);
 * with v itself the normal part had no jump, so a solid pressing on the wall was not strained
 * by it (its velocity gradient) as by its mirror image. */
static inline void mirror_image(const double n[DIM], const double v_wall[DIM], double v[DIM])
{
    double dv[DIM];
    for (int d = 0; d < DIM; d++) dv[d] = v[d] - v_wall[d];
    const double vn = dot(dv, n);
    for (int d = 0; d < DIM; d++) v[d] -= 2.0 * vn * n[d];
}

void walls_set_normals(const struct walls *W, struct particles *P)
{
    for (size_t i = 0; i < P->n; i++) {
        double n[DIM] = {0.0};
        if (P->state[i] == MIXSPH_STATE_WALL && W->def[particles_wall_index(P, i)].slip == WALL_FREE_SLIP) {
            double pos[DIM];
            for (int d = 0; d < DIM; d++) pos[d] = P->pos[d][i];
            walls_normal(W, particles_wall_index(P, i), pos, n);
        }
        for (int d = 0; d < DIM; d++) P->wall_n[d][i] = n[d];
    }
}

/* The arguments of a parallel loop of this file (core/team.h). */
/* The parallel loops of this file (core/team.h), each with its own arguments. */
struct extrapolate_loop { /* the fluid's state onto the wall particles */
    const struct walls *W;
    const struct kernel *K;
    const struct gather *G;
    double dx;            /* the particle spacing [m] */
    struct particles *P;
};

struct mirror_weights_loop { /* the mirror's weights and signs */
    const struct walls *W;
    const struct kernel *K;
    const struct gather *G;
    const struct particles *P;
    struct wall_mirror *M;
};

struct mirror_at_loop { /* the mirror's constants from the walls' velocities */
    const struct walls *W;
    const struct particles *P;
    struct wall_mirror *M;
    const double (*v_wall)[DIM]; /* per wall [m/s] */
};

struct mirror_fill_loop { /* the mirror applied to a velocity field */
    const struct wall_mirror *M;
    const struct gather *G;
    double constant;      /* 1: the whole map c + s a u, 0: its linear part s a u */
    double *const *v;     /* the field's DIM components */
};
static void mirror_weights_range(void *arg, size_t b, size_t e);
static void mirror_apply_range(void *arg, size_t b, size_t e);

static void extrapolate_range(void *arg, size_t b, size_t e)
{
    const struct extrapolate_loop *L = arg;
    const struct walls *W = L->W;
    const struct wall_state *wstate = W->state;
    const struct kernel *K = L->K;
    const struct gather *G = L->G;
    struct particles *P = L->P;
    const double g = W->g, vol = dim_cell_volume(L->dx), rho_alone = W->rho_alone;
    const int wendland = K->type == KERNEL_WENDLAND_C2;
    for (size_t i = b; i < e; i++) {
        if (P->state[i] != MIXSPH_STATE_WALL) continue;
        const size_t w = particles_wall_index(P, i);
        const struct wall_state *ws = &wstate[w];
        /* g - a_w, with g = -g e_up */
        double ga[DIM];
        for (int d = 0; d < DIM; d++) ga[d] = -ws->a[d];
        ga[DIM_UP] = -g - ws->a[DIM_UP];
        double sw = 0.0, sp = 0.0, sv[DIM] = {0.0}, srho = 0.0;
        for (size_t k = G->start[i]; k < G->start[i + 1]; k++) { /* the non-wall neighbours */
            const size_t j = G->list[k];
            double r[DIM];
            separation(P, i, j, r);
            const double wgt = extrapolation_weight(K, wendland, r);
            sw += wgt;
            sp += (P->p[j] + P->rho[j] * dot(ga, r)) * wgt;
            for (int d = 0; d < DIM; d++) sv[d] += P->vel[d][j] * wgt;
            srho += P->rho[j] * wgt;
        }
        const int noslip = W->def[w].slip == WALL_NO_SLIP;
        double uv[DIM];
        if (sw > 0.0) {
            const double pw = sp / sw;
            P->p[i] = pw > 0.0 ? pw : 0.0;
            if (noslip) {
                for (int d = 0; d < DIM; d++) uv[d] = 2.0 * ws->v[d] - sv[d] / sw;
            } else {
                double n[DIM];
                for (int d = 0; d < DIM; d++) {
                    uv[d] = sv[d] / sw;
                    n[d] = P->wall_n[d][i];
                }
                mirror_image(n, ws->v, uv);
            }
            P->rho[i] = srho / sw;
        } else {
            P->p[i] = 0.0;
            P->rho[i] = rho_alone;
            for (int d = 0; d < DIM; d++) uv[d] = ws->v[d];
        }
        for (int d = 0; d < DIM; d++) P->uv[d][i] = uv[d];
        if (!noslip) /* the mirror image in every pair term (walls.h) */
            for (int d = 0; d < DIM; d++) P->vel[d][i] = uv[d];
        P->m[i] = P->rho[i] * vol; /* the mass seen by the artificial viscosity */
        P->inv_rho[i] = 1.0 / P->rho[i];
    }
}

void walls_extrapolate_fluid(const struct walls *W, const struct kernel *K, const struct gather *G, double dx,
                             struct particles *P, size_t n, int n_threads)
{
    struct extrapolate_loop L = {.W = W, .K = K, .G = G, .dx = dx, .P = P};
    team_for_dynamic(n_threads, n, extrapolate_range, &L); /* wall particles near the fluid cost most */
}

struct wall_mirror *walls_mirror_create(void) { return calloc(1, sizeof(struct wall_mirror)); }

void walls_mirror_free(struct wall_mirror *M)
{
    if (!M) return;
    free(M->weight);
    for (int d = 0; d < DIM; d++) free(M->c[d]);
    free(M->sign);
    free(M->rows);
    free(M);
}

static int mirror_reserve(struct wall_mirror *M, size_t n, size_t n_list)
{
    if (M->cap_list < n_list) {
        const size_t cap = n_list + n_list / 4 + 64;
        double *w = realloc(M->weight, cap * sizeof(double));
        if (!w) return -1;
        M->weight = w;
        M->cap_list = cap;
    }
    if (M->cap_n < n) {
        const size_t cap = n + n / 4 + 64;
        for (int d = 0; d < DIM; d++) {
            double *c = realloc(M->c[d], cap * sizeof(double));
            if (!c) return -1;
            M->c[d] = c;
        }
        signed char *sg = realloc(M->sign, cap);
        if (!sg) return -1;
        M->sign = sg;
        size_t *rows = realloc(M->rows, cap * sizeof(size_t));
        if (!rows) return -1;
        M->rows = rows;
        M->cap_n = cap;
    }
    return 0;
}

int walls_mirror_build(struct wall_mirror *M, const struct walls *W, const struct kernel *K,
                       const struct gather *G, const struct particles *P, size_t n, int n_threads)
{
    if (mirror_reserve(M, n, G->start[n]) != 0) return -1;
    M->n_rows = 0;
    for (size_t i = 0; i < n; i++)
        if (P->state[i] == MIXSPH_STATE_WALL) M->rows[M->n_rows++] = i;
    for (int d = 0; d < DIM; d++) M->normal[d] = P->wall_n[d];
    struct mirror_weights_loop L = {.W = W, .K = K, .G = G, .P = P, .M = M};
    team_for(n_threads, M->n_rows, mirror_weights_range, &L);
    return 0;
}

static void mirror_weights_range(void *arg, size_t b, size_t e)
{
    const struct mirror_weights_loop *L = arg;
    const struct walls *W = L->W;
    const struct kernel *K = L->K;
    const struct gather *G = L->G;
    const struct particles *P = L->P;
    struct wall_mirror *M = L->M;
    const int wendland = K->type == KERNEL_WENDLAND_C2;
    for (size_t r = b; r < e; r++) {
        const size_t i = M->rows[r];
        double sw = 0.0;
        for (size_t k = G->start[i]; k < G->start[i + 1]; k++) {
            double r[DIM];
            separation(P, i, G->list[k], r);
            M->weight[k] = extrapolation_weight(K, wendland, r);
            sw += M->weight[k];
        }
        const int noslip = W->def[particles_wall_index(P, i)].slip == WALL_NO_SLIP;
        if (sw > 0.0) {
            for (size_t k = G->start[i]; k < G->start[i + 1]; k++) M->weight[k] /= sw;
            M->sign[i] = noslip ? -1 : 1;
        } else { /* no fluid around it: the wall's velocity */
            M->sign[i] = 0;
        }
    }
}

static void mirror_at_range(void *arg, size_t b, size_t e)
{
    const struct mirror_at_loop *L = arg;
    const struct walls *W = L->W;
    const struct particles *P = L->P;
    struct wall_mirror *M = L->M;
    const double (*v)[DIM] = L->v_wall;
    for (size_t r = b; r < e; r++) {
        const size_t i = M->rows[r];
        const size_t w = particles_wall_index(P, i);
        if (!M->sign[i]) { /* no fluid around it: the wall's velocity */
            for (int d = 0; d < DIM; d++) M->c[d][i] = v[w][d];
        } else if (W->def[w].slip == WALL_NO_SLIP) {
            for (int d = 0; d < DIM; d++) M->c[d][i] = 2.0 * v[w][d];
        } else { /* the mirror image's part from the wall's velocity, 2 (v_w . n) n */
            double n[DIM];
            for (int d = 0; d < DIM; d++) n[d] = P->wall_n[d][i];
            const double vn = dot(v[w], n);
            for (int d = 0; d < DIM; d++) M->c[d][i] = 2.0 * vn * n[d];
        }
    }
}

void walls_mirror_at(struct wall_mirror *M, const struct walls *W, const struct particles *P, double t_from, double dt,
                     int n_threads)
{
    const struct wall_state *wstate = W->state;
    double v[WALLS_MAX][DIM];
    for (size_t w = 0; w < W->n; w++) {
        const int mo = W->def[w].motion;
        for (int d = 0; d < DIM; d++) v[w][d] = wstate[w].v[d];
        if (mo >= 0 && dt > 0.0) step_end_velocity(&W->motions[mo], &wstate[w], t_from, dt, v[w]);
    }
    struct mirror_at_loop L = {.W = W, .P = P, .M = M, .v_wall = (const double (*)[DIM])v};
    team_for(n_threads, M->n_rows, mirror_at_range, &L);
}

void walls_mirror_fill(const struct wall_mirror *M, const struct gather *G, int with_constant, double *const v[DIM],
                       int n_threads)
{
    struct mirror_fill_loop L = {.M = M, .G = G, .constant = with_constant ? 1.0 : 0.0, .v = v};
    team_for(n_threads, M->n_rows, mirror_apply_range, &L);
}

static void mirror_apply_range(void *arg, size_t b, size_t e)
{
    const struct mirror_fill_loop *L = arg;
    const struct wall_mirror *M = L->M;
    const struct gather *G = L->G;
    const double c = L->constant;
    double *const *v = L->v;
    for (size_t r = b; r < e; r++) {
        const size_t i = M->rows[r];
        double av[DIM] = {0.0}; /* a u */
        for (size_t k = G->start[i]; k < G->start[i + 1]; k++) {
            const size_t j = G->list[k];
            for (int d = 0; d < DIM; d++) av[d] += M->weight[k] * v[d][j];
        }
        if (M->sign[i] > 0) { /* free slip: R a u, the reflection across the wall */
            double n[DIM];
            for (int d = 0; d < DIM; d++) n[d] = M->normal[d][i];
            const double an = dot(av, n);
            for (int d = 0; d < DIM; d++) av[d] -= 2.0 * an * n[d];
        }
        for (int d = 0; d < DIM; d++) v[d][i] = c * M->c[d][i] + M->sign[i] * av[d];
    }
}

