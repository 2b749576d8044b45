/*
 * labels.c -- label maps (public entry points hd_label_map,
 * hd_weighted_percentile): every label of a segmentation against a
 * reference's, with the voxel-surface figures (MONAI's, medpy's), the
 * surfel figures (DeepMind's, MONAI's use_subvoxels) and, optionally, each
 * connected component's.
 *
 * Phases: scan (one pass over both images, a row at a time: each label's
 * voxel counts, overlap and box), then per label: cut (the two windows of
 * the box plus one voxel, as binary images), voxel figures (surface voxels,
 * distances both ways, hd_summarize, hd_percentile_of,
 * hd_tolerance_scores), surfel figures (masks/surfels.c, distances between
 * surfel centres, area-weighted scores), components.  A window's margin is
 * background of that label, or lies outside the image; both count as
 * background for the erosion and for the cubes, so the window's surfaces
 * are the whole image's, and its points are placed by the image's indices.
 */
#include "masks/masks.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- options ------------------------------------------------------------------- */

void hd_label_image_init(hd_label_image_t *img, const void *labels, hd_label_type_t type, size_t n0, size_t n1,
                         size_t n2, const double spacing[3]) {
    memset(img, 0, sizeof *img);
    img->labels = labels;
    img->type = type;
    img->n[0] = n0, img->n[1] = n1, img->n[2] = n2;
    for (int c = 0; c < 3; c++) img->m[c][c] = spacing ? spacing[c] : 1.0;
    img->scale = 1.0;
}

void hd_label_options_init(hd_label_options_t *opt) {
    memset(opt, 0, sizeof *opt);
    opt->percentile = 95;
    opt->tau = 1;
    opt->rule = HD_AT_MOST;
    opt->connectivity = 1;
    opt->empty = HD_EMPTY_ERROR;
}

void hd_label_table_free(hd_label_table_t *t) {
    if (!t) return;
    free(t->rows);
    free(t->components);
    free(t);
}

/* ---- weighted percentile ------------------------------------------------------- */

typedef struct {
    double d, w;
} dw_t;

/* share(x) >= p: the exact sum x, rounded once, over the total. */
static int holds(const hd__xsum_t *x, double all, double p) { return hd__xsum_round(x) / all >= p / 100; }

/* The smallest distance d of s[0..n) with holds(weights of the distances
 * <= d), by a three-way quickselect: the values below the pivot either
 * already hold the share (the answer is among them) or not (then the
 * pivot, if it completes the share, or the values above it).  Sums are
 * exact, so the decision at each distinct value is the one a sorted pass
 * makes; past the end (the share never held after rounding), the largest
 * distance. */
static double weighted_select(dw_t *s, size_t n, double all, double p) {
    size_t lo = 0, hi = n;
    double largest = s[0].d;
    for (size_t k = 1; k < n; k++)
        if (s[k].d > largest) largest = s[k].d;
    hd__xsum_t acc;
    hd__xsum_init(&acc);
    while (lo < hi) {
        double a = s[lo].d, b = s[lo + (hi - lo) / 2].d, c = s[hi - 1].d;
        double v = a < b ? (b < c ? b : a < c ? c : a) : (a < c ? a : b < c ? c : b);
        size_t lt = lo, i = lo, gt = hi; /* [lo, lt) < v, [lt, i) == v, [gt, hi) > v */
        while (i < gt) {
            if (s[i].d < v) {
                dw_t t = s[i];
                s[i++] = s[lt], s[lt++] = t;
            } else if (s[i].d > v) {
                dw_t t = s[i];
                s[i] = s[--gt], s[gt] = t;
            } else
                i++;
        }
        hd__xsum_t below = acc;
        for (size_t k = lo; k < lt; k++) hd__xsum_add(&below, s[k].w);
        if (lt > lo && holds(&below, all, p)) {
            hi = lt;
            continue;
        }
        for (size_t k = lt; k < gt; k++) hd__xsum_add(&below, s[k].w);
        if (holds(&below, all, p)) return v;
        acc = below;
        lo = gt;
    }
    return largest;
}

