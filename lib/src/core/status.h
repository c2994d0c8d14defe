/* status.h - error reporting helpers shared by the library modules.
 * Messages are kept in caller-owned buffers (the simulation's, or one given to create):
 * the library never prints. */
#ifndef MIXSPH_STATUS_H
#define MIXSPH_STATUS_H
#include <stddef.h>
#include "mixsph.h"

#if defined(__MINGW32__) /* the FMU's win64 binary: mingw's C99 printf (__USE_MINGW_ANSI_STDIO) */
#define MIXSPH_PRINTF(a, b) __attribute__((format(gnu_printf, a, b)))
#elif defined(__GNUC__)
#define MIXSPH_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define MIXSPH_PRINTF(a, b)
#endif

/** Format a message into err (if non-NULL) and return st. */
mixsph_status status_set(char *err, size_t err_len, mixsph_status st, const char *fmt, ...)
    MIXSPH_PRINTF(4, 5);

#endif
