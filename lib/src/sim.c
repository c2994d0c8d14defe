/* sim.c - the simulation object: creation from a case (particles on the lattice, hydrostatic
 * initial state, walls, cell grid), stepping, outputs. Public API of mixsph.h. */
#include "sim.h"

#include "bed_friction.h"
#include "body_sites.h"
#include "budget.h"
#include "law_registry.h"
#include "state.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/stat.h>
#if defined(_WIN32)
#include <direct.h> /* the FMU's Windows binary (fmu/): its C runtime's mkdir takes no mode */
#endif

#include "clock.h"
#include "eos.h"
#include "geometry.h"
#include "integrate.h"
#include "monitors.h"
#include "output.h"
#include "particle_fields.h"
#include "status.h"

static int make_dir(const char *path)
{
#if defined(_WIN32)
    return _mkdir(path);
#else
    return mkdir(path, 0777);
#endif
}

/* A lattice site of a body, for the hydrostatic initialisation. */
struct site {
    long i, j, k;    /* lattice indices: x = (i + 1/2) dx, y = (j + 1/2) dx (3D; 0 in 2D), z = z_offset + (k + 1/2) dx */
    int medium;
    size_t body;     /* the body it belongs to */
};

_Static_assert(WALLS_MAX <= BED_FRICTION_SIDE && CASE_MAX_MEDIA <= BED_FRICTION_SIDE,
               "the bed friction's table holds every wall and every medium");

/* Whether some grain of the case takes a wall's Coulomb friction (bed_friction.h): a no-slip wall
 * whose friction on a medium is not "none" and whose law bounds the shear of every no-slip wall
 * (LAW_WALL_FRICTION) or takes it where the wall gives its angle (LAW_WALL_FRICTION_GIVEN). */
static int bed_friction_on(const struct case_def *c)
{
    for (size_t w = 0; w < c->n_walls; w++)
        for (size_t k = 0; k < c->n_media && c->walls[w].slip == WALL_NO_SLIP; k++) {
            const double mu = bed_friction_coefficient(c->walls[w].friction_of_medium_deg[k]);
            const unsigned features = law_get(c->media[k].law)->features;
            if ((mu == BED_FRICTION_OWN && (features & LAW_WALL_FRICTION)) ||
                (mu >= 0.0 && (features & (LAW_WALL_FRICTION | LAW_WALL_FRICTION_GIVEN))))
                return 1;
        }
    return 0;
}

/* The friction coefficient of each (wall, medium) pair (bed_friction.h); 0 where either is none. */
static void bed_friction_table_fill(const struct case_def *c, struct bed_friction_table *T)
{
    for (size_t q = 0; q < BED_FRICTION_SIDE * BED_FRICTION_SIDE; q++) T->mu[q] = 0.0;
    for (size_t w = 0; w < c->n_walls; w++)
        for (size_t k = 0; k < c->n_media; k++)
            T->mu[w * BED_FRICTION_SIDE + k] = bed_friction_coefficient(c->walls[w].friction_of_medium_deg[k]);
}

/* Whether some wall gives two media different friction coefficients: then the momentum pass reads
 * the (wall, medium) table, else each wall particle's one coefficient (particles.h wall_friction),
 * which keeps its pair loop free of table lookups. */
static int bed_friction_per_medium(const struct case_def *c)
{
    for (size_t w = 0; w < c->n_walls; w++)
        for (size_t k = 1; k < c->n_media; k++)
            if (bed_friction_coefficient(c->walls[w].friction_of_medium_deg[k]) !=
                bed_friction_coefficient(c->walls[w].friction_of_medium_deg[0]))
                return 1;
    return 0;
}

static int site_cmp(const void *a, const void *b)
{
    const struct site *p = a, *q = b;
    if (p->i != q->i) return p->i < q->i ? -1 : 1;
    if (p->j != q->j) return p->j < q->j ? -1 : 1;
    if (p->k != q->k) return p->k > q->k ? -1 : 1; /* top first */
    return 0;
}

/* The position of a lattice site. */
static void site_position(const struct site *st, double dx, double z_off, double pos[DIM])
{
    pos[0] = (st->i + 0.5) * dx;
#if DIM == 3
    pos[1] = (st->j + 0.5) * dx;
#endif
    pos[DIM_UP] = z_off + (st->k + 0.5) * dx;
}

/* Is pos too close to a wall, or behind one, to hold a particle? */
static int site_blocked(const mixsph_sim *s, const double pos[DIM])
{
    for (size_t w = 0; w < s->cfg.n_walls; w++) {
        int at_end = 0;
        const double d = walls_distance(&s->phys.walls, w, pos, &at_end);
        if (walls_site_blocked(d, at_end, s->phys.dx)) return 1;
    }
    return 0;
}

/* Append a site to the growing array. */
static int push_site(struct site **sites, size_t *n, size_t *cap, struct site st)
{
    if (*n == *cap) {
        struct site *q = realloc(*sites, 2 * *cap * sizeof *q);
        if (!q) return -1;
        *sites = q;
        *cap *= 2;
    }
    (*sites)[(*n)++] = st;
    return 0;
}

