/*
 * writers.c -- per-point distances to files: CSV, PLY or NPY by extension,
 * and the colour map that turns a distance into a colour.
 *
 * Every format carries the same columns, one row per point in the input
 * file's order: x, y, z (the coordinates as read, widened to double), the
 * distance to the nearest point of the other set, and `nearest`, the
 * 0-based index of that point (-1 when the other set is empty).
 *  - CSV: a header line `x,y,z,distance,nearest`, then numbers printed with
 *    17 significant digits, which read back as the same doubles.
 *  - PLY: binary_little_endian, `vertex` with double x y z distance, int
 *    nearest (double when an index exceeds 2^31 - 1) and uchar red green
 *    blue: the distance's colour, so that any viewer (MeshLab,
 *    CloudCompare) shows the deviation at once.
 *  - NPY: a plain (N, 5) float64 array, C order, columns as above; indices
 *    are exact in a double up to 2^53.
 * Colours come from viridis (perceptually uniform, readable in grey and by
 * colour-blind readers): 64 samples of matplotlib's table (CC0, by Nathaniel
 * Smith and Stefan van der Walt), interpolated linearly, at d / dmax clipped
 * to [0, 1].
 *
 * A file is written through output.c: into a temporary beside it, renamed
 * over the name only when the whole run has succeeded.  Each writer stops at
 * the first write that fails and returns its errno (a full disk is not
 * worth a million more failing rows); out_close checks the rest (fflush,
 * ferror, fclose), so a file is either complete or absent, and its loss is
 * an output failure (exit status 3), never a quiet success.
 */
#include "analysis.h"
#include "cli.h"
#include "output.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static const unsigned char viridis[64][3] = {
    {68, 1, 84}, {70, 7, 90}, {71, 13, 96}, {71, 19, 101},
    {72, 24, 106}, {72, 29, 111}, {72, 35, 116}, {72, 40, 120},
    {71, 45, 123}, {70, 50, 126}, {69, 55, 129}, {68, 59, 132},
    {66, 64, 134}, {64, 69, 136}, {62, 73, 137}, {61, 78, 138},
    {58, 83, 139}, {56, 88, 140}, {54, 92, 141}, {52, 96, 141},
    {50, 100, 142}, {49, 104, 142}, {47, 108, 142}, {45, 112, 142},
    {44, 115, 142}, {42, 119, 142}, {41, 123, 142}, {39, 127, 142},
    {38, 130, 142}, {36, 134, 142}, {35, 138, 141}, {33, 142, 141},
    {32, 146, 140}, {31, 150, 139}, {31, 154, 138}, {31, 158, 137},
    {31, 161, 135}, {33, 165, 133}, {35, 169, 131}, {38, 173, 129},
    {42, 176, 127}, {47, 180, 124}, {53, 183, 121}, {59, 187, 117},
    {66, 190, 113}, {74, 193, 109}, {82, 197, 105}, {90, 200, 100},
    {101, 203, 94}, {110, 206, 88}, {119, 209, 83}, {129, 211, 77},
    {139, 214, 70}, {149, 216, 64}, {160, 218, 57}, {170, 220, 50},
    {181, 222, 43}, {192, 223, 37}, {202, 225, 31}, {213, 226, 26},
    {223, 227, 24}, {234, 229, 26}, {244, 230, 30}, {253, 231, 37},
};

void colormap_viridis(double t, unsigned char rgb[3]) {
    if (!(t > 0.0)) t = 0.0; /* NaN too */
    if (t > 1.0) t = 1.0;
    double x = t * 63.0;
    int k = (int)x;
    if (k > 62) k = 62;
    double f = x - k;
    for (int c = 0; c < 3; c++) {
        double v = viridis[k][c] + (viridis[k + 1][c] - viridis[k][c]) * f;
        rgb[c] = (unsigned char)(v + 0.5);
    }
}

