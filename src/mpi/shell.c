/*
 * shell.c -- the engine's pass over one direction of a rank's local sets
 * (step 3 of mpi.c's essay).
 *
 * The engine's pass over one direction.  hd_directed(P, Q) on the local
 * sets gives h2, the largest u(a)^2 of the rank, with its witness: so
 * u(a)^2 <= h2 for every local a, and a point whose faces are clear of h2
 * is confirmed without a search of its own (the interior).  The interior's
 * exact maximum is the engine's own answer when the engine's witness is
 * interior (it is then the smallest index at h2), else one more engine
 * call on the interior alone.  Unless its list of refused points
 * overflows, the engine's maximum is filtered instead (keep_clear, in
 * hd__mpi_engine_both for both directions at once, else here): it keeps
 * only the points whose faces are clear of their own u, so its answer h_I
 * is a kept point's u, which is global, and the interior is every point
 * not refused, with maximum h_I at once: a point not refused was either
 * kept (exact) or never offered, and then its local u, which bounds its
 * global one, is below h_I or equal to it at a larger index than the
 * witness (hd__keep_t), so it cannot be the witness on any rank, whatever
 * other ranks hold near it.  The shell is the refused points alone (those
 * the engine could not prune and whose faces are not clear of their u),
 * few on the benchmark's scenes, far fewer than the points within h_I of a
 * face (mpi_bench counts both, docs/scale-out.md); the rank's largest u (the
 * slabs' scale) is the larger of h_I and the refused points' largest.  A
 * refused point's nearest point of Q is the engine's own answer (offered
 * with it: the exact distance and the smallest index at it), so the shell
 * needs no search of Q.  When the list overflows, every point from then
 * on is kept, so the larger of the answer and the listed points' is the
 * unfiltered answer (overflow_max).  Unfiltered, the shell is the points whose faces
 * are not clear of the engine's answer, the rank's largest u, and they get
 * per-point searches (hd_distances).  The engine prunes the points that cannot be the
 * farthest, which per-point searches cannot (mpi_bench times both on two
 * epochs of one scene; docs/scale-out.md), and the shell is the points
 * within h of the region's faces.
 *
 * Invariants: the local arrays' coordinates are moved (split) and put back
 * (unsplit) around each engine call on a subset, so every position holds
 * its own point again when a function here returns, and its index (gidx)
 * never changes.
 */
#include "mpi/search.h"

#include <assert.h>
#include <stdlib.h>

void hd__mpi_shell_free(hd__mpi_ctx_t *c, hd__mpi_shell_t *sh) {
    hd__mpi_free(c, sh->own_pos, sh->n, sizeof(uint32_t));
    hd__mpi_free(c, sh->unproven, sh->n, 1);
    hd__mpi_free(c, sh->nearest, sh->n, sizeof(size_t));
}

/* Which positions a split keeps: those with mask[k], or (mask NULL) those
 * not listed in out[0..nout), which increases (the shell's positions: the
 * interior is then kept without a byte a point to say so). */
typedef struct {
    const unsigned char *mask;
    const uint32_t *out;
    size_t nout;
} keep_t;

/* Partition in place of the coordinates (the indices stay by position):
 * the kept points to the front, in order; unsplit puts every point back.
 * Two ways, one result:
 *  - with an aside (room for the dropped points' coordinates), each kept
 *    point moves once, forwards, and each dropped one to the aside, in
 *    order; unsplit walks backwards and moves them back;
 *  - without one, by swaps, so the dropped points need no room of their own
 *    while they wait (their order among themselves is scrambled): unsplit
 *    undoes the same swaps in reverse order, which puts every point back
 *    where it was, since a swap is its own inverse and the swap of step k
 *    is between position k and the number t of kept points before k, which
 *    the reverse walk recovers by counting down.
 * A swap moves twice the bytes of a move, so the pairs take an aside when
 * it is small (aside_for: at most a 64th of the points, as the unpaired
 * points of a copy are; callgrind on mpi_bench counts both ways, and
 * docs/scale-out.md has the counts), and the interior's pass always swaps:
 * it may be the rank's peak, and its shell is a small part of the
 * points. */
HD__INLINE void swap3(double *xyz, size_t i, size_t k) {
    double t[3];
    memcpy(t, xyz + 3 * i, sizeof t);
    memcpy(xyz + 3 * i, xyz + 3 * k, sizeof t);
    memcpy(xyz + 3 * k, t, sizeof t);
}

static double *aside_for(hd__mpi_ctx_t *c, size_t n, size_t dropped) {
    return dropped <= n / 16 ? hd__mpi_alloc(c, dropped, 3 * sizeof(double)) : NULL;
}

/* Whether position k is dropped, walking forwards (o: the next listed
 * position's rank in out) or backwards (o: one past it). */
HD__INLINE int dropped(const keep_t *kp, size_t k, size_t *o) {
    if (kp->mask) return !kp->mask[k];
    if (*o < kp->nout && kp->out[*o] == k) return ++*o, 1;
    return 0;
}

HD__INLINE int dropped_back(const keep_t *kp, size_t k, size_t *o) {
    if (kp->mask) return !kp->mask[k];
    if (*o > 0 && kp->out[*o - 1] == k) return --*o, 1;
    return 0;
}

