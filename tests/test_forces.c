/* test_forces.c - the pair loops of forces.c (eq. (3) of Manenti et al. 2018, docs/model.md
 * section 2): each pair term against its formula and sign, pair symmetry m_i a_ij = -m_j a_ji,
 * and conservation of momentum by the gather loop in a box of two fluids far from any wall,
 * without gravity, with random positions, velocities, densities, masses, pressures and
 * viscosities set through the internals. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "eos.h"
#include "mixsph.h"
#include "sim_passes.h"
#include "test_random.h"

/* Two fluids side by side (a cross-medium interface), no gravity, one wall 0.8 m below:
 * far beyond the support 2h = 0.026 m, so every interaction is fluid-fluid. The continuity
 * equation is checked here as (3) writes it, without density diffusion (tests/test_diffusion.c). */
static const char *const BOX_CASE =
    "{\n"
    "  \"name\": \"forces_box\",\n"
    "  \"gravity\": 0.0,\n"
    "  \"numerics\": { \"dx\": 0.01, \"h_over_dx\": 1.3, \"t_end\": 0.1, \"wall_layers\": 3, \"density_diffusion\": 0 },\n"
    "  \"media\": {\n"
    "    \"water\": { \"type\": \"fluid\", \"rho\": 1000.0, \"c\": 30.0, \"mu\": 1.0e-3, \"alpha_m\": 0.1 },\n"
    "    \"oil\": { \"type\": \"fluid\", \"rho\": 800.0, \"c\": 20.0, \"mu\": 0.05, \"alpha_m\": 0.3 }\n"
    "  },\n"
    "  \"bodies\": {\n"
    "    \"left\": { \"medium\": \"water\", \"polygon\": [[0.0, 0.0], [0.1, 0.0], [0.1, 0.2], [0.0, 0.2]] },\n"
    "    \"right\": { \"medium\": \"oil\", \"polygon\": [[0.1, 0.0], [0.2, 0.0], [0.2, 0.2], [0.1, 0.2]] }\n"
    "  },\n"
    "  \"walls\": { \"far\": { \"polyline\": [[-0.5, -0.8], [0.7, -0.8]], \"fluid_side\": \"left\" } }\n"
    "}\n";

static uint64_t rng_state;

static double uniform(double a, double b) { return test_random_uniform(&rng_state, a, b); }

/* The box with every fluid particle displaced by up to 0.3 dx and given random velocity,
 * density (hence pressure, through the EOS), mass and viscosity; the cell list rebuilt.
 * White box: the primary fields are written here, and integrate_pressure_and_derived derives the per-step ones
 * (p, V = m / rho and whatever else the pair loops cache); fields only particles_push sets
 * are written here too: inv_m = 1/m, and uvx, uvz (the velocity the viscous term sees: a fluid
 * particle's own velocity). */
static int setup(void **state)
{
    mixsph_sim *s = NULL;
    char err[512];
    if (mixsph_sim_create_from_text(BOX_CASE, "forces_box.json", NULL, 0, &s, err, sizeof err) != MIXSPH_OK) {
        print_error("%s\n", err);
        return -1;
    }
    rng_state = 2024;
    struct particles *P = &s->phys.P;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] != MIXSPH_STATE_MOBILE) continue;
        const struct medium *m = &s->cfg.media[P->medium[i]];
        P->pos[0][i] += uniform(-0.3, 0.3) * s->phys.dx;
        P->pos[DIM_UP][i] += uniform(-0.3, 0.3) * s->phys.dx;
        P->vel[0][i] = P->uv[0][i] = uniform(-1.0, 1.0);
        P->vel[DIM_UP][i] = P->uv[DIM_UP][i] = uniform(-1.0, 1.0);
        P->rho[i] = m->rho0 * (1.0 + uniform(-0.01, 0.01));
        P->m[i] = m->rho0 * s->phys.dx * s->phys.dx * (1.0 + uniform(-0.2, 0.2));
        P->inv_m[i] = 1.0 / P->m[i];
        P->mu[i] = uniform(0.0, 0.1);
    }
    if (integrate_rebuild_lists(s) != MIXSPH_OK) { /* cells and neighbour ranges of the moved particles */
        mixsph_sim_destroy(s);
        return -1;
    }
    integrate_pressure_and_derived(s);
    *state = s;
    return 0;
}

