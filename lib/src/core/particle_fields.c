/* particle_fields.c - the particle-field table (see particle_fields.h).
 *
 * A row names its components by the members of struct particles (COMPONENTS*): the CSV columns
 * are the member names and the element type is the member's, so neither can disagree with the
 * struct. The rows are in the order files list them: run.h5 creates a snapshot's datasets and
 * run.xdmf lists its attributes in this order, snap_NNNN.csv writes the PF_KEY rows' columns
 * first and then the other PF_CSV rows in this order, states save the PF_STATE rows in it. */
#include "particle_fields.h"

#include <stdint.h>
#include <string.h>

#include "particles.h"

#define MEMBER_TYPE(a)                                                                                              \
    _Generic(((struct particles *)0)->a, double *: PF_F64, uint8_t *: PF_U8, uint16_t *: PF_U16, uint32_t *: PF_U32)
#define AT(a) offsetof(struct particles, a)
#define COMPONENTS1(a) .columns = #a, .type = MEMBER_TYPE(a), .components = 1, .member = {AT(a)}
/* A vector field (a member v[DIM]): its columns are the prefix followed by each axis ("vx,vz"). */
#if DIM == 2
#define VECTOR(v, prefix) .columns = prefix "x," prefix "z", .type = PF_F64, .components = 2, .member = {AT(v[0]), AT(v[1])}
#define STRESS(s, prefix)                                                                                            \
    .columns = prefix "xx," prefix "xz," prefix "zz," prefix "yy", .type = PF_F64, .components = SYM_N,              \
    .member = {AT(s[0]), AT(s[1]), AT(s[2]), AT(s[3])}
#else
#define VECTOR(v, prefix)                                                                                            \
    .columns = prefix "x," prefix "y," prefix "z", .type = PF_F64, .components = 3,                                   \
    .member = {AT(v[0]), AT(v[1]), AT(v[2])}, .y_odd = 1u << 1
#define STRESS(s, prefix)                                                                                            \
    .columns = prefix "xx," prefix "xz," prefix "zz," prefix "yy," prefix "xy," prefix "yz", .type = PF_F64,          \
    .components = SYM_N, .member = {AT(s[0]), AT(s[1]), AT(s[2]), AT(s[3]), AT(s[4]), AT(s[5])},              \
    .y_odd = (1u << SYM_XY) | (1u << SYM_YZ)
#endif

enum { OUT = PF_STATE | PF_HDF5 | PF_CSV | PF_VIEW }; /* a field of the snapshots */

