/*
 * tiny.c -- a tiny side replicated on every rank: no partition, no
 * exchange (the course of mpi.c when hd__mpi_tiny_side names a side).
 *
 * The rule (hd__mpi_tiny_side): side T is tiny when it has at most
 * HD__MPI_TINY_MAX points and the other side L has at least
 * HD__MPI_TINY_RATIO K times as many.  Every rank then holds all of T
 * (coordinates, global indices, one answer each: about 50 bytes a point
 * of T, and the nearest layer's structure of T while a search runs), at
 * most a sixteenth of a point of T for each point of L it holds on average,
 * so the replicated side adds a few bytes a local point; the points of L
 * never move.  The rule reads only the global counts, so every rank takes
 * the same course.
 *
 * Invariants.
 *  - Every rank holds T in global index order (an all-gather of each
 *    rank's points in its own index order, each point's global index from
 *    the index runs, hd__mpi_ranges_global, then sorted): position k of
 *    the replicated T is T's k-th smallest index, so a smallest position
 *    on ties is the smallest global index.
 *  - L -> T: each rank's engine on its own points of L (the caller's
 *    view, in index order: hd__mpi_views) against all of T gives the
 *    largest exact distance over them with the smallest index at it (its
 *    witness's nearest in T exact, smallest index on ties: T is whole).
 *    The maximum over the ranks is the far_op reduction: larger d2, then
 *    the smaller index of L; the ranks' points are disjoint, so this is
 *    the maximum over all of L with the smallest global index at it,
 *    hd_directed's witness on the union.
 *  - T -> L: each point of T takes its exact nearest among the rank's
 *    points of L (the nearest layer's search, a chunk of consecutive
 *    positions at a time, the smaller position kept on ties: the smaller
 *    global index), as (d2, global index); one MPI_Allreduce with
 *    near_op (smaller d2, then the smaller index) gives every rank each
 *    point's nearest over all of L with the smallest index on ties, the
 *    one hd_distances gives on the union.  The largest of those, at the
 *    smallest position of T (its smallest index), is h(T, L) and its
 *    witness.
 *  - Every value compared is an hd__d2 of the same doubles the single
 *    process compares, so the result is hd_hausdorff's bit for bit.
 */
#include "mpi/course.h"
#include "mpi/search.h"

#include <stdlib.h>

int hd__mpi_tiny_side(const hd__mpi_ctx_t *c, const uint64_t N[2]) {
    if (!c->replicate || c->K == 1) return -1;
    for (int s = 0; s < 2; s++)
        if (N[s] <= HD__MPI_TINY_MAX && N[s] * (uint64_t)HD__MPI_TINY_RATIO * (uint64_t)c->K <= N[1 - s]) return s;
    return -1;
}

void hd__mpi_tiny_free(hd__mpi_ctx_t *c, hd__mpi_tiny_t *t) {
    hd__mpi_free(c, t->xyz, t->n, 3 * sizeof(double));
    hd__mpi_free(c, t->g, t->n, sizeof(uint64_t));
    memset(t, 0, sizeof *t);
}

typedef struct { uint64_t g; size_t at; } by_g_t;
static int by_g(const void *x, const void *y) {
    const by_g_t *a = x, *b = y;
    return a->g < b->g ? -1 : a->g > b->g;
}

