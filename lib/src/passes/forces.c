/* forces.c - the continuity and momentum pair loops, eq. (3) of Manenti et al. (2018):
 *
 *   d rho_i/dt = rho_i sum_j V_j (u_i - u_j) . grad_i W_ij
 *   d u_i/dt   = -1/rho_i sum_j V_j (p_i + p_j) grad_i W_ij          (= -sum m_j (p_i+p_j)/(rho_i rho_j) gradW)
 *                - sum_j m_j Pi_ij grad_i W_ij                         (Monaghan: see below)
 *                + 1/rho_i sum_j V_j 2 mu_ij F r^2/(r^2 + eta^2) (u_i - u_j)   (Morris et al. 1997)
 *                + g
 * with V_j = m_j / rho_j, grad_i W_ij = F(r) (x_i - x_j) (kernel.h), eta^2 = numerics.eta2_over_h2 h^2 (0.01 h^2),
 * mu_ij = 2 mu_i mu_j / (mu_i + mu_j) the harmonic mean (it is bounded by 2 min(mu_i, mu_j), so
 * the explicit viscous step of a mobile grain next to a fixed one at mu_thr stays governed by
 * the grain's own viscosity, and water slides past grains with the water's viscosity), and
 * Pi_ij = -alpha c h min(u_ij . x_ij, 0) / (r^2 + eta^2) (1/rho_i + 1/rho_j)/2 (the mean of the
 * inverse densities: symmetric, like the usual inverse of the mean, and free of divisions), with
 * alpha c h the larger of the two particles' (0 for a medium without alpha_m). By default it acts
 * between particles of one medium (docs/model.md section 2: water-water) and between a particle and walls;
 * numerics.av_wall = 0 drops the wall pairs, av_mixed = 1 adds pairs of different media and
 * av_separating = 1 drops the min(., 0), all three as SPHERA does (its viscomon routine: every
 * pair, separating ones too; at its semi-analytic walls only the wall-normal velocity).
 * Wall particles enter with V = dx^2, their extrapolated pressure (walls.c), the kernel mean
 * density of the fluid near them, the fluid's own viscosity (mu_wall = 0 plus the fluid's) and
 * their no-slip mirror velocity in the viscous term.
 *
 * Symmetric evaluation: every pair is computed once, as a force f_ij = m_i a_ij = -m_j a_ji,
 * added to i and subtracted from j, so momentum is conserved to round-off by construction.
 * Particles are sorted by cell (cells.c); particle i meets the two contiguous ranges of its half
 * stencil kept by neighbours.c (the particles after it in its own row up to kx columns ahead,
 * and kx columns either side in the row above, trimmed to the candidates within 2h + skin at
 * the last build), so each pair is met once and the inner loops run over contiguous memory. In 3D
 * these ranges would leave most lanes idle (rows rc x rc in cross-section, and the walls' own
 * pairs: 17 % of the lanes within 2h in the SPHERIC dam break), so there i meets its entries of the pair list
 * instead (neighbours.h: the same half stencil within 2h + skin, without wall-wall pairs) through
 * indexed loads and stores (FORCES_J, chunk_add). The inner loops are
 * branch-free (the kernel factor is 0 beyond 2h; wall and artificial-viscosity terms are
 * selected arithmetically) and vectorised with `omp simd`. The loops are compiled for AVX-512,
 * AVX2 and baseline x86-64 and the widest is picked at run time (target_clones).
 *
 * Threads: the grid is cut into bands of two cell rows (index ranges fixed at the last build); a
 * band writes its own rows and the row above, so even bands never touch each other, nor odd bands: even bands run in parallel, then
 * odd bands. In 3D the bands are the pair list's blocks instead (neighbours.h: one layer and two
 * search radii along x or y, in four colours run one after the other), so that two threads find
 * several loaded blocks in each phase. The bands do not depend on the thread count and each band is walked in memory
 * order, so every particle receives its contributions in the same order whatever the number of
 * threads: results are bit-identical for any thread count.
 *
 * Two passes per step: the density rate (continuity, with the newest velocities) before the EOS,
 * momentum after; see integrate.c for why. Both run at the same positions over the same ranges,
 * so the density pass stores the kernel factor F of every lane and the momentum pass reads it
 * (fcache_layout below). With granular media integrate.c has the velocity gradient of each grain
 * (for its strain rate) gathered right after the density pass, over its gather ranges (all its
 * neighbours, three contiguous ranges): forces_velocity_gradient. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "forces.h"

#include "bed_friction.h"

#include <stdint.h>

#include "mixsph.h"
#include "team.h"

/* Not on Windows (the FMU's win64 binary): its loader has no ifunc to pick a clone. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && !defined(MIXSPH_NO_CLONES) && \
    !defined(__SANITIZE_ADDRESS__) && !defined(_WIN32)
#define FORCES_CLONES __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default"), noinline))
#else
#define FORCES_CLONES
#endif
#define FORCES_INLINE static inline __attribute__((always_inline))

#define FORCES_BAND_ROWS 2
/* The inner loops run over chunks of FORCES_CHUNK candidates with the lanes past the range
 * masked off (a whole AVX-512 vector of doubles, no scalar remainder): the ranges are short
 * (10-20 candidates), so scalar remainders would cost more than the vector part. Reads may go up
 * to FORCES_CHUNK - 1 elements past a range (particles.c keeps that padding initialised). */
#define FORCES_CHUNK 8
_Static_assert(FORCES_CHUNK - 1 <= FORCES_PAD, "forces.h promises callers reads of at most FORCES_PAD past a range");

/* 64-byte aligned blocks of the lane caches: C11's aligned_alloc, released by free; the C runtime
 * of the FMU's Windows binary (fmu/) has no aligned_alloc, but _aligned_malloc and _aligned_free. */
#if defined(_WIN32)
#include <malloc.h>
static void *aligned_block(size_t bytes) { return _aligned_malloc(bytes, 64); }
static void aligned_block_free(void *p) { _aligned_free(p); }
#else
static void *aligned_block(size_t bytes) { return aligned_alloc(64, bytes); }
static void aligned_block_free(void *p) { free(p); }
#endif

/* The sums over its wall neighbours j that a particle's bed friction needs (bed_friction.h; the
 * momentum pass with bed friction, over the no-slip walls that bound its shear): the walls' force
 * on it, the wall normal n = -sum_j V_j F_ij x_ij (out of the walls), the weight q = -sum_j V_j F_ij
 * of the walls with a given friction coefficient, that weight times their coefficient, the weight
 * of the walls that take the grain's own, and the weighted sum of the walls' velocities. */
enum { WALL_F = 0, WALL_N = DIM, WALL_Q_GIVEN = 2 * DIM, WALL_QMU_GIVEN, WALL_Q_OWN, WALL_V,
       WALL_SUMS = WALL_V + DIM }; /* F, N, V: DIM each */

/* The per-particle arrays of the grains in water (docs/model.md [GW]; params.grains_in_water): each
 * particle's role (GRAIN_ROLE_*), the water's pressure interpolated at a grain and its two sums, a
 * grain's Ergun factors (granular.h), its parcel's volume m / rho0 and the fraction of that volume
 * its solids take from the water (1 - n dry, 1 saturated: the parcel then carries its pore water;
 * 1 for every other particle). */
enum { GW_ROLE = 0, GW_PRESSURE, GW_SUM, GW_WEIGHT, GW_DRAG_VISCOUS, GW_DRAG_INERTIAL, GW_VOLUME, GW_SOLID, GW_ARRAYS };
#define GRAIN_ROLE_FLUID (-1.0) /* a particle of a LAW_FLUID medium */
#define GRAIN_ROLE_GRAIN 1.0    /* a particle of a LAW_GRAINS_IN_WATER medium; 0: any other (walls) */

struct forces {
    double *fk;               /* kernel factors of the pair lanes, density -> momentum pass */
    size_t *fk_off;           /* particle i's lanes start at fk + fk_off[i] */
    size_t fk_cap, fk_off_cap;
    int fk_valid;             /* fk holds this step's factors (set by the density pass, used once) */
    /* scratch sums of the passes, one per particle (+ FORCES_CHUNK of padding) */
    double *nbr_count;        /* density pass: same-medium neighbours within 2h */
    double *smooth_sum;       /* smoothing: sum_j B_ij W_ij V_j */
    double *smooth_weight;    /* smoothing: sum_j W_ij V_j */
    double *wall_sum[WALL_SUMS]; /* momentum pass with bed friction: each particle's wall sums (above) */
    double *bed_given, *bed_own; /* momentum pass with bed friction: which walls bound a particle's shear */
    double *diffusion_sum;    /* density pass: sum_j V_j psi_ij (-F_ij) of the density diffusion */
    double *gw[GW_ARRAYS];    /* the grains in water (above) */
    size_t scratch_cap;
    /* implicit viscosity: the viscous coupling w_ij >= 0 of every lane (layout of fk), stored by
     * the momentum pass, so that m_i du_i/dt = -sum_j w_ij (u_i - u_j) */
    double *visc_w;
    size_t visc_w_cap;
    int visc_valid;           /* visc_w holds the couplings at the current positions */
    struct pair_list list;    /* 3D: the pair list of the current neighbour lists (pair_list_attach) */
#if DIM == 3
    struct pair_blocks blocks; /* 3D: the threads' blocks of that list (neighbours.h) */
    int fk_layout_ok;          /* 3D: fk_off is the lane layout of that list (made once per list) */
#endif
};

/* Constants of one pass of the pair loops. */
struct pair_ctx {
    struct kernel K;
    double eta2, g;
    double av_wall;  /* 1: artificial viscosity between fluid and wall particles, 0: not */
    double av_mixed; /* 1: ... between particles of different media too, 0: same medium only */
    double av_cap;   /* u_ij.x_ij is capped at this: 0 (approaching pairs only) or +inf (all pairs) */
    int wendland;
    int arithmetic_mean;  /* implicit viscosity with the pair viscosity (mu_i + mu_j) / 2 */
    int stress;           /* the particles' deviatoric stresses enter the momentum pass */
    int bed_friction;     /* the momentum pass gathers the wall sums of the bed friction */
    double *wall_sum[WALL_SUMS]; /* with bed_friction: the wall sums (struct forces) */
    const double *bed_given, *bed_own; /* with bed_friction, per particle: 1 where the walls that give
                                        * their friction angle (bed_given) or take its own medium's
                                        * (bed_own) bound its shear, else 0 */
    const double *bed_mu; /* with bed_friction: each (wall, medium) pair's coefficient (bed_friction.h) */
    int bed_per_medium;   /* read bed_mu (some wall's coefficient differs by medium), else wall_friction */
    double *fk;           /* the kernel-factor cache (see forces_density_rate), or NULL */
    const size_t *fk_off; /* particle i's lanes start at fk + fk_off[i] */
    double *count;        /* scratch sums written by the band walks (see struct forces) */
    double *diffusion;    /* the density diffusion's sums (density pass), or NULL: no diffusion */
    const struct medium *media;
    double diffusion_g;   /* g with the hydrostatic form of the diffusion, 0 with Molteni's */
    double *sum, *weight;
    double *visc_w;       /* the viscous couplings of the lanes (implicit viscosity), or NULL */
    const double *in[DIM];     /* the velocity field a viscous operator is applied to */
    double *out[DIM];          /* and its result */
    double *out_diag;          /* and its diagonal, or NULL */
    const int32_t *group;      /* forces_viscous_group_couplings: each particle's group, or -1 */
    long group_stride;         /* groups per row of the group grid */
    double *group_w;           /* and its sums, 5 per group */
    double *gw[GW_ARRAYS];     /* the grains in water (struct forces), or NULL: none */
    double p_background;       /* the water's pressure at a free surface [Pa] (the grains in water) */
    const uint32_t *idx;        /* 3D: the pair list's candidates (pair_list_attach); 2D: NULL */
    const uint32_t *list_start; /* 3D: particle i's candidates are idx[list_start[i] .. list_start[i+1]) */
#if DIM == 3
    const struct pair_blocks *blocks; /* 3D: the threads' blocks of the list (bands_in_team) */
#endif
};

