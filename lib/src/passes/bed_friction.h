/* bed_friction.h - Coulomb friction of a wall (a bed) on a grain (docs/model.md [BF]).
 *
 * The force its no-slip walls exert on grain i is split along the walls' normal n (out of the
 * walls) into a normal part N and a tangential part. The normal part stays; the tangential part the
 * material law gave (the elastic-plastic law's mirrored stress, the paper law's viscous term with
 * the wall's no-slip velocity) is replaced by a Coulomb contact:
 *
 *   N' = N - 2 (p_b + p_w) V_i |n|                (neither the background pressure nor the pore
 *                                                  water's is a contact force of the grains)
 *   F_stick = -m_i u_t / dt - F_other,t           (the tangential force that stops the grain's slip
 *                                                  u_t over the next step, given the others)
 *   F_t = F_stick                 if |F_stick| <= tan(delta) N'   (the grain sticks)
 *   F_t = tan(delta) N' F_stick / |F_stick|       otherwise       (it slides: kinetic friction)
 *
 * and N' < 0 (a cohesive grain's tension mirrored by the wall) leaves no contact: a wall pushes a
 * grain and never pulls it. Summed over the grains of a body sliding on a bed, the friction is
 * tan(delta) times the normal load whatever the law's own shear at the wall: the Coulomb block.
 * (A bound alone, |F_t| <= tan(delta) N', left a sliding elastic-plastic block with the shear its
 * stress gave at the wall, about 70 % of tan(delta) N: on a 45-degree ramp with delta = 30 it
 * slid 1.15-1.18 times too fast, docs/validation/coulomb_block.md.) A pure function of a
 * grain's sums: forces.c gathers them in the momentum pass and calls it per grain. */
#ifndef MIXSPH_BED_FRICTION_H
#define MIXSPH_BED_FRICTION_H
#include "dim.h"

/* What the contact of one grain needs, gathered by the momentum pass. */
struct bed_contact {
    double wall_force[DIM];  /* F_w: the force of its bounded walls on it (pair forces) [N per m in 2D] */
    double normal[DIM];      /* n = -sum_j V_j grad_i W_ij over those walls: out of the walls, |n| ~ their weight [-] */
    double wall_velocity[DIM]; /* the walls' kernel-weighted mean velocity at it [m/s] */
    double tan_delta;        /* the walls' friction coefficient tan(delta) at it [-] */
    double force[DIM];       /* the total force on it: pair forces and gravity [N per m] */
    double velocity[DIM];    /* its velocity [m/s] */
    double mass;             /* [kg per m] */
    double volume;           /* [m2] */
    double p_background;     /* [Pa] */
    double pore_pressure;    /* its pore pressure p_w >= 0 [Pa]: the walls' normal force holds its part too */
    double dt;               /* the time step [s]; 0: the stick force holds the other forces only */
};

/* The friction coefficient of every (wall, medium) pair, as the momentum pass reads it: tan(delta)
 * >= 0, BED_FRICTION_OWN where the wall takes the grains' own phi, BED_FRICTION_NONE where it
 * bounds nothing (the law's own no-slip shear). Entry [w * BED_FRICTION_SIDE + k] is wall w's on
 * medium k; a particle's `medium` byte (a wall particle's: its wall) indexes either side, so the
 * side holds every wall and every medium of a case (sim.c checks) and is a power of two (an index
 * masked by BED_FRICTION_SIDE - 1 stays inside whatever byte a padding lane holds). */
#define BED_FRICTION_SIDE 16
#define BED_FRICTION_OWN (-1.0)
#define BED_FRICTION_NONE (-2.0)
struct bed_friction_table {
    double mu[BED_FRICTION_SIDE * BED_FRICTION_SIDE];
};

/** The coefficient of a friction angle delta [deg]: tan(delta); NaN (not given) BED_FRICTION_OWN;
 *  90 or more BED_FRICTION_NONE. */
double bed_friction_coefficient(double delta_deg);

/** The change of grain i's force that its bed friction makes (added to its pair force). */
void bed_friction_change(const struct bed_contact *c, double change[DIM]);

#endif
