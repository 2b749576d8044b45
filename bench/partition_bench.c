/*
 * partition_bench.c -- RCB against Morton ranges, the two partitions issue
 * 14 names, on the scenes of docs/scale-out.md (bench/support/scene.c):
 *     build/bench/partition_bench [--points N] [--parts LIST] [--cases LIST]
 * Both cut A and B together into P parts of equal counts (exactly, on all
 * the points: the best either can do): RCB as hd_mpi_hausdorff does (the
 * longest axis of a node's points, floor(k/2)/k of them to the left, ties
 * on the split coordinate by index), Morton by sorting 63-bit keys on the
 * scene's box and cutting the order into P runs (a sample sort's result).
 * For each, over both directions, it prints
 *  - cross%: the points whose exact nearest neighbour in the other set lies
 *    in another part: what any partition must forward at the least;
 *  - nbrs:   the mean number of other parts a part's cross points need.
 * The exact nearest neighbours come from hd_distances.
 */
#include <hausdorff.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene.h"

typedef struct { double x[3]; size_t id; } pt_t; /* id: A k, B n + k */

static int sort_axis; /* the bench's own comparator state (one thread) */

static int by_axis(const void *p, const void *q) {
    const pt_t *a = p, *b = q;
    double u = a->x[sort_axis], v = b->x[sort_axis];
    if (u != v) return u < v ? -1 : 1;
    return a->id < b->id ? -1 : a->id > b->id;
}

static void rcb(pt_t *s, size_t n, int p0, int k, int *part) {
    if (k == 1) {
        for (size_t t = 0; t < n; t++) part[s[t].id] = p0;
        return;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t t = 0; t < n; t++)
        for (int a = 0; a < 3; a++) {
            if (s[t].x[a] < lo[a]) lo[a] = s[t].x[a];
            if (s[t].x[a] > hi[a]) hi[a] = s[t].x[a];
        }
    sort_axis = 0;
    for (int a = 1; a < 3; a++)
        if (hi[a] - lo[a] > hi[sort_axis] - lo[sort_axis]) sort_axis = a;
    qsort(s, n, sizeof *s, by_axis);
    int kl = k / 2;
    size_t m = (size_t)((double)n * kl / k);
    rcb(s, m, p0, kl, part);
    rcb(s + m, n - m, p0 + kl, k - kl, part);
}

static uint64_t spread(uint64_t v) { /* 21 bits to every third of 63 */
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffULL;
    v = (v | v << 16) & 0x1f0000ff0000ffULL;
    v = (v | v << 8) & 0x100f00f00f00f00fULL;
    v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
    v = (v | v << 2) & 0x1249249249249249ULL;
    return v;
}

typedef struct { uint64_t key; size_t id; } key_t_;

static int by_key(const void *p, const void *q) {
    const key_t_ *a = p, *b = q;
    if (a->key != b->key) return a->key < b->key ? -1 : 1;
    return a->id < b->id ? -1 : a->id > b->id;
}

static void morton(const pt_t *s, size_t n, int P, int *part) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t t = 0; t < n; t++)
        for (int a = 0; a < 3; a++) {
            if (s[t].x[a] < lo[a]) lo[a] = s[t].x[a];
            if (s[t].x[a] > hi[a]) hi[a] = s[t].x[a];
        }
    double side = 0;
    for (int a = 0; a < 3; a++) side = hi[a] - lo[a] > side ? hi[a] - lo[a] : side;
    key_t_ *k = malloc(n * sizeof *k);
    for (size_t t = 0; t < n; t++) {
        uint64_t c[3];
        for (int a = 0; a < 3; a++) c[a] = (uint64_t)((s[t].x[a] - lo[a]) / side * 2097151.0);
        k[t].key = spread(c[0]) | spread(c[1]) << 1 | spread(c[2]) << 2;
        k[t].id = s[t].id;
    }
    qsort(k, n, sizeof *k, by_key);
    for (size_t t = 0; t < n; t++) part[k[t].id] = (int)((double)t * P / (double)n);
    free(k);
}

