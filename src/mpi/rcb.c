/*
 * rcb.c -- the partition: recursive coordinate bisection of space by the
 * ranks' samples (step 1 of mpi.c's essay), the regions it gives, and the
 * search of the tree for the ranks a point must ask (step 5).
 *
 * Invariants.
 *  - Keys are (coordinate on the node's axis, set, global index): distinct
 *    for distinct points, since (set, index) names one point.  So a node
 *    divides its samples exactly at floor(k/2)/k even when they share a
 *    coordinate (a lattice, a roof, every point equal), and hd__mpi_goes_left,
 *    which every rank applies to every point, orders points as
 *    select_nth ordered the samples: a point goes left when its key is
 *    smaller than the split sample's.
 *  - The tree has K - 1 nodes (a node per split, leaves are ranks), built
 *    by rank 0 only and broadcast, so every rank routes every point the
 *    same way.
 *  - A rank's region is the box its ancestors' splits bound (infinite
 *    where none does).  A point on a split plane may go either way, so the
 *    faces are closed: every point of another region lies on or beyond one
 *    of the region's faces, which is what the face tests of slab.c and
 *    shell.c need.
 *  - hd__mpi_candidates lists every rank whose box of the searched set has
 *    hd__box_lb2 <= u2 (ties included); a node's box is the union of its
 *    ranks', so a subtree pruned by its box holds no candidate.
 */
#include "mpi/partition.h"

