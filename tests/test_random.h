/* test_random.h - splitmix64: a fixed, portable random sequence for the tests' random particle
 * sets (the same numbers on every platform and compiler). */
#ifndef MIXSPH_TEST_RANDOM_H
#define MIXSPH_TEST_RANDOM_H
#include <stdint.h>

static inline uint64_t test_random_next(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Uniform in [a, b) from the top 53 bits. */
static inline double test_random_uniform(uint64_t *s, double a, double b)
{
    return a + (b - a) * (double)(test_random_next(s) >> 11) * (1.0 / 9007199254740992.0);
}

#endif
