/* monitors.c - outputs sampled during the run: diagnostics (kinetic energy, mass, time step,
 * lost particles, wall corrections, speed, grains held fixed) and the case's monitors:
 *   front          - the largest (+x) or smallest (-x) x of a medium's particles in the region;
 *   max_elevation  - the highest z (the vertical component, DIM_UP) of a medium's particles in
 *                    the region (the run-up when the region covers the opposite slope);
 *   wall_pressure  - the highest pressure of the first layer of a wall's particles in the region;
 *   wall_work      - the work a wall has done on the particles since t = 0 (walls.h, walls_move);
 *   pressure_probe - the fluid's pressure at a point, as SPH codes' gauges read it (DualSPHysics's
 *                    MeasureTool): the Shepard-normalised kernel interpolation over the non-wall
 *                    particles j within 2h of the point r,
 *                        p(r) = sum_j p_j V_j W(r - r_j) / sum_j V_j W(r - r_j),  V_j = m_j / rho_j,
 *                    and 0 ("dry") while the kernel sum sum_j V_j W(r - r_j) is below
 *                    PROBE_WET_KERNEL_SUM. A probe on a wall (key `wall`) is a sensor on the
 *                    wall's face: it reads at the point on the wall nearest to the sensor, moved
 *                    with the wall and then PROBE_WALL_STANDOFF_OVER_H h into the fluid along the
 *                    wall's normal (docs/model.md section 9);
 *   profile        - at given times, the top of a medium (highest particle centre + dx/2) in bins
 *                    of x, written to profile_<name>_<k>.csv (free surface, landslide surface,
 *                    mixture-water interface).
 *                    A profile with at_max_of = <m> is also rewritten as
 *                    profile_<name>_atmax.csv whenever the max_elevation monitor m reaches a new
 *                    highest value (so it holds the profile at the time of the maximum run-up).
 *   runout, wave_gauge, slide_impact, speed - the threshold monitors (threshold_monitors.h):
 *                    a deposit's run-out (and <name>_height, its thickest column), a gauge's
 *                    free-surface elevation, a slide's impact into still water (the time, and
 *                    <name>_speed, _thickness, _mass at it; kept once taken), a quantile of speeds.
 * Full-scale outputs (case key full_scale, case.h): <m>_Z = z_scale z + z_offset of every
 * max_elevation monitor m, and <m>_d_eta of the reference monitor: the error (13) of Manenti et
 * al. (2018), 100 |Z_max - Z_observed| / (Z_observed - Z_still) [%], with Z_max the highest value
 * of <m>_Z over the samples so far (its final value is the run's error).
 * Particle monitors ignore spray: a particle counts only if it has at least min_neighbours
 * particles of its own medium within the kernel support 2h (counted in the last pass).
 * Samples are taken every output.monitor_interval of simulated time; the extremes over the
 * samples and their times are kept, and each sample is a row of monitors.csv when an output
 * folder is set.
 * A monitor's region, point and bins are case input in x and z (and y in 3D): compared with
 * components 0 (x), DIM_UP (z) and, in 3D, 1 (y) of the particles' positions. In 3D a region is a
 * box (y_min..y_max, every y by default) and a probe's point is (x, y, z); a profile (x bins of a
 * section) is 2D only, which the case reader says (io/case.c). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "monitors.h"
#include "particle_fields.h"
#include "threshold_monitors.h"

#include "status.h"

/* A pressure probe on a wall reads 1.5 h from the wall into the fluid, the standoff of the
 * pressure points of DualSPHysics's dam-break example (0.9 - 0.8779 m = 1.5 h with its
 * h = sqrt(3) 0.0085 m), where the point's kernel support lies almost wholly on the fluid side
 * (a point on the wall itself has half its support in the wall and no fluid there). */
#define PROBE_WALL_STANDOFF_OVER_H 1.5
/* Kernel sum sum_j V_j W below which a probe is dry and reads 0 (DualSPHysics's MeasureTool:
 * -kclimit:0.5 -kcusedummy:0 in its examples): half of a full support's sum, 1. */
#define PROBE_WET_KERNEL_SUM 0.5

/* Diagnostics; the last two (the implicit viscous solve's) only with numerics.viscosity = "implicit". */
enum { OUT_KE, OUT_MASS, OUT_DT, OUT_LOST, OUT_CLIPS, OUT_VMAX, OUT_FIXED, OUT_EXCLUDED, OUT_EXCLUDED_M, OUT_EXCLUDED_E, OUT_FLOORED,
       OUT_VISC_ITER, OUT_VISC_RES, OUT_N_DIAG };
