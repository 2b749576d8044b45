/*
 * exchange.c -- moving every point to the rank of its region (step 2 of
 * mpi.c's essay) with MPI_Alltoallv in rounds.
 *
 * Invariants.
 *  - A point travels as its coordinates and its 4-byte number (28 bytes);
 *    the receiver knows every sender's index runs (ranges.c), so the
 *    number names the global index.
 *  - Senders walk their parts in increasing offset order, so each
 *    sender's run at the receiver is in increasing index order; the run of
 *    source r is received at base + got, straight into its slot of the
 *    local arrays (no second copy of the points), and a rank's own points
 *    are copied from the input into their slot in the same walk.
 *  - A round sends at most C = max(n / 8, 4096) points of a rank, so the
 *    send buffer is at most 3.5 bytes a point (3.9 when it is made whole
 *    huge pages, as the other buffers freed here may be: hd__mpi_scratch);
 *    every rank runs the same number of rounds (the allreduced maximum),
 *    each three collectives.
 *  - After the rounds, local order is global index order: as received when
 *    the runs follow each other in index order, else after a K-way merge
 *    applied in place (the numbers become 8-byte indices first).  The
 *    indices are then held encoded (hd__mpi_gidx_t, gidx.c): each round's numbers
 *    are encoded as they arrive (still in the cache), as if the runs were
 *    in order, and encoded again from the merged indices when they were
 *    not; the numbers and indices are freed before the call goes on.
 *    Nothing reorders the local arrays' indices afterwards.
 *  - loc->box is the exact box of each side's local points, merged from
 *    each run as it lands (the rank's own, each sender's): the same points
 *    as the local arrays hold, in whatever order the merge leaves them.
 */
#include "mpi/partition.h"

#include <assert.h>
#include <limits.h>
#include <stdlib.h>

/* Merge order of K runs of g[] sorted by index: perm[o] is the position of
 * the o-th smallest index (the runs are [at, end) ranges of positions). */
typedef struct { size_t at, end; } run_t;

static void merge_order(const uint64_t *g, run_t *runs, int K, int *heap, uint32_t *perm) {
    int n = 0;
    for (int r = 0; r < K; r++) {
        if (runs[r].at == runs[r].end) continue;
        int k = n++; /* sift up */
        while (k > 0 && g[runs[heap[(k - 1) / 2]].at] > g[runs[r].at]) {
            heap[k] = heap[(k - 1) / 2];
            k = (k - 1) / 2;
        }
        heap[k] = r;
    }
    size_t out = 0;
    while (n > 0) {
        run_t *top = &runs[heap[0]];
        perm[out++] = (uint32_t)top->at;
        int r = heap[0];
        if (++top->at == top->end) r = heap[--n];
        int k = 0; /* sift r down from the root */
        for (;;) {
            int ch = 2 * k + 1;
            if (ch >= n) break;
            if (ch + 1 < n && g[runs[heap[ch + 1]].at] < g[runs[heap[ch]].at]) ch++;
            if (g[runs[heap[ch]].at] >= g[runs[r].at]) break;
            heap[k] = heap[ch];
            k = ch;
        }
        if (n > 0) heap[k] = r;
    }
}

/* xyz[o], g[o] = old xyz[perm[o]], g[perm[o]] for every o, in place: each
 * cycle of the permutation is followed once, and perm[o] = o marks o
 * done (perm is destroyed). */
static void permute(double *xyz, uint64_t *g, uint32_t *perm, size_t n) {
    for (size_t i = 0; i < n; i++) {
        if (perm[i] == i) continue;
        double t[3];
        memcpy(t, xyz + 3 * i, sizeof t);
        uint64_t tg = g[i];
        size_t j = i;
        for (;;) {
            size_t k = perm[j];
            perm[j] = (uint32_t)j;
            if (k == i) {
                memcpy(xyz + 3 * j, t, sizeof t);
                g[j] = tg;
                break;
            }
            memcpy(xyz + 3 * j, xyz + 3 * k, sizeof t);
            g[j] = g[k];
            j = k;
        }
    }
}

/* Where point t of the local input goes: one byte a point up to 256 ranks,
 * two up to 65536. */
