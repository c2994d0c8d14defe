/* wall_surface.c - a 3D wall's surface from its form (wall_surface.h). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "wall_surface.h"

#include "status.h"
#include "stl.h"
#include "terrain.h"

/* The file of an stl or terrain wall, relative to the case's folder. */
static mixsph_status wall_file_path(const struct wall *wl, const char *case_dir, char *path, size_t len, char *err,
                                    size_t err_len)
{
    const int relative = wl->file[0] != '/' && case_dir && case_dir[0];
    const int n = relative ? snprintf(path, len, "%s/%s", case_dir, wl->file) : snprintf(path, len, "%s", wl->file);
    if (n < 0 || (size_t)n >= len) return status_set(err, err_len, MIXSPH_ERR_CASE, "the file name '%s' is too long", wl->file);
    return MIXSPH_OK;
}

mixsph_status wall_surface_build(struct wall *wl, const char *case_dir, char *err, size_t err_len)
{
    struct mesh m = {0};
    mixsph_status st = MIXSPH_OK;
    char path[2 * WALL_PATH_LEN + 2];
    switch (wl->form) {
    case WALL_FORM_POLYLINE:
        if (!(wl->y_max > wl->y_min))
            return status_set(err, err_len, MIXSPH_ERR_CASE, "a polyline wall in 3D needs y_min < y_max (its width)");
        st = mesh_add_extruded_polyline(&m, &wl->line, wl->side, wl->y_min, wl->y_max, err, err_len);
        break;
    case WALL_FORM_BOX:
        for (int d = 0; d < 3; d++)
            if (!(wl->box_max[d] > wl->box_min[d]))
                return status_set(err, err_len, MIXSPH_ERR_CASE, "a box needs min < max on every axis (axis %c: %g, %g)",
                                  "xyz"[d], wl->box_min[d], wl->box_max[d]);
        if (!wl->box_faces) return status_set(err, err_len, MIXSPH_ERR_CASE, "a box wall needs at least one face");
        st = mesh_add_box(&m, wl->box_min, wl->box_max, wl->box_faces, !wl->fluid_outside, err, err_len);
        break;
    case WALL_FORM_STL:
        if ((st = wall_file_path(wl, case_dir, path, sizeof path, err, err_len)) != MIXSPH_OK) return st;
        st = stl_read(path, &m, NULL, err, err_len);
        if (st == MIXSPH_OK && wl->flip) mesh_flip(&m);
        break;
    case WALL_FORM_TERRAIN: {
        if ((st = wall_file_path(wl, case_dir, path, sizeof path, err, err_len)) != MIXSPH_OK) return st;
        struct terrain t = {0};
        st = terrain_read_esri_ascii(path, &t, err, err_len);
        if (st == MIXSPH_OK) st = terrain_to_mesh(&t, &m, err, err_len);
        terrain_free(&t);
        if (st == MIXSPH_OK && m.n_triangles == 0)
            st = status_set(err, err_len, MIXSPH_ERR_CASE, "%s: no cell of the grid has data at its four nodes", path);
        break;
    }
    default: return status_set(err, err_len, MIXSPH_ERR_CASE, "unknown wall form %d", wl->form);
    }
    if (st == MIXSPH_OK) st = surface_build(&wl->surface, &m, err, err_len);
    mesh_free(&m);
    return st;
}

mixsph_status wall_side_walls(const struct wall *flume, struct wall *sides, char *err, size_t err_len)
{
    if (strlen(flume->name) + strlen("_sides") >= sizeof sides->name)
        return status_set(err, err_len, MIXSPH_ERR_CASE, "the name of its side walls, %s_sides, is too long", flume->name);
    double x0 = INFINITY, x1 = -INFINITY, z0 = INFINITY, z1 = -INFINITY;
    geom_grow_box(&flume->line, &x0, &x1, &z0, &z1);
    const double top = isnan(flume->side_walls_z_max) ? z1 : flume->side_walls_z_max;
    if (!(x1 > x0) || !(top > z0))
        return status_set(err, err_len, MIXSPH_ERR_CASE,
                          "side walls need a polyline spanning an x range and a top above its lowest point (%g)", z0);
    *sides = (struct wall){.form = WALL_FORM_BOX,
                           .box_min = {x0, flume->y_min, z0},
                           .box_max = {x1, flume->y_max, top},
                           .box_faces = MESH_BOX_YMIN | MESH_BOX_YMAX,
                           .side_walls = WALL_SIDES_NONE,
                           .side_walls_z_max = NAN,
                           .y_min = NAN,
                           .y_max = NAN,
                           .motion = -1,
                           .slip = flume->side_walls,
                           .friction_deg = flume->friction_deg};
    memcpy(sides->friction_of_medium_deg, flume->friction_of_medium_deg, sizeof sides->friction_of_medium_deg);
    const size_t len = strlen(flume->name); /* checked above: the name and "_sides" fit */
    memcpy(sides->name, flume->name, len);
    memcpy(sides->name + len, "_sides", sizeof "_sides");
    return wall_surface_build(sides, NULL, err, err_len);
}