static const char *const diag_names[OUT_N_DIAG] = {"kinetic_energy", "mass", "dt", "lost_particles", "wall_corrections",
                                                   "max_speed", "fixed_particles", "excluded_particles",
                                                   "excluded_mass", "excluded_energy", "floored_particles", "viscous_iterations",
                                                   "viscous_residual"};
/* out_monitor[k] of diagnostic d */
#define OUT_DIAG_CODE(d) (-1 - (int)(d))

/* out_monitor[k] of a monitor output: the case monitor m plus CASE_MAX_MONITORS times the kind
 * of output (the monitor's value, its full-scale elevation, the error (13) of its maximum, its
 * further outputs OUTK_EXTRA + j: case_monitor_extras). */
enum { OUTK_VALUE = 0, OUTK_FULL_Z = 1, OUTK_FULL_ERR = 2, OUTK_EXTRA = 3 };
#define OUT_CODE(m, kind) ((int)(m) + CASE_MAX_MONITORS * (kind))

_Static_assert(OUT_N_DIAG + CASE_MAX_SCALAR_OUTPUTS <= SIM_MAX_OUTPUTS, "outputs do not fit in SIM_MAX_OUTPUTS");

/* Add the output <monitor m's name><suffix> of the given kind. */
static void out_add_named(mixsph_sim *s, int m, int kind, const char *suffix)
{
    char name[2 * CASE_NAME_LEN];
    const size_t a = strlen(s->cfg.monitors[m].name), b = strlen(suffix);
    memcpy(name, s->cfg.monitors[m].name, a);
    memcpy(name + a, suffix, b + 1);
    name[CASE_NAME_LEN - 1] = '\0'; /* never cut: case.c checked the length */
    s->out.monitor[s->out.n] = OUT_CODE(m, kind);
    memcpy(s->out.name[s->out.n++], name, CASE_NAME_LEN);
}

/* A probe's point (case input: x, z, and y in 3D) as a position. */
static void case_point(const struct monitor_def *md, double pos[DIM])
{
    for (int d = 0; d < DIM; d++) pos[d] = 0.0;
    pos[0] = md->point_x;
#if DIM == 3
    pos[1] = md->point_y;
#endif
    pos[DIM_UP] = md->point_z;
}

/* The position pos of particle i. */
static void position_of(const struct particles *P, size_t i, double pos[DIM])
{
    for (int d = 0; d < DIM; d++) pos[d] = P->pos[d][i];
}

/* The point a pressure probe reads at now [m]: its point in the flow; on a wall, the point of the
 * wall nearest to the sensor (both moved with the wall), moved into the fluid along the wall's
 * normal by the standoff. */
static void probe_point(const mixsph_sim *s, const struct monitor_def *md, double pos[DIM])
{
    case_point(md, pos);
    if (md->wall < 0) return;
    const struct walls *W = &s->phys.walls;
    for (int d = 0; d < DIM; d++) pos[d] += W->state[md->wall].o[d];
    double n[DIM];
    int at_end;
    const double dist = walls_distance(W, (size_t)md->wall, pos, &at_end); /* the sensor's distance from the wall */
    walls_normal(W, (size_t)md->wall, pos, n);
    const double move = PROBE_WALL_STANDOFF_OVER_H * s->phys.h - dist;
    for (int d = 0; d < DIM; d++) pos[d] += move * n[d];
}

/* The fluid's pressure at pos [Pa]: the Shepard-normalised kernel interpolation over the
 * non-wall particles (head of the file), 0 when dry. The candidates are those of the cell
 * list's stencil around the point: the cells describe the positions of the last build, and no
 * particle has moved skin/2 since, so every particle now within 2h of the point is in it. */
