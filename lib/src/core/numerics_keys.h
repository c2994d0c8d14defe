/* numerics_keys.h - what the rows of numerics_keys.def (the keys of a case's `numerics`, one row
 * each) expand into. A file that needs one expansion defines NUMERICS_KEY as one of the macros
 * below (or its own), includes "numerics_keys.def" and undefines it:
 *
 *   struct forces_params {
 *       ...
 *   #define NUMERICS_KEY NUMERICS_MEMBER_OF_PAIR
 *   #include "numerics_keys.def"
 *   #undef NUMERICS_KEY
 *   };
 *
 * Macros only: no code, no dependency (the rows' fields are core/schema.h's, expanded where the
 * reader's table is, io/case_schema.c). */
#ifndef MIXSPH_NUMERICS_KEYS_H
#define MIXSPH_NUMERICS_KEYS_H

/* The C type of a key's value, by its type column (core/schema.h: what case_schema_read stores). */
#define NUMERICS_CTYPE_NUMBER double
#define NUMERICS_CTYPE_INTEGER int
#define NUMERICS_CTYPE_BOOL int
#define NUMERICS_CTYPE_CHOICE int

/* NUMERICS_IF_READ_BY(read_by, in, x): x when a row whose read_by column is `read_by` is held by
 * the struct `in` (SCHEME, PAIR, VISCOUS), nothing otherwise. One line per read_by and struct: a
 * new reader struct is a column of this table. */
#define NUMERICS_IF_READ_BY(read_by, in, x) NUMERICS_IF_##read_by##_##in(x)
#define NUMERICS_IF_SCHEME_SCHEME(x) x
#define NUMERICS_IF_SCHEME_PAIR(x)
#define NUMERICS_IF_SCHEME_VISCOUS(x)
#define NUMERICS_IF_PAIR_SCHEME(x)
#define NUMERICS_IF_PAIR_PAIR(x) x
#define NUMERICS_IF_PAIR_VISCOUS(x)
#define NUMERICS_IF_SCHEME_AND_PAIR_SCHEME(x) x
#define NUMERICS_IF_SCHEME_AND_PAIR_PAIR(x) x
#define NUMERICS_IF_SCHEME_AND_PAIR_VISCOUS(x)
#define NUMERICS_IF_VISCOUS_SCHEME(x)
#define NUMERICS_IF_VISCOUS_PAIR(x)
#define NUMERICS_IF_VISCOUS_VISCOUS(x) x
#define NUMERICS_IF_CREATION_SCHEME(x)
#define NUMERICS_IF_CREATION_PAIR(x)
#define NUMERICS_IF_CREATION_VISCOUS(x)

/* Member declarations: every key in struct case_def; the keys a struct of the step reads in it. */
#define NUMERICS_MEMBER_OF_CASE(type, member, read_by, as, ...) NUMERICS_CTYPE_##type member;
#define NUMERICS_MEMBER_OF_SCHEME(type, member, read_by, as, ...) \
    NUMERICS_IF_READ_BY(read_by, SCHEME, NUMERICS_CTYPE_##type as;)
#define NUMERICS_MEMBER_OF_PAIR(type, member, read_by, as, ...) \
    NUMERICS_IF_READ_BY(read_by, PAIR, NUMERICS_CTYPE_##type as;)
#define NUMERICS_MEMBER_OF_VISCOUS(type, member, read_by, as, ...) \
    NUMERICS_IF_READ_BY(read_by, VISCOUS, NUMERICS_CTYPE_##type as;)

#endif
