/*
 * test_io_laz.c -- the LAZ reader (src/io/laz.c): random point sets written
 * by the tests' LAZ writer (tests/internal/lazwrite.c, whose files
 * tests/laz_lazperf.py checks with laz-perf) read back bit-identically in
 * every point format family, chunking and thread count; and damaged files
 * refused with the place of the damage, never a crash, a hang or an
 * allocation beyond the file.  The shared PDAL files are checked outside
 * the tests (docs/formats.md).
 */
#include "check.h"
#include "files.h"
#include "gen.h"
#include "lazwrite.h"

#include "io/io.h"

#include <stdlib.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

static const lazw_opts_t plain = {0, 0, 50, NULL, 0, {0.01, 0.01, 0.001}, {1000.5, -20.25, 3}, 0};

/* Read the LAZ bytes b with `threads`; HD_OK and the cloud, or the code
 * and the message in e. */
static unsigned per_byte; /* the read options' laz_points_per_byte (0: default) */
static int read_laz(const tf_buf_t *b, int threads, hd_dtype_t dtype, hd_cloud_t **c, hd_error_t *e) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.threads = threads;
    o.dtype = dtype;
    o.laz_points_per_byte = per_byte;
    return hd__read_buffer(b->data, b->size, "t.laz", &o, c, e);
}

/* The file of p[0..n) under o reads as exactly X * scale + offset. */
static void round_trip(const lazw_opts_t *o, const lazw_point_t *p, size_t n, int threads) {
    tf_buf_t b = {0};
    lazw_encode(&b, o, p, n);
    hd_cloud_t *c = NULL;
    hd_error_t e;
    int rc = read_laz(&b, threads, HD_FLOAT64, &c, &e);
    if (rc) {
        hdt_fail(__FILE__, __LINE__, "refused: %s", e.message);
        tf_free(&b);
        return;
    }
    CHECK_EQ(c->count, n);
    hd_points_t q = hd_cloud_points(c);
    const double *d = q.data;
    size_t bad = 0;
    for (size_t k = 0; k < n && k < c->count; k++) {
        int32_t v[3] = {p[k].x, p[k].y, p[k].z};
        for (int a = 0; a < 3; a++) {
            double want = (double)v[a] * o->scale[a] + o->offset[a];
            if (memcmp(&want, &d[3 * k + a], sizeof want) != 0 && bad++ < 3)
                hdt_fail(__FILE__, __LINE__, "point %zu %c: %.17g != %.17g", k, "xyz"[a], d[3 * k + a], want);
        }
    }
    hd_cloud_free(c);
    tf_free(&b);
}

/* A random file of up to max_n points (seeded) in format fmt with `extra`
 * bytes, random fixed chunk sizes up to max_chunk (LASzip 1: one stream),
 * read back with `threads`. */
/* n random points for format fmt from seed (free them). */
static lazw_point_t *points(uint64_t seed, size_t n, int fmt) {
    gen_rng_t g;
    gen_seed(&g, seed);
    lazw_point_t *p = malloc(n * sizeof *p);
    lazw_random(&g, p, n, fmt);
    return p;
}

/* A random file of up to max_n points (seeded) in format fmt with `extra`
 * bytes, random fixed chunk sizes up to max_chunk (LASzip 1: one stream),
 * read back with `threads`. */
static void random_trip(int fmt, unsigned extra, int v1, uint64_t seed, size_t max_n, uint32_t max_chunk, int threads) {
    CONTEXT("format %d, extra %u%s, seed %llu", fmt, extra, v1 ? ", LASzip 1" : "", (unsigned long long)seed);
    size_t n = 1 + (size_t)(seed * 7919 % max_n);
    lazw_point_t *p = points(seed, n, fmt);
    lazw_opts_t o = plain;
    o.format = fmt;
    o.extra = extra;
    o.v1 = v1;
    o.chunk_size = 1 + (uint32_t)(seed * 104729 % max_chunk);
    round_trip(&o, p, n, threads);
    free(p);
}

TEST(pointwise_formats_0_to_3_with_and_without_extra_bytes_read_bit_identically) {
    for (int fmt = 0; fmt <= 3; fmt++)
        for (unsigned extra = 0; extra <= 3; extra += 3)
            for (uint64_t seed = 1; seed <= 3; seed++) random_trip(fmt, extra, 0, seed, 400, 120, (int)seed);
}