static double probe_pressure(const mixsph_sim *s, const double pos[DIM])
{
    const struct cells *C = &s->work.C;
    const struct particles *P = &s->phys.P;
    const struct kernel *K = &s->phys.K;
    for (int d = 0; d < DIM; d++)
        if (!(pos[d] >= C->lo[d])) return 0.0; /* a moving wall's probe carried off the grid */
    int c[DIM];
    cells_coords(C, pos, c);
    for (int d = 0; d < DIM; d++)
        if (c[d] >= C->n[d]) return 0.0;
    double sw = 0.0, swp = 0.0;
    for (int row = 0; row < CELLS_ROWS_AROUND; row++) {
        const struct range rg = cells_row(C, c, row);
        for (size_t j = rg.begin; j < rg.end; j++) {
            if (P->state[j] > MIXSPH_STATE_FIXED) continue;
            double r2 = 0.0;
            for (int d = 0; d < DIM; d++) r2 += (pos[d] - P->pos[d][j]) * (pos[d] - P->pos[d][j]);
            if (r2 >= K->r2max) continue;
            const double w = kernel_w(K, sqrt(r2)) * P->m[j] / P->rho[j];
            sw += w;
            swp += w * P->p[j];
        }
    }
    return sw >= PROBE_WET_KERNEL_SUM ? swp / sw : 0.0;
}

/* A pressure probe's definition against the simulation: a sensor lies on its wall, beside it
 * (not beyond an open end), and the point read lies inside the domain. */
static mixsph_status probe_check(mixsph_sim *s, const struct monitor_def *md)
{
    const struct case_def *c = &s->cfg;
    if (md->wall >= 0) {
        int at_end;
        const struct wall_state *ws = &s->phys.walls.state[md->wall]; /* the point is given at t = 0 */
        double sensor[DIM];
        case_point(md, sensor);
        for (int k = 0; k < DIM; k++) sensor[k] += ws->o[k];
        const double d = walls_distance(&s->phys.walls, (size_t)md->wall, sensor, &at_end);
        if (at_end || !(fabs(d) <= 0.5 * s->phys.dx))
            return SIM_FAIL(s, MIXSPH_ERR_CASE,
                            "%s: monitors.%s: the point (%g, %g) is not on the wall '%s' (%.3g m from it%s); a "
                            "pressure_probe with a wall is a sensor on it: its point within dx/2 = %g m of the wall",
                            c->origin, md->name, md->point_x, md->point_z, c->walls[md->wall].name, fabs(d),
                            at_end ? ", beyond its end" : "", 0.5 * s->phys.dx);
    }
    double pos[DIM];
    probe_point(s, md, pos);
    const double *dom = c->has_domain ? c->domain : s->phys.domain;
    int inside = 1;
    for (int d = 0; d < DIM; d++) inside &= pos[d] >= dom[2 * d] && pos[d] < dom[2 * d + 1];
    const double *dz = &dom[2 * DIM_UP];
    if (!inside)
        return SIM_FAIL(s, MIXSPH_ERR_CASE,
                        "%s: monitors.%s: the point the probe reads at, (%g, %g), is outside the domain [%g, %g] x "
                        "[%g, %g]", c->origin, md->name, pos[0], pos[DIM_UP], dom[0], dom[1], dz[0], dz[1]);
    return MIXSPH_OK;
}

mixsph_status monitors_init(mixsph_sim *s)
{
    for (size_t k = 0; k < s->cfg.n_monitors; k++)
        if (s->cfg.monitors[k].kind == MONITOR_PRESSURE_PROBE) {
            const mixsph_status st = probe_check(s, &s->cfg.monitors[k]);
            if (st != MIXSPH_OK) return st;
        }
    s->out.n = 0;
    const size_t n_diag = s->cfg.viscosity_implicit ? OUT_N_DIAG : OUT_VISC_ITER;
    for (size_t k = 0; k < n_diag; k++) {
        s->out.monitor[s->out.n] = OUT_DIAG_CODE(k);
        snprintf(s->out.name[s->out.n++], CASE_NAME_LEN, "%s", diag_names[k]);
    }
    for (size_t k = 0; k < s->cfg.n_monitors; k++) {
        s->out.profile_next[k] = 0;
        if (s->cfg.monitors[k].kind == MONITOR_PROFILE) continue;
        s->out.monitor[s->out.n] = OUT_CODE(k, OUTK_VALUE);
        snprintf(s->out.name[s->out.n++], CASE_NAME_LEN, "%s", s->cfg.monitors[k].name);
        const char *const *extra = case_monitor_extras(s->cfg.monitors[k].kind);
        for (int j = 0; extra[j]; j++) out_add_named(s, (int)k, OUTK_EXTRA + j, extra[j]);
    }
    /* case.c checked that the names fit and that there are at most CASE_MAX_SCALAR_OUTPUTS */
    const struct full_scale *fs = &s->cfg.full_scale;
    for (size_t k = 0; fs->on && k < s->cfg.n_monitors; k++)
        if (s->cfg.monitors[k].kind == MONITOR_MAX_ELEVATION) out_add_named(s, (int)k, OUTK_FULL_Z, CASE_FULL_SCALE_SUFFIX_Z);
    if (fs->on && fs->ref_monitor >= 0) out_add_named(s, fs->ref_monitor, OUTK_FULL_ERR, CASE_FULL_SCALE_SUFFIX_ERR);
    for (size_t k = 0; k < s->out.n; k++) {
        s->out.max[k] = s->out.min[k] = NAN;
        s->out.tmax[k] = s->out.tmin[k] = NAN;
    }
    s->out.n_samples = 0;
    return MIXSPH_OK;
}

