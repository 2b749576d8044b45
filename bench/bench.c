/*
 * bench.c -- the engine benchmark (`make bench`): the `auto` engine against
 * the peers a user would otherwise reach for, on the same points, in the
 * same run.
 *
 * For every case (overlapping, disjoint and partly overlapping Gaussians,
 * sizes 100:1 and 1:100, a cloud against a copy perturbed by 1e-3 sigma, a
 * cloud against its copy translated by 0.1% to 10% of its box, real models)
 * and every size, it
 *  - generates A and B in memory (tests/support/gen.c, fixed seeds) or reads
 *    them with hd_read_file (data/, through bench_read_model);
 *  - times one streaming pass over all input coordinates (the
 *    memory-bandwidth floor, bench_floor_pass in bench/support/benchutil.c)
 *    at each thread count;
 *  - times hd_hausdorff with the `auto` engine (median of up to 5 runs) and
 *    records distance evaluations per point and the algorithm that ran;
 *  - times the library's own "kdtree" algorithm (the peer-equivalent
 *    baseline) within a time budget;
 *  - writes A and B as raw float64 files and runs each peer program on them
 *    (bench/peers/: nanoflann serial and OpenMP, PCL, SciPy's
 *    directed_hausdorff and cKDTree, Open3D) under a timeout, checking that
 *    each returns the same distance.
 * Every measurement is one JSON line in the output file; bench/report.py
 * turns them into the tables and plots of docs/benchmarks.md.
 *
 * With --scale it also runs the scale curve: for n = 10^4 .. 10^8, two
 * n-point clouds generated in memory, H with 2 threads, each in a child
 * process of its own so that its peak memory (ru_maxrss) is its own.
 *
 * Nothing here is a test: numbers are measured, never asserted.
 */
#include "benchutil.h"
#include "gen.h"

#include <hausdorff.h>

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

/* The engine's own account of its plan (hd__engine_explain, an internal
 * function of the library, for benchmarks). */
#include "engine/engine.h"

/* ---- options ----------------------------------------------------------------- */

typedef struct {
    const char *out;
    const char *peers;   /* directory of the C++ peer programs */
    const char *scripts; /* directory of the Python peers */
    const char *data;    /* the bundled models */
    const char *only;    /* run only the cases whose name contains this */
    const char *cli;     /* the command-line tool, timed one process per run */
    const char *self;    /* this program, run again for one-shot calls */
    size_t sizes[8];
    int n_sizes;
    int threads[4];
    int n_threads;
    int runs;
    double budget;  /* seconds of repeated runs per method before stopping */
    double timeout; /* seconds before a peer is stopped */
    int peers_on, scale, kdtree_on, distances_on;
    FILE *fp;
    char tmp[256];
} bench_t;

/* ---- the cases ------------------------------------------------------------------ */

typedef struct {
    char name[64];
    double *a, *b;
    size_t na, nb;
    char note[128];
} pair_t;

static double *alloc_points(size_t n) {
    double *p = malloc(24 * (n ? n : 1));
    if (!p) {
        fprintf(stderr, "bench: out of memory for %zu points\n", n);
        exit(1);
    }
    return p;
}

/* gen_seed(s) starts one splitmix64 stream at position s, so seeds 1 and 2
 * give the same numbers shifted by one draw; spreading the seeds over the
 * 64-bit positions keeps the benchmark's clouds independent. */
static uint64_t spread_seed(uint64_t seed) { return seed * 0x5851f42d4c957f2dULL; }

static void gauss(uint64_t seed, double *p, size_t n, double mx) {
    gen_rng_t g;
    gen_seed(&g, spread_seed(seed));
    double m[3] = {mx, 0, 0};
    gen_gauss(&g, p, n, m, 1.0);
}

/* The extent of p's box along its widest axis. */
static double extent(const double *p, size_t n) {
    double w = 0;
    for (int c = 0; c < 3; c++) {
        double lo = p[c], hi = p[c];
        for (size_t k = 1; k < n; k++) {
            double v = p[3 * k + c];
            lo = v < lo ? v : lo;
            hi = v > hi ? v : hi;
        }
        w = hi - lo > w ? hi - lo : w;
    }
    return w;
}

enum {
    C_OVERLAP, C_DISJOINT, C_PARTIAL, C_BIG_SMALL, C_SMALL_BIG, C_PERTURBED, C_SHUFFLED,
    C_TRANSLATED
};

