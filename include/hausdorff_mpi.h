/*
 * hausdorff_mpi.h -- the exact Hausdorff distance of point sets spread over
 * the ranks of an MPI communicator.
 *
 * The optional library libhausdorff_mpi (built when CMake finds MPI) adds
 * calls over libhausdorff: every rank passes the points it holds, each
 * numbered by its global index, and every rank receives the same result,
 * bit for bit the one hd_hausdorff() returns on all the points in one
 * process, witness included (hd_mpi_hausdorff); or each rank receives, for
 * its own points, what hd_distances() returns for them on all the points
 * (hd_mpi_distances); or every rank receives hd_hausdorff_percentile()'s
 * figures on all the points (hd_mpi_hausdorff_percentile).  The options
 * are an hd_mpi_options_t (NULL: the defaults).  docs/scale-out.md
 * explains the algorithm and its costs.
 *
 * A first program:
 *
 *     #include <hausdorff_mpi.h>
 *     #include <stdio.h>
 *
 *     int main(int argc, char **argv) {
 *         MPI_Init(&argc, &argv);
 *         int rank;
 *         MPI_Comm_rank(MPI_COMM_WORLD, &rank);
 *         // rank r holds A's points 2r and 2r+1, and B's point r
 *         double a[6] = { rank, 0, 0,  rank, 1, 0 };
 *         double b[3] = { rank, 0, 0.5 };
 *         hd_mpi_part_t A = { hd_points_f64(a, 2), 2 * (size_t)rank };
 *         hd_mpi_part_t B = { hd_points_f64(b, 1), (size_t)rank };
 *         hd_symmetric_t r;
 *         hd_error_t err;
 *         int rc = hd_mpi_hausdorff(MPI_COMM_WORLD, &A, 1, &B, 1, NULL,
 *                                   &r, NULL, &err);
 *         if (rc != HD_OK) {           // the same code on every rank
 *             if (rank == 0) fprintf(stderr, "%s\n", err.message);
 *         } else if (rank == 0) {
 *             printf("H = %.17g, A[%zu] to B[%zu]\n", r.distance,
 *                    r.ab.i, r.ab.j);
 *         }
 *         MPI_Finalize();
 *         return rc != HD_OK;
 *     }
 *
 * Build with `mpicc -o prog prog.c -lhausdorff_mpi -lhausdorff` (installed
 * elsewhere than /usr/local or /usr: `mpicc -o prog prog.c $(pkg-config
 * --cflags --libs hausdorff_mpi)`), or in CMake with
 * `find_package(hausdorff COMPONENTS mpi)` and
 * `target_link_libraries(app hausdorff::hausdorff_mpi)`
 * (hausdorff::hausdorff_mpi_static for the static libraries), and run with
 * `mpirun -n 4 ./prog`: it prints H = 1.1180339887498949, A[1] to B[0].  As
 * root Open MPI also wants --allow-run-as-root, and on fewer cores than
 * ranks --oversubscribe (or a hostfile that gives the slots).
 *
 * Conventions: those of hausdorff.h (result codes, hd_error_t, ownership,
 * exactness, the tie rule), and for MPI:
 *  - Every call here is collective over `comm`: every rank calls it with
 *    the same options, and every rank returns the same result code, the
 *    same result and the same message (the first failing rank's, prefixed
 *    with "rank R: ").  A failure on one rank (a bad point, no memory) never
 *    leaves the others waiting: the ranks agree on a status before every
 *    step that could block.
 *  - The library duplicates `comm` for its own messages (so they never
 *    match the caller's) and frees the duplicate before returning.  MPI
 *    must be initialised.  Only the calling thread makes MPI calls; the
 *    threads the library starts (opt->engine.threads) make none, so
 *    MPI_THREAD_FUNNELED is the level the standard asks for.
 *  - Points are read during the call only, and may be laid out in any way
 *    over the ranks: any rank may hold any points of either set, or none.
 *  - Memory: the call holds about 33 bytes per point it ends up with while
 *    the points move and 25 after (coordinates, and their global indices
 *    in under a byte), plus the engine's structures (about 14.5 bytes a
 *    point) and the searches' (docs/scale-out.md); on one
 *    rank it runs on the caller's points without a copy.  hd_mpi_distances
 *    holds more (its entry says how much): every point needs its own
 *    search.
 */
