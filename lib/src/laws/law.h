/* law.h - the seam of the material laws. A law is one module under laws/ that fills one
 * `struct material_law`: its case keys (the rows of media.<name> of its type), the rules between
 * them and the values it derives once (finish), the per-particle state it declares (the fields of
 * struct particles its features name), a per-step update that is given dt and the velocity
 * gradient, its bounds on the time step, and what it hands the momentum pass: the per-particle
 * viscosity P->mu (the Morris Laplacian of a pairwise viscosity) and, with LAW_HAS_STRESS, the
 * deviatoric stress (P->stress), whose divergence the momentum pass adds in one symmetric pair
 * term (passes/forces.c). What else it asks of the step it declares as data: its feature bits
 * (enum law_feature, medium.h) and, for a law that holds particles, how a held particle is
 * integrated (struct medium's held_takes_kicks, held_viscosity, set by its finish); the step reads
 * these and never a law's id. Adding a
 * law: its module, one line in law_registry.c, an entry in enum law_id (medium.h) and its tests
 * (docs/development.md). */
#ifndef MIXSPH_LAW_H
#define MIXSPH_LAW_H
#include <stddef.h>

#include "kernel.h"
#include "medium.h"
#include "mixsph.h"
#include "neighbours.h"
#include "particles.h"
#include "schema.h"
#include "velocity_gradient.h"

/* What finish is given: the media read so far (this one last) and how to ask whether the case's
 * entry gives a key (rules such as "mu1 or mu_thr"), and where a message goes. */
struct law_finish_ctx {
    const struct medium *media;
    size_t n_media;
    int (*given)(const void *entry, const char *key);
    const char *(*text)(const void *entry, const char *key);  /* a string key's value, NULL if absent */
    double (*number)(const void *entry, const char *key);     /* a number key's value (checked by its row) */
    const void *entry;
    const char *origin, *path; /* for messages: "<origin>: <path>.<key>: ..." */
    char *err;
    size_t err_len;
};

/* What a law's state is created from: the simulation's fixed parameters, built once. */
struct law_setup {
    const struct medium *media;
    size_t n_media;
    size_t cap;                 /* particles */
    double x_min, x_max;        /* the domain's x range [m] */
    double dx, h;               /* spacing and smoothing length [m] */
    double g;                   /* gravity [m/s2] along -z */
    double p_background;        /* the equation of state's background pressure [Pa] */
    double fixed_bed_speed;     /* the paper law's fixed bed (numerics.fixed_bed_speed; < 0: off) */
};

/* What an update is given, every step after the equation of state and before the momentum pass. */
struct law_step {
    struct particles *P;
    size_t n;                                /* the active particles (sorted by cell) */
    const struct medium *media;
    const struct velocity_gradient *grad;    /* this step's, for the particles of LAW_USES_GRADIENT media */
    const struct gather *G;                  /* gather ranges (all neighbours of those particles) */
    const struct kernel *K;
    double dt;                               /* the step the state advances over [s]; 0: no advance */
    double p_background;                     /* the equation of state's background pressure [Pa] */
    int n_threads;
};

/* The laws of type "granular": the choices of media.<name>.law, a row of each of their key tables
 * (the first, the paper's, is the default). A number chooses by place in this list (0 paper, 1
 * elastic_plastic), so that a case parameter can choose the law (the FMU's `rheology`). */
static const struct case_choice law_granular_choices[] = {
    {"paper", LAW_MIXTURE_PAPER}, {"elastic_plastic", LAW_ELASTIC_PLASTIC}, {NULL, 0}};

struct material_law {
    const char *type;                 /* media.<name>.type that selects it */
    const char *name;                 /* media.<name>.law among the laws of one type (the first
                                         registered is the type's default) */
    const struct case_section *keys;  /* its keys: the section media.<type> */
    unsigned features;                /* enum law_feature */
    /** Rules between its keys and the values it derives (after the keys are read); a message
     *  naming the key on error (MIXSPH_ERR_CASE). */
    mixsph_status (*finish)(struct medium *m, const struct law_finish_ctx *ctx);
    /** The fastest wave of the medium [m/s]: the acoustic bound of the time step (4) takes the
     *  largest over the media. */
    double (*wave_speed)(const struct medium *m);
    /** The largest viscosity [Pa s] of its particles in the explicit viscous bound of (4), for
     *  estimates made before a run (the resource budget). */
    double (*viscosity_bound)(const struct medium *m);
    /** The pressure [Pa] a particle is created with, given the hydrostatic pressure of the column
     *  above it (NULL: that one, the fluids' and the paper's grains' start). */
    double (*initial_pressure)(const struct medium *m, double p_hydrostatic);
    /** Its state for one simulation (NULL members: the law has none); NULL when out of memory. */
    void *(*create)(const struct law_setup *setup);
    void (*destroy)(void *state);
    /** The per-step update of its particles; returns the particles it holds fixed (a law with
     *  LAW_HOLDS_PARTICLES), 0 otherwise. */
    long (*update)(void *state, const struct law_step *step);
};

#endif
