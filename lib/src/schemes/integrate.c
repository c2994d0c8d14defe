/* integrate.c - time step criterion (4) and the second-order leapfrog (docs/model.md section 4), in
 * kick-drift-kick form with position and density at whole steps and velocity at half steps:
 *   v^{n+1/2} = v^n + dt/2 a^n
 *   x^{n+1}   = x^n + dt v^{n+1/2}                   (walls kept uncrossed; walls move)
 *   rho^{n+1} = rho^n + dt D(x^{n+1}, v^{n+1/2})     (continuity pass, newest velocity)
 *   a^{n+1}   = A(x^{n+1}, rho^{n+1}, v^{n+1/2})     (EOS, wall pressure, momentum pass)
 *   v^{n+1}   = v^{n+1/2} + dt/2 a^{n+1}
 * In the density-velocity (acoustic) pair this is velocity Verlet, stable for omega dt < 2.
 * With numerics.viscosity = "implicit" the momentum pass leaves the viscous term out and the step
 * is symplectic Euler around the implicit viscous step (viscous.h; see implicit_viscous_step below):
 *   v* = v^n + dt a^n,  v^{n+1} = V_dt(v*),  x^{n+1} = x^n + dt v^{n+1},  then as above without
 *   the last kick, so that the particles move with the velocity the viscous step balanced.
 * Granular particles: after the density pass and the velocity-gradient pass (their strain rate
 * from v^{n+1/2}) mixture.c decides their regime; a fixed grain has its velocity zeroed, still
 * gets forces and the kicks, is not drifted, and enters dt with the viscosity it will have once
 * mobile (integrate_time_step; docs/model.md section 6); with the
 * medium option hold_fixed it gets no kicks either (SPHERA's momentum routine), so its velocity
 * stays 0; with the implicit scheme's rigid held grains (numerics.held_grains) it gets no kick and
 * stays at rest through the viscous step, then the velocity of one explicit step of its forces
 * (viscous.h). With numerics.pressure_smoothing > 0 the pressures are smoothed (forces.c) right
 * after the equation of state, before the regime decision reads them.
 * Evaluating both rates in one pass from the same old state would be explicit Euler for the
 * acoustic modes, which grow without bound (found the hard way: the hydrostatic tank blew up).
 * After the drift the particles are re-sorted and the neighbour ranges rebuilt only when one of
 * them has moved skin/2 since the last build or left the grid (neighbours.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "clock.h"
#include "integrate.h"
#include "team.h"

#include "eos.h"
#include "time_step.h"
#include "law_registry.h"
#include "status.h"
#include "viscous.h"

/* Distance [dx] at which a particle that would cross a wall is put back on its side. */
#define INTEGRATE_CLIP_GAP 0.1

/* (4): dt = min over particles of CFL_vis 2 h^2 / nu_i and CFL 2 h / (c_max + |u_i|).
 * A fixed grain enters the viscous bound with min(mu0, mu_thr), the largest viscosity it can
 * have once mobile, not with its mu_thr: that is the paper's saving (dt ~ 1/mu0, Table 2), and
 * a grain mobilised at the next step is then integrated stably from its first mobile step. It
 * also keeps the velocity a fixed grain picks up in one step (dt a) small, so grains whose forces
 * nearly balance stay fixed (docs/model.md section 6). Mobile grains have mu <= min(mu0, mu_thr). */
static inline double particle_time_step(const mixsph_sim *s, size_t i, int implicit)
{
    const struct particles *P = &s->phys.P;
    double u2 = 0.0;
    for (int d = 0; d < DIM; d++) u2 += P->vel[d][i] * P->vel[d][i];
    const double u = sqrt(u2);
    double mu = implicit ? 0.0 : P->mu[i];
    if (!implicit && P->state[i] == MIXSPH_STATE_FIXED) /* the viscosity it will have once mobilised */
        mu = s->scheme.media[P->medium[i]].held_viscosity;
    return time_step_bound(s->scheme.cfl, s->scheme.cfl_visc, s->phys.h, s->phys.c_max, u, P->rho[i], mu);
}

/* Whether held particle i (MIXSPH_STATE_FIXED) takes the kicks of its forces (laws/medium.h). */
static inline int held_kicked(const mixsph_sim *s, size_t i, int rigid)
{
    return medium_held_kicked(&s->scheme.media[s->phys.P.medium[i]], rigid);
}

/* The parallel loops of this file (core/team.h) each take their own arguments; their reductions
 * are exact (min, max, |, integer +), so any split of a loop gives the same. */

/* The time step (4) over the particles: its smallest bound. */
struct time_step_loop {
    const mixsph_sim *s;
    int implicit;     /* no viscous bound (the implicit viscous step) */
    double dt_min;    /* min */
};