int hd_weighted_percentile(const double *d, const double *w, size_t n, double p, double *out, hd_error_t *err) {
    hd__err_clear(err);
    if (!out || (n && (!d || !w))) return hd__err(err, HD_EINVAL, "distances, weights or result are NULL");
    if (!(p >= 0 && p <= 100)) return hd__err(err, HD_EINVAL, "the percentile is %g; it is in [0, 100]", p);
    if (!n) return hd__err(err, HD_EEMPTY, "no distances");
    int rc = hd__nan_check(d, n, 0, "the distances", err);
    if (rc != HD_OK) return rc;
    dw_t *s = hd__malloc_array(n, sizeof *s);
    if (!s) return hd__err(err, HD_ENOMEM, "out of memory for %zu distances", n);
    hd__xsum_t total;
    hd__xsum_init(&total);
    for (size_t k = 0; k < n; k++) {
        if (!(w[k] >= 0) || isinf(w[k])) {
            free(s);
            return hd__err(err, HD_EINVAL, "weight %zu is %g; weights are finite and >= 0", k, w[k]);
        }
        s[k] = (dw_t){d[k], w[k]};
        hd__xsum_add(&total, w[k]);
    }
    double all = hd__xsum_round(&total);
    if (!(all > 0)) {
        free(s);
        return hd__err(err, HD_EINVAL, "the weights add up to 0");
    }
    *out = weighted_select(s, n, all, p);
    free(s);
    return HD_OK;
}

/* ---- scan ---------------------------------------------------------------------- */

typedef struct {
    int64_t label;
    size_t count[2], overlap;
    size_t lo[3], hi[3]; /* box over both sides (inclusive) */
} label_stat_t;

typedef struct {
    label_stat_t *stat;
    size_t n, cap;
    size_t *slot; /* open addressing: index + 1, 0 = free */
    size_t slots; /* a power of two, > 2 n */
} label_set_t;

static size_t hash64(int64_t v, size_t mask) {
    uint64_t x = (uint64_t)v * 0x9E3779B97F4A7C15u;
    return (size_t)(x >> 17) & mask;
}

static label_stat_t *find_label(label_set_t *s, int64_t label, int add) {
    size_t mask = s->slots - 1, h = hash64(label, mask);
    for (;; h = (h + 1) & mask) {
        if (!s->slot[h]) break;
        if (s->stat[s->slot[h] - 1].label == label) return &s->stat[s->slot[h] - 1];
    }
    if (!add) return NULL;
    if (2 * (s->n + 1) >= s->slots) { /* grow and rehash */
        size_t slots = 2 * s->slots, *slot = calloc(slots, sizeof *slot);
        if (!slot) return NULL;
        for (size_t k = 0; k < s->n; k++) {
            size_t g = hash64(s->stat[k].label, slots - 1);
            while (slot[g]) g = (g + 1) & (slots - 1);
            slot[g] = k + 1;
        }
        free(s->slot);
        s->slot = slot, s->slots = slots;
        return find_label(s, label, add);
    }
    if (s->n == s->cap) {
        size_t cap = s->cap ? 2 * s->cap : 64;
        label_stat_t *st = realloc(s->stat, cap * sizeof *st);
        if (!st) return NULL;
        s->stat = st, s->cap = cap;
    }
    label_stat_t *st = &s->stat[s->n];
    memset(st, 0, sizeof *st);
    st->label = label;
    for (int a = 0; a < 3; a++) st->lo[a] = SIZE_MAX;
    s->slot[h] = ++s->n;
    return st;
}

/* Values [v, v + len) of an image as int64. */
static void load_row(const hd_label_image_t *img, size_t v, size_t len, int64_t *row) {
    const void *p = img->labels;
    switch (img->type) {
#define HD__ROW(T)                                                                                                     \
    for (size_t i = 0; i < len; i++) row[i] = (int64_t)((const T *)p)[v + i];                                       \
    break;
    case HD_LABEL_U8: HD__ROW(uint8_t)
    case HD_LABEL_I8: HD__ROW(int8_t)
    case HD_LABEL_U16: HD__ROW(uint16_t)
    case HD_LABEL_I16: HD__ROW(int16_t)
    case HD_LABEL_U32: HD__ROW(uint32_t)
    case HD_LABEL_I32: HD__ROW(int32_t)
    case HD_LABEL_I64: HD__ROW(int64_t)
    case HD_LABEL_U64: HD__ROW(uint64_t)
#undef HD__ROW
    }
}

/* Voxels [i0, i1) of row (j, k) hold `st`'s label on one side. */
static void add_run(label_stat_t *st, size_t i0, size_t i1, size_t j, size_t k) {
    const size_t lo[3] = {i0, j, k}, hi[3] = {i1 - 1, j, k};
    int first = st->count[0] + st->count[1] == 0;
    for (int a = 0; a < 3; a++) {
        if (lo[a] < st->lo[a]) st->lo[a] = lo[a];
        if (first || hi[a] > st->hi[a]) st->hi[a] = hi[a];
    }
}

