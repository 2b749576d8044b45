/*
 * lazgen.c -- writes the LAZ files of the laz-perf check (tests/laz_lazperf.py):
 *
 *   lazgen DIR
 *
 * For each case, DIR/NAME.laz from the tests' LAZ writer
 * (tests/internal/lazwrite.c) and DIR/NAME.txt with its points' integer
 * coordinates, "X Y Z" per line in file order; then prints the case names,
 * one per line.  Seeded: the same files on every run.
 *
 *   lazgen --seeds DIR
 *
 * writes the fuzz target's seed files (tests/corpus/laz/, committed).
 *
 *   lazgen --records FILE
 *
 * prints every whole record of a LAZ file as the library decodes it (every
 * field of every item, every layer), one line of hexadecimal each.
 *
 *   lazgen --copc FILE
 *
 * checks that FILE is a valid COPC file (lazwrite.h's lazw_copc_nodes:
 * the info VLR, the hierarchy pages, every node exactly a chunk) and
 * prints its node and point counts, or why not (exit 1).
 *
 * The cases named field_* are the output of hd_write_fields (the library's
 * LAZ writer) on a file of the tests' writer whose points all lie in
 * scanner channel 0, with seeded values: their NAME.txt lines are
 * "X Y Z HEX", HEX the value's eight bytes as a little-endian 64-bit
 * integer in hexadecimal; fieldsN_* have N fields (distance, nearest,
 * sign), N HEX on each line.  (laz-perf 0.0.7 hands its BYTE14 decoder
 * channel 0 unless the channel changes at that very point, where LASzip
 * hands the point's channel: on files with other channels it decodes
 * extra bytes wrongly, so they are checked by test_write_laz alone.)
 * The cases named record_* are hd_write_fields's output on pointwise LAZ
 * whose every field varies (tests/internal/lazwrite.c's lazw_pointwise),
 * all points or those whose first value is > 0.25: their NAME.txt lines
 * are each written record in hexadecimal, byte by byte, the values' eight
 * bytes each last (_fieldsN: N of them).  The cases named record_formatK_*
 * with K of 6-8 are layered LAZ whose every field varies
 * (lazwrite.c's lazw_rich_records14), compressed by the library's layered
 * encoder (src/io/laz14.c), or hd_write_fields's output on such a file
 * (_subset: the points whose first value is > 0.25, encoded again; without
 * a field, its points may use every scanner channel); their
 * NAME.txt lines are whole records as above.
 */
#include "files.h"
#include "gen.h"
#include "lazwrite.h"

#include <hausdorff.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void write_case(const char *dir, const char *name, const lazw_opts_t *o, uint64_t seed, size_t n,
                       int with_points) {
    gen_rng_t g;
    gen_seed(&g, seed);
    lazw_point_t *p = malloc(n * sizeof *p);
    if (!p) exit(1);
    lazw_random(&g, p, n, o->format);
    tf_buf_t b = {0};
    lazw_encode(&b, o, p, n);
    char path[4096];
    snprintf(path, sizeof path, "%s/%s.laz", dir, name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(b.data, 1, b.size, f) != b.size || fclose(f)) {
        perror(path);
        exit(1);
    }
    if (!with_points) {
        tf_free(&b);
        free(p);
        return;
    }
    snprintf(path, sizeof path, "%s/%s.txt", dir, name);
    f = fopen(path, "w");
    if (!f) {
        perror(path);
        exit(1);
    }
    for (size_t k = 0; k < n; k++) fprintf(f, "%d %d %d\n", (int)p[k].x, (int)p[k].y, (int)p[k].z);
    if (fclose(f)) exit(1);
    printf("%s\n", name);
    tf_free(&b);
    free(p);
}

/* The names of the fields of a case: distance, nearest, sign. */
static const char *const field_names[3] = {"distance", "nearest", "sign"};

/* Fields 2 and 3 of a case (field j's n values at v + j * n): an index, a
 * sign. */