/* Synthetic case `kind` at size n (translated: fraction `frac` of the box). */
static void make_case(pair_t *p, int kind, size_t n, double frac) {
    memset(p, 0, sizeof *p);
    size_t na = n, nb = n;
    if (kind == C_BIG_SMALL) nb = n / 100;
    if (kind == C_SMALL_BIG) na = n / 100;
    p->na = na;
    p->nb = nb;
    p->a = alloc_points(na);
    p->b = alloc_points(nb);
    switch (kind) {
    case C_OVERLAP:
    case C_DISJOINT:
    case C_PARTIAL: {
        /* Two Gaussians, B's mean `shift` sigma from A's along x. */
        static const struct {
            const char *name, *note;
            double shift;
        } g[] = {
            [C_OVERLAP] = {"overlapping", "two Gaussians, same mean", 0},
            [C_DISJOINT] = {"disjoint", "Gaussians 20 sigma apart", 20},
            [C_PARTIAL] = {"partial", "Gaussians 2 sigma apart", 2},
        };
        snprintf(p->name, sizeof p->name, "%s", g[kind].name);
        gauss(1, p->a, na, 0);
        gauss(2, p->b, nb, g[kind].shift);
        snprintf(p->note, sizeof p->note, "%s", g[kind].note);
        break;
    }
    case C_BIG_SMALL:
    case C_SMALL_BIG:
        snprintf(p->name, sizeof p->name, kind == C_BIG_SMALL ? "100:1" : "1:100");
        gauss(1, p->a, na, 0);
        gauss(2, p->b, nb, 0);
        snprintf(p->note, sizeof p->note, "overlapping Gaussians, |A|/|B| = %s",
                 kind == C_BIG_SMALL ? "100" : "1/100");
        break;
    case C_PERTURBED:
    case C_SHUFFLED: {
        /* Shuffled: the perturbed copy listed in a random order, so that no
         * point of B is at the position of its partner; the engine cannot
         * use the correspondence and must find every partner itself. */
        int shuffled = kind == C_SHUFFLED;
        snprintf(p->name, sizeof p->name, shuffled ? "perturbed, shuffled" : "perturbed");
        gauss(1, p->a, na, 0);
        gen_rng_t g;
        gen_seed(&g, spread_seed(3));
        for (size_t k = 0; k < 3 * nb; k++) p->b[k] = p->a[k] + 1e-3 * gen_normal(&g);
        snprintf(p->note, sizeof p->note, "copy + N(0, (1e-3 sigma)^2) noise%s",
                 shuffled ? ", shuffled" : "");
        for (size_t k = nb; shuffled && k > 1; k--) {
            size_t r = gen_u64(&g) % k;
            double t[3];
            memcpy(t, p->b + 3 * (k - 1), 24);
            memcpy(p->b + 3 * (k - 1), p->b + 3 * r, 24);
            memcpy(p->b + 3 * r, t, 24);
        }
        break;
    }
    default: {
        snprintf(p->name, sizeof p->name, "translated %g%%", 100 * frac);
        gauss(1, p->a, na, 0);
        double t = frac * extent(p->a, na);
        for (size_t k = 0; k < nb; k++) {
            p->b[3 * k] = p->a[3 * k] + t;
            p->b[3 * k + 1] = p->a[3 * k + 1];
            p->b[3 * k + 2] = p->a[3 * k + 2];
        }
        snprintf(p->note, sizeof p->note, "copy moved by %g of the box along x", frac);
    }
    }
}

/* Every `step`-th point of p (a decimated copy). */
static double *decimate(const double *p, size_t n, size_t step, size_t *m) {
    *m = (n + step - 1) / step;
    double *q = alloc_points(*m);
    for (size_t k = 0; k < *m; k++) memcpy(q + 3 * k, p + 3 * k * step, 24);
    return q;
}

/* ---- measuring ----------------------------------------------------------------- */

static void json_pair_head(bench_t *B, const pair_t *p, const char *method, int threads) {
    fprintf(B->fp, "{\"case\": \"%s\", \"note\": \"%s\", \"na\": %zu, \"nb\": %zu, \"method\": \"%s\", \"threads\": %d",
            p->name, p->note, p->na, p->nb, method, threads);
}

static void json_times(bench_t *B, const double *t, int n) {
    fprintf(B->fp, ", \"times\": [");
    for (int k = 0; k < n; k++) fprintf(B->fp, "%s%.6g", k ? ", " : "", t[k]);
    fprintf(B->fp, "]");
}

/* The library with `alg` at `threads` threads: median of up to B->runs
 * runs within the budget. */
