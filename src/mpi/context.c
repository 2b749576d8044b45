/*
 * context.c -- what every step of an MPI call shares (context.h's hd__mpi_ctx_t):
 * the count of the bytes it holds, the CPU it spends in MPI, the agreement
 * on a status, and the MPI types and the witness reduction.
 *
 * Invariants.
 *  - Every buffer of a call is allocated by hd__mpi_alloc and freed by
 *    hd__mpi_free with the same count and size, and memory the layer does
 *    not allocate but the call holds (the engine's structures at their
 *    documented bound, the nearest layer's while built) is charged with
 *    hd__mpi_charge for as long as it is held.  So c->cur is the bytes held
 *    now, c->peak the most held at once (hd_mpi_stats_t.peak_bytes), and
 *    c->cur is 0 when the call returns (mpi.c asserts it, on every path).
 *  - hd__mpi_agree is the only place where ranks learn of each other's
 *    failures: an allreduce of the first failing rank, then that rank's
 *    code and message broadcast.  Every collective a failed rank would not
 *    reach is preceded by it, so no rank waits for one that gave up, and
 *    every rank returns the same code and message.
 *  - Every MPI call's thread CPU is added to c->mpi_cpu (HD__MPI_TIMED), so the
 *    bookkeeping's CPU (stats->other_cpu) is what remains of the call's
 *    besides the MPI calls and the searches.
 */
#include "mpi/context.h"
#include "engine/engine.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <time.h>

/* CPU seconds of the calling thread (the searches' own cost with one
 * thread, whatever else the machine runs). */
double hd__mpi_cpu(void) {
    struct timespec ts;
    if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0) return 0;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- memory: every buffer counted, so the peak can be reported ---------- */

/* Large buffers ask for transparent huge pages: each is written once,
 * right after it is allocated, and a 4 KiB page costs many times more a
 * byte than a 2 MiB page, most when each takes a fault (bench/page_cost.c
 * measures the three; docs/scale-out.md, "Memory pages on this
 * machine").  A
 * buffer of HUGE_BYTES or more starts on a 2 MiB boundary and its whole
 * 2 MiB pages are marked; what is left after them, which the kernel maps
 * in small pages, is mapped in one call (hd__prefault), not a fault a
 * page.  A short-lived buffer (hd__mpi_scratch: freed before the engine's
 * pass, where the call's peak is) of at least SCRATCH_BYTES is made whole
 * 2 MiB pages when that adds at most an eighth of its size, and is charged
 * at that size; the long-lived ones are never rounded, so the peak is
 * what it was.  Where madvise or THP is missing this is plain memory. */
#define HUGE_BYTES ((size_t)4 << 20)
#define HUGE_PAGE ((size_t)2 << 20)
#define SCRATCH_BYTES (HUGE_PAGE / 9 * 8)

/* The bytes a buffer of `bytes` takes: rounded up to whole huge pages for
 * scratch when that wastes at most an eighth. */
static size_t span_of(size_t bytes, int scratch) {
#ifdef MADV_HUGEPAGE
    if (scratch && bytes >= SCRATCH_BYTES && bytes <= SIZE_MAX - HUGE_PAGE) {
        size_t whole = (bytes + HUGE_PAGE - 1) & ~(HUGE_PAGE - 1);
        if (whole - bytes <= bytes / 8) return whole;
    }
#else
    (void)scratch;
#endif
    return bytes;
}

static void *alloc_span(hd__mpi_ctx_t *c, size_t n, size_t size, int scratch) {
    if (size && n > SIZE_MAX / size) return NULL;
    size_t bytes = n * size, span = span_of(bytes, scratch);
    void *p = NULL;
#ifdef MADV_HUGEPAGE
    if (span >= HUGE_BYTES || span > bytes) {
        if (posix_memalign(&p, HUGE_PAGE, span) != 0) {
            p = NULL;
        } else {
            size_t huge = span & ~(HUGE_PAGE - 1);
            madvise(p, huge, MADV_HUGEPAGE); /* advice: failure changes nothing */
            /* the tail in small pages, from a huge page's boundary */
            if (huge < bytes) hd__prefault((unsigned char *)p + huge, bytes - huge);
        }
    } else
#endif
    {
        p = malloc(bytes ? bytes : 1);
        hd__prefault(p, bytes); /* one call, not a fault a page (a no-op below 64 KiB) */
    }
    if (p) {
        c->cur += span;
        if (c->cur > c->peak) c->peak = c->cur;
    }
    return p;
}

void *hd__mpi_alloc(hd__mpi_ctx_t *c, size_t n, size_t size) { return alloc_span(c, n, size, 0); }

void *hd__mpi_scratch(hd__mpi_ctx_t *c, size_t n, size_t size) { return alloc_span(c, n, size, 1); }

