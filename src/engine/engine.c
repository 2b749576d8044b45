/*
 * engine.c -- the `auto` engine's plan and its entry points for the layers
 * above (hd__engine_directed, hd__engine_hausdorff, hd__engine_trees for
 * the public index, and hd__engine_forced / hd__engine_explain for tests
 * and benchmarks).  The design, why each piece is there and what it was
 * measured to save, is told once, in docs/engine.md; the pieces live
 * beside this file: the correspondence path in pairs.c, the grid and its
 * pass in grid.c, the trees in build.c, their search in search.c, the walk
 * over two trees in walk.c, the running maximum the threads share in
 * max.c.
 *
 * The plan (engine_plan, engine_run) tries, in order: pairs.c's shortcuts,
 * then for each open direction the grid pass when its trial on a sample
 * is cheap in every direction (GRID_COST), else the bucket trees and
 * their walk (walk.c).  A direction settled by one path is not run again, and every
 * maximum found carries over to the next path.  The plan decides only
 * speed, never the answer.
 *
 * What the code relies on:
 *  - cmax (the shared hd__bound_t) is always the exact nearest squared
 *    distance of some point of A, so it never exceeds h(A,B)^2.
 *  - A point or node of A is discarded only when a point b of B is proven,
 *    exactly or through the bounds of tree.h (hd__kill_below,
 *    hd__may_reach, exact boxes), strictly within cmax of it, or at most at
 *    a maximum already attained at a smaller index of A (hd__kills): it
 *    cannot be the witness.
 *  - Every other point gets an exact search that returns the smallest
 *    nearest index (search.c, grid.c), and the maxima merge in max.c by
 *    hd__best_offer (larger distance, then smaller index).
 *  - Threads take subtrees of A from a shared counter; timing changes only
 *    how much is discarded, never what survives, so the result and the
 *    witness are the brute force's, bit for bit, at any thread count and in
 *    any schedule.
 */
#include "engine/pairs.h"
#include "engine/tree.h"
#include "engine/walk.h"

#include <assert.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- the plan: grid or trees -------------------------------------------------------- */

/* The grid pass is chosen when, run over a sample of each query set, it
 * costs at most GRID_COST distances and nodes per point; otherwise both
 * sets get the bucket trees.  The threshold separates two populations of
 * hd_bench's cases (bench/bench.c prints each case's trial cost and
 * plan): the cases the grid pass answers faster cost less, those the trees
 * answer faster (independent uniform cubes among them) cost more, and the
 * threshold lies near the geometric mean of the costliest of the first and
 * the cheapest of the second.  The figures are in docs/engine.md, "Step 2:
 * the plan". */
#define GRID_COST 4.0

/* The early decision (engine_plan): for sets of EARLY_MIN points or more,
 * h(A,B)'s trial runs on B's grid alone, primed from every
 * (n / EARLY_SAMPLE + 1)-th point of A (hd__grid_prime_sampled) rather
 * than from A's grid, and above EARLY_COST the trees are taken at once,
 * A's grid never built: on the trees' cases that grid and the other
 * direction's prime and trial are work thrown away.  With the weaker prime
 * the trial discards fewer of its points, so its cost tends to come out
 * higher than the full plan's; EARLY_COST keeps a margin above GRID_COST
 * for that (hd_bench prints the costs on each side of it; the figures are
 * in docs/engine.md, "Step 2: the plan"). */
#define EARLY_MIN 65536
#define EARLY_SAMPLE 65536
#define EARLY_COST 8.0

typedef struct {
    hd__src_t src[2]; /* 0: A, 1: B */
    size_t n[2];
    hd__box_t box[2];
    int threads, directions; /* 1: h(A,B) only; 2: both */
    hd__grid_t grid[2];
    hd__tree_t tree[2];
    int have_grid, have_tree, use_tree;
    hd__pairs_t pairs;    /* the correspondence path; pairs.resolved[d] */
    hd__max_t max[2];     /* direction d: from set d to set 1 - d */
    int max_ready;
    hd__counts_t counts[2];
    uint64_t culled[2];
    double cost[2];
    size_t seed[HD__PRIME_CELLS]; /* h(B,A)'s prime after an early decision */
    int nseed;
    hd__reuse_t pool;      /* the grids' and trees' arrays, reused as they are freed */
} engine_t;