/* The end of the run of l starting at i: eight bytes at a time where the
 * type is small (the background's long runs), then one value at a time. */
#define HD__RUN_END(T)                                                                                                 \
    static size_t run_end_##T(const T *row, size_t i, size_t n, T l) {                                               \
        if (sizeof(T) <= 2) {                                                                                          \
            uint64_t pat = 0;                                                                                          \
            for (size_t b = 0; b < 8 / sizeof(T); b++) memcpy((char *)&pat + b * sizeof(T), &l, sizeof(T));         \
            while (i + 8 / sizeof(T) <= n) {                                                                           \
                uint64_t w;                                                                                            \
                memcpy(&w, row + i, 8);                                                                                \
                if (w != pat) break;                                                                                   \
                i += 8 / sizeof(T);                                                                                    \
            }                                                                                                          \
        }                                                                                                              \
        while (i < n && row[i] == l) i++;                                                                              \
        return i;                                                                                                      \
    }
HD__RUN_END(uint8_t)
HD__RUN_END(int8_t)
HD__RUN_END(uint16_t)
HD__RUN_END(int16_t)
HD__RUN_END(uint32_t)
HD__RUN_END(int32_t)
HD__RUN_END(int64_t)
HD__RUN_END(uint64_t)
#undef HD__RUN_END

/* One row of both images (values of type T at pa and pb), a run of equal
 * labels at a time: background comes in long runs, so the table is
 * consulted once per run.  The overlap of label 0 is counted only when
 * asked for (it is the bulk of the image). */
#define HD__SCAN_ROW(name, T)                                                                                          \
    static int name(label_set_t *set, const void *pa, const void *pb, size_t n0, size_t j, size_t k, int zero) {      \
        const T *ra = pa, *rb = pb;                                                                                    \
        label_stat_t *last = NULL;                                                                                     \
        for (int side = 0; side < 2; side++) {                                                                         \
            const T *row = side ? rb : ra;                                                                             \
            for (size_t i = 0; i < n0;) {                                                                              \
                T l = row[i];                                                                                          \
                size_t s = i;                                                                                          \
                i = run_end_##T(row, i, n0, l);                                                                        \
                label_stat_t *st = last && last->label == (int64_t)l ? last : find_label(set, (int64_t)l, 1);         \
                if (!st) return -1;                                                                                    \
                add_run(st, s, i, j, k);                                                                               \
                st->count[side] += i - s;                                                                              \
                if (side == 0 && (l != 0 || zero)) {                                                                   \
                    size_t same = 0;                                                                                   \
                    for (size_t q = s; q < i; q++) same += rb[q] == l;                                                 \
                    st->overlap += same;                                                                               \
                }                                                                                                      \
                last = st;                                                                                             \
            }                                                                                                          \
        }                                                                                                              \
        return 0;                                                                                                      \
    }
HD__SCAN_ROW(scan_u8, uint8_t)
HD__SCAN_ROW(scan_i8, int8_t)
HD__SCAN_ROW(scan_u16, uint16_t)
HD__SCAN_ROW(scan_i16, int16_t)
HD__SCAN_ROW(scan_u32, uint32_t)
HD__SCAN_ROW(scan_i32, int32_t)
HD__SCAN_ROW(scan_i64, int64_t)
HD__SCAN_ROW(scan_u64, uint64_t)
#undef HD__SCAN_ROW

typedef int (*scan_row_fn)(label_set_t *, const void *, const void *, size_t, size_t, size_t, int);

/* Both images a row at a time, read in their own type (as int64 when the
 * two types differ). */
static int scan(const hd_label_image_t *a, const hd_label_image_t *b, int zero, label_set_t *set, hd_error_t *err) {
    static const scan_row_fn fn[] = {scan_u8, scan_i8, scan_u16, scan_i16, scan_u32, scan_i32, scan_i64, scan_u64};
    static const size_t size[] = {1, 1, 2, 2, 4, 4, 8, 8};
    const size_t *n = a->n, z = size[a->type];
    int64_t *row = a->type != b->type ? hd__malloc_array(2 * n[0], sizeof *row) : NULL;
    if (a->type != b->type && !row) return hd__err(err, HD_ENOMEM, "out of memory for a row of %zu labels", n[0]);
    int rc = HD_OK;
    for (size_t k = 0; k < n[2] && rc == HD_OK; k++)
        for (size_t j = 0; j < n[1] && rc == HD_OK; j++) {
            size_t v = (k * n[1] + j) * n[0];
            int bad;
            if (row) {
                load_row(a, v, n[0], row);
                load_row(b, v, n[0], row + n[0]);
                bad = scan_i64(set, row, row + n[0], n[0], j, k, zero);
            } else
                bad = fn[a->type](set, (const char *)a->labels + v * z, (const char *)b->labels + v * z, n[0], j, k,
                                  zero);
            if (bad) rc = hd__err(err, HD_ENOMEM, "out of memory for the labels");
        }
    free(row);
    return rc;
}

