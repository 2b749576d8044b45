/*
 * naive.c -- Algorithm 1 (NAIVEHDD) and the exact scans everything else
 * leans on.
 *
 * NAIVEHDD (paper, Algorithm 1, lines 1-9) takes, for every x in A, the
 * minimum over all y in B, and the maximum of those minima.  It evaluates
 * |A| * |B| squared distances and is the reference every other algorithm is
 * tested against.  Two details the paper leaves open are fixed here and
 * shared by all algorithms:
 *  - line 3 of the printed algorithm resets `cmax` where it means `cmin`;
 *    we reset cmin;
 *  - ties: the witness is the smallest index i in A whose minimum is the
 *    maximum, and the smallest j in B that attains that minimum (strict `<`
 *    when scanning B in increasing order keeps the first).
 * The work over A is cut into slices run by hd__parallel_for; partial
 * results merge with hd__best_offer.
 */
#include "classic/classic_int.h"

#include <stdlib.h>

double hd__nn_scan(const double *p, const double *xyz, size_t n, size_t *j,
                   uint64_t *evals) {
    double best = hd__d2(p, xyz);
    size_t bj = 0;
    for (size_t k = 1; k < n; k++) {
        double d = hd__d2(p, xyz + 3 * k);
        if (d < best) {
            best = d;
            bj = k;
        }
    }
    if (evals) *evals += n;
    if (j) *j = bj;
    return best;
}

size_t hd__first_at(const double *p, const double *xyz, size_t n, double d2,
                    uint64_t *evals) {
    for (size_t k = 0; k < n; k++) {
        if (hd__d2(p, xyz + 3 * k) == d2) {
            if (evals) *evals += k + 1;
            return k;
        }
    }
    if (evals) *evals += n;
    return HD__NONE; /* not reached when d2 is attained */
}

#define NAIVE_SLICE 256

typedef struct {
    const hd__job_t *job;
    hd__best_t *part;
    uint64_t *evals;
} naive_ctx;

static void naive_task(void *vctx, size_t task, int worker) {
    naive_ctx *c = vctx;
    const hd__job_t *job = c->job;
    size_t lo = task * NAIVE_SLICE, hi = lo + NAIVE_SLICE;
    if (hi > job->na) hi = job->na;
    hd__best_t best;
    hd__best_init(&best);
    uint64_t evals = 0;
    for (size_t i = lo; i < hi; i++) {
        size_t j;
        double cmin = hd__nn_scan(job->a + 3 * i, job->b, job->nb, &j, &evals);
        hd__best_offer(&best, cmin, i, j);
    }
    c->part[task] = best;
    c->evals[worker] += evals;
}

int hd__naive(const hd__job_t *job, hd_result_t *out, hd_error_t *err) {
    size_t tasks = (job->na + NAIVE_SLICE - 1) / NAIVE_SLICE;
    naive_ctx c;
    c.job = job;
    c.part = hd__malloc_array(tasks, sizeof *c.part);
    c.evals = hd__calloc_array((size_t)job->threads, sizeof *c.evals);
    if (!c.part || !c.evals) {
        free(c.part);
        free(c.evals);
        return hd__err(err, HD_ENOMEM, "out of memory");
    }
    hd__parallel_for(job->threads, tasks, naive_task, &c);
    hd__best_t best;
    hd__best_init(&best);
    hd__best_merge(&best, c.part, tasks);
    hd__best_store(&best, out);
    for (int w = 0; w < job->threads; w++) out->stats.distance_evals += c.evals[w];
    free(c.part);
    free(c.evals);
    return HD_OK;
}
