/* threshold_monitors.c - monitors defined by thresholds (docs/output.md "Threshold monitors"):
 *
 *   runout       - the deposit of a medium over columns of width `bin` along x: a column's
 *                  thickness is the volume of the medium's particles over it per unit width,
 *                      h_b = sum_j V_j |[x_j - dx/2, x_j + dx/2] n b| / (dx bin),  V_j = m_j / rho_j,
 *                  each particle spread over its own width dx (so a lattice that does not line up
 *                  with the columns gives no empty and no double columns). The run-out is the
 *                  farthest position along the direction where h >= threshold: the centre of the
 *                  farthest column that thick, moved towards the next column by the linear
 *                  interpolation of h to the threshold. A volume thickness needs no bed height
 *                  (a thin layer on a bed of any shape counts as thin) and does not jump with the
 *                  highest particle. The deposit's height is the largest h_b (H_inf of a column
 *                  collapse on a flat bed).
 *   wave_gauge   - the free surface at a station x (3D: (x, y)): the top (centre + dx/2, as the
 *                  profile monitor) of the highest particle of the medium in its column in the
 *                  window |x_j - x| <= window (3D: and |y_j - y| <= window), minus the still level. Splash is excluded by two rules:
 *                  a particle counts only with min_neighbours neighbours of its medium, and the
 *                  column is followed up from the medium's lowest particle through gaps of at
 *                  most GAUGE_GAP_OVER_DX dx, so a drop or jet separated from the water below by
 *                  a larger gap is not the surface. The column passes through the particles of
 *                  every medium (a slide's grains lying in the water do not cut it).
 *   slide_impact - the impact of a slide into still water, for the impulse product of Heller &
 *                  Hager (2010): the first sample at which the slide's front (the lowest lower
 *                  edge z_j - dx/2 of its counting particles) reaches the still level; then the
 *                  slide's centroid speed V_s = |sum m_j u_j| / sum m_j and mass m_s = sum m_j
 *                  over the medium's particles in the region, and its thickness normal to the
 *                  ramp s = max n.x_j - min n.x_j + dx over its counting particles, with n the
 *                  ramp's upward normal (sin alpha, cos alpha) for a ramp descending towards +x
 *                  (the slide lies on a straight ramp then: restrict the region to it). monitors.c
 *                  keeps the first values: the impact is taken once.
 *   speed        - a quantile of the speeds |u_j| of the medium's particles in the region (every
 *                  particle: a lone grain is one of the grains that must come to rest).
 * A monitor's region and station are case input in the x-z plane, compared with components 0 and
 * DIM_UP; the run-out's columns and the thickness per unit width are those of the 2D build. */
#include "threshold_monitors.h"

#include <math.h>
#include <stdlib.h>

/* The largest vertical gap [dx] a wave gauge follows up a water column: the lattice spacing of a
 * column is dx, and a surface that thins or tilts in the window leaves gaps below 2 dx. */
#define GAUGE_GAP_OVER_DX 2.0

int monitor_in_region(const struct monitor_def *md, const struct particles *P, size_t i)
{
    const double x = P->pos[0][i], z = P->pos[DIM_UP][i];
#if DIM == 3
    if (!(P->pos[1][i] >= md->y_min && P->pos[1][i] <= md->y_max)) return 0;
#endif
    return x >= md->x_min && x <= md->x_max && z >= md->z_min && z <= md->z_max;
}

/* A mobile or held particle of the monitor's medium (no wall particle). */
static int of_medium(const struct monitor_def *md, const struct particles *P, size_t i)
{
    return P->state[i] <= MIXSPH_STATE_FIXED && P->medium[i] == md->medium;
}

int monitor_counts(const struct monitor_def *md, const struct particles *P, size_t i)
{
    return of_medium(md, P, i) && P->nneigh[i] >= md->min_neighbours && monitor_in_region(md, P, i);
}

double runout_position(const mixsph_sim *s, const struct monitor_def *md, double *height)
{
    const struct particles *P = &s->phys.P;
    const double dx = s->phys.dx;
    *height = NAN;
    const size_t nb = (size_t)case_profile_bin_count(md); /* within output.max_profile_bins (budget.c) */
    double *h = calloc(nb, sizeof *h);
    if (!h) return NAN;
    for (size_t i = 0; i < P->n; i++) {
        if (!monitor_counts(md, P, i)) continue;
        const double a = P->pos[0][i] - 0.5 * dx - md->x_min, b = a + dx; /* the particle's width, from x_min */
        const double per_width = P->m[i] / P->rho[i] / (dx * md->bin);
        const long first = (long)floor(a / md->bin), last = (long)floor(b / md->bin);
        for (long k = first < 0 ? 0 : first; k <= last && k < (long)nb; k++) {
            const double overlap = fmin(b, (double)(k + 1) * md->bin) - fmax(a, (double)k * md->bin);
            if (overlap > 0.0) h[k] += overlap * per_width;
        }
    }
    double run = NAN, top = 0.0;
    for (size_t k = 0; k < nb; k++) top = fmax(top, h[k]);
    /* the farthest column at least threshold thick, walked from the far end */
    for (size_t q = 0; q < nb; q++) {
        const size_t k = md->direction > 0 ? nb - 1 - q : q;
        if (!(h[k] >= md->threshold)) continue;
        const double centre = md->x_min + ((double)k + 0.5) * md->bin;
        const int has_next = md->direction > 0 ? k + 1 < nb : k > 0;
        const double h_next = has_next ? h[md->direction > 0 ? k + 1 : k - 1] : 0.0;
        const double f = h[k] > h_next ? (h[k] - md->threshold) / (h[k] - h_next) : 0.0;
        run = centre + md->direction * f * md->bin;
        break;
    }
    free(h);
    if (!isnan(run)) *height = top;
    return run;
}

