/* time_step.h - criterion (4) of the time step (docs/model.md section 4) for one particle. */
#ifndef MIXSPH_TIME_STEP_H
#define MIXSPH_TIME_STEP_H

/** Criterion (4) for one particle: the acoustic bound cfl 2 h / (c_max + |u|) and, when mu > 0,
 *  the viscous bound cfl_visc 2 h^2 rho / mu [s]. The schemes take its minimum over the particles;
 *  the case's resource budget (io/budget.c) estimates the number of steps with it. */
static inline double time_step_bound(double cfl, double cfl_visc, double h, double c_max, double speed,
                                       double rho, double mu)
{
    double d = cfl * 2.0 * h / (c_max + speed);
    if (mu > 0.0) {
        const double dv = cfl_visc * 2.0 * h * h * rho / mu;
        if (dv < d) d = dv;
    }
    return d;
}

#endif
