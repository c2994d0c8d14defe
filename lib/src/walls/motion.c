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

void motion_velocity(const struct motion *m, double t, double *vx, double *vz)
{
    size_t k;
    double f;
    int outside;
    motion_locate(m, t / m->time_scale, &k, &f, &outside);
    if (outside) {
        *vx = m->speed_scale * m->vx[k];
        *vz = m->speed_scale * m->vz[k];
        return;
    }
    *vx = m->speed_scale * (m->vx[k] + f * (m->vx[k + 1] - m->vx[k]));
    *vz = m->speed_scale * (m->vz[k] + f * (m->vz[k + 1] - m->vz[k]));
}

void motion_acceleration(const struct motion *m, double t, double *ax, double *az)
{
    size_t k;
    double f;
    int outside;
    motion_locate(m, t / m->time_scale, &k, &f, &outside);
    if (outside) {
        *ax = *az = 0.0;
        return;
    }
    const double dt = (m->t[k + 1] - m->t[k]) * m->time_scale;
    *ax = m->speed_scale * (m->vx[k + 1] - m->vx[k]) / dt;
    *az = m->speed_scale * (m->vz[k + 1] - m->vz[k]) / dt;
}
