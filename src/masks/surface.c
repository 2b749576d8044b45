/*
 * surface.c -- the surface of a binary image, as medpy and MONAI find it:
 * mask ^ binary_erosion(mask, generate_binary_structure(rank, connectivity))
 * with the image's outside counting as background (scipy's border value 0).
 *
 * A foreground voxel is removed by the erosion when some neighbour is
 * background or lies outside the image.  Every neighbourhood holds the face
 * neighbours along its axes, so a voxel on the image's edge along such an
 * axis is on the surface at once; inside, every neighbour is within the
 * image and is read by its index difference.  With no axis in use (a
 * single voxel, or every axis of one voxel with dims 0) the erosion has
 * nothing to look at and the voxel is its own surface.
 */
#include "masks.h"

#include <assert.h>
#include <string.h>

void hd__neighbourhood(hd__neighbourhood_t *nb, const size_t n[3], int dims, int connectivity) {
    assert(connectivity >= 1 && connectivity <= 3 && (dims == 0 || dims == 2 || dims == 3));
    memset(nb, 0, sizeof *nb);
    for (int a = 0; a < 3; a++) {
        nb->used[a] = dims == 3 ? 1 : dims == 2 ? a < 2 : n[a] > 1;
        nb->rank += nb->used[a];
    }
    nb->connectivity = connectivity < nb->rank ? connectivity : nb->rank;
    for (int order = 1; order <= 3 && order <= connectivity; order++)
        for (int o = 0; o < 27; o++) {
            int d[3] = {o % 3 - 1, o / 3 % 3 - 1, o / 9 - 1}, nz = 0, ok = 1;
            for (int a = 0; a < 3; a++) {
                nz += d[a] != 0;
                if (d[a] && !nb->used[a]) ok = 0;
            }
            if (!ok || nz != order) continue;
            assert(nb->n < 26);
            memcpy(nb->d[nb->n], d, sizeof d);
            nb->step[nb->n++] = (ptrdiff_t)d[0] + (ptrdiff_t)d[1] * (ptrdiff_t)n[0] +
                                (ptrdiff_t)d[2] * (ptrdiff_t)(n[0] * n[1]);
        }
}

int hd__on_surface(const uint8_t *fg, const size_t n[3], const hd__neighbourhood_t *nb, size_t i, size_t j,
                   size_t k) {
    if (nb->rank == 0) return 1;
    const size_t at[3] = {i, j, k};
    for (int a = 0; a < 3; a++)
        if (nb->used[a] && (at[a] == 0 || at[a] == n[a] - 1)) return 1;
    size_t v = (k * n[1] + j) * n[0] + i;
    for (int q = 0; q < nb->n; q++)
        if (!fg[(size_t)((ptrdiff_t)v + nb->step[q])]) return 1;
    return 0;
}

double hd__voxel_world(const double m[3][4], double scale, int c, double i, double j, double k) {
    double q = ((m[c][0] * i + m[c][1] * j) + m[c][2] * k) + m[c][3];
    return scale != 1.0 ? q * scale : q;
}

void hd__window_points(const uint8_t *fg, const size_t w[3], const size_t off[3], const double m[3][4], double scale,
                       const hd__neighbourhood_t *nb, double *xyz, size_t *voxel, size_t *count) {
    size_t p = 0;
    for (size_t k = 0; k < w[2]; k++)
        for (size_t j = 0; j < w[1]; j++)
            for (size_t i = 0; i < w[0]; i++) {
                size_t v = (k * w[1] + j) * w[0] + i;
                if (!fg[v] || !hd__on_surface(fg, w, nb, i, j, k)) continue;
                if (xyz) {
                    double gi = (double)(off[0] + i), gj = (double)(off[1] + j), gk = (double)(off[2] + k);
                    for (int a = 0; a < 3; a++) xyz[3 * p + a] = hd__voxel_world(m, scale, a, gi, gj, gk);
                    if (voxel) voxel[p] = v;
                }
                p++;
            }
    *count = p;
}
