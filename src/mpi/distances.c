/*
 * distances.c -- per-point nearest neighbours over the ranks
 * (hd_mpi_distances): for every point a of A, on the rank that holds it,
 * the distance to its nearest point of all of B and that point's smallest
 * global index; likewise for B against A.  Bit for bit what hd_distances
 * gives on the union of all ranks' points.
 *
 * The course, on the partition of the Hausdorff distance (mpi.c's essay,
 * steps 1 and 2: the same RCB regions, the same exchange):
 *  1. Local pass.  Each rank builds the nearest layer's structures (what
 *     hd_distances builds) of its local A and B, and every local point a of
 *     P gets u(a)^2, the exact minimum of hd__d2 over local Q, and j(a), the
 *     smallest local position at it (hd__an_nearest: smallest position on
 *     ties; local order is global index order, so the smallest global
 *     index of local Q at u(a)).  When A and B have one size, a point's
 *     partner (the other side's point of its global index, as
 *     hd_distances pairs point i with point i) is tried first when it is
 *     here (partners: one merge of the two sides' indices), if a sample
 *     says the partners are near (a copy and its original; not two
 *     samplings of one scene, where the merge would cost time for nothing).
 *     No answer depends on them.
 *  2. Forwarding.  a is exact when its region's faces are clear of u(a)^2
 *     (hd__mpi_faces_clear, the proof of mpi.c's step 4: every point of
 *     another region is farther than u(a), none ties), or when no other
 *     rank's box of Q has hd__box_lb2 <= u(a)^2 (a computed lower bound of
 *     every distance to a point inside: every rank that may hold a point
 *     at u(a) or nearer, ties included, is a candidate).  A rank with no
 *     local Q bounds u(a) by the smallest hd__box_ub2 over the nonempty
 *     boxes (at least the distance to every point inside one of them, so
 *     the nearest point is within it).  No lower bound L prunes here: every
 *     point needs its exact answer.  The other points go, in one round, to
 *     each candidate rank, which answers with its exact (d2, smallest
 *     global index) from its structure of local Q; the asker keeps the
 *     smaller pair (d2 first, then the index): the exact global answer,
 *     since every value compared is an hd__d2 of the same doubles.
 *  3. Return.  The answers go back to the ranks that hold the points, by
 *     the reverse of the exchange: a sender's points arrived in its walk
 *     order (parts by offset, then points), and the local arrays keep that
 *     order within each sender (in runs when received in index order; when
 *     the runs were merged, in the merge's index order, which keeps each
 *     sender's points in their order), so this rank returns each sender's
 *     answers in position order, and the sender walks its parts again in
 *     the same order, routing each point through the RCB tree as the
 *     exchange did, and takes the next answer of that point's rank.
 *     dist = sqrt(d2), computed once, as hd_distances computes it.
 *  On one rank nothing moves: hd_distances runs on the caller's views (or
 *  on the parts packed in index order), and its positions become global
 *  indices.
 *
 * Memory (K > 1), per local point.  The coordinates are held once: a
 * structure keeps exact copies in its own order, so each local array of
 * coordinates is freed once its structure exists, and point k is read from
 * the structure through the inverse of its order (an_t.pos, 4 bytes).  So:
 * the encoded indices (hd__mpi_gidx_t, under a byte), the two structures (about 37
 * bytes a point of each set, 38 while one is built) with their inverse
 * orders, held through both directions (each set asks in one and is
 * searched in the other), and per point of the direction being computed:
 * during the search the local position of its nearest (8 bytes), the
 * partners (4, when used; the other side's indices decoded for their
 * merge are freed before the search) and the search's own answers (12);
 * after it u2 (8) and the global index, written over the position in the
 * same 8 bytes, with the other side's indices decoded in order for that
 * pass (8 bytes a point of it: the nearest points fall anywhere in it,
 * and a decode at random costs several times one in order).  A rank's own
 * points of that direction take 8 bytes for the distances while the
 * answers come back, then 8 for the indices, each receive buffer had once
 * what it replaces was sent and freed; where the runs were merged, the
 * answers are first reordered by sender into buffers of 16 bytes a point.
 * The forwarded points are packed with their answers so far (48 bytes
 * each, few), and their queries and answers are 40 bytes each.
 * Measured peak: 53-55 bytes a local point, the search of a direction
 * (docs/scale-out.md).
 */
#include "mpi/course.h"
#include "mpi/search.h"

#include <assert.h>
#include <limits.h>
#include <stdlib.h>

typedef struct {
    double *dist[2];
    size_t *nearest[2];
} outs_t;

/* One local set's structure, charged while held, and where each point
 * (by local position) is in it: the structure keeps exact copies of the
 * coordinates in its own order, so once it exists the local array of
 * coordinates is freed and point k is read from it (an_point). */
