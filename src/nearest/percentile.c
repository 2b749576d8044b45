/*
 * percentile.c -- percentiles of the per-point nearest distances (HD95)
 * without every distance: hd__percentile_points, which
 * hd_hausdorff_percentile (stats.c) runs.
 *
 * The P-th percentile (numpy's linear interpolation) needs only the values
 * of two ranks r1 <= r2 of the sorted distances.  The method:
 *  1. A sample: the exact squared distances of SAMPLE points of each set,
 *     spread evenly over its file order (a structure of the selection,
 *     hd__an_build_sel, searched completely with hd__an_band's widest band).
 *  2. A band per figure (A->B, B->A, both pooled): the sample values whose
 *     estimated ranks lie SPREAD standard deviations of a sample rank below
 *     r1 and above r2 (each sampled value weighs n / m points).
 *  3. One hd__an_band pass per direction over the union of the bands that
 *     direction serves: the points whose distance lies outside are only
 *     counted; those inside get their exact squared distance.
 *  4. For each figure: c points lie below its band and M inside.  When
 *     c <= r1 and c + |M| > r2, the values of ranks r1 and r2 are those of
 *     ranks r1 - c and r2 - c of M: every point counted below is strictly
 *     below rank r1's value and every point counted above strictly above
 *     rank r2's, so removing them moves neither rank's value but by c.
 *     Otherwise the failed side of the band is opened (nothing below, or
 *     nothing above) and the passes it needs run again; a band open on
 *     both sides always holds both ranks, so this ends.
 * The sample decides only the cost, never the answer: any band gives the
 * same bits, those of selecting ranks r1 and r2 among every exact squared
 * distance.  sqrt is monotone, so the distances' ranks hold the square
 * roots of the squared distances' ranks; the percentile is then
 * hd__lerp(sqrt(v1), sqrt(v2), t), as hd__percentiles_inplace computes it
 * from sorted distances.
 */
#include "nearest/nearest.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SAMPLE 4096 /* points sampled per direction for the bands */
#define SPREAD 6.0  /* a band's half-width, in standard deviations of a sample's estimated rank */

typedef hd__pct_sample_t sample_t;

