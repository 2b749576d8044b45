/*
 * mpi_int.h -- what the files of the MPI library (src/mpi/) share: the
 * call's context (context.c), the RCB tree (rcb.c), the index runs
 * (ranges.c), the local sets' indices (gidx.c), the exchange
 * (exchange.c), the per-point searches on slabs (slab.c), the engine's
 * pass and its shell (shell.c), the forwarding and the reduction of one
 * direction (forward.c), and the entry points (mpi.c, whose essay has the
 * algorithm).  Internal: names hd__mpi_*, and nothing outside src/mpi/
 * includes it but the white-box tests (tests/internal/mpi_*.c) and the
 * partition's benchmark (bench/rcb_bench.c).
 *
 * Conventions of every function here: a hd__mpi_ctx_t carries the call's
 * communicator, its error (c->e, what hd__mpi_agree() broadcasts) and its
 * count of bytes held (every buffer through hd__mpi_alloc/hd__mpi_free, so
 * the peak is known and the call can assert that it freed everything); a
 * function that can fail returns an HD_* code with c->e set, and collective
 * functions agree on a status before every collective a failed rank would
 * not reach.
 */
#ifndef HD_MPI_INT_H
#define HD_MPI_INT_H

#include "engine/engine.h"
#include "hausdorff_mpi.h"
#include "nearest/nearest.h"
#include "points/points.h"

#include <assert.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* ---- the call's context (context.c) -------------------------------------- */

typedef struct { double d2; uint64_t g; } hd__mpi_ans_t;                 /* an answer */
typedef struct { double d2; uint64_t i, j; } hd__mpi_far_t;              /* a witness */
typedef struct { double x[3]; uint64_t g, side; } hd__mpi_sample_t;
/* An RCB node: left/right >= 0 are nodes, < 0 are ranks -(r + 1). */
typedef struct { double s; uint64_t side, g; int axis, left, right, pad; } hd__mpi_node_t;
/* What each rank holds after the partition. */
typedef struct { hd__box_t box[2]; uint64_t n[2]; } hd__mpi_held_t;

typedef struct hd__mpi_ctx {
    MPI_Comm comm;
    int rank, K, threads;
    hd_error_t e;
    size_t cur, peak;          /* bytes of this call's buffers */
    uint64_t bytes_part, bytes_fwd, forwarded, forwarded_points, answered;
    uint64_t bytes_back;       /* per-point answers sent back (distances.c) */
    double search;             /* seconds in the engine and hd_distances */
    double search_cpu;         /* the calling thread's CPU seconds there */
    double mpi_cpu;            /* ... and in MPI calls */
    uint64_t shell;            /* points searched one by one (the shells) */
    uint64_t interior_passes;  /* second engine calls on an interior */
    int rounds;
    int first;                 /* the partition's first samples a rank (rcb.c) */
    MPI_Datatype ans_type, q_type, far_type, sample_type, node_type;
    MPI_Op far_op;
} hd__mpi_ctx_t;


double hd__mpi_cpu(void);
void *hd__mpi_alloc(hd__mpi_ctx_t *c, size_t n, size_t size);
void hd__mpi_free(hd__mpi_ctx_t *c, void *p, size_t n, size_t size);
/* A buffer freed before the engine's pass (the exchange's), which may be
 * rounded up to whole huge pages and is charged so; freed by
 * hd__mpi_free_scratch with the same count and size. */
void *hd__mpi_scratch(hd__mpi_ctx_t *c, size_t n, size_t size);
void hd__mpi_free_scratch(hd__mpi_ctx_t *c, void *p, size_t n, size_t size);
void hd__mpi_charge(hd__mpi_ctx_t *c, size_t bytes);
int hd__mpi_engine(hd__mpi_ctx_t *c, const hd_points_t *P, const hd_points_t *Q, hd_result_t *e);
int hd__mpi_engine_local(hd__mpi_ctx_t *c, const hd_points_t *P, const hd_points_t *Q, const hd__box_t *bp,
                         const hd__box_t *bq, hd_result_t *e);