typedef struct {
    hd__an_t s;
    size_t bytes;
    int built;
    uint32_t *pos;           /* n: local position -> position in s */
    size_t n;
} an_t;

static void an_free(hd__mpi_ctx_t *c, an_t *t) {
    if (t->built) hd__mpi_an_release(c, &t->s, t->bytes);
    hd__mpi_free(c, t->pos, t->n, sizeof(uint32_t));
    memset(t, 0, sizeof *t);
}

static inline void an_point(const an_t *t, size_t k, double out[3]) {
    uint32_t at = t->pos[k];
    out[0] = t->s.x[at], out[1] = t->s.y[at], out[2] = t->s.z[at];
}

/* The structure of local set xyz (n points), then its inverse order; the
 * coordinates are the caller's to free. */
static int an_of_set(hd__mpi_ctx_t *c, const double *xyz, size_t n, const hd__box_t *kb, an_t *t);

static int an_of(hd__mpi_ctx_t *c, const double *xyz, size_t n, const hd__box_t *kb, an_t *t) {
    memset(t, 0, sizeof *t);
    if (n == 0) return HD_OK;
    if (n > HD__AN_MAX_POINTS)
        return hd__err(&c->e, HD_ERANGE, "%zu points on one rank: the per-point search takes at most %zu", n,
                       (size_t)HD__AN_MAX_POINTS);
    hd_points_t v = hd_points_f64(xyz, n);
    int rc = hd__mpi_an_build(c, &t->s, &v, NULL, NULL, 0, kb, hd__thread_count(c->threads, n), &t->bytes);
    t->built = 1; /* freed by an_free whatever happened */
    return rc;
}

static int an_of_set(hd__mpi_ctx_t *c, const double *xyz, size_t n, const hd__box_t *kb, an_t *t) {
    int rc = an_of(c, xyz, n, kb, t);
    if (rc != HD_OK || n == 0) return rc;
    if (!(t->pos = hd__mpi_alloc(c, n, sizeof(uint32_t)))) return hd__mpi_nomem(c, "the structures", n);
    t->n = n;
    for (size_t at = 0; at < n; at++) t->pos[t->s.idx[at]] = (uint32_t)at;
    return HD_OK;
}

/* Side s's parts in offset order (the order the exchange walks them) and,
 * for each, where its first point goes in the outputs (part order as
 * given: part 0's points, then part 1's, ...). */
static int walk_order(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, int s, const hd_mpi_part_t ***order, size_t **base) {
    size_t np = in->nparts[s];
    *order = hd__mpi_alloc(c, np, sizeof **order);
    *base = hd__mpi_alloc(c, np, sizeof **base);
    size_t *given = hd__mpi_alloc(c, np, sizeof *given);
    if (!*order || !*base || !given) {
        hd__mpi_free(c, given, np, sizeof *given);
        return hd__mpi_nomem(c, "the parts", np);
    }
    for (size_t p = 0, at = 0; p < np; p++) {
        given[p] = at;
        at += in->parts[s][p].points.count;
        (*order)[p] = &in->parts[s][p];
    }
    qsort(*order, np, sizeof **order, hd__mpi_by_offset);
    for (size_t p = 0; p < np; p++) (*base)[p] = given[(size_t)((*order)[p] - in->parts[s])];
    hd__mpi_free(c, given, np, sizeof *given);
    return HD_OK;
}

static void walk_order_free(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, int s, const hd_mpi_part_t **order, size_t *base) {
    hd__mpi_free(c, order, in->nparts[s], sizeof *order);
    hd__mpi_free(c, base, in->nparts[s], sizeof *base);
}

/* ---- one rank ------------------------------------------------------------ */

/* Answers in index order (the views' order) on their way to the outputs in
 * part order: td/tn are the outputs themselves when the nonempty parts are
 * given in offset order, else arrays of their own, copied by unstage. */
typedef struct {
    double *td[2];
    size_t *tn[2];
    const hd_mpi_part_t **order[2];
    size_t *base[2];
} staged_t;

static int stage(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const int want[2], const outs_t *o, staged_t *sg) {
    memset(sg, 0, sizeof *sg);
    int rc = HD_OK;
    for (int s = 0; s < 2 && rc == HD_OK; s++) {
        if (!want[s] || (rc = walk_order(c, in, s, &sg->order[s], &sg->base[s])) != HD_OK) continue;
        int direct = 1;
        for (size_t p = 0, at = 0; p < in->nparts[s]; p++) {
            direct &= sg->base[s][p] == at;
            at += sg->order[s][p]->points.count;
        }
        sg->td[s] = o->dist[s];
        sg->tn[s] = o->nearest[s];
        if (direct) continue;
        if (o->dist[s] && !(sg->td[s] = hd__mpi_alloc(c, in->n[s], sizeof(double))))
            rc = hd__mpi_nomem(c, "the distances", in->n[s]);
        if (rc == HD_OK && o->nearest[s] && !(sg->tn[s] = hd__mpi_alloc(c, in->n[s], sizeof(size_t))))
            rc = hd__mpi_nomem(c, "the distances", in->n[s]);
    }
    return rc;
}

