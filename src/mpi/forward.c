/*
 * forward.c -- one direction, h(P, Q), over the partition: the shell's
 * points that other ranks may hold a nearer point for are forwarded to
 * them, and the exact farthest point is reduced (steps 4 to 6 of mpi.c's
 * essay).
 *
 * Invariants.
 *  - A shell point is exact when its faces are clear of u(a)^2 (the face
 *    test: no other rank holds a point as near, nor one that ties), or
 *    when no other rank's box of Q lies within u(a) (hd__box_lb2 <= u2,
 *    ties included); else it is forwarded to exactly those ranks, which
 *    answer with their exact (d2, smallest global index), and the smaller
 *    pair is kept: the exact global answer.
 *  - L, the largest exact u^2 over all ranks with the smallest index i_L
 *    at L, bounds the result from below: a point below (L, i_L) in the
 *    witness order cannot be the witness and is not forwarded.  A point
 *    at exactly L with a smaller index is forwarded.
 *  - A shell point whose local answer the first slab did not prove
 *    (sh.unproven) is never exact before the round: its answer is a point
 *    of Q, an upper bound u2 of its nearest distance, so the ranks within
 *    it are a superset of those it needs, and u2 below (L, i_L) still
 *    means it cannot win.  After the round its answer is proven by the
 *    slab's test, or searched again in all of the local Q (resolve).
 *  - Bounds before forwarding.  Every rank holds the same sample of Q
 *    (sample_q: at most SAMPLE_TOTAL points, each rank's share in
 *    proportion to its points, in global index order; all of Q when Q
 *    has no more).  A shell point not yet exact takes the nearest sample
 *    point (d2, global index) when it is smaller (d2 first, then the
 *    index): a point of Q, so still an upper bound u2 of its nearest
 *    distance, and the ranks within it are those its exact answer needs;
 *    when the sample is all of Q it is the exact global answer (the
 *    smallest position on ties is the smallest index) and the point is
 *    exact.  Each shell point whose local answer is exact over the local
 *    Q (not unproven; infinite when Q is empty here) also has a lower
 *    bound lb = min(local u2, hd__box_lb2 of every other rank's box of Q):
 *    a computed lower bound of its global nearest, so h(P,Q)^2 >= lb.
 *    The largest lb enters L as (lb, UINT64_MAX), an index no point
 *    has: a point whose u2 < L cannot be the witness, and one at u2 = L
 *    still can (loses() never drops it), so ties are kept.
 *  - Two rounds of forwarding a direction: first the CULL_FIRST points of
 *    each rank with the largest u2 that may win; their exact answers
 *    raise L (as exact points, with their indices), then every other
 *    point that may still win goes in the second round.  Every bound is
 *    final before its round's points are sent.  Every collective is
 *    preceded by hd__mpi_agree.
 */
#include "mpi/search.h"

#include <limits.h>
#include <stdlib.h>

/* A forwarded query: point k of the asking set to rank dest. */
typedef struct hd__mpi_pair { size_t k; int dest; int pad; } hd__mpi_pair_t;

static int pack_queries(hd__mpi_ctx_t *c, const double *P, const uint32_t *pos, const hd__mpi_pair_t *pairs, size_t np,
                        int *scount, int *sdispl, double **send, size_t **order) {
    for (int r = 0; r < c->K; r++) scount[r] = 0;
    for (size_t t = 0; t < np; t++) scount[pairs[t].dest]++;
    size_t total = 0;
    for (int r = 0; r < c->K; r++) {
        sdispl[r] = (int)total;
        total += (size_t)scount[r];
    }
    *send = hd__mpi_alloc(c, np, 3 * sizeof(double));
    *order = hd__mpi_alloc(c, np, sizeof(size_t));
    if (!*send || !*order) return hd__mpi_nomem(c, "forwarded queries", np);
    int *fill = hd__mpi_alloc(c, (size_t)c->K, sizeof(int));
    if (!fill) return hd__mpi_nomem(c, "forwarded queries", np);
    memcpy(fill, sdispl, (size_t)c->K * sizeof(int));
    for (size_t t = 0; t < np; t++) {
        size_t at = (size_t)fill[pairs[t].dest]++;
        size_t k = pairs[t].k;
        memcpy(*send + 3 * at, P + 3 * (pos ? pos[k] : k), 3 * sizeof(double));
        (*order)[at] = pairs[t].k;
    }
    hd__mpi_free(c, fill, (size_t)c->K, sizeof(int));
    return HD_OK;
}

void hd__mpi_pairs_free(hd__mpi_ctx_t *c, hd__mpi_pairs_t *pr) {
    hd__mpi_free(c, pr->p, pr->cap, sizeof(hd__mpi_pair_t));
    memset(pr, 0, sizeof *pr);
}

int hd__mpi_pairs_add(hd__mpi_ctx_t *c, hd__mpi_pairs_t *pr, size_t k, const int *list, int n) {
    if (pr->n + (size_t)n > pr->cap) {
        size_t ncap = pr->cap ? 2 * pr->cap : 1024;
        while (ncap < pr->n + (size_t)n) ncap *= 2;
        hd__mpi_pair_t *grown = hd__mpi_alloc(c, ncap, sizeof(hd__mpi_pair_t));
        if (!grown) return hd__mpi_nomem(c, "forwarded queries", ncap);
        if (pr->n) memcpy(grown, pr->p, pr->n * sizeof(hd__mpi_pair_t));
        hd__mpi_free(c, pr->p, pr->cap, sizeof(hd__mpi_pair_t));
        pr->p = grown;
        pr->cap = ncap;
    }
    for (int t = 0; t < n; t++) pr->p[pr->n++] = (hd__mpi_pair_t){k, list[t], 0};
    return HD_OK;
}