static void time_step_range(void *arg, size_t b, size_t e)
{
    struct time_step_loop *L = arg;
    const mixsph_sim *s = L->s;
    const struct particles *P = &s->phys.P;
    double dt = INFINITY;
    for (size_t i = b; i < e; i++) {
        if (P->state[i] > MIXSPH_STATE_FIXED) continue;
        const double d = particle_time_step(s, i, L->implicit);
        if (d < dt) dt = d;
    }
    team_min_double(&L->dt_min, dt);
}

double integrate_time_step(const mixsph_sim *s)
{
    /* no viscous bound with the implicit viscous step */
    struct time_step_loop L = {.s = s, .implicit = s->scheme.implicit, .dt_min = INFINITY};
    team_for(SIM_THREADS(s), s->phys.P.n, time_step_range, &L);
    return L.dt_min;
}

/* The equation of state of particle i (not a wall, not lost): pressure, 1/rho, volume, alpha c h. */
static inline void particle_pressure(mixsph_sim *s, size_t i)
{
    struct particles *P = &s->phys.P;
    const struct medium *m = &s->scheme.media[P->medium[i]];
    const double pb = s->scheme.p_background;
    double p = eos_pressure(P->rho[i], m->rho0, m->c) + pb;
    if (m->tension_cutoff && p < pb) p = pb; /* a cohesionless medium carries no tension */
    P->p[i] = p;
    P->inv_rho[i] = 1.0 / P->rho[i];
    P->vol[i] = P->m[i] * P->inv_rho[i];
    P->avc[i] = m->alpha_m * m->c * s->phys.h;
}

static void pressure_range(void *arg, size_t b, size_t e)
{
    mixsph_sim *s = arg;
    const struct particles *P = &s->phys.P;
    for (size_t i = b; i < e; i++) {
        if (P->state[i] == MIXSPH_STATE_WALL || P->state[i] == MIXSPH_STATE_LOST) continue;
        particle_pressure(s, i);
    }
}

void integrate_pressure_and_derived(mixsph_sim *s)
{
    team_for(SIM_THREADS(s), s->phys.P.n, pressure_range, s);
}

mixsph_status integrate_rebuild_lists(mixsph_sim *s)
{
    if (s->work.mirror.on && mirror_sides_make(&s->work.mirror, &s->phys.P) != 0)
        return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory for the mirror images");
    const long lost = cells_build(&s->work.C, &s->phys.P);
    if (lost < 0) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory in the cell list");
    s->phys.n_lost += lost;
    if (neighbours_build(&s->work.NB, &s->work.C, &s->phys.P, s->work.C.start[s->work.C.ncell], 2.0 * s->phys.h + s->work.NB.skin, SIM_THREADS(s)) != 0)
        return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory in the neighbour lists");
    return integrate_build_gather_lists(s);
}

/* near_wall[i]: whether particle i is within `reach` of a wall. */
struct near_wall_loop {
    mixsph_sim *s;
    double reach; /* [m] */
};

static void near_wall_range(void *arg, size_t b, size_t e)
{
    const struct near_wall_loop *L = arg;
    const mixsph_sim *s = L->s;
    const struct particles *P = &s->phys.P;
    const double reach = L->reach;
    for (size_t i = b; i < e; i++) {
        int close = 0;
        if (P->state[i] != MIXSPH_STATE_WALL)
            for (size_t w = 0; w < s->phys.walls.n && !close; w++) {
                double pos[DIM];
                for (int k = 0; k < DIM; k++) pos[k] = P->pos[k][i];
                close = walls_near(&s->phys.walls, w, pos, reach);
            }
        s->work.near_wall[i] = (uint8_t)close;
    }
}

/* Grains gather over all their neighbours (the velocity gradient), wall particles over the
 * non-wall ones (their pressure). */
mixsph_status integrate_build_gather_lists(mixsph_sim *s)
{
    const struct particles *P = &s->phys.P;
    const size_t n = s->work.C.start[s->work.C.ncell];
    if (s->work.mirror.on && (mirror_sides_resolve(&s->work.mirror, P) != 0 ||
                              ((s->phys.law_features & LAW_USES_GRADIENT) && velocity_gradient_reserve(&s->work.grad, P->n) != 0)))
        return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory for the mirror images");
    if (neighbours_gather_reserve(&s->work.G, P->cap) != 0) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory in the gather lists");
    for (size_t i = 0; i < n; i++) {
        uint8_t mode = NEIGHBOURS_GATHER_NONE;
        if (P->state[i] == MIXSPH_STATE_WALL || (s->scheme.media[P->medium[i]].features & LAW_USES_GRADIENT))
            mode = NEIGHBOURS_GATHER_ALL;
        s->work.G.mode[i] = mode;
    }
    if (neighbours_gather_build(&s->work.G, &s->work.NB, &s->work.C, P->state, n, 2.0 * s->phys.h + s->work.NB.skin, SIM_THREADS(s)) != 0)
        return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory in the gather lists");
    /* Particles that may reach a wall before the next build: until then every particle and
     * every wall moves less than skin/2 from its build position, so from any time in between
     * the remaining relative motion is below 2 skin. The others skip the wall-crossing test
     * (which could not fire for them: skipping it changes no result). */
    uint8_t *near = realloc(s->work.near_wall, P->cap ? P->cap : 1);
    if (!near) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory");
    s->work.near_wall = near;
    uint8_t *excluding = realloc(s->work.excluding, P->cap ? P->cap : 1);
    if (!excluding) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory");
    s->work.excluding = excluding;
    memset(excluding, 0, P->cap ? P->cap : 1);
    struct near_wall_loop L = {.s = s, .reach = 2.0 * s->work.NB.skin + 2.0 * s->phys.dx};
    team_for(SIM_THREADS(s), n, near_wall_range, &L);
    return MIXSPH_OK;
}

