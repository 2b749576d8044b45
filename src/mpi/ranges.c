/*
 * ranges.c -- the validation of a call's input and the index runs that name
 * every point (ranges.h's hd__mpi_ranges_t).
 *
 * Invariants.
 *  - hd__mpi_check_local refuses, before a point is read, more than
 *    2^32 - 1 points of a set on one rank (the exchange numbers a rank's
 *    points in 4 bytes, and the engine takes no more), and scans every
 *    point once (finite, within the range of hd__points_scan) with the
 *    local boxes.  It is local: the caller agrees on its status.
 *  - hd__mpi_check_ranges all-gathers every rank's nonempty parts as index
 *    runs and refuses two runs of one set that share an index, so a
 *    global index names one point over all ranks.  Sorted by (set, rank,
 *    first index), the runs turn a point's number (its rank among its
 *    sender's points of the set in index order) into its global index:
 *    number m lies in the last run whose first number is <= m.  Sorted by
 *    (set, first index), with the count of the set's indices below each
 *    (ord), they number a set's indices densely (the ordinals gidx.c
 *    encodes).
 */
#include "mpi/ranges.h"

#include <assert.h>
#include <string.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>

/* Part k of side s in increasing offset order (parts do not share
 * indices, so this is increasing global index order). */
int hd__mpi_by_offset(const void *x, const void *y) {
    const hd_mpi_part_t *p = *(const hd_mpi_part_t *const *)x, *q = *(const hd_mpi_part_t *const *)y;
    return p->offset < q->offset ? -1 : p->offset > q->offset;
}

int hd__mpi_by_range(const void *x, const void *y) {
    const hd__mpi_range_t *p = x, *q = y;
    if (p->side != q->side) return p->side - q->side;
    return p->lo < q->lo ? -1 : p->lo > q->lo;
}

static int by_owner(const void *x, const void *y) {
    const hd__mpi_range_t *p = x, *q = y;
    if (p->side != q->side) return p->side - q->side;
    if (p->rank != q->rank) return p->rank - q->rank;
    return p->lo < q->lo ? -1 : p->lo > q->lo;
}

void hd__mpi_ranges_free(hd__mpi_ctx_t *c, hd__mpi_ranges_t *rg) {
    hd__mpi_free(c, rg->all, rg->total, sizeof(hd__mpi_range_t));
    if (rg->seg) hd__mpi_free(c, rg->seg, 2 * ((size_t)rg->K + 1), sizeof(size_t));
    hd__mpi_free(c, rg->first, rg->total, sizeof(uint64_t));
    hd__mpi_free(c, rg->bylo, rg->total, sizeof(hd__mpi_range_t));
    hd__mpi_free(c, rg->ord, rg->total, sizeof(uint64_t));
    rg->all = NULL, rg->seg = NULL, rg->first = NULL, rg->bylo = NULL, rg->ord = NULL;
}

/* g[k] = the global index of point number num[k] of rank r's side s, for
 * num[] increasing; *i is a run of rank r's side s at or before num[0]'s
 * (its first: rg->seg[s (K + 1) + r]), and becomes num[n - 1]'s. */
void hd__mpi_ranges_globals(const hd__mpi_ranges_t *rg, int s, int r, size_t *i, const uint32_t *num, size_t n, uint64_t *g) {
    for (size_t k = 0; k < n; k++) {
        hd__mpi_ranges_seek(rg, s, r, i, num[k]);
        g[k] = rg->all[*i].lo + (num[k] - rg->first[*i]);
    }
}

/* The global index of point number m (any) of rank r's side s. */
uint64_t hd__mpi_ranges_global(const hd__mpi_ranges_t *rg, int s, int r, uint64_t m) {
    size_t lo = rg->seg[(size_t)s * ((size_t)rg->K + 1) + (size_t)r],
           hi = rg->seg[(size_t)s * ((size_t)rg->K + 1) + (size_t)r + 1] - 1;
    while (lo < hi) { /* the last part whose first number is <= m */
        size_t mid = lo + (hi - lo + 1) / 2;
        if (rg->first[mid] <= m) lo = mid;
        else hi = mid - 1;
    }
    return rg->all[lo].lo + (m - rg->first[lo]);
}

