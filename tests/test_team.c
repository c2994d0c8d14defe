/* test_team.c - the library's worker threads (core/team.h): every thread of a region runs once,
 * a barrier separates what is written before it from what is read after it, the shared counter
 * hands out each item once, the reductions are exact, a parallel call from inside a region runs
 * on the calling thread alone, and two host threads drive teams of their own at the same time. */
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "team.h"

#define ITEMS 10007
#define ROUNDS 200

struct region_arg {
    int ran[8];      /* times each tid ran */
    int n_seen[8];   /* the n each tid was given */
    long slots[8];   /* phase 1 writes its tid's slot, phase 2 reads every slot */
    long sums[8];
    team_counter next;
    unsigned char *taken; /* ITEMS: times each item was taken */
    double dmin, dmax;
    int bits;
    long total;
    int nested_n;    /* the n a nested team_run gave */
    int stale;       /* reads after a barrier that missed a write before it */
};

static void nested_fn(void *arg, int tid, int n)
{
    (void)tid;
    ((struct region_arg *)arg)->nested_n = n;
}

static void region(void *arg, int tid, int n)
{
    struct region_arg *A = arg;
    A->ran[tid]++;
    A->n_seen[tid] = n;
    for (int round = 0; round < ROUNDS; round++) {
        A->slots[tid] = (long)round * 100 + tid;
        team_barrier();
        long s = 0;
        for (int t = 0; t < n; t++) s += A->slots[t];
        A->sums[tid] = s; /* every thread must see every slot of this round */
        if (s != (long)round * 100 * n + (long)n * (n - 1) / 2) team_or_int(&A->stale, 1);
        team_barrier();
    }
    for (long k; (k = team_next(&A->next)) < ITEMS;) A->taken[k]++;
    team_min_double(&A->dmin, -(double)tid - 0.5);
    team_max_double(&A->dmax, (double)tid + 0.25);
    team_or_int(&A->bits, 1 << tid);
    team_add_long(&A->total, 1000 + tid);
    if (tid == n - 1) team_run(2, nested_fn, A);
}

/* 1 when a region of n_threads behaves as team.h says (no cmocka assertion: host threads call it). */
static int region_ok(int n_threads)
{
    struct region_arg A;
    memset(&A, 0, sizeof A);
    A.taken = calloc(ITEMS, 1);
    assert_non_null(A.taken);
    A.dmin = 0.0;
    A.dmax = 0.0;
    team_counter_reset(&A.next);
    team_run(n_threads, region, &A);
    const int n = n_threads < 1 ? 1 : n_threads;
    int ok = !A.stale;
    for (int t = 0; t < 8; t++) ok &= A.ran[t] == (t < n ? 1 : 0) && (t >= n || A.n_seen[t] == n);
    for (long k = 0; k < ITEMS; k++) ok &= A.taken[k] == 1;
    ok &= A.dmin == -(double)(n - 1) - 0.5 && A.dmax == (double)(n - 1) + 0.25;
    ok &= A.bits == (1 << n) - 1 && A.total == 1000L * n + (long)n * (n - 1) / 2 && A.nested_n == 1;
    free(A.taken);
    return ok;
}

static void test_regions(void **state)
{
    (void)state;
    for (int n = 0; n <= 5; n++) assert_true(region_ok(n));
    assert_true(region_ok(2)); /* the team is reused */
}

struct range_arg {
    unsigned char *hit;
};

static void mark(void *arg, size_t b, size_t e)
{
    struct range_arg *A = arg;
    for (size_t i = b; i < e; i++) A->hit[i]++;
}

/* loop (team_for or team_for_dynamic) on th threads hits each of n items once and nothing past them. */
static void assert_each_item_once(void (*loop)(int, size_t, team_range_fn, void *), int th, size_t n)
{
    struct range_arg A = {calloc(n + 1, 1)};
    assert_non_null(A.hit);
    loop(th, n, mark, &A);
    for (size_t i = 0; i < n; i++) assert_int_equal(A.hit[i], 1);
    assert_int_equal(A.hit[n], 0);
    free(A.hit);
}

/* team_share and team_for cover every item once, for counts below and above the thread count. */
static void test_for(void **state)
{
    (void)state;
    static const size_t counts[] = {0, 1, 2, 3, 7, 1000, 1001};
    for (size_t c = 0; c < sizeof counts / sizeof counts[0]; c++)
        for (int th = 1; th <= 4; th++) {
            const size_t n = counts[c];
            assert_each_item_once(team_for, th, n);
            size_t prev = 0;
            for (int t = 0; t < th; t++) {
                size_t b, e;
                team_share(n, t, th, &b, &e);
                assert_int_equal(b, prev);
                assert_true(e >= b && e - b <= n / (size_t)th + 1);
                prev = e;
            }
            assert_int_equal(prev, n);
        }
}

/* team_for_dynamic covers every item once and no more, for counts around its smallest chunk and
 * for many chunks per thread. */
static void test_for_dynamic(void **state)
{
    (void)state;
    static const size_t counts[] = {0, 1, TEAM_CHUNK_MIN, TEAM_CHUNK_MIN + 1, 5000, 100003};
    for (size_t c = 0; c < sizeof counts / sizeof counts[0]; c++)
        for (int th = 1; th <= 4; th++) {
            assert_each_item_once(team_for_dynamic, th, counts[c]);
        }
}

static void *host_thread(void *arg)
{
    int *ok = arg;
    for (int k = 0; k < 20; k++) *ok &= region_ok(2);
    return NULL;
}

/* Two host threads, each with its own team, at the same time. */
static void test_two_hosts(void **state)
{
    (void)state;
    pthread_t a, b;
    int ok_a = 1, ok_b = 1;
    assert_int_equal(pthread_create(&a, NULL, host_thread, &ok_a), 0);
    assert_int_equal(pthread_create(&b, NULL, host_thread, &ok_b), 0);
    pthread_join(a, NULL);
    pthread_join(b, NULL);
    assert_true(ok_a && ok_b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_regions), cmocka_unit_test(test_for),
                                       cmocka_unit_test(test_for_dynamic),
                                       cmocka_unit_test(test_two_hosts)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
