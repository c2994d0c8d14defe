/* clock.h - the monotonic wall clock the library times its own work with (outputs, solves). */
#ifndef MIXSPH_CLOCK_H
#define MIXSPH_CLOCK_H
#include <time.h>

/** Monotonic wall clock [s]. */
static inline double clock_monotonic_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

#endif
