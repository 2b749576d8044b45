/*
 * bvh_build.c -- the tree bvh.c searches: built in parallel, its triangles
 * prepared for the search's bounds only when a search first reaches them.
 *
 * The shape.  A node over n > LEAF triangles gives its first child the
 * n / 2 triangles whose centroids come first along the longest axis of
 * the node's centroids' box (three times the centroid, as summed here:
 * only an order) and its second child the rest; ties go either way.  So
 * the shape depends on n alone: a subtree over m triangles has
 * nodes_for(m) nodes, and every node's position in preorder (first child
 * next, second after the first's subtree) is known before its triangles
 * are split, which lets separate threads fill separate subtrees.  Each
 * split reads only its own range of keys, so the tree is the same at any
 * thread count.  Boxes are the exact minima and maxima of the corners (no
 * rounding), so a box bound computed from them holds for every triangle
 * below.
 *
 * The phases, each over every thread given:
 *  1. keys: each triangle's three centroid sums and its position;
 *  2. the top levels, one level at a time (the nodes of a level in
 *     parallel), until there are enough subtrees for the threads;
 *  3. the subtrees, each by one thread;
 *  4. the triangles gathered into leaf order with their boxes;
 *  5. the subtrees' node boxes from the leaves up, then the top levels'.
 * The keys are 32 bytes against a triangle's 80: the splits move keys,
 * and the triangles move once.
 *
 * Prepared triangles (hd__tri_prep, 376 bytes each) are made on first use
 * by hd__bvh_prep, into the next free record of one array (so a search
 * that reaches a third of the triangles writes a third of the array's
 * pages, not every page): slot[k] goes 0 -> HD__BVH_BUSY for the one
 * thread that claims triangle k (compare and swap), which takes the next
 * record (an atomic counter), writes it and then stores its position + 1
 * with release order; a reader that loads that with acquire order reads
 * the finished record.  A reader that finds HD__BVH_BUSY (another thread
 * is writing) prepares its own copy in a per-thread record: hd__tri_prep
 * is a function of the corners, so every copy has the same bits, and no
 * answer depends on who prepared what.  A query near the surface reaches
 * a few triangles: a tree queried by few points never prepares the rest.
 */
#include "mesh/mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define LEAF 4
/* Phase 2 stops when it has this many subtrees a thread, or when the
 * nodes left are this small. */
#define TASKS_PER_THREAD 16
#define SMALLEST_TASK 4096
/* Triangles a task of phases 1 and 4. */
#define CHUNK 16384

typedef struct {
    double c[3]; /* three times the centroid */
    uint32_t pos; /* the triangle's position in the caller's array */
} bkey_t;

/* ---- the shape ------------------------------------------------------- */

/* The node counts of subtrees over n and n + 1 triangles: each splits into
 * halves of n / 2 and n - n / 2 (or a leaf), and the halves of n and n + 1
 * are among m = n / 2 and m + 1. */
static void nodes_pair(size_t n, size_t *cn, size_t *cn1) {
    if (n + 1 <= LEAF) {
        *cn = *cn1 = 1;
        return;
    }
    size_t m = n / 2, a, b;
    nodes_pair(m, &a, &b);
    if (n <= LEAF) *cn = 1;
    else *cn = 1 + (n % 2 ? a + b : 2 * a);
    *cn1 = 1 + (n % 2 ? 2 * b : a + b);
}

static size_t nodes_for(size_t n) {
    size_t a, b;
    nodes_pair(n, &a, &b);
    return a;
}

/* ---- one split ------------------------------------------------------- */

HD__INLINE void swap_keys(bkey_t *x, long i, long j) {
    bkey_t s = x[i];
    x[i] = x[j], x[j] = s;
}

/* Ranges of more than BAND_MIN keys narrow by a band (narrow): a sample
 * of BAND_SAMPLE n^(2/3) keys, the band BAND_WIDTH sqrt(sample) sample
 * ranks either side of the rank (about 2 standard deviations of the
 * rank's place in the sample: the band misses it rarely, and then the
 * step still narrows; wider bands cost more than the misses they save).
 * Measured by `c2m_bench ... 2 1 near 1 1` (docs/benchmarks.md, "The
 * tree's build"). */
