/*
 * metrics.c -- the figures of segmentation and reconstruction benchmarks
 * (public entry points): scores at a distance tolerance (precision,
 * recall, F-score, normalized surface Dice), DTU's capped means, and
 * binary masks as the point sets of their surfaces (masks/surface.c).
 *
 * Scores at tolerances: the tolerances are sorted once; each distance is
 * placed by binary search in the bucket of the first (smallest) tolerance
 * it is within, so one pass over the distances serves every tolerance, and
 * the number (and weight) within tau_k is the sum of the buckets up to k.
 * Every decision is one comparison of the given double with the given
 * tolerance (d <= tau, or d < tau), the same on every machine.  Weights
 * are summed exactly (base/xsum.c: one accumulator a bucket, merged in
 * order), so a weighted figure does not depend on the order of the points.
 */
#include "masks/masks.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- scores at tolerances -------------------------------------------------- */

typedef struct {
    double tau;
    size_t k; /* its place in the caller's array */
} tau_slot_t;

static int by_tau(const void *x, const void *y) {
    const tau_slot_t *a = x, *b = y;
    return a->tau < b->tau ? -1 : a->tau > b->tau ? 1 : (a->k > b->k) - (a->k < b->k);
}

/* The first slot (of m, ascending) whose tolerance d is within; m if none. */
static size_t first_within(const tau_slot_t *t, size_t m, double d, hd_tolerance_rule_t rule) {
    size_t lo = 0, hi = m;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        int within = rule == HD_AT_MOST ? d <= t[mid].tau : d < t[mid].tau;
        if (within) hi = mid;
        else lo = mid + 1;
    }
    return lo;
}

static int check_weights(const double *w, size_t n, const char *side, hd_error_t *err) {
    for (size_t k = 0; w && k < n; k++)
        if (!(w[k] >= 0) || isinf(w[k]))
            return hd__err(err, HD_EINVAL, "weight %zu of %s is %g; weights are finite and >= 0", k, side, w[k]);
    return HD_OK;
}

/* One side: count[f] and weight[f] per bucket (m + 1 buckets), and the
 * exact total weight. */
static void side_buckets(const double *d, const double *w, size_t n, const tau_slot_t *t, size_t m,
                         hd_tolerance_rule_t rule, size_t *count, hd__xsum_t *weight, hd__xsum_t *total) {
    for (size_t p = 0; p < n; p++) {
        size_t f = first_within(t, m, d[p], rule);
        count[f]++;
        double v = w ? w[p] : 1.0;
        hd__xsum_add(&weight[f], v);
        hd__xsum_add(total, v);
    }
}

static double ratio(double num, double den) { return den > 0 ? num / den : NAN; }

