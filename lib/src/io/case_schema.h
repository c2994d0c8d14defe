/* case_schema.h - the sections of a case file (rows: core/schema.h; a medium's section is its
 * material law's, laws/law.h) and the table-driven reading of one JSON object. The same tables generate the key tables of docs/cases.md (tests/case_docs.c), so
 * the document cannot drift from the reader. Rules between keys (one of K and c, t/vx/vz of
 * equal length, a saturated medium's pore fluid, ...) are code in case.c. */
#ifndef MIXSPH_CASE_SCHEMA_H
#define MIXSPH_CASE_SCHEMA_H
#include <stddef.h>

#include "geometry.h"
#include "mixsph.h"
#include "schema.h"

struct cJSON;

/* Where messages go: "<origin>: <key path>: <what was expected>". */
struct case_reader {
    const char *origin;
    char *err;
    size_t err_len;
};

/** The sections of a case file, in the order of docs/cases.md; NULL after the last. */
const struct case_section *case_schema_section(size_t k);
/** The section with this id, NULL if none. */
const struct case_section *case_schema_find(const char *id);
/** The entry of `key` in a section, NULL if none. */
const struct case_key *case_schema_key(const struct case_section *s, const char *key);

/** Read the object `obj` at key path `path` by the section's table into the struct at `base`:
 * refuse unknown keys, keys of other variants and refused keys, check each key's presence,
 * type and range, store it in its field or write its default. `variant` is the bit of the
 * object's variant (0 for a section without variants). */
mixsph_status case_schema_read(const struct case_reader *r, const struct cJSON *obj, const char *path,
                               const struct case_section *s, unsigned variant, void *base);

/** Check (and store, if `base` is not NULL and it has a field) one key of a section. */
mixsph_status case_schema_read_key(const struct case_reader *r, const struct cJSON *obj, const char *path,
                                   const struct case_key *k, void *base);

/** The value stored in the field of a number, integer, boolean or choice key of the struct at
 *  `base` (a choice: its value). -1 when the key has no such field, 0 otherwise. */
int case_schema_stored_number(const struct case_key *k, const void *base, double *value);

/** An array of n >= min_n finite numbers (caller frees *out). */
mixsph_status case_schema_numbers(const struct case_reader *r, const struct cJSON *obj, const char *path,
                                  const char *key, size_t min_n, double **out, size_t *n);

/** An array of n >= min_n [x, z] points, no point repeating the previous one. */
mixsph_status case_schema_points(const struct case_reader *r, const struct cJSON *obj, const char *path,
                                 const char *key, size_t min_n, struct polyline *pl);

/** The range of a key as text: "0 < x <= 10", or for the document (unicode) markdown "0 < x ≤ 10"
 * ("" if none). */
void case_schema_range_text(const struct case_key *k, int unicode, char *buf, size_t len);
/** The default of a key as markdown for the document ("" if none). */
void case_schema_default_text(const struct case_key *k, char *buf, size_t len);
/** A number as short text: %g with "1e+09" written "1e9". */
void case_schema_number_text(double v, char *buf, size_t len);

#endif
