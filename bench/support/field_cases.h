/*
 * field_cases.h -- the five cases of issue 39 (per-point work), generated in
 * memory with fixed seeds, shared by percentile_bench and field_bench:
 *   a overlapping  two N(0, 1) Gaussians, N + N points
 *   b disjoint     B's mean 20 sigma from A's along x
 *   c partial      B's mean 2 sigma from A's
 *   d N / N/100    overlapping Gaussians, B a hundredth the size
 *   e shuffled     B = A + N(0, (1e-3)^2) noise, in random order
 */
#ifndef FIELD_CASES_H
#define FIELD_CASES_H

#include <stddef.h>

#define FIELD_CASES 5
extern const char *const field_case_names[FIELD_CASES];

/* Case c (0..4) with N points in A: a and b (room for 3 * n doubles each)
 * filled, *nb set to B's size. */
void field_case(int c, size_t n, double *a, double *b, size_t *nb);

#endif
