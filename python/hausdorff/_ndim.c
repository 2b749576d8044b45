/*
 * _ndim.c -- exact h(A, B) and nearest distances in any number of
 * coordinates (see _ndim.h for the contract).
 *
 * The squared distance of a point to a candidate is summed coordinate by
 * coordinate, first to last, and a candidate is abandoned once its partial
 * sum exceeds the bound that matters (the best squared distance so far):
 * every term is >= 0 and rounding is monotone, so the partial sums never
 * decrease and the full sum would exceed the bound too.  A candidate equal
 * to the bound is always summed to the end, so ties are seen and go to the
 * smallest index.  Eight candidates are summed side by side (eight
 * independent chains of the same operations), which changes no double.
 *
 * Nearest distances (every point's own, with no early stop) in at most
 * TREE_MAX_DIMS coordinates hold B's rows in a tree of boxes (see nd_set_t):
 * a point's scan visits the leaf it falls in, then the boxes nearer first,
 * leaving a box whose lower bound exceeds the best so far (see box_bound).
 * Otherwise B's rows are scanned in a stored order: index order for the
 * naive algorithm and nearest distances, a seeded random order for the
 * early break.
 *
 * The early-break algorithm (Taha and Hanbury, as scipy's
 * directed_hausdorff): points of A are visited in a seeded random order,
 * B's rows in another; the scan of a point stops as soon as a candidate is
 * strictly nearer than the largest nearest squared distance c known so far
 * (the point's own nearest is then below c, so it is not the maximum), or equal
 * to c when the point's index is above the witness's (it can then at most
 * tie with a smaller index).  A point whose scan ends without stopping has
 * its exact nearest squared distance and the smallest index attaining it.
 * The point realising the maximum with the smallest index is therefore
 * never stopped, and the result is the brute force's whatever the order.
 *
 * Threads share A by interleaving; each keeps its own c and witness and
 * publishes c to the others, who use it for the strict test only.  Every
 * value published is some point's exact nearest squared distance, so it
 * never exceeds the maximum M, and a point whose nearest is M is never
 * stopped by it; the thread holding the smallest such index records it.
 * Merging keeps the largest value, on ties the smallest index.
 */
#include "_ndim.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

enum {
    LANES = 8,         /* rows summed side by side: a block */
    BLOCK = 8,         /* coordinates summed between two tests of the bound */
    TREE_MAX_DIMS = 8, /* nearest(): above, boxes bound too little to pay for their tests */
    CENTRAL = 64       /* rows the early break tries first (see central_first) */
};

/* B as scanned: its rows in blocks of LANES, each block's coordinates
 * interleaved (coordinate k of the block's row l at [k * LANES + l]), so
 * that the LANES sums advance side by side on contiguous memory; the last
 * block is padded with zeros, which are never offered.  order[r] is stored
 * row r's index in the caller's B (NULL: r, and no tree).
 *
 * The tree: node 0 holds every row; an inner node's rows are split into
 * its two children at a block boundary, by a median of the coordinate along
 * which a sample of them spreads most; a leaf holds one block.  box[2 * dims
 * * node ...] is the node's bounding box, its lows then its highs. */
typedef struct {
    size_t lo, hi;     /* stored rows [lo, hi) */
    size_t child[2];   /* both 0 for a leaf (node 0, the root, is no child) */
    size_t axis;       /* an inner node's rows: child 0's have coordinate axis */
    double split;      /* <= split, child 1's >= split */
} nd_node_t;

typedef struct {
    double *blocks, *box;
    size_t *order;
    nd_node_t *nodes;
    size_t n, dims, nnodes;
} nd_set_t;

static size_t index_of(const nd_set_t *s, size_t r) {
    return s->order ? s->order[r] : r;
}

static void set_free(nd_set_t *s) {
    free(s->blocks);
    free(s->box);
    free(s->order);
    free(s->nodes);
}

static void swap_sizes(size_t *v, size_t i, size_t j) {
    size_t t = v[i];
    v[i] = v[j];
    v[j] = t;
}

static void swap_keyed(double *key, size_t *v, size_t i, size_t j) {
    double k = key[i];
    key[i] = key[j];
    key[j] = k;
    swap_sizes(v, i, j);
}

