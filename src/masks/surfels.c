/*
 * surfels.c -- a binary image's surface as surfels, the elements DeepMind's
 * surface-distance weighs by area (and MONAI's compute_surface_dice with
 * use_subvoxels=True): one per cube of 2 x 2 x 2 voxels (2 x 2 pixels in
 * 2-D) whose corners are neither all foreground nor all background, placed
 * at the cube's centre, its area that of the marching-cubes surface inside
 * the cube.
 *
 * The polygons of each of the 256 corner configurations are derived here,
 * not tabulated: the surface crosses each cube edge whose two corners
 * differ, at its midpoint; on each face the crossings pair into segments
 * (two crossings: one segment; four, the face's two foreground corners
 * diagonal: each foreground corner is cut off on its own, so foreground
 * meets across an edge of the cube, never across a face diagonal); every
 * crossing lies on two faces, so the segments close into loops, the
 * polygons.  A configuration of more than four foreground corners takes
 * the polygons of its complement (the same boundary seen from the other
 * side), so that a configuration and its complement have one area.  Each
 * loop is cut into a fan of triangles from one of its crossings, and a
 * surfel's area is the sum of its triangles' areas after the image's
 * linear map (the spacing): for an axis-aligned map this is DeepMind's
 * scaling of each triangle's area vector by the products of the other
 * axes' spacings.  A planar loop (every loop of one, two or four
 * face-adjacent corners, i.e. all that flat or axis-aligned boundaries
 * produce) is convex, and every fan gives its area.  A non-planar loop
 * (three corners of a face; four corners in a chain) has no one area; the
 * fan taken is the one of largest area, which depends on no numbering of
 * the cube (a fan is a set of triangles whatever the walk's start or
 * direction, and each sum is taken in sorted order), so a rotation or
 * reflection of the image (with isotropic spacing) leaves every surfel's
 * area unchanged; on those loops it is the triangulation of the classic
 * marching-cubes table, as the areas of DeepMind's table show
 * (docs/analysis.md, "Surfels").
 * In 2-D the cubes are squares, the loops segments between edge midpoints
 * (marching squares), a surfel's "area" their length.
 */
#include "masks.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Corner v of the unit cube is (v & 1, v >> 1 & 1, v >> 2 & 1).  Edge e
 * runs from corner *c0 to *c1 along axis e / 4 (edge_corners). */
static void edge_corners(int e, int *c0, int *c1) {
    int axis = e / 4, q = e % 4; /* q: the other two bits, low first */
    int lo = axis == 0 ? 1 : 0, hi = axis == 2 ? 1 : 2;
    int v = ((q & 1) << lo) | ((q >> 1 & 1) << hi);
    *c0 = v;
    *c1 = v | 1 << axis;
}

static int edge_of(int v, int w) {
    int axis = (v ^ w) == 1 ? 0 : (v ^ w) == 2 ? 1 : 2;
    int base = v & w, lo = axis == 0 ? 1 : 0, hi = axis == 2 ? 1 : 2;
    return axis * 4 + (base >> lo & 1) + 2 * (base >> hi & 1);
}

/* The crossing edges of `code`'s loops, each loop's edges in walking order,
 * loops separated by -1 (at most 12 crossings and 4 loops). */
