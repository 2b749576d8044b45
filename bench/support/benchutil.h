/*
 * benchutil.h -- what every benchmark program needs: clocks, a median that
 * does not disturb its input, and "is NAME in this comma-separated list".
 */
#ifndef HD_BENCHUTIL_H
#define HD_BENCHUTIL_H

/* Wall-clock seconds (monotonic) and this process's CPU seconds. */
double bench_now(void);
double bench_cpu_now(void);

/* Median of n > 0 values (the mean of the middle two when n is even); the
 * input is left as it is. */
double bench_median(const double *v, int n);

/* 1 when `name` is an item of the comma-separated `list`, or list is NULL. */
int bench_listed(const char *list, const char *name);

#endif