struct pair_system sim_pair_system(mixsph_sim *s)
{
    struct pair_system S;
    S.P = &s->phys.P;
    S.C = &s->work.C;
    S.NB = &s->work.NB;
    S.G = &s->work.G;
    S.media = s->scheme.media;
    S.params = s->scheme.pair;
    S.dt = s->phys.dt;
    S.n_threads = SIM_THREADS(s);
    return S;
}

static size_t active_particles(const mixsph_sim *s) { return s->work.C.start[s->work.C.ncell]; }

/* Whether a medium of the case uses law `id`. */
static int law_in_use(const mixsph_sim *s, int id)
{
    for (size_t k = 0; k < s->scheme.n_media; k++)
        if (s->scheme.media[k].law == id) return 1;
    return 0;
}

int integrate_density_rates(mixsph_sim *s, const struct pair_system *S)
{
    if (s->phys.law_features & LAW_USES_GRADIENT) return forces_density_rate_gradient(s->work.forces, S, &s->work.grad);
    return forces_density_rate(s->work.forces, S);
}

/* The material laws' updates over law_dt (0: at the current state, no advance), in the order of
 * their ids; a law that holds particles (LAW_HOLDS_PARTICLES) reports how many. */
void integrate_update_laws(mixsph_sim *s, double law_dt)
{
    const struct law_step step = {.P = &s->phys.P, .n = active_particles(s), .media = s->scheme.media, .grad = &s->work.grad,
                                  .G = &s->work.G, .K = &s->phys.K, .dt = law_dt,
                                  .p_background = s->scheme.p_background, .n_threads = SIM_THREADS(s)};
    long held = 0;
    for (int id = 0; id < LAW_COUNT; id++) {
        const struct material_law *law = law_get(id);
        if (!law->update || !law_in_use(s, id)) continue;
        const long count = law->update(s->phys.law_state[id], &step);
        if (law->features & LAW_HOLDS_PARTICLES) held += count;
    }
    s->phys.n_fixed = held;
}

/* After the densities are updated and the equation of state: pressures smoothed (with
 * numerics.pressure_smoothing), the grains' regimes, the walls' extrapolated state. Returns -1
 * when out of memory. */
static int pressures_and_regimes(mixsph_sim *s, const struct pair_system *S, int smooth, double law_dt)
{
    if (smooth && forces_smooth_pressure(s->work.forces, S, s->scheme.pressure_smoothing * s->phys.dt / s->phys.h) != 0) return -1;
    integrate_update_laws(s, law_dt);
    mirror_sides_refresh(&s->work.mirror, &s->phys.P, S->n_threads); /* the fluid's images, for the walls */
    walls_extrapolate_fluid(&s->phys.walls, &s->phys.K, &s->work.G, s->phys.dx, &s->phys.P, active_particles(s), S->n_threads);
    mirror_sides_refresh(&s->work.mirror, &s->phys.P, S->n_threads); /* and the walls' images */
    return 0;
}

/* v += dt a of the particles that take kicks (not walls, lost particles, held particles that take
 * no kicks: laws/law.h; in the implicit scheme rigid held grains stay at rest through the viscous
 * step). */
struct kick_loop {
    mixsph_sim *s;
    double dt; /* [s] */
};

static void kick_range(void *arg, size_t b, size_t e)
{
    const struct kick_loop *L = arg;
    const mixsph_sim *s = L->s;
    struct particles *P = &L->s->phys.P;
    const int rigid = s->scheme.implicit && s->scheme.held_grains_rigid;
    const double dt = L->dt;
    for (size_t i = b; i < e; i++) {
        if (P->state[i] > MIXSPH_STATE_FIXED) continue;
        if (P->state[i] == MIXSPH_STATE_FIXED && !held_kicked(s, i, rigid)) continue;
        for (int d = 0; d < DIM; d++) P->vel[d][i] += dt * P->acc[d][i];
    }
}