static int format_of(const char *path) {
    const char *dot = strrchr(path, '.');
    if (!dot) return DIST_UNKNOWN;
    if (strcasecmp(dot, ".csv") == 0) return DIST_CSV;
    if (strcasecmp(dot, ".ply") == 0) return DIST_PLY;
    if (strcasecmp(dot, ".npy") == 0) return DIST_NPY;
    return DIST_UNKNOWN;
}

_Static_assert(DIST_ROW_MAX >= 4 * NUM_TEXT + 32, "a CSV row fits");

static void put_le(unsigned char *p, const void *v, size_t n) {
    const unsigned char *s = v;
    unsigned one = 1;
    int little = *(const unsigned char *)&one == 1;
    for (size_t k = 0; k < n; k++) p[k] = little ? s[k] : s[n - 1 - k];
}

int distances_layout(const char *path, size_t count, double dmax, int wide, dist_layout_t *f, hd_error_t *err) {
    f->format = format_of(path);
    f->count = count;
    f->dmax = dmax;
    f->wide = wide;
    if (f->format != DIST_UNKNOWN) return HD_OK;
    snprintf(err->message, sizeof err->message, "%s: cannot tell the output format; name it .csv, .ply or .npy",
             path);
    return err->code = HD_EUNSUPPORTED;
}

int distances_wide(const size_t *nearest, size_t n) {
    int wide = 0;
    for (size_t k = 0; nearest && k < n; k++) wide |= nearest[k] > 2147483647u;
    return wide;
}

/* An NPY header of a (count, cols) float64 array: magic (6) + version (2)
 * + length (2) + dict, padded with spaces and a newline to a multiple of
 * 64 bytes. */
static int npy_header(char buf[DIST_HEAD_MAX], size_t count, int cols) {
    char dict[128];
    int m = snprintf(dict, sizeof dict, "{'descr': '<f8', 'fortran_order': False, 'shape': (%zu, %d), }", count,
                     cols);
    size_t total = 10 + (size_t)m + 1, padded = (total + 63) / 64 * 64;
    unsigned char head[10] = {0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0, 0, 0};
    uint16_t hl = (uint16_t)(padded - 10);
    put_le(head + 8, &hl, 2);
    memcpy(buf, head, 10);
    memcpy(buf + 10, dict, (size_t)m);
    memset(buf + 10 + m, ' ', padded - total);
    buf[padded - 1] = '\n';
    return (int)padded;
}

size_t distances_header(const dist_layout_t *f, char buf[DIST_HEAD_MAX]) {
    int n = 0;
    if (f->format == DIST_CSV) {
        n = snprintf(buf, DIST_HEAD_MAX, "x,y,z,distance,nearest\n");
    } else if (f->format == DIST_PLY) {
        char dm[NUM_TEXT];
        n = snprintf(buf, DIST_HEAD_MAX, "ply\nformat binary_little_endian 1.0\n"
                     "comment written by hausdorff %s: distance to the nearest point of the other set\n"
                     "comment colour: viridis, 0 to %s\n"
                     "element vertex %zu\n"
                     "property double x\nproperty double y\nproperty double z\n"
                     "property double distance\nproperty %s nearest\n"
                     "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n",
                     hd_version(), num_text(f->dmax, dm), f->count, f->wide ? "double" : "int");
    } else {
        n = npy_header(buf, f->count, 5);
    }
    return n < 0 ? 0 : (size_t)n;
}

