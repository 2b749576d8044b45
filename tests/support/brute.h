/*
 * brute.h -- the reference the tests trust: a plain double loop, written
 * independently of the library, with the squared distance evaluated as
 * dx*dx + dy*dy + dz*dz left to right and ties broken by the smallest index.
 */
#ifndef HD_TEST_BRUTE_H
#define HD_TEST_BRUTE_H

#include <stddef.h>

typedef struct brute {
    double d2;  /* squared directed distance */
    size_t i, j;
} brute_t;

brute_t brute_directed(const double *a, size_t na, const double *b, size_t nb);
double brute_d2(const double *p, const double *q);
/* Nearest squared distance from p to the nb points b, *j the smallest index
 * attaining it. */
double brute_nearest(const double *p, const double *b, size_t nb, size_t *j);
/* The documented transform (hausdorff.h, hd_transform_t) applied to n packed
 * points: out = ((r0*x + r1*y) + r2*z) + t0, and so on, in that order. */
void brute_transform(const double r[9], const double t[3], const double *in, double *out,
                     size_t n);

#endif
