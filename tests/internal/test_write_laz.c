/*
 * test_write_laz.c -- hd_write_field and hd_write_fields into layered LAZ
 * (src/io/write_laz.c):
 * files of the tests' LAZ writer (random points in every scanner channel,
 * fixed and variable chunks, with and without extra bytes) get a field;
 * the output is taken apart here: its header and LASzip VLR, its chunk
 * table, every chunk's old layers byte for byte as they were, and the
 * new BYTE14 layers (8 a field) decoded by this file's own loop over the
 * coder's primitives with LASzip's v3 rule for the scanner channels (the
 * channel of each point known from the points given to the writer), so
 * every value comes back bit for bit.  Pointwise LAZ (formats 0-3) whose
 * every field varies, compressed by the library's pointwise encoder, is
 * decoded back to its records, and hd_write_field's output (all points, a
 * subset) to the same records with the values after them.  laz-perf
 * checks these outputs too where it can (tests/laz_lazperf.py, field_*
 * cases).  And the LAZ refusals, the writer's own among them: chunks that
 * do not decode, given to hd__write_laz without the read of the input
 * that hd_write_field makes first and that refuses them before.
 */
#include "check.h"
#include "files.h"
#include "gen.h"
#include "lazwrite.h"

#include "io/io.h"
#include "io/lasfield.h"
#include "io/lazcoder.h"

#include <stdlib.h>
#include <string.h>

static uint64_t le(const unsigned char *p, int n) {
    uint64_t v = 0;
    for (int i = n - 1; i >= 0; i--) v = v << 8 | p[i];
    return v;
}


typedef struct {
    size_t offset, rec, vlr; /* the LASzip VLR's data */
    unsigned n_items, last_type, last_size;
    uint64_t table;
} laz_t;

static void parse(const unsigned char *d, laz_t *L) {
    L->offset = le(d + 96, 4);
    L->rec = le(d + 105, 2);
    size_t p = le(d + 94, 2);
    for (unsigned i = 0; i < le(d + 100, 4); i++) {
        if (memcmp(d + p + 2, "laszip encoded", 14) == 0) L->vlr = p + 54;
        p += 54 + le(d + p + 20, 2);
    }
    L->n_items = (unsigned)le(d + L->vlr + 32, 2);
    L->last_type = (unsigned)le(d + L->vlr + 34 + 6 * (L->n_items - 1), 2);
    L->last_size = (unsigned)le(d + L->vlr + 34 + 6 * (L->n_items - 1) + 2, 2);
    L->table = le(d + L->offset, 8);
}

/* The chunk table's byte sizes (and counts when variable) of nc chunks. */
static void table(const unsigned char *d, size_t size, uint64_t at, int variable, size_t nc, uint32_t *bytes,
                  uint32_t *counts) {
    hd__intcoder_t ic;
    CHECK(hd__intcoder_new(&ic, 32, 2) == HD_OK);
    hd__dec_t dec;
    hd__dec_init(&dec, d + at + 8, size - at - 8);
    uint32_t pc = 0, pb = 0;
    for (size_t k = 0; k < nc; k++) {
        if (variable) pc = counts[k] = (uint32_t)hd__ic_decode(&ic, &dec, (int32_t)pc, 0);
        pb = bytes[k] = (uint32_t)hd__ic_decode(&ic, &dec, (int32_t)pb, 1);
    }
    hd__intcoder_free(&ic);
}

/* The nb BYTE14 layers at `layers` (sizes `sz`) of a chunk of n points
 * with channels p[].channel, decoded with LASzip's v3 rule into out (nb
 * bytes a point): a channel's models and last bytes start from the last
 * bytes of the channel before it when it first appears; at a switch to a
 * channel seen before, the point is predicted from (and updates) the last
 * bytes of the channel it follows. */
static void decode_bytes(const unsigned char *first, const unsigned char *layers, const uint32_t *sz, size_t nb,
                         const lazw_point_t *p, size_t n, unsigned char *out) {
    hd__dec_t *dec = calloc(nb, sizeof *dec);
    hd__symmodel_t(*m)[4] = calloc(nb, sizeof *m);
    unsigned char *last = calloc(4, nb);
    int used[4] = {0};
    size_t at = 0;
    for (size_t b = 0; b < nb; b++) {
        hd__dec_init(&dec[b], layers + at, sz[b]);
        at += sz[b];
        for (int c = 0; c < 4; c++) CHECK(hd__symmodel_new(&m[b][c], 256) == HD_OK);
    }
    unsigned cur = p[0].channel;
    memcpy(last + cur * nb, first, nb);
    used[cur] = 1;
    memcpy(out, first, nb);
    for (size_t i = 1; i < n; i++) {
        unsigned char *L = last + cur * nb;
        if (p[i].channel != cur) {
            cur = p[i].channel;
            if (!used[cur]) {
                used[cur] = 1;
                memcpy(last + cur * nb, L, nb);
                L = last + cur * nb;
            }
        }
        for (size_t b = 0; b < nb; b++)
            if (sz[b]) L[b] = (unsigned char)(L[b] + hd__dec_symbol(&dec[b], &m[b][cur]));
        memcpy(out + i * nb, L, nb);
    }
    for (size_t b = 0; b < nb; b++) {
        CHECK(sz[b] == 0 || (dec[b].over == 0 && dec[b].p == dec[b].end)); /* each layer used up exactly */
        for (int c = 0; c < 4; c++) hd__symmodel_free(&m[b][c]);
    }
    free(dec), free(m), free(last);
}