int hd__mpi_round(hd__mpi_ctx_t *c, int rc, const double *P, const uint32_t *pos, const hd__mpi_pairs_t *pr,
                  hd__mpi_answer_t fn, void *arg, double *u2, uint64_t *jj) {
    int K = c->K;
    size_t np = pr->n, m = 0, *order = NULL;
    int *cnt = hd__mpi_alloc(c, 4 * (size_t)K, sizeof(int)); /* scount sdispl rcount rdispl */
    double *sendq = NULL, *recvq = NULL;
    hd__mpi_ans_t *ans = NULL, *back = NULL;
    if (rc == HD_OK && !cnt) rc = hd__mpi_nomem(c, "forwarded queries", np);
    int *scount = cnt, *sdispl = cnt + K, *rcount = cnt + 2 * K, *rdispl = cnt + 3 * K;
    if (rc == HD_OK && np > INT_MAX) rc = hd__err(&c->e, HD_EOVERFLOW, "%zu forwarded queries exceed MPI's int counts", np);
    if (rc == HD_OK) rc = pack_queries(c, P, pos, pr->p, np, scount, sdispl, &sendq, &order);
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    HD__MPI_GO(c, rc, MPI_Alltoall(scount, 1, MPI_INT, rcount, 1, MPI_INT, c->comm));
    for (int r = 0; r < K; r++) {
        if (m > INT_MAX) break;
        rdispl[r] = (int)m;
        m += (size_t)rcount[r];
    }
    if (m > INT_MAX) rc = hd__err(&c->e, HD_EOVERFLOW, "%zu queries received exceed MPI's int counts", m);
    if (rc == HD_OK) {
        recvq = hd__mpi_alloc(c, m, 3 * sizeof(double));
        ans = hd__mpi_alloc(c, m, sizeof(hd__mpi_ans_t));
        back = hd__mpi_alloc(c, np, sizeof(hd__mpi_ans_t));
        if (!recvq || !ans || !back) rc = hd__mpi_nomem(c, "forwarded queries", m);
    }
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    HD__MPI_GO(c, rc, MPI_Alltoallv(sendq, scount, sdispl, c->q_type, recvq, rcount, rdispl, c->q_type, c->comm));
    double t = hd__now(), u = hd__mpi_cpu();
    rc = fn(c, arg, recvq, m, ans);
    c->search += hd__now() - t;
    c->search_cpu += hd__mpi_cpu() - u;
    c->answered += m;
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    HD__MPI_GO(c, rc, MPI_Alltoallv(ans, rcount, rdispl, c->ans_type, back, scount, sdispl, c->ans_type, c->comm));
    c->rounds++;
    c->forwarded += np;
    c->bytes_fwd += (uint64_t)np * (3 * sizeof(double) + sizeof(hd__mpi_ans_t));
    for (size_t t = 0; t < np; t++) {
        size_t k = order[t];
        if (back[t].d2 < u2[k] || (back[t].d2 == u2[k] && back[t].g < jj[k])) {
            u2[k] = back[t].d2;
            jj[k] = back[t].g;
        }
    }
done:
    hd__mpi_free(c, cnt, 4 * (size_t)K, sizeof(int));
    hd__mpi_free(c, sendq, np, 3 * sizeof(double));
    hd__mpi_free(c, order, np, sizeof(size_t));
    hd__mpi_free(c, recvq, m, 3 * sizeof(double));
    hd__mpi_free(c, ans, m, sizeof(hd__mpi_ans_t));
    hd__mpi_free(c, back, np, sizeof(hd__mpi_ans_t));
    return rc;
}

/* Answer m queries against the local Q: exact nearest, smallest index. */
typedef struct {
    const hd__mpi_dir_t *d;
    const hd__box_t *mine;
    hd__mpi_qtree_t *q;
} answer_t;

static int answer(hd__mpi_ctx_t *c, void *arg, const double *pts, size_t m, hd__mpi_ans_t *ans) {
    const answer_t *a = arg;
    const hd__mpi_dir_t *d = a->d;
    if (m == 0) return HD_OK;
    if (d->nQ == 0) {
        for (size_t k = 0; k < m; k++) ans[k] = (hd__mpi_ans_t){INFINITY, UINT64_MAX};
        return HD_OK;
    }
    size_t *near = hd__mpi_alloc(c, m, sizeof(size_t));
    if (!near) return hd__mpi_nomem(c, "answers", m);
    int rc = hd__mpi_nearest_in_q(c, d, a->mine, a->q, pts, NULL, m, near, NULL);
    hd__mpi_gcur_t cq;
    hd__mpi_gcur_init(&cq, d->gQ);
    if (rc == HD_OK)
        for (size_t k = 0; k < m; k++)
            ans[k] = (hd__mpi_ans_t){hd__d2(pts + 3 * k, d->Q + 3 * near[k]), hd__mpi_gcur_at(&cq, near[k])};
    hd__mpi_free(c, near, m, sizeof(size_t));
    return rc;
}

/* The sample of Q every rank holds: at most this many points over all ranks. */
#define SAMPLE_TOTAL 4096
/* Points of each rank forwarded in the first round (the culling). */
#define CULL_FIRST 16

typedef struct {
    double *xyz;             /* n points, packed, in global index order */
    uint64_t *g;             /* their global indices */
    size_t n;
    int whole;               /* the sample is all of Q */
} qsample_t;

static void qsample_free(hd__mpi_ctx_t *c, qsample_t *qs) {
    hd__mpi_free(c, qs->xyz, qs->n, 3 * sizeof(double));
    hd__mpi_free(c, qs->g, qs->n, sizeof(uint64_t));
    memset(qs, 0, sizeof *qs);
}

static int by_g(const void *x, const void *y) {
    const hd__mpi_sample_t *a = x, *b = y;
    return (a->g > b->g) - (a->g < b->g);
}

/* The gathered sample in global index order: each rank's share is sorted
 * already (its positions increase, and local order is index order), at
 * cnt[K + r] with cnt[r] points, so the K runs are merged pairwise,
 * log2(K) passes over n, instead of sorted (indices are distinct: the
 * order is the same).  Returns the merged array (n, charged; `all` itself
 * when it is one run), or NULL when there is no room. */
