/* case_schema.c - the key tables of a case file and the table-driven reading of one section.
 * Each table row says what a key is (type, range, default, unit, meaning) and which field of
 * struct case_def (case.h) it fills (the rows of `numerics` are those of core/numerics_keys.def, which
 * also give the parameter structs of the step their members); tests/case_docs.c prints the same
 * rows as the key tables of docs/cases.md, and CTest (case_docs) fails when the document differs. Physics: docs/model.md
 * (1 kernel, 3 EOS, 4 time step, 5 mixture, 6 regimes, 8 walls, 9 reported quantities).
 * Messages have the form "<file>: <key path>: <what was expected>". */
#include "case_schema.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "case.h"
#include "law_registry.h"
#include "status.h"

#define FAIL(r, ...) status_set((r)->err, (r)->err_len, MIXSPH_ERR_CASE, __VA_ARGS__)
#define TRY(expr)                         \
    do {                                  \
        mixsph_status st_ = (expr);       \
        if (st_ != MIXSPH_OK) return st_; \
    } while (0)

#define COUNT(a) SCHEMA_COUNT(a)
#define DEF(v) SCHEMA_DEF(v)
#define RANGE(l, lopen, h, hopen) SCHEMA_RANGE(l, lopen, h, hopen)
#define ANYWHERE RANGE(-1e9, 0, 1e9, 0) /* coordinates [m] */
#define V(kind) (1u << (kind))

/* ---- choices -------------------------------------------------------------------------------- */

static const struct case_choice kernels[] = {{"cubic_spline", 0}, {"wendland_c2", 1}, {NULL, 0}};
static const struct case_choice wall_placements[] = {{"lattice", 0}, {"aligned", 1}, {NULL, 0}};
static const struct case_choice viscous_schemes[] = {{"explicit", 0}, {"implicit", 1}, {NULL, 0}};
static const struct case_choice viscous_preconditioners[] = {{"jacobi", 0}, {"two_level", 1}, {NULL, 0}};
static const struct case_choice viscosity_means[] = {{"harmonic", 0}, {"arithmetic", 1}, {NULL, 0}};
static const struct case_choice diffusion_forms[] = {{"hydrostatic", 0}, {"molteni", 1}, {NULL, 0}};
static const struct case_choice held_grain_modes[] = {{"solved", 0}, {"rigid", 1}, {NULL, 0}};
static const struct case_choice sides[] = {{"left", 1}, {"right", -1}, {NULL, 0}};
static const struct case_choice slips[] = {{"no-slip", WALL_NO_SLIP}, {"free-slip", WALL_FREE_SLIP}, {NULL, 0}};
static const struct case_choice side_walls[] = {
    {"no-slip", WALL_NO_SLIP}, {"free-slip", WALL_FREE_SLIP}, {"mirror", WALL_SIDES_MIRROR}, {NULL, 0}};
static const struct case_choice wall_forms[] = {{"polyline", WALL_FORM_POLYLINE},
                                                {"box", WALL_FORM_BOX},
                                                {"stl", WALL_FORM_STL},
                                                {"terrain", WALL_FORM_TERRAIN},
                                                {NULL, 0}};
static const struct case_choice box_fluid[] = {{"inside", 0}, {"outside", 1}, {NULL, 0}};
static const struct case_choice directions[] = {{"+x", 1}, {"-x", -1}, {NULL, 0}};
static const struct case_choice monitor_types[] = {{"front", MONITOR_FRONT},
                                                   {"max_elevation", MONITOR_MAX_ELEVATION},
                                                   {"kinetic_energy", MONITOR_KINETIC_ENERGY},
                                                   {"profile", MONITOR_PROFILE},
                                                   {"wall_pressure", MONITOR_WALL_PRESSURE},
                                                   {"wall_work", MONITOR_WALL_WORK},
                                                   {"pressure_probe", MONITOR_PRESSURE_PROBE},
                                                   {"runout", MONITOR_RUNOUT},
                                                   {"wave_gauge", MONITOR_WAVE_GAUGE},
                                                   {"slide_impact", MONITOR_SLIDE_IMPACT},
                                                   {"speed", MONITOR_SPEED},
                                                   {NULL, 0}};

/* ---- the tables ------------------------------------------------------------------------------ */

static const struct case_key top_keys[] = {
    {.key = "name", .type = CASE_STRING, .need = CASE_REQUIRED, .lo = 1, .hi = CASE_NAME_LEN - 1,
     .field = CASE_FIELD(case_def, name), .meaning = "case name; the default output folder is `out/<name>`"},
    {.key = "description", .type = CASE_STRING, .meaning = "free text (not read by the model)"},
    {.key = "parameters", .type = CASE_OBJECT,
     .meaning = "named numbers that values elsewhere in the case use as `\"$name\"` (see Parameters)"},
    {.key = "dimensions", .type = CASE_INTEGER, RANGE(2, 0, 3, 0), DEF(2), .unit = "-",
     .field = CASE_FIELD(case_def, dimensions),
     .meaning = "2: a vertical section in x and z; 3: x, y and z, z up (bodies, domain and monitors then take y)"},
    {.key = "gravity", .type = CASE_NUMBER, RANGE(0, 0, 100, 0), DEF(9.81), .unit = "m/s²",
     .field = CASE_FIELD(case_def, g), .meaning = "gravity magnitude, acting along −z"},
    {.key = "numerics", .type = CASE_OBJECT, .need = CASE_REQUIRED, .meaning = "resolution, time step, end time"},
    {.key = "domain", .type = CASE_OBJECT, .def_text = "bounding box", .meaning = "region of the run"},
    {.key = "media", .type = CASE_OBJECT, .need = CASE_REQUIRED, .meaning = "materials, keyed by name (at most 8)"},
    {.key = "bodies", .type = CASE_OBJECT, .need = CASE_REQUIRED,
     .meaning = "regions filled with particles, keyed by name (at most 16)"},
    {.key = "walls", .type = CASE_OBJECT, .need = CASE_REQUIRED, .meaning = "boundaries, keyed by name (at most 16)"},
    {.key = "motions", .type = CASE_OBJECT, .meaning = "prescribed velocity laws of walls, keyed by name (at most 8)"},
    {.key = "monitors", .type = CASE_OBJECT, .meaning = "measured outputs, keyed by name (at most 16)"},
    {.key = "full_scale", .type = CASE_OBJECT,
     .meaning = "map of lab elevations to full scale and the error (13) of the run-up"},
    {.key = "output", .type = CASE_OBJECT, .meaning = "output intervals and the limits of the output's size"},
};

