/*
 * partition.h -- private to src/mpi/: the partition of space into the
 * ranks' regions (rcb.c) and the exchange that moves every point to its
 * region's rank (exchange.c).
 *
 * Conventions of every function here: a hd__mpi_ctx_t carries the call's
 * communicator, its error (c->e, what hd__mpi_agree() broadcasts) and its
 * count of bytes held (every buffer through hd__mpi_alloc/hd__mpi_free, so
 * the peak is known and the call can assert that it freed everything); a
 * function that can fail returns an HD_* code with c->e set, and collective
 * functions agree on a status before every collective a failed rank would
 * not reach.
 */
#ifndef HD_MPI_PARTITION_H
#define HD_MPI_PARTITION_H

#include "mpi/ranges.h"

/* ---- the partition (rcb.c) and the exchange (exchange.c) ----------------- */

/* ---- the points that stay (prune.c) ---------------------------------------- */

/* Cells a side of each set's global box. */
#define HD__MPI_CELLS 8
typedef struct {
    int on;                  /* 0: every point moves */
    hd__box_t gbox[2];       /* each set's global box */
    double inv[2][3];        /* cells per unit of each axis (0: a flat axis) */
    unsigned char keep[2][HD__MPI_CELLS * HD__MPI_CELLS * HD__MPI_CELLS]; /* the cells whose points move */
} hd__mpi_prune_t;

/* The cell of point x of set s (the same arithmetic wherever asked). */
static inline int hd__mpi_cell(const hd__mpi_prune_t *pr, int s, const double *x) {
    int c = 0;
    for (int a = 2; a >= 0; a--) {
        double f = (x[a] - pr->gbox[s].lo[a]) * pr->inv[s][a];
        int i = f > 0 ? (int)f : 0;
        i = i < HD__MPI_CELLS ? i : HD__MPI_CELLS - 1;
        c = c * HD__MPI_CELLS + i;
    }
    return c;
}

/* Whether point x of set s moves (every point when the pruning is off). */
static inline int hd__mpi_moves(const hd__mpi_prune_t *pr, int s, const double *x) {
    return !pr || !pr->on || pr->keep[s][hd__mpi_cell(pr, s, x)];
}

/* The cells whose points may change the Hausdorff distance (both: the
 * symmetric one, else A's directed one), from each set's global box
 * (corners as hd__mpi_begin gives them), every cell's box and a sample of
 * each set (collective; prune.c states the bounds). */
int hd__mpi_prune(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const uint64_t N[2], const double corners[2][6], int both,
                  hd__mpi_prune_t *pr);

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
int hd__mpi_partition(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const hd__mpi_prune_t *pr, uint64_t N,
                      hd__mpi_node_t *tree);
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
    size_t *start[2];        /* else 2K a side: where sender r's run starts
                                (start[s][r]) and its length (start[s][K + r]);
                                the runs lie in the order of the senders'
                                smallest indices (exchange.c) */
    size_t n[2];
} hd__mpi_local_t;

/* pr: the points that stay (NULL: every point moves). */
int hd__mpi_exchange(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const hd__mpi_ranges_t *rg, const hd__mpi_node_t *tree,
                     const hd__mpi_prune_t *pr, hd__mpi_local_t *loc);

#endif /* HD_MPI_PARTITION_H */
