/* law_registry.c - one line per material law, in the order of enum law_id (medium.h). */
#include "law_registry.h"

#include <math.h>

extern const struct material_law law_newtonian, law_mixture_paper, law_elastic_solid, law_elastic_plastic;

static const struct material_law *const laws[LAW_COUNT] = {
    [LAW_NEWTONIAN] = &law_newtonian,
    [LAW_MIXTURE_PAPER] = &law_mixture_paper,
    [LAW_ELASTIC_SOLID] = &law_elastic_solid,
    [LAW_ELASTIC_PLASTIC] = &law_elastic_plastic,
};

const struct material_law *law_get(int id) { return id >= 0 && id < LAW_COUNT ? laws[id] : NULL; }

int law_unnamed(int law, int (*given)(const void *entry, const char *key), const void *entry)
{
    if (law == LAW_MIXTURE_PAPER && !given(entry, "mu_thr") && !given(entry, "mu1")) return LAW_ELASTIC_PLASTIC;
    return law;
}

double law_max_wave_speed(const struct medium *media, size_t n_media)
{
    double c = 0.0;
    for (size_t k = 0; k < n_media; k++) c = fmax(c, laws[media[k].law]->wave_speed(&media[k]));
    return c;
}