TEST(laszip_1_streams_of_version_1_items_read_bit_identically) {
    for (int fmt = 0; fmt <= 3; fmt++)
        for (unsigned extra = 0; extra <= 2; extra += 2) random_trip(fmt, extra, 1, 31, 700, 1, 2);
}

TEST(layered_format_6_with_channels_returns_and_extra_bytes_reads_bit_identically) {
    for (unsigned extra = 0; extra <= 2; extra += 2)
        for (uint64_t seed = 11; seed <= 14; seed++) random_trip(6, extra, 0, seed, 600, 200, 2);
}

TEST(variable_chunk_sizes_as_copc_writes_them_read_bit_identically) {
    gen_rng_t g;
    gen_seed(&g, 21);
    size_t n = 1000, sizes[40], nc = 0, left = n;
    while (left) {
        size_t k = 1 + (size_t)(gen_u64(&g) % 90);
        if (k > left || nc == 39) k = left;
        sizes[nc++] = k;
        left -= k;
    }
    lazw_point_t *p = malloc(n * sizeof *p);
    for (int fmt = 0; fmt <= 6; fmt += 6) {
        CONTEXT("format %d, seed 21", fmt);
        lazw_random(&g, p, n, fmt);
        lazw_opts_t o = plain;
        o.format = fmt;
        o.chunk_size = 0;
        o.chunks = sizes;
        o.n_chunks = nc;
        round_trip(&o, p, n, 3);
    }
    free(p);
}

TEST(a_chunk_whose_z_never_changes_has_an_empty_z_layer_and_keeps_its_z) {
    lazw_point_t p[100];
    for (int i = 0; i < 100; i++) p[i] = (lazw_point_t){i * 7, -i * 3, 42, 1, 1, (unsigned char)(i / 30)};
    lazw_opts_t o = plain;
    o.format = 6;
    round_trip(&o, p, 100, 1);
}

TEST(identical_points_compress_far_below_the_points_per_byte_limit) {
    /* the reader refuses chunks of more than HD_LAZ_POINTS_PER_BYTE points
     * per byte by default; degenerate data (a chunk of one repeated point)
     * in LASzip's chunks of 50,000 stays below */
    static lazw_point_t p[50000];
    for (int i = 0; i < 50000; i++) p[i] = (lazw_point_t){5, 6, 7, 1, 1, 0};
    for (int fmt = 0; fmt <= 6; fmt += 6) {
        CONTEXT("format %d", fmt);
        lazw_opts_t o = plain;
        o.format = fmt;
        o.chunk_size = 50000;
        tf_buf_t b = {0};
        lazw_encode(&b, &o, p, 50000);
        size_t bytes = b.size - lazw_last.chunk[0];
        CHECK(50000 / bytes < HD_LAZ_POINTS_PER_BYTE * 2 / 3);
        tf_free(&b);
        round_trip(&o, p, 50000, 1);
    }
}

/* ---- damaged files ----------------------------------------------------------- */
static void refused(const tf_buf_t *b, int code, const char *needle, long long at) {
    hd_cloud_t *c = (hd_cloud_t *)1;
    hd_error_t e;
    for (int threads = 1; threads <= 2; threads++) {
        CHECK_RC(read_laz(b, threads, threads == 1 ? HD_FLOAT64 : HD_FLOAT32, &c, &e), code);
        CHECK(c == NULL);
        if (strncmp(e.message, "t.laz: ", 7) != 0) hdt_fail(__FILE__, __LINE__, "message '%s' lacks the name", e.message);
        if (!strstr(e.message, needle)) hdt_fail(__FILE__, __LINE__, "message '%s' lacks '%s'", e.message, needle);
        if (at >= 0) CHECK_EQ(e.offset, at);
    }
}

static void sample_v(tf_buf_t *b, int fmt, size_t n, uint32_t chunk, int v1) {
    lazw_point_t *p = points(5, n, fmt);
    lazw_opts_t o = plain;
    o.format = fmt;
    o.chunk_size = chunk;
    o.v1 = v1;
    lazw_encode(b, &o, p, n);
    free(p);
}
static void sample(tf_buf_t *b, int fmt, size_t n, uint32_t chunk) { sample_v(b, fmt, n, chunk, 0); }
static void put_u32(tf_buf_t *b, size_t at, uint32_t v) {
    for (int i = 0; i < 4; i++) b->data[at + i] = (unsigned char)(v >> (8 * i));
}
static void put_u64(tf_buf_t *b, size_t at, uint64_t v) {
    for (int i = 0; i < 8; i++) b->data[at + i] = (unsigned char)(v >> (8 * i));
}

