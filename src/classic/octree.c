/*
 * octree.c -- a regular octree over a point set, with exact node boxes.
 *
 * The paper builds its octrees with PCL (Section 6); this is our own, with
 * the same shape: the root cell is the cube [lo, lo + side] on the points'
 * bounding box (side = its longest extent), and a cell at depth d is split at
 * its centre into eight cells of side side * 2^-(d+1).  The split values of a
 * node (`mid`) are computed once, as doubles, and every point is sent to the
 * octant given by the comparisons p[k] >= mid[k] (hd__octant); locating a
 * query point later uses the same stored values and the same comparisons, so
 * a point of the tree always finds its own leaf.
 *
 * The bounds the algorithms prune with are never taken from the cells: each
 * node carries the tight bounding box of its own points, made of their
 * coordinates.  A box that encloses its points exactly gives, through the
 * monotone-rounding argument in points/points.h, a computed lower bound no larger
 * and an upper bound no smaller than the computed hd__d2 to each of them.
 * (A cell's faces are rounded sums and need not enclose the points they
 * were meant to: that is why they only steer the descent.)
 *
 * Invariants, checked by tests/internal/test_octree.c:
 *  - the positions [begin, begin + count) of a node are the disjoint union of
 *    its children's, children listed by increasing octant, and idx is a
 *    permutation of 0..n-1; pts holds the points in that order, so a leaf's
 *    points are contiguous in memory;
 *  - within a leaf the points keep their original order (the partition is
 *    stable);
 *  - a node is a leaf when it reached max_depth, holds at most leaf_size
 *    points, or all its points are equal (a zero-extent box): this is also
 *    what stops the subdivision of coincident points (OHD with AHD = 0);
 *  - nodes come from an arena, and node[id] lists them in depth-first order.
 */
#include "classic/classic_int.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    hd__octree_t *t;
    size_t leaf_size;
    size_t *tmp_idx;
    double *tmp_pts;
    size_t node_cap;
} build_t;

static int add_node(build_t *b, hd__onode_t *nd) {
    hd__octree_t *t = b->t;
    if (t->nodes == UINT32_MAX) return HD_EOVERFLOW;
    if (t->nodes == b->node_cap) {
        size_t cap = b->node_cap ? 2 * b->node_cap : 64;
        hd__onode_t **p = hd__realloc_array(t->node, cap, sizeof *p);
        if (!p) return HD_ENOMEM;
        t->node = p;
        b->node_cap = cap;
    }
    nd->id = (uint32_t)t->nodes;
    t->node[t->nodes++] = nd;
    return HD_OK;
}

static int all_equal(const hd__box_t *b) {
    return b->lo[0] == b->hi[0] && b->lo[1] == b->hi[1] && b->lo[2] == b->hi[2];
}

static void box_add(hd__box_t *b, const double *p) {
    for (int k = 0; k < 3; k++) {
        if (p[k] < b->lo[k]) b->lo[k] = p[k];
        if (p[k] > b->hi[k]) b->hi[k] = p[k];
    }
}

/* Fill node `nd` (begin, count, box, octant and depth already set) and its
 * subtree; cell_lo is the low corner of its cell.  A child's tight box is
 * gathered while its points are moved into place. */