/* The staged answers to the outputs (when rc is HD_OK), and the stage freed. */
static void unstage(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const int want[2], outs_t *o, staged_t *sg, int rc) {
    for (int s = 0; s < 2 && rc == HD_OK; s++) {
        if (!want[s] || (sg->td[s] == o->dist[s] && sg->tn[s] == o->nearest[s])) continue;
        for (size_t p = 0, t = 0; p < in->nparts[s]; p++)
            for (size_t k = 0; k < sg->order[s][p]->points.count; k++, t++) {
                if (o->dist[s]) o->dist[s][sg->base[s][p] + k] = sg->td[s][t];
                if (o->nearest[s]) o->nearest[s][sg->base[s][p] + k] = sg->tn[s][t];
            }
    }
    for (int s = 0; s < 2; s++) {
        if (sg->td[s] != o->dist[s]) hd__mpi_free(c, sg->td[s], in->n[s], sizeof(double));
        if (sg->tn[s] != o->nearest[s]) hd__mpi_free(c, sg->tn[s], in->n[s], sizeof(size_t));
        if (sg->order[s]) walk_order_free(c, in, s, sg->order[s], sg->base[s]);
    }
}

/* hd_distances(P, Q) into P's answers and Q's (dist, nearest: positions in
 * the other set; any NULL), charged at its bound (60 bytes a point of each
 * set while built). */
static int local_distances(hd__mpi_ctx_t *c, const hd_points_t *P, const hd_points_t *Q, double *dp, size_t *np,
                           double *dq, size_t *nq) {
    size_t bytes = 60 * (P->count + Q->count);
    hd_options_t opt;
    hd_options_init(&opt);
    opt.threads = c->threads;
    hd__mpi_charge(c, bytes);
    double t0 = hd__now(), u0 = hd__mpi_cpu();
    int rc = hd_distances(P, Q, &opt, dp, np, dq, nq, &c->e);
    c->search += hd__now() - t0;
    c->search_cpu += hd__mpi_cpu() - u0;
    c->cur -= bytes;
    return rc;
}

/* hd_distances on the views; its positions (index order) become global
 * indices, and the answers go to the outputs in part order. */
static int single(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const hd__mpi_ranges_t *rg, const int want[2], outs_t *o) {
    hd__mpi_views_t vw;
    staged_t sg;
    memset(&sg, 0, sizeof sg);
    int rc = hd__mpi_views(c, in, &vw);
    if (rc == HD_OK) rc = stage(c, in, want, o, &sg);
    if (rc == HD_OK) rc = local_distances(c, &vw.v[0], &vw.v[1], sg.td[0], sg.tn[0], sg.td[1], sg.tn[1]);
    for (int s = 0; s < 2 && rc == HD_OK; s++)
        if (want[s] && sg.tn[s])
            for (size_t k = 0; k < in->n[s]; k++) sg.tn[s][k] = (size_t)hd__mpi_ranges_global(rg, 1 - s, 0, sg.tn[s][k]);
    unstage(c, in, want, o, &sg, rc);
    hd__mpi_views_free(c, in, &vw);
    return rc;
}

/* ---- a tiny side replicated (tiny.c) --------------------------------------- */

/* Side ts replicated on every rank, nothing partitioned (collective): each
 * rank's points of L take their nearest in all of T from hd_distances (a
 * position of T, whose global index the gather gives), and T's points their
 * nearest over all ranks' L from the reduction of hd__mpi_tiny_answers,
 * each rank writing its own points' (T in index order: a binary search of
 * its indices).  One sqrt of the exact d2, as hd_distances. */
