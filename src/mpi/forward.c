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
 *  - One round of forwarding a direction: every bound is final before
 *    anything is sent.  Every collective is preceded by hd__mpi_agree.
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

/* Whether the shell's point k, at u2, is below (L, i_L) in the witness
 * order, so that it cannot be the witness (cu: a cursor on P's indices,
 * asked in increasing k). */
static int loses(hd__mpi_gcur_t *cu, const hd__mpi_shell_t *sh, size_t k, double u2, double L, uint64_t iL) {
    return u2 < L || (u2 == L && hd__mpi_shell_g(cu, sh, k) > iL);
}

/* The shell's points the first slab answered without proof
 * (sh->unproven) and that can still win: the answer each has now, the
 * slab's or a smaller one from another rank, is its nearest when the
 * slab's proof holds for it (every point of Q outside the slab is then
 * farther; inside, the slab's answer was the nearest); the others ask all
 * of Q (hd__mpi_nearest_in_q again), and the smaller answer is kept (d2
 * first, then the index).  The flags of the points settled without a
 * search are cleared on the way. */
static int resolve(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__box_t *mine, hd__mpi_qtree_t *q, const hd__mpi_shell_t *sh, double *u2,
                   uint64_t *jj, double L, uint64_t iL) {
    hd__mpi_gcur_t cp;
    size_t m = 0;
    hd__mpi_gcur_init(&cp, d->gP);
    for (size_t k = 0; k < sh->n; k++) {
        if (!sh->unproven[k]) continue;
        int settled = loses(&cp, sh, k, u2[k], L, iL) ||
                      hd__mpi_slab_proves(mine, q->M0, hd__mpi_shell_pt(d, sh, k), u2[k]);
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

int hd__mpi_direction(hd__mpi_ctx_t *c, const hd__mpi_dir_t *d, const hd__mpi_node_t *tree, const hd__box_t *region,
                     const hd__mpi_held_t *held, hd__mpi_far_t *result) {
    int K = c->K, rc = HD_OK;
    const hd__box_t *mine = &region[c->rank];
    hd__mpi_shell_t sh;
    hd__mpi_qtree_t q;
    memset(&q, 0, sizeof q);
    double t0 = hd__now(), u0 = hd__mpi_cpu();
    rc = hd__mpi_shell_of(c, d, mine, &q, &sh);
    c->search += hd__now() - t0;
    c->search_cpu += hd__mpi_cpu() - u0;
    c->shell += sh.n;
    size_t nP = sh.n;
    double *u2 = hd__mpi_alloc(c, nP, sizeof(double));
    uint64_t *jj = hd__mpi_alloc(c, nP, sizeof(uint64_t));
    unsigned char *exact = hd__mpi_alloc(c, nP, 1);
    hd__box_t *nbox = hd__mpi_alloc(c, K > 1 ? (size_t)K - 1 : 1, sizeof(hd__box_t));
    int *list = hd__mpi_alloc(c, (size_t)K, sizeof(int));
    hd__mpi_pairs_t pr = {NULL, 0, 0};
    if (rc == HD_OK && (!u2 || !jj || !exact || !nbox || !list)) rc = hd__mpi_nomem(c, "per-point bounds", nP);
    hd__mpi_far_t Lmine = sh.inner, Lall;
    hd__mpi_gcur_t cp, cq; /* P's indices (the shell's, in order) and Q's */
    if (rc == HD_OK) {
        hd__mpi_gcur_init(&cp, d->gP);
        hd__mpi_gcur_init(&cq, d->gQ);
        for (size_t k = 0; k < nP; k++) {
            const double *p = hd__mpi_shell_pt(d, &sh, k);
            if (d->nQ == 0) {
                u2[k] = INFINITY;
                jj[k] = UINT64_MAX;
                exact[k] = 0;
                continue;
            }
            u2[k] = hd__d2(p, d->Q + 3 * sh.nearest[k]);
            jj[k] = hd__mpi_gcur_at(&cq, sh.nearest[k]);
            /* an answer the first slab did not prove is not exact yet (resolve) */
            exact[k] = (unsigned char)(!(sh.unproven && sh.unproven[k]) && hd__mpi_faces_clear(mine, p, u2[k]));
            hd__mpi_far_t f = {u2[k], hd__mpi_shell_g(&cp, &sh, k), jj[k]};
            if (exact[k] && hd__mpi_far_better(&f, &Lmine)) Lmine = f;
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
        hd__mpi_free(c, nbox, K > 1 ? (size_t)K - 1 : 1, sizeof(hd__box_t));     \
        hd__mpi_free(c, list, (size_t)K, sizeof(int));                           \
        hd__mpi_pairs_free(c, &pr);                                              \
        u2 = NULL, jj = NULL, exact = NULL, nbox = NULL, list = NULL;            \
        hd__mpi_free(c, sh.nearest, sh.n, sizeof(size_t));                       \
        hd__mpi_free(c, sh.unproven, sh.n, 1);                                   \
        sh.nearest = NULL, sh.unproven = NULL;                                   \
        hd__mpi_qtree_free(c, &q);                                               \
    } while (0)
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    /* L and the smallest index i_L of a confirmed point at L: a point
     * with u2 < L, or u2 = L and a larger index, cannot be the witness. */
    HD__MPI_GO(c, rc, MPI_Allreduce(&Lmine, &Lall, 1, c->far_type, c->far_op, c->comm));
    double L = Lall.d2;
    uint64_t iL = Lall.i;
    /* The points to forward, as (point, rank) pairs. */
    hd__mpi_gcur_init(&cp, d->gP);
    for (size_t k = 0; k < nP && rc == HD_OK; k++) {
        if (exact[k] || loses(&cp, &sh, k, u2[k], L, iL)) continue;
        int n = hd__mpi_asked(tree, nbox, held, K, d->qside, d->nQ == 0, hd__mpi_shell_pt(d, &sh, k), u2[k],
                                c->rank, list);
        if (n == 0) {
            exact[k] = !(sh.unproven && sh.unproven[k]); /* no other rank holds a point as near */
            continue;
        }
        c->forwarded_points++;
        rc = hd__mpi_pairs_add(c, &pr, k, list, n);
    }
    answer_t an = {d, mine, &q};
    if ((rc = hd__mpi_round(c, rc, d->P, sh.own_pos, &pr, answer, &an, u2, jj)) != HD_OK) goto done;
    /* local: a failure goes on to the agreement below, as the interior's */
    if (nP && d->nQ) rc = resolve(c, d, mine, &q, &sh, u2, jj, L, iL);
    /* Every point that could win is now exact; the others cannot win (a
     * point at L with a larger index than i_L loses to i_L). */
    hd__mpi_far_t best = sh.inner;
    hd__mpi_gcur_init(&cp, d->gP);
    for (size_t k = 0; k < nP; k++) {
        if (loses(&cp, &sh, k, u2[k], L, iL)) continue;
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
