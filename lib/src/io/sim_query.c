/* sim_query.c - read-only questions a host asks about a simulation or a case file before or
 * while it drives it (the FMU: which walls move and which way, which parameters a case lets a
 * host set) and its particle fields by the particle-field table. Nothing here changes a
 * simulation. See the last section of mixsph.h. */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "law_registry.h"
#include "particle_fields.h"
#include "sim.h"
#include "status.h"

mixsph_status mixsph_sim_case_number(const mixsph_sim *s, const char *key, double *value)
{
    if (!s || !key || !value) return MIXSPH_ERR_ARG;
    char unused[160]; /* s is the host's to read: it keeps no message of a query */
    return case_number(&s->cfg, key, value, unused, sizeof unused);
}

size_t mixsph_sim_wall_count(const mixsph_sim *s)
{
    return s ? s->cfg.n_walls : 0;
}

const char *mixsph_sim_wall_name(const mixsph_sim *s, size_t k)
{
    return s && k < s->cfg.n_walls ? s->cfg.walls[k].name : NULL;
}

size_t mixsph_sim_medium_count(const mixsph_sim *s)
{
    return s ? s->cfg.n_media : 0;
}

const char *mixsph_sim_medium_name(const mixsph_sim *s, size_t k)
{
    return s && k < s->cfg.n_media ? s->cfg.media[k].name : NULL;
}

const char *mixsph_sim_medium_law(const mixsph_sim *s, size_t k)
{
    return s && k < s->cfg.n_media ? law_get(s->cfg.media[k].law)->name : NULL;
}

int mixsph_sim_wall_moves(const mixsph_sim *s, size_t k)
{
    return s && k < s->cfg.n_walls && s->cfg.walls[k].motion >= 0;
}

mixsph_status mixsph_sim_wall_travel_direction(const mixsph_sim *s, size_t k, double *ux, double *uz)
{
    if (!s || !ux || !uz) return MIXSPH_ERR_ARG;
    *ux = *uz = 0.0;
    if (k >= s->cfg.n_walls || s->cfg.walls[k].motion < 0) return MIXSPH_ERR_ARG;
    /* The law's own rows, before its speed and time scales: the scales stretch a law, they do not
     * turn it, and a speed scale of 0 would otherwise leave no direction at all. The first row
     * of largest speed wins, so a law that reverses travels the way it goes fastest. */
    const struct motion *law = &s->cfg.motions[s->cfg.walls[k].motion];
    double fastest = 0.0;
    for (size_t row = 0; row < law->n; row++) {
        const double speed = hypot(law->vx[row], law->vz[row]);
        if (speed > fastest) {
            fastest = speed;
            *ux = law->vx[row] / speed;
            *uz = law->vz[row] / speed;
        }
    }
    return fastest > 0.0 ? MIXSPH_OK : MIXSPH_ERR_ARG;
}

/* The `parameters` object of the case file at path (parsed into *root, which the caller
 * deletes), or NULL when the case has none. */
static mixsph_status read_parameters_block(const char *path, cJSON **root, const cJSON **params, char *err,
                                           size_t err_len)
{
    *root = NULL;
    *params = NULL;
    if (!path) return status_set(err, err_len, MIXSPH_ERR_ARG, "no case file given");
    char *text = NULL;
    const mixsph_status st = case_read_file(path, &text, err, err_len);
    if (st != MIXSPH_OK) return st;
    *root = cJSON_Parse(text);
    free(text);
    if (!*root) return status_set(err, err_len, MIXSPH_ERR_CASE, "%s: not valid JSON", path);
    const cJSON *p = cJSON_GetObjectItemCaseSensitive(*root, "parameters");
    *params = cJSON_IsObject(p) ? p : NULL;
    return MIXSPH_OK;
}