static int tiny(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const hd__mpi_ranges_t *rg, const uint64_t N[2], int ts,
                const int want[2], outs_t *o) {
    int ls = 1 - ts;
    hd__mpi_views_t vw;
    staged_t sg;
    hd__mpi_tiny_t t;
    memset(&t, 0, sizeof t);
    memset(&sg, 0, sizeof sg);
    hd__mpi_ans_t *near = NULL;
    int rc = hd__mpi_views(c, in, &vw);
    if (rc == HD_OK) rc = stage(c, in, want, o, &sg);
    rc = hd__mpi_tiny_gather(c, rc, &vw.v[ts], rg, ts, N[ts], &t);
    if (want[ts]) {
        near = hd__mpi_alloc(c, t.n, sizeof *near);
        if (rc == HD_OK && !near) rc = hd__mpi_nomem(c, "the tiny side's answers", t.n);
        rc = hd__mpi_tiny_answers(c, rc, &vw.v[ls], &in->box[ls], rg, ls, &t, near);
        for (size_t m = 0; rc == HD_OK && m < in->n[ts]; m++) {
            uint64_t g = hd__mpi_ranges_global(rg, ts, c->rank, m);
            size_t lo = 0, hi = t.n;
            while (lo < hi) { /* T's position of index g */
                size_t mid = lo + (hi - lo) / 2;
                if (t.g[mid] < g) lo = mid + 1;
                else hi = mid;
            }
            if (sg.td[ts]) sg.td[ts][m] = sqrt(near[lo].d2);
            if (sg.tn[ts]) sg.tn[ts][m] = (size_t)near[lo].g;
        }
    }
    if (rc == HD_OK && want[ls] && in->n[ls]) {
        hd_points_t Tv = hd_points_f64(t.xyz, t.n);
        rc = local_distances(c, &vw.v[ls], &Tv, sg.td[ls], sg.tn[ls], NULL, NULL);
        for (size_t k = 0; rc == HD_OK && sg.tn[ls] && k < in->n[ls]; k++) sg.tn[ls][k] = (size_t)t.g[sg.tn[ls][k]];
    }
    rc = hd__mpi_agree(c, rc);
    unstage(c, in, want, o, &sg, rc);
    hd__mpi_free(c, near, t.n, sizeof *near);
    hd__mpi_tiny_free(c, &t);
    hd__mpi_views_free(c, in, &vw);
    return rc;
}

/* ---- the return ---------------------------------------------------------- */

/* The answers (d2, index) of side s's local points go back to the ranks
 * that hold them (step 3 of the essay), which write them to their outputs.
 * d2 is made the distance in place; d2 and j are freed here. */
static int give_back(hd__mpi_ctx_t *c, const hd__mpi_spread_t *sp, const hd__mpi_input_t *in, int s, double **d2p,
                     uint64_t **jp, outs_t *o) {
    int K = c->K, rc = HD_OK;
    const hd__mpi_local_t *loc = &sp->loc;
    size_t n = loc->n[s], own = (size_t)in->n[s], m = 0;
    double *d2 = *d2p, *sd = d2, *rd = NULL;
    uint64_t *j = *jp, *sj = j, *rj = NULL;
    int packed = 0; /* sd, sj are buffers of their own (else d2, j) */
    int *cnt = hd__mpi_alloc(c, 5 * (size_t)K, sizeof(int)); /* scount sdispl rcount rdispl cursor */
    const hd_mpi_part_t **order = NULL;
    size_t *base = NULL;
    if (!cnt) rc = hd__mpi_nomem(c, "the answers", (size_t)K);
    int *scount = cnt, *sdispl = cnt + K, *rcount = cnt + 2 * K, *rdispl = cnt + 3 * K, *cur = cnt + 4 * K;
    for (size_t k = 0; k < n && rc == HD_OK; k++) d2[k] = sqrt(d2[k]); /* one sqrt, as hd_distances */
    if (rc == HD_OK && !loc->merged[s]) {
        /* Runs as received: sender r's points are positions [start[r], start[r] + start[K + r]). */
        for (int r = 0; r < K; r++) {
            sdispl[r] = (int)loc->start[s][r];
            scount[r] = (int)loc->start[s][K + r];
        }
    } else if (rc == HD_OK) {
        /* Merged: each position's sender is the owner of its index (the
         * rank of its run); its points are in index order, the order it
         * sent them in. */
        sd = hd__mpi_alloc(c, n, sizeof(double));
        sj = hd__mpi_alloc(c, n, sizeof(uint64_t));
        packed = 1;
        if (!sd || !sj) rc = hd__mpi_nomem(c, "the answers", n);
        if (rc == HD_OK) {
            hd__mpi_gcur_t cu;
            memset(scount, 0, (size_t)K * sizeof(int));
            hd__mpi_gcur_init(&cu, &loc->gi[s]);
            for (size_t k = 0; k < n; k++) hd__mpi_gcur_at(&cu, k), scount[hd__mpi_gcur_rank(&cu)]++;
            for (int r = 0, at = 0; r < K; r++) sdispl[r] = cur[r] = at, at += scount[r];
            hd__mpi_gcur_init(&cu, &loc->gi[s]);
            for (size_t k = 0; k < n; k++) {
                hd__mpi_gcur_at(&cu, k);
                int r = hd__mpi_gcur_rank(&cu);
                sd[cur[r]] = d2[k];
                sj[cur[r]++] = j[k];
            }
            hd__mpi_free(c, d2, n, sizeof(double));
            hd__mpi_free(c, j, n, sizeof(uint64_t));
            *d2p = NULL, *jp = NULL, d2 = NULL, j = NULL;
        }
    }
    if (rc == HD_OK && own > INT_MAX)
        rc = hd__err(&c->e, HD_EOVERFLOW, "%zu points of %s on rank %d exceed MPI's int counts", own, s ? "B" : "A",
                     c->rank);
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    HD__MPI_GO(c, rc, MPI_Alltoall(scount, 1, MPI_INT, rcount, 1, MPI_INT, c->comm));
    for (int r = 0; r < K; r++) {
        rdispl[r] = (int)m;
        m += (size_t)rcount[r];
        if (r != c->rank) c->bytes_back += (uint64_t)scount[r] * (sizeof(double) + sizeof(uint64_t));
    }
    assert(m == own);
    /* The distances, then the indices: what was sent is freed before the
     * next receive buffer is had (8 bytes a point less at the peak). */
    if (!(rd = hd__mpi_alloc(c, m, sizeof(double)))) rc = hd__mpi_nomem(c, "the answers", m);
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    HD__MPI_GO(c, rc, MPI_Alltoallv(sd, scount, sdispl, MPI_DOUBLE, rd, rcount, rdispl, MPI_DOUBLE, c->comm));
    if (sd == *d2p) *d2p = NULL; /* not packed: the caller's array, freed here */
    hd__mpi_free(c, sd, n, sizeof(double));
    sd = NULL;
    if (!(rj = hd__mpi_alloc(c, m, sizeof(uint64_t)))) rc = hd__mpi_nomem(c, "the answers", m);
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    HD__MPI_GO(c, rc, MPI_Alltoallv(sj, scount, sdispl, MPI_UINT64_T, rj, rcount, rdispl, MPI_UINT64_T, c->comm));
    if (sj == *jp) *jp = NULL;
    hd__mpi_free(c, sj, n, sizeof(uint64_t));
    sj = NULL;
    packed = 0;
    /* The walk of the exchange again: each point's rank, and that rank's
     * next answer. */
    if ((rc = walk_order(c, in, s, &order, &base)) == HD_OK) {
        memcpy(cur, rdispl, (size_t)K * sizeof(int));
        for (size_t p = 0; p < in->nparts[s]; p++) {
            const hd_mpi_part_t *part = order[p];
            for (size_t k = 0; k < part->points.count; k++) {
                double x[3];
                hd__mpi_get_point(&part->points, k, x);
                int r = hd__mpi_rank_of(sp->tree, K, x, (uint64_t)s, part->offset + k);
                size_t at = (size_t)cur[r]++, slot = base[p] + k;
                if (o->dist[s]) o->dist[s][slot] = rd[at];
                if (o->nearest[s]) o->nearest[s][slot] = (size_t)rj[at];
            }
        }
        for (int r = 0; r < K; r++) assert(cur[r] == rdispl[r] + rcount[r]);
    }
done:
    if (packed) {
        hd__mpi_free(c, sd, n, sizeof(double));
        hd__mpi_free(c, sj, n, sizeof(uint64_t));
    }
    hd__mpi_free(c, rd, m, sizeof(double));
    hd__mpi_free(c, rj, m, sizeof(uint64_t));
    hd__mpi_free(c, cnt, 5 * (size_t)K, sizeof(int));
    if (order) walk_order_free(c, in, s, order, base);
    return rc;
}

