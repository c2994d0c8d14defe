/* output.c - the run's HDF5 file and XDMF sidecar, checkpoints and restart (HDF5 C API).
 *
 * run.h5 (one file per run, in the output folder; HDF5 default file format, so that a file left
 * open by a killed run opens without repair):
 *   /                   attributes: format = "mixsph-run", format_version, mixsph_version,
 *                       case_name, created_utc, n_snapshots (complete snapshots), restarts,
 *                       last_restart_time; first_snapshot (index of the first snapshot) when a
 *                       restored run starts a new file
 *   /metadata           attributes: case_origin, overrides ("key=value" lines), dx, h, t_end,
 *                       snapshot_interval, monitor_interval, gravity, n_particles (fluid and
 *                       granular), n_wall_particles, media (names; medium index k of a fluid or
 *                       granular particle), walls (names; medium index of a wall particle),
 *                       states ("0 mobile, 1 fixed, 2 wall, 3 lost")
 *   /metadata/case_json the case file's JSON text (string)
 *   /snapshots/NNNNNN   one group per snapshot (NNNNNN = snapshot index, as snap_NNNN.csv);
 *                       attributes time [s], step, index; datasets of all n particles (fluid,
 *                       granular and wall), row k = the particle of id k: the rows of the
 *                       particle-field table marked PF_HDF5 the simulation has, in table order
 *                       (core/particle_fields.c), today
 *       position  (n, D) float64 [m]      x, z (D = 2); x, y, z in a 3D build (D = 3)
 *       velocity  (n, D) float64 [m/s]    vx, vz; vx, vy, vz
 *       density   (n)    float64 [kg/m^3]
 *       pressure  (n)    float64 [Pa]
 *       viscosity (n)    float64 [Pa s]
 *       mass      (n)    float64 [kg]
 *       medium    (n)    uint8   [1]      index into /metadata media (walls: into walls)
 *       state     (n)    uint8   [1]      0 mobile, 1 fixed, 2 wall, 3 lost, 4 mirror image
 *       id        (n)    uint32  [1]      stable particle id
 *     then any fields of the simulation's material laws or scheme; every dataset has the
 *     attributes units and description.
 *   /xdmf/vertices_N    0..N-1, the XDMF Polyvertex topology of N particles
 *
 * A simulation sent back in time by mixsph_sim_load_state writes its snapshots again: each
 * replaces the group of the same index, and the sidecar lists the snapshots up to the newest.
 * A snapshot is written, then the file is flushed (H5Fflush) and n_snapshots updated, and then
 * run.xdmf is rewritten (to a temporary name, then renamed over the old one) listing the
 * snapshots so far: a run killed at any point leaves run.h5 with every flushed snapshot
 * readable and a sidecar that names only those. The writer takes no HDF5 file lock, so the
 * file can be read while the run goes on (what a reader sees is consistent between snapshots).
 *
 * run.xdmf: XDMF 3 (XDMF 2 attribute names, which readers of both accept), a temporal
 * collection of uniform grids, one per snapshot: Polyvertex topology, XY geometry in 2D (x, z: in
 * ParaView x to the right and z up), XYZ in 3D (the PF_GEOMETRY row), the other datasets as node
 * attributes (Scalar, Vector for DIM components, Matrix for the others).
 *
 * checkpoint files (mixsph_sim_write_checkpoint): an HDF5 file with the dataset /state (uint8,
 * the buffer of mixsph_sim_save_state: case text, overrides, every particle field and counter,
 * versioned and checksummed) and attributes format = "mixsph-checkpoint", time, step,
 * case_name, created_utc; written to PATH.tmp and renamed to PATH, so a crash never leaves a
 * half checkpoint under PATH.
 *
 * HDF5 never prints: its automatic error printing is switched off for the duration of each call
 * into it (and restored after), and its innermost error message goes into the simulation's
 * message. The HDF5 library is process-wide; the file handles belong to the simulation.
 * Debian's serial HDF5 is not thread-safe: simulations of one process may write outputs only
 * from one thread at a time (stepping them in turn, as the CLI and the FMU do, is fine). */
#include "output.h"

#include <errno.h>
#include <fcntl.h>
#include <hdf5.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "clock.h"
#include "monitors.h"
#include "particle_fields.h"
#include "sim_object.h"
#include "status.h"

#ifndef MIXSPH_VERSION
#define MIXSPH_VERSION "unknown"
#endif

#define RUN_FILE "run.h5"
#define XDMF_FILE "run.xdmf"
#define RUN_FORMAT_VERSION 2 /* 2: the deviatoric stress one dataset "stress" (n, SYM_N) (in 1: sxx, sxz, szz, syy) */

struct snap_rec {
    long index;     /* snapshot index (group name) */
    double t;       /* [s] */
    uint64_t step;
    size_t n;       /* particles */
};

struct output {
    hid_t file;
    char path[640], xdmf[640];
    struct snap_rec *snaps;
    size_t n_snaps, cap_snaps;
    void *scratch; /* gathered field of one snapshot */
    size_t scratch_len;
};