/* ---- one label ------------------------------------------------------------------- */

/* One side of one label in its window. */
typedef struct {
    uint8_t *fg;
    double *xyz;     /* surface voxels */
    size_t *voxel;   /* their window indices */
    size_t points;
    double *d;       /* their distances to the other side's surface */
    hd__surfels_t sf;
    double *sd;      /* the surfels' distances to the other side's surfels */
    uint32_t *comp;
    long long n_comp;
} side_t;

typedef struct {
    const hd_label_image_t *img[2];
    const hd_label_options_t *opt;
    size_t off[3], w[3], nvox;
    int surfel_dims;
    double area[2][256]; /* each side's surfel areas (its own map) */
    hd__neighbourhood_t nb, nb_comp;
    side_t s[2];
    hd_label_component_t *comps;
    size_t n_comps, cap_comps;
} label_work_t;

static void side_free(side_t *s) {
    free(s->fg), free(s->xyz), free(s->voxel), free(s->d), free(s->sd), free(s->comp);
    hd__surfels_free(&s->sf);
    memset(s, 0, sizeof *s);
}

static int cut(label_work_t *lw, int64_t label, hd_error_t *err) {
    size_t n0 = lw->w[0];
    int64_t *row = hd__malloc_array(n0, sizeof *row);
    for (int side = 0; side < 2; side++) lw->s[side].fg = hd__malloc_array(lw->nvox, 1);
    if (!row || !lw->s[0].fg || !lw->s[1].fg) {
        free(row);
        return hd__err(err, HD_ENOMEM, "out of memory for label %lld's %zu voxels", (long long)label, lw->nvox);
    }
    const size_t *n = lw->img[0]->n;
    for (int side = 0; side < 2; side++)
        for (size_t k = 0; k < lw->w[2]; k++)
            for (size_t j = 0; j < lw->w[1]; j++) {
                load_row(lw->img[side], ((lw->off[2] + k) * n[1] + lw->off[1] + j) * n[0] + lw->off[0], n0, row);
                uint8_t *dst = lw->s[side].fg + (k * lw->w[1] + j) * n0;
                for (size_t i = 0; i < n0; i++) dst[i] = row[i] == label;
            }
    free(row);
    return HD_OK;
}

static int surface_points(label_work_t *lw, side_t *s, hd_error_t *err) {
    int side = s == &lw->s[1];
    const hd_label_image_t *im = lw->img[side];
    hd__window_points(s->fg, lw->w, lw->off, im->m, im->scale, &lw->nb, NULL, NULL, &s->points);
    s->xyz = hd__malloc_array(s->points ? 3 * s->points : 3, sizeof *s->xyz);
    s->voxel = hd__malloc_array(s->points ? s->points : 1, sizeof *s->voxel);
    s->d = hd__malloc_array(s->points ? s->points : 1, sizeof *s->d);
    if (!s->xyz || !s->voxel || !s->d) return hd__err(err, HD_ENOMEM, "out of memory for %zu points", s->points);
    hd__window_points(s->fg, lw->w, lw->off, im->m, im->scale, &lw->nb, s->xyz, s->voxel, &s->points);
    if (hd__window_surfels(s->fg, lw->w, lw->off, im->m, im->scale, lw->surfel_dims, lw->area[side], &s->sf) < 0)
        return hd__err(err, HD_ENOMEM, "out of memory for surfels");
    s->sd = hd__malloc_array(s->sf.count ? s->sf.count : 1, sizeof *s->sd);
    if (!s->sd) return hd__err(err, HD_ENOMEM, "out of memory for %zu surfels", s->sf.count);
    return HD_OK;
}

/* Distances both ways between two point sets, +inf when the other is empty. */
static int both_ways(const double *pa, size_t na, const double *pb, size_t nb, double *da, double *db, int threads,
                     hd_error_t *err) {
    if (!na || !nb) {
        for (size_t k = 0; k < na; k++) da[k] = INFINITY;
        for (size_t k = 0; k < nb; k++) db[k] = INFINITY;
        return HD_OK;
    }
    hd_options_t o;
    hd_options_init(&o);
    o.threads = threads;
    hd_points_t A = hd_points_f64(pa, na), B = hd_points_f64(pb, nb);
    return hd_distances(&A, &B, &o, da, NULL, db, NULL, err);
}