static int run_library(bench_t *B, const pair_t *p, hd_algorithm_t alg, int threads,
                       double floor_s, double *H) {
    hd_points_t A = hd_points_f64(p->a, p->na), Bp = hd_points_f64(p->b, p->nb);
    hd_options_t o;
    hd_options_init(&o);
    o.algorithm = alg;
    o.threads = threads;
    double t[16], spent = 0;
    int n = 0;
    hd_symmetric_t s;
    hd_error_t e;
    double faults[16];
    for (int r = 0; r < B->runs && (r == 0 || spent < B->budget); r++) {
        long f0 = bench_minor_faults();
        double t0 = bench_now();
        if (hd_hausdorff(&A, &Bp, &o, &s, &e) != HD_OK) {
            fprintf(stderr, "bench: %s\n", e.message);
            return -1;
        }
        t[n] = bench_now() - t0;
        faults[n] = (double)(bench_minor_faults() - f0);
        spent += t[n++];
    }
    double med = bench_median(t, n);
    uint64_t evals = s.ab.stats.distance_evals + s.ba.stats.distance_evals;
    uint64_t culled = s.ab.stats.points_culled + s.ba.stats.points_culled;
    json_pair_head(B, p, alg == HD_ALG_AUTO ? "hausdorff auto" : "hausdorff kdtree", threads);
    fprintf(B->fp, ", \"median_s\": %.6g", med);
    json_times(B, t, n);
    fprintf(B->fp,
            ", \"distance\": %.17g, \"evals_per_point\": %.4g, \"culled_fraction\": %.4g, "
            "\"algorithm\": \"%s/%s\", \"floor_s\": %.6g, \"floor_ratio\": %.4g, \"page_faults\": %.0f}\n",
            s.distance, (double)evals / (double)(p->na + p->nb),
            (double)culled / (double)(p->na + p->nb), hd_algorithm_name(s.ab.algorithm),
            hd_algorithm_name(s.ba.algorithm), floor_s, med / floor_s, bench_median(faults, n));
    fflush(B->fp);
    *H = s.distance;
    fprintf(stderr, "  %-18s t=%d %10.4f s  H=%.17g  %.3g evals/pt  %.1fx floor\n",
            alg == HD_ALG_AUTO ? "hausdorff auto" : "hausdorff kdtree", threads, med, s.distance,
            (double)evals / (double)(p->na + p->nb), med / floor_s);
    return 0;
}

static int write_points(const char *path, const double *p, size_t n) {
    FILE *f = fopen(path, "wb");
    if (!f) return -1;
    size_t w = fwrite(p, 24, n, f);
    fclose(f);
    return w == n ? 0 : -1;
}

/* Run one peer command; parse its {"distance": D, "times": [...]} line.
 * The peer agrees when its distance equals H, or differs by at most
 * `tolerance` (an absolute bound, for peers that round the coordinates). */
static void run_peer(bench_t *B, const pair_t *p, const char *method, int threads,
                     const char *cmd, double H, double tolerance) {
    char line[8192];
    /* `cmd` may start with environment assignments: they go before timeout. */
    const char *prog = cmd;
    while (strchr(prog, '=') && strchr(prog, ' ') && strchr(prog, '=') < strchr(prog, ' ')) prog = strchr(prog, ' ') + 1;
    snprintf(line, sizeof line, "%.*stimeout %g %s 2>/dev/null", (int)(prog - cmd), cmd, B->timeout, prog);
    FILE *f = popen(line, "r");
    char buf[8192] = "";
    size_t got = f ? fread(buf, 1, sizeof buf - 1, f) : 0;
    buf[got] = '\0';
    int status = f ? pclose(f) : -1;
    json_pair_head(B, p, method, threads);
    double d = NAN, t[64];
    int n = 0;
    const char *ds = strstr(buf, "\"distance\":"), *ts = strstr(buf, "\"times\": [");
    if (ds && ts) {
        d = strtod(ds + 11, NULL);
        const char *q = ts + 10;
        while (n < 64) {
            char *end;
            double v = strtod(q, &end);
            if (end == q) break;
            t[n++] = v;
            q = end;
            while (*q == ',' || *q == ' ') q++;
        }
    }
    if (n == 0) {
        int timed_out = WIFEXITED(status) && WEXITSTATUS(status) == 124;
        fprintf(B->fp, ", \"failed\": \"%s\"}\n", timed_out ? "timeout" : "error");
        fprintf(stderr, "  %-18s t=%d  %s\n", method, threads, timed_out ? "timed out" : "failed");
        fflush(B->fp);
        return;
    }
    double med = bench_median(t, n);
    const char *same = d == H ? "exact" : fabs(d - H) <= tolerance ? "tolerance" : "DIFFERENT";
    fprintf(B->fp, ", \"median_s\": %.6g", med);
    json_times(B, t, n);
    fprintf(B->fp, ", \"distance\": %.17g, \"same\": \"%s\"}\n", d, same);
    fflush(B->fp);
    fprintf(stderr, "  %-18s t=%d %10.4f s  H=%.17g  %s\n", method, threads, med, d, same);
}

/* Per-point distances (hd_distances, both directions, distances and
 * nearest indices) at `threads` threads, median of up to B->runs runs
 * within the budget; "same" when the largest distance of each direction
 * is the Hausdorff distance H to the bit. */
