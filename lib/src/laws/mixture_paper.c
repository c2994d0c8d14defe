/* mixture.c - the granular phase of the mixture model (Manenti et al. 2018, Section 2.1-2.2;
 * docs/model.md sections 5-6): strain rate, pore pressure, effective stress, the regime of every
 * granular particle (rheology.h) and the pressure of the grains held fixed.
 *
 * Called every step after the density pass and the velocity-gradient pass (forces.h), which has
 * gathered for every granular particle the
 * uncorrected velocity gradient G and the matrix L from the velocities that already felt the
 * last forces (v^{n+1/2}, see integrate.c). Then, for each granular particle:
 *   grad u = G L^-1                     (first-order correction; L ignored where det L < 0.05)
 *   sqrt(II_D), p_w, sigma' = max(p - max(p_w, 0), 0), mu_app = eps_f mu_f + sigma' sin(phi) / (2 sqrt(II_D))
 *   regime: mu_app >= mu_thr -> FIXED (mu = mu_thr, velocity set to 0, not moved next step,
 *           in dt with min(mu0, mu_thr)); mu0 < mu_app < mu_thr -> mu0; else mu_app.
 * A fixed particle still receives forces and a velocity update every step (unless its medium
 * has hold_fixed, SPHERA's rule: then no acceleration, velocity exactly 0), so it is mobilised
 * again as soon as its neighbours shear it enough. The pore pressure of a saturated medium is
 * hydrostatic below the top of its saturated column: p_w = rho_f g (z_top - z) cos^2(alpha),
 * z_top the highest particle of a saturated medium in the particle's dx-wide column, alpha the
 * slope of z_top over +-2 columns. The pressure of a fixed particle follows the mobile granular
 * particles around it (the paper), extrapolated hydrostatically as at walls:
 *   p_i = sum_j (p_j + rho_j g (z_j - z_i)) W_ij / sum_j W_ij  over mobile granular j;
 * with no such neighbour it keeps the pressure of its own density. A medium with
 * `tension_cutoff` (an option; the paper's model has none) has its pressure floored at the
 * background pressure here and in the equation of state (integrate.c).
 *
 * Fixed bed (numerics.fixed_bed_speed = v_fb >= 0; off by default): SPHERA's rule for a granular
 * bed without an erosion criterion (its erosion_flag 1 with velocity_fixed_bed = v_fb; docs/model.md
 * section 6 calls it an optimisation, not part of the model). In every vertical column 2h wide
 * (from the domain's x_min) the highest granular particle no faster than v_fb is the top of the
 * fixed bed (a grain held fixed at the last regime decision counts as at rest); every grain of
 * the column more than 2h below that top is frozen whatever its rheology says: FIXED (velocity
 * 0, not moved, mu = mu_thr) with the hydrostatic pressure of the top particle,
 *   p_i = p_top + rho0_top g (z_top - z_i),
 * and the density of that pressure (SPHERA also adds the kinetic pressure of the two particles'
 * relative velocity, below 1 Pa here: left out). A column without such a particle has no fixed
 * bed. */
#include <math.h>
#include <stdlib.h>

#include "mixture_paper.h"

#include <string.h>

#include "eos.h"
#include "geometry.h"
#include "mixsph.h"
#include "pore_pressure.h"
#include "rheology.h"
#include "status.h"
#include "team.h"

/* ---- its case keys: media.<name> of type granular ------------------------------------------- */

static const struct case_choice granular_type[] = {{"granular", LAW_MIXTURE_PAPER}, {NULL, 0}};