static void more_fields(double *v, size_t n, size_t nf) {
    for (size_t j = 1; j < nf; j++)
        for (size_t k = 0; k < n; k++) v[j * n + k] = j == 1 ? (double)(k * 7 % 1000) : k % 3 ? 1.0 : -1.0;
}

/* The input b saved as DIR/NAME-input.laz, hd_write_fields of the nf
 * fields of n values v (field j's at v + j * n; nf = 0: hd_write_field of
 * v with o's name, "" for none) into DIR/NAME.laz (o: NULL
 * for the defaults), the input removed, and DIR/NAME.txt opened for the
 * expected lines. */
static FILE *write_field_of(const char *dir, const char *name, const tf_buf_t *b, const double *v, size_t n,
                            size_t nf, const hd_write_options_t *o) {
    char in[4096], out[4096];
    snprintf(in, sizeof in, "%s/%s-input.laz", dir, name);
    snprintf(out, sizeof out, "%s/%s.laz", dir, name);
    FILE *f = fopen(in, "wb");
    if (!f || fwrite(b->data, 1, b->size, f) != b->size || fclose(f)) {
        perror(in);
        exit(1);
    }
    hd_error_t err;
    hd_field_t fields[3];
    for (size_t j = 0; j < nf; j++) fields[j].name = field_names[j], fields[j].values = v + j * n;
    if ((nf ? hd_write_fields(in, out, fields, nf, n, o, NULL, &err) : hd_write_field(in, out, v, n, o, NULL, &err)) != HD_OK) {
        fprintf(stderr, "lazgen: %s\n", err.message);
        exit(1);
    }
    remove(in);
    snprintf(out, sizeof out, "%s/%s.txt", dir, name);
    if (!(f = fopen(out, "w"))) exit(1);
    return f;
}

/* The field case NAME: see the top of the file. */
static void field_case(const char *dir, const char *name, const lazw_opts_t *o, uint64_t seed, size_t n, size_t nf) {
    gen_rng_t g;
    gen_seed(&g, seed);
    lazw_point_t *p = malloc(n * sizeof *p);
    double *v = malloc(nf * n * sizeof *v);
    if (!p || !v) exit(1);
    lazw_random(&g, p, n, o->format);
    for (size_t k = 0; k < n; k++) {
        p[k].channel = 0;
        v[k] = k % 3 == 0 ? gen_unit(&g) * 100 : k % 3 == 1 ? v[k - 1] : gen_normal(&g);
    }
    more_fields(v, n, nf);
    tf_buf_t b = {0};
    lazw_encode(&b, o, p, n);
    FILE *f = write_field_of(dir, name, &b, v, n, nf, NULL);
    for (size_t k = 0; k < n; k++) {
        fprintf(f, "%d %d %d", (int)p[k].x, (int)p[k].y, (int)p[k].z);
        for (size_t j = 0; j < nf; j++) {
            uint64_t u;
            memcpy(&u, &v[j * n + k], 8);
            fprintf(f, " %016llx", (unsigned long long)u);
        }
        fputc('\n', f);
    }
    if (fclose(f)) exit(1);
    printf("%s\n", name);
    tf_free(&b);
    free(p);
    free(v);
}

/* The expected lines of a case: each kept record in hexadecimal, then its
 * nf values' bytes (kept: all, or those whose first value is > 0.25 when
 * `subset`); f is closed. */