/* ---- one direction ------------------------------------------------------- */

_Static_assert(sizeof(size_t) <= sizeof(uint64_t), "a position's slot holds a global index");

/* The n global indices of a local set in local order (8 bytes a point,
 * charged), or NULL when they cannot be had. */
static uint64_t *decode(hd__mpi_ctx_t *c, const hd__mpi_gidx_t *gi, size_t n) {
    uint64_t *g = hd__mpi_alloc(c, n, sizeof(uint64_t));
    if (g) hd__mpi_gidx_decode(gi, 0, n, g);
    return g;
}

#define PAIR_SAMPLES 64
#define PAIR_CHUNK 512 /* indices of P decoded at once by the partners' merge */

/* Whether the partners are worth their merge (an index decoded for every
 * point of both sides, wasted on unrelated sets: mpi_bench measures it): at least
 * half of PAIR_SAMPLES points of P, evenly spaced, have their partner
 * here and within the diagonal of its bucket's box (the scale of its
 * neighbours' spacing), as a copy's partners are; two independent
 * samplings of one scene have theirs anywhere.  The samples' indices are
 * decoded at random (a binary search over Q's), a few thousand decodes. */
static int partners_near(const hd__mpi_spread_t *sp, int s, const an_t *asking, const an_t *searched) {
    size_t nP = sp->loc.n[s], nQ = sp->loc.n[1 - s], m = nP < PAIR_SAMPLES ? nP : PAIR_SAMPLES, near = 0;
    const hd__mpi_gidx_t *gp = &sp->loc.gi[s], *gq = &sp->loc.gi[1 - s];
    const hd__an_t *t = &searched->s;
    for (size_t r = 0; r < m && nQ; r++) {
        size_t kp = r * nP / m, lo = 0, hi = nQ;
        uint64_t g = hd__mpi_gidx(gp, kp);
        while (lo < hi) {
            size_t mid = lo + (hi - lo) / 2;
            if (hd__mpi_gidx(gq, mid) < g) lo = mid + 1;
            else hi = mid;
        }
        if (lo == nQ || hd__mpi_gidx(gq, lo) != g) continue;
        uint32_t at = searched->pos[lo];
        size_t b0 = 0, b1 = t->nb; /* the bucket holding position at: start[b0] <= at < start[b0 + 1] */
        while (b1 - b0 > 1) {
            size_t mid = b0 + (b1 - b0) / 2;
            if (t->start[mid] <= at) b0 = mid;
            else b1 = mid;
        }
        uint32_t node = t->leaf[b0];
        double p[3], q[3], diag[3];
        for (int d = 0; d < 3; d++) diag[d] = t->hi[d][node] - t->lo[d][node];
        an_point(asking, kp, p);
        an_point(searched, lo, q);
        near += hd__d2(p, q) <= hd__d2(diag, (const double[3]){0, 0, 0});
    }
    return m > 0 && 2 * near >= m;
}

