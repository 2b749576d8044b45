/*
 * framework.c -- the paper's framework (Algorithm 8) and the dispatcher
 * that runs any of the paper's algorithms by name on a prepared job.
 *
 * The framework is only a choice: disjoint boxes -> NOHD; overlap degree
 * alpha <= theta -> EARLYBREAK; otherwise OHD.
 *
 * The paper never defines alpha beyond "0 when A and B just touch, 1 when
 * they fully overlap".  We define it per axis as the length of the
 * intersection of the two extents over the shorter extent, and alpha as the
 * product over the three axes.  An axis on which the shorter extent has
 * length zero (a flat set, a single point) counts 1 when the extents meet:
 * the flat set lies wholly within the other's extent on that axis, which is
 * full overlap there.  docs/algorithms.md gives the reasoning.
 *
 * The auto engine is not dispatched here: it reads the caller's views
 * without packed copies (api.c calls it directly).
 */
#include "classic/classic_int.h"

#include <math.h>
#include <string.h>

double hd__alpha(const hd__box_t *a, const hd__box_t *b, int *disjoint) {
    double alpha = 1.0;
    int apart = 0;
    for (int k = 0; k < 3; k++) {
        double lo = a->lo[k] > b->lo[k] ? a->lo[k] : b->lo[k];
        double hi = a->hi[k] < b->hi[k] ? a->hi[k] : b->hi[k];
        if (lo > hi) {
            apart = 1;
            continue;
        }
        double la = a->hi[k] - a->lo[k], lb = b->hi[k] - b->lo[k];
        double shorter = la < lb ? la : lb;
        double r = shorter > 0 ? (hi - lo) / shorter : 1.0;
        if (r > 1.0) r = 1.0;
        alpha *= r;
    }
    if (disjoint) *disjoint = apart;
    return apart ? 0.0 : alpha;
}

hd_algorithm_t hd__framework_choice(const hd__box_t *a, const hd__box_t *b,
                                    double theta) {
    int disjoint;
    double alpha = hd__alpha(a, b, &disjoint);
    if (disjoint) return HD_ALG_NOHD;
    if (alpha <= theta) return HD_ALG_EARLYBREAK;
    return HD_ALG_OHD;
}

/* Run one direction on a prepared job with algorithm `alg`. */
int hd__run_directed(hd__job_t *job, hd_algorithm_t alg, hd_result_t *out,
                     hd_error_t *err) {
    memset(out, 0, sizeof *out);
    if (alg == HD_ALG_FRAMEWORK)
        alg = hd__framework_choice(&job->box_a, &job->box_b, job->opt->theta);
    hd__directed_fn fn = NULL;
    switch (alg) {
    case HD_ALG_NAIVE: fn = hd__naive; break;
    case HD_ALG_EARLYBREAK: fn = hd__earlybreak; break;
    case HD_ALG_INC: fn = hd__inc; break;
    case HD_ALG_NOHD: fn = hd__nohd; break;
    case HD_ALG_OHD: fn = hd__ohd; break;
    case HD_ALG_KDTREE: fn = hd__kdtree; break;
    default: return hd__err(err, HD_EALGORITHM, "unknown algorithm");
    }
    job->threads = hd__thread_count(job->opt->threads, job->na);
    double t0 = hd__now();
    int rc = fn(job, out, err);
    out->seconds = hd__now() - t0;
    if (rc != HD_OK) return rc;
    if (out->algorithm == HD_ALG_AUTO && alg != HD_ALG_AUTO) out->algorithm = alg;
    out->distance = sqrt(out->distance2);
    return HD_OK;
}