/* split's and unsplit's walks, inlined into one copy for each way (mask
 * or list, aside or swaps), so that no test of the way is left in a loop:
 * they run over every local point. */
HD__INLINE size_t split_walk(double *xyz, size_t n, keep_t kp, double *aside) {
    size_t t = 0, a = 0;
    for (size_t k = 0, o = 0; k < n; k++) {
        if (dropped(&kp, k, &o)) {
            if (aside) memcpy(aside + 3 * a++, xyz + 3 * k, 3 * sizeof(double));
        } else {
            if (t != k) {
                if (aside) memcpy(xyz + 3 * t, xyz + 3 * k, 3 * sizeof(double));
                else swap3(xyz, t, k);
            }
            t++;
        }
    }
    return t;
}

HD__INLINE void unsplit_walk(double *xyz, size_t n, keep_t kp, const double *aside) {
    size_t t = 0;
    if (kp.mask)
        for (size_t k = 0; k < n; k++) t += kp.mask[k] != 0;
    else
        t = n - kp.nout;
    size_t a = n - t;
    for (size_t k = n, o = kp.nout; k-- > 0;) {
        if (dropped_back(&kp, k, &o)) {
            if (aside) memcpy(xyz + 3 * k, aside + 3 * --a, 3 * sizeof(double));
        } else if (--t != k) {
            if (aside) memcpy(xyz + 3 * k, xyz + 3 * t, 3 * sizeof(double));
            else swap3(xyz, t, k);
        }
    }
}

static size_t split(double *xyz, size_t n, keep_t kp, double *aside) {
    if (kp.mask && aside) return split_walk(xyz, n, (keep_t){kp.mask, NULL, 0}, aside);
    if (kp.mask) return split_walk(xyz, n, (keep_t){kp.mask, NULL, 0}, NULL);
    if (aside) return split_walk(xyz, n, (keep_t){NULL, kp.out, kp.nout}, aside);
    return split_walk(xyz, n, (keep_t){NULL, kp.out, kp.nout}, NULL);
}

static void unsplit(double *xyz, size_t n, keep_t kp, const double *aside) {
    if (kp.mask && aside) unsplit_walk(xyz, n, (keep_t){kp.mask, NULL, 0}, aside);
    else if (kp.mask) unsplit_walk(xyz, n, (keep_t){kp.mask, NULL, 0}, NULL);
    else if (aside) unsplit_walk(xyz, n, (keep_t){NULL, kp.out, kp.nout}, aside);
    else unsplit_walk(xyz, n, (keep_t){NULL, kp.out, kp.nout}, NULL);
}

/* The position of the m-th kept point (from 0). */
static size_t kept_at(keep_t kp, size_t n, size_t m) {
    for (size_t k = 0, t = 0, o = 0; k < n; k++) {
        if (dropped(&kp, k, &o)) continue;
        if (t++ == m) return k;
    }
    assert(0);
    return 0;
}

/* Marks the pairs: inp[i] = inq[j] = 1 when point i of P and point j of Q
 * have the same global index (the masks zeroed by the caller; both NULL:
 * count only), and returns their number.  One merge walk over both index
 * orders. */
static size_t mark_pairs(const hd__mpi_gidx_t *gP, size_t nP, const hd__mpi_gidx_t *gQ, size_t nQ, unsigned char *inp,
                         unsigned char *inq) {
    assert(gP->n == nP && gQ->n == nQ);
    (void)nP, (void)nQ;
    return hd__mpi_gidx_common(gP, gQ, inp, inq);
}

/* Whether the merge walk of mark_pairs is worth it: at least three
 * quarters of PAIRS_SAMPLE points of P, evenly spaced, have their partner
 * here (each found by a binary search of Q's indices, decoded at random:
 * a few thousand decodes, little beside the walk over every point),
 * and nearer than every one of PAIRS_RIVALS points of Q spread over its
 * positions (or tied), as a moved copy's partner is and a random point is
 * not (the engine's gate, docs/engine.md, step 0.5, asks the same of a
 * sample).  The correspondence pass wants nine tenths (is_paired), which
 * a sample of 64 misses by that much only at four standard deviations if
 * it were random; two unrelated sets of one size have about 1/K of their
 * partners here (half at K = 2), but all of them when each rank's input is
 * already its region (tiles): the index alone then took two independent
 * epochs for a copy, ran the engine unfiltered on "pairs" that are not,
 * and searched many more points one by one with a higher peak (mpi_bench
 * --layout tiles measures it, docs/scale-out.md).  A sample that
 * misses a copy only costs that pass, never an answer. */
#define PAIRS_SAMPLE 64
#define PAIRS_RIVALS 32
static int pairs_likely(const double *P, const hd__mpi_gidx_t *gP, size_t nP, const double *Q, const hd__mpi_gidx_t *gQ,
                        size_t nQ) {
    size_t m = nP < PAIRS_SAMPLE ? nP : PAIRS_SAMPLE, hits = 0, step = nQ / PAIRS_RIVALS + 1;
    for (size_t r = 0; r < m && nQ; r++) {
        size_t i = r * nP / m;
        uint64_t g = hd__mpi_gidx(gP, i);
        size_t lo = 0, hi = nQ;
        while (lo < hi) {
            size_t mid = lo + (hi - lo) / 2;
            if (hd__mpi_gidx(gQ, mid) < g) lo = mid + 1;
            else hi = mid;
        }
        if (lo == nQ || hd__mpi_gidx(gQ, lo) != g) continue;
        double d2 = hd__d2(P + 3 * i, Q + 3 * lo);
        int nearest = 1;
        for (size_t j = 0; j < nQ && nearest; j += step) nearest = hd__d2(P + 3 * i, Q + 3 * j) >= d2;
        hits += (size_t)nearest;
    }
    return 4 * hits >= 3 * m;
}