/* nf fields of n values (field j's at v + j * n): runs of equal values,
 * small steps, any double; an index; a sign. */
static void field_values(gen_rng_t *g, double *v, size_t n, size_t nf) {
    for (size_t k = 0; k < n; k++)
        v[k] = k % 5 == 0 ? gen_unit(g) * 1e3 : k % 5 == 1 ? v[k - 1] : k % 5 == 2 ? v[k - 1] + 1e-9 : gen_normal(g);
    for (size_t j = 1; j < nf; j++)
        for (size_t k = 0; k < n; k++) v[j * n + k] = j == 1 ? (double)(k * 7 % 1000) : k % 3 ? 1.0 : -1.0;
}

static const char *const field_names[3] = {"distance", "nearest", "sign"};

/* hd_write_fields of nf fields (values field_values's, names field_names). */
static int write_fields(const char *in, const char *out, const double *v, size_t n, size_t nf,
                        const hd_write_options_t *o, size_t *written, hd_error_t *err) {
    hd_field_t f[3];
    for (size_t j = 0; j < nf; j++) f[j].name = field_names[j], f[j].values = v + j * n;
    return hd_write_fields(in, out, f, nf, n, o, written, err);
}

static void laz_case(const lazw_opts_t *o, size_t n, uint64_t seed, size_t nf) {
    CONTEXT("format %d extra %u chunk %u seed %llu fields %zu", o->format, o->extra, o->chunk_size,
            (unsigned long long)seed, nf);
    gen_rng_t g;
    gen_seed(&g, seed);
    lazw_point_t *p = malloc(n * sizeof *p);
    lazw_random(&g, p, n, o->format);
    tf_buf_t b = {0};
    lazw_encode(&b, o, p, n);
    size_t nin = b.size, nb = 8 * nf;
    unsigned char *src = malloc(nin);
    memcpy(src, b.data, nin);
    const char *in = tf_finish(&b, "in.laz");
    double *v = malloc(nf * n * sizeof *v);
    unsigned char *got = malloc(n * nb);
    field_values(&g, v, n, nf);
    const char *out = tf_path("out.laz");
    hd_error_t err;
    size_t written = 0;
    if (nf == 1) CHECK_RC(hd_write_field(in, out, v, n, NULL, &written, &err), HD_OK);
    else CHECK_RC(write_fields(in, out, v, n, nf, NULL, &written, &err), HD_OK);
    CHECK_EQ(written, n);
    size_t no;
    unsigned char *d = tf_read(out, &no);
    laz_t I, O;
    parse(src, &I);
    parse(d, &O);
    CHECK_EQ(O.rec, I.rec + nb);
    CHECK_EQ(O.last_type, 14);
    CHECK_EQ(O.last_size, o->extra + nb);
    CHECK_EQ(O.n_items, I.n_items + (o->extra == 0));
    size_t nc = o->chunk_size ? (n + o->chunk_size - 1) / o->chunk_size : o->n_chunks;
    uint32_t *ib = calloc(nc, 4), *ob = calloc(nc, 4), *ic = calloc(nc, 4), *oc = calloc(nc, 4), *sz = calloc(nb, 4);
    table(src, nin, I.table, !o->chunk_size, nc, ib, ic);
    table(d, no, O.table, !o->chunk_size, nc, ob, oc);
    CHECK(memcmp(ic, oc, nc * 4) == 0);
    size_t at_i = I.offset + 8, at_o = O.offset + 8, first = 0, layers = 9 + o->extra;
    for (size_t c = 0; c < nc && !hdt_failed(); c++) {
        size_t k = o->chunk_size ? (n - first < o->chunk_size ? n - first : o->chunk_size) : o->chunks[c];
        const unsigned char *ci = src + at_i, *co = d + at_o;
        CHECK(memcmp(co, ci, I.rec) == 0);                            /* the first point */
        CHECK(memcmp(co + I.rec + nb, ci + I.rec, 4 + 4 * layers) == 0); /* count, old sizes */
        uint32_t old = 0, add = 0;
        for (size_t q = 0; q < layers; q++) old += (uint32_t)le(ci + I.rec + 4 + 4 * q, 4);
        for (size_t q = 0; q < nb; q++) add += sz[q] = (uint32_t)le(co + I.rec + nb + 4 + 4 * layers + 4 * q, 4);
        size_t hi = I.rec + 4 + 4 * layers, ho = hi + nb + 4 * nb;
        CHECK(memcmp(co + ho, ci + hi, old) == 0); /* the old layers */
        CHECK_EQ(ob[c], ib[c] + nb + 4 * nb + add);
        decode_bytes(co + I.rec, co + ho + old, sz, nb, p + first, k, got + first * nb);
        at_i += ib[c];
        at_o += ob[c];
        first += k;
    }
    for (size_t k = 0; k < n && !hdt_failed(); k++)
        for (size_t j = 0; j < nf; j++) {
            double x;
            memcpy(&x, got + k * nb + 8 * j, 8);
            CHECK_BITS(x, v[j * n + k]);
        }
    /* the points read back as before */
    hd_cloud_t *a = NULL, *c = NULL;
    CHECK_RC(hd_read_file(in, NULL, &a, &err), HD_OK);
    CHECK_RC(hd_read_file(out, NULL, &c, &err), HD_OK);
    CHECK(a && c && a->count == c->count && memcmp(a->data, c->data, 3 * n * sizeof(double)) == 0);
    hd_cloud_free(a);
    hd_cloud_free(c);
    free(ib), free(ob), free(ic), free(oc), free(sz);
    free(d), free(src), free(v), free(got), free(p);
}

