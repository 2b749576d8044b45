/*
 * api.c -- the public entry points for distances: options, algorithm names,
 * validation, dispatch, and the overlap degree that the framework uses.
 *
 * Every public call validates its inputs here, once (non-empty, finite,
 * within HD_MAX_COORD), then hands the algorithm a job of packed doubles.
 * The framework (Algorithm 8) lives here too because it is only a choice:
 * disjoint boxes -> NOHD; overlap degree alpha <= theta -> EARLYBREAK;
 * otherwise OHD.
 *
 * The paper never defines alpha beyond "0 when A and B just touch, 1 when
 * they fully overlap".  We define it per axis as the length of the
 * intersection of the two extents over the shorter extent, and alpha as the
 * product over the three axes.  An axis on which the shorter extent has
 * length zero (a flat set, a single point) counts 1 when the extents meet:
 * the flat set lies wholly within the other's extent on that axis, which is
 * full overlap there.  docs/algorithms.md gives the reasoning.
 */
#include "internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void hd_options_init(hd_options_t *opt) {
    memset(opt, 0, sizeof *opt);
    opt->algorithm = HD_ALG_AUTO;
    opt->threads = 0;
    opt->seed = 0;
    opt->depth = 6;
    opt->lambda = 0.01;
    opt->theta = 0.33;
    opt->early_break = 1;
    opt->culling = 1;
    opt->exclude_common = 1;
}

static const char *const alg_names[HD__ALG_COUNT] = {
    "auto", "naive", "earlybreak", "inc", "nohd", "ohd", "framework", "kdtree",
};

const char *hd_algorithm_name(hd_algorithm_t alg) {
    if ((int)alg < 0 || alg >= HD__ALG_COUNT) return "unknown";
    return alg_names[alg];
}

int hd_algorithm_from_name(const char *name, hd_algorithm_t *out) {
    if (!name || !out) return HD_EINVAL;
    for (int k = 0; k < HD__ALG_COUNT; k++) {
        if (strcmp(name, alg_names[k]) == 0) {
            *out = (hd_algorithm_t)k;
            return HD_OK;
        }
    }
    return HD_EALGORITHM;
}

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

static int check_options(const hd_options_t *o, hd_error_t *err) {
    if ((int)o->algorithm < 0 || o->algorithm >= HD__ALG_COUNT)
        return hd__err(err, HD_EALGORITHM, "unknown algorithm %d", (int)o->algorithm);
    if (o->threads < 0)
        return hd__err(err, HD_EINVAL, "threads must be 0 (every core) or positive, not %d", o->threads);
    if (o->depth < 1 || o->depth > 21)
        return hd__err(err, HD_EINVAL, "octree depth must be 1..21, not %d", o->depth);
    if (!(o->lambda > 0.0 && o->lambda <= 1.0))
        return hd__err(err, HD_EINVAL, "lambda must be in (0, 1], not %g", o->lambda);
    if (!(o->theta >= 0.0 && o->theta <= 1.0))
        return hd__err(err, HD_EINVAL, "theta must be in [0, 1], not %g", o->theta);
    return HD_OK;
}

