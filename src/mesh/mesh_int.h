/*
 * mesh_int.h -- for src/mesh/'s own files: the exact integers of the
 * kernel's exact path (exact.c) and what tri.c asks of it.
 *
 * A double is m * 2^e with m an integer of at most 53 bits.  Given the
 * smallest such e over every coordinate of a call (e0), every coordinate is
 * the integer m * 2^(e - e0) times 2^e0, and the squared distance to a
 * triangle is 2^(2 e0) N / M with N and M polynomials of degree 6 and 4 in
 * those integers (mesh.h, tri.c).  Within the domain (|x| <= 2^511, so
 * e - e0 + 53 <= 511 + 1074) a coordinate takes at most 1585 bits, a
 * difference 1586, and the largest number the exact path forms (a degree-6
 * product, or a comparison of the two sides of a midpoint test, shifted to a
 * common exponent: both sides within a factor 4 of N's bound) stays below
 * 2^9530, which HD__BIG_LIMBS limbs of 32 bits hold with room.
 */
#ifndef HD_MESH_INT_H
#define HD_MESH_INT_H

#include <stdint.h>

#include "mesh/mesh.h"

#define HD__BIG_LIMBS 304

/* Sign and magnitude; w[0] is the least significant limb; n limbs are used
 * and w[n - 1] != 0 (zero: n == 0 and neg == 0). */
typedef struct hd__big {
    int n, neg;
    uint32_t w[HD__BIG_LIMBS];
} hd__big_t;

void hd__big_set_u64(hd__big_t *r, uint64_t v);
/* r = x / 2^e0 for a double x that is a multiple of 2^e0. */
void hd__big_set_double(hd__big_t *r, double x, int e0);
void hd__big_add(hd__big_t *r, const hd__big_t *a, const hd__big_t *b);
void hd__big_sub(hd__big_t *r, const hd__big_t *a, const hd__big_t *b);
/* r must not be a or b. */
void hd__big_mul(hd__big_t *r, const hd__big_t *a, const hd__big_t *b);
void hd__big_shl(hd__big_t *r, const hd__big_t *a, int bits);
int hd__big_cmp(const hd__big_t *a, const hd__big_t *b);
int hd__big_sign(const hd__big_t *a);
/* a ~= f * 2^k with f in [0.5, 1) (0 for zero), f from a's top 64 bits. */
double hd__big_frexp(const hd__big_t *a, int *k);

/* The kernel's step 1 (tri.c): *use = the coordinates, or their copies in
 * out scaled by 2^s to put the largest magnitude in [1, 2) unless it
 * already lies in [2^-8, 2); -1 outside the domain, 0 when a nonzero
 * coordinate is or would become subnormal. */
int hd__tri_scale(const double *const in[4], double out[4][3], const double **use, int *s);

/* hd__tri_nearest with Dekker's TwoProd (fma 0) or the CPU's fused
 * multiply-add where it has one (fma 1, what hd__tri_nearest uses): the
 * same bits either way, which tests check. */
int hd__tri_nearest_variant(const double p[3], const double a[3], const double b[3],
                            const double c[3], hd__tri_near_t *out, int fma);

/* The exponent of the last bit of x's significand, with trailing zeros
 * dropped: x is a multiple of 2^hd__ulp_exp(x). x != 0, finite. */
int hd__ulp_exp(double x);

#endif
