/*
 * benchutil.h -- what every benchmark program needs: clocks, a median that
 * does not disturb its input, "is NAME in this comma-separated list", the
 * memory-bandwidth floor, and a model file read into packed doubles.
 */
#ifndef HD_BENCHUTIL_H
#define HD_BENCHUTIL_H

#include <hausdorff.h>

#include <stddef.h>
#include <stdint.h>

/* Wall-clock seconds (monotonic) and this process's CPU seconds. */
double bench_now(void);
/* Minor page faults of this process so far (getrusage): a first write to a
 * fresh page of memory takes one. */
long bench_minor_faults(void);
double bench_cpu_now(void);

/* Median of n > 0 values (the mean of the middle two when n is even); the
 * input is left as it is. */
double bench_median(const double *v, int n);

/* 1 when `name` is an item of the comma-separated `list`, or list is NULL. */
int bench_listed(const char *list, const char *name);

/* The numbers of a comma-separated list ("1e6,250000") into out[0..max),
 * read as doubles and truncated; returns how many, stopping at the first
 * item that is not a number. */
int bench_parse_sizes(const char *s, size_t *out, int max);

/* The memory-bandwidth floor: one streaming pass that reads every coordinate
 * of A (na points) and B (nb points) once, split over `threads` threads (the
 * caller's thread is one of them; below 1 counts as 1), each summing its
 * share of A and then its share of B with four independent accumulators, so
 * that the pass is bound by memory bandwidth rather than by the latency of
 * one chain of additions.  Every benchmark that reports a "memory pass" or a
 * "floor" uses this one definition, at the thread count of the runs it is
 * compared with.  Returns the median wall-clock seconds of 5 passes, or -1
 * when memory for the threads' bookkeeping cannot be had. */
double bench_floor_pass(const double *a, size_t na, const double *b, size_t nb, int threads);

/* The points of the model file at `path` read with hd_read_file as packed
 * float64 xyz triples: its vertices, or with sample > 0 that many points
 * drawn on its faces with `seed`; `threads` parsing threads (0: every core;
 * the points are the same at any count).  Returns a malloc'd array of 3 * *n
 * doubles that the caller owns and frees with free(), or NULL with *err (if
 * not NULL) set to the reader's message or to "out of memory". */
double *bench_read_model(const char *path, size_t sample, uint64_t seed, int threads, size_t *n,
                         hd_error_t *err);

#endif