static hd__mpi_sample_t *merge_runs(hd__mpi_ctx_t *c, hd__mpi_sample_t *all, size_t n, const int *cnt, int K) {
    size_t *b = hd__mpi_alloc(c, (size_t)K + 1, sizeof(size_t));
    hd__mpi_sample_t *tmp = hd__mpi_alloc(c, n ? n : 1, sizeof *tmp), *src = all, *dst = tmp;
    if (!b || !tmp) {
        hd__mpi_free(c, b, (size_t)K + 1, sizeof(size_t));
        hd__mpi_free(c, tmp, n ? n : 1, sizeof *tmp);
        return NULL;
    }
    size_t nb = 0; /* run t is [b[t], b[t + 1]) */
    for (int r = 0; r < K; r++)
        if (cnt[r]) b[nb++] = (size_t)cnt[K + r];
    b[nb] = n;
    while (nb > 1) {
        size_t m = 0;
        for (size_t t = 0; t < nb; t += 2) {
            size_t i = b[t], ie = b[t + 1], j = t + 1 < nb ? b[t + 1] : ie, je = t + 1 < nb ? b[t + 2] : ie, o = b[t];
            while (i < ie && j < je) dst[o++] = src[i].g < src[j].g ? src[i++] : src[j++];
            while (i < ie) dst[o++] = src[i++];
            while (j < je) dst[o++] = src[j++];
            b[m++] = b[t];
        }
        b[m] = n;
        nb = m;
        hd__mpi_sample_t *sw = src;
        src = dst, dst = sw;
    }
    hd__mpi_free(c, b, (size_t)K + 1, sizeof(size_t));
    if (src == all) { /* the runs merged back into all (or one run) */
        hd__mpi_free(c, tmp, n ? n : 1, sizeof *tmp);
        return all;
    }
    return tmp;
}

/* Each rank's share of the sample: all its points when Q has at most
 * SAMPLE_TOTAL, else n_r SAMPLE_TOTAL / N_Q of them (every rank computes
 * every share from held[]). */
static size_t sample_share(const hd__mpi_held_t *held, int r, int side, uint64_t NQ) {
    uint64_t n = held[r].n[side];
    return NQ <= SAMPLE_TOTAL ? (size_t)n : (size_t)(n * SAMPLE_TOTAL / NQ);
}

/* The sample of Q (collective; rc is the caller's status, agreed first):
 * rank r's share evenly spaced over its local Q, all-gathered and sorted
 * by global index. */
static int sample_q(hd__mpi_ctx_t *c, int rc, const hd__mpi_dir_t *d, const hd__mpi_held_t *held, qsample_t *qs) {
    int K = c->K;
    uint64_t NQ = 0;
    memset(qs, 0, sizeof *qs);
    for (int r = 0; r < K; r++) NQ += held[r].n[d->qside];
    size_t total = 0, mine = sample_share(held, c->rank, d->qside, NQ);
    for (int r = 0; r < K; r++) total += sample_share(held, r, d->qside, NQ);
    int *cnt = hd__mpi_alloc(c, 2 * (size_t)K, sizeof(int));
    hd__mpi_sample_t *own = hd__mpi_alloc(c, mine ? mine : 1, sizeof *own), *all = hd__mpi_alloc(c, total ? total : 1, sizeof *all);
    if (rc == HD_OK && (!cnt || !own || !all)) rc = hd__mpi_nomem(c, "the sample of the other set", total);
    if (rc == HD_OK) {
        qs->n = total;
        qs->whole = NQ <= SAMPLE_TOTAL;
        qs->xyz = hd__mpi_alloc(c, total, 3 * sizeof(double));
        qs->g = hd__mpi_alloc(c, total, sizeof(uint64_t));
        if (total && (!qs->xyz || !qs->g)) rc = hd__mpi_nomem(c, "the sample of the other set", total);
    }
    if (rc == HD_OK) {
        int t = 0;
        for (int r = 0; r < K; r++) cnt[r] = (int)sample_share(held, r, d->qside, NQ), cnt[K + r] = t, t += cnt[r];
        hd__mpi_gcur_t cq; /* the positions increase */
        hd__mpi_gcur_init(&cq, d->gQ);
        for (size_t k = 0; k < mine; k++) {
            size_t j = (size_t)((uint64_t)k * d->nQ / mine);
            memcpy(own[k].x, d->Q + 3 * j, sizeof own[k].x);
            own[k].g = hd__mpi_gcur_at(&cq, j);
            own[k].side = (uint64_t)d->qside;
        }
    }
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    HD__MPI_GO(c, rc, MPI_Allgatherv(own, (int)mine, c->sample_type, all, cnt, cnt + K, c->sample_type, c->comm));
    hd__mpi_sample_t *sorted = merge_runs(c, all, total, cnt, K);
    if (!sorted) qsort(all, total, sizeof *all, by_g), sorted = all; /* no room for the merge: the same order */
    for (size_t k = 0; k < total; k++) memcpy(qs->xyz + 3 * k, sorted[k].x, sizeof sorted[k].x), qs->g[k] = sorted[k].g;
    if (sorted != all) hd__mpi_free(c, sorted, total, sizeof *sorted);
done:
    hd__mpi_free(c, cnt, 2 * (size_t)K, sizeof(int));
    hd__mpi_free(c, own, mine ? mine : 1, sizeof *own);
    hd__mpi_free(c, all, total ? total : 1, sizeof *all);
    return rc;
}

/* Whether the shell's point k, at u2, is below (L, i_L) in the witness
 * order, so that it cannot be the witness (cu: a cursor on P's indices,
 * asked in increasing k). */
static int loses(hd__mpi_gcur_t *cu, const hd__mpi_shell_t *sh, size_t k, double u2, double L, uint64_t iL) {
    return u2 < L || (u2 == L && hd__mpi_shell_g(cu, sh, k) > iL);
}

/* loses(), remembered in exact[] (LOST): a point below (L, i_L) stays
 * below at every later step, since L only grows in the witness order and
 * an upper bound only falls, so its index is decoded once. */
#define LOST 4
static int lost(hd__mpi_gcur_t *cu, const hd__mpi_shell_t *sh, size_t k, double u2, double L, uint64_t iL,
                unsigned char *exact) {
    if (exact[k] & LOST) return 1;
    if (!loses(cu, sh, k, u2, L, iL)) return 0;
    exact[k] |= LOST;
    return 1;
}

/* Takes sample point j as point k's answer when smaller (d2 first, then
 * the index); returns its d2. */
static double offer(const hd__mpi_dir_t *d, const hd__mpi_shell_t *sh, const qsample_t *qs, size_t k, size_t j, double *u2,
                    uint64_t *jj) {
    double d2 = hd__d2(hd__mpi_shell_pt(d, sh, k), qs->xyz + 3 * j);
    if (d2 < u2[k] || (d2 == u2[k] && qs->g[j] < jj[k])) u2[k] = d2, jj[k] = qs->g[j];
    return d2;
}