static void expected_records(FILE *f, const unsigned char *recs, size_t rec, const double *v, size_t n, size_t nf,
                             int subset) {
    for (size_t k = 0; k < n; k++) {
        if (subset && !(v[k] > 0.25)) continue;
        for (size_t i = 0; i < rec; i++) fprintf(f, "%02x", recs[k * rec + i]);
        for (size_t j = 0; j < nf; j++) {
            unsigned char val[8];
            memcpy(val, &v[j * n + k], 8);
            for (int i = 0; i < 8; i++) fprintf(f, "%02x", val[i]);
        }
        fputc('\n', f);
    }
    if (fclose(f)) exit(1);
}
/* The record case NAME: see the top of the file. */
static void record_case(const char *dir, const char *name, int fmt, unsigned extra, int subset, uint64_t seed, size_t n,
                        size_t nf) {
    gen_rng_t g;
    gen_seed(&g, seed);
    size_t rec;
    unsigned char *recs = lazw_rich_records(&g, fmt, extra, n, &rec);
    double *v = malloc(nf * n * sizeof *v);
    if (!recs || !v) exit(1);
    for (size_t k = 0; k < n; k++) v[k] = k % 4 ? gen_normal(&g) : 0.5;
    more_fields(v, n, nf);
    tf_buf_t b = {0};
    lazw_pointwise(&b, fmt, extra, recs, rec, n, 1000);
    hd_write_options_t o;
    hd_write_options_init(&o);
    o.keep = subset ? HD_KEEP_FARTHER : HD_KEEP_ALL;
    o.threshold = 0.25;
    FILE *f = write_field_of(dir, name, &b, v, n, nf, &o);
    expected_records(f, recs, rec, v, n, nf, subset);
    printf("%s\n", name);
    tf_free(&b);
    free(recs);
    free(v);
}

static int save(const char *dir, const char *name, const tf_buf_t *b);

/* The layered record case NAME: records of LAS 1.4 format fmt whose every
 * field varies (channels switching when `channels`), compressed by the
 * library's layered encoder with items of `version`; with nf = 0 that file
 * is the case, else hd_write_fields's output on it (all points, or those
 * whose first value is > 0.25 when `subset`). */
static void record14_case(const char *dir, const char *name, int fmt, unsigned extra, int channels, unsigned version,
                          int subset, uint64_t seed, size_t n, size_t nf) {
    gen_rng_t g;
    gen_seed(&g, seed);
    size_t rec;
    unsigned char *recs = lazw_rich_records14(&g, fmt, extra, n, &rec, channels);
    double *v = malloc((nf ? nf : 1) * n * sizeof *v);
    if (!recs || !v) exit(1);
    for (size_t k = 0; k < n; k++) v[k] = k % 4 ? gen_normal(&g) : 0.5;
    more_fields(v, n, nf);
    tf_buf_t b = {0};
    lazw_layered(&b, fmt, extra, recs, rec, n, 1000, version);
    FILE *f;
    if (nf || subset) { /* nf = 0: the subset alone, no field added (write option name "") */
        hd_write_options_t o;
        hd_write_options_init(&o);
        o.keep = subset ? HD_KEEP_FARTHER : HD_KEEP_ALL;
        o.threshold = 0.25;
        if (!nf) o.name = "";
        f = write_field_of(dir, name, &b, v, n, nf, &o);
    } else {
        if (save(dir, name, &b)) exit(1);
        char path[4096];
        snprintf(path, sizeof path, "%s/%s.txt", dir, name);
        if (!(f = fopen(path, "w"))) exit(1);
    }
    expected_records(f, recs, rec, v, n, nf, subset);
    printf("%s\n", name);
    tf_free(&b);
    free(recs);
    free(v);
}

static int save(const char *dir, const char *name, const tf_buf_t *b) {
    char path[4096];
    snprintf(path, sizeof path, "%s/%s.laz", dir, name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(b->data, 1, b->size, f) != b->size || fclose(f)) {
        perror(path);
        return 1;
    }
    return 0;
}

static void put_le(tf_buf_t *b, size_t at, uint64_t v, int bytes) {
    for (int i = 0; i < bytes; i++) b->data[at + i] = (unsigned char)(v >> (8 * i));
}