TEST(layered_laz_gains_the_field_as_byte14_layers) {
    lazw_opts_t o = {6, 0, 50, NULL, 0, {0.01, 0.01, 0.001}, {1000.5, -20.25, 3}, 0};
    for (uint64_t seed = 1; seed <= 3; seed++) laz_case(&o, 1000, seed, 1);
    o.extra = 3; /* a BYTE14 item grows */
    laz_case(&o, 777, 4, 1);
    size_t chunks[4] = {1, 300, 2, 197};
    lazw_opts_t v = {6, 2, 0, chunks, 4, {0.01, 0.01, 0.01}, {0, 0, 0}, 0};
    laz_case(&v, 500, 5, 1);
    o.chunk_size = 1; /* one-point chunks: empty layers */
    laz_case(&o, 5, 6, 1);
}

TEST(layered_laz_gains_several_fields_as_eight_byte14_layers_each) {
    for (size_t nf = 2; nf <= 3; nf++) {
        lazw_opts_t o = {6, 0, 50, NULL, 0, {0.01, 0.01, 0.001}, {1000.5, -20.25, 3}, 0};
        laz_case(&o, 1000, 10 + nf, nf); /* a BYTE14 item of 8 * nf added */
        o.extra = 3;                      /* a BYTE14 item grows by 8 * nf */
        laz_case(&o, 777, 20 + nf, nf);
        size_t chunks[4] = {1, 300, 2, 197};
        lazw_opts_t v = {6, 2, 0, chunks, 4, {0.01, 0.01, 0.01}, {0, 0, 0}, 0};
        laz_case(&v, 500, 30 + nf, nf);
    }
}

/* The LAZ file (options o) of n random points of o's format drawn from
 * seed (lazw_random), in b. */
static void random_laz(tf_buf_t *b, const lazw_opts_t *o, size_t n, uint64_t seed) {
    gen_rng_t g;
    gen_seed(&g, seed);
    lazw_point_t *p = malloc(n * sizeof *p);
    lazw_random(&g, p, n, o->format);
    lazw_encode(b, o, p, n);
    free(p);
}

TEST(laz_extended_vlrs_follow_the_points_with_their_offset_moved) {
    lazw_opts_t o = {6, 0, 100, NULL, 0, {0.01, 0.01, 0.01}, {0, 0, 0}, 0};
    tf_buf_t b = {0};
    random_laz(&b, &o, 300, 31);
    uint64_t at = b.size; /* an extended VLR after the chunk table */
    for (int i = 0; i < 8; i++) b.data[235 + i] = (unsigned char)(at >> 8 * i);
    b.data[243] = 1;
    char user[16] = "someone", desc[32] = "kept";
    tf_u16(&b, 0, 0), tf_put(&b, user, 16), tf_u16(&b, 9, 0), tf_u64(&b, 4, 0), tf_put(&b, desc, 32), tf_put(&b, "EVLR", 4);
    const char *in = tf_finish(&b, "evlr.laz");
    double v[300];
    for (int k = 0; k < 300; k++) v[k] = k * 0.5;
    hd_error_t err;
    CHECK_RC(hd_write_field(in, tf_path("evlr_out.laz"), v, 300, NULL, NULL, &err), HD_OK);
    size_t n;
    unsigned char *d = tf_read(tf_path("evlr_out.laz"), &n);
    CHECK(d && n > 64 && memcmp(d + n - 4, "EVLR", 4) == 0);
    CHECK_EQ(le(d + 235, 8), n - 64);
    CHECK_EQ(le(d + 243, 4), 1);
    hd_cloud_t *c = NULL;
    CHECK_RC(hd_read_file(tf_path("evlr_out.laz"), NULL, &c, &err), HD_OK);
    CHECK(c && c->count == 300);
    hd_cloud_free(c);
    free(d);
}

/* ---- pointwise LAZ: every field compressed again ------------------------- */
/* Every whole record of the LAZ file at path, decoded by laz.c. */
static unsigned char *records_of(const char *path, size_t *n, size_t *rec) {
    size_t size;
    unsigned char *d = tf_read(path, &size);
    hd_error_t err;
    unsigned char *out = lazw_decode_records(path, d, size, n, rec, &err);
    if (!out) CONTEXT("%s", err.message);
    CHECK(out != NULL);
    free(d);
    return out;
}

/* A pointwise LAZ file in b (lazw_pointwise, chunks of `chunk` points) of
 * n random records of format fmt with `extra` bytes (lazw_rich_records),
 * drawn from g seeded with `seed` (g goes on from there); the records
 * returned (malloc'd), *rec bytes each. */
static unsigned char *pointwise_file(gen_rng_t *g, uint64_t seed, int fmt, unsigned extra, size_t n, size_t chunk,
                                     tf_buf_t *b, size_t *rec) {
    gen_seed(g, seed);
    unsigned char *recs = lazw_rich_records(g, fmt, extra, n, rec);
    lazw_pointwise(b, fmt, extra, recs, *rec, n, chunk);
    return recs;
}

/* The same, layered (lazw_layered: LAS 1.4 format fmt, items of
 * `version`; scanner channels switching when `channels`). */
static unsigned char *layered_file(gen_rng_t *g, uint64_t seed, int fmt, unsigned extra, int channels, size_t n,
                                   size_t chunk, unsigned version, tf_buf_t *b, size_t *rec) {
    gen_seed(g, seed);
    unsigned char *recs = lazw_rich_records14(g, fmt, extra, n, rec, channels);
    lazw_layered(b, fmt, extra, recs, *rec, n, chunk, version);
    return recs;
}