TEST(every_truncation_of_a_laz_file_is_refused_or_read_whole_never_partly) {
    for (int variant = 0; variant < 3; variant++) {
        int fmt = variant == 1 ? 6 : variant ? 1 : 0;
        tf_buf_t b = {0};
        sample_v(&b, fmt, 300, 64, variant == 2);
        size_t full = b.size;
        for (size_t cut = 0; cut < full; cut += 1 + cut / 16) {
            CONTEXT("format %d%s cut at %zu of %zu", fmt, variant == 2 ? " (LASzip 1)" : "", cut, full);
            b.size = cut;
            hd_cloud_t *c = NULL;
            hd_error_t e;
            int rc = read_laz(&b, 2, HD_FLOAT64, &c, &e);
            CHECK(rc != HD_OK);
            CHECK(e.offset == -1 || (e.offset >= 0 && (size_t)e.offset <= cut));
            hd_cloud_free(c);
        }
        tf_free(&b);
    }
}

TEST(a_chunk_table_outside_the_file_is_refused_with_the_offset_of_its_pointer) {
    tf_buf_t b = {0};
    sample(&b, 0, 100, 50);
    put_u64(&b, lazw_last.points, (uint64_t)b.size + 100);
    refused(&b, HD_EFORMAT, "chunk table at byte", (long long)lazw_last.points);
    tf_free(&b);
}

TEST(a_chunk_count_beyond_the_bytes_before_the_table_is_refused_before_allocating) {
    tf_buf_t b = {0};
    sample(&b, 0, 100, 50);
    put_u32(&b, lazw_last.table + 4, 0xFFFFFFF0u);
    refused(&b, HD_EFORMAT, "chunks in the", (long long)lazw_last.table + 4);
    tf_free(&b);
}

TEST(a_point_count_the_chunks_do_not_hold_is_refused) {
    tf_buf_t b = {0};
    sample(&b, 0, 100, 50);
    put_u32(&b, 107, 101); /* the header's count: 101 needs 3 chunks of 50 */
    refused(&b, HD_EFORMAT, "3 expected", (long long)lazw_last.table + 4);
    tf_free(&b);
    tf_buf_t v = {0};
    size_t sizes[2] = {40, 60};
    lazw_point_t p[100];
    gen_rng_t g;
    gen_seed(&g, 8);
    lazw_random(&g, p, 100, 6);
    lazw_opts_t o = plain;
    o.format = 6;
    o.chunk_size = 0;
    o.chunks = sizes;
    o.n_chunks = 2;
    lazw_encode(&v, &o, p, 100);
    put_u64(&v, 247, 1u << 30); /* far more than the table's chunks hold */
    refused(&v, HD_EFORMAT, "the chunks hold 100 points, the header says 1073741824", -1);
    tf_free(&v);
}

TEST(a_huge_point_count_in_a_tiny_chunk_is_refused_before_allocating) {
    /* one variable chunk claiming 2^31 points */
    lazw_point_t p[3] = {{1, 2, 3, 1, 1, 0}, {2, 3, 4, 1, 1, 0}, {3, 4, 5, 1, 1, 0}};
    size_t sizes[1] = {3};
    lazw_opts_t o = plain;
    o.format = 6;
    o.chunk_size = 0;
    o.chunks = sizes;
    o.n_chunks = 1;
    tf_buf_t b = {0};
    lazw_encode(&b, &o, p, 3);
    /* the same chunk bytes, the table and the header saying 2^31 points */
    size_t t = lazw_last.table;
    uint32_t cnt = 1u << 31, bytes = (uint32_t)(t - lazw_last.chunk[0]);
    b.size = t;
    lazw_table(&b, &cnt, &bytes, 1);
    put_u64(&b, 247, (uint64_t)1 << 31);
    refused(&b, HD_EFORMAT, "claims 2147483648 points in", (long long)lazw_last.chunk[0]);
    tf_free(&b);
}