/* Hostile shapes the reader refuses (regress-*): header counts lower than
 * the data (the one-point chunk, the last of several chunks, LASzip 1's
 * stream, a layered chunk whose own count lies too), items said to be of
 * another version than the data's (LASzip 1 streams whose lie decodes
 * without running past them), a format byte without its compression bit. */
static int lies(const char *dir) {
    static const struct {
        const char *name;
        int format, v1;
        uint32_t chunk;
        size_t n;
        uint64_t seed;
        uint32_t count; /* the header's count, 0: kept */
        int item;       /* an item whose version becomes 2, -1: none */
        int plain;      /* the format byte's compression bit cleared */
    } c[] = {{"regress-count-1-of-100", 0, 0, 1000, 100, 11, 1, -1, 0},
             {"regress-count-99-of-100-last-chunk", 1, 0, 50, 100, 12, 99, -1, 0},
             {"regress-count-60-of-100-laszip1", 3, 1, 1, 100, 13, 60, -1, 0},
             {"regress-count-99-of-100-layered", 6, 0, 100, 100, 14, 99, -1, 0},
             {"regress-point10-v1-said-v2", 0, 1, 1, 6, 3, 0, 0, 0},
             {"regress-rgb12-v1-said-v2", 2, 1, 1, 3, 3, 0, 1, 0},
             {"regress-compression-bit-cleared", 1, 0, 50, 100, 15, 0, -1, 1}};
    int rc = 0;
    for (size_t k = 0; k < sizeof c / sizeof c[0]; k++) {
        gen_rng_t g;
        gen_seed(&g, c[k].seed);
        lazw_point_t p[100];
        lazw_random(&g, p, c[k].n, c[k].format);
        lazw_opts_t o = {c[k].format, 0, c[k].chunk, NULL, 0, {0.01, 0.01, 0.01}, {-5, 7, 0.5}, c[k].v1};
        tf_buf_t b = {0};
        lazw_encode(&b, &o, p, c[k].n);
        if (c[k].count && c[k].format >= 6) {
            put_le(&b, 247, c[k].count, 8);
            put_le(&b, lazw_last.chunk[0] + 30, c[k].count, 4); /* the chunk's own count */
        } else if (c[k].count) {
            put_le(&b, 107, c[k].count, 4);
        }
        if (c[k].item >= 0) b.data[lazw_last.vlr + 34 + 6 * (size_t)c[k].item + 4] = 2;
        if (c[k].plain) b.data[104] &= 0x7f;
        rc |= save(dir, c[k].name, &b);
        tf_free(&b);
    }
    return rc;
}

/* The fuzz target's seeds (tests/corpus/laz/): small files of each scheme,
 * and the hostile shapes. */
