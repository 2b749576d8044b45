/* field_cases.c -- issue 39's five cases (field_cases.h). */
#include "field_cases.h"

#include "gen.h"

const char *const field_case_names[FIELD_CASES] = {"a_overlapping", "b_disjoint", "c_partial", "d_small_B",
                                                   "e_shuffled"};

void field_case(int c, size_t n, double *a, double *b, size_t *nb) {
    gen_rng_t g;
    gen_seed(&g, 39 + (uint64_t)c);
    *nb = c == 3 ? n / 100 : n;
    double m0[3] = {0, 0, 0}, m1[3] = {c == 1 ? 20.0 : c == 2 ? 2.0 : 0.0, 0, 0};
    gen_gauss(&g, a, n, m0, 1.0);
    if (c == 4) {
        for (size_t k = 0; k < 3 * n; k++) b[k] = a[k] + 1e-3 * gen_normal(&g);
        for (size_t k = n; k > 1; k--) gen_swap(b, k - 1, gen_u64(&g) % k);
    } else {
        gen_gauss(&g, b, *nb, m1, 1.0);
    }
}
