/* mirror_sides.c - the images of mirror side walls (mirror_sides.h). */
#include "mirror_sides.h"

#include <stdlib.h>
#include <string.h>

#include "mixsph.h"
#include "particle_fields.h"
#include "team.h"

/* Room for n images in the lists. */
static int reserve(struct mirror_sides *M, size_t n)
{
    if (M->cap >= n) return 0;
    const size_t cap = n + n / 4 + 64;
    uint32_t *image = realloc(M->image, cap * sizeof *image);
    if (image) M->image = image;
    uint32_t *source = realloc(M->source, cap * sizeof *source);
    if (source) M->source = source;
    uint8_t *high = realloc(M->high, cap * sizeof *high);
    if (high) M->high = high;
    if (!image || !source || !high) return -1;
    M->cap = cap;
    return 0;
}

/* Particle `to` becomes the image of particle `from` across the plane y = plane: every field
 * copied, the components a reflection across y = const reverses (particle_field.y_odd) reversed,
 * the position mirrored; its own id and mark kept, its state its source's (an image of a fluid or
 * granular particle MIXSPH_STATE_IMAGE, of a wall particle a wall particle, of a lost one lost). */
static void take_image(struct particles *P, size_t from, size_t to, double plane)
{
    const uint32_t id = P->id[to], mark = P->image_of[to];
    for (size_t k = 0; k < particle_field_count; k++) {
        const struct particle_field *f = &particle_fields[k];
        if (!particle_field_present(f, P->features)) continue;
        const size_t elem = particle_field_size(f->type);
        for (unsigned c = 0; c < f->components; c++) {
            char *a = particles_array(P, f->member[c]);
            memcpy(a + to * elem, a + from * elem, elem);
            if (f->y_odd & (1u << c)) { /* y_odd rows are F64 */
                double *v = (double *)(void *)a;
                v[to] = -v[to];
            }
        }
    }
#if DIM == 3
    P->pos[1][to] += 2.0 * plane; /* -y + 2 plane: the mirror of y */
#else
    (void)plane;
#endif
    const uint8_t st = P->state[from];
    P->state[to] = st == MIXSPH_STATE_WALL || st == MIXSPH_STATE_LOST ? st : MIXSPH_STATE_IMAGE;
    P->id[to] = id;
    P->image_of[to] = mark;
}

/* Whether real particle i needs an image across the low (side 0) or high (side 1) plane. */
static int needs_image(const struct mirror_sides *M, const struct particles *P, size_t i, int side)
{
#if DIM == 3
    if (P->state[i] == MIXSPH_STATE_LOST) return 0;
    const double d = side ? M->y_hi - P->pos[1][i] : P->pos[1][i] - M->y_lo;
    return d > 0.0 && d < M->reach; /* a particle on a plane is its own image */
#else
    (void)M, (void)P, (void)i, (void)side;
    return 0;
#endif
}

/* Keep the particles with keep[i] (in their order), drop the others. Returns 0, -1 when out of
 * memory. */
static int keep_only(struct particles *P, const uint8_t *keep)
{
    size_t kept = 0;
    for (size_t i = 0; i < P->n; i++) kept += keep[i] != 0;
    if (kept == P->n) return 0;
    size_t *perm = malloc(P->n * sizeof *perm);
    double *scratch = malloc(P->n * sizeof *scratch);
    if (!perm || !scratch) {
        free(perm);
        free(scratch);
        return -1;
    }
    size_t a = 0, b = kept;
    for (size_t i = 0; i < P->n; i++) perm[keep[i] ? a++ : b++] = i;
    particles_permute(P, perm, scratch);
    free(perm);
    free(scratch);
    P->n = kept;
    return 0;
}