/* The sample point nearest to the centre of the shell's box (a first
 * guess for every point of it). */
static size_t central(const hd__mpi_dir_t *d, const hd__mpi_shell_t *sh, const qsample_t *qs) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, m[3];
    for (size_t k = 0; k < sh->n; k++)
        for (int a = 0; a < 3; a++) {
            double x = hd__mpi_shell_pt(d, sh, k)[a];
            lo[a] = x < lo[a] ? x : lo[a], hi[a] = x > hi[a] ? x : hi[a];
        }
    for (int a = 0; a < 3; a++) m[a] = 0.5 * lo[a] + 0.5 * hi[a];
    size_t best = 0;
    double b2 = INFINITY;
    for (size_t j = 0; j < qs->n; j++) {
        double d2 = hd__d2(m, qs->xyz + 3 * j);
        if (d2 < b2) b2 = d2, best = j;
    }
    return best;
}

/* Before the sample's structure is built for many points (m marked in
 * exact[] with 2), a pilot: PILOT of them, evenly spread, take their
 * nearest sample point by brute force.  When none of them comes below L,
 * the sample is too sparse for these points (a lattice whose every point
 * is at L: a sample point is never that near), and the search is skipped
 * (returns 0): the bounds only spare work later, every point keeps the
 * upper bound it has, and the answers do not depend on them. */
#define PILOT 16
#define PILOT_MIN 256
static int pilot(const hd__mpi_dir_t *d, const hd__mpi_shell_t *sh, const qsample_t *qs, double L, double *u2, uint64_t *jj,
                 const unsigned char *exact, size_t m) {
    int below = 0;
    for (size_t k = 0, i = 0, t = 0; k < sh->n && t < PILOT; k++) {
        if (!(exact[k] & 2)) continue;
        if (i++ != t * m / PILOT) continue;
        t++;
        size_t best = 0;
        double b2 = INFINITY;
        for (size_t j = 0; j < qs->n; j++) {
            double d2 = hd__d2(hd__mpi_shell_pt(d, sh, k), qs->xyz + 3 * j);
            if (d2 < b2) b2 = d2, best = j;
        }
        below |= offer(d, sh, qs, k, best, u2, jj) < L;
    }
    return below;
}

/* The shell's points not yet exact take the sample's nearest point when
 * it is smaller (forward.c's invariants); with the whole of Q sampled
 * they become exact.  The paper's early break first: a point to which a
 * sample point is nearer than L (the central one, or the last one that
 * was) cannot be the witness, and takes that point, which keeps it below
 * L, without a search. */
static int sample_bounds(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, hd__mpi_shell_t *sh, const qsample_t *qs, double L,
                         uint64_t iL, double *u2, uint64_t *jj, unsigned char *exact) {
    size_t m = 0;
    if (qs->n == 0) return HD_OK;
    size_t guess[2] = {central(d, sh, qs), 0};
    guess[1] = guess[0];
    hd__mpi_gcur_t cp;
    hd__mpi_gcur_init(&cp, d->gP);
    for (size_t k = 0; k < sh->n; k++) {
        if (exact[k] || lost(&cp, sh, k, u2[k], L, iL, exact)) continue; /* a point that lost needs no bound */
        if (!qs->whole) {
            int t = 0;
            while (t < 2 && !(offer(d, sh, qs, k, guess[t], u2, jj) < L)) t++;
            if (t < 2) {
                guess[1] = guess[t];
                continue;
            }
        }
        exact[k] |= 2; /* searched below (a mark, cleared there) */
        m++;
    }
    if (m == 0 || m > HD__AN_MAX_POINTS || (!qs->whole && m >= PILOT_MIN && !pilot(d, sh, qs, L, u2, jj, exact, m))) {
        for (size_t k = 0; k < sh->n; k++) exact[k] &= (unsigned char)~2;
        return HD_OK;
    }
    /* The marked points in chunks of one batch: their positions, shell
     * numbers and answers take 16 bytes a point of a chunk, not of the
     * shell (a shell can be half a rank's points). */
    size_t batch = (d->nP + d->nQ) / 32 > 4096 ? (d->nP + d->nQ) / 32 : 4096, cap = m < batch ? m : batch;
    uint32_t *pos = hd__mpi_alloc(c, cap, sizeof(uint32_t)), *ks = hd__mpi_alloc(c, cap, sizeof(uint32_t));
    size_t *near = hd__mpi_alloc(c, cap, sizeof(size_t));
    int rc = pos && ks && near ? HD_OK : hd__mpi_nomem(c, "the searches", cap);
    for (size_t k = 0; k < sh->n;) {
        size_t t = 0;
        for (; k < sh->n && t < cap; k++) {
            if (!(exact[k] & 2)) continue;
            exact[k] = 0;
            if (rc == HD_OK) ks[t] = (uint32_t)k, pos[t] = sh->own_pos ? sh->own_pos[k] : (uint32_t)k;
            t++;
        }
        if (rc == HD_OK) rc = hd__mpi_nearest_among(c, qs->xyz, qs->n, d->P, pos, t, batch, near);
        for (size_t u = 0; u < t && rc == HD_OK; u++) {
            offer(d, sh, qs, ks[u], near[u], u2, jj);
            if (qs->whole) {
                exact[ks[u]] = 1;
                if (sh->unproven) sh->unproven[ks[u]] = 0;
            }
        }
    }
    hd__mpi_free(c, pos, cap, sizeof(uint32_t));
    hd__mpi_free(c, ks, cap, sizeof(uint32_t));
    hd__mpi_free(c, near, cap, sizeof(size_t));
    return rc;
}

/* A lower bound of the shell's point p's global nearest distance (its
 * local answer exact over the local Q: u2, infinite when Q is empty
 * here): the smaller of u2 and every other rank's box of Q. */
static double lower_bound(const hd__mpi_ctx_t *c, const hd__mpi_held_t *held, int side, const double *p, double u2) {
    double lb = u2;
    for (int r = 0; r < c->K; r++) {
        if (r == c->rank || held[r].n[side] == 0) continue;
        double b = hd__box_lb2(&held[r].box[side], p);
        lb = b < lb ? b : lb;
    }
    return lb;
}


