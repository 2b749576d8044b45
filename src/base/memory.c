/*
 * memory.c -- checked allocation and the arena that tree nodes come from.
 *
 * Every allocation of "count items of size bytes" goes through
 * hd__malloc_array, which refuses a product that overflows size_t before
 * calling malloc: a header that promises 2^62 vertices becomes HD_ENOMEM or
 * HD_EOVERFLOW, never a short buffer.  Trees allocate their nodes from an
 * arena (a list of large blocks) so that building costs a few mallocs, not
 * one per node, and freeing is one walk over the blocks.
 */
#include "base/base.h"

#include <stdlib.h>

void *hd__malloc_array(size_t n, size_t size) {
    if (hd__mul_overflows(n, size)) return NULL;
    size_t bytes = n * size;
    return malloc(bytes ? bytes : 1);
}

void *hd__calloc_array(size_t n, size_t size) {
    if (hd__mul_overflows(n, size)) return NULL;
    return calloc(n ? n : 1, size ? size : 1);
}

void *hd__realloc_array(void *p, size_t n, size_t size) {
    if (hd__mul_overflows(n, size)) return NULL;
    size_t bytes = n * size;
    return realloc(p, bytes ? bytes : 1);
}

struct hd__arena_block {
    struct hd__arena_block *next;
    size_t used, cap;
    _Alignas(16) unsigned char data[];
};

void hd__arena_init(hd__arena_t *a, size_t block_size) {
    a->head = NULL;
    a->block_size = block_size < 4096 ? 4096 : block_size;
    a->total = 0;
}

void *hd__arena_alloc(hd__arena_t *a, size_t size) {
    size = (size + 15) & ~(size_t)15;
    struct hd__arena_block *b = a->head;
    if (!b || b->cap - b->used < size) {
        size_t cap = size > a->block_size ? size : a->block_size;
        if (cap > SIZE_MAX - sizeof *b) return NULL;
        b = malloc(sizeof *b + cap);
        if (!b) return NULL;
        b->next = a->head;
        b->used = 0;
        b->cap = cap;
        a->head = b;
        a->total += sizeof *b + cap;
    }
    void *p = b->data + b->used;
    b->used += size;
    return p;
}

void hd__arena_free(hd__arena_t *a) {
    struct hd__arena_block *b = a->head;
    while (b) {
        struct hd__arena_block *n = b->next;
        free(b);
        b = n;
    }
    a->head = NULL;
    a->total = 0;
}