static int teardown(void **state)
{
    mixsph_sim_destroy(*state);
    return 0;
}

static double dist2(const struct particles *P, size_t i, size_t j)
{
    const double rx = P->pos[0][i] - P->pos[0][j], rz = P->pos[DIM_UP][i] - P->pos[DIM_UP][j];
    return rx * rx + rz * rz;
}

/* The case is what the other tests assume: only fluid-fluid pairs, both media present. */
static void test_setup_is_wall_free(void **state)
{
    const mixsph_sim *s = *state;
    const struct particles *P = &s->phys.P;
    size_t n_mob = 0, n_wall = 0, n_oil = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] == MIXSPH_STATE_WALL) {
            n_wall++;
            continue;
        }
        assert_int_equal(P->state[i], MIXSPH_STATE_MOBILE);
        n_mob++;
        n_oil += P->medium[i] == 1;
        for (size_t j = 0; j < P->n; j++)
            if (P->state[j] == MIXSPH_STATE_WALL) assert_true(dist2(P, i, j) > 4.0 * s->phys.K.r2max);
    }
    assert_int_equal(n_mob, 400); /* (0.2 / 0.01) x (0.2 / 0.01) lattice sites */
    assert_int_equal(n_oil, 200);
    assert_true(n_wall > 0);
}

/* Pair symmetry: m_i a_ij = -m_j a_ji for every fluid pair within the support, including pairs
 * across the two media; the continuity terms obey drho_ij / (rho_i V_j) = drho_ji / (rho_j V_i). */
static void test_pair_symmetry(void **state)
{
    mixsph_sim *s = *state;
    const struct particles *P = &s->phys.P;
    size_t pairs = 0, cross = 0;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] != MIXSPH_STATE_MOBILE) continue;
        double ax, az, dr;
        sim_pair_terms(s, i, i, &ax, &az, &dr);
        assert_true(ax == 0.0 && az == 0.0 && dr == 0.0); /* no self-interaction */
        for (size_t j = 0; j < P->n; j++) {
            if (j == i || P->state[j] != MIXSPH_STATE_MOBILE) continue;
            double axij, azij, drij, axji, azji, drji;
            sim_pair_terms(s, i, j, &axij, &azij, &drij);
            sim_pair_terms(s, j, i, &axji, &azji, &drji);
            if (dist2(P, i, j) >= s->phys.K.r2max) {
                /* outside the support: nothing (reference: compact support of W) */
                assert_true(axij == 0.0 && azij == 0.0 && drij == 0.0);
                continue;
            }
            pairs++;
            cross += P->medium[i] != P->medium[j];
            const double fx = P->m[i] * axij, fz = P->m[i] * azij, gx = P->m[j] * axji, gz = P->m[j] * azji;
            const double scale = hypot(fx, fz) + hypot(gx, gz);
            assert_true(scale > 0.0);
            /* reference: Newton's third law of the pair; tolerance 1e-12 relative (round-off of
             * the differently ordered products) */
            assert_true(hypot(fx + gx, fz + gz) <= 1e-12 * scale);
            /* continuity: rho_i V_j u_ij . grad_i W_ij is symmetric once divided by rho_i V_j;
             * same tolerance */
            const double ci = drij / (P->rho[i] * P->vol[j]), cj = drji / (P->rho[j] * P->vol[i]);
            assert_true(fabs(ci - cj) <= 1e-12 * (fabs(ci) + fabs(cj)) + 1e-300);
        }
    }
    print_message("%zu ordered pairs checked, %zu across the two media\n", pairs, cross);
    assert_true(pairs > 5000 && cross > 200);
}

/* Geometry and kinematics of the pair (i, j) of two distinct mobile particles within the support:
 * returns 0 for any other pair. */
struct pair_geom {
    double rx, rz, r2, F, ux, uz, vr;
};

