/*
 * prune.c -- the points that stay where they are (issue 41): before the
 * partition moves anything, a grid of cells over each set's global box,
 * the exact box of every cell's points (all-reduced) and a small sample
 * of each set (all-gathered) decide which cells' points cannot change the
 * answer; the exchange leaves those on their rank and the course never
 * sees them.
 *
 * Invariants (every bound is one of points.h's computed bounds, evaluated
 * in hd__d2's operation order, so each holds for the computed squared
 * distances the engine compares, not only for the real ones):
 *  - U[s][c] = min over some sample points o of the other set of
 *    hd__box_ub2(cell box, o) (those of the other set's cells around the
 *    one nearest the cell's centre: cell_u): at least the computed d2 of
 *    every point of the cell to its nearest in the other set (the
 *    sample's points are points of it), whichever points are tried.
 *  - L[s] = max over the sample of s of min over the other set's nonempty
 *    cells of hd__box_lb2(cell box, p): at most the computed d2 of the
 *    sample point p to its nearest, so at most h^2 of the direction s.
 *  - A cell of s whose U < L holds no point at h (every point's d2 <= U
 *    < L <= h^2): as a query it cannot be the witness, nor tie with it.
 *  - Every kept cell that is asked (both sets' in the symmetric call,
 *    A's in the directed one) keeps each cell of the other set within its
 *    U (hd__box_box_lb2 <= U, ties kept), to a fixed point: every point of
 *    a cell beyond that is farther from each of the cell's points than
 *    its own nearest, so it is nobody's nearest nor tied with one, and a
 *    kept point's nearest among the kept points is its nearest among all
 *    (a point kept as a searched one only keeps d2 <= U < L: it cannot
 *    win).  The other cells' points do not move.
 */
#include "mpi/partition.h"

#include <math.h>
#include <stdlib.h>

/* Sample points a side in all (each rank its share of its input). */
#define PRUNE_SAMPLE 1024
/* The points a cell's box is first taken over: one in at most
 * PRUNE_STRIDE, at least PRUNE_FIRST a cell on average (stride_of). */
#define PRUNE_STRIDE 16
#define PRUNE_FIRST 32
/* Cells a set. */
enum { NC = HD__MPI_CELLS * HD__MPI_CELLS * HD__MPI_CELLS };

/* By set, then by cell (the cell in g: prune() puts it there). */
static int by_side_cell(const void *x, const void *y) {
    const hd__mpi_sample_t *a = x, *b = y;
    if (a->side != b->side) return (a->side > b->side) - (a->side < b->side);
    return (a->g > b->g) - (a->g < b->g);
}

/* The sample of each set sorted by set, then by its cell in its own set's
 * grid: set s's sample points of cell k are all[at[s][k] .. at[s][k + 1]). */
typedef struct {
    const hd__mpi_prune_t *pr;
    const hd__box_t *box;            /* 2 NC global cell boxes */
    const unsigned char *full;       /* 2 NC: the cell holds a point */
    const hd__mpi_sample_t *all;
    size_t (*at)[NC + 1];
    double *U;                       /* 2 NC, < 0 until computed */
} cells_t;

/* U of cell k of set s (prune.c's invariants), computed when first asked.
 * Any sample point of the other set gives an upper bound; the smallest is
 * sought among the sample points of the other set's cells around the one
 * nearest the cell's centre, ring by ring (Chebyshev distance in cells),
 * up to one ring beyond the first that holds a sample point: the points
 * farther out are farther from every corner too, up to a cell or two, and
 * a larger U only keeps more cells. */
