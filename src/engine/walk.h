/*
 * walk.h -- private to src/engine/: the walk over two bucket trees for one
 * direction (walk.c), which the plan (engine.c) runs.
 */
#ifndef HD_ENGINE_WALK_H
#define HD_ENGINE_WALK_H

#include "engine/max.h"

/* The tree walk of h(A,B) over built trees ta and tb, into the shared
 * maximum m, with `threads` threads: first the nearest distances of the
 * nseed points seed[] of A (and of points spread over A's tree), then
 * every bucket of A.  counts and culled are added to. */
int hd__walk_directed(const hd__tree_t *ta, const hd__tree_t *tb, hd__max_t *m, int threads,
                      const size_t *seed, int nseed, hd__counts_t *counts, uint64_t *culled,
                      hd_error_t *err);

#endif /* HD_ENGINE_WALK_H */