static double weighted_mean(const double *d, const double *w, size_t n) {
    hd__xsum_t s, t;
    hd__xsum_init(&s);
    hd__xsum_init(&t);
    for (size_t k = 0; k < n; k++) {
        hd__xsum_add(&s, d[k] * w[k]);
        hd__xsum_add(&t, w[k]);
    }
    double tw = hd__xsum_round(&t);
    return tw > 0 ? hd__xsum_round(&s) / tw : NAN;
}

static int voxel_figures(label_work_t *lw, hd_label_row_t *r, hd_error_t *err) {
    const hd_label_options_t *o = lw->opt;
    side_t *a = &lw->s[0], *b = &lw->s[1];
    hd_tolerance_t t;
    int rc = hd_tolerance_scores(a->d, NULL, a->points, b->d, NULL, b->points, &o->tau, 1, o->rule, &t, err);
    if (rc != HD_OK) return rc;
    r->nsd = t.nsd;
    if (!a->points || !b->points) return HD_OK;
    hd_summary_t sm;
    hd_percentile_t pc;
    rc = hd_summarize(a->d, a->points, b->d, b->points, &sm, err);
    if (rc == HD_OK) rc = hd_percentile_of(a->d, a->points, b->d, b->points, o->percentile, &pc, err);
    if (rc != HD_OK) return rc;
    r->hd_ab = sm.max_ab, r->hd_ba = sm.max_ba;
    r->hausdorff = sm.max_ab > sm.max_ba ? sm.max_ab : sm.max_ba;
    r->hd_p = pc.symmetric, r->hd_p_pooled = pc.pooled;
    r->assd = sm.mean_pooled, r->asd_ab = sm.mean_ab, r->asd_ba = sm.mean_ba;
    return HD_OK;
}

static int surfel_figures(label_work_t *lw, hd_label_row_t *r, hd_error_t *err) {
    const hd_label_options_t *o = lw->opt;
    side_t *a = &lw->s[0], *b = &lw->s[1];
    r->surfels_a = a->sf.count, r->surfels_b = b->sf.count;
    hd_tolerance_t t;
    int rc = hd_tolerance_scores(a->sd, a->sf.area, a->sf.count, b->sd, b->sf.area, b->sf.count, &o->tau, 1, o->rule,
                                 &t, err);
    if (rc != HD_OK) return rc;
    r->area_a = t.total_a, r->area_b = t.total_b;
    r->nsd_surfel = t.nsd, r->overlap_ab = t.precision, r->overlap_ba = t.recall;
    if (!a->sf.count || !b->sf.count) return HD_OK;
    double pa, pb;
    rc = hd_weighted_percentile(a->sd, a->sf.area, a->sf.count, o->percentile, &pa, err);
    if (rc == HD_OK) rc = hd_weighted_percentile(b->sd, b->sf.area, b->sf.count, o->percentile, &pb, err);
    if (rc != HD_OK) return rc;
    r->hd_surfel = pa > pb ? pa : pb;
    r->asd_surfel_ab = weighted_mean(a->sd, a->sf.area, a->sf.count);
    r->asd_surfel_ba = weighted_mean(b->sd, b->sf.area, b->sf.count);
    return HD_OK;
}

static int push_component(label_work_t *lw, const hd_label_component_t *c) {
    if (lw->n_comps == lw->cap_comps) {
        size_t cap = lw->cap_comps ? 2 * lw->cap_comps : 64;
        hd_label_component_t *p = realloc(lw->comps, cap * sizeof *p);
        if (!p) return -1;
        lw->comps = p, lw->cap_comps = cap;
    }
    lw->comps[lw->n_comps++] = *c;
    return 0;
}

/* Each component of one side: its voxels, overlap, and its surface
 * voxels' distances (gathered by component with a counting sort). */
