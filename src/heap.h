/*
 * heap.h -- a binary heap of (key, payload) pairs, usable as a max-queue
 * (NOHD's decreasing priority queue, INC's queue of A entries) or as a
 * min-queue (OHD's ascending queue in NNDist).
 *
 * The order is total and deterministic: a larger key comes first in a
 * max-heap, a smaller key first in a min-heap, and equal keys come out by
 * increasing payload in both.  Payloads are small integers chosen by the
 * caller (node ids, entry slots), so two runs on the same input pop entries
 * in the same order and report the same counters.
 */
#ifndef HD_HEAP_H
#define HD_HEAP_H

#include <stddef.h>
#include <stdint.h>

typedef struct hd__heap_item {
    double key;
    uint64_t val;
} hd__heap_item_t;

typedef struct hd__heap {
    hd__heap_item_t *a;
    size_t n, cap;
    int max_first; /* 1: largest key first; 0: smallest key first */
} hd__heap_t;

/* An empty heap; nothing is allocated until the first push or reserve. */
void hd__heap_init(hd__heap_t *h, int max_first);
/* Make room for `cap` items, so that the next pushes up to that size cannot
 * fail.  Returns HD_OK or HD_ENOMEM. */
int hd__heap_reserve(hd__heap_t *h, size_t cap);
/* Insert an item, growing the storage when needed: HD_OK or HD_ENOMEM. */
int hd__heap_push(hd__heap_t *h, double key, uint64_t val);
/* Remove and return the first item; the heap must not be empty. */
hd__heap_item_t hd__heap_pop(hd__heap_t *h);
/* The first item without removing it (NULL when empty). */
const hd__heap_item_t *hd__heap_top(const hd__heap_t *h);
/* Forget every item, keeping the storage. */
void hd__heap_clear(hd__heap_t *h);
void hd__heap_free(hd__heap_t *h);

static inline size_t hd__heap_size(const hd__heap_t *h) { return h->n; }

#endif /* HD_HEAP_H */