static inline int dest_get(const void *d, int w, size_t t) {
    return w == 1 ? ((const uint8_t *)d)[t] : w == 2 ? ((const uint16_t *)d)[t] : (int)((const uint32_t *)d)[t];
}

static inline void dest_set(void *d, int w, size_t t, int r) {
    if (w == 1) ((uint8_t *)d)[t] = (uint8_t)r;
    else if (w == 2) ((uint16_t *)d)[t] = (uint16_t)r;
    else ((uint32_t *)d)[t] = (uint32_t)r;
}

/* A cursor over the local input in walking order (sides A then B, parts
 * in offset order): side s, part p, point k in it, and the next local
 * number of each side.  The passes run a tight loop over each part's
 * points, not a step function a point. */
typedef struct { int s; size_t p, k; uint64_t num[2]; } walk_t;

/* The points left in the cursor's part, after moving past finished parts
 * (0 at the end of the input). */
static size_t walk_avail(const hd__mpi_input_t *in, const hd_mpi_part_t **order[2], walk_t *w) {
    while (w->s < 2) {
        if (w->p < in->nparts[w->s]) {
            size_t n = order[w->s][w->p]->points.count;
            if (w->k < n) return n - w->k;
            w->p++, w->k = 0;
        } else {
            w->s++, w->p = 0, w->k = 0;
        }
    }
    return 0;
}

/* The box of n points (none: unchanged) merged into *b. */
static void box_run(hd__box_t *b, const double *xyz, size_t n) {
    if (n == 0) return;
    hd__box_t r;
    hd__box_of(xyz, n, &r);
    hd__box_merge(b, &r);
}

/* Where one part's run of points goes in a round: each point's
 * coordinates and number to its slot in the local arrays (lx, lo at
 * *own, when it stays) or in the send buffer (sx, so at sfill[2 r + s]).
 * Two ways, one result, chosen by the caller from how often consecutive
 * points change destination (the first pass counts it):
 *  - a branch on whether the point stays, for destinations in long runs
 *    (an input in space's order, as a rank reading its tiles has), where
 *    it is predicted;
 *  - tables indexed by it, with no branch, for destinations at random (an
 *    input in no spatial order: half the points stay at K = 2, and the
 *    branch was mispredicted as often, by callgrind's branch simulation;
 *    GCC turned plain ternaries back into the branch).  A rank's own
 *    block of the send buffer is empty, so its cursor, written back
 *    unchanged when a point stays, is never used.
 * Inlined with a constant `branchless`, so each way is its own loop. */
HD__INLINE void pack_run(const hd_points_t *v, const double *px, size_t k0, size_t m, const void *dest, int w,
                         size_t t, int me, int s, uint32_t num, double *lx, uint32_t *lo, size_t *own, double *sx,
                         uint32_t *so, int *sfill, int branchless) {
    double *const xto[2] = {sx, lx};
    uint32_t *const oto[2] = {so, lo};
    size_t cur[2] = {0, *own};
    for (size_t i = 0; i < m; i++, t++, num++) {
        int r = dest_get(dest, w, t);
        double *x;
        if (branchless) {
            int mine = r == me;
            cur[0] = (size_t)sfill[2 * r + s];
            size_t to = cur[mine];
            sfill[2 * r + s] = (int)cur[0] + !mine;
            cur[1] += (size_t)mine;
            x = xto[mine] + 3 * to;
            oto[mine][to] = num;
        } else if (r == me) {
            size_t to = cur[1]++;
            x = lx + 3 * to;
            lo[to] = num;
        } else {
            size_t to = (size_t)sfill[2 * r + s]++;
            x = sx + 3 * to;
            so[to] = num;
        }
        if (px) memcpy(x, px + 3 * (k0 + i), 3 * sizeof(double));
        else hd_points_get(v, k0 + i, x);
    }
    *own = cur[1];
}

/* Points sent per round by a rank: an eighth of its points (at least 64K),
 * so the send buffer is at most 28/8 = 3.5 bytes a point (the minimum
 * also makes the tests' larger sets take several rounds). */
#define ROUND_SHARE 8
#define ROUND_MIN 4096