int hd_tolerance_scores(const double *d_ab, const double *w_a, size_t n_a, const double *d_ba,
                        const double *w_b, size_t n_b, const double *taus, size_t n_tau,
                        hd_tolerance_rule_t rule, hd_tolerance_t *out, hd_error_t *err) {
    hd__err_clear(err);
    if ((n_a && !d_ab) || (n_b && !d_ba) || (n_tau && (!taus || !out)))
        return hd__err(err, HD_EINVAL, "distances, tolerances or results are NULL");
    if (rule != HD_AT_MOST && rule != HD_BELOW) return hd__err(err, HD_EINVAL, "unknown tolerance rule %d", (int)rule);
    for (size_t k = 0; k < n_tau; k++)
        if (!(taus[k] >= 0)) return hd__err(err, HD_EINVAL, "tolerance %zu is %g; tolerances are >= 0", k, taus[k]);
    int rc = hd__nan_check(d_ab, n_a, 0, "A to B", err);
    if (rc == HD_OK) rc = hd__nan_check(d_ba, n_b, 0, "B to A", err);
    if (rc == HD_OK) rc = check_weights(w_a, n_a, "A", err);
    if (rc == HD_OK) rc = check_weights(w_b, n_b, "B", err);
    if (rc != HD_OK || n_tau == 0) return rc;
    tau_slot_t *t = hd__malloc_array(n_tau, sizeof *t);
    size_t *count = hd__calloc_array(2 * (n_tau + 1), sizeof *count);
    hd__xsum_t *weight = hd__malloc_array(2 * (n_tau + 1) + 2, sizeof *weight);
    if (!t || !count || !weight) {
        free(t), free(count), free(weight);
        return hd__err(err, HD_ENOMEM, "out of memory for %zu tolerances", n_tau);
    }
    for (size_t k = 0; k < n_tau; k++) t[k] = (tau_slot_t){taus[k], k};
    qsort(t, n_tau, sizeof *t, by_tau);
    for (size_t q = 0; q < 2 * (n_tau + 1) + 2; q++) hd__xsum_init(&weight[q]);
    size_t m = n_tau;
    hd__xsum_t *tot = weight + 2 * (m + 1);
    side_buckets(d_ab, w_a, n_a, t, m, rule, count, weight, &tot[0]);
    side_buckets(d_ba, w_b, n_b, t, m, rule, count + m + 1, weight + m + 1, &tot[1]);
    double total_a = hd__xsum_round(&tot[0]), total_b = hd__xsum_round(&tot[1]);
    hd__xsum_t run[2];
    hd__xsum_init(&run[0]);
    hd__xsum_init(&run[1]);
    size_t c_a = 0, c_b = 0;
    for (size_t s = 0; s < m; s++) {
        c_a += count[s];
        c_b += count[m + 1 + s];
        hd__xsum_merge(&run[0], &weight[s]);
        hd__xsum_merge(&run[1], &weight[m + 1 + s]);
        hd_tolerance_t *o = &out[t[s].k];
        o->tau = t[s].tau;
        o->count_ab = c_a;
        o->count_ba = c_b;
        o->within_ab = hd__xsum_round(&run[0]);
        o->within_ba = hd__xsum_round(&run[1]);
        o->total_a = total_a;
        o->total_b = total_b;
        o->precision = ratio(o->within_ab, total_a);
        o->recall = ratio(o->within_ba, total_b);
        double pr = o->precision + o->recall;
        o->fscore = isnan(pr) ? NAN : pr > 0 ? 2 * o->precision * o->recall / pr : 0.0;
        hd__xsum_t both = run[0];
        hd__xsum_merge(&both, &run[1]);
        hd__xsum_t all = tot[0];
        hd__xsum_merge(&all, &tot[1]);
        o->nsd = ratio(hd__xsum_round(&both), hd__xsum_round(&all));
    }
    free(t), free(count), free(weight);
    return HD_OK;
}

/* ---- DTU's capped means ------------------------------------------------------ */

static double capped_mean(const double *d, size_t n, double cap, size_t *kept) {
    hd__xsum_t s;
    hd__xsum_init(&s);
    size_t c = 0;
    for (size_t k = 0; k < n; k++)
        if (d[k] < cap) {
            hd__xsum_add(&s, d[k]);
            c++;
        }
    *kept = c;
    return c ? hd__xsum_round(&s) / (double)c : NAN;
}

int hd_capped_means(const double *d_ab, size_t n_a, const double *d_ba, size_t n_b, double cap,
                    hd_capped_mean_t *out, hd_error_t *err) {
    hd__err_clear(err);
    if ((n_a && !d_ab) || (n_b && !d_ba) || !out) return hd__err(err, HD_EINVAL, "distances or result are NULL");
    if (!(cap > 0)) return hd__err(err, HD_EINVAL, "the cap is %g; it must be > 0", cap);
    int rc = hd__nan_check(d_ab, n_a, 0, "A to B", err);
    if (rc == HD_OK) rc = hd__nan_check(d_ba, n_b, 0, "B to A", err);
    if (rc != HD_OK) return rc;
    out->cap = cap;
    out->accuracy = capped_mean(d_ab, n_a, cap, &out->kept_ab);
    out->completeness = capped_mean(d_ba, n_b, cap, &out->kept_ba);
    out->overall = (out->accuracy + out->completeness) / 2;
    return HD_OK;
}

/* ---- masks ----------------------------------------------------------------------- */

