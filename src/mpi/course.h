/*
 * course.h -- private to src/mpi/: the course of a call (mpi.c, whose
 * essay has the algorithm): what the ranks hold after the partition, the
 * one-rank views, and the steps every entry point takes.
 *
 * Conventions of every function here: a hd__mpi_ctx_t carries the call's
 * communicator, its error (c->e, what hd__mpi_agree() broadcasts) and its
 * count of bytes held (every buffer through hd__mpi_alloc/hd__mpi_free, so
 * the peak is known and the call can assert that it freed everything); a
 * function that can fail returns an HD_* code with c->e set, and collective
 * functions agree on a status before every collective a failed rank would
 * not reach.
 */
#ifndef HD_MPI_COURSE_H
#define HD_MPI_COURSE_H

#include "mpi/partition.h"

/* ---- the course of a call (mpi.c) ---------------------------------------- */

/* What the ranks hold after the partition (K > 1). */
typedef struct {
    hd__mpi_node_t *tree;            /* K - 1 nodes */
    hd__box_t *region;       /* K: every rank's region */
    hd__mpi_held_t *held;            /* K: every rank's count and box a set */
    hd__mpi_local_t loc;             /* this rank's points */
} hd__mpi_spread_t;

/* K = 1: each set as one view (the caller's, or packed in index order). */
typedef struct {
    hd_points_t v[2];
    double *own[2];
    const hd_mpi_part_t **order[2];
} hd__mpi_views_t;

/* What a call's body holds from its start to its end. */
typedef struct {
    hd__mpi_ranges_t rg;
    hd__mpi_spread_t sp;             /* K > 1 */
    uint64_t N[2];           /* points of A and B over all ranks */
    double t0, cpu0;         /* the body's start (wall, thread CPU) */
} hd__mpi_course_t;

void hd__mpi_course_init(hd__mpi_ctx_t *c, hd__mpi_course_t *cs);
void hd__mpi_course_free(hd__mpi_ctx_t *c, hd__mpi_course_t *cs);
int hd__mpi_figures(hd__mpi_ctx_t *c, const hd__mpi_course_t *cs, uint64_t pts, hd_mpi_stats_t *st, double *tmax);

/* A call's body, run by hd__mpi_call inside its context (opt: the engine's
 * options of the call's hd_mpi_options_t, NULL for the defaults). */
typedef int (*hd__mpi_body_t)(hd__mpi_ctx_t *c, const hd_options_t *opt, hd__mpi_input_t *in, void *arg, hd_mpi_stats_t *st);

int hd__mpi_call(MPI_Comm comm, const hd_mpi_part_t *a, size_t na, const hd_mpi_part_t *b, size_t nb,
                 const hd_mpi_options_t *opt, hd__mpi_body_t body, void *arg, hd_mpi_stats_t *st, hd_error_t *err);
int hd__mpi_begin(hd__mpi_ctx_t *c, const hd_options_t *opt, hd__mpi_input_t *in, const void *res, hd__mpi_ranges_t *rg, uint64_t N[2],
                  double corners[2][6]);
/* pr: the points that stay out of the course (NULL: none; prune.c). */
int hd__mpi_spread(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const hd__mpi_ranges_t *rg, const uint64_t N[2],
                   const hd__mpi_prune_t *pr, hd__mpi_spread_t *sp);
void hd__mpi_spread_free(hd__mpi_ctx_t *c, hd__mpi_spread_t *sp);
int hd__mpi_views(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, hd__mpi_views_t *vw);
void hd__mpi_views_free(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, hd__mpi_views_t *vw);

/* ---- a tiny side replicated (tiny.c) -------------------------------------- */

/* Side s is tiny when N[s] <= HD__MPI_TINY_MAX and N[1 - s] >=
 * HD__MPI_TINY_RATIO K N[s] (docs/scale-out.md, "A tiny side"). */
#define HD__MPI_TINY_MAX 4096
#define HD__MPI_TINY_RATIO 16
/* The tiny side (0: A, 1: B), or -1: none, or K = 1, or the options'
 * replicate is 0.  From the global counts alone: every rank decides the same. */
int hd__mpi_tiny_side(const hd__mpi_ctx_t *c, const uint64_t N[2]);
/* All of a tiny side T on every rank, in global index order. */
typedef struct {
    double *xyz;             /* n points, packed */
    uint64_t *g;             /* their global indices, increasing */
    size_t n;
} hd__mpi_tiny_t;
/* Gathers side s (N_T points over all ranks; own: this rank's, in its
 * index order) on every rank (collective; rc: the caller's status, agreed
 * first). */
int hd__mpi_tiny_gather(hd__mpi_ctx_t *c, int rc, const hd_points_t *own, const hd__mpi_ranges_t *rg, int s,
                        uint64_t NT, hd__mpi_tiny_t *t);
void hd__mpi_tiny_free(hd__mpi_ctx_t *c, hd__mpi_tiny_t *t);
/* Every point k of T's nearest over all ranks' L into near[k] (exact d2,
 * the smallest global index on ties), on every rank (collective; rc agreed
 * first).  L: this rank's side ls (its view in index order), lbox its box. */
int hd__mpi_tiny_answers(hd__mpi_ctx_t *c, int rc, const hd_points_t *L, const hd__box_t *lbox,
                         const hd__mpi_ranges_t *rg, int ls, const hd__mpi_tiny_t *t, hd__mpi_ans_t *near);
/* The Hausdorff distance with side ts replicated on every rank
 * (collective): f[0] = h(A, B) and, when both, f[1] = h(B, A), with global
 * witnesses. */
int hd__mpi_tiny(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const hd__mpi_ranges_t *rg, const uint64_t N[2], int ts,
                 int both, hd__mpi_far_t f[2]);

#endif /* HD_MPI_COURSE_H */