#ifndef HAUSDORFF_MPI_H
#define HAUSDORFF_MPI_H

#include <mpi.h>

#include "hausdorff.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A run of consecutive points of one set held by this rank: its points are
 * the set's points offset, offset + 1, ..., offset + points.count - 1.  A
 * rank passes as many parts of each set as it holds (a tile file each, say);
 * over all ranks the parts of one set must not share an index (HD_EINVAL).
 * Indices need not cover 0..n-1 without gaps: the witness names them as
 * given. */
typedef struct hd_mpi_part {
    hd_points_t points;
    size_t offset;
} hd_mpi_part_t;

/* The options of the calls over the ranks.  hd_mpi_options_init fills the
 * defaults; NULL in a call means them. */
typedef struct hd_mpi_options {
    hd_options_t engine; /* the single-machine options: engine.threads is
                            the number of threads each rank uses (< 0 is
                            HD_EINVAL) and engine.algorithm must be a
                            valid one (HD_EALGORITHM), although the default
                            engine's per-point search always runs; the
                            other fields are ignored */
    int prune;           /* 1 (default): before the partition, the points
                            that the cells' bounds prove cannot change the
                            result stay on the rank that holds them
                            (docs/scale-out.md, "The points that stay");
                            0: every point moves to its region's rank.
                            The result is the same bit for bit; only the
                            work and the bytes moved differ (a comparison
                            for benchmarks).  hd_mpi_distances and
                            hd_mpi_hausdorff_percentile ignore it: every
                            point needs its own answer or class */
    int replicate;       /* 1 (default): a tiny side (at most 4096 points,
                            and the other side at least 16 K times as
                            large, K the ranks) is copied to every rank
                            and the other side's points stay where they
                            are: no partition, no exchange
                            (docs/scale-out.md, "A tiny side"); 0: the
                            partition's course, as for any sets.  The
                            result is the same bit for bit (hd_mpi_distances
                            too: every point's answer).
                            hd_mpi_hausdorff_percentile ignores it */
} hd_mpi_options_t;

/* Fill `opt` with the defaults: hd_options_init's engine options,
 * prune = 1 and replicate = 1. */
void hd_mpi_options_init(hd_mpi_options_t *opt);

/* What the exchange cost, the same on every rank (sums and maxima over the
 * ranks) except the fields marked "this rank". */
