/*
 * select.c -- the percentile of the per-point nearest distances over the
 * ranks without every distance (hausdorff_mpi.h:
 * hd_mpi_hausdorff_percentile): hd_hausdorff_percentile's four figures on
 * the union of every rank's points, to the bit, on every rank.
 *
 * On one rank: hd_hausdorff_percentile on the views (the figures depend on
 * the multiset of distances, not on the points' order).
 *
 * On K > 1 ranks, after the partition and the exchange (mpi.c's steps 1
 * and 2: each rank holds the points of its region), the single process's
 * method (nearest/percentile.c) with its passes split over the ranks:
 *  1. A sample: SAMPLE points of each set over all ranks (each rank's
 *     share in proportion to its points, evenly spaced), each with its
 *     exact global squared distance (exact_of below); every rank gathers
 *     every sample and computes the same bands (hd__percentile_band).
 *  2. A pass per direction over the band [L, H] (the union of the bands of
 *     the figures it serves): hd__an_band of the local points P against
 *     the local points Q counts the points whose local nearest squared
 *     distance u lies below L and keeps the values in [L, H].  The global
 *     distance g is min(u, what other ranks hold) <= u, so a point counted
 *     below is below globally.  A point whose region faces are clear of H
 *     (hd__mpi_faces_clear: every point of another region is strictly
 *     farther than sqrt(H)) has g = u when u <= H, and g > H when u > H:
 *     the pass classifies it exactly.  The others (the shell: near a face,
 *     or every point when the rank holds no Q) get their exact g: their
 *     local nearest, then, when u >= L and the faces are not clear of u,
 *     the candidate ranks' answers (hd__mpi_round, as hd_mpi_distances
 *     forwards).  Where g < u, the pass's classification of u is replaced
 *     by g's: u leaves the kept values (when in [L, H]), g joins them or
 *     the count below.  Each rank then holds the count of its points below
 *     L and the sorted multiset of its points' exact values in [L, H].
 *  3. Each figure (A->B, B->A, both pooled; ranks r1 <= r2 of numpy's
 *     interpolation, hd__percentile_ranks) sums, with one MPI_Allreduce,
 *     the points below its band and inside it.  When c <= r1 and
 *     c + inside > r2, ranks r1 - c and r2 - c of the values inside are
 *     selected exactly across the ranks: eight rounds of a radix selection
 *     on the values' bits (non-negative doubles order as their bits), each
 *     rank counting its values under the prefix found so far in 256 bins
 *     of the next 8 bits (a contiguous range of its sorted values), one
 *     MPI_Allreduce adding the counts.  Otherwise the failing side of the
 *     band is opened and the passes run again, as in the single process:
 *     a band open on both sides holds both ranks, so this ends.
 * The sample and the bands decide only the cost; every value selected is
 * an exact hd__d2 of the same doubles the single process reads, so the
 * ranks' values are its values and hd__lerp of their square roots its
 * result.  Every rank takes the same branches (the bands come from the
 * same gathered samples and reduced counts), so the collectives match.
 */
#include "mpi/course.h"
#include "mpi/search.h"

#include <stdlib.h>

#define SAMPLE 4096 /* points sampled per direction, over all ranks */
#define DIGIT 8
#define BINS (1u << DIGIT)

/* What every step reads: the local sets and their structures. */
typedef struct {
    const hd__mpi_spread_t *sp;
    hd__box_t kb;       /* the key box of every structure here */
    hd__an_t an[2];     /* the local sets' structures (n > 0) */
    size_t bytes[2];
    int built[2];
} local_t;

static int threads_for(const hd__mpi_ctx_t *c, size_t n) { return hd__thread_count(c->threads, n ? n : 1); }

/* ---- exact global distances of some local points ------------------------------ */

typedef struct {
    const local_t *lc;
    int qs;
} answer_arg_t;

/* Forwarded queries against this rank's local Q: the exact squared
 * distance to its nearest point (the index is not needed: values only). */