static void kick_velocities(mixsph_sim *s, double dt)
{
    struct kick_loop L = {.s = s, .dt = dt};
    team_for(SIM_THREADS(s), s->phys.P.n, kick_range, &L);
}

/* The time step the explicit scheme would take from the current state, at most dt: the kick over
 * which the implicit scheme judges rigid held grains. The regime decision (docs/model.md section
 * 6) judges a held grain on the velocity one step of its forces gives it, which grows with the
 * step; over the implicit step, up to hundreds of times the explicit one, grains whose forces
 * nearly balance would be released that the model holds. */
static double held_grain_judge_dt(const mixsph_sim *s, double dt)
{
    struct time_step_loop L = {.s = s, .implicit = 0, .dt_min = dt};
    team_for(SIM_THREADS(s), s->phys.P.n, time_step_range, &L);
    return L.dt_min;
}

/* Room for the implicit step's unknowns flags of cap particles (NULL when out of memory; the old
 * array is then freed). */
static unsigned char *realloc_unknowns(unsigned char *u, size_t cap)
{
    unsigned char *r = realloc(u, cap ? cap : 1);
    if (!r) free(u);
    return r;
}

/* With rigid held grains (numerics.held_grains = "rigid"): the velocity of every held grain that
 * takes kicks (laws/law.h) after one explicit step of judge_dt, as the explicit scheme gives it to
 * the grain it judges (mixture_paper.c): its acceleration by the other forces (P->acc of the last
 * momentum pass) plus the viscous one from the solved velocities around it, -(L u)_i / m_i with
 * u_i = 0; lu = L u of the solved field. */
struct held_kick_loop {
    mixsph_sim *s;
    double judge_dt;              /* [s] */
    const double *const *lu;      /* L u, DIM components */
};

static void held_kick_range(void *arg, size_t b, size_t e)
{
    const struct held_kick_loop *L = arg;
    const mixsph_sim *s = L->s;
    struct particles *P = &L->s->phys.P;
    const double judge_dt = L->judge_dt;
    for (size_t i = b; i < e; i++) {
        if (P->state[i] != MIXSPH_STATE_FIXED || !held_kicked(s, i, 0)) continue;
        for (int d = 0; d < DIM; d++) P->vel[d][i] = judge_dt * (P->acc[d][i] - L->lu[d][i] / P->m[i]);
    }
}

static void held_grain_kicks(mixsph_sim *s, int n_threads, double judge_dt, const double *const lu[DIM])
{
    struct held_kick_loop L = {.s = s, .judge_dt = judge_dt, .lu = lu};
    team_for(n_threads, active_particles(s), held_kick_range, &L);
}

/* The implicit viscous step over dt with the operator of the last momentum pass (at the current
 * positions; after a restored state it is rebuilt first). The step is symplectic Euler: the
 * velocities take the whole step's kick of the other forces and then the viscous step, and the
 * drift uses the result, so that at a steady state the velocity the particles move with is the
 * one at which the viscous and the other forces balance (a half kick before the drift, as in the
 * explicit leapfrog, would move them with an unbalanced half kick of the other forces: 2.4 % of
 * the lid speed in the lid-driven channel at 20 times the explicit viscous time step). A solve
 * that misses its tolerance stops the run. judge_dt: the kick of rigid held grains (viscous.h). */
/* The implicit step's unknowns: mobile particles, and held grains that take their forces
 * (mixture_paper.h). */
static void unknowns_range(void *arg, size_t b, size_t e)
{
    mixsph_sim *s = arg;
    const struct particles *P = &s->phys.P;
    const int rigid = s->scheme.held_grains_rigid;
    for (size_t i = b; i < e; i++)
        s->work.viscous_unknown[i] =
            P->state[i] == MIXSPH_STATE_MOBILE || (P->state[i] == MIXSPH_STATE_FIXED && held_kicked(s, i, rigid));
}

static int any_wall_moves(const struct walls *W)
{
    for (size_t w = 0; w < W->n; w++)
        if (W->def[w].motion >= 0) return 1;
    return 0;
}

/* The viscous force of the solved velocities on the wall particles of moving walls, -(L u)_j,
 * added to the force the momentum pass left in their accelerations (which leaves out the viscous
 * force in this scheme), so that a wall's work (walls_move) counts it. */
static void viscous_wall_forces(mixsph_sim *s, const double *const lu[DIM])
{
    const struct walls *W = &s->phys.walls;
    struct particles *P = &s->phys.P;
    for (size_t i = 0; i < active_particles(s); i++) {
        if (P->state[i] != MIXSPH_STATE_WALL || W->def[particles_wall_index(P, i)].motion < 0) continue;
        for (int d = 0; d < DIM; d++) P->acc[d][i] -= lu[d][i];
    }
}

