/*
 * mesh.c -- the faces of a mesh and points sampled uniformly on its surface.
 *
 * By default a mesh is read as its vertex set, as the paper compares point
 * sets.  With HD_MESH_SAMPLE the reader also collects the faces, each
 * polygon split into a fan of triangles (v0, v[k], v[k+1]), and this file
 * draws n points uniformly by area: a triangle is chosen with probability
 * proportional to its area (a binary search in the running sum of areas,
 * computed in double in face order), then a point uniformly inside it from
 * two uniform numbers u, v by the square-root map
 *     p = (1 - sqrt(u)) A + sqrt(u) (1 - v) B + sqrt(u) v C
 * (Osada et al., "Shape distributions", 2002, eq. 1).  Every random number
 * comes from hd__rng seeded with the caller's seed, in a fixed order, so the
 * same file and seed give the same points on every machine with IEEE
 * doubles.  Degenerate (zero-area) triangles are never chosen.
 */
#include "io.h"

#include <math.h>
#include <stdlib.h>

void hd__tris_init(hd__tris_t *t) {
    t->v = NULL;
    t->count = t->cap = 0;
}

void hd__tris_free(hd__tris_t *t) {
    free(t->v);
    hd__tris_init(t);
}

static int tris_reserve(hd__tris_t *t, size_t more) {
    if (more <= t->cap - t->count) return HD_OK;
    size_t want = t->count + more;
    if (want < t->count) return HD_EOVERFLOW;
    size_t cap = t->cap < SIZE_MAX / 4 ? t->cap * 2 : want;
    if (cap < want) cap = want;
    if (cap < 64) cap = 64;
    if (hd__mul_overflows(cap, 3)) return HD_EOVERFLOW;
    uint64_t *v = hd__realloc_array(t->v, 3 * cap, sizeof *v);
    if (!v) return HD_ENOMEM;
    t->v = v;
    t->cap = cap;
    return HD_OK;
}

int hd__tris_add(hd__tris_t *t, const uint64_t *v, size_t n) {
    if (n < 3) return HD_OK;
    int rc = tris_reserve(t, n - 2);
    if (rc) return rc;
    for (size_t k = 1; k + 1 < n; k++) {
        uint64_t *o = t->v + 3 * t->count++;
        o[0] = v[0];
        o[1] = v[k];
        o[2] = v[k + 1];
    }
    return HD_OK;
}

int hd__tris_append(hd__tris_t *t, hd__tris_t *src) {
    if (!src->count) return HD_OK;
    if (!t->count) {
        hd__tris_free(t);
        *t = *src;
        hd__tris_init(src);
        return HD_OK;
    }
    int rc = tris_reserve(t, src->count);
    if (rc) return rc;
    memcpy(t->v + 3 * t->count, src->v, 3 * src->count * sizeof *src->v);
    t->count += src->count;
    hd__tris_free(src);
    return HD_OK;
}

static double area2(const double *a, const double *b, const double *c) {
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double x = u[1] * v[2] - u[2] * v[1];
    double y = u[2] * v[0] - u[0] * v[2];
    double z = u[0] * v[1] - u[1] * v[0];
    return sqrt(x * x + y * y + z * z);
}

/* The same area scaled by 2^-s (s even), for meshes whose areas overflow
 * in area2: coordinates are accepted up to 1e153, so an edge can reach
 * 2e153 and a cross product component 8e306, whose square is infinite.
 * Scaling the edges by 2^(-s/2) is exact (a power of two, no underflow at
 * those magnitudes), so the ratios of the areas, which are all sampling
 * uses, are those of the unscaled areas up to rounding. */
static double area2_scaled(const double *a, const double *b, const double *c, int s) {
    double k = ldexp(1.0, -s / 2);
    double u[3] = {(b[0] - a[0]) * k, (b[1] - a[1]) * k, (b[2] - a[2]) * k};
    double v[3] = {(c[0] - a[0]) * k, (c[1] - a[1]) * k, (c[2] - a[2]) * k};
    double x = u[1] * v[2] - u[2] * v[1];
    double y = u[2] * v[0] - u[0] * v[2];
    double z = u[0] * v[1] - u[1] * v[0];
    return sqrt(x * x + y * y + z * z);
}

int hd__mesh_sample(const double *xyz, size_t nv, const hd__tris_t *t,
                    size_t n, uint64_t seed, hd__sink_t *out,
                    const char *name, hd_error_t *err) {
    if (t->count == 0)
        return hd__err(err, HD_EFORMAT, "%s: has no faces to sample from (read its vertices instead)", name);
    for (size_t k = 0; k < 3 * t->count; k++)
        if (t->v[k] >= nv)
            return hd__err(err, HD_EFORMAT, "%s: face %zu uses vertex %llu, but there are %zu vertices",
                           name, k / 3, (unsigned long long)t->v[k], nv);
    double *cum = hd__malloc_array(t->count, sizeof *cum);
    if (!cum) return hd__err(err, HD_ENOMEM, "%s: out of memory for %zu triangle areas", name, t->count);
    double total = 0.0;
    for (size_t k = 0; k < t->count; k++) {
        const uint64_t *f = t->v + 3 * k;
        total += area2(xyz + 3 * f[0], xyz + 3 * f[1], xyz + 3 * f[2]);
        cum[k] = total;
    }
    if (!isfinite(total)) {
        /* Areas too large for double: the same sums at 2^-600 scale.  The
         * edges (< 2^512 after the subtraction of coordinates below 1e153)
         * become < 2^212 and their cross products < 2^426: finite.  Only
         * such meshes take this path, so every other sample is unchanged. */
        total = 0.0;
        for (size_t k = 0; k < t->count; k++) {
            const uint64_t *f = t->v + 3 * k;
            total += area2_scaled(xyz + 3 * f[0], xyz + 3 * f[1], xyz + 3 * f[2], 600);
            cum[k] = total;
        }
    }
    if (!(total > 0) || !isfinite(total)) {
        free(cum);
        return hd__err(err, HD_EFORMAT, "%s: the faces have no area to sample from", name);
    }
    int rc = hd__sink_reserve(out, n);
    if (rc) {
        free(cum);
        return hd__err(err, rc, "%s: cannot allocate %zu sample points", name, n);
    }
    hd__rng_t rng;
    hd__rng_seed(&rng, seed);
    for (size_t s = 0; s < n; s++) {
        double x = hd__rng_unit(&rng) * total;
        size_t lo = 0, hi = t->count - 1; /* first k with cum[k] > x */
        while (lo < hi) {
            size_t mid = lo + (hi - lo) / 2;
            if (cum[mid] > x) hi = mid;
            else lo = mid + 1;
        }
        const uint64_t *f = t->v + 3 * lo;
        const double *a = xyz + 3 * f[0], *b = xyz + 3 * f[1], *c = xyz + 3 * f[2];
        double su = sqrt(hd__rng_unit(&rng)), v = hd__rng_unit(&rng);
        double wa = 1.0 - su, wb = su * (1.0 - v), wc = su * v;
        double p[3];
        for (int d = 0; d < 3; d++) p[d] = wa * a[d] + wb * b[d] + wc * c[d];
        if ((rc = hd__sink_push(out, p))) {
            free(cum);
            return hd__err(err, rc, "%s: sampled point %zu: %s", name, s, hd__point_problem(rc));
        }
    }
    free(cum);
    return HD_OK;
}
