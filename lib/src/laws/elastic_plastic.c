/* elastic_plastic.c - the elastic-perfectly-plastic granular law (media of type "granular" with
 * law "elastic_plastic"; docs/model.md section 10): inside the Drucker-Prager cone the grains are
 * an elastic solid, on it they flow with the Coulomb stress, so a heap stands and a deposit stops
 * with no hold rule, no mu_thr and no mu0, at the acoustic time step. Per grain and step:
 *   s <- Jaumann step of s with G over dt (elasticity.h),
 *   p' = p - p_b - max(p_w, 0) (the effective pressure; p_w the pore pressure [PW] of a
 *        saturated medium, pore_pressure.h, 0 when dry),
 *   (s, p') <- the return mapping onto the cone with the tension cut-off at its apex
 *              (drucker_prager.h); at the apex the pressure is set to p' + p_b + max(p_w, 0),
 * the pressure coming from the equation of state of the grains' sound speed (K = rho0 c^2, the
 * mixture density rho0 of (5)), the shear modulus from Poisson's ratio, G = 3 K (1 - 2 nu) /
 * (2 (1 + nu)). No viscosity (mu = 0): the waves are damped by Monaghan's artificial viscosity
 * with alpha_M c = c_p (fixed, below).
 * With rate_dependent the cone's strength grows with the plastic shear rate, mu(I) (mu_i.h,
 * docs/model.md [MI]): the trial returns onto the cone of cohesion k_c + dS, dS its step's rate
 * strength, so that the static cone (I -> 0) is today's law bit for bit.
 * Walls: the rough walls' stress and their friction are the momentum pass's (docs/model.md
 * [DP-W]). Experimental: the bundled cases keep the paper's law. */
#include <math.h>

#include "drucker_prager.h"
#include "elasticity.h"
#include "geometry.h"
#include "law.h"
#include "mu_i.h"
#include "pore_pressure.h"
#include "status.h"
#include "team.h"

static const struct case_choice granular_ep_type[] = {{"granular", LAW_ELASTIC_PLASTIC}, {NULL, 0}};
static const struct case_choice water_couplings[] = {
    {"mixture", WATER_COUPLING_MIXTURE}, {"grains", WATER_COUPLING_GRAINS}, {NULL, 0}};

