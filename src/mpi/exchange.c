/*
 * exchange.c -- moving every point to the rank of its region (step 2 of
 * mpi.c's essay) with MPI_Alltoallv in rounds.
 *
 * Invariants.
 *  - A point travels as its coordinates and its 4-byte number (28 bytes);
 *    the receiver knows every sender's index runs (ranges.c), so the
 *    number names the global index.
 *  - Senders walk their parts in increasing offset order, so each
 *    sender's run at the receiver is in increasing index order; the run of
 *    source r is received at base + got, straight into its slot of the
 *    local arrays (no second copy of the points), and a rank's own points
 *    are copied from the input into their slot in the same walk.
 *  - A round sends at most C = max(n / 8, 4096) points of a rank, so the
 *    send buffer is at most 3.5 bytes a point (3.9 when it is made whole
 *    huge pages, as the other buffers freed here may be: hd__mpi_scratch);
 *    every rank runs the same number of rounds (the allreduced maximum),
 *    each three collectives.
 *  - After the rounds, local order is global index order: as received when
 *    the runs follow each other in index order (they land in the order of
 *    their senders' smallest indices, so they do whenever no two ranks'
 *    indices interleave), else after a K-way merge
 *    applied in place (the numbers become 8-byte indices first).  The
 *    indices are then held encoded (hd__mpi_gidx_t, gidx.c): each round's numbers
 *    are encoded as they arrive (still in the cache), as if the runs were
 *    in order, and encoded again from the merged indices when they were
 *    not; the numbers and indices are freed before the call goes on.
 *    Nothing reorders the local arrays' indices afterwards.
 *  - A point of a cell prune.c leaves out (hd__mpi_moves false) goes
 *    nowhere, not even into this rank's own arrays: its destination is K,
 *    it keeps its number (the numbers count every input point), and no
 *    count, round or box includes it.
 *  - loc->box is the exact box of each side's local points, merged from
 *    each run as it lands (the rank's own, each sender's): the same points
 *    as the local arrays hold, in whatever order the merge leaves them.
 */
#include "mpi/partition.h"

#include <assert.h>
#include <limits.h>
#include <stdlib.h>

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

/* A cursor over the local input in walking order (sides A then B, parts
 * in offset order): side s, part p, point k in it, and the next local
 * number of each side.  The passes run a tight loop over each part's
 * points, not a step function a point. */
typedef struct { int s; size_t p, k; uint64_t num[2]; } walk_t;

/* The points left in the cursor's part, after moving past finished parts
 * (0 at the end of the input). */
static size_t walk_avail(const hd__mpi_input_t *in, const hd_mpi_part_t **order[2], walk_t *w) {
    while (w->s < 2) {
        if (w->p < in->nparts[w->s]) {
            size_t n = order[w->s][w->p]->points.count;
            if (w->k < n) return n - w->k;
            w->p++, w->k = 0;
        } else {
            w->s++, w->p = 0, w->k = 0;
        }
    }
    return 0;
}

/* The box of n points (none: unchanged) merged into *b. */
static void box_run(hd__box_t *b, const double *xyz, size_t n) {
    if (n == 0) return;
    hd__box_t r;
    hd__box_of(xyz, n, &r);
    hd__box_merge(b, &r);
}

/* Where one part's run of points goes in a round: each point's
 * coordinates and number to its slot in the local arrays (lx, lo at
 * *own, when it stays) or in the send buffer (sx, so at sfill[2 r + s]).
 * Two ways, one result, chosen by the caller from how often consecutive
 * points change destination (the plan counts it):
 *  - pack_runs, for destinations in long runs (an input in space's order,
 *    as a rank reading its tiles has): a run of one destination is found
 *    eight bytes at a time and copied at once, its numbers written in a
 *    loop without a branch;
 *  - pack_scattered, tables indexed by the destination, with no branch,
 *    for destinations at random (an input in no spatial order: half the
 *    points stay at K = 2, and a branch on it was mispredicted as often,
 *    by callgrind's branch simulation; GCC turned plain ternaries back
 *    into the branch).  A rank's own block of the send buffer is empty,
 *    so its cursor, written back unchanged when a point stays, is never
 *    used. */
