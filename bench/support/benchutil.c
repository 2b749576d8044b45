/*
 * benchutil.c -- see benchutil.h.
 *
 * The floor pass: a single chain of additions (s += p[k]) waits for each
 * add before the next, so it measures the adder's latency, about twice the
 * time memory needs to deliver the data; four independent sums keep enough
 * loads in flight for the pass to be bound by bandwidth, which is what a
 * "floor" for reading the points should be.  Worker k of T reads the k-th
 * T-th of A and then the k-th T-th of B, so exactly T threads read at once.
 */
#include "benchutil.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

static double clock_s(clockid_t id) {
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

double bench_now(void) { return clock_s(CLOCK_MONOTONIC); }

long bench_minor_faults(void) {
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_minflt;
}
double bench_cpu_now(void) { return clock_s(CLOCK_PROCESS_CPUTIME_ID); }

static int cmp_double(const void *x, const void *y) {
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

double bench_median(const double *v, int n) {
    double *s = malloc((size_t)n * sizeof *s);
    if (!s) return v[0];
    memcpy(s, v, (size_t)n * sizeof *s);
    qsort(s, (size_t)n, sizeof *s, cmp_double);
    double m = n % 2 ? s[n / 2] : 0.5 * (s[n / 2 - 1] + s[n / 2]);
    free(s);
    return m;
}

int bench_listed(const char *list, const char *name) {
    if (!list) return 1;
    size_t n = strlen(name);
    for (const char *p = list; (p = strstr(p, name)) != NULL; p += n)
        if ((p == list || p[-1] == ',') && (p[n] == ',' || p[n] == '\0')) return 1;
    return 0;
}

int bench_parse_sizes(const char *s, size_t *out, int max) {
    int n = 0;
    while (*s && n < max) {
        char *end;
        out[n++] = (size_t)strtod(s, &end);
        s = *end == ',' ? end + 1 : end;
        if (end == s && *s) break;
    }
    return n;
}

/* ---- the memory-bandwidth floor ------------------------------------------ */

/* One worker's share: a piece of A and a piece of B, and their sum. */
typedef struct {
    const double *p[2];
    size_t n[2];
    double sum;
} pass_part_t;

static double sum4(const double *p, size_t n) {
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
    size_t k = 0;
    for (; k + 4 <= n; k += 4) {
        s0 += p[k];
        s1 += p[k + 1];
        s2 += p[k + 2];
        s3 += p[k + 3];
    }
    for (; k < n; k++) s0 += p[k];
    return s0 + s1 + s2 + s3;
}

static void *pass_part(void *arg) {
    pass_part_t *s = arg;
    s->sum = sum4(s->p[0], s->n[0]) + sum4(s->p[1], s->n[1]);
    return NULL;
}

/* The sums go here, so that no pass can be optimised away. */
static volatile double pass_sink;

double bench_floor_pass(const double *a, size_t na, const double *b, size_t nb, int threads) {
    if (threads < 1) threads = 1;
    pass_part_t *part = malloc((size_t)threads * sizeof *part);
    pthread_t *tid = malloc((size_t)threads * sizeof *tid);
    char *started = malloc((size_t)threads);
    if (!part || !tid || !started) {
        free(part);
        free(tid);
        free(started);
        return -1.0;
    }
    const double *set[2] = {a, b};
    size_t len[2] = {3 * na, 3 * nb}, T = (size_t)threads;
    for (size_t k = 0; k < T; k++)
        for (int s = 0; s < 2; s++) {
            part[k].p[s] = set[s] + len[s] * k / T;
            part[k].n[s] = len[s] * (k + 1) / T - len[s] * k / T;
        }
    double t[5];
    for (int r = 0; r < 5; r++) {
        double t0 = bench_now();
        /* A worker that cannot be started is run by the caller's thread. */
        for (int k = 1; k < threads; k++) started[k] = pthread_create(&tid[k], NULL, pass_part, &part[k]) == 0;
        pass_part(&part[0]);
        for (int k = 1; k < threads; k++) {
            if (started[k]) pthread_join(tid[k], NULL);
            else pass_part(&part[k]);
        }
        t[r] = bench_now() - t0;
        for (int k = 0; k < threads; k++) pass_sink += part[k].sum;
    }
    free(part);
    free(tid);
    free(started);
    return bench_median(t, 5);
}

/* ---- reading a model ------------------------------------------------------ */

double *bench_read_model(const char *path, size_t sample, uint64_t seed, int threads, size_t *n,
                         hd_error_t *err) {
    hd_read_options_t ro;
    hd_read_options_init(&ro);
    ro.dtype = HD_FLOAT64;
    ro.threads = threads;
    if (sample) {
        ro.mesh = HD_MESH_SAMPLE;
        ro.sample = sample;
        ro.seed = seed;
    }
    hd_cloud_t *c;
    if (hd_read_file(path, &ro, &c, err) != HD_OK) return NULL;
    double *p = malloc(3 * sizeof(double) * (c->count ? c->count : 1));
    if (!p) {
        if (err) {
            err->code = HD_ENOMEM;
            err->line = err->offset = -1;
            snprintf(err->message, sizeof err->message, "%s: out of memory for %zu points", path, c->count);
        }
        hd_cloud_free(c);
        return NULL;
    }
    memcpy(p, c->data, 3 * sizeof(double) * c->count);
    *n = c->count;
    hd_cloud_free(c);
    return p;
}