/* The partners of side s's local points when the two sides have one size
 * (hd_distances' partners: point i of one side tried first for point i of
 * the other, a copy and its original in one order settling fast): for
 * each point of `asking`, by its position there, the position in
 * `searched` of the local point of the other side with its global index,
 * or HD__AN_NO_PARTNER when that point is on another rank.  Both sides'
 * local orders are their global indices' order, so one merge of the two
 * finds them (gq: Q's indices in local order).  NULL (no partners) when
 * the array cannot be had: no answer depends on the partners. */
static uint32_t *partners(hd__mpi_ctx_t *c, const hd__mpi_spread_t *sp, int s, const an_t *asking, const an_t *searched,
                          const uint64_t *gq) {
    size_t nP = sp->loc.n[s], nQ = sp->loc.n[1 - s];
    uint32_t *at = nP && nQ ? hd__mpi_alloc(c, nP, sizeof(uint32_t)) : NULL;
    if (!at) return NULL;
    for (size_t k = 0; k < nP; k++) at[k] = HD__AN_NO_PARTNER;
    uint64_t gp[PAIR_CHUNK]; /* P's indices, a chunk at a time */
    for (size_t k0 = 0, kq = 0; k0 < nP && kq < nQ; k0 += PAIR_CHUNK) {
        size_t m = nP - k0 < PAIR_CHUNK ? nP - k0 : PAIR_CHUNK;
        hd__mpi_gidx_decode(&sp->loc.gi[s], k0, m, gp);
        for (size_t t = 0; t < m && kq < nQ; t++) {
            while (kq < nQ && gq[kq] < gp[t]) kq++;
            if (kq < nQ && gq[kq] == gp[t]) at[asking->pos[k0 + t]] = searched->pos[kq];
        }
    }
    return at;
}

/* Answers from the structure of local Q (forwarded queries). */
typedef struct {
    const an_t *searched;
    const hd__box_t *kb;
    size_t nQ;
    const hd__mpi_gidx_t *gQ;
} answer_t;

static int answer(hd__mpi_ctx_t *c, void *arg, const double *pts, size_t m, hd__mpi_ans_t *ans) {
    const answer_t *a = arg;
    if (m == 0) return HD_OK;
    if (a->nQ == 0) {
        for (size_t k = 0; k < m; k++) ans[k] = (hd__mpi_ans_t){INFINITY, UINT64_MAX};
        return HD_OK;
    }
    size_t *near = hd__mpi_alloc(c, m, sizeof(size_t));
    an_t asked;
    int rc = near ? an_of(c, pts, m, a->kb, &asked) : hd__mpi_nomem(c, "answers", m);
    if (rc == HD_OK)
        rc = hd__mpi_an_nearest(c, &asked.s, &a->searched->s, NULL, hd__thread_count(c->threads, m), near);
    hd__mpi_gcur_t cq;
    hd__mpi_gcur_init(&cq, a->gQ);
    for (size_t k = 0; k < m && rc == HD_OK; k++) {
        double q[3];
        an_point(a->searched, near[k], q);
        ans[k] = (hd__mpi_ans_t){hd__d2(pts + 3 * k, q), hd__mpi_gcur_at(&cq, near[k])};
    }
    if (near) an_free(c, &asked);
    hd__mpi_free(c, near, m, sizeof(size_t));
    return rc;
}

/* The exact answers of side s's local points against all of the other
 * side (steps 1 and 2), then returned (step 3).  `asking` and `searched`
 * are the structures of local P and local Q on the key box kb. */