static mixsph_status implicit_viscous_step(mixsph_sim *s, double dt, double judge_dt)
{
    if (!s->work.viscous && !(s->work.viscous = viscous_create())) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory");
    const struct pair_system S = sim_pair_system(s);
    if (!forces_viscous_ready(s->work.forces)) {
        /* a restored state: the couplings at its positions; the momentum pass also rewrites the
         * accelerations from the kicked velocities, and rigid held grains are judged on the
         * restored ones, so those are kept */
        const size_t bytes = s->phys.P.n * sizeof(double);
        double *acc[DIM];
        int bad = 0;
        for (int d = 0; d < DIM; d++) bad |= !(acc[d] = malloc(bytes ? bytes : 1));
        if (!bad) {
            for (int d = 0; d < DIM; d++) memcpy(acc[d], s->phys.P.acc[d], bytes);
            bad = integrate_density_rates(s, &S) < 0 || forces_momentum(s->work.forces, &S) < 0;
            for (int d = 0; d < DIM; d++) memcpy(s->phys.P.acc[d], acc[d], bytes);
        }
        for (int d = 0; d < DIM; d++) free(acc[d]);
        if (bad) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory in the pair loops");
    }
    if (!s->work.wall_mirror && !(s->work.wall_mirror = walls_mirror_create()))
        return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory");
    struct viscous_report *rep = &s->work.viscous_last;
    if (!(s->work.viscous_unknown = realloc_unknowns(s->work.viscous_unknown, s->phys.P.cap)))
        return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory in the implicit viscous step");
    const int rigid = s->scheme.held_grains_rigid;
    team_for(S.n_threads, active_particles(s), unknowns_range, s);
    const struct viscous_params *vp = &s->scheme.viscous;
    const double t0 = clock_monotonic_s();
    int failed = viscous_step(s->work.viscous, s->work.forces, &S, s->work.wall_mirror, &s->phys.walls, s->phys.t, dt,
                              s->work.viscous_unknown, vp, rep);
    const int kicks = rigid && judge_dt > 0.0, walls_work = any_wall_moves(&s->phys.walls);
    if (!failed && (kicks || walls_work)) { /* one operator pass, L u of the solved field, for both */
        const double *lu[DIM];
        failed = viscous_solution_operator(s->work.viscous, s->work.forces, &S, lu) != 0;
        if (!failed && kicks) held_grain_kicks(s, S.n_threads, judge_dt, lu);
        if (!failed && walls_work) viscous_wall_forces(s, lu);
    }
    s->work.viscous_wall_s += clock_monotonic_s() - t0;
    if (failed) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory in the implicit viscous step");
    s->work.viscous_iterations += (uint64_t)rep->iterations;
    if (!rep->converged)
        return SIM_FAIL(s, MIXSPH_ERR_UNSTABLE,
                        "implicit viscous step: relative residual %.3g after %d iterations (tolerance %g, "
                        "numerics.viscous_max_iterations %d) at t = %.6g s (step %llu)",
                        rep->residual, rep->iterations, vp->tolerance, vp->max_iterations, s->phys.t,
                        (unsigned long long)s->phys.step);
    return MIXSPH_OK;
}

mixsph_status integrate_initial_rates(mixsph_sim *s)
{
    const struct pair_system S = sim_pair_system(s);
    const int bad = integrate_density_rates(s, &S);
    if (bad < 0) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory in the pair loops");
    if (bad) return SIM_FAIL(s, MIXSPH_ERR_UNSTABLE, "non-finite density rates in the initial state");
    integrate_pressure_and_derived(s);
    pressures_and_regimes(s, &S, 0, 0.0);
    const int bad_a = forces_momentum(s->work.forces, &S);
    if (bad_a < 0) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory in the pair loops");
    if (bad_a) return SIM_FAIL(s, MIXSPH_ERR_UNSTABLE, "non-finite forces in the initial state");
    s->phys.dt = integrate_time_step(s);
    return MIXSPH_OK;
}

/* ---- the stages of a step, shared by both schemes ---------------------------------------- */

/* The time step about to be taken, or a failure when it collapsed. */
static mixsph_status check_time_step(mixsph_sim *s)
{
    const double dt = s->phys.dt;
    if (!(dt > 1e-14) || !isfinite(dt))
        return SIM_FAIL(s, MIXSPH_ERR_UNSTABLE, "time step collapsed to %g s at t = %.6g s (step %llu)", dt, s->phys.t,
                        (unsigned long long)s->phys.step);
    return MIXSPH_OK;
}

/* The kick and drift of move_particles over particles [b, e). With the drift, in the same loop,
 * the largest squared displacement of an active particle (walls included: they moved before)
 * since the last build and whether one left the grid, as neighbours_max_shift2 computes them (max
 * and | are exact, so any order gives the same). */
