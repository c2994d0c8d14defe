/* mirror_sides.h - mirror side walls of an extruded 3D flume (a polyline's side_walls = "mirror"):
 * the planes y = y_lo and y = y_hi bound the flow as planes of symmetry, with no wall particles.
 * Every particle (fluid, granular or wall) closer than `reach` to a plane has an image across it:
 * its position mirrored, its vectors' y components and its stress's xy and yz components reversed
 * (particle_field.y_odd), every other field its own (mass, density, pressure, medium, ...). The
 * images are particles of the set (Libersky et al. 1993, the symmetry boundary of SPH): a fluid
 * or granular particle's image has the state MIXSPH_STATE_IMAGE, which the integration, the laws
 * and the monitors skip and every pair term (continuity, momentum, viscous, density diffusion,
 * velocity gradient, the walls' extrapolation) takes as a particle of its medium; a wall
 * particle's image is a wall particle (MIXSPH_STATE_WALL) whose force no wall's work or monitor
 * counts. Images mark themselves by P->image_of (1 + their source's id). They are made afresh at
 * each build of the neighbour lists (before the cell sort) and take their source's state at each
 * refresh (mirror_sides_refresh: after the drift, after the densities, after the walls'
 * extrapolation), so the flow is independent of y as the 2D case's by construction. Between
 * builds a particle moves less than skin/2, so reach = 2h + skin/2: a particle farther than that
 * from a plane at the build is never within 2h of an image of it before the next build. Two
 * planes at least 2h + skin apart: no particle needs the image of an image. */
#ifndef MIXSPH_MIRROR_SIDES_H
#define MIXSPH_MIRROR_SIDES_H
#include <stddef.h>
#include <stdint.h>

#include "dim.h"
#include "particles.h"

struct mirror_sides {
    int on;                 /* 3D with mirror side walls */
    double y_lo, y_hi;      /* the planes [m], the flow between them */
    double reach;           /* particles closer than this to a plane have an image across it [m] */
    size_t n_real;          /* the particles of the run (ids 0 .. n_real - 1); images take ids from n_real on */
    size_t n_images;
    uint32_t *image;        /* n_images: an image's index (after the last sort) */
    uint32_t *source;       /* n_images: its source's index */
    uint8_t *high;          /* n_images: 1 if across y_hi, 0 if across y_lo */
    uint32_t *index_of_id;  /* n_real: a particle's index by its id (scratch of mirror_sides_resolve) */
    size_t cap;
};

/** Before the first images: drop the wall particles beyond the planes (an extruded polyline's
 *  layers reach past its y range, for the corners with side walls; here the images of the
 *  particles inside stand there) and number the particles' ids afresh, 0 .. n - 1 in their
 *  order. Returns the number dropped, -1 when out of memory. */
long mirror_sides_trim(const struct mirror_sides *M, struct particles *P);
/** Drop the images, then append the image of every particle (not lost, not an image) at a
 *  distance d with 0 < d < reach from a plane, in its source's state (the sources at their
 *  current indices). Returns 0, -1 when out of memory. */
int mirror_sides_make(struct mirror_sides *M, struct particles *P);
/** After the particles were reordered (the cell sort): find each image and its source. Returns 0,
 *  -1 when out of memory. */
int mirror_sides_resolve(struct mirror_sides *M, const struct particles *P);
/** Every image takes its source's current state, mirrored; an image of a lost particle is lost. */
void mirror_sides_refresh(const struct mirror_sides *M, struct particles *P, int n_threads);
/** A particle that would cross a plane in its drift is reflected back (position and y velocity):
 *  the motion of its image. */
static inline void mirror_sides_reflect(const struct mirror_sides *M, double x[DIM], double v[DIM])
{
#if DIM == 3
    if (x[1] < M->y_lo) {
        x[1] = 2.0 * M->y_lo - x[1];
        v[1] = -v[1];
    } else if (x[1] > M->y_hi) {
        x[1] = 2.0 * M->y_hi - x[1];
        v[1] = -v[1];
    }
#else
    (void)M, (void)x, (void)v;
#endif
}
void mirror_sides_free(struct mirror_sides *M);

#endif