int hd__mpi_tiny_gather(hd__mpi_ctx_t *c, int rc, const hd_points_t *own, const hd__mpi_ranges_t *rg, int s, uint64_t NT,
                  hd__mpi_tiny_t *t) {
    int K = c->K, nmine = (int)own->count;
    int *cnt = hd__mpi_alloc(c, 2 * (size_t)K, sizeof(int));
    double *send = hd__mpi_alloc(c, own->count ? own->count : 1, 3 * sizeof(double));
    double *all = hd__mpi_alloc(c, NT, 3 * sizeof(double));
    by_g_t *ord = hd__mpi_alloc(c, NT, sizeof *ord);
    t->n = NT;
    t->xyz = hd__mpi_alloc(c, NT, 3 * sizeof(double));
    t->g = hd__mpi_alloc(c, NT, sizeof(uint64_t));
    if (rc == HD_OK && (!cnt || !send || !all || !ord || !t->xyz || !t->g)) rc = hd__mpi_nomem(c, "the tiny side", NT);
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    for (size_t k = 0; k < own->count; k++) hd__mpi_get_point(own, k, send + 3 * k);
    HD__MPI_GO(c, rc, MPI_Allgather(&nmine, 1, MPI_INT, cnt, 1, MPI_INT, c->comm));
    size_t at = 0;
    for (int r = 0; r < K; r++) {
        for (int m = 0; m < cnt[r]; m++, at++) ord[at] = (by_g_t){hd__mpi_ranges_global(rg, s, r, (uint64_t)m), at};
        cnt[K + r] = 3 * (int)(at - (size_t)cnt[r]);
        cnt[r] *= 3;
    }
    assert(at == NT);
    HD__MPI_GO(c, rc, MPI_Allgatherv(send, 3 * nmine, MPI_DOUBLE, all, cnt, cnt + K, MPI_DOUBLE, c->comm));
    c->bytes_part += (uint64_t)nmine * 3 * sizeof(double) * (uint64_t)(K - 1);
    qsort(ord, NT, sizeof *ord, by_g);
    for (size_t k = 0; k < NT; k++) {
        t->g[k] = ord[k].g;
        memcpy(t->xyz + 3 * k, all + 3 * ord[k].at, 3 * sizeof(double));
    }
done:
    hd__mpi_free(c, cnt, 2 * (size_t)K, sizeof(int));
    hd__mpi_free(c, send, own->count ? own->count : 1, 3 * sizeof(double));
    hd__mpi_free(c, all, NT, 3 * sizeof(double));
    hd__mpi_free(c, ord, NT, sizeof *ord);
    return rc;
}

/* h(L, T) over all ranks (collective; rc agreed first): the engine on the
 * rank's L, then the witness reduction. */
static int large_to_tiny(hd__mpi_ctx_t *c, int rc, const hd_points_t *L, const hd__mpi_ranges_t *rg, int ls,
                         const hd__mpi_tiny_t *t, hd__mpi_far_t *out) {
    hd__mpi_far_t mine = {-1.0, UINT64_MAX, UINT64_MAX};
    if (rc == HD_OK && L->count) {
        hd_points_t Tv = hd_points_f64(t->xyz, t->n);
        hd_result_t e;
        double t0 = hd__now(), u0 = hd__mpi_cpu();
        rc = hd__mpi_engine(c, L, &Tv, &e);
        c->search += hd__now() - t0;
        c->search_cpu += hd__mpi_cpu() - u0;
        if (rc == HD_OK) mine = (hd__mpi_far_t){e.distance2, hd__mpi_ranges_global(rg, ls, c->rank, e.i), t->g[e.j]};
    }
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) return rc;
    HD__MPI_TRY(c, MPI_Allreduce(&mine, out, 1, c->far_type, c->far_op, c->comm));
    return HD_OK;
}

/* The points of L a structure holds at once: a quarter of them, at least
 * this many (the nearest layer's structure takes about 38 bytes a point
 * of it while built: a quarter of that a local point). */
#define CHUNK_MIN 65536

/* Points [j0, j0 + n) of the view v, as a view. */
static hd_points_t sub_view(const hd_points_t *v, size_t j0, size_t n) {
    size_t elem = v->dtype == HD_FLOAT32 ? sizeof(float) : sizeof(double);
    ptrdiff_t stride = v->stride ? v->stride : 3 * (ptrdiff_t)elem;
    hd_points_t s = *v;
    s.data = (const unsigned char *)v->data + (ptrdiff_t)j0 * stride;
    s.count = n;
    return s;
}

/* For each point of T, its exact nearest among the rank's L (smallest
 * position on ties) into near[k] as (d2, position); (inf, UINT64_MAX)
 * when L is empty. */
