/*
 * memory.c -- checked allocation and the arena that tree nodes come from.
 *
 * Every allocation of "count items of size bytes" goes through
 * hd__malloc_array, which refuses a product that overflows size_t before
 * calling malloc: a header that promises 2^62 vertices becomes HD_ENOMEM or
 * HD_EOVERFLOW, never a short buffer.  Trees allocate their nodes from an
 * arena (a list of large blocks) so that building costs a few mallocs, not
 * one per node, and freeing is one walk over the blocks.
 *
 * hd__reuse_* keeps the large arrays one call frees, for the
 * arrays it allocates next: each block starts with a header of
 * REUSE_HEADER bytes holding its capacity, so a block is reused by any
 * request of at least a third of its capacity (best fit), and the pages
 * already touched are written again instead of fresh ones.  Requests below
 * REUSE_SMALL bytes are not worth keeping and are freed at once.
 *
 * hd__prefault asks the kernel to map a fresh block's pages in one call
 * (madvise MADV_POPULATE_WRITE) instead of one page fault per page on first
 * write; only for arrays that are written whole, since it maps every page.
 */
#include "base/base.h"

#include <stdint.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <unistd.h>

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

void hd__prefault(void *p, size_t bytes) {
#ifdef MADV_POPULATE_WRITE
    if (!p || bytes < HD__PREFAULT_MIN) return;
    long page = sysconf(_SC_PAGESIZE);
    if (page <= 0) return;
    uintptr_t a = ((uintptr_t)p + (uintptr_t)page - 1) & ~((uintptr_t)page - 1);
    uintptr_t e = ((uintptr_t)p + bytes) & ~((uintptr_t)page - 1);
    /* A hint: when the kernel cannot (before Linux 5.14: EINVAL) the pages
     * are mapped on first touch, as without it. */
    if (e > a) (void)madvise((void *)a, e - a, MADV_POPULATE_WRITE);
#else
    (void)p, (void)bytes;
#endif
}

#define REUSE_HEADER 64
#define REUSE_SMALL 65536

void hd__reuse_init(hd__reuse_t *pool) { pool->n = 0; }

static size_t reuse_cap(const void *p) { return *(const size_t *)((const unsigned char *)p - REUSE_HEADER); }

void *hd__reuse_get(hd__reuse_t *pool, size_t n, size_t size) {
    if (hd__mul_overflows(n, size) || n * size > SIZE_MAX - REUSE_HEADER) return NULL;
    size_t bytes = n * size;
    if (pool && bytes >= REUSE_SMALL) {
        int best = -1;
        for (int k = 0; k < pool->n; k++) {
            size_t cap = reuse_cap(pool->block[k]);
            if (cap >= bytes && cap / 3 <= bytes && (best < 0 || cap < reuse_cap(pool->block[best]))) best = k;
        }
        if (best >= 0) {
            void *p = pool->block[best];
            pool->block[best] = pool->block[--pool->n];
            return p;
        }
    }
    unsigned char *b = malloc(REUSE_HEADER + bytes);
    if (!b) return NULL;
    hd__prefault(b, REUSE_HEADER + bytes);
    *(size_t *)b = bytes;
    return b + REUSE_HEADER;
}

void hd__reuse_put(hd__reuse_t *pool, void *p) {
    if (!p) return;
    if (pool && pool->n < HD__REUSE_KEEP && reuse_cap(p) >= REUSE_SMALL) {
        pool->block[pool->n++] = p;
        return;
    }
    free((unsigned char *)p - REUSE_HEADER);
}

void hd__reuse_free(hd__reuse_t *pool) {
    for (int k = 0; k < pool->n; k++) free((unsigned char *)pool->block[k] - REUSE_HEADER);
    pool->n = 0;
}

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
