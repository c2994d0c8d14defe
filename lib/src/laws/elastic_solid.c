/* elastic_solid.c - the linear-elastic solid's module (elastic_solid.h): its case keys
 * (media.<name> of type elastic), its constants from Young's modulus and Poisson's ratio, its
 * wave speed and its per-step stress update. No state besides the particles' stress fields. */
#include "elastic_solid.h"

#include <math.h>

#include "status.h"

#include "elasticity.h"
#include "law.h"
#include "team.h"

static const struct case_choice elastic_type[] = {{"elastic", LAW_ELASTIC_SOLID}, {NULL, 0}};

static const struct case_key elastic_keys[] = {
    {.key = "type", .type = CASE_CHOICE, .need = CASE_REQUIRED, .choices = elastic_type,
     .field = CASE_FIELD(medium, law), .meaning = "\"elastic\": a linear-elastic solid (a test of the stress seam)"},
    {.key = "rho", .type = CASE_NUMBER, .need = CASE_REQUIRED, SCHEMA_RANGE(0, 1, 1e5, 0), .unit = "kg/m³",
     .field = CASE_FIELD(medium, rho0), .meaning = "reference density ρ0"},
    {.key = "E", .type = CASE_NUMBER, .need = CASE_REQUIRED, SCHEMA_RANGE(0, 1, 1e12, 0), .unit = "Pa",
     .field = CASE_FIELD(medium, elastic.youngs_modulus), .meaning = "Young's modulus"},
    {.key = "nu", .type = CASE_NUMBER, .need = CASE_REQUIRED, SCHEMA_RANGE(0, 0, 0.49, 0), .unit = "-",
     .field = CASE_FIELD(medium, elastic.poisson), .meaning = "Poisson's ratio ν: K = E/(3(1−2ν)) (the equation of state's), "
                                                       "G = E/(2(1+ν))"},
    {.key = "alpha_m", .type = CASE_NUMBER, SCHEMA_RANGE(0, 0, 10, 0), SCHEMA_DEF(0), .unit = "-",
     .field = CASE_FIELD(medium, alpha_m), .meaning = "Monaghan artificial viscosity coefficient α_M"},
};

static const struct case_section elastic_section = {
    SCHEMA_SECTION("media.elastic", "media.<name> of type elastic", elastic_keys)};

static mixsph_status elastic_finish(struct medium *m, const struct law_finish_ctx *ctx)
{
    const char *why = elasticity_constants(m->elastic.youngs_modulus, m->elastic.poisson, &m->bulk_modulus, &m->elastic.shear_modulus);
    if (why) return status_set(ctx->err, ctx->err_len, MIXSPH_ERR_CASE, "%s: %s: %s", ctx->origin, ctx->path, why);
    m->c = sqrt(m->bulk_modulus / m->rho0);
    m->mu = 0.0;
    return MIXSPH_OK;
}

static double elastic_wave_speed(const struct medium *m)
{
    return elasticity_wave_speed(m->bulk_modulus, m->elastic.shear_modulus, m->rho0);
}

static double elastic_viscosity_bound(const struct medium *m)
{
    (void)m;
    return 0.0;
}

/* A solid is created unloaded (density rho0, no stress): gravity then loads it. */
static double elastic_initial_pressure(const struct medium *m, double p_hydrostatic)
{
    (void)m;
    (void)p_hydrostatic;
    return 0.0;
}

static void elastic_range(void *arg, size_t b, size_t e)
{
    const struct law_step *step = arg;
    struct particles *P = step->P;
    const struct medium *media = step->media;
    const double dt = step->dt;
    for (size_t i = b; i < e; i++) {
        if (P->state[i] > MIXSPH_STATE_FIXED || media[P->medium[i]].law != LAW_ELASTIC_SOLID) continue;
        double g[DIM * DIM];
        velocity_gradient_corrected(step->grad, i, g);
        struct deviatoric_stress s = deviatoric_stress_load(P->stress, i);
        elasticity_jaumann_step(&s, g, media[P->medium[i]].elastic.shear_modulus, dt);
        deviatoric_stress_store(&s, P->stress, i);
    }
}

static long elastic_update(void *state, const struct law_step *step)
{
    (void)state;
    if (!(step->dt > 0.0)) return 0;
    team_for(step->n_threads, step->n, elastic_range, (void *)step);
    return 0;
}

const struct material_law law_elastic_solid = {
    .type = "elastic",
    .name = "linear",
    .keys = &elastic_section,
    .features = LAW_USES_GRADIENT | LAW_HAS_STRESS,
    .finish = elastic_finish,
    .wave_speed = elastic_wave_speed,
    .viscosity_bound = elastic_viscosity_bound,
    .initial_pressure = elastic_initial_pressure,
    .update = elastic_update,
};