#if DIM == 2 /* bodies are polygons of the x-z plane, placed on the 2D lattice */
/* Every body's free sites on the global lattice (a site belongs to the first body listing it). */
static mixsph_status collect_sites(mixsph_sim *s, double z_off, struct site **sites, size_t *n, size_t *cap)
{
    const double dx = s->phys.dx;
    double bx0 = INFINITY, bx1 = -INFINITY, bz0 = INFINITY, bz1 = -INFINITY;
    for (size_t b = 0; b < s->cfg.n_bodies; b++) {
        const struct polyline *pg = &s->cfg.bodies[b].polygon;
        for (size_t k = 0; k < pg->n; k++) {
            bx0 = fmin(bx0, pg->x[k]);
            bx1 = fmax(bx1, pg->x[k]);
            bz0 = fmin(bz0, pg->z[k]);
            bz1 = fmax(bz1, pg->z[k]);
        }
    }
    const long i0 = (long)floor(bx0 / dx) - 1, i1 = (long)ceil(bx1 / dx) + 1;
    const long k0 = (long)floor((bz0 - z_off) / dx) - 1, k1 = (long)ceil((bz1 - z_off) / dx) + 1;
    for (long k = k0; k <= k1; k++) {
        if (sim_interrupted(s))
            return SIM_FAIL(s, MIXSPH_ERR_INTERRUPTED, "%s: interrupted while filling the bodies", s->cfg.origin);
        for (long i = i0; i <= i1; i++) {
            const double pos[DIM] = {(i + 0.5) * dx, z_off + (k + 0.5) * dx};
            const double x = pos[0], z = pos[DIM_UP];
            int medium = -1;
            size_t body = 0;
            for (size_t b = 0; b < s->cfg.n_bodies && medium < 0; b++) {
                const struct body *bd = &s->cfg.bodies[b];
                if (z >= bd->z_min && z <= bd->z_max && geom_inside_polygon(&bd->polygon, x, z)) {
                    medium = bd->medium;
                    body = b;
                }
            }
            if (medium < 0 || site_blocked(s, pos)) continue;
            if (push_site(sites, n, cap, (struct site){i, 0, k, medium, body}) != 0)
                return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory");
        }
    }
    return MIXSPH_OK;
}
#else
/* by the body, then the lattice place: equal places together, the first body's first */
static int site_body_cmp(const void *a, const void *b)
{
    const int c = site_cmp(a, b);
    if (c != 0) return c;
    const struct site *p = a, *q = b;
    return p->body < q->body ? -1 : p->body > q->body;
}

/* Every body's free sites on the global lattice (io/body_sites.h; a site belongs to the first
 * body listing it). */
static mixsph_status collect_sites(mixsph_sim *s, double z_off, struct site **sites, size_t *n, size_t *cap)
{
    const double dx = s->phys.dx;
    const struct lattice L = {.dx = dx, .origin = {0.0, 0.0, z_off},
                              .max_points = (size_t)fmin(4.0 * s->cfg.max_particles + 1024.0, 1e15)};
    for (size_t b = 0; b < s->cfg.n_bodies; b++) {
        if (sim_interrupted(s))
            return SIM_FAIL(s, MIXSPH_ERR_INTERRUPTED, "%s: interrupted while filling the bodies", s->cfg.origin);
        struct point_set ps;
        memset(&ps, 0, sizeof ps);
        const mixsph_status st = body_sites(&s->cfg, b, &L, &ps, s->err, sizeof s->err);
        if (st != MIXSPH_OK) {
            point_set_free(&ps);
            return st;
        }
        for (size_t q = 0; q < ps.n; q++) {
            const struct site site = {lround(ps.pos[q][0] / dx - 0.5), lround(ps.pos[q][1] / dx - 0.5),
                                      lround((ps.pos[q][2] - z_off) / dx - 0.5), s->cfg.bodies[b].medium, b};
            if (push_site(sites, n, cap, site) != 0) {
                point_set_free(&ps);
                return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory");
            }
        }
        point_set_free(&ps);
    }
    qsort(*sites, *n, sizeof **sites, site_body_cmp);
    size_t kept = 0;
    for (size_t q = 0; q < *n; q++) {
        if (kept > 0 && site_cmp(&(*sites)[kept - 1], &(*sites)[q]) == 0) continue; /* a later body's copy */
        double pos[DIM];
        site_position(&(*sites)[q], dx, z_off, pos);
        if (site_blocked(s, pos)) continue;
        (*sites)[kept++] = (*sites)[q];
    }
    *n = kept;
    return MIXSPH_OK;
}
#endif

/* Fill every body on the global lattice, then give each particle the hydrostatic pressure of the
 * lattice column above it: p = sum over the sites above of rho0 g dx, plus half its own; rho from
 * the EOS; m = rho dx^DIM. */
