/*
 * grid.h -- private to src/engine/: the grid, a cheap index for sparse
 * queries, and its pass over one direction (grid.c).
 */
#ifndef HD_ENGINE_GRID_H
#define HD_ENGINE_GRID_H

#include "engine/max.h"

/* Points grouped by the cell of a uniform grid of 2^bits cubic cells per
 * axis over the set's box; cells are numbered along the Morton curve, so
 * the cells below any node of the implicit octree over them are a
 * contiguous range, and so are their points.  Each cell keeps a
 * representative, its point with the smallest original index. */
typedef struct hd__grid {
    size_t n;
    hd__src_t src;
    int bits;             /* cells per axis: 1 << bits (at most 6) */
    double lo[3], w, inv; /* cell (cx, cy, cz) spans lo + c * w .. lo + (c + 1) * w */
    double margin;        /* widening of every face that covers all rounding */
    uint32_t *perm;       /* n original indices grouped by cell */
    uint32_t *start;      /* 8^bits + 1 offsets into perm */
    double *rep;          /* per cell x, y, z of its representative; NaN if empty */
    hd__reuse_t *pool;     /* where the arrays come from and go back to (or NULL) */
} hd__grid_t;

/* The grid's arrays come from `pool` (NULL: plain allocations). */
int hd__grid_build(hd__grid_t *g, const hd__src_t *src, size_t n, const hd__box_t *box,
                   int threads, hd__reuse_t *pool, hd_error_t *err);
/* The same with the cells a set of n_cells points would get (a sample's
 * grid as fine as its set's). */
int hd__grid_build_as(hd__grid_t *g, const hd__src_t *src, size_t n, size_t n_cells,
                      const hd__box_t *box, int threads, hd__reuse_t *pool, hd_error_t *err);
void hd__grid_free(hd__grid_t *g);

/* Exact nearest neighbour of q in g, with the early stop of hd__tree_nearest
 * (stop2, tie2).  hit->bucket is unused. */
void hd__grid_nearest(const hd__grid_t *g, const double q[3], double stop2, double tie2,
                      hd__hit_t *hit, hd__counts_t *n);

/* h(A,B) by the grid: A's cells (ga) are visited in Morton order, and a
 * cell is discarded whole when one point of B is proven strictly within
 * cmax of its whole box; the points of the other cells are tested against
 * nearby points of B and searched exactly when none discards them (when
 * cmax is below a cell's diagonal, all of A's points in input order
 * instead).  On return m holds the maximum; counts and culled are added
 * to. */
int hd__grid_directed(const hd__grid_t *ga, const hd__grid_t *gb, hd__max_t *m, int threads,
                      hd__counts_t *counts, uint64_t *culled, hd_error_t *err);

/* Prime m with the exact nearest distances of the HD__PRIME_CELLS
 * representatives of A's cells (ga) that lie where B is emptiest. */
#define HD__PRIME_CELLS 32
void hd__grid_prime(const hd__grid_t *ga, const hd__grid_t *gb, hd__max_t *m,
                    hd__counts_t *counts);
/* The representatives of A's cells farthest from a grid gs of a sample of
 * B, for when B has no grid of its own yet: their indices into A (out),
 * their number returned. */
int hd__grid_prime_picks_far(const hd__grid_t *ga, const hd__grid_t *gs, size_t out[HD__PRIME_CELLS]);

/* The same from A's points alone, before A has a grid: of every
 * `step`-th point of A, the HD__PRIME_CELLS lying where B is emptiest. */
void hd__grid_prime_sampled(const hd__src_t *a, size_t na, size_t step, const hd__grid_t *gb,
                            hd__max_t *m, hd__counts_t *counts);

/* Prime m with the exact nearest distances of points of a sample of A
 * chosen where the maximum is likely, then run the grid pass over the
 * sample; returns its work (distances and nodes) per sampled point, or
 * stops early with some value above `limit`. */
double hd__grid_trial(const hd__src_t *a, size_t na, const hd__grid_t *gb, hd__max_t *m,
                      double limit, hd__counts_t *counts);

#endif /* HD_ENGINE_GRID_H */
