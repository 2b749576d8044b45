/*
 * mpi.c -- the exact Hausdorff distance of point sets spread over the ranks
 * of an MPI communicator (hausdorff_mpi.h).  A layer above the public entry
 * points: it calls the public API (hd_directed, hd_overlap), the nearest
 * layer's all-nearest search (nearest/nearest.h, what hd_distances runs)
 * and the points layer's geometry (points/points.h: the one squared
 * distance, boxes, the validation pass); nothing below includes it.  docs/scale-out.md has the
 * measurements and the cost model.
 *
 * The algorithm, for h(A,B) (the symmetric distance runs it both ways on one
 * partition):
 *  1. Partition.  Every rank samples its points of A and B (evenly spaced in
 *     its own order, as many as its share of 1024 a rank) and sends them to
 *     rank 0, which cuts space by recursive coordinate bisection (RCB): each
 *     node of k ranks splits its samples along their longest axis so that
 *     floor(k/2)/k of them go left.  The split key is a sample's
 *     (coordinate, set, global index), so points on the split plane are
 *     divided too (a lattice, or every point equal, still balances); a
 *     point goes left when its key is smaller.  The tree (k - 1 nodes) is
 *     broadcast; each rank's region is a box (faces at split coordinates,
 *     infinite outside), and every point of another region lies on or
 *     beyond one of its faces.
 *  2. One MPI_Alltoallv moves each point (x, y, z, global index: 32 bytes)
 *     to the rank of its region.  Senders send their parts in increasing
 *     index order, so each rank receives K sorted runs per set and merges
 *     them: local order is global index order, and a local "smallest index
 *     on ties" is the global one.
 *  3. The single-machine engine on each rank's part: hd_directed(local A,
 *     local B) gives h2, the rank's largest u(a)^2, where u(a)^2 is the
 *     exact minimum over local B (an upper bound on the minimum over all
 *     of B).  Every a whose region faces are clear of h2 (step 4's test
 *     with h2 >= u(a)^2) is settled without a search of its own, and the
 *     largest of those is the engine's answer (or one more engine call on
 *     them alone when the engine's witness is not among them).  The rest,
 *     the shell within h of the faces, get per-point searches (the
 *     nearest layer's, as hd_distances runs them: the nearest local b,
 *     smallest index on ties) on one structure of the local B per
 *     direction, which the forwarded queries of step 5 ask too.  The
 *     engine prunes the points that cannot be the farthest, which
 *     per-point searches cannot: on two epochs of one scene that is tens
 *     of times less work.  For a copy and its original (point g of B the
 *     moved point g of A) the rank first passes its whole pairs to the
 *     engine in the same order, so the engine's correspondence path runs
 *     (paired_pass).
 *  4. a is *confirmed* when every finite face of its region is strictly
 *     farther than u(a): a point b beyond the face at s on axis k has
 *     |fl(a_k - b_k)| >= |fl(a_k - s)| (rounding is monotone), and the
 *     squared sum keeps that order (points/points.h), so hd__d2(a, b) >=
 *     fl(gap^2) > u(a)^2: no other rank holds a point as near, nor one that
 *     ties.  L, the largest confirmed u^2 over all ranks with the smallest
 *     index i_L of a confirmed point at L (one allreduce), bounds h(A,B)^2
 *     from below: a point with u(a)^2 < L, or u(a)^2 = L and an index above
 *     i_L, cannot be the witness and is never forwarded.  (Skipping every
 *     u(a)^2 <= L would lose ties: a point at exactly L with a smaller
 *     index is the witness, and its smallest-index nearest point may lie on
 *     another rank; tests/api/mpi_api.c's checkerboard fails that way.)
 *  5. Every other a with u(a)^2 >= L is sent to each rank whose box of B
 *     points lies within u(a) (hd__box_lb2 <= u^2: a computed lower bound
 *     no larger than the computed distance to any point inside, so every
 *     rank holding a point at distance <= u(a), ties included, is asked).
 *     The boxes are all-gathered once and searched through the RCB tree
 *     (each node's box is the union of its ranks').  A rank with no B
 *     point has u = infinity; it bounds a by the nearest farthest corner of
 *     the nonempty boxes (hd__box_ub2: at least the distance to every point
 *     inside), so it asks only the candidate ranks.  The asked ranks answer
 *     with their exact nearest (squared distance, smallest global index),
 *     and the asker keeps the smaller pair: the exact global answer.  One
 *     round: the bound is final before anything is sent.
 *  6. Each rank's farthest exact point (largest d2, smallest index on ties)
 *     is max-reduced; the result is the pair hd_hausdorff gives on the
 *     union, bit for bit, since every value compared is an hd__d2 of the
 *     same doubles.
 *
 * Failures: any local failure (a bad point, memory) is agreed on before the
 * next collective that could block (agree(): an allreduce of the first
 * failing rank, then its code and message broadcast), so every rank returns
 * the same code and message and none waits for a rank that gave up.
 */
#include "hausdorff_mpi.h"
#include "nearest/nearest.h"
#include "points/points.h"

#include <assert.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>

#define SAMPLES_PER_RANK 1024

typedef struct { double x[3]; uint64_t g; } rec_t;               /* a moved point */
typedef struct { double d2; uint64_t g; } ans_t;                 /* an answer */
typedef struct { double d2; uint64_t i, j; } far_t;              /* a witness */
typedef struct { double x[3]; uint64_t g, side; } sample_t;
/* An RCB node: left/right >= 0 are nodes, < 0 are ranks -(r + 1). */
typedef struct { double s; uint64_t side, g; int axis, left, right, pad; } node_t;
/* What each rank holds after the partition. */
typedef struct { hd__box_t box[2]; uint64_t n[2]; } held_t;

typedef struct ctx {
    MPI_Comm comm;
    int rank, K, threads;
    hd_error_t e;
    size_t cur, peak;          /* bytes of this call's buffers */
    uint64_t bytes_part, bytes_fwd, forwarded, forwarded_points, answered;
    double search;             /* seconds in the engine and hd_distances */
    double search_cpu;         /* the calling thread's CPU seconds there */
    uint64_t shell;            /* points searched one by one (the shells) */
    int rounds;
    MPI_Datatype rec_type, ans_type, q_type, far_type, sample_type, node_type;
    MPI_Op far_op;
} ctx_t;

/* CPU seconds of the calling thread (the searches' own cost with one
 * thread, whatever else the machine runs). */
static double thread_cpu(void) {
    struct timespec ts;
    if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0) return 0;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- memory: every buffer counted, so the peak can be reported ---------- */

/* Large buffers ask for transparent huge pages: each is written once,
 * right after it is allocated, and first touches of 4 KiB pages (a fault
 * each) were a quarter of the time outside the searches on the machine of
 * docs/scale-out.md.  Where madvise or THP is missing this is plain
 * memory. */
#define HUGE_BYTES ((size_t)4 << 20)

static void *cmalloc(ctx_t *c, size_t n, size_t size) {
    if (size && n > SIZE_MAX / size) return NULL;
    size_t bytes = n * size;
    void *p = NULL;
#ifdef MADV_HUGEPAGE
    if (bytes >= HUGE_BYTES) {
        if (posix_memalign(&p, (size_t)2 << 20, bytes) != 0) p = NULL;
        else madvise(p, bytes, MADV_HUGEPAGE); /* advice: failure changes nothing */
    } else
#endif
        p = malloc(bytes ? bytes : 1);
    if (p) {
        c->cur += bytes;
        if (c->cur > c->peak) c->peak = c->cur;
    }
    return p;
}

static void cfree(ctx_t *c, void *p, size_t n, size_t size) {
    if (!p) return;
    c->cur -= n * size;
    free(p);
}

static int nomem(ctx_t *c, const char *what, size_t n) {
    return hd__err(&c->e, HD_ENOMEM, "out of memory for %s (%zu items)", what, n);
}

static int mpi_failed(ctx_t *c, const char *call, int code) {
    char text[MPI_MAX_ERROR_STRING];
    int len = 0;
    if (MPI_Error_string(code, text, &len) != MPI_SUCCESS) len = 0;
    text[len] = '\0';
    return hd__err(&c->e, HD_EIO, "%s failed: %s", call, len ? text : "unknown MPI error");
}

