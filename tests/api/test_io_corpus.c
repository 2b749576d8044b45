/*
 * test_io_corpus.c -- every file of the fuzzers' seed corpus
 * (tests/corpus/FORMAT/: small valid files, and the inputs that once made a
 * reader misbehave, named regress-*) is read as its format, as points and,
 * for meshes, sampled, and the reader's contract holds: a valid seed reads,
 * a failure leaves no cloud and a message that names the file, a success
 * holds finite points within range.  So `make test` replays what the
 * fuzzers found, under the sanitizers, without clang.  Each regress-* file
 * also has its expected outcome in `regress` below (points read, or the
 * code it is refused with, as points and sampled): a reader that starts
 * accepting what it refused, refusing what it read, or reading a different
 * number of points fails here, and a new regress-* file without a row
 * fails until it has one.
 */
#include "check.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The outcome of each regress-* file: read with `points` points (code
 * HD_OK) or refused with `code`, as points; and the same when sampled (8
 * points of float; meshes only, the first four formats of the test). */
typedef struct {
    const char *path;
    int code;
    size_t points;
    int sampled_code;
    size_t sampled_points;
    int seen;
} outcome_t;

static outcome_t regress[] = {
    {"tests/corpus/ply/regress-empty-window", HD_EFORMAT, 0, HD_EFORMAT, 0, 0},
    {"tests/corpus/ply/regress-face-first-list-count-2e64", HD_OK, 3, HD_EFORMAT, 0, 0},
    {"tests/corpus/ply/regress-bom.ply", HD_OK, 3, HD_OK, 8, 0},
    {"tests/corpus/obj/regress-empty-window", HD_EEMPTY, 0, HD_EEMPTY, 0, 0},
    {"tests/corpus/obj/regress-relative-index-2e62", HD_OK, 8, HD_EFORMAT, 0, 0},
    {"tests/corpus/obj/regress-bom.obj", HD_OK, 3, HD_OK, 8, 0},
    {"tests/corpus/obj/regress-utf32.obj", HD_EFORMAT, 0, HD_EFORMAT, 0, 0},
    {"tests/corpus/obj/regress-mac-line-ends.obj", HD_EFORMAT, 0, HD_EFORMAT, 0, 0},
    {"tests/corpus/obj/regress-two-statements-a-line.obj", HD_EFORMAT, 0, HD_EFORMAT, 0, 0},
    {"tests/corpus/obj/regress-obj-that-starts-with-lasf", HD_OK, 1, HD_EFORMAT, 0, 0},
    {"tests/corpus/off/regress-empty-window", HD_EFORMAT, 0, HD_EFORMAT, 0, 0},
    {"tests/corpus/off/regress-bom.off", HD_OK, 3, HD_OK, 8, 0},
    {"tests/corpus/stl/regress-binary-solid-header", HD_OK, 6, HD_OK, 8, 0},
    {"tests/corpus/stl/regress-empty-window", HD_EFORMAT, 0, HD_EFORMAT, 0, 0},
    {"tests/corpus/stl/regress-bom.stl", HD_OK, 3, HD_OK, 8, 0},
    {"tests/corpus/stl/regress-utf16-solid.stl", HD_EFORMAT, 0, HD_EFORMAT, 0, 0},
    {"tests/corpus/stl/regress-one-line.stl", HD_EFORMAT, 0, HD_EFORMAT, 0, 0},
    {"tests/corpus/xyz/regress-decimal-comma.csv", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/xyz/regress-empty-window", HD_EEMPTY, 0, 0, 0, 0},
    {"tests/corpus/xyz/regress-pts-count-2e64", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/xyz/regress-bom.xyz", HD_OK, 2, 0, 0, 0},
    {"tests/corpus/xyz/regress-bom-header.csv", HD_OK, 2, 0, 0, 0},
    {"tests/corpus/xyz/regress-utf16.xyz", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/xyz/regress-utf16-no-bom.txt", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/xyz/regress-tab-decimal-comma.txt", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/xyz/regress-thousands.xyz", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/xyz/regress-qnan-line1.xyz", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/xyz/regress-fortran-exponent-line1.xyz", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/xyz/regress-mac-line-ends.xyz", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/xyz/regress-quoted-numbers.csv", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/pcd/regress-empty-window", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/pcd/regress-bom.pcd", HD_OK, 2, 0, 0, 0},
    {"tests/corpus/npy/regress-empty-shape", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/las/regress-laz-repeated-items", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/laz/regress-count-1-of-100.laz", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/laz/regress-count-99-of-100-last-chunk.laz", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/laz/regress-count-60-of-100-laszip1.laz", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/laz/regress-count-99-of-100-layered.laz", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/laz/regress-point10-v1-said-v2.laz", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/laz/regress-rgb12-v1-said-v2.laz", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/laz/regress-compression-bit-cleared.laz", HD_EFORMAT, 0, 0, 0, 0},
    {"tests/corpus/laz/regress-dense-1000000-points.laz", HD_EUNSUPPORTED, 0, 0, 0, 0},
};
#define N_REGRESS (sizeof regress / sizeof regress[0])

static outcome_t *expected(const char *path) {
    for (size_t k = 0; k < N_REGRESS; k++)
        if (strcmp(regress[k].path, path) == 0) return &regress[k];
    return NULL;
}

static void read_one(const char *path, const char *format, int sample) {
    hd_read_options_t o;
    hd_read_options_init(&o);
    o.format = format;
    if (sample) {
        o.mesh = HD_MESH_SAMPLE;
        o.sample = 8;
        o.dtype = HD_FLOAT32;
    }
    hd_cloud_t *c = (hd_cloud_t *)&o; /* must be set to NULL on failure */
    hd_error_t e;
    int rc = hd_read_file(path, &o, &c, &e);
    int seed = strstr(path, "/regress-") == NULL;
    CONTEXT("%s as %s%s", path, format, sample ? ", sampled" : "");
    if (!seed) {
        outcome_t *want = expected(path);
        if (!want) {
            hdt_fail(__FILE__, __LINE__, "%s has no expected outcome: add a row to `regress`", path);
        } else {
            want->seen = 1;
            CHECK_RC(rc, sample ? want->sampled_code : want->code);
            size_t points = rc == HD_OK && c ? c->count : 0;
            CHECK_EQ(points, sample ? want->sampled_points : want->points);
        }
    }
    if (rc != HD_OK) {
        CHECK(c == NULL);
        CHECK_EQ(e.code, rc);
        CHECK(strncmp(e.message, path, strlen(path)) == 0);
        CHECK(rc != HD_EOVERFLOW);
        if (seed && !sample) hdt_fail(__FILE__, __LINE__, "valid seed refused: %s", e.message);
        return;
    }
    CHECK(c && c->count > 0);
    if (!c) return;
    hd_points_t p = hd_cloud_points(c);
    for (size_t k = 0; k < c->count; k++) {
        double q[3];
        hd_points_get(&p, k, q);
        for (int d = 0; d < 3; d++) CHECK(isfinite(q[d]) && fabs(q[d]) <= HD_MAX_COORD);
    }
    hd_cloud_free(c);
}

TEST(every_corpus_file_reads_or_is_refused_by_the_contract) {
    static const char *const formats[] = {"ply", "obj", "off", "stl", "xyz", "pcd", "las", "npy", "laz"};
    int files = 0;
    for (size_t f = 0; f < sizeof formats / sizeof formats[0]; f++) {
        char dir[256];
        snprintf(dir, sizeof dir, "tests/corpus/%s", formats[f]);
        DIR *d = opendir(dir);
        CHECK(d != NULL);
        if (!d) continue;
        struct dirent *ent;
        while ((ent = readdir(d)) != NULL) {
            if (ent->d_name[0] == '.') continue;
            char path[512];
            snprintf(path, sizeof path, "%s/%s", dir, ent->d_name);
            read_one(path, formats[f], 0);
            if (f < 4) read_one(path, formats[f], 1);
            files++;
        }
        closedir(d);
    }
    CHECK(files >= 24);
    for (size_t k = 0; k < N_REGRESS; k++) {
        CONTEXT("%s", regress[k].path);
        CHECK(regress[k].seen); /* a row whose file is gone */
    }
}