/* The correspondence pass is tried when nine tenths of P have their
 * partner (anything else is not a copy), and not on whole sets in one
 * order, which the engine's own path takes. */
static int is_paired(size_t nc, size_t nP, size_t nQ) {
    return !(nc < 64 || nc < nP - nP / 10 || (nc == nP && nc == nQ));
}

/* The engine on the pairs of P and Q (masks inp, inq), moved to the front
 * of both arrays and put back after: *e's positions are in P_c and Q_c.
 * sym: both directions (e[0] P to Q, e[1] Q to P), else e[0] only.  box:
 * NULL, or the boxes of all of P and Q, which hold the pairs (the engine
 * needs a box that holds its points, not the smallest). */
static int pairs_engine(hd__mpi_ctx_t *c, double *P, size_t nP, double *Q, size_t nQ, const unsigned char *inp,
                        const unsigned char *inq, size_t nc, int sym, const hd__box_t *box, hd_result_t e[2]) {
    double *py = aside_for(c, nP, nP - nc), *qx = aside_for(c, nQ, nQ - nc);
    split(P, nP, (keep_t){inp, NULL, 0}, py);
    split(Q, nQ, (keep_t){inq, NULL, 0}, qx);
    hd_points_t Pv = hd_points_f64(P, nc), Qv = hd_points_f64(Q, nc);
    hd_symmetric_t s;
    int rc = HD_OK;
    if (sym && (rc = hd__mpi_engine_sym(c, &Pv, &Qv, box ? &box[0] : NULL, box ? &box[1] : NULL, NULL, &s)) == HD_OK)
        e[0] = s.ab, e[1] = s.ba;
    if (!sym) rc = hd__mpi_engine_local(c, &Pv, &Qv, NULL, NULL, &e[0]);
    unsplit(P, nP, (keep_t){inp, NULL, 0}, py);
    unsplit(Q, nQ, (keep_t){inq, NULL, 0}, qx);
    hd__mpi_free(c, py, nP - nc, 3 * sizeof(double));
    hd__mpi_free(c, qx, nQ - nc, 3 * sizeof(double));
    return rc;
}

/* The engine's filter on a direction's maximum: point i of P counts only
 * when its region's faces are clear of its own local nearest distance
 * (then that distance is its global one: mpi.c, step 4); the others are
 * recorded, with the largest of their distances.  Once the list is full
 * the pass's answer is of no use (shell_of runs the engine again without
 * the filter), and the filter keeps every point, so that the rest of the
 * pass prunes as an unfiltered one does instead of searching every point
 * that nothing kept bounds (A far from the local B: every u large). */
static int keep_clear(void *ctx, size_t i, double d2, size_t j) {
    hd__mpi_refused_t *r = ctx;
    if (r->overflow || hd__mpi_faces_clear(r->mine, r->P + 3 * i, d2)) return 1;
    if (r->n == r->cap) {
        r->overflow = 1;
        return 1; /* kept, as every point after it: each refused point is listed (overflow_max) */
    }
    r->d2 = d2 > r->d2 ? d2 : r->d2;
    r->pos[r->n] = (uint32_t)i, r->near[r->n++] = (uint32_t)j;
    return 0;
}

/* The engine's unfiltered answer from a pass whose list overflowed (e,
 * its answer over the points kept, a real point): every point offered was
 * kept (exact) or refused and listed with its exact nearest (keep_clear
 * keeps every point from the overflow on), and a point never offered has
 * u below e's or equal to it at a larger index (hd__keep_t), so the rank's
 * largest u, smallest index on ties, is the larger of e and the listed
 * points' (local order is index order): what the engine gives without the
 * filter, without running it again. */
static hd_result_t overflow_max(const hd__mpi_refused_t *r, const double *Q, hd_result_t e) {
    for (size_t k = 0; k < r->n; k++) {
        size_t i = r->pos[k], j = r->near[k];
        double d2 = hd__d2(r->P + 3 * i, Q + 3 * j);
        if (d2 > e.distance2 || (d2 == e.distance2 && i < e.i)) e.distance2 = d2, e.distance = sqrt(d2), e.i = i, e.j = j;
    }
    return e;
}

/* Room for the refused points: an engine pass offers a few thousand
 * points of a million, and refuses those of the shell among them. */
#define REFUSED_ROOM(n) ((n) / 256 + 256)

/* The list's arrays, room for r->cap (HD_OK, or the error, charged). */
static int refused_alloc(hd__mpi_ctx_t *c, hd__mpi_refused_t *r, size_t n) {
    r->pos = hd__mpi_alloc(c, r->cap, sizeof(uint32_t));
    r->near = hd__mpi_alloc(c, r->cap, sizeof(uint32_t));
    return r->pos && r->near ? HD_OK : hd__mpi_nomem(c, "the shell", n);
}