static int answer(hd__mpi_ctx_t *c, void *arg, const double *pts, size_t m, hd__mpi_ans_t *ans) {
    const answer_arg_t *a = arg;
    const local_t *lc = a->lc;
    size_t nQ = lc->sp->loc.n[a->qs];
    const double *Q = lc->sp->loc.xyz[a->qs];
    if (m == 0) return HD_OK;
    if (nQ == 0) {
        for (size_t k = 0; k < m; k++) ans[k] = (hd__mpi_ans_t){INFINITY, UINT64_MAX};
        return HD_OK;
    }
    hd__an_t asked;
    size_t bytes = 0, *near = hd__mpi_alloc(c, m, sizeof(size_t));
    hd_points_t v = hd_points_f64(pts, m);
    int rc = near ? hd__mpi_an_build(c, &asked, &v, NULL, NULL, 0, &lc->kb, threads_for(c, m), &bytes)
                  : hd__mpi_nomem(c, "answers", m);
    if (rc == HD_OK) rc = hd__mpi_an_nearest(c, &asked, &lc->an[a->qs], NULL, threads_for(c, m), near);
    for (size_t k = 0; k < m && rc == HD_OK; k++) ans[k] = (hd__mpi_ans_t){hd__d2(pts + 3 * k, Q + 3 * near[k]), 0};
    if (bytes) hd__mpi_an_release(c, &asked, bytes);
    hd__mpi_free(c, near, m, sizeof(size_t));
    return rc;
}

/* The local nearest squared distances u[t] (+inf when this rank holds no
 * Q) of the m local points P[sel[t]] of side s (sel increasing). */
static int local_of(hd__mpi_ctx_t *c, const local_t *lc, int s, const uint32_t *sel, size_t m, double *u) {
    int qs = 1 - s;
    size_t nQ = lc->sp->loc.n[qs];
    const double *P = lc->sp->loc.xyz[s], *Q = lc->sp->loc.xyz[qs];
    if (m == 0) return HD_OK;
    if (nQ == 0) {
        for (size_t t = 0; t < m; t++) u[t] = INFINITY;
        return HD_OK;
    }
    uint32_t *names = hd__mpi_alloc(c, m, sizeof(uint32_t));
    size_t *near = hd__mpi_alloc(c, m, sizeof(size_t)), bytes = 0;
    int rc = names && near ? HD_OK : hd__mpi_nomem(c, "the shell", m);
    hd__an_t sub;
    hd_points_t v = hd_points_f64(P, lc->sp->loc.n[s]);
    for (size_t t = 0; t < m && rc == HD_OK; t++) names[t] = (uint32_t)t; /* answers at t */
    double t0 = hd__now(), u0 = hd__mpi_cpu();
    if (rc == HD_OK) rc = hd__mpi_an_build(c, &sub, &v, sel, names, m, &lc->kb, threads_for(c, m), &bytes);
    if (rc == HD_OK) rc = hd__mpi_an_nearest(c, &sub, &lc->an[qs], NULL, threads_for(c, m), near);
    for (size_t t = 0; t < m && rc == HD_OK; t++) u[t] = hd__d2(P + 3 * (size_t)sel[t], Q + 3 * near[t]);
    if (bytes) hd__mpi_an_release(c, &sub, bytes);
    c->search += hd__now() - t0;
    c->search_cpu += hd__mpi_cpu() - u0;
    hd__mpi_free(c, names, m, sizeof(uint32_t));
    hd__mpi_free(c, near, m, sizeof(size_t));
    return rc;
}

/* The exact global squared distances g[t] of the m local points P[sel[t]]
 * of side s (sel increasing), u[t] an actual squared distance from each to
 * a local point of Q (+inf when none is known), where the caller needs g
 * only when it is at most cap: g = u where u < skip (the caller needs only
 * that g < skip, and g <= u), and where the region's faces are clear of
 * min(u, cap) or no other rank's box of Q is that near (mpi.c's step 4);
 * the others ask the candidate ranks, and g is the smallest answer (when
 * u > cap, g <= cap is exact and g > cap only says so).  Collective (one
 * forwarding round, on every rank). */
