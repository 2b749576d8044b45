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
#include "mpi_int.h"

#include <limits.h>
#include <stdlib.h>

#define SAMPLES_PER_RANK 1024

static int key_less(const double *x, uint64_t side, uint64_t g, int axis,
                    const double *y, uint64_t yside, uint64_t yg) {
    if (x[axis] != y[axis]) return x[axis] < y[axis];
    if (side != yside) return side < yside;
    return g < yg;
}

static int sample_less(const sample_t *p, const sample_t *q, int axis) {
    return key_less(p->x, p->side, p->g, axis, q->x, q->side, q->g);
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
void hd__mpi_regions(const node_t *t, int node, hd__box_t box, hd__box_t *out) {
    if (node < 0) {
        out[-node - 1] = box;
        return;
    }
    const node_t *nd = &t[node];
    hd__box_t l = box, r = box;
    if (nd->s < l.hi[nd->axis]) l.hi[nd->axis] = nd->s;
    if (nd->s > r.lo[nd->axis]) r.lo[nd->axis] = nd->s;
    hd__mpi_regions(t, nd->left, l, out);
    hd__mpi_regions(t, nd->right, r, out);
}

/* Node boxes for the candidate search: the union of its ranks' boxes of
 * the searched set (empty ranks have lo = +inf, hi = -inf). */
hd__box_t hd__mpi_node_boxes(const node_t *t, int node, const held_t *held, int side, hd__box_t *out) {
    if (node < 0) return held[-node - 1].box[side];
    hd__box_t b = hd__mpi_node_boxes(t, t[node].left, held, side, out);
    hd__box_t r = hd__mpi_node_boxes(t, t[node].right, held, side, out);
    hd__box_merge(&b, &r);
    out[node] = b;
    return b;
}

/* Ranks other than `me` whose box of the searched set may hold a point
 * within u2 of p (ties included), appended to list. */
void hd__mpi_candidates(const node_t *t, const hd__box_t *nbox, const held_t *held, int side, int node,
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

int hd__mpi_asked(const node_t *t, const hd__box_t *nbox, const held_t *held, int K, int side, int none_here,
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

/* Rank 0 builds the RCB tree from everyone's samples; all get it. */
int hd__mpi_partition(ctx_t *c, const input_t *in, uint64_t N, node_t *tree) {
    int rc = HD_OK, K = c->K;
    uint64_t nloc = in->n[0] + in->n[1];
    uint64_t S = N < (uint64_t)SAMPLES_PER_RANK * (uint64_t)K ? N : (uint64_t)SAMPLES_PER_RANK * (uint64_t)K;
    size_t ns = (size_t)((double)S * (double)nloc / (double)N);
    if (ns > nloc) ns = (size_t)nloc;
    if (ns == 0 && nloc > 0) ns = 1;
    sample_t *mine = hd__mpi_alloc(c, ns, sizeof(sample_t));
    int *counts = hd__mpi_alloc(c, 2 * (size_t)K, sizeof(int));
    if (!mine || !counts) rc = hd__mpi_nomem(c, "samples", ns);
    if (rc == HD_OK && ns > INT_MAX / 64) rc = hd__err(&c->e, HD_EOVERFLOW, "too many samples");
    for (size_t t = 0; t < ns && rc == HD_OK; t++) {
        uint64_t at = (uint64_t)(((double)t + 0.5) * (double)nloc / (double)ns);
        if (at >= nloc) at = nloc - 1;
        cursor_t cu = {0, 0, 0};
        cursor_seek(in, at, &cu);
        const hd_mpi_part_t *p = &in->parts[cu.side][cu.part];
        hd__mpi_get_point(&p->points, cu.k, mine[t].x);
        mine[t].g = p->offset + cu.k;
        mine[t].side = (uint64_t)cu.side;
    }
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    int n = (int)ns;
    MPI_GO(c, rc, MPI_Gather(&n, 1, MPI_INT, counts, 1, MPI_INT, 0, c->comm));
    size_t total = 0;
    sample_t *all = NULL;
    if (c->rank == 0) {
        for (int r = 0; r < K; r++) {
            counts[K + r] = (int)total;
            total += (size_t)counts[r];
        }
        all = hd__mpi_alloc(c, total, sizeof(sample_t));
        if (!all) rc = hd__mpi_nomem(c, "samples", total);
    }
    if ((rc = hd__mpi_agree(c, rc)) == HD_OK) {
        double mpi_t0_;
        int mpi_rc_,
            e = MPI_TIMED(c, MPI_Gatherv(mine, n, c->sample_type, all, counts, counts + K, c->sample_type, 0, c->comm));
        if (e != MPI_SUCCESS) rc = hd__mpi_failed(c, "MPI_Gatherv", e);
        c->bytes_part += c->rank ? (uint64_t)ns * sizeof(sample_t) : 0;
        if (rc == HD_OK && c->rank == 0) {
            int next = 0;
            build(tree, &next, all, total, 0, K);
        }
    }
    if (c->rank == 0) hd__mpi_free(c, all, total, sizeof(sample_t));
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    if (K > 1) MPI_GO(c, rc, MPI_Bcast(tree, K - 1, c->node_type, 0, c->comm));
done:
    hd__mpi_free(c, mine, ns, sizeof(sample_t));
    hd__mpi_free(c, counts, 2 * (size_t)K, sizeof(int));
    return rc;
}