static void engine_free(engine_t *e) {
    if (e->have_grid)
        for (int k = 0; k < 2; k++) hd__grid_free(&e->grid[k]);
    if (e->have_tree)
        for (int k = 0; k < 2; k++) hd__tree_free(&e->tree[k]);
    for (int d = 0; d < e->max_ready; d++) hd__max_destroy(&e->max[d]);
    hd__pairs_free(&e->pairs);
    hd__reuse_free(&e->pool); /* keeps pool.peak, the call's high-water mark */
    e->have_grid = e->have_tree = e->max_ready = 0;
}

static int engine_init(engine_t *e, const hd_points_t *A, const hd_points_t *B,
                       const hd__box_t *box_a, const hd__box_t *box_b, const hd_options_t *opt,
                       int directions, hd_error_t *err) {
    memset(e, 0, sizeof *e);
    hd__reuse_init(&e->pool);
    hd__src_init(&e->src[0], A, NULL);
    hd__src_init(&e->src[1], B, NULL);
    e->n[0] = A->count;
    e->n[1] = B->count;
    e->box[0] = *box_a;
    e->box[1] = *box_b;
    e->directions = directions;
    e->threads = hd__thread_count(opt->threads, A->count > B->count ? A->count : B->count);
    for (int d = 0; d < directions; d++) {
        if (hd__max_init(&e->max[d]) != HD_OK) {
            engine_free(e);
            return hd__err(err, HD_ETHREAD, "cannot create a mutex");
        }
        e->max_ready = d + 1;
    }
    return HD_OK;
}

/* h(B,A)'s prime when the early decision leaves A without a grid: the
 * representatives of B's cells farthest from a grid of every
 * SEED_STEP-th point of A (hd__grid_prime_picks_far), kept in e->seed for
 * the tree walk's prime to resolve exactly once A's tree is built.  The
 * sample's grid has the cells A's own would have (hd__grid_build_as), so
 * its searches read few points a cell.  Without the seeds h(B,A)'s walk
 * started from a weaker maximum (docs/engine.md, "Step 2"). */
#define SEED_STEP 16

static int early_seeds(engine_t *e, hd_error_t *err) {
    hd__src_t sub = e->src[0];
    sub.kind = HD__SRC_ANY; /* every SEED_STEP-th point: the stride grows */
    sub.ps *= SEED_STEP;
    size_t ns = (e->n[0] + SEED_STEP - 1) / SEED_STEP;
    hd__grid_t gs;
    int rc = hd__grid_build_as(&gs, &sub, ns, e->n[0], &e->box[0], e->threads, &e->pool, err);
    if (rc) return rc;
    e->nseed = hd__grid_prime_picks_far(&e->grid[1], &gs, e->seed);
    hd__grid_free(&gs);
    return HD_OK;
}

/* Try the correspondence path and the ordered subset (unless a path is
 * forced); then build B's grid and, for large sets, run h(A,B)'s early
 * trial, which may send both sets to the trees at once (with seeds for
 * h(B,A)); else build A's grid, prime each direction's maximum from the
 * representatives of the query set's cells, and choose by the trials. */
