/* case.h - the case definition: media, bodies, walls, motion laws, numerics, monitors, output;
 * read from a JSON case file (cJSON) with numeric key=value overrides, and validated.
 * Every error names the file, the key and what was expected. */
#ifndef MIXSPH_CASE_H
#define MIXSPH_CASE_H
#include <stddef.h>
#include "geometry.h"
#include "medium.h"
#include "mixsph.h"
#include "numerics_keys.h"
#include "wall_def.h"

#define CASE_NAME_LEN MEDIUM_NAME_LEN /* names of all entries */
#define CASE_MAX_MEDIA 8
_Static_assert(CASE_MAX_MEDIA <= WALL_MEDIA_MAX, "a wall's friction per medium holds every medium of a case");
#define CASE_MAX_BODIES 16
#define CASE_MAX_WALLS WALLS_MAX
#define CASE_MAX_MOTIONS 8
#define CASE_MAX_MONITORS 16

#define CASE_PATH_LEN 512
/* The shape of a body: a 2D case's bodies are polygons; a 3D case's one of these. */
enum body_shape {
    BODY_POLYGON = 0,     /* 2D: the polygon; 3D: the polygon extruded across y_min <= y <= y_max */
    BODY_BOX = 1,         /* 3D: the box box_min <= p <= box_max */
    BODY_STL = 2,         /* 3D: the inside of a closed STL surface */
    BODY_BELOW_LEVEL = 3  /* 3D: the domain between z_min and z_max, minus what the walls block */
};
struct body {
    char name[CASE_NAME_LEN];
    int medium;               /* index into media */
    int shape;                /* enum body_shape */
    struct polyline polygon;  /* closed implicitly [m] */
    double z_min, z_max;      /* the body is clipped to z_min <= z <= z_max [m] */
    double y_min, y_max;      /* 3D polygon: its extrusion across y [m] */
    double box_min[3], box_max[3]; /* 3D box: opposite corners (x, y, z) [m] */
    char stl[CASE_PATH_LEN];  /* 3D STL: the file, a relative path resolved against the case file's folder */
};

#define CASE_MAX_PROFILE_TIMES 16

enum monitor_kind {
    MONITOR_FRONT = 0,
    MONITOR_MAX_ELEVATION = 1,
    MONITOR_PROFILE = 2,
    MONITOR_WALL_PRESSURE = 3,
    MONITOR_KINETIC_ENERGY = 4,
    MONITOR_WALL_WORK = 5,
    MONITOR_PRESSURE_PROBE = 6,
    MONITOR_RUNOUT = 7,       /* threshold monitors (monitors.c) */
    MONITOR_WAVE_GAUGE = 8,
    MONITOR_SLIDE_IMPACT = 9,
    MONITOR_SPEED = 10
};

struct monitor_def {
    char name[CASE_NAME_LEN];
    int kind;                 /* enum monitor_kind */
    int medium;               /* index into media (-1 for wall_pressure, wall_work and pressure_probe) */
    int wall;                 /* wall_pressure, wall_work: index into walls; pressure_probe: the wall the
                                 sensor (point_x, point_z) sits on, -1 for a point in the flow */
    double point_x, point_z;  /* pressure_probe: the point [m] (on a wall: the sensor, at t = 0) */
    double point_y;           /* pressure_probe in 3D: the point's y [m] */
    int direction;            /* front, runout: +1 largest x, -1 smallest x; slide_impact: the ramp descends
                                 towards +x (+1) or -x (-1) */
    double x_min, x_max;      /* region [m] (infinite when not given) */
    double z_min, z_max;
    double y_min, y_max;      /* 3D: the region across y [m] (infinite when not given) */
    int min_neighbours;       /* particles with fewer same-medium neighbours are spray, ignored */
    double bin;               /* profile, runout: bin (column) width [m] */
    double threshold;         /* runout: a column belongs to the deposit when it is at least this thick [m] */
    double still;             /* wave_gauge, slide_impact: the still water level (z) [m] */
    double window;            /* wave_gauge: half-width of the gauge's window around point_x [m] */
    double angle;             /* slide_impact: the ramp's angle to the horizontal [deg] */
    double quantile;          /* speed: the quantile of the medium's particle speeds, in (0, 1] */
    size_t n_times;           /* profile: times at which it is written [s] */
    double times[CASE_MAX_PROFILE_TIMES];
    int at_max_of;            /* profile: max_elevation monitor at whose every new maximum the profile is
                                 rewritten (profile_<name>_atmax.csv), -1 for none */
};

/* Scalar outputs that the case's monitors may add (the scalar monitors, the further outputs of
 * the monitors that have several, and the full-scale outputs below); monitors.c adds its
 * diagnostics and checks that all fit in SIM_MAX_OUTPUTS. */