static void refused_free(hd__mpi_ctx_t *c, hd__mpi_refused_t *r) {
    hd__mpi_free(c, r->pos, r->cap, sizeof(uint32_t));
    hd__mpi_free(c, r->near, r->cap, sizeof(uint32_t));
    r->pos = NULL;
    r->near = NULL;
    r->cap = 0;
}

void hd__mpi_pre_free(hd__mpi_ctx_t *c, hd__mpi_pre_t *pre) { refused_free(c, &pre->ref); }

int hd__mpi_engine_both(hd__mpi_ctx_t *c, double *xyz[2], const hd__mpi_gidx_t *g[2], const size_t n[2], const hd__box_t box[2],
                        const hd__box_t *mine, hd__mpi_pre_t pre[2], unsigned char *mask[2]) {
    memset(pre, 0, 2 * sizeof *pre);
    mask[0] = mask[1] = NULL;
    if (n[0] == 0 || n[1] == 0) return HD_OK; /* shell_of has nothing to ask the engine */
    /* The masks are marked in the walk that counts the pairs (2 bytes a
     * point while the local arrays alone are held: below the engine's
     * peak), and freed at once when the sets are not a copy; neither is
     * done when a sample finds few pairs. */
    int paired = 0;
    size_t nc = 0;
    if (pairs_likely(xyz[0], g[0], n[0], xyz[1], g[1], n[1])) {
        mask[0] = hd__mpi_alloc(c, n[0], 1);
        mask[1] = hd__mpi_alloc(c, n[1], 1);
        if (!mask[0] || !mask[1]) return hd__mpi_nomem(c, "the pairs", n[0]);
        memset(mask[0], 0, n[0]);
        memset(mask[1], 0, n[1]);
        nc = mark_pairs(g[0], n[0], g[1], n[1], mask[0], mask[1]);
        paired = is_paired(nc, n[0], n[1]);
        if (!paired || paired != is_paired(nc, n[1], n[0])) {
            for (int s = 0; s < 2; s++) hd__mpi_free(c, mask[s], n[s], 1), mask[s] = NULL;
            if (paired) return HD_OK; /* each direction on its own */
        }
    }
    hd_result_t e[2];
    hd__mpi_refused_t ref[2];
    memset(ref, 0, sizeof ref);
    int rc = HD_OK;
    if (!paired) {
        /* Each direction's maximum over the points whose faces are clear
         * of their own distance: the interior's maximum, at once (shell_of) */
        hd__keep_t keep[2];
        for (int s = 0; s < 2; s++) {
            ref[s] = (hd__mpi_refused_t){mine, xyz[s], 1, -1.0, NULL, 0, REFUSED_ROOM(n[s]), 0, NULL};
            keep[s] = (hd__keep_t){keep_clear, &ref[s]};
            if (rc == HD_OK) rc = refused_alloc(c, &ref[s], n[s]);
        }
        hd_points_t Av = hd_points_f64(xyz[0], n[0]), Bv = hd_points_f64(xyz[1], n[1]);
        hd_symmetric_t s;
        if (rc == HD_OK && (rc = hd__mpi_engine_sym(c, &Av, &Bv, &box[0], &box[1], keep, &s)) == HD_OK)
            e[0] = s.ab, e[1] = s.ba;
    } else {
        rc = pairs_engine(c, xyz[0], n[0], xyz[1], n[1], mask[0], mask[1], nc, 1, box, e);
    }
    for (int s = 0; s < 2; s++)
        pre[s] = rc == HD_OK ? (hd__mpi_pre_t){1, paired, e[s], mask[s], mask[1 - s], ref[s]} : (hd__mpi_pre_t){.ref = ref[s]};
    return rc;
}

/* The correspondence pass, for a copy and its original (|A| = |B|, point g
 * of B the moved point g of A).  After the partition a rank holds most
 * pairs whole, but not all (a face separates some), so its local sets
 * differ in size and the engine's correspondence path (docs/engine.md,
 * step 0.5), which settles a copy at a few ns a point, does not run on
 * them.  Here P_c, the local points of P whose partner is local too, and
 * Q_c, those partners, are passed to the engine in the same order (both
 * are in global index order), so the path runs (or ran already for both
 * directions: d->pre).  Its answer h_c, with
 * witness a*, bounds every u(a)^2 of P_c from above (Q_c is part of the
 * local Q), so the points of P_c whose faces are clear of h_c are settled
 * (the interior; the points of P without a local partner are shell).  The
 * interior's exact maximum is h_c at a* when a* is interior and no point
 * of Q_x, the local Q points whose partner is elsewhere, is nearer to a*
 * than h_c: then u(a*)^2 = h_c, no interior u exceeds it, and any point
 * of P_c with u^2 = h_c has u_c^2 = h_c too, so an index no smaller than
 * a*'s (the engine's tie rule).  The witness's j is the engine's, or the
 * smallest index of Q_x at exactly h_c.  Otherwise (*done = 0) the caller
 * runs the engine on the whole local sets (or takes d->pre's answer).
 * Done, *inq_out is Q's pairs' mask for paired_shell (*ownq_out: the
 * caller frees it, when it is this pass's own). */
/* paired_pass's mask of P: a pair whose faces are clear of h_c (the
 * interior), a pair that is not (the shell), or 0: no partner here (the
 * shell too). */
