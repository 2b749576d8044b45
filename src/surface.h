/*
 * surface.h -- private to the public entry points for meshes (surface.c,
 * m2m.c): a mesh view checked and copied into triangles.
 */
#ifndef HD_SURFACE_H
#define HD_SURFACE_H

#include "hausdorff.h"
#include "mesh/mesh.h"

/* The mesh's triangles (tris[k].index = k, corners widened to double),
 * every index and corner checked: HD_EINVAL (unknown index type, NULL
 * arrays, misaligned, an index beyond the vertices), HD_EEMPTY (no
 * triangles or no vertices), HD_ENONFINITE, HD_ERANGE, HD_ENOMEM, each
 * with a message naming the triangle.  *n_degenerate counts the
 * degenerate ones.  The caller frees *out. */
int hd__mesh_triangles(const hd_mesh_t *M, hd__tri_t **out, size_t *n_degenerate, hd_error_t *err);

#endif
