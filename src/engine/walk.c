/*
 * walk.c -- one direction of the engine over two bucket trees: h(A,B) by a
 * walk of A's tree in Morton order, each bucket of A's points resolved
 * against B's tree (search.c) after the cheap discards below, into the
 * maximum the threads share (max.c).  The plan (engine.c) runs it for a
 * direction the grid does not take; docs/engine.md tells why each piece is
 * there.  The rules engine.c's opening states hold here: a point or node
 * of A is discarded only when a point of B is proven strictly within cmax
 * of it, or at most at a maximum already attained at a smaller index.
 */
#include "engine/walk.h"
#include "engine/tree.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    hd__counts_t counts;
    uint64_t culled;
} worker_t;

typedef struct {
    const hd__tree_t *ta, *tb;
    hd__max_t *m;         /* the maximum so far, shared */
    int task_level;
    int extra_level;      /* log2 of how many buckets of B a bucket of A spans */
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
    ptrdiff_t drift;   /* where the previous bucket of A found most partners,
                        * relative to the same place along B's curve */
    ptrdiff_t pdrift;  /* the same for the last partner found, in points */
    int track;         /* whether try_bucket's partners update pdrift */
    double ratio;      /* |B| / |A|: position p along A's curve is near
                        * position p * ratio along B's */
    int window_miss;   /* consecutive buckets of A the window settled nothing in */
    unsigned window_tick;
} walk_t;

static void walk_init(walk_t *s, dir_ctx *c, worker_t *w) {
    s->c = c;
    s->w = w;
    hd__max_snapshot(c->m, &s->snap);
    s->have_bc = 0;
    s->hint = HD__NONE;
    s->drift = 0;
    s->pdrift = 0;
    s->track = 0;
    s->window_miss = 0;
    s->window_tick = 0;
    s->ratio = (double)c->tb->n / (double)c->ta->n;
}

static size_t node_points(const hd__tree_t *t, int level, size_t i) {
    size_t first = (i << level) * HD__BUCKET;
    size_t last = ((i + 1) << level) * HD__BUCKET;
    if (last > t->n) last = t->n;
    return last - first;
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
    double cmax2 = hd__bound_get(&s->c->m->cmax);
    double tie2 = ia > s->snap.i ? s->snap.d2 : -1.0;
    hd__hit_t hit;
    hd__tree_nearest(s->c->tb, a, cmax2, tie2, s->hint, &hit, &s->w->counts);
    s->hint = hit.bucket;
    memcpy(s->bc, hit.p, sizeof s->bc);
    s->bc_err = hit.perr;
    s->have_bc = 1;
    if (hit.killed || hit.d2 < cmax2 || hit.d2 <= tie2) return;
    hd__max_offer(s->c->m, hit.d2, ia, hit.j, &s->snap);
}

/* Buckets of B tried on each side of the guess along B's curve, while
 * points are left: a point still alive after them gets a search of its
 * own, which on nearly identical sets costs as much as a dozen more tries
 * (docs/engine.md). */
#define NEIGHBOURS 8

/* The shared walk of a bucket of A visits at most BLOCK_LEAVES buckets of
 * B, within the subtree of 2^BLOCK_LEVEL buckets around the last useful one,
 * before the points left over get their own searches. */
#define BLOCK_LEAVES 8
#define BLOCK_LEVEL 3

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
    size_t ia[HD__BUCKET]; /* original indices */
    double tie2;    /* the maximum so far when a live point may lose a tie
                     * to its witness (a larger index), else -1 */
} group_t;

/* The exact coordinates of point k of the group (read once). */
static const double *group_exact(const hd__tree_t *ta, group_t *g, int k) {
    if (!(g->read >> k & 1u)) {
        hd__src_get(&ta->src, g->ia[k], g->a[k]);
        g->read |= 1u << k;
    }
    return g->a[k];
}

/* The position along B's curve at the same relative place as position p
 * along A's (a guess: only speed depends on it).  A product, not a
 * quotient: a division in the window's loop would lie on the path to its
 * loads (callgrind on hd_bench's cases counts what it cost,
 * docs/engine.md). */
static inline ptrdiff_t same_place(const walk_t *s, size_t p) {
    return (ptrdiff_t)((double)(ptrdiff_t)p * s->ratio); /* signed: one conversion, no branch */
}