static double cell_u(cells_t *cl, int s, size_t k) {
    enum { M = HD__MPI_CELLS };
    double *u = &cl->U[(size_t)s * NC + k];
    if (*u >= 0) return *u;
    int t = 1 - s;
    const hd__box_t *b = &cl->box[(size_t)s * NC + k];
    double mid[3] = {0.5 * b->lo[0] + 0.5 * b->hi[0], 0.5 * b->lo[1] + 0.5 * b->hi[1], 0.5 * b->lo[2] + 0.5 * b->hi[2]};
    int c = hd__mpi_cell(cl->pr, t, mid), ci[3] = {c % M, c / M % M, c / (M * M)};
    double m = INFINITY;
    for (int r = 0, last = M; r <= last; r++)
        for (int z = ci[2] - r; z <= ci[2] + r; z++)
            for (int y = ci[1] - r; y <= ci[1] + r; y++)
                for (int x = ci[0] - r; x <= ci[0] + r; x++) {
                    int dz = abs(z - ci[2]), dy = abs(y - ci[1]), dx = abs(x - ci[0]);
                    if (x < 0 || y < 0 || z < 0 || x >= M || y >= M || z >= M) continue;
                    if ((dx > dy ? dx : dy) < r && dz < r) continue; /* an inner ring's */
                    size_t j = (size_t)x + (size_t)M * ((size_t)y + (size_t)M * (size_t)z);
                    for (size_t q = cl->at[t][j]; q < cl->at[t][j + 1]; q++) {
                        double d = hd__box_ub2(b, cl->all[q].x);
                        m = d < m ? d : m;
                    }
                    if (m < INFINITY && last > r + 1) last = r + 1;
                }
    return *u = m;
}

/* The squared half diagonal of a box: every point's farthest corner is at
 * least that far (in reals; the caller halves it again, far beyond any
 * rounding), so a cell with L below it is a query without its U. */
static double half_diag2(const hd__box_t *b) {
    double d = 0;
    for (int a = 0; a < 3; a++) d += 0.25 * (b->hi[a] - b->lo[a]) * (b->hi[a] - b->lo[a]);
    return d;
}

static size_t share(uint64_t n, uint64_t N) { return N <= PRUNE_SAMPLE ? (size_t)n : (size_t)(n * PRUNE_SAMPLE / N); }

/* This rank's share of each set's sample into own (mine[s] of set s, at
 * positions i n / ns of its own order; a point's g holds its cell). */
static void take_sample(const hd__mpi_input_t *in, const hd__mpi_prune_t *pr, const size_t mine[2],
                        hd__mpi_sample_t *own) {
    size_t o = 0;
    for (int s = 0; s < 2; s++) {
        size_t i = 0, ns = mine[s];
        uint64_t n = in->n[s], t0 = 0;
        for (size_t p = 0; p < in->nparts[s] && i < ns; p++) {
            const hd_points_t *v = &in->parts[s][p].points;
            const double *px = hd__mpi_packed(v);
            for (uint64_t next = (uint64_t)i * n / ns; i < ns && next < t0 + v->count; next = (uint64_t)i * n / ns) {
                size_t k = (size_t)(next - t0);
                if (px) memcpy(own[o].x, px + 3 * k, sizeof own[o].x);
                else hd_points_get(v, k, own[o].x);
                own[o].g = (uint64_t)hd__mpi_cell(pr, s, own[o].x), own[o].side = (uint64_t)s;
                o++, i++;
            }
            t0 += v->count;
        }
    }
}

/* The stride of set s's first boxes (N: the sets' global sizes). */
static size_t stride_of(const uint64_t N[2], int s) {
    uint64_t st = N[s] / ((uint64_t)NC * PRUNE_FIRST);
    return st < 1 ? 1 : st > PRUNE_STRIDE ? PRUNE_STRIDE : (size_t)st;
}

/* The boxes cb (2 NC boxes, hi negated, at +INFINITY on entry) of this
 * rank's points of each cell at positions of its own order that are
 * multiples of set s's stride[s] (1: every point; above, boxes inside the
 * cells'). */
