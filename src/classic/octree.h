/*
 * octree.h -- the project's own octree, used by NOHD (on A), OHD (on B) and
 * INC (on both).  See octree.c for the invariants.
 */
#ifndef HD_OCTREE_H
#define HD_OCTREE_H

#include "points/points.h"

typedef struct hd__onode {
    hd__box_t box;          /* tight box of the node's points (exact) */
    double mid[3];          /* the split values of the node's cell */
    size_t begin, count;    /* its points: positions [begin, begin+count) */
    struct hd__onode *kids; /* non-empty children, by increasing octant;
                               NULL at a leaf */
    uint32_t id;            /* 0 .. nodes-1, in creation (depth-first) order */
    uint8_t nkids;
    uint8_t octant;         /* bit k: upper half of the parent's cell on axis k */
    uint8_t depth;          /* the root is at depth 0 */
} hd__onode_t;

typedef struct hd__octree {
    hd__onode_t *root;
    hd__onode_t **node; /* node[id] */
    size_t *idx;        /* idx[p]: original index of the point at position p */
    double *pts;        /* pts[3p .. 3p+2]: its coordinates (a copy) */
    size_t n, nodes, leaves;
    int max_depth;      /* the cap asked for */
    int depth;          /* the deepest node built */
    double lo[3], side; /* the root cell, the cube [lo, lo + side] */
    hd__arena_t arena;
} hd__octree_t;

/* Build an octree over n > 0 packed points.  A node is split into its
 * non-empty octants while its depth is below max_depth (0..60), it holds
 * more than leaf_size points (>= 1) and its points are not all equal.
 * Returns HD_OK or HD_ENOMEM (with err set); on failure nothing is left
 * allocated. */
int hd__octree_build(hd__octree_t *t, const double *xyz, size_t n, int max_depth,
                     size_t leaf_size, hd_error_t *err);
void hd__octree_free(hd__octree_t *t);

/* The leaf whose cell contains p, found by the same split comparisons that
 * placed the tree's points (so a point of the tree finds its own leaf), or
 * NULL when p falls into an empty octant.  Cells on the border of the root
 * cell extend outwards without limit. */
const hd__onode_t *hd__octree_locate(const hd__octree_t *t, const double *p);

/* Octant of p in a node's cell: bit k set when p[k] >= mid[k]. */
HD__INLINE unsigned hd__octant(const double *mid, const double *p) {
    return (unsigned)(p[0] >= mid[0]) | (unsigned)(p[1] >= mid[1]) << 1 |
           (unsigned)(p[2] >= mid[2]) << 2;
}

/* Smallest computed squared distance between a point of box a and a point of
 * box b (0 when they meet).  Same operation order as hd__d2: with exact
 * boxes it never exceeds hd__d2 of a point pair drawn from them. */
HD__INLINE double hd__box_box_lb2(const hd__box_t *a, const hd__box_t *b) {
    double d[3];
    for (int k = 0; k < 3; k++) {
        double v = 0.0;
        if (b->lo[k] > a->hi[k]) v = b->lo[k] - a->hi[k];
        else if (a->lo[k] > b->hi[k]) v = a->lo[k] - b->hi[k];
        d[k] = v;
    }
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
}

/* Largest computed squared distance between a point of box a and a point of
 * box b (the farthest pair of corners); never below hd__d2 of such a pair. */
HD__INLINE double hd__box_box_ub2(const hd__box_t *a, const hd__box_t *b) {
    double d[3];
    for (int k = 0; k < 3; k++) {
        double u = a->hi[k] - b->lo[k], v = b->hi[k] - a->lo[k];
        if (u < 0) u = -u;
        if (v < 0) v = -v;
        d[k] = u > v ? u : v;
    }
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
}

/* Squared length of a box's diagonal (its size, for INC's choice). */
HD__INLINE double hd__box_size2(const hd__box_t *b) {
    double d[3];
    for (int k = 0; k < 3; k++) d[k] = b->hi[k] - b->lo[k];
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
}

#endif /* HD_OCTREE_H */