static void run_distances(bench_t *B, const pair_t *p, int threads, double H) {
    hd_points_t A = hd_points_f64(p->a, p->na), Bp = hd_points_f64(p->b, p->nb);
    hd_options_t o;
    hd_options_init(&o);
    o.threads = threads;
    double *dab = malloc(8 * p->na), *dba = malloc(8 * p->nb);
    size_t *iab = malloc(sizeof(size_t) * p->na), *iba = malloc(sizeof(size_t) * p->nb);
    if (!dab || !dba || !iab || !iba) {
        fprintf(stderr, "bench: out of memory for per-point distances\n");
        exit(1);
    }
    double t[16], faults[16], spent = 0;
    int n = 0;
    hd_error_t e;
    for (int r = 0; r < B->runs && (r == 0 || spent < B->budget); r++) {
        long f0 = bench_minor_faults();
        double t0 = bench_now();
        if (hd_distances(&A, &Bp, &o, dab, iab, dba, iba, &e) != HD_OK) {
            fprintf(stderr, "bench: %s\n", e.message);
            exit(1);
        }
        t[n] = bench_now() - t0;
        faults[n] = (double)(bench_minor_faults() - f0);
        spent += t[n++];
    }
    double m = 0;
    for (size_t k = 0; k < p->na; k++) m = dab[k] > m ? dab[k] : m;
    for (size_t k = 0; k < p->nb; k++) m = dba[k] > m ? dba[k] : m;
    double med = bench_median(t, n);
    json_pair_head(B, p, "hausdorff distances", threads);
    fprintf(B->fp, ", \"median_s\": %.6g", med);
    json_times(B, t, n);
    fprintf(B->fp, ", \"distance\": %.17g, \"same\": \"%s\", \"page_faults\": %.0f}\n", m,
            m == H ? "exact" : "DIFFERENT", bench_median(faults, n));
    fflush(B->fp);
    fprintf(stderr, "  %-18s t=%d %10.4f s  max=%.17g  %s\n", "hausdorff distances", threads, med, m,
            m == H ? "exact" : "DIFFERENT");
    free(dab);
    free(dba);
    free(iab);
    free(iba);
}

/* A NumPy .npy file of n x 3 float64 (what the command-line tool reads). */
static int write_npy(const char *path, const double *p, size_t n) {
    FILE *f = fopen(path, "wb");
    if (!f) return -1;
    char head[128];
    int len = snprintf(head, sizeof head, "{'descr': '<f8', 'fortran_order': False, 'shape': (%zu, 3), }", n);
    int total = (10 + len + 1 + 63) / 64 * 64; /* magic, version, length, dict, '\n' */
    unsigned short hl = (unsigned short)(total - 10);
    fwrite("\x93NUMPY\x01\x00", 1, 8, f);
    fputc(hl & 0xff, f);
    fputc(hl >> 8, f);
    fwrite(head, 1, (size_t)len, f);
    for (int k = 10 + len; k < total - 1; k++) fputc(' ', f);
    fputc('\n', f);
    size_t w = fwrite(p, 24, n, f);
    return fclose(f) == 0 && w == n ? 0 : -1;
}

/* A JSON number after "key": in s (NAN when absent). */
static double json_field(const char *s, const char *key) {
    char pat[64];
    snprintf(pat, sizeof pat, "\"%s\": ", key);
    const char *q = strstr(s, pat);
    return q ? strtod(q + strlen(pat), NULL) : NAN;
}

/* The first call in a fresh process: `cmd` is run B->runs times (within
 * the budget), each printing one JSON line with "seconds" (and, for this
 * program's --one-shot, "page_faults"); records the medians as `method`. */
static void run_fresh(bench_t *B, const pair_t *p, const char *method, int threads, const char *cmd,
                      double H) {
    double t[16], faults[16], spent = 0, d = NAN;
    int n = 0, nf = 0;
    for (int r = 0; r < B->runs && (r == 0 || spent < B->budget); r++) {
        FILE *f = popen(cmd, "r");
        char buf[8192] = "";
        size_t got = f ? fread(buf, 1, sizeof buf - 1, f) : 0;
        buf[got] = '\0';
        if (f) pclose(f);
        double sec = json_field(buf, "seconds"), pf = json_field(buf, "page_faults");
        d = json_field(buf, strstr(buf, "\"hausdorff\"") ? "hausdorff" : "distance");
        if (!(sec >= 0)) break;
        t[n++] = sec;
        spent += sec;
        if (pf >= 0) faults[nf++] = pf;
    }
    json_pair_head(B, p, method, threads);
    if (!n) {
        fprintf(B->fp, ", \"failed\": \"error\"}\n");
        fprintf(stderr, "  %-18s t=%d  failed\n", method, threads);
        fflush(B->fp);
        return;
    }
    double med = bench_median(t, n);
    fprintf(B->fp, ", \"median_s\": %.6g", med);
    json_times(B, t, n);
    if (nf) fprintf(B->fp, ", \"page_faults\": %.0f", bench_median(faults, nf));
    fprintf(B->fp, ", \"distance\": %.17g, \"same\": \"%s\"}\n", d, d == H ? "exact" : "DIFFERENT");
    fflush(B->fp);
    fprintf(stderr, "  %-18s t=%d %10.4f s  H=%.17g  %s\n", method, threads, med, d, d == H ? "exact" : "DIFFERENT");
}

