/* wall_def.h - a wall as a case defines it (docs/cases.md, "walls"): an open polyline with the
 * fluid on one side, its motion law and its slip condition. The case reader fills these; the
 * walls module (walls.h) builds its particles and moves them. */
#ifndef MIXSPH_WALL_DEF_H
#define MIXSPH_WALL_DEF_H

#include "geometry.h"
#include "motion.h"
#include "schema.h" /* SCHEMA_NAME_LEN */

#define WALLS_MAX 16 /* walls of one case */

enum wall_slip { WALL_NO_SLIP = 0, WALL_FREE_SLIP = 1 };

struct wall {
    char name[SCHEMA_NAME_LEN];
    struct polyline line;     /* open polyline [m] */
    int side;                 /* +1: fluid on the left of the direction of travel, -1: right */
    int motion;               /* index into the case's motions, -1 for a fixed wall */
    int slip;                 /* enum wall_slip */
};

#endif