static int exact_of(hd__mpi_ctx_t *c, int rc, const local_t *lc, int s, const uint32_t *sel, size_t m,
                    const double *u, double skip, double cap, double *g) {
    const hd__mpi_spread_t *sp = lc->sp;
    int K = c->K, qs = 1 - s, none_here = sp->loc.n[qs] == 0;
    const double *P = sp->loc.xyz[s];
    const hd__box_t *mine = &sp->region[c->rank];
    hd__box_t *nbox = hd__mpi_alloc(c, (size_t)K - 1, sizeof(hd__box_t));
    int *list = hd__mpi_alloc(c, (size_t)K, sizeof(int));
    uint64_t *jj = hd__mpi_alloc(c, m, sizeof(uint64_t));
    hd__mpi_pairs_t pr = {NULL, 0, 0};
    if (rc == HD_OK && (!nbox || !list || !jj)) rc = hd__mpi_nomem(c, "the shell", m);
    if (rc == HD_OK) hd__mpi_node_boxes(sp->tree, 0, sp->held, qs, nbox);
    for (size_t t = 0; t < m && rc == HD_OK; t++) {
        const double *p = P + 3 * (size_t)sel[t];
        double bound = u[t] < cap ? u[t] : cap;
        g[t] = u[t], jj[t] = 0;
        if (u[t] < skip || hd__mpi_faces_clear(mine, p, bound)) continue;
        int n = hd__mpi_asked(sp->tree, nbox, sp->held, K, qs, none_here, p, bound, c->rank, list);
        if (n == 0) continue;
        c->forwarded_points++;
        c->shell++; /* its exact distance from another rank */
        rc = hd__mpi_pairs_add(c, &pr, t, list, n);
    }
    hd__mpi_free(c, nbox, (size_t)K - 1, sizeof(hd__box_t));
    hd__mpi_free(c, list, (size_t)K, sizeof(int));
    answer_arg_t an = {lc, qs};
    rc = hd__mpi_round(c, rc, P, sel, &pr, answer, &an, g, jj);
    hd__mpi_pairs_free(c, &pr);
    hd__mpi_free(c, jj, m, sizeof(uint64_t));
    return rc;
}

/* ---- the sample ---------------------------------------------------------------- */