enum { T_CSV = 0, T_HDF5 = 1, T_CKPT = 2 };

/* ---- HDF5 errors: never printed, the innermost message kept -------------------------------- */

struct quiet {
    H5E_auto2_t fn;
    void *data;
};

static void quiet_on(struct quiet *q)
{
    H5Eget_auto2(H5E_DEFAULT, &q->fn, &q->data);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
}

static void quiet_off(const struct quiet *q) { H5Eset_auto2(H5E_DEFAULT, q->fn, q->data); }

struct cause {
    char text[300];
};

static herr_t cause_walk(unsigned n, const H5E_error2_t *e, void *data)
{
    (void)n;
    struct cause *c = data;
    if (e && e->desc && e->desc[0]) snprintf(c->text, sizeof c->text, "%s", e->desc);
    return 0;
}

/* The innermost message of HDF5's current error stack ("" if none). */
static const char *h5_cause(struct cause *c)
{
    c->text[0] = '\0';
    H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, cause_walk, c);
    return c->text;
}

#define H5_FAIL(s, what, path)                                                                                \
    do {                                                                                                    \
        struct cause c_;                                                                                    \
        h5_cause(&c_);                                                                                      \
        SIM_FAIL((s), MIXSPH_ERR_IO, "%s: %s%s%s", (path), (what), c_.text[0] ? " (HDF5: " : "",           \
                 c_.text[0] ? c_.text : "");                                                               \
        if (c_.text[0]) strncat((s)->err, ")", sizeof(s)->err - strlen((s)->err) - 1);                     \
    } while (0)

/* ---- small writers (return 0 on success) ---------------------------------------------------- */

static hid_t str_type(void)
{
    const hid_t t = H5Tcopy(H5T_C_S1);
    if (t < 0) return t;
    if (H5Tset_size(t, H5T_VARIABLE) < 0 || H5Tset_cset(t, H5T_CSET_UTF8) < 0) {
        H5Tclose(t);
        return -1;
    }
    return t;
}

/* Create or replace attribute `name` of `obj` and write `buf` (ftype on file, mtype in memory). */
static int attr_write(hid_t obj, const char *name, hid_t ftype, hid_t mtype, hsize_t n, const void *buf)
{
    if (H5Aexists(obj, name) > 0 && H5Adelete(obj, name) < 0) return -1;
    const hid_t sp = n ? H5Screate_simple(1, &n, NULL) : H5Screate(H5S_SCALAR);
    if (sp < 0) return -1;
    const hid_t a = H5Acreate2(obj, name, ftype, sp, H5P_DEFAULT, H5P_DEFAULT);
    int bad = a < 0 || H5Awrite(a, mtype, buf) < 0;
    if (a >= 0) bad |= H5Aclose(a) < 0;
    H5Sclose(sp);
    return bad ? -1 : 0;
}

static int attr_str(hid_t obj, const char *name, const char *v)
{
    const hid_t t = str_type();
    if (t < 0) return -1;
    const int r = attr_write(obj, name, t, t, 0, &v);
    H5Tclose(t);
    return r;
}

static int attr_strs(hid_t obj, const char *name, const char *const *v, size_t n)
{
    const hid_t t = str_type();
    if (t < 0) return -1;
    const char *none = "";
    const int r = attr_write(obj, name, t, t, n ? n : 1, n ? (const void *)v : (const void *)&none);
    H5Tclose(t);
    return r;
}

static int attr_f64(hid_t obj, const char *name, double v)
{
    return attr_write(obj, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, 0, &v);
}

static int attr_i64(hid_t obj, const char *name, long long v)
{
    return attr_write(obj, name, H5T_STD_I64LE, H5T_NATIVE_LLONG, 0, &v);
}

static int attr_read_i64(hid_t obj, const char *name, long long *v)
{
    const hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    if (a < 0) return -1;
    const int bad = H5Aread(a, H5T_NATIVE_LLONG, v) < 0;
    H5Aclose(a);
    return bad ? -1 : 0;
}

static int attr_read_f64(hid_t obj, const char *name, double *v)
{
    const hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    if (a < 0) return -1;
    const int bad = H5Aread(a, H5T_NATIVE_DOUBLE, v) < 0;
    H5Aclose(a);
    return bad ? -1 : 0;
}

/* Read a scalar string attribute into a malloc'd copy (NULL on failure). */
static char *attr_read_str(hid_t obj, const char *name)
{
    const hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    if (a < 0) return NULL;
    const hid_t t = str_type();
    char *v = NULL, *copy = NULL;
    if (t >= 0 && H5Aread(a, t, &v) >= 0 && v) {
        copy = malloc(strlen(v) + 1);
        if (copy) strcpy(copy, v);
        H5free_memory(v);
    }
    if (t >= 0) H5Tclose(t);
    H5Aclose(a);
    return copy;
}

