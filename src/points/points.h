/*
 * points.h -- point sets and the geometry every algorithm shares
 * (src/points/): the squared distance, boxes, the running maximum with its
 * witness, Morton keys, views and their validation, sources (how a view's
 * coordinates are read) and the radix sort of Morton keys.
 *
 * The one rule every module obeys is here: squared distances are evaluated
 * by hd__d2() and nothing else, as dx*dx + dy*dy + dz*dz left to right.  The
 * build passes -ffp-contract=off so no compiler fuses a multiply into an add;
 * with that, every algorithm computes exactly the doubles the brute force
 * computes, and since the only other operations on them are comparisons and
 * one final sqrt, results agree to the bit.
 *
 * Bounds on boxes are evaluated with the same operation order (hd__box_lb2,
 * hd__box_ub2).  IEEE rounding is monotone: if |u| <= |v| exactly then
 * fl(u*u) <= fl(v*v), and fl(fl(a+b)+c) is monotone in each argument.  A
 * box whose faces are coordinates of points it contains (or any doubles that
 * enclose those points exactly) therefore gives a computed lower bound no
 * larger, and a computed upper bound no smaller, than the computed squared
 * distance to any point inside.  That is why no epsilon appears in the
 * pruning tests: they compare values that rounding cannot reorder.
 */
#ifndef HD_POINTS_H
#define HD_POINTS_H

#include "base/base.h"

/* ---- the squared distance ------------------------------------------- */
HD__INLINE double hd__d2(const double *p, const double *q) {
    double dx = p[0] - q[0];
    double dy = p[1] - q[1];
    double dz = p[2] - q[2];
    return dx * dx + dy * dy + dz * dz;
}

/* Same function on separate coordinates (structure-of-arrays callers). */
HD__INLINE double hd__d2s(double px, double py, double pz, double qx, double qy,
                          double qz) {
    double dx = px - qx;
    double dy = py - qy;
    double dz = pz - qz;
    return dx * dx + dy * dy + dz * dz;
}

/* ---- boxes -------------------------------------------------------------- */
typedef struct hd__box {
    double lo[3], hi[3];
} hd__box_t;

/* Grow `into` to hold the box b too. */
HD__INLINE void hd__box_merge(hd__box_t *into, const hd__box_t *b) {
    for (int k = 0; k < 3; k++) {
        into->lo[k] = b->lo[k] < into->lo[k] ? b->lo[k] : into->lo[k];
        into->hi[k] = b->hi[k] > into->hi[k] ? b->hi[k] : into->hi[k];
    }
}

/* Smallest computed squared distance from p to any point in the box. */
HD__INLINE double hd__box_lb2(const hd__box_t *b, const double *p) {
    double d[3];
    for (int k = 0; k < 3; k++) {
        double v = 0.0;
        if (p[k] < b->lo[k]) v = b->lo[k] - p[k];
        else if (p[k] > b->hi[k]) v = p[k] - b->hi[k];
        d[k] = v;
    }
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
}

/* Largest computed squared distance from p to any point in the box (the
 * farthest corner). */
HD__INLINE double hd__box_ub2(const hd__box_t *b, const double *p) {
    double d[3];
    for (int k = 0; k < 3; k++) {
        double u = p[k] - b->lo[k], v = b->hi[k] - p[k];
        if (u < 0) u = -u;
        if (v < 0) v = -v;
        d[k] = u > v ? u : v;
    }
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
}

/* Box of n packed xyz doubles (n > 0). */
void hd__box_of(const double *xyz, size_t n, hd__box_t *out);
/* The same box, and whether every coordinate v has |v| <= HD_MAX_COORD
 * (1; 0 when one is larger, infinite or NaN, and then the box is
 * meaningless).  The one loop both hd__box_of and hd__points_scan run. */
int hd__box_checked(const double *xyz, size_t n, hd__box_t *out);

/* The computed lower bound hd__box_lb2 without branches (same values: the
 * gap on each axis is max(lo - p, p - hi, 0), evaluated as in hd__box_lb2). */
HD__INLINE double hd__box_lb2s(const hd__box_t *b, double x, double y, double z) {
    double u, v, gx, gy, gz;
    u = b->lo[0] - x, v = x - b->hi[0], gx = u > v ? u : v, gx = gx > 0 ? gx : 0;
    u = b->lo[1] - y, v = y - b->hi[1], gy = u > v ? u : v, gy = gy > 0 ? gy : 0;
    u = b->lo[2] - z, v = z - b->hi[2], gz = u > v ? u : v, gz = gz > 0 ? gz : 0;
    return gx * gx + gy * gy + gz * gz;
}

/* Smallest computed squared distance between a point of box a and a point of
 * box b (0 when they meet).  Same operation order as hd__d2: with exact
 * boxes it never exceeds hd__d2 of a point pair drawn from them.  The one
 * box-to-box bound: INC's MBRs (classic/) and the engine's walk over two
 * trees (engine/walk.c) both use it. */