/* Points of B tried on each point of A around its partner's expected
 * position (its own position moved by the last partner's offset). */
#define WINDOW 4 /* one vector of four (hd__v4d) */
#define SHIFTS 6 /* shifted windows tried after the first: three on each side, in turn */
#define REACH (SHIFTS / 2 * WINDOW) /* how far the window may move to either side */
#define WINDOW_REST 8
#define WINDOW_MISSES 4

/* Each live point of g against the WINDOW points of B around its own
 * place along B's curve moved by the offset of the last partner found
 * (pdrift): two curves over nearly the same points drift apart slowly, so
 * the partner of a point is most often within a few positions of where the
 * previous point's partner suggests.  Two passes: every live point against
 * the eight points around its place, all with the offset the group started
 * with and without a branch on the outcome; then each point left, in turn,
 * against its first four again when the offset has moved since, and the
 * four on each side, the next four, and the next (REACH), the offset
 * following each partner found.  A point is discarded on the proof of try_bucket
 * (hd__kill_below with both points' errors; the error of B's side is the
 * largest of the buckets decoded, which only lowers the threshold, since
 * hd__kill_below decreases as the error grows).  Ties at the maximum are
 * left to the buckets.  Which points are tried where changes only the
 * speed: every discard is a proof. */
HD__HOT static void try_window(walk_t *s, group_t *g, double cmax2) {
    const hd__tree_t *ta = s->c->ta, *tb = s->c->tb;
    size_t nb_pts = tb->nb * HD__BUCKET; /* positions, padding included */
    ptrdiff_t lo = same_place(s, g->first) + s->pdrift - WINDOW / 2 - REACH;
    ptrdiff_t hi = same_place(s, g->first + (size_t)g->m) + s->pdrift + WINDOW / 2 + REACH;
    if (lo < 0) lo = 0;
    if (hi > (ptrdiff_t)nb_pts) hi = (ptrdiff_t)nb_pts;
    if (hi - lo < WINDOW) return;
    size_t b0 = (size_t)lo / HD__BUCKET, b1 = ((size_t)hi - 1) / HD__BUCKET;
    if (b1 - b0 > 2) return; /* sizes far apart: the window spans too much */
    double x[3 * HD__BUCKET], y[3 * HD__BUCKET], z[3 * HD__BUCKET];
    double eb = 0;
    for (size_t b = b0; b <= b1; b++) {
        size_t o = (b - b0) * HD__BUCKET;
        hd__bucket_decode(tb, b, x + o, y + o, z + o);
        eb = tb->bucket[b].err > eb ? tb->bucket[b].err : eb;
    }
    double lim = hd__kill_below(cmax2, g->err + eb);
    /* Window starts relative to the decoded points: point k's place along
     * B's curve, moved by pdrift, less half the window, clamped. */
    const ptrdiff_t base = (ptrdiff_t)(b0 * HD__BUCKET);
    const ptrdiff_t top = (ptrdiff_t)((b1 + 1 - b0) * HD__BUCKET) - WINDOW;
    const int same_size = ta->n == tb->n;
    ptrdiff_t pd = s->pdrift, last = -1, last_place = 0;
    s->w->counts.evals += (uint64_t)(2 * WINDOW) * (uint64_t)__builtin_popcount(g->alive);
    /* First every live point against the 2 WINDOW points around its place
     * (two vectors), without a branch on the outcome (which goes either way
     * too often to be predicted), all with the drift the group started
     * with: eight points rather than four, since that drift is stale by up
     * to a bucket (hd_bench's independent uniform sets show how many more
     * points eight settle: docs/engine.md).  The last point settled is
     * remembered and its partner found again after the loop. */
    uint32_t hit = 0;
    int hk = -1;
    ptrdiff_t hw = 0;
    const ptrdiff_t top8 = top - WINDOW;
    for (uint32_t left = g->alive; left; left &= left - 1) {
        int k = __builtin_ctz(left);
        size_t pa = g->first + (size_t)k;
        ptrdiff_t place = same_size ? (ptrdiff_t)pa : same_place(s, pa);
        ptrdiff_t w = place + pd - WINDOW - base;
        w = w < 0 ? 0 : w > top8 ? top8 : w;
        hd__v4d bx, by, bz, cx, cy, cz;
        __builtin_memcpy(&bx, x + w, sizeof bx);
        __builtin_memcpy(&by, y + w, sizeof by);
        __builtin_memcpy(&bz, z + w, sizeof bz);
        __builtin_memcpy(&cx, x + w + WINDOW, sizeof cx);
        __builtin_memcpy(&cy, y + w + WINDOW, sizeof cy);
        __builtin_memcpy(&cz, z + w + WINDOW, sizeof cz);
        hd__v4d dx = g->x[k] - bx, dy = g->y[k] - by, dz = g->z[k] - bz;
        hd__v4d d = dx * dx + dy * dy + dz * dz;
        hd__v4d ex = g->x[k] - cx, ey = g->y[k] - cy, ez = g->z[k] - cz;
        hd__v4d e = ex * ex + ey * ey + ez * ez;
        hd__v4l in = (d < lim) | (e < lim);
        int any = (in[0] | in[1] | in[2] | in[3]) != 0;
        hit |= (uint32_t)any << k;
        hk = any ? k : hk;
        hw = any ? w : hw;
    }
    if (hk >= 0) {
        int arg = -1;
        for (int j = 0; j < 2 * WINDOW && arg < 0; j++)
            if (hd__d2s(g->x[hk], g->y[hk], g->z[hk], x[hw + j], y[hw + j], z[hw + j]) < lim) arg = j;
        assert(arg >= 0);
        last = hw + arg;
        size_t pa = g->first + (size_t)hk;
        last_place = same_size ? (ptrdiff_t)pa : same_place(s, pa);
        pd = base + last - last_place;
    }
#ifndef NDEBUG
    /* The proof from both approximations, for each point settled: it and
     * some point of its window, read exactly, lie strictly within cmax (a
     * position in the last bucket's padding holds a copy of that bucket's
     * point 0). */
    for (uint32_t left = hit; left; left &= left - 1) {
        int k = __builtin_ctz(left);
        size_t pa = g->first + (size_t)k;
        ptrdiff_t place = same_size ? (ptrdiff_t)pa : same_place(s, pa);
        ptrdiff_t w = place + s->pdrift - WINDOW - base;
        w = w < 0 ? 0 : w > top - WINDOW ? top - WINDOW : w;
        int proved = 0;
        for (int j = 0; j < 2 * WINDOW; j++) {
            if (!(hd__d2s(g->x[k], g->y[k], g->z[k], x[w + j], y[w + j], z[w + j]) < lim)) continue;
            size_t at = (size_t)(base + w + j);
            if (at >= tb->n) at = at / HD__BUCKET * HD__BUCKET;
            double ea[3], eb3[3];
            hd__src_get(&ta->src, g->ia[k], ea);
            hd__src_get(&tb->src, tb->perm[at], eb3);
            assert(!(hd__d2(ea, eb3) >= cmax2));
            proved = 1;
        }
        assert(proved);
    }
#endif
    g->alive &= ~hit;
    /* Then each point left, in turn, against the windows on either side of
     * its first (REACH), from the drift of the last point settled. */
    for (uint32_t left = g->alive; left; left &= left - 1) {
        int k = __builtin_ctz(left);
        size_t pa = g->first + (size_t)k;
        ptrdiff_t place = same_size ? (ptrdiff_t)pa : same_place(s, pa);
        ptrdiff_t w = place + pd - WINDOW / 2 - base;
        w = w < 0 ? 0 : w > top ? top : w;
        static const int8_t shift[SHIFTS + 1] = {0, -WINDOW, WINDOW, -2 * WINDOW, 2 * WINDOW, -3 * WINDOW, 3 * WINDOW};
        hd__v4l in = {0, 0, 0, 0};
        int found = 0;
        /* The first window again only when the drift has moved since. */
        for (int t = pd == s->pdrift; t <= SHIFTS && !found; t++) {
            ptrdiff_t v = w + shift[t];
            v = v < 0 ? 0 : v > top ? top : v;
            hd__v4d bx, by, bz;
            __builtin_memcpy(&bx, x + v, sizeof bx);
            __builtin_memcpy(&by, y + v, sizeof by);
            __builtin_memcpy(&bz, z + v, sizeof bz);
            hd__v4d dx = g->x[k] - bx, dy = g->y[k] - by, dz = g->z[k] - bz;
            hd__v4d d = dx * dx + dy * dy + dz * dz;
            in = d < lim;
            s->w->counts.evals += WINDOW;
            if (in[0] | in[1] | in[2] | in[3]) found = 1, w = v;
        }
        if (!found) continue;
        int arg = in[0] ? 0 : in[1] ? 1 : in[2] ? 2 : 3;
        last = w + arg;
#ifndef NDEBUG
        {
            size_t at = (size_t)(base + last);
            if (at >= tb->n) at = at / HD__BUCKET * HD__BUCKET;
            double ea[3], eb3[3];
            hd__src_get(&ta->src, g->ia[k], ea);
            hd__src_get(&tb->src, tb->perm[at], eb3);
            assert(!(hd__d2(ea, eb3) >= cmax2));
        }
#endif
        g->alive &= ~(1u << k);
        pd = base + last - place;
    }
    if (last < 0) return;
    s->pdrift = pd;
    s->bc[0] = x[last], s->bc[1] = y[last], s->bc[2] = z[last];
    s->bc_err = eb;
    s->have_bc = 1;
    s->hint = (size_t)(base + last) / HD__BUCKET;
}