static int pair_geom(const mixsph_sim *s, size_t i, size_t j, struct pair_geom *g)
{
    const struct particles *P = &s->phys.P;
    if (j == i || P->state[i] != MIXSPH_STATE_MOBILE || P->state[j] != MIXSPH_STATE_MOBILE || dist2(P, i, j) >= s->phys.K.r2max)
        return 0;
    g->rx = P->pos[0][i] - P->pos[0][j];
    g->rz = P->pos[DIM_UP][i] - P->pos[DIM_UP][j];
    g->r2 = g->rx * g->rx + g->rz * g->rz;
    g->F = kernel_f(&s->phys.K, sqrt(g->r2));
    g->ux = P->vel[0][i] - P->vel[0][j];
    g->uz = P->vel[DIM_UP][i] - P->vel[DIM_UP][j];
    g->vr = g->ux * g->rx + g->uz * g->rz;
    return 1;
}

/* Which term(s) of (3) are switched on. */
enum { TERM_PRESSURE = 1, TERM_MONAGHAN = 2, TERM_MORRIS = 4, TERM_MORRIS_MIXED = 8 };

/* Switch terms off through the inputs: alpha_M of the media (then integrate_pressure_and_derived refreshes the
 * per-particle fields and the pressures from the densities), p and mu of the particles. */
static void select_terms(mixsph_sim *s, int terms, const double *alpha, const double *mu)
{
    struct particles *P = &s->phys.P;
    for (size_t k = 0; k < s->cfg.n_media; k++) s->cfg.media[k].alpha_m = terms & TERM_MONAGHAN ? alpha[k] : 0.0;
    integrate_pressure_and_derived(s);
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] != MIXSPH_STATE_MOBILE) continue;
        if (!(terms & TERM_PRESSURE)) P->p[i] = 0.0;
        /* TERM_MORRIS: one viscosity for all (0.05 Pa s), so that every pairwise mean of
         * mu_i and mu_j is that value; TERM_MORRIS_MIXED: the random viscosities */
        P->mu[i] = terms & TERM_MORRIS_MIXED ? mu[i] : terms & TERM_MORRIS ? 0.05 : 0.0;
    }
}

/* The inputs select_terms overwrites: the particles' viscosities (returned, to free) and the
 * media's alpha_M (into alpha). */
static double *save_terms(const mixsph_sim *s, double *alpha)
{
    double *mu = malloc(s->phys.P.n * sizeof *mu);
    assert_non_null(mu);
    memcpy(mu, s->phys.P.mu, s->phys.P.n * sizeof *mu);
    for (size_t k = 0; k < s->cfg.n_media; k++) alpha[k] = s->cfg.media[k].alpha_m;
    return mu;
}