static void pack_scattered(const hd_points_t *v, const double *px, size_t k0, size_t m, const void *dest, int w,
                           size_t t, int me, int s, uint32_t num, double *lx, uint32_t *lo, size_t *own, double *sx,
                           uint32_t *so, int *sfill, int drop) {
    double *const xto[2] = {sx, lx};
    uint32_t *const oto[2] = {so, lo};
    size_t cur[2] = {0, *own};
    for (size_t i = 0; i < m; i++, t++, num++) {
        int r = dest_get(dest, w, t);
        if (r == drop) continue; /* it stays, out of the course (prune.c) */
        int mine = r == me;
        cur[0] = (size_t)sfill[2 * r + s];
        size_t to = cur[mine];
        sfill[2 * r + s] = (int)cur[0] + !mine;
        cur[1] += (size_t)mine;
        double *x = xto[mine] + 3 * to;
        oto[mine][to] = num;
        if (px) memcpy(x, px + 3 * (k0 + i), 3 * sizeof(double));
        else hd_points_get(v, k0 + i, x);
    }
    *own = cur[1];
}

/* The positions from t on (at most m, at least 1) whose rank is r. */
static inline size_t run_length(const void *dest, int w, size_t t, size_t m, int r) {
    size_t j = 1;
    if (w == 1) {
        const uint8_t *d = (const uint8_t *)dest + t;
        uint64_t all = (uint64_t)(uint8_t)r * UINT64_C(0x0101010101010101), wd;
        while (j + 8 <= m && (memcpy(&wd, d + j, 8), wd == all)) j += 8;
    }
    while (j < m && dest_get(dest, w, t + j) == r) j++;
    return j;
}

static void pack_runs(const hd_points_t *v, const double *px, size_t k0, size_t m, const void *dest, int w, size_t t,
                      int me, int s, uint32_t num, double *lx, uint32_t *lo, size_t *own, double *sx, uint32_t *so,
                      int *sfill, int drop) {
    for (size_t i = 0, n; i < m; i += n) {
        int r = dest_get(dest, w, t + i);
        n = run_length(dest, w, t + i, m - i, r);
        if (r == drop) continue; /* they stay, out of the course (prune.c) */
        size_t to;
        double *x;
        uint32_t *o;
        if (r == me) to = *own, *own += n, x = lx, o = lo;
        else to = (size_t)sfill[2 * r + s], sfill[2 * r + s] += (int)n, x = sx, o = so;
        x += 3 * to, o += to;
        if (px) memcpy(x, px + 3 * (k0 + i), n * 3 * sizeof(double));
        else
            for (size_t u = 0; u < n; u++) hd_points_get(v, k0 + i + u, x + 3 * u);
        for (size_t u = 0; u < n; u++) o[u] = num + (uint32_t)(i + u);
    }
}

/* Points sent per round by a rank: an eighth of its points (at least
 * ROUND_MIN), so the send buffer is at most 28/8 = 3.5 bytes a point (the
 * minimum also makes the tests' larger sets take several rounds). */
#define ROUND_SHARE 8
#define ROUND_MIN 4096

/* The exchange's state.  Counts by (rank r, side s) are at 2 r + s, sizes
 * by (side s, rank r) at s K + r. */
typedef struct {
    int K, me, w;                   /* ranks, this rank, bytes of a destination (dest_get; K: the point stays out) */
    const hd__mpi_prune_t *pr;      /* the points that stay out (NULL: none) */
    size_t nloc, C;                 /* local input points; at most C sent a round */
    const hd_mpi_part_t **order[2]; /* each side's parts by offset: the walking order */
    void *dest;                     /* each input position's rank (scratch) */
    size_t switches;                /* positions whose rank is not the previous one's */
    /* The rounds: round q walks the input positions [tb[q], tb[q + 1]), up
     * to the (q + 1) C-th point for another rank (the last to the end), and
     * sends rcnt[q 2K + 2 r + s] points of side s to rank r. */
    size_t maxr, nr, *tb;
    int *rcnt;
    int *tot, *rtot;                /* 2K: points sent in all, and received */
    int *per, *rper;                /* 2K: this round's, sent and received */
    int *sdisp, *sfill;             /* 2K: each block of the send buffer, and a cursor in it */
    int *sc, *sd, *rcn, *rd;        /* K: one side's counts and displacements for MPI */
    size_t *big;                    /* 2K: tot counted in size_t, checked against INT_MAX */
    size_t *base, *got;             /* 2K: where rank r's run of side s lands here, and how much arrived */
    double *sx;                     /* the send buffer (sendcap points) and the points' numbers */
    uint32_t *so;
    size_t sendcap;
    uint32_t *off[2];               /* each local point's number at its sender (scratch) */
    int *sorder;                    /* 2K: side s's senders in the order their runs land (s K + q) */
} xch_t;