static mixsph_status fill_bodies(mixsph_sim *s)
{
    const double dx = s->phys.dx, z_off = geom_lattice_z_offset(s->cfg.lattice_z0, dx);
    size_t n = 0, cap = 1024;
    struct site *sites = malloc(cap * sizeof *sites);
    if (!sites) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory");
    const mixsph_status st = collect_sites(s, z_off, &sites, &n, &cap);
    if (st != MIXSPH_OK) {
        free(sites);
        return st;
    }
    if (n == 0) {
        free(sites);
        return SIM_FAIL(s, MIXSPH_ERR_CASE, "%s: bodies: no particle fits in the bodies at dx = %g", s->cfg.origin, dx);
    }
    size_t per_body[CASE_MAX_BODIES] = {0}; /* particles each body got */
    for (size_t q = 0; q < n; q++) per_body[sites[q].body]++;
    /* a body that got no particle lies behind the walls, or within the bodies listed before it */
    for (size_t b = 0; b < s->cfg.n_bodies; b++) {
        if (per_body[b] > 0) continue;
        free(sites);
        return SIM_FAIL(s, MIXSPH_ERR_CASE,
                        "%s: bodies.%s: no particle of it lies on the fluid side of the walls (at least dx/2 from them) "
                        "outside the bodies listed before it, at dx = %g m", s->cfg.origin, s->cfg.bodies[b].name, dx);
    }
    if ((double)n > s->cfg.max_particles) { /* the budget's estimate was below it (budget.c) */
        free(sites);
        return SIM_FAIL(s, MIXSPH_ERR_CASE, "%s: numerics.dx: %g m gives %zu particles, over the limit of %g "
                        "(numerics.max_particles)", s->cfg.origin, dx, n, s->cfg.max_particles);
    }
    qsort(sites, n, sizeof *sites, site_cmp);
    s->phys.P.features = s->cfg.viscosity_implicit ? PARTICLE_FEATURE_IMPLICIT_VISCOUS : 0u;
    for (size_t k = 0; k < s->cfg.n_media; k++)
        if (law_get(s->cfg.media[k].law)->features & LAW_HAS_STRESS) s->phys.P.features |= PARTICLE_FEATURE_STRESS;
    if (bed_friction_on(&s->cfg)) s->phys.P.features |= PARTICLE_FEATURE_BED_FRICTION;
    for (size_t w = 0; w < s->cfg.n_walls; w++) /* a free-slip wall mirrors about its normal (walls.h) */
        if (s->cfg.walls[w].slip == WALL_FREE_SLIP) s->phys.P.features |= PARTICLE_FEATURE_WALL_NORMAL;
    if (s->phys.P.features & PARTICLE_FEATURE_STRESS) s->phys.P.features |= PARTICLE_FEATURE_WALL_NORMAL;
    for (size_t w = 0; w < s->cfg.n_walls && DIM == 3; w++) /* images across mirror side walls (mirror_sides.h) */
        if (s->cfg.walls[w].side_walls == WALL_SIDES_MIRROR) s->phys.P.features |= PARTICLE_FEATURE_MIRROR_SIDES;
    if (particles_alloc(&s->phys.P, n + n / 2 + 1024) != 0) {
        free(sites);
        return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory for %zu particles", n);
    }
    double above = 0.0; /* pressure of the column above the current site [Pa] */
    for (size_t q = 0; q < n; q++) {
        if (q == 0 || sites[q].i != sites[q - 1].i || sites[q].j != sites[q - 1].j) above = 0.0;
        const struct medium *m = &s->cfg.media[sites[q].medium];
        const double p = above + 0.5 * m->rho0 * s->cfg.g * dx;
        above += m->rho0 * s->cfg.g * dx;
        double (*const initial_pressure)(const struct medium *, double) = law_get(m->law)->initial_pressure;
        const double rho = eos_density(initial_pressure ? initial_pressure(m, p) : p, m->rho0, m->c);
        double pos[DIM];
        site_position(&sites[q], dx, z_off, pos);
        double mass = rho; /* rho dx^DIM, multiplied in that order */
        for (int d = 0; d < DIM; d++) mass *= dx;
        particles_push(&s->phys.P, pos, rho, mass, (uint8_t)sites[q].medium, MIXSPH_STATE_MOBILE);
        s->phys.P.mu[s->phys.P.n - 1] = m->mu;
    }
    s->phys.n_fluid = n;
    free(sites);
    return MIXSPH_OK;
}

/* The domain: given in the case, or the bounding box of all geometry (moving walls swept over
 * the run) with room for the wall layers, and half the height again above for splashes. Its
 * bounds along axis d are domain[2 d] and domain[2 d + 1] (sim_object.h). */
static void set_domain(mixsph_sim *s)
{
    const struct particles *P = &s->phys.P;
    double *dom = s->phys.domain;
    if (s->cfg.has_domain) {
        /* the case's domain bounds the fluids; the wall layers behind the walls may reach past
         * it at coarse dx (layers x dx), so it grows to hold every wall particle */
        memcpy(dom, s->cfg.domain, sizeof s->phys.domain);
        for (size_t i = s->phys.n_fluid; i < P->n; i++)
            for (int d = 0; d < DIM; d++) {
                dom[2 * d] = fmin(dom[2 * d], P->pos[d][i] - s->phys.dx);
                dom[2 * d + 1] = fmax(dom[2 * d + 1], P->pos[d][i] + s->phys.dx);
            }
        return;
    }
    double lo[DIM], hi[DIM];
    for (int d = 0; d < DIM; d++) {
        lo[d] = INFINITY;
        hi[d] = -INFINITY;
    }
    for (size_t i = 0; i < P->n; i++)
        for (int d = 0; d < DIM; d++) {
            lo[d] = fmin(lo[d], P->pos[d][i]);
            hi[d] = fmax(hi[d], P->pos[d][i]);
        }
    /* sweep of moving walls */
    for (size_t w = 0; w < s->cfg.n_walls; w++) {
        const int mo = s->cfg.walls[w].motion;
        if (mo < 0) continue;
        double o[DIM] = {0}, o_min[DIM] = {0}, o_max[DIM] = {0};
        const int nsub = 2000;
        const double dt = s->cfg.t_end / nsub;
        for (int k = 0; k < nsub; k++) {
            double v[DIM];
            motion_velocity(&s->cfg.motions[mo], (k + 0.5) * dt, v);
            for (int d = 0; d < DIM; d++) {
                o[d] += v[d] * dt;
                o_min[d] = fmin(o_min[d], o[d]);
                o_max[d] = fmax(o_max[d], o[d]);
            }
        }
        for (int d = 0; d < DIM; d++) {
            lo[d] += fmin(0.0, o_min[d]);
            hi[d] += fmax(0.0, o_max[d]);
        }
    }
    const double pad = 2.0 * s->phys.dx;
    for (int d = 0; d < DIM; d++) {
        dom[2 * d] = lo[d] - pad;
        dom[2 * d + 1] = (d == DIM_UP ? hi[d] + 0.5 * (hi[d] - lo[d]) : hi[d]) + pad; /* room for splashes */
    }
}

