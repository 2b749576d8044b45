/*
 * fuzz_reader.c -- a libFuzzer target for one reader, chosen at compile
 * time with -DHD_FUZZ_FORMAT='"ply"' (fuzz/run.sh builds one per format).
 *
 * The input is handed to the reader as a whole file of that format, twice:
 * as a point set (vertices, double storage) and, for mesh formats, sampled
 * (8 points, float storage), so the face paths are exercised too.  The
 * target asserts the reader's contract beyond "no crash": a failure leaves
 * no cloud, carries a non-empty message that starts with the file's name,
 * and a text-format failure names a line or a binary one an offset inside
 * the file, and no failure is a size overflow; a success holds at least one point, every coordinate finite and
 * within HD_MAX_COORD, and never more points than the input has bytes
 * (no reader may allocate more than the file can hold).
 */
#include "io/io.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#ifndef HD_FUZZ_FORMAT
#error "compile with -DHD_FUZZ_FORMAT='\"ply\"' (or obj, off, stl, xyz, pcd, las, npy)"
#endif

static void check(const uint8_t *data, size_t size, const hd_read_options_t *o) {
    hd_cloud_t *c = (hd_cloud_t *)1;
    hd_error_t e;
    int rc = hd__read_buffer(data, size, "fuzz." HD_FUZZ_FORMAT, o, &c, &e);
    if (rc != HD_OK) {
        /* no input can overflow a size: counts are bounded by the file, so
         * HD_EOVERFLOW would mean a reader's own bound was wrong */
        if (rc == HD_EOVERFLOW) abort();
        if (c != NULL || e.code != rc || strncmp(e.message, "fuzz." HD_FUZZ_FORMAT, 5 + strlen(HD_FUZZ_FORMAT)) != 0) abort();
        if (e.line != -1 && (e.line < 1 || (size_t)e.line > size + 1)) abort();
        if (e.offset != -1 && (e.offset < 0 || (size_t)e.offset > size)) abort();
        return;
    }
    if (!c || c->count == 0) abort();
    if (o->mesh == HD_MESH_VERTICES && c->count > size) abort();
    hd_points_t p = hd_cloud_points(c);
    for (size_t k = 0; k < c->count; k++) {
        double q[3];
        hd_points_get(&p, k, q);
        for (int d = 0; d < 3; d++)
            if (!isfinite(q[d]) || fabs(q[d]) > HD_MAX_COORD) abort();
    }
    hd_cloud_free(c);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.format = HD_FUZZ_FORMAT;
    o.threads = 2;
    check(data, size, &o);
    const char *mesh = "ply obj off stl";
    if (strstr(mesh, HD_FUZZ_FORMAT)) {
        o.mesh = HD_MESH_SAMPLE;
        o.sample = 8;
        o.dtype = HD_FLOAT32;
        check(data, size, &o);
    }
    return 0;
}