/* Try bucket i of B on the live points of g; a point is discarded when the
 * approximations prove some point of the bucket strictly within cmax, or
 * when the pair is too close to call and its exact distance does.
 * Returns how many points it discarded. */
HD__HOT static int try_bucket(walk_t *s, group_t *g, size_t i, double cmax2) {
    const hd__tree_t *tb = s->c->tb;
    const uint32_t alive0 = g->alive;
    const hd__bucket_t *bb = &tb->bucket[i];
    double lim = hd__kill_below(cmax2, g->err + bb->err);
    double reach = hd__may_reach(cmax2, g->err + bb->err);
    uint32_t near = 0;
    for (uint32_t left = g->alive; left; left &= left - 1) {
        int k = __builtin_ctz(left);
        double lb = hd__box_lb2s(&bb->box, g->x[k], g->y[k], g->z[k]);
        /* Within cmax, or at most the maximum for a point that would lose the
         * tie (with cmax = 0, as for a subset, only exact duplicates count). */
        if (lb < cmax2 || (lb <= s->snap.d2 && g->ia[k] > s->snap.i)) near |= 1u << k;
    }
    if (!near) return 0;
    double x[HD__BUCKET], y[HD__BUCKET], z[HD__BUCKET];
    int mb = hd__bucket_decode(tb, i, x, y, z);
    int close_k[HD__BUCKET], close_b[HD__BUCKET], n_close = 0;
    for (uint32_t left = near; left; left &= left - 1) {
        int k = __builtin_ctz(left);
        double d[HD__BUCKET];
        const double ax = g->x[k], ay = g->y[k], az = g->z[k];
        for (int q = 0; q < HD__BUCKET; q++) d[q] = hd__d2s(ax, ay, az, x[q], y[q], z[q]);
        s->w->counts.evals += (uint64_t)mb;
        double mn = hd__min32(d);
        if (mn > reach) continue;
        int arg = hd__find(d, mn);
        assert(arg < mb); /* the padding repeats point 0, so a real point comes first */
        if (mn < lim) {
#ifndef NDEBUG
            /* The proof from both approximations: the two points, read
             * exactly, lie strictly within cmax (NaN only if the caller's
             * points broke the contract). */
            double ea[3], eb[3];
            hd__src_get(&s->c->ta->src, g->ia[k], ea);
            hd__src_get(&tb->src, tb->perm[i * HD__BUCKET + (size_t)arg], eb);
            assert(!(hd__d2(ea, eb) >= cmax2));
#endif
            g->alive &= ~(1u << k);
            s->bc[0] = x[arg], s->bc[1] = y[arg], s->bc[2] = z[arg];
            s->bc_err = bb->err;
            s->have_bc = 1;
            s->hint = i;
            if (s->track)
                s->pdrift = (ptrdiff_t)(i * HD__BUCKET + (size_t)arg) - same_place(s, g->first + (size_t)k);
            continue;
        }
        close_k[n_close] = k;
        close_b[n_close++] = arg;
    }
    if (!n_close) return __builtin_popcount(alive0 & ~g->alive);
    /* Pairs too close to call from the approximations (ties, or nearly) are
     * decided exactly; their scattered loads are started together. */
    const hd__tree_t *ta = s->c->ta;
    if (ta->src.kind != HD__SRC_ANY && tb->src.kind != HD__SRC_ANY) {
        ptrdiff_t ea = hd__src_packed_stride(&ta->src), eb = hd__src_packed_stride(&tb->src);
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
        if (hd__kills(cmax2, &s->snap, e, g->ia[k])) {
            g->alive &= ~(1u << k);
            memcpy(s->bc, b, sizeof s->bc);
            s->bc_err = 0;
            s->have_bc = 1;
            s->hint = i;
        }
    }
    return __builtin_popcount(alive0 & ~g->alive);
}

