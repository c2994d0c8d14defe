/* neighbours.h - Verlet neighbour ranges with a skin over the cell list (cells.c).
 *
 * The cells are rows 2h + skin apart cut into kx narrow columns per row spacing, and the
 * particles are sorted by (row, column) (cells.h). For each particle i the pair loops (forces.c)
 * walk NEIGHBOURS_RANGES contiguous ranges of candidates j, its half stencil: the particles after
 * i in its own row up to column ix + kx, and the particles of columns ix-kx..ix+kx of the rows
 * after its own among those around it (the row above in 2D; in 3D the next row of its layer and
 * the three rows around it in the layer above), each trimmed at the build to the first and last
 * candidates closer than 2h + skin. Contiguous ranges keep the
 * inner loops on unit-stride loads (this CPU gathers slowly) while the narrow columns and the
 * trimming cut the candidates beyond 2h from about 70% (square cells of side 2h) to about half.
 * The ranges stay valid while no particle has moved more than skin/2 since the build (no pair
 * can have come closer than 2h unseen), so the sort and the build run once every many steps:
 * in this model the time step is set by the viscosity of the grains or by the sound speed, and a
 * particle moves a small fraction of h per step. Between builds particles keep their memory
 * order and the cells keep describing the build positions; bands of cell rows (3D: the blocks
 * below) are fixed index ranges, so the threads' write sets stay disjoint (forces.c). */
#ifndef MIXSPH_NEIGHBOURS_H
#define MIXSPH_NEIGHBOURS_H
#include <stddef.h>
#include <stdint.h>

#include "cells.h"
#include "particles.h"

/* Skin as a fraction of h: a larger skin means fewer builds but more candidates per pair loop
 * ((2h + skin)^2 / (2h)^2 of them are beyond 2h). */
#ifndef NEIGHBOURS_SKIN_OVER_H
#define NEIGHBOURS_SKIN_OVER_H 0.3
#endif

/* Entries past the end of a gather list that a chunked loop may read (see forces.c). */
#define NEIGHBOURS_PAD 16

/* The ranges of a particle's half stencil: the rest of its own row and the rows after it around
 * it (cells.h: 2 in 2D, the row above; 5 in 3D) */
#define NEIGHBOURS_RANGES (1 + CELLS_ROWS_AROUND / 2)

struct neighbours {
    double skin;        /* [m] */
    double *pos0[DIM];  /* positions at the last build [m] */
    uint32_t *rng;      /* per particle i, 2 NEIGHBOURS_RANGES entries: range r is [rng[2 R i + 2 r],
                         * rng[2 R i + 2 r + 1]), R = NEIGHBOURS_RANGES; r = 0 the rest of i's own row */
    size_t cap_n;
    uint64_t builds;    /* number of builds (diagnostic) */
};

/* Gather ranges: for chosen particles, their whole neighbourhood as CELLS_ROWS_AROUND contiguous
 * ranges (the rows around theirs, columns ix-kx..ix+kx, trimmed at the build to the candidates
 * closer than rc; i itself included), for loops that gather over one particle's neighbours (the
 * velocity gradient of grains, the pressure of wall particles). Built with the pair ranges,
 * from the same build positions. */
enum { NEIGHBOURS_GATHER_NONE = 0, NEIGHBOURS_GATHER_ALL = 1 };

struct gather {
    uint32_t *rng;      /* per particle i, 2 CELLS_ROWS_AROUND entries: [rng[2 A i + 2r], rng[2 A i + 2r + 1])
                         * for rows r = 0 .. A - 1, A = CELLS_ROWS_AROUND */
    uint8_t *mode;      /* per particle: NEIGHBOURS_GATHER_* (set by the caller before a build) */
    size_t cap_n;
    /* wall particles: their non-wall neighbours as a compact list (few of a wall's neighbours
     * are fluid, so a list beats the ranges): list[start[i] .. start[i+1]) */
    size_t *start;
    uint32_t *list;
    size_t cap_list;
};

/* The pair list: each particle's half-stencil candidates (its ranges above) closer than rc at the
 * build, pairs of two wall particles left out (their forces vanish, and a wall particle's density
 * rate is not used: it takes the fluid's extrapolated state, walls.h), as one compact
 * list of indices, ascending per particle. The 3D pair loops walk it instead of the ranges
 * (forces.c): in 3D the ranges' rows are rc x rc in cross-section, so only about 15 % of their
 * candidates lie within 2h and, with three wall particles for each fluid one, most of the rest
 * are wall-wall pairs; the list leaves the pair loops about two thirds of lanes within 2h, at the
 * cost of indexed loads. In 2D the ranges hold about 40 % of useful candidates and walls are few:
 * the contiguous ranges are kept there. */
struct pair_list {
    uint32_t *start;    /* n + 1 entries: particle i's candidates are j[start[i] .. start[i+1]) */
    uint32_t *j;        /* the candidates, then NEIGHBOURS_PAD entries of 0 (read by masked lanes) */
    size_t n;           /* particles listed */
    size_t cap_n, cap_j;
    uint64_t builds;    /* the NB->builds it was made from */
    int valid;          /* it describes the lists of that build */
};

