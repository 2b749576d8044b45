/*
 * read_bench.c -- read throughput of every format on a large file, against
 * the time `cat` takes to stream the same file to /dev/null.
 *
 *   read_bench [-n POINTS] [-r RUNS] [-d DIR] [-t THREADS] [FORMAT...]
 *   read_bench [-r RUNS] [-t THREADS] -f FILE...
 *
 * For each format (all by default) it writes POINTS points (10 000 000 by
 * default, seeded uniform in [-100, 100]^3) to DIR (default /tmp), streams
 * the file once to warm the page cache, then times RUNS runs (default 5) of
 * `cat FILE > /dev/null` and of hd_read_file(), and prints the medians as a
 * markdown table row: file size, cat time, read time (wall clock), read CPU
 * time (user + system, all threads: on a loaded machine it shows the work
 * done when the wall clock does not), MB/s, million points/s, and read time
 * over cat time.  First it prints the time to allocate and write once an
 * array of N doubles triples, the floor for any reader that returns fresh
 * memory (the kernel zeroes each page on its first touch).  The file is deleted afterwards.
 * Text is written the way scanners and exporters write it, six decimals
 * ("%.6f"), except the "xyz17" row, which uses the 17 significant digits
 * that round-trip a double (where the fast path of number.c gives way to
 * strtod).  Binary PCD, LAS, NPY, STL and PLY rows read straight from the
 * mapping.  The "laz" and "laz10" rows hold the LAS row's integers
 * LASzip-compressed (tests/internal/lazwrite.c) as point format 6 (layered)
 * and 0 (pointwise), chunks of 50 000 decoded in parallel.  With -f the
 * rows are the given files instead (their base names), read where they
 * are and kept: real data, e.g. a LAZ file against its LAS counterpart.  Timings are wall-clock (CLOCK_MONOTONIC); nothing is asserted.
 */
#include "gen.h"

#include "benchutil.h"
#include "lazwrite.h"

#include <hausdorff.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* ---- writers ------------------------------------------------------------- */
static void put_u16(FILE *f, unsigned v) { fputc((int)(v & 255), f), fputc((int)(v >> 8), f); }
static void put_u32(FILE *f, uint32_t v) { fwrite(&v, 4, 1, f); } /* little-endian host */

/* A greedy LZF compressor (3-byte hash, offsets < 8192), enough to produce
 * a realistic PCD binary_compressed stream. */
static size_t lzf_compress(const unsigned char *in, size_t n, unsigned char *out) {
    enum { HBITS = 16 };
    size_t *table = calloc((size_t)1 << HBITS, sizeof *table), ip = 0, op = 0, lit = 0, lit_at = op++;
    while (ip + 2 < n) {
        unsigned h = ((unsigned)in[ip] << 16 | (unsigned)in[ip + 1] << 8 | in[ip + 2]) * 2654435761u >> (32 - HBITS);
        size_t ref = table[h];
        table[h] = ip + 1; /* +1: 0 means empty */
        size_t off = ref ? ip - (ref - 1) : 0;
        if (ref && off >= 1 && off <= 8192 && memcmp(in + ref - 1, in + ip, 3) == 0) {
            size_t len = 3, max = n - ip < 264 ? n - ip : 264;
            while (len < max && in[ref - 1 + len] == in[ip + len]) len++;
            if (lit) out[lit_at] = (unsigned char)(lit - 1);
            else op--;
            size_t l = len - 2, o = off - 1;
            if (l < 7) out[op++] = (unsigned char)((l << 5) | (o >> 8));
            else out[op++] = (unsigned char)((7 << 5) | (o >> 8)), out[op++] = (unsigned char)(l - 7);
            out[op++] = (unsigned char)(o & 255);
            ip += len;
            lit = 0;
            lit_at = op++;
            continue;
        }
        out[op++] = in[ip++];
        if (++lit == 32) {
            out[lit_at] = 31;
            lit = 0;
            lit_at = op++;
        }
    }
    while (ip < n) {
        out[op++] = in[ip++];
        if (++lit == 32) {
            out[lit_at] = 31;
            lit = 0;
            lit_at = op++;
        }
    }
    if (lit) out[lit_at] = (unsigned char)(lit - 1);
    else op--;
    free(table);
    return op;
}