static int seeds(const char *dir) {
    static const size_t sizes[] = {9, 1, 20};
    lazw_opts_t o = {0, 0, 16, NULL, 0, {0.01, 0.01, 0.01}, {-5, 7, 0.5}, 0};
    write_case(dir, "fmt0_chunks16", &o, 1, 40, 0);
    o.format = 3, o.extra = 2;
    write_case(dir, "fmt3_extra2", &o, 2, 30, 0);
    o.format = 6, o.extra = 0;
    write_case(dir, "fmt6_channels", &o, 3, 60, 0);
    o.extra = 1, o.chunk_size = 0, o.chunks = sizes, o.n_chunks = 3;
    write_case(dir, "fmt6_variable_extra1", &o, 4, 30, 0);
    o.format = 1, o.extra = 0;
    write_case(dir, "fmt1_variable", &o, 5, 30, 0);
    o.format = 3, o.extra = 1, o.v1 = 1;
    write_case(dir, "fmt3_laszip1_extra1", &o, 6, 30, 0);
    /* layered, every field varying in all four channels: colour, NIR and
     * extra bytes, items of version 3 (the writers' whole-record decoder) */
    gen_rng_t g;
    gen_seed(&g, 7);
    size_t rec;
    unsigned char *recs = lazw_rich_records14(&g, 8, 2, 50, &rec, 1);
    tf_buf_t rb = {0};
    lazw_layered(&rb, 8, 2, recs, rec, 50, 20, 3);
    int rc0 = save(dir, "fmt8_every_field_extra2", &rb);
    tf_free(&rb);
    free(recs);
    recs = lazw_rich_records14(&g, 10, 0, 40, &rec, 1); /* and wave packets (WAVEPACKET14), version 4 */
    lazw_layered(&rb, 10, 0, recs, rec, 40, 20, 4);
    rc0 |= save(dir, "fmt10_every_field", &rb);
    tf_free(&rb);
    free(recs);
    /* one point repeated: over 64 points per byte, the reader's growing path */
    static lazw_point_t same[40000];
    for (size_t k = 0; k < 40000; k++) same[k] = (lazw_point_t){1, 2, 3, 1, 1, 0};
    lazw_opts_t r = {0, 0, 40000, NULL, 0, {0.5, 0.5, 0.5}, {0, 0, 0}, 0};
    tf_buf_t b = {0};
    lazw_encode(&b, &r, same, 40000);
    int rc = rc0 | save(dir, "fmt0_repeated_point", &b);
    tf_free(&b);
    /* a million copies of one point in one chunk, about 500 a byte: denser
     * than the reader's default limit (--laz-points-per-byte raises it) */
    static lazw_point_t many[1000000];
    for (size_t k = 0; k < 1000000; k++) many[k] = (lazw_point_t){1, 2, 3, 1, 1, 0};
    r.chunk_size = 1000000;
    lazw_encode(&b, &r, many, 1000000);
    rc |= save(dir, "regress-dense-1000000-points", &b);
    tf_free(&b);
    return rc | lies(dir);
}

/* lazgen --records FILE: every whole record of the LAZ file as the
 * library decodes it (every field, every layer), one line of hexadecimal
 * each; 1 with the error when it is refused. */
static int records(const char *path) {
    size_t size, n, rec;
    unsigned char *d = tf_read(path, &size);
    hd_error_t err;
    unsigned char *r = d ? lazw_decode_records(path, d, size, &n, &rec, &err) : NULL;
    if (!r) {
        fprintf(stderr, "lazgen: %s: %s\n", path, d ? err.message : "cannot read");
        free(d);
        return 1;
    }
    for (size_t k = 0; k < n; k++) {
        for (size_t i = 0; i < rec; i++) printf("%02x", r[k * rec + i]);
        putchar('\n');
    }
    free(r);
    free(d);
    return 0;
}

static int copc(const char *path) {
    size_t size, n = 0, cap = 1 << 20;
    unsigned char *d = tf_read(path, &size);
    lazw_node_t *nodes = malloc(cap * sizeof *nodes);
    char why[256];
    if (!d || !nodes) {
        fprintf(stderr, "lazgen: %s: cannot read\n", path);
        return 1;
    }
    int rc = lazw_copc_nodes(d, size, nodes, cap, &n, why, sizeof why);
    uint64_t points = 0;
    for (size_t k = 0; k < n; k++) points += nodes[k].count;
    if (rc) fprintf(stderr, "%s: not valid COPC: %s\n", path, why);
    else printf("%s: valid COPC: %zu nodes, %llu points\n", path, n, (unsigned long long)points);
    free(nodes);
    free(d);
    return rc ? 1 : 0;
}