#define BAND_MIN 1024
#define BAND_SAMPLE 0.5
#define BAND_WIDTH 1.0
/* Ranges of at most SORT_MAX + 1 keys are sorted by insertion (fewer
 * instructions than a partition of so few; `c2m_bench ... 2 1 near 1 1`). */
#define SORT_MAX 5

/* Partial sort of x[left .. right]: x[k] becomes the key of its rank on
 * axis a, with no larger one before it and no smaller one after.  A large
 * range first narrows to a band of values about the rank (narrow: two
 * partitions by values from a strided sample, the second over the keys
 * above the first's value only); then Hoare's selection, the pivot the
 * median of the ends and x[k], down to a few keys, sorted.  The sample
 * and the band only steer the work: any values give the same
 * postcondition.  Keys equal to the pivot stop both scans and are
 * swapped, so ties split evenly. */
static void select_rank(bkey_t *x, long left, long right, long k, int a);

/* The keys of x[lo .. hi] whose c[a] is below t (strict) or at most t
 * (!strict) moved before the others; returns the position of the first
 * other key.  Both kinds must be present: each scan then stops at a key
 * of the other kind, the first time at one of those, later at the key the
 * other scan left or swapped. */
HD__INLINE long partition_value(bkey_t *x, long lo, long hi, int a, double t, int strict) {
#define BEFORE(c) (strict ? (c) < t : (c) <= t)
    long i = lo, j = hi;
    for (;;) {
        while (BEFORE(x[i].c[a])) i++;
        while (!BEFORE(x[j].c[a])) j--;
        if (i >= j) return i;
        swap_keys(x, i, j);
        i++, j--;
    }
#undef BEFORE
}

/* One step of the selection of rank k in a large x[*left .. *right]: two
 * values u <= v about the rank from a strided sample, the keys below u moved
 * first and those above v last (two partitions, the second over the keys
 * from u up); the range narrows to the part holding rank k, the band
 * [u, v] unless the sample misled.  0 when it cannot narrow (no sample key
 * below u or above v: ties) or did not. */
static int narrow(bkey_t *x, long *left, long *right, long k, int a) {
    long l = *left, r = *right, n = r - l + 1;
    double cn = cbrt((double)n);
    long s = (long)(BAND_SAMPLE * cn * cn), d = (long)(BAND_WIDTH * sqrt((double)s)) + 1, step = n / s;
    for (long q = 1; q < s; q++) swap_keys(x, l + q, l + q * step);
    long ks = (long)((double)(k - l) * (double)s / (double)n);
    long ku = ks - d > 1 ? ks - d : 1, kv = ks + d < s - 2 ? ks + d : s - 2;
    select_rank(x, l, l + s - 1, l + ku, a);
    double u = x[l + ku].c[a];
    select_rank(x, l + ku, l + s - 1, l + kv, a);
    double v = x[l + kv].c[a];
    select_rank(x, l, l + ku - 1, l, a);          /* the sample's least at l */
    select_rank(x, l + kv + 1, l + s - 1, l + s - 1, a); /* its largest at l + s - 1 */
    if (!(x[l].c[a] < u) || !(x[l + s - 1].c[a] > v)) return 0;
    swap_keys(x, l + s - 1, r);
    long p = partition_value(x, l, r, a, u, 1);
    if (k < p) {
        *right = p - 1;
        return 1;
    }
    /* the rest holds u's key (at most v) and x[r] (above v) */
    long q = partition_value(x, p, r, a, v, 0);
    if (k >= q) *left = q;
    else *left = p, *right = q - 1;
    return *right - *left + 1 < n;
}

static void select_rank(bkey_t *x, long left, long right, long k, int a) {
    while (right - left > BAND_MIN && narrow(x, &left, &right, k, a)) {
    }
    while (right - left > SORT_MAX) {
        /* the pivot: the median of the ends and x[k] */
        if (x[k].c[a] < x[left].c[a]) swap_keys(x, k, left);
        if (x[right].c[a] < x[k].c[a]) swap_keys(x, right, k);
        if (x[k].c[a] < x[left].c[a]) swap_keys(x, k, left);
        double t = x[k].c[a];
        long i = left, j = right;
        swap_keys(x, left, k);
        if (x[right].c[a] > t) swap_keys(x, right, left);
        while (i < j) { /* x[left] <= t <= x[right] stop both scans */
            swap_keys(x, i, j);
            i++, j--;
            while (x[i].c[a] < t) i++;
            while (x[j].c[a] > t) j--;
        }
        if (x[left].c[a] == t) swap_keys(x, left, j);
        else swap_keys(x, ++j, right);
        if (j <= k) left = j + 1;
        if (k <= j) right = j - 1;
    }
    for (long i = left + 1; i <= right; i++) /* a few keys: sorted by insertion */
        for (long j = i; j > left && x[j].c[a] < x[j - 1].c[a]; j--) swap_keys(x, j, j - 1);
}

