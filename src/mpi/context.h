/*
 * context.h -- private to src/mpi/: the call's context (context.c): the
 * hd__mpi_ctx_t every function takes, its counted buffers, the engine's
 * calls, the agreement on errors, the HD__MPI_* wrappers of MPI calls, and
 * the records the call's MPI datatypes describe.  The library's files
 * include, by concern, ranges.h (the input's index runs and the local
 * sets' indices), partition.h (the RCB tree and the exchange), search.h
 * (the slabs, the engine's pass and its shell, the forwarding) and
 * course.h (the course of a call, mpi.c); nothing outside src/mpi/ does
 * but the white-box tests (tests/internal/mpi_*.c) and the partition's
 * benchmark (bench/rcb_bench.c).
 *
 * Conventions of every function here: a hd__mpi_ctx_t carries the call's
 * communicator, its error (c->e, what hd__mpi_agree() broadcasts) and its
 * count of bytes held (every buffer through hd__mpi_alloc/hd__mpi_free, so
 * the peak is known and the call can assert that it freed everything); a
 * function that can fail returns an HD_* code with c->e set, and collective
 * functions agree on a status before every collective a failed rank would
 * not reach.
 */
#ifndef HD_MPI_CONTEXT_H
#define HD_MPI_CONTEXT_H

#include "engine/engine.h"
#include "hausdorff_mpi.h"
#include "nearest/nearest.h"
#include "points/points.h"

#include <assert.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* ---- the call's context (context.c) -------------------------------------- */

typedef struct { double d2; uint64_t g; } hd__mpi_ans_t;                 /* an answer */
typedef struct { double d2; uint64_t i, j; } hd__mpi_far_t;              /* a witness */
typedef struct { double x[3]; uint64_t g, side; } hd__mpi_sample_t;
/* An RCB node: left/right >= 0 are nodes, < 0 are ranks -(r + 1). */
typedef struct { double s; uint64_t side, g; int axis, left, right, pad; } hd__mpi_node_t;
/* What each rank holds after the partition. */
typedef struct { hd__box_t box[2]; uint64_t n[2]; } hd__mpi_held_t;

typedef struct hd__mpi_ctx {
    MPI_Comm comm;
    int rank, K, threads;
    hd_error_t e;
    size_t cur, peak;          /* bytes of this call's buffers */
    uint64_t bytes_part, bytes_fwd, forwarded, forwarded_points, answered;
    uint64_t bytes_back;       /* per-point answers sent back (distances.c) */
    double search;             /* seconds in the engine and hd_distances */
    double search_cpu;         /* the calling thread's CPU seconds there */
    double mpi_cpu;            /* ... and in MPI calls */
    uint64_t shell;            /* points searched one by one (the shells) */
    uint64_t interior_passes;  /* second engine calls on an interior */
    int rounds;
    int first;                 /* the partition's first samples a rank (rcb.c) */
    int prune;                 /* hd_mpi_options_t's: cells that cannot matter stay (prune.c) */
    int replicate;             /* hd_mpi_options_t's: a tiny side on every rank (tiny.c) */
    MPI_Datatype ans_type, q_type, far_type, sample_type, node_type;
    MPI_Op far_op;             /* hd__mpi_far_t: the larger d2, then the smaller i */
    MPI_Op near_op;            /* hd__mpi_ans_t: the smaller d2, then the smaller g */
} hd__mpi_ctx_t;


double hd__mpi_cpu(void);
void *hd__mpi_alloc(hd__mpi_ctx_t *c, size_t n, size_t size);
void hd__mpi_free(hd__mpi_ctx_t *c, void *p, size_t n, size_t size);
/* A buffer freed before the engine's pass (the exchange's), which may be
 * rounded up to whole huge pages and is charged so; freed by
 * hd__mpi_free_scratch with the same count and size. */
void *hd__mpi_scratch(hd__mpi_ctx_t *c, size_t n, size_t size);
void hd__mpi_free_scratch(hd__mpi_ctx_t *c, void *p, size_t n, size_t size);
void hd__mpi_charge(hd__mpi_ctx_t *c, size_t bytes);
int hd__mpi_engine(hd__mpi_ctx_t *c, const hd_points_t *P, const hd_points_t *Q, hd_result_t *e);
int hd__mpi_engine_local(hd__mpi_ctx_t *c, const hd_points_t *P, const hd_points_t *Q, const hd__box_t *bp,
                         const hd__box_t *bq, hd_result_t *e);
int hd__mpi_engine_sym(hd__mpi_ctx_t *c, const hd_points_t *P, const hd_points_t *Q, const hd__box_t *bp,
                       const hd__box_t *bq, const hd__keep_t keep[2], hd_symmetric_t *s);
int hd__mpi_engine_above(hd__mpi_ctx_t *c, const hd_points_t *P, const hd_points_t *Q, double floor2, size_t floor_i,
                         hd_result_t *e);
int hd__mpi_engine_kept(hd__mpi_ctx_t *c, const hd_points_t *P, const hd_points_t *Q, const hd__keep_t *keep,
                        hd_result_t *e);
int hd__mpi_nomem(hd__mpi_ctx_t *c, const char *what, size_t n);
int hd__mpi_failed(hd__mpi_ctx_t *c, const char *call, int code);
int hd__mpi_agree(hd__mpi_ctx_t *c, int rc);
int hd__mpi_types_create(hd__mpi_ctx_t *c);
void hd__mpi_types_free(hd__mpi_ctx_t *c);

/* The witness order: larger d2 first, then the smaller index i. */
static inline int hd__mpi_far_better(const hd__mpi_far_t *x, const hd__mpi_far_t *y) {
    return x->d2 > y->d2 || (x->d2 == y->d2 && x->i < y->i);
}

/* The answer order: smaller d2 first, then the smaller global index. */
static inline int hd__mpi_ans_better(const hd__mpi_ans_t *x, const hd__mpi_ans_t *y) {
    return x->d2 < y->d2 || (x->d2 == y->d2 && x->g < y->g);
}

/* Every MPI call is timed (thread CPU): what is left of the call's CPU
 * besides them and the searches is its bookkeeping (stats->other_cpu). */
#define HD__MPI_TIMED(c, call) (mpi_t0_ = hd__mpi_cpu(), mpi_rc_ = (call), (c)->mpi_cpu += hd__mpi_cpu() - mpi_t0_, mpi_rc_)

#define HD__MPI_TRY(c, call)                                                      \
    do {                                                                      \
        double mpi_t0_;                                                       \
        int mpi_rc_;                                                          \
        mpi_rc_ = HD__MPI_TIMED(c, call);                                         \
        if (mpi_rc_ != MPI_SUCCESS) return hd__mpi_failed(c, #call, mpi_rc_); \
    } while (0)

/* The same in a function that frees its buffers at `done`. */
#define HD__MPI_GO(c, rc, call)                         \
    do {                                            \
        double mpi_t0_;                             \
        int mpi_rc_;                                \
        mpi_rc_ = HD__MPI_TIMED(c, call);               \
        if (mpi_rc_ != MPI_SUCCESS) {               \
            rc = hd__mpi_failed(c, #call, mpi_rc_); \
            goto done;                              \
        }                                           \
    } while (0)

#endif /* HD_MPI_CONTEXT_H */
