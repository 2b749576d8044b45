/*
 * slab.c -- the per-point searches of a rank's local set Q: the exact
 * nearest point of Q (smallest index on ties, as hd_distances gives it)
 * for the shell's points (shell.c) and the queries forwarded from other
 * ranks (forward.c).
 *
 * The structures of the searched local set Q for per-point searches (the
 * nearest layer's, as hd_distances builds them), built on first use and
 * kept for the direction: the shell and the forwarded queries ask them in
 * turn.  Only the points that ask need them, and those are few (the
 * shell: the engine's refused points, or in its unfiltered fallback the
 * points within h of a face; and queries from beyond the faces).  At most
 * SCAN_MAX of them, while nothing is built, are answered by one pass over
 * Q (scan_q) and need no structure; more ask one built over a slab: the
 * points of Q within a margin M of a finite face.  An answer from the slab is the answer from all of Q when
 * every point left out is provably farther (hd__mpi_slab_proves); the others,
 * when a few, are compared with every point of Q, else ask a slab as wide
 * as they need and an eighth more (it replaces the first), then all of Q.
 * The structures hold no copy of the points but their own: a slab's is
 * built over Q's positions and answers with them, an asking one over the
 * askers' positions and writes each answer at its asker
 * (hd__an_build_sel).
 *
 * Proof.  A point b of Q left out has fl(|b_k - s|) > M for every finite
 * face s (on axis k) of the region, which holds b.  For a lo face s and any
 * x, b_k - x_k = (b_k - s) + (s - x_k) > M + o with o = s - x_k; for a hi
 * face x_k - b_k = (x_k - s) + (s - b_k) > M + o with o = x_k - s.  So
 * |x_k - b_k| > lb = M + max over faces of o, and hd__d2(x, b) >= fl(fl(x_k
 * - b_k)^2) > lb^2 (1 - 4 eps) when lb^2 is normal: rounding is monotone.
 * lb is computed with a relative slack of 1e-12 and the test asks
 * d2 < lb^2 (1 - 1e-9), far beyond the few ulps involved; below 1e-140 no
 * proof is tried.
 */
#include "mpi/search.h"

#include <assert.h>
#include <stdlib.h>

/* A structure is charged, once built, at the most its build held (the
 * build's own account: what it allocated, hd__an_t.peak) on top of what
 * this layer held meanwhile, then at what it keeps. */
int hd__mpi_an_build(hd__mpi_ctx_t *c, hd__an_t *s, const hd_points_t *v, const uint32_t *sel, const uint32_t *names,
                     size_t m, const hd__box_t *kb, int threads, size_t *bytes) {
    int rc = sel ? hd__an_build_sel(s, v, sel, names, m, kb, threads, &c->e)
                 : hd__an_build(s, v, NULL, kb, threads, &c->e);
    *bytes = 0;
    if (rc != HD_OK) return rc;
    hd__mpi_charge(c, s->peak);
    c->cur -= s->peak;
    *bytes = hd__an_bytes(s);
    hd__mpi_charge(c, *bytes);
    return rc;
}

int hd__mpi_an_nearest(hd__mpi_ctx_t *c, const hd__an_t *asking, const hd__an_t *searched, const uint32_t *pair_at,
                       int threads, size_t *near) {
    size_t b = hd__an_nearest_bytes(asking, searched, threads);
    hd__mpi_charge(c, b);
    int rc = hd__an_nearest_paired(asking, searched, pair_at, threads, NULL, near, NULL, &c->e);
    c->cur -= b;
    return rc;
}

void hd__mpi_an_release(hd__mpi_ctx_t *c, hd__an_t *s, size_t bytes) {
    hd__an_free(s);
    c->cur -= bytes;
}

static void slab_free(hd__mpi_ctx_t *c, hd__mpi_slab_t *sl) {
    if (sl->built) hd__mpi_an_release(c, &sl->s, sl->bytes);
    memset(sl, 0, sizeof *sl);
}

void hd__mpi_qtree_free(hd__mpi_ctx_t *c, hd__mpi_qtree_t *q) {
    slab_free(c, &q->sub);
    slab_free(c, &q->full);
}

