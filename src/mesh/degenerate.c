/*
 * degenerate.c -- whether a triangle is degenerate: its corners collinear or
 * coincident, so that its convex hull is a segment or a point.
 *
 * That holds exactly when the cross product (b - a) x (c - a) is the zero
 * vector.  Each component is first evaluated in doubles: the differences
 * round once (relative error u = 2^-53), the two products once each and
 * the final difference once, so the computed value is within
 * (|x_j y_k| + |x_k y_j|) * 4u (1 + u)^4 of the exact one, plus at most
 * 3 * 2^-1074 from underflow.  A value beyond 8u times that permanent plus
 * 2^-1060 is certainly nonzero and the triangle spans a plane; otherwise
 * the components are computed exactly from the integers of mesh_int.h.
 */
#include "mesh_int.h"

#include <math.h>

static int filtered_nonzero(const double *a, const double *b, const double *c) {
    double x[3], y[3];
    for (int i = 0; i < 3; i++) x[i] = b[i] - a[i], y[i] = c[i] - a[i];
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        double v = x[j] * y[k] - x[k] * y[j];
        double perm = fabs(x[j] * y[k]) + fabs(x[k] * y[j]);
        if (fabs(v) > perm * 0x1p-50 + 0x1p-1060) return 1;
    }
    return 0;
}

static int exact_zero(const double *a, const double *b, const double *c) {
    const double *in[3] = {a, b, c};
    int e0 = 0, any = 0;
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            if (in[i][k] != 0) {
                int e = hd__ulp_exp(in[i][k]);
                e0 = !any || e < e0 ? e : e0;
                any = 1;
            }
    if (!any) return 1;
    hd__big_t A, B, C, x[3], y[3], s, t, r;
    for (int i = 0; i < 3; i++) {
        hd__big_set_double(&A, a[i], e0);
        hd__big_set_double(&B, b[i], e0);
        hd__big_set_double(&C, c[i], e0);
        hd__big_sub(&x[i], &B, &A);
        hd__big_sub(&y[i], &C, &A);
    }
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        hd__big_mul(&s, &x[j], &y[k]);
        hd__big_mul(&t, &x[k], &y[j]);
        hd__big_sub(&r, &s, &t);
        if (hd__big_sign(&r) != 0) return 0;
    }
    return 1;
}

int hd__tri_degenerate(const double a[3], const double b[3], const double c[3]) {
    return !filtered_nonzero(a, b, c) && exact_zero(a, b, c);
}
