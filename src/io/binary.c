/*
 * binary.c -- fixed-size binary records converted to points in parallel.
 *
 * Binary formats (PLY binary, PCD binary, STL, LAS, NPY) end in the same
 * loop, described by an hd__layout_t: n points, point k in record k / per
 * at sub * (k % per) bytes into it, coordinate c at byte off[c] with
 * type[c], a byte order, and optionally a scale and offset per coordinate
 * (LAS: X * scale + offset, evaluated in double in that order; the build
 * forbids fusing it into one rounding).  The caller has already checked that
 * the records lie inside the file.  This file reserves exactly n points,
 * then cuts the points into blocks that threads convert directly from the
 * mapping into the sink, checking every point.  Each block remembers its
 * first bad point; the first bad point in the file (the lowest block that
 * has one) is the one reported, so the error does not depend on the thread
 * count.  A reader call may ask for a range of the points
 * (hd_read_options_t.range_first/range_count): then only those records are
 * converted (and only their pages of the mapping touched), numbered from the
 * range's start in the sink but from the file's start in messages; or it
 * may ask for the count alone (hd_read_count), answered here from L->n
 * once the reader has checked its header and sizes.  The common layouts (three float32 or three float64 in the
 * machine's byte order, and LAS's three scaled int32) get a loop without a
 * type switch; every other layout goes through hd__ld_value, which computes
 * the same values.
 */
#include "io.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

#define BLOCK ((size_t)1 << 16)

typedef struct {
    hd__read_t *r;
    const unsigned char *base;
    const hd__layout_t *L;
    size_t first, n; /* the points converted: [first, first + n) of L's */
    size_t *bad;     /* per block: first bad point (from first), or SIZE_MAX */
} job_t;

static int host_big(void) {
    const uint16_t one = 1;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 0;
}

static const unsigned char *record(const hd__layout_t *L, const unsigned char *base, size_t k) {
    return base + (k / L->per) * L->stride + (k % L->per) * L->sub;
}

static void load(const hd__layout_t *L, const unsigned char *rec, double p[3]) {
    for (int c = 0; c < 3; c++) p[c] = hd__ld_value(rec + L->off[c], L->type[c], L->big);
    if (L->scale)
        for (int c = 0; c < 3; c++) p[c] = p[c] * L->scale[c] + L->offset[c];
}

static void convert(void *ctx, size_t task, int worker) {
    (void)worker;
    job_t *j = ctx;
    const hd__layout_t *L = j->L;
    hd__sink_t *s = j->r->sink;
    size_t lo = task * BLOCK, hi = lo + BLOCK < j->n ? lo + BLOCK : j->n;
    double lim = s->dtype == HD_FLOAT32 ? (double)FLT_MAX : HD_MAX_COORD;
    int same = L->type[0] == L->type[1] && L->type[1] == L->type[2] && L->big == host_big();
    int f32 = same && !L->scale && L->type[0] == HD__T_F32, f64 = same && !L->scale && L->type[0] == HD__T_F64;
    int i32 = same && L->scale && L->type[0] == HD__T_I32; /* LAS */
    j->bad[task] = SIZE_MAX;
    size_t rec_i = (j->first + lo) / L->per, sub_i = (j->first + lo) % L->per;
    for (size_t k = lo; k < hi; k++) {
        const unsigned char *rec = j->base + rec_i * L->stride + sub_i * L->sub;
        if (++sub_i == L->per) {
            sub_i = 0;
            rec_i++;
        }
        double p[3];
        if (f32) {
            float v[3];
            memcpy(&v[0], rec + L->off[0], 4);
            memcpy(&v[1], rec + L->off[1], 4);
            memcpy(&v[2], rec + L->off[2], 4);
            p[0] = v[0];
            p[1] = v[1];
            p[2] = v[2];
        } else if (f64) {
            memcpy(&p[0], rec + L->off[0], 8);
            memcpy(&p[1], rec + L->off[1], 8);
            memcpy(&p[2], rec + L->off[2], 8);
        } else if (i32) {
            int32_t v[3];
            memcpy(&v[0], rec + L->off[0], 4);
            memcpy(&v[1], rec + L->off[1], 4);
            memcpy(&v[2], rec + L->off[2], 4);
            for (int c = 0; c < 3; c++) p[c] = (double)v[c] * L->scale[c] + L->offset[c];
        } else {
            load(L, rec, p);
        }
        /* !(|x| <= lim) is true for NaN, infinities and out-of-range values */
        if (!(fabs(p[0]) <= lim && fabs(p[1]) <= lim && fabs(p[2]) <= lim)) {
            j->bad[task] = k;
            return;
        }
        hd__sink_set(s, k, p);
    }
}

int hd__binary_read(hd__read_t *r, const unsigned char *base, const hd__layout_t *L) {
    hd__sink_t *s = r->sink;
    if (s->count != 0) return hd__io_err(r, HD_EINVAL, "internal: binary points into a non-empty sink");
    if (r->count_only) { /* hd_read_count: the header's figure, nothing read */
        r->total = L->n;
        return HD__COUNTED;
    }
    /* A range of the points (hd_read_options_t.range_*): only its records
     * are touched.  With mesh sampling the range is of the sampled points,
     * which reader.c slices after sampling. */
    size_t first = 0, n = L->n;
    const hd_read_options_t *o = r->opt;
    if (o->range_count && o->mesh == HD_MESH_VERTICES) {
        if (o->range_first > L->n || o->range_count > L->n - o->range_first)
            return hd__io_err(r, HD_ERANGE, "points [%llu, %llu) asked of a file of %zu points",
                              (unsigned long long)o->range_first,
                              (unsigned long long)(o->range_first + o->range_count), L->n);
        first = (size_t)o->range_first;
        n = (size_t)o->range_count;
        r->ranged = 1;
    }
    if (n == 0) return HD_OK;
    int rc = hd__sink_reserve(s, n);
    if (rc) return hd__io_err(r, rc, "cannot allocate %zu points: %s", n, hd_strerror(rc));
    size_t blocks = (n + BLOCK - 1) / BLOCK;
    job_t j = {r, base, L, first, n, hd__malloc_array(blocks, sizeof(size_t))};
    if (!j.bad) return hd__io_err(r, HD_ENOMEM, "out of memory");
    hd__parallel_for(hd__thread_count(r->threads, blocks), blocks, convert, &j);
    for (size_t b = 0; rc == HD_OK && b < blocks; b++) {
        if (j.bad[b] == SIZE_MAX) continue;
        size_t k = first + j.bad[b];
        const unsigned char *rec = record(L, base, k);
        double p[3];
        load(L, rec, p);
        int code = hd__point_valid(p, s->dtype), c = 0;
        while (c < 2 && hd__point_valid((double[3]){p[c], 0, 0}, s->dtype) == HD_OK) c++;
        rc = hd__io_err_at(r, code, (long long)(L->file_offset + (size_t)(rec - base) + L->off[c]),
                           "point %zu: %s (%c = %g)", k, hd__point_problem(code), "xyz"[c], p[c]);
    }
    free(j.bad);
    if (rc == HD_OK) s->count = n;
    return rc;
}

int hd__binary_points(hd__read_t *r, const unsigned char *base, size_t n,
                      size_t stride, const size_t off[3],
                      const hd__type_t type[3], int big, size_t file_offset) {
    hd__layout_t L = {n, 1, stride, 0, {off[0], off[1], off[2]}, {type[0], type[1], type[2]}, big, NULL, NULL, file_offset};
    return hd__binary_read(r, base, &L);
}