static void take_boxes(const hd__mpi_input_t *in, const hd__mpi_prune_t *pr, const size_t stride_[2], double *cb) {
    for (int s = 0; s < 2; s++) {
        size_t t0 = 0, stride = stride_[s];
        for (size_t p = 0; p < in->nparts[s]; p++) {
            const hd_points_t *v = &in->parts[s][p].points;
            const double *px = hd__mpi_packed(v);
            for (size_t k = (stride - t0 % stride) % stride; k < v->count; k += stride) {
                double xb[3];
                const double *x = px ? px + 3 * k : (hd_points_get(v, k, xb), xb);
                double *b = cb + 6 * ((size_t)s * NC + (size_t)hd__mpi_cell(pr, s, x));
                for (int a = 0; a < 3; a++) {
                    b[a] = x[a] < b[a] ? x[a] : b[a];
                    b[3 + a] = -x[a] < b[3 + a] ? -x[a] : b[3 + a];
                }
            }
            t0 += v->count;
        }
    }
}

/* The all-reduced boxes gb (hi negated) as boxes and whether each holds a
 * point (into box and full, which may alias cb and gb as prune() does). */
static void read_boxes(const double *gb, hd__box_t *box, unsigned char *full) {
    for (size_t k = 0; k < 2 * NC; k++) {
        hd__box_t b;
        for (int a = 0; a < 3; a++) b.lo[a] = gb[6 * k + a], b.hi[a] = -gb[6 * k + 3 + a];
        box[k] = b;
    }
    for (size_t k = 0; k < 2 * NC; k++) full[k] = box[k].lo[0] <= box[k].hi[0];
}

/* The sample (total points, every rank's) by set (A's first) and cell:
 * set s's points are all[from[s] .. to[s]), those of its cell k
 * all[at[s][k] .. at[s][k + 1]). */
static void sort_sample(hd__mpi_sample_t *all, size_t total, size_t from[2], size_t to[2], size_t (*at)[NC + 1]) {
    qsort(all, total, sizeof *all, by_side_cell);
    size_t split = 0;
    while (split < total && all[split].side == 0) split++;
    from[0] = 0, to[0] = split, from[1] = split, to[1] = total;
    for (int s = 0; s < 2; s++) {
        size_t q = from[s];
        for (size_t k = 0; k <= NC; k++) {
            while (q < to[s] && all[q].g < k) q++;
            at[s][k] = q;
        }
    }
}

/* L of set s (prune.c's invariants) over its sample all[from .. to): a
 * sample point whose bound is already at most L cannot raise it, and the
 * other set's cell nearest it is tried first.  Once L reaches cap the
 * rest is not looked at (the value returned is then at least cap, at most
 * L: cap INFINITY for L itself). */
static double lower_L(const cells_t *cl, int s, size_t from, size_t to, double cap) {
    int t = 1 - s;
    const hd__box_t *box = cl->box + (size_t)t * NC;
    const unsigned char *full = cl->full + (size_t)t * NC;
    double L = -1.0;
    for (size_t j = from; j < to && !(L >= cap); j++) {
        const double *x = cl->all[j].x;
        size_t near = (size_t)hd__mpi_cell(cl->pr, t, x);
        if (full[near] && hd__box_lb2(&box[near], x) <= L) continue;
        double lb = INFINITY;
        for (size_t k = 0; k < NC && lb > L; k++)
            if (full[k]) {
                double d = hd__box_lb2(&box[k], x);
                lb = d < lb ? d : lb;
            }
        L = lb > L ? lb : L;
    }
    return L;
}

/* The cells kept (kp): cell k of s is kept when it may hold the witness of
 * direction s; then every kept point that is asked for its nearest (both
 * sets' in the symmetric call, A's in the directed one) keeps every cell
 * of the other set within its U, ties included, each kept cell once (todo,
 * 2 NC: the cells still to look from), and not at all once every cell of
 * the other set is kept: a kept point's nearest among the kept points is
 * its nearest among all, so a point kept only as a searched one keeps its
 * d2 <= U < L and cannot win either. */