long mirror_sides_trim(const struct mirror_sides *M, struct particles *P)
{
    uint8_t *keep = malloc(P->n ? P->n : 1);
    if (!keep) return -1;
    long dropped = 0;
    for (size_t i = 0; i < P->n; i++) {
#if DIM == 3
        keep[i] = P->state[i] != MIXSPH_STATE_WALL || (P->pos[1][i] >= M->y_lo && P->pos[1][i] <= M->y_hi);
#else
        (void)M;
        keep[i] = 1;
#endif
        dropped += !keep[i];
    }
    const int st = keep_only(P, keep);
    free(keep);
    if (st != 0) return -1;
    for (size_t i = 0; i < P->n; i++) P->id[i] = (uint32_t)i;
    return dropped;
}

int mirror_sides_make(struct mirror_sides *M, struct particles *P)
{
    /* drop the images: the particles of the run first, in their order */
    uint8_t *keep = malloc(P->n ? P->n : 1);
    if (!keep) return -1;
    for (size_t i = 0; i < P->n; i++) keep[i] = !particles_is_image(P, i);
    const int dropped = keep_only(P, keep);
    free(keep);
    if (dropped != 0) return -1;
    if (M->n_real == 0) M->n_real = P->n; /* the first call: the run's particles */
    size_t count = 0;
    for (size_t i = 0; i < P->n; i++) count += (size_t)needs_image(M, P, i, 0) + (size_t)needs_image(M, P, i, 1);
    if (P->cap < P->n + count && particles_alloc(P, P->n + count + count / 4 + 64) != 0) return -1;
    if (reserve(M, count) != 0) return -1;
    const size_t n = P->n;
    size_t k = 0;
    for (size_t i = 0; i < n; i++)
        for (int side = 0; side < 2; side++) {
            if (!needs_image(M, P, i, side)) continue;
            const size_t j = P->n++;
            P->id[j] = (uint32_t)(M->n_real + k);
            P->image_of[j] = P->id[i] + 1u;
            take_image(P, i, j, side ? M->y_hi : M->y_lo);
            M->image[k] = (uint32_t)j;
            M->source[k] = (uint32_t)i;
            M->high[k] = (uint8_t)side;
            k++;
        }
    M->n_images = k;
    return 0;
}

int mirror_sides_resolve(struct mirror_sides *M, const struct particles *P)
{
    if (!M->index_of_id) {
        M->index_of_id = malloc((M->n_real ? M->n_real : 1) * sizeof *M->index_of_id);
        if (!M->index_of_id) return -1;
    }
    size_t count = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (particles_is_image(P, i))
            count++;
        else
            M->index_of_id[P->id[i]] = (uint32_t)i;
    }
    if (reserve(M, count) != 0) return -1;
    size_t k = 0;
    const double mid = 0.5 * (M->y_lo + M->y_hi);
    for (size_t i = 0; i < P->n; i++) {
        if (!particles_is_image(P, i)) continue;
        M->image[k] = (uint32_t)i;
        M->source[k] = M->index_of_id[P->image_of[i] - 1u];
#if DIM == 3
        M->high[k] = P->pos[1][i] > mid;
#else
        (void)mid;
        M->high[k] = 0;
#endif
        k++;
    }
    M->n_images = k;
    return 0;
}

struct refresh_loop {
    const struct mirror_sides *M;
    struct particles *P;
};

static void refresh_range(void *arg, size_t b, size_t e)
{
    const struct refresh_loop *L = arg;
    const struct mirror_sides *M = L->M;
    for (size_t k = b; k < e; k++) take_image(L->P, M->source[k], M->image[k], M->high[k] ? M->y_hi : M->y_lo);
}

void mirror_sides_refresh(const struct mirror_sides *M, struct particles *P, int n_threads)
{
    if (!M->on || M->n_images == 0) return;
    struct refresh_loop L = {.M = M, .P = P};
    team_for(n_threads, M->n_images, refresh_range, &L);
}

void mirror_sides_free(struct mirror_sides *M)
{
    free(M->image);
    free(M->source);
    free(M->high);
    free(M->index_of_id);
    memset(M, 0, sizeof *M);
}