void hd__mpi_free(hd__mpi_ctx_t *c, void *p, size_t n, size_t size) {
    if (!p) return;
    c->cur -= n * size;
    free(p);
}

void hd__mpi_free_scratch(hd__mpi_ctx_t *c, void *p, size_t n, size_t size) {
    if (!p) return;
    c->cur -= span_of(n * size, 1);
    free(p);
}

/* Memory this layer does not allocate itself but the call holds: counted
 * in the peak while held. */
void hd__mpi_charge(hd__mpi_ctx_t *c, size_t bytes) {
    c->cur += bytes;
    if (c->cur > c->peak) c->peak = c->cur;
}

/* Every engine call of the library: charged, once it returns, at the
 * most memory the engine held during it (its results' stats.peak_bytes, its
 * pool's high-water mark: at most 16 bytes a point of both sets and less
 * on every path, docs/engine.md "Threads and memory"), on top of what this
 * layer held meanwhile.  On the local arrays (packed doubles, validated before the
 * exchange) it takes the engine's internal entries with the sets' boxes
 * (bp, bq; NULL: computed here), since hd_directed would validate every
 * point again (a pass over both sets); on
 * the caller's views (one rank: any layout) the public hd_directed.  s:
 * both directions at once (hd__engine_hausdorff), else h(P, Q) into e,
 * from a floor when floor2 >= 0 (hd__engine_directed_above); keep: NULL,
 * or the filter on each direction's maximum (hd__keep_t; s: two). */
enum { VIEWS, LOCAL };
static int engine_call(hd__mpi_ctx_t *c, int where, const hd_points_t *P, const hd_points_t *Q, const hd__box_t *bp,
                       const hd__box_t *bq, double floor2, size_t floor_i, const hd__keep_t *keep, hd_result_t *e,
                       hd_symmetric_t *s) {
    hd_options_t o;
    hd_options_init(&o);
    o.threads = c->threads;
    hd__box_t b[2];
    if (where == LOCAL) {
        if (bp) b[0] = *bp;
        else hd__box_of(P->data, P->count, &b[0]);
        if (bq) b[1] = *bq;
        else hd__box_of(Q->data, Q->count, &b[1]);
    }
    int rc = where == VIEWS ? hd_directed(P, Q, &o, e, &c->e)
             : s && keep    ? hd__engine_hausdorff_kept(P, Q, &b[0], &b[1], &o, keep, s, &c->e)
             : s            ? hd__engine_hausdorff(P, Q, &b[0], &b[1], &o, s, &c->e)
             : keep         ? hd__engine_directed_kept(P, Q, &b[0], &b[1], &o, keep, e, &c->e)
                            : hd__engine_directed_above(P, Q, &b[0], &b[1], &o, floor2, floor_i, e, &c->e);
    size_t bytes = rc != HD_OK ? 0 : s ? (size_t)s->ab.stats.peak_bytes : (size_t)e->stats.peak_bytes;
    hd__mpi_charge(c, bytes);
    c->cur -= bytes;
    return rc;
}

int hd__mpi_engine(hd__mpi_ctx_t *c, const hd_points_t *P, const hd_points_t *Q, hd_result_t *e) {
    return engine_call(c, VIEWS, P, Q, NULL, NULL, -1.0, 0, NULL, e, NULL);
}

int hd__mpi_engine_local(hd__mpi_ctx_t *c, const hd_points_t *P, const hd_points_t *Q, const hd__box_t *bp,
                         const hd__box_t *bq, hd_result_t *e) {
    return engine_call(c, LOCAL, P, Q, bp, bq, -1.0, 0, NULL, e, NULL);
}

/* h(P, Q) over the points *keep keeps (hd__keep_t). */
int hd__mpi_engine_kept(hd__mpi_ctx_t *c, const hd_points_t *P, const hd_points_t *Q, const hd__keep_t *keep,
                        hd_result_t *e) {
    return engine_call(c, LOCAL, P, Q, NULL, NULL, -1.0, 0, keep, e, NULL);
}

/* h(P, Q) where only an answer beating (floor2, floor_i) matters: the
 * points that cannot beat it are pruned as soon as one point of Q shows
 * it. */
int hd__mpi_engine_above(hd__mpi_ctx_t *c, const hd_points_t *P, const hd_points_t *Q, double floor2, size_t floor_i,
                         hd_result_t *e) {
    return engine_call(c, LOCAL, P, Q, NULL, NULL, floor2, floor_i, NULL, e, NULL);
}

/* Both directions in one call: the engine builds each set's structures
 * once for both (hd_directed builds both sets' too).  keep: NULL, or a
 * filter on each direction's maximum (hd__keep_t). */