static int nearest_in_l(hd__mpi_ctx_t *c, const hd_points_t *L, const hd__box_t *lbox, const hd__mpi_tiny_t *t,
                        hd__mpi_ans_t *near) {
    for (size_t k = 0; k < t->n; k++) near[k] = (hd__mpi_ans_t){INFINITY, UINT64_MAX};
    size_t nL = L->count, ch = nL / 4 > CHUNK_MIN ? nL / 4 : CHUNK_MIN;
    size_t *part = hd__mpi_alloc(c, t->n, sizeof(size_t));
    if (!part) return hd__mpi_nomem(c, "the tiny side's searches", t->n);
    hd_points_t Tv = hd_points_f64(t->xyz, t->n);
    int rc = HD_OK;
    for (size_t j0 = 0; j0 < nL && rc == HD_OK; j0 += ch) {
        size_t nj = nL - j0 < ch ? nL - j0 : ch;
        hd_points_t S = sub_view(L, j0, nj);
        hd__an_t searched, asking;
        size_t sb = 0, ab = 0;
        int threads = hd__thread_count(c->threads, nj);
        rc = hd__mpi_an_build(c, &searched, &S, NULL, NULL, nj, lbox, threads, &sb);
        if (rc == HD_OK) rc = hd__mpi_an_build(c, &asking, &Tv, NULL, NULL, t->n, lbox, threads, &ab);
        if (rc == HD_OK) rc = hd__mpi_an_nearest(c, &asking, &searched, NULL, threads, part);
        if (ab) hd__mpi_an_release(c, &asking, ab);
        if (sb) hd__mpi_an_release(c, &searched, sb);
        for (size_t k = 0; k < t->n && rc == HD_OK; k++) {
            double p[3];
            hd__mpi_get_point(L, j0 + part[k], p);
            double d2 = hd__d2(t->xyz + 3 * k, p);
            if (d2 < near[k].d2) near[k] = (hd__mpi_ans_t){d2, j0 + part[k]}; /* earlier chunks: smaller positions */
        }
    }
    hd__mpi_free(c, part, t->n, sizeof(size_t));
    return rc;
}

int hd__mpi_tiny_answers(hd__mpi_ctx_t *c, int rc, const hd_points_t *L, const hd__box_t *lbox,
                         const hd__mpi_ranges_t *rg, int ls, const hd__mpi_tiny_t *t, hd__mpi_ans_t *near) {
    if (rc == HD_OK) {
        double t0 = hd__now(), u0 = hd__mpi_cpu();
        rc = nearest_in_l(c, L, lbox, t, near);
        c->search += hd__now() - t0;
        c->search_cpu += hd__mpi_cpu() - u0;
    }
    for (size_t k = 0; rc == HD_OK && k < t->n; k++)
        if (near[k].g != UINT64_MAX) near[k].g = hd__mpi_ranges_global(rg, ls, c->rank, near[k].g);
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) return rc;
    HD__MPI_TRY(c, MPI_Allreduce(MPI_IN_PLACE, near, (int)t->n, c->ans_type, c->near_op, c->comm));
    /* a reduction's bytes, counted as a ring's: each rank sends each answer
     * twice less a K-th */
    c->bytes_part += 2 * (uint64_t)t->n * sizeof *near * (uint64_t)(c->K - 1) / (uint64_t)c->K;
    return HD_OK;
}

/* h(T, L) over all ranks (collective; rc agreed first). */
static int tiny_to_large(hd__mpi_ctx_t *c, int rc, const hd_points_t *L, const hd__box_t *lbox,
                         const hd__mpi_ranges_t *rg, int ls, const hd__mpi_tiny_t *t, hd__mpi_far_t *out) {
    hd__mpi_ans_t *near = hd__mpi_alloc(c, t->n, sizeof *near);
    if (rc == HD_OK && !near) rc = hd__mpi_nomem(c, "the tiny side's answers", t->n);
    if ((rc = hd__mpi_tiny_answers(c, rc, L, lbox, rg, ls, t, near)) == HD_OK) {
        size_t w = 0;
        for (size_t k = 1; k < t->n; k++)
            if (near[k].d2 > near[w].d2) w = k; /* the first at the largest: the smallest index */
        *out = (hd__mpi_far_t){near[w].d2, t->g[w], near[w].g};
    }
    hd__mpi_free(c, near, t->n, sizeof *near);
    return rc;
}

int hd__mpi_tiny(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const hd__mpi_ranges_t *rg, const uint64_t N[2], int ts,
                 int both, hd__mpi_far_t f[2]) {
    int ls = 1 - ts;
    hd__mpi_views_t vw;
    hd__mpi_tiny_t t;
    memset(&t, 0, sizeof t);
    int rc = hd__mpi_views(c, in, &vw);
    rc = hd__mpi_tiny_gather(c, rc, &vw.v[ts], rg, ts, N[ts], &t);
    /* A -> B is f[0]: L -> T when T is B, T -> L when T is A. */
    if (both || ts == 1) rc = large_to_tiny(c, rc, &vw.v[ls], rg, ls, &t, &f[ls]);
    if (both || ts == 0) rc = tiny_to_large(c, rc, &vw.v[ls], &in->box[ls], rg, ls, &t, &f[ts]);
    hd__mpi_tiny_free(c, &t);
    hd__mpi_views_free(c, in, &vw);
    return rc;
}
