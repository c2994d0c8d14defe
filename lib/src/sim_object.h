/* sim_object.h - the simulation object (the internal definition of the opaque mixsph_sim): the
 * case it was made from and the schemes' parameters set from it, the physical state, the
 * solver's workspaces and the output schedule. A definition only: the
 * schemes (schemes/), the outputs (io/monitors.c, io/output.c) and the state (io/state.c) work on
 * it; the laws, passes and walls do not see it (they take the parts they need); sim.c, on top,
 * creates and drives it. */
#ifndef MIXSPH_SIM_OBJECT_H
#define MIXSPH_SIM_OBJECT_H
#include <stdint.h>
#include <stdio.h>

#include "case.h"
#include "cells.h"
#include "forces.h"
#include "kernel.h"
#include "mixsph.h"
#include "law.h"
#include "mirror_sides.h"
#include "neighbours.h"
#include "particles.h"
#include "scheme_params.h"
#include "viscous.h"
#include "walls.h"

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

#define SIM_MAX_OUTPUTS (14 + CASE_MAX_SCALAR_OUTPUTS)

/* The physical state: what a state file or a checkpoint restores (io/state.c). */
struct sim_physics {
    struct kernel K;
    double dx, h;
    double c_max;                 /* highest sound speed [m/s] */
    double domain[2 * DIM];       /* bounds along axis d: domain[2 d] .. domain[2 d + 1] (x_min, x_max, z_min, z_max in 2D) [m] */
    struct particles P;
    size_t n_fluid, n_wall;       /* fluid/granular and wall particles */
    struct walls walls;           /* the walls' definitions and moving states */
    void *law_state[LAW_COUNT];   /* each material law's state (laws/law.h); NULL: stateless or unused */
    unsigned law_features;        /* the union of the media's law features (enum law_feature) */
    long n_fixed;                 /* granular particles held fixed after the last step */
    double t, dt;                 /* time, next time step [s] */
    uint64_t step;
    long n_lost;                  /* particles that left the domain */
    long n_clipped;               /* wall-crossing corrections applied (diagnostic) */
    long n_excluded;              /* particles excluded for a density beyond numerics.density_bound */
    double excluded_mass;         /* their mass [kg/m] */
    double excluded_energy;       /* their kinetic + potential energy (m g z, from z = 0) when excluded [J/m] */
};

/* The solver's workspaces: rebuilt from the physical state, never saved. */
struct sim_workspace {
    struct cells C;
    struct neighbours NB;         /* Verlet lists of the pair loops (skin NB.skin) */
    struct gather G;              /* gather lists: grains (all neighbours), walls (non-wall ones) */
    uint8_t *near_wall;           /* per particle: may reach a wall before the next list build */
    uint8_t *excluding;           /* per particle: its density left the bound in this step */
    struct forces *forces;        /* the pair loops' cache and scratch */
    struct velocity_gradient grad; /* per particle, gathered every step when a law asks for it */
    struct viscous_solver *viscous; /* numerics.viscosity = "implicit": the solver's workspace */
    struct wall_mirror *wall_mirror; /* the walls in the implicit viscous step (walls.h) */
    struct mirror_sides mirror;   /* 3D mirror side walls: the planes and their images (mirror_sides.h) */
    unsigned char *viscous_unknown; /* per particle: an unknown of the implicit viscous step */
    struct viscous_report viscous_last; /* the last solve */
    uint64_t viscous_iterations;  /* iterations of all solves so far (their mean is a diagnostic) */
    double viscous_wall_s;        /* wall time in the implicit viscous step in this process [s] */
};

/* The output schedule and files (io/monitors.c, io/output.c): diagnostics, then the case's
 * monitors, and the snapshots. */
struct sim_outputs {
    size_t n;
    char name[SIM_MAX_OUTPUTS][CASE_NAME_LEN];
    int monitor[SIM_MAX_OUTPUTS];                 /* case monitor behind output k, -1 for diagnostics */
    size_t profile_next[CASE_MAX_MONITORS];       /* profile monitors: next time to write */
    double max[SIM_MAX_OUTPUTS], tmax[SIM_MAX_OUTPUTS];
    double min[SIM_MAX_OUTPUTS], tmin[SIM_MAX_OUTPUTS];
    long n_samples;
    double next_sample, next_snapshot;
    int snap_index;
    char dir[512];
    FILE *monitor_csv;
    struct output *h5;            /* run.h5 and run.xdmf (output.c); NULL without an output folder */
    double seconds[3];            /* wall time writing CSV snapshots, HDF5 snapshots, checkpoints [s] */
    double run_wall_s;            /* wall time stepping this run since t = 0, incl. before a restart [s] */
    int csv_snapshots_off;        /* no snap_NNNN.csv (run.h5 only) */
};

struct mixsph_sim {
    struct case_def cfg;          /* read when the simulation is created and by the outputs, not by a step */
    /* what the simulation was created from (kept for state save/restore and metadata) */
    char *case_text, *case_origin;
    size_t n_ov;
    char **ov_key;
    double *ov_value;
    struct scheme_params scheme;  /* what a step reads, set once from cfg */
    struct sim_physics phys;
    struct sim_workspace work;
    struct sim_outputs out;
    int n_threads;
    mixsph_interrupt interrupt;   /* the host's request to stop, polled during creation and stepping */
    char err[1024];
};

/* Keep a message in the simulation and return its status. */
#define SIM_FAIL(s, st, ...) status_set((s)->err, sizeof (s)->err, (st), __VA_ARGS__)

/** Has the host asked to stop (mixsph_interrupt)? */
static inline int sim_interrupted(const mixsph_sim *s)
{
    return s->interrupt.requested && s->interrupt.requested(s->interrupt.user);
}

#endif
