/* schema.h - the rows of a keyed table: what a key of a case file is ({key, type, range, default,
 * unit, meaning} and the field of a struct it fills), grouped in sections. The table-driven reader
 * is io/case_schema.h; the tables live with what they configure (the case's own sections in
 * io/case_schema.c, the numerical parameters in core/numerics_keys.def, a material law's keys in
 * its module under laws/), so a law's keys are rows of its own module. Types only: no code, no dependency. */
#ifndef MIXSPH_SCHEMA_H
#define MIXSPH_SCHEMA_H
#include <stddef.h>

/* Room for the name of a case entry (a medium, a body, a wall, a motion, a monitor). */
#define SCHEMA_NAME_LEN 48

enum case_type {
    CASE_NUMBER,  /* a finite number in [lo, hi] (open ends as flagged) -> double */
    CASE_INTEGER, /* an integral number in [lo, hi] -> int */
    CASE_BOOL,    /* true or false, or 0 / 1 (the value of a parameter) -> int */
    CASE_STRING,  /* a string of lo to hi characters -> char[hi + 1] (no field: free text) */
    CASE_CHOICE,  /* one of the strings of `choices` -> int, the choice's value */
    CASE_NAME,    /* the name of another entry (a medium, a wall, ...): resolved by case.c */
    CASE_NUMBERS, /* an array of at least lo numbers: stored by case.c */
    CASE_POINTS,  /* an array of at least lo [x, z] points -> struct polyline */
    CASE_OBJECT,  /* an object: a section of its own */
    CASE_NUMBER_BY_NAME /* a number in [lo, hi] (-> double), or an object of such numbers keyed by the names of
                           other entries (a wall's friction per medium): its names resolved by case.c */
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

/* How a number selects a choice of a CASE_CHOICE key (its numeric_choice). */
enum case_numeric_choice {
    CASE_CHOICE_NAME_ONLY = 0, /* a string only */
    CASE_CHOICE_BY_VALUE = 1,  /* a number equal to the choice's value */
    CASE_CHOICE_BY_POSITION = 2 /* a number equal to the choice's place in the list, from 0: for choices whose
                                   values are internal ids (a granular medium's law) */
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
    int numeric_choice;       /* CASE_CHOICE: a number selects a choice too (enum case_numeric_choice), so that
                                 a numeric override (--set numerics.viscosity=1) or parameter can */
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

/* Shorthands for the tables' rows. */
#define SCHEMA_COUNT(a) (sizeof(a) / sizeof((a)[0]))
#define SCHEMA_DEF(v) .has_def = 1, .def = (v)
#define SCHEMA_RANGE(l, lopen, h, hopen) .lo = (l), .lo_open = (lopen), .hi = (h), .hi_open = (hopen)
#define SCHEMA_SECTION(id_, title_, keys_) .id = (id_), .title = (title_), .keys = (keys_), .n_keys = SCHEMA_COUNT(keys_)

#endif