/* Reorder key[0..n) and v[0..n) alike so that key[0..k) <= key[k..n): a
 * quickselect with a three-way partition, so that runs of equal keys
 * (grids) cost no more than others. */
static void select_keyed(double *key, size_t *v, size_t n, size_t k) {
    size_t lo = 0, hi = n;
    while (hi - lo > 1) {
        double x = key[lo], y = key[lo + (hi - lo) / 2], z = key[hi - 1];
        double pivot = x < y ? (y < z ? y : x < z ? z : x) : (x < z ? x : y < z ? z : y);
        size_t lt = lo, i = lo, gt = hi;
        while (i < gt) {
            if (key[i] < pivot) swap_keyed(key, v, lt++, i++);
            else if (key[i] > pivot) swap_keyed(key, v, i, --gt);
            else i++;
        }
        if (k < lt) hi = lt;
        else if (k >= gt) lo = gt;
        else return;
    }
}

/* The coordinate along which up to 64 of the rows v[0..n) spread most. */
static size_t split_axis(const size_t *v, size_t n, const double *B, size_t dims) {
    size_t step = n > 64 ? n / 64 : 1, axis = 0;
    double widest = -1.0;
    for (size_t k = 0; k < dims; k++) {
        double lo = B[v[0] * dims + k], hi = lo;
        for (size_t r = step; r < n; r += step) {
            double x = B[v[r] * dims + k];
            lo = x < lo ? x : lo;
            hi = x > hi ? x : hi;
        }
        if (hi - lo > widest) {
            widest = hi - lo;
            axis = k;
        }
    }
    return axis;
}

/* Node `node` over stored rows [lo, hi), and its subtree; s->order is
 * reordered in place (key: scratch, one double a row).  Returns the next
 * free node. */
static size_t tree_split(nd_set_t *s, const double *B, double *key, size_t node, size_t lo,
                         size_t hi) {
    s->nodes[node] = (nd_node_t){lo, hi, {0, 0}, 0, 0.0};
    if (hi - lo <= LANES) return node + 1;
    size_t blocks = (hi - lo + LANES - 1) / LANES, mid = lo + blocks / 2 * LANES;
    size_t *v = s->order + lo, axis = split_axis(v, hi - lo, B, s->dims);
    for (size_t r = lo; r < hi; r++) key[r] = B[s->order[r] * s->dims + axis];
    select_keyed(key + lo, v, hi - lo, mid - lo);
    size_t left = node + 1, right = tree_split(s, B, key, left, lo, mid);
    s->nodes[node].child[0] = left;
    s->nodes[node].child[1] = right;
    s->nodes[node].axis = axis;
    s->nodes[node].split = B[s->order[mid] * s->dims + axis];
    return tree_split(s, B, key, right, mid, hi);
}

/* Every node's box: a leaf's from its rows, an inner node's from its
 * children's (children come after their parent, so backwards works). */
static void tree_boxes(nd_set_t *s, const double *B) {
    size_t dims = s->dims;
    for (size_t node = s->nnodes; node-- > 0;) {
        const nd_node_t *nd = &s->nodes[node];
        double *lo = s->box + 2 * dims * node, *hi = lo + dims;
        if (!nd->child[0]) {
            memcpy(lo, B + s->order[nd->lo] * dims, dims * sizeof *lo);
            memcpy(hi, lo, dims * sizeof *hi);
            for (size_t r = nd->lo + 1; r < nd->hi; r++)
                for (size_t k = 0; k < dims; k++) {
                    double x = B[s->order[r] * dims + k];
                    lo[k] = x < lo[k] ? x : lo[k];
                    hi[k] = x > hi[k] ? x : hi[k];
                }
            continue;
        }
        const double *l = s->box + 2 * dims * nd->child[0], *r = s->box + 2 * dims * nd->child[1];
        for (size_t k = 0; k < dims; k++) {
            lo[k] = l[k] < r[k] ? l[k] : r[k];
            hi[k] = l[dims + k] > r[dims + k] ? l[dims + k] : r[dims + k];
        }
    }
}

/* The blocked copy of B, in the tree's order (tree), or in the order
 * given (the set then owns it; NULL: index order); -1 when there is no
 * memory for it (set_free frees what was had). */
