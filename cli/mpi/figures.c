/*
 * figures.c -- hausdorff-mpi's --percentile, --mean, --chamfer, --histogram
 * and --histogram-png: hausdorff's figures (cli/analysis.c's
 * analysis_figures, the very code hausdorff runs) over operations that
 * work across the ranks (hausdorff_mpi.h: hd_mpi_summarize,
 * hd_mpi_percentile_of, hd_mpi_histogram), each rank passing its own
 * per-point distances (hd_mpi_distances).  Each of those returns, on every
 * rank, the single process's result on all the distances, to the bit, so
 * the report printed from them (analysis_print, analysis_json) is
 * hausdorff's, character for character.  The histogram picture is drawn by
 * rank 0 alone, from those figures.
 *
 * Failures: the library's calls agree on their status; what this file does
 * on one rank only (allocating the histograms, drawing the picture) is
 * agreed with mpi_agree before the next collective, so no rank waits for
 * one that gave up.
 */
#include <hausdorff_mpi.h>

#include "analysis.h"
#include "mpi_cli.h"

#include <stdlib.h>

static int summarize_all(const double *d_ab, size_t n_a, const double *d_ba, size_t n_b, hd_summary_t *out,
                         hd_error_t *err) {
    return hd_mpi_summarize(MPI_COMM_WORLD, d_ab, n_a, d_ba, n_b, out, err);
}

static int percentile_all(const double *d_ab, size_t n_a, const double *d_ba, size_t n_b, double p,
                          hd_percentile_t *out, hd_error_t *err) {
    return hd_mpi_percentile_of(MPI_COMM_WORLD, d_ab, n_a, d_ba, n_b, p, out, err);
}

static int histogram_all(const double *values, size_t n, double lo, double hi, size_t bins, uint64_t *counts,
                         hd_error_t *err) {
    return hd_mpi_histogram(MPI_COMM_WORLD, values, n, lo, hi, bins, counts, err);
}

int mpi_figures(const analysis_args_t *an, const double *d_ab, size_t n_a, const double *d_ba, size_t n_b,
                analysis_result_t *r, hd_error_t *err) {
    static const analysis_ops_t all_ranks = {summarize_all, percentile_all, histogram_all};
    int rc = HD_OK, rank;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    if (an->histogram || an->histogram_png) { /* allocated here, agreed: analysis_figures would on one rank */
        r->hist_ab = calloc(an->bins, sizeof *r->hist_ab);
        r->hist_ba = r->directed ? NULL : calloc(an->bins, sizeof *r->hist_ba);
        if (!r->hist_ab || (!r->directed && !r->hist_ba)) {
            snprintf(err->message, sizeof err->message, "out of memory for %zu histogram bins", an->bins);
            rc = err->code = HD_ENOMEM;
        }
    }
    if ((rc = mpi_agree(rc, err)) != HD_OK) return rc;
    if ((rc = analysis_figures(an, &all_ranks, d_ab, n_a, d_ba, n_b, r, err)) != HD_OK) return rc;
    render_notes_t notes = analysis_notes(an, r);
    if (an->histogram_png && rank == 0)
        rc = render_histogram(an->histogram_png, r, &notes, an->bins, r->hist_markers, &r->n_hist_markers, err);
    return mpi_agree(rc, err);
}

/* ---- --render ----------------------------------------------------------------- */

/* The layers' merges as MPI operations (commutative: each is the minimum
 * of a total order, so any order of merging gives the same pixels). */
static void near_op(void *in, void *inout, int *len, MPI_Datatype *type) {
    (void)type;
    render_near_merge(inout, in, (size_t)*len);
}

static void far_op(void *in, void *inout, int *len, MPI_Datatype *type) {
    (void)type;
    render_far_merge(inout, in, (size_t)*len);
}

/* The ranks' layers merged into rank 0's (MPI_Reduce: the other ranks'
 * are left as they were). */
