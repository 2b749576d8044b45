/*
 * scene.h -- the benchmark scenes of docs/scale-out.md (scene.c): uniform
 * points, two epochs of a LiDAR-like scene (terrain, a denser city quarter
 * with buildings, a lake with no points; one building demolished and one
 * new in epoch B) and a perturbed copy (B = A + 1 cm noise).
 */
#ifndef HD_BENCH_SCENE_H
#define HD_BENCH_SCENE_H

#include <stddef.h>
#include <stdint.h>

/* n points of A and of B for case `which` ("uniform", "lidar", "copy"),
 * in the strip part of parts along x of the 1 km scene (0 of 1: all of
 * it), from the seed and the stream (a rank's number, say). */
void scene_make(const char *which, int part, int parts, uint64_t seed, uint64_t stream, double *a, double *b,
                size_t n);

/* The cases of issue 41, whose sides differ in size and are generated
 * point by point from their global index (so every K sees the same sets):
 *  - apart:   two uniform cubes of side 100, 1M points each, 300 apart in x;
 *  - near:    200K uniform in a cube of side 100 against 250K in another,
 *             2 apart in x;
 *  - tinyb / tinya: 2M uniform points in a cube of side 1000 against 500
 *             in it, and the other way round;
 *  - change:  two samplings of the 1 km LiDAR scene, 1M each, A with a
 *             tower 60 m tall (30 m x 30 m) in the park that B lacks;
 *  - lattice: the integer lattice 50^3 (125K) against the same lattice
 *             shifted by half a step on every axis (ties everywhere).
 * scene_sized returns 0 for another name; else it sets the sizes. */
int scene_sized(const char *which, uint64_t n[2]);
/* Point g of side s (0: A, 1: B) of a sized case, into p[0..3). */
void scene_point(const char *which, int s, uint64_t g, double *p);

#endif