/* The lower bound lb of the proof above for x, minus its slack. */
static double slab_lb(const hd__box_t *r, double M, const double *x) {
    double o = -INFINITY;
    for (int a = 0; a < 3; a++) {
        if (isfinite(r->lo[a]) && r->lo[a] - x[a] > o) o = r->lo[a] - x[a];
        if (isfinite(r->hi[a]) && x[a] - r->hi[a] > o) o = x[a] - r->hi[a];
    }
    if (!isfinite(o)) return 0; /* no finite face: every point is in the slab */
    return (M + o) - 1e-12 * (M + fabs(o));
}

int hd__mpi_slab_proves(const hd__box_t *r, double M, const double *x, double d2) {
    double lb = slab_lb(r, M, x);
    return lb > 1e-140 && d2 < lb * lb * (1 - 1e-9);
}

/* The finite faces of a region: axis and place of each. */
typedef struct {
    int n, axis[6];
    double at[6];
} faces_t;

static void faces_of(const hd__box_t *r, faces_t *f) {
    f->n = 0;
    for (int a = 0; a < 3; a++) {
        if (isfinite(r->lo[a])) f->axis[f->n] = a, f->at[f->n++] = r->lo[a];
        if (isfinite(r->hi[a])) f->axis[f->n] = a, f->at[f->n++] = r->hi[a];
    }
}

/* Whether b is within M of a finite face (the computed |b_k - s| <= M:
 * the proof's test, for a lo face or a hi face alike). */
static int near_face(const faces_t *f, const double *b, double M) {
    for (int k = 0; k < f->n; k++)
        if (fabs(b[f->axis[k]] - f->at[k]) <= M) return 1;
    return 0;
}

/* Build the slab of margin M (infinite: all of Q).  Its structure names
 * its points by their positions in Q (hd__an_build_sel): no copy of them
 * is made, and its answers need no map back. */
static int slab_build(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__box_t *r, double M, hd__mpi_slab_t *sl) {
    memset(sl, 0, sizeof *sl);
    sl->M = M;
    uint32_t *sel = NULL;
    int rc = HD_OK;
    size_t n = d->nQ;
    hd_points_t v = hd_points_f64(d->Q, d->nQ);
    if (isfinite(M)) {
        n = 0;
        faces_t f;
        faces_of(r, &f);
        for (size_t j = 0; j < d->nQ; j++) n += (size_t)near_face(&f, d->Q + 3 * j, M);
        if (n > 0 && !(sel = hd__mpi_alloc(c, n, sizeof(uint32_t)))) rc = hd__mpi_nomem(c, "the searched slab", n);
        for (size_t j = 0, t = 0; j < d->nQ && rc == HD_OK; j++)
            if (near_face(&f, d->Q + 3 * j, M)) sel[t++] = (uint32_t)j;
        /* the slab's box (keys only order, clamped: any box is exact) */
        for (int a = 0; a < 3 && rc == HD_OK && n > 0; a++) {
            double lo = d->Q[3 * (size_t)sel[0] + (size_t)a], hi = lo;
            for (size_t t = 1; t < n; t++) {
                double x = d->Q[3 * (size_t)sel[t] + (size_t)a];
                lo = x < lo ? x : lo;
                hi = x > hi ? x : hi;
            }
            sl->kb.lo[a] = lo, sl->kb.hi[a] = hi;
        }
    } else if (n > 0) {
        hd__box_of(d->Q, n, &sl->kb);
    }
    sl->n = n;
    if (rc == HD_OK && n > 0) {
        rc = hd__mpi_an_build(c, &sl->s, &v, sel, NULL, n, &sl->kb, hd__thread_count(c->threads, n), &sl->bytes);
        sl->built = 1; /* freed by slab_free whatever happened */
    }
    hd__mpi_free(c, sel, n, sizeof(uint32_t));
    return rc;
}

/* near[k] for the points k in list[0..m) (increasing), point k at pts +
 * 3 pos[k] (pos NULL: pts + 3 k), searched in a built slab: Q's index of
 * the nearest (smallest index on ties) within the slab, or SIZE_MAX when
 * the slab is empty.  The asking structure names each point k (names[] or
 * sel[], hd__an_build_sel), so the answers land in near[k] directly.
 * The askers go in batches of at most `batch` (consecutive in list
 * order, whose positions increase): a batch's structure takes about
 * 36 bytes an asker and its search 16, so a shell that is a large share of
 * the rank's points (the lidar scene in strips at K = 16: a quarter of a
 * set) would otherwise raise the call's peak by 50 bytes a point of it.
 * Every asker's answer is its own exact nearest point, whatever batch it
 * is in. */
