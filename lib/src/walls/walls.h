/* walls.h - walls from polylines (2D) or triangulated surfaces (3D) (docs/model.md section 8,
 * docs/numerics.md): layers of wall particles behind each wall, their motion, the extrapolation
 * of the fluid's state onto them, and the geometric guard against crossings. A wall treatment
 * plugs in here: it owns the wall particles' p, rho, m and viscous velocity (uv), which the pair
 * loops read.
 *
 * In 2D (DIM = 2) a wall is a polyline of the case in the vertical x-z plane: its distance,
 * normal and crossings are taken in that plane. In 3D (DIM = 3) it is the oriented surface of its
 * definition (wall_def.h, core/surface.h): distance and normal by the nearest triangle and its
 * pseudo-normal, crossings by a segment-triangle test; wall particles on the lattice only. Both
 * move by translation (their motion law's velocity; in 3D with its y component). */
#ifndef MIXSPH_WALLS_H
#define MIXSPH_WALLS_H
#include <stddef.h>

#include "dim.h"
#include "kernel.h"
#include "mixsph.h" /* mixsph_interrupt */
#include "neighbours.h"
#include "particles.h"
#include "wall_def.h"

/* The moving state of one wall. */
struct wall_state {
    double o[DIM];   /* displacement of the wall since t = 0 [m] */
    double v[DIM];   /* current velocity [m/s] */
    double a[DIM];   /* current acceleration [m/s2] */
    int ext;         /* driven by an external velocity (ext_v) instead of its motion law */
    double ext_v[DIM]; /* [m/s] */
    double work;     /* the work it has done on the particles since t = 0 [J/m] (walls_move) */
};

/* numerics.wall_placement: where the wall particles sit (docs/model.md section 8). */
enum wall_placement {
    WALL_PLACEMENT_LATTICE = 0, /* the sites of the global lattice behind each wall */
    WALL_PLACEMENT_ALIGNED = 1  /* rows parallel to each segment, fans at inner corners */
};

/* The walls of a simulation: their definitions and parameters, set once from the case
 * (walls_init), and their moving states. */
struct walls {
    size_t n;                       /* number of walls */
    const struct wall *def;         /* their definitions [n] (the case's) */
    const struct motion *motions;   /* the motion laws def[w].motion indexes (the case's) */
    int layers;                     /* layers of wall particles behind each wall */
    int placement;                  /* enum wall_placement */
    double lattice_z0;              /* a layer boundary of the particle lattice [m] (geom_lattice_z_offset) */
    double g;                       /* gravity [m/s2] along -e_up, in the extrapolated pressure */
    double rho_alone;               /* density of a wall particle with no fluid around it [kg/m3] */
    struct wall_state state[WALLS_MAX];
};

/** The walls from their definitions (kept by reference: they must outlive W) and parameters, at
 *  rest at t = 0 with their motion laws' velocity and acceleration there. */
void walls_init(struct walls *W, const struct wall *def, size_t n, const struct motion *motions, int layers,
                int placement, double lattice_z0, double g, double rho_alone);

/** Give moving wall w the velocity v and acceleration a from now on, between two steps: its
 *  state, its particles' velocity and their velocity in the viscous terms (the mirror of the
 *  last wall pass, which the next regime decision reads) change with it. */
void walls_change_velocity(struct walls *W, size_t w, const double v[DIM], const double a[DIM],
                           struct particles *P);

#define WALLS_INTERRUPTED (-2L)
#define WALLS_NOT_IN_3D (-3L) /* walls_generate: the aligned placement is 2D only */

/** Append the wall particles of every wall of the case at spacing dx (W->layers layers
 *  deep, placed as W->placement says); their `medium` field holds their wall's index and
 *  they start with their wall's velocity. Polls `interrupt` (may be NULL) at every lattice row,
 *  or every segment when aligned. Returns the number added, -1 when out of memory,
 *  WALLS_INTERRUPTED when the host asked to stop, WALLS_NOT_IN_3D for the aligned placement in 3D. In 3D a wall's particles are the
 *  lattice sites within the layers' depth behind its surface (and behind its open edges) and those
 *  in front of it that it blocks for the bodies (walls_site_blocked). */
long walls_generate(const struct walls *W, double dx, const mixsph_interrupt *interrupt,
                    struct particles *P);

/** Whether a lattice site at signed distance d [m] from a wall's surface (d < 0 behind it; at_end:
 *  its nearest point on an open edge) is too close to the wall to hold a body's particle: within
 *  dx/2 in front of the surface, or behind it. In 3D the wall's own particles take the sites it
 *  blocks within its layers' depth (walls_generate), so that the bodies' lattice and the wall's
 *  meet with no empty layer between them (docs/model.md section 8). */
static inline int walls_site_blocked(double d, int at_end, double dx)
{
    return !at_end && d < 0.5 * dx * (1.0 - 1e-9);
}

