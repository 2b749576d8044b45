/*
 * index.h -- private to the public entry points (api.c, index.c,
 * stats.c): the public index's nearest search by a chosen path (index.c),
 * for the tests.
 */
#ifndef HD_INDEX_H
#define HD_INDEX_H

#include "hausdorff.h"

/* How hd__index_nearest_by answers (index.c). */
typedef enum hd__nearest_path {
    /* As hd_index_nearest: the groups of nearest/allnearest.c, or the tree
     * for sets beyond that file's limit or without memory for the groups. */
    HD__NEAREST_AUTO = 0,
    /* For the tests: one search of the index's tree per query, the path
     * that only those sets take otherwise. */
    HD__NEAREST_TREE = 1
} hd__nearest_path_t;

/* hd_index_nearest by the given path. */
int hd__index_nearest_by(const hd_index_t *idx, const hd_points_t *Q, const hd_transform_t *T,
                         const hd_options_t *opt, double *dist, size_t *nearest,
                         hd__nearest_path_t path, hd_error_t *err);

#endif /* HD_INDEX_H */