/* The arrays of K or 2K counts, each its own allocation. */
#define XCH_INTS(x) {&(x)->tot, &(x)->rtot, &(x)->per, &(x)->rper, &(x)->sdisp, &(x)->sfill, \
                     &(x)->sc, &(x)->sd, &(x)->rcn, &(x)->rd}
#define XCH_INTS_2K 6 /* the first six have 2K, the others K */
#define XCH_SIZES(x) {&(x)->big, &(x)->base, &(x)->got}

static int xch_alloc(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, xch_t *x) {
    memset(x, 0, sizeof *x);
    x->K = c->K, x->me = c->rank, x->w = c->K < 256 ? 1 : c->K < 65536 ? 2 : 4;
    x->nloc = (size_t)(in->n[0] + in->n[1]);
    x->C = x->nloc / ROUND_SHARE < ROUND_MIN ? ROUND_MIN : x->nloc / ROUND_SHARE;
    x->maxr = x->nloc / x->C + 2, x->nr = 1;
    int **ints[] = XCH_INTS(x);
    size_t **sizes[] = XCH_SIZES(x);
    int ok = 1;
    for (int k = 0; k < (int)(sizeof ints / sizeof *ints); k++)
        ok &= (*ints[k] = hd__mpi_alloc(c, (k < XCH_INTS_2K ? 2 : 1) * (size_t)x->K, sizeof(int))) != NULL;
    for (int k = 0; k < (int)(sizeof sizes / sizeof *sizes); k++)
        ok &= (*sizes[k] = hd__mpi_alloc(c, 2 * (size_t)x->K, sizeof(size_t))) != NULL;
    for (int s = 0; s < 2; s++) ok &= (x->order[s] = hd__mpi_alloc(c, in->nparts[s], sizeof *x->order[s])) != NULL;
    x->dest = hd__mpi_scratch(c, x->nloc, (size_t)x->w);
    if (!ok || !x->dest) return hd__mpi_nomem(c, "the exchange", x->nloc);
    x->sorder = hd__mpi_alloc(c, 2 * (size_t)x->K, sizeof(int));
    if (!x->sorder) return hd__mpi_nomem(c, "the exchange", (size_t)x->K);
    x->tb = hd__mpi_alloc(c, x->maxr + 1, sizeof(size_t));
    x->rcnt = hd__mpi_alloc(c, x->maxr * 2 * (size_t)x->K, sizeof(int));
    if (!x->tb || !x->rcnt) return hd__mpi_nomem(c, "the exchange's rounds", x->maxr);
    return HD_OK;
}

static void xch_free_sends(hd__mpi_ctx_t *c, xch_t *x) {
    hd__mpi_free_scratch(c, x->sx, x->sendcap, 3 * sizeof(double));
    hd__mpi_free_scratch(c, x->so, x->sendcap, sizeof(uint32_t));
    hd__mpi_free_scratch(c, x->dest, x->nloc, (size_t)x->w);
    x->sx = NULL, x->so = NULL, x->dest = NULL;
}

static void xch_free(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, xch_t *x, const hd__mpi_local_t *loc) {
    int **ints[] = XCH_INTS(x);
    size_t **sizes[] = XCH_SIZES(x);
    for (int k = 0; k < (int)(sizeof ints / sizeof *ints); k++)
        hd__mpi_free(c, *ints[k], (k < XCH_INTS_2K ? 2 : 1) * (size_t)x->K, sizeof(int));
    for (int k = 0; k < (int)(sizeof sizes / sizeof *sizes); k++) hd__mpi_free(c, *sizes[k], 2 * (size_t)x->K, sizeof(size_t));
    hd__mpi_free(c, x->sorder, 2 * (size_t)x->K, sizeof(int));
    hd__mpi_free(c, x->tb, x->maxr + 1, sizeof(size_t));
    hd__mpi_free(c, x->rcnt, x->maxr * 2 * (size_t)x->K, sizeof(int));
    for (int s = 0; s < 2; s++) {
        hd__mpi_free(c, x->order[s], in->nparts[s], sizeof *x->order[s]);
        hd__mpi_free_scratch(c, x->off[s], loc->n[s], sizeof(uint32_t));
    }
    xch_free_sends(c, x);
}