static int build_node(build_t *b, hd__onode_t *nd, const double cell_lo[3]) {
    hd__octree_t *t = b->t;
    int rc = add_node(b, nd);
    if (rc != HD_OK) return rc;
    nd->kids = NULL;
    nd->nkids = 0;
    if (nd->depth > t->depth) t->depth = nd->depth;
    double half = ldexp(t->side, -(nd->depth + 1));
    for (int k = 0; k < 3; k++) nd->mid[k] = cell_lo[k] + half;
    if (nd->depth >= t->max_depth || nd->count <= b->leaf_size || all_equal(&nd->box)) {
        t->leaves++;
        return HD_OK;
    }
    /* Stable counting sort of the node's points by octant. */
    size_t cnt[8] = {0}, start[8], pos[8];
    for (size_t p = nd->begin; p < nd->begin + nd->count; p++)
        cnt[hd__octant(nd->mid, t->pts + 3 * p)]++;
    size_t s = nd->begin;
    int nk = 0;
    for (int o = 0; o < 8; o++) {
        start[o] = pos[o] = s;
        s += cnt[o];
        nk += cnt[o] != 0;
    }
    hd__box_t kbox[8];
    for (size_t p = nd->begin; p < nd->begin + nd->count; p++) {
        const double *x = t->pts + 3 * p;
        unsigned o = hd__octant(nd->mid, x);
        size_t q = pos[o]++;
        if (q == start[o]) {
            for (int k = 0; k < 3; k++) kbox[o].lo[k] = kbox[o].hi[k] = x[k];
        } else {
            box_add(&kbox[o], x);
        }
        b->tmp_idx[q] = t->idx[p];
        memcpy(b->tmp_pts + 3 * q, x, 3 * sizeof(double));
    }
    memcpy(t->idx + nd->begin, b->tmp_idx + nd->begin, nd->count * sizeof(size_t));
    memcpy(t->pts + 3 * nd->begin, b->tmp_pts + 3 * nd->begin, nd->count * 3 * sizeof(double));

    hd__onode_t *kids = hd__arena_alloc(&t->arena, (size_t)nk * sizeof *kids);
    if (!kids) return HD_ENOMEM;
    nd->kids = kids;
    nd->nkids = (uint8_t)nk;
    int k = 0;
    for (unsigned o = 0; o < 8; o++) {
        if (!cnt[o]) continue;
        hd__onode_t *c = &kids[k++];
        c->begin = start[o];
        c->count = cnt[o];
        c->box = kbox[o];
        c->octant = (uint8_t)o;
        c->depth = (uint8_t)(nd->depth + 1);
        double lo[3];
        for (int a = 0; a < 3; a++) lo[a] = (o >> a & 1u) ? nd->mid[a] : cell_lo[a];
        if ((rc = build_node(b, c, lo)) != HD_OK) return rc;
    }
    return HD_OK;
}

int hd__octree_build(hd__octree_t *t, const double *xyz, size_t n, int max_depth,
                     size_t leaf_size, hd_error_t *err) {
    memset(t, 0, sizeof *t);
    hd__arena_init(&t->arena, 64 * 1024);
    if (n == 0 || max_depth < 0 || max_depth > 60 || leaf_size < 1)
        return hd__err(err, HD_EINVAL, "octree: bad parameters (n=%zu, depth=%d, leaf=%zu)", n,
                       max_depth, leaf_size);
    t->n = n;
    t->max_depth = max_depth;
    build_t b = {t, leaf_size, NULL, NULL, 0};
    t->idx = hd__malloc_array(n, sizeof *t->idx);
    t->pts = hd__malloc_array(n, 3 * sizeof(double));
    b.tmp_idx = hd__malloc_array(n, sizeof *b.tmp_idx);
    b.tmp_pts = hd__malloc_array(n, 3 * sizeof(double));
    int rc = HD_ENOMEM;
    if (t->idx && t->pts && b.tmp_idx && b.tmp_pts) {
        for (size_t p = 0; p < n; p++) t->idx[p] = p;
        memcpy(t->pts, xyz, n * 3 * sizeof(double));
        hd__box_t box;
        hd__box_of(xyz, n, &box);
        t->side = 0.0;
        for (int k = 0; k < 3; k++) {
            t->lo[k] = box.lo[k];
            double e = box.hi[k] - box.lo[k];
            if (e > t->side) t->side = e;
        }
        t->root = hd__arena_alloc(&t->arena, sizeof *t->root);
        if (t->root) {
            t->root->box = box;
            t->root->begin = 0;
            t->root->count = n;
            t->root->octant = 0;
            t->root->depth = 0;
            rc = build_node(&b, t->root, t->lo);
        }
    }
    free(b.tmp_idx);
    free(b.tmp_pts);
    if (rc != HD_OK) {
        hd__octree_free(t);
        if (rc == HD_EOVERFLOW) return hd__err(err, rc, "octree: more than 2^32 nodes");
        return hd__err(err, HD_ENOMEM, "octree: out of memory for %zu points", n);
    }
    return HD_OK;
}

void hd__octree_free(hd__octree_t *t) {
    free(t->idx);
    free(t->pts);
    free(t->node);
    hd__arena_free(&t->arena);
    t->idx = NULL;
    t->pts = NULL;
    t->node = NULL;
    t->root = NULL;
}

const hd__onode_t *hd__octree_locate(const hd__octree_t *t, const double *p) {
    const hd__onode_t *nd = t->root;
    while (nd && nd->kids) {
        unsigned o = hd__octant(nd->mid, p);
        const hd__onode_t *next = NULL;
        for (int k = 0; k < nd->nkids; k++)
            if (nd->kids[k].octant == o) {
                next = &nd->kids[k];
                break;
            }
        nd = next;
    }
    return nd;
}