TEST(a_chunk_claiming_thousands_of_points_per_byte_fails_as_its_stream_runs_out) {
    /* a pointwise chunk of 50 real points whose table says 4000 per byte,
     * read with the limit raised to 4096: the reader takes the sequential
     * path, growing the result as points are decoded, and stops where the
     * stream runs past the chunk */
    lazw_point_t *p = points(9, 50, 0);
    size_t sizes[1] = {50};
    lazw_opts_t o = plain;
    o.chunk_size = 0;
    o.chunks = sizes;
    o.n_chunks = 1;
    tf_buf_t b = {0};
    lazw_encode(&b, &o, p, 50);
    size_t t = lazw_last.table;
    uint32_t bytes = (uint32_t)(t - lazw_last.chunk[0]), cnt = bytes * 4000;
    b.size = t;
    lazw_table(&b, &cnt, &bytes, 1);
    put_u32(&b, 107, cnt);
    per_byte = HD_LAZ_POINTS_PER_BYTE_MAX;
    refused(&b, HD_EFORMAT, "ran past the chunk's end", (long long)t);
    per_byte = 0;
    tf_free(&b);
    free(p);
}

TEST(a_chunk_shortened_in_the_table_makes_its_decoder_run_past_its_end) {
    for (int fmt = 0; fmt <= 6; fmt += 6) {
        CONTEXT("format %d", fmt);
        tf_buf_t b = {0};
        sample(&b, fmt, 200, 200);
        /* drop the chunk's last 40 bytes: the table entry is re-encoded
         * by writing the file again with the chunk cut is not possible, so
         * move the table 40 bytes earlier over the chunk's tail */
        size_t t = lazw_last.table, n = b.size - t;
        memmove(b.data + t - 40, b.data + t, n);
        b.size -= 40;
        put_u64(&b, lazw_last.points, t - 40);
        /* the table still says the chunk has its full size: it now runs
         * past the table */
        refused(&b, HD_EFORMAT, "runs past the chunk table", (long long)lazw_last.chunk[0]);
        tf_free(&b);
    }
}

TEST(a_damaged_layer_size_is_refused_with_the_chunk_offset) {
    tf_buf_t b = {0};
    sample(&b, 6, 100, 100);
    size_t sizes_at = lazw_last.chunk[0] + 30 + 4;
    put_u32(&b, sizes_at, 0x7FFFFFFF);
    refused(&b, HD_EFORMAT, "layers need", (long long)sizes_at);
    tf_free(&b);
    tf_buf_t c = {0};
    sample(&c, 6, 100, 100);
    uint32_t nxy = (uint32_t)hd__ld_u32(c.data + sizes_at, 0), nz = (uint32_t)hd__ld_u32(c.data + sizes_at + 4, 0);
    put_u32(&c, sizes_at, 3); /* x/y layer of 3 bytes: the layers no longer fill the chunk */
    refused(&c, HD_EFORMAT, "the chunk's layers fill only", (long long)sizes_at);
    put_u32(&c, sizes_at + 4, nz + nxy - 3); /* the z layer takes the rest: x/y runs past its 3 bytes */
    refused(&c, HD_EFORMAT, "x/y layer ends before its 100 points", -1);
    tf_free(&c);
    tf_buf_t d = {0};
    sample(&d, 6, 100, 100);
    put_u32(&d, lazw_last.chunk[0] + 30, 99);
    refused(&d, HD_EFORMAT, "the chunk says it holds 99 points, the chunk table 100", (long long)lazw_last.chunk[0] + 30);
    tf_free(&d);
}