static void pair_ctx_init(const struct pair_system *S, struct pair_ctx *X)
{
    const struct forces_params *fp = &S->params;
    X->K = fp->K;
    X->eta2 = fp->eta2;
    X->g = fp->g;
    X->av_wall = fp->av_wall ? 1.0 : 0.0;
    X->av_mixed = fp->av_mixed ? 1.0 : 0.0;
    X->av_cap = fp->av_separating ? INFINITY : 0.0;
    X->wendland = fp->K.type == KERNEL_WENDLAND_C2;
    X->arithmetic_mean = fp->arithmetic_mean;
    X->stress = fp->stress;
    X->bed_friction = fp->bed_friction;
    for (int q = 0; q < WALL_SUMS; q++) X->wall_sum[q] = NULL;
    X->bed_given = X->bed_own = NULL;
    X->bed_mu = fp->bed_mu.mu;
    X->bed_per_medium = fp->bed_per_medium;
    X->fk = NULL;
    X->fk_off = NULL;
    X->count = X->sum = X->weight = NULL;
    X->diffusion = NULL;
    X->media = S->media;
    X->diffusion_g = fp->diffusion_form == DENSITY_DIFFUSION_HYDROSTATIC ? fp->g : 0.0;
    X->visc_w = NULL;
    for (int d = 0; d < DIM; d++) {
        X->in[d] = NULL;
        X->out[d] = NULL;
    }
    X->out_diag = NULL;
    X->group = NULL;
    X->group_stride = 0;
    X->group_w = NULL;
    for (int q = 0; q < GW_ARRAYS; q++) X->gw[q] = NULL;
    X->p_background = fp->p_background;
    X->idx = X->list_start = NULL;
#if DIM == 3
    X->blocks = NULL;
#endif
}

/* Particle i's candidates for the pair loops: in 2D its NEIGHBOURS_RANGES ranges of particles, in
 * 3D one range of positions in the pair list X->idx (neighbours.h), written into buf. */
#if DIM == 3
#define PAIR_RANGES 1
#else
#define PAIR_RANGES NEIGHBOURS_RANGES
#endif
FORCES_INLINE const uint32_t *pair_ranges(const struct pair_ctx *X, const struct neighbours *NB, size_t i,
                                          uint32_t buf[2])
{
#if DIM == 3
    (void)NB;
    buf[0] = X->list_start[i];
    buf[1] = X->list_start[i + 1];
    return buf;
#else
    (void)X;
    (void)buf;
    return NB->rng + 2 * NEIGHBOURS_RANGES * i;
#endif
}

/* F of a pair at squared distance r2 (kernel.h). `wendland` is a compile-time constant in each
 * inlined copy (the band functions dispatch on the kernel once, outside the loops). */
FORCES_INLINE double pair_f(const struct pair_ctx *X, double r2, const int wendland)
{
    return kernel_f_q(&X->K, kernel_q(&X->K, r2), wendland);
}

/* The skeleton every pair pass runs over particle i's candidates: its nr ranges
 * [rng[2r], rng[2r + 1]) of the neighbour lists, in chunks of FORCES_CHUNK lanes from jb, the
 * first `lanes` of them inside the range (the rest masked off by FORCES_LANE_IN; the innermost
 * loop runs once, to declare it). A pass's body evaluates its pair term on the chunk's lanes with
 * `omp simd` and adds what j receives with chunk_add. */
#define FORCES_FOR_EACH_CHUNK(rng, nr, jb, lanes)                                                  \
    for (int r_ = 0; r_ < (nr); r_++)                                                               \
        for (size_t jb = (rng)[2 * r_], e_ = (rng)[2 * r_ + 1]; jb < e_; jb += FORCES_CHUNK)        \
            for (size_t lanes = e_ - jb < FORCES_CHUNK ? e_ - jb : FORCES_CHUNK, once_ = 1; once_; once_ = 0)

/* Candidate k of particle i's chunk that starts at jb, m lanes of it inside the range: in 2D the
 * particle jb + k itself (the ranges hold particles), in 3D entry jb + k of the pair list idx
 * (neighbours.h: the ranges hold positions in it), and i for a masked lane: its terms are then
 * zero (r = 0, every factor finite, times the lane mask), and the adds to j need no mask (a masked
 * lane adds 0 to i, which the walking thread owns); GCC 12 vectorises no masked scatter. The
 * entry is loaded before the select (the list is padded), so that the load needs no mask
 * either. The loops' text is the same in both; 2D compiles to the contiguous loads it always had. */
#if DIM == 3
FORCES_INLINE size_t forces_j(const uint32_t *restrict idx, size_t jb, size_t k, size_t m, size_t i)
{
    const size_t j = idx[jb + k], keep = (size_t)0 - (size_t)(k < m); /* all ones inside the range */
    return (j & keep) | (i & ~keep); /* bit operations: a select would become a phi of addresses, no gather */
}
#define FORCES_J(idx, jb, k, m, i) forces_j(idx, jb, k, m, i)
#else
#define FORCES_J(idx, jb, k, m, i) ((void)(idx), (void)(i), (jb) + (k))
#endif

/* Lane mask of a chunk: 1 for the first m lanes, 0 after (a select, no branch). */
#define FORCES_LANE_IN(k, m) ((k) < (m) ? 1.0 : 0.0)

/* Add the chunk's lane values v[] to its candidates' a[j] (FORCES_J): in 2D masked vector loads
 * and stores (AVX-512, AVX2), so a partial chunk needs no scalar tail and never writes past the
 * range (another thread may own what follows); in 3D a gather and a scatter, the candidates of one
 * particle being distinct and a masked lane adding its 0 to i. */
FORCES_INLINE void chunk_add(double *restrict a, const uint32_t *restrict idx, size_t jb, size_t m, size_t i,
                             const double *restrict v)
{
#pragma omp simd
    for (size_t k = 0; k < FORCES_CHUNK; k++)
#if DIM == 3 /* v is 0 on the masked lanes, whose j is i (FORCES_J) */
        a[FORCES_J(idx, jb, k, m, i)] += v[k];
#else
        if (k < m) a[FORCES_J(idx, jb, k, m, i)] += v[k];
#endif
}

/* Continuity between i and its nr ranges of candidates [rng[2r], rng[2r+1]) (one call per
 * particle: one set of lane sums, reduced once): d_i += V_j u_ij.x_ij F, d_j += V_i u_ij.x_ij F,
 * and same-medium neighbour counts. With `diffuse` (i of a fluid: diffuses), between particles of
 * one medium also the density diffusion's sums e_i += V_j psi_ij (-F), e_j -= V_i psi_ij (-F) with
 * psi_ij = rho_j - rho_i - hyd_i (z_i - z_j): hyd_i = rho0 g / c^2 of i's medium removes the
 * hydrostatic density difference of the linear EOS (Fourtakas et al. 2019 with gamma = 1; the
 * initial state of sim.c, p = rho0 g depth, is left exactly at rest), 0 keeps the whole
 * difference. psi_ji = -psi_ij, so sum_i V_i e_i = 0: the diffusion moves density between
 * particles and creates none. With `grains` (docs/model.md [GW]) a grain in water takes no
 * density rate from its fluid neighbours: water flowing past or through a parcel of grains does
 * not pack them; the fluid's rate counts a grain by the volume its solids take from the water
 * (GW_SOLID): the rest of the parcel is pore space the water flows through. */
FORCES_INLINE void continuity_range(const struct pair_ctx *X, struct particles *restrict P, size_t i,
                                    const uint32_t *restrict idx, const uint32_t *restrict rng, int nr, double *di, double *ni, double *ei,
                                    double *restrict count, double *restrict fk, double *restrict diff, double hyd_i,
                                    const int wendland, const int diffuse, const int grains)
{
    const double ti = P->tag[i], voli = P->vol[i], rhoi = P->rho[i];
    double xi[DIM], vi[DIM];
    const double *restrict x[DIM], *restrict v[DIM];
    DIM_UNROLL
    for (int d = 0; d < DIM; d++) {
        xi[d] = P->pos[d][i];
        vi[d] = P->vel[d][i];
        x[d] = P->pos[d];
        v[d] = P->vel[d];
    }
    const double *restrict vol = P->vol, *restrict tag = P->tag, *restrict rho = P->rho;
    const struct pair_ctx Xl = *X;
    const double fluid_i = ti >= 0.0 ? 1.0 : 0.0;
    const double *restrict role = grains ? X->gw[GW_ROLE] : NULL;
    const double role_i = grains ? role[i] : 0.0;
    const double *restrict solid = grains ? X->gw[GW_SOLID] : NULL;
    const double solid_i = grains ? solid[i] : 1.0;
    double acc[FORCES_CHUNK] = {0}, cnt[FORCES_CHUNK] = {0}, dif[FORCES_CHUNK] = {0};
    FORCES_FOR_EACH_CHUNK(rng, nr, jb, m) {
        double dj[FORCES_CHUNK], cj[FORCES_CHUNK], ej[FORCES_CHUNK];
#pragma omp simd
        for (size_t k = 0; k < FORCES_CHUNK; k++) {
            const size_t j = FORCES_J(idx, jb, k, m, i);
            const double in = FORCES_LANE_IN(k, m);
            double r[DIM], r2 = 0.0, uf = 0.0;
            DIM_UNROLL
            for (int d = 0; d < DIM; d++) {
                r[d] = xi[d] - x[d][j];
                r2 += r[d] * r[d];
            }
            const double F = pair_f(&Xl, r2, wendland) * in;
            DIM_UNROLL
            for (int d = 0; d < DIM; d++) uf += (vi[d] - v[d][j]) * r[d];
            uf *= F;
            const double c = (r2 < Xl.K.r2max ? 1.0 : 0.0) * (tag[j] == ti ? 1.0 : 0.0) * fluid_i * in;
            fk[k] = F;
            if (grains) { /* a grain's side of a grain-fluid pair drops out */
                const double keep_i = role_i == GRAIN_ROLE_GRAIN && role[j] == GRAIN_ROLE_FLUID ? 0.0 : 1.0;
                const double keep_j = role[j] == GRAIN_ROLE_GRAIN && role_i == GRAIN_ROLE_FLUID ? 0.0 : 1.0;
                acc[k] += keep_i * (role_i == GRAIN_ROLE_FLUID ? solid[j] : 1.0) * vol[j] * uf;
                dj[k] = keep_j * (role[j] == GRAIN_ROLE_FLUID ? solid_i : 1.0) * voli * uf;
            } else {
                acc[k] += vol[j] * uf;
                dj[k] = voli * uf;
            }
            cnt[k] += c;
            cj[k] = c;
            if (diffuse) {
                const double one = (tag[j] == ti ? 1.0 : 0.0) * fluid_i; /* F is 0 on masked lanes */
                const double q = -(rho[j] - rhoi - hyd_i * r[DIM_UP]) * F * one;
                dif[k] += vol[j] * q;
                ej[k] = -voli * q;
            }
        }
        chunk_add(P->drho, idx, jb, m, i, dj);
        chunk_add(count, idx, jb, m, i, cj);
        if (diffuse) chunk_add(diff, idx, jb, m, i, ej);
        fk += FORCES_CHUNK;
    }
    for (size_t k = 0; k < FORCES_CHUNK; k++) {
        *di += acc[k];
        *ni += cnt[k];
        if (diffuse) *ei += dif[k];
    }
}