static void keep_cells(cells_t *cl, const double L[2], int both, size_t *todo, unsigned char (*kp)[NC]) {
    const hd__box_t *box = cl->box;
    const unsigned char *full = cl->full;
    size_t nq = 0, out[2] = {0, 0}; /* out: the nonempty cells not kept */
    for (int s = 0; s < 2; s++)
        for (size_t k = 0; k < NC; k++) {
            kp[s][k] = full[s * NC + k] && (s == 0 || both) &&
                       (L[s] < 0.5 * half_diag2(&box[s * NC + k]) || !(cell_u(cl, s, k) < L[s]));
            if (kp[s][k]) todo[nq++] = (size_t)s * NC + k;
            out[s] += full[s * NC + k] && !kp[s][k];
        }
    while (nq) {
        size_t sk = todo[--nq];
        int s = (int)(sk / NC), t = 1 - s;
        if (!out[t]) continue;
        double u = cell_u(cl, s, sk % NC);
        for (size_t j = 0; j < NC; j++)
            if (!kp[t][j] && full[t * NC + j] && hd__box_box_lb2(&box[sk], &box[t * NC + j]) <= u) {
                kp[t][j] = 1, out[t]--;
                if (t == 0 || both) todo[nq++] = (size_t)t * NC + j;
            }
    }
}

/* Whether no asked cell can pass (both: the symmetric call; the directed
 * one is not tried), from boxes inside the cells' (every stride_of-th
 * point's) and their L' (lower_L over them): each box holds a cell's true
 * box's points only, so L' >= L and a nonempty one's half diagonal is at
 * most the true box's; a cell whose box here has L' below half its
 * squared half diagonal is kept by keep_cells whatever its U.  So L' is
 * sought only up to the smallest such half (cap).  A cell empty here is
 * not proved (it holds points between the strided ones only); its points
 * then move, as without the cells. */
static int none_can_pass(const cells_t *cl, const size_t from[2], const size_t to[2], int both) {
    for (int s = 0; s < (both ? 2 : 0); s++) {
        double cap = INFINITY;
        for (size_t k = 0; k < NC; k++)
            if (cl->full[s * NC + k]) {
                double h = 0.5 * half_diag2(&cl->box[s * NC + k]);
                cap = h < cap ? h : cap;
            }
        if (!(lower_L(cl, s, from[s], to[s], cap) < cap)) return 0;
    }
    return both;
}

