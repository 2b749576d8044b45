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


/* Blocks of about 2 MiB and more are mapped on their own (in huge pages
 * where the kernel gives them), middle-sized ones are cut from the set's
 * 2 MiB chunks, and more of them than the chunks hold come from malloc:
 * every block is writable whole and overlaps no other, whichever way it was
 * made (ASan checks the frees of the malloc'd ones). */
TEST(blocks_mapped_whole_or_cut_from_chunks_never_overlap) {
    enum { MID = 100, BIG = 3 };
    size_t mid_bytes = 100000, big_bytes[BIG] = {(size_t)2 << 20, ((size_t)5 << 20) + 1, 1900000};
    unsigned char *mid[MID], *big[BIG];
    hd__reuse_t r;
    hd__reuse_init(&r);
    for (int k = 0; k < BIG; k++) {
        big[k] = hd__reuse_get(&r, big_bytes[k], 1);
        CHECK(big[k] != NULL);
        memset(big[k], 200 + k, big_bytes[k]);
    }
    for (int k = 0; k < MID; k++) {
        mid[k] = hd__reuse_get(&r, mid_bytes, 1);
        CHECK(mid[k] != NULL);
        CHECK((uintptr_t)mid[k] % 16 == 0);
        memset(mid[k], k, mid_bytes);
    }
    CHECK(r.n_chunks >= 1 && r.n_chunks <= HD__REUSE_CHUNKS);
    for (int k = 0; k < MID; k++) CHECK(mid[k][0] == k && mid[k][mid_bytes - 1] == k);
    for (int k = 0; k < BIG; k++) CHECK(big[k][0] == 200 + k && big[k][big_bytes[k] - 1] == 200 + k);
    /* Given back (the set keeps 16, the rest are released), then reused. */
    for (int k = 0; k < MID; k++) hd__reuse_put(&r, mid[k]);
    for (int k = 0; k < BIG; k++) hd__reuse_put(&r, big[k]);
    unsigned char *again = hd__reuse_get(&r, mid_bytes, 1);
    CHECK(again != NULL);
    memset(again, 9, mid_bytes);
    hd__reuse_put(&r, again);
    hd__reuse_free(&r);
    CHECK_EQ(r.n, 0);
    CHECK_EQ(r.n_chunks, 0);
}

/* What a set holds from the system (held, and its most, peak) follows its
 * blocks: a block shrunk gives back the pages after its new size (whole
 * 2 MiB pages only, where it has them) and stays writable up to it; blocks given back stay held until the set is trimmed;
 * a trim gives the chunks back too once no block cut from them is in use;
 * the peak survives hd__reuse_free. */
/* A 2 MiB chunk is held and charged whole, so middle-sized arrays are cut
 * from one only where the chunk is not more than the call needs: never in a
 * pool that holds less than a chunk and a half (a call on a few hundred
 * thousand points), never for an array of more than half a chunk (it would
 * leave a tail that no array of its kind fits); those get blocks of their
 * own, held at their bytes.  An array of a quarter to a half of a chunk,
 * which fills that much of it, opens one in any pool; a pool that holds a
 * chunk and a half cuts its small arrays from a chunk as before (one fault
 * for the lot). */