/* Partial pressure smoothing (Di Monaco et al. 2011, as SPHERA applies it; option
 * numerics.pressure_smoothing): between i and its ranges, for pairs of non-wall particles,
 * B_ij = p_j - p_i + (rho_i + rho_j)/2 g (z_j - z_i) (the difference from the hydrostatic
 * extrapolation of p_j to z_i, so a hydrostatic field is left unchanged; B_ji = -B_ij):
 * a_i += B_ij W_ij V_j, u_i += W_ij V_j and a_j -= B_ij W_ij V_i, u_j += W_ij V_i. */
FORCES_INLINE void smooth_range(const struct pair_ctx *X, const struct particles *restrict P, size_t i,
                                const uint32_t *restrict idx, const uint32_t *restrict rng, int nr, double g, double *ai, double *ui,
                                double *restrict sum, double *restrict weight, const int wendland)
{
    const double pi = P->p[i], rhoi = P->rho[i], voli = P->vol[i];
    double xi[DIM];
    const double *restrict x[DIM];
    for (int d = 0; d < DIM; d++) {
        xi[d] = P->pos[d][i];
        x[d] = P->pos[d];
    }
    const double *restrict p = P->p, *restrict rho = P->rho;
    const double *restrict vol = P->vol, *restrict tag = P->tag;
    const struct pair_ctx Xl = *X;
    double sa[FORCES_CHUNK] = {0}, su[FORCES_CHUNK] = {0};
    FORCES_FOR_EACH_CHUNK(rng, nr, jb, m) {
        double aj[FORCES_CHUNK], uj[FORCES_CHUNK];
#pragma omp simd
        for (size_t k = 0; k < FORCES_CHUNK; k++) {
            const size_t j = FORCES_J(idx, jb, k, m, i);
            double r[DIM], r2 = 0.0;
            DIM_UNROLL
            for (int d = 0; d < DIM; d++) {
                r[d] = xi[d] - x[d][j];
                r2 += r[d] * r[d];
            }
            double w = kernel_w_q(&Xl.K, kernel_q(&Xl.K, r2), wendland);
            w *= FORCES_LANE_IN(k, m) * (tag[j] < 0.0 ? 0.0 : 1.0);
            const double b = (p[j] - pi - 0.5 * (rhoi + rho[j]) * g * r[DIM_UP]) * w;
            sa[k] += b * vol[j];
            su[k] += w * vol[j];
            aj[k] = -b * voli;
            uj[k] = w * voli;
        }
        chunk_add(sum, idx, jb, m, i, aj);
        chunk_add(weight, idx, jb, m, i, uj);
    }
    for (size_t k = 0; k < FORCES_CHUNK; k++) {
        *ai += sa[k];
        *ui += su[k];
    }
}

/* The water's pressure at the grains in water (docs/model.md [GW]): between i and its ranges, for a
 * pair of a grain and a fluid particle, the grain's sums a += V_f W (p_f + rho_f g (z_f - z_grain))
 * (the fluid's pressure carried hydrostatically to the grain's height) and u += V_f W, whose
 * quotient (Shepard's interpolation) is the water's pressure at the grain. */
FORCES_INLINE void water_pressure_range(const struct pair_ctx *X, const struct particles *restrict P, size_t i,
                                        const uint32_t *restrict idx, const uint32_t *restrict rng, int nr, double g, double *ai, double *ui,
                                        double *restrict sum, double *restrict weight, const int wendland)
{
    const double pi = P->p[i], rhoi = P->rho[i], voli = P->vol[i];
    const double *restrict role = X->gw[GW_ROLE];
    const double role_i = role[i];
    double xi[DIM];
    const double *restrict x[DIM];
    for (int d = 0; d < DIM; d++) {
        xi[d] = P->pos[d][i];
        x[d] = P->pos[d];
    }
    const double *restrict p = P->p, *restrict rho = P->rho, *restrict vol = P->vol;
    const struct pair_ctx Xl = *X;
    double sa[FORCES_CHUNK] = {0}, su[FORCES_CHUNK] = {0};
    FORCES_FOR_EACH_CHUNK(rng, nr, jb, m) {
        double aj[FORCES_CHUNK], uj[FORCES_CHUNK];
#pragma omp simd
        for (size_t k = 0; k < FORCES_CHUNK; k++) {
            const size_t j = FORCES_J(idx, jb, k, m, i);
            double r[DIM], r2 = 0.0;
            DIM_UNROLL
            for (int d = 0; d < DIM; d++) {
                r[d] = xi[d] - x[d][j];
                r2 += r[d] * r[d];
            }
            const double w = kernel_w_q(&Xl.K, kernel_q(&Xl.K, r2), wendland) * FORCES_LANE_IN(k, m);
            const double gi = role_i == GRAIN_ROLE_GRAIN && role[j] == GRAIN_ROLE_FLUID ? w : 0.0;
            const double gj = role[j] == GRAIN_ROLE_GRAIN && role_i == GRAIN_ROLE_FLUID ? w : 0.0;
            sa[k] += gi * vol[j] * (p[j] - rho[j] * g * r[DIM_UP]);
            su[k] += gi * vol[j];
            aj[k] = gj * voli * (pi + rhoi * g * r[DIM_UP]);
            uj[k] = gj * voli;
        }
        chunk_add(sum, idx, jb, m, i, aj);
        chunk_add(weight, idx, jb, m, i, uj);
    }
    for (size_t k = 0; k < FORCES_CHUNK; k++) {
        *ai += sa[k];
        *ui += su[k];
    }
}

/* Velocity gradient of granular particle i, gathered over its nr ranges of candidates: the uncorrected
 * G = sum_j V_j (u_j - u_i) (x) grad_i W and the correction matrix
 * L = sum_j V_j (x_j - x_i) (x) grad_i W of the strain rate (docs/model.md section 5), in the
 * layout of core/velocity_gradient.h (G's DIM x DIM, then L's upper triangle). Walls enter with
 * their no-slip velocity, so grains feel the shear of a wall. Only granular particles need it, so
 * it is a gather over them alone rather than part of the symmetric pass. */
enum { GRADIENT_SUMS = DIM * DIM + VELOCITY_GRADIENT_L_N };

FORCES_INLINE void gradient_range(const struct pair_ctx *X, const struct particles *restrict P, size_t i,
                                  const uint32_t *restrict rng, int nr, double *acc_i, const int wendland)
{
    double xi[DIM], ui[DIM];
    const double *restrict x[DIM], *restrict uv[DIM];
    for (int d = 0; d < DIM; d++) {
        xi[d] = P->pos[d][i];
        ui[d] = P->uv[d][i];
        x[d] = P->pos[d];
        uv[d] = P->uv[d];
    }
    const double *restrict vol = P->vol;
    const struct pair_ctx Xl = *X;
    double a[GRADIENT_SUMS][FORCES_CHUNK] = {{0}};
    FORCES_FOR_EACH_CHUNK(rng, nr, jb, m) {
#pragma omp simd
        for (size_t k = 0; k < FORCES_CHUNK; k++) {
            const size_t j = jb + k;
            double r[DIM], r2 = 0.0, du[DIM];
            DIM_UNROLL
            for (int d = 0; d < DIM; d++) {
                r[d] = xi[d] - x[d][j];
                r2 += r[d] * r[d];
            }
            const double vf = vol[j] * pair_f(&Xl, r2, wendland) * FORCES_LANE_IN(k, m);
            DIM_UNROLL
            for (int d = 0; d < DIM; d++) du[d] = (uv[d][j] - ui[d]) * vf;
            DIM_UNROLL
            for (int c = 0; c < DIM; c++)
                DIM_UNROLL
                for (int d = 0; d < DIM; d++) a[c * DIM + d][k] += du[c] * r[d];
            DIM_UNROLL
            for (int c = 0; c < DIM; c++)
                DIM_UNROLL
                for (int d = c; d < DIM; d++) a[DIM * DIM + velocity_gradient_l_index(c, d)][k] -= vf * r[c] * r[d];
        }
    }
    for (int q = 0; q < GRADIENT_SUMS; q++)
        for (size_t k = 0; k < FORCES_CHUNK; k++) acc_i[q] += a[q][k];
}

/* The stress a wall particle w of unit normal n (free-slip; n = 0 on no-slip walls and for the
 * other particles) adds to the stress s it takes from the particle it meets: the change of s
 * mirrored across the wall, whose shear on the wall's plane is reversed,
 * s' - s = -2 (q_t (x) n + n (x) q_t), q_t = s n - (n . s n) n, so the pair transmits the normal
 * stress and no shear (SYM_N components, dim.h; 2D: -2 s_nt (n t + t n), t = (-n_z, n_x),
 * s_nt = a (s_zz - s_xx) + b s_xz with a = n_x n_z, b = n_x^2 - n_z^2). */
#if DIM == 3
FORCES_INLINE void wall_mirror_change(const double n[3], const double s[SYM_N], double out[SYM_N])
{
    double q[3];
    for (int a = 0; a < 3; a++) {
        q[a] = 0.0;
        for (int b = 0; b < 3; b++) q[a] += s[sym_index3(a, b)] * n[b];
    }
    const double qn = q[0] * n[0] + q[1] * n[1] + q[2] * n[2];
    for (int a = 0; a < 3; a++) q[a] -= qn * n[a];
    for (int a = 0; a < 3; a++)
        for (int b = a; b < 3; b++) out[sym_index3(a, b)] = -2.0 * (q[a] * n[b] + n[a] * q[b]);
}
#endif

/* Momentum between i and its nr ranges of candidates: the pair force f_ij (per unit depth in 2D)
 * is added to i and subtracted from j (acc holds forces during the pass; forces_momentum divides
 * by the masses after it). With `implicit` the viscous force is left out and its coupling
 * w_ij = -F fv (>= 0) is stored per lane in wl instead, with the pair viscosity the arithmetic mean
 * where numerics.viscosity_mean says so. The kernel factors F are the density pass's (fk, the
 * cache); `wendland` only shapes the kernel W of the grains' drag. With `grains` a pair of a
 * grain in water and a fluid particle is that of docs/model.md [GW]: the grain's pressure in it is
 * the water's interpolated at the grain (water_pressure_range) acting on the volume of the
 * parcel's solids (GW_SOLID times m / rho0), it carries no deviatoric stress,
 * and Ergun's drag c_ij (u_i - u_j), c_ij = beta V_i V_j W_ij, beta the grain's (granular.h) with
 * the fluid particle's mu and rho and the pair's slip |u_i - u_j|, acts between them (in the
 * implicit couplings w_ij with `implicit`). Every term stays a pair force, added to i and
 * subtracted from j. */
enum { MOMENTUM_EXPLICIT_VISCOSITY = 0, MOMENTUM_IMPLICIT_VISCOSITY = 1 };
/* momentum_range's `friction`: none, one coefficient per wall (the wall particles' wall_friction),
 * or one per (wall, medium) pair (the table bed_mu: gathers, dearer per pair) */
enum { BED_FRICTION_OFF = 0, BED_FRICTION_BY_WALL = 1, BED_FRICTION_BY_MEDIUM = 2 };