/* The threads' schedule of the 3D pair loops over the pair list: the grid cut into blocks of one
 * layer and two search radii along a second axis (the rows' axis x or the axis y across them,
 * whichever holds more search radii: the longer), each block a set of whole cells. The half stencil of
 * a particle reaches its own layer and the one above, and one search radius either side along x
 * and y (cells.h), so the pair loops of a block write only its own particles and those of the
 * layer above, one radius around it; blocks of one colour (the parities of their layer and of
 * their place along the axis: NEIGHBOURS_COLOURS of them) therefore never write the same particle
 * and run in parallel, the colours one after the other. A particle receives the additions of its
 * blocks in the order of their colours and those within a block in memory order, whichever thread
 * walks it: results do not depend on the thread count. Within a colour the blocks are listed by
 * descending work (pair-list entries plus particles; ties by place), so that threads taking
 * them one at a time finish together (longest first). Blocks without particles are left out.
 * Bands of whole layers, as in 2D, left two threads with one or two loaded bands per phase: the
 * dam break's water fills a few layers. */
#if DIM == 3
enum { NEIGHBOURS_COLOURS = 4 };

struct pair_blocks {
    uint32_t (*block)[3]; /* per block: its first and end cell index along the axis, its layer */
    size_t first[NEIGHBOURS_COLOURS + 1]; /* colour c's blocks are block[first[c] .. first[c + 1]) */
    int axis;             /* the axis the blocks cut within a layer: 0 (x, columns) or 1 (y, rows) */
    size_t cap;
    uint64_t builds;      /* the NB->builds of the list it was made from */
};
#endif

void neighbours_free(struct neighbours *NB);
void neighbours_gather_free(struct gather *G);
/** Make room for cap particles in G. Returns -1 on allocation failure. */
int neighbours_gather_reserve(struct gather *G, size_t cap);
/** Build G for the first n particles (those with a mode) from the build positions of NB; the
 *  lists of the particles whose state is MIXSPH_STATE_WALL. Returns -1 on allocation failure. */
int neighbours_gather_build(struct gather *G, const struct neighbours *NB, const struct cells *C, const uint8_t *state,
                            size_t n, double rc, int n_threads);

/** Build the ranges of the first n particles (the cell list's active ones, sorted by cell) with
 *  a cut-off radius rc (2h + skin) from their current positions, which become the build
 *  positions. Returns -1 on allocation failure. */
int neighbours_build(struct neighbours *NB, const struct cells *C, const struct particles *P, size_t n, double rc,
                     int n_threads);

/** Rebuild the ranges from the build positions already in pos0 (a restored state). */
int neighbours_relist(struct neighbours *NB, const struct cells *C, size_t n, double rc, int n_threads);

/** Build L from the ranges of the first n particles of NB and their build positions: the
 *  candidates closer than rc, pairs of two particles whose state is MIXSPH_STATE_WALL left out.
 *  Returns -1 on allocation failure or beyond 2^32 - 1 entries. */
int neighbours_pair_list_build(struct pair_list *L, const struct neighbours *NB, const uint8_t *state, size_t n,
                               double rc, int n_threads);
void neighbours_pair_list_free(struct pair_list *L);

#if DIM == 3
/** Build the blocks B of the grid C from the pair list L of the particles it sorted (built from
 *  the same lists). Returns -1 on allocation failure. */
int neighbours_pair_blocks_build(struct pair_blocks *B, const struct pair_list *L, const struct cells *C);
void neighbours_pair_blocks_free(struct pair_blocks *B);

/** Particle range number k (0 .. neighbours_block_ranges(...) - 1) of block b of B: the cells of
 *  one row of the block (axis 0), or of the whole block (axis 1: its rows are contiguous). */
static inline size_t neighbours_block_ranges(const struct pair_blocks *B, const struct cells *C)
{
    return B->axis == 0 ? (size_t)C->n[1] : 1;
}
static inline struct range neighbours_block_range(const struct pair_blocks *B, const struct cells *C, size_t b,
                                                  size_t k)
{
    const uint32_t *q = B->block[b];
    const size_t layer0 = (size_t)q[2] * C->layer, n0 = (size_t)C->n[0];
    struct range r;
    if (B->axis == 0) {
        r.begin = C->start[layer0 + k * n0 + q[0]];
        r.end = C->start[layer0 + k * n0 + q[1]];
    } else {
        r.begin = C->start[layer0 + q[0] * n0];
        r.end = C->start[layer0 + q[1] * n0];
    }
    return r;
}
#endif

/** Make room for cap particles' build positions. Returns -1 on allocation failure. */
int neighbours_reserve(struct neighbours *NB, size_t cap);

/** Largest squared displacement of the first n particles since the last build, and whether
 *  one of them is outside the grid (then the caller rebuilds at once, which marks it lost). */
double neighbours_max_shift2(const struct neighbours *NB, const struct cells *C, const struct particles *P, size_t n,
                             int *outside, int n_threads);

#endif
