/* team.c - the library's worker threads (team.h): POSIX threads, waits that spin for at most
 * TEAM_SPIN_US and then sleep on the team's condition variable.
 *
 * A team: n_workers threads (tid 1 .. n_workers) besides the thread that owns it (tid 0). Three
 * counters, each advanced by one thread and waited on by others:
 *   work  - advanced by the owner when it hands out a region (fn, arg, n);
 *   done  - workers that have not yet finished the region, or seen that it is not theirs (the
 *           owner waits for 0 before it writes the next region);
 *   cycle - advanced by the last thread to reach a barrier.
 * A waiter spins on its counter and then sleeps under the mutex after counting itself in
 * `sleepers`; a thread that advances a counter wakes the sleepers if there are any. All counter and
 * sleeper accesses are sequentially consistent, so a waiter either sees the new value or is seen
 * as a sleeper (and then waits under the mutex, which the waker takes before broadcasting). */
#include "team.h"

#include <pthread.h>
#include <stdlib.h>
#include <time.h>

#if defined(__x86_64__) || defined(__i386__)
#define TEAM_PAUSE() __builtin_ia32_pause()
#else
#define TEAM_PAUSE() ((void)0)
#endif

#define SC __ATOMIC_SEQ_CST

/* How long a waiting thread spins before it sleeps [microseconds]: chosen by measurement
 * (docs/performance.md, "Two threads"); a define so that a benchmark build can set another. */
#ifndef TEAM_SPIN_US
#define TEAM_SPIN_US 100
#endif

struct team {
    pthread_mutex_t mu;
    pthread_cond_t cv;
    int sleepers;
    int n_workers;          /* started */
    pthread_t thread[TEAM_MAX_THREADS];
    /* the region */
    team_fn fn;
    void *arg;
    int n;                  /* threads of the region, the owner included */
    int stop;               /* the owner has exited: workers return */
    unsigned work;          /* regions handed out */
    int done;               /* workers that have not finished the region yet */
    /* the barrier */
    int arrived;
    unsigned cycle;
};

struct worker_arg {
    struct team *T;
    int tid;
    unsigned work; /* the regions handed out before it started */
};

/* The team a thread belongs to while it runs a region of more than one thread (workers: theirs;
 * the owner: its own, during team_run); NULL outside them. */
static _Thread_local struct team *current;
/* Regions the thread is running (a region of one thread included): nested calls run alone. */
static _Thread_local int depth;
/* The team the calling thread owns. */
static _Thread_local struct team *owned;

static double now_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e6 + (double)ts.tv_nsec * 1e-3;
}

static unsigned load_u(const unsigned *w) { return __atomic_load_n(w, SC); }

/* Wait until *w != old: spin up to TEAM_SPIN_US, then sleep. */
static void wait_change(struct team *T, const unsigned *w, unsigned old)
{
    double t_end = -1.0;
    for (unsigned k = 1;; k++) {
        if (load_u(w) != old) return;
        TEAM_PAUSE();
        if ((k & 63) == 0) { /* read the clock now and then: it costs more than a pause */
            const double t = now_us();
            if (t_end < 0.0) t_end = t + TEAM_SPIN_US;
            else if (t >= t_end) break;
        }
    }
    pthread_mutex_lock(&T->mu);
    __atomic_add_fetch(&T->sleepers, 1, SC);
    while (load_u(w) == old) pthread_cond_wait(&T->cv, &T->mu);
    __atomic_sub_fetch(&T->sleepers, 1, SC);
    pthread_mutex_unlock(&T->mu);
}

/* Wake the sleepers after a counter changed. */
static void wake(struct team *T)
{
    if (__atomic_load_n(&T->sleepers, SC) == 0) return;
    pthread_mutex_lock(&T->mu);
    pthread_cond_broadcast(&T->cv);
    pthread_mutex_unlock(&T->mu);
}

/* `done` counts down to 0; the owner waits on it as on a counter that changes to 0. */
static void wait_done(struct team *T)
{
    double t_end = -1.0;
    for (unsigned k = 1;; k++) {
        if (__atomic_load_n(&T->done, SC) == 0) return;
        TEAM_PAUSE();
        if ((k & 63) == 0) {
            const double t = now_us();
            if (t_end < 0.0) t_end = t + TEAM_SPIN_US;
            else if (t >= t_end) break;
        }
    }
    pthread_mutex_lock(&T->mu);
    __atomic_add_fetch(&T->sleepers, 1, SC);
    while (__atomic_load_n(&T->done, SC) != 0) pthread_cond_wait(&T->cv, &T->mu);
    __atomic_sub_fetch(&T->sleepers, 1, SC);
    pthread_mutex_unlock(&T->mu);
}

static void *worker_main(void *p)
{
    struct worker_arg wa = *(struct worker_arg *)p;
    free(p);
    struct team *T = wa.T;
    unsigned seen = wa.work;
    for (;;) {
        wait_change(T, &T->work, seen);
        seen++; /* the owner hands out the next region only after every worker is done */
        if (__atomic_load_n(&T->stop, SC)) return NULL;
        if (wa.tid < T->n) {
            current = T;
            depth = 1;
            T->fn(T->arg, wa.tid, T->n);
            depth = 0;
            current = NULL;
        }
        if (__atomic_sub_fetch(&T->done, 1, SC) == 0) wake(T);
    }
    return NULL;
}

