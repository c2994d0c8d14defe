/* elastic_solid.h - a linear-elastic solid (media of type "elastic"): pressure from the linear
 * equation of state of its bulk modulus K, the deviatoric stress s integrated with the Jaumann
 * rate from the velocity gradient, in plane strain (the out-of-plane component s_yy carried):
 *
 *   ds/dt = 2 G (D - tr(D)/3 I) + W s - s W,   D = (L + L^T)/2, W = (L - L^T)/2, L_ab = du_a/dx_b
 *
 * with D_yy = 0 (plane strain) and W acting in the x-z plane only (elasticity.h). Its P-wave
 * speed sqrt((K + 4G/3) / rho0) bounds the time step. It is the law that shows the stress seam
 * (docs/development.md, "How to add a material law"); its module is elastic_solid.c, which
 * registers `law_elastic_solid` (law_registry.c). */
#ifndef MIXSPH_ELASTIC_SOLID_H
#define MIXSPH_ELASTIC_SOLID_H

#endif