/* The rows of numerics_keys.def, each filling its member of struct case_def. */
#define NUMERICS_SCHEMA_ROW(type_, member, read_by, as, ...) \
    {.type = CASE_##type_, .field = CASE_FIELD(case_def, member), __VA_ARGS__},
static const struct case_key numerics_keys[] = {
#define NUMERICS_KEY NUMERICS_SCHEMA_ROW
#include "numerics_keys.def"
#undef NUMERICS_KEY
};

/* bound k (0: min, 1: max) along axis d of case_def.domain */
#define DOMAIN_FIELD(d, k) (offsetof(struct case_def, domain) + (2 * (d) + (k)) * sizeof(double) + 1)
/* y_min (k = 0), y_max (1) of a 3D case's domain, read apart (case.c copies them into domain) */
#define DOMAIN_Y_FIELD(k) (offsetof(struct case_def, domain_y) + (k) * sizeof(double) + 1)
static const struct case_key domain_keys[] = {
    {.key = "x_min", .type = CASE_NUMBER, .need = CASE_REQUIRED, ANYWHERE, .unit = "m", .field = DOMAIN_FIELD(0, 0),
     .meaning = "left end"},
    {.key = "x_max", .type = CASE_NUMBER, .need = CASE_REQUIRED, ANYWHERE, .unit = "m", .field = DOMAIN_FIELD(0, 1),
     .meaning = "right end, > x_min"},
    {.key = "y_min", .type = CASE_NUMBER, .need = CASE_SOMETIMES, .need_text = "3D", ANYWHERE, .unit = "m",
     .field = DOMAIN_Y_FIELD(0), .meaning = "3D: the side at the smallest y"},
    {.key = "y_max", .type = CASE_NUMBER, .need = CASE_SOMETIMES, .need_text = "3D", ANYWHERE, .unit = "m",
     .field = DOMAIN_Y_FIELD(1), .meaning = "3D: the side at the largest y, > y_min"},
    {.key = "z_min", .type = CASE_NUMBER, .need = CASE_REQUIRED, ANYWHERE, .unit = "m", .field = DOMAIN_FIELD(DIM_UP, 0),
     .meaning = "bottom"},
    {.key = "z_max", .type = CASE_NUMBER, .need = CASE_REQUIRED, ANYWHERE, .unit = "m", .field = DOMAIN_FIELD(DIM_UP, 1),
     .meaning = "top, > z_min"},
};

static const struct case_key body_keys[] = {
    {.key = "medium", .type = CASE_NAME, .need = CASE_REQUIRED, .meaning = "name of one of the media"},
    {.key = "polygon", .type = CASE_POINTS, .need = CASE_SOMETIMES, .need_text = "2D", .lo = 3, .unit = "m",
     .field = CASE_FIELD(body, polygon),
     .meaning = "the outline in x and z, closed implicitly; in 3D extruded across y_min ≤ y ≤ y_max. A 3D body "
                "takes one of polygon, box_min with box_max, or stl; with none of them it is the domain below z_max "
                "(inside the walls)"},
    {.key = "y_min", .type = CASE_NUMBER, .need = CASE_SOMETIMES, .need_text = "3D polygon", ANYWHERE, .unit = "m",
     .field = CASE_FIELD(body, y_min), .meaning = "3D: the polygon's extrusion starts at this y"},
    {.key = "y_max", .type = CASE_NUMBER, .need = CASE_SOMETIMES, .need_text = "3D polygon", ANYWHERE, .unit = "m",
     .field = CASE_FIELD(body, y_max), .meaning = "3D: ... and ends at this y, > y_min"},
    {.key = "box_min", .type = CASE_NUMBERS, .lo = 3, .unit = "m",
     .meaning = "3D: a box, its corner [x, y, z] of smallest coordinates (with box_max)"},
    {.key = "box_max", .type = CASE_NUMBERS, .lo = 3, .unit = "m", .meaning = "3D: the box's opposite corner [x, y, z]"},
    {.key = "stl", .type = CASE_STRING, .lo = 1, .hi = CASE_PATH_LEN - 1,
     .meaning = "3D: a closed triangulated surface (STL, ASCII or binary), the body its inside; a path relative to "
                "the case file's folder"},
    {.key = "z_min", .type = CASE_NUMBER, ANYWHERE, DEF(-INFINITY), .unit = "m", .field = CASE_FIELD(body, z_min),
     .meaning = "the body is clipped to z ≥ z_min"},
    {.key = "z_max", .type = CASE_NUMBER, ANYWHERE, DEF(INFINITY), .unit = "m", .field = CASE_FIELD(body, z_max),
     .meaning = "the body is clipped to z ≤ z_max (e.g. a reservoir level)"},
};

static const struct case_key wall_keys[] = {
    {.key = "polyline", .type = CASE_POINTS, .need = CASE_SOMETIMES, .need_text = "one of polyline, box_min, stl, terrain",
     .lo = 2, .unit = "m", .only = V(WALL_FORM_POLYLINE), .field = CASE_FIELD(wall, line),
     .meaning = "the wall, an open polyline of [x, z] points; consecutive points differ. In a 3D case it is "
                "extruded across y from y_min to y_max"},
    {.key = "fluid_side", .type = CASE_CHOICE, .need = CASE_SOMETIMES, .need_text = "polyline", .choices = sides,
     .only = V(WALL_FORM_POLYLINE), .field = CASE_FIELD(wall, side),
     .meaning = "the side of the fluid, seen along the polyline's direction of travel"},
    {.key = "y_min", .type = CASE_NUMBER, .need = CASE_SOMETIMES, .need_text = "a polyline of a 3D case", ANYWHERE,
     .unit = "m", .only = V(WALL_FORM_POLYLINE), .field = CASE_FIELD(wall, y_min),
     .meaning = "3D: the extruded polyline spans y from y_min to y_max"},
    {.key = "y_max", .type = CASE_NUMBER, .need = CASE_SOMETIMES, .need_text = "a polyline of a 3D case", ANYWHERE,
     .unit = "m", .only = V(WALL_FORM_POLYLINE), .field = CASE_FIELD(wall, y_max), .meaning = "3D: see y_min"},
    {.key = "side_walls", .type = CASE_CHOICE, .def_text = "none", .choices = side_walls, .only = V(WALL_FORM_POLYLINE),
     .field = CASE_FIELD(wall, side_walls),
     .meaning = "3D: add the planes y = y_min and y = y_max, fluid between them, as the wall <name>_sides with this "
                "slip condition (fixed, the polyline's friction); \"mirror\": the planes are planes of symmetry, "
                "without wall particles: every particle within 2h + skin/2 of one has its mirror image across it"},
    {.key = "side_walls_z_max", .type = CASE_NUMBER, ANYWHERE, .def_text = "the polyline's top", .unit = "m",
     .only = V(WALL_FORM_POLYLINE), .field = CASE_FIELD(wall, side_walls_z_max),
     .meaning = "3D: the side walls reach from the polyline's lowest point up to this height"},
    {.key = "box_min", .type = CASE_NUMBERS, .need = CASE_SOMETIMES, .need_text = "box", .lo = 3, .unit = "m",
     .only = V(WALL_FORM_BOX), .meaning = "3D: the box's lowest corner [x, y, z]"},
    {.key = "box_max", .type = CASE_NUMBERS, .need = CASE_SOMETIMES, .need_text = "box", .lo = 3, .unit = "m",
     .only = V(WALL_FORM_BOX), .meaning = "3D: the box's highest corner [x, y, z]"},
    {.key = "open_faces", .type = CASE_STRING, .lo = 1, .hi = 64, .def_text = "z_max", .only = V(WALL_FORM_BOX),
     .meaning = "3D: the faces the box leaves open, comma-separated among x_min, x_max, y_min, y_max, z_min, z_max, "
                "or none (a closed box)"},
    {.key = "fluid", .type = CASE_CHOICE, DEF(0), .choices = box_fluid, .only = V(WALL_FORM_BOX),
     .field = CASE_FIELD(wall, fluid_outside), .meaning = "3D: the fluid is inside the box (a tank) or outside it (an obstacle)"},
    {.key = "stl", .type = CASE_STRING, .need = CASE_SOMETIMES, .need_text = "stl", .lo = 1, .hi = WALL_PATH_LEN,
     .only = V(WALL_FORM_STL),
     .meaning = "3D: an STL file (ASCII or binary), relative to the case file's folder; the fluid is on the side its "
                "facets' normals point to (the right-hand rule of their vertices)"},
    {.key = "flip_normals", .type = CASE_BOOL, DEF(0), .only = V(WALL_FORM_STL), .field = CASE_FIELD(wall, flip),
     .meaning = "3D: the fluid is on the other side of the STL's facets"},
    {.key = "terrain", .type = CASE_STRING, .need = CASE_SOMETIMES, .need_text = "terrain", .lo = 1, .hi = WALL_PATH_LEN,
     .only = V(WALL_FORM_TERRAIN),
     .meaning = "3D: an ESRI ASCII height grid, relative to the case file's folder, turned into a surface; the fluid "
                "is above it"},
    {.key = "slip", .type = CASE_CHOICE, DEF(WALL_NO_SLIP), .choices = slips, .numeric_choice = 1,
     .field = CASE_FIELD(wall, slip), .meaning = "the condition on the tangential velocity"},
    {.key = "friction", .type = CASE_NUMBER_BY_NAME, RANGE(0, 0, 90, 0),
     .def_text = "elastic_plastic: φ of the grains; paper: 90", .unit = "deg",
     .field = CASE_FIELD(wall, friction_deg),
     .meaning = "bed friction angle δ of a no-slip wall on grains (docs/model.md [BF]): its shear on a sliding grain "
                "is tan δ times the normal force it exerts, on a grain at rest at most that (0: smooth; 90: none, "
                "the law's own no-slip shear). A number: every granular medium's δ; an object {\"medium\": δ, ...}: "
                "the δ of each granular medium it names, the default for the others"},
    {.key = "motion", .type = CASE_NAME, .def_text = "fixed", .meaning = "name of one of the motions"},
};

static const struct case_key motion_keys[] = {
    {.key = "t", .type = CASE_NUMBERS, .need = CASE_REQUIRED, .lo = 1, .unit = "s",
     .meaning = "times of the velocity law, strictly increasing"},
    {.key = "vx", .type = CASE_NUMBERS, .need = CASE_REQUIRED, .lo = 1, .unit = "m/s",
     .meaning = "horizontal velocity at those times (as many as t)"},
    {.key = "vy", .type = CASE_NUMBERS, .lo = 1, .unit = "m/s", .def_text = "0",
     .meaning = "3D: velocity across y at those times (as many as t)"},
    {.key = "vz", .type = CASE_NUMBERS, .need = CASE_REQUIRED, .lo = 1, .unit = "m/s",
     .meaning = "vertical velocity at those times (as many as t)"},
    {.key = "speed_scale", .type = CASE_NUMBER, RANGE(0, 0, 1e3, 0), DEF(1), .unit = "-",
     .field = CASE_FIELD(motion, speed_scale), .meaning = "the velocities are multiplied by this"},
    {.key = "time_scale", .type = CASE_NUMBER, RANGE(0, 1, 1e3, 0), DEF(1), .unit = "-",
     .field = CASE_FIELD(motion, time_scale), .meaning = "the law is stretched in time by this (law time = t / time_scale)"},
    {.key = "stroke_scale", .type = CASE_NUMBER, RANGE(0, 1, 1e3, 0), .unit = "-",
     .meaning = "instead of speed_scale: the displacement is multiplied by this (speed_scale = "
                "stroke_scale / time_scale)"},
};

#define PARTICLE_MONITORS                                                                                         \
    (V(MONITOR_FRONT) | V(MONITOR_MAX_ELEVATION) | V(MONITOR_PROFILE) | V(MONITOR_RUNOUT) | V(MONITOR_WAVE_GAUGE) | \
     V(MONITOR_SLIDE_IMPACT))
#define MEDIUM_MONITORS (PARTICLE_MONITORS | V(MONITOR_KINETIC_ENERGY) | V(MONITOR_SPEED))
#define WALL_MONITORS (V(MONITOR_WALL_PRESSURE) | V(MONITOR_WALL_WORK))
/* (a wall's work is the whole wall's; a wave gauge's window is its own) */
#define REGION_MONITORS ((MEDIUM_MONITORS & ~V(MONITOR_WAVE_GAUGE)) | V(MONITOR_WALL_PRESSURE))
static const struct case_key monitor_keys[] = {
    {.key = "type", .type = CASE_CHOICE, .need = CASE_REQUIRED, .choices = monitor_types,
     .field = CASE_FIELD(monitor_def, kind), .meaning = "what the monitor measures (below)"},
    {.key = "medium", .type = CASE_NAME, .need = CASE_REQUIRED, .only = MEDIUM_MONITORS,
     .meaning = "name of one of the media"},
    {.key = "wall", .type = CASE_NAME, .need = CASE_SOMETIMES, .need_text = "wall_pressure, wall_work",
     .only = WALL_MONITORS | V(MONITOR_PRESSURE_PROBE),
     .meaning = "name of one of the walls (pressure_probe: the wall whose sensor the point is; without it the point "
                "is in the flow)"},
    {.key = "x", .type = CASE_NUMBER, .need = CASE_REQUIRED, ANYWHERE, .only = V(MONITOR_PRESSURE_PROBE) | V(MONITOR_WAVE_GAUGE),
     .unit = "m", .field = CASE_FIELD(monitor_def, point_x),
     .meaning = "pressure_probe: the probe's point; with `wall`, the sensor's place on that wall (at t = 0), within dx/2 "
                "of it. wave_gauge: the gauge's station"},
    {.key = "y", .type = CASE_NUMBER, .need = CASE_SOMETIMES, .need_text = "3D", ANYWHERE,
     .only = V(MONITOR_PRESSURE_PROBE) | V(MONITOR_WAVE_GAUGE), .unit = "m", .field = CASE_FIELD(monitor_def, point_y),
     .meaning = "3D: the probe's point across; wave_gauge: the gauge's station across"},
    {.key = "z", .type = CASE_NUMBER, .need = CASE_REQUIRED, ANYWHERE, .only = V(MONITOR_PRESSURE_PROBE), .unit = "m",
     .field = CASE_FIELD(monitor_def, point_z), .meaning = "height of the probe's point"},
    {.key = "direction", .type = CASE_CHOICE, DEF(1), .choices = directions,
     .only = V(MONITOR_FRONT) | V(MONITOR_RUNOUT) | V(MONITOR_SLIDE_IMPACT), .field = CASE_FIELD(monitor_def, direction),
     .meaning = "front, runout: \"+x\": the largest x of the medium (of its deposit), \"-x\": the smallest; "
                "slide_impact: the way the ramp descends"},
    {.key = "min_neighbours", .type = CASE_INTEGER, RANGE(0, 0, 100, 0), DEF(3), .unit = "-", .only = PARTICLE_MONITORS,
     .field = CASE_FIELD(monitor_def, min_neighbours),
     .meaning = "a particle counts only with at least this many neighbours of its own medium within 2h (not spray)"},
    {.key = "x_min", .type = CASE_NUMBER, .need = CASE_SOMETIMES, .need_text = "profile, runout", ANYWHERE, .only = REGION_MONITORS, DEF(-INFINITY),
     .unit = "m", .field = CASE_FIELD(monitor_def, x_min), .meaning = "region the monitor looks at: left end"},
    {.key = "x_max", .type = CASE_NUMBER, .need = CASE_SOMETIMES, .need_text = "profile, runout", ANYWHERE, .only = REGION_MONITORS, DEF(INFINITY),
     .unit = "m", .field = CASE_FIELD(monitor_def, x_max), .meaning = "right end, > x_min"},
    {.key = "y_min", .type = CASE_NUMBER, ANYWHERE, .only = REGION_MONITORS, DEF(-INFINITY), .unit = "m",
     .field = CASE_FIELD(monitor_def, y_min), .meaning = "3D: the region's side at the smallest y"},
    {.key = "y_max", .type = CASE_NUMBER, ANYWHERE, .only = REGION_MONITORS, DEF(INFINITY), .unit = "m",
     .field = CASE_FIELD(monitor_def, y_max), .meaning = "3D: its side at the largest y, > y_min"},
    {.key = "z_min", .type = CASE_NUMBER, ANYWHERE, .only = REGION_MONITORS, DEF(-INFINITY), .unit = "m", .field = CASE_FIELD(monitor_def, z_min),
     .meaning = "bottom"},
    {.key = "z_max", .type = CASE_NUMBER, ANYWHERE, .only = REGION_MONITORS, DEF(INFINITY), .unit = "m", .field = CASE_FIELD(monitor_def, z_max),
     .meaning = "top, > z_min"},
    {.key = "bin", .type = CASE_NUMBER, RANGE(0, 1, 1e3, 0), .def_text = "dx", .unit = "m", .only = V(MONITOR_PROFILE) | V(MONITOR_RUNOUT),
     .field = CASE_FIELD(monitor_def, bin), .meaning = "width of the x bins (runout: of the deposit's columns)"},
    {.key = "times", .type = CASE_NUMBERS, .need = CASE_SOMETIMES, .need_text = "unless at_max_of", .lo = 1,
     .unit = "s", .only = V(MONITOR_PROFILE), .meaning = "times at which the profile is written, increasing (at most 16)"},
    {.key = "at_max_of", .type = CASE_NAME, .only = V(MONITOR_PROFILE),
     .meaning = "name of a max_elevation monitor: the profile is also written at each new highest value of that "
                "monitor (`profile_<name>_atmax.csv`)"},
    {.key = "threshold", .type = CASE_NUMBER, .need = CASE_REQUIRED, RANGE(0, 1, 1e3, 0), .unit = "m",
     .only = V(MONITOR_RUNOUT), .field = CASE_FIELD(monitor_def, threshold),
     .meaning = "a column is part of the deposit where the medium is at least this thick (e.g. a grain size, or 2 dx)"},
    {.key = "still", .type = CASE_NUMBER, .need = CASE_REQUIRED, ANYWHERE, .unit = "m",
     .only = V(MONITOR_WAVE_GAUGE) | V(MONITOR_SLIDE_IMPACT), .field = CASE_FIELD(monitor_def, still),
     .meaning = "the still water level (z): wave_gauge: eta is measured from it; slide_impact: the slide's front "
                "crossing it is the impact"},
    {.key = "window", .type = CASE_NUMBER, RANGE(0, 1, 1e3, 0), .def_text = "2 dx", .unit = "m",
     .only = V(MONITOR_WAVE_GAUGE), .field = CASE_FIELD(monitor_def, window),
     .meaning = "the gauge reads the particles within this distance of x (3D: of x and of y)"},
    {.key = "angle", .type = CASE_NUMBER, .need = CASE_REQUIRED, RANGE(0, 1, 90, 1), .unit = "degree",
     .only = V(MONITOR_SLIDE_IMPACT), .field = CASE_FIELD(monitor_def, angle),
     .meaning = "the ramp's angle to the horizontal (the slide's thickness is taken normal to it)"},
    {.key = "quantile", .type = CASE_NUMBER, RANGE(0, 1, 1, 0), DEF(1), .unit = "-", .only = V(MONITOR_SPEED),
     .field = CASE_FIELD(monitor_def, quantile),
     .meaning = "the quantile of the medium's particle speeds: 1 the largest, 0.99 the speed 99 % of them do not exceed"},
};

static const struct case_key full_scale_keys[] = {
    {.key = "z_scale", .type = CASE_NUMBER, .need = CASE_REQUIRED, RANGE(0, 1, 1e9, 0), .unit = "full-scale unit / m",
     .field = CASE_FIELD(full_scale, z_scale), .meaning = "Z = z_scale z + z_offset"},
    {.key = "z_offset", .type = CASE_NUMBER, ANYWHERE, DEF(0), .unit = "full-scale unit",
     .field = CASE_FIELD(full_scale, z_offset), .meaning = "full-scale elevation of z = 0"},
    {.key = "unit", .type = CASE_STRING, .hi = CASE_NAME_LEN - 1, .def_text = "m", .field = CASE_FIELD(full_scale, unit),
     .meaning = "unit of Z, a label (recorded; no output prints it yet)"},
    {.key = "reference", .type = CASE_OBJECT, .meaning = "the observation the error (13) compares with (below)"},
};

static const struct case_key reference_keys[] = {
    {.key = "monitor", .type = CASE_NAME, .need = CASE_REQUIRED,
     .meaning = "name of a max_elevation monitor (the run-up)"},
    {.key = "observed", .type = CASE_NUMBER, .need = CASE_REQUIRED, ANYWHERE, .unit = "full-scale unit",
     .field = CASE_FIELD(full_scale, observed), .meaning = "observed highest elevation Z_exp"},
    {.key = "still", .type = CASE_NUMBER, .need = CASE_REQUIRED, ANYWHERE, .unit = "full-scale unit",
     .field = CASE_FIELD(full_scale, still), .meaning = "still-water elevation Z_still of the error (13), < observed"},
};

static const struct case_key output_keys[] = {
    {.key = "monitor_interval", .type = CASE_NUMBER, RANGE(0, 1, 1e6, 0), .def_text = "t_end / 200", .unit = "s",
     .field = CASE_FIELD(case_def, monitor_interval), .meaning = "time between rows of monitors.csv"},
    {.key = "snapshot_interval", .type = CASE_NUMBER, RANGE(0, 0, 1e6, 0), DEF(0), .def_text = "0 (none)",
     .unit = "s", .field = CASE_FIELD(case_def, snapshot_interval), .meaning = "time between particle snapshots"},
    {.key = "max_monitor_rows", .type = CASE_NUMBER, RANGE(1, 0, 1e15, 0), DEF(1e6), .unit = "-",
     .field = CASE_FIELD(case_def, max_monitor_rows),
     .meaning = "limit of the resource budget: rows of monitors.csv, t_end / monitor_interval + 1"},
    {.key = "max_profile_bins", .type = CASE_NUMBER, RANGE(1, 0, 1e12, 0), DEF(1e5), .unit = "-",
     .field = CASE_FIELD(case_def, max_profile_bins),
     .meaning = "limit of the resource budget: x bins of one profile or runout monitor, its width / bin"},
    {.key = "max_snapshot_bytes", .type = CASE_NUMBER, RANGE(1, 0, 1e18, 0), DEF(2e10), .unit = "B",
     .field = CASE_FIELD(case_def, max_snapshot_bytes),
     .meaning = "limit of the resource budget: bytes of all particle snapshots (CSV and HDF5), estimated"},
};

#define SECTION(id_, title_, keys_) SCHEMA_SECTION(id_, title_, keys_)
/* The case's own sections; the media's (one per material law, laws/law_registry.h) come after
 * the first CASE_SECTIONS_BEFORE_MEDIA of them. */
static const struct case_section sections[] = {
    {SECTION("case", "the case (top level)", top_keys)},
    {SECTION("numerics", "numerics", numerics_keys)},
    {SECTION("domain", "domain", domain_keys)},
    {SECTION("bodies", "bodies.<name>", body_keys)},
    {SECTION("walls", "walls.<name>", wall_keys), .variant_noun = "wall", .variants = wall_forms},
    {SECTION("motions", "motions.<name>", motion_keys)},
    {SECTION("monitors", "monitors.<name>", monitor_keys), .variant_noun = "monitor", .variants = monitor_types},
    {SECTION("full_scale", "full_scale", full_scale_keys)},
    {SECTION("full_scale.reference", "full_scale.reference", reference_keys)},
    {SECTION("output", "output", output_keys)},
};
#define CASE_SECTIONS_BEFORE_MEDIA 3

const struct case_section *case_schema_section(size_t k)
{
    if (k < CASE_SECTIONS_BEFORE_MEDIA) return &sections[k];
    if (k < CASE_SECTIONS_BEFORE_MEDIA + LAW_COUNT) return law_get((int)(k - CASE_SECTIONS_BEFORE_MEDIA))->keys;
    k -= LAW_COUNT;
    return k < COUNT(sections) ? &sections[k] : NULL;
}

const struct case_section *case_schema_find(const char *id)
{
    for (size_t k = 0; case_schema_section(k); k++)
        if (strcmp(case_schema_section(k)->id, id) == 0) return case_schema_section(k);
    return NULL;
}

const struct case_key *case_schema_key(const struct case_section *s, const char *key)
{
    for (size_t k = 0; k < s->n_keys; k++)
        if (strcmp(s->keys[k].key, key) == 0) return &s->keys[k];
    return NULL;
}

/* ---- text --------------------------------------------------------------------------------------- */

void case_schema_number_text(double v, char *buf, size_t len)
{
    if (isinf(v)) {
        snprintf(buf, len, "%s", v > 0 ? "+∞" : "−∞");
        return;
    }
    char t[32];
    snprintf(t, sizeof t, "%g", v);
    char *e = strchr(t, 'e');
    if (e) { /* 1e+09 -> 1e9, 1e-05 -> 1e-5 */
        char *d = e + 1, *s = e + 1;
        if (*s == '+') s++;
        else if (*s == '-') *d++ = *s++;
        while (*s == '0' && s[1]) s++;
        memmove(d, s, strlen(s) + 1);
    }
    snprintf(buf, len, "%s", t);
}

void case_schema_range_text(const struct case_key *k, int unicode, char *buf, size_t len)
{
    char lo[32], hi[32];
    case_schema_number_text(k->lo, lo, sizeof lo);
    case_schema_number_text(k->hi, hi, sizeof hi);
    const char *le = unicode ? "≤" : "<=";
    switch (k->type) {
    case CASE_NUMBER:
    case CASE_INTEGER:
    case CASE_NUMBER_BY_NAME:
        snprintf(buf, len, "%s %s x %s %s", lo, k->lo_open ? "<" : le, k->hi_open ? "<" : le, hi);
        break;
    case CASE_STRING:
        if (k->hi <= 0) snprintf(buf, len, "%s", "");
        else if (k->lo > 0) snprintf(buf, len, "%s to %s characters", lo, hi);
        else snprintf(buf, len, "at most %s characters", hi);
        break;
    case CASE_CHOICE: {
        size_t at = 0;
        buf[0] = '\0';
        for (const struct case_choice *c = k->choices; c->name && at < len; c++)
            at += (size_t)snprintf(buf + at, len - at, unicode ? "%s`\"%s\"`" : "%s\"%s\"",
                                   c == k->choices ? "" : c[1].name ? ", " : " or ", c->name);
        if (k->numeric_choice)
            for (const struct case_choice *c = k->choices; c->name && at < len; c++)
                at += (size_t)snprintf(buf + at, len - at, "%s%d%s", c == k->choices ? " (or " : ", ",
                                       k->numeric_choice == CASE_CHOICE_BY_POSITION ? (int)(c - k->choices) : c->value,
                                       c[1].name ? "" : ")");
        break;
    }
    case CASE_NUMBERS: snprintf(buf, len, "at least %s", lo); break;
    case CASE_POINTS: snprintf(buf, len, "at least %s points", lo); break;
    default: snprintf(buf, len, "%s", "");
    }
}

void case_schema_default_text(const struct case_key *k, char *buf, size_t len)
{
    if (k->def_text) {
        snprintf(buf, len, k->type == CASE_STRING ? "`\"%s\"`" : "%s", k->def_text);
        return;
    }
    buf[0] = '\0';
    if (!k->has_def) return;
    if (k->type == CASE_BOOL) {
        snprintf(buf, len, "%s", k->def != 0.0 ? "true" : "false");
    } else if (k->type == CASE_CHOICE) {
        for (const struct case_choice *c = k->choices; c->name; c++)
            if (c->value == (int)k->def) snprintf(buf, len, "`\"%s\"`", c->name);
    } else {
        case_schema_number_text(k->def, buf, len);
    }
}

/* ---- reading ------------------------------------------------------------------------------------ */

static void key_path(char *buf, size_t len, const char *path, const char *key)
{
    snprintf(buf, len, "%s%s%s", path, *path ? "." : "", key);
}

static const char *expected_noun(enum case_type t)
{
    switch (t) {
    case CASE_NUMBER: return "a number";
    case CASE_INTEGER: return "an integer";
    case CASE_BOOL: return "true or false";
    case CASE_NUMBERS: return "an array of numbers";
    case CASE_POINTS: return "an array of [x, z] points";
    case CASE_OBJECT: return "an object";
    case CASE_NUMBER_BY_NAME: return "a number, or an object of numbers by name";
    default: return "a string";
    }
}

mixsph_status case_schema_numbers(const struct case_reader *r, const cJSON *obj, const char *path, const char *key,
                                  size_t min_n, double **out, size_t *n)
{
    char kp[256];
    key_path(kp, sizeof kp, path, key);
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!it) return FAIL(r, "%s: %s: missing (expected an array of numbers)", r->origin, kp);
    if (!cJSON_IsArray(it)) return FAIL(r, "%s: %s: expected an array of numbers", r->origin, kp);
    const size_t len = (size_t)cJSON_GetArraySize(it);
    if (len < min_n) return FAIL(r, "%s: %s: expected at least %zu number(s)", r->origin, kp, min_n);
    double *v = calloc(len ? len : 1, sizeof *v);
    if (!v) return status_set(r->err, r->err_len, MIXSPH_ERR_NOMEM, "out of memory");
    size_t k = 0;
    for (const cJSON *e = it->child; e; e = e->next, k++) {
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble)) {
            free(v);
            return FAIL(r, "%s: %s[%zu]: expected a number", r->origin, kp, k);
        }
        v[k] = e->valuedouble;
    }
    *out = v;
    *n = len;
    return MIXSPH_OK;
}