/** Signed distance of pos to wall w at its current position (< 0 behind it) [m], and whether the
 *  closest point is an end of the polyline (3D: on an open edge of the surface). */
double walls_distance(const struct walls *W, size_t w, const double pos[DIM], int *at_end);

/** May pos be within `reach` of wall w where it is now (either side)? 0 only when it is not: the
 *  crossing guard's filter, whose false positives cost only time. 2D: the exact distance; 3D: a
 *  bound per triangle of the buckets within reach (surface_may_be_within), no nearest-point search. */
int walls_near(const struct walls *W, size_t w, const double pos[DIM], double reach);

/** The unit normal n of wall w toward its fluid at the point of the wall nearest to pos. */
void walls_normal(const struct walls *W, size_t w, const double pos[DIM], double n[DIM]);

/** Move the walls and their particles from t_from by dt. */
void walls_move(struct walls *W, struct particles *P, double t_from, double dt);

/** Keep a particle moving p0 -> p1 on the fluid side of every wall: a crossing is put back at
 *  `gap` from the wall (p1 changed) and loses its velocity v into it (counted in *clips).
 *  o_old: the walls' displacements at the start of the step (walls already moved). */
void walls_keep_fluid_side(const struct walls *W, const double (*o_old)[DIM], double gap, const double p0[DIM],
                           double p1[DIM], double v[DIM], long *clips);

/** Every particle's wall normal P->wall_n (the field must be there when a wall is free-slip):
 *  on a free-slip wall's particle its wall's unit normal toward the fluid at the point of the
 *  wall nearest to it (walls_normal: at a polyline's vertex or a surface's edge or corner the
 *  normalised sum of the faces' normals), 0 elsewhere. Once, after walls_generate: walls only
 *  translate. */
void walls_set_normals(const struct walls *W, struct particles *P);

/** The state of the first n particles' wall particles from the fluid around them (Adami et
 *  al. 2012): pressure, density and the mass the artificial viscosity sees, and their velocity
 *  from the kernel average v~ of the fluid's: on a no-slip wall uv = 2 v_wall - v~ in the viscous
 *  terms (vel stays the wall's own); on a free-slip wall the mirror image of the fluid across
 *  the wall, v~ - 2 ((v~ - v_wall) . n) n (n = P->wall_n), as both uv and vel, so that every
 *  pair term (viscous, continuity, artificial viscosity) sees no tangential jump across it.
 *  Needs the gather lists of G. */
void walls_extrapolate_fluid(const struct walls *W, const struct kernel *K,
                             const struct gather *G, double dx, struct particles *P, size_t n, int n_threads);

/* The wall particles' velocity in the viscous terms as the affine map of the non-wall
 * velocities that walls_extrapolate_fluid evaluates, for a solve whose unknowns are those
 * velocities (viscous.h): wall particle g takes
 *     u_g = c_g + s_g R_g sum_k a_gk u_k,   a_gk = W_gk / sum_k W_gk over its non-wall neighbours,
 * with s_g = -1, R_g = I, c_g = 2 v_w (no-slip) or s_g = +1, R_g = I - 2 n n^T, c_g = 2 (v_w . n) n
 * (free slip: the reflection across the wall, n = P->wall_n), v_w its wall's velocity at the end
 * of the step; a wall particle with no non-wall neighbour takes v_w. */
struct wall_mirror {
    double *weight;      /* a_gk, aligned with the gather list */
    double *c[DIM];      /* c_g [m/s] */
    const double *normal[DIM]; /* n of R_g: P->wall_n at the last build (NULL with no free-slip wall) */
    signed char *sign;   /* s_g */
    size_t *rows;        /* the wall particles among the first n, in order */
    size_t n_rows;
    size_t cap_list, cap_n;
};

struct wall_mirror *walls_mirror_create(void);
void walls_mirror_free(struct wall_mirror *M);

/** The map's weights and signs at the current positions, over the first n particles. Needs the
 *  gather lists of G. Returns -1 when out of memory. */
int walls_mirror_build(struct wall_mirror *M, const struct walls *W, const struct kernel *K,
                       const struct gather *G, const struct particles *P, size_t n, int n_threads);

/** The map's constants with the walls' velocities at t_from + dt (dt > 0: by their motion law or
 *  external velocity over the step from t_from, walls not yet moved) or their current ones
 *  (dt = 0). */
void walls_mirror_at(struct wall_mirror *M, const struct walls *W,
                     const struct particles *P, double t_from, double dt, int n_threads);

/** Overwrite the wall rows of the velocity components v[d] with the map of their non-wall rows:
 *  c_g + s_g a u (with_constant) or s_g a u (its linear part). */
void walls_mirror_fill(const struct wall_mirror *M, const struct gather *G, int with_constant, double *const v[DIM],
                       int n_threads);


#endif