/* |v|^2 of particle i */
static double speed2(const struct particles *P, size_t i)
{
    double v2 = 0.0;
    for (int d = 0; d < DIM; d++) v2 += P->vel[d][i] * P->vel[d][i];
    return v2;
}

/* Output `part` of a monitor: 0 its value, 1 + j its further output j (case_monitor_extras). */
static double monitor_eval(const mixsph_sim *s, const struct monitor_def *md, int part)
{
    const struct particles *P = &s->phys.P;
    double best = NAN;
    if (md->kind == MONITOR_RUNOUT) {
        double height;
        const double run = runout_position(s, md, &height);
        return part == 0 ? run : height;
    }
    if (md->kind == MONITOR_WAVE_GAUGE) return wave_gauge_elevation(s, md);
    if (md->kind == MONITOR_SPEED) return speed_quantile(s, md);
    if (md->kind == MONITOR_SLIDE_IMPACT) {
        double impact[IMPACT_N];
        return slide_impact_now(s, md, impact) ? impact[part] : NAN; /* parts in enum slide_impact_output order */
    }
    if (md->kind == MONITOR_WALL_PRESSURE) {
        for (size_t i = 0; i < P->n; i++) {
            if (P->state[i] != MIXSPH_STATE_WALL || P->medium[i] != md->wall || particles_is_image(P, i) ||
                !monitor_in_region(md, P, i))
                continue;
            int at_end;
            double pos[DIM];
            position_of(P, i, pos);
            const double d = walls_distance(&s->phys.walls, (size_t)md->wall, pos, &at_end);
            if (d < -s->phys.dx) continue; /* first layer only */
            if (isnan(best) || P->p[i] > best) best = P->p[i];
        }
        return best;
    }
    if (md->kind == MONITOR_WALL_WORK) return s->phys.walls.state[md->wall].work;
    if (md->kind == MONITOR_PRESSURE_PROBE) {
        double pos[DIM];
        probe_point(s, md, pos);
        return probe_pressure(s, pos);
    }
    if (md->kind == MONITOR_KINETIC_ENERGY) { /* sum of m |u|^2 / 2 over the medium in the region [J/m] */
        double e = 0.0;
        for (size_t i = 0; i < P->n; i++)
            if (P->state[i] <= MIXSPH_STATE_FIXED && P->medium[i] == md->medium && monitor_in_region(md, P, i))
                e += 0.5 * P->m[i] * speed2(P, i);
        return e;
    }
    for (size_t i = 0; i < P->n; i++) {
        if (!monitor_counts(md, P, i)) continue;
        const double v = md->kind == MONITOR_FRONT ? md->direction * P->pos[0][i] : P->pos[DIM_UP][i];
        if (isnan(best) || v > best) best = v;
    }
    if (md->kind == MONITOR_FRONT && !isnan(best)) best *= md->direction;
    return best;
}

/* Particles whose density sits at the floor m W(0) of a medium without tension (docs/numerics.md
 * 2d): grains alone, apart from the rest. */
static long floored_particles(const mixsph_sim *s)
{
    const struct particles *P = &s->phys.P;
    const double w0 = kernel_w(&s->phys.K, 0.0);
    long n = 0;
    for (size_t i = 0; i < P->n; i++)
        n += P->state[i] <= MIXSPH_STATE_FIXED && s->scheme.media[P->medium[i]].tension_cutoff &&
             P->rho[i] <= P->m[i] * w0;
    return n;
}