/* --one-shot A.bin B.bin THREADS: read both files, call hd_hausdorff once
 * (the first call of a fresh process, as the command-line tool makes it),
 * print its time and the page faults it took (getrusage). */
static int one_shot(const char *fa, const char *fb, int threads) {
    const char *path[2] = {fa, fb};
    double *pts[2];
    size_t n[2];
    for (int k = 0; k < 2; k++) {
        FILE *f = fopen(path[k], "rb");
        if (!f) {
            perror(path[k]);
            return 1;
        }
        fseek(f, 0, SEEK_END);
        long bytes = ftell(f);
        fseek(f, 0, SEEK_SET);
        n[k] = bytes > 0 ? (size_t)bytes / 24 : 0;
        pts[k] = alloc_points(n[k]);
        /* Through a small buffer, so that the points are written by this
         * process as a reader writes them: pages the kernel fills in a
         * read() cost a trap on their first touch from user space on this
         * virtual machine, which would be charged to the call. */
        static double chunk[3 * 4096];
        for (size_t done = 0; done < n[k];) {
            size_t m = n[k] - done < 4096 ? n[k] - done : 4096;
            if (fread(chunk, 24, m, f) != m) {
                perror(path[k]);
                return 1;
            }
            memcpy(pts[k] + 3 * done, chunk, 24 * m);
            done += m;
        }
        fclose(f);
    }
    hd_points_t A = hd_points_f64(pts[0], n[0]), Bp = hd_points_f64(pts[1], n[1]);
    hd_options_t o;
    hd_options_init(&o);
    o.threads = threads;
    hd_symmetric_t s;
    hd_error_t e;
    long f0 = bench_minor_faults();
    double t0 = bench_now();
    if (hd_hausdorff(&A, &Bp, &o, &s, &e) != HD_OK) {
        fprintf(stderr, "bench: %s\n", e.message);
        return 1;
    }
    double t = bench_now() - t0;
    printf("{\"distance\": %.17g, \"seconds\": %.6g, \"page_faults\": %ld}\n", s.distance, t,
           bench_minor_faults() - f0);
    free(pts[0]);
    free(pts[1]);
    return 0;
}