/* The runs' orders (ranges.h's hd__mpi_ranges_t): rg->all (any order, rg->total
 * runs of rg->K ranks, no two of a side sharing an index) sorted by owner
 * with seg and first, and bylo with ord.  Local (check_ranges runs it on
 * every rank after the all-gather); fails only for memory. */
int hd__mpi_ranges_index(hd__mpi_ctx_t *c, hd__mpi_ranges_t *rg) {
    int K = rg->K;
    size_t total = rg->total;
    if (!rg->seg && !(rg->seg = hd__mpi_alloc(c, 2 * ((size_t)K + 1), sizeof(size_t))))
        return hd__mpi_nomem(c, "index ranges", (size_t)K);
    if (!rg->first && !(rg->first = hd__mpi_alloc(c, total, sizeof(uint64_t))))
        return hd__mpi_nomem(c, "index ranges", total);
    rg->bylo = hd__mpi_alloc(c, total, sizeof(hd__mpi_range_t));
    rg->ord = hd__mpi_alloc(c, total, sizeof(uint64_t));
    if (!rg->bylo || !rg->ord) return hd__mpi_nomem(c, "index ranges", total);
    memcpy(rg->bylo, rg->all, total * sizeof(hd__mpi_range_t));
    qsort(rg->bylo, total, sizeof(hd__mpi_range_t), hd__mpi_by_range);
    for (size_t i = 0; i < total; i++) {
        int same = i > 0 && rg->bylo[i].side == rg->bylo[i - 1].side;
        rg->ord[i] = same ? rg->ord[i - 1] + (rg->bylo[i - 1].hi - rg->bylo[i - 1].lo + 1) : 0;
    }
    qsort(rg->all, total, sizeof(hd__mpi_range_t), by_owner);
    size_t k = 0;
    for (int s = 0; s < 2; s++)
        for (int r = 0; r <= K; r++) {
            while (k < total && (rg->all[k].side < s || (rg->all[k].side == s && rg->all[k].rank < r))) k++;
            rg->seg[(size_t)s * ((size_t)K + 1) + (size_t)r] = k;
        }
    for (size_t i = 0; i < total; i++) {
        int same = i > 0 && rg->all[i].side == rg->all[i - 1].side && rg->all[i].rank == rg->all[i - 1].rank;
        rg->first[i] = same ? rg->first[i - 1] + (rg->all[i - 1].hi - rg->all[i - 1].lo + 1) : 0;
    }
    return HD_OK;
}

/* Over all ranks, no two parts of one set share an index; rg receives
 * every rank's parts. */
int hd__mpi_check_ranges(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, hd__mpi_ranges_t *rg) {
    int n = 0, rc = HD_OK, K = c->K;
    for (int s = 0; s < 2; s++)
        for (size_t k = 0; k < in->nparts[s]; k++) n += in->parts[s][k].points.count > 0;
    int *counts = hd__mpi_alloc(c, 2 * (size_t)K, sizeof(int));
    rg->K = K;
    rg->seg = hd__mpi_alloc(c, 2 * ((size_t)K + 1), sizeof(size_t));
    if (!counts || !rg->seg) rc = hd__mpi_nomem(c, "index ranges", (size_t)K);
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    HD__MPI_GO(c, rc, MPI_Allgather(&n, 1, MPI_INT, counts, 1, MPI_INT, c->comm));
    size_t total = 0;
    int *displ = counts + K;
    for (int r = 0; r < K; r++) {
        displ[r] = (int)(total * sizeof(hd__mpi_range_t));
        total += (size_t)counts[r];
        counts[r] *= (int)sizeof(hd__mpi_range_t);
    }
    hd__mpi_range_t *mine = hd__mpi_alloc(c, (size_t)n, sizeof(hd__mpi_range_t));
    rg->all = hd__mpi_alloc(c, total, sizeof(hd__mpi_range_t));
    rg->first = hd__mpi_alloc(c, total, sizeof(uint64_t));
    rg->total = total;
    if (!mine || !rg->all || !rg->first || total * sizeof(hd__mpi_range_t) > INT_MAX) rc = hd__mpi_nomem(c, "index ranges", total);
    if ((rc = hd__mpi_agree(c, rc)) == HD_OK) {
        int t = 0;
        for (int s = 0; s < 2; s++)
            for (size_t k = 0; k < in->nparts[s]; k++) {
                const hd_mpi_part_t *p = &in->parts[s][k];
                if (p->points.count)
                    mine[t++] = (hd__mpi_range_t){p->offset, p->offset + (p->points.count - 1), s, c->rank};
            }
        double mpi_t0_;
        int mpi_rc_,
            e = HD__MPI_TIMED(c, MPI_Allgatherv(mine, n * (int)sizeof(hd__mpi_range_t), MPI_BYTE, rg->all, counts, displ,
                                            MPI_BYTE, c->comm));
        if (e != MPI_SUCCESS) rc = hd__mpi_failed(c, "MPI_Allgatherv", e);
    }
    hd__mpi_free(c, mine, (size_t)n, sizeof(hd__mpi_range_t));
    if (rc == HD_OK) {
        hd__mpi_range_t *all = rg->all;
        qsort(all, total, sizeof(hd__mpi_range_t), hd__mpi_by_range);
        for (size_t k = 1; k < total; k++)
            if (all[k].side == all[k - 1].side && all[k].lo <= all[k - 1].hi) {
                rc = hd__err(&c->e, HD_EINVAL,
                             "parts of %s share indices: %llu..%llu on rank %d and %llu..%llu on rank %d",
                             all[k].side ? "B" : "A", (unsigned long long)all[k - 1].lo,
                             (unsigned long long)all[k - 1].hi, all[k - 1].rank, (unsigned long long)all[k].lo,
                             (unsigned long long)all[k].hi, all[k].rank);
                break;
            }
    }
    if (rc == HD_OK) rc = hd__mpi_ranges_index(c, rg);
    rc = hd__mpi_agree(c, rc); /* a refusal is every rank's; a failed allocation one's */
done:
    hd__mpi_free(c, counts, 2 * (size_t)K, sizeof(int));
    return rc;
}

