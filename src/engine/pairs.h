/*
 * pairs.h -- private to src/engine/: the correspondence path and the
 * ordered-subset shortcut (pairs.c), which the plan tries first.
 */
#ifndef HD_ENGINE_PAIRS_H
#define HD_ENGINE_PAIRS_H

#include "engine/grid.h"
#include "engine/max.h"

/* The correspondence path (pairs.c), for two sets of n points each
 * listed in the same order (a copy and its original).  hd__pairs_begin
 * tests a sample and, when the partners (a_i, b_i) look closer than other
 * neighbours, lists the pairs with the largest distances (P->active).
 * hd__pairs_resolve then resolves, for each direction d < directions, the
 * listed points of set d exactly, in decreasing order of pair distance,
 * until the rest provably cannot hold the witness (P->resolved[d]; max[d]
 * then holds h exactly): by scans of the other set while grid is NULL
 * (and a budget lasts), in grid[1 - d] otherwise.  It returns 1 when every
 * direction is resolved.  Otherwise max[d] has only been raised. */
struct hd__pair;
typedef struct hd__pairs {
    struct hd__pair *list; /* m pairs in resolution order */
    size_t m, n, pos[2];
    uint64_t scanned; /* points read by scans */
    int active, resolved[2];
} hd__pairs_t;

int hd__pairs_begin(hd__pairs_t *P, const hd__src_t src[2], size_t n, int threads,
                    hd__counts_t *counts, hd_error_t *err);
int hd__pairs_resolve(hd__pairs_t *P, const hd__src_t src[2], const hd__grid_t *grid,
                      hd__max_t *max, int directions, hd__counts_t *counts);
void hd__pairs_free(hd__pairs_t *P);

/* When the ns points of `small` appear, in order, as exact copies among the
 * nl > ns points of `large` (an ordered subset), h(small, large) = 0: offer
 * it to max with its witness and return 1; otherwise return 0 (after
 * reading at most a short window of `large` when the sets are unrelated). */
int hd__subset_resolve(const hd__src_t *small, size_t ns, const hd__src_t *large, size_t nl,
                       hd__max_t *max, hd__counts_t *counts);

#endif /* HD_ENGINE_PAIRS_H */