static int slab_search(hd__mpi_ctx_t *c, const hd__mpi_slab_t *sl, const double *pts, const uint32_t *pos, const uint32_t *list,
                       size_t m, size_t batch, size_t *near) {
    if (m == 0) return HD_OK;
    if (sl->n == 0) {
        for (size_t t = 0; t < m; t++) near[list[t]] = SIZE_MAX;
        return HD_OK;
    }
    if (batch < 1) batch = 1;
    if (batch > m) batch = m;
    uint32_t *sel = NULL; /* one batch's positions, when pos names them */
    if (pos && !(sel = hd__mpi_alloc(c, batch, sizeof(uint32_t)))) return hd__mpi_nomem(c, "the searches", batch);
    int rc = HD_OK;
    for (size_t t0 = 0; t0 < m && rc == HD_OK; t0 += batch) {
        size_t mb = m - t0 < batch ? m - t0 : batch;
        const uint32_t *lb = list + t0;
        for (size_t t = 0; sel && t < mb; t++) sel[t] = pos[lb[t]];
        const uint32_t *from = sel ? sel : lb;
        hd__an_t asking;
        size_t ab = 0;
        int threads = hd__thread_count(c->threads, mb > sl->n ? mb : sl->n);
        hd_points_t Sv = hd_points_f64(pts, (size_t)from[mb - 1] + 1); /* from[] increases */
        rc = hd__mpi_an_build(c, &asking, &Sv, from, sel ? lb : NULL, mb, &sl->kb, threads, &ab);
        if (rc == HD_OK) rc = hd__mpi_an_nearest(c, &asking, &sl->s, NULL, threads, near);
        if (ab) hd__mpi_an_release(c, &asking, ab);
    }
    hd__mpi_free(c, sel, batch, sizeof(uint32_t));
    return rc;
}

/* At most this many points the slab did not prove are compared with
 * every point of Q (on a copy: points whose partner is on another rank)
 * rather than searched in a wider slab.  One pass over Q serves them all,
 * and a point of Q is mostly passed over after one coordinate's gap; the
 * wider slab costs two passes over Q measuring face gaps and a structure
 * over the points in it.  The value is the one with the fewest
 * instructions on mpi_bench's copy case (callgrind; the counts are in
 * docs/scale-out.md). */
#define BRUTE_MAX 4

/* At most this many askers, while no slab is built, are answered by one
 * pass over all of Q (scan_q) instead: the engine's filter leaves a shell
 * of a few points on most ranks, for which the slab's two passes over Q
 * and its structure cost more than one pass (callgrind on mpi_bench's
 * uniform and lidar scenes; the counts are in docs/scale-out.md).  A
 * copy's shell (its pairs cut by a face) is larger and takes the slab. */
#define SCAN_MAX 16
_Static_assert(BRUTE_MAX <= SCAN_MAX, "the few the slab left take the scan's pass");

/* Whether point b lies beyond the box [lo, hi] on axis a by more than
 * sqrt(MB): the larger of its two gaps (positive on one side at most,
 * since lo <= hi), squared as hd__d2 squares the difference it bounds.
 * Both tests are taken, without a branch between them (pass_over_q's
 * first axis runs over every point of Q). */
static inline int beyond(const double *b, int a, const double lo[3], const double hi[3], double MB) {
    double g1 = b[a] - hi[a], g2 = lo[a] - b[a], g = g1 > g2 ? g1 : g2;
    return (g > 0) & (g * g > MB);
}

/* One pass over Q for m <= SCAN_MAX askers, asker t at X(list[t]) (list
 * NULL: X(t)), each from an upper bound of its nearest, best[t] at Q's
 * position at[t] (INFINITY and SIZE_MAX: none), which it lowers to the
 * exact nearest with the smallest index.  A point b of Q is passed over
 * without a distance when it is provably farther than every asker's
 * bound:
 *  - beyond the askers' box on an axis: g = fl(b_a - hi_a) > 0 with
 *    fl(g g) > MB, the largest bound (or the same below lo_a).  For an
 *    asker x, x_a <= hi_a, so fl(b_a - x_a) >= g (rounding is monotone),
 *    hd__d2(x, b) >= fl(fl(b_a - x_a)^2) >= fl(g g) (the squared sum only
 *    adds non-negative terms), > MB >= x's bound: farther, not tied;
 *  - for one asker, when fl(dx dx) > its bound (the same argument).
 * Every other b is compared exactly, the smaller index winning a tie. */
