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
#include <fcntl.h>
#include <sys/stat.h>
#include <time.h>

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

/* An NPY of n float64 points (k, 2k, 3k) at NAME; its path. */
static const char *npy(const char *name, int n) {
    char dict[128];
    int m = snprintf(dict, sizeof dict, "{'descr': '<f8', 'fortran_order': False, 'shape': (%d, 3), }", n);
    tf_buf_t b = {0};
    tf_put(&b, "\x93NUMPY\x01\x00", 8);
    tf_u16(&b, 118, 0);
    tf_putf(&b, "%-117.*s\n", m, dict);
    for (int k = 0; k < n; k++)
        for (int c = 1; c <= 3; c++) tf_f64(&b, (double)(c * k), 0);
    return tf_finish(&b, name);
}

/* The side `dir` expanded, every tile's count from its header gathered as
 * hausdorff-mpi gathers it (one process here), and the side numbered. */
static void count_side(const char *dir, tiles_t *s, const hd_read_options_t *ro) {
    hd_error_t err;
    CHECK_RC(tiles_expand(tf_path(dir), NULL, s, &err), HD_OK);
    uint64_t counts[8] = {0};
    CHECK(s->n <= 8);
    tiles_count(s, 0, 1, ro, counts);
    for (size_t k = 0; k < s->n; k++) {
        CHECK(counts[k] > 0);
        s->t[k].count = (size_t)(counts[k] - 1);
    }
    CHECK_RC(tiles_number(s, &err), HD_OK);
}

/* A time well after now, so that a rewrite is seen even where the clock
 * that stamps files is coarse. */
static void touch_later(const char *path) {
    struct timespec t[2] = {{0, UTIME_OMIT}, {time(NULL) + 100, 0}};
    CHECK(utimensat(AT_FDCWD, path, t, 0) == 0);
}

TEST(a_tile_grown_between_its_count_and_its_read_changed_during_the_run) {
    mkdir(tf_path("grow"), 0777);
    npy("grow/a.npy", 10);
    npy("grow/b.npy", 100);
    hd_read_options_t ro;
    hd_read_options_init(&ro);
    tiles_t s;
    count_side("grow", &s, &ro);
    CHECK_EQ(s.t[1].count, 100);
    touch_later(npy("grow/b.npy", 150)); /* points appended after the count */
    analysis_args_t an;
    memset(&an, 0, sizeof an);
    hd_cloud_t *c;
    hd_error_t err;
    CHECK_RC(tiles_read_points(&s, 5, 105, &ro, &an, 0, &c, &err), HD_EIO);
    CHECK(c == NULL);
    CHECK(strstr(err.message, "b.npy: changed during the run") != NULL);
    CHECK_RC(tiles_read_points(&s, 0, 10, &ro, &an, 0, &c, &err), HD_OK); /* a.npy alone: unchanged */
    CHECK_EQ(c->count, 10);
    hd_cloud_free(c);
    tiles_free(&s);
}

TEST(a_tile_rewritten_to_the_same_size_changed_during_the_run) {
    mkdir(tf_path("same"), 0777);
    tf_printf("same/a.xyz", "0 0 0\n");
    tiles_t s;
    hd_error_t err;
    CHECK_RC(tiles_expand(tf_path("same"), NULL, &s, &err), HD_OK);
    touch_later(tf_printf("same/a.xyz", "9 0 0\n"));
    hd_read_options_t ro;
    hd_read_options_init(&ro);
    analysis_args_t an;
    memset(&an, 0, sizeof an);
    hd_cloud_t *c;
    CHECK_RC(tiles_read(&s, 0, 1, &ro, &an, 0, &c, &err), HD_EIO);
    CHECK(strstr(err.message, "a.xyz: changed during the run") != NULL);
    tiles_free(&s);
    /* the same as one file, the side hausdorff reads right away */
    CHECK_RC(tiles_expand(tf_path("same/a.xyz"), NULL, &s, &err), HD_OK);
    touch_later(tf_printf("same/a.xyz", "8 0 0\n"));
    CHECK_RC(tiles_read(&s, 0, 1, &ro, &an, 0, &c, &err), HD_EIO);
    tiles_free(&s);
}

TEST(count_leaves_unknown_a_tile_that_changed_since_it_was_listed) {
    mkdir(tf_path("moved"), 0777);
    npy("moved/a.npy", 4);
    hd_read_options_t ro;
    hd_read_options_init(&ro);
    tiles_t s;
    hd_error_t err;
    CHECK_RC(tiles_expand(tf_path("moved"), NULL, &s, &err), HD_OK);
    touch_later(npy("moved/a.npy", 4));
    uint64_t counts[1] = {7};
    tiles_count(&s, 0, 1, &ro, counts);
    CHECK_EQ(counts[0], 0); /* shared by tiles then, and reading refuses it */
    tiles_free(&s);
}

