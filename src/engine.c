/*
 * engine.c -- the `auto` engine: exact h(A,B) and H(A,B) over the Morton
 * bucket indexes of engine_build.c.
 *
 * The engine combines three of the paper's ideas with an index that is cheap
 * to build.  Both sets are indexed once (engine_build.c); h(A,B) then walks
 * A's tree in Morton order and searches B's tree:
 *  1. A lower bound cmax is primed from a sample of A whose exact nearest
 *     distances are computed first (the paper's AHD, Algorithm 6, line 1).
 *  2. A whole node of A (a bucket or a run of buckets) is discarded when one
 *     point b of B is proven closer than cmax to every point of the node's
 *     box: hd__box_ub2(box, b) < cmax^2, strictly (the paper's CubeToPoints,
 *     Algorithm 4, lines 5-7, applied to A's nodes).  The b tried is the last
 *     point of B that discarded something, which is usually nearby because
 *     A is walked along its curve.
 *  3. Every remaining point a is first tested against that same b, then
 *     searched in B's tree starting from the bucket where the previous search
 *     ended, stopping as soon as some point of B lies strictly within cmax
 *     (EARLYBREAK, Algorithm 2, lines 8-10).  A search that does not stop is
 *     an exact nearest-neighbour search; its result is a candidate for the
 *     maximum and raises cmax.
 * Threads take subtrees of A from a shared counter and share cmax through
 * an atomic.
 *
 * Exactness and the witness.  cmax is always the exact nearest distance of
 * some point of A, so it never exceeds h(A,B).  A point or node is discarded
 * only on a strict inequality d2(a, b) < cmax^2 (or ub2 < cmax^2, which
 * bounds d2(a, b) from above for every a in the box: internal.h), which
 * proves that its nearest distance is strictly less than h(A,B): it can be
 * neither the maximum nor tied with it.  So every point whose nearest
 * distance equals h(A,B) reaches a search that cannot stop early and gets
 * its exact nearest distance and smallest nearest index (engine_search.c);
 * the per-task maxima merge with hd__best_offer, which keeps the smallest
 * index of A on ties.  The result is the brute force's, bit for bit, at any
 * thread count and in any schedule: timing changes only how much is
 * discarded, never what survives to the end.
 */
#include "index.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

/* ---- one direction ------------------------------------------------------------ */

typedef struct {
    hd__counts_t counts;
    uint64_t culled;
} worker_t;

typedef struct {
    const hd__tree_t *ta, *tb;
    hd__bound_t cmax;     /* the largest exact nearest distance so far */
    pthread_mutex_t lock; /* guards best */
    hd__best_t best;      /* the maximum so far with its canonical witness */
    int task_level;
    worker_t *w;
} dir_ctx;

/* The state of one task's walk. */
typedef struct {
    dir_ctx *c;
    worker_t *w;
    hd__best_t snap;   /* a consistent copy of c->best */
    double bc[3];      /* the last point of B that discarded something, */
    double bc_err;     /* known within this distance */
    int have_bc;
    size_t hint;       /* bucket of B where the last search ended */
} walk_t;

static void walk_init(walk_t *s, dir_ctx *c, worker_t *w) {
    s->c = c;
    s->w = w;
    pthread_mutex_lock(&c->lock);
    s->snap = c->best;
    pthread_mutex_unlock(&c->lock);
    s->have_bc = 0;
    s->hint = HD__NONE;
}

/* Record an exact nearest distance: into the shared maximum (canonical
 * witness by hd__best_offer), the shared bound, and this walk's snapshot. */
static void offer(walk_t *s, double d2, size_t i, size_t j) {
    dir_ctx *c = s->c;
    pthread_mutex_lock(&c->lock);
    hd__best_offer(&c->best, d2, i, j);
    s->snap = c->best;
    pthread_mutex_unlock(&c->lock);
    hd__bound_raise(&c->cmax, d2);
}

