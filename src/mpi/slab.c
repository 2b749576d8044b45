/*
 * slab.c -- the per-point searches of a rank's local set Q: the exact
 * nearest point of Q (smallest index on ties, as hd_distances gives it)
 * for the shell's points (shell.c) and the queries forwarded from other
 * ranks (forward.c).
 *
 * The structures of the searched local set Q for per-point searches (the
 * nearest layer's, as hd_distances builds them), built on first use and
 * kept for the direction: the shell and the forwarded queries ask them in
 * turn.  Only the points that ask need them, and those are few (the shell,
 * within h of the region's faces, and queries from beyond the faces), so
 * the first is built over a slab: the points of Q within a margin M of a
 * finite face.  An answer from the slab is the answer from all of Q when
 * every point left out is provably farther (slab_proves); the others,
 * when a few, are compared with every point of Q, else ask a slab twice as
 * wide as they need, then all of Q.
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
#include "mpi_int.h"

#include <assert.h>
#include <stdlib.h>

/* The nearest layer's bound on a structure being built (hausdorff.h,
 * hd_distances: up to about 60 bytes a point), charged while it is. */
#define AN_BUILD_BYTES 60

static size_t an_bytes(const hd__an_t *s) {
    return (s->n + 4) * (3 * sizeof(double) + 0) + s->n * sizeof(uint32_t) + (s->nb + 1) * 4 * sizeof(uint32_t) +
           (s->ng + 1) * 2 * sizeof(uint32_t) + s->nn * (sizeof(uint32_t) + 1 + 6 * sizeof(double));
}

int hd__mpi_an_build(ctx_t *c, hd__an_t *s, const hd_points_t *v, const hd__box_t *kb, int threads, size_t *bytes) {
    size_t b = AN_BUILD_BYTES * v->count;
    hd__mpi_charge(c, b);
    int rc = hd__an_build(s, v, NULL, kb, threads, &c->e);
    c->cur -= b;
    *bytes = rc == HD_OK ? an_bytes(s) : 0;
    hd__mpi_charge(c, *bytes);
    return rc;
}

void hd__mpi_an_release(ctx_t *c, hd__an_t *s, size_t bytes) {
    hd__an_free(s);
    c->cur -= bytes;
}

static void slab_free(ctx_t *c, slab_t *sl) {
    if (sl->built) hd__mpi_an_release(c, &sl->s, sl->bytes);
    hd__mpi_free(c, sl->map, sl->n, sizeof(uint32_t));
    memset(sl, 0, sizeof *sl);
}