static int loops_of(int code, int dims, int *out) {
    int popc = 0;
    for (int v = 0; v < 8; v++) popc += code >> v & 1;
    if (popc > 4) code ^= 0xff;
    int nbr[12][2], deg[12] = {0}, n2 = 0;
    int faces = dims == 2 ? 1 : 6;
    for (int f = 0; f < faces; f++) {
        int axis = dims == 2 ? 2 : f / 2, side = dims == 2 ? 0 : f % 2;
        int b = axis == 0 ? 1 : 0, c = axis == 2 ? 1 : 2, q[4];
        int corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
        for (int t = 0; t < 4; t++) q[t] = side << axis | corner[t][0] << b | corner[t][1] << c;
        int cross[4], nc = 0, e[4];
        for (int t = 0; t < 4; t++) {
            e[t] = edge_of(q[t], q[(t + 1) % 4]);
            if ((code >> q[t] & 1) != (code >> q[(t + 1) % 4] & 1)) cross[nc++] = t;
        }
        int pair[2][2], np = 0;
        if (nc == 2) pair[np][0] = e[cross[0]], pair[np++][1] = e[cross[1]];
        else if (nc == 4) {
            int first = code >> q[0] & 1 ? 3 : 0; /* cut off each foreground corner */
            for (int s = 0; s < 2; s++) pair[np][0] = e[(first + 2 * s) % 4], pair[np++][1] = e[(first + 2 * s + 1) % 4];
        }
        for (int s = 0; s < np; s++) {
            int x = pair[s][0], y = pair[s][1];
            if (dims == 2) { /* one face: each segment is a loop */
                out[n2++] = x, out[n2++] = y, out[n2++] = -1;
                continue;
            }
            nbr[x][deg[x]++] = y;
            nbr[y][deg[y]++] = x;
        }
    }
    if (dims == 2) return n2;
    int used[12] = {0}, n = 0;
    for (int e0 = 0; e0 < 12; e0++) {
        if (!deg[e0] || used[e0]) continue;
        int prev = -1, cur = e0;
        do {
            used[cur] = 1;
            out[n++] = cur;
            int next = nbr[cur][0] != prev ? nbr[cur][0] : nbr[cur][1];
            prev = cur;
            cur = next;
        } while (cur != e0 && !used[cur]);
        out[n++] = -1;
    }
    return n;
}

static void midpoint(int e, double p[3]) {
    int c0, c1;
    edge_corners(e, &c0, &c1);
    for (int a = 0; a < 3; a++) p[a] = ((c0 >> a & 1) + (c1 >> a & 1)) * 0.5;
}

static void mapped(const double lin[3][3], const double p[3], double q[3]) {
    for (int c = 0; c < 3; c++) q[c] = (lin[c][0] * p[0] + lin[c][1] * p[1]) + lin[c][2] * p[2];
}

static double norm3(const double v[3]) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