static int set_build(nd_set_t *s, const double *B, size_t nb, size_t dims, int tree,
                     size_t *order) {
    *s = (nd_set_t){NULL, NULL, order, NULL, nb, dims, 0};
    size_t nblocks = (nb + LANES - 1) / LANES;
    if (!dims || nblocks > SIZE_MAX / sizeof(double) / LANES / dims / 4) return -1;
    s->blocks = calloc(nblocks * LANES * dims, sizeof(double));
    if (!s->blocks) return -1;
    if (tree) {
        double *key = malloc(nb * sizeof *key);
        s->order = malloc(nb * sizeof *s->order);
        s->nodes = malloc(2 * nblocks * sizeof *s->nodes);
        s->box = malloc(2 * nblocks * 2 * dims * sizeof *s->box);
        if (!key || !s->order || !s->nodes || !s->box) {
            free(key);
            return -1;
        }
        for (size_t r = 0; r < nb; r++) s->order[r] = r;
        s->nnodes = tree_split(s, B, key, 0, 0, nb);
        free(key);
        tree_boxes(s, B);
    }
    for (size_t r = 0; r < nb; r++) {
        const double *row = B + index_of(s, r) * dims;
        double *dst = s->blocks + (r / LANES) * LANES * dims + r % LANES;
        for (size_t k = 0; k < dims; k++) dst[k * LANES] = row[k];
    }
    return 0;
}

/* Stored row r at squared distance d improves (*best, *best_r)? */
static void offer(const nd_set_t *s, double d, size_t r, double *best, size_t *best_r) {
    if (d < *best || (d == *best && index_of(s, r) < index_of(s, *best_r))) {
        *best = d;
        *best_r = r;
    }
}

/* The squared distances of a to the LANES rows of block blk: each s[l] is
 * exact unless all of them passed the bound at the same test (they are then
 * partial sums, all > bound). */
static void sq_dist_block(const double *a, const double *blk, size_t dims, double bound,
                          double s[LANES]) {
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0, s4 = 0.0, s5 = 0.0, s6 = 0.0, s7 = 0.0;
    size_t k = 0;
    while (k < dims) {
        size_t end = dims - k > BLOCK ? k + BLOCK : dims;
        for (; k < end; k++) {
            const double x = a[k], *p = blk + k * LANES;
            double d0 = x - p[0], d1 = x - p[1], d2 = x - p[2], d3 = x - p[3];
            double d4 = x - p[4], d5 = x - p[5], d6 = x - p[6], d7 = x - p[7];
            s0 += d0 * d0;
            s1 += d1 * d1;
            s2 += d2 * d2;
            s3 += d3 * d3;
            s4 += d4 * d4;
            s5 += d5 * d5;
            s6 += d6 * d6;
            s7 += d7 * d7;
        }
        if (s0 > bound && s1 > bound && s2 > bound && s3 > bound && s4 > bound && s5 > bound &&
            s6 > bound && s7 > bound)
            break;
    }
    const double v[LANES] = {s0, s1, s2, s3, s4, s5, s6, s7};
    memcpy(s, v, sizeof v);
}

/* The rows of block q offered to (*best, *best_r); the rows counted. */
static size_t visit_block(const nd_set_t *s, const double *a, size_t q, double *best,
                          size_t *best_r) {
    double d[LANES];
    size_t r = q * LANES;
    sq_dist_block(a, s->blocks + r * s->dims, s->dims, *best, d);
    size_t rows = s->n - r < LANES ? s->n - r : LANES;
    double least = d[0];
    for (size_t l = 1; l < rows; l++) least = d[l] < least ? d[l] : least;
    if (least <= *best)
        for (size_t l = 0; l < rows; l++) offer(s, d[l], r + l, best, best_r);
    return rows;
}

/* A lower bound of the squared distance of a to every point of node's box,
 * or a partial sum of it > bound.  Per coordinate, the gap g between a and
 * the box is fl(lo - a) or fl(a - hi), and a point p of the box is at least
 * as far: |fl(a - p)| >= g, since rounding is monotone (and symmetric).  So
 * each term of p's sum is at least g * g, and each partial sum at least the
 * box's (fl(x + y) grows with x and y): the box's sum never exceeds p's. */