TEST(pointwise_laz_is_compressed_again_with_every_field) {
    for (int fmt = 0; fmt <= 3; fmt++)
        for (unsigned extra = 0; extra <= 3; extra += 3) {
            CONTEXT("format %d extra %u", fmt, extra);
            gen_rng_t g;
            size_t n = 3001, rec;
            tf_buf_t b = {0};
            unsigned char *recs = pointwise_file(&g, 77 + (uint64_t)fmt * 10 + extra, fmt, extra, n, 1000, &b, &rec);
            const char *in = tf_finish(&b, "rich.laz");
            size_t m, mrec;
            unsigned char *back = records_of(in, &m, &mrec); /* the encoder's file decodes to its records */
            CHECK(m == n && mrec == rec && memcmp(back, recs, n * rec) == 0);
            free(back);
            double *v = malloc(n * sizeof *v);
            for (size_t k = 0; k < n; k++) v[k] = k % 4 ? gen_normal(&g) : 0.5;
            hd_error_t err;
            hd_write_options_t o;
            hd_write_options_init(&o);
            for (int keep = 0; keep < 2; keep++) {
                o.keep = keep ? HD_KEEP_FARTHER : HD_KEEP_ALL;
                o.threshold = 0.25;
                size_t written = 0;
                CHECK_RC(hd_write_field(in, tf_path("rich_out.laz"), v, n, &o, &written, &err), HD_OK);
                unsigned char *out = records_of(tf_path("rich_out.laz"), &m, &mrec);
                CHECK(mrec == rec + 8 && m == written);
                for (size_t k = 0, j = 0; k < n && !hdt_failed(); k++) {
                    if (keep && !(v[k] > 0.25)) continue;
                    CHECK(memcmp(out + j * mrec, recs + k * rec, rec) == 0);
                    double got;
                    memcpy(&got, out + j * mrec + rec, 8);
                    CHECK_BITS(got, v[k]);
                    j++;
                }
                free(out);
            }
            free(v);
            free(recs);
        }
}

TEST(pointwise_laz_takes_several_fields_in_the_byte_item) {
    for (int fmt = 1; fmt <= 3; fmt += 2)
        for (size_t nf = 2; nf <= 3; nf++) {
            unsigned extra = fmt == 3 ? 2 : 0;
            CONTEXT("format %d extra %u fields %zu", fmt, extra, nf);
            gen_rng_t g;
            size_t n = 2501, rec, m, mrec;
            tf_buf_t b = {0};
            unsigned char *recs = pointwise_file(&g, 177 + (uint64_t)fmt * 10 + nf, fmt, extra, n, 1000, &b, &rec);
            const char *in = tf_finish(&b, "rich_n.laz");
            double *v = malloc(nf * n * sizeof *v);
            field_values(&g, v, n, nf);
            hd_error_t err;
            hd_write_options_t o;
            hd_write_options_init(&o);
            for (int keep = 0; keep < 2; keep++) {
                o.keep = keep ? HD_KEEP_FARTHER : HD_KEEP_ALL;
                o.threshold = 0.25; /* on the first field */
                size_t written = 0;
                CHECK_RC(write_fields(in, tf_path("rich_n_out.laz"), v, n, nf, &o, &written, &err), HD_OK);
                unsigned char *out = records_of(tf_path("rich_n_out.laz"), &m, &mrec);
                CHECK(mrec == rec + 8 * nf && m == written);
                size_t j = 0;
                for (size_t k = 0; k < n && !hdt_failed(); k++) {
                    if (keep && !(v[k] > 0.25)) continue;
                    CHECK(memcmp(out + j * mrec, recs + k * rec, rec) == 0);
                    for (size_t f = 0; f < nf; f++) {
                        double x;
                        memcpy(&x, out + j * mrec + rec + 8 * f, 8);
                        CHECK_BITS(x, v[f * n + k]);
                    }
                    j++;
                }
                CHECK(keep ? j < n : j == n);
                free(out);
            }
            free(v);
            free(recs);
        }
}

/* ---- layered LAZ: every field of every layer ------------------------------ */
/* The LASzip VLR's compressor and its items' versions of the file at path. */
static void laz_vlr(const char *path, unsigned *compressor, unsigned *version, unsigned *n_items) {
    size_t size;
    unsigned char *d = tf_read(path, &size);
    laz_t L;
    memset(&L, 0, sizeof L);
    parse(d, &L);
    *compressor = (unsigned)le(d + L.vlr, 2);
    *n_items = L.n_items;
    for (unsigned i = 0; i < L.n_items; i++) version[i] = (unsigned)le(d + L.vlr + 34 + 6 * i + 4, 2);
    free(d);
}