/* The states of the material laws the media use, and the velocity gradient when one asks for it. */
static mixsph_status create_laws(mixsph_sim *s)
{
    const struct law_setup setup = {.media = s->cfg.media, .n_media = s->cfg.n_media, .cap = s->phys.P.n,
                                     .x_min = s->phys.domain[0], .x_max = s->phys.domain[1], .dx = s->phys.dx, .h = s->phys.h,
                                     .g = s->cfg.g, .p_background = s->cfg.p_background,
                                     .fixed_bed_speed = s->cfg.fixed_bed_speed};
    for (size_t k = 0; k < s->cfg.n_media; k++) {
        const int id = s->cfg.media[k].law;
        const struct material_law *law = law_get(id);
        s->phys.law_features |= law->features;
        if (law->create && !s->phys.law_state[id] && !(s->phys.law_state[id] = law->create(&setup)))
            return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory (the state of the material law of medium %s)",
                            s->cfg.media[k].name);
    }
    if (s->phys.P.features & PARTICLE_FEATURE_BED_FRICTION) /* the walls' friction on grains (bed_friction.h) */
        for (size_t i = 0; i < s->phys.P.n; i++) {
            struct particles *P = &s->phys.P;
            const int wall = P->state[i] == MIXSPH_STATE_WALL;
            const struct wall *w = wall ? &s->cfg.walls[particles_wall_index(P, i)] : NULL;
            P->wall_rough[i] = wall && w->slip == WALL_NO_SLIP;
            P->wall_friction[i] = wall ? bed_friction_coefficient(w->friction_of_medium_deg[0]) : 0.0;
        }
    if ((s->phys.law_features & LAW_USES_GRADIENT) && velocity_gradient_alloc(&s->work.grad, s->phys.P.n) != 0)
        return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory (velocity gradient)");
    return MIXSPH_OK;
}

/* The time schemes' parameters from the case and the laws' features (after create_laws): the
 * values derived from the case, then each `numerics` key its reader struct holds, as its row of
 * core/numerics_keys.def says. */
#define COPY_NUMERICS_KEY(type, member, read_by, as, ...)                         \
    NUMERICS_IF_READ_BY(read_by, SCHEME, s->scheme.as = c->member;)                \
    NUMERICS_IF_READ_BY(read_by, PAIR, s->scheme.pair.as = c->member;)             \
    NUMERICS_IF_READ_BY(read_by, VISCOUS, s->scheme.viscous.as = c->member;)
static void set_scheme_params(mixsph_sim *s)
{
    const struct case_def *c = &s->cfg;
    s->scheme = (struct scheme_params){
        .media = c->media,
        .n_media = c->n_media,
        .implicit = c->viscosity_implicit,
        .excluded_limit = (long)floor(c->excluded_max * (double)s->phys.n_fluid),
        .pair = {.K = s->phys.K,
                 .eta2 = c->eta2_over_h2 * s->phys.h * s->phys.h,
                 .g = c->g,
                 .stress = (s->phys.law_features & LAW_HAS_STRESS) != 0,
                 .bed_friction = (s->phys.P.features & PARTICLE_FEATURE_BED_FRICTION) != 0},
    };
#define NUMERICS_KEY COPY_NUMERICS_KEY
#include "numerics_keys.def"
#undef NUMERICS_KEY
    if (s->scheme.pair.bed_friction) {
        bed_friction_table_fill(c, &s->scheme.pair.bed_mu);
        s->scheme.pair.bed_per_medium = bed_friction_per_medium(c);
    }
    for (size_t k = 0; k < c->n_media; k++) /* a medium's finish may set it (not its law's features) */
        if (c->media[k].features & LAW_GRAINS_IN_WATER) s->scheme.pair.grains_in_water = 1;
}

/* The failure of a particle i outside the domain: "a particle at (x, z) lies outside it". */
static mixsph_status sim_fail_outside(mixsph_sim *s, size_t i)
{
    char at[3 * 32] = "";
    for (int d = 0; d < DIM; d++)
        snprintf(at + strlen(at), sizeof at - strlen(at), "%s%g", d ? ", " : "", s->phys.P.pos[d][i]);
    return SIM_FAIL(s, MIXSPH_ERR_CASE, "%s: domain: a particle at (%s) lies outside it", s->cfg.origin, at);
}

/* The planes of the mirror side walls (the extruded polylines whose side_walls is "mirror", all
 * with the same y range), the images' reach, and a domain that holds the images: with the
 * feature PARTICLE_FEATURE_MIRROR_SIDES only. */
static mixsph_status mirror_sides_init(mixsph_sim *s)
{
    struct mirror_sides *M = &s->work.mirror;
    if (!(s->phys.P.features & PARTICLE_FEATURE_MIRROR_SIDES)) return MIXSPH_OK;
    M->on = 1;
    M->y_lo = NAN;
    for (size_t w = 0; w < s->cfg.n_walls; w++) {
        const struct wall *wl = &s->cfg.walls[w];
        if (wl->side_walls != WALL_SIDES_MIRROR) continue;
        if (!isnan(M->y_lo) && (wl->y_min != M->y_lo || wl->y_max != M->y_hi))
            return SIM_FAIL(s, MIXSPH_ERR_CASE, "%s: walls.%s.side_walls: \"mirror\" on walls of different y ranges "
                            "([%g, %g] and [%g, %g]): the mirror planes are one pair", s->cfg.origin, wl->name, M->y_lo, M->y_hi,
                            wl->y_min, wl->y_max);
        M->y_lo = wl->y_min;
        M->y_hi = wl->y_max;
    }
    const double rc = 2.0 * s->phys.h + s->work.NB.skin; /* the lists' reach */
    M->reach = rc - 0.5 * s->work.NB.skin;              /* 2h + skin/2 (mirror_sides.h) */
    if (!(M->y_hi - M->y_lo >= rc))
        return SIM_FAIL(s, MIXSPH_ERR_CASE, "%s: side_walls \"mirror\": the planes y = %g and y = %g m are closer than "
                        "2h + skin = %g m (no image of an image is made)", s->cfg.origin, M->y_lo, M->y_hi, rc);
    const long trimmed = mirror_sides_trim(M, &s->phys.P);
    if (trimmed < 0) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory for the mirror images");
    s->phys.n_wall -= (size_t)trimmed;
    s->phys.domain[2] = fmin(s->phys.domain[2], M->y_lo - M->reach - s->phys.dx);
    s->phys.domain[3] = fmax(s->phys.domain[3], M->y_hi + M->reach + s->phys.dx);
    return MIXSPH_OK;
}