static size_t node_points(const hd__tree_t *t, int level, size_t i) {
    size_t first = (i << level) * HD__BUCKET;
    size_t last = ((i + 1) << level) * HD__BUCKET;
    if (last > t->n) last = t->n;
    return last - first;
}

/* The smallest squared distance between two boxes (0 when they meet). */
HD__INLINE double box_gap2(const hd__box_t *a, const hd__box_t *b) {
    double d[3];
    for (int k = 0; k < 3; k++) {
        double v = 0.0;
        if (a->lo[k] > b->hi[k]) v = a->lo[k] - b->hi[k];
        else if (b->lo[k] > a->hi[k]) v = b->lo[k] - a->hi[k];
        d[k] = v;
    }
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
}

HD__INLINE double centre_gap2(const hd__box_t *a, const hd__box_t *b) {
    double d = 0;
    for (int k = 0; k < 3; k++) {
        double u = (a->lo[k] + a->hi[k]) - (b->lo[k] + b->hi[k]);
        d += u * u;
    }
    return d;
}

/* Resolve one exact point a (original index ia) by a search: discard it,
 * or offer its exact nearest distance.  A point of B at squared distance
 * < cmax^2 discards it (its nearest distance is below the maximum); so does
 * one at distance <= the maximum found so far when that maximum was
 * attained at a smaller index (it cannot be the witness). */
static void resolve_point(walk_t *s, const double a[3], size_t ia) {
    double cmax2 = hd__bound_get(&s->c->cmax);
    double tie2 = ia > s->snap.i ? s->snap.d2 : -1.0;
    hd__hit_t hit;
    hd__tree_nearest(s->c->tb, a, cmax2, tie2, s->hint, &hit, &s->w->counts);
    s->hint = hit.bucket;
    memcpy(s->bc, hit.p, sizeof s->bc);
    s->bc_err = hit.perr;
    s->have_bc = 1;
    if (hit.killed || hit.d2 < cmax2 || hit.d2 <= tie2) return;
    offer(s, hit.d2, ia, hit.j);
}

/* Buckets of B a shared walk may read before the points left over get
 * their own searches. */
#define BLOCK_LEAVES 8

/* The points of one bucket of A being resolved together, known through
 * their quantised copy within err. */
typedef struct {
    int m;
    uint32_t alive; /* bit k: point k not yet discarded */
    double x[HD__BUCKET], y[HD__BUCKET], z[HD__BUCKET];
    double err;
    size_t first;   /* position of point 0 in A's order */
    uint32_t read;  /* bit k: point k's exact coordinates are in a[k] */
    double a[HD__BUCKET][3];
    size_t ia[HD__BUCKET];
} group_t;

/* The exact coordinates of point k of the group (read once). */
static const double *group_exact(const hd__tree_t *ta, group_t *g, int k) {
    if (!(g->read >> k & 1u)) {
        g->ia[k] = ta->perm[g->first + (size_t)k];
        hd__src_get(&ta->src, g->ia[k], g->a[k]);
        g->read |= 1u << k;
    }
    return g->a[k];
}

/* Try bucket i of B on the live points of g; a point is discarded when the
 * approximations prove some point of the bucket strictly within cmax, or
 * when the pair is too close to call and its exact distance does.
 * Returns 1 when the bucket was read. */