FORCES_INLINE void momentum_range(const struct pair_ctx *X, struct particles *restrict P, size_t i,
                                  const uint32_t *restrict idx, const uint32_t *restrict rng, int nr, double f_i[DIM],
                                  const double *restrict fk, double *restrict wl, const int wendland,
                                  const int implicit, const int stress, const int friction, const int grains)
{
    const double pi = P->p[i], voli = P->vol[i], mi = P->m[i], irhoi = P->inv_rho[i], mui = P->mu[i];
    const double ti = P->tag[i], avci = P->avc[i];
    const double walli = ti < 0.0 ? 1.0 : 0.0;
    double xi[DIM], vi[DIM], uvi[DIM], si[SYM_N], ni[DIM];
    const double *restrict x[DIM], *restrict v[DIM], *restrict uv[DIM], *restrict sg[SYM_N], *restrict wall_n[DIM];
    for (int d = 0; d < DIM; d++) {
        xi[d] = P->pos[d][i];
        vi[d] = P->vel[d][i];
        uvi[d] = P->uv[d][i];
        x[d] = P->pos[d];
        v[d] = P->vel[d];
        uv[d] = P->uv[d];
        wall_n[d] = P->wall_n[d];
        ni[d] = stress ? wall_n[d][i] : 0.0;
    }
    for (int c = 0; c < SYM_N; c++) {
        sg[c] = P->stress[c];
        si[c] = stress ? sg[c][i] : 0.0;
    }
    const double *restrict p = P->p, *restrict vol = P->vol;
    const double *restrict m = P->m, *restrict mu = P->mu, *restrict tag = P->tag;
    const double *restrict avc = P->avc;
    const double *restrict wall_rough = P->wall_rough, *restrict bed_mu = X->bed_mu;
    const double *restrict bed_given = X->bed_given, *restrict bed_own = X->bed_own;
    const double roughi = friction ? wall_rough[i] : 0.0;
    const double bgi = friction ? bed_given[i] : 0.0, boi = friction ? bed_own[i] : 0.0;
    /* the friction coefficients of a pair (bed_friction.h): wall j's on i's medium, down the column
     * of i's medium byte; wall i's on j's medium, along the row of its wall (its medium byte) */
    const uint8_t *restrict med = P->medium;
    const double *restrict wall_mu = P->wall_friction;
    const double wall_mu_i = friction == BED_FRICTION_BY_WALL ? wall_mu[i] : 0.0;
    const double *restrict mu_on_i = bed_mu + (P->medium[i] & (BED_FRICTION_SIDE - 1));
    const double *restrict mu_of_i = bed_mu + (size_t)(P->medium[i] & (BED_FRICTION_SIDE - 1)) * BED_FRICTION_SIDE;
    /* the grains in water (grains): roles, the water's pressure at the grains, Ergun's factors */
    const double *restrict role = grains ? X->gw[GW_ROLE] : NULL, *restrict p_water = grains ? X->gw[GW_PRESSURE] : NULL;
    const double *restrict drag_v = grains ? X->gw[GW_DRAG_VISCOUS] : NULL;
    const double *restrict drag_r = grains ? X->gw[GW_DRAG_INERTIAL] : NULL;
    const double *restrict rho = P->rho;
    const double *restrict vol0 = grains ? X->gw[GW_VOLUME] : NULL;
    const double role_i = grains ? role[i] : 0.0, p_water_i = grains ? p_water[i] : 0.0;
    const double vol0_i = grains ? vol0[i] : 0.0;
    const double *restrict solid = grains ? X->gw[GW_SOLID] : NULL;
    const double solid_i = grains ? solid[i] : 1.0;
    const double drag_vi = grains ? drag_v[i] : 0.0, drag_ri = grains ? drag_r[i] : 0.0, rhoi = P->rho[i];
#if DIM == 2
    /* i's mirror (a free-slip wall particle): cos 2theta and sin 2theta / 2 of its normal */
    const double mbi = ni[0] * ni[0] - ni[1] * ni[1];
    const double mai = ni[0] * ni[1];
#endif
    const int arithmetic = implicit && X->arithmetic_mean; /* the implicit couplings' mean */
    const struct pair_ctx Xl = *X;
    double sf[DIM][FORCES_CHUNK] = {{0}};         /* per-lane sums, reduced once */
    double ws[WALL_SUMS][FORCES_CHUNK] = {{0}};   /* i's wall sums (stress), per lane */
    FORCES_FOR_EACH_CHUNK(rng, nr, jb, n) {
        double fj[DIM][FORCES_CHUNK];
        double wj[WALL_SUMS][FORCES_CHUNK]; /* what j's wall sums receive from wall particle i */
#pragma omp simd
        for (size_t k = 0; k < FORCES_CHUNK; k++) {
            const size_t j = FORCES_J(idx, jb, k, n, i);
            const double in = FORCES_LANE_IN(k, n);
            double r[DIM], r2 = 0.0;
            DIM_UNROLL
            for (int d = 0; d < DIM; d++) {
                r[d] = xi[d] - x[d][j];
                r2 += r[d] * r[d];
            }
            const double F = fk[k];
            const double wallj = tag[j] < 0.0 ? 1.0 : 0.0;
            /* one division for 1 / (r^2 + eta^2) and 1 / (mu_i + mu_j) (a wall takes the
             * viscosity of the particle it meets; mu_i + mu_j > 0 but for wall-wall pairs,
             * which vanish; the 1e-30 keeps them finite) */
            const double muj = mu[j] + wallj * mui, mu_i = mui + walli * mu[j];
            const double r2e = r2 + Xl.eta2, mus = mu_i + muj + 1e-30;
            const double inv_d = 1.0 / (r2e * mus);
            const double inv_r2e = inv_d * mus;
            const double vv = voli * vol[j] * (1.0 - walli * wallj); /* wall-wall pairs vanish */
            /* pressure; a grain in water takes the water's (gi: i is the grain, gj: j is) */
            double gi = 0.0, gj = 0.0, pi_pair = pi, pj_pair = p[j], vv_pair = vv, vv_press = vv;
            if (grains) { /* and the grain's parcel volume m / rho0, however loose its packing */
                gi = role_i == GRAIN_ROLE_GRAIN && role[j] == GRAIN_ROLE_FLUID ? 1.0 : 0.0;
                gj = role[j] == GRAIN_ROLE_GRAIN && role_i == GRAIN_ROLE_FLUID ? 1.0 : 0.0;
                pi_pair = gi > 0.0 ? p_water_i : pi;
                pj_pair = gj > 0.0 ? p_water[j] : p[j];
                vv_pair = gi > 0.0 ? vol0_i * vol[j] : gj > 0.0 ? voli * vol0[j] : vv;
                /* the pressure acts on the volume the parcel's solids take from the water */
                vv_press = vv_pair * (gi > 0.0 ? solid_i : gj > 0.0 ? solid[j] : 1.0);
            }
            double fr = -vv_press * (pi_pair + pj_pair);
            /* artificial viscosity: approaching pairs (all pairs with av_separating) of one
             * medium (any two media with av_mixed), or of a particle and a wall (with av_wall);
             * avc is 0 for a medium without it */
            double vdotr = 0.0;
            DIM_UNROLL
            for (int d = 0; d < DIM; d++) vdotr += (vi[d] - v[d][j]) * r[d];
            vdotr = vdotr < Xl.av_cap ? vdotr : Xl.av_cap;
            const double same = (tag[j] == ti ? 1.0 : 0.0) + Xl.av_mixed * (1.0 - walli - wallj) + Xl.av_wall * (walli + wallj) > 0.0 ? 1.0 : 0.0;
            const double avc_ij = avci > avc[j] ? avci : avc[j];
            /* m_i m_j (1/rho_i + 1/rho_j) / 2 = m_i (m_j / rho_i + V_j) / 2 */
            fr += same * (1.0 - walli * wallj) * avc_ij * mi * (m[j] * irhoi + vol[j]) * vdotr * inv_r2e * 0.5;
            /* laminar viscosity, pairwise harmonic mean: mu_i + mu_j of Morris is replaced by
             * 2 mu_ij = 4 mu_i mu_j / (mu_i + mu_j); times r^2 / (r^2 + eta^2). The arithmetic
             * mean keeps Morris's mu_i + mu_j, between particles of one medium only. */
            const double fv = arithmetic && tag[j] == ti
                                  ? vv * mus * mus * r2 * inv_d
                                  : vv * 4.0 * mu_i * muj * r2 * inv_d;
            double cd = 0.0; /* Ergun's drag of a grain-fluid pair, c_ij */
            if (grains) {
                const double w = kernel_w_q(&Xl.K, kernel_q(&Xl.K, r2), wendland) * in;
                double slip2 = 0.0;
                DIM_UNROLL
                for (int d = 0; d < DIM; d++) slip2 += (uvi[d] - uv[d][j]) * (uvi[d] - uv[d][j]);
                const double beta = gi > 0.0 ? drag_vi * mu[j] + drag_ri * rho[j] * sqrt(slip2)
                                             : drag_v[j] * mui + drag_r[j] * rhoi * sqrt(slip2);
                cd = (gi + gj) * beta * vv_pair * w;
            }
            /* bed friction: to_i = 1 where wall particle j bounds grain i's shear (bed_friction.h),
             * to_j = 1 where wall particle i bounds grain j's */
            double mu_wj = 0.0, mu_wi = 0.0, given_j = 0.0, own_j = 0.0, given_i = 0.0, own_i = 0.0;
            double to_i = 0.0, to_j = 0.0;
            if (friction) { /* each coefficient given (tan delta >= 0), the grains' own or none */
                if (friction == BED_FRICTION_BY_WALL) { /* one per wall: contiguous loads, no lookup */
                    mu_wj = wall_mu[j];
                    mu_wi = wall_mu_i;
                } else {
                    const unsigned mj = med[j] & (BED_FRICTION_SIDE - 1);
                    mu_wj = mu_on_i[mj * BED_FRICTION_SIDE]; /* wall j's on grain i */
                    mu_wi = mu_of_i[mj];                     /* wall i's on grain j */
                }
                given_j = mu_wj >= 0.0 ? 1.0 : 0.0;
                own_j = mu_wj == BED_FRICTION_OWN ? 1.0 : 0.0;
                given_i = mu_wi >= 0.0 ? 1.0 : 0.0;
                own_i = mu_wi == BED_FRICTION_OWN ? 1.0 : 0.0;
                to_i = wall_rough[j] * (1.0 - walli) * (given_j * bgi + own_j * boi);
                to_j = roughi * (1.0 - wallj) * (given_i * bed_given[j] + own_i * bed_own[j]);
            }
            double f[DIM];
            if (implicit) {
                /* a bed's viscous shear on a grain is its Coulomb contact's (explicit): not in the solve */
                wl[k] = friction ? -F * fv * (1.0 - to_i - to_j) : -F * fv;
                if (grains) wl[k] += cd;
                DIM_UNROLL
                for (int d = 0; d < DIM; d++) f[d] = F * (fr * r[d]);
            } else {
                DIM_UNROLL
                for (int d = 0; d < DIM; d++) f[d] = F * (fr * r[d] + fv * (uvi[d] - uv[d][j]));
                if (grains) {
                    DIM_UNROLL
                    for (int d = 0; d < DIM; d++) f[d] -= cd * (uvi[d] - uv[d][j]);
                }
            }
            if (stress) { /* the deviatoric stress: V_i V_j (s_i + s_j) . grad_i W. A wall holds none of
                           * its own: a wall particle takes the stress s of the particle it meets, as
                           * it is on a no-slip wall, mirrored across the wall on a free-slip one
                           * (wall_mirror_change), so that the pair transmits the normal stress and
                           * no shear. */
                const double ci = 1.0 + wallj, cj = 1.0 + walli;
                double t[SYM_N];
#if DIM == 2
                const double maj = wall_n[0][j] * wall_n[1][j];
                const double mbj = wall_n[0][j] * wall_n[0][j] - wall_n[1][j] * wall_n[1][j];
                const double snt_i = maj * (si[SYM_ZZ] - si[SYM_XX]) + mbj * si[SYM_XZ]; /* i's shear on j's mirror */
                const double snt_j = mai * (sg[SYM_ZZ][j] - sg[SYM_XX][j]) + mbi * sg[SYM_XZ][j]; /* j's on i's */
                const double d_normal = 4.0 * (maj * snt_i + mai * snt_j), d_shear = 2.0 * (mbj * snt_i + mbi * snt_j);
                t[SYM_XX] = vv * (ci * si[SYM_XX] + cj * sg[SYM_XX][j] + d_normal);
                t[SYM_XZ] = vv * (ci * si[SYM_XZ] + cj * sg[SYM_XZ][j] - d_shear);
                t[SYM_ZZ] = vv * (ci * si[SYM_ZZ] + cj * sg[SYM_ZZ][j] - d_normal);
#else
                double nj[3], sj[SYM_N], mi_[SYM_N], mj_[SYM_N];
                DIM_UNROLL
                for (int d = 0; d < 3; d++) nj[d] = wall_n[d][j];
                DIM_UNROLL
                for (int c = 0; c < SYM_N; c++) sj[c] = sg[c][j];
                wall_mirror_change(nj, si, mi_); /* i's stress as wall particle j takes it */
                wall_mirror_change(ni, sj, mj_); /* j's as wall particle i takes it */
                DIM_UNROLL
                for (int c = 0; c < SYM_N; c++) t[c] = vv * (ci * si[c] + cj * sj[c] + mi_[c] + mj_[c]);
#endif
                if (grains) { /* a grain's skeleton does not push on the water: no stress in their pairs */
                    DIM_UNROLL
                    for (int c = 0; c < SYM_N; c++) t[c] *= 1.0 - gi - gj;
                }
                DIM_UNROLL
                for (int a = 0; a < DIM; a++) {
                    double tr = 0.0;
                    DIM_UNROLL
                    for (int b = 0; b < DIM; b++) tr += t[sym_index(a, b)] * r[b];
                    f[a] += F * tr;
                }
            }
            if (friction) { /* the wall sums of the bed friction: i's from a rough wall particle j that
                             * bounds i's shear, j's from such a wall particle i (its force on j is -f,
                             * its normal at j -V_i F x_ji) */
                const double qi = -vol[j] * F * to_i, qj = -voli * F * to_j;
                DIM_UNROLL
                for (int d = 0; d < DIM; d++) {
                    ws[WALL_F + d][k] += to_i * f[d];
                    ws[WALL_N + d][k] += qi * r[d];
                    ws[WALL_V + d][k] += qi * v[d][j];
                    wj[WALL_F + d][k] = -to_j * f[d];
                    wj[WALL_N + d][k] = -qj * r[d];
                    wj[WALL_V + d][k] = qj * vi[d];
                }
                ws[WALL_Q_GIVEN][k] += qi * given_j;
                ws[WALL_QMU_GIVEN][k] += qi * given_j * mu_wj;
                ws[WALL_Q_OWN][k] += qi * own_j;
                wj[WALL_Q_GIVEN][k] = qj * given_i;
                wj[WALL_QMU_GIVEN][k] = qj * given_i * mu_wi;
                wj[WALL_Q_OWN][k] = qj * own_i;
            }
            DIM_UNROLL
            for (int d = 0; d < DIM; d++) {
                sf[d][k] += f[d];
                fj[d][k] = -f[d]; /* forces: divided by the masses once, after the pass */
            }
        }
        for (int d = 0; d < DIM; d++) chunk_add(P->acc[d], idx, jb, n, i, fj[d]);
        if (friction && roughi != 0.0 && Xl.wall_sum[0])
            for (int q = 0; q < WALL_SUMS; q++) chunk_add(Xl.wall_sum[q], idx, jb, n, i, wj[q]);
        fk += FORCES_CHUNK;
        if (implicit) wl += FORCES_CHUNK;
    }
    for (int d = 0; d < DIM; d++) {
        double t = 0.0;
        for (size_t k = 0; k < FORCES_CHUNK; k++) t += sf[d][k];
        f_i[d] += t;
    }
    if (friction && Xl.wall_sum[0])
        for (int q = 0; q < WALL_SUMS; q++) {
            double t = 0.0;
            for (size_t k = 0; k < FORCES_CHUNK; k++) t += ws[q][k];
            Xl.wall_sum[q][i] += t;
        }
}