static int side_components(label_work_t *lw, int side, int64_t label, size_t *n_out, hd_error_t *err) {
    side_t *s = &lw->s[side], *other = &lw->s[!side];
    s->comp = hd__malloc_array(lw->nvox, sizeof *s->comp);
    if (!s->comp || (s->n_comp = hd__components(s->fg, lw->w, &lw->nb_comp, s->comp)) < 0)
        return hd__err(err, HD_ENOMEM, "out of memory for label %lld's components", (long long)label);
    size_t nc = (size_t)s->n_comp;
    *n_out = nc;
    size_t *start = hd__calloc_array(nc + 2, sizeof *start), *vox = hd__calloc_array(nc + 1, sizeof *vox);
    size_t *ovl = hd__calloc_array(nc + 1, sizeof *ovl);
    double *gathered = hd__malloc_array(s->points ? s->points : 1, sizeof *gathered);
    int rc = HD_OK;
    if (!start || !vox || !ovl || !gathered) {
        rc = hd__err(err, HD_ENOMEM, "out of memory for %zu components", nc);
        goto done;
    }
    for (size_t v = 0; v < lw->nvox; v++)
        if (s->comp[v]) vox[s->comp[v]]++, ovl[s->comp[v]] += other->fg[v] != 0;
    for (size_t p = 0; p < s->points; p++) start[s->comp[s->voxel[p]] + 1]++;
    for (size_t c = 1; c <= nc + 1; c++) start[c] += start[c - 1];
    for (size_t p = 0; p < s->points; p++) gathered[start[s->comp[s->voxel[p]]]++] = s->d[p];
    for (size_t c = nc + 1; c > 0; c--) start[c] = start[c - 1]; /* back to the starts */
    start[0] = 0;
    for (size_t c = 1; c <= nc && rc == HD_OK; c++) {
        const double *d = gathered + start[c];
        size_t np = start[c + 1] - start[c];
        hd_label_component_t out = {label, side, c, vox[c], ovl[c], np, 0, 0, INFINITY, 0};
        for (size_t k = 0; k < np; k++) {
            if (d[k] > out.hausdorff) out.hausdorff = d[k];
            if (d[k] < out.nearest) out.nearest = d[k];
        }
        if (other->points) rc = hd_percentile(d, np, lw->opt->percentile, &out.hd_p, err);
        else out.hd_p = INFINITY; /* every distance is +inf: no interpolation between them */
        int within = lw->opt->rule == HD_AT_MOST ? out.nearest <= lw->opt->tau : out.nearest < lw->opt->tau;
        out.detected = out.overlap > 0 || within;
        if (rc == HD_OK && push_component(lw, &out) < 0) rc = hd__err(err, HD_ENOMEM, "out of memory for components");
    }
done:
    free(start), free(vox), free(ovl), free(gathered);
    return rc;
}

static void set_window(label_work_t *lw, const label_stat_t *st) {
    const size_t *n = lw->img[0]->n;
    lw->nvox = 1;
    for (int a = 0; a < 3; a++) {
        lw->off[a] = st->lo[a] ? st->lo[a] - 1 : 0;
        size_t hi = st->hi[a] + 1 < n[a] ? st->hi[a] + 1 : n[a] - 1;
        lw->w[a] = hi - lw->off[a] + 1;
        lw->nvox *= lw->w[a];
    }
}

static void empty_figures(hd_label_row_t *r, hd_empty_policy_t policy) {
    double v = hd_empty_value(policy, r->points_a, r->points_b);
    r->hausdorff = r->hd_ab = r->hd_ba = r->hd_p = r->hd_p_pooled = r->assd = r->asd_ab = r->asd_ba = v;
    r->hd_surfel = r->asd_surfel_ab = r->asd_surfel_ba = v;
}