static const struct case_key elastic_plastic_keys[] = {
    {.key = "type", .type = CASE_CHOICE, .need = CASE_REQUIRED, .choices = granular_ep_type,
     .field = CASE_FIELD(medium, law), .meaning = "\"granular\""},
    {.key = "law", .type = CASE_CHOICE, .choices = law_granular_choices, .numeric_choice = CASE_CHOICE_BY_POSITION,
     SCHEMA_DEF(LAW_ELASTIC_PLASTIC), .def_text = "this law when the medium gives neither mu_thr nor mu1",
     .field = CASE_FIELD(medium, law),
     .meaning = "\"elastic_plastic\" (this table): Drucker-Prager; chosen by its number (a case parameter), the "
                "medium may hold the paper law's keys too (above)"},
    {.key = "rho", .type = CASE_NUMBER, .need = CASE_REQUIRED, SCHEMA_RANGE(0, 1, 1e5, 0), .unit = "kg/m³",
     .field = CASE_FIELD(medium, granular.rho_grain), .meaning = "density of the grains ρ_s"},
    {.key = "K", .type = CASE_NUMBER, .need = CASE_SOMETIMES, .need_text = "one of K, c", SCHEMA_RANGE(0, 1, 1e12, 0),
     .unit = "Pa", .field = CASE_FIELD(medium, bulk_modulus),
     .meaning = "bulk modulus of the grains K_s: c = √(K_s/ρ_s); the law's bulk modulus is ρ0 c²"},
    {.key = "c", .type = CASE_NUMBER, .need = CASE_SOMETIMES, .need_text = "one of K, c", SCHEMA_RANGE(0, 1, 1e5, 0),
     .unit = "m/s", .field = CASE_FIELD(medium, c), .meaning = "sound speed"},
    {.key = "porosity", .type = CASE_NUMBER, .need = CASE_REQUIRED, SCHEMA_RANGE(0, 1, 0.95, 0), .unit = "-",
     .field = CASE_FIELD(medium, granular.porosity), .meaning = "porosity n: the mixture density (5)"},
    {.key = "phi", .type = CASE_NUMBER, .need = CASE_REQUIRED, SCHEMA_RANGE(0, 1, 89, 0), .unit = "deg",
     .field = CASE_FIELD(medium, granular.phi_deg), .meaning = "angle of internal friction φ"},
    {.key = "cohesion", .type = CASE_NUMBER, SCHEMA_RANGE(0, 0, 1e9, 0), SCHEMA_DEF(0), .unit = "Pa",
     .field = CASE_FIELD(medium, dp.cohesion), .meaning = "cohesion c of the cone"},
    {.key = "dilatancy", .type = CASE_NUMBER, SCHEMA_RANGE(0, 0, 0, 0), SCHEMA_DEF(0), .unit = "deg",
     .field = CASE_FIELD(medium, dp.dilatancy_deg),
     .meaning = "dilatancy angle ψ (0 only: a dilating return changes the pressure, which the equation of state "
                "would undo)"},
    {.key = "nu", .type = CASE_NUMBER, SCHEMA_RANGE(0, 0, 0.49, 0), SCHEMA_DEF(0.3), .unit = "-",
     .field = CASE_FIELD(medium, elastic.poisson), .meaning = "Poisson's ratio: G = 3K(1−2ν)/(2(1+ν))"},
    {.key = "saturated", .type = CASE_BOOL, SCHEMA_DEF(0), .field = CASE_FIELD(medium, granular.saturated),
     .meaning = "pores filled with the pore fluid (else dry): yield on the effective stress of the pore pressure [PW]"},
    {.key = "pore_fluid", .type = CASE_NAME, .need = CASE_SOMETIMES, .need_text = "if saturated",
     .meaning = "name of a fluid medium defined before this one"},
    PORE_PRESSURE_KEY,
    {.key = "water_coupling", .type = CASE_CHOICE, SCHEMA_DEF(WATER_COUPLING_MIXTURE), .choices = water_couplings,
     .numeric_choice = CASE_CHOICE_BY_VALUE, .field = CASE_FIELD(medium, granular.water_coupling),
     .meaning = "how a grain particle meets a fluid particle: mixture (0), as one continuum, its own pressure and "
                "stress in the pair (model.md [WG]); grains (1), a parcel of grains in the water: the water's "
                "pressure interpolated at it, no stress, Ergun's drag with grain_diameter (model.md [GW])"},
    {.key = "grain_diameter", .type = CASE_NUMBER, .need = CASE_SOMETIMES, .need_text = "if water_coupling is grains",
     SCHEMA_RANGE(0, 1, 1, 0), .def_text = "with rate_dependent: 0.0005 (Jop et al. 2006's glass beads)", .unit = "m",
     .field = CASE_FIELD(medium, granular.grain_diameter),
     .meaning = "diameter d of the grains: the drag of the water through them (water_coupling grains), the inertial "
                "number I of rate_dependent"},
    {.key = "rate_dependent", .type = CASE_BOOL, SCHEMA_DEF(0), .field = CASE_FIELD(medium, mu_i.on),
     .meaning = "friction μ(I) = μ_s + Δμ I/(I + I_0) on the cone, of the inertial number I = γ̇_p d/√(p'/ρ_s) "
                "(model.md [MI]; μ_s the static cone's, sin φ); else the static cone alone"},
    {.key = "delta_mu", .type = CASE_NUMBER, SCHEMA_RANGE(0, 0, 2, 0), SCHEMA_DEF(0.26), .unit = "-",
     .field = CASE_FIELD(medium, mu_i.delta_mu),
     .meaning = "Δμ = μ_2 − μ_s of rate_dependent (Jop, Forterre & Pouliquen 2006, glass beads: tan 32.76° − tan "
                "20.9° = 0.26)"},
    {.key = "I0", .type = CASE_NUMBER, SCHEMA_RANGE(0, 1, 10, 0), SCHEMA_DEF(0.279), .unit = "-",
     .field = CASE_FIELD(medium, mu_i.I0),
     .meaning = "I_0 of rate_dependent: the inertial number at which half of Δμ is reached (Jop et al. 2006)"},
};