static int cmp_double(const void *x, const void *y) {
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

/* Every rank's sample of side s: its share of SAMPLE points, evenly
 * spaced over its local points, with their exact global squared
 * distances, sorted; gathered into smp[0..K) (smp[0].v holds all the
 * values, smp[r].v points into it).  Collective. */
static int sample_of(hd__mpi_ctx_t *c, int rc, const local_t *lc, int s, uint64_t N, hd__pct_sample_t *smp,
                     double **all, size_t *nall) {
    int K = c->K;
    size_t n = lc->sp->loc.n[s], m = n ? (size_t)((uint64_t)SAMPLE * n / N) + 1 : 0;
    if (m > n) m = n;
    uint32_t *sel = hd__mpi_alloc(c, m, sizeof(uint32_t));
    double *u = hd__mpi_alloc(c, m, sizeof(double)), *g = hd__mpi_alloc(c, m, sizeof(double));
    uint64_t *mn = hd__mpi_alloc(c, 2 * (size_t)K, sizeof(uint64_t));
    int *cnt = hd__mpi_alloc(c, 2 * (size_t)K, sizeof(int));
    *all = NULL, *nall = 0;
    if (rc == HD_OK && (!sel || !u || !g || !mn || !cnt)) rc = hd__mpi_nomem(c, "the sample", m);
    for (size_t k = 0; k < m && rc == HD_OK; k++) sel[k] = (uint32_t)((uint64_t)k * n / m);
    if (rc == HD_OK) rc = local_of(c, lc, s, sel, m, u);
    rc = exact_of(c, rc, lc, s, sel, m, u, 0.0, INFINITY, g);
    c->shell += m;
    if (rc == HD_OK) qsort(g, m, sizeof *g, cmp_double);
    uint64_t mine[2] = {m, n};
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    HD__MPI_GO(c, rc, MPI_Allgather(mine, 2, MPI_UINT64_T, mn, 2, MPI_UINT64_T, c->comm));
    for (int r = 0; r < K; r++) {
        cnt[K + r] = (int)*nall; /* displacements */
        cnt[r] = (int)mn[2 * r];
        *nall += (size_t)mn[2 * r];
    }
    if (!(*all = hd__mpi_alloc(c, *nall, sizeof(double)))) rc = hd__mpi_nomem(c, "the samples", *nall);
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    HD__MPI_GO(c, rc, MPI_Allgatherv(g, (int)m, MPI_DOUBLE, *all, cnt, cnt + K, MPI_DOUBLE, c->comm));
    for (int r = 0; r < K; r++)
        smp[r] = (hd__pct_sample_t){*all + cnt[K + r], (size_t)mn[2 * r], (size_t)mn[2 * r + 1]};
done:
    hd__mpi_free(c, sel, m, sizeof(uint32_t));
    hd__mpi_free(c, u, m, sizeof(double));
    hd__mpi_free(c, g, m, sizeof(double));
    hd__mpi_free(c, mn, 2 * (size_t)K, sizeof(uint64_t));
    hd__mpi_free(c, cnt, 2 * (size_t)K, sizeof(int));
    return rc;
}

/* ---- a direction's pass --------------------------------------------------------- */

/* This rank's points of one direction against the band [L, H]: below of
 * them have an exact global squared distance below L, and v[0..n) (sorted)
 * are the values of those inside. */
typedef struct {
    int have;
    double L, H;
    uint64_t below;
    double *v;
    size_t n, cap;
} part_t;

static void part_free(hd__mpi_ctx_t *c, part_t *pt) {
    hd__mpi_free(c, pt->v, pt->cap, sizeof(double));
    memset(pt, 0, sizeof *pt);
}

/* The values of `from` (sorted) without those of `minus` (sorted, a
 * sub-multiset of it), into `from` itself; returns how many are left. */
static size_t remove_sorted(double *from, size_t n, const double *minus, size_t nm) {
    size_t k = 0, j = 0;
    for (size_t i = 0; i < n; i++) {
        if (j < nm && from[i] == minus[j]) {
            j++;
            continue;
        }
        from[k++] = from[i];
    }
    assert(j == nm);
    return k;
}

/* The pass of side s over [L, H] into *pt (step 2 of the essay): the
 * band's class of every local point (hd__an_band_each), then the exact
 * global value of those inside or above it that another rank may hold a
 * nearer point for (exact_of), their class corrected where it is smaller.
 * Collective. */
static int pass(hd__mpi_ctx_t *c, const local_t *lc, int s, double L, double H, part_t *pt) {
    const hd__mpi_spread_t *sp = lc->sp;
    int qs = 1 - s, rc = HD_OK;
    size_t nP = sp->loc.n[s], nQ = sp->loc.n[qs], m = 0, nb = 0;
    hd__an_band_t b = {0, 0, 0, NULL, 0};
    part_free(c, pt);
    pt->L = L, pt->H = H;
    double *each = hd__mpi_alloc(c, nQ ? nP : 0, sizeof(double));
    if (!each) rc = hd__mpi_nomem(c, "the band", nP);
    double t0 = hd__now(), u0 = hd__mpi_cpu();
    if (rc == HD_OK && nP && nQ)
        rc = hd__an_band_each(&lc->an[s], &lc->an[qs], L, H, threads_for(c, nP), &b, each, &c->e);
    c->search += hd__now() - t0;
    c->search_cpu += hd__mpi_cpu() - u0;
    nb = b.n;
    c->shell += nb;
    /* the points not settled below (every point when no Q is here) */
    for (size_t k = 0; k < nP && rc == HD_OK; k++) m += nQ == 0 || each[k] >= 0;
    uint32_t *sel = hd__mpi_alloc(c, m, sizeof(uint32_t));
    double *u = hd__mpi_alloc(c, m, sizeof(double)), *g = hd__mpi_alloc(c, m, sizeof(double));
    double *minus = hd__mpi_alloc(c, m, sizeof(double));
    pt->cap = nb + m;
    pt->v = hd__mpi_alloc(c, pt->cap, sizeof(double));
    if (rc == HD_OK && (!sel || !u || !g || !minus || !pt->v)) rc = hd__mpi_nomem(c, "the band", nb + m);
    for (size_t k = 0, t = 0; k < nP && rc == HD_OK; k++)
        if (nQ == 0 || each[k] >= 0) sel[t] = (uint32_t)k, u[t++] = nQ ? each[k] : INFINITY;
    hd__mpi_free(c, each, nQ ? nP : 0, sizeof(double));
    rc = exact_of(c, rc, lc, s, sel, m, u, L, H, g);
    size_t nm = 0, np = nb;
    if (rc == HD_OK) {
        pt->below = b.below;
        if (nb) memcpy(pt->v, b.v, nb * sizeof(double));
        for (size_t t = 0; t < m; t++) {
            if (nQ && g[t] == u[t]) continue; /* the band's class is g's */
            if (nQ && u[t] <= H) minus[nm++] = u[t]; /* u >= L here: it was kept */
            if (g[t] < L) pt->below++;
            else if (g[t] <= H) pt->v[np++] = g[t];
        }
        qsort(pt->v, nb, sizeof(double), cmp_double);
        qsort(minus, nm, sizeof(double), cmp_double);
        pt->n = remove_sorted(pt->v, nb, minus, nm);
        for (size_t k = nb; k < np; k++) pt->v[pt->n++] = pt->v[k]; /* g's values, after the band's */
        qsort(pt->v, pt->n, sizeof(double), cmp_double);
        pt->have = 1;
    }
    free(b.v);
    hd__mpi_free(c, sel, m, sizeof(uint32_t));
    hd__mpi_free(c, u, m, sizeof(double));
    hd__mpi_free(c, g, m, sizeof(double));
    hd__mpi_free(c, minus, m, sizeof(double));
    return hd__mpi_agree(c, rc);
}

/* ---- the figures and their selection ---------------------------------------------- */

/* One figure: the values of the directions in `dirs` (bit d), its ranks,
 * its band, and its answer once settled. */
typedef struct {
    int dirs;
    size_t r1, r2;
    double t, lo2, hi2, v1, v2;
    int settled;
} figure_t;

/* The first position of sorted v[0..n) holding a value >= x (above: > x). */
static size_t first_at_least(const double *v, size_t n, double x, int above) {
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (above ? v[mid] <= x : v[mid] < x) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

/* One selection: rank k of a figure's values inside its band, over every
 * rank; a[d], b[d] the range of part d's local values under the prefix. */
typedef struct {
    const figure_t *f;
    uint64_t k, prefix;
    size_t a[2], b[2];
} sel_t;

/* The values of the ns selections into out[] (step 3's radix selection:
 * non-negative doubles order as their bits).  Collective. */
static int select_ranks(hd__mpi_ctx_t *c, const part_t pt[2], sel_t *sel, int ns, double *out) {
    size_t words = (size_t)ns * BINS;
    /* each selection's counts: this rank's by direction, then summed, then over every rank */
    uint64_t *dir = hd__mpi_alloc(c, 4 * words, sizeof(uint64_t)), *mine = dir + 2 * words, *all = mine + words;
    int rc = dir ? HD_OK : hd__mpi_nomem(c, "the selection's histograms", words);
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) return rc;
    for (int round = 0; round < 64 / DIGIT; round++) {
        int shift = 64 - DIGIT * (round + 1);
        memset(dir, 0, 3 * words * sizeof *dir);
        for (int s = 0; s < ns; s++)
            for (int d = 0; d < 2; d++) {
                uint64_t *h = dir + ((size_t)s * 2 + (size_t)d) * BINS;
                for (size_t i = sel[s].a[d]; i < sel[s].b[d]; i++) h[(hd__bits_of(pt[d].v[i]) >> shift) & (BINS - 1)]++;
                for (uint32_t e = 0; e < BINS; e++) mine[(size_t)s * BINS + e] += h[e];
            }
        HD__MPI_GO(c, rc, MPI_Allreduce(mine, all, (int)words, MPI_UINT64_T, MPI_SUM, c->comm));
        for (int s = 0; s < ns; s++) { /* the same walk on every rank */
            const uint64_t *h = all + (size_t)s * BINS;
            uint32_t b = 0;
            while (sel[s].k >= h[b]) sel[s].k -= h[b++];
            assert(b < BINS);
            sel[s].prefix = sel[s].prefix << DIGIT | b;
            for (int d = 0; d < 2; d++) { /* the local values under the longer prefix */
                const uint64_t *l = dir + ((size_t)s * 2 + (size_t)d) * BINS;
                for (uint32_t e = 0; e < b; e++) sel[s].a[d] += l[e];
                sel[s].b[d] = sel[s].a[d] + l[b];
            }
        }
    }
    for (int s = 0; s < ns; s++) out[s] = hd__double_of(sel[s].prefix);
done:
    hd__mpi_free(c, dir, 4 * words, sizeof(uint64_t));
    return rc;
}

/* Step 3 for every figure not settled: its counts over the ranks, then
 * either its two values (settled) or its band opened where it failed.
 * Collective. */
static int settle(hd__mpi_ctx_t *c, const part_t pt[2], figure_t *fig, int nf) {
    uint64_t cnt[6] = {0};
    sel_t sel[6];
    double val[6];
    int ns = 0;
    for (int f = 0; f < nf; f++)
        for (int d = 0; d < 2; d++) {
            if (fig[f].settled || !(fig[f].dirs >> d & 1)) continue;
            size_t a = first_at_least(pt[d].v, pt[d].n, fig[f].lo2, 0);
            size_t b = first_at_least(pt[d].v, pt[d].n, fig[f].hi2, 1);
            cnt[2 * f] += pt[d].below + a;
            cnt[2 * f + 1] += b - a;
        }
    HD__MPI_TRY(c, MPI_Allreduce(MPI_IN_PLACE, cnt, 2 * nf, MPI_UINT64_T, MPI_SUM, c->comm));
    for (int f = 0; f < nf; f++) {
        figure_t *x = &fig[f];
        uint64_t below = cnt[2 * f], inside = cnt[2 * f + 1];
        if (x->settled) continue;
        if (below > x->r1 || below + inside <= x->r2) {
            if (below > x->r1) x->lo2 = 0;
            if (below + inside <= x->r2) x->hi2 = INFINITY;
            continue;
        }
        for (int j = 0; j < 2; j++) {
            sel_t *s = &sel[ns++];
            *s = (sel_t){x, (j ? x->r2 : x->r1) - below, 0, {0, 0}, {0, 0}};
            for (int d = 0; d < 2; d++)
                if (x->dirs >> d & 1) {
                    s->a[d] = first_at_least(pt[d].v, pt[d].n, x->lo2, 0);
                    s->b[d] = first_at_least(pt[d].v, pt[d].n, x->hi2, 1);
                }
        }
    }
    if (ns == 0) return HD_OK; /* the same on every rank */
    int rc = select_ranks(c, pt, sel, ns, val);
    for (int s = 0; s < ns && rc == HD_OK; s += 2) {
        figure_t *x = (figure_t *)sel[s].f;
        x->v1 = val[s], x->v2 = val[s + 1], x->settled = 1;
    }
    return rc;
}

/* ---- the call ------------------------------------------------------------------ */

typedef struct {
    double p;
    hd_percentile_t *out;
} pct_arg_t;

/* The local sets' structures on one key box (as hd_mpi_distances). */
static int local_build(hd__mpi_ctx_t *c, const hd__mpi_spread_t *sp, local_t *lc) {
    int rc = HD_OK;
    memset(lc, 0, sizeof *lc);
    lc->sp = sp;
    lc->kb = sp->held[c->rank].box[0];
    hd__box_merge(&lc->kb, &sp->held[c->rank].box[1]);
    double t0 = hd__now(), u0 = hd__mpi_cpu();
    for (int s = 0; s < 2 && rc == HD_OK; s++) {
        size_t n = sp->loc.n[s];
        if (n == 0) continue;
        if (n > HD__AN_MAX_POINTS)
            rc = hd__err(&c->e, HD_ERANGE, "%zu points on one rank: the per-point search takes at most %zu", n,
                         (size_t)HD__AN_MAX_POINTS);
        hd_points_t v = hd_points_f64(sp->loc.xyz[s], n);
        if (rc == HD_OK)
            rc = hd__mpi_an_build(c, &lc->an[s], &v, NULL, NULL, 0, &lc->kb, threads_for(c, n), &lc->bytes[s]);
        lc->built[s] = rc == HD_OK;
    }
    c->search += hd__now() - t0;
    c->search_cpu += hd__mpi_cpu() - u0;
    return hd__mpi_agree(c, rc);
}

static void local_free(hd__mpi_ctx_t *c, local_t *lc) {
    for (int s = 0; s < 2; s++)
        if (lc->built[s]) hd__mpi_an_release(c, &lc->an[s], lc->bytes[s]);
}

/* The three figures from the bands of the gathered samples, then passes
 * and selections until each is settled (the essay's steps 1-3).
 * Collective. */
static int figures_of(hd__mpi_ctx_t *c, const local_t *lc, const uint64_t N[2], double p, figure_t fig[3]) {
    int K = c->K, rc = HD_OK;
    hd__pct_sample_t *smp = hd__mpi_alloc(c, 2 * (size_t)K, sizeof *smp);
    size_t *at = hd__mpi_alloc(c, 2 * (size_t)K, sizeof *at), nall[2] = {0, 0};
    double *all[2] = {NULL, NULL};
    part_t pt[2];
    memset(pt, 0, sizeof pt);
    if (!smp || !at) rc = hd__mpi_nomem(c, "the samples", (size_t)K);
    for (int s = 0; s < 2; s++) rc = sample_of(c, rc, lc, s, N[s], smp ? smp + (size_t)s * K : NULL, &all[s], &nall[s]);
    uint64_t n[3] = {N[0], N[1], N[0] + N[1]};
    for (int f = 0; f < 3 && rc == HD_OK; f++) {
        fig[f] = (figure_t){f + 1, 0, 0, 0, 0, INFINITY, 0, 0, 0};
        hd__percentile_ranks((size_t)n[f], p, &fig[f].r1, &fig[f].r2, &fig[f].t);
        /* A->B's samples, B->A's, or both (the 2K samples in a row) */
        hd__percentile_band(smp + (f == 1 ? (size_t)K : 0), f == 2 ? 2 * K : K, at, fig[f].r1, fig[f].r2, &fig[f].lo2,
                            &fig[f].hi2);
    }
    while (rc == HD_OK && !(fig[0].settled && fig[1].settled && fig[2].settled)) {
        for (int d = 0; d < 2 && rc == HD_OK; d++) {
            double L = fig[d].lo2 < fig[2].lo2 ? fig[d].lo2 : fig[2].lo2;
            double H = fig[d].hi2 > fig[2].hi2 ? fig[d].hi2 : fig[2].hi2;
            if (!pt[d].have || L != pt[d].L || H != pt[d].H) rc = pass(c, lc, d, L, H, &pt[d]);
        }
        if (rc == HD_OK) rc = settle(c, pt, fig, 3);
    }
    for (int d = 0; d < 2; d++) {
        part_free(c, &pt[d]);
        hd__mpi_free(c, all[d], nall[d], sizeof(double));
    }
    hd__mpi_free(c, smp, 2 * (size_t)K, sizeof *smp);
    hd__mpi_free(c, at, 2 * (size_t)K, sizeof *at);
    return rc;
}

static double figure_value(const figure_t *f) { return hd__lerp(sqrt(f->v1), sqrt(f->v2), f->t); }

static int percentile_body(hd__mpi_ctx_t *c, const hd_options_t *opt, hd__mpi_input_t *in, void *arg,
                           hd_mpi_stats_t *st) {
    pct_arg_t *a = arg;
    hd__mpi_course_t cs;
    hd__mpi_course_init(c, &cs);
    local_t lc;
    memset(&lc, 0, sizeof lc);
    int rc = a->out ? hd__percentile_check(a->p, &c->e) : HD_OK;
    if ((rc = hd__mpi_agree(c, rc)) == HD_OK) rc = hd__mpi_begin(c, opt, in, a->out, &cs.rg, cs.N, NULL);
    if (rc != HD_OK) goto done;
    uint64_t pts = in->n[0] + in->n[1];
    if (c->K == 1) {
        hd__mpi_views_t vw;
        if ((rc = hd__mpi_views(c, in, &vw)) == HD_OK) {
            double t0 = hd__now(), u0 = hd__mpi_cpu();
            rc = hd_hausdorff_percentile(&vw.v[0], &vw.v[1], opt, a->p, a->out, &c->e);
            c->search += hd__now() - t0;
            c->search_cpu += hd__mpi_cpu() - u0;
        }
        hd__mpi_views_free(c, in, &vw);
    } else {
        figure_t fig[3];
        if ((rc = hd__mpi_spread(c, in, &cs.rg, cs.N, NULL, &cs.sp)) != HD_OK) goto done;
        pts = cs.sp.loc.n[0] + cs.sp.loc.n[1];
        if ((rc = local_build(c, &cs.sp, &lc)) != HD_OK) goto done;
        if ((rc = figures_of(c, &lc, cs.N, a->p, fig)) != HD_OK) goto done;
        hd_percentile_t *o = a->out;
        o->p = a->p;
        o->ab = figure_value(&fig[0]);
        o->ba = figure_value(&fig[1]);
        o->symmetric = o->ab >= o->ba ? o->ab : o->ba;
        o->pooled = figure_value(&fig[2]);
    }
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    double tmax;
    rc = hd__mpi_figures(c, &cs, pts, st, &tmax);
done:
    local_free(c, &lc);
    hd__mpi_course_free(c, &cs);
    return rc;
}

int hd_mpi_hausdorff_percentile(MPI_Comm comm, const hd_mpi_part_t *a, size_t na, const hd_mpi_part_t *b, size_t nb,
                                const hd_mpi_options_t *opt, double p, hd_percentile_t *out, hd_mpi_stats_t *stats,
                                hd_error_t *err) {
    pct_arg_t arg = {p, out};
    return hd__mpi_call(comm, a, na, b, nb, opt, percentile_body, &arg, stats, err);
}