/* The area of one loop (or, in 2-D, the length of one segment). */
static int by_value(const void *x, const void *y) {
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

/* The sum of n values in ascending order: the same double whatever order
 * they came in (a loop's crossings are walked in an order that depends on
 * the numbering of the cube's edges, which the axes' order changes). */
static double sorted_sum(double *v, int n) {
    qsort(v, (size_t)n, sizeof *v, by_value);
    double s = 0;
    for (int t = 0; t < n; t++) s += v[t];
    return s;
}

/* Appends to part[] the areas of one loop's triangles (or, in 2-D, the
 * length of one segment); returns how many. */
static int loop_parts(const int *loop, int len, int dims, const double lin[3][3], double *part) {
    double p[12][3];
    for (int t = 0; t < len; t++) {
        double u[3];
        midpoint(loop[t], u);
        mapped(lin, u, p[t]);
    }
    if (dims == 2) {
        double d[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
        part[0] = len == 2 ? norm3(d) : 0.0;
        return 1;
    }
    /* the fan from crossing f: triangles (f, t, t + 1) around the loop; as
     * a set it does not depend on where the walk started or its direction */
    double best = -1, fan[12];
    int nfan = len - 2;
    for (int f = 0; f < len; f++) {
        double tri[12];
        for (int t = 1; t + 1 < len; t++) {
            const double *p0 = p[f], *p1 = p[(f + t) % len], *p2 = p[(f + t + 1) % len];
            double u[3], v[3], w[3];
            for (int q = 0; q < 3; q++) u[q] = p1[q] - p0[q], v[q] = p2[q] - p0[q];
            w[0] = u[1] * v[2] - u[2] * v[1];
            w[1] = u[2] * v[0] - u[0] * v[2];
            w[2] = u[0] * v[1] - u[1] * v[0];
            tri[t - 1] = norm3(w) / 2;
        }
        double sum = sorted_sum(tri, nfan);
        if (sum > best) {
            best = sum;
            memcpy(fan, tri, (size_t)nfan * sizeof *fan);
        }
    }
    memcpy(part, fan, (size_t)nfan * sizeof *part);
    return nfan;
}

void hd__surfel_areas(int dims, const double lin[3][3], double area[256]) {
    int codes = dims == 2 ? 16 : 256;
    memset(area, 0, 256 * sizeof *area);
    for (int code = 1; code < codes - 1; code++) {
        int ed[48], n = loops_of(code, dims, ed), start = 0, np = 0;
        double part[48];
        for (int t = 0; t < n; t++)
            if (ed[t] < 0) {
                np += loop_parts(ed + start, t - start, dims, lin, part + np);
                start = t + 1;
            }
        area[code] = sorted_sum(part, np);
    }
}

int hd__surfel_loops(int code, int dims, int *edges) { return loops_of(code, dims, edges); }

/* ---- extraction over a window ---------------------------------------------------- */

static int push_surfel(hd__surfels_t *s, double x, double y, double z, double area) {
    if (s->count == s->cap) {
        size_t cap = s->cap ? 2 * s->cap : 1024;
        double *xyz = realloc(s->xyz, cap * 3 * sizeof *xyz), *ar;
        if (!xyz) return -1;
        s->xyz = xyz;
        ar = realloc(s->area, cap * sizeof *ar);
        if (!ar) return -1;
        s->area = ar;
        s->cap = cap;
    }
    s->xyz[3 * s->count] = x, s->xyz[3 * s->count + 1] = y, s->xyz[3 * s->count + 2] = z;
    s->area[s->count++] = area;
    return 0;
}

/* The window with one voxel of background around it (0 or 1 each), so that
 * every cube meeting the window reads its corners without a test. */
static uint8_t *padded(const uint8_t *fg, const size_t w[3], int dims, size_t p[3]) {
    for (int a = 0; a < 3; a++) p[a] = w[a] + (a < 2 || dims == 3 ? 2 : 0);
    size_t kp = dims == 3 ? 1 : 0;
    uint8_t *out = calloc(p[0] * p[1] * p[2], 1);
    if (!out) return NULL;
    for (size_t k = 0; k < w[2]; k++)
        for (size_t j = 0; j < w[1]; j++) {
            const uint8_t *src = fg + (k * w[1] + j) * w[0];
            uint8_t *dst = out + ((k + kp) * p[1] + j + 1) * p[0] + 1;
            for (size_t i = 0; i < w[0]; i++) dst[i] = src[i] != 0;
        }
    return out;
}

int hd__window_surfels(const uint8_t *fg, const size_t w[3], const size_t off[3], const double m[3][4], double scale,
                       int dims, const double area[256], hd__surfels_t *out) {
    size_t p[3];
    uint8_t *pad = padded(fg, w, dims, p);
    if (!pad) return -1;
    int full = dims == 2 ? 15 : 255, rc = 0;
    size_t cubes_k = dims == 2 ? p[2] : p[2] - 1, dk = dims == 2 ? 0 : p[0] * p[1];
    /* cube (i, j, k) of the padded window covers its voxels i..i+1, j..j+1
     * (k..k+1): the window's cube (i - 1, j - 1, k - 1) (k itself in 2-D).
     * col[i] holds the corners of column i at their bit (v & 1 = 0), and
     * the cube's code is col[i] | col[i + 1] << 1. */
    uint8_t *col = malloc(p[0]);
    if (!col) {
        free(pad);
        return -1;
    }
    for (size_t k = 0; k < cubes_k && !rc; k++)
        for (size_t j = 0; j + 1 < p[1] && !rc; j++) {
            const uint8_t *r00 = pad + (k * p[1] + j) * p[0], *r10 = r00 + p[0];
            int any = 0;
            for (size_t i = 0; i < p[0]; i++) {
                int c = r00[i] | r10[i] << 2;
                if (dims == 3) c |= r00[i + dk] << 4 | r10[i + dk] << 6;
                col[i] = (uint8_t)c;
                any |= c;
            }
            if (!any) continue;
            for (size_t i = 0; i + 1 < p[0]; i++) {
                int code = col[i] | col[i + 1] << 1;
                if (code == 0 || code == full) continue;
                double ci = (double)off[0] + (double)i - 0.5, cj = (double)off[1] + (double)j - 0.5;
                double ck = dims == 2 ? (double)(off[2] + k) : (double)off[2] + (double)k - 0.5;
                if (push_surfel(out, hd__voxel_world(m, scale, 0, ci, cj, ck), hd__voxel_world(m, scale, 1, ci, cj, ck),
                                hd__voxel_world(m, scale, 2, ci, cj, ck), area[code]) < 0) {
                    rc = -1;
                    break;
                }
            }
        }
    free(col);
    free(pad);
    return rc;
}

void hd__surfels_free(hd__surfels_t *s) {
    free(s->xyz);
    free(s->area);
    memset(s, 0, sizeof *s);
}
