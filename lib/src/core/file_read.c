/* file_read.c - see file_read.h. */
#include "file_read.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "status.h"

mixsph_status file_read_all(const char *path, size_t max_bytes, char **data, size_t *len, char *err,
                            size_t err_len)
{
    *data = NULL;
    *len = 0;
    FILE *f = fopen(path, "rb");
    if (!f) return status_set(err, err_len, MIXSPH_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    /* never more than max_bytes + 1 bytes: the one beyond the limit tells a file that passes it */
    const size_t limit = max_bytes < SIZE_MAX - 1 ? max_bytes + 1 : max_bytes;
    size_t cap = limit < ((size_t)1 << 16) ? limit : (size_t)1 << 16, n = 0;
    char *buf = malloc(cap + 1);
    if (!buf) {
        fclose(f);
        return status_set(err, err_len, MIXSPH_ERR_NOMEM, "%s: out of memory", path);
    }
    for (;;) {
        n += fread(buf + n, 1, cap - n, f);
        if (n < cap || cap == limit) break; /* the end of the file, an error, or the limit reached */
        const size_t grown = cap > limit / 2 ? limit : 2 * cap;
        char *more = realloc(buf, grown + 1);
        if (!more) {
            free(buf);
            fclose(f);
            return status_set(err, err_len, MIXSPH_ERR_NOMEM, "%s: out of memory after %zu bytes", path, n);
        }
        buf = more;
        cap = grown;
    }
    const int failed = ferror(f);
    fclose(f);
    if (failed || n > max_bytes) {
        free(buf);
        return failed ? status_set(err, err_len, MIXSPH_ERR_IO, "%s: read error after %zu bytes", path, n)
                      : status_set(err, err_len, MIXSPH_ERR_IO, "%s: larger than the limit of %zu bytes", path,
                                   max_bytes);
    }
    buf[n] = '\0';
    *data = buf;
    *len = n;
    return MIXSPH_OK;
}
