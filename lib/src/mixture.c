/* mixture.c - the granular phase of the mixture model (Manenti et al. 2018, Section 2.1-2.2;
 * MODEL.md sections 5-6): strain rate, pore pressure, effective stress, the regime of every
 * granular particle (rheology.h) and the pressure of the grains held fixed.
 *
 * Called every step after the continuity pass, which has accumulated for every particle the
 * uncorrected velocity gradient G and the matrix L from the velocities that already felt the
 * last forces (v^{n+1/2}, see integrate.c). Then, for each granular particle:
 *   grad u = G L^-1                     (first-order correction; L ignored where det L < 0.05)
 *   sqrt(II_D), p_w, sigma' = max(p - max(p_w, 0), 0), mu_app = eps_f mu_f + sigma' sin(phi) / (2 sqrt(II_D))
 *   regime: mu_app >= mu_thr -> FIXED (mu = mu_thr, velocity set to 0, not moved next step,
 *           left out of dt); mu0 < mu_app < mu_thr -> mu0; else mu_app.
 * A fixed particle still receives forces and a velocity update every step (unless its medium
 * has hold_fixed, SPHERA's rule: then no acceleration, velocity exactly 0), so it is mobilised
 * again as soon as its neighbours shear it enough. The pore pressure of a saturated medium is
 * hydrostatic below the top of its saturated column: p_w = rho_f g (z_top - z) cos^2(alpha),
 * z_top the highest particle of a saturated medium in the particle's dx-wide column, alpha the
 * slope of z_top over +-2 columns. The pressure of a fixed particle follows the mobile granular
 * particles around it (the paper), extrapolated hydrostatically as at walls:
 *   p_i = sum_j (p_j + rho_j g (z_j - z_i)) W_ij / sum_j W_ij  over mobile granular j;
 * with no such neighbour it keeps the pressure of its own density. A medium with
 * `tension_cutoff` (not the paper's model, an option) has its pressure floored at the
 * background pressure here and in the equation of state (integrate.c).
 *
 * Fixed bed (numerics.fixed_bed_speed = v_fb >= 0; off by default): SPHERA's rule for a granular
 * bed without an erosion criterion (its erosion_flag 1 with velocity_fixed_bed = v_fb; MODEL.md
 * section 6 calls it an optimisation, not part of the model). In every vertical column 2h wide
 * (from the domain's x_min) the highest granular particle no faster than v_fb is the top of the
 * fixed bed (a grain held fixed at the last regime decision counts as at rest); every grain of
 * the column more than 2h below that top is frozen whatever its rheology says: FIXED (velocity
 * 0, not moved, mu = mu_thr) with the hydrostatic pressure of the top particle,
 *   p_i = p_top + rho0_top g (z_top - z_i),
 * and the density of that pressure (SPHERA also adds the kinetic pressure of the two particles'
 * relative velocity, below 1 Pa here: left out). A column without such a particle has no fixed
 * bed. */
#include <math.h>
#include <stdlib.h>

#include "eos.h"
#include "rheology.h"
#include "sim.h"
#include "status.h"

#define MIXTURE_DET_MIN 0.05 /* below this det L the correction is not applied */

mixsph_status mixture_alloc(mixsph_sim *s)
{
    struct kinematics *K = &s->kin;
    const size_t n = s->P.n + 1;
    double **f[7] = {&K->gux, &K->guz, &K->gwx, &K->gwz, &K->lxx, &K->lxz, &K->lzz};
    for (int k = 0; k < 7; k++) {
        *f[k] = calloc(n, sizeof(double));
        if (!*f[k]) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory (strain rates)");
    }
    K->nbins = (size_t)ceil((s->domain[1] - s->domain[0]) / s->dx) + 1;
    K->ztop = calloc(K->nbins, sizeof(double));
    if (!K->ztop) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory (pore pressure bins)");
    K->nbed = (size_t)ceil((s->domain[1] - s->domain[0]) / (2.0 * s->h)) + 1;
    K->bed_z = calloc(K->nbed, sizeof(double));
    K->bed_ref = calloc(K->nbed, sizeof(long));
    if (!K->bed_z || !K->bed_ref) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory (fixed bed columns)");
    return MIXSPH_OK;
}

void mixture_free(mixsph_sim *s)
{
    struct kinematics *K = &s->kin;
    free(K->gux);
    free(K->guz);
    free(K->gwx);
    free(K->gwz);
    free(K->lxx);
    free(K->lxz);
    free(K->lzz);
    free(K->ztop);
    free(K->bed_z);
    free(K->bed_ref);
}