static const struct case_section elastic_plastic_section = {
    SCHEMA_SECTION("media.granular.elastic_plastic", "media.<name> of type granular, law elastic_plastic",
                   elastic_plastic_keys)};

/* The grain diameter of rate_dependent when the medium gives none [m]: the glass beads whose mu(I)
 * Jop, Forterre & Pouliquen (2006) measured, as delta_mu and I0 are theirs. */
#define MU_I_GRAIN_DIAMETER 0.5e-3

#define FAIL(ctx, ...) status_set((ctx)->err, (ctx)->err_len, MIXSPH_ERR_CASE, __VA_ARGS__)

static mixsph_status elastic_plastic_finish(struct medium *m, const struct law_finish_ctx *ctx)
{
    if (ctx->given(ctx->entry, "K")) m->c = sqrt(m->bulk_modulus / m->granular.rho_grain);
    const mixsph_status st = pore_fluid_finish(m, ctx); /* the pore fluid, rho_f and the mixture density (5) */
    if (st != MIXSPH_OK) return st;
    m->bulk_modulus = m->rho0 * m->c * m->c;      /* the equation of state's */
    const char *why = elasticity_shear_from_bulk(m->bulk_modulus, m->elastic.poisson, &m->elastic.shear_modulus);
    if (!why)
        why = drucker_prager_matching(m->granular.phi_deg * GEOM_PI / 180.0, m->dp.cohesion, m->dp.dilatancy_deg * GEOM_PI / 180.0,
                                      &m->dp.alpha_phi, &m->dp.k_c, &m->dp.alpha_psi);
    if (why) return FAIL(ctx, "%s: %s: %s", ctx->origin, ctx->path, why);
    m->granular.sin_phi = sin(m->granular.phi_deg * GEOM_PI / 180.0);
    if (m->granular.water_coupling == WATER_COUPLING_GRAINS) {
        if (!ctx->given(ctx->entry, "grain_diameter"))
            return FAIL(ctx, "%s: %s.grain_diameter: missing (water_coupling \"grains\" needs the grains' diameter "
                        "for their drag)", ctx->origin, ctx->path);
        /* Ergun's drag per unit volume of a packed bed of porosity n (Gidaspow 1994, eq. 5.64 for
         * n < 0.8): beta = 150 (1-n)^2 mu_f / (n d^2) + 1.75 (1-n) rho_f |u_f - u_s| / d */
        const double n = m->granular.porosity, d = m->granular.grain_diameter;
        m->granular.drag_viscous = 150.0 * (1.0 - n) * (1.0 - n) / (n * d * d);
        m->granular.drag_inertial = 1.75 * (1.0 - n) / d;
        m->features |= LAW_GRAINS_IN_WATER;
    } else if (ctx->given(ctx->entry, "grain_diameter") && !m->mu_i.on) {
        return FAIL(ctx, "%s: %s.grain_diameter: used only with water_coupling \"grains\" (the mixture coupling has "
                    "no drag of its own) or rate_dependent", ctx->origin, ctx->path);
    }
    if (m->mu_i.on && !ctx->given(ctx->entry, "grain_diameter")) m->granular.grain_diameter = MU_I_GRAIN_DIAMETER;
    if (!m->mu_i.on) {
        const char *unused = ctx->given(ctx->entry, "delta_mu") ? "delta_mu" : ctx->given(ctx->entry, "I0") ? "I0" : NULL;
        if (unused)
            return FAIL(ctx, "%s: %s.%s: a parameter of the rate-dependent friction, used only with "
                        "\"rate_dependent\": true", ctx->origin, ctx->path, unused);
    }
    m->mu = 0.0;
    /* The grains' dissipation (docs/model.md [DP-AV]): Monaghan's term with alpha_M c = c_p, the
     * acoustic impedance rho c_p of the P wave on the approach speed of a pair, as a linearised
     * Riemann solver has it; a fixed numerical parameter, not a case key. */
    m->alpha_m = elasticity_wave_speed(m->bulk_modulus, m->elastic.shear_modulus, m->rho0) / m->c;
    return MIXSPH_OK;
}