static int engine_plan(engine_t *e, hd__engine_force_t force, hd_error_t *err) {
    /* Two sets of one size may be a copy and its original in the same
     * order; the correspondence path often settles that case in one pass,
     * before any index is built. */
    /* (Not with a filter on a maximum: those paths settle a direction
     * from its pairs' distances, which a filter may have refused.) */
    int filtered = e->max[0].keep.keep || e->max[1].keep.keep;
    if (force == HD__ENGINE_PLANNED && e->n[0] == e->n[1] && !filtered) {
        int rc = hd__pairs_begin(&e->pairs, e->src, e->n[0], e->threads, &e->counts[0], err);
        if (rc) return rc;
        if (hd__pairs_resolve(&e->pairs, e->src, NULL, e->max, e->directions, e->counts))
            return HD_OK;
    }
    /* The smaller set may be an ordered subset of the larger: its direction
     * is then 0, settled by one merge walk. */
    for (int d = 0; d < e->directions && force == HD__ENGINE_PLANNED && !filtered; d++)
        if (e->n[d] < e->n[1 - d])
            e->pairs.resolved[d] = hd__subset_resolve(&e->src[d], e->n[d], &e->src[1 - d],
                                                      e->n[1 - d], &e->max[d], &e->counts[d]);
    if (e->pairs.resolved[0] && (e->directions == 1 || e->pairs.resolved[1])) return HD_OK;
    /* B's grid first: h(A,B)'s trial needs no other.  Primed from a sample
     * of A, a trial costing more than EARLY_COST sends both sets to the
     * trees before A's grid is built (see EARLY_COST). */
    int rc = hd__grid_build(&e->grid[1], &e->src[1], e->n[1], &e->box[1], e->threads, &e->pool, err);
    if (rc) return rc;
    e->have_grid = 1;
    e->use_tree = 0;
    int early = force == HD__ENGINE_PLANNED && !e->pairs.active && !e->pairs.resolved[0] &&
                e->n[0] >= EARLY_MIN;
    double early_cost = 0;
    if (early) {
        hd__grid_prime_sampled(&e->src[0], e->n[0], e->n[0] / EARLY_SAMPLE + 1, &e->grid[1], &e->max[0],
                               &e->counts[0]);
        early_cost = hd__grid_trial(&e->src[0], e->n[0], &e->grid[1], &e->max[0], EARLY_COST, &e->counts[0]);
        if (early_cost > EARLY_COST) {
            e->cost[0] = early_cost;
            e->use_tree = 1;
            return e->directions == 2 && !e->pairs.resolved[1] ? early_seeds(e, err) : HD_OK;
        }
    }
    if ((rc = hd__grid_build(&e->grid[0], &e->src[0], e->n[0], &e->box[0], e->threads, &e->pool, err)))
        return rc;
    for (int d = 0; d < e->directions; d++)
        if (!e->pairs.resolved[d])
            hd__grid_prime(&e->grid[d], &e->grid[1 - d], &e->max[d], &e->counts[d]);
    hd__pairs_resolve(&e->pairs, e->src, e->grid, e->max, e->directions, e->counts);
    for (int d = 0; d < e->directions; d++) {
        if (e->pairs.resolved[d]) continue;
        /* A trial that found the grid cheap with the sample's prime stands,
         * and is not run again: on the grid's cases the two primes' trials
         * differed by at most 0.4 (docs/engine.md, "Step 2: the plan"),
         * and a grid case costs 2.6 at most against GRID_COST 4. */
        if (d == 0 && early && early_cost <= GRID_COST) e->cost[d] = early_cost;
        else
            e->cost[d] = hd__grid_trial(&e->src[d], e->n[d], &e->grid[1 - d], &e->max[d], GRID_COST,
                                        &e->counts[d]);
        if (e->cost[d] > GRID_COST) e->use_tree = 1;
    }
    return HD_OK;
}

/* The plan in a word: "pairs" when the correspondence path settled every
 * direction, else the path the rest runs. */
static hd__plan_path_t engine_plan_path(const engine_t *e) {
    int all = 1;
    for (int d = 0; d < e->directions; d++) all &= e->pairs.resolved[d];
    return all ? HD__PLAN_PAIRS : e->use_tree ? HD__PLAN_TREES : HD__PLAN_GRID;
}

/* The mean of a set's points (approximate: for the trees' frame only),
 * summed by slices of CENTROID_SLICE points over the threads, each in
 * four running sums per coordinate (the adds do not wait on each other),
 * and the slices' sums added in order: the same value at any thread
 * count.  Read only for a moved copy (engine_run), so no other case pays
 * the pass. */
#define CENTROID_SLICE 65536

typedef struct {
    const hd__src_t *src;
    size_t n;
    double (*sum)[3];
} centroid_ctx;

static void centroid_task(void *vctx, size_t task, int worker) {
    (void)worker;
    centroid_ctx *c = vctx;
    size_t lo = task * CENTROID_SLICE, hi = lo + CENTROID_SLICE < c->n ? lo + CENTROID_SLICE : c->n;
    double sum[4][3] = {{0}};
    for (size_t i = lo; i < hi; i++) {
        double p[3];
        hd__src_get(c->src, i, p);
        double *t = sum[i & 3];
        t[0] += p[0], t[1] += p[1], t[2] += p[2];
    }
    for (int k = 0; k < 3; k++) c->sum[task][k] = (sum[0][k] + sum[1][k]) + (sum[2][k] + sum[3][k]);
}

