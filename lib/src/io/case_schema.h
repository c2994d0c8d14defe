/* case_schema.h - the keys of a case file: one table per section ({key, type, range, default,
 * unit, meaning} and the field of struct case_def it fills), and the table-driven reading of one
 * JSON object. The same tables generate the key tables of docs/cases.md (tests/case_docs.c), so
 * the document cannot drift from the reader. Rules between keys (one of K and c, t/vx/vz of
 * equal length, a saturated medium's pore fluid, ...) are code in case.c. */
#ifndef MIXSPH_CASE_SCHEMA_H
#define MIXSPH_CASE_SCHEMA_H
#include <stddef.h>

#include "geometry.h"
#include "mixsph.h"

struct cJSON;

enum case_type {
    CASE_NUMBER,  /* a finite number in [lo, hi] (open ends as flagged) -> double */
    CASE_INTEGER, /* an integral number in [lo, hi] -> int */
    CASE_BOOL,    /* true or false, or 0 / 1 (the value of a parameter) -> int */
    CASE_STRING,  /* a string of lo to hi characters -> char[hi + 1] (no field: free text) */
    CASE_CHOICE,  /* one of the strings of `choices` -> int, the choice's value */
    CASE_NAME,    /* the name of another entry (a medium, a wall, ...): resolved by case.c */
    CASE_NUMBERS, /* an array of at least lo numbers: stored by case.c */
    CASE_POINTS,  /* an array of at least lo [x, z] points -> struct polyline */
    CASE_OBJECT   /* an object: a section of its own */
};

enum case_need {
    CASE_OPTIONAL = 0,
    CASE_REQUIRED = 1,
    CASE_SOMETIMES = 2 /* required in the cases `need_text` states, checked by case.c */
};

/* The field of member m of struct s that a key fills (0: none; an entry left zero fills none). */
#define CASE_FIELD(s, m) (offsetof(struct s, m) + 1)

struct case_choice {
    const char *name;
    int value;
};

struct case_key {
    const char *key;
    enum case_type type;
    enum case_need need;
    const char *need_text;    /* CASE_SOMETIMES: when it is required (for the document) */
    double lo, hi;            /* range of a number; characters of a string; least count of an array */
    int lo_open, hi_open;     /* 1: the end is excluded */
    int has_def;              /* 1: `def` is written to the field when the key is absent; 0: the field keeps
                                 what case.c set (e.g. a default that depends on other keys) */
    double def;               /* the default (a choice: its value; a Boolean: 0 or 1) */
    const char *def_text;     /* the default for the document when it is not `def`; a string's default */
    const char *unit;         /* SI unit, "-" for none, NULL where it does not apply */
    const char *meaning;
    size_t field;             /* CASE_FIELD(struct, member) of the field it fills, 0: none */
    const struct case_choice *choices; /* CASE_CHOICE: NULL-terminated */
    unsigned only;            /* sections with variants: the variants (bits) it belongs to, 0 = all */
    int numeric_choice;       /* CASE_CHOICE: a number equal to a choice's value selects it too (so that a
                                 numeric override such as --set numerics.viscosity=1 can) */
};

/* A key a case file may no longer use, and why. */
struct case_refused {
    const char *key;
    const char *why;
};

struct case_section {
    const char *id;           /* names the table in docs/cases.md: <!-- keys:<id> --> */
    const char *title;        /* e.g. "media.<name> (type fluid)" */
    const struct case_key *keys;
    size_t n_keys;
    const struct case_refused *refused; /* NULL-terminated, or NULL */
    const char *variant_noun;           /* e.g. "monitor" (NULL: no variants) */
    const struct case_choice *variants; /* variant v is bit (1u << value), NULL-terminated */
};

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