#define MPI_TRY(c, call)                                                  \
    do {                                                                  \
        int mpi_rc_ = (call);                                             \
        if (mpi_rc_ != MPI_SUCCESS) return mpi_failed(c, #call, mpi_rc_); \
    } while (0)

/* The same in a function that frees its buffers at `done`. */
#define MPI_GO(c, rc, call)                          \
    do {                                             \
        int mpi_rc_ = (call);                        \
        if (mpi_rc_ != MPI_SUCCESS) {                \
            rc = mpi_failed(c, #call, mpi_rc_);      \
            goto done;                               \
        }                                            \
    } while (0)

/* Every rank passes its local status; all return the first failing rank's
 * code with its message ("rank R: ..."), or HD_OK when none failed.  The
 * only place where ranks learn of each other's failures, called before
 * every collective that a failed rank would not reach. */
static int agree(ctx_t *c, int rc) {
    int mine = rc != HD_OK ? c->rank : c->K, first = c->K;
    if (MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, c->comm) != MPI_SUCCESS)
        return rc != HD_OK ? rc : hd__err(&c->e, HD_EIO, "MPI_Allreduce failed while agreeing on a status");
    if (first == c->K) return HD_OK;
    hd_error_t e = c->e;
    if (c->rank == first) {
        e.code = rc;
        snprintf(e.message, sizeof e.message, "rank %d: %.1000s", first, c->e.message);
    }
    if (MPI_Bcast(&e, (int)sizeof e, MPI_BYTE, first, c->comm) != MPI_SUCCESS)
        return hd__err(&c->e, HD_EIO, "MPI_Bcast failed while agreeing on a status");
    c->e = e;
    return e.code;
}

/* ---- the RCB tree ------------------------------------------------------- */

static int key_less(const double *x, uint64_t side, uint64_t g, int axis,
                    const double *y, uint64_t yside, uint64_t yg) {
    if (x[axis] != y[axis]) return x[axis] < y[axis];
    if (side != yside) return side < yside;
    return g < yg;
}

static int sample_less(const sample_t *p, const sample_t *q, int axis) {
    return key_less(p->x, p->side, p->g, axis, q->x, q->side, q->g);
}

static int goes_left(const node_t *nd, const double *x, uint64_t side, uint64_t g) {
    double v = x[nd->axis];
    if (v != nd->s) return v < nd->s;
    if (side != nd->side) return side < nd->side;
    return g < nd->g;
}

static int rank_of(const node_t *t, int K, const double *x, uint64_t side, uint64_t g) {
    if (K == 1) return 0;
    int k = 0;
    for (;;) {
        int next = goes_left(&t[k], x, side, g) ? t[k].left : t[k].right;
        if (next < 0) return -next - 1;
        k = next;
    }
}

static void swap_samples(sample_t *a, sample_t *b) {
    sample_t t = *a;
    *a = *b;
    *b = t;
}

/* Reorder s[0..n) so that s[m] is the m-th smallest key and everything
 * before it is smaller (keys are distinct: (set, index) names one point).
 * Quickselect with the median of three. */
static void select_nth(sample_t *s, size_t n, size_t m, int axis) {
    size_t lo = 0, hi = n - 1;
    while (hi > lo) {
        size_t mid = lo + (hi - lo) / 2;
        if (sample_less(&s[mid], &s[lo], axis)) swap_samples(&s[mid], &s[lo]);
        if (sample_less(&s[hi], &s[lo], axis)) swap_samples(&s[hi], &s[lo]);
        if (sample_less(&s[hi], &s[mid], axis)) swap_samples(&s[hi], &s[mid]);
        swap_samples(&s[mid], &s[hi]); /* pivot (the median) at hi */
        size_t store = lo;
        for (size_t k = lo; k < hi; k++)
            if (sample_less(&s[k], &s[hi], axis)) swap_samples(&s[k], &s[store++]);
        swap_samples(&s[store], &s[hi]);
        if (store == m) return;
        if (m < store) hi = store - 1;
        else lo = store + 1;
    }
}

/* Node for k ranks r0.. over samples s[0..n); returns its id or -(r0 + 1). */
static int build(node_t *t, int *next, sample_t *s, size_t n, int r0, int k) {
    if (k == 1) return -(r0 + 1);
    int id = (*next)++, kl = k / 2;
    node_t nd = {INFINITY, 0, 0, 0, 0, 0, 0}; /* no samples: all go left */
    size_t m = 0;
    if (n > 0) {
        double lo[3], hi[3];
        for (int a = 0; a < 3; a++) lo[a] = hi[a] = s[0].x[a];
        for (size_t q = 1; q < n; q++)
            for (int a = 0; a < 3; a++) {
                if (s[q].x[a] < lo[a]) lo[a] = s[q].x[a];
                if (s[q].x[a] > hi[a]) hi[a] = s[q].x[a];
            }
        for (int a = 1; a < 3; a++)
            if (hi[a] - lo[a] > hi[nd.axis] - lo[nd.axis]) nd.axis = a;
        m = (size_t)((double)n * kl / k);
        if (m >= n) m = n - 1;
        select_nth(s, n, m, nd.axis);
        nd.s = s[m].x[nd.axis];
        nd.side = s[m].side;
        nd.g = s[m].g;
    }
    nd.left = build(t, next, s, m, r0, kl);
    nd.right = build(t, next, s + m, n - m, r0 + kl, k - kl);
    t[id] = nd;
    return id;
}

/* Every rank's region: the box its splits bound (infinite elsewhere). */
static void regions(const node_t *t, int node, hd__box_t box, hd__box_t *out) {
    if (node < 0) {
        out[-node - 1] = box;
        return;
    }
    const node_t *nd = &t[node];
    hd__box_t l = box, r = box;
    if (nd->s < l.hi[nd->axis]) l.hi[nd->axis] = nd->s;
    if (nd->s > r.lo[nd->axis]) r.lo[nd->axis] = nd->s;
    regions(t, nd->left, l, out);
    regions(t, nd->right, r, out);
}

/* Node boxes for the candidate search: the union of its ranks' boxes of
 * the searched set (empty ranks have lo = +inf, hi = -inf). */
static hd__box_t node_boxes(const node_t *t, int node, const held_t *held, int side, hd__box_t *out) {
    if (node < 0) return held[-node - 1].box[side];
    hd__box_t b = node_boxes(t, t[node].left, held, side, out);
    hd__box_t r = node_boxes(t, t[node].right, held, side, out);
    hd__box_merge(&b, &r);
    out[node] = b;
    return b;
}

/* Ranks other than `me` whose box of the searched set may hold a point
 * within u2 of p (ties included), appended to list. */
static void candidates(const node_t *t, const hd__box_t *nbox, const held_t *held, int side, int node,
                       const double *p, double u2, int me, int *list, int *n) {
    if (node < 0) {
        int r = -node - 1;
        if (r != me && held[r].n[side] && hd__box_lb2(&held[r].box[side], p) <= u2) list[(*n)++] = r;
        return;
    }
    if (hd__box_lb2(&nbox[node], p) > u2) return;
    candidates(t, nbox, held, side, t[node].left, p, u2, me, list, n);
    candidates(t, nbox, held, side, t[node].right, p, u2, me, list, n);
}

/* ---- the witness reduction ---------------------------------------------- */

static int far_better(const far_t *x, const far_t *y) {
    return x->d2 > y->d2 || (x->d2 == y->d2 && x->i < y->i);
}

static void far_reduce(void *in, void *inout, int *len, MPI_Datatype *type) {
    (void)type;
    const far_t *x = in;
    far_t *y = inout;
    for (int k = 0; k < *len; k++)
        if (far_better(&x[k], &y[k])) y[k] = x[k];
}

/* ---- one direction: h(P, Q) over the partition -------------------------- */

typedef struct {
    const double *P;         /* local points asking, packed xyz */
    const uint64_t *gP;
    size_t nP;
    const double *Q;         /* local points searched */
    const uint64_t *gQ;
    size_t nQ;
    int qside;               /* 0: Q is A, 1: Q is B */
} dir_t;

/* The structure of the searched local set for per-point searches (the
 * nearest layer's, as hd_distances builds it), built on first use and kept
 * for the direction: the shell and the forwarded queries ask it in turn,
 * instead of hd_distances building it again for each. */
typedef struct {
    hd__an_t s;
    int built;
} qtree_t;

/* For each of n packed points, the nearest point of Q (exact, smallest
 * index on ties, as hd_distances gives it). */
static int nearest_in_q(ctx_t *c, const dir_t *d, qtree_t *q, const double *pts, size_t n, size_t *near) {
    if (n == 0) return HD_OK;
    hd_points_t Sv = hd_points_f64(pts, n), Qv = hd_points_f64(d->Q, d->nQ);
    int threads = hd__thread_count(c->threads, n > d->nQ ? n : d->nQ), rc;
    if (n > HD__AN_MAX_POINTS || d->nQ > HD__AN_MAX_POINTS) { /* hd_distances' kd-trees */
        hd_options_t o;
        hd_options_init(&o);
        o.threads = c->threads;
        return hd_distances(&Sv, &Qv, &o, NULL, near, NULL, NULL, &c->e);
    }
    hd__box_t kb;
    hd__box_of(d->Q, d->nQ, &kb); /* keys only order (clamped): any box is exact */
    if (!q->built) {
        rc = hd__an_build(&q->s, &Qv, NULL, &kb, threads, &c->e);
        q->built = 1; /* freed by qtree_free whatever happened */
        if (rc != HD_OK) return rc;
    }
    hd__an_t asking;
    rc = hd__an_build(&asking, &Sv, NULL, &kb, threads, &c->e);
    if (rc == HD_OK) rc = hd__an_nearest(&asking, &q->s, NULL, threads, NULL, near, NULL, &c->e);
    hd__an_free(&asking);
    return rc;
}

static void qtree_free(qtree_t *q) {
    if (q->built) hd__an_free(&q->s);
    q->built = 0;
}

/* 1 when every finite face of region r is farther from p than u2 allows
 * (computed fl(gap^2) > u2): then no point of another region is within u2
 * of p, nor at u2 (see the essay, step 4). */
static int faces_clear(const hd__box_t *r, const double *p, double u2) {
    for (int a = 0; a < 3; a++) {
        if (isfinite(r->lo[a])) {
            double g = p[a] - r->lo[a];
            if (!(g * g > u2)) return 0;
        }
        if (isfinite(r->hi[a])) {
            double g = r->hi[a] - p[a];
            if (!(g * g > u2)) return 0;
        }
    }
    return 1;
}

/* The engine's pass over one direction.  hd_directed(P, Q) on the local
 * sets gives h2, the largest u(a)^2 of the rank, with its witness: so
 * u(a)^2 <= h2 for every local a, and a point whose faces are clear of h2
 * is confirmed without a search of its own (the interior).  The interior's
 * exact maximum is the engine's own answer when the engine's witness is
 * interior (it is then the smallest index at h2), else one more engine
 * call on the interior alone.  The other points (the shell) get per-point
 * searches (hd_distances).  The engine prunes the points that cannot be the
 * farthest, which per-point searches cannot: on two epochs of one scene it
 * is tens of times faster (docs/scale-out.md), and the shell is the points
 * within h of the region's faces. */
typedef struct {
    const double *xyz;       /* the shell's points (P itself when all are) */
    const uint64_t *g;
    size_t n;
    size_t *nearest;         /* each one's nearest in Q (NULL if Q is empty) */
    double *own_xyz;         /* what was allocated for a proper subset */
    uint64_t *own_g;
    far_t inner;             /* exact over the interior; d2 = -1 if none */
} shell_t;

static void shell_free(ctx_t *c, shell_t *sh) {
    cfree(c, sh->own_xyz, sh->n, 3 * sizeof(double));
    cfree(c, sh->own_g, sh->n, sizeof(uint64_t));
    cfree(c, sh->nearest, sh->n, sizeof(size_t));
}

/* The correspondence pass, for a copy and its original (|A| = |B|, point g
 * of B the moved point g of A).  After the partition a rank holds most
 * pairs whole, but not all (a face separates some), so its local sets
 * differ in size and the engine's correspondence path (docs/engine.md,
 * step 0.5), which settles a copy at a few ns a point, does not run on
 * them.  Here P_c, the local points of P whose partner is local too, and
 * Q_c, those partners, are passed to the engine in the same order (both
 * are in global index order), so the path runs.  Its answer h_c, with
 * witness a*, bounds every u(a)^2 of P_c from above (Q_c is part of the
 * local Q), so the points of P_c whose faces are clear of h_c are settled
 * (the interior; the points of P without a local partner are shell).  The
 * interior's exact maximum is h_c at a* when a* is interior and no point
 * of Q_x, the local Q points whose partner is elsewhere, is nearer to a*
 * than h_c: then u(a*)^2 = h_c, no interior u exceeds it, and any point
 * of P_c with u^2 = h_c has u_c^2 = h_c too, so an index no smaller than
 * a*'s (the engine's tie rule).  The witness's j is the engine's, or the
 * smallest index of Q_x at exactly h_c.  Otherwise (*done = 0) the caller
 * runs the engine on the whole local sets.  Tried only when nine tenths
 * of P have their partner: anything else is not a copy. */
static int paired_pass(ctx_t *c, const dir_t *d, const hd__box_t *mine, unsigned char *in, size_t *nI,
                       far_t *inner, int *done) {
    size_t nP = d->nP, nQ = d->nQ, nc = 0;
    *done = 0;
    for (size_t i = 0, j = 0; i < nP && j < nQ;) {
        if (d->gP[i] == d->gQ[j]) nc++, i++, j++;
        else if (d->gP[i] < d->gQ[j]) i++;
        else j++;
    }
    if (nc < 64 || nc < nP - nP / 10 || (nc == nP && nc == nQ)) return HD_OK; /* whole sets: the engine's own */
    size_t nx = nQ - nc;
    double *pc = cmalloc(c, nc, 3 * sizeof(double)), *qc = cmalloc(c, nc, 3 * sizeof(double));
    size_t *pidx = cmalloc(c, nc, sizeof(size_t)), *qx = cmalloc(c, nx, sizeof(size_t));
    int rc = HD_OK;
    if (!pc || !qc || !pidx || !qx) rc = nomem(c, "the pairs", nc);
    for (size_t i = 0, j = 0, t = 0, x = 0; rc == HD_OK && j < nQ;) {
        if (i < nP && d->gP[i] == d->gQ[j]) {
            memcpy(pc + 3 * t, d->P + 3 * i, 3 * sizeof(double));
            memcpy(qc + 3 * t, d->Q + 3 * j, 3 * sizeof(double));
            pidx[t++] = i++;
            j++;
        } else if (i < nP && d->gP[i] < d->gQ[j]) {
            i++;
        } else {
            qx[x++] = j++;
        }
    }
    hd_result_t e;
    if (rc == HD_OK) {
        hd_points_t Pv = hd_points_f64(pc, nc), Qv = hd_points_f64(qc, nc);
        hd_options_t o;
        hd_options_init(&o);
        o.threads = c->threads;
        rc = hd_directed(&Pv, &Qv, &o, &e, &c->e);
    }
    if (rc == HD_OK) {
        size_t astar = pidx[e.i];
        memset(in, 0, nP);
        *nI = 0;
        for (size_t t = 0; t < nc; t++) *nI += in[pidx[t]] = (unsigned char)faces_clear(mine, d->P + 3 * pidx[t], e.distance2);
        double v = INFINITY;
        uint64_t jv = UINT64_MAX;
        for (size_t x = 0; x < nx && in[astar]; x++) {
            double d2 = hd__d2(d->P + 3 * astar, d->Q + 3 * qx[x]);
            if (d2 < v || (d2 == v && d->gQ[qx[x]] < jv)) v = d2, jv = d->gQ[qx[x]];
        }
        uint64_t jc = d->gP[pidx[e.j]]; /* Q_c's point e.j is the partner of P_c's point e.j */
        if (in[astar] && v >= e.distance2) {
            *inner = (far_t){e.distance2, d->gP[astar], v == e.distance2 && jv < jc ? jv : jc};
            *done = 1;
        }
    }
    cfree(c, pc, nc, 3 * sizeof(double));
    cfree(c, qc, nc, 3 * sizeof(double));
    cfree(c, pidx, nc, sizeof(size_t));
    cfree(c, qx, nx, sizeof(size_t));
    return rc;
}

static int shell_of(ctx_t *c, const dir_t *d, const hd__box_t *mine, qtree_t *q, shell_t *sh) {
    memset(sh, 0, sizeof *sh);
    sh->inner = (far_t){-1.0, UINT64_MAX, UINT64_MAX};
    sh->xyz = d->P;
    sh->g = d->gP;
    sh->n = d->nP;
    if (d->nP == 0 || d->nQ == 0) return HD_OK;
    hd_points_t Pv = hd_points_f64(d->P, d->nP), Qv = hd_points_f64(d->Q, d->nQ);
    hd_options_t o;
    hd_options_init(&o);
    o.threads = c->threads;
    hd_result_t e;
    unsigned char *in = cmalloc(c, d->nP, 1);
    if (!in) return nomem(c, "the interior", d->nP);
    size_t nI = 0;
    int done = 0;
    int rc = paired_pass(c, d, mine, in, &nI, &sh->inner, &done);
    if (rc == HD_OK && !done && (rc = hd_directed(&Pv, &Qv, &o, &e, &c->e)) == HD_OK) {
        nI = 0;
        for (size_t k = 0; k < d->nP; k++) nI += in[k] = (unsigned char)faces_clear(mine, d->P + 3 * k, e.distance2);
    }
    if (rc != HD_OK) {
        cfree(c, in, d->nP, 1);
        return rc;
    }
    size_t nS = d->nP - nI;
    if (done) {
        /* the interior's answer is the paired pass's */
    } else if (nI && in[e.i]) {
        sh->inner = (far_t){e.distance2, d->gP[e.i], d->gQ[e.j]};
    } else if (nI) {
        double *ixyz = cmalloc(c, nI, 3 * sizeof(double));
        size_t *idx = cmalloc(c, nI, sizeof(size_t));
        if (!ixyz || !idx) rc = nomem(c, "the interior", nI);
        for (size_t k = 0, t = 0; k < d->nP && rc == HD_OK; k++)
            if (in[k]) {
                memcpy(ixyz + 3 * t, d->P + 3 * k, 3 * sizeof(double));
                idx[t++] = k;
            }
        hd_points_t Iv = hd_points_f64(ixyz, nI);
        if (rc == HD_OK && (rc = hd_directed(&Iv, &Qv, &o, &e, &c->e)) == HD_OK)
            sh->inner = (far_t){e.distance2, d->gP[idx[e.i]], d->gQ[e.j]};
        cfree(c, ixyz, nI, 3 * sizeof(double));
        cfree(c, idx, nI, sizeof(size_t));
    }
    if (rc == HD_OK && nS && nI) { /* a proper subset: copied */
        sh->n = nS;
        sh->own_xyz = cmalloc(c, nS, 3 * sizeof(double));
        sh->own_g = cmalloc(c, nS, sizeof(uint64_t));
        if (!sh->own_xyz || !sh->own_g) rc = nomem(c, "the shell", nS);
        for (size_t k = 0, t = 0; k < d->nP && rc == HD_OK; k++)
            if (!in[k]) {
                memcpy(sh->own_xyz + 3 * t, d->P + 3 * k, 3 * sizeof(double));
                sh->own_g[t++] = d->gP[k];
            }
        sh->xyz = sh->own_xyz;
        sh->g = sh->own_g;
    }
    sh->n = nS;
    cfree(c, in, d->nP, 1);
    if (rc == HD_OK && nS) {
        sh->nearest = cmalloc(c, nS, sizeof(size_t));
        if (!sh->nearest) return nomem(c, "nearest neighbours", nS);
        rc = nearest_in_q(c, d, q, sh->xyz, nS, sh->nearest);
    }
    return rc;
}

typedef struct { size_t k; int dest; int pad; } pair_t;

static int pack_queries(ctx_t *c, const double *P, const pair_t *pairs, size_t np, int *scount, int *sdispl,
                        double **send, size_t **order) {
    for (int r = 0; r < c->K; r++) scount[r] = 0;
    for (size_t t = 0; t < np; t++) scount[pairs[t].dest]++;
    size_t total = 0;
    for (int r = 0; r < c->K; r++) {
        sdispl[r] = (int)total;
        total += (size_t)scount[r];
    }
    *send = cmalloc(c, np, 3 * sizeof(double));
    *order = cmalloc(c, np, sizeof(size_t));
    if (!*send || !*order) return nomem(c, "forwarded queries", np);
    int *fill = cmalloc(c, (size_t)c->K, sizeof(int));
    if (!fill) return nomem(c, "forwarded queries", np);
    memcpy(fill, sdispl, (size_t)c->K * sizeof(int));
    for (size_t t = 0; t < np; t++) {
        size_t at = (size_t)fill[pairs[t].dest]++;
        memcpy(*send + 3 * at, P + 3 * pairs[t].k, 3 * sizeof(double));
        (*order)[at] = pairs[t].k;
    }
    cfree(c, fill, (size_t)c->K, sizeof(int));
    return HD_OK;
}

/* Answer m queries against the local Q: exact nearest, smallest index. */
static int answer(ctx_t *c, const dir_t *d, qtree_t *q, const double *pts, size_t m, ans_t *ans) {
    if (m == 0) return HD_OK;
    if (d->nQ == 0) {
        for (size_t k = 0; k < m; k++) ans[k] = (ans_t){INFINITY, UINT64_MAX};
        return HD_OK;
    }
    size_t *near = cmalloc(c, m, sizeof(size_t));
    if (!near) return nomem(c, "answers", m);
    int rc = nearest_in_q(c, d, q, pts, m, near);
    if (rc == HD_OK)
        for (size_t k = 0; k < m; k++)
            ans[k] = (ans_t){hd__d2(pts + 3 * k, d->Q + 3 * near[k]), d->gQ[near[k]]};
    cfree(c, near, m, sizeof(size_t));
    return rc;
}

static int direction(ctx_t *c, const dir_t *d, const node_t *tree, const hd__box_t *region,
                     const held_t *held, far_t *result) {
    int K = c->K, rc = HD_OK;
    const hd__box_t *mine = &region[c->rank];
    shell_t sh;
    qtree_t q = {{0}, 0};
    double t0 = hd__now(), u0 = thread_cpu();
    rc = shell_of(c, d, mine, &q, &sh);
    c->search += hd__now() - t0;
    c->search_cpu += thread_cpu() - u0;
    c->shell += sh.n;
    size_t nP = sh.n, np = 0, cap = 0;
    const double *P = sh.xyz;
    const uint64_t *gP = sh.g;
    double *u2 = cmalloc(c, nP, sizeof(double));
    uint64_t *jj = cmalloc(c, nP, sizeof(uint64_t));
    unsigned char *exact = cmalloc(c, nP, 1);
    hd__box_t *nbox = cmalloc(c, K > 1 ? (size_t)K - 1 : 1, sizeof(hd__box_t));
    int *list = cmalloc(c, (size_t)K, sizeof(int));
    pair_t *pairs = NULL;
    int *cnt = cmalloc(c, 4 * (size_t)K, sizeof(int)); /* scount sdispl rcount rdispl */
    double *sendq = NULL, *recvq = NULL;
    size_t *order = NULL, m = 0;
    ans_t *ans = NULL, *back = NULL;
    if (rc == HD_OK && (!u2 || !jj || !exact || !nbox || !list || !cnt)) rc = nomem(c, "per-point bounds", nP);
    far_t Lmine = sh.inner, Lall;
    if (rc == HD_OK) {
        for (size_t k = 0; k < nP; k++) {
            const double *p = P + 3 * k;
            if (d->nQ == 0) {
                u2[k] = INFINITY;
                jj[k] = UINT64_MAX;
                exact[k] = 0;
                continue;
            }
            u2[k] = hd__d2(p, d->Q + 3 * sh.nearest[k]);
            jj[k] = d->gQ[sh.nearest[k]];
            exact[k] = (unsigned char)faces_clear(mine, p, u2[k]);
            far_t f = {u2[k], gP[k], jj[k]};
            if (exact[k] && far_better(&f, &Lmine)) Lmine = f;
        }
        if (K > 1) node_boxes(tree, 0, held, d->qside, nbox);
    }
    if ((rc = agree(c, rc)) != HD_OK) goto done;
    /* L and the smallest index i_L of a confirmed point at L: a point
     * with u2 < L, or u2 = L and a larger index, cannot be the witness. */
    MPI_GO(c, rc, MPI_Allreduce(&Lmine, &Lall, 1, c->far_type, c->far_op, c->comm));
    double L = Lall.d2;
    uint64_t iL = Lall.i;
    /* The points to forward, as (point, rank) pairs. */
    for (size_t k = 0; k < nP && rc == HD_OK; k++) {
        if (exact[k] || u2[k] < L || (u2[k] == L && gP[k] > iL)) continue;
        const double *p = P + 3 * k;
        double bound = u2[k];
        if (d->nQ == 0)
            for (int r = 0; r < K; r++)
                if (held[r].n[d->qside]) {
                    double ub = hd__box_ub2(&held[r].box[d->qside], p);
                    if (ub < bound) bound = ub;
                }
        int n = 0;
        if (K > 1) candidates(tree, nbox, held, d->qside, 0, p, bound, c->rank, list, &n);
        if (n == 0) {
            exact[k] = 1; /* no other rank holds a point as near */
            continue;
        }
        c->forwarded_points++;
        if (np + (size_t)n > cap) {
            size_t ncap = cap ? 2 * cap : 1024;
            while (ncap < np + (size_t)n) ncap *= 2;
            pair_t *grown = cmalloc(c, ncap, sizeof(pair_t));
            if (!grown) {
                rc = nomem(c, "forwarded queries", ncap);
                break;
            }
            if (np) memcpy(grown, pairs, np * sizeof(pair_t));
            cfree(c, pairs, cap, sizeof(pair_t));
            pairs = grown;
            cap = ncap;
        }
        for (int t = 0; t < n; t++) pairs[np++] = (pair_t){k, list[t], 0};
    }
    int *scount = cnt, *sdispl = cnt + K, *rcount = cnt + 2 * K, *rdispl = cnt + 3 * K;
    if (rc == HD_OK && np > INT_MAX) rc = hd__err(&c->e, HD_EOVERFLOW, "%zu forwarded queries exceed MPI's int counts", np);
    if (rc == HD_OK) rc = pack_queries(c, P, pairs, np, scount, sdispl, &sendq, &order);
    if ((rc = agree(c, rc)) != HD_OK) goto done;
    MPI_GO(c, rc, MPI_Alltoall(scount, 1, MPI_INT, rcount, 1, MPI_INT, c->comm));
    for (int r = 0; r < K; r++) {
        if (m > INT_MAX) break;
        rdispl[r] = (int)m;
        m += (size_t)rcount[r];
    }
    if (m > INT_MAX) rc = hd__err(&c->e, HD_EOVERFLOW, "%zu queries received exceed MPI's int counts", m);
    if (rc == HD_OK) {
        recvq = cmalloc(c, m, 3 * sizeof(double));
        ans = cmalloc(c, m, sizeof(ans_t));
        back = cmalloc(c, np, sizeof(ans_t));
        if (!recvq || !ans || !back) rc = nomem(c, "forwarded queries", m);
    }
    if ((rc = agree(c, rc)) != HD_OK) goto done;
    MPI_GO(c, rc, MPI_Alltoallv(sendq, scount, sdispl, c->q_type, recvq, rcount, rdispl, c->q_type, c->comm));
    double t = hd__now(), u = thread_cpu();
    rc = answer(c, d, &q, recvq, m, ans);
    c->search += hd__now() - t;
    c->search_cpu += thread_cpu() - u;
    c->answered += m;
    if ((rc = agree(c, rc)) != HD_OK) goto done;
    MPI_GO(c, rc, MPI_Alltoallv(ans, rcount, rdispl, c->ans_type, back, scount, sdispl, c->ans_type, c->comm));
    c->rounds++;
    c->forwarded += np;
    c->bytes_fwd += (uint64_t)np * (3 * sizeof(double) + sizeof(ans_t));
    for (size_t t = 0; t < np; t++) {
        size_t k = order[t];
        if (back[t].d2 < u2[k] || (back[t].d2 == u2[k] && back[t].g < jj[k])) {
            u2[k] = back[t].d2;
            jj[k] = back[t].g;
        }
    }
    /* Every point that could win is now exact; the others cannot win (a
     * point at L with a larger index than i_L loses to i_L). */
    far_t best = sh.inner;
    for (size_t k = 0; k < nP; k++) {
        if (u2[k] < L || (u2[k] == L && gP[k] > iL)) continue;
        far_t f = {u2[k], gP[k], jj[k]};
        if (far_better(&f, &best)) best = f;
    }
    MPI_GO(c, rc, MPI_Allreduce(&best, result, 1, c->far_type, c->far_op, c->comm));
done:
    cfree(c, u2, nP, sizeof(double));
    cfree(c, jj, nP, sizeof(uint64_t));
    cfree(c, exact, nP, 1);
    cfree(c, nbox, K > 1 ? (size_t)K - 1 : 1, sizeof(hd__box_t));
    cfree(c, list, (size_t)K, sizeof(int));
    cfree(c, cnt, 4 * (size_t)K, sizeof(int));
    cfree(c, pairs, cap, sizeof(pair_t));
    cfree(c, sendq, np, 3 * sizeof(double));
    cfree(c, order, np, sizeof(size_t));
    cfree(c, recvq, m, 3 * sizeof(double));
    cfree(c, ans, m, sizeof(ans_t));
    cfree(c, back, np, sizeof(ans_t));
    shell_free(c, &sh);
    qtree_free(&q);
    return rc;
}

/* ---- the partition and the exchange -------------------------------------- */

typedef struct {
    const hd_mpi_part_t *parts[2];
    size_t nparts[2];
    uint64_t n[2];            /* local points of A, B (input) */
    hd__box_t box[2];         /* local boxes (input) */
} input_t;

/* Point k of a view: packed doubles directly, anything else through
 * hd_points_get (the exchange reads every point twice). */
static inline void get_point(const hd_points_t *p, size_t k, double out[3]) {
    if (p->dtype == HD_FLOAT64 && (p->stride == 0 || p->stride == 3 * (ptrdiff_t)sizeof(double)) &&
        (p->cstride == 0 || p->cstride == (ptrdiff_t)sizeof(double)))
        memcpy(out, (const double *)p->data + 3 * k, 3 * sizeof(double));
    else
        hd_points_get(p, k, out);
}

/* Part k of side s in increasing offset order (parts do not share
 * indices, so this is increasing global index order). */
static int by_offset(const void *x, const void *y) {
    const hd_mpi_part_t *p = *(const hd_mpi_part_t *const *)x, *q = *(const hd_mpi_part_t *const *)y;
    return p->offset < q->offset ? -1 : p->offset > q->offset;
}

typedef struct { uint64_t lo, hi; int side, rank; } range_t;

static int by_range(const void *x, const void *y) {
    const range_t *p = x, *q = y;
    if (p->side != q->side) return p->side - q->side;
    return p->lo < q->lo ? -1 : p->lo > q->lo;
}

/* Over all ranks, no two parts of one set share an index. */
static int check_ranges(ctx_t *c, const input_t *in) {
    int n = 0, rc = HD_OK;
    for (int s = 0; s < 2; s++)
        for (size_t k = 0; k < in->nparts[s]; k++) n += in->parts[s][k].points.count > 0;
    int *counts = cmalloc(c, 2 * (size_t)c->K, sizeof(int));
    if (!counts) rc = nomem(c, "index ranges", (size_t)c->K);
    if ((rc = agree(c, rc)) != HD_OK) return rc;
    MPI_TRY(c, MPI_Allgather(&n, 1, MPI_INT, counts, 1, MPI_INT, c->comm));
    size_t total = 0;
    int *displ = counts + c->K;
    for (int r = 0; r < c->K; r++) {
        displ[r] = (int)(total * sizeof(range_t));
        total += (size_t)counts[r];
        counts[r] *= (int)sizeof(range_t);
    }
    range_t *mine = cmalloc(c, (size_t)n, sizeof(range_t)), *all = cmalloc(c, total, sizeof(range_t));
    if (!mine || !all || total * sizeof(range_t) > INT_MAX) rc = nomem(c, "index ranges", total);
    if ((rc = agree(c, rc)) == HD_OK) {
        int t = 0;
        for (int s = 0; s < 2; s++)
            for (size_t k = 0; k < in->nparts[s]; k++) {
                const hd_mpi_part_t *p = &in->parts[s][k];
                if (p->points.count)
                    mine[t++] = (range_t){p->offset, p->offset + (p->points.count - 1), s, c->rank};
            }
        int e = MPI_Allgatherv(mine, n * (int)sizeof(range_t), MPI_BYTE, all, counts, displ, MPI_BYTE, c->comm);
        if (e != MPI_SUCCESS) rc = mpi_failed(c, "MPI_Allgatherv", e);
    }
    if (rc == HD_OK) {
        qsort(all, total, sizeof(range_t), by_range);
        for (size_t k = 1; k < total; k++)
            if (all[k].side == all[k - 1].side && all[k].lo <= all[k - 1].hi) {
                rc = hd__err(&c->e, HD_EINVAL,
                             "parts of %s share indices: %llu..%llu on rank %d and %llu..%llu on rank %d",
                             all[k].side ? "B" : "A", (unsigned long long)all[k - 1].lo,
                             (unsigned long long)all[k - 1].hi, all[k - 1].rank, (unsigned long long)all[k].lo,
                             (unsigned long long)all[k].hi, all[k].rank);
                break;
            }
    }
    cfree(c, counts, 2 * (size_t)c->K, sizeof(int));
    cfree(c, mine, (size_t)n, sizeof(range_t));
    cfree(c, all, total, sizeof(range_t));
    return rc;
}

/* Local point t (A's parts in order, then B's) as side, part index. */
typedef struct { int side; size_t part, k; } cursor_t;

static void cursor_seek(const input_t *in, uint64_t t, cursor_t *cu) {
    for (int s = 0; s < 2; s++)
        for (size_t p = 0; p < in->nparts[s]; p++) {
            size_t n = in->parts[s][p].points.count;
            if (t < n) {
                *cu = (cursor_t){s, p, (size_t)t};
                return;
            }
            t -= n;
        }
}

/* Rank 0 builds the RCB tree from everyone's samples; all get it. */
static int partition(ctx_t *c, const input_t *in, uint64_t N, node_t *tree) {
    int rc = HD_OK, K = c->K;
    uint64_t nloc = in->n[0] + in->n[1];
    uint64_t S = N < (uint64_t)SAMPLES_PER_RANK * (uint64_t)K ? N : (uint64_t)SAMPLES_PER_RANK * (uint64_t)K;
    size_t ns = (size_t)((double)S * (double)nloc / (double)N);
    if (ns > nloc) ns = (size_t)nloc;
    if (ns == 0 && nloc > 0) ns = 1;
    sample_t *mine = cmalloc(c, ns, sizeof(sample_t));
    int *counts = cmalloc(c, 2 * (size_t)K, sizeof(int));
    if (!mine || !counts) rc = nomem(c, "samples", ns);
    if (rc == HD_OK && ns > INT_MAX / 64) rc = hd__err(&c->e, HD_EOVERFLOW, "too many samples");
    for (size_t t = 0; t < ns && rc == HD_OK; t++) {
        uint64_t at = (uint64_t)(((double)t + 0.5) * (double)nloc / (double)ns);
        if (at >= nloc) at = nloc - 1;
        cursor_t cu = {0, 0, 0};
        cursor_seek(in, at, &cu);
        const hd_mpi_part_t *p = &in->parts[cu.side][cu.part];
        get_point(&p->points, cu.k, mine[t].x);
        mine[t].g = p->offset + cu.k;
        mine[t].side = (uint64_t)cu.side;
    }
    if ((rc = agree(c, rc)) != HD_OK) goto done;
    int n = (int)ns;
    MPI_GO(c, rc, MPI_Gather(&n, 1, MPI_INT, counts, 1, MPI_INT, 0, c->comm));
    size_t total = 0;
    sample_t *all = NULL;
    if (c->rank == 0) {
        for (int r = 0; r < K; r++) {
            counts[K + r] = (int)total;
            total += (size_t)counts[r];
        }
        all = cmalloc(c, total, sizeof(sample_t));
        if (!all) rc = nomem(c, "samples", total);
    }
    if ((rc = agree(c, rc)) == HD_OK) {
        int e = MPI_Gatherv(mine, n, c->sample_type, all, counts, counts + K, c->sample_type, 0, c->comm);
        if (e != MPI_SUCCESS) rc = mpi_failed(c, "MPI_Gatherv", e);
        c->bytes_part += c->rank ? (uint64_t)ns * sizeof(sample_t) : 0;
        if (rc == HD_OK && c->rank == 0) {
            int next = 0;
            build(tree, &next, all, total, 0, K);
        }
    }
    if (c->rank == 0) cfree(c, all, total, sizeof(sample_t));
    if ((rc = agree(c, rc)) != HD_OK) goto done;
    if (K > 1) MPI_GO(c, rc, MPI_Bcast(tree, K - 1, c->node_type, 0, c->comm));
done:
    cfree(c, mine, ns, sizeof(sample_t));
    cfree(c, counts, 2 * (size_t)K, sizeof(int));
    return rc;
}

/* Merge K runs of records sorted by index into packed xyz and indices. */
typedef struct { const rec_t *at, *end; } run_t;

static void merge_runs(run_t *runs, int K, int *heap, double *xyz, uint64_t *g) {
    int n = 0;
    for (int r = 0; r < K; r++) {
        if (runs[r].at == runs[r].end) continue;
        int k = n++; /* sift up */
        while (k > 0 && runs[heap[(k - 1) / 2]].at->g > runs[r].at->g) {
            heap[k] = heap[(k - 1) / 2];
            k = (k - 1) / 2;
        }
        heap[k] = r;
    }
    size_t out = 0;
    while (n > 0) {
        run_t *top = &runs[heap[0]];
        memcpy(xyz + 3 * out, top->at->x, 3 * sizeof(double));
        g[out++] = top->at->g;
        int r = heap[0];
        if (++top->at == top->end) r = heap[--n];
        /* sift down r from the root */
        int k = 0;
        for (;;) {
            int ch = 2 * k + 1;
            if (ch >= n) break;
            if (ch + 1 < n && runs[heap[ch + 1]].at->g < runs[heap[ch]].at->g) ch++;
            if (runs[heap[ch]].at->g >= runs[r].at->g) break;
            heap[k] = heap[ch];
            k = ch;
        }
        if (n > 0) heap[k] = r;
    }
}

typedef struct {
    double *xyz[2];
    uint64_t *g[2];
    size_t n[2];
} local_t;

/* Move every point to the rank of its region (one MPI_Alltoallv). */
static int exchange(ctx_t *c, const input_t *in, const node_t *tree, local_t *loc) {
    int K = c->K, rc = HD_OK;
    size_t nloc = (size_t)(in->n[0] + in->n[1]), scap = nloc, rcap = 0;
    int *cnt = cmalloc(c, 8 * (size_t)K, sizeof(int)); /* per rank: s[2] r[2] scount sdispl rcount rdispl */
    size_t *fill = cmalloc(c, 2 * (size_t)K, sizeof(size_t));
    int *dest = cmalloc(c, nloc, sizeof(int));
    const hd_mpi_part_t **order[2] = {NULL, NULL};
    rec_t *send = NULL, *recv = NULL;
    run_t *runs = NULL;
    int *heap = NULL;
    for (int s = 0; s < 2; s++) order[s] = cmalloc(c, in->nparts[s], sizeof *order[s]);
    if (!cnt || !fill || !dest || !order[0] || !order[1]) rc = nomem(c, "the exchange", nloc);
    int *sc = cnt, *rcn = cnt + 2 * K, *scount = cnt + 4 * K, *sdispl = cnt + 5 * K, *rcount = cnt + 6 * K,
        *rdispl = cnt + 7 * K;
    if (rc == HD_OK) {
        memset(fill, 0, 2 * (size_t)K * sizeof(size_t));
        size_t t = 0;
        for (int s = 0; s < 2; s++) {
            for (size_t p = 0; p < in->nparts[s]; p++) order[s][p] = &in->parts[s][p];
            qsort(order[s], in->nparts[s], sizeof *order[s], by_offset);
            for (size_t p = 0; p < in->nparts[s]; p++)
                for (size_t k = 0; k < order[s][p]->points.count; k++) {
                    double x[3];
                    get_point(&order[s][p]->points, k, x);
                    int r = rank_of(tree, K, x, (uint64_t)s, order[s][p]->offset + k);
                    dest[t++] = r;
                    fill[2 * r + s]++;
                }
        }
        size_t total = 0;
        for (int r = 0; r < K && rc == HD_OK; r++) {
            if (fill[2 * r] > INT_MAX || fill[2 * r + 1] > INT_MAX || total > INT_MAX ||
                fill[2 * r] + fill[2 * r + 1] > (size_t)INT_MAX - total)
                rc = hd__err(&c->e, HD_EOVERFLOW, "more than 2^31 - 1 points to send from rank %d", c->rank);
            else {
                sc[2 * r] = (int)fill[2 * r];
                sc[2 * r + 1] = (int)fill[2 * r + 1];
                sdispl[r] = (int)total;
                scount[r] = sc[2 * r] + sc[2 * r + 1];
                size_t a0 = total;
                total += fill[2 * r] + fill[2 * r + 1];
                fill[2 * r + 1] = a0 + fill[2 * r]; /* where B's records start */
                fill[2 * r] = a0;
                if (r != c->rank) c->bytes_part += (uint64_t)scount[r] * sizeof(rec_t);
            }
        }
        send = cmalloc(c, scap, sizeof(rec_t));
        if (rc == HD_OK && !send) rc = nomem(c, "points to send", nloc);
        t = 0;
        for (int s = 0; s < 2 && rc == HD_OK; s++)
            for (size_t p = 0; p < in->nparts[s]; p++)
                for (size_t k = 0; k < order[s][p]->points.count; k++) {
                    rec_t *r = &send[fill[2 * dest[t++] + s]++];
                    get_point(&order[s][p]->points, k, r->x);
                    r->g = order[s][p]->offset + k;
                }
    }
    cfree(c, dest, nloc, sizeof(int));
    dest = NULL;
    if ((rc = agree(c, rc)) != HD_OK) goto done;
    MPI_GO(c, rc, MPI_Alltoall(sc, 2, MPI_INT, rcn, 2, MPI_INT, c->comm));
    size_t m = 0;
    loc->n[0] = loc->n[1] = 0;
    for (int r = 0; r < K && rc == HD_OK; r++) {
        size_t here = (size_t)rcn[2 * r] + (size_t)rcn[2 * r + 1];
        if (m > INT_MAX || here > (size_t)INT_MAX - m)
            rc = hd__err(&c->e, HD_EOVERFLOW, "more than 2^31 - 1 points to receive on rank %d", c->rank);
        else {
            rdispl[r] = (int)m;
            rcount[r] = (int)here;
            if (r != c->rank) m += here; /* its own stay in the send buffer */
            loc->n[0] += (size_t)rcn[2 * r];
            loc->n[1] += (size_t)rcn[2 * r + 1];
        }
    }
    if (rc == HD_OK) {
        rcap = m;
        recv = cmalloc(c, m, sizeof(rec_t));
        if (!recv) rc = nomem(c, "points received", m);
    }
    if ((rc = agree(c, rc)) != HD_OK) goto done;
    /* What stays on this rank is merged from the send buffer, not copied
     * through MPI. */
    int me = c->rank, keep_s = scount[me], keep_r = rcount[me];
    scount[me] = rcount[me] = 0;
    MPI_GO(c, rc, MPI_Alltoallv(send, scount, sdispl, c->rec_type, recv, rcount, rdispl, c->rec_type, c->comm));
    scount[me] = keep_s;
    rcount[me] = keep_r;
    runs = cmalloc(c, (size_t)K, sizeof(run_t));
    heap = cmalloc(c, (size_t)K, sizeof(int));
    for (int s = 0; s < 2; s++) {
        loc->xyz[s] = cmalloc(c, loc->n[s], 3 * sizeof(double));
        loc->g[s] = cmalloc(c, loc->n[s], sizeof(uint64_t));
        if (!loc->xyz[s] || !loc->g[s]) rc = nomem(c, "the local points", loc->n[s]);
    }
    if (!runs || !heap) rc = nomem(c, "the merge", (size_t)K);
    for (int s = 0; s < 2 && rc == HD_OK; s++) {
        for (int r = 0; r < K; r++) {
            const rec_t *b = (r == me ? send + sdispl[r] : recv + rdispl[r]) + (s ? rcn[2 * r] : 0);
            runs[r] = (run_t){b, b + rcn[2 * r + s]};
        }
        merge_runs(runs, K, heap, loc->xyz[s], loc->g[s]);
    }
    rc = agree(c, rc);
done:
    cfree(c, cnt, 8 * (size_t)K, sizeof(int));
    cfree(c, fill, 2 * (size_t)K, sizeof(size_t));
    cfree(c, dest, nloc, sizeof(int));
    for (int s = 0; s < 2; s++) cfree(c, order[s], in->nparts[s], sizeof *order[s]);
    cfree(c, send, scap, sizeof(rec_t));
    cfree(c, recv, rcap, sizeof(rec_t));
    cfree(c, runs, (size_t)K, sizeof(run_t));
    cfree(c, heap, (size_t)K, sizeof(int));
    return rc;
}

/* ---- the call ------------------------------------------------------------ */

static int types_create(ctx_t *c) {
    MPI_TRY(c, MPI_Type_contiguous((int)sizeof(rec_t), MPI_BYTE, &c->rec_type));
    MPI_TRY(c, MPI_Type_contiguous((int)sizeof(ans_t), MPI_BYTE, &c->ans_type));
    MPI_TRY(c, MPI_Type_contiguous(3, MPI_DOUBLE, &c->q_type));
    MPI_TRY(c, MPI_Type_contiguous((int)sizeof(far_t), MPI_BYTE, &c->far_type));
    MPI_TRY(c, MPI_Type_contiguous((int)sizeof(sample_t), MPI_BYTE, &c->sample_type));
    MPI_TRY(c, MPI_Type_contiguous((int)sizeof(node_t), MPI_BYTE, &c->node_type));
    MPI_Datatype *all[] = {&c->rec_type, &c->ans_type, &c->q_type, &c->far_type, &c->sample_type, &c->node_type};
    for (size_t k = 0; k < sizeof all / sizeof *all; k++) MPI_TRY(c, MPI_Type_commit(all[k]));
    MPI_TRY(c, MPI_Op_create(far_reduce, 1, &c->far_op));
    return HD_OK;
}

static void types_free(ctx_t *c) {
    MPI_Datatype *all[] = {&c->rec_type, &c->ans_type, &c->q_type, &c->far_type, &c->sample_type, &c->node_type};
    for (size_t k = 0; k < sizeof all / sizeof *all; k++)
        if (*all[k] != MPI_DATATYPE_NULL) MPI_Type_free(all[k]);
    if (c->far_op != MPI_OP_NULL) MPI_Op_free(&c->far_op);
}

/* Local checks: options, parts (views valid, finite, in range, indices
 * within size_t), with the local counts and boxes. */
static int check_local(ctx_t *c, const hd_options_t *opt, input_t *in, const void *out) {
    if (!out) return hd__err(&c->e, HD_EINVAL, "the result pointer is NULL");
    if (opt && opt->threads < 0)
        return hd__err(&c->e, HD_EINVAL, "threads must be 0 (every core) or positive, not %d", opt->threads);
    if (opt && ((int)opt->algorithm < 0 || opt->algorithm >= HD__ALG_COUNT))
        return hd__err(&c->e, HD_EALGORITHM, "unknown algorithm %d", (int)opt->algorithm);
    for (int s = 0; s < 2; s++) {
        const char *name = s ? "B" : "A";
        in->n[s] = 0;
        for (int k = 0; k < 3; k++) in->box[s].lo[k] = INFINITY, in->box[s].hi[k] = -INFINITY;
        if (in->nparts[s] && !in->parts[s]) return hd__err(&c->e, HD_EINVAL, "the parts of %s are NULL", name);
        for (size_t p = 0; p < in->nparts[s]; p++) {
            const hd_mpi_part_t *part = &in->parts[s][p];
            if (part->points.count == 0) continue;
            if (part->points.count - 1 > SIZE_MAX - part->offset || part->offset + part->points.count - 1 >= UINT64_MAX)
                return hd__err(&c->e, HD_EINVAL, "part %zu of %s: indices %zu + %zu run past SIZE_MAX", p, name,
                               part->offset, part->points.count);
            char what[64];
            snprintf(what, sizeof what, "%s (part %zu, first index %zu)", name, p, part->offset);
            hd__box_t box;
            int rc = hd__points_scan(&part->points, what, c->threads, &box, &c->e);
            if (rc != HD_OK) return rc;
            hd__box_merge(&in->box[s], &box);
            in->n[s] += part->points.count;
        }
    }
    return HD_OK;
}

enum { MODE_DIRECTED = 0, MODE_BOTH = 1, MODE_OVERLAP = 2 };
typedef struct { double *alpha; int *disjoint; } overlap_t;

/* `both` is a MODE_*: res is an hd_result_t, an hd_symmetric_t or an
 * overlap_t. */
static int run(ctx_t *c, const hd_options_t *opt, input_t *in, int both, void *res, hd_mpi_stats_t *st) {
    hd_symmetric_t *out = both == MODE_BOTH ? res : NULL;
    int K = c->K;
    double t0 = hd__now();
    node_t *tree = NULL;
    hd__box_t *region = NULL;
    held_t *held = NULL;
    local_t loc = {{NULL, NULL}, {NULL, NULL}, {0, 0}};
    int rc = check_local(c, opt, in, res);
    if ((rc = agree(c, rc)) != HD_OK) return rc;
    if ((rc = check_ranges(c, in)) != HD_OK) return rc;
    uint64_t n[2] = {in->n[0], in->n[1]}, N[2];
    MPI_GO(c, rc, MPI_Allreduce(n, N, 2, MPI_UINT64_T, MPI_SUM, c->comm));
    if (N[0] == 0 || N[1] == 0) return hd__err(&c->e, HD_EEMPTY, "point set %s is empty", N[0] ? "B" : "A");
    /* Global boxes (hi negated: one MIN), and alpha as hd_overlap gives it. */
    double bx[12], gb[12];
    for (int s = 0; s < 2; s++)
        for (int k = 0; k < 3; k++) bx[6 * s + k] = in->box[s].lo[k], bx[6 * s + 3 + k] = -in->box[s].hi[k];
    MPI_GO(c, rc, MPI_Allreduce(bx, gb, 12, MPI_DOUBLE, MPI_MIN, c->comm));
    double corners[2][6];
    for (int s = 0; s < 2; s++)
        for (int k = 0; k < 3; k++) corners[s][k] = gb[6 * s + k], corners[s][3 + k] = -gb[6 * s + 3 + k];
    hd_points_t ca = hd_points_f64(corners[0], 2), cb = hd_points_f64(corners[1], 2);
    if (both == MODE_OVERLAP) {
        overlap_t *o = res;
        return hd_overlap(&ca, &cb, o->alpha, o->disjoint, &c->e);
    }
    memset(res, 0, both ? sizeof(hd_symmetric_t) : sizeof(hd_result_t));
    if (both && (rc = hd_overlap(&ca, &cb, &out->alpha, &out->disjoint, &c->e)) != HD_OK) return rc;

    tree = cmalloc(c, K > 1 ? (size_t)K - 1 : 1, sizeof(node_t));
    region = cmalloc(c, (size_t)K, sizeof(hd__box_t));
    held = cmalloc(c, (size_t)K, sizeof(held_t));
    if (!tree || !region || !held) rc = nomem(c, "the partition", (size_t)K);
    if ((rc = agree(c, rc)) != HD_OK) goto done;
    if ((rc = partition(c, in, N[0] + N[1], tree)) != HD_OK) goto done;
    hd__box_t all = {{-INFINITY, -INFINITY, -INFINITY}, {INFINITY, INFINITY, INFINITY}};
    if (K > 1) regions(tree, 0, all, region);
    else region[0] = all;
    if ((rc = exchange(c, in, tree, &loc)) != HD_OK) goto done;

    /* What every rank holds now. */
    held_t h;
    for (int s = 0; s < 2; s++) {
        h.n[s] = loc.n[s];
        if (loc.n[s]) hd__box_of(loc.xyz[s], loc.n[s], &h.box[s]);
        else
            for (int k = 0; k < 3; k++) h.box[s].lo[k] = INFINITY, h.box[s].hi[k] = -INFINITY;
    }
    MPI_GO(c, rc, MPI_Allgather(&h, (int)sizeof h, MPI_BYTE, held, (int)sizeof h, MPI_BYTE, c->comm));

    far_t f[2];
    for (int s = 0; s < (both ? 2 : 1); s++) {
        dir_t d = {loc.xyz[s], loc.g[s], loc.n[s], loc.xyz[1 - s], loc.g[1 - s], loc.n[1 - s], 1 - s};
        if ((rc = direction(c, &d, tree, region, held, &f[s])) != HD_OK) goto done;
    }
    hd_result_t *r[2] = {both ? &out->ab : res, both ? &out->ba : NULL};
    for (int s = 0; s < (both ? 2 : 1); s++) {
        r[s]->distance2 = f[s].d2;
        r[s]->distance = sqrt(f[s].d2);
        r[s]->i = (size_t)f[s].i;
        r[s]->j = (size_t)f[s].j;
        r[s]->algorithm = HD_ALG_AUTO;
    }
    /* Figures. */
    double secs = hd__now() - t0, tmax = secs, tsum = secs, mine[3] = {secs, c->search, c->search_cpu}, most[3];
    MPI_GO(c, rc, MPI_Allreduce(mine, most, 3, MPI_DOUBLE, MPI_MAX, c->comm));
    tmax = most[0];
    MPI_GO(c, rc, MPI_Allreduce(&secs, &tsum, 1, MPI_DOUBLE, MPI_SUM, c->comm));
    for (int s = 0; s < (both ? 2 : 1); s++) r[s]->seconds = tmax;
    if (both) {
        out->distance = out->ab.distance2 >= out->ba.distance2 ? out->ab.distance : out->ba.distance;
        out->seconds = tmax;
    }
    if (st) {
        uint64_t pts = loc.n[0] + loc.n[1], work = pts + c->answered;
        uint64_t sums[6] = {c->bytes_part, c->bytes_fwd, c->forwarded, c->forwarded_points, work, c->shell}, gs[6];
        uint64_t maxes[3] = {pts, work, c->peak}, gm[3];
        MPI_GO(c, rc, MPI_Allreduce(sums, gs, 6, MPI_UINT64_T, MPI_SUM, c->comm));
        MPI_GO(c, rc, MPI_Allreduce(maxes, gm, 3, MPI_UINT64_T, MPI_MAX, c->comm));
        memset(st, 0, sizeof *st);
        st->ranks = K;
        st->points = N[0] + N[1];
        st->bytes_partition = gs[0];
        st->bytes_forwarding = gs[1];
        st->forwarded = gs[2];
        st->forwarded_points = gs[3];
        st->shell_points = gs[5];
        st->rounds = c->rounds;
        st->points_max = gm[0];
        st->imbalance = (double)gm[0] * K / (double)st->points;
        st->work_imbalance = (double)gm[1] * K / (double)gs[4];
        st->seconds_max = tmax;
        st->seconds_mean = tsum / K;
        st->search_seconds_max = most[1];
        st->search_seconds = c->search;
        st->search_cpu_max = most[2];
        st->peak_bytes_max = gm[2];
        st->seconds = secs;
        st->local_points = pts;
        st->peak_bytes = c->peak;
    }
done:
    for (int s = 0; s < 2; s++) {
        cfree(c, loc.xyz[s], loc.n[s], 3 * sizeof(double));
        cfree(c, loc.g[s], loc.n[s], sizeof(uint64_t));
    }
    cfree(c, tree, K > 1 ? (size_t)K - 1 : 1, sizeof(node_t));
    cfree(c, region, (size_t)K, sizeof(hd__box_t));
    cfree(c, held, (size_t)K, sizeof(held_t));
    return rc;
}

static int call(MPI_Comm comm, const hd_mpi_part_t *a, size_t na, const hd_mpi_part_t *b, size_t nb,
                const hd_options_t *opt, int both, void *out, hd_mpi_stats_t *st, hd_error_t *err) {
    hd__err_clear(err);
    ctx_t c;
    memset(&c, 0, sizeof c);
    c.rec_type = c.ans_type = c.q_type = c.far_type = c.sample_type = c.node_type = MPI_DATATYPE_NULL;
    c.far_op = MPI_OP_NULL;
    c.comm = MPI_COMM_NULL;
    hd__err_clear(&c.e);
    int init = 0, fin = 0;
    if (MPI_Initialized(&init) != MPI_SUCCESS || !init || MPI_Finalized(&fin) != MPI_SUCCESS || fin)
        return hd__err(err, HD_EINVAL, "MPI is not initialised (or already finalised)");
    if (comm == MPI_COMM_NULL) return hd__err(err, HD_EINVAL, "the communicator is MPI_COMM_NULL");
    int rc = HD_OK, e;
    if ((e = MPI_Comm_dup(comm, &c.comm)) != MPI_SUCCESS) {
        rc = mpi_failed(&c, "MPI_Comm_dup", e);
    } else {
        MPI_Comm_set_errhandler(c.comm, MPI_ERRORS_RETURN);
        MPI_Comm_rank(c.comm, &c.rank);
        MPI_Comm_size(c.comm, &c.K);
        c.threads = opt ? opt->threads : 0;
        if (c.threads < 0) c.threads = 1; /* refused by check_local, on every rank */
        rc = types_create(&c);
        if ((rc = agree(&c, rc)) == HD_OK) {
            input_t in = {{a, b}, {na, nb}, {0, 0}, {{{0}, {0}}, {{0}, {0}}}};
            rc = run(&c, opt, &in, both, out, st);
        }
        /* Every buffer of the call was freed, on every path (the
         * sanitizer build checks this instead of LeakSanitizer, which
         * Open MPI's own unfreed allocations drown: tests/mpi.cmake). */
        assert(c.cur == 0);
        types_free(&c);
        MPI_Comm_free(&c.comm);
    }
    if (rc != HD_OK && err) *err = c.e;
    return rc;
}

int hd_mpi_hausdorff(MPI_Comm comm, const hd_mpi_part_t *a, size_t na, const hd_mpi_part_t *b, size_t nb,
                     const hd_options_t *opt, hd_symmetric_t *out, hd_mpi_stats_t *stats, hd_error_t *err) {
    return call(comm, a, na, b, nb, opt, MODE_BOTH, out, stats, err);
}

int hd_mpi_directed(MPI_Comm comm, const hd_mpi_part_t *a, size_t na, const hd_mpi_part_t *b, size_t nb,
                    const hd_options_t *opt, hd_result_t *out, hd_mpi_stats_t *stats, hd_error_t *err) {
    return call(comm, a, na, b, nb, opt, MODE_DIRECTED, out, stats, err);
}

int hd_mpi_overlap(MPI_Comm comm, const hd_mpi_part_t *a, size_t na, const hd_mpi_part_t *b, size_t nb,
                   double *alpha, int *disjoint, hd_error_t *err) {
    overlap_t o = {alpha, disjoint};
    if (!alpha || !disjoint) o.alpha = NULL; /* refused by check_local, on every rank */
    return call(comm, a, na, b, nb, NULL, MODE_OVERLAP, o.alpha ? &o : NULL, NULL, err);
}
