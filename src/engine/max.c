/*
 * max.c -- the running maximum shared by the threads of one direction.
 *
 * Threads offer (d2, i, j) as they resolve points; the maximum keeps the
 * largest d2 and, on a tie, the smallest i (hd__best_offer), so the witness
 * does not depend on which thread offered first.  A snapshot is a copy
 * taken under the lock; it only grows, so a stale snapshot is a smaller,
 * still valid lower bound for pruning (hd__kills).  The tree walk
 * (engine.c), the grid (grid.c) and the partner pairs (pairs.c) all share
 * it; it lives here so that none of them depends on another for it.
 * A filter (hd__keep_t) may refuse a point: it then raises neither the
 * maximum nor the bound, so the others are pruned only against points
 * kept.
 */
#include "engine/max.h"

#include <assert.h>

int hd__max_init(hd__max_t *m) {
    hd__bound_init(&m->cmax, 0.0);
    hd__best_init(&m->best);
    m->keep = (hd__keep_t){NULL, NULL};
    return pthread_mutex_init(&m->lock, NULL) == 0 ? HD_OK : HD_ETHREAD;
}

void hd__max_destroy(hd__max_t *m) { pthread_mutex_destroy(&m->lock); }

void hd__max_offer(hd__max_t *m, double d2, size_t i, size_t j, hd__best_t *snap) {
    /* A squared distance of a real point (-1 would read as "nothing yet"). */
    assert(!(d2 < 0) && i != HD__NONE);
    pthread_mutex_lock(&m->lock);
    int kept = !m->keep.keep || m->keep.keep(m->keep.ctx, i, d2, j);
    if (kept) hd__best_offer(&m->best, d2, i, j);
    if (snap) *snap = m->best;
    pthread_mutex_unlock(&m->lock);
    if (kept) hd__bound_raise(&m->cmax, d2);
}

void hd__max_snapshot(hd__max_t *m, hd__best_t *snap) {
    pthread_mutex_lock(&m->lock);
    *snap = m->best;
    pthread_mutex_unlock(&m->lock);
}