static double box_bound(const nd_set_t *s, const double *a, size_t node, double bound) {
    const double *lo = s->box + 2 * s->dims * node, *hi = lo + s->dims;
    double sum = 0.0;
    for (size_t k = 0; k < s->dims && sum <= bound; k++) {
        double g = a[k] < lo[k] ? lo[k] - a[k] : a[k] > hi[k] ? a[k] - hi[k] : 0.0;
        sum += g * g;
    }
    return sum;
}

typedef struct {
    const nd_set_t *s;
    const double *a;
    double stop, best;
    size_t best_r, seen, skip; /* skip: the leaf visited first */
    int stopped;
} search_t;

/* The subtree of `node`, whose box is at least `bound` from a: left when
 * that exceeds the best (none of its rows can reach it, not even tie); the
 * nearer child first. */
static void tree_visit(search_t *q, size_t node, double bound) {
    if (q->stopped || bound > q->best) return;
    const nd_node_t *nd = &q->s->nodes[node];
    if (!nd->child[0]) {
        if (node == q->skip) return;
        q->seen += visit_block(q->s, q->a, nd->lo / LANES, &q->best, &q->best_r);
        q->stopped = q->best < q->stop;
        return;
    }
    double b0 = box_bound(q->s, q->a, nd->child[0], q->best);
    double b1 = box_bound(q->s, q->a, nd->child[1], q->best);
    int first = b1 < b0;
    tree_visit(q, nd->child[first], first ? b1 : b0);
    tree_visit(q, nd->child[!first], first ? b0 : b1);
}

/* Scan B for a's nearest row: *best, *best_r (a stored row).  Stops, and
 * returns 1, as soon as *best < stop; otherwise *best is a's exact nearest
 * squared distance and *best_r the row of the smallest index attaining it.
 * With a tree, the leaf a falls in (by the splits) comes first, as it
 * most often holds a row near enough to stop at, then the others. */
static int scan(const nd_set_t *s, const double *a, double stop, double *best, size_t *best_r,
                uint64_t *evals) {
    search_t q = {s, a, stop, INFINITY, 0, 0, 0, 0};
    if (s->nodes) {
        size_t leaf = 0;
        while (s->nodes[leaf].child[0])
            leaf = s->nodes[leaf].child[a[s->nodes[leaf].axis] >= s->nodes[leaf].split];
        q.seen = visit_block(s, a, s->nodes[leaf].lo / LANES, &q.best, &q.best_r);
        q.stopped = q.best < stop;
        q.skip = leaf;
        tree_visit(&q, 0, 0.0);
    } else {
        size_t nblocks = (s->n + LANES - 1) / LANES;
        for (size_t b = 0; !q.stopped && b < nblocks; b++) {
            q.seen += visit_block(s, a, b, &q.best, &q.best_r);
            q.stopped = q.best < stop;
        }
    }
    *evals += q.seen;
    *best = q.best;
    *best_r = q.best_r;
    return q.stopped;
}

/* ------------------------------------------------------------------------
 * Threads: job 0 runs on the caller's thread; a job whose thread cannot
 * start runs there too, after it.
 * ---------------------------------------------------------------------- */

static void run_jobs(void *(*fn)(void *), void *jobs, size_t size, int n) {
    pthread_t tid[64];
    int started[64] = {0};
    for (int t = 1; t < n; t++)
        started[t] = pthread_create(&tid[t], NULL, fn, (char *)jobs + (size_t)t * size) == 0;
    fn(jobs);
    for (int t = 1; t < n; t++) {
        if (started[t]) pthread_join(tid[t], NULL);
        else fn((char *)jobs + (size_t)t * size);
    }
}

static int clamp_threads(int threads, size_t work) {
    if (threads < 1) threads = 1;
    if (threads > 64) threads = 64;
    if ((size_t)threads > work) threads = work ? (int)work : 1;
    return threads;
}

/* ------------------------------------------------------------------------
 * h(A, B).
 * ---------------------------------------------------------------------- */

typedef struct {
    const double *A;
    size_t na;
    const size_t *visit; /* A's indices in visiting order (NULL: 0, 1, ...) */
    nd_set_t B;
    int early, t, T;
    _Atomic uint64_t *shared; /* bits of the largest c published (>= 0) */
    nd_directed_t res;
    int found;
} directed_job_t;

