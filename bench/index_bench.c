/*
 * index_bench.c -- the index (hd_index_build of B, hd_index_directed of A
 * against it) on two Gaussian sets of N points, B's mean 2 sigma from A's
 * along x, one thread: the tree's build (its Morton keys, hd__keys_f64)
 * and the queries, for callgrind (docs/benchmarks.md, "The Morton keys of
 * packed doubles"):
 *
 *   valgrind --tool=callgrind --collect-atstart=no --toggle-collect=hd_index_build \
 *       --toggle-collect=hd_index_directed build/bench/index_bench 300000
 *
 * It prints the distance, so that two builds can be seen to agree.
 *
 * usage: index_bench [N]   (default 300000)
 */
#include "gen.h"

#include <hausdorff.h>
#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv) {
    size_t n = argc > 1 ? strtoull(argv[1], NULL, 10) : 300000;
    double *a = malloc(24 * n), *b = malloc(24 * n), ma[3] = {0, 0, 0}, mb[3] = {2, 0, 0};
    if (!a || !b || n == 0) return 1;
    gen_rng_t g;
    gen_seed(&g, 39);
    gen_gauss(&g, a, n, ma, 1.0);
    gen_gauss(&g, b, n, mb, 1.0);
    hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, n);
    hd_options_t o;
    hd_options_init(&o);
    o.threads = 1;
    hd_error_t err;
    hd_index_t *idx = NULL;
    hd_result_t r;
    if (hd_index_build(&B, &o, &idx, &err) || hd_index_directed(idx, &A, NULL, &o, &r, &err)) {
        fprintf(stderr, "index_bench: %s\n", err.message);
        hd_index_free(idx);
        return 1;
    }
    printf("h(A, B) = %.17g (N = %zu)\n", r.distance, n);
    hd_index_free(idx);
    free(a), free(b);
    return 0;
}
