/* motion.c - a motion law's velocity and acceleration at a time: the row interval by bisection,
 * linear in between, held at the ends (a law starts and ends at rest or at constant speed). */
#include "motion.h"

/* Interval k and fraction f of law time tl: t[k] <= tl < t[k+1]; k = -1 before, n-1 after. */
static void motion_locate(const struct motion *m, double tl, size_t *k, double *f, int *outside)
{
    *outside = 0;
    if (m->n == 1 || tl <= m->t[0]) {
        *k = 0;
        *f = 0.0;
        *outside = 1;
        return;
    }
    if (tl >= m->t[m->n - 1]) {
        *k = m->n - 1;
        *f = 0.0;
        *outside = 1;
        return;
    }
    size_t lo = 0, hi = m->n - 1;
    while (hi - lo > 1) {
        size_t mid = (lo + hi) / 2;
        if (m->t[mid] <= tl) lo = mid;
        else hi = mid;
    }
    *k = lo;
    *f = (tl - m->t[lo]) / (m->t[lo + 1] - m->t[lo]);
}

/* The table's components (x, y, z) as a DIM vector (motion.h): y only in 3D. */
static void table_vector(double x, double y, double z, double v[DIM])
{
    for (int d = 0; d < DIM; d++) v[d] = 0.0;
    v[0] = x;
#if DIM == 3
    v[1] = y;
#else
    (void)y;
#endif
    v[DIM_UP] = z;
}

/* Row k of the table's y column (0 without one). */
static double vy_at(const struct motion *m, size_t k) { return m->vy ? m->vy[k] : 0.0; }

void motion_velocity(const struct motion *m, double t, double v[DIM])
{
    size_t k;
    double f;
    int outside;
    motion_locate(m, t / m->time_scale, &k, &f, &outside);
    if (outside) {
        table_vector(m->speed_scale * m->vx[k], m->speed_scale * vy_at(m, k), m->speed_scale * m->vz[k], v);
        return;
    }
    table_vector(m->speed_scale * (m->vx[k] + f * (m->vx[k + 1] - m->vx[k])),
                 m->speed_scale * (vy_at(m, k) + f * (vy_at(m, k + 1) - vy_at(m, k))),
                 m->speed_scale * (m->vz[k] + f * (m->vz[k + 1] - m->vz[k])), v);
}

void motion_acceleration(const struct motion *m, double t, double a[DIM])
{
    size_t k;
    double f;
    int outside;
    motion_locate(m, t / m->time_scale, &k, &f, &outside);
    if (outside) {
        table_vector(0.0, 0.0, 0.0, a);
        return;
    }
    const double dt = (m->t[k + 1] - m->t[k]) * m->time_scale;
    table_vector(m->speed_scale * (m->vx[k + 1] - m->vx[k]) / dt, m->speed_scale * (vy_at(m, k + 1) - vy_at(m, k)) / dt,
                 m->speed_scale * (m->vz[k + 1] - m->vz[k]) / dt, a);
}
