/*
 * write_bench.c -- hd_write_field's speed: a per-point double written back
 * into a LAS and a LAZ file of POINTS points, against copying the file;
 * with -f FIELDS, hd_write_fields writing FIELDS doubles a point (2:
 * distance, nearest; 3: and sign) in one pass.
 *
 *   write_bench [-n POINTS] [-r RUNS] [-d DIR] [-f FIELDS] [-k]
 *
 * It writes POINTS points (1 000 000 by default: seeded random walks of the
 * tests' LAZ writer, tests/internal/lazwrite.c) as LAS 1.4 point format 6
 * (uncompressed, 30-byte records) and as layered LAZ (chunks of 50 000, all
 * four scanner channels), and POINTS records of point format 3 whose every
 * field varies (lazw_rich_records) as pointwise LAZ (chunks of 50 000,
 * compressed by the library's pointwise encoder) to DIR (default /tmp), and
 * seeded values; then
 * times RUNS runs (default 5) of `cp FILE DIR/copy` and of hd_write_field
 * (which reads the input once through hd_read_file, to check it and count
 * its points, then writes the output and fsyncs it), and prints the medians
 * as markdown rows: input and output size, copy time, write time (wall),
 * its CPU time (user + system), million points/s.  Nothing is asserted;
 * the files are deleted afterwards (-k keeps the inputs, write_bench_in.las
 * and .laz in DIR).
 */
#include "gen.h"

#include "benchutil.h"
#include "lazwrite.h"

#include <hausdorff.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static void save(const char *path, const tf_buf_t *b) {
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(b->data, 1, b->size, f) != b->size || fclose(f)) {
        perror(path);
        exit(1);
    }
}

/* The LAS 1.4 format 6 file of the points p (the LAZ file's records). */
static void las_of(tf_buf_t *b, const lazw_point_t *p, size_t n) {
    size_t header = 375, rec = 30;
    tf_put(b, "LASF", 4);
    while (b->size < 24) tf_u8(b, 0);
    tf_u8(b, 1), tf_u8(b, 4);
    while (b->size < 94) tf_u8(b, 0);
    tf_u16(b, (unsigned)header, 0);
    tf_u32(b, (uint32_t)header, 0);
    tf_u32(b, 0, 0);
    tf_u8(b, 6);
    tf_u16(b, (unsigned)rec, 0);
    while (b->size < 131) tf_u8(b, 0);
    for (int c = 0; c < 3; c++) tf_f64(b, 0.001, 0);
    for (int c = 0; c < 3; c++) tf_f64(b, 0, 0);
    while (b->size < 247) tf_u8(b, 0);
    tf_u64(b, n, 0);
    while (b->size < header) tf_u8(b, 0);
    for (size_t k = 0; k < n; k++) {
        tf_u32(b, (uint32_t)p[k].x, 0), tf_u32(b, (uint32_t)p[k].y, 0), tf_u32(b, (uint32_t)p[k].z, 0);
        tf_u16(b, 0, 0);
        tf_u8(b, (unsigned)(p[k].r | p[k].n << 4));
        tf_u8(b, (unsigned)(p[k].channel << 4));
        tf_u8(b, 2), tf_u8(b, 7);
        tf_u16(b, 0, 0), tf_u16(b, 11, 0);
        tf_f64(b, 123456.5, 0);
    }
}

static off_t size_of(const char *path) {
    struct stat st;
    return stat(path, &st) == 0 ? st.st_size : -1;
}

static const char *const field_names[3] = {"distance", "nearest", "sign"};

