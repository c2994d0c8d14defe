/* walls.c - walls from polylines (docs/model.md section 8).
 *
 * Treatment: layers of dummy wall particles behind each polyline, as deep as the kernel support,
 * on the global lattice (i + 1/2) dx or in rows aligned with each segment (numerics.wall_placement);
 * their pressure is extrapolated from the fluid (Adami, Hu & Adams 2012, J. Comput. Phys. 231, eq. 27):
 *     p_w = [ sum_f p_f W_wf + (g - a_w) . sum_f rho_f (x_w - x_f) W_wf ] / sum_f W_wf
 * clamped at 0 (no suction at walls), and their velocity in viscous terms is the no-slip mirror
 * 2 v_wall - v~ (v~ the kernel average of the fluid velocity) or v~ for free slip; their density
 * (used by the artificial viscosity only) is the kernel average of the fluid's.
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

void walls_signed_distance(const struct walls *W, size_t w, double x, double z, double *d, int *at_end)
{
    const struct wall *wl = &W->def[w];
    *d = geom_signed_distance(&wl->line, wl->side, x - W->state[w].ox, z - W->state[w].oz, at_end);
}

void walls_normal(const struct walls *W, size_t w, double x, double z, double *nx, double *nz)
{
    const struct wall *wl = &W->def[w];
    geom_side_normal(&wl->line, wl->side, x - W->state[w].ox, z - W->state[w].oz, nx, nz);
}

void walls_init(struct walls *W, const struct wall *def, size_t n, const struct motion *motions, int layers,
                int placement, double lattice_z0, double g, double rho_alone)
{
    *W = (struct walls){.n = n, .def = def, .motions = motions, .layers = layers, .placement = placement,
                        .lattice_z0 = lattice_z0, .g = g, .rho_alone = rho_alone};
    for (size_t w = 0; w < n; w++) {
        const int mo = def[w].motion;
        if (mo < 0) continue;
        motion_velocity(&motions[mo], 0.0, &W->state[w].vx, &W->state[w].vz);
        motion_acceleration(&motions[mo], 0.0, &W->state[w].ax, &W->state[w].az);
    }
}

/* The next step sees the wall as if it had had its new velocity at the last wall pass: without
 * this a grain held fixed beside a wall that jumps to a new speed keeps its state (its strain rate
 * reads the old mirror) and then takes the new velocity difference with the viscosity mu_thr,
 * over a time step made for mu0 (an impulsive push of 1.5 m/s threw such grains at 20 m/s). */
void walls_change_velocity(struct walls *W, size_t w, double vx, double vz, double ax, double az, struct particles *P)
{
    struct wall_state *ws = W->state;
    const double mirror = W->def[w].slip == WALL_NO_SLIP ? 2.0 : 0.0; /* d u_g / d v_w */
    const double dvx = vx - ws[w].vx, dvz = vz - ws[w].vz;
    ws[w].vx = vx;
    ws[w].vz = vz;
    ws[w].ax = ax;
    ws[w].az = az;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] != MIXSPH_STATE_WALL || particles_wall_index(P, i) != w) continue;
        P->vx[i] = vx;
        P->vz[i] = vz;
        P->uvx[i] += mirror * dvx;
        P->uvz[i] += mirror * dvz;
    }
}

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
    P->vx[j] = P->uvx[j] = ws[w].vx;
    P->vz[j] = P->uvz[j] = ws[w].vz;
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
    for (size_t j = first; j < P->n; j++)
        if ((P->x[j] - x) * (P->x[j] - x) + (P->z[j] - z) * (P->z[j] - z) < dist * dist) return 1;
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

long walls_generate(const struct walls *W, double dx, const mixsph_interrupt *interrupt, struct particles *P)
{
    if (W->placement == WALL_PLACEMENT_ALIGNED) return walls_generate_aligned(W, dx, interrupt, P);
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
                if (push_wall_particle(ws, w, x, z, dx * dx, P) < 0) return -1;
                added++;
            }
        }
    }
    return added;
}

/* The velocity of a moving wall at the end of the step from t_from by dt: its motion law's, or
 * an external velocity (co-simulation input), which is constant over the step. */