TEST(unsupported_or_inconsistent_laszip_vlrs_are_refused_naming_the_field) {
    tf_buf_t b = {0};
    sample(&b, 0, 10, 50);
    size_t v = lazw_last.vlr;
    b.data[v] = 4; /* compressor 4: not defined */
    refused(&b, HD_EUNSUPPORTED, "compressor 4", (long long)v);
    b.data[v] = 2;
    b.data[v + 34 + 4] = 3; /* POINT10 version 3 */
    refused(&b, HD_EUNSUPPORTED, "item 1 is type 6 version 3", (long long)v + 34);
    b.data[v + 34 + 4] = 2;
    b.data[v + 34 + 2] = 21; /* POINT10 of 21 bytes */
    refused(&b, HD_EFORMAT, "has size 21, not 20", (long long)v + 36);
    b.data[v + 34 + 2] = 20;
    tf_free(&b);
    /* two BYTE items (a file with 2 extra bytes whose BYTE item is split
     * into two of one byte; the VLR and the point offset grow by 6) */
    tf_buf_t x = {0};
    lazw_opts_t o = plain;
    o.extra = 2;
    lazw_point_t p[10];
    for (int i = 0; i < 10; i++) p[i] = (lazw_point_t){i, i, i, 1, 1, 0};
    lazw_encode(&x, &o, p, 10);
    size_t it = lazw_last.vlr + 34 + 6;
    tf_put(&x, "123456", 6);
    memmove(x.data + it + 6, x.data + it, x.size - 6 - it);
    x.data[it + 2] = 1;
    x.data[it + 6 + 2] = 1;
    x.data[lazw_last.vlr + 32] = 3;
    x.data[lazw_last.vlr - 54 + 20] += 6;
    put_u32(&x, 96, (uint32_t)lazw_last.points + 6);
    refused(&x, HD_EFORMAT, "LASzip item 3 repeats item 2's type 0", (long long)it + 6);
    tf_free(&x);
    sample(&b, 0, 10, 50);
    b.data[v - 54 + 2] = 'L'; /* no VLR of user "laszip encoded" */
    refused(&b, HD_EFORMAT, "no LASzip VLR", 104);
    tf_free(&b);
}

TEST(a_laz_point_beyond_the_float_range_is_refused_naming_it) {
    lazw_point_t p[3] = {{0, 0, 0, 1, 1, 0}, {1, 1, 1, 1, 1, 0}, {2, 2, 2147483647, 1, 1, 0}};
    lazw_opts_t o = plain;
    o.scale[2] = 1e150;
    tf_buf_t b = {0};
    lazw_encode(&b, &o, p, 3);
    hd_cloud_t *c = NULL;
    hd_error_t e;
    CHECK_RC(read_laz(&b, 1, HD_FLOAT64, &c, &e), HD_ERANGE);
    CHECK(strstr(e.message, "point 2 (in the chunk starting here)") != NULL);
    CHECK_EQ(e.offset, (long long)lazw_last.chunk[0]);
    hd_cloud_free(c);
    tf_free(&b);
}

/* ---- counts and items that do not describe the data ------------------------- */
/* hd_read_count on the bytes b: its code, the message in e. */
static int count_laz(const tf_buf_t *b, uint64_t *n, hd_error_t *e) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    return hd__count_buffer(b->data, b->size, "t.laz", &o, n, e);
}

/* b is refused by a read and by hd_read_count, each message holding needle. */
static void refused_and_not_counted(const tf_buf_t *b, const char *needle) {
    refused(b, HD_EFORMAT, needle, -1);
    uint64_t n = 7;
    hd_error_t e;
    CHECK_RC(count_laz(b, &n, &e), HD_EFORMAT);
    CHECK_EQ(n, 0);
    if (!strstr(e.message, needle)) hdt_fail(__FILE__, __LINE__, "count's message '%s' lacks '%s'", e.message, needle);
}

TEST(a_header_count_lower_than_the_data_is_refused_never_read_partly) {
    /* one chunk of 100, two of 50 (the lie lands in the last), LASzip 1's
     * single stream; counts 1 (the one-point chunk: its stream must be the
     * four bytes an empty one is) to 99 */
    static const uint32_t chunks[3] = {200, 50, 1};
    static const uint32_t lies[4] = {1, 2, 60, 99};
    for (int v = 0; v < 3; v++)
        for (int l = 0; l < 4; l++) {
            CONTEXT("chunks of %u%s, header count %u of 100", chunks[v], v == 2 ? " (LASzip 1)" : "", lies[l]);
            tf_buf_t b = {0};
            sample_v(&b, v == 2 ? 3 : 0, 100, chunks[v], v == 2);
            put_u32(&b, 107, lies[l]);
            if (v == 1 && lies[l] <= 50) /* fewer chunks than the table: refused by the table */
                refused(&b, HD_EFORMAT, "chunks for", -1);
            else
                refused_and_not_counted(&b, "left after its");
            tf_free(&b);
        }
}