static void pass_over_q(const hd__mpi_dir_t *d, const double *pts, const uint32_t *pos, const uint32_t *list, size_t m,
                        double *best, size_t *at) {
#define X(t) (pts + 3 * (pos ? pos[list ? list[t] : (t)] : list ? list[t] : (t)))
    double lo[3], hi[3];
    assert(m > 0 && m <= SCAN_MAX);
    for (int a = 0; a < 3; a++) lo[a] = hi[a] = X(0)[a];
    for (size_t t = 1; t < m; t++)
        for (int a = 0; a < 3; a++) {
            lo[a] = X(t)[a] < lo[a] ? X(t)[a] : lo[a];
            hi[a] = X(t)[a] > hi[a] ? X(t)[a] : hi[a];
        }
    /* the axes, the askers' thinnest first: most points of Q are beyond
     * the box on it (a shell lies along a face) */
    int ax[3] = {0, 1, 2};
    for (int a = 1; a < 3; a++)
        for (int k = a; k > 0 && hi[ax[k]] - lo[ax[k]] < hi[ax[k - 1]] - lo[ax[k - 1]]; k--) {
            int t = ax[k];
            ax[k] = ax[k - 1], ax[k - 1] = t;
        }
    /* The first axis's test runs over a block, keeping the points it does
     * not pass over (a shell's askers lie along a face: most of Q is
     * beyond them on its normal); the rest runs on those alone. */
    uint32_t keep[4096];
    for (size_t j0 = 0; j0 < d->nQ; j0 += 4096) {
        double MB = 0;
        for (size_t t = 0; t < m; t++) MB = best[t] > MB ? best[t] : MB;
        size_t j1 = d->nQ - j0 < 4096 ? d->nQ : j0 + 4096, nk = 0;
        for (size_t j = j0; j < j1; j++) {
            keep[nk] = (uint32_t)(j - j0);
            nk += !beyond(d->Q + 3 * j, ax[0], lo, hi, MB);
        }
        for (size_t i = 0; i < nk; i++) {
            size_t j = j0 + keep[i];
            const double *b = d->Q + 3 * j;
            if (beyond(b, ax[1], lo, hi, MB) || beyond(b, ax[2], lo, hi, MB)) continue;
            for (size_t t = 0; t < m; t++) {
                const double *x = X(t);
                double dx = x[0] - b[0];
                if (dx * dx > best[t]) continue;
                double d2 = hd__d2(x, b);
                if (d2 < best[t] || (d2 == best[t] && j < at[t])) best[t] = d2, at[t] = j;
            }
        }
    }
#undef X
}

/* The exact nearest point of Q (smallest index on ties) for each of the
 * n <= SCAN_MAX askers at pts + 3 pos[k] (pos NULL: pts + 3 k): bounds
 * from a strided sample of Q, then one pass over it. */
static void scan_q(const hd__mpi_dir_t *d, const double *pts, const uint32_t *pos, size_t n, size_t *near) {
    double best[SCAN_MAX];
    assert(n <= SCAN_MAX && d->nQ > 0);
    for (size_t t = 0; t < n; t++) best[t] = INFINITY, near[t] = SIZE_MAX;
    size_t step = d->nQ / 1024 + 1;
    for (size_t j = 0; j < d->nQ; j += step)
        for (size_t t = 0; t < n; t++) {
            double d2 = hd__d2(pts + 3 * (pos ? pos[t] : t), d->Q + 3 * j);
            if (d2 < best[t]) best[t] = d2, near[t] = j; /* j increases: the first at a tie */
        }
    pass_over_q(d, pts, pos, NULL, n, best, near);
}