static void step_end_velocity(const struct motion *m, const struct wall_state *ws, double t_from, double dt,
                              double *vx, double *vz)
{
    if (ws->ext) {
        *vx = ws->ext_vx;
        *vz = ws->ext_vz;
    } else {
        motion_velocity(m, t_from + dt, vx, vz);
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
    double dxw[WALLS_MAX] = {0}, dzw[WALLS_MAX] = {0}, fx[WALLS_MAX] = {0}, fz[WALLS_MAX] = {0};
    for (size_t w = 0; w < W->n; w++) {
        const int mo = W->def[w].motion;
        if (mo < 0) continue;
        const struct motion *m = &W->motions[mo];
        struct wall_state *ws = &wstate[w];
        double vx, vz;
        step_end_velocity(m, ws, t_from, dt, &ws->vx, &ws->vz);
        if (ws->ext) {
            vx = ws->vx;
            vz = ws->vz;
            ws->ax = ws->az = 0.0;
        } else {
            motion_velocity(m, t_from + 0.5 * dt, &vx, &vz);
            motion_acceleration(m, t_from + dt, &ws->ax, &ws->az);
        }
        dxw[w] = vx * dt;
        dzw[w] = vz * dt;
        ws->ox += dxw[w];
        ws->oz += dzw[w];
        moving = 1;
    }
    if (!moving) return;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] != MIXSPH_STATE_WALL) continue;
        const size_t w = particles_wall_index(P, i);
        if (W->def[w].motion < 0) continue;
        fx[w] += P->ax[i];
        fz[w] += P->az[i];
        P->x[i] += dxw[w];
        P->z[i] += dzw[w];
        P->vx[i] = wstate[w].vx;
        P->vz[i] = wstate[w].vz;
    }
    for (size_t w = 0; w < W->n; w++) wstate[w].work -= fx[w] * dxw[w] + fz[w] * dzw[w];
}

void walls_clip(const struct walls *W, const double *ox_old, const double *oz_old, double gap, double x0, double z0,
                double *x1, double *z1, double *vx, double *vz, long *clips)
{
    for (int pass = 0; pass < 4; pass++) {
        int hit = 0;
        for (size_t w = 0; w < W->n && !hit; w++) {
            const struct wall *wl = &W->def[w];
            const struct wall_state *ws = &W->state[w];
            /* the path in the frame of the wall */
            const double ax = x0 - ox_old[w], az = z0 - oz_old[w];
            const double bx = *x1 - ws->ox, bz = *z1 - ws->oz;
            for (size_t k = 0; k + 1 < wl->line.n; k++) {
                const double cx = wl->line.x[k], cz = wl->line.z[k];
                const double ex = wl->line.x[k + 1] - cx, ez = wl->line.z[k + 1] - cz;
                double sc;
                if (!geom_path_crosses(ax, az, bx, bz, cx, cz, cx + ex, cz + ez, &sc)) continue;
                /* fluid-side unit normal of this segment */
                const double len = hypot(ex, ez);
                const double nx = -ez / len * wl->side, nz = ex / len * wl->side;
                /* only a crossing from the fluid side into the wall counts */
                if ((bx - ax) * nx + (bz - az) * nz >= 0.0) continue;
                const double px = ax + sc * (bx - ax), pz = az + sc * (bz - az);
                *x1 = px + gap * nx + ws->ox;
                *z1 = pz + gap * nz + ws->oz;
                const double vn = (*vx - ws->vx) * nx + (*vz - ws->vz) * nz;
                if (vn < 0.0) {
                    *vx -= vn * nx;
                    *vz -= vn * nz;
                }
                (*clips)++;
                hit = 1;
                break;
            }
        }
        if (!hit) return;
    }
}

/* The kernel weight of a non-wall neighbour at (rx, rz) from a wall particle in the
 * extrapolation onto it. */
static inline double extrapolation_weight(const struct kernel *K, int wendland, double rx, double rz)
{
    const double q = kernel_q(K, rx * rx + rz * rz);
    return wendland ? kernel_w_q(K, q, 1) : kernel_w_q(K, q, 0);
}

/* A wall particle's velocity in the viscous terms from the fluid's kernel average: the mirror
 * about the wall's velocity (no-slip: the average at the wall is its velocity) or the average
 * itself (free slip: no shear across it). */