mixsph_status case_schema_points(const struct case_reader *r, const cJSON *obj, const char *path, const char *key,
                                 size_t min_n, struct polyline *pl)
{
    char kp[256];
    key_path(kp, sizeof kp, path, key);
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!it) return FAIL(r, "%s: %s: missing (expected an array of [x, z] points)", r->origin, kp);
    if (!cJSON_IsArray(it)) return FAIL(r, "%s: %s: expected an array of [x, z] points", r->origin, kp);
    const size_t len = (size_t)cJSON_GetArraySize(it);
    if (len < min_n) return FAIL(r, "%s: %s: expected at least %zu [x, z] point(s)", r->origin, kp, min_n);
    pl->x = calloc(len, sizeof(double));
    pl->z = calloc(len, sizeof(double));
    pl->n = len;
    if (!pl->x || !pl->z) return status_set(r->err, r->err_len, MIXSPH_ERR_NOMEM, "out of memory");
    size_t k = 0;
    for (const cJSON *e = it->child; e; e = e->next, k++) {
        const cJSON *a = cJSON_IsArray(e) && cJSON_GetArraySize(e) == 2 ? e->child : NULL;
        if (!a || !cJSON_IsNumber(a) || !cJSON_IsNumber(a->next) || !isfinite(a->valuedouble) ||
            !isfinite(a->next->valuedouble))
            return FAIL(r, "%s: %s[%zu]: expected a point [x, z] of two numbers", r->origin, kp, k);
        pl->x[k] = a->valuedouble;
        pl->z[k] = a->next->valuedouble;
        if (k > 0 && pl->x[k] == pl->x[k - 1] && pl->z[k] == pl->z[k - 1])
            return FAIL(r, "%s: %s[%zu]: repeats the previous point", r->origin, kp, k);
    }
    return MIXSPH_OK;
}