/* Whether particle i takes density diffusion: fluids do; walls do not (their density is the
 * fluid's, extrapolated), nor do grains (their density carries their packing and, under the
 * elastic-plastic law, the elastic pressure of a stress state: diffused, a heap that stands
 * creeps, docs/numerics.md section 2c). A pair diffuses only within one medium, so i decides. */
FORCES_INLINE int diffuses(const struct pair_ctx *X, const struct particles *restrict P, size_t i)
{
    return P->tag[i] >= 0.0 && (X->media[P->medium[i]].features & LAW_DENSITY_DIFFUSION);
}

/* hyd_i of continuity_range: rho0 g / c^2 of i's medium with the hydrostatic form of the
 * diffusion, 0 with Molteni's and for walls (which take no diffusion). */
FORCES_INLINE double diffusion_hydrostatic(const struct pair_ctx *X, const struct particles *restrict P, size_t i)
{
    if (P->tag[i] < 0.0) return 0.0;
    const struct medium *m = &X->media[P->medium[i]];
    return m->rho0 * X->diffusion_g / (m->c * m->c);
}

/* D_i of particle i in medium m from its sum e_i = sum_j V_j psi_ij (-F_ij): [DD] of
 * docs/numerics.md section 2c, 2 delta h c_i e_i. */
static inline double diffusion_rate(double delta_h, const struct medium *m, double e_i)
{
    return 2.0 * delta_h * m->c * e_i;
}

/* The band walks, one inlined copy per kernel (`wendland` constant), dispatched below. */
FORCES_INLINE void continuity_walk(const struct pair_ctx *X, const struct neighbours *NB, struct particles *restrict P,
                                   size_t b0, size_t b1, const int grains, const int diffuse, const int wendland)
{
    for (size_t i = b0; i < b1; i++) {
        double di = 0.0, ni = 0.0, ei = 0.0;
        const int diffuse_i = diffuse && diffuses(X, P, i);
        const double hyd_i = diffuse_i ? diffusion_hydrostatic(X, P, i) : 0.0;
        uint32_t buf[2];
        continuity_range(X, P, i, X->idx, pair_ranges(X, NB, i, buf), PAIR_RANGES, &di, &ni, &ei, X->count,
                         X->fk + X->fk_off[i], X->diffusion, hyd_i, wendland, diffuse_i, grains);
        P->drho[i] += di;
        X->count[i] += ni;
        if (diffuse_i) X->diffusion[i] += ei;
    }
}

FORCES_CLONES
static void gradient_particle(const struct pair_ctx *X, const struct gather *G, const struct particles *restrict P,
                              struct velocity_gradient *restrict out, size_t i)
{
    double acc[GRADIENT_SUMS] = {0};
    const uint32_t *rng = G->rng + 2 * CELLS_ROWS_AROUND * i;
    if (X->wendland) gradient_range(X, P, i, rng, CELLS_ROWS_AROUND, acc, 1);
    else gradient_range(X, P, i, rng, CELLS_ROWS_AROUND, acc, 0);
    for (int q = 0; q < DIM * DIM; q++) out->g[q][i] = acc[q];
    for (int q = 0; q < VELOCITY_GRADIENT_L_N; q++) out->l[q][i] = acc[DIM * DIM + q];
}

/* momentum_range with the (wall, medium) table of bed friction coefficients: one copy, its
 * options taken at run time, rather than one per combination of them as for the other walks (a
 * case whose walls give media different friction angles is rare; this copy runs slower, and
 * forces.c builds in half the time). */
static __attribute__((noinline)) void momentum_range_by_medium(const struct pair_ctx *X, struct particles *restrict P,
                                                               size_t i, const uint32_t *restrict rng, double f[DIM],
                                                               const double *restrict fk, double *restrict wl,
                                                               int wendland, int implicit, int stress, int grains)
{
    momentum_range(X, P, i, X->idx, rng, PAIR_RANGES, f, fk, wl, wendland, implicit, stress, BED_FRICTION_BY_MEDIUM,
                   grains);
}

FORCES_INLINE void momentum_walk(const struct pair_ctx *X, const struct neighbours *NB, struct particles *restrict P,
                                 size_t b0, size_t b1, const int implicit, const int stress, const int friction,
                                 const int grains)
{
    const int wendland = X->wendland;
    for (size_t i = b0; i < b1; i++) {
        double f[DIM] = {0.0};
        uint32_t buf[2];
        const uint32_t *rng = pair_ranges(X, NB, i, buf);
        const double *fk = X->fk + X->fk_off[i];
        double *wl = implicit ? X->visc_w + X->fk_off[i] : NULL;
        /* The bed friction's sums of a pair vanish unless i is a grain whose shear walls bound or a
         * wall particle that bounds one (to_i = to_j = 0 in momentum_range): the other particles,
         * the water's most, walk their pairs without them, to the same forces bit for bit. */
        if (friction && (P->wall_rough[i] != 0.0 || X->bed_given[i] != 0.0 || X->bed_own[i] != 0.0)) {
            if (X->bed_per_medium)
                momentum_range_by_medium(X, P, i, rng, f, fk, wl, wendland, implicit, stress, grains);
            else
                momentum_range(X, P, i, X->idx, rng, PAIR_RANGES, f, fk, wl, wendland, implicit, stress,
                               BED_FRICTION_BY_WALL, grains);
        } else
            momentum_range(X, P, i, X->idx, rng, PAIR_RANGES, f, fk, wl, wendland, implicit, stress, 0, grains);
        for (int d = 0; d < DIM; d++) P->acc[d][i] += f[d];
    }
}

/* The viscous operator's pair sums over i's ranges: for each component,
 * out_i += sum_j w_ij (in_i - in_j) and out_j -= w_ij (in_i - in_j); with `diagonal` also
 * diag_i += sum_j w_ij and diag_j += w_ij. */
FORCES_INLINE void viscous_range(const struct pair_ctx *X, size_t i, const uint32_t *restrict idx, const uint32_t *restrict rng,
                                 const double *restrict wl, const int diagonal)
{
    const double *restrict u[DIM];
    double *restrict o[DIM];
    double ui[DIM];
    for (int d = 0; d < DIM; d++) {
        u[d] = X->in[d];
        o[d] = X->out[d];
        ui[d] = u[d][i];
    }
    double *restrict od = X->out_diag;
    double so[DIM][FORCES_CHUNK] = {{0}}, sd[FORCES_CHUNK] = {0};
    FORCES_FOR_EACH_CHUNK(rng, PAIR_RANGES, jb, m) {
        double oj[DIM][FORCES_CHUNK];
#pragma omp simd
        for (size_t k = 0; k < FORCES_CHUNK; k++) {
            const size_t j = FORCES_J(idx, jb, k, m, i);
            const double w = wl[k];
            DIM_UNROLL
            for (int d = 0; d < DIM; d++) {
                const double du = w * (ui[d] - u[d][j]);
                so[d][k] += du;
                oj[d][k] = -du;
            }
            if (diagonal) sd[k] += w;
        }
        for (int d = 0; d < DIM; d++) chunk_add(o[d], idx, jb, m, i, oj[d]);
        if (diagonal) chunk_add(od, idx, jb, m, i, wl);
        wl += FORCES_CHUNK;
    }
    for (int d = 0; d < DIM; d++) {
        double t = 0.0;
        for (size_t k = 0; k < FORCES_CHUNK; k++) t += so[d][k];
        o[d][i] += t;
    }
    if (diagonal) {
        double td = 0.0;
        for (size_t k = 0; k < FORCES_CHUNK; k++) td += sd[k];
        od[i] += td;
    }
}

