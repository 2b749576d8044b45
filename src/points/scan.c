/*
 * scan.c -- validating a view and taking its box in one fast pass: the
 * same answer as hd__points_check, for any caller that validates large
 * views (the entry points of the `auto` engine and of per-point distances
 * use it).  It lives in points/ beside the reference so that every layer
 * above may call it.
 *
 * hd__points_check (points.c) reads every point through hd_points_get and
 * tests each coordinate in turn; it is the reference, and its messages are
 * the library's.  Inputs are often hundreds of millions of points, where
 * that pass alone can cost more than the rest of the work, so
 * hd__points_scan does the same checks with loops specialised for packed
 * double and float arrays, without branches in the loop body, over
 * `threads` threads.  Whenever it finds anything wrong (or the view is not
 * packed) it calls hd__points_check, which reports the problem with its
 * usual message; so both agree on every input, and the fast path only
 * decides that nothing is wrong.
 *
 * The test |v| <= HD_MAX_COORD is false for NaN and for infinities, so one
 * comparison per coordinate covers non-finite and out-of-range values.
 */
#include "points/points.h"

#include <math.h>
#include <stdlib.h>

#define SCAN_SLICE 65536

typedef struct {
    const hd_points_t *p;
    size_t n;
    hd__box_t *part;
    int *bad; /* per slice: 1 when something is wrong */
} scan_ctx;

HD__HOT static void scan_task(void *vctx, size_t task, int worker) {
    (void)worker;
    scan_ctx *c = vctx;
    size_t lo = task * SCAN_SLICE, hi = lo + SCAN_SLICE < c->n ? lo + SCAN_SLICE : c->n;
    const size_t m = hi - lo;
    if (c->p->dtype == HD_FLOAT64) {
        c->bad[task] = !hd__box_checked((const double *)c->p->data + 3 * lo, m, &c->part[task]);
        return;
    }
    const float *v = (const float *)c->p->data + 3 * lo;
    double mn[3] = {v[0], v[1], v[2]}, mx[3] = {v[0], v[1], v[2]};
    int ok = 1;
    for (size_t i = 0; i < m; i++)
        for (int k = 0; k < 3; k++) {
            double x = v[3 * i + (size_t)k];
            ok &= fabs(x) <= HD_MAX_COORD;
            mn[k] = x < mn[k] ? x : mn[k];
            mx[k] = x > mx[k] ? x : mx[k];
        }
    for (int k = 0; k < 3; k++) {
        c->part[task].lo[k] = mn[k];
        c->part[task].hi[k] = mx[k];
    }
    c->bad[task] = !ok;
}

int hd__points_scan(const hd_points_t *p, const char *what, int threads, hd__box_t *box,
                    hd_error_t *err) {
    if (!p || p->count == 0 || !p->data || (p->dtype != HD_FLOAT64 && p->dtype != HD_FLOAT32))
        return hd__points_check(p, what, box, err);
    hd__src_t s;
    hd__src_init(&s, p, NULL);
    if (s.kind == HD__SRC_ANY || hd__points_aligned(p, what, NULL) != HD_OK)
        return hd__points_check(p, what, box, err); /* which reports a misaligned view */
    scan_ctx c;
    c.p = p;
    c.n = p->count;
    size_t slices = (c.n + SCAN_SLICE - 1) / SCAN_SLICE;
    c.part = hd__malloc_array(slices, sizeof *c.part);
    c.bad = hd__malloc_array(slices, sizeof *c.bad);
    if (!c.part || !c.bad) {
        free(c.part);
        free(c.bad);
        return hd__points_check(p, what, box, err);
    }
    hd__parallel_for(hd__thread_count(threads, slices), slices, scan_task, &c);
    int bad = 0;
    hd__box_t b = c.part[0];
    for (size_t t = 0; t < slices; t++) {
        bad |= c.bad[t];
        for (int k = 0; k < 3; k++) {
            b.lo[k] = c.part[t].lo[k] < b.lo[k] ? c.part[t].lo[k] : b.lo[k];
            b.hi[k] = c.part[t].hi[k] > b.hi[k] ? c.part[t].hi[k] : b.hi[k];
        }
    }
    free(c.part);
    free(c.bad);
    if (bad) return hd__points_check(p, what, box, err);
    if (box) *box = b;
    return HD_OK;
}
