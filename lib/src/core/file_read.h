/* file_read.h - a whole input file in memory, bounded: the geometry readers (STL, ESRI grids)
 * parse from a buffer, so that they can look at a file's size and first bytes before choosing
 * a format, and name the line of an error. */
#ifndef MIXSPH_FILE_READ_H
#define MIXSPH_FILE_READ_H
#include <stddef.h>

#include "mixsph.h"

/** Read the file at `path` into *data (malloc'd, NUL-terminated beyond *len bytes). A file of
 *  more than max_bytes is refused (MIXSPH_ERR_IO, naming the limit) after reading max_bytes + 1
 *  of it, so that a wrong path to a huge file costs no more memory than the limit. The file is read in growing chunks rather
 *  than sized with fseek/ftell, whose long offset is 32-bit on win64 (the FMU's build). */
mixsph_status file_read_all(const char *path, size_t max_bytes, char **data, size_t *len, char *err,
                            size_t err_len);

#endif
