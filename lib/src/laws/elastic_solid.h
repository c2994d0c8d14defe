/* elastic_solid.h - a linear-elastic solid (media of type "elastic"): pressure from the linear
 * equation of state of its bulk modulus K, the deviatoric stress s integrated with the Jaumann
 * rate from the velocity gradient, in plane strain (the out-of-plane component s_yy carried):
 *
 *   ds/dt = 2 G (D - tr(D)/3 I) + W s - s W,   D = (L + L^T)/2, W = (L - L^T)/2, L_ab = du_a/dx_b
 *
 * with D_yy = 0 (plane strain) and W acting in the x-z plane only. Its P-wave speed
 * sqrt((K + 4G/3) / rho0) bounds the time step. It is the law that shows the stress seam
 * (docs/development.md) and the base of an elastic-plastic law's trial stress. */
#ifndef MIXSPH_ELASTIC_SOLID_H
#define MIXSPH_ELASTIC_SOLID_H

/* A plane-strain deviatoric stress [Pa], tension positive. */
struct deviatoric_stress {
    double xx, xz, zz, yy;
};

/** s advanced over dt [s] by the Jaumann rate above with shear modulus G [Pa] and the velocity
 *  gradient grad = (du/dx, du/dz, dw/dx, dw/dz) [1/s] (explicit Euler, as the density). */
static inline struct deviatoric_stress elastic_solid_jaumann_step(struct deviatoric_stress s, const double grad[4],
                                                                  double G, double dt)
{
    const double dxx = grad[0], dzz = grad[3], dxz = 0.5 * (grad[1] + grad[2]);
    const double w = 0.5 * (grad[1] - grad[2]); /* W_xz = -W_zx */
    const double third_tr = (dxx + dzz) / 3.0;
    const struct deviatoric_stress rate = {
        .xx = 2.0 * G * (dxx - third_tr) + 2.0 * w * s.xz,
        .xz = 2.0 * G * dxz + w * (s.zz - s.xx),
        .zz = 2.0 * G * (dzz - third_tr) - 2.0 * w * s.xz,
        .yy = 2.0 * G * (0.0 - third_tr),
    };
    return (struct deviatoric_stress){s.xx + dt * rate.xx, s.xz + dt * rate.xz, s.zz + dt * rate.zz, s.yy + dt * rate.yy};
}

#endif