static int centroid_of(const hd__src_t *src, size_t n, int threads, double out[3], hd_error_t *err) {
    if (n == 0) {
        out[0] = out[1] = out[2] = 0;
        return HD_OK;
    }
    size_t slices = (n + CENTROID_SLICE - 1) / CENTROID_SLICE;
    centroid_ctx c = {src, n, hd__malloc_array(slices, sizeof *c.sum)};
    if (!c.sum) return hd__err(err, HD_ENOMEM, "out of memory");
    hd__parallel_for(hd__thread_count(threads, slices), slices, centroid_task, &c);
    for (int k = 0; k < 3; k++) {
        double t = 0;
        for (size_t s = 0; s < slices; s++) t += c.sum[s][k];
        out[k] = t / (double)n;
    }
    free(c.sum);
    return HD_OK;
}

/* force: the plan's choice, or the grid or the trees forced. */
/* B is taken for a moved copy of A (engine_run's grids) when its box is
 * A's moved by one vector: the two corners' moves differ by at most this
 * fraction of A's extent, and the move itself is larger.  A bound on
 * relative noise only decides which grid the trees get, never the
 * answer. */
#define MOVED_SKEW 1e-4

static int engine_run(engine_t *e, hd__engine_force_t force, hd_result_t out[2], hd_error_t *err) {
    int rc = engine_plan(e, force, err);
    if (rc) return rc;
    if (force != HD__ENGINE_PLANNED) e->use_tree = force == HD__ENGINE_FORCE_TREES;
    if (e->use_tree) {
        /* The grids give way to the trees (memory stays under 16 bytes per
         * point of both sets: hd__tree_build_pair); the maxima found so far
         * stay valid.  Both trees' Morton grids have the same cell size, and
         * the walk's neighbour scans rely on the two curves lining up.  When B's box is A's box moved (both
         * corners by the same vector, within MOVED_SKEW of the extent, and
         * by more than that), B looks like a moved copy: each grid is centred on its
         * own set's centroid, so that the copy lists its points in nearly
         * the original's order.  Any other pair (nearly identical sets, a
         * subset, a part, a different shape) shares one grid over both
         * boxes, so that equal points get equal keys. */
        double c[2][3], r = 0, ext = 0, skew = 0, move = 0;
        for (int k = 0; k < 3; k++) {
            double x0 = e->box[0].hi[k] - e->box[0].lo[k];
            double dlo = e->box[1].lo[k] - e->box[0].lo[k], dhi = e->box[1].hi[k] - e->box[0].hi[k];
            ext = x0 > ext ? x0 : ext;
            skew = fabs(dlo - dhi) > skew ? fabs(dlo - dhi) : skew;
            move = fabs(dlo) > move ? fabs(dlo) : move;
        }
        hd__box_t g[2];
        if (skew <= MOVED_SKEW * ext && move > MOVED_SKEW * ext) {
            for (int s2 = 0; s2 < 2; s2++) {
                if ((rc = centroid_of(&e->src[s2], e->n[s2], e->threads, c[s2], err)) != HD_OK) return rc;
                for (int k = 0; k < 3; k++) {
                    double u = c[s2][k] - e->box[s2].lo[k], v = e->box[s2].hi[k] - c[s2][k];
                    r = u > r ? u : r;
                    r = v > r ? v : r;
                }
            }
            for (int s2 = 0; s2 < 2; s2++)
                for (int k = 0; k < 3; k++) {
                    g[s2].lo[k] = c[s2][k] - r;
                    g[s2].hi[k] = c[s2][k] + r;
                }
        } else {
            double lo[3], w = 0;
            for (int k = 0; k < 3; k++) {
                lo[k] = e->box[0].lo[k] < e->box[1].lo[k] ? e->box[0].lo[k] : e->box[1].lo[k];
                double hi = e->box[0].hi[k] > e->box[1].hi[k] ? e->box[0].hi[k] : e->box[1].hi[k];
                w = hi - lo[k] > w ? hi - lo[k] : w;
            }
            for (int s2 = 0; s2 < 2; s2++)
                for (int k = 0; k < 3; k++) g[s2].lo[k] = lo[k], g[s2].hi[k] = lo[k] + w;
        }
        for (int k = 0; k < 2; k++) hd__grid_free(&e->grid[k]);
        e->have_grid = 0;
        rc = hd__tree_build_pair(e->tree, e->src, e->n, g, e->threads, &e->pool, err);
        if (rc) return rc;
        e->have_tree = 1;
    }
    for (int d = 0; d < e->directions; d++) {
        double t0 = hd__now();
        if (e->pairs.resolved[d])
            rc = HD_OK;
        else if (e->use_tree)
            rc = hd__walk_directed(&e->tree[d], &e->tree[1 - d], &e->max[d], e->threads, d ? e->seed : NULL,
                               d ? e->nseed : 0, &e->counts[d], &e->culled[d], err);
        else
            rc = hd__grid_directed(&e->grid[d], &e->grid[1 - d], &e->max[d], e->threads,
                                   &e->counts[d], &e->culled[d], err);
        if (rc) return rc;
        hd_result_t *r = &out[d];
        memset(r, 0, sizeof *r);
        hd__best_t b;
        hd__max_snapshot(&e->max[d], &b);
        r->distance2 = b.d2;
        r->distance = sqrt(b.d2);
        r->i = b.i;
        r->j = b.j;
        r->algorithm = HD_ALG_AUTO;
        r->stats.distance_evals = e->counts[d].evals + e->counts[d].exact;
        r->stats.nodes_visited = e->counts[d].nodes;
        r->stats.points_culled = e->culled[d];
        r->seconds = hd__now() - t0;
    }
    return HD_OK;
}

