/* elasticity.c - isotropic hypoelasticity in plane strain (elasticity.h). */
#include "elasticity.h"

#include <math.h>
#include <stddef.h>

const char *elasticity_constants(double E, double nu, double *K, double *G)
{
    if (!(E > 0.0) || !isfinite(E)) return "Young's modulus E must be a positive finite number of pascals";
    /* K > 0 and G > 0 need -1 < nu < 1/2; nu = 1/2 is the incompressible limit, K infinite */
    if (!(nu > -1.0 && nu < 0.5)) return "Poisson's ratio nu must lie in (-1, 0.5): K and G are positive only there";
    *K = E / (3.0 * (1.0 - 2.0 * nu));
    *G = E / (2.0 * (1.0 + nu));
    return NULL;
}

const char *elasticity_shear_from_bulk(double K, double nu, double *G)
{
    if (!(K > 0.0) || !isfinite(K)) return "bulk modulus K must be a positive finite number of pascals";
    if (!(nu > -1.0 && nu < 0.5)) return "Poisson's ratio nu must lie in (-1, 0.5): K and G are positive only there";
    *G = 3.0 * K * (1.0 - 2.0 * nu) / (2.0 * (1.0 + nu));
    return NULL;
}

double elasticity_wave_speed(double K, double G, double rho)
{
    return sqrt((K + 4.0 * G / 3.0) / rho);
}

double elasticity_static_strain(double rho, double g, double H, double E)
{
    return rho * g * H / E;
}

#if DIM == 2
void elasticity_jaumann_step(struct deviatoric_stress *s, const double L[DIM * DIM], double G, double dt)
{
    const double dudx = L[0], dudz = L[1], dwdx = L[2], dwdz = L[3];
    /* Q = (I - W dt/2)^-1 (I + W dt/2) with W_xz = -W_zx = w: a rotation whose cosine and sine
     * are (1 - b^2)/(1 + b^2) and 2 b/(1 + b^2), b = w dt / 2; Q = [[cq, sq], [-sq, cq]]. */
    const double b = 0.25 * (dudz - dwdx) * dt;
    const double den = 1.0 + b * b;
    const double cq = (1.0 - b * b) / den, sq = 2.0 * b / den;
    /* Q s Q^T of the in-plane block [[xx, xz], [xz, zz]]; yy lies on the rotation axis */
    const double cc = cq * cq, ss = sq * sq, cs = cq * sq;
    const double xx = cc * s->xx + 2.0 * cs * s->xz + ss * s->zz;
    const double zz = ss * s->xx - 2.0 * cs * s->xz + cc * s->zz;
    const double xz = cs * (s->zz - s->xx) + (cc - ss) * s->xz;
    /* 2 G D' dt, D' the deviator of the 3D strain rate (D_yy = 0) */
    const double tr3 = (dudx + dwdz) / 3.0;
    const double g2 = 2.0 * G * dt;
    s->xx = xx + g2 * (dudx - tr3);
    s->zz = zz + g2 * (dwdz - tr3);
    s->xz = xz + g2 * 0.5 * (dudz + dwdx);
    s->yy = s->yy - g2 * tr3;
}

double elasticity_pressure_step(double p, const double L[DIM * DIM], double K, double dt)
{
    return p - K * (L[0] + L[3]) * dt;
}
#else
void elasticity_jaumann_step(struct deviatoric_stress *s, const double L[DIM * DIM], double G, double dt)
{
    /* A = W dt / 2, W = (L - L^T) / 2; Q = I + 2 (A + A^2) / (1 + |a|^2) */
    double A[3][3], A2[3][3], Q[3][3], S[3][3], QS[3][3];
    double a2 = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            A[i][j] = 0.25 * (L[3 * i + j] - L[3 * j + i]) * dt;
            if (i < j) a2 += A[i][j] * A[i][j];
        }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            A2[i][j] = 0.0;
            for (int k = 0; k < 3; k++) A2[i][j] += A[i][k] * A[k][j];
        }
    const double f = 2.0 / (1.0 + a2);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) Q[i][j] = (i == j ? 1.0 : 0.0) + f * (A[i][j] + A2[i][j]);
    const double c[SYM_N] = {[SYM_XX] = s->xx, [SYM_XZ] = s->xz, [SYM_ZZ] = s->zz,
                             [SYM_YY] = s->yy, [SYM_XY] = s->xy, [SYM_YZ] = s->yz};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) S[i][j] = c[sym_index3(i, j)];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            QS[i][j] = 0.0;
            for (int k = 0; k < 3; k++) QS[i][j] += Q[i][k] * S[k][j];
        }
    double R[3][3]; /* Q S Q^T + 2 G D' dt */
    const double tr3 = (L[0] + L[4] + L[8]) / 3.0, g2 = 2.0 * G * dt;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double r = 0.0;
            for (int k = 0; k < 3; k++) r += QS[i][k] * Q[j][k];
            R[i][j] = r + g2 * (0.5 * (L[3 * i + j] + L[3 * j + i]) - (i == j ? tr3 : 0.0));
        }
    s->xx = R[0][0];
    s->yy = R[1][1];
    s->zz = R[2][2];
    s->xy = 0.5 * (R[0][1] + R[1][0]);
    s->xz = 0.5 * (R[0][2] + R[2][0]);
    s->yz = 0.5 * (R[1][2] + R[2][1]);
}

double elasticity_pressure_step(double p, const double L[DIM * DIM], double K, double dt)
{
    return p - K * (L[0] + L[4] + L[8]) * dt;
}
#endif