/* Each term of (3) against its formula and sign, switched on one at a time. */
static void test_pair_terms(void **state)
{
    mixsph_sim *s = *state;
    struct particles *P = &s->phys.P;
    const struct kernel *K = &s->phys.K;
    const double eta2 = 0.01 * s->phys.h * s->phys.h;
    const double F0 = kernel_f(K, 0.0); /* the kernel's largest |F| */
    const size_t n = P->n;
    double alpha[CASE_MAX_MEDIA];
    double *mu = save_terms(s, alpha);
    size_t checked = 0, approaching = 0, compressed = 0;
    size_t mixed = 0;
    for (int term = TERM_PRESSURE; term <= TERM_MORRIS_MIXED; term <<= 1) {
        select_terms(s, term, alpha, mu);
        for (size_t i = 0; i < n; i++) {
            for (size_t j = 0; j < n; j++) {
                struct pair_geom g;
                if (!pair_geom(s, i, j, &g)) continue;
                const double rx = g.rx, rz = g.rz, r2 = g.r2, F = g.F, ux = g.ux, uz = g.uz, vr = g.vr;
                const double rhoi = P->rho[i], rhoj = P->rho[j], mj = P->m[j];
                double ax, az, dr;
                sim_pair_terms(s, i, j, &ax, &az, &dr);
                checked++;
                if (term == TERM_PRESSURE) {
                    /* a_ij = -m_j (p_i + p_j) / (rho_i rho_j) grad_i W_ij (eq. 3); the pressures
                     * are those of the EOS, p = c^2 (rho - rho0) (test_eos) */
                    const struct medium *mi = &s->cfg.media[P->medium[i]];
                    assert_true(P->p[i] == eos_pressure(rhoi, mi->rho0, mi->c));
                    const double fp = -mj * (P->p[i] + P->p[j]) / (rhoi * rhoj) * F;
                    const double fpmax = fp / F * F0;
                    /* reference: the formula; tolerance 1e-12 relative to the largest value the
                     * kernel gives (round-off: (1 - q/2)^3 loses relative accuracy near 2h) */
                    assert_true(hypot(ax - fp * rx, az - fp * rz) <= 1e-12 * fabs(fpmax) * sqrt(r2));
                    /* sign: positive pressures push i away from j */
                    if (P->p[i] + P->p[j] > 0.0) assert_true(ax * rx + az * rz > 0.0);
                    /* continuity: rate of rho_i = rho_i V_j u_ij . grad_i W_ij (eq. 3); reference:
                     * the formula, tolerance 1e-12 relative */
                    const double dref = rhoi * mj / rhoj * vr * F;
                    assert_true(fabs(dr - dref) <= 1e-12 * fabs(dref / F * F0));
                    /* sign: approaching particles compress i */
                    if (vr < 0.0) {
                        assert_true(dr > 0.0);
                        compressed++;
                    }
                } else if (term == TERM_MONAGHAN) {
                    /* -m_j Pi_ij grad_i W_ij, Pi_ij = -alpha c h u.r / ((r^2 + eta^2) rho_bar) for
                     * approaching pairs of one medium, 0 otherwise (Monaghan 1992, beta = 0;
                     * docs/model.md section 2: fluid pairs only, so 0 across the two media) */
                    const struct medium *md = &s->cfg.media[P->medium[i]];
                    double fa = 0.0;
                    if (vr < 0.0 && P->medium[i] == P->medium[j]) {
                        const double pi_ij = -md->alpha_m * md->c * s->phys.h * vr / (r2 + eta2) / (0.5 * (rhoi + rhoj));
                        fa = -mj * pi_ij * F;
                        approaching++;
                        /* dissipative: the force opposes the approach */
                        assert_true(ax * ux + az * uz < 0.0);
                    }
                    /* reference: the formula with rho_bar = (rho_i + rho_j)/2; tolerance 1e-12
                     * relative plus (rho_i - rho_j)^2 / (4 rho_i rho_j) (< 1e-4 here): forces.c
                     * may use the mean of 1/rho instead of 1/rho_bar, equal to that order */
                    const double tol = 1e-12 + (rhoi - rhoj) * (rhoi - rhoj) / (4.0 * rhoi * rhoj);
                    assert_true(hypot(ax - fa * rx, az - fa * rz) <= tol * fabs(fa / F * F0) * sqrt(r2));
                } else if (term == TERM_MORRIS) {
                    /* m_j (mu_i + mu_j) / (rho_i rho_j) F r^2 / (r^2 + eta^2) u_ij (Morris et al.
                     * 1997, eq. 30) with mu_i = mu_j = 0.05 Pa s; reference: the formula,
                     * tolerance 1e-12 relative (to F(0)) */
                    const double fm = mj * (2.0 * 0.05) / (rhoi * rhoj) * F * r2 / (r2 + eta2);
                    assert_true(hypot(ax - fm * ux, az - fm * uz) <= 1e-12 * fabs(fm / F * F0) * hypot(ux, uz));
                    /* dissipative: opposes the relative velocity */
                    assert_true(ax * ux + az * uz <= 0.0);
                } else {
                    /* different viscosities: the same term with mu_i + mu_j replaced by twice a
                     * pairwise mean (docs/model.md section 7 leaves the mean open): the force is along
                     * -u_ij, and the mean lies between min(mu_i, mu_j) and max(mu_i, mu_j) */
                    const double unit = mj / (rhoi * rhoj) * F * r2 / (r2 + eta2); /* < 0 */
                    const double u2 = ux * ux + uz * uz;
                    const double mean = (ax * ux + az * uz) / (2.0 * unit * u2);
                    const double px = ax - (ax * ux + az * uz) / u2 * ux, pz = az - (ax * ux + az * uz) / u2 * uz;
                    const double lo = fmin(mu[i], mu[j]), hi = fmax(mu[i], mu[j]);
                    /* reference: parallel to u_ij, tolerance 1e-12 relative (to F(0)) */
                    assert_true(hypot(px, pz) <= 1e-12 * fabs(unit / F * F0) * 2.0 * hi * sqrt(u2));
                    /* reference: a mean of mu_i and mu_j; tolerance 1e-12 relative */
                    assert_true(mean >= lo * (1.0 - 1e-12) && mean <= hi * (1.0 + 1e-12));
                    mixed++;
                }
            }
        }
    }
    select_terms(s, TERM_PRESSURE | TERM_MONAGHAN | TERM_MORRIS_MIXED, alpha, mu);
    free(mu);
    print_message("%zu pair terms checked; %zu approaching pairs within one medium, %zu compressing\n", checked,
                  approaching, compressed);
    assert_true(checked > 20000 && approaching > 1000 && compressed > 1000 && mixed > 5000);
}