size_t distances_row(const dist_layout_t *f, const double q[3], double d, const size_t *nearest,
                     unsigned char buf[DIST_ROW_MAX]) {
    if (f->format == DIST_CSV) {
        char t[4][NUM_TEXT];
        int n;
        if (nearest)
            n = snprintf((char *)buf, DIST_ROW_MAX, "%s,%s,%s,%s,%zu\n", num_text(q[0], t[0]), num_text(q[1], t[1]),
                         num_text(q[2], t[2]), num_text(d, t[3]), *nearest);
        else
            n = snprintf((char *)buf, DIST_ROW_MAX, "%s,%s,%s,%s,-1\n", num_text(q[0], t[0]), num_text(q[1], t[1]),
                         num_text(q[2], t[2]), num_text(d, t[3]));
        return n < 0 ? 0 : (size_t)n;
    }
    double v[5] = {q[0], q[1], q[2], d, nearest ? (double)*nearest : -1.0};
    size_t o = 0;
    for (int c = 0; c < 4; c++, o += 8) put_le(buf + o, &v[c], 8);
    if (f->format == DIST_NPY || f->wide) {
        put_le(buf + o, &v[4], 8);
        o += 8;
    } else {
        int32_t j = nearest ? (int32_t)*nearest : -1;
        put_le(buf + o, &j, 4);
        o += 4;
    }
    if (f->format == DIST_PLY) {
        colormap_viridis(f->dmax > 0 ? d / f->dmax : 0.0, buf + o);
        o += 3;
    }
    return o;
}

/* errno of a failed write; -1 when unknown, never 0 */
static int write_errno(void) { return errno ? errno : -1; }

/* One file of rows: the header, then row(k) for every point (its bytes in
 * buf, at most ROW_MAX), stopping at the first write that fails. */
enum { ROW_MAX = 12 * NUM_TEXT + 64 };
typedef size_t (*row_fn)(const dist_layout_t *f, const double q[3], size_t k, const void *ctx,
                         unsigned char buf[ROW_MAX]);

static int write_rows(const char *path, const hd_points_t *P, const dist_layout_t *lay, const char *head,
                      size_t n, row_fn row, const void *ctx, hd_error_t *err) {
    FILE *f = out_open(path, err);
    if (!f) return err->code;
    errno = 0;
    int werr = fwrite(head, 1, n, f) != n ? write_errno() : 0;
    unsigned char buf[ROW_MAX];
    for (size_t k = 0; k < P->count && !werr; k++) {
        double q[3];
        hd_points_get(P, k, q);
        n = row(lay, q, k, ctx, buf);
        if (fwrite(buf, 1, n, f) != n) werr = write_errno();
    }
    return out_close(f, werr, err);
}

typedef struct {
    const double *d;
    const size_t *nearest;
} plain_cols_t;

static size_t plain_row(const dist_layout_t *f, const double q[3], size_t k, const void *ctx,
                        unsigned char buf[ROW_MAX]) {
    const plain_cols_t *c = ctx;
    return distances_row(f, q, c->d[k], c->nearest ? &c->nearest[k] : NULL, buf);
}

_Static_assert((int)ROW_MAX >= (int)DIST_ROW_MAX, "a row of write_distances fits");

int write_distances(const char *path, const hd_points_t *P, const double *d,
                    const size_t *nearest, double dmax, hd_error_t *err) {
    dist_layout_t lay;
    if (distances_layout(path, P->count, dmax, distances_wide(nearest, P->count), &lay, err)) return err->code;
    char head[DIST_HEAD_MAX];
    size_t n = distances_header(&lay, head);
    plain_cols_t c = {d, nearest};
    return write_rows(path, P, &lay, head, n, plain_row, &c, err);
}

int distances_format_known(const char *path) { return format_of(path) != DIST_UNKNOWN; }

/* ---- distances to a surface (--surface) ---------------------------------------- */