static mixsph_status sim_init(mixsph_sim *s)
{
    mixsph_status st;
    s->phys.dx = s->cfg.dx;
    s->phys.h = s->cfg.h_over_dx * s->phys.dx;
    s->phys.K = kernel_make_type(s->phys.h, s->cfg.kernel);
    s->phys.c_max = law_max_wave_speed(s->cfg.media, s->cfg.n_media);
    /* a wall particle with no fluid around it takes the first medium's density */
    walls_init(&s->phys.walls, s->cfg.walls, s->cfg.n_walls, s->cfg.motions, s->cfg.wall_layers, s->cfg.wall_placement,
               s->cfg.lattice_z0, s->cfg.g, s->cfg.media[0].rho0);
    if ((st = fill_bodies(s)) != MIXSPH_OK) return st;
    const long n_wall = walls_generate(&s->phys.walls, s->phys.dx, &s->interrupt, &s->phys.P);
    if (n_wall == WALLS_INTERRUPTED)
        return SIM_FAIL(s, MIXSPH_ERR_INTERRUPTED, "%s: interrupted while placing the wall particles", s->cfg.origin);
    if (n_wall == WALLS_NOT_IN_3D)
        return SIM_FAIL(s, MIXSPH_ERR_CASE, "%s: numerics.wall_placement: 'aligned' is 2D only (a 3D case's wall "
                        "particles are lattice sites)", s->cfg.origin);
    if (n_wall < 0) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory for wall particles");
    s->phys.n_wall = (size_t)n_wall;
    if (s->phys.P.features & PARTICLE_FEATURE_WALL_NORMAL) /* what the free-slip walls mirror about (walls.h) */
        walls_set_normals(&s->phys.walls, &s->phys.P);
    set_domain(s);
    if ((st = create_laws(s)) != MIXSPH_OK) return st;
    set_scheme_params(s);
    if (!(s->work.forces = forces_create())) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory");
    const double *dom = s->cfg.has_domain ? s->cfg.domain : s->phys.domain;
    for (size_t i = 0; i < s->phys.n_fluid; i++) { /* fluids come first until the first sort */
        int inside = 1;
        for (int d = 0; d < DIM; d++)
            inside &= s->phys.P.pos[d][i] >= dom[2 * d] && s->phys.P.pos[d][i] < dom[2 * d + 1];
        if (!inside) return sim_fail_outside(s, i);
    }
    s->work.NB.skin = NEIGHBOURS_SKIN_OVER_H * s->phys.h;
    if ((st = mirror_sides_init(s)) != MIXSPH_OK) return st; /* before the grid: it widens the domain */
    double grid_lo[DIM], grid_hi[DIM];
    for (int d = 0; d < DIM; d++) {
        grid_lo[d] = s->phys.domain[2 * d];
        grid_hi[d] = s->phys.domain[2 * d + 1];
    }
    if (cells_init_columns(&s->work.C, grid_lo, grid_hi, 2.0 * s->phys.h + s->work.NB.skin, SIM_CELL_COLUMNS) != 0)
        return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "%s: cannot build a cell grid for the domain [%g, %g] x [%g, %g]",
                        s->cfg.origin, s->phys.domain[0], s->phys.domain[1], s->phys.domain[2], s->phys.domain[3]);
    if (s->work.mirror.on && mirror_sides_make(&s->work.mirror, &s->phys.P) != 0)
        return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory for the mirror images");
    if (cells_build(&s->work.C, &s->phys.P) < 0) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory in the cell list");
    s->phys.n_lost = 0;
    for (size_t i = 0; i < s->phys.P.n; i++)
        if (s->phys.P.state[i] == MIXSPH_STATE_LOST) return sim_fail_outside(s, i);
    if (sim_interrupted(s)) return SIM_FAIL(s, MIXSPH_ERR_INTERRUPTED, "%s: interrupted after sorting the particles", s->cfg.origin);
    if (neighbours_build(&s->work.NB, &s->work.C, &s->phys.P, s->work.C.start[s->work.C.ncell], 2.0 * s->phys.h + s->work.NB.skin, SIM_THREADS(s)) != 0)
        return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory in the neighbour lists");
    if (sim_interrupted(s)) return SIM_FAIL(s, MIXSPH_ERR_INTERRUPTED, "%s: interrupted after the neighbour lists", s->cfg.origin);
    if ((st = integrate_build_gather_lists(s)) != MIXSPH_OK) return st;
    if ((st = integrate_initial_rates(s)) != MIXSPH_OK) return st;
    if ((st = monitors_init(s)) != MIXSPH_OK) return st;
    s->out.next_sample = 0.0;
    s->out.next_snapshot = 0.0;
    return MIXSPH_OK;
}

static char *dup_string(const char *t)
{
    const size_t n = strlen(t) + 1;
    char *d = malloc(n);
    if (d) memcpy(d, t, n);
    return d;
}

/* Keep a copy of the case text and the overrides (state save/restore and metadata). */
static mixsph_status sim_keep_source(mixsph_sim *s, const char *text, const char *origin, const mixsph_override *ov,
                                     size_t n_ov)
{
    s->case_text = dup_string(text);
    s->case_origin = dup_string(origin ? origin : "");
    s->ov_key = calloc(n_ov + 1, sizeof *s->ov_key);
    s->ov_value = calloc(n_ov + 1, sizeof *s->ov_value);
    if (!s->case_text || !s->case_origin || !s->ov_key || !s->ov_value)
        return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory");
    for (size_t k = 0; k < n_ov; k++) {
        if (!(s->ov_key[k] = dup_string(ov[k].key ? ov[k].key : ""))) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory");
        s->ov_value[k] = ov[k].value;
        s->n_ov = k + 1;
    }
    return MIXSPH_OK;
}

mixsph_status mixsph_sim_create_from_text(const char *json_text, const char *origin, const mixsph_override *ov,
                                          size_t n_ov, mixsph_sim **out, char *err, size_t err_len)
{
    return sim_create_from_text(json_text, origin, ov, n_ov, NULL, out, err, err_len);
}