static int cmp_double(const void *x, const void *y) {
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

/* The sample of direction d: its SAMPLE points spread evenly over the
 * file order, their exact squared distances sorted. */
static int sample_of(const hd__pct_src_t *src, int d, size_t n, sample_t *s, hd_error_t *err) {
    size_t m = n < SAMPLE ? n : SAMPLE;
    s->v = NULL, s->m = m, s->n = n;
    uint32_t *sel = hd__malloc_array(m, sizeof *sel);
    if (!sel) return hd__err(err, HD_ENOMEM, "cannot allocate a sample of %zu points", m);
    for (size_t k = 0; k < m; k++) sel[k] = (uint32_t)((uint64_t)k * n / m); /* increasing: n >= m */
    hd__an_band_t b;
    int rc = src->sample(src->ctx, d, sel, m, &b, err);
    free(sel);
    if (rc) return rc;
    qsort(b.v, b.n, sizeof *b.v, cmp_double);
    s->v = b.v;
    return HD_OK;
}

void hd__percentile_band(const hd__pct_sample_t *s, int ns, size_t *at, size_t r1, size_t r2, double *lo2,
                         double *hi2) {
    double total = 0, var = 0, slack = 0;
    for (int i = 0; i < ns; i++) total += (double)s[i].n;
    double q = ((double)r1 + 0.5) / total;
    for (int i = 0; i < ns; i++) {
        at[i] = 0;
        if (s[i].m == 0) continue;
        double w = (double)s[i].n / (double)s[i].m, f = 1.0 - (double)s[i].m / (double)s[i].n;
        var += w * w * (double)s[i].m * q * (1 - q) * f;
        slack += f > 0 ? w : 0;
    }
    double delta = SPREAD * sqrt(var) + slack, below = 0;
    *lo2 = 0, *hi2 = INFINITY;
    for (;;) { /* the samples merged, a value (with its copies) at a time */
        double v = INFINITY;
        for (int i = 0; i < ns; i++)
            if (at[i] < s[i].m && s[i].v[at[i]] < v) v = s[i].v[at[i]];
        if (v == INFINITY) return;
        if (below <= (double)r1 - delta) *lo2 = v;
        for (int i = 0; i < ns; i++)
            while (at[i] < s[i].m && s[i].v[at[i]] == v) at[i]++, below += (double)s[i].n / (double)s[i].m;
        if (below >= (double)r2 + 1 + delta) {
            *hi2 = v;
            return;
        }
    }
}

static void band_of(const sample_t *s, int ns, size_t r1, size_t r2, double *lo2, double *hi2) {
    size_t at[2];
    hd__percentile_band(s, ns, at, r1, r2, lo2, hi2);
}

/* One figure: its ranks, its band, and its answer once settled. */
typedef struct {
    size_t r1, r2;
    double t, lo2, hi2;
    double v1, v2;
    int settled;
} figure_t;

/* Settles figure f from the passes parts[0..np) when its band holds both
 * ranks, else opens the side that failed.  HD_OK or HD_ENOMEM. */
static int figure_select(figure_t *f, const hd__an_band_t *parts, int np, hd_error_t *err) {
    size_t below = 0, inside = 0;
    for (int i = 0; i < np; i++) {
        below += parts[i].below;
        for (size_t k = 0; k < parts[i].n; k++) {
            below += parts[i].v[k] < f->lo2;
            inside += parts[i].v[k] >= f->lo2 && parts[i].v[k] <= f->hi2;
        }
    }
    if (below > f->r1 || below + inside <= f->r2) {
        if (below > f->r1) f->lo2 = 0;
        if (below + inside <= f->r2) f->hi2 = INFINITY;
        return HD_OK;
    }
    double *m = hd__malloc_array(inside, sizeof *m);
    if (!m) return hd__err(err, HD_ENOMEM, "cannot copy %zu distances", inside);
    size_t k = 0;
    for (int i = 0; i < np; i++)
        for (size_t j = 0; j < parts[i].n; j++)
            if (parts[i].v[j] >= f->lo2 && parts[i].v[j] <= f->hi2) m[k++] = parts[i].v[j];
    hd__select(m, inside, f->r1 - below);
    f->v1 = m[f->r1 - below];
    hd__select(m, inside, f->r2 - below);
    f->v2 = m[f->r2 - below];
    free(m);
    f->settled = 1;
    return HD_OK;
}

static void figure_init(figure_t *f, size_t n, double p) {
    hd__percentile_ranks(n, p, &f->r1, &f->r2, &f->t);
    f->settled = 0;
}

static double figure_value(const figure_t *f) {
    return hd__lerp(sqrt(f->v1), sqrt(f->v2), f->t);
}

/* The passes: part[d] classifies direction d against the union of the
 * bands of its figure and the pooled one; a pass runs again only when that
 * union changed. */
typedef struct {
    const hd__pct_src_t *src;
    hd__an_band_t part[2];
    double lo2[2], hi2[2]; /* the union each part was made with */
} passes_t;

static int passes_update(passes_t *ps, const figure_t *dir, const figure_t *pooled, hd_error_t *err) {
    for (int d = 0; d < 2; d++) {
        double lo2 = dir[d].lo2 < pooled->lo2 ? dir[d].lo2 : pooled->lo2;
        double hi2 = dir[d].hi2 > pooled->hi2 ? dir[d].hi2 : pooled->hi2;
        if (ps->part[d].v && lo2 == ps->lo2[d] && hi2 == ps->hi2[d]) continue;
        free(ps->part[d].v);
        ps->part[d].v = NULL;
        int rc = ps->src->band(ps->src->ctx, d, lo2, hi2, &ps->part[d], err);
        if (rc) return rc;
        ps->lo2[d] = lo2, ps->hi2[d] = hi2;
    }
    return HD_OK;
}

int hd__percentile_run(const hd__pct_src_t *src, size_t na, size_t nb, double p, hd_percentile_t *out,
                       hd_error_t *err) {
    size_t n[2] = {na, nb};
    sample_t smp[2] = {{0}, {0}};
    figure_t dir[2], pooled;
    passes_t ps = {src, {{0}, {0}}, {0, 0}, {0, 0}};
    int rc = HD_OK;
    for (int d = 0; d < 2 && rc == HD_OK; d++) rc = sample_of(src, d, n[d], &smp[d], err);
    for (int d = 0; d < 2 && rc == HD_OK; d++) {
        figure_init(&dir[d], n[d], p);
        band_of(&smp[d], 1, dir[d].r1, dir[d].r2, &dir[d].lo2, &dir[d].hi2);
    }
    if (rc == HD_OK) {
        figure_init(&pooled, na + nb, p);
        band_of(smp, 2, pooled.r1, pooled.r2, &pooled.lo2, &pooled.hi2);
    }
    while (rc == HD_OK && !(dir[0].settled && dir[1].settled && pooled.settled)) {
        if ((rc = passes_update(&ps, dir, &pooled, err))) break;
        for (int d = 0; d < 2 && rc == HD_OK; d++)
            if (!dir[d].settled) rc = figure_select(&dir[d], &ps.part[d], 1, err);
        if (rc == HD_OK && !pooled.settled) rc = figure_select(&pooled, ps.part, 2, err);
    }
    if (rc == HD_OK) {
        out->p = p;
        out->ab = figure_value(&dir[0]);
        out->ba = figure_value(&dir[1]);
        out->symmetric = out->ab >= out->ba ? out->ab : out->ba;
        out->pooled = figure_value(&pooled);
    }
    for (int d = 0; d < 2; d++) free(smp[d].v), free(ps.part[d].v);
    return rc;
}

/* The structures' source: the samples on a structure of the sampled
 * points searching the other set's whole structure, the passes by
 * hd__an_band_settled. */
typedef struct {
    const hd__an_t *s;
    const hd_points_t *set[2];
    const hd__box_t *keybox;
    int threads;
} an_src_t;

static int an_sample(void *ctx, int d, const uint32_t *sel, size_t m, hd__an_band_t *out, hd_error_t *err) {
    const an_src_t *c = ctx;
    hd__an_t one;
    int rc = hd__an_build_sel(&one, c->set[d], sel, NULL, m, c->keybox, c->threads, err);
    if (rc) return rc;
    rc = hd__an_band(&one, &c->s[1 - d], 0.0, INFINITY, c->threads, out, err);
    hd__an_free(&one);
    return rc;
}

static int an_band(void *ctx, int d, double lo2, double hi2, hd__an_band_t *out, hd_error_t *err) {
    const an_src_t *c = ctx;
    return hd__an_band_settled(&c->s[d], &c->s[1 - d], c->set[d], c->keybox, lo2, hi2, c->threads, out, NULL,
                               err);
}

int hd__percentile_points(const hd_points_t *A, const hd_points_t *B, const hd__an_t s[2],
                          const hd__box_t *keybox, int threads, double p, hd_percentile_t *out, hd_error_t *err) {
    an_src_t c = {s, {A, B}, keybox, threads};
    hd__pct_src_t src = {an_sample, an_band, &c};
    return hd__percentile_run(&src, A->count, B->count, p, out, err);
}
