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
    if (an->histogram_png && rank == 0)
        rc = render_histogram(an->histogram_png, r, an, an->bins, r->hist_markers, &r->n_hist_markers, err);
    return mpi_agree(rc, err);
}