double monitors_value(const mixsph_sim *s, size_t k)
{
    const struct particles *P = &s->phys.P;
    if (s->out.monitor[k] >= 0) {
        const int m = s->out.monitor[k] % CASE_MAX_MONITORS, kind = s->out.monitor[k] / CASE_MAX_MONITORS;
        if (kind == OUTK_FULL_ERR) {
            /* the error (13) of the highest value so far of the monitor's own output */
            for (size_t j = 0; j < s->out.n; j++)
                if (s->out.monitor[j] == OUT_CODE(m, OUTK_VALUE))
                    return isnan(s->out.max[j]) ? NAN
                                                : case_full_scale_error(&s->cfg, case_full_scale_z(&s->cfg, s->out.max[j]));
            return NAN;
        }
        const struct monitor_def *md = &s->cfg.monitors[m];
        /* a slide's impact is taken once: its first values (the outputs' extremes, which a
         * checkpoint keeps) */
        if (md->kind == MONITOR_SLIDE_IMPACT && !isnan(s->out.max[k])) return s->out.max[k];
        const double v = monitor_eval(s, md, kind >= OUTK_EXTRA ? 1 + kind - OUTK_EXTRA : 0);
        return kind == OUTK_FULL_Z && !isnan(v) ? case_full_scale_z(&s->cfg, v) : v;
    }
    const int d = -1 - s->out.monitor[k];
    if (d == OUT_DT) return s->phys.dt;
    if (d == OUT_LOST) return (double)s->phys.n_lost;
    if (d == OUT_CLIPS) return (double)s->phys.n_clipped;
    if (d == OUT_FIXED) return (double)s->phys.n_fixed;
    if (d == OUT_EXCLUDED) return (double)s->phys.n_excluded;
    if (d == OUT_EXCLUDED_M) return s->phys.excluded_mass;
    if (d == OUT_EXCLUDED_E) return s->phys.excluded_energy;
    if (d == OUT_FLOORED) return (double)floored_particles(s);
    if (d == OUT_VISC_ITER) return (double)s->work.viscous_last.iterations;
    if (d == OUT_VISC_RES) return s->work.viscous_last.residual;
    double ke = 0.0, mass = 0.0, vmax = 0.0;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] > MIXSPH_STATE_FIXED) continue;
        const double v2 = speed2(P, i);
        ke += 0.5 * P->m[i] * v2;
        mass += P->m[i];
        if (v2 > vmax) vmax = v2;
    }
    return d == OUT_KE ? ke : d == OUT_MASS ? mass : sqrt(vmax);
}

