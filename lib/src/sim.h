/* sim.h - the simulation object (internal definition of the opaque mixsph_sim). It owns all
 * state: the case, the particles, the cell list, the walls' motion, the outputs and files. */
#ifndef MIXSPH_SIM_H
#define MIXSPH_SIM_H
#include <stdint.h>
#include <stdio.h>

#include "case.h"
#include "cells.h"
#include "kernel.h"
#include "mixsph.h"
#include "neighbours.h"
#include "particles.h"

#ifdef _OPENMP
#include <omp.h>
#define SIM_THREADS(s) ((s)->n_threads > 0 ? (s)->n_threads : omp_get_max_threads())
#else
#define SIM_THREADS(s) 1
#endif

/* Cell columns per neighbour-search radius (cells.c, neighbours.c). */
#ifndef SIM_CELL_COLUMNS
#define SIM_CELL_COLUMNS 4
#endif

#define SIM_MAX_OUTPUTS (8 + CASE_MAX_MONITORS)

struct wall_state {
    double ox, oz;   /* displacement of the wall since t = 0 [m] */
    double vx, vz;   /* current velocity [m/s] */
    double ax, az;   /* current acceleration [m/s2] */
    int ext;         /* driven by an external velocity (ext_vx, ext_vz) instead of its motion law */
    double ext_vx, ext_vz; /* [m/s] */
};

/* Per-step scratch of the granular strain rate (not permuted: filled and used within a step). */
struct kinematics {
    double *gux, *guz, *gwx, *gwz; /* uncorrected velocity gradient du/dx, du/dz, dw/dx, dw/dz [1/s] */
    double *lxx, *lxz, *lzz;       /* correction matrix L (symmetric) [-] */
    double *ztop;                  /* per x-bin of width dx: top of the saturated granular column [m] */
    size_t nbins;
    /* numerics.fixed_bed_speed >= 0 (SPHERA's fixed bed, mixture.c): per column 2h wide, the
     * highest granular particle no faster than that speed (bed_ref, -1 for none) and its z [m] */
    double *bed_z;
    long *bed_ref;
    size_t nbed;
};

struct mixsph_sim {
    struct case_def cfg;
    /* what the simulation was created from (kept for state save/restore and metadata) */
    char *case_text, *case_origin;
    size_t n_ov;
    char **ov_key;
    double *ov_value;
    struct kernel K;
    double dx, h;
    double c_max;                 /* highest sound speed [m/s] */
    double domain[4];             /* x_min, x_max, z_min, z_max [m] */
    struct particles P;
    struct cells C;
    struct neighbours NB;         /* Verlet lists of the pair loops (skin NB.skin) */
    struct gather G;              /* gather lists: grains (all neighbours), walls (non-wall ones) */
    uint8_t *near_wall;           /* per particle: may reach a wall before the next list build */
    double *fk;                   /* kernel factors of the pair lanes, continuity -> momentum pass (forces.c) */
    size_t *fk_off, fk_cap, fk_off_cap;
    int fk_valid;                 /* fk holds this step's factors (set by the continuity pass, used once) */
    size_t n_fluid, n_wall;       /* fluid/granular and wall particles */
    struct wall_state walls[CASE_MAX_WALLS];
    int has_granular;             /* any granular medium: strain rates and regimes every step */
    struct kinematics kin;
    long n_fixed;                 /* granular particles held fixed after the last step */

    double t, dt;                 /* time, next time step [s] */
    uint64_t step;
    int n_threads;
    long n_lost;                  /* particles that left the domain */
    long n_clipped;               /* wall-crossing corrections applied (diagnostic) */

    /* outputs: diagnostics then the case's monitors */
    size_t n_out;
    char out_name[SIM_MAX_OUTPUTS][CASE_NAME_LEN];
    int out_monitor[SIM_MAX_OUTPUTS];             /* case monitor behind output k, -1 for diagnostics */
    size_t profile_next[CASE_MAX_MONITORS];       /* profile monitors: next time to write */
    double out_max[SIM_MAX_OUTPUTS], out_tmax[SIM_MAX_OUTPUTS];
    double out_min[SIM_MAX_OUTPUTS], out_tmin[SIM_MAX_OUTPUTS];
    long n_samples;
    double next_sample, next_snapshot;
    int snap_index;
    char out_dir[512];
    FILE *monitor_csv;
    struct output *h5;            /* run.h5 and run.xdmf (output.c); NULL without an output folder */
    double out_seconds[3];        /* wall time writing CSV snapshots, HDF5 snapshots, checkpoints [s] */
    double run_wall_s;            /* wall time stepping this run since t = 0, incl. before a restart [s] */
    int csv_snapshots_off;        /* no snap_NNNN.csv (run.h5 only) */

    char err[1024];
};

/* state.c */
int state_same_case(const mixsph_sim *s, const char *text, const char *const *keys, const double *values, size_t n_ov);

/* walls.c */
mixsph_status walls_generate(mixsph_sim *s);
void walls_signed_distance(const mixsph_sim *s, size_t w, double x, double z, double *d, int *at_end);
void walls_move(mixsph_sim *s, double t_from, double dt);
void walls_clip(const mixsph_sim *s, const double *ox_old, const double *oz_old, double x0, double z0,
                double *x1, double *z1, double *vx, double *vz, long *clips);
void walls_pressure(mixsph_sim *s);

/* sim.c: monotonic wall clock [s] */
double sim_clock_s(void);

/* forces.c */
int forces_compute(mixsph_sim *s);
int forces_continuity(mixsph_sim *s);
void forces_smooth_pressure(mixsph_sim *s);
void forces_pair_for_test(mixsph_sim *s, size_t i, size_t j, double *ax, double *az, double *drho);

/* mixture.c */
mixsph_status mixture_alloc(mixsph_sim *s);
void mixture_free(mixsph_sim *s);
void mixture_update(mixsph_sim *s);

/* integrate.c */
mixsph_status integrate_rebuild(mixsph_sim *s);
mixsph_status integrate_gather(mixsph_sim *s);
double integrate_time_step(const mixsph_sim *s);
mixsph_status integrate_step(mixsph_sim *s);
void integrate_eos(mixsph_sim *s);

/* monitors.c */
void monitors_init(mixsph_sim *s);
double monitors_value(const mixsph_sim *s, size_t k);
mixsph_status monitors_sample(mixsph_sim *s);
mixsph_status monitors_profiles(mixsph_sim *s);
mixsph_status monitors_open(mixsph_sim *s);
mixsph_status monitors_snapshot(mixsph_sim *s);

#define SIM_FAIL(s, st, ...) status_set((s)->err, sizeof (s)->err, (st), __VA_ARGS__)

#endif