FORCES_CLONES
static void viscous_band(const struct pair_ctx *X, const struct neighbours *NB, struct particles *restrict P,
                         size_t b0, size_t b1)
{
    (void)P;
    const int diagonal = X->out_diag != NULL;
    for (size_t i = b0; i < b1; i++) {
        uint32_t buf[2];
        const uint32_t *rng = pair_ranges(X, NB, i, buf);
        if (diagonal) viscous_range(X, i, X->idx, rng, X->visc_w + X->fk_off[i], 1);
        else viscous_range(X, i, X->idx, rng, X->visc_w + X->fk_off[i], 0);
    }
}

/* The couplings of the pairs of i's two ranges summed by the group of their other end (see
 * forces_viscous_group_couplings). */
static void group_band(const struct pair_ctx *X, const struct neighbours *NB, struct particles *restrict P, size_t b0,
                       size_t b1)
{
    (void)P;
    const int32_t *group = X->group;
    const uint32_t *idx = X->idx;
    const long s = X->group_stride;
    for (size_t i = b0; i < b1; i++) {
        const int32_t gi = group[i];
        if (gi < 0) continue;
        double *gw = X->group_w + 5 * (size_t)gi;
        uint32_t buf[2];
        const uint32_t *rng = pair_ranges(X, NB, i, buf);
        const double *wl = X->visc_w + X->fk_off[i];
        FORCES_FOR_EACH_CHUNK(rng, PAIR_RANGES, jb, m) {
                for (size_t k = 0; k < m; k++) {
                    const int32_t gj = group[FORCES_J(idx, jb, k, m, i)];
                    if (gj < 0) continue;
                    const long d = (long)gj - (long)gi;
                    const int slot = d == 0 ? 0 : d == 1 ? 1 : d == s - 1 ? 2 : d == s ? 3 : 4;
                    gw[slot] += wl[k];
                }
                wl += FORCES_CHUNK;
            }
    }
}

FORCES_CLONES
static void water_pressure_band(const struct pair_ctx *X, const struct neighbours *NB, struct particles *restrict P,
                                size_t b0, size_t b1)
{
    double *sum = X->gw[GW_SUM], *weight = X->gw[GW_WEIGHT];
    for (size_t i = b0; i < b1; i++) {
        double a = 0.0, u = 0.0;
        uint32_t buf[2];
        const uint32_t *rng = pair_ranges(X, NB, i, buf);
        if (X->wendland) water_pressure_range(X, P, i, X->idx, rng, PAIR_RANGES, X->g, &a, &u, sum, weight, 1);
        else water_pressure_range(X, P, i, X->idx, rng, PAIR_RANGES, X->g, &a, &u, sum, weight, 0);
        sum[i] += a;
        weight[i] += u;
    }
}

FORCES_CLONES
static void smooth_band(const struct pair_ctx *X, const struct neighbours *NB, struct particles *restrict P, size_t b0,
                        size_t b1)
{
    for (size_t i = b0; i < b1; i++) {
        if (P->tag[i] < 0.0) continue; /* walls neither smooth nor are smoothed */
        double a = 0.0, u = 0.0;
        uint32_t buf[2];
        const uint32_t *rng = pair_ranges(X, NB, i, buf);
        if (X->wendland) smooth_range(X, P, i, X->idx, rng, PAIR_RANGES, X->g, &a, &u, X->sum, X->weight, 1);
        else smooth_range(X, P, i, X->idx, rng, PAIR_RANGES, X->g, &a, &u, X->sum, X->weight, 0);
        X->sum[i] += a;
        X->weight[i] += u;
    }
}

/* Call walk(X, ..., wendland) with the kernel as a constant: one inlined copy of the walk per
 * kernel (the density pass evaluates it; the momentum pass reads its factors from the cache). */
#define FORCES_DISPATCH(walk, X, ...)                   \
    do {                                                \
        if ((X)->wendland) walk(X, __VA_ARGS__, 1);     \
        else walk(X, __VA_ARGS__, 0);                   \
    } while (0)

FORCES_CLONES
static void continuity_band(const struct pair_ctx *X, const struct neighbours *NB, struct particles *restrict P,
                            size_t b0, size_t b1)
{
    if (X->gw[GW_ROLE]) {
        if (X->diffusion) FORCES_DISPATCH(continuity_walk, X, NB, P, b0, b1, 1, 1);
        else FORCES_DISPATCH(continuity_walk, X, NB, P, b0, b1, 1, 0);
    } else {
        if (X->diffusion) FORCES_DISPATCH(continuity_walk, X, NB, P, b0, b1, 0, 1);
        else FORCES_DISPATCH(continuity_walk, X, NB, P, b0, b1, 0, 0);
    }
}

/* The momentum band walk, one inlined copy per use of the stress term, of the bed friction's sums and of
 * the grains in water. */
FORCES_INLINE void momentum_band_variant(const struct pair_ctx *X, const struct neighbours *NB,
                                         struct particles *restrict P, size_t b0, size_t b1, const int stress,
                                         const int friction, const int grains)
{
    if (X->visc_w) momentum_walk(X, NB, P, b0, b1, MOMENTUM_IMPLICIT_VISCOSITY, stress, friction, grains);
    else momentum_walk(X, NB, P, b0, b1, MOMENTUM_EXPLICIT_VISCOSITY, stress, friction, grains);
}

FORCES_CLONES
static void momentum_band(const struct pair_ctx *X, const struct neighbours *NB, struct particles *restrict P,
                          size_t b0, size_t b1)
{
    /* the grains in water come with a granular law that has a stress (the elastic-plastic law) */
    if (X->gw[GW_ROLE]) momentum_band_variant(X, NB, P, b0, b1, 1, X->bed_friction, 1);
    else if (X->stress) momentum_band_variant(X, NB, P, b0, b1, 1, X->bed_friction, 0);
    else if (X->bed_friction) momentum_band_variant(X, NB, P, b0, b1, 0, 1, 0);
    else momentum_band_variant(X, NB, P, b0, b1, 0, 0, 0);
}

struct forces *forces_create(void) { return calloc(1, sizeof(struct forces)); }

void forces_free(struct forces *F)
{
    if (!F) return;
    aligned_block_free(F->fk);
    free(F->fk_off);
    free(F->nbr_count);
    free(F->smooth_sum);
    free(F->smooth_weight);
    for (int q = 0; q < WALL_SUMS; q++) free(F->wall_sum[q]);
    for (int q = 0; q < GW_ARRAYS; q++) free(F->gw[q]);
    free(F->bed_given);
    free(F->bed_own);
    free(F->diffusion_sum);
    aligned_block_free(F->visc_w);
    neighbours_pair_list_free(&F->list);
#if DIM == 3
    neighbours_pair_blocks_free(&F->blocks);
#endif
    free(F);
}

int forces_cache_pending(const struct forces *F) { return F->fk_valid; }

void forces_forget_cache(struct forces *F)
{
    F->fk_valid = 0;
    F->visc_valid = 0;
}

int forces_viscous_ready(const struct forces *F) { return F->visc_valid; }

/* The kernel-factor cache: the density pass stores F(r_ij) of every lane it evaluates (masked
 * lanes 0), and the momentum pass of the same step, at the same positions and over the same
 * ranges, reads it instead of evaluating the kernel again (a square root and, for the cubic
 * spline, a division per lane): the same numbers, so results are unchanged. Lanes of particle i
 * start at fk_off[i], FORCES_CHUNK per chunk of each of its ranges (pair_ranges). Returns -1 if the cache
 * cannot be allocated (out of memory: the momentum pass has no copy of its walks that evaluates
 * the kernel, which would double the build time of this file). */
static int fcache_layout(struct forces *F, const struct pair_ctx *X, const struct neighbours *NB, size_t n)
{
#if DIM == 3 /* the list's layout, kept until the list is made again (pair_list_attach) */
    if (F->fk_layout_ok) return 0;
#endif
    if (F->fk_off_cap < n + 1) {
        size_t *o = realloc(F->fk_off, (n + 1) * sizeof *o);
        if (!o) return -1;
        F->fk_off = o;
        F->fk_off_cap = n + 1;
    }
    size_t total = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t buf[2];
        const uint32_t *rng = pair_ranges(X, NB, i, buf);
        F->fk_off[i] = total;
        for (int r = 0; r < PAIR_RANGES; r++) {
            const size_t len = rng[2 * r + 1] - rng[2 * r];
            total += (len + FORCES_CHUNK - 1) / FORCES_CHUNK * FORCES_CHUNK;
        }
    }
    F->fk_off[n] = total;
    if (F->fk_cap < total) {
        const size_t cap = total + total / 4 + FORCES_CHUNK;
        aligned_block_free(F->fk);
        F->fk = aligned_block((cap * sizeof(double) + 63) / 64 * 64);
        F->fk_cap = F->fk ? cap : 0;
        if (!F->fk) return -1;
    }
#if DIM == 3
    F->fk_layout_ok = 1;
#endif
    return 0;
}

/* In 3D the pair loops walk the pair list of the current neighbour lists (neighbours.h), made
 * here at the first pass after each build of the lists (the neighbour search leaves walls to the
 * state, which the list needs); in 2D they walk the ranges and X is left as it is. */
static int pair_list_attach(struct forces *F, const struct pair_system *S, size_t n, struct pair_ctx *X)
{
#if DIM == 3
    struct pair_list *L = &F->list;
    /* the cells' row spacing is the lists' cut-off, 2h + skin (sim.c) */
    if (!L->valid || L->builds != S->NB->builds || L->n != n) {
        F->fk_layout_ok = 0;
        if (neighbours_pair_list_build(L, S->NB, S->P->state, n, S->C->size, S->n_threads) != 0 ||
            neighbours_pair_blocks_build(&F->blocks, L, S->C) != 0) {
            L->valid = 0;
            return -1;
        }
    }
    X->idx = L->j;
    X->list_start = L->start;
    X->blocks = &F->blocks;
#else
    (void)F;
    (void)S;
    (void)n;
    (void)X;
#endif
    return 0;
}

/* Room for n particles' scratch sums (zeroed padding past the end for the chunked loops). */
static int scratch_reserve(struct forces *F, size_t n)
{
    if (F->scratch_cap >= n) return 0;
    const size_t cap = n + n / 4 + 64;
    double **a[6 + WALL_SUMS + GW_ARRAYS] = {&F->nbr_count, &F->smooth_sum, &F->smooth_weight, &F->diffusion_sum,
                                             &F->bed_given, &F->bed_own};
    for (int q = 0; q < WALL_SUMS; q++) a[6 + q] = &F->wall_sum[q];
    for (int q = 0; q < GW_ARRAYS; q++) a[6 + WALL_SUMS + q] = &F->gw[q];
    for (int k = 0; k < 6 + WALL_SUMS + GW_ARRAYS; k++) {
        double *q = realloc(*a[k], (cap + FORCES_CHUNK) * sizeof(double));
        if (!q) return -1;
        memset(q, 0, (cap + FORCES_CHUNK) * sizeof(double));
        *a[k] = q;
    }
    F->scratch_cap = cap;
    return 0;
}

typedef void (*band_fn)(const struct pair_ctx *, const struct neighbours *, struct particles *restrict, size_t, size_t);

/* Walk `fn` over all bands of FORCES_BAND_ROWS cell rows, even bands in parallel, then odd, the
 * threads taking bands one at a time from the counters bands[0] (even) and bands[1] (odd), reset
 * before the region: to be called by every thread of a team region (core/team.h), each phase
 * ending with a barrier (the odd one not with `last_nowait`); with one thread, the calling
 * thread walks them all in the same order. A pass runs its bands and its per-particle loop after
 * them in one region, so that a step has few fork-joins and barriers: each waits for a thread
 * that another process may have descheduled (docs/performance.md, "Under load"). */