int hd__mpi_engine_sym(hd__mpi_ctx_t *c, const hd_points_t *P, const hd_points_t *Q, const hd__box_t *bp,
                       const hd__box_t *bq, const hd__keep_t keep[2], hd_symmetric_t *s);
int hd__mpi_engine_above(hd__mpi_ctx_t *c, const hd_points_t *P, const hd_points_t *Q, double floor2, size_t floor_i,
                         hd_result_t *e);
int hd__mpi_engine_kept(hd__mpi_ctx_t *c, const hd_points_t *P, const hd_points_t *Q, const hd__keep_t *keep,
                        hd_result_t *e);
int hd__mpi_nomem(hd__mpi_ctx_t *c, const char *what, size_t n);
int hd__mpi_failed(hd__mpi_ctx_t *c, const char *call, int code);
int hd__mpi_agree(hd__mpi_ctx_t *c, int rc);
int hd__mpi_types_create(hd__mpi_ctx_t *c);
void hd__mpi_types_free(hd__mpi_ctx_t *c);

/* The witness order: larger d2 first, then the smaller index i. */
static inline int hd__mpi_far_better(const hd__mpi_far_t *x, const hd__mpi_far_t *y) {
    return x->d2 > y->d2 || (x->d2 == y->d2 && x->i < y->i);
}

/* Every MPI call is timed (thread CPU): what is left of the call's CPU
 * besides them and the searches is its bookkeeping (stats->other_cpu). */
#define HD__MPI_TIMED(c, call) (mpi_t0_ = hd__mpi_cpu(), mpi_rc_ = (call), (c)->mpi_cpu += hd__mpi_cpu() - mpi_t0_, mpi_rc_)

