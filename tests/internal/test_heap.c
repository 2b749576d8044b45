/*
 * test_heap.c -- the priority queue of NOHD, OHD and INC (src/base/heap.c): it
 * pops in key order (largest first as a max-queue, smallest first as a
 * min-queue), breaks ties by the smaller payload, and agrees with a plain
 * reference under any mix of pushes and pops.
 */
#include "check.h"
#include "gen.h"
#include "base/base.h"

#include <math.h>
#include <stdlib.h>

/* The reference: the position of the item that must come out first. */
static size_t ref_first(const hd__heap_item_t *v, size_t n, int max_first) {
    size_t best = 0;
    for (size_t k = 1; k < n; k++) {
        int better = max_first ? v[k].key > v[best].key : v[k].key < v[best].key;
        if (better || (v[k].key == v[best].key && v[k].val < v[best].val)) best = k;
    }
    return best;
}

/* A key drawn from a small set (many ties), from a wide range, or infinite. */
static double random_key(gen_rng_t *g) {
    switch (gen_u64(g) % 4) {
    case 0: return (double)(gen_u64(g) % 5);
    case 1: return gen_normal(g) * 1e150;
    case 2: return gen_unit(g) * 1e-150;
    default: return gen_u64(g) % 7 == 0 ? INFINITY : gen_unit(g);
    }
}

static void pops_in_order(int max_first) {
    gen_rng_t g;
    for (uint64_t seed = 1; seed <= 50; seed++) {
        CONTEXT("seed=%llu max_first=%d", (unsigned long long)seed, max_first);
        gen_seed(&g, seed);
        size_t n = 1 + gen_u64(&g) % 500;
        hd__heap_item_t *ref = malloc(n * sizeof *ref);
        hd__heap_t h;
        hd__heap_init(&h, max_first);
        for (size_t k = 0; k < n; k++) {
            ref[k].key = random_key(&g);
            ref[k].val = gen_u64(&g) % 1000;
            CHECK_RC(hd__heap_push(&h, ref[k].key, ref[k].val), HD_OK);
        }
        CHECK_EQ(hd__heap_size(&h), n);
        size_t left = n;
        while (left && !hdt_failed()) {
            size_t f = ref_first(ref, left, max_first);
            CHECK(hd__heap_top(&h) != NULL);
            hd__heap_item_t it = hd__heap_pop(&h);
            CHECK_BITS(it.key, ref[f].key);
            CHECK_EQ(it.val, ref[f].val);
            ref[f] = ref[--left];
        }
        CHECK_EQ(hd__heap_size(&h), 0);
        CHECK(hd__heap_top(&h) == NULL);
        hd__heap_free(&h);
        free(ref);
        if (hdt_failed()) return;
    }
}

TEST(max_queue_pops_largest_key_first_ties_by_smaller_payload) { pops_in_order(1); }

TEST(min_queue_pops_smallest_key_first_ties_by_smaller_payload) { pops_in_order(0); }

TEST(interleaved_pushes_and_pops_agree_with_a_reference) {
    gen_rng_t g;
    for (uint64_t seed = 1; seed <= 40; seed++) {
        int max_first = (int)(seed & 1);
        CONTEXT("seed=%llu max_first=%d", (unsigned long long)seed, max_first);
        gen_seed(&g, seed);
        hd__heap_item_t ref[2000];
        size_t n = 0;
        hd__heap_t h;
        hd__heap_init(&h, max_first);
        for (int step = 0; step < 3000 && !hdt_failed(); step++) {
            if (n < 2000 && (n == 0 || gen_u64(&g) % 3 != 0)) {
                ref[n].key = random_key(&g);
                ref[n].val = gen_u64(&g) % 50;
                CHECK_RC(hd__heap_push(&h, ref[n].key, ref[n].val), HD_OK);
                n++;
            } else {
                size_t f = ref_first(ref, n, max_first);
                hd__heap_item_t it = hd__heap_pop(&h);
                CHECK_BITS(it.key, ref[f].key);
                CHECK_EQ(it.val, ref[f].val);
                ref[f] = ref[--n];
            }
            CHECK_EQ(hd__heap_size(&h), n);
        }
        hd__heap_free(&h);
        if (hdt_failed()) return;
    }
}

TEST(reserved_room_is_used_without_growing) {
    hd__heap_t h;
    hd__heap_init(&h, 1);
    CHECK_RC(hd__heap_reserve(&h, 100), HD_OK);
    hd__heap_item_t *storage = h.a;
    for (int k = 0; k < 100; k++) CHECK_RC(hd__heap_push(&h, k % 7, (uint64_t)k), HD_OK);
    CHECK(h.a == storage);
    CHECK_EQ(h.cap, 100);
    CHECK_RC(hd__heap_push(&h, 1.0, 100), HD_OK); /* the 101st grows it */
    CHECK(h.cap > 100);
    hd__heap_free(&h);
}

TEST(clear_empties_the_queue_and_keeps_its_storage) {
    hd__heap_t h;
    hd__heap_init(&h, 0);
    for (int k = 0; k < 40; k++) CHECK_RC(hd__heap_push(&h, -k, (uint64_t)k), HD_OK);
    size_t cap = h.cap;
    hd__heap_clear(&h);
    CHECK_EQ(hd__heap_size(&h), 0);
    CHECK(hd__heap_top(&h) == NULL);
    CHECK_EQ(h.cap, cap);
    CHECK_RC(hd__heap_push(&h, 3.0, 9), HD_OK);
    CHECK_BITS(hd__heap_pop(&h).key, 3.0);
    hd__heap_free(&h);
    hd__heap_free(&h); /* freeing twice is harmless */
}
