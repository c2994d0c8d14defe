/* team.h - the library's own worker threads: fork-join parallel loops whose waiting the library
 * controls, whatever the host's environment.
 *
 * Why not OpenMP's: a waiting thread of GNU OpenMP spins for a count read from OMP_WAIT_POLICY /
 * GOMP_SPINCOUNT once, when libgomp loads (about 3 ms by default), so a host that cannot set the
 * environment (the FMU, a Dask worker) gets that policy, and under load a spinning waiter keeps a
 * core busy that the thread it waits for could run on (docs/performance.md, "Two threads").
 * Here a waiting thread spins for at most TEAM_SPIN_US (team.c: 100) microseconds and then
 * sleeps on a condition variable; the steps' barriers come every 50-200 microseconds on an idle machine, so
 * a waiter rarely sleeps there, and under load it gives its core up within that time.
 *
 * Each calling thread has its own team (created at its first parallel call with more than one
 * thread and kept, like OpenMP's), so simulations stepped from different host threads do not
 * share workers. A parallel call from inside a team's function runs on the calling thread alone.
 *
 * Work division: team_share gives each thread one contiguous block (OpenMP's schedule(static));
 * team_next hands out items one at a time (schedule(dynamic, 1)). Neither decides any result:
 * the callers' loops write per-item results, and their reductions are exact (min, max, |,
 * integer +) or combined in a fixed order by the caller. */
#ifndef MIXSPH_TEAM_H
#define MIXSPH_TEAM_H

#include <stddef.h>

/* The most threads of a team (mixsph_sim_set_threads accepts up to 1024; more run as this many). */
#define TEAM_MAX_THREADS 256

/* The body of a parallel region, run once by each of n threads, tid = 0 .. n - 1 (0: the caller). */
typedef void (*team_fn)(void *arg, int tid, int n);

/* Run fn(arg, tid, n) on n threads of the calling thread's team and return when all have
 * returned; n <= 1, or a call from inside a team's function, runs fn(arg, 0, 1) on the caller.
 * When threads cannot be started, the call runs with as many as there are (at least the caller). */
void team_run(int n, team_fn fn, void *arg);

/* A loop over n items split into the threads' blocks (team_share): body(arg, begin, end) once per
 * thread, in a region of n_threads; reductions go through the team_* combinations below. */
typedef void (*team_range_fn)(void *arg, size_t begin, size_t end);
void team_for(int n_threads, size_t n, team_range_fn body, void *arg);

/* As team_for, but the items in about TEAM_CHUNKS_PER_THREAD chunks per thread (at least
 * TEAM_CHUNK_MIN items each) that the threads take one at a time: body(arg, begin, end) once per
 * chunk, so the body must not depend on how the items are grouped (per-item results, exact
 * reductions). For loops whose items cost unevenly along the index (the neighbour lists' builds:
 * particles sorted by cell, the fluid in the lower layers), where team_for's equal blocks leave
 * one thread waiting for the other. One thread: body(arg, 0, n). */
#define TEAM_CHUNKS_PER_THREAD 16
#define TEAM_CHUNK_MIN 256
void team_for_dynamic(int n_threads, size_t n, team_range_fn body, void *arg);

/* Inside fn of team_run: return when all n threads of the team have called it. */
void team_barrier(void);

/* Thread tid's block [*begin, *end) of n items split among nth threads. */
static inline void team_share(size_t n, int tid, int nth, size_t *begin, size_t *end)
{
    const size_t q = n / (size_t)nth, r = n % (size_t)nth, t = (size_t)tid;
    *begin = t * q + (t < r ? t : r);
    *end = *begin + q + (t < r ? 1 : 0);
}

/* Inside fn of team_run: a counter the team's threads take items from, item = team_next(&c),
 * until it returns a value >= the count; reset with team_counter_reset before the region (or by
 * one thread before a team_barrier). */
typedef struct {
    _Alignas(64) long next;
} team_counter;
void team_counter_reset(team_counter *c);
long team_next(team_counter *c);

/* Exact combinations of the threads' partial results, for reductions inside a region. */
void team_min_double(double *target, double v);
void team_max_double(double *target, double v);
void team_or_int(int *target, int v);
void team_add_long(long *target, long v);

#endif