static void select_mid(bkey_t *k, size_t n, size_t mid, int a) { select_rank(k, 0, (long)n - 1, (long)mid, a); }

/* The axis along which the n keys' centroids spread most, over every
 * step-th key: at least AXIS_SAMPLE keys of a node, AXIS_SAMPLE_LARGE of
 * one of AXIS_LARGE keys or more (the small nodes are most of the tree,
 * and a small sample leaves their searches as fast: docs/benchmarks.md,
 * "The tree's build"; the large nodes' axes cost little to sample).  The
 * sample's choice can differ from the whole node's where two axes'
 * extents are close or a few outlying centroids decide an extent; any
 * axis gives a valid tree, and the key order within a node's range
 * depends on the range alone, so the choice is the same at any thread
 * count. */
#define AXIS_SAMPLE 8
#define AXIS_SAMPLE_LARGE 64
#define AXIS_LARGE 1024
static int longest_axis(const bkey_t *k, size_t n) {
    double lo[3], hi[3];
    size_t want = n >= AXIS_LARGE ? AXIS_SAMPLE_LARGE : AXIS_SAMPLE, step = n / want > 1 ? n / want : 1;
    for (int a = 0; a < 3; a++) lo[a] = hi[a] = k[0].c[a];
    for (size_t i = step; i < n; i += step)
        for (int a = 0; a < 3; a++) {
            double c = k[i].c[a];
            lo[a] = lo[a] < c ? lo[a] : c; /* this order: one minsd, no copies */
            hi[a] = hi[a] > c ? hi[a] : c;
        }
    int axis = 0;
    for (int a = 1; a < 3; a++)
        if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
    return axis;
}

/* Node `me` over keys [first, first + n): a leaf, or split (the halves
 * selected) with its second child's position returned; 0 for a leaf. */
static size_t split(hd__bvh_node_t *nodes, bkey_t *keys, size_t me, size_t first, size_t n, size_t first_size) {
    hd__bvh_node_t *node = &nodes[me];
    if (n <= LEAF) {
        node->first_or_second = (uint32_t)first;
        node->count = (uint32_t)n;
        return 0;
    }
    select_mid(keys + first, n, n / 2, longest_axis(keys + first, n));
    size_t second = me + 1 + first_size;
    node->first_or_second = (uint32_t)second;
    node->count = 0;
    return second;
}

/* A whole subtree; returns its number of nodes. */
static size_t subtree(hd__bvh_node_t *nodes, bkey_t *keys, size_t me, size_t first, size_t n) {
    if (n <= LEAF) {
        split(nodes, keys, me, first, n, 0);
        return 1;
    }
    select_mid(keys + first, n, n / 2, longest_axis(keys + first, n));
    size_t used = 1 + subtree(nodes, keys, me + 1, first, n / 2);
    nodes[me].first_or_second = (uint32_t)(me + used);
    nodes[me].count = 0;
    return used + subtree(nodes, keys, me + used, first + n / 2, n - n / 2);
}

/* ---- the phases -------------------------------------------------------- */

typedef struct {
    size_t me, first, n;
} range_t;

typedef struct {
    hd__bvh_t *t;
    const hd__tri_t *in; /* the caller's triangles, in their order */
    bkey_t *keys;
    range_t *cur, *next; /* phase 2's level and the next one (2 a node) */
} build_t;

static void tri_box(const hd__tri_t *t, hd__box_t *b) {
    for (int k = 0; k < 3; k++) {
        double lo = t->v[0][k], hi = lo;
        for (int j = 1; j < 3; j++) {
            lo = t->v[j][k] < lo ? t->v[j][k] : lo;
            hi = t->v[j][k] > hi ? t->v[j][k] : hi;
        }
        b->lo[k] = lo, b->hi[k] = hi;
    }
}