int hd__mpi_nearest_among(hd__mpi_ctx_t *c, const double *S, size_t m, const double *pts, const uint32_t *pos, size_t n,
                          size_t batch, size_t *near) {
    if (n == 0) return HD_OK;
    hd__mpi_dir_t d;
    memset(&d, 0, sizeof d);
    d.Q = (double *)S; /* only read */
    d.nQ = m;
    hd__mpi_slab_t sl;
    uint32_t *list = hd__mpi_alloc(c, n, sizeof(uint32_t));
    if (!list) return hd__mpi_nomem(c, "the searches", n);
    for (size_t k = 0; k < n; k++) list[k] = (uint32_t)k;
    int rc = slab_build(c, &d, NULL, INFINITY, &sl); /* an infinite margin: all of S, no region read */
    if (rc == HD_OK) rc = slab_search(c, &sl, pts, pos, list, n, batch, near);
    slab_free(c, &sl);
    hd__mpi_free(c, list, n, sizeof(uint32_t));
    return rc;
}

/* The points of Q a structure over all of Q holds at once: a quarter of
 * the rank's points (both sets), at least CHUNK_MIN.  A structure takes
 * about 38 bytes a point of it while built, so all of Q on a rank that
 * holds Q alone (two sets far apart: every point of one set on some
 * ranks) would add 38 bytes a local point to the 25 the points take;
 * chunks add at most a quarter of that. */
#define CHUNK_MIN 65536
static size_t chunk_of(const hd__mpi_dir_t *d) {
    size_t ch = (d->nP + d->nQ) / 4;
    return ch > CHUNK_MIN ? ch : CHUNK_MIN;
}

/* All of Q searched by the m askers list[0..m) in chunks of consecutive
 * positions, one structure at a time: each asker keeps the nearest over
 * the chunks (d2 first, then the smaller position: the smaller index,
 * since local order is index order), so its answer is its exact nearest
 * in Q with the smallest index on ties, as one structure over all of Q
 * gives it.  near[k] holds an upper bound's position or SIZE_MAX on
 * entry. */
static int chunked_search(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const double *pts, const uint32_t *pos,
                          const uint32_t *list, size_t m, size_t batch, size_t n, size_t *near) {
#define X(k) (pts + 3 * (pos ? pos[k] : (k)))
    size_t ch = chunk_of(d);
    size_t *part = hd__mpi_alloc(c, n, sizeof(size_t));
    uint32_t *sel = hd__mpi_alloc(c, ch < d->nQ ? ch : d->nQ, sizeof(uint32_t));
    int rc = part && sel ? HD_OK : hd__mpi_nomem(c, "the searches", m);
    for (size_t j0 = 0; j0 < d->nQ && rc == HD_OK; j0 += ch) {
        size_t nj = d->nQ - j0 < ch ? d->nQ - j0 : ch;
        hd__mpi_slab_t sl;
        memset(&sl, 0, sizeof sl);
        sl.M = INFINITY;
        sl.n = nj;
        for (size_t t = 0; t < nj; t++) sel[t] = (uint32_t)(j0 + t);
        hd__box_of(d->Q + 3 * j0, nj, &sl.kb);
        hd_points_t v = hd_points_f64(d->Q, d->nQ);
        rc = hd__mpi_an_build(c, &sl.s, &v, sel, NULL, nj, &sl.kb, hd__thread_count(c->threads, nj), &sl.bytes);
        sl.built = 1;
        if (rc == HD_OK) rc = slab_search(c, &sl, pts, pos, list, m, batch, part);
        slab_free(c, &sl);
        for (size_t t = 0; t < m && rc == HD_OK; t++) {
            size_t k = list[t], j = part[k], b = near[k];
            double d2 = hd__d2(X(k), d->Q + 3 * j);
            if (b == SIZE_MAX) {
                near[k] = j;
                continue;
            }
            double b2 = hd__d2(X(k), d->Q + 3 * b);
            if (d2 < b2 || (d2 == b2 && j < b)) near[k] = j;
        }
    }
    hd__mpi_free(c, part, n, sizeof(size_t));
    hd__mpi_free(c, sel, ch < d->nQ ? ch : d->nQ, sizeof(uint32_t));
    return rc;
#undef X
}