typedef struct hd_mpi_stats {
    int ranks;
    uint64_t points;            /* input points of A and B */
    uint64_t bytes_partition;   /* bytes sent to other ranks to move the
                                   points (28 a point moved) and choose the
                                   regions (the samples, and the counts
                                   that refine the splits); with a tiny
                                   side replicated, its points (24 each to
                                   each other rank) and its answers'
                                   reduction (counted as a ring's) */
    uint64_t bytes_forwarding;  /* bytes of forwarded queries (24 each) and
                                   their answers (16 each) */
    uint64_t bytes_returned;    /* hd_mpi_distances: bytes of per-point
                                   answers sent back to the rank that
                                   holds the point (16 each); 0 otherwise */
    uint64_t forwarded;         /* (point, rank) queries forwarded */
    uint64_t forwarded_points;  /* points forwarded to one rank or more */
    uint64_t shell_points;      /* points searched one by one, in both
                                   directions (the shells: the others are
                                   settled by the engine's pruned pass) */
    int rounds;                 /* forwarding rounds (two per direction of
                                   the Hausdorff distance: the likeliest
                                   points first, then the rest; one per
                                   direction of hd_mpi_distances; 0 on one
                                   rank, where none is needed) */
    uint64_t points_max;        /* most points (A and B) a rank computed on */
    double imbalance;           /* points_max over the mean per rank */
    double work_imbalance;      /* the same with forwarded queries answered
                                   counted as points */
    double seconds_max;         /* the slowest rank's time in the call */
    double seconds_mean;
    double search_seconds_max;  /* the most a rank spent in the per-point
                                   searches (its own points and the
                                   queries it answered) */
    double search_cpu_max;      /* the same in CPU seconds of the calling
                                   thread: with opt->engine.threads = 1 the
                                   searches' own cost, whatever the load */
    double other_cpu_max;       /* the most CPU seconds of a rank's calling
                                   thread outside the searches and the MPI
                                   calls: validation, sampling, packing,
                                   merging, boxes (the bookkeeping) */
    uint64_t peak_bytes_max;    /* most bytes a rank held at once for this
                                   call: its buffers, the per-point
                                   searches' structures (up to about 38
                                   bytes a point while built, as their
                                   builds count it), and the engine's,
                                   charged at what the engine held at
                                   most during each of its calls (about
                                   14.5 bytes a point of uniform sets,
                                   never above 16 plus 4 MiB); not the
                                   caller's input, nor MPI's own buffers */
    double seconds;             /* this rank: time in the call */
    double search_seconds;      /* this rank: time in the searches */
    double other_cpu;           /* this rank: the bookkeeping's CPU seconds */
    uint64_t local_points;      /* this rank: points after the partition */
    uint64_t peak_bytes;        /* this rank: peak of the buffers above */
    double search_cpu;          /* this rank: the searches' CPU seconds */
} hd_mpi_stats_t;

/* H(A,B) of the points every rank holds, with both directions and their
 * witnesses: the result hd_hausdorff() gives on the union of all ranks'
 * points, to the bit (distances, witnesses in global indices, alpha,
 * disjoint).  Collective over comm.
 *
 * a, na: this rank's parts of A (na may be 0, a is then not read); b, nb
 *   likewise for B.  Read during the call only.  A part with no points is
 *   allowed.  Over all ranks each set must have a point (HD_EEMPTY).
 * opt: NULL for the defaults (hd_mpi_options_t above; out->ab.algorithm
 *   is HD_ALG_AUTO whatever engine.algorithm says).
 * out: receives the result on every rank; its stats are zero and its
 *   seconds are the slowest rank's.
 * stats: NULL, or receives the exchange figures above.
 * err: NULL, or receives the context of a failure.
 * Errors: as hd_hausdorff (HD_EINVAL, HD_EEMPTY, HD_ENONFINITE, HD_ERANGE,
 *   HD_ENOMEM, HD_ETHREAD), HD_EINVAL too for parts that share an index or
 *   run past SIZE_MAX, HD_ERANGE for more than 2^32 - 1 points of a set on
 *   one rank (checked before any point is read), HD_EOVERFLOW for more than 2^31 - 1 records between
 *   two ranks (MPI's int counts), HD_EIO when an MPI call fails.
 * Thread safety: as any collective MPI call: one call at a time per
 *   communicator. */
int hd_mpi_hausdorff(MPI_Comm comm, const hd_mpi_part_t *a, size_t na,
                     const hd_mpi_part_t *b, size_t nb,
                     const hd_mpi_options_t *opt, hd_symmetric_t *out,
                     hd_mpi_stats_t *stats, hd_error_t *err);

/* h(A,B) alone, as hd_directed() gives it: the same arguments and errors
 * as hd_mpi_hausdorff, half the work. */
int hd_mpi_directed(MPI_Comm comm, const hd_mpi_part_t *a, size_t na,
                    const hd_mpi_part_t *b, size_t nb,
                    const hd_mpi_options_t *opt, hd_result_t *out,
                    hd_mpi_stats_t *stats, hd_error_t *err);