/* The ranks of one part's n points (side s, first global index g0) into
 * dest from position t, K for a point that stays out (prune.c).  The
 * tree's root is copied into a local: the byte stores may alias anything,
 * and would make the compiler load the root again for every point (at
 * K = 2 the root is the whole walk). */
static void route_run(const hd__mpi_node_t *tree, int K, const hd__mpi_prune_t *cells, int s, const hd_points_t *v,
                      uint64_t g0, void *dest, int w, size_t t) {
    const double *px = hd__mpi_packed(v);
    hd__mpi_node_t root = K > 1 ? tree[0] : (hd__mpi_node_t){0};
    if (K == 2 && px && !cells && w == 1) { /* the root's two leaves: its coordinate decides but at a tie */
        uint8_t *d = (uint8_t *)dest + t, lr = (uint8_t)(-root.left - 1), rr = (uint8_t)(-root.right - 1);
        for (size_t k = 0; k < v->count; k++) {
            double c = px[3 * k + (size_t)root.axis];
            d[k] = c < root.s ? lr : c > root.s ? rr : hd__mpi_goes_left(&root, px + 3 * k, (uint64_t)s, g0 + k) ? lr : rr;
        }
        return;
    }
    for (size_t k = 0; k < v->count; k++, t++) {
        double xb[3];
        const double *pt = px ? px + 3 * k : (hd_points_get(v, k, xb), xb);
        int r = 0;
        if (cells && !hd__mpi_moves(cells, s, pt)) r = K;
        else if (K > 1) {
            int next = hd__mpi_goes_left(&root, pt, (uint64_t)s, g0 + k) ? root.left : root.right;
            while (next >= 0)
                next = hd__mpi_goes_left(&tree[next], pt, (uint64_t)s, g0 + k) ? tree[next].left : tree[next].right;
            r = -next - 1;
        }
        dest_set(dest, w, t, r);
    }
}

/* Positions [t0, t1)'s points for a rank other than me (neither me nor K,
 * out of the course): a count without a branch, which the compiler
 * vectorizes for one-byte destinations. */
static size_t others_in(const void *dest, int w, size_t t0, size_t t1, int me, int K) {
    size_t n = 0;
    if (w == 1) {
        const uint8_t *d = dest, m8 = (uint8_t)me, k8 = (uint8_t)K;
        for (size_t t = t0; t < t1; t++) n += (size_t)((d[t] != m8) & (d[t] != k8));
    } else {
        for (size_t t = t0; t < t1; t++) {
            int r = dest_get(dest, w, t);
            n += (size_t)((r != me) & (r != K));
        }
    }
    return n;
}

/* Positions counted between checks of the rounds' cuts (at most
 * ROUND_MIN, so a block holds at most one cut). */
#define PLAN_BLOCK 1024

/* The rounds' cuts (tb, nr): round q ends before the position of the
 * ((q + 1) C + 1)-th point for another rank.  Blocks are counted without a
 * branch; only a block that holds a cut is walked point by point. */
static void plan_cuts(xch_t *x) {
    size_t out = 0, q = 0, cut = x->C;
    x->tb[0] = 0;
    for (size_t b = 0; b < x->nloc; b += PLAN_BLOCK) {
        size_t e = x->nloc - b < PLAN_BLOCK ? x->nloc : b + PLAN_BLOCK, o = others_in(x->dest, x->w, b, e, x->me, x->K);
        if (out + o <= cut) {
            out += o;
            continue;
        }
        for (size_t t = b; t < e; t++) {
            int r = dest_get(x->dest, x->w, t);
            if (r == x->me || r == x->K) continue;
            if (out == cut) x->tb[++q] = t, cut += x->C;
            assert(q < x->maxr);
            out++;
        }
    }
    x->nr = q + 1;
    x->tb[x->nr] = x->nloc;
}

/* Each round's counts by (rank, side) for the other ranks (rcnt), the
 * totals to every rank (big) and the positions whose rank differs from the
 * previous position's (switches): a histogram of each round's positions of
 * each side (A's positions come first: n[0] of them). */