static const struct case_key granular_keys[] = {
    {.key = "type", .type = CASE_CHOICE, .need = CASE_REQUIRED, .choices = granular_type,
     .field = CASE_FIELD(medium, law), .meaning = "\"granular\": a mixture at the packing limit"},
    {.key = "law", .type = CASE_CHOICE, .choices = law_granular_choices, .numeric_choice = CASE_CHOICE_BY_POSITION,
     SCHEMA_DEF(LAW_MIXTURE_PAPER), .def_text = "this law when the medium gives mu_thr or mu1, else elastic_plastic",
     .field = CASE_FIELD(medium, law),
     .meaning = "its material law: \"paper\" (this table) or \"elastic_plastic\" (the next); chosen by its number "
                "(a case parameter), the medium may hold the other law's keys too (below)"},
    {.key = "rho", .type = CASE_NUMBER, .need = CASE_REQUIRED, SCHEMA_RANGE(0, 1, 1e5, 0), .unit = "kg/m³",
     .field = CASE_FIELD(medium, granular.rho_grain), .meaning = "density of the grains ρ_s"},
    {.key = "K", .type = CASE_NUMBER, .need = CASE_SOMETIMES, .need_text = "one of K, c", SCHEMA_RANGE(0, 1, 1e12, 0),
     .unit = "Pa", .field = CASE_FIELD(medium, bulk_modulus), .meaning = "bulk modulus of the grains K_s: c = √(K_s/ρ_s)"},
    {.key = "c", .type = CASE_NUMBER, .need = CASE_SOMETIMES, .need_text = "one of K, c", SCHEMA_RANGE(0, 1, 1e5, 0),
     .unit = "m/s", .field = CASE_FIELD(medium, c), .meaning = "sound speed"},
    {.key = "porosity", .type = CASE_NUMBER, .need = CASE_REQUIRED, SCHEMA_RANGE(0, 1, 0.95, 0), .unit = "-",
     .field = CASE_FIELD(medium, granular.porosity), .meaning = "porosity n = ε_f at the packing limit"},
    {.key = "phi", .type = CASE_NUMBER, .need = CASE_REQUIRED, SCHEMA_RANGE(0, 1, 89, 0), .unit = "deg",
     .field = CASE_FIELD(medium, granular.phi_deg), .meaning = "angle of internal friction φ"},
    {.key = "saturated", .type = CASE_BOOL, SCHEMA_DEF(0), .field = CASE_FIELD(medium, granular.saturated),
     .meaning = "pores filled with the pore fluid (else dry)"},
    {.key = "pore_fluid", .type = CASE_NAME, .need = CASE_SOMETIMES, .need_text = "if saturated",
     .meaning = "name of a fluid medium defined before this one"},
    PORE_PRESSURE_KEY,
    {.key = "mu_thr", .type = CASE_NUMBER, .need = CASE_SOMETIMES, .need_text = "unless mu1", SCHEMA_RANGE(0, 1, 1e12, 0),
     .unit = "Pa s", .field = CASE_FIELD(medium, paper.mu_thr),
     .meaning = "threshold viscosity μ_thr: a grain with μ_app ≥ μ_thr is held fixed"},
    {.key = "mu0", .type = CASE_NUMBER, SCHEMA_RANGE(0, 1, 1e12, 0), SCHEMA_DEF(INFINITY), .def_text = "+∞ (no limit)",
     .unit = "Pa s", .field = CASE_FIELD(medium, paper.mu0),
     .meaning = "limiting viscosity μ0: μ_app between μ0 and μ_thr is replaced by μ0; μ0 ≥ μ_thr: no limit"},
    {.key = "mu1", .type = CASE_NUMBER, SCHEMA_RANGE(0, 1, 1e12, 0), .unit = "Pa s",
     .meaning = "instead of mu_thr and mu0: the rheology of Run 7, μ_thr = μ1 without a limit"},
    {.key = "tension_cutoff", .type = CASE_BOOL, SCHEMA_DEF(0), .field = CASE_FIELD(medium, tension_cutoff),
     .meaning = "no tensile pressure: p below the background pressure is raised to it, as a cohesionless "
                "medium carries no tension (below); false: the paper's model, whose equation of state pulls "
                "grains together in tension"},
    {.key = "hold_fixed", .type = CASE_BOOL, SCHEMA_DEF(0), .field = CASE_FIELD(medium, paper.hold_fixed),
     .meaning = "a grain held fixed gets no acceleration (below)"},
    {.key = "alpha_m", .type = CASE_NUMBER, SCHEMA_RANGE(0, 0, 10, 0), SCHEMA_DEF(0), .unit = "-",
     .field = CASE_FIELD(medium, alpha_m), .meaning = "Monaghan artificial viscosity coefficient α_M of the grains"},
};