/* Per-point nearest neighbours over the ranks, as hd_distances() gives
 * them on the union of all ranks' points, to the bit: for each point a_k
 * of A that this rank passes, dist_ab[k] = min over all of B (every rank's
 * points) of |a_k - b| and nearest_ab[k] = the smallest global index of B
 * at that distance; dist_ba and nearest_ba likewise for this rank's points
 * of B against all of A.  Collective over comm.
 *
 * a, na, b, nb, opt: as hd_mpi_hausdorff (only opt->engine.threads is
 *   read besides the checks).
 * dist_ab, nearest_ab: NULL, or arrays of this rank's points of A (the sum
 *   of its parts' counts), filled in the order of its parts: part 0's
 *   points, then part 1's, ...; dist_ba, nearest_ba likewise for B.  A
 *   direction is computed when any rank passes an output for it; a rank's
 *   NULL outputs are not written (a rank with no points of a set passes
 *   NULL or anything).  Undefined when the call fails.
 * stats: NULL, or the figures of hd_mpi_stats_t: bytes_returned counts the
 *   answers sent back to the points' ranks; shell_points the points whose
 *   region faces were not clear of their local nearest distance;
 *   forwarded* the queries sent to other ranks (no lower bound prunes
 *   them: every point needs its answer); rounds one per direction.
 * err: NULL, or receives the context of a failure.
 * Memory, per point a rank holds after the partition: under a byte (its
 *   coded index), about 37 bytes a point of each set for the nearest layer's
 *   structures, which hold the coordinates (about 38 while one is built), and
 *   about 24 bytes a point of the direction being computed during its
 *   search (16 after it); 8 bytes a point of the rank's own input while the
 *   answers come back (24 while they are sent when the ranks' index runs
 *   interleave).  Measured peak: 53-55 bytes a point a rank holds
 *   (docs/scale-out.md).  On one rank,
 *   hd_distances on the caller's points (charged at its 60 bytes a point),
 *   without a copy when a set has one nonempty part (else its parts are
 *   packed, 24 bytes a point), into the outputs themselves when the parts
 *   are given in index order (else through a copy, 16 bytes a point).
 * Errors: as hd_mpi_hausdorff (HD_EEMPTY when a set has no point on any
 *   rank), HD_EOVERFLOW for more than 2^31 - 1 points of a set on one rank
 *   (MPI's int counts).
 * Thread safety: as hd_mpi_hausdorff. */
int hd_mpi_distances(MPI_Comm comm, const hd_mpi_part_t *a, size_t na,
                     const hd_mpi_part_t *b, size_t nb,
                     const hd_mpi_options_t *opt, double *dist_ab,
                     size_t *nearest_ab, double *dist_ba,
                     size_t *nearest_ba, hd_mpi_stats_t *stats,
                     hd_error_t *err);

/* hd_hausdorff_percentile() on the union of all ranks' points: numpy's
 * linear percentile p of the nearest distances A->B, B->A, their maximum
 * (MONAI's HD95 for p = 95) and both directions pooled (medpy's), to the
 * bit, on every rank, without every per-point distance: after the
 * partition each rank classifies its points against a band around the
 * answer drawn from a sample, searching completely only the points near
 * the band or near its region's faces, and the ranks select the values
 * of the two ranks numpy interpolates from the band's values with
 * MPI_Allreduce counts (src/mpi/select.c has the method and the proof).
 * Collective over comm.
 * a, na, b, nb, opt: as hd_mpi_hausdorff (only opt->engine.threads is read
 *   besides the checks).  p: in [0, 100].
 * out: the figures (the same on every rank).
 * stats: NULL, or the figures of hd_mpi_stats_t; here shell_points counts
 *   the exact searches the ranks made (a band's values, the sample, the
 *   points forwarded: the rest were only bounded; 0 on one rank), and
 *   forwarded* the queries sent to other ranks for them.
 * err: NULL, or receives the context of a failure.
 * Memory, per point a rank holds after the partition: the two local
 *   structures of hd_mpi_distances (about 37 bytes a point of each set)
 *   and 8 bytes a point kept by a band.  On one rank,
 *   hd_hausdorff_percentile on the caller's points (packed when a set has
 *   several parts, 24 bytes a point).
 * Errors: as hd_mpi_hausdorff (HD_EEMPTY when a set has no point on any
 *   rank), HD_EINVAL for p outside [0, 100].
 * Thread safety: as hd_mpi_hausdorff. */