/* The shell's points the first slab answered without proof
 * (sh->unproven) and that can still win: the answer each has now, the
 * slab's or a smaller one from another rank, is its nearest when the
 * slab's proof holds for it (every point of Q outside the slab is then
 * farther; inside, the slab's answer was the nearest); the others ask all
 * of Q (hd__mpi_nearest_in_q again), and the smaller answer is kept (d2
 * first, then the index).  A point whose answer is its partner, from no
 * search (HD__MPI_UNSEARCHED), is settled only by losing.  The flags of
 * the points settled without a search are cleared on the way. */
static int resolve(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__box_t *mine, hd__mpi_qtree_t *q, const hd__mpi_shell_t *sh, double *u2,
                   uint64_t *jj, unsigned char *exact, double L, uint64_t iL) {
    hd__mpi_gcur_t cp;
    size_t m = 0;
    hd__mpi_gcur_init(&cp, d->gP);
    for (size_t k = 0; k < sh->n; k++) {
        if (!sh->unproven[k]) continue;
        int settled = lost(&cp, sh, k, u2[k], L, iL, exact) ||
                      (sh->unproven[k] == 1 && hd__mpi_slab_proves(mine, q->M0, hd__mpi_shell_pt(d, sh, k), u2[k]));
        sh->unproven[k] = (unsigned char)!settled;
        m += !settled;
    }
    if (m == 0) return HD_OK;
    uint32_t *pos = hd__mpi_alloc(c, m, sizeof(uint32_t)), *ks = hd__mpi_alloc(c, m, sizeof(uint32_t));
    size_t *near = hd__mpi_alloc(c, m, sizeof(size_t));
    int rc = pos && ks && near ? HD_OK : hd__mpi_nomem(c, "the searches", m);
    for (size_t k = 0, t = 0; k < sh->n && rc == HD_OK; k++) {
        if (!sh->unproven[k]) continue;
        ks[t] = (uint32_t)k;
        pos[t++] = sh->own_pos ? sh->own_pos[k] : (uint32_t)k;
    }
    if (rc == HD_OK) rc = hd__mpi_nearest_in_q(c, d, mine, q, d->P, pos, m, near, NULL);
    for (size_t t = 0; t < m && rc == HD_OK; t++) {
        size_t k = ks[t];
        double d2 = hd__d2(hd__mpi_shell_pt(d, sh, k), d->Q + 3 * near[t]);
        uint64_t g = hd__mpi_gidx(d->gQ, near[t]);
        if (d2 < u2[k] || (d2 == u2[k] && g < jj[k])) u2[k] = d2, jj[k] = g;
    }
    hd__mpi_free(c, pos, m, sizeof(uint32_t));
    hd__mpi_free(c, ks, m, sizeof(uint32_t));
    hd__mpi_free(c, near, m, sizeof(size_t));
    return rc;
}

/* The best of L and what the shell's points bound h^2 with: each exact
 * point's (u2, index), and, when held is not NULL, each other point's
 * lower bound (lower_bound, for a local answer exact over the local Q)
 * with no index (forward.c's invariants). */
static hd__mpi_far_t bounds_below(const hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__mpi_shell_t *sh,
                                  const hd__mpi_held_t *held, const double *u2, const uint64_t *jj,
                                  const unsigned char *exact, hd__mpi_far_t L) {
    hd__mpi_gcur_t cp;
    hd__mpi_gcur_init(&cp, d->gP);
    for (size_t k = 0; k < sh->n; k++) {
        /* below L's d2, neither (u2[k], its index) nor a lower bound (at
         * most u2[k]) beats L: the index is decoded only when one may */
        if (u2[k] < L.d2 || (!(exact[k] & 1) && (!held || (sh->unproven && sh->unproven[k])))) continue;
        hd__mpi_far_t f = exact[k] & 1 ? (hd__mpi_far_t){u2[k], hd__mpi_shell_g(&cp, sh, k), jj[k]}
                                   : (hd__mpi_far_t){lower_bound(c, held, d->qside, hd__mpi_shell_pt(d, sh, k), u2[k]),
                                                     UINT64_MAX, UINT64_MAX};
        if (hd__mpi_far_better(&f, &L)) L = f;
    }
    return L;
}

/* One round of forwarding (collective; rc is the caller's status): every
 * shell point not exact, that may still win over (L, i_L), and, when
 * pick is not NULL, picked (pick[k] = 1), goes to the ranks that may
 * hold a point as near (ties included); one that none may is exact.  A
 * picked point forwarded is marked pick[k] = 2: it is exact after the
 * round (pick never holds an unproven point). */
static int forward(hd__mpi_ctx_t *c, int rc, const hd__mpi_dir_t *d, const hd__mpi_shell_t *sh, const hd__mpi_node_t *tree,
                   const hd__box_t *nbox, const hd__mpi_held_t *held, unsigned char *pick, double L, uint64_t iL,
                   int *list, answer_t *an, double *u2, uint64_t *jj, unsigned char *exact) {
    hd__mpi_pairs_t pr = {NULL, 0, 0};
    hd__mpi_gcur_t cp;
    hd__mpi_gcur_init(&cp, d->gP);
    for (size_t k = 0; k < sh->n && rc == HD_OK; k++) {
        if (exact[k] || (pick && !pick[k]) || lost(&cp, sh, k, u2[k], L, iL, exact)) continue;
        int n = hd__mpi_asked(tree, nbox, held, c->K, d->qside, d->nQ == 0, hd__mpi_shell_pt(d, sh, k), u2[k],
                              c->rank, list);
        if (n == 0) {
            exact[k] = !(sh->unproven && sh->unproven[k]); /* no other rank holds a point as near */
            continue;
        }
        c->forwarded_points++;
        if (pick) pick[k] = 2;
        rc = hd__mpi_pairs_add(c, &pr, k, list, n);
    }
    rc = hd__mpi_round(c, rc, d->P, sh->own_pos, &pr, answer, an, u2, jj);
    hd__mpi_pairs_free(c, &pr);
    return rc;
}