TEST(a_range_read_decodes_the_last_chunk_so_a_lowered_count_is_refused_there_too) {
    tf_buf_t b = {0};
    sample(&b, 0, 100, 50);
    put_u32(&b, 107, 99);
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.range_first = 0;
    o.range_count = 10; /* the first chunk only */
    hd_cloud_t *c = NULL;
    hd_error_t e;
    CHECK_RC(hd__read_buffer(b.data, b.size, "t.laz", &o, &c, &e), HD_EFORMAT);
    if (!strstr(e.message, "chunk 2 of 2: ") || !strstr(e.message, "left after its 49 points"))
        hdt_fail(__FILE__, __LINE__, "message '%s' does not name the last chunk's unread bytes", e.message);
    CHECK(c == NULL);
    tf_free(&b);
}

TEST(a_layered_chunk_whose_count_and_table_are_both_lowered_leaves_its_x_y_layer_unfinished) {
    tf_buf_t b = {0};
    sample(&b, 6, 100, 100);
    put_u64(&b, 247, 99);
    put_u32(&b, lazw_last.chunk[0] + 30, 99); /* the chunk's own count */
    refused_and_not_counted(&b, "of the chunk's x/y layer are left after its 99 points");
    tf_free(&b);
}

TEST(a_one_point_layered_chunk_has_an_empty_stream_of_four_bytes_or_none_per_decoded_layer) {
    static const size_t sizes[3] = {1, 30, 1};
    lazw_point_t *p = points(41, 32, 6);
    lazw_opts_t o = plain;
    o.format = 6;
    o.chunk_size = 0;
    o.chunks = sizes;
    o.n_chunks = 3;
    round_trip(&o, p, 32, 2);
    tf_buf_t b = {0};
    lazw_encode(&b, &o, p, 32);
    size_t nxy_at = lazw_last.chunk[0] + 30 + 4;
    CHECK_EQ(hd__ld_u32(b.data + nxy_at, 0), 4);
    CHECK_EQ(hd__ld_u32(b.data + nxy_at + 4, 0), 0);
    /* the one-point chunk's x/y layer of 3 bytes and a z layer of 1 */
    put_u32(&b, nxy_at, 3);
    put_u32(&b, nxy_at + 4, 1);
    refused(&b, HD_EFORMAT, "chunk 1 of 3: the chunk's x/y layer ends before its 1 point (the decoder ran past the layer's end)", -1);
    tf_free(&b);
    free(p);
}

TEST(a_skipped_layer_cannot_hide_bytes_the_layer_sizes_do_not_account_for) {
    tf_buf_t b = {0};
    sample(&b, 6, 100, 100);
    size_t sizes_at = lazw_last.chunk[0] + 30 + 4;
    uint32_t nxy = (uint32_t)hd__ld_u32(b.data + sizes_at, 0);
    put_u32(&b, sizes_at, nxy - 1); /* one byte of x/y in no layer */
    refused(&b, HD_EFORMAT, "the chunk's layers fill only", (long long)sizes_at);
    tf_free(&b);
}

TEST(laszip_items_whose_version_is_not_the_one_the_data_was_written_with_are_refused) {
    /* LASzip 1.x streams of version 1 items said to be version 2: POINT10
     * in format 0, RGB12 in format 2 (item 2).  Seeds and sizes whose lie
     * decodes without running past the stream: only the bytes left show it. */
    static const struct { int fmt, item; size_t n; } lie[2] = {{0, 0, 6}, {2, 1, 3}};
    for (int k = 0; k < 2; k++) {
        CONTEXT("format %d, item %d of version 1 said to be 2, %zu points, seed 3", lie[k].fmt, lie[k].item + 1, lie[k].n);
        lazw_point_t *p = points(3, lie[k].n, lie[k].fmt);
        lazw_opts_t o = plain;
        o.format = lie[k].fmt;
        o.v1 = 1;
        tf_buf_t b = {0};
        lazw_encode(&b, &o, p, lie[k].n);
        b.data[lazw_last.vlr + 34 + 6 * lie[k].item + 4] = 2;
        refused(&b, HD_EFORMAT, "the LASzip VLR's items are not the ones it was written with", -1);
        tf_free(&b);
        free(p);
    }
}

/* ---- memory bounded by the file ---------------------------------------------- */
/* The growth of the peak resident memory (MiB, capped at 255) of reading b
 * in a child process with one thread; -1 if the child failed to report. */
