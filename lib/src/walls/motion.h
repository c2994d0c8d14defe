/* motion.h - a prescribed motion law: a velocity table, linear between its rows, stretched in
 * time and scaled in speed (docs/cases.md, "motions"); the walls move by it. As a DIM vector the
 * table's velocity is (vx, vz) in 2D, (vx, vy, vz) in 3D (vy NULL: 0; a 2D case has none). */
#ifndef MIXSPH_MOTION_H
#define MIXSPH_MOTION_H
#include <stddef.h>

#include "dim.h"
#include "schema.h" /* SCHEMA_NAME_LEN */

struct motion {
    char name[SCHEMA_NAME_LEN];
    size_t n;
    double *t, *vx, *vy, *vz; /* velocity law, linear between rows [s], [m/s]; vy may be NULL (0) */
    double speed_scale;       /* velocities are multiplied by this [-] */
    double time_scale;        /* the law is stretched in time by this [-] */
};

/** Velocity v of a motion law at time t (linear between rows, held at the ends). */
void motion_velocity(const struct motion *m, double t, double v[DIM]);
/** Acceleration a of a motion law at time t (slope of the current interval). */
void motion_acceleration(const struct motion *m, double t, double a[DIM]);

#endif