static inline double mirror_velocity(int noslip, double v_wall, double v_fluid)
{
    return noslip ? 2.0 * v_wall - v_fluid : v_fluid;
}

/* A free-slip wall particle's velocity seen by a solid, which has a stress: besides the fluid's
 * tangential velocity, its normal velocity mirrored about the wall's, so that a solid pressing
 * on the wall is strained by it (its velocity gradient) as by its mirror image. (nx, nz) = 0
 * leaves (*vx, *vz) as they are. */
static inline void mirror_normal_velocity(double nx, double nz, double vx_wall, double vz_wall, double *vx, double *vz)
{
    const double vn = (*vx - vx_wall) * nx + (*vz - vz_wall) * nz;
    *vx -= 2.0 * vn * nx;
    *vz -= 2.0 * vn * nz;
}

/* The arguments of a parallel loop of this file (core/team.h). */
struct wall_loop {
    const struct walls *W;
    const struct kernel *K;
    const struct gather *G;
    double dx;
    struct particles *P;
    const struct particles *cP;
    struct wall_mirror *M;
    const struct wall_mirror *cM;
    const double *vx_wall, *vz_wall;
    double c;
    double *vx, *vz;
};
static void mirror_weights_range(void *arg, size_t b, size_t e);
static void mirror_apply_range(void *arg, size_t b, size_t e);

static void extrapolate_range(void *arg, size_t b, size_t e)
{
    const struct wall_loop *L = arg;
    const struct walls *W = L->W;
    const struct wall_state *wstate = W->state;
    const struct kernel *K = L->K;
    const struct gather *G = L->G;
    struct particles *P = L->P;
    const double g = W->g, vol = L->dx * L->dx, rho_alone = W->rho_alone;
    const int wendland = K->type == KERNEL_WENDLAND_C2;
    for (size_t i = b; i < e; i++) {
        if (P->state[i] != MIXSPH_STATE_WALL) continue;
        const size_t w = particles_wall_index(P, i);
        const struct wall_state *ws = &wstate[w];
        /* g - a_w, with g = (0, -g) */
        const double gx = -ws->ax, gz = -g - ws->az;
        const double xi = P->x[i], zi = P->z[i];
        double sw = 0.0, sp = 0.0, svx = 0.0, svz = 0.0, srho = 0.0;
        for (size_t k = G->start[i]; k < G->start[i + 1]; k++) { /* the non-wall neighbours */
            const size_t j = G->list[k];
            const double rx = xi - P->x[j], rz = zi - P->z[j];
            const double wgt = extrapolation_weight(K, wendland, rx, rz);
            sw += wgt;
            sp += (P->p[j] + P->rho[j] * (gx * rx + gz * rz)) * wgt;
            svx += P->vx[j] * wgt;
            srho += P->rho[j] * wgt;
            svz += P->vz[j] * wgt;
        }
        const int noslip = W->def[w].slip == WALL_NO_SLIP;
        if (sw > 0.0) {
            const double pw = sp / sw;
            P->p[i] = pw > 0.0 ? pw : 0.0;
            P->uvx[i] = mirror_velocity(noslip, ws->vx, svx / sw);
            P->uvz[i] = mirror_velocity(noslip, ws->vz, svz / sw);
            if (P->wall_nx && !noslip) /* a wall that mirrors a solid's stress (particles.h) */
                mirror_normal_velocity(P->wall_nx[i], P->wall_nz[i], ws->vx, ws->vz, &P->uvx[i], &P->uvz[i]);
            P->rho[i] = srho / sw;
        } else {
            P->p[i] = 0.0;
            P->rho[i] = rho_alone;
            P->uvx[i] = ws->vx;
            P->uvz[i] = ws->vz;
        }
        P->m[i] = P->rho[i] * vol; /* the mass seen by the artificial viscosity */
        P->inv_rho[i] = 1.0 / P->rho[i];
    }
}

void walls_extrapolate_fluid(const struct walls *W, const struct kernel *K, const struct gather *G, double dx,
                             struct particles *P, size_t n, int n_threads)
{
    struct wall_loop L = {.W = W, .K = K, .G = G, .dx = dx, .P = P};
    team_for(n_threads, n, extrapolate_range, &L);
}