int hd__mpi_nearest_in_q(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__box_t *r, hd__mpi_qtree_t *q, const double *pts,
                         const uint32_t *pos, size_t n, size_t *near, unsigned char *unproven) {
    if (n == 0) return HD_OK;
    if (n <= SCAN_MAX && !q->sub.built && !q->full.built && d->nQ > 0) {
        scan_q(d, pts, pos, n, near); /* exact: nothing left unproven */
        return HD_OK;
    }
#define X(k) (pts + 3 * (pos ? pos[k] : (k)))
    if (n > HD__AN_MAX_POINTS || d->nQ > HD__AN_MAX_POINTS) { /* hd_distances' kd-trees */
        double *own = pos ? hd__mpi_alloc(c, n, 3 * sizeof(double)) : NULL;
        if (pos && !own) return hd__mpi_nomem(c, "the searches", n);
        for (size_t k = 0; own && k < n; k++) memcpy(own + 3 * k, X(k), 3 * sizeof(double));
        hd_points_t Sv = hd_points_f64(own ? own : pts, n), Qv = hd_points_f64(d->Q, d->nQ);
        hd_options_t o;
        hd_options_init(&o);
        o.threads = c->threads;
        int rc = hd_distances(&Sv, &Qv, &o, NULL, near, NULL, NULL, &c->e);
        hd__mpi_free(c, own, n, 3 * sizeof(double));
        return rc;
    }
    uint32_t *list = hd__mpi_alloc(c, n, sizeof(uint32_t));
    if (!list) return hd__mpi_nomem(c, "the searches", n);
    int rc = HD_OK;
    size_t m = n;
    /* Askers a batch: a thirty-second of the rank's points (1.6 bytes a
     * point of them in the batch's structure and search), at least 4096. */
    size_t batch = (d->nP + d->nQ) / 32 > 4096 ? (d->nP + d->nQ) / 32 : 4096;
    for (size_t k = 0; k < n; k++) list[k] = (uint32_t)k;
    /* the slab, a wider one for what it did not prove, then all of Q */
    for (int level = 0; level < 3 && m > 0 && rc == HD_OK; level++) {
        hd__mpi_slab_t *sl = level == 2 ? &q->full : &q->sub;
        double M = level == 2 ? INFINITY : q->M0;
        if (level == 1 && m <= BRUTE_MAX) { /* a few: every point of Q, in one pass */
            /* each from the slab's answer, an upper bound */
            double best[BRUTE_MAX];
            size_t at[BRUTE_MAX];
            for (size_t t = 0; t < m; t++) {
                size_t j = near[list[t]];
                at[t] = j;
                best[t] = j == SIZE_MAX ? INFINITY : hd__d2(X(list[t]), d->Q + 3 * j);
            }
            pass_over_q(d, pts, pos, list, m, best, at);
            for (size_t t = 0; t < m; t++) near[list[t]] = at[t];
            m = 0;
            break;
        }
        if (level == 1) { /* what the unproven need, and an eighth more, if finite */
            double need = q->sub.M;
            for (size_t t = 0; t < m; t++) {
                size_t j = near[list[t]];
                double u = j == SIZE_MAX ? INFINITY : sqrt(hd__d2(X(list[t]), d->Q + 3 * j));
                double o = q->sub.M - slab_lb(r, q->sub.M, X(list[t])); /* -(max o), about */
                if (u + o > need) need = u + o;
            }
            M = 1.125 * need;
            if (!isfinite(M) || M <= q->sub.M) continue;
            slab_free(c, &q->sub);
        }
        if (level == 2 && !sl->built && d->nQ > chunk_of(d)) { /* all of Q, a chunk at a time */
            rc = chunked_search(c, d, pts, pos, list, m, batch, n, near);
            break;
        }
        if (!sl->built && (rc = slab_build(c, d, r, M, sl)) != HD_OK) break;
        if ((rc = slab_search(c, sl, pts, pos, list, m, batch, near)) != HD_OK) break;
        if (level == 2) break;
        size_t keep = 0;
        for (size_t t = 0; t < m; t++) {
            size_t k = list[t], j = near[k];
            if (j != SIZE_MAX && hd__mpi_slab_proves(r, sl->M, X(k), hd__d2(X(k), d->Q + 3 * j))) continue;
            if (unproven && level == 0 && j != SIZE_MAX) unproven[k] = 1; /* the caller's, with an answer */
            else list[keep++] = k;
        }
        m = keep;
    }
    hd__mpi_free(c, list, n, sizeof(uint32_t));
    return rc;
#undef X
}