/* A particle the gauge's column may pass through: a mobile or held particle of any medium in
 * the window, not spray (the medium's own neighbours; grains under or in the water belong to
 * the column as much as the water does). */
static int in_gauge_column(const struct monitor_def *md, const struct particles *P, size_t i)
{
    return P->state[i] <= MIXSPH_STATE_FIXED && P->nneigh[i] >= md->min_neighbours &&
           fabs(P->pos[0][i] - md->point_x) <= md->window
#if DIM == 3
           && fabs(P->pos[1][i] - md->point_y) <= md->window /* a square column about (x, y) */
#endif
        ;
}

double wave_gauge_elevation(const mixsph_sim *s, const struct monitor_def *md)
{
    const struct particles *P = &s->phys.P;
    const double dx = s->phys.dx, gap = GAUGE_GAP_OVER_DX * dx;
    double top = INFINITY;
    for (size_t i = 0; i < P->n; i++)
        if (in_gauge_column(md, P, i) && P->medium[i] == md->medium) top = fmin(top, P->pos[DIM_UP][i]);
    if (isinf(top)) return NAN;
    /* follow the column up from its lowest particle of the medium: the highest particle (of any
     * medium) within `gap` above the top so far, until none is (each round moves the top to a
     * higher particle, so the rounds end; about the column's height / (2 dx) of them) */
    for (;;) {
        double next = top;
        for (size_t i = 0; i < P->n; i++) {
            if (!in_gauge_column(md, P, i)) continue;
            const double z = P->pos[DIM_UP][i];
            if (z > next && z <= top + gap) next = z;
        }
        if (!(next > top)) break;
        top = next;
    }
    /* the surface: the highest particle of the medium in the column so followed */
    double surface = -INFINITY;
    for (size_t i = 0; i < P->n; i++)
        if (in_gauge_column(md, P, i) && P->medium[i] == md->medium && P->pos[DIM_UP][i] <= top)
            surface = fmax(surface, P->pos[DIM_UP][i]);
    return surface + 0.5 * dx - md->still;
}

int slide_impact_now(const mixsph_sim *s, const struct monitor_def *md, double out[IMPACT_N])
{
    const struct particles *P = &s->phys.P;
    const double dx = s->phys.dx, a = md->angle * GEOM_PI / 180.0;
    const double n[2] = {md->direction * sin(a), cos(a)}; /* the ramp's upward normal in x-z */
    double low = INFINITY, lo_n = INFINITY, hi_n = -INFINITY;
    for (size_t i = 0; i < P->n; i++) {
        if (!monitor_counts(md, P, i)) continue;
        low = fmin(low, P->pos[DIM_UP][i] - 0.5 * dx);
        const double d = n[0] * P->pos[0][i] + n[1] * P->pos[DIM_UP][i];
        lo_n = fmin(lo_n, d);
        hi_n = fmax(hi_n, d);
    }
    if (!(low <= md->still)) return 0;
    double mass = 0.0, mom[DIM] = {0.0};
    for (size_t i = 0; i < P->n; i++) {
        if (!of_medium(md, P, i) || !monitor_in_region(md, P, i)) continue;
        mass += P->m[i];
        for (int d = 0; d < DIM; d++) mom[d] += P->m[i] * P->vel[d][i];
    }
    double m2 = 0.0;
    for (int d = 0; d < DIM; d++) m2 += mom[d] * mom[d];
    out[IMPACT_TIME] = s->phys.t;
    out[IMPACT_SPEED] = sqrt(m2) / mass;
    out[IMPACT_THICKNESS] = hi_n - lo_n + dx;
    out[IMPACT_MASS] = mass;
    return 1;
}

/* |u_i|^2 */
static double speed2_of(const struct particles *P, size_t i)
{
    double v2 = 0.0;
    for (int d = 0; d < DIM; d++) v2 += P->vel[d][i] * P->vel[d][i];
    return v2;
}

/* Particles of the speed monitor with |u|^2 <= v2 (all of them for v2 = INFINITY). */
static size_t count_at_most(const struct monitor_def *md, const struct particles *P, double v2, double *largest)
{
    size_t n = 0;
    *largest = -1.0;
    for (size_t i = 0; i < P->n; i++) {
        if (!of_medium(md, P, i) || !monitor_in_region(md, P, i)) continue;
        const double u2 = speed2_of(P, i);
        if (u2 > v2) continue;
        n++;
        *largest = fmax(*largest, u2);
    }
    return n;
}

/* The k-th smallest |u|^2 (k = ceil(quantile N)) by bisection on the value, which needs no copy of
 * the speeds: the smallest v2 with at least k speeds^2 <= v2, then snapped to the largest
 * speed^2 at or below it (an exact particle value). About 64 passes over the particles when the
 * quantile is below 1; one at 1. */
double speed_quantile(const mixsph_sim *s, const struct monitor_def *md)
{
    const struct particles *P = &s->phys.P;
    double vmax2;
    const size_t n = count_at_most(md, P, INFINITY, &vmax2);
    if (n == 0) return NAN;
    size_t k = (size_t)ceil(md->quantile * (double)n);
    if (k < 1) k = 1;
    if (k >= n) return sqrt(vmax2);
    double lo = 0.0, hi = vmax2, snapped;
    if (count_at_most(md, P, 0.0, &snapped) >= k) return 0.0;
    while (1) { /* count(lo) < k <= count(hi) */
        const double mid = 0.5 * (lo + hi);
        if (!(mid > lo && mid < hi)) break;
        if (count_at_most(md, P, mid, &snapped) >= k) hi = mid;
        else lo = mid;
    }
    count_at_most(md, P, hi, &snapped);
    return sqrt(snapped);
}