void mixsph_sim_set_interrupt(mixsph_sim *s, const mixsph_interrupt *interrupt)
{
    if (!s) return;
    s->interrupt = interrupt ? *interrupt : (mixsph_interrupt){NULL, NULL};
}

mixsph_status sim_create_from_text(const char *json_text, const char *origin, const mixsph_override *ov, size_t n_ov,
                                   const mixsph_interrupt *interrupt, mixsph_sim **out, char *err, size_t err_len)
{
    if (!out) return status_set(err, err_len, MIXSPH_ERR_ARG, "mixsph_sim_create: out is NULL");
    *out = NULL;
    if (n_ov > 0 && !ov) return status_set(err, err_len, MIXSPH_ERR_ARG, "mixsph_sim_create: overrides are NULL");
    mixsph_sim *s = calloc(1, sizeof *s);
    if (!s) return status_set(err, err_len, MIXSPH_ERR_NOMEM, "out of memory");
    mixsph_sim_set_interrupt(s, interrupt);
    mixsph_status st = case_parse(json_text, origin, ov, n_ov, &s->cfg, s->err, sizeof s->err);
    if (st == MIXSPH_OK) st = budget_check(&s->cfg, s->err, sizeof s->err); /* before anything is allocated */
    if (st == MIXSPH_OK) st = sim_keep_source(s, json_text, origin, ov, n_ov);
    if (st == MIXSPH_OK) st = sim_init(s);
    if (st != MIXSPH_OK) {
        status_set(err, err_len, st, "%s", s->err);
        mixsph_sim_destroy(s);
        return st;
    }
    *out = s;
    return MIXSPH_OK;
}

mixsph_status mixsph_sim_create(const char *case_path, const mixsph_override *ov, size_t n_ov, mixsph_sim **out,
                                char *err, size_t err_len)
{
    return mixsph_sim_create_interruptible(case_path, ov, n_ov, NULL, out, err, err_len);
}

mixsph_status mixsph_sim_create_interruptible(const char *case_path, const mixsph_override *ov, size_t n_ov,
                                              const mixsph_interrupt *interrupt, mixsph_sim **out, char *err,
                                              size_t err_len)
{
    if (out) *out = NULL;
    if (!case_path) return status_set(err, err_len, MIXSPH_ERR_ARG, "mixsph_sim_create: no case file given");
    char *text = NULL;
    mixsph_status st = case_read_file(case_path, &text, err, err_len);
    if (st != MIXSPH_OK) return st;
    st = sim_create_from_text(text, case_path, ov, n_ov, interrupt, out, err, err_len);
    free(text);
    return st;
}

mixsph_status mixsph_sim_create_from_state(const void *buf, size_t len, mixsph_sim **out, char *err, size_t err_len)
{
    return sim_create_from_state(buf, len, NULL, out, err, err_len);
}

mixsph_status sim_create_from_state(const void *buf, size_t len, const mixsph_interrupt *interrupt, mixsph_sim **out,
                                    char *err, size_t err_len)
{
    if (!out) return status_set(err, err_len, MIXSPH_ERR_ARG, "create_from_state: out is NULL");
    *out = NULL;
    struct state_source src;
    mixsph_status st = state_read_source(buf, len, &src, err, err_len);
    mixsph_override *ov = NULL;
    if (st == MIXSPH_OK && !(ov = calloc(src.n_ov + 1, sizeof *ov))) st = status_set(err, err_len, MIXSPH_ERR_NOMEM, "out of memory");
    if (st == MIXSPH_OK) {
        for (size_t k = 0; k < src.n_ov; k++) ov[k] = (mixsph_override){src.keys[k], src.values[k]};
        st = sim_create_from_text(src.text, src.origin, ov, src.n_ov, interrupt, out, err, err_len);
    }
    free(ov);
    state_source_free(&src);
    if (st != MIXSPH_OK) return st;
    st = mixsph_sim_load_state(*out, buf, len);
    if (st != MIXSPH_OK) {
        status_set(err, err_len, st, "%s", (*out)->err);
        mixsph_sim_destroy(*out);
        *out = NULL;
    }
    return st;
}

mixsph_status mixsph_sim_create_from_checkpoint(const char *path, mixsph_sim **out, char *err, size_t err_len)
{
    return mixsph_sim_create_from_checkpoint_interruptible(path, NULL, out, err, err_len);
}

mixsph_status mixsph_sim_create_from_checkpoint_interruptible(const char *path, const mixsph_interrupt *interrupt,
                                                              mixsph_sim **out, char *err, size_t err_len)
{
    if (out) *out = NULL;
    if (!path || !out) return status_set(err, err_len, MIXSPH_ERR_ARG, "create_from_checkpoint: no file or no out");
    unsigned char *buf = NULL;
    size_t len = 0;
    double run_wall = NAN;
    mixsph_status st = output_read_checkpoint(path, &buf, &len, &run_wall, err, err_len);
    if (st == MIXSPH_OK) {
        char msg[900];
        st = sim_create_from_state(buf, len, interrupt, out, msg, sizeof msg);
        if (st != MIXSPH_OK) status_set(err, err_len, st, "checkpoint %s: %s", path, msg);
        else (*out)->out.run_wall_s = run_wall;
    }
    free(buf);
    return st;
}

void mixsph_sim_destroy(mixsph_sim *s)
{
    if (!s) return;
    if (s->out.monitor_csv) fclose(s->out.monitor_csv);
    output_close(s);
    for (int id = 0; id < LAW_COUNT; id++)
        if (s->phys.law_state[id]) law_get(id)->destroy(s->phys.law_state[id]);
    velocity_gradient_free(&s->work.grad);
    forces_free(s->work.forces);
    viscous_free(s->work.viscous);
    free(s->work.viscous_unknown);
    walls_mirror_free(s->work.wall_mirror);
    mirror_sides_free(&s->work.mirror);
    particles_free(&s->phys.P);
    cells_free(&s->work.C);
    neighbours_free(&s->work.NB);
    neighbours_gather_free(&s->work.G);
    free(s->work.near_wall);
    free(s->work.excluding);
    case_free(&s->cfg);
    for (size_t k = 0; k < s->n_ov; k++) free(s->ov_key[k]);
    free(s->ov_key);
    free(s->ov_value);
    free(s->case_text);
    free(s->case_origin);
    free(s);
}