/* Picks (pick[k] = 1) the CULL_FIRST shell points with the largest u2
 * that are not exact, not unproven and may still win over (L, i_L). */
static void cull_pick(const hd__mpi_dir_t *d, const hd__mpi_shell_t *sh, const double *u2, unsigned char *exact,
                      double L, uint64_t iL, unsigned char *pick) {
    size_t top[CULL_FIRST], nt = 0;
    hd__mpi_gcur_t cp;
    hd__mpi_gcur_init(&cp, d->gP);
    memset(pick, 0, sh->n);
    for (size_t k = 0; k < sh->n; k++) {
        if (exact[k] || (sh->unproven && sh->unproven[k]) || lost(&cp, sh, k, u2[k], L, iL, exact)) continue;
        if (nt == CULL_FIRST && !(u2[k] > u2[top[nt - 1]])) continue;
        size_t t = nt < CULL_FIRST ? nt++ : nt - 1; /* insertion, largest first */
        for (; t > 0 && u2[top[t - 1]] < u2[k]; t--) top[t] = top[t - 1];
        top[t] = k;
    }
    for (size_t t = 0; t < nt; t++) pick[top[t]] = 1;
}

/* A rank holding no point of Q (two sets apart, one tiny side: every
 * point of P may be in its shell) keeps per-point state only for the
 * shell points that may still win after the sample's bounds; the others
 * lose to (L, i_L) now and at every later step, since L only grows and
 * an upper bound only falls (loses()), so dropping them changes no
 * answer.  Their lower bounds (lower_bound from the local Q's box, none
 * when Q is empty here, and every other rank's) enter L as bounds_below
 * enters them, computed without arrays.  A deferred shell (shell.c: most
 * of P, not searched one by one) takes the same course, and its points
 * that may still win are then searched in the local Q (deferred_answers). */
static hd__mpi_far_t one_sided_below(const hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__mpi_shell_t *sh,
                                     const hd__mpi_held_t *held, hd__mpi_far_t L) {
    const hd__box_t *own = &held[c->rank].box[d->qside];
    for (size_t k = 0; k < sh->n; k++) {
        const double *p = hd__mpi_shell_pt(d, sh, k);
        double lb = d->nQ ? hd__box_lb2(own, p) : INFINITY; /* the local Q's box: below every local answer */
        hd__mpi_far_t f = {lower_bound(c, held, d->qside, p, lb), UINT64_MAX, UINT64_MAX};
        if (hd__mpi_far_better(&f, &L)) L = f;
    }
    return L;
}

/* The sample's bounds (sample_bounds) on P's positions pos[0..n) as a
 * shell of their own, into arrays of n. */
static int one_sided_bounds(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const qsample_t *qs, hd__mpi_far_t L,
                            uint32_t *pos, size_t n, double *u2, uint64_t *jj, unsigned char *exact) {
    hd__mpi_shell_t part;
    memset(&part, 0, sizeof part);
    part.n = n;
    part.own_pos = pos;
    for (size_t k = 0; k < n; k++) u2[k] = INFINITY, jj[k] = UINT64_MAX, exact[k] = 0;
    return sample_bounds(c, d, &part, qs, L.d2, L.i, u2, jj, exact);
}

static int one_sided_loses(const hd__mpi_dir_t *d, uint32_t pos, double u2, hd__mpi_far_t L) {
    return u2 < L.d2 || (u2 == L.d2 && hd__mpi_gidx(d->gP, pos) > L.i);
}

/* The shell of a rank without Q (all of P), or a deferred one (shell.c:
 * most of P, no local answers yet), cut to the points that may still win: the sample's bounds a chunk of P at a time
 * mark them (a bit each), then their bounds are computed again into
 * arrays of their number (the same answers: a point kept had no sample
 * point below L, so both passes searched the whole sample for it, and the
 * nearest sample point, d2 first, then the index, does not depend on the
 * order).  On success the shell is the kept positions and *u2, *jj,
 * *exact hold *n of them. */
static int one_sided_shell(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, hd__mpi_shell_t *sh, const qsample_t *qs,
                           hd__mpi_far_t L, double **u2, uint64_t **jj, unsigned char **exact, size_t *n) {
    size_t nP = sh->n, ch = nP / 8 > 65536 ? nP / 8 : 65536, kept = 0, nb = (nP + 7) / 8;
    if (ch > nP) ch = nP;
    uint32_t *pos = hd__mpi_alloc(c, ch, sizeof(uint32_t));
    double *cu = hd__mpi_alloc(c, ch, sizeof(double));
    uint64_t *cj = hd__mpi_alloc(c, ch, sizeof(uint64_t));
    unsigned char *ce = hd__mpi_alloc(c, ch, 1), *win = hd__mpi_alloc(c, nb, 1);
    int rc = pos && cu && cj && ce && win ? HD_OK : hd__mpi_nomem(c, "per-point bounds", ch);
    if (rc == HD_OK) memset(win, 0, nb);
    for (size_t k0 = 0; k0 < nP && rc == HD_OK; k0 += ch) {
        size_t m = nP - k0 < ch ? nP - k0 : ch;
        for (size_t t = 0; t < m; t++) pos[t] = sh->own_pos ? sh->own_pos[k0 + t] : (uint32_t)(k0 + t);
        rc = one_sided_bounds(c, d, qs, L, pos, m, cu, cj, ce);
        for (size_t t = 0; t < m && rc == HD_OK; t++)
            if (!one_sided_loses(d, pos[t], cu[t], L)) win[(k0 + t) / 8] |= (unsigned char)(1u << ((k0 + t) % 8)), kept++;
    }
    hd__mpi_free(c, pos, ch, sizeof(uint32_t));
    hd__mpi_free(c, cu, ch, sizeof(double));
    hd__mpi_free(c, cj, ch, sizeof(uint64_t));
    hd__mpi_free(c, ce, ch, 1);
    uint32_t *kp = NULL;
    double *ku = NULL;
    uint64_t *kj = NULL;
    unsigned char *ke = NULL;
    if (rc == HD_OK) {
        kp = hd__mpi_alloc(c, kept, sizeof(uint32_t));
        ku = hd__mpi_alloc(c, kept, sizeof(double));
        kj = hd__mpi_alloc(c, kept, sizeof(uint64_t));
        ke = hd__mpi_alloc(c, kept, 1);
        if (!kp || !ku || !kj || !ke) rc = hd__mpi_nomem(c, "per-point bounds", kept);
    }
    for (size_t k = 0, t = 0; k < nP && rc == HD_OK; k++)
        if (win[k / 8] >> (k % 8) & 1) kp[t++] = sh->own_pos ? sh->own_pos[k] : (uint32_t)k;
    hd__mpi_free(c, win, nb, 1);
    if (rc == HD_OK) rc = one_sided_bounds(c, d, qs, L, kp, kept, ku, kj, ke);
    if (rc != HD_OK) {
        hd__mpi_free(c, kp, kept, sizeof(uint32_t));
        hd__mpi_free(c, ku, kept, sizeof(double));
        hd__mpi_free(c, kj, kept, sizeof(uint64_t));
        hd__mpi_free(c, ke, kept, 1);
        return rc;
    }
    hd__mpi_free(c, sh->own_pos, sh->n, sizeof(uint32_t));
    sh->own_pos = kp;
    sh->n = kept;
    *u2 = ku, *jj = kj, *exact = ke, *n = kept;
    return HD_OK;
}