static const struct case_refused granular_refused[] = {
    {"d50", "not used by the model: the packing-limit law of the mixture has no grain size (docs/model.md "
            "sections 5-6); remove the key"},
    {NULL, NULL}};

static const struct case_section granular_section = {
    SCHEMA_SECTION("media.granular", "media.<name> of type granular", granular_keys), .refused = granular_refused};

#define FAIL(ctx, ...) status_set((ctx)->err, (ctx)->err_len, MIXSPH_ERR_CASE, __VA_ARGS__)

/* The rules between its keys and what it derives: the sound speed of the grains, sin(phi), the
 * pore fluid, the mixture density (5), eps_f mu_f and the mu1 rheology of Run 7. */
static mixsph_status granular_finish(struct medium *md, const struct law_finish_ctx *ctx)
{
    if (ctx->given(ctx->entry, "K")) md->c = sqrt(md->bulk_modulus / md->granular.rho_grain);
    md->granular.sin_phi = sin(md->granular.phi_deg * GEOM_PI / 180.0);
    const mixsph_status st = pore_fluid_finish(md, ctx); /* the pore fluid, rho_f and (5) */
    if (st != MIXSPH_OK) return st;
    md->paper.eps_f_mu_f = md->granular.saturated ? md->granular.porosity * ctx->media[md->granular.pore_fluid].mu : 0.0;
    if (ctx->given(ctx->entry, "mu1")) {
        if (ctx->given(ctx->entry, "mu_thr") || ctx->given(ctx->entry, "mu0"))
            return FAIL(ctx, "%s: %s.mu1: the mu1 rheology (Run 7) replaces mu_thr and mu0: give mu1 alone", ctx->origin,
                        ctx->path);
        md->paper.mu_thr = ctx->number(ctx->entry, "mu1"); /* mu0 keeps its default: no limit */
        md->paper.mu1_mode = 1;
    } else if (!ctx->given(ctx->entry, "mu_thr")) {
        return FAIL(ctx, "%s: %s.mu_thr: missing (expected a number, or mu1): the paper's law, which this medium "
                         "names, holds its grains above the threshold viscosity mu_thr; without \"law\" a medium "
                         "that gives neither runs the elastic-plastic law (docs/model.md section 10)", ctx->origin,
                    ctx->path);
    }
    md->mu = 0.0; /* set by the rheology */
    md->held_takes_kicks = mixture_paper_held_grain_kicked(md, 0);
    md->held_viscosity = mixture_paper_held_viscosity(md);
    return MIXSPH_OK;
}

static double granular_wave_speed(const struct medium *m) { return m->c; }

/* ---- its state: the pore pressure's and the fixed bed's columns ---------------------------- */

struct mixture {
    const struct medium *media;
    double g, p_background, fixed_bed_speed;
    double x_min, dx, h;
    struct pore_columns *pore; /* the tops of the wet columns (the pore pressure) */
    /* numerics.fixed_bed_speed >= 0 (SPHERA's fixed bed): per column 2h wide, the highest
     * granular particle no faster than that speed (bed_ref, -1 for none) and its z [m] */
    double *bed_z;
    long *bed_ref;
    size_t nbed;
};

static void mixture_free(void *state);

static void *mixture_create(const struct law_setup *setup)
{
    struct mixture *M = calloc(1, sizeof *M);
    if (!M) return NULL;
    M->media = setup->media;
    M->g = setup->g;
    M->p_background = setup->p_background;
    M->fixed_bed_speed = setup->fixed_bed_speed;
    const double x_min = setup->x_min, x_max = setup->x_max, dx = setup->dx, h = setup->h;
    M->x_min = x_min;
    M->dx = dx;
    M->h = h;
    M->pore = pore_columns_create(setup);
    M->nbed = (size_t)ceil((x_max - x_min) / (2.0 * h)) + 1;
    M->bed_z = calloc(M->nbed, sizeof(double));
    M->bed_ref = calloc(M->nbed, sizeof(long));
    if (!M->pore || !M->bed_z || !M->bed_ref) {
        mixture_free(M);
        return NULL;
    }
    return M;
}