/* ---- entry points ---------------------------------------------------------------- */

int hd__engine_trees(const hd__tree_t *ta, const hd__tree_t *tb, int threads, hd_result_t *out,
                     hd_error_t *err) {
    hd__max_t m;
    if (hd__max_init(&m) != HD_OK) return hd__err(err, HD_ETHREAD, "cannot create a mutex");
    hd__counts_t counts = {0, 0, 0};
    uint64_t culled = 0;
    int rc = hd__walk_directed(ta, tb, &m, threads, NULL, 0, &counts, &culled, err);
    if (rc == HD_OK) {
        memset(out, 0, sizeof *out);
        out->distance2 = m.best.d2;
        out->distance = sqrt(m.best.d2);
        out->i = m.best.i;
        out->j = m.best.j;
        out->algorithm = HD_ALG_AUTO;
        out->stats.distance_evals = counts.evals + counts.exact;
        out->stats.nodes_visited = counts.nodes;
        out->stats.points_culled = culled;
    }
    hd__max_destroy(&m);
    return rc;
}

int hd__engine_directed(const hd_points_t *A, const hd_points_t *B, const hd__box_t *box_a,
                        const hd__box_t *box_b, const hd_options_t *opt, hd_result_t *out,
                        hd_error_t *err) {
    return hd__engine_directed_above(A, B, box_a, box_b, opt, -1.0, 0, out, err);
}

static int engine_directed(const hd_points_t *A, const hd_points_t *B, const hd__box_t *box_a,
                           const hd__box_t *box_b, const hd_options_t *opt, double floor2, size_t floor_i,
                           const hd__keep_t *keep, hd_result_t *out, hd_error_t *err) {
    double t0 = hd__now();
    engine_t e;
    int rc = engine_init(&e, A, B, box_a, box_b, opt, 1, err);
    if (rc) return rc;
    if (keep) e.max[0].keep = *keep;
    /* A virtual point at the floor: every path only offers real points to
     * the maximum and prunes against it, so what survives is what beats it. */
    if (floor2 >= 0) {
        hd__best_offer(&e.max[0].best, floor2, floor_i, HD__NONE);
        hd__bound_raise(&e.max[0].cmax, floor2);
    }
    hd_result_t r[2];
    rc = engine_run(&e, HD__ENGINE_PLANNED, r, err);
    engine_free(&e);
    if (rc) return rc;
    *out = r[0];
    out->stats.peak_bytes = e.pool.peak;
    out->seconds = hd__now() - t0;
    return HD_OK;
}

int hd__engine_directed_above(const hd_points_t *A, const hd_points_t *B, const hd__box_t *box_a,
                              const hd__box_t *box_b, const hd_options_t *opt, double floor2, size_t floor_i,
                              hd_result_t *out, hd_error_t *err) {
    return engine_directed(A, B, box_a, box_b, opt, floor2, floor_i, NULL, out, err);
}

int hd__engine_directed_kept(const hd_points_t *A, const hd_points_t *B, const hd__box_t *box_a,
                             const hd__box_t *box_b, const hd_options_t *opt, const hd__keep_t *keep,
                             hd_result_t *out, hd_error_t *err) {
    return engine_directed(A, B, box_a, box_b, opt, -1.0, 0, keep, out, err);
}