static size_t surface_header(const dist_layout_t *f, int sign, char buf[DIST_HEAD_MAX]) {
    int n = 0;
    if (f->format == DIST_CSV) {
        n = snprintf(buf, DIST_HEAD_MAX, "x,y,z,distance,face,closest_x,closest_y,closest_z,u,v,w%s\n",
                     sign ? ",sign" : "");
    } else if (f->format == DIST_PLY) {
        char dm[NUM_TEXT];
        n = snprintf(buf, DIST_HEAD_MAX, "ply\nformat binary_little_endian 1.0\n"
                     "comment written by hausdorff %s: distance to the nearest face of the surface of B\n"
                     "comment colour: viridis, 0 to %s\n"
                     "element vertex %zu\n"
                     "property double x\nproperty double y\nproperty double z\n"
                     "property double distance\nproperty %s face\n"
                     "property double closest_x\nproperty double closest_y\nproperty double closest_z\n"
                     "property double u\nproperty double v\nproperty double w\n%s"
                     "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n",
                     hd_version(), num_text(f->dmax, dm), f->count, f->wide ? "double" : "int",
                     sign ? "property char sign\n" : "");
    } else {
        n = npy_header(buf, f->count, sign ? 12 : 11);
    }
    return n < 0 ? 0 : (size_t)n;
}

static size_t surface_row(const dist_layout_t *f, const double q[3], double d, const surface_columns_t *c,
                          size_t k, unsigned char buf[ROW_MAX]) {
    const double *cp = c->closest + 3 * k, *b = c->bary + 3 * k;
    if (f->format == DIST_CSV) {
        char t[10][NUM_TEXT], sg[8] = "";
        if (c->sign) snprintf(sg, sizeof sg, ",%d", c->sign[k]);
        int n = snprintf((char *)buf, ROW_MAX, "%s,%s,%s,%s,%zu,%s,%s,%s,%s,%s,%s%s\n", num_text(q[0], t[0]),
                         num_text(q[1], t[1]), num_text(q[2], t[2]), num_text(d, t[3]), c->face[k],
                         num_text(cp[0], t[4]), num_text(cp[1], t[5]), num_text(cp[2], t[6]), num_text(b[0], t[7]),
                         num_text(b[1], t[8]), num_text(b[2], t[9]), sg);
        return n < 0 ? 0 : (size_t)n;
    }
    size_t o = 0;
    double v[4] = {q[0], q[1], q[2], d}, face = (double)c->face[k];
    for (int i = 0; i < 4; i++, o += 8) put_le(buf + o, &v[i], 8);
    if (f->format == DIST_NPY || f->wide) {
        put_le(buf + o, &face, 8);
        o += 8;
    } else {
        int32_t j = (int32_t)c->face[k];
        put_le(buf + o, &j, 4);
        o += 4;
    }
    for (int i = 0; i < 3; i++, o += 8) put_le(buf + o, &cp[i], 8);
    for (int i = 0; i < 3; i++, o += 8) put_le(buf + o, &b[i], 8);
    if (c->sign && f->format == DIST_NPY) {
        double s = c->sign[k];
        put_le(buf + o, &s, 8);
        o += 8;
    } else if (c->sign) {
        buf[o++] = (unsigned char)c->sign[k];
    }
    if (f->format == DIST_PLY) {
        colormap_viridis(f->dmax > 0 ? d / f->dmax : 0.0, buf + o);
        o += 3;
    }
    return o;
}

typedef struct {
    const double *d;
    const surface_columns_t *c;
} surf_cols_t;

static size_t surf_row(const dist_layout_t *f, const double q[3], size_t k, const void *ctx,
                       unsigned char buf[ROW_MAX]) {
    const surf_cols_t *s = ctx;
    return surface_row(f, q, s->d[k], s->c, k, buf);
}

int write_surface_distances(const char *path, const hd_points_t *P, const double *d,
                            const surface_columns_t *c, double dmax, hd_error_t *err) {
    dist_layout_t lay;
    if (distances_layout(path, P->count, dmax, distances_wide(c->face, P->count), &lay, err)) return err->code;
    char head[DIST_HEAD_MAX];
    size_t n = surface_header(&lay, c->sign != NULL, head);
    surf_cols_t s = {d, c};
    return write_rows(path, P, &lay, head, n, surf_row, &s, err);
}
