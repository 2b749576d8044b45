/*
 * gen.c -- seeded generators (see gen.h).  splitmix64 drives everything, so
 * a seed fully determines a point set on every machine.
 */
#include "gen.h"

#include <math.h>

void gen_seed(gen_rng_t *r, uint64_t seed) { r->s = seed * 0x9e3779b97f4a7c15ULL + 1; }

uint64_t gen_u64(gen_rng_t *r) {
    uint64_t z = (r->s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

double gen_unit(gen_rng_t *r) { return (double)(gen_u64(r) >> 11) * 0x1.0p-53; }

double gen_normal(gen_rng_t *r) {
    double u = gen_unit(r), v = gen_unit(r);
    if (u < 1e-300) u = 1e-300;
    return sqrt(-2.0 * log(u)) * cos(6.283185307179586 * v);
}

void gen_gauss(gen_rng_t *r, double *xyz, size_t n, const double mean[3], double sigma) {
    for (size_t k = 0; k < n; k++)
        for (int c = 0; c < 3; c++) xyz[3 * k + c] = mean[c] + sigma * gen_normal(r);
}

void gen_cube(gen_rng_t *r, double *xyz, size_t n, double lo, double hi) {
    for (size_t k = 0; k < 3 * n; k++) xyz[k] = lo + (hi - lo) * gen_unit(r);
}

void gen_lattice(gen_rng_t *r, double *xyz, size_t n, int side) {
    for (size_t k = 0; k < 3 * n; k++) xyz[k] = (double)(gen_u64(r) % (uint64_t)side);
}

void gen_line(gen_rng_t *r, double *xyz, size_t n) {
    double d[3] = {gen_normal(r), gen_normal(r), gen_normal(r)};
    for (size_t k = 0; k < n; k++) {
        double t = 10.0 * gen_unit(r) - 5.0;
        for (int c = 0; c < 3; c++) xyz[3 * k + c] = t * d[c];
    }
}

void gen_plane(gen_rng_t *r, double *xyz, size_t n) {
    double u[3] = {gen_normal(r), gen_normal(r), gen_normal(r)};
    double v[3] = {gen_normal(r), gen_normal(r), gen_normal(r)};
    for (size_t k = 0; k < n; k++) {
        double s = 2.0 * gen_unit(r) - 1.0, t = 2.0 * gen_unit(r) - 1.0;
        for (int c = 0; c < 3; c++) xyz[3 * k + c] = s * u[c] + t * v[c];
    }
}

void gen_torus(gen_rng_t *r, double *xyz, size_t n, double R, double rr) {
    for (size_t k = 0; k < n; k++) {
        double a = 6.283185307179586 * gen_unit(r), b = 6.283185307179586 * gen_unit(r);
        xyz[3 * k + 0] = (R + rr * cos(b)) * cos(a);
        xyz[3 * k + 1] = (R + rr * cos(b)) * sin(a);
        xyz[3 * k + 2] = rr * sin(b);
    }
}

void gen_affine(double *xyz, size_t n, double scale, double offset) {
    for (size_t k = 0; k < 3 * n; k++) xyz[k] = xyz[k] * scale + offset;
}
