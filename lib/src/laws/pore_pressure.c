/* pore_pressure.c - see pore_pressure.h. */
#include "pore_pressure.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "status.h"

struct pore_columns *pore_columns_create(const struct law_setup *setup)
{
    struct pore_columns *C = calloc(1, sizeof *C);
    if (!C) return NULL;
    C->x_min = setup->x_min;
    C->dx = setup->dx;
    C->g = setup->g;
    C->nbins = (size_t)ceil((setup->x_max - setup->x_min) / setup->dx) + 1;
    C->ztop = calloc(C->nbins, sizeof(double));
    C->wet_top = calloc(C->nbins, sizeof(double));
    C->wet_rho = calloc(C->nbins, sizeof(double));
    if (!C->ztop || !C->wet_top || !C->wet_rho) {
        pore_columns_free(C);
        return NULL;
    }
    return C;
}

void pore_columns_free(struct pore_columns *C)
{
    if (!C) return;
    free(C->ztop);
    free(C->wet_top);
    free(C->wet_rho);
    free(C);
}

/* The column of x (clamped to the ends). */
static size_t bin_of(const struct pore_columns *C, double x)
{
    double b = floor((x - C->x_min) / C->dx);
    if (b < 0) b = 0;
    if (b > (double)(C->nbins - 1)) b = (double)(C->nbins - 1);
    return (size_t)b;
}

void pore_columns_tops(struct pore_columns *C, const struct particles *P, const struct medium *media)
{
    for (size_t b = 0; b < C->nbins; b++) C->ztop[b] = C->wet_top[b] = -INFINITY;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] > MIXSPH_STATE_FIXED) continue;
        const struct medium *m = &media[P->medium[i]];
        const int fluid = m->law == LAW_NEWTONIAN;
        if (!fluid && !m->granular.saturated) continue;
        const size_t b = bin_of(C, P->pos[0][i]);
        const double top = P->pos[DIM_UP][i] + 0.5 * C->dx;
        if (m->granular.saturated && top > C->ztop[b]) C->ztop[b] = top;
        if (top > C->wet_top[b]) { /* ties: the first in memory order, whatever the threads */
            C->wet_top[b] = top;
            C->wet_rho[b] = fluid ? m->rho0 : m->granular.rho_f;
        }
    }
}

/* rho_f g (top[b] - z) cos^2(alpha) below the top of column b, alpha the top's slope over the
 * columns two either side (0 where one of them is empty), 0 above the top. */
static double hydrostatic_below(const struct pore_columns *C, const double *ztop, size_t b, double rho_f, double z)
{
    const double top = ztop[b];
    if (!(top > z)) return 0.0;
    const size_t bl = b >= 2 ? b - 2 : 0, br = b + 2 < C->nbins ? b + 2 : C->nbins - 1;
    double slope = 0.0;
    if (br > bl && isfinite(ztop[bl]) && isfinite(ztop[br])) slope = (ztop[br] - ztop[bl]) / ((double)(br - bl) * C->dx);
    const double cos2 = 1.0 / (1.0 + slope * slope);
    return rho_f * C->g * (top - z) * cos2;
}

double pore_pressure(const struct pore_columns *C, const struct medium *m, double x, double z)
{
    const size_t b = bin_of(C, x);
    if (m->granular.pore_pressure == PORE_GRANULAR_COLUMN)
        return m->granular.saturated ? hydrostatic_below(C, C->ztop, b, m->granular.rho_f, z) : 0.0;
    /* free_surface: a saturated medium's pores hold its own pore fluid, a dry medium's the fluid
     * it is under */
    return hydrostatic_below(C, C->wet_top, b, m->granular.saturated ? m->granular.rho_f : C->wet_rho[b], z);
}

#define FAIL(ctx, ...) status_set((ctx)->err, (ctx)->err_len, MIXSPH_ERR_CASE, __VA_ARGS__)

mixsph_status pore_fluid_finish(struct medium *md, const struct law_finish_ctx *ctx)
{
    md->granular.pore_fluid = -1;
    const char *fluid = ctx->text(ctx->entry, "pore_fluid");
    if (fluid) {
        for (size_t k = 0; k + 1 < ctx->n_media; k++)
            if (strcmp(ctx->media[k].name, fluid) == 0) md->granular.pore_fluid = (int)k;
        if (md->granular.pore_fluid < 0 || ctx->media[md->granular.pore_fluid].law != LAW_NEWTONIAN)
            return FAIL(ctx, "%s: %s.pore_fluid: '%s' is not a fluid medium defined before this one", ctx->origin,
                        ctx->path, fluid);
    }
    if (md->granular.saturated && md->granular.pore_fluid < 0)
        return FAIL(ctx, "%s: %s.pore_fluid: missing (a saturated medium needs the name of its pore fluid)", ctx->origin,
                    ctx->path);
    const double n = md->granular.porosity;
    if (md->granular.saturated) {
        const struct medium *f = &ctx->media[md->granular.pore_fluid];
        md->granular.rho_f = f->rho0;
        md->rho0 = n * f->rho0 + (1.0 - n) * md->granular.rho_grain; /* (5), saturated */
    } else {
        md->granular.rho_f = 0.0;
        md->rho0 = (1.0 - n) * md->granular.rho_grain; /* (5), dry */
    }
    return MIXSPH_OK;
}