/* The loops over all pairs: the density and momentum passes give each particle the sum of
 * its pair terms (against a brute-force sum of forces_pair_for_test over all particles) and the
 * count of its same-medium neighbours, and the total momentum change sum_i m_i a_i vanishes
 * (no gravity, no wall within reach). */
static void test_momentum_conservation(void **state)
{
    mixsph_sim *s = *state;
    struct particles *P = &s->phys.P;
    assert_int_equal(sim_density_pass(s), 0);
    assert_int_equal(sim_momentum_pass(s), 0);
    double sx = 0.0, sz = 0.0, sabs = 0.0;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] != MIXSPH_STATE_MOBILE) continue;
        double bx = 0.0, bz = 0.0, babs = 0.0, bd = 0.0, bdabs = 0.0;
        unsigned nn = 0;
        for (size_t j = 0; j < P->n; j++) {
            double ax, az, dr;
            sim_pair_terms(s, i, j, &ax, &az, &dr);
            bx += ax;
            bz += az;
            babs += hypot(ax, az);
            bd += dr;
            bdabs += fabs(dr);
            nn += j != i && P->state[j] != MIXSPH_STATE_WALL && P->medium[j] == P->medium[i] &&
                  dist2(P, i, j) < s->phys.K.r2max;
        }
        /* reference: brute force over all j; tolerance 1e-12 of the sum of |pair terms| (the
         * sums differ only in order) */
        assert_true(hypot(P->acc[0][i] - bx, P->acc[DIM_UP][i] - bz) <= 1e-12 * babs);
        assert_true(fabs(P->drho[i] - bd) <= 1e-12 * bdabs);
        assert_int_equal(P->nneigh[i], nn); /* the spray criterion of the monitors */
        sx += P->m[i] * P->acc[0][i];
        sz += P->m[i] * P->acc[DIM_UP][i];
        sabs += P->m[i] * hypot(P->acc[0][i], P->acc[DIM_UP][i]);
    }
    print_message("|sum m a| = %.3e N/m, sum |m a| = %.3e N/m\n", hypot(sx, sz), sabs);
    assert_true(sabs > 0.0);
    /* reference: 0 (every pair term antisymmetric); tolerance 1e-12 of sum |m a|: round-off of
     * about 1e4 pair terms of relative size 1e-16 */
    assert_true(hypot(sx, sz) <= 1e-12 * sabs);

    /* The momentum pass above read the kernel factors cached by the continuity pass, once:
     * called again without a continuity pass it refuses (-1, as out of memory: no copy of its
     * walks evaluates the kernel); after another continuity pass it gives the same forces.
     * Reference: the first run; tolerance: none. */
    double *ax0 = malloc(P->n * sizeof *ax0), *az0 = malloc(P->n * sizeof *az0);
    assert_non_null(ax0);
    assert_non_null(az0);
    memcpy(ax0, P->acc[0], P->n * sizeof *ax0);
    memcpy(az0, P->acc[DIM_UP], P->n * sizeof *az0);
    assert_int_equal(forces_cache_pending(s->work.forces), 0); /* used once */
    assert_int_equal(sim_momentum_pass(s), -1);
    assert_int_equal(sim_density_pass(s), 0);
    assert_int_equal(sim_momentum_pass(s), 0);
    assert_memory_equal(ax0, P->acc[0], P->n * sizeof *ax0);
    assert_memory_equal(az0, P->acc[DIM_UP], P->n * sizeof *az0);
    free(ax0);
    free(az0);
}


