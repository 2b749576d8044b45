/*
 * keys_bench.c -- two callers of the Morton keys of packed doubles
 * (hd__keys_f64), one thread, for callgrind (docs/benchmarks.md, "The
 * Morton keys of packed doubles"):
 *
 *   index  hd_index_build of B and hd_index_directed of A against it, two
 *          Gaussian sets of N points, B's mean 2 sigma from A's along x
 *          (the tree's build and the queries' keys):
 *            valgrind --tool=callgrind --collect-atstart=no \
 *              --toggle-collect=hd_index_build --toggle-collect=hd_index_directed \
 *              build/bench/keys_bench 300000 index
 *   cubes  hd_hausdorff of two independent uniform cubes of N points (the
 *          engine's trees, src/engine/build.c):
 *            valgrind --tool=callgrind --collect-atstart=no \
 *              --toggle-collect=hd_hausdorff build/bench/keys_bench 1000000 cubes
 *
 * It prints the distance, so that two builds can be seen to agree.
 *
 * usage: keys_bench [N] [index | cubes]   (default 300000 index)
 */
#include "gen.h"

#include <hausdorff.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char **argv) {
    size_t n = argc > 1 ? strtoull(argv[1], NULL, 10) : 300000;
    int cubes = argc > 2 && strcmp(argv[2], "cubes") == 0;
    double *a = malloc(24 * n), *b = malloc(24 * n), ma[3] = {0, 0, 0}, mb[3] = {2, 0, 0};
    if (!a || !b || n == 0) return 1;
    gen_rng_t g;
    gen_seed(&g, cubes ? 41 : 39);
    if (cubes) gen_cube(&g, a, n, 0.0, 1.0), gen_cube(&g, b, n, 0.0, 1.0);
    else gen_gauss(&g, a, n, ma, 1.0), gen_gauss(&g, b, n, mb, 1.0);
    hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, n);
    hd_options_t o;
    hd_options_init(&o);
    o.threads = 1;
    hd_error_t err;
    hd_index_t *idx = NULL;
    hd_result_t r;
    hd_symmetric_t s;
    int rc = cubes ? hd_hausdorff(&A, &B, &o, &s, &err)
                   : hd_index_build(&B, &o, &idx, &err) || hd_index_directed(idx, &A, NULL, &o, &r, &err);
    hd_index_free(idx);
    if (rc) {
        fprintf(stderr, "keys_bench: %s\n", err.message);
        return 1;
    }
    printf("%s = %.17g (N = %zu)\n", cubes ? "H(A, B)" : "h(A, B)", cubes ? s.distance : r.distance, n);
    free(a), free(b);
    return 0;
}