static double from_bits(uint64_t u) {
    double d;
    memcpy(&d, &u, sizeof d);
    return d;
}

static uint64_t to_bits(double d) {
    uint64_t u;
    memcpy(&u, &d, sizeof u);
    return u;
}

/* Non-negative doubles order as their bit patterns. */
static void publish(_Atomic uint64_t *shared, double c) {
    uint64_t want = to_bits(c), cur = atomic_load_explicit(shared, memory_order_relaxed);
    while (want > cur &&
           !atomic_compare_exchange_weak_explicit(shared, &cur, want, memory_order_relaxed,
                                                  memory_order_relaxed)) {
    }
}

/* The bound below which point i's scan stops (see the file's comment). */
static double stop_of(const directed_job_t *J, double c, size_t ci, size_t i) {
    if (!J->early) return -INFINITY;
    double g = from_bits(atomic_load_explicit(J->shared, memory_order_relaxed));
    double own = c >= 0 && i > ci ? nextafter(c, INFINITY) : c;
    return g > own ? g : own;
}

static void *directed_job(void *arg) {
    directed_job_t *J = arg;
    size_t dims = J->B.dims, ci = 0, cj = 0;
    double c = -1.0; /* no point yet */
    uint64_t evals = 0;
    for (size_t v = (size_t)J->t; v < J->na; v += (size_t)J->T) {
        size_t i = J->visit ? J->visit[v] : v, k;
        double best;
        if (scan(&J->B, J->A + i * dims, stop_of(J, c, ci, i), &best, &k, &evals)) continue;
        if (best > c || (best == c && i < ci)) {
            c = best;
            ci = i;
            cj = index_of(&J->B, k);
            if (J->early) publish(J->shared, c);
        }
    }
    J->found = c >= 0;
    J->res = (nd_directed_t){c, ci, cj, evals};
    return NULL;
}

/* splitmix64: the visiting orders' random numbers. */
static uint64_t next_random(uint64_t *state) {
    uint64_t z = (*state += 0x9e3779b97f4a7c15u);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return z ^ (z >> 31);
}

/* v[0..n) in a random order. */
static void shuffle_part(size_t *v, size_t n, uint64_t *state) {
    for (size_t k = n; k > 1; k--) {
        size_t r = (size_t)(next_random(state) % k), t = v[k - 1];
        v[k - 1] = v[r];
        v[r] = t;
    }
}

/* 0, 1, ..., n - 1 in a random order. */
static void shuffle(size_t *v, size_t n, uint64_t *state) {
    for (size_t k = 0; k < n; k++) v[k] = k;
    shuffle_part(v, n, state);
}

/* A squared distance for ordering heuristics only (any rounding will do). */
static double rough_dist2(const double *p, const double *q, size_t dims) {
    double s = 0.0;
    for (size_t k = 0; k < dims; k++) s += (p[k] - q[k]) * (p[k] - q[k]);
    return s;
}

/* Do the rows order[0..m) come nearer to A's points than order[m..2m) do?
 * Asked of the first points of `visit` (a random sample of A). */
static int nearer_first(const double *A, const size_t *visit, size_t na, const double *B,
                        const size_t *order, size_t m, size_t dims) {
    size_t wins = 0, tries = na < 64 ? na : 64;
    for (size_t v = 0; v < tries; v++) {
        const double *a = A + visit[v] * dims;
        double best[2] = {INFINITY, INFINITY};
        for (size_t r = 0; r < 2 * m; r++) {
            double d = rough_dist2(a, B + order[r] * dims, dims);
            best[r >= m] = d < best[r >= m] ? d : best[r >= m];
        }
        wins += best[0] < best[1];
    }
    return 2 * wins > tries;
}

/* Any order of B gives the same result; the early break is quick when
 * the first rows are near most points of A.  In many coordinates the rows
 * nearest A's centroid are (a point is nearer the middle than a random
 * other point is), in few they are not (nearest neighbours are much nearer
 * than the middle): so the CENTRAL rows nearest the centroid go first, in
 * that order, when on a sample of A they come nearer than as many random
 * rows; the rest stay in random order.  -1 when there is no memory. */