int hd__mpi_prune(hd__mpi_ctx_t *c, const hd__mpi_input_t *in, const uint64_t N[2], const double corners[2][6], int both,
                  hd__mpi_prune_t *pr) {
    int K = c->K, rc = HD_OK;
    memset(pr, 0, sizeof *pr);
    for (int s = 0; s < 2; s++)
        for (int k = 0; k < 3; k++) {
            pr->gbox[s].lo[k] = corners[s][k], pr->gbox[s].hi[k] = corners[s][3 + k];
            double w = corners[s][3 + k] - corners[s][k];
            pr->inv[s][k] = w > 0 ? HD__MPI_CELLS / w : 0.0;
        }
    /* Each cell's box over all ranks (hi negated: one MIN). */
    double *cb = hd__mpi_alloc(c, 2 * NC * 6, sizeof(double)), *gb = hd__mpi_alloc(c, 2 * NC * 6, sizeof(double));
    size_t mine[2] = {share(in->n[0], N[0]), share(in->n[1], N[1])};
    hd__mpi_sample_t *own = hd__mpi_alloc(c, mine[0] + mine[1] + 1, sizeof *own);
    int *cnt = hd__mpi_alloc(c, 2 * (size_t)K, sizeof(int));
    hd__mpi_sample_t *all = NULL;
    double *U = hd__mpi_alloc(c, 2 * NC, sizeof(double));
    size_t (*at)[NC + 1] = hd__mpi_alloc(c, 2, sizeof *at), *todo = hd__mpi_alloc(c, 2 * NC, sizeof(size_t));
    /* the directed call takes the true boxes at once (none_can_pass) */
    size_t total = 0, stride[2] = {both ? stride_of(N, 0) : 1, both ? stride_of(N, 1) : 1}, every[2] = {1, 1};
    hd__box_t *box = (hd__box_t *)(void *)cb;          /* the global cell boxes, read from gb */
    unsigned char *full = (unsigned char *)(void *)gb; /* gb read into box first */
    if (!cb || !gb || !own || !cnt || !U || !at || !todo) rc = hd__mpi_nomem(c, "the cells", NC);
    if (rc == HD_OK) {
        for (size_t k = 0; k < 2 * NC; k++)
            for (int a = 0; a < 6; a++) cb[6 * k + a] = INFINITY;
        take_sample(in, pr, mine, own);
        take_boxes(in, pr, stride, cb);
    }
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    HD__MPI_GO(c, rc, MPI_Allreduce(cb, gb, 2 * NC * 6, MPI_DOUBLE, MPI_MIN, c->comm));
    int m = (int)(mine[0] + mine[1]);
    HD__MPI_GO(c, rc, MPI_Allgather(&m, 1, MPI_INT, cnt, 1, MPI_INT, c->comm));
    for (int r = 0; r < K; r++) cnt[K + r] = (int)total, total += (size_t)cnt[r];
    all = hd__mpi_alloc(c, total ? total : 1, sizeof *all);
    if (!all) rc = hd__mpi_nomem(c, "the sample", total);
    if ((rc = hd__mpi_agree(c, rc)) != HD_OK) goto done;
    HD__MPI_GO(c, rc, MPI_Allgatherv(own, m, c->sample_type, all, cnt, cnt + K, c->sample_type, c->comm));
    /* The sample by set and cell; first the strided boxes decide whether
     * any cell may pass (every rank the same: the same reduced values). */
    size_t from[2], to[2];
    sort_sample(all, total, from, to, at);
    for (size_t k = 0; k < 2 * NC; k++) U[k] = -1.0; /* not computed: cell_u */
    cells_t cl = {pr, box, full, all, at, U};
    read_boxes(gb, box, full);
    if (none_can_pass(&cl, from, to, both)) goto done; /* pr->on 0: every point moves */
    if (stride[0] > 1 || stride[1] > 1) { /* else the boxes are the true ones already */
        for (size_t k = 0; k < 2 * NC; k++)
            for (int a = 0; a < 6; a++) cb[6 * k + a] = INFINITY;
        take_boxes(in, pr, every, cb);
        HD__MPI_GO(c, rc, MPI_Allreduce(cb, gb, 2 * NC * 6, MPI_DOUBLE, MPI_MIN, c->comm));
        read_boxes(gb, box, full);
    }
    double L[2] = {lower_L(&cl, 0, from[0], to[0], INFINITY), lower_L(&cl, 1, from[1], to[1], INFINITY)};
    /* Then U as the cells need it (the smallest found: a larger one would
     * keep more cells). */
    keep_cells(&cl, L, both, todo, pr->keep);
    pr->on = 1;
done:
    hd__mpi_free(c, cb, 2 * NC * 6, sizeof(double));
    hd__mpi_free(c, gb, 2 * NC * 6, sizeof(double));
    hd__mpi_free(c, own, mine[0] + mine[1] + 1, sizeof *own);
    hd__mpi_free(c, cnt, 2 * (size_t)K, sizeof(int));
    hd__mpi_free(c, all, total ? total : 1, sizeof *all);
    hd__mpi_free(c, U, 2 * NC, sizeof(double));
    hd__mpi_free(c, at, 2, sizeof *at);
    hd__mpi_free(c, todo, 2 * NC, sizeof(size_t));
    return rc;
}