mixsph_status mixsph_case_declares_parameter(const char *case_path, const char *name, int *declared, char *err,
                                             size_t err_len)
{
    if (!name || !declared) return status_set(err, err_len, MIXSPH_ERR_ARG, "mixsph_case_declares_parameter: NULL argument");
    *declared = 0;
    cJSON *root;
    const cJSON *params;
    const mixsph_status st = read_parameters_block(case_path, &root, &params, err, err_len);
    if (st != MIXSPH_OK) return st;
    *declared = cJSON_IsNumber(cJSON_GetObjectItemCaseSensitive(params, name));
    cJSON_Delete(root);
    return MIXSPH_OK;
}

mixsph_status mixsph_case_parameter_names(const char *case_path, char *names, size_t names_len, size_t *n,
                                          char *err, size_t err_len)
{
    if (!names || names_len == 0 || !n)
        return status_set(err, err_len, MIXSPH_ERR_ARG, "mixsph_case_parameter_names: NULL argument");
    names[0] = '\0';
    *n = 0;
    cJSON *root;
    const cJSON *params;
    const mixsph_status st = read_parameters_block(case_path, &root, &params, err, err_len);
    if (st != MIXSPH_OK) return st;
    size_t used = 0;
    for (const cJSON *p = params ? params->child : NULL; p; p = p->next) {
        if (!cJSON_IsNumber(p) || !p->string) continue;
        const int w = snprintf(names + used, names_len - used, "%s%s", *n ? ", " : "", p->string);
        (*n)++;
        used = w < 0 || used + (size_t)w >= names_len ? names_len - 1 : used + (size_t)w;
    }
    cJSON_Delete(root);
    return MIXSPH_OK;
}

/* ---- particle fields: the rows of the particle-field table marked PF_VIEW the simulation has -- */

_Static_assert(PARTICLE_FIELD_MAX_COMPONENTS == MIXSPH_FIELD_MAX_COMPONENTS, "the view holds every component");

static const struct particle_field *view_field(const mixsph_sim *s, size_t k)
{
    for (size_t r = 0; r < particle_field_count; r++) {
        const struct particle_field *f = &particle_fields[r];
        if ((f->where & PF_VIEW) && particle_field_present(f, s->phys.P.features) && k-- == 0) return f;
    }
    return NULL;
}

size_t mixsph_sim_particle_field_count(const mixsph_sim *s)
{
    size_t n = 0;
    while (s && view_field(s, n)) n++;
    return n;
}

static void view_fill(const mixsph_sim *s, const struct particle_field *pf, mixsph_particle_field *f)
{
    static const mixsph_field_type types[] = {[PF_F64] = MIXSPH_FIELD_F64, [PF_U8] = MIXSPH_FIELD_U8,
                                              [PF_U16] = MIXSPH_FIELD_U16, [PF_U32] = MIXSPH_FIELD_U32};
    memset(f, 0, sizeof *f);
    f->name = pf->name;
    f->columns = pf->columns;
    f->unit = pf->unit;
    f->description = pf->description;
    f->owner = particle_field_owner_name(pf->owner);
    f->components = pf->components;
    f->type = types[pf->type];
    f->n = s->phys.P.n;
    for (unsigned c = 0; c < pf->components; c++) f->data[c] = particles_array(&s->phys.P, pf->member[c]);
}

mixsph_status mixsph_sim_particle_field(const mixsph_sim *s, size_t k, mixsph_particle_field *f)
{
    const struct particle_field *pf = s && f ? view_field(s, k) : NULL;
    if (!pf) return MIXSPH_ERR_ARG;
    view_fill(s, pf, f);
    return MIXSPH_OK;
}

mixsph_status mixsph_sim_particle_field_find(const mixsph_sim *s, const char *name, mixsph_particle_field *f)
{
    if (!s || !name || !f) return MIXSPH_ERR_ARG;
    const struct particle_field *pf;
    for (size_t k = 0; (pf = view_field(s, k)) != NULL; k++)
        if (strcmp(pf->name, name) == 0) {
            view_fill(s, pf, f);
            return MIXSPH_OK;
        }
    return MIXSPH_ERR_ARG;
}