static void make_keys(void *ctx, size_t task, int worker) {
    (void)worker;
    build_t *B = ctx;
    size_t lo = task * CHUNK, hi = lo + CHUNK < B->t->n_tris ? lo + CHUNK : B->t->n_tris;
    for (size_t i = lo; i < hi; i++) {
        const hd__tri_t *t = &B->in[i];
        bkey_t *k = &B->keys[i];
        for (int a = 0; a < 3; a++) k->c[a] = t->v[0][a] + t->v[1][a] + t->v[2][a];
        k->pos = (uint32_t)i;
    }
}

/* Phase 2: the node cur[task] split; its children (or none) in next[2 task ..]. */
static void top_split(void *ctx, size_t task, int worker) {
    (void)worker;
    build_t *B = ctx;
    range_t r = B->cur[task];
    size_t half = r.n / 2;
    size_t second = split(B->t->nodes, B->keys, r.me, r.first, r.n, r.n > LEAF ? nodes_for(half) : 0);
    B->next[2 * task] = second ? (range_t){r.me + 1, r.first, half} : (range_t){0, 0, 0};
    B->next[2 * task + 1] = second ? (range_t){second, r.first + half, r.n - half} : (range_t){0, 0, 0};
}

static void build_subtree(void *ctx, size_t task, int worker) {
    (void)worker;
    build_t *B = ctx;
    range_t r = B->cur[task];
    subtree(B->t->nodes, B->keys, r.me, r.first, r.n);
}

static void gather(void *ctx, size_t task, int worker) {
    (void)worker;
    build_t *B = ctx;
    hd__bvh_t *t = B->t;
    size_t lo = task * CHUNK, hi = lo + CHUNK < t->n_tris ? lo + CHUNK : t->n_tris;
    for (size_t j = lo; j < hi; j++) {
        t->tris[j] = B->in[B->keys[j].pos];
        tri_box(&t->tris[j], &t->boxes[j]);
    }
}

/* Node me's box from its leaves' triangles or its children's boxes
 * (which, later in preorder, are done first). */
static void node_box(hd__bvh_t *t, size_t me) {
    hd__bvh_node_t *node = &t->nodes[me];
    if (node->count) {
        node->box = t->boxes[node->first_or_second];
        for (size_t k = 1; k < node->count; k++) hd__box_merge(&node->box, &t->boxes[node->first_or_second + k]);
    } else {
        node->box = t->nodes[me + 1].box;
        hd__box_merge(&node->box, &t->nodes[node->first_or_second].box);
    }
}

static void subtree_boxes(void *ctx, size_t task, int worker) {
    (void)worker;
    build_t *B = ctx;
    range_t r = B->cur[task];
    for (size_t me = r.me + nodes_for(r.n); me-- > r.me;) node_box(B->t, me);
}

/* Phase 2: splits level by level while the ranges are few and large;
 * leaves B->cur with the subtrees left (*n_sub of them).  The nodes above
 * them are the positions not inside any subtree: top[0 .. *n_top). */
static void top_levels(build_t *B, int threads, size_t *n_sub, size_t *top, size_t *n_top) {
    size_t nc = 1;
    *n_top = 0;
    B->cur[0] = (range_t){0, 0, B->t->n_tris};
    while (threads > 1 && nc < (size_t)threads * TASKS_PER_THREAD && B->cur[0].n > SMALLEST_TASK) {
        hd__parallel_for(threads, nc, top_split, B);
        size_t m = 0;
        for (size_t i = 0; i < nc; i++) top[(*n_top)++] = B->cur[i].me;
        for (size_t i = 0; i < 2 * nc; i++)
            if (B->next[i].n) B->cur[m++] = B->next[i];
        nc = m;
    }
    *n_sub = nc;
}

/* Everything the build allocated, and the frames (hd__bvh_frames); the
 * tree is left zeroed, so freeing it twice is harmless. */
void hd__bvh_free(hd__bvh_t *t) {
    free((void *)t->slot);
    free((void *)t->used);
    hd__reuse_put(NULL, t->tris);
    hd__reuse_put(NULL, t->nodes);
    hd__reuse_put(NULL, t->boxes);
    free(t->prep_pool);
    free(t->frames);
    memset(t, 0, sizeof *t);
}