TEST(a_chunk_is_mapped_only_where_the_call_needs_what_it_holds) {
    hd__reuse_t r;
    hd__reuse_init(&r);
    size_t mid = 100000, wide = 1600000, big = (size_t)4 << 20;
    unsigned char *m = hd__reuse_get(&r, mid, 1);
    CHECK(m != NULL && r.n_chunks == 0);
    CHECK(r.held >= mid && r.held <= mid + 4096); /* its bytes and a header */
    memset(m, 1, mid);
    unsigned char *a = hd__reuse_get(&r, big, 1);
    CHECK(a != NULL);
    size_t held = r.held;
    unsigned char *w = hd__reuse_get(&r, wide, 1);
    CHECK(w != NULL && r.n_chunks == 0);
    CHECK(r.held - held >= wide && r.held - held <= wide + 4096);
    memset(w, 2, wide);
    unsigned char *c = hd__reuse_get(&r, mid, 1);
    CHECK(c != NULL && r.n_chunks == 1 && r.cut_out == 1);
    memset(c, 3, mid);
    CHECK(m[mid - 1] == 1 && w[wide - 1] == 2 && c[mid - 1] == 3);
    hd__reuse_put(&r, m);
    hd__reuse_put(&r, w);
    hd__reuse_put(&r, c);
    hd__reuse_put(&r, a);
    hd__reuse_free(&r);
    CHECK(r.held == 0 && r.n_chunks == 0);
    hd__reuse_init(&r);
    size_t quarter = 600000;
    unsigned char *q = hd__reuse_get(&r, quarter, 1);
    CHECK(q != NULL && r.n_chunks == 1 && r.cut_out == 1);
    memset(q, 4, quarter);
    hd__reuse_put(&r, q);
    hd__reuse_free(&r);
    CHECK(r.held == 0 && r.n_chunks == 0);
}

/* hd__reuse_take trims every kept block but the one that serves the
 * request; when that one was cut from a chunk, the chunk must stay mapped
 * (it once was unmapped under it: a crash in the engine's build). */
TEST(taking_a_kept_block_cut_from_a_chunk_keeps_its_chunk) {
    hd__reuse_t r;
    hd__reuse_init(&r);
    size_t mid = 200000, big = (size_t)4 << 20;
    unsigned char *a = hd__reuse_get(&r, big, 1); /* a pool large enough for chunks */
    CHECK(a != NULL);
    unsigned char *m = hd__reuse_get(&r, mid, 1); /* cut from a chunk */
    CHECK(m != NULL && r.n_chunks == 1);
    memset(m, 6, mid);
    hd__reuse_put(&r, m); /* kept, nothing cut is in use */
    CHECK(r.n == 1 && r.cut_out == 0);
    unsigned char *t = hd__reuse_take(&r, mid - 1000, 1); /* served by m */
    CHECK(t == m && r.n_chunks == 1 && r.cut_out == 1);
    memset(t, 7, mid - 1000); /* mapped: ASan or a fault says otherwise */
    CHECK_EQ(t[mid - 1001], 7);
    hd__reuse_put(&r, t);
    hd__reuse_put(&r, a);
    hd__reuse_free(&r);
    CHECK(r.held == 0);
}

TEST(a_set_counts_what_it_holds_and_gives_back_shrunk_tails_and_trimmed_blocks) {
    hd__reuse_t r;
    hd__reuse_init(&r);
    size_t big = (size_t)8 << 20, small = (size_t)1 << 20, mid = 100000;
    unsigned char *a = hd__reuse_get(&r, big, 1);
    CHECK(a != NULL);
    memset(a, 3, big);
    CHECK(r.held >= big && r.peak == r.held);
    unsigned char *m = hd__reuse_get(&r, mid, 1); /* cut from a chunk */
    CHECK(m != NULL && r.n_chunks == 1);
    memset(m, 5, mid);
    size_t before = r.held;
    hd__reuse_shrink(&r, a, small);
    /* Mapped on its own: the pages past `small` go back, those in 2 MiB
     * pages (where the kernel gave them) up to the next 2 MiB boundary. */
    CHECK(r.held + (big - ((size_t)2 << 20)) <= before && r.held >= small);
    memset(a, 4, small);
    CHECK_EQ(a[small - 1], 4);
    hd__reuse_put(&r, a);
    size_t kept = r.held;
    CHECK(kept >= small + ((size_t)2 << 20) && r.n == 1);
    hd__reuse_trim(&r); /* m is in use: its chunk stays */
    CHECK(r.n == 0 && r.n_chunks == 1 && r.held < kept && r.held >= ((size_t)2 << 20));
    CHECK_EQ(m[mid - 1], 5);
    hd__reuse_put(&r, m);
    hd__reuse_trim(&r);
    CHECK(r.n == 0 && r.n_chunks == 0 && r.held == 0);
    CHECK(r.peak >= big);
    size_t peak = r.peak;
    hd__reuse_free(&r);
    CHECK(r.held == 0 && r.peak == peak);
}