static int measure_label(label_work_t *lw, const label_stat_t *st, int64_t label, hd_label_row_t *r,
                         hd_error_t *err) {
    const hd_label_options_t *o = lw->opt;
    memset(r, 0, sizeof *r);
    r->label = label;
    r->voxels_a = st ? st->count[0] : 0, r->voxels_b = st ? st->count[1] : 0;
    r->overlap = st ? st->overlap : 0;
    r->empty = (r->voxels_a == 0) | (r->voxels_b == 0) << 1;
    size_t tot = r->voxels_a + r->voxels_b;
    r->dice = tot ? 2 * (double)r->overlap / (double)tot : NAN;
    if (r->empty && o->empty == HD_EMPTY_ERROR)
        return hd__err(err, HD_EEMPTY, "label %lld is absent from %s (choose an empty policy to report it)",
                       (long long)label, r->empty == 3 ? "both images" : r->empty == 1 ? "A" : "B");
    if (r->empty == 3) {
        r->nsd = r->nsd_surfel = r->overlap_ab = r->overlap_ba = NAN;
        empty_figures(r, o->empty);
        return HD_OK;
    }
    set_window(lw, st);
    int rc = cut(lw, label, err);
    if (rc != HD_OK) return rc;
    hd__neighbourhood(&lw->nb, lw->w, o->dims, o->connectivity);
    int cc = o->components == 26 ? 3 : o->components == 18 || o->components == 8 ? 2 : 1;
    hd__neighbourhood(&lw->nb_comp, lw->w, o->dims, cc);
    for (int side = 0; side < 2 && rc == HD_OK; side++) rc = surface_points(lw, &lw->s[side], err);
    side_t *a = &lw->s[0], *b = &lw->s[1];
    if (rc == HD_OK) rc = both_ways(a->xyz, a->points, b->xyz, b->points, a->d, b->d, o->threads, err);
    if (rc == HD_OK) rc = both_ways(a->sf.xyz, a->sf.count, b->sf.xyz, b->sf.count, a->sd, b->sd, o->threads, err);
    r->points_a = a->points, r->points_b = b->points;
    if (rc == HD_OK) rc = voxel_figures(lw, r, err);
    if (rc == HD_OK) rc = surfel_figures(lw, r, err);
    if (rc == HD_OK && r->empty) empty_figures(r, o->empty);
    if (rc == HD_OK && o->components) rc = side_components(lw, 0, label, &r->components_a, err);
    if (rc == HD_OK && o->components) rc = side_components(lw, 1, label, &r->components_b, err);
    side_free(&lw->s[0]);
    side_free(&lw->s[1]);
    return rc;
}

/* ---- entry point ----------------------------------------------------------------- */

static int check_image(const hd_label_image_t *im, const char *name, hd_error_t *err) {
    if (!im->labels) return hd__err(err, HD_EINVAL, "label image %s has no values", name);
    if ((unsigned)im->type > HD_LABEL_U64) return hd__err(err, HD_EINVAL, "label image %s: unknown type", name);
    size_t v = 1;
    for (int a = 0; a < 3; a++) {
        if (!im->n[a]) return hd__err(err, HD_EINVAL, "label image %s: dimension %d is 0", name, a);
        if (v > SIZE_MAX / 16 / im->n[a]) return hd__err(err, HD_EOVERFLOW, "label image %s: too many voxels", name);
        v *= im->n[a];
    }
    for (int corner = 0; corner < 8; corner++)
        for (int c = 0; c < 3; c++) {
            double ijk[3];
            for (int a = 0; a < 3; a++) ijk[a] = corner >> a & 1 ? (double)im->n[a] : -1.0;
            double q = hd__voxel_world(im->m, im->scale, c, ijk[0], ijk[1], ijk[2]);
            if (!(fabs(q) <= HD_MAX_COORD))
                return hd__err(err, isnan(q) || isinf(q) ? HD_ENONFINITE : HD_ERANGE,
                               "label image %s: its corner maps to %c = %g, beyond %g", name, "xyz"[c], q,
                               HD_MAX_COORD);
        }
    return HD_OK;
}

static int check_options(const hd_label_image_t *a, const hd_label_image_t *b, const hd_label_options_t *o,
                         hd_error_t *err) {
    int rc = check_image(a, "A", err);
    if (rc == HD_OK) rc = check_image(b, "B", err);
    if (rc != HD_OK) return rc;
    for (int k = 0; k < 3; k++)
        if (a->n[k] != b->n[k])
            return hd__err(err, HD_EINVAL, "the label images differ in size: %zu x %zu x %zu and %zu x %zu x %zu",
                           a->n[0], a->n[1], a->n[2], b->n[0], b->n[1], b->n[2]);
    if (!(o->percentile >= 0 && o->percentile <= 100))
        return hd__err(err, HD_EINVAL, "the percentile is %g; it is in [0, 100]", o->percentile);
    if (!(o->tau >= 0)) return hd__err(err, HD_EINVAL, "the tolerance is %g; it is >= 0", o->tau);
    if (o->rule != HD_AT_MOST && o->rule != HD_BELOW) return hd__err(err, HD_EINVAL, "unknown tolerance rule");
    if (o->connectivity < 1 || o->connectivity > 3)
        return hd__err(err, HD_EINVAL, "connectivity is %d; it is 1, 2 or 3", o->connectivity);
    if (o->dims != 0 && o->dims != 2 && o->dims != 3)
        return hd__err(err, HD_EINVAL, "dims is %d; it is 0 (auto), 2 or 3", o->dims);
    if (o->components && o->components != 4 && o->components != 8 && o->components != 6 && o->components != 18 &&
        o->components != 26)
        return hd__err(err, HD_EINVAL, "component connectivity is %d; it is 6, 18, 26 (3-D) or 4, 8 (2-D)",
                       o->components);
    if ((unsigned)o->empty > HD_EMPTY_SKIMAGE) return hd__err(err, HD_EINVAL, "unknown empty policy");
    if (o->n_labels && !o->labels) return hd__err(err, HD_EINVAL, "the list of labels is NULL");
    return HD_OK;
}