static void plan_counts(xch_t *x, size_t nA, size_t *hist) {
    int K = x->K, w = x->w;
    const uint8_t *d8 = x->dest;
    for (size_t t = 1; t < x->nloc; t++)
        x->switches += w == 1 ? (size_t)(d8[t] != d8[t - 1]) : (size_t)(dest_get(x->dest, w, t) != dest_get(x->dest, w, t - 1));
    for (size_t q = 0; q < x->nr; q++) {
        int *row = x->rcnt + q * 2 * (size_t)K;
        for (int s = 0; s < 2; s++) {
            size_t a = s ? nA : 0, e = s ? x->nloc : nA;
            a = a > x->tb[q] ? a : x->tb[q], e = e < x->tb[q + 1] ? e : x->tb[q + 1];
            if (a >= e) continue;
            memset(hist, 0, ((size_t)K + 1) * sizeof *hist);
            if (w == 1 && K <= 4) /* a count a rank without a branch, vectorized, for the few */
                for (int r = 0; r < K; r++) hist[r] = (e - a) - others_in(x->dest, 1, a, e, r, r);
            else if (w == 1)
                for (size_t t = a; t < e; t++) hist[d8[t]]++;
            else
                for (size_t t = a; t < e; t++) hist[dest_get(x->dest, w, t)]++;
            for (int r = 0; r < K; r++) {
                x->big[2 * r + s] += hist[r];
                if (r != x->me) row[2 * r + s] += (int)hist[r];
            }
        }
    }
}

/* The first pass: each input position's rank (dest), the totals to each
 * rank (tot), and the rounds' cuts and counts (tb, rcnt). */
static int xch_plan(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const hd__mpi_node_t *tree, xch_t *x) {
    int K = x->K, me = x->me, rc = HD_OK;
    memset(x->big, 0, 2 * (size_t)K * sizeof(size_t));
    memset(x->rcnt, 0, x->maxr * 2 * (size_t)K * sizeof(int));
    const hd__mpi_prune_t *cells = x->pr && x->pr->on ? x->pr : NULL; /* NULL: every point moves */
    size_t t = 0;
    for (int s = 0; s < 2; s++) {
        for (size_t p = 0; p < in->nparts[s]; p++) x->order[s][p] = &in->parts[s][p];
        qsort(x->order[s], in->nparts[s], sizeof *x->order[s], hd__mpi_by_offset);
        for (size_t p = 0; p < in->nparts[s]; p++) {
            route_run(tree, K, cells, s, &x->order[s][p]->points, x->order[s][p]->offset, x->dest, x->w, t);
            t += x->order[s][p]->points.count;
        }
    }
    size_t *hist = hd__mpi_alloc(c, (size_t)K + 1, sizeof *hist);
    if (!hist) return hd__mpi_nomem(c, "the exchange's counts", (size_t)K);
    plan_cuts(x);
    plan_counts(x, (size_t)in->n[0], hist);
    hd__mpi_free(c, hist, (size_t)K + 1, sizeof *hist);
    for (int k = 0; k < 2 * K; k++) {
        if (x->big[k] > INT_MAX) rc = HD_EOVERFLOW;
        x->tot[k] = x->big[k] > INT_MAX ? INT_MAX : (int)x->big[k];
    }
    if (rc != HD_OK)
        return hd__err(&c->e, HD_EOVERFLOW, "more than 2^31 - 1 points of a set to send from rank %d to one rank",
                       c->rank);
    size_t own = (size_t)x->tot[2 * me] + (size_t)x->tot[2 * me + 1];
    x->sendcap = x->nloc - own < x->C ? x->nloc - own : x->C;
    for (int r = 0; r < K; r++)
        if (r != me) c->bytes_part += ((uint64_t)x->tot[2 * r] + (uint64_t)x->tot[2 * r + 1]) * (3 * sizeof(double) + 4);
    return HD_OK;
}

typedef struct { uint64_t lo; int r; } sender_t;
static int by_lo(const void *p, const void *q) {
    const sender_t *a = p, *b = q;
    return a->lo != b->lo ? (a->lo < b->lo ? -1 : 1) : (a->r > b->r) - (a->r < b->r);
}

/* The senders of side s in the order of the smallest index each holds
 * (from the index runs; a rank without one last): their runs land in that
 * order, so when no two ranks' indices interleave (each rank's parts one
 * block, whatever the ranks' order, as hausdorff-mpi's B rotated by K/2)
 * the local arrays are in index order as received, without a merge. */