static void *field_of(const struct case_key *k, void *base) { return base && k->field ? (char *)base + k->field - 1 : NULL; }

int case_schema_stored_number(const struct case_key *k, const void *base, double *value)
{
    const void *f = field_of(k, (void *)base);
    if (!f) return -1;
    switch (k->type) {
    case CASE_NUMBER:
    case CASE_NUMBER_BY_NAME: *value = *(const double *)f; return 0;
    case CASE_INTEGER:
    case CASE_BOOL:
    case CASE_CHOICE: *value = *(const int *)f; return 0;
    default: return -1;
    }
}

/* A number of the key's type in its range. */
static mixsph_status read_number(const struct case_reader *r, const cJSON *it, const char *kp, const struct case_key *k,
                                 double *v)
{
    if (!cJSON_IsNumber(it) || !isfinite(it->valuedouble))
        return FAIL(r, "%s: %s: expected %s", r->origin, kp, expected_noun(k->type));
    *v = it->valuedouble;
    if ((k->lo_open ? *v <= k->lo : *v < k->lo) || (k->hi_open ? *v >= k->hi : *v > k->hi)) {
        char range[96];
        case_schema_range_text(k, 0, range, sizeof range);
        return FAIL(r, "%s: %s: %g is out of range (expected %s)", r->origin, kp, *v, range);
    }
    if (k->type == CASE_INTEGER && *v != floor(*v)) return FAIL(r, "%s: %s: expected an integer", r->origin, kp);
    return MIXSPH_OK;
}