/* A deferred shell's points, once cut (one_sided_shell), get their
 * nearest in the local Q (hd__mpi_nearest_in_q: exact, or a point of the
 * first slab, marked unproven for resolve), kept when smaller than the
 * sample's (d2 first, then the index); a point is exact when its answer is
 * proven and its faces are clear of it (then no other rank holds a point
 * as near: the sample's point, if it came from another rank, would lie
 * beyond a face within u), or when the whole of Q was the sample. */
static int deferred_answers(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__box_t *mine, hd__mpi_qtree_t *q,
                            hd__mpi_shell_t *sh, double *u2, uint64_t *jj, unsigned char *exact) {
    size_t n = sh->n;
    size_t *near = hd__mpi_alloc(c, n, sizeof(size_t));
    sh->unproven = hd__mpi_alloc(c, n, 1);
    if (!near || !sh->unproven) {
        hd__mpi_free(c, near, n, sizeof(size_t));
        return hd__mpi_nomem(c, "nearest neighbours", n);
    }
    memset(sh->unproven, 0, n);
    int rc = hd__mpi_nearest_in_q(c, d, mine, q, d->P, sh->own_pos, n, near, sh->unproven);
    hd__mpi_gcur_t cq;
    hd__mpi_gcur_init(&cq, d->gQ);
    for (size_t k = 0; k < n && rc == HD_OK; k++) {
        const double *p = hd__mpi_shell_pt(d, sh, k);
        if (near[k] != SIZE_MAX) {
            double d2 = hd__d2(p, d->Q + 3 * near[k]);
            uint64_t g = hd__mpi_gcur_at(&cq, near[k]);
            if (d2 < u2[k] || (d2 == u2[k] && g < jj[k])) u2[k] = d2, jj[k] = g;
        }
        if (exact[k] & 1) sh->unproven[k] = 0; /* the sample was all of Q */
        else exact[k] = (unsigned char)(!sh->unproven[k] && hd__mpi_faces_clear(mine, p, u2[k]));
    }
    hd__mpi_free(c, near, n, sizeof(size_t));
    return rc;
}