static void senders_by_index(hd__mpi_ctx_t *c, const hd__mpi_ranges_t *rg, int s, int K, int *order) {
    sender_t *t = hd__mpi_alloc(c, (size_t)K, sizeof *t);
    if (!t) { /* rank order: still correct, the merge sorts */
        for (int r = 0; r < K; r++) order[r] = r;
        return;
    }
    for (int r = 0; r < K; r++) {
        size_t a = rg->seg[(size_t)s * ((size_t)K + 1) + (size_t)r], b = rg->seg[(size_t)s * ((size_t)K + 1) + (size_t)r + 1];
        t[r] = (sender_t){a < b ? rg->all[a].lo : UINT64_MAX, r};
    }
    qsort(t, (size_t)K, sizeof *t, by_lo);
    for (int q = 0; q < K; q++) order[q] = t[q].r;
    hd__mpi_free(c, t, (size_t)K, sizeof *t);
}

/* From the totals received (rtot): where each sender's run lands (base),
 * the local arrays, their indices' code, and the send buffer. */
static int xch_local(hd__mpi_ctx_t *c, const hd__mpi_ranges_t *rg, xch_t *x, hd__mpi_local_t *loc) {
    int K = x->K, rc = HD_OK;
    for (int s = 0; s < 2 && rc == HD_OK; s++) {
        size_t m = 0;
        senders_by_index(c, rg, s, K, x->sorder + (size_t)s * (size_t)K);
        for (int q = 0; q < K; q++) {
            int r = x->sorder[(size_t)s * (size_t)K + (size_t)q];
            x->base[s * K + r] = m;
            x->got[s * K + r] = 0;
            m += (size_t)x->rtot[2 * r + s];
        }
        loc->n[s] = m;
        for (int k = 0; k < 3; k++) loc->box[s].lo[k] = INFINITY, loc->box[s].hi[k] = -INFINITY;
        if (m > INT_MAX) {
            rc = hd__err(&c->e, HD_EOVERFLOW, "more than 2^31 - 1 points of %s to receive on rank %d",
                         s ? "B" : "A", c->rank);
            loc->n[0] = loc->n[1] = 0;
        }
    }
    for (int s = 0; s < 2 && rc == HD_OK; s++) {
        loc->xyz[s] = hd__mpi_alloc(c, loc->n[s], 3 * sizeof(double));
        x->off[s] = hd__mpi_scratch(c, loc->n[s], sizeof(uint32_t));
        if (!loc->xyz[s] || !x->off[s]) rc = hd__mpi_nomem(c, "the local points", loc->n[s]);
        else rc = hd__mpi_gidx_init(c, &loc->gi[s], rg, s, loc->n[s]);
    }
    if (rc == HD_OK) {
        x->sx = hd__mpi_scratch(c, x->sendcap, 3 * sizeof(double));
        x->so = hd__mpi_scratch(c, x->sendcap, sizeof(uint32_t));
        if (!x->sx || !x->so) rc = hd__mpi_nomem(c, "points to send", x->sendcap);
    }
    return rc;
}

/* Round `round`'s positions packed into the send buffer, a part's run at a
 * time, and this rank's own points into their slots (from ownat[s] on);
 * their numbers encoded and their box taken while in the cache (as if the
 * runs were in index order, else encoded again by xch_order). */
static void xch_pack(const hd__mpi_input_t *in, const hd__mpi_ranges_t *rg, xch_t *x, hd__mpi_local_t *loc,
                     uint64_t round, walk_t *at, size_t ownat[2]) {
    int K = x->K, me = x->me;
    if (round < x->nr) memcpy(x->per, x->rcnt + round * 2 * (size_t)K, 2 * (size_t)K * sizeof(int));
    else memset(x->per, 0, 2 * (size_t)K * sizeof(int));
    int pos = 0; /* the send buffer: A's blocks by rank, then B's */
    for (int s = 0; s < 2; s++)
        for (int r = 0; r < K; r++) {
            x->sdisp[2 * r + s] = x->sfill[2 * r + s] = pos;
            pos += x->per[2 * r + s];
        }
    /* Destinations that change at more than a quarter of the points are
     * packed without a branch on them (pack_scattered): a branch mispredicted
     * at random costs more than the tables' few instructions a point, and
     * an input in space's order (tiles) is copied a run at a time
     * (mpi_bench times both orders; the figures are in docs/scale-out.md). */
    int scattered = x->switches > x->nloc / 4;
    size_t own0[2] = {ownat[0], ownat[1]};
    for (size_t t = round < x->nr ? x->tb[round] : x->nloc, t1 = round < x->nr ? x->tb[round + 1] : x->nloc; t < t1;) {
        size_t avail = walk_avail(in, x->order, at), m = t1 - t < avail ? t1 - t : avail;
        assert(avail > 0);
        int s = at->s;
        const hd_points_t *v = &x->order[s][at->p]->points;
        const double *px = hd__mpi_packed(v);
        uint32_t num = (uint32_t)at->num[s];
        if (scattered)
            pack_scattered(v, px, at->k, m, x->dest, x->w, t, me, s, num, loc->xyz[s], x->off[s], &ownat[s], x->sx,
                           x->so, x->sfill, K);
        else
            pack_runs(v, px, at->k, m, x->dest, x->w, t, me, s, num, loc->xyz[s], x->off[s], &ownat[s], x->sx, x->so,
                      x->sfill, K);
        t += m;
        at->k += m;
        at->num[s] += m;
    }
    for (int s = 0; s < 2; s++) {
        hd__mpi_gidx_put_numbers(&loc->gi[s], rg, me, own0[s], x->off[s] + own0[s], ownat[s] - own0[s]);
        box_run(&loc->box[s], loc->xyz[s] + 3 * own0[s], ownat[s] - own0[s]);
    }
}