struct drift_loop {
    mixsph_sim *s;
    double dt;                /* the drift [s] */
    double half_kick;         /* the kick before it [s] (0: none) */
    const double (*o_old)[DIM]; /* the walls' displacements before they moved (walls_keep_fluid_side) */
    size_t n_active;
    long clips;               /* + particles put back on their side of a wall */
    double shift2;            /* max squared displacement since the last build [m2] */
    int outside;              /* | one left the grid */
};

static void drift_range(void *arg, size_t b, size_t e)
{
    struct drift_loop *L = arg;
    const mixsph_sim *s = L->s;
    struct particles *P = &L->s->phys.P;
    const double dt = L->dt, half_kick = L->half_kick, gap = INTEGRATE_CLIP_GAP * s->phys.dx;
    const size_t n_active = L->n_active;
    const struct cells *C = &s->work.C;
    double lo[DIM], hi[DIM];
    for (int d = 0; d < DIM; d++) {
        lo[d] = C->lo[d];
        hi[d] = cells_hi(C, d);
    }
    long clips = 0;
    double shift2 = 0.0;
    int outside = 0;
    for (size_t i = b; i < e; i++) {
        const int st = P->state[i];
        if (st != MIXSPH_STATE_WALL && st != MIXSPH_STATE_LOST) {
            const double kick = st == MIXSPH_STATE_FIXED && !held_kicked(s, i, 0) ? 0.0 : half_kick;
            double v[DIM];
            for (int d = 0; d < DIM; d++) v[d] = P->vel[d][i] + kick * P->acc[d][i];
            if (st == MIXSPH_STATE_MOBILE) { /* fixed grains are not moved */
                double x0[DIM], x1[DIM];
                for (int d = 0; d < DIM; d++) {
                    x0[d] = P->pos[d][i];
                    x1[d] = x0[d] + dt * v[d];
                }
                if (s->work.near_wall[i]) walls_keep_fluid_side(&s->phys.walls, L->o_old, gap, x0, x1, v, &clips);
                if (s->work.mirror.on) mirror_sides_reflect(&s->work.mirror, x1, v);
                for (int d = 0; d < DIM; d++) P->pos[d][i] = x1[d];
            }
            for (int d = 0; d < DIM; d++) P->vel[d][i] = P->uv[d][i] = v[d];
        }
        if (i < n_active) {
            double d2 = 0.0;
            for (int d = 0; d < DIM; d++) {
                const double dd = P->pos[d][i] - s->work.NB.pos0[d][i];
                d2 += dd * dd;
                outside |= !(P->pos[d][i] >= lo[d] && P->pos[d][i] < hi[d]);
            }
            shift2 = d2 > shift2 ? d2 : shift2;
        }
    }
    team_add_long(&L->clips, clips);
    team_max_double(&L->shift2, shift2);
    team_or_int(&L->outside, outside);
}

/* The walls move over dt (their displacements before it kept in o_old), then every
 * particle takes `half_kick` of its acceleration (the explicit scheme's first half kick; 0: none)
 * and drifts with the result (grains held fixed are not moved; walls kept uncrossed); time
 * advances; the neighbour lists are rebuilt when a particle has moved skin/2 since their build
 * or left the grid. */
static mixsph_status move_particles(mixsph_sim *s, double dt, double half_kick)
{
    struct particles *P = &s->phys.P;
    double o_old[WALLS_MAX][DIM];
    for (size_t w = 0; w < s->phys.walls.n; w++)
        for (int d = 0; d < DIM; d++) o_old[w][d] = s->phys.walls.state[w].o[d];
    walls_move(&s->phys.walls, P, s->phys.t, dt);
    struct drift_loop L = {.s = s, .dt = dt, .half_kick = half_kick, .o_old = (const double (*)[DIM])o_old,
                           .n_active = s->work.C.start[s->work.C.ncell]};
    team_for(SIM_THREADS(s), P->n, drift_range, &L);
    s->phys.n_clipped += L.clips;
    s->phys.t += dt;
    s->phys.step++;
    /* the lists hold while no particle has moved skin/2 since their build; a particle that left
     * the grid is marked lost by the rebuild at once */
    if (L.outside || 4.0 * L.shift2 >= s->work.NB.skin * s->work.NB.skin) {
        const mixsph_status st = integrate_rebuild_lists(s); /* images made afresh at their sources' state */
        if (st != MIXSPH_OK) return st;
    }
    mirror_sides_refresh(&s->work.mirror, P, SIM_THREADS(s)); /* the images at the new positions and velocities */
    return MIXSPH_OK;
}

/* Whether density rho of a particle of medium m lies beyond numerics.density_bound (docs/numerics.md
 * 2e). A medium that bounds its tension has no lower side: its density falls as its grains part. */
static inline int density_out_of_bound(const struct medium *m, double bound, double rho)
{
    if (!(bound > 0.0)) return 0;
    return !(rho <= (1.0 + bound) * m->rho0) || (medium_carries_tension(m) && !(rho >= (1.0 - bound) * m->rho0));
}