int hd__mpi_direction(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__mpi_node_t *tree, const hd__box_t *region,
                     const hd__mpi_held_t *held, hd__mpi_far_t *result) {
    int K = c->K, rc = HD_OK;
    const hd__box_t *mine = &region[c->rank];
    hd__mpi_shell_t sh;
    hd__mpi_qtree_t q;
    qsample_t qs;
    memset(&q, 0, sizeof q);
    memset(&qs, 0, sizeof qs);
    double t0 = hd__now(), u0 = hd__mpi_cpu();
    rc = hd__mpi_shell_of(c, d, mine, &q, &sh);
    c->search += hd__now() - t0;
    c->search_cpu += hd__mpi_cpu() - u0;
    c->shell += sh.n;
    /* one: the rank holds no Q; its shell is cut after the sample's
     * bounds (one_sided_shell), and its arrays are had then */
    int one = rc == HD_OK && sh.n > 0 && (d->nQ == 0 || sh.deferred);
    size_t nP = one ? 0 : sh.n;
    /* Each point's answer's index takes the slot of its local nearest
     * position (written once read, by memcpy: the slot's type becomes
     * uint64_t's), so the two are never held at once. */
    _Static_assert(sizeof(size_t) == sizeof(uint64_t), "a position's slot holds an index");
    uint64_t *jj = sh.nearest ? (uint64_t *)(void *)sh.nearest : hd__mpi_alloc(c, nP, sizeof(uint64_t));
    size_t *near = sh.nearest;
    sh.nearest = NULL;
    double *u2 = hd__mpi_alloc(c, nP, sizeof(double));
    unsigned char *exact = hd__mpi_alloc(c, nP, 1), *pick = hd__mpi_alloc(c, nP, 1);
    hd__box_t *nbox = hd__mpi_alloc(c, K > 1 ? (size_t)K - 1 : 1, sizeof(hd__box_t));
    int *list = hd__mpi_alloc(c, (size_t)K, sizeof(int));
    if (rc == HD_OK && (!u2 || !jj || !exact || !pick || !nbox || !list)) rc = hd__mpi_nomem(c, "per-point bounds", nP);
    hd__mpi_far_t Lmine = sh.inner, Lall;
    hd__mpi_gcur_t cp, cq; /* P's indices (the shell's, in order) and Q's */
    if (rc == HD_OK) {
        hd__mpi_gcur_init(&cq, d->gQ);
        for (size_t k = 0; k < nP; k++) {
            const double *p = hd__mpi_shell_pt(d, &sh, k);
            if (d->nQ == 0) {
                u2[k] = INFINITY;
                jj[k] = UINT64_MAX;
                exact[k] = 0;
                continue;
            }
            size_t j = near[k];
            uint64_t g = hd__mpi_gcur_at(&cq, j);
            u2[k] = hd__d2(p, d->Q + 3 * j);
            memcpy(&jj[k], &g, sizeof g);
            /* an answer the first slab did not prove is not exact yet (resolve) */
            exact[k] = (unsigned char)(!(sh.unproven && sh.unproven[k]) && hd__mpi_faces_clear(mine, p, u2[k]));
        }
        if (K > 1) hd__mpi_node_boxes(tree, 0, held, d->qside, nbox);
    }
    /* What the searches and the forwarding held, freed before the
     * interior's engine call (and on failure). */
#define DIRECTION_FREE()                                                         \
    do {                                                                         \
        hd__mpi_free(c, u2, nP, sizeof(double));                                 \
        hd__mpi_free(c, jj, nP, sizeof(uint64_t));                               \
        hd__mpi_free(c, exact, nP, 1);                                           \
        hd__mpi_free(c, pick, nP, 1);                                            \
        hd__mpi_free(c, nbox, K > 1 ? (size_t)K - 1 : 1, sizeof(hd__box_t));     \
        hd__mpi_free(c, list, (size_t)K, sizeof(int));                           \
        u2 = NULL, jj = NULL, exact = NULL, pick = NULL, nbox = NULL, list = NULL; \
        hd__mpi_free(c, sh.nearest, sh.n, sizeof(size_t));                       \
        hd__mpi_free(c, sh.unproven, sh.n, 1);                                   \
        sh.nearest = NULL, sh.unproven = NULL;                                   \
        hd__mpi_qtree_free(c, &q);                                               \
        qsample_free(c, &qs);                                                    \
    } while (0)
    /* Bounds before forwarding: the exact points and every lower bound
     * into L (with the smallest index i_L of a confirmed point at L, none
     * for a lower bound: a point with u2 < L, or u2 = L and a larger
     * index, cannot be the witness); then the sample's upper bounds. */
    if (rc == HD_OK) Lmine = one ? one_sided_below(c, d, &sh, held, Lmine) : bounds_below(c, d, &sh, held, u2, jj, exact, Lmine);
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    HD__MPI_GO(c, rc, MPI_Allreduce(&Lmine, &Lall, 1, c->far_type, c->far_op, c->comm));
    if ((rc = sample_q(c, rc, d, held, &qs)) != HD_OK) goto done;
    t0 = hd__now(), u0 = hd__mpi_cpu();
    if (one) {
        hd__mpi_free(c, u2, 0, sizeof(double));
        hd__mpi_free(c, jj, 0, sizeof(uint64_t));
        hd__mpi_free(c, exact, 0, 1);
        hd__mpi_free(c, pick, 0, 1);
        u2 = NULL, jj = NULL, exact = NULL, pick = NULL;
        rc = one_sided_shell(c, d, &sh, &qs, Lall, &u2, &jj, &exact, &nP);
        if (rc == HD_OK && !(pick = hd__mpi_alloc(c, nP, 1))) rc = hd__mpi_nomem(c, "per-point bounds", nP);
        if (rc == HD_OK && d->nQ) rc = deferred_answers(c, d, mine, &q, &sh, u2, jj, exact);
    } else {
        rc = sample_bounds(c, d, &sh, &qs, Lall.d2, Lall.i, u2, jj, exact);
    }
    c->search += hd__now() - t0;
    c->search_cpu += hd__mpi_cpu() - u0;
    answer_t an = {d, mine, &q};
    /* The first round: the few likeliest to win; their exact answers,
     * and those the whole sample made exact, raise L. */
    if (rc == HD_OK) cull_pick(d, &sh, u2, exact, Lall.d2, Lall.i, pick);
    if ((rc = forward(c, rc, d, &sh, tree, nbox, held, pick, Lall.d2, Lall.i, list, &an, u2, jj, exact)) != HD_OK) goto done;
    for (size_t k = 0; k < nP; k++) exact[k] |= pick[k] == 2;
    Lmine = bounds_below(c, d, &sh, NULL, u2, jj, exact, Lall);
    HD__MPI_GO(c, rc, MPI_Allreduce(&Lmine, &Lall, 1, c->far_type, c->far_op, c->comm));
    double L = Lall.d2;
    uint64_t iL = Lall.i;
    /* The second round: every other point that may still win. */
    if ((rc = forward(c, rc, d, &sh, tree, nbox, held, NULL, L, iL, list, &an, u2, jj, exact)) != HD_OK) goto done;
    /* local: a failure goes on to the agreement below, as the interior's */
    if (nP && d->nQ) rc = resolve(c, d, mine, &q, &sh, u2, jj, exact, L, iL);
    /* Every point that could win is now exact; the others cannot win (a
     * point at L with a larger index than i_L loses to i_L). */
    hd__mpi_far_t best = sh.inner;
    hd__mpi_gcur_init(&cp, d->gP);
    for (size_t k = 0; k < nP; k++) {
        if (lost(&cp, &sh, k, u2[k], L, iL, exact)) continue;
        hd__mpi_far_t f = {u2[k], hd__mpi_shell_g(&cp, &sh, k), jj[k]};
        if (hd__mpi_far_better(&f, &best)) best = f;
    }
    /* The interior's maximum, when not known, is needed only where the
     * engine's answer (h2, a*), a* in the shell, beats the best known
     * over all ranks: every interior point is below (h2, a*) (u <= h2,
     * and a* is the smallest index at h2), so it cannot beat what (h2, a*)
     * does not. */
    DIRECTION_FREE();
    hd__mpi_far_t G;
    HD__MPI_GO(c, rc, MPI_Allreduce(&best, &G, 1, c->far_type, c->far_op, c->comm));
    if (rc == HD_OK && sh.lazy && hd__mpi_far_better(&sh.h, &G)) {
        hd__mpi_far_t I = {-1.0, UINT64_MAX, UINT64_MAX};
        double t1 = hd__now(), u1 = hd__mpi_cpu();
        rc = hd__mpi_interior_max(c, d, mine, &sh, sh.h.d2, &G, &I);
        c->search += hd__now() - t1;
        c->search_cpu += hd__mpi_cpu() - u1;
        c->interior_passes++;
        if (hd__mpi_far_better(&I, &best)) best = I;
    }
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    HD__MPI_GO(c, rc, MPI_Allreduce(&best, result, 1, c->far_type, c->far_op, c->comm));
done:
    DIRECTION_FREE();
    hd__mpi_shell_free(c, &sh);
    return rc;
#undef DIRECTION_FREE
}