static mixsph_status read_choice(const struct case_reader *r, const cJSON *it, const char *kp, const struct case_key *k,
                                 int *value)
{
    for (const struct case_choice *c = k->choices; c->name; c++)
        if (strcmp(it->valuestring, c->name) == 0) {
            *value = c->value;
            return MIXSPH_OK;
        }
    char list[256];
    case_schema_range_text(k, 0, list, sizeof list);
    return FAIL(r, "%s: %s: '%s' (expected %s)", r->origin, kp, it->valuestring, list);
}

mixsph_status case_schema_read_key(const struct case_reader *r, const cJSON *obj, const char *path,
                                   const struct case_key *k, void *base)
{
    char kp[256];
    key_path(kp, sizeof kp, path, k->key);
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, k->key);
    void *f = field_of(k, base);
    if (!it) {
        if (k->need == CASE_REQUIRED)
            return FAIL(r, "%s: %s: missing (expected %s)", r->origin, kp, expected_noun(k->type));
        if (!f) return MIXSPH_OK;
        if (k->type == CASE_STRING && k->def_text) snprintf((char *)f, (size_t)k->hi + 1, "%s", k->def_text);
        if (!k->has_def) return MIXSPH_OK;
        if (k->type == CASE_NUMBER || k->type == CASE_NUMBER_BY_NAME) *(double *)f = k->def;
        else *(int *)f = (int)k->def; /* integer, Boolean, choice */
        return MIXSPH_OK;
    }
    double v = 0.0;
    int iv = 0;
    switch (k->type) {
    case CASE_NUMBER:
    case CASE_INTEGER:
        TRY(read_number(r, it, kp, k, &v));
        if (f && k->type == CASE_NUMBER) *(double *)f = v;
        else if (f) *(int *)f = (int)v;
        return MIXSPH_OK;
    case CASE_BOOL:
        if (cJSON_IsNumber(it) && (it->valuedouble == 0.0 || it->valuedouble == 1.0)) iv = it->valuedouble != 0.0;
        else if (cJSON_IsBool(it)) iv = cJSON_IsTrue(it);
        else return FAIL(r, "%s: %s: expected true or false", r->origin, kp);
        if (f) *(int *)f = iv;
        return MIXSPH_OK;
    case CASE_STRING:
    case CASE_CHOICE:
    case CASE_NAME:
        if (k->type == CASE_CHOICE && k->numeric_choice && cJSON_IsNumber(it)) {
            for (const struct case_choice *c = k->choices; c->name; c++)
                if (it->valuedouble == (double)(k->numeric_choice == CASE_CHOICE_BY_POSITION ? (int)(c - k->choices)
                                                                                             : c->value)) {
                    if (f) *(int *)f = c->value;
                    return MIXSPH_OK;
                }
            char list[256];
            case_schema_range_text(k, 0, list, sizeof list);
            return FAIL(r, "%s: %s: %g is not the number of a choice (expected %s)", r->origin, kp, it->valuedouble,
                        list);
        }
        if (!cJSON_IsString(it)) return FAIL(r, "%s: %s: expected a string", r->origin, kp);
        if (k->type == CASE_CHOICE) {
            TRY(read_choice(r, it, kp, k, &iv));
            if (f) *(int *)f = iv;
        } else if (k->type == CASE_STRING && k->hi > 0) {
            const size_t n = strlen(it->valuestring);
            if ((double)n < k->lo || (double)n > k->hi) {
                char range[96];
                case_schema_range_text(k, 0, range, sizeof range);
                return FAIL(r, "%s: %s: expected %s", r->origin, kp, range);
            }
            if (f) memcpy(f, it->valuestring, n + 1);
        }
        return MIXSPH_OK;
    case CASE_NUMBERS: {
        double *tmp = NULL;
        size_t n = 0;
        TRY(case_schema_numbers(r, obj, path, k->key, (size_t)k->lo, &tmp, &n));
        free(tmp);
        return MIXSPH_OK;
    }
    case CASE_POINTS: {
        struct polyline tmp = {0, NULL, NULL};
        struct polyline *pl = f ? (struct polyline *)f : &tmp;
        const mixsph_status st = case_schema_points(r, obj, path, k->key, (size_t)k->lo, pl);
        geom_free(&tmp);
        return st;
    }
    case CASE_OBJECT:
        if (!cJSON_IsObject(it)) return FAIL(r, "%s: %s: expected an object", r->origin, kp);
        return MIXSPH_OK;
    case CASE_NUMBER_BY_NAME:
        if (!cJSON_IsObject(it)) { /* the number form: a number of the key's range */
            TRY(read_number(r, it, kp, k, &v));
            if (f) *(double *)f = v;
            return MIXSPH_OK;
        }
        for (const cJSON *e = it->child; e; e = e->next) { /* each name's number in the range; case.c the names */
            char ep[512]; /* kp, a dot and the name */
            key_path(ep, sizeof ep, kp, e->string);
            if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble))
                return FAIL(r, "%s: %s: expected a number", r->origin, ep);
            TRY(read_number(r, e, ep, k, &v));
        }
        return MIXSPH_OK;
    }
    return MIXSPH_OK;
}