static double elastic_plastic_wave_speed(const struct medium *m)
{
    return elasticity_wave_speed(m->bulk_modulus, m->elastic.shear_modulus, m->rho0);
}

static double elastic_plastic_viscosity_bound(const struct medium *m)
{
    (void)m;
    return 0.0;
}

/* Its state: the tops of the saturated columns (the pore pressure). */
static void *elastic_plastic_create(const struct law_setup *setup) { return pore_columns_create(setup); }

static void elastic_plastic_destroy(void *state) { pore_columns_free(state); }

struct plastic_loop {
    const struct law_step *step;
    const struct pore_columns *pore;
    long plastic; /* + over the threads */
};

static void plastic_range(void *arg, size_t b, size_t e)
{
    struct plastic_loop *L = arg;
    const struct law_step *step = L->step;
    const struct pore_columns *pore = L->pore;
    struct particles *P = step->P;
    const struct medium *media = step->media;
    const double dt = step->dt, pb = step->p_background;
    long plastic = 0;
    for (size_t i = b; i < e; i++) {
        if (P->state[i] > MIXSPH_STATE_FIXED) continue;
        const struct medium *m = &media[P->medium[i]];
        if (m->law != LAW_ELASTIC_PLASTIC) continue;
        double g[DIM * DIM];
        velocity_gradient_corrected(step->grad, i, g);
        struct deviatoric_stress s = deviatoric_stress_load(P->stress, i);
        elasticity_jaumann_step(&s, g, m->elastic.shear_modulus, dt);
        struct drucker_prager_material dp = {.K = m->bulk_modulus, .G = m->elastic.shear_modulus,
                                             .alpha_phi = m->dp.alpha_phi, .k_c = m->dp.k_c,
                                             .alpha_psi = m->dp.alpha_psi};
        const double pw = fmax(pore_pressure(pore, m, P->pos[0][i], P->pos[DIM_UP][i]), 0.0);
        if (P->pore_p) P->pore_p[i] = pw; /* the bed friction's (passes/bed_friction.h) */
        double p_eff = P->p[i] - pb - pw;
        if (m->mu_i.on) /* mu(I): the cone widened by the step's rate strength (mu_i.h; psi = 0) */
            dp.k_c += mu_i_strength_increment(drucker_prager_sqrt_j2(&s), 3.0 * dp.alpha_phi * p_eff + dp.k_c, p_eff,
                                              dp.G * dt, m->granular.grain_diameter, m->granular.rho_grain, &m->mu_i);
        const enum drucker_prager_outcome out = drucker_prager_return(&s, &p_eff, &dp);
        if (out == DRUCKER_PRAGER_APEX) P->p[i] = p_eff + pb + pw; /* the tension cut-off */
        plastic += out != DRUCKER_PRAGER_ELASTIC;
        deviatoric_stress_store(&s, P->stress, i);
    }
    team_add_long(&L->plastic, plastic);
}

/* The per-step update: see the head of this file. Returns the grains on the cone or its apex. */
static long elastic_plastic_update(void *state, const struct law_step *step)
{
    struct pore_columns *pore = state;
    if (!(step->dt > 0.0)) return 0;
    pore_columns_tops(pore, step->P, step->media); /* (of the fluids and saturated media, of any law) */
    struct plastic_loop L = {.step = step, .pore = pore};
    team_for(step->n_threads, step->n, plastic_range, &L);
    return L.plastic;
}

const struct material_law law_elastic_plastic = {
    .type = "granular",
    .name = "elastic_plastic",
    .keys = &elastic_plastic_section,
    .features = LAW_USES_GRADIENT | LAW_HAS_STRESS | LAW_CAPS_TENSION | LAW_WALL_FRICTION,
    .finish = elastic_plastic_finish,
    .wave_speed = elastic_plastic_wave_speed,
    .viscosity_bound = elastic_plastic_viscosity_bound,
    .create = elastic_plastic_create,
    .destroy = elastic_plastic_destroy,
    .update = elastic_plastic_update,
};