static void run_pair(bench_t *B, pair_t *p) {
    if (B->only && !strstr(p->name, B->only)) return;
    hd_points_t A = hd_points_f64(p->a, p->na), Bp = hd_points_f64(p->b, p->nb);
    hd_options_t o;
    hd_options_init(&o);
    char plan[256] = "?";
    hd__engine_explain(&A, &Bp, &o, NULL, plan, sizeof plan, NULL);
    fprintf(stderr, "%s: %zu / %zu points; plan: %s\n", p->name, p->na, p->nb, plan);
    json_pair_head(B, p, "plan", 0);
    fprintf(B->fp, ", \"plan\": \"%s\"}\n", plan);
    double H = NAN, floor_s[4];
    for (int k = 0; k < B->n_threads; k++) {
        floor_s[k] = bench_floor_pass(p->a, p->na, p->b, p->nb, B->threads[k]);
        json_pair_head(B, p, "floor", B->threads[k]);
        fprintf(B->fp, ", \"median_s\": %.6g}\n", floor_s[k]);
    }
    for (int k = 0; k < B->n_threads; k++)
        if (run_library(B, p, HD_ALG_AUTO, B->threads[k], floor_s[k], &H)) return;
    double Hk;
    if (B->kdtree_on)
        for (int k = 0; k < B->n_threads; k++) run_library(B, p, HD_ALG_KDTREE, B->threads[k], floor_s[k], &Hk);
    if (B->distances_on)
        for (int k = 0; k < B->n_threads; k++) run_distances(B, p, B->threads[k], H);
    char fa[512], fb[512], cmd[2048];
    snprintf(fa, sizeof fa, "%s/a.bin", B->tmp);
    snprintf(fb, sizeof fb, "%s/b.bin", B->tmp);
    if (write_points(fa, p->a, p->na) || write_points(fb, p->b, p->nb)) {
        fprintf(stderr, "bench: cannot write %s\n", B->tmp);
        return;
    }
    /* The first call of a fresh process, and the command-line tool (one
     * process per run; its computing time, reading excluded). */
    char na[512], nb[512];
    snprintf(na, sizeof na, "%s/a.npy", B->tmp);
    snprintf(nb, sizeof nb, "%s/b.npy", B->tmp);
    int npy = B->cli && !write_npy(na, p->a, p->na) && !write_npy(nb, p->b, p->nb);
    for (int k = 0; k < B->n_threads; k++) {
        int t = B->threads[k];
        snprintf(cmd, sizeof cmd, "%s --one-shot %s %s %d", B->self, fa, fb, t);
        run_fresh(B, p, "hausdorff auto, first call", t, cmd, H);
        if (npy) {
            snprintf(cmd, sizeof cmd, "%s --json --quiet --threads %d %s %s", B->cli, t, na, nb);
            run_fresh(B, p, "hausdorff CLI", t, cmd, H);
        }
    }
    if (npy) {
        unlink(na);
        unlink(nb);
    }
    if (!B->peers_on) {
        unlink(fa);
        unlink(fb);
        return;
    }
    /* Tolerances: double peers may sum in another order or take the root
     * differently (a few units in the last place of H); PCL rounds every
     * coordinate to float32, which moves a distance by up to about two float
     * roundings of the largest coordinate. */
    double scale = 0;
    for (size_t k = 0; k < 3 * p->na; k++) scale = fabs(p->a[k]) > scale ? fabs(p->a[k]) : scale;
    for (size_t k = 0; k < 3 * p->nb; k++) scale = fabs(p->b[k]) > scale ? fabs(p->b[k]) : scale;
    double tol_double = 8 * 0x1p-52 * H, tol_float = 4 * sqrt(3.0) * 0x1p-24 * scale + 8 * 0x1p-24 * H;
    for (int k = 0; k < B->n_threads; k++) {
        int t = B->threads[k];
        snprintf(cmd, sizeof cmd, "%s/nanoflann_hd %s %s %d %d %g", B->peers, fa, fb, t, B->runs, B->budget);
        run_peer(B, p, "nanoflann kd-tree", t, cmd, H, 0);
        snprintf(cmd, sizeof cmd, "%s/pcl_hd %s %s %d %d %g", B->peers, fa, fb, t, B->runs, B->budget);
        run_peer(B, p, "PCL KdTreeFLANN", t, cmd, H, tol_float);
        snprintf(cmd, sizeof cmd, "/usr/bin/python3 %s/scipy_hd.py ckdtree %s %s %d %d %g", B->scripts, fa, fb, t,
                 B->runs, B->budget);
        run_peer(B, p, "scipy cKDTree", t, cmd, H, tol_double);
        snprintf(cmd, sizeof cmd, "OMP_NUM_THREADS=%d /usr/bin/python3 %s/open3d_hd.py %s %s %d %d %g", t,
                 B->scripts, fa, fb, t, B->runs, B->budget);
        run_peer(B, p, "Open3D", t, cmd, H, tol_double);
    }
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 %s/scipy_hd.py directed_hausdorff %s %s 1 %d %g", B->scripts, fa,
             fb, B->runs, B->budget);
    run_peer(B, p, "scipy directed_hausdorff", 1, cmd, H, tol_double);
    unlink(fa);
    unlink(fb);
}

static void free_pair(pair_t *p) {
    free(p->a);
    free(p->b);
}

/* ---- the scale curve ------------------------------------------------------------- */

typedef struct {
    void *p;
    size_t lo, hi;
    uint64_t seed;
    int f32;
} gen_part_t;

/* Gaussian points [lo, hi), each block of 2^16 points from its own seed, so
 * the cloud is the same at any thread count. */
static void *gen_part(void *arg) {
    gen_part_t *g = arg;
    for (size_t blk = g->lo >> 16; (blk << 16) < g->hi; blk++) {
        gen_rng_t r;
        gen_seed(&r, spread_seed(g->seed << 24 | blk));
        size_t s = blk << 16, e = s + 65536 < g->hi ? s + 65536 : g->hi;
        if (s < g->lo) s = g->lo;
        for (size_t k = s; k < e; k++)
            for (int c = 0; c < 3; c++) {
                double v = gen_normal(&r);
                if (g->f32) ((float *)g->p)[3 * k + c] = (float)v;
                else ((double *)g->p)[3 * k + c] = v;
            }
    }
    return NULL;
}

static void *gen_cloud(size_t n, uint64_t seed, int f32) {
    void *p = malloc((f32 ? 12 : 24) * n);
    if (!p) return NULL;
    /* Split at block boundaries between two threads. */
    size_t half = ((n / 2) >> 16) << 16;
    gen_part_t g[2] = {{p, 0, half, seed, f32}, {p, half, n, seed, f32}};
    pthread_t t;
    pthread_create(&t, NULL, gen_part, &g[1]);
    gen_part(&g[0]);
    pthread_join(t, NULL);
    return p;
}