static int write_file(const char *fmt, const char *path, const double *p, size_t n) {
    FILE *f = fopen(path, "wb");
    if (!f) return -1;
    setvbuf(f, NULL, _IOFBF, 1 << 20);
    if (!strcmp(fmt, "xyz") || !strcmp(fmt, "xyz17") || !strcmp(fmt, "csv")) {
        const char *line = !strcmp(fmt, "xyz") ? "%.6f %.6f %.6f\n" : !strcmp(fmt, "csv") ? "%.6f,%.6f,%.6f,1\n" : "%.17g %.17g %.17g\n";
        if (!strcmp(fmt, "csv")) fputs("x,y,z,intensity\n", f);
        for (size_t k = 0; k < n; k++) fprintf(f, line, p[3 * k], p[3 * k + 1], p[3 * k + 2]);
    } else if (!strcmp(fmt, "obj")) {
        for (size_t k = 0; k < n; k++) fprintf(f, "v %.6f %.6f %.6f\n", p[3 * k], p[3 * k + 1], p[3 * k + 2]);
    } else if (!strcmp(fmt, "off")) {
        fprintf(f, "OFF\n%zu 0 0\n", n);
        for (size_t k = 0; k < n; k++) fprintf(f, "%.6f %.6f %.6f\n", p[3 * k], p[3 * k + 1], p[3 * k + 2]);
    } else if (!strncmp(fmt, "ply", 3)) {
        int bin = strcmp(fmt, "ply_ascii") != 0, f32 = !strcmp(fmt, "ply_f32");
        fprintf(f, "ply\nformat %s 1.0\nelement vertex %zu\nproperty %s x\nproperty %s y\nproperty %s z\nend_header\n",
                bin ? "binary_little_endian" : "ascii", n, f32 ? "float" : "double", f32 ? "float" : "double",
                f32 ? "float" : "double");
        for (size_t k = 0; k < n; k++) {
            if (!bin) fprintf(f, "%.6f %.6f %.6f\n", p[3 * k], p[3 * k + 1], p[3 * k + 2]);
            else if (f32)
                for (int d = 0; d < 3; d++) {
                    float v = (float)p[3 * k + d];
                    fwrite(&v, 4, 1, f);
                }
            else fwrite(p + 3 * k, 8, 3, f);
        }
    } else if (!strcmp(fmt, "stl")) {
        char h[80] = "read_bench";
        fwrite(h, 1, 80, f);
        put_u32(f, (uint32_t)(n / 3));
        for (size_t t = 0; t < n / 3; t++) {
            float v[12] = {0, 0, 1};
            for (int k = 0; k < 9; k++) v[3 + k] = (float)p[9 * t + k];
            fwrite(v, 4, 12, f);
            put_u16(f, 0);
        }
    } else if (!strncmp(fmt, "pcd", 3)) {
        const char *data = !strcmp(fmt, "pcd_ascii") ? "ascii" : !strcmp(fmt, "pcd_bin") ? "binary" : "binary_compressed";
        fprintf(f, "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH %zu\nHEIGHT 1\n"
                   "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS %zu\nDATA %s\n", n, n, data);
        if (!strcmp(data, "ascii")) {
            for (size_t k = 0; k < n; k++) fprintf(f, "%.6f %.6f %.6f\n", p[3 * k], p[3 * k + 1], p[3 * k + 2]);
        } else {
            float *v = malloc(n * 12);
            int soa = !strcmp(data, "binary_compressed");
            for (size_t k = 0; k < n; k++)
                for (int d = 0; d < 3; d++) v[soa ? d * n + k : 3 * k + d] = (float)p[3 * k + d];
            if (!soa) {
                fwrite(v, 12, n, f);
            } else {
                unsigned char *z = malloc(n * 12 + n * 12 / 32 + 64);
                size_t zn = lzf_compress((unsigned char *)v, n * 12, z);
                put_u32(f, (uint32_t)zn);
                put_u32(f, (uint32_t)(n * 12));
                fwrite(z, 1, zn, f);
                free(z);
            }
            free(v);
        }
    } else if (!strcmp(fmt, "las")) {
        unsigned char h[375] = "LASF";
        h[24] = 1, h[25] = 4;
        memcpy(h + 94, &(uint16_t){375}, 2);
        memcpy(h + 96, &(uint32_t){375}, 4);
        h[104] = 6;
        memcpy(h + 105, &(uint16_t){30}, 2);
        double scale[3] = {1e-6, 1e-6, 1e-6}, zero[3] = {0, 0, 0};
        memcpy(h + 131, scale, 24);
        memcpy(h + 155, zero, 24);
        uint64_t cnt = n;
        memcpy(h + 247, &cnt, 8);
        fwrite(h, 1, 375, f);
        for (size_t k = 0; k < n; k++) {
            unsigned char rec[30] = {0};
            for (int d = 0; d < 3; d++) {
                int32_t X = (int32_t)(p[3 * k + d] * 1e6);
                memcpy(rec + 4 * d, &X, 4);
            }
            fwrite(rec, 1, 30, f);
        }
    } else if (!strncmp(fmt, "laz", 3)) {
        /* the LAS row's integers, LASzip-compressed in chunks of 50 000:
         * laz = point format 6 (layered), laz10 = format 0 (pointwise) */
        lazw_point_t *q = malloc(n * sizeof *q);
        for (size_t k = 0; k < n; k++) {
            int32_t X[3];
            for (int d = 0; d < 3; d++) X[d] = (int32_t)(p[3 * k + d] * 1e6);
            q[k] = (lazw_point_t){X[0], X[1], X[2], 1, 1, 0};
        }
        lazw_opts_t o = {strcmp(fmt, "laz10") ? 6 : 0, 0, 50000, NULL, 0, {1e-6, 1e-6, 1e-6}, {0, 0, 0}, 0};
        tf_buf_t b = {0};
        lazw_encode(&b, &o, q, n);
        fwrite(b.data, 1, b.size, f);
        tf_free(&b);
        free(q);
    } else if (!strcmp(fmt, "npy")) {
        char h[128];
        int len = snprintf(h, sizeof h, "{'descr': '<f8', 'fortran_order': False, 'shape': (%zu, 3), }", n);
        while ((10 + len + 1) % 64) h[len++] = ' ';
        h[len++] = '\n';
        fwrite("\x93NUMPY\x01\x00", 1, 8, f);
        put_u16(f, (unsigned)len);
        fwrite(h, 1, (size_t)len, f);
        fwrite(p, 24, n, f);
    } else {
        fclose(f);
        return -1;
    }
    return fclose(f);
}