/* Column of x among n columns of the given width from the domain's x_min (clamped to the ends). */
static size_t column_of(const mixsph_sim *s, double x, double width, size_t n)
{
    double b = floor((x - s->domain[0]) / width);
    if (b < 0) b = 0;
    if (b > (double)(n - 1)) b = (double)(n - 1);
    return (size_t)b;
}

/* Pore-pressure bin of x: columns dx wide. */
static size_t bin_of(const mixsph_sim *s, double x)
{
    return column_of(s, x, s->dx, s->kin.nbins);
}

/* Top of the saturated granular column in every bin. */
static void saturated_tops(mixsph_sim *s)
{
    struct kinematics *K = &s->kin;
    const struct particles *P = &s->P;
    for (size_t b = 0; b < K->nbins; b++) K->ztop[b] = -INFINITY;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] > MIXSPH_STATE_FIXED) continue;
        const struct medium *m = &s->cfg.media[P->medium[i]];
        if (m->kind != MEDIUM_GRANULAR || !m->saturated) continue;
        const size_t b = bin_of(s, P->x[i]);
        const double top = P->z[i] + 0.5 * s->dx;
        if (top > K->ztop[b]) K->ztop[b] = top;
    }
}

/* Fixed-bed column of x: columns 2h wide. */
static size_t bed_column(const mixsph_sim *s, double x)
{
    return column_of(s, x, 2.0 * s->h, s->kin.nbed);
}

/* Top of the fixed bed in every column: the highest granular particle no faster than
 * fixed_bed_speed (a grain fixed at the last decision counts as at rest); ties go to the first
 * in memory order, so the choice does not depend on the threads. */
static void fixed_bed_tops(mixsph_sim *s, size_t n)
{
    struct kinematics *K = &s->kin;
    const struct particles *P = &s->P;
    const double v2 = s->cfg.fixed_bed_speed * s->cfg.fixed_bed_speed;
    for (size_t b = 0; b < K->nbed; b++) {
        K->bed_z[b] = -INFINITY;
        K->bed_ref[b] = -1;
    }
    for (size_t i = 0; i < n; i++) {
        if (P->state[i] > MIXSPH_STATE_FIXED || s->cfg.media[P->medium[i]].kind != MEDIUM_GRANULAR) continue;
        if (P->state[i] == MIXSPH_STATE_MOBILE && P->vx[i] * P->vx[i] + P->vz[i] * P->vz[i] > v2) continue;
        const size_t b = bed_column(s, P->x[i]);
        if (P->z[i] > K->bed_z[b]) {
            K->bed_z[b] = P->z[i];
            K->bed_ref[b] = (long)i;
        }
    }
}

/* Whether grain i lies more than 2h below the top of its column's fixed bed. */
static int frozen(const mixsph_sim *s, size_t i)
{
    return s->P.z[i] < s->kin.bed_z[bed_column(s, s->P.x[i])] - 2.0 * s->h;
}

/* Pore pressure of a saturated grain at (x, z). */
static double pore_pressure(const mixsph_sim *s, const struct medium *m, double x, double z)
{
    const struct kinematics *K = &s->kin;
    const size_t b = bin_of(s, x);
    const double top = K->ztop[b];
    if (!(top > z)) return 0.0;
    const size_t bl = b >= 2 ? b - 2 : 0, br = b + 2 < K->nbins ? b + 2 : K->nbins - 1;
    double slope = 0.0;
    if (br > bl && isfinite(K->ztop[bl]) && isfinite(K->ztop[br]))
        slope = (K->ztop[br] - K->ztop[bl]) / ((double)(br - bl) * s->dx);
    const double cos2 = 1.0 / (1.0 + slope * slope);
    return m->rho_f * s->cfg.g * (top - z) * cos2;
}