#include <assert.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The first samples: FIRST_MOST a rank, but at most FIRST_TOTAL at rank 0
 * (then FIRST_FEWEST a rank at the least).  Rank 0's tree costs time in
 * proportion to its samples times its levels and a hd__mpi_sample_t of
 * buffer a sample, all on rank 0 while the others wait, so the total is
 * capped (bench/rcb_bench.c measures the tree's time and memory).  The
 * second samples (refine) set the balance; the first only bracket each
 * split, so fewer first samples move the largest region's excess over its
 * share little (mpi_partition's balance check bounds it; the figures are
 * in docs/scale-out.md, "Fewer first samples at many ranks"). */
#define FIRST_MOST 1024
#define FIRST_FEWEST 64
#define FIRST_TOTAL 65536
#define REFINE_PER_RANK 32768 /* the second samples (refine) */
#define REFINE_BINS 64

static int key_less(const double *x, uint64_t side, uint64_t g, int axis,
                    const double *y, uint64_t yside, uint64_t yg) {
    if (x[axis] != y[axis]) return x[axis] < y[axis];
    if (side != yside) return side < yside;
    return g < yg;
}

static int sample_less(const hd__mpi_sample_t *p, const hd__mpi_sample_t *q, int axis) {
    return key_less(p->x, p->side, p->g, axis, q->x, q->side, q->g);
}

static void swap_samples(hd__mpi_sample_t *a, hd__mpi_sample_t *b) {
    hd__mpi_sample_t t = *a;
    *a = *b;
    *b = t;
}

/* Reorder s[0..n) so that s[m] is the m-th smallest key and everything
 * before it is smaller (keys are distinct: (set, index) names one point).
 * Quickselect with the median of three. */
static void select_nth(hd__mpi_sample_t *s, size_t n, size_t m, int axis) {
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

int hd__mpi_first_samples(int K) {
    int per = K > 0 ? FIRST_TOTAL / K : FIRST_MOST;
    per = per > FIRST_MOST ? FIRST_MOST : per < FIRST_FEWEST ? FIRST_FEWEST : per;
    assert(per >= FIRST_FEWEST && per <= FIRST_MOST);
    return per;
}

/* Node for k ranks r0.. over samples s[0..n); returns its id or -(r0 + 1).
 * br[2 id], br[2 id + 1]: the coordinates, on the node's axis, of the
 * samples about three standard deviations of a sample quantile either side
 * of the split (the range refine() searches; lo > hi: none). */
static int build(hd__mpi_node_t *t, double *br, int *next, hd__mpi_sample_t *s, size_t n, int r0, int k) {
    if (k == 1) return -(r0 + 1);
    int id = (*next)++, kl = k / 2;
    hd__mpi_node_t nd = {INFINITY, 0, 0, 0, 0, 0, 0}; /* no samples: all go left */
    size_t m = 0;
    br[2 * id] = INFINITY;
    br[2 * id + 1] = -INFINITY;
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
        /* Selecting within each side keeps both sides' sets of samples. */
        size_t w = (size_t)(3.0 * sqrt((double)n)) + 2;
        br[2 * id] = lo[nd.axis];
        br[2 * id + 1] = hi[nd.axis];
        if (m >= w) {
            select_nth(s, m, m - w, nd.axis);
            br[2 * id] = s[m - w].x[nd.axis];
        }
        if (n - m > w) {
            select_nth(s + m + 1, n - m - 1, w - 1, nd.axis);
            br[2 * id + 1] = s[m + w].x[nd.axis];
        }
    }
    nd.left = build(t, br, next, s, m, r0, kl);
    nd.right = build(t, br, next, s + m, n - m, r0 + kl, k - kl);
    t[id] = nd;
    return id;
}

void hd__mpi_rcb_tree(hd__mpi_sample_t *s, size_t n, int K, hd__mpi_node_t *t, double *br) {
    int next = 0;
    build(t, br, &next, s, n, 0, K);
    assert(next == K - 1);
}

/* Every rank's region: the box its splits bound (infinite elsewhere). */
void hd__mpi_regions(const hd__mpi_node_t *t, int node, hd__box_t box, hd__box_t *out) {
    if (node < 0) {
        out[-node - 1] = box;
        return;
    }
    const hd__mpi_node_t *nd = &t[node];
    hd__box_t l = box, r = box;
    if (nd->s < l.hi[nd->axis]) l.hi[nd->axis] = nd->s;
    if (nd->s > r.lo[nd->axis]) r.lo[nd->axis] = nd->s;
    hd__mpi_regions(t, nd->left, l, out);
    hd__mpi_regions(t, nd->right, r, out);
}

/* Node boxes for the candidate search: the union of its ranks' boxes of
 * the searched set (empty ranks have lo = +inf, hi = -inf). */
hd__box_t hd__mpi_node_boxes(const hd__mpi_node_t *t, int node, const hd__mpi_held_t *held, int side, hd__box_t *out) {
    if (node < 0) return held[-node - 1].box[side];
    hd__box_t b = hd__mpi_node_boxes(t, t[node].left, held, side, out);
    hd__box_t r = hd__mpi_node_boxes(t, t[node].right, held, side, out);
    hd__box_merge(&b, &r);
    out[node] = b;
    return b;
}

/* Ranks other than `me` whose box of the searched set may hold a point
 * within u2 of p (ties included), appended to list. */
void hd__mpi_candidates(const hd__mpi_node_t *t, const hd__box_t *nbox, const hd__mpi_held_t *held, int side, int node,
                       const double *p, double u2, int me, int *list, int *n) {
    if (node < 0) {
        int r = -node - 1;
        if (r != me && held[r].n[side] && hd__box_lb2(&held[r].box[side], p) <= u2) list[(*n)++] = r;
        return;
    }
    if (hd__box_lb2(&nbox[node], p) > u2) return;
    hd__mpi_candidates(t, nbox, held, side, t[node].left, p, u2, me, list, n);
    hd__mpi_candidates(t, nbox, held, side, t[node].right, p, u2, me, list, n);
}

int hd__mpi_asked(const hd__mpi_node_t *t, const hd__box_t *nbox, const hd__mpi_held_t *held, int K, int side, int none_here,
                  const double *p, double u2, int me, int *list) {
    double bound = u2;
    if (none_here)
        for (int r = 0; r < K; r++)
            if (held[r].n[side]) {
                double ub = hd__box_ub2(&held[r].box[side], p);
                if (ub < bound) bound = ub;
            }
    int n = 0;
    if (K > 1) hd__mpi_candidates(t, nbox, held, side, 0, p, bound, me, list, &n);
    return n;
}

/* ns samples of this rank's nloc points (A's parts in order, then B's:
 * local point t is the t-th of them), evenly spaced, into out, without
 * those that stay out (pr, prune.c: the regions balance the points that
 * move), but at least the first when every one stays out; returns how
 * many were taken. */
static size_t take_samples(const hd__mpi_input_t *in, const hd__mpi_prune_t *pr, uint64_t nloc, size_t ns,
                           hd__mpi_sample_t *out) {
    size_t taken = 0;
    int side = 0;
    size_t part = 0;
    uint64_t base = 0; /* local number of the part's first point */
    for (size_t t = 0; t < ns; t++) {
        uint64_t at = (uint64_t)(((double)t + 0.5) * (double)nloc / (double)ns);
        if (at >= nloc) at = nloc - 1;
        /* at grows with t: the part that holds it is this one or a later one */
        while (part >= in->nparts[side] || at - base >= in->parts[side][part].points.count) {
            if (part < in->nparts[side]) base += in->parts[side][part++].points.count;
            else side++, part = 0;
        }
        const hd_mpi_part_t *p = &in->parts[side][part];
        hd__mpi_sample_t *o = &out[taken];
        hd__mpi_get_point(&p->points, (size_t)(at - base), o->x);
        o->g = p->offset + (at - base);
        o->side = (uint64_t)side;
        taken += hd__mpi_moves(pr, side, o->x) || (taken == 0 && t + 1 == ns);
    }
    return taken;
}

/* How many of this rank's nloc points to sample, when the job samples
 * `rate` of its points: at least one from a rank that has points. */
static size_t sample_count(uint64_t nloc, double rate) {
    size_t ns = (size_t)(rate * (double)nloc + 0.5);
    if (ns > nloc) ns = (size_t)nloc;
    if (ns == 0 && nloc > 0) ns = 1;
    return ns;
}

/* Node id's depth and number of ranks (leaves) below it. */
static int shape(const hd__mpi_node_t *t, int node, int depth, int *dep, int *ranks) {
    if (node < 0) return 1;
    dep[node] = depth;
    ranks[node] = shape(t, t[node].left, depth + 1, dep, ranks) + shape(t, t[node].right, depth + 1, dep, ranks);
    return ranks[node];
}

/* Edge j of node id's REFINE_BINS bins over [lo, hi]: nondecreasing in j,
 * the same double on every rank. */
static double edge(const double *br, int id, int j) {
    double lo = br[2 * id], hi = br[2 * id + 1];
    return j == REFINE_BINS ? hi : lo + (hi - lo) * ((double)j / REFINE_BINS);
}

/* The second step of the partition.  Rank 0's tree divides the first
 * samples (c->first a rank, 64-1024) exactly, but a sample quantile is off
 * the true one by about a standard deviation of 1 / (2 sqrt(samples)) of
 * the node's points, and the largest of K regions a few times that
 * (mpi_bench's imbalance, docs/scale-out.md); four times more with 64
 * samples than with 1024.  So each split is moved, level by
 * level from the root, to the best of REFINE_BINS + 1 planes spread over
 * its bracket (build) or kept, judged by exact counts of a second, larger
 * sample (REFINE_PER_RANK a rank, at most a quarter of the points) routed
 * through the tree as refined so far: one all-reduce of REFINE_BINS + 3
 * counts a node per level, no gather.  A plane at coordinate e is the key
 * (e, 0, 0): a point goes left when its coordinate is below e.
 * Invariants: every rank decides from the same summed counts with the same
 * arithmetic, so the tree stays identical on all ranks; a split moves only
 * to a candidate that divides the second sample strictly closer to
 * floor(k/2)/k than the split it replaces (never worse on what it
 * measures); any split is a valid partition, so the result never depends
 * on it, only the balance does. */
static int refine(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const hd__mpi_prune_t *pr, uint64_t N, hd__mpi_node_t *tree,
                  const double *br) {
    int rc = HD_OK, K = c->K, nodes = K - 1;
    uint64_t nloc = in->n[0] + in->n[1];
    double rate = (double)REFINE_PER_RANK * K / (double)N;
    if (rate > 0.25) rate = 0.25;
    if (rate * (double)N <= 2.0 * c->first * K) return HD_OK; /* no more than the first samples */
    size_t ns = sample_count(nloc, rate), width = REFINE_BINS + 3;
    hd__mpi_sample_t *r = hd__mpi_alloc(c, ns, sizeof(hd__mpi_sample_t));
    int *dep = hd__mpi_alloc(c, 3 * (size_t)nodes, sizeof(int));
    int *at = hd__mpi_alloc(c, ns, sizeof(int)); /* each sample's node at the current depth */
    uint64_t *cnt = hd__mpi_alloc(c, 2 * (size_t)nodes * width, sizeof(uint64_t));
    double *edges = hd__mpi_alloc(c, (size_t)nodes * (REFINE_BINS + 1), sizeof(double));
    if (!r || !dep || !at || !cnt || !edges) rc = hd__mpi_nomem(c, "the partition's second samples", ns);
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    size_t nr = take_samples(in, pr, nloc, ns, r); /* ns stays the arrays' size */
    int *ranks = dep + nodes, *slot = dep + 2 * (size_t)nodes; /* slot: index among its depth's nodes */
    shape(tree, 0, 0, dep, ranks);
    for (size_t q = 0; q < nr; q++) at[q] = 0;
    for (int depth = 0;; depth++) {
        int level = 0;
        for (int id = 0; id < nodes; id++) {
            slot[id] = dep[id] == depth ? level++ : -1;
            for (int j = 0; slot[id] >= 0 && j <= REFINE_BINS; j++)
                edges[(size_t)id * (REFINE_BINS + 1) + (size_t)j] = edge(br, id, j);
        }
        if (!level) break;
        uint64_t *sum = cnt + (size_t)level * width;
        memset(cnt, 0, (size_t)level * width * sizeof *cnt);
        for (size_t q = 0; q < nr; q++) {
            int id = at[q];
            if (id < 0) continue;
            assert(slot[id] >= 0);
            const hd__mpi_node_t *nd = &tree[id];
            uint64_t *h = cnt + (size_t)slot[id] * width;
            double v = r[q].x[nd->axis];
            const double *e = edges + (size_t)id * (REFINE_BINS + 1);
            int lo = 0, hi = REFINE_BINS + 1; /* how many edges are <= v: in [lo, hi] */
            if (br[2 * id] > br[2 * id + 1] || v < e[0]) hi = 0; /* most are outside the bracket */
            else if (v >= e[REFINE_BINS]) lo = hi;
            else
                while (lo < hi) {
                    int mid = (lo + hi) / 2;
                    if (e[mid] <= v) lo = mid + 1;
                    else hi = mid;
                }
            h[lo]++;
            h[REFINE_BINS + 2] += (uint64_t)hd__mpi_goes_left(nd, r[q].x, r[q].side, r[q].g);
        }
        HD__MPI_GO(c, rc, MPI_Allreduce(cnt, sum, (int)((size_t)level * width), MPI_UINT64_T, MPI_SUM, c->comm));
        c->bytes_part += (uint64_t)level * width * sizeof *cnt; /* what this rank contributed */
        for (int id = 0; id < nodes; id++) {
            if (slot[id] < 0 || br[2 * id] > br[2 * id + 1]) continue; /* no bracket: no samples (s infinite) */
            const uint64_t *h = sum + (size_t)slot[id] * width;
            uint64_t total = 0;
            for (int t = 0; t <= REFINE_BINS + 1; t++) total += h[t];
            double want = (double)total * (double)(ranks[id] / 2) / (double)ranks[id];
            double best = fabs((double)h[REFINE_BINS + 2] - want);
            uint64_t left = 0;
            int pick = -1;
            for (int j = 0; j <= REFINE_BINS; j++) {
                left += h[j]; /* points below edge j */
                if (fabs((double)left - want) < best) best = fabs((double)left - want), pick = j;
            }
            if (pick >= 0) {
                tree[id].s = edges[(size_t)id * (REFINE_BINS + 1) + (size_t)pick];
                tree[id].side = 0;
                tree[id].g = 0;
            }
        }
        for (size_t q = 0; q < nr; q++)
            if (at[q] >= 0) {
                const hd__mpi_node_t *nd = &tree[at[q]];
                at[q] = hd__mpi_goes_left(nd, r[q].x, r[q].side, r[q].g) ? nd->left : nd->right;
            }
    }
done:
    hd__mpi_free(c, r, ns, sizeof(hd__mpi_sample_t));
    hd__mpi_free(c, dep, 3 * (size_t)nodes, sizeof(int));
    hd__mpi_free(c, at, ns, sizeof(int));
    hd__mpi_free(c, cnt, 2 * (size_t)nodes * width, sizeof(uint64_t));
    hd__mpi_free(c, edges, (size_t)nodes * (REFINE_BINS + 1), sizeof(double));
    return rc;
}

/* Rank 0 builds the RCB tree from everyone's first samples (c->first a
 * rank); all get it, and refine() then moves its splits by a second
 * sample's exact counts. */
int hd__mpi_partition(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const hd__mpi_prune_t *pr, uint64_t N,
                      hd__mpi_node_t *tree) {
    int rc = HD_OK, K = c->K;
    uint64_t nloc = in->n[0] + in->n[1];
    uint64_t S = (uint64_t)c->first * (uint64_t)K;
    if (S > N) S = N;
    size_t ns = sample_count(nloc, (double)S / (double)N);
    hd__mpi_sample_t *mine = hd__mpi_alloc(c, ns, sizeof(hd__mpi_sample_t));
    int *counts = hd__mpi_alloc(c, 2 * (size_t)K, sizeof(int));
    double *br = hd__mpi_alloc(c, 2 * (size_t)K, sizeof(double));
    if (!mine || !counts || !br) rc = hd__mpi_nomem(c, "samples", ns);
    if (rc == HD_OK && ns > INT_MAX / 64) rc = hd__err(&c->e, HD_EOVERFLOW, "too many samples");
    size_t nt = rc == HD_OK ? take_samples(in, pr, nloc, ns, mine) : 0;
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    int n = (int)nt;
    HD__MPI_GO(c, rc, MPI_Gather(&n, 1, MPI_INT, counts, 1, MPI_INT, 0, c->comm));
    size_t total = 0;
    hd__mpi_sample_t *all = NULL;
    if (c->rank == 0) {
        for (int r = 0; r < K; r++) {
            counts[K + r] = (int)total;
            total += (size_t)counts[r];
        }
        all = hd__mpi_alloc(c, total, sizeof(hd__mpi_sample_t));
        if (!all) rc = hd__mpi_nomem(c, "samples", total);
    }
    if ((rc = hd__mpi_agree(c, rc)) == HD_OK) {
        double mpi_t0_;
        int mpi_rc_,
            e = HD__MPI_TIMED(c, MPI_Gatherv(mine, n, c->sample_type, all, counts, counts + K, c->sample_type, 0, c->comm));
        if (e != MPI_SUCCESS) rc = hd__mpi_failed(c, "MPI_Gatherv", e);
        c->bytes_part += c->rank ? (uint64_t)nt * sizeof(hd__mpi_sample_t) : 0;
        if (rc == HD_OK && c->rank == 0) hd__mpi_rcb_tree(all, total, K, tree, br);
    }
    if (c->rank == 0) hd__mpi_free(c, all, total, sizeof(hd__mpi_sample_t));
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    if (K > 1) HD__MPI_GO(c, rc, MPI_Bcast(tree, K - 1, c->node_type, 0, c->comm));
    if (K > 1) HD__MPI_GO(c, rc, MPI_Bcast(br, 2 * (K - 1), MPI_DOUBLE, 0, c->comm));
    if (K > 1) rc = refine(c, in, pr, N, tree, br);
done:
    hd__mpi_free(c, br, 2 * (size_t)K, sizeof(double));
    hd__mpi_free(c, mine, ns, sizeof(hd__mpi_sample_t));
    hd__mpi_free(c, counts, 2 * (size_t)K, sizeof(int));
    return rc;
}