static int try_bucket(walk_t *s, group_t *g, size_t i, double cmax2) {
    const hd__tree_t *tb = s->c->tb;
    const hd__bucket_t *bb = &tb->bucket[i];
    double lim = hd__kill_below(cmax2, g->err + bb->err);
    double reach = hd__may_reach(cmax2, g->err + bb->err);
    double lb[HD__BUCKET];
    for (int k = 0; k < HD__BUCKET; k++) lb[k] = hd__box_lb2s(&bb->box, g->x[k], g->y[k], g->z[k]);
    uint32_t near = 0;
    for (int k = 0; k < g->m; k++)
        if ((g->alive >> k & 1u) && lb[k] < cmax2) near |= 1u << k;
    if (!near) return 0;
    double x[HD__BUCKET], y[HD__BUCKET], z[HD__BUCKET];
    int mb = hd__bucket_decode(tb, i, x, y, z);
    int close_k[HD__BUCKET], close_b[HD__BUCKET], n_close = 0;
    for (int k = 0; k < g->m; k++) {
        if (!(near >> k & 1u)) continue;
        double d[HD__BUCKET];
        const double ax = g->x[k], ay = g->y[k], az = g->z[k];
        for (int q = 0; q < HD__BUCKET; q++) d[q] = hd__d2s(ax, ay, az, x[q], y[q], z[q]);
        s->w->counts.evals += (uint64_t)mb;
        double mn = hd__min32(d);
        if (mn > reach) continue;
        int arg = hd__find(d, mn);
        if (mn < lim) {
            g->alive &= ~(1u << k);
            s->bc[0] = x[arg], s->bc[1] = y[arg], s->bc[2] = z[arg];
            s->bc_err = bb->err;
            s->have_bc = 1;
            s->hint = i;
            continue;
        }
        close_k[n_close] = k;
        close_b[n_close++] = arg;
    }
    if (!n_close) return 1;
    /* Pairs too close to call from the approximations (ties, or nearly) are
     * decided exactly; their scattered loads are started together. */
    const hd__tree_t *ta = s->c->ta;
    if (ta->src.kind != 2 && tb->src.kind != 2) {
        ptrdiff_t ea = ta->src.kind == 0 ? 24 : 12, eb = tb->src.kind == 0 ? 24 : 12;
        for (int r = 0; r < n_close; r++) {
            __builtin_prefetch(ta->src.base + (ptrdiff_t)ta->perm[g->first + (size_t)close_k[r]] * ea);
            __builtin_prefetch(tb->src.base + (ptrdiff_t)tb->perm[i * HD__BUCKET + (size_t)close_b[r]] * eb);
        }
    }
    for (int r = 0; r < n_close; r++) {
        int k = close_k[r];
        const double *a = group_exact(ta, g, k);
        double b[3];
        hd__src_get(&tb->src, tb->perm[i * HD__BUCKET + (size_t)close_b[r]], b);
        double e = hd__d2(a, b);
        s->w->counts.exact++;
        if (e < cmax2 || (e <= s->snap.d2 && g->ia[k] > s->snap.i)) {
            g->alive &= ~(1u << k);
            memcpy(s->bc, b, sizeof s->bc);
            s->bc_err = 0;
            s->have_bc = 1;
            s->hint = i;
        }
    }
    return 1;
}

/* Resolve the points of A's bucket bk together, from their quantised copy:
 * try the last useful point of B on each; then the bucket of B where the
 * last search ended and its neighbours along B's curve (for nearly
 * identical sets the nearest points sit at nearly the same place on both
 * curves); then a short walk of B's tree for the whole bucket, nearest
 * buckets first.  Every point that the approximations prove irrelevant is
 * discarded; the points left are read exactly and get their own search. */