static void mixture_free(void *state)
{
    struct mixture *M = state;
    if (!M) return;
    pore_columns_free(M->pore);
    free(M->bed_z);
    free(M->bed_ref);
    free(M);
}

/* Column of x among n columns of the given width from the domain's x_min (clamped to the ends). */
static size_t column_of(const struct mixture *M, double x, double width, size_t n)
{
    double b = floor((x - M->x_min) / width);
    if (b < 0) b = 0;
    if (b > (double)(n - 1)) b = (double)(n - 1);
    return (size_t)b;
}

/* Fixed-bed column of x: columns 2h wide. */
static size_t bed_column(const struct mixture *M, double x)
{
    return column_of(M, x, 2.0 * M->h, M->nbed);
}

/* Top of the fixed bed in every column: the highest granular particle no faster than
 * fixed_bed_speed (a grain fixed at the last decision counts as at rest); ties go to the first
 * in memory order, so the choice does not depend on the threads. */
static void fixed_bed_tops(struct mixture *M, const struct particles *P, size_t n)
{
    const double v2 = M->fixed_bed_speed * M->fixed_bed_speed;
    for (size_t b = 0; b < M->nbed; b++) {
        M->bed_z[b] = -INFINITY;
        M->bed_ref[b] = -1;
    }
    for (size_t i = 0; i < n; i++) {
        if (P->state[i] > MIXSPH_STATE_FIXED || M->media[P->medium[i]].law != LAW_MIXTURE_PAPER) continue;
        double u2 = 0.0;
        for (int d = 0; d < DIM; d++) u2 += P->vel[d][i] * P->vel[d][i];
        if (P->state[i] == MIXSPH_STATE_MOBILE && u2 > v2) continue;
        const size_t b = bed_column(M, P->pos[0][i]);
        if (P->pos[DIM_UP][i] > M->bed_z[b]) {
            M->bed_z[b] = P->pos[DIM_UP][i];
            M->bed_ref[b] = (long)i;
        }
    }
}

/* Whether grain i lies more than 2h below the top of its column's fixed bed. */
static int frozen(const struct mixture *M, const struct particles *P, size_t i)
{
    return P->pos[DIM_UP][i] < M->bed_z[bed_column(M, P->pos[0][i])] - 2.0 * M->h;
}

/* The three loops of the update in one parallel region (each waits for the one before: the
 * second reads the regimes of the first, the third the pressures of the second). */
struct mixture_region {
    struct mixture *M;
    const struct law_step *step;
    int fixed_bed;
    long fixed; /* + over the threads */
};