static int direction(hd__mpi_ctx_t *c, const hd__mpi_spread_t *sp, const hd__mpi_input_t *in, int s, int paired,
                     const an_t *asking, const an_t *searched, const hd__box_t *kb, outs_t *o) {
    int K = c->K, rc = HD_OK, qs = 1 - s;
    const hd__mpi_local_t *loc = &sp->loc;
    size_t nP = loc->n[s], nQ = loc->n[qs], nf = 0;
    const hd__box_t *mine = &sp->region[c->rank];
    double *u2 = NULL;
    uint64_t *jj = NULL, *gq = NULL;
    /* near[k], the local position of point k's nearest, becomes jj[k], its
     * global index, in the same 8 bytes (size_t is at most as wide as
     * uint64_t: the bytes are moved, never read as the other type). */
    unsigned char *slot = hd__mpi_alloc(c, nP, sizeof(uint64_t));
    size_t *near = (size_t *)(void *)slot;
    hd__box_t *nbox = hd__mpi_alloc(c, (size_t)K - 1, sizeof(hd__box_t));
    int *list = hd__mpi_alloc(c, (size_t)K, sizeof(int));
    hd__mpi_pairs_t pr = {NULL, 0, 0};
    if (!slot || !nbox || !list) rc = hd__mpi_nomem(c, "the distances", nP);
    /* 1. The local pass: the partners first (when the sides have one size
     * and a sample finds them near), from Q's indices decoded in order. */
    double t0 = hd__now(), u0 = hd__mpi_cpu();
    if (rc == HD_OK && nP && nQ) {
        uint32_t *pair_at = NULL;
        if (paired && partners_near(sp, s, asking, searched) && (gq = decode(c, &loc->gi[qs], nQ)))
            pair_at = partners(c, sp, s, asking, searched, gq);
        hd__mpi_free(c, gq, nQ, sizeof(uint64_t)); /* decoded again below: not held in the search */
        gq = NULL;
        rc = hd__mpi_an_nearest(c, &asking->s, &searched->s, pair_at, hd__thread_count(c->threads, nP), near);
        hd__mpi_free(c, pair_at, nP, sizeof(uint32_t));
    }
    /* Then, once the search's arrays are freed, each point's exact squared
     * distance and global index.  near[] goes anywhere in Q: Q's indices
     * are decoded in order (8 bytes a point of Q), not one by one at
     * random.  Backwards, so that near[k] is read before its bytes are
     * overwritten whatever the width of size_t. */
    if (rc == HD_OK && nQ && !(gq = decode(c, &loc->gi[qs], nQ))) rc = hd__mpi_nomem(c, "the distances", nQ);
    if (rc == HD_OK && !(u2 = hd__mpi_alloc(c, nP, sizeof(double)))) rc = hd__mpi_nomem(c, "the distances", nP);
    for (size_t k = nP; k-- > 0 && rc == HD_OK;) {
        double p[3], q[3];
        uint64_t g = UINT64_MAX;
        an_point(asking, k, p);
        u2[k] = INFINITY;
        if (nQ) {
            an_point(searched, near[k], q);
            u2[k] = hd__d2(p, q);
            g = gq[near[k]];
        }
        memcpy(slot + k * sizeof g, &g, sizeof g);
    }
    jj = (uint64_t *)(void *)slot;
    hd__mpi_free(c, gq, nQ, sizeof(uint64_t));
    c->search += hd__now() - t0;
    c->search_cpu += hd__mpi_cpu() - u0;
    /* 2. The points whose faces are not clear ask the candidate ranks; the
     * forwarded ones are packed (few), with their answers so far. */
    if (rc == HD_OK) hd__mpi_node_boxes(sp->tree, 0, sp->held, qs, nbox);
    for (size_t k = 0; k < nP && rc == HD_OK; k++) {
        double p[3];
        an_point(asking, k, p);
        if (hd__mpi_faces_clear(mine, p, u2[k])) continue;
        c->shell++;
        int n = hd__mpi_asked(sp->tree, nbox, sp->held, K, qs, nQ == 0, p, u2[k], c->rank, list);
        if (n == 0) continue; /* no other rank holds a point as near */
        c->forwarded_points++;
        rc = hd__mpi_pairs_add(c, &pr, nf++, list, n);
    }
    double *fx = hd__mpi_alloc(c, nf, 3 * sizeof(double)), *fu = hd__mpi_alloc(c, nf, sizeof(double));
    uint64_t *fj = hd__mpi_alloc(c, nf, sizeof(uint64_t));
    size_t *fk = hd__mpi_alloc(c, nf, sizeof(size_t));
    if (rc == HD_OK && (!fx || !fu || !fj || !fk)) rc = hd__mpi_nomem(c, "forwarded queries", nf);
    for (size_t k = 0, f = 0; k < nP && f < nf && rc == HD_OK; k++) { /* the same points, in order */
        double p[3];
        an_point(asking, k, p);
        if (hd__mpi_faces_clear(mine, p, u2[k]) ||
            hd__mpi_asked(sp->tree, nbox, sp->held, K, qs, nQ == 0, p, u2[k], c->rank, list) == 0)
            continue;
        memcpy(fx + 3 * f, p, sizeof p);
        fu[f] = u2[k], fj[f] = jj[k], fk[f++] = k;
    }
    hd__mpi_free(c, nbox, (size_t)K - 1, sizeof(hd__box_t));
    hd__mpi_free(c, list, (size_t)K, sizeof(int));
    answer_t an = {searched, kb, nQ, &sp->loc.gi[qs]};
    rc = hd__mpi_round(c, rc, fx, NULL, &pr, answer, &an, fu, fj);
    for (size_t f = 0; f < nf && rc == HD_OK; f++) u2[fk[f]] = fu[f], jj[fk[f]] = fj[f];
    hd__mpi_pairs_free(c, &pr);
    hd__mpi_free(c, fx, nf, 3 * sizeof(double));
    hd__mpi_free(c, fu, nf, sizeof(double));
    hd__mpi_free(c, fj, nf, sizeof(uint64_t));
    hd__mpi_free(c, fk, nf, sizeof(size_t));
    /* 3. Back to the points' ranks. */
    if (rc == HD_OK) rc = give_back(c, sp, in, s, &u2, &jj, o);
    hd__mpi_free(c, u2, nP, sizeof(double));
    hd__mpi_free(c, jj, nP, sizeof(uint64_t));
    return rc;
}

