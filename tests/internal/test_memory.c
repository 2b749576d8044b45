/*
 * test_memory.c -- the allocation helpers of src/base/memory.c that the
 * engine's one-shot cost rests on: a reuse set hands a block given back to
 * the next request it fits (and only then), and a prefaulted block is an
 * ordinary writable block.
 */
#include "check.h"
#include "base/base.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

TEST(a_reuse_set_hands_a_returned_block_to_a_request_it_fits) {
    hd__reuse_t r;
    hd__reuse_init(&r);
    unsigned char *a = hd__reuse_get(&r, 1 << 20, 4);
    CHECK(a != NULL);
    memset(a, 1, (size_t)4 << 20);
    hd__reuse_put(&r, a);
    /* Larger than the block, or under a third of it: fresh memory. */
    unsigned char *big = hd__reuse_get(&r, (1 << 20) + 1, 4), *tiny = hd__reuse_get(&r, 1 << 18, 4);
    CHECK(big != a && tiny != a);
    /* A request it fits gets it back, once. */
    unsigned char *b = hd__reuse_get(&r, 3 << 18, 4), *c = hd__reuse_get(&r, 3 << 18, 4);
    CHECK(b == a && c != a);
    CHECK_EQ(b[0], 1);
    hd__reuse_put(&r, big);
    hd__reuse_put(&r, tiny);
    hd__reuse_put(&r, b);
    hd__reuse_put(&r, c);
    hd__reuse_put(&r, NULL);
    CHECK_EQ(r.n, 4);
    hd__reuse_free(&r);
    CHECK_EQ(r.n, 0);
    /* Without a set, blocks are plain allocations (ASan checks the frees). */
    void *p = hd__reuse_get(NULL, 1 << 20, 8), *q = hd__reuse_get(NULL, 3, 8);
    CHECK(p != NULL && q != NULL);
    hd__reuse_put(NULL, p);
    hd__reuse_put(NULL, q);
    CHECK(hd__reuse_get(&r, SIZE_MAX / 2, 4) == NULL);
}

TEST(a_prefaulted_block_is_written_and_freed_as_any_other) {
    size_t bytes = (size_t)3 << 20;
    unsigned char *p = malloc(bytes + 1);
    CHECK(p != NULL);
    hd__prefault(p + 1, bytes);  /* an unaligned start: its whole pages only */
    hd__prefault(p, 100);        /* below the threshold: nothing */
    hd__prefault(NULL, bytes);
    memset(p, 7, bytes + 1);
    CHECK_EQ(p[0], 7);
    CHECK_EQ(p[bytes], 7);
    free(p);
}