/* Run one direction on a prepared job with algorithm `alg`. */
int hd__run_directed(hd__job_t *job, hd_algorithm_t alg, hd_result_t *out,
                     hd_error_t *err) {
    memset(out, 0, sizeof *out);
    if (alg == HD_ALG_FRAMEWORK)
        alg = hd__framework_choice(&job->box_a, &job->box_b, job->opt->theta);
    hd__directed_fn fn = NULL;
    switch (alg) {
    case HD_ALG_AUTO: fn = hd__engine; break;
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

typedef struct {
    double *owned_a, *owned_b;
    hd__job_t job;
} prepared_t;

static int prepare(const hd_points_t *A, const hd_points_t *B,
                   const hd_options_t *opt, hd_options_t *defaults,
                   prepared_t *p, hd_error_t *err) {
    memset(p, 0, sizeof *p);
    if (!opt) {
        hd_options_init(defaults);
        opt = defaults;
    }
    int rc = check_options(opt, err);
    if (rc) return rc;
    if (opt->algorithm == HD_ALG_AUTO) { /* the engine's fast, parallel pass */
        if ((rc = hd__points_scan(A, "A", opt->threads, &p->job.box_a, err))) return rc;
        if ((rc = hd__points_scan(B, "B", opt->threads, &p->job.box_b, err))) return rc;
    } else {
        if ((rc = hd__points_check(A, "A", &p->job.box_a, err))) return rc;
        if ((rc = hd__points_check(B, "B", &p->job.box_b, err))) return rc;
    }
    p->job.na = A->count;
    p->job.nb = B->count;
    p->job.opt = opt;
    /* The auto engine reads the views itself (no packed copies). */
    if (opt->algorithm == HD_ALG_AUTO) return HD_OK;
    if ((rc = hd__points_f64(A, NULL, &p->owned_a, &p->job.a, err))) return rc;
    if ((rc = hd__points_f64(B, NULL, &p->owned_b, &p->job.b, err))) {
        free(p->owned_a);
        return rc;
    }
    return HD_OK;
}

int hd_directed(const hd_points_t *A, const hd_points_t *B,
                const hd_options_t *opt, hd_result_t *out, hd_error_t *err) {
    hd__err_clear(err);
    if (!out) return hd__err(err, HD_EINVAL, "result pointer is NULL");
    hd_options_t defaults;
    prepared_t p;
    int rc = prepare(A, B, opt, &defaults, &p, err);
    if (rc) return rc;
    if (p.job.opt->algorithm == HD_ALG_AUTO)
        rc = hd__engine_directed(A, B, &p.job.box_a, &p.job.box_b, p.job.opt, out, err);
    else
        rc = hd__run_directed(&p.job, p.job.opt->algorithm, out, err);
    free(p.owned_a);
    free(p.owned_b);
    return rc;
}

int hd_hausdorff(const hd_points_t *A, const hd_points_t *B,
                 const hd_options_t *opt, hd_symmetric_t *out, hd_error_t *err) {
    hd__err_clear(err);
    if (!out) return hd__err(err, HD_EINVAL, "result pointer is NULL");
    memset(out, 0, sizeof *out);
    hd_options_t defaults;
    prepared_t p;
    int rc = prepare(A, B, opt, &defaults, &p, err);
    if (rc) return rc;
    double t0 = hd__now();
    out->alpha = hd__alpha(&p.job.box_a, &p.job.box_b, &out->disjoint);
    if (p.job.opt->algorithm == HD_ALG_AUTO)
        rc = hd__engine_hausdorff(A, B, &p.job.box_a, &p.job.box_b, p.job.opt, out, err);
    else
        rc = hd__run_directed(&p.job, p.job.opt->algorithm, &out->ab, err);
    if (rc == HD_OK && p.job.opt->algorithm != HD_ALG_AUTO) {
        hd__job_t rev = p.job;
        rev.a = p.job.b;
        rev.na = p.job.nb;
        rev.b = p.job.a;
        rev.nb = p.job.na;
        rev.box_a = p.job.box_b;
        rev.box_b = p.job.box_a;
        rc = hd__run_directed(&rev, p.job.opt->algorithm, &out->ba, err);
    }
    out->seconds = hd__now() - t0;
    if (rc == HD_OK)
        out->distance = out->ab.distance2 >= out->ba.distance2 ? out->ab.distance
                                                               : out->ba.distance;
    free(p.owned_a);
    free(p.owned_b);
    return rc;
}

int hd_overlap(const hd_points_t *A, const hd_points_t *B, double *alpha,
               int *disjoint, hd_error_t *err) {
    hd__err_clear(err);
    hd__box_t ba, bb;
    int rc;
    if ((rc = hd__points_check(A, "A", &ba, err))) return rc;
    if ((rc = hd__points_check(B, "B", &bb, err))) return rc;
    int dj;
    double a = hd__alpha(&ba, &bb, &dj);
    if (alpha) *alpha = a;
    if (disjoint) *disjoint = dj;
    return HD_OK;
}