static int read_growth_mib(const tf_buf_t *b) {
    pid_t pid = fork();
    if (pid == 0) {
        struct rusage u0, u1;
        getrusage(RUSAGE_SELF, &u0);
        hd_cloud_t *c = NULL;
        hd_error_t e;
        read_laz(b, 1, HD_FLOAT64, &c, &e);
        hd_cloud_free(c);
        getrusage(RUSAGE_SELF, &u1);
        long mib = (u1.ru_maxrss - u0.ru_maxrss) / 1024;
        _exit(mib > 255 ? 255 : (int)mib);
    }
    int status = 0;
    if (pid < 0 || waitpid(pid, &status, 0) != pid || !WIFEXITED(status)) return -1;
    return WEXITSTATUS(status);
}

TEST(a_record_of_65515_extra_bytes_with_a_stream_of_four_creates_models_only_for_what_it_decodes) {
    /* one point of 65,515 extra bytes (a 66 KB file) whose header says two:
     * the second point's BYTE symbols run past the four-byte stream at
     * once; creating every extra byte's model up front cost 150 MB */
    lazw_point_t p[1] = {{1, 2, 3, 1, 1, 0}};
    lazw_opts_t o = plain;
    o.extra = 65515;
    o.chunk_size = 1000;
    tf_buf_t b = {0};
    lazw_encode(&b, &o, p, 1);
    CHECK(b.size < 67000);
    put_u32(&b, 107, 2);
    refused(&b, HD_EFORMAT, "ran past the chunk's end", -1);
    int mib = read_growth_mib(&b);
    if (mib < 0 || mib > 32) hdt_fail(__FILE__, __LINE__, "reading grew the resident memory by %d MiB", mib);
    tf_free(&b);
}

TEST(extra_bytes_models_created_at_first_use_decode_a_record_of_65515_extra_bytes) {
    lazw_point_t *p = points(51, 3, 0);
    lazw_opts_t o = plain;
    o.extra = 65515;
    round_trip(&o, p, 3, 1);
    free(p);
}

TEST(a_chunk_denser_than_the_default_points_per_byte_is_refused_naming_the_limit_and_how_to_raise_it) {
    /* a million copies of one point in one chunk: a valid stream of about
     * 500 points a byte, 24 MB of result from 2 KB; the default limit
     * refuses it before decoding, a raised one reads it */
    size_t n = 1000000;
    lazw_point_t *p = malloc(n * sizeof *p);
    for (size_t k = 0; k < n; k++) p[k] = (lazw_point_t){5, 6, 7, 1, 1, 0};
    lazw_opts_t o = plain;
    o.chunk_size = (uint32_t)n;
    tf_buf_t b = {0};
    lazw_encode(&b, &o, p, n);
    size_t bytes = lazw_last.table - lazw_last.chunk[0];
    CHECK(n / bytes > HD_LAZ_POINTS_PER_BYTE && n / bytes < 1024);
    refused(&b, HD_EUNSUPPORTED, "above the limit of 256 points a compressed byte (the default)", (long long)lazw_last.chunk[0]);
    refused(&b, HD_EUNSUPPORTED, "--laz-points-per-byte N (read option laz_points_per_byte)", -1);
    per_byte = 1024;
    round_trip(&o, p, n, 2);
    per_byte = 300;
    refused(&b, HD_EUNSUPPORTED, "limit of 300 points a compressed byte (as asked)", -1);
    per_byte = HD_LAZ_POINTS_PER_BYTE_MAX + 1;
    refused(&b, HD_EINVAL, "laz_points_per_byte 4097 is above 4096", -1);
    per_byte = 0;
    tf_free(&b);
    free(p);
}

TEST(a_laz_file_whose_format_byte_lost_its_compression_bit_is_refused_naming_the_laszip_vlr) {
    for (int fmt = 0; fmt <= 6; fmt += 6) {
        CONTEXT("format %d", fmt);
        tf_buf_t b = {0};
        sample(&b, fmt, 100, 50);
        b.data[104] &= 0x7f; /* read as LAS: 100 records do not fit */
        refused(&b, HD_EFORMAT, "file ends inside the points", (long long)b.size);
        refused(&b, HD_EFORMAT, "a LASzip VLR (user 'laszip encoded', record 22204), so its points are compressed", -1);
        tf_free(&b);
    }
}