static int central_first(const double *A, size_t na, const size_t *visit, const double *B,
                         size_t nb, size_t dims, size_t *order, uint64_t *state) {
    if (nb < 2 * CENTRAL) return 0;
    double *c = calloc(dims, sizeof *c), *key = malloc(nb * sizeof *key);
    if (!c || !key) {
        free(c);
        free(key);
        return -1;
    }
    for (size_t i = 0; i < na; i++)
        for (size_t k = 0; k < dims; k++) c[k] += A[i * dims + k] / (double)na;
    for (size_t r = 0; r < nb; r++) key[r] = rough_dist2(B + order[r] * dims, c, dims);
    select_keyed(key, order, nb, CENTRAL);
    for (size_t r = 1; r < CENTRAL; r++) /* insertion sort of the first CENTRAL */
        for (size_t q = r; q > 0 && key[q] < key[q - 1]; q--) swap_keyed(key, order, q, q - 1);
    shuffle_part(order + CENTRAL, nb - CENTRAL, state);
    if (!nearer_first(A, visit, na, B, order, CENTRAL, dims)) shuffle_part(order, nb, state);
    free(c);
    free(key);
    return 0;
}

int nd_directed(const double *A, size_t na, const double *B, size_t nb, size_t dims,
                int early, uint64_t seed, int threads, nd_directed_t *out) {
    size_t *visit = NULL, *order = NULL;
    nd_set_t set = {NULL, NULL, NULL, NULL, nb, dims, 0};
    if (early) { /* A and B in random orders, central rows of B perhaps first */
        visit = malloc(na * sizeof *visit);
        order = malloc(nb * sizeof *order);
    }
    uint64_t state = seed;
    if (visit && order) {
        shuffle(visit, na, &state);
        shuffle(order, nb, &state);
    }
    if ((early && (!visit || !order || central_first(A, na, visit, B, nb, dims, order, &state))) ||
        set_build(&set, B, nb, dims, 0, order)) {
        free(visit);
        if (!set.order) free(order);
        set_free(&set);
        return -1;
    }
    int T = clamp_threads(threads, na);
    directed_job_t jobs[64];
    _Atomic uint64_t shared = 0;
    for (int t = 0; t < T; t++)
        jobs[t] = (directed_job_t){A, na, visit, set, early, t, T, &shared, {0, 0, 0, 0}, 0};
    run_jobs(directed_job, jobs, sizeof jobs[0], T);
    nd_directed_t r = {-1.0, 0, 0, 0};
    uint64_t evals = 0;
    for (int t = 0; t < T; t++) {
        const nd_directed_t *x = &jobs[t].res;
        evals += x->distance_evals;
        if (jobs[t].found && (x->d2 > r.d2 || (x->d2 == r.d2 && x->i < r.i))) r = *x;
    }
    r.distance_evals = evals;
    *out = r;
    free(visit);
    set_free(&set);
    return 0;
}

/* ------------------------------------------------------------------------
 * Nearest distances.
 * ---------------------------------------------------------------------- */

typedef struct {
    const double *A;
    size_t lo, hi;
    nd_set_t B;
    double *dist;
    size_t *nearest;
} nearest_job_t;

static void *nearest_job(void *arg) {
    nearest_job_t *J = arg;
    uint64_t evals = 0;
    for (size_t i = J->lo; i < J->hi; i++) {
        double best;
        size_t k;
        scan(&J->B, J->A + i * J->B.dims, -INFINITY, &best, &k, &evals);
        if (J->dist) J->dist[i] = sqrt(best);
        if (J->nearest) J->nearest[i] = index_of(&J->B, k);
    }
    return NULL;
}

int nd_nearest(const double *A, size_t na, const double *B, size_t nb, size_t dims,
               int threads, double *dist, size_t *nearest) {
    nd_set_t set;
    if (set_build(&set, B, nb, dims, dims <= TREE_MAX_DIMS, NULL)) {
        set_free(&set);
        return -1;
    }
    int T = clamp_threads(threads, na);
    nearest_job_t jobs[64];
    for (int t = 0; t < T; t++)
        jobs[t] = (nearest_job_t){A, na * (size_t)t / (size_t)T, na * (size_t)(t + 1) / (size_t)T,
                                  set, dist, nearest};
    run_jobs(nearest_job, jobs, sizeof jobs[0], T);
    set_free(&set);
    return 0;
}