int main(int argc, char **argv) {
    if (argc == 3 && strcmp(argv[1], "--seeds") == 0) return seeds(argv[2]);
    if (argc == 3 && strcmp(argv[1], "--copc") == 0) return copc(argv[2]);
    if (argc == 3 && strcmp(argv[1], "--records") == 0) return records(argv[2]);
    if (argc != 2) {
        fprintf(stderr, "usage: lazgen DIR | lazgen --seeds DIR | lazgen --records FILE | lazgen --copc FILE\n");
        return 2;
    }
    static const size_t sizes[] = {1, 700, 33, 2000, 1266};
    for (int fmt = 0; fmt <= 3; fmt++)
        for (unsigned extra = 0; extra <= 2; extra += 2) {
            char name[64];
            snprintf(name, sizeof name, "format%d_extra%u", fmt, extra);
            lazw_opts_t o = {fmt, extra, 1000, NULL, 0, {0.01, 0.01, 0.01}, {100, 200, 300}, 0};
            write_case(argv[1], name, &o, 100 + (uint64_t)fmt * 10 + extra, 2500, 1);
        }
    for (unsigned extra = 0; extra <= 3; extra += 3) {
        char name[64];
        snprintf(name, sizeof name, "format6_extra%u", extra);
        lazw_opts_t o = {6, extra, 1000, NULL, 0, {0.001, 0.001, 0.001}, {0, 0, 0}, 0};
        write_case(argv[1], name, &o, 200 + extra, 2500, 1);
    }
    lazw_opts_t v = {6, 0, 0, sizes, 5, {0.01, 0.01, 0.01}, {0, 0, 0}, 0};
    write_case(argv[1], "format6_variable_chunks", &v, 300, 4000, 1);
    v.format = 1;
    write_case(argv[1], "format1_variable_chunks", &v, 301, 4000, 1);
    lazw_opts_t w = {6, 0, 1000, NULL, 0, {0.001, 0.001, 0.001}, {0, 0, 0}, 0};
    field_case(argv[1], "field_format6_extra0", &w, 400, 2500, 1);
    field_case(argv[1], "fields2_format6_extra0", &w, 410, 2500, 2);
    w.extra = 3, w.chunk_size = 0, w.chunks = sizes, w.n_chunks = 5;
    field_case(argv[1], "field_format6_extra3_variable_chunks", &w, 401, 4000, 1);
    field_case(argv[1], "fields3_format6_extra3_variable_chunks", &w, 411, 4000, 3);
    record_case(argv[1], "record_format1_extra0", 1, 0, 0, 500, 2500, 1);
    record_case(argv[1], "record_format2_extra3", 2, 3, 0, 501, 2500, 1);
    record_case(argv[1], "record_format3_extra1_subset", 3, 1, 1, 502, 3001, 1);
    record_case(argv[1], "record_format0_extra0_subset", 0, 0, 1, 503, 2500, 1);
    record_case(argv[1], "record_format1_extra0_fields3", 1, 0, 0, 510, 2500, 3);
    record_case(argv[1], "record_format3_extra1_fields2_subset", 3, 1, 1, 511, 3001, 2);
    /* layered, every layer.  laz-perf 0.0.7 hands the RGB14, RGBNIR14 and
     * BYTE14 decoders channel 0 except at a point where the channel
     * changes, so colours, extra bytes and fields go with channel 0; the
     * nine POINT14 layers switch channels */
    record14_case(argv[1], "record_format6_channels_v3", 6, 0, 1, 3, 0, 600, 3001, 0);
    record14_case(argv[1], "record_format6_channels_v4", 6, 0, 1, 4, 0, 604, 3001, 0);
    record14_case(argv[1], "record_format7_v4", 7, 0, 0, 4, 0, 601, 3001, 0);
    record14_case(argv[1], "record_format8_v3", 8, 0, 0, 3, 0, 602, 3001, 0);
    record14_case(argv[1], "record_format8_extra2_v4", 8, 2, 0, 4, 0, 603, 2500, 0);
    record14_case(argv[1], "record_format6_extra1_subset", 6, 1, 0, 3, 1, 610, 3001, 1);
    record14_case(argv[1], "record_format6_channels_subset", 6, 0, 1, 4, 1, 612, 3001, 0);
    record14_case(argv[1], "record_format7_fields2_subset", 7, 0, 0, 4, 1, 611, 3001, 2);
    return 0;
}
