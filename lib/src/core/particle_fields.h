/* particle_fields.h - the particle-field table: one row per field of struct particles (its
 * name in files, unit, components, element type, owner, the simulation features it needs and
 * where it goes). Allocation, growth, permutation, copy, saved states and checkpoints, run.h5 and
 * run.xdmf, the CSV snapshots, the public field view and (through the files) the Python readers
 * all walk this table; none of them lists fields of its own.
 *
 * Adding a field: one member in struct particles (particles.h), one row in particle_fields.c.
 * See "How to add a particle field" in docs/development.md. */
#ifndef MIXSPH_PARTICLE_FIELDS_H
#define MIXSPH_PARTICLE_FIELDS_H
#include <stddef.h>

#include "dim.h"

#define PARTICLE_FIELD_MAX_COMPONENTS 6 /* a symmetric tensor in 3D */

/* Element types (sizes 8, 1, 2, 4 bytes). */
enum particle_field_type { PF_F64, PF_U8, PF_U16, PF_U32 };

/* Who owns a field: writes it and gives it its meaning. */
enum particle_field_owner { PF_OWNER_CORE, PF_OWNER_SCHEME, PF_OWNER_LAW };

/* Where a field goes (bits of .where). */
enum {
    PF_STATE = 1u << 0,    /* saved in states and checkpoints (mixsph_sim_save_state) */
    PF_HDF5 = 1u << 1,     /* a dataset of every run.h5 snapshot and an attribute of run.xdmf */
    PF_CSV = 1u << 2,      /* columns of snap_NNNN.csv (named by .columns) */
    PF_VIEW = 1u << 3,     /* in the public view (mixsph_sim_particle_field) */
    PF_GEOMETRY = 1u << 4, /* the points of run.xdmf (its Geometry, not an Attribute) */
    PF_KEY = 1u << 5       /* the particle's key: the first column(s) of every CSV row */
};

/* Features of a simulation a field may need (bits of .needs and of struct particles' features):
 * a row whose needs are not all among a simulation's features is absent from it (no memory, no
 * file, no state). */
enum {
    PARTICLE_FEATURE_IMPLICIT_VISCOUS = 1u << 0, /* numerics.viscosity = "implicit" (viscous.h) */
    PARTICLE_FEATURE_STRESS = 1u << 1,           /* a medium's law carries a stress (laws/law.h) */
    PARTICLE_FEATURE_BED_FRICTION = 1u << 2,     /* walls' Coulomb friction on grains (sim.c bed_friction_on) */
    PARTICLE_FEATURE_WALL_NORMAL = 1u << 3,      /* a free-slip wall or a stress to mirror (walls_set_normals) */
    PARTICLE_FEATURE_MIRROR_SIDES = 1u << 4      /* 3D mirror side walls: images of particles (mirror_sides.h) */
};

struct particle_field {
    const char *name;        /* the field's name in run.h5 (dataset), run.xdmf and the view */
    const char *columns;     /* its components' names, comma-separated: CSV columns ("x,z") */
    const char *unit;        /* SI unit as written in files ("1" for counts and indices) */
    const char *description; /* the HDF5 dataset's description attribute */
    enum particle_field_type type;
    enum particle_field_owner owner;
    unsigned components;     /* 1..PARTICLE_FIELD_MAX_COMPONENTS; rank 2 (n, components) in run.h5 if > 1 */
    unsigned needs;          /* PARTICLE_FEATURE_* bits; 0: every simulation */
    unsigned where;          /* PF_STATE, PF_HDF5, ... bits */
    int csv_digits;          /* significant digits of a F64 value in the CSV (%.*g) */
    unsigned y_odd;          /* bit c: component c (F64) changes sign under a reflection across a plane
                              * y = const (a vector's y, a tensor's xy and yz; 3D only): an image
                              * across a mirror side wall takes it reversed (mirror_sides.h) */
    size_t member[PARTICLE_FIELD_MAX_COMPONENTS]; /* offsetof(struct particles, array) per component */
};

/** The table (particle_field_count rows, in the order files list them). */
extern const struct particle_field particle_fields[];
extern const size_t particle_field_count;

/** Bytes of one element of a field of type t. */
size_t particle_field_size(enum particle_field_type t);

/** Whether field f exists in a simulation with these features. */
static inline int particle_field_present(const struct particle_field *f, unsigned features)
{
    return (f->needs & ~features) == 0;
}

/** "core", "scheme" or "law". */
const char *particle_field_owner_name(enum particle_field_owner o);

/** Component c of f's column names (into buf, "" past the last). */
const char *particle_field_column(const struct particle_field *f, unsigned c, char *buf, size_t len);

#endif
