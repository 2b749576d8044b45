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
 *  2. MPI_Alltoallv moves each point to the rank of its region as its
 *     coordinates and a 4-byte number, its rank among the sender's points
 *     of its set in index order (28 bytes; every rank knows every rank's
 *     index runs, so the receiver turns it back into the global index).
 *     Each source's run is received straight into its slot of the local
 *     arrays, in rounds of at most an eighth of a rank's points, so the
 *     points are never held twice.  Senders walk their parts in increasing
 *     index order, so each run is sorted; when the runs follow each other
 *     in index order (each rank's parts above the previous rank's) the
 *     local arrays are in global order as received and keep the numbers
 *     (gidx_t: 28 bytes a point, the index computed where one is needed),
 *     else the numbers become 8-byte indices and the arrays are merged in
 *     place (a permutation, 4 bytes a point): local order is global index
 *     order, and a local "smallest index on ties" is the global one.  The
 *     arrays are never reordered afterwards (the engine's passes on a
 *     subset move coordinates only), so a position's index is fixed.
 *     On one rank none of this happens: the engine runs on the caller's
 *     points as they are (one part a set) or packed once (several).
 *  3. The single-machine engine on each rank's part: hd_directed(local A,
 *     local B) gives h2, the rank's largest u(a)^2, where u(a)^2 is the
 *     exact minimum over local B (an upper bound on the minimum over all
 *     of B).  Every a whose region faces are clear of h2 (step 4's test
 *     with h2 >= u(a)^2) is settled without a search of its own (the
 *     interior).  When the engine's witness is interior, it is the
 *     interior's maximum; else the interior's maximum is computed (one
 *     more engine call on it) only on a rank where the engine's answer
 *     beats the best over all ranks found without it (step 6): every
 *     interior point is below that answer.  The rest, the shell within h
 *     of the faces, get per-point searches (the nearest layer's, as
 *     hd_distances runs them: the nearest local b, smallest index on
 *     ties) on a structure of the slab of local B within about 2h of the
 *     faces, which the forwarded queries of step 5 ask too; an answer the
 *     slab cannot prove (see slab_t) asks a wider slab, then all of B.
 *     The engine prunes the points that cannot be the farthest, which
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
 *     is max-reduced; then the ranks of step 3 whose engine answer beats
 *     that add their interior's maximum, and it is reduced again.  The
 *     result is the pair hd_hausdorff gives on the union, bit for bit,
 *     since every value compared is an hd__d2 of the same doubles.
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
    double mpi_cpu;            /* ... and in MPI calls */
    uint64_t shell;            /* points searched one by one (the shells) */
    uint64_t interior_passes;  /* second engine calls on an interior */
    int rounds;
    MPI_Datatype ans_type, q_type, far_type, sample_type, node_type;
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
    {
        p = malloc(bytes ? bytes : 1);
        hd__prefault(p, bytes); /* one call, not a fault a page (a no-op below 1 MiB) */
    }
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

/* Memory this layer does not allocate itself but the call holds: counted
 * in the peak while held. */
static void charge(ctx_t *c, size_t bytes) {
    c->cur += bytes;
    if (c->cur > c->peak) c->peak = c->cur;
}

/* The engine's own memory, which this layer cannot see: docs/engine.md
 * bounds it by 16 bytes a point of each set (its two trees while sorted;
 * the grids take less), which is charged for the call's duration. */
#define ENGINE_BYTES 16