/* cross%, nbrs for one partition. */
static void measure(size_t n, const int *part, int P, const size_t *nab, const size_t *nba, double out[2]) {
    size_t cross = 0;
    char *seen = calloc((size_t)P * (size_t)P, 1);
    for (int dir = 0; dir < 2; dir++) {
        const size_t *nn = dir ? nba : nab;
        size_t po = dir ? n : 0, qo = dir ? 0 : n;
        for (size_t k = 0; k < n; k++) {
            int mine = part[po + k], other = part[qo + nn[k]];
            if (other != mine) {
                cross++;
                seen[(size_t)mine * (size_t)P + (size_t)other] = 1;
            }
        }
    }
    size_t pairs = 0;
    for (size_t k = 0; k < (size_t)P * (size_t)P; k++) pairs += seen[k];
    out[0] = 100.0 * (double)cross / (2.0 * (double)n);
    out[1] = (double)pairs / P;
    free(seen);
}

int main(int argc, char **argv) {
    size_t n = 200000;
    const char *parts = "16,64,256,1024", *cases = "uniform,lidar,copy";
    for (int k = 1; k < argc; k++) {
        if (!strcmp(argv[k], "--points") && k + 1 < argc) n = (size_t)atof(argv[++k]);
        else if (!strcmp(argv[k], "--parts") && k + 1 < argc) parts = argv[++k];
        else if (!strcmp(argv[k], "--cases") && k + 1 < argc) cases = argv[++k];
        else {
            fprintf(stderr, "partition_bench: unknown argument %s\n", argv[k]);
            return 1;
        }
    }
    double *a = malloc(3 * n * sizeof *a), *b = malloc(3 * n * sizeof *b), *dab = malloc(n * sizeof *dab),
           *dba = malloc(n * sizeof *dba);
    size_t *nab = malloc(n * sizeof *nab), *nba = malloc(n * sizeof *nba);
    pt_t *s = malloc(2 * n * sizeof *s);
    int *part = malloc(2 * n * sizeof *part);
    printf("# partition_bench: %zu points per side; cross%% = nearest in another part, nbrs = other parts "
           "per part\n", n);
    printf("# case     parts   RCB cross%%   nbrs   Morton cross%%   nbrs\n");
    char cl[256];
    snprintf(cl, sizeof cl, "%s", cases);
    for (char *c = strtok(cl, ","); c; c = strtok(NULL, ",")) {
        scene_make(c, 0, 1, 7, 0, a, b, n);
        hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, n);
        hd_error_t err;
        if (hd_distances(&A, &B, NULL, dab, nab, dba, nba, &err) != HD_OK) {
            fprintf(stderr, "partition_bench: %s\n", err.message);
            return 1;
        }
        char pl[256];
        snprintf(pl, sizeof pl, "%s", parts);
        char *save = NULL;
        for (char *q = strtok_r(pl, ",", &save); q; q = strtok_r(NULL, ",", &save)) {
            int P = atoi(q);
            double r[2][2];
            for (int m = 0; m < 2; m++) {
                for (size_t k = 0; k < n; k++) {
                    memcpy(s[k].x, a + 3 * k, sizeof s[k].x), s[k].id = k;
                    memcpy(s[n + k].x, b + 3 * k, sizeof s[k].x), s[n + k].id = n + k;
                }
                if (m == 0) rcb(s, 2 * n, 0, P, part);
                else morton(s, 2 * n, P, part);
                measure(n, part, P, nab, nba, r[m]);
            }
            printf("%-8s %6d %10.3f %6.1f %13.3f %6.1f\n", c, P, r[0][0], r[0][1], r[1][0], r[1][1]);
            fflush(stdout);
        }
    }
    free(a), free(b), free(dab), free(dba), free(nab), free(nba), free(s), free(part);
    return 0;
}