/* One scale run in this process: prints a JSON line on stdout. */
static int scale_one(size_t n, int f32, int threads) {
    void *a = gen_cloud(n, 11, f32), *b = gen_cloud(n, 12, f32);
    if (!a || !b) {
        fprintf(stderr, "bench: cannot allocate two clouds of %zu points\n", n);
        return 1;
    }
    hd_points_t A = f32 ? hd_points_f32(a, n) : hd_points_f64(a, n);
    hd_points_t B = f32 ? hd_points_f32(b, n) : hd_points_f64(b, n);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    double rss_before = (double)ru.ru_maxrss * 1024.0;
    hd_options_t o;
    hd_options_init(&o);
    o.threads = threads;
    hd_symmetric_t s;
    hd_error_t e;
    int runs = n <= 10000000 ? 3 : 1;
    double t[3];
    for (int r = 0; r < runs; r++) {
        double t0 = bench_now();
        if (hd_hausdorff(&A, &B, &o, &s, &e) != HD_OK) {
            fprintf(stderr, "bench: %s\n", e.message);
            return 1;
        }
        t[r] = bench_now() - t0;
    }
    getrusage(RUSAGE_SELF, &ru);
    double input = (double)n * 2 * (f32 ? 12 : 24);
    /* The plan, asked after the timed runs and the memory reading. */
    char plan[256] = "?";
    hd__engine_explain(&A, &B, &o, NULL, plan, sizeof plan, NULL);
    printf("{\"case\": \"scale\", \"method\": \"hausdorff auto\", \"n\": %zu, \"dtype\": \"%s\", \"threads\": %d, "
           "\"median_s\": %.6g, \"runs\": %d, \"distance\": %.17g, \"input_bytes\": %.0f, "
           "\"peak_rss_bytes\": %.0f, \"rss_after_input_bytes\": %.0f, \"plan\": \"%s\"}\n",
           n, f32 ? "float32" : "float64", threads, bench_median(t, runs), runs, s.distance, input,
           (double)ru.ru_maxrss * 1024.0, rss_before, plan);
    free(a);
    free(b);
    return 0;
}

static void run_scale(bench_t *B, const char *self) {
    static const size_t ns[] = {10000, 100000, 1000000, 10000000, 100000000};
    for (int f32 = 0; f32 < 2; f32++)
        for (size_t k = 0; k < sizeof ns / sizeof ns[0]; k++) {
            if (f32 && ns[k] < 100000000) continue;
            char cmd[1024];
            snprintf(cmd, sizeof cmd, "%s --scale-one %zu%s", self, ns[k], f32 ? " --float32" : "");
            fprintf(stderr, "scale: %zu points per cloud%s\n", ns[k], f32 ? " (float32)" : "");
            FILE *f = popen(cmd, "r");
            char line[2048];
            if (f && fgets(line, sizeof line, f)) {
                fputs(line, B->fp);
                fputs(line, stderr);
                fflush(B->fp);
            }
            if (f) pclose(f);
        }
}

/* ---- main ------------------------------------------------------------------------ */

static void usage(void) {
    fprintf(stderr,
            "usage: hd_bench [--out FILE] [--peers DIR] [--scripts DIR] [--data DIR]\n"
            "                [--sizes N,N,...] [--threads T,T] [--runs R] [--budget S]\n"
            "                [--timeout S] [--case NAME] [--no-peers] [--no-kdtree]\n"
            "                [--no-distances] [--cli PATH] [--scale] [--quick]\n"
            "       hd_bench --scale-one N [--float32]\n"
            "       hd_bench --one-shot A.bin B.bin THREADS\n");
}