#define HD__MPI_TRY(c, call)                                                      \
    do {                                                                      \
        double mpi_t0_;                                                       \
        int mpi_rc_;                                                          \
        mpi_rc_ = HD__MPI_TIMED(c, call);                                         \
        if (mpi_rc_ != MPI_SUCCESS) return hd__mpi_failed(c, #call, mpi_rc_); \
    } while (0)

/* The same in a function that frees its buffers at `done`. */
#define HD__MPI_GO(c, rc, call)                         \
    do {                                            \
        double mpi_t0_;                             \
        int mpi_rc_;                                \
        mpi_rc_ = HD__MPI_TIMED(c, call);               \
        if (mpi_rc_ != MPI_SUCCESS) {               \
            rc = hd__mpi_failed(c, #call, mpi_rc_); \
            goto done;                              \
        }                                           \
    } while (0)

/* ---- the input and its index runs (ranges.c) ----------------------------- */

typedef struct {
    const hd_mpi_part_t *parts[2];
    size_t nparts[2];
    uint64_t n[2];            /* local points of A, B (input) */
    hd__box_t box[2];         /* local boxes (input) */
} hd__mpi_input_t;

/* A view of packed doubles (the common layout) as its array, read in
 * place; NULL for any other layout, read through hd_points_get. */
static inline const double *hd__mpi_packed(const hd_points_t *p) {
    if (p->dtype == HD_FLOAT64 && (p->stride == 0 || p->stride == 3 * (ptrdiff_t)sizeof(double)) &&
        (p->cstride == 0 || p->cstride == (ptrdiff_t)sizeof(double)))
        return p->data;
    return NULL;
}

/* Point k of a view. */
static inline void hd__mpi_get_point(const hd_points_t *p, size_t k, double out[3]) {
    const double *x = hd__mpi_packed(p);
    if (x) memcpy(out, x + 3 * k, 3 * sizeof(double));
    else hd_points_get(p, k, out);
}

typedef struct { uint64_t lo, hi; int side, rank; } hd__mpi_range_t;

/* Every rank's nonempty parts (all-gathered by check_ranges), sorted by
 * (side, rank, first index): side s, rank r's are all[seg[s (K + 1) + r]]
 * up to all[seg[s (K + 1) + r + 1]], and first[i] is the number of part
 * i's first point among its rank's points of its side in index order.  So
 * point number m of rank r's side s names a global index (ranges_globals),
 * which lets the exchange send 4-byte numbers instead of 8-byte indices.
 * The same runs sorted by (side, first index) are bylo (side s's at the
 * same positions seg[s (K + 1)] .. seg[s (K + 1) + K] as in all), and
 * ord[i] is the number of side indices below bylo[i].lo over all ranks:
 * index g of run i is the side's ordinal ord[i] + (g - lo), dense in
 * 0 .. N_side - 1 (what hd__mpi_gidx_t encodes). */
struct hd__mpi_ranges {
    int K;
    hd__mpi_range_t *all;
    size_t total;
    size_t *seg;
    uint64_t *first;
    hd__mpi_range_t *bylo;
    uint64_t *ord;
};

/* The global indices of a local set, by position (gidx.c).  Local order is
 * global index order, so the ordinals (hd__mpi_ranges_t.ord) of a local set
 * increase with the position, and they are held Elias-Fano coded: with
 * n points among the side's U indices and l = floor(log2(U / n)), the low
 * l bits of each ordinal in a packed array, and the high part h of the
 * k-th ordinal as bit h + k of a bit array of n + (U - 1 >> l) + 1 bits
 * (one 1 a point, U >> l < 2n zeros), with the position of every 64th 1
 * (samp): l + 1 + 2^f bits a point (U / n = 2^(l + f), 0 <= f < 1) and
 * a word per 64 points, less than 4 + log2(U / n) bits in all, not 4 or 8
 * bytes (0.5 B/pt at U / n = 2, 0.625 at 4, 0.875 at 16: K ranks holding
 * equal shares; docs/scale-out.md).  The exchange encodes them once (from its 4-byte
 * numbers, or from the 8-byte indices of merged runs, both freed then),
 * and they are never reordered afterwards (split and unsplit move
 * coordinates only), so position k's index is fixed for the call.  An index is the ordinal's run's first index plus the ordinal's
 * offset in it (run, rord: the side's runs of hd__mpi_ranges_t by first index). */
typedef struct hd__mpi_ranges hd__mpi_ranges_t;
typedef struct {
    uint64_t *w;             /* one allocation: low, high, samp */
    size_t words;            /* its words (charged) */
    const uint64_t *low, *high, *samp;
    size_t n;                /* positions */
    int l;                   /* low bits an ordinal */
    const hd__mpi_range_t *run;      /* the side's runs by first index */
    const uint64_t *rord;    /* each one's first ordinal */
    size_t nrun;
    int side;
} hd__mpi_gidx_t;

int hd__mpi_gidx_init(hd__mpi_ctx_t *c, hd__mpi_gidx_t *x, const hd__mpi_ranges_t *rg, int side, size_t n);
/* Positions k .. k + n - 1's indices are g[0 .. n - 1] (increasing, and
 * above those of the positions before k), or the indices of numbers
 * num[0 .. n - 1] at their sender r (increasing: a run received in index
 * order).  The code is written once, from calls covering 0 .. x->n - 1. */
void hd__mpi_gidx_put_indices(hd__mpi_gidx_t *x, size_t k, const uint64_t *g, size_t n);
void hd__mpi_gidx_put_numbers(hd__mpi_gidx_t *x, const hd__mpi_ranges_t *rg, int r, size_t k, const uint32_t *num, size_t n);
/* The code emptied (every word zero), to be written again. */
void hd__mpi_gidx_clear(hd__mpi_gidx_t *x);
void hd__mpi_gidx_free(hd__mpi_ctx_t *c, hd__mpi_gidx_t *x);
/* Position k's index, at any k (a select from the sample before it and a
 * binary search of the runs). */
uint64_t hd__mpi_gidx(const hd__mpi_gidx_t *x, size_t k);
/* Positions k .. k + m - 1's indices into g[0 .. m - 1]: a select for the
 * first, then the 1s of the high bits in order and the runs only forward
 * (a fraction of a cursor's cost a position, when all are wanted). */
void hd__mpi_gidx_decode(const hd__mpi_gidx_t *x, size_t k, size_t m, uint64_t *g);

/* The low l bits of position k's ordinal. */
static inline uint64_t hd__mpi_gidx_low(const hd__mpi_gidx_t *x, size_t k) {
    if (x->l == 0) return 0;
    uint64_t bit = (uint64_t)k * (uint64_t)x->l;
    size_t w = (size_t)(bit >> 6);
    unsigned o = (unsigned)(bit & 63);
    uint64_t v = x->low[w] >> o;
    if (o + (unsigned)x->l > 64) v |= x->low[w + 1] << (64 - o);
    return v & ((UINT64_C(1) << x->l) - 1);
}

/* A walk over a local set's global indices at nondecreasing positions:
 * the next position's 1 is the next set bit of the high bits (in the
 * current word or a following one), and its run the current one (a
 * subtraction and a comparison); anything else (a jump, a new run) is
 * hd__mpi_gcur_next's.  Positions may also go back (then as
 * hd__mpi_gidx). */
typedef struct {
    const hd__mpi_gidx_t *x;
    size_t k;                /* the last position decoded (SIZE_MAX: none) */
    size_t wi;               /* the word of the high bits holding its 1 */
    uint64_t w;              /* that word's 1s after it */
    size_t run;              /* the run of its ordinal (SIZE_MAX: none) */
    uint64_t first, span, lo; /* that run: ordinals first .. first + span
                                 name indices lo .. lo + span */
    uint64_t g;              /* its index */
} hd__mpi_gcur_t;

void hd__mpi_gcur_init(hd__mpi_gcur_t *cu, const hd__mpi_gidx_t *x);
uint64_t hd__mpi_gcur_next(hd__mpi_gcur_t *cu, size_t k);

static inline uint64_t hd__mpi_gcur_at(hd__mpi_gcur_t *cu, size_t k) {
    if (k == cu->k) return cu->g;
    if (k == cu->k + 1 && cu->run != SIZE_MAX) { /* k < n: a 1 follows */
        size_t wi = cu->wi;
        uint64_t w = cu->w;
        while (!w) w = cu->x->high[++wi];
        uint64_t h = (((uint64_t)wi << 6) | (uint64_t)__builtin_ctzll(w)) - k;
        uint64_t d = ((h << cu->x->l) | hd__mpi_gidx_low(cu->x, k)) - cu->first;
        if (d <= cu->span) {
            cu->wi = wi;
            cu->w = w & (w - 1);
            cu->k = k;
            return cu->g = cu->lo + d;
        }
    }
    return hd__mpi_gcur_next(cu, k);
}

/* The rank whose parts hold the cursor's last index. */
static inline int hd__mpi_gcur_rank(const hd__mpi_gcur_t *cu) {
    return cu->x->run[cu->run].rank;
}

typedef struct {
    double *P;               /* local points asking, packed xyz (reordered
                                and restored by split/unsplit) */
    const hd__mpi_gidx_t *gP;        /* their global indices, by position */
    size_t nP;
    double *Q;               /* local points searched */
    const hd__mpi_gidx_t *gQ;
    size_t nQ;
    int qside;               /* 0: Q is A, 1: Q is B */
    const struct hd__mpi_pre *pre;   /* the engine's answer, when computed for both
                                directions at once (NULL: not) */
} hd__mpi_dir_t;

int hd__mpi_by_offset(const void *x, const void *y);
int hd__mpi_by_range(const void *x, const void *y); /* hd__mpi_range_t by (side, lo) */
void hd__mpi_ranges_free(hd__mpi_ctx_t *c, hd__mpi_ranges_t *rg);
int hd__mpi_ranges_index(hd__mpi_ctx_t *c, hd__mpi_ranges_t *rg);
void hd__mpi_ranges_globals(const hd__mpi_ranges_t *rg, int s, int r, size_t *i, const uint32_t *num, size_t n, uint64_t *g);
uint64_t hd__mpi_ranges_global(const hd__mpi_ranges_t *rg, int s, int r, uint64_t m);
/* *i, a run of rank r's side s at or before number m's (numbers only grow
 * along a walk), becomes the run holding number m. */
static inline void hd__mpi_ranges_seek(const hd__mpi_ranges_t *rg, int s, int r, size_t *i, uint64_t m) {
    while (m - rg->first[*i] > rg->all[*i].hi - rg->all[*i].lo) ++*i;
    assert(*i < rg->seg[(size_t)s * ((size_t)rg->K + 1) + (size_t)r + 1] && m >= rg->first[*i]);
    (void)s, (void)r; /* the assert's */
}
int hd__mpi_check_ranges(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, hd__mpi_ranges_t *rg);
int hd__mpi_check_local(hd__mpi_ctx_t *c, const hd_options_t *opt, hd__mpi_input_t *in, const void *out);

/* ---- the partition (rcb.c) and the exchange (exchange.c) ----------------- */

/* Whether a point (coordinates x, set side, global index g) goes to the
 * left of a node: its key (coordinate, set, index) below the split's. */
static inline int hd__mpi_goes_left(const hd__mpi_node_t *nd, const double *x, uint64_t side, uint64_t g) {
    double v = x[nd->axis];
    if (v != nd->s) return v < nd->s;
    if (side != nd->side) return side < nd->side;
    return g < nd->g;
}

/* The rank whose region holds the point (a walk down the tree; inline,
 * since the exchange asks it for every point). */
static inline int hd__mpi_rank_of(const hd__mpi_node_t *t, int K, const double *x, uint64_t side, uint64_t g) {
    if (K == 1) return 0;
    int k = 0;
    for (;;) {
        int next = hd__mpi_goes_left(&t[k], x, side, g) ? t[k].left : t[k].right;
        if (next < 0) return -next - 1;
        k = next;
    }
}
void hd__mpi_regions(const hd__mpi_node_t *t, int node, hd__box_t box, hd__box_t *out);
hd__box_t hd__mpi_node_boxes(const hd__mpi_node_t *t, int node, const hd__mpi_held_t *held, int side, hd__box_t *out);
void hd__mpi_candidates(const hd__mpi_node_t *t, const hd__box_t *nbox, const hd__mpi_held_t *held, int side, int node,
                        const double *p, double u2, int me, int *list, int *n);
/* The first samples a rank of K gives rank 0's tree: 1024 up to 64 ranks,
 * then fewer, so that rank 0 holds at most 65536 of them (at least 64 a
 * rank, which the second samples still balance: rcb.c). */
int hd__mpi_first_samples(int K);
/* Rank 0's tree over n first samples s (reordered) for K ranks: the K - 1
 * nodes into t, each node's bracket into br[2 id], br[2 id + 1]. */
void hd__mpi_rcb_tree(hd__mpi_sample_t *s, size_t n, int K, hd__mpi_node_t *t, double *br);
/* Cut space into the K ranks' regions (tree, K - 1 nodes): rank 0's tree
 * over c->first samples a rank, refined by a second sample's counts. */
int hd__mpi_partition(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, uint64_t N, hd__mpi_node_t *tree);
/* The ranks other than `me` that p must ask (into list; their number is
 * returned): those whose box of `side` may hold a point within u2 of p,
 * ties included; when this rank holds no point of `side` (none_here), u2
 * is first lowered to the nearest farthest corner of the nonempty boxes,
 * which bounds the distance to the nearest point from above. */
int hd__mpi_asked(const hd__mpi_node_t *t, const hd__box_t *nbox, const hd__mpi_held_t *held, int K, int side, int none_here,
                  const double *p, double u2, int me, int *list);

typedef struct {
    double *xyz[2];
    hd__box_t box[2];        /* the exact box of each side's points (empty: lo > hi) */
    hd__mpi_gidx_t gi[2];            /* their global indices */
    int merged[2];           /* the senders' runs were merged, */
    size_t *start[2];        /* else K + 1 a side: each sender's run */
    size_t n[2];
} hd__mpi_local_t;

int hd__mpi_exchange(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const hd__mpi_ranges_t *rg, const hd__mpi_node_t *tree, hd__mpi_local_t *loc);

/* ---- the per-point searches (slab.c) ------------------------------------- */

/* 1 when every finite face of region r is farther from p than u2 allows
 * (computed fl(gap^2) > u2): then no point of another region is within u2
 * of p, nor at u2 (see mpi.c's essay, step 4). */
static inline int hd__mpi_faces_clear(const hd__box_t *r, const double *p, double u2) {
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

/* The slabs of the searched local set Q (slab.c has the proof). */
typedef struct {
    hd__an_t s;
    int built;
    size_t n, bytes;         /* its points (named by their positions in Q) */
    double M;                /* its margin (infinite: all of Q) */
    hd__box_t kb;            /* the key box its askers use too */
} hd__mpi_slab_t;

typedef struct {
    hd__mpi_slab_t sub, full;
    double M0;               /* the first slab's margin (set by shell_of) */
} hd__mpi_qtree_t;

void hd__mpi_qtree_free(hd__mpi_ctx_t *c, hd__mpi_qtree_t *q);
/* The nearest layer's structure of v (sel NULL), or of v's m points
 * sel[0..m) named by names[] or their positions in v (hd__an_build_sel),
 * charged at its build's measured peak while built, then at what it
 * holds (*bytes, to subtract when it is freed). */
int hd__mpi_an_build(hd__mpi_ctx_t *c, hd__an_t *s, const hd_points_t *v, const uint32_t *sel, const uint32_t *names,
                     size_t m, const hd__box_t *kb, int threads, size_t *bytes);
/* hd__an_nearest_paired(asking, searched, pair_at) into near (no
 * distances; pair_at may be NULL: no partners), its own arrays charged
 * while it runs. */
int hd__mpi_an_nearest(hd__mpi_ctx_t *c, const hd__an_t *asking, const hd__an_t *searched, const uint32_t *pair_at,
                       int threads, size_t *near);
/* Frees a structure hd__mpi_an_build made and takes its bytes off the count. */
void hd__mpi_an_release(hd__mpi_ctx_t *c, hd__an_t *s, size_t bytes);
/* For each of n points, point k at pts + 3 pos[k] (pos NULL: pts + 3 k),
 * its nearest point of Q into near[k] (exact, smallest index on ties, as
 * hd_distances gives it), from q's slabs (slab.c), built as needed.  With
 * `unproven` (n flags, zeroed by the caller), a point the first slab
 * answers but does not prove is left with that answer (a point of Q, so
 * an upper bound of its nearest distance) and flagged, for the caller to
 * prove by a smaller answer from elsewhere (hd__mpi_slab_proves with the
 * first slab's margin, q->M0) or to ask again without `unproven`. */
int hd__mpi_nearest_in_q(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__box_t *r, hd__mpi_qtree_t *q, const double *pts,
                         const uint32_t *pos, size_t n, size_t *near, unsigned char *unproven);
/* Whether every point of Q farther than M from all of r's finite faces is
 * farther from x than sqrt(d2) (slab.c's proof). */
int hd__mpi_slab_proves(const hd__box_t *r, double M, const double *x, double d2);

/* ---- the engine's pass and its shell (shell.c) --------------------------- */

/* What the engine's pass leaves for per-point searches (shell.c's essay). */
typedef struct {
    size_t n;                /* the shell's points, read in P (hd__mpi_shell_pt) */
    size_t *nearest;         /* each one's nearest in Q (NULL if Q is empty) */
    uint32_t *own_pos;       /* each one's position in P (NULL: all of P) */
    unsigned char *unproven; /* each one's: nearest[] only a point of the first slab
                                (hd__mpi_nearest_in_q), or NULL */
    hd__mpi_far_t inner;             /* exact over the interior; d2 = -1 if none
                                or not known (lazy) */
    int lazy;                /* the interior's maximum was not computed */
    hd__mpi_far_t h;                 /* then: the engine's answer, whose witness
                                is in the shell and bounds the interior */
} hd__mpi_shell_t;

/* The shell's point k: its coordinates are P's, not a copy. */
static inline const double *hd__mpi_shell_pt(const hd__mpi_dir_t *d, const hd__mpi_shell_t *sh, size_t k) {
    return d->P + 3 * (sh->own_pos ? sh->own_pos[k] : k);
}

/* The points of P the engine's maximum refused (shell.c, keep_clear):
 * those whose region faces are not clear of their own local nearest
 * distance, which may be only local. */
typedef struct {
    const hd__box_t *mine;   /* the rank's region */
    const double *P;
    int on;                  /* the engine's answer is over the points kept */
    double d2;               /* the largest refused u^2 (-1: none) */
    uint32_t *pos;           /* refused positions in P (repeats possible) */
    size_t n, cap;
    int overflow;            /* more than cap were refused: pos is partial */
    uint32_t *near;          /* each one's nearest position in Q, the engine's
                                (the smallest index at its u), by pos: 4
                                bytes, as the local sets' positions are */
} hd__mpi_refused_t;

/* The engine's answer for a direction, computed before it runs: the
 * symmetric call runs the engine once for both directions
 * (hd__mpi_engine_both), since each of its calls builds both sets'
 * structures. */
typedef struct hd__mpi_pre {
    int have;                /* 0: the direction runs the engine itself */
    int paired;              /* the answer is on the pairs (P_c, Q_c) */
    hd_result_t e;           /* positions in P and Q, or in P_c and Q_c */
    const unsigned char *inp, *inq; /* paired: the pairs' masks of P, Q */
    hd__mpi_refused_t ref;           /* not paired: what e's maximum left out */
} hd__mpi_pre_t;

/* mask[s]: NULL, or the pairs' mask of side s (n[s] bytes) when paired,
 * which the caller frees (hd__mpi_free) after both directions, as it
 * frees pre[s] (hd__mpi_pre_free).  mine: the rank's region. */
int hd__mpi_engine_both(hd__mpi_ctx_t *c, double *xyz[2], const hd__mpi_gidx_t *g[2], const size_t n[2], const hd__box_t box[2],
                        const hd__box_t *mine, hd__mpi_pre_t pre[2], unsigned char *mask[2]);
void hd__mpi_pre_free(hd__mpi_ctx_t *c, hd__mpi_pre_t *pre);
void hd__mpi_shell_free(hd__mpi_ctx_t *c, hd__mpi_shell_t *sh);
int hd__mpi_interior_max(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__box_t *mine, const hd__mpi_shell_t *sh, double h2,
                         const hd__mpi_far_t *G, hd__mpi_far_t *out);
uint64_t hd__mpi_shell_g(hd__mpi_gcur_t *cu, const hd__mpi_shell_t *sh, size_t k);
int hd__mpi_shell_of(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__box_t *mine, hd__mpi_qtree_t *q, hd__mpi_shell_t *sh);

/* ---- one direction over the partition (forward.c) ------------------------ */

/* Forwarded queries: point k of the asking set to rank dest. */
typedef struct { size_t k; int dest; int pad; } hd__mpi_pair_t;
typedef struct { hd__mpi_pair_t *p; size_t n, cap; } hd__mpi_pairs_t;
int hd__mpi_pairs_add(hd__mpi_ctx_t *c, hd__mpi_pairs_t *pr, size_t k, const int *list, int n);
void hd__mpi_pairs_free(hd__mpi_ctx_t *c, hd__mpi_pairs_t *pr);

/* Answers m queries pts against this rank's local set: exact (d2,
 * smallest global index), or (infinity, UINT64_MAX) when it holds none. */
typedef int (*hd__mpi_answer_t)(hd__mpi_ctx_t *c, void *arg, const double *pts, size_t m, hd__mpi_ans_t *ans);

/* One round of forwarding (collective; rc is the caller's status, agreed
 * first): each pair (k, r) sends point k of P (at P + 3 pos[k], pos NULL:
 * P + 3 k) to rank r, every rank answers what it receives with fn, and
 * each answer replaces (u2[k], jj[k]) when smaller (d2 first, then the
 * index). */
int hd__mpi_round(hd__mpi_ctx_t *c, int rc, const double *P, const uint32_t *pos, const hd__mpi_pairs_t *pr,
                  hd__mpi_answer_t fn, void *arg, double *u2, uint64_t *jj);

int hd__mpi_direction(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__mpi_node_t *tree, const hd__box_t *region, const hd__mpi_held_t *held,
                      hd__mpi_far_t *result);

/* ---- the course of a call (mpi.c) ---------------------------------------- */

/* What the ranks hold after the partition (K > 1). */
typedef struct {
    hd__mpi_node_t *tree;            /* K - 1 nodes */
    hd__box_t *region;       /* K: every rank's region */
    hd__mpi_held_t *held;            /* K: every rank's count and box a set */
    hd__mpi_local_t loc;             /* this rank's points */
} hd__mpi_spread_t;

/* K = 1: each set as one view (the caller's, or packed in index order). */
typedef struct {
    hd_points_t v[2];
    double *own[2];
    const hd_mpi_part_t **order[2];
} hd__mpi_views_t;

/* What a call's body holds from its start to its end. */
typedef struct {
    hd__mpi_ranges_t rg;
    hd__mpi_spread_t sp;             /* K > 1 */
    uint64_t N[2];           /* points of A and B over all ranks */
    double t0, cpu0;         /* the body's start (wall, thread CPU) */
} hd__mpi_course_t;

void hd__mpi_course_init(hd__mpi_ctx_t *c, hd__mpi_course_t *cs);
void hd__mpi_course_free(hd__mpi_ctx_t *c, hd__mpi_course_t *cs);
int hd__mpi_figures(hd__mpi_ctx_t *c, const hd__mpi_course_t *cs, uint64_t pts, hd_mpi_stats_t *st, double *tmax);

/* A call's body, run by hd__mpi_call inside its context. */
typedef int (*hd__mpi_body_t)(hd__mpi_ctx_t *c, const hd_options_t *opt, hd__mpi_input_t *in, void *arg, hd_mpi_stats_t *st);

int hd__mpi_call(MPI_Comm comm, const hd_mpi_part_t *a, size_t na, const hd_mpi_part_t *b, size_t nb,
                 const hd_options_t *opt, hd__mpi_body_t body, void *arg, hd_mpi_stats_t *st, hd_error_t *err);
int hd__mpi_begin(hd__mpi_ctx_t *c, const hd_options_t *opt, hd__mpi_input_t *in, const void *res, hd__mpi_ranges_t *rg, uint64_t N[2],
                  double corners[2][6]);
int hd__mpi_spread(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const hd__mpi_ranges_t *rg, const uint64_t N[2], hd__mpi_spread_t *sp);
void hd__mpi_spread_free(hd__mpi_ctx_t *c, hd__mpi_spread_t *sp);
int hd__mpi_views(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, hd__mpi_views_t *vw);
void hd__mpi_views_free(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, hd__mpi_views_t *vw);

#endif /* HD_MPI_INT_H */