#define INTERIOR 1
#define PAIRED_SHELL 2

static int paired_pass(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__box_t *mine, unsigned char **inp, size_t *nI,
                       hd__mpi_far_t *inner, int *done, unsigned char **ownq_out, const unsigned char **inq_out) {
    size_t nP = d->nP, nQ = d->nQ, nc;
    const hd__mpi_pre_t *pre = d->pre && d->pre->have ? d->pre : NULL;
    *done = 0;
    *inp = NULL;
    *ownq_out = NULL;
    *inq_out = NULL;
    if (pre && !pre->paired) return HD_OK;
    if (!pre && (!pairs_likely(d->P, d->gP, nP, d->Q, d->gQ, nQ) ||
                 !is_paired(nc = mark_pairs(d->gP, nP, d->gQ, nQ, NULL, NULL), nP, nQ)))
        return HD_OK;
    /* P's mask is made the interior's below, so it is this pass's own; Q's
     * is only read, hd__mpi_engine_both's when it marked them */
    unsigned char *in = *inp = hd__mpi_alloc(c, nP, 1), *ownq = pre ? NULL : hd__mpi_alloc(c, nQ, 1);
    const unsigned char *inq = pre ? pre->inq : ownq;
    int rc = HD_OK;
    if (!in || !inq) {
        rc = hd__mpi_nomem(c, "the pairs", nP);
        goto done;
    }
    if (pre) {
        memcpy(in, pre->inp, nP);
    } else {
        memset(in, 0, nP);
        memset(ownq, 0, nQ);
        nc = mark_pairs(d->gP, nP, d->gQ, nQ, in, ownq);
    }
    hd_result_t e[2];
    if (pre) e[0] = pre->e;
    else rc = pairs_engine(c, d->P, nP, d->Q, nQ, in, inq, nc, 0, NULL, e);
    if (rc == HD_OK) {
        /* a*, and Q_c's e.j: P_c's e.j's partner (the same index) */
        keep_t kp = {in, NULL, 0};
        size_t astar = kept_at(kp, nP, e[0].i);
        uint64_t gi = hd__mpi_gidx(d->gP, astar), jc = hd__mpi_gidx(d->gP, kept_at(kp, nP, e[0].j));
        /* in[i]: INTERIOR, PAIRED_SHELL (a pair, faces not clear), or 0
         * (no partner here: shell too) */
        hd__mpi_faces_t fc;
        hd__mpi_faces_of(mine, &fc);
        *nI = 0;
        for (size_t i = 0; i < nP; i++) {
            int clear = in[i] && hd__mpi_faces_clear_of(&fc, d->P + 3 * i, e[0].distance2);
            *nI += (size_t)clear;
            in[i] = clear ? INTERIOR : in[i] ? PAIRED_SHELL : 0;
        }
        /* The nearest point of Q_x to a* (position order is index order:
         * the first at the minimum is the smallest index). */
        double v = INFINITY;
        size_t jx = SIZE_MAX;
        for (size_t j = 0; j < nQ && in[astar] == INTERIOR; j++) {
            const unsigned char *z = memchr(inq + j, 0, nQ - j); /* the next of Q_x */
            if (!z) break;
            j = (size_t)(z - inq);
            double d2 = hd__d2(d->P + 3 * astar, d->Q + 3 * j);
            if (d2 < v) v = d2, jx = j;
        }
        uint64_t jv = jx == SIZE_MAX ? UINT64_MAX : hd__mpi_gidx(d->gQ, jx);
        if (in[astar] == INTERIOR && v >= e[0].distance2) {
            *inner = (hd__mpi_far_t){e[0].distance2, gi, v == e[0].distance2 && jv < jc ? jv : jc};
            *done = 1;
            *inq_out = inq; /* the shell's partners (paired_shell) */
            *ownq_out = ownq;
            return rc;
        }
    }
done:
    hd__mpi_free(c, ownq, nQ, 1);
    return rc;
}

/* The exact maximum over the interior, the points whose faces are clear
 * of h2 (their local u is global), where it beats G, the best over every
 * rank without it (else *out has d2 = -1: it cannot change the result).
 * The engine runs on a compacted copy of them with its maximum starting at
 * G: as (G.d2, p*), p* the number of interior points whose global index is
 * below G's, since the copy's positions are in global index order, so a
 * point beats the floor exactly when it beats G (G's point is not
 * interior: the interior's maximum is what G was computed without).  The
 * points that cannot are pruned as soon as one point of Q shows it, which
 * is most of them. */
