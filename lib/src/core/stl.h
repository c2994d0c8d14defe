/* stl.h - STL files (ASCII and binary) to and from triangle meshes (mesh.h).
 *
 * Reading: the format is told from the content, not the name or the first word: a file is ASCII
 * when it starts with "solid" and holds no NUL byte; otherwise binary, whose size must be exactly
 * 84 + 50 n bytes for the n triangles its header declares (binary files whose 80-byte header
 * starts with "solid", as several CAD exporters write, are read as binary: their triangle count
 * or coordinates always bring NUL bytes). A triangle's normal is taken from its vertex order
 * (right-hand rule), the file's normal is ignored: STL writers often leave it zero or stale, and
 * the standard makes the two agree. Vertices at exactly the same coordinates are merged (a hash
 * of their bits), so that a closed STL body is closed by its indices (mesh_check_closed).
 * Triangles of zero area (slivers some exporters leave) are dropped and counted.
 *
 * Errors name the file, the line (ASCII) or the triangle (binary) and what is wrong: truncated,
 * non-finite coordinate, a keyword other than the grammar's, no triangles, more triangles than
 * STL_MAX_TRIANGLES. */
#ifndef MIXSPH_STL_H
#define MIXSPH_STL_H
#include <stddef.h>

#include "mesh.h"
#include "mixsph.h"

/* The most triangles read from one file (a binary file of this many is 1.6 GB): a bound against
 * a corrupt count or a wrong file, far above a case's mesh. */
#define STL_MAX_TRIANGLES ((size_t)1 << 25)

struct stl_read_report {
    int binary;                /* the format found */
    size_t triangles;          /* triangles in the file */
    size_t degenerate_dropped; /* of which had no area and were dropped */
};

/** Append the triangles of the STL file at `path` to m; report (may be NULL) receives what was
 *  found. On failure m keeps what it held before plus possibly part of the file: free it. */
mixsph_status stl_read(const char *path, struct mesh *m, struct stl_read_report *report, char *err, size_t err_len);

/** Write m as an STL file: binary (little-endian float32 coordinates and normals) or ASCII
 *  (coordinates with 17 significant digits, so that reading it back gives the same doubles).
 *  `name` is the ASCII solid's name or the start of the binary header. */
mixsph_status stl_write(const char *path, const struct mesh *m, int binary, const char *name, char *err,
                        size_t err_len);

#endif