/* ---- the call ------------------------------------------------------------ */

static int distances(hd__mpi_ctx_t *c, const hd_options_t *opt, hd__mpi_input_t *in, void *arg, hd_mpi_stats_t *st) {
    outs_t *o = arg;
    hd__mpi_course_t cs;
    hd__mpi_course_init(c, &cs);
    hd__mpi_spread_t *sp = &cs.sp;
    an_t an[2];
    memset(an, 0, sizeof an);
    int rc = hd__mpi_begin(c, opt, in, o, &cs.rg, cs.N, NULL);
    if (rc != HD_OK) goto done;
    uint64_t pts = in->n[0] + in->n[1];
    /* A direction runs when some rank asks for it. */
    int asks[2] = {o->dist[0] || o->nearest[0], o->dist[1] || o->nearest[1]}, want[2];
    HD__MPI_GO(c, rc, MPI_Allreduce(asks, want, 2, MPI_INT, MPI_MAX, c->comm));
    int ts = hd__mpi_tiny_side(c, cs.N);
    if (c->K == 1) {
        if ((rc = single(c, in, &cs.rg, want, o)) != HD_OK) goto done;
    } else if (ts >= 0 && (want[0] || want[1])) {
        if ((rc = tiny(c, in, &cs.rg, cs.N, ts, want, o)) != HD_OK) goto done;
    } else if (want[0] || want[1]) {
        if ((rc = hd__mpi_spread(c, in, &cs.rg, cs.N, NULL, sp)) != HD_OK) goto done;
        pts = sp->loc.n[0] + sp->loc.n[1];
        /* Both structures on one key box: the queries' groups and the
         * buckets they search are neighbours in memory (as hd_distances). */
        hd__box_t kb = sp->held[c->rank].box[0];
        hd__box_merge(&kb, &sp->held[c->rank].box[1]);
        double t1 = hd__now(), u1 = hd__mpi_cpu();
        for (int s = 0; s < 2 && rc == HD_OK; s++) { /* the coordinates move into the structures */
            rc = an_of_set(c, sp->loc.xyz[s], sp->loc.n[s], &kb, &an[s]);
            hd__mpi_free(c, sp->loc.xyz[s], sp->loc.n[s], 3 * sizeof(double));
            sp->loc.xyz[s] = NULL;
        }
        c->search += hd__now() - t1;
        c->search_cpu += hd__mpi_cpu() - u1;
        if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
        for (int s = 0; s < 2; s++)
            if (want[s] && (rc = direction(c, sp, in, s, cs.N[0] == cs.N[1], &an[s], &an[1 - s], &kb, o)) != HD_OK)
                goto done;
    }
    double tmax;
    rc = hd__mpi_figures(c, &cs, pts, st, &tmax);
done:
    an_free(c, &an[0]);
    an_free(c, &an[1]);
    hd__mpi_course_free(c, &cs);
    return rc;
}

int hd_mpi_distances(MPI_Comm comm, const hd_mpi_part_t *a, size_t na, const hd_mpi_part_t *b, size_t nb,
                     const hd_mpi_options_t *opt, double *dist_ab, size_t *nearest_ab, double *dist_ba,
                     size_t *nearest_ba, hd_mpi_stats_t *stats, hd_error_t *err) {
    outs_t o = {{dist_ab, dist_ba}, {nearest_ab, nearest_ba}};
    return hd__mpi_call(comm, a, na, b, nb, opt, distances, &o, stats, err);
}
