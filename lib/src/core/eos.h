/* eos.h - linearised Tait equation of state p = c0^2 (rho - rho0) (docs/model.md section 3). */
#ifndef MIXSPH_EOS_H
#define MIXSPH_EOS_H

/** Pressure [Pa] from density for sound speed c [m/s] and reference density rho0 [kg/m3]. */
static inline double eos_pressure(double rho, double rho0, double c)
{
    return c * c * (rho - rho0);
}

/** Density [kg/m3] giving pressure p (the inverse of eos_pressure). */
static inline double eos_density(double p, double rho0, double c)
{
    return rho0 + p / (c * c);
}

#endif