HD__INLINE double hd__box_box_lb2(const hd__box_t *a, const hd__box_t *b) {
    double d[3];
    for (int k = 0; k < 3; k++) {
        double v = 0.0;
        if (b->lo[k] > a->hi[k]) v = b->lo[k] - a->hi[k];
        else if (a->lo[k] > b->hi[k]) v = a->lo[k] - b->hi[k];
        d[k] = v;
    }
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
}

/* Largest computed squared distance between a point of box a and a point of
 * box b (the farthest pair of corners); never below hd__d2 of such a pair. */
HD__INLINE double hd__box_box_ub2(const hd__box_t *a, const hd__box_t *b) {
    double d[3];
    for (int k = 0; k < 3; k++) {
        double u = a->hi[k] - b->lo[k], v = b->hi[k] - a->lo[k];
        if (u < 0) u = -u;
        if (v < 0) v = -v;
        d[k] = u > v ? u : v;
    }
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
}

/* ---- the running maximum with its witness ------------------------------- */
/* best.d2 = -1 means "nothing yet".  Merge keeps the larger d2 and, on a
 * tie, the smaller i: so the witness is independent of evaluation order. */
typedef struct hd__best {
    double d2;
    size_t i, j;
} hd__best_t;

HD__INLINE void hd__best_init(hd__best_t *b) {
    b->d2 = -1.0;
    b->i = HD__NONE;
    b->j = HD__NONE;
}

HD__INLINE void hd__best_offer(hd__best_t *b, double d2, size_t i, size_t j) {
    if (d2 > b->d2 || (d2 == b->d2 && i < b->i)) {
        b->d2 = d2;
        b->i = i;
        b->j = j;
    }
}

/* Merge the partial results of n tasks into b (in task order; by the tie
 * rule the result would be the same in any order). */
HD__INLINE void hd__best_merge(hd__best_t *b, const hd__best_t *part, size_t n) {
    for (size_t t = 0; t < n; t++) hd__best_offer(b, part[t].d2, part[t].i, part[t].j);
}

/* Store b's squared distance and witness in a directed result. */
HD__INLINE void hd__best_store(const hd__best_t *b, hd_result_t *out) {
    out->distance2 = b->d2;
    out->i = b->i;
    out->j = b->j;
}

/* ---- Morton keys -------------------------------------------------------- */
/* Cubic cells over a box, 1024 per axis along its longest side (cell =
 * (c - lo) * scale, clamped to the grid), and the 30-bit Morton key of a
 * point's cell.  Keys only order points along the curve, for locality: any
 * value would be correct, so no rounding argument is needed here. */
typedef struct hd__keygrid {
    double lo[3], scale;
} hd__keygrid_t;

HD__INLINE void hd__keygrid_init(hd__keygrid_t *g, const hd__box_t *b) {
    double ext = 0;
    for (int k = 0; k < 3; k++) {
        g->lo[k] = b->lo[k];
        ext = b->hi[k] - b->lo[k] > ext ? b->hi[k] - b->lo[k] : ext;
    }
    g->scale = ext > 0 ? 1024.0 / ext : 0.0;
}

/* The 10 bits of v (< 1024) spread to every third bit (Morton
 * interleaving): a table of 4 KB (source.c), one read per coordinate
 * instead of some fifteen operations. */
extern const uint32_t hd__spread_table[1024];

HD__INLINE uint32_t hd__spread10(uint32_t v) { return hd__spread_table[v & 0x3ffu]; }

/* The cell of `g` holding coordinate v on axis k, clamped to the grid
 * (min and max rather than branches: the same cells for finite v). */
HD__INLINE uint32_t hd__key_cell(const hd__keygrid_t *g, int k, double v) {
    double u = (v - g->lo[k]) * g->scale;
    u = u < 1023.0 ? u : 1023.0;
    u = u > 0 ? u : 0;
    return (uint32_t)u;
}

HD__INLINE uint32_t hd__key30(const hd__keygrid_t *g, const double p[3]) {
    return hd__spread10(hd__key_cell(g, 0, p[0])) | hd__spread10(hd__key_cell(g, 1, p[1])) << 1 |
           hd__spread10(hd__key_cell(g, 2, p[2])) << 2;
}

/* ---- point sets --------------------------------------------------------- */
/* Validate a view (non-empty, finite, |c| <= HD_MAX_COORD) and compute its
 * box in the same pass.  `what` names the set in messages ("A", "B"). */
/* HD_OK, or HD_EINVAL when a packed view (read through double or float
 * pointers) is not aligned to its element; views with other strides are
 * read byte by byte and may lie anywhere.  hd__points_check calls it. */
int hd__points_aligned(const hd_points_t *p, const char *what, hd_error_t *err);
int hd__points_check(const hd_points_t *p, const char *what, hd__box_t *box,
                     hd_error_t *err);

/* Packed doubles for a view: borrowed when the view already is packed
 * doubles, else a new copy in *owned (free it).  T, if not NULL, is applied
 * (which always copies). */
int hd__points_f64(const hd_points_t *p, const hd_transform_t *T,
                   double **owned, const double **xyz, hd_error_t *err);

