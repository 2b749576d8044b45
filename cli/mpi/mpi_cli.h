/*
 * mpi_cli.h -- what hausdorff-mpi's files share (cli/mpi/).
 */
#ifndef HD_MPI_CLI_H
#define HD_MPI_CLI_H

#include <hausdorff.h>

/* The first failing rank's code and message, on every rank (HD_OK when no
 * rank failed).  Collective over MPI_COMM_WORLD. */
int mpi_agree(int rc, hd_error_t *err);

/* Write a --distances file (writer.c): this rank's rows P, d, nearest
 * (nearest NULL: -1), the side's points first, first + 1, ...; total is
 * the file's rows over all ranks, dmax the PLY colour scale.  Collective;
 * HD_OK, or the same OUT_EFAIL (HD_EUNSUPPORTED, HD_ENOMEM) and message on
 * every rank.  The file is renamed into place by rank 0's out_finish. */
int mpi_write_distances(const char *path, const hd_points_t *P, size_t first, const double *d,
                        const size_t *nearest, size_t total, double dmax, hd_error_t *err);

/* The per-point files (writeback.c): --distances (tables by every rank,
 * files written back into a side's own format by rank 0 from the
 * gathered distances), --farther-than, --nearer-than, as hausdorff writes
 * them; d_ab, j_ab (d_ba, j_ba) this rank's values of part[0] ([1]), j
 * NULL: -1; total the sides' counts; what was written into r (rank 0).
 * Collective; the same code and message on every rank. */
struct analysis_args;
struct analysis_result;
struct hd_mpi_part;
int mpi_write_files(const struct analysis_args *an, const char *path_a, const char *path_b,
                    const struct hd_mpi_part part[2], const double *d_ab, const size_t *j_ab, const double *d_ba,
                    const size_t *j_ba, const uint64_t total[2], double dmax, int directed,
                    struct analysis_result *r, hd_error_t *err);

/* The figures hausdorff computes from per-point distances (--percentile,
 * --mean, --chamfer, --histogram, --histogram-png) over the ranks
 * (figures.c): d_ab and d_ba are this rank's distances (d_ba NULL when
 * r->directed), r->n_a and r->n_b all of A's and B's counts.  Fills r as
 * analysis_run does, the same doubles and counts; the picture is drawn by
 * rank 0.  Collective; the same code and message on every rank. */
struct analysis_args;
struct analysis_result;
int mpi_figures(const struct analysis_args *an, const double *d_ab, size_t n_a, const double *d_ba, size_t n_b,
                struct analysis_result *r, hd_error_t *err);

/* --render across the ranks (figures.c): each rank draws its points of A
 * (d_a, its distances) and B into per-pixel layers (render_splat), the
 * layers are merged on rank 0 (MPI_Reduce with the merges as operations),
 * which draws hausdorff's picture from them (render_compose); wp and wq are
 * the witness pair's points, r the figures (r->pct for the bar).  Fills
 * r's render fields on rank 0.  Collective. */
struct hd_mpi_part;
struct hd_symmetric;
int mpi_render(const struct analysis_args *an, const struct hd_mpi_part part[2], const double *d_a,
               const double wp[3], const double wq[3], const struct hd_symmetric *s, const char *path_a,
               const char *path_b, struct analysis_result *r, hd_error_t *err);

#endif
