/*
 * gen.c -- seeded generators (see gen.h).  splitmix64 drives everything, so
 * a seed fully determines a point set on every machine.
 */
#include "gen.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The seed is hashed into the starting state, not used as a position: with
 * s = seed * increment, seeds 1 and 2 were the same stream one draw apart, so
 * clouds made from consecutive seeds were correlated. */
void gen_seed(gen_rng_t *r, uint64_t seed) {
    r->s = seed;
    r->s = gen_u64(r) ^ 0x2545f4914f6cdd1dULL;
}

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

void gen_cube_pair(gen_rng_t *r, size_t na, size_t nb, double **a, double **b, hd_points_t *A, hd_points_t *B) {
    *a = malloc(24 * (na ? na : 1));
    *b = malloc(24 * (nb ? nb : 1));
    if (!*a || !*b) {
        fprintf(stderr, "gen_cube_pair: out of memory for %zu + %zu points\n", na, nb);
        abort();
    }
    gen_cube(r, *a, na, 0, 1);
    gen_cube(r, *b, nb, 0, 1);
    *A = hd_points_f64(*a, na);
    *B = hd_points_f64(*b, nb);
}

int gen_mixed_pair(uint64_t seed, size_t n, double **a, double **b, hd_points_t *A, hd_points_t *B) {
    int kind = (int)(seed % 5);
    gen_rng_t g;
    gen_seed(&g, seed);
    size_t na = n, nb = kind == 3 ? 1 + gen_u64(&g) % 40 : kind == 4 ? n : 1 + n / 2 + gen_u64(&g) % n;
    *a = malloc(24 * na);
    *b = malloc(24 * nb);
    if (!*a || !*b) {
        fprintf(stderr, "gen_mixed_pair: out of memory for %zu + %zu points\n", na, nb);
        abort();
    }
    double m0[3] = {0, 0, 0}, m1[3] = {0.5, 0, 0};
    if (kind == 0 || kind == 3) {
        gen_gauss(&g, *a, na, m0, 1.0);
        gen_gauss(&g, *b, nb, m1, 1.0);
    } else if (kind == 1 || kind == 2) {
        gen_lattice(&g, *a, na, kind == 1 ? 8 : 3);
        gen_lattice(&g, *b, nb, kind == 1 ? 8 : 3);
        gen_affine(*b, nb, 1.0, 0.5);
    } else {
        gen_gauss(&g, *a, na, m0, 1.0);
        for (size_t k = 0; k < 3 * na; k++) (*b)[k] = (*a)[k] + 1e-3 * gen_normal(&g);
        for (size_t k = nb; k > 1; k--) gen_swap(*b, k - 1, gen_u64(&g) % k);
    }
    *A = hd_points_f64(*a, na);
    *B = hd_points_f64(*b, nb);
    return kind;
}

hd_mesh_t gen_soup_view(const gen_soup_t *s) {
    hd_mesh_t m = {hd_points_f64(s->v, s->nv), s->t, s->nt, HD_INDEX_U64};
    return m;
}

