/*
 * cli_tiles_unit.c -- cli/tiles.c as a program that spreads tiles over
 * processes (hausdorff-mpi) uses it: tiles_share cuts a side into
 * contiguous ranges that cover every tile once, in order; tiles_read of a
 * range gives exactly that range's points of the whole side, numbered from
 * the range's start; tiles_number numbers the whole side from gathered
 * counts; tiles_locate finds the tile of a global index past empty tiles.  The command line's behaviour is tests/cli_tiles.py's.
 */
#include "check.h"
#include "files.h"
#include "gen.h"
#include "tiles.h"

#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static tiles_t sized(const uint64_t *bytes, size_t n) {
    tiles_t s;
    memset(&s, 0, sizeof s);
    s.kind = TILES_LIST;
    s.arg = "@sizes.txt";
    s.n = n;
    s.t = calloc(n ? n : 1, sizeof *s.t);
    for (size_t k = 0; k < n; k++) s.t[k].bytes = bytes[k];
    return s;
}

TEST(share_gives_each_part_the_tiles_that_start_in_its_byte_range) {
    const uint64_t bytes[] = {10, 0, 30, 5, 5, 50}; /* starts 0 10 10 40 45 50 of 100 */
    tiles_t s = sized(bytes, 6);
    size_t first, n;
    tiles_share(&s, 0, 3, &first, &n); /* [0, 33) */
    CHECK_EQ(first, 0);
    CHECK_EQ(n, 3);
    tiles_share(&s, 1, 3, &first, &n); /* [33, 66) */
    CHECK_EQ(first, 3);
    CHECK_EQ(n, 3);
    tiles_share(&s, 2, 3, &first, &n); /* [66, 100): no tile starts there */
    CHECK_EQ(n, 0);
    free(s.t);
}

TEST(share_covers_every_tile_once_in_order_for_any_sizes_and_parts) {
    gen_rng_t r;
    for (uint64_t seed = 1; seed <= 200; seed++) {
        gen_seed(&r, seed);
        size_t n = (size_t)(gen_u64(&r) % 40);
        uint64_t bytes[40];
        for (size_t k = 0; k < n; k++) bytes[k] = gen_u64(&r) % 4 == 0 ? 0 : gen_u64(&r) % ((uint64_t)1 << 40);
        tiles_t s = sized(bytes, n);
        int parts = 1 + (int)(gen_u64(&r) % 9);
        CONTEXT("seed %llu, %zu tiles, %d parts", (unsigned long long)seed, n, parts);
        size_t next = 0;
        for (int p = 0; p < parts; p++) {
            size_t first, m;
            tiles_share(&s, p, parts, &first, &m);
            if (m) CHECK_EQ(first, next);
            next += m;
        }
        CHECK_EQ(next, n);
        free(s.t);
    }
}

TEST(share_of_tiles_without_sizes_goes_to_the_last_part) {
    const uint64_t bytes[] = {0, 0, 0};
    tiles_t s = sized(bytes, 3);
    size_t first, n;
    tiles_share(&s, 0, 2, &first, &n);
    CHECK_EQ(n, 0);
    tiles_share(&s, 1, 2, &first, &n);
    CHECK_EQ(first, 0);
    CHECK_EQ(n, 3);
    free(s.t);
}

TEST(locate_finds_the_tile_of_a_global_index_past_empty_tiles) {
    const uint64_t bytes[] = {0, 0, 0, 0, 0};
    tiles_t s = sized(bytes, 5);
    const size_t first[] = {0, 5, 5, 5, 8}, count[] = {5, 0, 0, 3, 0};
    for (int k = 0; k < 5; k++) s.t[k].first = first[k], s.t[k].count = count[k];
    size_t local;
    CHECK_EQ(tiles_locate(&s, 0, &local), 0);
    CHECK_EQ(local, 0);
    CHECK_EQ(tiles_locate(&s, 4, &local), 0);
    CHECK_EQ(local, 4);
    CHECK_EQ(tiles_locate(&s, 5, &local), 3);
    CHECK_EQ(local, 0);
    CHECK_EQ(tiles_locate(&s, 7, &local), 3);
    CHECK_EQ(local, 2);
    free(s.t);
}

TEST(reading_a_range_gives_that_range_of_the_whole_side) {
    mkdir(tf_path("side"), 0777);
    tf_printf("side/a.xyz", "0 0 0\n1 0 0\n");
    tf_printf("side/b.xyz", "2 0 0\n");
    tf_printf("side/c.xyz", "3 0 0\n4 0 0\n5 0 0\n");
    tiles_t s;
    hd_error_t err;
    CHECK_RC(tiles_expand(tf_path("side"), NULL, &s, &err), HD_OK);
    CHECK_EQ(s.n, 3);
    hd_read_options_t ro;
    hd_read_options_init(&ro);
    analysis_args_t an;
    memset(&an, 0, sizeof an); /* no --empty policy, surface masks */
    hd_cloud_t *whole, *part;
    CHECK_RC(tiles_read(&s, 0, 3, &ro, &an, 0, &whole, &err), HD_OK);
    CHECK_EQ(whole->count, 6);
    CHECK_EQ(s.t[2].first, 3);
    const size_t start[] = {0, 2, 3, 6}; /* tile k's points of the whole: [start[k], start[k + 1]) */
    for (size_t first = 0; first <= 3; first++)
        for (size_t n = 0; first + n <= 3; n++) {
            CONTEXT("tiles [%zu, %zu)", first, first + n);
            CHECK_RC(tiles_read(&s, first, n, &ro, &an, 0, &part, &err), HD_OK);
            size_t want = start[first + n] - start[first];
            CHECK_EQ(part->count, want);
            if (want)
                CHECK(memcmp(part->data, (double *)whole->data + 3 * start[first], want * 3 * sizeof(double)) == 0);
            if (n) CHECK_EQ(s.t[first].first, 0); /* numbered from the range's start */
            hd_cloud_free(part);
        }
    hd_cloud_free(whole);
    tiles_free(&s);
}

TEST(number_gives_each_tile_the_counts_before_it_and_refuses_overflow) {
    const uint64_t bytes[] = {0, 0, 0, 0};
    tiles_t s = sized(bytes, 4);
    const size_t count[] = {5, 0, 3, 2};
    for (int k = 0; k < 4; k++) s.t[k].count = count[k];
    hd_error_t err;
    CHECK_RC(tiles_number(&s, &err), HD_OK);
    CHECK_EQ(s.t[0].first, 0);
    CHECK_EQ(s.t[1].first, 5);
    CHECK_EQ(s.t[2].first, 5);
    CHECK_EQ(s.t[3].first, 8);
    size_t local;
    CHECK_EQ(tiles_locate(&s, 9, &local), 3);
    CHECK_EQ(local, 1);
    s.t[2].count = SIZE_MAX - 4;
    CHECK_RC(tiles_number(&s, &err), HD_EOVERFLOW);
    free(s.t);
}