/* The switches of the Monaghan term (numerics.av_mixed, numerics.av_separating: SPHERA applies
 * it to every pair of particles, separating ones too): each combination against the formula,
 * with alpha c h of the pair the larger of the two particles' (forces.c). */
static void test_monaghan_switches(void **state)
{
    mixsph_sim *s = *state;
    struct particles *P = &s->phys.P;
    const struct kernel *K = &s->phys.K;
    const double eta2 = 0.01 * s->phys.h * s->phys.h;
    const double F0 = kernel_f(K, 0.0);
    const size_t n = P->n;
    double alpha[CASE_MAX_MEDIA];
    double *mu = save_terms(s, alpha);
    select_terms(s, TERM_MONAGHAN, alpha, mu);
    size_t on[4] = {0}, off[4] = {0};
    for (int mode = 0; mode < 4; mode++) {
        const int mixed = mode & 1, separating = (mode >> 1) & 1;
        s->scheme.pair.av_mixed = mixed;
        s->scheme.pair.av_separating = separating;
        for (size_t i = 0; i < n; i++) {
            for (size_t j = 0; j < n; j++) {
                struct pair_geom g;
                if (!pair_geom(s, i, j, &g)) continue;
                const double rx = g.rx, rz = g.rz, r2 = g.r2, F = g.F, vr = g.vr;
                const double rhoi = P->rho[i], rhoj = P->rho[j], mj = P->m[j];
                const struct medium *mdi = &s->cfg.media[P->medium[i]], *mdj = &s->cfg.media[P->medium[j]];
                const double avc = fmax(mdi->alpha_m * mdi->c, mdj->alpha_m * mdj->c) * s->phys.h;
                const int acts = (vr < 0.0 || separating) && (P->medium[i] == P->medium[j] || mixed);
                double ax, az, dr;
                sim_pair_terms(s, i, j, &ax, &az, &dr);
                const double fa = acts ? mj * avc * vr / (r2 + eta2) / (0.5 * (rhoi + rhoj)) * F : 0.0;
                /* reference: Monaghan's Pi_ij with the pair's switches; tolerance as in
                 * test_pair_terms (the mean of 1/rho for 1/rho_bar) */
                const double tol = 1e-12 + (rhoi - rhoj) * (rhoi - rhoj) / (4.0 * rhoi * rhoj);
                const double scale = mj * avc * fabs(vr) / (r2 + eta2) / (0.5 * (rhoi + rhoj)) * fabs(F0);
                assert_true(hypot(ax - fa * rx, az - fa * rz) <= tol * scale * sqrt(r2));
                /* dissipative whenever it acts: the force opposes the relative velocity's
                 * component along x_ij */
                if (acts && fa != 0.0) assert_true((ax * rx + az * rz) * vr < 0.0);
                acts ? on[mode]++ : off[mode]++;
            }
        }
    }
    s->scheme.pair.av_mixed = 0;
    s->scheme.pair.av_separating = 0;
    select_terms(s, TERM_PRESSURE | TERM_MONAGHAN | TERM_MORRIS_MIXED, alpha, mu);
    free(mu);
    /* every mode met pairs where the term acts, and all but the all-pairs mode pairs where it
     * does not */
    for (int mode = 0; mode < 4; mode++) assert_true(on[mode] > 1000);
    assert_true(off[0] > off[1] && off[1] > 0 && off[2] > 0 && off[3] == 0);
}

/* A fluid layer sliding along a wall (numerics.av_wall): with the Monaghan term between fluid
 * and wall particles (the default) the wall drags the layer, since a particle approaches the
 * wall particles ahead of it; without it, the fluid-wall pair forces carry no tangential part
 * (no laminar viscosity, pressures 0). */