static void walk_bucket(walk_t *s, size_t bk) {
    const hd__tree_t *ta = s->c->ta, *tb = s->c->tb;
    group_t g;
    g.m = hd__bucket_decode(ta, bk, g.x, g.y, g.z);
    g.err = ta->bucket[bk].err;
    g.first = bk * HD__BUCKET;
    g.read = 0;
    double cmax2 = hd__bound_get(&s->c->cmax);
    g.alive = g.m == 32 ? 0xffffffffu : (1u << g.m) - 1;
    if (s->have_bc) {
        double lim = hd__kill_below(cmax2, g.err + s->bc_err);
        for (int k = 0; k < g.m; k++)
            if (hd__d2s(g.x[k], g.y[k], g.z[k], s->bc[0], s->bc[1], s->bc[2]) < lim)
                g.alive &= ~(1u << k);
        s->w->counts.evals += (uint64_t)g.m;
    }
    if (g.alive) {
        size_t h = s->hint != HD__NONE ? s->hint : (size_t)((double)bk * (double)tb->nb / (double)ta->nb);
        if (h >= tb->nb) h = tb->nb - 1;
        try_bucket(s, &g, h, cmax2);
        if (g.alive && h + 1 < tb->nb) try_bucket(s, &g, h + 1, cmax2);
        if (g.alive && h > 0) try_bucket(s, &g, h - 1, cmax2);
    }
    const hd__box_t *ba = hd__tree_box(ta, 0, bk);
    struct {
        int level;
        size_t i;
        double gap2;
    } stack[2 * HD__MAX_LEVELS + 2];
    int sp = 0, leaves = 0;
    /* The shared walk pays when cmax is small next to the bucket (nearly
     * identical sets): then only the few buckets of B overlapping this one
     * can discard its points, and the walk visits just those.  When cmax is
     * larger than the bucket, many buckets of B lie within cmax of it and
     * per-point searches, ordered by each point's own distance, do better. */
    double diag2 = 0;
    for (int k = 0; k < 3; k++) diag2 += (ba->hi[k] - ba->lo[k]) * (ba->hi[k] - ba->lo[k]);
    if (g.alive && diag2 > cmax2) {
        stack[0].level = tb->levels - 1;
        stack[0].i = 0;
        stack[0].gap2 = box_gap2(ba, hd__tree_box(tb, tb->levels - 1, 0));
        sp = 1;
    }
    while (sp > 0 && g.alive && leaves < BLOCK_LEAVES) {
        sp--;
        if (stack[sp].gap2 >= cmax2) continue;
        int l = stack[sp].level;
        size_t i = stack[sp].i;
        s->w->counts.nodes++;
        if (l == 0) {
            leaves += try_bucket(s, &g, i, cmax2);
            continue;
        }
        size_t c0 = 2 * i, c1 = 2 * i + 1;
        const hd__box_t *b0 = hd__tree_box(tb, l - 1, c0);
        double g0 = box_gap2(ba, b0);
        if (c1 >= tb->count[l - 1]) {
            if (g0 < cmax2) stack[sp].level = l - 1, stack[sp].i = c0, stack[sp].gap2 = g0, sp++;
            continue;
        }
        const hd__box_t *b1 = hd__tree_box(tb, l - 1, c1);
        double g1 = box_gap2(ba, b1);
        /* Nearer child (by gap, then by centre distance) on top. */
        if (g0 > g1 || (g0 == g1 && centre_gap2(ba, b0) > centre_gap2(ba, b1))) {
            size_t t = c0;
            c0 = c1;
            c1 = t;
            double u = g0;
            g0 = g1;
            g1 = u;
        }
        if (g1 < cmax2) stack[sp].level = l - 1, stack[sp].i = c1, stack[sp].gap2 = g1, sp++;
        if (g0 < cmax2) stack[sp].level = l - 1, stack[sp].i = c0, stack[sp].gap2 = g0, sp++;
    }
    s->w->culled += (uint64_t)(g.m - __builtin_popcount(g.alive));
    if (!g.alive) return;
    /* The points left are read exactly; start all their loads at once. */
    if (ta->src.kind != 2) {
        ptrdiff_t el = ta->src.kind == 0 ? 24 : 12;
        for (int k = 0; k < g.m; k++)
            if ((g.alive >> k & 1u) && !(g.read >> k & 1u))
                __builtin_prefetch(ta->src.base + (ptrdiff_t)ta->perm[g.first + (size_t)k] * el);
    }
    for (int k = 0; k < g.m; k++) {
        if (!(g.alive >> k & 1u)) continue;
        const double *a = group_exact(ta, &g, k); /* sets g.ia[k] */
        resolve_point(s, a, g.ia[k]);
    }
}