/* Local checks: options, parts (views valid, finite, in range, indices
 * within size_t), with the local counts and boxes. */
int hd__mpi_check_local(hd__mpi_ctx_t *c, const hd_options_t *opt, hd__mpi_input_t *in, const void *out) {
    if (!out) return hd__err(&c->e, HD_EINVAL, "the result pointer is NULL");
    if (opt && opt->threads < 0)
        return hd__err(&c->e, HD_EINVAL, "threads must be 0 (every core) or positive, not %d", opt->threads);
    if (opt && ((int)opt->algorithm < 0 || opt->algorithm >= HD__ALG_COUNT))
        return hd__err(&c->e, HD_EALGORITHM, "unknown algorithm %d", (int)opt->algorithm);
    for (int s = 0; s < 2; s++) {
        const char *name = s ? "B" : "A";
        in->n[s] = 0;
        for (int k = 0; k < 3; k++) in->box[s].lo[k] = INFINITY, in->box[s].hi[k] = -INFINITY;
        if (in->nparts[s] && !in->parts[s]) return hd__err(&c->e, HD_EINVAL, "the parts of %s are NULL", name);
        /* The exchange numbers a rank's points of a set in 4 bytes (and
         * the engine takes at most 2^32 - 1 a set): refused before a
         * point is read. */
        uint64_t held = 0;
        for (size_t p = 0; p < in->nparts[s]; p++) {
            size_t n = in->parts[s][p].points.count;
            if (n > UINT32_MAX - held)
                return hd__err(&c->e, HD_ERANGE, "%s: more than 2^32 - 1 points on one rank (%zu parts so far)",
                               name, p + 1);
            held += n;
        }
        for (size_t p = 0; p < in->nparts[s]; p++) {
            const hd_mpi_part_t *part = &in->parts[s][p];
            if (part->points.count == 0) continue;
            if (part->points.count - 1 > SIZE_MAX - part->offset || part->offset + part->points.count - 1 >= UINT64_MAX)
                return hd__err(&c->e, HD_EINVAL, "part %zu of %s: indices %zu + %zu run past SIZE_MAX", p, name,
                               part->offset, part->points.count);
            char what[64];
            snprintf(what, sizeof what, "%s (part %zu, first index %zu)", name, p, part->offset);
            hd__box_t box;
            int rc = hd__points_scan(&part->points, what, c->threads, &box, &c->e);
            if (rc != HD_OK) return rc;
            hd__box_merge(&in->box[s], &box);
            in->n[s] += part->points.count;
        }
    }
    return HD_OK;
}