mixsph_status monitors_open(mixsph_sim *s)
{
    char path[600];
    snprintf(path, sizeof path, "%s/monitors.csv", s->out.dir);
    s->out.monitor_csv = fopen(path, "w");
    if (!s->out.monitor_csv) return SIM_FAIL(s, MIXSPH_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
    fprintf(s->out.monitor_csv, "t,step");
    for (size_t k = 0; k < s->out.n; k++) fprintf(s->out.monitor_csv, ",%s", s->out.name[k]);
    fprintf(s->out.monitor_csv, "\n");
    fflush(s->out.monitor_csv);
    return MIXSPH_OK;
}

/* Write profile monitor md as <out_dir>/profile_<name>_<tag>.csv, taken now, requested at t_req. */
static mixsph_status profile_write(mixsph_sim *s, const struct monitor_def *md, const char *tag, double t_req,
                                   const char *note)
{
    const struct particles *P = &s->phys.P;
    const size_t nb = (size_t)case_profile_bin_count(md); /* >= 1, within output.max_profile_bins (budget.c) */
    double *top = malloc(nb * sizeof *top);
    if (!top) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory (profile)");
    for (size_t b = 0; b < nb; b++) top[b] = -INFINITY;
    for (size_t i = 0; i < P->n; i++) {
        if (!monitor_counts(md, P, i)) continue;
        size_t b = (size_t)((P->pos[0][i] - md->x_min) / md->bin);
        if (b >= nb) b = nb - 1;
        const double top_i = P->pos[DIM_UP][i] + 0.5 * s->phys.dx;
        if (top_i > top[b]) top[b] = top_i;
    }
    char path[700];
    snprintf(path, sizeof path, "%s/profile_%s_%s.csv", s->out.dir, md->name, tag);
    FILE *f = fopen(path, "w");
    if (!f) {
        free(top);
        return SIM_FAIL(s, MIXSPH_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
    }
    fprintf(f, "# profile %s of %s at t = %.9g s (requested %.9g s): top of the medium per x bin%s\nx,z_top\n",
            md->name, s->cfg.media[md->medium].name, s->phys.t, t_req, note);
    for (size_t b = 0; b < nb; b++) {
        fprintf(f, "%.7g,", md->x_min + (b + 0.5) * md->bin);
        if (isfinite(top[b])) fprintf(f, "%.7g\n", top[b]);
        else fprintf(f, "nan\n");
    }
    free(top);
    const int bad = ferror(f);
    if (fclose(f) != 0 || bad) return SIM_FAIL(s, MIXSPH_ERR_IO, "%s: write failed", path);
    return MIXSPH_OK;
}

/* Write the profiles that are due (needs an output folder). */
mixsph_status monitors_profiles(mixsph_sim *s)
{
    for (size_t k = 0; k < s->cfg.n_monitors; k++) {
        const struct monitor_def *md = &s->cfg.monitors[k];
        if (md->kind != MONITOR_PROFILE || s->out.profile_next[k] >= md->n_times || s->phys.t < md->times[s->out.profile_next[k]])
            continue;
        if (s->out.dir[0]) {
            char tag[32];
            snprintf(tag, sizeof tag, "%zu", s->out.profile_next[k]);
            mixsph_status st = profile_write(s, md, tag, md->times[s->out.profile_next[k]], "");
            if (st != MIXSPH_OK) return st;
        }
        s->out.profile_next[k]++;
    }
    return MIXSPH_OK;
}

/* Rewrite the at_max_of profiles of case monitor m, which has just reached a new maximum. */
static mixsph_status profiles_at_max(mixsph_sim *s, int m)
{
    for (size_t k = 0; s->out.dir[0] && k < s->cfg.n_monitors; k++) {
        const struct monitor_def *md = &s->cfg.monitors[k];
        if (md->kind != MONITOR_PROFILE || md->at_max_of != m) continue;
        char note[96];
        snprintf(note, sizeof note, ", at the maximum of %s so far", s->cfg.monitors[m].name);
        mixsph_status st = profile_write(s, md, "atmax", s->phys.t, note);
        if (st != MIXSPH_OK) return st;
    }
    return MIXSPH_OK;
}

mixsph_status monitors_sample(mixsph_sim *s)
{

    double v[SIM_MAX_OUTPUTS];
    for (size_t k = 0; k < s->out.n; k++) {
        v[k] = monitors_value(s, k);
        if (isnan(v[k])) continue;
        if (isnan(s->out.max[k]) || v[k] > s->out.max[k]) {
            s->out.max[k] = v[k];
            s->out.tmax[k] = s->phys.t;
            const int code = s->out.monitor[k];
            if (code >= 0 && code < CASE_MAX_MONITORS && s->cfg.monitors[code].kind == MONITOR_MAX_ELEVATION) {
                mixsph_status st = profiles_at_max(s, code);
                if (st != MIXSPH_OK) return st;
            }
        }
        if (isnan(s->out.min[k]) || v[k] < s->out.min[k]) {
            s->out.min[k] = v[k];
            s->out.tmin[k] = s->phys.t;
        }
    }
    s->out.n_samples++;
    if (s->out.monitor_csv) {
        fprintf(s->out.monitor_csv, "%.9g,%llu", s->phys.t, (unsigned long long)s->phys.step);
        for (size_t k = 0; k < s->out.n; k++) fprintf(s->out.monitor_csv, ",%.9g", v[k]);
        fprintf(s->out.monitor_csv, "\n");
        if (fflush(s->out.monitor_csv) != 0) return SIM_FAIL(s, MIXSPH_ERR_IO, "%s/monitors.csv: write failed", s->out.dir);
    }
    return MIXSPH_OK;
}

/* The fields of the CSV snapshots, in their column order: the PF_KEY rows of the particle-field
 * table first, then its other PF_CSV rows in table order (those the simulation has). */
static size_t csv_fields(const struct particles *P, const struct particle_field **out)
{
    size_t n = 0;
    for (unsigned key = 2; key-- > 0;)
        for (size_t k = 0; k < particle_field_count; k++) {
            const struct particle_field *f = &particle_fields[k];
            if ((f->where & PF_CSV) && !!(f->where & PF_KEY) == (int)key && particle_field_present(f, P->features))
                out[n++] = f;
        }
    return n;
}

/* A row is written in runs of values of one kind (doubles as "%.<digits>g", integers as %u), up to
 * CSV_RUN values per fprintf call (a call per value made the CSV snapshots of the dam break about
 * a fifth slower); a call passes CSV_RUN values whatever its format uses: C ignores the extra ones. */
enum { CSV_RUN = 16 };

struct csv_run {
    int integers;                        /* %u values (else doubles) */
    size_t n;                            /* values */
    const void *a[CSV_RUN];              /* their arrays */
    enum particle_field_type type[CSV_RUN];
    char fmt[CSV_RUN * 8 + 2];           /* "%.17g," is at most 7 characters; "\n" after the last */
};

static void csv_run_write(FILE *f, const struct csv_run *r, size_t i)
{
    if (r->integers) {
        unsigned u[CSV_RUN] = {0};
        for (size_t q = 0; q < r->n; q++)
            u[q] = r->type[q] == PF_U8    ? ((const uint8_t *)r->a[q])[i]
                   : r->type[q] == PF_U16 ? ((const uint16_t *)r->a[q])[i]
                                          : ((const uint32_t *)r->a[q])[i];
        fprintf(f, r->fmt, u[0], u[1], u[2], u[3], u[4], u[5], u[6], u[7], u[8], u[9], u[10], u[11], u[12], u[13], u[14],
                u[15]);
    } else {
        double v[CSV_RUN] = {0};
        for (size_t q = 0; q < r->n; q++) v[q] = ((const double *)r->a[q])[i];
        fprintf(f, r->fmt, v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9], v[10], v[11], v[12], v[13], v[14],
                v[15]);
    }
}

/* Particle snapshot as CSV (snap_NNNN.csv): a line "# t = T s", a header of the column names,
 * one row per particle, walls included. */
mixsph_status monitors_snapshot(mixsph_sim *s)
{
    char path[600];
    snprintf(path, sizeof path, "%s/snap_%04d.csv", s->out.dir, s->out.snap_index);
    const struct particles *P = &s->phys.P;
    const struct particle_field *cols[64];
    if (particle_field_count > 64) return SIM_FAIL(s, MIXSPH_ERR_ARG, "%s: more particle fields than 64", path);
    const size_t nc = csv_fields(P, cols);
    size_t nv = 0, nr = 0;
    for (size_t c = 0; c < nc; c++) nv += cols[c]->components;
    struct csv_run *runs = calloc(nv ? nv : 1, sizeof *runs); /* at most one run per value */
    if (!runs) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory");
    nv = 0;
    for (size_t c = 0; c < nc; c++)
        for (unsigned k = 0; k < cols[c]->components; k++, nv++) {
            const int integers = cols[c]->type != PF_F64;
            if (nr == 0 || runs[nr - 1].integers != integers || runs[nr - 1].n == CSV_RUN)
                runs[nr++] = (struct csv_run){.integers = integers};
            struct csv_run *r = &runs[nr - 1];
            r->a[r->n] = particles_array(P, cols[c]->member[k]);
            r->type[r->n++] = cols[c]->type;
            const size_t len = strlen(r->fmt);
            if (integers) snprintf(r->fmt + len, sizeof r->fmt - len, "%s%%u", nv ? "," : "");
            else snprintf(r->fmt + len, sizeof r->fmt - len, "%s%%.%dg", nv ? "," : "", cols[c]->csv_digits);
        }
    if (nr) strcat(runs[nr - 1].fmt, "\n");
    FILE *f = fopen(path, "w");
    if (!f) {
        free(runs);
        return SIM_FAIL(s, MIXSPH_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
    }
    fprintf(f, "# t = %.9g s\n", s->phys.t);
    for (size_t c = 0; c < nc; c++) fprintf(f, "%s%s", c ? "," : "", cols[c]->columns);
    fputc('\n', f);
    for (size_t i = 0; i < P->n; i++)
        for (size_t q = 0; q < nr; q++) csv_run_write(f, &runs[q], i);
    free(runs);
    const int bad = ferror(f);
    if (fclose(f) != 0 || bad) return SIM_FAIL(s, MIXSPH_ERR_IO, "%s: write failed", path);
    s->out.snap_index++;
    return MIXSPH_OK;
}