/* rho += dt drho and the equation of state. Particles whose new density is beyond the bound keep
 * the old one for this step's momentum pass and are marked for exclusion (exclude_particles). */
struct density_update_loop {
    mixsph_sim *s;
    double dt;    /* [s] */
    int bad_rho;  /* | a non-positive density */
    long beyond;  /* + particles beyond the density bound */
};

static void density_update_range(void *arg, size_t b, size_t e)
{
    struct density_update_loop *L = arg;
    mixsph_sim *s = L->s;
    struct particles *P = &s->phys.P;
    const double dt = L->dt, bound = s->scheme.density_bound;
    const double w0 = kernel_w(&s->phys.K, 0.0);
    const struct medium *media = s->scheme.media;
    int bad_rho = 0;
    long beyond = 0;
    for (size_t i = b; i < e; i++) {
        if (P->state[i] > MIXSPH_STATE_FIXED) continue;
        double rho = P->rho[i] + dt * P->drho[i];
        /* A particle's summation density sum_j m_j W_ij is at least its own m_i W(0). The continuity
         * equation has no self term and crosses that bound where the neighbours fly apart (a grain
         * thrown clear of a slide): it is the density of a particle alone (docs/numerics.md 2d).
         * Only for a medium that carries no tension, where a density below rho0 is grains parting;
         * in any other medium a density that low is a blow-up, which the step must report. */
        if (media[P->medium[i]].tension_cutoff && rho < P->m[i] * w0) rho = P->m[i] * w0;
        /* A parcel of grains in water (LAW_GRAINS_IN_WATER, docs/model.md [GW]) keeps its packing rho0
         * at least: its grains part only by water coming between them, which is the water's room,
         * not a larger parcel (whose volume m / rho would carry more of the pore pressure's push) */
        if ((media[P->medium[i]].features & LAW_GRAINS_IN_WATER) && rho < media[P->medium[i]].rho0)
            rho = media[P->medium[i]].rho0;
        if (density_out_of_bound(&media[P->medium[i]], bound, rho)) {
            s->work.excluding[i] = 1;
            beyond++;
        } else {
            P->rho[i] = rho;
        }
        bad_rho |= !(P->rho[i] > 0.0);
        particle_pressure(s, i);
    }
    team_or_int(&L->bad_rho, bad_rho);
    team_add_long(&L->beyond, beyond);
}

/* The particles marked in the density update leave the run as a lost particle does (their
 * energy counted), and the lists are rebuilt without them; past numerics.excluded_max the step
 * fails instead (docs/numerics.md 2e). */
static mixsph_status exclude_particles(mixsph_sim *s)
{
    struct particles *P = &s->phys.P;
    const double g = s->cfg.g;
    size_t last = 0;
    double last_rho = 0.0;
    for (size_t i = 0; i < P->n; i++) {
        if (!s->work.excluding[i]) continue;
        s->work.excluding[i] = 0;
        last = i;
        last_rho = P->rho[i] + s->phys.dt * P->drho[i];
        s->phys.excluded_mass += P->m[i];
        double u2 = 0.0;
        for (int d = 0; d < DIM; d++) u2 += P->vel[d][i] * P->vel[d][i];
        s->phys.excluded_energy += P->m[i] * (0.5 * u2 + g * P->pos[DIM_UP][i]);
        s->phys.n_excluded++;
        P->state[i] = MIXSPH_STATE_LOST;
        for (int d = 0; d < DIM; d++) P->vel[d][i] = P->uv[d][i] = 0.0;
    }
    if (s->phys.n_excluded > s->scheme.excluded_limit)
        return SIM_FAIL(s, MIXSPH_ERR_UNSTABLE,
                        "%ld particles excluded for a density beyond numerics.density_bound = %g of rho0, more than "
                        "numerics.excluded_max allows (%ld); the last: particle %u (x = %g, z = %g, density %g kg/m3) "
                        "at t = %.6g s",
                        s->phys.n_excluded, s->scheme.density_bound, s->scheme.excluded_limit, P->id[last],
                        P->pos[0][last], P->pos[DIM_UP][last], last_rho, s->phys.t);
    forces_forget_cache(s->work.forces); /* its factors and viscous couplings are of the old lists */
    return integrate_rebuild_lists(s);
}

/* The rates at the new positions: the density pass (and the velocity gradient), the densities
 * and the equation of state, the pressure smoothing, the material laws' updates over dt, the
 * walls' extrapolated state and the momentum pass. */