mixsph_status mixsph_sim_set_threads(mixsph_sim *s, int n_threads)
{
    if (!s) return MIXSPH_ERR_ARG;
    if (n_threads < 0 || n_threads > 1024) return SIM_FAIL(s, MIXSPH_ERR_ARG, "threads: %d is not in 0..1024", n_threads);
    s->n_threads = n_threads;
    return MIXSPH_OK;
}

/* Output folder: created if missing; new files (resume = 0) or the files of the run a restored
 * state came from continued (resume = 1, output.c). */
static mixsph_status sim_output_dir(mixsph_sim *s, const char *dir, int resume)
{
    if (!s || !dir || !*dir) return s ? SIM_FAIL(s, MIXSPH_ERR_ARG, "output folder: empty name") : MIXSPH_ERR_ARG;
    if (strlen(dir) >= sizeof s->out.dir) return SIM_FAIL(s, MIXSPH_ERR_ARG, "output folder: name too long");
    /* create each missing component */
    char path[sizeof s->out.dir];
    strcpy(path, dir);
    for (char *p = path + 1; *p; p++) {
        if (*p != '/') continue;
        *p = '\0';
        if (make_dir(path) != 0 && errno != EEXIST)
            return SIM_FAIL(s, MIXSPH_ERR_IO, "output folder %s: cannot create %s: %s", dir, path, strerror(errno));
        *p = '/';
    }
    if (make_dir(path) != 0 && errno != EEXIST)
        return SIM_FAIL(s, MIXSPH_ERR_IO, "output folder %s: cannot create: %s", dir, strerror(errno));
    if (s->out.monitor_csv) {
        fclose(s->out.monitor_csv);
        s->out.monitor_csv = NULL;
    }
    output_close(s);
    strcpy(s->out.dir, dir);
    mixsph_status st = output_open(s, resume); /* first: it refuses the folder of another run */
    if (st == MIXSPH_OK) st = resume ? output_resume_monitors(s) : monitors_open(s);
    if (st != MIXSPH_OK) { /* no half-set output folder */
        if (s->out.monitor_csv) fclose(s->out.monitor_csv);
        s->out.monitor_csv = NULL;
        s->out.dir[0] = '\0';
    }
    return st;
}

mixsph_status mixsph_sim_set_output_dir(mixsph_sim *s, const char *dir) { return sim_output_dir(s, dir, 0); }

mixsph_status mixsph_sim_resume_output_dir(mixsph_sim *s, const char *dir) { return sim_output_dir(s, dir, 1); }

/* Outputs are due at whole multiples of their interval; an output is taken at the first step
 * that reaches one, within SIM_OUTPUT_SLACK (the steps' sum of rounding errors). */
#define SIM_OUTPUT_SLACK 1e-12

/* The first multiple of `interval` after time t (beyond the slack), counted from t itself: however
 * small the interval, one call reaches past t (an accumulated next += interval may not move at
 * all once interval is below the spacing of doubles at t). */
static double next_output_time(double t, double interval)
{
    const double k = floor((t + SIM_OUTPUT_SLACK) / interval) + 1.0;
    const double next = k * interval;
    return next > t + SIM_OUTPUT_SLACK ? next : nextafter(t + SIM_OUTPUT_SLACK, INFINITY);
}

/* Take the samples and snapshots that are due at the current time. */
static mixsph_status sim_outputs_due(mixsph_sim *s)
{
    mixsph_status st = monitors_profiles(s);
    if (st == MIXSPH_OK && s->phys.t >= s->out.next_sample - SIM_OUTPUT_SLACK) {
        st = monitors_sample(s);
        s->out.next_sample = next_output_time(s->phys.t, s->cfg.monitor_interval);
    }
    if (st == MIXSPH_OK && s->cfg.snapshot_interval > 0.0 && s->out.dir[0] &&
        s->phys.t >= s->out.next_snapshot - SIM_OUTPUT_SLACK) {
        st = output_snapshot(s); /* snap_NNNN.csv and run.h5 */
        s->out.next_snapshot = next_output_time(s->phys.t, s->cfg.snapshot_interval);
    }
    return st;
}

mixsph_status mixsph_sim_step(mixsph_sim *s)
{
    if (!s) return MIXSPH_ERR_ARG;
    const double t0 = clock_monotonic_s();
    mixsph_status st = MIXSPH_OK;
    if (s->phys.step == 0 && s->out.n_samples == 0) st = sim_outputs_due(s);
    if (st == MIXSPH_OK) st = integrate_step(s);
    if (st == MIXSPH_OK) st = sim_outputs_due(s);
    s->out.run_wall_s += clock_monotonic_s() - t0;
    return st;
}


double mixsph_sim_run_wall_time(const mixsph_sim *s) { return s ? s->out.run_wall_s : NAN; }

mixsph_status mixsph_sim_viscous_cost(const mixsph_sim *s, uint64_t *iterations, double *wall_s)
{
    if (!s || !iterations || !wall_s) return MIXSPH_ERR_ARG;
    *iterations = s->work.viscous_iterations;
    *wall_s = s->work.viscous_wall_s;
    return MIXSPH_OK;
}

