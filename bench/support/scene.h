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

#endif