struct wall_mirror *walls_mirror_create(void) { return calloc(1, sizeof(struct wall_mirror)); }

void walls_mirror_free(struct wall_mirror *M)
{
    if (!M) return;
    free(M->weight);
    free(M->cx);
    free(M->cz);
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
        double *cx = realloc(M->cx, cap * sizeof(double));
        if (!cx) return -1;
        M->cx = cx;
        double *cz = realloc(M->cz, cap * sizeof(double));
        if (!cz) return -1;
        M->cz = cz;
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
    struct wall_loop L = {.W = W, .K = K, .G = G, .cP = P, .M = M};
    team_for(n_threads, M->n_rows, mirror_weights_range, &L);
    return 0;
}

static void mirror_weights_range(void *arg, size_t b, size_t e)
{
    const struct wall_loop *L = arg;
    const struct walls *W = L->W;
    const struct kernel *K = L->K;
    const struct gather *G = L->G;
    const struct particles *P = L->cP;
    struct wall_mirror *M = L->M;
    const int wendland = K->type == KERNEL_WENDLAND_C2;
    for (size_t r = b; r < e; r++) {
        const size_t i = M->rows[r];
        double sw = 0.0;
        for (size_t k = G->start[i]; k < G->start[i + 1]; k++) {
            const size_t j = G->list[k];
            M->weight[k] = extrapolation_weight(K, wendland, P->x[i] - P->x[j], P->z[i] - P->z[j]);
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
    const struct wall_loop *L = arg;
    const struct walls *W = L->W;
    const struct particles *P = L->cP;
    struct wall_mirror *M = L->M;
    const double *vx = L->vx_wall, *vz = L->vz_wall;
    for (size_t r = b; r < e; r++) {
        const size_t i = M->rows[r];
        const size_t w = particles_wall_index(P, i);
        const int noslip = W->def[w].slip == WALL_NO_SLIP;
        M->cx[i] = M->sign[i] ? mirror_velocity(noslip, vx[w], 0.0) : vx[w];
        M->cz[i] = M->sign[i] ? mirror_velocity(noslip, vz[w], 0.0) : vz[w];
    }
}

void walls_mirror_at(struct wall_mirror *M, const struct walls *W, const struct particles *P, double t_from, double dt,
                     int n_threads)
{
    const struct wall_state *wstate = W->state;
    double vx[WALLS_MAX], vz[WALLS_MAX];
    for (size_t w = 0; w < W->n; w++) {
        const int mo = W->def[w].motion;
        vx[w] = wstate[w].vx;
        vz[w] = wstate[w].vz;
        if (mo >= 0 && dt > 0.0) step_end_velocity(&W->motions[mo], &wstate[w], t_from, dt, &vx[w], &vz[w]);
    }
    struct wall_loop L = {.W = W, .cP = P, .M = M, .vx_wall = vx, .vz_wall = vz};
    team_for(n_threads, M->n_rows, mirror_at_range, &L);
}

void walls_mirror_apply(const struct wall_mirror *M, const struct gather *G, int with_constant, double *vx,
                        double *vz, int n_threads)
{
    struct wall_loop L = {.cM = M, .G = G, .c = with_constant ? 1.0 : 0.0, .vx = vx, .vz = vz};
    team_for(n_threads, M->n_rows, mirror_apply_range, &L);
}

static void mirror_apply_range(void *arg, size_t b, size_t e)
{
    const struct wall_loop *L = arg;
    const struct wall_mirror *M = L->cM;
    const struct gather *G = L->G;
    const double c = L->c;
    double *vx = L->vx, *vz = L->vz;
    for (size_t r = b; r < e; r++) {
        const size_t i = M->rows[r];
        double ax = 0.0, az = 0.0;
        for (size_t k = G->start[i]; k < G->start[i + 1]; k++) {
            const size_t j = G->list[k];
            ax += M->weight[k] * vx[j];
            az += M->weight[k] * vz[j];
        }
        vx[i] = c * M->cx[i] + M->sign[i] * ax;
        vz[i] = c * M->cz[i] + M->sign[i] * az;
    }
}
