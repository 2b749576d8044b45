/* brute.c -- see brute.h. */
#include "brute.h"

double brute_d2(const double *p, const double *q) {
    double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
    return dx * dx + dy * dy + dz * dz;
}

brute_t brute_directed(const double *a, size_t na, const double *b, size_t nb) {
    brute_t r = {-1.0, 0, 0};
    for (size_t i = 0; i < na; i++) {
        size_t mj;
        double m = brute_nearest(a + 3 * i, b, nb, &mj);
        if (m > r.d2) { r.d2 = m; r.i = i; r.j = mj; }
    }
    return r;
}

double brute_nearest(const double *p, const double *b, size_t nb, size_t *j) {
    double m = brute_d2(p, b);
    size_t mj = 0;
    for (size_t k = 1; k < nb; k++) {
        double d = brute_d2(p, b + 3 * k);
        if (d < m) { m = d; mj = k; }
    }
    if (j) *j = mj;
    return m;
}

void brute_transform(const double r[9], const double t[3], const double *in, double *out,
                     size_t n) {
    for (size_t k = 0; k < n; k++) {
        const double *p = in + 3 * k;
        double x = p[0], y = p[1], z = p[2];
        for (int c = 0; c < 3; c++) {
            double v = r[3 * c] * x;
            v = v + r[3 * c + 1] * y;
            v = v + r[3 * c + 2] * z;
            out[3 * k + c] = v + t[c];
        }
    }
}