static mixsph_status new_rates(mixsph_sim *s, double dt)
{
    struct particles *P = &s->phys.P;
    const struct pair_system S = sim_pair_system(s);
    int bad_rho = integrate_density_rates(s, &S);
    if (bad_rho < 0) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory in the pair loops");
    /* the densities and the equation of state, in one loop */
    struct density_update_loop L = {.s = s, .dt = dt};
    team_for(SIM_THREADS(s), P->n, density_update_range, &L);
    bad_rho |= L.bad_rho;
    mirror_sides_refresh(&s->work.mirror, P, SIM_THREADS(s)); /* the images' densities, for the smoothing */
    if (pressures_and_regimes(s, &S, s->scheme.pressure_smoothing > 0.0, dt) != 0)
        return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory in the pair loops");
    const int bad_a = forces_momentum(s->work.forces, &S);
    if (bad_a < 0) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory in the pair loops");
    if (bad_a || bad_rho) {
        for (size_t i = 0; i < P->n; i++) {
            double sum = 0.0;
            for (int d = 0; d < DIM; d++) sum += P->acc[d][i];
            if (P->state[i] <= MIXSPH_STATE_FIXED && !(isfinite(sum + P->drho[i]) && P->rho[i] > 0.0))
                return SIM_FAIL(s, MIXSPH_ERR_UNSTABLE,
                                "non-finite acceleration or non-positive density (%g kg/m3) at particle %u (x = %g, z = %g) at t = %.6g s",
                                P->rho[i], P->id[i], P->pos[0][i], P->pos[DIM_UP][i], s->phys.t);
        }
    }
    if (L.beyond > 0) return exclude_particles(s);
    return MIXSPH_OK;
}

/* The last half kick (`last_kick`, 0 for none) and the next time step, in one loop. */
struct last_kick_loop {
    mixsph_sim *s;
    double last_kick; /* [s] */
    int implicit;     /* the time step without the viscous bound */
    double dt_min;    /* min: the next time step [s] */
};

static void last_kick_range(void *arg, size_t b, size_t e)
{
    struct last_kick_loop *L = arg;
    const mixsph_sim *s = L->s;
    struct particles *P = &L->s->phys.P;
    const double last_kick = L->last_kick;
    const int implicit = L->implicit;
    double dt_next = INFINITY;
    for (size_t i = b; i < e; i++) {
        if (P->state[i] > MIXSPH_STATE_FIXED) continue;
        if (last_kick > 0.0 && !(P->state[i] == MIXSPH_STATE_FIXED && !held_kicked(s, i, 0)))
            for (int d = 0; d < DIM; d++) P->vel[d][i] += last_kick * P->acc[d][i];
        const double d = particle_time_step(s, i, implicit);
        if (d < dt_next) dt_next = d;
    }
    team_min_double(&L->dt_min, dt_next);
}

static void last_kick_and_time_step(mixsph_sim *s, double last_kick, int implicit)
{
    struct last_kick_loop L = {.s = s, .last_kick = last_kick, .implicit = implicit, .dt_min = INFINITY};
    team_for(SIM_THREADS(s), s->phys.P.n, last_kick_range, &L);
    s->phys.dt = L.dt_min;
}

/* ---- the two schemes ------------------------------------------------------------------------ */

/* The explicit scheme: kick-drift-kick leapfrog (velocity Verlet), the viscous term in the
 * momentum pass and its bound in the time step. */
static mixsph_status explicit_step(mixsph_sim *s)
{
    mixsph_status st = check_time_step(s);
    if (st != MIXSPH_OK) return st;
    const double dt = s->phys.dt;
    if ((st = move_particles(s, dt, 0.5 * dt)) != MIXSPH_OK) return st; /* v^{n+1/2}, x^{n+1} */
    if ((st = new_rates(s, dt)) != MIXSPH_OK) return st;                /* rho^{n+1}, a^{n+1} */
    last_kick_and_time_step(s, 0.5 * dt, 0);                            /* v^{n+1} */
    return MIXSPH_OK;
}

/* The implicit scheme: symplectic Euler around the implicit viscous step. The velocities take
 * the whole step's kick of the other forces, then the viscous step (held grains judged as the
 * explicit scheme would, with numerics.held_grains = "rigid"), and the particles drift with the
 * result; no viscous bound on the time step. */
static mixsph_status implicit_step(mixsph_sim *s)
{
    mixsph_status st = check_time_step(s);
    if (st != MIXSPH_OK) return st;
    const double dt = s->phys.dt;
    /* from the state before the kick, as the explicit scheme's step would be; 0: none held */
    const double judge_dt = s->scheme.held_grains_rigid && s->phys.n_fixed > 0 ? held_grain_judge_dt(s, dt) : 0.0;
    kick_velocities(s, dt);
    if ((st = implicit_viscous_step(s, dt, judge_dt)) != MIXSPH_OK) return st;
    if ((st = move_particles(s, dt, 0.0)) != MIXSPH_OK) return st;
    if ((st = new_rates(s, dt)) != MIXSPH_OK) return st;
    last_kick_and_time_step(s, 0.0, 1);
    return MIXSPH_OK;
}

mixsph_status integrate_step(mixsph_sim *s)
{
    return s->scheme.implicit ? implicit_step(s) : explicit_step(s);
}