int hd__bvh_build_threads(hd__bvh_t *t, hd__tri_t *tris, size_t n, int threads) {
    memset(t, 0, sizeof *t);
    if (n == 0 || n > ((size_t)1 << 31)) return HD_EOVERFLOW;
    if (threads < 1) threads = 1;
    if (threads > 256) threads = 256;
    t->n_tris = n;
    t->n_nodes = nodes_for(n);
    /* written whole: mapped at once, in 2 MiB pages where the kernel
     * gives them (hd__reuse_get); the prepared records only as they are
     * first written (a search reaches a part of them) */
    t->tris = hd__reuse_get(NULL, n, sizeof *t->tris);
    t->nodes = hd__reuse_get(NULL, t->n_nodes, sizeof *t->nodes);
    t->boxes = hd__reuse_get(NULL, n, sizeof *t->boxes);
    t->prep_pool = hd__malloc_array(n, sizeof *t->prep_pool);
    t->slot = hd__calloc_array(n, sizeof *t->slot);
    t->used = malloc(sizeof *t->used);
    /* phase 2's levels end below threads * TASKS_PER_THREAD ranges, so a
     * level has fewer than twice that, and the nodes above them too */
    size_t most = 2 * (size_t)threads * TASKS_PER_THREAD;
    bkey_t *keys = hd__reuse_get(NULL, n, sizeof *keys);
    range_t *ranges = hd__malloc_array(3 * most, sizeof *ranges);
    size_t *top = hd__malloc_array(most, sizeof *top);
    if (!t->tris || !t->nodes || !t->boxes || !t->prep_pool || !t->slot || !t->used || !keys || !ranges || !top) {
        hd__reuse_put(NULL, keys), free(ranges), free(top);
        hd__bvh_t failed = *t;
        failed.tris = NULL; /* hd__bvh_free would free it */
        hd__reuse_put(NULL, t->tris);
        hd__bvh_free(&failed);
        memset(t, 0, sizeof *t);
        return HD_ENOMEM; /* the triangles stay the caller's */
    }
    atomic_init(t->used, 0);
    build_t B = {t, tris, keys, ranges, ranges + most};
    size_t chunks = (n + CHUNK - 1) / CHUNK, n_sub, n_top;
    hd__parallel_for(threads, chunks, make_keys, &B);
    top_levels(&B, threads, &n_sub, top, &n_top);
    hd__parallel_for(threads, n_sub, build_subtree, &B);
    hd__parallel_for(threads, chunks, gather, &B);
    hd__parallel_for(threads, n_sub, subtree_boxes, &B);
    for (size_t i = n_top; i-- > 0;) node_box(t, top[i]); /* deeper levels listed later */
    hd__reuse_put(NULL, keys), free(ranges), free(top);
    free(tris); /* taken over: its triangles are now t->tris */
    return HD_OK;
}

int hd__bvh_build(hd__bvh_t *t, hd__tri_t *tris, size_t n) { return hd__bvh_build_threads(t, tris, n, 1); }

/* ---- prepared on first use ------------------------------------------- */

const hd__tri_prep_t *hd__bvh_prep_first(const hd__bvh_t *t, size_t k) {
    static _Thread_local hd__tri_prep_t own;
    const hd__tri_t *tr = &t->tris[k];
    uint_least32_t s = 0;
    if (atomic_compare_exchange_strong_explicit(&t->slot[k], &s, HD__BVH_BUSY, memory_order_acquire,
                                                memory_order_acquire)) {
        size_t r = atomic_fetch_add_explicit(t->used, 1, memory_order_relaxed); /* < n: one a triangle */
        hd__tri_prep(tr->v[0], tr->v[1], tr->v[2], &t->prep_pool[r]);
        atomic_store_explicit(&t->slot[k], (uint_least32_t)(r + 1), memory_order_release);
        return &t->prep_pool[r];
    }
    if (s != HD__BVH_BUSY) return &t->prep_pool[s - 1]; /* finished since the caller looked */
    hd__tri_prep(tr->v[0], tr->v[1], tr->v[2], &own);
    return &own;
}
