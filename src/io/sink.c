/*
 * sink.c -- the growing array of points a reader fills, and the one check
 * every point passes before it is kept.
 *
 * Points are stored as the caller asked: packed doubles by default, packed
 * floats with HD_FLOAT32.  A double that is out of float range would become
 * infinite when narrowed, so the check knows the storage type: a point is
 * kept only if every coordinate is finite, within HD_MAX_COORD, and (for
 * float storage) within FLT_MAX.  Readers reserve room only for counts they
 * have checked against the bytes left in the file, so the sink never grows
 * beyond what the file can hold.
 *
 * Transparent huge pages (MADV_HUGEPAGE) were tried for large arrays: they
 * remove most of the page-fault cost of filling fresh memory, but where
 * memory is fragmented the kernel first compacts it synchronously, a stall
 * far longer than the faults saved (docs/benchmarks.md, "Reading").  So
 * the sink takes plain memory, whose cost is predictable.
 */
#include "io.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

void hd__sink_init(hd__sink_t *s, hd_dtype_t dtype) {
    s->data = NULL;
    s->count = s->cap = 0;
    s->dtype = dtype;
    s->fixed = 0;
}

static size_t point_bytes(hd_dtype_t d) {
    return d == HD_FLOAT32 ? 3 * sizeof(float) : 3 * sizeof(double);
}

int hd__sink_reserve(hd__sink_t *s, size_t n) {
    if (n <= s->cap - s->count) return HD_OK;
    if (s->fixed) return HD_EOVERFLOW; /* a window cannot grow */
    size_t want = s->count + n;
    if (want < s->count) return HD_EOVERFLOW;
    size_t cap = s->cap < SIZE_MAX / 2 ? s->cap + s->cap / 2 : want;
    if (cap < want) cap = want;
    if (cap < 256) cap = 256;
    if (hd__mul_overflows(cap, point_bytes(s->dtype))) return HD_EOVERFLOW;
    void *p = realloc(s->data, cap * point_bytes(s->dtype));
    if (!p) return HD_ENOMEM;
    s->data = p;
    s->cap = cap;
    return HD_OK;
}

int hd__point_valid(const double p[3], hd_dtype_t dtype) {
    double lim = dtype == HD_FLOAT32 ? (double)FLT_MAX : HD_MAX_COORD;
    for (int c = 0; c < 3; c++) {
        if (!isfinite(p[c])) return HD_ENONFINITE;
        if (fabs(p[c]) > lim) return HD_ERANGE;
    }
    return HD_OK;
}

const char *hd__point_problem(int code) {
    switch (code) {
    case HD_ENONFINITE: return "coordinate is NaN or infinite";
    case HD_ERANGE: return "coordinate magnitude beyond 1e153 (or beyond float range with --float32)";
    default: return hd_strerror(code);
    }
}

int hd__sink_push(hd__sink_t *s, const double p[3]) {
    int rc = hd__point_valid(p, s->dtype);
    if (rc) return rc;
    if (s->count == s->cap && (rc = hd__sink_reserve(s, 1))) return rc;
    hd__sink_set(s, s->count++, p);
    return HD_OK;
}

void hd__sink_free(hd__sink_t *s) {
    free(s->data);
    s->data = NULL;
    s->count = s->cap = 0;
}
