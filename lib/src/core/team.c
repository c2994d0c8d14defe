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

/* What a thread is doing with teams, kept under a key (not in C11 _Thread_local variables: in
 * the FMU's shared object those would need the dynamic loader's __tls_get_addr, one more library
 * its binary needs): the team it owns, the team whose region it runs (a worker's, or its own
 * during team_run; NULL outside regions of more than one thread) and the regions it is in (a
 * region of one thread included: nested calls run alone). An owner's state is allocated and
 * freed, with its team, when the thread exits; a worker's is on its stack. */
struct thread_state {
    struct team *owned;
    struct team *current;
    int depth;
    int on_heap;
};

/* The one process-wide item: the key under which each host thread finds its own state, created
 * once (pthread_once) and never changed; two simulations (or FMU instances) share the key, not a
 * team: a team belongs to the thread that steps them, and they step one at a time on it. */
static pthread_key_t state_key;
static int state_key_ok;
static pthread_once_t state_key_once = PTHREAD_ONCE_INIT;

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
    struct thread_state st = {0};
    pthread_setspecific(state_key, &st); /* the key exists: the owner made it before its team */
    for (;;) {
        wait_change(T, &T->work, seen);
        seen++; /* the owner hands out the next region only after every worker is done */
        if (__atomic_load_n(&T->stop, SC)) return NULL;
        if (wa.tid < T->n) {
            st.current = T;
            st.depth = 1;
            T->fn(T->arg, wa.tid, T->n);
            st.depth = 0;
            st.current = NULL;
        }
        if (__atomic_sub_fetch(&T->done, 1, SC) == 0) wake(T);
    }
    return NULL;
}

/* When a thread that owns a team exits, its workers return and the team is freed. */
static void team_free(struct team *T)
{
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

static void state_free(void *p)
{
    struct thread_state *st = p;
    if (!st->on_heap) return;
    if (st->owned) team_free(st->owned);
    free(st);
}

static void state_key_create(void) { state_key_ok = pthread_key_create(&state_key, state_free) == 0; }

/* The calling thread's state, made at its first call; NULL when it cannot be. */
static struct thread_state *thread_state(void)
{
    pthread_once(&state_key_once, state_key_create);
    if (!state_key_ok) return NULL;
    struct thread_state *st = pthread_getspecific(state_key);
    if (!st) {
        st = calloc(1, sizeof *st);
        if (!st) return NULL;
        st->on_heap = 1;
        if (pthread_setspecific(state_key, st) != 0) {
            free(st);
            return NULL;
        }
    }
    return st;
}

/* The calling thread's team with at least `want` workers started (fewer if threads cannot be
 * started), or NULL. */
static struct team *own_team(struct thread_state *st, int want)
{
    struct team *T = st->owned;
    if (!T) {
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
        st->owned = T;
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
    struct thread_state *st = thread_state();
    if (!st) { /* no state, no team */
        fn(arg, 0, 1);
        return;
    }
    struct team *T = n > 1 && st->depth == 0 ? own_team(st, n - 1) : NULL;
    if (T && T->n_workers + 1 < n) n = T->n_workers + 1;
    if (!T || n <= 1) {
        struct team *outer = st->current;
        st->current = NULL; /* a barrier inside waits for no one */
        st->depth++;
        fn(arg, 0, 1);
        st->depth--;
        st->current = outer;
        return;
    }
    T->fn = fn;
    T->arg = arg;
    T->n = n;
    T->arrived = 0;
    __atomic_store_n(&T->done, T->n_workers, SC); /* workers beyond n see it too and skip it */
    __atomic_add_fetch(&T->work, 1, SC);
    wake(T);
    st->current = T;
    st->depth = 1;
    fn(arg, 0, n);
    st->depth = 0;
    wait_done(T);
    st->current = NULL;
}

void team_barrier(void)
{
    const struct thread_state *st = state_key_ok ? pthread_getspecific(state_key) : NULL;
    struct team *T = st ? st->current : NULL;
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

struct for_dynamic_arg {
    team_range_fn body;
    void *arg;
    size_t n, chunk;
    team_counter next;
};

static void for_dynamic_region(void *arg, int tid, int nth)
{
    (void)tid;
    (void)nth;
    struct for_dynamic_arg *A = arg;
    for (long k; (size_t)(k = team_next(&A->next)) < (A->n + A->chunk - 1) / A->chunk;) {
        const size_t b = (size_t)k * A->chunk, e = b + A->chunk < A->n ? b + A->chunk : A->n;
        A->body(A->arg, b, e);
    }
}

void team_for_dynamic(int n_threads, size_t n, team_range_fn body, void *arg)
{
    if (n_threads <= 1 || n <= TEAM_CHUNK_MIN) {
        if (n > 0) body(arg, 0, n);
        return;
    }
    struct for_dynamic_arg A = {body, arg, n, n / ((size_t)n_threads * TEAM_CHUNKS_PER_THREAD), {0}};
    if (A.chunk < TEAM_CHUNK_MIN) A.chunk = TEAM_CHUNK_MIN;
    team_counter_reset(&A.next);
    team_run(n_threads, for_dynamic_region, &A);
}