static void mixture_region(void *arg, int tid, int nth)
{
    struct mixture_region *R = arg;
    struct mixture *M = R->M;
    const struct law_step *step = R->step;
    const struct kernel *KW = step->K;
    const struct gather *G = step->G;
    struct particles *P = step->P;
    const struct medium *media = M->media;
    const int fixed_bed = R->fixed_bed;
    const double g = M->g, pb = M->p_background;
    size_t b, e;
    team_share(step->n, tid, nth, &b, &e);
    long fixed = 0;
    for (size_t i = b; i < e; i++) {
        /* a mirror image takes its source's regime at the refresh after the laws (mirror_sides.h) */
        if (P->state[i] == MIXSPH_STATE_WALL || P->state[i] == MIXSPH_STATE_IMAGE) continue;
        const struct medium *m = &media[P->medium[i]];
        if (m->law != LAW_MIXTURE_PAPER) continue;
        double grad[DIM * DIM];
        velocity_gradient_corrected(step->grad, i, grad);
        const double sii = rheology_sqrt_ii(grad);
        const double pw = pore_pressure(M->pore, m, P->pos[0][i], P->pos[DIM_UP][i]);
        if (P->pore_p) P->pore_p[i] = pw > 0.0 ? pw : 0.0; /* the bed friction's (passes/bed_friction.h) */
        const double sigma = rheology_effective_stress(P->p[i] - pb, pw);
        const double mu_app = rheology_apparent(sigma, m->granular.sin_phi, sii, m->paper.eps_f_mu_f, m->paper.mu_thr);
        double mu;
        int fix = rheology_regime(mu_app, m->paper.mu_thr, m->paper.mu0, &mu) == RHEOLOGY_FIXED;
        if (fixed_bed && frozen(M, P, i)) {
            fix = 1;
            mu = m->paper.mu_thr;
        }
        if (fix) {
            P->state[i] = MIXSPH_STATE_FIXED;
            for (int d = 0; d < DIM; d++) P->vel[d][i] = P->uv[d][i] = 0.0;
            fixed++;
        } else {
            P->state[i] = MIXSPH_STATE_MOBILE;
        }
        P->mu[i] = mu;
    }
    team_add_long(&R->fixed, fixed);
    team_barrier(); /* the regimes, and the count of fixed grains, are complete */
    if (R->fixed == 0) return;
    /* pressure of the fixed grains from the mobile grains around them */
    for (size_t i = b; i < e; i++) {
        if (P->state[i] != MIXSPH_STATE_FIXED || (fixed_bed && frozen(M, P, i))) continue;
        const double zi = P->pos[DIM_UP][i];
        double sw = 0.0, sp = 0.0;
        const uint32_t *rng = G->rng + 2 * CELLS_ROWS_AROUND * i; /* the rows of the neighbourhood */
        for (size_t k = 0; k < 2 * CELLS_ROWS_AROUND; k += 2)
            for (size_t j = rng[k]; j < rng[k + 1]; j++) {
                if (P->state[j] != MIXSPH_STATE_MOBILE || media[P->medium[j]].law != LAW_MIXTURE_PAPER) continue;
                double r2 = 0.0;
                for (int d = 0; d < DIM; d++) r2 += (P->pos[d][i] - P->pos[d][j]) * (P->pos[d][i] - P->pos[d][j]);
                if (r2 >= KW->r2max) continue;
                const double w = kernel_w(KW, sqrt(r2));
                sw += w;
                sp += (P->p[j] + P->rho[j] * g * (P->pos[DIM_UP][j] - zi)) * w;
            }
        if (sw > 0.0) {
            const double p = sp / sw;
            P->p[i] = media[P->medium[i]].tension_cutoff && p < pb ? pb : p;
        }
    }
    if (!fixed_bed) return;
    team_barrier();
    /* the frozen grains: hydrostatic from the top of their column's fixed bed (its pressure is
     * final: the top is never frozen, and its extrapolation above is done) */
    for (size_t i = b; i < e; i++) {
        if (P->state[i] != MIXSPH_STATE_FIXED || !frozen(M, P, i)) continue;
        const size_t top = (size_t)M->bed_ref[bed_column(M, P->pos[0][i])];
        const struct medium *m = &media[P->medium[i]];
        double p = P->p[top] + media[P->medium[top]].rho0 * g * (P->pos[DIM_UP][top] - P->pos[DIM_UP][i]);
        if (m->tension_cutoff && p < pb) p = pb;
        P->p[i] = p;
        P->rho[i] = eos_density(p - pb, m->rho0, m->c);
        P->inv_rho[i] = 1.0 / P->rho[i];
        P->vol[i] = P->m[i] * P->inv_rho[i];
    }
}

static long mixture_update(void *state, const struct law_step *step)
{
    struct mixture *M = state;
    struct particles *P = step->P;
    pore_columns_tops(M->pore, P, M->media);
    struct mixture_region R = {.M = M, .step = step, .fixed_bed = M->fixed_bed_speed >= 0.0};
    if (R.fixed_bed) fixed_bed_tops(M, P, step->n);
    team_run(step->n_threads, mixture_region, &R);
    return R.fixed;
}

const struct material_law law_mixture_paper = {
    .type = "granular",
    .name = "paper",
    .keys = &granular_section,
    .features = LAW_USES_GRADIENT | LAW_HOLDS_PARTICLES | LAW_WALL_FRICTION_GIVEN,
    .finish = granular_finish,
    .wave_speed = granular_wave_speed,
    .viscosity_bound = mixture_paper_held_viscosity,
    .create = mixture_create,
    .destroy = mixture_free,
    .update = mixture_update,
};