/* The buckets of B that may hold points of B's Morton cell `key`: those
 * points lie along B's curve between the last bucket whose first key is
 * below `key` and the last one whose first key equals it.  Writes at most
 * two buckets (in a cell crowded enough to span more, the first two) and
 * returns how many. */
static int key_buckets(const hd__tree_t *t, uint32_t key, size_t out[2]) {
    size_t lo = 0, hi = t->nb; /* the first bucket whose first key is >= key */
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (t->fkey[mid] < key) lo = mid + 1;
        else hi = mid;
    }
    int n = 0;
    if (lo > 0) out[n++] = lo - 1;
    if (lo < t->nb && t->fkey[lo] == key) out[n++] = lo;
    return n;
}

/* Before the points left in a group get searches of their own: a point
 * whose partner lies across a jump of B's curve is not near its own
 * position along it, but it is in one of the few cells of B's Morton grid
 * that its ball of radius cmax meets.  Each of those cells is found along
 * B's curve by its key (a binary search over the buckets' first keys) and
 * its buckets are tried like any other (try_bucket's proofs).  Only speed
 * depends on which buckets are tried. */
static void try_cells(walk_t *s, group_t *g, double cmax2) {
    const hd__tree_t *tb = s->c->tb;
    const hd__keygrid_t *grid = &tb->grid;
    if (grid->scale == 0.0) return;
    double r = sqrt(cmax2 > g->tie2 ? cmax2 : g->tie2);
    for (uint32_t left = g->alive; left; left &= left - 1) {
        int k = __builtin_ctz(left);
        if (!(g->alive >> k & 1u)) continue; /* discarded by a bucket tried for another point */
        const double p[3] = {g->x[k], g->y[k], g->z[k]};
        uint32_t c[3][2];
        for (int d = 0; d < 3; d++) {
            c[d][0] = hd__key_cell(grid, d, p[d] - r);
            c[d][1] = hd__key_cell(grid, d, p[d] + r);
        }
        size_t tried[16];
        int nt = 0;
        for (int corner = 0; corner < 8 && (g->alive >> k & 1u); corner++) {
            uint32_t x = c[0][corner & 1], y = c[1][corner >> 1 & 1], z = c[2][corner >> 2];
            if ((corner & 1 && x == c[0][0]) || (corner & 2 && y == c[1][0]) || (corner & 4 && z == c[2][0]))
                continue; /* the same cell as a corner already taken */
            size_t bk[2];
            int m = key_buckets(tb, hd__spread10(x) | hd__spread10(y) << 1 | hd__spread10(z) << 2, bk);
            for (int q = 0; q < m && (g->alive >> k & 1u); q++) {
                int seen = 0;
                for (int t = 0; t < nt; t++) seen |= tried[t] == bk[q];
                if (seen) continue;
                tried[nt++] = bk[q];
                try_bucket(s, g, bk[q], cmax2);
            }
        }
    }
}