TEST(text_has_numbers_when_a_line_starts_with_one) {
#define CASE(text, want) {text, sizeof text - 1, want} /* NUL bytes kept */
    static const struct {
        const char *text;
        size_t len;
        int want;
    } cases[] = {
        CASE("", 0),
        CASE("This folder holds the 2019 tiles.\nSee notes.\n", 0),
        CASE("x,y,z\n", 0),
        CASE("tile,date\nA1,2019\n", 0),
        CASE("# comment 1 2 3\n// 4 5 6\n\n", 0),
        CASE("Information\nnanometres\n", 0),
        CASE(".\n-\n+x\n", 0),
        CASE("x y z\n1 2 3\n", 1),
        CASE("  \t1 2 3", 1),
        CASE(",;-.5,1,2\n", 1),
        CASE("+7 zebra\n", 1), /* a malformed tile stays a tile: reading refuses it */
        CASE("NaN 1 2\n", 1),
        CASE("-Infinity 1 2\n", 1),
        CASE("inf\n", 1),
        CASE("\xef\xbb\xbf" "1 2 3\n", 1),
        CASE("x y z\r1 2 3\r", 1),
        CASE("\xff\xfe" "1\0 \0" "2\0 \0" "3\0", 1), /* UTF-16: a tile, which the reader refuses by name */
        CASE("\xff\xfe" "R\0e\0a\0d\0", 0),
        CASE("a very long header line of words, longer than what is kept of it\n2 3 4\n", 1),
        CASE("\"x\",\"y\",\"z\"\n\"1.5\",\"2\",\"3\"\n", 1), /* quoted numbers: the reader refuses them */
        CASE("\"name\",\"date\"\n\"\n", 0),
    };
#undef CASE
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        CONTEXT("case %zu: %s", k, cases[k].text);
        CHECK_EQ(tiles_text_has_numbers(tf_write("t.txt", cases[k].text, cases[k].len)), cases[k].want);
    }
    CHECK_EQ(tiles_text_has_numbers(tf_path("missing.txt")), -1);
}

TEST(a_directory_skips_its_text_without_numbers_and_keeps_every_other_text) {
    mkdir(tf_path("docs"), 0777);
    tf_printf("docs/README.txt", "Tiles of the 2019 survey.\n");
    tf_printf("docs/index.CSV", "tile,date\nA1,2019\n");
    tf_printf("docs/notes.xyz", "not numbers\n"); /* a point-file name: a tile, whose read fails */
    tf_printf("docs/p.txt", "x y z\n1 2 3\n");
    tiles_t s;
    hd_error_t err;
    CHECK_RC(tiles_expand(tf_path("docs"), NULL, &s, &err), HD_OK);
    CHECK_EQ(s.n, 2);
    CHECK(strstr(s.t[0].path, "notes.xyz") && strstr(s.t[1].path, "p.txt"));
    CHECK_EQ(s.n_skipped, 2);
    CHECK(strcmp(s.skipped[0].name, "README.txt") == 0 && strcmp(s.skipped[1].name, "index.CSV") == 0);
    CHECK(strstr(s.skipped[0].reason, "no line") || strstr(s.skipped[0].reason, "without a line"));
    tiles_free(&s);
}

TEST(a_digest_tells_apart_listings_that_differ_in_a_file_or_its_stat) {
    mkdir(tf_path("dig"), 0777);
    tf_printf("dig/a.xyz", "0 0 0\n");
    tiles_t s, t;
    hd_error_t err;
    CHECK_RC(tiles_expand(tf_path("dig"), NULL, &s, &err), HD_OK);
    CHECK_RC(tiles_expand(tf_path("dig"), NULL, &t, &err), HD_OK);
    CHECK(tiles_digest(&s) == tiles_digest(&t));
    tiles_free(&t);
    touch_later(tf_printf("dig/a.xyz", "1 0 0\n"));
    CHECK_RC(tiles_expand(tf_path("dig"), NULL, &t, &err), HD_OK);
    CHECK(tiles_digest(&s) != tiles_digest(&t));
    tiles_free(&t);
    tf_printf("dig/b.xyz", "0 0 0\n");
    CHECK_RC(tiles_expand(tf_path("dig"), NULL, &t, &err), HD_OK);
    CHECK(tiles_digest(&s) != tiles_digest(&t));
    tiles_free(&t);
    tiles_free(&s);
}