/* Move every point to the rank of its region.  Each point goes as its
 * coordinates and a 4-byte number: its rank among the sender's points of
 * its set in index order (hd__mpi_ranges_t turns it back into the global index).
 * Each source's run is received straight into its slot of the local
 * arrays, in rounds of at most an eighth of the sender's points, so no
 * copy of all the points is ever held twice; a rank's own points are
 * copied from the input into their slot.  Runs are in index order, since
 * senders walk their parts in offset order; when the runs follow each
 * other in index order too (each rank's parts lie above the previous
 * rank's) the local arrays are in global order as received (loc->start:
 * each sender's run), else the numbers become indices and the arrays are
 * merged in place (a permutation from a K-way merge, 4 bytes a point;
 * loc->merged).  Either way loc->gi holds the indices encoded. */
int hd__mpi_exchange(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const hd__mpi_ranges_t *rg, const hd__mpi_node_t *tree, hd__mpi_local_t *loc) {
    int K = c->K, me = c->rank, rc = HD_OK, w = K <= 256 ? 1 : K <= 65536 ? 2 : 4;
    size_t nloc = (size_t)(in->n[0] + in->n[1]), C = nloc / ROUND_SHARE, sendcap = 0;
    if (C < ROUND_MIN) C = ROUND_MIN;
    /* ints per rank: totals sent tot[2] and received rtot[2]; this round's
     * per[2] and rper[2]; where each (rank, side) block of the send buffer
     * starts, sdisp[2], and a cursor in it, sfill[2]; one side's counts and
     * displacements for MPI: sc sd rcn rd */
    int *cnt = hd__mpi_alloc(c, 16 * (size_t)K, sizeof(int));
    /* base[s K + r], then got[s K + r]; then big[2 r + s], the first
     * pass's counts (tot) in size_t, checked against INT_MAX once */
    size_t *base = hd__mpi_alloc(c, 6 * (size_t)K, sizeof(size_t));
    void *dest = hd__mpi_scratch(c, nloc, (size_t)w);
    const hd_mpi_part_t **order[2] = {NULL, NULL};
    uint32_t *off[2] = {NULL, NULL};
    double *sx = NULL;
    uint32_t *so = NULL;
    uint32_t *perm = NULL;
    size_t permn = 0, gn = 0;
    uint64_t *g = NULL;      /* the indices of merged runs */
    run_t *runs = NULL;
    int *heap = NULL;
    for (int s = 0; s < 2; s++) order[s] = hd__mpi_alloc(c, in->nparts[s], sizeof *order[s]);
    if (!cnt || !base || !dest || !order[0] || !order[1]) rc = hd__mpi_nomem(c, "the exchange", nloc);
    int *tot = cnt, *rtot = cnt + 2 * K, *per = cnt + 4 * K, *rper = cnt + 6 * K, *sdisp = cnt + 8 * K,
        *sfill = cnt + 10 * K, *sc = cnt + 12 * K, *sd = cnt + 13 * K, *rcn = cnt + 14 * K, *rd = cnt + 15 * K;
    size_t *got = base + 2 * K, *big = base + 4 * K, own = 0, switches = 0; /* points whose destination is not the previous one's */
    /* The rounds: round q walks the input positions [tb[q], tb[q + 1]),
     * up to the (q + 1) C-th point for another rank (the last to the end),
     * and sends rcnt[q 2K + 2 r + s] points of side s to rank r. */
    size_t maxr = nloc / C + 2, nr = 1;
    size_t *tb = hd__mpi_alloc(c, maxr + 1, sizeof(size_t));
    int *rcnt = hd__mpi_alloc(c, maxr * 2 * (size_t)K, sizeof(int));
    if (rc == HD_OK && (!tb || !rcnt)) rc = hd__mpi_nomem(c, "the exchange's rounds", maxr);
    if (rc == HD_OK) {
        memset(big, 0, 2 * (size_t)K * sizeof(size_t));
        memset(rcnt, 0, maxr * 2 * (size_t)K * sizeof(int));
        size_t t = 0, out = 0, q = 0, cut = C; /* cut: where round q ends, (q + 1) C points sent */
        int prev = -1, *row = rcnt;              /* row: round q's counts */
        tb[0] = 0;
        for (int s = 0; s < 2; s++) {
            for (size_t p = 0; p < in->nparts[s]; p++) order[s][p] = &in->parts[s][p];
            qsort(order[s], in->nparts[s], sizeof *order[s], hd__mpi_by_offset);
            for (size_t p = 0; p < in->nparts[s]; p++) {
                const hd_points_t *v = &order[s][p]->points;
                const double *px = hd__mpi_packed(v);
                uint64_t g0 = order[s][p]->offset;
                for (size_t k = 0; k < v->count; k++, t++) {
                    double xb[3];
                    const double *x = px ? px + 3 * k : (hd_points_get(v, k, xb), xb);
                    int r = hd__mpi_rank_of(tree, K, x, (uint64_t)s, g0 + k);
                    dest_set(dest, w, t, r);
                    switches += (size_t)(r != prev);
                    prev = r;
                    big[2 * r + s]++;
                    /* No branch on whether the point stays: in an input
                     * that is not in space's order it does at random (half
                     * the points at K = 2), and the branch was mispredicted
                     * as often (callgrind's branch simulation). */
                    int other = r != me;
                    if (out == cut && other) tb[++q] = t, row += 2 * (size_t)K, cut += C;
                    assert(q < maxr && cut == (q + 1) * C && row == rcnt + q * 2 * (size_t)K);
                    row[2 * r + s] += other;
                    out += (size_t)other;
                }
            }
        }
        nr = q + 1;
        tb[nr] = nloc;
        for (int k = 0; k < 2 * K; k++) {
            if (big[k] > INT_MAX) rc = HD_EOVERFLOW;
            tot[k] = big[k] > INT_MAX ? INT_MAX : (int)big[k];
        }
        if (rc != HD_OK)
            rc = hd__err(&c->e, HD_EOVERFLOW, "more than 2^31 - 1 points of a set to send from rank %d to one rank",
                         c->rank);
        own = (size_t)tot[2 * me] + (size_t)tot[2 * me + 1];
        sendcap = nloc - own < C ? nloc - own : C;
        for (int r = 0; r < K; r++)
            if (r != me) c->bytes_part += ((uint64_t)tot[2 * r] + (uint64_t)tot[2 * r + 1]) * (3 * sizeof(double) + 4);
    }
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    HD__MPI_GO(c, rc, MPI_Alltoall(tot, 2, MPI_INT, rtot, 2, MPI_INT, c->comm));
    for (int s = 0; s < 2 && rc == HD_OK; s++) {
        size_t m = 0;
        for (int r = 0; r < K; r++) {
            base[s * K + r] = m;
            got[s * K + r] = 0;
            m += (size_t)rtot[2 * r + s];
        }
        loc->n[s] = m;
        for (int k = 0; k < 3; k++) loc->box[s].lo[k] = INFINITY, loc->box[s].hi[k] = -INFINITY;
        if (m > INT_MAX) {
            rc = hd__err(&c->e, HD_EOVERFLOW, "more than 2^31 - 1 points of %s to receive on rank %d",
                         s ? "B" : "A", c->rank);
            loc->n[0] = loc->n[1] = 0;
        }
    }
    for (int s = 0; s < 2 && rc == HD_OK; s++) {
        loc->xyz[s] = hd__mpi_alloc(c, loc->n[s], 3 * sizeof(double));
        off[s] = hd__mpi_scratch(c, loc->n[s], sizeof(uint32_t));
        if (!loc->xyz[s] || !off[s]) rc = hd__mpi_nomem(c, "the local points", loc->n[s]);
        else rc = hd__mpi_gidx_init(c, &loc->gi[s], rg, s, loc->n[s]);
    }
    if (rc == HD_OK) {
        sx = hd__mpi_scratch(c, sendcap, 3 * sizeof(double));
        so = hd__mpi_scratch(c, sendcap, sizeof(uint32_t));
        if (!sx || !so) rc = hd__mpi_nomem(c, "points to send", sendcap);
    }
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    uint64_t mine = nr, rounds = 0;
    HD__MPI_GO(c, rc, MPI_Allreduce(&mine, &rounds, 1, MPI_UINT64_T, MPI_MAX, c->comm));
    walk_t at = {0, 0, 0, {0, 0}};
    /* Destinations that change at more than a quarter of the points are
     * packed without a branch on them (pack_run): a branch mispredicted at
     * random costs more than the tables' few instructions a point, and an
     * input in space's order (tiles) keeps the branch, which is predicted
     * (mpi_bench times both orders; the figures are in docs/scale-out.md). */
    int scattered = switches > nloc / 4;
    size_t ownat[2] = {base[me], base[K + me]};
    for (uint64_t round = 0; round < rounds; round++) {
        if (round < nr) memcpy(per, rcnt + round * 2 * (size_t)K, 2 * (size_t)K * sizeof(int));
        else memset(per, 0, 2 * (size_t)K * sizeof(int));
        int pos = 0; /* the send buffer: A's blocks by rank, then B's */
        for (int s = 0; s < 2; s++)
            for (int r = 0; r < K; r++) {
                sdisp[2 * r + s] = sfill[2 * r + s] = pos;
                pos += per[2 * r + s];
            }
        size_t own0[2] = {ownat[0], ownat[1]};
        /* Pack the round's positions, a part's run at a time. */
        for (size_t t = round < nr ? tb[round] : nloc, t1 = round < nr ? tb[round + 1] : nloc; t < t1;) {
            size_t avail = walk_avail(in, order, &at), m = t1 - t < avail ? t1 - t : avail;
            assert(avail > 0);
            int s = at.s;
            const hd_points_t *v = &order[s][at.p]->points;
            const double *px = hd__mpi_packed(v);
            uint32_t num = (uint32_t)at.num[s];
            if (scattered)
                pack_run(v, px, at.k, m, dest, w, t, me, s, num, loc->xyz[s], off[s], &ownat[s], sx, so, sfill, 1);
            else
                pack_run(v, px, at.k, m, dest, w, t, me, s, num, loc->xyz[s], off[s], &ownat[s], sx, so, sfill, 0);
            t += m;
            at.k += m;
            at.num[s] += m;
        }
        /* The numbers are encoded, and the points' box taken, while in the
         * cache: the numbers as if the runs were in index order (else
         * encoded again below). */
        for (int s = 0; s < 2; s++) {
            hd__mpi_gidx_put_numbers(&loc->gi[s], rg, me, own0[s], off[s] + own0[s], ownat[s] - own0[s]);
            box_run(&loc->box[s], loc->xyz[s] + 3 * own0[s], ownat[s] - own0[s]);
        }
        HD__MPI_GO(c, rc, MPI_Alltoall(per, 2, MPI_INT, rper, 2, MPI_INT, c->comm));
        for (int s = 0; s < 2; s++) {
            for (int r = 0; r < K; r++) {
                sc[r] = per[2 * r + s];
                sd[r] = sdisp[2 * r + s];
                rcn[r] = rper[2 * r + s];
                rd[r] = (int)(base[s * K + r] + got[s * K + r]);
                got[s * K + r] += (size_t)rcn[r];
            }
            HD__MPI_GO(c, rc, MPI_Alltoallv(sx, sc, sd, c->q_type, loc->xyz[s], rcn, rd, c->q_type, c->comm));
            HD__MPI_GO(c, rc, MPI_Alltoallv(so, sc, sd, MPI_UINT32_T, off[s], rcn, rd, MPI_UINT32_T, c->comm));
            for (int r = 0; r < K; r++)
                if (r != me) {
                    hd__mpi_gidx_put_numbers(&loc->gi[s], rg, r, (size_t)rd[r], off[s] + rd[r], (size_t)rcn[r]);
                    box_run(&loc->box[s], loc->xyz[s] + 3 * (size_t)rd[r], (size_t)rcn[r]);
                }
        }
    }
    hd__mpi_free_scratch(c, sx, sendcap, 3 * sizeof(double));
    hd__mpi_free_scratch(c, so, sendcap, sizeof(uint32_t));
    hd__mpi_free_scratch(c, dest, nloc, (size_t)w);
    sx = NULL, so = NULL, dest = NULL;
    assert(ownat[0] == base[me] + (size_t)rtot[2 * me] && ownat[1] == base[K + me] + (size_t)rtot[2 * me + 1]);
    /* The runs in index order as received (each rank's parts above the
     * previous rank's): the numbers were encoded as received, and are
     * freed.  Else the numbers become indices (8 bytes), the runs are
     * merged into index order, and the indices are encoded afresh. */
    for (int s = 0; s < 2 && rc == HD_OK; s++) {
        loc->start[s] = hd__mpi_alloc(c, (size_t)K + 1, sizeof(size_t));
        if (!loc->start[s]) {
            rc = hd__mpi_nomem(c, "the local indices", (size_t)K);
            break;
        }
        int sorted = 1;
        uint64_t last = 0;
        for (int r = 0; r < K; r++) {
            size_t lo = base[s * K + r], hi = lo + (size_t)rtot[2 * r + s];
            loc->start[s][r] = lo;
            if (hi > lo) {
                if (lo > 0 && hd__mpi_ranges_global(rg, s, r, off[s][lo]) < last) sorted = 0;
                last = hd__mpi_ranges_global(rg, s, r, off[s][hi - 1]);
            }
        }
        loc->start[s][K] = loc->n[s];
        if (sorted) {
            hd__mpi_free_scratch(c, off[s], loc->n[s], sizeof(uint32_t));
            off[s] = NULL;
            continue;
        }
        loc->merged[s] = 1;
        g = hd__mpi_alloc(c, loc->n[s], sizeof(uint64_t));
        if (!g) {
            rc = hd__mpi_nomem(c, "the local indices", loc->n[s]);
            break;
        }
        gn = loc->n[s];
        for (int r = 0; r < K; r++) {
            size_t lo = base[s * K + r], hi = lo + (size_t)rtot[2 * r + s],
                   i = rg->seg[(size_t)s * ((size_t)K + 1) + (size_t)r];
            hd__mpi_ranges_globals(rg, s, r, &i, off[s] + lo, hi - lo, g + lo);
        }
        hd__mpi_free_scratch(c, off[s], loc->n[s], sizeof(uint32_t));
        off[s] = NULL;
        permn = loc->n[s];
        perm = hd__mpi_alloc(c, permn, sizeof(uint32_t));
        runs = hd__mpi_alloc(c, (size_t)K, sizeof(run_t));
        heap = hd__mpi_alloc(c, (size_t)K, sizeof(int));
        if (!perm || !runs || !heap) {
            rc = hd__mpi_nomem(c, "the merge", loc->n[s]);
            break;
        }
        for (int r = 0; r < K; r++) runs[r] = (run_t){base[s * K + r], base[s * K + r] + (size_t)rtot[2 * r + s]};
        merge_order(g, runs, K, heap, perm);
        permute(loc->xyz[s], g, perm, loc->n[s]);
        hd__mpi_free(c, perm, permn, sizeof(uint32_t));
        hd__mpi_free(c, runs, (size_t)K, sizeof(run_t));
        hd__mpi_free(c, heap, (size_t)K, sizeof(int));
        perm = NULL, runs = NULL, heap = NULL;
        hd__mpi_gidx_clear(&loc->gi[s]);
        hd__mpi_gidx_put_indices(&loc->gi[s], 0, g, loc->n[s]);
        hd__mpi_free(c, g, gn, sizeof(uint64_t));
        g = NULL;
    }
    rc = hd__mpi_agree(c, rc);
done:
    hd__mpi_free(c, tb, maxr + 1, sizeof(size_t));
    hd__mpi_free(c, rcnt, maxr * 2 * (size_t)K, sizeof(int));
    hd__mpi_free(c, cnt, 16 * (size_t)K, sizeof(int));
    hd__mpi_free(c, base, 6 * (size_t)K, sizeof(size_t));
    hd__mpi_free_scratch(c, dest, nloc, (size_t)w);
    for (int s = 0; s < 2; s++) {
        hd__mpi_free(c, order[s], in->nparts[s], sizeof *order[s]);
        hd__mpi_free_scratch(c, off[s], loc->n[s], sizeof(uint32_t));
    }
    hd__mpi_free_scratch(c, sx, sendcap, 3 * sizeof(double));
    hd__mpi_free_scratch(c, so, sendcap, sizeof(uint32_t));
    hd__mpi_free(c, perm, permn, sizeof(uint32_t));
    hd__mpi_free(c, runs, (size_t)K, sizeof(run_t));
    hd__mpi_free(c, heap, (size_t)K, sizeof(int));
    hd__mpi_free(c, g, gn, sizeof(uint64_t));
    return rc;
}