int main(int argc, char **argv) {
    bench_t B;
    memset(&B, 0, sizeof B);
    B.out = "bench-results.jsonl";
    B.peers = ".";
    B.scripts = "bench/peers";
    B.data = "data";
    B.n_sizes = bench_parse_sizes("10000,100000,1000000", B.sizes, 8);
    B.threads[0] = 1;
    B.threads[1] = 2;
    B.n_threads = 2;
    B.runs = 5;
    B.budget = 10;
    B.timeout = 120;
    B.peers_on = 1;
    B.kdtree_on = 1;
    B.distances_on = 1;
    B.self = argv[0];
    size_t scale_n = 0;
    int f32 = 0;
    for (int k = 1; k < argc; k++) {
        const char *o = argv[k], *v = k + 1 < argc ? argv[k + 1] : NULL;
        if (!strcmp(o, "--out") && v) B.out = v, k++;
        else if (!strcmp(o, "--peers") && v) B.peers = v, k++;
        else if (!strcmp(o, "--scripts") && v) B.scripts = v, k++;
        else if (!strcmp(o, "--data") && v) B.data = v, k++;
        else if (!strcmp(o, "--case") && v) B.only = v, k++;
        else if (!strcmp(o, "--sizes") && v) B.n_sizes = bench_parse_sizes(v, B.sizes, 8), k++;
        else if (!strcmp(o, "--threads") && v) {
            size_t t[4];
            B.n_threads = bench_parse_sizes(v, t, 4);
            for (int i = 0; i < B.n_threads; i++) B.threads[i] = (int)t[i];
            k++;
        } else if (!strcmp(o, "--runs") && v) B.runs = atoi(v), k++;
        else if (!strcmp(o, "--budget") && v) B.budget = atof(v), k++;
        else if (!strcmp(o, "--timeout") && v) B.timeout = atof(v), k++;
        else if (!strcmp(o, "--no-peers")) B.peers_on = 0;
        else if (!strcmp(o, "--no-kdtree")) B.kdtree_on = 0;
        else if (!strcmp(o, "--no-distances")) B.distances_on = 0;
        else if (!strcmp(o, "--cli") && v) B.cli = v, k++;
        else if (!strcmp(o, "--one-shot") && k + 3 < argc) return one_shot(argv[k + 1], argv[k + 2], atoi(argv[k + 3]));
        else if (!strcmp(o, "--scale")) B.scale = 1;
        else if (!strcmp(o, "--quick")) B.n_sizes = bench_parse_sizes("10000,100000", B.sizes, 8), B.runs = 3;
        else if (!strcmp(o, "--scale-one") && v) scale_n = (size_t)strtod(v, NULL), k++;
        else if (!strcmp(o, "--float32")) f32 = 1;
        else {
            usage();
            return 2;
        }
    }
    if (B.runs < 1 || B.runs > 16) B.runs = 5;
    if (scale_n) return scale_one(scale_n, f32, 2);

    B.fp = fopen(B.out, "w");
    if (!B.fp) {
        perror(B.out);
        return 1;
    }
    snprintf(B.tmp, sizeof B.tmp, "/tmp/hd-bench-%d", (int)getpid());
    mkdir(B.tmp, 0700);

    /* Synthetic cases at every size. */
    int kinds[] = {C_OVERLAP, C_DISJOINT, C_PARTIAL, C_BIG_SMALL, C_SMALL_BIG, C_PERTURBED, C_SHUFFLED};
    for (int s = 0; s < B.n_sizes; s++)
        for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++) {
            if ((kinds[k] == C_BIG_SMALL || kinds[k] == C_SMALL_BIG) && B.sizes[s] < 10000) continue;
            pair_t p;
            make_case(&p, kinds[k], B.sizes[s], 0);
            run_pair(&B, &p);
            free_pair(&p);
        }
    /* The translation sweep at the largest size. */
    double fracs[] = {0.001, 0.003, 0.01, 0.03, 0.1};
    for (size_t k = 0; k < sizeof fracs / sizeof fracs[0]; k++) {
        pair_t p;
        make_case(&p, C_TRANSLATED, B.sizes[B.n_sizes - 1], fracs[k]);
        run_pair(&B, &p);
        free_pair(&p);
    }
    /* Real models: vertices, and 10^6 points sampled on their faces. */
    struct {
        const char *name, *a, *b;
        size_t sample, decimate;
    } models[] = {
        {"armadillo / decimated", "armadillo.ply", NULL, 0, 10},
        {"lion / lion-head", "cgal_lion.ply", "cgal_lion_head.ply", 0, 0},
        {"wuson OBJ / STL", "wuson_obj.ply", "wuson_stl.ply", 0, 0},
        {"armadillo 1M / decimated", "orig/armadillo.off", NULL, 1000000, 10},
        {"lion 1M / lion-head 1M", "orig/lion.off", "orig/lion-head.off", 1000000, 0},
    };
    for (size_t k = 0; k < sizeof models / sizeof models[0]; k++) {
        pair_t p;
        memset(&p, 0, sizeof p);
        snprintf(p.name, sizeof p.name, "%s", models[k].name);
        char path[1024];
        hd_error_t e;
        snprintf(path, sizeof path, "%s/%s", B.data, models[k].a);
        p.a = bench_read_model(path, models[k].sample, 1, 0, &p.na, &e);
        if (p.a && models[k].b) {
            snprintf(path, sizeof path, "%s/%s", B.data, models[k].b);
            p.b = bench_read_model(path, models[k].sample, 2, 0, &p.nb, &e);
        }
        if (!p.a || (models[k].b && !p.b)) {
            fprintf(stderr, "bench: %s\n", e.message);
            free_pair(&p);
            continue;
        }
        if (models[k].b) {
            snprintf(p.note, sizeof p.note, "%s%s vs %s", models[k].sample ? "sampled " : "", models[k].a,
                     models[k].b);
        } else {
            p.b = decimate(p.a, p.na, models[k].decimate, &p.nb);
            snprintf(p.note, sizeof p.note, "%s%s vs every %zuth point", models[k].sample ? "sampled " : "",
                     models[k].a, models[k].decimate);
        }
        run_pair(&B, &p);
        free_pair(&p);
    }
    if (B.scale) run_scale(&B, argv[0]);
    fclose(B.fp);
    rmdir(B.tmp);
    return 0;
}