int hd__mpi_interior_max(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__box_t *mine, const hd__mpi_shell_t *sh, double h2,
                         const hd__mpi_far_t *G, hd__mpi_far_t *out) {
    *out = (hd__mpi_far_t){-1.0, UINT64_MAX, UINT64_MAX};
    /* The interior is what the shell is not (shell_of: the points whose
     * faces are not clear of the same h2, a proper subset: own_pos). */
    assert(sh->own_pos && sh->n < d->nP);
    keep_t in = {NULL, sh->own_pos, sh->n};
    size_t below = 0;
    hd__mpi_gcur_t cu;
    hd__mpi_gcur_init(&cu, d->gP);
    for (size_t k = 0, o = 0; k < d->nP && hd__mpi_gcur_at(&cu, k) < G->i; k++) below += !dropped(&in, k, &o);
    size_t nI = split(d->P, d->nP, in, NULL); /* by swaps: this pass may be the peak */
#ifndef NDEBUG
    for (size_t k = 0; k < nI; k++) assert(hd__mpi_faces_clear(mine, d->P + 3 * k, h2));
#else
    (void)mine, (void)h2;
#endif
    hd_points_t Iv = hd_points_f64(d->P, nI), Qv = hd_points_f64(d->Q, d->nQ);
    hd_result_t e;
    int rc = G->d2 >= 0 ? hd__mpi_engine_above(c, &Iv, &Qv, G->d2, below, &e) : hd__mpi_engine_local(c, &Iv, &Qv, NULL, NULL, &e);
    unsplit(d->P, d->nP, in, NULL);
    if (rc == HD_OK && (G->d2 < 0 || e.distance2 > G->d2 || (e.distance2 == G->d2 && e.i < below)))
        *out = (hd__mpi_far_t){e.distance2, hd__mpi_gidx(d->gP, kept_at(in, d->nP, e.i)), hd__mpi_gidx(d->gQ, e.j)};
    return rc;
}

/* The global index of the shell's point k, through a cursor on P's
 * indices (the shell's points are in P's order). */
uint64_t hd__mpi_shell_g(hd__mpi_gcur_t *cu, const hd__mpi_shell_t *sh, size_t k) {
    return hd__mpi_gcur_at(cu, sh->own_pos ? sh->own_pos[k] : k);
}

/* A refused point and its nearest position in Q, the engine's answer. */
typedef struct {
    uint32_t pos, near;
} refd_t;

static int by_pos(const void *x, const void *y) {
    uint32_t a = ((const refd_t *)x)->pos, b = ((const refd_t *)y)->pos;
    return (a > b) - (a < b);
}

/* The shell from the filter's complete list: the refused positions,
 * increasing, each once (the engine may offer a point twice, with the
 * same answer), and each one's nearest position in Q, the engine's exact
 * answer with the smallest index at its u, so no search of Q is needed;
 * in arrays of exactly their number (NULL when none), as
 * hd__mpi_shell_free frees them. */
static int refused_shell(hd__mpi_ctx_t *c, const hd__mpi_refused_t *ref, uint32_t **pos, size_t **near, size_t *n) {
    *pos = NULL;
    *near = NULL;
    *n = 0;
    if (ref->n == 0) return HD_OK;
    refd_t *t = hd__mpi_alloc(c, ref->n, sizeof *t);
    if (!t) return hd__mpi_nomem(c, "the shell", ref->n);
    for (size_t r = 0; r < ref->n; r++) t[r] = (refd_t){ref->pos[r], ref->near[r]};
    qsort(t, ref->n, sizeof *t, by_pos);
    size_t m = 1;
    for (size_t r = 1; r < ref->n; r++) {
        assert(t[r].pos != t[m - 1].pos || t[r].near == t[m - 1].near);
        if (t[r].pos != t[m - 1].pos) t[m++] = t[r];
    }
    uint32_t *p = hd__mpi_alloc(c, m, sizeof *p);
    size_t *q = hd__mpi_alloc(c, m, sizeof *q);
    for (size_t k = 0; p && q && k < m; k++) p[k] = t[k].pos, q[k] = t[k].near;
    hd__mpi_free(c, t, ref->n, sizeof *t);
    if (!p || !q) {
        hd__mpi_free(c, p, m, sizeof *p);
        hd__mpi_free(c, q, m, sizeof *q);
        return hd__mpi_nomem(c, "the shell", m);
    }
    *pos = p;
    *near = q;
    *n = m;
    return HD_OK;
}

/* The shell of a paired pass that is done (in[k] != INTERIOR, nS points):
 * a point whose partner is here takes it as its answer, a point of Q and
 * so an upper bound of its nearest distance, not searched
 * (HD__MPI_UNSEARCHED): forward.c searches it only when that bound may
 * still win over (L, i_L) (resolve), and on a copy, or a lattice against
 * its shift, almost every shell point's partner distance is below the
 * interior's answer or ties it at a larger index, so none is.  A point
 * without its partner here is searched now (hd__mpi_nearest_in_q), as
 * every shell point is otherwise.  P_c's m-th point's partner is Q_c's
 * m-th (both in index order). */
/* Whether the 8 bytes at p are all 1 (INTERIOR, or a pair in Q's mask):
 * paired_shell steps over those 8 at a time. */
HD__INLINE int all_ones(const unsigned char *p) {
    uint64_t w;
    memcpy(&w, p, sizeof w);
    return w == UINT64_C(0x0101010101010101);
}