void mixture_update(mixsph_sim *s)
{
    struct particles *P = &s->P;
    const struct kinematics *K = &s->kin;
    const struct cells *C = &s->C;
    const size_t n = C->start[C->ncell];
    saturated_tops(s);
    const int fixed_bed = s->cfg.fixed_bed_speed >= 0.0;
    if (fixed_bed) fixed_bed_tops(s, n);
    long fixed = 0;
#pragma omp parallel for schedule(static) reduction(+ : fixed) num_threads(SIM_THREADS(s))
    for (size_t i = 0; i < n; i++) {
        if (P->state[i] == MIXSPH_STATE_WALL) continue;
        const struct medium *m = &s->cfg.media[P->medium[i]];
        if (m->kind != MEDIUM_GRANULAR) continue;
        double dudx = K->gux[i], dudz = K->guz[i], dwdx = K->gwx[i], dwdz = K->gwz[i];
        const double det = K->lxx[i] * K->lzz[i] - K->lxz[i] * K->lxz[i];
        if (det > MIXTURE_DET_MIN) {
            const double a = K->lzz[i] / det, b = -K->lxz[i] / det, d = K->lxx[i] / det; /* L^-1 = [a b; b d] */
            const double ux = dudx * a + dudz * b, uz = dudx * b + dudz * d;
            const double wx = dwdx * a + dwdz * b, wz = dwdx * b + dwdz * d;
            dudx = ux;
            dudz = uz;
            dwdx = wx;
            dwdz = wz;
        }
        const double sii = rheology_sqrt_ii(dudx, dudz, dwdx, dwdz);
        const double pw = m->saturated ? pore_pressure(s, m, P->x[i], P->z[i]) : 0.0;
        const double sigma = rheology_effective_stress(P->p[i] - s->cfg.p_background, pw);
        const double mu_app = rheology_apparent(sigma, m->sin_phi, sii, m->eps_f_mu_f, m->mu_thr);
        double mu;
        int fix = rheology_regime(mu_app, m->mu_thr, m->mu0, &mu) == RHEOLOGY_FIXED;
        if (fixed_bed && frozen(s, i)) {
            fix = 1;
            mu = m->mu_thr;
        }
        if (fix) {
            P->state[i] = MIXSPH_STATE_FIXED;
            P->vx[i] = P->vz[i] = P->uvx[i] = P->uvz[i] = 0.0;
            fixed++;
        } else {
            P->state[i] = MIXSPH_STATE_MOBILE;
        }
        P->mu[i] = mu;
    }
    s->n_fixed = fixed;
    if (fixed == 0) return;
    /* pressure of the fixed grains from the mobile grains around them */
    const struct kernel *KW = &s->K;
    const double g = s->cfg.g;
#pragma omp parallel for schedule(static) num_threads(SIM_THREADS(s))
    for (size_t i = 0; i < n; i++) {
        if (P->state[i] != MIXSPH_STATE_FIXED || (fixed_bed && frozen(s, i))) continue;
        const double xi = P->x[i], zi = P->z[i];
        double sw = 0.0, sp = 0.0;
        for (size_t k = 0; k < 6; k += 2) /* the three rows of the neighbourhood */
            for (size_t j = s->G.rng[6 * i + k]; j < s->G.rng[6 * i + k + 1]; j++) {
            if (P->state[j] != MIXSPH_STATE_MOBILE || s->cfg.media[P->medium[j]].kind != MEDIUM_GRANULAR) continue;
            const double rx = xi - P->x[j], rz = zi - P->z[j];
            const double r2 = rx * rx + rz * rz;
            if (r2 >= KW->r2max) continue;
            const double w = kernel_w(KW, sqrt(r2));
            sw += w;
            sp += (P->p[j] + P->rho[j] * g * (P->z[j] - zi)) * w;
        }
        if (sw > 0.0) {
            const double pb = s->cfg.p_background;
            const double p = sp / sw;
            P->p[i] = s->cfg.media[P->medium[i]].tension_cutoff && p < pb ? pb : p;
        }
    }
    if (!fixed_bed) return;
    /* the frozen grains: hydrostatic from the top of their column's fixed bed (its pressure is
     * final: the top is never frozen, and its extrapolation above is done) */
    const double pb = s->cfg.p_background;
#pragma omp parallel for schedule(static) num_threads(SIM_THREADS(s))
    for (size_t i = 0; i < n; i++) {
        if (P->state[i] != MIXSPH_STATE_FIXED || !frozen(s, i)) continue;
        const size_t top = (size_t)K->bed_ref[bed_column(s, P->x[i])];
        const struct medium *m = &s->cfg.media[P->medium[i]];
        double p = P->p[top] + s->cfg.media[P->medium[top]].rho0 * g * (P->z[top] - P->z[i]);
        if (m->tension_cutoff && p < pb) p = pb;
        P->p[i] = p;
        P->rho[i] = eos_density(p - pb, m->rho0, m->c);
        P->inv_rho[i] = 1.0 / P->rho[i];
        P->vol[i] = P->m[i] * P->inv_rho[i];
    }
}
