/*
 * views.c -- the caller's points of a set as one view in global index
 * order, without a copy when they are one part (course.h's
 * hd__mpi_views_t): what the engine runs on where nothing is partitioned,
 * on one rank (mpi.c, distances.c) and beside a replicated tiny side
 * (tiny.c).
 *
 * Invariant: position m of a set's view is the rank's m-th point of that
 * set in index order (its parts sorted by offset), so
 * hd__mpi_ranges_global(rg, s, rank, m) is its global index, and a
 * smallest position on ties is the smallest global index among the rank's
 * points.
 */
#include "mpi/course.h"

#include <stdlib.h>

/* A set given as one part (or one nonempty part) is the caller's view, of
 * any layout; else its parts are packed into one array in index order (24
 * bytes a point). */
int hd__mpi_views(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, hd__mpi_views_t *vw) {
    memset(vw, 0, sizeof *vw);
    for (int s = 0; s < 2; s++) {
        size_t nonempty = 0, last = 0;
        for (size_t p = 0; p < in->nparts[s]; p++)
            if (in->parts[s][p].points.count) nonempty++, last = p;
        if (nonempty == 1) {
            vw->v[s] = in->parts[s][last].points;
            continue;
        }
        vw->own[s] = hd__mpi_alloc(c, in->n[s], 3 * sizeof(double));
        vw->order[s] = hd__mpi_alloc(c, in->nparts[s], sizeof *vw->order[s]);
        if (!vw->own[s] || !vw->order[s]) return hd__mpi_nomem(c, "the parts", in->n[s]);
        const hd_mpi_part_t **order = vw->order[s];
        for (size_t p = 0; p < in->nparts[s]; p++) order[p] = &in->parts[s][p];
        qsort(order, in->nparts[s], sizeof *order, hd__mpi_by_offset);
        size_t t = 0;
        for (size_t p = 0; p < in->nparts[s]; p++)
            for (size_t k = 0; k < order[p]->points.count; k++)
                hd__mpi_get_point(&order[p]->points, k, vw->own[s] + 3 * t++);
        vw->v[s] = hd_points_f64(vw->own[s], in->n[s]);
    }
    return HD_OK;
}

void hd__mpi_views_free(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, hd__mpi_views_t *vw) {
    for (int s = 0; s < 2; s++) {
        hd__mpi_free(c, vw->own[s], in->n[s], 3 * sizeof(double));
        hd__mpi_free(c, vw->order[s], in->nparts[s], sizeof *vw->order[s]);
        vw->own[s] = NULL, vw->order[s] = NULL;
    }
}

