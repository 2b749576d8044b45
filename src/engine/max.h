/*
 * max.h -- private to src/engine/: the running maximum shared by the
 * threads of one direction (max.c), which the walk, the grid and the pairs
 * raise together.
 */
#ifndef HD_ENGINE_MAX_H
#define HD_ENGINE_MAX_H

#include "engine/engine.h"

#include <pthread.h>

/* cmax (the bound all threads raise), and under a lock the maximum so far
 * with its canonical witness. */
typedef struct hd__max {
    hd__bound_t cmax;
    pthread_mutex_t lock;
    hd__best_t best;
    hd__keep_t keep;
} hd__max_t;

int hd__max_init(hd__max_t *m);
void hd__max_destroy(hd__max_t *m);
/* Record an exact nearest distance d2 of point i (nearest j), unless the
 * maximum's filter refuses it; *snap gets a consistent copy of the maximum
 * so far. */
void hd__max_offer(hd__max_t *m, double d2, size_t i, size_t j, hd__best_t *snap);
void hd__max_snapshot(hd__max_t *m, hd__best_t *snap);

/* Whether a point of B at squared distance d2 from point i of A proves that
 * i is not the witness: its nearest distance is then below the maximum
 * (d2 < cmax2), or at most a maximum already attained at a smaller index
 * (snap, a consistent copy of the maximum so far). */
HD__INLINE int hd__kills(double cmax2, const hd__best_t *snap, double d2, size_t i) {
    return d2 < cmax2 || (d2 <= snap->d2 && i > snap->i);
}

#endif /* HD_ENGINE_MAX_H */