/* Write dataset `name` in `loc`: rank 1 (n) or 2 (n, m), with units and description. */
static int dset_write(hid_t loc, const char *name, hid_t ftype, hid_t mtype, hsize_t n, hsize_t m, const void *buf,
                      const char *units, const char *description)
{
    const hsize_t dims[2] = {n, m};
    const hid_t sp = H5Screate_simple(m ? 2 : 1, dims, NULL);
    if (sp < 0) return -1;
    const hid_t d = H5Dcreate2(loc, name, ftype, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    int bad = d < 0;
    if (!bad && n > 0) bad = H5Dwrite(d, mtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0;
    if (!bad && units) bad = attr_str(d, "units", units) < 0;
    if (!bad && description) bad = attr_str(d, "description", description) < 0;
    if (d >= 0) bad |= H5Dclose(d) < 0;
    H5Sclose(sp);
    return bad ? -1 : 0;
}

static int dset_string(hid_t loc, const char *name, const char *text)
{
    const hid_t t = str_type();
    if (t < 0) return -1;
    const hid_t sp = H5Screate(H5S_SCALAR);
    const hid_t d = sp < 0 ? -1 : H5Dcreate2(loc, name, t, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    int bad = d < 0 || H5Dwrite(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, &text) < 0;
    if (d >= 0) bad |= H5Dclose(d) < 0;
    if (sp >= 0) H5Sclose(sp);
    H5Tclose(t);
    return bad ? -1 : 0;
}

static char *dset_read_string(hid_t loc, const char *name)
{
    const hid_t d = H5Dopen2(loc, name, H5P_DEFAULT);
    if (d < 0) return NULL;
    const hid_t t = str_type();
    char *v = NULL, *copy = NULL;
    if (t >= 0 && H5Dread(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, &v) >= 0 && v) {
        copy = malloc(strlen(v) + 1);
        if (copy) strcpy(copy, v);
        H5free_memory(v);
    }
    if (t >= 0) H5Tclose(t);
    H5Dclose(d);
    return copy;
}

static void utc_now(char *buf, size_t n)
{
    const time_t now = time(NULL);
    struct tm tm;
    if (gmtime_r(&now, &tm)) strftime(buf, n, "%Y-%m-%dT%H:%M:%SZ", &tm);
    else snprintf(buf, n, "unknown");
}

/* The overrides of s as "key=value" lines (malloc'd; "" if none). */
static char *overrides_text(const mixsph_sim *s)
{
    size_t len = 1;
    for (size_t k = 0; k < s->n_ov; k++) len += strlen(s->ov_key[k]) + 32;
    char *t = malloc(len), *p = t;
    if (!t) return NULL;
    *p = '\0';
    for (size_t k = 0; k < s->n_ov; k++) p += sprintf(p, "%s=%.17g\n", s->ov_key[k], s->ov_value[k]);
    return t;
}

/* File access without HDF5 file locks (readers may open the file while the run writes it). */
static hid_t fapl_nolock(void)
{
    const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
#if H5_VERSION_GE(1, 10, 7)
    if (fapl >= 0) H5Pset_file_locking(fapl, 0, 1);
#endif
    return fapl;
}

/* ---- the run file --------------------------------------------------------------------------- */

static mixsph_status run_create(mixsph_sim *s, struct output *o)
{
    const hid_t fapl = fapl_nolock();
    o->file = H5Fcreate(o->path, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    if (o->file < 0) H5_FAIL(s, "cannot create the HDF5 run file", o->path); /* before any other call */
    if (fapl >= 0) H5Pclose(fapl);
    if (o->file < 0) return MIXSPH_ERR_IO;
    char created[64];
    utc_now(created, sizeof created);
    char *ov = overrides_text(s);
    if (!ov) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory");
    const char *media[CASE_MAX_MEDIA], *walls[CASE_MAX_WALLS];
    for (size_t k = 0; k < s->cfg.n_media; k++) media[k] = s->cfg.media[k].name;
    for (size_t k = 0; k < s->cfg.n_walls; k++) walls[k] = s->cfg.walls[k].name;
    int bad = attr_str(o->file, "format", "mixsph-run") || attr_i64(o->file, "format_version", RUN_FORMAT_VERSION) ||
              attr_str(o->file, "mixsph_version", MIXSPH_VERSION) || attr_str(o->file, "case_name", s->cfg.name) ||
              attr_str(o->file, "created_utc", created) || attr_i64(o->file, "n_snapshots", 0) ||
              attr_i64(o->file, "restarts", 0);
    const hid_t g = bad ? -1 : H5Gcreate2(o->file, "metadata", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    bad = bad || g < 0;
    if (!bad)
        bad = dset_string(g, "case_json", s->case_text ? s->case_text : "") ||
              attr_str(g, "case_origin", s->case_origin ? s->case_origin : "") || attr_str(g, "overrides", ov) ||
              attr_f64(g, "dx", s->phys.dx) || attr_f64(g, "h", s->phys.h) || attr_f64(g, "t_end", s->cfg.t_end) ||
              attr_f64(g, "snapshot_interval", s->cfg.snapshot_interval) ||
              attr_f64(g, "monitor_interval", s->cfg.monitor_interval) || attr_f64(g, "gravity", s->cfg.g) ||
              attr_i64(g, "n_particles", (long long)s->phys.n_fluid) || attr_i64(g, "n_wall_particles", (long long)s->phys.n_wall) ||
              attr_strs(g, "media", media, s->cfg.n_media) || attr_strs(g, "walls", walls, s->cfg.n_walls) ||
              attr_str(g, "states", "0 mobile, 1 fixed (granular, elastic-plastic regime), 2 wall, 3 lost, 4 mirror image");
    if (g >= 0) H5Gclose(g);
    free(ov);
    hid_t g2 = -1, g3 = -1;
    if (!bad) bad = (g2 = H5Gcreate2(o->file, "snapshots", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) < 0;
    if (!bad) bad = (g3 = H5Gcreate2(o->file, "xdmf", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) < 0;
    if (g2 >= 0) H5Gclose(g2);
    if (g3 >= 0) H5Gclose(g3);
    if (!bad) bad = H5Fflush(o->file, H5F_SCOPE_LOCAL) < 0;
    if (bad) {
        H5_FAIL(s, "cannot write the metadata", o->path);
        return MIXSPH_ERR_IO;
    }
    return MIXSPH_OK;
}

static int snaps_push(struct output *o, struct snap_rec r)
{
    if (o->n_snaps == o->cap_snaps) {
        const size_t cap = o->cap_snaps ? 2 * o->cap_snaps : 64;
        struct snap_rec *q = realloc(o->snaps, cap * sizeof *q);
        if (!q) return -1;
        o->snaps = q;
        o->cap_snaps = cap;
    }
    o->snaps[o->n_snaps++] = r;
    return 0;
}

struct scan {
    mixsph_sim *s;
    struct output *o;
    long keep_below;  /* snapshots with a higher or equal index are dropped */
    char drop[64][16];
    size_t n_drop;
    int bad;
};

static herr_t scan_snapshot(hid_t g, const char *name, const H5L_info_t *info, void *data)
{
    (void)info;
    struct scan *sc = data;
    const hid_t sg = H5Gopen2(g, name, H5P_DEFAULT);
    if (sg < 0) return 0; /* not a group: ignored */
    long long index = -1, step = 0, n = 0;
    double t = 0.0;
    const int ok = attr_read_i64(sg, "index", &index) == 0 && attr_read_f64(sg, "time", &t) == 0 &&
                   attr_read_i64(sg, "step", &step) == 0 && attr_read_i64(sg, "n", &n) == 0;
    H5Gclose(sg);
    if (!ok || index >= sc->keep_below) {
        /* incomplete or after the restored state: dropped (64 at a time, the caller repeats) */
        if (sc->n_drop < 64 && strlen(name) < sizeof sc->drop[0]) strcpy(sc->drop[sc->n_drop++], name);
        return 0;
    }
    if (snaps_push(sc->o, (struct snap_rec){(long)index, t, (uint64_t)step, (size_t)n})) sc->bad = 1;
    return 0;
}

/* Continue an existing run file: check that it is of the same case and overrides, drop the
 * snapshots at or after the restored state, list the others. */
static mixsph_status run_continue(mixsph_sim *s, struct output *o)
{
    const hid_t fapl = fapl_nolock();
    o->file = H5Fopen(o->path, H5F_ACC_RDWR, fapl);
    if (o->file < 0) H5_FAIL(s, "cannot open the run file to continue it (give another output folder)", o->path);
    if (fapl >= 0) H5Pclose(fapl);
    if (o->file < 0) return MIXSPH_ERR_IO;
    const hid_t g = H5Gopen2(o->file, "metadata", H5P_DEFAULT);
    char *text = g < 0 ? NULL : dset_read_string(g, "case_json");
    char *ov = g < 0 ? NULL : attr_read_str(g, "overrides");
    char *mine = overrides_text(s);
    if (g >= 0) H5Gclose(g);
    const int same = text && ov && mine && strcmp(text, s->case_text ? s->case_text : "") == 0 && strcmp(ov, mine) == 0;
    free(text);
    free(ov);
    free(mine);
    if (!same)
        return SIM_FAIL(s, MIXSPH_ERR_ARG,
                        "%s: holds a run of another case or other overrides than the checkpoint's; give another output "
                        "folder",
                        o->path);
    for (int pass = 0;; pass++) {
        struct scan sc = {s, o, s->out.snap_index, {{0}}, 0, 0};
        o->n_snaps = 0;
        hsize_t idx = 0;
        if (H5Literate_by_name(o->file, "snapshots", H5_INDEX_NAME, H5_ITER_INC, &idx, scan_snapshot, &sc, H5P_DEFAULT) < 0) {
            H5_FAIL(s, "cannot list the snapshots", o->path);
            return MIXSPH_ERR_IO;
        }
        if (sc.bad) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory");
        if (sc.n_drop == 0) break;
        const hid_t gs = H5Gopen2(o->file, "snapshots", H5P_DEFAULT);
        for (size_t k = 0; k < sc.n_drop && gs >= 0; k++)
            if (H5Ldelete(gs, sc.drop[k], H5P_DEFAULT) < 0) sc.bad = 1;
        if (gs >= 0) H5Gclose(gs);
        if (gs < 0 || sc.bad) {
            H5_FAIL(s, "cannot drop the snapshots after the checkpoint", o->path);
            return MIXSPH_ERR_IO;
        }
    }
    long long restarts = 0;
    attr_read_i64(o->file, "restarts", &restarts);
    if (attr_i64(o->file, "restarts", restarts + 1) || attr_f64(o->file, "last_restart_time", s->phys.t) ||
        attr_i64(o->file, "n_snapshots", (long long)o->n_snaps) || H5Fflush(o->file, H5F_SCOPE_LOCAL) < 0) {
        H5_FAIL(s, "cannot update the run file", o->path);
        return MIXSPH_ERR_IO;
    }
    return MIXSPH_OK;
}

/* ---- XDMF sidecar --------------------------------------------------------------------------- */

static void xdmf_item(FILE *f, const char *indent, size_t n, int comps, const char *type, int prec, long index,
                      const char *field)
{
    fprintf(f, "%s<DataItem Dimensions=\"%zu", indent, n);
    if (comps) fprintf(f, " %d", comps);
    fprintf(f, "\" NumberType=\"%s\" Precision=\"%d\" Format=\"HDF\">%s:/snapshots/%06ld/%s</DataItem>\n", type, prec,
            RUN_FILE, index, field);
}

/* A field as a node attribute: Scalar, Vector (DIM components, as the geometry's axes) or Matrix
 * (others). */
static void xdmf_attribute(FILE *f, const struct snap_rec *r, const struct particle_field *pf)
{
    const unsigned m = pf->components;
    fprintf(f, "        <Attribute Name=\"%s\" AttributeType=\"%s\" Center=\"Node\">\n", pf->name,
            m == 1 ? "Scalar" : m == DIM ? "Vector" : "Matrix");
    xdmf_item(f, "          ", r->n, m > 1 ? (int)m : 0, pf->type == PF_F64 ? "Float" : "UInt",
              (int)particle_field_size(pf->type), r->index, pf->name);
    fprintf(f, "        </Attribute>\n");
}

/* Make sure /xdmf/vertices_N exists (0..N-1, the Polyvertex topology). */
static int xdmf_vertices(struct output *o, size_t n)
{
    char name[64];
    snprintf(name, sizeof name, "/xdmf/vertices_%zu", n);
    if (H5Lexists(o->file, name, H5P_DEFAULT) > 0) return 0;
    uint32_t *v = malloc((n ? n : 1) * sizeof *v);
    if (!v) return -1;
    for (size_t k = 0; k < n; k++) v[k] = (uint32_t)k;
    const int r = dset_write(o->file, name, H5T_STD_U32LE, H5T_NATIVE_UINT32, n, 1, v, "1",
                             "XDMF Polyvertex topology: particle k is vertex k");
    free(v);
    return r;
}

static int xdmf_write(const mixsph_sim *s, const struct output *o)
{
    char tmp[700];
    snprintf(tmp, sizeof tmp, "%s.tmp", o->xdmf);
    FILE *f = fopen(tmp, "w");
    if (!f) return -1;
    fprintf(f, "<?xml version=\"1.0\" ?>\n<!-- mixsph run of case %s: particles as a time series of point clouds; the "
               "data are in %s (%s) -->\n",
            s->cfg.name, RUN_FILE, DIM == 2 ? "x, z -> X, Y" : "x, y, z -> X, Y, Z");
    fprintf(f, "<Xdmf Version=\"3.0\">\n  <Domain>\n    <Grid Name=\"particles\" GridType=\"Collection\" "
               "CollectionType=\"Temporal\">\n");
    for (size_t k = 0; k < o->n_snaps; k++) {
        const struct snap_rec *r = &o->snaps[k];
        fprintf(f, "      <Grid Name=\"snapshot_%06ld\" GridType=\"Uniform\">\n", r->index);
        fprintf(f, "        <Time Value=\"%.17g\"/>\n", r->t);
        fprintf(f, "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%zu\" NodesPerElement=\"1\">\n", r->n);
        fprintf(f, "          <DataItem Dimensions=\"%zu 1\" NumberType=\"UInt\" Precision=\"4\" "
                   "Format=\"HDF\">%s:/xdmf/vertices_%zu</DataItem>\n",
                r->n, RUN_FILE, r->n);
        fprintf(f, "        </Topology>\n        <Geometry GeometryType=\"%s\">\n", DIM == 2 ? "XY" : "XYZ");
        for (size_t k = 0; k < particle_field_count; k++) {
            const struct particle_field *pf = &particle_fields[k];
            if ((pf->where & (PF_HDF5 | PF_GEOMETRY)) == (PF_HDF5 | PF_GEOMETRY) &&
                particle_field_present(pf, s->phys.P.features))
                xdmf_item(f, "          ", r->n, (int)pf->components, pf->type == PF_F64 ? "Float" : "UInt",
                          (int)particle_field_size(pf->type), r->index, pf->name);
        }
        fprintf(f, "        </Geometry>\n");
        for (size_t k = 0; k < particle_field_count; k++) {
            const struct particle_field *pf = &particle_fields[k];
            if ((pf->where & (PF_HDF5 | PF_GEOMETRY)) == PF_HDF5 && particle_field_present(pf, s->phys.P.features))
                xdmf_attribute(f, r, pf);
        }
        fprintf(f, "      </Grid>\n");
    }
    fprintf(f, "    </Grid>\n  </Domain>\n</Xdmf>\n");
    const int bad = ferror(f);
    if (fclose(f) != 0 || bad || rename(tmp, o->xdmf) != 0) {
        remove(tmp);
        return -1;
    }
    return 0;
}

/* ---- open, snapshot, close ------------------------------------------------------------------ */

mixsph_status output_open(mixsph_sim *s, int resume)
{
    output_close(s);
    struct output *o = calloc(1, sizeof *o);
    if (!o) return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory");
    o->file = -1;
    snprintf(o->path, sizeof o->path, "%s/%s", s->out.dir, RUN_FILE);
    snprintf(o->xdmf, sizeof o->xdmf, "%s/%s", s->out.dir, XDMF_FILE);
    struct quiet q;
    quiet_on(&q);
    mixsph_status st;
    if (resume && access(o->path, F_OK) == 0) {
        st = run_continue(s, o);
    } else {
        st = run_create(s, o);
        /* a restored run in a new folder: its snapshots start at the restored index */
        if (st == MIXSPH_OK && resume &&
            (attr_i64(o->file, "restarts", 1) || attr_f64(o->file, "last_restart_time", s->phys.t) ||
             attr_i64(o->file, "first_snapshot", s->out.snap_index))) {
            H5_FAIL(s, "cannot write the metadata", o->path);
            st = MIXSPH_ERR_IO;
        }
    }
    quiet_off(&q);
    if (st == MIXSPH_OK && xdmf_write(s, o) != 0)
        st = SIM_FAIL(s, MIXSPH_ERR_IO, "%s: cannot write: %s", o->xdmf, strerror(errno));
    s->out.h5 = o;
    if (st != MIXSPH_OK) output_close(s);
    return st;
}

void output_close(mixsph_sim *s)
{
    struct output *o = s->out.h5;
    if (!o) return;
    if (o->file >= 0) {
        struct quiet q;
        quiet_on(&q);
        H5Fclose(o->file);
        quiet_off(&q);
    }
    free(o->snaps);
    free(o->scratch);
    free(o);
    s->out.h5 = NULL;
}

static void *scratch(struct output *o, size_t bytes)
{
    if (bytes > o->scratch_len) {
        void *p = realloc(o->scratch, bytes);
        if (!p) return NULL;
        o->scratch = p;
        o->scratch_len = bytes;
    }
    return o->scratch;
}

/* HDF5 file (little-endian) and memory types of a field's elements. */
static hid_t field_file_type(enum particle_field_type t)
{
    switch (t) {
    case PF_F64: return H5T_IEEE_F64LE;
    case PF_U8: return H5T_STD_U8LE;
    case PF_U16: return H5T_STD_U16LE;
    case PF_U32: return H5T_STD_U32LE;
    }
    return -1;
}

static hid_t field_mem_type(enum particle_field_type t)
{
    switch (t) {
    case PF_F64: return H5T_NATIVE_DOUBLE;
    case PF_U8: return H5T_NATIVE_UINT8;
    case PF_U16: return H5T_NATIVE_UINT16;
    case PF_U32: return H5T_NATIVE_UINT32;
    }
    return -1;
}

/* Write field f of P as a dataset of g: its components interleaved, (n) or (n, components),
 * row = the particle's id when the ids are 0..n-1 (by_id), else storage order. */
static int write_field(struct output *o, hid_t g, const struct particles *P, int by_id, const struct particle_field *f)
{
    const size_t n = P->n, m = f->components;
    void *buf = scratch(o, (n ? n : 1) * m * particle_field_size(f->type));
    if (!buf) return -1;
#define GATHER(T)                                                                         \
    do {                                                                                  \
        const T *a_ = particles_array(P, f->member[c]);                                   \
        T *b_ = buf;                                                                      \
        for (size_t i = 0; i < n; i++) b_[(by_id ? P->id[i] : i) * m + c] = a_[i];       \
    } while (0)
    for (unsigned c = 0; c < m; c++) switch (f->type) {
        case PF_F64: GATHER(double); break;
        case PF_U8: GATHER(uint8_t); break;
        case PF_U16: GATHER(uint16_t); break;
        case PF_U32: GATHER(uint32_t); break;
        }
#undef GATHER
    return dset_write(g, f->name, field_file_type(f->type), field_mem_type(f->type), n, m > 1 ? m : 0, buf, f->unit,
                      f->description);
}

static int write_snapshot(mixsph_sim *s, struct output *o, long index)
{
    const struct particles *P = &s->phys.P;
    int by_id = 1;
    for (size_t i = 0; i < P->n && by_id; i++) by_id = P->id[i] < P->n;
    char name[64];
    snprintf(name, sizeof name, "/snapshots/%06ld", index);
    /* a snapshot of this index from before a mixsph_sim_load_state that went back in time */
    if (H5Lexists(o->file, name, H5P_DEFAULT) > 0 && H5Ldelete(o->file, name, H5P_DEFAULT) < 0) return -1;
    while (o->n_snaps > 0 && o->snaps[o->n_snaps - 1].index >= index) o->n_snaps--;
    const hid_t g = H5Gcreate2(o->file, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (g < 0) return -1;
    /* the attribute index is written last: a group without it is incomplete */
    int bad = attr_f64(g, "time", s->phys.t) || attr_i64(g, "step", (long long)s->phys.step) ||
              attr_i64(g, "n", (long long)P->n) || attr_str(g, "time_units", "s");
    for (size_t k = 0; k < particle_field_count && !bad; k++) {
        const struct particle_field *f = &particle_fields[k];
        if ((f->where & PF_HDF5) && particle_field_present(f, P->features)) bad = write_field(o, g, P, by_id, f);
    }
    bad = bad || attr_i64(g, "index", index);
    bad |= H5Gclose(g) < 0;
    bad = bad || xdmf_vertices(o, P->n);
    bad = bad || attr_i64(o->file, "n_snapshots", (long long)o->n_snaps + 1);
    bad = bad || H5Fflush(o->file, H5F_SCOPE_LOCAL) < 0;
    return bad ? -1 : 0;
}

mixsph_status output_snapshot(mixsph_sim *s)
{
    const long index = s->out.snap_index;
    const double t0 = clock_monotonic_s();
    mixsph_status st = MIXSPH_OK;
    if (s->out.csv_snapshots_off) s->out.snap_index++;
    else st = monitors_snapshot(s);
    const double t1 = clock_monotonic_s();
    s->out.seconds[T_CSV] += t1 - t0;
    struct output *o = s->out.h5;
    if (st != MIXSPH_OK || !o) return st;
    struct quiet q;
    quiet_on(&q);
    const int bad = write_snapshot(s, o, index);
    if (bad) H5_FAIL(s, "cannot write a snapshot", o->path);
    quiet_off(&q);
    if (bad) return MIXSPH_ERR_IO;
    if (snaps_push(o, (struct snap_rec){index, s->phys.t, s->phys.step, s->phys.P.n}))
        return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory");
    if (xdmf_write(s, o) != 0) return SIM_FAIL(s, MIXSPH_ERR_IO, "%s: cannot write: %s", o->xdmf, strerror(errno));
    s->out.seconds[T_HDF5] += clock_monotonic_s() - t1;
    return MIXSPH_OK;
}

/* ---- monitors.csv continued after a restore ------------------------------------------------- */

mixsph_status output_resume_monitors(mixsph_sim *s)
{
    char path[600];
    snprintf(path, sizeof path, "%s/monitors.csv", s->out.dir);
    FILE *f = fopen(path, "r");
    if (!f) return monitors_open(s);
    /* keep the header line and the first n_samples rows */
    long keep_lines = 1 + s->out.n_samples, lines = 0;
    off_t pos = 0;
    int c;
    while (lines < keep_lines && (c = fgetc(f)) != EOF) {
        pos++;
        if (c == '\n') lines++;
    }
    fclose(f);
    if (truncate(path, pos) != 0) return SIM_FAIL(s, MIXSPH_ERR_IO, "%s: cannot truncate: %s", path, strerror(errno));
    s->out.monitor_csv = fopen(path, "a");
    if (!s->out.monitor_csv) return SIM_FAIL(s, MIXSPH_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
    return MIXSPH_OK;
}

/* ---- checkpoints ---------------------------------------------------------------------------- */

mixsph_status mixsph_sim_write_checkpoint(mixsph_sim *s, const char *path)
{
    if (!s) return MIXSPH_ERR_ARG;
    if (!path || !*path) return SIM_FAIL(s, MIXSPH_ERR_ARG, "checkpoint: no file name");
    const double t0 = clock_monotonic_s();
    void *buf = NULL;
    size_t len = 0;
    mixsph_status st = mixsph_sim_save_state(s, &buf, &len);
    if (st != MIXSPH_OK) return SIM_FAIL(s, st, "checkpoint %s: cannot serialise the state", path);
    const size_t plen = strlen(path);
    char *tmp = malloc(plen + 5);
    if (!tmp) {
        mixsph_state_free(buf);
        return SIM_FAIL(s, MIXSPH_ERR_NOMEM, "out of memory");
    }
    memcpy(tmp, path, plen);
    memcpy(tmp + plen, ".tmp", 5);
    struct quiet q;
    quiet_on(&q);
    const hid_t fapl = fapl_nolock();
    const hid_t f = H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    if (f < 0) H5_FAIL(s, "cannot create the checkpoint", tmp);
    if (fapl >= 0) H5Pclose(fapl);
    char created[64];
    utc_now(created, sizeof created);
    int bad = f < 0;
    if (!bad)
        bad = attr_str(f, "format", "mixsph-checkpoint") || attr_i64(f, "format_version", RUN_FORMAT_VERSION) ||
              attr_str(f, "mixsph_version", MIXSPH_VERSION) || attr_str(f, "case_name", s->cfg.name) ||
              attr_str(f, "case_origin", s->case_origin ? s->case_origin : "") || attr_str(f, "created_utc", created) ||
              attr_f64(f, "time", s->phys.t) || attr_i64(f, "step", (long long)s->phys.step) ||
              attr_f64(f, "run_wall_time_s", s->out.run_wall_s) ||
              dset_write(f, "state", H5T_STD_U8LE, H5T_NATIVE_UINT8, len, 0, buf, "1",
                         "mixsph_sim_save_state buffer (versioned, checksummed; same build and machine type)");
    if (f >= 0) bad |= H5Fclose(f) < 0;
    if (bad && f >= 0) H5_FAIL(s, "cannot write the checkpoint", tmp);
    quiet_off(&q);
    mixsph_state_free(buf);
    if (!bad) {
        /* on disk before it replaces the previous checkpoint */
        const int fd = open(tmp, O_RDONLY);
        if (fd >= 0) {
            fsync(fd);
            close(fd);
        }
        if (rename(tmp, path) != 0) {
            SIM_FAIL(s, MIXSPH_ERR_IO, "checkpoint %s: cannot rename %s to it: %s", path, tmp, strerror(errno));
            bad = 1;
        }
    }
    if (bad) remove(tmp);
    free(tmp);
    const double spent = clock_monotonic_s() - t0;
    s->out.seconds[T_CKPT] += spent;
    s->out.run_wall_s += spent; /* the run's time includes its checkpoints (after this one's attribute) */
    return bad ? MIXSPH_ERR_IO : MIXSPH_OK;
}

mixsph_status output_read_checkpoint(const char *path, unsigned char **state, size_t *len, double *run_wall_s,
                                     char *err, size_t err_len)
{
    *state = NULL;
    *len = 0;
    *run_wall_s = NAN;
    if (access(path, R_OK) != 0)
        return status_set(err, err_len, MIXSPH_ERR_ARG, "checkpoint %s: cannot read: %s", path, strerror(errno));
    struct quiet q;
    quiet_on(&q);
    struct cause c;
    mixsph_status st = MIXSPH_OK;
    unsigned char *buf = NULL;
    size_t n_read = 0;
    double run_wall = NAN;
    const hid_t fapl = fapl_nolock();
    const hid_t f = H5Fopen(path, H5F_ACC_RDONLY, fapl);
    if (f < 0) h5_cause(&c); /* before any other call clears it */
    if (fapl >= 0) H5Pclose(fapl);
    if (f < 0) {
        st = status_set(err, err_len, MIXSPH_ERR_ARG, "checkpoint %s: not an HDF5 file (HDF5: %s)", path, c.text);
    } else {
        const hid_t d = H5Dopen2(f, "state", H5P_DEFAULT);
        const hid_t sp = d < 0 ? -1 : H5Dget_space(d);
        hsize_t n = 0;
        if (sp < 0 || H5Sget_simple_extent_ndims(sp) != 1 || H5Sget_simple_extent_dims(sp, &n, NULL) < 0 || n == 0) {
            st = status_set(err, err_len, MIXSPH_ERR_ARG, "checkpoint %s: no /state dataset (not a mixsph checkpoint)", path);
        } else if (!(buf = malloc((size_t)n))) {
            st = status_set(err, err_len, MIXSPH_ERR_NOMEM, "out of memory");
        } else if (H5Dread(d, H5T_NATIVE_UINT8, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0) {
            st = status_set(err, err_len, MIXSPH_ERR_IO, "checkpoint %s: cannot read /state (HDF5: %s)", path, h5_cause(&c));
        } else {
            n_read = (size_t)n;
        }
        if (sp >= 0) H5Sclose(sp);
        if (d >= 0) H5Dclose(d);
        /* the run's wall time up to the checkpoint (absent from older checkpoints: unknown) */
        if (H5Aexists(f, "run_wall_time_s") <= 0 || attr_read_f64(f, "run_wall_time_s", &run_wall) != 0)
            run_wall = NAN;
        H5Fclose(f);
    }
    quiet_off(&q);
    if (st != MIXSPH_OK) {
        free(buf);
        return st;
    }
    *state = buf;
    *len = (size_t)n_read;
    *run_wall_s = run_wall;
    return MIXSPH_OK;
}

mixsph_status mixsph_sim_set_csv_snapshots(mixsph_sim *s, int on)
{
    if (!s) return MIXSPH_ERR_ARG;
    s->out.csv_snapshots_off = !on;
    return MIXSPH_OK;
}

void mixsph_sim_output_time(const mixsph_sim *s, double *csv_s, double *hdf5_s, double *checkpoint_s)
{
    if (csv_s) *csv_s = s ? s->out.seconds[T_CSV] : 0.0;
    if (hdf5_s) *hdf5_s = s ? s->out.seconds[T_HDF5] : 0.0;
    if (checkpoint_s) *checkpoint_s = s ? s->out.seconds[T_CKPT] : 0.0;
}