#if DIM == 2
enum { FORCES_PHASES = 2 }; /* even bands, odd bands */
static void bands_in_team(const struct pair_system *S, band_fn fn, const struct pair_ctx *X,
                          team_counter bands[FORCES_PHASES], int last_nowait)
{
    const struct cells *C = S->C;
    const long layers = C->n[DIM_UP], nb = (layers + FORCES_BAND_ROWS - 1) / FORCES_BAND_ROWS;
    struct particles *P = S->P;
#define FORCES_BAND(b)                                                                                        \
    do {                                                                                                      \
        const long r0 = (b) * FORCES_BAND_ROWS;                                                               \
        const long r1 = r0 + FORCES_BAND_ROWS < layers ? r0 + FORCES_BAND_ROWS : layers;                      \
        fn(X, S->NB, P, C->start[(size_t)r0 * C->layer], C->start[(size_t)r1 * C->layer]);                   \
    } while (0)
    for (long b; (b = 2 * team_next(&bands[0])) < nb;) FORCES_BAND(b);
    team_barrier();
    for (long b; (b = 2 * team_next(&bands[1]) + 1) < nb;) FORCES_BAND(b);
    if (!last_nowait) team_barrier();
#undef FORCES_BAND
}

#else
/* In 3D the phases are the colours of the pair list's blocks (neighbours.h: layers cut along a
 * second axis, so that two threads find several loaded blocks in every phase), the threads taking
 * a colour's blocks one at a time, longest first, from the counter bands[c]; otherwise as in 2D. */
enum { FORCES_PHASES = NEIGHBOURS_COLOURS };
static void bands_in_team(const struct pair_system *S, band_fn fn, const struct pair_ctx *X,
                          team_counter bands[FORCES_PHASES], int last_nowait)
{
    const struct cells *C = S->C;
    const struct pair_blocks *B = X->blocks;
    const size_t ranges = neighbours_block_ranges(B, C);
    for (int c = 0; c < NEIGHBOURS_COLOURS; c++) {
        const long nb = (long)(B->first[c + 1] - B->first[c]);
        for (long k; (k = team_next(&bands[c])) < nb;)
            for (size_t q = 0; q < ranges; q++) {
                const struct range r = neighbours_block_range(B, C, B->first[c] + (size_t)k, q);
                if (r.end > r.begin) fn(X, S->NB, S->P, r.begin, r.end);
            }
        if (c + 1 < NEIGHBOURS_COLOURS || !last_nowait) team_barrier();
    }
}
#endif

/* A pass's parallel region: its pair context, band counters and outcome. */
struct pass_region {
    const struct pair_system *S;
    const struct pair_ctx *X;
    band_fn fn;
    team_counter bands[FORCES_PHASES];
    size_t n;                         /* active particles */
    struct velocity_gradient *grad;   /* density pass: the grains' velocity gradient, or NULL */
    const double *count;              /* density pass: the neighbour counts */
    const double *diffusion;          /* density pass: the density diffusion's sums, or NULL (off) */
    double delta_h;                   /* density pass: delta h of the density diffusion */
    double g;                         /* momentum pass: gravity */
    const double *const *wall_sums;   /* momentum pass with bed friction: the walls' sums */
    const double *bed_given, *bed_own; /* and which walls bound each particle's shear */
    double theta_dt_over_h;           /* smoothing */
    const double *sum, *weight;       /* smoothing: its sums */
    int bad;                          /* a non-finite rate (| over the threads) */
};

static void pass_region_init(struct pass_region *R, const struct pair_system *S, const struct pair_ctx *X, band_fn fn,
                             size_t n)
{
    memset(R, 0, sizeof *R);
    R->S = S;
    R->X = X;
    R->fn = fn;
    R->n = n;
    for (int c = 0; c < FORCES_PHASES; c++) team_counter_reset(&R->bands[c]);
}

/* A region of the bands alone (the viscous operator, the group couplings). */
static void bands_region(void *arg, int tid, int nth)
{
    (void)tid;
    (void)nth;
    struct pass_region *R = arg;
    bands_in_team(R->S, R->fn, R->X, R->bands, 1);
}

static size_t active_count(const struct pair_system *S) { return S->C->start[S->C->ncell]; }

/* The roles of the n active particles and the grains' Ergun factors (docs/model.md [GW]), into X's
 * arrays; the padding after them neutral. Needs scratch_reserve(F, n). */
static void grains_in_water_roles(struct forces *F, const struct pair_system *S, size_t n, struct pair_ctx *X)
{
    const struct particles *P = S->P;
    double *role = F->gw[GW_ROLE], *dv = F->gw[GW_DRAG_VISCOUS], *dr = F->gw[GW_DRAG_INERTIAL];
    double *vol0 = F->gw[GW_VOLUME], *solid = F->gw[GW_SOLID];
    for (size_t i = 0; i < n; i++) {
        const struct medium *m = &S->media[P->medium[i]];
        const int wall = P->state[i] == MIXSPH_STATE_WALL;
        const int grain = !wall && (m->features & LAW_GRAINS_IN_WATER);
        role[i] = grain ? GRAIN_ROLE_GRAIN : !wall && (m->features & LAW_FLUID) ? GRAIN_ROLE_FLUID : 0.0;
        dv[i] = grain ? m->granular.drag_viscous : 0.0;
        dr[i] = grain ? m->granular.drag_inertial : 0.0;
        vol0[i] = grain ? P->m[i] / m->rho0 : 0.0;
        solid[i] = grain && !m->granular.saturated ? 1.0 - m->granular.porosity : 1.0;
    }
    for (size_t i = n; i < n + FORCES_CHUNK; i++) role[i] = dv[i] = dr[i] = vol0[i] = 0.0, solid[i] = 1.0;
    for (int q = 0; q < GW_ARRAYS; q++) X->gw[q] = F->gw[q];
}

/* The water's pressure interpolated at each grain in water (water_pressure_range), at least the
 * background pressure (the water's at a free surface: it holds no tension on a grain); a grain
 * with no fluid neighbour keeps its own (it meets no fluid particle). */
static void water_pressure_region(void *arg, int tid, int nth)
{
    struct pass_region *R = arg;
    struct particles *P = R->S->P;
    const struct pair_ctx *X = R->X;
    const double pb = R->S->params.p_background;
    bands_in_team(R->S, water_pressure_band, X, R->bands, 0);
    size_t b, e;
    team_share(R->n, tid, nth, &b, &e);
    const double *role = X->gw[GW_ROLE], *sum = X->gw[GW_SUM], *weight = X->gw[GW_WEIGHT];
    double *pw = X->gw[GW_PRESSURE];
    for (size_t i = b; i < e; i++)
        pw[i] = role[i] == GRAIN_ROLE_GRAIN && weight[i] > 0.0 ? fmax(sum[i] / weight[i], pb) : P->p[i];
}

/* The density pass, and with `grad` the velocity gradient of the grains, in one parallel
 * region: the gradient reads positions, velocities and volumes, which the density pass does not
 * write, so it runs while the last bands finish; the per-particle loop after the bands waits for
 * them. */
static void density_region(void *arg, int tid, int nth)
{
    struct pass_region *R = arg;
    struct particles *P = R->S->P;
    const struct medium *M = R->S->media;
    const double *count = R->count;
    bands_in_team(R->S, continuity_band, R->X, R->bands, R->grad != NULL);
    size_t b, e;
    team_share(R->n, tid, nth, &b, &e);
    if (R->grad) {
        for (size_t i = b; i < e; i++)
            if (P->state[i] <= MIXSPH_STATE_FIXED && (M[P->medium[i]].features & LAW_USES_GRADIENT))
                gradient_particle(R->X, R->S->G, P, R->grad, i);
        team_barrier(); /* the last bands */
    }
    int bad = 0;
    for (size_t i = b; i < e; i++) {
        P->drho[i] *= P->rho[i];
        if (R->diffusion && P->tag[i] >= 0.0) P->drho[i] += diffusion_rate(R->delta_h, &M[P->medium[i]], R->diffusion[i]);
        P->nneigh[i] = (uint16_t)(count[i] < 65535.0 ? count[i] : 65535.0);
        bad |= P->state[i] == MIXSPH_STATE_MOBILE && !isfinite(P->drho[i]);
    }
    team_or_int(&R->bad, bad);
}

static int density_rate(struct forces *F, const struct pair_system *S, struct velocity_gradient *grad)
{
    struct particles *P = S->P;
    struct pair_ctx X;
    pair_ctx_init(S, &X);
    const size_t n = active_count(S);
    if (scratch_reserve(F, n) != 0 || pair_list_attach(F, S, n, &X) != 0) return -1;
    memset(P->drho, 0, n * sizeof(double));
    memset(F->nbr_count, 0, n * sizeof(double));
    X.count = F->nbr_count;
    if (S->params.grains_in_water) grains_in_water_roles(F, S, n, &X);
    const double delta_h = S->params.diffusion * X.K.h;
    if (delta_h > 0.0) {
        memset(F->diffusion_sum, 0, n * sizeof(double));
        X.diffusion = F->diffusion_sum;
    }
    const double *diffusion = X.diffusion;
    /* the kernel factors for the momentum pass at these positions (out of memory without them) */
    F->fk_valid = 0;
    if (fcache_layout(F, &X, S->NB, n) != 0) return -1;
    F->fk_valid = 1;
    X.fk = F->fk;
    X.fk_off = F->fk_off;
    struct pass_region R;
    pass_region_init(&R, S, &X, continuity_band, n);
    R.grad = grad;
    R.count = F->nbr_count;
    R.diffusion = diffusion;
    R.delta_h = delta_h;
    team_run(S->n_threads, density_region, &R);
    return R.bad;
}

int forces_density_rate(struct forces *F, const struct pair_system *S) { return density_rate(F, S, NULL); }

int forces_density_rate_gradient(struct forces *F, const struct pair_system *S, struct velocity_gradient *grad)
{
    return density_rate(F, S, grad);
}

static void gradient_region(void *arg, int tid, int nth)
{
    const struct pass_region *R = arg;
    const struct particles *P = R->S->P;
    const struct medium *M = R->S->media;
    size_t b, e;
    team_share(R->n, tid, nth, &b, &e);
    for (size_t i = b; i < e; i++)
        if (P->state[i] <= MIXSPH_STATE_FIXED && (M[P->medium[i]].features & LAW_USES_GRADIENT))
            gradient_particle(R->X, R->S->G, P, R->grad, i);
}

void forces_velocity_gradient(const struct pair_system *S, struct velocity_gradient *out)
{
    struct pair_ctx X;
    pair_ctx_init(S, &X);
    struct pass_region R;
    pass_region_init(&R, S, &X, NULL, active_count(S));
    R.grad = out;
    team_run(S->n_threads, gradient_region, &R);
}

/* The bed friction of grain i (bed_friction.h) from its wall sums: its walls' friction coefficient
 * is their tan(delta) weighted by q (its medium's tan(phi) where a wall takes it), their velocity
 * the q-weighted mean. `f` holds its pair force; gravity is added for the stick force only. */
static void bed_friction_apply(const struct pass_region *R, const struct particles *P, size_t i, double tan_phi,
                               double f[DIM])
{
    const double *const *ws = R->wall_sums;
    const double q = ws[WALL_Q_GIVEN][i] + ws[WALL_Q_OWN][i];
    if (!(q > 0.0)) return;
    struct bed_contact c = {.tan_delta = (ws[WALL_QMU_GIVEN][i] + ws[WALL_Q_OWN][i] * tan_phi) / q,
                            .mass = P->m[i], .volume = P->vol[i], .p_background = R->S->params.p_background,
                            .pore_pressure = P->pore_p[i], .dt = R->S->dt};
    for (int d = 0; d < DIM; d++) {
        c.wall_force[d] = ws[WALL_F + d][i];
        c.normal[d] = ws[WALL_N + d][i];
        c.wall_velocity[d] = ws[WALL_V + d][i] / q;
        c.force[d] = d == DIM_UP ? f[d] - P->m[i] * R->g : f[d];
        c.velocity[d] = P->vel[d][i];
    }
    double change[DIM];
    bed_friction_change(&c, change);
    for (int d = 0; d < DIM; d++) f[d] += change[d];
}