static int engine_directed(ctx_t *c, const hd_points_t *P, const hd_points_t *Q, hd_result_t *e) {
    hd_options_t o;
    hd_options_init(&o);
    o.threads = c->threads;
    size_t bytes = ENGINE_BYTES * (P->count + Q->count);
    charge(c, bytes);
    int rc = hd_directed(P, Q, &o, e, &c->e);
    c->cur -= bytes;
    return rc;
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

/* Every MPI call is timed (thread CPU): what is left of the call's CPU
 * besides them and the searches is its bookkeeping (stats->other_cpu). */
#define MPI_TIMED(c, call) (mpi_t0_ = thread_cpu(), mpi_rc_ = (call), (c)->mpi_cpu += thread_cpu() - mpi_t0_, mpi_rc_)

#define MPI_TRY(c, call)                                                  \
    do {                                                                  \
        double mpi_t0_;                                                   \
        int mpi_rc_;                                                      \
        mpi_rc_ = MPI_TIMED(c, call);                                     \
        if (mpi_rc_ != MPI_SUCCESS) return mpi_failed(c, #call, mpi_rc_); \
    } while (0)

/* The same in a function that frees its buffers at `done`. */
#define MPI_GO(c, rc, call)                          \
    do {                                             \
        double mpi_t0_;                              \
        int mpi_rc_;                                 \
        mpi_rc_ = MPI_TIMED(c, call);                \
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
    double mpi_t0_;
    int mpi_rc_;
    if (MPI_TIMED(c, MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, c->comm)) != MPI_SUCCESS)
        return rc != HD_OK ? rc : hd__err(&c->e, HD_EIO, "MPI_Allreduce failed while agreeing on a status");
    if (first == c->K) return HD_OK;
    hd_error_t e = c->e;
    if (c->rank == first) {
        e.code = rc;
        snprintf(e.message, sizeof e.message, "rank %d: %.1000s", first, c->e.message);
    }
    if (MPI_TIMED(c, MPI_Bcast(&e, (int)sizeof e, MPI_BYTE, first, c->comm)) != MPI_SUCCESS)
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

/* The global indices of a local set, by position (local order is global
 * index order).  Not stored as 8-byte indices: each point keeps the 4-byte
 * number it came with (its rank among its sender's points of the set, in
 * index order), and since the senders' runs lie in the local array one
 * after the other, a position names its sender (start[]) and the sender's
 * index runs (ranges_t) turn the number into the index (gidx).  Where the
 * runs had to be merged (the senders' index ranges interleave), positions
 * no longer name senders and the indices are stored (g).  The arrays are
 * never reordered after the exchange (split/unsplit move coordinates
 * only), so position k's index is fixed for the call. */
typedef struct ranges ranges_t;
typedef struct {
    const uint64_t *g;       /* each position's index (runs merged), or NULL */
    const uint32_t *num;     /* else each position's number at its sender */
    const size_t *start;     /* K + 1: where each sender's run starts */
    const ranges_t *rg;
    int side, K;
} gidx_t;

static uint64_t gidx(const gidx_t *x, size_t k);

typedef struct {
    double *P;               /* local points asking, packed xyz (reordered
                                and restored by split/unsplit) */
    const gidx_t *gP;        /* their global indices, by position */
    size_t nP;
    double *Q;               /* local points searched */
    const gidx_t *gQ;
    size_t nQ;
    int qside;               /* 0: Q is A, 1: Q is B */
} dir_t;

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

/* The structures of the searched local set Q for per-point searches (the
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
 * proof is tried. */
typedef struct {
    hd__an_t s;
    int built;
    size_t n, bytes;
    uint32_t *map;           /* the slab's points in Q (NULL: all of Q) */
    double M;                /* its margin (infinite: all of Q) */
    hd__box_t kb;            /* the key box its askers use too */
} slab_t;

typedef struct {
    slab_t sub, full;
    double M0;               /* the first slab's margin (set by shell_of) */
} qtree_t;

/* The nearest layer's bound on a structure being built (hausdorff.h,
 * hd_distances: up to about 60 bytes a point), charged while it is. */
#define AN_BUILD_BYTES 60

static size_t an_bytes(const hd__an_t *s) {
    return (s->n + 4) * (3 * sizeof(double) + 0) + s->n * sizeof(uint32_t) + (s->nb + 1) * 4 * sizeof(uint32_t) +
           (s->ng + 1) * 2 * sizeof(uint32_t) + s->nn * (sizeof(uint32_t) + 1 + 6 * sizeof(double));
}

static int an_build(ctx_t *c, hd__an_t *s, const hd_points_t *v, const hd__box_t *kb, int threads, size_t *bytes) {
    size_t b = AN_BUILD_BYTES * v->count;
    charge(c, b);
    int rc = hd__an_build(s, v, NULL, kb, threads, &c->e);
    c->cur -= b;
    *bytes = rc == HD_OK ? an_bytes(s) : 0;
    charge(c, *bytes);
    return rc;
}

static void slab_free(ctx_t *c, slab_t *sl) {
    if (sl->built) {
        hd__an_free(&sl->s);
        c->cur -= sl->bytes;
    }
    cfree(c, sl->map, sl->n, sizeof(uint32_t));
    memset(sl, 0, sizeof *sl);
}

static void qtree_free(ctx_t *c, qtree_t *q) {
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
        sl->map = cmalloc(c, n, sizeof(uint32_t));
        xyz = cmalloc(c, n, 3 * sizeof(double));
        sl->n = n;
        if (!sl->map || !xyz) rc = nomem(c, "the searched slab", n);
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
        rc = an_build(c, &sl->s, &v, &sl->kb, hd__thread_count(c->threads, n), &sl->bytes);
        sl->built = 1; /* freed by slab_free whatever happened */
    }
    cfree(c, xyz, n, 3 * sizeof(double));
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
    double *xyz = cmalloc(c, m, 3 * sizeof(double));
    size_t *got = cmalloc(c, m, sizeof(size_t));
    int rc = HD_OK;
    if (!xyz || !got) rc = nomem(c, "the searches", m);
    for (size_t t = 0; t < m && rc == HD_OK; t++) memcpy(xyz + 3 * t, pts + 3 * list[t], 3 * sizeof(double));
    hd__an_t asking;
    size_t ab = 0;
    int threads = hd__thread_count(c->threads, m > sl->n ? m : sl->n);
    hd_points_t Sv = hd_points_f64(xyz, m);
    if (rc == HD_OK && (rc = an_build(c, &asking, &Sv, &sl->kb, threads, &ab)) == HD_OK)
        rc = hd__an_nearest(&asking, &sl->s, NULL, threads, NULL, got, NULL, &c->e);
    if (ab) {
        hd__an_free(&asking);
        c->cur -= ab;
    }
    for (size_t t = 0; t < m && rc == HD_OK; t++) near[list[t]] = sl->map ? sl->map[got[t]] : got[t];
    cfree(c, xyz, m, 3 * sizeof(double));
    cfree(c, got, m, sizeof(size_t));
    return rc;
}

/* At most this many points the slab did not prove are searched by brute
 * force (a handful, on a copy: points whose partner is on another rank)
 * rather than in a wider slab, which costs as much as a few hundred
 * thousand distances to build. */
#define BRUTE_MAX 16

/* For each of n packed points, the nearest point of Q (exact, smallest
 * index on ties, as hd_distances gives it). */
static int nearest_in_q(ctx_t *c, const dir_t *d, const hd__box_t *r, qtree_t *q, const double *pts, size_t n,
                        size_t *near) {
    if (n == 0) return HD_OK;
    if (n > HD__AN_MAX_POINTS || d->nQ > HD__AN_MAX_POINTS) { /* hd_distances' kd-trees */
        hd_points_t Sv = hd_points_f64(pts, n), Qv = hd_points_f64(d->Q, d->nQ);
        hd_options_t o;
        hd_options_init(&o);
        o.threads = c->threads;
        return hd_distances(&Sv, &Qv, &o, NULL, near, NULL, NULL, &c->e);
    }
    size_t *list = cmalloc(c, n, sizeof(size_t));
    if (!list) return nomem(c, "the searches", n);
    int rc = HD_OK;
    size_t m = n;
    for (size_t k = 0; k < n; k++) list[k] = k;
    /* the slab, a wider one for what it did not prove, then all of Q */
    for (int level = 0; level < 3 && m > 0 && rc == HD_OK; level++) {
        slab_t *sl = level == 2 ? &q->full : &q->sub;
        double M = level == 2 ? INFINITY : q->M0;
        if (level == 1 && m <= BRUTE_MAX) { /* a few: every point of Q, in index order */
            for (size_t t = 0; t < m; t++) {
                const double *x = pts + 3 * list[t];
                double best = INFINITY;
                size_t at = SIZE_MAX;
                for (size_t j = 0; j < d->nQ; j++) {
                    double d2 = hd__d2(x, d->Q + 3 * j);
                    if (d2 < best) best = d2, at = j;
                }
                near[list[t]] = at;
            }
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
    cfree(c, list, n, sizeof(size_t));
    return rc;
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
    size_t n;
    size_t *nearest;         /* each one's nearest in Q (NULL if Q is empty) */
    double *own_xyz;         /* what was allocated for a proper subset */
    uint32_t *own_pos;       /* ... with each one's position in P */
    far_t inner;             /* exact over the interior; d2 = -1 if none
                                or not known (lazy) */
    int lazy;                /* the interior's maximum was not computed */
    far_t h;                 /* then: the engine's answer, whose witness
                                is in the shell and bounds the interior */
} shell_t;

static void shell_free(ctx_t *c, shell_t *sh) {
    cfree(c, sh->own_xyz, sh->n, 3 * sizeof(double));
    cfree(c, sh->own_pos, sh->n, sizeof(uint32_t));
    cfree(c, sh->nearest, sh->n, sizeof(size_t));
}

/* Stable partition in place of the coordinates (the indices stay by
 * position): the points k with keep[k] to the front, in order, the others
 * to aside (in order; NULL: the caller has them already).  unsplit puts
 * everything back. */
static void split(double *xyz, size_t n, const unsigned char *keep, double *axyz) {
    size_t t = 0, a = 0;
    for (size_t k = 0; k < n; k++) {
        if (keep[k]) {
            if (t != k) memcpy(xyz + 3 * t, xyz + 3 * k, 3 * sizeof(double));
            t++;
        } else if (axyz) {
            memcpy(axyz + 3 * a++, xyz + 3 * k, 3 * sizeof(double));
        }
    }
}

/* The position of the m-th point k (from 0) with keep[k]. */
static size_t kept_at(const unsigned char *keep, size_t n, size_t m) {
    for (size_t k = 0, t = 0; k < n; k++)
        if (keep[k] && t++ == m) return k;
    assert(0);
    return 0;
}

static void unsplit(double *xyz, size_t n, const unsigned char *keep, const double *axyz) {
    size_t t = 0, a = 0;
    for (size_t k = 0; k < n; k++) t += keep[k] != 0;
    a = n - t;
    for (size_t k = n; k-- > 0;) {
        if (keep[k]) {
            --t;
            if (t != k) memcpy(xyz + 3 * k, xyz + 3 * t, 3 * sizeof(double));
        } else {
            --a;
            memcpy(xyz + 3 * k, axyz + 3 * a, 3 * sizeof(double));
        }
    }
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
static int paired_pass(ctx_t *c, const dir_t *d, const hd__box_t *mine, unsigned char **inp, size_t *nI,
                       far_t *inner, int *done) {
    size_t nP = d->nP, nQ = d->nQ, nc = 0;
    *done = 0;
    *inp = NULL;
    for (size_t i = 0, j = 0; i < nP && j < nQ;) {
        uint64_t gi = gidx(d->gP, i), gj = gidx(d->gQ, j);
        if (gi == gj) nc++, i++, j++;
        else if (gi < gj) i++;
        else j++;
    }
    if (nc < 64 || nc < nP - nP / 10 || (nc == nP && nc == nQ)) return HD_OK; /* whole sets: the engine's own */
    /* The pairs to the front of P and Q, in order; the others aside. */
    size_t nx = nQ - nc, ny = nP - nc;
    unsigned char *in = *inp = cmalloc(c, nP, 1), *inq = cmalloc(c, nQ, 1);
    double *qx = cmalloc(c, nx, 3 * sizeof(double)), *py = cmalloc(c, ny, 3 * sizeof(double));
    int rc = HD_OK;
    if (!in || !inq || !qx || !py) {
        rc = nomem(c, "the pairs", nc);
        goto done;
    }
    memset(in, 0, nP);
    memset(inq, 0, nQ);
    for (size_t i = 0, j = 0; i < nP && j < nQ;) {
        uint64_t gi = gidx(d->gP, i), gj = gidx(d->gQ, j);
        if (gi == gj) in[i++] = inq[j++] = 1;
        else if (gi < gj) i++;
        else j++;
    }
    split(d->P, nP, in, py);
    split(d->Q, nQ, inq, qx);
    hd_result_t e;
    hd_points_t Pv = hd_points_f64(d->P, nc), Qv = hd_points_f64(d->Q, nc);
    rc = engine_directed(c, &Pv, &Qv, &e);
    unsplit(d->P, nP, in, py);
    unsplit(d->Q, nQ, inq, qx);
    if (rc == HD_OK) {
        /* a*, and Q_c's e.j: P_c's e.j's partner (the same index) */
        size_t astar = kept_at(in, nP, e.i);
        uint64_t gi = gidx(d->gP, astar), jc = gidx(d->gP, kept_at(in, nP, e.j));
        *nI = 0;
        for (size_t i = 0; i < nP; i++)
            *nI += in[i] = (unsigned char)(in[i] && faces_clear(mine, d->P + 3 * i, e.distance2));
        /* The nearest point of Q_x to a* (position order is index order:
         * the first at the minimum is the smallest index). */
        double v = INFINITY;
        size_t jx = SIZE_MAX;
        for (size_t j = 0; j < nQ && in[astar]; j++) {
            if (inq[j]) continue;
            double d2 = hd__d2(d->P + 3 * astar, d->Q + 3 * j);
            if (d2 < v) v = d2, jx = j;
        }
        uint64_t jv = jx == SIZE_MAX ? UINT64_MAX : gidx(d->gQ, jx);
        if (in[astar] && v >= e.distance2) {
            *inner = (far_t){e.distance2, gi, v == e.distance2 && jv < jc ? jv : jc};
            *done = 1;
        }
    }
done:
    cfree(c, inq, nQ, 1);
    cfree(c, qx, nx, 3 * sizeof(double));
    cfree(c, py, ny, 3 * sizeof(double));
    return rc;
}

/* The exact maximum over the interior, the points whose faces are clear
 * of h2 (their local u is global): the engine on a copy of them. */
static int interior_max(ctx_t *c, const dir_t *d, const hd__box_t *mine, const shell_t *sh, double h2, far_t *out) {
    unsigned char *in = cmalloc(c, d->nP, 1);
    if (!in) return nomem(c, "the interior", d->nP);
    size_t nI = 0;
    for (size_t k = 0; k < d->nP; k++) nI += in[k] = (unsigned char)faces_clear(mine, d->P + 3 * k, h2);
    assert(nI + sh->n == d->nP && sh->own_xyz);
    split(d->P, d->nP, in, NULL); /* the shell's copy is the aside */
    hd_points_t Iv = hd_points_f64(d->P, nI), Qv = hd_points_f64(d->Q, d->nQ);
    hd_result_t e;
    int rc = engine_directed(c, &Iv, &Qv, &e);
    unsplit(d->P, d->nP, in, sh->own_xyz);
    if (rc == HD_OK) *out = (far_t){e.distance2, gidx(d->gP, kept_at(in, d->nP, e.i)), gidx(d->gQ, e.j)};
    cfree(c, in, d->nP, 1);
    return rc;
}

/* The global index of the shell's point k. */
static uint64_t shell_g(const dir_t *d, const shell_t *sh, size_t k) {
    return gidx(d->gP, sh->own_pos ? sh->own_pos[k] : k);
}

static int shell_of(ctx_t *c, const dir_t *d, const hd__box_t *mine, qtree_t *q, shell_t *sh) {
    memset(sh, 0, sizeof *sh);
    sh->inner = (far_t){-1.0, UINT64_MAX, UINT64_MAX};
    sh->xyz = d->P;
    sh->n = d->nP;
    if (d->nP == 0 || d->nQ == 0) return HD_OK;
    hd_points_t Pv = hd_points_f64(d->P, d->nP), Qv = hd_points_f64(d->Q, d->nQ);
    hd_result_t e;
    unsigned char *in = NULL; /* allocated after the engine's pass, the peak */
    size_t nI = 0;
    int done = 0;
    int rc = paired_pass(c, d, mine, &in, &nI, &sh->inner, &done);
    if (rc == HD_OK && !done && (rc = engine_directed(c, &Pv, &Qv, &e)) == HD_OK) {
        if (!in && !(in = cmalloc(c, d->nP, 1))) rc = nomem(c, "the interior", d->nP);
        nI = 0;
        for (size_t k = 0; k < d->nP && rc == HD_OK; k++)
            nI += in[k] = (unsigned char)faces_clear(mine, d->P + 3 * k, e.distance2);
    }
    if (rc != HD_OK) {
        cfree(c, in, d->nP, 1);
        return rc;
    }
    size_t nS = d->nP - nI;
    /* The shell's points have u <= sqrt(h2) (those of the paired pass's
     * interior, h_c) and lie within it of a face, so their nearest points
     * lie within about 2 sqrt(h2) of one: the slab's margin. */
    q->M0 = 2.5 * sqrt(done ? sh->inner.d2 : e.distance2);
    if (done) {
        /* the interior's answer is the paired pass's */
    } else if (nI && in[e.i]) {
        sh->inner = (far_t){e.distance2, gidx(d->gP, e.i), gidx(d->gQ, e.j)};
    } else if (nI) {
        sh->lazy = 1; /* interior_max, only if it can matter */
        sh->h = (far_t){e.distance2, gidx(d->gP, e.i), gidx(d->gQ, e.j)};
    }
    if (rc == HD_OK && nS && nI) { /* a proper subset: copied */
        sh->n = nS;
        sh->own_xyz = cmalloc(c, nS, 3 * sizeof(double));
        sh->own_pos = cmalloc(c, nS, sizeof(uint32_t));
        if (!sh->own_xyz || !sh->own_pos) rc = nomem(c, "the shell", nS);
        for (size_t k = 0, t = 0; k < d->nP && rc == HD_OK; k++)
            if (!in[k]) {
                memcpy(sh->own_xyz + 3 * t, d->P + 3 * k, 3 * sizeof(double));
                sh->own_pos[t++] = (uint32_t)k;
            }
        sh->xyz = sh->own_xyz;
    }
    sh->n = nS;
    cfree(c, in, d->nP, 1);
    if (rc == HD_OK && nS) {
        sh->nearest = cmalloc(c, nS, sizeof(size_t));
        if (!sh->nearest) return nomem(c, "nearest neighbours", nS);
        rc = nearest_in_q(c, d, mine, q, sh->xyz, nS, sh->nearest);
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
static int answer(ctx_t *c, const dir_t *d, const hd__box_t *mine, qtree_t *q, const double *pts, size_t m,
                  ans_t *ans) {
    if (m == 0) return HD_OK;
    if (d->nQ == 0) {
        for (size_t k = 0; k < m; k++) ans[k] = (ans_t){INFINITY, UINT64_MAX};
        return HD_OK;
    }
    size_t *near = cmalloc(c, m, sizeof(size_t));
    if (!near) return nomem(c, "answers", m);
    int rc = nearest_in_q(c, d, mine, q, pts, m, near);
    if (rc == HD_OK)
        for (size_t k = 0; k < m; k++)
            ans[k] = (ans_t){hd__d2(pts + 3 * k, d->Q + 3 * near[k]), gidx(d->gQ, near[k])};
    cfree(c, near, m, sizeof(size_t));
    return rc;
}

static int direction(ctx_t *c, const dir_t *d, const node_t *tree, const hd__box_t *region,
                     const held_t *held, far_t *result) {
    int K = c->K, rc = HD_OK;
    const hd__box_t *mine = &region[c->rank];
    shell_t sh;
    qtree_t q;
    memset(&q, 0, sizeof q);
    double t0 = hd__now(), u0 = thread_cpu();
    rc = shell_of(c, d, mine, &q, &sh);
    c->search += hd__now() - t0;
    c->search_cpu += thread_cpu() - u0;
    c->shell += sh.n;
    size_t nP = sh.n, np = 0, cap = 0;
    const double *P = sh.xyz;
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
            jj[k] = gidx(d->gQ, sh.nearest[k]);
            exact[k] = (unsigned char)faces_clear(mine, p, u2[k]);
            far_t f = {u2[k], shell_g(d, &sh, k), jj[k]};
            if (exact[k] && far_better(&f, &Lmine)) Lmine = f;
        }
        if (K > 1) node_boxes(tree, 0, held, d->qside, nbox);
    }
    /* What the searches and the forwarding held, freed before the
     * interior's engine call (and on failure). */
#define DIRECTION_FREE()                               \
    do {                                               \
        cfree(c, u2, nP, sizeof(double));              \
        cfree(c, jj, nP, sizeof(uint64_t));            \
        cfree(c, exact, nP, 1);                        \
        cfree(c, nbox, K > 1 ? (size_t)K - 1 : 1, sizeof(hd__box_t)); \
        cfree(c, list, (size_t)K, sizeof(int));        \
        cfree(c, cnt, 4 * (size_t)K, sizeof(int));     \
        cfree(c, pairs, cap, sizeof(pair_t));          \
        cfree(c, sendq, np, 3 * sizeof(double));       \
        cfree(c, order, np, sizeof(size_t));           \
        cfree(c, recvq, m, 3 * sizeof(double));        \
        cfree(c, ans, m, sizeof(ans_t));               \
        cfree(c, back, np, sizeof(ans_t));             \
        u2 = NULL, jj = NULL, exact = NULL, nbox = NULL, list = NULL, cnt = NULL, pairs = NULL; \
        sendq = NULL, order = NULL, recvq = NULL, ans = NULL, back = NULL; \
        cfree(c, sh.nearest, sh.n, sizeof(size_t));    \
        sh.nearest = NULL;                             \
        qtree_free(c, &q);                             \
    } while (0)
    if ((rc = agree(c, rc)) != HD_OK) goto done;
    /* L and the smallest index i_L of a confirmed point at L: a point
     * with u2 < L, or u2 = L and a larger index, cannot be the witness. */
    MPI_GO(c, rc, MPI_Allreduce(&Lmine, &Lall, 1, c->far_type, c->far_op, c->comm));
    double L = Lall.d2;
    uint64_t iL = Lall.i;
    /* The points to forward, as (point, rank) pairs. */
    for (size_t k = 0; k < nP && rc == HD_OK; k++) {
        if (exact[k] || u2[k] < L || (u2[k] == L && shell_g(d, &sh, k) > iL)) continue;
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
    rc = answer(c, d, mine, &q, recvq, m, ans);
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
        if (u2[k] < L || (u2[k] == L && shell_g(d, &sh, k) > iL)) continue;
        far_t f = {u2[k], shell_g(d, &sh, k), jj[k]};
        if (far_better(&f, &best)) best = f;
    }
    /* The interior's maximum, when not known, is needed only where the
     * engine's answer (h2, a*), a* in the shell, beats the best known
     * over all ranks: every interior point is below (h2, a*) (u <= h2,
     * and a* is the smallest index at h2), so it cannot beat what (h2, a*)
     * does not. */
    DIRECTION_FREE();
    far_t G;
    MPI_GO(c, rc, MPI_Allreduce(&best, &G, 1, c->far_type, c->far_op, c->comm));
    if (sh.lazy && far_better(&sh.h, &G)) {
        far_t I = {-1.0, UINT64_MAX, UINT64_MAX};
        double t1 = hd__now(), u1 = thread_cpu();
        rc = interior_max(c, d, mine, &sh, sh.h.d2, &I);
        c->search += hd__now() - t1;
        c->search_cpu += thread_cpu() - u1;
        c->interior_passes++;
        if (far_better(&I, &best)) best = I;
    }
    if ((rc = agree(c, rc)) != HD_OK) goto done;
    MPI_GO(c, rc, MPI_Allreduce(&best, result, 1, c->far_type, c->far_op, c->comm));
done:
    DIRECTION_FREE();
    shell_free(c, &sh);
    return rc;
#undef DIRECTION_FREE
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

static int by_owner(const void *x, const void *y) {
    const range_t *p = x, *q = y;
    if (p->side != q->side) return p->side - q->side;
    if (p->rank != q->rank) return p->rank - q->rank;
    return p->lo < q->lo ? -1 : p->lo > q->lo;
}

/* Every rank's nonempty parts (all-gathered by check_ranges), sorted by
 * (side, rank, first index): side s, rank r's are all[seg[s (K + 1) + r]]
 * up to all[seg[s (K + 1) + r + 1]], and first[i] is the number of part
 * i's first point among its rank's points of its side in index order.  So
 * point number m of rank r's side s names a global index (ranges_globals),
 * which lets the exchange send 4-byte numbers instead of 8-byte indices,
 * and the local arrays keep them (gidx_t): held for the whole call. */
struct ranges {
    int K;
    range_t *all;
    size_t total;
    size_t *seg;
    uint64_t *first;
};

static void ranges_free(ctx_t *c, ranges_t *rg) {
    cfree(c, rg->all, rg->total, sizeof(range_t));
    if (rg->seg) cfree(c, rg->seg, 2 * ((size_t)rg->K + 1), sizeof(size_t));
    cfree(c, rg->first, rg->total, sizeof(uint64_t));
    rg->all = NULL, rg->seg = NULL, rg->first = NULL;
}

/* g[k] = the global index of point number num[k] of rank r's side s, for
 * num[] increasing. */
static void ranges_globals(const ranges_t *rg, int s, int r, const uint32_t *num, size_t n, uint64_t *g) {
    size_t i = rg->seg[(size_t)s * ((size_t)rg->K + 1) + (size_t)r];
    for (size_t k = 0; k < n; k++) {
        while (num[k] - rg->first[i] > rg->all[i].hi - rg->all[i].lo) i++;
        assert(i < rg->seg[(size_t)s * ((size_t)rg->K + 1) + (size_t)r + 1] && num[k] >= rg->first[i]);
        g[k] = rg->all[i].lo + (num[k] - rg->first[i]);
    }
}

/* The global index of point number m (any) of rank r's side s. */
static uint64_t ranges_global(const ranges_t *rg, int s, int r, uint64_t m) {
    size_t lo = rg->seg[(size_t)s * ((size_t)rg->K + 1) + (size_t)r],
           hi = rg->seg[(size_t)s * ((size_t)rg->K + 1) + (size_t)r + 1] - 1;
    while (lo < hi) { /* the last part whose first number is <= m */
        size_t mid = lo + (hi - lo + 1) / 2;
        if (rg->first[mid] <= m) lo = mid;
        else hi = mid - 1;
    }
    return rg->all[lo].lo + (m - rg->first[lo]);
}

static uint64_t gidx(const gidx_t *x, size_t k) {
    if (x->g) return x->g[k];
    int lo = 0, hi = x->K - 1;
    while (lo < hi) { /* the last sender whose run starts at or before k */
        int mid = lo + (hi - lo + 1) / 2;
        if (x->start[mid] <= k) lo = mid;
        else hi = mid - 1;
    }
    assert(k >= x->start[lo] && k < x->start[lo + 1]);
    return ranges_global(x->rg, x->side, lo, x->num[k]);
}

/* Over all ranks, no two parts of one set share an index; rg receives
 * every rank's parts. */
static int check_ranges(ctx_t *c, const input_t *in, ranges_t *rg) {
    int n = 0, rc = HD_OK, K = c->K;
    for (int s = 0; s < 2; s++)
        for (size_t k = 0; k < in->nparts[s]; k++) n += in->parts[s][k].points.count > 0;
    int *counts = cmalloc(c, 2 * (size_t)K, sizeof(int));
    rg->K = K;
    rg->seg = cmalloc(c, 2 * ((size_t)K + 1), sizeof(size_t));
    if (!counts || !rg->seg) rc = nomem(c, "index ranges", (size_t)K);
    if ((rc = agree(c, rc)) != HD_OK) goto done;
    MPI_GO(c, rc, MPI_Allgather(&n, 1, MPI_INT, counts, 1, MPI_INT, c->comm));
    size_t total = 0;
    int *displ = counts + K;
    for (int r = 0; r < K; r++) {
        displ[r] = (int)(total * sizeof(range_t));
        total += (size_t)counts[r];
        counts[r] *= (int)sizeof(range_t);
    }
    range_t *mine = cmalloc(c, (size_t)n, sizeof(range_t));
    rg->all = cmalloc(c, total, sizeof(range_t));
    rg->first = cmalloc(c, total, sizeof(uint64_t));
    rg->total = total;
    if (!mine || !rg->all || !rg->first || total * sizeof(range_t) > INT_MAX) rc = nomem(c, "index ranges", total);
    if ((rc = agree(c, rc)) == HD_OK) {
        int t = 0;
        for (int s = 0; s < 2; s++)
            for (size_t k = 0; k < in->nparts[s]; k++) {
                const hd_mpi_part_t *p = &in->parts[s][k];
                if (p->points.count)
                    mine[t++] = (range_t){p->offset, p->offset + (p->points.count - 1), s, c->rank};
            }
        double mpi_t0_;
        int mpi_rc_,
            e = MPI_TIMED(c, MPI_Allgatherv(mine, n * (int)sizeof(range_t), MPI_BYTE, rg->all, counts, displ,
                                            MPI_BYTE, c->comm));
        if (e != MPI_SUCCESS) rc = mpi_failed(c, "MPI_Allgatherv", e);
    }
    cfree(c, mine, (size_t)n, sizeof(range_t));
    if (rc == HD_OK) {
        range_t *all = rg->all;
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
    if (rc == HD_OK) {
        qsort(rg->all, total, sizeof(range_t), by_owner);
        size_t k = 0;
        for (int s = 0; s < 2; s++)
            for (int r = 0; r <= K; r++) {
                while (k < total && (rg->all[k].side < s || (rg->all[k].side == s && rg->all[k].rank < r))) k++;
                rg->seg[(size_t)s * ((size_t)K + 1) + (size_t)r] = k;
            }
        for (size_t i = 0; i < total; i++) {
            int same = i > 0 && rg->all[i].side == rg->all[i - 1].side && rg->all[i].rank == rg->all[i - 1].rank;
            rg->first[i] = same ? rg->first[i - 1] + (rg->all[i - 1].hi - rg->all[i - 1].lo + 1) : 0;
        }
    }
done:
    cfree(c, counts, 2 * (size_t)K, sizeof(int));
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
        double mpi_t0_;
        int mpi_rc_,
            e = MPI_TIMED(c, MPI_Gatherv(mine, n, c->sample_type, all, counts, counts + K, c->sample_type, 0, c->comm));
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

/* Merge order of K runs of g[] sorted by index: perm[o] is the position of
 * the o-th smallest index (the runs are [at, end) ranges of positions). */
typedef struct { size_t at, end; } run_t;

static void merge_order(const uint64_t *g, run_t *runs, int K, int *heap, uint32_t *perm) {
    int n = 0;
    for (int r = 0; r < K; r++) {
        if (runs[r].at == runs[r].end) continue;
        int k = n++; /* sift up */
        while (k > 0 && g[runs[heap[(k - 1) / 2]].at] > g[runs[r].at]) {
            heap[k] = heap[(k - 1) / 2];
            k = (k - 1) / 2;
        }
        heap[k] = r;
    }
    size_t out = 0;
    while (n > 0) {
        run_t *top = &runs[heap[0]];
        perm[out++] = (uint32_t)top->at;
        int r = heap[0];
        if (++top->at == top->end) r = heap[--n];
        int k = 0; /* sift r down from the root */
        for (;;) {
            int ch = 2 * k + 1;
            if (ch >= n) break;
            if (ch + 1 < n && g[runs[heap[ch + 1]].at] < g[runs[heap[ch]].at]) ch++;
            if (g[runs[heap[ch]].at] >= g[runs[r].at]) break;
            heap[k] = heap[ch];
            k = ch;
        }
        if (n > 0) heap[k] = r;
    }
}

/* xyz[o], g[o] = old xyz[perm[o]], g[perm[o]] for every o, in place: each
 * cycle of the permutation is followed once, and perm[o] = o marks o
 * done (perm is destroyed). */
static void permute(double *xyz, uint64_t *g, uint32_t *perm, size_t n) {
    for (size_t i = 0; i < n; i++) {
        if (perm[i] == i) continue;
        double t[3];
        memcpy(t, xyz + 3 * i, sizeof t);
        uint64_t tg = g[i];
        size_t j = i;
        for (;;) {
            size_t k = perm[j];
            perm[j] = (uint32_t)j;
            if (k == i) {
                memcpy(xyz + 3 * j, t, sizeof t);
                g[j] = tg;
                break;
            }
            memcpy(xyz + 3 * j, xyz + 3 * k, sizeof t);
            g[j] = g[k];
            j = k;
        }
    }
}

typedef struct {
    double *xyz[2];
    uint64_t *g[2];          /* the indices, where the runs were merged */
    uint32_t *num[2];        /* else the senders' numbers (gidx_t) */
    size_t *start[2];        /* K + 1 a side: each sender's run */
    size_t n[2];
} local_t;

/* Where point t of the local input goes: one byte a point up to 256 ranks,
 * two up to 65536. */
static inline int dest_get(const void *d, int w, size_t t) {
    return w == 1 ? ((const uint8_t *)d)[t] : w == 2 ? ((const uint16_t *)d)[t] : (int)((const uint32_t *)d)[t];
}

static inline void dest_set(void *d, int w, size_t t, int r) {
    if (w == 1) ((uint8_t *)d)[t] = (uint8_t)r;
    else if (w == 2) ((uint16_t *)d)[t] = (uint16_t)r;
    else ((uint32_t *)d)[t] = (uint32_t)r;
}

/* A position in the local input: side, part (in offset order), point in
 * it, point t overall, and the point's local number in its side. */
typedef struct { int s; size_t p, k, t; uint64_t num[2]; } walk_t;

static int walk_next(const input_t *in, const hd_mpi_part_t **order[2], walk_t *w) {
    while (w->s < 2) {
        if (w->p < in->nparts[w->s] && w->k < order[w->s][w->p]->points.count) return 1;
        if (w->p < in->nparts[w->s]) w->p++, w->k = 0;
        else w->s++, w->p = 0, w->k = 0;
    }
    return 0;
}

static void walk_step(walk_t *w) {
    w->k++;
    w->t++;
    w->num[w->s]++;
}

/* Points sent per round by a rank: an eighth of its points (at least 64K),
 * so the send buffer is at most 28/8 = 3.5 bytes a point (the minimum
 * also makes the tests' larger sets take several rounds). */
#define ROUND_SHARE 8
#define ROUND_MIN 4096

/* Move every point to the rank of its region.  Each point goes as its
 * coordinates and a 4-byte number: its rank among the sender's points of
 * its set in index order (ranges_t turns it back into the global index).
 * Each source's run is received straight into its slot of the local
 * arrays, in rounds of at most an eighth of the sender's points, so no
 * copy of all the points is ever held twice; a rank's own points are
 * copied from the input into their slot.  Runs are in index order, since
 * senders walk their parts in offset order; when the runs follow each
 * other in index order too (each rank's parts lie above the previous
 * rank's) the local arrays are in global order as received and the
 * numbers stay (loc->num, loc->start: gidx_t), else they become indices
 * (loc->g) and the arrays are merged in place (a permutation from a K-way
 * merge, 4 bytes a point). */
static int exchange(ctx_t *c, const input_t *in, const ranges_t *rg, const node_t *tree, local_t *loc) {
    int K = c->K, me = c->rank, rc = HD_OK, w = K <= 256 ? 1 : K <= 65536 ? 2 : 4;
    size_t nloc = (size_t)(in->n[0] + in->n[1]), C = nloc / ROUND_SHARE, sendcap = 0;
    if (C < ROUND_MIN) C = ROUND_MIN;
    /* ints per rank: totals sent tot[2] and received rtot[2]; this round's
     * per[2] and rper[2]; where each (rank, side) block of the send buffer
     * starts, sdisp[2], and a cursor in it, sfill[2]; one side's counts and
     * displacements for MPI: sc sd rcn rd */
    int *cnt = cmalloc(c, 16 * (size_t)K, sizeof(int));
    size_t *base = cmalloc(c, 4 * (size_t)K, sizeof(size_t)); /* base[s K + r], then got[s K + r] */
    void *dest = cmalloc(c, nloc, (size_t)w);
    const hd_mpi_part_t **order[2] = {NULL, NULL};
    uint32_t *off[2] = {NULL, NULL};
    double *sx = NULL;
    uint32_t *so = NULL;
    uint32_t *perm = NULL;
    size_t permn = 0;
    run_t *runs = NULL;
    int *heap = NULL;
    for (int s = 0; s < 2; s++) order[s] = cmalloc(c, in->nparts[s], sizeof *order[s]);
    if (!cnt || !base || !dest || !order[0] || !order[1]) rc = nomem(c, "the exchange", nloc);
    int *tot = cnt, *rtot = cnt + 2 * K, *per = cnt + 4 * K, *rper = cnt + 6 * K, *sdisp = cnt + 8 * K,
        *sfill = cnt + 10 * K, *sc = cnt + 12 * K, *sd = cnt + 13 * K, *rcn = cnt + 14 * K, *rd = cnt + 15 * K;
    size_t *got = base + 2 * K, own = 0;
    if (rc == HD_OK) {
        memset(tot, 0, 2 * (size_t)K * sizeof(int));
        size_t t = 0;
        for (int s = 0; s < 2; s++) {
            for (size_t p = 0; p < in->nparts[s]; p++) order[s][p] = &in->parts[s][p];
            qsort(order[s], in->nparts[s], sizeof *order[s], by_offset);
            for (size_t p = 0; p < in->nparts[s]; p++)
                for (size_t k = 0; k < order[s][p]->points.count; k++) {
                    double x[3];
                    get_point(&order[s][p]->points, k, x);
                    int r = rank_of(tree, K, x, (uint64_t)s, order[s][p]->offset + k);
                    dest_set(dest, w, t++, r);
                    if (tot[2 * r + s] == INT_MAX) rc = HD_EOVERFLOW;
                    else tot[2 * r + s]++;
                }
        }
        if (rc != HD_OK)
            rc = hd__err(&c->e, HD_EOVERFLOW, "more than 2^31 - 1 points of a set to send from rank %d to one rank",
                         c->rank);
        own = (size_t)tot[2 * me] + (size_t)tot[2 * me + 1];
        sendcap = nloc - own < C ? nloc - own : C;
        for (int r = 0; r < K; r++)
            if (r != me) c->bytes_part += ((uint64_t)tot[2 * r] + (uint64_t)tot[2 * r + 1]) * (3 * sizeof(double) + 4);
    }
    if ((rc = agree(c, rc)) != HD_OK) goto done;
    MPI_GO(c, rc, MPI_Alltoall(tot, 2, MPI_INT, rtot, 2, MPI_INT, c->comm));
    for (int s = 0; s < 2 && rc == HD_OK; s++) {
        size_t m = 0;
        for (int r = 0; r < K; r++) {
            base[s * K + r] = m;
            got[s * K + r] = 0;
            m += (size_t)rtot[2 * r + s];
        }
        loc->n[s] = m;
        if (m > INT_MAX) {
            rc = hd__err(&c->e, HD_EOVERFLOW, "more than 2^31 - 1 points of %s to receive on rank %d",
                         s ? "B" : "A", c->rank);
            loc->n[0] = loc->n[1] = 0;
        }
    }
    for (int s = 0; s < 2 && rc == HD_OK; s++) {
        loc->xyz[s] = cmalloc(c, loc->n[s], 3 * sizeof(double));
        off[s] = cmalloc(c, loc->n[s], sizeof(uint32_t));
        if (!loc->xyz[s] || !off[s]) rc = nomem(c, "the local points", loc->n[s]);
    }
    if (rc == HD_OK) {
        sx = cmalloc(c, sendcap, 3 * sizeof(double));
        so = cmalloc(c, sendcap, sizeof(uint32_t));
        if (!sx || !so) rc = nomem(c, "points to send", sendcap);
    }
    if ((rc = agree(c, rc)) != HD_OK) goto done;
    uint64_t mine = (nloc - own + C - 1) / C, rounds = 0;
    MPI_GO(c, rc, MPI_Allreduce(&mine, &rounds, 1, MPI_UINT64_T, MPI_MAX, c->comm));
    if (rounds == 0) rounds = 1; /* a round copies the own points too */
    walk_t at = {0, 0, 0, 0, {0, 0}};
    size_t ownat[2] = {base[me], base[K + me]};
    for (uint64_t round = 0; round < rounds; round++) {
        /* The window: from `at` up to the C-th point for another rank. */
        memset(per, 0, 2 * (size_t)K * sizeof(int));
        walk_t end = at;
        size_t out = 0;
        while (walk_next(in, order, &end)) {
            int r = dest_get(dest, w, end.t);
            if (r != me) {
                if (out == C) break;
                per[2 * r + end.s]++, out++;
            }
            walk_step(&end);
        }
        int pos = 0; /* the send buffer: A's blocks by rank, then B's */
        for (int s = 0; s < 2; s++)
            for (int r = 0; r < K; r++) {
                sdisp[2 * r + s] = sfill[2 * r + s] = pos;
                pos += per[2 * r + s];
            }
        while (at.t < end.t && walk_next(in, order, &at)) {
            int r = dest_get(dest, w, at.t), s = at.s;
            size_t to;
            double *x;
            if (r == me) {
                to = ownat[s]++;
                x = loc->xyz[s] + 3 * to;
                off[s][to] = (uint32_t)at.num[s];
            } else {
                to = (size_t)sfill[2 * r + s]++;
                x = sx + 3 * to;
                so[to] = (uint32_t)at.num[s];
            }
            get_point(&order[s][at.p]->points, at.k, x);
            walk_step(&at);
        }
        MPI_GO(c, rc, MPI_Alltoall(per, 2, MPI_INT, rper, 2, MPI_INT, c->comm));
        for (int s = 0; s < 2; s++) {
            for (int r = 0; r < K; r++) {
                sc[r] = per[2 * r + s];
                sd[r] = sdisp[2 * r + s];
                rcn[r] = rper[2 * r + s];
                rd[r] = (int)(base[s * K + r] + got[s * K + r]);
                got[s * K + r] += (size_t)rcn[r];
            }
            MPI_GO(c, rc, MPI_Alltoallv(sx, sc, sd, c->q_type, loc->xyz[s], rcn, rd, c->q_type, c->comm));
            MPI_GO(c, rc, MPI_Alltoallv(so, sc, sd, MPI_UINT32_T, off[s], rcn, rd, MPI_UINT32_T, c->comm));
        }
    }
    cfree(c, sx, sendcap, 3 * sizeof(double));
    cfree(c, so, sendcap, sizeof(uint32_t));
    cfree(c, dest, nloc, (size_t)w);
    sx = NULL, so = NULL, dest = NULL;
    assert(ownat[0] == base[me] + (size_t)rtot[2 * me] && ownat[1] == base[K + me] + (size_t)rtot[2 * me + 1]);
    /* The runs in index order as received (each rank's parts above the
     * previous rank's): the numbers stay and name the indices (gidx_t,
     * 4 bytes a point).  Else the numbers become indices (8 bytes) and
     * the runs are merged into index order. */
    for (int s = 0; s < 2 && rc == HD_OK; s++) {
        loc->start[s] = cmalloc(c, (size_t)K + 1, sizeof(size_t));
        if (!loc->start[s]) {
            rc = nomem(c, "the local indices", (size_t)K);
            break;
        }
        int sorted = 1;
        uint64_t last = 0;
        for (int r = 0; r < K; r++) {
            size_t lo = base[s * K + r], hi = lo + (size_t)rtot[2 * r + s];
            loc->start[s][r] = lo;
            if (hi > lo) {
                if (lo > 0 && ranges_global(rg, s, r, off[s][lo]) < last) sorted = 0;
                last = ranges_global(rg, s, r, off[s][hi - 1]);
            }
        }
        loc->start[s][K] = loc->n[s];
        if (sorted) {
            loc->num[s] = off[s];
            off[s] = NULL;
            continue;
        }
        loc->g[s] = cmalloc(c, loc->n[s], sizeof(uint64_t));
        if (!loc->g[s]) {
            rc = nomem(c, "the local indices", loc->n[s]);
            break;
        }
        for (int r = 0; r < K; r++) {
            size_t lo = base[s * K + r], hi = lo + (size_t)rtot[2 * r + s];
            ranges_globals(rg, s, r, off[s] + lo, hi - lo, loc->g[s] + lo);
        }
        cfree(c, off[s], loc->n[s], sizeof(uint32_t));
        off[s] = NULL;
        permn = loc->n[s];
        perm = cmalloc(c, permn, sizeof(uint32_t));
        runs = cmalloc(c, (size_t)K, sizeof(run_t));
        heap = cmalloc(c, (size_t)K, sizeof(int));
        if (!perm || !runs || !heap) {
            rc = nomem(c, "the merge", loc->n[s]);
            break;
        }
        for (int r = 0; r < K; r++) runs[r] = (run_t){base[s * K + r], base[s * K + r] + (size_t)rtot[2 * r + s]};
        merge_order(loc->g[s], runs, K, heap, perm);
        permute(loc->xyz[s], loc->g[s], perm, loc->n[s]);
        cfree(c, perm, permn, sizeof(uint32_t));
        cfree(c, runs, (size_t)K, sizeof(run_t));
        cfree(c, heap, (size_t)K, sizeof(int));
        perm = NULL, runs = NULL, heap = NULL;
    }
    rc = agree(c, rc);
done:
    cfree(c, cnt, 16 * (size_t)K, sizeof(int));
    cfree(c, base, 4 * (size_t)K, sizeof(size_t));
    cfree(c, dest, nloc, (size_t)w);
    for (int s = 0; s < 2; s++) {
        cfree(c, order[s], in->nparts[s], sizeof *order[s]);
        cfree(c, off[s], loc->n[s], sizeof(uint32_t));
    }
    cfree(c, sx, sendcap, 3 * sizeof(double));
    cfree(c, so, sendcap, sizeof(uint32_t));
    cfree(c, perm, permn, sizeof(uint32_t));
    cfree(c, runs, (size_t)K, sizeof(run_t));
    cfree(c, heap, (size_t)K, sizeof(int));
    return rc;
}

/* ---- the call ------------------------------------------------------------ */

static int types_create(ctx_t *c) {
    MPI_TRY(c, MPI_Type_contiguous((int)sizeof(ans_t), MPI_BYTE, &c->ans_type));
    MPI_TRY(c, MPI_Type_contiguous(3, MPI_DOUBLE, &c->q_type));
    MPI_TRY(c, MPI_Type_contiguous((int)sizeof(far_t), MPI_BYTE, &c->far_type));
    MPI_TRY(c, MPI_Type_contiguous((int)sizeof(sample_t), MPI_BYTE, &c->sample_type));
    MPI_TRY(c, MPI_Type_contiguous((int)sizeof(node_t), MPI_BYTE, &c->node_type));
    MPI_Datatype *all[] = {&c->ans_type, &c->q_type, &c->far_type, &c->sample_type, &c->node_type};
    for (size_t k = 0; k < sizeof all / sizeof *all; k++) MPI_TRY(c, MPI_Type_commit(all[k]));
    MPI_TRY(c, MPI_Op_create(far_reduce, 1, &c->far_op));
    return HD_OK;
}

static void types_free(ctx_t *c) {
    MPI_Datatype *all[] = {&c->ans_type, &c->q_type, &c->far_type, &c->sample_type, &c->node_type};
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
        /* The exchange numbers a rank's points of a set in 4 bytes (and
         * the engine takes at most 2^32 - 1 a set): refused before a
         * point is read. */
        uint64_t held = 0;
        for (size_t p = 0; p < in->nparts[s]; p++) {
            size_t n = in->parts[s][p].points.count;
            if (n > UINT32_MAX - held)
                return hd__err(&c->e, HD_ERANGE, "%s: more than 2^32 - 1 points on one rank (%zu parts so far)",
                               name, p + 1);
            held += n;
        }
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

/* K = 1: no partition, no exchange and no copy: the engine runs on the
 * caller's points, a view of any layout, when each set is one part (else
 * the parts are packed into one array in index order, 24 bytes a point),
 * and its local indices become global ones (ranges_global).  Local order
 * is index order, so the engine's smallest index on ties is the global
 * one. */
static int single(ctx_t *c, const input_t *in, const ranges_t *rg, int both, far_t *f) {
    hd_points_t v[2];
    double *own[2] = {NULL, NULL};
    const hd_mpi_part_t **order[2] = {NULL, NULL};
    int rc = HD_OK;
    for (int s = 0; s < 2 && rc == HD_OK; s++) {
        size_t nonempty = 0, last = 0;
        for (size_t p = 0; p < in->nparts[s]; p++)
            if (in->parts[s][p].points.count) nonempty++, last = p;
        if (nonempty == 1) {
            v[s] = in->parts[s][last].points;
            continue;
        }
        own[s] = cmalloc(c, in->n[s], 3 * sizeof(double));
        order[s] = cmalloc(c, in->nparts[s], sizeof *order[s]);
        if (!own[s] || !order[s]) {
            rc = nomem(c, "the parts", in->n[s]);
            break;
        }
        for (size_t p = 0; p < in->nparts[s]; p++) order[s][p] = &in->parts[s][p];
        qsort(order[s], in->nparts[s], sizeof *order[s], by_offset);
        size_t t = 0;
        for (size_t p = 0; p < in->nparts[s]; p++)
            for (size_t k = 0; k < order[s][p]->points.count; k++) get_point(&order[s][p]->points, k, own[s] + 3 * t++);
        v[s] = hd_points_f64(own[s], in->n[s]);
    }
    double t0 = hd__now(), u0 = thread_cpu();
    for (int s = 0; s < (both ? 2 : 1) && rc == HD_OK; s++) {
        hd_result_t e;
        if ((rc = engine_directed(c, &v[s], &v[1 - s], &e)) == HD_OK)
            f[s] = (far_t){e.distance2, ranges_global(rg, s, 0, e.i), ranges_global(rg, 1 - s, 0, e.j)};
    }
    c->search += hd__now() - t0;
    c->search_cpu += thread_cpu() - u0;
    for (int s = 0; s < 2; s++) {
        cfree(c, own[s], in->n[s], 3 * sizeof(double));
        cfree(c, order[s], in->nparts[s], sizeof *order[s]);
    }
    return rc;
}

enum { MODE_DIRECTED = 0, MODE_BOTH = 1, MODE_OVERLAP = 2 };
typedef struct { double *alpha; int *disjoint; } overlap_t;

/* `both` is a MODE_*: res is an hd_result_t, an hd_symmetric_t or an
 * overlap_t. */
static int run(ctx_t *c, const hd_options_t *opt, input_t *in, int both, void *res, hd_mpi_stats_t *st) {
    hd_symmetric_t *out = both == MODE_BOTH ? res : NULL;
    int K = c->K;
    double t0 = hd__now(), cpu0 = thread_cpu();
    node_t *tree = NULL;
    hd__box_t *region = NULL;
    held_t *held = NULL;
    local_t loc = {{NULL, NULL}, {NULL, NULL}, {NULL, NULL}, {NULL, NULL}, {0, 0}};
    ranges_t rg = {K, NULL, 0, NULL, NULL};
    int rc = check_local(c, opt, in, res);
    if ((rc = agree(c, rc)) != HD_OK) return rc;
    if ((rc = check_ranges(c, in, &rg)) != HD_OK) goto done;
    uint64_t n[2] = {in->n[0], in->n[1]}, N[2];
    MPI_GO(c, rc, MPI_Allreduce(n, N, 2, MPI_UINT64_T, MPI_SUM, c->comm));
    if (N[0] == 0 || N[1] == 0) {
        rc = hd__err(&c->e, HD_EEMPTY, "point set %s is empty", N[0] ? "B" : "A");
        goto done;
    }
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
        rc = hd_overlap(&ca, &cb, o->alpha, o->disjoint, &c->e);
        goto done;
    }
    memset(res, 0, both ? sizeof(hd_symmetric_t) : sizeof(hd_result_t));
    if (both && (rc = hd_overlap(&ca, &cb, &out->alpha, &out->disjoint, &c->e)) != HD_OK) goto done;

    far_t f[2];
    uint64_t pts;
    if (K == 1) {
        if ((rc = single(c, in, &rg, both, f)) != HD_OK) goto done;
        pts = in->n[0] + in->n[1];
    } else {
        tree = cmalloc(c, (size_t)K - 1, sizeof(node_t));
        region = cmalloc(c, (size_t)K, sizeof(hd__box_t));
        held = cmalloc(c, (size_t)K, sizeof(held_t));
        if (!tree || !region || !held) rc = nomem(c, "the partition", (size_t)K);
        if ((rc = agree(c, rc)) != HD_OK) goto done;
        if ((rc = partition(c, in, N[0] + N[1], tree)) != HD_OK) goto done;
        hd__box_t all = {{-INFINITY, -INFINITY, -INFINITY}, {INFINITY, INFINITY, INFINITY}};
        regions(tree, 0, all, region);
        if ((rc = exchange(c, in, &rg, tree, &loc)) != HD_OK) goto done;

        /* What every rank holds now. */
        held_t h;
        for (int s = 0; s < 2; s++) {
            h.n[s] = loc.n[s];
            if (loc.n[s]) hd__box_of(loc.xyz[s], loc.n[s], &h.box[s]);
            else
                for (int k = 0; k < 3; k++) h.box[s].lo[k] = INFINITY, h.box[s].hi[k] = -INFINITY;
        }
        MPI_GO(c, rc, MPI_Allgather(&h, (int)sizeof h, MPI_BYTE, held, (int)sizeof h, MPI_BYTE, c->comm));
        for (int s = 0; s < (both ? 2 : 1); s++) {
            gidx_t gi[2];
            for (int t = 0; t < 2; t++) gi[t] = (gidx_t){loc.g[t], loc.num[t], loc.start[t], &rg, t, K};
            dir_t d = {loc.xyz[s], &gi[s], loc.n[s], loc.xyz[1 - s], &gi[1 - s], loc.n[1 - s], 1 - s};
            if ((rc = direction(c, &d, tree, region, held, &f[s])) != HD_OK) goto done;
        }
        pts = loc.n[0] + loc.n[1];
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
    double other = thread_cpu() - cpu0 - c->search_cpu - c->mpi_cpu;
    double secs = hd__now() - t0, tmax = secs, tsum = secs, mine[4] = {secs, c->search, c->search_cpu, other}, most[4];
    MPI_GO(c, rc, MPI_Allreduce(mine, most, 4, MPI_DOUBLE, MPI_MAX, c->comm));
    tmax = most[0];
    MPI_GO(c, rc, MPI_Allreduce(&secs, &tsum, 1, MPI_DOUBLE, MPI_SUM, c->comm));
    for (int s = 0; s < (both ? 2 : 1); s++) r[s]->seconds = tmax;
    if (both) {
        out->distance = out->ab.distance2 >= out->ba.distance2 ? out->ab.distance : out->ba.distance;
        out->seconds = tmax;
    }
    if (st) {
        uint64_t work = pts + c->answered;
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
        st->other_cpu_max = most[3];
        st->other_cpu = other;
        st->peak_bytes_max = gm[2];
        st->seconds = secs;
        st->local_points = pts;
        st->peak_bytes = c->peak;
    }
done:
    for (int s = 0; s < 2; s++) {
        cfree(c, loc.xyz[s], loc.n[s], 3 * sizeof(double));
        cfree(c, loc.g[s], loc.n[s], sizeof(uint64_t));
        cfree(c, loc.num[s], loc.n[s], sizeof(uint32_t));
        if (loc.start[s]) cfree(c, loc.start[s], (size_t)K + 1, sizeof(size_t));
    }
    cfree(c, tree, (size_t)K - 1, sizeof(node_t));
    cfree(c, region, (size_t)K, sizeof(hd__box_t));
    cfree(c, held, (size_t)K, sizeof(held_t));
    ranges_free(c, &rg);
    return rc;
}

static int call(MPI_Comm comm, const hd_mpi_part_t *a, size_t na, const hd_mpi_part_t *b, size_t nb,
                const hd_options_t *opt, int both, void *out, hd_mpi_stats_t *st, hd_error_t *err) {
    hd__err_clear(err);
    ctx_t c;
    memset(&c, 0, sizeof c);
    c.ans_type = c.q_type = c.far_type = c.sample_type = c.node_type = MPI_DATATYPE_NULL;
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
