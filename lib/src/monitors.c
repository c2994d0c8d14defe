/* monitors.c - scalar outputs sampled during the run: diagnostics (kinetic energy, mass, time
 * step, lost particles, wall corrections, speed, grains held fixed) and the case's monitors:
 *   front          - the largest (+x) or smallest (-x) x of a medium's particles;
 *   max_elevation  - the highest z of a medium's particles inside [x_min, x_max] (the run-up
 *                    when the range covers the opposite slope).
 * Both ignore spray: a particle counts only if it has at least min_neighbours particles of its
 * own medium within the kernel support 2h (counted in the last force pass).
 * Samples are taken every output.monitor_interval of simulated time; the extremes over the
 * samples and their times are kept, and each sample is a row of monitors.csv when an output
 * folder is set. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sim.h"
#include "status.h"

enum { OUT_KE, OUT_MASS, OUT_DT, OUT_LOST, OUT_CLIPS, OUT_VMAX, OUT_FIXED, OUT_N_DIAG };
static const char *const diag_names[OUT_N_DIAG] = {"kinetic_energy", "mass", "dt", "lost_particles", "wall_corrections",
                                                   "max_speed", "fixed_particles"};

void monitors_init(mixsph_sim *s)
{
    s->n_out = 0;
    for (size_t k = 0; k < OUT_N_DIAG; k++) snprintf(s->out_name[s->n_out++], CASE_NAME_LEN, "%s", diag_names[k]);
    for (size_t k = 0; k < s->cfg.n_monitors; k++) snprintf(s->out_name[s->n_out++], CASE_NAME_LEN, "%s", s->cfg.monitors[k].name);
    for (size_t k = 0; k < s->n_out; k++) {
        s->out_max[k] = s->out_min[k] = NAN;
        s->out_tmax[k] = s->out_tmin[k] = NAN;
    }
    s->n_samples = 0;
}

static double monitor_eval(const mixsph_sim *s, const struct monitor_def *md)
{
    const struct particles *P = &s->P;
    double best = NAN;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] > MIXSPH_STATE_FIXED || P->medium[i] != md->medium) continue;
        if (P->nneigh[i] < md->min_neighbours) continue;
        double v;
        if (md->kind == MONITOR_FRONT) {
            v = md->direction * P->x[i];
        } else {
            if (P->x[i] < md->x_min || P->x[i] > md->x_max) continue;
            v = P->z[i];
        }
        if (isnan(best) || v > best) best = v;
    }
    if (md->kind == MONITOR_FRONT && !isnan(best)) best *= md->direction;
    return best;
}

double monitors_value(const mixsph_sim *s, size_t k)
{
    const struct particles *P = &s->P;
    if (k >= OUT_N_DIAG) return monitor_eval(s, &s->cfg.monitors[k - OUT_N_DIAG]);
    if (k == OUT_DT) return s->dt;
    if (k == OUT_LOST) return (double)s->n_lost;
    if (k == OUT_CLIPS) return (double)s->n_clipped;
    if (k == OUT_FIXED) return (double)s->n_fixed;
    double ke = 0.0, mass = 0.0, vmax = 0.0;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] > MIXSPH_STATE_FIXED) continue;
        const double v2 = P->vx[i] * P->vx[i] + P->vz[i] * P->vz[i];
        ke += 0.5 * P->m[i] * v2;
        mass += P->m[i];
        if (v2 > vmax) vmax = v2;
    }
    return k == OUT_KE ? ke : k == OUT_MASS ? mass : sqrt(vmax);
}

mixsph_status monitors_open(mixsph_sim *s)
{
    char path[600];
    snprintf(path, sizeof path, "%s/monitors.csv", s->out_dir);
    s->monitor_csv = fopen(path, "w");
    if (!s->monitor_csv) return SIM_FAIL(s, MIXSPH_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
    fprintf(s->monitor_csv, "t,step");
    for (size_t k = 0; k < s->n_out; k++) fprintf(s->monitor_csv, ",%s", s->out_name[k]);
    fprintf(s->monitor_csv, "\n");
    fflush(s->monitor_csv);
    return MIXSPH_OK;
}

mixsph_status monitors_sample(mixsph_sim *s)
{
    double v[SIM_MAX_OUTPUTS];
    for (size_t k = 0; k < s->n_out; k++) {
        v[k] = monitors_value(s, k);
        if (isnan(v[k])) continue;
        if (isnan(s->out_max[k]) || v[k] > s->out_max[k]) {
            s->out_max[k] = v[k];
            s->out_tmax[k] = s->t;
        }
        if (isnan(s->out_min[k]) || v[k] < s->out_min[k]) {
            s->out_min[k] = v[k];
            s->out_tmin[k] = s->t;
        }
    }
    s->n_samples++;
    if (s->monitor_csv) {
        fprintf(s->monitor_csv, "%.9g,%llu", s->t, (unsigned long long)s->step);
        for (size_t k = 0; k < s->n_out; k++) fprintf(s->monitor_csv, ",%.9g", v[k]);
        fprintf(s->monitor_csv, "\n");
        if (fflush(s->monitor_csv) != 0) return SIM_FAIL(s, MIXSPH_ERR_IO, "%s/monitors.csv: write failed", s->out_dir);
    }
    return MIXSPH_OK;
}

/* Particle snapshot as CSV (snap_NNNN.csv): one row per particle, walls included. */
mixsph_status monitors_snapshot(mixsph_sim *s)
{
    char path[600];
    snprintf(path, sizeof path, "%s/snap_%04d.csv", s->out_dir, s->snap_index);
    FILE *f = fopen(path, "w");
    if (!f) return SIM_FAIL(s, MIXSPH_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
    const struct particles *P = &s->P;
    fprintf(f, "# t = %.9g s\nid,x,z,vx,vz,rho,p,mu,medium,state\n", s->t);
    for (size_t i = 0; i < P->n; i++)
        fprintf(f, "%u,%.7g,%.7g,%.6g,%.6g,%.7g,%.6g,%.6g,%u,%u\n", P->id[i], P->x[i], P->z[i], P->vx[i], P->vz[i],
                P->rho[i], P->p[i], P->mu[i], P->medium[i], P->state[i]);
    const int bad = ferror(f);
    if (fclose(f) != 0 || bad) return SIM_FAIL(s, MIXSPH_ERR_IO, "%s: write failed", path);
    s->snap_index++;
    return MIXSPH_OK;
}