void hd_mask_init(hd_mask_t *mask, const uint8_t *voxels, size_t n0, size_t n1, size_t n2,
                  const double spacing[3]) {
    memset(mask, 0, sizeof *mask);
    mask->voxels = voxels;
    mask->n[0] = n0, mask->n[1] = n1, mask->n[2] = n2;
    for (int c = 0; c < 3; c++) mask->m[c][c] = spacing ? spacing[c] : 1.0;
    mask->scale = 1.0;
}

void hd_mask_options_init(hd_mask_options_t *opt) {
    memset(opt, 0, sizeof *opt);
    opt->points = HD_MASK_SURFACE;
    opt->connectivity = 1;
    opt->dtype = HD_FLOAT64;
}

/* The box's eight corners bound every voxel's coordinates (the map is
 * affine), so checking them keeps every point finite and within limit. */
static int check_corners(const hd_mask_t *mk, double limit, hd_error_t *err) {
    for (int corner = 0; corner < 8; corner++) {
        double ijk[3];
        for (int a = 0; a < 3; a++) ijk[a] = corner >> a & 1 ? (double)(mk->n[a] - 1) : 0.0;
        for (int c = 0; c < 3; c++) {
            double q = hd__voxel_world(mk->m, mk->scale, c, ijk[0], ijk[1], ijk[2]);
            if (!(fabs(q) <= limit))
                return hd__err(err, isnan(q) || isinf(q) ? HD_ENONFINITE : HD_ERANGE,
                               "the mask's voxel (%.0f, %.0f, %.0f) maps to %c = %g, beyond %g", ijk[0], ijk[1],
                               ijk[2], "xyz"[c], q, limit);
        }
    }
    return HD_OK;
}

static int check_mask(const hd_mask_t *mk, const hd_mask_options_t *o, size_t *nvox, hd_error_t *err) {
    if (!mk || !o) return hd__err(err, HD_EINVAL, "mask or options are NULL");
    if (o->points != HD_MASK_SURFACE && o->points != HD_MASK_ALL)
        return hd__err(err, HD_EINVAL, "unknown mask points %d", (int)o->points);
    if (o->connectivity < 1 || o->connectivity > 3)
        return hd__err(err, HD_EINVAL, "connectivity is %d; it is 1, 2 or 3", o->connectivity);
    if (o->dims != 0 && o->dims != 2 && o->dims != 3)
        return hd__err(err, HD_EINVAL, "dims is %d; it is 0 (auto), 2 or 3", o->dims);
    if (o->dtype != HD_FLOAT64 && o->dtype != HD_FLOAT32) return hd__err(err, HD_EINVAL, "unknown dtype");
    size_t v = 1;
    for (int a = 0; a < 3; a++) {
        if (mk->n[a] == 0) return hd__err(err, HD_EINVAL, "the mask's dimension %d is 0", a);
        if (v > SIZE_MAX / mk->n[a] / 2) return hd__err(err, HD_EOVERFLOW, "the mask's voxel count overflows");
        v *= mk->n[a];
    }
    if (!mk->voxels) return hd__err(err, HD_EINVAL, "the mask's voxels are NULL");
    if (!isfinite(mk->scale)) return hd__err(err, HD_ENONFINITE, "the mask's scale is not finite");
    *nvox = v;
    return check_corners(mk, o->dtype == HD_FLOAT32 ? FLT_MAX : HD_MAX_COORD, err);
}

static hd_cloud_t *new_cloud(size_t count, hd_dtype_t dtype) {
    hd_cloud_t *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->data = hd__malloc_array(count ? 3 * count : 3, dtype == HD_FLOAT32 ? sizeof(float) : sizeof(double));
    if (!c->data) {
        free(c);
        return NULL;
    }
    c->count = count;
    c->dtype = dtype;
    memcpy(c->format, "mask", 5);
    return c;
}