/* Resolve the points of A's bucket bk together, from their quantised copy:
 * try the last useful point of B on each; then each point against the few
 * points of B around its expected place along B's curve (try_window); then
 * the bucket of B at the same relative place moved by the drift, and the
 * one where the last search ended, with their neighbours along B's curve
 * (for nearly identical sets the nearest points sit at nearly the same
 * place on both curves); then a short walk of B's tree for the whole
 * bucket, nearest buckets first; then, for each point left, the buckets of
 * the cells of B around it found by their keys (try_cells).  Every point
 * that the approximations prove irrelevant is discarded; the points left
 * are read exactly and get their own search. */
HD__HOT static void walk_bucket(walk_t *s, size_t bk) {
    const hd__tree_t *ta = s->c->ta, *tb = s->c->tb;
    group_t g;
    g.m = hd__bucket_decode(ta, bk, g.x, g.y, g.z);
    g.err = ta->bucket[bk].err;
    g.first = bk * HD__BUCKET;
    g.read = 0;
    double cmax2 = hd__bound_get(&s->c->m->cmax);
    g.alive = g.m == 32 ? 0xffffffffu : (1u << g.m) - 1;
    /* A live point may lose a tie to the witness when its index is larger
     * (the largest index of the group decides, without a branch a point). */
    size_t largest = 0;
    for (int k = 0; k < g.m; k++) {
        g.ia[k] = ta->perm[g.first + (size_t)k];
        assert(g.ia[k] < ta->n);
        largest = g.ia[k] > largest ? g.ia[k] : largest;
    }
    g.tie2 = largest > s->snap.i ? s->snap.d2 : -1.0;
    if (s->have_bc) {
        double lim = hd__kill_below(cmax2, g.err + s->bc_err);
        for (int k = 0; k < g.m; k++)
            if (hd__d2s(g.x[k], g.y[k], g.z[k], s->bc[0], s->bc[1], s->bc[2]) < lim)
                g.alive &= ~(1u << k);
        s->w->counts.evals += (uint64_t)g.m;
    }
    /* Where the window settles nothing WINDOW_MISSES times in a row (a
     * translated copy, whose partners all lie at the maximum distance, too
     * close to call from the approximations), it is tried only on every
     * WINDOW_REST-th bucket of A until it settles something again. */
    if (g.alive && (s->window_miss < WINDOW_MISSES || ++s->window_tick % WINDOW_REST == 0)) {
        uint32_t before = g.alive;
        try_window(s, &g, cmax2);
        s->window_miss = g.alive == before ? s->window_miss + 1 : 0;
    }
    if (g.alive) {
        /* Two guesses: the bucket at the same relative position along B's
         * curve moved by the drift that served the previous bucket (two
         * curves over nearly the same points drift apart slowly, by the
         * points that crossed a cell face), and the bucket where the last
         * search ended. */
        size_t same = (size_t)((double)bk * (double)tb->nb / (double)ta->nb);
        ptrdiff_t at = (ptrdiff_t)same + s->drift;
        size_t guess[2] = {at < 0 ? 0 : (size_t)at, s->hint};
        size_t most = HD__NONE;
        int most_k = 0;
        for (int q = 0; q < 2 && g.alive; q++) {
            size_t h = guess[q];
            if (h == HD__NONE || (q == 1 && h + NEIGHBOURS >= guess[0] && h <= guess[0] + NEIGHBOURS)) continue;
            if (h >= tb->nb) h = tb->nb - 1;
            s->track = q == 0;
            int k = try_bucket(s, &g, h, cmax2);
            s->track = 0;
            if (k > most_k) most_k = k, most = h;
            for (size_t r = 1; r <= NEIGHBOURS && g.alive; r++) {
                if (h + r < tb->nb && (k = try_bucket(s, &g, h + r, cmax2)) > most_k) most_k = k, most = h + r;
                if (g.alive && h >= r && (k = try_bucket(s, &g, h - r, cmax2)) > most_k) most_k = k, most = h - r;
            }
        }
        if (most != HD__NONE) s->drift = (ptrdiff_t)most - (ptrdiff_t)same;
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
        /* The walk covers the subtree of BLOCK_SPAN buckets around the last
         * useful bucket of B: points that close are close along the curve
         * too, apart from the curve's jumps, which the searches handle. */
        int l = BLOCK_LEVEL + s->c->extra_level;
        if (l > tb->levels - 1) l = tb->levels - 1;
        size_t h = s->hint != HD__NONE ? s->hint : 0;
        stack[0].level = l;
        stack[0].i = h >> l;
        stack[0].gap2 = hd__box_box_lb2(ba, hd__tree_box(tb, l, h >> l));
        sp = 1;
    }
    /* A node of B matters when it may hold a point strictly within cmax,
     * or one at most the maximum for a point that would lose the tie. */
#define MATTERS(gap2) ((gap2) < cmax2 || (gap2) <= g.tie2)
    while (sp > 0 && g.alive && leaves < (BLOCK_LEAVES << s->c->extra_level)) {
        sp--;
        if (!MATTERS(stack[sp].gap2)) continue;
        int l = stack[sp].level;
        size_t i = stack[sp].i;
        s->w->counts.nodes++;
        if (l == 0) {
            try_bucket(s, &g, i, cmax2);
            leaves++;
            continue;
        }
        size_t c0 = 2 * i, c1 = 2 * i + 1;
        const hd__box_t *b0 = hd__tree_box(tb, l - 1, c0);
        double g0 = hd__box_box_lb2(ba, b0);
        if (c1 >= tb->count[l - 1]) {
            if (MATTERS(g0)) stack[sp].level = l - 1, stack[sp].i = c0, stack[sp].gap2 = g0, sp++;
            continue;
        }
        const hd__box_t *b1 = hd__tree_box(tb, l - 1, c1);
        double g1 = hd__box_box_lb2(ba, b1);
        /* Nearer child (by gap, then by centre distance) on top. */
        if (g0 > g1 || (g0 == g1 && centre_gap2(ba, b0) > centre_gap2(ba, b1))) {
            size_t t = c0;
            c0 = c1;
            c1 = t;
            double u = g0;
            g0 = g1;
            g1 = u;
        }
        if (MATTERS(g1)) stack[sp].level = l - 1, stack[sp].i = c1, stack[sp].gap2 = g1, sp++;
        if (MATTERS(g0)) stack[sp].level = l - 1, stack[sp].i = c0, stack[sp].gap2 = g0, sp++;
    }
#undef MATTERS
    if (g.alive) try_cells(s, &g, cmax2);
    s->w->culled += (uint64_t)(g.m - __builtin_popcount(g.alive));
    if (!g.alive) return;
    /* The points left are read exactly; start all their loads at once. */
    if (ta->src.kind != HD__SRC_ANY) {
        ptrdiff_t el = hd__src_packed_stride(&ta->src);
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
        double cmax2 = hd__bound_get(&s->c->m->cmax);
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

static void prime(dir_ctx *c, const size_t *seed, int nseed) {
    const hd__tree_t *ta = c->ta;
    walk_t s;
    /* The points discarded here are walked again later: count the work, not
     * the discards. */
    worker_t w;
    memset(&w, 0, sizeof w);
    walk_init(&s, c, &w);
    for (int k = 0; k < nseed; k++) {
        double a[3];
        hd__src_get(&ta->src, seed[k], a);
        resolve_point(&s, a, seed[k]);
    }
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
        hd__top_insert(size, top, &nt, PRIME_BUCKETS, d, b);
    }
    for (int k = 0; k < nt; k++) {
        s.have_bc = 0;
        walk_bucket(&s, top[k]);
    }
    c->w[0].counts.evals += w.counts.evals;
    c->w[0].counts.exact += w.counts.exact;
    c->w[0].counts.nodes += w.counts.nodes;
}

/* Tasks are subtrees of A's tree at this level: 2^6 = 64 buckets each
 * (fewer when the tree is lower), many per thread so the shared counter
 * balances them, each long enough to repay taking it. */
#define TASK_LEVEL 6
/* A bucket of a set much sparser than B spans that many more buckets of B:
 * its shared walk may visit up to 2^EXTRA_LEVEL_MOST = 16 times more (the
 * walk's extra_level, log2 of |B| / |A| in buckets, stops here). */
#define EXTRA_LEVEL_MOST 4

int hd__walk_directed(const hd__tree_t *ta, const hd__tree_t *tb, hd__max_t *m, int threads,
                      const size_t *seed, int nseed, hd__counts_t *counts, uint64_t *culled,
                      hd_error_t *err) {
    dir_ctx c;
    memset(&c, 0, sizeof c);
    c.ta = ta;
    c.tb = tb;
    c.m = m;
    c.task_level = ta->levels - 1 < TASK_LEVEL ? ta->levels - 1 : TASK_LEVEL;
    while (c.extra_level < EXTRA_LEVEL_MOST && (ta->nb << (c.extra_level + 1)) <= tb->nb) c.extra_level++;
    size_t tasks = ta->count[c.task_level];
    if (threads < 1) threads = 1;
    c.w = hd__calloc_array((size_t)threads, sizeof *c.w);
    if (!c.w) return hd__err(err, HD_ENOMEM, "out of memory");
    prime(&c, seed, nseed);
    hd__parallel_for(threads, tasks, walk_task, &c);
    for (int k = 0; k < threads; k++) {
        counts->evals += c.w[k].counts.evals;
        counts->exact += c.w[k].counts.exact;
        counts->nodes += c.w[k].counts.nodes;
        *culled += c.w[k].culled;
    }
    free(c.w);
    return HD_OK;
}

