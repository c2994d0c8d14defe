/* bed_friction.c - Coulomb friction of a wall on a grain (bed_friction.h, docs/model.md [BF]). */
#include "bed_friction.h"

#include <math.h>

#include "geometry.h" /* GEOM_PI */

/* delta from which the bed friction is "none" (docs/model.md [BF]): the law's own shear, unbounded [deg] */
#define BED_FRICTION_NONE_DEG 90.0

double bed_friction_coefficient(double delta_deg)
{
    if (isnan(delta_deg)) return BED_FRICTION_OWN;
    if (delta_deg >= BED_FRICTION_NONE_DEG) return BED_FRICTION_NONE;
    return tan(delta_deg * GEOM_PI / 180.0);
}

void bed_friction_change(const struct bed_contact *c, double change[DIM])
{
    for (int d = 0; d < DIM; d++) change[d] = 0.0;
    const double nn = dim_norm(c->normal);
    if (!(nn > 0.0)) return;
    double e[DIM], fn = 0.0;
    for (int d = 0; d < DIM; d++) {
        e[d] = c->normal[d] / nn;
        fn += c->wall_force[d] * e[d];
    }
    double t_wall[DIM]; /* the law's tangential wall force, which the contact replaces */
    for (int d = 0; d < DIM; d++) t_wall[d] = c->wall_force[d] - fn * e[d];
    const double n_eff = fn - 2.0 * (c->p_background + c->pore_pressure) * c->volume * nn;
    if (n_eff <= 0.0) { /* no contact: the walls neither pull the grain nor shear it */
        for (int d = 0; d < DIM; d++) change[d] = -t_wall[d] - (n_eff < 0.0 ? n_eff * e[d] : 0.0);
        return;
    }
    /* the tangential force that stops the slip over dt, given the other forces */
    double u_n = 0.0, o_n = 0.0, u[DIM], other[DIM];
    for (int d = 0; d < DIM; d++) {
        u[d] = c->velocity[d] - c->wall_velocity[d];
        other[d] = c->force[d] - t_wall[d];
        u_n += u[d] * e[d];
        o_n += other[d] * e[d];
    }
    const double inv_dt = c->dt > 0.0 ? 1.0 / c->dt : 0.0;
    double stick[DIM];
    for (int d = 0; d < DIM; d++) stick[d] = -c->mass * (u[d] - u_n * e[d]) * inv_dt - (other[d] - o_n * e[d]);
    const double s = dim_norm(stick), bound = c->tan_delta * n_eff;
    const double scale = s > bound ? bound / s : 1.0;
    for (int d = 0; d < DIM; d++) change[d] = scale * stick[d] - t_wall[d];
}