const struct particle_field particle_fields[] = {
    /* the snapshots' fields (run.h5, run.xdmf, snap_NNNN.csv, the view), as run.h5 lists them */
    {.name = "position", VECTOR(pos, ""), .unit = "m", .description = DIM == 2 ? "x, z (z up)" : "x, y, z (z up)", .owner = PF_OWNER_CORE,
     .where = OUT | PF_GEOMETRY, .csv_digits = 7},
    {.name = "velocity", VECTOR(vel, "v"), .unit = "m/s", .description = "vx, vz", .owner = PF_OWNER_CORE,
     .where = OUT, .csv_digits = 6},
    {.name = "density", COMPONENTS1(rho), .unit = "kg/m^3", .description = "density", .owner = PF_OWNER_CORE,
     .where = OUT, .csv_digits = 7},
    {.name = "pressure", COMPONENTS1(p), .unit = "Pa", .description = "pressure", .owner = PF_OWNER_CORE,
     .where = OUT, .csv_digits = 6},
    {.name = "viscosity", COMPONENTS1(mu), .unit = "Pa s", .description = "dynamic (apparent) viscosity",
     .owner = PF_OWNER_LAW, .where = OUT, .csv_digits = 6},
    {.name = "mass", COMPONENTS1(m), .unit = "kg", .description = "mass (per unit depth of the 2D model)",
     .owner = PF_OWNER_CORE, .where = PF_STATE | PF_HDF5 | PF_VIEW},
    {.name = "medium", COMPONENTS1(medium), .unit = "1",
     .description = "index into /metadata media (fluid and granular particles) or walls (wall particles)",
     .owner = PF_OWNER_CORE, .where = OUT},
    {.name = "state", COMPONENTS1(state), .unit = "1", .description = "0 mobile, 1 fixed, 2 wall, 3 lost, 4 mirror image",
     .owner = PF_OWNER_CORE, .where = OUT},
    {.name = "id", COMPONENTS1(id), .unit = "1", .description = "stable particle id", .owner = PF_OWNER_CORE,
     .where = OUT | PF_KEY},
    /* the solver's own fields (states only) */
    {.name = "viscous_velocity", VECTOR(uv, "uv"), .unit = "m/s",
     .description = "velocity seen by viscous terms (walls: no-slip mirror velocity)", .owner = PF_OWNER_CORE,
     .where = PF_STATE},
    {.name = "volume", COMPONENTS1(vol), .unit = "m^3", .description = "volume m/rho (per unit depth)",
     .owner = PF_OWNER_CORE, .where = PF_STATE},
    {.name = "acceleration", VECTOR(acc, "a"), .unit = "m/s^2",
     .description = "ax, az; of a wall particle the force the other particles exert on it [N/m]",
     .owner = PF_OWNER_CORE, .where = PF_STATE},
    {.name = "density_rate", COMPONENTS1(drho), .unit = "kg/m^3/s", .description = "density rate",
     .owner = PF_OWNER_CORE, .where = PF_STATE},
    {.name = "tag", COMPONENTS1(tag), .unit = "1", .description = "medium index as a number, -1 for walls",
     .owner = PF_OWNER_CORE, .where = PF_STATE},
    {.name = "inverse_density", COMPONENTS1(inv_rho), .unit = "m^3/kg", .description = "1 / density",
     .owner = PF_OWNER_CORE, .where = PF_STATE},
    {.name = "inverse_mass", COMPONENTS1(inv_m), .unit = "1/kg", .description = "1 / mass, 0 for walls",
     .owner = PF_OWNER_CORE, .where = PF_STATE},
    {.name = "artificial_viscosity", COMPONENTS1(avc), .unit = "m^2/s",
     .description = "alpha_M c h of the particle's medium", .owner = PF_OWNER_CORE, .where = PF_STATE},
    {.name = "neighbours", COMPONENTS1(nneigh), .unit = "1",
     .description = "neighbours of the same medium within 2h (last force pass)", .owner = PF_OWNER_CORE,
     .where = PF_STATE},
    {.name = "viscous_increment", VECTOR(visc_dv, "visc_dv"), .unit = "m/s",
     .description = "velocity change of the last implicit viscous step (its warm start)",
     .owner = PF_OWNER_SCHEME, .needs = PARTICLE_FEATURE_IMPLICIT_VISCOUS, .where = PF_STATE},
    {.name = "viscous_stage_increment", VECTOR(visc_d1, "visc_d1"), .unit = "m/s",
     .description = "velocity change of the first stage of the last implicit viscous step",
     .owner = PF_OWNER_SCHEME, .needs = PARTICLE_FEATURE_IMPLICIT_VISCOUS, .where = PF_STATE},
    {.name = "viscous_increment_before", VECTOR(visc_dvp, "visc_dvp"), .unit = "m/s",
     .description = "viscous_increment of the step before the last", .owner = PF_OWNER_SCHEME,
     .needs = PARTICLE_FEATURE_IMPLICIT_VISCOUS, .where = PF_STATE},
    {.name = "viscous_stage_increment_before", VECTOR(visc_d1p, "visc_d1p"), .unit = "m/s",
     .description = "viscous_stage_increment of the step before the last", .owner = PF_OWNER_SCHEME,
     .needs = PARTICLE_FEATURE_IMPLICIT_VISCOUS, .where = PF_STATE},
    {.name = "stress", STRESS(stress, "s"), .unit = "Pa",
     .description = "deviatoric stress (tension positive): xx, xz, zz, yy (2D: plane strain, yy out of plane)"
#if DIM == 3
                    ", xy, yz"
#endif
     , .owner = PF_OWNER_LAW, .needs = PARTICLE_FEATURE_STRESS, .where = OUT, .csv_digits = 6},
    {.name = "wall_rough", COMPONENTS1(wall_rough), .unit = "1",
     .description = "1 for a particle of a no-slip wall (its friction applies), 0 for the others",
     .owner = PF_OWNER_CORE, .needs = PARTICLE_FEATURE_BED_FRICTION, .where = PF_STATE},
    {.name = "wall_normal", VECTOR(wall_n, "wall_n"), .unit = "1",
     .description = "a free-slip wall particle's unit normal toward the fluid, across which it mirrors "
                    "the velocity and a solid's stress (0 for the others)",
     .owner = PF_OWNER_CORE, .needs = PARTICLE_FEATURE_WALL_NORMAL, .where = PF_STATE},
    {.name = "wall_friction", COMPONENTS1(wall_friction), .unit = "1",
     .description = "a wall particle's friction coefficient tan(delta) on grains (-1: the grains' own tan(phi), -2: none)",
     .owner = PF_OWNER_CORE, .needs = PARTICLE_FEATURE_BED_FRICTION, .where = PF_STATE},
    {.name = "pore_pressure", COMPONENTS1(pore_p), .unit = "Pa",
     .description = "a grain's pore pressure p_w (>= 0) of its law's last update, left out of the bed friction's "
                    "normal force (0 for the others)",
     .owner = PF_OWNER_LAW, .needs = PARTICLE_FEATURE_BED_FRICTION, .where = PF_STATE},
    {.name = "image_of", COMPONENTS1(image_of), .unit = "1",
     .description = "a mirror image across a mirror side wall: 1 + the id of the particle it images (0 for the others)",
     .owner = PF_OWNER_CORE, .needs = PARTICLE_FEATURE_MIRROR_SIDES, .where = PF_STATE},
};

const size_t particle_field_count = sizeof particle_fields / sizeof particle_fields[0];

size_t particle_field_size(enum particle_field_type t)
{
    switch (t) {
    case PF_F64: return sizeof(double);
    case PF_U8: return sizeof(uint8_t);
    case PF_U16: return sizeof(uint16_t);
    case PF_U32: return sizeof(uint32_t);
    }
    return 0;
}

const char *particle_field_owner_name(enum particle_field_owner o)
{
    switch (o) {
    case PF_OWNER_CORE: return "core";
    case PF_OWNER_SCHEME: return "scheme";
    case PF_OWNER_LAW: return "law";
    }
    return "?";
}

const char *particle_field_column(const struct particle_field *f, unsigned c, char *buf, size_t len)
{
    const char *p = f->columns;
    for (unsigned k = 0; k < c && p; k++) {
        p = strchr(p, ',');
        if (p) p++;
    }
    if (!p || len == 0) {
        if (len) buf[0] = '\0';
        return buf;
    }
    const char *end = strchr(p, ',');
    size_t n = end ? (size_t)(end - p) : strlen(p);
    if (n >= len) n = len - 1;
    memcpy(buf, p, n);
    buf[n] = '\0';
    return buf;
}