/* Pass 0 counts the points, pass 1 writes them into c. */
static size_t mask_pass(const hd_mask_t *mk, const hd_mask_options_t *o, const hd__neighbourhood_t *nb,
                        hd_cloud_t *c, size_t *foreground) {
    const size_t *n = mk->n;
    size_t p = 0, fg = 0;
    for (size_t k = 0; k < n[2]; k++)
        for (size_t j = 0; j < n[1]; j++)
            for (size_t i = 0; i < n[0]; i++) {
                size_t v = (k * n[1] + j) * n[0] + i;
                if (!mk->voxels[v]) continue;
                fg++;
                if (o->points == HD_MASK_SURFACE && !hd__on_surface(mk->voxels, n, nb, i, j, k)) continue;
                if (c) {
                    double q[3];
                    for (int a = 0; a < 3; a++) q[a] = hd__voxel_world(mk->m, mk->scale, a, (double)i, (double)j, (double)k);
                    if (c->dtype == HD_FLOAT32)
                        for (int a = 0; a < 3; a++) ((float *)c->data)[3 * p + a] = (float)q[a];
                    else
                        memcpy((double *)c->data + 3 * p, q, sizeof q);
                }
                p++;
            }
    *foreground = fg;
    return p;
}

int hd_mask_points(const hd_mask_t *mask, const hd_mask_options_t *opt, hd_cloud_t **out, hd_mask_info_t *info,
                   hd_error_t *err) {
    hd__err_clear(err);
    if (!out) return hd__err(err, HD_EINVAL, "result pointer is NULL");
    *out = NULL;
    size_t nvox;
    int rc = check_mask(mask, opt, &nvox, err);
    if (rc != HD_OK) return rc;
    hd__neighbourhood_t nb;
    hd__neighbourhood(&nb, mask->n, opt->dims, opt->connectivity);
    size_t fg, np = mask_pass(mask, opt, &nb, NULL, &fg);
    hd_cloud_t *c = new_cloud(np, opt->dtype);
    if (!c) return hd__err(err, HD_ENOMEM, "out of memory for the mask's %zu points", np);
    mask_pass(mask, opt, &nb, c, &fg);
    if (info) {
        info->foreground = fg;
        info->points = np;
        info->surface_dims = opt->points == HD_MASK_SURFACE ? nb.rank : 0;
        info->connectivity = opt->points == HD_MASK_SURFACE ? nb.connectivity : 0;
    }
    *out = c;
    return HD_OK;
}

int hd_mask_surfels(const hd_mask_t *mask, int dims, hd_cloud_t **points, double **areas, hd_error_t *err) {
    hd__err_clear(err);
    if (!points || !areas) return hd__err(err, HD_EINVAL, "result pointers are NULL");
    *points = NULL, *areas = NULL;
    if (dims != 0 && dims != 2 && dims != 3) return hd__err(err, HD_EINVAL, "dims is %d; it is 0 (auto), 2 or 3", dims);
    hd_mask_options_t o;
    hd_mask_options_init(&o);
    size_t nvox;
    int rc = check_mask(mask, &o, &nvox, err);
    if (rc != HD_OK) return rc;
    if (dims == 0) dims = mask->n[2] == 1 ? 2 : 3;
    double lin[3][3], area[256];
    for (int c = 0; c < 3; c++)
        for (int a = 0; a < 3; a++) lin[c][a] = mask->scale != 1.0 ? mask->m[c][a] * mask->scale : mask->m[c][a];
    hd__surfel_areas(dims, lin, area);
    hd__surfels_t sf = {0};
    const size_t off[3] = {0, 0, 0};
    hd_cloud_t *c = calloc(1, sizeof *c);
    if (!c || hd__window_surfels(mask->voxels, mask->n, off, mask->m, mask->scale, dims, area, &sf) < 0) {
        free(c);
        hd__surfels_free(&sf);
        return hd__err(err, HD_ENOMEM, "out of memory for the mask's surfels");
    }
    if (!sf.count) { /* an empty mask: still the caller's buffers */
        sf.xyz = malloc(3 * sizeof *sf.xyz), sf.area = malloc(sizeof *sf.area);
        if (!sf.xyz || !sf.area) {
            free(c);
            hd__surfels_free(&sf);
            return hd__err(err, HD_ENOMEM, "out of memory");
        }
    }
    c->data = sf.xyz, c->count = sf.count, c->dtype = HD_FLOAT64;
    memcpy(c->format, "surfels", 8);
    *points = c, *areas = sf.area;
    return HD_OK;
}