#define CASE_MAX_SCALAR_OUTPUTS (2 * CASE_MAX_MONITORS + 1)
/* A monitor's further outputs <name><suffix> beyond its own <name> (runout: the deposit's
 * height; slide_impact: the slide's speed, thickness and mass at the impact) */
#define CASE_MAX_MONITOR_EXTRAS 3
#define CASE_FULL_SCALE_SUFFIX_Z "_Z"        /* output <m>_Z: full-scale elevation of monitor m */
#define CASE_FULL_SCALE_SUFFIX_ERR "_d_eta"  /* output <m>_d_eta: error (13) [%] of its highest value */

/* Optional full-scale report: an affine map from a lab elevation z [m] to a full-scale elevation
 * Z = z_scale z + z_offset (e.g. metres a.m.s.l.; Vajont: Z = 1211.8 z + 0.3, fitted to Manenti
 * et al. 2018, Table 5). Every max_elevation monitor <m> gets the output <m>_Z; the reference
 * monitor also gets <m>_d_eta, the paper's error (13) of its highest value so far,
 * 100 |Z_max - observed| / (observed - still) [%]. */
struct full_scale {
    int on;
    double z_scale;           /* [full-scale unit per m], > 0 */
    double z_offset;          /* [full-scale unit] */
    char unit[CASE_NAME_LEN]; /* e.g. "m a.m.s.l." (for reports) */
    int ref_monitor;          /* index into monitors (a max_elevation monitor), -1 for no reference */
    double observed;          /* observed highest elevation Z_exp [full-scale unit] */
    double still;             /* still-water elevation Z_still [full-scale unit] of the error (13) */
};

struct case_def {
    char origin[256];         /* file name, for messages */
    char name[CASE_NAME_LEN];
    int dimensions;           /* 2 or 3: the case's space (the build's DIM must equal it) */
    double g;                 /* gravity magnitude [m/s2], acting along -z */
    /* every key of `numerics`, as the member its row names (core/numerics_keys.def: what each
     * holds, its unit and who reads it) */
#define NUMERICS_KEY NUMERICS_MEMBER_OF_CASE
#include "numerics_keys.def"
#undef NUMERICS_KEY
    int has_domain;
    double domain[2 * DIM];   /* bounds along axis d: domain[2 d] .. domain[2 d + 1] [m] (the case gives x and
                                 z: x_min, x_max, z_min, z_max in 2D); particles leaving it are lost */
    double domain_y[2];       /* the domain's y_min, y_max as read (3D; copied into domain) [m] */
    double monitor_interval;  /* [s] */
    double snapshot_interval; /* [s], 0 = none */
    /* the resource budget (budget.h) beyond numerics.max_*: limits on what the case asks for,
     * checked from the case alone before anything is allocated */
    double max_monitor_rows;    /* rows of monitors.csv [-] */
    double max_profile_bins;    /* bins of one profile monitor [-] */
    double max_snapshot_bytes;  /* bytes of all particle snapshots (CSV and HDF5) [B] */
    size_t n_media, n_bodies, n_walls, n_motions, n_monitors;
    struct medium media[CASE_MAX_MEDIA];
    struct body bodies[CASE_MAX_BODIES];
    struct wall walls[CASE_MAX_WALLS];
    struct motion motions[CASE_MAX_MOTIONS];
    struct monitor_def monitors[CASE_MAX_MONITORS];
    struct full_scale full_scale;
};

/** Read and validate a case from JSON text; `origin` names it in messages. */
mixsph_status case_parse(const char *json_text, const char *origin, const mixsph_override *ov,
                         size_t n_ov, struct case_def *c, char *err, size_t err_len);

/** Read a whole file into a NUL-terminated buffer (caller frees). */
mixsph_status case_read_file(const char *path, char **text, char *err, size_t err_len);

void case_free(struct case_def *c);

/** The value a case gives a numeric key of its top level, `numerics` or `output` ("numerics.cfl",
 *  "t_end"...: the file's, an override's or the default; a choice as its value). MIXSPH_ERR_ARG,
 *  with a message, for any other key. */
mixsph_status case_number(const struct case_def *c, const char *key, double *value, char *err, size_t err_len);

/** The suffixes of the further outputs <name><suffix> of a monitor of this kind (NULL-terminated;
 *  empty for a monitor with one output). */
const char *const *case_monitor_extras(int kind);

/** Full-scale elevation of a lab elevation z [m] (the case's full_scale map; z itself without one). */
double case_full_scale_z(const struct case_def *c, double z);
/** The error (13) [%] of a full-scale elevation Z against the case's reference (NAN without one). */
double case_full_scale_error(const struct case_def *c, double Z);

/** Number of x bins of a profile monitor: ceil(width / bin), at least 1 (not finite when the
 *  bin is too small to count them; the budget refuses that). */
double case_profile_bin_count(const struct monitor_def *md);

#endif
