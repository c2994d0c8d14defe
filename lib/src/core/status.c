/* status.c - status strings (from the one list in mixsph.h) and message formatting. */
#include "status.h"

#include <stdarg.h>
#include <stdio.h>

const char *mixsph_status_string(mixsph_status st)
{
    switch (st) {
#define MIXSPH_X_CASE(name, text) \
    case name:                    \
        return text;
        MIXSPH_STATUS_LIST(MIXSPH_X_CASE)
#undef MIXSPH_X_CASE
    }
    return "unknown status";
}

mixsph_status status_set(char *err, size_t err_len, mixsph_status st, const char *fmt, ...)
{
    if (err && err_len > 0) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, err_len, fmt, ap);
        va_end(ap);
    }
    return st;
}