static int paired_shell(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__box_t *mine, hd__mpi_qtree_t *q,
                        const unsigned char *in, const unsigned char *inq, size_t nS, hd__mpi_shell_t *sh) {
    sh->own_pos = hd__mpi_alloc(c, nS, sizeof(uint32_t));
    sh->nearest = hd__mpi_alloc(c, nS, sizeof(size_t));
    sh->unproven = hd__mpi_alloc(c, nS, 1);
    if (!sh->own_pos || !sh->nearest || !sh->unproven) return hd__mpi_nomem(c, "the shell", nS);
    size_t t = 0, m = 0;
    for (size_t k = 0, j = 0; k < d->nP; k++) {
        while (k + 8 <= d->nP && j + 8 <= d->nQ && all_ones(in + k) && all_ones(inq + j)) k += 8, j += 8;
        if (k == d->nP) break;
        if (in[k] == INTERIOR) {
            while (!inq[j]) j++;
            j++;
            continue;
        }
        sh->own_pos[t] = (uint32_t)k;
        sh->unproven[t] = in[k] ? HD__MPI_UNSEARCHED : 0;
        if (in[k]) {
            while (!inq[j]) j++;
            sh->nearest[t] = j++;
        }
        m += !in[k];
        t++;
    }
    assert(t == nS);
    if (m == 0) return HD_OK;
    /* the points without a partner here, searched now */
    uint32_t *pos = hd__mpi_alloc(c, m, sizeof(uint32_t));
    size_t *near = hd__mpi_alloc(c, m, sizeof(size_t));
    unsigned char *unp = hd__mpi_alloc(c, m, 1);
    int rc = pos && near && unp ? HD_OK : hd__mpi_nomem(c, "nearest neighbours", m);
    for (size_t k = 0, u = 0; k < nS && rc == HD_OK; k++)
        if (!sh->unproven[k]) pos[u++] = sh->own_pos[k];
    if (rc == HD_OK) memset(unp, 0, m), rc = hd__mpi_nearest_in_q(c, d, mine, q, d->P, pos, m, near, unp);
    for (size_t k = 0, u = 0; k < nS && rc == HD_OK; k++)
        if (!sh->unproven[k]) sh->nearest[k] = near[u], sh->unproven[k] = unp[u++];
    hd__mpi_free(c, pos, m, sizeof(uint32_t));
    hd__mpi_free(c, near, m, sizeof(size_t));
    hd__mpi_free(c, unp, m, 1);
    return rc;
}

/* The smallest shell searched after the sample's bounds rather than one by
 * one (below), when it is also at least half of P: a shell of a few
 * points is searched at once, and on two epochs of one scene the shell is
 * a small part of P, so neither takes this course. */
#define DEFER_MIN 1024