static void momentum_region(void *arg, int tid, int nth)
{
    struct pass_region *R = arg;
    struct particles *P = R->S->P;
    const struct medium *M = R->S->media;
    const double g = R->g;
    bands_in_team(R->S, momentum_band, R->X, R->bands, 0);
    size_t b, e;
    team_share(R->n, tid, nth, &b, &e);
    int bad = 0;
    for (size_t i = b; i < e; i++) {
        if (P->state[i] == MIXSPH_STATE_WALL) continue; /* keeps the force on it: its wall's work (walls_move) */
        if (R->wall_sums && (R->bed_given[i] != 0.0 || R->bed_own[i] != 0.0)) {
            const double s = M[P->medium[i]].granular.sin_phi;
            double f[DIM];
            for (int d = 0; d < DIM; d++) f[d] = P->acc[d][i];
            bed_friction_apply(R, P, i, s / sqrt(1.0 - s * s), f);
            for (int d = 0; d < DIM; d++) P->acc[d][i] = f[d];
        }
        double sum = 0.0;
        for (int d = 0; d < DIM; d++) { /* the pass summed forces */
            P->acc[d][i] = d == DIM_UP ? P->acc[d][i] * P->inv_m[i] - g : P->acc[d][i] * P->inv_m[i];
            sum += P->acc[d][i];
        }
        bad |= P->state[i] == MIXSPH_STATE_MOBILE && !isfinite(sum);
    }
    team_or_int(&R->bad, bad);
}

int forces_momentum(struct forces *F, const struct pair_system *S)
{
    struct particles *P = S->P;
    struct pair_ctx X;
    pair_ctx_init(S, &X);
    const size_t n = active_count(S);
    for (int d = 0; d < DIM; d++) memset(P->acc[d], 0, n * sizeof(double));
    F->visc_valid = 0;
    if (pair_list_attach(F, S, n, &X) != 0) return -1;
    /* the kernel factors of the density pass of this step, at these positions (the implicit
     * couplings are stored in their lane layout) */
    if (!F->fk_valid) return -1;
    X.fk = F->fk;
    X.fk_off = F->fk_off;
    if (S->params.implicit_viscosity) {
        const size_t lanes = F->fk_off[n];
        if (F->visc_w_cap < lanes) {
            const size_t cap = lanes + lanes / 4 + FORCES_CHUNK;
            aligned_block_free(F->visc_w);
            F->visc_w = aligned_block((cap * sizeof(double) + 63) / 64 * 64);
            F->visc_w_cap = F->visc_w ? cap : 0;
            if (!F->visc_w) return -1;
        }
        X.visc_w = F->visc_w;
    }
    F->fk_valid = 0;
    const int friction = X.bed_friction;
    if ((friction || S->params.grains_in_water) && scratch_reserve(F, n) != 0) return -1;
    if (S->params.grains_in_water) { /* the water's pressure at the grains, before the pairs use it */
        grains_in_water_roles(F, S, n, &X);
        memset(F->gw[GW_SUM], 0, n * sizeof(double));
        memset(F->gw[GW_WEIGHT], 0, n * sizeof(double));
        struct pass_region W;
        pass_region_init(&W, S, &X, water_pressure_band, n);
        team_run(S->n_threads, water_pressure_region, &W);
        for (size_t i = n; i < n + FORCES_CHUNK; i++) F->gw[GW_PRESSURE][i] = 0.0;
    }
    if (friction) {
        for (int q = 0; q < WALL_SUMS; q++) {
            memset(F->wall_sum[q], 0, n * sizeof(double));
            X.wall_sum[q] = F->wall_sum[q];
        }
        for (size_t i = 0; i < n; i++) { /* which walls bound a grain's shear: its law's (laws/medium.h) */
            const unsigned ft = P->state[i] == MIXSPH_STATE_WALL ? 0u : S->media[P->medium[i]].features;
            F->bed_given[i] = ft & (LAW_WALL_FRICTION | LAW_WALL_FRICTION_GIVEN) ? 1.0 : 0.0;
            F->bed_own[i] = ft & LAW_WALL_FRICTION ? 1.0 : 0.0;
        }
        X.bed_given = F->bed_given;
        X.bed_own = F->bed_own;
    }
    struct pass_region R;
    pass_region_init(&R, S, &X, momentum_band, n);
    R.g = X.g;
    R.wall_sums = friction ? (const double *const *)F->wall_sum : NULL;
    R.bed_given = F->bed_given;
    R.bed_own = F->bed_own;
    team_run(S->n_threads, momentum_region, &R);
    F->visc_valid = X.visc_w != NULL;
    return R.bad;
}

/* A pass context over the couplings the last implicit momentum pass stored; -1 without them. */
static int stored_couplings(const struct forces *F, const struct pair_system *S, struct pair_ctx *X)
{
    if (!F->visc_valid) return -1;
    pair_ctx_init(S, X);
    X->visc_w = F->visc_w;
    X->fk_off = F->fk_off;
    X->idx = F->list.j; /* 3D: the pair list they were stored over (2D: unused) */
    X->list_start = F->list.start;
#if DIM == 3
    X->blocks = &F->blocks;
#endif
    return 0;
}

int forces_viscous_apply(const struct forces *F, const struct pair_system *S, const double *const in[DIM],
                         double *const out[DIM], double *diag)
{
    struct pair_ctx X;
    if (stored_couplings(F, S, &X) != 0) return -1;
    const size_t n = active_count(S);
    for (int d = 0; d < DIM; d++) {
        memset(out[d], 0, n * sizeof(double));
        X.in[d] = in[d];
        X.out[d] = out[d];
    }
    if (diag) memset(diag, 0, n * sizeof(double));
    X.out_diag = diag;
    struct pass_region R;
    pass_region_init(&R, S, &X, viscous_band, n);
    team_run(S->n_threads, bands_region, &R);
    return 0;
}

int forces_viscous_group_couplings(const struct forces *F, const struct pair_system *S, const int32_t *group,
                                   long groups_per_row, double *sums)
{
    struct pair_ctx X;
    if (stored_couplings(F, S, &X) != 0) return -1;
    X.group = group;
    X.group_stride = groups_per_row;
    X.group_w = sums;
    struct pass_region R;
    pass_region_init(&R, S, &X, group_band, active_count(S));
    team_run(S->n_threads, bands_region, &R);
    return 0;
}

void forces_pair_for_test(const struct pair_system *S, size_t i, size_t j, double a[DIM], double *drho)
{
    struct pair_ctx X;
    pair_ctx_init(S, &X);
    struct particles *P = S->P;
    double save[DIM + 1];
    for (int d = 0; d < DIM; d++) save[d] = P->acc[d][j];
    save[DIM] = P->drho[j];
    double f[DIM] = {0.0}, di = 0.0, ni = 0.0, ei = 0.0;
    double *count = calloc(j + 1 + FORCES_CHUNK, sizeof(double)); /* the range's neighbour counts */
    double *diff = calloc(j + 1 + FORCES_CHUNK, sizeof(double));  /* and diffusion sums */
    if (!count || !diff) {
        free(count);
        free(diff);
        for (int d = 0; d < DIM; d++) a[d] = NAN;
        *drho = NAN;
        return;
    }
#if DIM == 3 /* a list of the one candidate j (its masked lanes read j too) */
    uint32_t one[FORCES_CHUNK];
    for (int k = 0; k < FORCES_CHUNK; k++) one[k] = (uint32_t)j;
    const uint32_t pair[2] = {0, 1}, *idx = one;
#else
    const uint32_t pair[2] = {(uint32_t)j, (uint32_t)j + 1}, *idx = NULL;
#endif
    /* the density pass first: it stores the kernel factor the momentum pass reads */
    _Alignas(64) double fk[FORCES_CHUNK] = {0};
    const double delta_h = S->params.diffusion * X.K.h;
    if (delta_h > 0.0 && diffuses(&X, P, i)) {
        continuity_range(&X, P, i, idx, pair, 1, &di, &ni, &ei, count, fk, diff, diffusion_hydrostatic(&X, P, i),
                         X.wendland, 1, 0);
        *drho = P->rho[i] * di + diffusion_rate(delta_h, &S->media[P->medium[i]], ei);
    } else {
        continuity_range(&X, P, i, idx, pair, 1, &di, &ni, &ei, count, fk, NULL, 0.0, X.wendland, 0, 0);
        *drho = P->rho[i] * di;
    }
    momentum_range(&X, P, i, idx, pair, 1, f, fk, NULL, X.wendland, MOMENTUM_EXPLICIT_VISCOSITY, X.stress, 0, 0);
    for (int d = 0; d < DIM; d++) {
        a[d] = f[d] * P->inv_m[i];
        P->acc[d][j] = save[d];
    }
    P->drho[j] = save[DIM];
    free(count);
    free(diff);
}

/* The partial pressure smoothing of SPHERA (numerics.pressure_smoothing = theta_P > 0; Di Monaco
 * et al. 2011), after the equation of state: every non-wall particle's pressure relaxes toward
 * the kernel mean of its non-wall neighbours' pressures, hydrostatically extrapolated to it,
 *   p_i += theta_P c_i dt / h * sum_j B_ij W_ij V_j / sum_j W_ij V_j,
 * and its density follows (rho_i += dp_i / c_i^2), so the next density step starts from the
 * smoothed state. Masses are untouched. A damping of the acoustic noise of weakly compressible
 * SPH (like delta-SPH's density diffusion); an option, off by default. */
static void smooth_region(void *arg, int tid, int nth)
{
    struct pass_region *R = arg;
    struct particles *P = R->S->P;
    const struct medium *M = R->S->media;
    const double *sum = R->sum, *weight = R->weight;
    bands_in_team(R->S, smooth_band, R->X, R->bands, 0);
    size_t b, e;
    team_share(R->n, tid, nth, &b, &e);
    for (size_t i = b; i < e; i++) {
        if (P->state[i] > MIXSPH_STATE_FIXED || !(weight[i] > 0.0)) continue;
        const double c = M[P->medium[i]].c;
        const double dp = R->theta_dt_over_h * c * sum[i] / weight[i];
        P->p[i] += dp;
        P->rho[i] += dp / (c * c);
        P->inv_rho[i] = 1.0 / P->rho[i];
        P->vol[i] = P->m[i] * P->inv_rho[i];
    }
}

int forces_smooth_pressure(struct forces *F, const struct pair_system *S, double theta_dt_over_h)
{
    struct pair_ctx X;
    pair_ctx_init(S, &X);
    const size_t n = active_count(S);
    if (scratch_reserve(F, n) != 0 || pair_list_attach(F, S, n, &X) != 0) return -1;
    memset(F->smooth_sum, 0, n * sizeof(double));
    memset(F->smooth_weight, 0, n * sizeof(double));
    X.sum = F->smooth_sum;
    X.weight = F->smooth_weight;
    struct pass_region R;
    pass_region_init(&R, S, &X, smooth_band, n);
    R.theta_dt_over_h = theta_dt_over_h;
    R.sum = F->smooth_sum;
    R.weight = F->smooth_weight;
    team_run(S->n_threads, smooth_region, &R);
    return 0;
}
