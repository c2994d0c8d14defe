/* threshold_monitors.h - monitors defined by thresholds on a medium's particles (docs/output.md):
 * a deposit's run-out and height, a wave gauge's free-surface elevation, a slide's impact into
 * still water, a quantile of the particles' speeds. monitors.c samples them as outputs. */
#ifndef MIXSPH_THRESHOLD_MONITORS_H
#define MIXSPH_THRESHOLD_MONITORS_H

#include "sim_object.h"

/* The outputs of a slide_impact monitor, in the order of its outputs <name>, <name>_speed,
 * <name>_thickness, <name>_mass (case_monitor_extras). */
enum slide_impact_output { IMPACT_TIME, IMPACT_SPEED, IMPACT_THICKNESS, IMPACT_MASS, IMPACT_N };

/** Whether particle i lies in the region of a monitor (bounds of x and z). */
int monitor_in_region(const struct monitor_def *md, const struct particles *P, size_t i);

/** Whether particle i counts for a particle monitor: a mobile or held particle of the monitor's
 *  medium, in its region, with at least min_neighbours neighbours of its medium (not spray). */
int monitor_counts(const struct monitor_def *md, const struct particles *P, size_t i);

/** runout: the farthest position along the monitor's direction where the medium's deposit is at
 *  least `threshold` thick [m], and in *height the thickest column [m]; NAN (both) when no column
 *  is, or when the columns cannot be allocated. */
double runout_position(const mixsph_sim *s, const struct monitor_def *md, double *height);

/** wave_gauge: the free-surface elevation eta [m] above the still level at the station; NAN
 *  while no particle of the medium lies in the window. */
double wave_gauge_elevation(const mixsph_sim *s, const struct monitor_def *md);

/** slide_impact: whether the slide's front has reached the still level now; if so, out[] holds
 *  the time, the centroid speed, the thickness normal to the ramp and the mass (enum
 *  slide_impact_output). */
int slide_impact_now(const mixsph_sim *s, const struct monitor_def *md, double out[IMPACT_N]);

/** speed: the quantile `quantile` of the speeds of the medium's particles in the region [m/s];
 *  NAN when there are none. */
double speed_quantile(const mixsph_sim *s, const struct monitor_def *md);

#endif
