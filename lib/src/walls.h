/* walls.h - walls from polylines (docs/model.md section 8, docs/numerics.md): layers of wall
 * particles behind each polyline, their motion, the extrapolation of the fluid's state onto
 * them, and the geometric guard against crossings. A wall treatment plugs in here: it owns the
 * wall particles' p, rho, m and viscous velocity (uvx, uvz), which the pair loops read. */
#ifndef MIXSPH_WALLS_H
#define MIXSPH_WALLS_H
#include <stddef.h>

#include "case.h"
#include "kernel.h"
#include "neighbours.h"
#include "particles.h"

/* The moving state of one wall. */
struct wall_state {
    double ox, oz;   /* displacement of the wall since t = 0 [m] */
    double vx, vz;   /* current velocity [m/s] */
    double ax, az;   /* current acceleration [m/s2] */
    int ext;         /* driven by an external velocity (ext_vx, ext_vz) instead of its motion law */
    double ext_vx, ext_vz; /* [m/s] */
};

/** Velocity and acceleration of every wall at t = 0 from its motion law. */
void walls_start(const struct case_def *cfg, struct wall_state *ws);

#define WALLS_INTERRUPTED (-2L)

/** Append the wall particles of every wall of the case at spacing dx (cfg->wall_layers layers
 *  deep, on the global lattice); their `medium` field holds their wall's index and they start
 *  with their wall's velocity. Polls `interrupt` (may be NULL) at every lattice row. Returns the
 *  number added, -1 when out of memory, WALLS_INTERRUPTED when the host asked to stop. */
long walls_generate(const struct case_def *cfg, const struct wall_state *ws, double dx, const mixsph_interrupt *interrupt,
                    struct particles *P);

/** Signed distance of (x, z) to wall w at its current position (< 0 behind it), and whether the
 *  closest point is an end of the polyline. */
void walls_signed_distance(const struct case_def *cfg, const struct wall_state *ws, size_t w, double x, double z,
                           double *d, int *at_end);

/** Move the walls and their particles from t_from by dt. */
void walls_move(const struct case_def *cfg, struct wall_state *ws, struct particles *P, double t_from, double dt);

/** Keep a particle moving (x0,z0) -> (*x1,*z1) on the fluid side of every wall: a crossing is
 *  put back at `gap` from the wall and loses its velocity into it (counted in *clips).
 *  ox_old/oz_old: the walls' displacements at the start of the step (walls already moved). */
void walls_clip(const struct case_def *cfg, const struct wall_state *ws, const double *ox_old, const double *oz_old,
                double gap, double x0, double z0, double *x1, double *z1, double *vx, double *vz, long *clips);

/** The state of the first n particles' wall particles from the fluid around them (Adami et
 *  al. 2012): pressure, viscous (mirror) velocity uvx/uvz, density and the mass the artificial
 *  viscosity sees. Needs the gather lists of G. */
void walls_extrapolate_fluid(const struct case_def *cfg, const struct wall_state *ws, const struct kernel *K,
                             const struct gather *G, double dx, struct particles *P, size_t n, int n_threads);

#endif
