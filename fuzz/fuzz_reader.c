/*
 * fuzz_reader.c -- a libFuzzer target for one reader in one mesh mode,
 * chosen at compile time (fuzz/fuzz.mk builds every combination):
 *
 *   -DHD_FUZZ_FORMAT='"ply"'                      fuzz_ply: the file as points
 *                                                 (a mesh as its vertices)
 *   -DHD_FUZZ_FORMAT='"ply"' -DHD_FUZZ_SAMPLE=64  fuzz_ply_sample: a mesh's
 *                                                 faces, 64 points sampled on
 *                                                 them with a fixed seed
 *
 * The input is the whole file.  Inputs of odd size are stored as float32,
 * of even size as float64, so both storage types are exercised without a
 * second read (and a reproducer replays the same way).
 *
 * The target asserts the reader's contract beyond "no crash": a failure
 * leaves no cloud, carries a non-empty message that starts with the file's
 * name, and a text-format failure names a line or a binary one an offset
 * inside the file, and no failure is a size overflow; a success holds at
 * least one point, every coordinate finite and within HD_MAX_COORD; as
 * vertices never more points than the input has bytes (no reader may
 * allocate more than the file can hold; a LAZ
 * chunk up to HD_LAZ_POINTS_PER_BYTE points per byte), sampled exactly the sample size.
 * A LAZ file read also has its chunks decoded again to whole records
 * (every field, every layer), which must agree with the points read.
 * After a success two more reads check the range contract: where the
 * header count answers it equals the count read, and a range read of the
 * middle third gives exactly that slice of the whole read, bit for bit.
 */
#include "io/io.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#ifndef HD_FUZZ_FORMAT
#error "compile with -DHD_FUZZ_FORMAT='\"ply\"' (or obj, off, stl, xyz, pcd, las, npy)"
#endif

#define NAME "fuzz." HD_FUZZ_FORMAT

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#ifndef HD_FUZZ_SAMPLE
/* A LAZ file read as points: its chunks decoded again to whole records,
 * every field of every item (laz.c's hd__laz_chunk_records; every layer of
 * layered LAZ, laz14.c), as the writers of subsets do.  Each chunk decodes
 * or fails with a message; one that decodes gives, as doubles
 * X * scale + offset, exactly the points the read gave. */
static void laz_records(const uint8_t *data, size_t size, const hd_cloud_t *c) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    hd__file_t f = {NAME, data, size};
    hd__sink_t sink;
    hd__sink_init(&sink, HD_FLOAT64);
    hd_error_t e;
    hd__read_t r = {&f, &o, 1, &sink, NULL, 0, &e, 0, 0, 0};
    hd__las_header_t h;
    memset(&h, 0, sizeof h);
    h.minor = data[25], h.fmt = data[104] & 63, h.header = hd__ld_u16(data + 94, 0), h.offset = hd__ld_u32(data + 96, 0);
    h.n_vlr = hd__ld_u32(data + 100, 0), h.rec = hd__ld_u16(data + 105, 0), h.count = c->count;
    hd__laz_chunks_t cs;
    if (hd__laz_chunks(&r, &h, &cs) != HD_OK) return;
    for (size_t k = 0; k < cs.n_chunks; k++) {
        size_t n = (size_t)(cs.first[k + 1] - cs.first[k]);
        unsigned char *recs = malloc((n + 1) * h.rec);
        if (!recs) abort();
        e.message[0] = 0;
        int rc = hd__laz_chunk_records(&r, &h, &cs, k, recs);
        if (rc != HD_OK && (rc == HD_EOVERFLOW || strncmp(e.message, NAME, strlen(NAME)) != 0)) abort();
        for (size_t i = 0; rc == HD_OK && c->dtype == HD_FLOAT64 && i < n; i++)
            for (int d = 0; d < 3; d++) {
                double scale, shift, got = ((const double *)c->data)[3 * (cs.first[k] + i) + (size_t)d];
                memcpy(&scale, data + 131 + 8 * d, 8);
                memcpy(&shift, data + 155 + 8 * d, 8);
                if ((double)(int32_t)hd__ld_u32(recs + i * h.rec + 4 * (size_t)d, 0) * scale + shift != got) abort();
            }
        free(recs);
    }
    hd__laz_chunks_free(&cs);
    hd__sink_free(&sink);
}
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.format = HD_FUZZ_FORMAT;
    o.threads = 2;
    o.dtype = size & 1 ? HD_FLOAT32 : HD_FLOAT64;
#ifdef HD_FUZZ_SAMPLE
    o.mesh = HD_MESH_SAMPLE;
    o.sample = HD_FUZZ_SAMPLE;
    o.seed = 7;
#endif
    hd_cloud_t *c = (hd_cloud_t *)1;
    hd_error_t e;
    int rc = hd__read_buffer(data, size, NAME, &o, &c, &e);
    if (rc != HD_OK) {
        /* no input can overflow a size: counts are bounded by the file, so
         * HD_EOVERFLOW would mean a reader's own bound was wrong */
        if (rc == HD_EOVERFLOW) abort();
        if (c != NULL || e.code != rc || strncmp(e.message, NAME, strlen(NAME)) != 0) abort();
        if (e.line != -1 && (e.line < 1 || (size_t)e.line > size + 1)) abort();
        if (e.offset != -1 && (e.offset < 0 || (size_t)e.offset > size)) abort();
        return 0;
    }
    if (!c || c->count == 0 || c->dtype != o.dtype) abort();
#ifdef HD_FUZZ_SAMPLE
    if (c->count != HD_FUZZ_SAMPLE) abort();
#else
    /* LAZ (named las or laz: the compression bit decides): a chunk may hold
     * up to HD_LAZ_POINTS_PER_BYTE points per byte (a run of identical
     * points costs a tiny fraction of a bit each) */
    int laz = size > 104 && memcmp(data, "LASF", 4) == 0 && (data[104] & 0x80);
    if (c->count > (laz ? HD_LAZ_POINTS_PER_BYTE : 1) * size) abort();
#endif
    hd_points_t p = hd_cloud_points(c);
    for (size_t k = 0; k < c->count; k++) {
        double q[3];
        hd_points_get(&p, k, q);
        for (int d = 0; d < 3; d++)
            if (!isfinite(q[d]) || fabs(q[d]) > HD_MAX_COORD) abort();
    }
#ifndef HD_FUZZ_SAMPLE
    /* only what was read as LAS: another reader's file may merely start with "LASF" */
    if (laz && size >= 227 && (strcmp(HD_FUZZ_FORMAT, "las") == 0 || strcmp(HD_FUZZ_FORMAT, "laz") == 0))
        laz_records(data, size, c);
#endif
    uint64_t total;
    rc = hd__count_buffer(data, size, NAME, &o, &total, &e);
    if (rc == HD_OK ? total != c->count : rc != HD_EUNSUPPORTED) abort();
    o.range_first = c->count / 3;
    o.range_count = c->count - c->count / 3 - c->count / 3;
    hd_cloud_t *part = NULL;
    rc = hd__read_buffer(data, size, NAME, &o, &part, &e);
    size_t el = c->dtype == HD_FLOAT32 ? 3 * sizeof(float) : 3 * sizeof(double);
    if (rc != HD_OK || part->count != o.range_count ||
        memcmp(part->data, (const char *)c->data + o.range_first * el, part->count * el) != 0)
        abort();
    hd_cloud_free(part);
    hd_cloud_free(c);
    return 0;
}