static void row(const char *name, const char *in, const char *dir, const double *v, size_t n, size_t nf, int runs) {
    hd_field_t f[3];
    for (size_t j = 0; j < nf; j++) f[j].name = field_names[j], f[j].values = v + j * n;
    char out[4096], copy[4096], cmd[9000];
    const char *ext = strrchr(in, '.');
    snprintf(out, sizeof out, "%s/write_bench_out_%s%s", dir, name, ext);
    snprintf(copy, sizeof copy, "%s/write_bench_copy_%s%s", dir, name, ext);
    snprintf(cmd, sizeof cmd, "cp '%s' '%s' && sync '%s'", in, copy, copy);
    double *tc = malloc(runs * sizeof *tc), *tw = malloc(runs * sizeof *tw), *cpu = malloc(runs * sizeof *cpu);
    for (int r = 0; r < runs; r++) {
        double t0 = bench_now();
        if (system(cmd) != 0) exit(1);
        tc[r] = bench_now() - t0;
        double c0 = bench_cpu_now();
        t0 = bench_now();
        hd_error_t err;
        int rc = nf == 1 ? hd_write_field(in, out, v, n, NULL, NULL, &err)
                         : hd_write_fields(in, out, f, nf, n, NULL, NULL, &err);
        if (rc != HD_OK) {
            fprintf(stderr, "write_bench: %s\n", err.message);
            exit(1);
        }
        tw[r] = bench_now() - t0;
        cpu[r] = bench_cpu_now() - c0;
    }
    double w = bench_median(tw, runs);
    printf("| %s | %.1f MB | %.1f MB | %.3f s | %.3f s | %.3f s | %.2f |\n", name, size_of(in) / 1e6, size_of(out) / 1e6,
           bench_median(tc, runs), w, bench_median(cpu, runs), n / w / 1e6);
    remove(out);
    remove(copy);
    free(tc), free(tw), free(cpu);
}

int main(int argc, char **argv) {
    size_t n = 1000000;
    int runs = 5;
    const char *dir = "/tmp";
    int keep = 0;
    size_t nf = 1;
    for (int i = 1; i < argc; i += 2) {
        if (strcmp(argv[i], "-k") == 0) {
            keep = 1;
            i--;
            continue;
        }
        if (i + 1 >= argc) break;
        if (strcmp(argv[i], "-n") == 0) n = (size_t)atof(argv[i + 1]);
        else if (strcmp(argv[i], "-r") == 0) runs = atoi(argv[i + 1]);
        else if (strcmp(argv[i], "-d") == 0) dir = argv[i + 1];
        else if (strcmp(argv[i], "-f") == 0) nf = (size_t)atoi(argv[i + 1]);
    }
    if (nf < 1 || nf > 3) {
        fprintf(stderr, "write_bench: -f takes 1, 2 or 3 fields\n");
        return 2;
    }
    gen_rng_t g;
    gen_seed(&g, 20261202);
    lazw_point_t *p = malloc(n * sizeof *p);
    double *v = malloc(3 * n * sizeof *v);
    lazw_random(&g, p, n, 6);
    for (size_t k = 0; k < n; k++) v[k] = gen_unit(&g) * 0.05;
    for (size_t k = 0; k < n; k++) v[n + k] = (double)(k * 7919 % n), v[2 * n + k] = k % 3 ? 1.0 : -1.0;
    char las[4096], laz[4096], laz3[4096];
    snprintf(laz3, sizeof laz3, "%s/write_bench_in3.laz", dir);
    snprintf(las, sizeof las, "%s/write_bench_in.las", dir);
    snprintf(laz, sizeof laz, "%s/write_bench_in.laz", dir);
    tf_buf_t b = {0};
    las_of(&b, p, n);
    save(las, &b);
    tf_free(&b);
    lazw_opts_t o = {6, 0, 50000, NULL, 0, {0.001, 0.001, 0.001}, {0, 0, 0}, 0};
    lazw_encode(&b, &o, p, n);
    save(laz, &b);
    tf_free(&b);
    size_t rec;
    unsigned char *recs = lazw_rich_records(&g, 3, 0, n, &rec);
    lazw_pointwise(&b, 3, 0, recs, rec, n, 50000);
    save(laz3, &b);
    tf_free(&b);
    free(recs);
    printf("| format | input | output | copy (cp + sync) | hd_write_field | its CPU | Mpoints/s |\n|---|---|---|---|---|---|---|\n");
    row("las", las, dir, v, n, nf, runs);
    row("laz", laz, dir, v, n, nf, runs);
    row("laz3", laz3, dir, v, n, nf, runs);
    if (!keep) {
        remove(las);
        remove(laz);
        remove(laz3);
    }
    free(p);
    free(v);
    return 0;
}