mixsph_status mixsph_sim_advance_to(mixsph_sim *s, double t)
{
    if (!s) return MIXSPH_ERR_ARG;
    if (!isfinite(t)) return SIM_FAIL(s, MIXSPH_ERR_ARG, "advance_to: time %g is not finite", t);
    while (s->phys.t < t) {
        if (sim_interrupted(s))
            return SIM_FAIL(s, MIXSPH_ERR_INTERRUPTED, "interrupted at t = %.9g s, step %llu", s->phys.t,
                            (unsigned long long)s->phys.step);
        mixsph_status st = mixsph_sim_step(s);
        if (st != MIXSPH_OK) return st;
    }
    return MIXSPH_OK;
}

const char *mixsph_sim_last_error(const mixsph_sim *s) { return s ? s->err : "no simulation"; }
double mixsph_sim_time(const mixsph_sim *s) { return s->phys.t; }
double mixsph_sim_end_time(const mixsph_sim *s) { return s->cfg.t_end; }
double mixsph_sim_dt(const mixsph_sim *s) { return s->phys.dt; }
uint64_t mixsph_sim_steps(const mixsph_sim *s) { return s->phys.step; }
size_t mixsph_sim_particles(const mixsph_sim *s) { return s->phys.n_fluid; }
size_t mixsph_sim_wall_particles(const mixsph_sim *s) { return s->phys.n_wall; }
const char *mixsph_sim_name(const mixsph_sim *s) { return s->cfg.name; }
const char *mixsph_sim_case_text(const mixsph_sim *s) { return s ? s->case_text : NULL; }
const char *mixsph_sim_case_origin(const mixsph_sim *s) { return s ? s->case_origin : NULL; }

/* The moving wall named `wall`, or -1 with a message. */
static long sim_moving_wall(mixsph_sim *s, const char *wall)
{
    for (size_t w = 0; w < s->cfg.n_walls; w++) {
        if (strcmp(s->cfg.walls[w].name, wall) != 0) continue;
        if (s->cfg.walls[w].motion < 0) {
            SIM_FAIL(s, MIXSPH_ERR_ARG, "wall %s is fixed (it has no motion in the case), it cannot be driven", wall);
            return -1;
        }
        return (long)w;
    }
    SIM_FAIL(s, MIXSPH_ERR_ARG, "wall %s: no such wall in case %s", wall, s->cfg.origin);
    return -1;
}

mixsph_status mixsph_sim_set_wall_velocity(mixsph_sim *s, const char *wall, double vx, double vz)
{
    if (!s) return MIXSPH_ERR_ARG;
    if (!wall) return SIM_FAIL(s, MIXSPH_ERR_ARG, "set_wall_velocity: no wall name");
    if (!isfinite(vx) || !isfinite(vz))
        return SIM_FAIL(s, MIXSPH_ERR_ARG, "wall %s: external velocity (%g, %g) m/s is not finite", wall, vx, vz);
    const long w = sim_moving_wall(s, wall);
    if (w < 0) return MIXSPH_ERR_ARG;
    struct wall_state *ws = &s->phys.walls.state[w];
    const double a[DIM] = {0.0};
    ws->ext = 1;
    for (int d = 0; d < DIM; d++) ws->ext_v[d] = 0.0;
    ws->ext_v[0] = vx; /* a wall moves in the x-z plane of its polyline (walls.h) */
    ws->ext_v[DIM_UP] = vz;
    walls_change_velocity(&s->phys.walls, (size_t)w, ws->ext_v, a, &s->phys.P);
    return MIXSPH_OK;
}

mixsph_status mixsph_sim_release_wall_velocity(mixsph_sim *s, const char *wall)
{
    if (!s) return MIXSPH_ERR_ARG;
    if (!wall) return SIM_FAIL(s, MIXSPH_ERR_ARG, "release_wall_velocity: no wall name");
    const long w = sim_moving_wall(s, wall);
    if (w < 0) return MIXSPH_ERR_ARG;
    if (s->phys.walls.state[w].ext) {
        const struct motion *law = &s->cfg.motions[s->cfg.walls[w].motion];
        double v[DIM], a[DIM];
        motion_velocity(law, s->phys.t, v);
        motion_acceleration(law, s->phys.t, a);
        walls_change_velocity(&s->phys.walls, (size_t)w, v, a, &s->phys.P);
    }
    s->phys.walls.state[w].ext = 0;
    return MIXSPH_OK;
}
size_t mixsph_sim_output_count(const mixsph_sim *s) { return s->out.n; }

const char *mixsph_sim_output_name(const mixsph_sim *s, size_t k) { return k < s->out.n ? s->out.name[k] : NULL; }

double mixsph_sim_output_value(const mixsph_sim *s, size_t k) { return k < s->out.n ? monitors_value(s, k) : NAN; }

void mixsph_sim_output_extremes(const mixsph_sim *s, size_t k, double *max, double *t_max, double *min, double *t_min)
{
    const int ok = k < s->out.n;
    if (max) *max = ok ? s->out.max[k] : NAN;
    if (t_max) *t_max = ok ? s->out.tmax[k] : NAN;
    if (min) *min = ok ? s->out.min[k] : NAN;
    if (t_min) *t_min = ok ? s->out.tmin[k] : NAN;
}

long mixsph_sim_output_find(const mixsph_sim *s, const char *name)
{
    for (size_t k = 0; k < s->out.n; k++)
        if (name && strcmp(s->out.name[k], name) == 0) return (long)k;
    return -1;
}

mixsph_status mixsph_sim_particles_view(const mixsph_sim *s, mixsph_particles_view *v)
{
    if (!s || !v) return MIXSPH_ERR_ARG;
    const struct particles *P = &s->phys.P;
    v->n = P->n;
    v->n_fluid = s->phys.n_fluid;
    v->dim = DIM;
    for (int d = 0; d < 3; d++) {
        v->pos[d] = d < DIM ? P->pos[d] : NULL;
        v->vel[d] = d < DIM ? P->vel[d] : NULL;
    }
    v->rho = P->rho;
    v->p = P->p;
    v->mu = P->mu;
    v->medium = P->medium;
    v->state = P->state;
    v->id = P->id;
    return MIXSPH_OK;
}