static void walk_node(walk_t *s, int level, size_t i) {
    const hd__tree_t *ta = s->c->ta;
    if (s->have_bc) {
        double cmax2 = hd__bound_get(&s->c->cmax);
        if (hd__box_ub2(hd__tree_box(ta, level, i), s->bc) < hd__kill_below(cmax2, s->bc_err)) {
            s->w->culled += node_points(ta, level, i);
            return;
        }
    }
    if (level == 0) {
        walk_bucket(s, i);
        return;
    }
    walk_node(s, level - 1, 2 * i);
    if (2 * i + 1 < ta->count[level - 1]) walk_node(s, level - 1, 2 * i + 1);
}

static void walk_task(void *vctx, size_t task, int worker) {
    dir_ctx *c = vctx;
    walk_t s;
    walk_init(&s, c, &c->w[worker]);
    walk_node(&s, c->task_level, task);
}

/* Prime cmax with the exact nearest distances of a sample of A: points
 * evenly spread along A's curve, and every point of the buckets of A with
 * the largest boxes (sparse regions, where the maximum tends to be). */
#define PRIME_SPREAD 64
#define PRIME_BUCKETS 16

static void prime(dir_ctx *c) {
    const hd__tree_t *ta = c->ta;
    walk_t s;
    /* The points discarded here are walked again later: count the work, not
     * the discards. */
    worker_t w;
    memset(&w, 0, sizeof w);
    walk_init(&s, c, &w);
    size_t step = ta->n / PRIME_SPREAD + 1;
    for (size_t k = step / 2; k < ta->n; k += step) {
        double a[3];
        size_t ia = ta->perm[k];
        hd__src_get(&ta->src, ia, a);
        resolve_point(&s, a, ia);
    }
    size_t top[PRIME_BUCKETS];
    double size[PRIME_BUCKETS];
    int nt = 0;
    for (size_t b = 0; b < ta->nb; b++) {
        const hd__box_t *x = hd__tree_box(ta, 0, b);
        double d = 0;
        for (int k = 0; k < 3; k++) d += (x->hi[k] - x->lo[k]) * (x->hi[k] - x->lo[k]);
        if (nt < PRIME_BUCKETS || d > size[nt - 1]) {
            int p = nt < PRIME_BUCKETS ? nt++ : PRIME_BUCKETS - 1;
            while (p > 0 && size[p - 1] < d) {
                size[p] = size[p - 1];
                top[p] = top[p - 1];
                p--;
            }
            size[p] = d;
            top[p] = b;
        }
    }
    for (int k = 0; k < nt; k++) {
        s.have_bc = 0;
        walk_bucket(&s, top[k]);
    }
    c->w[0].counts.evals += w.counts.evals;
    c->w[0].counts.exact += w.counts.exact;
    c->w[0].counts.nodes += w.counts.nodes;
}

/* h(A,B) over built indexes of A and B. */
static int engine_directed(const hd__tree_t *ta, const hd__tree_t *tb, int threads,
                           hd_result_t *out, hd_error_t *err) {
    dir_ctx c;
    memset(&c, 0, sizeof c);
    c.ta = ta;
    c.tb = tb;
    hd__bound_init(&c.cmax, 0.0);
    hd__best_init(&c.best);
    /* Tasks are subtrees of about 64 buckets (1024 points). */
    c.task_level = ta->levels - 1 < 6 ? ta->levels - 1 : 6;
    size_t tasks = ta->count[c.task_level];
    if (threads < 1) threads = 1;
    c.w = hd__malloc_array((size_t)threads, sizeof *c.w);
    if (!c.w) return hd__err(err, HD_ENOMEM, "out of memory");
    if (pthread_mutex_init(&c.lock, NULL) != 0) {
        free(c.w);
        return hd__err(err, HD_ETHREAD, "cannot create a mutex");
    }
    memset(c.w, 0, (size_t)threads * sizeof *c.w);
    prime(&c);
    int rc = hd__parallel_for(threads, tasks, walk_task, &c);
    pthread_mutex_destroy(&c.lock);
    if (rc != HD_OK) {
        free(c.w);
        return hd__err(err, rc, "%s", hd_strerror(rc));
    }
    memset(&out->stats, 0, sizeof out->stats);
    for (int k = 0; k < threads; k++) {
        out->stats.distance_evals += c.w[k].counts.evals;
        out->stats.nodes_visited += c.w[k].counts.nodes;
        out->stats.points_culled += c.w[k].culled;
    }
    out->distance2 = c.best.d2;
    out->distance = sqrt(c.best.d2);
    out->i = c.best.i;
    out->j = c.best.j;
    out->algorithm = HD_ALG_AUTO;
    free(c.w);
    return HD_OK;
}

