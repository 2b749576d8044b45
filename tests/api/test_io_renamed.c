/*
 * test_io_renamed.c -- the content always confirms the format: every valid
 * file of the seed corpus (tests/corpus/FORMAT/), copied under the
 * extension of every other format, is either read right (the same points,
 * bit for bit, as under its own name) or refused with a message naming the
 * file; never misread.  An OFF named .xyz was once read as 25 031 "points"
 * (its counts and face rows included), and a PLY named .xyz failed with
 * "'format' is not a number".
 */
#include "check.h"
#include "files.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>

static const char *const exts[] = {"ply", "obj", "off", "stl", "xyz", "csv", "pts", "pcd", "las", "npy"};

static unsigned char *slurp(const char *path, size_t *n) {
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *b = malloc(len > 0 ? (size_t)len : 1);
    *n = b ? fread(b, 1, (size_t)len, f) : 0;
    fclose(f);
    return b;
}

static void one_file(const char *dir, const char *name) {
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    hd_cloud_t *ref = NULL, *c = NULL;
    hd_error_t e;
    if (hd_read_file(path, NULL, &ref, &e) != HD_OK) return; /* not a valid seed under its own name */
    size_t n;
    unsigned char *bytes = slurp(path, &n);
    CHECK(bytes != NULL);
    const char *own = strrchr(name, '.') ? strrchr(name, '.') + 1 : "";
    for (size_t k = 0; k < sizeof exts / sizeof exts[0]; k++) {
        if (strcmp(exts[k], own) == 0) continue;
        char renamed[128];
        snprintf(renamed, sizeof renamed, "renamed.%s", exts[k]);
        const char *p = tf_write(renamed, bytes, n);
        CONTEXT("%s named %s", path, renamed);
        int rc = hd_read_file(p, NULL, &c, &e);
        if (rc != HD_OK) {
            CHECK(c == NULL);
            CHECK(strncmp(e.message, p, strlen(p)) == 0);
            continue;
        }
        /* read: it must be the same points */
        if (c->count != ref->count || memcmp(c->data, ref->data, 3 * sizeof(double) * c->count) != 0)
            hdt_fail(__FILE__, __LINE__, "misread: %zu points (format %s) where its own name gives %zu", c->count,
                     c->format, ref->count);
        hd_cloud_free(c);
    }
    free(bytes);
    hd_cloud_free(ref);
}

TEST(every_corpus_file_under_every_other_extension_is_read_right_or_refused) {
    static const char *const dirs[] = {"ply", "obj", "off", "stl", "xyz", "pcd", "las", "npy"};
    for (size_t d = 0; d < sizeof dirs / sizeof dirs[0]; d++) {
        char dir[256];
        snprintf(dir, sizeof dir, "tests/corpus/%s", dirs[d]);
        DIR *dp = opendir(dir);
        CHECK(dp != NULL);
        if (!dp) continue;
        struct dirent *de;
        while ((de = readdir(dp)))
            if (de->d_name[0] != '.' && strncmp(de->d_name, "regress-", 8) != 0) one_file(dir, de->d_name);
        closedir(dp);
    }
}

TEST(an_off_named_xyz_is_refused_naming_what_it_is) {
    hd_cloud_t *c;
    hd_error_t e;
    const char *p = tf_printf("mesh.xyz", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    CHECK_RC(hd_read_file(p, NULL, &c, &e), HD_EFORMAT);
    CHECK(strstr(e.message, "the name says xyz but the content is off") != NULL);
    /* without its keyword: the face row has 4 fields where points have 3 */
    p = tf_printf("bare.xyz", "3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    CHECK_RC(hd_read_file(p, NULL, &c, &e), HD_EFORMAT);
    CHECK(strstr(e.message, "bare.xyz:5: 4 fields where the first row (line 1), whole numbers only, has 3") != NULL);
    p = tf_printf("cloud.xyz", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                               "property float z\nend_header\n1 2 3\n");
    CHECK_RC(hd_read_file(p, NULL, &c, &e), HD_EFORMAT);
    CHECK(strstr(e.message, "the name says xyz but the content is ply") != NULL);
}

TEST(point_rows_with_a_constant_number_of_columns_read_as_before) {
    hd_cloud_t *c;
    hd_error_t e;
    CHECK_RC(hd_read_file(tf_printf("rgb.xyz", "1 2 3 255 0 0\n4 5 6 0 255 0\n"), NULL, &c, &e), HD_OK);
    CHECK_EQ(c->count, 2);
    hd_cloud_free(c);
    CHECK_RC(hd_read_file(tf_printf("hdr.csv", "x,y,z,i\n1,2,3,4\n5,6,7,8\n"), NULL, &c, &e), HD_OK);
    CHECK_EQ(c->count, 2);
    hd_cloud_free(c);
    CHECK_RC(hd_read_file(tf_printf("n.pts", "2\n1 2 3 9\n4 5 6 9\n"), NULL, &c, &e), HD_OK);
    CHECK_EQ(c->count, 2);
    hd_cloud_free(c);
    /* ragged extra columns are fine when the first row is not all whole numbers */
    CHECK_RC(hd_read_file(tf_printf("ragged.xyz", "1.5 2 3\n4 5 6 7 8\n"), NULL, &c, &e), HD_OK);
    CHECK_EQ(c->count, 2);
    hd_cloud_free(c);
}