static const char *const all_formats[] = {"ply_f32", "ply_f64", "ply_ascii", "stl", "obj", "off", "xyz", "xyz17", "csv",
                                          "pcd_bin", "pcd_z", "pcd_ascii", "las", "laz", "laz10", "npy", NULL};
static const char *extension(const char *fmt) {
    if (!strncmp(fmt, "ply", 3)) return "ply";
    if (!strncmp(fmt, "pcd", 3)) return "pcd";
    if (!strcmp(fmt, "xyz17")) return "xyz";
    if (!strcmp(fmt, "laz10")) return "laz";
    return fmt;
}

int main(int argc, char **argv) {
    size_t n = 10000000;
    int runs = 5, threads = 0, given = 0;
    const char *dir = "/tmp";
    const char *chosen[32];
    int n_chosen = 0;
    for (int k = 1; k < argc; k++) {
        if (!strcmp(argv[k], "-n") && k + 1 < argc) n = strtoull(argv[++k], NULL, 10);
        else if (!strcmp(argv[k], "-r") && k + 1 < argc) runs = atoi(argv[++k]);
        else if (!strcmp(argv[k], "-d") && k + 1 < argc) dir = argv[++k];
        else if (!strcmp(argv[k], "-t") && k + 1 < argc) threads = atoi(argv[++k]);
        else if (!strcmp(argv[k], "-f")) given = 1;
        else if (n_chosen < 32) chosen[n_chosen++] = argv[k];
    }
    if (runs < 1 || runs > 99 || n < 3) {
        fprintf(stderr, "usage: read_bench [-n POINTS] [-r RUNS] [-d DIR] [-t THREADS] [FORMAT...]\n"
                        "       read_bench [-r RUNS] [-t THREADS] -f FILE...\n");
        return 1;
    }
    if (!n_chosen)
        for (int k = 0; all_formats[k]; k++) chosen[n_chosen++] = all_formats[k];
    if (given) n = 3; /* nothing to generate */
    double *p = malloc(3 * n * sizeof *p);
    gen_rng_t r;
    gen_seed(&r, 1);
    gen_cube(&r, p, n, -100, 100);
    /* the floor for any reader that returns fresh memory: allocating the
     * result array and writing it once (the kernel zeroes every page on its
     * first touch) */
    double touch_t[99];
    for (int k = 0; k < runs; k++) {
        double t0 = bench_now();
        unsigned char *m = malloc(n * 3 * sizeof(double));
        memset(m, k + 1, n * 3 * sizeof(double));
        touch_t[k] = bench_now() - t0;
        if (m[n] != (unsigned char)(k + 1)) return 1;
        free(m);
    }
    if (!given)
        printf("First touch of a %zu-point double array (%.0f MB): %.3f s (median of %d)\n\n", n, n * 24 / 1e6,
               bench_median(touch_t, runs), runs);
    printf("| %s | file MB | cat s | read s | read CPU s | read MB/s | Mpoints/s | read / cat |\n"
           "|---|---|---|---|---|---|---|---|\n", given ? "file" : "format");
    for (int c = 0; c < n_chosen; c++) {
        char path[1024], cmd[1100];
        snprintf(path, sizeof path, "%s/read_bench_%d.%s", dir, (int)getpid(), extension(chosen[c]));
        if (given) snprintf(path, sizeof path, "%s", chosen[c]);
        else if (write_file(chosen[c], path, p, n)) {
            fprintf(stderr, "read_bench: cannot write %s as %s\n", path, chosen[c]);
            return 1;
        }
        struct stat st;
        stat(path, &st);
        double mb = (double)st.st_size / 1e6, cat_t[99], read_t[99], cpu_t[99];
        snprintf(cmd, sizeof cmd, "cat '%s' > /dev/null", path);
        if (system(cmd) != 0) return 1;
        size_t count = 0;
        for (int k = 0; k < runs; k++) {
            double t0 = bench_now();
            if (system(cmd) != 0) return 1;
            cat_t[k] = bench_now() - t0;
            hd_read_options_t o;
            hd_read_options_init(&o);
            o.threads = threads;
            hd_cloud_t *cl;
            hd_error_t e;
            double c0 = bench_cpu_now();
            t0 = bench_now();
            int rc = hd_read_file(path, &o, &cl, &e);
            read_t[k] = bench_now() - t0;
            cpu_t[k] = bench_cpu_now() - c0;
            if (rc) {
                fprintf(stderr, "read_bench: %s\n", e.message);
                return 1;
            }
            count = cl->count;
            hd_cloud_free(cl);
        }
        if (!given) unlink(path);
        const char *slash = strrchr(chosen[c], '/'), *row = given && slash ? slash + 1 : chosen[c];
        double ct = bench_median(cat_t, runs), rt = bench_median(read_t, runs), cp = bench_median(cpu_t, runs);
        printf("| %s | %.1f | %.3f | %.3f | %.3f | %.0f | %.1f | %.1f |\n", row, mb, ct, rt, cp, mb / rt,
               (double)count / rt / 1e6, rt / ct);
        fflush(stdout);
    }
    free(p);
    return 0;
}