TEST(layered_laz_every_field_decodes_back_to_its_records) {
    for (int fmt = 6; fmt <= 10; fmt++)
        for (unsigned extra = 0; extra <= 3; extra += 3)
            for (unsigned version = 3; version <= 4; version++)
                for (int channels = 0; channels < 2; channels++) {
                    uint64_t seed = 300 + (uint64_t)fmt * 100 + extra * 10 + version * 2 + (uint64_t)channels;
                    CONTEXT("format %d extra %u version %u channels %d seed %llu", fmt, extra, version, channels,
                            (unsigned long long)seed);
                    gen_rng_t g;
                    size_t n = 3001, rec, m, mrec;
                    tf_buf_t b = {0};
                    unsigned char *recs = layered_file(&g, seed, fmt, extra, channels, n, 1000, version, &b, &rec);
                    const char *in = tf_finish(&b, "rich14.laz");
                    unsigned char *back = records_of(in, &m, &mrec);
                    CHECK(m == n && mrec == rec);
                    for (size_t k = 0; k < n && !hdt_failed(); k++) {
                        CONTEXT("format %d extra %u version %u channels %d point %zu", fmt, extra, version, channels, k);
                        CHECK(memcmp(back + k * rec, recs + k * rec, rec) == 0);
                    }
                    free(back);
                    /* the ordinary reader (x, y, z layers only) agrees */
                    hd_cloud_t *pts = NULL;
                    hd_error_t err;
                    CHECK_RC(hd_read_file(in, NULL, &pts, &err), HD_OK);
                    const double *xyz = pts ? (const double *)pts->data : NULL;
                    for (size_t k = 0; pts && k < n && !hdt_failed(); k++)
                        for (int c = 0; c < 3; c++)
                            CHECK_BITS(xyz[3 * k + (size_t)c], (double)(int32_t)le(recs + k * rec + 4 * c, 4) * 0.01);
                    hd_cloud_free(pts);
                    free(recs);
                }
}

TEST(layered_laz_subsets_are_compressed_again_every_field) {
    for (int fmt = 6; fmt <= 10; fmt++)
        for (size_t nf = 1; nf <= 2; nf++) {
            unsigned extra = fmt == 7 || fmt == 9 ? 2 : 0, version = fmt == 8 || fmt == 9 ? 3 : 4;
            CONTEXT("format %d extra %u fields %zu version %u", fmt, extra, nf, version);
            gen_rng_t g;
            size_t n = 2501, rec, m, mrec;
            tf_buf_t b = {0};
            unsigned char *recs = layered_file(&g, 577 + (uint64_t)fmt * 10 + nf, fmt, extra, 1, n, 700, version, &b, &rec);
            const char *in = tf_finish(&b, "rich14_sub.laz");
            double *v = malloc(nf * n * sizeof *v);
            field_values(&g, v, n, nf);
            hd_error_t err;
            hd_write_options_t o;
            hd_write_options_init(&o);
            /* keep 0: every point, the fields appended as BYTE14 layers by
             * write_laz.c (its own encoder), decoded here by laz14.c */
            for (int keep = 0; keep <= 2; keep++) {
                o.keep = keep == 0 ? HD_KEEP_ALL : keep == 1 ? HD_KEEP_FARTHER : HD_KEEP_NEARER;
                o.threshold = 0.25; /* on the first field */
                size_t written = 0;
                CHECK_RC(write_fields(in, tf_path("rich14_sub_out.laz"), v, n, nf, &o, &written, &err), HD_OK);
                unsigned compressor = 0, versions[32], n_items = 0;
                laz_vlr(tf_path("rich14_sub_out.laz"), &compressor, versions, &n_items);
                CHECK(compressor == 3);
                for (unsigned i = 0; i < n_items; i++) CHECK(versions[i] == version);
                unsigned char *out = records_of(tf_path("rich14_sub_out.laz"), &m, &mrec);
                CHECK(mrec == rec + 8 * nf && m == written);
                size_t j = 0;
                for (size_t k = 0; k < n && !hdt_failed(); k++) {
                    if (keep == 1 ? !(v[k] > 0.25) : keep == 2 ? !(v[k] <= 0.25) : 0) continue;
                    CONTEXT("point %zu (written %zu)", k, j);
                    CHECK(memcmp(out + j * mrec, recs + k * rec, rec) == 0);
                    for (size_t f = 0; f < nf; f++) {
                        double x;
                        memcpy(&x, out + j * mrec + rec + 8 * f, 8);
                        CHECK_BITS(x, v[f * n + k]);
                    }
                    j++;
                }
                CHECK(j == written && j > 0 && (keep ? j < n : j == n));
                free(out);
            }
            free(v);
            free(recs);
        }
}

TEST(layered_laz_subsets_of_one_point_and_of_none) {
    gen_rng_t g;
    size_t n = 120, rec, m, mrec;
    tf_buf_t b = {0};
    unsigned char *recs = layered_file(&g, 43, 8, 1, 1, n, 50, 4, &b, &rec);
    const char *in = tf_finish(&b, "rich14_one.laz");
    double *v = calloc(n, sizeof *v);
    v[77] = 1; /* the one point farther than 0.5: a chunk of one point, its layers those of an empty stream */
    hd_write_options_t o;
    hd_write_options_init(&o);
    o.keep = HD_KEEP_FARTHER;
    o.threshold = 0.5;
    hd_error_t err;
    size_t written = 9;
    CHECK_RC(hd_write_field(in, tf_path("rich14_one_out.laz"), v, n, &o, &written, &err), HD_OK);
    unsigned char *out = records_of(tf_path("rich14_one_out.laz"), &m, &mrec);
    CHECK(written == 1 && m == 1 && mrec == rec + 8);
    CHECK(out && memcmp(out, recs + 77 * rec, rec) == 0);
    free(out);
    o.threshold = 2; /* none */
    CHECK_RC(hd_write_field(in, tf_path("rich14_none_out.laz"), v, n, &o, &written, &err), HD_OK);
    hd_cloud_t *c = NULL;
    CHECK(written == 0);
    int rc = hd_read_file(tf_path("rich14_none_out.laz"), NULL, &c, &err);
    CHECK(rc == HD_OK ? c->count == 0 : rc == HD_EEMPTY);
    hd_cloud_free(c);
    free(v);
    free(recs);
}

