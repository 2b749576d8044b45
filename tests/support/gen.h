/*
 * gen.h -- seeded point-set generators shared by tests, benchmarks and
 * experiments.  All take an explicit seed; none reads the clock.
 * Every generator fills packed xyz doubles.
 */
#ifndef HD_TEST_GEN_H
#define HD_TEST_GEN_H

#include <hausdorff.h>

#include <stddef.h>
#include <stdint.h>

typedef struct gen_rng { uint64_t s; } gen_rng_t;
void gen_seed(gen_rng_t *r, uint64_t seed);
uint64_t gen_u64(gen_rng_t *r);
double gen_unit(gen_rng_t *r);          /* [0, 1) */
double gen_normal(gen_rng_t *r);        /* standard normal */

/* n points ~ N(mean, sigma^2 I). */
void gen_gauss(gen_rng_t *r, double *xyz, size_t n, const double mean[3], double sigma);
/* n points uniform in the cube [lo, hi]^3. */
void gen_cube(gen_rng_t *r, double *xyz, size_t n, double lo, double hi);
/* Two new arrays of na and nb points uniform in the unit cube (A's first),
 * with their views; the caller frees *a and *b.  Aborts the test program
 * when out of memory. */
void gen_cube_pair(gen_rng_t *r, size_t na, size_t nb, double **a, double **b, hd_points_t *A, hd_points_t *B);
/* Two new arrays by seed, with their views (the caller frees *a and *b):
 * kind seed % 5 (returned) is 0 Gaussians, 1 lattices of 8 per side (many
 * distances tie), 2 lattices of 3 per side (duplicates in both), 3 n
 * points against 1-40, 4 a noisy copy of A in random order.  A has n
 * points.  Aborts the test program when out of memory. */
int gen_mixed_pair(uint64_t seed, size_t n, double **a, double **b, hd_points_t *A, hd_points_t *B);

/* A triangle soup: nv packed xyz vertices and nt index triples, owned by
 * the test (gen_soup_free), seen by the library through gen_soup_view. */
typedef struct {
    double *v;
    size_t nv;
    uint64_t *t;
    size_t nt;
} gen_soup_t;
hd_mesh_t gen_soup_view(const gen_soup_t *s);
void gen_soup_free(gen_soup_t *s);
/* Integer lattice points chosen at random in [0, side)^3 (ties galore). */
void gen_lattice(gen_rng_t *r, double *xyz, size_t n, int side);
/* n points on a random line segment / plane patch through the origin. */
void gen_line(gen_rng_t *r, double *xyz, size_t n);
void gen_plane(gen_rng_t *r, double *xyz, size_t n);
/* n points on a torus (major radius R, minor radius rr), centred at 0. */
void gen_torus(gen_rng_t *r, double *xyz, size_t n, double R, double rr);
/* A closed torus mesh (major radius R, minor radius rr) around the z axis:
 * nu x nv vertices on the smooth torus, each grid quad split into two
 * outward triangles (2 nu nv in all).  New arrays *v (packed xyz, nu nv
 * vertices) and *t (3 indices a triangle); the caller frees them.  Aborts
 * the program when out of memory. */
void gen_torus_mesh(double R, double rr, int nu, int nv, double **v, uint64_t **t);
/* Scale and shift every coordinate: x -> x * scale + offset. */
void gen_affine(double *xyz, size_t n, double scale, double offset);
/* n points uniform by area on the surface of a spur gear centred at 0, axis
 * z, z in [-thickness/2, thickness/2]: `teeth` trapezoidal teeth between
 * root_radius and tip_radius (per tooth: root land 45%, flank 15%, tip land
 * 25%, flank 15% of the angular pitch, radius linear in angle on the flanks),
 * a round bore of bore_radius.  The surface is the two faces, the toothed
 * rim and the bore wall. */
void gen_gear(gen_rng_t *r, double *xyz, size_t n, int teeth, double root_radius,
              double tip_radius, double bore_radius, double thickness);

/* How gen_copy makes B from A: same-order copies of A (n Gaussian points, or
 * lattice points for LATTICE_HALF) with noise of 1e-3 or 1e-12, exact, moved
 * by an exact binary step (every pair at one distance), moved by half a
 * lattice step (ties with the neighbours), with repeated points, with three
 * outliers, with a few partners exchanged, scaled by 1.001, both moved to
 * 1e9, both scaled to 1e-150. */
enum {
    GEN_COPY_NOISE, GEN_COPY_NOISE_TINY, GEN_COPY_EXACT, GEN_COPY_SHIFT, GEN_COPY_LATTICE_HALF,
    GEN_COPY_DUPLICATES, GEN_COPY_OUTLIERS, GEN_COPY_SWAPPED, GEN_COPY_SCALED, GEN_COPY_FAR,
    GEN_COPY_SUBNORMAL_SCALE, GEN_COPY_KINDS
};
extern const char *const gen_copy_name[GEN_COPY_KINDS];
/* A (n points) and B, a copy of A in the same order made by `how`. */
void gen_copy(gen_rng_t *r, int how, double *a, double *b, size_t n);
/* Exchange points x and y of xyz. */
void gen_swap(double *xyz, size_t x, size_t y);

#endif