static int reduce_layers(render_layers_t *L, int rank, hd_error_t *err) {
    MPI_Datatype tn = MPI_DATATYPE_NULL, tf = MPI_DATATYPE_NULL;
    MPI_Op on = MPI_OP_NULL, of = MPI_OP_NULL;
    int ok = MPI_Type_contiguous((int)sizeof(render_px_t), MPI_BYTE, &tn) == MPI_SUCCESS &&
             MPI_Type_commit(&tn) == MPI_SUCCESS &&
             MPI_Type_contiguous((int)sizeof(render_far_t), MPI_BYTE, &tf) == MPI_SUCCESS &&
             MPI_Type_commit(&tf) == MPI_SUCCESS && MPI_Op_create(near_op, 1, &on) == MPI_SUCCESS &&
             MPI_Op_create(far_op, 1, &of) == MPI_SUCCESS;
    int n = (int)L->n;
    ok = ok && MPI_Reduce(rank ? L->near : MPI_IN_PLACE, L->near, n, tn, on, 0, MPI_COMM_WORLD) == MPI_SUCCESS;
    ok = ok && MPI_Reduce(rank ? L->far : MPI_IN_PLACE, L->far, n, tf, of, 0, MPI_COMM_WORLD) == MPI_SUCCESS;
    ok = ok && MPI_Reduce(rank ? L->b : MPI_IN_PLACE, L->b, n, MPI_UNSIGNED_CHAR, MPI_MAX, 0, MPI_COMM_WORLD) ==
                   MPI_SUCCESS;
    if (on != MPI_OP_NULL) MPI_Op_free(&on);
    if (of != MPI_OP_NULL) MPI_Op_free(&of);
    if (tn != MPI_DATATYPE_NULL) MPI_Type_free(&tn);
    if (tf != MPI_DATATYPE_NULL) MPI_Type_free(&tf);
    if (ok) return HD_OK;
    snprintf(err->message, sizeof err->message, "merging the picture's layers over the ranks failed");
    return err->code = HD_EIO;
}

int mpi_render(const analysis_args_t *an, const hd_mpi_part_t part[2], const double *d_a, const double wp[3],
               const double wq[3], const hd_symmetric_t *s, const char *path_a, const char *path_b,
               analysis_result_t *r, hd_error_t *err) {
    int rank;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    /* the scene, the same on every rank: all points' bounds, A's count,
     * hausdorff's scale, and whether some distance lies beyond it */
    render_scene_t sc;
    render_scene_bounds(&sc, &part[0].points, &part[1].points);
    MPI_Allreduce(MPI_IN_PLACE, sc.lo, 3, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
    MPI_Allreduce(MPI_IN_PLACE, sc.hi, 3, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    sc.n_a = r->n_a;
    sc.dmax = analysis_scale(an, r);
    sc.clipped = 0;
    for (size_t k = 0; k < part[0].points.count; k++) sc.clipped |= d_a[k] > sc.dmax;
    MPI_Allreduce(MPI_IN_PLACE, &sc.clipped, 1, MPI_INT, MPI_LOR, MPI_COMM_WORLD);
    render_layers_t L;
    int rc = HD_OK;
    if (render_layers_init(&L)) {
        snprintf(err->message, sizeof err->message, "out of memory for the picture");
        rc = err->code = HD_ENOMEM;
    }
    if ((rc = mpi_agree(rc, err)) != HD_OK) return rc;
    render_splat(&sc, &part[0].points, part[0].offset, d_a, &part[1].points, &L);
    rc = reduce_layers(&L, rank, err);
    if (rc == HD_OK && rank == 0) {
        char title[640];
        analysis_render_title(path_a, r->n_a, path_b, title, sizeof title);
        render_notes_t notes = analysis_notes(an, r);
        rc = render_compose(an->render_out, &sc, &L, wp, wq, s, r->directed, &notes, title, r->markers,
                            &r->n_markers, &r->render, &r->render_w, &r->render_h, err);
    }
    render_layers_free(&L);
    return mpi_agree(rc, err);
}