TEST(layered_laz_subsets_are_the_same_file_on_any_thread_count) {
    gen_rng_t g;
    size_t n = 9001, rec;
    tf_buf_t b = {0};
    unsigned char *recs = layered_file(&g, 47, 7, 1, 1, n, 400, 3, &b, &rec); /* 23 chunks: several batches of any thread count */
    const char *in = tf_finish(&b, "rich14_threads.laz");
    double *v = malloc(n * sizeof *v);
    for (size_t k = 0; k < n; k++) v[k] = gen_normal(&g);
    hd_read_options_t r;
    hd_read_options_init(&r);
    hd_write_options_t o;
    hd_write_options_init(&o);
    o.keep = HD_KEEP_FARTHER;
    o.read = &r;
    hd_error_t err;
    unsigned char *first = NULL;
    size_t first_size = 0;
    static const int threads[] = {1, 2, 3, 8};
    for (int t = 0; t < 4; t++) {
        CONTEXT("threads %d", threads[t]);
        r.threads = threads[t];
        CHECK_RC(hd_write_field(in, tf_path("rich14_threads_out.laz"), v, n, &o, NULL, &err), HD_OK);
        size_t size;
        unsigned char *d = tf_read(tf_path("rich14_threads_out.laz"), &size);
        if (!first) {
            first = d, first_size = size;
            continue;
        }
        CHECK(size == first_size && memcmp(d, first, size) == 0);
        free(d);
    }
    free(first);
    free(v);
    free(recs);
}

TEST(layered_laz_damaged_layers_are_errors_with_offsets) {
    gen_rng_t g;
    size_t n = 300, rec;
    tf_buf_t b = {0};
    unsigned char *recs = layered_file(&g, 41, 7, 2, 1, n, 300, 4, &b, &rec);
    unsigned char *d = b.data;
    size_t offset = le(d + 96, 4), chunk = offset + 8, sizes = chunk + rec + 4;
    /* the classification layer (the third) one byte shorter, the flags layer one longer */
    uint32_t c = (uint32_t)le(d + sizes + 8, 4), f = (uint32_t)le(d + sizes + 12, 4);
    CHECK(c > 1 && f > 1);
    for (int q = 0; q < 4; q++) d[sizes + 8 + q] = (unsigned char)((c - 1) >> 8 * q), d[sizes + 12 + q] = (unsigned char)((f + 1) >> 8 * q);
    const char *in = tf_finish(&b, "rich14_bad.laz");
    hd_write_options_t o;
    hd_write_options_init(&o);
    o.keep = HD_KEEP_FARTHER;
    double *v = calloc(n, sizeof *v);
    v[3] = 1;
    hd_error_t err;
    CHECK_RC(hd_write_field(in, tf_path("rich14_bad_out.laz"), v, n, &o, NULL, &err), HD_EFORMAT);
    CHECK(strstr(err.message, "chunk 1 of 1") && strstr(err.message, "classification layer"));
    CHECK(err.offset > (long long)sizes);
    free(v);
    free(recs);
}

/* hd__write_laz on the n points of the LAZ bytes d (named `name`), keeping
 * `keep` of them (v > 0.5 farther), on `threads` threads, into a temporary
 * stream: what hd_write_field does once its read of the input has passed.
 * A chunk that does not decode fails that read first, so only a call
 * without it reaches the writer's own decoding. */
static int write_laz_unread(const char *name, const unsigned char *d, size_t size, const double *v, size_t n,
                            hd_keep_t keep, int threads, hd_error_t *err) {
    hd__file_t f = {name, d, size};
    hd_read_options_t r;
    hd_read_options_init(&r);
    r.threads = threads;
    hd_field_t field = {"distance", v};
    FILE *out = tmpfile();
    CHECK(out != NULL);
    hd__writer_t w = {.in = &f, .out_name = "unread_out.laz", .out = out, .v = v, .n = n, .f = &field, .nf = 1,
                      .keep = keep, .threshold = 0.5, .ropt = &r, .err = err};
    hd__err_clear(err);
    int rc = hd__write_laz(&w);
    fclose(out);
    return rc;
}

/* The LAZ file b (n points of rec bytes, three chunks: lazw_last) with
 * chunk 3 damaged, then chunks 2 and 3: the first that fails is named by
 * the writer, with an offset inside it, every point kept or a subset,
 * whether its batch of tasks holds the chunk after it or not (1 and 3
 * threads). */
static void damaged_chunks_name_the_first(const tf_buf_t *b, size_t n, size_t rec, const char *what) {
    size_t start[4] = {lazw_last.chunk[0], lazw_last.chunk[1], lazw_last.chunk[2], lazw_last.table};
    double *v = calloc(n, sizeof *v);
    v[3] = v[1500] = 1;
    for (int first = 2; first >= 1; first--) {
        unsigned char *d = malloc(b->size);
        memcpy(d, b->data, b->size);
        for (size_t c = (size_t)first; c < 3; c++)
            for (size_t i = 0; i < 64; i++) d[start[c] + rec + 200 + i] ^= 0x5A; /* the stream (layer 0) */
        char says[32];
        snprintf(says, sizeof says, "chunk %d of 3: ", first + 1);
        static const int threads[] = {1, 3};
        for (int keep = 0; keep < 2; keep++)
            for (int t = 0; t < 2; t++) {
                CONTEXT("%s: chunks %d to 3 damaged, keep %s, threads %d", what, first + 1, keep ? "farther" : "all",
                        threads[t]);
                hd_error_t err;
                CHECK_RC(write_laz_unread("bad.laz", d, b->size, v, n, keep ? HD_KEEP_FARTHER : HD_KEEP_ALL,
                                          threads[t], &err),
                         HD_EFORMAT);
                CONTEXT("%s (offset %lld)", err.message, err.offset);
                CHECK(strstr(err.message, "bad.laz") && strstr(err.message, says));
                CHECK(err.offset > (long long)start[first] && err.offset <= (long long)start[first + 1]);
            }
        free(d);
    }
    free(v);
}