static const char *const SLIDE_CASE =
    "{\n"
    "  \"name\": \"wall_slide\",\n"
    "  \"gravity\": 0.0,\n"
    "  \"numerics\": { \"dx\": 0.01, \"t_end\": 0.1 },\n"
    "  \"media\": { \"water\": { \"type\": \"fluid\", \"rho\": 1000.0, \"c\": 30.0, \"mu\": 0.0, \"alpha_m\": 0.1 } },\n"
    "  \"bodies\": { \"layer\": { \"medium\": \"water\", \"polygon\": [[0.0, 0.0], [0.3, 0.0], [0.3, 0.05], [0.0, 0.05]] } },\n"
    "  \"walls\": { \"bed\": { \"polyline\": [[-0.2, 0.0], [0.5, 0.0]], \"fluid_side\": \"left\" } }\n"
    "}\n";

static void test_monaghan_at_walls(void **state)
{
    (void)state;
    mixsph_sim *s = NULL;
    char err[512];
    assert_int_equal(mixsph_sim_create_from_text(SLIDE_CASE, "wall_slide.json", NULL, 0, &s, err, sizeof err), MIXSPH_OK);
    struct particles *P = &s->phys.P;
    for (size_t i = 0; i < P->n; i++) {
        if (P->state[i] != MIXSPH_STATE_MOBILE) continue;
        P->vel[0][i] = P->uv[0][i] = 1.0; /* sliding along the wall, +x */
        P->vel[DIM_UP][i] = P->uv[DIM_UP][i] = 0.0;
        P->rho[i] = s->cfg.media[0].rho0; /* p = 0 */
    }
    integrate_pressure_and_derived(s);
    for (int av_wall = 1; av_wall >= 0; av_wall--) {
        s->scheme.pair.av_wall = av_wall;
        double drag = 0.0, mass = 0.0;
        size_t pairs = 0;
        for (size_t i = 0; i < P->n; i++) {
            if (P->state[i] != MIXSPH_STATE_MOBILE || P->pos[0][i] < 0.05 || P->pos[0][i] > 0.25) continue; /* away from the ends */
            for (size_t j = 0; j < P->n; j++) {
                if (P->state[j] != MIXSPH_STATE_WALL || dist2(P, i, j) >= s->phys.K.r2max) continue;
                double ax, az, dr;
                sim_pair_terms(s, i, j, &ax, &az, &dr);
                if (!av_wall) {
                    /* reference: no term acts (no pressure, no viscosity, no Monaghan term);
                     * tolerance: exactly 0 */
                    assert_true(ax == 0.0 && az == 0.0);
                } else {
                    const double vr = (P->vel[0][i] - P->vel[0][j]) * (P->pos[0][i] - P->pos[0][j]) + (P->vel[DIM_UP][i] - P->vel[DIM_UP][j]) * (P->pos[DIM_UP][i] - P->pos[DIM_UP][j]);
                    /* approaching wall particles resist, receding ones do not */
                    if (vr >= 0.0) assert_true(ax == 0.0 && az == 0.0);
                    else assert_true(ax < 0.0);
                }
                drag += P->m[i] * ax;
                pairs++;
            }
            mass += P->m[i];
        }
        print_message("av_wall = %d: %zu fluid-wall pairs, mean tangential acceleration %.4g m/s2\n", av_wall, pairs,
                      drag / mass);
        assert_true(pairs > 100);
        if (av_wall) assert_true(drag < 0.0); /* a net drag against the sliding */
        else assert_true(drag == 0.0);
    }
    mixsph_sim_destroy(s);
    /* a switch that is not a Boolean is refused, naming the key */
    char text[2048];
    const char *at = strstr(SLIDE_CASE, "\"t_end\": 0.1");
    assert_non_null(at);
    snprintf(text, sizeof text, "%.*s\"av_wall\": \"no\", %s", (int)(at - SLIDE_CASE), SLIDE_CASE, at);
    s = NULL;
    assert_int_equal(mixsph_sim_create_from_text(text, "wall_slide.json", NULL, 0, &s, err, sizeof err), MIXSPH_ERR_CASE);
    assert_null(s);
    print_message("refused: %s\n", err);
    assert_non_null(strstr(err, "numerics.av_wall"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_setup_is_wall_free),
        cmocka_unit_test(test_pair_symmetry),
        cmocka_unit_test(test_pair_terms),
        cmocka_unit_test(test_momentum_conservation),
        cmocka_unit_test(test_monaghan_switches),
        cmocka_unit_test(test_monaghan_at_walls),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
