/* particles.c - see particles.h. Every loop over fields walks the particle-field table. */
#include "particles.h"

#include <stdlib.h>
#include <string.h>

#include "mixsph.h"
#include "particle_fields.h"

#define PARTICLES_PAD 8

static void set_array(struct particles *P, size_t member, void *a) { memcpy((char *)P + member, &a, sizeof a); }

int particles_alloc(struct particles *P, size_t cap)
{
    if (cap < 16) cap = 16;
    /* PARTICLES_PAD zeroed elements past cap: the vectorised pair loops may read (never write)
     * up to 7 elements past a range */
    for (size_t k = 0; k < particle_field_count; k++) {
        const struct particle_field *f = &particle_fields[k];
        if (!particle_field_present(f, P->features)) continue;
        const size_t elem = particle_field_size(f->type);
        for (unsigned c = 0; c < f->components; c++) {
            char *a = realloc(particles_array(P, f->member[c]), (cap + PARTICLES_PAD) * elem);
            if (!a) return -1;
            set_array(P, f->member[c], a);
            const size_t kept = P->cap < cap ? P->cap : cap;
            memset(a + kept * elem, 0, (cap + PARTICLES_PAD - kept) * elem);
        }
    }
    P->cap = cap;
    return 0;
}

void particles_free(struct particles *P)
{
    for (size_t k = 0; k < particle_field_count; k++)
        for (unsigned c = 0; c < particle_fields[k].components; c++) free(particles_array(P, particle_fields[k].member[c]));
    memset(P, 0, sizeof *P);
}

size_t particles_push(struct particles *P, const double pos[DIM], double rho, double m, uint8_t medium, uint8_t state)
{
    if (P->n == P->cap && particles_alloc(P, 2 * P->cap) != 0) return (size_t)-1;
    const size_t i = P->n++;
    for (size_t k = 0; k < particle_field_count; k++) {
        const struct particle_field *f = &particle_fields[k];
        if (!particle_field_present(f, P->features)) continue;
        const size_t elem = particle_field_size(f->type);
        for (unsigned c = 0; c < f->components; c++) memset((char *)particles_array(P, f->member[c]) + i * elem, 0, elem);
    }
    for (int d = 0; d < DIM; d++) P->pos[d][i] = pos[d];
    P->rho[i] = rho;
    P->m[i] = m;
    P->vol[i] = m / rho;
    P->medium[i] = medium;
    P->state[i] = state;
    P->tag[i] = state == MIXSPH_STATE_WALL ? -1.0 : (double)medium;
    P->inv_rho[i] = 1.0 / rho;
    P->inv_m[i] = m > 0.0 && state != MIXSPH_STATE_WALL ? 1.0 / m : 0.0;
    P->id[i] = (uint32_t)i;
    return i;
}

/* d[k] = a[perm[k]] for elements of `elem` bytes, then back into a. */
#define GATHER(T)                                                      \
    do {                                                               \
        T *d_ = scratch, *a_ = a;                                      \
        for (size_t k = 0; k < n; k++) d_[k] = a_[perm[k]];            \
        memcpy(a_, d_, n * sizeof(T));                                 \
    } while (0)

void particles_permute(struct particles *P, const size_t *perm, void *scratch)
{
    const size_t n = P->n;
    if (n == 0) return;
    for (size_t k = 0; k < particle_field_count; k++) {
        const struct particle_field *f = &particle_fields[k];
        if (!particle_field_present(f, P->features)) continue;
        for (unsigned c = 0; c < f->components; c++) {
            void *a = particles_array(P, f->member[c]);
            switch (f->type) {
            case PF_F64: GATHER(double); break;
            case PF_U8: GATHER(uint8_t); break;
            case PF_U16: GATHER(uint16_t); break;
            case PF_U32: GATHER(uint32_t); break;
            }
        }
    }
}

void particles_copy_values(struct particles *dst, const struct particles *src)
{
    for (size_t k = 0; k < particle_field_count; k++) {
        const struct particle_field *f = &particle_fields[k];
        if (!particle_field_present(f, src->features)) continue;
        for (unsigned c = 0; c < f->components; c++)
            memcpy(particles_array(dst, f->member[c]), particles_array(src, f->member[c]),
                   src->n * particle_field_size(f->type));
    }
}

int particles_copy(struct particles *dst, const struct particles *src)
{
    memset(dst, 0, sizeof *dst);
    dst->features = src->features;
    if (particles_alloc(dst, src->cap) != 0) return -1;
    dst->n = src->n;
    particles_copy_values(dst, src);
    return 0;
}