/* ---- entry points ---------------------------------------------------------------- */

int hd__engine_trees(const hd__tree_t *ta, const hd__tree_t *tb, int threads, hd_result_t *out,
                     hd_error_t *err) {
    return engine_directed(ta, tb, threads, out, err);
}

static int build_pair(const hd_points_t *A, const hd_points_t *B, int threads, hd__tree_t *ta,
                      hd__tree_t *tb, double *build_seconds, hd_error_t *err) {
    hd__src_t sa, sb;
    hd__src_init(&sa, A, NULL);
    hd__src_init(&sb, B, NULL);
    double t0 = hd__now();
    int rc = hd__tree_build(ta, &sa, A->count, threads, err);
    if (rc) return rc;
    rc = hd__tree_build(tb, &sb, B->count, threads, err);
    if (rc) {
        hd__tree_free(ta);
        return rc;
    }
    *build_seconds = hd__now() - t0;
    return HD_OK;
}

int hd__engine_directed(const hd_points_t *A, const hd_points_t *B, const hd_options_t *opt,
                        hd_result_t *out, hd_error_t *err) {
    size_t n = A->count > B->count ? A->count : B->count;
    int threads = hd__thread_count(opt->threads, n);
    hd__tree_t ta, tb;
    double tbuild;
    double t0 = hd__now();
    int rc = build_pair(A, B, threads, &ta, &tb, &tbuild, err);
    if (rc) return rc;
    rc = engine_directed(&ta, &tb, threads, out, err);
    hd__tree_free(&ta);
    hd__tree_free(&tb);
    out->seconds = hd__now() - t0;
    return rc;
}

int hd__engine_hausdorff(const hd_points_t *A, const hd_points_t *B, const hd_options_t *opt,
                         hd_symmetric_t *out, hd_error_t *err) {
    size_t n = A->count > B->count ? A->count : B->count;
    int threads = hd__thread_count(opt->threads, n);
    hd__tree_t ta, tb;
    double tbuild;
    int rc = build_pair(A, B, threads, &ta, &tb, &tbuild, err);
    if (rc) return rc;
    double t0 = hd__now();
    rc = engine_directed(&ta, &tb, threads, &out->ab, err);
    double t1 = hd__now();
    if (rc == HD_OK) rc = engine_directed(&tb, &ta, threads, &out->ba, err);
    double t2 = hd__now();
    /* Each direction reports its own walk plus half of the shared build. */
    out->ab.seconds = (t1 - t0) + tbuild / 2;
    out->ba.seconds = (t2 - t1) + tbuild / 2;
    hd__tree_free(&ta);
    hd__tree_free(&tb);
    return rc;
}

/* The packed-doubles form used by hd__run_directed (hd_directed with the
 * packed job, e.g. from other modules). */
int hd__engine(const hd__job_t *job, hd_result_t *out, hd_error_t *err) {
    hd_points_t A = hd_points_f64(job->a, job->na), B = hd_points_f64(job->b, job->nb);
    return hd__engine_directed(&A, &B, job->opt, out, err);
}
