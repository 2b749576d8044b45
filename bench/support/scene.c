/*
 * scene.c -- the benchmark scenes (scene.h).
 */
#include "scene.h"

#include <math.h>
#include <string.h>

#include "gen.h"

static double terrain(double x, double y) {
    return 20 * sin(x / 170.0) * cos(y / 130.0) + 5 * sin(x / 37.0 + y / 53.0);
}

static int in_lake(double x, double y) { return (x - 780) * (x - 780) + (y - 300) * (y - 300) < 200.0 * 200.0; }

static int in_city(double x, double y) { return x < 400 && y > 500; }

/* Building height at (x, y) in the given epoch, 0 outside: 20 m squares
 * on a 30 m grid in the city; building (3, 3) demolished in epoch 1, and
 * one new in the park at (600, 700) in epoch 1; epoch 2 is epoch 0 with a
 * tower 60 m tall at (450, 150). */
static double building(double x, double y, int epoch) {
    if (epoch == 2 && fabs(x - 450) < 15 && fabs(y - 150) < 15) return 60;
    if (epoch == 2) epoch = 0;
    if (epoch == 1 && fabs(x - 600) < 10 && fabs(y - 700) < 10) return 15;
    if (!in_city(x, y)) return 0;
    int i = (int)(x / 30), j = (int)((y - 500) / 30);
    double u = x - 30 * i, v = (y - 500) - 30 * j;
    if (u < 5 || u > 25 || v < 5 || v > 25) return 0;
    if (epoch == 1 && i == 3 && j == 3) return 0;
    return 10 + (double)((i * 7 + j * 13) % 5) * 6;
}

/* n points of the scene in x in [xlo, xhi). */
static void lidar(gen_rng_t *g, double *p, size_t n, double xlo, double xhi, int epoch) {
    for (size_t k = 0; k < n;) {
        double x = xlo + (xhi - xlo) * gen_unit(g), y = 1000 * gen_unit(g);
        if (in_lake(x, y)) continue;                            /* water: no returns */
        if (!in_city(x, y) && gen_unit(g) >= 0.25) continue;   /* the city is 4x denser */
        double h = building(x, y, epoch), z = terrain(x, y) + 0.05 * gen_normal(g);
        if (h > 0) {
            if (gen_unit(g) < 0.8) z += h; /* roof */
            else z += h * gen_unit(g);     /* wall-ish returns */
        }
        p[3 * k] = x, p[3 * k + 1] = y, p[3 * k + 2] = z;
        k++;
    }
}

void scene_make(const char *which, int part, int parts, uint64_t seed, uint64_t stream, double *a, double *b,
                size_t n) {
    gen_rng_t g;
    gen_seed(&g, seed * 1000003 + stream);
    double xlo = 1000.0 * part / parts, xhi = 1000.0 * (part + 1) / parts;
    if (strcmp(which, "uniform") == 0) {
        for (size_t k = 0; k < n; k++) {
            a[3 * k] = xlo + (xhi - xlo) * gen_unit(&g), a[3 * k + 1] = 1000 * gen_unit(&g),
            a[3 * k + 2] = 1000 * gen_unit(&g);
            b[3 * k] = xlo + (xhi - xlo) * gen_unit(&g), b[3 * k + 1] = 1000 * gen_unit(&g),
            b[3 * k + 2] = 1000 * gen_unit(&g);
        }
    } else if (strcmp(which, "lidar") == 0) {
        lidar(&g, a, n, xlo, xhi, 0);
        lidar(&g, b, n, xlo, xhi, 1);
    } else { /* copy */
        lidar(&g, a, n, xlo, xhi, 0);
        for (size_t k = 0; k < 3 * n; k++) b[k] = a[k] + 0.01 * gen_normal(&g);
    }
}


int scene_sized(const char *which, uint64_t n[2]) {
    static const struct { const char *name; uint64_t n[2]; } sized[] = {
        {"apart", {1000000, 1000000}}, {"near", {200000, 250000}}, {"tinyb", {2000000, 500}},
        {"tinya", {500, 2000000}},     {"change", {1000000, 1000000}}, {"lattice", {125000, 125000}}};
    for (size_t k = 0; k < sizeof sized / sizeof sized[0]; k++)
        if (strcmp(which, sized[k].name) == 0) {
            n[0] = sized[k].n[0], n[1] = sized[k].n[1];
            return 1;
        }
    return 0;
}

void scene_point(const char *which, int s, uint64_t g, double *p) {
    gen_rng_t r;
    gen_seed(&r, (g * 2 + (uint64_t)s) * 0x9E3779B97F4A7C15ull + 41);
    if (strcmp(which, "lattice") == 0) {
        for (int k = 0; k < 3; k++, g /= 50) p[k] = (double)(g % 50) + 0.5 * s;
        return;
    }
    if (strcmp(which, "change") == 0) {
        lidar(&r, p, 1, 0, 1000, s ? 0 : 2);
        return;
    }
    double side = 100, x0 = 0;
    if (strcmp(which, "apart") == 0) x0 = s ? 400 : 0;
    else if (strcmp(which, "near") == 0) x0 = s ? 102 : 0;
    else side = 1000; /* tinya, tinyb */
    p[0] = x0 + side * gen_unit(&r), p[1] = side * gen_unit(&r), p[2] = side * gen_unit(&r);
}