void hd__mpi_qtree_free(ctx_t *c, qtree_t *q) {
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

static int slab_proves(const hd__box_t *r, double M, const double *x, double d2) {
    double lb = slab_lb(r, M, x);
    return lb > 1e-140 && d2 < lb * lb * (1 - 1e-9);
}

/* The distance from b to the nearest finite face of r, as computed. */
static double face_gap(const hd__box_t *r, const double *b) {
    double g = INFINITY;
    for (int a = 0; a < 3; a++) {
        if (isfinite(r->lo[a]) && fabs(b[a] - r->lo[a]) < g) g = fabs(b[a] - r->lo[a]);
        if (isfinite(r->hi[a]) && fabs(r->hi[a] - b[a]) < g) g = fabs(r->hi[a] - b[a]);
    }
    return g;
}

/* Build the slab of margin M (infinite: all of Q). */
static int slab_build(ctx_t *c, const dir_t *d, const hd__box_t *r, double M, slab_t *sl) {
    memset(sl, 0, sizeof *sl);
    sl->M = M;
    double *xyz = NULL;
    int rc = HD_OK;
    size_t n = d->nQ;
    if (isfinite(M)) {
        n = 0;
        for (size_t j = 0; j < d->nQ; j++) n += face_gap(r, d->Q + 3 * j) <= M;
        sl->map = hd__mpi_alloc(c, n, sizeof(uint32_t));
        xyz = hd__mpi_alloc(c, n, 3 * sizeof(double));
        sl->n = n;
        if (!sl->map || !xyz) rc = hd__mpi_nomem(c, "the searched slab", n);
        for (size_t j = 0, t = 0; j < d->nQ && rc == HD_OK; j++)
            if (face_gap(r, d->Q + 3 * j) <= M) {
                memcpy(xyz + 3 * t, d->Q + 3 * j, 3 * sizeof(double));
                sl->map[t++] = (uint32_t)j;
            }
    }
    sl->n = n;
    hd_points_t v = hd_points_f64(xyz ? xyz : d->Q, n);
    if (rc == HD_OK && n > 0) {
        hd__box_of(xyz ? xyz : d->Q, n, &sl->kb); /* keys only order (clamped): any box is exact */
        rc = hd__mpi_an_build(c, &sl->s, &v, &sl->kb, hd__thread_count(c->threads, n), &sl->bytes);
        sl->built = 1; /* freed by slab_free whatever happened */
    }
    hd__mpi_free(c, xyz, n, 3 * sizeof(double));
    return rc;
}

/* near[k] for the points pts[k], k in list[0..m), searched in a built slab:
 * Q's index of the nearest (smallest index on ties) within the slab, or
 * SIZE_MAX when the slab is empty. */
static int slab_search(ctx_t *c, const slab_t *sl, const double *pts, const size_t *list, size_t m, size_t *near) {
    if (m == 0) return HD_OK;
    if (sl->n == 0) {
        for (size_t t = 0; t < m; t++) near[list[t]] = SIZE_MAX;
        return HD_OK;
    }
    double *xyz = hd__mpi_alloc(c, m, 3 * sizeof(double));
    size_t *got = hd__mpi_alloc(c, m, sizeof(size_t));
    int rc = HD_OK;
    if (!xyz || !got) rc = hd__mpi_nomem(c, "the searches", m);
    for (size_t t = 0; t < m && rc == HD_OK; t++) memcpy(xyz + 3 * t, pts + 3 * list[t], 3 * sizeof(double));
    hd__an_t asking;
    size_t ab = 0;
    int threads = hd__thread_count(c->threads, m > sl->n ? m : sl->n);
    hd_points_t Sv = hd_points_f64(xyz, m);
    if (rc == HD_OK && (rc = hd__mpi_an_build(c, &asking, &Sv, &sl->kb, threads, &ab)) == HD_OK)
        rc = hd__an_nearest(&asking, &sl->s, NULL, threads, NULL, got, NULL, &c->e);
    if (ab) hd__mpi_an_release(c, &asking, ab);
    for (size_t t = 0; t < m && rc == HD_OK; t++) near[list[t]] = sl->map ? sl->map[got[t]] : got[t];
    hd__mpi_free(c, xyz, m, 3 * sizeof(double));
    hd__mpi_free(c, got, m, sizeof(size_t));
    return rc;
}

/* At most this many points the slab did not prove are compared with
 * every point of Q (on a copy: points whose partner is on another rank)
 * rather than searched in a wider slab.  One pass over Q serves them all,
 * and a point of Q is mostly passed over after one coordinate's gap; the
 * wider slab costs two passes over Q measuring face gaps and a structure
 * over the points in it.  Measured (callgrind, the copy at K = 2, 400K
 * points a rank): 160M instructions with 4, 176M with 0 or 1. */
#define BRUTE_MAX 4

/* For each of n packed points, the nearest point of Q (exact, smallest
 * index on ties, as hd_distances gives it). */
int hd__mpi_nearest_in_q(ctx_t *c, const dir_t *d, const hd__box_t *r, qtree_t *q, const double *pts, size_t n,
                        size_t *near) {
    if (n == 0) return HD_OK;
    if (n > HD__AN_MAX_POINTS || d->nQ > HD__AN_MAX_POINTS) { /* hd_distances' kd-trees */
        hd_points_t Sv = hd_points_f64(pts, n), Qv = hd_points_f64(d->Q, d->nQ);
        hd_options_t o;
        hd_options_init(&o);
        o.threads = c->threads;
        return hd_distances(&Sv, &Qv, &o, NULL, near, NULL, NULL, &c->e);
    }
    size_t *list = hd__mpi_alloc(c, n, sizeof(size_t));
    if (!list) return hd__mpi_nomem(c, "the searches", n);
    int rc = HD_OK;
    size_t m = n;
    for (size_t k = 0; k < n; k++) list[k] = k;
    /* the slab, a wider one for what it did not prove, then all of Q */
    for (int level = 0; level < 3 && m > 0 && rc == HD_OK; level++) {
        slab_t *sl = level == 2 ? &q->full : &q->sub;
        double M = level == 2 ? INFINITY : q->M0;
        if (level == 1 && m <= BRUTE_MAX) { /* a few: every point of Q, in one pass */
            /* Each starts from the slab's answer (an upper bound), and a
             * point b of Q whose x gap alone exceeds it is passed over:
             * hd__d2(x, b) >= fl(dx * dx) (the sum only adds non-negative
             * terms, and rounding is monotone), so b is farther, not tied. */
            double best[BRUTE_MAX];
            size_t at[BRUTE_MAX];
            for (size_t t = 0; t < m; t++) {
                size_t j = near[list[t]];
                at[t] = j;
                best[t] = j == SIZE_MAX ? INFINITY : hd__d2(pts + 3 * list[t], d->Q + 3 * j);
            }
            for (size_t j = 0; j < d->nQ; j++) {
                const double *b = d->Q + 3 * j;
                for (size_t t = 0; t < m; t++) {
                    const double *x = pts + 3 * list[t];
                    double dx = x[0] - b[0];
                    if (dx * dx > best[t]) continue;
                    double d2 = hd__d2(x, b);
                    if (d2 < best[t] || (d2 == best[t] && j < at[t])) best[t] = d2, at[t] = j;
                }
            }
            for (size_t t = 0; t < m; t++) near[list[t]] = at[t];
            m = 0;
            break;
        }
        if (level == 1) { /* twice what the unproven need, if finite */
            double need = q->sub.M;
            for (size_t t = 0; t < m; t++) {
                size_t j = near[list[t]];
                double u = j == SIZE_MAX ? INFINITY : sqrt(hd__d2(pts + 3 * list[t], d->Q + 3 * j));
                double o = q->sub.M - slab_lb(r, q->sub.M, pts + 3 * list[t]); /* -(max o), about */
                if (u + o > need) need = u + o;
            }
            M = 2 * need;
            if (!isfinite(M) || M <= q->sub.M) continue;
            slab_free(c, &q->sub);
        }
        if (!sl->built && (rc = slab_build(c, d, r, M, sl)) != HD_OK) break;
        if ((rc = slab_search(c, sl, pts, list, m, near)) != HD_OK) break;
        if (level == 2) break;
        size_t keep = 0;
        for (size_t t = 0; t < m; t++) {
            size_t k = list[t], j = near[k];
            if (j == SIZE_MAX || !slab_proves(r, sl->M, pts + 3 * k, hd__d2(pts + 3 * k, d->Q + 3 * j)))
                list[keep++] = k;
        }
        m = keep;
    }
    hd__mpi_free(c, list, n, sizeof(size_t));
    return rc;
}
