/* brute.c -- see brute.h. */
#include "brute.h"

double brute_d2(const double *p, const double *q) {
    double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
    return dx * dx + dy * dy + dz * dz;
}

brute_t brute_directed(const double *a, size_t na, const double *b, size_t nb) {
    brute_t r = {-1.0, 0, 0};
    for (size_t i = 0; i < na; i++) {
        double m = brute_d2(a + 3 * i, b);
        size_t mj = 0;
        for (size_t j = 1; j < nb; j++) {
            double d = brute_d2(a + 3 * i, b + 3 * j);
            if (d < m) { m = d; mj = j; }
        }
        if (m > r.d2) { r.d2 = m; r.i = i; r.j = mj; }
    }
    return r;
}