/* Pointwise: each chunk decoded to records (and, every point kept, encoded
 * by the same task); layered: every point kept, each chunk's channels
 * decoded from its first layer (write_laz.c), a subset every layer. */
TEST(laz_chunks_that_do_not_decode_are_the_writers_errors_with_the_first_ones_offset) {
    for (int layered = 0; layered < 2; layered++) {
        gen_rng_t g;
        size_t n = 2500, rec;
        tf_buf_t b = {0};
        unsigned char *recs = layered ? layered_file(&g, 59, 7, 1, 1, n, 1000, 3, &b, &rec)
                                      : pointwise_file(&g, 53, 3, 2, n, 1000, &b, &rec);
        damaged_chunks_name_the_first(&b, n, rec, layered ? "layered, seed 59" : "pointwise, seed 53");
        tf_free(&b);
        free(recs);
    }
}

TEST(laszip1_streams_are_refused_by_name) {
    lazw_opts_t o = {1, 0, 10, NULL, 0, {0.01, 0.01, 0.01}, {0, 0, 0}, 1};
    tf_buf_t b = {0};
    random_laz(&b, &o, 20, 9);
    const char *in = tf_finish(&b, "v1.laz");
    double v[20] = {0};
    hd_error_t err;
    CHECK_RC(hd_write_field(in, tf_path("v1_out.laz"), v, 20, NULL, NULL, &err), HD_EUNSUPPORTED);
    CHECK(strstr(err.message, "LASzip 1.x compression"));
}

/* ---- COPC: the hierarchy follows the chunks --------------------------------- */
/* A COPC file of n points in the variable chunks `chunks` (lazw_copc:
 * two hierarchy pages, an empty node, an EVLR after the hierarchy). */
static const char *copc_file(gen_rng_t *g, const size_t *chunks, size_t nc, size_t n, const char *name,
                             unsigned char **d, size_t *size) {
    lazw_point_t *p = malloc(n * sizeof *p);
    lazw_random(g, p, n, 6);
    lazw_opts_t o = {6, 2, 0, chunks, nc, {0.01, 0.01, 0.01}, {0, 0, 0}, 0};
    tf_buf_t laz = {0}, b = {0};
    lazw_encode(&laz, &o, p, n);
    size_t start[64];
    memcpy(start, lazw_last.chunk, sizeof start);
    lazw_copc(&b, laz.data, laz.size, start, chunks, nc);
    *size = b.size;
    *d = malloc(b.size);
    memcpy(*d, b.data, b.size);
    tf_free(&laz);
    free(p);
    return tf_finish(&b, name);
}

/* The nodes of a COPC file, checked (lazw_copc_nodes); *n of them. */
static lazw_node_t *copc_nodes(const unsigned char *d, size_t size, size_t *n) {
    lazw_node_t *nodes = calloc(64, sizeof *nodes);
    char why[256] = "";
    int rc = lazw_copc_nodes(d, size, nodes, 64, n, why, sizeof why);
    CONTEXT("%s", why);
    CHECK(rc == 0);
    return nodes;
}

/* Whether point k is kept (keep: 0 every point, 1 value > 0.25, 2 <= 0.25). */
static int kept_at(const double *v, size_t k, int keep) {
    return keep == 1 ? v[k] > 0.25 : keep == 2 ? v[k] <= 0.25 : 1;
}

/* Output node by node as the input's (out valid COPC): the same keys, each
 * node's kept points, each point's record the input's with the nf values
 * appended; returns the nodes emptied (absent from out's nodes). */
static size_t copc_same_nodes(const char *in, const unsigned char *din, size_t nin, const char *out, const double *v,
                              size_t n, size_t nf, int keep) {
    size_t no, ni = 0, nn = 0, mi, mo, ri, ro, emptied = 0;
    unsigned char *dout = tf_read(out, &no);
    lazw_node_t *a = copc_nodes(din, nin, &ni), *b = copc_nodes(dout, no, &nn);
    hd_error_t err;
    unsigned char *ra = lazw_decode_records(in, din, nin, &mi, &ri, &err);
    unsigned char *rb = lazw_decode_records(out, dout, no, &mo, &ro, &err);
    CHECK(ra && rb && mi == n && ro == ri + 8 * nf);
    for (size_t k = 0; k < ni && ra && rb && !hdt_failed(); k++) {
        CONTEXT("node %zu (level %d, x %d), keep %d", k, a[k].key[0], a[k].key[1], keep);
        size_t j = 0, want = 0;
        while (j < nn && memcmp(a[k].key, b[j].key, sizeof a[k].key) != 0) j++;
        for (uint64_t i = 0; i < a[k].count; i++) want += (size_t)kept_at(v, (size_t)(a[k].first + i), keep);
        if (want == 0) {
            CHECK(j == nn); /* emptied: no node with points */
            emptied++;
            continue;
        }
        CHECK(j < nn && b[j].count == want);
        for (uint64_t i = 0, o = 0; j < nn && i < a[k].count && !hdt_failed(); i++) {
            size_t p = (size_t)(a[k].first + i);
            if (!kept_at(v, p, keep)) continue;
            const unsigned char *x = ra + p * ri, *y = rb + (b[j].first + o++) * ro;
            CHECK(memcmp(x, y, ri) == 0);
            for (size_t f = 0; f < nf; f++) {
                double val;
                memcpy(&val, y + ri + 8 * f, 8);
                CHECK_BITS(val, v[f * n + p]);
            }
        }
    }
    /* the EVLR after the hierarchy is still the file's last, where the header says */
    CHECK(no > 64 && memcmp(dout + no - 4, "EVLR", 4) == 0 && le(dout + 243, 4) == 2);
    free(a), free(b), free(ra), free(rb), free(dout);
    return emptied;
}

