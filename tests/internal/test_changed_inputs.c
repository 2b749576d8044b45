/*
 * test_changed_inputs.c -- hausdorff.h forbids changing the points during a
 * call, but a Python thread can write NaN into an input array while the
 * engine runs.  The answer is then meaningless; what must hold is that the
 * library neither reads out of bounds nor loops for ever.  These white-box
 * tests hand the algorithms points with NaN that validation never saw, as
 * such a write would.  Once the engine crashed in hd__find (a NaN minimum
 * found nowhere, the scan ran off the array) and INC refined one entry for
 * ever (a NaN box never compared >= its candidates).
 */
#include "check.h"
#include "gen.h"
#include "classic/classic.h"
#include "engine/tree.h" /* white-box: the bucket kernels */

#include <math.h>
#include <stdlib.h>

TEST(find_of_a_nan_minimum_stays_in_the_bucket) {
    double c[HD__BUCKET];
    for (int k = 0; k < HD__BUCKET; k++) c[k] = NAN;
    CHECK_EQ(hd__find(c, hd__min32(c)), 0);
    c[7] = 1.0;
    CHECK_EQ(hd__find(c, 1.0), 7);
}

static hd__box_t box_of(const double *p, size_t n) {
    hd__box_t b = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            if (p[3 * i + k] < b.lo[k]) b.lo[k] = p[3 * i + k];
            if (p[3 * i + k] > b.hi[k]) b.hi[k] = p[3 * i + k];
        }
    return b;
}

/* Random points, their box taken before `bad` of them become NaN. */
static double *poisoned(size_t n, uint64_t seed, size_t bad, hd__box_t *box) {
    double *p = malloc(3 * n * sizeof *p);
    gen_rng_t r;
    gen_seed(&r, seed);
    gen_cube(&r, p, n, 0.0, 1.0);
    *box = box_of(p, n);
    for (size_t k = 0; k < bad; k++) p[3 * ((k * 7919) % n) + k % 3] = NAN;
    return p;
}

TEST(inc_returns_when_points_turn_nan_after_validation) {
    size_t n = 3000;
    for (uint64_t seed = 1; seed <= 4; seed++) {
        CONTEXT("seed %llu", (unsigned long long)seed);
        hd__box_t ba, bb;
        double *a = poisoned(n, seed, 5, &ba), *b = poisoned(n, seed + 100, 5, &bb);
        hd_options_t o;
        hd_options_init(&o);
        o.threads = 1;
        hd__job_t job = {a, n, b, n, ba, bb, &o, 1};
        hd_result_t r;
        hd_error_t e;
        (void)hd__inc(&job, &r, &e); /* any answer; it must come back */
        free(a);
        free(b);
    }
}

TEST(engine_stays_in_bounds_when_points_turn_nan_after_validation) {
    size_t n = 20000;
    for (uint64_t seed = 1; seed <= 4; seed++) {
        for (int threads = 1; threads <= 2; threads++) {
            CONTEXT("seed %llu, %d threads", (unsigned long long)seed, threads);
            hd__box_t ba, bb;
            double *a = poisoned(n, seed, 50, &ba), *b = poisoned(n, seed + 100, 50, &bb);
            hd_points_t A = hd_points_f64(a, n), B = hd_points_f64(b, n);
            hd_options_t o;
            hd_options_init(&o);
            o.threads = threads;
            hd_result_t r;
            hd_symmetric_t s;
            hd_error_t e;
            (void)hd__engine_directed(&A, &B, &ba, &bb, &o, &r, &e);
            (void)hd__engine_hausdorff(&A, &B, &ba, &bb, &o, &s, &e);
            free(a);
            free(b);
        }
    }
}