void gen_soup_free(gen_soup_t *s) {
    free(s->v);
    free(s->t);
    s->v = NULL;
    s->t = NULL;
    s->nv = s->nt = 0;
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

void gen_torus_mesh(double R, double rr, int nu, int nv, double **v, uint64_t **t) {
    size_t n = (size_t)nu * (size_t)nv;
    *v = malloc(3 * n * sizeof **v);
    *t = malloc(6 * n * sizeof **t);
    if (!*v || !*t) {
        fprintf(stderr, "gen_torus_mesh: out of memory\n");
        abort();
    }
    for (int i = 0; i < nu; i++)
        for (int j = 0; j < nv; j++) {
            double a = 6.283185307179586 * i / nu, b = 6.283185307179586 * j / nv, *x = *v + 3 * (i * (size_t)nv + j);
            x[0] = (R + rr * cos(b)) * cos(a), x[1] = (R + rr * cos(b)) * sin(a), x[2] = rr * sin(b);
        }
    uint64_t *f = *t;
    for (int i = 0; i < nu; i++)
        for (int j = 0; j < nv; j++) {
            uint64_t a = (uint64_t)i * nv + j, b = (uint64_t)((i + 1) % nu) * nv + j,
                     c = (uint64_t)((i + 1) % nu) * nv + (j + 1) % nv, d = (uint64_t)i * nv + (j + 1) % nv;
            f[0] = a, f[1] = b, f[2] = c, f[3] = a, f[4] = c, f[5] = d;
            f += 6;
        }
}

void gen_affine(double *xyz, size_t n, double scale, double offset) {
    for (size_t k = 0; k < 3 * n; k++) xyz[k] = xyz[k] * scale + offset;
}

/* The gear's outer radius at polar angle phi (see gen.h). */
static double gear_radius(double phi, int teeth, double rr, double rt) {
    double u = phi * (double)teeth / 6.283185307179586;
    u -= floor(u);
    if (u < 0.45) return rr;
    if (u < 0.60) return rr + (rt - rr) * (u - 0.45) / 0.15;
    if (u < 0.85) return rt;
    return rt - (rt - rr) * (u - 0.85) / 0.15;
}

/* The teeth are identical, so one tooth's profile is tabulated as a polyline
 * of GEAR_STEPS segments (cumulative arc length in cum[]); the rim is
 * sampled by picking a tooth, then an arc length on that polyline (binary
 * search), then a height.  Faces are sampled by rejection in the tip disc.
 * The three parts get points in proportion to their areas (the face area is
 * the polyline polygon's, by the shoelace formula, minus the bore). */
#define GEAR_STEPS 400
void gen_gear(gen_rng_t *r, double *xyz, size_t n, int teeth, double rr, double rt,
              double rb, double thickness) {
    const double two_pi = 6.283185307179586, pitch = two_pi / (double)teeth;
    double tx[GEAR_STEPS + 1], ty[GEAR_STEPS + 1], cum[GEAR_STEPS + 1];
    double twice_area = 0.0;
    cum[0] = 0.0;
    for (int k = 0; k <= GEAR_STEPS; k++) {
        double phi = pitch * (double)k / GEAR_STEPS, rad = gear_radius(phi, teeth, rr, rt);
        if (k == GEAR_STEPS) rad = gear_radius(0.0, teeth, rr, rt); /* closes the period */
        tx[k] = rad * cos(phi), ty[k] = rad * sin(phi);
        if (k > 0) {
            cum[k] = cum[k - 1] + hypot(tx[k] - tx[k - 1], ty[k] - ty[k - 1]);
            twice_area += tx[k - 1] * ty[k] - tx[k] * ty[k - 1];
        }
    }
    double perimeter = (double)teeth * cum[GEAR_STEPS];
    double face = 0.5 * (double)teeth * twice_area - 0.5 * two_pi * rb * rb;
    double rim = perimeter * thickness, bore = two_pi * rb * thickness;
    double total = 2.0 * face + rim + bore;
    for (size_t k = 0; k < n; k++) {
        double *p = xyz + 3 * k, pick = total * gen_unit(r);
        if (pick < 2.0 * face) { /* a face: top or bottom */
            for (;;) {
                double x = rt * (2.0 * gen_unit(r) - 1.0), y = rt * (2.0 * gen_unit(r) - 1.0);
                double rho = hypot(x, y), phi = atan2(y, x);
                if (phi < 0) phi += two_pi;
                if (rho >= rb && rho <= gear_radius(phi, teeth, rr, rt)) {
                    p[0] = x, p[1] = y;
                    break;
                }
            }
            p[2] = (pick < face ? 0.5 : -0.5) * thickness;
        } else if (pick < 2.0 * face + rim) { /* the rim: a tooth, then arc length */
            int tooth = (int)((double)teeth * gen_unit(r));
            double s = cum[GEAR_STEPS] * gen_unit(r);
            int lo = 0, hi = GEAR_STEPS; /* the segment [lo, lo + 1] holding s */
            while (hi - lo > 1) {
                int mid = (lo + hi) / 2;
                if (cum[mid] <= s) lo = mid;
                else hi = mid;
            }
            double len = cum[lo + 1] - cum[lo], t = len > 0 ? (s - cum[lo]) / len : 0.0;
            double x = tx[lo] + t * (tx[lo + 1] - tx[lo]), y = ty[lo] + t * (ty[lo + 1] - ty[lo]);
            double c = cos(pitch * tooth), sn = sin(pitch * tooth);
            p[0] = c * x - sn * y, p[1] = sn * x + c * y;
            p[2] = thickness * (gen_unit(r) - 0.5);
        } else { /* the bore wall */
            double phi = two_pi * gen_unit(r);
            p[0] = rb * cos(phi), p[1] = rb * sin(phi);
            p[2] = thickness * (gen_unit(r) - 0.5);
        }
    }
}

const char *const gen_copy_name[GEN_COPY_KINDS] = {
    "noise", "tiny-noise", "exact", "shift", "lattice-half-step", "duplicates", "outliers",
    "swapped", "scaled", "far-offset", "1e-150-scale",
};

void gen_swap(double *xyz, size_t x, size_t y) {
    double t[3];
    memcpy(t, xyz + 3 * x, 24);
    memcpy(xyz + 3 * x, xyz + 3 * y, 24);
    memcpy(xyz + 3 * y, t, 24);
}

void gen_copy(gen_rng_t *r, int how, double *a, double *b, size_t n) {
    double m0[3] = {0, 0, 0};
    if (how == GEN_COPY_LATTICE_HALF) gen_lattice(r, a, n, 2 + (int)(gen_u64(r) % 20));
    else gen_gauss(r, a, n, m0, 1.0);
    if (how == GEN_COPY_DUPLICATES) /* every point repeated a few times */
        for (size_t k = 0; k < n; k++)
            if (gen_u64(r) % 3 == 0) memcpy(a + 3 * k, a + 3 * (gen_u64(r) % n), 24);
    double sigma = how == GEN_COPY_NOISE_TINY ? 1e-12 : 1e-3;
    for (size_t k = 0; k < 3 * n; k++) {
        switch (how) {
        case GEN_COPY_EXACT: b[k] = a[k]; break;
        /* Moves by exact binary fractions: every pair at the same distance. */
        case GEN_COPY_SHIFT: b[k] = a[k] + (k % 3 == 0 ? 0x1p-10 : 0.0); break;
        case GEN_COPY_LATTICE_HALF: b[k] = a[k] + (k % 3 == 1 ? 0.5 : 0.0); break;
        case GEN_COPY_SCALED: b[k] = a[k] * 1.001; break;
        default: b[k] = a[k] + sigma * gen_normal(r);
        }
    }
    if (how == GEN_COPY_OUTLIERS)
        for (int k = 0; k < 3; k++) b[3 * (gen_u64(r) % n) + (size_t)k] += 0.5;
    if (how == GEN_COPY_SWAPPED) /* a few partners exchanged with other points */
        for (size_t k = 0; k < 1 + n / 200; k++) {
            size_t x = gen_u64(r) % n;
            gen_swap(b, x, gen_u64(r) % n);
        }
    if (how == GEN_COPY_FAR) {
        gen_affine(a, n, 1.0, 1e9);
        gen_affine(b, n, 1.0, 1e9);
    }
    if (how == GEN_COPY_SUBNORMAL_SCALE) {
        gen_affine(a, n, 1e-150, 0.0);
        gen_affine(b, n, 1e-150, 0.0);
    }
}