int hd_mpi_hausdorff_percentile(MPI_Comm comm, const hd_mpi_part_t *a, size_t na,
                                const hd_mpi_part_t *b, size_t nb,
                                const hd_mpi_options_t *opt, double p,
                                hd_percentile_t *out, hd_mpi_stats_t *stats,
                                hd_error_t *err);

/* The overlap degree alpha and *disjoint of the bounding boxes of all of A
 * and all of B, as hd_overlap() gives them on the union (hausdorff.h);
 * with hd_mpi_directed it makes what hd_hausdorff's result holds besides
 * the distances.  Collective; arguments and errors as hd_mpi_hausdorff
 * (no options). */
int hd_mpi_overlap(MPI_Comm comm, const hd_mpi_part_t *a, size_t na,
                   const hd_mpi_part_t *b, size_t nb, double *alpha,
                   int *disjoint, hd_error_t *err);

/* ---- figures of per-point distances spread over the ranks ----------------
 * Each rank passes its part of the per-point distances (hd_mpi_distances'
 * output, or any split: a rank may pass none), and every rank receives the
 * single-process function's result on the concatenation of every rank's
 * values in rank order, to the bit, without any value moving between
 * ranks.  Collective over comm; every rank returns the same code, the same
 * result and the same message (the first failing rank's).  The checks are
 * made in the single-process function's order, so the code is the one it
 * would return; a NaN's message names its global index. */

/* hd_summarize on the concatenation: d_ab holds this rank's n_a distances
 * of A's points to B (NULL allowed when n_a = 0), d_ba its n_b of B's to A.
 * B's distances are absent (their fields NaN, as hd_summarize with d_ba
 * NULL) when every rank passes d_ba = NULL; otherwise a rank's NULL d_ba is
 * none of them.  The sums are exact and rounded once (hausdorff.h), hence
 * the same for any split: each rank's exact accumulators are added over
 * the ranks (one MPI_Allreduce of 4 x 74 int64) and rounded once.
 * Errors: as hd_summarize (HD_EINVAL, HD_EEMPTY when a set's distances
 * are empty over all ranks, HD_ENONFINITE), HD_ENOMEM, HD_EIO. */
int hd_mpi_summarize(MPI_Comm comm, const double *d_ab, size_t n_a,
                     const double *d_ba, size_t n_b, hd_summary_t *out,
                     hd_error_t *err);

/* hd_percentile_of on the concatenation (numpy's linear percentile p of
 * A->B, B->A, their maximum, and both pooled), with d_ab, n_a, d_ba, n_b as
 * hd_mpi_summarize.  The ranks' values needed are found by an exact
 * distributed radix selection over the doubles' bits: eight rounds of an
 * MPI_Allreduce of 256 counts for each of the (up to) three figures, and
 * eight passes over the local values; one more of three minima.  The one difference from hd_percentile_of: when the result is a
 * zero, it is +0.0 (the single-process selection may return -0.0 when the
 * values hold both zeros; distances never do).
 * Errors: as hd_percentile_of (HD_EINVAL for p outside [0, 100] too),
 * HD_ENOMEM, HD_EIO. */
int hd_mpi_percentile_of(MPI_Comm comm, const double *d_ab, size_t n_a,
                         const double *d_ba, size_t n_b, double p,
                         hd_percentile_t *out, hd_error_t *err);

/* hd_histogram's counts of this rank's n values, summed over the ranks
 * into counts (`bins` elements on every rank); lo, hi and bins must be the
 * same on every rank.  Errors: as hd_histogram, HD_EOVERFLOW for more
 * than INT_MAX bins, HD_EIO. */
int hd_mpi_histogram(MPI_Comm comm, const double *values, size_t n,
                     double lo, double hi, size_t bins, uint64_t *counts,
                     hd_error_t *err);

#ifdef __cplusplus
}
#endif
#endif /* HAUSDORFF_MPI_H */