/* When a thread that owns a team exits, its workers return and the team is freed. */
static pthread_key_t owner_key;
static int owner_key_ok;
static pthread_once_t owner_key_once = PTHREAD_ONCE_INIT;

static void team_free(void *p)
{
    struct team *T = p;
    __atomic_store_n(&T->stop, 1, SC);
    __atomic_add_fetch(&T->work, 1, SC);
    pthread_mutex_lock(&T->mu);
    pthread_cond_broadcast(&T->cv);
    pthread_mutex_unlock(&T->mu);
    for (int k = 0; k < T->n_workers; k++) pthread_join(T->thread[k], NULL);
    pthread_cond_destroy(&T->cv);
    pthread_mutex_destroy(&T->mu);
    free(T);
}

static void owner_key_create(void) { owner_key_ok = pthread_key_create(&owner_key, team_free) == 0; }

/* The calling thread's team with at least `want` workers started (fewer if threads cannot be
 * started), or NULL. */
static struct team *own_team(int want)
{
    struct team *T = owned;
    if (!T) {
        pthread_once(&owner_key_once, owner_key_create);
        if (!owner_key_ok) return NULL;
        T = calloc(1, sizeof *T);
        if (!T) return NULL;
        if (pthread_mutex_init(&T->mu, NULL) != 0) {
            free(T);
            return NULL;
        }
        if (pthread_cond_init(&T->cv, NULL) != 0) {
            pthread_mutex_destroy(&T->mu);
            free(T);
            return NULL;
        }
        if (pthread_setspecific(owner_key, T) != 0) {
            pthread_cond_destroy(&T->cv);
            pthread_mutex_destroy(&T->mu);
            free(T);
            return NULL;
        }
        owned = T;
    }
    while (T->n_workers < want) {
        struct worker_arg *wa = malloc(sizeof *wa);
        if (!wa) break;
        wa->T = T;
        wa->tid = T->n_workers + 1;
        wa->work = T->work;
        if (pthread_create(&T->thread[T->n_workers], NULL, worker_main, wa) != 0) {
            free(wa);
            break;
        }
        T->n_workers++;
    }
    return T;
}

void team_run(int n, team_fn fn, void *arg)
{
    if (n > TEAM_MAX_THREADS) n = TEAM_MAX_THREADS;
    struct team *T = n > 1 && depth == 0 ? own_team(n - 1) : NULL;
    if (T && T->n_workers + 1 < n) n = T->n_workers + 1;
    if (!T || n <= 1) {
        struct team *outer = current;
        current = NULL; /* a barrier inside waits for no one */
        depth++;
        fn(arg, 0, 1);
        depth--;
        current = outer;
        return;
    }
    T->fn = fn;
    T->arg = arg;
    T->n = n;
    T->arrived = 0;
    __atomic_store_n(&T->done, T->n_workers, SC); /* workers beyond n see it too and skip it */
    __atomic_add_fetch(&T->work, 1, SC);
    wake(T);
    current = T;
    depth = 1;
    fn(arg, 0, n);
    depth = 0;
    wait_done(T);
    current = NULL;
}

void team_barrier(void)
{
    struct team *T = current;
    if (!T || T->n <= 1) return;
    const unsigned c = load_u(&T->cycle);
    if (__atomic_add_fetch(&T->arrived, 1, SC) == T->n) {
        __atomic_store_n(&T->arrived, 0, SC);
        __atomic_add_fetch(&T->cycle, 1, SC);
        wake(T);
    } else {
        wait_change(T, &T->cycle, c);
    }
}

void team_counter_reset(team_counter *c) { __atomic_store_n(&c->next, 0, SC); }

long team_next(team_counter *c) { return __atomic_fetch_add(&c->next, 1, SC); }

void team_min_double(double *target, double v)
{
    double cur;
    __atomic_load(target, &cur, SC);
    while (v < cur && !__atomic_compare_exchange(target, &cur, &v, 0, SC, SC)) {
    }
}

void team_max_double(double *target, double v)
{
    double cur;
    __atomic_load(target, &cur, SC);
    while (v > cur && !__atomic_compare_exchange(target, &cur, &v, 0, SC, SC)) {
    }
}

void team_or_int(int *target, int v)
{
    if (v) __atomic_fetch_or(target, v, SC);
}

void team_add_long(long *target, long v)
{
    if (v) __atomic_fetch_add(target, v, SC);
}

struct for_arg {
    team_range_fn body;
    void *arg;
    size_t n;
};

static void for_region(void *arg, int tid, int nth)
{
    const struct for_arg *A = arg;
    size_t b, e;
    team_share(A->n, tid, nth, &b, &e);
    if (b < e) A->body(A->arg, b, e);
}

void team_for(int n_threads, size_t n, team_range_fn body, void *arg)
{
    struct for_arg A = {body, arg, n};
    if (n_threads > 1 && n < (size_t)n_threads) n_threads = n > 0 ? (int)n : 1;
    team_run(n_threads, for_region, &A);
}