static int engine_symmetric(const hd_points_t *A, const hd_points_t *B, const hd__box_t *box_a,
                            const hd__box_t *box_b, const hd_options_t *opt, hd__engine_force_t force,
                            const hd__keep_t keep[2], hd_symmetric_t *out, hd_error_t *err) {
    double t0 = hd__now();
    engine_t e;
    int rc = engine_init(&e, A, B, box_a, box_b, opt, 2, err);
    if (rc) return rc;
    for (int d = 0; d < 2 && keep; d++) e.max[d].keep = keep[d];
    hd_result_t r[2];
    rc = engine_run(&e, force, r, err);
    engine_free(&e);
    if (rc) return rc;
    /* The shared work (grids or trees, the plan) is split between the two
     * directions' times in proportion to nothing in particular: half each. */
    double total = hd__now() - t0, walks = r[0].seconds + r[1].seconds;
    out->ab = r[0];
    out->ba = r[1];
    out->ab.stats.peak_bytes = out->ba.stats.peak_bytes = e.pool.peak; /* one call, one peak */
    out->ab.seconds = r[0].seconds + (total - walks) / 2;
    out->ba.seconds = r[1].seconds + (total - walks) / 2;
    return HD_OK;
}

int hd__engine_hausdorff(const hd_points_t *A, const hd_points_t *B, const hd__box_t *box_a,
                         const hd__box_t *box_b, const hd_options_t *opt, hd_symmetric_t *out,
                         hd_error_t *err) {
    return engine_symmetric(A, B, box_a, box_b, opt, HD__ENGINE_PLANNED, NULL, out, err);
}

int hd__engine_hausdorff_kept(const hd_points_t *A, const hd_points_t *B, const hd__box_t *box_a,
                              const hd__box_t *box_b, const hd_options_t *opt, const hd__keep_t keep[2],
                              hd_symmetric_t *out, hd_error_t *err) {
    return engine_symmetric(A, B, box_a, box_b, opt, HD__ENGINE_PLANNED, keep, out, err);
}

int hd__engine_forced(const hd_points_t *A, const hd_points_t *B, const hd_options_t *opt,
                      hd__engine_force_t force, hd_symmetric_t *out, hd_error_t *err) {
    hd__box_t ba, bb;
    int rc = hd__points_scan(A, "A", opt->threads, &ba, err);
    if (rc == HD_OK) rc = hd__points_scan(B, "B", opt->threads, &bb, err);
    if (rc) return rc;
    memset(out, 0, sizeof *out);
    rc = engine_symmetric(A, B, &ba, &bb, opt, force, NULL, out, err);
    if (rc == HD_OK)
        out->distance = out->ab.distance2 >= out->ba.distance2 ? out->ab.distance : out->ba.distance;
    return rc;
}

int hd__engine_explain(const hd_points_t *A, const hd_points_t *B, const hd_options_t *opt,
                       hd__engine_plan_t *plan, char *buf, size_t len, hd_error_t *err) {
    hd__box_t ba, bb;
    int rc = hd__points_scan(A, "A", opt->threads, &ba, err);
    if (rc == HD_OK) rc = hd__points_scan(B, "B", opt->threads, &bb, err);
    if (rc) return rc;
    engine_t e;
    rc = engine_init(&e, A, B, &ba, &bb, opt, 2, err);
    if (rc) return rc;
    rc = engine_plan(&e, HD__ENGINE_PLANNED, err);
    if (rc == HD_OK) {
        hd__engine_plan_t p = {engine_plan_path(&e), e.pairs.active != 0,
                               {e.pairs.resolved[0] != 0, e.pairs.resolved[1] != 0}, {e.cost[0], e.cost[1]}};
        static const char *const name[] = {[HD__PLAN_PAIRS] = "pairs", [HD__PLAN_GRID] = "grid",
                                           [HD__PLAN_TREES] = "trees"};
        if (plan) *plan = p;
        if (len)
            snprintf(buf, len,
                     "%s (pairs %s, resolved %d / %d; grid trial: %.3g / %.3g distances and nodes per "
                     "point)",
                     name[p.path], p.pairs_listed ? "listed" : "not tried", p.resolved[0], p.resolved[1],
                     p.grid_cost[0], p.grid_cost[1]);
    }
    engine_free(&e);
    return rc;
}
