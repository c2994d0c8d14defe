/* wall_def.h - a wall as a case defines it (docs/cases.md, "walls"): its geometry with the fluid
 * on one side, its motion law and its slip condition. The case reader fills these; the walls
 * module (walls.h) builds its particles and moves them.
 *
 * In 2D a wall is an open polyline of the x-z plane. In 3D it is an oriented triangulated surface
 * whose normals point to the fluid (core/surface.h), built once from one of the forms below by
 * wall_surface_build (wall_surface.h): a polyline extruded across y, a box, an STL file or a
 * terrain grid. */
#ifndef MIXSPH_WALL_DEF_H
#define MIXSPH_WALL_DEF_H

#include "geometry.h"
#include "motion.h"
#include "schema.h" /* SCHEMA_NAME_LEN */
#include "surface.h"

#define WALLS_MAX 16 /* walls of one case */
#define WALL_PATH_LEN 255 /* the longest file name of an stl or terrain wall */
#define WALL_MEDIA_MAX 8  /* media a wall's friction is given for: those of a case (io/case.h checks) */

enum wall_slip { WALL_NO_SLIP = 0, WALL_FREE_SLIP = 1 };

/* The geometry a wall is given by: the key present in its entry of the case. */
enum wall_form {
    WALL_FORM_POLYLINE = 0, /* 2D; in 3D extruded across [y_min, y_max] */
    WALL_FORM_BOX = 1,      /* 3D: the faces of an axis-aligned box */
    WALL_FORM_STL = 2,      /* 3D: the triangles of an STL file */
    WALL_FORM_TERRAIN = 3   /* 3D: the surface of an ESRI ASCII height grid, fluid above */
};

/* The sides a flume's side walls take (the key side_walls of an extruded polyline). */
enum wall_side_walls {
    WALL_SIDES_NONE = -1,  /* else the side walls' enum wall_slip */
    WALL_SIDES_MIRROR = -2 /* the planes are planes of symmetry: images, no particles (mirror_sides.h) */
};

struct wall {
    char name[SCHEMA_NAME_LEN];
    int form;                 /* enum wall_form */
    struct polyline line;     /* polyline: the open polyline [m] */
    int side;                 /* polyline: +1 fluid on the left of the direction of travel, -1 right */
    double y_min, y_max;      /* polyline in 3D: the extrusion's extent across y [m] (NaN: not given) */
    int side_walls;           /* polyline in 3D: enum wall_side_walls or the slip of the two side walls */
    double side_walls_z_max;  /* their top [m] (NaN: the polyline's highest point) */
    double box_min[3], box_max[3]; /* box: opposite corners [m] */
    unsigned box_faces;       /* box: the faces present, MESH_BOX_* bits of mesh.h */
    int fluid_outside;        /* box: the fluid is outside it (an obstacle) instead of inside (a tank) */
    char file[WALL_PATH_LEN + 1]; /* stl, terrain: the file, relative to the case file's folder */
    int flip;                 /* stl: the fluid is behind the facets' normals (right-hand rule) */
    struct surface surface;   /* 3D: the wall's triangles, normals toward the fluid (wall_surface_build) */
    int motion;               /* index into the case's motions, -1 for a fixed wall */
    int slip;                 /* enum wall_slip; a free-slip wall's particles carry the fluid's
                               * velocity mirrored across it in every pair term (walls.h) */
    double friction_deg;      /* friction angle delta on grains [deg] (the number form of its key); NaN: not given */
    double friction_of_medium_deg[WALL_MEDIA_MAX]; /* delta on the grains of each medium of the case [deg]: the
                                                    * one its key names for it, else friction_deg; NaN: the
                                                    * grains' own phi (case.c fills it for every medium) */
};

#endif
