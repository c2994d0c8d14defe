/* budget.h - the resource budget of a case: what a run of it will ask for (particles, wall
 * particles, lattice sites scanned, profile bins, monitor rows, snapshot bytes, time steps),
 * estimated from the case alone, checked against the limits of its numerics.max_* and output.max_*
 * keys before anything is allocated. A case over a limit is refused with a message naming the key
 * that asks for it, the estimate and the limit with its key, so a user with a bigger machine
 * knows what to raise. */
#ifndef MIXSPH_BUDGET_H
#define MIXSPH_BUDGET_H
#include <stddef.h>

#include "case.h"

/* The estimates of a case (the counts are doubles: they may exceed any integer type). */
struct budget {
    double particles;       /* fluid and granular particles: the bodies' areas / dx^2 */
    double wall_particles;  /* the walls' lengths x layers / dx */
    double lattice_sites;   /* sites of the bounding boxes the creation scans */
    double steps;           /* t_end / the largest time step of criterion (4) at rest */
    double monitor_rows;    /* rows of monitors.csv */
    double snapshot_bytes;  /* CSV and HDF5 snapshots of every particle */
};

/** The estimates of case c (its keys read and validated). */
void budget_estimate(const struct case_def *c, struct budget *b);

/** Refuse (MIXSPH_ERR_CASE, message in err) a case whose estimates exceed its limits. */
mixsph_status budget_check(const struct case_def *c, char *err, size_t err_len);

#endif