/* Every round (as many as the rank with the most): pack, then each side's
 * blocks to their ranks, received straight into the local arrays, whose
 * numbers are encoded and box taken as they land (collective). */
static int xch_rounds(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const hd__mpi_ranges_t *rg, xch_t *x,
                      hd__mpi_local_t *loc) {
    int K = x->K, me = x->me;
    uint64_t mine = x->nr, rounds = 0;
    HD__MPI_TRY(c, MPI_Allreduce(&mine, &rounds, 1, MPI_UINT64_T, MPI_MAX, c->comm));
    walk_t at = {0, 0, 0, {0, 0}};
    size_t ownat[2] = {x->base[me], x->base[K + me]};
    for (uint64_t round = 0; round < rounds; round++) {
        xch_pack(in, rg, x, loc, round, &at, ownat);
        HD__MPI_TRY(c, MPI_Alltoall(x->per, 2, MPI_INT, x->rper, 2, MPI_INT, c->comm));
        for (int s = 0; s < 2; s++) {
            for (int r = 0; r < K; r++) {
                x->sc[r] = x->per[2 * r + s];
                x->sd[r] = x->sdisp[2 * r + s];
                x->rcn[r] = x->rper[2 * r + s];
                x->rd[r] = (int)(x->base[s * K + r] + x->got[s * K + r]);
                x->got[s * K + r] += (size_t)x->rcn[r];
            }
            HD__MPI_TRY(c, MPI_Alltoallv(x->sx, x->sc, x->sd, c->q_type, loc->xyz[s], x->rcn, x->rd, c->q_type, c->comm));
            HD__MPI_TRY(c, MPI_Alltoallv(x->so, x->sc, x->sd, MPI_UINT32_T, x->off[s], x->rcn, x->rd, MPI_UINT32_T,
                                         c->comm));
            for (int r = 0; r < K; r++)
                if (r != me) {
                    hd__mpi_gidx_put_numbers(&loc->gi[s], rg, r, (size_t)x->rd[r], x->off[s] + x->rd[r],
                                             (size_t)x->rcn[r]);
                    box_run(&loc->box[s], loc->xyz[s] + 3 * (size_t)x->rd[r], (size_t)x->rcn[r]);
                }
        }
    }
    assert(ownat[0] == x->base[me] + (size_t)x->rtot[2 * me] &&
           ownat[1] == x->base[K + me] + (size_t)x->rtot[2 * me + 1]);
    return HD_OK;
}

/* Side s's runs put in index order: when they arrived so (each rank's
 * parts above the previous rank's), the numbers were encoded as received
 * and are freed; else they become indices (8 bytes), the runs are merged
 * into index order, and the indices are encoded afresh. */