/* Apply T to one point, in the documented order. */
HD__INLINE void hd__transform_apply(const hd_transform_t *T, const double *p,
                                    double *o) {
    const double *r = T->r;
    o[0] = ((r[0] * p[0] + r[1] * p[1]) + r[2] * p[2]) + T->t[0];
    o[1] = ((r[3] * p[0] + r[4] * p[1]) + r[5] * p[2]) + T->t[1];
    o[2] = ((r[6] * p[0] + r[7] * p[1]) + r[8] * p[2]) + T->t[2];
}

/* hd__points_check's result, computed with `threads` threads by a fast pass
 * for packed views (scan.c); any problem is reported by
 * hd__points_check itself. */
int hd__points_scan(const hd_points_t *p, const char *what, int threads,
                    hd__box_t *box, hd_error_t *err);

/* ---- sources: where the coordinates of a set come from (source.c) ---------- */
/* How a source's points lie in memory.  The hot loops test the kind to
 * skip the general path; the values are fixed (0, 1, 2). */
typedef enum hd__src_kind {
    HD__SRC_F64 = 0, /* packed doubles: point k at base + 24 k */
    HD__SRC_F32 = 1, /* packed floats: point k at base + 12 k */
    HD__SRC_ANY = 2  /* any element type and strides (ps, cs) */
} hd__src_kind_t;

/* Where the coordinates of a set come from. */
typedef struct hd__src {
    const char *base;
    ptrdiff_t ps, cs;           /* point and coordinate strides in bytes */
    hd__src_kind_t kind;        /* the layout: packed double, packed float or any */
    hd_dtype_t dtype;
    const hd_transform_t *T;    /* applied to every point read, or NULL */
} hd__src_t;

void hd__src_init(hd__src_t *s, const hd_points_t *p, const hd_transform_t *T);

/* The bytes from one point to the next of a packed source (HD__SRC_F64 or
 * HD__SRC_F32): what a prefetch of point k adds to base, k times.  The
 * one place the two packed strides are written for the readers ahead. */
HD__INLINE ptrdiff_t hd__src_packed_stride(const hd__src_t *s) {
    return s->kind == HD__SRC_F64 ? 24 : 12;
}

/* Point k of the source (original numbering), transformed if T is set. */
HD__INLINE void hd__src_get(const hd__src_t *s, size_t k, double out[3]) {
    double p[3];
    if (s->kind == HD__SRC_F64) {
        const double *q = (const double *)(const void *)(s->base + (ptrdiff_t)k * 24);
        p[0] = q[0], p[1] = q[1], p[2] = q[2];
    } else if (s->kind == HD__SRC_F32) {
        const float *q = (const float *)(const void *)(s->base + (ptrdiff_t)k * 12);
        p[0] = q[0], p[1] = q[1], p[2] = q[2];
    } else {
        const char *b = s->base + (ptrdiff_t)k * s->ps;
        for (int c = 0; c < 3; c++) {
            if (s->dtype == HD_FLOAT32) {
                float v;
                __builtin_memcpy(&v, b + c * s->cs, sizeof v);
                p[c] = v;
            } else {
                __builtin_memcpy(&p[c], b + c * s->cs, sizeof(double));
            }
        }
    }
    if (s->T) hd__transform_apply(s->T, p, out);
    else out[0] = p[0], out[1] = p[1], out[2] = p[2];
}

/* The Morton keys on grid of the packed doubles xyz's points [lo, hi),
 * above their indices (keys[i] = key << 32 | i): hd__key30's keys, by a
 * loop that vectorises, compiled for AVX2 where there is one (source.c).
 * The layout the engine's callers mostly pass (field_bench's build phase
 * and keys_bench measure it). */
void hd__keys_f64(const double *xyz, const hd__keygrid_t *grid, size_t lo, size_t hi, uint64_t *restrict keys);

/* The Morton keys on grid of points [lo, hi) of src, above their indices
 * (keys[i] = key << 32 | i), as the builds and the index's queries sort
 * them: hd__keys_f64 for packed doubles without a transform, else point
 * by point through hd__src_get (the grid in a local, so that the stores
 * cannot be taken to change it). */
HD__INLINE void hd__src_keys(const hd__src_t *src, const hd__keygrid_t *grid, size_t lo, size_t hi,
                             uint64_t *keys) {
    if (src->kind == HD__SRC_F64 && !src->T) {
        hd__keys_f64((const double *)(const void *)src->base, grid, lo, hi, keys);
        return;
    }
    hd__keygrid_t g = *grid;
    for (size_t i = lo; i < hi; i++) {
        double p[3];
        hd__src_get(src, i, p);
        keys[i] = (uint64_t)hd__key30(&g, p) << 32 | (uint64_t)i;
    }
}

/* Sort a[0..n) of 64-bit words by bits 32..61 (a Morton key above a 32-bit
 * index), stable, in three counting passes of 10 bits over `threads`
 * threads.  The result ends in the buffer *tmp pointed to on entry (an odd
 * number of passes), and the two pointers are exchanged so that *a points
 * to it; nearest/allnearest.c relies on that.  Returns HD_OK, or HD_ENOMEM with
 * nothing moved. */
int hd__radix_sort(uint64_t **a, uint64_t **tmp, size_t n, int threads);

#endif /* HD_POINTS_H */