TEST(copc_written_back_has_its_hierarchy_on_the_grown_chunks) {
    for (size_t nf = 1; nf <= 2; nf++) {
        uint64_t seed = 700 + nf;
        CONTEXT("fields %zu seed %llu", nf, (unsigned long long)seed);
        gen_rng_t g;
        gen_seed(&g, seed);
        size_t chunks[6] = {1, 300, 2, 197, 250, 250}, n = 1000, nin;
        unsigned char *din;
        const char *in = copc_file(&g, chunks, 6, n, "in.copc.laz", &din, &nin);
        size_t ni = 0;
        free(copc_nodes(din, nin, &ni)); /* the fixture is valid COPC */
        CHECK_EQ(ni, 6);
        double *v = malloc(nf * n * sizeof *v);
        field_values(&g, v, n, nf);
        hd_error_t err;
        size_t written = 0;
        CHECK_RC(write_fields(in, tf_path("out.copc.laz"), v, n, nf, NULL, &written, &err), HD_OK);
        CHECK_EQ(written, n);
        CHECK_EQ(copc_same_nodes(in, din, nin, tf_path("out.copc.laz"), v, n, nf, 0), 0);
        free(v), free(din);
    }
}

TEST(copc_subsets_keep_each_nodes_points_as_its_chunk) {
    gen_rng_t g;
    gen_seed(&g, 711);
    size_t chunks[6] = {1, 300, 2, 197, 250, 250}, n = 1000, nin, emptied = 0;
    unsigned char *din;
    const char *in = copc_file(&g, chunks, 6, n, "sub.copc.laz", &din, &nin);
    double *v = malloc(2 * n * sizeof *v);
    field_values(&g, v, n, 2);
    hd_write_options_t o;
    hd_write_options_init(&o);
    o.threshold = 0.25;
    for (int keep = 1; keep <= 2; keep++) {
        CONTEXT("keep %s (seed 711)", keep == 1 ? "farther" : "nearer");
        o.keep = keep == 1 ? HD_KEEP_FARTHER : HD_KEEP_NEARER;
        hd_error_t err;
        size_t written = 0;
        CHECK_RC(write_fields(in, tf_path("sub_out.copc.laz"), v, n, 2, &o, &written, &err), HD_OK);
        CHECK(written > 0 && written < n);
        emptied += copc_same_nodes(in, din, nin, tf_path("sub_out.copc.laz"), v, n, 2, keep);
    }
    CHECK(emptied > 0); /* a node lost every point: its entry is 0, 0, 0 */
    /* the same file on 1 and 2 threads (2: batches of 4 chunks, 6 nodes) */
    hd_read_options_t r;
    hd_read_options_init(&r);
    o.read = &r;
    unsigned char *f[2];
    size_t size[2];
    for (int t = 0; t < 2; t++) {
        r.threads = t + 1;
        hd_error_t err;
        CHECK_RC(write_fields(in, tf_path("sub_threads.copc.laz"), v, n, 2, &o, NULL, &err), HD_OK);
        f[t] = tf_read(tf_path("sub_threads.copc.laz"), &size[t]);
    }
    CHECK(f[0] && f[1] && size[0] == size[1] && memcmp(f[0], f[1], size[0]) == 0);
    free(f[0]), free(f[1]);
    free(v), free(din);
}

TEST(copc_hierarchy_entries_that_are_no_chunk_are_refused_by_name) {
    gen_rng_t g;
    gen_seed(&g, 721);
    size_t chunks[4] = {100, 200, 300, 400}, n = 1000, nin;
    unsigned char *din;
    copc_file(&g, chunks, 4, n, "bad.copc.laz", &din, &nin);
    double *v = calloc(n, sizeof *v);
    uint64_t root = le(din + 375 + 54 + 40, 8);
    /* the root page's first entry (chunk 0): its offset, its byte size, its count; then the child page pointer */
    static const struct { size_t at; int delta; const char *says; } cases[] = {
        {16, 1, "is not the start of a chunk"}, {24, 1, "bytes and"}, {28, 1, "points, chunk"},
        {3 * 32 + 16, -64, "is not inside the hierarchy EVLR"}};
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        CONTEXT("case %zu (seed 721)", c);
        unsigned char *d = malloc(nin);
        memcpy(d, din, nin);
        d[root + cases[c].at] = (unsigned char)(d[root + cases[c].at] + cases[c].delta);
        const char *bad = tf_write("bad_entry.copc.laz", d, nin);
        hd_write_options_t o;
        hd_write_options_init(&o);
        for (int keep = 0; keep <= 1; keep++) { /* every point, and a subset */
            o.keep = keep ? HD_KEEP_NEARER : HD_KEEP_ALL;
            hd_error_t err;
            CHECK_RC(hd_write_field(bad, tf_path("bad_out.laz"), v, n, &o, NULL, &err), HD_EFORMAT);
            CHECK(strstr(err.message, "bad_entry.copc.laz") && strstr(err.message, "COPC hierarchy entry") &&
                  strstr(err.message, cases[c].says));
        }
        free(d);
    }
    free(v), free(din);
}