static int xch_order(hd__mpi_ctx_t *c, const hd__mpi_ranges_t *rg, xch_t *x, hd__mpi_local_t *loc, int s) {
    int K = x->K;
    size_t n = loc->n[s];
    loc->start[s] = hd__mpi_alloc(c, 2 * (size_t)K, sizeof(size_t));
    if (!loc->start[s]) return hd__mpi_nomem(c, "the local indices", (size_t)K);
    int sorted = 1;
    uint64_t last = 0;
    for (int q = 0; q < K; q++) { /* the runs in the order they land */
        int r = x->sorder[(size_t)s * (size_t)K + (size_t)q];
        size_t lo = x->base[s * K + r], hi = lo + (size_t)x->rtot[2 * r + s];
        loc->start[s][r] = lo;
        loc->start[s][K + r] = hi - lo;
        if (hi > lo) {
            if (lo > 0 && hd__mpi_ranges_global(rg, s, r, x->off[s][lo]) < last) sorted = 0;
            last = hd__mpi_ranges_global(rg, s, r, x->off[s][hi - 1]);
        }
    }
    if (!sorted) {
        loc->merged[s] = 1;
        uint64_t *g = hd__mpi_alloc(c, n, sizeof(uint64_t));
        if (!g) return hd__mpi_nomem(c, "the local indices", n);
        for (int r = 0; r < K; r++) {
            size_t lo = x->base[s * K + r], hi = lo + (size_t)x->rtot[2 * r + s],
                   i = rg->seg[(size_t)s * ((size_t)K + 1) + (size_t)r];
            hd__mpi_ranges_globals(rg, s, r, &i, x->off[s] + lo, hi - lo, g + lo);
        }
        hd__mpi_free_scratch(c, x->off[s], n, sizeof(uint32_t));
        x->off[s] = NULL;
        uint32_t *perm = hd__mpi_alloc(c, n, sizeof(uint32_t));
        run_t *runs = hd__mpi_alloc(c, (size_t)K, sizeof(run_t));
        int *heap = hd__mpi_alloc(c, (size_t)K, sizeof(int));
        int rc = perm && runs && heap ? HD_OK : hd__mpi_nomem(c, "the merge", n);
        if (rc == HD_OK) {
            for (int r = 0; r < K; r++)
                runs[r] = (run_t){x->base[s * K + r], x->base[s * K + r] + (size_t)x->rtot[2 * r + s]};
            merge_order(g, runs, K, heap, perm);
            permute(loc->xyz[s], g, perm, n);
        }
        hd__mpi_free(c, perm, n, sizeof(uint32_t));
        hd__mpi_free(c, runs, (size_t)K, sizeof(run_t));
        hd__mpi_free(c, heap, (size_t)K, sizeof(int));
        if (rc == HD_OK) {
            hd__mpi_gidx_clear(&loc->gi[s]);
            hd__mpi_gidx_put_indices(&loc->gi[s], 0, g, n);
        }
        hd__mpi_free(c, g, n, sizeof(uint64_t));
        return rc;
    }
    hd__mpi_free_scratch(c, x->off[s], n, sizeof(uint32_t));
    x->off[s] = NULL;
    return HD_OK;
}

/* Move every point to the rank of its region.  Each point goes as its
 * coordinates and a 4-byte number: its rank among the sender's points of
 * its set in index order (hd__mpi_ranges_t turns it back into the global index).
 * Each source's run is received straight into its slot of the local
 * arrays, in rounds of at most an eighth of the sender's points, so no
 * copy of all the points is ever held twice; a rank's own points are
 * copied from the input into their slot.  Runs are in index order, since
 * senders walk their parts in offset order; when the runs follow each
 * other in index order too (each rank's parts lie above the previous
 * rank's) the local arrays are in global order as received (loc->start:
 * each sender's run), else the numbers become indices and the arrays are
 * merged in place (a permutation from a K-way merge, 4 bytes a point;
 * loc->merged).  Either way loc->gi holds the indices encoded.  The
 * phases: the plan (a first pass), the totals, the local arrays, the
 * rounds, the order; every rank agrees on a status before each
 * collective. */
int hd__mpi_exchange(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const hd__mpi_ranges_t *rg,
                     const hd__mpi_node_t *tree, const hd__mpi_prune_t *pr, hd__mpi_local_t *loc) {
    xch_t x;
    int rc = xch_alloc(c, in, &x);
    x.pr = pr;
    if (rc == HD_OK) rc = xch_plan(c, in, tree, &x);
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    HD__MPI_GO(c, rc, MPI_Alltoall(x.tot, 2, MPI_INT, x.rtot, 2, MPI_INT, c->comm));
    rc = xch_local(c, rg, &x, loc);
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    if ((rc = xch_rounds(c, in, rg, &x, loc)) != HD_OK) goto done;
    xch_free_sends(c, &x);
    for (int s = 0; s < 2 && rc == HD_OK; s++) rc = xch_order(c, rg, &x, loc, s);
    rc = hd__mpi_agree(c, rc);
done:
    xch_free(c, in, &x, loc);
    return rc;
}
