/* newtonian.c - the Newtonian fluid (media of type "fluid"): a constant dynamic viscosity mu
 * (the Morris Laplacian of the momentum pass, docs/model.md section 2) and the linear equation
 * of state of its sound speed; no per-particle state and no per-step update. */
#include "law.h"

static const struct case_choice fluid_type[] = {{"fluid", LAW_NEWTONIAN}, {NULL, 0}};

static const struct case_key fluid_keys[] = {
    {.key = "type", .type = CASE_CHOICE, .need = CASE_REQUIRED, .choices = fluid_type,
     .field = CASE_FIELD(medium, law), .meaning = "\"fluid\" (this table), \"granular\" or \"elastic\" (the tables below)"},
    {.key = "rho", .type = CASE_NUMBER, .need = CASE_REQUIRED, SCHEMA_RANGE(0, 1, 1e5, 0), .unit = "kg/m³",
     .field = CASE_FIELD(medium, rho0), .meaning = "reference density ρ0"},
    {.key = "K", .type = CASE_NUMBER, .need = CASE_SOMETIMES, .need_text = "one of K, c", SCHEMA_RANGE(0, 1, 1e12, 0),
     .unit = "Pa", .field = CASE_FIELD(medium, bulk_modulus), .meaning = "bulk modulus of the linear equation of state: c = √(K/ρ0)"},
    {.key = "c", .type = CASE_NUMBER, .need = CASE_SOMETIMES, .need_text = "one of K, c", SCHEMA_RANGE(0, 1, 1e5, 0),
     .unit = "m/s", .field = CASE_FIELD(medium, c), .meaning = "sound speed"},
    {.key = "mu", .type = CASE_NUMBER, SCHEMA_RANGE(0, 0, 1e9, 0), SCHEMA_DEF(0), .unit = "Pa s",
     .field = CASE_FIELD(medium, mu), .meaning = "dynamic viscosity"},
    {.key = "alpha_m", .type = CASE_NUMBER, SCHEMA_RANGE(0, 0, 10, 0), SCHEMA_DEF(0), .unit = "-",
     .field = CASE_FIELD(medium, alpha_m), .meaning = "Monaghan artificial viscosity coefficient α_M"},
};

static const struct case_section fluid_section = {
    SCHEMA_SECTION("media.fluid", "media.<name> of type fluid", fluid_keys)};

#include <math.h>

static mixsph_status fluid_finish(struct medium *m, const struct law_finish_ctx *ctx)
{
    if (ctx->given(ctx->entry, "K")) m->c = sqrt(m->bulk_modulus / m->rho0);
    return MIXSPH_OK;
}

static double fluid_wave_speed(const struct medium *m) { return m->c; }

static double fluid_viscosity_bound(const struct medium *m) { return m->mu; }

const struct material_law law_newtonian = {
    .type = "fluid",
    .name = "newtonian",
    .keys = &fluid_section,
    .features = LAW_DENSITY_DIFFUSION | LAW_FLUID,
    .finish = fluid_finish,
    .wave_speed = fluid_wave_speed,
    .viscosity_bound = fluid_viscosity_bound,
};