static int by_label(const void *x, const void *y) {
    int64_t a = ((const label_stat_t *)x)->label, b = ((const label_stat_t *)y)->label;
    return (a > b) - (a < b);
}

/* The labels to measure: the caller's, or every nonzero one found, sorted. */
static int64_t *chosen_labels(label_set_t *set, const hd_label_options_t *o, size_t *n) {
    if (o->labels) {
        *n = o->n_labels;
        int64_t *l = hd__malloc_array(o->n_labels ? o->n_labels : 1, sizeof *l);
        if (l && o->n_labels) memcpy(l, o->labels, o->n_labels * sizeof *l);
        return l;
    }
    label_stat_t *sorted = hd__malloc_array(set->n ? set->n : 1, sizeof *sorted);
    int64_t *l = hd__malloc_array(set->n ? set->n : 1, sizeof *l);
    if (!sorted || !l) {
        free(sorted), free(l);
        return NULL;
    }
    memcpy(sorted, set->stat, set->n * sizeof *sorted);
    qsort(sorted, set->n, sizeof *sorted, by_label);
    *n = 0;
    for (size_t k = 0; k < set->n; k++)
        if (sorted[k].label != 0) l[(*n)++] = sorted[k].label;
    free(sorted);
    return l;
}

static void linear_part(const hd_label_image_t *im, double lin[3][3]) {
    for (int c = 0; c < 3; c++)
        for (int a = 0; a < 3; a++) lin[c][a] = im->scale != 1.0 ? im->m[c][a] * im->scale : im->m[c][a];
}

int hd_label_map(const hd_label_image_t *a, const hd_label_image_t *b, const hd_label_options_t *opt,
                 hd_label_table_t **out, hd_error_t *err) {
    hd__err_clear(err);
    if (!out) return hd__err(err, HD_EINVAL, "result pointer is NULL");
    *out = NULL;
    hd_label_options_t defaults;
    hd_label_options_init(&defaults);
    if (!opt) opt = &defaults;
    if (!a || !b) return hd__err(err, HD_EINVAL, "a label image is NULL");
    int rc = check_options(a, b, opt, err);
    if (rc != HD_OK) return rc;
    label_set_t set = {0};
    set.slots = 64;
    set.slot = calloc(set.slots, sizeof *set.slot);
    if (!set.slot) return hd__err(err, HD_ENOMEM, "out of memory");
    int zero = 0; /* is label 0 asked for? */
    for (size_t k = 0; opt->labels && k < opt->n_labels; k++) zero |= opt->labels[k] == 0;
    rc = scan(a, b, zero, &set, err);
    size_t n_rows = 0;
    int64_t *labels = rc == HD_OK ? chosen_labels(&set, opt, &n_rows) : NULL;
    hd_label_table_t *t = calloc(1, sizeof *t);
    if (rc == HD_OK && (!labels || !t || !(t->rows = hd__calloc_array(n_rows ? n_rows : 1, sizeof *t->rows))))
        rc = hd__err(err, HD_ENOMEM, "out of memory for %zu labels", n_rows);
    label_work_t lw;
    memset(&lw, 0, sizeof lw);
    lw.img[0] = a, lw.img[1] = b, lw.opt = opt;
    lw.surfel_dims = opt->dims == 2 || (opt->dims == 0 && a->n[2] == 1) ? 2 : 3;
    for (int side = 0; side < 2; side++) {
        double lin[3][3];
        linear_part(lw.img[side], lin);
        hd__surfel_areas(lw.surfel_dims, lin, lw.area[side]);
    }
    for (size_t k = 0; rc == HD_OK && k < n_rows; k++) {
        t->n_rows = k + 1;
        rc = measure_label(&lw, find_label(&set, labels[k], 0), labels[k], &t->rows[k], err);
    }
    free(labels), free(set.stat), free(set.slot);
    side_free(&lw.s[0]);
    side_free(&lw.s[1]);
    if (rc != HD_OK) {
        free(lw.comps);
        hd_label_table_free(t);
        return rc;
    }
    t->components = lw.comps, t->n_components = lw.n_comps;
    *out = t;
    return HD_OK;
}
