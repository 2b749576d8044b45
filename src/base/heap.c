/*
 * heap.c -- the priority queues of NOHD (Algorithm 3, the "descending order"
 * DPQ), OHD's NNDist (Algorithm 7, the "ascending order" APQ) and INC.
 * It lives in base/ because it knows nothing about points: a key and a
 * payload per item; the paper's algorithms in classic/ use it.
 *
 * The paper re-sorts its queues after every expansion ("Sort DPQ in
 * descending order using the second element", Algorithm 3 line 17;
 * Algorithm 7 line 15); a binary heap gives the same dequeue order in
 * O(log n) per operation.  The invariant is the usual one: no item comes
 * after its parent in the heap's order (`before` below), so the root is the
 * first item.  Ties between equal keys are broken by the payload, which makes
 * the order a total one and every traversal repeatable.
 */
#include "base/base.h"


#include <stdlib.h>

void hd__heap_init(hd__heap_t *h, int max_first) {
    h->a = NULL;
    h->n = 0;
    h->cap = 0;
    h->max_first = max_first;
}

int hd__heap_reserve(hd__heap_t *h, size_t cap) {
    if (cap <= h->cap) return HD_OK;
    hd__heap_item_t *a = hd__realloc_array(h->a, cap, sizeof *a);
    if (!a) return HD_ENOMEM;
    h->a = a;
    h->cap = cap;
    return HD_OK;
}

/* 1 when x must come out before y. */
static inline int before(const hd__heap_t *h, const hd__heap_item_t *x,
                         const hd__heap_item_t *y) {
    if (x->key != y->key) return h->max_first ? x->key > y->key : x->key < y->key;
    return x->val < y->val;
}

int hd__heap_push(hd__heap_t *h, double key, uint64_t val) {
    if (h->n == h->cap) {
        if (hd__mul_overflows(h->cap, 2)) return HD_ENOMEM;
        int rc = hd__heap_reserve(h, h->cap ? 2 * h->cap : 16);
        if (rc != HD_OK) return rc;
    }
    hd__heap_item_t it = {key, val};
    size_t k = h->n++;
    while (k > 0) {
        size_t parent = (k - 1) / 2;
        if (!before(h, &it, &h->a[parent])) break;
        h->a[k] = h->a[parent];
        k = parent;
    }
    h->a[k] = it;
    return HD_OK;
}

hd__heap_item_t hd__heap_pop(hd__heap_t *h) {
    hd__heap_item_t top = h->a[0];
    hd__heap_item_t last = h->a[--h->n];
    size_t n = h->n, k = 0;
    for (;;) {
        size_t c = 2 * k + 1;
        if (c >= n) break;
        if (c + 1 < n && before(h, &h->a[c + 1], &h->a[c])) c++;
        if (!before(h, &h->a[c], &last)) break;
        h->a[k] = h->a[c];
        k = c;
    }
    if (n > 0) h->a[k] = last;
    return top;
}

const hd__heap_item_t *hd__heap_top(const hd__heap_t *h) { return h->n ? &h->a[0] : NULL; }

void hd__heap_clear(hd__heap_t *h) { h->n = 0; }

void hd__heap_free(hd__heap_t *h) {
    free(h->a);
    h->a = NULL;
    h->n = h->cap = 0;
}