int hd__mpi_shell_of(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__box_t *mine, hd__mpi_qtree_t *q, hd__mpi_shell_t *sh) {
    memset(sh, 0, sizeof *sh);
    sh->inner = (hd__mpi_far_t){-1.0, UINT64_MAX, UINT64_MAX};
    sh->n = d->nP;
    if (d->nP == 0 || d->nQ == 0) return HD_OK;
    hd_points_t Pv = hd_points_f64(d->P, d->nP), Qv = hd_points_f64(d->Q, d->nQ);
    hd_result_t e;
    unsigned char *in = NULL; /* allocated after the engine's pass, the peak */
    size_t nI = 0;
    int done = 0;
    unsigned char *ownq = NULL; /* Q's pairs' mask, when the paired pass made it */
    const unsigned char *inq = NULL;
    int rc = paired_pass(c, d, mine, &in, &nI, &sh->inner, &done, &ownq, &inq);
    const hd__mpi_pre_t *pre = d->pre && d->pre->have && !d->pre->paired ? d->pre : NULL;
    /* The engine's answer over the points kept (hd__mpi_engine_both): every
     * point of P either was refused (its faces not clear of its own u), or
     * has u no larger than the answer, which a kept point attains.  With
     * the refused points' list incomplete, or no point kept, the engine
     * runs again on the whole local sets, without the filter: the same
     * filter over the same sets would fail again (it refuses by the same
     * faces), so it is run here only when it has not run yet. */
    const hd__mpi_refused_t *ref = pre && pre->ref.on ? &pre->ref : NULL;
    hd__mpi_refused_t own = {mine, d->P, 0, -1.0, NULL, 0, 0, 0, NULL}; /* when the engine runs here */
    int filter = !ref, have = 0; /* the filter not tried yet; e unfiltered */
    if (ref && ref->overflow && pre->e.i != HD__NONE) {
        e = overflow_max(ref, d->Q, pre->e), have = 1;
        pre = NULL, ref = NULL;
    } else if (ref && (ref->overflow || pre->e.i == HD__NONE)) {
        pre = NULL, ref = NULL;
    } else if (rc == HD_OK && !done && pre) {
        e = pre->e, have = !ref;
    }
    if (rc == HD_OK && !done && !pre && filter) {
        own.cap = REFUSED_ROOM(d->nP);
        hd__keep_t keep = {keep_clear, &own};
        rc = refused_alloc(c, &own, d->nP);
        if (rc == HD_OK && (rc = hd__mpi_engine_kept(c, &Pv, &Qv, &keep, &e)) == HD_OK && e.i != HD__NONE) {
            if (!own.overflow) ref = &own;
            else e = overflow_max(&own, d->Q, e), have = 1;
        }
    }
    /* The shell's positions, when it is the refused points (below). */
    uint32_t *refpos = NULL;
    size_t *refnear = NULL, nref = 0;
    if (rc == HD_OK && !done && ref) {
        /* The filter's list is complete, so the shell is the refused
         * points alone, whatever their faces: every other point is either
         * kept (its faces clear of its own u: exact) or was never offered,
         * so its local u, which bounds its global one, is below the
         * answer h_I or equal to it at a larger index than the witness
         * (hd__keep_t); and h_I is a kept point's global u, so such a point
         * cannot be the witness on any rank. */
        rc = refused_shell(c, ref, &refpos, &refnear, &nref);
        nI = d->nP - nref;
    } else if (rc == HD_OK && !done && (have || (rc = hd__mpi_engine_local(c, &Pv, &Qv, NULL, NULL, &e)) == HD_OK)) {
        /* Unfiltered: the engine's answer is the rank's largest u, which
         * only the points whose faces are clear of it may take as global */
        if (!in && !(in = hd__mpi_alloc(c, d->nP, 1))) rc = hd__mpi_nomem(c, "the interior", d->nP);
        hd__mpi_faces_t fc;
        hd__mpi_faces_of(mine, &fc);
        nI = 0;
        for (size_t k = 0; k < d->nP && rc == HD_OK; k++)
            nI += in[k] = (unsigned char)hd__mpi_faces_clear_of(&fc, d->P + 3 * k, e.distance2);
    }
    if (rc != HD_OK) {
        hd__mpi_free(c, in, d->nP, 1);
        hd__mpi_free(c, ownq, d->nQ, 1);
        hd__mpi_free(c, refpos, nref, sizeof(uint32_t));
        hd__mpi_free(c, refnear, nref, sizeof(size_t));
        refused_free(c, &own);
        return rc;
    }
    size_t nS = d->nP - nI;
    /* The shell's points have u <= h = sqrt(h2) (those of the paired
     * pass's interior, h_c) and lie within h of a face, so their nearest
     * points lie within 2h of one.  Most are far nearer: their u is a
     * point spacing, h the largest u of the rank (over water, at an
     * outlier).  The first slab's margin is 1.5 h, which proves every
     * point with u below half of h; the others keep the slab's answer
     * through the forwarding round (forward.c, resolve), and those still
     * unproven then ask a slab as wide as they need (slab.c), never wider
     * than the 2h that would hold them all.
     * (At 2.5 h the slab held up to half of Q on lidar at K = 16 and was
     * the rank's memory peak; at 1.25 h, uniform sets at K = 2 needed the
     * second slab: docs/scale-out.md.) */
    /* h: the largest u of the rank, the kept points' or the refused ones' */
    q->M0 = 1.5 * sqrt(done ? sh->inner.d2 : ref && ref->d2 > e.distance2 ? ref->d2 : e.distance2);
    /* A kept witness is interior: it was not refused. */
    for (size_t k = 0; !done && ref && k < nref; k++) assert(refpos[k] != e.i);
    refused_free(c, &own);
    if (done) {
        /* the interior's answer is the paired pass's */
    } else if (ref || (nI && in[e.i])) {
        sh->inner = (hd__mpi_far_t){e.distance2, hd__mpi_gidx(d->gP, e.i), hd__mpi_gidx(d->gQ, e.j)};
    } else if (nI) {
        sh->lazy = 1; /* interior_max, only if it can matter */
        sh->h = (hd__mpi_far_t){e.distance2, hd__mpi_gidx(d->gP, e.i), hd__mpi_gidx(d->gQ, e.j)};
    }
    if (rc == HD_OK && ref) { /* the refused points: a proper subset (the witness is kept) */
        assert(nI > 0);
        sh->own_pos = refpos;
        sh->nearest = refnear; /* exact over all of Q: nothing unproven */
    } else if (rc == HD_OK && done && nS) { /* the paired pass's shell, with its partners */
        sh->n = nS;
        rc = paired_shell(c, d, mine, q, in, inq, nS, sh);
    } else if (rc == HD_OK && nS && nI) { /* a proper subset: its positions */
        sh->n = nS;
        if (!(sh->own_pos = hd__mpi_alloc(c, nS, sizeof(uint32_t)))) rc = hd__mpi_nomem(c, "the shell", nS);
        for (size_t k = 0, t = 0; k < d->nP && rc == HD_OK; k++)
            if (!in[k]) sh->own_pos[t++] = (uint32_t)k;
    }
    sh->n = nS;
    hd__mpi_free(c, in, d->nP, 1);
    hd__mpi_free(c, ownq, d->nQ, 1);
    if (done) return rc; /* every shell point has its answer or bound (paired_shell) */
    /* A shell of most of P (sets far apart: every point within h of a
     * face) is not searched one by one here: the sample's bounds come
     * first and only the points that may still win are searched
     * (forward.c, one_sided_shell), as on a rank without Q.  Not when
     * the interior's maximum may be needed (lazy): hd__mpi_interior_max
     * takes the interior as what the shell's positions leave, which the
     * cut would change. */
    if (rc == HD_OK && nS && !ref && !sh->lazy && nS >= DEFER_MIN && 2 * nS >= d->nP) {
        sh->deferred = 1;
        return rc;
    }
    if (rc == HD_OK && nS) {
        if (!ref) sh->nearest = hd__mpi_alloc(c, nS, sizeof(size_t));
        sh->unproven = hd__mpi_alloc(c, nS, 1);
        if (!sh->nearest || !sh->unproven) return hd__mpi_nomem(c, "nearest neighbours", nS);
        memset(sh->unproven, 0, nS);
        if (!ref) rc = hd__mpi_nearest_in_q(c, d, mine, q, d->P, sh->own_pos, nS, sh->nearest, sh->unproven);
    }
    return rc;
}