int hd__mpi_engine_sym(hd__mpi_ctx_t *c, const hd_points_t *P, const hd_points_t *Q, const hd__box_t *bp,
                       const hd__box_t *bq, const hd__keep_t keep[2], hd_symmetric_t *s) {
    return engine_call(c, LOCAL, P, Q, bp, bq, -1.0, 0, keep, NULL, s);
}

int hd__mpi_nomem(hd__mpi_ctx_t *c, const char *what, size_t n) {
    return hd__err(&c->e, HD_ENOMEM, "out of memory for %s (%zu items)", what, n);
}

int hd__mpi_failed(hd__mpi_ctx_t *c, const char *call, int code) {
    char text[MPI_MAX_ERROR_STRING];
    int len = 0;
    if (MPI_Error_string(code, text, &len) != MPI_SUCCESS) len = 0;
    text[len] = '\0';
    return hd__err(&c->e, HD_EIO, "%s failed: %s", call, len ? text : "unknown MPI error");
}

/* Every rank passes its local status; all return the first failing rank's
 * code with its message ("rank R: ..."), or HD_OK when none failed.  The
 * only place where ranks learn of each other's failures, called before
 * every collective that a failed rank would not reach. */
int hd__mpi_agree(hd__mpi_ctx_t *c, int rc) {
    int mine = rc != HD_OK ? c->rank : c->K, first = c->K;
    double mpi_t0_;
    int mpi_rc_;
    if (HD__MPI_TIMED(c, MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, c->comm)) != MPI_SUCCESS)
        return rc != HD_OK ? rc : hd__err(&c->e, HD_EIO, "MPI_Allreduce failed while agreeing on a status");
    if (first == c->K) return HD_OK;
    hd_error_t e = c->e;
    if (c->rank == first) {
        e.code = rc;
        snprintf(e.message, sizeof e.message, "rank %d: %.1000s", first, c->e.message);
    }
    if (HD__MPI_TIMED(c, MPI_Bcast(&e, (int)sizeof e, MPI_BYTE, first, c->comm)) != MPI_SUCCESS)
        return hd__err(&c->e, HD_EIO, "MPI_Bcast failed while agreeing on a status");
    c->e = e;
    return e.code;
}

/* ---- the witness and nearest reductions ---------------------------------- */

static void far_reduce(void *in, void *inout, int *len, MPI_Datatype *type) {
    (void)type;
    const hd__mpi_far_t *x = in;
    hd__mpi_far_t *y = inout;
    for (int k = 0; k < *len; k++)
        if (hd__mpi_far_better(&x[k], &y[k])) y[k] = x[k];
}

static void near_reduce(void *in, void *inout, int *len, MPI_Datatype *type) {
    (void)type;
    const hd__mpi_ans_t *x = in;
    hd__mpi_ans_t *y = inout;
    for (int k = 0; k < *len; k++)
        if (hd__mpi_ans_better(&x[k], &y[k])) y[k] = x[k];
}
int hd__mpi_types_create(hd__mpi_ctx_t *c) {
    HD__MPI_TRY(c, MPI_Type_contiguous((int)sizeof(hd__mpi_ans_t), MPI_BYTE, &c->ans_type));
    HD__MPI_TRY(c, MPI_Type_contiguous(3, MPI_DOUBLE, &c->q_type));
    HD__MPI_TRY(c, MPI_Type_contiguous((int)sizeof(hd__mpi_far_t), MPI_BYTE, &c->far_type));
    HD__MPI_TRY(c, MPI_Type_contiguous((int)sizeof(hd__mpi_sample_t), MPI_BYTE, &c->sample_type));
    HD__MPI_TRY(c, MPI_Type_contiguous((int)sizeof(hd__mpi_node_t), MPI_BYTE, &c->node_type));
    MPI_Datatype *all[] = {&c->ans_type, &c->q_type, &c->far_type, &c->sample_type, &c->node_type};
    for (size_t k = 0; k < sizeof all / sizeof *all; k++) HD__MPI_TRY(c, MPI_Type_commit(all[k]));
    HD__MPI_TRY(c, MPI_Op_create(far_reduce, 1, &c->far_op));
    HD__MPI_TRY(c, MPI_Op_create(near_reduce, 1, &c->near_op));
    return HD_OK;
}

void hd__mpi_types_free(hd__mpi_ctx_t *c) {
    MPI_Datatype *all[] = {&c->ans_type, &c->q_type, &c->far_type, &c->sample_type, &c->node_type};
    for (size_t k = 0; k < sizeof all / sizeof *all; k++)
        if (*all[k] != MPI_DATATYPE_NULL) MPI_Type_free(all[k]);
    if (c->far_op != MPI_OP_NULL) MPI_Op_free(&c->far_op);
    if (c->near_op != MPI_OP_NULL) MPI_Op_free(&c->near_op);
}
