/*
 * api.c -- the public entry points for distances (like Lua's lapi.c: the
 * boundary, nothing more): options, algorithm names, validation, and the
 * hand-off to the auto engine (src/engine/) or to the paper's algorithms
 * through their dispatcher (src/classic/framework.c).
 *
 * Every public call validates its inputs here, once (non-empty, finite,
 * within HD_MAX_COORD, by src/points/), then hands the algorithm either the
 * views (the engine reads them itself) or a job of packed doubles.
 */
#include "classic/classic.h"
#include "engine/engine.h"

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