/* "a kinetic_energy monitor does not take this key (only front, max_elevation or profile)" */
static mixsph_status refuse_variant(const struct case_reader *r, const char *kp, const struct case_section *s,
                                    unsigned variant, unsigned only)
{
    char list[256] = "";
    const char *mine = "";
    size_t at = 0, n = 0, total = 0;
    for (const struct case_choice *c = s->variants; c->name; c++) total += (only & V(c->value)) != 0;
    for (const struct case_choice *c = s->variants; c->name; c++) {
        if (variant & V(c->value)) mine = c->name;
        if (!(only & V(c->value)) || at >= sizeof list) continue;
        n++;
        at += (size_t)snprintf(list + at, sizeof list - at, "%s%s", n == 1 ? "" : n == total ? " or " : ", ", c->name);
    }
    return FAIL(r, "%s: %s: a %s %s does not take this key (only %s)", r->origin, kp, mine, s->variant_noun, list);
}

mixsph_status case_schema_read(const struct case_reader *r, const cJSON *obj, const char *path,
                               const struct case_section *s, unsigned variant, void *base)
{
    if (!cJSON_IsObject(obj)) return FAIL(r, "%s: %s: expected an object", r->origin, *path ? path : "the case");
    for (const cJSON *it = obj->child; it; it = it->next) {
        char kp[256];
        key_path(kp, sizeof kp, path, it->string);
        const struct case_key *k = case_schema_key(s, it->string);
        if (!k) {
            for (const struct case_refused *x = s->refused; x && x->key; x++)
                if (strcmp(x->key, it->string) == 0) return FAIL(r, "%s: %s: %s", r->origin, kp, x->why);
            return FAIL(r, "%s: %s: unknown key", r->origin, kp);
        }
        if (k->only && variant && !(k->only & variant)) return refuse_variant(r, kp, s, variant, k->only);
    }
    for (size_t i = 0; i < s->n_keys; i++) {
        const struct case_key *k = &s->keys[i];
        if (k->only && variant && !(k->only & variant)) continue;
        TRY(case_schema_read_key(r, obj, path, k, base));
    }
    return MIXSPH_OK;
}
